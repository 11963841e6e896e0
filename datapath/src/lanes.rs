//! The operations the error bound is written in: +, −, ×, ÷, |x|, compares, mask logic and
//! selects on f64, nothing else (no FMA, no reassociation, no branch on data). Code written in
//! them is branch-free, so a loop that runs it over coordinate columns is vectorised by the
//! compiler (8 lanes under AVX-512F, 4 under AVX2) with each lane's result the one-case result
//! bit for bit (NaN encodings aside, which Rust leaves open). `f64` implements [`Lane`], and
//! [`crate::lanes_x86`] implements it on AVX-512F and AVX2 registers (the bound's explicit SIMD).

use std::fmt::Debug;
use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

/// One f64 value or a vector of them, with a mask type for compares.
pub trait Lane:
    Copy
    + Debug
    + PartialEq
    + Default
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// Per-lane booleans.
    type M: Copy + Debug + PartialEq + BitOr<Output = Self::M> + BitAnd<Output = Self::M> + Not<Output = Self::M>;
    /// Every lane `x`.
    fn splat(x: f64) -> Self;
    /// Every lane `b`.
    fn mask(b: bool) -> Self::M;
    /// |x| per lane.
    fn abs(self) -> Self;
    /// Lanes where `self <= o` (false on NaN).
    fn le(self, o: Self) -> Self::M;
    /// Lanes where `self < o` (false on NaN).
    fn lt(self, o: Self) -> Self::M;
    /// Lanes where `self >= o` (false on NaN).
    fn ge(self, o: Self) -> Self::M {
        o.le(self)
    }
    /// Lanes where `self > o` (false on NaN).
    fn gt(self, o: Self) -> Self::M {
        o.lt(self)
    }
    /// `m ? a : b` per lane.
    fn select(m: Self::M, a: Self, b: Self) -> Self;
}

impl Lane for f64 {
    type M = bool;
    #[inline(always)]
    fn splat(x: f64) -> Self {
        x
    }
    #[inline(always)]
    fn mask(b: bool) -> bool {
        b
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f64::abs(self)
    }
    #[inline(always)]
    fn le(self, o: Self) -> bool {
        self <= o
    }
    #[inline(always)]
    fn lt(self, o: Self) -> bool {
        self < o
    }
    #[inline(always)]
    fn select(m: bool, a: Self, b: Self) -> Self {
        if m {
            a
        } else {
            b
        }
    }
}
