//! Judging one model result: the model's bits against the golden f64 reference on the same
//! (format-quantised) inputs, and against the error bound of the datapath.

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
    /// Golden result on the quantised inputs.
    pub golden: MtResult,
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
    /// A property failure: a decisive case whose hit/miss differs from the golden (or from the
    /// bound's exact decision), or a shared hit whose t error exceeds the bound.
    pub fn violation(&self) -> Option<String> {
        if !self.decisive {
            return None;
        }
        if self.hit != self.golden.hit || self.golden.hit != self.exact_hit {
            return Some(format!("hit/miss: model {} golden {} exact {}", self.hit, self.golden.hit, self.exact_hit));
        }
        if self.hit && self.t_error() > self.t_err + self.golden.t.abs() * 1e-12 {
            return Some(format!("t error {:e} exceeds bound {:e}", self.t_error(), self.t_err));
        }
        None
    }
    /// |t_model − t_golden|.
    pub fn t_error(&self) -> f64 {
        (self.t - self.golden.t).abs()
    }
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

/// Runs the model on one test and judges it.
pub fn judge<F: Format>(rti: &Rti<F>, ray: &Ray64, tri: &Tri64) -> Judged {
    let f = &rti.fmt;
    let out = rti.test(&rti.ray(ray.o, ray.d, ray.tmin, ray.tmax), &rti.tri(tri.v));
    let (rq, tq) = quantise(rti, ray, tri);
    let golden = golden::intersect(&rq, &tq, faces(rti));
    let b = RtiBound::new(f.error_model(), f.div_mode(), rq.o, rq.d, tq.v);
    let v = b.verdict(rti.cull, f.to_f64(rti.det_thr), rq.tmin, rq.tmax);
    Judged {
        hit: out.hit,
        t: f.to_f64(out.t),
        golden,
        decisive: v.decisive,
        exact_hit: v.hit,
        t_err: b.t_err,
        ulp: f.ulp(golden.t),
    }
}
