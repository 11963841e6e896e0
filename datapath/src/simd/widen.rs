//! Widening a column to binary64 — binary32 (`dst[k] = src[k] as f64`), bfloat16 and `e8mM`
//! (the encoding shifted into binary32's fields first), binary16, fixed point (the value times
//! its step) — the same bits as the one-value conversion, on the widest lanes the machine has
//! (AVX-512F: 8, AVX2: 4, else the compiler's baseline).

use super::{f64_lanes, F64Lanes, Kernel};

/// `dst[k] = src[k] as f64` for every `k`, on the widest lanes `cap`, the thread's cap and
/// the machine allow (the same bits on every one).
///
/// # Panics
/// If the lengths differ.
pub fn f32_to_f64(cap: Kernel, src: &[f32], dst: &mut [f64]) {
    widen_column(cap, src, (), dst)
}

/// `dst[k] = f32::from_bits((src[k] as u32) << 16) as f64` for every `k` (bfloat16
/// encodings), on the widest lanes `cap`, the thread's cap and the machine allow.
///
/// # Panics
/// If the lengths differ.
pub fn bf16_to_f64(cap: Kernel, src: &[u16], dst: &mut [f64]) {
    widen_column(cap, src, (), dst)
}

/// `dst[k] = src[k].to_f64()` for every `k` (binary16, exact; a NaN stays a NaN), by the
/// hardware conversions where `cap`, the thread's cap and the machine allow (AVX-512F's
/// `vcvtph2ps`, or F16C's on AVX2, then `vcvtps2pd`), else `half`'s slice conversion.
///
/// # Panics
/// If the lengths differ.
pub fn f16_to_f64(cap: Kernel, src: &[half::f16], dst: &mut [f64]) {
    use half::slice::HalfFloatSliceExt;
    assert_eq!(src.len(), dst.len(), "widen: columns of different lengths");
    let done = match f64_lanes(cap) {
        // SAFETY: AVX-512F is present (f64_lanes detected it)
        #[cfg(target_arch = "x86_64")]
        F64Lanes::Avx512 => unsafe { f16_avx512(src, dst) },
        // SAFETY: AVX2 is present (f64_lanes detected it) and F16C (checked)
        #[cfg(target_arch = "x86_64")]
        F64Lanes::Avx2 if std::arch::is_x86_feature_detected!("f16c") => unsafe { f16_avx2(src, dst) },
        _ => 0,
    };
    src[done..].convert_to_f64_slice(&mut dst[done..]);
}

/// The whole 16-value steps of [`f16_to_f64`] on AVX-512F; returns the values done.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn f16_avx512(src: &[half::f16], dst: &mut [f64]) -> usize {
    use std::arch::x86_64::*;
    let whole = src.len() - src.len() % 16;
    let mut i = 0;
    while i < whole {
        // SAFETY: i + 16 <= both lengths (equal); f16 is 16 bits of plain data
        unsafe {
            let h = _mm256_loadu_si256(src.as_ptr().add(i).cast());
            let f = _mm512_cvtph_ps(h);
            let lo = _mm512_cvtps_pd(_mm512_castps512_ps256(f));
            let hi = _mm512_cvtps_pd(_mm256_castpd_ps(_mm512_extractf64x4_pd::<1>(_mm512_castps_pd(f))));
            _mm512_storeu_pd(dst.as_mut_ptr().add(i), lo);
            _mm512_storeu_pd(dst.as_mut_ptr().add(i + 8), hi);
        }
        i += 16;
    }
    whole
}

/// The whole 8-value steps of [`f16_to_f64`] on AVX2 with F16C; returns the values done.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,f16c")]
fn f16_avx2(src: &[half::f16], dst: &mut [f64]) -> usize {
    use std::arch::x86_64::*;
    let whole = src.len() - src.len() % 8;
    let mut i = 0;
    while i < whole {
        // SAFETY: i + 8 <= both lengths (equal); f16 is 16 bits of plain data
        unsafe {
            let f = _mm256_cvtph_ps(_mm_loadu_si128(src.as_ptr().add(i).cast()));
            _mm256_storeu_pd(dst.as_mut_ptr().add(i), _mm256_cvtps_pd(_mm256_castps256_ps128(f)));
            _mm256_storeu_pd(dst.as_mut_ptr().add(i + 4), _mm256_cvtps_pd(_mm256_extractf128_ps::<1>(f)));
        }
        i += 8;
    }
    whole
}

/// `dst[k] = f32::from_bits((src[k] as u32) << shift) as f64` for every `k` (`e8mM`
/// encodings, `shift` = 23 − M: binary32's exponent, so the shifted encoding is the same value
/// in binary32, subnormals, infinities included; a NaN becomes `f64::NAN`, as the format's
/// `to_f64` gives it), on the widest lanes `cap`, the thread's cap and the machine allow.
///
/// # Panics
/// If the lengths differ.
pub fn e8_to_f64(cap: Kernel, src: &[u64], shift: u32, dst: &mut [f64]) {
    assert!(shift <= 23, "e8mM: a shift of {shift} bits");
    widen_column(cap, src, shift, dst)
}

/// Whether [`fixed_to_f64`] runs in vector lanes here for the values of a `width`-bit
/// fixed-point format: with AVX-512F and AVX-512DQ (`vcvtqq2pd`) at any width, or on any
/// binary64 lanes (AVX-512F, AVX2; within `cap` and the thread's cap) at widths up to 52, whose
/// values lie within ±2^51.
pub fn fixed_in_lanes(cap: Kernel, width: u32) -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        let lanes = f64_lanes(cap);
        (lanes == F64Lanes::Avx512 && std::arch::is_x86_feature_detected!("avx512dq"))
            || (width <= 52 && lanes != F64Lanes::Baseline)
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        let _ = (cap, width);
        false
    }
}

/// `dst[k] = src[k] as f64 * scale` for every `k` (a fixed-point column, `scale` its step
/// 2^−F): the same two roundings as the one-value code. In AVX-512DQ lanes (`vcvtqq2pd`,
/// `vmulpd`) where the machine has them; else, when every value of the column lies in
/// [−2^51, 2^51) (checked first), on the binary64 lanes [`f64_lanes`] picks by the exact
/// integer-to-binary64 conversion of that range ([`Narrow`]: `x + 1.5·2^52` formed in the
/// integer bits, then `− 1.5·2^52`, both exact), then the same `× scale`; else value by value.
///
/// # Panics
/// If the lengths differ.
pub fn fixed_to_f64(cap: Kernel, src: &[i64], scale: f64, dst: &mut [f64]) {
    assert_eq!(src.len(), dst.len(), "widen: columns of different lengths");
    let done = match f64_lanes(cap) {
        // SAFETY: AVX-512F is present (f64_lanes detected it), AVX-512DQ too (detected)
        #[cfg(target_arch = "x86_64")]
        F64Lanes::Avx512 if std::arch::is_x86_feature_detected!("avx512dq") => {
            unsafe { avx512dq(src, scale, dst) };
            true
        }
        // SAFETY: AVX-512F is present (f64_lanes detected it)
        #[cfg(target_arch = "x86_64")]
        F64Lanes::Avx512 => unsafe { narrow_avx512(src, scale, dst) },
        // SAFETY: AVX2 is present (f64_lanes detected it)
        #[cfg(target_arch = "x86_64")]
        F64Lanes::Avx2 => unsafe { narrow_avx2(src, scale, dst) },
        _ => false,
    };
    if !done {
        body(src, scale, dst)
    }
}

/// Every value of `src` lies in [−2^51, 2^51) (a loop the compiler vectorises).
#[inline(always)]
fn narrow(src: &[i64]) -> bool {
    src.iter().fold(0u64, |a, &x| a | ((x as u64).wrapping_add(1 << 51) >> 52)) == 0
}

/// The column through [`Narrow`] when every value is within its range (checked first, in the
/// same lanes); false, `dst` untouched, otherwise.
#[inline(always)]
fn narrow_body(src: &[i64], scale: f64, dst: &mut [f64]) -> bool {
    if !narrow(src) {
        return false;
    }
    // SAFETY: Narrow is a transparent i64; every value is in [-2^51, 2^51) (checked)
    let src = unsafe { std::slice::from_raw_parts(src.as_ptr().cast::<Narrow>(), src.len()) };
    body(src, scale, dst);
    true
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn narrow_avx512(src: &[i64], scale: f64, dst: &mut [f64]) -> bool {
    narrow_body(src, scale, dst)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn narrow_avx2(src: &[i64], scale: f64, dst: &mut [f64]) -> bool {
    narrow_body(src, scale, dst)
}

/// A fixed-point value in [−2^51, 2^51), which converts to binary64 exactly without
/// AVX-512DQ's `vcvtqq2pd`.
#[derive(Clone, Copy)]
#[repr(transparent)]
struct Narrow(i64);

/// Any column on the binary64 lanes [`f64_lanes`] picks; `p` the type's parameter. (Only a
/// fixed-point column needs AVX-512DQ: [`fixed_to_f64`] dispatches its own.)
fn widen_column<T: Widen>(cap: Kernel, src: &[T], p: T::P, dst: &mut [f64]) {
    assert_eq!(src.len(), dst.len(), "widen: columns of different lengths");
    match f64_lanes(cap) {
        // SAFETY: AVX-512F is present (f64_lanes detected it)
        #[cfg(target_arch = "x86_64")]
        F64Lanes::Avx512 => unsafe { avx512(src, p, dst) },
        // SAFETY: AVX2 is present (f64_lanes detected it)
        #[cfg(target_arch = "x86_64")]
        F64Lanes::Avx2 => unsafe { avx2(src, p, dst) },
        _ => body(src, p, dst),
    }
}

/// A value widened to binary64, with its type's parameter `P`.
trait Widen: Copy {
    type P: Copy;
    fn widen(self, p: Self::P) -> f64;
}

impl Widen for f32 {
    type P = ();
    #[inline(always)]
    fn widen(self, _: ()) -> f64 {
        self as f64
    }
}

impl Widen for u16 {
    type P = ();
    /// A bfloat16 encoding: binary32's upper half.
    #[inline(always)]
    fn widen(self, _: ()) -> f64 {
        f32::from_bits(u32::from(self) << 16) as f64
    }
}

impl Widen for u64 {
    type P = u32;
    /// An `e8mM` encoding shifted by 23 − M into binary32's fields (a NaN as `f64::NAN`).
    #[inline(always)]
    fn widen(self, shift: u32) -> f64 {
        let y = f32::from_bits((self as u32) << shift) as f64;
        if y.is_nan() {
            f64::NAN
        } else {
            y
        }
    }
}

impl Widen for i64 {
    type P = f64;
    /// A fixed-point value, times its step.
    #[inline(always)]
    fn widen(self, scale: f64) -> f64 {
        self as f64 * scale
    }
}

impl Widen for Narrow {
    type P = f64;
    /// A fixed-point value in [−2^51, 2^51), times its step: `1.5·2^52 + x` has the bits of
    /// `1.5·2^52` plus `x` (its exponent's unit is 1, and the sum stays within [2^52, 2^53)),
    /// so subtracting `1.5·2^52` gives `x` exactly — `x as f64`.
    #[inline(always)]
    fn widen(self, scale: f64) -> f64 {
        const MAGIC: f64 = 6755399441055744.0; // 1.5 · 2^52
        let x = f64::from_bits(MAGIC.to_bits().wrapping_add(self.0 as u64)) - MAGIC;
        x * scale
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512dq")]
fn avx512dq<T: Widen>(src: &[T], p: T::P, dst: &mut [f64]) {
    body(src, p, dst)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn avx512<T: Widen>(src: &[T], p: T::P, dst: &mut [f64]) {
    body(src, p, dst)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn avx2<T: Widen>(src: &[T], p: T::P, dst: &mut [f64]) {
    body(src, p, dst)
}

#[inline(always)]
fn body<T: Widen>(src: &[T], p: T::P, dst: &mut [f64]) {
    for (d, &x) in dst.iter_mut().zip(src) {
        *d = x.widen(p);
    }
}
