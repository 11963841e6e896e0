//! AVX512-FP16: 32 binary16 lanes computed natively (`vaddph` … `vdivph`, each correctly
//! rounded to binary16, round to nearest even from MXCSR's default, subnormals always kept:
//! the FP16 instructions ignore MXCSR.DAZ / FTZ), a mask is a `__mmask32`. Only the binary16
//! kernels use it: loads, stores and the rounding step are identities.

use half::f16;
use std::arch::x86_64::*;
/// Lanes per vector.
pub const LANES: usize = 32;
/// A mask.
pub type M = __mmask32;
table_ops!("avx512fp16,avx512bw,avx512f", __m512h, M, "binary16";
    add = _mm512_add_ph, sub = _mm512_sub_ph, mul = _mm512_mul_ph, div = _mm512_div_ph,
    max = _mm512_max_ph, min = _mm512_min_ph, cmp = _mm512_cmp_ph_mask);
/// Every lane the binary16 with these bits.
#[inline]
#[target_feature(enable = "avx512fp16,avx512bw,avx512f")]
fn splat_bits(x: u16) -> __m512h {
    _mm512_castsi512_ph(_mm512_set1_epi16(x as i16))
}
/// Every lane x, a binary16 value (0, ±1, −0, a det threshold read from binary16).
#[inline]
#[target_feature(enable = "avx512fp16,avx512bw,avx512f")]
pub fn splat(x: f32) -> __m512h {
    let h = f16::from_f32(x);
    debug_assert!(h.to_f32().to_bits() == x.to_bits(), "{x} is not a binary16 value");
    splat_bits(h.to_bits())
}
/// Every lane the binary16 x, bits and all.
#[inline]
#[target_feature(enable = "avx512fp16,avx512bw,avx512f")]
pub fn splat16(x: f16) -> __m512h {
    splat_bits(x.to_bits())
}
/// Every lane binary16's canonical NaN, 0x7e00.
#[inline]
#[target_feature(enable = "avx512fp16,avx512bw,avx512f")]
pub fn canonical_nan() -> __m512h {
    splat_bits(0x7e00)
}
/// Both masks.
#[inline]
#[target_feature(enable = "avx512fp16,avx512bw,avx512f")]
pub fn and_m(a: M, b: M) -> M {
    a & b
}
/// The mask as lane bits (lane k in bit k).
#[inline]
#[target_feature(enable = "avx512fp16,avx512bw,avx512f")]
pub fn bits(m: M) -> u32 {
    m
}
/// `m ? b : a` per lane.
#[inline]
#[target_feature(enable = "avx512fp16,avx512bw,avx512f")]
pub fn blend(a: __m512h, b: __m512h, m: M) -> __m512h {
    _mm512_mask_blend_ph(m, a, b)
}
/// `sign(x) ? b : a` per lane.
#[inline]
#[target_feature(enable = "avx512fp16,avx512bw,avx512f")]
pub fn blend_sign(a: __m512h, b: __m512h, x: __m512h) -> __m512h {
    _mm512_mask_blend_ph(_mm512_movepi16_mask(_mm512_castph_si512(x)), a, b)
}
/// The bits of `a` and `b` combined by a 512-bit logic instruction.
macro_rules! bits_op {
    ($op:ident, $a:expr, $b:expr) => {
        _mm512_castsi512_ph($op(_mm512_castph_si512($a), $b))
    };
}
/// The sign bits of x (everything else cleared).
#[inline]
#[target_feature(enable = "avx512fp16,avx512bw,avx512f")]
pub fn sign(x: __m512h) -> __m512h {
    bits_op!(_mm512_and_si512, x, _mm512_set1_epi16(i16::MIN))
}
/// |x| by clearing the sign bit.
#[inline]
#[target_feature(enable = "avx512fp16,avx512bw,avx512f")]
pub fn abs(x: __m512h) -> __m512h {
    bits_op!(_mm512_and_si512, x, _mm512_set1_epi16(i16::MAX))
}
/// a ⊕ b, bitwise.
#[inline]
#[target_feature(enable = "avx512fp16,avx512bw,avx512f")]
pub fn xor(a: __m512h, b: __m512h) -> __m512h {
    bits_op!(_mm512_xor_si512, a, _mm512_castph_si512(b))
}
/// Either mask.
#[inline]
#[target_feature(enable = "avx512fp16,avx512bw,avx512f")]
pub fn or_m(a: M, b: M) -> M {
    a | b
}
/// The mask's complement.
#[inline]
#[target_feature(enable = "avx512fp16,avx512bw,avx512f")]
pub fn not_m(a: M) -> M {
    !a
}
/// `sel ? b : a` per lane, on masks.
#[inline]
#[target_feature(enable = "avx512fp16,avx512bw,avx512f")]
pub fn blend_m(a: M, b: M, sel: M) -> M {
    (a & !sel) | (b & sel)
}
/// Lanes whose sign bit is set.
#[inline]
#[target_feature(enable = "avx512fp16,avx512bw,avx512f")]
pub fn sign_m(x: __m512h) -> M {
    _mm512_movepi16_mask(_mm512_castph_si512(x))
}
/// Writes the mask's lanes as bools 0 / 1 to `p[i..i + 32]`.
///
/// # Safety
/// `p[i..i + 32]` must be in bounds.
#[inline]
#[target_feature(enable = "avx512fp16,avx512bw,avx512f")]
pub unsafe fn flags(p: *mut bool, i: usize, m: M) {
    for k in 0..4 {
        // SAFETY: in bounds (the caller); every byte written is 0 or 1, a valid bool.
        unsafe { (p.add(i + 8 * k) as *mut u64).write_unaligned(super::SPREAD[(m >> (8 * k) & 0xff) as usize]) };
    }
}
/// # Safety
/// `p[i..i + 32]` must be in bounds.
#[inline]
#[target_feature(enable = "avx512fp16,avx512bw,avx512f")]
pub unsafe fn load16(p: *const f16, i: usize) -> __m512h {
    unsafe { _mm512_castsi512_ph(_mm512_loadu_si512(p.add(i) as *const __m512i)) }
}
/// # Safety
/// `p[i..i + 32]` must be in bounds.
#[inline]
#[target_feature(enable = "avx512fp16,avx512bw,avx512f")]
pub unsafe fn store16(p: *mut f16, i: usize, x: __m512h) {
    unsafe { _mm512_storeu_si512(p.add(i) as *mut __m512i, _mm512_castph_si512(x)) }
}
/// The lanes are binary16 already: nothing to round.
#[inline]
#[target_feature(enable = "avx512fp16,avx512bw,avx512f")]
pub fn round16(x: __m512h) -> __m512h {
    x
}
/// The next binary16 encoding above each lane, as [`super::v8::next_up16`].
#[inline]
#[target_feature(enable = "avx512fp16,avx512bw,avx512f")]
pub fn next_up16(v: __m512h) -> __m512h {
    _mm512_castsi512_ph(super::step_up16x32(_mm512_castph_si512(v)))
}
