//! The per-operation oracle: one operation of binary16, bfloat16 or binary32 on encodings,
//! computed by `rustc_apfloat` (LLVM's APFloat: arbitrary precision, correctly rounded,
//! round to nearest, ties to even), with the datapath's documented rules around it:
//!
//! * FTZ: a subnormal operand reads as zero of its sign; a subnormal result (after rounding)
//!   becomes zero of its sign;
//! * division by reciprocal (`recip_div`): a ÷ b is a × (1 ÷ b), each operation rounded (and
//!   flushed under FTZ) on its own;
//! * `Recip` is 1 ÷ b; `Lt` and `Le` are IEEE ordered comparisons (a NaN operand gives false,
//!   −0 equals +0), returned as 1 or 0; `Cmp` is both, (a < b) + 2 (a <= b).
//!
//! NaN results are returned as APFloat makes them; the caller judges them by the model's NaN
//! rule (the canonical rule: any NaN result must be the format's canonical NaN).

use rustc_apfloat::ieee::{BFloat, Half, Single};
use rustc_apfloat::{Float, Round};

/// The formats the oracle covers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OracleFormat {
    /// IEEE binary16.
    Binary16,
    /// bfloat16 (binary32's exponent, 7 fraction bits).
    BFloat16,
    /// IEEE binary32.
    Binary32,
}

/// An operation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OracleOp {
    /// a + b.
    Add,
    /// a − b.
    Sub,
    /// a × b.
    Mul,
    /// a ÷ b (by reciprocal when `recip_div`).
    Div,
    /// 1 ÷ b.
    Recip,
    /// a < b.
    Lt,
    /// a <= b.
    Le,
    /// Both comparisons as one result: (a < b) + 2 (a <= b).
    Cmp,
}

/// The rules around the IEEE operation.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OracleRules {
    /// Flush subnormal operands and results to zero of their sign.
    pub ftz: bool,
    /// Division is a reciprocal then a multiply.
    pub recip_div: bool,
}

/// `op(a, b)` on encodings of `fmt` under `rules`.
pub fn oracle_op(fmt: OracleFormat, rules: OracleRules, op: OracleOp, a: u64, b: u64) -> u64 {
    match fmt {
        OracleFormat::Binary16 => run::<Half>(rules, op, a, b),
        OracleFormat::BFloat16 => run::<BFloat>(rules, op, a, b),
        OracleFormat::Binary32 => run::<Single>(rules, op, a, b),
    }
}

fn flush<T: Float>(rules: OracleRules, x: T) -> T {
    if rules.ftz && x.is_denormal() {
        if x.is_negative() {
            -T::ZERO
        } else {
            T::ZERO
        }
    } else {
        x
    }
}

fn lt<T: Float>(x: T, y: T) -> bool {
    x.partial_cmp(&y) == Some(std::cmp::Ordering::Less)
}

fn le<T: Float>(x: T, y: T) -> bool {
    matches!(x.partial_cmp(&y), Some(std::cmp::Ordering::Less | std::cmp::Ordering::Equal))
}

fn run<T: Float>(rules: OracleRules, op: OracleOp, a: u64, b: u64) -> u64 {
    let r = Round::NearestTiesToEven;
    let (x, y) = (flush(rules, T::from_bits(a as u128)), flush(rules, T::from_bits(b as u128)));
    let one = T::from_u128(1).value;
    let recip = |y: T| flush(rules, one.div_r(y, r).value);
    let v = match op {
        OracleOp::Add => x.add_r(y, r).value,
        OracleOp::Sub => x.sub_r(y, r).value,
        OracleOp::Mul => x.mul_r(y, r).value,
        OracleOp::Div if rules.recip_div => x.mul_r(recip(y), r).value,
        OracleOp::Div => x.div_r(y, r).value,
        OracleOp::Recip => recip(y),
        OracleOp::Lt => return lt(x, y) as u64,
        OracleOp::Le => return le(x, y) as u64,
        OracleOp::Cmp => return lt(x, y) as u64 + 2 * le(x, y) as u64,
    };
    flush(rules, v).to_bits() as u64
}

#[cfg(test)]
mod tests {
    use super::*;
    use OracleFormat::*;
    use OracleOp::*;

    #[test]
    fn hand_checked_results() {
        let d = OracleRules::default();
        // binary16 ulp(1) = 2^-10: 1 + 2^-11 (0x1000) is a tie, to even (1.0); 1 + 3·2^-12
        // (0x1200) rounds up to 1 + 2^-10; 1 + 3·2^-11 (0x1600) is a tie, to even (1 + 2^-9)
        assert_eq!(oracle_op(Binary16, d, Add, 0x3c00, 0x1000), 0x3c00);
        assert_eq!(oracle_op(Binary16, d, Add, 0x3c00, 0x1200), 0x3c01);
        assert_eq!(oracle_op(Binary16, d, Add, 0x3c00, 0x1600), 0x3c02);
        // 1 / 3 in binary32 and bfloat16
        assert_eq!(oracle_op(Binary32, d, Div, 0x3f80_0000, 0x4040_0000), 0x3eaa_aaab);
        assert_eq!(oracle_op(BFloat16, d, Recip, 0, 0x4040), 0x3eab);
        // the smallest binary16 subnormal: kept, or flushed under FTZ (operand and result)
        assert_eq!(oracle_op(Binary16, d, Mul, 0x0001, 0x3c00), 0x0001);
        let ftz = OracleRules { ftz: true, ..d };
        assert_eq!(oracle_op(Binary16, ftz, Mul, 0x0001, 0x3c00), 0x0000);
        assert_eq!(oracle_op(Binary16, ftz, Mul, 0x8400, 0x3800), 0x8000); // −min normal / 2
                                                                           // comparisons: NaN false, −0 == +0
        assert_eq!(oracle_op(Binary16, d, Le, 0x8000, 0x0000), 1);
        assert_eq!(oracle_op(Binary16, d, Lt, 0x8000, 0x0000), 0);
        assert_eq!(oracle_op(Binary16, d, Le, 0x7e00, 0x7e00), 0);
        assert_eq!(oracle_op(Binary16, d, Cmp, 0x3c00, 0x4000), 3); // 1 < 2
        assert_eq!(oracle_op(Binary16, d, Cmp, 0x4000, 0x4000), 2); // 2 <= 2
        assert_eq!(oracle_op(Binary16, d, Cmp, 0x7e00, 0x4000), 0); // NaN
                                                                    // 5 / 3 by reciprocal: 5 × RN(1/3) is one ulp below RN(5/3) in binary16; 11 / 11 is
                                                                    // 1 - 2^-11 (checked with Python's struct 'e' packing)
        let rd = OracleRules { recip_div: true, ..d };
        assert_eq!(oracle_op(Binary16, d, Div, 0x4500, 0x4200), 0x3eab);
        assert_eq!(oracle_op(Binary16, rd, Div, 0x4500, 0x4200), 0x3eaa);
        assert_eq!(oracle_op(Binary16, rd, Div, 0x4980, 0x4980), 0x3bff);
    }
}
