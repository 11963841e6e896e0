//! The commands: one file each (its options as a clap `Args` and its `run`), the option groups
//! they share (`args`) and what every command uses (`common`). `main.rs` parses the command
//! line and calls [`dispatch`].

pub mod arch;
pub mod args;
pub mod common;
pub mod completions;
pub mod cover;
pub mod equiv;
pub mod explain;
pub mod faults;
pub mod man;
pub mod merge;
pub mod ops;
pub mod plan;
pub mod prove;
pub mod render;
pub mod report;
pub mod smt;
pub mod speed;
pub mod stages;
pub mod stats;
pub mod stress;
pub mod traverse;
pub mod vectors;
pub mod verify;

/// What the command files use.
pub mod prelude {
    pub use super::args::*;
    pub use super::common::*;
    pub use datapath::format::DivMode;
    pub use datapath::rti::{stage_table, Cull, Op, Rti, RtiConfig, TieRule};
    pub use datapath::slab::{Slab, SlabConfig};
    pub use datapath::{with_format, AnyFormat};
    pub use golden::{Ray64, Tri64};
    pub use raypipe::partial::Sharded;
    pub use raypipe::scene::Scene;
    pub use raypipe::Outcome;
    pub use std::path::PathBuf;
    pub use vectors::outdir::OutDir;
}

use prelude::*;

/// The commands.
#[derive(clap::Subcommand)]
pub enum Cmd {
    /// Print a shell completion script (bash, zsh, fish, elvish or powershell) on stdout.
    Completions(completions::Args),
    /// Print the man page (roff) of raypipe, or of one of its commands, on stdout.
    Man(man::Args),
    /// Run every format's RTI model against the golden reference (the default command).
    Verify(verify::Args),
    /// Print every stage signal of one ray–triangle (or ray–box) test beside the references.
    Explain(explain::Args),
    /// The 2-bit ray history and 1-bit trail traversals against the stack traversal on a scene's BVH.
    Traverse(traverse::Args),
    /// One operation of a format against the per-op oracle (APFloat): every pair or specials + random; shardable.
    Ops(ops::Args),
    /// Merge the partial results of a sharded run (--shard K/N --partial FILE) into its report.
    Merge(merge::Args),
    /// The thesis hardware as a throughput model: figure 3-3 (time against leaf size per pipeline count) and its calibration.
    Arch(arch::Args),
    /// The thesis's experiments (figs. 3-1, 3-2, 3-4, 3-5, restart overhead) over leaf sizes.
    Stats(stats::Args),
    /// Render through the bit-accurate pipeline (slab traversal → RTI min-capture) and diff with the golden.
    Render(render::Args),
    /// Write a self-describing vector set for RTL testbenches (or check one with --check).
    Vectors(vectors::Args),
    /// Run the fault bank against a vector set: which hardware bugs the set detects.
    Faults(faults::Args),
    /// What a scene needs: tree depth and history bits, culling, and the narrowest format within an error budget.
    Plan(plan::Args),
    /// Run time against error for every variant on the same inputs: markdown, JSON and SVG with the Pareto front.
    Report(report::Args),
    /// This machine's no-FMA FP peak and each RTI / slab implementation's throughput as a fraction of it.
    Speed(speed::Args),
    /// The numerical stability stress suite: failures against the exact decision per class, format and variant.
    Stress(stress::Args),
    /// Print the RTI stage table (markdown).
    Stages(stages::Args),
    /// Emit a unit's stage model as SMT-LIB 2, generated from its stage table and format contract.
    Smt(smt::Args),
    /// Prove a guarantee with an SMT solver: PROVEN (0), a counterexample (1) or unknown (3).
    Prove(prove::Args),
    /// Prove a Verilog DUT's outputs equal to the model's signals (yosys + SMT): PROVEN (0), a counterexample (1) or unknown (3).
    Equiv(equiv::Args),
    /// The functional coverage of vector sets: every signal's bins, merged over the sets, holes listed.
    Cover(cover::Args),
}

/// Runs a command (none: the main job, `raypipe verify` with every default).
pub fn dispatch(cmd: Option<Cmd>) -> Result<Outcome, String> {
    match cmd {
        None => verify::run(verify::Args::main_job()),
        Some(Cmd::Completions(a)) => completions::run(a),
        Some(Cmd::Man(a)) => man::run(a),
        Some(Cmd::Verify(a)) => verify::run(a),
        Some(Cmd::Explain(a)) => explain::run(a),
        Some(Cmd::Traverse(a)) => traverse::run(a),
        Some(Cmd::Ops(a)) => ops::run(a),
        Some(Cmd::Merge(a)) => merge::run(a),
        Some(Cmd::Arch(a)) => arch::run(a),
        Some(Cmd::Stats(a)) => stats::run(a),
        Some(Cmd::Render(a)) => render::run(a),
        Some(Cmd::Vectors(a)) => vectors::run(a),
        Some(Cmd::Faults(a)) => faults::run(a),
        Some(Cmd::Plan(a)) => plan::run(a),
        Some(Cmd::Report(a)) => report::run(a),
        Some(Cmd::Speed(a)) => speed::run(a),
        Some(Cmd::Stress(a)) => stress::run(a),
        Some(Cmd::Stages(a)) => stages::run(a),
        Some(Cmd::Smt(a)) => smt::run(a),
        Some(Cmd::Prove(a)) => prove::run(a),
        Some(Cmd::Equiv(a)) => equiv::run(a),
        Some(Cmd::Cover(a)) => cover::run(a),
    }
}
