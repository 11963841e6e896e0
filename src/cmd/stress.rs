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
    /// Also measure the functional coverage of the suite's cases (per format the RTI unit's and
    /// each slab variant's coverage model, the stress classes as class bins; a pass of its own,
    /// the report unchanged) and write it to FILE (`raypipe cover FILE…`; docs/coverage.md).
    #[arg(long)]
    pub cover: Option<PathBuf>,
    #[command(flatten)]
    pub run: EngineArgs,
    #[command(flatten)]
    pub sharding: ShardArgs,
}

/// Runs `raypipe stress`.
pub fn run(a: Args) -> Result<Outcome, String> {
    let Args { format, variant, count, seed, json, cover, run, sharding } = a;
    let sh = shard_of(sharding.shard.as_deref(), sharding.partial.as_deref())?;
    if let Some(c) = &cover {
        // before the work: a file raypipe did not write is never replaced
        check_written_path("--cover", c, vectors::cover_file::KIND)?;
    }
    let mut cfg = raypipe::stress::StressConfig::new(format, variant, count as usize, seed);
    cfg.engine = run.engine(raypipe::stress::CHUNK_CASES).with_shard(sh);
    cfg.progress = !run.quiet;
    let rep = raypipe::stress::stress(&cfg)?;
    if let Some(path) = &cover {
        let models = raypipe::stress::cover::cover(&cfg, &command_as_typed())?;
        raypipe::cover_run::write(path, &models, &command_as_typed())?;
    }
    let id = Run {
        args: raypipe::stress::args(&cfg),
        scene_hash: String::new(),
        chunk: raypipe::stress::CHUNK_CASES,
        shard: sh,
    };
    conclude(json, sharding.partial.as_deref(), id, rep)
}
