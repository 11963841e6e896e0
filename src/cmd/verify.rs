//! `raypipe verify` (the default command): every format's RTI model and slab variants against
//! the golden reference on a scene's rays.

use super::prelude::*;
use raypipe::verify::VerifyConfig;

/// Default formats of `raypipe verify`.
pub const DEFAULT_FORMATS: [&str; 5] = ["f32", "fp16", "bf16", "e8m16", "q8.24:divide"];

/// The options of `raypipe verify`.
#[derive(clap::Args, Clone)]
pub struct Args {
    /// OBJ scene (default: the built-in Cornell box + icosphere + needles).
    #[arg(long)]
    pub scene: Option<PathBuf>,
    /// Format(s) to verify, comma-separated or repeated (default: f32,fp16,bf16,e8m16,q8.24:divide).
    #[arg(long, value_delimiter = ',', value_parser = parse_format)]
    pub format: Vec<AnyFormat>,
    /// Number of rays.
    #[arg(long, default_value_t = 1024, value_parser = clap::value_parser!(u64).range(1..))]
    pub rays: u64,
    /// Ray generator seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Scenes up to this many triangles are tested exhaustively per ray; larger ones per ray
    /// against its target triangle and this many minus one random others.
    #[arg(long, default_value_t = 512, value_parser = clap::value_parser!(u64).range(1..))]
    pub sample: u64,
    /// Print the results as JSON.
    #[arg(long)]
    pub json: bool,
    /// A plan (`raypipe plan --json`): verify only its formats within budget (unless --format).
    #[arg(long)]
    pub plan: Option<PathBuf>,
    /// Rays per chunk of the streaming engine; the results do not depend on it.
    #[arg(long, default_value_t = raypipe::verify::CHUNK_RAYS, value_parser = clap::value_parser!(u64).range(1..=1_000_000))]
    pub chunk: u64,
    #[command(flatten)]
    pub run: EngineArgs,
    #[command(flatten)]
    pub sharding: ShardArgs,
    /// Run the RTI model with this fault of the bank (a name `raypipe faults --unit rti`
    /// lists): a model wrong on purpose, to see the judge catch it on this scene.
    #[arg(long)]
    pub inject: Option<String>,
    #[command(flatten)]
    pub rti: RtiArgs,
    /// Also measure the functional coverage of the run's tests (per format the RTI unit's and
    /// each slab variant's coverage model; a pass of its own, the report unchanged) and write it
    /// to FILE (`raypipe cover FILE…` reports and merges it; docs/coverage.md).
    #[arg(long)]
    pub cover: Option<PathBuf>,
    /// Use no kernel wider than this (as a machine without the wider ones would; the bits and
    /// the report are the same, only the speed changes): scalar, avx2, avx512 or avx512fp16.
    #[arg(long, value_parser = ["scalar", "avx2", "avx512", "avx512fp16"])]
    pub cap: Option<String>,
}

impl Args {
    /// The main job `raypipe` runs without a command: every default of `raypipe verify`.
    pub fn main_job() -> Self {
        Args {
            scene: None,
            format: Vec::new(),
            rays: 1024,
            seed: 1,
            sample: 512,
            json: false,
            plan: None,
            chunk: raypipe::verify::CHUNK_RAYS,
            run: EngineArgs { threads: None, quiet: false },
            sharding: ShardArgs { shard: None, partial: None },
            inject: None,
            rti: RtiArgs { cull: false, det_threshold: 0.0, tie: Tie::First },
            cover: None,
            cap: None,
        }
    }
}

/// Runs `raypipe verify`.
pub fn run(a: Args) -> Result<Outcome, String> {
    let rti = a.rti.config()?;
    let inject = a.inject.as_deref().map(rti_fault).transpose()?;
    let scene = load_scene(a.scene.as_deref())?;
    let plan = a.plan.as_deref().map(raypipe::plan::load).transpose()?;
    if let Some(p) = &plan {
        p.check_scene(&scene)?;
    }
    let formats = match (a.format.is_empty(), &plan) {
        (false, _) => a.format,
        (true, Some(p)) => p.within_budget()?,
        (true, None) => DEFAULT_FORMATS.iter().map(|f| f.parse().expect("built-in format name")).collect(),
    };
    check_tests(a.rays, &scene, a.sample)?;
    if let Some(c) = &a.cover {
        // before the work: a file raypipe did not write is never replaced
        check_written_path("--cover", c, vectors::cover_file::KIND)?;
    }
    let shard = shard_of(a.sharding.shard.as_deref(), a.sharding.partial.as_deref())?;
    apply_cap(a.cap.as_deref());
    let mut cfg = VerifyConfig::new(formats, a.rays, a.seed, rti, a.sample as usize);
    cfg.engine = a.run.engine(a.chunk).with_shard(shard);
    cfg.progress = !a.run.quiet;
    cfg.inject = inject;
    let data = raypipe::verify::accumulate(&cfg, &scene);
    if let Some(path) = &a.cover {
        let models = raypipe::verify::cover::cover(&cfg, &scene, &command_as_typed())?;
        raypipe::cover_run::write(path, &models, &command_as_typed())?;
    }
    let id = Run {
        args: raypipe::verify::args(&cfg),
        scene_hash: raypipe::partial::scene_hash(&scene),
        chunk: a.chunk,
        shard,
    };
    conclude(a.json, a.sharding.partial.as_deref(), id, data)
}
