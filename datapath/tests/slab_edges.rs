//! The slab unit at the edges of each format: the cases that once made a variant named
//! conservative or directed miss a box the exact decision hits, each one a test, and the
//! refusal of a promise a format cannot keep.

use datapath::slab::{Slab, SlabConfig, CONSERVATIVE_ULPS};
use datapath::{with_format, AnyFormat, Format};

/// (format, variant, ray o+d, box min+max): every one an exact hit.
const CASES: [(&str, &str, [f64; 6], [f64; 6]); 10] = [
    // a subnormal (or tiny) direction component: 1 ⊘ d overflows to ∞
    ("f32", "conservative", [0.0, 0.0, 0.0, 1.0, 0.0, 1e-39], [0.0, -1.0, 1e-37, 1000.0, 1.0, 2e-37]),
    ("bf16", "conservative", [0.0, 0.0, 0.0, 1.0, 0.0, 1e-39], [0.0, -1.0, 1e-37, 1000.0, 1.0, 2e-37]),
    ("fp16", "conservative", [0.0, 0.0, 0.0, 1.0, 0.0, 1e-5], [0.0, -1.0, 1e-3, 1000.0, 1.0, 2e-3]),
    ("f32", "directed", [0.0, 0.0, 0.0, 1.0, 0.0, 1e-39], [0.0, -1.0, 1e-37, 1000.0, 1.0, 2e-37]),
    ("fp16", "directed", [0.0, 0.0, 0.0, 1.0, 0.0, 1e-5], [0.0, -1.0, 1e-3, 1000.0, 1.0, 2e-3]),
    // a plane minus origin that overflows to ∞ while the distance is finite
    ("fp16", "conservative", [-50000.0, 0.0, 0.0, 1000.0, 1.0, 0.0], [30000.0, 50.0, -1.0, 60000.0, 1000.0, 1.0]),
    ("fp16", "directed", [-50000.0, 0.0, 0.0, 1000.0, 1.0, 0.0], [30000.0, 50.0, -1.0, 60000.0, 1000.0, 1.0]),
    // saturating fixed point: the exit plane's difference saturates
    ("q8.24", "directed", [-100.0, 0.0, 0.0, 4.0, 1.0, 0.0], [-100.0, 40.0, -1.0, 100.0, 60.0, 1.0]),
    ("q8.24:divide", "directed", [-100.0, 0.0, 0.0, 4.0, 1.0, 0.0], [-100.0, 40.0, -1.0, 100.0, 60.0, 1.0]),
    // q1.F holds no 1: every reciprocal saturates
    ("q1.15", "directed", [-0.5, 0.0, 0.0, 0.5, 0.1, 0.0], [-0.1, -0.1, -0.1, 0.1, 0.1, 0.1]),
];

fn run<F: Format>(f: F, sc: SlabConfig, x: [f64; 6], b: [f64; 6]) -> (bool, Option<bool>) {
    let s = Slab::new(f, sc);
    let q = |v: f64| f.to_f64(f.from_f64(v));
    let stored = s.store_box([b[0], b[1], b[2]], [b[3], b[4], b[5]]).unwrap();
    let hit = s.test(&s.prepare([x[0], x[1], x[2]], [x[3], x[4], x[5]], 0.0, f64::INFINITY), &stored).hit;
    let exact = golden::slab_exact(
        [q(x[0]), q(x[1]), q(x[2])],
        [q(x[3]), q(x[4]), q(x[5])],
        0.0,
        q(f64::INFINITY),
        [b[0], b[1], b[2]],
        [b[3], b[4], b[5]],
    );
    (hit, exact)
}

#[test]
fn the_reported_misses_are_hits_now() {
    for (name, variant, x, b) in CASES {
        let any: AnyFormat = name.parse().unwrap();
        let (hit, exact) = with_format!(any, |f| run(f, SlabConfig::named_for(variant, &f).unwrap(), x, b));
        assert_eq!(exact, Some(true), "{name} {variant}: the case must be an exact hit");
        assert!(hit, "{name} {variant} {x:?} {b:?}: missed");
    }
}

/// Without the guard, the same widening misses the float cases: the guard is what fixes them
/// (so the test above can fail).
#[test]
fn widening_without_the_guard_misses_them() {
    let unguarded = SlabConfig { guard: false, ..SlabConfig::named("conservative").unwrap() };
    assert_eq!(unguarded.widen_ulps, CONSERVATIVE_ULPS);
    let mut missed = 0;
    for (name, variant, x, b) in CASES.iter().filter(|c| c.1 == "conservative") {
        let any: AnyFormat = name.parse().unwrap();
        let (hit, _) = with_format!(any, |f| run(f, unguarded, *x, *b));
        assert!(!hit, "{name} {variant}: hits without the guard: the case tests nothing");
        missed += 1;
    }
    assert_eq!(missed, 4);
}

/// The directed variant before its fixed-point rules (a saturated difference taken as a bound)
/// is what missed q8.24: a plain round-to-nearest unit misses it too.
#[test]
fn plain_misses_the_saturating_case() {
    let any: AnyFormat = "q8.24".parse().unwrap();
    let (hit, exact) = with_format!(any, |f| run(
        f,
        SlabConfig::named("plain").unwrap(),
        [-100.0, 0.0, 0.0, 4.0, 1.0, 0.0],
        [-100.0, 40.0, -1.0, 100.0, 60.0, 1.0]
    ));
    assert_eq!((hit, exact), (false, Some(true)));
}

#[test]
fn a_promise_the_format_cannot_keep_is_refused() {
    for (name, variant, why) in [
        ("q8.24", "conservative", "fixed point"),
        ("q8.24:divide", "conservative", "fixed point"),
        ("q1.15", "conservative", "fixed point"),
        ("fp16:ftz", "conservative", "flush-to-zero"),
        ("f32:ftz+divide", "conservative", "flush-to-zero"),
        ("q16.16:wrap", "directed", "wrap"),
        ("e5m2", "conservative", "fewer than 4 fraction bits"),
        ("e4m3", "conservative", "fewer than 4 fraction bits"),
    ] {
        let any: AnyFormat = name.parse().unwrap();
        let e = with_format!(any, |f| SlabConfig::named_for(variant, &f)).unwrap_err();
        assert!(e.contains(variant) && e.contains(name) && e.contains(why), "{e}");
        let listed = with_format!(any, |f| SlabConfig::variants_for(&f));
        assert!(!listed.contains(&variant), "{name}: {listed:?}");
    }
    for name in ["f32", "fp16", "bf16", "e8m16", "e5m4", "f32:propagate+divide"] {
        let any: AnyFormat = name.parse().unwrap();
        assert_eq!(with_format!(any, |f| SlabConfig::variants_for(&f)).len(), 5, "{name}");
    }
    let q: AnyFormat = "q8.24".parse().unwrap();
    assert_eq!(with_format!(q, |f| SlabConfig::variants_for(&f)), ["plain", "directed", "take-on-false", "embree"]);
}
