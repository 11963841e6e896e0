//! criterion benchmarks of the slab (BVI) unit: every variant of every default format on its
//! fastest bit-identical batch (the SIMD kernels for f32 / fp16, the scalar model otherwise),
//! as pairs and as one ray against every box, beside the scalar model.
//! Run: `cargo bench --bench slab` (`RAYPIPE_PLAN=plan.json` benches only a plan's formats).

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use datapath::slab::{BoxesSoa, Slab, SlabConfig, SlabOutSoa, SlabRaysSoa};
use datapath::{with_format, AnyFormat, Format};
use std::hint::black_box;

/// Large blocks (the batch columns) at staggered page offsets, so that a kernel's columns do
/// not share cache sets (see [`datapath::alloc`]).
#[global_allocator]
static ALLOC: datapath::alloc::Staggered = datapath::alloc::Staggered;

const N: usize = 4096;

fn bench_slab(c: &mut Criterion) {
    let scene = raypipe::scene::Scene::builtin();
    let rays = scene.rays(N, 42);
    let mut g = c.benchmark_group("slab_batch");
    g.throughput(Throughput::Elements(N as u64));
    let formats: Vec<AnyFormat> = match std::env::var_os("RAYPIPE_PLAN") {
        Some(p) => raypipe::plan::load(std::path::Path::new(&p)).and_then(|p| p.within_budget()).expect("RAYPIPE_PLAN"),
        None => ["f32", "fp16", "bf16", "q8.24:divide"].iter().map(|n| n.parse().unwrap()).collect(),
    };
    for any in formats {
        with_format!(any, |f| {
            // the variants this format accepts (a conservative promise it cannot keep is refused)
            for v in SlabConfig::variants_for(&f) {
                let s = Slab::new(f, SlabConfig::named(v).unwrap());
                let (mut rs, mut bs) = (SlabRaysSoa::default(), BoxesSoa::default());
                for (ray, t) in &rays {
                    rs.push(&s.prepare(ray.o, ray.d, ray.tmin, ray.tmax));
                    let tri = &scene.tris[*t];
                    let lo = std::array::from_fn(|a| tri.v.iter().map(|p| p[a]).fold(f64::INFINITY, f64::min));
                    let hi = std::array::from_fn(|a| tri.v.iter().map(|p| p[a]).fold(f64::NEG_INFINITY, f64::max));
                    bs.push(&s.store_box(lo, hi).unwrap_or_else(|_| s.empty_box()));
                }
                let mut out = SlabOutSoa::with_len(N);
                let id = format!("{}/{v}", f.name());
                // the fastest path on every kernel this machine has, each under its cap (the
                // directed variant and other formats run the scalar model whatever the cap)
                let ray = rs.get(0);
                for k in datapath::simd::kernels_here().into_iter().filter(|&k| k != datapath::simd::Kernel::Scalar) {
                    datapath::simd::with_kernel_cap(k, || {
                        g.bench_function(BenchmarkId::new(format!("fastest_pairs_{k:?}"), &id), |b| {
                            b.iter(|| datapath::simd::slab_batch(&s, black_box(&rs), black_box(&bs), &mut out))
                        });
                        g.bench_function(BenchmarkId::new(format!("fastest_one_ray_{k:?}"), &id), |b| {
                            b.iter(|| datapath::simd::slab_ray(&s, black_box(&ray), black_box(&bs), &mut out))
                        });
                    });
                }
                g.bench_function(BenchmarkId::new("scalar_pairs", &id), |b| {
                    b.iter(|| s.batch(black_box(&rs), black_box(&bs), &mut out))
                });
            }
        });
    }
    g.finish();
}

criterion_group!(benches, bench_slab);
criterion_main!(benches);
