//! `raypipe stats`: the thesis's experiments (figures 3-1, 3-2, 3-4, 3-5 and the restart
//! overhead) on a scene, for a sweep of leaf sizes. Independent of number formats: the box
//! tester is the golden f64 slab test, the triangle test the golden f64 Möller–Trumbore.
//!
//! Per ray the nearest hit is searched in traversal order (2-bit history traversal): the leaf
//! holding the nearest hit among all leaves the ray reaches is found, and the work up to and
//! including that leaf is counted — leaves visited, RTI tests, passes (back traversals =
//! passes − 1) and the level distance of each back traversal. Rays without any hit count the
//! whole traversal.

use crate::bvh::build;
use crate::scene::Scene;
use golden::bvh::stack_traverse;
use serde::Serialize;

/// Results for one leaf size.
#[derive(Clone, Debug, Serialize)]
pub struct LeafSizeStats {
    /// Triangles per leaf at most.
    pub leaf_size: u32,
    /// BVH leaves.
    pub leaves: usize,
    /// BVH levels.
    pub depth: usize,
    /// Rays traced.
    pub rays: u64,
    /// Rays with a hit.
    pub rays_hit: u64,
    /// Fig. 3-1: mean rays per visited leaf (available parallelism for the RTI pipelines).
    pub rays_per_leaf: f64,
    /// Fig. 3-2: RTI tests per ray that do not produce the nearest hit.
    pub wasted_rti_per_ray: f64,
    /// Fig. 3-4: histogram of back traversals per ray (index = count, last bin = that many or more).
    pub back_traversals: Vec<u64>,
    /// Share of rays needing no back traversal.
    pub no_back_traversal: f64,
    /// Fig. 3-5: histogram of back-traversal distances in levels (index = distance).
    pub back_distance: Vec<u64>,
    /// Share of back traversals within 8 levels.
    pub within_8_levels: f64,
    /// Box tests of the history traversal / the stack traversal (same leaves).
    pub restart_overhead: f64,
}

/// The whole run.
#[derive(Clone, Debug, Serialize)]
pub struct StatsReport {
    /// Scene.
    pub scene: String,
    /// Triangles.
    pub triangles: usize,
    /// Rays per leaf size.
    pub rays: usize,
    /// Seed.
    pub seed: u64,
    /// One row per leaf size.
    pub rows: Vec<LeafSizeStats>,
}

impl StatsReport {
    /// Why the run measured no traversal: every leaf size's BVH is one leaf (0 inner levels).
    pub fn vacuous(&self) -> Option<String> {
        (!self.rows.is_empty() && self.rows.iter().all(|w| w.depth == 0)).then(|| {
            format!("the BVH is one leaf at every leaf size ({} triangle(s)): no traversal to measure", self.triangles)
        })
    }

    /// Pass, or inconclusive when the run measured no traversal.
    pub fn outcome(&self) -> crate::Outcome {
        match self.vacuous() {
            Some(_) => crate::Outcome::Inconclusive,
            None => crate::Outcome::Pass,
        }
    }
}

const BACK_BINS: usize = 11;

/// One chunk's share of the figures: counts (rays hit, wasted RTI tests, history box tests,
/// stack box tests, leaf visits), back traversals per ray, back-traversal distances, and the
/// set of leaves visited.
#[derive(Default)]
struct StatsAcc {
    c: engine::Counts<5>,
    back: engine::Counts<BACK_BINS>,
    dist: engine::Tally,
    seen: engine::Bits,
}

impl engine::Merge for StatsAcc {
    fn merge(&mut self, o: Self) {
        self.c.merge(o.c);
        self.back.merge(o.back);
        self.dist.merge(o.dist);
        self.seen.merge(o.seen);
    }
}

/// Runs the sweep on the engine (rays by index, see [`crate::traverse::CameraRays`]).
pub fn stats(scene: &Scene, leaf_sizes: &[u32], rays: usize, seed: u64) -> Result<StatsReport, String> {
    stats_on(&engine::Engine::new(crate::traverse::CHUNK_RAYS), false, scene, leaf_sizes, rays, seed)
}

/// [`stats`] on a given engine, with progress on stderr when `progress`.
pub fn stats_on(
    eng: &engine::Engine,
    progress: bool,
    scene: &Scene,
    leaf_sizes: &[u32],
    rays: usize,
    seed: u64,
) -> Result<StatsReport, String> {
    use engine::Merge as _;
    let gen = crate::traverse::CameraRays::new(scene, rays, seed);
    let mut rows = Vec::new();
    for &ls in leaf_sizes {
        let b = build(scene, ls);
        let hw = b.layout_ids(256)?;
        let tree = b.golden_tree();
        let bar = engine::Progress::new(rays as u64, "rays", !progress);
        bar.message(format!("leaf size {ls}"));
        let acc = engine::run(
            eng,
            rays as u64,
            &bar,
            || (),
            |_, range| {
                let mut acc = StatsAcc::default();
                for k in range {
                    let ray = gen.ray(k);
                    let w = b.nearest_work(&hw, scene, &ray);
                    let (h, upto) = (&w.history, w.leaves.len());
                    let g = stack_traverse(&tree, upto.max(1), b.box_test(&ray));
                    let tests: u64 = w.leaves.iter().map(|&l| b.leaf_tris[l as usize].len() as u64).sum();
                    for &leaf in &w.leaves {
                        acc.seen.insert(leaf as usize);
                    }
                    let add = [w.hit as u64, tests - w.hit as u64, h.box_tests, g.box_tests, upto as u64];
                    for (a, x) in acc.c.0.iter_mut().zip(add) {
                        *a += x;
                    }
                    acc.back.0[(h.passes.saturating_sub(1) as usize).min(BACK_BINS - 1)] += 1;
                    for &d in &h.back_distances {
                        acc.dist.add((d as usize).min(b.depth + 1), 1);
                    }
                }
                acc
            },
        );
        bar.finish();
        let mut dist = engine::Tally(vec![0u64; b.depth + 2]);
        dist.merge(acc.dist);
        let dist = dist.0;
        let [rays_hit, wasted, hist_tests, stack_tests, visits] = acc.c.0;
        let back = acc.back.0.to_vec();
        let total_back: u64 = dist.iter().sum();
        let n = rays.max(1) as f64;
        rows.push(LeafSizeStats {
            leaf_size: ls,
            leaves: b.leaf_tris.len(),
            depth: b.depth,
            rays: rays as u64,
            rays_hit,
            rays_per_leaf: visits as f64 / acc.seen.count().max(1) as f64,
            wasted_rti_per_ray: wasted as f64 / n,
            no_back_traversal: back[0] as f64 / n,
            within_8_levels: dist.iter().take(9).sum::<u64>() as f64 / total_back.max(1) as f64,
            back_traversals: back,
            back_distance: dist,
            restart_overhead: hist_tests as f64 / stack_tests.max(1) as f64,
        });
    }
    Ok(StatsReport { scene: scene.name.clone(), triangles: scene.tris.len(), rays, seed, rows })
}

/// The report as text tables.
pub fn render(r: &StatsReport) -> String {
    let mut s = format!(
        "raypipe stats: scene {} ({} triangles), {} rays (half primary, half random), seed {}\n\n",
        r.scene, r.triangles, r.rays, r.seed
    );
    s += &format!(
        "{:>9} {:>8} {:>7} {:>10} {:>13} {:>14} {:>13} {:>12} {:>9}\n",
        "leaf size",
        "leaves",
        "levels",
        "rays hit",
        "rays/leaf",
        "wasted RTI/ray",
        "no back-trav",
        "back<=8 lvl",
        "overhead"
    );
    for w in &r.rows {
        s += &format!(
            "{:>9} {:>8} {:>7} {:>10} {:>13.2} {:>14.2} {:>12.1}% {:>11.1}% {:>8.2}x\n",
            w.leaf_size,
            w.leaves,
            w.depth,
            w.rays_hit,
            w.rays_per_leaf,
            w.wasted_rti_per_ray,
            100.0 * w.no_back_traversal,
            100.0 * w.within_8_levels,
            w.restart_overhead
        );
    }
    if let Some(why) = r.vacuous() {
        s += &format!("\nINCONCLUSIVE: {why}\n");
    }
    s += "\nback traversals per ray (fig. 3-4), share of rays for 0, 1, .., 9, >=10:\n";
    for w in &r.rows {
        let n = w.rays.max(1) as f64;
        s += &format!(
            "  leaf size {:>3}: {}\n",
            w.leaf_size,
            w.back_traversals.iter().map(|&c| format!("{:.1}%", 100.0 * c as f64 / n)).collect::<Vec<_>>().join(" ")
        );
    }
    s
}

/// One line figure: file name, y label, the value per leaf size.
type Figure = (&'static str, &'static str, fn(&LeafSizeStats) -> f64);

/// The files [`write_svgs`] writes (checked before the work starts).
pub const SVG_FILES: [&str; 5] = [
    "fig3-1_rays_per_leaf.svg",
    "fig3-2_wasted_rti.svg",
    "fig3-4_no_back_traversal.svg",
    "restart_overhead.svg",
    "fig3-5_back_distance.svg",
];

/// Writes the figures as SVG files into `out` (plotters, SVG backend only).
pub fn write_svgs(r: &StatsReport, out: &vectors::outdir::OutDir) -> Result<Vec<std::path::PathBuf>, String> {
    use plotters::prelude::*;
    let err = |e: &dyn std::fmt::Display| e.to_string();
    let mut written = Vec::new();
    let series: [Figure; 4] = [
        ("fig3-1_rays_per_leaf.svg", "rays per visited leaf", |w| w.rays_per_leaf),
        ("fig3-2_wasted_rti.svg", "wasted RTI tests per ray", |w| w.wasted_rti_per_ray),
        ("fig3-4_no_back_traversal.svg", "rays without back traversal (%)", |w| 100.0 * w.no_back_traversal),
        ("restart_overhead.svg", "history / stack box tests", |w| w.restart_overhead),
    ];
    for (file, label, f) in series {
        let mut svg = String::new();
        let pts: Vec<(f64, f64)> = r.rows.iter().map(|w| ((w.leaf_size as f64).log2(), f(w))).collect();
        let ymax = pts.iter().map(|p| p.1).fold(0.0, f64::max) * 1.1 + 1e-9;
        let xmax = pts.iter().map(|p| p.0).fold(0.0, f64::max) + 0.5;
        {
            let root = SVGBackend::with_string(&mut svg, (640, 400)).into_drawing_area();
            root.fill(&WHITE).map_err(|e| err(&e))?;
            let mut chart = ChartBuilder::on(&root)
                .caption(format!("{} — {}", r.scene, label), ("sans-serif", 18))
                .margin(12)
                .x_label_area_size(36)
                .y_label_area_size(56)
                .build_cartesian_2d(-0.5..xmax, 0.0..ymax)
                .map_err(|e| err(&e))?;
            chart.configure_mesh().x_desc("leaf size (log2)").y_desc(label).draw().map_err(|e| err(&e))?;
            chart.draw_series(LineSeries::new(pts.clone(), &BLUE)).map_err(|e| err(&e))?;
            chart.draw_series(pts.iter().map(|&p| Circle::new(p, 4, BLUE.filled()))).map_err(|e| err(&e))?;
            root.present().map_err(|e| err(&e))?;
        }
        written.push(out.write(file, svg.as_bytes())?);
    }
    // fig. 3-5: back-traversal distance distribution, one line per leaf size
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (640, 400)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| err(&e))?;
        let maxd = r.rows.iter().map(|w| w.back_distance.len()).max().unwrap_or(1) as f64;
        let mut chart = ChartBuilder::on(&root)
            .caption(format!("{} — back-traversal distance (levels)", r.scene), ("sans-serif", 18))
            .margin(12)
            .x_label_area_size(36)
            .y_label_area_size(56)
            .build_cartesian_2d(0.0..maxd, 0.0..100.0)
            .map_err(|e| err(&e))?;
        chart.configure_mesh().x_desc("levels").y_desc("share of back traversals (%)").draw().map_err(|e| err(&e))?;
        for (k, w) in r.rows.iter().enumerate() {
            let total: u64 = w.back_distance.iter().sum::<u64>().max(1);
            let pts: Vec<(f64, f64)> =
                w.back_distance.iter().enumerate().map(|(d, &c)| (d as f64, 100.0 * c as f64 / total as f64)).collect();
            let color = Palette99::pick(k).to_rgba();
            chart
                .draw_series(LineSeries::new(pts, color))
                .map_err(|e| err(&e))?
                .label(format!("leaf size {}", w.leaf_size))
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], color));
        }
        chart.configure_series_labels().background_style(WHITE).border_style(BLACK).draw().map_err(|e| err(&e))?;
        root.present().map_err(|e| err(&e))?;
    }
    written.push(out.write(SVG_FILES[4], svg.as_bytes())?);
    Ok(written)
}
