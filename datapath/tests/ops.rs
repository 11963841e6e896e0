//! Per-operation verification of every number format against independent oracles:
//! `rustc_apfloat` (the Rust port of LLVM's APFloat: binary16, binary32, bfloat16 and custom
//! `eEmM` layouts through its `Semantics` trait), exact rationals (every float layout, fixed
//! point) and, with `--features softfloat` (its build needs cmake), Berkeley SoftFloat.
//! Cases are TestFloat-style: tables of special exponents and significand patterns, then seeded
//! random operands (uniform bits, near exponents for cancellation and ties, sparse significands).

mod oracle;

use datapath::format::{
    Bf16, DivMode, F16Half, F32Native, Fixed, FloatLayout, Format, FpOpts, FxOverflow, FxRound, Ieee, IeeeBackend,
    NanMode, Soft, Subnormals,
};
use datapath::rng::SplitMix64;
use num_rational::BigRational;
use oracle::{Fx, Op, OPS};
use rustc_apfloat::ieee::{BFloat, Half, IeeeFloat, Semantics, Single};
use rustc_apfloat::Round;

const SEED: u64 = 0x5eed_0001;

fn divide() -> FpOpts {
    FpOpts { div: DivMode::Divide, ..FpOpts::default() }
}

fn apply<F: Format>(f: &F, op: Op, a: F::V, b: F::V) -> F::V {
    match op {
        Op::Add => f.add(a, b),
        Op::Sub => f.sub(a, b),
        Op::Mul => f.mul(a, b),
        Op::Div => f.div(a, b),
    }
}

/// Level-1 operands: special exponents × significand patterns × signs.
fn specials(l: FloatLayout) -> Vec<u64> {
    let top = (1u64 << l.exp_bits) - 1;
    let bias = l.bias() as u64;
    let mut exps = vec![0, 1, 2, bias - 1, bias, bias + 1, top - 2, top - 1, top];
    exps.retain(|&e| e <= top);
    let mm = l.man_mask();
    let half = 1u64 << (l.man_bits - 1);
    let fracs = [0, 1, 2, half, half + 1, mm, mm - 1, 0x5555_5555_5555_5555 & mm, mm >> 1, (half >> 1) | 1];
    let mut v = Vec::new();
    for &e in &exps {
        for &f in &fracs {
            for s in [0, l.sign_mask()] {
                v.push(s | (e << l.man_bits) | (f & mm));
            }
        }
    }
    v.sort_unstable();
    v.dedup();
    v
}

/// Level-2 operands: seeded random pairs of three kinds.
fn random_pairs(l: FloatLayout, n: usize, seed: u64) -> Vec<(u64, u64)> {
    let mut r = SplitMix64::new(seed);
    let mask = (l.sign_mask() << 1).wrapping_sub(1);
    let mut v = Vec::with_capacity(3 * n);
    for _ in 0..n {
        v.push((r.next_u64() & mask, r.next_u64() & mask));
    }
    // near exponents: cancellation in +/-, half-ulp ties in +
    for _ in 0..n {
        let a = r.next_u64() & mask;
        let ea = ((a & l.exp_mask()) >> l.man_bits) as i64;
        let de = r.below(l.man_bits as u64 + 4) as i64 - 2;
        let eb = (ea - de).clamp(0, (1 << l.exp_bits) - 2) as u64;
        let b = (r.next_u64() & (l.sign_mask() | l.man_mask())) | (eb << l.man_bits);
        v.push((a, b));
    }
    // sparse significands: exact and halfway products and quotients
    for _ in 0..n {
        let mut sparse = || {
            let e = 1 + r.below((1 << l.exp_bits) - 2);
            let f = (1u64 << r.below(l.man_bits as u64))
                | (1u64 << r.below(l.man_bits as u64))
                | (r.below(2) * l.man_mask());
            ((r.below(2) * l.sign_mask()) | (e << l.man_bits) | (f & l.man_mask())) & mask
        };
        let (a, b) = (sparse(), sparse());
        v.push((a, b));
    }
    v
}

fn all_cases(l: FloatLayout, n: usize, seed: u64) -> Vec<(u64, u64)> {
    let sp = specials(l);
    let mut v: Vec<(u64, u64)> = sp.iter().flat_map(|&a| sp.iter().map(move |&b| (a, b))).collect();
    v.extend(random_pairs(l, n, seed));
    v
}

fn check_against_rationals<B: IeeeBackend>(f: &Ieee<B>, n: usize) {
    let l = f.backend.layout();
    let mut failures = Vec::new();
    for (a, b) in all_cases(l, n, SEED ^ l.width() as u64) {
        for op in OPS {
            let got = f.to_bits(apply(f, op, f.from_bits(a), f.from_bits(b)));
            let want = oracle::float_op(l, op, a, b);
            if got != want && failures.len() < 10 {
                failures.push(format!("{} {op:?} {a:#x} {b:#x}: got {got:#x} want {want:#x}", f.name()));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn custom_layouts_match_exact_rationals() {
    for (e, m) in [(8, 16), (5, 2), (4, 3), (2, 1), (6, 9), (5, 10), (8, 7), (8, 23), (11, 52), (3, 20)] {
        check_against_rationals(&Ieee::new(Soft(FloatLayout::new(e, m)), divide()), 3000);
    }
}

#[test]
fn bf16_matches_exact_rationals() {
    check_against_rationals(&Ieee::new(Bf16, divide()), 20000);
}

#[test]
fn fp16_and_f32_match_exact_rationals() {
    check_against_rationals(&Ieee::new(F16Half, divide()), 5000);
    check_against_rationals(&Ieee::new(F32Native, divide()), 5000);
}

/// One APFloat operation, nearest-even, on encodings.
fn ap_op<T: rustc_apfloat::Float>(op: Op, a: u64, b: u64) -> u64 {
    ap_op_in::<T>(Round::NearestTiesToEven, op, a, b)
}

/// One APFloat operation in rounding mode `r`, on encodings.
fn ap_op_in<T: rustc_apfloat::Float>(r: Round, op: Op, a: u64, b: u64) -> u64 {
    let (x, y) = (T::from_bits(a as u128), T::from_bits(b as u128));
    let v = match op {
        Op::Add => x.add_r(y, r),
        Op::Sub => x.sub_r(y, r),
        Op::Mul => x.mul_r(y, r),
        Op::Div => x.div_r(y, r),
    };
    v.value.to_bits() as u64
}

/// APFloat semantics for a custom `eEmM` layout (1 + E + M bits).
macro_rules! ap_layout {
    ($name:ident, $bits:literal, $exp:literal) => {
        struct $name;
        impl Semantics for $name {
            const BITS: usize = $bits;
            const EXP_BITS: usize = $exp;
        }
    };
}
ap_layout!(E8M16, 25, 8);
ap_layout!(E5M2, 8, 5);
ap_layout!(E6M9, 16, 6);
ap_layout!(E4M3, 8, 4);
ap_layout!(E3M20, 24, 3);

/// An independent oracle returns its own NaNs and payloads; ours is the canonical NaN: compare
/// NaN-ness and require the canonical encoding, otherwise compare bits.
fn check_against_oracle<B: IeeeBackend>(f: &Ieee<B>, oracle: fn(Op, u64, u64) -> u64, name: &str, n: usize) {
    let l = f.backend.layout();
    let mut failures = Vec::new();
    let mut count = 0u64;
    for (a, b) in all_cases(l, n, SEED ^ 0x5f) {
        for op in OPS {
            let got = f.to_bits(apply(f, op, f.from_bits(a), f.from_bits(b)));
            let want = oracle(op, a, b);
            let ok = if l.is_nan(want) { got == l.canonical_nan() } else { got == want };
            count += 1;
            if !ok && failures.len() < 10 {
                failures.push(format!("{} {op:?} {a:#x} {b:#x}: got {got:#x} {name} {want:#x}", f.name()));
            }
        }
    }
    assert!(count > 10_000, "{count} cases");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn fp16_matches_apfloat() {
    check_against_oracle(&Ieee::new(F16Half, divide()), ap_op::<Half>, "apfloat", 100_000);
}

#[test]
fn f32_matches_apfloat() {
    check_against_oracle(&Ieee::new(F32Native, divide()), ap_op::<Single>, "apfloat", 100_000);
}

#[test]
fn bf16_matches_apfloat() {
    check_against_oracle(&Ieee::new(Bf16, divide()), ap_op::<BFloat>, "apfloat", 50_000);
}

#[test]
fn custom_layouts_match_apfloat() {
    fn one<S: Semantics>(e: u32, m: u32) {
        assert_eq!(S::BITS as u32, 1 + e + m);
        check_against_oracle(
            &Ieee::new(Soft(FloatLayout::new(e, m)), divide()),
            ap_op::<IeeeFloat<S>>,
            "apfloat",
            10_000,
        );
    }
    one::<E8M16>(8, 16);
    one::<E5M2>(5, 2);
    one::<E6M9>(6, 9);
    one::<E4M3>(4, 3);
    one::<E3M20>(3, 20);
}

/// A mutated engine (ties rounded away from zero instead of to even) must fail the oracle
/// comparison: the check can fail.
#[test]
fn the_apfloat_check_catches_a_wrong_rounding() {
    fn away(op: Op, a: u64, b: u64) -> u64 {
        ap_op_in::<Half>(Round::NearestTiesToAway, op, a, b)
    }
    let f = Ieee::new(F16Half, divide());
    let r = std::panic::catch_unwind(|| check_against_oracle(&f, away, "ties-away", 20_000));
    assert!(r.is_err(), "ties-to-away was not told apart from ties-to-even");
}

#[cfg(feature = "softfloat")]
mod softfloat {
    use super::*;
    use softfloat_wrapper::{Float as _, RoundingMode, F16 as Sf16, F32 as Sf32};

    /// One SoftFloat operation, nearest-even.
    fn sf_apply<T: softfloat_wrapper::Float>(op: Op, x: T, y: T) -> T {
        let rm = RoundingMode::TiesToEven;
        match op {
            Op::Add => x.add(y, rm),
            Op::Sub => x.sub(y, rm),
            Op::Mul => x.mul(y, rm),
            Op::Div => x.div(y, rm),
        }
    }

    pub fn sf_op16(op: Op, a: u64, b: u64) -> u64 {
        sf_apply(op, Sf16::from_bits(a as u16), Sf16::from_bits(b as u16)).to_bits() as u64
    }

    fn sf_op32(op: Op, a: u64, b: u64) -> u64 {
        sf_apply(op, Sf32::from_bits(a as u32), Sf32::from_bits(b as u32)).to_bits() as u64
    }

    #[test]
    fn fp16_matches_softfloat() {
        check_against_oracle(&Ieee::new(F16Half, divide()), sf_op16, "softfloat", 100_000);
    }

    #[test]
    fn f32_matches_softfloat() {
        check_against_oracle(&Ieee::new(F32Native, divide()), sf_op32, "softfloat", 100_000);
    }

    /// All 2^32 binary16 operand pairs for + - × ÷ against SoftFloat. Run with
    /// `cargo test --release -p datapath --features softfloat --test ops -- --ignored exhaustive_fp16`.
    #[test]
    #[ignore = "long: every binary16 operand pair (see README for the measured duration)"]
    fn exhaustive_fp16_against_softfloat() {
        super::exhaustive_fp16(sf_op16, "softfloat");
    }
}

#[test]
fn native_backends_equal_the_soft_engine() {
    fn cmp<B: IeeeBackend>(f: Ieee<B>) {
        let s = Ieee::new(Soft(f.backend.layout()), f.opts);
        for (a, b) in all_cases(f.backend.layout(), 50_000, SEED ^ 0xab) {
            for op in OPS {
                let x = f.to_bits(apply(&f, op, f.from_bits(a), f.from_bits(b)));
                let y = s.to_bits(apply(&s, op, s.from_bits(a), s.from_bits(b)));
                assert_eq!(x, y, "{} {op:?} {a:#x} {b:#x}", f.name());
            }
        }
    }
    for opts in [
        divide(),
        FpOpts::default(),
        FpOpts { subnormals: Subnormals::Ftz, nan: NanMode::Propagate, div: DivMode::Divide },
    ] {
        cmp(Ieee::new(F32Native, opts));
        cmp(Ieee::new(F16Half, opts));
        cmp(Ieee::new(Bf16, opts));
    }
}

fn conversions<B: IeeeBackend>(f: &Ieee<B>) {
    let l = f.backend.layout();
    let mut r = SplitMix64::new(SEED ^ 0xc0);
    let mut xs: Vec<f64> =
        vec![0.0, -0.0, f64::INFINITY, f64::NEG_INFINITY, f64::MIN_POSITIVE, 5e-324, f64::MAX, 1.0, -1.0];
    for _ in 0..20_000 {
        // random f64 across and beyond the format's range
        let e = r.range(l.emin() as f64 - l.man_bits as f64 - 4.0, l.emax() as f64 + 3.0).floor() as i32;
        let x = r.range(1.0, 2.0) * 2f64.powi(e);
        xs.push(if r.below(2) == 0 { x } else { -x });
        // exact midpoints between neighbours (ties) and their neighbours in f64
        let b = r.next_u64() & (l.sign_mask() | l.exp_mask() | l.man_mask()) & !l.sign_mask();
        if !l.is_nan(b) && !l.is_inf(b) && !l.is_inf(b + 1) && l.man_bits < 52 {
            let mid = (l.to_f64(b) + l.to_f64(b + 1)) / 2.0;
            xs.extend([mid, -mid, f64::from_bits(mid.to_bits() + 1), f64::from_bits(mid.to_bits() - 1)]);
        }
    }
    for x in xs {
        let got = f.to_bits(f.from_f64(x));
        let want = oracle::float_from_f64(l, x);
        assert_eq!(got, want, "{} from_f64({x:e})", f.name());
        if !l.is_nan(got) && !l.is_inf(got) {
            let back = f.to_f64(f.from_bits(got));
            assert_eq!(BigRational::from_float(back).unwrap(), oracle::exact(l, got), "{} to_f64({got:#x})", f.name());
        }
    }
}

#[test]
fn f64_conversion_is_correctly_rounded_and_back_exact() {
    conversions(&Ieee::new(F32Native, divide()));
    conversions(&Ieee::new(F16Half, divide()));
    conversions(&Ieee::new(Bf16, divide()));
    for (e, m) in [(8, 16), (5, 2), (6, 9), (11, 52)] {
        conversions(&Ieee::new(Soft(FloatLayout::new(e, m)), divide()));
    }
}

/// `to_f64_column` of `vals` equals `to_f64` of each value, bit for bit (NaN payloads too),
/// at every length up to 40 and at the full length (the vector loops' remainders).
fn column_is_elementwise<F: Format>(f: &F, vals: &[F::V]) {
    let want: Vec<u64> = vals.iter().map(|&v| f.to_f64(v).to_bits()).collect();
    for n in (0..=40.min(vals.len())).chain([vals.len()]) {
        let mut got = vec![f64::NAN; n];
        f.to_f64_column(&vals[..n], &mut got);
        for (k, (g, w)) in got.iter().zip(&want).enumerate() {
            assert_eq!(g.to_bits(), *w, "{} to_f64_column lane {k} of {n}: {:#x}", f.name(), f.to_bits(vals[k]));
        }
    }
}

#[test]
fn column_conversion_equals_the_element_conversion() {
    // every encoding of the 16-bit formats (NaNs, subnormals, ±0, ±∞ included)
    let fp16 = Ieee::new(F16Half, divide());
    column_is_elementwise(&fp16, &(0..=u16::MAX).map(|b| fp16.from_bits(b as u64)).collect::<Vec<_>>());
    let bf16 = Ieee::new(Bf16, divide());
    column_is_elementwise(&bf16, &(0..=u16::MAX).map(|b| bf16.from_bits(b as u64)).collect::<Vec<_>>());
    // the binary32 specials and random encodings, a custom layout, fixed point
    let f32f = Ieee::new(F32Native, divide());
    let mut r = SplitMix64::new(SEED ^ 0xc01);
    let bits32: Vec<u64> =
        specials(FloatLayout::BINARY32).into_iter().chain((0..20_000).map(|_| r.next_u64() & 0xffff_ffff)).collect();
    column_is_elementwise(&f32f, &bits32.iter().map(|&b| f32f.from_bits(b)).collect::<Vec<_>>());
    let e8m16 = Ieee::new(Soft(FloatLayout::new(8, 16)), divide());
    let bits: Vec<u64> = (0..20_000).map(|_| r.next_u64() & 0x1ff_ffff).collect();
    column_is_elementwise(&e8m16, &bits.iter().map(|&b| e8m16.from_bits(b)).collect::<Vec<_>>());
    // fixed point of several widths (up to 52 bits the conversion without AVX-512DQ; 53 and 64
    // the one with it, or value by value): random encodings, the extremes, 0 and ±1 ulp
    for (i, fr) in [(8, 24), (1, 15), (16, 16), (1, 31), (26, 26), (27, 26), (32, 32)] {
        let q = Fixed::new(i, fr, FxRound::NearestEven, FxOverflow::Saturate, DivMode::Divide).unwrap();
        let w = i + fr;
        let top = 1u64 << (w - 1);
        let edges = [0, 1, top - 1, top, top + 1, (top << 1).wrapping_sub(1)];
        let vals: Vec<i64> = (0..20_000).map(|_| r.next_u64()).chain(edges).map(|b| q.from_bits(b)).collect();
        column_is_elementwise(&q, &vals);
        // the hint: up to 52 bits a fixed-point column converts at vector speed on AVX2
        #[cfg(target_arch = "x86_64")]
        if w <= 52 && std::arch::is_x86_feature_detected!("avx2") {
            assert!(q.fast_f64_column(), "q{i}.{fr}");
        }
    }
    // the hint: the host's binary32, binary16 and bfloat16 convert at vector speed
    assert!(f32f.fast_f64_column() && fp16.fast_f64_column() && bf16.fast_f64_column());
}

#[test]
fn half_crate_from_f64_is_not_correctly_rounded_but_ours_is() {
    // 1 + 2^-11 + 2^-40 lies just above the midpoint between 1 and 1 + 2^-10: it must round up.
    // Through f32 the 2^-40 is lost and the tie goes to even (1.0): a double-rounding error.
    let x = 1.0 + 2f64.powi(-11) + 2f64.powi(-40);
    let f = Ieee::new(F16Half, FpOpts::default());
    assert_eq!(f.to_bits(f.from_f64(x)), 0x3c01);
    assert_eq!(half::f16::from_f32(x as f32).to_bits(), 0x3c00);
}

#[test]
fn flush_to_zero_flushes_operands_and_results() {
    fn ftz<B: IeeeBackend>(b: B) {
        let f = Ieee::new(b, FpOpts { subnormals: Subnormals::Ftz, ..divide() });
        let l = b.layout();
        for (a, c) in all_cases(l, 5000, SEED ^ 0xf7) {
            for op in OPS {
                let got = f.to_bits(apply(&f, op, f.from_bits(a), f.from_bits(c)));
                let want = oracle::flush(l, oracle::float_op(l, op, oracle::flush(l, a), oracle::flush(l, c)));
                assert_eq!(got, want, "{} {op:?} {a:#x} {c:#x}", f.name());
            }
        }
        // input conversion flushes too
        assert_eq!(f.to_bits(f.from_f64(l.min_normal() / 2.0)), 0);
        assert_eq!(f.to_bits(f.from_f64(-l.min_normal() / 2.0)), l.sign_mask());
    }
    ftz(F32Native);
    ftz(F16Half);
    ftz(Bf16);
    ftz(Soft(FloatLayout::new(8, 16)));
}

#[test]
fn nan_rules_canonical_and_propagate() {
    fn nan<B: IeeeBackend>(b: B) {
        let l = b.layout();
        let canon = Ieee::new(b, divide());
        let prop = Ieee::new(b, FpOpts { nan: NanMode::Propagate, ..divide() });
        let snan = l.exp_mask() | 1; // signalling, payload 1
        let neg_qnan = l.sign_mask() | l.exp_mask() | (1 << (l.man_bits - 1)) | 1;
        let one = l.from_f64(1.0);
        let inf = l.inf(false);
        for op in OPS {
            for (a, c) in [(snan, one), (one, snan), (neg_qnan, snan), (snan, neg_qnan)] {
                let got = canon.to_bits(apply(&canon, op, canon.from_bits(a), canon.from_bits(c)));
                assert_eq!(got, l.canonical_nan(), "{} {op:?}", canon.name());
                let first = if l.is_nan(a) { a } else { c };
                let got = prop.to_bits(apply(&prop, op, prop.from_bits(a), prop.from_bits(c)));
                assert_eq!(got, l.quiet(first), "{} {op:?} {a:#x} {c:#x}", prop.name());
            }
        }
        // invalid operations make the canonical NaN in both modes
        for f in [&canon, &prop] {
            assert_eq!(f.to_bits(f.sub(f.from_bits(inf), f.from_bits(inf))), l.canonical_nan());
            assert_eq!(f.to_bits(f.mul(f.from_bits(inf), f.zero())), l.canonical_nan());
            assert_eq!(f.to_bits(f.div(f.zero(), f.zero())), l.canonical_nan());
        }
    }
    nan(F32Native);
    nan(F16Half);
    nan(Bf16);
    nan(Soft(FloatLayout::new(8, 16)));
}

#[test]
fn recip_mul_division_is_reciprocal_then_multiply() {
    fn rm<B: IeeeBackend>(b: B) {
        let l = b.layout();
        let f = Ieee::new(b, FpOpts::default());
        let one = l.from_f64(1.0);
        let mut differs = 0;
        for (a, c) in all_cases(l, 5000, SEED ^ 0xd1) {
            let got = f.to_bits(f.div(f.from_bits(a), f.from_bits(c)));
            let recip = oracle::float_op(l, Op::Div, one, c);
            let want = oracle::float_op(l, Op::Mul, a, recip);
            assert_eq!(got, want, "{} {a:#x} / {c:#x}", f.name());
            differs += (want != oracle::float_op(l, Op::Div, a, c)) as u32;
        }
        assert!(differs > 0, "recip-mul never differed from a true divide: the test cannot tell them apart");
    }
    rm(F32Native);
    rm(F16Half);
    rm(Soft(FloatLayout::new(8, 16)));
}

fn fixed_formats() -> Vec<Fixed> {
    let mut v = Vec::new();
    for (i, f) in [(8, 24), (16, 16), (1, 15), (4, 4), (33, 31), (2, 62), (64, 0), (1, 1)] {
        for round in [FxRound::Floor, FxRound::Ceil, FxRound::Trunc, FxRound::NearestEven] {
            for overflow in [FxOverflow::Saturate, FxOverflow::Wrap] {
                v.push(Fixed::new(i, f, round, overflow, DivMode::Divide).unwrap());
            }
        }
    }
    v
}

#[test]
fn fixed_point_ops_match_exact_rationals() {
    let mut r = SplitMix64::new(SEED ^ 0xf1);
    for f in fixed_formats() {
        let o = Fx { i: f.int_bits, f: f.frac_bits, round: f.round, overflow: f.overflow };
        let (max, min) = (f.max_raw(), f.min_raw());
        let one = 1i64.checked_shl(f.frac_bits).filter(|&x| x <= max).unwrap_or(max);
        // 1.5, or the largest value when it does not fit (no overflow in a debug build)
        let one_and_half = (one as i128 * 3 / 2).min(max as i128) as i64;
        let mut vals =
            vec![0, 1, -1, 2, -2, max, min, max - 1, min + 1, one, -one, one / 2, -one / 2, one / 2 + 1, one_and_half];
        for _ in 0..40 {
            vals.push(f.from_bits(r.next_u64()));
            vals.push(f.from_bits(r.next_u64() >> r.below(64)));
        }
        for &a in &vals {
            for &b in &vals {
                for op in OPS {
                    let got = apply(&f, op, a, b);
                    let want = o.op(op, a, b);
                    assert_eq!(got, want, "{} {op:?} {a} {b}", f.name());
                }
            }
        }
        for _ in 0..2000 {
            let x = r.range(-1.5, 1.5)
                * 2f64.powi(f.int_bits as i32 + 1 - r.below(f.int_bits as u64 + f.frac_bits as u64 + 4) as i32);
            let want = o.round(&BigRational::from_float(x).unwrap());
            assert_eq!(f.from_f64(x), want, "{} from_f64({x:e})", f.name());
        }
        assert_eq!(f.from_f64(f64::INFINITY), max);
        assert_eq!(f.from_f64(f64::NEG_INFINITY), min);
        assert_eq!(f.from_bits(f.to_bits(min)), min);
    }
}

#[test]
fn fixed_recip_mul_is_reciprocal_then_multiply() {
    let f = Fixed::new(8, 24, FxRound::NearestEven, FxOverflow::Saturate, DivMode::RecipMul).unwrap();
    let exact = Fixed { div: DivMode::Divide, ..f };
    let mut r = SplitMix64::new(SEED ^ 0xf2);
    for _ in 0..10_000 {
        let (a, b) = (f.from_bits(r.next_u64() >> 4), f.from_bits(r.next_u64() >> 8));
        assert_eq!(f.div(a, b), exact.mul(a, exact.div(f.one(), b)));
    }
}

/// All 2^32 binary16 operand pairs for + - × ÷ against APFloat. Run with
/// `cargo test --release -p datapath --test ops -- --ignored exhaustive_fp16`.
#[test]
#[ignore = "long: every binary16 operand pair (see README for the measured duration)"]
fn exhaustive_fp16_against_apfloat() {
    exhaustive_fp16(ap_op::<Half>, "apfloat");
}

fn exhaustive_fp16(oracle: fn(Op, u64, u64) -> u64, name: &str) {
    let f = Ieee::new(F16Half, divide());
    let l = FloatLayout::BINARY16;
    let threads = std::thread::available_parallelism().map_or(2, |n| n.get());
    let start = std::time::Instant::now();
    let bad: u64 = std::thread::scope(|s| {
        let hs: Vec<_> = (0..threads)
            .map(|t| {
                s.spawn(move || {
                    let mut bad = 0u64;
                    for a in (t as u64..65536).step_by(threads) {
                        for b in 0..65536u64 {
                            for op in OPS {
                                let got = f.to_bits(apply(&f, op, f.from_bits(a), f.from_bits(b)));
                                let want = oracle(op, a, b);
                                let ok = if l.is_nan(want) { got == l.canonical_nan() } else { got == want };
                                if !ok {
                                    if bad < 5 {
                                        eprintln!("{op:?} {a:#06x} {b:#06x}: got {got:#06x} {name} {want:#06x}");
                                    }
                                    bad += 1;
                                }
                            }
                        }
                    }
                    bad
                })
            })
            .collect();
        hs.into_iter().map(|h| h.join().unwrap()).sum()
    });
    eprintln!(
        "exhaustive fp16 against {name}: 4 x 2^32 ops on {threads} threads in {:.1} s, {bad} mismatches",
        start.elapsed().as_secs_f64()
    );
    assert_eq!(bad, 0);
}
