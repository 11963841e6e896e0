//! Random draws in lanes: a run of [`SplitMix64::below`] draws written to a column at once,
//! the same numbers in the same order as drawing them one by one. SplitMix64's state moves by
//! a constant per draw, so draw k is `mix(state + k · GAMMA)` whatever came before it, and
//! the lanes are independent (AVX-512F + DQ: 8 lanes, AVX2: 4, else the compiler's baseline).

use super::{f64_lanes, F64Lanes, Kernel};
use crate::rng::{mix, SplitMix64, GAMMA};

/// `out[k] = r.below(n)` for k = 0, 1, … in turn (and `r` moved on as those draws move it),
/// on the widest lanes `cap`, the thread's cap and the machine allow.
///
/// # Panics
/// If `n` is 0 or above `u32::MAX` (the draws are `u32` indices).
pub fn below_column(cap: Kernel, r: &mut SplitMix64, n: u64, out: &mut [u32]) {
    assert!(n > 0 && n <= u64::from(u32::MAX), "below_column: n = {n} is not in 1..=u32::MAX");
    let s = r.state();
    match f64_lanes(cap) {
        // SAFETY: AVX-512F and DQ are present (f64_lanes detected F, DQ checked here)
        #[cfg(target_arch = "x86_64")]
        F64Lanes::Avx512 if std::arch::is_x86_feature_detected!("avx512dq") => unsafe { avx512(s, n, out) },
        // SAFETY: AVX2 is present (f64_lanes detected it, or checked here under AVX-512F)
        #[cfg(target_arch = "x86_64")]
        F64Lanes::Avx2 => unsafe { avx2(s, n, out) },
        // SAFETY: as above
        #[cfg(target_arch = "x86_64")]
        F64Lanes::Avx512 if std::arch::is_x86_feature_detected!("avx2") => unsafe { avx2(s, n, out) },
        _ => body(s, n, out),
    }
    r.skip(out.len() as u64);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512dq")]
fn avx512(s: u64, n: u64, out: &mut [u32]) {
    body(s, n, out)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn avx2(s: u64, n: u64, out: &mut [u32]) {
    body(s, n, out)
}

/// Draw k + 1 from state `s` into `out[k]`: ⌊x · n / 2^64⌋ of x = `mix(s + (k + 1) · GAMMA)`,
/// taken in 32-bit halves (n < 2^32): ⌊(x_hi · n + ⌊x_lo · n / 2^32⌋) / 2^32⌋, which is the
/// same integer (the dropped fraction is below 1) and never overflows 64 bits.
#[inline(always)]
fn body(s: u64, n: u64, out: &mut [u32]) {
    // the state before draw k + 1, s + (k + 1) · GAMMA, as a running sum (an induction the
    // compiler keeps in lanes; no 64-bit multiply per draw)
    let mut z = s;
    for o in out.iter_mut() {
        z = z.wrapping_add(GAMMA);
        let x = mix(z);
        let (hi, lo) = (x >> 32, x & 0xffff_ffff);
        *o = ((hi * n + ((lo * n) >> 32)) >> 32) as u32;
    }
}
