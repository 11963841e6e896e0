//! The fault bank and its injector: the names, the exactness of the rounding faults against an
//! independent computation, the benign argument, and the campaign's verdicts.

use datapath::fault::{Cmp, Fault, NoFault};
use datapath::format::{F32Native, FpOpts, Ieee};
use datapath::rng::SplitMix64;
use datapath::rti::{Op, Ray, Rti, RtiConfig, Tri};
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
    assert!(BANK.len() >= 30);
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
