//! `raypipe merge`: merge the partial results of a sharded run (--shard K/N --partial FILE) into its report.

use super::prelude::*;

/// The options of `raypipe merge`.
#[derive(clap::Args, Clone)]
pub struct Args {
    /// The partial files, one per shard (any order).
    #[arg(required = true)]
    pub partials: Vec<PathBuf>,
    /// A report's files (markdown, JSON, SVG) into this directory (report partials only).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Print the results as JSON.
    #[arg(long)]
    pub json: bool,
}

/// Runs `raypipe merge`.
pub fn run(a: Args) -> Result<Outcome, String> {
    let Args { partials, out, json } = a;
    let dir = out.as_deref().map(|d| OutDir::check(d, &raypipe::time_vs_error::FILES)).transpose()?;
    let parts = raypipe::partial::read_all(&partials)?;
    if dir.is_some() && parts[0].command != "report" {
        return Err(format!("--out writes a report's files; these are {} partials", parts[0].command));
    }
    // merge_data checks each shard's consistency and adds them up
    use raypipe::partial::merge_data;
    match parts[0].command.as_str() {
        "report" => {
            let mut rep = merge_data::<raypipe::time_vs_error::ReportData>(&parts)?.finish()?;
            // the timings come from the shards' machines; the merge names its own
            rep.command = command_as_typed();
            if let Some(dir) = &dir {
                for f in raypipe::time_vs_error::write(&rep, dir)? {
                    eprintln!("wrote {}", f.display());
                }
            }
            emit(json, &rep, raypipe::time_vs_error::markdown)?;
            Ok(Outcome::Pass)
        }
        "stress" => finish_and_print(json, merge_data::<raypipe::stress::StressReport>(&parts)?),
        "traverse" => finish_and_print(json, merge_data::<raypipe::traverse::TraverseReport>(&parts)?),
        "ops" => finish_and_print(json, merge_data::<raypipe::ops::OpsData>(&parts)?),
        "verify" => finish_and_print(json, merge_data::<raypipe::verify::VerifyData>(&parts)?),
        other => Err(format!("raypipe merge: partials of '{other}' cannot be merged by this raypipe")),
    }
}
