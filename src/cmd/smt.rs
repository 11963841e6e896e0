//! `raypipe smt`: emit a unit's stage model as SMT-LIB 2, generated from its stage table and
//! the format's contract (docs/proofs.md).

use super::prelude::*;

/// The options of `raypipe smt`.
#[derive(clap::Args, Clone)]
pub struct Args {
    /// Unit: rti, slab or op.
    #[arg(long, default_value = "rti")]
    pub unit: String,
    /// Format (IEEE-like floats: f32, fp16, bf16, eEmM, with their options).
    #[arg(long, default_value = "fp16")]
    pub format: String,
    /// Slab variant: plain, conservative, take-on-false, embree.
    #[arg(long, default_value = "plain")]
    pub variant: String,
    /// RTI options.
    #[command(flatten)]
    pub rti: RtiArgs,
    /// Slab variant changes (mutants).
    #[command(flatten)]
    pub mutation: SlabMutation,
    /// Write model.smt2 and model.json (inputs, signals) into DIR instead of printing the script.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Print the script, inputs and signals as JSON.
    #[arg(long)]
    pub json: bool,
}

/// The request `a` names.
pub fn request(
    unit: &str,
    format: &str,
    variant: &str,
    rti: &RtiArgs,
    m: &SlabMutation,
) -> Result<formal::smt::Request, String> {
    Ok(formal::smt::Request {
        unit: unit.parse()?,
        format: parse_format(format)?,
        rti: rti.config()?,
        variant: variant.to_string(),
        widen: m.widen,
        no_guard: m.no_guard,
    })
}

/// A slab request (no RTI options).
pub fn request_slab(format: &str, variant: &str, m: &SlabMutation) -> Result<formal::smt::Request, String> {
    Ok(formal::smt::Request {
        unit: formal::smt::Unit::Slab,
        format: parse_format(format)?,
        rti: RtiConfig::default(),
        variant: variant.to_string(),
        widen: m.widen,
        no_guard: m.no_guard,
    })
}

/// The model as JSON: the script, its inputs and signals.
pub fn model_json(m: &formal::smt::Model, command: &str) -> serde_json::Value {
    serde_json::json!({
        "command": command,
        "width": m.width,
        "inputs": m.inputs,
        "signals": m.signals.iter().map(|(n, flag)| serde_json::json!({"name": n, "flag": flag})).collect::<Vec<_>>(),
        "smt2": m.text,
    })
}

/// Runs `raypipe smt`.
pub fn run(a: Args) -> Result<Outcome, String> {
    let req = request(&a.unit, &a.format, &a.variant, &a.rti, &a.mutation)?;
    let out = match &a.out {
        Some(d) => Some(OutDir::check(d, &["model.smt2", "model.json"])?),
        None => None,
    };
    let m = formal::smt::emit(&req)?;
    let j = model_json(&m, &command_as_typed());
    match out {
        Some(o) => {
            o.write("model.smt2", m.text.as_bytes())?;
            let mut j = j;
            j.as_object_mut().expect("an object").remove("smt2");
            o.write("model.json", (serde_json::to_string_pretty(&j).map_err(|e| e.to_string())? + "\n").as_bytes())?;
            if a.json {
                println!("{}", serde_json::json!({"out": o.path(), "signals": m.signals.len()}));
            } else {
                eprintln!("wrote {} ({} signals)", o.path().join("model.smt2").display(), m.signals.len());
            }
        }
        None if a.json => println!("{}", serde_json::to_string_pretty(&j).map_err(|e| e.to_string())?),
        None => print!("{}", m.text),
    }
    Ok(Outcome::Pass)
}
