//! `raypipe speed`: this machine's no-FMA floating-point peak (vector adds and multiplies per
//! second) and each RTI / slab implementation's throughput as a fraction of it, for its op
//! count (51 for RTI, 12 for the slab test) — one thread, one run, the seed and sizes printed.

use datapath::format::{F16Half, F32Native, FpOpts, Ieee};
use datapath::rng::SplitMix64;
use datapath::rti::{HitsSoa, RaysSoa, Rti, RtiConfig, TrisSoa};
use datapath::simd::{rti_batch_f16, rti_batch_f32, Kernel};
use datapath::slab::{BoxesSoa, Slab, SlabConfig, SlabOutSoa, SlabRaysSoa};
use datapath::Format;
use golden::{Ray64, Tri64};
use serde::Serialize;
use std::hint::black_box;
use std::time::Instant;

/// Floating-point operations of one RTI test as the fraction of peak counts them: 51 (the stage
/// table has 48 + a reciprocal and 3 multiplies, or 48 + 3 divides; a divide is not one add's
/// cost, so the figure is a throughput yardstick, not an exact op count).
pub const RTI_OPS: f64 = 51.0;
/// Floating-point operations of one slab test (6 subtracts, 6 multiplies).
pub const SLAB_OPS: f64 = 12.0;

/// One measured implementation.
#[derive(Clone, Debug, Serialize)]
pub struct SpeedRow {
    /// What ran.
    pub name: String,
    /// Million tests per second.
    pub mtests_per_s: f64,
    /// Floating-point ops per test.
    pub ops: f64,
    /// The peak the fraction is taken against: "binary32", "binary16" (the AVX512-FP16
    /// peak, for binary16 rows on a machine that has it), or "none" (f64 work and whole runs:
    /// `ops` 0, fraction 0).
    pub peak: String,
    /// Throughput × ops / the peak of its precision.
    pub fraction_of_peak: f64,
}

/// The measurement.
#[derive(Clone, Debug, Serialize)]
pub struct SpeedReport {
    /// Pairs per run.
    pub pairs: usize,
    /// Seed of the inputs.
    pub seed: u64,
    /// Which kernel the f32 / fp16 dispatch chose.
    pub kernels: [String; 2],
    /// Measured no-FMA peak, giga lane-ops per second (binary32, widest vector unit found).
    pub peak_gops: f64,
    /// Measured no-FMA binary16 peak (AVX512-FP16 `vaddph` / `vmulph`), where the machine has it.
    pub peak16_gops: Option<f64>,
    /// Rows.
    pub rows: Vec<SpeedRow>,
    /// Which formats have a SIMD batch path for RTI and which run the scalar model only.
    pub batch_paths: Vec<String>,
    /// The widest kernel allowed (`--cap`), when capped.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cap: Option<String>,
    /// The machine: CPU model, cores, instruction-set extensions.
    pub machine: String,
    /// The engine's end-to-end rate (verify f32) over the rti f32 kernel's rate of the same
    /// run, per thread count measured: (threads, fraction).
    pub engine_over_f32_kernel: Vec<(usize, f64)>,
}

/// The RTI batch path of each format family (the SIMD kernels of `datapath::simd`).
pub const BATCH_PATHS: [&str; 5] = [
    "f32, fp16: binary32 / binary16 kernels (IEEE subnormals or FTZ, flushing in the lanes; canonical NaN)",
    "bf16: binary32 lanes, each op rounded to bf16 in integer lanes (IEEE or FTZ, canonical NaN)",
    "eEmM with M <= 24, E <= 10: binary64 lanes, each op rounded to the format in the lanes (subnormals, FTZ, overflow), a range filter skipping that work where the stage-1 values prove it unneeded (IEEE or FTZ, canonical NaN); the slab kernels: every variant, IEEE or FTZ, grid steps in the lanes (a raw subnormal t limit under FTZ: that lane on the scalar model)",
    "scalar model only: the propagate NaN rule, eEmM with E = 11 or M > 24, any :propagate float; every format's directed slab variant on ray-box pairs (one ray x many boxes has kernels)",
    "fixed point qI.F with I + F <= 32: i64 lanes for RTI and slab (every variant), every rounding, overflow and division mode (datapath::simd::fixed); wider fixed point: scalar model only",
];

/// Adds and multiplies on independent accumulators for about `secs`, on the widest vector
/// unit the kernels use here: lane-ops per second.
fn peak(secs: f64) -> f64 {
    #[cfg(target_arch = "x86_64")]
    {
        let k = datapath::simd::kernels_here();
        if k.contains(&Kernel::Avx512) {
            // SAFETY: AVX-512F detected.
            return unsafe { peak_avx512(secs) };
        }
        if k.contains(&Kernel::Avx2) {
            // SAFETY: AVX2 detected.
            return unsafe { peak_avx2(secs) };
        }
    }
    peak_scalar(secs)
}

/// The binary16 no-FMA peak on AVX512-FP16, where the machine has it: lane-ops per second.
fn peak16(secs: f64) -> Option<f64> {
    #[cfg(target_arch = "x86_64")]
    if datapath::simd::kernels_here().contains(&Kernel::Avx512Fp16) {
        // SAFETY: AVX512-FP16 (with AVX-512F and BW) detected.
        return Some(unsafe { peak_avx512fp16(secs) });
    }
    let _ = secs;
    None
}

/// Runs `burst` (which performs `per_burst` operations) repeatedly for about `secs`: operations
/// per second. The clock is read between groups of bursts (1, 2, 4, … up to 64), not after each
/// one: a clock read costs tens of nanoseconds, about a tenth of a 512-box slab batch.
fn timed(secs: f64, per_burst: u64, mut burst: impl FnMut()) -> f64 {
    let (t0, mut n, mut group) = (Instant::now(), 0u64, 1u64);
    while n == 0 || t0.elapsed().as_secs_f64() < secs {
        for _ in 0..group {
            burst();
        }
        n += group;
        group = (group * 2).min(64);
    }
    (n * per_burst) as f64 / t0.elapsed().as_secs_f64()
}

fn peak_scalar(secs: f64) -> f64 {
    let (a, m) = (black_box(-1e-7f32), black_box(1.000_000_1f32));
    let mut acc = [1.0f32; 12];
    let iters = 10_000u64;
    let r = timed(secs, iters * 12 * 2, || {
        let mut v = acc; // in registers for the burst
        for _ in 0..iters {
            for x in v.iter_mut() {
                *x = (*x + a) * m;
            }
        }
        acc = black_box(v);
    });
    black_box(acc);
    r
}

/// A vector peak loop: 12 independent add-then-multiply chains, kept in registers. `$a` and
/// `$m` keep every value normal in the lanes' format (near 1, neither growing nor decaying).
macro_rules! peak_simd {
    ($name:ident, $feat:literal, $set1:ident, $add:ident, $mul:ident, $lanes:expr, $a:expr, $m:expr) => {
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = $feat)]
        fn $name(secs: f64) -> f64 {
            use std::arch::x86_64::*;
            let a = $set1(black_box($a));
            let m = $set1(black_box($m));
            let mut acc = [$set1(1.0); 12];
            let iters = 10_000u64;
            let r = timed(secs, iters * 12 * 2 * $lanes, || {
                let mut v = acc; // in registers for the burst
                for _ in 0..iters {
                    for x in v.iter_mut() {
                        *x = $mul($add(*x, a), m);
                    }
                }
                acc = black_box(v);
            });
            black_box(acc);
            r
        }
    };
}

peak_simd!(peak_avx2, "avx2", _mm256_set1_ps, _mm256_add_ps, _mm256_mul_ps, 8, -1e-7, 1.000_000_1);
peak_simd!(peak_avx512, "avx512f", _mm512_set1_ps, _mm512_add_ps, _mm512_mul_ps, 16, -1e-7, 1.000_000_1);
// binary16: −1e-7 would be a subnormal there (and 1.0000001 would be 1), so −2^-11 and 1 + 2^-10
peak_simd!(
    peak_avx512fp16,
    "avx512fp16,avx512bw,avx512f",
    set1_ph,
    _mm512_add_ph,
    _mm512_mul_ph,
    32,
    -1.0 / 2048.0,
    1.0 + 1.0 / 1024.0
);

/// Every binary16 lane x (a binary32 value rounded by `half`): the peak loop's constants.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512fp16,avx512bw,avx512f")]
fn set1_ph(x: f32) -> std::arch::x86_64::__m512h {
    use std::arch::x86_64::*;
    _mm512_castsi512_ph(_mm512_set1_epi16(half::f16::from_f32(x).to_bits() as i16))
}

/// Best of `reps` timings of `f` over `n` tests, each repeating `f` for at least 20 ms
/// (a small working set stays in cache): million tests per second.
fn rate(n: usize, reps: usize, mut f: impl FnMut()) -> f64 {
    (0..reps).map(|_| timed(0.02, n as u64, &mut f) / 1e6).fold(0.0, f64::max)
}

/// One implementation measured beside the peak: `reps` times, a 20 ms timing of `f` between
/// two 5 ms peak bursts (binary32, and binary16 where AVX512-FP16 exists), so that both are
/// sampled across the run's clock changes. Returns the row with its best rate (its fraction of
/// peak is set by [`speed`] against the run's best peak of its precision) and the best peak
/// bursts seen.
fn row(name: &str, n: usize, ops: f64, reps: usize, f: impl FnMut()) -> (SpeedRow, [f64; 2]) {
    let mut one = in_turns(vec![Turn { name: name.into(), n, ops, f: Box::new(f) }], reps);
    one.pop().expect("one row in, one row out")
}

/// A row to measure [`in_turns`] with others: its name, tests per call, operations per test
/// and the call.
struct Turn<'a> {
    name: String,
    n: usize,
    ops: f64,
    f: Box<dyn FnMut() + 'a>,
}

/// Rows measured in turns, as [`row`] measures one: `reps` rounds, each a 20 ms timing of
/// every row's call in list order, each followed by a 5 ms peak burst — so that the rows whose
/// ratio the report states (each format's RTI batch path against the binary32 kernel) are
/// timed across the same stretch of the run, not one after the other (on a shared machine a
/// slow stretch then slows both, instead of one). Each row its best rate; every row the best
/// peak bursts seen.
fn in_turns(mut list: Vec<Turn<'_>>, reps: usize) -> Vec<(SpeedRow, [f64; 2])> {
    let burst = || [peak(0.005), peak16(0.005).unwrap_or(0.0)];
    let mut p = burst();
    let mut best = vec![0.0f64; list.len()];
    for _ in 0..reps {
        for (m, t) in best.iter_mut().zip(list.iter_mut()) {
            *m = m.max(timed(0.02, t.n as u64, &mut t.f));
            let q = burst();
            p = [p[0].max(q[0]), p[1].max(q[1])];
        }
    }
    list.iter()
        .zip(best)
        .map(|(t, m)| {
            let peak = if t.name.contains("fp16") && p[1] > 0.0 { "binary16" } else { "binary32" };
            let row = SpeedRow {
                name: t.name.clone(),
                mtests_per_s: m / 1e6,
                ops: t.ops,
                peak: peak.into(),
                fraction_of_peak: 0.0,
            };
            (row, p)
        })
        .collect()
}

/// The RTI input columns of `cases` in the unit's format.
fn columns<F: Format>(rti: &Rti<F>, cases: &[(Ray64, Tri64)]) -> (RaysSoa<F::V>, TrisSoa<F::V>) {
    let (mut rays, mut tris) = (RaysSoa::default(), TrisSoa::default());
    for (ray, t) in cases {
        rays.push(&rti.ray(ray.o, ray.d, ray.tmin, ray.tmax));
        tris.push(&rti.tri(t.v));
    }
    (rays, tris)
}

/// The slab unit's input columns for `cases`: each ray and its triangle's bounding box (the
/// empty box where the format cannot hold it).
fn slab_columns<F: Format>(s: &Slab<F>, cases: &[(Ray64, Tri64)]) -> (SlabRaysSoa<F::V>, BoxesSoa<F::V>) {
    let (mut rs, mut bs) = (SlabRaysSoa::default(), BoxesSoa::default());
    for (ray, tri) in cases {
        rs.push(&s.prepare(ray.o, ray.d, ray.tmin, ray.tmax));
        let lo = std::array::from_fn(|a| tri.v.iter().map(|p| p[a]).fold(f64::INFINITY, f64::min));
        let hi = std::array::from_fn(|a| tri.v.iter().map(|p| p[a]).fold(f64::NEG_INFINITY, f64::max));
        bs.push(&s.store_box(lo, hi).unwrap_or_else(|_| s.empty_box()));
    }
    (rs, bs)
}

/// `pairs` seeded rays of the built-in scene, each paired with its target triangle.
fn scene_cases(pairs: usize, seed: u64) -> Vec<(Ray64, Tri64)> {
    let scene = crate::scene::Scene::builtin();
    scene.rays(pairs, seed).into_iter().map(|(ray, t)| (ray, scene.tris[t])).collect()
}

/// Million RTI tests per second of a format's fastest bit-identical implementation (the SIMD
/// kernels for binary32 and binary16 where they apply, the scalar batch otherwise), over
/// `pairs` pairs of the built-in scene that stay in cache.
pub fn rti_rate(any: datapath::AnyFormat, pairs: usize, seed: u64) -> f64 {
    let cases = scene_cases(pairs, seed);
    datapath::with_format!(any, |f| {
        let rti = Rti::new(f, RtiConfig::default());
        let (rays, tris) = columns(&rti, &cases);
        let mut out = HitsSoa::with_len(pairs);
        rate(pairs, 3, || {
            datapath::simd::rti_batch(&rti, &rays, &tris, &mut out);
        })
    })
}

/// Measures.
pub fn speed(pairs: usize, seed: u64) -> SpeedReport {
    // half the pairs aim at their triangle, half at a random one (hits and misses mixed)
    let scene = crate::scene::Scene::builtin();
    let mut r = SplitMix64::new(seed);
    let mut cases = scene_cases(pairs, seed);
    for c in cases.iter_mut() {
        if r.below(2) == 1 {
            c.1 = scene.tris[r.below(scene.tris.len() as u64) as usize];
        }
    }
    let mut rows = Vec::new();
    let mut peaks = Vec::new();
    let mut push = |(row, p): (SpeedRow, [f64; 2])| {
        rows.push(row);
        peaks.push(p);
    };
    let f32f = Ieee::new(F32Native, FpOpts::default());
    let f16f = Ieee::new(F16Half, FpOpts::default());
    let r32 = Rti::new(f32f, RtiConfig::default());
    let r16 = Rti::new(f16f, RtiConfig::default());
    let (rays32, tris32) = columns(&r32, &cases);
    let (rays16, tris16) = columns(&r16, &cases);
    let mut o32 = HitsSoa::with_len(pairs);
    let mut o16 = HitsSoa::with_len(pairs);
    let mut k = [Kernel::Scalar; 2];
    // the RTI batch paths in turns (the ratios the report states are of these rows): binary32,
    // binary16, and those of bf16 (binary32 lanes), e8m16 (binary64 lanes, see
    // datapath::format::narrow) and q16.16 (i64 lanes, datapath::simd::fixed); BATCH_PATHS says
    // what runs where
    let narrow = ["bf16", "e8m16", "q16.16"];
    let mut kernels = {
        let (k32, k16) = k.split_at_mut(1);
        let mut turns = vec![
            Turn {
                name: "rti f32 kernel (dispatch)".into(),
                n: pairs,
                ops: RTI_OPS,
                f: Box::new(|| k32[0] = rti_batch_f32(&r32, &rays32, &tris32, &mut o32)),
            },
            Turn {
                name: "rti fp16 kernel (dispatch)".into(),
                n: pairs,
                ops: RTI_OPS,
                f: Box::new(|| k16[0] = rti_batch_f16(&r16, &rays16, &tris16, &mut o16)),
            },
        ];
        for name in narrow {
            let any: datapath::AnyFormat = name.parse().expect("a built-in format name");
            datapath::with_format!(any, |f| {
                let rti = Rti::new(f, RtiConfig::default());
                let (rays, tris) = columns(&rti, &cases);
                let mut out = HitsSoa::with_len(pairs);
                turns.push(Turn {
                    name: format!("rti {name} kernel (dispatch)"),
                    n: pairs,
                    ops: RTI_OPS,
                    f: Box::new(move || {
                        datapath::simd::rti_batch(&rti, &rays, &tris, &mut out);
                    }),
                });
            });
        }
        in_turns(turns, 7).into_iter()
    };
    let mut next_kernel = || kernels.next().expect("a row per turn");
    push(next_kernel());
    push(row("rti f32 scalar model", pairs, RTI_OPS, 3, || r32.batch(&rays32, &tris32, &mut o32)));
    push(next_kernel());
    push(row("rti fp16 scalar model", pairs, RTI_OPS, 3, || r16.batch(&rays16, &tris16, &mut o16)));
    for name in narrow {
        let any: datapath::AnyFormat = name.parse().expect("a built-in format name");
        push(next_kernel());
        datapath::with_format!(any, |f| {
            let rti = Rti::new(f, RtiConfig::default());
            let (rays, tris) = columns(&rti, &cases);
            let mut out = HitsSoa::with_len(pairs);
            push(row(&format!("rti {name} scalar model"), pairs, RTI_OPS, 3, || rti.batch(&rays, &tris, &mut out)));
        });
    }
    // on a machine with AVX512-FP16, the AVX-512F binary16 kernel too (binary16 through
    // conversions, against the same, AVX512-FP16, peak)
    if datapath::simd::kernels_here().contains(&Kernel::Avx512Fp16) {
        datapath::simd::with_kernel_cap(Kernel::Avx512, || {
            push(row("rti fp16 kernel (AVX-512F, capped)", pairs, RTI_OPS, 7, || {
                rti_batch_f16(&r16, &rays16, &tris16, &mut o16);
            }));
        });
    }
    // on a machine with AVX-512, the AVX2 kernels too (against the same, AVX-512, peak)
    if datapath::simd::kernels_here().contains(&Kernel::Avx512) {
        datapath::simd::with_kernel_cap(Kernel::Avx2, || {
            push(row("rti f32 kernel (AVX2, capped)", pairs, RTI_OPS, 7, || {
                rti_batch_f32(&r32, &rays32, &tris32, &mut o32);
            }));
            push(row("rti fp16 kernel (AVX2, capped)", pairs, RTI_OPS, 7, || {
                rti_batch_f16(&r16, &rays16, &tris16, &mut o16);
            }));
        });
    }
    // the AVX2 binary16 kernel with its rounding in binary32 lanes instead of an F16C round
    // trip per operation (docs/speed.md: measured both; the dispatch keeps the faster)
    if datapath::simd::kernels_here().contains(&Kernel::Avx2) {
        push(row("rti fp16 kernel (AVX2, rounding in binary32 lanes)", pairs, RTI_OPS, 7, || {
            datapath::simd::rti_batch_f16_lanes(&r16, &rays16, &tris16, &mut o16);
        }));
    }
    let c16: Vec<([half::f16; 6], [half::f16; 9])> = cases
        .iter()
        .map(|(r, t)| {
            let ray = [r.o[0], r.o[1], r.o[2], r.d[0], r.d[1], r.d[2]].map(half::f16::from_f64);
            let v: Vec<half::f16> = t.v.iter().flatten().map(|&x| half::f16::from_f64(x)).collect();
            (ray, v.try_into().expect("nine coordinates"))
        })
        .collect();
    push(row("half-crate scalar fp16 MT (baseline)", pairs, RTI_OPS, 3, || {
        black_box(c16.iter().filter(|(r, t)| half_mt(black_box(r), black_box(t))).count());
    }));
    // the slab unit over the bounding boxes of the same triangles: pairs, and one ray against
    // every box (the shape a node's or a level's children have)
    let bf16f: datapath::AnyFormat = "bf16".parse().expect("a built-in format name");
    let q16f: datapath::AnyFormat = "q16.16".parse().expect("a built-in format name");
    let e8f: datapath::AnyFormat = "e8m16".parse().expect("a built-in format name");
    for (name, any) in [
        ("f32", datapath::AnyFormat::F32(f32f)),
        ("fp16", datapath::AnyFormat::F16(f16f)),
        ("bf16", bf16f),
        ("e8m16", e8f),
        ("q16.16", q16f),
    ] {
        datapath::with_format!(any, |f| {
            let s = Slab::new(f, SlabConfig::default());
            let (rs, bs) = slab_columns(&s, &cases);
            let mut out = SlabOutSoa::with_len(pairs);
            push(row(&format!("slab {name} kernel (dispatch, plain)"), pairs, SLAB_OPS, 7, || {
                datapath::simd::slab_batch(&s, &rs, &bs, &mut out);
            }));
            if pairs > 0 {
                let ray = rs.get(0);
                push(row(&format!("slab {name} kernel, one ray x {pairs} boxes (plain)"), pairs, SLAB_OPS, 7, || {
                    datapath::simd::slab_ray(&s, &ray, &bs, &mut out);
                }));
            }
            push(row(&format!("slab {name} scalar model (plain)"), pairs, SLAB_OPS, 3, || s.batch(&rs, &bs, &mut out)));
        });
    }
    if datapath::simd::kernels_here().contains(&Kernel::Avx2) {
        let s = Slab::new(f16f, SlabConfig::default());
        let (rs, bs) = slab_columns(&s, &cases);
        let mut out = SlabOutSoa::with_len(pairs);
        datapath::simd::with_kernel_cap(Kernel::Avx2, || {
            push(row("slab fp16 kernel (AVX2, capped, plain)", pairs, SLAB_OPS, 7, || {
                datapath::simd::slab_batch_f16(&s, &rs, &bs, &mut out);
            }));
        });
        push(row("slab fp16 kernel (AVX2, rounding in binary32 lanes, plain)", pairs, SLAB_OPS, 7, || {
            datapath::simd::slab_batch_f16_lanes(&s, &rs, &bs, &mut out);
        }));
    }
    // the golden and the error bound on f64 lanes (one ray against a block of 256 triangles, as
    // the engine runs them; f64 work, so no fraction of the binary32 peak)
    {
        let n = pairs.clamp(1, 256);
        let ray =
            cases.first().map_or(Ray64 { o: [0.0; 3], d: [0.0, 0.0, 1.0], tmin: 0.0, tmax: f64::INFINITY }, |c| c.0);
        let cols: [Vec<f64>; 9] =
            std::array::from_fn(|k| (0..n).map(|i| cases.get(i).map_or(0.0, |c| c.1.v[k / 3][k % 3])).collect());
        let c9 = || -> [&[f64]; 9] { std::array::from_fn(|k| &cols[k][..]) };
        let (mut hit, mut t) = (vec![false; n], vec![0.0; n]);
        let level = crate::golden_level();
        push(row(&format!("golden mt f64 block ({level:?})"), n, 0.0, 3, || {
            golden::block::intersect_block(level, &ray, golden::Faces::default(), c9(), &mut hit, &mut t)
        }));
        let (mut dec, mut te) = (vec![false; n], vec![0.0; n]);
        let opts = datapath::bound::BlockOpts {
            em: f32f.error_model(),
            div: datapath::format::DivMode::RecipMul,
            cull: datapath::rti::Cull::TwoSided,
            det_threshold: 0.0,
        };
        let bray = datapath::bound::BlockRay { o: ray.o, d: ray.d, tmin: ray.tmin, tmax: ray.tmax };
        push(row("error bound f64 block (widest here)", n, 0.0, 3, || {
            datapath::bound::verdict_block(Kernel::Avx512Fp16, opts, bray, c9(), &mut dec, &mut hit, &mut te)
        }));
        // the same bound as one loop the compiler vectorises (before the explicit registers)
        push(row("error bound f64 block, compiler-vectorised loop (widest here)", n, 0.0, 3, || {
            datapath::bound::verdict_block_loop(Kernel::Avx512Fp16, opts, bray, c9(), &mut dec, &mut hit, &mut te)
        }));
        // the same block with the static filter in front (datapath::bound_filter; verify's path)
        let mut cert = vec![false; n];
        push(row("error bound f64 block, static filter first (widest here)", n, 0.0, 3, || {
            datapath::bound_filter::verdict_block_filtered(
                Kernel::Avx512Fp16,
                opts,
                bray,
                c9(),
                None,
                &mut dec,
                &mut hit,
                &mut te,
                &mut cert,
            );
        }));
    }
    // the traversals on the built-in scene's BVH, f32 slab unit as box tester, first 4 leaves,
    // 4096 rays (M rays/s): the 2-bit history traversal with each box test of a ray remembered
    // and its result's buffers reused (as `traverse` and `render` run it) against the ordered
    // stack traversal (the speed issue's ratio, history >= 0.8 of stack, is these two rows of
    // one run)
    {
        let scene = crate::scene::Scene::builtin();
        let b = crate::bvh::build(&scene, 4);
        let s = Slab::new(f32f, SlabConfig::default());
        let boxes: Vec<_> =
            b.nodes.iter().map(|nd| s.store_box(nd.min, nd.max).unwrap_or_else(|_| s.empty_box())).collect();
        if let Ok(hw) = b.layout_ids(64) {
            let tree = b.golden_tree();
            let rays: Vec<_> =
                crate::traverse::rays(&scene, 4096, seed).iter().map(|r| s.prepare(r.o, r.d, r.tmin, r.tmax)).collect();
            let test = |r: &datapath::slab::SlabRay<f32>, i: u32| {
                let o = s.test(r, &boxes[i as usize]);
                o.hit.then_some(o.t_near as f64)
            };
            let mut memo = datapath::box_memo::BoxMemo::new(boxes.len());
            let mut res = datapath::bvh::StacklessResult::default();
            let mut sink = 0usize;
            push(row(
                "traverse: 2-bit history, box tests remembered, f32 slab, N = 4 (M rays/s)",
                rays.len(),
                0.0,
                3,
                || {
                    for r in &rays {
                        memo.next_ray();
                        datapath::bvh::history_traverse_into(&hw, 4, |&i| memo.get_or(i, || test(r, i)), &mut res);
                        sink += res.leaves.len();
                    }
                },
            ));
            push(row("traverse: ordered stack, f32 slab, N = 4 (M rays/s)", rays.len(), 0.0, 3, || {
                for r in &rays {
                    sink += golden::bvh::stack_traverse(&tree, 4, |i| test(r, i)).leaves.len();
                }
            }));
            std::hint::black_box(sink);
        }
    }
    // a batch far beyond the caches: one pass over 1 M-pair columns against the same pairs
    // streamed through L1-sized chunks gathered from the scene (gather included)
    {
        let big = 1 << 20;
        let (mut br, mut bt) = (RaysSoa::with_capacity(big), TrisSoa::with_capacity(big));
        for i in 0..big {
            br.push(&rays32.get(i % pairs.max(1)));
            bt.push(&tris32.get(i % pairs.max(1)));
        }
        let mut bo = HitsSoa::with_len(big);
        if pairs > 0 {
            push(row("rti f32 kernel, one pass over 1 M-pair columns", big, RTI_OPS, 3, || {
                rti_batch_f32(&r32, &br, &bt, &mut bo);
            }));
            let mut sink = 0;
            push(row("rti f32 kernel, 1 M pairs streamed through L1 chunks", big, RTI_OPS, 3, || {
                datapath::simd::rti_stream(
                    &r32,
                    big,
                    |range, rs, ts| {
                        // the chunk's pairs, column by column, from the cached columns
                        let mut k = 0;
                        while k < range.len() {
                            let from = (range.start + k) % pairs;
                            let m = (pairs - from).min(range.len() - k);
                            let cols = rs.o.iter_mut().chain(&mut rs.d).chain([&mut rs.tmin, &mut rs.tmax]);
                            let srcs = rays32.o.iter().chain(&rays32.d).chain([&rays32.tmin, &rays32.tmax]);
                            for (dst, src) in
                                cols.chain(ts.v.iter_mut().flatten()).zip(srcs.chain(tris32.v.iter().flatten()))
                            {
                                dst[k..k + m].copy_from_slice(&src[from..from + m]);
                            }
                            k += m;
                        }
                    },
                    |_, _, _, out| sink += out.hit[0] as usize,
                );
            }));
            black_box(sink);
        }
    }
    // column placement: 128 Ki pairs (columns of 512 KiB, beyond L2) with the columns at
    // staggered page offsets (this binary's allocator) and all at one page offset (where the
    // system allocator puts such blocks), for the RTI and the slab pairs kernels
    if pairs > 0 && datapath::alloc::is_global() {
        use datapath::alloc::{with_placement, Placement};
        let mid = 1 << 17;
        let s = Slab::new(f32f, SlabConfig::default());
        let (srays, sboxes) = slab_columns(&s, &cases);
        for (label, place) in
            [("staggered columns", Placement::Staggered), ("columns at one page offset", Placement::SamePageOffset)]
        {
            let (br, bt, mut bo, sr, sb, mut so) = with_placement(place, || {
                let (mut br, mut bt) = (RaysSoa::with_capacity(mid), TrisSoa::with_capacity(mid));
                let (mut sr, mut sb) = (SlabRaysSoa::default(), BoxesSoa::default());
                for i in 0..mid {
                    br.push(&rays32.get(i % pairs));
                    bt.push(&tris32.get(i % pairs));
                    sr.push(&srays.get(i % pairs));
                    sb.push(&sboxes.get(i % pairs));
                }
                (br, bt, HitsSoa::with_len(mid), sr, sb, SlabOutSoa::with_len(mid))
            });
            push(row(&format!("rti f32 kernel, 128 Ki pairs, {label}"), mid, RTI_OPS, 3, || {
                rti_batch_f32(&r32, &br, &bt, &mut bo);
            }));
            push(row(&format!("slab f32 kernel, 128 Ki pairs, {label}"), mid, SLAB_OPS, 3, || {
                datapath::simd::slab_batch(&s, &sr, &sb, &mut so);
            }));
            // (freed here, before the next placement's columns are made)
        }
    }
    // the streaming engine end to end: `verify` on the built-in scene (every ray against all 368
    // triangles, the slab variants included), tests judged per second of wall time, on one
    // thread and on every core (the ratio is the engine's thread scaling)
    {
        let scene = crate::scene::Scene::builtin();
        let rays = 2048;
        let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
        for t in [1, threads] {
            let mut cfg = crate::verify::VerifyConfig::new(
                vec!["f32".parse().expect("built-in format")],
                rays,
                seed,
                RtiConfig::default(),
                512,
            );
            cfg.engine = engine::Engine::new(crate::verify::CHUNK_RAYS).with_threads(Some(t));
            let best =
                (0..3).map(|_| crate::verify::verify(&cfg, &scene).formats[0].judged_mtests_per_s).fold(0.0, f64::max);
            rows.push(SpeedRow {
                name: format!(
                    "engine: verify f32 end to end, {rays} rays x 368 triangles + 5 slab variants, {t} thread(s)"
                ),
                mtests_per_s: best,
                ops: 0.0,
                peak: "binary32".into(),
                fraction_of_peak: 0.0,
            });
        }
    }
    // every fraction against the one, best, peak of the run: the best rate over the best peak
    // (a ratio taken per timing would reward a peak burst that the shared machine slowed)
    let peak = peaks.iter().map(|p| p[0]).fold(0.0, f64::max);
    let peak16 = peaks.iter().map(|p| p[1]).fold(0.0, f64::max);
    for r in &mut rows {
        // f64 work (the golden, the bound) and whole runs (the engine) have no op count: no
        // fraction of a binary32 / binary16 peak
        if r.ops == 0.0 {
            r.peak = "none".into();
            continue;
        }
        let p = if r.peak == "binary16" { peak16 } else { peak };
        r.fraction_of_peak = r.mtests_per_s * 1e6 * r.ops / p;
    }
    let rate = |name: &str| rows.iter().find(|r| r.name == name).map_or(0.0, |r| r.mtests_per_s);
    let f32k = rate("rti f32 kernel (dispatch)");
    let engine_over_f32_kernel = rows
        .iter()
        .filter_map(|r| {
            let t = r.name.strip_prefix("engine: verify f32 end to end")?.rsplit(", ").next()?;
            let threads = t.strip_suffix(" thread(s)")?.parse().ok()?;
            (f32k > 0.0).then(|| (threads, r.mtests_per_s / f32k))
        })
        .collect();
    SpeedReport {
        engine_over_f32_kernel,
        batch_paths: BATCH_PATHS.iter().map(|s| s.to_string()).collect(),
        pairs,
        seed,
        kernels: k.map(|k| format!("{k:?}")),
        peak_gops: peak / 1e9,
        peak16_gops: (peak16 > 0.0).then_some(peak16 / 1e9),
        rows,
        cap: None,
        machine: crate::machine::machine(),
    }
}

/// Textbook Möller–Trumbore in `half`'s f16 (every operation rounded by the crate).
fn half_mt(r: &[half::f16; 6], v: &[half::f16; 9]) -> bool {
    use half::f16;
    let sub = |a: [f16; 3], b: [f16; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let cross =
        |a: [f16; 3], b: [f16; 3]| [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
    let dot = |a: [f16; 3], b: [f16; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let (o, d) = ([r[0], r[1], r[2]], [r[3], r[4], r[5]]);
    let (v0, v1, v2) = ([v[0], v[1], v[2]], [v[3], v[4], v[5]], [v[6], v[7], v[8]]);
    let (e1, e2) = (sub(v1, v0), sub(v2, v0));
    let p = cross(d, e2);
    let det = dot(e1, p);
    let inv = f16::ONE / det;
    let s = sub(o, v0);
    let u = dot(s, p) * inv;
    let q = cross(s, e1);
    let w = dot(d, q) * inv;
    let t = dot(e2, q) * inv;
    u >= f16::ZERO && w >= f16::ZERO && u + w <= f16::ONE && t >= f16::ZERO
}

/// The measurement as a markdown table.
pub fn render(s: &SpeedReport) -> String {
    let p16 = s.peak16_gops.map_or(String::new(), |p| format!(", {p:.1} G lane-ops/s (binary16, AVX512-FP16)"));
    let mut out = format!(
        "raypipe speed on {}: {} pairs (built-in scene, seed {}), one thread; kernels{}: f32 {}, fp16 {}; measured no-FMA peak {:.1} G lane-ops/s (binary32){p16}\n\n",
        s.machine,
        s.pairs,
        s.seed,
        s.cap.as_ref().map_or(String::new(), |c| format!(" (capped at {c})")),
        s.kernels[0],
        s.kernels[1],
        s.peak_gops
    );
    let with16 = s.peak16_gops.is_some();
    out += if with16 {
        "| implementation | M tests/s | ops/test | fraction of peak | peak |\n|---|---:|---:|---:|---|\n"
    } else {
        "| implementation | M tests/s | ops/test | fraction of peak |\n|---|---:|---:|---:|\n"
    };
    for r in &s.rows {
        out += &if r.peak == "none" {
            format!("| {} | {:.1} | — | — |", r.name, r.mtests_per_s)
        } else {
            format!("| {} | {:.1} | {} | {:.3} |", r.name, r.mtests_per_s, r.ops, r.fraction_of_peak)
        };
        out += &if with16 { format!(" {} |\n", r.peak) } else { "\n".into() };
    }
    // each format's RTI batch path against the binary32 kernel of the same run
    let rate = |name: &str| s.rows.iter().find(|r| r.name == name).map(|r| r.mtests_per_s);
    if let Some(f32k) = rate("rti f32 kernel (dispatch)").filter(|&r| r > 0.0) {
        let ratios: Vec<String> = ["fp16", "bf16", "e8m16", "q16.16"]
            .iter()
            .filter_map(|f| rate(&format!("rti {f} kernel (dispatch)")).map(|r| format!("{f} {:.3}", r / f32k)))
            .collect();
        out += &format!("\nRTI batch path / f32 kernel, this run: {}\n", ratios.join(", "));
    }
    if !s.engine_over_f32_kernel.is_empty() {
        let e: Vec<String> = s.engine_over_f32_kernel.iter().map(|(t, f)| format!("{t} thread(s) {f:.4}")).collect();
        out += &format!("engine (verify f32 end to end, judged tests) / rti f32 kernel, this run: {}\n", e.join(", "));
    }
    out += "\nRTI batch paths:\n";
    for p in &s.batch_paths {
        out += &format!("- {p}\n");
    }
    out
}
