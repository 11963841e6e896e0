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
    }
}

const TETRA: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n";

#[test]
fn a_closed_outward_mesh_allows_culling_and_a_flipped_face_does_not() {
    // faces wound counter-clockwise seen from outside
    let good = obj("tetra", &format!("{TETRA}f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"));
    let p = plan(&cfg(&["f32"], 0.0), &good).unwrap();
    assert!(p.closed && p.consistently_oriented && p.culling_applies, "{p:?}");
    assert_eq!(p.level_pipelines, raypipe::bvh::build(&good, 4).depth);
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
    let b = raypipe::bvh::build(&scene, 4);
    assert_eq!(p.level_pipelines, b.depth);
    assert_eq!(p.history_bits, 2 * b.depth);
    assert_eq!(p.leaf_size_range, [2, 4]);
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
