//! `raypipe plan`: what a scene needs: tree depth and history bits, culling, and the narrowest format within an error budget.

use super::prelude::*;

/// The options of `raypipe plan`.
#[derive(clap::Args, Clone)]
pub struct Args {
    /// OBJ scene (default: the built-in scene).
    #[arg(long)]
    pub scene: Option<PathBuf>,
    /// Candidate formats, comma-separated.
    #[arg(long, value_delimiter = ',', value_parser = parse_format, default_value = "fp16,bf16,e8m16,f32,q8.24:divide")]
    pub format: Vec<AnyFormat>,
    /// RTI pipelines at most (the plan chooses the count and the leaf size from the throughput model).
    #[arg(long, default_value_t = 4)]
    pub pipelines: u32,
    /// Largest acceptable rate of hit/miss disagreements with the golden, per test.
    #[arg(long, default_value_t = 1e-4)]
    pub budget: f64,
    /// Rays of the measurement.
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u64).range(1..))]
    pub rays: u64,
    /// Seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Level pipelines the hardware has.
    #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u64).range(1..=256))]
    pub levels: u64,
    /// BRAM bits the traversal core has for the tree (default: unlimited).
    #[arg(long)]
    pub bram_bits: Option<u64>,
    /// Rays of the throughput model's traversals.
    #[arg(long, default_value_t = 20000, value_parser = clap::value_parser!(u64).range(1..))]
    pub model_rays: u64,
    /// Leaf sizes the model considers (1..=255), comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "1,2,3,4,6,8,12,16,24,32,48,64,128", value_parser = clap::value_parser!(u32).range(1..=255))]
    pub leaf_sizes: Vec<u32>,
    #[command(flatten)]
    pub hw: ArchArgs,
    /// Print the plan as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Runs `raypipe plan`.
pub fn run(a: Args) -> Result<Outcome, String> {
    let Args { scene, format, pipelines, budget, rays, seed, levels, bram_bits, model_rays, leaf_sizes, hw, json } = a;
    let scene = load_scene(scene.as_deref())?;
    check_tests(rays, &scene, 512)?;
    check_rays(model_rays)?;
    let cfg = raypipe::plan::PlanConfig {
        formats: format,
        pipelines,
        budget,
        rays,
        seed,
        max_levels: levels as usize,
        arch: hw.params(pipelines.max(1), levels as u32),
        model_rays,
        bram_bits,
        leaf_sizes,
    };
    let p = raypipe::plan::plan(&cfg, &scene)?;
    emit(json, &p, raypipe::plan::render)?;
    Ok(Outcome::Pass)
}
