//! The bounding-volume intersection (BVI) pipeline: the slab test in 6 subtracts and 6
//! multiplies per ray–box test, then the compare unit.
//!
//! Per ray, once (stage 0): `inv_d = 1 ⊘ d` (the format's division), after the direction
//! preparation of the variant ([`DirPrep`]). Per box: stage 1 subtracts the origin from both
//! planes of each axis, stage 2 multiplies by `inv_d`, stage 3 picks near/far per axis by the
//! sign bit of `inv_d`, stage 4 (compare unit) accumulates `t_near` from `tmin` and `t_far` from
//! `tmax` with the variant's comparator ([`SlabNan`]), stage 5 optionally widens the interval by
//! `widen_ulps` grid steps (the conservative variants), stage 6 decides `hit = t_near <= t_far`.
//! `t_near` (widened) is the entry distance that orders children.
//!
//! Comparators are written out: no `min`/`max` (which treat NaN and ±0 in ways hardware does
//! not). With number inputs a NaN arises from `0 × ∞` (the origin exactly on a slab plane of
//! an axis whose direction component is ±0, so `inv_d = ±∞`) and, in the `conservative`
//! variant, from the guard (below); a NaN input (origin, direction, box, t interval) gives NaN
//! signals too, and a NaN direction component can still hit (its axis is ignored).
//!
//! # Why `conservative` never misses (IEEE formats with gradual underflow)
//! Write `t = (b − o)/d` for the exact plane distance of finite inputs and
//! `t_c = (b ⊖ o) ⊗ (1 ⊘ d)` for the computed one (`⊗ (1 ⊘ d)` is one reciprocal and one
//! multiply in both division modes: `1 ⊗ r = r`). Each rounding to nearest has relative error
//! at most `u = 2^-(M+1)` while its result is a normal number, a subtract is exact when its
//! result is subnormal, and a multiply whose result is subnormal adds at most half a
//! subnormal step `s`. The **guard** (stage 0 and stage 1) removes the two cases where that
//! model fails: a reciprocal of a finite nonzero `d` that is not a normal number (`1 ⊘ d`
//! overflowed to ±∞, or is subnormal or zero: its error is absolute, not relative) and a
//! subtract of finite operands that overflowed to ±∞. Either becomes the canonical NaN, the
//! products it feeds are NaN, and the `Ignore` comparator drops them: that axis (reciprocal) or
//! that plane (subtract) imposes no constraint, which only widens the interval. Every other
//! finite product obeys `|t_c − t| ≤ γ₃|t| + s/2` with `γ₃ = 3u/(1 − 3u)`, hence
//! `|t_c − t| ≤ 3u/(1 − 6u)·|t_c| + s/2`. For a normal `t_c` the smallest of the 4 steps
//! toward −∞ is at least `u·|t_c|` (the steps below a power of two `2^e` are `2^(e−M−1) = u·2^e`,
//! half those above it), so 4 steps cover `4u|t_c| ≥ 3u/(1 − 6u)·|t_c|` whenever `u ≤ 1/24`:
//! the variant needs at least [`MIN_MAN_BITS`] = 4 fraction bits (`u ≤ 1/32`) and refuses
//! narrower formats (e5m2, e4m3, …). For a subnormal `t_c` the steps are `s`, `|t|` is below
//! about the least normal `2^M·s`, and the error is below `3u/(1 − 6u)·2^M·s + s/2 < 2.4 s`. A product
//! that overflowed to ±∞ from finite factors has `|t|` above the largest finite value, so one
//! step toward zero (±∞ → ±max) is already on the right side. Widening the accumulated
//! `t_near` by 4 steps toward −∞ (IEEE nextDown) and `t_far` by 4 toward +∞ (nextUp) widens
//! every candidate by at least its error (the steps are monotone), so the widened interval
//! contains the exact one: an exact hit is never missed. A `d = ±0` axis is exact
//! (`1 ⊘ ±0 = ±∞`, and `b ⊖ o` has the sign of `b − o` and is zero only when `b = o`, a NaN
//! product the comparator drops: the closed box's face). Under flush-to-zero a subnormal
//! difference becomes zero and the argument fails, and fixed point has no ∞ to overflow to:
//! `conservative` refuses both (use `directed`).

use crate::fault::{Cmp, Fault, NoFault};
use crate::format::Format;
use crate::probe::{NoProbe, Probe};
use crate::stage::{Op, Rule, SigDef};
use crate::{record, record_flags};

/// What the compare unit does with a NaN slab distance.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SlabNan {
    /// pbrt-v4's form `t = (x > t) ? x : t` (near) and `t = (x < t) ? x : t` (far): a NaN axis
    /// value loses every compare and is ignored. With a ±0 direction component and the origin
    /// on that slab's plane, the axis imposes no constraint — exactly right for a closed box.
    Ignore,
    /// The form `t = (x <= t) ? t : x` (near) and `t = (t <= x) ? t : x` (far): the compare is
    /// false for a NaN on either side and the operand is taken. A NaN axis value replaces the
    /// accumulator, and the next axis's value replaces a NaN accumulator: a NaN from the x or y
    /// axis is dropped (like `Ignore`), a NaN from the z axis (last in the chain) reaches the
    /// decision and the box is missed. The naive chain's asymmetry, modelled as hardware has it.
    TakeOnFalse,
}

/// How the per-ray reciprocal direction is formed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum DirPrep {
    /// `inv_d = 1 ⊘ d`; a ±0 component gives ±∞.
    Plain,
    /// Embree's robust form: a component with |d| < δ is replaced by ±δ (sign of d kept, +δ for
    /// +0, −δ for −0) before `1 ⊘ d`, δ = 2 ⊘ max-finite rounded up (so 1/δ stays finite);
    /// no ∞ and no NaN reach the datapath.
    Embree,
}

/// Options of a slab unit.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct SlabConfig {
    /// NaN comparator convention.
    pub nan: SlabNan,
    /// Direction preparation.
    pub prep: DirPrep,
    /// Steps of the format's grid `t_near` is moved down and `t_far` up before the decision
    /// (0 = plain; negative narrows). 4 makes a float datapath with IEEE subnormals conservative
    /// (see [`CONSERVATIVE_ULPS`]); −4 makes it never report a hit the exact test misses.
    pub widen_ulps: i32,
    /// Directed interval arithmetic instead of round-to-nearest (see [`Slab::trace_directed`]):
    /// conservative in every format, fixed point and flush-to-zero included.
    pub directed: bool,
    /// The conservative variant's guard (IEEE float formats only; no effect in fixed point): a
    /// reciprocal `1 ⊘ d` of a finite nonzero `d` that is not a normal number, and a stage-1
    /// subtract of finite operands that overflowed to ±∞, become the canonical NaN (see the
    /// module docs).
    pub guard: bool,
}

/// Widening that, with the guard, makes the float slab test conservative (the proof is in the
/// module docs): every guarded computed distance is within 4 grid steps of the exact one.
pub const CONSERVATIVE_ULPS: i32 = 4;

/// The fewest fraction bits the 4-step proof holds for (`u = 2^-(M+1) <= 1/32`).
pub const MIN_MAN_BITS: u32 = 4;

/// The stage table of the round-to-nearest slab datapath (variants plain, conservative,
/// take-on-false, embree), in the order the probe reports the signals. Stage 0 runs once per
/// ray; `sel*` rows are the compare unit's compare-selects; `step*` rows the widening.
pub const SLAB_TABLE: [SigDef; 39] = [
    l(0, "dx", Rule::Read("in_dx"), "input read of d.x: a NaN reads as the canonical NaN (quieted, payload kept, under propagate); a subnormal as ±0 under FTZ; o, tmin, tmax are read the same way"),
    l(0, "dy", Rule::Read("in_dy"), "input read of d.y (as dx)"),
    l(0, "dz", Rule::Read("in_dz"), "input read of d.z (as dx)"),
    l(0, "pdx", Rule::Prep("dx"), "embree: |dx| < δ ? ±δ : dx; else dx"),
    l(0, "pdy", Rule::Prep("dy"), "likewise"),
    l(0, "pdz", Rule::Prep("dz"), "likewise"),
    g(0, "inv_dx", Op::Div, "one", "pdx", Rule::ArithGuardRecip),
    g(0, "inv_dy", Op::Div, "one", "pdy", Rule::ArithGuardRecip),
    g(0, "inv_dz", Op::Div, "one", "pdz", Rule::ArithGuardRecip),
    // (guard, conservative only: 1 ⊘ pd of a finite nonzero pd that is not a normal number
    // is the canonical NaN; a subtract of finite operands that gives ±∞ is the canonical NaN)
    g(1, "lox", Op::Sub, "minx", "ox", Rule::ArithGuardSub),
    g(1, "hix", Op::Sub, "maxx", "ox", Rule::ArithGuardSub),
    g(1, "loy", Op::Sub, "miny", "oy", Rule::ArithGuardSub),
    g(1, "hiy", Op::Sub, "maxy", "oy", Rule::ArithGuardSub),
    g(1, "loz", Op::Sub, "minz", "oz", Rule::ArithGuardSub),
    g(1, "hiz", Op::Sub, "maxz", "oz", Rule::ArithGuardSub),
    s(2, "tlox", Op::Mul, "lox", "inv_dx"),
    s(2, "thix", Op::Mul, "hix", "inv_dx"),
    s(2, "tloy", Op::Mul, "loy", "inv_dy"),
    s(2, "thiy", Op::Mul, "hiy", "inv_dy"),
    s(2, "tloz", Op::Mul, "loz", "inv_dz"),
    s(2, "thiz", Op::Mul, "hiz", "inv_dz"),
    l(3, "negx", Rule::SignBit("inv_dx"), "sign bit of inv_dx"),
    l(3, "negy", Rule::SignBit("inv_dy"), "sign bit of inv_dy"),
    l(3, "negz", Rule::SignBit("inv_dz"), "sign bit of inv_dz"),
    l(3, "nearx", Rule::Mux("negx", "thix", "tlox"), "negx ? thix : tlox"),
    l(3, "farx", Rule::Mux("negx", "tlox", "thix"), "negx ? tlox : thix"),
    l(3, "neary", Rule::Mux("negy", "thiy", "tloy"), "negy ? thiy : tloy"),
    l(3, "fary", Rule::Mux("negy", "tloy", "thiy"), "negy ? tloy : thiy"),
    l(3, "nearz", Rule::Mux("negz", "thiz", "tloz"), "negz ? thiz : tloz"),
    l(3, "farz", Rule::Mux("negz", "tloz", "thiz"), "negz ? tloz : thiz"),
    l(4, "tn_x", Rule::SelNear("tmin", "nearx"), "selnear(tmin, nearx)"),
    l(4, "tn_xy", Rule::SelNear("tn_x", "neary"), "selnear(tn_x, neary)"),
    l(4, "tn_xyz", Rule::SelNear("tn_xy", "nearz"), "selnear(tn_xy, nearz)"),
    l(4, "tf_x", Rule::SelFar("tmax", "farx"), "selfar(tmax, farx)"),
    l(4, "tf_xy", Rule::SelFar("tf_x", "fary"), "selfar(tf_x, fary)"),
    l(4, "tf_xyz", Rule::SelFar("tf_xy", "farz"), "selfar(tf_xy, farz)"),
    l(5, "t_near", Rule::Widen("tn_xyz", false), "tn_xyz stepped widen_ulps times toward −∞ (IEEE nextDown; toward +∞, nextUp, if widen_ulps < 0)"),
    l(5, "t_far", Rule::Widen("tf_xyz", true), "tf_xyz stepped widen_ulps times toward +∞ (IEEE nextUp; toward −∞, nextDown, if widen_ulps < 0)"),
    l(6, "hit", Rule::Le("t_near", "t_far"), "t_near <= t_far"),
];

/// Input names of the slab unit, in the vector files' order: origin, direction, t interval,
/// box min and max corners.
pub const SLAB_INPUTS: [&str; 14] =
    ["ox", "oy", "oz", "dx", "dy", "dz", "tmin", "tmax", "minx", "miny", "minz", "maxx", "maxy", "maxz"];

/// The rules of the grid steps of stage 5 (and of the directed variant), in words: what
/// nextUp / nextDown return at the special values.
pub const STEP_RULES: &str = "nextUp(x) is the least format value greater than x and nextDown(x) the greatest value less than x (IEEE 754 nextUp/nextDown: toward +inf and toward -inf, whatever the sign of x); nextUp(+inf) = +inf, nextDown(-inf) = -inf, nextUp(-inf) = -max, nextDown(+inf) = +max; nextUp(+0) = nextUp(-0) = the least positive value (the smallest subnormal, or under FTZ the smallest normal) and nextDown(±0) its negative; a NaN stays the same NaN (bits unchanged); under FTZ the subnormals are skipped (nextDown of the smallest positive normal is +0, nextUp of its negative is -0); fixed point: plus or minus one step, the most positive and most negative values unchanged";

const fn s(stage: u8, name: &'static str, op: Op, a: &'static str, b: &'static str) -> SigDef {
    SigDef { stage, name, op, a, b, note: "", rule: Rule::Arith }
}
const fn g(stage: u8, name: &'static str, op: Op, a: &'static str, b: &'static str, rule: Rule) -> SigDef {
    SigDef { stage, name, op, a, b, note: "", rule }
}
const fn l(stage: u8, name: &'static str, rule: Rule, note: &'static str) -> SigDef {
    SigDef { stage, name, op: Op::Logic, a: "", b: "", note, rule }
}

/// The named slab variants: `plain` (Ignore, Plain, 0), `conservative` (Ignore, Plain, +4),
/// `directed` (interval arithmetic), `take-on-false` (TakeOnFalse, Plain, 0), `embree` (Ignore, Embree, 0).
pub const SLAB_VARIANTS: [&str; 5] = ["plain", "conservative", "directed", "take-on-false", "embree"];

impl SlabConfig {
    /// Whether this variant promises zero false misses in format `f`: the directed variant in
    /// every format that does not wrap; the guarded ulp widening by at least
    /// [`CONSERVATIVE_ULPS`] in float formats with IEEE subnormals.
    pub fn is_conservative<F: Format>(&self, f: &F) -> bool {
        // the widening proof needs u <= 1/32: at least 4 fraction bits
        let float = matches!(f.kind(), crate::format::FormatKind::Float(l) if l.man_bits >= MIN_MAN_BITS);
        (self.directed && !f.wraps())
            || (!self.directed
                && self.guard
                && self.nan == SlabNan::Ignore
                && self.prep == DirPrep::Plain
                && self.widen_ulps >= CONSERVATIVE_ULPS
                && float
                && !f.flushes())
    }

    /// Whether this variant promises conservativeness at all (it is `directed` or guarded):
    /// such a variant must keep its promise in every format it accepts.
    pub fn promises_conservative(&self) -> bool {
        self.directed || self.guard
    }

    /// The variant for format `f`, or a clear refusal when it promises conservativeness that
    /// `f` cannot give (`conservative` in fixed point or under flush-to-zero, `directed` in a
    /// wrapping fixed-point format).
    pub fn for_format<F: Format>(self, name: &str, f: &F) -> Result<Self, String> {
        if self.promises_conservative() && !self.is_conservative(f) {
            let why = if self.directed {
                "wrapping fixed point has no bound that survives a wrap-around (use :saturate)"
            } else if matches!(f.kind(), crate::format::FormatKind::Float(l) if l.man_bits < MIN_MAN_BITS) {
                "with fewer than 4 fraction bits, 4 grid steps do not bound three roundings (use directed)"
            } else if f.flushes() {
                "under flush-to-zero a subnormal difference becomes 0 and 4 grid steps no longer bound the error (use directed)"
            } else {
                "fixed point has no infinity for an overflow to reach (use directed)"
            };
            return Err(format!("the {name} slab variant is not conservative in {}: {why}", f.name()));
        }
        Ok(self)
    }

    /// The named variants that format `f` accepts (see [`SlabConfig::for_format`]).
    pub fn variants_for<F: Format>(f: &F) -> Vec<&'static str> {
        SLAB_VARIANTS.iter().copied().filter(|v| SlabConfig::named_for(v, f).is_ok()).collect()
    }

    /// A named variant for format `f` ([`SlabConfig::named`], then [`SlabConfig::for_format`]).
    pub fn named_for<F: Format>(name: &str, f: &F) -> Result<Self, String> {
        Self::named(name)?.for_format(name, f)
    }

    /// A named variant (see [`SLAB_VARIANTS`]).
    pub fn named(name: &str) -> Result<Self, String> {
        let c = |nan, prep, widen_ulps| Ok(SlabConfig { nan, prep, widen_ulps, directed: false, guard: false });
        match name {
            "plain" => c(SlabNan::Ignore, DirPrep::Plain, 0),
            "directed" => Ok(SlabConfig { directed: true, ..SlabConfig::default() }),
            "conservative" => Ok(SlabConfig { guard: true, ..c(SlabNan::Ignore, DirPrep::Plain, CONSERVATIVE_ULPS)? }),
            "take-on-false" => c(SlabNan::TakeOnFalse, DirPrep::Plain, 0),
            "embree" => c(SlabNan::Ignore, DirPrep::Embree, 0),
            other => Err(format!("unknown slab variant '{other}'; variants: {}", SLAB_VARIANTS.join(", "))),
        }
    }
}

impl Default for SlabConfig {
    fn default() -> Self {
        Self { nan: SlabNan::Ignore, prep: DirPrep::Plain, widen_ulps: 0, directed: false, guard: false }
    }
}

/// A ray prepared for the slab unit: origin, reciprocal direction, t interval.
#[derive(Clone, Copy, Debug, Default)]
pub struct SlabRay<V> {
    /// Origin.
    pub o: [V; 3],
    /// 1 ⊘ d per axis (after the direction preparation).
    pub inv_d: [V; 3],
    /// Smallest accepted t.
    pub tmin: V,
    /// Largest accepted t.
    pub tmax: V,
    /// Directed variant: a lower bound of 1/d per axis.
    pub inv_lo: [V; 3],
    /// Directed variant: an upper bound of 1/d per axis.
    pub inv_hi: [V; 3],
    /// Directed variant: the axis is treated as parallel (d reads as ±0).
    pub parallel: [bool; 3],
}

/// An axis-aligned box.
#[derive(Clone, Copy, Debug, Default)]
pub struct Aabb<V> {
    /// Lower corner.
    pub min: [V; 3],
    /// Upper corner.
    pub max: [V; 3],
}

/// Output of one ray–box test.
#[derive(Clone, Copy, Debug, Default)]
pub struct SlabOut<V> {
    /// The interval is non-empty.
    pub hit: bool,
    /// Entry distance (after widening): orders children.
    pub t_near: V,
    /// Exit distance (after widening).
    pub t_far: V,
}

/// Why a box cannot be stored in a format.
#[derive(Clone, Debug, PartialEq)]
pub enum BoxError {
    /// A coordinate is NaN.
    Nan,
    /// min > max on an axis (use [`Slab::empty_box`] for empty slots).
    Inverted,
    /// A fixed-point format cannot hold the outward-rounded coordinate.
    OutOfRange(f64),
}

impl std::fmt::Display for BoxError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            BoxError::Nan => write!(f, "box coordinate is NaN"),
            BoxError::Inverted => write!(f, "box min exceeds max"),
            BoxError::OutOfRange(x) => {
                write!(f, "box coordinate {x} is outside the fixed-point range")
            }
        }
    }
}

impl std::error::Error for BoxError {}

/// A slab unit in format `F`.
#[derive(Clone, Copy, Debug)]
pub struct Slab<F: Format> {
    /// Compute format (also the box format inside the datapath).
    pub fmt: F,
    /// Variant.
    pub cfg: SlabConfig,
}

impl<F: Format> Slab<F> {
    /// A slab unit.
    pub fn new(fmt: F, cfg: SlabConfig) -> Self {
        Self { fmt, cfg }
    }

    /// Stage 0 (once per ray): quantises the ray and forms `inv_d`, reporting its signals.
    pub fn prepare_trace<P: Probe<F::V>>(
        &self,
        o: [f64; 3],
        d: [f64; 3],
        tmin: f64,
        tmax: f64,
        p: &mut P,
    ) -> SlabRay<F::V> {
        let f = &self.fmt;
        let q = |x: f64| f.from_f64(x);
        self.prepare_faulty(o.map(q), d.map(q), q(tmin), q(tmax), p, &NoFault)
    }

    /// Stage 0 on a ray of format encodings (read first by [`Format::read_input`]: a NaN as
    /// the canonical NaN, or quieted under `propagate`; FTZ subnormals as zero), with every site computed by `x` (a hardware
    /// fault; [`NoFault`] is the datapath itself). Sites: the arithmetic sites `inv_dx`,
    /// `inv_dy`, `inv_dz`; the compare sites `pdx`, `pdy`, `pdz` (Embree: `|d| < δ`); the
    /// logic sites `pdx_sign`, `pdy_sign`, `pdz_sign` (Embree: the replacement's sign, d's sign
    /// bit) and `guard_recip` (the conservative guard's reciprocal decision).
    pub fn prepare_faulty<P: Probe<F::V>, X: Fault<F>>(
        &self,
        o: [F::V; 3],
        d: [F::V; 3],
        tmin: F::V,
        tmax: F::V,
        p: &mut P,
        x: &X,
    ) -> SlabRay<F::V> {
        let f = &self.fmt;
        let one = f.one();
        // the stage-0 input read of every ray input (the stage table's dx, dy, dz;
        // Format::read_input): a NaN reads as the canonical NaN, quieted with its payload kept
        // under :propagate; under FTZ a subnormal reads as zero of its sign; numbers unchanged
        let conv = |v: F::V| f.read_input(v);
        let (o, d, tmin, tmax) = (o.map(conv), d.map(conv), conv(tmin), conv(tmax));
        let [dx, dy, dz] = d;
        let prep = |site, sign_site, v: F::V| match self.cfg.prep {
            DirPrep::Plain => v,
            DirPrep::Embree => {
                let delta = self.delta();
                if x.compare(f, site, Cmp::Lt, f.abs(v), delta) {
                    if x.flag(sign_site, f.sign_bit(v)) {
                        f.sub(f.zero(), delta)
                    } else {
                        delta
                    }
                } else {
                    v
                }
            }
        };
        let (pdx, pdy, pdz) = (prep("pdx", "pdx_sign", dx), prep("pdy", "pdy_sign", dy), prep("pdz", "pdz_sign", dz));
        let guard = self.guard_layout();
        let recip = |site, d: F::V| {
            let r = x.arith(f, site, Op::Div, one, d);
            match guard {
                Some(l) if x.flag("guard_recip", guarded_recip(l, f.to_bits(d), f.to_bits(r))) => {
                    f.from_bits(l.canonical_nan())
                }
                _ => r,
            }
        };
        let inv_dx = recip("inv_dx", pdx);
        let inv_dy = recip("inv_dy", pdy);
        let inv_dz = recip("inv_dz", pdz);
        record!(p; dx, dy, dz, pdx, pdy, pdz, inv_dx, inv_dy, inv_dz);
        let inv = [inv_dx, inv_dy, inv_dz];
        let mut ray = SlabRay { o, inv_d: inv, tmin, tmax, inv_lo: inv, inv_hi: inv, parallel: [false; 3] };
        if self.cfg.directed {
            let (top, bottom) = (f.from_f64(f64::INFINITY), f.from_f64(f64::NEG_INFINITY));
            // a fixed format without 1 (q1.F) holds no reciprocal of any of its values but
            // -1's: |1/d| >= 1 > max, so 1/d is bracketed by the saturation value
            let no_one = f.to_f64(one) != 1.0;
            let d = [dx, dy, dz];
            for a in 0..3 {
                let zero = f.le(d[a], f.zero()) && f.le(f.zero(), d[a]);
                ray.parallel[a] = zero;
                if no_one {
                    let end = if f.sign_bit(d[a]) { bottom } else { top };
                    ray.inv_lo[a] = end;
                    ray.inv_hi[a] = end;
                } else {
                    ray.inv_lo[a] = f.next_down(inv[a]);
                    ray.inv_hi[a] = f.next_up(inv[a]);
                }
            }
            let [inv_lox, inv_loy, inv_loz] = ray.inv_lo;
            let [inv_hix, inv_hiy, inv_hiz] = ray.inv_hi;
            let [parx, pary, parz] = ray.parallel;
            record!(p; inv_lox, inv_loy, inv_loz, inv_hix, inv_hiy, inv_hiz);
            record_flags!(p; parx, pary, parz);
        }
        ray
    }

    /// Stage 0 without probing.
    pub fn prepare(&self, o: [f64; 3], d: [f64; 3], tmin: f64, tmax: f64) -> SlabRay<F::V> {
        self.prepare_trace(o, d, tmin, tmax, &mut NoProbe)
    }

    /// Stage 0 on a ray already in the format's encodings, without probing ([`Self::prepare`]
    /// after its conversions).
    pub fn prepare_encoded(&self, o: [F::V; 3], d: [F::V; 3], tmin: F::V, tmax: F::V) -> SlabRay<F::V> {
        self.prepare_faulty(o, d, tmin, tmax, &mut NoProbe, &NoFault)
    }

    /// The float layout the guard checks against, when the guard is on and the format is a float.
    #[inline(always)]
    fn guard_layout(&self) -> Option<crate::format::FloatLayout> {
        match (self.cfg.guard, self.fmt.kind()) {
            (true, crate::format::FormatKind::Float(l)) => Some(l),
            _ => None,
        }
    }

    /// The stage-1 subtract at `site`, `a ⊖ b`, guarded: the canonical NaN if finite operands
    /// overflowed (the logic site `guard_sub` is the guard's decision).
    #[inline(always)]
    fn sub_guarded<X: Fault<F>>(
        &self,
        x: &X,
        g: Option<crate::format::FloatLayout>,
        site: &'static str,
        a: F::V,
        b: F::V,
    ) -> F::V {
        let f = &self.fmt;
        let r = x.arith(f, site, Op::Sub, a, b);
        match g {
            Some(l) if x.flag("guard_sub", guarded_sub(l, f.to_bits(a), f.to_bits(b), f.to_bits(r))) => {
                f.from_bits(l.canonical_nan())
            }
            _ => r,
        }
    }

    /// Embree's δ for this format: 2 ⊘ max-finite, rounded up (1/δ = max/2 stays finite).
    pub fn delta(&self) -> F::V {
        let f = &self.fmt;
        f.round_up(2.0 / f.error_model().max)
    }

    /// The compare-select of the near chain at compare site `site`: `acc` replaced by `v` when
    /// v is farther in.
    #[inline(always)]
    fn near_sel<X: Fault<F>>(&self, x: &X, site: &'static str, acc: F::V, v: F::V) -> F::V {
        let f = &self.fmt;
        match self.cfg.nan {
            SlabNan::Ignore => {
                if x.compare(f, site, Cmp::Lt, acc, v) {
                    v
                } else {
                    acc
                }
            }
            SlabNan::TakeOnFalse => {
                if x.compare(f, site, Cmp::Le, v, acc) {
                    acc
                } else {
                    v
                }
            }
        }
    }

    /// The compare-select of the far chain at compare site `site`.
    #[inline(always)]
    fn far_sel<X: Fault<F>>(&self, x: &X, site: &'static str, acc: F::V, v: F::V) -> F::V {
        let f = &self.fmt;
        match self.cfg.nan {
            SlabNan::Ignore => {
                if x.compare(f, site, Cmp::Lt, v, acc) {
                    v
                } else {
                    acc
                }
            }
            SlabNan::TakeOnFalse => {
                if x.compare(f, site, Cmp::Le, acc, v) {
                    acc
                } else {
                    v
                }
            }
        }
    }

    /// One ray–box test through every stage, reporting each signal to the probe.
    #[inline(always)]
    pub fn trace<P: Probe<F::V>>(&self, r: &SlabRay<F::V>, b: &Aabb<F::V>, p: &mut P) -> SlabOut<F::V> {
        self.trace_faulty(r, b, p, &NoFault)
    }

    /// [`Slab::trace`] with every site computed by `x` (a hardware fault; [`NoFault`] is the
    /// datapath itself). Sites are the stage table's signal names: arithmetic `lox` … `hiz`,
    /// `tlox` … `thiz`; logic `negx`, `negy`, `negz` and `guard_sub`; compare `tn_x`, `tn_xy`,
    /// `tn_xyz`, `tf_x`, `tf_xy`, `tf_xyz` (the compare-selects) and `hit`; grid steps `t_near`,
    /// `t_far` (each widening step). The directed variant has no fault sites (it ignores `x`).
    #[inline(always)]
    pub fn trace_faulty<P: Probe<F::V>, X: Fault<F>>(
        &self,
        r: &SlabRay<F::V>,
        b: &Aabb<F::V>,
        p: &mut P,
        x: &X,
    ) -> SlabOut<F::V> {
        if self.cfg.directed {
            return self.trace_directed(r, b, p);
        }
        let f = &self.fmt;
        let [ox, oy, oz] = r.o;
        let [ix, iy, iz] = r.inv_d;
        // stage 1: six subtracts (guarded in the conservative variant)
        let g = self.guard_layout();
        let lox = self.sub_guarded(x, g, "lox", b.min[0], ox);
        let hix = self.sub_guarded(x, g, "hix", b.max[0], ox);
        let loy = self.sub_guarded(x, g, "loy", b.min[1], oy);
        let hiy = self.sub_guarded(x, g, "hiy", b.max[1], oy);
        let loz = self.sub_guarded(x, g, "loz", b.min[2], oz);
        let hiz = self.sub_guarded(x, g, "hiz", b.max[2], oz);
        record!(p; lox, hix, loy, hiy, loz, hiz);
        // stage 2: six multiplies
        let mul = |s, a, b| x.arith(f, s, Op::Mul, a, b);
        let tlox = mul("tlox", lox, ix);
        let thix = mul("thix", hix, ix);
        let tloy = mul("tloy", loy, iy);
        let thiy = mul("thiy", hiy, iy);
        let tloz = mul("tloz", loz, iz);
        let thiz = mul("thiz", hiz, iz);
        record!(p; tlox, thix, tloy, thiy, tloz, thiz);
        // stage 3: near/far by the sign bit of inv_d
        let negx = x.flag("negx", f.sign_bit(ix));
        let negy = x.flag("negy", f.sign_bit(iy));
        let negz = x.flag("negz", f.sign_bit(iz));
        let (nearx, farx) = if negx { (thix, tlox) } else { (tlox, thix) };
        let (neary, fary) = if negy { (thiy, tloy) } else { (tloy, thiy) };
        let (nearz, farz) = if negz { (thiz, tloz) } else { (tloz, thiz) };
        record_flags!(p; negx, negy, negz);
        record!(p; nearx, farx, neary, fary, nearz, farz);
        // stage 4: the compare unit, accumulating from tmin / tmax in axis order x, y, z
        let tn_x = self.near_sel(x, "tn_x", r.tmin, nearx);
        let tn_xy = self.near_sel(x, "tn_xy", tn_x, neary);
        let tn_xyz = self.near_sel(x, "tn_xyz", tn_xy, nearz);
        let tf_x = self.far_sel(x, "tf_x", r.tmax, farx);
        let tf_xy = self.far_sel(x, "tf_xy", tf_x, fary);
        let tf_xyz = self.far_sel(x, "tf_xyz", tf_xy, farz);
        record!(p; tn_x, tn_xy, tn_xyz, tf_x, tf_xy, tf_xyz);
        // stage 5: widening (conservative variants): t_near toward −∞, t_far toward +∞
        let (mut t_near, mut t_far) = (tn_xyz, tf_xyz);
        let wide = self.cfg.widen_ulps > 0;
        for _ in 0..self.cfg.widen_ulps.unsigned_abs() {
            t_near = x.step(f, "t_near", !wide, t_near);
            t_far = x.step(f, "t_far", wide, t_far);
        }
        record!(p; t_near, t_far);
        // stage 6: decision
        let hit = x.compare(f, "hit", Cmp::Le, t_near, t_far);
        record_flags!(p; hit);
        SlabOut { hit, t_near, t_far }
    }

    /// The directed variant: interval arithmetic in the format's own operations, conservative
    /// in every format that does not wrap. Stage 0 adds `1/d` bounds `inv_lo = nextDown(1 ⊘ d)`,
    /// `inv_hi = nextUp(1 ⊘ d)` (in a fixed format without 1, q1.F, both are the saturation
    /// value of d's sign: |1/d| ≥ 1 exceeds the range) and a parallel flag per axis (d reads
    /// as ±0). Stage 1 brackets each plane distance: `lo = nextDown(b ⊖ o)`,
    /// `hi = nextUp(b ⊖ o)` (one rounded subtract, then one step: the exact difference lies
    /// within one step of any rounding, flushes included). Stage 2 forms, with 6 multiplies, a
    /// lower bound of the entry plane's t and an upper bound of the exit plane's t, picking
    /// the bracket ends by sign (entry plane = min plane when d > 0, max plane when d < 0) and
    /// stepping each product outward once more (nextDown / nextUp).
    ///
    /// **Unbounded ends.** A lower bracket end equal to the format's most negative value
    /// (−∞ in floats, the most negative encoding in fixed point) stands for −∞, and an upper
    /// end equal to the most positive value (+∞, or the most positive encoding) for +∞: a
    /// saturated or overflowed result is only known to lie beyond. When a product's factor is
    /// such an end, the product is not formed: the entry bound is the most negative value and
    /// the exit bound the most positive (no constraint; `0 × ∞` is also covered). With the
    /// signs fixed by d, these are the only values the product could bound.
    ///
    /// Why this never misses: the exact `t = (b − o)·(1/d)` with `b − o ∈ [lo, hi]` and
    /// `1/d ∈ [inv_lo, inv_hi]` of d's sign; for d > 0 and `lo ≥ 0`, `t ≥ lo·(1/d) ≥ lo·inv_lo`,
    /// for `lo < 0`, `t ≥ lo·inv_hi` (and mirrored for d < 0 and for the exit), and a rounded
    /// product stepped outward once is on the far side of the exact product. A product that
    /// saturates stays a bound where it matters: a saturated entry bound at the most positive
    /// value is still below the exact t, and one at the most negative value is below `tmin`
    /// (likewise for the exit and `tmax`). Stage 4 accumulates with the `Ignore` comparator
    /// (a NaN, possible only from a NaN input, drops that constraint); a parallel axis adds
    /// no constraint when `min <= o <= max` and forces a miss otherwise.
    pub fn trace_directed<P: Probe<F::V>>(&self, r: &SlabRay<F::V>, b: &Aabb<F::V>, p: &mut P) -> SlabOut<F::V> {
        let f = &self.fmt;
        let mut near = r.tmin;
        let mut far = r.tmax;
        let mut outside = false;
        let (top, bottom) = (f.from_f64(f64::INFINITY), f.from_f64(f64::NEG_INFINITY));
        // an upper end standing for +∞, a lower end standing for −∞
        let up_inf = |v: F::V| f.to_bits(v) == f.to_bits(top);
        let lo_inf = |v: F::V| f.to_bits(v) == f.to_bits(bottom);
        for a in 0..3 {
            let o = r.o[a];
            if r.parallel[a] {
                let inside = f.le(b.min[a], o) && f.le(o, b.max[a]);
                outside |= !inside;
                if P::ON {
                    p.flag(["inside_x", "inside_y", "inside_z"][a], inside);
                }
                continue;
            }
            let neg = f.sign_bit(r.inv_d[a]);
            // entry plane and exit plane of this axis
            let (pe, px) = if neg { (b.max[a], b.min[a]) } else { (b.min[a], b.max[a]) };
            let de = f.sub(pe, o);
            let dxp = f.sub(px, o);
            let (de_lo, de_hi) = (f.next_down(de), f.next_up(de));
            let (dx_lo, dx_hi) = (f.next_down(dxp), f.next_up(dxp));
            // lower bound of de·(1/d): d > 0 → the smallest de, d < 0 → the largest; then the
            // 1/d end by that factor's sign. Each factor with "is it an unbounded end".
            let (x_e, x_e_inf) = if neg { (de_hi, up_inf(de_hi)) } else { (de_lo, lo_inf(de_lo)) };
            let (inv_e, inv_e_inf) =
                if f.sign_bit(x_e) { (r.inv_hi[a], up_inf(r.inv_hi[a])) } else { (r.inv_lo[a], lo_inf(r.inv_lo[a])) };
            // upper bound of dx·(1/d): d > 0 → the largest dx, d < 0 → the smallest
            let (x_x, x_x_inf) = if neg { (dx_lo, lo_inf(dx_lo)) } else { (dx_hi, up_inf(dx_hi)) };
            let (inv_x, inv_x_inf) =
                if f.sign_bit(x_x) { (r.inv_lo[a], lo_inf(r.inv_lo[a])) } else { (r.inv_hi[a], up_inf(r.inv_hi[a])) };
            let t_entry = if x_e_inf || inv_e_inf { bottom } else { f.next_down(f.mul(x_e, inv_e)) };
            let t_exit = if x_x_inf || inv_x_inf { top } else { f.next_up(f.mul(x_x, inv_x)) };
            if P::ON {
                p.value(["entry_x", "entry_y", "entry_z"][a], t_entry);
                p.value(["exit_x", "exit_y", "exit_z"][a], t_exit);
            }
            near = self.near_sel(&NoFault, "", near, t_entry);
            far = self.far_sel(&NoFault, "", far, t_exit);
        }
        let (t_near, t_far) = (near, far);
        record!(p; t_near, t_far);
        let hit = !outside && f.le(t_near, t_far);
        record_flags!(p; outside, hit);
        SlabOut { hit, t_near, t_far }
    }

    /// One ray–box test without probing.
    #[inline(always)]
    pub fn test(&self, r: &SlabRay<F::V>, b: &Aabb<F::V>) -> SlabOut<F::V> {
        self.trace(r, b, &mut NoProbe)
    }

    /// Stores an f64 box conservatively: min rounded down, max rounded up, so the stored box
    /// contains the original. Float formats clamp beyond their range to ±∞ (still containing);
    /// fixed point reports [`BoxError::OutOfRange`].
    pub fn store_box(&self, min: [f64; 3], max: [f64; 3]) -> Result<Aabb<F::V>, BoxError> {
        let f = &self.fmt;
        if min.iter().chain(max.iter()).any(|x| x.is_nan()) {
            return Err(BoxError::Nan);
        }
        if (0..3).any(|a| min[a] > max[a]) {
            return Err(BoxError::Inverted);
        }
        let mut b = Aabb { min: [f.zero(); 3], max: [f.zero(); 3] };
        for a in 0..3 {
            b.min[a] = f.round_down(min[a]);
            b.max[a] = f.round_up(max[a]);
            if f.to_f64(b.min[a]) > min[a] {
                return Err(BoxError::OutOfRange(min[a]));
            }
            if f.to_f64(b.max[a]) < max[a] {
                return Err(BoxError::OutOfRange(max[a]));
            }
        }
        Ok(b)
    }

    /// Stores an f64 box in a (narrower) storage format `S`, outward-rounded, then widens it into
    /// this compute format, again outward: the datapath's box contains the original (the
    /// thesis's fp16 bounding volumes with f32 arithmetic).
    pub fn store_box_via<S: Format>(&self, s: &S, min: [f64; 3], max: [f64; 3]) -> Result<Aabb<F::V>, BoxError> {
        let stored = Slab::new(*s, self.cfg).store_box(min, max)?;
        let lo = stored.min.map(|v| s.to_f64(v));
        let hi = stored.max.map(|v| s.to_f64(v));
        self.store_box(lo, hi)
    }

    /// The empty-slot encoding: min = +largest, max = −largest on every axis (+∞/−∞ in float
    /// formats); no ray whose origin and direction are finite in the format hits it (a ray that
    /// overflowed the format makes ∞ − ∞ or ∞ × 0, a NaN the comparator may ignore).
    pub fn empty_box(&self) -> Aabb<F::V> {
        let f = &self.fmt;
        let hi = f.from_f64(f64::INFINITY);
        let lo = f.from_f64(f64::NEG_INFINITY);
        Aabb { min: [hi; 3], max: [lo; 3] }
    }

    /// Pairwise batch over structure-of-arrays: ray i against box i. Bit-identical to
    /// [`Slab::test`]; allocation-free.
    ///
    /// # Panics
    /// If the columns differ in length.
    pub fn batch(&self, rays: &SlabRaysSoa<F::V>, boxes: &BoxesSoa<F::V>, out: &mut SlabOutSoa<F::V>) {
        let n = rays.tmin.len();
        assert!(boxes.min[0].len() == n && out.hit.len() == n, "batch lengths differ");
        self.batch_from(rays, boxes, out, 0);
    }

    /// [`Slab::batch`] from slot `from` on (the SIMD kernel's tail).
    ///
    /// # Panics
    /// If a column is shorter than the ray batch.
    pub fn batch_from(
        &self,
        rays: &SlabRaysSoa<F::V>,
        boxes: &BoxesSoa<F::V>,
        out: &mut SlabOutSoa<F::V>,
        from: usize,
    ) {
        for i in from..rays.tmin.len() {
            out.set(i, self.test(&rays.get(i), &boxes.get(i)));
        }
    }

    /// One ray against every box of a structure-of-arrays batch (a node's children, a level,
    /// a whole scene): slot i is box i. Bit-identical to [`Slab::test`]; allocation-free.
    ///
    /// # Panics
    /// If the columns differ in length.
    pub fn batch_ray(&self, ray: &SlabRay<F::V>, boxes: &BoxesSoa<F::V>, out: &mut SlabOutSoa<F::V>) {
        assert!(boxes.min[0].len() == out.hit.len(), "batch lengths differ");
        self.batch_ray_from(ray, boxes, out, 0);
    }

    /// [`Slab::batch_ray`] from slot `from` on (the SIMD kernel's tail).
    ///
    /// # Panics
    /// If a column is shorter than the output.
    pub fn batch_ray_from(&self, ray: &SlabRay<F::V>, boxes: &BoxesSoa<F::V>, out: &mut SlabOutSoa<F::V>, from: usize) {
        for i in from..out.hit.len() {
            out.set(i, self.test(ray, &boxes.get(i)));
        }
    }
}

/// Prepared slab rays as structure-of-arrays columns.
#[derive(Clone, Debug, Default)]
pub struct SlabRaysSoa<V> {
    /// Origin columns.
    pub o: [Vec<V>; 3],
    /// Reciprocal direction columns.
    pub inv_d: [Vec<V>; 3],
    /// Lower 1/d bound columns (directed variant).
    pub inv_lo: [Vec<V>; 3],
    /// Upper 1/d bound columns (directed variant).
    pub inv_hi: [Vec<V>; 3],
    /// Parallel-axis flag columns (directed variant).
    pub parallel: [Vec<bool>; 3],
    /// tmin column.
    pub tmin: Vec<V>,
    /// tmax column.
    pub tmax: Vec<V>,
}

impl<V: Copy> SlabRaysSoa<V> {
    /// Appends a ray.
    pub fn push(&mut self, r: &SlabRay<V>) {
        for a in 0..3 {
            self.o[a].push(r.o[a]);
            self.inv_d[a].push(r.inv_d[a]);
            self.inv_lo[a].push(r.inv_lo[a]);
            self.inv_hi[a].push(r.inv_hi[a]);
            self.parallel[a].push(r.parallel[a]);
        }
        self.tmin.push(r.tmin);
        self.tmax.push(r.tmax);
    }
    /// Ray i.
    #[inline(always)]
    pub fn get(&self, i: usize) -> SlabRay<V> {
        SlabRay {
            o: [self.o[0][i], self.o[1][i], self.o[2][i]],
            inv_d: [self.inv_d[0][i], self.inv_d[1][i], self.inv_d[2][i]],
            tmin: self.tmin[i],
            tmax: self.tmax[i],
            inv_lo: [self.inv_lo[0][i], self.inv_lo[1][i], self.inv_lo[2][i]],
            inv_hi: [self.inv_hi[0][i], self.inv_hi[1][i], self.inv_hi[2][i]],
            parallel: [self.parallel[0][i], self.parallel[1][i], self.parallel[2][i]],
        }
    }
}

/// Boxes as structure-of-arrays columns.
#[derive(Clone, Debug, Default)]
pub struct BoxesSoa<V> {
    /// Lower-corner columns.
    pub min: [Vec<V>; 3],
    /// Upper-corner columns.
    pub max: [Vec<V>; 3],
}

impl<V: Copy> BoxesSoa<V> {
    /// Appends a box.
    pub fn push(&mut self, b: &Aabb<V>) {
        for a in 0..3 {
            self.min[a].push(b.min[a]);
            self.max[a].push(b.max[a]);
        }
    }
    /// Box i.
    #[inline(always)]
    pub fn get(&self, i: usize) -> Aabb<V> {
        Aabb {
            min: [self.min[0][i], self.min[1][i], self.min[2][i]],
            max: [self.max[0][i], self.max[1][i], self.max[2][i]],
        }
    }
}

/// Slab outputs as structure-of-arrays columns.
#[derive(Clone, Debug, Default)]
pub struct SlabOutSoa<V> {
    /// Hit bits.
    pub hit: Vec<bool>,
    /// Entry distances.
    pub t_near: Vec<V>,
    /// Exit distances.
    pub t_far: Vec<V>,
}

impl<V: Copy + Default> SlabOutSoa<V> {
    /// Output columns for `n` results.
    pub fn with_len(n: usize) -> Self {
        Self { hit: vec![false; n], t_near: vec![V::default(); n], t_far: vec![V::default(); n] }
    }

    /// Writes one result into slot i.
    pub fn set(&mut self, i: usize, o: SlabOut<V>) {
        self.hit[i] = o.hit;
        self.t_near[i] = o.t_near;
        self.t_far[i] = o.t_far;
    }
}

/// The guard's reciprocal rule on encodings: `d` finite and nonzero, `1 ⊘ d` not a normal
/// number (±∞, ±0 or subnormal).
pub fn guarded_recip(l: crate::format::FloatLayout, d: u64, r: u64) -> bool {
    let finite = |b: u64| !l.is_nan(b) && !l.is_inf(b);
    finite(d) && !l.is_zero(d) && (l.is_inf(r) || l.is_zero(r) || l.is_subnormal(r))
}

/// The guard's subtract rule on encodings: both operands finite, the difference ±∞.
pub fn guarded_sub(l: crate::format::FloatLayout, a: u64, b: u64, r: u64) -> bool {
    let finite = |x: u64| !l.is_nan(x) && !l.is_inf(x);
    finite(a) && finite(b) && l.is_inf(r)
}
