//! `raypipe prove`: prove one of raypipe's guarantees with an SMT solver (docs/proofs.md).
//! Exit 0 PROVEN, 1 counterexample, 3 unknown (timeout: nothing proven).

use super::prelude::*;
use datapath::Format;

/// The options of `raypipe prove`.
#[derive(clap::Args, Clone)]
pub struct Args {
    /// Property: slab-never-misses.
    pub property: String,
    /// Format (IEEE-like floats with at most 6 exponent bits: fp16, e5mM, e4mM, ...).
    #[arg(long, default_value = "fp16")]
    pub format: String,
    /// Slab variant.
    #[arg(long, default_value = "conservative")]
    pub variant: String,
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
    /// Print the result as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Runs `raypipe prove`.
pub fn run(a: Args) -> Result<Outcome, String> {
    if !(a.timeout >= 0.0 && a.timeout.is_finite()) {
        return Err(format!("--timeout must be a finite number of seconds >= 0, got {}", a.timeout));
    }
    if !matches!(a.solver.as_str(), "auto" | "bitwuzla" | "cvc5" | "z3") {
        return Err(format!("unknown solver '{}': auto, bitwuzla, cvc5, z3", a.solver));
    }
    let p = match a.property.as_str() {
        "slab-never-misses" => {
            let req = super::smt::request_slab(&a.format, &a.variant, &a.mutation)?;
            let threads =
                a.threads.map_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()), |t| t as usize);
            formal::prove::slab::prove(&req, &a.solver, a.timeout, threads)?
        }
        other => return Err(format!("unknown property '{other}'; properties: slab-never-misses")),
    };
    let explain = (p.verdict.result == "sat").then(|| explain_command(&a, &p));
    let j = serde_json::json!({
        "command": command_as_typed(),
        "property": p.property,
        "format": p.format,
        "variant": a.variant,
        "mutation": a.mutation.flags().trim(),
        "status": p.status(),
        "theorem": p.theorem,
        "solver": p.verdict.solver,
        "solver_version": p.verdict.version,
        "seconds": p.verdict.seconds,
        "witness": p.witness.iter().map(|(n, v)| (n.clone(), serde_json::json!(format!("{v:#x}")))).collect::<serde_json::Map<_, _>>(),
        "explain": explain,
        "steps": p.steps.iter().map(|(what, v)| serde_json::json!({"query": what, "result": v.result, "solver": v.solver, "seconds": v.seconds})).collect::<Vec<_>>(),
    });
    emit(a.json, &j, |_| {
        let mut s = format!(
            "{}: {} for {} (variant {}{}) — {} {} in {:.1} s\n",
            p.property,
            p.status(),
            p.format,
            a.variant,
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

/// The `raypipe explain` command that replays a slab counterexample.
fn explain_command(a: &Args, p: &formal::prove::Proof) -> String {
    let f = parse_format(&a.format).expect("parsed before");
    let val = |n: &str| {
        let bits = p.witness.iter().find(|(k, _)| k == n).map_or(0, |(_, v)| *v);
        with_format!(&f, |f| f.to_f64(f.from_bits(bits)))
    };
    let list = |ns: &[&str]| ns.iter().map(|n| format!("{:?}", val(n))).collect::<Vec<_>>().join(",");
    format!(
        "raypipe explain --unit slab --format {} --variant {}{} --ray {} --box {} --tmin {:?} --tmax {:?}",
        a.format,
        a.variant,
        a.mutation.flags(),
        list(&["ox", "oy", "oz", "dx", "dy", "dz"]),
        list(&["minx", "miny", "minz", "maxx", "maxy", "maxz"]),
        val("tmin"),
        val("tmax")
    )
}
