//! A static filter in front of the per-test error bound ([`crate::bound`]), in the manner of
//! CGAL's static filters and Shewchuk's stage-A bounds: one error constant per block of tests
//! (one ray against a block of triangles), computed from the block's largest magnitudes, decides
//! the tests whose compared quantities clear it; only the rest run the per-test bound.
//!
//! **What it certifies, and why that is the per-test verdict.** The per-test bound
//! ([`RtiBound::new`](crate::bound::RtiBound::new)) carries for each signal its f64 value `v`, its monomial sum `a` and its
//! error bound `e` through sums `e = e₀ + u·(|v| + e₀) + add_eta` (e₀ = ex + ey) and products
//! `e = e₀ + u·(|v| + e₀) + eta` (e₀ = |x|·ey + |y|·ex + ex·ey), `a` adding and multiplying. Every
//! term is non-negative and non-decreasing in |x|, |y|, ex, ey, ax, ay; binary64 rounding to
//! nearest is monotone; and |x ± y| <= |x| + |y|, |x·y| = |x|·|y|. So the same recurrences run on
//! *magnitudes* — the bound's own recurrences (`Ctx` in magnitude mode, where a difference adds),
//! from an upper bound on the inputs' |value| (the block's largest |x| + |y| of the pairs below)
//! and the block's largest first differences |v1 − v0|, |v2 − v0|, |o − v0| per component — give, for every signal, `E = e + 2⁻⁴⁵·a` no smaller than
//! any lane's `err()`, and a range check (`V + E <= max` at every step) that implies every lane's. A lane is
//! certified when (1) the block's range check holds and no input is NaN, (2) the lane is not
//! valid (its exact decision is a miss: the per-test verdict's `hit` is false), (3) every
//! quantity the verdict compares clears the static constant (|det_q| > E_det, |det| > E_det,
//! |u'| > E_u', |v'| > E_v', |det − (u'+v')| > E_det + E_uv, |t'| > E_t'), which implies it
//! clears its per-test bound, and (4) none of the three quotients (t, u, v) can raise the
//! per-test overflow flag: with `D = |det| − E_det` (> 0 by (3), and no larger than the
//! per-test `|det| − err_det`), the per-test `|q| + Δ₁` is at most (|num|·D + E_num·D +
//! |num|·E_det)/D², and a division-free check with a 2⁻⁴⁰ margin bounds its `1/denom <= max`
//! (reciprocal mode) and `mag + extra <= max` (`quot_may_overflow`; first once for all three
//! on the lane's largest numerator and the largest constant, see `certify`). Then the
//! per-test verdict is decisive with `hit` false, and that is what a certified lane gets; its
//! `t_err` is +∞ (no t to bound: the lane misses). Every other lane runs [`RtiBound::new`](crate::bound::RtiBound::new) and
//! [`RtiBound::verdict`](crate::bound::RtiBound::verdict) itself. The lane values (det, u', v', t', u'+v') are the per-test
//! bound's own (`RtiBound::new`'s `v`, the same operations in the same order).
//!
//! **Per-lane constants (coarse formats).** A block's constants grow with its largest
//! differences, where each lane's bound has its own: in a format with unit roundoff
//! u >= 2⁻¹⁶ ([`LANE_U`]: binary16, bfloat16, `eEmM` with M <= 15) they certify few lanes. Such
//! a format's constants are per lane instead, in the manner of Shewchuk's stage-A bounds:
//! `E = G·m + H` for each compared signal, `m` the lane's *magnitude* of the signal — the
//! value's operations on absolute values, a difference adding (`lane_magnitudes`; the same
//! binary64 operations in the same order, so `|v| <= m` exactly, rounding to nearest being
//! monotone and odd, and `m <= M`, the block's magnitude from its largest differences) — and
//! G, H per block (`lane_consts`). By induction over the per-test bound's steps, with
//! `e_x <= g_x·m_x + h_x` for the operands: an input has g = h = 0; a difference of inputs
//! `e = u·|v| + add_eta` gives g = u, h = add_eta; a sum gives
//! `e <= (1 + u)(g_x·m_x + g_y·m_y + h_x + h_y) + u·|v| + add_eta`, so
//! g = (1 + u)·max(g_x, g_y) + u, h = (1 + u)(h_x + h_y) + add_eta; a product
//! `e0 <= (g_x + g_y + g_x·g_y)·m_x·m_y + h_y·m_x·(1 + g_x) + h_x·m_y·(1 + g_y) + h_x·h_y`, the
//! lane's m_x, m_y in the `h` terms bounded by the block's M_x, M_y, so
//! g = (1 + u)(g_x + g_y + g_x·g_y) + u, h = (1 + u)(h_y·M_x·(1 + g_x) + h_x·M_y·(1 + g_y) +
//! h_x·h_y) + eta. The binary64 evaluation of both the per-test bound and these constants is
//! absorbed by inflating every step by `PHI` = 1 + 2⁻⁴⁰ (each step rounds a few times, each
//! within 1 + 2⁻⁵³; `m`'s own rounding too) and adding `TAU` = 2⁻⁶⁰⁰ to every `eta` and
//! `add_eta` (binary64 underflow, at most 2⁻¹⁰⁷⁵ an operation, as a normal number so that the
//! constants round relatively: a product of a constant with a magnitude that underflows is
//! off by at most 2⁻¹⁰⁷⁵, which the `TAU` the step adds absorbs in `PHI`); then `G = g·PHI`, `H = (h + 2⁻⁴⁵·A)·PHI + TAU` (A the block's
//! monomial sum) give `RN(RN(G·m) + H) >=` the lane's computed `err()`. The range check is the
//! same recurrence's `(1 + g)·M + h` (times `PHI`) against `max` at every step, which bounds
//! every lane's `|v| + e`. Conditions (1)–(4) then read the lane's E where they read the
//! block's, and the argument is unchanged. (A finer format keeps the block's constants: they
//! already certify nearly every lane the per-test bound decides as a miss, at less cost.)
//!
//! **Constants over a set.** Every recurrence above is non-decreasing in the magnitudes it
//! starts from and the range check only stricter, so any upper bounds on the block's largest
//! differences and sums serve, certifying at most the lanes the block's own would. [`SetMaxima`]
//! holds such bounds over every triangle of a set (verify: a scene's triangles in a format, as
//! the columns hold them): per component the largest binary64 |v1 − v0|, |v2 − v0|, |v1| + |v0|,
//! |v2| + |v0| over the set, and per axis the smallest and largest v0 and the largest |v0|, from
//! which [`SetMaxima::for_ray`] bounds the origin's terms (binary64 o − v0 is non-increasing in
//! v0, so over [lo, hi] its magnitude is at most max(|o − lo|, |o − hi|); |o| + |v0| at most
//! |o| + max |v0|). [`Constants::new`] computes a ray's constants from them once for all of its
//! blocks (`verdict_block_filtered`'s `pre`); a set with a non-finite coordinate has none, and
//! its blocks use their own.
//!
//! `tests` (here and `datapath/tests/bound_filter.rs`) check the implication lane by lane
//! against the per-test bound on random and edge blocks (subnormal, huge, ±0, ±∞, NaN inputs),
//! with block and with per-lane constants (binary16, e8m7 and e5m10 under FTZ).

use crate::bound::{BlockOpts, BlockRay, Bnd, Ctx, Steps};
use crate::format::DivMode;
use crate::lanes::Lane;
use crate::rti::Cull;
use crate::simd::F64Lanes;

/// A block's constants (where its range check holds and no input is NaN; else no lane is
/// certified): each compared signal's `E` (det, u', v', t', u' + v') for every lane, or per
/// lane (coarse formats, see [`LANE_U`]).
#[derive(Clone, Copy, Debug)]
enum Static {
    /// The same `E` for every lane.
    Block([f64; 5]),
    /// Each lane's `E` from its magnitudes.
    Lane(LaneConsts),
}

/// Where a lane's constants `E` (det, u', v', t', u' + v') come from.
trait LaneE: Copy {
    /// The constants of the lane (or of each lane of a vector) with these inputs.
    fn of<L: Lane>(&self, o: [L; 3], d: [L; 3], v: [[L; 3]; 3]) -> [L; 5];
}

/// The block's: every lane's.
impl LaneE for [f64; 5] {
    #[inline(always)]
    fn of<L: Lane>(&self, _: [L; 3], _: [L; 3], _: [[L; 3]; 3]) -> [L; 5] {
        self.map(L::splat)
    }
}

/// `g·m + h` of the lane's magnitudes (a NaN magnitude, of a lane whose values are NaN, gives
/// NaN constants: no compare clears them).
impl LaneE for LaneConsts {
    #[inline(always)]
    fn of<L: Lane>(&self, o: [L; 3], d: [L; 3], v: [[L; 3]; 3]) -> [L; 5] {
        let m = lane_magnitudes(o, d, v);
        std::array::from_fn(|k| L::splat(self.g[k]) * m[k] + L::splat(self.h[k]))
    }
}

/// Formats whose unit roundoff is at least this get per-lane constants (`LaneConsts`):
/// a speed choice only (a finer format's block constants already certify nearly every lane the
/// per-test bound decides as a miss); every verdict is the per-test bound's either way.
pub const LANE_U: f64 = 1.0 / 65536.0;

/// Relative inflation of every step of the per-lane recurrences: it absorbs the binary64
/// roundings of the per-test bound's step (at most seven, each within a factor 1 + 2⁻⁵³), of
/// the lane's magnitude `m` and of the recurrence itself.
const PHI: f64 = 1.0 + 1.0 / (1u64 << 40) as f64;

/// Absolute slack added with every `eta` and `add_eta` of the per-lane recurrences: binary64
/// underflow in the per-test bound's step or the lane's magnitude (2⁻¹⁰⁷⁵ an operation), as a
/// normal number far above the underflow range (2⁻⁶⁰⁰), so that every constant it enters is
/// rounded relatively — and, a speed choice, so that its products with a block's magnitudes
/// stay normal (binary64 arithmetic with subnormal results is slow on x86: a microcode assist
/// per operation) for any magnitude above about 2⁻⁴⁰⁰.
const TAU: f64 = f64::from_bits((1023 - 600) << 52);

/// Per-lane constants: for each compared signal (det, u', v', t', u' + v') `g` and `h` with
/// every lane's per-test `err() <= g·m + h`, `m` the lane's magnitude of the signal (its
/// absolute-value evaluation, [`lane_magnitudes`]). See the module documentation.
#[derive(Clone, Copy, Debug)]
struct LaneConsts {
    g: [f64; 5],
    h: [f64; 5],
}

/// One signal of the per-lane recurrences: `g` and `h` (every lane's per-test `e <= g·m + h`),
/// the block's largest magnitude `m` (no smaller than any lane's) and monomial sum `a`.
#[derive(Clone, Copy, Debug)]
struct Lb {
    g: f64,
    h: f64,
    m: f64,
    a: f64,
}

/// The per-lane recurrences' constants, and their range check: false once some signal's
/// `(1 + g)·M + h` (no smaller than any lane's `|v| + e`), inflated by [`PHI`], exceeds the
/// format's largest magnitude or is NaN.
struct LaneCtx {
    u: f64,
    eta: f64,
    add_eta: f64,
    max: f64,
    ok: bool,
}

impl LaneCtx {
    #[inline(always)]
    fn check(&mut self, b: Lb) -> Lb {
        self.ok &= (b.m + b.g * b.m + b.h) * PHI <= self.max;
        b
    }
    #[inline(always)]
    fn input(&mut self, x: f64) -> Lb {
        self.check(Lb { g: 0.0, h: 0.0, m: x, a: x })
    }
    /// The difference of two inputs, `v` the block's largest |x − y|, `a` its largest |x| + |y|.
    #[inline(always)]
    fn input_difference(&mut self, v: f64, a: f64) -> Lb {
        self.check(Lb { g: PHI * self.u, h: PHI * self.add_eta, m: v, a })
    }
    #[inline(always)]
    fn mul(&mut self, x: Lb, y: Lb) -> Lb {
        let u = self.u;
        let g = PHI * ((1.0 + u) * (x.g + y.g + x.g * y.g) + u);
        let k = y.h * x.m * (1.0 + x.g) + x.h * y.m * (1.0 + y.g) + x.h * y.h;
        let h = PHI * ((1.0 + u) * k + self.eta);
        self.check(Lb { g, h, m: x.m * y.m, a: x.a * y.a })
    }
    #[inline(always)]
    fn add(&mut self, x: Lb, y: Lb) -> Lb {
        let u = self.u;
        let g = PHI * ((1.0 + u) * x.g.max(y.g) + u);
        let h = PHI * ((1.0 + u) * (x.h + y.h) + self.add_eta);
        self.check(Lb { g, h, m: x.m + y.m, a: x.a + y.a })
    }
}

/// The recurrences' steps (a difference of magnitudes adds), the products in the datapath's
/// order.
impl Steps for LaneCtx {
    type S = Lb;
    #[inline(always)]
    fn mul(&mut self, x: Lb, y: Lb) -> Lb {
        LaneCtx::mul(self, x, y)
    }
    #[inline(always)]
    fn add(&mut self, x: Lb, y: Lb) -> Lb {
        LaneCtx::add(self, x, y)
    }
    #[inline(always)]
    fn sub(&mut self, x: Lb, y: Lb) -> Lb {
        LaneCtx::add(self, x, y)
    }
}

/// The lane values' binary64 operations (`values`), or with `MAG` their absolute-value
/// evaluation (`lane_magnitudes`: a difference adds), the products in the datapath's order.
/// On one f64 or on each lane of a vector of them (the same operations per lane).
struct F64Steps<L, const MAG: bool>(std::marker::PhantomData<L>);

impl<L: Lane, const MAG: bool> Steps for F64Steps<L, MAG> {
    type S = L;
    #[inline(always)]
    fn mul(&mut self, x: L, y: L) -> L {
        x * y
    }
    #[inline(always)]
    fn add(&mut self, x: L, y: L) -> L {
        x + y
    }
    #[inline(always)]
    fn sub(&mut self, x: L, y: L) -> L {
        if MAG {
            x + y
        } else {
            x - y
        }
    }
}

/// The per-lane constants of a block from its largest magnitudes (as [`statics`] reads them),
/// or `None` when the block's range check fails.
#[inline(always)]
fn lane_consts(o: BlockOpts, r: BlockRay, big: f64, ve: [f64; 9], ae: [f64; 9]) -> Option<LaneConsts> {
    let mut l = LaneCtx { u: o.em.u, eta: o.em.eta + TAU, add_eta: o.em.add_eta + TAU, max: o.em.max, ok: true };
    // the lanes' inputs and the ray's (as `statics` checks them)
    l.input(big);
    for x in r.o {
        l.input(x.abs());
    }
    let d3 = r.d.map(|x| l.input(x.abs()));
    let diff: [Lb; 9] = std::array::from_fn(|k| l.input_difference(ve[k], ae[k]));
    let e1 = [diff[0], diff[1], diff[2]];
    let e2 = [diff[3], diff[4], diff[5]];
    let s = [diff[6], diff[7], diff[8]];
    let p = l.cross(d3, e2);
    let q = l.cross(s, e1);
    let sig = [l.dot(e1, p), l.dot(s, p), l.dot(d3, q), l.dot(e2, q)];
    let uv = l.add(sig[1], sig[2]);
    let all = [sig[0], sig[1], sig[2], sig[3], uv];
    l.ok.then(|| LaneConsts {
        g: all.map(|b| b.g * PHI),
        h: all.map(|b| (b.h + crate::bound::F64_SLACK * b.a) * PHI + TAU),
    })
}

/// The block's largest magnitudes: per first-difference component (e1 = v1 − v0, e2 = v2 − v0,
/// s = o − v0, as each lane computes them) its largest |value| and largest monomial sum
/// |x| + |y|, the largest of those sums (no smaller than any non-NaN |input| of the lanes: each
/// vertex column is in a sum), and whether an input of the lanes is NaN. Column by column,
/// branch-free.
#[inline(always)]
fn maxima(r: BlockRay, c: [&[f64]; 9]) -> Maxima {
    let (mut ve, mut ae) = ([0.0f64; 9], [0.0f64; 9]);
    let mut bad = false;
    for a in 0..3 {
        let y = c[a];
        for k in 0..3 {
            // (the vertex columns' NaNs are in the first two pairs)
            let (vm, am, nan) = if k < 2 {
                column_maxima(c[3 * (k + 1) + a], y)
            } else {
                let (vm, am) = origin_maxima(r.o[a], y);
                (vm, am, false)
            };
            ve[3 * k + a] = vm;
            ae[3 * k + a] = am;
            bad |= nan;
        }
    }
    (ve, ae, largest(ae), bad)
}

/// The largest of the monomial-sum maxima (none is NaN: a maximum never takes one).
#[inline(always)]
fn largest(ae: [f64; 9]) -> f64 {
    ae.iter().fold(0.0f64, |m, &x| if x > m { x } else { m })
}

/// Over the lanes of columns x and y: the largest |x − y| and |x| + |y|, and whether a value is
/// NaN (a running sum of the |x| + |y| is NaN exactly then: a sum of magnitudes is never NaN
/// otherwise, +∞ plus anything non-negative staying +∞). Eight independent accumulators per
/// quantity, so the loop vectorises.
#[inline(always)]
fn column_maxima(x: &[f64], y: &[f64]) -> (f64, f64, bool) {
    const W: usize = 8;
    let (mut vm, mut am, mut nf) = ([0.0f64; W], [0.0f64; W], [0.0f64; W]);
    let mut step = |j: usize, xi: f64, yi: f64| {
        let (dv, sv) = ((xi - yi).abs(), xi.abs() + yi.abs());
        vm[j] = if dv > vm[j] { dv } else { vm[j] };
        am[j] = if sv > am[j] { sv } else { am[j] };
        nf[j] += sv;
    };
    let (xc, yc) = (x.chunks_exact(W), y.chunks_exact(W));
    let (xr, yr) = (xc.remainder(), yc.remainder());
    for (xs, ys) in xc.zip(yc) {
        for j in 0..W {
            step(j, xs[j], ys[j]);
        }
    }
    for (&xi, &yi) in xr.iter().zip(yr) {
        step(0, xi, yi);
    }
    fold(vm, am, nf)
}

/// [`column_maxima`] with x one value (the ray's origin on an axis).
/// [`column_maxima`]'s first two with x one value (the ray's origin on an axis; its range and
/// NaN are [`statics`]' checks, y's NaNs [`column_maxima`]'s).
#[inline(always)]
fn origin_maxima(xi: f64, y: &[f64]) -> (f64, f64) {
    const W: usize = 8;
    let (mut vm, mut am) = ([0.0f64; W], [0.0f64; W]);
    let mut step = |j: usize, yi: f64| {
        let (dv, sv) = ((xi - yi).abs(), xi.abs() + yi.abs());
        vm[j] = if dv > vm[j] { dv } else { vm[j] };
        am[j] = if sv > am[j] { sv } else { am[j] };
    };
    let yc = y.chunks_exact(W);
    let yr = yc.remainder();
    for ys in yc {
        for (j, &yi) in ys.iter().enumerate() {
            step(j, yi);
        }
    }
    for &yi in yr {
        step(0, yi);
    }
    let (v, a, _) = fold(vm, am, [0.0; W]);
    (v, a)
}

/// [`maxima`] in explicit vector registers of `V` (its feature present): per axis one pass
/// over the three vertex columns giving the three components' maxima (e1 = v1 − v0,
/// e2 = v2 − v0, s = o − v0) and the NaN flag. Equal to [`maxima`]: a maximum of non-NaN
/// values does not depend on the order or grouping it is taken in (every value is an absolute
/// value or a sum of two, never −0; a NaN is never taken: `maxpd` keeps its second operand,
/// the running maximum, and the scalar compares fail), and a sum of magnitudes is NaN exactly
/// when one of its terms is, in any order.
///
/// # Safety
/// `V`'s instruction set must be present.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn maxima_v<V: crate::lanes_x86::Vector>(r: BlockRay, c: [&[f64]; 9]) -> Maxima {
    let (mut ve, mut ae) = ([0.0f64; 9], [0.0f64; 9]);
    let mut bad = false;
    for a in 0..3 {
        // SAFETY: the caller's contract
        let (vm, am, nan) = unsafe { axis_maxima_v::<V>(r.o[a], c[a], c[3 + a], c[6 + a]) };
        for k in 0..3 {
            ve[3 * k + a] = vm[k];
            ae[3 * k + a] = am[k];
        }
        bad |= nan;
    }
    (ve, ae, largest(ae), bad)
}

/// One axis of [`maxima_v`]: over the lanes of v0, v1, v2 (and the origin's value `o`) the
/// largest |v1 − v0|, |v2 − v0|, |o − v0| and |v1| + |v0|, |v2| + |v0|, |o| + |v0|, and whether
/// an input is NaN; the lanes past the last whole vector by the scalar steps
/// ([`column_maxima`], [`origin_maxima`]).
///
/// # Safety
/// `V`'s instruction set must be present.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn axis_maxima_v<V: crate::lanes_x86::Vector>(
    o: f64,
    v0: &[f64],
    v1: &[f64],
    v2: &[f64],
) -> ([f64; 3], [f64; 3], bool) {
    let n = v0.len();
    assert!(v1.len() == n && v2.len() == n, "column lengths differ");
    let whole = n - n % V::N;
    let zero = V::splat(0.0);
    let (mut vm, mut am) = ([zero; 3], [zero; 3]);
    let mut nf = zero;
    let (ox, oa) = (V::splat(o), V::splat(o.abs()));
    let mut i = 0;
    while i < whole {
        // SAFETY: i + N <= n for the three columns (same length); the caller's contract
        let (y, x1, x2) =
            unsafe { (V::load(v0.as_ptr().add(i)), V::load(v1.as_ptr().add(i)), V::load(v2.as_ptr().add(i))) };
        let (ya, x1a, x2a) = (y.abs(), x1.abs(), x2.abs());
        let dv = [(x1 - y).abs(), (x2 - y).abs(), (ox - y).abs()];
        let sv = [x1a + ya, x2a + ya, oa + ya];
        for k in 0..3 {
            vm[k] = dv[k].max_of(vm[k]);
            am[k] = sv[k].max_of(am[k]);
        }
        // NaN exactly when one of y, x1, x2 is (the third sum repeats y)
        nf = nf + (sv[0] + sv[1]);
        i += V::N;
    }
    let lanes = |v: V| {
        let mut a = [0.0f64; 8];
        // SAFETY: N <= 8 lanes written; the caller's contract for the feature
        unsafe { v.store(a.as_mut_ptr()) };
        a
    };
    let max = |p: f64, q: f64| if p > q { p } else { q };
    let fold = |v: V, m: f64| lanes(v)[..V::N].iter().fold(m, |m, &l| max(l, m));
    let rn = lanes(nf)[..V::N].iter().any(|l| l.is_nan());
    // the tail by the scalar steps (origin_maxima takes |o| and o's finiteness even on an
    // empty tail)
    let (ov, oa) = origin_maxima(o, &v0[whole..]);
    let t = [column_maxima(&v1[whole..], &v0[whole..]), column_maxima(&v2[whole..], &v0[whole..]), (ov, oa, false)];
    let vmax = std::array::from_fn(|k| fold(vm[k], t[k].0));
    let amax = std::array::from_fn(|k| fold(am[k], t[k].1));
    (vmax, amax, rn | t.iter().any(|x| x.2))
}

/// The accumulators folded (the NaN flag: a NaN sum).
fn fold<const W: usize>(vm: [f64; W], am: [f64; W], nf: [f64; W]) -> (f64, f64, bool) {
    let m = |x: [f64; W]| x.iter().fold(0.0f64, |m, &v| m.max(v));
    (m(vm), m(am), nf.iter().any(|v| v.is_nan()))
}

#[inline(always)]
fn statics(o: BlockOpts, r: BlockRay, (ve, ae, big, nan): Maxima) -> Option<Static> {
    if nan || r.o.iter().chain(&r.d).any(|x| x.is_nan()) {
        return None;
    }
    if o.em.u >= LANE_U {
        // a coarse format: the per-lane constants alone (the block's would seldom be smaller)
        return lane_consts(o, r, big, ve, ae).map(Static::Lane);
    }
    // the per-test recurrences on magnitudes (`Ctx` in magnitude mode: a difference adds)
    let mut m = Ctx::<f64>::new(o.em, true);
    // the lanes' inputs' range: `big` is no smaller than any |input| of theirs (an infinite one
    // makes it infinite and fails the check); the ray's values are checked on their own
    m.input(big);
    for x in r.o {
        m.input(x.abs());
    }
    let d3 = r.d.map(|x| m.input(x.abs()));
    // the first differences taken lane by lane (translation does not loosen the constants)
    let diff: [Bnd<f64>; 9] = std::array::from_fn(|k| m.input_difference(ve[k], ae[k]));
    let e1 = [diff[0], diff[1], diff[2]];
    let e2 = [diff[3], diff[4], diff[5]];
    let s = [diff[6], diff[7], diff[8]];
    let p = m.cross(d3, e2);
    let q = m.cross(s, e1);
    let det = m.dot(e1, p);
    let up = m.dot(s, p);
    let vp = m.dot(d3, q);
    let tp = m.dot(e2, q);
    let uv = m.add(up, vp);
    (!m.overflow).then(|| Static::Block([det.err(), up.err(), vp.err(), tp.err(), uv.err()]))
}

/// Relative room of [`certify`]'s test for a quotient that surely overflows (a speed choice:
/// such a lane skips the three one-by-one checks, which it would fail).
const HOPELESS: f64 = 1.0 / (1u64 << 30) as f64;

/// Relative margin of the quotient check below: it absorbs the per-test bound's roundings of
/// `q`, `Δ₁`, `mag` and `extra` (at most about ten binary64 roundings, a factor below
/// 1 + 2⁻⁴⁹) and this check's own (a dozen more).
const QUOT_MARGIN: f64 = 1.0 / (1u64 << 40) as f64;

/// Whether the per-test quotient `num / det` can raise the overflow flag, bounded from the
/// static constants without a division (`d`: |det| − E_det, > 0, no larger than the per-test
/// `|det| − err_det`): false certifies it cannot. With X = |num|, the per-test
/// `mag = |q| + (err_num + |q|·err_det)/denom` is at most (X·d + E_num·d + X·E_det)/d², so
/// `mag + extra <= max` follows from `(X·d + E_num·d + X·E_det)·(1 + 2u + u²) +
/// (eta·(X + E_num)·(1 + u) + eta)·d² <= max·d²·(1 − 2⁻⁴⁰)` (reciprocal mode; divide mode:
/// `·(1 + u) + eta·d²`), and
/// `1/denom <= max` from `max·d·(1 − 2⁻⁴⁰) >= 1`. Every term is finite (the block's range check
/// bounds X, d and the constants by the format's largest value); a NaN fails the check.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
/// On one f64 or on each lane of a vector of them (the same operations per lane; `u`, `eta`,
/// `max` the format's, `recip` the block's).
fn quot_may_overflow<L: Lane>(recip: bool, u: f64, eta: f64, max: f64, num: L, e_num: L, e_det: L, d: L) -> L::M {
    let c = L::splat;
    let x = num.abs();
    let d2 = d * d;
    let m = x * d + e_num * d + x * e_det;
    let lhs = if recip {
        m * c(1.0 + (2.0 * u + u * u)) + (c(eta) * (x + e_num) * c(1.0 + u) + c(eta)) * d2
    } else {
        m * c(1.0 + u) + c(eta) * d2
    };
    let fits = lhs.le(c(max) * d2 * c(1.0 - QUOT_MARGIN));
    !(fits & (L::mask(!recip) | recip_fits(max, d)))
}

/// [`quot_may_overflow`]'s reciprocal-mode check `max·d·(1 − 2⁻⁴⁰) >= 1` (false on NaN).
#[inline(always)]
fn recip_fits<L: Lane>(max: f64, d: L) -> L::M {
    (L::splat(max) * d * L::splat(1.0 - QUOT_MARGIN)).ge(L::splat(1.0))
}

/// As [`crate::bound::verdict_block`] — per lane the verdict's `decisive` and `hit`, and
/// `t_err` — with the static filter in front: a certified lane gets `decisive` true, `hit`
/// false and `t_err` +∞ (it misses: no t to bound), which is the per-test verdict (module
/// documentation); every other lane is the per-test bound's. Returns the number of certified
/// lanes. `certified` is scratch space (its length is the block's). The block's constants are
/// `pre` where given — [`Constants::new`] for the same `opts` and `ray` from [`SetMaxima`] of a
/// set holding every triangle of the block (the caller's promise: constants from smaller
/// magnitudes than the block's would certify wrongly) — else computed from the block's own
/// maxima ([`block_maxima`]).
///
/// # Panics
/// If the column lengths differ.
#[allow(clippy::too_many_arguments)]
pub fn verdict_block_filtered(
    cap: crate::simd::Kernel,
    opts: BlockOpts,
    ray: BlockRay,
    tris: [&[f64]; 9],
    pre: Option<&Constants>,
    decisive: &mut [bool],
    hit: &mut [bool],
    t_err: &mut [f64],
    certified: &mut [bool],
) -> usize {
    let n = hit.len();
    assert!(
        decisive.len() == n && t_err.len() == n && certified.len() == n && tris.iter().all(|c| c.len() == n),
        "column lengths differ"
    );
    // the block's constants: `pre`, or from its own maxima (on the widest vector registers)
    let st = match pre {
        Some(k) => k.0,
        None => statics(opts, ray, block_maxima(cap, ray, tris)),
    };
    let Some(st) = st else {
        // no constants (range check, NaN): no lane is certified
        crate::bound::verdict_block(cap, opts, ray, tris, decisive, hit, t_err);
        certified.fill(false);
        return 0;
    };
    match crate::simd::f64_lanes(cap) {
        // SAFETY: AVX-512F is present (f64_lanes detected it)
        #[cfg(target_arch = "x86_64")]
        F64Lanes::Avx512 => unsafe { certify_avx512(opts, ray, st, tris, certified, t_err) },
        // SAFETY: AVX2 is present (f64_lanes detected it)
        #[cfg(target_arch = "x86_64")]
        F64Lanes::Avx2 => unsafe { certify_avx2(opts, ray, st, tris, certified, t_err) },
        _ => certify(opts, ray, st, tris, certified, t_err),
    }
    let k = certified.iter().filter(|&&c| c).count();
    // a certified lane's verdict
    let miss = (true, false, f64::INFINITY);
    if n - k > n / 8 && k < n / 4 {
        // most lanes left: the per-test bound on the whole block in vector registers, then the
        // certified lanes' verdicts put back (cheaper than the rest lane by lane)
        crate::bound::verdict_block(cap, opts, ray, tris, decisive, hit, t_err);
        for i in (0..n).filter(|&i| certified[i]) {
            (decisive[i], hit[i], t_err[i]) = miss;
        }
    } else if n - k > PACK_FROM {
        // many certified, more than a few left: the lanes left packed, a group at a time,
        // through the per-test bound in vector registers; the certified ones get their verdict
        packed(tris, certified, Some(miss), decisive, hit, t_err, |c, d, h, t| {
            crate::bound::verdict_block(cap, opts, ray, c, d, h, t)
        });
    } else {
        // every lane the certified verdict (vector stores), then the few left one by one,
        // found from the certificate's bit masks
        decisive.fill(miss.0);
        hit.fill(miss.1);
        t_err.fill(miss.2);
        for (w, len) in crate::simd::mask::words(n) {
            let mut todo = !crate::simd::mask::bits(&certified[w..w + len]) & (u64::MAX >> (64 - len));
            while todo != 0 {
                let i = w + todo.trailing_zeros() as usize;
                (decisive[i], hit[i], t_err[i]) = crate::bound::lane(opts, ray, tris, i);
                todo &= todo - 1;
            }
        }
    }
    k
}

/// [`verdict_block_filtered`] on the lanes `i` with `skip[i]` false only — their `decisive`,
/// `hit` and `t_err` written, every other lane's left as it was — the lanes packed into groups
/// of their own (`packed`: a lane's verdict does not depend on where it sits); `pre` as there
/// (constants from the block's triangles' set, else each group's own).
///
/// # Panics
/// If the column lengths differ.
#[allow(clippy::too_many_arguments)]
pub fn verdict_lanes_filtered(
    cap: crate::simd::Kernel,
    opts: BlockOpts,
    ray: BlockRay,
    tris: [&[f64]; 9],
    pre: Option<&Constants>,
    skip: &[bool],
    decisive: &mut [bool],
    hit: &mut [bool],
    t_err: &mut [f64],
) {
    let mut certified = [false; PACK];
    packed(tris, skip, None, decisive, hit, t_err, |c, d, h, t| {
        verdict_block_filtered(cap, opts, ray, c, pre, d, h, t, &mut certified[..d.len()]);
    });
}

/// Lanes per group in [`packed`].
const PACK: usize = 64;

/// Uncertified lanes of a mostly certified block beyond which they go packed through the
/// per-test bound in vector registers rather than one by one (a speed choice only).
const PACK_FROM: usize = 8;

/// `verdict` (a per-lane verdict on columns: decisive, hit, t bound) on every lane `i` with
/// `skip[i]` false: those lanes, in lane order, copied into groups of [`PACK`] lanes, each
/// group's columns through `verdict`, its outputs written back to their lanes; a skipped
/// lane's outputs get `fill` (not written when `fill` is `None`).
///
/// # Panics
/// If the column lengths differ.
fn packed(
    tris: [&[f64]; 9],
    skip: &[bool],
    fill: Option<(bool, bool, f64)>,
    decisive: &mut [bool],
    hit: &mut [bool],
    t_err: &mut [f64],
    mut verdict: impl FnMut([&[f64]; 9], &mut [bool], &mut [bool], &mut [f64]),
) {
    let n = skip.len();
    assert!(
        decisive.len() == n && hit.len() == n && t_err.len() == n && tris.iter().all(|c| c.len() == n),
        "column lengths differ"
    );
    assert!(u32::try_from(n).is_ok(), "packed: more lanes than u32 indexes");
    if let Some((d, h, t)) = fill {
        // every lane's outputs filled; the lanes not skipped are written again below
        decisive.fill(d);
        hit.fill(h);
        t_err.fill(t);
    }
    if skip.iter().all(|&s| s) {
        // no lane to run (often: a block the bound decided whole), no group's space to clear
        return;
    }
    let mut cols = [[0.0f64; PACK]; 9];
    let (mut dec, mut hi, mut te) = ([false; PACK], [false; PACK], [0.0f64; PACK]);
    let mut lanes = [0u32; PACK];
    // one group: its lanes' columns gathered (vector gathers where the machine has them),
    // the verdict, its outputs written back to their lanes
    let mut run = |idx: &[u32]| {
        let m = idx.len();
        for (col, src) in cols.iter_mut().zip(tris) {
            crate::simd::gather::gather(
                crate::simd::Kernel::Avx512Fp16,
                src,
                idx,
                false,
                std::array::from_ref,
                [&mut col[..m]],
            );
        }
        let c: [&[f64]; 9] = std::array::from_fn(|k| &cols[k][..m]);
        verdict(c, &mut dec[..m], &mut hi[..m], &mut te[..m]);
        for (j, &l) in idx.iter().enumerate() {
            let l = l as usize;
            (decisive[l], hit[l], t_err[l]) = (dec[j], hi[j], te[j]);
        }
    };
    // the lanes not skipped, in lane order, word by word (their bits), PACK to a group
    let mut m = 0;
    for (w, len) in crate::simd::mask::words(n) {
        let mut todo = !crate::simd::mask::bits(&skip[w..w + len]) & (u64::MAX >> (64 - len));
        while todo != 0 {
            lanes[m] = (w + todo.trailing_zeros() as usize) as u32;
            todo &= todo - 1;
            m += 1;
            if m == PACK {
                run(&lanes);
                m = 0;
            }
        }
    }
    if m > 0 {
        run(&lanes[..m]);
    }
}

/// The block's largest magnitudes the static constants come from, on the widest instruction
/// level `cap` allows and the machine has: per first-difference component (e1 x, y, z, e2 x,
/// y, z, s x, y, z) the largest |value| and the largest monomial sum, the largest of those sums
/// (no smaller than any non-NaN |input| of the lanes), and whether an input of the lanes is NaN
/// (an infinite input makes the sums infinite). The same bits on every level.
pub fn block_maxima(cap: crate::simd::Kernel, ray: BlockRay, tris: [&[f64]; 9]) -> Maxima {
    let n = tris[0].len();
    assert!(tris.iter().all(|c| c.len() == n), "column lengths differ");
    match crate::simd::f64_lanes(cap) {
        // SAFETY: AVX-512F is present (f64_lanes detected it)
        #[cfg(target_arch = "x86_64")]
        F64Lanes::Avx512 => unsafe { maxima_avx512(ray, tris) },
        // SAFETY: AVX2 is present (f64_lanes detected it)
        #[cfg(target_arch = "x86_64")]
        F64Lanes::Avx2 => unsafe { maxima_avx2(ray, tris) },
        _ => maxima(ray, tris),
    }
}

/// A block's largest magnitudes, as the static constants read them ([`block_maxima`]): per
/// first-difference component (e1 x, y, z, e2 x, y, z, s x, y, z) the largest |value| and the
/// largest monomial sum, the largest of those sums, and whether an input is NaN.
pub type Maxima = ([f64; 9], [f64; 9], f64, bool);

/// Bounds on the magnitudes a block's static constants come from, over every triangle of a
/// set (a scene's triangles in a format): for any block of the set's triangles and any ray,
/// [`SetMaxima::for_ray`] is no smaller, component by component, than the block's
/// [`block_maxima`] — so the constants computed from it serve every such block. Every
/// recurrence of the constants is non-decreasing in the magnitudes it starts from, and the
/// range check only stricter (module documentation), so constants from larger magnitudes are
/// sound, certifying at most the lanes the block's own would (CGAL's static filters take such
/// bounds over all of a program's inputs).
#[derive(Clone, Copy, Debug)]
pub struct SetMaxima {
    /// e1 x, y, z, e2 x, y, z: the largest binary64 |v1 − v0| (|v2 − v0|) and |v1| + |v0|
    /// (|v2| + |v0|) over the set, as a lane computes them.
    ve: [f64; 6],
    ae: [f64; 6],
    /// Per axis the smallest and largest v0 and the largest |v0|.
    lo: [f64; 3],
    hi: [f64; 3],
    a0: [f64; 3],
    /// Every coordinate of the set finite, and the set not empty.
    finite: bool,
}

impl SetMaxima {
    /// The bounds over these triangles (v0 x, y, z, v1 x, y, z, v2 x, y, z each: the columns'
    /// order).
    pub fn of(tris: impl IntoIterator<Item = [f64; 9]>) -> Self {
        let mut m = SetMaxima {
            ve: [0.0; 6],
            ae: [0.0; 6],
            lo: [f64::INFINITY; 3],
            hi: [f64::NEG_INFINITY; 3],
            a0: [0.0; 3],
            finite: false,
        };
        let mut all_finite = true;
        let mut any = false;
        for t in tris {
            any = true;
            all_finite &= t.iter().all(|x| x.is_finite());
            for a in 0..3 {
                let y = t[a];
                for k in 0..2 {
                    let x = t[3 * (k + 1) + a];
                    m.ve[3 * k + a] = m.ve[3 * k + a].max((x - y).abs());
                    m.ae[3 * k + a] = m.ae[3 * k + a].max(x.abs() + y.abs());
                }
                m.lo[a] = m.lo[a].min(y);
                m.hi[a] = m.hi[a].max(y);
                m.a0[a] = m.a0[a].max(y.abs());
            }
        }
        m.finite = any && all_finite;
        m
    }

    /// The maxima (as [`block_maxima`] gives them) bounding every block of the set's triangles
    /// against `ray`, or `None` when the set has a non-finite coordinate or no triangle (then
    /// the blocks' own maxima serve). The origin's components: binary64 o − v0 is
    /// non-increasing in v0 (rounding is monotone), so over v0 in [lo, hi] its magnitude is at
    /// most the larger of |o − lo| and |o − hi|; |o| + |v0| at most |o| + max |v0|.
    pub fn for_ray(&self, ray: BlockRay) -> Option<Maxima> {
        if !self.finite {
            return None;
        }
        let mut ve = [0.0; 9];
        let mut ae = [0.0; 9];
        ve[..6].copy_from_slice(&self.ve);
        ae[..6].copy_from_slice(&self.ae);
        for a in 0..3 {
            let o = ray.o[a];
            ve[6 + a] = (o - self.lo[a]).abs().max((o - self.hi[a]).abs());
            ae[6 + a] = o.abs() + self.a0[a];
        }
        // (a NaN origin makes these NaN; the constants refuse a NaN ray on its own)
        Some((ve, ae, largest(ae), false))
    }
}

/// A block's static constants computed ahead ([`Constants::new`]), for
/// [`verdict_block_filtered`]'s `pre`: every block of a set against one ray shares them.
#[derive(Clone, Copy, Debug)]
pub struct Constants(Option<Static>);

impl Constants {
    /// The constants for `opts` and `ray` from maxima that bound a block's (`SetMaxima::for_ray`
    /// or [`block_maxima`]); none (no lane certified) where the range check fails or an input
    /// is NaN.
    pub fn new(opts: BlockOpts, ray: BlockRay, m: Maxima) -> Self {
        Constants(statics(opts, ray, m))
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn maxima_avx512(r: BlockRay, c: [&[f64]; 9]) -> Maxima {
    // SAFETY: AVX-512F is enabled on this function
    unsafe { maxima_v::<crate::lanes_x86::F64x8>(r, c) }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn maxima_avx2(r: BlockRay, c: [&[f64]; 9]) -> Maxima {
    // SAFETY: AVX2 is enabled on this function
    unsafe { maxima_v::<crate::lanes_x86::F64x4>(r, c) }
}

/// [`certify`] on one instruction set's vectors (whole vectors of `$v`, then the rest lane by
/// lane).
macro_rules! certify_on {
    ($name:ident, $feat:literal, $v:ty) => {
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = $feat)]
        fn $name(o: BlockOpts, r: BlockRay, st: Static, c: [&[f64]; 9], out: &mut [bool], mark: &mut [f64]) {
            // SAFETY: the feature is enabled on this function (its callers detected it)
            unsafe {
                match st {
                    Static::Block(e) => certify_vectors::<$v, _>(o, r, e, c, out, mark),
                    Static::Lane(l) => certify_vectors::<$v, _>(o, r, l, c, out, mark),
                }
            }
        }
    };
}

certify_on!(certify_avx512, "avx512f", crate::lanes_x86::F64x8);
certify_on!(certify_avx2, "avx2", crate::lanes_x86::F64x4);

/// The values `RtiBound::new` carries for det, u', v', t' and u' + v' (its `v`): the same
/// binary64 operations in the same order (no error terms; `tests::values_are_the_bounds`).
#[inline(always)]
pub fn values(o: [f64; 3], d: [f64; 3], v: [[f64; 3]; 3]) -> [f64; 5] {
    values_of(o, d, v)
}

/// [`values`] on each lane of `L` (the same operations per lane).
#[inline(always)]
fn values_of<L: Lane>(o: [L; 3], d: [L; 3], v: [[L; 3]; 3]) -> [L; 5] {
    let [v0, v1, v2] = v;
    let e1 = [v1[0] - v0[0], v1[1] - v0[1], v1[2] - v0[2]];
    let e2 = [v2[0] - v0[0], v2[1] - v0[1], v2[2] - v0[2]];
    let s = [o[0] - v0[0], o[1] - v0[1], o[2] - v0[2]];
    let mut f = F64Steps::<L, false>(std::marker::PhantomData);
    let p = f.cross(d, e2);
    let q = f.cross(s, e1);
    let (det, up, vp, tp) = (f.dot(e1, p), f.dot(s, p), f.dot(d, q), f.dot(e2, q));
    [det, up, vp, tp, up + vp]
}

/// The lane magnitudes of det, u', v', t' and u' + v' ([`values`] on absolute values, a
/// difference adding): the same binary64 operations in the same order, so each is no smaller
/// than the magnitude of the value [`values`] computes (rounding to nearest is monotone and
/// odd), and no larger than the block's magnitude of the signal in [`lane_consts`].
#[inline(always)]
fn lane_magnitudes<L: Lane>(o: [L; 3], d: [L; 3], v: [[L; 3]; 3]) -> [L; 5] {
    let [v0, v1, v2] = v;
    let e1 = [(v1[0] - v0[0]).abs(), (v1[1] - v0[1]).abs(), (v1[2] - v0[2]).abs()];
    let e2 = [(v2[0] - v0[0]).abs(), (v2[1] - v0[1]).abs(), (v2[2] - v0[2]).abs()];
    let s = [(o[0] - v0[0]).abs(), (o[1] - v0[1]).abs(), (o[2] - v0[2]).abs()];
    let d = d.map(L::abs);
    let mut f = F64Steps::<L, true>(std::marker::PhantomData);
    let p = f.cross(d, e2);
    let q = f.cross(s, e1);
    let (det, up, vp, tp) = (f.dot(e1, p), f.dot(s, p), f.dot(d, q), f.dot(e2, q));
    [det, up, vp, tp, up + vp]
}

/// Per lane, whether the static constants certify it (conditions (2) to (4) of the module
/// documentation; (1) is the caller's), branch-free per lane, with the block's constants or,
/// where the block has per-lane constants (a coarse format), each lane's own.
/// Condition (4) first as one quotient check on the lane's largest numerator magnitude
/// max(|t'|, |u'|, |v'|) with the largest of its three constants: [`quot_may_overflow`]'s
/// inequality, divided by d² > 0, has every left-hand term non-decreasing in the numerator and
/// in its constant (and the right side free of both), so what it certifies there holds for
/// each of the three. A lane that meets (2) and (3) but not that check (few: |det| near its
/// bound) then takes the three checks one by one (those lanes marked in `mark`, scratch space
/// of the block's length).
#[inline(always)]
fn certify(o: BlockOpts, r: BlockRay, st: Static, c: [&[f64]; 9], out: &mut [bool], mark: &mut [f64]) {
    match st {
        Static::Block(e) => certify_lanes(o, r, e, c, out, mark, 0),
        Static::Lane(l) => certify_lanes(o, r, l, c, out, mark, 0),
    }
}

/// [`certify`] with the lanes' constants from `k` on whole vectors of `V` first (called from a
/// function compiled for `V`'s instruction set), then lane by lane: each lane's verdict is
/// [`lane_verdict`]'s, the same operations on a vector's lanes as on one f64.
///
/// # Safety
/// `V`'s instruction set must be present.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn certify_vectors<V: crate::lanes_x86::Vector, K: LaneE>(
    o: BlockOpts,
    r: BlockRay,
    k: K,
    c: [&[f64]; 9],
    out: &mut [bool],
    mark: &mut [f64],
) {
    let n = out.len();
    assert!(mark.len() == n && c.iter().all(|col| col.len() == n), "certify: columns of another length");
    let whole = n - n % V::N;
    let (ro, rd) = (r.o.map(V::splat), r.d.map(V::splat));
    let (one, zero) = (V::splat(1.0), V::splat(0.0));
    let mut near = false;
    let mut i = 0;
    while i < whole {
        // SAFETY: i + N <= n for every column (checked above); the caller's contract
        let v: [[V; 3]; 3] =
            std::array::from_fn(|p| std::array::from_fn(|a| unsafe { V::load(c[3 * p + a].as_ptr().add(i)) }));
        let (ok, again) = lane_verdict(o, k, ro, rd, v);
        let bits = V::bits(ok);
        for (j, x) in out[i..i + V::N].iter_mut().enumerate() {
            *x = bits >> j & 1 != 0;
        }
        // SAFETY: as the loads
        unsafe { V::select(again, one, zero).store(mark.as_mut_ptr().add(i)) };
        near |= V::bits(again) != 0;
        i += V::N;
    }
    certify_lanes(o, r, k, c, out, mark, whole);
    if near {
        certify_near(o, r, k, c, out, mark, 0..whole);
    }
}

/// [`certify`] with the lanes' constants from `k`, lane by lane from lane `from` on (the lanes
/// before are the caller's).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn certify_lanes<K: LaneE>(
    o: BlockOpts,
    r: BlockRay,
    k: K,
    c: [&[f64]; 9],
    out: &mut [bool],
    mark: &mut [f64],
    from: usize,
) {
    assert_eq!(mark.len(), out.len(), "certify: scratch of another length");
    let mut near = false;
    for i in from..out.len() {
        let v = tri_at(c, i);
        let (ok, again) = lane_verdict(o, k, r.o, r.d, v);
        out[i] = ok;
        mark[i] = if again { 1.0 } else { 0.0 };
        near |= again;
    }
    if near {
        certify_near(o, r, k, c, out, mark, from..out.len());
    }
}

/// Lane `i`'s triangle from the nine coordinate columns.
#[inline(always)]
fn tri_at(c: [&[f64]; 9], i: usize) -> [[f64; 3]; 3] {
    std::array::from_fn(|p| std::array::from_fn(|a| c[3 * p + a][i]))
}

/// The lanes of `range` marked in `mark` (they met conditions (2) and (3) but not the one
/// quotient check): the three quotient checks one by one.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn certify_near<K: LaneE>(
    o: BlockOpts,
    r: BlockRay,
    k: K,
    c: [&[f64]; 9],
    out: &mut [bool],
    mark: &[f64],
    range: std::ops::Range<usize>,
) {
    let (u, eta, max) = (o.em.u, o.em.eta, o.em.max);
    let recip = o.div == DivMode::RecipMul;
    for i in range {
        if mark[i] != 0.0 {
            let v = tri_at(c, i);
            let (_, d, [up, vp, tp], e) = lane_cleared(o, k, r.o, r.d, v);
            out[i] = !(quot_may_overflow(recip, u, eta, max, tp, e[3], e[0], d)
                | quot_may_overflow(recip, u, eta, max, up, e[1], e[0], d)
                | quot_may_overflow(recip, u, eta, max, vp, e[2], e[0], d));
        }
    }
}

/// One lane's (or each lane of a vector's) certificate and whether it takes the three quotient
/// checks one by one ([`certify`]): certified when conditions (2) and (3) hold and the one
/// quotient check on the largest numerator magnitude max(|t'|, |u'|, |v'|) with the largest of
/// its three constants passes; taken again when (2) and (3) hold, that check fails and the
/// lane is not hopeless — its largest quotient surely leaves the range (|num| >= max·|det|,
/// with room), or its reciprocal check fails (the same `1/denom <= max` test, on the same d,
/// is in each of the three): such a lane fails the three checks too (leaving a lane
/// uncertified is always safe). Where (2) and (3) hold no value is NaN, so the maximum's
/// treatment of NaN (f64's or `maxpd`'s) does not reach the verdict.
#[inline(always)]
fn lane_verdict<L: Lane, K: LaneE>(o: BlockOpts, k: K, ro: [L; 3], rd: [L; 3], v: [[L; 3]; 3]) -> (L::M, L::M) {
    let (u, eta, max) = (o.em.u, o.em.eta, o.em.max);
    let recip = o.div == DivMode::RecipMul;
    let (cleared, d, [up, vp, tp], e) = lane_cleared(o, k, ro, rd, v);
    let larger = |a: L, b: L| L::select(a.gt(b), a, b);
    let x = larger(larger(tp.abs(), up.abs()), vp.abs());
    let e_num = larger(larger(e[3], e[1]), e[2]);
    let over = quot_may_overflow(recip, u, eta, max, x, e_num, e[0], d);
    let c = L::splat;
    let hopeless = x.ge(c(max) * (d + e[0]) * c(1.0 + HOPELESS)) | (L::mask(recip) & !recip_fits(max, d));
    (cleared & !over, cleared & over & !hopeless)
}

/// Lane `i`'s (or each lane of a vector's) conditions (2) and (3) of the module documentation
/// (not valid, every compared quantity clear of its constant), its `d = |det| − E_det`, its
/// numerators u', v', t' and its constants E (det, u', v', t', u' + v') from `k`.
#[inline(always)]
fn lane_cleared<L: Lane, K: LaneE>(
    o: BlockOpts,
    k: K,
    ro: [L; 3],
    rd: [L; 3],
    v: [[L; 3]; 3],
) -> (L::M, L, [L; 3], [L; 5]) {
    let [det, up, vp, tp, uv] = values_of(ro, rd, v);
    let e = k.of(ro, rd, v);
    let thr = L::splat(o.det_threshold);
    let zero = L::splat(0.0);
    let det_q = if o.cull == Cull::Backface { det - thr } else { det.abs() - thr };
    let pos = det.gt(zero);
    let sgn = |x: L| L::select(pos, x, -x);
    let valid = det_q.gt(zero) & sgn(up).ge(zero) & sgn(vp).ge(zero) & sgn(det - uv).ge(zero) & sgn(tp).ge(zero);
    let clear = |x: L, e: L| x.abs().gt(e);
    let cleared = clear(det_q, e[0])
        & clear(det, e[0])
        & clear(up, e[1])
        & clear(vp, e[2])
        & clear(det - uv, e[0] + e[4])
        & clear(tp, e[3]);
    (!valid & cleared, det.abs() - e[0], [up, vp, tp], e)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bound::RtiBound;
    use crate::rng::SplitMix64;

    /// `values` is `RtiBound::new`'s `v` bit for bit (the filter's lane values are the per-test
    /// bound's own), on ordinary, tiny, huge, zero and non-finite inputs.
    #[test]
    fn values_are_the_bounds() {
        let mut r = SplitMix64::new(7);
        let em = crate::format::ErrorModel { u: 0.0, eta: 0.0, add_eta: 0.0, max: f64::MAX };
        let x = |r: &mut SplitMix64| match r.below(8) {
            0 => 0.0,
            1 => -0.0,
            2 => f64::INFINITY,
            3 => f64::NAN,
            4 => r.range(-1.0, 1.0) * 1e-300,
            5 => r.range(-1.0, 1.0) * 1e300,
            _ => r.range(-4.0, 4.0),
        };
        for _ in 0..20000 {
            let o = std::array::from_fn(|_| x(&mut r));
            let d = std::array::from_fn(|_| x(&mut r));
            let v = std::array::from_fn(|_| std::array::from_fn(|_| x(&mut r)));
            let b = RtiBound::<f64>::new(em, DivMode::Divide, o, d, v);
            let want = [b.det.v, b.up.v, b.vp.v, b.tp.v, b.uv.v];
            let got = values(o, d, v);
            for k in 0..5 {
                assert!(got[k].to_bits() == want[k].to_bits() || (got[k].is_nan() && want[k].is_nan()), "{k}");
            }
        }
    }

    /// The per-lane theorem itself, lane by lane: wherever a block's per-lane constants exist
    /// (its range check holds), every lane's per-test `err()` of det, u', v', t' and u' + v' is
    /// at most `G·m + H` of its magnitudes, `|v| <= m` and `|v| + e <= max`; on scene-like blocks, blocks of
    /// edge values (±0, subnormals of the format and of binary64, powers of two, integers that
    /// tie, values near the format's largest) and mixed ones, in coarse formats (binary16,
    /// bfloat16, e8m7, e5m10 under FTZ, e4m3, e2m1) and the division modes. Also: the blocks
    /// tried have their constants (the range check passes) often enough.
    #[test]
    #[allow(clippy::needless_range_loop)] // lanes of nine columns
    fn every_lane_error_is_within_its_lane_constant() {
        let mut r = SplitMix64::new(21);
        let mut blocks_with = 0;
        for name in ["fp16", "bf16", "e8m7", "e5m10:ftz", "e4m3", "e2m1"] {
            let f: crate::AnyFormat = name.parse().unwrap();
            let em = crate::with_format!(f, |f| crate::Format::error_model(&f));
            let q = |x: f64| -> f64 {
                crate::with_format!(f, |f| crate::Format::to_f64(&f, crate::Format::from_f64(&f, x)))
            };
            assert!(em.u >= LANE_U, "{name}");
            for round in 0..300 {
                let kind = round % 3;
                let x = |r: &mut SplitMix64, scale: f64| {
                    let v = match (kind, r.below(10)) {
                        (0, _) | (2, 0..=6) => r.range(-2.0, 2.0) * scale,
                        (_, 0) => 0.0,
                        (_, 1) => -0.0,
                        (_, 2) => 2f64.powi(-(r.below(30) as i32)) * r.range(-1.0, 1.0).signum(),
                        (_, 3) => f64::from_bits(r.next_u64() & 0x000f_ffff_ffff_ffff),
                        (_, 4) => em.max * r.range(-1.0, 1.0) * 2f64.powi(-(r.below(4) as i32)),
                        (_, 5) => em.eta * (r.below(64) as f64) * r.range(-1.0, 1.0).signum(),
                        _ => (r.below(9) as f64) - 4.0,
                    };
                    q(v)
                };
                let n = 1 + r.below(40) as usize;
                let o = BlockOpts {
                    em,
                    div: if round % 2 == 0 { DivMode::Divide } else { DivMode::RecipMul },
                    cull: Cull::TwoSided,
                    det_threshold: 0.0,
                };
                let ray = BlockRay {
                    o: std::array::from_fn(|_| x(&mut r, 1.0)),
                    d: std::array::from_fn(|_| x(&mut r, 1.0)),
                    tmin: 0.0,
                    tmax: f64::INFINITY,
                };
                let base: [f64; 3] = std::array::from_fn(|_| x(&mut r, 1.0));
                let cols: Vec<Vec<f64>> = (0..9)
                    .map(|k| {
                        (0..n)
                            .map(|_| if kind == 0 { q(base[k % 3] + x(&mut r, 0.05)) } else { x(&mut r, 1.0) })
                            .collect()
                    })
                    .collect();
                let c: [&[f64]; 9] = std::array::from_fn(|k| &cols[k][..]);
                let (ve, ae, big, nan) = maxima(ray, c);
                if nan {
                    continue;
                }
                let Some(l) = lane_consts(o, ray, big, ve, ae) else { continue };
                blocks_with += 1;
                for i in 0..n {
                    let v: [[f64; 3]; 3] = std::array::from_fn(|p| std::array::from_fn(|a| c[3 * p + a][i]));
                    let b = RtiBound::<f64>::new(em, o.div, ray.o, ray.d, v);
                    let m = lane_magnitudes(ray.o, ray.d, v);
                    let sig = [b.det, b.up, b.vp, b.tp, b.uv];
                    for k in 0..5 {
                        let e = l.g[k] * m[k] + l.h[k];
                        assert!(sig[k].v.abs() <= m[k], "{name} signal {k}: |v| {} > m {}", sig[k].v, m[k]);
                        assert!(sig[k].err() <= e, "{name} signal {k} lane {i}: err {} > G·m + H = {e}", sig[k].err());
                        // the range check's (the quotients' own overflow is condition (4)'s)
                        assert!(sig[k].v.abs() + sig[k].e <= em.max, "{name} signal {k} lane {i} out of range");
                    }
                }
            }
        }
        assert!(blocks_with > 900, "only {blocks_with} blocks had per-lane constants");
    }
}
