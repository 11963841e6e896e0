//! Multi-core runs give the same results as one thread (rayon pools of 1 and 2 threads).

use raypipe::scene::Scene;
use raypipe::verify::{verify, verify_slab, VerifyConfig};

fn pool(n: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new().num_threads(n).build().unwrap()
}

/// The report as JSON without the timing fields.
fn untimed<T: serde::Serialize>(r: &T) -> serde_json::Value {
    fn strip(v: &mut serde_json::Value) {
        match v {
            serde_json::Value::Object(m) => {
                m.remove("mtests_per_s");
                m.values_mut().for_each(strip);
            }
            serde_json::Value::Array(a) => a.iter_mut().for_each(strip),
            _ => {}
        }
    }
    let mut v = serde_json::to_value(r).unwrap();
    strip(&mut v);
    v
}

#[test]
fn verify_is_the_same_on_one_and_two_threads() {
    let scene = Scene::builtin();
    let cfg = VerifyConfig {
        formats: ["f32", "fp16", "q8.24:divide"].iter().map(|f| f.parse().unwrap()).collect(),
        rays: 64,
        seed: 5,
        rti: Default::default(),
        sample: 512,
    };
    let one = pool(1).install(|| verify(&cfg, &scene));
    let two = pool(2).install(|| verify(&cfg, &scene));
    assert_eq!(untimed(&one), untimed(&two));
    assert!(one.formats.iter().all(|f| f.tests > 0));
    let s1 = pool(1).install(|| verify_slab(&cfg, &scene));
    let s2 = pool(2).install(|| verify_slab(&cfg, &scene));
    assert_eq!(untimed(&s1), untimed(&s2));
}

#[test]
fn stats_are_the_same_on_one_and_two_threads() {
    let scene = Scene::builtin();
    let one = pool(1).install(|| raypipe::stats::stats(&scene, &[2, 8], 300, 4).unwrap());
    let two = pool(2).install(|| raypipe::stats::stats(&scene, &[2, 8], 300, 4).unwrap());
    assert_eq!(serde_json::to_string(&one).unwrap(), serde_json::to_string(&two).unwrap());
    assert!(one.rows.iter().all(|r| r.rays_hit > 0));
}

#[test]
fn skipped_work_is_counted() {
    let scene = Scene::builtin();
    // RTI: every hit was valid, so the divides skipped are at most the tests without a hit
    let cfg =
        VerifyConfig { formats: vec!["f32".parse().unwrap()], rays: 16, seed: 2, rti: Default::default(), sample: 512 };
    let f = &verify(&cfg, &scene).formats[0];
    assert!(f.divide_skipped > 0 && f.divide_skipped <= f.tests - f.model_hits, "{f:?}");
    // traversal: stopping at N = 1 skips box tests; an N no ray reaches skips none
    let t = |n: usize| {
        raypipe::traverse::traverse(
            &raypipe::traverse::TraverseConfig {
                formats: vec!["f32".parse().unwrap()],
                variant: "plain".into(),
                rays: 200,
                seed: 3,
                n,
                leaf_size: 4,
                levels: 64,
            },
            &scene,
        )
        .unwrap()
        .rows[0]
            .box_tests_skipped
    };
    assert!(t(1) > 0);
    assert_eq!(t(1_000_000), 0);
}
