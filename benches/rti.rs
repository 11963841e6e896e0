//! criterion benchmarks of the RTI models (pairwise batch path) against baselines: the golden
//! f64 reference, a plain scalar f32 Möller–Trumbore and a `half`-crate scalar fp16 one.
//! Run: `cargo bench --bench rti` (`RAYPIPE_PLAN=plan.json` benches only a plan's formats).
//! Last, the run measures this machine's no-FMA add / multiply peak and prints each
//! implementation's throughput as a fraction of it (the `raypipe speed` table).

use criterion::{criterion_group, BenchmarkId, Criterion, Throughput};
use datapath::rng::SplitMix64;
use datapath::rti::{HitsSoa, RaysSoa, Rti, RtiConfig, TrisSoa};
use datapath::{with_format, AnyFormat, Format};
use golden::{Faces, Ray64, Tri64};
use half::f16;
use std::hint::black_box;

/// Large blocks (the batch columns) at staggered page offsets, so that a kernel's columns do
/// not share cache sets (see [`datapath::alloc`]).
#[global_allocator]
static ALLOC: datapath::alloc::Staggered = datapath::alloc::Staggered;

const N: usize = 4096;

fn cases() -> Vec<(Ray64, Tri64)> {
    let scene = raypipe::scene::Scene::builtin();
    let mut r = SplitMix64::new(42);
    scene
        .rays(N, 42)
        .into_iter()
        .map(|(ray, target)| {
            let i = if r.below(2) == 0 { target } else { r.below(scene.tris.len() as u64) as usize };
            (ray, scene.tris[i])
        })
        .collect()
}

fn bench_models(c: &mut Criterion) {
    let cases = cases();
    let mut g = c.benchmark_group("rti_batch");
    g.throughput(Throughput::Elements(N as u64));
    // RAYPIPE_PLAN=plan.json (from `raypipe plan --json`) benches only the plan's formats within budget
    let formats: Vec<AnyFormat> = match std::env::var_os("RAYPIPE_PLAN") {
        Some(p) => raypipe::plan::load(std::path::Path::new(&p)).and_then(|p| p.within_budget()).expect("RAYPIPE_PLAN"),
        None => ["f32", "fp16", "bf16", "e8m16", "q8.24:divide"].iter().map(|n| n.parse().unwrap()).collect(),
    };
    for any in formats {
        with_format!(any, |f| {
            let rti = Rti::new(f, RtiConfig::default());
            let (mut rays, mut tris) = (RaysSoa::default(), TrisSoa::default());
            for (ray, tri) in &cases {
                rays.push(&rti.ray(ray.o, ray.d, ray.tmin, ray.tmax));
                tris.push(&rti.tri(tri.v));
            }
            let mut out = HitsSoa::with_len(N);
            g.bench_with_input(BenchmarkId::new("model", rti.fmt.name()), &(), |b, _| {
                b.iter(|| rti.batch(black_box(&rays), black_box(&tris), &mut out))
            });
        });
    }
    // the SIMD kernels with runtime dispatch (bit-identical to the models above)
    {
        use datapath::format::{F16Half, F32Native, FpOpts, Ieee};
        let r32 = Rti::new(Ieee::new(F32Native, FpOpts::default()), RtiConfig::default());
        let r16 = Rti::new(Ieee::new(F16Half, FpOpts::default()), RtiConfig::default());
        let (mut rays32, mut tris32, mut rays16, mut tris16) =
            (RaysSoa::default(), TrisSoa::default(), RaysSoa::default(), TrisSoa::default());
        for (ray, tri) in &cases {
            rays32.push(&r32.ray(ray.o, ray.d, ray.tmin, ray.tmax));
            tris32.push(&r32.tri(tri.v));
            rays16.push(&r16.ray(ray.o, ray.d, ray.tmin, ray.tmax));
            tris16.push(&r16.tri(tri.v));
        }
        let (mut o32, mut o16) = (HitsSoa::with_len(N), HitsSoa::with_len(N));
        // every SIMD kernel this machine has (AVX2, and AVX-512F / AVX512-FP16 where present), each
        // under its cap
        for k in datapath::simd::kernels_here().into_iter().filter(|&k| k != datapath::simd::Kernel::Scalar) {
            datapath::simd::with_kernel_cap(k, || {
                // (binary32 has no AVX512-FP16 kernel: under that cap it runs the AVX-512F one)
                if k != datapath::simd::Kernel::Avx512Fp16 {
                    g.bench_function(BenchmarkId::new("simd_f32", format!("{k:?}")), |b| {
                        b.iter(|| datapath::simd::rti_batch_f32(&r32, black_box(&rays32), black_box(&tris32), &mut o32))
                    });
                }
                g.bench_function(BenchmarkId::new("simd_fp16", format!("{k:?}")), |b| {
                    b.iter(|| datapath::simd::rti_batch_f16(&r16, black_box(&rays16), black_box(&tris16), &mut o16))
                });
            });
        }
    }
    g.bench_function("golden_f64", |b| {
        b.iter(|| {
            cases
                .iter()
                .filter(|(ray, tri)| golden::intersect(black_box(ray), black_box(tri), Faces::default()).hit)
                .count()
        })
    });
    let c32: Vec<([f32; 6], [f32; 9])> = cases
        .iter()
        .map(|(r, t)| {
            let ray = [r.o[0], r.o[1], r.o[2], r.d[0], r.d[1], r.d[2]].map(|x| x as f32);
            let v: Vec<f32> = t.v.iter().flatten().map(|&x| x as f32).collect();
            (ray, v.try_into().unwrap())
        })
        .collect();
    g.bench_function("plain_scalar_f32_mt", |b| {
        b.iter(|| c32.iter().filter(|(r, t)| plain_mt(black_box(r), black_box(t)).is_some()).count())
    });
    let c16: Vec<([f16; 6], [f16; 9])> =
        c32.iter().map(|(r, t)| (r.map(f16::from_f32), t.map(f16::from_f32))).collect();
    g.bench_function("half_scalar_fp16_mt", |b| {
        b.iter(|| c16.iter().filter(|(r, t)| plain_mt(black_box(r), black_box(t)).is_some()).count())
    });
    g.finish();
}

/// Textbook Möller–Trumbore in any `Copy` arithmetic type (the baselines).
fn plain_mt<T>(r: &[T; 6], v: &[T; 9]) -> Option<T>
where
    T: Copy
        + PartialOrd
        + std::ops::Add<Output = T>
        + std::ops::Sub<Output = T>
        + std::ops::Mul<Output = T>
        + std::ops::Div<Output = T>
        + From<u8>,
{
    let zero = T::from(0u8);
    let one = T::from(1u8);
    let sub = |a: [T; 3], b: [T; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let cross =
        |a: [T; 3], b: [T; 3]| [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
    let dot = |a: [T; 3], b: [T; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let (o, d) = ([r[0], r[1], r[2]], [r[3], r[4], r[5]]);
    let (v0, v1, v2) = ([v[0], v[1], v[2]], [v[3], v[4], v[5]], [v[6], v[7], v[8]]);
    let e1 = sub(v1, v0);
    let e2 = sub(v2, v0);
    let p = cross(d, e2);
    let det = dot(e1, p);
    if det == zero {
        return None;
    }
    let inv = one / det;
    let s = sub(o, v0);
    let u = dot(s, p) * inv;
    let q = cross(s, e1);
    let w = dot(d, q) * inv;
    let t = dot(e2, q) * inv;
    (u >= zero && w >= zero && u + w <= one && t >= zero).then_some(t)
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).measurement_time(std::time::Duration::from_secs(2)).warm_up_time(std::time::Duration::from_millis(500));
    targets = bench_models
}
/// criterion's main, then this machine's no-FMA peak and every RTI / slab implementation's
/// throughput as a fraction of it (`raypipe speed`'s table, 512 cached pairs, seed 1), unless
/// criterion was only asked to list or filter.
fn main() {
    benches();
    Criterion::default().configure_from_args().final_summary();
    let args: Vec<String> = std::env::args().skip(1).filter(|a| a != "--bench").collect();
    if args.is_empty() {
        println!("\n{}", raypipe::speed::render(&raypipe::speed::speed(512, 1)));
    }
}
