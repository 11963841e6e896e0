//! `raypipe faults`: run the fault bank against a vector set: which hardware bugs the set detects.

use super::prelude::*;

/// The options of `raypipe faults`.
#[derive(clap::Args, Clone)]
pub struct Args {
    /// Unit (units with a fault bank: rti, slab, capture, traverse, op).
    #[arg(long, default_value = "rti")]
    pub unit: String,
    /// OBJ scene whose BVH the generated traverse set uses (default: the built-in scene;
    /// leaf size 4, first 8 leaves).
    #[arg(long, conflicts_with = "set")]
    pub scene: Option<PathBuf>,
    /// Slab variant of the generated set (unit slab): plain, conservative, take-on-false, embree.
    #[arg(long, default_value = "plain", conflicts_with = "set")]
    pub variant: String,
    /// Number format of the generated set (default f32).
    #[arg(long, value_parser = parse_format)]
    pub format: Option<AnyFormat>,
    /// Coverage level of the generated set: 1 or 2.
    #[arg(long, default_value_t = 1)]
    pub level: u32,
    /// Vectors per coverage class of the generated set.
    #[arg(long, default_value_t = 64)]
    pub count: u64,
    /// Seed of the generated set.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Compare only the outputs (rti: valid, hit, t, u, v; slab: hit, t_near, t_far), as for
    /// a DUT without probe ports.
    #[arg(long)]
    pub outputs_only: bool,
    /// Run on the set in this directory instead of generating one (its unit, format and options).
    #[arg(long, conflicts_with_all = ["format", "level", "count", "seed"])]
    pub set: Option<PathBuf>,
    /// Print the campaign as JSON.
    #[arg(long)]
    pub json: bool,
    /// Worker threads for generating the set (the result does not depend on it).
    #[arg(long)]
    pub threads: Option<usize>,
    #[command(flatten)]
    pub rti: RtiArgs,
}

/// Runs `raypipe faults`.
pub fn run(a: Args) -> Result<Outcome, String> {
    let Args { unit, scene, variant, format, level, count, seed, outputs_only, set, json, threads, rti } = a;
    let c = match set {
        Some(dir) => raypipe::faults::on_dir(&dir, outputs_only)?,
        None => {
            limit("--count", count, MAX_VECTOR_COUNT, "a set is built in memory")?;
            let unit: vectors::gen::Unit = unit.parse()?;
            let tree = traverse_tree(unit, scene.as_deref(), 4, None)?;
            let req = vectors::gen::Request {
                unit,
                tree,
                leaves: 8,
                max_levels: 64,
                explicit: None,
                closure: None,
                threads: threads.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get())),
                format: format.unwrap_or_else(|| "f32".parse().expect("built-in format name")),
                count: count as usize,
                seed,
                level,
                command: command_without_threads(),
                rti: rti.config()?,
                slab_variant: variant,
            };
            raypipe::faults::on_request(&req, outputs_only)?
        }
    };
    emit(json, &c, raypipe::faults::render)?;
    Ok(Outcome::from(c.complete()))
}
