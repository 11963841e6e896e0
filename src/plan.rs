//! `raypipe plan`: what a scene needs from the hardware — tree depth (level pipelines and
//! history bits) at the thesis's recommended leaf size, whether back-face culling applies,
//! and per candidate format how many triangles collapse when stored and what disagreement
//! with the golden it costs, with the smallest format meeting an error budget.

use crate::scene::Scene;
use crate::verify::{verify, VerifyConfig};
use datapath::{with_format, AnyFormat, Format};
use serde::{Deserialize, Serialize};
use std::collections::HashMap;

/// What to plan for.
#[derive(Clone, Debug)]
pub struct PlanConfig {
    /// Candidate formats.
    pub formats: Vec<AnyFormat>,
    /// RTI pipelines of the design (the thesis: leaf size between half and one times this).
    pub pipelines: u32,
    /// Largest acceptable rate of hit/miss disagreements with the golden, per test.
    pub budget: f64,
    /// Rays of the measurement.
    pub rays: usize,
    /// Seed of the measurement.
    pub seed: u64,
    /// Level pipelines the hardware has.
    pub max_levels: usize,
}

/// One candidate format.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct FormatFit {
    /// Format name.
    pub format: String,
    /// Bits per value.
    pub width: u32,
    /// Triangles with two vertices that become equal when stored in the format.
    pub collapsed_triangles: usize,
    /// Ray–triangle tests measured.
    pub tests: u64,
    /// Golden hits the model misses.
    pub false_misses: u64,
    /// Model hits the golden misses.
    pub false_hits: u64,
    /// (false misses + false hits) / tests.
    pub disagreement_rate: f64,
    /// Within the budget (and usable: see `unusable`).
    pub meets_budget: bool,
    /// Why the format cannot be chosen whatever its disagreement rate, if it cannot.
    pub unusable: Option<String>,
}

/// The plan.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Plan {
    /// Scene name.
    pub scene: String,
    /// Triangles.
    pub triangles: usize,
    /// Power of two the coordinates were scaled by into [-1, 1]^3.
    pub scale: f64,
    /// RTI pipelines assumed.
    pub pipelines: u32,
    /// Recommended leaf sizes (half to one times the pipelines).
    pub leaf_size_range: [u32; 2],
    /// Leaf size planned (the top of the range).
    pub leaf_size: u32,
    /// Tree levels below the root at that leaf size: the level pipelines needed.
    pub level_pipelines: usize,
    /// Ray history bits (2 per level).
    pub history_bits: usize,
    /// The tree fits the hardware's level pipelines.
    pub fits_levels: bool,
    /// Every edge is shared by exactly two triangles.
    pub closed: bool,
    /// Closed and every shared edge runs in opposite directions in its two triangles.
    pub consistently_oriented: bool,
    /// Back-face culling cannot lose a first visible hit for rays from outside the mesh.
    pub culling_applies: bool,
    /// Budget (disagreements per test).
    pub budget: f64,
    /// Candidate formats, as given.
    pub formats: Vec<FormatFit>,
    /// The narrowest format meeting the budget.
    pub smallest_within_budget: Option<String>,
    /// Rays and seed of the measurement.
    pub rays: usize,
    /// Seed.
    pub seed: u64,
}

/// Reads a plan written by `raypipe plan --json`.
pub fn load(path: &std::path::Path) -> Result<Plan, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    serde_json::from_str(&text)
        .map_err(|e| format!("{}: not a plan ({e}); write one with raypipe plan --json", path.display()))
}

impl Plan {
    /// The plan's formats within its budget, as formats.
    pub fn within_budget(&self) -> Result<Vec<AnyFormat>, String> {
        let v: Vec<AnyFormat> =
            self.formats.iter().filter(|f| f.meets_budget).map(|f| f.format.parse()).collect::<Result<_, _>>()?;
        if v.is_empty() {
            return Err(format!("the plan has no format within its budget {:e}", self.budget));
        }
        Ok(v)
    }

    /// The narrowest format within the budget.
    pub fn narrowest(&self) -> Result<AnyFormat, String> {
        self.smallest_within_budget
            .as_deref()
            .ok_or_else(|| format!("the plan has no format within its budget {:e}", self.budget))?
            .parse()
    }

    /// The plan was made for this scene (same name and triangle count).
    pub fn check_scene(&self, scene: &Scene) -> Result<(), String> {
        if self.scene != scene.name || self.triangles != scene.tris.len() {
            return Err(format!(
                "the plan was made for scene {} ({} triangles), not {} ({} triangles)",
                self.scene,
                self.triangles,
                scene.name,
                scene.tris.len()
            ));
        }
        Ok(())
    }
}

/// Closed / consistently oriented, from the triangles' exact vertex coordinates.
fn topology(scene: &Scene) -> (bool, bool) {
    let key = |p: &[f64; 3]| p.map(f64::to_bits);
    // undirected edge -> (count, sum of directions: +1 for a->b with a < b, -1 otherwise)
    let mut edges: HashMap<([u64; 3], [u64; 3]), (u32, i32)> = HashMap::new();
    for t in &scene.tris {
        for k in 0..3 {
            let (a, b) = (key(&t.v[k]), key(&t.v[(k + 1) % 3]));
            let (lo, hi, dir) = if a < b { (a, b, 1) } else { (b, a, -1) };
            let e = edges.entry((lo, hi)).or_insert((0, 0));
            e.0 += 1;
            e.1 += dir;
        }
    }
    let closed = !edges.is_empty() && edges.values().all(|&(n, _)| n == 2);
    (closed, closed && edges.values().all(|&(_, d)| d == 0))
}

fn collapsed<F: Format>(f: F, scene: &Scene) -> usize {
    scene
        .tris
        .iter()
        .filter(|t| {
            let q = t.v.map(|p| p.map(|x| f.to_bits(f.from_f64(x))));
            q[0] == q[1] || q[1] == q[2] || q[0] == q[2]
        })
        .count()
}

/// Plans the hardware for a scene.
pub fn plan(cfg: &PlanConfig, scene: &Scene) -> Result<Plan, String> {
    if cfg.pipelines == 0 || cfg.pipelines > 255 {
        return Err(format!("--pipelines must be 1..=255, got {}", cfg.pipelines));
    }
    if cfg.budget.is_nan() || cfg.budget < 0.0 {
        return Err(format!("--budget must be a rate >= 0, got {}", cfg.budget));
    }
    let leaf_size_range = [cfg.pipelines.div_ceil(2), cfg.pipelines];
    let leaf_size = cfg.pipelines;
    let b = crate::bvh::build(scene, leaf_size);
    let (closed, oriented) = topology(scene);
    let vcfg = VerifyConfig::new(cfg.formats.clone(), cfg.rays, cfg.seed, Default::default(), 512);
    let rep = verify(&vcfg, scene);
    let formats: Vec<FormatFit> = cfg
        .formats
        .iter()
        .zip(&rep.formats)
        .map(|(f, r)| {
            let rate = (r.false_misses + r.false_hits) as f64 / (r.tests.max(1)) as f64;
            let collapsed_triangles = with_format!(*f, |f| collapsed(f, scene));
            // a format that holds none of the scene (every triangle collapses), or in which no
            // test is decisive, agrees with the golden by missing everything: never within budget
            let unusable = if collapsed_triangles == scene.tris.len() {
                Some("every triangle collapses when stored".to_string())
            } else if r.decisive == 0 {
                Some("no test is decisive (the run proves nothing in this format)".to_string())
            } else {
                None
            };
            FormatFit {
                format: r.format.clone(),
                width: r.width,
                collapsed_triangles,
                tests: r.tests,
                false_misses: r.false_misses,
                false_hits: r.false_hits,
                disagreement_rate: rate,
                meets_budget: rate <= cfg.budget && unusable.is_none(),
                unusable,
            }
        })
        .collect();
    let smallest = formats.iter().filter(|f| f.meets_budget).min_by_key(|f| f.width).map(|f| f.format.clone());
    Ok(Plan {
        scene: scene.name.clone(),
        triangles: scene.tris.len(),
        scale: scene.scale,
        pipelines: cfg.pipelines,
        leaf_size_range,
        leaf_size,
        level_pipelines: b.depth,
        history_bits: 2 * b.depth,
        fits_levels: b.depth <= cfg.max_levels,
        closed,
        consistently_oriented: oriented,
        culling_applies: oriented,
        budget: cfg.budget,
        formats,
        smallest_within_budget: smallest,
        rays: cfg.rays,
        seed: cfg.seed,
    })
}

/// The plan as text.
pub fn render(p: &Plan) -> String {
    let mut s = format!(
        "raypipe plan: scene {} ({} triangles, coordinates x {}), {} RTI pipelines\n\n",
        p.scene, p.triangles, p.scale, p.pipelines
    );
    s += &format!(
        "leaf size {} (the thesis: {}..={} for {} pipelines): {} level pipelines, {} history bits ({})\n",
        p.leaf_size,
        p.leaf_size_range[0],
        p.leaf_size_range[1],
        p.pipelines,
        p.level_pipelines,
        p.history_bits,
        if p.fits_levels { "fits the hardware" } else { "DOES NOT fit the hardware's level pipelines" }
    );
    s += &format!(
        "mesh: closed {}, consistently oriented {}: back-face culling {}\n\n",
        p.closed,
        p.consistently_oriented,
        if p.culling_applies { "applies (rays from outside)" } else { "does not apply (keep two-sided)" }
    );
    s += &format!(
        "{:<16} {:>5} {:>10} {:>8} {:>8} {:>8} {:>12} {:>7}\n",
        "format", "bits", "collapsed", "tests", "f.miss", "f.hit", "disagree", "budget"
    );
    for f in &p.formats {
        s += &format!(
            "{:<16} {:>5} {:>10} {:>8} {:>8} {:>8} {:>12.3e} {:>7}\n",
            f.format,
            f.width,
            f.collapsed_triangles,
            f.tests,
            f.false_misses,
            f.false_hits,
            f.disagreement_rate,
            if f.meets_budget {
                "ok"
            } else if f.unusable.is_some() {
                "unusable"
            } else {
                "over"
            }
        );
    }
    for f in p.formats.iter().filter(|f| f.unusable.is_some()) {
        s += &format!("{} unusable: {}\n", f.format, f.unusable.as_deref().unwrap_or(""));
    }
    s += &format!(
        "\nnarrowest format within {:e} disagreements per test: {} ({} rays, seed {})\n",
        p.budget,
        p.smallest_within_budget.as_deref().unwrap_or("none"),
        p.rays,
        p.seed
    );
    s
}
