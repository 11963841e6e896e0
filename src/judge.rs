//! Judging one model result: the model's bits against the reference decision on the same
//! (format-quantised) inputs, and against the error bound of the datapath.
//!
//! The **reference decision** is the exact hit/miss of the quantised test, found by a filter
//! first (CGAL's filtered predicates): the det-scaled quantities the decision reads (det,
//! u', v', det − (u' + v'), t' and t against the interval's finite ends), evaluated in f64 in
//! the datapath's order, each clear of zero by more than the bound on their f64 evaluation
//! ([`datapath::bound::RtiBound`] with the zero error model [`EXACT_F64`], i.e. its
//! `F64_SLACK` term alone), give the exact signs; a test the filter cannot decide (or whose
//! f64 evaluation overflows) *falls through* to exact rational arithmetic
//! ([`golden::intersect_exact`]). The golden f64 Möller–Trumbore (textbook order) gives t.

use datapath::bound::RtiBound;
use datapath::rti::{Cull, Rti};
use datapath::Format;
use golden::{Faces, MtResult, Ray64, Tri64};

/// Everything known about one ray–triangle test.
#[derive(Clone, Copy, Debug)]
pub struct Judged {
    /// Model hit bit.
    pub hit: bool,
    /// Model t as f64.
    pub t: f64,
    /// Golden result on the quantised inputs (its t is the reference t).
    pub golden: MtResult,
    /// The reference (exact) hit decision: the f64 filter's, or exact rational arithmetic's.
    pub reference_hit: bool,
    /// The f64 filter could not decide: exact rational arithmetic did.
    pub fell_through: bool,
    /// The error bound says the model must reproduce the exact decision.
    pub decisive: bool,
    /// The bound's exact decision.
    pub exact_hit: bool,
    /// Bound on |t − t_exact| when decisive.
    pub t_err: f64,
    /// Spacing of the format's grid at the golden t.
    pub ulp: f64,
}

impl Judged {
    /// A property failure: a decisive case whose hit/miss differs from the reference decision
    /// (which, in a decisive case, is the bound's exact decision), or a shared hit whose t
    /// error exceeds the bound.
    pub fn violation(&self) -> Option<String> {
        violation(self.decisive, self.hit, self.reference_hit, self.exact_hit, self.t, self.golden.t, self.t_err)
    }
    /// |t_model − t_golden|.
    pub fn t_error(&self) -> f64 {
        (self.t - self.golden.t).abs()
    }
}

/// Relative slack on the t bound: binary64's own rounding of the golden t.
pub const T_SLACK: f64 = 1e-12;

/// The property on one test, the one rule `verify` and `explain` judge by: nothing unless
/// `decisive`; then a hit/miss that differs from the reference decision (or a reference that
/// differs from the bound's `exact_hit`), else a model hit whose |t − t_golden| exceeds
/// `t_err + |t_golden|·T_SLACK`. Returns the failure's message.
pub fn violation(
    decisive: bool,
    hit: bool,
    reference_hit: bool,
    exact_hit: bool,
    t: f64,
    t_golden: f64,
    t_err: f64,
) -> Option<String> {
    if !decisive {
        return None;
    }
    if hit != reference_hit || reference_hit != exact_hit {
        return Some(format!("hit/miss: model {hit} exact {reference_hit}"));
    }
    let e = (t - t_golden).abs();
    if hit && e > t_err + t_golden.abs() * T_SLACK {
        return Some(format!("t error {e:e} exceeds bound {t_err:e}"));
    }
    None
}

/// The golden's face options matching an RTI unit.
pub fn faces<F: Format>(rti: &Rti<F>) -> Faces {
    Faces { cull: rti.cull == Cull::Backface, det_threshold: rti.fmt.to_f64(rti.det_thr) }
}

/// Quantises the f64 ray and triangle into the format and back (what the hardware sees).
pub fn quantise<F: Format>(rti: &Rti<F>, ray: &Ray64, tri: &Tri64) -> (Ray64, Tri64) {
    let f = &rti.fmt;
    let q = |x: f64| f.to_f64(f.from_f64(x));
    (
        Ray64 { o: ray.o.map(q), d: ray.d.map(q), tmin: q(ray.tmin), tmax: q(ray.tmax) },
        Tri64 { v: tri.v.map(|p| p.map(q)) },
    )
}

/// The error model of an exact evaluation: no rounding error, only the bound's f64
/// evaluation slack (the f64 filter of the reference decision).
pub const EXACT_F64: datapath::format::ErrorModel =
    datapath::format::ErrorModel { u: 0.0, eta: 0.0, add_eta: 0.0, max: f64::MAX };

/// What decided a test's reference hit/miss.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum DecidedBy {
    /// The format's error bound was decisive (its f64 evaluation's slack included).
    Bound,
    /// The f64 filter (the bound with zero format error) certified the signs.
    F64Filter,
    /// Exact rational arithmetic on the quantised inputs.
    Exact,
    /// No exact answer (a non-finite quantised input): the golden f64 test's.
    GoldenF64,
}

impl DecidedBy {
    /// The words `explain` prints.
    pub fn words(self) -> &'static str {
        match self {
            DecidedBy::Bound => "the error bound",
            DecidedBy::F64Filter => "the f64 filter",
            DecidedBy::Exact => "exact rational arithmetic",
            DecidedBy::GoldenF64 => "the golden f64 test (no exact answer for non-finite inputs)",
        }
    }

    /// The f64 filter could not decide (verify counts these as `exact`).
    pub fn fell_through(self) -> bool {
        matches!(self, DecidedBy::Exact | DecidedBy::GoldenF64)
    }
}

/// The reference decision of a quantised test and whether it fell through the f64 filter to
/// exact rational arithmetic (see the module documentation); `golden_hit` stands in where the
/// exact arithmetic has no answer (a non-finite input).
pub fn reference<F: Format>(rti: &Rti<F>, rq: &Ray64, tq: &Tri64, golden_hit: bool) -> (bool, bool) {
    let (hit, by) = reference_by(rti, rq, tq, golden_hit);
    (hit, by.fell_through())
}

/// [`reference`], naming what decided: the f64 filter, exact rational arithmetic, or (no
/// exact answer) the golden f64 test.
pub fn reference_by<F: Format>(rti: &Rti<F>, rq: &Ray64, tq: &Tri64, golden_hit: bool) -> (bool, DecidedBy) {
    let o = f64_filter_opts(rti);
    let v = RtiBound::new(o.em, o.div, rq.o, rq.d, tq.v).verdict(o.cull, o.det_threshold, rq.tmin, rq.tmax);
    reference_after(rti, rq, tq, (v.decisive, v.hit), golden_hit)
}

/// The f64 filter's options as a block of tests takes them: the lanes of
/// [`datapath::bound::verdict_block`] (or its statically filtered form) with these options are
/// the verdicts [`reference_by`] starts from, lane by lane.
pub fn f64_filter_opts<F: Format>(rti: &Rti<F>) -> datapath::bound::BlockOpts {
    datapath::bound::BlockOpts {
        em: EXACT_F64,
        div: datapath::format::DivMode::Divide,
        cull: rti.cull,
        det_threshold: rti.fmt.to_f64(rti.det_thr),
    }
}

/// [`reference_by`] given the f64 filter's verdict on the test, (decisive, hit): the filter's
/// hit when decisive, else exact rational arithmetic (or the golden f64 hit when there is no
/// exact answer).
pub fn reference_after<F: Format>(
    rti: &Rti<F>,
    rq: &Ray64,
    tq: &Tri64,
    (decisive, hit): (bool, bool),
    golden_hit: bool,
) -> (bool, DecidedBy) {
    if decisive {
        (hit, DecidedBy::F64Filter)
    } else {
        match golden::intersect_exact(rq, tq, faces(rti)) {
            Some(h) => (h, DecidedBy::Exact),
            None => (golden_hit, DecidedBy::GoldenF64),
        }
    }
}

/// The reference decision `verify` judges a test by: the format's error bound's when it is
/// decisive (`verdict`, computed on the quantised inputs `rq`, `tq`), else [`reference_by`].
pub fn decide<F: Format>(
    rti: &Rti<F>,
    rq: &Ray64,
    tq: &Tri64,
    verdict: datapath::bound::Verdict,
    golden_hit: bool,
) -> (bool, DecidedBy) {
    if verdict.decisive {
        (verdict.hit, DecidedBy::Bound)
    } else {
        reference_by(rti, rq, tq, golden_hit)
    }
}

/// Runs the model on one test and judges it.
pub fn judge<F: Format>(rti: &Rti<F>, ray: &Ray64, tri: &Tri64) -> Judged {
    let f = &rti.fmt;
    let out = rti.test(&rti.ray(ray.o, ray.d, ray.tmin, ray.tmax), &rti.tri(tri.v));
    let (rq, tq) = quantise(rti, ray, tri);
    let golden = golden::intersect(&rq, &tq, faces(rti));
    let b = RtiBound::new(f.error_model(), f.div_mode(), rq.o, rq.d, tq.v);
    let v = b.verdict(rti.cull, f.to_f64(rti.det_thr), rq.tmin, rq.tmax);
    // a decisive case is also decided by the f64 filter (the model's bounds include its slack)
    let (reference_hit, by) = decide(rti, &rq, &tq, v, golden.hit);
    let fell_through = by.fell_through();
    Judged {
        hit: out.hit,
        t: f.to_f64(out.t),
        golden,
        reference_hit,
        fell_through,
        decisive: v.decisive,
        exact_hit: v.hit,
        t_err: b.t_err,
        ulp: f.ulp(golden.t),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use datapath::format::{F32Native, FpOpts, Ieee};
    use datapath::rti::RtiConfig;

    fn rti() -> Rti<Ieee<F32Native>> {
        Rti::new(Ieee::new(F32Native, FpOpts::default()), RtiConfig::default())
    }

    const TRI: Tri64 = Tri64 { v: [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] };

    fn down(x: f64, y: f64) -> Ray64 {
        Ray64 { o: [x, y, 1.0], d: [0.0, 0.0, -1.0], tmin: 0.0, tmax: f64::INFINITY }
    }

    /// A test clear of every threshold is decided by the f64 filter; one exactly on an edge or
    /// a vertex (u' = 0, or u' + v' = det) cannot be, falls through, and gets the exact
    /// answer (the closed triangle: a hit); one a hair outside an edge, far from the origin
    /// (cancellation), falls through and misses.
    #[test]
    fn the_reference_filters_first_and_falls_through_to_exact_arithmetic() {
        let r = rti();
        assert_eq!(reference(&r, &down(0.25, 0.25), &TRI, false), (true, false));
        assert_eq!(reference(&r, &down(2.0, 2.0), &TRI, true), (false, false));
        for (x, y) in [(0.0, 0.5), (0.5, 0.0), (0.5, 0.5), (0.0, 0.0), (1.0, 0.0)] {
            assert_eq!(reference(&r, &down(x, y), &TRI, false), (true, true), "({x}, {y})");
        }
        // tiny margins the f64 evaluation resolves exactly: still the filter's
        let e = 2f64.powi(-60);
        assert_eq!(reference(&r, &down(-e, 0.5), &TRI, true), (false, false));
        // the same triangle far from the origin (x + 2^30): u' = -2^-20 against monomials of
        // 2^31, which the f64 filter cannot certify; exact arithmetic says outside
        let far = Tri64 { v: TRI.v.map(|p| [p[0] + 2f64.powi(30), p[1], p[2]]) };
        let x = 2f64.powi(30) - 2f64.powi(-20);
        assert_eq!(reference(&r, &down(x, 0.5), &far, true), (false, true));
        assert_eq!(reference(&r, &down(x + 2f64.powi(-19), 0.5), &far, false), (true, true));
        // a NaN input has no exact answer: the golden's stands
        assert_eq!(reference(&r, &down(f64::NAN, 0.5), &TRI, true), (true, true));
    }

    /// The property, case by case: nothing is asked of a test that is not decisive; a decisive
    /// one fails on a hit/miss that differs from the reference, and on a shared hit whose t
    /// error exceeds the bound (plus 1e-12 relative of t for the f64 evaluation of the error).
    #[test]
    fn a_violation_is_a_decisive_disagreement_or_a_t_beyond_its_bound() {
        let golden = MtResult { hit: true, t: 2.0, ..golden::intersect(&down(0.25, 0.25), &TRI, Faces::default()) };
        let j = Judged {
            hit: true,
            t: 2.0 + 1e-6,
            golden,
            reference_hit: true,
            fell_through: false,
            decisive: true,
            exact_hit: true,
            t_err: 1e-6,
            ulp: 2f64.powi(-22),
        };
        assert_eq!(j.t_error(), (2.0 + 1e-6) - 2.0);
        assert_eq!(j.violation(), None, "t error at the bound");
        let slack = 2.0 * 1e-12;
        assert_eq!(Judged { t: 2.0 + 1e-6 + slack * 0.5, ..j }.violation(), None, "within the f64 slack");
        let over = Judged { t: 2.0 - 1e-6 - slack * 4.0, ..j };
        assert!(over.violation().unwrap().starts_with("t error "), "{:?}", over.violation());
        // exactly on the bound (2^-20 = t_err + 2·1e-12 in f64): not a violation
        let on = Judged { t: 2.0 + 2f64.powi(-20), t_err: 2f64.powi(-20) - slack, ..j };
        assert_eq!(on.t_err + on.golden.t.abs() * 1e-12, on.t_error());
        assert_eq!(on.violation(), None);
        let miss = Judged { hit: false, ..j };
        assert_eq!(miss.violation().as_deref(), Some("hit/miss: model false exact true"));
        let false_hit = Judged { reference_hit: false, exact_hit: false, ..j };
        assert_eq!(false_hit.violation().as_deref(), Some("hit/miss: model true exact false"));
        // the reference and the bound's exact decision disagree: reported too
        assert!(Judged { exact_hit: false, ..j }.violation().unwrap().starts_with("hit/miss"));
        // a shared miss has no t to judge; a non-decisive test is never a violation
        assert_eq!(Judged { hit: false, reference_hit: false, exact_hit: false, t: 9.0, ..j }.violation(), None);
        assert_eq!(Judged { decisive: false, hit: false, t: 9.0, ..j }.violation(), None);
        assert_eq!(Judged { decisive: false, ..over }.violation(), None);
    }

    /// The golden's faces follow the unit's culling and its det threshold (as the format
    /// stores it).
    #[test]
    fn the_golden_faces_are_the_units() {
        let f = Ieee::new(F32Native, FpOpts::default());
        assert_eq!(faces(&rti()), Faces { cull: false, det_threshold: 0.0 });
        let culled = Rti::new(f, RtiConfig { cull: Cull::Backface, det_threshold: 0.1, ..RtiConfig::default() });
        assert_eq!(faces(&culled), Faces { cull: true, det_threshold: 0.1f32 as f64 });
        let two = Rti::new(f, RtiConfig { cull: Cull::TwoSided, det_threshold: 0.25, ..RtiConfig::default() });
        assert_eq!(faces(&two), Faces { cull: false, det_threshold: 0.25 });
    }

    /// The judge uses the reference: an on-edge test's reference hit is the exact one, and
    /// fell_through says so.
    #[test]
    fn the_judge_reports_the_fall_through() {
        let r = rti();
        let j = judge(&r, &down(0.0, 0.5), &TRI);
        assert!(j.reference_hit && j.fell_through && !j.decisive);
        let j = judge(&r, &down(0.25, 0.25), &TRI);
        assert!(j.reference_hit && !j.fell_through && j.decisive);
    }
}
