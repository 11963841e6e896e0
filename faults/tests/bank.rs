//! The fault bank and its injector: the names, the exactness of the rounding faults against an
//! independent computation, the benign argument, and the campaign's verdicts.

use datapath::fault::{Cmp, Fault, Logic, NoFault};
use datapath::format::{F32Native, FpOpts, Ieee};
use datapath::probe::NoProbe;
use datapath::rng::SplitMix64;
use datapath::rti::{Op, Ray, Rti, RtiConfig, Tri};
use datapath::slab::{Aabb, Slab, SlabConfig};
use datapath::Format;
use faults::bank::{by_name, Kind, BANK};
use faults::inject::Injected;
use proptest::prelude::*;

fn f32f() -> Ieee<F32Native> {
    Ieee::new(F32Native, FpOpts::default())
}

#[test]
fn every_fault_has_a_unique_name_a_site_and_a_description() {
    let mut names: Vec<&str> = BANK.iter().map(|s| s.name).collect();
    names.sort_unstable();
    names.dedup();
    assert_eq!(names.len(), BANK.len(), "duplicate fault names");
    for s in BANK {
        assert!(s.name.starts_with(&format!("{}.{}.", s.unit, s.site)), "{}: name is unit.site.kind", s.name);
        assert!(!s.what.is_empty());
    }
    // at least 40 faults over every unit, each unit with its own
    assert!(BANK.len() >= 89);
    for (unit, n) in [("rti", 34), ("slab", 27), ("capture", 6), ("traverse", 8), ("op", 14)] {
        assert_eq!(BANK.iter().filter(|s| s.unit == unit).count(), n, "{unit}");
    }
}

/// Slab outputs (hit, t_near bits, t_far bits) of one test with fault `x`.
fn slab_out<F: Format, X: Fault<F>>(s: &Slab<F>, v: &[f64; 14], x: &X) -> (bool, u64, u64) {
    let f = &s.fmt;
    let q = |i: usize| f.from_f64(v[i]);
    let ray = s.prepare_faulty([q(0), q(1), q(2)], [q(3), q(4), q(5)], q(6), q(7), &mut NoProbe, x);
    let b = Aabb { min: [q(8), q(9), q(10)], max: [q(11), q(12), q(13)] };
    let o = s.trace_faulty(&ray, &b, &mut NoProbe, x);
    (o.hit, f.to_bits(o.t_near), f.to_bits(o.t_far))
}

/// A slab input of random values in [-2, 2] with one in four an edge value (zeros of both
/// signs, ±1, ±inf, NaN, subnormal, huge), origins sometimes on a face plane.
fn slab_input(r: &mut SplitMix64) -> [f64; 14] {
    let edge = [0.0f64, -0.0, 1.0, -1.0, f64::INFINITY, f64::NEG_INFINITY, f64::NAN, 1e-40, -3e38, 6e-39];
    let val = |r: &mut SplitMix64| if r.below(4) == 0 { edge[r.below(10) as usize] } else { r.range(-2.0, 2.0) };
    let mut v: [f64; 14] = std::array::from_fn(|_| val(r));
    for a in 0..3 {
        if v[8 + a] > v[11 + a] {
            v.swap(8 + a, 11 + a);
        }
        match r.below(4) {
            0 => v[a] = v[8 + a],
            1 => v[a] = v[11 + a],
            _ => {}
        }
    }
    v
}

/// The value of `a × b` in binary32 rounded toward zero, from the exact binary64 product.
fn mul_rz(a: f32, b: f32) -> f32 {
    let p = a as f64 * b as f64; // exact: 24 + 24 bits
    let r = p as f32;
    if (r as f64).abs() > p.abs() && r.is_finite() || r.is_infinite() && p.is_finite() {
        f32::from_bits(r.to_bits() - 1)
    } else {
        r
    }
}

proptest! {
    /// The truncating multiplier fault equals truncation computed independently.
    #[test]
    fn the_truncating_multiplier_is_exact(a in -1e30f32..1e30, b in -1e-5f32..1e5) {
        let f = f32f();
        let x = Injected::new(by_name("rti.pxa.rz").unwrap());
        let got = Fault::arith(&x, &f, "pxa", Op::Mul, a, b);
        let want = mul_rz(a, b);
        prop_assert_eq!(got.to_bits(), want.to_bits(), "{} × {}", a, b);
        // every other site is the fault-free datapath
        prop_assert_eq!(Fault::arith(&x, &f, "pxb", Op::Mul, a, b).to_bits(), (a * b).to_bits());
        prop_assert!(x.reached() && !x.unmodelled());
    }

    /// The one benign fault leaves the outputs alone on random and edge inputs.
    #[test]
    fn the_benign_fault_changes_no_output(seed in any::<u64>()) {
        let f = f32f();
        let mut r = SplitMix64::new(seed);
        let edge = [0.0f64, -0.0, 1.0, -1.0, f64::INFINITY, f64::NAN, 1e-40, 3e38];
        let mut val = || if r.below(4) == 0 { edge[r.below(8) as usize] } else { r.range(-2.0, 2.0) };
        let spec = by_name("rti.pos.loose").unwrap();
        prop_assert!(spec.benign.is_some());
        for thr in [0.0, 1e-6] {
            let rti = Rti::new(f, RtiConfig { det_threshold: thr, ..RtiConfig::default() });
            for _ in 0..64 {
                let ray = Ray { o: [val(), val(), val()].map(|v| f.from_f64(v)), d: [val(), val(), val()].map(|v| f.from_f64(v)), tmin: f.zero(), tmax: f.from_f64(f64::INFINITY) };
                let tri = Tri { v: [[val(), val(), val()], [val(), val(), val()], [val(), val(), val()]].map(|p| p.map(|v| f.from_f64(v))) };
                let x = Injected::new(spec);
                let (a, b) = (rti.trace_faulty(&ray, &tri, &mut datapath::probe::NoProbe, &NoFault), rti.trace_faulty(&ray, &tri, &mut datapath::probe::NoProbe, &x));
                prop_assert_eq!((a.valid, a.hit, a.t.to_bits(), a.u.to_bits(), a.v.to_bits()), (b.valid, b.hit, b.t.to_bits(), b.u.to_bits(), b.v.to_bits()));
            }
        }
    }
}

#[test]
fn compare_faults_change_only_their_site() {
    let f = f32f();
    let strict = Injected::new(by_name("rti.u_ok.strict").unwrap());
    assert!(!Fault::compare(&strict, &f, "u_ok", Cmp::Le, 0.0f32, 0.0));
    assert!(Fault::compare(&strict, &f, "v_ok", Cmp::Le, 0.0f32, 0.0));
    let stuck = Injected::new(by_name("rti.t_ok.stuck1").unwrap());
    assert!(Fault::compare(&stuck, &f, "t_ok", Cmp::Le, 1.0f32, 0.0));
    assert!(matches!(by_name("rti.det_xy.fma").unwrap().kind, Kind::Fused { product: "detx", first: true }));
}

#[test]
fn the_fused_adder_rounds_once() {
    // det_xy = fma(e1x, px, dety): with e1x·px = 1 + 2^-21 + 3·2^-46 (not a binary32 value)
    // and dety = -1, the fused result keeps 2^-21 + 2^-44 (3·2^-46 rounded), the unfused one
    // 2^-21
    let f = f32f();
    let x = Injected::new(by_name("rti.det_xy.fma").unwrap());
    let (a, b) = (1.0f32 + f32::EPSILON, 1.0f32 + 3.0 * f32::EPSILON);
    let detx = Fault::arith(&x, &f, "detx", Op::Mul, a, b);
    let got = Fault::arith(&x, &f, "det_xy", Op::Add, detx, -1.0f32);
    let exact = (a as f64 * b as f64 - 1.0) as f32;
    assert_eq!(got.to_bits(), exact.to_bits());
    assert_ne!(got.to_bits(), (detx - 1.0).to_bits());
}

#[test]
fn faults_outside_the_exact_formats_say_so() {
    let f: datapath::format::Fixed = "q8.24"
        .parse::<datapath::AnyFormat>()
        .map(|a| match a {
            datapath::AnyFormat::Fixed(f) => f,
            _ => unreachable!(),
        })
        .unwrap();
    let x = Injected::new(by_name("rti.pxa.rz").unwrap());
    let one = f.from_f64(1.5);
    let r = Fault::arith(&x, &f, "pxa", Op::Mul, one, one);
    assert_eq!(f.to_bits(r), f.to_bits(f.mul(one, one)), "the fault-free value stands in");
    assert!(x.unmodelled());
}

/// The argument of `slab.inv_dz.rna`, checked on every binary16 and bfloat16 divisor and on
/// 2^20 binary32 ones (random bits and every power of two): 1 ⊘ d rounded half away from zero
/// (rustc_apfloat) equals the datapath's nearest-even reciprocal.
#[test]
fn a_reciprocal_is_never_a_tie() {
    fn check<F: Format>(f: F, bits: impl Iterator<Item = u64>) {
        let x = Injected::new(by_name("slab.inv_dz.rna").unwrap());
        for b in bits {
            let d = f.from_bits(b);
            let got = Fault::arith(&x, &f, "inv_dz", Op::Div, f.one(), d);
            assert_eq!(f.to_bits(got), f.to_bits(f.div(f.one(), d)), "{} d = {b:#x}", f.name());
        }
        assert!(!x.unmodelled());
    }
    let any = |n: &str| n.parse::<datapath::AnyFormat>().unwrap();
    datapath::with_format!(any("fp16"), |f| check(f, 0..1 << 16));
    datapath::with_format!(any("bf16"), |f| check(f, 0..1 << 16));
    let mut r = SplitMix64::new(7);
    let pow2 = (0..256u64).flat_map(|e| [e << 23, (e << 23) | 1 << 31]);
    check(f32f(), (0..1 << 20).map(move |_| r.next_u64() & 0xffff_ffff).chain(pow2));
}

proptest! {
    /// The zero-sign argument: the tie faults change t_near / t_far only by the sign of a zero,
    /// which the conservative variant's widening erases (outputs identical there).
    #[test]
    fn slab_tie_faults_flip_only_zero_signs(seed in any::<u64>()) {
        let f = f32f();
        let mut r = SplitMix64::new(seed);
        for name in ["slab.tn_x.tie", "slab.tf_xyz.tie"] {
            let x = Injected::new(by_name(name).unwrap());
            for variant in ["plain", "conservative", "take-on-false"] {
                let s = Slab::new(f, SlabConfig::named(variant).unwrap());
                for _ in 0..64 {
                    let v = slab_input(&mut r);
                    let (a, b) = (slab_out(&s, &v, &NoFault), slab_out(&s, &v, &x));
                    if variant == "conservative" {
                        prop_assert_eq!(a, b, "{} {:?}", name, v);
                    } else {
                        let zero_pair = |p: u64, q: u64| p == q || (p | q) & 0x7fff_ffff == 0;
                        prop_assert!(a.0 == b.0 && zero_pair(a.1, b.1) && zero_pair(a.2, b.2), "{} {} {:?}", name, variant, v);
                    }
                }
            }
        }
    }

    /// The guard argument of `slab.inv_dy.ftz` (conservative) and the equality argument of
    /// `slab.pdx.loose` (embree): no output changes, with huge and tiny direction components
    /// and |d.x| = δ among the inputs.
    #[test]
    fn the_conditionally_benign_slab_faults_change_no_output(seed in any::<u64>()) {
        let f = f32f();
        let mut r = SplitMix64::new(seed);
        let flush = Injected::new(by_name("slab.inv_dy.ftz").unwrap());
        let loose = Injected::new(by_name("slab.pdx.loose").unwrap());
        let (cons, embree) = (Slab::new(f, SlabConfig::named("conservative").unwrap()), Slab::new(f, SlabConfig::named("embree").unwrap()));
        let delta = f.to_f64(embree.delta());
        for _ in 0..64 {
            let mut v = slab_input(&mut r);
            v[4] = [3e38, -2.9e38, 1e38, r.range(-2.0, 2.0)][r.below(4) as usize];
            v[3] = [delta, -delta, f.to_f64(f.next_up(embree.delta())), r.range(-1.0, 1.0)][r.below(4) as usize];
            prop_assert_eq!(slab_out(&cons, &v, &NoFault), slab_out(&cons, &v, &flush), "{:?}", v);
            prop_assert_eq!(slab_out(&embree, &v, &NoFault), slab_out(&embree, &v, &loose), "{:?}", v);
        }
        prop_assert!(flush.reached() && loose.reached());
    }
}

/// A plain slab test where the first near select ties: origin on the x entry face (near.x =
/// +0) against tmin = -0; the tie fault takes +0.
#[test]
fn the_tie_fault_shows_outside_the_conservative_variant() {
    let f = f32f();
    let s = Slab::new(f, SlabConfig::named("plain").unwrap());
    let v = [0.0, 0.5, 0.5, 1.0, 0.25, 0.25, -0.0, f64::INFINITY, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0];
    let x = Injected::new(by_name("slab.tn_x.tie").unwrap());
    assert_eq!(slab_out(&s, &v, &NoFault).1, (-0.0f32).to_bits() as u64);
    assert_eq!(slab_out(&s, &v, &x).1, 0.0f32.to_bits() as u64);
}

#[test]
fn step_select_and_nan_faults_do_what_they_say() {
    let f = f32f();
    // two's complement step: right for positive values, toward zero for negative ones
    let twos = Injected::new(by_name("slab.t_far.twos").unwrap());
    assert_eq!(Fault::step(&twos, &f, "t_far", true, 1.0f32), f.next_up(1.0f32));
    assert_eq!(Fault::step(&twos, &f, "t_far", true, -1.0f32).to_bits(), (-1.0f32).to_bits() + 1);
    assert!(Fault::step(&twos, &f, "t_far", true, -1.0f32) < -1.0);
    assert!(Fault::step(&twos, &f, "t_far", true, f32::INFINITY).is_nan());
    assert_eq!(Fault::step(&twos, &f, "t_near", false, -1.0f32), f.next_down(-1.0f32));
    let bypass = Injected::new(by_name("slab.t_near.bypass").unwrap());
    assert_eq!(Fault::step(&bypass, &f, "t_near", false, 2.0f32), 2.0);
    assert_eq!(Fault::step(&bypass, &f, "t_far", true, 2.0f32), f.next_up(2.0f32));
    let nan = Injected::new(by_name("slab.tn_xy.nan").unwrap());
    assert!(Fault::compare(&nan, &f, "tn_xy", Cmp::Lt, 1.0f32, f32::NAN));
    assert!(!Fault::compare(&nan, &f, "tn_x", Cmp::Lt, 1.0f32, f32::NAN));
    assert!(!Fault::compare(&nan, &f, "tn_xy", Cmp::Lt, 2.0f32, 1.0));
    let tie = Injected::new(by_name("slab.tn_x.tie").unwrap());
    assert!(Fault::compare(&tie, &f, "tn_x", Cmp::Lt, 1.0f32, 1.0));
    assert!(!Fault::compare(&tie, &f, "tn_x", Cmp::Le, 1.0f32, 1.0));
    let sel = Injected::new(by_name("slab.negz.stuck1").unwrap());
    assert!(Logic::flag(&sel, "negz", false));
    assert!(!Logic::flag(&sel, "negx", false));
}

/// A two-leaf tree: the root's children are leaves 10 (left, entry t = `tl`) and 11 (right,
/// entry `tr`); boxes are their entry distances (NaN: a miss).
fn two_leaves(tl: f64, tr: f64) -> datapath::bvh::HwTree<f64> {
    use datapath::bvh::{Bank, HwTree, Level, LEAF_FLAG};
    HwTree {
        root_box: 0.0,
        root_addr: 0,
        levels: vec![Level {
            left: Bank { boxes: vec![tl], addr: vec![LEAF_FLAG | 10] },
            right: Bank { boxes: vec![tr], addr: vec![LEAF_FLAG | 11] },
        }],
    }
}

/// The traversal faults change the leaf order or count the way their RTL bug does, on a tree
/// traced by hand.
#[test]
fn traversal_faults_do_what_they_say() {
    let leaves = |tl: f64, tr: f64, n: usize, fault: Option<&str>| {
        let t = two_leaves(tl, tr);
        let test = |b: &f64| (!b.is_nan()).then_some(*b);
        match fault {
            None => datapath::bvh::history_traverse_faulty(&t, n, test, &NoFault).leaves,
            Some(name) => {
                let x = Injected::new(by_name(name).unwrap());
                let r = datapath::bvh::history_traverse_faulty(&t, n, test, &x).leaves;
                assert!(x.reached(), "{name}");
                r
            }
        }
    };
    // a tie goes left first; the tie fault sends it right
    assert_eq!(leaves(1.0, 1.0, 2, None), [10, 11]);
    assert_eq!(leaves(1.0, 1.0, 2, Some("traverse.near.tie")), [11, 10]);
    assert_eq!(leaves(1.0, 2.0, 2, Some("traverse.near.tie")), [10, 11]);
    // the nearer child first; swapped: the farther
    assert_eq!(leaves(2.0, 1.0, 2, None), [11, 10]);
    assert_eq!(leaves(2.0, 1.0, 2, Some("traverse.near.swap")), [10, 11]);
    // one pass only: the farther child is never visited
    assert_eq!(leaves(1.0, 2.0, 2, Some("traverse.more.stuck0")), [10]);
    assert_eq!(leaves(1.0, 2.0, 2, Some("traverse.mark_split.stuck0")), [10]);
    // the N limit: one leaf asked, two given
    assert_eq!(leaves(1.0, 2.0, 1, None), [10]);
    assert_eq!(leaves(1.0, 2.0, 1, Some("traverse.n_limit.plus1")), [10, 11]);
    // one child hit: the history says 01; without the mark it stays 00
    let t = two_leaves(1.0, f64::NAN);
    let test = |b: &f64| (!b.is_nan()).then_some(*b);
    assert_eq!(datapath::bvh::history_traverse_faulty(&t, 2, test, &NoFault).state, [datapath::bvh::hist::PASS]);
    let x = Injected::new(by_name("traverse.mark_pass.stuck0").unwrap());
    assert_eq!(datapath::bvh::history_traverse_faulty(&t, 2, test, &x).state, [datapath::bvh::hist::NEW]);
}

proptest! {
    /// The argument of `rti.e1x.nan`: with NaN inputs of every sign and payload, in a canonical
    /// and a propagating format, valid and hit never change, and t, u, v change only where
    /// valid is 0 (not compared there); the e1x probe does change when v0.x or v1.x is a NaN
    /// with a payload the canonical rule would drop.
    #[test]
    fn the_nan_rule_fault_changes_no_compared_rti_output(seed in any::<u64>()) {
        let mut r = SplitMix64::new(seed);
        for name in ["fp16", "fp16:propagate"] {
            let any: datapath::AnyFormat = name.parse().unwrap();
            datapath::with_format!(any, |f| {
                let spec = by_name("rti.e1x.nan").unwrap();
                let rti = Rti::new(f, RtiConfig::default());
                let mut shown = false;
                for _ in 0..64 {
                    let val = |r: &mut SplitMix64| match r.below(4) {
                        0 => f.from_bits(0x7c00 | (r.next_u64() & 0x3ff).max(1) | (r.below(2) << 15)),
                        _ => f.from_f64(r.range(-2.0, 2.0)),
                    };
                    let ray = Ray { o: [val(&mut r), val(&mut r), val(&mut r)], d: [val(&mut r), val(&mut r), val(&mut r)], tmin: f.zero(), tmax: f.from_f64(f64::INFINITY) };
                    let tri = Tri { v: [[val(&mut r), val(&mut r), val(&mut r)], [val(&mut r), val(&mut r), val(&mut r)], [val(&mut r), val(&mut r), val(&mut r)]] };
                    let x = Injected::new(spec);
                    let (a, b) = (rti.trace_faulty(&ray, &tri, &mut NoProbe, &NoFault), rti.trace_faulty(&ray, &tri, &mut NoProbe, &x));
                    prop_assert_eq!((a.valid, a.hit), (b.valid, b.hit));
                    if a.valid {
                        prop_assert_eq!([f.to_bits(a.t), f.to_bits(a.u), f.to_bits(a.v)], [f.to_bits(b.t), f.to_bits(b.u), f.to_bits(b.v)]);
                    }
                    shown |= f.to_bits(Fault::arith(&x, &f, "e1x", Op::Sub, tri.v[1][0], tri.v[0][0])) != f.to_bits(f.sub(tri.v[1][0], tri.v[0][0]));
                }
                prop_assert!(shown, "{}: the fault never showed on the e1x site", name);
                Ok::<(), TestCaseError>(())
            })?;
        }
    }
}
