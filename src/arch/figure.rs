//! `raypipe arch`: figure 3-3 of the thesis (execution time against leaf size for several
//! pipeline counts) from the throughput model on a scene's real traversals, the check of the
//! thesis's conclusion (the fastest leaf size lies between n/2 and n), and the calibration
//! against the thesis's two headline figures (1.35 G RTI/s, ~50 M rays/s).

use super::{estimate, gather, ArchParams, Estimate, SceneEvents};
use crate::scene::Scene;
use serde::Serialize;

/// The thesis's RTI throughput (ch. 6): 1.35 G RTI tests per second.
pub const THESIS_RTI_RATE: f64 = 1.35e9;
/// The thesis's traversal throughput (ch. 5): about 50 M rays per second at 200 MHz.
pub const THESIS_TRAV_RATE: f64 = 50e6;
/// The back traversals per ray the thesis's traversal figure assumes (ch. 5: "about 4").
pub const THESIS_BACK_TRAVERSALS: f64 = 4.0;

/// What to sweep.
#[derive(Clone, Debug)]
pub struct ArchConfig {
    /// Base parameters (their `pipelines` is the calibration's pipeline count).
    pub params: ArchParams,
    /// Pipeline counts of the figure.
    pub pipelines: Vec<u32>,
    /// Leaf sizes of the figure (1..=255).
    pub leaf_sizes: Vec<u32>,
    /// Rays (half primary, half random, as `raypipe stats`).
    pub rays: u64,
    /// Random-ray seed.
    pub seed: u64,
}

/// The events of one leaf size, summarised.
#[derive(Clone, Debug, Serialize)]
pub struct LeafSizeEvents {
    /// Triangles per leaf at most.
    pub leaf_size: u32,
    /// Leaves.
    pub leaves: usize,
    /// Tree levels below the root.
    pub depth: usize,
    /// Rays with a hit.
    pub rays_hit: u64,
    /// RTI tests the rays need.
    pub rti_tests: u64,
    /// Mean rays per tested leaf (figure 3-1).
    pub rays_per_leaf: f64,
    /// Mean traversal passes per ray (restarts + 1).
    pub passes_per_ray: f64,
}

/// The fastest leaf size of one pipeline count.
#[derive(Clone, Debug, Serialize)]
pub struct Optimum {
    /// RTI pipelines.
    pub pipelines: u32,
    /// The thesis's recommended leaf sizes: ⌈n/2⌉..=n.
    pub rule: [u32; 2],
    /// The swept leaf size with the least total time (the smaller on a tie).
    pub leaf_size: u32,
    /// Its total time in seconds.
    pub total_s: f64,
    /// It lies in the thesis's range.
    pub within_rule: bool,
    /// The swept leaf size with the least RTI time alone.
    pub rti_leaf_size: u32,
    /// That one lies in the thesis's range.
    pub rti_within_rule: bool,
}

/// The model against the thesis's headline figures.
#[derive(Clone, Debug, Serialize)]
pub struct Calibration {
    /// The thesis's RTI rate (tests/s).
    pub thesis_rti_rate: f64,
    /// The model's peak RTI rate with the base parameters (n · f · b / c).
    pub peak_rti_rate: f64,
    /// Pipelines whose peak reaches the thesis's rate at the base clock and interleave.
    pub pipelines_for_thesis_rate: u32,
    /// The model's sustained RTI rate on the scene (base pipelines, their fastest leaf size).
    pub sustained_rti_rate: f64,
    /// Its share of the peak.
    pub sustained_share: f64,
    /// The thesis's traversal rate (rays/s).
    pub thesis_trav_rate: f64,
    /// The model's rate for rays of 1 + 4 passes (the thesis's "about 4 back traversals").
    pub trav_rate_at_thesis_back_traversals: f64,
    /// The passes per ray that give the thesis's rate with the base clock and ports.
    pub passes_for_thesis_rate: f64,
    /// The model's traversal rate on the scene (base parameters, same leaf size).
    pub scene_trav_rate: f64,
    /// The scene's passes per ray at that leaf size.
    pub scene_passes_per_ray: f64,
}

/// The whole run.
#[derive(Clone, Debug, Serialize)]
pub struct ArchReport {
    /// Scene.
    pub scene: String,
    /// Triangles.
    pub triangles: usize,
    /// Rays.
    pub rays: u64,
    /// Seed.
    pub seed: u64,
    /// Base parameters.
    pub params: ArchParams,
    /// Events per leaf size.
    pub events: Vec<LeafSizeEvents>,
    /// One estimate per (leaf size, pipeline count), leaf size major.
    pub rows: Vec<Estimate>,
    /// Per pipeline count, the fastest leaf size.
    pub optima: Vec<Optimum>,
    /// Against the thesis.
    pub calibration: Calibration,
}

/// The events of every leaf size (one tree build and traversal each).
pub fn sweep_events(
    eng: &engine::Engine,
    scene: &Scene,
    leaf_sizes: &[u32],
    rays: u64,
    seed: u64,
) -> Result<Vec<SceneEvents>, String> {
    let gen = crate::traverse::CameraRays::new(scene, rays as usize, seed);
    leaf_sizes
        .iter()
        .map(|&ls| {
            let b = crate::bvh::build(scene, ls);
            gather(eng, scene, &b, ls, rays, |k| gen.ray(k))
        })
        .collect()
}

/// The least-total-time estimate (the first on a tie) and the least-RTI-time one.
fn best<'a>(rows: impl Iterator<Item = &'a Estimate> + Clone) -> Option<(&'a Estimate, &'a Estimate)> {
    // `min_by` keeps the first of equal minima
    let by = |f: fn(&Estimate) -> f64| rows.clone().min_by(|a, b| f(a).total_cmp(&f(b)));
    Some((by(|e| e.total_s)?, by(|e| e.rti_s)?))
}

/// Runs the sweep.
pub fn arch(eng: &engine::Engine, cfg: &ArchConfig, scene: &Scene) -> Result<ArchReport, String> {
    cfg.params.check()?;
    if cfg.pipelines.is_empty() || cfg.leaf_sizes.is_empty() {
        return Err("give at least one pipeline count and one leaf size".into());
    }
    for &n in &cfg.pipelines {
        ArchParams { pipelines: n, ..cfg.params.clone() }.check()?;
    }
    let mut leaf_sizes = cfg.leaf_sizes.clone();
    leaf_sizes.sort_unstable();
    leaf_sizes.dedup();
    let events = sweep_events(eng, scene, &leaf_sizes, cfg.rays, cfg.seed)?;
    let mut rows = Vec::new();
    for e in &events {
        for &n in &cfg.pipelines {
            rows.push(estimate(&ArchParams { pipelines: n, ..cfg.params.clone() }, e));
        }
    }
    let optima = cfg
        .pipelines
        .iter()
        .map(|&n| {
            let (t, r) = best(rows.iter().filter(|e| e.pipelines == n)).expect("a leaf size per pipeline count");
            let rule = [n.div_ceil(2), n];
            let within = |l: u32| (rule[0]..=rule[1]).contains(&l);
            Optimum {
                pipelines: n,
                rule,
                leaf_size: t.leaf_size,
                total_s: t.total_s,
                within_rule: within(t.leaf_size),
                rti_leaf_size: r.leaf_size,
                rti_within_rule: within(r.leaf_size),
            }
        })
        .collect();
    // calibration at the base parameters and their fastest leaf size
    let base: Vec<Estimate> = events.iter().map(|e| estimate(&cfg.params, e)).collect();
    let (b, _) = best(base.iter()).expect("a leaf size");
    let be = events.iter().find(|e| e.leaf_size == b.leaf_size).expect("the leaf sizes are distinct");
    let p = &cfg.params;
    let peak = p.rti_peak();
    let per_pipeline = peak / p.pipelines as f64;
    let entry = p.trav_mhz * 1e6 * p.ports as f64;
    let calibration = Calibration {
        thesis_rti_rate: THESIS_RTI_RATE,
        peak_rti_rate: peak,
        pipelines_for_thesis_rate: (THESIS_RTI_RATE / per_pipeline).ceil() as u32,
        sustained_rti_rate: b.rti_rate,
        sustained_share: b.rti_rate / peak,
        thesis_trav_rate: THESIS_TRAV_RATE,
        trav_rate_at_thesis_back_traversals: entry / (1.0 + THESIS_BACK_TRAVERSALS),
        passes_for_thesis_rate: entry / THESIS_TRAV_RATE,
        scene_trav_rate: b.trav_rate,
        scene_passes_per_ray: be.passes_per_ray(),
    };
    let events = events
        .iter()
        .map(|e| {
            let tested = e.leaf_rays.iter().filter(|&&r| r > 0).count() as u64;
            LeafSizeEvents {
                leaf_size: e.leaf_size,
                leaves: e.leaf_tris.len(),
                depth: e.depth,
                rays_hit: e.rays_hit,
                rti_tests: e.rti_tests(),
                rays_per_leaf: e.leaf_rays.iter().sum::<u64>() as f64 / tested.max(1) as f64,
                passes_per_ray: e.passes_per_ray(),
            }
        })
        .collect();
    Ok(ArchReport {
        scene: scene.name.clone(),
        triangles: scene.tris.len(),
        rays: cfg.rays,
        seed: cfg.seed,
        params: cfg.params.clone(),
        events,
        rows,
        optima,
        calibration,
    })
}

/// The report as text tables.
pub fn render(r: &ArchReport) -> String {
    let p = &r.params;
    let mut s = format!(
        "raypipe arch: scene {} ({} triangles), {} rays (half primary, half random), seed {}\n\
         RTI: {} MHz, {} ray buffers, triangle every {} cycles, latency {}, DRAM {} B/cycle \
         (ray {} B, result {} B){}; traversal: {} MHz, {} level pipelines x {} cycles, {} port(s)\n\n",
        r.scene,
        r.triangles,
        r.rays,
        r.seed,
        p.rti_mhz,
        p.buffers,
        p.cadence(),
        p.rti_latency,
        p.dram_bytes_per_cycle,
        p.ray_bytes,
        p.result_bytes,
        if p.overlap_io { ", I/O overlapped" } else { "" },
        p.trav_mhz,
        p.levels,
        p.level_latency,
        p.ports
    );
    s += "leaf size  leaves  levels   RTI tests  rays/leaf  passes/ray\n";
    for e in &r.events {
        s += &format!(
            "{:>9} {:>7} {:>7} {:>11} {:>10.2} {:>11.3}\n",
            e.leaf_size, e.leaves, e.depth, e.rti_tests, e.rays_per_leaf, e.passes_per_ray
        );
    }
    let ns: Vec<u32> = r.optima.iter().map(|o| o.pipelines).collect();
    s += "\nfig. 3-3: modelled time in microseconds (traversal + RTI) against leaf size\nleaf size";
    for n in &ns {
        s += &format!(" {:>12}", format!("n={n}"));
    }
    s += "\n";
    for e in &r.events {
        s += &format!("{:>9}", e.leaf_size);
        for n in &ns {
            let est = r.rows.iter().find(|x| x.leaf_size == e.leaf_size && x.pipelines == *n).expect("a row");
            s += &format!(" {:>12.1}", est.total_s * 1e6);
        }
        s += "\n";
    }
    s += "\nfastest leaf size per pipeline count (the thesis: between n/2 and n)\n";
    s += "pipelines  rule      total: leaf size  in rule   RTI alone: leaf size  in rule\n";
    for o in &r.optima {
        s += &format!(
            "{:>9}  {:>3}..={:<3} {:>17}  {:>7} {:>22}  {:>7}\n",
            o.pipelines,
            o.rule[0],
            o.rule[1],
            o.leaf_size,
            if o.within_rule { "yes" } else { "no" },
            o.rti_leaf_size,
            if o.rti_within_rule { "yes" } else { "no" }
        );
    }
    let c = &r.calibration;
    s += &format!(
        "\ncalibration ({} pipelines): RTI peak {:.3} G tests/s (thesis {:.2} G: {} pipelines at {} MHz); \
         sustained on this scene {:.3} G/s ({:.1} % of peak)\n\
         traversal: {:.1} M rays/s at 1 + {} passes (thesis ~{:.0} M: {:.1} passes per ray); \
         on this scene {:.1} M rays/s at {:.3} passes per ray\n",
        p.pipelines,
        c.peak_rti_rate / 1e9,
        c.thesis_rti_rate / 1e9,
        c.pipelines_for_thesis_rate,
        p.rti_mhz,
        c.sustained_rti_rate / 1e9,
        100.0 * c.sustained_share,
        c.trav_rate_at_thesis_back_traversals / 1e6,
        THESIS_BACK_TRAVERSALS,
        c.thesis_trav_rate / 1e6,
        c.passes_for_thesis_rate,
        c.scene_trav_rate / 1e6,
        c.scene_passes_per_ray
    );
    s
}

/// SVG files `write_svgs` writes.
pub const SVG_FILES: [&str; 2] = ["fig3-3_time_vs_leaf_size.svg", "fig3-3_rti_time_vs_leaf_size.svg"];

/// Writes figure 3-3 (total time, and RTI time alone) as SVG files into `out`.
pub fn write_svgs(r: &ArchReport, out: &vectors::outdir::OutDir) -> Result<Vec<std::path::PathBuf>, String> {
    use plotters::prelude::*;
    let err = |e: &dyn std::fmt::Display| e.to_string();
    let mut written = Vec::new();
    type Series = (&'static str, &'static str, fn(&Estimate) -> f64);
    let series: [Series; 2] = [
        (SVG_FILES[0], "modelled time, traversal + RTI (us)", |e| e.total_s * 1e6),
        (SVG_FILES[1], "modelled RTI time (us)", |e| e.rti_s * 1e6),
    ];
    for (file, label, f) in series {
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, (640, 400)).into_drawing_area();
            root.fill(&WHITE).map_err(|e| err(&e))?;
            let ymax = r.rows.iter().map(f).fold(0.0, f64::max) * 1.1 + 1e-9;
            let xmax = r.events.iter().map(|e| (e.leaf_size as f64).log2()).fold(0.0, f64::max) + 0.5;
            let mut chart = ChartBuilder::on(&root)
                .caption(format!("{} — fig. 3-3: {}", r.scene, label), ("sans-serif", 16))
                .margin(12)
                .x_label_area_size(36)
                .y_label_area_size(64)
                .build_cartesian_2d(-0.5..xmax, 0.0..ymax)
                .map_err(|e| err(&e))?;
            chart.configure_mesh().x_desc("leaf size (log2)").y_desc(label).draw().map_err(|e| err(&e))?;
            for (k, o) in r.optima.iter().enumerate() {
                let pts: Vec<(f64, f64)> = r
                    .rows
                    .iter()
                    .filter(|e| e.pipelines == o.pipelines)
                    .map(|e| ((e.leaf_size as f64).log2(), f(e)))
                    .collect();
                let color = Palette99::pick(k).to_rgba();
                chart
                    .draw_series(LineSeries::new(pts.clone(), color))
                    .map_err(|e| err(&e))?
                    .label(format!("{} pipelines", o.pipelines))
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], color));
                chart.draw_series(pts.iter().map(|&p| Circle::new(p, 3, color.filled()))).map_err(|e| err(&e))?;
            }
            chart.configure_series_labels().background_style(WHITE).border_style(BLACK).draw().map_err(|e| err(&e))?;
            root.present().map_err(|e| err(&e))?;
        }
        written.push(out.write(file, svg.as_bytes())?);
    }
    Ok(written)
}
