//! Vector generation for every unit: the request, the coverage classes crossed per level, and
//! the set (files, manifest) built in memory; the cases of each unit are in `rti`, `slab` and
//! `op` (capture and traverse: `crate::capture`, `crate::traverse`). Writing is
//! [`crate::write`], reading back and re-checking [`crate::read`] and [`crate::check`].
//!
//! Every vector carries a coverage-class id. Level 1 covers each named class with `count`
//! vectors (TestFloat's level 1: each class on its own). Inputs are always produced through the
//! format's own input conversion, so re-reading them reproduces the same bits.

pub mod op;
pub mod rti;
pub mod slab;
pub mod slab_rays;

pub use op::*;
pub use rti::*;
pub use slab::*;

use crate::manifest::{self, Class, Field, Kind, Manifest, Stage};
use crate::rows::{is_float, kind_of, per_class_rows, push_rows, slab_options, Layout, Rows};
use datapath::fault::NoFault;
use datapath::format::FormatKind;
use datapath::probe::{Recorder, Signal};
use datapath::rng::SplitMix64;
use datapath::rti::{stage_count, stage_table, Op, Rti, RtiConfig, RTI_INPUTS};
use datapath::slab::{Slab, SlabConfig, SLAB_TABLE};
use datapath::{with_format, AnyFormat, Format};
use std::collections::BTreeMap;
use std::str::FromStr;

/// The unit a vector set exercises.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Unit {
    /// Ray–triangle pipeline.
    Rti,
    /// Ray–box pipeline.
    Slab,
    /// Single operations.
    Op,
    /// BVH traversal (2-bit ray history) with the slab unit as box tester.
    Traverse,
    /// The min-capture unit over one leaf of RTI results.
    Capture,
}

impl FromStr for Unit {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "rti" => Ok(Unit::Rti),
            "slab" => Ok(Unit::Slab),
            "op" => Ok(Unit::Op),
            "traverse" => Ok(Unit::Traverse),
            "capture" => Ok(Unit::Capture),
            other => Err(format!("unknown unit '{other}' (units: rti, slab, op, traverse, capture)")),
        }
    }
}

impl Unit {
    fn name(self) -> &'static str {
        match self {
            Unit::Rti => "rti",
            Unit::Slab => "slab",
            Unit::Op => "op",
            Unit::Traverse => "traverse",
            Unit::Capture => "capture",
        }
    }
}

/// What to generate.
#[derive(Clone, Debug)]
pub struct Request {
    /// Unit.
    pub unit: Unit,
    /// Number format.
    pub format: AnyFormat,
    /// Vectors per coverage class.
    pub count: usize,
    /// Seed.
    pub seed: u64,
    /// Coverage level: 1 (each class on its own) or 2 (level 1 plus crossed classes).
    pub level: u32,
    /// Worker threads (the output does not depend on it).
    pub threads: usize,
    /// The command line, recorded in the manifest.
    pub command: String,
    /// RTI options.
    pub rti: RtiConfig,
    /// Slab variant name (units slab and traverse).
    pub slab_variant: String,
    /// The BVH (unit traverse).
    pub tree: Option<crate::traverse::TreeInput>,
    /// First N leaves per ray (unit traverse).
    pub leaves: usize,
    /// Level pipelines the hardware has (unit traverse).
    pub max_levels: usize,
    /// Input rows given instead of drawn from the seed (unit slab): a proof's counterexamples.
    pub explicit: Option<Explicit>,
    /// Input rows appended as one more class after the seeded classes (units rti, slab, op,
    /// capture): the coverage closure's directed vectors (`crate::close`).
    pub closure: Option<Explicit>,
}

impl Request {
    /// A level-1 request of `unit` in `format`: one vector per class, seed 1, one thread, the
    /// default RTI options and slab variant `plain`, no tree, 8 leaves, 64 level pipelines, no
    /// given rows (set the fields that differ).
    pub fn new(unit: Unit, format: AnyFormat) -> Self {
        Request {
            unit,
            format,
            count: 1,
            seed: 1,
            level: 1,
            threads: 1,
            command: String::new(),
            rti: RtiConfig::default(),
            slab_variant: "plain".into(),
            tree: None,
            leaves: 8,
            max_levels: 64,
            explicit: None,
            closure: None,
        }
    }
}

/// A set's input rows given by their writer (e.g. `raypipe prove --out`), one class.
#[derive(Clone, Debug, PartialEq)]
pub struct Explicit {
    /// The class name (e.g. `smt`).
    pub class: String,
    /// What the class covers, in words.
    pub covers: String,
    /// What wrote the rows (the manifest's `origin`).
    pub origin: String,
    /// Input rows: the unit's input encodings in its input order (slab: `SLAB_INPUTS`).
    pub rows: Vec<Vec<u64>>,
}

/// A generated set: the manifest (hashes filled on writing) and the file contents.
#[derive(Clone, Debug)]
pub struct VectorSet {
    /// Manifest.
    pub manifest: Manifest,
    /// (file name, contents).
    pub files: Vec<(String, String)>,
}

/// A format's contract as the manifest's `contract` object: clause name → its words.
pub fn contract_map<F: Format>(f: &F) -> BTreeMap<String, String> {
    let c = f.contract();
    [
        ("encoding", c.encoding),
        ("rounding", c.rounding),
        ("subnormals", c.subnormals),
        ("nan", c.nan),
        ("overflow", c.overflow),
        ("division", c.division),
        ("compare", c.compare),
    ]
    .into_iter()
    .map(|(k, v)| (k.to_string(), v))
    .collect()
}

/// Special input values injected into a case.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Special {
    Subnormal,
    InfNan,
}

pub(crate) fn specials_for<F: Format>(f: &F) -> Vec<u64> {
    match f.kind() {
        FormatKind::Float(l) => {
            let top = (1u64 << l.exp_bits) - 1;
            let bias = l.bias() as u64;
            let mm = l.man_mask();
            let mut v = Vec::new();
            for e in [0, 1, bias - 1, bias, bias + 1, top - 1, top] {
                for fr in [0, 1, mm >> 1, mm, 1 << (l.man_bits - 1)] {
                    for s in [0, l.sign_mask()] {
                        v.push(s | (e << l.man_bits) | (fr & mm));
                    }
                }
            }
            v.sort_unstable();
            v.dedup();
            v
        }
        FormatKind::Fixed { .. } => {
            let vals = [0.0, 1.0, -1.0, 0.5, -0.5, f64::INFINITY, f64::NEG_INFINITY];
            let mut v: Vec<u64> = vals.iter().map(|&x| f.to_bits(f.from_f64(x))).collect();
            v.extend([1, u64::MAX].map(|raw| f.to_bits(f.from_bits(raw)))); // one step, minus one step
            v.sort_unstable();
            v.dedup();
            v
        }
    }
}

/// Generates a vector set.
pub fn generate(req: &Request) -> Result<VectorSet, String> {
    if req.count == 0 {
        return Err("--count must be at least 1".into());
    }
    if !(1..=2).contains(&req.level) {
        return Err(format!(
            "coverage level {} does not exist (1: each class on its own, 2: classes crossed)",
            req.level
        ));
    }
    with_format!(req.format, |f| generate_in(f, req))
}

pub(crate) fn generate_in<F: Format>(f: F, req: &Request) -> Result<VectorSet, String> {
    if req.explicit.is_some() && req.unit != Unit::Slab {
        return Err("given input rows are supported for the slab unit only".into());
    }
    if req.closure.is_some() && req.explicit.is_some() {
        return Err("a set of given rows has no closure class".into());
    }
    let w = f.width();
    let k = kind_of(&f);
    let mut r = SplitMix64::new(req.seed);
    let mut options = BTreeMap::new();
    let mut params = format_params(&f);
    let (mut classes, latency, stages): (Vec<(String, String)>, u32, Vec<Stage>);
    let pool = rayon::ThreadPoolBuilder::new().num_threads(req.threads.max(1)).build().map_err(|e| e.to_string())?;
    let unit = req.unit.name();
    let mut files: Vec<Rows> = Vec::new();
    let mut counts: Vec<usize>;
    let inputs_layout = |names: &[&str], extra: Vec<(String, &'static str, Kind, u32, Option<u8>)>| {
        let mut l = vec![("class".to_string(), "in", Kind::Uint, 8, None)];
        l.extend(extra);
        l.extend(names.iter().map(|n| (n.to_string(), "in", k.clone(), w, None)));
        Layout(l)
    };
    match req.unit {
        Unit::Rti => {
            let rti = Rti::new(f, req.rti);
            options.insert("cull".into(), format!("{:?}", req.rti.cull));
            options.insert("input_read".into(), crate::rows::input_read(&f));
            options.insert(
                "det_threshold".into(),
                format!("{:?} (as the format rounds it: {})", req.rti.det_threshold, f.hex(rti.det_thr)),
            );
            options.insert("tie".into(), format!("{:?}", req.rti.tie));
            params.insert("cull_backface".into(), (req.rti.cull == datapath::rti::Cull::Backface) as u64);
            params.insert("det_thr".into(), f.to_bits(rti.det_thr));
            params.insert("tie_last".into(), (req.rti.tie == datapath::rti::TieRule::Last) as u64);
            let table = stage_table(f.div_mode());
            let crosses = rti_crosses(req.level);
            classes = crosses.iter().map(|c| c.describe()).collect();
            latency = stage_count(f.div_mode()) as u32;
            stages = table
                .iter()
                .map(|d| Stage { stage: d.stage, name: d.name.into(), op: op_text(d.op, d.a, d.b, d.note) })
                .collect();
            let out = Layout(vec![
                ("valid".into(), "out", Kind::Flag, 1, Some(7)),
                ("hit".into(), "out", Kind::Flag, 1, Some(table.last().unwrap().stage)),
                ("t".into(), "out", k.clone(), w, Some(table.iter().find(|d| d.name == "t").unwrap().stage)),
                ("u".into(), "out", k.clone(), w, Some(table.iter().find(|d| d.name == "u").unwrap().stage)),
                ("v".into(), "out", k.clone(), w, Some(table.iter().find(|d| d.name == "v").unwrap().stage)),
            ]);
            let st = Layout(
                table
                    .iter()
                    .map(|d| {
                        if d.op == Op::Logic {
                            (d.name.to_string(), "out", Kind::Flag, 1, Some(d.stage))
                        } else {
                            (d.name.to_string(), "out", k.clone(), w, Some(d.stage))
                        }
                    })
                    .collect(),
            );
            files.push(Rows {
                name: "rti_inputs.hex".into(),
                role: "inputs".into(),
                layout: inputs_layout(&RTI_INPUTS, vec![]),
                lines: vec![],
            });
            files.push(Rows {
                name: "rti_expected.hex".into(),
                role: "expected outputs".into(),
                layout: out,
                lines: vec![],
            });
            files.push(Rows {
                name: "rti_stages.hex".into(),
                role: crate::hdl::STAGE_ROLE.into(),
                layout: st,
                lines: vec![],
            });
            let float = is_float(&f);
            let per_class = pool.install(|| {
                per_class_rows(req.seed, crosses.len(), req.count, |c, r| {
                    let cross = crosses[c];
                    if cross.special.is_some() && !float {
                        return Ok(None);
                    }
                    let mut x = rti_case(cross, r);
                    match (cross.geom, f.kind()) {
                        (14, FormatKind::Float(l)) => {
                            // draws until the model finds the ray valid (at most 64): the tie
                            // must reach t, u, v, which a testbench compares only when valid
                            for _ in 0..64 {
                                let p = l.man_bits as i32 + 1;
                                let a = (p + 1) / 2;
                                let bd = (p + 2 - a) / 2;
                                let be = p + 2 - a - bd;
                                // ± an odd integer of n bits, over 2^n
                                let mut odd = |n: i32| {
                                    let v = ((1u64 << (n - 1)) + r.below(1u64 << (n - 1))) | 1;
                                    let s = if r.below(2) == 0 { 1.0 } else { -1.0 };
                                    s * v as f64 / (n as f64).exp2()
                                };
                                let (o, e1) = ([odd(a), odd(a), odd(a)], [odd(a), odd(a), odd(a)]);
                                let (dx, dy, e2x, e2z) = (odd(bd), odd(bd), odd(be), odd(be));
                                x = [
                                    o[0],
                                    o[1],
                                    o[2],
                                    dx,
                                    dy,
                                    0.0,
                                    0.0,
                                    f64::INFINITY,
                                    0.0,
                                    0.0,
                                    0.0,
                                    e1[0],
                                    e1[1],
                                    e1[2],
                                    e2x,
                                    0.0,
                                    e2z,
                                ];
                                let (ray, tri) = rti_inputs(&f, &x);
                                if rti.test(&ray, &tri).valid {
                                    break;
                                }
                            }
                        }
                        (15 | 16, FormatKind::Float(l)) => {
                            let (lv, dv) = if cross.geom == 15 {
                                (((l.emin() - 1).div_euclid(2) as f64).exp2(), 1.0)
                            } else {
                                let lv = ((-(-l.emin()).div_euclid(3) + 1) as f64).exp2();
                                (lv, lv * ((2 - l.emin()) as f64).exp2())
                            };
                            for (i, xi) in x.iter_mut().enumerate() {
                                if (3..6).contains(&i) {
                                    *xi *= dv;
                                } else if i != 6 && i != 7 {
                                    *xi *= lv;
                                }
                            }
                        }
                        (15 | 16, _) => return Ok(None),
                        _ => {}
                    }
                    // t_at_limits: placements until the model finds one valid with a number t
                    // (at most 16)
                    for _ in 0..16 * (cross.geom == 12) as usize {
                        let (ray, tri) = rti_inputs(&f, &x);
                        let o = rti.test(&ray, &tri);
                        if o.valid && !f.is_nan(o.t) {
                            break;
                        }
                        x = rti_case(cross, r);
                    }
                    // subnormal inputs as raw encodings (also in FTZ formats, whose reads flush
                    // them: a DUT without the input flush fails)
                    let mut raw: Vec<(usize, u64)> = Vec::new();
                    if let Some(sp) = cross.special {
                        for _ in 0..1 + r.below(3) {
                            let i = r.below(17) as usize;
                            // a later draw at the same input replaces an earlier one
                            raw.retain(|&(j, _)| j != i);
                            x[i] = if sp == Special::Subnormal {
                                let k = 1 + r.below(3);
                                let sub = f.to_f64(f.from_bits(k));
                                let neg = r.below(2) != 0;
                                if let FormatKind::Float(l) = f.kind() {
                                    raw.push((i, if neg { l.sign_mask() | k } else { k }));
                                }
                                if neg {
                                    -sub
                                } else {
                                    sub
                                }
                            } else {
                                [f64::INFINITY, f64::NEG_INFINITY, f64::NAN][r.below(3) as usize]
                            };
                        }
                    }
                    let mut bits: Vec<u64> = x.iter().map(|&v| f.to_bits(f.from_f64(v))).collect();
                    for (i, b) in raw {
                        bits[i] = b;
                    }
                    any_nans(&f, r, &x, &mut bits);
                    if cross.geom == 12 {
                        let (ray, tri) = rti_inputs(&f, &x);
                        let o = rti.test(&ray, &tri);
                        if o.valid && !f.is_nan(o.t) {
                            match r.below(2) {
                                0 => bits[7] = f.to_bits(o.t),
                                _ => bits[6] = f.to_bits(f.next_up(o.t)),
                            }
                        }
                    }
                    Ok(Some(rti_rows(&rti, c as u64, &bits).to_vec()))
                })
            })?;
            let per_class = append_closure(req, &mut classes, per_class, RTI_INPUTS.len(), |c, bits| {
                let bits: Vec<u64> = bits.iter().map(|&b| f.to_bits(f.from_bits(b))).collect();
                rti_rows(&rti, c, &bits).to_vec()
            })?;
            counts = push_rows(&mut files, per_class);
        }
        Unit::Slab => {
            let sc = SlabConfig::named_for(&req.slab_variant, &f)?;
            if sc.directed {
                return Err("the directed slab variant has a data-dependent signal set; vectors support plain, conservative, take-on-false and embree".into());
            }
            let slab = Slab::new(f, sc);
            options.insert("variant".into(), req.slab_variant.clone());
            slab_options(&mut options, &sc);
            options.insert("input_read".into(), crate::rows::input_read(&f));
            params.insert("slab_guard".into(), sc.guard as u64);
            params.insert("slab_take_on_false".into(), (sc.nan == datapath::slab::SlabNan::TakeOnFalse) as u64);
            params.insert("slab_embree".into(), (sc.prep == datapath::slab::DirPrep::Embree) as u64);
            params.insert("slab_delta".into(), f.to_bits(slab.delta()));
            params.insert(
                "slab_widen_ulps".into(),
                u64::try_from(sc.widen_ulps).map_err(|_| "vectors support only non-negative widening")?,
            );
            let crosses = slab_crosses(req.level);
            classes = match &req.explicit {
                Some(ex) => vec![(ex.class.clone(), ex.covers.clone())],
                None => crosses.iter().map(|c| c.describe()).collect(),
            };
            latency = 7;
            stages = SLAB_TABLE
                .iter()
                .map(|d| Stage { stage: d.stage, name: d.name.into(), op: op_text(d.op, d.a, d.b, d.note) })
                .collect();
            let names = datapath::slab::SLAB_INPUTS;
            let out = Layout(vec![
                ("hit".into(), "out", Kind::Flag, 1, Some(6)),
                ("t_near".into(), "out", k.clone(), w, Some(5)),
                ("t_far".into(), "out", k.clone(), w, Some(5)),
            ]);
            let st = Layout(
                SLAB_TABLE
                    .iter()
                    .map(|d| {
                        let flag = matches!(d.name, "negx" | "negy" | "negz" | "hit");
                        if flag {
                            (d.name.to_string(), "out", Kind::Flag, 1, Some(d.stage))
                        } else {
                            (d.name.to_string(), "out", k.clone(), w, Some(d.stage))
                        }
                    })
                    .collect(),
            );
            files.push(Rows {
                name: "slab_inputs.hex".into(),
                role: "inputs (box already stored outward-rounded)".into(),
                layout: inputs_layout(&names, vec![]),
                lines: vec![],
            });
            files.push(Rows {
                name: "slab_expected.hex".into(),
                role: "expected outputs".into(),
                layout: out,
                lines: vec![],
            });
            files.push(Rows {
                name: "slab_stages.hex".into(),
                role: crate::hdl::STAGE_ROLE.into(),
                layout: st,
                lines: vec![],
            });
            let float = is_float(&f);
            if let Some(ex) = &req.explicit {
                let mut rows = Vec::new();
                for bits in &ex.rows {
                    if bits.len() != names.len() {
                        return Err(format!("a slab input row has {} fields, not {}", bits.len(), names.len()));
                    }
                    let bits: Vec<u64> = bits.iter().map(|&b| f.to_bits(f.from_bits(b))).collect();
                    rows.push(slab_rows(&slab, 0, &bits).to_vec());
                }
                counts = push_rows(&mut files, vec![rows]);
            } else {
                let per_class = pool.install(|| {
                    per_class_rows(req.seed, crosses.len(), req.count, |c, r| {
                        let cross = crosses[c];
                        if cross.special && !float {
                            return Ok(None);
                        }
                        let case_bits = |r: &mut SplitMix64| -> Result<Vec<u64>, String> {
                            let x = slab_case(cross, r, datapath::format::edges(&f));
                            let b = slab
                                .store_box([x[8], x[9], x[10]], [x[11], x[12], x[13]])
                                .map_err(|e| e.to_string())?;
                            let mut bits: Vec<u64> = x[..8].iter().map(|&v| f.to_bits(f.from_f64(v))).collect();
                            bits.extend(b.min.iter().chain(b.max.iter()).map(|&v| f.to_bits(v)));
                            any_nans(&f, r, &x[..8], &mut bits);
                            // an origin placed on a face plane stays on it once the box is stored
                            // (outward-rounded)
                            for a in 0..3 {
                                if x[a] == x[8 + a] {
                                    bits[a] = bits[8 + a];
                                } else if x[a] == x[11 + a] {
                                    bits[a] = bits[11 + a];
                                }
                            }
                            Ok(bits)
                        };
                        let mut bits = case_bits(r)?;
                        match cross.ray {
                            // t_at_limits: placements until the model finds a hit with number limits
                            // (at most 16)
                            8 => {
                                for _ in 0..16 {
                                    if let Some(b) = slab_at_limits(&slab, &bits, r) {
                                        bits = b;
                                        break;
                                    }
                                    bits = case_bits(r)?;
                                }
                            }
                            9 | 10 if !float => return Ok(None),
                            9 => slab_ties(&f, r, &mut bits),
                            10 => slab_subnormal_gap(&f, r, &mut bits),
                            _ => {}
                        }
                        Ok(Some(slab_rows(&slab, c as u64, &bits).to_vec()))
                    })
                })?;
                let per_class = append_closure(req, &mut classes, per_class, names.len(), |c, bits| {
                    let bits: Vec<u64> = bits.iter().map(|&b| f.to_bits(f.from_bits(b))).collect();
                    slab_rows(&slab, c, &bits).to_vec()
                })?;
                counts = push_rows(&mut files, per_class);
            }
        }
        Unit::Capture => {
            let rti = Rti::new(f, RtiConfig { tie: req.rti.tie, ..RtiConfig::default() });
            options.insert("tie".into(), format!("{:?}", req.rti.tie));
            params.insert("tie_last".into(), (req.rti.tie == datapath::rti::TieRule::Last) as u64);
            params.insert("slots".into(), crate::capture::SLOTS as u64);
            classes = crate::capture::CLASSES.iter().map(|(n, c)| (n.to_string(), c.to_string())).collect();
            latency = crate::capture::SLOTS as u32;
            stages =
                crate::capture::stage_table().into_iter().map(|(stage, name, op)| Stage { stage, name, op }).collect();
            files.push(Rows::new("capture_inputs.hex", "inputs", crate::capture::input_layout(&k, w)));
            files.push(Rows::new("capture_expected.hex", "expected outputs", crate::capture::output_layout(&k, w)));
            files.push(Rows::new("capture_stages.hex", crate::hdl::STAGE_ROLE, crate::capture::stage_layout(&k, w)));
            let per_class = pool.install(|| {
                per_class_rows(req.seed, classes.len(), req.count, |c, r| {
                    let bits = crate::capture::case(&f, c, r);
                    let [expected, stages] = crate::capture::out_rows(&rti, &bits, &NoFault);
                    let mut inputs = vec![c as u64];
                    inputs.extend(bits);
                    Ok(Some(vec![inputs, expected, stages]))
                })
            })?;
            let n_in = crate::capture::input_layout(&k, w).0.len() - 1;
            let per_class = append_closure(req, &mut classes, per_class, n_in, |c, bits| {
                let [expected, stages] = crate::capture::out_rows(&rti, bits, &NoFault);
                let mut inputs = vec![c];
                inputs.extend_from_slice(bits);
                vec![inputs, expected, stages]
            })?;
            counts = push_rows(&mut files, per_class);
        }
        Unit::Op => {
            classes = OP_CLASSES[..if req.level >= 2 { 4 } else { 3 }]
                .iter()
                .map(|(n, c)| (n.to_string(), c.to_string()))
                .collect();
            latency = 1;
            stages = OPCODES
                .iter()
                .enumerate()
                .map(|(i, o)| Stage { stage: 1, name: format!("opcode {i}"), op: o.to_string() })
                .collect();
            options.insert(
                "opcodes".into(),
                OPCODES.iter().enumerate().map(|(i, o)| format!("{i}={o}")).collect::<Vec<_>>().join(", "),
            );
            let inl = Layout(vec![
                ("class".into(), "in", Kind::Uint, 8, None),
                ("opcode".into(), "in", Kind::Uint, 4, None),
                ("a".into(), "in", k.clone(), w, None),
                ("b".into(), "in", k.clone(), w, None),
            ]);
            let out = Layout(vec![
                ("result".into(), "out", k.clone(), w, Some(1)),
                ("cmp".into(), "out", Kind::Flag, 1, Some(1)),
            ]);
            files.push(Rows { name: "op_inputs.hex".into(), role: "inputs".into(), layout: inl, lines: vec![] });
            files.push(Rows {
                name: "op_expected.hex".into(),
                role: "expected outputs (result is 0 for compares, cmp is 0 for arithmetic)".into(),
                layout: out,
                lines: vec![],
            });
            counts = vec![0; classes.len()];
            let sp = specials_for(&f);
            let mask = if w >= 64 { u64::MAX } else { (1u64 << w) - 1 };
            let mut pairs: Vec<(u64, u64, u64)> = Vec::new();
            for op in 0..OPCODES.len() as u64 {
                for &a in &sp {
                    for &b in &sp {
                        pairs.push((0, a, b | (op << 60)));
                    }
                }
                for _ in 0..req.count {
                    pairs.push((1, r.next_u64() & mask, (r.next_u64() & mask) | (op << 60)));
                }
                if op <= 2 {
                    for (a, b) in op_ties(&f, op, req.count, &mut r) {
                        pairs.push((2, a, b | (op << 60)));
                    }
                }
                if req.level >= 2 {
                    for &s in &sp {
                        for _ in 0..req.count.div_ceil(8) {
                            pairs.push((3, s, (r.next_u64() & mask) | (op << 60)));
                            pairs.push((3, r.next_u64() & mask, s | (op << 60)));
                        }
                    }
                }
            }
            if let Some(cl) = &req.closure {
                let c = classes.len() as u64;
                classes.push((cl.class.clone(), cl.covers.clone()));
                counts.push(0);
                for row in &cl.rows {
                    let [op, a, b] = row[..] else {
                        return Err(format!("an op input row has {} fields, not 3 (opcode, a, b)", row.len()));
                    };
                    if op >= OPCODES.len() as u64 {
                        return Err(format!("opcode {op} does not exist"));
                    }
                    pairs.push((c, a & mask, (b & mask) | (op << 60)));
                }
            }
            for (c, a, bop) in pairs {
                let (op, b) = (bop >> 60, bop & ((1u64 << 60) - 1) & mask);
                let (x, y) = (f.from_bits(a), f.from_bits(b));
                let (res, cmp) = op_eval(&f, op, x, y);
                files[0].push(&[c, op, a, b]);
                files[1].push(&[res, cmp]);
                counts[c as usize] += 1;
            }
        }
        Unit::Traverse => {
            let tree = req.tree.as_ref().ok_or("unit traverse needs a scene's BVH")?;
            classes = crate::traverse::classes(req.level);
            latency = 0;
            stages = Vec::new();
            let parts = pool.install(|| {
                crate::traverse::generate(
                    f,
                    &req.slab_variant,
                    tree,
                    req.leaves,
                    req.max_levels,
                    req.count,
                    req.seed,
                    req.level,
                    inputs_layout(&crate::traverse::RAY_INPUTS, vec![]),
                    req.closure.as_ref(),
                )
            })?;
            if let Some(cl) = &req.closure {
                classes.push((cl.class.clone(), cl.covers.clone()));
            }
            files = parts.files;
            counts = parts.counts;
            params.extend(parts.params);
            options.extend(parts.options);
        }
    }
    let manifest = Manifest {
        schema: manifest::SCHEMA,
        raypipe_version: env!("CARGO_PKG_VERSION").into(),
        git: git_hash(),
        command: req.command.clone(),
        seed: req.seed,
        count: req.count,
        unit: unit.into(),
        level: req.level,
        format: f.name(),
        contract: contract_map(&f),
        options,
        params,
        latency,
        stages,
        acceptable_values: ACCEPTABLE.into(),
        files: files
            .iter()
            .map(|fr| {
                let mut fields = fr.layout.fields();
                acceptance(req.unit, &fr.role, &mut fields);
                let width: u32 = fields.iter().map(|x| x.width).sum();
                manifest::File {
                    name: fr.name.clone(),
                    role: fr.role.clone(),
                    rows: fr.lines.len(),
                    width,
                    digits: width.div_ceil(4),
                    fields,
                    sha256: String::new(),
                }
            })
            .collect(),
        classes: classes
            .iter()
            .enumerate()
            .map(|(i, (n, c))| Class { id: i as u32, name: n.clone(), covers: c.clone(), count: counts[i] })
            .collect(),
        minimal: None,
        origin: req.explicit.as_ref().map(|e| e.origin.clone()),
        closure: req
            .closure
            .as_ref()
            .map(|cl| manifest::Closure { class: classes.len() as u32 - 1, origin: cl.origin.clone() }),
    };
    Ok(VectorSet { manifest, files: files.into_iter().map(|fr| (fr.name, fr.lines.join("\n") + "\n")).collect() })
}

/// `per_class` with the request's closure rows appended as one more class (named in
/// `classes`); `rows(class, input bits)` builds a row's files. Unchanged without a closure.
fn append_closure(
    req: &Request,
    classes: &mut Vec<(String, String)>,
    mut per_class: Vec<crate::rows::ClassRows>,
    inputs: usize,
    rows: impl Fn(u64, &[u64]) -> Vec<Vec<u64>>,
) -> Result<Vec<crate::rows::ClassRows>, String> {
    let Some(cl) = &req.closure else { return Ok(per_class) };
    if req.explicit.is_some() {
        return Err("a set of given rows has no closure class".into());
    }
    let c = classes.len() as u64;
    classes.push((cl.class.clone(), cl.covers.clone()));
    let mut out = Vec::with_capacity(cl.rows.len());
    for bits in &cl.rows {
        if bits.len() != inputs {
            return Err(format!("a closure input row has {} fields, not {inputs}", bits.len()));
        }
        out.push(rows(c, bits));
    }
    per_class.push(out);
    Ok(per_class)
}

/// What the manifest says of acceptable values.
pub const ACCEPTABLE: &str = "exact: every operation is correctly rounded per the contract, so each output field has exactly one acceptable value; a field with care_when F is compared only when the 1-bit field F of the expected output row is 1 (any value is acceptable otherwise); a field marked implementation_defined depends on how the DUT is built and is compared only on request (+strict in the kit's testbenches)";

/// The per-field acceptance rules: rti `t`, `u`, `v` and every stage signal after the valid
/// bit's stage (the divide and what depends on it, `hit` excepted) are don't-care when
/// `valid = 0` (a DUT may skip the divide); traverse `passes` and `box_tests` count work the way
/// the model's traversal does it (one pass per walk from the root, the root box once and two
/// boxes per level visited) and are implementation-defined.
pub(crate) fn acceptance(unit: Unit, role: &str, fields: &mut [Field]) {
    let output = role == "expected outputs" || role.starts_with("expected results");
    match unit {
        Unit::Rti => {
            for f in fields.iter_mut().filter(|f| f.dir == "out") {
                let after_valid = f.stage.is_some_and(|s| s > 7) && f.name != "hit";
                let outputs_tuv = output && ["t", "u", "v"].contains(&f.name.as_str());
                if outputs_tuv || (role == crate::hdl::STAGE_ROLE && after_valid) {
                    f.care_when = Some("valid".into());
                }
            }
        }
        Unit::Traverse => {
            for f in fields.iter_mut().filter(|f| f.name == "passes" || f.name == "box_tests") {
                f.implementation_defined = true;
            }
        }
        _ => {}
    }
}

/// The format's contract as integers.
pub(crate) fn format_params<F: Format>(f: &F) -> BTreeMap<String, u64> {
    let mut p = BTreeMap::new();
    match f.kind() {
        FormatKind::Float(l) => {
            p.insert("float".into(), 1);
            p.insert("exp".into(), l.exp_bits as u64);
            p.insert("man".into(), l.man_bits as u64);
        }
        FormatKind::Fixed { int_bits, frac_bits } => {
            p.insert("float".into(), 0);
            p.insert("fx_int".into(), int_bits as u64);
            p.insert("fx_frac".into(), frac_bits as u64);
        }
    }
    p.insert("width".into(), f.width() as u64);
    p.insert("ftz".into(), f.flushes() as u64);
    p.insert("nan_propagate".into(), f.nan_propagates() as u64);
    p.insert("recip_mul".into(), (f.div_mode() == datapath::format::DivMode::RecipMul) as u64);
    p
}

pub(crate) fn signals<F: Format>(f: &F, rec: &Recorder<F::V>) -> Vec<u64> {
    rec.signals
        .iter()
        .map(|(_, s)| match s {
            Signal::Value(x) => f.to_bits(*x),
            Signal::Flag(b) => *b as u64,
        })
        .collect()
}

/// Every NaN the f64 case holds becomes a random NaN encoding of the float format (either
/// sign, quiet or signaling, a random nonzero payload), so the sets exercise NaN sign and
/// payload paths; fixed-point formats have no NaN (their cases hold none).
pub(crate) fn any_nans<F: Format>(f: &F, r: &mut SplitMix64, x: &[f64], bits: &mut [u64]) {
    let FormatKind::Float(l) = f.kind() else { return };
    for (b, v) in bits.iter_mut().zip(x) {
        if v.is_nan() {
            let payload = (r.next_u64() & l.man_mask()).max(1);
            let sign = if r.below(2) == 0 { 0 } else { l.sign_mask() };
            *b = sign | (((1u64 << l.exp_bits) - 1) << l.man_bits) | payload;
        }
    }
}

pub(crate) fn git_hash() -> String {
    std::process::Command::new("git")
        .args(["rev-parse", "HEAD"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .unwrap_or_else(|| "unknown".into())
}
