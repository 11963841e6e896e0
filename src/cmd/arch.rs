//! `raypipe arch`: the thesis hardware as a throughput model: figure 3-3 (time against leaf size per pipeline count) and its calibration.

use super::prelude::*;

/// The options of `raypipe arch`.
#[derive(clap::Args, Clone)]
pub struct Args {
    /// OBJ scene (default: the built-in scene).
    #[arg(long)]
    pub scene: Option<PathBuf>,
    /// Rays (half primary, half random incoherent, as `stats`).
    #[arg(long, default_value_t = 20000, value_parser = clap::value_parser!(u64).range(1..))]
    pub rays: u64,
    /// Random-ray seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Leaf sizes to sweep (1..=255), comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "1,2,3,4,6,8,12,16,24,32,48,64", value_parser = clap::value_parser!(u32).range(1..=255))]
    pub leaf_sizes: Vec<u32>,
    /// RTI pipeline counts of the figure, comma-separated.
    #[arg(long = "sweep-pipelines", value_delimiter = ',', default_value = "4,8,16,32", value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub sweep: Vec<u32>,
    /// RTI pipelines of the calibration.
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub pipelines: u32,
    /// Level pipelines of the traversal core (default 32: the thesis's 25 to 32 levels).
    #[arg(long, default_value_t = 32, value_parser = clap::value_parser!(u32).range(1..=256))]
    pub levels: u32,
    #[command(flatten)]
    pub hw: ArchArgs,
    /// Write figure 3-3 as SVG into this directory.
    #[arg(long)]
    pub svg: Option<PathBuf>,
    /// Print the results as JSON.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub run: EngineArgs,
}

/// Runs `raypipe arch`.
pub fn run(a: Args) -> Result<Outcome, String> {
    let Args { scene, rays, seed, leaf_sizes, sweep, pipelines, levels, hw, svg, json, run } = a;
    check_rays(rays)?;
    let params = hw.params(pipelines, levels);
    params.check()?;
    let out = svg.as_deref().map(|d| OutDir::check(d, &raypipe::arch::SVG_FILES)).transpose()?;
    let scene = load_scene(scene.as_deref())?;
    let eng = run.engine(raypipe::traverse::CHUNK_RAYS);
    let cfg = raypipe::arch::ArchConfig { params, pipelines: sweep, leaf_sizes, rays, seed };
    let rep = raypipe::arch::arch(&eng, &cfg, &scene)?;
    emit(json, &rep, raypipe::arch::render)?;
    if let Some(out) = out {
        for p in raypipe::arch::write_svgs(&rep, &out)? {
            eprintln!("wrote {}", p.display());
        }
    }
    Ok(Outcome::Pass)
}
