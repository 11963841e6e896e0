//! AVX2, 4 binary64 lanes holding a narrow format's values exactly (see
//! [`crate::format::narrow`]); a mask is a vector of all-ones / all-zeros lanes.

use crate::format::narrow::Narrow;
use std::arch::x86_64::*;
/// Lanes per vector.
pub const LANES: usize = 4;
/// A mask.
pub type M = __m256d;
table_ops!("avx2", __m256d, M, "binary64";
    add = _mm256_add_pd, sub = _mm256_sub_pd, mul = _mm256_mul_pd, div = _mm256_div_pd,
    max = _mm256_max_pd, min = _mm256_min_pd, cmp = _mm256_cmp_pd);
/// Every lane x.
#[inline]
#[target_feature(enable = "avx2")]
pub fn splat(x: f64) -> __m256d {
    _mm256_set1_pd(x)
}
/// Every lane the integer x.
#[inline]
#[target_feature(enable = "avx2")]
fn int(x: u64) -> __m256i {
    _mm256_set1_epi64x(x as i64)
}
/// A shift count for the `sll` / `srl` forms.
#[inline]
#[target_feature(enable = "avx2")]
fn count(n: u32) -> __m128i {
    _mm_cvtsi64_si128(n as i64)
}
/// Every lane binary64's canonical NaN (stored as the format's canonical NaN).
#[inline]
#[target_feature(enable = "avx2")]
pub fn canonical_nan() -> __m256d {
    _mm256_castsi256_pd(int(0x7ff8_0000_0000_0000))
}
/// Both masks.
#[inline]
#[target_feature(enable = "avx2")]
pub fn and_m(a: M, b: M) -> M {
    _mm256_and_pd(a, b)
}
/// Either mask.
#[inline]
#[target_feature(enable = "avx2")]
pub fn or_m(a: M, b: M) -> M {
    _mm256_or_pd(a, b)
}
/// The mask as lane bits (lane k in bit k).
#[inline]
#[target_feature(enable = "avx2")]
pub fn bits(m: M) -> u32 {
    _mm256_movemask_pd(m) as u32
}
/// `m ? b : a` per lane.
#[inline]
#[target_feature(enable = "avx2")]
pub fn blend(a: __m256d, b: __m256d, m: M) -> __m256d {
    _mm256_blendv_pd(a, b, m)
}
/// `sign(x) ? b : a` per lane.
#[inline]
#[target_feature(enable = "avx2")]
pub fn blend_sign(a: __m256d, b: __m256d, x: __m256d) -> __m256d {
    _mm256_blendv_pd(a, b, x)
}
/// The mask's complement.
#[inline]
#[target_feature(enable = "avx2")]
pub fn not_m(a: M) -> M {
    _mm256_xor_pd(a, _mm256_castsi256_pd(int(u64::MAX)))
}
/// `sel ? b : a` per lane, on masks.
#[inline]
#[target_feature(enable = "avx2")]
pub fn blend_m(a: M, b: M, sel: M) -> M {
    _mm256_blendv_pd(a, b, sel)
}
/// Lanes whose sign bit is set.
#[inline]
#[target_feature(enable = "avx2")]
pub fn sign_m(x: __m256d) -> M {
    _mm256_castsi256_pd(_mm256_cmpgt_epi64(_mm256_setzero_si256(), _mm256_castpd_si256(x)))
}
/// The sign bits of x (everything else cleared).
#[inline]
#[target_feature(enable = "avx2")]
pub fn sign(x: __m256d) -> __m256d {
    _mm256_and_pd(x, _mm256_set1_pd(-0.0))
}
/// |x| by clearing the sign bit.
#[inline]
#[target_feature(enable = "avx2")]
pub fn abs(x: __m256d) -> __m256d {
    _mm256_andnot_pd(_mm256_set1_pd(-0.0), x)
}
/// a ⊕ b, bitwise.
#[inline]
#[target_feature(enable = "avx2")]
pub fn xor(a: __m256d, b: __m256d) -> __m256d {
    _mm256_xor_pd(a, b)
}
/// Writes the mask's lanes as bools 0 / 1 to `p[i..i + 4]`.
///
/// # Safety
/// `p[i..i + 4]` must be in bounds.
#[inline]
#[target_feature(enable = "avx2")]
pub unsafe fn flags(p: *mut bool, i: usize, m: M) {
    // SAFETY: in bounds (the caller); every byte written is 0 or 1, a valid bool.
    unsafe { (p.add(i) as *mut u32).write_unaligned(super::SPREAD[bits(m) as usize] as u32) }
}
/// The binary64 just below each lane of a magnitude `a` (a NaN for +0).
#[inline]
#[target_feature(enable = "avx2")]
fn pred(a: __m256d) -> __m256d {
    _mm256_castsi256_pd(_mm256_sub_epi64(_mm256_castpd_si256(a), int(1)))
}
/// Each lane's binary64 exponent field alone: 2^⌊log2 |x|⌋ for a normal x, 0 for ±0
/// (and binary64 subnormals), +∞ for ±∞ and NaN.
#[inline]
#[target_feature(enable = "avx2")]
fn exponent(x: __m256d) -> __m256d {
    _mm256_and_pd(x, _mm256_castsi256_pd(int(0x7ff0_0000_0000_0000)))
}
/// The range filter (see [`crate::format::narrow`]): true when on every lane the
/// nonzero magnitudes among `v` (the stage-1 results and the direction) are at least
/// `n.fast_lo` and all magnitudes at most `n.fast_hi`, so that no result of stages 2-7
/// leaves {±0} ∪ [2^emin, max]. A NaN fails (the unfiltered stage 1 turns an infinite
/// difference into a NaN, which must take the filtered road).
///
/// Four operations a value, on a = |x|: the upper limit on the sum of the magnitudes (a
/// rounded sum of nonnegative terms is at least each term; a NaN or an infinity makes it
/// fail), which is stricter than the limit on each; the lower limit on the binary64 just
/// below a (encoding − 1: order kept for a > 0, and ±0 becomes the all-ones NaN, which
/// `vminpd` skips, returning its second operand, the running minimum). Four running sums
/// and minima, joined last.
#[inline]
#[target_feature(enable = "avx2")]
pub fn fast_ok(v: &[__m256d; 12], n: &Narrow) -> bool {
    let mut sum = [splat(0.0); 4];
    let mut lo = [splat(f64::INFINITY); 4];
    for (k, &x) in v.iter().enumerate() {
        let a = abs(x);
        sum[k % 4] = add(sum[k % 4], a);
        lo[k % 4] = _mm256_min_pd(pred(a), lo[k % 4]);
    }
    let sum = add(add(sum[0], sum[1]), add(sum[2], sum[3]));
    let lo = _mm256_min_pd(_mm256_min_pd(lo[0], lo[1]), _mm256_min_pd(lo[2], lo[3]));
    bits(and_m(le(sum, splat(n.fast_hi)), le(pred(splat(n.fast_lo)), lo))) == (1 << LANES) - 1
}
/// Whether a lane of magnitudes `a` lies outside [2^emin, max + ulp(max)/2) (±0 and a NaN
/// included: they take [`round_full`]'s full road, which keeps them): a's encoding minus
/// 2^emin's is at least the range's width as unsigned integers (order kept for magnitudes;
/// ±0 and a < 2^emin wrap to the top), read by AVX2's signed compare after adding 2^63 —
/// one wrapping add of 2^63 − 2^emin's encoding.
#[inline]
#[target_feature(enable = "avx2")]
fn any_outside_normal(a: __m256d, n: &Narrow) -> bool {
    let odd = _mm256_castpd_si256(outside_normal(a, n));
    _mm256_testz_si256(odd, odd) == 0
}
/// The lanes [`any_outside_normal`] finds (all ones where outside).
#[inline]
#[target_feature(enable = "avx2")]
fn outside_normal(a: __m256d, n: &Narrow) -> M {
    let (lo, hi) = (n.min_normal.to_bits(), n.overflow_at.to_bits());
    let t = _mm256_add_epi64(_mm256_castpd_si256(a), int((1u64 << 63).wrapping_sub(lo)));
    _mm256_castsi256_pd(_mm256_cmpgt_epi64(t, int((hi - lo - 1) ^ (1u64 << 63))))
}
/// [`super::v8d::next_up_soft`]'s normal-range step on 4 lanes (the range test as
/// [`any_outside_normal`] reads it: AVX2's signed compare after adding 2^63).
#[inline]
#[target_feature(enable = "avx2")]
fn step_inside(x: __m256d, n: &Narrow) -> Option<__m256d> {
    let b = _mm256_castpd_si256(x);
    let a = _mm256_and_si256(b, int(0x7fff_ffff_ffff_ffff));
    let (lo, hi) = (n.min_normal.to_bits() + 1, n.max_finite.to_bits());
    let t = _mm256_add_epi64(a, int((1u64 << 63).wrapping_sub(lo)));
    let odd = _mm256_cmpgt_epi64(t, int((hi - lo - 1) ^ (1u64 << 63)));
    if _mm256_testz_si256(odd, odd) == 0 {
        return None;
    }
    // ±2^(52 − M): its negation where the sign bit is set
    let m = _mm256_sub_epi64(_mm256_setzero_si256(), _mm256_srli_epi64::<63>(b));
    let step = int(1u64 << (52 - n.lay.man_bits));
    let signed = _mm256_sub_epi64(_mm256_xor_si256(step, m), m);
    Some(_mm256_castsi256_pd(_mm256_add_epi64(b, signed)))
}
narrow_ops!("avx2", "avx2,fma", __m256d, _mm256_fmadd_pd, _mm256_fmsub_pd);
/// Loads 4 `eEmM` encodings as binary64 (exact).
///
/// # Safety
/// `p[i..i + 4]` must be in bounds.
#[inline]
#[target_feature(enable = "avx2")]
pub unsafe fn load_soft(p: *const u64, i: usize, n: &Narrow) -> __m256d {
    let (l, m) = (n.lay, n.lay.man_bits);
    let b = unsafe { _mm256_loadu_si256(p.add(i) as *const __m256i) };
    if n.e8 {
        return unsafe { load_e8(p, i, n) };
    }
    let emax = (1u64 << l.exp_bits) - 1;
    let e = _mm256_and_si256(_mm256_srl_epi64(b, count(m)), int(emax));
    let f = _mm256_and_si256(b, int((1u64 << m) - 1));
    let s = _mm256_slli_epi64::<63>(_mm256_srl_epi64(b, count(l.width() - 1)));
    let frac = _mm256_sll_epi64(f, count(52 - m));
    let bexp = _mm256_sll_epi64(_mm256_add_epi64(e, int((1023 - l.bias()) as u64)), count(52));
    let normal = _mm256_or_si256(_mm256_or_si256(s, bexp), frac);
    let special = _mm256_or_si256(_mm256_or_si256(s, int(0x7ff0_0000_0000_0000)), frac);
    // a subnormal: fraction × 2^(emin − M), the fraction converted exactly via 2^52
    let two52 = splat(4503599627370496.0);
    let fv = _mm256_sub_pd(_mm256_castsi256_pd(_mm256_or_si256(f, int(0x4330_0000_0000_0000))), two52);
    let sub = _mm256_or_pd(_mm256_mul_pd(fv, splat(n.step)), _mm256_castsi256_pd(s));
    let r = blend(_mm256_castsi256_pd(normal), sub, _mm256_castsi256_pd(_mm256_cmpeq_epi64(e, int(0))));
    blend(r, _mm256_castsi256_pd(special), _mm256_castsi256_pd(_mm256_cmpeq_epi64(e, int(emax))))
}
/// [`load_soft`] for `e8mM` with M ≤ 23 (`n.e8`), as `v8d::load_e8`.
///
/// # Safety
/// `p[i..i + 4]` must be in bounds.
#[inline]
#[target_feature(enable = "avx2")]
pub unsafe fn load_e8(p: *const u64, i: usize, n: &Narrow) -> __m256d {
    let b = unsafe { _mm256_loadu_si256(p.add(i) as *const __m256i) };
    // the low 32 bits of each lane
    let lo = _mm256_castsi256_si128(_mm256_permutevar8x32_epi32(b, _mm256_setr_epi32(0, 2, 4, 6, 0, 2, 4, 6)));
    _mm256_cvtps_pd(_mm_castsi128_ps(_mm_sll_epi32(lo, count(n.e8_shift))))
}
/// [`store_soft`] for `e8mM` with M ≤ 23 (`n.e8`), as `v8d::store_e8`.
///
/// # Safety
/// `p[i..i + 4]` must be in bounds.
#[inline]
#[target_feature(enable = "avx2")]
pub unsafe fn store_e8(p: *mut u64, i: usize, x: __m256d, n: &Narrow) {
    let b32 = _mm_srl_epi32(_mm_castps_si128(_mm256_cvtpd_ps(x)), count(n.e8_shift));
    unsafe { _mm256_storeu_si256(p.add(i) as *mut __m256i, _mm256_cvtepu32_epi64(b32)) }
}
/// Stores 4 lanes holding `eEmM` values (or a NaN, stored as the canonical NaN) as
/// encodings.
///
/// # Safety
/// `p[i..i + 4]` must be in bounds.
#[inline]
#[target_feature(enable = "avx2")]
pub unsafe fn store_soft(p: *mut u64, i: usize, x: __m256d, n: &Narrow) {
    let (l, m) = (n.lay, n.lay.man_bits);
    if n.e8 {
        return unsafe { store_e8(p, i, blend(x, canonical_nan(), unord(x, x)), n) };
    }
    let b = _mm256_castpd_si256(x);
    let s = _mm256_sll_epi64(_mm256_srli_epi64::<63>(b), count(l.width() - 1));
    let a = abs(x);
    let bexp = _mm256_srli_epi64::<52>(_mm256_castpd_si256(a));
    let e = _mm256_sub_epi64(bexp, int((1023 - l.bias()) as u64));
    let frac = _mm256_srl_epi64(_mm256_and_si256(b, int((1u64 << 52) - 1)), count(52 - m));
    let normal = _mm256_or_si256(s, _mm256_or_si256(_mm256_sll_epi64(e, count(m)), frac));
    // a subnormal: |x| / 2^(emin − M) is an integer < 2^52, read off 2^52 + it
    let two52 = splat(4503599627370496.0);
    let q = _mm256_castpd_si256(_mm256_add_pd(_mm256_mul_pd(a, splat(n.inv_step)), two52));
    let sub = _mm256_or_si256(s, _mm256_and_si256(q, int((1u64 << 52) - 1)));
    let inf = _mm256_or_si256(s, int(l.exp_mask()));
    let r = blend(_mm256_castsi256_pd(normal), _mm256_castsi256_pd(sub), lt(a, splat(n.min_normal)));
    let r = blend(r, _mm256_castsi256_pd(inf), _mm256_cmp_pd::<_CMP_EQ_OQ>(a, splat(f64::INFINITY)));
    let r = blend(r, _mm256_castsi256_pd(int(l.canonical_nan())), unord(x, x));
    unsafe { _mm256_storeu_si256(p.add(i) as *mut __m256i, _mm256_castpd_si256(r)) }
}
/// [`super::v8d::next_up_soft_n`] on 4 lanes.
#[inline]
#[target_feature(enable = "avx2,fma")]
pub fn next_up_soft_n(x: __m256d, k: u32, n: &Narrow) -> __m256d {
    if n.e8 && k <= 64 && (k << n.e8_shift) <= 1 << 24 {
        // exact both ways: the lanes are binary32 values (the upper four binary32 lanes of
        // the step are don't-care)
        let f = _mm256_castps128_ps256(_mm256_cvtpd_ps(x));
        let r = _mm256_castps256_ps128(super::v8::next_up_by_n(f, (k << n.e8_shift) as i32));
        blend(_mm256_cvtps_pd(r), x, _mm256_cmp_pd::<_CMP_UNORD_Q>(x, x))
    } else {
        (0..k).fold(x, |v, _| next_up_soft(v, n))
    }
}
