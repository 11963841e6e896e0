//! AVX-512F: 16 lanes, a mask is a `__mmask16` (binary16 via the AVX-512F conversions,
//! the binary16 step on 256-bit AVX2 integer lanes).

use half::f16;
use std::arch::x86_64::*;
/// Lanes per vector.
pub const LANES: usize = 16;
/// A mask.
pub type M = __mmask16;
table_ops!("avx512f", __m512, M, "binary32";
    add = _mm512_add_ps, sub = _mm512_sub_ps, mul = _mm512_mul_ps, div = _mm512_div_ps,
    max = _mm512_max_ps, min = _mm512_min_ps, cmp = _mm512_cmp_ps_mask);
/// vcvtps2ph: round to nearest even, exceptions suppressed (flags are not modelled).
const NEAREST: i32 = _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC;
/// Loads 16 bf16 encodings as binary32 (exact: bf16 is binary32's top half).
///
/// # Safety
/// `p[i..i + 16]` must be in bounds.
#[inline]
#[target_feature(enable = "avx512f")]
pub unsafe fn load_bf16(p: *const u16, i: usize) -> __m512 {
    let h = unsafe { _mm256_loadu_si256(p.add(i) as *const __m256i) };
    _mm512_castsi512_ps(_mm512_slli_epi32::<16>(_mm512_cvtepu16_epi32(h)))
}
/// Stores 16 lanes holding bf16 values as bf16 encodings (their top halves).
///
/// # Safety
/// `p[i..i + 16]` must be in bounds.
#[inline]
#[target_feature(enable = "avx512f")]
pub unsafe fn store_bf16(p: *mut u16, i: usize, x: __m512) {
    let w = _mm512_srli_epi32::<16>(_mm512_castps_si512(x));
    unsafe { _mm256_storeu_si256(p.add(i) as *mut __m256i, _mm512_cvtepi32_epi16(w)) }
}
/// Rounds binary32 lanes to bf16, nearest-even, as the scalar model's `Bf16::round_f32`.
#[inline]
#[target_feature(enable = "avx512f")]
pub fn round_bf16(x: __m512) -> __m512 {
    let b = _mm512_castps_si512(x);
    let lsb = _mm512_and_si512(_mm512_srli_epi32::<16>(b), _mm512_set1_epi32(1));
    let r = _mm512_add_epi32(_mm512_add_epi32(b, _mm512_set1_epi32(0x7fff)), lsb);
    _mm512_castsi512_ps(_mm512_and_si512(r, _mm512_set1_epi32(0xffff_0000_u32 as i32)))
}
/// Under FTZ, lanes below binary32's (and bf16's) smallest normal become zeros of the same sign.
#[inline]
#[target_feature(enable = "avx512f")]
pub fn flush_bf16(x: __m512, ftz: bool) -> __m512 {
    match ftz {
        true => blend(x, sign(x), lt(abs(x), splat(f32::MIN_POSITIVE))),
        false => x,
    }
}
/// Every lane x.
#[inline]
#[target_feature(enable = "avx512f")]
pub fn splat(x: f32) -> __m512 {
    _mm512_set1_ps(x)
}
/// Every lane binary32's canonical NaN (`vcvtps2ph` makes it binary16's 0x7e00).
#[inline]
#[target_feature(enable = "avx512f")]
pub fn canonical_nan() -> __m512 {
    splat_bits(0x7fc0_0000)
}
/// Every lane the binary16 value x, held in binary32 (exact).
#[inline]
#[target_feature(enable = "avx512f")]
pub fn splat16(x: f16) -> __m512 {
    splat(x.to_f32())
}
/// Every lane the binary32 with these bits.
#[inline]
#[target_feature(enable = "avx512f")]
pub fn splat_bits(x: u32) -> __m512 {
    _mm512_castsi512_ps(_mm512_set1_epi32(x as i32))
}
/// Both masks.
#[inline]
#[target_feature(enable = "avx512f")]
pub fn and_m(a: M, b: M) -> M {
    a & b
}
/// The mask as lane bits (lane k in bit k).
#[inline]
#[target_feature(enable = "avx512f")]
pub fn bits(m: M) -> u32 {
    m as u32
}
/// `m ? b : a` per lane.
#[inline]
#[target_feature(enable = "avx512f")]
pub fn blend(a: __m512, b: __m512, m: M) -> __m512 {
    _mm512_mask_blend_ps(m, a, b)
}
/// `sign(x) ? b : a` per lane.
#[inline]
#[target_feature(enable = "avx512f")]
pub fn blend_sign(a: __m512, b: __m512, x: __m512) -> __m512 {
    let m = _mm512_test_epi32_mask(_mm512_castps_si512(x), _mm512_set1_epi32(i32::MIN));
    _mm512_mask_blend_ps(m, a, b)
}
/// The sign bits of x (everything else cleared).
#[inline]
#[target_feature(enable = "avx512f")]
pub fn sign(x: __m512) -> __m512 {
    _mm512_castsi512_ps(_mm512_and_si512(_mm512_castps_si512(x), _mm512_set1_epi32(i32::MIN)))
}
/// |x| by clearing the sign bit.
#[inline]
#[target_feature(enable = "avx512f")]
pub fn abs(x: __m512) -> __m512 {
    _mm512_castsi512_ps(_mm512_and_si512(_mm512_castps_si512(x), _mm512_set1_epi32(i32::MAX)))
}
/// a ⊕ b, bitwise.
#[inline]
#[target_feature(enable = "avx512f")]
pub fn xor(a: __m512, b: __m512) -> __m512 {
    _mm512_castsi512_ps(_mm512_xor_si512(_mm512_castps_si512(a), _mm512_castps_si512(b)))
}
/// Either mask.
#[inline]
#[target_feature(enable = "avx512f")]
pub fn or_m(a: M, b: M) -> M {
    a | b
}
/// The mask's complement.
#[inline]
#[target_feature(enable = "avx512f")]
pub fn not_m(a: M) -> M {
    !a
}
/// `sel ? b : a` per lane, on masks.
#[inline]
#[target_feature(enable = "avx512f")]
pub fn blend_m(a: M, b: M, sel: M) -> M {
    (a & !sel) | (b & sel)
}
/// Lanes whose sign bit is set.
#[inline]
#[target_feature(enable = "avx512f")]
pub fn sign_m(x: __m512) -> M {
    _mm512_test_epi32_mask(_mm512_castps_si512(x), _mm512_set1_epi32(i32::MIN))
}
/// Writes the mask's lanes as bools 0 / 1 to `p[i..i + 16]`.
///
/// # Safety
/// `p[i..i + 16]` must be in bounds.
#[inline]
#[target_feature(enable = "avx512f")]
pub unsafe fn flags(p: *mut bool, i: usize, m: M) {
    // SAFETY: in bounds (the caller); every byte written is 0 or 1, a valid bool.
    unsafe {
        (p.add(i) as *mut u64).write_unaligned(super::SPREAD[(m & 0xff) as usize]);
        (p.add(i + 8) as *mut u64).write_unaligned(super::SPREAD[(m >> 8) as usize]);
    }
}
/// # Safety
/// `p[i..i + 16]` must be in bounds.
#[inline]
#[target_feature(enable = "avx512f")]
pub unsafe fn load32(p: *const f32, i: usize) -> __m512 {
    unsafe { _mm512_loadu_ps(p.add(i)) }
}
/// # Safety
/// `p[i..i + 16]` must be in bounds.
#[inline]
#[target_feature(enable = "avx512f")]
pub unsafe fn store32(p: *mut f32, i: usize, x: __m512) {
    unsafe { _mm512_storeu_ps(p.add(i), x) }
}
/// # Safety
/// `p[i..i + 16]` must be in bounds.
#[inline]
#[target_feature(enable = "avx512f")]
pub unsafe fn load16(p: *const f16, i: usize) -> __m512 {
    unsafe { _mm512_cvtph_ps(_mm256_loadu_si256(p.add(i) as *const __m256i)) }
}
/// # Safety
/// `p[i..i + 16]` must be in bounds.
#[inline]
#[target_feature(enable = "avx512f")]
pub unsafe fn store16(p: *mut f16, i: usize, x: __m512) {
    unsafe { _mm256_storeu_si256(p.add(i) as *mut __m256i, _mm512_cvtps_ph::<NEAREST>(x)) }
}
/// Rounds binary32 lanes to binary16 (nearest-even), held in binary32.
#[inline]
#[target_feature(enable = "avx512f")]
pub fn round16(x: __m512) -> __m512 {
    _mm512_cvtph_ps(_mm512_cvtps_ph::<NEAREST>(x))
}
/// The next binary32 encoding above each lane, as [`super::v8::next_up`].
#[inline]
#[target_feature(enable = "avx512f")]
pub fn next_up(v: __m512) -> __m512 {
    next_up_by(v, 1)
}
/// The step up by `unit` encodings of binary32 (1: binary32's grid, 2^16: bf16's), as
/// [`super::v8::next_up_by`]: NaN and +inf unchanged, ±0 to `unit`, negative values `unit`
/// encodings toward zero.
#[inline]
#[target_feature(enable = "avx512f")]
fn next_up_by(v: __m512, unit: i32) -> __m512 {
    let b = _mm512_castps_si512(_mm512_add_ps(v, _mm512_setzero_ps()));
    let keep = _mm512_cmp_ps_mask::<_CMP_NLT_UQ>(v, _mm512_set1_ps(f32::INFINITY));
    let one = _mm512_or_si512(_mm512_srai_epi32::<31>(b), _mm512_set1_epi32(1));
    let step = _mm512_sllv_epi32(one, _mm512_set1_epi32(unit.trailing_zeros() as i32));
    let r = _mm512_add_epi32(b, step);
    _mm512_castsi512_ps(_mm512_mask_blend_epi32(keep, r, _mm512_castps_si512(v)))
}
/// `n` steps of [`next_up_by`] at once, as [`super::v8::next_up_by_n`].
#[inline]
#[target_feature(enable = "avx512f")]
fn next_up_by_n(v: __m512, units: i32) -> __m512 {
    debug_assert!((1..=1 << 24).contains(&units));
    let b = _mm512_castps_si512(v);
    let sgn = _mm512_srai_epi32::<31>(b);
    let mag = _mm512_and_si512(b, _mm512_set1_epi32(0x7fff_ffff));
    let key = _mm512_sub_epi32(_mm512_xor_si512(mag, sgn), sgn);
    let top = 0x7f80_0000;
    let k = _mm512_add_epi32(_mm512_min_epi32(key, _mm512_set1_epi32(top - units)), _mm512_set1_epi32(units));
    let neg = _mm512_cmplt_epi32_mask(k, _mm512_set1_epi32(1));
    let r = _mm512_mask_or_epi32(_mm512_abs_epi32(k), neg, _mm512_abs_epi32(k), _mm512_set1_epi32(i32::MIN));
    _mm512_castsi512_ps(_mm512_mask_blend_epi32(_mm512_cmp_ps_mask::<_CMP_UNORD_Q>(v, v), r, b))
}
/// `n` steps of [`next_up`].
#[inline]
#[target_feature(enable = "avx512f")]
pub fn next_up_n(v: __m512, n: u32) -> __m512 {
    if n <= 64 {
        next_up_by_n(v, n as i32)
    } else {
        (0..n).fold(v, |v, _| next_up(v))
    }
}
/// `n` steps of [`next_up_bf16`].
#[inline]
#[target_feature(enable = "avx512f")]
pub fn next_up_bf16_n(v: __m512, n: u32) -> __m512 {
    if n <= 64 {
        next_up_by_n(v, (n as i32) << 16)
    } else {
        (0..n).fold(v, |v, _| next_up_bf16(v))
    }
}
/// [`next_up`] on the bf16 grid, for lanes that hold bf16 values (a step of 2^16 in the
/// binary32 encoding; NaN and +inf unchanged, ±0 to the least bf16 subnormal).
#[inline]
#[target_feature(enable = "avx512f")]
pub fn next_up_bf16(v: __m512) -> __m512 {
    next_up_by(v, 0x1_0000)
}
/// [`next_up`] on the binary16 grid, for lanes that hold binary16 values.
#[inline]
#[target_feature(enable = "avx512f,avx2")]
pub fn next_up16(v: __m512) -> __m512 {
    // exact: every lane is a binary16 value (a NaN stays a NaN and is kept)
    _mm512_cvtph_ps(super::step_up16(_mm512_cvtps_ph::<NEAREST>(v)))
}
