//! raypipe: bit-accurate ray-tracing datapath models judged against a golden reference.
//!
//! Data flow: scene ([`scene`]) → rays → model stages (`datapath`) → compare with the golden
//! (`golden`) and the error bounds ([`judge`]) → report ([`verify`], [`explain`]).
#![warn(missing_docs)]

pub mod arch;
pub mod bvh;
pub mod explain;
pub mod faults;
pub mod judge;
pub mod ops;
pub mod partial;
pub mod plan;
pub mod render;
pub mod report;
pub mod scene;
pub mod speed;
pub mod stats;
pub mod stress;
pub mod traverse;
pub mod verify;

/// How a run ended, as its exit code: 0 every property held, 1 one failed, 3 the run proved
/// nothing (no test could decide the property). Bad input is 2 (a clear error, no result).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Outcome {
    /// Every property held on a run that decided something.
    Pass = 0,
    /// A property failed.
    Fail = 1,
    /// Nothing failed, but no test decided the property: the run proved nothing.
    Inconclusive = 3,
}

impl From<bool> for Outcome {
    fn from(passed: bool) -> Self {
        if passed {
            Outcome::Pass
        } else {
            Outcome::Fail
        }
    }
}
