//! `raypipe plan`: what a scene needs from the hardware — the leaf size and RTI pipeline count
//! with the least modelled time (the thesis hardware's throughput model, [`crate::arch`])
//! within a budget of pipelines, level pipelines and BRAM bits, beside the thesis's rule of
//! thumb; tree depth (level pipelines and history bits) at that leaf size; whether back-face
//! culling applies; and per candidate format how many triangles collapse when stored and what
//! disagreement with the golden it costs, with the smallest format meeting an error budget.

use crate::arch::{estimate, ArchParams};
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
    /// RTI pipelines at most (the plan chooses 1..=this; the thesis's rule of thumb: leaf size
    /// between half and one times the pipelines).
    pub pipelines: u32,
    /// Largest acceptable rate of hit/miss disagreements with the golden, per test.
    pub budget: f64,
    /// Rays of the measurement.
    pub rays: u64,
    /// Seed of the measurement.
    pub seed: u64,
    /// Level pipelines the hardware has.
    pub max_levels: usize,
    /// The throughput model's parameters (its pipelines and levels are the candidates' and
    /// `max_levels`).
    pub arch: ArchParams,
    /// Rays of the model's traversals (half primary, half random, as `raypipe arch`).
    pub model_rays: u64,
    /// BRAM bits the traversal core has for the tree, if limited.
    pub bram_bits: Option<u64>,
    /// Leaf sizes the model considers (1..=255).
    pub leaf_sizes: Vec<u32>,
}

/// The leaf sizes `plan` considers by default.
pub const LEAF_SIZES: [u32; 13] = [1, 2, 3, 4, 6, 8, 12, 16, 24, 32, 48, 64, 128];

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
    /// RTI pipelines chosen (the least modelled time; the fewer on a tie).
    pub pipelines: u32,
    /// The thesis's recommended leaf sizes for those pipelines (half to one times them).
    pub leaf_size_range: [u32; 2],
    /// Leaf size chosen (the least modelled time; the smaller on a tie).
    pub leaf_size: u32,
    /// The budget: RTI pipelines at most.
    #[serde(default)]
    pub max_pipelines: u32,
    /// Modelled time of the chosen design in seconds (traversal + RTI, the model's rays);
    /// `None` when no candidate fits the budget.
    #[serde(default)]
    pub modelled_s: Option<f64>,
    /// The rule of thumb at the budget: leaf size = pipelines = the budget's pipelines.
    #[serde(default)]
    pub rule_leaf_size: u32,
    /// Its modelled time in seconds (`None` when its tree does not fit the budget).
    #[serde(default)]
    pub rule_modelled_s: Option<f64>,
    /// BRAM bits of the chosen tree (boxes and address words).
    #[serde(default)]
    pub bram_bits: u64,
    /// The BRAM budget, if any.
    #[serde(default)]
    pub bram_budget: Option<u64>,
    /// The chosen tree fits the BRAM budget.
    #[serde(default)]
    pub fits_bram: bool,
    /// Rays of the model's traversals.
    #[serde(default)]
    pub model_rays: u64,
    /// The model's parameters (pipelines and levels as chosen).
    #[serde(default)]
    pub arch: ArchParams,
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
    pub rays: u64,
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

/// The design the model chooses.
struct Choice {
    pipelines: u32,
    leaf_size: u32,
    modelled_s: Option<f64>,
    rule_modelled_s: Option<f64>,
    bram_bits: u64,
    arch: ArchParams,
}

/// The (pipelines, leaf size) with the least modelled time within the budget: pipelines
/// 1..=`cfg.pipelines`, trees that fit `cfg.max_levels` level pipelines and `cfg.bram_bits`.
/// Ties go to fewer pipelines, then to the smaller leaf size. When no candidate tree fits, the
/// rule of thumb (leaf size = pipelines = the budget) is planned and reported as not fitting.
fn choose(cfg: &PlanConfig, scene: &Scene) -> Result<Choice, String> {
    let rule = cfg.pipelines.min(255);
    let mut sizes: Vec<u32> = cfg.leaf_sizes.iter().copied().chain([rule]).filter(|l| (1..=255).contains(l)).collect();
    sizes.sort_unstable();
    sizes.dedup();
    let base = ArchParams { levels: cfg.max_levels.clamp(1, u32::MAX as usize) as u32, ..cfg.arch.clone() };
    base.check()?;
    let eng = engine::Engine::new(crate::traverse::CHUNK_RAYS);
    let gen = crate::traverse::CameraRays::new(scene, cfg.model_rays as usize, cfg.seed);
    // (time, pipelines, leaf size, bram bits): the order of the comparison is the tie rule
    let mut best: Option<(f64, u32, u32, u64)> = None;
    let mut rule_s = None;
    for &ls in &sizes {
        let b = crate::bvh::build(scene, ls);
        if b.depth > cfg.max_levels {
            continue;
        }
        let e = crate::arch::gather(&eng, scene, &b, ls, cfg.model_rays, |k| gen.ray(k))?;
        for n in 1..=cfg.pipelines {
            let est = estimate(&ArchParams { pipelines: n, ..base.clone() }, &e);
            if cfg.bram_bits.is_some_and(|budget| est.bram_bits > budget) {
                continue;
            }
            if n == cfg.pipelines && ls == rule {
                rule_s = Some(est.total_s);
            }
            let cand = (est.total_s, n, ls, est.bram_bits);
            if best.is_none_or(|b| (cand.0, cand.1, cand.2) < (b.0, b.1, b.2)) {
                best = Some(cand);
            }
        }
    }
    let (modelled_s, pipelines, leaf_size, bram_bits) = match best {
        Some((s, n, l, bits)) => (Some(s), n, l, bits),
        None => {
            // nothing fits: the rule of thumb's tree, with the BRAM it would need
            (None, cfg.pipelines, rule, base.bram_bits(crate::bvh::build(scene, rule).bram_boxes()))
        }
    };
    Ok(Choice {
        pipelines,
        leaf_size,
        modelled_s,
        rule_modelled_s: rule_s,
        bram_bits,
        arch: ArchParams { pipelines, ..base },
    })
}

/// Plans the hardware for a scene.
pub fn plan(cfg: &PlanConfig, scene: &Scene) -> Result<Plan, String> {
    if cfg.pipelines == 0 || cfg.pipelines > 255 {
        return Err(format!("--pipelines must be 1..=255, got {}", cfg.pipelines));
    }
    if cfg.model_rays == 0 {
        return Err("--model-rays must be at least 1".into());
    }
    if cfg.budget.is_nan() || cfg.budget < 0.0 {
        return Err(format!("--budget must be a rate >= 0, got {}", cfg.budget));
    }
    let choice = choose(cfg, scene)?;
    let leaf_size = choice.leaf_size;
    let leaf_size_range = [choice.pipelines.div_ceil(2), choice.pipelines];
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
        pipelines: choice.pipelines,
        leaf_size_range,
        leaf_size,
        max_pipelines: cfg.pipelines,
        modelled_s: choice.modelled_s,
        rule_leaf_size: cfg.pipelines.min(255),
        rule_modelled_s: choice.rule_modelled_s,
        bram_bits: choice.bram_bits,
        bram_budget: cfg.bram_bits,
        fits_bram: cfg.bram_bits.is_none_or(|budget| choice.bram_bits <= budget),
        model_rays: cfg.model_rays,
        arch: choice.arch,
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
    let us = |x: Option<f64>| x.map_or("n/a (does not fit)".to_string(), |x| format!("{:.1} us", x * 1e6));
    s += &format!(
        "modelled (raypipe arch, {} rays): {} pipelines of at most {}, leaf size {}: {}; \
         the rule of thumb (leaf size = pipelines = {}): {}\n",
        p.model_rays,
        p.pipelines,
        p.max_pipelines,
        p.leaf_size,
        us(p.modelled_s),
        p.rule_leaf_size,
        us(p.rule_modelled_s)
    );
    s += &format!(
        "leaf size {} (the thesis: {}..={} for {} pipelines): {} level pipelines, {} history bits, \
         {} BRAM bits{} ({})\n",
        p.leaf_size,
        p.leaf_size_range[0],
        p.leaf_size_range[1],
        p.pipelines,
        p.level_pipelines,
        p.history_bits,
        p.bram_bits,
        p.bram_budget.map_or(String::new(), |b| format!(" of {b}")),
        match (p.fits_levels, p.fits_bram) {
            (true, true) => "fits the hardware",
            (false, _) => "DOES NOT fit the hardware's level pipelines",
            (true, false) => "DOES NOT fit the BRAM budget",
        }
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
