//! Golden reference: plain f64 intersection code, written independently of the `datapath`
//! models it judges (it shares no code with them).
#![warn(missing_docs)]

pub mod block;
pub mod bvh;
pub mod mt;
pub mod ops;
pub mod slab;

pub use mt::{closest_hit, intersect, intersect_exact, Faces, MtResult, Ray64, Tri64};
pub use slab::{slab_exact, slab_f64, SlabResult};
