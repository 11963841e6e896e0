//! The numerical stability stress suite: named, seeded generators of hard cases, and per class
//! and format (and slab variant) the failures against the exact decision — the rational
//! Möller–Trumbore and slab tests on the same quantised inputs the model sees.
//!
//! Watertightness classes (rays at shared edges and vertices of a closed icosphere, rays from
//! inside it) also count *cracks*: cases where the exact decision hits the mesh but the model
//! hits none of the candidate triangles.

use crate::scene::icosphere;
use datapath::format::Edges;
use datapath::rng::SplitMix64;
use datapath::rti::{Rti, RtiConfig};
use datapath::slab::{Slab, SlabConfig};
use datapath::{with_format, AnyFormat, Format};
use golden::{Faces, Ray64, Tri64};
use serde::Serialize;
use vectors::gen::slab_rays;

pub mod cover;

/// What to run.
#[derive(Clone, Debug)]
pub struct StressConfig {
    /// Formats.
    pub formats: Vec<AnyFormat>,
    /// Slab variants.
    pub variants: Vec<String>,
    /// Cases per class.
    pub count: usize,
    /// Seed (case i of a class draws from its own stream derived from it).
    pub seed: u64,
    /// Threads and cases per chunk (the results do not depend on either).
    pub engine: engine::Engine,
    /// Show progress on stderr (when it is a terminal and the run lasts over a second).
    pub progress: bool,
}

/// Cases per chunk of `stress` on the engine.
pub const CHUNK_CASES: u64 = 16;

impl StressConfig {
    /// A configuration on every core, the default chunk, no progress output.
    pub fn new(formats: Vec<AnyFormat>, variants: Vec<String>, count: usize, seed: u64) -> Self {
        StressConfig { formats, variants, count, seed, engine: engine::Engine::new(CHUNK_CASES), progress: false }
    }
}

/// RTI stress classes.
pub const RTI_STRESS: [(&str, &str); 13] = [
    ("shared_edge", "from outside at a point of an edge shared by two triangles of a closed icosphere; must hit one"),
    ("shared_vertex", "from outside at a vertex of a closed icosphere, against its fan; must hit one"),
    ("inside_closed", "from inside a closed icosphere, random direction; must hit it"),
    ("near_parallel", "direction within ~1e-4 of the triangle's plane (|det| -> 0)"),
    ("tiny", "triangle of size 2^-20 near the origin"),
    ("needle", "triangle 1e-4 wide and 1 long"),
    ("far_from_origin", "triangle of size 2^-6 at distance ~2^9 from the origin, ray from near it"),
    ("t_near_zero", "origin within 2^-20 of the triangle's plane (self-intersection)"),
    ("axis_parallel", "axis-parallel direction (two components 0)"),
    ("subnormal", "coordinates around the format's smallest normal (subnormal operands and products)"),
    ("huge", "coordinates around max/2^8 of the format (overflowing products)"),
    ("signed_zero", "a third of the coordinates replaced by +0 or -0"),
    ("inf_nan", "one input +inf, -inf or NaN (no exact decision; the model's hits are counted)"),
];

/// Slab stress classes. The last seven hunt for the misses of a conservative variant at the
/// edges of the format: reciprocals that overflow or lose precision, subtracts that overflow
/// or saturate, and boxes at the format's maximum.
pub const SLAB_STRESS: [(&str, &str); 15] = [
    ("origin_on_face", "origin on a face plane, a direction component +0 or -0"),
    ("grazing", "aimed at a face, edge or corner point of the box"),
    ("inside", "origin inside the box"),
    ("zero_extent", "box of zero extent on one or more axes"),
    ("far_from_origin", "box of size 2^-6 at distance ~2^9"),
    ("tiny", "box of size 2^-20"),
    ("axis_parallel", "axis-parallel direction"),
    ("inf_nan", "one ray input +inf, -inf or NaN (no exact decision; the model's hits are counted)"),
    ("subnormal_d", "a direction component of 1 to 8 smallest steps (subnormal; 1/d overflows), the box's slab on that axis at t in [0.5, 4]"),
    ("tiny_d", "a direction component of 1 to 64 smallest normals (fixed point: steps), the box's slab at t in [0.5, 4]"),
    ("huge_d", "a direction component within 2^4 of the format's maximum (1/d subnormal or a few steps), the box at t ~ 1/|d|"),
    ("zero_inf_d", "direction components +0, -0, +inf or -inf (inf: no exact decision), origin inside, on a face or outside"),
    ("near_max", "box planes and origin near +-max on one axis: plane minus origin overflows (floats) or saturates (fixed point)"),
    ("max_planes", "box planes at exactly +-max on an axis, origin inside or outside"),
    ("mixed_edges", "two of the above edges at once on different axes"),
];

/// Failures of one RTI class in one format.
#[derive(Clone, Debug, PartialEq, Serialize, serde::Deserialize)]
pub struct RtiStressRow {
    /// Class.
    pub class: String,
    /// Format.
    pub format: String,
    /// Ray–triangle tests.
    pub tests: u64,
    /// Tests with a non-finite input after quantisation (no exact decision).
    pub undecided: u64,
    /// Exact hit, model miss.
    pub false_misses: u64,
    /// Exact miss, model hit.
    pub false_hits: u64,
    /// Model hits among the undecided tests.
    pub undecided_hits: u64,
    /// Watertightness cases whose exact decision hits the mesh but the model hits nothing.
    pub cracks: u64,
}

/// Failures of one slab class in one format and variant.
#[derive(Clone, Debug, PartialEq, Serialize, serde::Deserialize)]
pub struct SlabStressRow {
    /// Class.
    pub class: String,
    /// Format.
    pub format: String,
    /// Variant.
    pub variant: String,
    /// The variant promises never to miss in this format.
    pub conservative: bool,
    /// Ray–box tests.
    pub tests: u64,
    /// Cases whose box the format cannot store (fixed point beyond the range): not tested.
    pub unstorable: u64,
    /// Decided tests whose exact decision is a hit (the misses a conservative variant must not make).
    pub exact_hits: u64,
    /// Non-finite ray input (no exact decision).
    pub undecided: u64,
    /// Exact hit of the unrounded box, model miss.
    pub false_misses: u64,
    /// Exact miss, model hit.
    pub false_hits: u64,
    /// Model hits among the undecided tests.
    pub undecided_hits: u64,
}

/// The whole suite.
#[derive(Clone, Debug, PartialEq, Serialize, serde::Deserialize)]
pub struct StressReport {
    /// Seed.
    pub seed: u64,
    /// Cases per class.
    pub count: usize,
    /// RTI rows, class-major.
    pub rti: Vec<RtiStressRow>,
    /// Slab rows, class-major.
    pub slab: Vec<SlabStressRow>,
    /// Format–variant pairs not run: the variant promises conservativeness the format cannot give.
    pub refused: Vec<String>,
    /// No variant that promises conservativeness missed a box the exact decision hits.
    pub passed: bool,
}

/// One RTI case: a ray and candidate triangles; `mesh` marks a watertightness case.
struct Case {
    ray: Ray64,
    tris: Vec<Tri64>,
    mesh: bool,
}

fn unit(r: &mut SplitMix64) -> [f64; 3] {
    let z = r.range(-1.0, 1.0);
    let phi = r.range(0.0, std::f64::consts::TAU);
    let s = (1.0 - z * z).sqrt();
    [s * phi.cos(), s * phi.sin(), z]
}

fn ray(o: [f64; 3], d: [f64; 3]) -> Ray64 {
    Ray64 { o, d, tmin: 0.0, tmax: f64::INFINITY }
}

/// A ray from `o` through the point with barycentrics (b1, b2) of `t`.
fn aimed(o: [f64; 3], t: &Tri64, b1: f64, b2: f64) -> Ray64 {
    let p: [f64; 3] = std::array::from_fn(|a| t.v[0][a] + b1 * (t.v[1][a] - t.v[0][a]) + b2 * (t.v[2][a] - t.v[0][a]));
    ray(o, std::array::from_fn(|a| p[a] - o[a]))
}

fn random_tri(r: &mut SplitMix64, center: [f64; 3], size: f64) -> Tri64 {
    Tri64 { v: std::array::from_fn(|_| std::array::from_fn(|a| center[a] + size * r.range(-1.0, 1.0))) }
}

fn rti_case(class: usize, r: &mut SplitMix64, sphere: &[Tri64], min_normal: f64, max: f64) -> Case {
    let outside = |r: &mut SplitMix64| unit(r).map(|x| 3.0 * x);
    let single = |ray: Ray64, t: Tri64| Case { ray, tris: vec![t], mesh: false };
    match class {
        0 => {
            let (i, k) = (r.below(sphere.len() as u64) as usize, r.below(3) as usize);
            let t = &sphere[i];
            let (a, b) = (t.v[k], t.v[(k + 1) % 3]);
            let s = r.range(0.0, 1.0);
            let p: [f64; 3] = std::array::from_fn(|x| a[x] + s * (b[x] - a[x]));
            let o = outside(r);
            let tris = sphere.iter().filter(|u| u.v.contains(&a) && u.v.contains(&b)).copied().collect();
            Case { ray: ray(o, std::array::from_fn(|x| p[x] - o[x])), tris, mesh: true }
        }
        1 => {
            let p = sphere[r.below(sphere.len() as u64) as usize].v[r.below(3) as usize];
            let o = outside(r);
            let tris = sphere.iter().filter(|u| u.v.contains(&p)).copied().collect();
            Case { ray: ray(o, std::array::from_fn(|x| p[x] - o[x])), tris, mesh: true }
        }
        2 => Case { ray: ray(unit(r).map(|x| 0.5 * x), unit(r)), tris: sphere.to_vec(), mesh: true },
        3 => {
            let t = random_tri(r, [0.0; 3], 1.0);
            let e1: [f64; 3] = std::array::from_fn(|a| t.v[1][a] - t.v[0][a]);
            let e2: [f64; 3] = std::array::from_fn(|a| t.v[2][a] - t.v[0][a]);
            let n = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]];
            let (b1, b2) = (r.range(0.0, 0.5), r.range(0.0, 0.5));
            let p: [f64; 3] = std::array::from_fn(|a| t.v[0][a] + b1 * e1[a] + b2 * e2[a]);
            // along the plane (from an in-plane direction), lifted by ~1e-4 of the normal
            let (s, u) = (r.range(-2.0, 2.0), r.range(-2.0, 2.0));
            let eps = 1e-4 * r.range(-1.0, 1.0);
            let o: [f64; 3] = std::array::from_fn(|a| p[a] + s * e1[a] + u * e2[a] + eps * n[a]);
            single(ray(o, std::array::from_fn(|a| p[a] - o[a])), t)
        }
        4 => {
            let t = random_tri(r, [0.0; 3], (-20f64).exp2());
            single(aimed(unit(r), &t, r.range(-0.2, 1.0), r.range(-0.2, 1.0)), t)
        }
        5 => {
            let a = unit(r);
            let b: [f64; 3] = std::array::from_fn(|k| a[k] + unit(r)[k]);
            let c: [f64; 3] = std::array::from_fn(|k| b[k] + 1e-4 * r.range(-1.0, 1.0));
            let t = Tri64 { v: [a, b, c] };
            single(aimed(outside(r), &t, r.range(-0.1, 1.0), r.range(-0.1, 1.0)), t)
        }
        6 => {
            let c = unit(r).map(|x| 512.0 * x);
            let t = random_tri(r, c, (-6f64).exp2());
            let o: [f64; 3] = std::array::from_fn(|a| c[a] + unit(r)[a]);
            single(aimed(o, &t, r.range(-0.2, 1.0), r.range(-0.2, 1.0)), t)
        }
        7 => {
            let t = random_tri(r, [0.0; 3], 1.0);
            let mut rr = aimed([0.0; 3], &t, r.range(-0.2, 1.0), r.range(-0.2, 1.0));
            // origin = the aimed point plus a tiny offset, direction random
            rr.o = std::array::from_fn(|a| rr.d[a] + (-20f64).exp2() * r.range(-1.0, 1.0));
            rr.d = unit(r);
            single(rr, t)
        }
        8 => {
            let t = random_tri(r, [0.0; 3], 1.0);
            let a = r.below(3) as usize;
            let mut d = [0.0; 3];
            d[a] = if r.below(2) == 0 { 1.0 } else { -1.0 };
            let mut o: [f64; 3] = std::array::from_fn(|_| r.range(-0.5, 0.5));
            o[a] = -3.0 * d[a];
            single(ray(o, d), t)
        }
        9 | 10 => {
            let s = if class == 9 { min_normal * 4.0 } else { max / 256.0 };
            let t = random_tri(r, [0.0; 3], s);
            let o = unit(r).map(|x| 3.0 * s * x);
            single(aimed(o, &t, r.range(-0.2, 1.0), r.range(-0.2, 1.0)), t)
        }
        11 => {
            let t = random_tri(r, [0.0; 3], 1.0);
            let mut c = single(aimed(outside(r), &t, r.range(-0.2, 1.0), r.range(-0.2, 1.0)), t);
            let zap = |x: &mut f64, r: &mut SplitMix64| {
                if r.below(3) == 0 {
                    *x = if r.below(2) == 0 { 0.0 } else { -0.0 };
                }
            };
            c.ray.o.iter_mut().chain(c.ray.d.iter_mut()).for_each(|x| zap(x, r));
            c.tris[0].v.iter_mut().flatten().for_each(|x| zap(x, r));
            c
        }
        _ => {
            let t = random_tri(r, [0.0; 3], 1.0);
            let mut c = single(aimed(outside(r), &t, r.range(-0.2, 1.0), r.range(-0.2, 1.0)), t);
            let v = [f64::INFINITY, f64::NEG_INFINITY, f64::NAN][r.below(3) as usize];
            let i = r.below(15) as usize;
            if i < 3 {
                c.ray.o[i] = v;
            } else if i < 6 {
                c.ray.d[i - 3] = v;
            } else {
                c.tris[0].v[(i - 6) / 3][(i - 6) % 3] = v;
            }
            c
        }
    }
}

/// Stream number of the stress cases in [`SplitMix64::for_item`].
pub const STRESS_STREAM: u64 = 0x7374_7273; // "strs"

/// The generator of case `i` of `class` in `unit` (1: RTI, 2: slab):
/// `SplitMix64::for_item(seed ^ (unit << 32) ^ class, STRESS_STREAM, i)`, so any case can be
/// made without the cases before it.
pub fn case_rng(seed: u64, unit: u64, class: usize, i: u64) -> SplitMix64 {
    SplitMix64::for_item(seed ^ (unit << 32) ^ class as u64, STRESS_STREAM, i)
}

/// Runs `classes × count` cases on the engine: item j is case `j mod count` of class
/// `j / count`; `case(class, rng, counters)` adds one case's counts.
fn run_classes<const N: usize>(
    cfg: &StressConfig,
    unit: u64,
    classes: usize,
    what: String,
    case: impl Fn(usize, &mut SplitMix64, &mut [u64; N]) + Sync + Send,
) -> Vec<[u64; N]> {
    let count = cfg.count as u64;
    let items = classes as u64 * count;
    let progress = engine::Progress::new(cfg.engine.shard_items(items), "cases", !cfg.progress);
    progress.message(what);
    let acc: Vec<engine::Counts<N>> = engine::run(
        &cfg.engine,
        items,
        &progress,
        || (),
        |_, range| {
            let mut acc = vec![engine::Counts::<N>::default(); classes];
            for j in range {
                let class = (j / count) as usize;
                let mut r = case_rng(cfg.seed, unit, class, j % count);
                case(class, &mut r, &mut acc[class].0);
            }
            acc
        },
    );
    progress.finish();
    if acc.is_empty() {
        return vec![[0; N]; classes];
    }
    acc.into_iter().map(|c| c.0).collect()
}

fn rti_rows<F: Format>(f: F, cfg: &StressConfig) -> Vec<RtiStressRow> {
    let rti = Rti::new(f, RtiConfig::default());
    let sphere = icosphere([0.0; 3], 1.0, 2);
    let em = f.error_model();
    let min_normal = match f.kind() {
        datapath::format::FormatKind::Float(l) => l.min_normal(),
        datapath::format::FormatKind::Fixed { .. } => em.eta,
    };
    let q = |x: f64| f.to_f64(f.from_f64(x));
    // tests, undecided, false misses, false hits, undecided hits, cracks
    let counts = run_classes::<6>(cfg, 1, RTI_STRESS.len(), format!("rti {}", f.name()), |class, r, c| {
        let case = rti_case(class, r, &sphere, min_normal, em.max);
        let mray = rti.ray(case.ray.o, case.ray.d, case.ray.tmin, case.ray.tmax);
        let qray = Ray64 { o: case.ray.o.map(q), d: case.ray.d.map(q), tmin: q(case.ray.tmin), tmax: q(case.ray.tmax) };
        let (mut exact_any, mut model_any) = (false, false);
        for t in &case.tris {
            let hit = rti.test(&mray, &rti.tri(t.v)).hit;
            let qt = Tri64 { v: t.v.map(|p| p.map(q)) };
            c[0] += 1;
            model_any |= hit;
            match golden::intersect_exact(&qray, &qt, Faces::default()) {
                None => {
                    c[1] += 1;
                    c[4] += hit as u64;
                }
                Some(e) => {
                    exact_any |= e;
                    c[2] += (e && !hit) as u64;
                    c[3] += (!e && hit) as u64;
                }
            }
        }
        c[5] += (case.mesh && exact_any && !model_any) as u64;
    });
    counts
        .into_iter()
        .enumerate()
        .map(|(class, c)| RtiStressRow {
            class: RTI_STRESS[class].0.into(),
            format: f.name(),
            tests: c[0],
            undecided: c[1],
            false_misses: c[2],
            false_hits: c[3],
            undecided_hits: c[4],
            cracks: c[5],
        })
        .collect()
}

fn slab_case(class: usize, r: &mut SplitMix64, e: Edges) -> ([f64; 8], [f64; 3], [f64; 3]) {
    if class >= 8 {
        return slab_edge_case(class, r, e);
    }
    let (scale, center) = match class {
        4 => ((-6f64).exp2(), unit(r).map(|x| 512.0 * x)),
        5 => ((-20f64).exp2(), [0.0; 3]),
        _ => (1.0, [0.0; 3]),
    };
    let (lo, hi) = slab_rays::random_box(r, scale, center, class == 3);
    let mut o: [f64; 3] = std::array::from_fn(|a| center[a] + scale * r.range(-2.0, 2.0));
    let mut d = unit(r);
    match class {
        0 => slab_rays::origin_on_face(r, &lo, &hi, &mut o, &mut d),
        1 => d = slab_rays::toward_surface(r, &lo, &hi, &o),
        2 => o = slab_rays::inside(r, &lo, &hi),
        6 => {
            d = [0.0; 3];
            let a = r.below(3) as usize;
            d[a] = if r.below(2) == 0 { 1.0 } else { -1.0 };
            for b in (0..3).filter(|&b| b != a) {
                o[b] = r.range(lo[b] - 0.1 * scale, hi[b] + 0.1 * scale);
            }
        }
        7 => {
            let i = r.below(6) as usize;
            let v = [f64::INFINITY, f64::NEG_INFINITY, f64::NAN][r.below(3) as usize];
            if i < 3 {
                o[i] = v;
            } else {
                d[i - 3] = v;
            }
        }
        _ => {}
    }
    ([o[0], o[1], o[2], d[0], d[1], d[2], 0.0, f64::INFINITY], lo, hi)
}

/// A random sign.
fn sign(r: &mut SplitMix64) -> f64 {
    if r.below(2) == 0 {
        1.0
    } else {
        -1.0
    }
}

/// The edge classes (8 and up): a ray that hits a box on the ordinary axes at t* and whose
/// special axis (or two) is built from the format's scales.
fn slab_edge_case(class: usize, r: &mut SplitMix64, e: Edges) -> ([f64; 8], [f64; 3], [f64; 3]) {
    // t stays well inside every format's range (q1.F holds t < 1)
    let tcap = (e.max / 2.0).min(8.0);
    let (t1, t2) = {
        let a = r.range(0.0625, 0.5) * tcap;
        (a, a * r.range(1.0, 2.0))
    };
    let tmid = (t1 + t2) / 2.0;
    // ordinary axes: a box of half-width w around the point the ray reaches at tmid
    let w = (e.max / 8.0).min(1.0) * r.range(0.05, 0.5);
    let mut lo = [0.0; 3];
    let mut hi = [0.0; 3];
    let mut o = [0.0; 3];
    let mut d = [0.0; 3];
    for a in 0..3 {
        let p = r.range(-0.5, 0.5) * w;
        lo[a] = p - w;
        hi[a] = p + w;
        d[a] = r.range(-1.0, 1.0) * w / tcap;
        o[a] = p - d[a] * tmid;
    }
    let kinds: Vec<usize> = if class == 14 {
        let k1 = 8 + r.below(6) as usize;
        let k2 = 8 + r.below(6) as usize;
        vec![k1, k2]
    } else {
        vec![class]
    };
    let first = r.below(3) as usize;
    for (j, &kind) in kinds.iter().enumerate() {
        let a = (first + j) % 3;
        match kind {
            // tiny components: the slab at t in [t1, t2] scaled by d
            8 | 9 => {
                let k = if kind == 8 { e.least * (1.0 + r.below(8) as f64) } else { e.min_normal * r.range(1.0, 64.0) };
                let da = sign(r) * k;
                d[a] = da;
                o[a] = 0.0;
                let (x, y) = (da * t1, da * t2);
                (lo[a], hi[a]) = (x.min(y), x.max(y));
            }
            // huge components: the box at t ~ 1/|d|, i.e. one unit or so from the origin
            10 => {
                let da = sign(r) * e.max * (-(r.range(0.0, 4.0))).exp2();
                d[a] = da;
                o[a] = 0.0;
                let u = (e.max / 4.0).min(2.0);
                let (x, y) = (da.signum() * u * r.range(0.1, 0.5), da.signum() * u * r.range(0.5, 1.0));
                (lo[a], hi[a]) = (x.min(y), x.max(y));
            }
            // zero and infinite components, the origin inside, on a face or outside
            11 => {
                d[a] = if r.below(10) < 7 { sign(r) * 0.0 } else { sign(r) * f64::INFINITY };
                o[a] = match r.below(3) {
                    0 => r.range(lo[a], hi[a]),
                    1 => {
                        if r.below(2) == 0 {
                            lo[a]
                        } else {
                            hi[a]
                        }
                    }
                    _ => hi[a] + w * r.range(0.01, 1.0),
                };
            }
            // planes near +-max, the origin near the opposite end: b - o beyond the range
            12 => {
                let s = sign(r);
                if r.below(2) == 0 {
                    // a box beyond the middle, the origin near the opposite end
                    let (x, y) = (r.range(0.3, 0.9) * e.max, r.range(0.3, 0.9) * e.max);
                    (lo[a], hi[a]) = if s > 0.0 { (x.min(y), x.max(y)) } else { (-x.max(y), -x.min(y)) };
                    o[a] = -s * r.range(0.3, 0.95) * e.max;
                } else {
                    // a box across the middle, the origin on (or just before) its near plane:
                    // the far plane's difference exceeds the range
                    let (x, y) = (r.range(0.55, 0.95) * e.max, r.range(0.55, 0.95) * e.max);
                    (lo[a], hi[a]) = (-x, y);
                    let before = if r.below(2) == 0 { 0.0 } else { r.range(0.0, 0.04) * e.max };
                    o[a] = if s > 0.0 { lo[a] - before } else { hi[a] + before };
                    // leave the slab just after tmid, and cross the other axes' slabs in a
                    // narrow window around tmid: a shrunken exit misses them
                    let far = if s > 0.0 { hi[a] } else { lo[a] };
                    d[a] = ((far - o[a]) / (1.1 * tmid)).clamp(-e.max, e.max);
                    if kinds.len() == 1 {
                        for b in (0..3).filter(|&b| b != a) {
                            d[b] = sign(r) * w * r.range(2.0, 4.0) / tmid;
                            o[b] = (lo[b] + hi[b]) / 2.0 - d[b] * tmid;
                        }
                    }
                    continue;
                }
                // reach the middle of the slab at tmid
                d[a] = ((lo[a] + hi[a]) / 2.0 - o[a]) / tmid;
                d[a] = d[a].clamp(-e.max, e.max);
            }
            // planes at exactly +-max
            _ => {
                (lo[a], hi[a]) = match r.below(3) {
                    0 => (-e.max, e.max),
                    1 => (r.range(0.0, 0.5) * e.max, e.max),
                    _ => (-e.max, -r.range(0.0, 0.5) * e.max),
                };
                o[a] =
                    if r.below(2) == 0 { r.range(lo[a], hi[a]) } else { -hi[a].signum() * r.range(0.5, 1.0) * e.max };
                d[a] = (((lo[a] + hi[a]) / 2.0 - o[a]) / tmid).clamp(-e.max, e.max);
            }
        }
    }
    ([o[0], o[1], o[2], d[0], d[1], d[2], 0.0, f64::INFINITY], lo, hi)
}

fn slab_rows<F: Format>(f: F, sc: SlabConfig, variant: &str, cfg: &StressConfig) -> Vec<SlabStressRow> {
    let s = Slab::new(f, sc);
    let edges = datapath::format::edges(&f);
    let q = |x: f64| f.to_f64(f.from_f64(x));
    // tests, undecided, unstorable, exact hits, false misses, false hits, undecided hits
    let what = format!("slab {} {variant}", f.name());
    let counts = run_classes::<7>(cfg, 2, SLAB_STRESS.len(), what, |class, r, c| {
        let (x, lo, hi) = slab_case(class, r, edges);
        // the box corners as the format holds them, so that a point on a face (origin or aim)
        // stays on it after quantisation; store_box keeps them exactly
        let (lo, hi) = (lo.map(q), hi.map(q));
        let Ok(b) = s.store_box(lo, hi) else {
            c[2] += 1;
            return;
        };
        let sr = s.prepare([x[0], x[1], x[2]], [x[3], x[4], x[5]], x[6], x[7]);
        let hit = s.test(&sr, &b).hit;
        c[0] += 1;
        let (oq, dq) = ([q(x[0]), q(x[1]), q(x[2])], [q(x[3]), q(x[4]), q(x[5])]);
        let exact = if oq.iter().chain(&dq).any(|v| !v.is_finite()) {
            None
        } else {
            golden::slab_exact(oq, dq, q(x[6]), q(x[7]), lo, hi)
        };
        let Some(e) = exact else {
            c[1] += 1;
            c[6] += hit as u64;
            return;
        };
        c[3] += e as u64;
        c[4] += (e && !hit) as u64;
        c[5] += (!e && hit) as u64;
    });
    counts
        .into_iter()
        .enumerate()
        .map(|(class, c)| SlabStressRow {
            class: SLAB_STRESS[class].0.into(),
            format: f.name(),
            variant: variant.into(),
            conservative: sc.is_conservative(&f),
            tests: c[0],
            undecided: c[1],
            unstorable: c[2],
            exact_hits: c[3],
            false_misses: c[4],
            false_hits: c[5],
            undecided_hits: c[6],
        })
        .collect()
}

impl StressReport {
    /// Adds another shard's report of the same run (every row's counts; `passed` again).
    pub fn merge(&mut self, o: StressReport) -> Result<(), String> {
        let rkey = |r: &RtiStressRow| (r.class.clone(), r.format.clone());
        let skey = |r: &SlabStressRow| (r.class.clone(), r.format.clone(), r.variant.clone(), r.conservative);
        if self.rti.iter().map(rkey).ne(o.rti.iter().map(rkey))
            || self.slab.iter().map(skey).ne(o.slab.iter().map(skey))
            || (self.seed, self.count, &self.refused) != (o.seed, o.count, &o.refused)
        {
            return Err("partials disagree on the stress classes".into());
        }
        for (a, b) in self.rti.iter_mut().zip(o.rti) {
            a.tests += b.tests;
            a.undecided += b.undecided;
            a.false_misses += b.false_misses;
            a.false_hits += b.false_hits;
            a.undecided_hits += b.undecided_hits;
            a.cracks += b.cracks;
        }
        for (a, b) in self.slab.iter_mut().zip(o.slab) {
            a.tests += b.tests;
            a.unstorable += b.unstorable;
            a.exact_hits += b.exact_hits;
            a.undecided += b.undecided;
            a.false_misses += b.false_misses;
            a.false_hits += b.false_hits;
            a.undecided_hits += b.undecided_hits;
        }
        self.passed = self.slab.iter().all(|x| !x.conservative || x.false_misses == 0);
        Ok(())
    }
}

impl crate::partial::Consistent for StressReport {
    /// Every row's counts within their totals, each slab class's tests and unstorable boxes
    /// those of the shard's cases of that class (one box per case), and `passed` what the
    /// rows say.
    fn check(&self, share: &dyn Fn(u64, u64) -> u64) -> Result<(), String> {
        self.check_rows(Some(share))
    }
}

impl crate::partial::Sharded for StressReport {
    const COMMAND: &'static str = "stress";
    type Report = StressReport;
    fn add(&mut self, other: Self) -> Result<(), String> {
        self.merge(other)
    }
    fn finish(self) -> Result<StressReport, String> {
        Ok(self)
    }
    fn render(r: &StressReport) -> String {
        render(r)
    }
    fn outcome(r: &StressReport) -> crate::Outcome {
        crate::Outcome::from(r.passed)
    }
}

impl StressReport {
    /// Checks the rows ([`crate::partial::Consistent`]); the slab class totals only with `share`.
    pub fn check_rows(&self, share: Option<&dyn Fn(u64, u64) -> u64>) -> Result<(), String> {
        use crate::partial::require;
        for r in &self.rti {
            let decided = r.tests.saturating_sub(r.undecided);
            require(
                r.undecided <= r.tests && r.false_misses + r.false_hits <= decided && r.undecided_hits <= r.undecided,
                || format!("rti {} {}: counts do not fit: {r:?}", r.class, r.format),
            )?;
        }
        let count = self.count as u64;
        for r in &self.slab {
            let decided = r.tests.saturating_sub(r.undecided);
            require(
                r.undecided <= r.tests
                    && r.exact_hits <= decided
                    && r.false_misses <= r.exact_hits
                    && r.false_hits <= decided - r.exact_hits
                    && r.undecided_hits <= r.undecided,
                || format!("slab {} {} {}: counts do not fit: {r:?}", r.class, r.format, r.variant),
            )?;
            if let Some(share) = share {
                let class = SLAB_STRESS
                    .iter()
                    .position(|c| c.0 == r.class)
                    .ok_or_else(|| format!("slab class {} does not exist", r.class))?
                    as u64;
                let want = share(class * count, (class + 1) * count);
                require(r.tests + r.unstorable == want, || {
                    format!(
                        "slab {} {} {}: {} tests + {} unstorable boxes, but the shard ran {want} cases of the class",
                        r.class, r.format, r.variant, r.tests, r.unstorable
                    )
                })?;
            }
        }
        let passed = self.slab.iter().all(|x| !x.conservative || x.false_misses == 0);
        require(self.passed == passed, || format!("passed is {} but the rows say {passed}", self.passed))
    }
}

/// The options that change a stress run's results, for a partial's `args`.
pub fn args(cfg: &StressConfig) -> serde_json::Value {
    serde_json::json!({
        "formats": cfg.formats.iter().map(|f| f.to_string()).collect::<Vec<_>>(),
        "variants": cfg.variants,
        "count": cfg.count,
        "seed": cfg.seed,
    })
}

/// Runs the suite.
pub fn stress(cfg: &StressConfig) -> Result<StressReport, String> {
    if cfg.count == 0 {
        return Err("--count must be at least 1".into());
    }
    let mut rti = Vec::new();
    let mut slab = Vec::new();
    let mut refused = Vec::new();
    for v in &cfg.variants {
        SlabConfig::named(v)?;
    }
    for f in &cfg.formats {
        rti.extend(with_format!(*f, |f| rti_rows(f, cfg)));
        for v in &cfg.variants {
            let named = SlabConfig::named(v)?;
            match with_format!(*f, |f| named.for_format(v, &f)) {
                Ok(sc) => slab.extend(with_format!(*f, |f| slab_rows(f, sc, v, cfg))),
                Err(why) => refused.push(why),
            }
        }
    }
    let passed = slab.iter().all(|x| !x.conservative || x.false_misses == 0);
    Ok(StressReport { seed: cfg.seed, count: cfg.count, rti, slab, refused, passed })
}

/// The report as markdown tables.
pub fn render(r: &StressReport) -> String {
    let mut s = format!("raypipe stress: {} cases per class, seed {}\n\n", r.count, r.seed);
    s += "| RTI class | format | tests | false misses | false hits | cracks | undecided (model hits) |\n|---|---|---:|---:|---:|---:|---:|\n";
    for x in &r.rti {
        s += &format!(
            "| {} | {} | {} | {} | {} | {} | {} ({}) |\n",
            x.class, x.format, x.tests, x.false_misses, x.false_hits, x.cracks, x.undecided, x.undecided_hits
        );
    }
    s += "\n| slab class | format | variant | tests | exact hits | false misses | false hits | undecided (model hits) | unstorable |\n|---|---|---|---:|---:|---:|---:|---:|---:|\n";
    for x in &r.slab {
        let flag = if x.conservative && x.false_misses > 0 { " VIOLATION" } else { "" };
        s += &format!(
            "| {} | {} | {} | {} | {} | {}{flag} | {} | {} ({}) | {} |\n",
            x.class,
            x.format,
            x.variant,
            x.tests,
            x.exact_hits,
            x.false_misses,
            x.false_hits,
            x.undecided,
            x.undecided_hits,
            x.unstorable
        );
    }
    for why in &r.refused {
        s += &format!("\nnot run: {why}\n");
    }
    s += &format!(
        "\nproperty (no conservative or directed variant misses a box the exact decision hits): {}\n",
        if r.passed { "PASS" } else { "FAIL" }
    );
    s
}
