//! AVX-512F, 8 binary64 lanes holding a narrow format's values exactly; masks as `__mmask8`.

use crate::format::narrow::Narrow;
use std::arch::x86_64::*;
/// Lanes per vector.
pub const LANES: usize = 8;
/// A mask.
pub type M = __mmask8;
table_ops!("avx512f", __m512d, M, "binary64";
    add = _mm512_add_pd, sub = _mm512_sub_pd, mul = _mm512_mul_pd, div = _mm512_div_pd,
    max = _mm512_max_pd, min = _mm512_min_pd, cmp = _mm512_cmp_pd_mask);
/// Every lane x.
#[inline]
#[target_feature(enable = "avx512f")]
pub fn splat(x: f64) -> __m512d {
    _mm512_set1_pd(x)
}
/// Every lane the integer x.
#[inline]
#[target_feature(enable = "avx512f")]
fn int(x: u64) -> __m512i {
    _mm512_set1_epi64(x as i64)
}
/// A shift count for the `sll` / `srl` forms.
#[inline]
#[target_feature(enable = "avx512f")]
fn count(n: u32) -> __m128i {
    _mm_cvtsi64_si128(n as i64)
}
/// The lanes as integers.
#[inline]
#[target_feature(enable = "avx512f")]
fn ib(x: __m512d) -> __m512i {
    _mm512_castpd_si512(x)
}
/// The integers as lanes.
#[inline]
#[target_feature(enable = "avx512f")]
fn fb(x: __m512i) -> __m512d {
    _mm512_castsi512_pd(x)
}
/// Every lane binary64's canonical NaN (stored as the format's canonical NaN).
#[inline]
#[target_feature(enable = "avx512f")]
pub fn canonical_nan() -> __m512d {
    fb(int(0x7ff8_0000_0000_0000))
}
/// Both masks.
#[inline]
#[target_feature(enable = "avx512f")]
pub fn and_m(a: M, b: M) -> M {
    a & b
}
/// Either mask.
#[inline]
#[target_feature(enable = "avx512f")]
pub fn or_m(a: M, b: M) -> M {
    a | b
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
pub fn blend(a: __m512d, b: __m512d, m: M) -> __m512d {
    _mm512_mask_blend_pd(m, a, b)
}
/// `sign(x) ? b : a` per lane.
#[inline]
#[target_feature(enable = "avx512f")]
pub fn blend_sign(a: __m512d, b: __m512d, x: __m512d) -> __m512d {
    _mm512_mask_blend_pd(sign_m(x), a, b)
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
pub fn sign_m(x: __m512d) -> M {
    _mm512_test_epi64_mask(ib(x), int(1 << 63))
}
/// The sign bits of x (everything else cleared).
#[inline]
#[target_feature(enable = "avx512f")]
pub fn sign(x: __m512d) -> __m512d {
    fb(_mm512_and_si512(ib(x), int(1 << 63)))
}
/// |x| by clearing the sign bit.
#[inline]
#[target_feature(enable = "avx512f")]
pub fn abs(x: __m512d) -> __m512d {
    fb(_mm512_and_si512(ib(x), int(!(1 << 63))))
}
/// a ⊕ b, bitwise.
#[inline]
#[target_feature(enable = "avx512f")]
pub fn xor(a: __m512d, b: __m512d) -> __m512d {
    fb(_mm512_xor_si512(ib(a), ib(b)))
}
/// Writes the mask's lanes as bools 0 / 1 to `p[i..i + 8]`.
///
/// # Safety
/// `p[i..i + 8]` must be in bounds.
#[inline]
#[target_feature(enable = "avx512f")]
pub unsafe fn flags(p: *mut bool, i: usize, m: M) {
    // SAFETY: in bounds (the caller); every byte written is 0 or 1, a valid bool.
    unsafe { (p.add(i) as *mut u64).write_unaligned(super::SPREAD[m as usize]) }
}
/// The binary64 just below each lane of a magnitude `a` (a NaN for +0).
#[inline]
#[target_feature(enable = "avx512f")]
fn pred(a: __m512d) -> __m512d {
    fb(_mm512_sub_epi64(ib(a), int(1)))
}
/// [`super::v4d::exponent`] on 8 lanes.
#[inline]
#[target_feature(enable = "avx512f")]
fn exponent(x: __m512d) -> __m512d {
    fb(_mm512_and_si512(ib(x), int(0x7ff0_0000_0000_0000)))
}
/// [`super::v4d::fast_ok`] on 8 lanes, in three AVX-512 operations a value: the largest
/// magnitude by `vrangepd` (max-abs, sign cleared), and the smallest nonzero magnitude
/// by `vfixupimmpd` (±0 becomes +∞, a NaN becomes +0, every other class stays itself)
/// and `vrangepd` (min-abs, sign cleared), each over a balanced tree of the twelve.
/// `vrangepd` returns the other operand when one is a quiet NaN (as `maxNum` does), so
/// the NaN is caught by the lower limit: it reads as +0 there, below `fast_lo` (> 0);
/// an infinity fails the upper limit.
#[inline]
#[target_feature(enable = "avx512f,avx512dq")]
pub fn fast_ok(v: &[__m512d; 12], n: &Narrow) -> bool {
    // vfixupimmpd's table: a 4-bit response per input class, class j in bits 4j..4j+3
    // (QNaN, SNaN, ±0, +1, −∞, +∞, negative, positive); 1 = the input itself, 5 = +∞,
    // 8 = +0
    let table = int(0x1111_1588);
    let nz = |x: __m512d| _mm512_fixupimm_pd::<0>(x, x, table);
    // imm bits 1:0 = 11 max-abs / 10 min-abs; bits 3:2 = 10 sign cleared
    let hi = |a, b| _mm512_range_pd::<0b1011>(a, b);
    let lo = |a, b| _mm512_range_pd::<0b1010>(a, b);
    let z: [__m512d; 12] = std::array::from_fn(|k| nz(v[k]));
    let h = |k: usize| hi(hi(v[k], v[k + 1]), hi(v[k + 2], v[k + 3]));
    let l = |k: usize| lo(lo(z[k], z[k + 1]), lo(z[k + 2], z[k + 3]));
    let (h, l) = (hi(hi(h(0), h(4)), h(8)), lo(lo(l(0), l(4)), l(8)));
    let ok =
        _mm512_cmp_pd_mask::<_CMP_LE_OQ>(h, splat(n.fast_hi)) & _mm512_cmp_pd_mask::<_CMP_GE_OQ>(l, splat(n.fast_lo));
    ok == u8::MAX
}
/// Whether a lane of magnitudes `a` lies outside [2^emin, max + ulp(max)/2) (±0 and a NaN
/// included: they take [`round_full`]'s full road, which keeps them): one unsigned compare
/// of a's encoding minus 2^emin's (order kept for magnitudes; ±0 and a < 2^emin wrap to
/// the top) against the width of the range.
#[inline]
#[target_feature(enable = "avx512f")]
fn any_outside_normal(a: __m512d, n: &Narrow) -> bool {
    outside_normal(a, n) != 0
}
/// The lanes [`any_outside_normal`] finds.
#[inline]
#[target_feature(enable = "avx512f")]
fn outside_normal(a: __m512d, n: &Narrow) -> M {
    let (lo, hi) = (n.min_normal.to_bits(), n.overflow_at.to_bits());
    _mm512_cmpge_epu64_mask(_mm512_sub_epi64(ib(a), int(lo)), int(hi - lo))
}
/// [`next_up_soft`] when every lane's magnitude is strictly between 2^emin and the format's
/// largest (else `None`): there a format value's binary64 encoding has its fraction in the top
/// M of 52 bits, and the next value up is the encoding plus 2^(52 − M) (a positive lane) or
/// minus it (a negative one, toward zero) — a carry or borrow into the exponent lands on the
/// next binade's first or the binade below's last value, both normal.
#[inline]
#[target_feature(enable = "avx512f")]
fn step_inside(x: __m512d, n: &Narrow) -> Option<__m512d> {
    let b = ib(x);
    let a = _mm512_and_si512(b, int(0x7fff_ffff_ffff_ffff));
    let (lo, hi) = (n.min_normal.to_bits() + 1, n.max_finite.to_bits());
    if _mm512_cmpge_epu64_mask(_mm512_sub_epi64(a, int(lo)), int(hi - lo)) != 0 {
        return None;
    }
    let one = _mm512_or_si512(_mm512_srai_epi64::<63>(b), int(1));
    Some(fb(_mm512_add_epi64(b, _mm512_sll_epi64(one, count(52 - n.lay.man_bits)))))
}
narrow_ops!("avx512f", "avx512f", __m512d, _mm512_fmadd_pd, _mm512_fmsub_pd);
/// Loads 8 `eEmM` encodings as binary64 (exact).
///
/// # Safety
/// `p[i..i + 8]` must be in bounds.
#[inline]
#[target_feature(enable = "avx512f")]
pub unsafe fn load_soft(p: *const u64, i: usize, n: &Narrow) -> __m512d {
    let (l, m) = (n.lay, n.lay.man_bits);
    let b = unsafe { _mm512_loadu_si512(p.add(i) as *const __m512i) };
    if n.e8 {
        return unsafe { load_e8(p, i, n) };
    }
    let emax = (1u64 << l.exp_bits) - 1;
    let e = _mm512_and_si512(_mm512_srl_epi64(b, count(m)), int(emax));
    let f = _mm512_and_si512(b, int((1u64 << m) - 1));
    let s = _mm512_slli_epi64::<63>(_mm512_srl_epi64(b, count(l.width() - 1)));
    let frac = _mm512_sll_epi64(f, count(52 - m));
    let bexp = _mm512_sll_epi64(_mm512_add_epi64(e, int((1023 - l.bias()) as u64)), count(52));
    let normal = fb(_mm512_or_si512(_mm512_or_si512(s, bexp), frac));
    let special = fb(_mm512_or_si512(_mm512_or_si512(s, int(0x7ff0_0000_0000_0000)), frac));
    // a subnormal: fraction × 2^(emin − M), the fraction converted exactly via 2^52
    let two52 = splat(4503599627370496.0);
    let fv = _mm512_sub_pd(fb(_mm512_or_si512(f, int(0x4330_0000_0000_0000))), two52);
    let sub = fb(_mm512_or_si512(ib(_mm512_mul_pd(fv, splat(n.step))), s));
    let r = blend(normal, sub, _mm512_cmpeq_epi64_mask(e, int(0)));
    blend(r, special, _mm512_cmpeq_epi64_mask(e, int(emax)))
}
/// [`load_soft`] for `e8mM` with M ≤ 23 (`n.e8`): binary32's exponent, so the
/// encoding shifted to binary32's fraction width is the same value in binary32
/// (subnormals, infinities and NaNs included), widened exactly to binary64.
///
/// # Safety
/// `p[i..i + 8]` must be in bounds.
#[inline]
#[target_feature(enable = "avx512f")]
pub unsafe fn load_e8(p: *const u64, i: usize, n: &Narrow) -> __m512d {
    // the low halves of the 8 lanes to the low 256 bits (the encodings fit 32 bits):
    // one `vpermd` from memory, written out because LLVM turns the permute intrinsic
    // into a `vpmovqd` (two shuffle uops and a separate load)
    let idx = _mm512_setr_epi32(0, 2, 4, 6, 8, 10, 12, 14, 0, 0, 0, 0, 0, 0, 0, 0);
    let low: __m512i;
    // SAFETY: `p[i..i + 8]` is in bounds (the caller): the 64 bytes read; the asm
    // writes only its output register.
    unsafe {
        std::arch::asm!(
            "vpermd {o}, {x}, zmmword ptr [{p}]",
            o = lateout(zmm_reg) low,
            x = in(zmm_reg) idx,
            p = in(reg) p.add(i),
            options(pure, readonly, nostack, preserves_flags)
        );
    }
    let low = _mm512_castsi512_si256(low);
    _mm512_cvtps_pd(_mm256_castsi256_ps(_mm256_sll_epi32(low, count(n.e8_shift))))
}
/// [`store_soft`] for `e8mM` with M ≤ 23 (`n.e8`): the lanes hold target values, which
/// binary32 holds exactly, so narrowing is exact and the binary32 encoding shifted
/// right is the target's. A NaN lane must be binary64's canonical NaN, which narrows
/// to binary32's, whose shift is the target's canonical NaN.
///
/// # Safety
/// `p[i..i + 8]` must be in bounds.
#[inline]
#[target_feature(enable = "avx512f")]
pub unsafe fn store_e8(p: *mut u64, i: usize, x: __m512d, n: &Narrow) {
    let b32 = _mm256_srl_epi32(_mm256_castps_si256(_mm512_cvtpd_ps(x)), count(n.e8_shift));
    unsafe { _mm512_storeu_si512(p.add(i) as *mut __m512i, _mm512_cvtepu32_epi64(b32)) }
}
/// Stores 8 lanes holding `eEmM` values (or a NaN, stored as the canonical NaN) as
/// encodings.
///
/// # Safety
/// `p[i..i + 8]` must be in bounds.
#[inline]
#[target_feature(enable = "avx512f")]
pub unsafe fn store_soft(p: *mut u64, i: usize, x: __m512d, n: &Narrow) {
    let (l, m) = (n.lay, n.lay.man_bits);
    if n.e8 {
        return unsafe { store_e8(p, i, blend(x, canonical_nan(), unord(x, x)), n) };
    }
    let b = ib(x);
    let s = _mm512_sll_epi64(_mm512_srli_epi64::<63>(b), count(l.width() - 1));
    let a = abs(x);
    let bexp = _mm512_srli_epi64::<52>(ib(a));
    let e = _mm512_sub_epi64(bexp, int((1023 - l.bias()) as u64));
    let frac = _mm512_srl_epi64(_mm512_and_si512(b, int((1u64 << 52) - 1)), count(52 - m));
    let normal = fb(_mm512_or_si512(s, _mm512_or_si512(_mm512_sll_epi64(e, count(m)), frac)));
    // a subnormal: |x| / 2^(emin − M) is an integer < 2^52, read off 2^52 + it
    let two52 = splat(4503599627370496.0);
    let q = ib(_mm512_add_pd(_mm512_mul_pd(a, splat(n.inv_step)), two52));
    let sub = fb(_mm512_or_si512(s, _mm512_and_si512(q, int((1u64 << 52) - 1))));
    let inf = fb(_mm512_or_si512(s, int(l.exp_mask())));
    let r = blend(normal, sub, lt(a, splat(n.min_normal)));
    let r = blend(r, inf, _mm512_cmp_pd_mask::<_CMP_EQ_OQ>(a, splat(f64::INFINITY)));
    let r = blend(r, fb(int(l.canonical_nan())), unord(x, x));
    unsafe { _mm512_storeu_si512(p.add(i) as *mut __m512i, ib(r)) }
}
/// `k` steps of [`next_up_soft`] at once (lanes holding `eEmM` values): for `e8mM`
/// (`n.e8`) with k·2^(23 − M) at most 2^24, on binary32 — which holds every `e8mM` value,
/// its grid being binary32's every 2^(23 − M)-th encoding, subnormals included — by
/// [`super::v8::next_up_by_n`] (NaN lanes kept as they are); else k single steps.
#[inline]
#[target_feature(enable = "avx512f,avx2")]
pub fn next_up_soft_n(x: __m512d, k: u32, n: &Narrow) -> __m512d {
    if n.e8 && k <= 64 && (k << n.e8_shift) <= 1 << 24 {
        // exact both ways: the lanes are binary32 values
        let r = super::v8::next_up_by_n(_mm512_cvtpd_ps(x), (k << n.e8_shift) as i32);
        blend(_mm512_cvtps_pd(r), x, _mm512_cmp_pd_mask::<_CMP_UNORD_Q>(x, x))
    } else {
        (0..k).fold(x, |v, _| next_up_soft(v, n))
    }
}
