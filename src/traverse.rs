//! `raypipe traverse`: the thesis's 2-bit ray history traversal and Laine's 1-bit restart trail
//! against the ordered stack traversal on a scene's BVH, ray by ray, with every format's slab
//! unit as the box tester: the same first N leaves in the same order, plus the work each does.

use crate::bvh::{build, SceneBvh};
use crate::scene::Scene;
use datapath::bvh::{history_traverse, trail_traverse, HwTree};
use datapath::rng::SplitMix64;
use datapath::slab::{Slab, SlabConfig};
use datapath::{with_format, AnyFormat, Format};
use golden::bvh::{stack_traverse, Tree};
use golden::Ray64;
use serde::Serialize;

/// What to run.
#[derive(Clone, Debug)]
pub struct TraverseConfig {
    /// Box formats.
    pub formats: Vec<AnyFormat>,
    /// Slab variant name.
    pub variant: String,
    /// Rays (half primary, half random incoherent).
    pub rays: usize,
    /// Seed.
    pub seed: u64,
    /// Leaves wanted per ray (the first N).
    pub n: usize,
    /// Triangles per leaf at most.
    pub leaf_size: u32,
    /// Level pipelines (history width / 2) available.
    pub levels: usize,
}

/// Results for one format.
#[derive(Clone, Debug, Serialize)]
pub struct TraverseRow {
    /// Box format.
    pub format: String,
    /// Rays traced.
    pub rays: u64,
    /// Rays whose history traversal differs from the stack traversal (must be 0).
    pub history_mismatches: u64,
    /// Rays whose trail traversal differs from the stack traversal (must be 0).
    pub trail_mismatches: u64,
    /// Leaves emitted (all rays).
    pub leaves: u64,
    /// Rays that reached at least one leaf.
    pub rays_with_leaves: u64,
    /// Rays that needed no restart (one pass) among those with leaves.
    pub rays_without_restart: u64,
    /// Box tests of the stack traversal.
    pub stack_box_tests: u64,
    /// Box tests of the history traversal.
    pub history_box_tests: u64,
    /// Box tests of the trail traversal.
    pub trail_box_tests: u64,
    /// Restarts of the history traversal.
    pub restarts: u64,
    /// Back-traversal distances within 8 levels.
    pub back_within_8: u64,
    /// Back traversals.
    pub back_total: u64,
    /// Box tests a traversal to the end would add after the first N leaves: the work stopping
    /// at N skips.
    pub box_tests_skipped: u64,
}

/// The whole run.
#[derive(Clone, Debug, Serialize)]
pub struct TraverseReport {
    /// Scene name.
    pub scene: String,
    /// Triangles.
    pub triangles: usize,
    /// Leaves of the BVH.
    pub bvh_leaves: usize,
    /// Levels of the BVH (level pipelines used).
    pub depth: usize,
    /// Leaf size limit.
    pub leaf_size: u32,
    /// Slab variant.
    pub variant: String,
    /// Seed.
    pub seed: u64,
    /// N.
    pub n: usize,
    /// Per format.
    pub rows: Vec<TraverseRow>,
    /// No mismatch.
    pub passed: bool,
}

/// Primary rays on a pinhole camera in front of the scene (looking +z), then random ones.
pub fn rays(scene: &Scene, count: usize, seed: u64) -> Vec<Ray64> {
    let (lo, hi) = scene.bounds();
    let c: [f64; 3] = std::array::from_fn(|a| (lo[a] + hi[a]) / 2.0);
    let ext = (0..3).map(|a| hi[a] - lo[a]).fold(0.0, f64::max).max(1e-6);
    let eye = [c[0], c[1], lo[2] - 1.5 * ext];
    let primary = count / 2;
    let side = (primary as f64).sqrt().ceil().max(1.0) as usize;
    let mut out = Vec::with_capacity(count);
    for k in 0..primary {
        let (i, j) = (k % side, k / side);
        let sx = ((i as f64 + 0.5) / side as f64 - 0.5) * 0.8;
        let sy = ((j as f64 + 0.5) / side as f64 - 0.5) * 0.8;
        out.push(Ray64 { o: eye, d: [sx, sy, 1.0], tmin: 0.0, tmax: f64::INFINITY });
    }
    let mut r = SplitMix64::new(seed);
    while out.len() < count {
        let o = std::array::from_fn(|a| r.range(lo[a], hi[a]));
        let z = r.range(-1.0, 1.0);
        let phi = r.range(0.0, std::f64::consts::TAU);
        let s = (1.0 - z * z).sqrt();
        out.push(Ray64 { o, d: [s * phi.cos(), s * phi.sin(), z], tmin: 0.0, tmax: f64::INFINITY });
    }
    out
}

/// Runs the equivalence check.
pub fn traverse(cfg: &TraverseConfig, scene: &Scene) -> Result<TraverseReport, String> {
    let sc = SlabConfig::named(&cfg.variant)?;
    for f in &cfg.formats {
        with_format!(*f, |f| sc.for_format(&cfg.variant, &f).map(|_| ()))?;
    }
    let b = build(scene, cfg.leaf_size);
    let hw = b.layout_ids(cfg.levels)?;
    let tree = b.golden_tree();
    let rays = rays(scene, cfg.rays, cfg.seed);
    let mut rows = Vec::new();
    for f in &cfg.formats {
        rows.push(with_format!(*f, |f| one_format(f, sc, &b, &hw, &tree, &rays, cfg.n))?);
    }
    Ok(TraverseReport {
        scene: scene.name.clone(),
        triangles: scene.tris.len(),
        bvh_leaves: b.leaf_tris.len(),
        depth: b.depth,
        leaf_size: cfg.leaf_size,
        variant: cfg.variant.clone(),
        seed: cfg.seed,
        n: cfg.n,
        passed: rows.iter().all(|r| r.history_mismatches == 0 && r.trail_mismatches == 0),
        rows,
    })
}

fn one_format<F: Format>(
    f: F,
    sc: SlabConfig,
    b: &SceneBvh,
    hw: &HwTree<u32>,
    tree: &Tree,
    rays: &[Ray64],
    n: usize,
) -> Result<TraverseRow, String> {
    let s = Slab::new(f, sc);
    let boxes: Vec<_> =
        b.nodes.iter().map(|nd| s.store_box(nd.min, nd.max)).collect::<Result<_, _>>().map_err(|e| e.to_string())?;
    let mut row = TraverseRow {
        format: f.name(),
        rays: 0,
        history_mismatches: 0,
        trail_mismatches: 0,
        leaves: 0,
        rays_with_leaves: 0,
        rays_without_restart: 0,
        stack_box_tests: 0,
        history_box_tests: 0,
        trail_box_tests: 0,
        restarts: 0,
        back_within_8: 0,
        back_total: 0,
        box_tests_skipped: 0,
    };
    for ray in rays {
        let sr = s.prepare(ray.o, ray.d, ray.tmin, ray.tmax);
        let test = |i: u32| {
            let o = s.test(&sr, &boxes[i as usize]);
            o.hit.then(|| f.to_f64(o.t_near))
        };
        let g = stack_traverse(tree, n, test);
        let h = history_traverse(hw, n, |&i| test(i));
        if h.leaves.len() == n {
            row.box_tests_skipped += history_traverse(hw, usize::MAX, |&i| test(i)).box_tests - h.box_tests;
        }
        let t = trail_traverse(hw, n, |&i| test(i));
        row.rays += 1;
        row.history_mismatches += (h.leaves != g.leaves) as u64;
        row.trail_mismatches += (t.leaves != g.leaves) as u64;
        row.leaves += g.leaves.len() as u64;
        if !g.leaves.is_empty() {
            row.rays_with_leaves += 1;
            row.rays_without_restart += (h.passes == 1) as u64;
        }
        row.stack_box_tests += g.box_tests;
        row.history_box_tests += h.box_tests;
        row.trail_box_tests += t.box_tests;
        row.restarts += h.passes.saturating_sub(1);
        row.back_total += h.back_distances.len() as u64;
        row.back_within_8 += h.back_distances.iter().filter(|&&d| d <= 8).count() as u64;
    }
    Ok(row)
}

/// The report as text.
pub fn render(r: &TraverseReport) -> String {
    let mut s = format!(
        "raypipe traverse: scene {} ({} triangles), BVH {} leaves (<= {} triangles each), {} levels; slab variant {}; first N = {} leaves; seed {}\n\n",
        r.scene, r.triangles, r.bvh_leaves, r.leaf_size, r.depth, r.variant, r.n, r.seed
    );
    s += &format!(
        "{:<14} {:>8} {:>9} {:>9} {:>9} {:>11} {:>12} {:>12} {:>10} {:>9}\n",
        "format", "rays", "hist≠", "trail≠", "leaves", "no-restart", "stack tests", "hist tests", "overhead", "back<=8"
    );
    for w in &r.rows {
        s += &format!(
            "{:<14} {:>8} {:>9} {:>9} {:>9} {:>10.1}% {:>12} {:>12} {:>9.2}x {:>8.1}%\n",
            w.format,
            w.rays,
            w.history_mismatches,
            w.trail_mismatches,
            w.leaves,
            100.0 * w.rays_without_restart as f64 / w.rays_with_leaves.max(1) as f64,
            w.stack_box_tests,
            w.history_box_tests,
            w.history_box_tests as f64 / w.stack_box_tests.max(1) as f64,
            100.0 * w.back_within_8 as f64 / w.back_total.max(1) as f64
        );
    }
    s += "\nhist≠/trail≠: rays whose first-N leaf sequence differs from the ordered stack traversal with the same box tester (must be 0).\n";
    s += "no-restart: rays with leaves that needed a single pass; overhead: box tests of the history traversal / the stack traversal's; back<=8: back traversals within 8 levels.\n";
    s += "skipped work: box tests a traversal to the end would add after the first N leaves: ";
    s += &r
        .rows
        .iter()
        .map(|w| {
            format!(
                "{} {} ({:.1}% of the history traversal's)",
                w.format,
                w.box_tests_skipped,
                100.0 * w.box_tests_skipped as f64 / w.history_box_tests.max(1) as f64
            )
        })
        .collect::<Vec<_>>()
        .join(", ");
    s += "\n";
    s += if r.passed { "equivalence: PASS\n" } else { "equivalence: FAIL\n" };
    s
}
