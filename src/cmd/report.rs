//! `raypipe report`: run time against error for every variant on the same inputs: markdown, JSON and SVG with the Pareto front.

use super::prelude::*;

/// The options of `raypipe report`.
#[derive(clap::Args, Clone)]
pub struct Args {
    /// OBJ scenes (repeatable; the built-in scene is always included).
    #[arg(long)]
    pub scene: Vec<PathBuf>,
    /// Formats, comma-separated.
    #[arg(long, value_delimiter = ',', value_parser = parse_format, default_value = "f32,fp16,bf16,e8m16,q8.24:divide,f32:ftz+divide")]
    pub format: Vec<AnyFormat>,
    /// Slab variants, comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "plain,conservative,directed,take-on-false,embree")]
    pub variant: Vec<String>,
    /// Rays per scene.
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u64).range(1..))]
    pub rays: u64,
    /// Stress cases per class.
    #[arg(long, default_value_t = 200, value_parser = clap::value_parser!(u64).range(1..))]
    pub stress_count: u64,
    /// Seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Directory for report.md, report.json and the SVG plots.
    #[arg(long, default_value = "report-out")]
    pub out: PathBuf,
    /// Print JSON instead of markdown.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub sharding: ShardArgs,
}

/// Runs `raypipe report`.
pub fn run(a: Args) -> Result<Outcome, String> {
    let Args { scene, format, variant, rays, stress_count, seed, out, json, sharding } = a;
    let sh = shard_of(sharding.shard.as_deref(), sharding.partial.as_deref())?;
    // a shard writes its partial, not the report's files
    let dir = match sharding.partial {
        None => Some(OutDir::check(&out, &raypipe::time_vs_error::FILES)?),
        Some(_) => None,
    };
    let mut scenes = vec![Scene::builtin()];
    for p in &scene {
        scenes.push(load_scene(Some(p))?);
    }
    for s in &scenes {
        check_tests(rays, s, 512)?;
    }
    let cfg = raypipe::time_vs_error::ReportConfig {
        formats: format,
        variants: variant,
        rays,
        stress_count: stress_count as usize,
        seed,
        engine: engine::Engine::new(raypipe::verify::CHUNK_RAYS).with_shard(sh),
    };
    if let Some(path) = &sharding.partial {
        let data = raypipe::time_vs_error::accumulate(&cfg, &scenes)?;
        let id = Run {
            args: raypipe::time_vs_error::args(&cfg, &scenes),
            scene_hash: String::new(),
            chunk: raypipe::verify::CHUNK_RAYS,
            shard: sh,
        };
        return conclude(json, Some(path), id, data);
    }
    let mut rep = raypipe::time_vs_error::report(&cfg, &scenes)?;
    rep.command = command_as_typed();
    let files = raypipe::time_vs_error::write(&rep, dir.as_ref().expect("checked when there is no partial"))?;
    emit(json, &rep, raypipe::time_vs_error::markdown)?;
    for f in files {
        eprintln!("wrote {}", f.display());
    }
    Ok(Outcome::Pass)
}
