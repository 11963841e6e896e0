//! Vector generation, atomic writing and the read-back check, for the `rti`, `slab` and `op` units.
//!
//! Every vector carries a coverage-class id. Level 1 covers each named class with `count`
//! vectors (TestFloat's level 1: each class on its own). Inputs are always produced through the
//! format's own input conversion, so re-reading them reproduces the same bits.

use crate::manifest::{self, Class, Field, Kind, Manifest, Stage};
use crate::pack::unpack;
use crate::rows::{is_float, kind_of, per_class_rows, push_rows, slab_options, Layout, Rows};
use datapath::fault::{Fault, NoFault};
use datapath::format::FormatKind;
use datapath::probe::{Recorder, Signal};
use datapath::rng::SplitMix64;
use datapath::rti::{stage_count, stage_table, Op, Ray, Rti, RtiConfig, Tri, RTI_INPUTS};
use datapath::slab::{Aabb, Slab, SlabConfig, SLAB_TABLE};
use datapath::{with_format, AnyFormat, Format};
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
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

/// Geometric RTI classes (level 1 ids 0-5, 8 and 12-16): how the triangle and ray are placed.
const RTI_GEOMETRY: [(usize, &str, &str); 12] = [
    (0, "random", "ray aimed at a random barycentric point in [-0.3, 1.3]^2 of a random triangle in [-1, 1]^3"),
    (1, "edge", "aimed exactly at a point of an edge (one barycentric 0)"),
    (2, "vertex", "aimed exactly at a vertex"),
    (3, "near_parallel", "direction within ~1e-3 of the triangle's plane (|det| -> 0)"),
    (4, "degenerate", "collinear vertices (zero area)"),
    (5, "needle", "long triangle 1e-3 wide"),
    (8, "t_near_zero", "origin on the triangle's plane (t = 0)"),
    (
        12,
        "t_at_limits",
        "a random placement the model finds valid with a number t, then the t interval ending on that t: tmax = t (a hit only if the compare is t <= tmax), or tmin = the next value above t (a miss only if the tmin compare is made)",
    ),
    (13, "point_triangle", "all three vertices at one point: det, u', v' and t' are zero, so only the det check rejects it"),
    (
        14,
        "ties",
        "v0 = 0, e2.y = 0 and d.z = 0, so p.x = d.y * e2.z and p.y = -d.x * e2.z are exact; e1, o (so s), and e2.x, e2.z, d.x, d.y odd integers of a, be and bd bits scaled by powers of two (a = floor((p + 1) / 2), bd = floor((p + 2 - a) / 2), be = p + 2 - a - bd for a float of p significant bits): detx = e1.x * p.x and upy = s.y * p.y span p or p + 1 bits and, at p + 1, fall exactly halfway between two values (round-half-even vs half-away)",
    ),
    (
        15,
        "tiny_products",
        "a random placement with the origin and vertices scaled by 2^floor((emin - 1) / 2) (floats only): stage-2 and stage-3 results fall into the subnormal range",
    ),
    (
        16,
        "t_subnormal",
        "a random placement with the origin and vertices scaled by L = 2^(ceil(emin / 3) + 1) and the direction by L * 2^(2 - emin) (floats only): t near 2^(emin - 2), a subnormal, with det, u' and t' normal",
    ),
];

/// Value modifiers of the RTI classes (level 1 ids 6, 7, 9, 10, 11), applied after placement.
const RTI_MODIFIERS: [(usize, &str, &str); 5] = [
    (6, "huge", "coordinates scaled by 2^12"),
    (7, "tiny", "coordinates scaled by 2^-12"),
    (9, "signed_zero", "some coordinates +0 or -0"),
    (10, "subnormal", "some inputs the format's smallest subnormals, written as raw encodings also in FTZ formats (floats only)"),
    (11, "inf_nan", "some inputs +inf, -inf or NaN (floats only; a NaN is a random NaN encoding: either sign, quiet or signaling, random payload)"),
];

/// Special input values injected into a case.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Special {
    Subnormal,
    InfNan,
}

/// One RTI coverage class: a placement plus at most one modifier.
#[derive(Clone, Copy, Debug)]
struct RtiCross {
    geom: usize,
    scale: f64,
    signed_zero: bool,
    special: Option<Special>,
    /// Index into RTI_GEOMETRY and RTI_MODIFIERS (None: plain placement).
    names: (usize, Option<usize>),
}

impl RtiCross {
    fn describe(&self) -> (String, String) {
        let (g, m) = self.names;
        match (g, m) {
            (0, Some(m)) => (RTI_MODIFIERS[m].1.into(), RTI_MODIFIERS[m].2.into()),
            (g, None) => (RTI_GEOMETRY[g].1.into(), RTI_GEOMETRY[g].2.into()),
            (g, Some(m)) => (
                format!("{}+{}", RTI_GEOMETRY[g].1, RTI_MODIFIERS[m].1),
                format!("{}; and {}", RTI_GEOMETRY[g].2, RTI_MODIFIERS[m].2),
            ),
        }
    }
}

/// The RTI classes of a level, in class-id order: level 1 as the seventeen named classes (ids
/// 0-16), level 2 adds every placement other than random crossed with every modifier.
fn rti_crosses(level: u32) -> Vec<RtiCross> {
    let cross = |g: usize, m: Option<usize>| {
        let id = m.map(|m| RTI_MODIFIERS[m].0);
        RtiCross {
            geom: RTI_GEOMETRY[g].0,
            scale: match id {
                Some(6) => 4096.0,
                Some(7) => 1.0 / 4096.0,
                _ => 1.0,
            },
            signed_zero: id == Some(9),
            special: match id {
                Some(10) => Some(Special::Subnormal),
                Some(11) => Some(Special::InfNan),
                _ => None,
            },
            names: (g, m),
        }
    };
    let mut v: Vec<RtiCross> = (0..17)
        .map(|id| match RTI_GEOMETRY.iter().position(|g| g.0 == id) {
            Some(g) => cross(g, None),
            None => cross(0, RTI_MODIFIERS.iter().position(|m| m.0 == id)),
        })
        .collect();
    if level >= 2 {
        for g in 1..RTI_GEOMETRY.len() {
            for m in 0..RTI_MODIFIERS.len() {
                v.push(cross(g, Some(m)));
            }
        }
    }
    v
}

/// Slab ray placements (level 1 ids 0-3).
const SLAB_RAYS: [(&str, &str); 11] = [
    ("random", "random ray and box in [-1, 1]^3"),
    ("face_signed_zero", "origin on a face plane, one direction component +0 or -0"),
    ("grazing", "aimed at a face, edge or corner point of the box"),
    ("inside", "origin inside the box"),
    ("edge_d", "a direction component of 1 to 8 least steps (subnormal: 1/d overflows), 1 to 64 least normals, or within 2^4 of the maximum (1/d subnormal), the box's slab on that axis where the ray meets it at t in [0.5, 4]"),
    ("near_max", "box planes near +-max on one axis, the origin near the other end or on the near plane, the direction component huge or near 1: plane minus origin overflows (floats) or saturates (fixed point)"),
    ("t_interval", "a random, face or inside placement with tmin one of -0, +0, -inf, a negative, a positive, a subnormal of either sign, and tmax one of -0, +0, NaN, +inf, a negative, a positive, a subnormal"),
    ("zero_t", "origin on the entry face plane of one axis and the exit face plane of another (inside on the third), tmin and tmax each +0 or -0: zero distances tie with zero limits of the other sign"),
    ("t_at_limits", "a placement the model finds hit with number limits, then the interval ending on them: tmax = the unwidened t_near stepped 2 * widen_ulps steps toward -inf, or tmin = the unwidened t_far stepped as far toward +inf (after widening t_near = t_far: a hit only if the decision is <=)"),
    ("ties", "floats: either one axis with the origin at 0, 1/d of significand m (odd part m'), 3m' of p + 1 bits and both planes 3 * 2^s: the products lo * inv_d and hi * inv_d fall exactly halfway between two values; or one axis with d = +-2^j, both planes in [0.5, 1 - 9u) and the origin +-(2k + 1) * u / 2 (u the step in [0.5, 1), k < 8): both subtracts fall exactly halfway; the other axes hold the origin inside with small d"),
    ("subnormal_gap", "floats: one axis with both planes and the origin small subnormal encodings (1 to 16 least steps, either sign; written as raw encodings also in FTZ formats), d on it +-1 (t subnormal) or 1 to 8 least normals (t near 1); the other axes hold the origin inside with small d"),
];
const SLAB_ZERO: (&str, &str) = ("zero_extent", "box of zero extent on one or more axes");
const SLAB_SPECIAL: (&str, &str) =
    ("inf_nan", "ray inputs +inf, -inf or NaN (floats only; a NaN is a random NaN encoding: either sign, quiet or signaling, random payload)");

/// One slab coverage class: a ray placement, a zero-extent box, special inputs.
#[derive(Clone, Copy, Debug)]
struct SlabCross {
    ray: usize,
    zero_box: bool,
    special: bool,
}

impl SlabCross {
    fn describe(&self) -> (String, String) {
        let mut parts: Vec<(&str, &str)> = Vec::new();
        if self.ray > 0 || (!self.zero_box && !self.special) {
            parts.push(SLAB_RAYS[self.ray]);
        }
        if self.zero_box {
            parts.push(SLAB_ZERO);
        }
        if self.special {
            parts.push(SLAB_SPECIAL);
        }
        (
            parts.iter().map(|p| p.0).collect::<Vec<_>>().join("+"),
            parts.iter().map(|p| p.1).collect::<Vec<_>>().join("; and "),
        )
    }
}

/// The slab classes of a level: level 1 the thirteen named classes (ids 0-12), level 2 adds each
/// special placement with a zero-extent box and with special inputs, and the two together.
fn slab_crosses(level: u32) -> Vec<SlabCross> {
    let c = |ray, zero_box, special| SlabCross { ray, zero_box, special };
    let mut v = vec![c(0, false, false), c(1, false, false), c(2, false, false), c(3, false, false)];
    v.push(c(0, true, false));
    v.push(c(0, false, true));
    v.push(c(4, false, false));
    v.push(c(5, false, false));
    for ray in 6..SLAB_RAYS.len() {
        v.push(c(ray, false, false));
    }
    if level >= 2 {
        for ray in 1..4 {
            v.push(c(ray, true, false));
            v.push(c(ray, false, true));
        }
        v.push(c(0, true, true));
    }
    v
}

const OP_CLASSES: [(&str, &str); 4] = [
    ("special", "TestFloat level 1: every pair of special operands (zeros, subnormals, min/max normal, one, all-ones significands, inf, NaN; fixed: extremes and one)"),
    ("random", "uniform random operand bits"),
    ("ties", "floats, add, sub and mul: operand pairs whose exact result lies exactly halfway between two format values (add / sub: a random value in [1, 2) and an odd multiple of its half step below 2^-4; mul: odd significands of na = floor((p + 2) / 2) and p + 2 - na bits whose product has p + 1 bits), found by drawing and checking the exact result in binary64 (p <= 24)"),
    ("special_x_random", "level 2: each special operand against random operands, on either side"),
];

/// Op codes of the `op` unit.
pub const OPCODES: [&str; 6] = ["add", "sub", "mul", "div", "lt", "le"];

fn rti_case(cross: RtiCross, r: &mut SplitMix64) -> [f64; 17] {
    let class = cross.geom;
    let p = |r: &mut SplitMix64| [r.range(-1.0, 1.0), r.range(-1.0, 1.0), r.range(-1.0, 1.0)];
    let mut v = [p(r), p(r), p(r)];
    let o = p(r);
    let (mut b1, mut b2) = (r.range(-0.3, 1.3), r.range(-0.3, 1.3));
    match class {
        1 => match r.below(3) {
            0 => b1 = 0.0,
            1 => b2 = 0.0,
            _ => b2 = 1.0 - b1,
        },
        2 => {
            let k = r.below(3);
            (b1, b2) = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)][k as usize];
        }
        13 => v = [v[0]; 3],
        4 => {
            let t = r.range(-1.0, 2.0);
            v[2] = std::array::from_fn(|a| v[0][a] + t * (v[1][a] - v[0][a]));
        }
        5 => {
            let w = 1e-3;
            v[2] = std::array::from_fn(|a| v[1][a] + w * r.range(-1.0, 1.0));
        }
        _ => {}
    }
    let b0 = 1.0 - b1 - b2;
    let target: [f64; 3] = std::array::from_fn(|a| b0 * v[0][a] + b1 * v[1][a] + b2 * v[2][a]);
    let mut o = o;
    let mut d: [f64; 3] = std::array::from_fn(|a| target[a] - o[a]);
    if class == 3 {
        // move the origin into the plane, then lift it slightly off
        let e1: [f64; 3] = std::array::from_fn(|a| v[1][a] - v[0][a]);
        let e2: [f64; 3] = std::array::from_fn(|a| v[2][a] - v[0][a]);
        let s = r.range(-1.0, 1.0);
        let t = r.range(-1.0, 1.0);
        o = std::array::from_fn(|a| target[a] + s * e1[a] + t * e2[a]);
        let n = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]];
        let eps = 1e-3 * r.range(-1.0, 1.0);
        o = std::array::from_fn(|a| o[a] + eps * n[a]);
        d = std::array::from_fn(|a| target[a] - o[a]);
    }
    if class == 8 {
        o = target;
        d = p(r);
    }
    let scale = cross.scale;
    let mut x = [0.0; 17];
    for a in 0..3 {
        x[a] = o[a] * scale;
        x[3 + a] = d[a] * scale;
        for k in 0..3 {
            x[8 + 3 * k + a] = v[k][a] * scale;
        }
    }
    x[6] = 0.0;
    x[7] = if r.below(4) == 0 { r.range(0.0, 3.0) * scale } else { f64::INFINITY };
    if cross.signed_zero {
        for xi in x.iter_mut() {
            if r.below(3) == 0 {
                *xi = if r.below(2) == 0 { 0.0 } else { -0.0 };
            }
        }
    }
    x
}

fn specials_for<F: Format>(f: &F) -> Vec<u64> {
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

fn generate_in<F: Format>(f: F, req: &Request) -> Result<VectorSet, String> {
    let w = f.width();
    let k = kind_of(&f);
    let mut r = SplitMix64::new(req.seed);
    let mut options = BTreeMap::new();
    let mut params = format_params(&f);
    let (classes, latency, stages): (Vec<(String, String)>, u32, Vec<Stage>);
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
            classes = crosses.iter().map(|c| c.describe()).collect();
            latency = 7;
            stages = SLAB_TABLE
                .iter()
                .map(|d| Stage { stage: d.stage, name: d.name.into(), op: op_text(d.op, d.a, d.b, d.note) })
                .collect();
            let names =
                ["ox", "oy", "oz", "dx", "dy", "dz", "tmin", "tmax", "minx", "miny", "minz", "maxx", "maxy", "maxz"];
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
            let per_class = pool.install(|| {
                per_class_rows(req.seed, crosses.len(), req.count, |c, r| {
                    let cross = crosses[c];
                    if cross.special && !float {
                        return Ok(None);
                    }
                    let case_bits = |r: &mut SplitMix64| -> Result<Vec<u64>, String> {
                        let x = slab_case(cross, r, datapath::format::edges(&f));
                        let b =
                            slab.store_box([x[8], x[9], x[10]], [x[11], x[12], x[13]]).map_err(|e| e.to_string())?;
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
            counts = push_rows(&mut files, per_class);
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
                )
            })?;
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
    };
    Ok(VectorSet { manifest, files: files.into_iter().map(|fr| (fr.name, fr.lines.join("\n") + "\n")).collect() })
}

/// What the manifest says of acceptable values.
pub const ACCEPTABLE: &str = "exact: every operation is correctly rounded per the contract, so each output field has exactly one acceptable value; a field with care_when F is compared only when the 1-bit field F of the expected output row is 1 (any value is acceptable otherwise); a field marked implementation_defined depends on how the DUT is built and is compared only on request (+strict in the kit's testbenches)";

/// The per-field acceptance rules: rti `t`, `u`, `v` and every stage signal after the valid
/// bit's stage (the divide and what depends on it, `hit` excepted) are don't-care when
/// `valid = 0` (a DUT may skip the divide); traverse `passes` and `box_tests` count work the way
/// the model's traversal does it (one pass per walk from the root, the root box once and two
/// boxes per level visited) and are implementation-defined.
fn acceptance(unit: Unit, role: &str, fields: &mut [Field]) {
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
fn format_params<F: Format>(f: &F) -> BTreeMap<String, u64> {
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

fn op_text(op: Op, a: &str, b: &str, note: &str) -> String {
    match op {
        Op::Sub => format!("{a} - {b}"),
        Op::Add => format!("{a} + {b}"),
        Op::Mul => format!("{a} * {b}"),
        Op::Div => format!("{a} / {b}"),
        Op::Logic => note.to_string(),
    }
}

fn op_eval<F: Format>(f: &F, op: u64, x: F::V, y: F::V) -> (u64, u64) {
    op_eval_faulty(f, op, x, y, &NoFault)
}

/// One op-unit vector with its site (the op code's name: `add`, `sub`, `mul`, `div`, `lt`,
/// `le`) computed by `x`: (result, cmp).
fn op_eval_faulty<F: Format, X: Fault<F>>(f: &F, op: u64, a: F::V, b: F::V, x: &X) -> (u64, u64) {
    use datapath::fault::Cmp;
    match op {
        0 => (f.to_bits(x.arith(f, "add", Op::Add, a, b)), 0),
        1 => (f.to_bits(x.arith(f, "sub", Op::Sub, a, b)), 0),
        2 => (f.to_bits(x.arith(f, "mul", Op::Mul, a, b)), 0),
        3 => (f.to_bits(x.arith(f, "div", Op::Div, a, b)), 0),
        4 => (0, x.compare(f, "lt", Cmp::Lt, a, b) as u64),
        _ => (0, x.compare(f, "le", Cmp::Le, a, b) as u64),
    }
}

/// The expected row (result, cmp) of one op vector (`bits`: op code, a, b) with its site
/// computed by `x` (`NoFault`: the row a set holds); the op unit has no stage file.
pub fn op_out_rows<F: Format, X: Fault<F>>(f: &F, bits: &[u64], x: &X) -> [Vec<u64>; 2] {
    let (res, cmp) = op_eval_faulty(f, bits[0], f.from_bits(bits[1]), f.from_bits(bits[2]), x);
    [vec![res, cmp], Vec::new()]
}

/// Model rows for one RTI vector: inputs, expected outputs, stage signals.
/// The ray and triangle of a case's 17 f64 inputs (o, d, tmin, tmax, v0, v1, v2) in format `f`.
fn rti_inputs<F: Format>(f: &F, x: &[f64; 17]) -> (Ray<F::V>, Tri<F::V>) {
    rti_case_of(f, &x.map(|v| f.to_bits(f.from_f64(v))))
}

/// The ray and triangle of an RTI input row's 17 encodings (o, d, tmin, tmax, v0, v1, v2).
pub fn rti_case_of<F: Format>(f: &F, bits: &[u64]) -> (Ray<F::V>, Tri<F::V>) {
    let v = |i: usize| f.from_bits(bits[i]);
    (
        Ray { o: [v(0), v(1), v(2)], d: [v(3), v(4), v(5)], tmin: v(6), tmax: v(7) },
        Tri { v: [[v(8), v(9), v(10)], [v(11), v(12), v(13)], [v(14), v(15), v(16)]] },
    )
}

/// The expected row (valid, hit, t, u, v) and the stage row of one RTI test with every site
/// computed by `x` (`NoFault`: the rows a set holds).
pub fn rti_out_rows<F: Format, X: Fault<F>>(rti: &Rti<F>, ray: &Ray<F::V>, tri: &Tri<F::V>, x: &X) -> [Vec<u64>; 2] {
    let f = &rti.fmt;
    let mut rec = Recorder::new();
    let out = rti.trace_faulty(ray, tri, &mut rec, x);
    [vec![out.valid as u64, out.hit as u64, f.to_bits(out.t), f.to_bits(out.u), f.to_bits(out.v)], signals(f, &rec)]
}

fn rti_rows<F: Format>(rti: &Rti<F>, class: u64, bits: &[u64]) -> [Vec<u64>; 3] {
    let (ray, tri) = rti_case_of(&rti.fmt, bits);
    let [expected, stages] = rti_out_rows(rti, &ray, &tri, &NoFault);
    let mut inputs = vec![class];
    inputs.extend_from_slice(bits);
    [inputs, expected, stages]
}

fn signals<F: Format>(f: &F, rec: &Recorder<F::V>) -> Vec<u64> {
    rec.signals
        .iter()
        .map(|(_, s)| match s {
            Signal::Value(x) => f.to_bits(*x),
            Signal::Flag(b) => *b as u64,
        })
        .collect()
}

fn slab_case(cross: SlabCross, r: &mut SplitMix64, e: datapath::format::Edges) -> [f64; 14] {
    let mut lo = [0.0; 3];
    let mut hi = [0.0; 3];
    for a in 0..3 {
        let c = r.range(-1.0, 1.0);
        let e = if cross.zero_box && r.below(2) == 0 { 0.0 } else { r.range(0.01, 0.5) };
        lo[a] = c - e;
        hi[a] = c + e;
    }
    let mut o: [f64; 3] = std::array::from_fn(|_| r.range(-2.0, 2.0));
    let mut d: [f64; 3] = std::array::from_fn(|_| r.range(-1.0, 1.0));
    match cross.ray {
        1 => {
            let a = r.below(3) as usize;
            o[a] = if r.below(2) == 0 { lo[a] } else { hi[a] };
            for b in 0..3 {
                if b != a {
                    o[b] = r.range(lo[b], hi[b]);
                }
            }
            let z = r.below(3) as usize;
            d[z] = if r.below(2) == 0 { 0.0 } else { -0.0 };
        }
        2 => {
            let mut p: [f64; 3] = std::array::from_fn(|a| r.range(lo[a], hi[a]));
            for a in 0..1 + r.below(3) as usize {
                p[a] = if r.below(2) == 0 { lo[a] } else { hi[a] };
            }
            d = std::array::from_fn(|a| p[a] - o[a]);
        }
        3 => o = std::array::from_fn(|a| r.range(lo[a], hi[a])),
        4 => {
            // the ray crosses the other axes' slabs around t = tm; axis a's slab where the ray
            // meets it at t in [t1, t2] (q1.F holds t < 1)
            let cap = (e.max / 2.0).min(4.0);
            let (t1, t2) = (r.range(0.125, 0.5) * cap, r.range(0.5, 1.0) * cap);
            let tm = (t1 + t2) / 2.0;
            let a = r.below(3) as usize;
            for b in (0..3).filter(|&b| b != a) {
                let p = r.range(lo[b], hi[b]);
                d[b] = r.range(-0.05, 0.05);
                o[b] = p - d[b] * tm;
            }
            let s = if r.below(2) == 0 { 1.0 } else { -1.0 };
            d[a] = s * match r.below(3) {
                0 => e.least * (1 + r.below(8)) as f64,
                1 => e.min_normal * r.range(1.0, 64.0),
                _ => e.max * (-r.range(0.0, 4.0)).exp2(),
            };
            o[a] = 0.0;
            let (x, y) = (d[a] * t1, d[a] * t2);
            // a huge d puts the slab beyond the range: then near one unit instead (t ~ 1/|d|)
            let (x, y) =
                if y.abs() > e.max / 2.0 { (s * 0.5f64.min(e.max / 4.0), s * 1f64.min(e.max / 2.0)) } else { (x, y) };
            (lo[a], hi[a]) = (x.min(y), x.max(y));
        }
        5 => {
            let a = r.below(3) as usize;
            let s = if r.below(2) == 0 { 1.0 } else { -1.0 };
            let tm = (e.max / 4.0).min(2.0) * r.range(0.25, 1.0);
            let mode = r.below(3);
            if mode < 2 {
                let (x, y) = (r.range(0.3, 0.9) * e.max, r.range(0.3, 0.9) * e.max);
                (lo[a], hi[a]) = if s > 0.0 { (x.min(y), x.max(y)) } else { (-x.max(y), -x.min(y)) };
                o[a] = -s * r.range(0.3, 0.95) * e.max;
                // a huge d (1/d subnormal), or one near 1: the overflowed difference alone
                // decides the axis
                d[a] = if mode == 0 {
                    (((lo[a] + hi[a]) / 2.0 - o[a]) / tm).clamp(-e.max, e.max)
                } else {
                    s * r.range(0.5, 2.0).min(e.max)
                };
            } else {
                (lo[a], hi[a]) = (-r.range(0.55, 0.95) * e.max, r.range(0.55, 0.95) * e.max);
                o[a] = if s > 0.0 { lo[a] } else { hi[a] };
                let far = if s > 0.0 { hi[a] } else { lo[a] };
                d[a] = ((far - o[a]) / (1.1 * tm)).clamp(-e.max, e.max);
            }
            for b in (0..3).filter(|&b| b != a) {
                d[b] = r.range(-1.0, 1.0) * (hi[b] - lo[b]) / tm;
                o[b] = (lo[b] + hi[b]) / 2.0 - d[b] * tm;
            }
        }
        6 => {
            let base = SlabCross { ray: [0, 1, 3][r.below(3) as usize], ..cross };
            let mut x = slab_case(base, r, e);
            let sub = e.least * (1 + r.below(4)) as f64;
            x[6] =
                [-0.0, 0.0, f64::NEG_INFINITY, -r.range(0.0, 2.0), r.range(0.0, 2.0), sub, -sub][r.below(7) as usize];
            x[7] =
                [-0.0, 0.0, f64::NAN, f64::INFINITY, -r.range(0.0, 2.0), r.range(0.0, 3.0), sub][r.below(7) as usize];
            return x;
        }
        7 => {
            let a = r.below(3) as usize;
            for b in 0..3 {
                o[b] = r.range(lo[b], hi[b]);
                while d[b] == 0.0 {
                    d[b] = r.range(-1.0, 1.0);
                }
            }
            // on the entry face of axis a and the exit face of another axis b
            let b = (a + 1 + r.below(2) as usize) % 3;
            o[a] = if d[a] > 0.0 { lo[a] } else { hi[a] };
            o[b] = if d[b] > 0.0 { hi[b] } else { lo[b] };
            let z = |r: &mut SplitMix64| if r.below(2) == 0 { 0.0 } else { -0.0 };
            let (tmin, tmax) = (z(r), z(r));
            return [o[0], o[1], o[2], d[0], d[1], d[2], tmin, tmax, lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]];
        }
        8..=10 => {
            // placed here; t_at_limits, ties and subnormal_gap set their values on the
            // format's encodings (slab_special_bits)
            let base = SlabCross { ray: [0, 2, 3][r.below(3) as usize], ..cross };
            return slab_case(base, r, e);
        }
        _ => {}
    }
    if cross.special {
        let i = r.below(6) as usize;
        let v = [f64::INFINITY, f64::NEG_INFINITY, f64::NAN][r.below(3) as usize];
        if i < 3 {
            o[i] = v;
        } else {
            d[i - 3] = v;
        }
    }
    let tmax = if r.below(4) == 0 { r.range(0.0, 3.0) } else { f64::INFINITY };
    [o[0], o[1], o[2], d[0], d[1], d[2], 0.0, tmax, lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]]
}

/// Every NaN the f64 case holds becomes a random NaN encoding of the float format (either
/// sign, quiet or signaling, a random nonzero payload), so the sets exercise NaN sign and
/// payload paths; fixed-point formats have no NaN (their cases hold none).
fn any_nans<F: Format>(f: &F, r: &mut SplitMix64, x: &[f64], bits: &mut [u64]) {
    let FormatKind::Float(l) = f.kind() else { return };
    for (b, v) in bits.iter_mut().zip(x) {
        if v.is_nan() {
            let payload = (r.next_u64() & l.man_mask()).max(1);
            let sign = if r.below(2) == 0 { 0 } else { l.sign_mask() };
            *b = sign | (((1u64 << l.exp_bits) - 1) << l.man_bits) | payload;
        }
    }
}

/// Up to `count` operand pairs (encodings) of op code `op` (0 add, 1 sub, 2 mul) whose exact
/// result lies exactly halfway between two values of float format `f` (p ≤ 24: the exact
/// result is a binary64 value), each checked: the exact result differs from its rounding by
/// exactly half the rounded value's step. None for other formats (at most 64 draws per pair).
fn op_ties<F: Format>(f: &F, op: u64, count: usize, r: &mut SplitMix64) -> Vec<(u64, u64)> {
    let FormatKind::Float(l) = f.kind() else { return Vec::new() };
    if l.man_bits > 23 {
        return Vec::new();
    }
    let p = l.man_bits as i32 + 1;
    // ± an odd integer of n bits over 2^(n-1): in [1, 2)
    let odd = |n: i32, r: &mut SplitMix64| {
        let v = ((1u64 << (n - 1)) + r.below(1u64 << (n - 1))) | 1;
        let s = if r.below(2) == 0 { 1.0 } else { -1.0 };
        s * v as f64 / ((n - 1) as f64).exp2()
    };
    let mut out = Vec::new();
    for _ in 0..count * 64 {
        if out.len() == count {
            break;
        }
        let (a, b) = match op {
            2 => {
                // odd significands of na and nb bits, na + nb = p + 2: a product of p + 1 bits
                // (about half the draws) is odd, so exactly halfway
                let na = (p + 2) / 2;
                (odd(na, r), odd(p + 2 - na, r))
            }
            _ => {
                let a = f.to_f64(f.from_f64(r.range(1.0, 2.0)));
                let half = (-(p as f64)).exp2();
                let k = (2 * r.below(1u64 << (p - 4).clamp(1, 8)) + 1) as f64;
                (a, if r.below(2) == 0 { k * half } else { -k * half })
            }
        };
        let (fa, fb) = (f.from_f64(a), f.from_f64(b));
        if f.to_f64(fa) != a || f.to_f64(fb) != b {
            continue;
        }
        let exact = match op {
            0 => a + b,
            1 => a - b,
            _ => a * b,
        };
        let rounded = f.to_f64(f.from_f64(exact));
        if exact.is_finite() && rounded != 0.0 && (exact - rounded).abs() == f.ulp(rounded) / 2.0 {
            out.push((f.to_bits(fa), f.to_bits(fb)));
        }
    }
    out
}

/// The t_at_limits class on a placement's encodings: when the unwidened unit hits with number
/// limits tn <= tf, the interval is made to end on them (`tmax` = tn stepped 2W times toward
/// −∞, or `tmin` = tf stepped 2W times toward +∞, W = widen_ulps); `None` otherwise.
fn slab_at_limits<F: Format>(s: &Slab<F>, bits: &[u64], r: &mut SplitMix64) -> Option<Vec<u64>> {
    let f = &s.fmt;
    let bare = Slab::new(*f, SlabConfig { widen_ulps: 0, ..s.cfg });
    let [out, _] = slab_out_rows(&bare, bits, &NoFault);
    let (tn, tf) = (f.from_bits(out[1]), f.from_bits(out[2]));
    let number = |v: F::V| !f.is_nan(v) && f.to_f64(v).is_finite();
    if out[0] == 0 || !number(tn) || !number(tf) {
        return None;
    }
    let steps = 2 * s.cfg.widen_ulps.max(0);
    let mut b = bits.to_vec();
    if r.below(2) == 0 {
        let t = (0..steps).fold(tn, |t, _| f.next_down(t));
        b[7] = f.to_bits(t);
    } else {
        let t = (0..steps).fold(tf, |t, _| f.next_up(t));
        b[6] = f.to_bits(t);
    }
    Some(b)
}

/// Puts the origin inside the box with a small direction component on every axis but `a`
/// (encodings of a slab input row), so that axis `a` alone sets t_near and t_far.
fn slab_others_inside<F: Format>(f: &F, a: usize, r: &mut SplitMix64, bits: &mut [u64]) {
    for b in (0..3).filter(|&b| b != a) {
        let (lo, hi) = (f.to_f64(f.from_bits(bits[8 + b])), f.to_f64(f.from_bits(bits[11 + b])));
        bits[b] = f.to_bits(f.from_f64(r.range(lo, hi)));
        bits[3 + b] = f.to_bits(f.from_f64(r.range(-0.05, 0.05)));
    }
}

/// The ties class on a float placement's encodings (see the class description).
fn slab_ties<F: Format>(f: &F, r: &mut SplitMix64, bits: &mut [u64]) {
    let FormatKind::Float(l) = f.kind() else { return };
    let p = l.man_bits as i32 + 1;
    let a = r.below(3) as usize;
    slab_others_inside(f, a, r, bits);
    let sign = |r: &mut SplitMix64| if r.below(2) == 0 { 1.0 } else { -1.0 };
    if r.below(2) == 0 {
        // products: 1 ⊘ d of significand m, odd part m' with 3m' of p + 1 bits (at most 64 tries)
        for _ in 0..64 {
            let d = f.from_f64(sign(r) * r.range(0.5, 2.0));
            let inv = f.to_f64(f.div(f.one(), d)).abs();
            let m = (inv.to_bits() & ((1 << 52) - 1)) | (1 << 52);
            let odd = m >> m.trailing_zeros();
            if 64 - (3 * odd).leading_zeros() as i32 == p + 1 {
                let s = (-2 - r.below(2) as i32) as f64;
                let (x1, x2) = (3.0 * s.exp2(), 3.0 * (s + 1.0).exp2());
                let (lo, hi) = if r.below(2) == 0 { (x1, x2) } else { (-x2, -x1) };
                bits[a] = f.to_bits(f.zero());
                bits[3 + a] = f.to_bits(d);
                bits[8 + a] = f.to_bits(f.from_f64(lo));
                bits[11 + a] = f.to_bits(f.from_f64(hi));
                return;
            }
        }
    }
    // subtracts: planes in [0.5, 1 - 9u), origin ±(2k + 1)u/2
    let u = (-p as f64).exp2();
    let half = 1u64 << (p - 1);
    let pick = |r: &mut SplitMix64| (half + 9 + r.below(half - 18)) as f64 * u;
    let (x, y) = (pick(r), pick(r));
    let (lo, hi) = (x.min(y), if x == y { x + u } else { x.max(y) });
    let o = sign(r) * (2 * r.below(8) + 1) as f64 * u / 2.0;
    bits[a] = f.to_bits(f.from_f64(o));
    bits[3 + a] = f.to_bits(f.from_f64(sign(r) * (r.below(3) as f64 - 1.0).exp2()));
    bits[8 + a] = f.to_bits(f.from_f64(lo));
    bits[11 + a] = f.to_bits(f.from_f64(hi));
}

/// The subnormal_gap class on a float placement's encodings (see the class description).
fn slab_subnormal_gap<F: Format>(f: &F, r: &mut SplitMix64, bits: &mut [u64]) {
    let FormatKind::Float(l) = f.kind() else { return };
    let a = r.below(3) as usize;
    slab_others_inside(f, a, r, bits);
    // a signed multiple of the least subnormal step, as its raw encoding
    let mut k = || (1 + r.below(16) as i64) * if r.below(2) == 0 { 1 } else { -1 };
    let enc = |k: i64| if k < 0 { l.sign_mask() | k.unsigned_abs() } else { k as u64 };
    let (x, y, o) = (k(), k(), k());
    bits[a] = enc(o);
    bits[8 + a] = enc(x.min(y));
    bits[11 + a] = enc(x.max(y));
    let s = if r.below(2) == 0 { 1.0 } else { -1.0 };
    let d = if r.below(2) == 0 { 1.0 } else { l.min_normal() * r.range(1.0, 8.0) };
    bits[3 + a] = f.to_bits(f.from_f64(s * d));
}

/// The expected row (hit, t_near, t_far) and the stage row of one slab test on an input row's
/// 14 encodings (o, d, tmin, tmax, box min, box max) with every site computed by `x`
/// (`NoFault`: the rows a set holds).
pub fn slab_out_rows<F: Format, X: Fault<F>>(s: &Slab<F>, bits: &[u64], x: &X) -> [Vec<u64>; 2] {
    let f = &s.fmt;
    let v = |i: usize| f.from_bits(bits[i]);
    let mut rec = Recorder::new();
    let ray = s.prepare_faulty([v(0), v(1), v(2)], [v(3), v(4), v(5)], v(6), v(7), &mut rec, x);
    let b = Aabb { min: [v(8), v(9), v(10)], max: [v(11), v(12), v(13)] };
    let out = s.trace_faulty(&ray, &b, &mut rec, x);
    [vec![out.hit as u64, f.to_bits(out.t_near), f.to_bits(out.t_far)], signals(f, &rec)]
}

/// Model rows for one slab vector.
fn slab_rows<F: Format>(s: &Slab<F>, class: u64, bits: &[u64]) -> [Vec<u64>; 3] {
    let [expected, stages] = slab_out_rows(s, bits, &NoFault);
    let mut inputs = vec![class];
    inputs.extend_from_slice(bits);
    [inputs, expected, stages]
}

fn git_hash() -> String {
    std::process::Command::new("git")
        .args(["rev-parse", "HEAD"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .unwrap_or_else(|| "unknown".into())
}

fn sha256_hex(data: &[u8]) -> String {
    Sha256::digest(data).iter().map(|b| format!("{b:02x}")).collect()
}

/// Checks, before any work, that `dir` can take a vector set: it does not exist (nothing is
/// created yet), is empty, or is a set raypipe wrote — its `manifest.json` reads as a raypipe
/// manifest and every entry is a regular file that manifest names (its data files, the
/// manifest, `raypipe_pkg.sv`, `raypipe_pkg.vhd`). Anything else is refused and left untouched.
pub fn check_out(dir: &Path) -> Result<(), String> {
    if !dir.exists() {
        return crate::outdir::OutDir::check(dir, &[]).map(|_| ());
    }
    if !dir.is_dir() {
        return Err(format!("{} exists and is not a directory", dir.display()));
    }
    let entries: Vec<std::fs::DirEntry> = std::fs::read_dir(dir)
        .map_err(|e| format!("{}: {e}", dir.display()))?
        .collect::<Result<_, _>>()
        .map_err(|e| format!("{}: {e}", dir.display()))?;
    if entries.is_empty() {
        return Ok(());
    }
    let refuse = |why: String| {
        Err(format!(
            "{} is not a vector set raypipe wrote ({why}); refusing to replace it: choose another --out",
            dir.display()
        ))
    };
    let Ok(text) = std::fs::read_to_string(dir.join("manifest.json")) else {
        return refuse("no manifest.json".into());
    };
    let Ok(m) = serde_json::from_str::<Manifest>(&text) else {
        return refuse("its manifest.json is not a raypipe manifest".into());
    };
    let mut allowed: Vec<&str> = m.files.iter().map(|f| f.name.as_str()).collect();
    allowed.extend(["manifest.json", "raypipe_pkg.sv", "raypipe_pkg.vhd"]);
    for e in &entries {
        let name = e.file_name();
        let name = name.to_string_lossy();
        let file = e.file_type().map(|t| t.is_file()).unwrap_or(false);
        if !file || !allowed.contains(&name.as_ref()) {
            return refuse(format!("it holds {name}, which its manifest does not list"));
        }
    }
    Ok(())
}

/// Writes the set into `dir` (see [`check_out`] for what may be replaced): built in the
/// temporary sibling `.<dir>.raypipe-partial` (removed on SIGINT, and by the next run if left),
/// then renamed into place, so that an interrupted run never leaves a half set that looks whole.
pub fn write_set(set: &VectorSet, dir: &Path) -> Result<PathBuf, String> {
    use crate::outdir::{partial_of, register_partial, unregister_partial};
    check_out(dir)?;
    let parent = dir.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    std::fs::create_dir_all(parent).map_err(|e| format!("{}: {e}", parent.display()))?;
    let tmp = partial_of(dir)?;
    const OWN: &str = ".raypipe-partial";
    if tmp.exists() {
        // an interrupted run's leftover (it holds the mark raypipe writes first)
        if !tmp.join(OWN).is_file() {
            return Err(format!(
                "{} exists and was not left by raypipe; remove it or choose another --out",
                tmp.display()
            ));
        }
        std::fs::remove_dir_all(&tmp).map_err(|e| format!("{}: {e}", tmp.display()))?;
    }
    std::fs::create_dir(&tmp).map_err(|e| format!("{}: {e}", tmp.display()))?;
    register_partial(&tmp);
    let result = (|| {
        std::fs::write(tmp.join(OWN), "").map_err(|e| format!("{}: {e}", tmp.display()))?;
        let mut manifest = set.manifest.clone();
        for (fname, content) in &set.files {
            std::fs::write(tmp.join(fname), content).map_err(|e| format!("{fname}: {e}"))?;
            if let Some(m) = manifest.files.iter_mut().find(|m| &m.name == fname) {
                m.sha256 = sha256_hex(content.as_bytes());
            }
        }
        std::fs::write(tmp.join("raypipe_pkg.sv"), crate::hdl::sv_package(&manifest))
            .map_err(|e| format!("raypipe_pkg.sv: {e}"))?;
        std::fs::write(tmp.join("raypipe_pkg.vhd"), crate::hdl::vhdl_package(&manifest))
            .map_err(|e| format!("raypipe_pkg.vhd: {e}"))?;
        let json = serde_json::to_string_pretty(&manifest).map_err(|e| e.to_string())? + "\n";
        std::fs::write(tmp.join("manifest.json"), json).map_err(|e| format!("manifest.json: {e}"))?;
        std::fs::remove_file(tmp.join(OWN)).map_err(|e| format!("{}: {e}", tmp.display()))?;
        // the earlier set (checked above) goes aside, the new one into place, then the old is removed
        let old = parent.join(format!(".{}.raypipe-old", dir.file_name().unwrap_or_default().to_string_lossy()));
        if dir.exists() {
            check_out(dir)?;
            let _ = std::fs::remove_dir_all(&old);
            std::fs::rename(dir, &old).map_err(|e| format!("{}: {e}", dir.display()))?;
        }
        std::fs::rename(&tmp, dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        if old.exists() {
            std::fs::remove_dir_all(&old).map_err(|e| format!("{}: {e}", old.display()))?;
        }
        Ok(dir.to_path_buf())
    })();
    if result.is_err() && tmp.exists() {
        let _ = std::fs::remove_dir_all(&tmp);
    }
    unregister_partial(&tmp);
    result
}

pub use crate::check::check_set;

/// Reads every data file the manifest lists, checking its hash, digit count and row count.
pub fn read_files(dir: &Path, m: &Manifest) -> Result<Vec<Vec<Vec<u64>>>, String> {
    let mut contents = Vec::new();
    for fm in &m.files {
        let c = std::fs::read_to_string(dir.join(&fm.name)).map_err(|e| format!("{}: {e}", fm.name))?;
        if sha256_hex(c.as_bytes()) != fm.sha256 {
            return Err(format!("{}: sha256 differs from the manifest", fm.name));
        }
        contents.push(parse_rows(fm, &c)?);
    }
    Ok(contents)
}

/// The rows of a generated set's files (in the manifest's order), unpacked into fields.
pub fn set_rows(set: &VectorSet) -> Result<Vec<Vec<Vec<u64>>>, String> {
    set.manifest
        .files
        .iter()
        .map(|fm| {
            let text = set.files.iter().find(|(n, _)| *n == fm.name).map(|(_, t)| t.as_str());
            parse_rows(fm, text.ok_or(format!("{}: not in the set", fm.name))?)
        })
        .collect()
}

/// One file's rows, each unpacked into its fields (widths from the manifest).
fn parse_rows(fm: &crate::manifest::File, c: &str) -> Result<Vec<Vec<u64>>, String> {
    let rows: Vec<Vec<u64>> = c
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if l.len() != fm.digits as usize {
                return Err(format!(
                    "{} line {}: {} hex digits, the manifest says {}",
                    fm.name,
                    i + 1,
                    l.len(),
                    fm.digits
                ));
            }
            unpack(l, &fm.fields.iter().map(|x| x.width).collect::<Vec<_>>())
                .map_err(|e| format!("{} line {}: {e}", fm.name, i + 1))
        })
        .collect::<Result<_, _>>()?;
    if rows.len() != fm.rows {
        return Err(format!("{}: {} rows, manifest says {}", fm.name, rows.len(), fm.rows));
    }
    Ok(rows)
}

/// Re-runs the model on every input row and compares every expected and stage row bit for
/// bit (the manifest already checked against this raypipe's). Returns the vectors checked.
pub(crate) fn check_rows(
    m: &Manifest,
    unit: Unit,
    any: AnyFormat,
    contents: &[Vec<Vec<u64>>],
) -> Result<usize, String> {
    // the inputs' class ids and the counts the manifest gives them
    if let Some(inputs) = contents.first() {
        for c in &m.classes {
            let n = inputs.iter().filter(|r| r.first() == Some(&(c.id as u64))).count();
            if n != c.count {
                return Err(format!(
                    "manifest.json: class {} ({}) has count {}, the inputs hold {n}",
                    c.id, c.name, c.count
                ));
            }
        }
        if let Some((i, r)) =
            inputs.iter().enumerate().find(|(_, r)| !m.classes.iter().any(|c| r.first() == Some(&(c.id as u64))))
        {
            return Err(format!(
                "{} line {}: class {} is not in the manifest",
                m.files[0].name,
                i + 1,
                r.first().copied().unwrap_or(0)
            ));
        }
    }
    if unit == Unit::Traverse {
        return with_format!(any, |f| check_traverse(f, m, contents));
    }
    with_format!(any, |f| {
        let n = contents[0].len();
        for (i, input) in contents[0].iter().enumerate() {
            let (class, bits) = (input[0], &input[1..]);
            let want: Vec<Vec<u64>> = match unit {
                Unit::Rti => {
                    let rti = Rti::new(f, rti_config_from(m)?);
                    rti_rows(&rti, class, bits)[1..].to_vec()
                }
                Unit::Slab => slab_rows(&Slab::new(f, slab_config_from(m)?), class, bits)[1..].to_vec(),
                Unit::Capture => crate::capture::out_rows(&capture_rti_from(f, m), bits, &NoFault).to_vec(),
                Unit::Op => {
                    let (res, cmp) = op_eval(&f, bits[0], f.from_bits(bits[1]), f.from_bits(bits[2]));
                    vec![vec![res, cmp]]
                }
                Unit::Traverse => unreachable!("checked above"),
            };
            for (k, w) in want.iter().enumerate() {
                if &contents[k + 1][i] != w {
                    let fm = &m.files[k + 1];
                    let bad = fm
                        .fields
                        .iter()
                        .zip(w.iter().zip(&contents[k + 1][i]))
                        .find(|(_, (a, b))| a != b)
                        .map(|(x, _)| x.name.clone());
                    return Err(format!(
                        "{} line {}: field {} differs from the model",
                        fm.name,
                        i + 1,
                        bad.unwrap_or_default()
                    ));
                }
            }
        }
        Ok(n)
    })
}

/// One level's left and right bank rows.
pub type BankImages<'a> = (&'a Vec<Vec<u64>>, &'a Vec<Vec<u64>>);

/// A traverse set's BRAM images: the root entry row and each level's two banks, by file name.
pub fn tree_images<'a>(
    m: &Manifest,
    contents: &'a [Vec<Vec<u64>>],
) -> Result<(&'a [u64], Vec<BankImages<'a>>), String> {
    let idx = |name: &str| m.files.iter().position(|x| x.name == name);
    let levels = m.params.get("levels").copied().ok_or("manifest.json: params has no levels")? as usize;
    let root = idx("tree_root.hex").and_then(|i| contents.get(i)?.first()).ok_or("the set has no tree_root.hex row")?;
    let mut banks = Vec::new();
    for l in 0..levels {
        let (Some(a), Some(b)) = (idx(&format!("tree_l{l}_left.hex")), idx(&format!("tree_l{l}_right.hex"))) else {
            return Err(format!("the set lacks the level {l} bank images"));
        };
        banks.push((&contents[a], &contents[b]));
    }
    Ok((root, banks))
}

/// The traverse unit's check: the tree comes from the set's own BRAM images.
fn check_traverse<F: Format>(f: F, m: &Manifest, contents: &[Vec<Vec<u64>>]) -> Result<usize, String> {
    let n = m.params.get("leaves").copied().ok_or("manifest has no leaves parameter")? as usize;
    let (root, images) = tree_images(m, contents)?;
    let banks: Vec<_> = images.into_iter().map(|(a, b)| (a.clone(), b.clone())).collect();
    let variant = m.options.get("variant").map_or("plain", |s| s.as_str());
    let want = crate::traverse::recheck(f, variant, n, root, &banks, &contents[0])?;
    for (i, w) in want.iter().enumerate() {
        if &contents[1][i] != w {
            let fm = &m.files[1];
            let bad = fm
                .fields
                .iter()
                .zip(w.iter().zip(&contents[1][i]))
                .find(|(_, (a, b))| a != b)
                .map(|(x, _)| x.name.clone());
            return Err(format!(
                "{} line {}: field {} differs from the model",
                fm.name,
                i + 1,
                bad.unwrap_or_default()
            ));
        }
    }
    Ok(want.len())
}

/// The slab variant a set's manifest names (`plain` when it names none).
pub fn slab_config_from(m: &Manifest) -> Result<SlabConfig, String> {
    SlabConfig::named(m.options.get("variant").map_or("plain", |s| s.as_str()))
}

/// The min-capture tie rule a set's manifest names (`first` when it names none).
fn tie_from(m: &Manifest) -> datapath::rti::TieRule {
    match m.options.get("tie").map(String::as_str) {
        Some("Last") => datapath::rti::TieRule::Last,
        _ => datapath::rti::TieRule::First,
    }
}

/// The unit a capture set's manifest names: an RTI unit of format `f` with its tie rule (the
/// min-capture unit reads nothing else of it).
pub fn capture_rti_from<F: Format>(f: F, m: &Manifest) -> Rti<F> {
    Rti::new(f, RtiConfig { tie: tie_from(m), ..RtiConfig::default() })
}

/// The RTI unit's configuration a set's manifest names (cull, det threshold, tie rule).
pub fn rti_config_from(m: &Manifest) -> Result<RtiConfig, String> {
    use datapath::rti::Cull;
    let cull = match m.options.get("cull").map(String::as_str) {
        Some("Backface") => Cull::Backface,
        _ => Cull::TwoSided,
    };
    let tie = tie_from(m);
    let det_threshold = m
        .options
        .get("det_threshold")
        .and_then(|s| s.split_whitespace().next())
        .and_then(|s| s.parse().ok())
        .ok_or("manifest has no det_threshold")?;
    Ok(RtiConfig { cull, det_threshold, tie })
}
