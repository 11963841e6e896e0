//! A signed fixed-point format `qI.F` as SMT-LIB 2 bit-vectors: every operation is a pure
//! function of its operands' encodings (two's complement, `I + F` bits), written out as the
//! contract states it (`datapath::format::fixed`): the exact result formed in a wider
//! bit-vector, rounded once per the rounding mode, then saturated or wrapped.
//!
//! - `x ± y`: exact in `w + 1` bits, then the overflow rule.
//! - `x × y`: the exact product in `2w + 2` bits divided by `2^F`, rounded, then the overflow rule.
//! - `x ÷ y`: `(x·2^F) / y` rounded once (quotient and remainder in `w + F + 3` bits, the
//!   divisor's sign moved to the dividend), then the overflow rule; `y = 0` gives the most
//!   positive value for `x > 0`, the most negative for `x < 0` and 0 for `0 ÷ 0`; the
//!   recip-mul datapath forms `1 ÷ y` that way and multiplies.
//! - Rounding of `n / d` (`d > 0`, `q = floor(n / d)`, `r = n − q·d`): floor `q`; ceil `q + 1`
//!   when `r ≠ 0`; trunc `q + 1` when `r ≠ 0` and `n < 0`; nearest-even `q + 1` when
//!   `2r > d` or `2r = d` and `q` is odd.
//! - Compares are signed (`bvslt`, `bvsle`); there is no NaN, and the input read is the identity.

use super::ieee::bv;
use datapath::format::{DivMode, Fixed, FxOverflow, FxRound};
use datapath::Format;
use std::fmt::Write;

/// The SMT-LIB form of one fixed-point format with its datapath options.
#[derive(Clone, Copy, Debug)]
pub struct FixedSmt {
    /// Integer bits, sign included.
    pub int_bits: u32,
    /// Fraction bits.
    pub frac_bits: u32,
    /// Rounding of products and quotients.
    pub round: FxRound,
    /// Overflow rule.
    pub overflow: FxOverflow,
    /// Division mode.
    pub div: DivMode,
    /// The encoding of the datapath's 1 (saturated when 1 is out of range).
    pub one: u64,
}

impl FixedSmt {
    /// The SMT form of fixed-point format `x`.
    pub fn of(x: &Fixed) -> Self {
        Self {
            int_bits: x.int_bits,
            frac_bits: x.frac_bits,
            round: x.round,
            overflow: x.overflow,
            div: x.div,
            one: x.to_bits(x.one()),
        }
    }

    /// Width in bits.
    pub fn width(&self) -> u32 {
        self.int_bits + self.frac_bits
    }

    /// A literal encoding.
    pub fn lit(&self, x: u64) -> String {
        bv(x, self.width())
    }

    /// The bit-vector sort of one encoding.
    pub fn bv_sort(&self) -> String {
        format!("(_ BitVec {})", self.width())
    }

    fn max(&self) -> u64 {
        (1u64 << (self.width() - 1)) - 1
    }

    fn min(&self) -> u64 {
        1u64 << (self.width() - 1)
    }

    /// The widths of the exact intermediate results: sum, product, quotient.
    fn wide(&self) -> [u32; 3] {
        let w = self.width();
        [w + 1, 2 * w + 2, w + self.frac_bits + 3]
    }

    /// The helper functions every term of this format uses (`rp_` prefix).
    pub fn prelude(&self) -> String {
        let w = self.width();
        let f = self.frac_bits;
        let b = self.bv_sort();
        let (max, min, zero) = (self.lit(self.max()), self.lit(self.min()), self.lit(0));
        let mut s = String::new();
        let _ = writeln!(
            s,
            "; format q{}.{}: {w}-bit two's complement, value = encoding · 2^-{f}; rounding {:?}, overflow {:?}",
            self.int_bits, self.frac_bits, self.round, self.overflow
        );
        let _ = writeln!(s, "; no NaN; the input read and the operand read are the identity");
        let _ = writeln!(s, "(define-fun rp_isnan ((x {b})) Bool false)");
        let _ = writeln!(s, "(define-fun rp_flush ((x {b})) {b} x)");
        let _ = writeln!(s, "(define-fun rp_read ((x {b})) {b} x)");
        let _ = writeln!(s, "(define-fun rp_neg ((x {b})) Bool (bvslt x {zero}))");
        let _ = writeln!(s, "; signed compares");
        let _ = writeln!(s, "(define-fun rp_lt ((a {b}) (b {b})) Bool (bvslt a b))");
        let _ = writeln!(s, "(define-fun rp_le ((a {b}) (b {b})) Bool (bvsle a b))");
        let abs = match self.overflow {
            FxOverflow::Saturate => format!("(ite (= x {min}) {max} (ite (bvslt x {zero}) (bvneg x) x))"),
            FxOverflow::Wrap => format!("(ite (bvslt x {zero}) (bvneg x) x)"),
        };
        let _ = writeln!(s, "; |x| under the overflow rule (|most negative| saturates or wraps to itself)");
        let _ = writeln!(s, "(define-fun rp_abs ((x {b})) {b} {abs})");
        let _ = writeln!(s, "; one step up / down (held at the ends)");
        let _ = writeln!(s, "(define-fun rp_up ((x {b})) {b} (ite (= x {max}) x (bvadd x {})))", self.lit(1));
        let _ = writeln!(s, "(define-fun rp_down ((x {b})) {b} (ite (= x {min}) x (bvsub x {})))", self.lit(1));
        let _ = writeln!(s, "; the overflow rule on an exact wide result");
        let [ws, wm, wd] = self.wide();
        // one function per distinct width (the product's and the quotient's may coincide)
        let mut widths = vec![ws, wm, wd];
        widths.sort_unstable();
        widths.dedup();
        for &k in &widths {
            let ext = |lit: &str| format!("((_ sign_extend {}) {lit})", k - w);
            let low = format!("((_ extract {} 0) x)", w - 1);
            let body = match self.overflow {
                FxOverflow::Saturate => {
                    format!("(ite (bvsgt x {}) {max} (ite (bvslt x {}) {min} {low}))", ext(&max), ext(&min))
                }
                FxOverflow::Wrap => low,
            };
            let _ = writeln!(s, "(define-fun rp_fit{k} ((x (_ BitVec {k}))) {b} {body})");
        }
        let _ = writeln!(s, "; rounding n / d to an integer: q = floor(n / d), 0 <= r < d, n's sign");
        let mut rounded = vec![wm, wd];
        rounded.dedup();
        for k in rounded {
            let one = bv(1, k);
            let body = match self.round {
                FxRound::Floor => "q".to_string(),
                FxRound::Ceil => format!("(ite (= r {}) q (bvadd q {one}))", bv(0, k)),
                FxRound::Trunc => format!("(ite (and (not (= r {})) nlt0) (bvadd q {one}) q)", bv(0, k)),
                FxRound::NearestEven => format!(
                    "(let ((t (bvshl r {one}))) (ite (or (bvugt t d) (and (= t d) (= ((_ extract 0 0) q) #b1))) (bvadd q {one}) q))"
                ),
            };
            let _ = writeln!(
                s,
                "(define-fun rp_rnd{k} ((q (_ BitVec {k})) (r (_ BitVec {k})) (d (_ BitVec {k})) (nlt0 Bool)) (_ BitVec {k}) {body})"
            );
        }
        let sx = |k: u32, x: &str| format!("((_ sign_extend {}) {x})", k - w);
        let _ = writeln!(s, "; x ± y: exact in {ws} bits, then the overflow rule");
        let _ = writeln!(
            s,
            "(define-fun rp_add ((a {b}) (b {b})) {b} (rp_fit{ws} (bvadd {} {})))",
            sx(ws, "a"),
            sx(ws, "b")
        );
        let _ = writeln!(
            s,
            "(define-fun rp_sub ((a {b}) (b {b})) {b} (rp_fit{ws} (bvsub {} {})))",
            sx(ws, "a"),
            sx(ws, "b")
        );
        let _ = writeln!(s, "; x × y: the exact product / 2^{f}, rounded, then the overflow rule");
        let _ = writeln!(
            s,
            "(define-fun rp_mul ((a {b}) (b {b})) {b} (let ((p (bvmul {} {}))) (rp_fit{wm} (rp_rnd{wm} (bvashr p {}) (bvand p {}) {} (bvslt p {})))))",
            sx(wm, "a"),
            sx(wm, "b"),
            bv(f as u64, wm),
            lit_wide(wm, (1u128 << f) - 1),
            lit_wide(wm, 1u128 << f),
            bv(0, wm)
        );
        let _ = writeln!(
            s,
            "; x ÷ y: (x · 2^{f}) / y rounded once, then the overflow rule; y = 0 saturates by x's sign, 0 ÷ 0 = 0"
        );
        let z = bv(0, wd);
        let _ = writeln!(
            s,
            "(define-fun rp_div ((a {b}) (b {b})) {b} (let ((n0 (bvshl {} {})) (d0 {})) (let ((n (ite (bvslt d0 {z}) (bvneg n0) n0)) (d (ite (bvslt d0 {z}) (bvneg d0) d0))) (let ((qt (bvsdiv n d)) (rt (bvsrem n d))) (ite (= b {zero}) (ite (bvsgt a {zero}) {max} (ite (bvslt a {zero}) {min} {zero})) (rp_fit{wd} (rp_rnd{wd} (ite (bvslt rt {z}) (bvsub qt {}) qt) (ite (bvslt rt {z}) (bvadd rt d) rt) d (bvslt n {z}))))))))",
            sx(wd, "a"),
            bv(f as u64, wd),
            sx(wd, "b"),
            bv(1, wd)
        );
        let _ = writeln!(s, "; no slab guard in fixed point");
        let _ = writeln!(s, "(define-fun rp_grecip ((d {b}) (r {b})) Bool false)");
        let _ = writeln!(s, "(define-fun rp_gsub ((a {b}) (b {b}) (r {b})) Bool false)");
        s
    }

    /// Defines `name` as the result of `op` (`rp_add`, `rp_sub`, `rp_mul`, `rp_div`) on the
    /// operands' value terms.
    pub fn result(&self, out: &mut String, name: &str, op: &str, a: &str, b: &str) {
        let _ = writeln!(out, "(define-fun {name} () {} ({op} {a} {b}))", self.bv_sort());
    }

    /// Defines the terms of `name = a ÷ b` per the division mode (`name!q` the reciprocal in
    /// `recip` mode) and returns the term of the quotient.
    pub fn div(&self, out: &mut String, name: &str, a: &str, b: &str) -> String {
        match self.div {
            DivMode::Divide => self.result(out, &format!("{name}!r"), "rp_div", a, b),
            DivMode::RecipMul => {
                let q = format!("{name}!q");
                self.result(out, &q, "rp_div", &self.lit(self.one), b);
                self.result(out, &format!("{name}!r"), "rp_mul", a, &q);
            }
        }
        format!("{name}!r")
    }
}

/// A bit-vector literal of `k` bits (up to 128) of value `x`.
fn lit_wide(k: u32, x: u128) -> String {
    let digits: String = (0..k).rev().map(|i| if i < 128 && (x >> i) & 1 == 1 { '1' } else { '0' }).collect();
    format!("#b{digits}")
}

#[cfg(test)]
mod tests {
    use crate::smt::{emit, FormatSmt, Request, Unit};
    use datapath::AnyFormat;

    /// The emitted model is of the requested format: rounding, overflow, division and 1 as the
    /// format name states them (options included), and the logic is bit-vectors only.
    #[test]
    fn the_emitted_fixed_format_is_the_requested_one() {
        for name in ["q8.8", "q4.4:ceil+wrap+divide", "q1.15:trunc", "q16.16:nearest+wrap", "q32.32:divide"] {
            let format: AnyFormat = name.parse().unwrap();
            let AnyFormat::Fixed(f) = format else { unreachable!() };
            let req = Request {
                unit: Unit::Op,
                format,
                rti: Default::default(),
                variant: "plain".into(),
                widen: None,
                no_guard: false,
            };
            let m = emit(&req).unwrap();
            let FormatSmt::Fixed(x) = m.float else { panic!("{name}: not emitted as fixed point") };
            assert_eq!((x.round, x.overflow, x.div), (f.round, f.overflow, f.div), "{name}");
            use datapath::Format;
            assert_eq!(x.one, f.to_bits(f.one()), "{name}");
            assert!(m.text.contains("(set-logic QF_BV)") && !m.text.contains("FloatingPoint"), "{name}");
            assert_eq!(m.width, f.int_bits + f.frac_bits);
        }
    }
}
