//! `raypipe vectors`: write a self-describing vector set for RTL testbenches (or check one with --check).

use super::prelude::*;

/// The options of `raypipe vectors`.
#[derive(clap::Args, Clone)]
pub struct Args {
    /// Unit: rti, slab, op, traverse or capture (the min-capture unit).
    #[arg(long, default_value = "rti")]
    pub unit: String,
    /// Number format (default f32, or the plan's narrowest format within its budget).
    #[arg(long, value_parser = parse_format)]
    pub format: Option<AnyFormat>,
    /// A plan (`raypipe plan --json`): its format, leaf size and level pipelines.
    #[arg(long)]
    pub plan: Option<PathBuf>,
    /// Output directory (replaced atomically).
    #[arg(long, required_unless_present = "check")]
    pub out: Option<PathBuf>,
    /// Vectors per coverage class.
    #[arg(long, default_value_t = 64)]
    pub count: u64,
    /// Seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Coverage level: 1 (every class on its own) or 2 (level 1 plus crossed classes).
    #[arg(long, default_value_t = 1)]
    pub level: u32,
    /// Worker threads (default: every core); the files do not depend on it.
    #[arg(long)]
    pub threads: Option<usize>,
    /// Slab variant (units slab and traverse): plain, conservative, take-on-false, embree.
    #[arg(long, default_value = "plain")]
    pub variant: String,
    /// Re-check an existing set against the models instead of writing one (a minimal set:
    /// also that it still detects every fault its manifest names).
    #[arg(long)]
    pub check: Option<PathBuf>,
    /// Write the minimal set: the fewest vectors of the default set (greedy set cover over
    /// the fault bank) that still detect every fault it detects from the outputs.
    #[arg(long, conflicts_with = "check")]
    pub minimal: bool,
    /// OBJ scene whose BVH the traverse unit uses (default: the built-in scene).
    #[arg(long)]
    pub scene: Option<PathBuf>,
    /// First N leaves per ray (unit traverse, 1..=255).
    #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u64).range(1..=255))]
    pub leaves: u64,
    /// Triangles per leaf at most (unit traverse, 1..=255; default 4, or the plan's).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=255))]
    pub leaf_size: Option<u32>,
    /// Level pipelines the hardware has (unit traverse; the history holds 2 bits per level;
    /// default 64, or the plan's).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..))]
    pub levels: Option<u64>,
    /// Also write a wrapper for a DUT with your own ports: `axis` writes `axis_map.json` (where
    /// each field sits on s_axis_tdata / m_axis_tdata) and `raypipe_axis_wrap.sv` into the set
    /// (streaming units: rti, slab, op, capture; see docs/your-dut.md).
    #[arg(long, value_parser = ["axis"])]
    pub wrapper: Option<String>,
    /// Your field map (an edited `axis_map.json`) for `--wrapper axis`, instead of the default
    /// packing (fields from bit 0 in file order).
    #[arg(long, requires = "wrapper")]
    pub axis_map: Option<PathBuf>,
    /// Close the coverage: append a class `close` of directed vectors, found by a seeded
    /// search, that reach the bins of the coverage model the set leaves empty (units rti, slab,
    /// op, capture; docs/coverage.md).
    #[arg(long, conflicts_with_all = ["check", "minimal"])]
    pub close: bool,
    /// Candidates the closure's search may measure at most.
    #[arg(long, default_value_t = vectors::close::DEFAULT_BUDGET, requires = "close")]
    pub close_budget: u64,
    /// Print what was written (or checked) as JSON.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub rti: RtiArgs,
}

/// Runs `raypipe vectors`.
pub fn run(a: Args) -> Result<Outcome, String> {
    let Args {
        unit,
        format,
        plan,
        out,
        count,
        seed,
        level,
        threads,
        variant,
        check,
        minimal,
        scene,
        leaves,
        leaf_size,
        levels,
        wrapper,
        axis_map,
        close,
        close_budget,
        json,
        rti,
    } = a;
    if let Some(dir) = check {
        let n = vectors::check::check_set(&dir)?;
        let detects = raypipe::faults::check_minimal(&dir)?;
        let j = serde_json::json!({
            "command": command_as_typed(),
            "checked": dir.display().to_string(),
            "vectors": n,
            "minimal_detects": detects,
        });
        emit(json, &j, |_| {
            let mut s = format!(
                "{}: {n} vectors; the manifest, the HDL packages and every input, expected and stage row are what this raypipe writes\n",
                dir.display()
            );
            if let Some(d) = detects {
                s += &format!("{}: a minimal set; it still detects all {d} faults its manifest names\n", dir.display());
            }
            s
        })?;
        return Ok(Outcome::Pass);
    }
    let out = out.ok_or("--out is required")?;
    limit("--count", count, MAX_VECTOR_COUNT, "a set is built in memory before it is written")?;
    vectors::write::check_out(&out)?;
    let unit: vectors::gen::Unit = unit.parse()?;
    if wrapper.is_some() && unit == vectors::gen::Unit::Traverse {
        return Err("--wrapper axis covers the streaming units (rti, slab, op, capture)".into());
    }
    if let Some(p) = &axis_map {
        // a map that does not read is refused before any work; its fields are checked below
        let text = std::fs::read_to_string(p).map_err(|e| format!("--axis-map {}: {e}", p.display()))?;
        serde_json::from_str::<vectors::axis::AxisMap>(&text)
            .map_err(|e| format!("--axis-map {}: {e}", p.display()))?;
    }
    // a plan fixes what the scene does not need: the format, the leaf size, the levels
    let plan = plan.as_deref().map(raypipe::plan::load).transpose()?;
    let format = match (format, &plan) {
        (Some(f), _) => f,
        (None, Some(p)) => p.narrowest()?,
        (None, None) => "f32".parse().expect("built-in format name"),
    };
    // the plan's leaf size and level pipelines, unless given (a conflict is refused)
    let (leaf_size, levels) = match &plan {
        Some(p) => {
            for (flag, given, planned) in [
                ("--leaf-size", leaf_size.map(u64::from), p.leaf_size as u64),
                ("--levels", levels, p.level_pipelines as u64),
            ] {
                if let Some(g) = given.filter(|&g| g != planned) {
                    return Err(format!("{flag} {g} conflicts with the plan's {planned}; drop one of them"));
                }
            }
            (p.leaf_size, p.level_pipelines as u64)
        }
        None => (leaf_size.unwrap_or(4), levels.unwrap_or(64)),
    };
    let tree = traverse_tree(unit, scene.as_deref(), leaf_size, plan.as_ref())?;
    let req = vectors::gen::Request {
        unit,
        tree,
        leaves: leaves as usize,
        max_levels: levels as usize,
        explicit: None,
        closure: None,
        threads: threads.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get())),
        format,
        count: count as usize,
        seed,
        level,
        command: command_without_threads(),
        rti: rti.config()?,
        slab_variant: variant,
    };
    let mut closure: Option<vectors::close::Closed> = None;
    let set = if close {
        limit("--close-budget", close_budget, 100_000_000, "the search measures candidates one batch at a time")?;
        let c = vectors::close::close(&req, close_budget)?;
        closure = Some(c.clone());
        c.set
    } else {
        vectors::gen::generate(&req)?
    };
    let mut minimal_line: Option<String> = None;
    let set = if minimal {
        let (cut, c) = faults::minimal::minimal(&set, &command_without_threads())?;
        let m = cut.manifest.minimal.as_ref().expect("a minimal set says so");
        minimal_line = Some(format!(
            "minimal set: {} of {} vectors ({:.1} %) detect the {} faults of the {} bank the default set detects from the outputs ({} escape both; see raypipe faults)",
            cut.manifest.files[0].rows,
            m.from_vectors,
            100.0 * cut.manifest.files[0].rows as f64 / m.from_vectors.max(1) as f64,
            m.detects.len(),
            cut.manifest.unit,
            c.escaped
        ));
        cut
    } else {
        set
    };
    let extra = match wrapper {
        Some(_) => vectors::axis::files_for(&set.manifest, axis_map.as_deref())?,
        None => Vec::new(),
    };
    vectors::write::write_set_with(&set, &out, &extra)?;
    let m = &set.manifest;
    let pct = |(h, n): (u64, u64)| 100.0 * h as f64 / n.max(1) as f64;
    let j = serde_json::json!({
        "command": command_as_typed(),
        "out": out.display().to_string(),
        "unit": m.unit,
        "format": m.format,
        "seed": m.seed,
        "vectors": m.files[0].rows,
        "classes": m.classes.iter().map(|c| serde_json::json!({"name": c.name, "count": c.count})).collect::<Vec<_>>(),
        "closure": closure.as_ref().map(|c| serde_json::json!({
            "bins_hit_before": c.before.0,
            "bins_before": c.before.1,
            "bins_hit_after": c.after.0,
            "bins_after": c.after.1,
            "candidates": c.candidates,
            "kept": c.kept,
        })),
        "minimal": m.minimal,
    });
    emit(json, &j, |_| {
        let mut s = String::new();
        if let Some(c) = &closure {
            s += &format!(
                "coverage closure: before {} of {} reachable bins ({:.1} %), after {} of {} ({:.1} %; the close class's own bin included); {} of {} candidates kept as class close\n",
                c.before.0,
                c.before.1,
                pct(c.before),
                c.after.0,
                c.after.1,
                pct(c.after),
                c.kept,
                c.candidates
            );
        }
        if let Some(l) = &minimal_line {
            s += l;
            s += "\n";
        }
        s += &format!(
            "wrote {}: unit {}, format {}, {} vectors ({}), seed {}\n",
            out.display(),
            m.unit,
            m.format,
            m.files[0].rows,
            m.classes.iter().map(|c| format!("{} {}", c.name, c.count)).collect::<Vec<_>>().join(", "),
            m.seed
        );
        s
    })?;
    Ok(Outcome::Pass)
}
