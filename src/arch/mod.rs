//! The thesis architecture as a throughput model: scene events ([`events`]) → cycle counts of
//! the RTI accelerator and the traversal core ([`model`], parameters in [`params`]) → figure
//! 3-3, its conclusion and the calibration against the thesis ([`figure`]); `raypipe plan`
//! chooses the leaf size and pipeline count from it.

pub mod events;
pub mod figure;
pub mod model;
pub mod params;

pub use events::{gather, SceneEvents};
pub use figure::{arch, render, write_svgs, ArchConfig, ArchReport, SVG_FILES};
pub use model::{estimate, Estimate, RtiCycles, TravCycles};
pub use params::ArchParams;
