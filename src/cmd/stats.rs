//! `raypipe stats`: the thesis's experiments (figs. 3-1, 3-2, 3-4, 3-5, restart overhead) over leaf sizes.

use super::prelude::*;

/// The options of `raypipe stats`.
#[derive(clap::Args, Clone)]
pub struct Args {
    /// OBJ scene (default: the built-in scene).
    #[arg(long)]
    pub scene: Option<PathBuf>,
    /// Rays (half primary, half random incoherent).
    #[arg(long, default_value_t = 20000, value_parser = clap::value_parser!(u64).range(1..))]
    pub rays: u64,
    /// Random-ray seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Leaf sizes to sweep (1..=255), comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "1,2,4,8,16,32", value_parser = clap::value_parser!(u32).range(1..=255))]
    pub leaf_sizes: Vec<u32>,
    /// Write the figures as SVG into this directory.
    #[arg(long)]
    pub svg: Option<PathBuf>,
    /// Print the results as JSON.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub run: EngineArgs,
}

/// Runs `raypipe stats`.
pub fn run(a: Args) -> Result<Outcome, String> {
    let Args { scene, rays, seed, leaf_sizes, svg, json, run } = a;
    check_rays(rays)?;
    let out = svg.as_deref().map(|d| OutDir::check(d, &raypipe::stats::SVG_FILES)).transpose()?;
    let scene = load_scene(scene.as_deref())?;
    let eng = run.engine(raypipe::traverse::CHUNK_RAYS);
    let rep = raypipe::stats::stats_on(&eng, !run.quiet, &scene, &leaf_sizes, rays as usize, seed)?;
    emit(json, &rep, raypipe::stats::render)?;
    if let Some(out) = out {
        for p in raypipe::stats::write_svgs(&rep, &out)? {
            eprintln!("wrote {}", p.display());
        }
    }
    Ok(rep.outcome())
}
