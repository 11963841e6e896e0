//! A coverage recorder for live testbenches: every input row a testbench drives into its DUT,
//! counted (with the model's outputs and stage signals for that row) into the coverage model
//! of the unit, format and options (`vectors::cover`), then written as a coverage file that
//! `raypipe cover` reports and merges with vector sets, `verify`/`stress`/`ops --cover` files
//! and other testbenches' files (counts add exactly). The rows' class is `live`.

use crate::unit::{Kind, Unit};
use std::sync::Mutex;
use vectors::cover::RowBins;
use vectors::cover_file::{CoverCounts, RunModel};

/// The class of every recorded row.
pub const CLASS: (&str, &str) = ("live", "rows a live testbench drove into its DUT (recorded through the C ABI)");

/// A recorder: its own model of the unit (so it needs no handle) and the counts so far.
pub struct Recorder {
    unit: Unit,
    run: RunModel,
    /// The model's row lookup, built once.
    bins: RowBins,
    state: Mutex<State>,
}

#[derive(Default)]
struct State {
    counts: CoverCounts,
    contents: Vec<Vec<Vec<u64>>>,
    hits: Vec<(usize, usize)>,
    stages: Vec<u64>,
}

impl Recorder {
    /// A recorder for the unit `unit` ("rti", "slab", "op") in `format` with the CLI `options`.
    pub fn new(unit: &str, format: &str, options: &str) -> Result<Self, String> {
        let unit = Unit::new(unit, format, options)?;
        let req = unit.request.clone().ok_or("the traverse unit has no live coverage model")?;
        if !unit.has_stages {
            return Err("the directed slab variant has no coverage model (its signal set depends on the data)".into());
        }
        let mut req = req;
        req.command = "live testbench (raypipe C ABI)".into();
        let run = RunModel::new(&req, Some(&[(CLASS.0, CLASS.1, 1)]))?;
        let bins = RowBins::new(&run.manifest);
        Ok(Recorder { unit, run, bins, state: Mutex::new(State::default()) })
    }

    /// Counts one input row (the C ABI's row: no class column).
    pub fn add(&self, row: &[u64]) -> Result<(), String> {
        self.unit.check_row(row)?;
        let mut st = self.state.lock().map_err(|_| "the recorder's lock is poisoned")?;
        let State { counts, contents, hits, stages } = &mut *st;
        if contents.is_empty() {
            *contents = vec![vec![Vec::new()]; 3];
        }
        let mut out = vec![0u64; self.unit.outputs()];
        stages.clear();
        let want = if self.unit.kind == Kind::Op { None } else { Some(&mut *stages) };
        self.unit.eval(row, &mut out, want)?;
        contents[0][0].clear();
        contents[0][0].push(0);
        contents[0][0].extend_from_slice(row);
        contents[1][0] = out;
        contents[2][0].clone_from(stages);
        self.run.count(&self.bins, contents, hits, counts)
    }

    /// Values in one input row of the recorder's unit.
    pub fn inputs(&self) -> usize {
        self.unit.kind.inputs()
    }

    /// Rows counted so far.
    pub fn rows(&self) -> u64 {
        self.state.lock().map_or(0, |s| s.counts.vectors)
    }

    /// Writes the coverage file `path` (atomically); a file there that raypipe did not write is
    /// never replaced (an error).
    pub fn write(&self, path: &std::path::Path) -> Result<(), String> {
        vectors::outdir::check_file_out(
            "the coverage file",
            path,
            vectors::cover_file::is_coverage,
            "raypipe did not write it",
        )?;
        let counts = self.state.lock().map_err(|_| "the recorder's lock is poisoned")?.counts.clone();
        let (m, c) = self.run.finish(counts);
        let text = vectors::cover_file::write(&[(m, c)], "live testbench (raypipe C ABI)");
        vectors::outdir::atomic_write(path, text.as_bytes())
    }
}
