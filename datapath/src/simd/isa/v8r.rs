//! AVX2 with binary16 kept in binary32 lanes and rounded there (no F16C round trip per
//! operation): [`super::v8`] with its `round16` replaced by [`round16_lanes`]. The issue that
//! asked for it expected the round trip (`vcvtps2ph` then `vcvtph2ps`, two conversions per
//! operation) to be the binary16 kernel's cost on AVX2; `raypipe speed` measures both kernels
//! side by side (docs/speed.md), and the dispatch keeps the faster one.

pub use super::v8::*;
use std::arch::x86_64::*;

/// Rounds binary32 lanes to binary16 (nearest-even), held in binary32, as [`round16_lanes`].
#[inline]
#[target_feature(enable = "avx2")]
pub fn round16(x: __m256) -> __m256 {
    round16_lanes(x)
}

/// [`super::v8::round16`] without leaving binary32: |x| + c − c with c = 2^(e + 13), e = x's
/// exponent clamped to [−14, 16], is |x| rounded to a multiple of c's binary32 ulp 2^(e − 10)
/// — the binary16 ulp at x's exponent (the subnormal grid 2^−24 below 2^−14) — nearest-even,
/// in one add and one subtract; 65520 and above (they round to 2^16) become +inf; the sign is
/// put back. NaN stays NaN (quiet; the kernels canonicalise NaN where values leave them).
/// Above 2^16 the clamp keeps c finite (c = +inf would make inf + c − c a NaN).
#[inline]
#[target_feature(enable = "avx2")]
pub fn round16_lanes(x: __m256) -> __m256 {
    let b = _mm256_castps_si256(x);
    let sign = _mm256_and_ps(x, splat_bits(0x8000_0000));
    let a = _mm256_and_ps(x, splat_bits(0x7fff_ffff));
    let e = _mm256_min_epi32(
        _mm256_max_epi32(_mm256_and_si256(b, _mm256_set1_epi32(0x7f80_0000)), _mm256_set1_epi32(0x3880_0000)),
        _mm256_set1_epi32(0x4780_0000),
    );
    let c = _mm256_castsi256_ps(_mm256_add_epi32(e, _mm256_set1_epi32(13 << 23)));
    let r = _mm256_sub_ps(_mm256_add_ps(a, c), c);
    let r = _mm256_blendv_ps(r, splat(f32::INFINITY), _mm256_cmp_ps::<_CMP_GE_OQ>(r, splat(65536.0)));
    _mm256_or_ps(r, sign)
}
