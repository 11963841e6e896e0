//! `raypipe traverse`: the 2-bit ray history and 1-bit trail traversals against the stack traversal on a scene's BVH.

use super::prelude::*;

/// The options of `raypipe traverse`.
#[derive(clap::Args, Clone)]
pub struct Args {
    /// OBJ scene (default: the built-in scene).
    #[arg(long)]
    pub scene: Option<PathBuf>,
    /// Box format(s) of the slab tester, comma-separated.
    #[arg(long, value_delimiter = ',', value_parser = parse_format, default_value = "f32,fp16,bf16,q8.24:divide")]
    pub format: Vec<AnyFormat>,
    /// Slab variant: plain, conservative, directed, take-on-false, embree.
    #[arg(long, default_value = "plain")]
    pub variant: String,
    /// Rays (half primary from a camera in front, half random incoherent).
    #[arg(long, default_value_t = 20000, value_parser = clap::value_parser!(u64).range(1..))]
    pub rays: u64,
    /// Random-ray seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// First N leaves per ray.
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u64).range(1..))]
    pub n: u64,
    /// Triangles per leaf at most (1..=255).
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(1..=255))]
    pub leaf_size: u32,
    /// Level pipelines available (the history holds 2 bits per level).
    #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u64).range(1..))]
    pub levels: u64,
    /// Print the results as JSON.
    #[arg(long)]
    pub json: bool,
    /// Also measure the functional coverage of the run's rays (per format the traverse unit's
    /// coverage model on the run's BVH; a pass of its own, the report unchanged) and write it to
    /// FILE (`raypipe cover FILE…` reports and merges it; docs/coverage.md).
    #[arg(long)]
    pub cover: Option<PathBuf>,
    #[command(flatten)]
    pub run: EngineArgs,
    #[command(flatten)]
    pub sharding: ShardArgs,
}

/// Runs `raypipe traverse`.
pub fn run(a: Args) -> Result<Outcome, String> {
    let Args { scene, format, variant, rays, seed, n, leaf_size, levels, json, cover, run, sharding } = a;
    check_rays(rays)?;
    if let Some(c) = &cover {
        // before the work: a file raypipe did not write is never replaced
        check_written_path("--cover", c, vectors::cover_file::KIND)?;
        if variant == "directed" {
            return Err(
                "--cover: the traverse unit's coverage model has the slab variants plain, conservative, take-on-false and embree as its box tester (directed has none)"
                    .into(),
            );
        }
    }
    let sh = shard_of(sharding.shard.as_deref(), sharding.partial.as_deref())?;
    let scene = load_scene(scene.as_deref())?;
    let cfg = raypipe::traverse::TraverseConfig {
        formats: format,
        variant,
        rays: rays as usize,
        seed,
        n: n as usize,
        leaf_size,
        levels: levels as usize,
        engine: run.engine(raypipe::traverse::CHUNK_RAYS).with_shard(sh),
        progress: !run.quiet,
    };
    let rep = raypipe::traverse::traverse(&cfg, &scene)?;
    if let Some(path) = &cover {
        let models = raypipe::traverse::cover::cover(&cfg, &scene, &command_as_typed())?;
        raypipe::cover_run::write(path, &models, &command_as_typed())?;
    }
    let id = Run {
        args: raypipe::traverse::args(&cfg),
        scene_hash: raypipe::partial::scene_hash(&scene),
        chunk: raypipe::traverse::CHUNK_RAYS,
        shard: sh,
    };
    conclude(json, sharding.partial.as_deref(), id, rep)
}
