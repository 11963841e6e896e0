//! Hardware fault models and fault campaigns: the measure of a vector set is the bugs it
//! catches. [`bank`] names each fault (the one-line RTL bug it stands for, the site it
//! changes, whether it is provably benign on the outputs), [`inject`] makes it a
//! [`datapath::fault::Fault`] the stage models run with, and [`campaign`] runs the bank over a
//! vector set and says which faults the set detects, by which vectors and classes;
//! [`minimal`] cuts a set to the fewest vectors that still detect what it detects.
#![warn(missing_docs)]
#![forbid(unsafe_code)]

pub mod bank;
pub mod campaign;
pub mod inject;
pub mod minimal;

pub use bank::{Kind, Mode, Spec, BANK};
pub use campaign::{run, Campaign, Outcome};
