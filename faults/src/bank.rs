//! The fault bank: one [`Spec`] per hardware bug, each a one-line change to one site of a
//! stage model (the site names are the stage table's signal names, see
//! `datapath::rti::Rti::trace_faulty`).

/// A rounding mode other than the datapath's nearest-even.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// Toward zero (truncation).
    TowardZero,
    /// Toward +∞.
    TowardPositive,
    /// Toward −∞.
    TowardNegative,
    /// To nearest, ties away from zero (a round-half-up adder on magnitudes).
    NearestTiesToAway,
}

/// How a fault changes its site.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// The arithmetic or compare site's operands are swapped (a − b computed as b − a,
    /// a < b as b < a).
    Swap,
    /// The arithmetic site's second operand is replaced by its first (a wrong mux select).
    FirstTwice,
    /// The arithmetic site rounds in another mode (same operands, same rules otherwise).
    Round(Mode),
    /// The adder site takes the product of `product`'s operands unrounded: the adder and the
    /// multiplier that feeds it (its first operand when `first`, else its second) fused into
    /// one multiply-add, rounded once.
    Fused {
        /// The multiplier site whose rounding is lost.
        product: &'static str,
        /// The product is the adder's first operand.
        first: bool,
    },
    /// The arithmetic site flushes a subnormal result to zero of its sign (FTZ in one stage).
    Flush,
    /// The compare site is strict where it should not be (a ≤ b computed as a < b).
    Strict,
    /// The compare site is loose where it should be strict (a < b computed as a ≤ b).
    Loose,
    /// The compare or logic site's output is stuck at this value (a check left out, a
    /// select tied off).
    Stuck(bool),
    /// The compare site's tie goes the other way (a < b computed as a ≤ b, a ≤ b as a < b):
    /// a compare-select that takes the new operand on a tie where it should keep the held one,
    /// or the reverse.
    TieSwap,
    /// The compare site is true when an operand is NaN (the compare written as the negation
    /// of the opposite compare, `!(b <= a)` for `a < b`): the NaN handling of a select inverted.
    Unordered,
    /// The grid-step site passes its input through (the widening stage bypassed).
    Bypass,
    /// The arithmetic site follows the other NaN rule: a NaN result is the first NaN operand,
    /// quieted, in a canonical-NaN format (propagation where the contract says canonical), or
    /// the canonical NaN in a propagating one.
    NanRule,
    /// The limit site counts to one more than it should (`==` where `<` was meant, or a
    /// counter compared before its increment).
    OffByOne,
    /// The grid-step site adds (nextUp) or subtracts (nextDown) one on the encoding as an
    /// unsigned integer, wrapping in the format's width: right for positive numbers, the wrong
    /// way for negative ones, ±0 and ±∞ step into the other sign or a NaN.
    TwosStep,
}

/// When a fault changes no output, and why.
#[derive(Clone, Copy, Debug)]
pub enum Benign {
    /// On every input of every configuration of its unit.
    Always(&'static str),
    /// On every input of the named slab variants (the argument holds there only).
    InVariants(&'static [&'static str], &'static str),
}

impl Benign {
    /// The argument, when the fault is benign in the configuration of slab variant `variant`
    /// (`None` for units without variants).
    pub fn applies(&self, variant: Option<&str>) -> Option<&'static str> {
        match *self {
            Benign::Always(why) => Some(why),
            Benign::InVariants(v, why) => variant.filter(|x| v.contains(x)).map(|_| why),
        }
    }
}

/// One fault of the bank.
#[derive(Clone, Copy, Debug)]
pub struct Spec {
    /// Unique name: `unit.site.kind`.
    pub name: &'static str,
    /// The unit it is injected into (`rti`, `slab`, `capture`, `traverse`, `op`).
    pub unit: &'static str,
    /// The site it changes (a signal name of the unit's stage table).
    pub site: &'static str,
    /// The change.
    pub kind: Kind,
    /// The RTL bug it stands for, in one line.
    pub what: &'static str,
    /// When the unit's outputs (rti: valid, hit, t, u, v; slab: hit, t_near, t_far) are
    /// identical to the fault-free unit's on every input: where, and the argument. Such a
    /// fault may still show on a stage probe.
    pub benign: Option<Benign>,
}

const fn rti(name: &'static str, site: &'static str, kind: Kind, what: &'static str) -> Spec {
    Spec { name, unit: "rti", site, kind, what, benign: None }
}

const fn slab(name: &'static str, site: &'static str, kind: Kind, what: &'static str) -> Spec {
    Spec { name, unit: "slab", site, kind, what, benign: None }
}

const fn capture(name: &'static str, site: &'static str, kind: Kind, what: &'static str) -> Spec {
    Spec { name, unit: "capture", site, kind, what, benign: None }
}

const fn traverse(name: &'static str, site: &'static str, kind: Kind, what: &'static str) -> Spec {
    Spec { name, unit: "traverse", site, kind, what, benign: None }
}

const fn op(name: &'static str, site: &'static str, kind: Kind, what: &'static str) -> Spec {
    Spec { name, unit: "op", site, kind, what, benign: None }
}

const fn slab_benign(name: &'static str, site: &'static str, kind: Kind, what: &'static str, b: Benign) -> Spec {
    Spec { name, unit: "slab", site, kind, what, benign: Some(b) }
}

/// Where a slab fault that only flips the sign of a zero t_near / t_far is benign: the
/// conservative variant's widening maps +0 and −0 to the same value (4 steps toward −∞ from
/// either zero is the 4th negative value, toward +∞ the 4th positive one), and the decision
/// compares the widened values.
const ZERO_SIGN_WIDENED: Benign = Benign::InVariants(
    &["conservative"],
    "the fault changes only the sign of a zero: a tie of two numbers is a tie of equal encodings except +0 against -0; t_near and t_far are then widened by 4 grid steps, and 4 steps from +0 or from -0 give the same value, so hit, t_near and t_far are unchanged",
);

/// Every fault of the bank.
pub const BANK: &[Spec] = &[
    rti("rti.e1x.swap", "e1x", Kind::Swap, "stage 1: e1.x wired as v0.x − v1.x (operand order of one subtractor)"),
    rti("rti.e2z.swap", "e2z", Kind::Swap, "stage 1: e2.z wired as v0.z − v2.z"),
    rti("rti.sy.swap", "sy", Kind::Swap, "stage 1: s.y wired as v0.y − o.y"),
    rti("rti.px.swap", "px", Kind::Swap, "stage 3: p.x = pxb − pxa (one cross-product component negated)"),
    rti("rti.qz.swap", "qz", Kind::Swap, "stage 3: q.z = qzb − qza"),
    rti(
        "rti.pya.first",
        "pya",
        Kind::FirstTwice,
        "stage 2: pya = d.z × d.z (the multiplier's second operand mux selects the first)",
    ),
    rti("rti.uv.first", "uv", Kind::FirstTwice, "stage 7: u + v computed as u + u"),
    rti("rti.pxa.rz", "pxa", Kind::Round(Mode::TowardZero), "stage 2: multiplier pxa truncates (rounds toward zero)"),
    rti("rti.qyb.rz", "qyb", Kind::Round(Mode::TowardZero), "stage 2: multiplier qyb truncates"),
    rti(
        "rti.detx.rna",
        "detx",
        Kind::Round(Mode::NearestTiesToAway),
        "stage 4: multiplier detx rounds half away from zero",
    ),
    rti(
        "rti.upy.rna",
        "upy",
        Kind::Round(Mode::NearestTiesToAway),
        "stage 4: multiplier upy rounds half away from zero",
    ),
    rti(
        "rti.e1y.rna",
        "e1y",
        Kind::Round(Mode::NearestTiesToAway),
        "stage 1: subtractor e1y rounds half away from zero",
    ),
    rti("rti.tp.rup", "tp", Kind::Round(Mode::TowardPositive), "stage 6: adder t' rounds toward +∞"),
    rti("rti.up_xy.rdn", "up_xy", Kind::Round(Mode::TowardNegative), "stage 5: adder up_xy rounds toward −∞"),
    rti(
        "rti.t.rz",
        "t",
        Kind::Round(Mode::TowardZero),
        "output t: the final multiplier (divider under :divide) truncates",
    ),
    rti(
        "rti.inv_det.rz",
        "inv_det",
        Kind::Round(Mode::TowardZero),
        "reciprocal 1/det truncates (reciprocal-multiply datapaths)",
    ),
    rti(
        "rti.det_xy.fma",
        "det_xy",
        Kind::Fused { product: "detx", first: true },
        "stages 4-5 fused: det_xy = fma(e1.x, p.x, dety) (detx never rounded)",
    ),
    rti(
        "rti.vp.fma",
        "vp",
        Kind::Fused { product: "vpz", first: false },
        "stages 4-6 fused: v' = fma(d.z, q.z, vp_xy) (vpz never rounded)",
    ),
    rti(
        "rti.t.ftz",
        "t",
        Kind::Flush,
        "output t flushes a subnormal result to zero (an FTZ multiplier or divider in one stage)",
    ),
    rti("rti.qx.ftz", "qx", Kind::Flush, "stage 3: subtractor q.x flushes a subnormal result to zero"),
    rti("rti.u_ok.strict", "u_ok", Kind::Strict, "stage 7: u' ≥ 0 tested as u' > 0 (an edge hit is lost)"),
    rti("rti.v_ok.strict", "v_ok", Kind::Strict, "stage 7: v' ≥ 0 tested as v' > 0"),
    rti("rti.uv_ok.strict", "uv_ok", Kind::Strict, "stage 7: u' + v' ≤ det tested as u' + v' < det"),
    rti("rti.t_ok.strict", "t_ok", Kind::Strict, "stage 7: t' ≥ 0 tested as t' > 0"),
    rti("rti.tmin_ok.strict", "tmin_ok", Kind::Strict, "t interval: tmin ≤ t tested as tmin < t"),
    rti("rti.tmax_ok.strict", "tmax_ok", Kind::Strict, "t interval: t ≤ tmax tested as t < tmax"),
    rti("rti.det_ok.loose", "det_ok", Kind::Loose, "stage 7: threshold < |det| tested as threshold ≤ |det|"),
    Spec {
        name: "rti.pos.loose",
        unit: "rti",
        site: "pos",
        kind: Kind::Loose,
        what: "stage 7: the det sign select tests 0 ≤ det instead of 0 < det",
        benign: Some(Benign::Always(
            "the selects differ only when det is ±0, and then det_ok is false (the threshold is ≥ 0, \
             so neither thr < |±0| nor thr < ±0 holds), valid and hit are false whatever the selects \
             give, and t, u, v do not read them; the u_ok, v_ok, uv_ok, t_ok probes do show it",
        )),
    },
    Spec {
        name: "rti.e1x.nan",
        unit: "rti",
        site: "e1x",
        kind: Kind::NanRule,
        what: "stage 1: subtractor e1.x follows the other NaN rule (a payload propagated where the contract says canonical, or the reverse)",
        benign: Some(Benign::Always(
            "the fault changes only which NaN e1.x is, and a NaN e1.x makes detx, det_xy and det NaN, so det_ok is false (thr < |NaN| and thr < NaN are false), valid and hit are 0, and t, u, v are compared only where valid is 1 (care_when); the e1x stage probe, compared always, shows it",
        )),
    },
    rti("rti.t_ok.stuck1", "t_ok", Kind::Stuck(true), "stage 7: the t' ≥ 0 check left out (hits behind the origin)"),
    rti("rti.uv_ok.stuck1", "uv_ok", Kind::Stuck(true), "stage 7: the u' + v' ≤ det check left out"),
    rti("rti.det_ok.stuck1", "det_ok", Kind::Stuck(true), "stage 7: the det threshold check left out"),
    rti("rti.tmax_ok.stuck1", "tmax_ok", Kind::Stuck(true), "t interval: the tmax compare tied off"),
    rti("rti.tmin_ok.stuck1", "tmin_ok", Kind::Stuck(true), "t interval: the tmin compare tied off"),
    slab("slab.lox.swap", "lox", Kind::Swap, "stage 1: lo.x wired as o.x − min.x (operand order of one subtractor)"),
    slab("slab.hiz.swap", "hiz", Kind::Swap, "stage 1: hi.z wired as o.z − max.z"),
    slab("slab.hiy.first", "hiy", Kind::FirstTwice, "stage 1: hi.y = max.y − max.y (the second operand mux selects the first)"),
    slab("slab.thix.first", "thix", Kind::FirstTwice, "stage 2: t_hi.x = hi.x × hi.x instead of hi.x × inv_d.x"),
    slab("slab.tloy.rz", "tloy", Kind::Round(Mode::TowardZero), "stage 2: multiplier t_lo.y truncates (rounds toward zero)"),
    slab("slab.thiz.rup", "thiz", Kind::Round(Mode::TowardPositive), "stage 2: multiplier t_hi.z rounds toward +∞"),
    slab("slab.loz.rdn", "loz", Kind::Round(Mode::TowardNegative), "stage 1: subtractor lo.z rounds toward −∞"),
    slab("slab.hix.rna", "hix", Kind::Round(Mode::NearestTiesToAway), "stage 1: subtractor hi.x rounds half away from zero"),
    slab("slab.tlox.rna", "tlox", Kind::Round(Mode::NearestTiesToAway), "stage 2: multiplier t_lo.x rounds half away from zero"),
    slab("slab.inv_dx.rz", "inv_dx", Kind::Round(Mode::TowardZero), "stage 0: reciprocal 1/d.x truncates"),
    slab_benign(
        "slab.inv_dz.rna",
        "inv_dz",
        Kind::Round(Mode::NearestTiesToAway),
        "stage 0: reciprocal 1/d.z rounds half away from zero",
        Benign::Always(
            "1/d has a finite binary expansion only when |d| is a power of two (an odd significand factor m > 1 makes 1/m periodic), and then 1/d = ±2^k is representable, overflows (both modes give ±inf) or would be half the least subnormal, which needs |d| = 2^(emax+M) > max (binary32, binary16, bfloat16): 1/d is never exactly halfway, and ties-away agrees with ties-to-even; zeros, infinities and NaN give the same special results",
        ),
    ),
    slab_benign(
        "slab.inv_dy.ftz",
        "inv_dy",
        Kind::Flush,
        "stage 0: reciprocal 1/d.y flushes a subnormal result to zero (a huge d)",
        Benign::InVariants(
            &["conservative"],
            "the guard turns a reciprocal of a finite nonzero d that is subnormal or zero into the canonical NaN alike, so flushing a subnormal 1/d first changes nothing",
        ),
    ),
    slab("slab.loy.ftz", "loy", Kind::Flush, "stage 1: subtractor lo.y flushes a subnormal difference to zero"),
    slab("slab.tloz.ftz", "tloz", Kind::Flush, "stage 2: multiplier t_lo.z flushes a subnormal product to zero"),
    slab("slab.negx.stuck0", "negx", Kind::Stuck(false), "stage 3: the x near/far select ignores the sign of 1/d.x (select tied to 0)"),
    slab("slab.negz.stuck1", "negz", Kind::Stuck(true), "stage 3: the z near/far select always swaps (select tied to 1)"),
    slab_benign(
        "slab.tn_x.tie",
        "tn_x",
        Kind::TieSwap,
        "stage 4: the first near compare-select (against tmin) breaks a tie the other way",
        ZERO_SIGN_WIDENED,
    ),
    slab_benign(
        "slab.tf_xyz.tie",
        "tf_xyz",
        Kind::TieSwap,
        "stage 4: the last far compare-select breaks a tie the other way",
        ZERO_SIGN_WIDENED,
    ),
    slab("slab.tn_xy.nan", "tn_xy", Kind::Unordered, "stage 4: the y near compare-select's NaN handling inverted (the compare written as the negation of the opposite one)"),
    slab("slab.tf_x.nan", "tf_x", Kind::Unordered, "stage 4: the x far compare-select's NaN handling inverted"),
    slab("slab.hit.strict", "hit", Kind::Strict, "stage 6: t_near ≤ t_far tested as t_near < t_far (touching and zero-extent boxes missed)"),
    slab("slab.guard_sub.stuck0", "guard_sub", Kind::Stuck(false), "conservative guard: the overflowed-subtract check left out"),
    slab("slab.guard_recip.stuck0", "guard_recip", Kind::Stuck(false), "conservative guard: the non-normal-reciprocal check left out"),
    slab("slab.t_near.bypass", "t_near", Kind::Bypass, "stage 5: t_near's widening bypassed (its mux select tied)"),
    slab("slab.t_far.twos", "t_far", Kind::TwosStep, "stage 5: t_far's nextUp adds one to the encoding (wrong way for negative values)"),
    slab_benign(
        "slab.pdx.loose",
        "pdx",
        Kind::Loose,
        "embree: |d.x| < δ tested as |d.x| ≤ δ",
        Benign::Always(
            "the compare differs only at |d.x| = δ, where the replacement (+δ, or −δ = 0 − δ for a negative d.x) is d.x itself, bit for bit",
        ),
    ),
    slab("slab.pdy_sign.stuck0", "pdy_sign", Kind::Stuck(false), "embree: the replacement's sign select tied to 0 (a small negative or −0 d.y becomes +δ)"),
    capture("capture.take.tie", "take", Kind::TieSwap, "min-capture: equal t decided by the other tie rule (t < best for t ≤ best, or the reverse)"),
    capture("capture.take.swap", "take", Kind::Swap, "min-capture: the compare's operands swapped (the farthest hit kept)"),
    capture("capture.take.stuck1", "take", Kind::Stuck(true), "min-capture: the compare left out (every hit taken: the last hit wins)"),
    capture("capture.take.stuck0", "take", Kind::Stuck(false), "min-capture: the compare tied to 0 (the first hit kept)"),
    capture("capture.hit.stuck1", "hit", Kind::Stuck(true), "min-capture: the result's hit bit not gating the unit (a nearer miss is taken)"),
    capture("capture.held.stuck1", "held", Kind::Stuck(true), "min-capture: the held-hit bit tied to 1 (the first hit compared against the reset t = +0)"),
    traverse("traverse.near.tie", "near", Kind::TieSwap, "traversal: equal entry t sends the ray to the right child first (t_r ≤ t_l for t_r < t_l)"),
    traverse("traverse.near.swap", "near", Kind::Swap, "traversal: the nearer/farther select inverted (the farther child first)"),
    traverse("traverse.mark_split.stuck0", "mark_split", Kind::Stuck(false), "traversal: a level where both children hit is not set to 10 (the farther child never visited)"),
    traverse("traverse.mark_pass.stuck0", "mark_pass", Kind::Stuck(false), "traversal: a level where one child hits is not set to 01 (its history stays 00)"),
    traverse("traverse.resume.stuck0", "resume", Kind::Stuck(false), "traversal: the restart resumes at the shallowest 10 instead of the deepest (priority encoder reversed)"),
    traverse("traverse.reset_deeper.stuck0", "reset_deeper", Kind::Stuck(false), "traversal: after 10 → 11 the deeper levels keep their history (no reset to 00)"),
    traverse("traverse.more.stuck0", "more", Kind::Stuck(false), "traversal: the restart check tied to 0 (one pass only)"),
    traverse("traverse.n_limit.plus1", "n_limit", Kind::OffByOne, "traversal: the N-leaf limit counts one leaf too many"),
    op("op.add.rz", "add", Kind::Round(Mode::TowardZero), "adder truncates (rounds toward zero)"),
    op("op.add.rna", "add", Kind::Round(Mode::NearestTiesToAway), "adder rounds half away from zero"),
    op("op.sub.rdn", "sub", Kind::Round(Mode::TowardNegative), "subtractor rounds toward −∞"),
    op("op.sub.swap", "sub", Kind::Swap, "subtractor computes b − a"),
    op("op.mul.rup", "mul", Kind::Round(Mode::TowardPositive), "multiplier rounds toward +∞"),
    op("op.mul.rna", "mul", Kind::Round(Mode::NearestTiesToAway), "multiplier rounds half away from zero"),
    op("op.mul.ftz", "mul", Kind::Flush, "multiplier flushes a subnormal product to zero"),
    op("op.add.ftz", "add", Kind::Flush, "adder flushes a subnormal sum to zero"),
    op("op.div.rz", "div", Kind::Round(Mode::TowardZero), "divider (the reciprocal unit of a ⊗ (1 ⊘ b) datapaths) truncates"),
    op("op.add.nan", "add", Kind::NanRule, "adder follows the other NaN rule (propagates a payload where the contract says canonical, or the reverse)"),
    op("op.mul.nan", "mul", Kind::NanRule, "multiplier follows the other NaN rule"),
    op("op.lt.loose", "lt", Kind::Loose, "a < b computed as a ≤ b"),
    op("op.le.strict", "le", Kind::Strict, "a ≤ b computed as a < b"),
    op("op.lt.nan", "lt", Kind::Unordered, "a < b true when an operand is NaN"),
];

/// The fault named `name`.
pub fn by_name(name: &str) -> Option<&'static Spec> {
    BANK.iter().find(|s| s.name == name)
}
