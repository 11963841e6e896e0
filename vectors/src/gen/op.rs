//! The op unit's vectors: single operations on special and random operands, rounding ties,
//! and the expected result and flag rows.

use datapath::fault::{Fault, NoFault};
use datapath::format::FormatKind;
use datapath::rng::SplitMix64;
use datapath::rti::Op;
use datapath::Format;

pub(crate) const OP_CLASSES: [(&str, &str); 4] = [
    ("special", "TestFloat level 1: every pair of special operands (zeros, subnormals, min/max normal, one, all-ones significands, inf, NaN; fixed: extremes and one)"),
    ("random", "uniform random operand bits"),
    ("ties", "floats, add, sub and mul: operand pairs whose exact result lies exactly halfway between two format values (add / sub: a random value in [1, 2) and an odd multiple of its half step below 2^-4; mul: odd significands of na = floor((p + 2) / 2) and p + 2 - na bits whose product has p + 1 bits), found by drawing and checking the exact result in binary64 (p <= 24)"),
    ("special_x_random", "level 2: each special operand against random operands, on either side"),
];

/// Op codes of the `op` unit.
pub const OPCODES: [&str; 6] = ["add", "sub", "mul", "div", "lt", "le"];

pub(crate) fn op_text(op: Op, a: &str, b: &str, note: &str) -> String {
    match op {
        Op::Sub => format!("{a} - {b}"),
        Op::Add => format!("{a} + {b}"),
        Op::Mul => format!("{a} * {b}"),
        Op::Div => format!("{a} / {b}"),
        Op::Logic => note.to_string(),
    }
}

/// The op unit's result of opcode `op` (0 add, 1 sub, 2 mul, 3 div, 4 lt, 5 le) on x and y: (result bits, compare bit).
pub fn op_eval<F: Format>(f: &F, op: u64, x: F::V, y: F::V) -> (u64, u64) {
    op_eval_faulty(f, op, x, y, &NoFault)
}

/// One op-unit vector with its site (the op code's name: `add`, `sub`, `mul`, `div`, `lt`,
/// `le`) computed by `x`: (result, cmp).
pub(crate) fn op_eval_faulty<F: Format, X: Fault<F>>(f: &F, op: u64, a: F::V, b: F::V, x: &X) -> (u64, u64) {
    use datapath::fault::Cmp;
    match op {
        0 => (f.to_bits(x.arith(f, "add", Op::Add, a, b)), 0),
        1 => (f.to_bits(x.arith(f, "sub", Op::Sub, a, b)), 0),
        2 => (f.to_bits(x.arith(f, "mul", Op::Mul, a, b)), 0),
        3 => (f.to_bits(x.arith(f, "div", Op::Div, a, b)), 0),
        4 => (0, x.compare(f, "lt", Cmp::Lt, a, b) as u64),
        _ => (0, x.compare(f, "le", Cmp::Le, a, b) as u64),
    }
}

/// The expected row (result, cmp) of one op vector (`bits`: op code, a, b) with its site
/// computed by `x` (`NoFault`: the row a set holds); the op unit has no stage file.
pub fn op_out_rows<F: Format, X: Fault<F>>(f: &F, bits: &[u64], x: &X) -> [Vec<u64>; 2] {
    let (res, cmp) = op_eval_faulty(f, bits[0], f.from_bits(bits[1]), f.from_bits(bits[2]), x);
    [vec![res, cmp], Vec::new()]
}

/// Up to `count` operand pairs (encodings) of op code `op` (0 add, 1 sub, 2 mul) whose exact
/// result lies exactly halfway between two values of float format `f` (p ≤ 24: the exact
/// result is a binary64 value), each checked: the exact result differs from its rounding by
/// exactly half the rounded value's step. None for other formats (at most 64 draws per pair).
pub(crate) fn op_ties<F: Format>(f: &F, op: u64, count: usize, r: &mut SplitMix64) -> Vec<(u64, u64)> {
    let FormatKind::Float(l) = f.kind() else { return Vec::new() };
    if l.man_bits > 23 {
        return Vec::new();
    }
    let p = l.man_bits as i32 + 1;
    // ± an odd integer of n bits over 2^(n-1): in [1, 2)
    let odd = |n: i32, r: &mut SplitMix64| {
        let v = ((1u64 << (n - 1)) + r.below(1u64 << (n - 1))) | 1;
        let s = if r.below(2) == 0 { 1.0 } else { -1.0 };
        s * v as f64 / ((n - 1) as f64).exp2()
    };
    let mut out = Vec::new();
    for _ in 0..count * 64 {
        if out.len() == count {
            break;
        }
        let (a, b) = match op {
            2 => {
                // odd significands of na and nb bits, na + nb = p + 2: a product of p + 1 bits
                // (about half the draws) is odd, so exactly halfway
                let na = (p + 2) / 2;
                (odd(na, r), odd(p + 2 - na, r))
            }
            _ => {
                let a = f.to_f64(f.from_f64(r.range(1.0, 2.0)));
                let half = (-(p as f64)).exp2();
                let k = (2 * r.below(1u64 << (p - 4).clamp(1, 8)) + 1) as f64;
                (a, if r.below(2) == 0 { k * half } else { -k * half })
            }
        };
        let (fa, fb) = (f.from_f64(a), f.from_f64(b));
        if f.to_f64(fa) != a || f.to_f64(fb) != b {
            continue;
        }
        let exact = match op {
            0 => a + b,
            1 => a - b,
            _ => a * b,
        };
        let rounded = f.to_f64(f.from_f64(exact));
        if exact.is_finite() && rounded != 0.0 && (exact - rounded).abs() == f.ulp(rounded) / 2.0 {
            out.push((f.to_bits(fa), f.to_bits(fb)));
        }
    }
    out
}
