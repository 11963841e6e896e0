//! `raypipe ops`: one operation of a format's model against the independent per-op oracle
//! (`golden::ops`, APFloat) on the streaming engine — every operand pair of a 16-bit format
//! with `--exhaustive` (2³² items), else TestFloat-style levels: every pair of the format's
//! special operands, then seeded random encodings. Sharded and merged like `verify`.
//!
//! Item i of an exhaustive sweep is the pair (a, b) = (i >> 16, i & 0xffff). Item i of a
//! sampled sweep is pair (s[i / S], s[i mod S]) of the S special operands while i < S², and
//! after that two random encodings drawn by `SplitMix64::for_item(seed, OPS_STREAM, i)`.
//! A result is right when its encoding equals the oracle's, or, when the oracle's is a NaN,
//! when it is the format's canonical NaN (the canonical NaN rule). `lt` and `le` are 0 or 1;
//! `cmp` is both, (a < b) + 2 (a <= b).

use datapath::format::{DivMode, NanMode, Subnormals};
use datapath::rng::SplitMix64;
use datapath::{AnyFormat, Format};
use golden::ops::{oracle_op, OracleFormat, OracleOp, OracleRules};
use serde::{Deserialize, Serialize};

/// Stream number of the random operands in [`SplitMix64::for_item`].
pub const OPS_STREAM: u64 = 0x6f70_7321;
/// Items per chunk.
pub const CHUNK: u64 = 1 << 16;

/// The operations `ops` sweeps.
pub const OP_NAMES: [&str; 8] = ["add", "sub", "mul", "div", "recip", "lt", "le", "cmp"];

/// What to sweep.
#[derive(Clone, Debug)]
pub struct OpsConfig {
    /// Format (f32, fp16 or bf16, canonical NaN rule).
    pub format: AnyFormat,
    /// Operation name (one of [`OP_NAMES`]).
    pub op: String,
    /// Every operand pair (16-bit formats only).
    pub exhaustive: bool,
    /// Items of a sampled sweep.
    pub count: u64,
    /// Seed of the random operands.
    pub seed: u64,
    /// The engine (its shard included).
    pub engine: engine::Engine,
    /// Progress on stderr.
    pub progress: bool,
}

/// What a sweep accumulates (a shard's partial result).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct OpsData {
    /// Format name.
    pub format: String,
    /// Operation.
    pub op: String,
    /// Items of the whole sweep.
    pub items: u64,
    /// Every pair.
    pub exhaustive: bool,
    /// Seed.
    pub seed: u64,
    /// Tests run, results differing from the oracle.
    pub counts: engine::Counts<2>,
    /// The first differing item: its operands and results.
    pub first: engine::First<u64, String>,
}

impl OpsData {
    /// Adds another shard's data of the same sweep.
    pub fn merge(&mut self, o: OpsData) -> Result<(), String> {
        use engine::Merge as _;
        if (&self.format, &self.op, self.items, self.exhaustive, self.seed)
            != (&o.format, &o.op, o.items, o.exhaustive, o.seed)
        {
            return Err("partials disagree on the sweep".into());
        }
        self.counts.merge(o.counts);
        self.first.merge(o.first);
        Ok(())
    }
}

impl crate::partial::Sharded for OpsData {
    const COMMAND: &'static str = "ops";
    type Report = OpsReport;
    fn add(&mut self, other: Self) -> Result<(), String> {
        self.merge(other)
    }
    fn finish(self) -> Result<OpsReport, String> {
        Ok(finish(self))
    }
    fn render(r: &OpsReport) -> String {
        render(r)
    }
    fn outcome(r: &OpsReport) -> crate::Outcome {
        crate::Outcome::from(r.passed)
    }
}

impl crate::partial::Consistent for OpsData {
    /// One test per item of the shard, mismatches within the tests, a first mismatch record
    /// exactly when mismatches are counted.
    fn check(&self, share: &dyn Fn(u64, u64) -> u64) -> Result<(), String> {
        use crate::partial::require;
        let [tests, bad] = self.counts.0;
        let want = share(0, self.items);
        require(tests == want, || format!("{tests} tests, but the shard's items are {want}"))?;
        require(bad <= tests, || format!("{bad} mismatches exceed {tests} tests"))?;
        require((bad > 0) == self.first.0.is_some(), || {
            format!(
                "{bad} mismatches counted but the first-mismatch record is {}",
                if self.first.0.is_some() { "present" } else { "missing" }
            )
        })
    }
}

/// The report.
#[derive(Clone, Debug, Serialize)]
pub struct OpsReport {
    /// Format name.
    pub format: String,
    /// Operation.
    pub op: String,
    /// Every pair.
    pub exhaustive: bool,
    /// Seed (sampled sweeps).
    pub seed: u64,
    /// Tests run.
    pub tests: u64,
    /// Results differing from the oracle.
    pub mismatches: u64,
    /// The first differing item.
    pub first_mismatch: Option<String>,
    /// No mismatch.
    pub passed: bool,
}

fn oracle_format(f: &AnyFormat) -> Result<(OracleFormat, datapath::format::FpOpts), String> {
    let (o, opts) = match f {
        AnyFormat::F16(x) => (OracleFormat::Binary16, x.opts),
        AnyFormat::Bf16(x) => (OracleFormat::BFloat16, x.opts),
        AnyFormat::F32(x) => (OracleFormat::Binary32, x.opts),
        _ => return Err(format!("raypipe ops: the per-op oracle covers f32, fp16 and bf16, not {}", f.name())),
    };
    if opts.nan != NanMode::Canonical {
        return Err(format!(
            "raypipe ops: {} uses the propagate NaN rule; the oracle judges the canonical rule",
            f.name()
        ));
    }
    Ok((o, opts))
}

fn oracle_op_of(name: &str) -> Result<OracleOp, String> {
    Ok(match name {
        "add" => OracleOp::Add,
        "sub" => OracleOp::Sub,
        "mul" => OracleOp::Mul,
        "div" => OracleOp::Div,
        "recip" => OracleOp::Recip,
        "lt" => OracleOp::Lt,
        "le" => OracleOp::Le,
        "cmp" => OracleOp::Cmp,
        other => return Err(format!("unknown --op '{other}'; ops: {}", OP_NAMES.join(", "))),
    })
}

/// Items of the sweep (refusing what it cannot run).
pub fn items(cfg: &OpsConfig) -> Result<u64, String> {
    oracle_format(&cfg.format)?;
    oracle_op_of(&cfg.op)?;
    let width = datapath::with_format!(cfg.format, |f| f.width());
    if cfg.exhaustive {
        if width != 16 {
            return Err(format!(
                "--exhaustive needs a 16-bit format (2^32 pairs); {} has {width} bits",
                cfg.format.name()
            ));
        }
        return Ok(1 << 32);
    }
    if cfg.count == 0 {
        return Err("--count must be at least 1".into());
    }
    Ok(cfg.count)
}

/// The special operands of a layout (TestFloat's level 1 in spirit): ±0, the smallest and
/// largest subnormals, the smallest normal and its successor, ±1 and its neighbours, 2, the
/// largest finite value, ±∞, a quiet and a signalling NaN.
fn specials(width: u32, man: u32) -> Vec<u64> {
    let sign = 1u64 << (width - 1);
    let exp_mask = sign - (1 << man);
    let one = ((exp_mask >> man) >> 1) << man;
    let mut v = vec![
        0,
        1,
        (1 << man) - 1,
        1 << man,
        (1 << man) + 1,
        one - 1,
        one,
        one + 1,
        one + (1 << man),
        exp_mask - 1,
        exp_mask,
        exp_mask | (1 << (man - 1)),
        exp_mask | 1,
    ];
    let neg: Vec<u64> = v.iter().map(|x| x | sign).collect();
    v.extend(neg);
    v
}

/// The operand mask of a `width`-bit format and its special operands ([`specials`]).
fn sweep_operands(of: OracleFormat, width: u32) -> (u64, Vec<u64>) {
    let mask = if width == 64 { u64::MAX } else { (1u64 << width) - 1 };
    let man = match of {
        OracleFormat::Binary16 => 10,
        OracleFormat::BFloat16 => 7,
        OracleFormat::Binary32 => 23,
    };
    (mask, specials(width, man))
}

/// Item `i` of the sweep: every pair in order (exhaustive), or the specials' pairs `sp` first,
/// then random pairs (masked to the format's width).
fn pair_of(cfg: &OpsConfig, sp: &[u64], mask: u64, i: u64) -> (u64, u64) {
    let s = sp.len() as u64;
    if cfg.exhaustive {
        (i >> 16, i & 0xffff)
    } else if i < s * s {
        (sp[(i / s) as usize], sp[(i % s) as usize])
    } else {
        let mut r = SplitMix64::for_item(cfg.seed, OPS_STREAM, i);
        (r.next_u64() & mask, r.next_u64() & mask)
    }
}

/// The functional coverage of the engine's shard of the sweep (`raypipe ops --cover`): every
/// item as a row of the op unit's coverage model (`vectors::cover`; the manifest of an op set
/// of the format defines it). Rows: class `special` for the specials' pairs, `random` for the
/// others (exhaustive: every pair); the opcode of the operation (`recip` is `div` with a = 1,
/// `cmp` is one `lt` and one `le` row); the expected outputs as the op unit computes them.
pub fn cover(cfg: &OpsConfig) -> Result<(vectors::manifest::Manifest, vectors::cover::Coverage), String> {
    let n = items(cfg)?;
    let (of, _) = oracle_format(&cfg.format)?;
    let op = oracle_op_of(&cfg.op)?;
    let mut req = vectors::gen::Request::new(vectors::gen::Unit::Op, cfg.format);
    req.command = "raypipe ops --cover".into();
    // the op set's classes are the model's class bins (rows of class 0 `special`, 1 `random`)
    let run = vectors::cover_file::RunModel::new(&req, None)?;
    let opcodes: &[u64] = match op {
        OracleOp::Add => &[0],
        OracleOp::Sub => &[1],
        OracleOp::Mul => &[2],
        OracleOp::Div | OracleOp::Recip => &[3],
        OracleOp::Lt => &[4],
        OracleOp::Le => &[5],
        OracleOp::Cmp => &[4, 5],
    };
    let bar = engine::Progress::new(cfg.engine.shard_items(n), "pairs (coverage)", !cfg.progress);
    let acc = datapath::with_format!(cfg.format, |f| {
        let (mask, sp) = sweep_operands(of, f.width());
        let one = f.to_bits(f.one());
        let bins = vectors::cover::RowBins::new(&run.manifest);
        engine::run(
            &cfg.engine,
            n,
            &bar,
            || (vec![vec![vec![0u64; 4]], vec![vec![0u64; 2]]], Vec::new()),
            |(contents, hits), range| {
                let mut acc = crate::cover_run::CoverAcc::new(1);
                for i in range {
                    let (a, b) = pair_of(cfg, &sp, mask, i);
                    let a = if op == OracleOp::Recip { one } else { a };
                    let class = u64::from(cfg.exhaustive || i >= (sp.len() * sp.len()) as u64);
                    for &code in opcodes {
                        let (res, cmp) = vectors::gen::op_eval(&f, code, f.from_bits(a), f.from_bits(b));
                        contents[0][0].copy_from_slice(&[class, code, a, b]);
                        contents[1][0].copy_from_slice(&[res, cmp]);
                        // (a row of the op unit's own layout: every field is there)
                        run.count(&bins, contents, hits, &mut acc.0[0]).expect("an op row");
                    }
                }
                acc
            },
        )
    });
    bar.finish();
    Ok(run.finish(acc.0.into_iter().next().unwrap_or_default()))
}

/// Runs the engine's shard of the sweep.
pub fn accumulate(cfg: &OpsConfig) -> Result<OpsData, String> {
    let n = items(cfg)?;
    let (of, opts) = oracle_format(&cfg.format)?;
    let op = oracle_op_of(&cfg.op)?;
    let rules = OracleRules { ftz: opts.subnormals == Subnormals::Ftz, recip_div: opts.div == DivMode::RecipMul };
    let bar = engine::Progress::new(cfg.engine.shard_items(n), "pairs", !cfg.progress);
    bar.message(format!("{} {}", cfg.format.name(), cfg.op));
    let acc = datapath::with_format!(cfg.format, |f| {
        let (mask, sp) = sweep_operands(of, f.width());
        // the canonical NaN: what the model makes of any NaN input (the canonical rule)
        let canonical = f.to_bits(f.from_f64(f64::NAN));
        let pair = |i: u64| pair_of(cfg, &sp, mask, i);
        engine::run(
            &cfg.engine,
            n,
            &bar,
            || (),
            |_, range| {
                let mut counts = engine::Counts::<2>::default();
                let mut first = engine::First::default();
                for i in range {
                    let (a, b) = pair(i);
                    let (x, y) = (f.from_bits(a), f.from_bits(b));
                    let got = match op {
                        OracleOp::Add => f.to_bits(f.add(x, y)),
                        OracleOp::Sub => f.to_bits(f.sub(x, y)),
                        OracleOp::Mul => f.to_bits(f.mul(x, y)),
                        OracleOp::Div => f.to_bits(f.div(x, y)),
                        OracleOp::Recip => f.to_bits(f.div(f.one(), y)),
                        OracleOp::Lt => f.lt(x, y) as u64,
                        OracleOp::Le => f.le(x, y) as u64,
                        OracleOp::Cmp => f.lt(x, y) as u64 + 2 * f.le(x, y) as u64,
                    };
                    let want = oracle_op(of, rules, op, a, b);
                    let cmp = matches!(op, OracleOp::Lt | OracleOp::Le | OracleOp::Cmp);
                    let ok = if !cmp && f.is_nan(f.from_bits(want)) { got == canonical } else { got == want };
                    counts.0[0] += 1;
                    if !ok {
                        counts.0[1] += 1;
                        first.offer(i, || {
                            format!("item {i}: {a:#x} {} {b:#x}: model {got:#x}, oracle {want:#x}", cfg.op)
                        });
                    }
                }
                (counts, first)
            },
        )
    });
    bar.finish();
    Ok(OpsData {
        format: cfg.format.name(),
        op: cfg.op.clone(),
        items: n,
        exhaustive: cfg.exhaustive,
        seed: cfg.seed,
        counts: acc.0,
        first: acc.1,
    })
}

/// The options that change a sweep's results, for a partial's `args`.
pub fn args(cfg: &OpsConfig) -> serde_json::Value {
    serde_json::json!({
        "format": cfg.format.name(),
        "op": cfg.op,
        "exhaustive": cfg.exhaustive,
        "count": cfg.count,
        "seed": cfg.seed,
    })
}

/// The report of (merged) data.
pub fn finish(d: OpsData) -> OpsReport {
    OpsReport {
        format: d.format,
        op: d.op,
        exhaustive: d.exhaustive,
        seed: d.seed,
        tests: d.counts.0[0],
        mismatches: d.counts.0[1],
        first_mismatch: d.first.into_inner(),
        passed: d.counts.0[1] == 0,
    }
}

/// The report as text.
pub fn render(r: &OpsReport) -> String {
    let mut s = format!(
        "raypipe ops: {} {} against the per-op oracle (APFloat), {}: {} tests, {} mismatches\n",
        r.format,
        r.op,
        if r.exhaustive { "every operand pair".to_string() } else { format!("specials then random, seed {}", r.seed) },
        r.tests,
        r.mismatches
    );
    if let Some(m) = &r.first_mismatch {
        s += &format!("first mismatch: {m}\n");
    }
    s
}
