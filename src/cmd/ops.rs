//! `raypipe ops`: one operation of a format against the per-op oracle (APFloat): every pair or specials + random; shardable.

use super::prelude::*;

/// The options of `raypipe ops`.
#[derive(clap::Args, Clone)]
pub struct Args {
    /// Format: f32, fp16 or bf16 (ieee or ftz, recip or divide; canonical NaN rule).
    #[arg(long, value_parser = parse_format)]
    pub format: AnyFormat,
    /// Operation: add, sub, mul, div (the format's division mode), recip, lt, le, cmp (both compares).
    #[arg(long)]
    pub op: String,
    /// Every operand pair (16-bit formats: 2^32 pairs).
    #[arg(long)]
    pub exhaustive: bool,
    /// Pairs of a sampled sweep (the special operands' pairs first, then random).
    #[arg(long, default_value_t = 1_000_000)]
    pub count: u64,
    /// Seed of the random pairs.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Print the results as JSON.
    #[arg(long)]
    pub json: bool,
    /// Also measure the functional coverage of the sweep (the op unit's coverage model) and
    /// write it to FILE (`raypipe cover FILE…` reports and merges it; docs/coverage.md).
    #[arg(long)]
    pub cover: Option<PathBuf>,
    #[command(flatten)]
    pub run: EngineArgs,
    #[command(flatten)]
    pub sharding: ShardArgs,
}

/// Runs `raypipe ops`.
pub fn run(a: Args) -> Result<Outcome, String> {
    let Args { format, op, exhaustive, count, seed, json, cover, run, sharding } = a;
    let sh = shard_of(sharding.shard.as_deref(), sharding.partial.as_deref())?;
    if let Some(c) = &cover {
        // before the work: a file raypipe did not write is never replaced
        check_written_path("--cover", c, vectors::cover_file::KIND)?;
    }
    let cfg = raypipe::ops::OpsConfig {
        format,
        op,
        exhaustive,
        count,
        seed,
        engine: run.engine(raypipe::ops::CHUNK).with_shard(sh),
        progress: !run.quiet,
    };
    let data = raypipe::ops::accumulate(&cfg)?;
    if let Some(path) = &cover {
        let (m, c) = raypipe::ops::cover(&cfg)?;
        raypipe::cover_run::write(path, &[(m, c)], &command_as_typed())?;
    }
    let id = Run { args: raypipe::ops::args(&cfg), scene_hash: String::new(), chunk: raypipe::ops::CHUNK, shard: sh };
    conclude(json, sharding.partial.as_deref(), id, data)
}
