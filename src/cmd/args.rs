//! The option groups several commands share: the RTI unit's options, the engine's, sharding,
//! the thesis hardware's parameters.

use super::prelude::*;
use clap::ValueEnum;

/// The min-capture tie rule on the command line.
#[derive(Clone, Copy, ValueEnum)]
pub enum Tie {
    /// Keep the first of equal t.
    First,
    /// Take the last of equal t.
    Last,
}

/// The RTI unit's options (culling, det threshold, tie rule).
#[derive(clap::Args, Clone)]
pub struct RtiArgs {
    /// Cull back faces (hit needs det > threshold) instead of two-sided (|det| > threshold).
    #[arg(long)]
    pub cull: bool,
    /// det threshold (>= 0).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    pub det_threshold: f64,
    /// Min-capture tie rule on equal t.
    #[arg(long, value_enum, default_value_t = Tie::First)]
    pub tie: Tie,
}

impl RtiArgs {
    /// The RTI configuration, refused when the det threshold is not a finite number >= 0.
    pub fn config(&self) -> Result<RtiConfig, String> {
        if !(self.det_threshold >= 0.0 && self.det_threshold.is_finite()) {
            return Err(format!("--det-threshold must be a finite number >= 0, got {}", self.det_threshold));
        }
        Ok(RtiConfig {
            cull: if self.cull { Cull::Backface } else { Cull::TwoSided },
            det_threshold: self.det_threshold,
            tie: match self.tie {
                Tie::First => TieRule::First,
                Tie::Last => TieRule::Last,
            },
        })
    }
}

/// How a streamed run executes (the results do not depend on it).
#[derive(clap::Args, Clone)]
pub struct EngineArgs {
    /// Worker threads (default: every core); the results do not depend on it.
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=1024))]
    pub threads: Option<u64>,
    /// No progress bar on stderr.
    #[arg(long)]
    pub quiet: bool,
}

impl EngineArgs {
    /// The engine with chunks of `chunk` items on the chosen threads.
    pub fn engine(&self, chunk: u64) -> engine::Engine {
        engine::Engine::new(chunk).with_threads(self.threads.map(|t| t as usize))
    }
}

/// Sharding of a run (`raypipe merge` puts the shards together).
#[derive(clap::Args, Clone)]
pub struct ShardArgs {
    /// Run one shard of the work: K/N (0 <= K < N), or `slurm` (the Slurm array task's); needs
    /// --partial.
    #[arg(long)]
    pub shard: Option<String>,
    /// Write this shard's partial result to FILE (JSON) for `raypipe merge`.
    #[arg(long)]
    pub partial: Option<PathBuf>,
}

/// The thesis hardware's parameters (`raypipe arch`, `raypipe plan`); defaults are the thesis's
/// values where it gives one (docs/arch.md).
#[derive(clap::Args, Clone)]
pub struct ArchArgs {
    /// Ray packet buffers interleaved on the RTI pipelines (thesis: 4).
    #[arg(long, default_value_t = 4)]
    pub buffers: u32,
    /// Cycles to assemble a triangle from DRAM (thesis: 3).
    #[arg(long, default_value_t = 3)]
    pub tri_assemble: u32,
    /// Cycles to broadcast a triangle (thesis: 1).
    #[arg(long, default_value_t = 1)]
    pub tri_broadcast: u32,
    /// RTI pipeline latency in cycles (default: the modelled datapath's 10 stages).
    #[arg(long, default_value_t = 10)]
    pub rti_latency: u32,
    /// RTI clock in MHz (thesis: 100).
    #[arg(long, default_value_t = 100.0)]
    pub rti_mhz: f64,
    /// DRAM bytes per RTI cycle for rays and results.
    #[arg(long, default_value_t = 12)]
    pub dram_bytes: u32,
    /// Bytes per ray in DRAM.
    #[arg(long, default_value_t = 36)]
    pub ray_bytes: u32,
    /// Bytes per result in DRAM.
    #[arg(long, default_value_t = 16)]
    pub result_bytes: u32,
    /// Overlap ray loads and result stores with the triangle stream.
    #[arg(long)]
    pub overlap_io: bool,
    /// Rays entering the traversal core per cycle (2: dual-port BRAM).
    #[arg(long, default_value_t = 1)]
    pub ports: u32,
    /// Cycles per level pipeline.
    #[arg(long, default_value_t = 16)]
    pub level_latency: u32,
    /// Traversal clock in MHz (thesis: 200).
    #[arg(long, default_value_t = 200.0)]
    pub trav_mhz: f64,
    /// BRAM bits per stored box.
    #[arg(long, default_value_t = 192)]
    pub box_bits: u32,
    /// BRAM bits per child address word.
    #[arg(long, default_value_t = 32)]
    pub addr_bits: u32,
}

impl ArchArgs {
    /// The parameters, with the RTI pipelines and the traversal core's level pipelines.
    pub fn params(&self, pipelines: u32, levels: u32) -> raypipe::arch::ArchParams {
        raypipe::arch::ArchParams {
            pipelines,
            buffers: self.buffers,
            tri_assemble: self.tri_assemble,
            tri_broadcast: self.tri_broadcast,
            rti_latency: self.rti_latency,
            rti_mhz: self.rti_mhz,
            dram_bytes_per_cycle: self.dram_bytes,
            ray_bytes: self.ray_bytes,
            result_bytes: self.result_bytes,
            overlap_io: self.overlap_io,
            levels,
            ports: self.ports,
            level_latency: self.level_latency,
            trav_mhz: self.trav_mhz,
            box_bits: self.box_bits,
            addr_bits: self.addr_bits,
        }
    }
}

/// Changes to a named slab variant, to build the mutants a proof must refute.
#[derive(clap::Args, Clone, Default)]
pub struct SlabMutation {
    /// Widen t_near / t_far by N grid steps instead of the variant's own number.
    #[arg(long, allow_hyphen_values = true)]
    pub widen: Option<i32>,
    /// Leave out the conservative variant's guard.
    #[arg(long)]
    pub no_guard: bool,
}

impl SlabMutation {
    /// The variant `cfg` with these changes.
    pub fn apply(&self, mut cfg: SlabConfig) -> SlabConfig {
        if let Some(w) = self.widen {
            cfg.widen_ulps = w;
        }
        if self.no_guard {
            cfg.guard = false;
        }
        cfg
    }

    /// The options as typed (for a reproducing command).
    pub fn flags(&self) -> String {
        let mut s = String::new();
        if let Some(w) = self.widen {
            s += &format!(" --widen {w}");
        }
        if self.no_guard {
            s += " --no-guard";
        }
        s
    }
}

/// Refuses a solver name `raypipe_solve.py` does not drive, or a timeout that is not a finite
/// number of seconds >= 0 (0: no limit).
pub fn check_solver(solver: &str, timeout: f64) -> Result<(), String> {
    if !(timeout >= 0.0 && timeout.is_finite()) {
        return Err(format!("--timeout must be a finite number of seconds >= 0, got {timeout}"));
    }
    if !matches!(solver, "auto" | "bitwuzla" | "cvc5" | "z3") {
        return Err(format!("unknown solver '{solver}': auto, bitwuzla, cvc5, z3"));
    }
    Ok(())
}
