//! Multi-core runs give the same results as one thread: the streaming engine's reports do not
//! depend on the thread count or the chunk size, and they equal the scalar per-test judge.

mod common;

use common::untimed;
use raypipe::scene::Scene;
use raypipe::verify::{verify, verify_slab, VerifyConfig};

fn pool(n: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new().num_threads(n).build().unwrap()
}

fn cfg(formats: &[&str], rays: u64, seed: u64) -> VerifyConfig {
    VerifyConfig::new(formats.iter().map(|f| f.parse().unwrap()).collect(), rays, seed, Default::default(), 512)
}

#[test]
fn verify_does_not_depend_on_threads_or_chunks() {
    let scene = Scene::builtin();
    let base = cfg(&["f32", "fp16", "q8.24:divide"], 64, 5);
    let one = {
        let mut c = base.clone();
        c.engine = engine::Engine { threads: 1, chunk: 64, shard: engine::Shard::ALL };
        verify(&c, &scene)
    };
    assert!(one.formats.iter().all(|f| f.tests > 0));
    for (threads, chunk) in [(2, 16), (2, 1), (3, 5), (1, 7), (4, 1000)] {
        let mut c = base.clone();
        c.engine = engine::Engine { threads, chunk, shard: engine::Shard::ALL };
        assert_eq!(untimed(&one), untimed(&verify(&c, &scene)), "threads {threads} chunk {chunk}");
    }
    let s1 = pool(1).install(|| verify_slab(&base, &scene));
    assert_eq!(untimed(&s1), untimed(&one.slab));
}

/// The streaming report against the scalar per-test path: `judge::judge` on every (ray,
/// triangle) test, the scalar min-capture unit, `golden::closest_hit`, and the scalar slab
/// model against `golden::slab_f64` / `slab_exact`. Counts and maxima are equal; each median is
/// the lower edge of the 2^-10-wide bucket holding the exact upper median.
#[test]
fn the_streaming_engine_equals_the_scalar_judge() {
    use datapath::rti::{Capture, Rti};
    use datapath::slab::{Slab, SlabConfig};
    use datapath::{with_format, Format};
    let scene = Scene::builtin();
    let c = cfg(&["f32", "bf16", "e5m10:ftz"], 24, 9);
    let rep = verify(&c, &scene);
    for (f, got) in c.formats.iter().zip(&rep.formats) {
        with_format!(*f, |fmt| {
            let rti = Rti::new(fmt, c.rti);
            let mut n = [0u64; 11];
            let (mut ulps, mut rels) = (Vec::new(), Vec::new());
            let mut slab = vec![[0u64; 5]; 0];
            let variants = SlabConfig::variants_for(&rti.fmt);
            slab.resize(variants.len(), [0; 5]);
            for (i, (ray, _)) in scene.rays(c.rays as usize, c.seed).iter().enumerate() {
                let _ = i;
                let mut cap = Capture::default();
                // the closest hit among the reference decisions (nearest golden t)
                let mut best: Option<(usize, f64)> = None;
                for (k, tri) in scene.tris.iter().enumerate() {
                    let j = raypipe::judge::judge(&rti, ray, tri);
                    n[0] += 1;
                    n[1] += j.decisive as u64;
                    n[2] += j.reference_hit as u64;
                    n[3] += j.hit as u64;
                    n[4] += (j.reference_hit && !j.hit) as u64;
                    n[5] += (!j.reference_hit && j.hit) as u64;
                    n[6] += j.violation().is_some() as u64;
                    n[10] += j.fell_through as u64;
                    if j.reference_hit && best.is_none_or(|(_, bt)| j.golden.t < bt) {
                        best = Some((k, j.golden.t));
                    }
                    if j.hit && j.reference_hit {
                        n[7] += 1;
                        ulps.push(j.t_error() / j.ulp);
                        rels.push(j.t_error() / j.golden.t.abs().max(f64::MIN_POSITIVE));
                    }
                    let out = rti.test(&rti.ray(ray.o, ray.d, ray.tmin, ray.tmax), &rti.tri(tri.v));
                    n[9] += !out.valid as u64;
                    rti.capture(&mut cap, &out, k as u32);
                }
                n[8] += !match (best, cap.hit) {
                    (None, false) => true,
                    (Some((gi, _)), true) => gi == cap.id as usize,
                    _ => false,
                } as u64;
                let qf = |x: f64| rti.fmt.to_f64(rti.fmt.from_f64(x));
                for (v, acc) in variants.iter().zip(slab.iter_mut()) {
                    let s = Slab::new(rti.fmt, SlabConfig::named(v).unwrap());
                    let sr = s.prepare(ray.o, ray.d, ray.tmin, ray.tmax);
                    let (oq, dq) = (ray.o.map(qf), ray.d.map(qf));
                    for t in &scene.tris {
                        let lo = std::array::from_fn(|a| t.v.iter().map(|p| p[a]).fold(f64::INFINITY, f64::min));
                        let hi = std::array::from_fn(|a| t.v.iter().map(|p| p[a]).fold(f64::NEG_INFINITY, f64::max));
                        let hit = s.test(&sr, &s.store_box(lo, hi).unwrap_or_else(|_| s.empty_box())).hit;
                        let g = golden::slab_f64(oq, dq, qf(ray.tmin), qf(ray.tmax), lo, hi);
                        let scale = 1f64.max(g.t_near.abs()).max(if g.t_far.is_finite() { g.t_far.abs() } else { 0.0 });
                        let close = (g.t_far - g.t_near).abs() <= 1e-9 * scale;
                        let exact = if close || g.hit != hit {
                            acc[4] += 1;
                            golden::slab_exact(oq, dq, qf(ray.tmin), qf(ray.tmax), lo, hi).unwrap_or(g.hit)
                        } else {
                            g.hit
                        };
                        acc[0] += 1;
                        acc[1] += exact as u64;
                        acc[2] += (exact && !hit) as u64;
                        acc[3] += (!exact && hit) as u64;
                    }
                }
            }
            let want = [
                got.tests,
                got.decisive,
                got.golden_hits,
                got.model_hits,
                got.false_misses,
                got.false_hits,
                got.violations,
                got.shared_hits,
                got.closest_disagreements,
                got.divide_skipped,
                got.exact,
            ];
            assert_eq!(n, want, "{}", got.format);
            assert!(n[7] > 10, "{}: too few shared hits to compare errors", got.format);
            for (xs, med, max) in [
                (&mut ulps, got.t_err_ulps_median, got.t_err_ulps_max),
                (&mut rels, got.t_err_rel_median, got.t_err_rel_max),
            ] {
                xs.sort_by(f64::total_cmp);
                assert_eq!(max.to_bits(), xs.last().unwrap().to_bits(), "{}", got.format);
                let m = xs[xs.len() / 2];
                assert!(
                    med <= m && m < med * (1.0 + 2f64.powi(-10)) + f64::MIN_POSITIVE,
                    "{}: median {med} vs {m}",
                    got.format
                );
            }
            let rows: Vec<_> = rep.slab.iter().filter(|r| r.format == got.format).collect();
            assert_eq!(rows.len(), variants.len());
            for (r, a) in rows.iter().zip(&slab) {
                assert_eq!(
                    [r.tests, r.exact_hits, r.false_misses, r.false_hits, r.exact_calls],
                    *a,
                    "{} {}",
                    r.format,
                    r.variant
                );
            }
        });
    }
}

#[test]
fn stats_and_traverse_do_not_depend_on_threads_or_chunks() {
    let scene = Scene::builtin();
    let on = |threads, chunk| {
        raypipe::stats::stats_on(
            &engine::Engine { threads, chunk, shard: engine::Shard::ALL },
            false,
            &scene,
            &[2, 8],
            300,
            4,
        )
        .unwrap()
    };
    let one = on(1, 1000);
    for (t, c) in [(2, 256), (3, 7), (2, 1)] {
        assert_eq!(serde_json::to_string(&one).unwrap(), serde_json::to_string(&on(t, c)).unwrap(), "{t} {c}");
    }
    assert!(one.rows.iter().all(|r| r.rays_hit > 0));
    let tr = |threads, chunk| {
        raypipe::traverse::traverse(
            &traverse_cfg(200, 3, engine::Engine { threads, chunk, shard: engine::Shard::ALL }),
            &scene,
        )
        .unwrap()
    };
    let one = tr(1, 1000);
    assert!(one.passed && one.rows.iter().all(|r| r.leaves > 0));
    for (t, c) in [(2, 256), (3, 7), (2, 1)] {
        assert_eq!(serde_json::to_string(&one).unwrap(), serde_json::to_string(&tr(t, c)).unwrap(), "{t} {c}");
    }
}

fn traverse_cfg(n: usize, seed: u64, engine: engine::Engine) -> raypipe::traverse::TraverseConfig {
    raypipe::traverse::TraverseConfig {
        formats: ["f32", "fp16", "q8.24:divide"].iter().map(|f| f.parse().unwrap()).collect(),
        variant: "plain".into(),
        rays: 200,
        seed,
        n,
        leaf_size: 4,
        levels: 64,
        engine,
        progress: false,
    }
}

#[test]
fn skipped_work_is_counted() {
    let scene = Scene::builtin();
    // RTI: every hit was valid, so the divides skipped are at most the tests without a hit
    let f = &verify(&cfg(&["f32"], 16, 2), &scene).formats[0];
    assert!(f.divide_skipped > 0 && f.divide_skipped <= f.tests - f.model_hits, "{f:?}");
    // traversal: stopping at N = 1 skips box tests; an N no ray reaches skips none
    let t = |n: usize| {
        raypipe::traverse::traverse(&traverse_cfg(n, 3, engine::Engine::new(256)), &scene).unwrap().rows[0]
            .box_tests_skipped
    };
    assert!(t(1) > 0);
    assert_eq!(t(1_000_000), 0);
}
