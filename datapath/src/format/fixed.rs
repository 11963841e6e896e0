//! Signed two's-complement fixed point `qI.F`: `I` integer bits (sign included) and `F` fraction
//! bits, total width 2..=64. Values are raw integers scaled by 2^-F; products and quotients are
//! formed exactly in i128 and then rounded and overflowed per the datapath's stated modes.

use super::layout::pow2;
use super::{Contract, DivMode, ErrorModel, Format, FormatKind};

/// Rounding of products, quotients and input conversion.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FxRound {
    /// Toward −∞ (dropping the low bits of a two's-complement value).
    Floor,
    /// Toward +∞.
    Ceil,
    /// Toward zero.
    Trunc,
    /// To nearest, ties to even.
    NearestEven,
}

/// What happens to a result outside the range.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FxOverflow {
    /// Clamp to the most positive / most negative value.
    Saturate,
    /// Keep the low `width` bits (two's-complement wrap-around).
    Wrap,
}

/// A signed fixed-point format with its rounding, overflow and division modes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Fixed {
    /// Integer bits, sign included (>= 1).
    pub int_bits: u32,
    /// Fraction bits.
    pub frac_bits: u32,
    /// Rounding mode.
    pub round: FxRound,
    /// Overflow mode.
    pub overflow: FxOverflow,
    /// Division mode.
    pub div: DivMode,
}

impl Fixed {
    /// A `qI.F` format; checks 1 <= I and 2 <= I + F <= 64.
    pub fn new(
        int_bits: u32,
        frac_bits: u32,
        round: FxRound,
        overflow: FxOverflow,
        div: DivMode,
    ) -> Result<Self, String> {
        // checked: `q4294967295.3` must not wrap to a 2-bit format
        let w = int_bits.saturating_add(frac_bits);
        if int_bits == 0 || !(2..=64).contains(&w) {
            return Err(format!(
                "q{int_bits}.{frac_bits}: need at least 1 integer (sign) bit and a total width of 2..=64"
            ));
        }
        Ok(Self { int_bits, frac_bits, round, overflow, div })
    }
    fn w(&self) -> u32 {
        self.int_bits + self.frac_bits
    }
    /// Most positive raw value.
    pub fn max_raw(&self) -> i64 {
        ((1u64 << (self.w() - 1)) - 1) as i64
    }
    /// Most negative raw value.
    pub fn min_raw(&self) -> i64 {
        if self.w() == 64 {
            i64::MIN
        } else {
            -(1i64 << (self.w() - 1))
        }
    }
    /// Applies the overflow mode to an exact integer result.
    #[inline(always)]
    fn fit(&self, x: i128) -> i64 {
        match self.overflow {
            FxOverflow::Saturate => x.clamp(self.min_raw() as i128, self.max_raw() as i128) as i64,
            FxOverflow::Wrap => {
                let sh = 128 - self.w();
                ((x << sh) >> sh) as i64
            }
        }
    }
    /// Rounds the exact rational `num / den` (den > 0) to an integer per the rounding mode.
    #[inline(always)]
    fn round_div(&self, num: i128, den: i128) -> i128 {
        debug_assert!(den > 0);
        let q = num.div_euclid(den); // floor
        let r = num.rem_euclid(den); // 0 <= r < den
        if r == 0 {
            return q;
        }
        match self.round {
            FxRound::Floor => q,
            FxRound::Ceil => q + 1,
            FxRound::Trunc => {
                if num < 0 {
                    q + 1
                } else {
                    q
                }
            }
            FxRound::NearestEven => {
                let twice = 2 * r;
                if twice > den || (twice == den && q & 1 == 1) {
                    q + 1
                } else {
                    q
                }
            }
        }
    }
    fn round_name(&self) -> &'static str {
        match self.round {
            FxRound::Floor => "floor",
            FxRound::Ceil => "ceil",
            FxRound::Trunc => "trunc",
            FxRound::NearestEven => "nearest",
        }
    }
}

impl Format for Fixed {
    type V = i64;

    fn name(&self) -> String {
        let mut opts = Vec::new();
        if self.round != FxRound::Floor {
            opts.push(self.round_name());
        }
        if self.overflow == FxOverflow::Wrap {
            opts.push("wrap");
        }
        if self.div == DivMode::Divide {
            opts.push("divide");
        }
        if opts.is_empty() {
            format!("q{}.{}", self.int_bits, self.frac_bits)
        } else {
            format!("q{}.{}:{}", self.int_bits, self.frac_bits, opts.join("+"))
        }
    }
    fn kind(&self) -> FormatKind {
        FormatKind::Fixed { int_bits: self.int_bits, frac_bits: self.frac_bits }
    }
    fn width(&self) -> u32 {
        self.w()
    }
    fn contract(&self) -> Contract {
        let step = format!("2^-{}", self.frac_bits);
        Contract {
            encoding: format!(
                "signed two's complement, {} bits: {} integer bits (sign included) and {} fraction bits; step {step}",
                self.w(),
                self.int_bits,
                self.frac_bits
            ),
            rounding: format!(
                "+ and - exact; x and / formed exactly in i128 and rounded {} to the step; f64 input conversion rounded the same way",
                match self.round {
                    FxRound::Floor => "toward -inf (floor)",
                    FxRound::Ceil => "toward +inf (ceil)",
                    FxRound::Trunc => "toward zero",
                    FxRound::NearestEven => "to nearest, ties to even",
                }
            ),
            subnormals: "not applicable".into(),
            nan: "no NaN encoding; an f64 NaN input converts to 0 (the CLI rejects NaN inputs before conversion)".into(),
            overflow: match self.overflow {
                FxOverflow::Saturate => "results and inputs outside the range saturate to the most positive / most negative value; ±inf inputs saturate".into(),
                FxOverflow::Wrap => "results and inputs outside the range wrap modulo 2^width; ±inf inputs saturate".into(),
            },
            division: format!(
                "{}; x / 0 gives the most positive value for x > 0, the most negative for x < 0, and 0 for 0 / 0",
                match self.div {
                    DivMode::Divide => "a / b rounded once",
                    DivMode::RecipMul => "a x (1 / b): reciprocal rounded, then a rounded multiply",
                }
            ),
            compare: "two's-complement integer compare".into(),
        }
    }
    fn error_model(&self) -> ErrorModel {
        let step = pow2(-(self.frac_bits as i32));
        let eta = if self.round == FxRound::NearestEven { step / 2.0 } else { step };
        ErrorModel { u: 0.0, eta, add_eta: 0.0, max: self.max_raw() as f64 * step }
    }
    fn div_mode(&self) -> DivMode {
        self.div
    }

    fn from_f64(&self, x: f64) -> i64 {
        if x.is_nan() {
            return 0;
        }
        if x.is_infinite() {
            return if x > 0.0 { self.max_raw() } else { self.min_raw() };
        }
        // scaling by 2^F is exact in f64 for every finite x of interest (no overflow below 2^960)
        let y = x * pow2(self.frac_bits as i32);
        let r = match self.round {
            FxRound::Floor => y.floor(),
            FxRound::Ceil => y.ceil(),
            FxRound::Trunc => y.trunc(),
            FxRound::NearestEven => y.round_ties_even(),
        };
        if r.abs() < 2f64.powi(126) {
            self.fit(r as i128)
        } else {
            match self.overflow {
                FxOverflow::Saturate => {
                    if r > 0.0 {
                        self.max_raw()
                    } else {
                        self.min_raw()
                    }
                }
                FxOverflow::Wrap => 0, // a multiple of 2^75 or more: zero modulo 2^width
            }
        }
    }
    fn to_f64(&self, v: i64) -> f64 {
        v as f64 * pow2(-(self.frac_bits as i32))
    }
    fn to_f64_column(&self, src: &[i64], dst: &mut [f64]) {
        // the same two roundings in vector lanes where the machine has them
        crate::simd::widen::fixed_to_f64(crate::simd::Kernel::Avx512Fp16, src, pow2(-(self.frac_bits as i32)), dst)
    }
    fn fast_f64_column(&self) -> bool {
        crate::simd::widen::fixed_in_lanes(crate::simd::Kernel::Avx512Fp16, self.w())
    }
    fn to_bits(&self, v: i64) -> u64 {
        (v as u64) & (u64::MAX >> (64 - self.w()))
    }
    fn from_bits(&self, b: u64) -> i64 {
        let sh = 64 - self.w();
        ((b << sh) as i64) >> sh
    }

    #[inline(always)]
    fn add(&self, a: i64, b: i64) -> i64 {
        self.fit(a as i128 + b as i128)
    }
    #[inline(always)]
    fn sub(&self, a: i64, b: i64) -> i64 {
        self.fit(a as i128 - b as i128)
    }
    #[inline(always)]
    fn mul(&self, a: i64, b: i64) -> i64 {
        let p = a as i128 * b as i128;
        self.fit(self.round_div(p, 1i128 << self.frac_bits))
    }
    #[inline(always)]
    fn div(&self, a: i64, b: i64) -> i64 {
        match self.div {
            DivMode::Divide => self.div_exact(a, b),
            DivMode::RecipMul => {
                let r = self.div_exact(self.one(), b);
                self.mul(a, r)
            }
        }
    }
    #[inline(always)]
    fn lt(&self, a: i64, b: i64) -> bool {
        a < b
    }
    #[inline(always)]
    fn le(&self, a: i64, b: i64) -> bool {
        a <= b
    }
    fn is_nan(&self, _v: i64) -> bool {
        false
    }
    #[inline(always)]
    fn abs(&self, a: i64) -> i64 {
        self.fit((a as i128).abs())
    }
    fn zero(&self) -> i64 {
        0
    }
    fn ulp(&self, _x: f64) -> f64 {
        pow2(-(self.frac_bits as i32))
    }
    fn wraps(&self) -> bool {
        self.overflow == FxOverflow::Wrap
    }
    fn sign_bit(&self, v: i64) -> bool {
        v < 0
    }
    fn next_up(&self, v: i64) -> i64 {
        if v == self.max_raw() {
            v
        } else {
            v + 1
        }
    }
    fn next_down(&self, v: i64) -> i64 {
        if v == self.min_raw() {
            v
        } else {
            v - 1
        }
    }
}

impl Fixed {
    /// a / b rounded once (division by zero saturates, 0/0 = 0).
    #[inline(always)]
    fn div_exact(&self, a: i64, b: i64) -> i64 {
        if b == 0 {
            return match a.signum() {
                1 => self.max_raw(),
                -1 => self.min_raw(),
                _ => 0,
            };
        }
        let (mut num, mut den) = ((a as i128) << self.frac_bits, b as i128);
        if den < 0 {
            num = -num;
            den = -den;
        }
        self.fit(self.round_div(num, den))
    }
}
