//! Independent oracles for the per-op tests: exact rationals (num-rational) rounded by code that
//! shares nothing with the engine under test, and IEEE special-value rules taken from f64.
#![allow(dead_code)]

use datapath::format::{FloatLayout, FxOverflow, FxRound};
use num_bigint::BigInt;
use num_rational::BigRational;
use num_traits::{One, Signed, Zero};

/// Arithmetic operation under test.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Op {
    Add,
    Sub,
    Mul,
    Div,
}
pub const OPS: [Op; 4] = [Op::Add, Op::Sub, Op::Mul, Op::Div];

fn pow2(e: i64) -> BigRational {
    let two = BigInt::from(2);
    if e >= 0 {
        BigRational::from_integer(two.pow(e as u32))
    } else {
        BigRational::new(BigInt::one(), two.pow((-e) as u32))
    }
}

/// Exact value of a finite encoding, from the field definitions.
pub fn exact(l: FloatLayout, bits: u64) -> BigRational {
    let m = l.man_bits;
    let frac = bits & ((1 << m) - 1);
    let biased = (bits >> m) & ((1 << l.exp_bits) - 1);
    let bias = (1i64 << (l.exp_bits - 1)) - 1;
    let mag = if biased == 0 {
        BigRational::from_integer(BigInt::from(frac)) * pow2(1 - bias - m as i64)
    } else {
        BigRational::from_integer(BigInt::from(frac | (1 << m))) * pow2(biased as i64 - bias - m as i64)
    };
    if bits >> (l.exp_bits + m) & 1 == 1 {
        -mag
    } else {
        mag
    }
}

/// floor(log2(a)) for a > 0.
fn ilog2(a: &BigRational) -> i64 {
    let mut e = a.numer().bits() as i64 - a.denom().bits() as i64;
    while &pow2(e) > a {
        e -= 1;
    }
    while &pow2(e + 1) <= a {
        e += 1;
    }
    e
}

/// Nearest-even rounding of a nonzero exact rational into the layout (gradual underflow,
/// overflow to infinity), encoded from the field definitions.
pub fn round_float(l: FloatLayout, q: &BigRational) -> u64 {
    assert!(!q.is_zero());
    let neg = q.is_negative();
    let a = q.abs();
    let m = l.man_bits as i64;
    let bias = (1i64 << (l.exp_bits - 1)) - 1;
    let emin = 1 - bias;
    let e = ilog2(&a);
    let mut qe = e.max(emin) - m;
    let scaled = &a / pow2(qe);
    let mut k = scaled.floor().to_integer();
    let rem = scaled - BigRational::from_integer(k.clone());
    let half = BigRational::new(BigInt::one(), BigInt::from(2));
    if rem > half || (rem == half && (&k % 2u32) == BigInt::one()) {
        k += 1;
    }
    let two_m = BigInt::from(1u64 << m);
    if k == BigInt::from(2) * &two_m {
        k /= 2;
        qe += 1;
    }
    let sign = if neg { 1u64 << (l.exp_bits + l.man_bits) } else { 0 };
    let inf = sign | (((1u64 << l.exp_bits) - 1) << m);
    let k64: u64 = k.try_into().unwrap();
    if k64 == 0 {
        return sign;
    }
    if k64 >= 1 << m {
        let biased = qe + m + bias;
        if biased >= (1 << l.exp_bits) - 1 {
            return inf;
        }
        sign | ((biased as u64) << m) | (k64 - (1 << m))
    } else {
        sign | k64
    }
}

fn is_nan(l: FloatLayout, b: u64) -> bool {
    let e = (b >> l.man_bits) & ((1 << l.exp_bits) - 1);
    e == (1 << l.exp_bits) - 1 && b & ((1 << l.man_bits) - 1) != 0
}
fn is_special(l: FloatLayout, b: u64) -> bool {
    (b >> l.man_bits) & ((1 << l.exp_bits) - 1) == (1 << l.exp_bits) - 1
}

/// The IEEE nearest-even result of `a op b` with gradual underflow; every NaN result is the
/// canonical NaN. Finite nonzero results come from exact rationals; zeros, infinities and NaN
/// (whose signs follow IEEE rules) from f64, which implements those rules exactly.
pub fn float_op(l: FloatLayout, op: Op, a: u64, b: u64) -> u64 {
    let canonical = (((1u64 << l.exp_bits) - 1) << l.man_bits) | (1 << (l.man_bits - 1));
    if is_nan(l, a) || is_nan(l, b) {
        return canonical;
    }
    let special = is_special(l, a) || is_special(l, b);
    let exact_res = if special {
        None
    } else {
        let (xa, xb) = (exact(l, a), exact(l, b));
        match op {
            Op::Add => Some(&xa + &xb),
            Op::Sub => Some(&xa - &xb),
            Op::Mul => Some(&xa * &xb),
            Op::Div if xb.is_zero() => None,
            Op::Div => Some(&xa / &xb),
        }
    };
    match exact_res {
        Some(q) if !q.is_zero() => round_float(l, &q),
        _ => {
            // special operands or an exact zero: f64 gives the IEEE class and sign
            let fa = l.to_f64(a);
            let fb = l.to_f64(b);
            let r = match op {
                Op::Add => fa + fb,
                Op::Sub => fa - fb,
                Op::Mul => fa * fb,
                Op::Div => fa / fb,
            };
            let sign = if r.is_sign_negative() { 1u64 << (l.exp_bits + l.man_bits) } else { 0 };
            if r.is_nan() {
                canonical
            } else if r.is_infinite() {
                sign | (((1u64 << l.exp_bits) - 1) << l.man_bits)
            } else {
                assert_eq!(r, 0.0, "finite special result must be a zero");
                sign
            }
        }
    }
}

/// Correct rounding of an f64 into the layout.
pub fn float_from_f64(l: FloatLayout, x: f64) -> u64 {
    if x.is_nan() {
        return (((1u64 << l.exp_bits) - 1) << l.man_bits) | (1 << (l.man_bits - 1));
    }
    let sign = if x.is_sign_negative() { 1u64 << (l.exp_bits + l.man_bits) } else { 0 };
    if x.is_infinite() {
        return sign | (((1u64 << l.exp_bits) - 1) << l.man_bits);
    }
    if x == 0.0 {
        return sign;
    }
    round_float(l, &BigRational::from_float(x).unwrap())
}

/// Flushes a subnormal encoding to zero of the same sign.
pub fn flush(l: FloatLayout, b: u64) -> u64 {
    let biased = (b >> l.man_bits) & ((1 << l.exp_bits) - 1);
    if biased == 0 {
        b & (1 << (l.exp_bits + l.man_bits))
    } else {
        b
    }
}

/// Fixed-point oracle: `i`.`f`, raw values as i64.
#[derive(Clone, Copy, Debug)]
pub struct Fx {
    pub i: u32,
    pub f: u32,
    pub round: FxRound,
    pub overflow: FxOverflow,
}

impl Fx {
    pub fn w(&self) -> u32 {
        self.i + self.f
    }
    pub fn value(&self, raw: i64) -> BigRational {
        BigRational::from_integer(BigInt::from(raw)) * pow2(-(self.f as i64))
    }
    /// Rounds an exact rational to the grid per the rounding mode, then applies overflow.
    pub fn round(&self, q: &BigRational) -> i64 {
        let s = q * pow2(self.f as i64);
        let fl = s.floor().to_integer();
        let exact = BigRational::from_integer(fl.clone()) == s;
        let k = if exact {
            fl
        } else {
            match self.round {
                FxRound::Floor => fl,
                FxRound::Ceil => fl + 1,
                FxRound::Trunc => {
                    if s.is_negative() {
                        fl + 1
                    } else {
                        fl
                    }
                }
                FxRound::NearestEven => {
                    let rem = &s - BigRational::from_integer(fl.clone());
                    let half = BigRational::new(BigInt::one(), BigInt::from(2));
                    if rem > half || (rem == half && (&fl % 2u32 != BigInt::zero())) {
                        fl + 1
                    } else {
                        fl
                    }
                }
            }
        };
        self.fit(k)
    }
    pub fn fit(&self, k: BigInt) -> i64 {
        let w = self.w();
        let max = (BigInt::one() << (w - 1)) - 1;
        let min = -(BigInt::one() << (w - 1));
        let r = match self.overflow {
            FxOverflow::Saturate => k.clamp(min, max),
            FxOverflow::Wrap => {
                let modulus = BigInt::one() << w;
                let mut r = ((k % &modulus) + &modulus) % &modulus;
                if r > max {
                    r -= modulus;
                }
                r
            }
        };
        r.try_into().unwrap()
    }
    pub fn op(&self, op: Op, a: i64, b: i64) -> i64 {
        let (x, y) = (self.value(a), self.value(b));
        match op {
            Op::Add => self.round(&(x + y)),
            Op::Sub => self.round(&(x - y)),
            Op::Mul => self.round(&(x * y)),
            Op::Div => {
                if b == 0 {
                    let w = self.w();
                    match a.signum() {
                        1 => ((1u64 << (w - 1)) - 1) as i64,
                        -1 => (-(BigInt::one() << (w - 1))).try_into().unwrap(),
                        _ => 0,
                    }
                } else {
                    self.round(&(x / y))
                }
            }
        }
    }
}
