//! `raypipe verify`: every chosen format's RTI model against the golden reference on a scene's
//! rays, with the property check (decisive cases must agree; t within its bound), error
//! statistics and model throughput.

use crate::judge::{judge, Judged};
use crate::scene::Scene;
use datapath::rti::{Capture, Rti, RtiConfig};
use datapath::{with_format, AnyFormat, Format};
use golden::{Ray64, Tri64};
use serde::Serialize;
use std::time::Instant;

/// What to run.
#[derive(Clone, Debug)]
pub struct VerifyConfig {
    /// Formats to verify.
    pub formats: Vec<AnyFormat>,
    /// Number of rays.
    pub rays: usize,
    /// Seed of the ray generator.
    pub seed: u64,
    /// RTI options.
    pub rti: RtiConfig,
    /// Scenes with at most this many triangles are tested exhaustively per ray; larger ones
    /// test each ray against its target triangle and `sample - 1` seeded random others.
    pub sample: usize,
}

/// Results for one format.
#[derive(Clone, Debug, Serialize)]
pub struct FormatReport {
    /// Format name.
    pub format: String,
    /// Bits per value.
    pub width: u32,
    /// Ray–triangle tests run.
    pub tests: u64,
    /// Tests whose error bound makes the decision certain.
    pub decisive: u64,
    /// Golden hits.
    pub golden_hits: u64,
    /// Model hits.
    pub model_hits: u64,
    /// Model miss where the golden hits.
    pub false_misses: u64,
    /// Model hit where the golden misses.
    pub false_hits: u64,
    /// Property failures (must be 0).
    pub violations: u64,
    /// Tests where both hit.
    pub shared_hits: u64,
    /// Median |t − t_golden| in units of the format's ulp at t_golden.
    pub t_err_ulps_median: f64,
    /// Largest |t − t_golden| in ulps.
    pub t_err_ulps_max: f64,
    /// Median |t − t_golden| / |t_golden|.
    pub t_err_rel_median: f64,
    /// Largest relative t error.
    pub t_err_rel_max: f64,
    /// Rays whose min-capture result names a different triangle (or hit/miss) than the golden closest hit.
    pub closest_disagreements: u64,
    /// Throughput of the fastest bit-identical batch path (the SIMD kernel for f32 / fp16),
    /// fed from the scene in L1-sized chunks, gather included: million tests per second (one thread).
    pub mtests_per_s: f64,
    /// Tests whose valid bit was cleared at stage 7: the work a valid-gated divide stage (and
    /// everything after it) skips.
    pub divide_skipped: u64,
    /// The first property failure, as an `explain` command line.
    pub first_violation: Option<String>,
}

/// The whole run.
#[derive(Clone, Debug, Serialize)]
pub struct VerifyReport {
    /// Scene name.
    pub scene: String,
    /// Triangles in the scene.
    pub triangles: usize,
    /// The power of two applied to the scene's coordinates.
    pub scale: f64,
    /// Rays cast.
    pub rays: usize,
    /// Ray seed.
    pub seed: u64,
    /// Triangles tested per ray.
    pub tests_per_ray: usize,
    /// Per-format results.
    pub formats: Vec<FormatReport>,
    /// Slab unit results per format and variant.
    pub slab: Vec<SlabReport>,
    /// No property failed.
    pub passed: bool,
    /// Formats in which no test was decisive: the property was not tested there.
    pub inconclusive: Vec<String>,
}

impl VerifyReport {
    /// The exit outcome: a failure, else inconclusive when a format had no decisive test.
    pub fn outcome(&self) -> crate::Outcome {
        match (self.passed, self.inconclusive.is_empty()) {
            (false, _) => crate::Outcome::Fail,
            (true, false) => crate::Outcome::Inconclusive,
            (true, true) => crate::Outcome::Pass,
        }
    }
}

/// The (ray, triangle) test list: per ray, the triangles it is tested against.
fn test_lists(scene: &Scene, rays: &[(Ray64, usize)], sample: usize, seed: u64) -> Vec<Vec<usize>> {
    let n = scene.tris.len();
    if n <= sample {
        return rays.iter().map(|_| (0..n).collect()).collect();
    }
    let mut r = datapath::rng::SplitMix64::new(seed ^ 0x7e57);
    rays.iter()
        .map(|&(_, target)| {
            let mut v = vec![target];
            v.extend((1..sample).map(|_| r.below(n as u64) as usize));
            v
        })
        .collect()
}

fn explain_cmd(fmt: &str, ray: &Ray64, tri: &Tri64, scale: f64) -> String {
    let j = |xs: &[f64]| xs.iter().map(|x| format!("{x:?}")).collect::<Vec<_>>().join(",");
    let tv: Vec<f64> = tri.v.iter().flatten().copied().collect();
    format!(
        "raypipe explain --format {fmt} --ray {},{} --tri {}  # scene coordinates x {scale:?}",
        j(&ray.o),
        j(&ray.d),
        j(&tv)
    )
}

fn median(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// One ray's share of a format report: counts (tests, decisive, golden hits, model hits,
/// false misses, false hits, violations, shared hits, closest-hit disagreements, divides
/// skipped), t errors and the first violation.
#[derive(Default)]
struct RayAcc {
    c: [u64; 10],
    ulps: Vec<f64>,
    rels: Vec<f64>,
    first_violation: Option<String>,
}

fn run_format<F: Format>(
    fmt: F,
    cfg: &VerifyConfig,
    scene: &Scene,
    rays: &[(Ray64, usize)],
    lists: &[Vec<usize>],
) -> FormatReport {
    let rti = Rti::new(fmt, cfg.rti);
    let name = rti.fmt.name();
    let mut rep = FormatReport {
        format: name.clone(),
        width: rti.fmt.width(),
        tests: 0,
        decisive: 0,
        golden_hits: 0,
        model_hits: 0,
        false_misses: 0,
        false_hits: 0,
        violations: 0,
        shared_hits: 0,
        t_err_ulps_median: 0.0,
        t_err_ulps_max: 0.0,
        t_err_rel_median: 0.0,
        t_err_rel_max: 0.0,
        closest_disagreements: 0,
        divide_skipped: 0,
        mtests_per_s: 0.0,
        first_violation: None,
    };
    let faces = crate::judge::faces(&rti);
    // rays in parallel, merged in ray order: the report does not depend on the thread count
    let per_ray = |(ray, _): &(Ray64, usize), list: &Vec<usize>| {
        let mut acc = RayAcc::default();
        let mray = rti.ray(ray.o, ray.d, ray.tmin, ray.tmax);
        let mut cap = Capture::default();
        let (rq, _) = crate::judge::quantise(&rti, ray, &scene.tris[0]);
        let mut qtris = Vec::with_capacity(list.len());
        for (k, &ti) in list.iter().enumerate() {
            let tri = &scene.tris[ti];
            let j: Judged = judge(&rti, ray, tri);
            acc.c[0] += 1;
            acc.c[1] += j.decisive as u64;
            acc.c[2] += j.golden.hit as u64;
            acc.c[3] += j.hit as u64;
            acc.c[4] += (j.golden.hit && !j.hit) as u64;
            acc.c[5] += (!j.golden.hit && j.hit) as u64;
            if let Some(why) = j.violation() {
                acc.c[6] += 1;
                if acc.first_violation.is_none() {
                    acc.first_violation = Some(format!("{why}: {}", explain_cmd(&name, ray, tri, scene.scale)));
                }
            }
            if j.hit && j.golden.hit {
                acc.c[7] += 1;
                acc.ulps.push(j.t_error() / j.ulp);
                acc.rels.push(j.t_error() / j.golden.t.abs().max(f64::MIN_POSITIVE));
            }
            let out = rti.test(&mray, &rti.tri(tri.v));
            acc.c[9] += !out.valid as u64;
            rti.capture(&mut cap, &out, k as u32);
            qtris.push(crate::judge::quantise(&rti, ray, tri).1);
        }
        let g = golden::closest_hit(&rq, &qtris, faces);
        let same = match (g, cap.hit) {
            (None, false) => true,
            (Some((gi, _)), true) => list[gi] == list[cap.id as usize],
            _ => false,
        };
        acc.c[8] += !same as u64;
        acc
    };
    let parts: Vec<RayAcc> = {
        use rayon::prelude::*;
        rays.par_iter().zip(lists.par_iter()).map(|(r, l)| per_ray(r, l)).collect()
    };
    let (mut ulps, mut rels) = (Vec::new(), Vec::new());
    let mut c = [0u64; 10];
    for p in parts {
        for (a, b) in c.iter_mut().zip(p.c) {
            *a += b;
        }
        ulps.extend(p.ulps);
        rels.extend(p.rels);
        if rep.first_violation.is_none() {
            rep.first_violation = p.first_violation;
        }
    }
    [
        rep.tests,
        rep.decisive,
        rep.golden_hits,
        rep.model_hits,
        rep.false_misses,
        rep.false_hits,
        rep.violations,
        rep.shared_hits,
        rep.closest_disagreements,
        rep.divide_skipped,
    ] = c;
    rep.t_err_ulps_max = ulps.iter().copied().fold(0.0, f64::max);
    rep.t_err_rel_max = rels.iter().copied().fold(0.0, f64::max);
    rep.t_err_ulps_median = median(&mut ulps);
    rep.t_err_rel_median = median(&mut rels);
    rep.mtests_per_s = throughput(&rti, scene, rays, lists);
    rep
}

/// Times the fastest bit-identical batch path (the SIMD kernels for f32 / fp16, the scalar
/// model otherwise) over every test of the run, one thread, streamed through L1-sized chunks
/// gathered from the scene: million tests per second, the gather included.
fn throughput<F: Format + 'static>(rti: &Rti<F>, scene: &Scene, rays: &[(Ray64, usize)], lists: &[Vec<usize>]) -> f64
where
    F::V: 'static + Default,
{
    let pairs: Vec<(usize, usize)> =
        lists.iter().enumerate().flat_map(|(r, list)| list.iter().map(move |&t| (r, t))).collect();
    let mrays: Vec<_> = rays.iter().map(|(ray, _)| rti.ray(ray.o, ray.d, ray.tmin, ray.tmax)).collect();
    let mtris: Vec<_> = scene.tris.iter().map(|t| rti.tri(t.v)).collect();
    let mut sink = 0usize;
    let t0 = Instant::now();
    datapath::simd::rti_stream(
        rti,
        pairs.len(),
        |range, rs, ts| {
            for (k, &(r, t)) in pairs[range].iter().enumerate() {
                rs.set(k, &mrays[r]);
                ts.set(k, &mtris[t]);
            }
        },
        |_, _, _, out| sink += out.hit.iter().filter(|&&h| h).count(),
    );
    let secs = t0.elapsed().as_secs_f64();
    std::hint::black_box(sink);
    if secs > 0.0 {
        pairs.len() as f64 / secs / 1e6
    } else {
        0.0
    }
}

/// Runs every format on the scene.
pub fn verify(cfg: &VerifyConfig, scene: &Scene) -> VerifyReport {
    let rays = scene.rays(cfg.rays, cfg.seed);
    let lists = test_lists(scene, &rays, cfg.sample, cfg.seed);
    let formats: Vec<FormatReport> =
        cfg.formats.iter().map(|f| with_format!(*f, |f| run_format(f, cfg, scene, &rays, &lists))).collect();
    let slab = verify_slab(cfg, scene);
    let slab_ok = slab.iter().all(|r| !r.conservative || r.false_misses == 0);
    VerifyReport {
        scene: scene.name.clone(),
        triangles: scene.tris.len(),
        scale: scene.scale,
        rays: rays.len(),
        seed: cfg.seed,
        tests_per_ray: lists.first().map_or(0, Vec::len),
        passed: formats.iter().all(|f| f.violations == 0) && slab_ok,
        inconclusive: formats.iter().filter(|f| f.decisive == 0).map(|f| f.format.clone()).collect(),
        formats,
        slab,
    }
}

/// The report as a text table.
pub fn render(r: &VerifyReport) -> String {
    let mut s = format!(
        "raypipe verify: scene {} ({} triangles, coordinates x {:?}), {} rays, seed {}, {} tests per ray\n\n",
        r.scene, r.triangles, r.scale, r.rays, r.seed, r.tests_per_ray
    );
    s += &format!(
        "{:<16} {:>9} {:>9} {:>8} {:>8} {:>7} {:>7} {:>6} {:>10} {:>10} {:>9} {:>9} {:>8} {:>9}\n",
        "format",
        "tests",
        "decisive",
        "g-hits",
        "m-hits",
        "f-miss",
        "f-hit",
        "viol",
        "t ulp med",
        "t ulp max",
        "t rel med",
        "t rel max",
        "closest≠",
        "Mtests/s"
    );
    for f in &r.formats {
        s += &format!(
            "{:<16} {:>9} {:>9} {:>8} {:>8} {:>7} {:>7} {:>6} {:>10.3} {:>10.3} {:>9.2e} {:>9.2e} {:>8} {:>9.2}\n",
            f.format,
            f.tests,
            f.decisive,
            f.golden_hits,
            f.model_hits,
            f.false_misses,
            f.false_hits,
            f.violations,
            f.t_err_ulps_median,
            f.t_err_ulps_max,
            f.t_err_rel_median,
            f.t_err_rel_max,
            f.closest_disagreements,
            f.mtests_per_s
        );
    }
    s += "\nf-miss/f-hit: model vs golden f64 on the same quantised inputs; viol: decisive tests (error bound clear of every threshold) where hit/miss differs or the t error exceeds its bound.\n";
    s += "skipped work: tests whose valid bit clears at stage 7, so a valid-gated divide stage skips them: ";
    s += &r
        .formats
        .iter()
        .map(|f| format!("{} {:.1}%", f.format, 100.0 * f.divide_skipped as f64 / f.tests.max(1) as f64))
        .collect::<Vec<_>>()
        .join(", ");
    s += "\n";
    s += &render_slab(&r.slab);
    if r.passed && !r.inconclusive.is_empty() {
        s += &format!(
            "property: INCONCLUSIVE: no decisive test in {} (every test's error bound straddles a threshold: degenerate triangles, or coordinates too large for the format): the run proved nothing there\n",
            r.inconclusive.join(", ")
        );
    } else if r.passed {
        s += "property: PASS (no violations)\n";
    } else {
        s += "property: FAIL\n";
        for f in r.formats.iter().filter(|f| f.violations > 0) {
            s += &format!(
                "  {}: {} violations; first: {}\n",
                f.format,
                f.violations,
                f.first_violation.as_deref().unwrap_or("")
            );
        }
    }
    s
}

/// Slab results for one format and variant.
#[derive(Clone, Debug, Serialize)]
pub struct SlabReport {
    /// Format name.
    pub format: String,
    /// Variant name.
    pub variant: String,
    /// The variant promises zero false misses.
    pub conservative: bool,
    /// Ray–box tests run.
    pub tests: u64,
    /// Exact hits (rational decision on the quantised ray and the original box).
    pub exact_hits: u64,
    /// Model miss where the exact test hits.
    pub false_misses: u64,
    /// Model hit where the exact test misses.
    pub false_hits: u64,
    /// Tests settled by the exact rational decision (near the boundary or disagreeing with f64).
    pub exact_calls: u64,
    /// Throughput of the fastest bit-identical batch path (the SIMD kernel for f32 / fp16), million tests per second (one thread).
    pub mtests_per_s: f64,
}

/// Runs the slab unit on every (ray, box) pair: the boxes are the bounding boxes of the
/// triangles each ray is tested against (axis-aligned walls give zero-extent boxes).
pub fn verify_slab(cfg: &VerifyConfig, scene: &Scene) -> Vec<SlabReport> {
    let rays = scene.rays(cfg.rays, cfg.seed);
    let lists = test_lists(scene, &rays, cfg.sample, cfg.seed);
    let boxes: Vec<([f64; 3], [f64; 3])> = scene
        .tris
        .iter()
        .map(|t| {
            let lo = std::array::from_fn(|a| t.v.iter().map(|p| p[a]).fold(f64::INFINITY, f64::min));
            let hi = std::array::from_fn(|a| t.v.iter().map(|p| p[a]).fold(f64::NEG_INFINITY, f64::max));
            (lo, hi)
        })
        .collect();
    let mut out = Vec::new();
    for f in &cfg.formats {
        // only the variants the format accepts (a conservative promise it cannot keep is refused)
        for v in with_format!(*f, |f| datapath::slab::SlabConfig::variants_for(&f)) {
            let sc = datapath::slab::SlabConfig::named(v).expect("built-in variant");
            out.push(with_format!(*f, |f| slab_one(f, v, sc, &rays, &lists, &boxes)));
        }
    }
    out
}

fn slab_one<F: Format>(
    f: F,
    name: &str,
    sc: datapath::slab::SlabConfig,
    rays: &[(Ray64, usize)],
    lists: &[Vec<usize>],
    boxes: &[([f64; 3], [f64; 3])],
) -> SlabReport {
    use datapath::slab::{BoxesSoa, Slab, SlabOutSoa, SlabRaysSoa};
    let s = Slab::new(f, sc);
    let stored: Vec<_> = boxes.iter().map(|(lo, hi)| s.store_box(*lo, *hi).unwrap_or_else(|_| s.empty_box())).collect();
    let mut rep = SlabReport {
        format: f.name(),
        variant: name.to_string(),
        conservative: sc.is_conservative(&f),
        tests: 0,
        exact_hits: 0,
        false_misses: 0,
        false_hits: 0,
        exact_calls: 0,
        mtests_per_s: 0.0,
    };
    // decisions per ray in parallel (the exact rational test is the slow part), summed in order
    let per_ray = |(ray, _): &(Ray64, usize), list: &Vec<usize>| {
        let mut c = [0u64; 5]; // tests, exact hits, false misses, false hits, exact calls
        let sr = s.prepare(ray.o, ray.d, ray.tmin, ray.tmax);
        let q = |x: f64| f.to_f64(f.from_f64(x));
        let (oq, dq) = (ray.o.map(q), ray.d.map(q));
        for &i in list {
            let (lo, hi) = boxes[i];
            let hit = s.test(&sr, &stored[i]).hit;
            let g = golden::slab_f64(oq, dq, q(ray.tmin), q(ray.tmax), lo, hi);
            let scale = 1.0f64.max(g.t_near.abs()).max(if g.t_far.is_finite() { g.t_far.abs() } else { 0.0 });
            let close = (g.t_far - g.t_near).abs() <= 1e-9 * scale;
            let exact = if close || g.hit != hit {
                c[4] += 1;
                // verify's rays and boxes are finite; a ray that overflowed the format has no
                // exact decision and counts as the f64 reference says
                golden::slab_exact(oq, dq, q(ray.tmin), q(ray.tmax), lo, hi).unwrap_or(g.hit)
            } else {
                g.hit
            };
            c[0] += 1;
            c[1] += exact as u64;
            c[2] += (exact && !hit) as u64;
            c[3] += (!exact && hit) as u64;
        }
        c
    };
    let parts: Vec<[u64; 5]> = {
        use rayon::prelude::*;
        rays.par_iter().zip(lists.par_iter()).map(|(r, l)| per_ray(r, l)).collect()
    };
    let c = parts.iter().fold([0u64; 5], |a, p| std::array::from_fn(|k| a[k] + p[k]));
    [rep.tests, rep.exact_hits, rep.false_misses, rep.false_hits, rep.exact_calls] = c;
    // the timed single-thread batch over the same pairs
    let (mut rs, mut bs) = (SlabRaysSoa::default(), BoxesSoa::default());
    for ((ray, _), list) in rays.iter().zip(lists) {
        let sr = s.prepare(ray.o, ray.d, ray.tmin, ray.tmax);
        for &i in list {
            rs.push(&sr);
            bs.push(&stored[i]);
        }
    }
    let mut out = SlabOutSoa::with_len(rs.tmin.len());
    // one untimed pass first (the output pages are faulted in), then the best of three
    datapath::simd::slab_batch(&s, &rs, &bs, &mut out);
    let secs = (0..3)
        .map(|_| {
            let t0 = Instant::now();
            datapath::simd::slab_batch(&s, &rs, &bs, &mut out);
            t0.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min);
    std::hint::black_box(&out);
    rep.mtests_per_s = if secs > 0.0 { rep.tests as f64 / secs / 1e6 } else { 0.0 };
    rep
}

/// The slab results as a text table.
pub fn render_slab(rows: &[SlabReport]) -> String {
    let mut s = format!(
        "\nslab (BVI) unit: boxes = bounding boxes of the tested triangles; false misses / hits against the exact rational decision\n\n{:<16} {:<14} {:>9} {:>9} {:>8} {:>8} {:>9}\n",
        "format", "variant", "tests", "exact-hit", "f-miss", "f-hit", "Mtests/s"
    );
    for r in rows {
        s += &format!(
            "{:<16} {:<14} {:>9} {:>9} {:>8} {:>8} {:>9.2}{}\n",
            r.format,
            r.variant,
            r.tests,
            r.exact_hits,
            r.false_misses,
            r.false_hits,
            r.mtests_per_s,
            if r.conservative && r.false_misses > 0 { "  <- VIOLATION: conservative variant missed" } else { "" }
        );
    }
    s
}
