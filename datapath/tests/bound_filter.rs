//! The static filter in front of the per-test error bound (`bound_filter::verdict_block_filtered`)
//! gives every lane exactly the per-test verdict (`bound::verdict_block`): `decisive` and `hit`
//! on every lane, `t_err` on every lane it did not certify (+∞ on a certified lane, which is
//! decisive and misses), on blocks near a ray (most lanes certified), blocks with edge values
//! (subnormal, near the format's largest, ±0, ±∞, NaN, small integers whose compares tie), in
//! binary32, binary16, bfloat16-like, FTZ and fixed-point error models, both division modes,
//! both cull rules, a zero and a nonzero det threshold, on every instruction level the machine
//! has (under `emu/avx512`: AVX-512F too) — with the block's own constants and with constants
//! computed ahead from the bounds of a larger set holding the block's triangles
//! (`SetMaxima`, `Constants`: verify's path, one set per scene and format).

use datapath::bound::{verdict_block, BlockOpts, BlockRay, RtiBound};
use datapath::bound_filter::{verdict_block_filtered, Constants, SetMaxima};
use datapath::format::DivMode;
use datapath::rng::SplitMix64;
use datapath::rti::Cull;
use datapath::simd::kernels_here;
use proptest::prelude::*;

fn error_model(k: usize) -> datapath::format::ErrorModel {
    let name = ["f32", "fp16", "e8m7", "f32:ftz", "q8.24", "e5m10:ftz"][k];
    let f: datapath::AnyFormat = name.parse().unwrap();
    datapath::with_format!(f, |f| datapath::Format::error_model(&f))
}

/// An edge value; `finite`: no ±∞, NaN or value near the format's largest (so the block's
/// constants exist and can certify).
fn edge(r: &mut SplitMix64, max: f64, finite: bool) -> f64 {
    let k = if finite { [0, 1, 4, 6, 7, 8, 9, 10][r.below(8) as usize] } else { r.below(14) };
    match k {
        0 => 0.0,
        1 => -0.0,
        2 => f64::INFINITY,
        3 => f64::NAN,
        4 => f64::from_bits(r.next_u64() & 0x000f_ffff_ffff_ffff),
        5 => max * r.range(0.25, 1.5),
        6 => (r.below(9) as f64) - 4.0,
        7 => 2f64.powi(-(r.below(40) as i32)) * r.range(-1.0, 1.0),
        _ => r.range(-2.0, 2.0),
    }
}

/// A set holding every triangle of the block and each again with its vertices rotated (v1, v2,
/// v0: other first differences, the same values): constants from its bounds (`None` where it
/// has none: a non-finite coordinate).
fn set_constants(opts: BlockOpts, ray: BlockRay, cols: &[Vec<f64>; 9]) -> Option<Constants> {
    let n = cols[0].len();
    let tris = (0..n).flat_map(|i| {
        let t: [f64; 9] = std::array::from_fn(|k| cols[k][i]);
        [t, std::array::from_fn(|k| t[(k + 3) % 9])]
    });
    SetMaxima::of(tris).for_ray(ray).map(|m| Constants::new(opts, ray, m))
}

/// Runs the per-test bound and the filter (the block's own constants, and the set's of
/// [`set_constants`]) on one block, on every kernel here, and compares lane by lane (every
/// kernel certifies the same lanes); returns the lanes certified by
/// the block's constants, the lanes the per-test bound finds decisive misses, and the lanes
/// certified by the set's constants.
fn same(opts: BlockOpts, ray: BlockRay, cols: &[Vec<f64>; 9]) -> Result<(usize, usize, usize), TestCaseError> {
    let n = cols[0].len();
    let c = || std::array::from_fn(|k| &cols[k][..]);
    let set = set_constants(opts, ray, cols);
    let (mut certified, mut misses, mut by_set) = (0, 0, 0);
    // the lanes each kernel's filter certifies, which must be the first kernel's (every
    // instruction set runs the same lane operations)
    let mut first: [Option<Vec<bool>>; 2] = [None, None];
    for k in kernels_here() {
        let (mut dec, mut hit, mut te) = (vec![false; n], vec![false; n], vec![0.0; n]);
        verdict_block(k, opts, ray, c(), &mut dec, &mut hit, &mut te);
        for (which, pre) in [(0, None), (1, set.as_ref())] {
            let (mut fdec, mut fhit, mut fte, mut cert) =
                (vec![false; n], vec![false; n], vec![0.0; n], vec![false; n]);
            let got = verdict_block_filtered(k, opts, ray, c(), pre, &mut fdec, &mut fhit, &mut fte, &mut cert);
            for i in 0..n {
                prop_assert_eq!(
                    (fdec[i], fhit[i]),
                    (dec[i], hit[i]),
                    "{:?} constants {} lane {}: certified {}",
                    k,
                    which,
                    i,
                    cert[i]
                );
                if cert[i] {
                    prop_assert!(
                        fte[i] == f64::INFINITY && dec[i] && !hit[i],
                        "{:?} constants {} lane {}",
                        k,
                        which,
                        i
                    );
                } else {
                    prop_assert!(
                        fte[i].to_bits() == te[i].to_bits() || (fte[i].is_nan() && te[i].is_nan()),
                        "{:?} constants {} lane {}",
                        k,
                        which,
                        i
                    );
                }
            }
            prop_assert_eq!(got, cert.iter().filter(|&&c| c).count());
            match &first[which] {
                None => first[which] = Some(cert.clone()),
                Some(f) => prop_assert_eq!(f, &cert, "{:?} constants {}: other lanes certified", k, which),
            }
            if which == 0 {
                certified = got;
            } else {
                by_set = got;
            }
        }
        misses = (0..n).filter(|&i| dec[i] && !hit[i]).count();
    }
    Ok((certified, misses, by_set))
}

fn opts(r: &mut SplitMix64, fmt: usize, divide: bool, cull: bool) -> BlockOpts {
    BlockOpts {
        em: error_model(fmt),
        div: if divide { DivMode::Divide } else { DivMode::RecipMul },
        cull: if cull { Cull::Backface } else { Cull::TwoSided },
        det_threshold: if r.below(3) == 0 { 1e-3 } else { 0.0 },
    }
}

/// One block of edge values (`fin`: finite ones only) through both; as [`same`].
fn edge_block(
    seed: u64,
    n: usize,
    divide: bool,
    cull: bool,
    fmt: usize,
    fin: bool,
) -> Result<(usize, usize, usize), TestCaseError> {
    let mut r = SplitMix64::new(seed);
    let o = opts(&mut r, fmt, divide, cull);
    let max = o.em.max;
    let edge = |r: &mut SplitMix64| edge(r, max, fin);
    let ray = BlockRay {
        o: std::array::from_fn(|_| if r.below(4) == 0 { edge(&mut r) } else { r.range(-3.0, 3.0) }),
        d: std::array::from_fn(|_| if r.below(4) == 0 { edge(&mut r) } else { r.range(-1.0, 1.0) }),
        tmin: if r.below(3) == 0 { edge(&mut r) } else { 0.0 },
        tmax: if r.below(3) == 0 { edge(&mut r) } else { f64::INFINITY },
    };
    let rare = r.below(3) == 0;
    let cols: [Vec<f64>; 9] = std::array::from_fn(|_| {
        (0..n).map(|_| if !rare || r.below(8) == 0 { edge(&mut r) } else { r.range(-2.0, 2.0) }).collect()
    });
    same(o, ray, &cols)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// Edge values anywhere in the ray and the triangles.
    #[test]
    fn edge_blocks_get_the_per_test_verdict(seed in any::<u64>(), n in 0usize..80, divide in any::<bool>(), cull in any::<bool>(), fmt in 0usize..6, fin in any::<bool>()) {
        edge_block(seed, n, divide, cull, fmt, fin)?;
    }
}

/// Blocks of finite edge values (±0, subnormal, powers of two down to 2^-39, small integers): the filter
/// certifies lanes there too (its path is tested, not only its fallback), each as the per-test
/// bound decides it.
#[test]
fn finite_edge_blocks_are_certified_as_the_per_test_bound_decides() {
    let (mut certified, mut by_set) = (0, 0);
    for seed in 0..300u64 {
        let (k, _, ks) = edge_block(seed, 48, seed % 2 == 0, seed % 3 == 0, (seed % 6) as usize, true).unwrap();
        certified += k;
        by_set += ks;
    }
    assert!(certified > 100, "only {certified} lanes certified");
    assert!(by_set > 100, "only {by_set} lanes certified by the set's constants");
}

/// Triangles scattered around a ray, as a scene's block is: every lane gets the per-test
/// verdict, and the filter certifies most of the lanes the per-test bound decides as misses —
/// all of them in binary32 (plain and FTZ) and q8.24 by the block's constants; in binary16,
/// e8m7 and e5m10:ftz (coarse formats: the block's constants grow with its largest
/// differences and would leave a fifth to two thirds) by the per-lane constants.
#[test]
fn scene_like_blocks_are_mostly_certified() {
    let mut total = [(0usize, 0usize, 0usize); 6];
    for seed in 0..48u64 {
        for divide in [false, true] {
            for (fmt, t) in total.iter_mut().enumerate() {
                let mut r = SplitMix64::new(seed);
                let o = opts(&mut r, fmt, divide, false);
                let n = 64;
                let ray = BlockRay { o: [0.1, -0.2, -3.0], d: [0.01, 0.02, 1.0], tmin: 0.0, tmax: f64::INFINITY };
                let mut cols: [Vec<f64>; 9] = std::array::from_fn(|_| Vec::with_capacity(n));
                for _ in 0..n {
                    let c = [r.range(-2.0, 2.0), r.range(-2.0, 2.0), r.range(-1.0, 1.0)];
                    for p in 0..3 {
                        for a in 0..3 {
                            cols[3 * p + a].push(c[a] + r.range(-0.1, 0.1));
                        }
                    }
                }
                let (k, misses, ks) = same(o, ray, &cols).unwrap();
                t.0 += k;
                t.1 += misses;
                t.2 += ks;
            }
        }
    }
    let share = |f: usize| total[f].0 as f64 / total[f].1 as f64;
    for f in [0, 3, 4] {
        assert!(share(f) > 0.99, "format {f}: {:?}", total[f]);
    }
    // the per-lane constants at work (the block's alone: 0.82, 0.81 and 0.28 here)
    assert!(share(1) > 0.98, "binary16: {:?}", total[1]);
    assert!(share(5) > 0.9, "e5m10:ftz: {:?}", total[5]);
    assert!(share(2) > 0.9, "e8m7: {:?}", total[2]);
    // the set's constants (its bounds no smaller than the block's) certify nearly as many
    for (f, t) in total.iter().enumerate() {
        assert!(t.2 as f64 >= 0.9 * t.0 as f64, "format {f}: set {} against the block's {}", t.2, t.0);
    }
}

/// Far triangles and a slow ray, so that a lane's quotient t = t'/det (or u, v) can leave the
/// format's range while every compared quantity clears its constant (condition (4) of the
/// filter): each lane gets the per-test verdict, in binary16 (largest 65504) and e8m7, both
/// division modes — a certificate that ignored a quotient's overflow flag would be caught here
/// (the per-test bound finds such lanes not decisive; the test requires some).
#[test]
fn lanes_whose_quotients_overflow_get_the_per_test_verdict() {
    let (mut undecided, mut certified) = (0, 0);
    for seed in 0..64u64 {
        for divide in [false, true] {
            for fmt in [1, 2, 5] {
                let mut r = SplitMix64::new(seed ^ 0x9e37);
                let o = opts(&mut r, fmt, divide, false);
                let n = 64;
                let slow = 2f64.powi(-(r.below(12) as i32) - 4);
                let ray = BlockRay { o: [0.0, 0.0, 0.0], d: [0.0, 0.0, slow], tmin: 0.0, tmax: f64::INFINITY };
                let mut cols: [Vec<f64>; 9] = std::array::from_fn(|_| Vec::with_capacity(n));
                // alike triangles (the block's constants near each lane's own bounds) beside
                // the ray (it misses them), at a distance the slow ray takes long to reach
                let (far, size) = (r.range(10.0, 2000.0), r.range(0.05, 1.0));
                for _ in 0..n {
                    let c = [r.range(1.5, 2.0), r.range(-0.5, 0.5), far * r.range(0.99, 1.0)];
                    for p in 0..3 {
                        for a in 0..3 {
                            cols[3 * p + a].push(c[a] + size * r.range(-1.0, 1.0));
                        }
                    }
                }
                let (k, _, _) = same(o, ray, &cols).unwrap();
                certified += k;
                undecided += (0..n).filter(|&i| only_a_quotient_overflows(o, ray, &cols, i)).count();
            }
        }
    }
    assert!(undecided > 100, "only {undecided} lanes undecided by a quotient's overflow alone");
    assert!(certified > 100, "only {certified} lanes certified");
}

/// Whether lane `i` misses with every compared quantity clear of its per-test bound, the
/// per-test verdict undecided by the overflow flag alone (a quotient left the format's range).
fn only_a_quotient_overflows(o: BlockOpts, ray: BlockRay, cols: &[Vec<f64>; 9], i: usize) -> bool {
    let v = std::array::from_fn(|p| std::array::from_fn(|a| cols[3 * p + a][i]));
    let b = RtiBound::<f64>::new(o.em, o.div, ray.o, ray.d, v);
    let mut quiet = b;
    quiet.overflow = false;
    let (with, without) = (
        b.verdict(o.cull, o.det_threshold, ray.tmin, ray.tmax),
        quiet.verdict(o.cull, o.det_threshold, ray.tmin, ray.tmax),
    );
    b.overflow && !with.decisive && without.decisive && !without.hit
}

/// Blocks of 300 lanes, about half of them triangles the ray passes through or near (the per-test
/// bound decides those) and half far beside it (certified), in every error model: the lanes
/// left go through the per-test bound packed, several groups a block, and every lane still
/// gets its own verdict.
#[test]
fn half_certified_blocks_get_the_per_test_verdict() {
    let mut mixed = 0;
    for seed in 0..24u64 {
        for fmt in 0..6 {
            let mut r = SplitMix64::new(seed ^ 0x5a5a);
            let o = opts(&mut r, fmt, seed % 2 == 0, seed % 3 == 0);
            let n = 300;
            let ray = BlockRay { o: [0.1, -0.2, -3.0], d: [0.01, 0.02, 1.0], tmin: 0.0, tmax: f64::INFINITY };
            let mut cols: [Vec<f64>; 9] = std::array::from_fn(|_| Vec::with_capacity(n));
            for _ in 0..n {
                let near = r.below(2) == 0;
                let c =
                    if near { [0.1, -0.2, r.range(-1.0, 1.0)] } else { [r.range(-2.0, 2.0), r.range(-2.0, 2.0), 0.0] };
                let size = if near { r.range(0.001, 0.3) } else { 0.1 };
                for p in 0..3 {
                    for a in 0..3 {
                        cols[3 * p + a].push(c[a] + size * r.range(-1.0, 1.0));
                    }
                }
            }
            let (k, _, _) = same(o, ray, &cols).unwrap();
            mixed += (n / 4 <= k && n - k > n / 8 + 64) as usize;
        }
    }
    assert!(mixed > 20, "only {mixed} blocks took the packed path with more than one group");
}

/// `verdict_lanes_filtered` writes each lane not skipped with its per-test verdict (decisive and
/// hit always, the t bound where the filter did not certify it: +∞ there) and leaves every
/// skipped lane as it was, on edge blocks of up to 200 lanes (several groups) with random skips.
#[test]
fn lanes_filtered_write_exactly_the_lanes_not_skipped() {
    use datapath::bound_filter::verdict_lanes_filtered;
    let mut written = 0;
    for seed in 0..200u64 {
        let mut r = SplitMix64::new(seed ^ 0x1a9e);
        let o = opts(&mut r, (seed % 6) as usize, seed % 2 == 0, seed % 3 == 0);
        let n = r.below(200) as usize;
        let ray = BlockRay { o: [0.1, -0.2, -3.0], d: [0.01, 0.02, 1.0], tmin: 0.0, tmax: f64::INFINITY };
        let cols: [Vec<f64>; 9] =
            std::array::from_fn(|_| (0..n).map(|_| edge(&mut r, o.em.max, seed % 4 != 0)).collect());
        let c: [&[f64]; 9] = std::array::from_fn(|k| &cols[k][..]);
        let skip: Vec<bool> = (0..n).map(|_| r.below(3) == 0).collect();
        for k in kernels_here() {
            let (mut dec, mut hit, mut te) = (vec![false; n], vec![false; n], vec![0.0; n]);
            verdict_block(k, o, ray, c, &mut dec, &mut hit, &mut te);
            for pre in [None, set_constants(o, ray, &cols)] {
                let (mut fdec, mut fhit, mut fte) = (vec![true; n], vec![true; n], vec![-7.0; n]);
                verdict_lanes_filtered(k, o, ray, c, pre.as_ref(), &skip, &mut fdec, &mut fhit, &mut fte);
                for i in 0..n {
                    if skip[i] {
                        assert!(fdec[i] && fhit[i] && fte[i] == -7.0, "{k:?} seed {seed}: skipped lane {i} written");
                    } else {
                        assert_eq!((fdec[i], fhit[i]), (dec[i], hit[i]), "{k:?} seed {seed} lane {i}");
                        let same = fte[i].to_bits() == te[i].to_bits() || (fte[i].is_nan() && te[i].is_nan());
                        assert!(same || (fte[i] == f64::INFINITY && dec[i] && !hit[i]), "{k:?} seed {seed} lane {i}");
                        written += 1;
                    }
                }
            }
        }
    }
    assert!(written > 10_000, "only {written} lanes written");
}

/// `SetMaxima::for_ray` is no smaller, component by component, than `block_maxima` of any
/// block of the set's triangles (whole, single triangles, random subsets), and the NaN flag
/// clear, on sets of ordinary and edge values (±0, subnormals, powers of two, small integers,
/// values near binary64's largest, whose differences overflow) and origins among them (±∞
/// too); `None` exactly when a coordinate of the set is not finite or the set is empty.
#[test]
fn set_maxima_bound_every_block_of_the_set() {
    use datapath::bound_filter::block_maxima;
    let mut checked = 0;
    for seed in 0..600u64 {
        let mut r = SplitMix64::new(seed ^ 0x5e7);
        let n = r.below(40) as usize;
        let fin = seed % 5 != 0;
        let x = |r: &mut SplitMix64| match r.below(6) {
            0 => edge(r, 1e308, fin),
            1 => 1.7e308 * r.range(-1.0, 1.0),
            _ => r.range(-3.0, 3.0),
        };
        let tris: Vec<[f64; 9]> = (0..n).map(|_| std::array::from_fn(|_| x(&mut r))).collect();
        let o: [f64; 3] = std::array::from_fn(|_| match r.below(8) {
            0 => f64::INFINITY * r.range(-1.0, 1.0).signum(),
            1 => edge(&mut r, 1e308, true),
            _ => r.range(-5.0, 5.0),
        });
        let ray = BlockRay { o, d: [0.3, -0.2, 1.0], tmin: 0.0, tmax: f64::INFINITY };
        let m = SetMaxima::of(tris.iter().copied()).for_ray(ray);
        let finite = n > 0 && tris.iter().flatten().all(|v| v.is_finite());
        assert_eq!(m.is_some(), finite, "seed {seed}");
        let Some((ve, ae, big, nan)) = m else { continue };
        assert!(!nan);
        for t in 0..6 {
            let pick: Vec<usize> = match t {
                0 => (0..n).collect(),
                1 => vec![r.below(n as u64) as usize],
                _ => (0..n).filter(|_| r.below(2) == 0).collect(),
            };
            let cols: [Vec<f64>; 9] = std::array::from_fn(|k| pick.iter().map(|&i| tris[i][k]).collect());
            let (bv, ba, bb, bn) =
                block_maxima(datapath::simd::Kernel::Scalar, ray, std::array::from_fn(|k| &cols[k][..]));
            assert!(!bn, "seed {seed}");
            for k in 0..9 {
                assert!(bv[k] <= ve[k], "seed {seed} block {t}: |difference| {k}: {} > {}", bv[k], ve[k]);
                assert!(ba[k] <= ae[k], "seed {seed} block {t}: sum {k}: {} > {}", ba[k], ae[k]);
            }
            assert!(bb <= big, "seed {seed} block {t}");
            checked += 1;
        }
    }
    assert!(checked > 1500, "only {checked} blocks checked");
}
