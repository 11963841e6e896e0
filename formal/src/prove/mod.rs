//! Proofs of raypipe's guarantees: each property is a query on the emitted SMT model (so a
//! proof about it is a proof about the Rust model, see `python/tests/test_smt.py`) whose
//! assertions are satisfiable exactly when the guarantee fails. `unsat` is PROVEN; `sat`
//! gives a counterexample; `unknown` (a timeout) proves nothing.

pub mod history;
pub mod rti_bound;
pub mod slab;
pub mod slab_directed;
pub mod slab_planes;

use crate::solver::Verdict;

/// The outcome of one proof attempt.
#[derive(Clone, Debug)]
pub struct Proof {
    /// Property name.
    pub property: String,
    /// Format name.
    pub format: String,
    /// What was proven, in words (the theorem), and its assumptions.
    pub theorem: String,
    /// The solver's verdict.
    pub verdict: Verdict,
    /// A counterexample's inputs by name (encodings), when `sat`.
    pub witness: Vec<(String, u64)>,
    /// Each solver query: what it asked and its verdict.
    pub steps: Vec<(String, Verdict)>,
}

impl Proof {
    /// `PROVEN`, `COUNTEREXAMPLE` or `UNKNOWN`.
    pub fn status(&self) -> &'static str {
        match self.verdict.result.as_str() {
            "unsat" => "PROVEN",
            "sat" => "COUNTEREXAMPLE",
            _ => "UNKNOWN",
        }
    }
}
