//! `raypipe plan`: the tree depth, culling and format choice it reports.

use raypipe::plan::{plan, PlanConfig};
use raypipe::scene::Scene;

fn obj(name: &str, text: &str) -> Scene {
    let dir = std::env::temp_dir().join(format!("raypipe-plan-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(format!("{name}.obj"));
    std::fs::write(&p, text).unwrap();
    Scene::load_obj(&p).unwrap()
}

fn cfg(formats: &[&str], budget: f64) -> PlanConfig {
    PlanConfig {
        formats: formats.iter().map(|f| f.parse().unwrap()).collect(),
        pipelines: 4,
        budget,
        rays: 32,
        seed: 3,
        max_levels: 64,
        arch: raypipe::arch::ArchParams::default(),
        model_rays: 2000,
        bram_bits: None,
        leaf_sizes: raypipe::plan::LEAF_SIZES.to_vec(),
    }
}

const TETRA: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n";

#[test]
fn a_closed_outward_mesh_allows_culling_and_a_flipped_face_does_not() {
    // faces wound counter-clockwise seen from outside
    let good = obj("tetra", &format!("{TETRA}f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"));
    let p = plan(&cfg(&["f32"], 0.0), &good).unwrap();
    assert!(p.closed && p.consistently_oriented && p.culling_applies, "{p:?}");
    assert_eq!(p.level_pipelines, raypipe::bvh::build(&good, p.leaf_size).depth);
    assert_eq!(p.history_bits, 2 * p.level_pipelines);
    let flipped = obj("flipped", &format!("{TETRA}f 1 2 3\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"));
    let p = plan(&cfg(&["f32"], 0.0), &flipped).unwrap();
    assert!(p.closed && !p.consistently_oriented && !p.culling_applies);
    let open = obj("open", &format!("{TETRA}f 1 3 2\nf 1 2 4\nf 1 4 3\n"));
    assert!(!plan(&cfg(&["f32"], 0.0), &open).unwrap().closed);
}

#[test]
fn depth_history_bits_and_the_narrowest_format_within_budget() {
    let scene = Scene::builtin();
    let p = plan(&cfg(&["bf16", "fp16", "f32"], 1.0), &scene).unwrap();
    let b = raypipe::bvh::build(&scene, p.leaf_size);
    assert_eq!(p.level_pipelines, b.depth);
    assert_eq!(p.history_bits, 2 * b.depth);
    assert_eq!(p.leaf_size_range, [p.pipelines.div_ceil(2), p.pipelines]);
    // a budget of 1 admits everything: the narrowest (first of equal width) wins
    assert_eq!(p.smallest_within_budget.as_deref(), Some("bf16"));
    // a zero budget admits only formats with no disagreement in the measurement
    let p = plan(&cfg(&["bf16", "f32"], 0.0), &scene).unwrap();
    let bf = &p.formats[0];
    assert!(bf.false_misses + bf.false_hits > 0, "bf16 disagrees somewhere on the built-in scene: {bf:?}");
    assert_eq!(p.smallest_within_budget.as_deref(), Some("f32"));
    // too few level pipelines
    let p = plan(&PlanConfig { max_levels: 2, ..cfg(&["f32"], 0.0) }, &scene).unwrap();
    assert!(!p.fits_levels);
}

#[test]
fn bad_plan_requests_are_clear_errors() {
    let scene = Scene::builtin();
    assert!(plan(&PlanConfig { pipelines: 0, ..cfg(&["f32"], 0.0) }, &scene).unwrap_err().contains("--pipelines"));
    assert!(plan(&cfg(&["f32"], f64::NAN), &scene).unwrap_err().contains("--budget"));
    assert!(plan(&cfg(&["f32"], -1.0), &scene).unwrap_err().contains("--budget"));
}

/// The plan's design is the model's minimum over the budget: no (pipelines, leaf size) in the
/// budget is modelled faster, ties go to fewer pipelines then to the smaller leaf, and the rule
/// of thumb is reported with its own modelled time.
#[test]
fn the_plan_chooses_the_least_modelled_time_within_the_budget() {
    use raypipe::arch::{estimate, gather, ArchParams};
    let scene = Scene::builtin();
    let c = PlanConfig { pipelines: 8, leaf_sizes: vec![1, 2, 4, 8, 16], ..cfg(&["f32"], 1.0) };
    let p = plan(&c, &scene).unwrap();
    assert!(p.pipelines >= 1 && p.pipelines <= 8 && p.max_pipelines == 8);
    let best = p.modelled_s.expect("a design fits");
    // an independent evaluation of every candidate
    let eng = engine::Engine::new(64);
    let gen = raypipe::traverse::CameraRays::new(&scene, c.model_rays as usize, c.seed);
    let mut seen_rule = None;
    for ls in [1, 2, 4, 8, 16] {
        let b = raypipe::bvh::build(&scene, ls);
        let e = gather(&eng, &scene, &b, ls, c.model_rays, |k| gen.ray(k)).unwrap();
        for n in 1..=8 {
            let est = estimate(&ArchParams { pipelines: n, levels: 64, ..ArchParams::default() }, &e);
            assert!(est.total_s >= best, "{n} pipelines, leaf size {ls}: {} < the plan's {best}", est.total_s);
            if est.total_s == best {
                assert!((p.pipelines, p.leaf_size) <= (n, ls), "the tie rule: {n}, {ls} before the plan's");
            }
            if (n, ls) == (p.pipelines, p.leaf_size) {
                assert_eq!(est.total_s, best);
            }
            if (n, ls) == (8, 8) {
                seen_rule = Some(est.total_s);
            }
        }
    }
    assert_eq!(p.rule_leaf_size, 8);
    assert_eq!(p.rule_modelled_s, seen_rule);
    // a BRAM budget below the chosen tree's excludes it
    let tight = PlanConfig { bram_bits: Some(p.bram_bits - 1), ..c.clone() };
    let q = plan(&tight, &scene).unwrap();
    assert!(q.bram_bits < p.bram_bits || q.modelled_s.is_none(), "{q:?}");
    assert_ne!((q.pipelines, q.leaf_size, q.modelled_s), (p.pipelines, p.leaf_size, p.modelled_s));
    assert!(p.fits_bram && q.fits_bram == q.modelled_s.is_some());
    // a budget no tree fits: the rule of thumb's tree, reported as not fitting, with its bits
    let none = plan(&PlanConfig { bram_bits: Some(1), ..c.clone() }, &scene).unwrap();
    assert_eq!((none.modelled_s, none.fits_bram, none.leaf_size), (None, false, 8));
    assert!(none.bram_bits > 1);
}
