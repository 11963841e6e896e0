//! Proofs of raypipe's guarantees.
