//! An IEEE-like float format as SMT-LIB 2: encodings are bit-vectors of the format's width,
//! arithmetic goes through `FloatingPoint` terms rounded to nearest-even, and the contract's
//! input read, flush-to-zero, NaN and grid-step rules are written out as bit-vector functions.
//!
//! An arithmetic result is a declared bit-vector tied to its `FloatingPoint` value by
//! [`IeeeSmt::result`]: a NaN result is the contract's NaN encoding (canonical, or the first
//! NaN operand quieted under `propagate`), under FTZ a subnormal result is the zero of its
//! sign, and every other result is the unique encoding whose `to_fp` equals the value
//! (SMT-LIB's `=` on floats tells −0 from +0). SMT-LIB has no `fp.to_ieee_bv` in every
//! solver, so the tie is an assertion; it determines the bits uniquely.

use datapath::format::{DivMode, FloatLayout};
use std::fmt::Write;

/// The SMT-LIB form of one float format with its datapath options.
#[derive(Clone, Copy, Debug)]
pub struct IeeeSmt {
    /// Bit layout.
    pub lay: FloatLayout,
    /// Subnormal results and operands flush to zero.
    pub ftz: bool,
    /// NaN results carry the first NaN operand's payload, quieted.
    pub propagate: bool,
    /// Division mode.
    pub div: DivMode,
}

/// A bit-vector literal of `w` bits.
pub fn bv(x: u64, w: u32) -> String {
    if w.is_multiple_of(4) {
        format!("#x{:0width$x}", x, width = (w / 4) as usize)
    } else {
        format!("#b{:0width$b}", x, width = w as usize)
    }
}

impl IeeeSmt {
    /// Width in bits.
    pub fn width(&self) -> u32 {
        self.lay.width()
    }

    /// A literal encoding.
    pub fn lit(&self, x: u64) -> String {
        bv(x, self.width())
    }

    /// The `FloatingPoint` sort.
    pub fn fp_sort(&self) -> String {
        format!("(_ FloatingPoint {} {})", self.lay.exp_bits, self.lay.man_bits + 1)
    }

    /// The bit-vector sort of one encoding.
    pub fn bv_sort(&self) -> String {
        format!("(_ BitVec {})", self.width())
    }

    /// The helper functions every term of this format uses (`rp_` prefix).
    pub fn prelude(&self) -> String {
        let l = self.lay;
        let (w, m) = (l.width(), l.man_bits);
        let b = self.bv_sort();
        let f = self.fp_sort();
        let lit = |x| self.lit(x);
        let mut s = String::new();
        let exp = |x: &str| format!("((_ extract {} {}) {x})", w - 2, m);
        let man = |x: &str| format!("((_ extract {} 0) {x})", m - 1);
        let ones = bv((1 << l.exp_bits) - 1, l.exp_bits);
        let ezero = bv(0, l.exp_bits);
        let mzero = bv(0, m);
        let sign = lit(l.sign_mask());
        let cnan = lit(l.canonical_nan());
        let _ = writeln!(s, "; format {}: 1 sign, {} exponent, {} fraction bits", w, l.exp_bits, m);
        let _ = writeln!(s, "(define-fun rp_fp ((x {b})) {f} ((_ to_fp {} {}) x))", l.exp_bits, m + 1);
        let _ = writeln!(
            s,
            "(define-fun rp_isnan ((x {b})) Bool (and (= {} {ones}) (not (= {} {mzero}))))",
            exp("x"),
            man("x")
        );
        let _ =
            writeln!(s, "(define-fun rp_isinf ((x {b})) Bool (and (= {} {ones}) (= {} {mzero})))", exp("x"), man("x"));
        let _ = writeln!(
            s,
            "(define-fun rp_iszero ((x {b})) Bool (and (= {} {ezero}) (= {} {mzero})))",
            exp("x"),
            man("x")
        );
        let _ = writeln!(
            s,
            "(define-fun rp_issub ((x {b})) Bool (and (= {} {ezero}) (not (= {} {mzero}))))",
            exp("x"),
            man("x")
        );
        let _ = writeln!(s, "(define-fun rp_finite ((x {b})) Bool (not (= {} {ones})))", exp("x"));
        let _ = writeln!(s, "(define-fun rp_neg ((x {b})) Bool (= ((_ extract {} {}) x) #b1))", w - 1, w - 1);
        let _ = writeln!(s, "(define-fun rp_quiet ((x {b})) {b} (bvor x {}))", lit(1 << (m - 1)));
        // operand read inside every operation and compare: FTZ reads a subnormal as zero
        let flush = if self.ftz { format!("(ite (rp_issub x) (bvand x {sign}) x)") } else { "x".into() };
        let _ = writeln!(s, "; operand read (FTZ: a subnormal operand reads as the zero of its sign)");
        let _ = writeln!(s, "(define-fun rp_flush ((x {b})) {b} {flush})");
        // the stage-0 input read
        let nan_read = if self.propagate { "(rp_quiet x)".to_string() } else { cnan.clone() };
        let _ = writeln!(
            s,
            "; stage-0 input read: a NaN reads as the {}; numbers as the operand read",
            if self.propagate { "NaN quieted (payload and sign kept)" } else { "canonical NaN" }
        );
        let _ = writeln!(s, "(define-fun rp_read ((x {b})) {b} (ite (rp_isnan x) {nan_read} (rp_flush x)))");
        // the NaN a result takes
        let nanres = if self.propagate {
            format!("(ite (rp_isnan a) (rp_quiet a) (ite (rp_isnan b) (rp_quiet b) {cnan}))")
        } else {
            cnan.clone()
        };
        let _ = writeln!(
            s,
            "; NaN result: {}",
            if self.propagate { "the first NaN operand quieted, else the canonical NaN" } else { "the canonical NaN" }
        );
        let _ = writeln!(s, "(define-fun rp_nanres ((a {b}) (b {b})) {b} {nanres})");
        let ftz_res = if self.ftz {
            format!("(ite (fp.isSubnormal v) (= r (ite (fp.isNegative v) {sign} {})) (= (rp_fp r) v))", lit(0))
        } else {
            "(= (rp_fp r) v)".into()
        };
        let _ = writeln!(s, "; result write: r is the encoding of value v computed from operands a, b");
        let _ = writeln!(s, "(define-fun rp_res ((r {b}) (v {f}) (a {b}) (b {b})) Bool (ite (fp.isNaN v) (= r (rp_nanres a b)) {ftz_res}))");
        let _ = writeln!(s, "; IEEE ordered compares (false with a NaN, -0 == +0), on read operands");
        let _ =
            writeln!(s, "(define-fun rp_lt ((a {b}) (b {b})) Bool (fp.lt (rp_fp (rp_flush a)) (rp_fp (rp_flush b))))");
        let _ =
            writeln!(s, "(define-fun rp_le ((a {b}) (b {b})) Bool (fp.leq (rp_fp (rp_flush a)) (rp_fp (rp_flush b))))");
        let _ = writeln!(s, "(define-fun rp_abs ((x {b})) {b} (bvand x (bvnot {sign})))");
        // grid steps
        let minpos = if self.ftz { 1u64 << m } else { 1 };
        let one = lit(1);
        let up_core = format!("(ite (rp_iszero x) {} (ite (rp_neg x) (bvsub x {one}) (bvadd x {one})))", lit(minpos));
        let up_body = if self.ftz { format!("(let ((r {up_core})) (ite (rp_issub r) {sign} r))") } else { up_core };
        let _ = writeln!(s, "; nextUp / nextDown (NaN unchanged, nextUp(+inf) = +inf; FTZ skips the subnormals)");
        let _ = writeln!(
            s,
            "(define-fun rp_up ((x {b})) {b} (ite (or (rp_isnan x) (= x {})) x {up_body}))",
            lit(l.inf(false))
        );
        let _ = writeln!(
            s,
            "(define-fun rp_down ((x {b})) {b} (ite (rp_isnan x) x (bvxor (rp_up (bvxor x {sign})) {sign})))"
        );
        let _ = writeln!(s, "; the conservative slab guard");
        let _ = writeln!(s, "(define-fun rp_grecip ((d {b}) (r {b})) Bool (and (rp_finite d) (not (rp_iszero d)) (or (rp_isinf r) (rp_iszero r) (rp_issub r))))");
        let _ = writeln!(
            s,
            "(define-fun rp_gsub ((a {b}) (b {b}) (r {b})) Bool (and (rp_finite a) (rp_finite b) (rp_isinf r)))"
        );
        s
    }

    /// Declares `name` as the result of one rounded operation `op` (`fp.add`, `fp.sub`,
    /// `fp.mul`, `fp.div`) of encodings `a` and `b`, with its tying assertion. Each operand is
    /// (encoding, term taken as its value): an input's read (`rp_read in_x`) is taken as the
    /// input received (`in_x`) — the same value (a NaN read is still NaN, a flushed one flushes
    /// again to the same) — so a DUT that computes on the received encoding meets the same term.
    pub fn result(&self, out: &mut String, name: &str, op: &str, a: (&str, &str), b: (&str, &str)) {
        let _ = writeln!(out, "(declare-const {name} {})", self.bv_sort());
        let ((a, fa), (b, fb)) = (a, b);
        let _ = writeln!(
            out,
            "(assert (rp_res {name} ({op} RNE (rp_fp (rp_flush {fa})) (rp_fp (rp_flush {fb}))) {a} {b}))"
        );
    }

    /// The encoding of 1.
    pub fn one(&self) -> u64 {
        (self.lay.bias() as u64) << self.lay.man_bits
    }

    /// Declares the terms of `name = a ÷ b` per the division mode (`name!q` holds the
    /// reciprocal in `recip` mode) and returns the term of the quotient.
    /// Operands as in [`IeeeSmt::result`].
    pub fn div(&self, out: &mut String, name: &str, a: (&str, &str), b: (&str, &str)) -> String {
        match self.div {
            DivMode::Divide => {
                self.result(out, &format!("{name}!r"), "fp.div", a, b);
            }
            DivMode::RecipMul => {
                let one = self.lit(self.one());
                let q = format!("{name}!q");
                self.result(out, &q, "fp.div", (&one, &one), b);
                self.result(out, &format!("{name}!r"), "fp.mul", a, (&q, &q));
            }
        }
        format!("{name}!r")
    }
}
