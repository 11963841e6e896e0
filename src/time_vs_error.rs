//! `raypipe report`: every variant on the same inputs — random rays on the scenes and the
//! stress classes — as run time per test against error, with the Pareto front marked.
//!
//! RTI error: hit/miss disagreements with the exact rational decision on the quantised inputs
//! (scene rays against their target and sampled triangles, plus the decided stress tests), and
//! the t error (ulps, relative) on shared hits from `verify`. Slab error: false misses and
//! false hits against the exact decision (`verify`'s slab table plus the stress classes).
//! Time, one thread: RTI — the fastest bit-identical implementation (the SIMD kernels for
//! binary32 / binary16, the scalar batch otherwise) on 512 cached pairs; slab — the fastest
//! bit-identical batch (the SIMD kernels for binary32 / binary16 but the directed variant) over
//! the scenes' pairs, weighted.

use crate::scene::Scene;
use crate::stress::{stress, StressConfig, StressReport};
use crate::verify::{VerifyConfig, VerifyData};
use datapath::rng::SplitMix64;
use datapath::rti::{Rti, RtiConfig};
use datapath::{with_format, AnyFormat, Format};
use golden::{Faces, Ray64, Tri64};
use serde::{Deserialize, Serialize};

/// What to run.
#[derive(Clone, Debug)]
pub struct ReportConfig {
    /// Formats.
    pub formats: Vec<AnyFormat>,
    /// Slab variants.
    pub variants: Vec<String>,
    /// Rays per scene.
    pub rays: u64,
    /// Stress cases per class.
    pub stress_count: usize,
    /// Seed.
    pub seed: u64,
    /// The engine (threads, shard) of every streamed part.
    pub engine: engine::Engine,
}

/// One variant's point.
#[derive(Clone, Debug, Serialize)]
pub struct Point {
    /// "rti" or "slab".
    pub unit: String,
    /// Format (and slab variant).
    pub variant: String,
    /// Bits per value.
    pub width: u32,
    /// Single-thread time per test, ns (see the module notes).
    pub ns_per_test: f64,
    /// Decided tests (scenes and stress).
    pub tests: u64,
    /// Exact hit, model miss.
    pub false_misses: u64,
    /// Exact miss, model hit.
    pub false_hits: u64,
    /// (false misses + false hits) / tests.
    pub error_rate: f64,
    /// RTI: median t error on shared hits, ulps of the format (largest over the scenes).
    pub t_err_ulps_median: f64,
    /// RTI: largest t error, ulps.
    pub t_err_ulps_max: f64,
    /// RTI: largest relative t error.
    pub t_err_rel_max: f64,
    /// No other variant of the unit is at least as fast and at least as accurate, and better in one.
    pub pareto: bool,
}

impl Point {
    /// A point with nothing measured yet.
    fn new(unit: &str, variant: String, f: AnyFormat) -> Self {
        Point {
            unit: unit.into(),
            variant,
            width: with_format!(f, |f| f.width()),
            ns_per_test: 0.0,
            tests: 0,
            false_misses: 0,
            false_hits: 0,
            error_rate: 0.0,
            t_err_ulps_median: 0.0,
            t_err_ulps_max: 0.0,
            t_err_rel_max: 0.0,
            pareto: false,
        }
    }
}

/// The report.
#[derive(Clone, Debug, Serialize)]
pub struct Report {
    /// Scenes.
    pub scenes: Vec<String>,
    /// Rays per scene.
    pub rays: u64,
    /// Stress cases per class.
    pub stress_count: usize,
    /// Seed.
    pub seed: u64,
    /// Points, RTI first.
    pub points: Vec<Point>,
    /// Format–variant pairs not run: the variant promises conservativeness the format cannot give.
    pub refused: Vec<String>,
    /// The command line (set by the CLI; empty from the library).
    #[serde(default)]
    pub command: String,
    /// The machine the timings were taken on (CPU model, cores, ISA).
    #[serde(default)]
    pub machine: String,
}

/// Scene rays against their target and 31 sampled triangles: (tests, false misses, false hits)
/// against the exact decision on the quantised inputs, over the engine's shard of the rays
/// (ray i samples its triangles from `SplitMix64::new(seed ^ i · 0x9e3779b97f4a7c15)`).
fn exact_rti<F: Format>(f: F, scene: &Scene, rays: u64, seed: u64, eng: &engine::Engine) -> [u64; 3] {
    let rti = Rti::new(f, RtiConfig::default());
    let q = |x: f64| f.to_f64(f.from_f64(x));
    let gen = scene.ray_gen(seed);
    let n = scene.tris.len() as u64;
    let acc = engine::run(
        eng,
        rays,
        &engine::Progress::off(),
        || (),
        |_, range| {
            let mut c = engine::Counts::<3>::default();
            for i in range {
                let (ray, target) = gen.ray(scene, i);
                let mut r = SplitMix64::new(seed ^ i.wrapping_mul(0x9e37_79b9_7f4a_7c15));
                let mut ids = vec![target];
                ids.extend((0..31.min(n as usize - 1)).map(|_| r.below(n) as usize));
                let mray = rti.ray(ray.o, ray.d, ray.tmin, ray.tmax);
                let qray = Ray64 { o: ray.o.map(q), d: ray.d.map(q), tmin: q(ray.tmin), tmax: q(ray.tmax) };
                for &t in &ids {
                    let tri = &scene.tris[t];
                    let hit = rti.test(&mray, &rti.tri(tri.v)).hit;
                    let Some(e) =
                        golden::intersect_exact(&qray, &Tri64 { v: tri.v.map(|p| p.map(q)) }, Faces::default())
                    else {
                        continue;
                    };
                    c.0[0] += 1;
                    c.0[1] += (e && !hit) as u64;
                    c.0[2] += (!e && hit) as u64;
                }
            }
            c
        },
    );
    acc.0
}

fn mark_pareto(points: &mut [Point]) {
    let snapshot: Vec<(String, f64, f64)> =
        points.iter().map(|p| (p.unit.clone(), p.ns_per_test, p.error_rate)).collect();
    for p in points.iter_mut() {
        p.pareto = !snapshot.iter().any(|(u, t, e)| {
            *u == p.unit && *t <= p.ns_per_test && *e <= p.error_rate && (*t < p.ns_per_test || *e < p.error_rate)
        });
    }
}

/// What a report run accumulates (a shard's partial result): the stress suite, and per format
/// its RTI kernel rate (measured by the shard: a timing) and, per scene, the verify data and the
/// exact-decision counts.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReportData {
    /// Scene names.
    pub scenes: Vec<String>,
    /// Formats, by name.
    pub formats: Vec<String>,
    /// Slab variants.
    pub variants: Vec<String>,
    /// Rays per scene.
    pub rays: u64,
    /// Stress cases per class.
    pub stress_count: usize,
    /// Seed.
    pub seed: u64,
    /// The stress suite.
    pub stress: StressReport,
    /// Per format: the fastest bit-identical RTI implementation's rate (million tests/s).
    pub rti_rate: Vec<f64>,
    /// Per format, per scene: verify's data.
    pub verify: Vec<Vec<VerifyData>>,
    /// Per format, per scene: exact-decision tests, false misses, false hits.
    pub exact: Vec<Vec<[u64; 3]>>,
}

impl ReportData {
    /// Adds another shard's data of the same run (the rate: the faster measurement).
    pub fn merge(&mut self, o: ReportData) -> Result<(), String> {
        if (&self.scenes, &self.formats, &self.variants) != (&o.scenes, &o.formats, &o.variants) {
            return Err("partials disagree on the scenes, formats or variants".into());
        }
        self.stress.merge(o.stress)?;
        for (a, b) in self.rti_rate.iter_mut().zip(o.rti_rate) {
            *a = a.max(b);
        }
        for (a, b) in self.verify.iter_mut().zip(o.verify) {
            for (x, y) in a.iter_mut().zip(b) {
                x.merge(y)?;
            }
        }
        for (a, b) in self.exact.iter_mut().zip(o.exact) {
            for (x, y) in a.iter_mut().zip(b) {
                for k in 0..3 {
                    x[k] += y[k];
                }
            }
        }
        Ok(())
    }
}

impl crate::partial::Sharded for ReportData {
    const COMMAND: &'static str = "report";
    type Report = Report;
    fn add(&mut self, other: Self) -> Result<(), String> {
        self.merge(other)
    }
    fn finish(self) -> Result<Report, String> {
        finish(self)
    }
    fn render(r: &Report) -> String {
        markdown(r)
    }
    fn outcome(_: &Report) -> crate::Outcome {
        crate::Outcome::Pass
    }
}

impl crate::partial::Consistent for ReportData {
    /// The stress rows and every scene's verify data consistent in themselves (their shares
    /// of the run use their own chunk sizes, so totals are not checked here), one entry per
    /// format and scene, and exact-decision mismatches within the exact-decision tests.
    fn check(&self, _share: &dyn Fn(u64, u64) -> u64) -> Result<(), String> {
        use crate::partial::require;
        self.stress.check_rows(None)?;
        let (nf, ns) = (self.formats.len(), self.scenes.len());
        require(
            self.rti_rate.len() == nf
                && self.verify.len() == nf
                && self.exact.len() == nf
                && self.verify.iter().all(|v| v.len() == ns)
                && self.exact.iter().all(|v| v.len() == ns),
            || format!("not one entry per format ({nf}) and scene ({ns})"),
        )?;
        for v in self.verify.iter().flatten() {
            v.check_formats(None)?;
        }
        for [tests, fm, fh] in self.exact.iter().flatten() {
            require(fm + fh <= *tests, || format!("exact decisions: {fm} + {fh} mismatches exceed {tests} tests"))?;
        }
        Ok(())
    }
}

/// The options that change a report's results, for a partial's `args`.
pub fn args(cfg: &ReportConfig, scenes: &[Scene]) -> serde_json::Value {
    serde_json::json!({
        "formats": cfg.formats.iter().map(|f| f.to_string()).collect::<Vec<_>>(),
        "variants": cfg.variants,
        "rays": cfg.rays,
        "stress_count": cfg.stress_count,
        "seed": cfg.seed,
        "scenes": scenes.iter().map(crate::partial::scene_hash).collect::<Vec<_>>(),
    })
}

/// Runs every variant on every scene and the stress classes.
pub fn report(cfg: &ReportConfig, scenes: &[Scene]) -> Result<Report, String> {
    finish(accumulate(cfg, scenes)?)
}

/// Runs the engine's shard of every part.
pub fn accumulate(cfg: &ReportConfig, scenes: &[Scene]) -> Result<ReportData, String> {
    if scenes.is_empty() || cfg.rays == 0 {
        return Err("report needs at least one scene and one ray".into());
    }
    let mut scfg = StressConfig::new(cfg.formats.clone(), cfg.variants.clone(), cfg.stress_count.max(1), cfg.seed);
    scfg.engine = engine::Engine { chunk: crate::stress::CHUNK_CASES, ..cfg.engine };
    let st = stress(&scfg)?;
    let mut vcfg = VerifyConfig::new(cfg.formats.clone(), cfg.rays, cfg.seed, RtiConfig::default(), 512);
    vcfg.engine = engine::Engine { chunk: crate::verify::CHUNK_RAYS, ..cfg.engine };
    let mut verify = Vec::new();
    let mut exact = Vec::new();
    let mut rti_rate = Vec::new();
    for f in &cfg.formats {
        // time: the fastest bit-identical implementation (SIMD kernel where one applies)
        rti_rate.push(crate::speed::rti_rate(*f, 512, cfg.seed));
        let one = VerifyConfig { formats: vec![*f], ..vcfg.clone() };
        verify.push(scenes.iter().map(|s| crate::verify::accumulate(&one, s)).collect());
        exact.push(
            scenes.iter().map(|s| with_format!(*f, |f| exact_rti(f, s, cfg.rays, cfg.seed, &vcfg.engine))).collect(),
        );
    }
    Ok(ReportData {
        scenes: scenes.iter().map(|s| s.name.clone()).collect(),
        formats: cfg.formats.iter().map(|f| f.to_string()).collect(),
        variants: cfg.variants.clone(),
        rays: cfg.rays,
        stress_count: cfg.stress_count,
        seed: cfg.seed,
        stress: st,
        rti_rate,
        verify,
        exact,
    })
}

/// The report of (merged) data.
pub fn finish(d: ReportData) -> Result<Report, String> {
    let formats: Vec<AnyFormat> = d.formats.iter().map(|f| f.parse()).collect::<Result<_, _>>()?;
    let st = &d.stress;
    let mut points = Vec::new();
    // per format, per scene: the verify report (RTI row and slab rows)
    let reports: Vec<Vec<crate::verify::VerifyReport>> =
        d.verify.iter().map(|per| per.iter().map(|v| crate::verify::finish(v.clone())).collect()).collect();
    for (k, f) in formats.iter().enumerate() {
        let name = f.name();
        let mut p = Point::new("rti", name.clone(), *f);
        p.ns_per_test = 1e3 / d.rti_rate[k].max(1e-9);
        for (v, e) in reports[k].iter().zip(&d.exact[k]) {
            let r = &v.formats[0];
            p.t_err_ulps_median = p.t_err_ulps_median.max(r.t_err_ulps_median);
            p.t_err_ulps_max = p.t_err_ulps_max.max(r.t_err_ulps_max);
            p.t_err_rel_max = p.t_err_rel_max.max(r.t_err_rel_max);
            p.tests += e[0];
            p.false_misses += e[1];
            p.false_hits += e[2];
        }
        for x in st.rti.iter().filter(|x| x.format == name) {
            p.tests += x.tests - x.undecided;
            p.false_misses += x.false_misses;
            p.false_hits += x.false_hits;
        }
        p.error_rate = (p.false_misses + p.false_hits) as f64 / p.tests.max(1) as f64;
        points.push(p);
    }
    for (k, f) in formats.iter().enumerate() {
        let name = f.name();
        for v in &d.variants {
            let named = datapath::slab::SlabConfig::named(v)?;
            // a variant that cannot keep its promise in this format is not run (stress names it)
            if with_format!(*f, |f| named.for_format(v, &f)).is_err() {
                continue;
            }
            let mut p = Point::new("slab", format!("{name} {v}"), *f);
            let (mut time, mut timed) = (0.0, 0u64);
            for rep in &reports[k] {
                for r in rep.slab.iter().filter(|r| &r.variant == v) {
                    time += r.tests as f64 * 1e3 / r.mtests_per_s.max(1e-9);
                    timed += r.tests;
                    p.tests += r.tests;
                    p.false_misses += r.false_misses;
                    p.false_hits += r.false_hits;
                }
            }
            for x in st.slab.iter().filter(|x| x.format == name && &x.variant == v) {
                p.tests += x.tests - x.undecided;
                p.false_misses += x.false_misses;
                p.false_hits += x.false_hits;
            }
            p.ns_per_test = time / timed.max(1) as f64;
            p.error_rate = (p.false_misses + p.false_hits) as f64 / p.tests.max(1) as f64;
            points.push(p);
        }
    }
    mark_pareto(&mut points);
    Ok(Report {
        scenes: d.scenes,
        rays: d.rays,
        stress_count: d.stress_count,
        seed: d.seed,
        points,
        refused: st.refused.clone(),
        command: String::new(),
        machine: crate::machine::machine(),
    })
}

/// The report as README-ready markdown.
pub fn markdown(r: &Report) -> String {
    let mut s = String::new();
    if !r.command.is_empty() {
        s += &format!(
            "`{}` on {} (ns/test is measured there; every other column is a count).\n\n",
            r.command, r.machine
        );
    }
    s += &format!(
        "Scenes: {}; {} rays per scene, {} stress cases per class, seed {}. Pareto: ★.\n\n",
        r.scenes.join(", "),
        r.rays,
        r.stress_count,
        r.seed
    );
    s += "| unit | variant | bits | ns/test | tests | false misses | false hits | error rate | t err median / max (ulps) | t err rel max | Pareto |\n";
    s += "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|:-:|\n";
    for p in &r.points {
        let terr = if p.unit == "rti" {
            format!("{:.2} / {:.3e}", p.t_err_ulps_median, p.t_err_ulps_max)
        } else {
            "–".into()
        };
        let rel = if p.unit == "rti" { format!("{:.2e}", p.t_err_rel_max) } else { "–".into() };
        s += &format!(
            "| {} | {} | {} | {:.1} | {} | {} | {} | {:.2e} | {} | {} | {} |\n",
            p.unit,
            p.variant,
            p.width,
            p.ns_per_test,
            p.tests,
            p.false_misses,
            p.false_hits,
            p.error_rate,
            terr,
            rel,
            if p.pareto { "★" } else { "" }
        );
    }
    for why in &r.refused {
        s += &format!("\nnot run: {why}\n");
    }
    s
}

/// Writes `report.md`, `report.json`, `report_rti.svg` and `report_slab.svg` into `dir`.
pub fn write(r: &Report, out: &vectors::outdir::OutDir) -> Result<Vec<std::path::PathBuf>, String> {
    let mut written = vec![out.write("report.md", markdown(r).as_bytes())?];
    let json = serde_json::to_string_pretty(r).map_err(|e| e.to_string())? + "\n";
    written.push(out.write("report.json", json.as_bytes())?);
    for unit in ["rti", "slab"] {
        let pts: Vec<&Point> = r.points.iter().filter(|p| p.unit == unit).collect();
        if pts.is_empty() {
            continue;
        }
        let name = format!("report_{unit}.svg");
        let svg = plot(unit, &pts).map_err(|e| format!("{name}: {e}"))?;
        written.push(out.write(&name, svg.as_bytes())?);
    }
    Ok(written)
}

/// The files [`write`] may write (checked before the work starts).
pub const FILES: [&str; 4] = ["report.md", "report.json", "report_rti.svg", "report_slab.svg"];

/// Error rates below this (none seen) are drawn at it.
const ERR_FLOOR: f64 = 1e-7;

/// One unit's plot: time per test against error rate, both on log scales, the Pareto front in
/// red, every point labelled beside its dot where that overlaps no other dot or label, and
/// named under the plot otherwise.
fn plot(unit: &str, pts: &[&Point]) -> Result<String, String> {
    let mut svg = String::new();
    draw(unit, pts, &mut svg)?;
    Ok(svg)
}

/// [`plot`]'s drawing, into `svg`.
fn draw(unit: &str, pts: &[&Point], svg: &mut String) -> Result<(), String> {
    use plotters::prelude::*;
    let err = |e: &dyn std::fmt::Display| e.to_string();
    let (w, h) = (900u32, 560u32);
    let x = |p: &Point| p.ns_per_test.max(1e-3).log10();
    let y = |p: &Point| p.error_rate.max(ERR_FLOOR).log10();
    let span = |v: Vec<f64>, pad: f64| {
        let (lo, hi) = v.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &c| (a.min(c), b.max(c)));
        (lo - pad)..(hi + pad).max(lo + 2.0 * pad)
    };
    let xs = span(pts.iter().map(|p| x(p)).collect(), 0.25);
    let ys = span(pts.iter().map(|p| y(p)).collect(), 0.3);
    // one significant digit where the axis spans decades, two where it spans less
    let digits = if ys.end - ys.start < 2.0 { 1 } else { 0 };
    let root = SVGBackend::with_string(svg, (w, h)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(format!("{unit}: time per test vs error (Pareto front in red)"), ("sans-serif", 18))
        .margin(14)
        .x_label_area_size(56)
        .y_label_area_size(70)
        .build_cartesian_2d(xs, ys)
        .map_err(|e| err(&e))?;
    let pow = |v: &f64| {
        let e = 10f64.powf(*v);
        if e >= 10.0 {
            format!("{e:.0}")
        } else {
            format!("{e:.2}")
        }
    };
    let floor = format!("{ERR_FLOOR:.0e} = none seen");
    chart
        .configure_mesh()
        .x_desc("ns per test (one thread, log scale)")
        .y_desc(format!("error rate (log scale; {floor})"))
        .x_label_formatter(&pow)
        .y_label_formatter(&|v| format!("{:.*e}", digits, 10f64.powf(*v)))
        .draw()
        .map_err(|e| err(&e))?;
    let mut front: Vec<(f64, f64)> = pts.iter().filter(|p| p.pareto).map(|p| (x(p), y(p))).collect();
    front.sort_by(|a, b| a.0.total_cmp(&b.0));
    chart.draw_series(LineSeries::new(front, RED.stroke_width(2))).map_err(|e| err(&e))?;
    // labels: at the first of six offsets whose box overlaps no dot and no placed label; a
    // point with none free is named in a line under the plot instead. The Pareto points are
    // placed first, then the fastest
    let at: Vec<(f64, f64)> = pts.iter().map(|p| (x(p), y(p))).collect();
    let px: Vec<(i32, i32)> = at.iter().map(|c| chart.backend_coord(c)).collect();
    let mut placed: Vec<(i32, i32, i32, i32)> = px.iter().map(|&(x, y)| (x - 5, y - 5, x + 5, y + 5)).collect();
    let mut order: Vec<usize> = (0..pts.len()).collect();
    order.sort_by(|&a, &b| pts[b].pareto.cmp(&pts[a].pareto).then(pts[a].ns_per_test.total_cmp(&pts[b].ns_per_test)));
    let mut crowded = Vec::new();
    for i in order {
        let p = pts[i];
        let ((x0, y0), (tw, th)) = (px[i], (6 * p.variant.chars().count() as i32, 12));
        let free = [(7, -6), (7, 6), (7, -18), (7, 18), (-tw - 7, -6), (-tw - 7, 6)].into_iter().find(|&(dx, dy)| {
            let r = (x0 + dx, y0 + dy, x0 + dx + tw, y0 + dy + th);
            r.2 < w as i32 && r.0 > 0 && !placed.iter().any(|q| r.0 < q.2 && q.0 < r.2 && r.1 < q.3 && q.1 < r.3)
        });
        let c = if p.pareto { RED } else { BLUE };
        let dot = EmptyElement::at(at[i]) + Circle::new((0, 0), 4, c.filled());
        match free {
            Some((dx, dy)) => {
                placed.push((x0 + dx, y0 + dy, x0 + dx + tw, y0 + dy + th));
                let label = Text::new(p.variant.clone(), (dx, dy), ("sans-serif", 11));
                chart.draw_series(std::iter::once(dot + label)).map_err(|e| err(&e))?;
            }
            None => {
                chart.draw_series(std::iter::once(dot)).map_err(|e| err(&e))?;
                crowded.push(p.variant.as_str());
            }
        }
    }
    if !crowded.is_empty() {
        let note = format!("not labelled (crowded): {}", crowded.join(", "));
        root.draw(&Text::new(note, (14, h as i32 - 16), ("sans-serif", 10))).map_err(|e| err(&e))?;
    }
    root.present().map_err(|e| err(&e))?;
    Ok(())
}
