//! The `raypipe` command line.

use clap::{Parser, Subcommand, ValueEnum};
use datapath::format::DivMode;
use datapath::rti::{stage_table, Cull, Op, Rti, RtiConfig, TieRule};
use datapath::slab::{Slab, SlabConfig};
use datapath::{with_format, AnyFormat};
use golden::{Ray64, Tri64};
use raypipe::scene::Scene;
use raypipe::verify::{render, verify, VerifyConfig};
use raypipe::Outcome;
use std::path::PathBuf;
use std::process::ExitCode;
use vectors::outdir::OutDir;

/// Large blocks (the batch columns) at staggered page offsets, so that a kernel's columns do
/// not share cache sets (see [`datapath::alloc`]).
#[global_allocator]
static ALLOC: datapath::alloc::Staggered = datapath::alloc::Staggered;

/// Default formats of `raypipe verify`.
const DEFAULT_FORMATS: [&str; 5] = ["f32", "fp16", "bf16", "e8m16", "q8.24:divide"];

#[derive(Parser)]
#[command(
    name = "raypipe",
    version,
    about = "Bit-accurate ray-tracing datapath models judged against a golden f64 reference"
)]
struct Cli {
    #[command(subcommand)]
    cmd: Option<Cmd>,
}

#[derive(Clone, Copy, ValueEnum)]
enum Tie {
    First,
    Last,
}

#[derive(clap::Args, Clone)]
struct RtiArgs {
    /// Cull back faces (hit needs det > threshold) instead of two-sided (|det| > threshold).
    #[arg(long)]
    cull: bool,
    /// det threshold (>= 0).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    det_threshold: f64,
    /// Min-capture tie rule on equal t.
    #[arg(long, value_enum, default_value_t = Tie::First)]
    tie: Tie,
}

impl RtiArgs {
    fn config(&self) -> Result<RtiConfig, String> {
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
struct EngineArgs {
    /// Worker threads (default: every core); the results do not depend on it.
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=1024))]
    threads: Option<u64>,
    /// No progress bar on stderr.
    #[arg(long)]
    quiet: bool,
}

impl EngineArgs {
    fn engine(&self, chunk: u64) -> engine::Engine {
        engine::Engine::new(chunk).with_threads(self.threads.map(|t| t as usize))
    }
}

/// Sharding of a run (`raypipe merge` puts the shards together).
#[derive(clap::Args, Clone)]
struct ShardArgs {
    /// Run one shard of the work: K/N (0 <= K < N), or `slurm` (the Slurm array task's); needs
    /// --partial.
    #[arg(long)]
    shard: Option<String>,
    /// Write this shard's partial result to FILE (JSON) for `raypipe merge`.
    #[arg(long)]
    partial: Option<PathBuf>,
}

/// The thesis hardware's parameters (`raypipe arch`, `raypipe plan`); defaults are the thesis's
/// values where it gives one (docs/arch.md).
#[derive(clap::Args, Clone)]
struct ArchArgs {
    /// Ray packet buffers interleaved on the RTI pipelines (thesis: 4).
    #[arg(long, default_value_t = 4)]
    buffers: u32,
    /// Cycles to assemble a triangle from DRAM (thesis: 3).
    #[arg(long, default_value_t = 3)]
    tri_assemble: u32,
    /// Cycles to broadcast a triangle (thesis: 1).
    #[arg(long, default_value_t = 1)]
    tri_broadcast: u32,
    /// RTI pipeline latency in cycles (default: the modelled datapath's 10 stages).
    #[arg(long, default_value_t = 10)]
    rti_latency: u32,
    /// RTI clock in MHz (thesis: 100).
    #[arg(long, default_value_t = 100.0)]
    rti_mhz: f64,
    /// DRAM bytes per RTI cycle for rays and results.
    #[arg(long, default_value_t = 12)]
    dram_bytes: u32,
    /// Bytes per ray in DRAM.
    #[arg(long, default_value_t = 36)]
    ray_bytes: u32,
    /// Bytes per result in DRAM.
    #[arg(long, default_value_t = 16)]
    result_bytes: u32,
    /// Overlap ray loads and result stores with the triangle stream.
    #[arg(long)]
    overlap_io: bool,
    /// Rays entering the traversal core per cycle (2: dual-port BRAM).
    #[arg(long, default_value_t = 1)]
    ports: u32,
    /// Cycles per level pipeline.
    #[arg(long, default_value_t = 16)]
    level_latency: u32,
    /// Traversal clock in MHz (thesis: 200).
    #[arg(long, default_value_t = 200.0)]
    trav_mhz: f64,
    /// BRAM bits per stored box.
    #[arg(long, default_value_t = 192)]
    box_bits: u32,
    /// BRAM bits per child address word.
    #[arg(long, default_value_t = 32)]
    addr_bits: u32,
}

impl ArchArgs {
    /// The parameters, with the RTI pipelines and the traversal core's level pipelines.
    fn params(&self, pipelines: u32, levels: u32) -> raypipe::arch::ArchParams {
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

#[derive(clap::Args, Clone)]
struct VerifyArgs {
    /// OBJ scene (default: the built-in Cornell box + icosphere + needles).
    #[arg(long)]
    scene: Option<PathBuf>,
    /// Format(s) to verify, comma-separated or repeated (default: f32,fp16,bf16,e8m16,q8.24:divide).
    #[arg(long, value_delimiter = ',', value_parser = parse_format)]
    format: Vec<AnyFormat>,
    /// Number of rays.
    #[arg(long, default_value_t = 1024, value_parser = clap::value_parser!(u64).range(1..))]
    rays: u64,
    /// Ray generator seed.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Scenes up to this many triangles are tested exhaustively per ray; larger ones per ray
    /// against its target triangle and this many minus one random others.
    #[arg(long, default_value_t = 512, value_parser = clap::value_parser!(u64).range(1..))]
    sample: u64,
    /// Print the results as JSON.
    #[arg(long)]
    json: bool,
    /// A plan (`raypipe plan --json`): verify only its formats within budget (unless --format).
    #[arg(long)]
    plan: Option<PathBuf>,
    /// Worker threads (default: every core); the results do not depend on it.
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=1024))]
    threads: Option<u64>,
    /// Rays per chunk of the streaming engine; the results do not depend on it.
    #[arg(long, default_value_t = raypipe::verify::CHUNK_RAYS, value_parser = clap::value_parser!(u64).range(1..=1_000_000))]
    chunk: u64,
    /// No progress bar on stderr.
    #[arg(long)]
    quiet: bool,
    /// Run one shard of the rays: K/N (0 <= K < N), or `slurm` (the Slurm array task's);
    /// needs --partial.
    #[arg(long)]
    shard: Option<String>,
    /// Write this shard's partial result to FILE (JSON) for `raypipe merge`.
    #[arg(long)]
    partial: Option<PathBuf>,
    /// Run the RTI model with this fault of the bank (a name `raypipe faults --unit rti`
    /// lists): a model wrong on purpose, to see the judge catch it on this scene.
    #[arg(long)]
    inject: Option<String>,
    #[command(flatten)]
    rti: RtiArgs,
}

#[derive(Subcommand)]
enum Cmd {
    /// Print a shell completion script (bash, zsh, fish, elvish or powershell) on stdout.
    Completions {
        /// The shell.
        #[arg(value_enum)]
        shell: clap_complete::Shell,
    },
    /// Print the man page (roff) of raypipe, or of one of its commands, on stdout.
    Man {
        /// A command (e.g. verify); none: the page of raypipe itself, which lists them.
        command: Option<String>,
    },
    /// Run every format's RTI model against the golden reference (the default command).
    Verify(VerifyArgs),
    /// Print every stage signal of one ray–triangle (or ray–box) test beside the references.
    Explain {
        /// Unit: rti or slab.
        #[arg(long, default_value = "rti")]
        unit: String,
        /// Format name.
        #[arg(long, value_parser = parse_format)]
        format: AnyFormat,
        /// Ray: ox,oy,oz,dx,dy,dz.
        #[arg(long, allow_hyphen_values = true)]
        ray: String,
        /// Triangle (unit rti): x0,y0,z0,x1,y1,z1,x2,y2,z2.
        #[arg(long, allow_hyphen_values = true)]
        tri: Option<String>,
        /// Box (unit slab): minx,miny,minz,maxx,maxy,maxz.
        #[arg(long = "box", allow_hyphen_values = true)]
        aabb: Option<String>,
        /// Slab variant: plain, conservative, directed, take-on-false, embree.
        #[arg(long, default_value = "plain")]
        variant: String,
        /// Smallest accepted t.
        #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
        tmin: f64,
        /// Largest accepted t.
        #[arg(long, default_value_t = f64::INFINITY, allow_hyphen_values = true)]
        tmax: f64,
        #[command(flatten)]
        rti: RtiArgs,
        /// Print the trace as JSON (every signal's value and bits, the references, the verdict).
        #[arg(long)]
        json: bool,
        /// Run the RTI model with this fault of the bank (as `verify --inject`).
        #[arg(long)]
        inject: Option<String>,
    },
    /// The 2-bit ray history and 1-bit trail traversals against the stack traversal on a scene's BVH.
    Traverse {
        /// OBJ scene (default: the built-in scene).
        #[arg(long)]
        scene: Option<PathBuf>,
        /// Box format(s) of the slab tester, comma-separated.
        #[arg(long, value_delimiter = ',', value_parser = parse_format, default_value = "f32,fp16,bf16,q8.24:divide")]
        format: Vec<AnyFormat>,
        /// Slab variant: plain, conservative, directed, take-on-false, embree.
        #[arg(long, default_value = "plain")]
        variant: String,
        /// Rays (half primary from a camera in front, half random incoherent).
        #[arg(long, default_value_t = 20000, value_parser = clap::value_parser!(u64).range(1..))]
        rays: u64,
        /// Random-ray seed.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// First N leaves per ray.
        #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u64).range(1..))]
        n: u64,
        /// Triangles per leaf at most (1..=255).
        #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(1..=255))]
        leaf_size: u32,
        /// Level pipelines available (the history holds 2 bits per level).
        #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u64).range(1..))]
        levels: u64,
        /// Print the results as JSON.
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        run: EngineArgs,
        #[command(flatten)]
        sharding: ShardArgs,
    },
    /// One operation of a format against the per-op oracle (APFloat): every pair or specials + random; shardable.
    Ops {
        /// Format: f32, fp16 or bf16 (ieee or ftz, recip or divide; canonical NaN rule).
        #[arg(long, value_parser = parse_format)]
        format: AnyFormat,
        /// Operation: add, sub, mul, div (the format's division mode), recip, lt, le, cmp (both compares).
        #[arg(long)]
        op: String,
        /// Every operand pair (16-bit formats: 2^32 pairs).
        #[arg(long)]
        exhaustive: bool,
        /// Pairs of a sampled sweep (the special operands' pairs first, then random).
        #[arg(long, default_value_t = 1_000_000)]
        count: u64,
        /// Seed of the random pairs.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Run one shard: K/N or slurm; needs --partial.
        #[arg(long)]
        shard: Option<String>,
        /// Write this shard's partial result to FILE for `raypipe merge`.
        #[arg(long)]
        partial: Option<PathBuf>,
        /// Print the results as JSON.
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        run: EngineArgs,
    },
    /// Merge the partial results of a sharded run (--shard K/N --partial FILE) into its report.
    Merge {
        /// The partial files, one per shard (any order).
        #[arg(required = true)]
        partials: Vec<PathBuf>,
        /// A report's files (markdown, JSON, SVG) into this directory (report partials only).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Print the results as JSON.
        #[arg(long)]
        json: bool,
    },
    /// The thesis hardware as a throughput model: figure 3-3 (time against leaf size per pipeline count) and its calibration.
    Arch {
        /// OBJ scene (default: the built-in scene).
        #[arg(long)]
        scene: Option<PathBuf>,
        /// Rays (half primary, half random incoherent, as `stats`).
        #[arg(long, default_value_t = 20000, value_parser = clap::value_parser!(u64).range(1..))]
        rays: u64,
        /// Random-ray seed.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Leaf sizes to sweep (1..=255), comma-separated.
        #[arg(long, value_delimiter = ',', default_value = "1,2,3,4,6,8,12,16,24,32,48,64", value_parser = clap::value_parser!(u32).range(1..=255))]
        leaf_sizes: Vec<u32>,
        /// RTI pipeline counts of the figure, comma-separated.
        #[arg(long = "sweep-pipelines", value_delimiter = ',', default_value = "4,8,16,32", value_parser = clap::value_parser!(u32).range(1..=4096))]
        sweep: Vec<u32>,
        /// RTI pipelines of the calibration.
        #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u32).range(1..=4096))]
        pipelines: u32,
        /// Level pipelines of the traversal core (default 32: the thesis's 25 to 32 levels).
        #[arg(long, default_value_t = 32, value_parser = clap::value_parser!(u32).range(1..=256))]
        levels: u32,
        #[command(flatten)]
        hw: ArchArgs,
        /// Write figure 3-3 as SVG into this directory.
        #[arg(long)]
        svg: Option<PathBuf>,
        /// Print the results as JSON.
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        run: EngineArgs,
    },
    /// The thesis's experiments (figs. 3-1, 3-2, 3-4, 3-5, restart overhead) over leaf sizes.
    Stats {
        /// OBJ scene (default: the built-in scene).
        #[arg(long)]
        scene: Option<PathBuf>,
        /// Rays (half primary, half random incoherent).
        #[arg(long, default_value_t = 20000, value_parser = clap::value_parser!(u64).range(1..))]
        rays: u64,
        /// Random-ray seed.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Leaf sizes to sweep (1..=255), comma-separated.
        #[arg(long, value_delimiter = ',', default_value = "1,2,4,8,16,32", value_parser = clap::value_parser!(u32).range(1..=255))]
        leaf_sizes: Vec<u32>,
        /// Write the figures as SVG into this directory.
        #[arg(long)]
        svg: Option<PathBuf>,
        /// Print the results as JSON.
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        run: EngineArgs,
    },
    /// Render through the bit-accurate pipeline (slab traversal → RTI min-capture) and diff with the golden.
    Render {
        /// OBJ scene (default: the built-in scene).
        #[arg(long)]
        scene: Option<PathBuf>,
        /// Format of both units.
        #[arg(long, value_parser = parse_format, default_value = "f32")]
        format: AnyFormat,
        /// Slab variant: plain, conservative, directed, take-on-false, embree.
        #[arg(long, default_value = "plain")]
        variant: String,
        /// Image width.
        #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(1..=8192))]
        width: u32,
        /// Image height.
        #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(1..=8192))]
        height: u32,
        /// Triangles per leaf at most.
        #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(1..=255))]
        leaf_size: u32,
        /// Eye position X,Y,Z (default: the automatic view, which frames the scene's bounding box from in front, to the right and above, or stands inside an enclosed scene).
        #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
        eye: Option<[f64; 3]>,
        /// The point at the image centre X,Y,Z (default: the bounding box's centre).
        #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
        look_at: Option<[f64; 3]>,
        /// Up direction X,Y,Z.
        #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true, default_value = "0,1,0")]
        up: [f64; 3],
        /// Vertical field of view in degrees, in (0, 180).
        #[arg(long, default_value_t = 45.0, allow_hyphen_values = true)]
        fov: f64,
        /// Output directory for render.png and diff.png.
        #[arg(long, default_value = "render-out")]
        out: PathBuf,
        /// Print the counts as JSON.
        #[arg(long)]
        json: bool,
    },
    /// Write a self-describing vector set for RTL testbenches (or check one with --check).
    Vectors {
        /// Unit: rti, slab, op, traverse or capture (the min-capture unit).
        #[arg(long, default_value = "rti")]
        unit: String,
        /// Number format (default f32, or the plan's narrowest format within its budget).
        #[arg(long, value_parser = parse_format)]
        format: Option<AnyFormat>,
        /// A plan (`raypipe plan --json`): its format, leaf size and level pipelines.
        #[arg(long)]
        plan: Option<PathBuf>,
        /// Output directory (replaced atomically).
        #[arg(long, required_unless_present = "check")]
        out: Option<PathBuf>,
        /// Vectors per coverage class.
        #[arg(long, default_value_t = 64)]
        count: u64,
        /// Seed.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Coverage level: 1 (every class on its own) or 2 (level 1 plus crossed classes).
        #[arg(long, default_value_t = 1)]
        level: u32,
        /// Worker threads (default: every core); the files do not depend on it.
        #[arg(long)]
        threads: Option<usize>,
        /// Slab variant (units slab and traverse): plain, conservative, take-on-false, embree.
        #[arg(long, default_value = "plain")]
        variant: String,
        /// Re-check an existing set against the models instead of writing one (a minimal set:
        /// also that it still detects every fault its manifest names).
        #[arg(long)]
        check: Option<PathBuf>,
        /// Write the minimal set: the fewest vectors of the default set (greedy set cover over
        /// the fault bank) that still detect every fault it detects from the outputs.
        #[arg(long, conflicts_with = "check")]
        minimal: bool,
        /// OBJ scene whose BVH the traverse unit uses (default: the built-in scene).
        #[arg(long)]
        scene: Option<PathBuf>,
        /// First N leaves per ray (unit traverse, 1..=255).
        #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u64).range(1..=255))]
        leaves: u64,
        /// Triangles per leaf at most (unit traverse, 1..=255; default 4, or the plan's).
        #[arg(long, value_parser = clap::value_parser!(u32).range(1..=255))]
        leaf_size: Option<u32>,
        /// Level pipelines the hardware has (unit traverse; the history holds 2 bits per level;
        /// default 64, or the plan's).
        #[arg(long, value_parser = clap::value_parser!(u64).range(1..))]
        levels: Option<u64>,
        #[command(flatten)]
        rti: RtiArgs,
    },
    /// Run the fault bank against a vector set: which hardware bugs the set detects.
    Faults {
        /// Unit (units with a fault bank: rti, slab, capture, traverse, op).
        #[arg(long, default_value = "rti")]
        unit: String,
        /// OBJ scene whose BVH the generated traverse set uses (default: the built-in scene;
        /// leaf size 4, first 8 leaves).
        #[arg(long, conflicts_with = "set")]
        scene: Option<PathBuf>,
        /// Slab variant of the generated set (unit slab): plain, conservative, take-on-false, embree.
        #[arg(long, default_value = "plain", conflicts_with = "set")]
        variant: String,
        /// Number format of the generated set (default f32).
        #[arg(long, value_parser = parse_format)]
        format: Option<AnyFormat>,
        /// Coverage level of the generated set: 1 or 2.
        #[arg(long, default_value_t = 1)]
        level: u32,
        /// Vectors per coverage class of the generated set.
        #[arg(long, default_value_t = 64)]
        count: u64,
        /// Seed of the generated set.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Compare only the outputs (rti: valid, hit, t, u, v; slab: hit, t_near, t_far), as for
        /// a DUT without probe ports.
        #[arg(long)]
        outputs_only: bool,
        /// Run on the set in this directory instead of generating one (its unit, format and options).
        #[arg(long, conflicts_with_all = ["format", "level", "count", "seed"])]
        set: Option<PathBuf>,
        /// Print the campaign as JSON.
        #[arg(long)]
        json: bool,
        /// Worker threads for generating the set (the result does not depend on it).
        #[arg(long)]
        threads: Option<usize>,
        #[command(flatten)]
        rti: RtiArgs,
    },
    /// What a scene needs: tree depth and history bits, culling, and the narrowest format within an error budget.
    Plan {
        /// OBJ scene (default: the built-in scene).
        #[arg(long)]
        scene: Option<PathBuf>,
        /// Candidate formats, comma-separated.
        #[arg(long, value_delimiter = ',', value_parser = parse_format, default_value = "fp16,bf16,e8m16,f32,q8.24:divide")]
        format: Vec<AnyFormat>,
        /// RTI pipelines at most (the plan chooses the count and the leaf size from the throughput model).
        #[arg(long, default_value_t = 4)]
        pipelines: u32,
        /// Largest acceptable rate of hit/miss disagreements with the golden, per test.
        #[arg(long, default_value_t = 1e-4)]
        budget: f64,
        /// Rays of the measurement.
        #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u64).range(1..))]
        rays: u64,
        /// Seed.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Level pipelines the hardware has.
        #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u64).range(1..=256))]
        levels: u64,
        /// BRAM bits the traversal core has for the tree (default: unlimited).
        #[arg(long)]
        bram_bits: Option<u64>,
        /// Rays of the throughput model's traversals.
        #[arg(long, default_value_t = 20000, value_parser = clap::value_parser!(u64).range(1..))]
        model_rays: u64,
        /// Leaf sizes the model considers (1..=255), comma-separated.
        #[arg(long, value_delimiter = ',', default_value = "1,2,3,4,6,8,12,16,24,32,48,64,128", value_parser = clap::value_parser!(u32).range(1..=255))]
        leaf_sizes: Vec<u32>,
        #[command(flatten)]
        hw: ArchArgs,
        /// Print the plan as JSON.
        #[arg(long)]
        json: bool,
    },
    /// Run time against error for every variant on the same inputs: markdown, JSON and SVG with the Pareto front.
    Report {
        /// OBJ scenes (repeatable; the built-in scene is always included).
        #[arg(long)]
        scene: Vec<PathBuf>,
        /// Formats, comma-separated.
        #[arg(long, value_delimiter = ',', value_parser = parse_format, default_value = "f32,fp16,bf16,e8m16,q8.24:divide,f32:ftz+divide")]
        format: Vec<AnyFormat>,
        /// Slab variants, comma-separated.
        #[arg(long, value_delimiter = ',', default_value = "plain,conservative,directed,take-on-false,embree")]
        variant: Vec<String>,
        /// Rays per scene.
        #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u64).range(1..))]
        rays: u64,
        /// Stress cases per class.
        #[arg(long, default_value_t = 200, value_parser = clap::value_parser!(u64).range(1..))]
        stress_count: u64,
        /// Seed.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Directory for report.md, report.json and the SVG plots.
        #[arg(long, default_value = "report-out")]
        out: PathBuf,
        /// Print JSON instead of markdown.
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        sharding: ShardArgs,
    },
    /// This machine's no-FMA FP peak and each RTI / slab implementation's throughput as a fraction of it.
    Speed {
        /// Ray–triangle pairs per call (the default 512 keeps the 15 input columns in L1).
        #[arg(long, default_value_t = 512, value_parser = clap::value_parser!(u64).range(8..))]
        pairs: u64,
        /// Seed.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Use no kernel wider than this (as a machine without the wider ones would): scalar, avx2, avx512 or avx512fp16.
        #[arg(long, value_parser = ["scalar", "avx2", "avx512", "avx512fp16"])]
        cap: Option<String>,
        /// Print the results as JSON.
        #[arg(long)]
        json: bool,
    },
    /// The numerical stability stress suite: failures against the exact decision per class, format and variant.
    Stress {
        /// Formats, comma-separated.
        #[arg(long, value_delimiter = ',', value_parser = parse_format, default_value = "f32,fp16,bf16,q8.24:divide")]
        format: Vec<AnyFormat>,
        /// Slab variants, comma-separated.
        #[arg(long, value_delimiter = ',', default_value = "plain,conservative,directed,embree")]
        variant: Vec<String>,
        /// Cases per class.
        #[arg(long, default_value_t = 500, value_parser = clap::value_parser!(u64).range(1..))]
        count: u64,
        /// Seed.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Print the results as JSON.
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        run: EngineArgs,
        #[command(flatten)]
        sharding: ShardArgs,
    },
    /// Print the RTI stage table (markdown).
    Stages {
        /// Unit: rti or slab.
        #[arg(long, default_value = "rti")]
        unit: String,
        /// Division mode of the RTI unit: recip (1/det then multiplies) or divide.
        #[arg(long, default_value = "recip")]
        div: String,
    },
}

fn parse_format(s: &str) -> Result<AnyFormat, String> {
    s.parse()
}

/// A point or direction X,Y,Z (finite numbers).
fn parse_vec3(s: &str) -> Result<[f64; 3], String> {
    let v = parse_list("X,Y,Z", s, 3)?;
    Ok([v[0], v[1], v[2]])
}

/// A point or direction as the command line takes it back.
fn vec3(v: [f64; 3]) -> String {
    format!("{},{},{}", v[0], v[1], v[2])
}

fn parse_list(what: &str, s: &str, n: usize) -> Result<Vec<f64>, String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|t| t.trim().parse::<f64>().map_err(|_| format!("{what}: '{t}' is not a number")))
        .collect::<Result<_, _>>()?;
    if v.len() != n {
        return Err(format!("{what}: expected {n} comma-separated numbers, got {}", v.len()));
    }
    if let Some(x) = v.iter().find(|x| !x.is_finite()) {
        return Err(format!("{what}: coordinates must be finite, got {x}"));
    }
    Ok(v)
}

/// The t interval of `explain`: both ends numbers (±inf allowed), tmin <= tmax, tmin not +inf
/// and tmax not -inf.
fn check_interval(tmin: f64, tmax: f64) -> Result<(), String> {
    for (name, v) in [("--tmin", tmin), ("--tmax", tmax)] {
        if v.is_nan() {
            return Err(format!("{name} must be a number, got NaN"));
        }
    }
    if tmin == f64::INFINITY || tmax == f64::NEG_INFINITY || tmin > tmax {
        return Err(format!(
            "the t interval [--tmin {tmin}, --tmax {tmax}] is empty: need tmin <= tmax, tmin < inf, tmax > -inf"
        ));
    }
    Ok(())
}

/// Prints `value` as JSON, or the text `render` gives.
fn emit<T: serde::Serialize>(json: bool, value: &T, render: impl FnOnce(&T) -> String) -> Result<(), String> {
    if json {
        println!("{}", serde_json::to_string_pretty(value).map_err(|e| e.to_string())?);
    } else {
        print!("{}", render(value));
    }
    Ok(())
}

/// Triangles tested per ray at most: each worker holds one ray's test list (4 bytes each).
/// Verify, plan and report stream their rays, so the number of rays is not limited.
const MAX_SAMPLE: u64 = 1 << 24;
/// Pairs per `speed` call at most (15 columns of 4 bytes: 1 GiB).
const MAX_SPEED_PAIRS: u64 = 1 << 24;
/// Vectors per class at most (the set is built in memory before it is written).
const MAX_VECTOR_COUNT: u64 = 100_000;

/// Refuses a size this build cannot serve, before any work.
fn limit(what: &str, n: u64, max: u64, why: &str) -> Result<(), String> {
    if n > max {
        return Err(format!("{what} = {n} is more than this command can hold: at most {max} ({why})"));
    }
    Ok(())
}

/// Rays of one verify / plan / report run at most. They are streamed (memory does not grow
/// with them), but 10¹¹ rays × 512 tests is already months of one machine: a larger campaign
/// is split into runs with different seeds.
const MAX_RAYS: u64 = 100_000_000_000;

/// Refuses more rays than one streamed run takes.
fn check_rays(rays: u64) -> Result<(), String> {
    limit("--rays", rays, MAX_RAYS, "a single streamed run; split a larger campaign into runs with different seeds")
}

/// Refuses a run this build cannot serve: too many rays, or a per-ray test list too long.
fn check_tests(rays: u64, _scene: &Scene, sample: u64) -> Result<(), String> {
    check_rays(rays)?;
    limit("--sample", sample, MAX_SAMPLE, "each worker holds one ray's test list")
}

/// The OBJ scene at `path`, or the built-in scene.
fn load_scene(path: Option<&std::path::Path>) -> Result<Scene, String> {
    match path {
        Some(p) => Scene::load_obj(p).map_err(|e| e.to_string()),
        None => Ok(Scene::builtin()),
    }
}

fn run_verify(a: VerifyArgs) -> Result<Outcome, String> {
    let rti = a.rti.config()?;
    let inject = a.inject.as_deref().map(rti_fault).transpose()?;
    let scene = load_scene(a.scene.as_deref())?;
    let plan = a.plan.as_deref().map(raypipe::plan::load).transpose()?;
    if let Some(p) = &plan {
        p.check_scene(&scene)?;
    }
    let formats = match (a.format.is_empty(), &plan) {
        (false, _) => a.format,
        (true, Some(p)) => p.within_budget()?,
        (true, None) => DEFAULT_FORMATS.iter().map(|f| f.parse().expect("built-in format name")).collect(),
    };
    check_tests(a.rays, &scene, a.sample)?;
    let shard = shard_of(a.shard.as_deref(), a.partial.as_deref())?;
    let mut cfg = VerifyConfig::new(formats, a.rays as usize, a.seed, rti, a.sample as usize);
    cfg.engine = engine::Engine::new(a.chunk).with_threads(a.threads.map(|t| t as usize)).with_shard(shard);
    cfg.progress = !a.quiet;
    cfg.inject = inject;
    if let Some(path) = &a.partial {
        let data = raypipe::verify::accumulate(&cfg, &scene);
        let (args, hash) = (raypipe::verify::args(&cfg), raypipe::partial::scene_hash(&scene));
        let p = raypipe::partial::Partial::new("verify", args, hash, a.chunk, shard, data);
        return shard_done(a.json, path, p);
    }
    let rep = verify(&cfg, &scene);
    emit(a.json, &rep, render)?;
    Ok(rep.outcome())
}

/// The RTI fault of the bank named `name` (`verify --inject`).
fn rti_fault(name: &str) -> Result<&'static faults::bank::Spec, String> {
    match faults::bank::by_name(name) {
        Some(x) if x.unit == "rti" => Ok(x),
        Some(x) => Err(format!(
            "--inject {name}: a {} fault; verify injects RTI faults (raypipe faults --unit rti lists them)",
            x.unit
        )),
        None => {
            Err(format!("--inject {name}: no such fault in the bank (raypipe faults --unit rti lists the RTI faults)"))
        }
    }
}

/// The shard of a run from `--shard` (checked against `--partial` before any work: a shard
/// needs a partial file to write, and the file must be one raypipe may write).
fn shard_of(shard: Option<&str>, partial: Option<&std::path::Path>) -> Result<engine::Shard, String> {
    let s = match shard {
        Some(s) => engine::Shard::parse(s, |v| std::env::var(v).ok())?,
        None => engine::Shard::ALL,
    };
    match partial {
        Some(p) => raypipe::partial::check_path(p)?,
        None if shard.is_some() => {
            return Err("--shard needs --partial FILE (merge the shards with raypipe merge)".into())
        }
        None => {}
    }
    Ok(s)
}

/// Writes a shard's partial result and says so (JSON with `json`); the shard's run passes.
fn shard_done<T: serde::Serialize>(
    json: bool,
    path: &std::path::Path,
    p: raypipe::partial::Partial<T>,
) -> Result<Outcome, String> {
    raypipe::partial::write(path, &p)?;
    let (command, shard) = (&p.command, p.shard);
    if json {
        let v = serde_json::json!({ "command": command, "shard": shard, "partial": path.display().to_string() });
        println!("{}", serde_json::to_string_pretty(&v).map_err(|e| e.to_string())?);
    } else {
        println!(
            "raypipe {command}: shard {shard} written to {} (merge every shard with raypipe merge)",
            path.display()
        );
    }
    Ok(Outcome::Pass)
}

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

fn run() -> Result<Outcome, String> {
    // the manifest records the exact command line: it must be text
    if let Some(a) = std::env::args_os().find(|a| a.to_str().is_none()) {
        return Err(format!(
            "argument {a:?} is not valid UTF-8; raypipe records its command line and needs text arguments"
        ));
    }
    let cli = Cli::parse();
    match cli.cmd {
        None => run_verify(VerifyArgs {
            scene: None,
            format: Vec::new(),
            rays: 1024,
            seed: 1,
            sample: 512,
            json: false,
            plan: None,
            threads: None,
            chunk: raypipe::verify::CHUNK_RAYS,
            quiet: false,
            shard: None,
            partial: None,
            inject: None,
            rti: RtiArgs { cull: false, det_threshold: 0.0, tie: Tie::First },
        }),
        Some(Cmd::Verify(a)) => run_verify(a),
        Some(Cmd::Completions { shell }) => {
            use clap::CommandFactory;
            clap_complete::generate(shell, &mut Cli::command(), "raypipe", &mut std::io::stdout());
            Ok(Outcome::Pass)
        }
        Some(Cmd::Man { command }) => {
            use clap::CommandFactory;
            let mut cli = Cli::command();
            cli.build();
            let page = match command {
                None => cli,
                Some(name) => {
                    let names: Vec<String> = cli.get_subcommands().map(|c| c.get_name().to_string()).collect();
                    let sub = cli.find_subcommand(&name).ok_or_else(|| {
                        format!("raypipe man: no command '{name}'; the commands: {}", names.join(", "))
                    })?;
                    // the page of `raypipe NAME` is named raypipe-NAME(1)
                    sub.clone().name(format!("raypipe-{name}")).bin_name(format!("raypipe {name}"))
                }
            };
            let mut roff = Vec::new();
            clap_mangen::Man::new(page).render(&mut roff).map_err(|e| e.to_string())?;
            std::io::Write::write_all(&mut std::io::stdout(), &roff).map_err(|e| e.to_string())?;
            Ok(Outcome::Pass)
        }
        Some(Cmd::Explain { unit, format, ray, tri, aabb, variant, tmin, tmax, rti, json, inject }) => {
            let cfg = rti.config()?;
            let inject = inject.as_deref().map(rti_fault).transpose()?;
            if inject.is_some() && unit != "rti" {
                return Err("--inject: explain injects RTI faults (--unit rti)".into());
            }
            let r = parse_list("--ray", &ray, 6)?;
            check_interval(tmin, tmax)?;
            let ray = Ray64 { o: [r[0], r[1], r[2]], d: [r[3], r[4], r[5]], tmin, tmax };
            match unit.as_str() {
                "rti" => {
                    let t = parse_list("--tri", tri.as_deref().ok_or("--unit rti needs --tri")?, 9)?;
                    let tri = Tri64 { v: [[t[0], t[1], t[2]], [t[3], t[4], t[5]], [t[6], t[7], t[8]]] };
                    let t = with_format!(format, |f| raypipe::explain::trace_rti_faulty(
                        &Rti::new(f, cfg),
                        &ray,
                        &tri,
                        inject
                    ));
                    emit(json, &t, raypipe::explain::render_rti)?;
                }
                "slab" => {
                    let b = parse_list("--box", aabb.as_deref().ok_or("--unit slab needs --box")?, 6)?;
                    let (lo, hi) = ([b[0], b[1], b[2]], [b[3], b[4], b[5]]);
                    let t = with_format!(format, |f| {
                        let sc = SlabConfig::named_for(&variant, &f)?;
                        raypipe::explain::trace_slab(&Slab::new(f, sc), &variant, &ray, lo, hi)
                    })?;
                    emit(json, &t, raypipe::explain::render_slab)?;
                }
                other => return Err(format!("unknown unit '{other}'; units: rti, slab")),
            }
            Ok(Outcome::Pass)
        }
        Some(Cmd::Traverse { scene, format, variant, rays, seed, n, leaf_size, levels, json, run, sharding }) => {
            check_rays(rays)?;
            let sh = shard_of(sharding.shard.as_deref(), sharding.partial.as_deref())?;
            let scene = load_scene(scene.as_deref())?;
            let cfg = raypipe::traverse::TraverseConfig {
                formats: format,
                variant,
                rays: rays as usize,
                seed,
                n: n as usize,
                leaf_size,
                levels: levels as usize,
                engine: run.engine(raypipe::traverse::CHUNK_RAYS).with_shard(sh),
                progress: !run.quiet,
            };
            let rep = raypipe::traverse::traverse(&cfg, &scene)?;
            if let Some(path) = &sharding.partial {
                let hash = raypipe::partial::scene_hash(&scene);
                let args = raypipe::traverse::args(&cfg);
                let p = raypipe::partial::Partial::new("traverse", args, hash, raypipe::traverse::CHUNK_RAYS, sh, rep);
                return shard_done(json, path, p);
            }
            emit(json, &rep, raypipe::traverse::render)?;
            Ok(rep.outcome())
        }
        Some(Cmd::Ops { format, op, exhaustive, count, seed, shard, partial, json, run }) => {
            let sh = shard_of(shard.as_deref(), partial.as_deref())?;
            let cfg = raypipe::ops::OpsConfig {
                format,
                op,
                exhaustive,
                count,
                seed,
                engine: run.engine(raypipe::ops::CHUNK).with_shard(sh),
                progress: !run.quiet,
            };
            let data = raypipe::ops::accumulate(&cfg)?;
            if let Some(path) = &partial {
                let p = raypipe::partial::Partial::new(
                    "ops",
                    raypipe::ops::args(&cfg),
                    String::new(),
                    raypipe::ops::CHUNK,
                    sh,
                    data,
                );
                return shard_done(json, path, p);
            }
            let rep = raypipe::ops::finish(data);
            emit(json, &rep, raypipe::ops::render)?;
            Ok(Outcome::from(rep.passed))
        }
        Some(Cmd::Merge { partials, out, json }) => {
            let dir = out.as_deref().map(|d| OutDir::check(d, &raypipe::report::FILES)).transpose()?;
            let parts = raypipe::partial::read_all(&partials)?;
            if dir.is_some() && parts[0].command != "report" {
                return Err(format!("--out writes a report's files; these are {} partials", parts[0].command));
            }
            match parts[0].command.as_str() {
                "report" => {
                    let mut rep = raypipe::report::finish(raypipe::partial::merge_data(
                        &parts,
                        raypipe::report::ReportData::merge,
                    )?)?;
                    // the timings come from the shards' machines; the merge names its own
                    rep.command = command_as_typed();
                    if let Some(dir) = &dir {
                        for f in raypipe::report::write(&rep, dir)? {
                            eprintln!("wrote {}", f.display());
                        }
                    }
                    emit(json, &rep, raypipe::report::markdown)?;
                    Ok(Outcome::Pass)
                }
                "stress" => {
                    let rep = raypipe::partial::merge_data(&parts, raypipe::stress::StressReport::merge)?;
                    emit(json, &rep, raypipe::stress::render)?;
                    Ok(Outcome::from(rep.passed))
                }
                "traverse" => {
                    let rep = raypipe::partial::merge_data(&parts, raypipe::traverse::TraverseReport::merge)?;
                    emit(json, &rep, raypipe::traverse::render)?;
                    Ok(rep.outcome())
                }
                "ops" => {
                    let rep = raypipe::ops::finish(raypipe::partial::merge_data(&parts, raypipe::ops::OpsData::merge)?);
                    emit(json, &rep, raypipe::ops::render)?;
                    Ok(Outcome::from(rep.passed))
                }
                "verify" => {
                    let rep = raypipe::verify::finish(raypipe::partial::merge_data(
                        &parts,
                        raypipe::verify::VerifyData::merge,
                    )?);
                    emit(json, &rep, render)?;
                    Ok(rep.outcome())
                }
                other => Err(format!("raypipe merge: partials of '{other}' cannot be merged by this raypipe")),
            }
        }
        Some(Cmd::Arch { scene, rays, seed, leaf_sizes, sweep, pipelines, levels, hw, svg, json, run }) => {
            check_rays(rays)?;
            let params = hw.params(pipelines, levels);
            params.check()?;
            let out = svg.as_deref().map(|d| OutDir::check(d, &raypipe::arch::SVG_FILES)).transpose()?;
            let scene = load_scene(scene.as_deref())?;
            let eng = run.engine(raypipe::traverse::CHUNK_RAYS);
            let cfg = raypipe::arch::ArchConfig { params, pipelines: sweep, leaf_sizes, rays, seed };
            let rep = raypipe::arch::arch(&eng, &cfg, &scene)?;
            emit(json, &rep, raypipe::arch::render)?;
            if let Some(out) = out {
                for p in raypipe::arch::write_svgs(&rep, &out)? {
                    eprintln!("wrote {}", p.display());
                }
            }
            Ok(Outcome::Pass)
        }
        Some(Cmd::Stats { scene, rays, seed, leaf_sizes, svg, json, run }) => {
            check_rays(rays)?;
            let out = svg.as_deref().map(|d| OutDir::check(d, &raypipe::stats::SVG_FILES)).transpose()?;
            let scene = load_scene(scene.as_deref())?;
            let eng = run.engine(raypipe::traverse::CHUNK_RAYS);
            let rep = raypipe::stats::stats_on(&eng, !run.quiet, &scene, &leaf_sizes, rays as usize, seed)?;
            emit(json, &rep, raypipe::stats::render)?;
            if let Some(out) = out {
                for p in raypipe::stats::write_svgs(&rep, &out)? {
                    eprintln!("wrote {}", p.display());
                }
            }
            Ok(rep.outcome())
        }
        Some(Cmd::Render { scene, format, variant, width, height, leaf_size, eye, look_at, up, fov, out, json }) => {
            with_format!(format, |f| SlabConfig::named_for(&variant, &f).map(|_| ()))?;
            let scene = load_scene(scene.as_deref())?;
            let auto = raypipe::camera::Camera::auto(&scene, fov, width as f64 / height as f64);
            let camera = raypipe::camera::Camera {
                eye: eye.unwrap_or(auto.eye),
                look_at: look_at.unwrap_or(auto.look_at),
                up,
                fov,
            };
            camera.check()?;
            let dir = OutDir::check(&out, &raypipe::render::FILES)?;
            let rep = with_format!(format, |f| raypipe::render::render(
                f, &variant, &scene, &camera, width, height, leaf_size, &dir
            ))?;
            emit(json, &rep, |rep| {
                format!(
                    "raypipe render: scene {}, format {}, slab variant {}: {} pixels, golden hits {}, holes (golden hit, pipeline miss) {}, false hits {}, other triangle {}; wrote {}/render.png and {}/diff.png (red: hole, blue: false hit, yellow: other triangle)",
                    scene.name, rep.format, rep.variant, rep.pixels, rep.golden_hits, rep.holes, rep.false_hits, rep.other_triangle, out.display(), out.display()
                ) + &format!("\ncamera: --eye {} --look-at {} --up {} --fov {}", vec3(rep.camera.eye), vec3(rep.camera.look_at), vec3(rep.camera.up), rep.camera.fov) + &format!("\nboxes the slab unit culled on the way to the golden closest hit: {}{}\n", rep.culled,
                    if rep.conservative { if rep.culled > 0 { " (VIOLATION: the variant is conservative in this format)" } else { " (the variant is conservative in this format: must be 0)" } } else { "" })
                    + &rep.vacuous().map(|why| format!("culling check: INCONCLUSIVE: {why}\n")).unwrap_or_default()
            })?;
            Ok(rep.outcome())
        }
        Some(Cmd::Vectors {
            unit,
            format,
            plan,
            out,
            count,
            seed,
            level,
            threads,
            variant,
            check,
            minimal,
            scene,
            leaves,
            leaf_size,
            levels,
            rti,
        }) => {
            if let Some(dir) = check {
                let n = vectors::gen::check_set(&dir)?;
                println!(
                    "{}: {n} vectors; the manifest, the HDL packages and every input, expected and stage row are what this raypipe writes",
                    dir.display()
                );
                if let Some(detects) = raypipe::faults::check_minimal(&dir)? {
                    println!(
                        "{}: a minimal set; it still detects all {detects} faults its manifest names",
                        dir.display()
                    );
                }
                return Ok(Outcome::Pass);
            }
            let out = out.ok_or("--out is required")?;
            limit("--count", count, MAX_VECTOR_COUNT, "a set is built in memory before it is written")?;
            vectors::gen::check_out(&out)?;
            let unit: vectors::gen::Unit = unit.parse()?;
            // a plan fixes what the scene does not need: the format, the leaf size, the levels
            let plan = plan.as_deref().map(raypipe::plan::load).transpose()?;
            let format = match (format, &plan) {
                (Some(f), _) => f,
                (None, Some(p)) => p.narrowest()?,
                (None, None) => "f32".parse().expect("built-in format name"),
            };
            // the plan's leaf size and level pipelines, unless given (a conflict is refused)
            let (leaf_size, levels) = match &plan {
                Some(p) => {
                    for (flag, given, planned) in [
                        ("--leaf-size", leaf_size.map(u64::from), p.leaf_size as u64),
                        ("--levels", levels, p.level_pipelines as u64),
                    ] {
                        if let Some(g) = given.filter(|&g| g != planned) {
                            return Err(format!("{flag} {g} conflicts with the plan's {planned}; drop one of them"));
                        }
                    }
                    (p.leaf_size, p.level_pipelines as u64)
                }
                None => (leaf_size.unwrap_or(4), levels.unwrap_or(64)),
            };
            let tree = traverse_tree(unit, scene.as_deref(), leaf_size, plan.as_ref())?;
            let req = vectors::gen::Request {
                unit,
                tree,
                leaves: leaves as usize,
                max_levels: levels as usize,
                threads: threads.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get())),
                format,
                count: count as usize,
                seed,
                level,
                command: command_without_threads(),
                rti: rti.config()?,
                slab_variant: variant,
            };
            let set = vectors::gen::generate(&req)?;
            let set = if minimal {
                let (cut, c) = faults::minimal::minimal(&set, &command_without_threads())?;
                let m = cut.manifest.minimal.as_ref().expect("a minimal set says so");
                println!(
                    "minimal set: {} of {} vectors ({:.1} %) detect the {} faults of the {} bank the default set detects from the outputs ({} escape both; see raypipe faults)",
                    cut.manifest.files[0].rows,
                    m.from_vectors,
                    100.0 * cut.manifest.files[0].rows as f64 / m.from_vectors.max(1) as f64,
                    m.detects.len(),
                    cut.manifest.unit,
                    c.escaped
                );
                cut
            } else {
                set
            };
            vectors::gen::write_set(&set, &out)?;
            let m = &set.manifest;
            println!(
                "wrote {}: unit {}, format {}, {} vectors ({}), seed {}",
                out.display(),
                m.unit,
                m.format,
                m.files[0].rows,
                m.classes.iter().map(|c| format!("{} {}", c.name, c.count)).collect::<Vec<_>>().join(", "),
                m.seed
            );
            Ok(Outcome::Pass)
        }
        Some(Cmd::Faults {
            unit,
            scene,
            variant,
            format,
            level,
            count,
            seed,
            outputs_only,
            set,
            json,
            threads,
            rti,
        }) => {
            let c = match set {
                Some(dir) => raypipe::faults::on_dir(&dir, outputs_only)?,
                None => {
                    limit("--count", count, MAX_VECTOR_COUNT, "a set is built in memory")?;
                    let unit: vectors::gen::Unit = unit.parse()?;
                    let tree = traverse_tree(unit, scene.as_deref(), 4, None)?;
                    let req = vectors::gen::Request {
                        unit,
                        tree,
                        leaves: 8,
                        max_levels: 64,
                        threads: threads.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get())),
                        format: format.unwrap_or_else(|| "f32".parse().expect("built-in format name")),
                        count: count as usize,
                        seed,
                        level,
                        command: command_without_threads(),
                        rti: rti.config()?,
                        slab_variant: variant,
                    };
                    raypipe::faults::on_request(&req, outputs_only)?
                }
            };
            emit(json, &c, raypipe::faults::render)?;
            Ok(Outcome::from(c.complete()))
        }
        Some(Cmd::Plan {
            scene,
            format,
            pipelines,
            budget,
            rays,
            seed,
            levels,
            bram_bits,
            model_rays,
            leaf_sizes,
            hw,
            json,
        }) => {
            let scene = load_scene(scene.as_deref())?;
            check_tests(rays, &scene, 512)?;
            check_rays(model_rays)?;
            let cfg = raypipe::plan::PlanConfig {
                formats: format,
                pipelines,
                budget,
                rays: rays as usize,
                seed,
                max_levels: levels as usize,
                arch: hw.params(pipelines.max(1), levels as u32),
                model_rays,
                bram_bits,
                leaf_sizes,
            };
            let p = raypipe::plan::plan(&cfg, &scene)?;
            emit(json, &p, raypipe::plan::render)?;
            Ok(Outcome::Pass)
        }
        Some(Cmd::Report { scene, format, variant, rays, stress_count, seed, out, json, sharding }) => {
            let sh = shard_of(sharding.shard.as_deref(), sharding.partial.as_deref())?;
            // a shard writes its partial, not the report's files
            let dir = match sharding.partial {
                None => Some(OutDir::check(&out, &raypipe::report::FILES)?),
                Some(_) => None,
            };
            let mut scenes = vec![Scene::builtin()];
            for p in &scene {
                scenes.push(load_scene(Some(p))?);
            }
            for s in &scenes {
                check_tests(rays, s, 512)?;
            }
            let cfg = raypipe::report::ReportConfig {
                formats: format,
                variants: variant,
                rays: rays as usize,
                stress_count: stress_count as usize,
                seed,
                engine: engine::Engine::new(raypipe::verify::CHUNK_RAYS).with_shard(sh),
            };
            if let Some(path) = &sharding.partial {
                let data = raypipe::report::accumulate(&cfg, &scenes)?;
                let args = raypipe::report::args(&cfg, &scenes);
                let p = raypipe::partial::Partial::new(
                    "report",
                    args,
                    String::new(),
                    raypipe::verify::CHUNK_RAYS,
                    sh,
                    data,
                );
                return shard_done(json, path, p);
            }
            let mut rep = raypipe::report::report(&cfg, &scenes)?;
            rep.command = command_as_typed();
            let files = raypipe::report::write(&rep, dir.as_ref().expect("checked when there is no partial"))?;
            emit(json, &rep, raypipe::report::markdown)?;
            for f in files {
                eprintln!("wrote {}", f.display());
            }
            Ok(Outcome::Pass)
        }
        Some(Cmd::Speed { pairs, seed, cap, json }) => {
            limit("--pairs", pairs, MAX_SPEED_PAIRS, "the columns are held in memory")?;
            if let Some(c) = &cap {
                use datapath::simd::Kernel;
                let k = match c.as_str() {
                    "scalar" => Kernel::Scalar,
                    "avx2" => Kernel::Avx2,
                    "avx512" => Kernel::Avx512,
                    _ => Kernel::Avx512Fp16,
                };
                datapath::simd::cap_process(k);
            }
            let mut rep = raypipe::speed::speed(pairs as usize, seed);
            rep.cap = cap;
            emit(json, &rep, raypipe::speed::render)?;
            Ok(Outcome::Pass)
        }
        Some(Cmd::Stress { format, variant, count, seed, json, run, sharding }) => {
            let sh = shard_of(sharding.shard.as_deref(), sharding.partial.as_deref())?;
            let mut cfg = raypipe::stress::StressConfig::new(format, variant, count as usize, seed);
            cfg.engine = run.engine(raypipe::stress::CHUNK_CASES).with_shard(sh);
            cfg.progress = !run.quiet;
            let rep = raypipe::stress::stress(&cfg)?;
            if let Some(path) = &sharding.partial {
                let args = raypipe::stress::args(&cfg);
                let p = raypipe::partial::Partial::new(
                    "stress",
                    args,
                    String::new(),
                    raypipe::stress::CHUNK_CASES,
                    sh,
                    rep,
                );
                return shard_done(json, path, p);
            }
            emit(json, &rep, raypipe::stress::render)?;
            Ok(Outcome::from(rep.passed))
        }
        Some(Cmd::Stages { unit, div }) => {
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
    }
}

/// The command line as recorded in a vector set's manifest: without `--threads`, which does
/// not change a single byte of the set.
/// The command line as a user types it: `raypipe` and the arguments, without `--threads`.
fn command_as_typed() -> String {
    let c = command_without_threads();
    match c.split_once(' ') {
        Some((_, rest)) => format!("raypipe {rest}"),
        None => "raypipe".to_string(),
    }
}

fn command_without_threads() -> String {
    let mut out = Vec::new();
    let mut args = std::env::args();
    while let Some(a) = args.next() {
        if a == "--threads" {
            args.next();
        } else if !a.starts_with("--threads=") {
            out.push(a);
        }
    }
    out.join(" ")
}

/// The BVH a traverse vector set uses: the scene's (default: the built-in one) built with
/// `leaf_size` triangles per leaf, checked against the plan when there is one; `None` for the
/// other units, which refuse `--scene`.
fn traverse_tree(
    unit: vectors::gen::Unit,
    scene: Option<&std::path::Path>,
    leaf_size: u32,
    plan: Option<&raypipe::plan::Plan>,
) -> Result<Option<vectors::traverse::TreeInput>, String> {
    if unit != vectors::gen::Unit::Traverse {
        return match scene {
            Some(_) => Err(format!("--scene is for unit traverse; unit {unit:?} draws its own cases")),
            None => Ok(None),
        };
    }
    let scene = load_scene(scene)?;
    if let Some(p) = plan {
        p.check_scene(&scene)?;
    }
    let b = raypipe::bvh::build(&scene, leaf_size);
    Ok(Some(vectors::traverse::TreeInput { name: scene.name.clone(), nodes: b.nodes, root: 0 }))
}

fn main() -> ExitCode {
    // a closed stdout pipe (`raypipe … | head`) ends the process quietly, as it does any Unix
    // tool, instead of failing a print (Rust ignores SIGPIPE by default, so println! panics)
    #[cfg(unix)]
    // SAFETY: restoring the default disposition of one signal before any thread starts
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    // an interrupted run removes its temporary files and directories (exit 130, as a shell does)
    let _ = ctrlc::set_handler(|| {
        vectors::outdir::remove_partials();
        eprintln!("interrupted: removed the partial output");
        std::process::exit(130);
    });
    match run() {
        Ok(o) => ExitCode::from(o as u8),
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}
