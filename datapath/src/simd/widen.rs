//! Widening a binary32 column to binary64: `dst[k] = src[k] as f64`, exact for every value
//! (a NaN stays a NaN, as Rust's cast leaves it: the same as the one-value cast), on the
//! widest lanes the machine has (AVX-512F: 8, AVX2: 4, else the compiler's baseline).

use super::select::best_kernel;
use super::Kernel;

/// `dst[k] = src[k] as f64` for every `k`, on the widest lanes `cap`, the thread's cap and
/// the machine allow (the same bits on every one).
///
/// # Panics
/// If the lengths differ.
pub fn f32_to_f64(cap: Kernel, src: &[f32], dst: &mut [f64]) {
    assert_eq!(src.len(), dst.len(), "f32_to_f64: columns of different lengths");
    let k = best_kernel(true, cap);
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::is_x86_feature_detected as has;
        if k >= Kernel::Avx512 && has!("avx512f") {
            // SAFETY: AVX-512F is present (checked above)
            return unsafe { avx512(src, dst) };
        }
        if k >= Kernel::Avx2 && has!("avx2") {
            // SAFETY: AVX2 is present (checked above)
            return unsafe { avx2(src, dst) };
        }
    }
    let _ = k;
    body(src, dst)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn avx512(src: &[f32], dst: &mut [f64]) {
    body(src, dst)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn avx2(src: &[f32], dst: &mut [f64]) {
    body(src, dst)
}

#[inline(always)]
fn body(src: &[f32], dst: &mut [f64]) {
    for (d, &x) in dst.iter_mut().zip(src) {
        *d = x as f64;
    }
}
