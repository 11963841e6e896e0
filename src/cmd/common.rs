//! What every command uses: argument parsers, the JSON-or-text output, scene loading, the
//! shard of a run and its partial file, the command line as typed.

use super::prelude::*;

/// A format name.
pub fn parse_format(s: &str) -> Result<AnyFormat, String> {
    s.parse()
}

/// A point or direction X,Y,Z (finite numbers).
pub fn parse_vec3(s: &str) -> Result<[f64; 3], String> {
    let v = parse_list("X,Y,Z", s, 3)?;
    Ok([v[0], v[1], v[2]])
}

/// A point or direction as the command line takes it back.
pub fn vec3(v: [f64; 3]) -> String {
    format!("{},{},{}", v[0], v[1], v[2])
}

/// `n` comma-separated finite numbers (`what` names the option in errors).
pub fn parse_list(what: &str, s: &str, n: usize) -> Result<Vec<f64>, String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|t| t.trim().parse::<f64>().map_err(|_| format!("{what}: '{t}' is not a number")))
        .collect::<Result<_, _>>()?;
    if v.len() != n {
        return Err(format!("{what}: expected {n} comma-separated numbers, got {}", v.len()));
    }
    if let Some(x) = v.iter().find(|x| !x.is_finite()) {
        return Err(format!("{what}: coordinates must be finite, got {x}"));
    }
    Ok(v)
}

/// The t interval of `explain`: both ends numbers (±inf allowed), tmin <= tmax, tmin not +inf
/// and tmax not -inf.
pub fn check_interval(tmin: f64, tmax: f64) -> Result<(), String> {
    for (name, v) in [("--tmin", tmin), ("--tmax", tmax)] {
        if v.is_nan() {
            return Err(format!("{name} must be a number, got NaN"));
        }
    }
    if tmin == f64::INFINITY || tmax == f64::NEG_INFINITY || tmin > tmax {
        return Err(format!(
            "the t interval [--tmin {tmin}, --tmax {tmax}] is empty: need tmin <= tmax, tmin < inf, tmax > -inf"
        ));
    }
    Ok(())
}

/// Prints `value` as JSON, or the text `render` gives.
pub fn emit<T: serde::Serialize>(json: bool, value: &T, render: impl FnOnce(&T) -> String) -> Result<(), String> {
    if json {
        println!("{}", serde_json::to_string_pretty(value).map_err(|e| e.to_string())?);
    } else {
        print!("{}", render(value));
    }
    Ok(())
}

/// Triangles tested per ray at most: each worker holds one ray's test list (4 bytes each).
/// Verify, plan and report stream their rays, so the number of rays is not limited.
pub const MAX_SAMPLE: u64 = 1 << 24;
/// Pairs per `speed` call at most (15 columns of 4 bytes: 1 GiB).
pub const MAX_SPEED_PAIRS: u64 = 1 << 24;
/// Vectors per class at most (the set is built in memory before it is written).
pub const MAX_VECTOR_COUNT: u64 = 100_000;

/// Refuses a size this build cannot serve, before any work.
pub fn limit(what: &str, n: u64, max: u64, why: &str) -> Result<(), String> {
    if n > max {
        return Err(format!("{what} = {n} is more than this command can hold: at most {max} ({why})"));
    }
    Ok(())
}

/// Rays of one verify / plan / report run at most. They are streamed (memory does not grow
/// with them), but 10¹¹ rays × 512 tests is already months of one machine: a larger campaign
/// is split into runs with different seeds.
pub const MAX_RAYS: u64 = 100_000_000_000;

/// Refuses more rays than one streamed run takes.
pub fn check_rays(rays: u64) -> Result<(), String> {
    limit("--rays", rays, MAX_RAYS, "a single streamed run; split a larger campaign into runs with different seeds")
}

/// Refuses a run this build cannot serve: too many rays, or a per-ray test list too long.
pub fn check_tests(rays: u64, _scene: &Scene, sample: u64) -> Result<(), String> {
    check_rays(rays)?;
    limit("--sample", sample, MAX_SAMPLE, "each worker holds one ray's test list")
}

/// The OBJ scene at `path`, or the built-in scene.
pub fn load_scene(path: Option<&std::path::Path>) -> Result<Scene, String> {
    match path {
        Some(p) => Scene::load_obj(p).map_err(|e| e.to_string()),
        None => Ok(Scene::builtin()),
    }
}

/// The RTI fault of the bank named `name` (`verify --inject`).
pub fn rti_fault(name: &str) -> Result<&'static faults::bank::Spec, String> {
    match faults::bank::by_name(name) {
        Some(x) if x.unit == "rti" => Ok(x),
        Some(x) => Err(format!(
            "--inject {name}: a {} fault; verify injects RTI faults (raypipe faults --unit rti lists them)",
            x.unit
        )),
        None => {
            Err(format!("--inject {name}: no such fault in the bank (raypipe faults --unit rti lists the RTI faults)"))
        }
    }
}

/// The shard of a run from `--shard` (checked against `--partial` before any work: a shard
/// needs a partial file to write, and the file must be one raypipe may write).
pub fn shard_of(shard: Option<&str>, partial: Option<&std::path::Path>) -> Result<engine::Shard, String> {
    let s = match shard {
        Some(s) => engine::Shard::parse(s, |v| std::env::var(v).ok())?,
        None => engine::Shard::ALL,
    };
    match partial {
        Some(p) => raypipe::partial::check_path(p)?,
        None if shard.is_some() => {
            return Err("--shard needs --partial FILE (merge the shards with raypipe merge)".into())
        }
        None => {}
    }
    Ok(s)
}

/// The end of a sharded command's run: with `--partial` the shard's data is written to that
/// file (and the shard passes: the verdict is the merge's); otherwise the data is finished
/// into the report, printed (JSON with `json`) and its outcome returned.
pub fn conclude<T: Sharded>(
    json: bool,
    partial: Option<&std::path::Path>,
    run: Run,
    data: T,
) -> Result<Outcome, String> {
    match partial {
        Some(path) => {
            let p = raypipe::partial::Partial::new(T::COMMAND, run.args, run.scene_hash, run.chunk, run.shard, data);
            shard_done(json, path, p)
        }
        None => finish_and_print(json, data),
    }
}

/// What identifies a sharded run in its partial: the options that change its results, the
/// scene's hash (empty without a scene), the chunk size and the shard.
pub struct Run {
    /// Every option that changes the results.
    pub args: serde_json::Value,
    /// [`raypipe::partial::scene_hash`], or empty.
    pub scene_hash: String,
    /// Items per chunk.
    pub chunk: u64,
    /// This run's shard.
    pub shard: engine::Shard,
}

/// Finishes (merged) data into its report, prints it and returns its outcome.
pub fn finish_and_print<T: Sharded>(json: bool, data: T) -> Result<Outcome, String> {
    let rep = data.finish()?;
    emit(json, &rep, T::render)?;
    Ok(T::outcome(&rep))
}

/// Writes a shard's partial result and says so (JSON with `json`); the shard's run passes.
pub fn shard_done<T: serde::Serialize>(
    json: bool,
    path: &std::path::Path,
    p: raypipe::partial::Partial<T>,
) -> Result<Outcome, String> {
    raypipe::partial::write(path, &p)?;
    let (command, shard) = (&p.command, p.shard);
    if json {
        let v = serde_json::json!({ "command": command, "shard": shard, "partial": path.display().to_string() });
        println!("{}", serde_json::to_string_pretty(&v).map_err(|e| e.to_string())?);
    } else {
        println!(
            "raypipe {command}: shard {shard} written to {} (merge every shard with raypipe merge)",
            path.display()
        );
    }
    Ok(Outcome::Pass)
}

/// The command line as a user types it: `raypipe` and the arguments, without `--threads`.
pub fn command_as_typed() -> String {
    let c = command_without_threads();
    match c.split_once(' ') {
        Some((_, rest)) => format!("raypipe {rest}"),
        None => "raypipe".to_string(),
    }
}

/// The command line as recorded in a vector set's manifest: without `--threads`, which does
/// not change a single byte of the set.
pub fn command_without_threads() -> String {
    let mut out = Vec::new();
    let mut args = std::env::args();
    while let Some(a) = args.next() {
        if a == "--threads" {
            args.next();
        } else if !a.starts_with("--threads=") {
            out.push(a);
        }
    }
    out.join(" ")
}

/// The BVH a traverse vector set uses: the scene's (default: the built-in one) built with
/// `leaf_size` triangles per leaf, checked against the plan when there is one; `None` for the
/// other units, which refuse `--scene`.
pub fn traverse_tree(
    unit: vectors::gen::Unit,
    scene: Option<&std::path::Path>,
    leaf_size: u32,
    plan: Option<&raypipe::plan::Plan>,
) -> Result<Option<vectors::traverse::TreeInput>, String> {
    if unit != vectors::gen::Unit::Traverse {
        return match scene {
            Some(_) => Err(format!("--scene is for unit traverse; unit {unit:?} draws its own cases")),
            None => Ok(None),
        };
    }
    let scene = load_scene(scene)?;
    if let Some(p) = plan {
        p.check_scene(&scene)?;
    }
    let b = raypipe::bvh::build(&scene, leaf_size);
    Ok(Some(vectors::traverse::TreeInput { name: scene.name.clone(), nodes: b.nodes, root: 0 }))
}

/// Writes a proof's counterexample as a one-vector set of class `smt` of the rti or slab unit
/// to `out`, with the model's expected outputs and stage signals: the row is the witness's
/// value of `{key_prefix}NAME` for each input NAME of the unit. Returns the set's directory.
#[allow(clippy::too_many_arguments)]
pub fn write_smt_set(
    out: &std::path::Path,
    unit: vectors::gen::Unit,
    format: AnyFormat,
    rti: datapath::rti::RtiConfig,
    variant: &str,
    covers: String,
    witness: &[(String, u64)],
    key_prefix: &str,
) -> Result<std::path::PathBuf, String> {
    let names: &[&str] = match unit {
        vectors::gen::Unit::Rti => &datapath::rti::RTI_INPUTS,
        vectors::gen::Unit::Slab => &datapath::slab::SLAB_INPUTS,
        other => return Err(format!("a counterexample set is of the rti or slab unit, not {other:?}")),
    };
    let row: Vec<u64> = names
        .iter()
        .map(|n| {
            let key = format!("{key_prefix}{n}");
            witness.iter().find(|(k, _)| *k == key).map(|(_, v)| *v).ok_or(format!("the witness has no {key}"))
        })
        .collect::<Result<_, _>>()?;
    let req = vectors::gen::Request {
        unit,
        format,
        count: 1,
        seed: 0,
        level: 1,
        threads: 1,
        command: command_as_typed(),
        rti,
        slab_variant: variant.to_string(),
        tree: None,
        leaves: 8,
        max_levels: 64,
        explicit: Some(vectors::gen::Explicit {
            class: "smt".into(),
            covers,
            origin: command_as_typed(),
            rows: vec![row],
        }),
        closure: None,
    };
    let set = vectors::gen::generate(&req)?;
    vectors::write::write_set(&set, out)
}

/// Refuses an output file (`flag`) raypipe may not write, before any work: a directory, a
/// missing parent directory, or an existing file whose first lines do not hold `marker`.
pub fn check_written_path(flag: &str, path: &std::path::Path, marker: &str) -> Result<(), String> {
    let ours = |text: &str| text.lines().take(4).any(|l| l.contains(marker));
    vectors::outdir::check_file_out(flag, path, ours, "raypipe did not write it")
}

/// Limits every kernel dispatch of the process to `cap` (`--cap`: scalar, avx2, avx512 or
/// avx512fp16; the bits do not change, only the instructions): a narrower machine's speed.
pub fn apply_cap(cap: Option<&str>) {
    use datapath::simd::Kernel;
    if let Some(c) = cap {
        let k = match c {
            "scalar" => Kernel::Scalar,
            "avx2" => Kernel::Avx2,
            "avx512" => Kernel::Avx512,
            _ => Kernel::Avx512Fp16,
        };
        datapath::simd::cap_process(k);
    }
}
