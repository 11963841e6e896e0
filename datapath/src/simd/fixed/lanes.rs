//! The lane arithmetic of fixed point: a format's constants ([`Lanes`]), the operations every
//! lane type implements, and the RTI, slab and op loops written once over them.

use crate::format::{Fixed, FxRound};
use crate::rti::{HitsSoa, RaysSoa, TrisSoa};
use crate::simd::select::{Kernel, SlabRays};
use crate::slab::{BoxesSoa, SlabOutSoa};
use crate::stage::Op;
use crate::Format as _;

/// The widest kernel of the fixed-point batch path (AVX-512F with AVX-512DQ: 8 i64 lanes).
pub const WIDEST_FIXED: Kernel = Kernel::Avx512;

/// The constants of one fixed-point format's lane arithmetic.
#[derive(Clone, Copy, Debug)]
pub(super) struct Lanes {
    /// Fraction bits F.
    pub(super) f: u32,
    /// 64 − w: the wrap shift.
    pub(super) sh: u32,
    /// Most negative raw value.
    pub(super) min: i64,
    /// Most positive raw value.
    pub(super) max: i64,
    /// 2^F − 1: the bits a product's shift drops.
    pub(super) low: i64,
    /// 2^(F−1) (the tie), or i64::MAX when F = 0 (no bits dropped, never a tie).
    pub(super) half: i64,
    /// The format's 1 (rounded into range), the reciprocal's numerator.
    pub(super) one: i64,
}

impl Lanes {
    /// The constants of `f`, when it has a batch path (width ≤ 32).
    pub(super) fn of(f: &Fixed) -> Option<Self> {
        let w = f.int_bits + f.frac_bits;
        (w <= 32).then(|| Self {
            f: f.frac_bits,
            sh: 64 - w,
            min: f.min_raw(),
            max: f.max_raw(),
            low: (1i64 << f.frac_bits) - 1,
            half: if f.frac_bits == 0 { i64::MAX } else { 1i64 << (f.frac_bits - 1) },
            one: f.one(),
        })
    }
}

/// Rounding modes as const parameters.
pub(super) const FLOOR: u8 = 0;
pub(super) const CEIL: u8 = 1;
pub(super) const TRUNC: u8 = 2;
pub(super) const NEAREST: u8 = 3;

pub(super) const fn round_code(r: FxRound) -> u8 {
    match r {
        FxRound::Floor => FLOOR,
        FxRound::Ceil => CEIL,
        FxRound::Trunc => TRUNC,
        FxRound::NearestEven => NEAREST,
    }
}

/// `x` if `c`, else `y` (a select, never a branch).
#[inline(always)]
pub(super) fn sel(c: bool, x: i64, y: i64) -> i64 {
    let m = -(c as i64);
    (x & m) | (y & !m)
}

/// The overflow mode applied to an exact result that fits i64.
#[inline(always)]
pub(super) fn fit<const WRAP: bool>(c: &Lanes, x: i64) -> i64 {
    if WRAP {
        (x << c.sh) >> c.sh
    } else {
        x.max(c.min).min(c.max)
    }
}

/// The rounding increment of a quotient whose floor is `q` with remainder 0 ≤ r < d, for an
/// exact value of sign `neg`: 0 or 1.
#[inline(always)]
pub(super) fn bump<const R: u8>(q: i64, r: i64, d: i64, neg: bool) -> i64 {
    let inexact = r != 0;
    (match R {
        FLOOR => false,
        CEIL => inexact,
        TRUNC => inexact & neg,
        _ => {
            let twice = r << 1;
            (twice > d) | ((twice == d) & (q & 1 == 1))
        }
    }) as i64
}

/// `a + b`, then the overflow mode.
#[inline(always)]
pub(super) fn add<const WRAP: bool>(c: &Lanes, a: i64, b: i64) -> i64 {
    fit::<WRAP>(c, a + b)
}

/// `a − b`, then the overflow mode.
#[inline(always)]
pub(super) fn sub<const WRAP: bool>(c: &Lanes, a: i64, b: i64) -> i64 {
    fit::<WRAP>(c, a - b)
}

/// `a × b / 2^F` rounded by the mode, then the overflow mode.
#[inline(always)]
pub(super) fn mul<const R: u8, const WRAP: bool>(c: &Lanes, a: i64, b: i64) -> i64 {
    // raw values are 32-bit: a signed 32 x 32 -> 64-bit multiply, exact
    let p = (a as i32 as i64) * (b as i32 as i64);
    let q = p >> c.f;
    let r = p & c.low;
    let up = match R {
        NEAREST => ((r > c.half) | ((r == c.half) & (q & 1 == 1))) as i64,
        _ => bump::<R>(q, r, 1, p < 0),
    };
    fit::<WRAP>(c, q + up)
}

/// `a / b` rounded once (see the module documentation).
#[inline(always)]
pub(super) fn div<const R: u8, const WRAP: bool, const TWO: bool>(c: &Lanes, a: i64, b: i64) -> i64 {
    let n0 = a << c.f;
    let neg_b = b < 0;
    let n = sel(neg_b, n0.wrapping_neg(), n0);
    let d0 = sel(neg_b, b.wrapping_neg(), b);
    let zero = d0 == 0;
    let d = sel(zero, 1, d0);
    let (nf, df) = (n as f64, d as f64);
    // SAFETY: |n / d| <= 2^62 (d >= 1), finite, so its floor fits i64
    let mut q: i64 = unsafe { (nf / df).floor().to_int_unchecked() };
    let mut r = n.wrapping_sub(q.wrapping_mul(d));
    if TWO {
        // SAFETY: |r / d| <= 2^11 here (see the module documentation)
        q += unsafe { (r as f64 / df).floor().to_int_unchecked::<i64>() };
        r = n.wrapping_sub(q.wrapping_mul(d));
    }
    let low = r < 0;
    q -= low as i64;
    r += sel(low, d, 0);
    let res = fit::<WRAP>(c, q + bump::<R>(q, r, d, n < 0));
    let by_zero = sel(a > 0, c.max, sel(a < 0, c.min, 0));
    sel(zero, by_zero, res)
}

/// The format's division (its mode).
#[inline(always)]
pub(super) fn divide<const R: u8, const WRAP: bool, const TWO: bool, const RECIP: bool>(
    c: &Lanes,
    a: i64,
    b: i64,
) -> i64 {
    if RECIP {
        mul::<R, WRAP>(c, a, div::<R, WRAP, TWO>(c, c.one, b))
    } else {
        div::<R, WRAP, TWO>(c, a, b)
    }
}

/// The lane operations of the RTI and operation loops: `V` holds `L` raw values, a mask is
/// a `u8` (bit j: lane j). Every operation is the scalar function of the same name above,
/// lane by lane.
pub(super) trait Ops: Copy {
    /// Lanes per vector.
    const L: usize;
    /// A vector of raw values.
    type V: Copy;
    /// The format's constants.
    fn c(&self) -> &Lanes;
    /// `col[i..i + L]`.
    fn load(&self, col: &[i64], i: usize) -> Self::V;
    /// `col[i..i + L] = v`.
    fn store(&self, col: &mut [i64], i: usize, v: Self::V);
    /// Every lane `x`.
    fn splat(&self, x: i64) -> Self::V;
    /// [`add`].
    fn add<const WRAP: bool>(&self, a: Self::V, b: Self::V) -> Self::V;
    /// [`sub`].
    fn sub<const WRAP: bool>(&self, a: Self::V, b: Self::V) -> Self::V;
    /// [`mul`].
    fn mul<const R: u8, const WRAP: bool>(&self, a: Self::V, b: Self::V) -> Self::V;
    /// [`div`].
    fn div<const R: u8, const WRAP: bool, const TWO: bool>(&self, a: Self::V, b: Self::V) -> Self::V;
    /// `fit(|a|)`.
    fn abs<const WRAP: bool>(&self, a: Self::V) -> Self::V;
    /// `a < b` per lane.
    fn lt(&self, a: Self::V, b: Self::V) -> u8;
    /// `a <= b` per lane.
    fn le(&self, a: Self::V, b: Self::V) -> u8;
    /// `a == b` per lane.
    fn eq(&self, a: Self::V, b: Self::V) -> u8;
    /// `m ? a : b` per lane.
    fn sel(&self, m: u8, a: Self::V, b: Self::V) -> Self::V;
    /// The larger of `a` and `b`.
    fn max(&self, a: Self::V, b: Self::V) -> Self::V;
    /// The smaller of `a` and `b`.
    fn min(&self, a: Self::V, b: Self::V) -> Self::V;
    /// `a + k` without the overflow mode (|k| small, `a` a raw value: no i64 overflow).
    fn step(&self, a: Self::V, k: i64) -> Self::V;
    /// `col[i..i + L]` of a flag column as a mask.
    fn load_flags(&self, col: &[bool], i: usize) -> u8 {
        (0..Self::L).fold(0, |m, j| m | (col[i + j] as u8) << j)
    }
    /// The format's division (its mode).
    #[inline(always)]
    fn divide<const R: u8, const WRAP: bool, const TWO: bool, const RECIP: bool>(
        &self,
        a: Self::V,
        b: Self::V,
    ) -> Self::V {
        if RECIP {
            let one = self.splat(self.c().one);
            self.mul::<R, WRAP>(a, self.div::<R, WRAP, TWO>(one, b))
        } else {
            self.div::<R, WRAP, TWO>(a, b)
        }
    }
}

/// Writes the 8 bits of `m` (lanes `0..l`) as bools at `out[i..i + l]`.
#[inline(always)]
pub(super) fn store_flags(out: &mut [bool], i: usize, l: usize, m: u8) {
    for (j, o) in out[i..i + l].iter_mut().enumerate() {
        *o = m >> j & 1 == 1;
    }
}

/// Portable lanes: `L` raw values in an array, each operation the scalar function lane by
/// lane (the compiler vectorises the copies).
#[derive(Clone, Copy)]
pub(super) struct Port<const L: usize>(pub(super) Lanes);

impl<const L: usize> Port<L> {
    #[inline(always)]
    pub(super) fn map2(a: [i64; L], b: [i64; L], f: impl Fn(i64, i64) -> i64) -> [i64; L] {
        std::array::from_fn(|i| f(a[i], b[i]))
    }
    #[inline(always)]
    pub(super) fn bits(a: [i64; L], b: [i64; L], f: impl Fn(i64, i64) -> bool) -> u8 {
        (0..L).fold(0, |m, i| m | (f(a[i], b[i]) as u8) << i)
    }
}

impl<const L: usize> Ops for Port<L> {
    const L: usize = L;
    type V = [i64; L];
    #[inline(always)]
    fn c(&self) -> &Lanes {
        &self.0
    }
    #[inline(always)]
    fn load(&self, col: &[i64], i: usize) -> [i64; L] {
        col[i..i + L].try_into().expect("L lanes")
    }
    #[inline(always)]
    fn store(&self, col: &mut [i64], i: usize, v: [i64; L]) {
        col[i..i + L].copy_from_slice(&v)
    }
    #[inline(always)]
    fn splat(&self, x: i64) -> [i64; L] {
        [x; L]
    }
    #[inline(always)]
    fn add<const WRAP: bool>(&self, a: [i64; L], b: [i64; L]) -> [i64; L] {
        Self::map2(a, b, |a, b| add::<WRAP>(&self.0, a, b))
    }
    #[inline(always)]
    fn sub<const WRAP: bool>(&self, a: [i64; L], b: [i64; L]) -> [i64; L] {
        Self::map2(a, b, |a, b| sub::<WRAP>(&self.0, a, b))
    }
    #[inline(always)]
    fn mul<const R: u8, const WRAP: bool>(&self, a: [i64; L], b: [i64; L]) -> [i64; L] {
        Self::map2(a, b, |a, b| mul::<R, WRAP>(&self.0, a, b))
    }
    #[inline(always)]
    fn div<const R: u8, const WRAP: bool, const TWO: bool>(&self, a: [i64; L], b: [i64; L]) -> [i64; L] {
        Self::map2(a, b, |a, b| div::<R, WRAP, TWO>(&self.0, a, b))
    }
    #[inline(always)]
    fn abs<const WRAP: bool>(&self, a: [i64; L]) -> [i64; L] {
        a.map(|a| fit::<WRAP>(&self.0, a.abs()))
    }
    #[inline(always)]
    fn lt(&self, a: [i64; L], b: [i64; L]) -> u8 {
        Self::bits(a, b, |a, b| a < b)
    }
    #[inline(always)]
    fn le(&self, a: [i64; L], b: [i64; L]) -> u8 {
        Self::bits(a, b, |a, b| a <= b)
    }
    #[inline(always)]
    fn eq(&self, a: [i64; L], b: [i64; L]) -> u8 {
        Self::bits(a, b, |a, b| a == b)
    }
    #[inline(always)]
    fn sel(&self, m: u8, a: [i64; L], b: [i64; L]) -> [i64; L] {
        std::array::from_fn(|i| sel(m >> i & 1 == 1, a[i], b[i]))
    }
    #[inline(always)]
    fn max(&self, a: [i64; L], b: [i64; L]) -> [i64; L] {
        Self::map2(a, b, i64::max)
    }
    #[inline(always)]
    fn min(&self, a: [i64; L], b: [i64; L]) -> [i64; L] {
        Self::map2(a, b, i64::min)
    }
    #[inline(always)]
    fn step(&self, a: [i64; L], k: i64) -> [i64; L] {
        a.map(|a| a + k)
    }
}

/// One vector of RTI tests in the stage table's order of operations, branch-free.
#[inline(always)]
pub(super) fn rti_vec<X: Ops, const R: u8, const WRAP: bool, const TWO: bool, const RECIP: bool>(
    x: &X,
    thr: X::V,
    backface: bool,
    i: &[X::V; 17],
) -> (u8, u8, X::V, X::V, X::V) {
    let sub = |a, b| x.sub::<WRAP>(a, b);
    let add = |a, b| x.add::<WRAP>(a, b);
    let mul = |a, b| x.mul::<R, WRAP>(a, b);
    let div = |a, b| x.div::<R, WRAP, TWO>(a, b);
    let [ox, oy, oz, dx, dy, dz, tmin, tmax, v0x, v0y, v0z, v1x, v1y, v1z, v2x, v2y, v2z] = *i;
    let (e1x, e1y, e1z) = (sub(v1x, v0x), sub(v1y, v0y), sub(v1z, v0z));
    let (e2x, e2y, e2z) = (sub(v2x, v0x), sub(v2y, v0y), sub(v2z, v0z));
    let (sx, sy, sz) = (sub(ox, v0x), sub(oy, v0y), sub(oz, v0z));
    let px = sub(mul(dy, e2z), mul(dz, e2y));
    let py = sub(mul(dz, e2x), mul(dx, e2z));
    let pz = sub(mul(dx, e2y), mul(dy, e2x));
    let qx = sub(mul(sy, e1z), mul(sz, e1y));
    let qy = sub(mul(sz, e1x), mul(sx, e1z));
    let qz = sub(mul(sx, e1y), mul(sy, e1x));
    let det = add(add(mul(e1x, px), mul(e1y, py)), mul(e1z, pz));
    let up = add(add(mul(sx, px), mul(sy, py)), mul(sz, pz));
    let vp = add(add(mul(dx, qx), mul(dy, qy)), mul(dz, qz));
    let tp = add(add(mul(e2x, qx), mul(e2y, qy)), mul(e2z, qz));
    let uv = add(up, vp);
    let zero = x.splat(0);
    let det_ok = x.lt(thr, if backface { det } else { x.abs::<WRAP>(det) });
    let pos = x.lt(zero, det);
    // det > 0 ? 0 <= y : y <= 0, and det > 0 ? uv <= det : det <= uv
    let ok = |y| (pos & x.le(zero, y)) | (!pos & x.le(y, zero));
    let uv_ok = (pos & x.le(uv, det)) | (!pos & x.le(det, uv));
    let valid = det_ok & ok(up) & ok(vp) & uv_ok & ok(tp);
    let (t, u, v) = if RECIP {
        // the model's inv_det is its division one / det, itself one x (1 / det) in this mode
        let inv = x.divide::<R, WRAP, TWO, RECIP>(x.splat(x.c().one), det);
        (mul(tp, inv), mul(up, inv), mul(vp, inv))
    } else {
        (div(tp, det), div(up, det), div(vp, det))
    };
    let hit = valid & x.le(tmin, t) & x.le(t, tmax);
    (valid, hit, t, u, v)
}

/// The RTI loop over slots `0..full` (a multiple of `L`).
#[inline(always)]
pub(super) fn rti_loop<X: Ops, const R: u8, const WRAP: bool, const TWO: bool, const RECIP: bool>(
    x: &X,
    thr: i64,
    backface: bool,
    rays: &RaysSoa<i64>,
    tris: &TrisSoa<i64>,
    out: &mut HitsSoa<i64>,
    full: usize,
) {
    let [o, d] = [&rays.o, &rays.d];
    let [v0, v1, v2] = &tris.v;
    let cols: [&[i64]; 17] = [
        &o[0], &o[1], &o[2], &d[0], &d[1], &d[2], &rays.tmin, &rays.tmax, &v0[0], &v0[1], &v0[2], &v1[0], &v1[1],
        &v1[2], &v2[0], &v2[1], &v2[2],
    ];
    let thr = x.splat(thr);
    for i in (0..full).step_by(X::L) {
        let inp: [X::V; 17] = std::array::from_fn(|k| x.load(cols[k], i));
        let (valid, hit, t, u, v) = rti_vec::<X, R, WRAP, TWO, RECIP>(x, thr, backface, &inp);
        store_flags(&mut out.valid, i, X::L, valid);
        store_flags(&mut out.hit, i, X::L, hit);
        x.store(&mut out.t, i, t);
        x.store(&mut out.u, i, u);
        x.store(&mut out.v, i, v);
    }
}

/// One operation over columns, `L` lanes at a time (the tail on the scalar functions).
#[inline(always)]
pub(super) fn op_loop<X: Ops, const R: u8, const WRAP: bool, const TWO: bool, const RECIP: bool>(
    x: &X,
    op: Op,
    a: &[i64],
    b: &[i64],
    out: &mut [i64],
) {
    let full = out.len() / X::L * X::L;
    for i in (0..full).step_by(X::L) {
        let (p, q) = (x.load(a, i), x.load(b, i));
        let r = match op {
            Op::Add => x.add::<WRAP>(p, q),
            Op::Sub => x.sub::<WRAP>(p, q),
            Op::Mul => x.mul::<R, WRAP>(p, q),
            _ => x.divide::<R, WRAP, TWO, RECIP>(p, q),
        };
        x.store(out, i, r);
    }
    let c = x.c();
    for i in full..out.len() {
        out[i] = match op {
            Op::Add => add::<WRAP>(c, a[i], b[i]),
            Op::Sub => sub::<WRAP>(c, a[i], b[i]),
            Op::Mul => mul::<R, WRAP>(c, a[i], b[i]),
            _ => divide::<R, WRAP, TWO, RECIP>(c, a[i], b[i]),
        };
    }
}

/// The ray of a slab vector: every value per lane (pairs) or broadcast (one ray).
#[derive(Clone, Copy)]
pub(super) struct SlabRayV<V> {
    pub(super) o: [V; 3],
    pub(super) inv_d: [V; 3],
    pub(super) inv_lo: [V; 3],
    pub(super) inv_hi: [V; 3],
    /// Lanes whose axis is parallel (directed variant).
    pub(super) parallel: [u8; 3],
    pub(super) tmin: V,
    pub(super) tmax: V,
}

/// One vector of slab tests (stage table of [`crate::slab`]), branch-free: (hit, t_near,
/// t_far). Fixed point has no NaN, so both comparators of the compare unit are max (near) and
/// min (far); `next_up` / `next_down` are ±1 step saturating at the range's ends; the guard is
/// off (the conservative variant refuses fixed point).
#[inline(always)]
pub(super) fn slab_vec<X: Ops, const R: u8, const WRAP: bool>(
    x: &X,
    s: &crate::slab::SlabConfig,
    r: &SlabRayV<X::V>,
    bmin: [X::V; 3],
    bmax: [X::V; 3],
) -> (u8, X::V, X::V) {
    let c = x.c();
    let (top, bottom) = (x.splat(c.max), x.splat(c.min));
    let up = |v| x.min(x.step(v, 1), top);
    let down = |v| x.max(x.step(v, -1), bottom);
    let zero = x.splat(0);
    let neg = |v| x.lt(v, zero);
    if s.directed {
        let (mut near, mut far, mut outside) = (r.tmin, r.tmax, 0u8);
        for a in 0..3 {
            let o = r.o[a];
            let par = r.parallel[a];
            let inside = x.le(bmin[a], o) & x.le(o, bmax[a]);
            outside |= par & !inside;
            let ng = neg(r.inv_d[a]);
            let (pe, px) = (x.sel(ng, bmax[a], bmin[a]), x.sel(ng, bmin[a], bmax[a]));
            let (de, dx) = (x.sub::<WRAP>(pe, o), x.sub::<WRAP>(px, o));
            let (de_lo, de_hi, dx_lo, dx_hi) = (down(de), up(de), down(dx), up(dx));
            let (up_inf, lo_inf) = (|v| x.eq(v, top), |v| x.eq(v, bottom));
            let x_e = x.sel(ng, de_hi, de_lo);
            let x_e_inf = (ng & up_inf(de_hi)) | (!ng & lo_inf(de_lo));
            let se = neg(x_e);
            let inv_e = x.sel(se, r.inv_hi[a], r.inv_lo[a]);
            let inv_e_inf = (se & up_inf(r.inv_hi[a])) | (!se & lo_inf(r.inv_lo[a]));
            let x_x = x.sel(ng, dx_lo, dx_hi);
            let x_x_inf = (ng & lo_inf(dx_lo)) | (!ng & up_inf(dx_hi));
            let sx = neg(x_x);
            let inv_x = x.sel(sx, r.inv_lo[a], r.inv_hi[a]);
            let inv_x_inf = (sx & lo_inf(r.inv_lo[a])) | (!sx & up_inf(r.inv_hi[a]));
            let entry = x.sel(x_e_inf | inv_e_inf, bottom, down(x.mul::<R, WRAP>(x_e, inv_e)));
            let exit = x.sel(x_x_inf | inv_x_inf, top, up(x.mul::<R, WRAP>(x_x, inv_x)));
            // a parallel axis adds no constraint
            near = x.sel(par, near, x.max(near, entry));
            far = x.sel(par, far, x.min(far, exit));
        }
        return (!outside & x.le(near, far), near, far);
    }
    let (near, far) = slab_chains::<X, R, WRAP>(x, r, bmin, bmax);
    slab_widen(x, s.widen_ulps, near, far)
}

/// The round-to-nearest variants' planes and comparator chains (stages 1-4; the same for
/// every such variant of a format, fixed point having no NaN): (t_near, t_far) before the
/// widening. Reads the ray's origin, 1/d and t interval only.
#[inline(always)]
fn slab_chains<X: Ops, const R: u8, const WRAP: bool>(
    x: &X,
    r: &SlabRayV<X::V>,
    bmin: [X::V; 3],
    bmax: [X::V; 3],
) -> (X::V, X::V) {
    let zero = x.splat(0);
    let (mut near, mut far) = (r.tmin, r.tmax);
    for a in 0..3 {
        let (lo, hi) = (x.sub::<WRAP>(bmin[a], r.o[a]), x.sub::<WRAP>(bmax[a], r.o[a]));
        let (tlo, thi) = (x.mul::<R, WRAP>(lo, r.inv_d[a]), x.mul::<R, WRAP>(hi, r.inv_d[a]));
        let ng = x.lt(r.inv_d[a], zero);
        near = x.max(near, x.sel(ng, thi, tlo));
        far = x.min(far, x.sel(ng, tlo, thi));
    }
    (near, far)
}

/// Stage 5, the widening by `widen` steps (saturating; outward when positive), and the hit
/// compare: (hit, t_near, t_far).
#[inline(always)]
fn slab_widen<X: Ops>(x: &X, widen: i32, mut near: X::V, mut far: X::V) -> (u8, X::V, X::V) {
    let c = x.c();
    let (top, bottom) = (x.splat(c.max), x.splat(c.min));
    let w = widen.unsigned_abs() as i64;
    if widen > 0 {
        near = x.max(x.step(near, -w), bottom);
        far = x.min(x.step(far, w), top);
    } else if widen < 0 {
        near = x.min(x.step(near, w), top);
        far = x.max(x.step(far, -w), bottom);
    }
    (x.le(near, far), near, far)
}

/// The slab loop over slots `0..full` (a multiple of `L`; pairs, or one ray against every
/// box).
#[inline(always)]
pub(super) fn slab_loop<X: Ops, const R: u8, const WRAP: bool, const TWO: bool, const RECIP: bool>(
    x: &X,
    s: &crate::slab::SlabConfig,
    rays: SlabRays<'_, i64>,
    boxes: &BoxesSoa<i64>,
    out: &mut SlabOutSoa<i64>,
    full: usize,
) {
    match rays {
        SlabRays::One(r) if s.directed => slab_directed_one::<X, R, WRAP>(x, r, boxes, out, full),
        SlabRays::One(r) => {
            // the ray broadcast once, read by reference (a copy of its 14 vectors per step
            // was a memory copy per vector)
            let ray = broadcast(x, r);
            for i in (0..full).step_by(X::L) {
                slab_step::<X, R, WRAP>(x, s, &ray, boxes, out, i);
            }
        }
        SlabRays::Pairs(r) => {
            for i in (0..full).step_by(X::L) {
                let ray = SlabRayV {
                    o: load3(x, &r.o, i),
                    inv_d: load3(x, &r.inv_d, i),
                    inv_lo: load3(x, &r.inv_lo, i),
                    inv_hi: load3(x, &r.inv_hi, i),
                    parallel: [
                        x.load_flags(&r.parallel[0], i),
                        x.load_flags(&r.parallel[1], i),
                        x.load_flags(&r.parallel[2], i),
                    ],
                    tmin: x.load(&r.tmin, i),
                    tmax: x.load(&r.tmax, i),
                };
                slab_step::<X, R, WRAP>(x, s, &ray, boxes, out, i);
            }
        }
    }
}

/// The directed variant of [`slab_vec`] on one ray against every box over slots `0..full` (a
/// multiple of `L`), the outputs stored — the same bits, with what the ray decides alike for
/// every lane decided once per axis instead of selected per lane: whether the axis is parallel
/// (then only the origin's inside test), the direction's sign (which plane is the entry, which
/// bracket end each difference takes: two grid steps per axis instead of four), and whether the
/// 1/d ends stand for ±∞ (usually neither: no per-lane test).
#[inline(always)]
fn slab_directed_one<X: Ops, const R: u8, const WRAP: bool>(
    x: &X,
    r: &crate::slab::SlabRay<i64>,
    boxes: &BoxesSoa<i64>,
    out: &mut SlabOutSoa<i64>,
    full: usize,
) {
    let c = *x.c();
    let (top, bottom) = (x.splat(c.max), x.splat(c.min));
    let up = |v| x.min(x.step(v, 1), top);
    let down = |v| x.max(x.step(v, -1), bottom);
    let zero = x.splat(0);
    let all = |b: bool| if b { u8::MAX } else { 0 };
    // per axis, uniform: the origin, 1/d's ends and whether each stands for ±∞, the sign of 1/d
    let o = r.o.map(|v| x.splat(v));
    let (inv_lo, inv_hi) = (r.inv_lo.map(|v| x.splat(v)), r.inv_hi.map(|v| x.splat(v)));
    let lo_inf = r.inv_lo.map(|v| v == c.min);
    let hi_inf = r.inv_hi.map(|v| v == c.max);
    let ng = r.inv_d.map(|v| v < 0);
    let (tmin, tmax) = (x.splat(r.tmin), x.splat(r.tmax));
    for i in (0..full).step_by(X::L) {
        let (bmin, bmax) = (load3(x, &boxes.min, i), load3(x, &boxes.max, i));
        let (mut near, mut far, mut outside) = (tmin, tmax, 0u8);
        for a in 0..3 {
            if r.parallel[a] {
                // a parallel axis adds no constraint but the origin's inside test
                outside |= !(x.le(bmin[a], o[a]) & x.le(o[a], bmax[a]));
                continue;
            }
            // the entry difference's bracket end and the exit's (by the direction's sign), and
            // whether each is the range's end (standing for ±∞)
            let (x_e, x_e_inf, x_x, x_x_inf) = if ng[a] {
                let (e, xx) = (up(x.sub::<WRAP>(bmax[a], o[a])), down(x.sub::<WRAP>(bmin[a], o[a])));
                (e, x.eq(e, top), xx, x.eq(xx, bottom))
            } else {
                let (e, xx) = (down(x.sub::<WRAP>(bmin[a], o[a])), up(x.sub::<WRAP>(bmax[a], o[a])));
                (e, x.eq(e, bottom), xx, x.eq(xx, top))
            };
            // the 1/d end by the bracket end's sign: negative → inv_hi (entry) / inv_lo (exit)
            let (se, sx) = (x.lt(x_e, zero), x.lt(x_x, zero));
            let inv_e = x.sel(se, inv_hi[a], inv_lo[a]);
            let inv_x = x.sel(sx, inv_lo[a], inv_hi[a]);
            let (hi, lo) = (all(hi_inf[a]), all(lo_inf[a]));
            let (inv_e_inf, inv_x_inf) =
                if hi_inf[a] || lo_inf[a] { ((se & hi) | (!se & lo), (sx & lo) | (!sx & hi)) } else { (0, 0) };
            let entry = x.sel(x_e_inf | inv_e_inf, bottom, down(x.mul::<R, WRAP>(x_e, inv_e)));
            let exit = x.sel(x_x_inf | inv_x_inf, top, up(x.mul::<R, WRAP>(x_x, inv_x)));
            near = x.max(near, entry);
            far = x.min(far, exit);
        }
        store_flags(&mut out.hit, i, X::L, !outside & x.le(near, far));
        x.store(&mut out.t_near, i, near);
        x.store(&mut out.t_far, i, far);
    }
}

/// One ray's values in every lane (a one-ray batch's [`SlabRayV`]).
#[inline(always)]
fn broadcast<X: Ops>(x: &X, r: &crate::slab::SlabRay<i64>) -> SlabRayV<X::V> {
    SlabRayV {
        o: r.o.map(|v| x.splat(v)),
        inv_d: r.inv_d.map(|v| x.splat(v)),
        inv_lo: r.inv_lo.map(|v| x.splat(v)),
        inv_hi: r.inv_hi.map(|v| x.splat(v)),
        parallel: r.parallel.map(|p| if p { u8::MAX } else { 0 }),
        tmin: x.splat(r.tmin),
        tmax: x.splat(r.tmax),
    }
}

/// Several round-to-nearest variants of one format (`group`, none directed) on one ray and
/// the same boxes over slots `0..full` (a multiple of `L`), `outs[j]` for `group[j]`: the
/// planes and chains ([`slab_chains`]) computed once per vector, then each variant's widening
/// and stores — each output bit for bit [`slab_loop`]'s for that variant alone (the variants
/// differ only in the widening: fixed point has no NaN, so neither comparator nor guard
/// applies).
#[inline(always)]
pub(super) fn slab_shared_loop<X: Ops, const R: u8, const WRAP: bool, const TWO: bool, const RECIP: bool>(
    x: &X,
    group: &[&crate::slab::Slab<Fixed>],
    r: &crate::slab::SlabRay<i64>,
    boxes: &BoxesSoa<i64>,
    outs: &mut [SlabOutSoa<i64>],
    full: usize,
) {
    assert!(group.len() == outs.len(), "slab_shared_loop: a group of another shape");
    let ray = broadcast(x, r);
    for i in (0..full).step_by(X::L) {
        let (bmin, bmax) = (load3(x, &boxes.min, i), load3(x, &boxes.max, i));
        let (near, far) = slab_chains::<X, R, WRAP>(x, &ray, bmin, bmax);
        for (s, out) in group.iter().zip(outs.iter_mut()) {
            let (hit, near, far) = slab_widen(x, s.cfg.widen_ulps, near, far);
            store_flags(&mut out.hit, i, X::L, hit);
            x.store(&mut out.t_near, i, near);
            x.store(&mut out.t_far, i, far);
        }
    }
}

/// One vector of [`slab_loop`]: lanes `i..i + L` of the boxes against `ray`, the outputs
/// stored.
#[inline(always)]
fn slab_step<X: Ops, const R: u8, const WRAP: bool>(
    x: &X,
    s: &crate::slab::SlabConfig,
    ray: &SlabRayV<X::V>,
    boxes: &BoxesSoa<i64>,
    out: &mut SlabOutSoa<i64>,
    i: usize,
) {
    let (bmin, bmax) = (load3(x, &boxes.min, i), load3(x, &boxes.max, i));
    let (hit, near, far) = slab_vec::<X, R, WRAP>(x, s, ray, bmin, bmax);
    store_flags(&mut out.hit, i, X::L, hit);
    x.store(&mut out.t_near, i, near);
    x.store(&mut out.t_far, i, far);
}

/// Lane `i`'s vector of each of three columns. A function, not a closure in `array::map`: a
/// closure is compiled apart from the `#[target_feature]` kernel that inlines this code, so its
/// vector intrinsics became calls (AVX2 q8.24 slab pairs: a fifth of the time in a call to
/// `_mm256_add_epi64`).
#[inline(always)]
fn load3<X: Ops>(x: &X, c: &[Vec<i64>; 3], i: usize) -> [X::V; 3] {
    [x.load(&c[0], i), x.load(&c[1], i), x.load(&c[2], i)]
}

/// Calls `$f::<$x, R, WRAP, TWO, RECIP>($args)` for the format's modes.
macro_rules! by_modes {
    ($fmt:expr, $f:ident, $x:ty, $($arg:expr),*) => {{
        let fmt: &Fixed = $fmt;
        let wrap = fmt.overflow == FxOverflow::Wrap;
        // a quotient can reach 2^53 only when w - 1 + F >= 53; under saturation it saturates
        let two = wrap && fmt.int_bits + 2 * fmt.frac_bits > 53;
        let recip = fmt.div == DivMode::RecipMul;
        macro_rules! go {
            ($r:expr) => {
                match (wrap, two, recip) {
                    (false, _, false) => $f::<$x, { $r }, false, false, false>($($arg),*),
                    (false, _, true) => $f::<$x, { $r }, false, false, true>($($arg),*),
                    (true, false, false) => $f::<$x, { $r }, true, false, false>($($arg),*),
                    (true, false, true) => $f::<$x, { $r }, true, false, true>($($arg),*),
                    (true, true, false) => $f::<$x, { $r }, true, true, false>($($arg),*),
                    (true, true, true) => $f::<$x, { $r }, true, true, true>($($arg),*),
                }
            };
        }
        match round_code(fmt.round) {
            FLOOR => go!(FLOOR),
            CEIL => go!(CEIL),
            TRUNC => go!(TRUNC),
            _ => go!(NEAREST),
        }
    }};
}
