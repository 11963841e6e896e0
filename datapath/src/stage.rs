//! A stage table's rows: what each recorded signal computes ([`Op`], [`SigDef`]), shared by the
//! RTI and slab units' tables and by the fault sites (its own module, so that the units and
//! the fault hooks import it and not each other).

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
}
