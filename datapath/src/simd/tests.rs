use super::isa::{self, v4d, v8d};
use crate::format::{Ieee, Soft};
use crate::Format;

/// The range filter of both binary64-lane ISAs passes a vector exactly when, on every lane,
/// every one of the twelve values is ±0 or a magnitude in [`fast_lo`, `fast_hi`] (the
/// predicate of `datapath::format::narrow`, written here per value) and, on AVX2, the sum of
/// the twelve magnitudes is at most `fast_hi` too: NaNs, infinities, zeros, the limits and
/// their neighbours, one odd value in one lane among ordinary ones.
#[test]
fn the_range_filter_is_the_documented_predicate() {
    use crate::rng::SplitMix64;
    use std::arch::is_x86_feature_detected as has;
    for name in ["e8m16", "e10m24", "e8m7", "e6m9"] {
        let crate::AnyFormat::Soft(f) = name.parse::<crate::AnyFormat>().unwrap() else { unreachable!() };
        let n = super::select::narrow_of(&f).unwrap();
        let (lo, hi) = (n.fast_lo, n.fast_hi);
        let odd = [
            f64::NAN,
            -f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            0.0,
            -0.0,
            lo,
            -lo,
            hi,
            -hi,
            lo * (1.0 - f64::EPSILON / 2.0),
            -lo * (1.0 - f64::EPSILON / 2.0),
            hi * (1.0 + f64::EPSILON),
            -hi * (1.0 + f64::EPSILON),
            lo / 2.0,
            hi * 2.0,
            f64::MIN_POSITIVE,
            f64::MAX,
        ];
        let ordinary = (lo * hi).sqrt();
        let pass = |x: f64| !x.is_nan() && x.abs() <= hi && (x == 0.0 || x.abs() >= lo);
        let mut r = SplitMix64::new(0xf11);
        for round in 0..4000 {
            // every value ordinary, then one to three odd values at random places
            let mut v = [[ordinary; 8]; 12];
            for _ in 0..round % 4 {
                v[r.below(12) as usize][r.below(8) as usize] = odd[r.below(odd.len() as u64) as usize];
            }
            let want = v.iter().flatten().all(|&x| pass(x));
            if has!("avx2") && has!("fma") {
                for half in 0..2 {
                    let w: [std::arch::x86_64::__m256d; 12] = std::array::from_fn(|k| {
                        let l = &v[k][4 * half..4 * half + 4];
                        // SAFETY: the features were detected.
                        unsafe { std::mem::transmute::<[f64; 4], _>([l[0], l[1], l[2], l[3]]) }
                    });
                    // AVX2 checks the sum of the magnitudes against fast_hi (stricter)
                    let want = (4 * half..4 * half + 4)
                        .all(|j| v.iter().all(|l| pass(l[j])) && v.iter().map(|l| l[j].abs()).sum::<f64>() <= hi);
                    // SAFETY: the features were detected.
                    assert_eq!(unsafe { v4d::fast_ok(&w, &n) }, want, "{name} v4d {v:?}");
                }
            }
            if has!("avx512f") && has!("avx512dq") {
                // SAFETY: the features were detected.
                let w: [std::arch::x86_64::__m512d; 12] =
                    std::array::from_fn(|k| unsafe { std::mem::transmute::<[f64; 8], _>(v[k]) });
                // SAFETY: the features were detected.
                assert_eq!(unsafe { v8d::fast_ok(&w, &n) }, want, "{name} v8d {v:?}");
            }
        }
    }
}

/// The lanes' grid step equals the model's `next_up` on every encoding of small formats
/// (subnormals, ±0, ±max, ±∞ dense), on every binary64-lane ISA here, and `k` steps at once
/// (`next_up_soft_n`, k = 1, 2, 4, 5, 64; binary32's key for `e8mM`) the model's `next_up`
/// taken k times. (Under FTZ the step goes through `slab_ftz!`, held to the model by the slab
/// proptests in `:ftz`.)
#[test]
fn next_up_in_binary64_lanes_equals_the_model_on_every_encoding() {
    use std::arch::is_x86_feature_detected as has;
    for name in ["e5m4", "e4m3", "e3m2", "e2m1", "e8m7", "e8m2", "e5m10", "e6m9"] {
        let crate::AnyFormat::Soft(f) = name.parse::<crate::AnyFormat>().unwrap() else { unreachable!() };
        let f: Ieee<Soft> = f;
        let n = super::select::narrow_of(&f).unwrap();
        let lay = n.lay;
        let vals: Vec<u64> = (0..1u64 << lay.width()).filter(|&b| !lay.is_nan(b)).collect();
        for k in [1u32, 2, 4, 5, 64] {
            for &b in &vals {
                let want = f.to_f64((0..k).fold(f.from_bits(b), |v, _| f.next_up(v)));
                let x = f.to_f64(f.from_bits(b));
                let mut got = Vec::new();
                if has!("avx2") && has!("fma") {
                    // SAFETY: the features were detected.
                    let (one, many) = unsafe {
                        let one = (0..k).fold(v4d::splat(x), |v, _| v4d::next_up_soft(v, &n));
                        let t = |v| std::mem::transmute::<std::arch::x86_64::__m256d, [f64; 4]>(v);
                        (t(one), t(v4d::next_up_soft_n(v4d::splat(x), k, &n)))
                    };
                    got.extend([("v4d one step", one[0]), ("v4d k steps", many[3])]);
                }
                if has!("avx512f") {
                    // SAFETY: the feature was detected.
                    let (one, many) = unsafe {
                        let one = (0..k).fold(v8d::splat(x), |v, _| v8d::next_up_soft(v, &n));
                        let t = |v| std::mem::transmute::<std::arch::x86_64::__m512d, [f64; 8]>(v);
                        (t(one), t(v8d::next_up_soft_n(v8d::splat(x), k, &n)))
                    };
                    got.extend([("v8d one step", one[0]), ("v8d k steps", many[7])]);
                }
                for (what, g) in got {
                    assert_eq!(
                        g.to_bits(),
                        want.to_bits(),
                        "{name} {what}, k {k}: from {x:e} to {g:e}, the model {want:e}"
                    );
                }
            }
        }
    }
}

/// `isa::v8r::round16_lanes` equals the F16C round trip (`vcvtps2ph` nearest-even, then
/// `vcvtph2ps`) on every binary32 encoding: the same bits, or NaN for NaN.
#[test]
fn round16_in_lanes_equals_the_conversion_on_every_binary32() {
    use std::arch::is_x86_feature_detected as has;
    use std::arch::x86_64::*;
    if !(has!("avx2") && has!("f16c")) {
        return;
    }
    #[target_feature(enable = "avx2,f16c")]
    fn sweep(from: u32, to: u32) -> Option<(u32, u32, u32)> {
        let mut b = from;
        while b < to {
            let x = _mm256_castsi256_ps(_mm256_add_epi32(
                _mm256_set1_epi32(b as i32),
                _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7),
            ));
            let got: [u32; 8] = unsafe { std::mem::transmute(isa::v8r::round16_lanes(x)) };
            let want: [u32; 8] = unsafe { std::mem::transmute(isa::v8::round16(x)) };
            for k in 0..8 {
                let nan = |v: u32| v & 0x7fff_ffff > 0x7f80_0000;
                if got[k] != want[k] && !(nan(got[k]) && nan(want[k])) {
                    return Some((b + k as u32, got[k], want[k]));
                }
            }
            b = b.wrapping_add(8);
            if b == 0 {
                break;
            }
        }
        None
    }
    // every encoding, in two halves (the sign) of 2^31
    for (from, to) in [(0u32, 0x8000_0000u32), (0x8000_0000, u32::MAX)] {
        // SAFETY: the features were detected.
        let bad = unsafe { sweep(from, to) };
        assert_eq!(bad, None, "(input, lanes, conversion)");
    }
}

/// The binary32-lane grid steps — one step ([`isa::v8::next_up`], [`isa::v16::next_up`] and
/// their bf16-grid forms) and `n` steps at once (`next_up_n`, `next_up_bf16_n`, n = 1 … 6, 64,
/// 65, the widening of the conservative slab variants) — equal the model's `next_up` taken
/// n times, on every bf16 encoding and on binary32 encodings dense around ±0, the
/// subnormal/normal boundary, powers of two, ±max, ±∞ and NaNs, plus random ones: the same
/// bits, or NaN for NaN.
#[test]
fn binary32_lane_steps_equal_the_model_n_times() {
    use crate::rng::SplitMix64;
    use std::arch::is_x86_feature_detected as has;
    use std::arch::x86_64::*;
    let crate::AnyFormat::F32(f32m) = "f32".parse::<crate::AnyFormat>().unwrap() else { unreachable!() };
    let crate::AnyFormat::Bf16(bf) = "bf16".parse::<crate::AnyFormat>().unwrap() else { unreachable!() };
    let mut enc: Vec<u32> = Vec::new();
    for centre in [0u32, 0x0080_0000, 0x3f80_0000, 0x4000_0000, 0x7f7f_ff00, 0x7f80_0000, 0x7fc0_0000] {
        for sign in [0, 0x8000_0000u32] {
            for k in 0..600u32 {
                enc.push((centre | sign).wrapping_add(k).wrapping_sub(300));
            }
        }
    }
    let mut r = SplitMix64::new(5);
    enc.extend((0..20_000).map(|_| r.next_u64() as u32));
    let bfe: Vec<u32> = (0..1u32 << 16).map(|b| b << 16).collect();
    let same = |g: f32, w: f32| g.to_bits() == w.to_bits() || (g.is_nan() && w.is_nan());
    for (grid, encs) in [(1u32, &enc), (16, &bfe)] {
        let model = |b: u32, n: u32| -> f32 {
            if grid == 1 {
                (0..n).fold(f32::from_bits(b), |v, _| f32m.next_up(v))
            } else {
                f32::from_bits(((0..n).fold((b >> 16) as u16, |v, _| bf.next_up(v)) as u32) << 16)
            }
        };
        for n in [1u32, 2, 3, 4, 5, 6, 64, 65] {
            for lanes in encs.chunks(16) {
                let mut x = [0.0f32; 16];
                for (k, &b) in lanes.iter().enumerate() {
                    x[k] = f32::from_bits(b);
                }
                let want: Vec<f32> = x.iter().map(|v| model(v.to_bits(), n)).collect();
                let mut got: Vec<(&str, [f32; 16])> = Vec::new();
                if has!("avx2") {
                    // SAFETY: AVX2 was detected; [f32; 8] and __m256 have the same size
                    let run = |h: [f32; 8]| unsafe {
                        let v = std::mem::transmute::<[f32; 8], __m256>(h);
                        let (one, many) = if grid == 1 {
                            (isa::v8::next_up(v), isa::v8::next_up_n(v, n))
                        } else {
                            (isa::v8::next_up_bf16(v), isa::v8::next_up_bf16_n(v, n))
                        };
                        let one =
                            (1..n).fold(
                                one,
                                |v, _| if grid == 1 { isa::v8::next_up(v) } else { isa::v8::next_up_bf16(v) },
                            );
                        (std::mem::transmute::<__m256, [f32; 8]>(one), std::mem::transmute::<__m256, [f32; 8]>(many))
                    };
                    let (a, b) = (run(x[..8].try_into().unwrap()), run(x[8..].try_into().unwrap()));
                    got.push(("v8 one step", std::array::from_fn(|k| if k < 8 { a.0[k] } else { b.0[k - 8] })));
                    got.push(("v8 n steps", std::array::from_fn(|k| if k < 8 { a.1[k] } else { b.1[k - 8] })));
                }
                if has!("avx512f") {
                    // SAFETY: AVX-512F was detected; [f32; 16] and __m512 have the same size
                    let (one, many) = unsafe {
                        let v = std::mem::transmute::<[f32; 16], __m512>(x);
                        let step = |v| if grid == 1 { isa::v16::next_up(v) } else { isa::v16::next_up_bf16(v) };
                        let many = if grid == 1 { isa::v16::next_up_n(v, n) } else { isa::v16::next_up_bf16_n(v, n) };
                        ((0..n).fold(v, |v, _| step(v)), many)
                    };
                    // SAFETY: as above
                    got.push(("v16 one step", unsafe { std::mem::transmute::<__m512, [f32; 16]>(one) }));
                    // SAFETY: as above
                    got.push(("v16 n steps", unsafe { std::mem::transmute::<__m512, [f32; 16]>(many) }));
                }
                for (what, g) in got {
                    for k in 0..lanes.len() {
                        assert!(
                            same(g[k], want[k]),
                            "{what}, grid {grid}, n {n}: {:#x} -> {:#x}, the model {:#x}",
                            x[k].to_bits(),
                            g[k].to_bits(),
                            want[k].to_bits()
                        );
                    }
                }
            }
        }
    }
}
