//! `raypipe stages`: print the RTI stage table (markdown).

use super::prelude::*;

/// The options of `raypipe stages`.
#[derive(clap::Args, Clone)]
pub struct Args {
    /// Unit: rti or slab.
    #[arg(long, default_value = "rti")]
    pub unit: String,
    /// Division mode of the RTI unit: recip (1/det then multiplies) or divide.
    #[arg(long, default_value = "recip")]
    pub div: String,
}

/// Runs `raypipe stages`.
pub fn run(a: Args) -> Result<Outcome, String> {
    let Args { unit, div } = a;
    let d = match div.as_str() {
        "recip" => DivMode::RecipMul,
        "divide" => DivMode::Divide,
        other => return Err(format!("--div must be recip or divide, got '{other}'")),
    };
    match unit.as_str() {
        "rti" => print!("{}", stages_markdown(&stage_table(d))),
        "slab" => print!("{}", stages_markdown(&datapath::slab::SLAB_TABLE)),
        other => return Err(format!("unknown unit '{other}'; units: rti, slab")),
    }
    Ok(Outcome::Pass)
}

/// A stage table as markdown.
fn stages_markdown(table: &[datapath::rti::SigDef]) -> String {
    let mut s = String::from("| stage | signal | op | operands |\n|---|---|---|---|\n");
    for d in table {
        let (op, operands) = match d.op {
            Op::Sub => ("sub", format!("{} − {}", d.a, d.b)),
            Op::Add => ("add", format!("{} + {}", d.a, d.b)),
            Op::Mul => ("mul", format!("{} × {}", d.a, d.b)),
            Op::Div => ("div", format!("{} ÷ {}", d.a, d.b)),
            Op::Logic => ("cmp/logic", d.note.to_string()),
        };
        s += &format!("| {} | `{}` | {} | {} |\n", d.stage, d.name, op, operands);
    }
    s
}
