//! The SIMD kernels return exactly the scalar model's bits, specials included.

use datapath::format::{DivMode, F16Half, F32Native, FpOpts, Ieee, NanMode, Subnormals};
use datapath::rng::SplitMix64;
use datapath::rti::{Cull, HitsSoa, RaysSoa, Rti, RtiConfig, TieRule, TrisSoa};
use datapath::simd::{
    kernel_f16, kernel_f32, kernels_here, rti_batch_f16, rti_batch_f32, with_kernel_cap, Kernel, WIDEST_F16, WIDEST_F32,
};
use datapath::Format;
use proptest::prelude::*;

/// A lane value: mostly ordinary, sometimes a special of the format (bits).
fn value<F: Format>(f: &F, r: &mut SplitMix64, specials: &[u64]) -> F::V {
    match r.below(10) {
        0 => f.from_bits(specials[r.below(specials.len() as u64) as usize]),
        1 => f.from_bits(r.next_u64()),
        _ => f.from_f64(r.range(-2.0, 2.0)),
    }
}

fn columns<F: Format>(f: &F, n: usize, seed: u64, specials: &[u64]) -> (RaysSoa<F::V>, TrisSoa<F::V>) {
    let mut r = SplitMix64::new(seed);
    let mut rays = RaysSoa::default();
    let mut tris = TrisSoa::default();
    for _ in 0..n {
        // aim at the triangle most of the time so that hits occur
        let v: [[F::V; 3]; 3] = std::array::from_fn(|_| std::array::from_fn(|_| value(f, &mut r, specials)));
        let o: [F::V; 3] = std::array::from_fn(|_| value(f, &mut r, specials));
        let d: [F::V; 3] = if r.below(2) == 0 {
            std::array::from_fn(|a| f.sub(v[0][a], o[a]))
        } else {
            std::array::from_fn(|_| value(f, &mut r, specials))
        };
        let tmin = if r.below(4) == 0 { value(f, &mut r, specials) } else { f.zero() };
        let tmax = if r.below(4) == 0 { value(f, &mut r, specials) } else { f.from_f64(f64::INFINITY) };
        rays.push(&datapath::rti::Ray { o, d, tmin, tmax });
        tris.push(&datapath::rti::Tri { v });
    }
    (rays, tris)
}

fn same<F: Format>(f: &F, a: &HitsSoa<F::V>, b: &HitsSoa<F::V>) -> Result<(), TestCaseError> {
    prop_assert_eq!(&a.hit, &b.hit);
    prop_assert_eq!(&a.valid, &b.valid);
    for (name, x, y) in [("t", &a.t, &b.t), ("u", &a.u, &b.u), ("v", &a.v, &b.v)] {
        let xb: Vec<u64> = x.iter().map(|&v| f.to_bits(v)).collect();
        let yb: Vec<u64> = y.iter().map(|&v| f.to_bits(v)).collect();
        prop_assert_eq!(xb, yb, "{}", name);
    }
    Ok(())
}

const F32_SPECIALS: [u64; 12] = [
    0,
    0x8000_0000,
    1,
    0x8000_0001,
    0x007f_ffff,
    0x0080_0000,
    0x7f7f_ffff,
    0xff7f_ffff,
    0x7f80_0000,
    0xff80_0000,
    0x7fc0_0001,
    0xffa0_0000,
];
const F16_SPECIALS: [u64; 12] = [0, 0x8000, 1, 0x8001, 0x03ff, 0x0400, 0x7bff, 0xfbff, 0x7c00, 0xfc00, 0x7e01, 0xfd00];

fn config(cull: bool, thr: f64) -> RtiConfig {
    RtiConfig { cull: if cull { Cull::Backface } else { Cull::TwoSided }, det_threshold: thr, tie: TieRule::First }
}

/// Runs `batch` on every kernel this machine has (each under a cap, checking that the cap's
/// kernel, or the format's `widest` below it, is the one that ran) and compares it with the
/// scalar model's bits.
fn on_every_kernel<O>(
    widest: Kernel,
    scalar: &O,
    mut batch: impl FnMut(&mut O) -> Kernel,
    mut fresh: impl FnMut() -> O,
    same: impl Fn(&O, &O) -> Result<(), TestCaseError>,
) -> Result<(), TestCaseError> {
    for k in kernels_here() {
        let mut out = fresh();
        let ran = with_kernel_cap(k, || batch(&mut out));
        prop_assert_eq!(ran, k.min(widest));
        same(scalar, &out)?;
    }
    Ok(())
}

/// A typed RTI batch entry point (`rti_batch_f32`, …).
type RtiBatchFn<F> =
    fn(&Rti<F>, &RaysSoa<<F as Format>::V>, &TrisSoa<<F as Format>::V>, &mut HitsSoa<<F as Format>::V>) -> Kernel;

/// FTZ options, either division mode.
fn ftz_opts(divide: bool) -> FpOpts {
    FpOpts {
        div: if divide { DivMode::Divide } else { DivMode::RecipMul },
        subnormals: Subnormals::Ftz,
        ..FpOpts::default()
    }
}

/// `batch` on every kernel against the scalar model, on columns of the edge encodings and on
/// ordinary columns at scale 2^k.
fn check_ftz<F: Format + Copy>(
    rti: &Rti<F>,
    n: usize,
    seed: u64,
    (specials, k): (&[u64], i32),
    widest: Kernel,
    batch: RtiBatchFn<F>,
) -> Result<(), TestCaseError>
where
    F::V: Default,
{
    let f = rti.fmt;
    for (rays, tris) in [columns(&f, n, seed, specials), scaled_columns(&f, n, seed, k)] {
        let mut a = HitsSoa::with_len(n);
        rti.batch(&rays, &tris, &mut a);
        on_every_kernel(widest, &a, |b| batch(rti, &rays, &tris, b), || HitsSoa::with_len(n), |a, b| same(&f, a, b))?;
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    #[test]
    fn f32_kernels_match_the_scalar_model(seed in any::<u64>(), n in 0usize..300, divide in any::<bool>(), cull in any::<bool>(), thr in prop_oneof![Just(0.0), Just(1e-6), Just(0.5)]) {
        let f = Ieee::new(F32Native, FpOpts { div: if divide { DivMode::Divide } else { DivMode::RecipMul }, ..FpOpts::default() });
        let rti = Rti::new(f, config(cull, thr));
        let (rays, tris) = columns(&f, n, seed, &F32_SPECIALS);
        let mut a = HitsSoa::with_len(n);
        rti.batch(&rays, &tris, &mut a);
        on_every_kernel(WIDEST_F32, &a, |b| rti_batch_f32(&rti, &rays, &tris, b), || HitsSoa::with_len(n), |a, b| same(&f, a, b))?;
    }

    /// binary32 under FTZ: the same kernels with every operand read and every result flushed in
    /// the lanes; columns with the edge encodings (subnormals included), and ordinary columns at
    /// a scale where the products of stages 2-7 fall into the subnormal range.
    #[test]
    fn f32_ftz_kernels_match_the_scalar_model(seed in any::<u64>(), n in 0usize..300, divide in any::<bool>(), cull in any::<bool>(), thr in prop_oneof![Just(0.0), Just(1e-40), Just(0.5)], k in -48i32..-20) {
        let f = Ieee::new(F32Native, ftz_opts(divide));
        check_ftz(&Rti::new(f, config(cull, thr)), n, seed, (&F32_SPECIALS, k), WIDEST_F32, rti_batch_f32)?;
    }

    /// binary16 under FTZ, likewise (products subnormal at scales 2^−12…2^−3).
    #[test]
    fn f16_ftz_kernels_match_the_scalar_model(seed in any::<u64>(), n in 0usize..300, divide in any::<bool>(), cull in any::<bool>(), thr in prop_oneof![Just(0.0), Just(1e-3), Just(0.5)], k in -12i32..-2) {
        let f = Ieee::new(F16Half, ftz_opts(divide));
        check_ftz(&Rti::new(f, config(cull, thr)), n, seed, (&F16_SPECIALS, k), WIDEST_F16, rti_batch_f16)?;
    }

    #[test]
    fn f16_kernels_match_the_scalar_model(seed in any::<u64>(), n in 0usize..300, divide in any::<bool>(), cull in any::<bool>(), thr in prop_oneof![Just(0.0), Just(1e-3), Just(0.5)]) {
        let f = Ieee::new(F16Half, FpOpts { div: if divide { DivMode::Divide } else { DivMode::RecipMul }, ..FpOpts::default() });
        let rti = Rti::new(f, config(cull, thr));
        let (rays, tris) = columns(&f, n, seed, &F16_SPECIALS);
        let mut a = HitsSoa::with_len(n);
        rti.batch(&rays, &tris, &mut a);
        on_every_kernel(WIDEST_F16, &a, |b| rti_batch_f16(&rti, &rays, &tris, b), || HitsSoa::with_len(n), |a, b| same(&f, a, b))?;
    }
}

proptest! {
    // a measured alternative, not the dispatched kernel: fewer cases
    #![proptest_config(ProptestConfig { cases: 16, ..ProptestConfig::default() })]

    /// The AVX2 binary16 RTI kernel whose rounding stays in binary32 lanes (`isa::v8r`), with
    /// and without FTZ (products subnormal at scales 2^−12…2^−3).
    #[test]
    fn f16_kernel_rounding_in_lanes_matches_the_scalar_model(seed in any::<u64>(), n in 0usize..300, divide in any::<bool>(), cull in any::<bool>(), thr in prop_oneof![Just(0.0), Just(1e-3), Just(0.5)], k in -12i32..-2) {
        let f = Ieee::new(F16Half, FpOpts { div: if divide { DivMode::Divide } else { DivMode::RecipMul }, ..FpOpts::default() });
        let rti = Rti::new(f, config(cull, thr));
        let (rays, tris) = columns(&f, n, seed, &F16_SPECIALS);
        let mut a = HitsSoa::with_len(n);
        rti.batch(&rays, &tris, &mut a);
        on_every_kernel(Kernel::Avx2, &a, |b| datapath::simd::rti_batch_f16_lanes(&rti, &rays, &tris, b), || HitsSoa::with_len(n), |a, b| same(&f, a, b))?;
        let g = Ieee::new(F16Half, ftz_opts(divide));
        check_ftz(&Rti::new(g, config(cull, thr)), n, seed, (&F16_SPECIALS, k), Kernel::Avx2, datapath::simd::rti_batch_f16_lanes)?;
    }
}

/// Edge encodings of a float layout: ±0, ±least subnormal, the largest subnormal, the least
/// normal, ±max finite, ±infinity, a quiet NaN with a payload and a negative signalling NaN.
fn float_specials(l: datapath::format::FloatLayout) -> Vec<u64> {
    let s = l.sign_mask();
    let e = l.exp_mask();
    let top = 1u64 << l.man_bits;
    vec![0, s, 1, s | 1, top - 1, top, e - 1, s | (e - 1), e, s | e, e | (top >> 1) | 1, s | e | 1]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    /// The narrow float formats' binary64-lane kernels (bf16 and `eEmM` with M <= 24, E <= 10,
    /// every subnormal and division mode) return the scalar model's bits on every kernel.
    #[test]
    fn narrow_float_kernels_match_the_scalar_model(seed in any::<u64>(), n in 0usize..300, fmt in 0usize..12, cull in any::<bool>(), thr in prop_oneof![Just(0.0), Just(1e-3), Just(0.5)]) {
        use datapath::format::{Bf16, Soft, FloatLayout};
        use datapath::simd::{kernel_narrow, rti_batch_bf16, rti_batch_soft, WIDEST_NARROW};
        let names = ["bf16", "bf16:ftz", "bf16:divide", "bf16:ftz+divide", "e8m16", "e8m16:ftz+divide", "e5m4", "e5m4:ftz", "e4m3:divide", "e10m24", "e10m24:ftz", "e2m1"];
        let any: datapath::AnyFormat = names[fmt].parse().unwrap();
        match any {
            datapath::AnyFormat::Bf16(f) => {
                let rti = Rti::new(f, config(cull, thr));
                let (rays, tris) = columns(&f, n, seed, &float_specials(FloatLayout::BFLOAT16));
                let mut a = HitsSoa::with_len(n);
                rti.batch(&rays, &tris, &mut a);
                prop_assert_eq!(kernel_narrow(&rti), kernels_here().last().unwrap().min(&WIDEST_NARROW).to_owned());
                on_every_kernel(WIDEST_NARROW, &a, |b| rti_batch_bf16(&rti, &rays, &tris, b), || HitsSoa::with_len(n), |a, b| same(&f, a, b))?;
                let _: Option<Ieee<Bf16>> = None;
            }
            datapath::AnyFormat::Soft(f) => {
                let rti = Rti::new(f, config(cull, thr));
                let (rays, tris) = columns(&f, n, seed, &float_specials(f.backend.0));
                let mut a = HitsSoa::with_len(n);
                rti.batch(&rays, &tris, &mut a);
                on_every_kernel(WIDEST_NARROW, &a, |b| rti_batch_soft(&rti, &rays, &tris, b), || HitsSoa::with_len(n), |a, b| same(&f, a, b))?;
                let _: Option<Ieee<Soft>> = None;
            }
            _ => unreachable!(),
        }
    }
}

/// Columns of ordinary values at one scale 2^k (no specials), so that whole vectors pass or
/// fail the narrow kernels' range filter together: the scales where products underflow to
/// subnormals or overflow are the ones that hold the filter's limits to account.
fn scaled_columns<F: Format>(f: &F, n: usize, seed: u64, k: i32) -> (RaysSoa<F::V>, TrisSoa<F::V>) {
    let mut r = SplitMix64::new(seed);
    let s = 2f64.powi(k);
    let (mut rays, mut tris) = (RaysSoa::default(), TrisSoa::default());
    for _ in 0..n {
        let v: [[F::V; 3]; 3] = std::array::from_fn(|_| std::array::from_fn(|_| f.from_f64(r.range(-2.0, 2.0) * s)));
        let o: [F::V; 3] = std::array::from_fn(|_| f.from_f64(r.range(-2.0, 2.0) * s));
        let d: [F::V; 3] = std::array::from_fn(|a| f.sub(v[0][a], o[a]));
        rays.push(&datapath::rti::Ray { o, d, tmin: f.zero(), tmax: f.from_f64(f64::INFINITY) });
        tris.push(&datapath::rti::Tri { v });
    }
    (rays, tris)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    /// The narrow kernels' range filter at its limits: ordinary inputs at a scale from deep in
    /// the underflow range to near overflow give the scalar model's bits.
    #[test]
    fn narrow_kernels_match_the_scalar_model_at_every_scale(seed in any::<u64>(), n in 8usize..200, fmt in 0usize..5, frac in 0.0f64..1.0) {
        use datapath::format::Soft;
        use datapath::simd::{rti_batch_soft, WIDEST_NARROW};
        let names = ["e8m16", "e8m16:ftz", "e5m4", "e10m24:divide", "e6m9:ftz+divide"];
        let any: datapath::AnyFormat = names[fmt].parse().unwrap();
        let datapath::AnyFormat::Soft(f) = any else { unreachable!() };
        let lay = f.backend.0;
        // k from emin / 2 - 4 (stage-2 products subnormal) to emax / 3 + 2 (t', det overflow)
        let (lo, hi) = (lay.emin() / 2 - 4, lay.emax() / 3 + 2);
        let k = lo + ((hi - lo) as f64 * frac) as i32;
        let rti = Rti::new(f, RtiConfig::default());
        let (rays, tris) = scaled_columns(&f, n, seed, k);
        let mut a = HitsSoa::with_len(n);
        rti.batch(&rays, &tris, &mut a);
        on_every_kernel(WIDEST_NARROW, &a, |b| rti_batch_soft(&rti, &rays, &tris, b), || HitsSoa::with_len(n), |a, b| same(&f, a, b))?;
        let _: Option<Ieee<Soft>> = None;
    }
}

/// Formats outside the narrow path (E = 11, M > 24, the propagate NaN rule) run the scalar model.
#[test]
fn formats_outside_the_narrow_path_run_the_scalar_model() {
    for name in ["e11m20", "e8m25", "e8m16:propagate", "bf16:propagate"] {
        let any: datapath::AnyFormat = name.parse().unwrap();
        let k = match any {
            datapath::AnyFormat::Bf16(f) => datapath::simd::kernel_narrow(&Rti::new(f, RtiConfig::default())),
            datapath::AnyFormat::Soft(f) => datapath::simd::kernel_narrow(&Rti::new(f, RtiConfig::default())),
            _ => unreachable!(),
        };
        assert_eq!(k, Kernel::Scalar, "{name}");
    }
}

#[test]
fn the_kernels_here_are_the_ones_the_machine_has_and_a_cap_is_restored() {
    let k = kernels_here();
    assert_eq!(k[0], Kernel::Scalar);
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::is_x86_feature_detected as has;
        assert_eq!(k.contains(&Kernel::Avx2), has!("avx2") && has!("f16c"));
        assert_eq!(k.contains(&Kernel::Avx512), has!("avx512f") && has!("avx2") && has!("f16c"));
        assert_eq!(
            k.contains(&Kernel::Avx512Fp16),
            has!("avx512fp16") && has!("avx512bw") && has!("avx512f") && has!("avx2") && has!("f16c")
        );
    }
    // `RAYPIPE_EXPECT_KERNEL=avx512` (set by `emu/avx512`, which runs these tests under
    // an emulator) makes
    // a machine without the kernel a failure instead of a silent skip
    if let Ok(want) = std::env::var("RAYPIPE_EXPECT_KERNEL") {
        let want = match want.as_str() {
            "avx2" => Kernel::Avx2,
            "avx512" => Kernel::Avx512,
            "avx512fp16" => Kernel::Avx512Fp16,
            other => panic!("unknown kernel {other:?}"),
        };
        assert!(k.contains(&want), "{want:?} expected, this machine has {k:?}");
    }
    let f = Ieee::new(F32Native, FpOpts::default());
    let rti = Rti::new(f, RtiConfig::default());
    let best = *k.last().unwrap();
    assert_eq!(kernel_f32(&rti), best.min(WIDEST_F32));
    let h = Rti::new(Ieee::new(F16Half, FpOpts::default()), RtiConfig::default());
    assert_eq!(kernel_f16(&h), best);
    assert_eq!(with_kernel_cap(Kernel::Scalar, || kernel_f32(&rti)), Kernel::Scalar);
    // nested caps, and a cap left by a panic, are undone
    with_kernel_cap(Kernel::Avx2, || {
        assert_eq!(with_kernel_cap(Kernel::Scalar, || kernel_f32(&rti)), Kernel::Scalar);
        assert_eq!(kernel_f32(&rti), best.min(Kernel::Avx2));
        assert_eq!(kernel_f16(&h), best.min(Kernel::Avx2));
    });
    assert!(std::panic::catch_unwind(|| with_kernel_cap(Kernel::Scalar, || panic!("inside"))).is_err());
    assert_eq!(kernel_f32(&rti), best.min(WIDEST_F32));
}

#[test]
fn the_kernels_run_where_the_machine_has_them_and_hit_often_enough_to_matter() {
    let f32f = Ieee::new(F32Native, FpOpts::default());
    let f16f = Ieee::new(F16Half, FpOpts::default());
    #[cfg(target_arch = "x86_64")]
    {
        let best = *kernels_here().last().unwrap();
        assert_eq!(kernel_f32(&Rti::new(f32f, RtiConfig::default())), best.min(WIDEST_F32));
        assert_eq!(kernel_f16(&Rti::new(f16f, RtiConfig::default())), best);
    }
    // formats the kernels do not model fall back to the scalar model (FTZ has RTI kernels;
    // the propagate NaN rule does not)
    let prop = Ieee::new(F16Half, FpOpts { nan: NanMode::Propagate, ..FpOpts::default() });
    let prop32 = Ieee::new(F32Native, FpOpts { nan: NanMode::Propagate, ..FpOpts::default() });
    assert_eq!(kernel_f16(&Rti::new(prop, RtiConfig::default())), Kernel::Scalar);
    assert_eq!(kernel_f32(&Rti::new(prop32, RtiConfig::default())), Kernel::Scalar);
    // so does a negative or NaN det threshold (the kernels' sign-flip side tests assume >= 0)
    for thr in [-0.5f32, f32::NAN] {
        let mut neg = Rti::new(f32f, RtiConfig::default());
        neg.det_thr = thr;
        assert_eq!(kernel_f32(&neg), Kernel::Scalar);
        let mut neg16 = Rti::new(f16f, RtiConfig::default());
        neg16.det_thr = half::f16::from_f32(thr);
        assert_eq!(kernel_f16(&neg16), Kernel::Scalar);
    }
    // the generated columns are not vacuous: hits, misses and NaN outputs all occur
    let rti = Rti::new(f32f, RtiConfig::default());
    let (rays, tris) = columns(&f32f, 4000, 3, &F32_SPECIALS);
    let mut out = HitsSoa::with_len(4000);
    rti_batch_f32(&rti, &rays, &tris, &mut out);
    let hits = out.hit.iter().filter(|&&h| h).count();
    assert!(hits > 200 && hits < 3800, "{hits}");
    assert!(out.t.iter().any(|t| t.is_nan()) && out.t.iter().any(|t| t.is_infinite()));
}

mod slab {
    use super::*;
    use datapath::simd::{
        slab_batch_bf16, slab_batch_f16, slab_batch_f32, slab_kernel_f16, slab_kernel_f32, slab_ray_bf16, slab_ray_f16,
        slab_ray_f32, slab_ray_kernel_f16, slab_ray_kernel_f32,
    };
    use datapath::slab::{Aabb, BoxesSoa, Slab, SlabConfig, SlabOutSoa, SlabRay, SlabRaysSoa};

    fn f64_value(r: &mut SplitMix64) -> f64 {
        match r.below(12) {
            0 => [0.0, -0.0, f64::INFINITY, f64::NEG_INFINITY, f64::NAN, 1e-40, -1e-40, 3e38, 6e-8, 65504.0]
                [r.below(10) as usize],
            1 => f32::from_bits(r.next_u64() as u32) as f64,
            _ => r.range(-2.0, 2.0),
        }
    }

    /// A seeded slab batch: rays (half aimed near their box), boxes (a quarter raw bits).
    fn batch<F: Format>(s: &Slab<F>, seed: u64, n: usize) -> (SlabRaysSoa<F::V>, BoxesSoa<F::V>) {
        let f = &s.fmt;
        let mut r = SplitMix64::new(seed);
        let (mut rays, mut boxes) = (SlabRaysSoa::default(), BoxesSoa::default());
        let e = datapath::format::edges(f);
        for _ in 0..n {
            // one case in 8 at the scale of the smallest normal, where plane differences and
            // products fall into the subnormal range (flushed under FTZ)
            let sc = if r.below(8) == 0 { e.min_normal * 4.0 } else { 1.0 };
            let c: [f64; 3] = std::array::from_fn(|_| r.range(-1.0, 1.0) * sc);
            let o: [f64; 3] = std::array::from_fn(|_| f64_value(&mut r) * sc);
            // half the rays aim near the box centre so that hits and grazes occur
            let d: [f64; 3] = if r.below(2) == 0 {
                std::array::from_fn(|a| (c[a] + r.range(-0.6, 0.6) * sc - o[a]) / sc)
            } else {
                std::array::from_fn(|_| f64_value(&mut r))
            };
            // the t interval: mostly [0, inf), sometimes specials, NaN included (a one-ray batch
            // skips its per-vector NaN check when its interval holds numbers)
            // (and the format's edges: ±max, ±least, ±min normal, whose grid steps leave the
            // finite range or cross into or out of the subnormals)
            let limit = |r: &mut SplitMix64, usual: f64| match r.below(20) {
                0 => f64::NAN,
                1 => f64_value(r),
                2 => [e.max, -e.max, e.least, -e.least, e.min_normal, -e.min_normal][r.below(6) as usize],
                _ => usual,
            };
            let tmin = limit(&mut r, 0.0);
            let tmax = limit(&mut r, f64::INFINITY);
            let mut ray = s.prepare(o, d, tmin, tmax);
            // and sometimes a NaN with a payload or a sign (prepare canonicalises NaN; the
            // kernels must canonicalise what the column holds)
            let inf = f.to_bits(f.from_f64(f64::INFINITY));
            let sign = f.to_bits(f.from_f64(-0.0));
            for t in [&mut ray.tmin, &mut ray.tmax] {
                if r.below(20) == 0 {
                    *t = f.from_bits(inf | (1 + r.below(4)) | if r.below(2) == 0 { sign } else { 0 });
                }
            }
            // and raw encodings `prepare` would have flushed under FTZ: subnormal t limits,
            // origins and reciprocals (the model reads the operands flushed, and passes a t
            // limit through its comparators as it is)
            let raw_sub = |r: &mut SplitMix64| f.from_bits((1 + r.below(4)) | if r.below(2) == 0 { sign } else { 0 });
            for t in [&mut ray.tmin, &mut ray.tmax] {
                if r.below(24) == 0 {
                    *t = raw_sub(&mut r);
                }
            }
            for a in 0..3 {
                if r.below(40) == 0 {
                    ray.o[a] = raw_sub(&mut r);
                }
                if r.below(40) == 0 {
                    ray.inv_d[a] = raw_sub(&mut r);
                }
            }
            rays.push(&ray);
            // a box around c, or raw bits
            let b = if r.below(4) == 0 {
                Aabb {
                    min: std::array::from_fn(|_| f.from_bits(r.next_u64())),
                    max: std::array::from_fn(|_| f.from_bits(r.next_u64())),
                }
            } else {
                let e: [f64; 3] = std::array::from_fn(|_| if r.below(5) == 0 { 0.0 } else { r.range(0.0, 0.5) * sc });
                s.store_box(std::array::from_fn(|a| c[a] - e[a]), std::array::from_fn(|a| c[a] + e[a])).unwrap()
            };
            boxes.push(&b);
        }
        (rays, boxes)
    }

    type PairsFn<F> = fn(
        &Slab<F>,
        &SlabRaysSoa<<F as Format>::V>,
        &BoxesSoa<<F as Format>::V>,
        &mut SlabOutSoa<<F as Format>::V>,
    ) -> Kernel;
    type RayFn<F> = fn(
        &Slab<F>,
        &SlabRay<<F as Format>::V>,
        &BoxesSoa<<F as Format>::V>,
        &mut SlabOutSoa<<F as Format>::V>,
    ) -> Kernel;

    fn same<F: Format>(f: &F, a: &SlabOutSoa<F::V>, b: &SlabOutSoa<F::V>) -> Result<(), TestCaseError> {
        prop_assert_eq!(&a.hit, &b.hit);
        let bits = |x: &Vec<F::V>| x.iter().map(|&v| f.to_bits(v)).collect::<Vec<_>>();
        prop_assert_eq!(bits(&a.t_near), bits(&b.t_near));
        prop_assert_eq!(bits(&a.t_far), bits(&b.t_far));
        Ok(())
    }

    /// The kernels (pairs, and one ray against all the boxes) against the scalar model.
    fn check<F: Format + Copy>(
        widest: Kernel,
        f: F,
        variant: &str,
        seed: u64,
        n: usize,
        pairs: PairsFn<F>,
        one: RayFn<F>,
    ) -> Result<(), TestCaseError>
    where
        F::V: Default,
    {
        let s = Slab::new(f, SlabConfig::named(variant).unwrap());
        let (rays, boxes) = batch(&s, seed, n);
        // the directed variant's pairs run the scalar model (its kernel takes one-ray batches)
        let pairs_widest = if s.cfg.directed { Kernel::Scalar } else { widest };
        check_shapes(&s, &rays, &boxes, (pairs_widest, widest), pairs, one, seed, &[0])
    }

    /// `pairs` on the whole batch, then `one` for the rays `(seed + k) % n` (k in `offsets`)
    /// against every box, on every kernel (`widest`: the pairs' and the one-ray batches'),
    /// against the scalar model's bits.
    #[allow(clippy::too_many_arguments)]
    fn check_shapes<F: Format + Copy>(
        s: &Slab<F>,
        rays: &SlabRaysSoa<F::V>,
        boxes: &BoxesSoa<F::V>,
        widest: (Kernel, Kernel),
        pairs: PairsFn<F>,
        one: RayFn<F>,
        seed: u64,
        offsets: &[usize],
    ) -> Result<(), TestCaseError>
    where
        F::V: Default,
    {
        let n = rays.tmin.len();
        let mut a = SlabOutSoa::with_len(n);
        s.batch(rays, boxes, &mut a);
        let fresh = || SlabOutSoa::with_len(n);
        on_every_kernel(widest.0, &a, |b| pairs(s, rays, boxes, b), fresh, |a, b| same(&s.fmt, a, b))?;
        for &k in offsets.iter().filter(|&&k| k < n) {
            let ray = rays.get((seed as usize + k) % n);
            s.batch_ray(&ray, boxes, &mut a);
            on_every_kernel(widest.1, &a, |b| one(s, &ray, boxes, b), fresh, |a, b| same(&s.fmt, a, b))?;
        }
        Ok(())
    }

    /// Rays and boxes at the guard's edges (subnormal, tiny and huge direction components;
    /// boxes and origins near ±max): the kernels equal the guarded model, and the guard changes
    /// the model's answer on some of them (the edges are reached).
    fn edge_batch<F: Format>(s: &Slab<F>, seed: u64, n: usize) -> (SlabRaysSoa<F::V>, BoxesSoa<F::V>) {
        let f = &s.fmt;
        let e = datapath::format::edges(f);
        let mut r = SplitMix64::new(seed);
        let (mut rays, mut boxes) = (SlabRaysSoa::default(), BoxesSoa::default());
        let sgn = |r: &mut SplitMix64| if r.below(2) == 0 { 1.0 } else { -1.0 };
        for _ in 0..n {
            let mut o: [f64; 3] = std::array::from_fn(|_| r.range(-1.0, 1.0));
            let mut d: [f64; 3] = std::array::from_fn(|_| r.range(-1.0, 1.0));
            let mut lo: [f64; 3] = std::array::from_fn(|_| r.range(-1.0, 0.0));
            let mut hi: [f64; 3] = std::array::from_fn(|_| r.range(0.0, 1.0));
            let a = r.below(3) as usize;
            match r.below(4) {
                0 => {
                    d[a] = sgn(&mut r) * e.least * (1 + r.below(8)) as f64;
                    o[a] = 0.0;
                    (lo[a], hi[a]) = if d[a] > 0.0 { (d[a], 4.0 * d[a]) } else { (4.0 * d[a], d[a]) };
                }
                1 => d[a] = sgn(&mut r) * e.max * (-r.range(0.0, 4.0)).exp2(),
                2 => {
                    o[a] = -e.max * r.range(0.3, 0.95);
                    (lo[a], hi[a]) = (e.max * r.range(0.1, 0.5), e.max * r.range(0.5, 0.95));
                    d[a] = e.max / 8.0;
                }
                _ => {
                    (lo[a], hi[a]) = (-e.max * r.range(0.5, 0.95), e.max * r.range(0.5, 0.95));
                    o[a] = lo[a];
                    d[a] = e.max / 16.0;
                }
            }
            rays.push(&s.prepare(o, d, 0.0, f64::INFINITY));
            boxes.push(&s.store_box(lo, hi).unwrap());
        }
        (rays, boxes)
    }

    fn check_edges<F: Format + Copy>(
        widest: Kernel,
        f: F,
        pairs: PairsFn<F>,
        one: RayFn<F>,
    ) -> Result<(), TestCaseError>
    where
        F::V: Default,
    {
        let s = Slab::new(f, SlabConfig::named("conservative").unwrap());
        let unguarded = Slab::new(f, SlabConfig { guard: false, ..s.cfg });
        let n = 4000;
        let (rays, boxes) = edge_batch(&s, 0xed9e, n);
        let mut a = SlabOutSoa::with_len(n);
        s.batch(&rays, &boxes, &mut a);
        let fresh = || SlabOutSoa::with_len(n);
        on_every_kernel(widest, &a, |b| pairs(&s, &rays, &boxes, b), fresh, |a, b| same(&f, a, b))?;
        // the unguarded unit on the unguarded rays answers otherwise somewhere: the guard acts
        let (urays, _) = edge_batch(&unguarded, 0xed9e, n);
        let mut u = SlabOutSoa::with_len(n);
        unguarded.batch(&urays, &boxes, &mut u);
        prop_assert!(a.hit.iter().zip(&u.hit).filter(|(g, u)| g != u).count() > 10);
        for k in [0, 1, 2, 3, 17, n - 1] {
            let ray = rays.get(k);
            s.batch_ray(&ray, &boxes, &mut a);
            on_every_kernel(widest, &a, |b| one(&s, &ray, &boxes, b), fresh, |a, b| same(&f, a, b))?;
        }
        Ok(())
    }

    #[test]
    fn slab_kernels_match_the_guard_at_the_edges() {
        check_edges(WIDEST_F32, Ieee::new(F32Native, FpOpts::default()), slab_batch_f32, slab_ray_f32).unwrap();
        check_edges(WIDEST_F16, Ieee::new(F16Half, FpOpts::default()), slab_batch_f16, slab_ray_f16).unwrap();
        let div = FpOpts { div: DivMode::Divide, ..FpOpts::default() };
        check_edges(WIDEST_F32, Ieee::new(F32Native, div), slab_batch_f32, slab_ray_f32).unwrap();
        check_edges(WIDEST_F16, Ieee::new(F16Half, div), slab_batch_f16, slab_ray_f16).unwrap();
        let bf = |o| Ieee::new(datapath::format::Bf16, o);
        check_edges(datapath::simd::WIDEST_NARROW, bf(FpOpts::default()), slab_batch_bf16, slab_ray_bf16).unwrap();
        check_edges(datapath::simd::WIDEST_NARROW, bf(div), slab_batch_bf16, slab_ray_bf16).unwrap();
        // eEmM: grid steps in binary64 lanes next to ±max and the least subnormal
        for name in ["e8m16", "e5m10", "e6m9:divide", "e10m24"] {
            let datapath::AnyFormat::Soft(f) = name.parse().unwrap() else { unreachable!() };
            check_edges(
                datapath::simd::WIDEST_NARROW,
                f,
                datapath::simd::slab_batch_soft,
                datapath::simd::slab_ray_soft,
            )
            .unwrap();
        }
    }

    const VARIANTS: [&str; 5] = ["plain", "conservative", "take-on-false", "embree", "directed"];

    /// The default options, under FTZ when `ftz` (the batch holds raw subnormal t limits,
    /// origins and reciprocals, which the model reads flushed).
    fn subnormals(ftz: bool) -> FpOpts {
        FpOpts { subnormals: if ftz { Subnormals::Ftz } else { Subnormals::Ieee }, ..FpOpts::default() }
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

        #[test]
        fn f32_slab_kernels_match_the_scalar_model(seed in any::<u64>(), n in 0usize..300, v in 0usize..5, ftz in any::<bool>()) {
            check(WIDEST_F32, Ieee::new(F32Native, subnormals(ftz)), VARIANTS[v], seed, n, slab_batch_f32, slab_ray_f32)?;
        }

        #[test]
        fn f16_slab_kernels_match_the_scalar_model(seed in any::<u64>(), n in 0usize..300, v in 0usize..5, ftz in any::<bool>()) {
            check(WIDEST_F16, Ieee::new(F16Half, subnormals(ftz)), VARIANTS[v], seed, n, slab_batch_f16, slab_ray_f16)?;
        }

        /// bf16's slab kernels (binary32 lanes, each result rounded to bf16 in the integer lanes).
        #[test]
        fn bf16_slab_kernels_match_the_scalar_model(seed in any::<u64>(), n in 0usize..300, v in 0usize..5, divide in any::<bool>(), ftz in any::<bool>()) {
            let o = FpOpts { div: if divide { DivMode::Divide } else { DivMode::RecipMul }, ..subnormals(ftz) };
            check(datapath::simd::WIDEST_NARROW, Ieee::new(datapath::format::Bf16, o), VARIANTS[v], seed, n, slab_batch_bf16, slab_ray_bf16)?;
        }
    }

    /// `slab_ray_f16` on at most the AVX2 kernel (a cap only lowers: an outer one stands).
    fn ray_f16_at_most_avx2(
        s: &Slab<Ieee<F16Half>>,
        r: &SlabRay<half::f16>,
        b: &BoxesSoa<half::f16>,
        o: &mut SlabOutSoa<half::f16>,
    ) -> Kernel {
        match slab_ray_f16(s, r, b, o) {
            k if k > Kernel::Avx2 => with_kernel_cap(Kernel::Avx2, || slab_ray_f16(s, r, b, o)),
            k => k,
        }
    }

    proptest! {
        // a measured alternative, not the dispatched kernel: fewer cases
        #![proptest_config(ProptestConfig { cases: 16, ..ProptestConfig::default() })]

        /// The AVX2 binary16 slab kernel whose rounding stays in binary32 lanes (`isa::v8r`),
        /// its one-ray batches the AVX2 kernel's.
        #[test]
        fn f16_slab_kernels_rounding_in_lanes_match_the_scalar_model(seed in any::<u64>(), n in 0usize..300, v in 0usize..5, ftz in any::<bool>()) {
            check(Kernel::Avx2, Ieee::new(F16Half, subnormals(ftz)), VARIANTS[v], seed, n, datapath::simd::slab_batch_f16_lanes, ray_f16_at_most_avx2)?;
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 128, ..ProptestConfig::default() })]

        /// The `eEmM` slab kernels (binary64 lanes, each result rounded in the lanes, grid steps
        /// in the lanes), pairs and one ray against every box: the scalar model's bits in every
        /// variant (the directed one on one-ray batches), either subnormal mode (under FTZ with
        /// raw subnormal t limits, origins and reciprocals in the columns).
        #[test]
        fn soft_float_slab_kernels_match_the_scalar_model(seed in any::<u64>(), n in 0usize..300, v in 0usize..5, fmt in 0usize..10) {
            use datapath::simd::{slab_batch_soft, slab_kernel_soft, slab_ray_kernel_soft, slab_ray_soft, WIDEST_NARROW};
            let names = ["e8m16", "e5m4", "e10m24:divide", "e8m7", "e6m9:divide", "e8m16:ftz", "e8m23:divide", "e5m10:ftz", "e6m9:ftz+divide", "e4m3:ftz"];
            let datapath::AnyFormat::Soft(f) = names[fmt].parse().unwrap() else { unreachable!() };
            let s = Slab::new(f, SlabConfig::named(VARIANTS[v]).unwrap());
            let best = |ok: bool| if ok { WIDEST_NARROW } else { Kernel::Scalar };
            let (pairs_widest, one_widest) = (best(VARIANTS[v] != "directed"), best(true));
            let here = *kernels_here().last().unwrap();
            prop_assert_eq!(slab_kernel_soft(&s), here.min(pairs_widest));
            prop_assert_eq!(slab_ray_kernel_soft(&s), here.min(one_widest));
            let (rays, boxes) = batch(&s, seed, n);
            check_shapes(&s, &rays, &boxes, (pairs_widest, one_widest), slab_batch_soft, slab_ray_soft, seed, &[0, 1, 7])?;
        }
    }

    /// One case of the shared one-ray slab batch (`slab_ray_shared`: the round-to-nearest
    /// variants' planes computed once): the subset `pick` of the four variants of `f` (in
    /// reverse order when `seed` is odd), each prepared from the ray `(o, d, tmin, tmax)` (its
    /// t limit replaced by a NaN with a payload and a sign when `payload`), against `boxes`
    /// with a plane on the origin every third box, on every kernel here: every output is
    /// `alone`'s bits for that variant, and the batch declines (`None`) exactly when the
    /// prepared rays differ (origin, 1/d or t interval, bit for bit) or the cap leaves no
    /// kernel.
    #[allow(clippy::too_many_arguments)]
    fn shared_case<F: Format + 'static>(
        f: F,
        seed: u64,
        pick: u32,
        ray: ([f64; 3], [f64; 3], f64, f64),
        payload: bool,
        mut boxes: BoxesSoa<F::V>,
        alone: RayFn<F>,
    ) -> Result<(), TestCaseError> {
        use datapath::simd::slab_ray_shared;
        let all: Vec<Slab<F>> = VARIANTS[..4].iter().map(|v| Slab::new(f, SlabConfig::named(v).unwrap())).collect();
        let mut idx: Vec<usize> = (0..4).filter(|&j| pick >> j & 1 == 1).collect();
        if seed % 2 == 1 {
            idx.reverse();
        }
        let group: Vec<&Slab<F>> = idx.iter().map(|&j| &all[j]).collect();
        let (o, d, tmin, tmax) = ray;
        let prepared: Vec<_> = group
            .iter()
            .map(|s| {
                let mut ray = s.prepare(o, d, tmin, tmax);
                if payload {
                    // a NaN t limit with a payload and a sign, as a column could hold
                    ray.tmax = f.from_bits(f.to_bits(f.from_f64(f64::INFINITY)) | 3 | f.to_bits(f.from_f64(-0.0)));
                }
                ray
            })
            .collect();
        let refs: Vec<_> = prepared.iter().collect();
        let n = boxes.min[0].len();
        // planes on the origin every third box (0 · inf is NaN where 1/d is infinite)
        for i in (0..n).step_by(3) {
            boxes.min[i % 3][i] = refs[0].o[i % 3];
            boxes.max[(i + 1) % 3][i] = refs[0].o[(i + 1) % 3];
        }
        let bits = |v: &[F::V]| v.iter().map(|&x| f.to_bits(x)).collect::<Vec<_>>();
        let key = |r: &&SlabRay<F::V>| (bits(&r.o), bits(&r.inv_d), bits(&[r.tmin, r.tmax]));
        let same = refs.iter().all(|r| key(r) == key(&refs[0]));
        for k in kernels_here() {
            let mut outs: Vec<SlabOutSoa<F::V>> = (0..group.len()).map(|_| SlabOutSoa::with_len(n)).collect();
            let got = with_kernel_cap(k, || slab_ray_shared(&group, &refs, &boxes, &mut outs));
            prop_assert_eq!(got.is_some(), same && k != Kernel::Scalar, "{:?} {:?}", k, idx);
            if got.is_some() {
                for (j, out) in outs.iter().enumerate() {
                    let mut want = SlabOutSoa::with_len(n);
                    with_kernel_cap(k, || alone(group[j], refs[j], &boxes, &mut want));
                    for i in 0..n {
                        prop_assert_eq!(
                            (out.hit[i], f.to_bits(out.t_near[i]), f.to_bits(out.t_far[i])),
                            (want.hit[i], f.to_bits(want.t_near[i]), f.to_bits(want.t_far[i])),
                            "{} {} lane {} of {} on {:?}",
                            f.name(),
                            VARIANTS[idx[j]],
                            i,
                            n,
                            k
                        );
                    }
                }
            }
        }
        Ok(())
    }

    /// A ray for [`shared_case`] on a float format: origin and direction components mostly
    /// ordinary, sometimes specials; a zero direction component (1/d = ±inf, shared by all but
    /// embree) or a tiny one (embree's and the conservative guard's rays differ); t limits
    /// sometimes specials.
    fn float_shared_ray(e: &datapath::format::Edges, r: &mut SplitMix64) -> ([f64; 3], [f64; 3], f64, f64) {
        let o: [f64; 3] = std::array::from_fn(|_| if r.below(8) == 0 { f64_value(r) } else { r.range(-1.0, 1.0) });
        let d: [f64; 3] = std::array::from_fn(|_| match r.below(10) {
            0 => 0.0,
            1 => r.range(-1.0, 1.0) * e.least,
            2 => f64_value(r),
            _ => r.range(-2.0, 2.0),
        });
        let limit = |r: &mut SplitMix64, usual: f64| if r.below(8) == 0 { f64_value(r) } else { usual };
        let (tmin, tmax) = (limit(r, 0.0), limit(r, f64::INFINITY));
        (o, d, tmin, tmax)
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

        /// The shared one-ray slab batch of the float formats (binary32, binary16, bf16 and
        /// `eEmM` layouts; IEEE subnormals) gives every variant of the group the one-ray
        /// batch's bits — any subset of the four, in either order, rays from the same origin,
        /// direction and t interval (specials, zero and tiny direction components, NaN limits
        /// with payloads) — and declines exactly when their prepared rays differ or the
        /// machine (cap) has no kernel.
        #[test]
        fn shared_slab_batches_equal_each_variant_alone(seed in any::<u64>(), n in 0usize..300, fmt in 0usize..9, pick in 1u32..16) {
            use datapath::simd::slab_ray_soft;
            let mut r = SplitMix64::new(seed ^ 0x5ead);
            let payload = r.below(4) == 0;
            let names = ["e8m16", "e5m4", "e10m24:divide", "e8m7", "e6m9:divide", "e8m23:divide"];
            match fmt {
                0 => {
                    let f = Ieee::new(F32Native, subnormals(false));
                    let ray = float_shared_ray(&datapath::format::edges(&f), &mut r);
                    let boxes = batch(&Slab::new(f, SlabConfig::default()), seed, n).1;
                    shared_case(f, seed, pick, ray, payload, boxes, slab_ray_f32)?;
                }
                1 => {
                    let f = Ieee::new(F16Half, subnormals(false));
                    let ray = float_shared_ray(&datapath::format::edges(&f), &mut r);
                    let boxes = batch(&Slab::new(f, SlabConfig::default()), seed, n).1;
                    shared_case(f, seed, pick, ray, payload, boxes, slab_ray_f16)?;
                }
                2 => {
                    let o = FpOpts { div: if seed % 4 < 2 { DivMode::Divide } else { DivMode::RecipMul }, ..subnormals(false) };
                    let f = Ieee::new(datapath::format::Bf16, o);
                    let ray = float_shared_ray(&datapath::format::edges(&f), &mut r);
                    let boxes = batch(&Slab::new(f, SlabConfig::default()), seed, n).1;
                    shared_case(f, seed, pick, ray, payload, boxes, datapath::simd::slab_ray_bf16)?;
                }
                _ => {
                    let datapath::AnyFormat::Soft(f) = names[fmt - 3].parse().unwrap() else { unreachable!() };
                    let ray = float_shared_ray(&datapath::format::edges(&f), &mut r);
                    let boxes = batch(&Slab::new(f, SlabConfig::default()), seed, n).1;
                    shared_case(f, seed, pick, ray, payload, boxes, slab_ray_soft)?;
                }
            }
        }

        /// The shared one-ray slab batch of the fixed-point formats (every rounding, overflow
        /// and division mode): each variant of the group `slab_ray_fixed`'s bits, the chains
        /// computed once (its variants differ only in the widening), rays with parallel axes
        /// and saturated reciprocals, t intervals mostly [0, max].
        #[test]
        fn shared_fixed_slab_batches_equal_each_variant_alone(seed in any::<u64>(), n in 0usize..300, name in 0usize..8, mode in 0usize..16, pick in 1u32..16) {
            let f = super::fixed(&format!("{}{}", super::FIXED_NAMES[name], super::FIXED_MODES[mode]));
            let m = f.to_f64(f.max_raw()) / 4.0;
            let step = f.to_f64(1);
            let mut r = SplitMix64::new(seed ^ 0x5ead);
            let o: [f64; 3] = std::array::from_fn(|_| r.range(-m, m));
            let d: [f64; 3] = std::array::from_fn(|_| match r.below(6) {
                0 => 0.0,
                1 => step * (r.below(5) as f64 - 2.0),
                _ => r.range(-m, m),
            });
            let tmin = if r.below(8) == 0 { r.range(-m, m) } else { 0.0 };
            let tmax = if r.below(8) == 0 { r.range(-m, m) } else { f64::INFINITY };
            let boxes = fixed_slab_batch(&Slab::new(f, SlabConfig::default()), seed, n).1;
            shared_case(f, seed, pick, (o, d, tmin, tmax), false, boxes, datapath::simd::slab_ray_fixed)?;
        }
    }

    /// A shared slab batch keeps each variant's comparator where they part: a ray along two
    /// axes (1/d = +inf on the third) through boxes around it whose plane on that axis is the
    /// origin's coordinate, a NaN plane (0 · inf) that plain ignores and take-on-false takes,
    /// and boxes the conservative widening changes; every kernel, against each variant alone.
    #[test]
    fn shared_soft_slab_batches_keep_each_comparator() {
        use datapath::simd::{slab_ray_shared, slab_ray_soft};
        let datapath::AnyFormat::Soft(f) = "e8m16".parse().unwrap() else { unreachable!() };
        let group: Vec<Slab<_>> = ["plain", "take-on-false", "conservative"]
            .iter()
            .map(|v| Slab::new(f, SlabConfig::named(v).unwrap()))
            .collect();
        let group: Vec<&Slab<_>> = group.iter().collect();
        let o = [0.25, 0.5, -0.5];
        let rays: Vec<_> = group.iter().map(|s| s.prepare(o, [1.0, 1.0, 0.0], 0.0, f64::INFINITY)).collect();
        let refs: Vec<_> = rays.iter().collect();
        let q = |x: f64| f.from_f64(x);
        let mut boxes = BoxesSoa::default();
        for k in 0..100 {
            // x: t in [0.5, 1]; y: every third box entered 3 grid steps after t = 1 (a miss by less
            // than the widening: plain misses, conservative hits), else around the ray; z
            // (1/d = +inf): every other box's near plane on the origin, a NaN plane (0 · inf)
            // plain ignores and take-on-false takes (last in the chain: t_near stays NaN)
            let y = if k % 3 == 0 { [o[1] + 1.0 + 3.0 * 2f64.powi(-16), o[1] + 2.0] } else { [o[1] - 1.0, o[1] + 2.0] };
            let z = if k % 2 == 0 { [o[2], o[2] + 1.0] } else { [o[2] - 1.0, o[2] + 1.0] };
            boxes.push(&Aabb { min: [q(o[0] + 0.5), q(y[0]), q(z[0])], max: [q(o[0] + 1.0), q(y[1]), q(z[1])] });
        }
        for k in kernels_here() {
            let mut outs: Vec<SlabOutSoa<u64>> = (0..3).map(|_| SlabOutSoa::with_len(100)).collect();
            let got = with_kernel_cap(k, || slab_ray_shared(&group, &refs, &boxes, &mut outs));
            assert_eq!(got.is_some(), k != Kernel::Scalar, "{k:?}");
            if got.is_none() {
                continue;
            }
            let mut hits = [0; 3];
            for (j, out) in outs.iter().enumerate() {
                let mut want = SlabOutSoa::with_len(100);
                with_kernel_cap(k, || slab_ray_soft(group[j], refs[j], &boxes, &mut want));
                for i in 0..100 {
                    assert_eq!(
                        (out.hit[i], out.t_near[i], out.t_far[i]),
                        (want.hit[i], want.t_near[i], want.t_far[i]),
                        "variant {j} lane {i} on {k:?}"
                    );
                }
                hits[j] = out.hit.iter().filter(|&&h| h).count();
            }
            // the comparators part on these boxes (else the test would not tell them apart)
            assert!(hits[0] != hits[1] && hits[0] != hits[2], "hits {hits:?}");
        }
    }

    /// Whether the shared slab batch declines plain with `second` of format `f` on `boxes`
    /// (`None`, and nothing written).
    fn declines<F: Format + 'static>(f: F, second: &str, boxes: &BoxesSoa<F::V>) -> bool {
        let (a, b) =
            (Slab::new(f, SlabConfig::named("plain").unwrap()), Slab::new(f, SlabConfig::named(second).unwrap()));
        let ray = a.prepare([0.1, 0.2, 0.3], [1.0, 0.5, 0.25], 0.0, f64::INFINITY);
        let n = boxes.min[0].len();
        let mut outs = vec![SlabOutSoa::with_len(n), SlabOutSoa::with_len(n)];
        datapath::simd::slab_ray_shared(&[&a, &b], &[&ray, &ray], boxes, &mut outs).is_none()
            && outs.iter().all(|o| !o.hit.iter().any(|&h| h))
    }

    /// A shared slab batch declines a group with the directed variant, a format that flushes
    /// subnormals, or mismatched lengths (nothing written): `eEmM`, binary32 under FTZ,
    /// binary16 and fixed point with the directed variant.
    #[test]
    fn shared_slab_batches_decline_what_they_do_not_share() {
        use datapath::simd::slab_ray_shared;
        let plain = SlabConfig::named("plain").unwrap();
        for (name, v) in [("e8m16", "directed"), ("e8m16:ftz", "plain"), ("e5m10:ftz", "take-on-false")] {
            let datapath::AnyFormat::Soft(f) = name.parse().unwrap() else { unreachable!() };
            assert!(declines(f, v, &batch(&Slab::new(f, plain), 3, 40).1), "{name} {v}");
        }
        let f = Ieee::new(F32Native, subnormals(true));
        assert!(declines(f, "plain", &batch(&Slab::new(f, plain), 3, 40).1), "f32:ftz");
        let f = Ieee::new(F16Half, subnormals(false));
        assert!(declines(f, "directed", &batch(&Slab::new(f, plain), 3, 40).1), "fp16 directed");
        let f = super::fixed("q16.16");
        assert!(declines(f, "directed", &fixed_slab_batch(&Slab::new(f, plain), 3, 40).1), "q16.16 directed");
        let datapath::AnyFormat::Soft(f) = "e8m16".parse().unwrap() else { unreachable!() };
        let a = Slab::new(f, plain);
        let (_, boxes) = batch(&a, 3, 40);
        let ray = a.prepare([0.1, 0.2, 0.3], [1.0, 0.5, 0.25], 0.0, f64::INFINITY);
        let mut outs = vec![SlabOutSoa::with_len(40)];
        assert!(slab_ray_shared(&[&a, &a], &[&ray, &ray], &boxes, &mut outs).is_none(), "two variants, one output");
    }

    /// One-ray `eEmM` slab batches whose box planes sit on the ray's origin, a few grid steps
    /// from it, the smallest normal from it or at ±max, at an ordinary scale, at the smallest
    /// normal, among the subnormals and near the largest value — plane differences of zero,
    /// subnormal, exactly 2^emin and near-overflow size, whose
    /// rounding and grid steps the kernels leave to the scalar model (they note those lanes
    /// instead of branching per vector) — in every variant, the directed one included: the
    /// scalar model's bits on every kernel.
    #[test]
    fn soft_float_one_ray_slab_kernels_at_zero_tiny_and_huge_plane_differences() {
        use datapath::simd::{slab_ray_soft, WIDEST_NARROW};
        let mut r = SplitMix64::new(0x51ab);
        for name in ["e8m16", "e5m4", "e8m7", "e5m10", "e8m23:divide", "e6m9"] {
            let datapath::AnyFormat::Soft(f) = name.parse().unwrap() else { unreachable!() };
            let e = datapath::format::edges(&f);
            for v in VARIANTS {
                let s = Slab::new(f, SlabConfig::named(v).unwrap());
                for scale in [1.0, e.min_normal, e.least * 8.0, e.max / 4.0] {
                    let q = |x: f64| f.from_f64(x);
                    let o = [0.3, -0.7, 0.55].map(|x| q(x * scale));
                    // (long directions too: |1/d| < 1 keeps a product with a plane difference
                    // stepped past ±max in range, so only the step can tell)
                    let long = if r.below(2) == 0 { 1.0 } else { 64.0 };
                    // (and tiny components, whose 1/d ends stand for ±∞)
                    let d: [f64; 3] = std::array::from_fn(|_| match r.below(4) {
                        0 => r.range(-1.0, 1.0) * e.least,
                        _ => r.range(-1.0, 1.0) * long,
                    });
                    let ray = s.prepare(o.map(|x| f.to_f64(x)), d, 0.0, f64::INFINITY);
                    // a plane k grid steps from the origin's coordinate (k in -3..=3)
                    let step = |x, k: i64| {
                        (0..k.unsigned_abs()).fold(x, |x, _| if k > 0 { f.next_up(x) } else { f.next_down(x) })
                    };
                    // or the smallest normal away (a difference of exactly 2^emin), or at ±max
                    // (a difference that rounds to the largest value)
                    let mut plane = |a: usize, sign: f64| match r.below(8) {
                        0 => q(f.to_f64(o[a]) + sign * e.min_normal),
                        1 => q(sign * e.max),
                        _ => step(o[a], sign as i64 * r.below(4) as i64),
                    };
                    let mut boxes = BoxesSoa::default();
                    for k in 0..64 {
                        let lo: [_; 3] = std::array::from_fn(|a| plane(a, -1.0));
                        let hi: [_; 3] = std::array::from_fn(|a| plane(a, 1.0));
                        boxes.push(&Aabb { min: lo, max: hi });
                        if k % 16 == 0 {
                            // every plane at ±max: each exit's difference rounds to ±max and
                            // steps out to ±∞ (t_far +∞, where a wrong step leaves it finite)
                            boxes.push(&Aabb { min: [q(-e.max); 3], max: [q(e.max); 3] });
                        }
                    }
                    let n = boxes.min[0].len();
                    let mut a = SlabOutSoa::with_len(n);
                    s.batch_ray(&ray, &boxes, &mut a);
                    let fresh = || SlabOutSoa::with_len(n);
                    on_every_kernel(
                        WIDEST_NARROW,
                        &a,
                        |b| slab_ray_soft(&s, &ray, &boxes, b),
                        fresh,
                        |a, b| same(&s.fmt, a, b),
                    )
                    .unwrap_or_else(|err| panic!("{name} {v} at scale {scale:e}: {err}"));
                }
            }
        }
    }

    /// A seeded fixed-point slab batch within the format's range: origins, directions (some
    /// axis components 0: parallel axes, some tiny: saturated 1/d) and boxes scaled to a
    /// quarter of the range, a quarter of the boxes raw bits (possibly inverted), t intervals
    /// mostly [0, max].
    fn fixed_slab_batch(s: &Slab<datapath::format::Fixed>, seed: u64, n: usize) -> (SlabRaysSoa<i64>, BoxesSoa<i64>) {
        let f = &s.fmt;
        let m = f.to_f64(f.max_raw()) / 4.0;
        let step = f.to_f64(1);
        let mut r = SplitMix64::new(seed);
        let (mut rays, mut boxes) = (SlabRaysSoa::default(), BoxesSoa::default());
        for _ in 0..n {
            let c: [f64; 3] = std::array::from_fn(|_| r.range(-m, m) / 2.0);
            let o: [f64; 3] = std::array::from_fn(|_| r.range(-m, m));
            let d: [f64; 3] = std::array::from_fn(|a| match r.below(8) {
                0 => 0.0,
                1 => step * (r.below(5) as f64 - 2.0),
                2 => r.range(-m, m),
                _ => c[a] + r.range(-m, m) / 4.0 - o[a],
            });
            let tmin = if r.below(8) == 0 { r.range(-m, m) } else { 0.0 };
            let tmax = if r.below(8) == 0 { r.range(-m, m) } else { f64::INFINITY };
            rays.push(&s.prepare(o, d, tmin, tmax));
            let b = if r.below(4) == 0 {
                Aabb {
                    min: std::array::from_fn(|_| f.from_bits(r.next_u64())),
                    max: std::array::from_fn(|_| f.from_bits(r.next_u64())),
                }
            } else {
                let e: [f64; 3] = std::array::from_fn(|_| if r.below(5) == 0 { 0.0 } else { r.range(0.0, m / 2.0) });
                s.store_box(std::array::from_fn(|a| c[a] - e[a]), std::array::from_fn(|a| c[a] + e[a])).unwrap()
            };
            boxes.push(&b);
        }
        (rays, boxes)
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 128, ..ProptestConfig::default() })]

        /// The fixed-point slab kernels (i64 lanes), pairs and one ray against every box, in
        /// every variant (the directed one included) and every rounding, overflow and division
        /// mode, return the scalar model's bits.
        #[test]
        fn fixed_point_slab_kernels_match_the_scalar_model(seed in any::<u64>(), n in 0usize..300, v in 0usize..5, name in 0usize..8, mode in 0usize..16) {
            use datapath::simd::{slab_batch_fixed, slab_ray_fixed};
            let f = super::fixed(&format!("{}{}", super::FIXED_NAMES[name], super::FIXED_MODES[mode]));
            let s = Slab::new(f, SlabConfig::named(VARIANTS[v]).unwrap());
            let (rays, boxes) = fixed_slab_batch(&s, seed, n);
            let widest = super::widest_fixed();
            check_shapes(&s, &rays, &boxes, (widest, widest), slab_batch_fixed, slab_ray_fixed, seed, &[0, 1, 7])?;
        }
    }

    #[test]
    fn the_slab_kernels_run_and_the_directed_variant_runs_on_one_ray_batches_only() {
        let f = Ieee::new(F32Native, FpOpts::default());
        let h = Ieee::new(F16Half, FpOpts::default());
        let best = *kernels_here().last().unwrap();
        let named = |v| SlabConfig::named(v).unwrap();
        assert_eq!(slab_kernel_f32(&Slab::new(f, named("conservative"))), best.min(WIDEST_F32));
        assert_eq!(slab_kernel_f16(&Slab::new(h, named("conservative"))), best);
        let directed = SlabConfig::named("directed").unwrap();
        assert_eq!(slab_kernel_f32(&Slab::new(f, directed)), Kernel::Scalar);
        assert_eq!(slab_kernel_f16(&Slab::new(h, directed)), Kernel::Scalar);
        assert_eq!(slab_ray_kernel_f32(&Slab::new(f, directed)), best.min(WIDEST_F32));
        assert_eq!(slab_ray_kernel_f16(&Slab::new(h, directed)), best);
        // the generated batches are not vacuous: hits, misses and NaN distances occur, and the
        // conservative variant widens (its intervals differ from plain's)
        for (fmt_hits, nan) in [
            {
                let s = Slab::new(f, SlabConfig::named("plain").unwrap());
                let (rays, boxes) = batch(&s, 5, 4000);
                let mut out = SlabOutSoa::with_len(4000);
                slab_batch_f32(&s, &rays, &boxes, &mut out);
                (out.hit.iter().filter(|&&h| h).count(), out.t_near.iter().chain(&out.t_far).any(|t| t.is_nan()))
            },
            {
                let s = Slab::new(h, SlabConfig::named("plain").unwrap());
                let (rays, boxes) = batch(&s, 5, 4000);
                let mut out = SlabOutSoa::with_len(4000);
                slab_batch_f16(&s, &rays, &boxes, &mut out);
                (out.hit.iter().filter(|&&h| h).count(), out.t_near.iter().chain(&out.t_far).any(|t| t.is_nan()))
            },
        ] {
            assert!(fmt_hits > 200 && fmt_hits < 3800, "{fmt_hits}");
            assert!(nan);
        }
    }

    /// The directed variant's one-ray kernel against the model over many rays (each proptest
    /// case above takes one ray): parallel axes (d = ±0), infinite and NaN components, raw-bit
    /// boxes; and the batches are not vacuous (hits, misses, unbounded ends occur).
    #[test]
    fn the_directed_one_ray_kernel_equals_the_model_on_many_rays() {
        fn run<F: Format + Copy>(widest: Kernel, f: F, one: RayFn<F>) -> (usize, usize)
        where
            F::V: Default,
        {
            let s = Slab::new(f, SlabConfig::named("directed").unwrap());
            let (mut hits, mut total) = (0, 0);
            for seed in 0..300u64 {
                let n = 40 + (seed as usize % 29);
                let (rays, boxes) = batch(&s, seed, n);
                let fresh = || SlabOutSoa::with_len(n);
                for k in [0, n / 2, n - 1] {
                    let ray = rays.get(k);
                    let mut a = SlabOutSoa::with_len(n);
                    s.batch_ray(&ray, &boxes, &mut a);
                    hits += a.hit.iter().filter(|&&h| h).count();
                    total += n;
                    on_every_kernel(widest, &a, |b| one(&s, &ray, &boxes, b), fresh, |a, b| same(&f, a, b))
                        .unwrap_or_else(|e| panic!("seed {seed} ray {k}: {e}"));
                }
            }
            (hits, total)
        }
        for (hits, total) in [
            run(WIDEST_F32, Ieee::new(F32Native, FpOpts::default()), slab_ray_f32),
            run(WIDEST_F16, Ieee::new(F16Half, FpOpts::default()), slab_ray_f16),
            run(datapath::simd::WIDEST_NARROW, Ieee::new(datapath::format::Bf16, FpOpts::default()), slab_ray_bf16),
        ] {
            assert!(hits > total / 50 && hits < total - total / 50, "{hits} of {total}");
        }
    }

    #[test]
    fn one_ray_batches_hit_and_miss() {
        // one ray against many boxes: a ray through the middle of a row of boxes
        let f = Ieee::new(F16Half, FpOpts::default());
        let s = Slab::new(f, SlabConfig::named("conservative").unwrap());
        let (_, boxes) = batch(&s, 1, 300);
        let ray = s.prepare([0.0, 0.0, -5.0], [0.01, -0.02, 1.0], 0.0, f64::INFINITY);
        let (mut a, mut b) = (SlabOutSoa::with_len(300), SlabOutSoa::with_len(300));
        s.batch_ray(&ray, &boxes, &mut a);
        slab_ray_f16(&s, &ray, &boxes, &mut b);
        let hits = b.hit.iter().filter(|&&h| h).count();
        assert!(hits > 10 && hits < 290, "{hits}");
        assert_eq!(a.hit, b.hit);
        assert_eq!(
            a.t_near.iter().map(|t| t.to_bits()).collect::<Vec<_>>(),
            b.t_near.iter().map(|t| t.to_bits()).collect::<Vec<_>>()
        );
    }
}

#[test]
fn a_short_column_is_never_read_past_its_end_by_a_kernel() {
    // the kernels read every column through raw pointers: a batch whose columns disagree in
    // length must take the scalar path, which panics on the short column
    let f = Ieee::new(F32Native, FpOpts::default());
    let rti = Rti::new(f, RtiConfig::default());
    let (mut rays, tris) = columns(&f, 16, 1, &F32_SPECIALS);
    rays.d[1].truncate(9);
    let r = std::panic::catch_unwind(move || {
        let mut out = HitsSoa::with_len(16);
        rti_batch_f32(&rti, &rays, &tris, &mut out)
    });
    assert!(r.is_err());
}

mod generic {
    use super::*;
    use datapath::simd::{rti_batch, rti_stream, slab_batch, CHUNK};
    use datapath::slab::{Slab, SlabConfig, SlabOutSoa, SlabRaysSoa};
    use datapath::{with_format, AnyFormat};

    /// The format-generic dispatch runs the kernels for binary32 / binary16 and the scalar
    /// model otherwise, with the scalar model's bits either way.
    #[test]
    fn the_generic_dispatch_picks_the_kernel_by_format() {
        let best = *kernels_here().last().unwrap();
        for name in ["f32", "fp16", "bf16", "q8.24:divide", "q20.20"] {
            let any: AnyFormat = name.parse().unwrap();
            with_format!(any, |f| {
                let rti = Rti::new(f, RtiConfig::default());
                let specials: Vec<u64> = vec![0, 1, f.to_bits(f.from_f64(f64::INFINITY))];
                let (rays, tris) = columns(&f, 77, 4, &specials);
                let (mut a, mut b) = (HitsSoa::with_len(77), HitsSoa::with_len(77));
                rti.batch(&rays, &tris, &mut a);
                let k = rti_batch(&rti, &rays, &tris, &mut b);
                same(&f, &a, &b).unwrap();
                let expect = match name {
                    "f32" => best.min(WIDEST_F32),
                    "fp16" => best,
                    _ => Kernel::Scalar,
                };
                // bf16 runs its own kernels (binary32 lanes), RTI and slab; fixed point of at
                // most 32 bits its own (i64 lanes), RTI and slab
                let rti_expect = match name {
                    "bf16" => best.min(datapath::simd::WIDEST_NARROW),
                    "q8.24:divide" => best.min(super::widest_fixed()),
                    _ => expect,
                };
                let slab_expect = rti_expect;
                assert_eq!(k, rti_expect, "{name}");
                let s = Slab::new(f, SlabConfig::named("conservative").unwrap());
                let (mut sr, mut sb) = (SlabRaysSoa::default(), datapath::slab::BoxesSoa::default());
                for i in 0..77 {
                    let r = rays.get(i);
                    let o = r.o.map(|x| f.to_f64(x));
                    let d = r.d.map(|x| f.to_f64(x));
                    sr.push(&s.prepare(o, d, 0.0, f64::INFINITY));
                    sb.push(&s.store_box([-1.0, -1.0, -1.0], [0.5, 0.25, 1.0]).unwrap());
                }
                let (mut x, mut y) = (SlabOutSoa::with_len(77), SlabOutSoa::with_len(77));
                s.batch(&sr, &sb, &mut x);
                let k = slab_batch(&s, &sr, &sb, &mut y);
                assert_eq!(x.hit, y.hit);
                assert_eq!(k, slab_expect, "{name}");
            });
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 16, ..ProptestConfig::default() })]

        /// Streaming in L1-sized chunks gives every slot the bits one whole batch gives it.
        #[test]
        fn the_stream_equals_one_batch(seed in any::<u64>(), n in prop_oneof![0usize..3, CHUNK - 3..CHUNK + 3, 3 * CHUNK..4 * CHUNK]) {
            let f = Ieee::new(F32Native, FpOpts::default());
            let rti = Rti::new(f, RtiConfig::default());
            let (rays, tris) = columns(&f, n, seed, &F32_SPECIALS);
            let mut whole = HitsSoa::with_len(n);
            rti.batch(&rays, &tris, &mut whole);
            let mut streamed = HitsSoa::with_len(n);
            let mut chunks = 0;
            rti_stream(
                &rti,
                n,
                |r, ra, tr| {
                    assert!(ra.len() == r.len() && tr.len() == r.len());
                    for (k, i) in r.enumerate() {
                        ra.set(k, &rays.get(i));
                        tr.set(k, &tris.get(i));
                    }
                },
                |r, _, _, out| {
                    assert!(r.len() <= CHUNK && out.len() == r.len());
                    chunks += 1;
                    for (k, i) in r.enumerate() {
                        streamed.hit[i] = out.hit[k];
                        streamed.valid[i] = out.valid[k];
                        streamed.t[i] = out.t[k];
                        streamed.u[i] = out.u[k];
                        streamed.v[i] = out.v[k];
                    }
                },
            );
            prop_assert_eq!(chunks, n.div_ceil(CHUNK));
            same(&f, &whole, &streamed)?;
        }
    }
}

/// The error bound on f64 lanes (`bound::verdict_block`) equals the scalar bound on every lane,
/// for every instruction level the machine has (under `emu/avx512`: AVX-512F too).
mod bound_block {
    use super::*;
    use datapath::bound::{verdict_block, BlockOpts, BlockRay, RtiBound};

    fn edge(r: &mut SplitMix64) -> f64 {
        match r.below(12) {
            0 => 0.0,
            1 => -0.0,
            2 => f64::INFINITY,
            3 => f64::NAN,
            4 => f64::from_bits(r.next_u64() & 0x000f_ffff_ffff_ffff),
            5 => 3.4e38 * r.range(0.5, 2.0),
            6 => (r.below(9) as f64) - 4.0,
            _ => r.range(-2.0, 2.0),
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(96))]
        #[test]
        fn the_bound_on_lanes_equals_the_scalar_bound(seed in any::<u64>(), n in 0usize..70, divide in any::<bool>(), cull in any::<bool>(), fmt in 0usize..3) {
            let mut r = SplitMix64::new(seed);
            let em = match fmt {
                0 => Ieee::new(F32Native, FpOpts::default()).error_model(),
                1 => Ieee::new(F16Half, FpOpts::default()).error_model(),
                _ => {
                    let q: datapath::AnyFormat = "q8.24".parse().unwrap();
                    datapath::with_format!(q, |f| f.error_model())
                }
            };
            let opts = BlockOpts {
                em,
                div: if divide { DivMode::Divide } else { DivMode::RecipMul },
                cull: if cull { Cull::Backface } else { Cull::TwoSided },
                det_threshold: if r.below(3) == 0 { 1e-3 } else { 0.0 },
            };
            let ray = BlockRay {
                o: std::array::from_fn(|_| edge(&mut r)),
                d: std::array::from_fn(|_| edge(&mut r)),
                tmin: if r.below(3) == 0 { edge(&mut r) } else { 0.0 },
                tmax: if r.below(3) == 0 { edge(&mut r) } else { f64::INFINITY },
            };
            let cols: [Vec<f64>; 9] = std::array::from_fn(|_| (0..n).map(|_| edge(&mut r)).collect());
            for (k, explicit) in kernels_here().into_iter().flat_map(|k| [(k, false), (k, true)]) {
                let (mut dec, mut hit, mut te) = (vec![false; n], vec![false; n], vec![0.0; n]);
                // the loop the compiler vectorises, and the explicit vector registers
                let block = if explicit { verdict_block } else { datapath::bound::verdict_block_loop };
                block(k, opts, ray, std::array::from_fn(|c| &cols[c][..]), &mut dec, &mut hit, &mut te);
                for i in 0..n {
                    let v = std::array::from_fn(|p| std::array::from_fn(|a| cols[3 * p + a][i]));
                    let b = RtiBound::new(opts.em, opts.div, ray.o, ray.d, v);
                    let want = b.verdict(opts.cull, opts.det_threshold, ray.tmin, ray.tmax);
                    prop_assert_eq!((dec[i], hit[i]), (want.decisive, want.hit), "{:?} lane {}", k, i);
                    // NaN bounds compare as NaN (Rust leaves a NaN's encoding open)
                    prop_assert!(te[i].to_bits() == b.t_err.to_bits() || (te[i].is_nan() && b.t_err.is_nan()), "{:?} lane {}", k, i);
                }
            }
        }
    }
}

/// The static filter in front of the bound (`bound_filter::verdict_block_filtered`) certifies
/// the same lanes and gives the same verdicts on every instruction level the machine has (its
/// block maxima and its certificate run in AVX2 or AVX-512F vector registers; under
/// `emu/avx512`: AVX-512F too), on blocks of ordinary triangles (most lanes certified) with
/// edge values mixed in, with the block's constants (binary32) and each lane's (binary16, e8m7,
/// e5m10 under FTZ), both division modes and cull rules; and the block
/// maxima it starts from are the same bits on every level, on lengths around the vector widths
/// and inputs with zeros of both signs, subnormals, huge values, infinities and NaNs.
mod bound_filter_block {
    use super::*;
    use datapath::bound::{BlockOpts, BlockRay};
    use datapath::bound_filter::{block_maxima, verdict_block_filtered};

    fn bits(m: ([f64; 9], [f64; 9], f64, bool)) -> (Vec<u64>, u64, bool) {
        (m.0.iter().chain(&m.1).map(|x| x.to_bits()).collect(), m.2.to_bits(), m.3)
    }

    #[test]
    fn the_block_maxima_are_the_same_on_every_kernel() {
        let mut r = SplitMix64::new(11);
        let x = |r: &mut SplitMix64, wild: bool| match r.below(if wild { 12 } else { 8 }) {
            0 => 0.0,
            1 => -0.0,
            2 => 5e-324 * r.range(-8.0, 8.0).round(),
            3 => r.range(-1.0, 1.0) * 1e300,
            8 | 9 => f64::INFINITY * r.range(-1.0, 1.0).signum(),
            10 | 11 => f64::NAN,
            _ => r.range(-4.0, 4.0),
        };
        let mut compared = 0;
        for n in [0, 1, 3, 4, 5, 7, 8, 9, 15, 16, 17, 31, 64, 255, 256] {
            for t in 0..60 {
                // ordinary blocks, blocks of edge values, and ordinary blocks with one edge
                // value in one column's lane (or the ray's origin)
                let wild = t % 3 == 1;
                let mut cols: Vec<Vec<f64>> = (0..9).map(|_| (0..n).map(|_| x(&mut r, wild)).collect()).collect();
                let mut o: [f64; 3] = std::array::from_fn(|_| x(&mut r, wild));
                if t % 3 == 2 {
                    let e =
                        [0.0, -0.0, 5e-324, -1e300, f64::INFINITY, f64::NEG_INFINITY, f64::NAN][r.below(7) as usize];
                    match (r.below(10) as usize, n) {
                        (9, _) | (_, 0) => o[r.below(3) as usize] = e,
                        (c, _) => cols[c][r.below(n as u64) as usize] = e,
                    }
                }
                let c: [&[f64]; 9] = std::array::from_fn(|k| &cols[k][..]);
                let ray = BlockRay { o, d: [1.0, 0.5, 0.25], tmin: 0.0, tmax: 1.0 };
                let want = bits(block_maxima(Kernel::Scalar, ray, c));
                for k in kernels_here() {
                    assert_eq!(bits(block_maxima(k, ray, c)), want, "{k:?} n {n}");
                    compared += 1;
                }
            }
        }
        assert!(compared >= 600);
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]
        #[test]
        fn the_filter_is_the_same_on_every_kernel(seed in any::<u64>(), n in 0usize..300, wild in 0u64..4, fmt in 0usize..4) {
            let mut r = SplitMix64::new(seed);
            let x = |r: &mut SplitMix64, c: f64| {
                if wild > 0 && r.below(64) < wild {
                    match r.below(6) {
                        0 => 0.0,
                        1 => -0.0,
                        2 => f64::from_bits(r.next_u64() & 0x000f_ffff_ffff_ffff),
                        3 => 3.0e38 * r.range(-1.0, 1.0),
                        4 => f64::INFINITY,
                        _ => f64::NAN,
                    }
                } else {
                    c + r.range(-0.05, 0.05)
                }
            };
            // binary32 (the block's constants for every lane) and coarse formats (each lane's
            // own constants: binary16, e8m7, e5m10 under FTZ), both division modes and cull
            // rules, a zero and a nonzero det threshold
            let name = ["f32", "fp16", "e8m7", "e5m10:ftz"][fmt];
            let f: datapath::AnyFormat = name.parse().unwrap();
            let opts = BlockOpts {
                em: datapath::with_format!(f, |f| datapath::Format::error_model(&f)),
                div: if r.below(2) == 0 { DivMode::RecipMul } else { DivMode::Divide },
                cull: if r.below(2) == 0 { Cull::TwoSided } else { Cull::Backface },
                det_threshold: if r.below(3) == 0 { 1e-3 } else { 0.0 },
            };
            let ray = BlockRay { o: [0.0, 0.0, -2.0], d: [r.range(-0.3, 0.3), r.range(-0.3, 0.3), 1.0], tmin: 0.0, tmax: f64::INFINITY };
            let centres: Vec<[f64; 3]> = (0..n).map(|_| [r.range(-1.0, 1.0), r.range(-1.0, 1.0), r.range(-0.5, 0.5)]).collect();
            let cols: [Vec<f64>; 9] = std::array::from_fn(|c| centres.iter().map(|p| x(&mut r, p[c % 3])).collect());
            let run = |k: Kernel| {
                let (mut dec, mut hit, mut te, mut cert) = (vec![false; n], vec![false; n], vec![0.0; n], vec![false; n]);
                let got = verdict_block_filtered(k, opts, ray, std::array::from_fn(|c| &cols[c][..]), None, &mut dec, &mut hit, &mut te, &mut cert);
                (got, dec, hit, te.iter().map(|t| if t.is_nan() { u64::MAX } else { t.to_bits() }).collect::<Vec<_>>(), cert)
            };
            let want = run(Kernel::Scalar);
            if wild == 0 && n > 0 && fmt == 0 {
                prop_assert!(want.0 > 0, "an ordinary block certifies lanes");
            }
            for k in kernels_here() {
                prop_assert_eq!(&run(k), &want, "{:?}", k);
            }
        }
    }
}

/// Add, subtract, multiply and divide through `batch` (`out[i] = a[i] op b[i]`) on every
/// kernel this machine has, each result equal to the format's own operation (its division
/// mode included).
fn ops_on_every_kernel<F: Format>(
    f: &F,
    name: &str,
    a: &[F::V],
    b: &[F::V],
    batch: impl Fn(datapath::rti::Op, &[F::V], &[F::V], &mut [F::V]),
) where
    F::V: Default + PartialEq + std::fmt::Debug,
{
    use datapath::rti::Op;
    for k in kernels_here() {
        for op in [Op::Add, Op::Sub, Op::Mul, Op::Div] {
            let mut out = vec![F::V::default(); a.len()];
            with_kernel_cap(k, || batch(op, a, b, &mut out));
            for i in 0..a.len() {
                let want = match op {
                    Op::Add => f.add(a[i], b[i]),
                    Op::Sub => f.sub(a[i], b[i]),
                    Op::Mul => f.mul(a[i], b[i]),
                    _ => f.div(a[i], b[i]),
                };
                assert_eq!(out[i], want, "{name} {op:?} {:?} {:?} on {k:?}", a[i], b[i]);
            }
        }
    }
}

/// Operand pairs of a wide `eEmM` format whose sums and differences land where the lanes'
/// rounding has its edges (random pairs almost never do): 2^k ± 2^(k − j) for j up to 60
/// (around M and S = 52 − M especially),
/// just above a power of two (within 2^−S of it: the two-operation rounding's binade below)
/// and just below one (rounding up into the next binade), ties to even and zeros of either
/// sign, at exponents from emin to emax and both signs.
fn rounding_edges(f: &datapath::format::Ieee<datapath::format::Soft>) -> Vec<(u64, u64)> {
    use datapath::format::IeeeBackend as _;
    use datapath::Format as _;
    let lay = f.backend.layout();
    let (emin, emax, m) = (lay.emin(), lay.emax(), lay.man_bits as i32);
    let p2 = |e: i32| (e as f64).exp2();
    let mut out = Vec::new();
    // S = 52 − M: the rounding's binade edge lies within 2^−S of a power of two
    let s = 52 - m;
    let js = [1, 2, 3, m, m + 1, m + 2, m + 3, s - 2, s - 1, s, s + 1, s + 2, s + 3, 45, 52, 53, 60];
    for k in [emin, emin + m + 2, -3, 0, 1, emax - 1, emax] {
        for j in js {
            for sa in [1.0, -1.0] {
                for sb in [1.0, -1.0] {
                    // 2^k, the value above and below it, ±2^(k − j) (held where the format can)
                    let a = [p2(k), p2(k) * (1.0 + p2(-m)), p2(k) * (2.0 - p2(-m))];
                    for a in a {
                        for b in [p2(k - j), p2(k - j) * 3.0, p2(k - j) * (1.0 + p2(-m))] {
                            let (x, y) = (f.from_f64(sa * a), f.from_f64(sb * b));
                            if f.to_f64(x) == sa * a && f.to_f64(y) == sb * b {
                                out.push((x, y));
                            }
                        }
                    }
                }
            }
        }
    }
    for (x, y) in [(0.0, 0.0), (-0.0, -0.0), (-0.0, 0.0), (0.0, -0.0), (-0.0, 1.0), (1.0, -0.0), (-1.0, 0.0)] {
        out.push((f.from_f64(x), f.from_f64(y)));
    }
    out
}

/// The double-rounding argument of `datapath::format::narrow`, checked exhaustively: every
/// operand pair of e5m4, e4m3, e3m2 and e2m1 (every subnormal and division mode) and 2^20
/// random pairs of e8m16 and e10m24 (fewer under emu/avx512, see below) with their
/// [`rounding_edges`], through + − × ÷ in binary64 lanes then rounded to the
/// format, equals the soft-float model's correctly rounded operation, bit for bit.
#[test]
fn narrow_ops_in_binary64_lanes_equal_the_soft_float_model_exhaustively() {
    use datapath::simd::{op_batch_soft, op_kernel_soft};
    for name in ["e5m4", "e4m3", "e3m2", "e2m1", "e8m16", "e10m24"] {
        for opts in ["", ":ftz", ":divide", ":ftz+divide"] {
            let full = format!("{name}{opts}");
            let any: datapath::AnyFormat = full.parse().unwrap();
            let datapath::AnyFormat::Soft(f) = any else { unreachable!() };
            let w = f.width();
            // on the emulated machine (emu/avx512, ~100x slower) the formats wider than 6 bits
            // take 2^12 random pairs; the host runs every pair
            let emulated = std::env::var_os("RAYPIPE_EXPECT_KERNEL").is_some();
            let (a, b): (Vec<u64>, Vec<u64>) = if w <= 6 || (w <= 10 && !emulated) {
                (0..1u64 << (2 * w)).map(|k| (k >> w, k & ((1 << w) - 1))).unzip()
            } else {
                let mut r = SplitMix64::new(0x0b5);
                let n = if emulated { 1 << 12 } else { 1 << 20 };
                let mut pairs: Vec<(u64, u64)> =
                    (0..n).map(|_| (f.from_bits(r.next_u64()), f.from_bits(r.next_u64()))).collect();
                pairs.extend(rounding_edges(&f));
                pairs.into_iter().unzip()
            };
            for k in kernels_here() {
                let ran = with_kernel_cap(k, || op_kernel_soft(&f));
                assert_eq!(ran, k.min(datapath::simd::WIDEST_NARROW), "{full}");
            }
            ops_on_every_kernel(&f, &full, &a, &b, |op, a, b, out| {
                op_batch_soft(&f, op, a, b, out);
            });
        }
    }
}

/// Fixed-point formats of every rounding, overflow and division mode, at widths that take
/// each of the lanes' division paths (one correction step; two under wrap when a quotient can
/// reach 2^53: q8.24, q1.31; no fraction bits: q32.0).
const FIXED_NAMES: [&str; 8] = ["q16.16", "q8.24", "q1.31", "q4.4", "q32.0", "q12.20", "q2.6", "q20.4"];
const FIXED_MODES: [&str; 16] = [
    "",
    ":ceil",
    ":trunc",
    ":nearest",
    ":wrap",
    ":ceil+wrap",
    ":trunc+wrap",
    ":nearest+wrap",
    ":divide",
    ":ceil+divide",
    ":trunc+divide",
    ":nearest+divide",
    ":wrap+divide",
    ":ceil+wrap+divide",
    ":trunc+wrap+divide",
    ":nearest+wrap+divide",
];

/// The widest fixed-point kernel this machine can run: the 8-lane kernel needs AVX-512DQ too.
fn widest_fixed() -> Kernel {
    #[cfg(target_arch = "x86_64")]
    if !std::arch::is_x86_feature_detected!("avx512dq") {
        return Kernel::Avx2;
    }
    datapath::simd::fixed::WIDEST_FIXED
}

fn fixed(name: &str) -> datapath::format::Fixed {
    match name.parse::<datapath::AnyFormat>().unwrap() {
        datapath::AnyFormat::Fixed(f) => f,
        _ => unreachable!("{name} is fixed point"),
    }
}

/// The edge raw values of a fixed-point format: 0, ±1 step, the most positive and most
/// negative values and their neighbours, ±1, ±1/2 and ±half the range.
fn fixed_specials(f: &datapath::format::Fixed) -> Vec<u64> {
    let (lo, hi) = (f.min_raw(), f.max_raw());
    let one = f.one();
    [0, 1, -1, hi, hi - 1, lo, lo + 1, one, -one, one / 2, -one / 2, hi / 2, lo / 2, hi / 2 + 1]
        .map(|v| f.to_bits(v.clamp(lo, hi)))
        .to_vec()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

    /// The fixed-point i64-lane RTI kernels return the scalar model's bits on every kernel,
    /// every rounding, overflow and division mode, both cullings.
    #[test]
    fn fixed_point_kernels_match_the_scalar_model(seed in any::<u64>(), n in 0usize..300, name in 0usize..8, mode in 0usize..16, cull in any::<bool>(), thr in prop_oneof![Just(0.0), Just(1e-3), Just(0.5)]) {
        use datapath::simd::fixed::{kernel_fixed, rti_batch_fixed};
        let f = fixed(&format!("{}{}", FIXED_NAMES[name], FIXED_MODES[mode]));
        let rti = Rti::new(f, config(cull, thr));
        let (rays, tris) = columns(&f, n, seed, &fixed_specials(&f));
        let mut a = HitsSoa::with_len(n);
        rti.batch(&rays, &tris, &mut a);
        for k in kernels_here() {
            let mut out = HitsSoa::with_len(n);
            let ran = with_kernel_cap(k, || rti_batch_fixed(&rti, &rays, &tris, &mut out));
            prop_assert_eq!(ran, with_kernel_cap(k, || kernel_fixed(&f)));
            prop_assert_eq!(ran, k.min(widest_fixed()));
            same(&f, &a, &out)?;
        }
    }
}

/// Every fixed-point operation on i64 lanes equals the scalar model (exact i128 arithmetic):
/// every operand pair of the 8-bit formats, 2^16 random and edge pairs of the wider ones (2^10
/// of each under emu/avx512), in every rounding, overflow and division mode, on every kernel.
#[test]
fn fixed_point_ops_in_i64_lanes_equal_the_i128_model() {
    use datapath::simd::fixed::op_batch_fixed;
    for name in FIXED_NAMES {
        for mode in FIXED_MODES {
            let full = format!("{name}{mode}");
            let f = fixed(&full);
            let w = f.width();
            // on the emulated machine (emu/avx512) every format takes 2^10 random pairs
            let emulated = std::env::var_os("RAYPIPE_EXPECT_KERNEL").is_some();
            let (a, b): (Vec<i64>, Vec<i64>) = if w <= 8 && !emulated {
                (0..1u64 << (2 * w)).map(|k| (f.from_bits(k >> w), f.from_bits(k & ((1 << w) - 1)))).unzip()
            } else {
                let sp = fixed_specials(&f);
                let mut r = SplitMix64::new(0xf1);
                let n = if emulated { 1 << 10 } else { 1 << 16 };
                let pick = |r: &mut SplitMix64| match r.below(4) {
                    0 => f.from_bits(sp[r.below(sp.len() as u64) as usize]),
                    // small magnitudes: the products and quotients that round
                    1 => r.below(1 << 12) as i64 - (1 << 11),
                    _ => f.from_bits(r.next_u64()),
                };
                (0..n).map(|_| (pick(&mut r), pick(&mut r))).unzip()
            };
            ops_on_every_kernel(&f, &full, &a, &b, |op, a, b, out| {
                op_batch_fixed(&f, op, a, b, out);
            });
        }
    }
}

/// Fixed-point formats wider than 32 bits keep the scalar model.
#[test]
fn fixed_point_formats_wider_than_32_bits_run_the_scalar_model() {
    for name in ["q16.17", "q32.32", "q8.56", "q33.0"] {
        assert_eq!(datapath::simd::fixed::kernel_fixed(&fixed(name)), Kernel::Scalar, "{name}");
    }
}

/// `simd::gather::gather` on every kernel is the plain copy `cols[c][k] = pick(&recs[idx[k]])[c]`
/// bit for bit: 4- and 8-byte numbers (the AVX-512F and AVX2 gathers), 2-byte ones (`u16`,
/// `half::f16`, `half::bf16`: pairs by 4-byte gathers; an even and an odd number of columns,
/// one column with room after it, and one at a record's end — its values: that no byte past a
/// record is read is `pair_reads_fit`'s rule, not observable here), a field at
/// an offset within its record, every length up to 70 (whole 16- and 8-lane steps and tails),
/// NaN payloads copied as they are; an index out of range (in the first, second and fourth
/// 8-lane step) and a short column panic.
mod gather {
    use super::*;
    use datapath::simd::gather::gather;
    use datapath::simd::{kernels_here, with_kernel_cap, Kernel};

    #[derive(Clone, Copy)]
    struct Rec {
        _pad: [u16; 3],
        a: [f32; 5],
        b: [f64; 3],
        h: [u16; 2],
        q: [i64; 2],
        m: [half::f16; 9],
        g: [half::bf16; 3],
        one: [u16; 1],
        // fields of several whole and partial 4-, 8- and 16-value rows
        a9: [f32; 9],
        b6: [f64; 6],
        w6: [u16; 6],
        w17: [u16; 17],
    }

    /// A one-column 2-byte field at the record's end (no 2 bytes after it to read).
    #[derive(Clone, Copy)]
    #[repr(C)]
    struct Tail {
        a: u16,
        z: [u16; 1],
    }

    fn recs(r: &mut SplitMix64, n: usize) -> Vec<Rec> {
        (0..n)
            .map(|_| Rec {
                _pad: [0; 3],
                a: std::array::from_fn(|_| f32::from_bits(r.next_u64() as u32)),
                b: std::array::from_fn(|_| f64::from_bits(r.next_u64())),
                h: std::array::from_fn(|_| r.next_u64() as u16),
                q: std::array::from_fn(|_| r.next_u64() as i64),
                m: std::array::from_fn(|_| half::f16::from_bits(r.next_u64() as u16)),
                g: std::array::from_fn(|_| half::bf16::from_bits(r.next_u64() as u16)),
                one: [r.next_u64() as u16],
                a9: std::array::from_fn(|_| f32::from_bits(r.next_u64() as u32)),
                b6: std::array::from_fn(|_| f64::from_bits(r.next_u64())),
                w6: std::array::from_fn(|_| r.next_u64() as u16),
                w17: std::array::from_fn(|_| r.next_u64() as u16),
            })
            .collect()
    }

    fn check<R, T: Copy + Default + 'static, const C: usize>(
        k: Kernel,
        recs: &[R],
        idx: &[u32],
        pick: impl Fn(&R) -> &[T; C] + Copy,
        bits: impl Fn(T) -> u64,
    ) {
        let mut cols: [Vec<T>; C] = std::array::from_fn(|_| vec![T::default(); idx.len() + 3]);
        with_kernel_cap(k, || gather(k, recs, idx, true, pick, cols.each_mut().map(|c| &mut c[..])));
        for (j, &i) in idx.iter().enumerate() {
            for (c, (col, &want)) in cols.iter().zip(pick(&recs[i as usize])).enumerate() {
                assert_eq!(bits(col[j]), bits(want), "{k:?} lane {j} of {} column {c}", idx.len());
            }
        }
        assert!(
            cols.iter().all(|c| c[idx.len()..].iter().all(|&x| bits(x) == bits(T::default()))),
            "{k:?}: wrote past the block"
        );
    }

    #[test]
    fn gathers_are_the_plain_copy_on_every_kernel() {
        let mut r = SplitMix64::new(0x9a7);
        let recs = recs(&mut r, 300);
        for k in kernels_here() {
            for n in (0..=70).chain([255, 256]) {
                let idx: Vec<u32> = (0..n).map(|_| r.below(300) as u32).collect();
                check(k, &recs, &idx, |x| &x.a, |v: f32| u64::from(v.to_bits()));
                check(k, &recs, &idx, |x| &x.b, f64::to_bits);
                check(k, &recs, &idx, |x| &x.h, u64::from);
                check(k, &recs, &idx, |x| &x.q, |v: i64| v as u64);
                check(k, &recs, &idx, |x| &x.m, |v: half::f16| u64::from(v.to_bits()));
                check(k, &recs, &idx, |x| &x.g, |v: half::bf16| u64::from(v.to_bits()));
                check(k, &recs, &idx, |x| &x.one, u64::from);
                check(k, &recs, &idx, |x| &x.a9, |v: f32| u64::from(v.to_bits()));
                check(k, &recs, &idx, |x| &x.b6, f64::to_bits);
                check(k, &recs, &idx, |x| &x.w6, u64::from);
                check(k, &recs, &idx, |x| &x.w17, u64::from);
                let tails: Vec<Tail> = recs.iter().map(|x| Tail { a: x.h[0], z: x.one }).collect();
                check(k, &tails, &idx, |x| &x.z, u64::from);
            }
        }
    }

    #[test]
    fn out_of_range_indices_and_short_columns_panic_on_every_kernel() {
        let mut r = SplitMix64::new(0x9a8);
        let recs = recs(&mut r, 40);
        for k in kernels_here() {
            for bad in [0usize, 5, 15, 16, 31] {
                let mut idx: Vec<u32> = (0..32).map(|_| r.below(40) as u32).collect();
                idx[bad] = 40;
                let res = std::panic::catch_unwind(|| {
                    let mut cols: [Vec<f32>; 5] = std::array::from_fn(|_| vec![0.0; 32]);
                    with_kernel_cap(k, || gather(k, &recs, &idx, false, |x| &x.a, cols.each_mut().map(|c| &mut c[..])));
                });
                assert!(res.is_err(), "{k:?}: index 40 of 40 records at lane {bad} taken");
            }
            let res = std::panic::catch_unwind(|| {
                let idx = [1u32; 20];
                let mut cols: [Vec<f64>; 3] = [vec![0.0; 20], vec![0.0; 19], vec![0.0; 20]];
                gather(k, &recs, &idx, false, |x| &x.b, cols.each_mut().map(|c| &mut c[..]));
            });
            assert!(res.is_err(), "{k:?}: a short column taken");
        }
    }
}

mod draw {
    use datapath::rng::SplitMix64;
    use datapath::simd::draw::below_column;
    use datapath::simd::{kernels_here, with_kernel_cap};

    /// A column of draws equals the same draws taken one by one (every length up to 70, bounds
    /// from 1 to u32::MAX, states anywhere), and leaves the generator where they leave it.
    #[test]
    fn a_column_of_draws_equals_the_draws_one_by_one() {
        let mut g = SplitMix64::new(99);
        for round in 0..3000 {
            let n = match round % 5 {
                0 => 1,
                1 => u64::from(u32::MAX),
                2 => 1 + g.below(10),
                _ => 1 + g.below(u64::from(u32::MAX)),
            };
            let len = (round % 71) as usize;
            let seed = g.next_u64();
            let mut one = SplitMix64::new(seed);
            let want: Vec<u32> = (0..len).map(|_| one.below(n) as u32).collect();
            let after = one.next_u64();
            for k in kernels_here() {
                let mut r = SplitMix64::new(seed);
                let mut got = vec![7u32; len];
                with_kernel_cap(k, || below_column(k, &mut r, n, &mut got));
                assert_eq!(got, want, "{k:?} n {n} len {len}");
                assert_eq!(r.next_u64(), after, "{k:?}: the generator left elsewhere");
            }
        }
    }

    #[test]
    #[should_panic(expected = "below_column")]
    fn a_bound_above_u32_is_refused() {
        below_column(datapath::simd::Kernel::Scalar, &mut SplitMix64::new(1), 1 << 32, &mut [0; 3]);
    }
}

mod widen {
    use datapath::rng::SplitMix64;
    use datapath::simd::widen::{bf16_to_f64, e8_to_f64, f16_to_f64, f32_to_f64, fixed_to_f64};
    use datapath::simd::{kernels_here, with_kernel_cap};

    /// Every binary32 class (zeros, subnormals, normals, infinities, NaNs) widens to the
    /// one-value cast's f64 on every kernel, at every length up to 100.
    #[test]
    fn a_widened_column_equals_the_cast_of_each_value() {
        let mut g = SplitMix64::new(5);
        let specials =
            [0u32, 0x8000_0000, 1, 0x807f_ffff, 0x0080_0000, 0x7f7f_ffff, 0x7f80_0000, 0xff80_0000, 0x7fc0_0000];
        for len in 0..100 {
            let src: Vec<f32> = (0..len)
                .map(|i| {
                    if i % 3 == 0 {
                        f32::from_bits(specials[g.below(9) as usize])
                    } else {
                        f32::from_bits(g.next_u64() as u32)
                    }
                })
                .collect();
            for k in kernels_here() {
                let mut dst = vec![0.5; len];
                with_kernel_cap(k, || f32_to_f64(k, &src, &mut dst));
                for (i, (&x, &y)) in src.iter().zip(&dst).enumerate() {
                    let want = x as f64;
                    assert!(
                        y.to_bits() == want.to_bits() || (y.is_nan() && want.is_nan()),
                        "{k:?} lane {i}: {x:?} -> {y:?}"
                    );
                }
            }
        }
    }

    /// Every encoding of e8m7 and e8m2, and e8m16 encodings dense at the edges (zeros,
    /// subnormals, the normal boundary, the largest, ∞, NaNs) and random, widen to the format's
    /// exact `to_f64` on every kernel (the same bits, NaNs included) — through the format's
    /// column conversion, which takes this path for `e8mM`.
    #[test]
    fn e8_encodings_widen_to_their_values() {
        use datapath::Format;
        let mut g = SplitMix64::new(4);
        for name in ["e8m7", "e8m2", "e8m16", "e8m16:ftz"] {
            let datapath::AnyFormat::Soft(f) = name.parse::<datapath::AnyFormat>().unwrap() else { unreachable!() };
            let m = f.backend.0.man_bits;
            let w = 9 + m;
            let src: Vec<u64> = if w <= 16 {
                (0..1u64 << w).collect()
            } else {
                // e8m16: zero, the subnormals' ends, the normal boundary, the largest, ∞, NaNs
                let edges = [0u64, 1, 0xffff, 0x1_0000, 0xfe_ffff, 0xff_0000, 0xff_0001, 0xff_ffff];
                edges
                    .iter()
                    .flat_map(|&e| (0..64u64).flat_map(move |k| [e + k, e.wrapping_sub(k)].map(|x| x & 0xff_ffff)))
                    .flat_map(|x| [x, x | 0x100_0000])
                    .chain((0..5000).map(|_| g.next_u64() & 0x1ff_ffff))
                    .collect()
            };
            assert!(f.fast_f64_column(), "{name}");
            for k in kernels_here() {
                let mut dst = vec![0.5; src.len()];
                with_kernel_cap(k, || f.to_f64_column(&src, &mut dst));
                let mut direct = vec![0.5; src.len()];
                e8_to_f64(k, &src, 23 - m, &mut direct);
                for ((&x, &y), &z) in src.iter().zip(&dst).zip(&direct) {
                    let want = f.to_f64(x);
                    let ok = |y: f64| y.to_bits() == want.to_bits();
                    assert!(ok(y) && ok(z), "{name} {k:?} {x:#x} -> {y:?} / {z:?}, want {want:?}");
                }
            }
        }
    }

    /// A fixed-point column widens to the one-value `raw as f64 * 2^-F` on every kernel (the
    /// same bits): values of every magnitude up to ±2^63, those past 2^53 rounding alike, and
    /// columns within ±2^51 (the conversion without AVX-512DQ: its edges −2^51 and 2^51 − 1, and
    /// such a column with one value just outside), at ragged lengths, for several F.
    #[test]
    fn a_fixed_point_column_widens_as_each_value() {
        let mut g = SplitMix64::new(9);
        let edges = [-(1i64 << 51), (1 << 51) - 1, 0, -1, 1];
        for f in [0, 8, 16, 24, 31, 63] {
            let scale = 2f64.powi(-f);
            for len in [0, 1, 7, 8, 9, 17, 256, 300] {
                let wide: Vec<i64> =
                    (0..len).map(|i| (g.next_u64() as i64) >> (i % 64)).chain([i64::MIN, i64::MAX, 0, -1]).collect();
                let narrow: Vec<i64> = (0..len).map(|i| (g.next_u64() as i64) >> (12 + i % 52)).chain(edges).collect();
                let mut outside = narrow.clone();
                outside[len / 2] = if len % 2 == 0 { (1 << 51) + 12345 } else { -(1 << 51) - 1 }; // past each end
                for (k, src) in kernels_here().into_iter().flat_map(|k| [(k, &wide), (k, &narrow), (k, &outside)]) {
                    let mut dst = vec![0.5; src.len()];
                    with_kernel_cap(k, || fixed_to_f64(k, src, scale, &mut dst));
                    for (&x, &y) in src.iter().zip(&dst) {
                        assert_eq!(y.to_bits(), (x as f64 * scale).to_bits(), "{k:?} F {f} {x}");
                    }
                }
            }
        }
    }

    /// Every binary16 encoding widens to `half`'s `to_f64` of it (the same bits; a NaN a NaN)
    /// on every kernel, whole and at ragged lengths.
    #[test]
    fn every_binary16_encoding_widens_to_its_value() {
        let src: Vec<half::f16> = (0..=u16::MAX).map(half::f16::from_bits).collect();
        for k in kernels_here() {
            for len in [src.len(), 0, 1, 7, 8, 9, 15, 16, 17, 1000] {
                let mut dst = vec![0.5; len];
                with_kernel_cap(k, || f16_to_f64(k, &src[..len], &mut dst));
                for (&x, &y) in src.iter().zip(&dst) {
                    let want = x.to_f64();
                    assert!(
                        y.to_bits() == want.to_bits() || (y.is_nan() && want.is_nan()),
                        "{k:?} {:#06x} -> {y:?}",
                        x.to_bits()
                    );
                }
            }
        }
    }

    /// Every bfloat16 encoding widens to its binary32 value's f64 (the encoding shifted into
    /// binary32's upper half) on every kernel, whole and at ragged lengths.
    #[test]
    fn every_bfloat16_encoding_widens_to_its_value() {
        let src: Vec<u16> = (0..=u16::MAX).collect();
        for k in kernels_here() {
            for len in [src.len(), 0, 1, 7, 8, 9, 17, 1000] {
                let mut dst = vec![0.5; len];
                with_kernel_cap(k, || bf16_to_f64(k, &src[..len], &mut dst));
                for (&x, &y) in src.iter().zip(&dst) {
                    let want = f32::from_bits(u32::from(x) << 16) as f64;
                    assert!(y.to_bits() == want.to_bits() || (y.is_nan() && want.is_nan()), "{k:?} {x:#06x} -> {y:?}");
                }
            }
        }
    }
}
