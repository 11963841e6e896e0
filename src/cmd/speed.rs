//! `raypipe speed`: this machine's no-FMA FP peak and each RTI / slab implementation's throughput as a fraction of it.

use super::prelude::*;

/// The options of `raypipe speed`.
#[derive(clap::Args, Clone)]
pub struct Args {
    /// Ray–triangle pairs per call (the default 512 keeps the 15 input columns in L1).
    #[arg(long, default_value_t = 512, value_parser = clap::value_parser!(u64).range(8..))]
    pub pairs: u64,
    /// Seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Use no kernel wider than this (as a machine without the wider ones would): scalar, avx2, avx512 or avx512fp16.
    #[arg(long, value_parser = ["scalar", "avx2", "avx512", "avx512fp16"])]
    pub cap: Option<String>,
    /// Print the results as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Runs `raypipe speed`.
pub fn run(a: Args) -> Result<Outcome, String> {
    let Args { pairs, seed, cap, json } = a;
    limit("--pairs", pairs, MAX_SPEED_PAIRS, "the columns are held in memory")?;
    apply_cap(cap.as_deref());
    let mut rep = raypipe::speed::speed(pairs as usize, seed);
    rep.cap = cap;
    emit(json, &rep, raypipe::speed::render)?;
    Ok(Outcome::Pass)
}
