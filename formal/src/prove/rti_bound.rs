//! `rti-bound`: the RTI error bound (`datapath::bound`) holds for every finite input of a small
//! float format (fp16 and every `eEmM` of at most 16 bits whose values fit the exact check).
//!
//! **Lemma (per operation, by exhaustive enumeration of the model's own operations).** Let
//! `u = 2^-p` and `η = 2^-q` be the format's error model (`u` its unit roundoff, `η` half its
//! smallest subnormal step; `add_eta` 0 under gradual underflow) and `ρ = 1 − 2^-MARGIN_BITS`.
//! For every pair of finite operands whose model result is finite:
//! - `add`, `sub`: `|x ⊕ y − (x ± y)| <= ρ·(u·|x ± y| + add_eta)`;
//! - `mul`: `|x ⊗ y − x·y| <= ρ·(u·|x·y| + η)`;
//! - `recip` (the recip-mul datapath's `1 ⊘ d`): `|1 ⊘ d − 1/d| <= ρ·(u/|d| + η)`;
//! - `div` (the divide datapath's `n ⊘ d`): `|n ⊘ d − n/d| <= ρ·(u·|n/d| + η)`.
//!
//! Every value of a covered format is an integer multiple `k·2^-s` of its smallest subnormal
//! step with `|k| < 2^kbits`, so each inequality is checked exactly on 128-bit integers after
//! multiplying both sides by a power of two (the recip and div forms are multiplied by `|d|`).
//!
//! **Composition** (written: docs/proofs.md, "rti-bound"). The bound mirrors the stage table
//! row for row ([`COMPOSED_ROWS`], checked against `datapath::rti::stage_table`); by induction
//! over the rows, the lemma and the triangle inequality give `|model − exact| <= ρ·E` for every
//! signal, `E` the documented bound evaluated in real arithmetic; the margin `1 − ρ` and
//! `F64_SLACK` cover its binary64 evaluation in the judge.

use datapath::format::{DivMode, ErrorModel, FloatLayout, FormatKind};
use datapath::stage::Op;
use datapath::Format;

/// Every operation's error is at most `1 − 2^-MARGIN_BITS` of its term (the margin the
/// binary64 evaluation of the bound needs, docs/proofs.md).
pub const MARGIN_BITS: u32 = 20;

/// The arithmetic rows (stage, name, op, a, b) the composition is written for, both division
/// modes (the last three rows of each mode apart); checked against the stage table at run time.
pub const COMPOSED_ROWS: &[(u8, &str, Op, &str, &str)] = &[
    (1, "e1x", Op::Sub, "v1x", "v0x"),
    (1, "e1y", Op::Sub, "v1y", "v0y"),
    (1, "e1z", Op::Sub, "v1z", "v0z"),
    (1, "e2x", Op::Sub, "v2x", "v0x"),
    (1, "e2y", Op::Sub, "v2y", "v0y"),
    (1, "e2z", Op::Sub, "v2z", "v0z"),
    (1, "sx", Op::Sub, "ox", "v0x"),
    (1, "sy", Op::Sub, "oy", "v0y"),
    (1, "sz", Op::Sub, "oz", "v0z"),
    (2, "pxa", Op::Mul, "dy", "e2z"),
    (2, "pxb", Op::Mul, "dz", "e2y"),
    (2, "pya", Op::Mul, "dz", "e2x"),
    (2, "pyb", Op::Mul, "dx", "e2z"),
    (2, "pza", Op::Mul, "dx", "e2y"),
    (2, "pzb", Op::Mul, "dy", "e2x"),
    (2, "qxa", Op::Mul, "sy", "e1z"),
    (2, "qxb", Op::Mul, "sz", "e1y"),
    (2, "qya", Op::Mul, "sz", "e1x"),
    (2, "qyb", Op::Mul, "sx", "e1z"),
    (2, "qza", Op::Mul, "sx", "e1y"),
    (2, "qzb", Op::Mul, "sy", "e1x"),
    (3, "px", Op::Sub, "pxa", "pxb"),
    (3, "py", Op::Sub, "pya", "pyb"),
    (3, "pz", Op::Sub, "pza", "pzb"),
    (3, "qx", Op::Sub, "qxa", "qxb"),
    (3, "qy", Op::Sub, "qya", "qyb"),
    (3, "qz", Op::Sub, "qza", "qzb"),
    (4, "detx", Op::Mul, "e1x", "px"),
    (4, "dety", Op::Mul, "e1y", "py"),
    (4, "detz", Op::Mul, "e1z", "pz"),
    (4, "upx", Op::Mul, "sx", "px"),
    (4, "upy", Op::Mul, "sy", "py"),
    (4, "upz", Op::Mul, "sz", "pz"),
    (4, "vpx", Op::Mul, "dx", "qx"),
    (4, "vpy", Op::Mul, "dy", "qy"),
    (4, "vpz", Op::Mul, "dz", "qz"),
    (4, "tpx", Op::Mul, "e2x", "qx"),
    (4, "tpy", Op::Mul, "e2y", "qy"),
    (4, "tpz", Op::Mul, "e2z", "qz"),
    (5, "det_xy", Op::Add, "detx", "dety"),
    (5, "up_xy", Op::Add, "upx", "upy"),
    (5, "vp_xy", Op::Add, "vpx", "vpy"),
    (5, "tp_xy", Op::Add, "tpx", "tpy"),
    (6, "det", Op::Add, "det_xy", "detz"),
    (6, "up", Op::Add, "up_xy", "upz"),
    (6, "vp", Op::Add, "vp_xy", "vpz"),
    (6, "tp", Op::Add, "tp_xy", "tpz"),
    (7, "uv", Op::Add, "up", "vp"),
];

/// The division rows the composition is written for, per division mode.
pub fn composed_division(div: DivMode) -> &'static [(u8, &'static str, Op, &'static str, &'static str)] {
    match div {
        DivMode::RecipMul => &[
            (8, "inv_det", Op::Div, "one", "det"),
            (9, "t", Op::Mul, "tp", "inv_det"),
            (9, "u", Op::Mul, "up", "inv_det"),
            (9, "v", Op::Mul, "vp", "inv_det"),
        ],
        DivMode::Divide => {
            &[(8, "t", Op::Div, "tp", "det"), (8, "u", Op::Div, "up", "det"), (8, "v", Op::Div, "vp", "det")]
        }
    }
}

/// Checks that the stage table's arithmetic rows are exactly the rows the composition is
/// written for (the proof is about this table: a changed row must change the proof).
pub fn check_table(div: DivMode) -> Result<(), String> {
    let table: Vec<(u8, &str, Op, &str, &str)> = datapath::rti::stage_table(div)
        .iter()
        .filter(|r| r.op != Op::Logic)
        .map(|r| (r.stage, r.name, r.op, r.a, r.b))
        .collect();
    let want: Vec<(u8, &str, Op, &str, &str)> = COMPOSED_ROWS.iter().chain(composed_division(div)).copied().collect();
    if table != want {
        let first = table.iter().zip(&want).position(|(a, b)| a != b).unwrap_or(table.len().min(want.len()));
        return Err(format!(
            "the RTI stage table differs from the rows the rti-bound composition is written for (row {first}: table {:?}, proof {:?})",
            table.get(first),
            want.get(first)
        ));
    }
    Ok(())
}

/// A change to the error model the proof must refute.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mutant {
    /// The documented bound.
    None,
    /// η = 0: the underflow term of a multiply or divide dropped.
    NoEta,
    /// u/16: a sixteenth of the unit roundoff.
    USixteenth,
}

impl Mutant {
    /// Parses a mutant's name (`no-eta`, `u-sixteenth`).
    pub fn parse(s: &str) -> Result<Self, String> {
        match s {
            "no-eta" => Ok(Self::NoEta),
            "u-sixteenth" => Ok(Self::USixteenth),
            _ => Err(format!("unknown rti-bound mutant '{s}'; mutants: no-eta, u-sixteenth")),
        }
    }
    /// The error model with this change.
    pub fn apply(self, em: ErrorModel) -> ErrorModel {
        match self {
            Self::None => em,
            Self::NoEta => ErrorModel { eta: 0.0, ..em },
            Self::USixteenth => ErrorModel { u: em.u / 16.0, ..em },
        }
    }
}

/// The exponent `k` of an exact power of two `2^k`.
fn log2_exact(x: f64) -> Option<i32> {
    (x > 0.0 && x.is_finite() && x.to_bits() & ((1u64 << 52) - 1) == 0 && x.is_normal())
        .then(|| ((x.to_bits() >> 52) as i32) - 1023)
}

/// The integer scaling of a covered format: values are `k·2^-s`, `|k| < 2^kbits`; `u = 2^-p`,
/// `η = 2^-q` (None: 0), `add_eta = 2^-qa` (None: 0).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Scale {
    /// Exponent of the smallest subnormal step: values are `k·2^-s`.
    pub s: u32,
    /// Bits of the largest `|k|`.
    pub kbits: u32,
    /// `u = 2^-p`.
    pub p: u32,
    /// `η = 2^-q`, or 0.
    pub q: Option<u32>,
    /// `add_eta = 2^-qa`, or 0.
    pub qa: Option<u32>,
}

/// Whether the proof covers format `f` with error model `em`, and its integer scaling; or why not.
pub fn covers<F: Format>(f: &F, em: ErrorModel) -> Result<Scale, String> {
    let l = match f.kind() {
        FormatKind::Float(l) if l.width() <= 16 => l,
        FormatKind::Float(l) => {
            return Err(format!(
                "{}: rti-bound enumerates every operand pair, for floats of at most 16 bits (this has {})",
                f.name(),
                l.width()
            ))
        }
        FormatKind::Fixed { .. } => return Err(format!("{}: rti-bound covers float formats", f.name())),
    };
    if f.flushes() {
        return Err(format!(
            "{}: under flush-to-zero a subnormal input reads as zero, so the bound's inputs are not the model's: not covered",
            f.name()
        ));
    }
    let s = (l.man_bits as i32 - l.emin()) as u32;
    // the largest |k|: max_finite · 2^s < 2^(emax + 1 + s)
    let kbits = (l.emax() + 1) as u32 + s;
    let pow = |x: f64, what: &str| -> Result<Option<u32>, String> {
        if x == 0.0 {
            return Ok(None);
        }
        match log2_exact(x) {
            Some(k) if k < 0 => Ok(Some((-k) as u32)),
            _ => Err(format!("{}: the error model's {what} ({x:e}) is not a negative power of two", f.name())),
        }
    };
    let p = pow(em.u, "u")?.ok_or(format!("{}: the error model's u is 0", f.name()))?;
    let q = pow(em.eta, "eta")?;
    let qa = pow(em.add_eta, "add_eta")?;
    let sc = Scale { s, kbits, p, q, qa };
    // every scaled product and bound in 128 bits, and an input difference exact in binary64
    if 2 * kbits + p + MARGIN_BITS + 4 > 126
        || kbits + 1 > 53
        || p > 30
        || q.is_some_and(|q| q > s + p)
        || qa.is_some_and(|q| q > s + p)
    {
        return Err(format!(
            "{}: the exact check covers formats whose values are k·2^-s with 2·bits(k) + p + {MARGIN_BITS} + 4 <= 126 (this has bits(k) = {kbits}, p = {p})",
            f.name()
        ));
    }
    // a non-finite model value raises the judge's overflow flag (docs/proofs.md, step 1):
    // 224·2^-53·max² < u (the format's own u: a mutant changes only the lemma)
    let u0 = f.error_model().u;
    if 224.0 * (-53f64).exp2() * l.max_finite() * l.max_finite() >= u0 {
        return Err(format!(
            "{}: the overflow argument needs 224·2^-53·max² < u (max {:e}, u {:e})",
            f.name(),
            l.max_finite(),
            u0
        ));
    }
    Ok(sc)
}

/// An operation of the RTI datapath whose rounding the lemma bounds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum LemmaOp {
    Add,
    Sub,
    Mul,
    /// `1 ⊘ d` (the recip-mul datapath).
    Recip,
    /// `n ⊘ d` (the divide datapath).
    Div,
}

impl LemmaOp {
    fn name(self) -> &'static str {
        match self {
            Self::Add => "add",
            Self::Sub => "sub",
            Self::Mul => "mul",
            Self::Recip => "recip",
            Self::Div => "div",
        }
    }
}

/// One operation's lemma over every operand pair.
#[derive(Clone, Debug, PartialEq)]
pub struct OpLemma {
    /// `add`, `sub`, `mul`, `recip` or `div`.
    pub op: &'static str,
    /// The inequality, in words.
    pub statement: String,
    /// Operand pairs with a finite result, checked (None when a violation stopped the search).
    pub cases: Option<u64>,
    /// Operand pairs whose result is not finite (no claim; the bound flags them as overflow).
    pub overflowed: Option<u64>,
    /// The largest ratio error / term over the pairs checked, with its operands' encodings.
    pub worst: Option<(f64, u64, u64)>,
    /// The first violation in operand order: the operands' and the result's encodings.
    pub violation: Option<[u64; 3]>,
}

/// Per-thread tally of one operation.
#[derive(Default)]
struct Tally {
    cases: u64,
    overflowed: u64,
    worst: Option<(f64, u64, u64)>,
    violation: Option<[u64; 3]>,
}

/// The binary64 filter's factor: a pair with `err_f <= FILTER·term_f` (both evaluated in
/// binary64 from the exact operand values) satisfies the lemma; every other pair is decided by
/// the exact check. Sound: with `z_f = fl(x ∘ y)`, `|z_f − z| <= 2^-53·|z|`; `err_f` and
/// `term_f = fl(u·|z_f| + η)` are each within a relative 2^-52 of `|r − z_f|` and
/// `u·|z_f| + η`; so `err <= err_f·(1 + 2^-52) + 2^-52·|z|` and `|z| <= term/u = 2^p·term`,
/// `term_f <= term·(1 + 2^-51)`, giving `err <= term·(1 − 2^-19 + 2^-50 + 2^(p−52))`, which is
/// at most `(1 − 2^-20)·term` for `p <= 30` (checked by [`covers`]).
const FILTER: f64 = 1.0 - 1.0 / (1u64 << 19) as f64;

/// Checks `err ≤ ρ·term` exactly: `err·2^m ≤ term·(2^m − 1)`.
#[inline(always)]
fn within(err: u128, term: u128) -> bool {
    (err << MARGIN_BITS) <= term * ((1u128 << MARGIN_BITS) - 1)
}

/// The scaled error and term of `op` on operands `ka`, `kb` with result `kr` (all `k·2^-s`),
/// both multiplied by the same positive power of two (`u·term` made an integer).
#[inline(always)]
fn scaled(op: LemmaOp, sc: Scale, ka: i64, kb: i64, kr: i64) -> (u128, u128) {
    let (s, p) = (sc.s, sc.p);
    let (ka, kb, kr) = (ka as i128, kb as i128, kr as i128);
    // η·2^(2s+p) and add_eta·2^(s+p) as integers (0 when the term is 0)
    let eta2 = sc.q.map_or(0, |q| 1i128 << (2 * s + p - q));
    let eta1 = sc.q.map_or(0, |q| 1i128 << (s + p - q));
    let add1 = sc.qa.map_or(0, |q| 1i128 << (s + p - q));
    let (err, term) = match op {
        // scale 2^-s; ×2^p: |kr − K|·2^p ≤ ρ·(|K| + add_eta·2^(s+p))
        LemmaOp::Add | LemmaOp::Sub => {
            let k = if op == LemmaOp::Add { ka + kb } else { ka - kb };
            ((kr - k).abs() << p, k.abs() + add1)
        }
        // scale 2^-2s; ×2^p
        LemmaOp::Mul => {
            let k = ka * kb;
            (((kr << s) - k).abs() << p, k.abs() + eta2)
        }
        // |1 ⊘ d − 1/d| ≤ ρ(u/|d| + η), times |d|: |r·d − 1| ≤ ρ(u + η|d|); scale 2^-2s; ×2^p
        LemmaOp::Recip => ((kr * kb - (1i128 << (2 * s))).abs() << p, (1i128 << (2 * s)) + eta1 * kb.abs()),
        // |n ⊘ d − n/d| ≤ ρ(u|n/d| + η), times |d|: |r·d − n| ≤ ρ(u|n| + η|d|)
        LemmaOp::Div => ((kr * kb - (ka << s)).abs() << p, (ka.abs() << s) + eta1 * kb.abs()),
    };
    (err as u128, term as u128)
}

/// The lemma's statement for `op`, in words.
fn statement(op: LemmaOp) -> String {
    let rho = format!("(1 − 2^-{MARGIN_BITS})");
    match op {
        LemmaOp::Add => format!("|x ⊕ y − (x + y)| ≤ {rho}·(u·|x + y| + add_eta)"),
        LemmaOp::Sub => format!("|x ⊖ y − (x − y)| ≤ {rho}·(u·|x − y| + add_eta)"),
        LemmaOp::Mul => format!("|x ⊗ y − x·y| ≤ {rho}·(u·|x·y| + η)"),
        LemmaOp::Recip => format!("|1 ⊘ d − 1/d| ≤ {rho}·(u/|d| + η)"),
        LemmaOp::Div => format!("|n ⊘ d − n/d| ≤ {rho}·(u·|n/d| + η)"),
    }
}

/// Checks the lemma of every operation the RTI datapath of `f` uses (add, sub, mul, and recip
/// or div per its division mode) under error model `em`, on `threads` threads (the result does
/// not depend on them).
pub fn enumerate<F: Format>(f: &F, em: ErrorModel, threads: usize) -> Result<Vec<OpLemma>, String> {
    enumerate_with(f, em, threads, FILTER)
}

/// [`enumerate`] with the binary64 filter's factor `filter` (negative: every pair decided exactly).
fn enumerate_with<F: Format>(f: &F, em: ErrorModel, threads: usize, filter: f64) -> Result<Vec<OpLemma>, String> {
    let sc = covers(f, em)?;
    let FormatKind::Float(l) = f.kind() else { unreachable!() };
    let n = 1u64 << l.width();
    // every encoding's k (finite ones), by encoding
    let scale = (sc.s as f64).exp2();
    let ks: Vec<Option<i64>> = (0..n)
        .map(|b| {
            let x = f.to_f64(f.from_bits(b));
            x.is_finite().then_some((x * scale) as i64)
        })
        .collect();
    let finite: Vec<(u64, F::V, i64)> = (0..n).filter_map(|b| ks[b as usize].map(|k| (b, f.from_bits(b), k))).collect();
    use LemmaOp::{Add, Div, Mul, Recip, Sub};
    let ops = match f.div_mode() {
        DivMode::RecipMul => [Add, Sub, Mul, Recip],
        DivMode::Divide => [Add, Sub, Mul, Div],
    };
    let one = f.one();
    let k_one = 1i64 << sc.s;
    let threads = threads.max(1);
    let inv = 1.0 / scale;
    let u = em.u;
    let mut out = Vec::new();
    for op in ops {
        let eta_op = if matches!(op, Add | Sub) { em.add_eta } else { em.eta };
        // the first operand's list: recip has one operand (the divisor, as b)
        let firsts: Vec<(u64, F::V, i64)> =
            if op == Recip { vec![(f.to_bits(one), one, k_one)] } else { finite.clone() };
        let chunk = firsts.len().div_ceil(threads).max(1);
        let tallies: Vec<Tally> = std::thread::scope(|sc_| {
            let hs: Vec<_> = firsts
                .chunks(chunk)
                .map(|part| {
                    let (finite, ks) = (&finite, &ks);
                    sc_.spawn(move || {
                        let mut t = Tally::default();
                        for &(ab, av, ka) in part {
                            for &(bb, bv, kb) in finite {
                                let r = match op {
                                    Add => f.add(av, bv),
                                    Sub => f.sub(av, bv),
                                    Mul => f.mul(av, bv),
                                    Recip | Div => f.div(av, bv),
                                };
                                let rb = f.to_bits(r);
                                let Some(kr) = ks[rb as usize] else {
                                    if l.is_nan(rb) && !matches!(op, Recip | Div) {
                                        // finite operands never give NaN in add, sub, mul
                                        t.violation = Some([ab, bb, rb]);
                                        return t;
                                    }
                                    t.overflowed += 1;
                                    continue;
                                };
                                // the binary64 filter (sound: see FILTER), then the exact check
                                let (xa, xb) = (ka as f64 * inv, kb as f64 * inv);
                                let z = match op {
                                    Add => xa + xb,
                                    Sub => xa - xb,
                                    Mul => xa * xb,
                                    Recip | Div => xa / xb,
                                };
                                let err_f = (kr as f64 * inv - z).abs();
                                let term_f = u * z.abs() + eta_op;
                                if err_f > term_f * filter {
                                    let (err, term) = scaled(op, sc, ka, kb, kr);
                                    if !within(err, term) {
                                        t.violation = Some([ab, bb, rb]);
                                        return t;
                                    }
                                }
                                t.cases += 1;
                                if err_f > 0.0 {
                                    let ratio = err_f / term_f;
                                    if t.worst.is_none_or(|w| ratio > w.0) {
                                        t.worst = Some((ratio, ab, bb));
                                    }
                                }
                            }
                        }
                        t
                    })
                })
                .collect();
            hs.into_iter().map(|h| h.join().expect("enumeration thread")).collect()
        });
        let violation = tallies.iter().find_map(|t| t.violation);
        let mut worst: Option<(f64, u64, u64)> = None;
        for t in &tallies {
            if let Some(w) = t.worst {
                if worst.is_none_or(|m| w.0 > m.0) {
                    worst = Some(w);
                }
            }
        }
        let (cases, overflowed) = if violation.is_some() {
            (None, None)
        } else {
            (Some(tallies.iter().map(|t| t.cases).sum()), Some(tallies.iter().map(|t| t.overflowed).sum()))
        };
        out.push(OpLemma {
            op: op.name(),
            statement: statement(op),
            cases,
            overflowed,
            worst: if violation.is_some() { None } else { worst },
            violation,
        });
    }
    Ok(out)
}

/// One RTI input: origin, direction, the three vertices (the format's values in binary64).
pub type Input = ([f64; 3], [f64; 3], [[f64; 3]; 3]);

/// A whole input breaking the bound, with each quantity's check.
pub type Witness = (Input, Vec<Checked>);

/// The RTI input that isolates one multiply: `v0 = 0`, `v1 = (−1, 0, 0)`, `v2 = (0, y, 0)`,
/// `o = (0, 0, x)`, `d = (0, 0, 1)`; then det = y and u' = v' = 0 exactly, and t' = e2·(s × e1)
/// is computed as `y ⊗ (−x)` with every other operation exact; returns (origin, direction,
/// vertices) as the format's values.
pub fn isolating_input(x: f64, y: f64) -> Input {
    ([0.0, 0.0, x], [0.0, 0.0, 1.0], [[0.0; 3], [-1.0, 0.0, 0.0], [0.0, y, 0.0]])
}

/// A whole RTI input breaking the bound under `em`, searched from the multiplies that break the
/// lemma by more than 4× their term: det = y over the values in [1, 2) in encoding order, x over
/// every finite value; at most 4096 inputs are checked exactly. Deterministic.
pub fn find_witness<F: Format>(f: &F, em: ErrorModel) -> Option<Witness> {
    let sc = covers(f, em).ok()?;
    let l = layout(f)?;
    let scale = (sc.s as f64).exp2();
    let finite: Vec<(F::V, f64)> = (0..1u64 << l.width())
        .map(|b| f.from_bits(b))
        .map(|v| (v, f.to_f64(v)))
        .filter(|(_, x)| x.is_finite())
        .collect();
    let mut full = 0;
    for &(yv, y) in finite.iter().filter(|(_, y)| (1.0..2.0).contains(y)) {
        for &(xv, x) in &finite {
            let r = f.to_f64(f.mul(xv, yv));
            if !r.is_finite() {
                continue;
            }
            let (err, term) = scaled(LemmaOp::Mul, sc, (x * scale) as i64, (y * scale) as i64, (r * scale) as i64);
            if err <= 4 * term {
                continue;
            }
            let (o, d, v) = isolating_input(x, y);
            if let Some(c) = check_input(f, em, o, d, v) {
                if c.iter().any(|c| !c.holds) {
                    return Some(((o, d, v), c));
                }
            }
            full += 1;
            if full >= 4096 {
                return None;
            }
        }
    }
    None
}

/// The layout a covered format has.
pub fn layout<F: Format>(f: &F) -> Option<FloatLayout> {
    match f.kind() {
        FormatKind::Float(l) => Some(l),
        FormatKind::Fixed { .. } => None,
    }
}

/// One quantity's end-to-end check on one input: the model's value, the exact value and the
/// bound, and whether `|model − exact| <= bound`.
#[derive(Clone, Debug)]
pub struct Checked {
    /// `det`, `up`, `vp`, `tp`, `uv` or `t`.
    pub name: &'static str,
    /// The model's value.
    pub model: f64,
    /// The exact value (rounded to binary64 for display).
    pub exact: f64,
    /// The bound the judge computes (`err()`, or `t_err` for t).
    pub bound: f64,
    /// |model − exact| <= bound, decided exactly.
    pub holds: bool,
}

/// Runs the RTI model of `f` on one input and checks each decision quantity against the bound
/// under error model `em`, exactly (rational arithmetic); `None` when the bound's overflow flag
/// is set (no claim) or an input is not finite.
pub fn check_input<F: Format>(
    f: &F,
    em: ErrorModel,
    o: [f64; 3],
    d: [f64; 3],
    v: [[f64; 3]; 3],
) -> Option<Vec<Checked>> {
    use datapath::bound::RtiBound;
    use datapath::probe::Recorder;
    use datapath::rti::{Rti, RtiConfig};
    use num_rational::BigRational;
    use num_traits::{Signed, Zero};
    let all = o.iter().chain(&d).chain(v.iter().flatten());
    if !all.clone().all(|x| x.is_finite()) {
        return None;
    }
    let b = RtiBound::<f64>::new(em, f.div_mode(), o, d, v);
    if b.overflow {
        return None;
    }
    let rti = Rti::new(*f, RtiConfig::default());
    let mut rec = Recorder::new();
    rti.trace(&rti.ray(o, d, 0.0, f64::INFINITY), &rti.tri(v), &mut rec);
    let q = |x: f64| BigRational::from_float(x).expect("finite");
    let sub = |a: [f64; 3], b: [f64; 3]| -> [BigRational; 3] { std::array::from_fn(|i| q(a[i]) - q(b[i])) };
    let cross = |a: &[BigRational; 3], b: &[BigRational; 3]| -> [BigRational; 3] {
        [&a[1] * &b[2] - &a[2] * &b[1], &a[2] * &b[0] - &a[0] * &b[2], &a[0] * &b[1] - &a[1] * &b[0]]
    };
    let dot =
        |a: &[BigRational; 3], b: &[BigRational; 3]| -> BigRational { &a[0] * &b[0] + &a[1] * &b[1] + &a[2] * &b[2] };
    let (e1, e2, s) = (sub(v[1], v[0]), sub(v[2], v[0]), sub(o, v[0]));
    let dq: [BigRational; 3] = d.map(q);
    let p = cross(&dq, &e2);
    let qq = cross(&s, &e1);
    let det = dot(&e1, &p);
    let (up, vp, tp) = (dot(&s, &p), dot(&dq, &qq), dot(&e2, &qq));
    let uv = &up + &vp;
    let model = |n: &str| rec.value(n).map(|x| f.to_f64(x));
    let mut out = Vec::new();
    let mut one = |name: &'static str, exact: &BigRational, bound: f64| {
        let Some(m) = model(name) else { return };
        if !m.is_finite() {
            // a non-finite model value under a clear overflow flag breaks the bound
            out.push(Checked { name, model: m, exact: f64::NAN, bound, holds: false });
            return;
        }
        let holds = bound == f64::INFINITY || (q(m) - exact).abs() <= q(bound);
        let shown = num_traits::ToPrimitive::to_f64(exact).unwrap_or(f64::NAN);
        out.push(Checked { name, model: m, exact: shown, bound, holds });
    };
    one("det", &det, b.det.err());
    one("up", &up, b.up.err());
    one("vp", &vp, b.vp.err());
    one("tp", &tp, b.tp.err());
    one("uv", &uv, b.uv.err());
    if !det.is_zero() && b.t_err.is_finite() {
        one("t", &(&tp / &det), b.t_err);
    }
    Some(out)
}

/// The outcome of `raypipe prove rti-bound`.
#[derive(Clone, Debug)]
pub struct RtiBoundProof {
    /// `PROVEN` or `COUNTEREXAMPLE`.
    pub status: &'static str,
    /// The theorem (PROVEN) or what failed, in words.
    pub statement: String,
    /// Each operation's lemma.
    pub lemmas: Vec<OpLemma>,
    /// The integer scaling the exact check used.
    pub scale: Scale,
    /// A whole RTI input (origin, direction, vertices) whose quantity breaks the bound, and its check.
    pub witness: Option<Witness>,
    /// Seconds of the enumeration.
    pub seconds: f64,
}

/// Proves (or refutes, for a mutant) that the RTI bound of `f` holds: the stage table is the
/// composed one, and every operation's lemma holds over every operand pair.
pub fn prove<F: Format>(f: &F, mutant: Mutant, threads: usize) -> Result<RtiBoundProof, String> {
    let t0 = std::time::Instant::now();
    let div = f.div_mode();
    check_table(div)?;
    let em = mutant.apply(f.error_model());
    let scale = covers(f, em)?;
    let lemmas = enumerate(f, em, threads)?;
    let seconds = t0.elapsed().as_secs_f64();
    let failed: Vec<&OpLemma> = lemmas.iter().filter(|l| l.violation.is_some()).collect();
    if failed.is_empty() {
        let statement = format!(
            "for every input of {} (origin, direction, three vertices) whose values are finite and for which the bound's overflow flag is clear, each RTI decision quantity q of the model (det, u', v', t', u'+v', and t = t'/det when det is clear of zero) satisfies |q_model − q_exact| <= err(q), the bound raypipe's judge computes (datapath::bound); hence a decisive test's hit/miss is the exact one. By: the per-operation lemma over every operand pair ({}), the composition over the stage table's rows (docs/proofs.md)",
            f.name(),
            lemmas.iter().map(|l| format!("{} {} pairs", l.op, l.cases.unwrap_or(0))).collect::<Vec<_>>().join(", ")
        );
        return Ok(RtiBoundProof { status: "PROVEN", statement, lemmas, scale, witness: None, seconds });
    }
    // a whole input breaking the bound, from the multiplies that break the lemma
    let witness =
        if lemmas.iter().any(|l| l.op == "mul" && l.violation.is_some()) { find_witness(f, em) } else { None };
    let statement = format!(
        "the per-operation lemma fails for {} ({}){}",
        failed.iter().map(|l| l.op).collect::<Vec<_>>().join(", "),
        failed
            .iter()
            .map(|l| {
                let [a, b, r] = l.violation.unwrap();
                format!("{}: a {a:#x}, b {b:#x} gives {r:#x}", l.op)
            })
            .collect::<Vec<_>>()
            .join("; "),
        if witness.is_some() {
            "; a whole RTI input breaks the bound"
        } else {
            "; no whole input breaking the bound was found from it"
        }
    );
    Ok(RtiBoundProof { status: "COUNTEREXAMPLE", statement, lemmas, scale, witness, seconds })
}

#[cfg(test)]
mod tests {
    use super::*;
    use datapath::format::AnyFormat;
    fn parse_format(s: &str) -> Result<AnyFormat, String> {
        s.parse::<AnyFormat>().map_err(|e| e.to_string())
    }

    /// The composition's rows are the stage table's, in both division modes.
    #[test]
    fn the_composed_rows_are_the_stage_tables() {
        check_table(DivMode::RecipMul).unwrap();
        check_table(DivMode::Divide).unwrap();
    }

    /// The exact check on hand-worked fp16 cases: 1 ⊗ (1 + 2^-10) is exact (error 0); the
    /// sum 1 + 2^-11 is a tie that rounds to 1 (error 2^-11 = u·1 < u·|1 + 2^-11|: within,
    /// ratio 1/(1 + 2^-11)); a subnormal product 2^-24 · 0.5 = 2^-25 is a tie that rounds to 0
    /// (error η exactly, term u·2^-25 + η).
    #[test]
    fn the_scaled_check_matches_hand_worked_cases() {
        let sc = Scale { s: 24, kbits: 40, p: 11, q: Some(25), qa: None };
        let k = |x: f64| (x * 2f64.powi(24)) as i64;
        let (e, t) = scaled(LemmaOp::Mul, sc, k(1.0), k(1.0 + 2f64.powi(-10)), k(1.0 + 2f64.powi(-10)));
        assert_eq!(e, 0);
        assert!(within(e, t));
        let (e, t) = scaled(LemmaOp::Add, sc, k(1.0), k(2f64.powi(-11)), k(1.0));
        // err·2^11 = 2^-11·2^24·2^11 = 2^24; term = (1 + 2^-11)·2^24
        assert_eq!((e, t), (1 << 24, (1 << 24) + (1 << 13)));
        assert!(within(e, t));
        let (e, t) = scaled(LemmaOp::Mul, sc, k(2f64.powi(-24)), k(0.5), 0);
        // scale 2^-48 × 2^11: err = 2^-25·2^59 = 2^34, term = 2^-25·2^48 + 2^-25·2^59
        assert_eq!((e, t), (1 << 34, (1 << 23) + (1 << 34)));
        assert!(within(e, t));
        // without η the same product is far outside its term
        let (e, t) = scaled(LemmaOp::Mul, Scale { q: None, ..sc }, k(2f64.powi(-24)), k(0.5), 0);
        assert!(!within(e, t));
    }

    /// The lemma holds for e5m6 (every pair: 2^24) and its mutants are refuted; the worst ratio
    /// of the documented model is below 1 by at least the margin.
    #[test]
    fn the_lemma_holds_for_a_small_format_and_mutants_are_refuted() {
        let f = parse_format("e5m6").unwrap();
        datapath::with_format!(&f, |f| {
            let em = f.error_model();
            let ls = enumerate(f, em, 2).unwrap();
            assert_eq!(ls.iter().map(|l| l.op).collect::<Vec<_>>(), ["add", "sub", "mul", "recip"]);
            for l in &ls {
                assert!(l.violation.is_none(), "{}: {:?}", l.op, l.violation);
                assert!(l.cases.unwrap() > 0);
                let w = l.worst.unwrap().0;
                assert!(w > 0.5 && w <= 1.0 - 2f64.powi(-(MARGIN_BITS as i32)), "{} worst {w}", l.op);
            }
            // threads do not change the result
            assert_eq!(enumerate(f, em, 1).unwrap(), ls);
            for m in [Mutant::NoEta, Mutant::USixteenth] {
                let ls = enumerate(f, m.apply(em), 2).unwrap();
                let mul = ls.iter().find(|l| l.op == "mul").unwrap();
                assert!(mul.violation.is_some(), "{m:?} refuted at mul");
                assert_eq!(
                    enumerate(f, m.apply(em), 1).unwrap(),
                    ls,
                    "{m:?}: the first violation does not depend on threads"
                );
            }
        });
    }

    /// The binary64 filter decides no pair differently from the exact check: with the filter
    /// off (every pair decided in 128-bit integers) the results are the same, for the documented
    /// model and for both mutants (whose first violations the filter must not hide).
    #[test]
    fn the_filter_changes_no_verdict() {
        let f = parse_format("e5m6").unwrap();
        datapath::with_format!(&f, |f| {
            for m in [Mutant::None, Mutant::NoEta, Mutant::USixteenth] {
                let em = m.apply(f.error_model());
                assert_eq!(enumerate_with(f, em, 2, FILTER).unwrap(), enumerate_with(f, em, 2, -1.0).unwrap(), "{m:?}");
            }
        });
    }

    /// Formats the exact check cannot cover are refused with the reason.
    #[test]
    fn uncovered_formats_are_refused() {
        for (name, why) in
            [("f32", "at most 16 bits"), ("bf16", "2·bits(k)"), ("fp16:ftz", "flush-to-zero"), ("q8.8", "float")]
        {
            let f = parse_format(name).unwrap();
            let e = datapath::with_format!(&f, |f| covers(f, f.error_model()).unwrap_err());
            assert!(e.contains(why), "{name}: {e}");
        }
    }
    /// The theorem's statement sampled end to end, exactly: for fp16 inputs drawn from random
    /// encodings (subnormals, huge and tiny values, ±0 included) and from near-degenerate
    /// triangles, every quantity the bound claims is within it (rational arithmetic), in both
    /// division modes; cases where the overflow flag is set make no claim and are counted.
    #[test]
    fn the_bound_holds_on_sampled_inputs_exactly() {
        let mut r = datapath::rng::SplitMix64::new(36);
        for name in ["fp16", "fp16:divide", "e5m6"] {
            let f = parse_format(name).unwrap();
            datapath::with_format!(&f, |f| {
                let FormatKind::Float(l) = f.kind() else { unreachable!() };
                let mask = (1u64 << l.width()) - 1;
                let (mut claimed, mut checked) = (0, 0);
                for i in 0..6000 {
                    let mut val = |scale: f64| -> f64 {
                        match i % 3 {
                            // any finite encoding
                            0 => loop {
                                let x = f.to_f64(f.from_bits(r.next_u64() & mask));
                                if x.is_finite() {
                                    break x;
                                }
                            },
                            // one binade-wide band, rounded into the format
                            1 => f.to_f64(f.from_f64((r.unit() * 2.0 - 1.0) * scale)),
                            // near-degenerate: a base point plus a tiny offset
                            _ => f.to_f64(f.from_f64(scale * (1.0 + (r.unit() - 0.5) * 1e-3))),
                        }
                    };
                    let sc = [1.0, 2f64.powi(-12), 2f64.powi(6)][(i / 3) % 3];
                    let o = [val(sc), val(sc), val(sc)];
                    let d = [val(1.0), val(1.0), val(1.0)];
                    let v = [[val(sc), val(sc), val(sc)], [val(sc), val(sc), val(sc)], [val(sc), val(sc), val(sc)]];
                    if let Some(cs) = check_input(f, f.error_model(), o, d, v) {
                        claimed += 1;
                        for c in &cs {
                            checked += 1;
                            assert!(
                                c.holds,
                                "{name}: {} model {} exact {} bound {} at o {o:?} d {d:?} v {v:?}",
                                c.name, c.model, c.exact, c.bound
                            );
                        }
                    }
                }
                assert!(
                    claimed > 1000 && checked > 5 * claimed,
                    "{name}: {claimed} inputs with a claim, {checked} quantities"
                );
            });
        }
    }

    /// A mutant's refutation carries a whole RTI input that breaks the mutated bound, and the
    /// same input is within the documented bound.
    #[test]
    fn a_mutant_is_refuted_by_a_whole_input() {
        let f = parse_format("e5m6").unwrap();
        datapath::with_format!(&f, |f| {
            assert_eq!(prove(f, Mutant::None, 2).unwrap().status, "PROVEN");
            for m in [Mutant::NoEta, Mutant::USixteenth] {
                let p = prove(f, m, 2).unwrap();
                assert_eq!(p.status, "COUNTEREXAMPLE", "{m:?}");
                let ((o, d, v), cs) =
                    p.witness.clone().unwrap_or_else(|| panic!("{m:?}: no whole input: {}", p.statement));
                assert!(cs.iter().any(|c| !c.holds));
                let again = check_input(f, m.apply(f.error_model()), o, d, v).unwrap();
                assert!(again.iter().any(|c| c.name == "tp" && !c.holds), "{m:?}: t' breaks the mutated bound");
                let documented = check_input(f, f.error_model(), o, d, v).unwrap();
                assert!(documented.iter().all(|c| c.holds), "{m:?}: the documented bound holds there");
            }
        });
    }
}
