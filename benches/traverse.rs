//! criterion benchmarks of the traversals and of vector export, on the built-in scene:
//! the 2-bit history traversal and the ordered stack traversal (first N = 4 leaves, the f32
//! slab model as box tester), obvhs's own BVH2 closest-hit traversal on the same rays (a
//! different job, the software baseline), and writing a vector set.
//! Run: `cargo bench --bench traverse`.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use datapath::bvh::{history_traverse, HwTree};
use datapath::format::{F32Native, FpOpts, Ieee};
use datapath::slab::{Aabb, Slab, SlabConfig};
use golden::bvh::stack_traverse;
use std::hint::black_box;

/// Large blocks (the batch columns) at staggered page offsets, so that a kernel's columns do
/// not share cache sets (see [`datapath::alloc`]).
#[global_allocator]
static ALLOC: datapath::alloc::Staggered = datapath::alloc::Staggered;

const RAYS: usize = 4096;

fn bench_traversals(c: &mut Criterion) {
    let scene = raypipe::scene::Scene::builtin();
    let b = raypipe::bvh::build(&scene, 4);
    let s = Slab::new(Ieee::new(F32Native, FpOpts::default()), SlabConfig::default());
    let boxes: Vec<Aabb<f32>> = b.nodes.iter().map(|n| s.store_box(n.min, n.max).expect("finite box")).collect();
    let hw: HwTree<u32> = b.layout_ids(64).expect("fits");
    let tree = b.golden_tree();
    let rays: Vec<_> =
        raypipe::traverse::rays(&scene, RAYS, 1).iter().map(|r| s.prepare(r.o, r.d, r.tmin, r.tmax)).collect();
    let mut g = c.benchmark_group("traverse");
    g.throughput(Throughput::Elements(RAYS as u64));
    g.bench_function("history_f32_slab_n4", |bch| {
        bch.iter(|| {
            rays.iter()
                .map(|r| {
                    history_traverse(&hw, 4, |&i| {
                        let o = s.test(r, &boxes[i as usize]);
                        o.hit.then_some(o.t_near as f64)
                    })
                    .leaves
                    .len()
                })
                .sum::<usize>()
        })
    });
    // the same history traversal with each box test of a ray computed once (datapath::box_memo;
    // the traversal's results and counted box tests unchanged): against the stack traversal,
    // the ratio (history >= 0.8 of stack)
    let mut memo = datapath::box_memo::BoxMemo::new(boxes.len());
    g.bench_function("history_f32_slab_n4_memo", |bch| {
        bch.iter(|| {
            rays.iter()
                .map(|r| {
                    memo.next_ray();
                    history_traverse(&hw, 4, |&i| {
                        memo.get_or(i, || {
                            let o = s.test(r, &boxes[i as usize]);
                            o.hit.then_some(o.t_near as f64)
                        })
                    })
                    .leaves
                    .len()
                })
                .sum::<usize>()
        })
    });
    g.bench_function("stack_f32_slab_n4", |bch| {
        bch.iter(|| {
            rays.iter()
                .map(|r| {
                    stack_traverse(&tree, 4, |i| {
                        let o = s.test(r, &boxes[i as usize]);
                        o.hit.then_some(o.t_near as f64)
                    })
                    .leaves
                    .len()
                })
                .sum::<usize>()
        })
    });
    // obvhs's BVH2 over the same triangles, closest hit with its own triangle test
    use obvhs::{bvh2::builder::build_bvh2_from_tris, ray::Ray, ray::RayHit, triangle::Triangle, BvhBuildParams};
    let v = |p: [f64; 3]| glam::Vec3A::new(p[0] as f32, p[1] as f32, p[2] as f32);
    let tris: Vec<Triangle> =
        scene.tris.iter().map(|t| Triangle { v0: v(t.v[0]), v1: v(t.v[1]), v2: v(t.v[2]) }).collect();
    let bvh = build_bvh2_from_tris(&tris, BvhBuildParams::medium_build(), &mut std::time::Duration::default());
    let orays: Vec<Ray> =
        raypipe::traverse::rays(&scene, RAYS, 1).iter().map(|r| Ray::new_inf(v(r.o), v(r.d).normalize())).collect();
    g.bench_function("obvhs_bvh2_closest_hit", |bch| {
        bch.iter(|| {
            orays
                .iter()
                .filter(|r| {
                    let mut hit = RayHit::none();
                    bvh.ray_traverse(**r, &mut hit, |ray, id| tris[bvh.primitive_indices[id] as usize].intersect(ray))
                })
                .count()
        })
    });
    g.finish();
}

fn bench_export(c: &mut Criterion) {
    let mut g = c.benchmark_group("vectors");
    let dir = std::env::temp_dir().join(format!("raypipe-bench-vectors-{}", std::process::id()));
    let req = vectors::gen::Request {
        count: 64,
        command: "bench".into(),
        ..vectors::gen::Request::new(vectors::gen::Unit::Rti, "f32".parse().expect("format"))
    };
    g.throughput(Throughput::Elements(12 * 64));
    g.bench_function("rti_f32_generate_and_write", |bch| {
        bch.iter(|| {
            let set = vectors::gen::generate(black_box(&req)).expect("set");
            vectors::write::write_set(&set, &dir).expect("written");
        })
    });
    g.finish();
    let _ = std::fs::remove_dir_all(&dir);
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10).measurement_time(std::time::Duration::from_secs(2)).warm_up_time(std::time::Duration::from_millis(300));
    targets = bench_traversals, bench_export
}
criterion_main!(benches);
