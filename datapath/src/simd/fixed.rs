//! The fixed-point batch path: `qI.F` formats of at most 32 bits on 64-bit integer lanes, bit
//! for bit the scalar model of [`Fixed`] (every rounding and overflow mode, either division
//! mode), for the RTI unit and for single operations.
//!
//! The scalar model forms products and quotients exactly in i128. With a total width w ≤ 32
//! every raw value lies in [−2^31, 2^31 − 1], so the lanes need no i128:
//!
//! * **+ −**: the exact sum of two raw values fits i64 (|a ± b| ≤ 2^32); then the overflow mode.
//! * **×**: the exact product of two raw values fits i64 (|a·b| ≤ 2^62; it is formed as a
//!   signed 32 × 32 → 64-bit multiply); `p / 2^F` rounded by the mode from the arithmetic
//!   shift `q = p >> F` (floor, i.e. toward −∞) and the dropped bits `r = p & (2^F − 1)`
//!   (0 ≤ r < 2^F): toward +∞ adds 1 when r ≠ 0, toward zero adds 1 when r ≠ 0 and p < 0, to
//!   nearest-even adds 1 when r > 2^(F−1) or r = 2^(F−1) and q is odd; then the overflow mode.
//! * **÷** (`a / b`, b ≠ 0): the numerator `n = a·2^F` (|n| ≤ 2^62, and exact in binary64:
//!   it has the ≤ 32 significant bits of a) and the denominator `d = |b|` (sign moved to n)
//!   are converted to binary64 exactly; `q0 = ⌊RN(n / d)⌋`. While |n / d| < 2^53 the
//!   binary64 quotient's error is below one unit and `q0` is ⌊n / d⌋ or ⌊n / d⌋ + 1, so the
//!   remainder `r = n − q0·d` (computed modulo 2^64, exact because the true value is small)
//!   lies in [−d, d): one step (`r < 0`: q0 − 1, r + d) gives the floor and 0 ≤ r < d, from
//!   which the rounding mode decides as for ×. A quotient reaches 2^53 only when w − 1 + F
//!   ≥ 53; such formats take a second correction step (q0 + ⌊RN(r / d)⌋, |r / d| ≤ 2^10)
//!   before the final one. Under saturation a quotient that large saturates whatever its
//!   low bits. `b = 0` gives the most positive value for a > 0, the most negative for a < 0,
//!   0 for 0 / 0, as in the model. The reciprocal mode is `a × (1 / b)`, both rounded.
//! * **Overflow**: saturate clamps to [−2^(w−1), 2^(w−1) − 1]; wrap keeps the low w bits,
//!   sign-extended (`(x << (64 − w)) >> (64 − w)`).
//! * **Compares** are integer compares; |x| is `fit(|x|)` (the most negative value saturates
//!   or wraps, as in the model).
//!
//! One formulation of the RTI stage table, `rti_vec`, runs on a lane type of the `Ops`
//! trait: AVX-512F + DQ registers of 8 lanes (`zmm::Z`: vpmuldq, vpsraq, vpminsq/vpmaxsq,
//! vcvtqq2pd, vdivpd, vcvtpd2qq toward −∞, vpmullq), AVX2 registers of 4 lanes holding
//! biased values (`ymm::Y`: order, min, max and saturation as binary64 operations, division
//! from a shared reciprocal estimate, see its documentation) and portable arrays of 4 lanes
//! on which each operation is the branch-free scalar function of this module (`Port`, for
//! the saturating formats whose products exceed `ymm::Y`'s range). Every mode is a const
//! parameter, so no lane decides a mode; the slots after the last full vector run the scalar
//! model.

use super::select::{Kernel, SlabRays};
use crate::format::{DivMode, Fixed, FxOverflow, FxRound};
use crate::rti::{Cull, HitsSoa, RaysSoa, Rti, TrisSoa};
use crate::slab::{BoxesSoa, Slab, SlabOutSoa, SlabRay, SlabRaysSoa};
use crate::stage::Op;
use crate::Format as _;

/// The widest kernel of the fixed-point batch path (AVX-512F with AVX-512DQ: 8 i64 lanes).
pub const WIDEST_FIXED: Kernel = Kernel::Avx512;

/// The constants of one fixed-point format's lane arithmetic.
#[derive(Clone, Copy, Debug)]
struct Lanes {
    /// Fraction bits F.
    f: u32,
    /// 64 − w: the wrap shift.
    sh: u32,
    /// Most negative raw value.
    min: i64,
    /// Most positive raw value.
    max: i64,
    /// 2^F − 1: the bits a product's shift drops.
    low: i64,
    /// 2^(F−1) (the tie), or i64::MAX when F = 0 (no bits dropped, never a tie).
    half: i64,
    /// The format's 1 (rounded into range), the reciprocal's numerator.
    one: i64,
}

impl Lanes {
    /// The constants of `f`, when it has a batch path (width ≤ 32).
    fn of(f: &Fixed) -> Option<Self> {
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
const FLOOR: u8 = 0;
const CEIL: u8 = 1;
const TRUNC: u8 = 2;
const NEAREST: u8 = 3;

const fn round_code(r: FxRound) -> u8 {
    match r {
        FxRound::Floor => FLOOR,
        FxRound::Ceil => CEIL,
        FxRound::Trunc => TRUNC,
        FxRound::NearestEven => NEAREST,
    }
}

/// `x` if `c`, else `y` (a select, never a branch).
#[inline(always)]
fn sel(c: bool, x: i64, y: i64) -> i64 {
    let m = -(c as i64);
    (x & m) | (y & !m)
}

/// The overflow mode applied to an exact result that fits i64.
#[inline(always)]
fn fit<const WRAP: bool>(c: &Lanes, x: i64) -> i64 {
    if WRAP {
        (x << c.sh) >> c.sh
    } else {
        x.max(c.min).min(c.max)
    }
}

/// The rounding increment of a quotient whose floor is `q` with remainder 0 ≤ r < d, for an
/// exact value of sign `neg`: 0 or 1.
#[inline(always)]
fn bump<const R: u8>(q: i64, r: i64, d: i64, neg: bool) -> i64 {
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
fn add<const WRAP: bool>(c: &Lanes, a: i64, b: i64) -> i64 {
    fit::<WRAP>(c, a + b)
}

/// `a − b`, then the overflow mode.
#[inline(always)]
fn sub<const WRAP: bool>(c: &Lanes, a: i64, b: i64) -> i64 {
    fit::<WRAP>(c, a - b)
}

/// `a × b / 2^F` rounded by the mode, then the overflow mode.
#[inline(always)]
fn mul<const R: u8, const WRAP: bool>(c: &Lanes, a: i64, b: i64) -> i64 {
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
fn div<const R: u8, const WRAP: bool, const TWO: bool>(c: &Lanes, a: i64, b: i64) -> i64 {
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
fn divide<const R: u8, const WRAP: bool, const TWO: bool, const RECIP: bool>(c: &Lanes, a: i64, b: i64) -> i64 {
    if RECIP {
        mul::<R, WRAP>(c, a, div::<R, WRAP, TWO>(c, c.one, b))
    } else {
        div::<R, WRAP, TWO>(c, a, b)
    }
}

/// The lane operations of the RTI and operation loops: `V` holds `L` raw values, a mask is
/// a `u8` (bit j: lane j). Every operation is the scalar function of the same name above,
/// lane by lane.
trait Ops: Copy {
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
fn store_flags(out: &mut [bool], i: usize, l: usize, m: u8) {
    for (j, o) in out[i..i + l].iter_mut().enumerate() {
        *o = m >> j & 1 == 1;
    }
}

/// Portable lanes: `L` raw values in an array, each operation the scalar function lane by
/// lane (the compiler vectorises the copies).
#[derive(Clone, Copy)]
struct Port<const L: usize>(Lanes);

impl<const L: usize> Port<L> {
    #[inline(always)]
    fn map2(a: [i64; L], b: [i64; L], f: impl Fn(i64, i64) -> i64) -> [i64; L] {
        std::array::from_fn(|i| f(a[i], b[i]))
    }
    #[inline(always)]
    fn bits(a: [i64; L], b: [i64; L], f: impl Fn(i64, i64) -> bool) -> u8 {
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
fn rti_vec<X: Ops, const R: u8, const WRAP: bool, const TWO: bool, const RECIP: bool>(
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
fn rti_loop<X: Ops, const R: u8, const WRAP: bool, const TWO: bool, const RECIP: bool>(
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
fn op_loop<X: Ops, const R: u8, const WRAP: bool, const TWO: bool, const RECIP: bool>(
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
struct SlabRayV<V> {
    o: [V; 3],
    inv_d: [V; 3],
    inv_lo: [V; 3],
    inv_hi: [V; 3],
    /// Lanes whose axis is parallel (directed variant).
    parallel: [u8; 3],
    tmin: V,
    tmax: V,
}

/// One vector of slab tests (stage table of [`crate::slab`]), branch-free: (hit, t_near,
/// t_far). Fixed point has no NaN, so both comparators of the compare unit are max (near) and
/// min (far); `next_up` / `next_down` are ±1 step saturating at the range's ends; the guard is
/// off (the conservative variant refuses fixed point).
#[inline(always)]
fn slab_vec<X: Ops, const R: u8, const WRAP: bool>(
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
    let (mut near, mut far) = (r.tmin, r.tmax);
    for a in 0..3 {
        let (lo, hi) = (x.sub::<WRAP>(bmin[a], r.o[a]), x.sub::<WRAP>(bmax[a], r.o[a]));
        let (tlo, thi) = (x.mul::<R, WRAP>(lo, r.inv_d[a]), x.mul::<R, WRAP>(hi, r.inv_d[a]));
        let ng = neg(r.inv_d[a]);
        near = x.max(near, x.sel(ng, thi, tlo));
        far = x.min(far, x.sel(ng, tlo, thi));
    }
    // stage 5: widening by |widen_ulps| steps (saturating)
    let w = s.widen_ulps.unsigned_abs() as i64;
    if s.widen_ulps > 0 {
        near = x.max(x.step(near, -w), bottom);
        far = x.min(x.step(far, w), top);
    } else if s.widen_ulps < 0 {
        near = x.min(x.step(near, w), top);
        far = x.max(x.step(far, -w), bottom);
    }
    (x.le(near, far), near, far)
}

/// The slab loop over slots `0..full` (a multiple of `L`; pairs, or one ray against every
/// box).
#[inline(always)]
fn slab_loop<X: Ops, const R: u8, const WRAP: bool, const TWO: bool, const RECIP: bool>(
    x: &X,
    s: &crate::slab::SlabConfig,
    rays: SlabRays<'_, i64>,
    boxes: &BoxesSoa<i64>,
    out: &mut SlabOutSoa<i64>,
    full: usize,
) {
    let one = match rays {
        SlabRays::One(r) => Some(SlabRayV {
            o: r.o.map(|v| x.splat(v)),
            inv_d: r.inv_d.map(|v| x.splat(v)),
            inv_lo: r.inv_lo.map(|v| x.splat(v)),
            inv_hi: r.inv_hi.map(|v| x.splat(v)),
            parallel: r.parallel.map(|p| if p { u8::MAX } else { 0 }),
            tmin: x.splat(r.tmin),
            tmax: x.splat(r.tmax),
        }),
        SlabRays::Pairs(_) => None,
    };
    for i in (0..full).step_by(X::L) {
        let ray = match (one, rays) {
            (Some(r), _) => r,
            (None, SlabRays::Pairs(r)) => SlabRayV {
                o: [0, 1, 2].map(|a| x.load(&r.o[a], i)),
                inv_d: [0, 1, 2].map(|a| x.load(&r.inv_d[a], i)),
                inv_lo: [0, 1, 2].map(|a| x.load(&r.inv_lo[a], i)),
                inv_hi: [0, 1, 2].map(|a| x.load(&r.inv_hi[a], i)),
                parallel: [0, 1, 2].map(|a| x.load_flags(&r.parallel[a], i)),
                tmin: x.load(&r.tmin, i),
                tmax: x.load(&r.tmax, i),
            },
            (None, SlabRays::One(_)) => unreachable!("the one-ray shape is broadcast above"),
        };
        let bmin = [0, 1, 2].map(|a| x.load(&boxes.min[a], i));
        let bmax = [0, 1, 2].map(|a| x.load(&boxes.max[a], i));
        let (hit, near, far) = slab_vec::<X, R, WRAP>(x, s, &ray, bmin, bmax);
        store_flags(&mut out.hit, i, X::L, hit);
        x.store(&mut out.t_near, i, near);
        x.store(&mut out.t_far, i, far);
    }
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

/// AVX-512F + DQ lanes: 8 raw values in a zmm register, masks in `__mmask8`.
#[cfg(target_arch = "x86_64")]
mod zmm {
    use super::*;
    use std::arch::x86_64::*;

    /// The format's constants, broadcast. A value of this type exists only where AVX-512F
    /// and AVX-512DQ were detected ([`Z::new`] is unsafe), which is what makes the
    /// intrinsics in its methods sound.
    #[derive(Clone, Copy)]
    pub(super) struct Z {
        c: Lanes,
        min: __m512i,
        max: __m512i,
        low: __m512i,
        unit: __m512i,
        one: __m512i,
        f: __m128i,
        sh: __m128i,
    }

    /// `_mm512_cvt_roundpd_epi64` toward −∞: the floor of each lane as an integer.
    const FLOOR_CVT: i32 = _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC;

    impl Z {
        /// The broadcast constants of `c`.
        ///
        /// # Safety
        /// The CPU has AVX-512F and AVX-512DQ.
        #[inline(always)]
        pub(super) unsafe fn new(c: Lanes) -> Self {
            // SAFETY: the caller's promise
            unsafe {
                Self {
                    c,
                    min: _mm512_set1_epi64(c.min),
                    max: _mm512_set1_epi64(c.max),
                    low: _mm512_set1_epi64(c.low),
                    unit: _mm512_set1_epi64(c.low + 1),
                    one: _mm512_set1_epi64(1),
                    f: _mm_cvtsi64_si128(c.f as i64),
                    sh: _mm_cvtsi64_si128(c.sh as i64),
                }
            }
        }
        /// [`fit`].
        #[inline(always)]
        fn fit<const WRAP: bool>(&self, x: __m512i) -> __m512i {
            // SAFETY (every method): `self` exists, so the features do (see the type)
            unsafe {
                if WRAP {
                    _mm512_sra_epi64(_mm512_sll_epi64(x, self.sh), self.sh)
                } else {
                    _mm512_min_epi64(_mm512_max_epi64(x, self.min), self.max)
                }
            }
        }
        /// `q` + [`bump`] (remainder `r` of `d`, exact value negative in `neg`).
        #[inline(always)]
        fn bump<const R: u8>(&self, q: __m512i, r: __m512i, d: __m512i, neg: __mmask8) -> __m512i {
            unsafe {
                let inexact = _mm512_test_epi64_mask(r, r);
                let m = match R {
                    FLOOR => 0,
                    CEIL => inexact,
                    TRUNC => inexact & neg,
                    _ => {
                        let twice = _mm512_add_epi64(r, r);
                        _mm512_cmpgt_epi64_mask(twice, d)
                            | (_mm512_cmpeq_epi64_mask(twice, d) & _mm512_test_epi64_mask(q, self.one))
                    }
                };
                _mm512_mask_add_epi64(q, m, q, self.one)
            }
        }
    }

    impl Ops for Z {
        const L: usize = 8;
        type V = __m512i;
        #[inline(always)]
        fn c(&self) -> &Lanes {
            &self.c
        }
        #[inline(always)]
        fn load(&self, col: &[i64], i: usize) -> __m512i {
            let s = &col[i..i + 8];
            unsafe { _mm512_loadu_si512(s.as_ptr().cast()) }
        }
        #[inline(always)]
        fn store(&self, col: &mut [i64], i: usize, v: __m512i) {
            let s = &mut col[i..i + 8];
            unsafe { _mm512_storeu_si512(s.as_mut_ptr().cast(), v) }
        }
        #[inline(always)]
        fn splat(&self, x: i64) -> __m512i {
            unsafe { _mm512_set1_epi64(x) }
        }
        #[inline(always)]
        fn add<const WRAP: bool>(&self, a: __m512i, b: __m512i) -> __m512i {
            self.fit::<WRAP>(unsafe { _mm512_add_epi64(a, b) })
        }
        #[inline(always)]
        fn sub<const WRAP: bool>(&self, a: __m512i, b: __m512i) -> __m512i {
            self.fit::<WRAP>(unsafe { _mm512_sub_epi64(a, b) })
        }
        #[inline(always)]
        fn mul<const R: u8, const WRAP: bool>(&self, a: __m512i, b: __m512i) -> __m512i {
            unsafe {
                // the raw values are 32-bit: vpmuldq is the exact product
                let p = _mm512_mul_epi32(a, b);
                let q = _mm512_sra_epi64(p, self.f);
                let r = _mm512_and_si512(p, self.low);
                // to nearest: 2r against 2^F is r against 2^(F-1)
                self.fit::<WRAP>(self.bump::<R>(q, r, self.unit, _mm512_movepi64_mask(p)))
            }
        }
        #[inline(always)]
        fn div<const R: u8, const WRAP: bool, const TWO: bool>(&self, a: __m512i, b: __m512i) -> __m512i {
            unsafe {
                let zero = _mm512_setzero_si512();
                let n0 = _mm512_sll_epi64(a, self.f);
                let n = _mm512_mask_sub_epi64(n0, _mm512_movepi64_mask(b), zero, n0);
                let d0 = _mm512_abs_epi64(b);
                let by0 = _mm512_testn_epi64_mask(d0, d0);
                let d = _mm512_mask_mov_epi64(d0, by0, self.one);
                let df = _mm512_cvtepi64_pd(d);
                let mut q = _mm512_cvt_roundpd_epi64::<FLOOR_CVT>(_mm512_div_pd(_mm512_cvtepi64_pd(n), df));
                let mut r = _mm512_sub_epi64(n, _mm512_mullo_epi64(q, d));
                if TWO {
                    let step = _mm512_cvt_roundpd_epi64::<FLOOR_CVT>(_mm512_div_pd(_mm512_cvtepi64_pd(r), df));
                    q = _mm512_add_epi64(q, step);
                    r = _mm512_sub_epi64(n, _mm512_mullo_epi64(q, d));
                }
                let below = _mm512_movepi64_mask(r);
                q = _mm512_mask_sub_epi64(q, below, q, self.one);
                r = _mm512_mask_add_epi64(r, below, r, d);
                let res = self.fit::<WRAP>(self.bump::<R>(q, r, d, _mm512_movepi64_mask(n)));
                let pos = _mm512_mask_mov_epi64(zero, _mm512_cmpgt_epi64_mask(a, zero), self.max);
                let by_zero = _mm512_mask_mov_epi64(pos, _mm512_movepi64_mask(a), self.min);
                _mm512_mask_mov_epi64(res, by0, by_zero)
            }
        }
        #[inline(always)]
        fn abs<const WRAP: bool>(&self, a: __m512i) -> __m512i {
            self.fit::<WRAP>(unsafe { _mm512_abs_epi64(a) })
        }
        #[inline(always)]
        fn lt(&self, a: __m512i, b: __m512i) -> u8 {
            unsafe { _mm512_cmplt_epi64_mask(a, b) }
        }
        #[inline(always)]
        fn le(&self, a: __m512i, b: __m512i) -> u8 {
            unsafe { _mm512_cmple_epi64_mask(a, b) }
        }
        #[inline(always)]
        fn eq(&self, a: __m512i, b: __m512i) -> u8 {
            unsafe { _mm512_cmpeq_epi64_mask(a, b) }
        }
        #[inline(always)]
        fn sel(&self, m: u8, a: __m512i, b: __m512i) -> __m512i {
            unsafe { _mm512_mask_blend_epi64(m, b, a) }
        }
        #[inline(always)]
        fn max(&self, a: __m512i, b: __m512i) -> __m512i {
            unsafe { _mm512_max_epi64(a, b) }
        }
        #[inline(always)]
        fn min(&self, a: __m512i, b: __m512i) -> __m512i {
            unsafe { _mm512_min_epi64(a, b) }
        }
        #[inline(always)]
        fn step(&self, a: __m512i, k: i64) -> __m512i {
            unsafe { _mm512_add_epi64(a, _mm512_set1_epi64(k)) }
        }
    }
}

/// AVX2 lanes: 4 raw values in a ymm register, each held **biased**: the 64-bit pattern of
/// `v + M` with `M = 0x4338_0000_0000_0000` (the binary64 `1.5 · 2^52`), which for
/// |v| < 2^51 is also the binary64 encoding of the number `1.5 · 2^52 + v`. The one pattern
/// serves three instruction families that AVX2 lacks in 64-bit integer form:
///
/// * **order** (`vcmppd`, `vmaxpd`, `vminpd`): biased values compare as binary64 numbers in
///   the order of `v`, so compares, min, max and saturation are one floating-point op each
///   (AVX2 has no 64-bit integer min / max, and its one signed 64-bit compare runs on one port);
/// * **products** (`vpmuldq`): `M`'s low 32 bits are zero, so the low half of a biased raw
///   value is the raw value's own 32 bits, the operand `vpmuldq` reads;
/// * **conversion**: `v` as binary64 is `bits(v + M) − 1.5 · 2^52` (one subtraction, no
///   `vcvtqq2pd`), and a binary64 `x` with |x| ≤ 2^51 rounded to an integer *and* biased is
///   `x + 1.5 · 2^52` (one addition, no `vcvtpd2qq`).
///
/// `M`'s low 51 bits are zero too, so the low w bits of a biased value are those of `v`
/// (wrapping is mask, sign flip, subtract, whatever the magnitude), and adding an integer to
/// a biased value is adding it to `v`. The bias is added at every load and removed at every
/// store. The lanes are exact while every value the saturating arithmetic orders stays below
/// 2^51 in magnitude: raw values and their sums (< 2^33), quotients clamped to the range,
/// and products after the shift, |a·b / 2^F| ≤ 2^(2w − 2 − F); [`Y::fits`] admits the
/// saturating formats with 2w − 2 − F ≤ 50 (`q16.16`, `q8.24`, `q1.31`, every format of at
/// most 26 bits) and every wrapping one. Others take the portable lanes.
///
/// Division under saturation: the quotient `Q = a·2^F / b` is estimated as
/// `x = RN(a · RN(2^F / b))` (the reciprocal shared by the divisions of one divisor, as in
/// RTI's three), clamped to [min, max] and rounded to the nearest integer `q0`. For
/// min ≤ Q < max + 1 the estimate is within 2^−20 of Q (two roundings of relative error
/// 2^−53 on |Q| < 2^31), so `q0` is ⌊Q⌋ or ⌊Q⌋ + 1 and the remainder step of the module
/// documentation gives the floor. For Q ≥ max + 1 the clamp gives q0 = max with a remainder
/// ≥ d (no step), for Q < min it gives q0 = min with a negative remainder (the step makes
/// min − 1): both then saturate as the exact quotient would. The remainder is
/// `±(a·2^F − q0·b)` with both 32-bit factors of `vpmuldq`. Division under wrapping needs
/// the exact quotient up to 2^62 and runs the scalar function per lane.
#[cfg(target_arch = "x86_64")]
mod ymm {
    use super::*;
    use std::arch::x86_64::*;

    /// The bias: binary64 `1.5 · 2^52`.
    const M: i64 = 0x4338_0000_0000_0000;

    /// `sel`'s masks: entry m has lane j all ones when bit j of m is set.
    static EXPAND: [[i64; 4]; 16] = {
        let mut t = [[0i64; 4]; 16];
        let mut m = 0;
        while m < 16 {
            let mut j = 0;
            while j < 4 {
                t[m][j] = -(((m >> j) & 1) as i64);
                j += 1;
            }
            m += 1;
        }
        t
    };

    /// The format's constants, broadcast and biased. A value of this type exists only where
    /// AVX2 was detected ([`Y::new`] is unsafe), which is what makes the intrinsics in its
    /// methods sound.
    #[derive(Clone, Copy)]
    pub(super) struct Y {
        c: Lanes,
        /// M as an integer.
        m: __m256i,
        /// M as a binary64.
        md: __m256d,
        /// 2M as a binary64 (|v| is max(M + v, 2M − (M + v))).
        m2d: __m256d,
        /// Biased min and max, as binary64.
        bmin: __m256d,
        bmax: __m256d,
        /// min and max as binary64.
        fmin: __m256d,
        fmax: __m256d,
        /// The product shift's constants: 2^63 (floor), 2^63 + 2^F − 1 (toward +∞),
        /// 2^63 + 2^(F−1) − 1 (to nearest), and M − 2^(63−F) (unbias the shift, bias the
        /// result).
        k_floor: __m256i,
        k_ceil: __m256i,
        k_near: __m256i,
        unshift: __m256i,
        /// 1 when F ≥ 1 (the quotient's last bit breaks a tie), else 0.
        tie_bit: __m256i,
        low: __m256i,
        one: __m256i,
        /// 2^F as binary64.
        scale: __m256d,
        /// Wrap: the low w bits, 2^(w−1), and M − 2^(w−1).
        wmask: __m256i,
        wsign: __m256i,
        wunsign: __m256i,
        f: __m128i,
    }

    impl Y {
        /// Whether the biased lanes compute format `c` exactly (see the type).
        pub(super) fn fits(c: &Lanes, wrap: bool) -> bool {
            let w = 64 - c.sh;
            wrap || 2 * w - 2 - c.f.min(2 * w - 2) <= 50
        }

        /// The broadcast constants of `c`.
        ///
        /// # Safety
        /// The CPU has AVX2.
        #[inline(always)]
        pub(super) unsafe fn new(c: Lanes) -> Self {
            let w = 64 - c.sh;
            let f = c.f;
            let b = |v: i64| f64::from_bits(M.wrapping_add(v) as u64);
            let near = if f == 0 { 0 } else { (1i64 << (f - 1)) - 1 };
            // SAFETY: the caller's promise
            unsafe {
                let i = _mm256_set1_epi64x;
                let d = _mm256_set1_pd;
                Self {
                    c,
                    m: i(M),
                    md: d(f64::from_bits(M as u64)),
                    m2d: d(2.0 * f64::from_bits(M as u64)),
                    bmin: d(b(c.min)),
                    bmax: d(b(c.max)),
                    fmin: d(c.min as f64),
                    fmax: d(c.max as f64),
                    k_floor: i(i64::MIN),
                    k_ceil: i(i64::MIN.wrapping_add(c.low)),
                    k_near: i(i64::MIN.wrapping_add(near)),
                    unshift: i(M.wrapping_sub((1u64 << (63 - f)) as i64)),
                    tie_bit: i((f > 0) as i64),
                    low: i(c.low),
                    one: i(1),
                    scale: d((1u64 << f) as f64),
                    wmask: i(((1u64 << w) - 1) as i64),
                    wsign: i(1i64 << (w - 1)),
                    wunsign: i(M.wrapping_sub(1i64 << (w - 1))),
                    f: _mm_cvtsi64_si128(f as i64),
                }
            }
        }
        /// [`fit`] of a biased value.
        #[inline(always)]
        fn fit<const WRAP: bool>(&self, x: __m256i) -> __m256i {
            // SAFETY (every method): `self` exists, so AVX2 does (see the type)
            unsafe {
                if WRAP {
                    // the low w bits, sign-extended, biased: ((x & mask) ^ 2^(w-1)) + M - 2^(w-1)
                    _mm256_add_epi64(_mm256_xor_si256(_mm256_and_si256(x, self.wmask), self.wsign), self.wunsign)
                } else {
                    let x = _mm256_castsi256_pd(x);
                    _mm256_castpd_si256(_mm256_min_pd(_mm256_max_pd(x, self.bmin), self.bmax))
                }
            }
        }
        /// The unbiased value.
        #[inline(always)]
        fn plain(&self, x: __m256i) -> __m256i {
            unsafe { _mm256_sub_epi64(x, self.m) }
        }
        /// The value as binary64 (exact).
        #[inline(always)]
        fn float(&self, x: __m256i) -> __m256d {
            unsafe { _mm256_sub_pd(_mm256_castsi256_pd(x), self.md) }
        }
        /// Lanes where `x` (plain) is negative, all ones.
        #[inline(always)]
        fn negative(&self, x: __m256i) -> __m256i {
            unsafe { _mm256_cmpgt_epi64(_mm256_setzero_si256(), x) }
        }
        /// A 4-bit compare mask of two biased vectors.
        #[inline(always)]
        fn cmp<const P: i32>(&self, a: __m256i, b: __m256i) -> u8 {
            unsafe { _mm256_movemask_pd(_mm256_cmp_pd::<P>(_mm256_castsi256_pd(a), _mm256_castsi256_pd(b))) as u8 }
        }
    }

    impl Ops for Y {
        const L: usize = 4;
        type V = __m256i;
        #[inline(always)]
        fn c(&self) -> &Lanes {
            &self.c
        }
        #[inline(always)]
        fn load(&self, col: &[i64], i: usize) -> __m256i {
            let s = &col[i..i + 4];
            unsafe { _mm256_add_epi64(_mm256_loadu_si256(s.as_ptr().cast()), self.m) }
        }
        #[inline(always)]
        fn store(&self, col: &mut [i64], i: usize, v: __m256i) {
            let s = &mut col[i..i + 4];
            unsafe { _mm256_storeu_si256(s.as_mut_ptr().cast(), self.plain(v)) }
        }
        #[inline(always)]
        fn splat(&self, x: i64) -> __m256i {
            unsafe { _mm256_set1_epi64x(x.wrapping_add(M)) }
        }
        #[inline(always)]
        fn add<const WRAP: bool>(&self, a: __m256i, b: __m256i) -> __m256i {
            self.fit::<WRAP>(unsafe { _mm256_add_epi64(a, self.plain(b)) })
        }
        #[inline(always)]
        fn sub<const WRAP: bool>(&self, a: __m256i, b: __m256i) -> __m256i {
            self.fit::<WRAP>(unsafe { _mm256_add_epi64(_mm256_sub_epi64(a, b), self.m) })
        }
        #[inline(always)]
        fn mul<const R: u8, const WRAP: bool>(&self, a: __m256i, b: __m256i) -> __m256i {
            unsafe {
                // the low halves are the 32-bit raw values: vpmuldq is the exact product
                let p = _mm256_mul_epi32(a, b);
                // the rounded quotient by 2^F as a floor: (p + k) >> F with the arithmetic
                // shift made logical by 2^63 (p + 2^63 >= 0 as |p| <= 2^62)
                let biased = match R {
                    FLOOR => _mm256_add_epi64(p, self.k_floor),
                    CEIL => _mm256_add_epi64(p, self.k_ceil),
                    TRUNC => _mm256_add_epi64(
                        _mm256_add_epi64(p, self.k_floor),
                        _mm256_and_si256(self.negative(p), self.low),
                    ),
                    // ties to even: + 2^(F-1) - 1 + (bit F of p)
                    _ => {
                        let bit = _mm256_and_si256(_mm256_srl_epi64(p, self.f), self.tie_bit);
                        _mm256_add_epi64(_mm256_add_epi64(p, self.k_near), bit)
                    }
                };
                self.fit::<WRAP>(_mm256_add_epi64(_mm256_srl_epi64(biased, self.f), self.unshift))
            }
        }
        #[inline(always)]
        fn div<const R: u8, const WRAP: bool, const TWO: bool>(&self, a: __m256i, b: __m256i) -> __m256i {
            if WRAP {
                // the exact quotient can reach 2^62: the scalar function, lane by lane
                let (mut pa, mut pb) = ([0i64; 4], [0i64; 4]);
                self.store(&mut pa, 0, a);
                self.store(&mut pb, 0, b);
                let q: [i64; 4] = std::array::from_fn(|j| div::<R, WRAP, TWO>(&self.c, pa[j], pb[j]));
                return self.load(&q, 0);
            }
            unsafe {
                let zero = _mm256_setzero_si256();
                let (pa, pb) = (self.plain(a), self.plain(b));
                let sb = self.negative(pb);
                let by0 = _mm256_cmpeq_epi64(pb, zero);
                // d = |b| (2^31 at the most negative b), 1 for b = 0
                let d = _mm256_sub_epi64(_mm256_sub_epi64(_mm256_xor_si256(pb, sb), sb), by0);
                // the estimate, clamped, rounded to an integer and biased in one addition
                let recip = _mm256_div_pd(self.scale, self.float(b));
                let x = _mm256_mul_pd(self.float(a), recip);
                let x = _mm256_min_pd(_mm256_max_pd(x, self.fmin), self.fmax);
                let q0 = _mm256_castpd_si256(_mm256_add_pd(x, self.md));
                // r = n - q0 d with n = a 2^F sign(b), d = |b|: the sign of b moved from d to n
                let n0 = _mm256_sll_epi64(pa, self.f);
                let rs = _mm256_sub_epi64(n0, _mm256_mul_epi32(q0, b));
                let r = _mm256_sub_epi64(_mm256_xor_si256(rs, sb), sb);
                // one step to the floor: r < 0 gives q0 - 1, r + d
                let below = self.negative(r);
                let q = _mm256_add_epi64(q0, below);
                let r = _mm256_add_epi64(r, _mm256_and_si256(below, d));
                let q = match R {
                    FLOOR => q,
                    CEIL => {
                        _mm256_sub_epi64(q, _mm256_andnot_si256(_mm256_cmpeq_epi64(r, zero), _mm256_set1_epi64x(-1)))
                    }
                    TRUNC => {
                        let n = _mm256_sub_epi64(_mm256_xor_si256(n0, sb), sb);
                        _mm256_sub_epi64(q, _mm256_andnot_si256(_mm256_cmpeq_epi64(r, zero), self.negative(n)))
                    }
                    _ => {
                        let twice = _mm256_add_epi64(r, r);
                        let odd = _mm256_sub_epi64(zero, _mm256_and_si256(q, self.one));
                        let up = _mm256_or_si256(
                            _mm256_cmpgt_epi64(twice, d),
                            _mm256_and_si256(_mm256_cmpeq_epi64(twice, d), odd),
                        );
                        _mm256_sub_epi64(q, up)
                    }
                };
                let res = self.fit::<WRAP>(q);
                // b = 0: the most positive value for a > 0, the most negative for a < 0, 0 for 0
                let pos = _mm256_and_si256(_mm256_cmpgt_epi64(pa, zero), _mm256_set1_epi64x(self.c.max));
                let neg = _mm256_and_si256(self.negative(pa), _mm256_set1_epi64x(self.c.min));
                let by_zero = _mm256_add_epi64(_mm256_or_si256(pos, neg), self.m);
                _mm256_blendv_epi8(res, by_zero, by0)
            }
        }
        #[inline(always)]
        fn abs<const WRAP: bool>(&self, a: __m256i) -> __m256i {
            unsafe {
                let x = _mm256_castsi256_pd(a);
                self.fit::<WRAP>(_mm256_castpd_si256(_mm256_max_pd(x, _mm256_sub_pd(self.m2d, x))))
            }
        }
        #[inline(always)]
        fn lt(&self, a: __m256i, b: __m256i) -> u8 {
            self.cmp::<_CMP_LT_OQ>(a, b)
        }
        #[inline(always)]
        fn le(&self, a: __m256i, b: __m256i) -> u8 {
            self.cmp::<_CMP_LE_OQ>(a, b)
        }
        #[inline(always)]
        fn eq(&self, a: __m256i, b: __m256i) -> u8 {
            self.cmp::<_CMP_EQ_OQ>(a, b)
        }
        #[inline(always)]
        fn sel(&self, m: u8, a: __m256i, b: __m256i) -> __m256i {
            unsafe {
                let mask = _mm256_loadu_si256(EXPAND[(m & 15) as usize].as_ptr().cast());
                _mm256_blendv_epi8(b, a, mask)
            }
        }
        #[inline(always)]
        fn max(&self, a: __m256i, b: __m256i) -> __m256i {
            unsafe { _mm256_castpd_si256(_mm256_max_pd(_mm256_castsi256_pd(a), _mm256_castsi256_pd(b))) }
        }
        #[inline(always)]
        fn min(&self, a: __m256i, b: __m256i) -> __m256i {
            unsafe { _mm256_castpd_si256(_mm256_min_pd(_mm256_castsi256_pd(a), _mm256_castsi256_pd(b))) }
        }
        #[inline(always)]
        fn step(&self, a: __m256i, k: i64) -> __m256i {
            unsafe { _mm256_add_epi64(a, _mm256_set1_epi64x(k)) }
        }
    }
}

/// The per-instruction-set kernels: AVX2 on [`ymm::Y`] (portable 4-lane arrays for the
/// formats it does not admit), AVX-512F + DQ on [`zmm::Z`]; the RTI and slab ones in the signatures of `datapath::simd`'s dispatch tables
/// (lanes `0..full`, a multiple of the lane count).
#[cfg(target_arch = "x86_64")]
mod isa {
    use super::*;

    /// The constants of a format the dispatch accepted (`kernel_fixed` names a kernel only
    /// for formats that have them).
    fn lanes(f: &Fixed) -> Lanes {
        Lanes::of(f).expect("the dispatch checked the format")
    }

    /// The RTI loop on lanes `x` for `rti`'s modes.
    #[inline(always)]
    fn rti_any<X: Ops>(
        x: &X,
        rti: &Rti<Fixed>,
        rays: &RaysSoa<i64>,
        tris: &TrisSoa<i64>,
        out: &mut HitsSoa<i64>,
        full: usize,
    ) {
        let backface = rti.cull == Cull::Backface;
        by_modes!(&rti.fmt, rti_loop, X, x, rti.det_thr, backface, rays, tris, out, full)
    }

    /// AVX2 (4 lanes).
    #[target_feature(enable = "avx2")]
    pub(super) fn rti_avx2(
        rti: &Rti<Fixed>,
        rays: &RaysSoa<i64>,
        tris: &TrisSoa<i64>,
        out: &mut HitsSoa<i64>,
        full: usize,
    ) {
        let c = lanes(&rti.fmt);
        if ymm::Y::fits(&c, rti.fmt.overflow == FxOverflow::Wrap) {
            // SAFETY: this function's features
            rti_any(&unsafe { ymm::Y::new(c) }, rti, rays, tris, out, full)
        } else {
            rti_any(&Port::<4>(c), rti, rays, tris, out, full)
        }
    }

    /// AVX-512F + DQ (8 lanes).
    #[target_feature(enable = "avx512f,avx512dq")]
    pub(super) fn rti_avx512(
        rti: &Rti<Fixed>,
        rays: &RaysSoa<i64>,
        tris: &TrisSoa<i64>,
        out: &mut HitsSoa<i64>,
        full: usize,
    ) {
        // SAFETY: this function's features
        let z = unsafe { zmm::Z::new(lanes(&rti.fmt)) };
        rti_any(&z, rti, rays, tris, out, full)
    }

    /// The slab loop on lanes `x` for the unit's modes.
    #[inline(always)]
    fn slab_any<X: Ops>(
        x: &X,
        s: &Slab<Fixed>,
        rays: SlabRays<'_, i64>,
        boxes: &BoxesSoa<i64>,
        out: &mut SlabOutSoa<i64>,
        full: usize,
    ) {
        by_modes!(&s.fmt, slab_loop, X, x, &s.cfg, rays, boxes, out, full)
    }

    /// AVX2 (4 lanes).
    #[target_feature(enable = "avx2")]
    pub(super) fn slab_avx2(
        s: &Slab<Fixed>,
        rays: SlabRays<'_, i64>,
        boxes: &BoxesSoa<i64>,
        out: &mut SlabOutSoa<i64>,
        full: usize,
    ) {
        let c = lanes(&s.fmt);
        if ymm::Y::fits(&c, s.fmt.overflow == FxOverflow::Wrap) {
            // SAFETY: this function's features
            slab_any(&unsafe { ymm::Y::new(c) }, s, rays, boxes, out, full)
        } else {
            slab_any(&Port::<4>(c), s, rays, boxes, out, full)
        }
    }

    /// AVX-512F + DQ (8 lanes).
    #[target_feature(enable = "avx512f,avx512dq")]
    pub(super) fn slab_avx512(
        s: &Slab<Fixed>,
        rays: SlabRays<'_, i64>,
        boxes: &BoxesSoa<i64>,
        out: &mut SlabOutSoa<i64>,
        full: usize,
    ) {
        // SAFETY: this function's features
        let z = unsafe { zmm::Z::new(lanes(&s.fmt)) };
        slab_any(&z, s, rays, boxes, out, full)
    }

    /// AVX2 (4 lanes).
    #[target_feature(enable = "avx2")]
    pub(super) fn op_avx2(f: &Fixed, op: Op, a: &[i64], b: &[i64], out: &mut [i64]) {
        let c = lanes(f);
        if ymm::Y::fits(&c, f.overflow == FxOverflow::Wrap) {
            // SAFETY: this function's features
            let y = unsafe { ymm::Y::new(c) };
            by_modes!(f, op_loop, ymm::Y, &y, op, a, b, out)
        } else {
            let x = Port::<4>(c);
            by_modes!(f, op_loop, Port<4>, &x, op, a, b, out)
        }
    }

    /// AVX-512F + DQ (8 lanes).
    #[target_feature(enable = "avx512f,avx512dq")]
    pub(super) fn op_avx512(f: &Fixed, op: Op, a: &[i64], b: &[i64], out: &mut [i64]) {
        // SAFETY: this function's features
        let z = unsafe { zmm::Z::new(lanes(f)) };
        by_modes!(f, op_loop, zmm::Z, &z, op, a, b, out)
    }
}

/// The kernel `rti_batch_fixed` / `op_batch_fixed` use for this format on this machine:
/// formats of at most 32 bits on i64 lanes, the scalar model otherwise.
pub fn kernel_fixed(f: &Fixed) -> Kernel {
    let k = super::select::best_kernel(Lanes::of(f).is_some(), WIDEST_FIXED);
    // the 8-lane kernel also needs AVX-512DQ (64-bit multiplies and conversions)
    #[cfg(target_arch = "x86_64")]
    if k == Kernel::Avx512 && !std::arch::is_x86_feature_detected!("avx512dq") {
        return Kernel::Avx2;
    }
    k
}

/// [`Rti::batch`] for a fixed-point format on the fastest kernel available; the same bits.
///
/// # Panics
/// If the column lengths differ.
pub fn rti_batch_fixed(rti: &Rti<Fixed>, rays: &RaysSoa<i64>, tris: &TrisSoa<i64>, out: &mut HitsSoa<i64>) -> Kernel {
    super::select::rti_dispatch(
        rti,
        rays,
        tris,
        out,
        kernel_fixed(&rti.fmt),
        #[cfg(target_arch = "x86_64")]
        (isa::rti_avx2, isa::rti_avx512, None),
    )
}

/// `Add`, `Sub`, `Mul` or `Div` (in the format's division mode) of a fixed-point format on
/// whole columns, `out[i] = a[i] op b[i]`, on the fastest kernel available; the model's bits.
///
/// # Panics
/// If the slice lengths differ or `op` is `Logic`.
pub fn op_batch_fixed(f: &Fixed, op: Op, a: &[i64], b: &[i64], out: &mut [i64]) -> Kernel {
    assert!(a.len() == b.len() && b.len() == out.len(), "batch lengths differ");
    assert!(op != Op::Logic, "op_batch_fixed computes arithmetic only");
    let which = kernel_fixed(f);
    #[cfg(target_arch = "x86_64")]
    match which {
        // SAFETY: `which` names a kernel only after run-time feature detection, and only for
        // formats with lanes.
        Kernel::Avx2 => {
            unsafe { isa::op_avx2(f, op, a, b, out) };
            return which;
        }
        Kernel::Scalar => {}
        _ => {
            unsafe { isa::op_avx512(f, op, a, b, out) };
            return which;
        }
    }
    let _ = which;
    for i in 0..out.len() {
        out[i] = match op {
            Op::Add => f.add(a[i], b[i]),
            Op::Sub => f.sub(a[i], b[i]),
            Op::Mul => f.mul(a[i], b[i]),
            _ => f.div(a[i], b[i]),
        };
    }
    Kernel::Scalar
}

/// The kernel `slab_batch_fixed` / `slab_ray_fixed` use for this unit: as [`kernel_fixed`],
/// every variant.
pub fn slab_kernel_fixed(s: &Slab<Fixed>) -> Kernel {
    kernel_fixed(&s.fmt)
}

/// The slab unit on the kernel `slab_kernel_fixed` names, through `datapath::simd`'s dispatch.
fn slab_fixed(s: &Slab<Fixed>, rays: SlabRays<'_, i64>, boxes: &BoxesSoa<i64>, out: &mut SlabOutSoa<i64>) -> Kernel {
    super::select::slab_dispatch(
        s,
        rays,
        boxes,
        out,
        slab_kernel_fixed(s),
        #[cfg(target_arch = "x86_64")]
        (isa::slab_avx2, isa::slab_avx512, None),
    )
}

/// [`Slab::batch`] for a fixed-point format on the fastest kernel available; the same bits.
///
/// # Panics
/// If the column lengths differ.
pub fn slab_batch_fixed(
    s: &Slab<Fixed>,
    rays: &SlabRaysSoa<i64>,
    boxes: &BoxesSoa<i64>,
    out: &mut SlabOutSoa<i64>,
) -> Kernel {
    slab_fixed(s, SlabRays::Pairs(rays), boxes, out)
}

/// [`Slab::batch_ray`] (one ray, many boxes) for a fixed-point format on the fastest kernel
/// available; the same bits.
///
/// # Panics
/// If the column lengths differ.
pub fn slab_ray_fixed(s: &Slab<Fixed>, ray: &SlabRay<i64>, boxes: &BoxesSoa<i64>, out: &mut SlabOutSoa<i64>) -> Kernel {
    slab_fixed(s, SlabRays::One(ray), boxes, out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lanes(name: &str) -> Lanes {
        match name.parse::<crate::AnyFormat>().expect("a format") {
            crate::AnyFormat::Fixed(f) => Lanes::of(&f).expect("at most 32 bits"),
            _ => unreachable!("{name} is fixed point"),
        }
    }

    /// The biased AVX2 lanes admit exactly the formats whose shifted products stay below 2^51
    /// under saturation (2w − 2 − F ≤ 50), and every wrapping one.
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn the_biased_lanes_admit_the_documented_formats() {
        for (name, sat) in [
            ("q16.16", true),
            ("q8.24", true),
            ("q1.31", true),
            ("q20.12", true),
            ("q21.11", false),
            ("q24.8", false),
            ("q32.0", false),
            ("q26.0", true),
            ("q27.0", false),
            ("q2.6", true),
        ] {
            let c = lanes(name);
            assert_eq!(ymm::Y::fits(&c, false), sat, "{name} saturating");
            assert!(ymm::Y::fits(&c, true), "{name} wrapping");
        }
    }
}
