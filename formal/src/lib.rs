//! Proof, not sampling: the stage models as SMT-LIB 2 generated from the stage tables
//! ([`smt`]), the solver driver ([`solver`]) and the proofs of the guarantees ([`prove`]).
#![warn(missing_docs)]

pub mod prove;
pub mod smt;
pub mod solver;
