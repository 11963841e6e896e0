//! raypipe: bit-accurate ray-tracing datapath models judged against a golden reference.
//!
//! Data flow: scene ([`scene`]) → rays → model stages (`datapath`) → compare with the golden
//! (`golden`) and the error bounds ([`judge`]) → report ([`verify`], [`explain`]).
#![warn(missing_docs)]

pub mod bvh;
pub mod explain;
pub mod judge;
pub mod plan;
pub mod render;
pub mod report;
pub mod scene;
pub mod speed;
pub mod stats;
pub mod stress;
pub mod traverse;
pub mod verify;
