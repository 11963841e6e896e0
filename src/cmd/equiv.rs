//! `raypipe equiv`: prove a Verilog DUT's outputs equal to the model's signals of the same
//! names for every input — yosys writes the DUT as SMT-LIB, a solver checks the miter with the
//! emitted model (docs/proofs.md). Exit 0 PROVEN, 1 counterexample (replayed in Icarus),
//! 3 unknown (a timeout proves nothing).

use super::prelude::*;

/// The options of `raypipe equiv`.
#[derive(clap::Args, Clone)]
pub struct Args {
    /// A Verilog source of the DUT (repeat for several; `.sv` files are read as SystemVerilog).
    #[arg(long, required = true)]
    pub rtl: Vec<PathBuf>,
    /// An include directory (repeat for several).
    #[arg(long)]
    pub incdir: Vec<PathBuf>,
    /// A preprocessor define, NAME or NAME=VALUE (repeat for several).
    #[arg(long)]
    pub define: Vec<String>,
    /// The DUT's top module.
    #[arg(long)]
    pub top: String,
    /// A top-module parameter, NAME=VALUE (repeat for several).
    #[arg(long)]
    pub param: Vec<String>,
    /// Unit of the model: rti, slab or op.
    #[arg(long, default_value = "op")]
    pub unit: String,
    /// Format of the model.
    #[arg(long, default_value = "fp16")]
    pub format: String,
    /// Slab variant of the model.
    #[arg(long, default_value = "plain")]
    pub variant: String,
    /// RTI options.
    #[command(flatten)]
    pub rti: RtiArgs,
    /// Compare only these outputs (comma-separated; default: every output named like a model
    /// signal); with --stage-row: prove only these stage signals.
    #[arg(long, value_delimiter = ',')]
    pub outputs: Vec<String>,
    /// Solver: auto (bitwuzla for binary16/32/64/128 sorts, else cvc5), bitwuzla, cvc5, z3.
    #[arg(long, default_value = "auto")]
    pub solver: String,
    /// Give up on an output after this many seconds (0: no limit); a timeout proves nothing.
    #[arg(long, default_value_t = 600.0)]
    pub timeout: f64,
    /// The vector set the DUT is built for (its package is read with the sources; its manifest
    /// gives the unit, format, variant, options and row layouts). Needed with --stage-row.
    #[arg(long)]
    pub set: Option<PathBuf>,
    /// A pipelined DUT's row register: `in=REG` (the input register), or `K=[IN]:[STG][@EDGES]`
    /// (the registers holding the row after table stage K: inputs part, stage-signal part, and
    /// the clock edges from the previous row, 1 by default). Repeat for every row; proves the
    /// DUT stage by stage (docs/proofs.md).
    #[arg(long = "stage-row")]
    pub stage_row: Vec<String>,
    /// Bounded model checking of a stage of several edges: the transaction enters at each
    /// cycle 1..=P after reset (default: the stage's edges - 1).
    #[arg(long)]
    pub phases: Option<u32>,
    /// With --stage-row: replace every instance of MODULE (ports a, b, y; every other port tied
    /// to a constant) by its operation OP (mul: a × b; add: a + b, or a − b with `sub` tied to
    /// 1), rounded to nearest-even, after proving the module alone equal to it (repeat for
    /// several modules; docs/proofs.md).
    #[arg(long = "abstract")]
    pub abstract_: Vec<String>,
    /// With --abstract: also use an abstraction whose module-alone proof did not finish in
    /// --timeout (never a refuted one); a proof is then PROVEN only IF those modules are (exit 3).
    #[arg(long)]
    pub trust_unfinished: bool,
    /// With --stage-row: search a whole-input counterexample for the first stage signal that
    /// differs (bounded model checking from reset through every earlier stage, one transaction)
    /// and write it to DIR as a vector set (class smt) the kit's runner replays in a simulator.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Queries run at once (default: the machine's cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Print the result as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Runs `raypipe equiv`.
pub fn run(a: Args) -> Result<Outcome, String> {
    check_solver(&a.solver, a.timeout)?;
    if !a.stage_row.is_empty() || a.set.is_some() {
        return run_stages(&a);
    }
    if !a.abstract_.is_empty() {
        return Err("--abstract replaces modules in a stage-by-stage proof: give --set and --stage-row".into());
    }
    if a.out.is_some() {
        return Err("--out writes a pipelined DUT's whole-input counterexample: give --set and --stage-row (a combinational counterexample is replayed in Icarus directly)".into());
    }
    let params = a
        .param
        .iter()
        .map(|p| p.split_once('=').map(|(k, v)| (k.to_string(), v.to_string())))
        .collect::<Option<Vec<_>>>()
        .ok_or("--param takes NAME=VALUE")?;
    let req = super::smt::request(&a.unit, &a.format, &a.variant, &a.rti, &SlabMutation::default())?;
    let model = formal::smt::emit(&req)?;
    let dut = formal::equiv::Dut {
        rtl: a.rtl.clone(),
        incdirs: a.incdir.clone(),
        defines: a.define.clone(),
        top: a.top.clone(),
        params,
    };
    let work = std::env::temp_dir().join(format!("raypipe-equiv-{}", std::process::id()));
    std::fs::create_dir_all(&work).map_err(|e| format!("{}: {e}", work.display()))?;
    let result = prove_in(&a, &model, &dut, &work);
    let _ = std::fs::remove_dir_all(&work);
    result
}

fn prove_in(
    a: &Args,
    model: &formal::smt::Model,
    dut: &formal::equiv::Dut,
    work: &std::path::Path,
) -> Result<Outcome, String> {
    let ds = formal::equiv::dut_smt(dut, work)?;
    let mut plan = formal::equiv::plan(model, &ds)?;
    if !a.outputs.is_empty() {
        if let Some(o) = a.outputs.iter().find(|o| !plan.compared.contains(o)) {
            return Err(format!(
                "--outputs {o}: not an output of {} named like a model signal ({})",
                ds.module,
                plan.compared.join(", ")
            ));
        }
        let (keep, drop): (Vec<String>, Vec<String>) = plan.compared.into_iter().partition(|o| a.outputs.contains(o));
        plan.compared = keep;
        plan.ignored.extend(drop);
    }
    let t0 = std::time::Instant::now();
    let proofs = formal::equiv::prove(model, &ds, &plan, &a.solver, a.timeout)?;
    // every counterexample replayed in Icarus: the DUT's value there must be the solver's
    let mut replays = Vec::new();
    for p in &proofs {
        if let Some(w) = &p.witness {
            let sim = formal::equiv::replay_icarus(dut, &ds, w, work)
                .map(|vals| vals.iter().find(|(n, _)| *n == p.name).map(|x| x.1));
            replays.push((p.name.clone(), sim));
        }
    }
    let status = if proofs.iter().all(|p| p.verdict.result == "unsat") {
        "PROVEN"
    } else if proofs.iter().any(|p| {
        p.witness.as_ref().is_some_and(|w| {
            replays.iter().any(|(n, s)| *n == p.name && matches!(s, Ok(Some(v)) if *v == w.dut && *v != w.model))
        })
    }) {
        "COUNTEREXAMPLE"
    } else {
        "UNKNOWN"
    };
    let seconds = t0.elapsed().as_secs_f64();
    let hex = |v: u64| format!("{v:#x}");
    let j = serde_json::json!({
        "command": command_as_typed(),
        "status": status,
        "top": a.top,
        "unit": a.unit,
        "format": a.format,
        "yosys": ds.yosys,
        "seconds": seconds,
        "ignored_outputs": plan.ignored,
        "outputs": proofs.iter().map(|p| {
            let replay = replays.iter().find(|(n, _)| *n == p.name).map(|(_, s)| match s {
                Ok(Some(v)) => serde_json::json!(hex(*v)),
                Ok(None) => serde_json::json!("no value printed"),
                Err(e) => serde_json::json!(e),
            });
            serde_json::json!({
                "name": p.name,
                "result": p.verdict.result,
                "solver": p.verdict.solver,
                "solver_version": p.verdict.version,
                "seconds": p.verdict.seconds,
                "counterexample": p.witness.as_ref().map(|w| serde_json::json!({
                    "inputs": w.inputs.iter().map(|(n, v)| (n.clone(), serde_json::json!(hex(*v)))).collect::<serde_json::Map<_, _>>(),
                    "dut": hex(w.dut),
                    "model": hex(w.model),
                    "icarus": replay,
                })),
            })
        }).collect::<Vec<_>>(),
    });
    emit(a.json, &j, |_| {
        let mut s = format!(
            "equiv {} vs the {} model in {}: {status} ({} outputs, {:.1} s; {})\n",
            a.top,
            a.unit,
            a.format,
            proofs.len(),
            seconds,
            ds.yosys
        );
        for p in &proofs {
            s += &format!(
                "  {}: {} ({} {} {:.1} s)\n",
                p.name,
                match p.verdict.result.as_str() {
                    "unsat" => "equal for every input",
                    "sat" => "DIFFERS",
                    _ => "unknown",
                },
                p.verdict.solver,
                p.verdict.version,
                p.verdict.seconds
            );
            if let Some(w) = &p.witness {
                let ins: Vec<String> = w.inputs.iter().map(|(n, v)| format!("{n}={}", hex(*v))).collect();
                s += &format!("    inputs {}: DUT {}, model {}", ins.join(" "), hex(w.dut), hex(w.model));
                match replays.iter().find(|(n, _)| *n == p.name).map(|(_, r)| r) {
                    Some(Ok(Some(v))) => s += &format!("; Icarus replay: DUT {}\n", hex(*v)),
                    Some(Ok(None)) => s += "; Icarus replay printed no value\n",
                    Some(Err(e)) => s += &format!("; Icarus replay failed: {e}\n"),
                    None => s += "\n",
                }
            }
        }
        if !plan.ignored.is_empty() {
            s += &format!("not compared: {}\n", plan.ignored.join(", "));
        }
        s
    })?;
    Ok(match status {
        "PROVEN" => Outcome::Pass,
        "COUNTEREXAMPLE" => Outcome::Fail,
        _ => Outcome::Inconclusive,
    })
}

/// Writes a pipelined DUT's whole-input counterexample (the witness's `in_*` values) as a
/// one-vector set of class `smt`; returns the set's directory.
fn write_whole(
    out: &std::path::Path,
    m: &vectors::manifest::Manifest,
    req: &formal::smt::Request,
    witness: &[(String, u64)],
) -> Result<PathBuf, String> {
    write_smt_set(
        out,
        if req.unit == formal::smt::Unit::Rti { vectors::gen::Unit::Rti } else { vectors::gen::Unit::Slab },
        req.format,
        req.rti,
        &req.variant,
        format!(
            "a counterexample of raypipe equiv: an input row on which the DUT's stage registers differ from the {} model ({} in {})",
            m.unit, m.unit, m.format
        ),
        witness,
        "in_",
    )
}

/// The set's row layouts, from its manifest.
fn layout(m: &vectors::manifest::Manifest) -> Result<formal::equiv::stages::Layout, String> {
    use formal::equiv::stages::{FieldPos, Layout};
    let pos = |f: &vectors::manifest::File| -> Vec<FieldPos> {
        f.fields.iter().map(|x| FieldPos { name: x.name.clone(), lsb: x.lsb, width: x.width }).collect()
    };
    let inputs = m.files.first().ok_or("manifest.json: no input file")?;
    let outputs = m.files.get(1).ok_or("manifest.json: no expected-output file")?;
    let stages = m
        .files
        .iter()
        .find(|f| f.role == vectors::hdl::STAGE_ROLE)
        .ok_or("the set has no stage-signal file (write it without --no-stages)")?;
    Ok(Layout {
        inputs: pos(inputs),
        in_w: inputs.width,
        stages: pos(stages),
        stg_w: stages.width,
        outputs: pos(outputs),
        out_w: outputs.width,
    })
}

/// `raypipe equiv --set DIR --stage-row ...`: a pipelined DUT proven stage by stage.
fn run_stages(a: &Args) -> Result<Outcome, String> {
    let set = a.set.as_ref().ok_or("--stage-row needs --set DIR (the vector set the DUT is built for)")?;
    if a.stage_row.is_empty() {
        return Err("--set proves a pipelined DUT: name its row registers with --stage-row".into());
    }
    if !a.param.is_empty() {
        return Err("--param: a pipelined DUT takes its parameters from the set's package".into());
    }
    let m = vectors::manifest::Manifest::read(set)?;
    let unit: formal::smt::Unit = m.unit.parse().map_err(|e| format!("{}: {e}", set.display()))?;
    if unit == formal::smt::Unit::Op {
        return Err("the op unit is combinational: prove it without --set and --stage-row".into());
    }
    let format: AnyFormat = m.format.parse().map_err(|e| format!("manifest.json: format: {e}"))?;
    let req = formal::smt::Request {
        unit,
        format,
        rti: if unit == formal::smt::Unit::Rti { vectors::read::rti_config_from(&m)? } else { RtiConfig::default() },
        variant: m.options.get("variant").cloned().unwrap_or_else(|| "plain".into()),
        widen: None,
        no_guard: false,
    };
    if let Some(out) = &a.out {
        // before the work: never overwrite what raypipe did not write
        vectors::write::check_out(out)?;
    }
    let lay = layout(&m)?;
    let rows = a.stage_row.iter().map(|s| formal::equiv::stages::parse_row(s)).collect::<Result<Vec<_>, _>>()?;
    let pkg = set.join("raypipe_pkg.sv");
    if !pkg.is_file() {
        return Err(format!("{}: no such file (the set's SystemVerilog package)", pkg.display()));
    }
    let mut rtl = vec![pkg];
    rtl.extend(a.rtl.iter().cloned());
    let dut = formal::equiv::Dut {
        rtl,
        incdirs: a.incdir.clone(),
        defines: a.define.clone(),
        top: a.top.clone(),
        params: Vec::new(),
    };
    let threads = a.threads.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get())).max(1);
    let work = std::env::temp_dir().join(format!("raypipe-equiv-{}", std::process::id()));
    std::fs::create_dir_all(&work).map_err(|e| format!("{}: {e}", work.display()))?;
    let t0 = std::time::Instant::now();
    let abs = a.abstract_.iter().map(|s| formal::equiv::abstraction::parse(s)).collect::<Result<Vec<_>, _>>()?;
    let result = formal::equiv::stages::elaborate(&dut, &abs, &work).and_then(|n| {
        let set = formal::equiv::stages::Settings {
            phases: a.phases,
            only: a.outputs.clone(),
            solver: a.solver.clone(),
            timeout_s: a.timeout,
            threads,
            trust_unfinished: a.trust_unfinished,
            whole_input: a.out.is_some(),
        };
        formal::equiv::stages::prove(&req, &n, &rows, &lay, &set, &work)
    });
    let _ = std::fs::remove_dir_all(&work);
    let formal::equiv::stages::Proof { steps: proofs, plan, whole } = result?;
    // the whole-input counterexample as a vector set: the witness row with the model's expected
    // outputs and stage signals, which the DUT fails
    let written = match (&a.out, &whole) {
        (Some(out), Some(w)) if w.verdict.result == "sat" => Some(write_whole(out, &m, &req, &w.witness)?),
        _ => None,
    };
    let seconds = t0.elapsed().as_secs_f64();
    use formal::equiv::stages::Goal;
    // the DUT's verdict comes from the steps; a module proof only decides whether its
    // abstraction was used (a refuted or unfinished module's instances stay concrete), except
    // an unfinished one used under --trust-unfinished, which the verdict is conditional on
    let is_module = |p: &&formal::equiv::stages::StepProof| matches!(p.goal, Goal::Module(..));
    let trusted: Vec<String> = proofs
        .iter()
        .filter(|p| is_module(p) && p.verdict.result != "unsat")
        .filter_map(|p| match &p.goal {
            Goal::Module(g, s) if plan.instances.iter().any(|i| i.group == *g) => Some(s.clone()),
            _ => None,
        })
        .collect();
    let steps: Vec<&formal::equiv::stages::StepProof> = proofs.iter().filter(|p| !is_module(p)).collect();
    // a proof of some signals only (--outputs) proves the DUT equal on those
    let status = if steps.iter().all(|p| p.verdict.result == "unsat") {
        if !trusted.is_empty() {
            "PROVEN IF the modules trusted are their operations"
        } else if a.outputs.is_empty() {
            "PROVEN"
        } else {
            "PROVEN (the signals named)"
        }
    } else if steps.iter().any(|p| p.verdict.result == "sat") {
        "COUNTEREXAMPLE"
    } else {
        "UNKNOWN"
    };
    let goal_name = |g: &Goal| match g {
        Goal::Signal(s) => s.clone(),
        Goal::Carried => "(carried fields)".to_string(),
        Goal::Ports => "(out_row, stg_row)".to_string(),
        Goal::Module(_, s) => s.clone(),
        Goal::Latency(l, p) => format!("(out_valid {l} edges after in_valid, entries 1..={p})"),
    };
    let stages_of = |p: &formal::equiv::stages::StepProof| match (p.stages, &p.goal) {
        (Some((lo, hi)), _) if lo == hi => format!("{lo}"),
        (Some((lo, hi)), _) => format!("{lo}..={hi}"),
        (None, Goal::Module(..)) => "module".into(),
        (None, Goal::Latency(..)) => "valid".into(),
        (None, _) => "ports".into(),
    };
    let hex = |v: u64| format!("{v:#x}");
    let witness_json = |p: &formal::equiv::stages::StepProof| {
        (!p.witness.is_empty()).then(|| {
            p.witness.iter().map(|(k, v)| (k.clone(), serde_json::json!(hex(*v)))).collect::<serde_json::Map<_, _>>()
        })
    };
    let j = serde_json::json!({
        "command": command_as_typed(),
        "status": status,
        "top": a.top,
        "set": set.display().to_string(),
        "unit": m.unit,
        "format": m.format,
        "seconds": seconds,
        "abstraction": {
            "instances": plan.instances.iter().map(|i| &i.name).collect::<Vec<_>>(),
            "concrete": plan.concrete.iter().map(|(n, why)| serde_json::json!({"instance": n, "why": why})).collect::<Vec<_>>(),
            "trusted_unproven": trusted,
        },
        "whole_input": whole.as_ref().map(|p| serde_json::json!({
            "goal": goal_name(&p.goal),
            "method": p.method,
            "result": p.verdict.result,
            "seconds": p.verdict.seconds,
            "counterexample": witness_json(p),
            "vectors": written.as_ref().map(|d| d.display().to_string()),
        })),
        "steps": proofs.iter().map(|p| serde_json::json!({
            "stages": stages_of(p),
            "method": p.method,
            "goal": goal_name(&p.goal),
            "result": p.verdict.result,
            "solver": p.verdict.solver,
            "solver_version": p.verdict.version,
            "seconds": p.verdict.seconds,
            "counterexample": witness_json(p),
        })).collect::<Vec<_>>(),
    });
    emit(a.json, &j, |_| {
        let mut s = format!(
            "equiv {} (pipelined, stage by stage) vs the {} model in {} of {}: {status} ({} queries, {:.1} s)\n",
            a.top,
            m.unit,
            m.format,
            set.display(),
            proofs.len(),
            seconds
        );
        if !plan.instances.is_empty() {
            let names: Vec<&str> = plan.instances.iter().map(|i| i.name.as_str()).collect();
            s += &format!("  abstracted (each module proven alone below): {}\n", names.join(" "));
        }
        for (n, why) in &plan.concrete {
            s += &format!("  left concrete: {n}: {why}\n");
        }
        for t in &trusted {
            s += &format!("  TRUSTED, not proven (--trust-unfinished): {t}\n");
        }
        for p in &proofs {
            s += &format!(
                "  stage {:>5} {:<22} {}: {} ({} {:.1} s)\n",
                stages_of(p),
                goal_name(&p.goal),
                p.method,
                match p.verdict.result.as_str() {
                    "unsat" => "equal",
                    "sat" => "DIFFERS",
                    _ => "unknown",
                },
                p.verdict.solver,
                p.verdict.seconds
            );
            if !p.witness.is_empty() {
                let w: Vec<String> = p.witness.iter().map(|(k, v)| format!("{k}={}", hex(*v))).collect();
                s += &format!("      {}\n", w.join(" "));
            }
        }
        if let Some(p) = &whole {
            s += &format!(
                "  whole input, {}: {} ({}, {:.1} s)\n",
                goal_name(&p.goal),
                match p.verdict.result.as_str() {
                    "sat" => "a whole input row differs",
                    "unsat" => "no single transaction from reset reaches the difference",
                    _ => "unknown",
                },
                p.method,
                p.verdict.seconds
            );
            if let Some(d) = &written {
                s += &format!("  vector set (class smt): {} — replay it with your kit runner (hdl/run)\n", d.display());
            }
        }
        s
    })?;
    Ok(match status {
        "PROVEN" | "PROVEN (the signals named)" => Outcome::Pass,
        "COUNTEREXAMPLE" => Outcome::Fail,
        _ => Outcome::Inconclusive,
    })
}
