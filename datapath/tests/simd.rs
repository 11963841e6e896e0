//! The SIMD kernels return exactly the scalar model's bits, specials included.

use datapath::format::{DivMode, F16Half, F32Native, FpOpts, Ieee, NanMode, Subnormals};
use datapath::rng::SplitMix64;
use datapath::rti::{Cull, HitsSoa, RaysSoa, Rti, RtiConfig, TieRule, TrisSoa};
use datapath::simd::{kernel_f16, kernel_f32, rti_batch_f16, rti_batch_f32, Kernel};
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

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    #[test]
    fn f32_kernel_matches_the_scalar_model(seed in any::<u64>(), n in 0usize..70, divide in any::<bool>(), cull in any::<bool>(), thr in prop_oneof![Just(0.0), Just(1e-6), Just(0.5)]) {
        let f = Ieee::new(F32Native, FpOpts { div: if divide { DivMode::Divide } else { DivMode::RecipMul }, ..FpOpts::default() });
        let rti = Rti::new(f, config(cull, thr));
        let (rays, tris) = columns(&f, n, seed, &F32_SPECIALS);
        let (mut a, mut b) = (HitsSoa::with_len(n), HitsSoa::with_len(n));
        rti.batch(&rays, &tris, &mut a);
        rti_batch_f32(&rti, &rays, &tris, &mut b);
        same(&f, &a, &b)?;
    }

    #[test]
    fn f16_kernel_matches_the_scalar_model(seed in any::<u64>(), n in 0usize..70, divide in any::<bool>(), cull in any::<bool>(), thr in prop_oneof![Just(0.0), Just(1e-3), Just(0.5)]) {
        let f = Ieee::new(F16Half, FpOpts { div: if divide { DivMode::Divide } else { DivMode::RecipMul }, ..FpOpts::default() });
        let rti = Rti::new(f, config(cull, thr));
        let (rays, tris) = columns(&f, n, seed, &F16_SPECIALS);
        let (mut a, mut b) = (HitsSoa::with_len(n), HitsSoa::with_len(n));
        rti.batch(&rays, &tris, &mut a);
        rti_batch_f16(&rti, &rays, &tris, &mut b);
        same(&f, &a, &b)?;
    }
}

#[test]
fn the_kernels_run_where_the_machine_has_them_and_hit_often_enough_to_matter() {
    let f32f = Ieee::new(F32Native, FpOpts::default());
    let f16f = Ieee::new(F16Half, FpOpts::default());
    #[cfg(target_arch = "x86_64")]
    {
        let avx2 = std::arch::is_x86_feature_detected!("avx2");
        let f16c = std::arch::is_x86_feature_detected!("f16c");
        assert_eq!(kernel_f32(&Rti::new(f32f, RtiConfig::default())) == Kernel::Avx2, avx2);
        assert_eq!(kernel_f16(&Rti::new(f16f, RtiConfig::default())) == Kernel::Avx2, avx2 && f16c);
    }
    // formats the kernels do not model fall back to the scalar model
    let ftz = Ieee::new(F32Native, FpOpts { subnormals: Subnormals::Ftz, ..FpOpts::default() });
    let prop = Ieee::new(F16Half, FpOpts { nan: NanMode::Propagate, ..FpOpts::default() });
    assert_eq!(kernel_f32(&Rti::new(ftz, RtiConfig::default())), Kernel::Scalar);
    assert_eq!(kernel_f16(&Rti::new(prop, RtiConfig::default())), Kernel::Scalar);
    // the generated columns are not vacuous: hits, misses and NaN outputs all occur
    let rti = Rti::new(f32f, RtiConfig::default());
    let (rays, tris) = columns(&f32f, 4000, 3, &F32_SPECIALS);
    let mut out = HitsSoa::with_len(4000);
    rti_batch_f32(&rti, &rays, &tris, &mut out);
    let hits = out.hit.iter().filter(|&&h| h).count();
    assert!(hits > 200 && hits < 3800, "{hits}");
    assert!(out.t.iter().any(|t| t.is_nan()) && out.t.iter().any(|t| t.is_infinite()));
}
