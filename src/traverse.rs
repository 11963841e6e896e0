//! `raypipe traverse`: the thesis's 2-bit ray history traversal and Laine's 1-bit restart trail
//! against the ordered stack traversal on a scene's BVH, ray by ray, with every format's slab
//! unit as the box tester: the same first N leaves in the same order, plus the work each does.

pub mod cover;

use crate::bvh::{build, SceneBvh};
use crate::scene::Scene;
use datapath::box_memo::BoxMemo;
use datapath::bvh::{history_traverse_into, trail_traverse, HwTree, StacklessResult};
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
    /// Threads and rays per chunk (the results do not depend on either).
    pub engine: engine::Engine,
    /// Show progress on stderr (when it is a terminal and the run lasts over a second).
    pub progress: bool,
}

/// Results for one format.
#[derive(Clone, Debug, PartialEq, Serialize, serde::Deserialize)]
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
#[derive(Clone, Debug, PartialEq, Serialize, serde::Deserialize)]
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
    /// Why the run proved nothing ([`TraverseReport::vacuous`]), when it did not.
    #[serde(default)]
    pub inconclusive: Option<String>,
}

impl TraverseReport {
    /// Why the run exercised nothing (the BVH has no inner level, or no ray reached a leaf):
    /// then a pass proves nothing.
    pub fn vacuous(&self) -> Option<String> {
        if self.depth == 0 {
            Some(format!(
                "the BVH is one leaf ({} triangle(s), 0 inner levels): the ray history never held a bit",
                self.triangles
            ))
        } else if self.rows.iter().all(|r| r.rays_with_leaves == 0) {
            Some("no ray reached a leaf: no traversal was compared".into())
        } else {
            None
        }
    }

    /// The report with `inconclusive` set from its rows.
    pub fn with_verdict(mut self) -> Self {
        self.inconclusive = self.vacuous();
        self
    }

    /// The exit outcome: a mismatch fails; a run that exercised nothing is inconclusive.
    pub fn outcome(&self) -> crate::Outcome {
        match (self.passed, self.vacuous()) {
            (false, _) => crate::Outcome::Fail,
            (true, Some(_)) => crate::Outcome::Inconclusive,
            (true, None) => crate::Outcome::Pass,
        }
    }
}

/// Primary rays on a pinhole camera in front of the scene (looking +z), then random ones.
pub fn rays(scene: &Scene, count: usize, seed: u64) -> Vec<Ray64> {
    let g = CameraRays::new(scene, count, seed);
    (0..count as u64).map(|k| g.ray(k)).collect()
}

/// Stream number of the random rays of [`CameraRays`] in [`SplitMix64::for_item`].
pub const RANDOM_RAYS_STREAM: u64 = 0x7472_6176; // "trav"

/// Makes ray `k` of [`rays`] without the rays before it: rays `0..count/2` are the primary
/// rays of a `side × side` pinhole grid (`side = ⌈√(count/2)⌉`, row-major from the lower left)
/// from an eye 1.5 scene extents in front of the scene; ray `k >= count/2` is random, drawn
/// from `SplitMix64::for_item(seed, RANDOM_RAYS_STREAM, k)`: origin uniform in the bounds,
/// direction uniform on the sphere.
#[derive(Clone, Copy, Debug)]
pub struct CameraRays {
    lo: [f64; 3],
    hi: [f64; 3],
    eye: [f64; 3],
    primary: u64,
    side: u64,
    seed: u64,
}

impl CameraRays {
    /// The generator of `count` rays of `scene` under `seed`.
    pub fn new(scene: &Scene, count: usize, seed: u64) -> Self {
        let (lo, hi) = scene.bounds();
        let c: [f64; 3] = std::array::from_fn(|a| (lo[a] + hi[a]) / 2.0);
        let ext = (0..3).map(|a| hi[a] - lo[a]).fold(0.0, f64::max).max(1e-6);
        let primary = count as u64 / 2;
        let side = (primary as f64).sqrt().ceil().max(1.0) as u64;
        CameraRays { lo, hi, eye: [c[0], c[1], lo[2] - 1.5 * ext], primary, side, seed }
    }
    /// Ray `k`.
    pub fn ray(&self, k: u64) -> Ray64 {
        if k < self.primary {
            let (i, j) = (k % self.side, k / self.side);
            let sx = ((i as f64 + 0.5) / self.side as f64 - 0.5) * 0.8;
            let sy = ((j as f64 + 0.5) / self.side as f64 - 0.5) * 0.8;
            return Ray64 { o: self.eye, d: [sx, sy, 1.0], tmin: 0.0, tmax: f64::INFINITY };
        }
        let mut r = SplitMix64::for_item(self.seed, RANDOM_RAYS_STREAM, k);
        let o = std::array::from_fn(|a| r.range(self.lo[a], self.hi[a]));
        let z = r.range(-1.0, 1.0);
        let phi = r.range(0.0, std::f64::consts::TAU);
        let s = (1.0 - z * z).sqrt();
        Ray64 { o, d: [s * phi.cos(), s * phi.sin(), z], tmin: 0.0, tmax: f64::INFINITY }
    }
}

/// Rays per chunk of `traverse` and `stats` on the engine.
pub const CHUNK_RAYS: u64 = 256;

/// Runs the equivalence check.
pub fn traverse(cfg: &TraverseConfig, scene: &Scene) -> Result<TraverseReport, String> {
    let sc = SlabConfig::named(&cfg.variant)?;
    for f in &cfg.formats {
        with_format!(*f, |f| sc.for_format(&cfg.variant, &f).map(|_| ()))?;
    }
    let b = build(scene, cfg.leaf_size);
    let hw = b.layout_ids(cfg.levels)?;
    let tree = b.golden_tree();
    let gen = CameraRays::new(scene, cfg.rays, cfg.seed);
    let mut rows = Vec::new();
    for f in &cfg.formats {
        rows.push(with_format!(*f, |f| one_format(f, sc, &b, &hw, &tree, &gen, cfg))?);
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
        inconclusive: None,
    }
    .with_verdict())
}

/// Counters of [`TraverseRow`] in field order from `rays` to `box_tests_skipped`.
impl TraverseRow {
    fn counters(&self) -> [u64; COUNTERS] {
        [
            self.rays,
            self.history_mismatches,
            self.trail_mismatches,
            self.leaves,
            self.rays_with_leaves,
            self.rays_without_restart,
            self.stack_box_tests,
            self.history_box_tests,
            self.trail_box_tests,
            self.restarts,
            self.back_within_8,
            self.back_total,
            self.box_tests_skipped,
        ]
    }

    fn from_counters(format: String, c: [u64; COUNTERS]) -> Self {
        let [rays, history_mismatches, trail_mismatches, leaves, rays_with_leaves, rays_without_restart, stack_box_tests, history_box_tests, trail_box_tests, restarts, back_within_8, back_total, box_tests_skipped] =
            c;
        TraverseRow {
            format,
            rays,
            history_mismatches,
            trail_mismatches,
            leaves,
            rays_with_leaves,
            rays_without_restart,
            stack_box_tests,
            history_box_tests,
            trail_box_tests,
            restarts,
            back_within_8,
            back_total,
            box_tests_skipped,
        }
    }
}

impl TraverseReport {
    /// Adds another shard's report of the same run (every row's counters; `passed` again).
    pub fn merge(&mut self, o: TraverseReport) -> Result<(), String> {
        let names = |r: &TraverseReport| r.rows.iter().map(|x| x.format.clone()).collect::<Vec<_>>();
        if names(self) != names(&o) {
            return Err("partials disagree on the formats".into());
        }
        for (a, b) in self.rows.iter_mut().zip(o.rows) {
            let (x, y) = (a.counters(), b.counters());
            *a = TraverseRow::from_counters(a.format.clone(), std::array::from_fn(|k| x[k] + y[k]));
        }
        self.passed = self.rows.iter().all(|r| r.history_mismatches == 0 && r.trail_mismatches == 0);
        self.inconclusive = self.vacuous();
        Ok(())
    }
}

impl crate::partial::Sharded for TraverseReport {
    const COMMAND: &'static str = "traverse";
    type Report = TraverseReport;
    fn add(&mut self, other: Self) -> Result<(), String> {
        self.merge(other)
    }
    fn finish(self) -> Result<TraverseReport, String> {
        Ok(self.with_verdict())
    }
    fn render(r: &TraverseReport) -> String {
        render(r)
    }
    fn outcome(r: &TraverseReport) -> crate::Outcome {
        r.outcome()
    }
}

impl crate::partial::Consistent for TraverseReport {
    /// Every row over the same rays, its per-ray counts within them, and `passed` and
    /// `inconclusive` what the rows and the tree say.
    fn check(&self, _share: &dyn Fn(u64, u64) -> u64) -> Result<(), String> {
        use crate::partial::require;
        let rays = self.rows.first().map_or(0, |r| r.rays);
        for r in &self.rows {
            require(r.rays == rays, || format!("{}: {} rays, the first row {rays}", r.format, r.rays))?;
            require(
                r.history_mismatches <= rays
                    && r.trail_mismatches <= rays
                    && r.rays_with_leaves <= rays
                    && r.rays_without_restart <= r.rays_with_leaves
                    && r.rays_with_leaves <= r.leaves,
                || format!("{}: per-ray counts do not fit {rays} rays: {r:?}", r.format),
            )?;
        }
        let passed = self.rows.iter().all(|r| r.history_mismatches == 0 && r.trail_mismatches == 0);
        require(self.passed == passed, || format!("passed is {} but the rows say {passed}", self.passed))?;
        require(self.inconclusive == self.vacuous(), || {
            format!("inconclusive is {:?} but the tree and rows say {:?}", self.inconclusive, self.vacuous())
        })
    }
}

/// The options that change a traverse run's results, for a partial's `args`.
pub fn args(cfg: &TraverseConfig) -> serde_json::Value {
    serde_json::json!({
        "formats": cfg.formats.iter().map(|f| f.to_string()).collect::<Vec<_>>(),
        "variant": cfg.variant,
        "rays": cfg.rays,
        "seed": cfg.seed,
        "n": cfg.n,
        "leaf_size": cfg.leaf_size,
        "levels": cfg.levels,
    })
}

const COUNTERS: usize = 13;

fn one_format<F: Format>(
    f: F,
    sc: SlabConfig,
    b: &SceneBvh,
    hw: &HwTree<u32>,
    tree: &Tree,
    gen: &CameraRays,
    cfg: &TraverseConfig,
) -> Result<TraverseRow, String> {
    let s = Slab::new(f, sc);
    let boxes: Vec<_> =
        b.nodes.iter().map(|nd| s.store_box(nd.min, nd.max)).collect::<Result<_, _>>().map_err(|e| e.to_string())?;
    let n = cfg.n;
    let progress = engine::Progress::new(cfg.engine.shard_items(cfg.rays as u64), "rays", !cfg.progress);
    progress.message(f.name());
    let acc = engine::run(
        &cfg.engine,
        cfg.rays as u64,
        &progress,
        // each box test of a ray computed once and remembered for the four traversals (their
        // results and counted box tests unchanged: datapath::box_memo)
        || (BoxMemo::new(boxes.len()), StacklessResult::default(), StacklessResult::default()),
        |(memo, h, end), range| {
            let mut c = engine::Counts::<COUNTERS>::default();
            for k in range {
                let ray = gen.ray(k);
                let sr = s.prepare(ray.o, ray.d, ray.tmin, ray.tmax);
                let test = |i: u32| {
                    let o = s.test(&sr, &boxes[i as usize]);
                    o.hit.then(|| f.to_f64(o.t_near))
                };
                memo.next_ray();
                let g = stack_traverse(tree, n, |i| memo.get_or(i, || test(i)));
                history_traverse_into(hw, n, |&i| memo.get_or(i, || test(i)), h);
                let skipped = if h.leaves.len() == n {
                    history_traverse_into(hw, usize::MAX, |&i| memo.get_or(i, || test(i)), end);
                    end.box_tests - h.box_tests
                } else {
                    0
                };
                let t = trail_traverse(hw, n, |&i| memo.get_or(i, || test(i)));
                let with_leaves = !g.leaves.is_empty();
                let add = [
                    1,
                    (h.leaves != g.leaves) as u64,
                    (t.leaves != g.leaves) as u64,
                    g.leaves.len() as u64,
                    with_leaves as u64,
                    (with_leaves && h.passes == 1) as u64,
                    g.box_tests,
                    h.box_tests,
                    t.box_tests,
                    h.passes.saturating_sub(1),
                    h.back_distances.iter().filter(|&&d| d <= 8).count() as u64,
                    h.back_distances.len() as u64,
                    skipped,
                ];
                for (a, b) in c.0.iter_mut().zip(add) {
                    *a += b;
                }
            }
            c
        },
    );
    progress.finish();
    Ok(TraverseRow::from_counters(f.name(), acc.0))
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
    match (r.passed, r.vacuous()) {
        (false, _) => s += "equivalence: FAIL\n",
        (true, Some(why)) => s += &format!("equivalence: INCONCLUSIVE: {why}; the run proved nothing\n"),
        (true, None) => s += "equivalence: PASS\n",
    }
    s
}
