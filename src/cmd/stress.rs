//! `raypipe stress`: the numerical stability stress suite: failures against the exact decision per class, format and variant.

use super::prelude::*;

/// The options of `raypipe stress`.
#[derive(clap::Args, Clone)]
pub struct Args {
    /// Formats, comma-separated.
    #[arg(long, value_delimiter = ',', value_parser = parse_format, default_value = "f32,fp16,bf16,q8.24:divide")]
    pub format: Vec<AnyFormat>,
    /// Slab variants, comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "plain,conservative,directed,embree")]
    pub variant: Vec<String>,
    /// Cases per class.
    #[arg(long, default_value_t = 500, value_parser = clap::value_parser!(u64).range(1..))]
    pub count: u64,
    /// Seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Print the results as JSON.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub run: EngineArgs,
    #[command(flatten)]
    pub sharding: ShardArgs,
}

/// Runs `raypipe stress`.
pub fn run(a: Args) -> Result<Outcome, String> {
    let Args { format, variant, count, seed, json, run, sharding } = a;
    let sh = shard_of(sharding.shard.as_deref(), sharding.partial.as_deref())?;
    let mut cfg = raypipe::stress::StressConfig::new(format, variant, count as usize, seed);
    cfg.engine = run.engine(raypipe::stress::CHUNK_CASES).with_shard(sh);
    cfg.progress = !run.quiet;
    let rep = raypipe::stress::stress(&cfg)?;
    let id = Run {
        args: raypipe::stress::args(&cfg),
        scene_hash: String::new(),
        chunk: raypipe::stress::CHUNK_CASES,
        shard: sh,
    };
    conclude(json, sharding.partial.as_deref(), id, rep)
}
