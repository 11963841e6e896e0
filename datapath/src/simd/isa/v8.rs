//! AVX2 (+ F16C for binary16): 8 lanes, a mask is a vector of all-ones / all-zeros lanes.

use half::f16;
use std::arch::x86_64::*;
/// Lanes per vector.
pub const LANES: usize = 8;
/// A mask.
pub type M = __m256;
table_ops!("avx2", __m256, M, "binary32";
    add = _mm256_add_ps, sub = _mm256_sub_ps, mul = _mm256_mul_ps, div = _mm256_div_ps,
    max = _mm256_max_ps, min = _mm256_min_ps, cmp = _mm256_cmp_ps);
/// Every lane x.
#[inline]
#[target_feature(enable = "avx2")]
pub fn splat(x: f32) -> __m256 {
    _mm256_set1_ps(x)
}
/// Every lane binary32's canonical NaN (`vcvtps2ph` makes it binary16's 0x7e00).
#[inline]
#[target_feature(enable = "avx2")]
pub fn canonical_nan() -> __m256 {
    splat_bits(0x7fc0_0000)
}
/// Every lane the binary16 value x, held in binary32 (exact).
#[inline]
#[target_feature(enable = "avx2")]
pub fn splat16(x: f16) -> __m256 {
    splat(x.to_f32())
}
/// Every lane the binary32 with these bits.
#[inline]
#[target_feature(enable = "avx2")]
pub fn splat_bits(x: u32) -> __m256 {
    _mm256_castsi256_ps(_mm256_set1_epi32(x as i32))
}
/// Both masks.
#[inline]
#[target_feature(enable = "avx2")]
pub fn and_m(a: M, b: M) -> M {
    _mm256_and_ps(a, b)
}
/// The mask as lane bits (lane k in bit k).
#[inline]
#[target_feature(enable = "avx2")]
pub fn bits(m: M) -> u32 {
    _mm256_movemask_ps(m) as u32
}
/// `m ? b : a` per lane.
#[inline]
#[target_feature(enable = "avx2")]
pub fn blend(a: __m256, b: __m256, m: M) -> __m256 {
    _mm256_blendv_ps(a, b, m)
}
/// `sign(x) ? b : a` per lane (the sign bit of x, as vblendvps reads it).
#[inline]
#[target_feature(enable = "avx2")]
pub fn blend_sign(a: __m256, b: __m256, x: __m256) -> __m256 {
    _mm256_blendv_ps(a, b, x)
}
/// The sign bits of x (everything else cleared).
#[inline]
#[target_feature(enable = "avx2")]
pub fn sign(x: __m256) -> __m256 {
    _mm256_and_ps(x, _mm256_set1_ps(-0.0))
}
/// |x| by clearing the sign bit.
#[inline]
#[target_feature(enable = "avx2")]
pub fn abs(x: __m256) -> __m256 {
    _mm256_andnot_ps(_mm256_set1_ps(-0.0), x)
}
/// a ⊕ b, bitwise.
#[inline]
#[target_feature(enable = "avx2")]
pub fn xor(a: __m256, b: __m256) -> __m256 {
    _mm256_xor_ps(a, b)
}
/// Either mask.
#[inline]
#[target_feature(enable = "avx2")]
pub fn or_m(a: M, b: M) -> M {
    _mm256_or_ps(a, b)
}
/// The mask's complement.
#[inline]
#[target_feature(enable = "avx2")]
pub fn not_m(a: M) -> M {
    _mm256_xor_ps(a, _mm256_castsi256_ps(_mm256_set1_epi32(-1)))
}
/// `sel ? b : a` per lane, on masks.
#[inline]
#[target_feature(enable = "avx2")]
pub fn blend_m(a: M, b: M, sel: M) -> M {
    _mm256_blendv_ps(a, b, sel)
}
/// Lanes whose sign bit is set.
#[inline]
#[target_feature(enable = "avx2")]
pub fn sign_m(x: __m256) -> M {
    _mm256_castsi256_ps(_mm256_srai_epi32::<31>(_mm256_castps_si256(x)))
}
/// Writes the mask's lanes as bools 0 / 1 to `p[i..i + 8]`.
///
/// # Safety
/// `p[i..i + 8]` must be in bounds.
#[inline]
#[target_feature(enable = "avx2")]
pub unsafe fn flags(p: *mut bool, i: usize, m: M) {
    // SAFETY: in bounds (the caller); every byte written is 0 or 1, a valid bool.
    unsafe { (p.add(i) as *mut u64).write_unaligned(super::SPREAD[bits(m) as usize]) }
}
/// # Safety
/// `p[i..i + 8]` must be in bounds.
#[inline]
#[target_feature(enable = "avx2")]
pub unsafe fn load32(p: *const f32, i: usize) -> __m256 {
    unsafe { _mm256_loadu_ps(p.add(i)) }
}
/// # Safety
/// `p[i..i + 8]` must be in bounds.
#[inline]
#[target_feature(enable = "avx2")]
pub unsafe fn store32(p: *mut f32, i: usize, x: __m256) {
    unsafe { _mm256_storeu_ps(p.add(i), x) }
}
/// # Safety
/// `p[i..i + 8]` must be in bounds.
#[inline]
#[target_feature(enable = "avx2,f16c")]
pub unsafe fn load16(p: *const f16, i: usize) -> __m256 {
    unsafe { _mm256_cvtph_ps(_mm_loadu_si128(p.add(i) as *const __m128i)) }
}
/// # Safety
/// `p[i..i + 8]` must be in bounds.
#[inline]
#[target_feature(enable = "avx2,f16c")]
pub unsafe fn store16(p: *mut f16, i: usize, x: __m256) {
    unsafe { _mm_storeu_si128(p.add(i) as *mut __m128i, _mm256_cvtps_ph::<_MM_FROUND_TO_NEAREST_INT>(x)) }
}
/// Loads 8 bf16 encodings as binary32 (exact: bf16 is binary32's top half).
///
/// # Safety
/// `p[i..i + 8]` must be in bounds.
#[inline]
#[target_feature(enable = "avx2")]
pub unsafe fn load_bf16(p: *const u16, i: usize) -> __m256 {
    let h = unsafe { _mm_loadu_si128(p.add(i) as *const __m128i) };
    _mm256_castsi256_ps(_mm256_slli_epi32::<16>(_mm256_cvtepu16_epi32(h)))
}
/// Stores 8 lanes holding bf16 values as bf16 encodings (their top halves).
///
/// # Safety
/// `p[i..i + 8]` must be in bounds.
#[inline]
#[target_feature(enable = "avx2")]
pub unsafe fn store_bf16(p: *mut u16, i: usize, x: __m256) {
    let w = _mm256_srli_epi32::<16>(_mm256_castps_si256(x));
    // packing works per 128-bit half: take quadwords 0 and 2
    let packed = _mm256_permute4x64_epi64::<0b1000>(_mm256_packus_epi32(w, w));
    unsafe { _mm_storeu_si128(p.add(i) as *mut __m128i, _mm256_castsi256_si128(packed)) }
}
/// Rounds binary32 lanes to bf16, nearest-even, as the scalar model's `Bf16::round_f32`:
/// `(b + 0x7fff + ((b >> 16) & 1))` with the low 16 bits cleared (a carry steps the
/// exponent; past the largest finite value it reaches infinity).
#[inline]
#[target_feature(enable = "avx2")]
pub fn round_bf16(x: __m256) -> __m256 {
    let b = _mm256_castps_si256(x);
    let lsb = _mm256_and_si256(_mm256_srli_epi32::<16>(b), _mm256_set1_epi32(1));
    let r = _mm256_add_epi32(_mm256_add_epi32(b, _mm256_set1_epi32(0x7fff)), lsb);
    _mm256_castsi256_ps(_mm256_and_si256(r, _mm256_set1_epi32(0xffff_0000_u32 as i32)))
}
/// Under FTZ, lanes below binary32's (and bf16's) smallest normal become zeros of the same sign.
#[inline]
#[target_feature(enable = "avx2")]
pub fn flush_bf16(x: __m256, ftz: bool) -> __m256 {
    match ftz {
        true => blend(x, sign(x), lt(abs(x), splat(f32::MIN_POSITIVE))),
        false => x,
    }
}
/// Rounds binary32 lanes to binary16 (nearest-even), held in binary32.
#[inline]
#[target_feature(enable = "avx2,f16c")]
pub fn round16(x: __m256) -> __m256 {
    _mm256_cvtph_ps(_mm256_cvtps_ph::<_MM_FROUND_TO_NEAREST_INT>(x))
}
/// The next binary32 encoding above each lane (NaN and +inf unchanged, ±0 to the
/// smallest subnormal), as the scalar model's `next_up` with IEEE subnormals.
#[inline]
#[target_feature(enable = "avx2")]
pub fn next_up(v: __m256) -> __m256 {
    next_up_by(v, 1)
}
/// The step up by `unit` encodings of binary32 (1: binary32's grid, 2^16: bf16's): NaN
/// and +inf unchanged, ±0 to `unit`, negative values `unit` encodings toward zero. (−0 is
/// first made +0 by adding +0, exact for every other number; a NaN's bits are kept.)
#[inline]
#[target_feature(enable = "avx2")]
pub(in crate::simd) fn next_up_by(v: __m256, unit: i32) -> __m256 {
    let b = _mm256_castps_si256(_mm256_add_ps(v, _mm256_setzero_ps()));
    // NaN or +inf: kept
    let keep = _mm256_castps_si256(_mm256_cmp_ps::<_CMP_NLT_UQ>(v, _mm256_set1_ps(f32::INFINITY)));
    // negative: bits − unit, positive (+0 included): bits + unit
    let one = _mm256_or_si256(_mm256_srai_epi32::<31>(b), _mm256_set1_epi32(1));
    // (unit a power of two: ±1 shifted)
    let step = _mm256_sllv_epi32(one, _mm256_set1_epi32(unit.trailing_zeros() as i32));
    let r = _mm256_add_epi32(b, step);
    _mm256_castsi256_ps(_mm256_blendv_epi8(r, _mm256_castps_si256(v), keep))
}
/// `n` steps of [`next_up_by`] at once, `unit · n` (`units`) at most 2^24: on the ordered
/// key k = ±|bits| (the sign's, −0 and +0 both 0) a step adds `unit`, up to +inf's key
/// 2^31 − 2^23, and a key k ≤ 0 is the negative value of magnitude −k (0: −0, which only a
/// step from below reaches); NaN kept.
#[inline]
#[target_feature(enable = "avx2")]
pub(in crate::simd) fn next_up_by_n(v: __m256, units: i32) -> __m256 {
    debug_assert!((1..=1 << 24).contains(&units));
    let b = _mm256_castps_si256(v);
    let sgn = _mm256_srai_epi32::<31>(b);
    let mag = _mm256_and_si256(b, _mm256_set1_epi32(0x7fff_ffff));
    let key = _mm256_sub_epi32(_mm256_xor_si256(mag, sgn), sgn);
    let top = 0x7f80_0000;
    let k = _mm256_add_epi32(_mm256_min_epi32(key, _mm256_set1_epi32(top - units)), _mm256_set1_epi32(units));
    let neg = _mm256_cmpgt_epi32(_mm256_set1_epi32(1), k);
    let r = _mm256_or_si256(_mm256_abs_epi32(k), _mm256_and_si256(neg, _mm256_set1_epi32(i32::MIN)));
    _mm256_castsi256_ps(_mm256_blendv_epi8(r, b, _mm256_castps_si256(_mm256_cmp_ps::<_CMP_UNORD_Q>(v, v))))
}
/// `n` steps of [`next_up`].
#[inline]
#[target_feature(enable = "avx2")]
pub fn next_up_n(v: __m256, n: u32) -> __m256 {
    if n <= 64 {
        next_up_by_n(v, n as i32)
    } else {
        (0..n).fold(v, |v, _| next_up(v))
    }
}
/// `n` steps of [`next_up_bf16`].
#[inline]
#[target_feature(enable = "avx2")]
pub fn next_up_bf16_n(v: __m256, n: u32) -> __m256 {
    if n <= 64 {
        next_up_by_n(v, (n as i32) << 16)
    } else {
        (0..n).fold(v, |v, _| next_up_bf16(v))
    }
}
/// [`next_up`] on the bf16 grid, for lanes that hold bf16 values (a step of 2^16 in the
/// binary32 encoding; NaN and +inf unchanged, ±0 to the least bf16 subnormal).
#[inline]
#[target_feature(enable = "avx2")]
pub fn next_up_bf16(v: __m256) -> __m256 {
    next_up_by(v, 0x1_0000)
}
/// [`next_up`] on the binary16 grid, for lanes that hold binary16 values.
#[inline]
#[target_feature(enable = "avx2,f16c")]
pub fn next_up16(v: __m256) -> __m256 {
    // exact: every lane is a binary16 value (a NaN stays a NaN and is kept); the upper
    // 8 halves of the 256-bit step are don't-care
    let b = _mm256_castsi128_si256(_mm256_cvtps_ph::<_MM_FROUND_TO_NEAREST_INT>(v));
    _mm256_cvtph_ps(_mm256_castsi256_si128(super::step_up16(b)))
}
