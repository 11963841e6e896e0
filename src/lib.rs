//! raypipe: bit-accurate ray-tracing datapath models judged against a golden reference.
//!
//! Data flow: scene ([`scene`]) → rays → model stages (`datapath`) → compare with the golden
//! (`golden`) and the error bounds ([`judge`]) → report ([`verify`], [`explain`]).
#![warn(missing_docs)]

pub mod arch;
pub mod bvh;
pub mod camera;
pub mod cover_reference;
pub mod cover_run;
pub mod explain;
pub mod faults;
pub mod field_reference;
pub mod judge;
pub mod machine;
pub mod ops;
pub mod partial;
pub mod plan;
pub mod render;
pub mod scene;
pub mod speed;
pub mod stats;
pub mod stress;
pub mod time_vs_error;
pub mod traverse;
pub mod verify;

/// The golden's f64-lane level for the engine: the fastest here within the kernels' caps
/// (`datapath::simd::cap_process`, `raypipe speed --cap`); the golden crate itself knows no cap.
pub fn golden_level() -> golden::block::Level {
    use datapath::simd::{kernels_here, Kernel};
    use golden::block::Level;
    let k = kernels_here();
    let allowed = |l: &Level| match l {
        Level::Scalar => true,
        Level::Avx2 => k.contains(&Kernel::Avx2),
        Level::Avx512 => k.contains(&Kernel::Avx512),
    };
    golden::block::levels_here().into_iter().rfind(allowed).unwrap_or(Level::Scalar)
}

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
