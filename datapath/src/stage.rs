//! A stage table's rows: what each recorded signal computes ([`Op`], [`Rule`], [`SigDef`]),
//! shared by the RTI and slab units' tables, the fault sites and the SMT-LIB form of the models
//! (its own module, so that the units and their consumers import it and not each other).
//!
//! A row's [`Rule`] is its formula as data: the SMT emitter translates rules into terms one
//! for one, so the tables are the single description of both the Rust models and the SMT
//! model (a test evaluates the SMT on vector sets and compares every signal with the Rust
//! model bit for bit). Operand names are earlier signals, the unit's inputs, or the
//! constants `one` (1), `zero` (+0) and `thr` (the RTI det threshold).

/// Operation of one signal in the stage table.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Op {
    /// a - b.
    Sub,
    /// a + b.
    Add,
    /// a × b.
    Mul,
    /// a ÷ b (per the format's division mode).
    Div,
    /// A comparison or logic bit; the formula is in the note.
    Logic,
}

/// A row's formula as data (operands name signals, inputs or the constants `one`, `zero`, `thr`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rule {
    /// The row's [`Op`] on `a` and `b` (one rounded operation of the format).
    Arith,
    /// The row's [`Op`], then the conservative slab guard's reciprocal rule when the variant
    /// has the guard: a finite nonzero divisor whose result is ±∞, ±0 or subnormal gives the
    /// canonical NaN.
    ArithGuardRecip,
    /// The row's [`Op`], then the guard's subtract rule when the variant has it: finite
    /// operands whose difference is ±∞ give the canonical NaN.
    ArithGuardSub,
    /// The stage-0 input read of an input (`Format::read_input`).
    Read(&'static str),
    /// The slab variant's direction preparation of a read direction component (identity, or
    /// Embree's `|d| < δ ? ±δ : d`).
    Prep(&'static str),
    /// The sign bit of a value (a flag).
    SignBit(&'static str),
    /// `c ? a : b` for a flag `c`.
    Mux(&'static str, &'static str, &'static str),
    /// The IEEE ordered compare `a <= b` (false with a NaN, −0 == +0; FTZ reads subnormals as 0).
    Le(&'static str, &'static str),
    /// RTI det test: two-sided `thr < |det|`, backface culling `thr < det`.
    DetOk(&'static str),
    /// RTI sign-oriented compare: `0 < det ? a <= b : b <= a` (`pos = 0 < det` is one
    /// compare shared by the rows that use it).
    Oriented(&'static str, &'static str),
    /// The AND of flags.
    All(&'static [&'static str]),
    /// The slab compare unit's near select of accumulator `acc` and candidate `x` per the
    /// variant's NaN comparator: `Ignore` `acc < x ? x : acc`; `TakeOnFalse` `x <= acc ? acc : x`.
    SelNear(&'static str, &'static str),
    /// The far select: `Ignore` `x < acc ? x : acc`; `TakeOnFalse` `acc <= x ? acc : x`.
    SelFar(&'static str, &'static str),
    /// A value stepped `widen_ulps` grid steps (nextDown each when `up` is false, nextUp when
    /// true; the other direction when `widen_ulps < 0`).
    Widen(&'static str, bool),
}

/// One row of the stage table: `name = a op b` at `stage`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SigDef {
    /// Pipeline stage (1-based).
    pub stage: u8,
    /// Signal name (as recorded by the probe).
    pub name: &'static str,
    /// Operation.
    pub op: Op,
    /// First operand (input or earlier signal).
    pub a: &'static str,
    /// Second operand.
    pub b: &'static str,
    /// Formula for logic bits.
    pub note: &'static str,
    /// The formula as data.
    pub rule: Rule,
}
