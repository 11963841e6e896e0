//! Bit-accurate models of ray-tracing hardware datapaths: number formats ([`format`](mod@format)), the
//! latency-reordered Möller–Trumbore ray–triangle pipeline ([`rti`]) with per-stage probes
//! ([`probe`]), and its error bounds ([`bound`]).
#![warn(missing_docs)]

pub mod alloc;
pub mod bound;
pub mod bvh;
pub mod format;
pub mod probe;
pub mod rng;
pub mod rti;
pub mod simd;
pub mod slab;

pub use format::{AnyFormat, Format};
