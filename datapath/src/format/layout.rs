//! Exact integer arithmetic for IEEE-754-like binary formats with `e` exponent and `m` fraction
//! bits: the soft-float engine behind custom formats, and the correctly rounded f64 conversion
//! of every float format. Round-to-nearest-even, gradual underflow, overflow to infinity.
//!
//! A finite value is handled as `sig × 2^exp` with an integer significand; every operation forms
//! the exact result (or an exact stand-in that rounds identically) and rounds once in [`FloatLayout::round`].

/// Bit layout of an IEEE-754-like binary format: 1 sign, `exp_bits` exponent, `man_bits` fraction bits.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct FloatLayout {
    /// Exponent field width (2..=11).
    pub exp_bits: u32,
    /// Fraction (trailing significand) field width (1..=52).
    pub man_bits: u32,
}

/// A finite value decoded as `(-1)^neg × sig × 2^exp`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Decoded {
    /// Sign.
    pub neg: bool,
    /// Integer significand (hidden bit included for normals).
    pub sig: u64,
    /// Exponent of the significand's least significant bit.
    pub exp: i32,
}

/// Builds 2^e as an f64 exactly, for -1074 <= e <= 1023.
#[inline]
pub(crate) fn pow2(e: i32) -> f64 {
    debug_assert!((-1074..=1023).contains(&e));
    if e >= -1022 {
        f64::from_bits(((e + 1023) as u64) << 52)
    } else {
        f64::from_bits(1u64 << (e + 1074))
    }
}

impl FloatLayout {
    /// IEEE binary32.
    pub const BINARY32: Self = Self::new(8, 23);
    /// IEEE binary16.
    pub const BINARY16: Self = Self::new(5, 10);
    /// bfloat16.
    pub const BFLOAT16: Self = Self::new(8, 7);
    /// IEEE binary64.
    pub const BINARY64: Self = Self::new(11, 52);

    /// A layout with `e` exponent and `m` fraction bits.
    #[inline]
    pub const fn new(exp_bits: u32, man_bits: u32) -> Self {
        Self { exp_bits, man_bits }
    }

    /// Checks the widths this engine supports (every such format is a subset of binary64).
    pub fn validate(exp_bits: u32, man_bits: u32) -> Result<Self, String> {
        if !(2..=11).contains(&exp_bits) {
            return Err(format!("exponent width {exp_bits} out of range 2..=11"));
        }
        if !(1..=52).contains(&man_bits) {
            return Err(format!("fraction width {man_bits} out of range 1..=52"));
        }
        Ok(Self::new(exp_bits, man_bits))
    }

    /// Total width in bits.
    #[inline]
    pub const fn width(&self) -> u32 {
        1 + self.exp_bits + self.man_bits
    }
    /// Exponent bias.
    #[inline]
    pub const fn bias(&self) -> i32 {
        (1 << (self.exp_bits - 1)) - 1
    }
    /// Smallest normal exponent.
    #[inline]
    pub const fn emin(&self) -> i32 {
        1 - self.bias()
    }
    /// Largest finite exponent.
    #[inline]
    pub const fn emax(&self) -> i32 {
        self.bias()
    }
    /// Sign bit mask.
    #[inline]
    pub const fn sign_mask(&self) -> u64 {
        1 << (self.exp_bits + self.man_bits)
    }
    /// Exponent field mask.
    #[inline]
    pub const fn exp_mask(&self) -> u64 {
        ((1 << self.exp_bits) - 1) << self.man_bits
    }
    /// Fraction field mask.
    #[inline]
    pub const fn man_mask(&self) -> u64 {
        (1 << self.man_bits) - 1
    }
    /// The canonical quiet NaN: sign 0, exponent all ones, fraction MSB set, rest 0.
    #[inline]
    pub const fn canonical_nan(&self) -> u64 {
        self.exp_mask() | (1 << (self.man_bits - 1))
    }
    /// Infinity with the given sign.
    #[inline]
    pub const fn inf(&self, neg: bool) -> u64 {
        self.exp_mask() | if neg { self.sign_mask() } else { 0 }
    }
    /// Zero with the given sign.
    #[inline]
    pub const fn zero(&self, neg: bool) -> u64 {
        if neg {
            self.sign_mask()
        } else {
            0
        }
    }
    /// Largest finite magnitude as f64.
    pub fn max_finite(&self) -> f64 {
        let m = self.man_bits as i32;
        // (2 - 2^-m) * 2^emax
        (2.0 - pow2(-m)) * pow2(self.emax())
    }
    /// Smallest positive normal as f64.
    pub fn min_normal(&self) -> f64 {
        pow2(self.emin())
    }
    /// Unit roundoff 2^-(m+1) of round-to-nearest.
    pub fn unit_roundoff(&self) -> f64 {
        pow2(-(self.man_bits as i32) - 1)
    }

    /// True for NaN encodings.
    #[inline]
    pub const fn is_nan(&self, b: u64) -> bool {
        b & self.exp_mask() == self.exp_mask() && b & self.man_mask() != 0
    }
    /// True for ±infinity.
    #[inline]
    pub const fn is_inf(&self, b: u64) -> bool {
        b & (self.exp_mask() | self.man_mask()) == self.exp_mask()
    }
    /// True for ±0.
    #[inline]
    pub const fn is_zero(&self, b: u64) -> bool {
        b & (self.exp_mask() | self.man_mask()) == 0
    }
    /// True for nonzero subnormals.
    #[inline]
    pub const fn is_subnormal(&self, b: u64) -> bool {
        b & self.exp_mask() == 0 && b & self.man_mask() != 0
    }
    /// True when the sign bit is set.
    #[inline]
    pub const fn is_neg(&self, b: u64) -> bool {
        b & self.sign_mask() != 0
    }
    /// Sets the quiet bit (fraction MSB).
    #[inline]
    pub const fn quiet(&self, b: u64) -> u64 {
        b | (1 << (self.man_bits - 1))
    }

    /// Decodes a finite encoding (callers exclude NaN and infinity).
    #[inline]
    pub fn decode(&self, b: u64) -> Decoded {
        let neg = self.is_neg(b);
        let biased = ((b & self.exp_mask()) >> self.man_bits) as i32;
        let frac = b & self.man_mask();
        let m = self.man_bits as i32;
        if biased == 0 {
            Decoded { neg, sig: frac, exp: self.emin() - m }
        } else {
            Decoded { neg, sig: frac | (1 << self.man_bits), exp: biased - self.bias() - m }
        }
    }

    /// Rounds `(-1)^neg × sig × 2^exp` (exact) to this format, nearest-even, with gradual
    /// underflow and overflow to infinity. `sig` must be below 2^126.
    #[inline]
    pub fn round(&self, neg: bool, sig: u128, exp: i32) -> u64 {
        let sign = self.zero(neg);
        if sig == 0 {
            return sign;
        }
        let m = self.man_bits as i32;
        let len = 128 - sig.leading_zeros() as i32;
        let lead = exp + len - 1; // exponent of the leading bit
        let mut q = (lead - m).max(self.emin() - m); // exponent of the result's LSB
        let mut kept: u128 = if exp >= q {
            sig << (exp - q)
        } else {
            let sh = (q - exp) as u32;
            if sh >= 127 {
                0 // sig < 2^126 <= half a unit: rounds to zero
            } else {
                let kept = sig >> sh;
                let rem = sig & ((1u128 << sh) - 1);
                let half = 1u128 << (sh - 1);
                if rem > half || (rem == half && kept & 1 == 1) {
                    kept + 1
                } else {
                    kept
                }
            }
        };
        if kept >> (m + 1) != 0 {
            // rounding carried into a new binade: kept == 2^(m+1)
            kept >>= 1;
            q += 1;
        }
        if kept == 0 {
            return sign;
        }
        let biased = if kept >> m != 0 { q + m + self.bias() } else { 0 };
        if biased >= (1 << self.exp_bits) - 1 {
            return self.inf(neg);
        }
        sign | ((biased as u64) << self.man_bits) | (kept as u64 & self.man_mask())
    }

    /// Correctly rounded (nearest-even) conversion from f64. NaN becomes the canonical NaN.
    #[inline]
    pub fn from_f64(&self, x: f64) -> u64 {
        if x.is_nan() {
            return self.canonical_nan();
        }
        if x.is_infinite() {
            return self.inf(x < 0.0);
        }
        let d = FloatLayout::BINARY64.decode(x.to_bits());
        self.round(d.neg, d.sig as u128, d.exp)
    }

    /// Exact conversion to f64 (every supported format is a subset of binary64).
    #[inline]
    pub fn to_f64(&self, b: u64) -> f64 {
        if self.is_nan(b) {
            return f64::NAN;
        }
        if self.is_inf(b) {
            return if self.is_neg(b) { f64::NEG_INFINITY } else { f64::INFINITY };
        }
        let d = self.decode(b);
        // sig < 2^53 is exact; scaling by 2^exp is exact because the result is representable.
        let mag = if d.exp >= -1022 {
            d.sig as f64 * pow2(d.exp)
        } else {
            // split the scale so that no intermediate is rounded
            (d.sig as f64 * pow2(d.exp + 200)) * pow2(-200)
        };
        if d.neg {
            -mag
        } else {
            mag
        }
    }

    /// IEEE addition, nearest-even. Any NaN result is the canonical NaN.
    #[inline]
    pub fn add(&self, a: u64, b: u64) -> u64 {
        if self.is_nan(a) || self.is_nan(b) {
            return self.canonical_nan();
        }
        match (self.is_inf(a), self.is_inf(b)) {
            (true, true) if self.is_neg(a) != self.is_neg(b) => return self.canonical_nan(),
            (true, _) => return a,
            (_, true) => return b,
            _ => {}
        }
        let (x, y) = (self.decode(a), self.decode(b));
        if x.sig == 0 && y.sig == 0 {
            // +0 + -0 = +0 under nearest-even; -0 + -0 = -0
            return self.zero(x.neg && y.neg);
        }
        if x.sig == 0 {
            return b;
        }
        if y.sig == 0 {
            return a;
        }
        // big has the larger LSB exponent
        let (big, small) = if x.exp >= y.exp { (x, y) } else { (y, x) };
        let d = big.exp - small.exp;
        let (sb, ss, exp) = if d > 70 {
            // |small| < 2^(big.exp-17): a one-bit stand-in far below big's LSB rounds identically
            ((big.sig as u128) << 70, 1u128, big.exp - 70)
        } else {
            ((big.sig as u128) << d, small.sig as u128, small.exp)
        };
        if big.neg == small.neg {
            self.round(big.neg, sb + ss, exp)
        } else if sb > ss {
            self.round(big.neg, sb - ss, exp)
        } else if ss > sb {
            self.round(small.neg, ss - sb, exp)
        } else {
            self.zero(false) // exact cancellation gives +0 under nearest-even
        }
    }

    /// IEEE subtraction, nearest-even.
    #[inline]
    pub fn sub(&self, a: u64, b: u64) -> u64 {
        if self.is_nan(b) {
            return self.canonical_nan();
        }
        self.add(a, b ^ self.sign_mask())
    }

    /// IEEE multiplication, nearest-even.
    #[inline]
    pub fn mul(&self, a: u64, b: u64) -> u64 {
        if self.is_nan(a) || self.is_nan(b) {
            return self.canonical_nan();
        }
        let neg = self.is_neg(a) != self.is_neg(b);
        let (ia, ib) = (self.is_inf(a), self.is_inf(b));
        if ia || ib {
            if self.is_zero(a) || self.is_zero(b) {
                return self.canonical_nan();
            }
            return self.inf(neg);
        }
        let (x, y) = (self.decode(a), self.decode(b));
        self.round(neg, x.sig as u128 * y.sig as u128, x.exp + y.exp)
    }

    /// IEEE division, nearest-even.
    #[inline]
    pub fn div(&self, a: u64, b: u64) -> u64 {
        if self.is_nan(a) || self.is_nan(b) {
            return self.canonical_nan();
        }
        let neg = self.is_neg(a) != self.is_neg(b);
        let (ia, ib) = (self.is_inf(a), self.is_inf(b));
        let (za, zb) = (self.is_zero(a), self.is_zero(b));
        if (ia && ib) || (za && zb) {
            return self.canonical_nan();
        }
        if ia || zb {
            return self.inf(neg);
        }
        if ib || za {
            return self.zero(neg);
        }
        let (x, y) = (self.decode(a), self.decode(b));
        let la = 64 - x.sig.leading_zeros() as i32;
        let lb = 64 - y.sig.leading_zeros() as i32;
        let k = (lb - la + self.man_bits as i32 + 3).max(0);
        let num = (x.sig as u128) << k;
        let q = num / y.sig as u128;
        let r = num % y.sig as u128;
        // q has at least m+3 bits; the appended sticky bit lies below the rounding point
        let sig = (q << 1) | (r != 0) as u128;
        self.round(neg, sig, x.exp - y.exp - k - 1)
    }

    /// IEEE ordered comparison a < b (false if either is NaN; -0 == +0).
    #[inline]
    pub fn lt(&self, a: u64, b: u64) -> bool {
        self.to_f64(a) < self.to_f64(b)
    }
    /// IEEE ordered comparison a <= b (false if either is NaN; -0 == +0).
    #[inline]
    pub fn le(&self, a: u64, b: u64) -> bool {
        self.to_f64(a) <= self.to_f64(b)
    }

    /// Spacing of the format's grid at |x| (one unit in the last place).
    pub fn ulp(&self, x: f64) -> f64 {
        let m = self.man_bits as i32;
        let ax = x.abs();
        if !ax.is_finite() || ax < self.min_normal() {
            return pow2(self.emin() - m);
        }
        let e = FloatLayout::BINARY64.decode(ax.to_bits());
        let lead = e.exp + 63 - e.sig.leading_zeros() as i32;
        pow2((lead.min(self.emax()) - m).max(self.emin() - m))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn binary32_layout_matches_native_encodings() {
        let l = FloatLayout::BINARY32;
        for x in [1.0f32, -2.5, 3.4028235e38, 1.0e-45, 1.1754944e-38, 0.1] {
            assert_eq!(l.from_f64(x as f64), x.to_bits() as u64, "{x}");
            assert_eq!(l.to_f64(x.to_bits() as u64), x as f64);
        }
        assert_eq!(l.max_finite(), f32::MAX as f64);
        assert_eq!(l.min_normal(), f32::MIN_POSITIVE as f64);
    }

    #[test]
    fn rounding_ties_go_to_even_and_overflow_to_inf() {
        let l = FloatLayout::BINARY16;
        // 2049 lies halfway between 2048 and 2050 in binary16: ties to even (2048)
        assert_eq!(l.to_f64(l.from_f64(2049.0)), 2048.0);
        assert_eq!(l.to_f64(l.from_f64(2051.0)), 2052.0);
        assert_eq!(l.from_f64(65520.0), l.inf(false)); // halfway to 2^16 rounds to inf
        assert_eq!(l.to_f64(l.from_f64(65519.99)), 65504.0);
        // smallest subnormal 2^-24; half of it ties to zero, just above rounds up
        assert_eq!(l.from_f64(pow2(-25)), 0);
        assert_eq!(l.from_f64(pow2(-25) * 1.0000001), 1);
    }
}
