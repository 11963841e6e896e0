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
    /// Compare only these outputs (comma-separated; default: every output named like a model signal).
    #[arg(long, value_delimiter = ',')]
    pub outputs: Vec<String>,
    /// Solver: auto (bitwuzla for binary16/32/64/128 sorts, else cvc5), bitwuzla, cvc5, z3.
    #[arg(long, default_value = "auto")]
    pub solver: String,
    /// Give up on an output after this many seconds (0: no limit); a timeout proves nothing.
    #[arg(long, default_value_t = 600.0)]
    pub timeout: f64,
    /// Print the result as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Runs `raypipe equiv`.
pub fn run(a: Args) -> Result<Outcome, String> {
    check_solver(&a.solver, a.timeout)?;
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
