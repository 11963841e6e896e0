//! Widening a binary32 or bfloat16 column to binary64: `dst[k] = src[k] as f64` (bfloat16:
//! its encoding shifted into binary32's upper half first), exact for every value (a NaN stays
//! a NaN, as Rust's cast leaves it: the same as the one-value cast), on the widest lanes the
//! machine has (AVX-512F: 8, AVX2: 4, else the compiler's baseline).

use super::{f64_lanes, F64Lanes, Kernel};

/// `dst[k] = src[k] as f64` for every `k`, on the widest lanes `cap`, the thread's cap and
/// the machine allow (the same bits on every one).
///
/// # Panics
/// If the lengths differ.
pub fn f32_to_f64(cap: Kernel, src: &[f32], dst: &mut [f64]) {
    widen_column(cap, src, dst)
}

/// `dst[k] = f32::from_bits((src[k] as u32) << 16) as f64` for every `k` (bfloat16
/// encodings), on the widest lanes `cap`, the thread's cap and the machine allow.
///
/// # Panics
/// If the lengths differ.
pub fn bf16_to_f64(cap: Kernel, src: &[u16], dst: &mut [f64]) {
    widen_column(cap, src, dst)
}

/// Either column on the binary64 lanes [`f64_lanes`] picks.
fn widen_column<T: Widen>(cap: Kernel, src: &[T], dst: &mut [f64]) {
    assert_eq!(src.len(), dst.len(), "widen: columns of different lengths");
    match f64_lanes(cap) {
        // SAFETY: AVX-512F is present (f64_lanes detected it)
        #[cfg(target_arch = "x86_64")]
        F64Lanes::Avx512 => unsafe { avx512(src, dst) },
        // SAFETY: AVX2 is present (f64_lanes detected it)
        #[cfg(target_arch = "x86_64")]
        F64Lanes::Avx2 => unsafe { avx2(src, dst) },
        _ => body(src, dst),
    }
}

/// A value widened to binary64 exactly.
trait Widen: Copy {
    fn widen(self) -> f64;
}

impl Widen for f32 {
    #[inline(always)]
    fn widen(self) -> f64 {
        self as f64
    }
}

impl Widen for u16 {
    /// A bfloat16 encoding: binary32's upper half.
    #[inline(always)]
    fn widen(self) -> f64 {
        f32::from_bits(u32::from(self) << 16) as f64
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn avx512<T: Widen>(src: &[T], dst: &mut [f64]) {
    body(src, dst)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn avx2<T: Widen>(src: &[T], dst: &mut [f64]) {
    body(src, dst)
}

#[inline(always)]
fn body<T: Widen>(src: &[T], dst: &mut [f64]) {
    for (d, &x) in dst.iter_mut().zip(src) {
        *d = x.widen();
    }
}
