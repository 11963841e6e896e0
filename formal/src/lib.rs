//! Proof, not sampling: the stage models as SMT-LIB 2 generated from the stage tables
//! ([`smt`]), the solver driver ([`solver`]), the proofs of the guarantees ([`prove`]) and
//! formal equivalence of a DUT with the model ([`equiv`]).
#![warn(missing_docs)]

pub mod equiv;
pub mod prove;
pub mod smt;
pub mod solver;
