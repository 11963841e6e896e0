//! `raypipe prove`: prove one of raypipe's guarantees (docs/proofs.md): by SMT solver and
//! enumeration (slab-never-misses), enumeration and a written composition (rti-bound) or
//! explicit-state search (history-equals-stack).
//! Exit 0 PROVEN, 1 counterexample, 3 unknown (timeout: nothing proven).

use super::prelude::*;
use datapath::Format;

/// The options of `raypipe prove`.
#[derive(clap::Args, Clone)]
pub struct Args {
    /// Property: slab-never-misses, rti-bound, history-equals-stack.
    pub property: String,
    /// Format (default fp16). slab-never-misses: floats of at most 16 bits (fp16, bf16, eEmM);
    /// with --variant directed also saturating fixed point of at most 16 bits (q8.8, ...).
    /// rti-bound: fp16 and small eEmM without FTZ, recip-mul or :divide.
    #[arg(long)]
    pub format: Option<String>,
    /// Slab variant of slab-never-misses: conservative (default) or directed.
    #[arg(long)]
    pub variant: Option<String>,
    /// history-equals-stack: every tree of 1 to this many levels (at most 6).
    #[arg(long, default_value_t = 6)]
    pub depth: usize,
    /// history-equals-stack: every N (leaves asked for) from 0 to this (at most 8; 4 at depth 6).
    #[arg(long, default_value_t = 4)]
    pub n: usize,
    /// history-equals-stack: also offer NaN entry distances (checks that NaN orders as a tie).
    #[arg(long)]
    pub nan: bool,
    /// A mutant the proof must refute. history-equals-stack: of the control logic
    /// (resume-shallowest, no-reset-deeper, no-mark-split, one-pass, ties-right, no-mark-pass);
    /// rti-bound: of the error model (no-eta, u-sixteenth).
    #[arg(long)]
    pub mutant: Option<String>,
    /// Slab variant changes (a mutant the proof must refute).
    #[command(flatten)]
    pub mutation: SlabMutation,
    /// Solver: auto (bitwuzla for binary16/32/64/128 sorts, else cvc5), bitwuzla, cvc5, z3.
    #[arg(long, default_value = "auto")]
    pub solver: String,
    /// Give up after this many seconds (0: no limit); a timeout proves nothing (exit 3).
    #[arg(long, default_value_t = 600.0)]
    pub timeout: f64,
    /// Threads of an exhaustive enumeration (default: every core); the result does not depend on it.
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=1024))]
    pub threads: Option<u64>,
    /// slab-never-misses: write a counterexample as a vector set (class smt) to DIR.
    #[arg(long)]
    pub out: Option<std::path::PathBuf>,
    /// Print the result as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Runs `raypipe prove`.
pub fn run(a: Args) -> Result<Outcome, String> {
    check_solver(&a.solver, a.timeout)?;
    if a.property == "history-equals-stack" {
        return history(&a);
    }
    if a.property == "rti-bound" {
        return rti_bound(&a);
    }
    if a.mutant.is_some() || a.nan {
        return Err("--mutant belongs to history-equals-stack and rti-bound, --nan to history-equals-stack".into());
    }
    if let Some(out) = &a.out {
        // before the work: never overwrite what raypipe did not write
        vectors::write::check_out(out)?;
    }
    let format = a.format.clone().unwrap_or_else(|| "fp16".into());
    let variant = a.variant.clone().unwrap_or_else(|| "conservative".into());
    let p = match a.property.as_str() {
        "slab-never-misses" => {
            let req = super::smt::request_slab(&format, &variant, &a.mutation)?;
            formal::prove::slab::prove(&req, &a.solver, a.timeout, threads(a.threads))?
        }
        other => {
            return Err(format!(
                "unknown property '{other}'; properties: slab-never-misses, rti-bound, history-equals-stack"
            ))
        }
    };
    let explain = (p.verdict.result == "sat").then(|| explain_command(&format, &variant, &a.mutation, &p));
    let written = match (&a.out, p.verdict.result.as_str()) {
        (Some(out), "sat") => Some(write_counterexample(out, &format, &variant, &a.mutation, &p)?),
        _ => None,
    };
    let j = serde_json::json!({
        "command": command_as_typed(),
        "property": p.property,
        "format": p.format,
        "variant": variant,
        "mutation": a.mutation.flags().trim(),
        "status": p.status(),
        "theorem": p.theorem,
        "solver": p.verdict.solver,
        "solver_version": p.verdict.version,
        "seconds": p.verdict.seconds,
        "witness": p.witness.iter().map(|(n, v)| (n.clone(), serde_json::json!(format!("{v:#x}")))).collect::<serde_json::Map<_, _>>(),
        "explain": explain,
        "vectors": written.as_ref().map(|d| d.display().to_string()),
        "steps": p.steps.iter().map(|(what, v)| serde_json::json!({"query": what, "result": v.result, "solver": v.solver, "seconds": v.seconds})).collect::<Vec<_>>(),
    });
    emit(a.json, &j, |_| {
        let mut s = format!(
            "{}: {} for {} (variant {}{}) — {} {} in {:.1} s\n",
            p.property,
            p.status(),
            p.format,
            variant,
            a.mutation.flags(),
            p.verdict.solver,
            p.verdict.version,
            p.verdict.seconds
        );
        for (what, v) in &p.steps {
            s += &format!("  {what}: {} ({} {:.1} s)\n", v.result, v.solver, v.seconds);
        }
        match p.status() {
            "PROVEN" => s += &format!("theorem: {}\n", p.theorem),
            "COUNTEREXAMPLE" => {
                s += &format!(
                    "counterexample: {}\nreproduce: {}\n",
                    p.witness.iter().map(|(n, v)| format!("{n}={v:#x}")).collect::<Vec<_>>().join(" "),
                    explain.clone().unwrap_or_default()
                );
                if let Some(d) = &written {
                    s += &format!("vector set (class smt): {}\n", d.display());
                }
            }
            _ => s += "nothing proven: the solver gave up (raise --timeout)\n",
        }
        s
    })?;
    Ok(match p.status() {
        "PROVEN" => Outcome::Pass,
        "COUNTEREXAMPLE" => Outcome::Fail,
        _ => Outcome::Inconclusive,
    })
}

/// `raypipe prove history-equals-stack`: the explicit-state search over the history control.
fn history(a: &Args) -> Result<Outcome, String> {
    if a.out.is_some() {
        return Err("history-equals-stack prints its counterexample tree; --out writes slab vector sets".into());
    }
    if a.format.is_some() || a.variant.is_some() || !a.mutation.flags().is_empty() {
        return Err("history-equals-stack is about the traversal's control logic: --format, --variant, --widen and --no-guard do not apply".into());
    }
    let mutant =
        a.mutant.as_deref().map_or(Ok(formal::prove::history::Mutant::None), formal::prove::history::Mutant::parse)?;
    let p = formal::prove::history::prove(a.depth, a.n, a.nan, mutant, threads(a.threads))?;
    let j = serde_json::json!({
        "command": command_as_typed(),
        "property": "history-equals-stack",
        "depth": a.depth,
        "n": a.n,
        "nan": a.nan,
        "mutant": a.mutant,
        "status": p.status,
        "statement": p.statement,
        "method": "explicit-state search over datapath::bvh::history_pass_faulty (docs/proofs.md)",
        "seconds": p.seconds,
        "states": p.cases.iter().map(|&(levels, n, states)| serde_json::json!({"levels": levels, "n": n, "states": states})).collect::<Vec<_>>(),
        "counterexample": p.counterexample,
    });
    emit(a.json, &j, |_| {
        let states: u64 = p.cases.iter().map(|c| c.2).sum();
        let mut s = format!(
            "history-equals-stack: {} for 1..={} levels, N 0..={}{}{} — explicit-state search, {} merged states in {:.1} s\n",
            p.status,
            a.depth,
            a.n,
            if a.nan { ", NaN entries" } else { "" },
            a.mutant.as_ref().map_or(String::new(), |m| format!(", mutant {m}")),
            states,
            p.seconds
        );
        match p.status {
            "PROVEN" => s += &format!("theorem: {}\n", p.statement),
            _ => s += &format!("{}\n{}\n", p.statement, p.counterexample.clone().unwrap_or_default()),
        }
        s
    })?;
    Ok(match p.status {
        "PROVEN" => Outcome::Pass,
        "COUNTEREXAMPLE" => Outcome::Fail,
        _ => Outcome::Inconclusive,
    })
}

/// `raypipe prove rti-bound`: every operation's lemma by enumeration; the composition written.
fn rti_bound(a: &Args) -> Result<Outcome, String> {
    use formal::prove::rti_bound::{prove, Mutant, MARGIN_BITS};
    if a.out.is_some() {
        return Err("rti-bound's counterexamples are of the error bound, not of the datapath's outputs: there is no vector set to write (--out); the witness prints as a raypipe explain command".into());
    }
    if a.variant.is_some() || !a.mutation.flags().is_empty() || a.nan {
        return Err("rti-bound is about the RTI unit: --variant, --widen, --no-guard and --nan do not apply".into());
    }
    let format = a.format.clone().unwrap_or_else(|| "fp16".into());
    let f = parse_format(&format)?;
    let mutant = a.mutant.as_deref().map_or(Ok(Mutant::None), Mutant::parse)?;
    let p = with_format!(&f, |f| prove(f, mutant, threads(a.threads)))?;
    let (em, div) = with_format!(&f, |f| (mutant.apply(f.error_model()), f.div_mode()));
    let list = |xs: &[f64]| xs.iter().map(|x| format!("{x:?}")).collect::<Vec<_>>().join(",");
    let explain = p.witness.as_ref().map(|((o, d, v), _)| {
        format!(
            "raypipe explain --unit rti --format {format} --ray {},{} --tri {}",
            list(o),
            list(d),
            list(&v.iter().flatten().copied().collect::<Vec<_>>())
        )
    });
    let lemma_json = |l: &formal::prove::rti_bound::OpLemma| {
        serde_json::json!({
            "op": l.op,
            "statement": l.statement,
            "pairs": l.cases,
            "not_finite": l.overflowed,
            "worst_ratio": l.worst.map(|w| w.0),
            "worst_operands": l.worst.map(|w| [format!("{:#x}", w.1), format!("{:#x}", w.2)]),
            "violation": l.violation.map(|v| v.map(|x| format!("{x:#x}"))),
        })
    };
    let j = serde_json::json!({
        "command": command_as_typed(),
        "property": "rti-bound",
        "format": f.name(),
        "division": format!("{div:?}"),
        "mutant": a.mutant,
        "error_model": {"u": em.u, "eta": em.eta, "add_eta": em.add_eta, "max": em.max},
        "margin": format!("1 - 2^-{MARGIN_BITS}"),
        "status": p.status,
        "statement": p.statement,
        "method": "every operand pair of each operation of the model, checked exactly in 128-bit integers; the composition over the stage table's rows is written in docs/proofs.md",
        "seconds": p.seconds,
        "lemmas": p.lemmas.iter().map(lemma_json).collect::<Vec<_>>(),
        "witness": p.witness.as_ref().map(|(_, cs)| cs.iter().map(|c| serde_json::json!({
            "quantity": c.name,
            "model": c.model,
            "model_bits": format!("{:#x}", with_format!(&f, |f| f.to_bits(f.from_f64(c.model)))),
            "exact": c.exact,
            "bound": c.bound,
            "holds": c.holds,
        })).collect::<Vec<_>>()),
        "explain": explain,
    });
    emit(a.json, &j, |_| {
        let mut s = format!(
            "rti-bound: {} for {}{} — enumeration of every operand pair in {:.1} s\n",
            p.status,
            f.name(),
            a.mutant.as_ref().map_or(String::new(), |m| format!(", mutant {m}")),
            p.seconds
        );
        for l in &p.lemmas {
            s += &match (l.violation, l.cases) {
                (Some([x, y, r]), _) => {
                    format!("  {}: {} FAILS at {x:#x}, {y:#x} (result {r:#x})\n", l.op, l.statement)
                }
                (None, Some(n)) => format!(
                    "  {}: {} holds on {n} pairs (worst ratio {:.6}){}\n",
                    l.op,
                    l.statement,
                    l.worst.map_or(0.0, |w| w.0),
                    l.overflowed
                        .filter(|&o| o > 0)
                        .map_or(String::new(), |o| format!("; {o} with a result not finite (no claim)"))
                ),
                _ => String::new(),
            };
        }
        s += &format!("{}: {}\n", if p.status == "PROVEN" { "theorem" } else { "refuted" }, p.statement);
        if let Some((_, cs)) = &p.witness {
            for c in cs.iter().filter(|c| !c.holds) {
                s += &format!("  {}: model {:?}, exact {:?}, bound {:e}: outside\n", c.name, c.model, c.exact, c.bound);
            }
            s += &format!("reproduce: {}\n", explain.clone().unwrap_or_default());
        }
        s
    })?;
    Ok(if p.status == "PROVEN" { Outcome::Pass } else { Outcome::Fail })
}

/// Writes a slab counterexample as a one-vector set of class `smt` whose expected outputs are
/// the unmutated variant's (a DUT with the mutant's bug fails it); returns the set's directory.
fn write_counterexample(
    out: &std::path::Path,
    format: &str,
    variant: &str,
    mutation: &SlabMutation,
    p: &formal::prove::Proof,
) -> Result<std::path::PathBuf, String> {
    write_smt_set(
        out,
        vectors::gen::Unit::Slab,
        parse_format(format)?,
        datapath::rti::RtiConfig::default(),
        variant,
        format!(
            "a counterexample of raypipe prove slab-never-misses for variant {variant}{}: an input whose exact slab interval is non-empty and which that mutant misses; the expected outputs are the {variant} variant's own",
            mutation.flags()
        ),
        &p.witness,
        "",
    )
}

/// The `raypipe explain` command that replays a slab counterexample.
fn explain_command(format: &str, variant: &str, mutation: &SlabMutation, p: &formal::prove::Proof) -> String {
    let f = parse_format(format).expect("parsed before");
    let val = |n: &str| {
        let bits = p.witness.iter().find(|(k, _)| k == n).map_or(0, |(_, v)| *v);
        with_format!(&f, |f| f.to_f64(f.from_bits(bits)))
    };
    let list = |ns: &[&str]| ns.iter().map(|n| format!("{:?}", val(n))).collect::<Vec<_>>().join(",");
    format!(
        "raypipe explain --unit slab --format {} --variant {}{} --ray {} --box {} --tmin {:?} --tmax {:?}",
        format,
        variant,
        mutation.flags(),
        list(&["ox", "oy", "oz", "dx", "dy", "dz"]),
        list(&["minx", "miny", "minz", "maxx", "maxy", "maxz"]),
        val("tmin"),
        val("tmax")
    )
}

/// The `--threads` given, or every core.
fn threads(t: Option<u64>) -> usize {
    t.map_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()), |t| t as usize)
}
