//! Bit-exact IEEE arithmetic backends: each computes + - × ÷ rounded once to nearest-even with
//! gradual underflow. NaN payloads are left to [`super::Ieee`], which applies the NaN rule.

use super::layout::FloatLayout;
use half::f16;
use std::fmt::Debug;

/// Raw IEEE arithmetic of one float layout (nearest-even, subnormals kept, any NaN payload).
pub trait IeeeBackend: Clone + Copy + Debug + Send + Sync + 'static {
    /// Register type.
    type V: Copy + Debug + Default + Send + Sync + 'static;
    /// The bit layout.
    fn layout(&self) -> FloatLayout;
    /// Base name (without options).
    fn name(&self) -> String;
    /// Encoding of a value.
    fn bits(v: Self::V) -> u64;
    /// Value of an encoding.
    fn from_bits(b: u64) -> Self::V;
    /// a + b.
    fn add(&self, a: Self::V, b: Self::V) -> Self::V;
    /// a - b.
    fn sub(&self, a: Self::V, b: Self::V) -> Self::V;
    /// a × b.
    fn mul(&self, a: Self::V, b: Self::V) -> Self::V;
    /// a ÷ b.
    fn div(&self, a: Self::V, b: Self::V) -> Self::V;
    /// Correctly rounded conversion from f64.
    #[inline]
    #[allow(clippy::wrong_self_convention)] // a format carries run-time parameters
    fn from_f64(&self, x: f64) -> Self::V {
        Self::from_bits(self.layout().from_f64(x))
    }
    /// Exact conversion to f64.
    #[inline]
    fn to_f64(&self, v: Self::V) -> f64 {
        self.layout().to_f64(Self::bits(v))
    }
    /// [`Self::to_f64`] of a column: `dst[k] = to_f64(src[k])` for every `k` (equal lengths).
    #[inline]
    fn to_f64_column(&self, src: &[Self::V], dst: &mut [f64]) {
        assert_eq!(src.len(), dst.len(), "to_f64_column: columns of different lengths");
        for (d, &x) in dst.iter_mut().zip(src) {
            *d = self.to_f64(x);
        }
    }
    /// Whether [`Self::to_f64_column`] runs at vector speed (a hint for callers choosing between
    /// converting and keeping an f64 copy; the values are the same either way).
    #[inline]
    fn fast_f64_column(&self) -> bool {
        false
    }
    /// a < b, IEEE ordered.
    #[inline]
    fn lt(&self, a: Self::V, b: Self::V) -> bool {
        self.to_f64(a) < self.to_f64(b)
    }
    /// a <= b, IEEE ordered.
    #[inline]
    fn le(&self, a: Self::V, b: Self::V) -> bool {
        self.to_f64(a) <= self.to_f64(b)
    }
}

/// IEEE binary32 on the host's f32 unit (Rust never contracts to FMA).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct F32Native;

impl IeeeBackend for F32Native {
    type V = f32;
    #[inline(always)]
    fn layout(&self) -> FloatLayout {
        FloatLayout::BINARY32
    }
    fn name(&self) -> String {
        "f32".into()
    }
    #[inline(always)]
    fn bits(v: f32) -> u64 {
        v.to_bits() as u64
    }
    #[inline(always)]
    fn from_bits(b: u64) -> f32 {
        f32::from_bits(b as u32)
    }
    #[inline(always)]
    fn add(&self, a: f32, b: f32) -> f32 {
        a + b
    }
    #[inline(always)]
    fn sub(&self, a: f32, b: f32) -> f32 {
        a - b
    }
    #[inline(always)]
    fn mul(&self, a: f32, b: f32) -> f32 {
        a * b
    }
    #[inline(always)]
    fn div(&self, a: f32, b: f32) -> f32 {
        a / b
    }
    #[inline(always)]
    #[allow(clippy::wrong_self_convention)] // a format carries run-time parameters
    fn from_f64(&self, x: f64) -> f32 {
        x as f32 // Rust's f64 -> f32 cast rounds to nearest-even
    }
    #[inline(always)]
    fn to_f64(&self, v: f32) -> f64 {
        v as f64
    }
    #[inline]
    fn to_f64_column(&self, src: &[f32], dst: &mut [f64]) {
        // the same `as f64` on the widest lanes the machine has
        crate::simd::widen::f32_to_f64(crate::simd::Kernel::Avx512Fp16, src, dst)
    }
    #[inline(always)]
    fn fast_f64_column(&self) -> bool {
        true
    }
    #[inline(always)]
    fn lt(&self, a: f32, b: f32) -> bool {
        a < b
    }
    #[inline(always)]
    fn le(&self, a: f32, b: f32) -> bool {
        a <= b
    }
}

/// IEEE binary16 through the `half` crate: each op computed in f32 and rounded once to binary16,
/// which is correctly rounded because 24 >= 2·11 + 2. Conversion from f64 is our own exact rounding.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct F16Half;

impl IeeeBackend for F16Half {
    type V = f16;
    #[inline(always)]
    fn layout(&self) -> FloatLayout {
        FloatLayout::BINARY16
    }
    fn name(&self) -> String {
        "fp16".into()
    }
    #[inline(always)]
    fn bits(v: f16) -> u64 {
        v.to_bits() as u64
    }
    #[inline(always)]
    fn from_bits(b: u64) -> f16 {
        f16::from_bits(b as u16)
    }
    #[inline(always)]
    fn add(&self, a: f16, b: f16) -> f16 {
        a + b
    }
    #[inline(always)]
    fn sub(&self, a: f16, b: f16) -> f16 {
        a - b
    }
    #[inline(always)]
    fn mul(&self, a: f16, b: f16) -> f16 {
        a * b
    }
    #[inline(always)]
    fn div(&self, a: f16, b: f16) -> f16 {
        a / b
    }
    #[inline(always)]
    fn to_f64(&self, v: f16) -> f64 {
        v.to_f64()
    }
    #[inline]
    fn to_f64_column(&self, src: &[f16], dst: &mut [f64]) {
        // the hardware conversion on the widest lanes the machine has
        crate::simd::widen::f16_to_f64(crate::simd::Kernel::Avx512Fp16, src, dst)
    }
    #[inline(always)]
    fn fast_f64_column(&self) -> bool {
        true
    }
    #[inline(always)]
    fn lt(&self, a: f16, b: f16) -> bool {
        a.to_f32() < b.to_f32()
    }
    #[inline(always)]
    fn le(&self, a: f16, b: f16) -> bool {
        a.to_f32() <= b.to_f32()
    }
}

/// bfloat16: operands widened exactly to f32, one f32 op, then our nearest-even f32 → bf16
/// rounding (correct: 24 >= 2·8 + 2, and both share the exponent range).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Bf16;

impl Bf16 {
    #[inline(always)]
    fn wide(v: u16) -> f32 {
        f32::from_bits((v as u32) << 16)
    }
    /// Nearest-even rounding of an f32 to bfloat16 bits (NaN → 0x7fc0).
    #[inline(always)]
    pub fn round_f32(x: f32) -> u16 {
        if x.is_nan() {
            return 0x7fc0;
        }
        let b = x.to_bits();
        ((b + 0x7fff + ((b >> 16) & 1)) >> 16) as u16
    }
}

impl IeeeBackend for Bf16 {
    type V = u16;
    #[inline(always)]
    fn layout(&self) -> FloatLayout {
        FloatLayout::BFLOAT16
    }
    fn name(&self) -> String {
        "bf16".into()
    }
    #[inline(always)]
    fn bits(v: u16) -> u64 {
        v as u64
    }
    #[inline(always)]
    fn from_bits(b: u64) -> u16 {
        b as u16
    }
    #[inline(always)]
    fn add(&self, a: u16, b: u16) -> u16 {
        Self::round_f32(Self::wide(a) + Self::wide(b))
    }
    #[inline(always)]
    fn sub(&self, a: u16, b: u16) -> u16 {
        Self::round_f32(Self::wide(a) - Self::wide(b))
    }
    #[inline(always)]
    fn mul(&self, a: u16, b: u16) -> u16 {
        Self::round_f32(Self::wide(a) * Self::wide(b))
    }
    #[inline(always)]
    fn div(&self, a: u16, b: u16) -> u16 {
        Self::round_f32(Self::wide(a) / Self::wide(b))
    }
    #[inline(always)]
    fn to_f64(&self, v: u16) -> f64 {
        Self::wide(v) as f64
    }
    #[inline]
    fn to_f64_column(&self, src: &[u16], dst: &mut [f64]) {
        // the same shift and widening on the widest lanes the machine has
        crate::simd::widen::bf16_to_f64(crate::simd::Kernel::Avx512Fp16, src, dst)
    }
    #[inline(always)]
    fn fast_f64_column(&self) -> bool {
        true
    }
    #[inline(always)]
    fn lt(&self, a: u16, b: u16) -> bool {
        Self::wide(a) < Self::wide(b)
    }
    #[inline(always)]
    fn le(&self, a: u16, b: u16) -> bool {
        Self::wide(a) <= Self::wide(b)
    }
}

/// Any `eEmM` layout in exact integer soft-float ([`FloatLayout`]'s engine).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Soft(pub FloatLayout);

impl IeeeBackend for Soft {
    type V = u64;
    #[inline(always)]
    fn layout(&self) -> FloatLayout {
        self.0
    }
    fn name(&self) -> String {
        format!("e{}m{}", self.0.exp_bits, self.0.man_bits)
    }
    fn to_f64_column(&self, src: &[u64], dst: &mut [f64]) {
        let l = self.0;
        if l.exp_bits == 8 && l.man_bits <= 23 {
            // e8mM: the encoding shifted to binary32's fraction width is the same value in
            // binary32, widened exactly, in the lanes
            crate::simd::widen::e8_to_f64(crate::simd::Kernel::Avx512Fp16, src, 23 - l.man_bits, dst)
        } else {
            assert_eq!(src.len(), dst.len(), "to_f64_column: columns of different lengths");
            for (d, &x) in dst.iter_mut().zip(src) {
                *d = l.to_f64(x);
            }
        }
    }
    fn fast_f64_column(&self) -> bool {
        self.0.exp_bits == 8 && self.0.man_bits <= 23
    }
    #[inline(always)]
    fn bits(v: u64) -> u64 {
        v
    }
    #[inline(always)]
    fn from_bits(b: u64) -> u64 {
        b
    }
    fn add(&self, a: u64, b: u64) -> u64 {
        self.0.add(a, b)
    }
    fn sub(&self, a: u64, b: u64) -> u64 {
        self.0.sub(a, b)
    }
    fn mul(&self, a: u64, b: u64) -> u64 {
        self.0.mul(a, b)
    }
    fn div(&self, a: u64, b: u64) -> u64 {
        self.0.div(a, b)
    }
}
