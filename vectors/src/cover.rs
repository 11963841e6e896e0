//! Functional coverage of vector sets: a coverage model read from a set's manifest (every
//! field of the inputs, the expected outputs and the stage signals is a coverpoint, with bins
//! by the field's kind) and the counts a set's rows put into its bins. Counts merge exactly
//! (integer sums), so the coverage of shards merged is the coverage of one pass.
//!
//! Bins:
//! - an IEEE-like float field: `+0`, `-0`, `+subnormal`, `-subnormal`, `+min normal`,
//!   `-min normal`, `+normal`, `-normal`, `+max finite`, `-max finite`, `+inf`, `-inf`,
//!   `canonical NaN` (the contract's: exponent all ones, only the top fraction bit set, either
//!   sign) and `other NaN` (any other payload, quiet or signaling); a normal bin excludes the
//!   smallest and the largest normal, which have their own bins;
//! - a fixed-point field: `0`, `+1 step`, `-1 step`, `+max` (saturated high), `min`
//!   (saturated low), `positive`, `negative` (the others of each sign);
//! - a flag: `0`, `1`;
//! - the class column: one bin per class of the manifest;
//! - traverse: the leaves returned (`0`, `1 to N-1`, `N`: the N-limit reached), the passes
//!   (`0`, `1`, `2`, `3 or more`) and each level's final history state (`00` … `11`); and, from
//!   the ray re-run on the set's own tree (the rows do not hold them), the back-traversal
//!   distance of each restart (`0`, `1`, `2`, `3 or more` levels) and the ties between siblings
//!   on the path (`no tie`; a tie where the nearer, left, child is taken; one where the farther,
//!   right, child is taken: on resuming the pair or passing it in `11`);
//! - the op unit: its `opcode`, the compare outcome of `a` and `b` under `lt` / `le`, and the
//!   operand classes of `a` and `b` crossed per opcode;
//! - every compare of the stage table (rti `u_ok`, `v_ok`, `t_ok`, `uv_ok`, `tmin_ok`, `tmax_ok`; slab `hit` and the
//!   compare-select chain `tn_*`, `tf_*`): the outcome of its operands as the datapath reads
//!   them (FTZ: a subnormal as zero) — `<`, `=`, `>`, `unordered` (a NaN operand);
//! - every rounded operation of the stage table (add, sub, mul, div rows) in an IEEE-like
//!   format: its rounding event — `exact`, `inexact` (rounded, not a tie), `tie` (the exact
//!   result halfway between two neighbours), `overflow` (±inf from finite operands),
//!   `underflow` (tiny and inexact), `flushed` (FTZ: a nonzero tiny result written as zero),
//!   `NaN` (a NaN result: a NaN operand, an invalid operation or the conservative guard).
//!   Exact values: sums by TwoSum in binary64, products exactly in binary64 (significands of
//!   at most 26 bits), quotients by comparing `r × b` with `a` exactly.
//!
//! - every operation of the stage table in fixed point (and the op unit's result): the event
//!   of its exact result — `exact`, `inexact` (rounded), `saturated` or `wrapped` (beyond the
//!   range, by the format), `divide by zero` (exact integer arithmetic in i128);
//!
//! Unreachable bins, with the reason, left out of the totals: in a format with the canonical
//! NaN rule, `other NaN` of every output and stage signal; under flush-to-zero, the subnormal
//! bins of every output and stage signal. (Inputs can hold anything.)
//!
//! A field the manifest marks `care_when F` is counted only in rows whose expected `F` is 1 (the
//! rows where its value is defined).

use crate::manifest::{Field, Kind, Manifest};
use serde::Serialize;

/// One bin and its count.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Bin {
    /// Bin name.
    pub name: String,
    /// Hits.
    pub count: u64,
    /// Why no vector can reach it (it is then left out of the totals), if it cannot.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub unreachable: Option<&'static str>,
}

/// Why a canonical-NaN format's signals never hold another NaN.
pub const WHY_CANONICAL: &str =
    "the contract's NaN rule: every NaN result and every NaN input read is the canonical NaN (contract.nan)";
/// Why a flush-to-zero format's signals never hold a subnormal.
pub const WHY_FTZ: &str =
    "flush-to-zero: every subnormal result and every subnormal input read is a zero of its sign (contract.subnormals)";

/// One coverpoint: a field of a set file and its bins.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Coverpoint {
    /// Field (signal) name.
    pub signal: String,
    /// The file it belongs to (`inputs`, `expected outputs`, `stage signals`).
    pub role: String,
    /// Pipeline stage (outputs and stage signals).
    pub stage: Option<u8>,
    /// What the bins are: `value class`, `flag`, `class`.
    pub kind: String,
    /// Bins in their fixed order.
    pub bins: Vec<Bin>,
}

/// The coverage of one or more sets of one unit, format and options.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Coverage {
    /// Unit.
    pub unit: String,
    /// Format.
    pub format: String,
    /// The options of the manifest that defines the model (a slab variant, the RTI's cull and
    /// threshold, …): coverage merges only with coverage of the same unit, format and options.
    #[serde(skip)]
    pub options: std::collections::BTreeMap<String, String>,
    /// Vectors counted.
    pub vectors: u64,
    /// Coverpoints in file and field order.
    pub coverpoints: Vec<Coverpoint>,
}

/// The bins of a float field (see the module documentation).
pub const FLOAT_BINS: [&str; 14] = [
    "+0",
    "-0",
    "+subnormal",
    "-subnormal",
    "+min normal",
    "-min normal",
    "+normal",
    "-normal",
    "+max finite",
    "-max finite",
    "+inf",
    "-inf",
    "canonical NaN",
    "other NaN",
];

/// The bins of a fixed-point field.
pub const FIXED_BINS: [&str; 7] = ["0", "+1 step", "-1 step", "+max", "min", "positive", "negative"];

/// The float bin of encoding `v` with `exp` exponent and `man` fraction bits.
pub fn float_bin(v: u64, exp: u32, man: u32) -> usize {
    let neg = (v >> (exp + man)) & 1 == 1;
    let e = (v >> man) & ((1 << exp) - 1);
    let m = v & ((1 << man) - 1);
    let top = (1 << exp) - 1;
    let s = usize::from(neg);
    if e == top {
        if m == 0 {
            return 10 + s;
        }
        return if m == 1 << (man - 1) { 12 } else { 13 };
    }
    if e == 0 {
        return if m == 0 { s } else { 2 + s };
    }
    if e == 1 && m == 0 {
        return 4 + s;
    }
    if e == top - 1 && m == (1 << man) - 1 {
        return 8 + s;
    }
    6 + s
}

/// The fixed-point bin of a `width`-bit two's-complement encoding `v`.
pub fn fixed_bin(v: u64, width: u32) -> usize {
    let mask = if width == 64 { u64::MAX } else { (1 << width) - 1 };
    let v = v & mask;
    let max = mask >> 1;
    let min = max + 1;
    match v {
        0 => 0,
        1 => 1,
        x if x == mask => 2,
        x if x == max => 3,
        x if x == min => 4,
        x if x < min => 5,
        _ => 6,
    }
}

impl Coverage {
    /// The empty coverage model of a set with manifest `m`.
    pub fn model(m: &Manifest) -> Self {
        let mut coverpoints = Vec::new();
        for (i, f) in m.files.iter().enumerate() {
            if !per_vector(m, i) {
                continue;
            }
            for x in &f.fields {
                let (kind, bins): (&str, Vec<String>) = match &x.kind {
                    Kind::Ieee { .. } => ("value class", FLOAT_BINS.iter().map(|s| s.to_string()).collect()),
                    Kind::Fixed { .. } => ("value class", FIXED_BINS.iter().map(|s| s.to_string()).collect()),
                    Kind::Flag => ("flag", vec!["0".into(), "1".into()]),
                    Kind::Uint if x.name == "class" => ("class", m.classes.iter().map(|c| c.name.clone()).collect()),
                    Kind::Uint => match traverse_bins(m, &x.name) {
                        Some((kind, bins)) => (kind, bins.iter().map(|b| b.to_string()).collect()),
                        None => continue,
                    },
                };
                // (capture holds and moves its inputs' bits: no rule of computed values applies)
                let out = x.dir == "out" && matches!(x.kind, Kind::Ieee { .. }) && m.unit != "capture";
                let canonical = !m.format.contains("propagate");
                let ftz = m.format.contains("ftz");
                let why = |name: &str| -> Option<&'static str> {
                    match name {
                        "other NaN" if out && canonical => Some(WHY_CANONICAL),
                        "+subnormal" | "-subnormal" if out && ftz => Some(WHY_FTZ),
                        _ if x.dir == "out" && m.unit != "capture" => unit_value_reason(m, x, name),
                        _ => None,
                    }
                };
                let empty_class = |k: usize| kind == "class" && m.classes.get(k).is_some_and(|c| c.count == 0);
                coverpoints.push(Coverpoint {
                    signal: x.name.clone(),
                    role: role_name(&f.role).into(),
                    stage: x.stage,
                    kind: kind.into(),
                    bins: bins
                        .into_iter()
                        .enumerate()
                        .map(|(k, name)| Bin {
                            unreachable: if empty_class(k) { Some(WHY_NO_CLASS_ROWS) } else { why(&name) },
                            name,
                            count: 0,
                        })
                        .collect(),
                });
            }
        }
        for (stage, name, a, b) in compares(m) {
            let fixed =
                !matches!(field(m, if a == "zero" { b } else { a }).map(|x| &x.1.kind), Some(Kind::Ieee { .. }));
            coverpoints.push(Coverpoint {
                signal: format!("{name} ({a} vs {b})"),
                role: "stage signals".into(),
                stage: Some(stage),
                kind: "compare".into(),
                bins: compare_bins(fixed),
            });
        }
        let ftz = m.format.contains("ftz");
        let mut rows: Vec<(u8, String)> =
            arith_rows(m).into_iter().map(|(stage, name, op, _, _)| (stage, format!("{name} ({op})"))).collect();
        if op_unit_rounding(m) {
            rows.push((1, "result (add, sub, mul or div by opcode)".into()));
        }
        for (stage, signal) in rows {
            coverpoints.push(Coverpoint {
                signal: signal.clone(),
                role: "stage signals".into(),
                stage: Some(stage),
                kind: "rounding".into(),
                bins: ROUNDING_BINS
                    .iter()
                    .map(|&n| Bin {
                        name: n.into(),
                        count: 0,
                        unreachable: match n {
                            "flushed" if !ftz => Some(WHY_NO_FTZ),
                            "underflow" if ftz => Some(WHY_FTZ_UNDERFLOW),
                            _ => unit_rounding_reason(m, &signal, n),
                        },
                    })
                    .collect(),
            });
        }
        let mut fixed_rows: Vec<(u8, String, &str)> = fixed_arith_rows(m)
            .into_iter()
            .map(|(stage, name, op, _, _)| (stage, format!("{name} ({op})"), op))
            .collect();
        if op_unit_fixed(m) {
            fixed_rows.push((1, "result (add, sub, mul or div by opcode)".into(), "any"));
        }
        let saturating = !m.format.contains("wrap");
        for (stage, signal, op) in fixed_rows {
            coverpoints.push(Coverpoint {
                signal: signal.clone(),
                role: "stage signals".into(),
                stage: Some(stage),
                kind: "fixed-point event".into(),
                bins: FIXED_EVENT_BINS
                    .iter()
                    .map(|&n| Bin {
                        name: n.into(),
                        count: 0,
                        unreachable: match n {
                            "saturated" if !saturating => Some(WHY_WRAPS),
                            "wrapped" if saturating => Some(WHY_SATURATES),
                            "inexact" if matches!(op, "add" | "sub") => Some(WHY_FIXED_SUM_EXACT),
                            "divide by zero" if op != "div" && op != "any" => Some(WHY_NOT_DIV),
                            _ => fixed_event_reason(m, &signal, n),
                        },
                    })
                    .collect(),
            });
        }
        for (stage, name, op, _, _) in cancel_rows(m) {
            let man = m.params.get("man").copied().unwrap_or(0);
            coverpoints.push(Coverpoint {
                signal: format!("{name} ({op})"),
                role: "stage signals".into(),
                stage: Some(stage),
                kind: "cancellation".into(),
                bins: cancellation_bins(man)
                    .into_iter()
                    .map(|n| Bin { name: n, count: 0, unreachable: None })
                    .collect(),
            });
        }
        for (stage, name, op, a, b) in crossed_rows(m) {
            coverpoints.push(Coverpoint {
                signal: format!("{name} ({op}): {a} x {b}"),
                role: "stage signals".into(),
                stage: Some(stage),
                kind: "operand cross".into(),
                bins: cross_bins(|n| cross_reason(m, (name, a, b), n)),
            });
        }
        for e in events(m) {
            coverpoints.push(Coverpoint {
                signal: e.signal(),
                role: "events".into(),
                stage: None,
                kind: "event".into(),
                bins: e
                    .bins()
                    .iter()
                    .map(|&n| Bin { name: n.into(), count: 0, unreachable: e.unreachable(m, n) })
                    .collect(),
            });
        }
        if op_unit_extras(m) {
            // the op unit: its operands' compare outcome under lt / le, and (IEEE-like) the
            // operand classes crossed with each opcode
            let fixed = !matches!(field(m, "a").map(|x| &x.1.kind), Some(Kind::Ieee { .. }));
            coverpoints.push(Coverpoint {
                signal: "cmp (a vs b, opcodes lt and le)".into(),
                role: "stage signals".into(),
                stage: Some(1),
                kind: "compare".into(),
                bins: compare_bins(fixed),
            });
            if !fixed {
                for op in crate::gen::OPCODES {
                    coverpoints.push(Coverpoint {
                        signal: format!("{op}: a x b"),
                        role: "stage signals".into(),
                        stage: Some(1),
                        kind: "operand cross".into(),
                        bins: cross_bins(|n| (m.format.contains("ftz") && n.contains("subnormal")).then_some(WHY_FTZ)),
                    });
                }
            }
        }
        Coverage { unit: m.unit.clone(), format: m.format.clone(), options: m.options.clone(), vectors: 0, coverpoints }
    }

    /// Whether `other` is coverage of the same unit, format and options (the two merge).
    pub fn same_model(&self, other: &Coverage) -> bool {
        self.unit == other.unit && self.format == other.format && self.options == other.options
    }

    /// A name for the model among others of a run: unit, format and (when it has one) the slab
    /// variant, e.g. `slab fp16 conservative`.
    pub fn title(&self) -> String {
        match self.options.get("variant") {
            Some(v) => format!("{} {} {v}", self.unit, self.format),
            None => format!("{} {}", self.unit, self.format),
        }
    }

    /// The coverage of a set's rows (`contents`: every file's rows, unpacked, as
    /// [`crate::read::read_files`] gives them).
    pub fn measure(m: &Manifest, contents: &[Vec<Vec<u64>>]) -> Result<Self, String> {
        let mut c = Self::model(m);
        let rows = contents.first().map_or(0, |r| r.len());
        c.add_rows(m, contents, 0..rows)?;
        Ok(c)
    }

    /// The coverage of the set in directory `dir` (manifest `m`), read row by row: its
    /// per-vector files in lockstep, one row in memory at a time, every file's SHA-256 and row
    /// count checked against the manifest (a mismatch is an error, after the rows are read).
    pub fn measure_dir(dir: &std::path::Path, m: &Manifest) -> Result<Self, String> {
        use sha2::{Digest, Sha256};
        use std::io::BufRead;
        let mut c = Self::model(m);
        let mut bins = RowBins::new(m);
        if m.unit == "traverse" {
            // the tree images (small, read whole; their hashes are checked with the rest below)
            let mut images = Vec::new();
            for (i, fm) in m.files.iter().enumerate() {
                images.push(if per_vector(m, i) {
                    Vec::new()
                } else {
                    let t = std::fs::read_to_string(dir.join(&fm.name)).map_err(|e| format!("{}: {e}", fm.name))?;
                    crate::read::parse_rows(fm, &t)?
                });
            }
            bins = bins.with_set(&images)?;
        }
        let mut readers = Vec::new();
        for (i, fm) in m.files.iter().enumerate() {
            let file = std::fs::File::open(dir.join(&fm.name)).map_err(|e| format!("{}: {e}", fm.name))?;
            let widths: Vec<u32> = fm.fields.iter().map(|x| x.width).collect();
            readers.push((
                std::io::BufReader::with_capacity(1 << 16, file),
                Sha256::new(),
                widths,
                per_vector(m, i),
                0usize,
            ));
        }
        let mut contents: Vec<Vec<Vec<u64>>> = m.files.iter().map(|_| vec![Vec::new()]).collect();
        let mut line = String::new();
        let mut hits = Vec::new();
        let rows = m.files.first().map_or(0, |f| f.rows);
        for _ in 0..rows {
            for (i, (r, sha, widths, pv, n)) in readers.iter_mut().enumerate() {
                if !*pv {
                    continue;
                }
                let fm = &m.files[i];
                line.clear();
                if r.read_line(&mut line).map_err(|e| format!("{}: {e}", fm.name))? == 0 {
                    return Err(format!("{}: {} rows, manifest says {}", fm.name, n, fm.rows));
                }
                sha.update(line.as_bytes());
                *n += 1;
                let l = line.trim_end_matches('\n');
                if l.len() != fm.digits as usize {
                    return Err(format!(
                        "{} line {n}: {} hex digits, the manifest says {}",
                        fm.name,
                        l.len(),
                        fm.digits
                    ));
                }
                contents[i][0] = crate::pack::unpack(l, widths).map_err(|e| format!("{} line {n}: {e}", fm.name))?;
            }
            hits.clear();
            bins.hits(&contents, 0, &mut hits)?;
            for &(p, b) in &hits {
                if let Some(b) = c.coverpoints.get_mut(p).and_then(|p| p.bins.get_mut(b)) {
                    b.count += 1;
                }
            }
            c.vectors += 1;
        }
        for (i, (mut r, mut sha, _, pv, n)) in readers.into_iter().enumerate() {
            let fm = &m.files[i];
            // the rest of the file (all of it for a file without a row per vector)
            let mut rest = Vec::new();
            std::io::Read::read_to_end(&mut r, &mut rest).map_err(|e| format!("{}: {e}", fm.name))?;
            if pv && !rest.is_empty() {
                return Err(format!("{}: more rows than the manifest's {} ({n} read)", fm.name, fm.rows));
            }
            sha.update(&rest);
            let hex: String = sha.finalize().iter().map(|b| format!("{b:02x}")).collect();
            if hex != fm.sha256 {
                return Err(format!("{}: sha256 differs from the manifest", fm.name));
            }
        }
        Ok(c)
    }

    /// Counts the rows `range` of a set into the bins.
    pub fn add_rows(
        &mut self,
        m: &Manifest,
        contents: &[Vec<Vec<u64>>],
        range: std::ops::Range<usize>,
    ) -> Result<(), String> {
        let bins = RowBins::new(m).with_set(contents)?;
        let mut hits = Vec::new();
        for row in range {
            hits.clear();
            bins.hits(contents, row, &mut hits)?;
            for &(cp, bin) in &hits {
                if let Some(b) = self.coverpoints.get_mut(cp).and_then(|p| p.bins.get_mut(bin)) {
                    b.count += 1;
                }
            }
            self.vectors += 1;
        }
        Ok(())
    }

    /// Adds `other`'s counts (the same unit, format, options and coverage model). The class
    /// coverpoint merges by bin name: a class of either side is a bin of the sum (a closed set
    /// adds `close`, a `verify` run `scene`), unreachable only when it is unreachable on both.
    pub fn merge(&mut self, other: &Coverage) -> Result<(), String> {
        if other.unit != self.unit || other.format != self.format {
            return Err(format!(
                "cannot merge coverage of {} {} into {} {}",
                other.unit, other.format, self.unit, self.format
            ));
        }
        if other.options != self.options {
            let differ: Vec<&str> = self
                .options
                .keys()
                .chain(other.options.keys())
                .filter(|k| self.options.get(*k) != other.options.get(*k))
                .map(|k| k.as_str())
                .collect::<std::collections::BTreeSet<_>>()
                .into_iter()
                .collect();
            return Err(format!("cannot merge coverage of different options ({} differ)", differ.join(", ")));
        }
        let shape = |c: &Coverage| -> Vec<(String, String, Vec<String>)> {
            c.coverpoints
                .iter()
                .map(|p| {
                    let bins =
                        if p.kind == "class" { Vec::new() } else { p.bins.iter().map(|b| b.name.clone()).collect() };
                    (p.role.clone(), p.signal.clone(), bins)
                })
                .collect()
        };
        if shape(self) != shape(other) {
            return Err("cannot merge: the sets have different coverage models (options or classes differ)".into());
        }
        for (p, q) in self.coverpoints.iter_mut().zip(&other.coverpoints) {
            if p.kind == "class" {
                for c in &q.bins {
                    match p.bins.iter_mut().find(|b| b.name == c.name) {
                        Some(b) => {
                            b.count += c.count;
                            if c.unreachable.is_none() {
                                b.unreachable = None;
                            }
                        }
                        None => p.bins.push(c.clone()),
                    }
                }
                continue;
            }
            for (b, c) in p.bins.iter_mut().zip(&q.bins) {
                b.count += c.count;
            }
        }
        self.vectors += other.vectors;
        Ok(())
    }

    /// (reachable bins hit, reachable bins).
    pub fn totals(&self) -> (u64, u64) {
        let bins = self.coverpoints.iter().flat_map(|p| &p.bins).filter(|b| b.unreachable.is_none());
        (bins.clone().filter(|b| b.count > 0).count() as u64, bins.count() as u64)
    }

    /// Bins marked unreachable that a vector hit: a contradiction (empty when the model is right).
    pub fn contradictions(&self) -> Vec<String> {
        self.coverpoints
            .iter()
            .flat_map(|p| {
                p.bins
                    .iter()
                    .filter(|b| b.unreachable.is_some() && b.count > 0)
                    .map(move |b| format!("{} {}: {}", p.role, p.signal, b.name))
            })
            .collect()
    }
}

/// The bins one row hits, as (coverpoint, bin) indices into [`Coverage::model`]'s order: what
/// counting and the coverage closure's search share (the compares and operations of the set's
/// unit found once). It holds what it needs of the manifest, so a long-lived owner (a live
/// recorder) keeps one.
pub struct RowBins {
    ix: Ix,
    ftz: bool,
    cmps: Vec<(u8, &'static str, &'static str, &'static str)>,
    ariths: Vec<(u8, &'static str, &'static str, &'static str, &'static str)>,
    op_rounding: bool,
    fixed_ops: Vec<(u8, &'static str, &'static str, &'static str, &'static str)>,
    op_fixed: bool,
    cancels: Vec<(u8, &'static str, &'static str, &'static str, &'static str)>,
    crossed: Vec<(u8, &'static str, &'static str, &'static str, &'static str)>,
    min_normal: f64,
    events: Vec<Event>,
    op_extras: bool,
    op_crosses: bool,
    /// The traverse unit: the set's tree, to re-run each ray for its path events.
    path: Option<crate::traverse::PathReplay>,
}

impl RowBins {
    /// The lookup for sets with manifest `m`.
    pub fn new(m: &Manifest) -> Self {
        RowBins {
            ix: Ix::new(m),
            ftz: m.format.contains("ftz"),
            cmps: compares(m),
            ariths: arith_rows(m),
            op_rounding: op_unit_rounding(m),
            fixed_ops: fixed_arith_rows(m),
            op_fixed: op_unit_fixed(m),
            cancels: cancel_rows(m),
            crossed: crossed_rows(m),
            min_normal: min_normal(m),
            events: events(m),
            op_extras: op_unit_extras(m),
            op_crosses: op_unit_extras(m) && matches!(field(m, "a").map(|x| &x.1.kind), Some(Kind::Ieee { .. })),
            path: None,
        }
    }

    /// The lookup with what a unit's rows alone do not give, taken from the set's `contents`
    /// (its files in manifest order): for the traverse unit, the tree from its BRAM images (the
    /// per-vector files may be empty), whose re-run of each ray gives the back-traversal
    /// distances and ties. Other units: unchanged.
    pub fn with_set(mut self, contents: &[Vec<Vec<u64>>]) -> Result<Self, String> {
        if self.ix.m.unit == "traverse" {
            self.path = Some(crate::traverse::PathReplay::from_set(&self.ix.m, contents)?);
        }
        Ok(self)
    }

    /// Appends to `out` the (coverpoint, bin) of every bin row `row` of `contents` hits.
    pub fn hits(&self, contents: &[Vec<Vec<u64>>], row: usize, out: &mut Vec<(usize, usize)>) -> Result<(), String> {
        let (m, ftz) = (&self.ix.m, self.ftz);
        // the expected-output row's flag named by a care_when
        let ix = &self.ix;
        let out_flag = |name: &str| -> Option<bool> {
            let k = *ix.outs.get(name)?;
            Some(contents.get(1)?.get(row)?.get(k)? & 1 == 1)
        };
        let mut cp = 0;
        for (i, f) in m.files.iter().enumerate() {
            if !per_vector(m, i) {
                continue;
            }
            let vals = contents.get(i).and_then(|c| c.get(row)).ok_or(format!("{}: no row {}", f.name, row + 1))?;
            for (k, x) in f.fields.iter().enumerate() {
                let Some(bin) = bin_of(x, vals[k], m) else { continue };
                let here = cp;
                cp += 1;
                if let Some(flag) = &x.care_when {
                    if out_flag(flag) == Some(false) {
                        continue;
                    }
                }
                out.push((here, bin));
            }
        }
        // `zero`: the constant 0 of the RTI's sign tests
        let cmp_operand = |n: &str| if n == "zero" { Some(Some(0.0)) } else { operand(ix, contents, row, n, ftz) };
        for &(_, _, a, b) in &self.cmps {
            if let (Some(x), Some(y)) = (cmp_operand(a), cmp_operand(b)) {
                out.push((cp, compare_bin(x, y)));
            }
            cp += 1;
        }
        for &(_, name, op, a, b) in &self.ariths {
            if let Some(bin) = rounding_event(ix, contents, row, name, op, a, b, ftz) {
                out.push((cp, bin));
            }
            cp += 1;
        }
        if self.op_rounding {
            // the op unit: the operation the row's opcode selects (0 add, 1 sub, 2 mul,
            // 3 div in divide mode; the reciprocal mode's a * (1/b) rounds twice: not counted)
            if let Some(bin) = op_unit_op(ix, contents, row)
                .and_then(|op| rounding_event(ix, contents, row, "result", op, "a", "b", ftz))
            {
                out.push((cp, bin));
            }
            cp += 1;
        }
        for &(_, name, op, a, b) in &self.fixed_ops {
            if let Some(bin) = fixed_event(ix, contents, row, name, op, a, b) {
                out.push((cp, bin));
            }
            cp += 1;
        }
        if self.op_fixed {
            if let Some(bin) =
                op_unit_op(ix, contents, row).and_then(|op| fixed_event(ix, contents, row, "result", op, "a", "b"))
            {
                out.push((cp, bin));
            }
            cp += 1;
        }
        for &(_, name, op, a, b) in &self.cancels {
            if let Some(bin) = cancellation(ix, contents, row, name, op, a, b, ftz) {
                out.push((cp, bin));
            }
            cp += 1;
        }
        for &(_, name, _, a, b) in &self.crossed {
            // a result gated by a care flag (RTI after `valid`): counted only where it is defined
            let cared =
                ix.field(name).and_then(|(_, x, _)| x.care_when.as_deref()).is_none_or(|c| out_flag(c) != Some(false));
            if let (true, Some(x), Some(y)) =
                (cared, operand(ix, contents, row, a, ftz), operand(ix, contents, row, b, ftz))
            {
                out.push((cp, cross_class(x, self.min_normal) * CROSS_CLASSES.len() + cross_class(y, self.min_normal)));
            }
            cp += 1;
        }
        let path = match (&self.path, self.events.contains(&Event::TraverseBack)) {
            (Some(p), _) => {
                let ray = contents.first().and_then(|c| c.get(row)).ok_or(format!("no input row {}", row + 1))?;
                Some(p.events(ray))
            }
            (None, true) => {
                return Err("the traverse unit's path coverage re-runs each ray on the set's tree: the lookup needs the set's tree images (RowBins::with_set)".into())
            }
            (None, false) => None,
        };
        for e in &self.events {
            if let (Some(p), Event::TraverseBack) = (&path, e) {
                // each restart's distance, once per ray per bin
                let mut seen = [false; BACK_BINS.len()];
                for &d in &p.back_distances {
                    seen[(d as usize).min(BACK_BINS.len() - 1)] = true;
                }
                out.extend(seen.iter().enumerate().filter(|x| *x.1).map(|(b, _)| (cp, b)));
                cp += 1;
                continue;
            }
            if let (Some(p), Event::TraverseTie) = (&path, e) {
                if p.ties == [0, 0] {
                    out.push((cp, 0));
                }
                out.extend((0..2).filter(|&k| p.ties[k] > 0).map(|k| (cp, k + 1)));
                cp += 1;
                continue;
            }
            let v = |n: &str| operand(ix, contents, row, n, ftz);
            let flag = |n: &str| {
                ix.field(n).and_then(|(i, _, k)| contents.get(i)?.get(row)?.get(k).copied()).map(|b| b & 1 == 1)
            };
            for bin in e.measure(m, &v, &flag) {
                out.push((cp, bin));
            }
            cp += 1;
        }
        if self.op_extras {
            let opcode = ix.field("opcode").and_then(|(i, _, k)| contents.get(i)?.get(row)?.get(k).copied());
            let (x, y) = (operand(ix, contents, row, "a", ftz), operand(ix, contents, row, "b", ftz));
            if let (Some(4 | 5), Some(x), Some(y)) = (opcode, x, y) {
                out.push((cp, compare_bin(x, y)));
            }
            cp += 1;
            if self.op_crosses {
                if let (Some(op), Some(x), Some(y)) = (opcode, x, y) {
                    if (op as usize) < crate::gen::OPCODES.len() {
                        let bin =
                            cross_class(x, self.min_normal) * CROSS_CLASSES.len() + cross_class(y, self.min_normal);
                        out.push((cp + op as usize, bin));
                    }
                }
            }
        }
        Ok(())
    }
}

/// The bins of a compare coverpoint (`unordered` unreachable in fixed point).
fn compare_bins(fixed: bool) -> Vec<Bin> {
    COMPARE_BINS
        .iter()
        .map(|&n| Bin {
            name: n.into(),
            count: 0,
            unreachable: (n == "unordered" && fixed).then_some(WHY_FIXED_ORDERED),
        })
        .collect()
}

/// The bins of an operand cross (`a class x b class`), each unreachable where `why` says.
fn cross_bins(why: impl Fn(&str) -> Option<&'static str>) -> Vec<Bin> {
    CROSS_CLASSES
        .iter()
        .flat_map(|x| CROSS_CLASSES.iter().map(move |y| format!("{x} x {y}")))
        .map(|n| Bin { unreachable: why(&n), name: n, count: 0 })
        .collect()
}

/// The op unit's operation that row `row`'s opcode selects, as one rounding: 0 add, 1 sub, 2
/// mul, 3 div in divide mode (the reciprocal mode's a × (1/b) rounds twice: none).
fn op_unit_op(ix: &Ix, contents: &[Vec<Vec<u64>>], row: usize) -> Option<&'static str> {
    let opcode = ix.field("opcode").and_then(|(i, _, k)| contents.get(i)?.get(row)?.get(k).copied());
    match opcode {
        Some(0) => Some("add"),
        Some(1) => Some("sub"),
        Some(2) => Some("mul"),
        Some(3) if ix.m.format.contains("divide") => Some("div"),
        _ => None,
    }
}

/// The compare bin (<, =, >, unordered) of two operands as the datapath reads them.
fn compare_bin(x: Option<f64>, y: Option<f64>) -> usize {
    match (x, y) {
        (None, _) | (_, None) => 3,
        (Some(x), Some(y)) if x < y => 0,
        (Some(x), Some(y)) if x == y => 1,
        _ => 2,
    }
}

/// Whether the set is an op set with operands `a`, `b` and an `opcode` (its compare outcome and
/// operand crosses are counted).
fn op_unit_extras(m: &Manifest) -> bool {
    m.unit == "op" && field(m, "opcode").is_some() && field(m, "a").is_some() && field(m, "b").is_some()
}

/// XML text escaping for attribute values.
fn xml(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// A UTC date and time (`YYYY-MM-DDThh:mm:ss`) from seconds since 1970.
pub fn utc(secs: u64) -> String {
    let (days, rem) = (secs / 86_400, secs % 86_400);
    // civil from days (H. Hinnant's algorithm)
    let z = days as i64 + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!("{y:04}-{m:02}-{d:02}T{:02}:{:02}:{:02}", rem / 3600, rem / 60 % 60, rem % 60)
}

impl Coverage {
    /// The coverage as UCIS 1.0 XML (the Accellera interchange format that pyucis and the
    /// simulators' coverage tools read): one instance `raypipe_<unit>`, one covergroup per file
    /// role (`inputs`, `expected_outputs`, `stage_signals`, `events`), one coverpoint per
    /// signal, one bin per bin (`type="ignore"`: unreachable). `written` is the writing time
    /// (UTC), `command` the command that measured it (the history node's `cmd`).
    pub fn ucis_xml(&self, written: &str, command: &str) -> String {
        ucis_xml_all(std::slice::from_ref(self), written, command)
    }
}

/// Several models' coverage (a `verify` or `stress` run's: one per unit, format and variant) as
/// one UCIS 1.0 document: one instance per model, named `raypipe_<unit>_<format>[_<variant>]`
/// with `.`, `:` and `+` of the format as `_` (one model: `raypipe_<unit>`, as
/// [`Coverage::ucis_xml`]), each as that method describes.
pub fn ucis_xml_all(covs: &[Coverage], written: &str, command: &str) -> String {
    let mut s = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    s += &format!(
        "<UCIS xmlns:ucis=\"http://www.w3.org/2001/XMLSchema-instance\" writtenBy=\"raypipe {}\" writtenTime=\"{written}\" ucisVersion=\"1.0\">\n",
        env!("CARGO_PKG_VERSION")
    );
    s += "  <sourceFiles fileName=\"manifest.json\" id=\"1\"/>\n";
    s += &format!(
        "  <historyNodes historyNodeId=\"0\" logicalName=\"raypipe cover\" physicalName=\"raypipe-cover.xml\" kind=\"1\" testStatus=\"true\" simtime=\"0.0\" timeunit=\"ns\" runCwd=\".\" cpuTime=\"0.0\" seed=\"0\" cmd=\"{}\" args=\"\" compulsory=\"0\" date=\"{written}\" userName=\"raypipe\" cost=\"0.0\" toolCategory=\"UCIS:simulator\" ucisVersion=\"1.0\" vendorId=\"raypipe\" vendorTool=\"raypipe\" vendorToolVersion=\"{}\"/>\n",
        xml(command),
        env!("CARGO_PKG_VERSION")
    );
    let ident = |x: &str| x.replace([':', '+', '.', ' ', '-'], "_");
    for (key, c) in covs.iter().enumerate() {
        let unit = xml(&c.unit);
        let fmt = xml(&ident(&c.format));
        let name = if covs.len() == 1 {
            format!("raypipe_{unit}")
        } else {
            match c.options.get("variant") {
                Some(v) => format!("raypipe_{unit}_{fmt}_{}", xml(&ident(v))),
                None => format!("raypipe_{unit}_{fmt}"),
            }
        };
        s += &format!(
            "  <instanceCoverages name=\"{name}\" key=\"{key}\" instanceId=\"{key}\" moduleName=\"raypipe_{unit}_{fmt}\">\n    <id file=\"1\" line=\"1\" inlineCount=\"1\"/>\n    <covergroupCoverage>\n"
        );
        let mut roles: Vec<&str> = Vec::new();
        for p in &c.coverpoints {
            if !roles.contains(&p.role.as_str()) {
                roles.push(&p.role);
            }
        }
        for role in roles {
            let cg = role.replace(' ', "_");
            s += &format!(
                "      <cgInstance name=\"{cg}\" key=\"0\">\n        <options weight=\"1\" goal=\"100\" at_least=\"1\" per_instance=\"true\" merge_instances=\"true\"/>\n        <cgId cgName=\"{cg}\" moduleName=\"raypipe_{unit}\">\n          <cginstSourceId file=\"1\" line=\"1\" inlineCount=\"1\"/>\n          <cgSourceId file=\"1\" line=\"1\" inlineCount=\"1\"/>\n        </cgId>\n"
            );
            for p in c.coverpoints.iter().filter(|p| p.role == role) {
                s += &format!(
                    "        <coverpoint name=\"{}\" key=\"0\">\n          <options weight=\"1\" goal=\"100\" at_least=\"1\" auto_bin_max=\"64\" detect_overlap=\"false\"/>\n",
                    xml(&p.signal)
                );
                for b in &p.bins {
                    s += &format!(
                        "          <coverpointBin name=\"{}\" type=\"{}\" key=\"0\">\n            <range from=\"-1\" to=\"-1\">\n              <contents coverageCount=\"{}\"/>\n            </range>\n          </coverpointBin>\n",
                        xml(&b.name),
                        if b.unreachable.is_some() { "ignore" } else { "bins" },
                        b.count
                    );
                }
                s += "        </coverpoint>\n";
            }
            s += "      </cgInstance>\n";
        }
        s += "    </covergroupCoverage>\n  </instanceCoverages>\n";
    }
    s += "</UCIS>\n";
    s
}

/// The traverse unit's counters and history registers: (kind, bins), for its fields `count`
/// (leaves returned), `passes` and `hist_<level>` (the final 2-bit history of each level); and
/// the op unit's `opcode` (one bin per operation).
fn traverse_bins(m: &Manifest, name: &str) -> Option<(&'static str, &'static [&'static str])> {
    if m.unit == "op" && name == "opcode" {
        return Some(("opcode", &crate::gen::OPCODES));
    }
    if m.unit != "traverse" {
        return None;
    }
    match name {
        "count" => Some(("leaves returned", &["0", "1 to N-1", "N (the N-limit reached)"])),
        "passes" => Some(("passes", &["0 (root missed)", "1", "2", "3 or more"])),
        n if n.starts_with("hist_") => Some(("history state", &["00 new", "01 pass", "10 split", "11 done"])),
        _ => None,
    }
}

/// The bins of a rounded operation.
pub const ROUNDING_BINS: [&str; 7] = ["exact", "inexact", "tie", "overflow", "underflow", "flushed", "NaN"];
/// Why a format without flush-to-zero never flushes.
pub const WHY_NO_FTZ: &str = "the format keeps subnormals: no result is flushed";
/// Why a flush-to-zero format never underflows.
pub const WHY_FTZ_UNDERFLOW: &str = "flush-to-zero: every tiny result is flushed (counted as flushed)";

/// Why a sum or difference is never tiny and inexact (IEEE formats with subnormals).
pub const WHY_SUM_TINY_EXACT: &str = "a sum or difference of two values is a multiple of the smallest subnormal, so one below the smallest normal in magnitude is a subnormal exactly: with gradual underflow an add or subtract never underflows inexactly";
/// Why the RTI unit's t, u and v are never negative where they are compared.
pub const WHY_RTI_SIGN: &str = "compared only when valid: then |det| > det_threshold >= 0 (det a number, not zero) and u', v', t' are NaN-free and zero or of det's sign (u_ok, v_ok, t_ok), and 1/det has det's sign: the product (or quotient) is +0, -0, positive, +inf or NaN, never a negative nonzero value";
/// Why the RTI unit's u and v never reach the largest finite value.
pub const WHY_RTI_UV_BOUNDED: &str = "compared only when valid: then (det > 0) 0 <= u', 0 <= v' and u' <= fl(u' + v') <= det (u_ok, v_ok, uv_ok; the mirror for det < 0), so u = u' x (1/det) is at most det x fl(1/det) rounded (at most 2) while 1/det is finite, and +inf or NaN when it overflows; in divide mode u = u'/det is at most 1 (v alike)";
/// Why the RTI unit's u and v never overflow.
pub const WHY_RTI_UV_NO_OVERFLOW: &str = "compared only when valid: |u'| <= |det| (uv_ok), so u' x (1/det) is at most 2 while 1/det is finite, and an infinite 1/det is an infinite operand (an exact result); u'/det is at most 1 (v alike)";
/// Why 1/x never rounds to the largest finite value.
pub const WHY_RECIP_NOT_MAX: &str = "1/x rounds to +-max only for |x| in (2^-(emax+1), 2^-(emax+1)/(1 - 2^-(M+2))], a relative width below 2^-(M+1); that range is subnormal, where values are 2^(2-M) apart relative to 2^-(emax+1), so it holds no value";
/// Why 1/x never rounds a tie.
pub const WHY_RECIP_NO_TIE: &str = "1/x is exact when x is a power of two, and otherwise (x = m 2^e, m odd > 1) has an infinite binary expansion, never halfway between two values";
/// Why the RTI unit's 1/det is a number where it is compared.
pub const WHY_RTI_DET_NUMBER: &str =
    "compared only when valid: then |det| > det_threshold, so det is not NaN and 1/det is not NaN";
/// Why the conservative guard removes tiny and overflowed reciprocals.
pub const WHY_GUARD_RECIP: &str = "the conservative guard: 1/d of a finite nonzero d whose result is subnormal, zero or infinite (overflowed) is the canonical NaN (counted as NaN)";
/// Why the conservative guard removes overflowed differences.
pub const WHY_GUARD_SUB: &str =
    "the conservative guard: a difference of finite operands that overflows is the canonical NaN (counted as NaN)";
/// Why Embree's direction preparation leaves no zero and no infinite reciprocal.
pub const WHY_EMBREE: &str = "embree preparation: |d| < delta becomes +-delta (delta = 2/max rounded up, > 0), so pd is never zero, and 1/pd is at most 1/delta <= max/2 in magnitude: never infinite from a finite pd, never an overflow";
/// Why Embree's preparation in fixed point leaves no tiny pd and no saturated reciprocal.
pub const WHY_EMBREE_FIXED: &str = "embree preparation: |d| < delta becomes +-delta (delta = 2/max rounded up, more than one step), so pd is never 0 or one step, and |1/pd| <= 1/delta <= max/2: never saturated";
/// Why a class bin stays empty.
pub const WHY_NO_CLASS_ROWS: &str =
    "the class has no vectors in this format (its manifest count is 0: a floats-only class in fixed point)";
/// The bins of the traverse unit's back-traversal distance (levels per restart).
pub const BACK_BINS: [&str; 4] = ["0", "1", "2", "3 or more"];
/// Why a back-traversal distance exceeds what the tree allows.
pub const WHY_BACK_DEPTH: &str = "a restart resumes at a level of the tree from a pass that ended at one: with L levels (params.levels) the distance is at most L - 1";
/// Why a fixed-point reciprocal is never 0 or one step.
pub const WHY_FIXED_RECIP: &str = "every value x of qI.F (I integer bits, F fraction bits) has |x| < 2^(I-1), so |1/x| > 2^(F-I+1) steps >= 2 steps when F >= I (and 1/0 and a too large 1/x saturate): no rounding gives 0 or one step";
/// Why the RTI unit's fixed-point t, u and v are never negative where they are compared.
pub const WHY_RTI_SIGN_FIXED: &str = "compared only when valid: then det is nonzero and u', v', t' are zero or of det's sign (u_ok, v_ok, t_ok), as is 1/det: the exact product (or quotient) is >= 0, and no rounding (floor, ceil, toward zero, nearest) of a value >= 0 is negative when the format saturates";
/// Why the RTI unit's fixed-point u and v never saturate high.
pub const WHY_RTI_UV_BOUNDED_FIXED: &str = "compared only when valid: then 0 <= u' <= fl(u' + v') <= det (det > 0; the mirror for det < 0), so u = u' x (1/det) is at most det x fl(1/det) plus a rounding, at most 2 + 2 steps below the largest value of a format with at least 3 integer bits (1/det saturated is below 1/det, det x (1/det) <= 1 + det x step); u'/det is at most 1 (v alike)";
/// Why a widened entry distance never takes some values.
pub const WHY_WIDEN_NEAR: &str = "t_near is tn_xyz stepped toward -inf (nextDown) at least once: nextDown never returns -0 or +inf, and from two steps on never +max (only nextDown(+inf) is +max)";
/// Why a widened exit distance never takes some values.
pub const WHY_WIDEN_FAR: &str = "t_far is tf_xyz stepped toward +inf (nextUp) at least once: nextUp never returns +0 or -inf, and from two steps on never -max (only nextUp(-inf) is -max)";

/// Why a reciprocal never overflows under flush-to-zero.
pub const WHY_FTZ_RECIP: &str = "flush-to-zero: every nonzero operand is normal, |x| >= 2^emin, so |1/x| <= 2^-emin = 2^(bias-1) < max: 1/x never overflows (+-inf only as 1/+-0, exactly); where RTI compares them det is nonzero (so normal), so 1/det is finite and u, v are at most about 2";

/// Whether the set's format is an IEEE-like float with flush-to-zero.
fn ftz_float(m: &Manifest) -> bool {
    m.params.get("float") == Some(&1) && m.params.get("ftz") == Some(&1)
}

/// Whether the set's format is an IEEE-like float with gradual underflow.
fn gradual(m: &Manifest) -> bool {
    m.params.get("float") == Some(&1) && m.params.get("ftz") != Some(&1)
}

/// A unit's reason why a value-class bin of output or stage field `x` is unreachable.
fn unit_value_reason(m: &Manifest, x: &Field, bin: &str) -> Option<&'static str> {
    if let Kind::Fixed { int, frac } = x.kind {
        return fixed_value_reason(m, x, bin, int, frac);
    }
    if !matches!(x.kind, Kind::Ieee { .. }) {
        return None;
    }
    let neg_nonzero = matches!(bin, "-subnormal" | "-min normal" | "-normal" | "-max finite" | "-inf");
    let divide = m.params.get("recip_mul") == Some(&0);
    let widen = m.params.get("slab_widen_ulps").copied().unwrap_or(0);
    let guard = m.params.get("slab_guard") == Some(&1);
    let embree = m.params.get("slab_embree") == Some(&1) && gradual(m);
    let valid = x.care_when.as_deref() == Some("valid");
    match (m.unit.as_str(), x.name.as_str()) {
        ("rti", "t" | "u" | "v") if valid && neg_nonzero => Some(WHY_RTI_SIGN),
        ("rti", "u" | "v") if valid && (bin == "+max finite" || (divide && bin == "+inf")) => Some(WHY_RTI_UV_BOUNDED),
        ("rti", "inv_det") if valid && matches!(bin, "+max finite" | "-max finite") => Some(WHY_RECIP_NOT_MAX),
        ("rti", "inv_det") if valid && bin.ends_with("NaN") => Some(WHY_RTI_DET_NUMBER),
        ("rti", "inv_det") if valid && ftz_float(m) && matches!(bin, "+inf" | "-inf") => Some(WHY_FTZ_RECIP),
        ("rti", "inv_det") if valid && culled(m) && (neg_nonzero || bin == "-0") => Some(WHY_CULL_POSITIVE),
        ("rti", "inv_det") if valid && threshold_bounds_recip(m) && matches!(bin, "+inf" | "-inf") => {
            Some(WHY_THRESHOLD_RECIP)
        }
        ("rti", "u" | "v") if valid && threshold_bounds_recip(m) && bin == "+inf" => Some(WHY_THRESHOLD_RECIP),
        ("rti", "u" | "v") if valid && ftz_float(m) && bin == "+inf" => Some(WHY_FTZ_RECIP),
        ("slab", "inv_dx" | "inv_dy" | "inv_dz") => match bin {
            "+max finite" | "-max finite" => Some(WHY_RECIP_NOT_MAX),
            "+subnormal" | "-subnormal" if guard => Some(WHY_GUARD_RECIP),
            "+inf" | "-inf" if embree => Some(WHY_EMBREE),
            _ => None,
        },
        ("slab", "pdx" | "pdy" | "pdz") if embree && matches!(bin, "+0" | "-0") => Some(WHY_EMBREE),
        ("slab", "t_near") if widen >= 1 && gradual(m) => match bin {
            "-0" | "+inf" => Some(WHY_WIDEN_NEAR),
            "+max finite" if widen >= 2 => Some(WHY_WIDEN_NEAR),
            _ => None,
        },
        ("slab", "t_far") if widen >= 1 && gradual(m) => match bin {
            "+0" | "-inf" => Some(WHY_WIDEN_FAR),
            "-max finite" if widen >= 2 => Some(WHY_WIDEN_FAR),
            _ => None,
        },
        _ => None,
    }
}

/// [`unit_value_reason`] for a fixed-point field `x` of format `q<int>.<frac>`.
fn fixed_value_reason(m: &Manifest, x: &Field, bin: &str, int: u32, frac: u32) -> Option<&'static str> {
    let saturating = !m.format.contains("wrap");
    let valid = x.care_when.as_deref() == Some("valid");
    let recip =
        matches!((m.unit.as_str(), x.name.as_str()), ("rti", "inv_det") | ("slab", "inv_dx" | "inv_dy" | "inv_dz"));
    let embree = m.params.get("slab_embree") == Some(&1) && m.params.get("slab_delta").is_some_and(|&d| d > 1);
    match (m.unit.as_str(), x.name.as_str()) {
        ("slab", "pdx" | "pdy" | "pdz") if embree && matches!(bin, "0" | "+1 step" | "-1 step") => {
            Some(WHY_EMBREE_FIXED)
        }
        _ if recip && embree && saturating && matches!(bin, "+max" | "min") => Some(WHY_EMBREE_FIXED),
        _ if recip && saturating && frac >= int && matches!(bin, "0" | "+1 step" | "-1 step") => Some(WHY_FIXED_RECIP),
        ("rti", "t" | "u" | "v") if valid && saturating && matches!(bin, "-1 step" | "min" | "negative") => {
            Some(WHY_RTI_SIGN_FIXED)
        }
        ("rti", "u" | "v") if valid && saturating && int >= 3 && bin == "+max" => Some(WHY_RTI_UV_BOUNDED_FIXED),
        _ => None,
    }
}

/// A unit's reason why rounding bin `bin` of operation coverpoint `signal` (`name (op)`) is
/// unreachable.
fn unit_rounding_reason(m: &Manifest, signal: &str, bin: &str) -> Option<&'static str> {
    let (name, op) = signal.split_once(" (")?;
    let op = op.trim_end_matches(')');
    let guard = m.params.get("slab_guard") == Some(&1);
    let valid = field(m, name).is_some_and(|x| x.1.care_when.as_deref() == Some("valid"));
    let recip = matches!((m.unit.as_str(), name), ("rti", "inv_det") | ("slab", "inv_dx" | "inv_dy" | "inv_dz"));
    match (bin, op) {
        ("underflow", "add" | "sub") if gradual(m) => Some(WHY_SUM_TINY_EXACT),
        ("tie", "div") if recip => Some(WHY_RECIP_NO_TIE),
        ("NaN", "div") if m.unit == "rti" && name == "inv_det" && valid => Some(WHY_RTI_DET_NUMBER),
        ("overflow" | "underflow", "div") if m.unit == "slab" && recip && guard => Some(WHY_GUARD_RECIP),
        ("overflow", "sub") if m.unit == "slab" && guard => Some(WHY_GUARD_SUB),
        ("overflow", "div") if recip && ftz_float(m) => Some(WHY_FTZ_RECIP),
        ("overflow", "div") if m.unit == "rti" && valid && recip && threshold_bounds_recip(m) => {
            Some(WHY_THRESHOLD_RECIP)
        }
        ("overflow", "div") if m.unit == "slab" && recip && m.params.get("slab_embree") == Some(&1) && gradual(m) => {
            Some(WHY_EMBREE)
        }
        ("overflow", "mul" | "div") if m.unit == "rti" && valid && (name == "u" || name == "v") => {
            Some(WHY_RTI_UV_NO_OVERFLOW)
        }
        _ => None,
    }
}

/// The rounded operations of the set's unit with IEEE-like operands: (stage, signal, op, a, b).
fn arith_rows(m: &Manifest) -> Vec<(u8, &'static str, &'static str, &'static str, &'static str)> {
    stage_ops(m, |k| matches!(k, Kind::Ieee { .. }))
}

/// The operations of the stage table (add, sub, mul, div rows) whose result and operands are
/// fields of kind `kind_ok` (or the constant `one`): (stage, signal, op, a, b).
fn stage_ops(
    m: &Manifest,
    kind_ok: impl Fn(&Kind) -> bool,
) -> Vec<(u8, &'static str, &'static str, &'static str, &'static str)> {
    use datapath::stage::{Op, Rule};
    let known = |n: &str| n == "one" || field(m, n).is_some_and(|x| kind_ok(&x.1.kind));
    stage_table_of(m)
        .into_iter()
        .filter(|d| matches!(d.rule, Rule::Arith | Rule::ArithGuardRecip | Rule::ArithGuardSub))
        .filter_map(|d| {
            let op = match d.op {
                Op::Add => "add",
                Op::Sub => "sub",
                Op::Mul => "mul",
                Op::Div => "div",
                Op::Logic => return None,
            };
            Some((d.stage, d.name, op, d.a, d.b))
        })
        .filter(|&(_, n, _, a, b)| known(n) && known(a) && known(b))
        .collect()
}

/// The operations of the set's unit with fixed-point operands: (stage, signal, op, a, b).
fn fixed_arith_rows(m: &Manifest) -> Vec<(u8, &'static str, &'static str, &'static str, &'static str)> {
    stage_ops(m, |k| matches!(k, Kind::Fixed { .. }))
}

/// Whether the set is an op set with a fixed-point result (its operation events are counted).
fn op_unit_fixed(m: &Manifest) -> bool {
    m.unit == "op"
        && field(m, "result").is_some_and(|x| matches!(x.1.kind, Kind::Fixed { .. }))
        && field(m, "opcode").is_some()
}

/// The bins of a fixed-point operation: the exact result against the format's range.
pub const FIXED_EVENT_BINS: [&str; 5] = ["exact", "inexact", "saturated", "wrapped", "divide by zero"];
/// Why a saturating format never wraps.
pub const WHY_SATURATES: &str =
    "the format saturates: a result beyond the range is clamped to its end (counted as saturated)";
/// Why a wrapping format never saturates.
pub const WHY_WRAPS: &str = "the format wraps: a result beyond the range is taken modulo 2^width (counted as wrapped)";
/// Why a fixed-point sum or difference is never inexact.
pub const WHY_FIXED_SUM_EXACT: &str =
    "a sum or difference of two values on the same grid is on the grid: exact, or beyond the range";
/// Why RTI's fixed-point u and v never leave the range where they are counted.
pub const WHY_RTI_UV_FIXED_IN_RANGE: &str = "counted only when valid: 0 <= u' <= fl(u' + v') <= det (det > 0; the mirror for det < 0), so u'/det is in [0, 1], and u' x fl(1/det) is at most det x fl(1/det) <= 1 + det x step <= 2 (u' <= det < 2^(I-1)... at most 2 plus a step), inside a range of at least 3 integer bits (v alike)";
/// Why a fixed-point u or v of a valid hit is never past 1 in divide mode.
pub const WHY_RTI_BARY_DIVIDE_FIXED: &str = "divide mode, fixed point, a valid hit: 0 <= u' <= det (det > 0; the mirror for det < 0), so u'/det is in [0, 1] exactly and every rounding mode keeps it there (0 and 1 are on the grid); fixed point has no inf or NaN (v alike)";
/// Why the op unit's division is not counted in reciprocal mode.
pub const WHY_OP_RECIP_NOT_COUNTED: &str = "in reciprocal mode the op unit's div is a x (1/b), two roundings: not counted as one operation (only add, sub, mul)";
/// Why an operation that is not a division never divides by zero.
pub const WHY_NOT_DIV: &str = "not a division";

/// The fixed-point event bin of operation `name = a op b` in row `row`: the exact result
/// (sums exactly; a product a b / 2^F; a quotient a 2^F / b; `one` is 2^F) inside the range
/// and on the grid (exact), inside and off it (inexact: rounded), or beyond the range
/// (saturated or wrapped, by the format); a division by zero has its own bin. None when the
/// result is don't-care in this row (care_when).
fn fixed_event(
    ix: &Ix,
    contents: &[Vec<Vec<u64>>],
    row: usize,
    name: &str,
    op: &str,
    a: &str,
    b: &str,
) -> Option<usize> {
    let (_, rf, _) = ix.field(name)?;
    let Kind::Fixed { frac, .. } = rf.kind else { return None };
    raw_fixed(ix, contents, row, name)?;
    let val = |n: &str| if n == "one" { Some(1i128 << frac) } else { raw_fixed(ix, contents, row, n) };
    let (x, y) = (val(a)?, val(b)?);
    let w = rf.width;
    let (lo, hi) = (-(1i128 << (w - 1)), (1i128 << (w - 1)) - 1);
    // the exact result as num / den steps, den > 0
    let (num, den) = match op {
        "add" => (x + y, 1),
        "sub" => (x - y, 1),
        "mul" => (x * y, 1i128 << frac),
        "div" if y == 0 => return Some(4),
        "div" if y < 0 => (-(x << frac), -y),
        "div" => (x << frac, y),
        _ => return None,
    };
    let beyond = num > hi * den || num < lo * den;
    let saturating = !ix.m.format.contains("wrap");
    Some(match (beyond, num % den == 0) {
        (true, _) if saturating => 2,
        (true, _) => 3,
        (false, true) => 0,
        (false, false) => 1,
    })
}

/// A unit's reason why fixed-point event bin `bin` of operation coverpoint `signal`
/// (`name (op)`) is unreachable.
fn fixed_event_reason(m: &Manifest, signal: &str, bin: &str) -> Option<&'static str> {
    let (name, _) = signal.split_once(" (")?;
    let valid = field(m, name).is_some_and(|x| x.1.care_when.as_deref() == Some("valid"));
    let divide = m.format.contains("divide");
    let embree = m.params.get("slab_embree") == Some(&1) && m.params.get("slab_delta").is_some_and(|&d| d > 1);
    let int = match field(m, name).map(|x| &x.1.kind) {
        Some(Kind::Fixed { int, .. }) => *int,
        _ => 0,
    };
    match (m.unit.as_str(), name, bin) {
        ("rti", _, "divide by zero") if valid => Some(WHY_VALID_DET_NONZERO),
        ("rti", "u" | "v", "saturated") if valid && (divide || int >= 3) => Some(WHY_RTI_UV_FIXED_IN_RANGE),
        ("op", "result", "divide by zero") if !divide => Some(WHY_OP_RECIP_NOT_COUNTED),
        ("slab", "inv_dx" | "inv_dy" | "inv_dz", "saturated" | "divide by zero") if embree => Some(WHY_EMBREE_FIXED),
        _ => None,
    }
}

/// The raw (two's-complement, in steps) value of fixed-point field `name` in row `row`; None
/// when it is don't-care in this row (care_when) or not a fixed-point field.
fn raw_fixed(ix: &Ix, contents: &[Vec<Vec<u64>>], row: usize, name: &str) -> Option<i128> {
    let (x, v) = cared(ix, contents, row, name)?;
    let Kind::Fixed { .. } = x.kind else { return None };
    let sh = 128 - x.width;
    Some(((v as i128) << sh) >> sh)
}

/// Whether the set is an op set with an IEEE-like result (its rounding events are counted).
fn op_unit_rounding(m: &Manifest) -> bool {
    m.unit == "op"
        && field(m, "result").is_some_and(|x| matches!(x.1.kind, Kind::Ieee { .. }))
        && field(m, "opcode").is_some()
}

/// The stage table of the set's unit (rti, slab; empty for the others).
fn stage_table_of(m: &Manifest) -> Vec<datapath::stage::SigDef> {
    match m.unit.as_str() {
        "rti" => {
            let div = if m.format.contains("divide") {
                datapath::format::DivMode::Divide
            } else {
                datapath::format::DivMode::RecipMul
            };
            datapath::rti::stage_table(div)
        }
        "slab" => datapath::slab::SLAB_TABLE.to_vec(),
        _ => Vec::new(),
    }
}

/// The rounding event of operation `name = a op b` in row `row` (None: don't-care).
#[allow(clippy::too_many_arguments)]
fn rounding_event(
    ix: &Ix,
    contents: &[Vec<Vec<u64>>],
    row: usize,
    name: &str,
    op: &str,
    a: &str,
    b: &str,
    ftz: bool,
) -> Option<usize> {
    let (_, rf, _) = ix.field(name)?;
    let Kind::Ieee { exp, man } = rf.kind else { return None };
    let val = |n: &str, flush: bool| -> Option<Option<f64>> {
        if n == "one" {
            return Some(Some(1.0));
        }
        operand(ix, contents, row, n, flush)
    };
    let r = val(name, false)?;
    let (x, y) = (val(a, ftz)?, val(b, ftz)?);
    let Some(r) = r else { return Some(6) };
    let (Some(x), Some(y)) = (x, y) else { return Some(6) };
    if op == "div" && y == 0.0 {
        // x / ±0 = ±inf exactly (IEEE's divide by zero, not a rounding)
        return Some(0);
    }
    if x.is_infinite() || y.is_infinite() {
        // an infinite operand with a non-NaN result: the result is exact (±inf, or x / ±inf = ±0)
        return Some(0);
    }
    if r.is_infinite() {
        return Some(3);
    }
    let bias = (1i32 << (exp - 1)) - 1;
    let min_normal = pow2(i64::from(1 - bias));
    // the exact result as an unevaluated sum s + e (quotients: the sign of a - r*b instead)
    let (s, e) = match op {
        "add" | "sub" => {
            let y = if op == "sub" { -y } else { y };
            let s = x + y;
            let bb = s - x;
            (s, (x - (s - bb)) + (y - bb))
        }
        "mul" => (x * y, 0.0),
        _ => {
            // x / y against r: the exact quotient's position by r*y vs x (exact products)
            let diff = x - r * y; // exact: r*y and x are within a rounding of each other
            let dir = if diff == 0.0 { 0.0 } else { diff.signum() * y.signum() };
            if dir == 0.0 {
                return Some(0);
            }
            let tiny = x.abs() < min_normal * y.abs();
            if ftz && tiny {
                return Some(if r == 0.0 { 5 } else { 1 });
            }
            let n = neighbour(r, dir > 0.0, exp, man);
            let mid = (r + n) / 2.0;
            let tie = mid * y == x;
            return Some(if tie {
                2
            } else if tiny {
                4
            } else {
                1
            });
        }
    };
    if s == r && e == 0.0 {
        return Some(0);
    }
    let up = if s != r { s > r } else { e > 0.0 };
    let tiny = s.abs() < min_normal || (s.abs() == min_normal && e != 0.0 && e.signum() != s.signum());
    if ftz && tiny {
        return Some(if r == 0.0 && (s != 0.0 || e != 0.0) { 5 } else { 1 });
    }
    let n = neighbour(r, up, exp, man);
    let mid = (r + n) / 2.0;
    if s == mid && e == 0.0 {
        return Some(2);
    }
    Some(if tiny { 4 } else { 1 })
}

/// The format value next to `r` (up: toward +inf), as binary64.
fn neighbour(r: f64, up: bool, exp: u32, man: u32) -> f64 {
    let bias = (1i32 << (exp - 1)) - 1;
    let min_sub = pow2(i64::from(1 - bias - man as i32));
    if r == 0.0 {
        return if up { min_sub } else { -min_sub };
    }
    // the step at r's binade (subnormal step below the smallest normal)
    let away = (r > 0.0) == up;
    let a = r.abs();
    let e = ((a.to_bits() >> 52) & 0x7ff) as i32 - 1023; // a is a binary64 normal
    let step_at = |e: i32| pow2(i64::from(e.max(1 - bias) - man as i32));
    let step = if away {
        step_at(e)
    } else if a == pow2(i64::from(e)) {
        step_at(e - 1)
    } else {
        step_at(e)
    };
    let n = if away { a + step } else { a - step };
    if r > 0.0 {
        n
    } else {
        -n
    }
}

/// The bins of a subtraction's (or addition's) cancellation depth: the bits lost, the exponent of
/// the larger operand minus the exponent of the result, for operands of opposite effective
/// signs.
pub fn cancellation_bins(man: u64) -> Vec<String> {
    vec![
        "same signs or a zero operand (no cancellation)".into(),
        "0 bits lost".into(),
        "1 bit lost".into(),
        format!("2 to {man} bits lost"),
        format!("{} or more bits lost", man + 1),
        "exact zero (x - x)".into(),
    ]
}

/// The exponent of a nonzero finite binary64 value (floor of log2 |v|).
fn exponent(v: f64) -> i64 {
    let b = v.abs().to_bits();
    let e = ((b >> 52) & 0x7ff) as i64;
    if e == 0 {
        // a binary64 subnormal: below every format value raypipe has, but stay exact
        return -1023 - (b.leading_zeros() as i64 - 12);
    }
    e - 1023
}

/// The cancellation bin of `name = a op b` in row `row` (None: don't-care or a NaN / infinite
/// operand or result).
#[allow(clippy::too_many_arguments)]
fn cancellation(
    ix: &Ix,
    contents: &[Vec<Vec<u64>>],
    row: usize,
    name: &str,
    op: &str,
    a: &str,
    b: &str,
    ftz: bool,
) -> Option<usize> {
    let m = &ix.m;
    let man = m.params.get("man").copied()? as i64;
    let r = operand(ix, contents, row, name, false)??;
    let x = operand(ix, contents, row, a, ftz)??;
    let y = operand(ix, contents, row, b, ftz)??;
    if !(x.is_finite() && y.is_finite() && r.is_finite()) {
        return None;
    }
    let y = if op == "sub" { -y } else { y };
    if x == 0.0 || y == 0.0 || (x > 0.0) == (y > 0.0) {
        return Some(0);
    }
    if x == -y {
        return Some(5);
    }
    if r == 0.0 {
        // flushed (FTZ): everything lost
        return Some(4);
    }
    let lost = exponent(x).max(exponent(y)) - exponent(r);
    Some(match lost {
        i64::MIN..=0 => 1,
        1 => 2,
        l if l <= man => 3,
        _ => 4,
    })
}

/// The operand classes of a cross: zero (either sign), subnormal, normal (the smallest and
/// largest included), infinite, NaN — as the datapath reads the operand (FTZ: a subnormal as
/// zero).
pub const CROSS_CLASSES: [&str; 5] = ["zero", "subnormal", "normal", "inf", "NaN"];

/// The cross class of an operand read by `operand` in a format whose smallest normal is
/// `min_normal`.
fn cross_class(v: Option<f64>, min_normal: f64) -> usize {
    let Some(v) = v else { return 4 };
    if v == 0.0 {
        0
    } else if v.is_infinite() {
        3
    } else if v.abs() < min_normal {
        1
    } else {
        2
    }
}

/// The smallest normal of the set's float format (0 for fixed point).
fn min_normal(m: &Manifest) -> f64 {
    match (m.params.get("float"), m.params.get("exp")) {
        (Some(1), Some(&e)) => pow2(i64::from(2 - (1i32 << (e - 1)))),
        _ => 0.0,
    }
}

/// The operations whose cancellation depth is counted: every add and subtract of
/// [`arith_rows`].
fn cancel_rows(m: &Manifest) -> Vec<(u8, &'static str, &'static str, &'static str, &'static str)> {
    arith_rows(m).into_iter().filter(|r| r.2 == "add" || r.2 == "sub").collect()
}

/// The operations whose operand classes are crossed: every rounded operation of the stage
/// table with two signal operands (not the constant 1); one gated by a care_when (RTI's t, u,
/// v after `valid`) is counted only where it is defined, and its cells `valid` rules out are
/// marked in [`cross_reason`].
fn crossed_rows(m: &Manifest) -> Vec<(u8, &'static str, &'static str, &'static str, &'static str)> {
    arith_rows(m).into_iter().filter(|&(_, name, _, a, _)| a != "one" && field(m, name).is_some()).collect()
}

/// Why a cross bin is unreachable (`b` the second operand's signal, `bin` "x x y").
fn cross_reason(m: &Manifest, (name, a, b): (&str, &str, &str), bin: &str) -> Option<&'static str> {
    let (x, y) = bin.split_once(" x ")?;
    let ftz = m.params.get("ftz") == Some(&1);
    if field(m, name).is_some_and(|f| f.1.care_when.is_some()) {
        // RTI after `valid` (t, u, v: t' u' v' times 1/det, or divided by det)
        if x == "NaN" || y == "NaN" {
            return Some(WHY_VALID_NUMBERS);
        }
        let barycentric = a == "up" || a == "vp";
        let recip = b == "inv_det";
        match (recip, x, y) {
            (true, "inf", _) if barycentric && y != "zero" => return Some(WHY_VALID_UV_INF_RECIP),
            (true, "normal", "inf") if barycentric => return Some(WHY_VALID_UV_TINY_DET),
            (true, _, "inf") if ftz => return Some(WHY_VALID_FTZ_RECIP),
            (true, _, "inf") if threshold_bounds_recip(m) => return Some(WHY_THRESHOLD_RECIP),
            (false, _, "zero") => return Some(WHY_VALID_DET_NONZERO),
            (false, "inf", _) if barycentric && y != "inf" => return Some(WHY_VALID_UV_INF_DIV),
            (false, "normal", "subnormal") if barycentric => return Some(WHY_VALID_UV_TINY_DET),
            _ => {}
        }
    }
    let guard = m.params.get("slab_guard") == Some(&1);
    if ftz && (x == "subnormal" || y == "subnormal") {
        return Some(WHY_FTZ);
    }
    if m.unit == "slab" && guard && b.starts_with("inv_d") && y == "subnormal" {
        return Some(WHY_GUARD_RECIP);
    }
    if m.unit == "slab" && m.params.get("slab_embree") == Some(&1) && !ftz && b.starts_with("inv_d") && y == "inf" {
        return Some(WHY_EMBREE);
    }
    None
}

/// Whether the RTI set culls back faces (then `valid` needs det > threshold).
fn culled(m: &Manifest) -> bool {
    m.unit == "rti" && m.params.get("cull_backface") == Some(&1)
}

/// Whether the RTI set's det threshold keeps 1/det finite where it is counted (`valid`):
/// a threshold t > 0 with 1/t below the format's largest finite value (IEEE-like formats).
fn threshold_bounds_recip(m: &Manifest) -> bool {
    let p = |k: &str| m.params.get(k).copied();
    let (Some(1), Some(exp), Some(man), Some(thr)) = (p("float"), p("exp"), p("man"), p("det_thr")) else {
        return false;
    };
    let t = decode(m, thr);
    let max = (2.0 - pow2(-(man as i64))) * pow2((1i64 << (exp - 1)) - 1);
    t > 0.0 && 1.0 / t < max
}

/// Why 1/det is never negative (or -0) under backface culling where it is counted.
pub const WHY_CULL_POSITIVE: &str = "counted only when valid: under backface culling valid needs det > det_threshold >= 0, so 1/det is positive, or +0 for det = +inf";
/// Why 1/det stays finite under a positive det threshold where it is counted.
pub const WHY_THRESHOLD_RECIP: &str = "counted only when valid: |det| > det_threshold > 0 (det_ok), so |1/det| <= fl(1/det_threshold), finite since 1/det_threshold is below the largest finite value: 1/det never overflows, and u' x (1/det), v' x (1/det) (|u'|, |v'| <= |det|) stay at most 2";

/// Why an operand of RTI's t, u or v (counted only when `valid`) is never NaN.
pub const WHY_VALID_NUMBERS: &str = "counted only when valid: then det is a number with |det| > det_threshold (det_ok), so 1/det is not NaN, and t', u', v' are NaN-free (t_ok, u_ok, v_ok)";
/// Why an infinite u' or v' meets only a zero 1/det.
pub const WHY_VALID_UV_INF_RECIP: &str = "counted only when valid: |u'| <= |det| and |v'| <= |det| (uv_ok with u_ok, v_ok), so an infinite u' or v' needs an infinite det, whose reciprocal is 0";
/// Why an infinite u' or v' meets only an infinite det.
pub const WHY_VALID_UV_INF_DIV: &str = "counted only when valid: |u'| <= |det| and |v'| <= |det| (uv_ok with u_ok, v_ok), so an infinite u' or v' needs an infinite det";
/// Why a normal u' or v' never meets a subnormal det (or its infinite reciprocal).
pub const WHY_VALID_UV_TINY_DET: &str = "counted only when valid: |u'| <= |det| and |v'| <= |det| (uv_ok with u_ok, v_ok); 1/det overflows only for |det| < 1/max < the smallest normal, so with an infinite 1/det (or a subnormal det) u' and v' are zero or subnormal";
/// Why 1/det is finite under flush-to-zero when valid.
pub const WHY_VALID_FTZ_RECIP: &str = "counted only when valid under flush-to-zero: det is nonzero, so normal (a subnormal det is read as zero) or infinite, and 1/det of a normal det is at most 1/min_normal = 2^(emax-1) in magnitude: never infinite";
/// Why the divisor det is never zero when valid.
pub const WHY_VALID_DET_NONZERO: &str =
    "counted only when valid: |det| > det_threshold >= 0 (det_ok), so det is not zero";

/// A per-unit event coverpoint.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Event {
    /// RTI: det against the threshold (and its sign).
    RtiDet,
    /// Slab: the origin against the box on one axis.
    SlabOrigin(usize),
    /// Slab: the box's extent on one axis.
    SlabExtent(usize),
    /// Slab, conservative: which guard fired.
    SlabGuard,
    /// Slab, a variant without the guard: where the conservative guard would fire (the cross
    /// guard × variant, read across the variants' models).
    SlabGuardCondition,
    /// Capture: a hit whose t equals the held hit's.
    CaptureTie,
    /// Capture: each slot's comparator, a hit's t against the held hit's (true: tie rule last).
    CaptureCompare(bool),
    /// RTI, a valid hit: where its barycentric `u` (0) or `v` (1) is: at 0, at 1, between or
    /// past (rounding).
    RtiBary(usize),
    /// RTI, a valid hit: its `t` at the interval's ends.
    RtiT,
    /// Slab, a hit: the entry distance against the exit distance before widening.
    SlabTouch,
    /// Traverse: the back-traversal distance of each restart (the ray re-run on the set's tree).
    TraverseBack,
    /// Traverse: ties between siblings on the ray's path and the child taken at each.
    TraverseTie,
}

const AXES: [&str; 3] = ["x", "y", "z"];

/// The event coverpoints of the set's unit.
fn events(m: &Manifest) -> Vec<Event> {
    let float = m.params.get("float") == Some(&1);
    match m.unit.as_str() {
        "rti" if field(m, "det").is_some() => vec![Event::RtiDet, Event::RtiBary(0), Event::RtiBary(1), Event::RtiT],
        "slab" => {
            let mut v: Vec<Event> = (0..3).map(Event::SlabOrigin).chain((0..3).map(Event::SlabExtent)).collect();
            if float {
                v.push(if m.params.get("slab_guard") == Some(&1) {
                    Event::SlabGuard
                } else {
                    Event::SlabGuardCondition
                });
            }
            if field(m, "tn_xyz").is_some() {
                v.push(Event::SlabTouch);
            }
            v
        }
        "capture" => vec![Event::CaptureTie, Event::CaptureCompare(m.params.get("tie_last") == Some(&1))],
        "traverse" => vec![Event::TraverseBack, Event::TraverseTie],
        _ => Vec::new(),
    }
}

/// Why an event bin of a fixed-point set is never reached.
pub const WHY_EVENT_FIXED_NAN: &str = "fixed point has no NaN";
/// Why a hit's t is never outside [tmin, tmax].
pub const WHY_HIT_T_IN_RANGE: &str =
    "hit = valid & tmin_ok & tmax_ok, the compares tmin <= t and t <= tmax of the final (divided) t at stage 10: a hit's t is in [tmin, tmax], never NaN";
/// Why a slab without widening never hits with its entry past its exit.
pub const WHY_NO_WIDENING: &str =
    "without widening (slab_widen_ulps 0) t_near = tn_xyz and t_far = tf_xyz, and a hit needs t_near <= t_far";
/// Why a zero threshold leaves a bin empty.
pub const WHY_ZERO_THRESHOLD: &str = "the det threshold is 0: no nonzero det is at or below it in magnitude";

impl Event {
    fn signal(self) -> String {
        match self {
            Event::RtiDet => "det against the threshold".into(),
            Event::SlabOrigin(a) => format!("origin against the box, axis {}", AXES[a]),
            Event::SlabExtent(a) => format!("box extent, axis {}", AXES[a]),
            Event::SlabGuard => "conservative guard fired".into(),
            Event::SlabGuardCondition => "the conservative guard's condition (this variant has no guard)".into(),
            Event::CaptureTie => "a hit's t equals the held hit's t".into(),
            Event::CaptureCompare(_) => "each slot's compare: a hit's t against the held hit's t".into(),
            Event::RtiBary(k) => format!("{} of a valid hit", ["u", "v"][k]),
            Event::RtiT => "t of a valid hit against tmin and tmax".into(),
            Event::SlabTouch => "a hit's entry against its exit (tn_xyz vs tf_xyz)".into(),
            Event::TraverseBack => "back-traversal distance of a restart (levels)".into(),
            Event::TraverseTie => "siblings both hit at equal entry t (a tie) on the path".into(),
        }
    }

    fn bins(self) -> &'static [&'static str] {
        match self {
            Event::RtiDet => &[
                "det > threshold",
                "0 < det <= threshold",
                "det = +-0",
                "-threshold <= det < 0",
                "det < -threshold (culled under backface culling)",
                "NaN",
            ],
            Event::SlabOrigin(_) => &[
                "o < min",
                "o = min (on the min face)",
                "min < o < max",
                "o = max (on the max face)",
                "o > max",
                "NaN",
            ],
            Event::SlabExtent(_) => &["min < max", "min = max (zero extent)", "min > max (empty)", "NaN"],
            Event::SlabGuard => &["no guard", "reciprocal guarded", "difference guarded"],
            Event::SlabGuardCondition => &[
                "no guard condition",
                "1/d of a finite nonzero d is inf, zero or subnormal",
                "o - face of finite operands overflows",
            ],
            Event::CaptureTie => &["no tie", "tie (the tie rule decides)"],
            Event::CaptureCompare(false) => &[
                "t < held t (the new hit is taken)",
                "t = held t (tie rule first: the held hit is kept)",
                "t > held t (the held hit is kept)",
            ],
            Event::CaptureCompare(true) => &[
                "t < held t (the new hit is taken)",
                "t = held t (tie rule last: the new hit is taken)",
                "t > held t (the held hit is kept)",
            ],
            Event::RtiBary(0) => {
                &["u = 0 (on the edge v0-v2)", "0 < u < 1", "u = 1 (at the vertex v1)", "other (past 1, inf, NaN)"]
            }
            Event::RtiBary(_) => {
                &["v = 0 (on the edge v0-v1)", "0 < v < 1", "v = 1 (at the vertex v2)", "other (past 1, inf, NaN)"]
            }
            Event::RtiT => &["t = tmin", "tmin < t < tmax", "t = tmax", "other (past an end, NaN)"],
            Event::SlabTouch => &[
                "entry < exit",
                "entry = exit (touching: an edge, a corner or a zero-extent box)",
                "entry > exit (a hit by widening)",
            ],
            Event::TraverseBack => &BACK_BINS,
            Event::TraverseTie => {
                &["no tie", "tie, the nearer (left) child taken", "tie, the farther (right) child taken"]
            }
        }
    }

    fn unreachable(self, m: &Manifest, bin: &str) -> Option<&'static str> {
        let float = m.params.get("float") == Some(&1);
        if bin == "NaN" && !float {
            return Some(WHY_EVENT_FIXED_NAN);
        }
        let zero_thr = m.params.get("det_thr").is_some_and(|&b| {
            let (exp, man) = (m.params.get("exp").copied().unwrap_or(0), m.params.get("man").copied().unwrap_or(0));
            if float {
                b & ((1u64 << (exp + man)) - 1) == 0
            } else {
                b == 0
            }
        });
        let widen = m.params.get("slab_widen_ulps").copied().unwrap_or(0);
        match (self, bin) {
            (Event::RtiDet, "0 < det <= threshold" | "-threshold <= det < 0") if zero_thr => Some(WHY_ZERO_THRESHOLD),
            (Event::SlabTouch, "entry > exit (a hit by widening)") if widen == 0 => Some(WHY_NO_WIDENING),
            (Event::RtiT, "other (past an end, NaN)") => Some(WHY_HIT_T_IN_RANGE),
            (Event::RtiBary(_), "other (past 1, inf, NaN)") if !float && m.format.contains("divide") => {
                Some(WHY_RTI_BARY_DIVIDE_FIXED)
            }
            (Event::TraverseBack, b) => {
                // a restart resumes at a level 0..levels-1 from a pass that ended at one
                let levels = m.params.get("levels").copied().unwrap_or(0);
                let least = BACK_BINS.iter().position(|&x| x == b).unwrap_or(0) as u64;
                (least + 1 > levels).then_some(WHY_BACK_DEPTH)
            }
            _ => None,
        }
    }

    /// The bins row values hit: `v(name)` an operand as the datapath reads it, `flag(name)` a
    /// 1-bit field.
    fn measure(
        self,
        m: &Manifest,
        v: &dyn Fn(&str) -> Option<Option<f64>>,
        flag: &dyn Fn(&str) -> Option<bool>,
    ) -> Vec<usize> {
        let num = |n: &str| v(n);
        match self {
            Event::RtiDet => {
                let Some(det) = num("det") else { return Vec::new() };
                let thr = m.params.get("det_thr").map_or(0.0, |&b| decode(m, b));
                let Some(d) = det else { return vec![5] };
                vec![if d > thr {
                    0
                } else if d > 0.0 {
                    1
                } else if d == 0.0 {
                    2
                } else if d >= -thr {
                    3
                } else {
                    4
                }]
            }
            Event::SlabOrigin(a) => {
                let (Some(o), Some(lo), Some(hi)) = (num(["ox", "oy", "oz"][a]), num(MINS[a]), num(MAXS[a])) else {
                    return Vec::new();
                };
                let (Some(o), Some(lo), Some(hi)) = (o, lo, hi) else { return vec![5] };
                vec![if o == lo {
                    1
                } else if o == hi {
                    3
                } else if o < lo {
                    0
                } else if o > hi {
                    4
                } else {
                    2
                }]
            }
            Event::SlabExtent(a) => {
                let (Some(lo), Some(hi)) = (num(MINS[a]), num(MAXS[a])) else {
                    return Vec::new();
                };
                vec![match (lo, hi) {
                    (Some(lo), Some(hi)) if lo < hi => 0,
                    (Some(lo), Some(hi)) if lo == hi => 1,
                    (Some(_), Some(_)) => 2,
                    _ => 3,
                }]
            }
            Event::SlabGuard | Event::SlabGuardCondition => {
                let finite = |x: Option<Option<f64>>| matches!(x, Some(Some(x)) if x.is_finite());
                // the guard writes NaN where its condition holds; without it the value stands
                let min_normal = min_normal(m);
                let guarded = self == Event::SlabGuard;
                let tiny_or_inf = |x: Option<Option<f64>>| {
                    if guarded {
                        matches!(x, Some(None))
                    } else {
                        matches!(x, Some(Some(v)) if !v.is_finite() || v.abs() < min_normal)
                    }
                };
                let overflowed = |x: Option<Option<f64>>| {
                    if guarded {
                        matches!(x, Some(None))
                    } else {
                        matches!(x, Some(Some(v)) if v.is_infinite())
                    }
                };
                let mut out = Vec::new();
                for (pd, inv) in [("pdx", "inv_dx"), ("pdy", "inv_dy"), ("pdz", "inv_dz")] {
                    let d = num(pd);
                    if finite(d) && d != Some(Some(0.0)) && tiny_or_inf(num(inv)) {
                        out.push(1);
                        break;
                    }
                }
                'sub: for a in 0..3 {
                    for (r, b) in [(["lox", "loy", "loz"][a], MINS[a]), (["hix", "hiy", "hiz"][a], MAXS[a])] {
                        if finite(num(b)) && finite(num(["ox", "oy", "oz"][a])) && overflowed(num(r)) {
                            out.push(2);
                            break 'sub;
                        }
                    }
                }
                if out.is_empty() {
                    out.push(0);
                }
                out
            }
            Event::RtiBary(_) | Event::RtiT if !(flag("valid") == Some(true) && flag("hit") == Some(true)) => {
                Vec::new()
            }
            Event::RtiBary(k) => {
                let Some(x) = num(["u", "v"][k]) else { return Vec::new() };
                // 1 in the set's units (fixed point: steps)
                let one = m.params.get("fx_frac").map_or(1.0, |&f| pow2(f as i64));
                vec![match x {
                    Some(0.0) => 0, // ±0
                    Some(x) if x > 0.0 && x < one => 1,
                    Some(x) if x == one => 2,
                    _ => 3,
                }]
            }
            Event::RtiT => {
                let (Some(t), Some(lo), Some(hi)) = (num("t"), num("tmin"), num("tmax")) else { return Vec::new() };
                vec![match (t, lo, hi) {
                    (Some(t), Some(lo), _) if t == lo => 0,
                    (Some(t), _, Some(hi)) if t == hi => 2,
                    (Some(t), Some(lo), Some(hi)) if lo < t && t < hi => 1,
                    _ => 3,
                }]
            }
            Event::SlabTouch => {
                if flag("hit") != Some(true) {
                    return Vec::new();
                }
                match (num("tn_xyz"), num("tf_xyz")) {
                    (Some(Some(n)), Some(Some(f))) => vec![if n < f {
                        0
                    } else if n == f {
                        1
                    } else {
                        2
                    }],
                    _ => Vec::new(),
                }
            }
            // measured from the replayed path (RowBins::hits), not from the row's fields
            Event::TraverseBack | Event::TraverseTie => Vec::new(),
            Event::CaptureCompare(_) => {
                let slots = m.params.get("slots").copied().unwrap_or(0) as usize;
                let mut seen = [false; 3];
                for s in 1..slots {
                    if flag(&format!("hit{s}")) != Some(true) || flag(&format!("c{}_hit", s - 1)) != Some(true) {
                        continue;
                    }
                    if let (Some(x @ Some(_)), Some(y @ Some(_))) =
                        (num(&format!("t{s}")), num(&format!("c{}_t", s - 1)))
                    {
                        seen[compare_bin(x, y)] = true;
                    }
                }
                (0..3).filter(|&k| seen[k]).collect()
            }
            Event::CaptureTie => {
                let slots = m.params.get("slots").copied().unwrap_or(0) as usize;
                let tie = (1..slots).any(|s| {
                    flag(&format!("hit{s}")) == Some(true)
                        && flag(&format!("c{}_hit", s - 1)) == Some(true)
                        && matches!((num(&format!("t{s}")), num(&format!("c{}_t", s - 1))), (Some(Some(x)), Some(Some(y))) if x == y)
                });
                vec![usize::from(tie)]
            }
        }
    }
}

/// The box planes' input names per axis.
const MINS: [&str; 3] = ["minx", "miny", "minz"];
/// The box planes' input names per axis.
const MAXS: [&str; 3] = ["maxx", "maxy", "maxz"];

/// The value of encoding `b` in the set's format (a NaN as NaN).
fn decode(m: &Manifest, b: u64) -> f64 {
    let p = |k: &str| m.params.get(k).copied().unwrap_or(0);
    if p("float") == 1 {
        ieee_value(b, p("exp") as u32, p("man") as u32, false).unwrap_or(f64::NAN)
    } else {
        // in steps, as `operand` reads fixed-point fields
        fixed_steps(b, p("width") as u32)
    }
}

/// The value of an IEEE-like encoding `v` with `exp` exponent and `man` fraction bits (a
/// subnormal as a zero of its sign under `ftz`); None for a NaN.
fn ieee_value(v: u64, exp: u32, man: u32, ftz: bool) -> Option<f64> {
    let neg = (v >> (exp + man)) & 1 == 1;
    let e = (v >> man) & ((1 << exp) - 1);
    let f = v & ((1 << man) - 1);
    let bias = (1i64 << (exp - 1)) - 1;
    let mag = if e == (1 << exp) - 1 {
        if f != 0 {
            return None;
        }
        f64::INFINITY
    } else if e == 0 {
        if ftz {
            0.0
        } else {
            f as f64 * pow2(1 - bias - man as i64)
        }
    } else {
        (f as f64 + (1u64 << man) as f64) * pow2(e as i64 - bias - man as i64)
    };
    Some(if neg { -mag } else { mag })
}

/// 2^k, exactly (a binary64 normal built from its exponent; `powi` outside that range).
fn pow2(k: i64) -> f64 {
    if (-1022..=1023).contains(&k) {
        f64::from_bits(((k + 1023) as u64) << 52)
    } else {
        2f64.powi(k as i32)
    }
}

/// A `w`-bit two's-complement encoding as a signed integer (fixed point in steps).
fn fixed_steps(v: u64, w: u32) -> f64 {
    let s = if w == 64 { v as i64 } else { ((v << (64 - w)) as i64) >> (64 - w) };
    s as f64
}

/// The bins of a compare.
pub const COMPARE_BINS: [&str; 4] = ["<", "=", ">", "unordered"];

/// Why a fixed-point compare is never unordered.
pub const WHY_FIXED_ORDERED: &str = "fixed point has no NaN: every compare is ordered";

/// The compares of the set's unit: (stage, signal, a, b) from its stage table.
fn compares(m: &Manifest) -> Vec<(u8, &'static str, &'static str, &'static str)> {
    use datapath::stage::Rule;
    let table = stage_table_of(m);
    table
        .into_iter()
        .filter_map(|d| match d.rule {
            Rule::Le(a, b) | Rule::SelNear(a, b) | Rule::SelFar(a, b) | Rule::Oriented(a, b) => {
                Some((d.stage, d.name, a, b))
            }
            _ => None,
        })
        .filter(|(_, _, a, b)| (*a == "zero" || field(m, a).is_some()) && field(m, b).is_some())
        .collect()
}

/// The per-vector file index and field of signal `name`.
fn field<'a>(m: &'a Manifest, name: &str) -> Option<(usize, &'a Field, usize)> {
    m.files
        .iter()
        .enumerate()
        .filter(|(i, _)| per_vector(m, *i))
        .find_map(|(i, f)| f.fields.iter().position(|x| x.name == name).map(|k| (i, &f.fields[k], k)))
}

/// Field positions by name, found once per set for the per-row paths ([`field`]'s answers).
struct Ix {
    /// The manifest (a copy).
    m: Manifest,
    fields: std::collections::HashMap<String, (usize, Field, usize), Fnv>,
    /// The expected-output file's fields (what a care_when names).
    outs: std::collections::HashMap<String, usize, Fnv>,
}

/// FNV-1a: the field-name lookups of every row hash short names (SipHash's set-up cost would
/// dominate the count).
#[derive(Clone, Copy, Default)]
struct Fnv;

/// [`Fnv`]'s state.
struct FnvHasher(u64);

impl std::hash::BuildHasher for Fnv {
    type Hasher = FnvHasher;
    fn build_hasher(&self) -> FnvHasher {
        FnvHasher(0xcbf2_9ce4_8422_2325)
    }
}

impl std::hash::Hasher for FnvHasher {
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
        }
    }
    fn finish(&self) -> u64 {
        self.0
    }
}

impl Ix {
    fn new(m: &Manifest) -> Self {
        let mut fields = std::collections::HashMap::with_hasher(Fnv);
        for (i, f) in m.files.iter().enumerate().filter(|(i, _)| per_vector(m, *i)) {
            for (k, x) in f.fields.iter().enumerate() {
                fields.entry(x.name.clone()).or_insert((i, x.clone(), k));
            }
        }
        let mut outs = std::collections::HashMap::with_hasher(Fnv);
        if let Some(f) = m.files.get(1) {
            for (k, x) in f.fields.iter().enumerate() {
                outs.entry(x.name.clone()).or_insert(k);
            }
        }
        Ix { m: m.clone(), fields, outs }
    }

    fn field(&self, name: &str) -> Option<(usize, &Field, usize)> {
        self.fields.get(name).map(|(i, x, k)| (*i, x, *k))
    }
}

/// Operand `name` of row `row` as the datapath's compare reads it: `Some(None)` a NaN,
/// `Some(Some(v))` a number; `None` when the value is don't-care in this row (care_when).
fn operand(ix: &Ix, contents: &[Vec<Vec<u64>>], row: usize, name: &str, ftz: bool) -> Option<Option<f64>> {
    let (x, v) = cared(ix, contents, row, name)?;
    Some(match x.kind {
        Kind::Ieee { exp, man } => ieee_value(v, exp, man, ftz),
        Kind::Fixed { .. } => Some(fixed_steps(v, x.width)),
        _ => Some(v as f64),
    })
}

/// Field `name` of row `row` and its raw encoding; None when the field is don't-care in this
/// row (its care_when flag is 0) or absent.
fn cared<'a>(ix: &'a Ix, contents: &[Vec<Vec<u64>>], row: usize, name: &str) -> Option<(&'a Field, u64)> {
    let (i, x, k) = ix.field(name)?;
    if let Some(flag) = &x.care_when {
        let j = *ix.outs.get(flag.as_str())?;
        if contents.get(1)?.get(row)?.get(j)? & 1 == 0 {
            return None;
        }
    }
    Some((x, *contents.get(i)?.get(row)?.get(k)?))
}

/// Whether file `i` of the manifest holds one row per vector.
fn per_vector(m: &Manifest, i: usize) -> bool {
    i < 2 || m.files[i].role == crate::hdl::STAGE_ROLE
}

/// A short name for a file's role.
fn role_name(role: &str) -> &'static str {
    if role.starts_with("inputs") {
        "inputs"
    } else if role == crate::hdl::STAGE_ROLE {
        "stage signals"
    } else {
        "expected outputs"
    }
}

/// The bin of value `v` of field `x` (None: a field without coverpoint).
fn bin_of(x: &Field, v: u64, m: &Manifest) -> Option<usize> {
    match &x.kind {
        Kind::Ieee { exp, man } => Some(float_bin(v, *exp, *man)),
        Kind::Fixed { .. } => Some(fixed_bin(v, x.width)),
        Kind::Flag => Some((v & 1) as usize),
        Kind::Uint if x.name == "class" => Some((v as usize).min(m.classes.len())),
        Kind::Uint => {
            traverse_bins(m, &x.name)?;
            let n = m.params.get("leaves").copied().unwrap_or(0);
            Some(match x.name.as_str() {
                "opcode" => (v as usize).min(crate::gen::OPCODES.len() - 1),
                "count" if v == 0 => 0,
                "count" if v < n => 1,
                "count" => 2,
                "passes" => (v as usize).min(3),
                _ => (v & 3) as usize,
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn utc_dates() {
        assert_eq!(utc(0), "1970-01-01T00:00:00");
        assert_eq!(utc(951_782_400), "2000-02-29T00:00:00");
        assert_eq!(utc(1_796_390_257), "2026-12-04T13:17:37");
    }

    /// The arithmetic behind three reasons, over every fp16 and e5m6 value: 1/x never rounds
    /// to ±max and is never a tie (WHY_RECIP_NOT_MAX, WHY_RECIP_NO_TIE); a tiny sum of two
    /// e5m6 values is exact (WHY_SUM_TINY_EXACT, every pair).
    #[test]
    fn reciprocals_and_tiny_sums_exhaustively() {
        use datapath::Format;
        for name in ["fp16", "e5m6"] {
            let f: datapath::AnyFormat = name.parse().unwrap();
            datapath::with_format!(f, |f| {
                let datapath::format::FormatKind::Float(l) = f.kind() else { unreachable!() };
                let n = 1u64 << f.width();
                let max = f.to_f64(f.from_bits((((1u64 << l.exp_bits) - 2) << l.man_bits) | l.man_mask()));
                let mut ties = 0;
                for b in 0..n {
                    let x = f.from_bits(b);
                    let xf = f.to_f64(x);
                    if !xf.is_finite() || xf == 0.0 {
                        continue;
                    }
                    let r = f.to_f64(f.div(f.one(), x));
                    assert_ne!(r.abs(), max, "{name}: 1/{xf}");
                    // a tie: r x = 1 ± half a step exactly; the exact 1/x against the midpoint
                    if r.is_finite() && r != 0.0 {
                        let up = f.to_f64(f.next_up(f.from_f64(r)));
                        let down = f.to_f64(f.next_down(f.from_f64(r)));
                        for nb in [up, down] {
                            if nb.is_finite() && ((r + nb) / 2.0) * xf == 1.0 {
                                ties += 1;
                            }
                        }
                    }
                }
                assert_eq!(ties, 0, "{name}");
            });
        }
        let f: datapath::AnyFormat = "e5m6".parse().unwrap();
        datapath::with_format!(f, |f| {
            let min_normal = pow2(i64::from(-14));
            let n = 1u64 << f.width();
            let mut tiny = 0u64;
            for a in 0..n {
                let x = f.to_f64(f.from_bits(a));
                if !x.is_finite() {
                    continue;
                }
                for b in 0..n {
                    let y = f.to_f64(f.from_bits(b));
                    if !y.is_finite() || (x + y).abs() >= min_normal {
                        continue;
                    }
                    assert_eq!(f.to_f64(f.add(f.from_bits(a), f.from_bits(b))), x + y, "{x} + {y}");
                    tiny += 1;
                }
            }
            // every pair of subnormals and of nearby normals of opposite signs
            assert!(tiny > 1 << 14, "{tiny}");
        });
    }

    #[test]
    fn fp16_and_fixed_bins_by_hand() {
        let b = |v| FLOAT_BINS[float_bin(v, 5, 10)];
        assert_eq!(
            [b(0x0000), b(0x8000), b(0x0001), b(0x83ff), b(0x0400), b(0x8400), b(0x3c00), b(0xbc00)],
            ["+0", "-0", "+subnormal", "-subnormal", "+min normal", "-min normal", "+normal", "-normal"]
        );
        assert_eq!(
            [b(0x7bff), b(0xfbff), b(0x7c00), b(0xfc00), b(0x7e00), b(0xfe00), b(0x7c01), b(0x7e01)],
            ["+max finite", "-max finite", "+inf", "-inf", "canonical NaN", "canonical NaN", "other NaN", "other NaN"]
        );
        let q = |v| FIXED_BINS[fixed_bin(v, 16)];
        assert_eq!(
            [q(0), q(1), q(0xffff), q(0x7fff), q(0x8000), q(0x0100), q(0xff00)],
            ["0", "+1 step", "-1 step", "+max", "min", "positive", "negative"]
        );
    }
}
