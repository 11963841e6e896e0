//! Error bounds of the RTI datapath, written next to the arithmetic they bound (pbrt-v4 style,
//! but as a per-case running bound rather than a worst case).
//!
//! Model of one rounded operation of a format (see [`ErrorModel`]):
//! `|fl(x ∘ y) − (x ∘ y)| <= u·|fl(x ∘ y)| + eta`, for a multiply or divide, and with
//! `add_eta` instead of `eta` for an add/subtract (IEEE gradual underflow adds exactly in the
//! subnormal range, fixed point adds exactly; FTZ can lose up to the smallest normal). This holds
//! whenever no magnitude exceeds `max`.
//!
//! [`RtiBound`] mirrors the datapath of [`crate::rti`] operation for operation, carrying for each
//! signal its exact value `v` (evaluated in f64), the sum of absolute monomials `a`, and an upper
//! bound `e` on |computed − exact| for the format:
//! - input:      e = 0 (inputs are already in the format; the reference sees the same values)
//! - x ± y:      e = ex + ey + u·(|x ± y| + ex + ey) + add_eta
//! - x × y:      e = |x|·ey + |y|·ex + ex·ey + u·(|x·y| + …) + eta
//! - t = t'/det: with D = |det| − e_det > 0, |t'ₘ/detₘ − t| <= (e_t' + |t|·e_det) / D =: Δ₁; then
//!   recip-mul adds (2u + u²)·(|t| + Δ₁) + eta·(|t'| + e_t')·(1 + u) + eta, divide adds u·(|t| + Δ₁) + eta.
//!
//! The f64 evaluation of `v` is itself off by at most ~10·2⁻⁵³·a; `F64_SLACK·a` is added to every
//! bound. A case is *decisive* when every sign the validity test reads is larger than its bound:
//! then the model's hit/miss must equal the exact one, and |t_model − t| <= `t_err`.

use crate::format::{DivMode, ErrorModel};
use crate::lanes::Lane;
use crate::rti::Cull;

/// Relative slack covering the f64 evaluation of the exact values.
pub const F64_SLACK: f64 = 1.0 / (1u64 << 45) as f64;

/// A signal's exact value, its absolute-monomial sum and its error bound (generic over [`Lane`]; `f64` is one case).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Bnd<T = f64> {
    /// Exact value (f64 evaluation).
    pub v: T,
    /// Sum of the absolute values of its monomials.
    pub a: T,
    /// Upper bound on |computed − exact| in the format.
    pub e: T,
}

impl<T: Lane> Bnd<T> {
    /// Bound for use in decisions: `e` plus the f64 evaluation slack.
    #[inline(always)]
    pub fn err(&self) -> T {
        self.e + T::splat(F64_SLACK) * self.a
    }
}

/// The error model's constants as lanes, and the running overflow flag.
pub(crate) struct Ctx<T: Lane> {
    u: T,
    eta: T,
    add_eta: T,
    max: T,
    pub(crate) overflow: T::M,
    /// Magnitude mode (the static filter, `crate::bound_filter`): every value is an upper bound
    /// on a magnitude, so a difference adds (|x − y| <= |x| + |y|); the error terms and the
    /// range check are the same formulas.
    magnitudes: bool,
}

// Every step is branch-free (flags or-ed, results selected): the same code serves one case
// and vectorises when a loop runs it over columns (`verdict_block`).
impl<T: Lane> Ctx<T> {
    /// The constants of `em`, no overflow yet; `magnitudes`: see the field.
    #[inline(always)]
    pub(crate) fn new(em: ErrorModel, magnitudes: bool) -> Self {
        Ctx {
            u: T::splat(em.u),
            eta: T::splat(em.eta),
            add_eta: T::splat(em.add_eta),
            max: T::splat(em.max),
            overflow: T::mask(false),
            magnitudes,
        }
    }
    #[inline(always)]
    pub(crate) fn check(&mut self, b: Bnd<T>) -> Bnd<T> {
        let m = b.v.abs() + b.e;
        // NaN or above the largest magnitude
        self.overflow = self.overflow | !m.le(self.max);
        b
    }
    #[inline(always)]
    pub(crate) fn input(&mut self, x: T) -> Bnd<T> {
        self.check(Bnd { v: x, a: x.abs(), e: T::splat(0.0) })
    }
    #[inline(always)]
    fn addsub(&mut self, x: Bnd<T>, y: Bnd<T>, sub: bool) -> Bnd<T> {
        let v = if sub && !self.magnitudes { x.v - y.v } else { x.v + y.v };
        let e0 = x.e + y.e;
        let e = e0 + self.u * (v.abs() + e0) + self.add_eta;
        self.check(Bnd { v, a: x.a + y.a, e })
    }
    #[inline(always)]
    pub(crate) fn add(&mut self, x: Bnd<T>, y: Bnd<T>) -> Bnd<T> {
        self.addsub(x, y, false)
    }
    #[inline(always)]
    fn sub(&mut self, x: Bnd<T>, y: Bnd<T>) -> Bnd<T> {
        self.addsub(x, y, true)
    }
    /// The difference of two inputs whose value is `v` and monomial sum `a`, as [`Self::sub`]
    /// of two inputs bounds it (magnitude mode: `v` the largest |x − y| over a block's lanes).
    #[inline(always)]
    pub(crate) fn input_difference(&mut self, v: T, a: T) -> Bnd<T> {
        let e0 = T::splat(0.0);
        let e = e0 + self.u * (v.abs() + e0) + self.add_eta;
        self.check(Bnd { v, a, e })
    }
    #[inline(always)]
    fn mul(&mut self, x: Bnd<T>, y: Bnd<T>) -> Bnd<T> {
        let v = x.v * y.v;
        let e0 = x.v.abs() * y.e + y.v.abs() * x.e + x.e * y.e;
        let e = e0 + self.u * (v.abs() + e0) + self.eta;
        self.check(Bnd { v, a: x.a * y.a, e })
    }
    /// The bound of `num / det` (t = t'/det and the barycentrics): see the module docs; +∞
    /// when det is not clear of zero (`ok` false: `denom = |det| − e_det <= 0`).
    #[inline(always)]
    fn quot(&mut self, num: Bnd<T>, det: Bnd<T>, denom: T, ok: T::M, div: DivMode) -> T {
        let q = num.v / det.v;
        let d1 = (num.err() + q.abs() * det.err()) / denom;
        let mag = q.abs() + d1;
        let u = self.u;
        let one = T::splat(1.0);
        let extra = match div {
            DivMode::RecipMul => {
                self.overflow = self.overflow | (ok & (one / denom).gt(self.max));
                (T::splat(2.0) * u + u * u) * mag + self.eta * (num.v.abs() + num.err()) * (one + u) + self.eta
            }
            DivMode::Divide => u * mag + self.eta,
        };
        self.overflow = self.overflow | (ok & (mag + extra).gt(self.max));
        T::select(ok, d1 + extra, T::splat(f64::INFINITY))
    }
}

/// The operations of the RTI datapath's cross and dot products, and the two products in the
/// datapath's order (the order every running bound of this crate must follow: the per-test
/// bound, the static filter's block and per-lane constants).
pub(crate) trait Steps {
    /// One signal.
    type S: Copy;
    /// x × y.
    fn mul(&mut self, x: Self::S, y: Self::S) -> Self::S;
    /// x + y.
    fn add(&mut self, x: Self::S, y: Self::S) -> Self::S;
    /// x − y.
    fn sub(&mut self, x: Self::S, y: Self::S) -> Self::S;
    /// a × b: each component's two products, then their differences.
    #[inline(always)]
    fn cross(&mut self, a: [Self::S; 3], b: [Self::S; 3]) -> [Self::S; 3] {
        let xa = self.mul(a[1], b[2]);
        let xb = self.mul(a[2], b[1]);
        let ya = self.mul(a[2], b[0]);
        let yb = self.mul(a[0], b[2]);
        let za = self.mul(a[0], b[1]);
        let zb = self.mul(a[1], b[0]);
        [self.sub(xa, xb), self.sub(ya, yb), self.sub(za, zb)]
    }
    /// a · b: the three products, then (x + y) + z.
    #[inline(always)]
    fn dot(&mut self, a: [Self::S; 3], b: [Self::S; 3]) -> Self::S {
        let x = self.mul(a[0], b[0]);
        let y = self.mul(a[1], b[1]);
        let z = self.mul(a[2], b[2]);
        let xy = self.add(x, y);
        self.add(xy, z)
    }
}

impl<T: Lane> Steps for Ctx<T> {
    type S = Bnd<T>;
    #[inline(always)]
    fn mul(&mut self, x: Bnd<T>, y: Bnd<T>) -> Bnd<T> {
        Ctx::mul(self, x, y)
    }
    #[inline(always)]
    fn add(&mut self, x: Bnd<T>, y: Bnd<T>) -> Bnd<T> {
        Ctx::add(self, x, y)
    }
    #[inline(always)]
    fn sub(&mut self, x: Bnd<T>, y: Bnd<T>) -> Bnd<T> {
        Ctx::sub(self, x, y)
    }
}

/// Running error bounds of every RTI signal the decision and the outputs depend on (generic over [`Lane`]; `f64` is one case).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RtiBound<T: Lane = f64> {
    /// det = e1·(d × e2).
    pub det: Bnd<T>,
    /// u' = s·(d × e2).
    pub up: Bnd<T>,
    /// v' = d·(s × e1).
    pub vp: Bnd<T>,
    /// t' = e2·(s × e1).
    pub tp: Bnd<T>,
    /// u' + v'.
    pub uv: Bnd<T>,
    /// Bound on |t_model − t| (infinite when det is not decisive).
    pub t_err: T,
    /// Bound on |u_model − u|.
    pub u_err: T,
    /// Bound on |v_model − v|.
    pub v_err: T,
    /// Some magnitude may exceed the format's range: no bound holds.
    pub overflow: T::M,
}

/// The exact decision the bound predicts and whether the model must reproduce it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Verdict<M = bool> {
    /// Every compared quantity is farther from its threshold than its error bound.
    pub decisive: M,
    /// The exact (f64-evaluated) hit decision.
    pub hit: M,
}

impl<T: Lane> RtiBound<T> {
    /// Bounds for one ray (origin, direction) and triangle given as the format's values in f64.
    #[inline(always)]
    pub fn new(em: ErrorModel, div: DivMode, o: [T; 3], d: [T; 3], v: [[T; 3]; 3]) -> Self {
        let mut c = Ctx::new(em, false);
        // written out (no array::map / from_fn): the lanes stay in registers
        let o = [c.input(o[0]), c.input(o[1]), c.input(o[2])];
        let d = [c.input(d[0]), c.input(d[1]), c.input(d[2])];
        let v0 = [c.input(v[0][0]), c.input(v[0][1]), c.input(v[0][2])];
        let v1 = [c.input(v[1][0]), c.input(v[1][1]), c.input(v[1][2])];
        let v2 = [c.input(v[2][0]), c.input(v[2][1]), c.input(v[2][2])];
        let e1 = [c.sub(v1[0], v0[0]), c.sub(v1[1], v0[1]), c.sub(v1[2], v0[2])];
        let e2 = [c.sub(v2[0], v0[0]), c.sub(v2[1], v0[1]), c.sub(v2[2], v0[2])];
        let s = [c.sub(o[0], v0[0]), c.sub(o[1], v0[1]), c.sub(o[2], v0[2])];
        let p = c.cross(d, e2);
        let q = c.cross(s, e1);
        let det = c.dot(e1, p);
        let up = c.dot(s, p);
        let vp = c.dot(d, q);
        let tp = c.dot(e2, q);
        let uv = c.add(up, vp);
        let denom = det.v.abs() - det.err();
        // det not clear of zero (denom <= 0): the quotient is unbounded
        let ok = !denom.le(T::splat(0.0));
        let t_err = c.quot(tp, det, denom, ok, div);
        let u_err = c.quot(up, det, denom, ok, div);
        let v_err = c.quot(vp, det, denom, ok, div);
        Self { det, up, vp, tp, uv, t_err, u_err, v_err, overflow: c.overflow }
    }

    /// Exact t (f64 evaluation).
    #[inline(always)]
    pub fn t(&self) -> T {
        self.tp.v / self.det.v
    }

    /// The exact decision and whether it is decisive for the model with these options.
    #[inline(always)]
    pub fn verdict(&self, cull: Cull, det_threshold: f64, tmin: f64, tmax: f64) -> Verdict<T::M> {
        let clear = |x: T, b: T| x.abs().gt(b);
        let zero = T::splat(0.0);
        let thr = T::splat(det_threshold);
        let det_q = match cull {
            Cull::TwoSided => self.det.v.abs() - thr,
            Cull::Backface => self.det.v - thr,
        };
        let pos = self.det.v.gt(zero);
        let sgn = |x: T| T::select(pos, x, -x);
        let det_ok = det_q.gt(zero);
        let u_ok = sgn(self.up.v).ge(zero);
        let v_ok = sgn(self.vp.v).ge(zero);
        let uv_ok = sgn(self.det.v - self.uv.v).ge(zero);
        let t_ok = sgn(self.tp.v).ge(zero);
        let valid = det_ok & u_ok & v_ok & uv_ok & t_ok;
        let decisive = !self.overflow
            & clear(det_q, self.det.err())
            & clear(self.det.v, self.det.err())
            & clear(self.up.v, self.up.err())
            & clear(self.vp.v, self.vp.err())
            & clear(self.det.v - self.uv.v, self.det.err() + self.uv.err())
            & clear(self.tp.v, self.tp.err());
        let t = self.t();
        let (lo, hi) = (T::splat(tmin), T::splat(tmax));
        // a valid case also decides t against the finite ends of [tmin, tmax] (an infinite
        // or NaN end decides every finite t alike: no clearance from t's error is needed)
        let hit = valid & t.ge(lo) & t.le(hi);
        let t_clear = (T::mask(!tmin.is_finite()) | clear(t - lo, self.t_err))
            & (T::mask(!tmax.is_finite()) | clear(t - hi, self.t_err));
        Verdict { decisive: decisive & (!valid | t_clear), hit }
    }
}

/// One ray against a block of triangles: each lane's [`RtiBound::new`] and
/// [`RtiBound::verdict`], the same code as one case, run over coordinate columns in f64 lanes.
#[derive(Clone, Copy, Debug)]
pub struct BlockRay {
    /// Origin (the format's values in f64).
    pub o: [f64; 3],
    /// Direction.
    pub d: [f64; 3],
    /// Smallest accepted t.
    pub tmin: f64,
    /// Largest accepted t.
    pub tmax: f64,
}

/// The options every lane of a block shares.
#[derive(Clone, Copy, Debug)]
pub struct BlockOpts {
    /// The format's rounding model.
    pub em: ErrorModel,
    /// Division mode.
    pub div: DivMode,
    /// Face culling.
    pub cull: Cull,
    /// det threshold (the format's value in f64).
    pub det_threshold: f64,
}

/// [`verdict_block`] as one loop over the lanes that the compiler vectorises (AVX-512F lanes,
/// AVX2 lanes or the baseline, the widest within `cap`); bit-identical to it (same operations,
/// same order; the level changes only the instructions).
///
/// # Panics
/// If the column lengths differ.
pub fn verdict_block_loop(
    cap: crate::simd::Kernel,
    opts: BlockOpts,
    ray: BlockRay,
    tris: [&[f64]; 9],
    decisive: &mut [bool],
    hit: &mut [bool],
    t_err: &mut [f64],
) {
    run_block(
        cap,
        (opts, ray, tris),
        (decisive, hit, t_err),
        #[cfg(target_arch = "x86_64")]
        (block_avx512, block_avx2),
    )
}

/// Per lane: the verdict's `decisive` and `hit`, and the bound `t_err`, for `ray` against
/// triangle columns x0 y0 z0 x1 y1 z1 x2 y2 z2, on explicit vector registers
/// ([`crate::lanes_x86`]: the bound written in [`crate::lanes::Lane`] on 8 AVX-512F or 4 AVX2
/// binary64 lanes, the remainder lane by lane) or the baseline (the widest the machine has
/// within `cap`); bit-identical to [`RtiBound::new`] + [`RtiBound::verdict`] on each lane and
/// to [`verdict_block_loop`], the loop the compiler vectorises (measured beside it by `raypipe
/// speed`: 1.35–1.45× its rate on AVX-512F, about equal on AVX2; docs/speed.md).
///
/// # Panics
/// If the column lengths differ.
pub fn verdict_block(
    cap: crate::simd::Kernel,
    opts: BlockOpts,
    ray: BlockRay,
    tris: [&[f64]; 9],
    decisive: &mut [bool],
    hit: &mut [bool],
    t_err: &mut [f64],
) {
    run_block(
        cap,
        (opts, ray, tris),
        (decisive, hit, t_err),
        #[cfg(target_arch = "x86_64")]
        (explicit_avx512, explicit_avx2),
    )
}

/// A block body compiled for one instruction set (called after detecting it).
#[cfg(target_arch = "x86_64")]
type BlockFn = unsafe fn(BlockOpts, BlockRay, [&[f64]; 9], &mut [bool], &mut [bool], &mut [f64]);

/// The column checks, then `avx512` or `avx2` (the widest the machine has within `cap`, and
/// this thread's and the process's caps), else the baseline loop.
fn run_block(
    cap: crate::simd::Kernel,
    (opts, ray, tris): (BlockOpts, BlockRay, [&[f64]; 9]),
    (decisive, hit, t_err): (&mut [bool], &mut [bool], &mut [f64]),
    #[cfg(target_arch = "x86_64")] (avx512, avx2): (BlockFn, BlockFn),
) {
    use crate::simd::F64Lanes;
    let n = hit.len();
    assert!(decisive.len() == n && t_err.len() == n && tris.iter().all(|c| c.len() == n), "column lengths differ");
    match crate::simd::f64_lanes(cap) {
        // SAFETY: AVX-512F is present (f64_lanes detected it)
        #[cfg(target_arch = "x86_64")]
        F64Lanes::Avx512 => unsafe { avx512(opts, ray, tris, decisive, hit, t_err) },
        // SAFETY: AVX2 is present (f64_lanes detected it)
        #[cfg(target_arch = "x86_64")]
        F64Lanes::Avx2 => unsafe { avx2(opts, ray, tris, decisive, hit, t_err) },
        _ => block_body(opts, ray, tris, decisive, hit, t_err),
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn explicit_avx512(o: BlockOpts, r: BlockRay, c: [&[f64]; 9], dec: &mut [bool], hit: &mut [bool], te: &mut [f64]) {
    explicit_body::<crate::lanes_x86::F64x8>(o, r, c, dec, hit, te)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn explicit_avx2(o: BlockOpts, r: BlockRay, c: [&[f64]; 9], dec: &mut [bool], hit: &mut [bool], te: &mut [f64]) {
    explicit_body::<crate::lanes_x86::F64x4>(o, r, c, dec, hit, te)
}

/// The bound on `V::N` lanes at a time, the remainder lane by lane (inlined into a function
/// compiled with `V`'s feature).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn explicit_body<V: crate::lanes_x86::Vector>(
    o: BlockOpts,
    r: BlockRay,
    c: [&[f64]; 9],
    dec: &mut [bool],
    hit: &mut [bool],
    te: &mut [f64],
) {
    let n = hit.len();
    let full = n / V::N * V::N;
    let sp = V::splat;
    let (ro, rd) = ([sp(r.o[0]), sp(r.o[1]), sp(r.o[2])], [sp(r.d[0]), sp(r.d[1]), sp(r.d[2])]);
    for i in (0..full).step_by(V::N) {
        // SAFETY: i + N <= n = every column's length; the caller has V's feature
        let ld = |k: usize| unsafe { V::load(c[k].as_ptr().add(i)) };
        let v = [[ld(0), ld(1), ld(2)], [ld(3), ld(4), ld(5)], [ld(6), ld(7), ld(8)]];
        let b = RtiBound::<V>::new(o.em, o.div, ro, rd, v);
        let vd = b.verdict(o.cull, o.det_threshold, r.tmin, r.tmax);
        // SAFETY: as above
        unsafe { b.t_err.store(te.as_mut_ptr().add(i)) };
        let (d, h) = (V::bits(vd.decisive), V::bits(vd.hit));
        for k in 0..V::N {
            dec[i + k] = d >> k & 1 == 1;
            hit[i + k] = h >> k & 1 == 1;
        }
    }
    for i in full..n {
        (dec[i], hit[i], te[i]) = lane(o, r, c, i);
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn block_avx512(o: BlockOpts, r: BlockRay, c: [&[f64]; 9], dec: &mut [bool], hit: &mut [bool], te: &mut [f64]) {
    block_body(o, r, c, dec, hit, te)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn block_avx2(o: BlockOpts, r: BlockRay, c: [&[f64]; 9], dec: &mut [bool], hit: &mut [bool], te: &mut [f64]) {
    block_body(o, r, c, dec, hit, te)
}

#[inline(always)]
fn block_body(o: BlockOpts, r: BlockRay, c: [&[f64]; 9], dec: &mut [bool], hit: &mut [bool], te: &mut [f64]) {
    let n = hit.len();
    // one case per iteration, branch-free: the loop vectoriser carries 8 (AVX-512F) or 4
    // (AVX2) iterations per instruction
    for i in 0..n {
        (dec[i], hit[i], te[i]) = lane(o, r, c, i);
    }
}

/// Lane `i` of a block: the verdict's `decisive` and `hit`, and `t_err` ([`RtiBound::new`] and
/// [`RtiBound::verdict`] of that triangle).
#[inline(always)]
pub(crate) fn lane(o: BlockOpts, r: BlockRay, c: [&[f64]; 9], i: usize) -> (bool, bool, f64) {
    let v = [[c[0][i], c[1][i], c[2][i]], [c[3][i], c[4][i], c[5][i]], [c[6][i], c[7][i], c[8][i]]];
    let b = RtiBound::<f64>::new(o.em, o.div, r.o, r.d, v);
    let vd = b.verdict(o.cull, o.det_threshold, r.tmin, r.tmax);
    (vd.decisive, vd.hit, b.t_err)
}

#[cfg(test)]
mod tests {
    use super::{Bnd, Ctx};

    fn ctx() -> Ctx<f64> {
        // binary32's unit roundoff, and error floors large enough to show in every sum
        Ctx {
            u: 2f64.powi(-24),
            eta: 2f64.powi(-20),
            add_eta: 2f64.powi(-21),
            max: 1e30,
            overflow: false,
            magnitudes: false,
        }
    }

    /// Each step adds exactly the error terms the module documentation states, worked by hand:
    /// x ± y: e = ex + ey + u·(|x ± y| + ex + ey) + add_eta; x × y: e = |x|·ey + |y|·ex + ex·ey
    /// + u·(|x·y| + that) + eta; the monomial sums add (±) and multiply (×).
    #[test]
    fn each_step_adds_the_documented_error_terms() {
        let mut c = ctx();
        let (u, eta, add_eta) = (c.u, c.eta, c.add_eta);
        let x = Bnd { v: 1.5, a: 1.5, e: 0.25 };
        let y = Bnd { v: -0.5, a: 0.75, e: 0.125 };
        let s = c.add(x, y);
        assert_eq!((s.v, s.a), (1.0, 2.25));
        assert_eq!(s.e, 0.375 + u * (1.0 + 0.375) + add_eta);
        let d = c.sub(x, y);
        assert_eq!((d.v, d.a), (2.0, 2.25));
        assert_eq!(d.e, 0.375 + u * (2.0 + 0.375) + add_eta);
        let p = c.mul(x, y);
        // e0 = 1.5·0.125 + 0.5·0.25 + 0.25·0.125 = 0.1875 + 0.125 + 0.03125
        let e0 = 0.34375;
        assert_eq!((p.v, p.a), (-0.75, 1.125));
        assert_eq!(p.e, e0 + u * (0.75 + e0) + eta);
        assert!(!c.overflow);
    }

    /// The quotient's bound, worked by hand from the module documentation (every value below
    /// is exact in binary64, so the order of the operations does not matter): num = 3 ± 0.5,
    /// det = −2 ± 0.25, D = 1.75: q = −1.5, Δ₁ = (0.5 + 1.5·0.25) / 1.75 = 0.5, |q| + Δ₁ = 2;
    /// recip-mul adds (2u + u²)·2 + eta·(3 + 0.5)·(1 + u) + eta, divide adds u·2 + eta; a det
    /// not clear of zero gives +∞; 1/D and |q| + Δ₁ + extra above max raise the overflow flag.
    #[test]
    fn the_quotient_bound_is_the_documented_one() {
        use crate::format::DivMode;
        let num = Bnd { v: 3.0, a: 0.0, e: 0.5 };
        let det = Bnd { v: -2.0, a: 0.0, e: 0.25 };
        let mut c = ctx();
        let (u, eta) = (c.u, c.eta);
        let r = c.quot(num, det, 1.75, true, DivMode::RecipMul);
        assert_eq!(r, 0.5 + (2.0 * u + u * u) * 2.0 + eta * 3.5 * (1.0 + u) + eta);
        assert!(!c.overflow);
        let r = c.quot(num, det, 1.75, true, DivMode::Divide);
        assert_eq!(r, 0.5 + u * 2.0 + eta);
        assert!(!c.overflow);
        assert_eq!(c.quot(num, det, -0.5, false, DivMode::Divide), f64::INFINITY);
        assert!(!c.overflow, "no bound, no overflow claim");
        // |q| + Δ₁ + extra = 2.0… above a max of 2
        let mut c = Ctx { max: 2.0, ..ctx() };
        c.quot(num, det, 1.75, true, DivMode::Divide);
        assert!(c.overflow);
        // recip-mul: 1/D above max (D = 0.25: 4 > max 3) even where the quotient is not
        let mut c = Ctx { max: 3.0, ..ctx() };
        let small = Bnd { v: 0.125, a: 0.0, e: 0.0 };
        c.quot(small, Bnd { v: -1.0, a: 0.0, e: 0.75 }, 0.25, true, DivMode::RecipMul);
        assert!(c.overflow, "the reciprocal 1/D = 4 exceeds max");
        let mut c = Ctx { max: 3.0, ..ctx() };
        c.quot(small, Bnd { v: -1.0, a: 0.0, e: 0.75 }, 0.25, true, DivMode::Divide);
        assert!(!c.overflow, "divide forms no reciprocal");
    }

    /// The overflow flag rises when |v| + e exceeds the largest magnitude (or is NaN), even
    /// when |v| alone does not, and stays raised.
    #[test]
    fn overflow_is_flagged_by_value_plus_bound_and_stays() {
        let mut c = ctx();
        c.check(Bnd { v: 0.75e30, a: 0.75e30, e: 0.25e30 });
        assert!(!c.overflow, "|v| + e = max is not above max");
        c.check(Bnd { v: 0.75e30, a: 0.75e30, e: 0.5e30 });
        assert!(c.overflow, "|v| + e above max");
        c.check(Bnd { v: 1.0, a: 1.0, e: 0.0 });
        assert!(c.overflow, "the flag stays raised");
        let mut c = ctx();
        c.check(Bnd { v: -1.0, a: 1.0, e: 1.5e30 });
        assert!(c.overflow, "a bound alone above max");
        let mut c = ctx();
        c.check(Bnd { v: f64::NAN, a: 0.0, e: 0.0 });
        assert!(c.overflow, "NaN");
    }

    /// The verdict of a clear hit against [tmin, tmax] ends that are infinite, NaN, within t's
    /// error of t, or clear of it.
    #[test]
    fn an_infinite_or_nan_end_of_the_t_range_needs_no_clearance() {
        use super::RtiBound;
        use crate::format::{DivMode, ErrorModel};
        use crate::rti::Cull;
        // a ray along +z from z = −3 through the middle of a triangle in z = 0: t = 3, clear
        let em = ErrorModel { u: 2f64.powi(-24), eta: 2f64.powi(-140), add_eta: 2f64.powi(-149), max: 3.4e38 };
        let v = [[-1.0, -1.0, 0.0], [2.0, -1.0, 0.0], [-1.0, 2.0, 0.0]];
        let b = RtiBound::<f64>::new(em, DivMode::Divide, [0.0, 0.0, -3.0], [0.0, 0.0, 1.0], v);
        assert_eq!(b.t(), 3.0);
        assert!(b.t_err > 0.0 && b.t_err < 1e-5);
        let verdict = |tmin, tmax| {
            let vd = b.verdict(Cull::TwoSided, 0.0, tmin, tmax);
            (vd.decisive, vd.hit)
        };
        // an infinite end decides every finite t the same way; so does a NaN end (t ≥ NaN and
        // t ≤ NaN are false for every t): no clearance from t's error is asked of either
        assert_eq!(verdict(0.0, f64::INFINITY), (true, true));
        assert_eq!(verdict(f64::NEG_INFINITY, f64::INFINITY), (true, true));
        assert_eq!(verdict(0.0, f64::NAN), (true, false));
        assert_eq!(verdict(f64::NAN, 10.0), (true, false));
        // a finite end within t's error of t is not decisive; one clear of it is
        assert!(!verdict(0.0, 3.0).0);
        assert!(!verdict(3.0, 10.0).0);
        assert_eq!(verdict(2.0, 4.0), (true, true));
        assert_eq!(verdict(3.5, 4.0), (true, false));
    }

    /// The block verdict equals the scalar `RtiBound::new` + `verdict` on every lane, on every
    /// kernel this machine has (bits of `t_err` included), for ordinary and degenerate lanes.
    #[test]
    fn the_block_verdict_is_the_scalar_verdict_on_every_kernel() {
        use super::{verdict_block, BlockOpts, BlockRay, RtiBound};
        use crate::format::{DivMode, ErrorModel};
        use crate::rti::Cull;
        use crate::simd::{kernels_here, with_kernel_cap};
        let mut r = crate::rng::SplitMix64::new(3);
        let n = 37;
        // every third lane a triangle around the ray's crossing of z = 0 (a hit), a degenerate
        // one (v2 at the origin) every ninth, random ones otherwise
        let around = [-1.0, -1.0, 0.0, 2.0, -1.0, 0.0, -1.0, 2.0, 0.0];
        let cols: [Vec<f64>; 9] = std::array::from_fn(|k| {
            (0..n)
                .map(|i| match i % 9 {
                    0 | 3 | 6 => around[k] + (r.unit() - 0.5) * 0.1,
                    4 if k >= 6 => 0.0,
                    _ => r.unit() * 2.0 - 1.0,
                })
                .collect()
        });
        let em = ErrorModel { u: 2f64.powi(-24), eta: 2f64.powi(-140), add_eta: 2f64.powi(-149), max: 3.4e38 };
        let (mut seen_hit, mut seen_miss) = (false, false);
        for (cull, thr, tmin, tmax) in [
            (Cull::TwoSided, 0.0, 0.0, f64::INFINITY),
            (Cull::Backface, 1e-3, 0.5, 4.0),
            (Cull::TwoSided, 0.1, 1.0, 1.5),
        ] {
            let opts = BlockOpts { em, div: DivMode::Divide, cull, det_threshold: thr };
            let ray = BlockRay { o: [0.1, -0.2, -3.0], d: [0.05, 0.1, 1.0], tmin, tmax };
            let want: Vec<(bool, bool, u64)> = (0..n)
                .map(|i| {
                    let v = std::array::from_fn(|p| std::array::from_fn(|a| cols[3 * p + a][i]));
                    let b = RtiBound::<f64>::new(em, DivMode::Divide, ray.o, ray.d, v);
                    let vd = b.verdict(cull, thr, tmin, tmax);
                    (vd.decisive, vd.hit, b.t_err.to_bits())
                })
                .collect();
            seen_hit |= want.iter().any(|w| w.0 && w.1);
            seen_miss |= want.iter().any(|w| w.0 && !w.1);
            for k in kernels_here() {
                let (mut dec, mut hit, mut te) = (vec![false; n], vec![true; n], vec![f64::NAN; n]);
                let c: [&[f64]; 9] = std::array::from_fn(|j| cols[j].as_slice());
                with_kernel_cap(k, || verdict_block(k, opts, ray, c, &mut dec, &mut hit, &mut te));
                for i in 0..n {
                    assert_eq!((dec[i], hit[i], te[i].to_bits()), want[i], "{k:?} lane {i}");
                }
            }
        }
        assert!(seen_hit && seen_miss, "the lanes hold decisive hits and misses");
    }
}
