//! [`Lane`] on x86 vector registers: 8 binary64 lanes of AVX-512F ([`F64x8`], compare masks
//! in a `__mmask8`) and 4 of AVX2 ([`F64x4`], masks as all-ones lanes), so that code written in
//! [`Lane`] (the error bound) runs as explicit SIMD instead of relying on the loop vectoriser.
//! Each operation is the one IEEE operation on every lane (no FMA, no reassociation); negation
//! flips the sign bit (−(+0) = −0, as f64's), compares are ordered-quiet (false on NaN),
//! selects are blends.
//!
//! The methods are `#[inline(always)]` and call the instructions without run-time checks: use
//! these types only inside a function compiled with the feature (`#[target_feature(enable =
//! "avx512f")]` / `"avx2"`) that the caller reached after detecting it.

use crate::lanes::Lane;
use std::arch::x86_64::*;
use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

/// Eight binary64 lanes (AVX-512F).
#[derive(Clone, Copy, Debug)]
pub struct F64x8(pub __m512d);
/// Eight lane booleans (an AVX-512 mask register).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct M8(pub u8);
/// Four binary64 lanes (AVX2).
#[derive(Clone, Copy, Debug)]
pub struct F64x4(pub __m256d);
/// Four lane booleans as all-ones / all-zeros binary64 lanes.
#[derive(Clone, Copy, Debug)]
pub struct M4(pub __m256d);

macro_rules! binop {
    ($t:ty, $tr:ident, $f:ident, $intr:ident) => {
        impl $tr for $t {
            type Output = $t;
            #[inline(always)]
            fn $f(self, o: $t) -> $t {
                // SAFETY: used only where the feature was detected (module documentation)
                unsafe { Self($intr(self.0, o.0)) }
            }
        }
    };
}
binop!(F64x8, Add, add, _mm512_add_pd);
binop!(F64x8, Sub, sub, _mm512_sub_pd);
binop!(F64x8, Mul, mul, _mm512_mul_pd);
binop!(F64x8, Div, div, _mm512_div_pd);
binop!(F64x4, Add, add, _mm256_add_pd);
binop!(F64x4, Sub, sub, _mm256_sub_pd);
binop!(F64x4, Mul, mul, _mm256_mul_pd);
binop!(F64x4, Div, div, _mm256_div_pd);

impl Neg for F64x8 {
    type Output = F64x8;
    #[inline(always)]
    fn neg(self) -> F64x8 {
        // SAFETY: as above; the sign bit flipped in the integer domain (AVX-512F)
        unsafe { Self(_mm512_castsi512_pd(_mm512_xor_si512(_mm512_castpd_si512(self.0), _mm512_set1_epi64(i64::MIN)))) }
    }
}
impl Neg for F64x4 {
    type Output = F64x4;
    #[inline(always)]
    fn neg(self) -> F64x4 {
        // SAFETY: as above
        unsafe { Self(_mm256_xor_pd(self.0, _mm256_set1_pd(-0.0))) }
    }
}

impl PartialEq for F64x8 {
    fn eq(&self, o: &Self) -> bool {
        // SAFETY: plain bits
        unsafe { std::mem::transmute::<__m512d, [u64; 8]>(self.0) == std::mem::transmute::<__m512d, [u64; 8]>(o.0) }
    }
}
impl PartialEq for F64x4 {
    fn eq(&self, o: &Self) -> bool {
        // SAFETY: plain bits
        unsafe { std::mem::transmute::<__m256d, [u64; 4]>(self.0) == std::mem::transmute::<__m256d, [u64; 4]>(o.0) }
    }
}
impl PartialEq for M4 {
    fn eq(&self, o: &Self) -> bool {
        F64x4(self.0) == F64x4(o.0)
    }
}
impl Default for F64x8 {
    fn default() -> Self {
        // SAFETY: zeroed bits are a valid vector
        unsafe { std::mem::zeroed() }
    }
}
impl Default for F64x4 {
    fn default() -> Self {
        // SAFETY: zeroed bits are a valid vector
        unsafe { std::mem::zeroed() }
    }
}

impl BitOr for M8 {
    type Output = M8;
    #[inline(always)]
    fn bitor(self, o: M8) -> M8 {
        M8(self.0 | o.0)
    }
}
impl BitAnd for M8 {
    type Output = M8;
    #[inline(always)]
    fn bitand(self, o: M8) -> M8 {
        M8(self.0 & o.0)
    }
}
impl Not for M8 {
    type Output = M8;
    #[inline(always)]
    fn not(self) -> M8 {
        M8(!self.0)
    }
}
impl BitOr for M4 {
    type Output = M4;
    #[inline(always)]
    fn bitor(self, o: M4) -> M4 {
        // SAFETY: as above
        unsafe { M4(_mm256_or_pd(self.0, o.0)) }
    }
}
impl BitAnd for M4 {
    type Output = M4;
    #[inline(always)]
    fn bitand(self, o: M4) -> M4 {
        // SAFETY: as above
        unsafe { M4(_mm256_and_pd(self.0, o.0)) }
    }
}
impl Not for M4 {
    type Output = M4;
    #[inline(always)]
    fn not(self) -> M4 {
        // SAFETY: as above
        unsafe { M4(_mm256_xor_pd(self.0, _mm256_castsi256_pd(_mm256_set1_epi64x(-1)))) }
    }
}

impl Lane for F64x8 {
    type M = M8;
    #[inline(always)]
    fn splat(x: f64) -> Self {
        // SAFETY: as above
        unsafe { Self(_mm512_set1_pd(x)) }
    }
    #[inline(always)]
    fn mask(b: bool) -> M8 {
        M8(if b { 0xff } else { 0 })
    }
    #[inline(always)]
    fn abs(self) -> Self {
        // SAFETY: as above
        unsafe { Self(_mm512_abs_pd(self.0)) }
    }
    #[inline(always)]
    fn le(self, o: Self) -> M8 {
        // SAFETY: as above
        unsafe { M8(_mm512_cmp_pd_mask::<_CMP_LE_OQ>(self.0, o.0)) }
    }
    #[inline(always)]
    fn lt(self, o: Self) -> M8 {
        // SAFETY: as above
        unsafe { M8(_mm512_cmp_pd_mask::<_CMP_LT_OQ>(self.0, o.0)) }
    }
    #[inline(always)]
    fn select(m: M8, a: Self, b: Self) -> Self {
        // SAFETY: as above (a mask bit set takes the second operand)
        unsafe { Self(_mm512_mask_blend_pd(m.0, b.0, a.0)) }
    }
}

impl Lane for F64x4 {
    type M = M4;
    #[inline(always)]
    fn splat(x: f64) -> Self {
        // SAFETY: as above
        unsafe { Self(_mm256_set1_pd(x)) }
    }
    #[inline(always)]
    fn mask(b: bool) -> M4 {
        // SAFETY: as above
        unsafe { M4(_mm256_castsi256_pd(_mm256_set1_epi64x(if b { -1 } else { 0 }))) }
    }
    #[inline(always)]
    fn abs(self) -> Self {
        // SAFETY: as above
        unsafe { Self(_mm256_andnot_pd(_mm256_set1_pd(-0.0), self.0)) }
    }
    #[inline(always)]
    fn le(self, o: Self) -> M4 {
        // SAFETY: as above
        unsafe { M4(_mm256_cmp_pd::<_CMP_LE_OQ>(self.0, o.0)) }
    }
    #[inline(always)]
    fn lt(self, o: Self) -> M4 {
        // SAFETY: as above
        unsafe { M4(_mm256_cmp_pd::<_CMP_LT_OQ>(self.0, o.0)) }
    }
    #[inline(always)]
    fn select(m: M4, a: Self, b: Self) -> Self {
        // SAFETY: as above (a set mask lane takes the second operand)
        unsafe { Self(_mm256_blendv_pd(b.0, a.0, m.0)) }
    }
}

/// A [`Lane`] vector that loads and stores f64 columns: what a block body needs to run code
/// written in [`Lane`] over columns.
pub trait Vector: Lane {
    /// Lanes per vector.
    const N: usize;
    /// The `N` values at `p`.
    ///
    /// # Safety
    /// `p..p + N` must be readable f64s, and the vector's feature present.
    unsafe fn load(p: *const f64) -> Self;
    /// Writes the lanes to `p..p + N`.
    ///
    /// # Safety
    /// `p..p + N` must be writable f64s, and the vector's feature present.
    unsafe fn store(self, p: *mut f64);
    /// The mask as bits, lane k in bit k.
    fn bits(m: Self::M) -> u32;
    /// Per lane `self > o ? self : o` (`maxpd`: o where either is NaN or both are zeros).
    fn max_of(self, o: Self) -> Self;
}

impl Vector for F64x8 {
    const N: usize = 8;
    #[inline(always)]
    unsafe fn load(p: *const f64) -> Self {
        // SAFETY: the caller's contract
        unsafe { Self(_mm512_loadu_pd(p)) }
    }
    #[inline(always)]
    unsafe fn store(self, p: *mut f64) {
        // SAFETY: the caller's contract
        unsafe { _mm512_storeu_pd(p, self.0) }
    }
    #[inline(always)]
    fn bits(m: M8) -> u32 {
        u32::from(m.0)
    }
    #[inline(always)]
    fn max_of(self, o: Self) -> Self {
        // SAFETY: used only where the feature was detected (module documentation)
        unsafe { Self(_mm512_max_pd(self.0, o.0)) }
    }
}

impl Vector for F64x4 {
    const N: usize = 4;
    #[inline(always)]
    unsafe fn load(p: *const f64) -> Self {
        // SAFETY: the caller's contract
        unsafe { Self(_mm256_loadu_pd(p)) }
    }
    #[inline(always)]
    unsafe fn store(self, p: *mut f64) {
        // SAFETY: the caller's contract
        unsafe { _mm256_storeu_pd(p, self.0) }
    }
    #[inline(always)]
    fn bits(m: M4) -> u32 {
        // SAFETY: used only where the feature was detected (module documentation)
        unsafe { _mm256_movemask_pd(m.0) as u32 }
    }
    #[inline(always)]
    fn max_of(self, o: Self) -> Self {
        // SAFETY: used only where the feature was detected (module documentation)
        unsafe { Self(_mm256_max_pd(self.0, o.0)) }
    }
}
