//! `raypipe prove`: prove one of raypipe's guarantees with an SMT solver (docs/proofs.md).

use super::prelude::*;

/// The options of `raypipe prove`.
#[derive(clap::Args, Clone)]
pub struct Args {
    /// Property: slab-never-misses.
    pub property: String,
    /// Format.
    #[arg(long, default_value = "fp16")]
    pub format: String,
    /// Print the result as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Runs `raypipe prove`.
pub fn run(a: Args) -> Result<Outcome, String> {
    let _ = (&a.property, &a.format, a.json);
    Err("raypipe prove: not yet".into())
}
