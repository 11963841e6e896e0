//! The slab (BVI) unit: every face × signed-zero direction case in every format and variant
//! against the exact decision; zero false misses for the conservative variant on random and
//! adversarial cases; non-conservative disagreements only within the ±4-ulp band; conservative
//! box storage (also in a narrower storage format); batch = scalar; empty slots.

use datapath::format::{Format, Subnormals};
use datapath::probe::{Recorder, Signal};
use datapath::rng::SplitMix64;
use datapath::slab::{
    BoxError, BoxesSoa, DirPrep, Slab, SlabConfig, SlabNan, SlabOutSoa, SlabRaysSoa, CONSERVATIVE_ULPS,
};
use datapath::{with_format, AnyFormat};
use golden::slab_exact as exact_decision;

/// The exact decision of inputs that are finite by construction.
fn slab_exact(o: [f64; 3], d: [f64; 3], tmin: f64, tmax: f64, lo: [f64; 3], hi: [f64; 3]) -> bool {
    exact_decision(o, d, tmin, tmax, lo, hi).expect("finite ray")
}

const FLOATS: [&str; 6] = ["f32", "f32:divide", "fp16", "bf16", "e8m16", "e5m10"];
const ALL: [&str; 10] = [
    "f32",
    "f32:divide",
    "fp16",
    "bf16",
    "e8m16",
    "e5m10",
    "fp16:ftz",
    "f32:ftz",
    "q8.24:divide",
    "q16.16:nearest+divide",
];

fn fmt(name: &str) -> AnyFormat {
    name.parse().unwrap()
}

fn cfg(nan: SlabNan, prep: DirPrep, widen_ulps: i32) -> SlabConfig {
    // a widening variant carries the guard, as `conservative` does
    SlabConfig { nan, prep, widen_ulps, directed: false, guard: widen_ulps > 0 }
}

fn directed() -> SlabConfig {
    SlabConfig::named("directed").unwrap()
}

/// Runs the model on f64 inputs (box stored conservatively) and returns (hit, any NaN signal).
fn run<F: Format>(
    s: &Slab<F>,
    o: [f64; 3],
    d: [f64; 3],
    tmin: f64,
    tmax: f64,
    lo: [f64; 3],
    hi: [f64; 3],
) -> (bool, bool) {
    let mut rec = Recorder::new();
    let ray = s.prepare_trace(o, d, tmin, tmax, &mut rec);
    let b = s.store_box(lo, hi).expect("box fits");
    let out = s.trace(&ray, &b, &mut rec);
    let nan = rec.signals.iter().any(|(_, v)| matches!(v, Signal::Value(x) if s.fmt.is_nan(*x)));
    (out.hit, nan)
}

/// Origin on each of the 6 faces (other coordinates inside, on the edge, or outside the face),
/// one direction component +0 or −0 on each axis, the others from {±1, ±0.5}: every value and
/// every product is exact in every format, so the model must give the exact answer except
/// where its convention says otherwise.
#[test]
fn faces_times_signed_zero_directions_in_every_format_and_variant() {
    let (lo, hi) = ([-0.5; 3], [0.5; 3]);
    let others = [0.25, 0.75, -0.5, 0.5, -0.75];
    let comps = [1.0, -1.0, 0.5, -0.5];
    let mut cases = Vec::new();
    for face_axis in 0..3 {
        for plane in [-0.5, 0.5] {
            for &u in &others {
                for &v in &others {
                    let mut o = [0.0; 3];
                    o[face_axis] = plane;
                    o[(face_axis + 1) % 3] = u;
                    o[(face_axis + 2) % 3] = v;
                    for zero_axis in 0..3 {
                        for zero in [0.0, -0.0] {
                            for &c1 in &comps {
                                for &c2 in &comps {
                                    let mut d = [0.0; 3];
                                    d[zero_axis] = zero;
                                    d[(zero_axis + 1) % 3] = c1;
                                    d[(zero_axis + 2) % 3] = c2;
                                    cases.push((o, d));
                                }
                            }
                        }
                    }
                }
            }
        }
    }
    assert_eq!(cases.len(), 6 * 25 * 3 * 2 * 16);
    // a NaN (0 × ∞) arises on axis a when d[a] = ±0 and o[a] lies on one of its planes
    let nan_axis = |o: [f64; 3], d: [f64; 3], a: usize| d[a] == 0.0 && (o[a] == lo[a] || o[a] == hi[a]);
    let mut report = String::new();
    for name in ALL {
        let any = fmt(name);
        let float_ieee = FLOATS.contains(&name);
        with_format!(any, |f| {
            for variant in [
                cfg(SlabNan::Ignore, DirPrep::Plain, 0),
                cfg(SlabNan::Ignore, DirPrep::Plain, CONSERVATIVE_ULPS),
                cfg(SlabNan::TakeOnFalse, DirPrep::Plain, 0),
                cfg(SlabNan::Ignore, DirPrep::Embree, 0),
                directed(),
            ] {
                let s = Slab::new(f, variant);
                let (mut false_miss, mut false_hit, mut face_plane) = (0, 0, 0);
                for &(o, d) in &cases {
                    let exact = slab_exact(o, d, 0.0, f64::INFINITY, lo, hi);
                    let (hit, nan) = run(&s, o, d, 0.0, f64::INFINITY, lo, hi);
                    let in_plane = (0..3).any(|a| nan_axis(o, d, a));
                    face_plane += in_plane as u32;
                    false_miss += (exact && !hit) as u32;
                    false_hit += (!exact && hit) as u32;
                    let ctx = || format!("{name} {variant:?} o {o:?} d {d:?}: exact {exact} model {hit}");
                    match (variant.nan, variant.prep) {
                        _ if variant.directed => assert!(hit || !exact, "directed variant missed: {}", ctx()),
                        (SlabNan::Ignore, DirPrep::Plain) if float_ieee || name.contains("ftz") => {
                            if variant.widen_ulps == 0 {
                                assert_eq!(hit, exact, "{}", ctx());
                            } else {
                                assert!(hit || !exact, "{}", ctx());
                            }
                        }
                        (SlabNan::TakeOnFalse, DirPrep::Plain) if float_ieee || name.contains("ftz") => {
                            assert_eq!(hit, take_on_false_chain(o, d, 0.0, f64::INFINITY, lo, hi), "{}", ctx());
                        }
                        (SlabNan::Ignore, DirPrep::Embree) => {
                            assert!(!nan, "{}: Embree preparation let a NaN through", ctx());
                            if hit != exact {
                                assert!(in_plane, "{}: disagreement outside the face-plane cases", ctx());
                            }
                        }
                        _ => {
                            // fixed point with a plain reciprocal: 1/0 saturates; no claim beyond
                            // "no NaN exists" (fixed point has none)
                            assert!(!nan);
                        }
                    }
                }
                report += &format!("{name:<22} {variant:?}: false misses {false_miss}, false hits {false_hit} of {} ({face_plane} in-plane)\n", cases.len());
            }
        });
    }
    eprint!("{report}");
}

/// The take-on-false chain's semantics on exact values (every value of the face grid is exact):
/// a NaN axis value replaces the accumulator, erasing tmin/tmax and earlier axes; a value after
/// a NaN accumulator replaces it; otherwise the usual max (near) / min (far).
fn take_on_false_chain(o: [f64; 3], d: [f64; 3], tmin: f64, tmax: f64, lo: [f64; 3], hi: [f64; 3]) -> bool {
    let (mut near, mut far) = (tmin, tmax);
    for a in 0..3 {
        let inv = 1.0 / d[a];
        let (t0, t1) = ((lo[a] - o[a]) * inv, (hi[a] - o[a]) * inv);
        let (n, f) = if inv.is_sign_negative() { (t1, t0) } else { (t0, t1) };
        near = if n.is_nan() || near.is_nan() || n > near { n } else { near };
        far = if f.is_nan() || far.is_nan() || f < far { f } else { far };
    }
    near <= far
}

/// Adversarial and random cases: boxes of every size (zero extent, tiny, huge, beyond the
/// format's range), rays grazing faces, edges and corners, origins inside, axis-parallel rays.
fn random_case(r: &mut SplitMix64) -> ([f64; 3], [f64; 3], f64, [f64; 3], [f64; 3]) {
    let mut lo = [0.0; 3];
    let mut hi = [0.0; 3];
    let big = r.below(8) == 0;
    for a in 0..3 {
        let c = r.range(-1.0, 1.0) * if big { 1e6 } else { 1.0 };
        let e = if r.below(10) == 0 { 0.0 } else { 2f64.powf(r.range(-20.0, if big { 40.0 } else { 2.0 })) };
        lo[a] = c - e;
        hi[a] = c + e;
    }
    // a target: inside, on a face, on an edge or at a corner
    let mut p: [f64; 3] = std::array::from_fn(|a| r.range(lo[a], hi[a]));
    let pinned = r.below(4) as usize; // how many coordinates sit exactly on a plane
    for a in 0..pinned.min(3) {
        p[a] = if r.below(2) == 0 { lo[a] } else { hi[a] };
    }
    let o: [f64; 3] = if r.below(6) == 0 {
        std::array::from_fn(|a| r.range(lo[a], hi[a])) // origin inside
    } else {
        std::array::from_fn(|a| p[a] + r.range(-4.0, 4.0) * (hi[a] - lo[a] + 1.0))
    };
    let mut d = [p[0] - o[0], p[1] - o[1], p[2] - o[2]];
    if r.below(5) == 0 {
        let a = r.below(3) as usize;
        d[a] = if r.below(2) == 0 { 0.0 } else { -0.0 }; // axis-parallel
    }
    if r.below(7) == 0 {
        d = std::array::from_fn(|_| r.range(-1.0, 1.0)); // random direction
    }
    let tmax = if r.below(5) == 0 { r.range(0.0, 3.0) } else { f64::INFINITY };
    (o, d, tmax, lo, hi)
}

#[test]
fn conservative_variant_never_misses_and_the_plain_one_errs_only_within_four_ulps() {
    let mut report = String::new();
    for name in FLOATS {
        with_format!(fmt(name), |f| {
            let plain = Slab::new(f, cfg(SlabNan::Ignore, DirPrep::Plain, 0));
            let wide = Slab::new(f, cfg(SlabNan::Ignore, DirPrep::Plain, CONSERVATIVE_ULPS));
            let narrow = Slab::new(f, cfg(SlabNan::Ignore, DirPrep::Plain, -CONSERVATIVE_ULPS));
            let mut r = SplitMix64::new(0x51ab_0001);
            let (mut n, mut exact_hits, mut plain_wrong, mut wide_false_hits) = (0, 0, 0, 0);
            for _ in 0..20_000 {
                let (o, d, tmax, lo, hi) = random_case(&mut r);
                let q = |x: f64| f.to_f64(f.from_f64(x));
                let (oq, dq) = (o.map(q), d.map(q));
                if oq.iter().chain(dq.iter()).any(|x| !x.is_finite()) {
                    continue; // the ray itself does not fit the format
                }
                let tq = q(tmax);
                // the original box judges conservativeness; the stored (outward-rounded) box,
                // which the datapath really holds, judges the narrowed and plain variants
                let exact = slab_exact(oq, dq, 0.0, tq, lo, hi);
                let b = wide.store_box(lo, hi).unwrap();
                let exact_stored = slab_exact(oq, dq, 0.0, tq, b.min.map(|v| f.to_f64(v)), b.max.map(|v| f.to_f64(v)));
                let test = |s: &Slab<_>| s.test(&s.prepare(o, d, 0.0, tmax), &b).hit;
                let (hp, hw, hn) = (test(&plain), test(&wide), test(&narrow));
                let ctx = || {
                    format!("{name}: o {o:?} d {d:?} tmax {tmax} box {lo:?}..{hi:?}: exact {exact} (stored box {exact_stored}) plain {hp} wide {hw} narrow {hn}")
                };
                assert!(hw || !exact, "conservative variant missed: {}", ctx());
                assert!(!hn || exact_stored, "narrowed variant hit a missed box: {}", ctx());
                n += 1;
                exact_hits += exact as u32;
                plain_wrong += (hp != exact_stored) as u32;
                wide_false_hits += (hw && !exact) as u32;
            }
            assert!(n > 15_000 && exact_hits > 3000, "{name}: too few usable cases ({n}, {exact_hits} hits)");
            report += &format!("{name}: {n} cases, {exact_hits} exact hits, plain disagreements (vs the stored box) {plain_wrong}, conservative false hits {wide_false_hits}\n");
        });
    }
    eprint!("{report}");
}

/// The directed (interval) variant is conservative in every format: IEEE floats, flush-to-zero
/// floats and saturating fixed point.
#[test]
fn directed_variant_never_misses_in_any_format() {
    let mut report = String::new();
    for name in ALL {
        with_format!(fmt(name), |f| {
            let s = Slab::new(f, directed());
            let mut r = SplitMix64::new(0x51ab_0005);
            let (mut n, mut hits, mut false_hits) = (0, 0, 0);
            for _ in 0..20_000 {
                let (o, d, tmax, lo, hi) = random_case(&mut r);
                let q = |x: f64| f.to_f64(f.from_f64(x));
                let (oq, dq) = (o.map(q), d.map(q));
                // the ray must fit the format (fixed point saturates instead of overflowing)
                if o.iter()
                    .chain(d.iter())
                    .zip(oq.iter().chain(dq.iter()))
                    .any(|(x, y)| !y.is_finite() || (x.abs() > 1.0 && (x - y).abs() > x.abs() * 0.5))
                {
                    continue;
                }
                let Ok(b) = s.store_box(lo, hi) else { continue };
                let tq = q(tmax);
                let exact = slab_exact(oq, dq, 0.0, tq, lo, hi);
                let hit = s.test(&s.prepare(o, d, 0.0, tmax), &b).hit;
                assert!(hit || !exact, "{name}: directed missed o {o:?} d {d:?} tmax {tmax} box {lo:?}..{hi:?}");
                n += 1;
                hits += exact as u32;
                false_hits += (hit && !exact) as u32;
            }
            assert!(n > 5000 && hits > 1000, "{name}: too few usable cases ({n}, {hits} hits)");
            report += &format!("{name}: {n} cases, {hits} exact hits, directed false hits {false_hits}\n");
        });
    }
    eprint!("{report}");
}

#[test]
fn narrow_box_storage_contains_the_original() {
    let mut r = SplitMix64::new(0x51ab_0002);
    for storage in ["fp16", "bf16", "e5m2", "fp16:ftz", "q8.8", "q16.16:nearest", "f32"] {
        with_format!(fmt(storage), |s| {
            let compute = Slab::new(fmt_f32(), SlabConfig::default());
            for _ in 0..20_000 {
                let (_, _, _, lo, hi) = random_case(&mut r);
                match compute.store_box_via(&s, lo, hi) {
                    Ok(b) => {
                        for a in 0..3 {
                            assert!(
                                (b.min[a] as f64) <= lo[a] && (b.max[a] as f64) >= hi[a],
                                "{storage}: {lo:?}..{hi:?} stored as {b:?}"
                            );
                        }
                    }
                    Err(BoxError::OutOfRange(x)) => {
                        assert!(
                            storage.starts_with('q'),
                            "{storage}: float storage clamps to infinity, got out-of-range {x}"
                        );
                        assert!(x.abs() > 127.0 || storage == "q8.8" && x.abs() > 127.0, "{storage}: {x} was in range");
                    }
                    Err(e) => panic!("{storage}: {e}"),
                }
            }
            // beyond the float format's range: clamp to infinity, still containing
            if !storage.starts_with('q') {
                let b = compute.store_box_via(&s, [-1e300; 3], [1e300; 3]).unwrap();
                assert!(b.min.iter().all(|x| *x == f32::NEG_INFINITY) && b.max.iter().all(|x| *x == f32::INFINITY));
            }
        });
    }
    let s = Slab::new(fmt_f32(), SlabConfig::default());
    assert_eq!(s.store_box([0.0, f64::NAN, 0.0], [1.0; 3]).unwrap_err(), BoxError::Nan);
    assert_eq!(s.store_box([2.0, 0.0, 0.0], [1.0; 3]).unwrap_err(), BoxError::Inverted);
    // the messages a refused box reports (CLI errors quote them)
    assert_eq!(BoxError::Nan.to_string(), "box coordinate is NaN");
    assert_eq!(BoxError::Inverted.to_string(), "box min exceeds max");
    assert_eq!(BoxError::OutOfRange(300.5).to_string(), "box coordinate 300.5 is outside the fixed-point range");
    // zero-extent boxes stay zero-extent when exactly representable, and still contain the point
    let b = s.store_box([0.5; 3], [0.5; 3]).unwrap();
    assert_eq!((b.min, b.max), ([0.5; 3], [0.5; 3]));
}

fn fmt_f32() -> datapath::format::Ieee<datapath::format::F32Native> {
    match fmt("f32") {
        AnyFormat::F32(f) => f,
        _ => unreachable!(),
    }
}

#[test]
fn conservative_holds_with_fp16_boxes_and_f32_arithmetic() {
    let s16 = match fmt("fp16") {
        AnyFormat::F16(f) => f,
        _ => unreachable!(),
    };
    let wide = Slab::new(fmt_f32(), cfg(SlabNan::Ignore, DirPrep::Plain, CONSERVATIVE_ULPS));
    let mut r = SplitMix64::new(0x51ab_0003);
    let mut hits = 0;
    for _ in 0..20_000 {
        let (o, d, tmax, lo, hi) = random_case(&mut r);
        let q = |x: f64| x as f32 as f64;
        let exact = slab_exact(o.map(q), d.map(q), 0.0, q(tmax), lo, hi);
        let b = wide.store_box_via(&s16, lo, hi).unwrap();
        let hit = wide.test(&wide.prepare(o, d, 0.0, tmax), &b).hit;
        assert!(hit || !exact, "missed: o {o:?} d {d:?} box {lo:?}..{hi:?}");
        hits += exact as u32;
    }
    assert!(hits > 3000);
}

#[test]
fn batch_equals_scalar_and_empty_slots_are_never_hit() {
    let mut r = SplitMix64::new(0x51ab_0004);
    for name in ALL {
        with_format!(fmt(name), |f| {
            for variant in [cfg(SlabNan::Ignore, DirPrep::Plain, 0), cfg(SlabNan::TakeOnFalse, DirPrep::Embree, 4)] {
                let s = Slab::new(f, variant);
                let (mut rays, mut boxes) = (SlabRaysSoa::default(), BoxesSoa::default());
                let mut scalar = Vec::new();
                for _ in 0..3000 {
                    let (o, d, tmax, lo, hi) = random_case(&mut r);
                    let ray = s.prepare(o, d, 0.0, tmax);
                    // raw bit patterns too: NaN, infinities, subnormals
                    let mut b = s.store_box(lo, hi).unwrap_or_else(|_| s.empty_box());
                    if r.below(4) == 0 {
                        b.min[r.below(3) as usize] = f.from_bits(r.next_u64());
                    }
                    rays.push(&ray);
                    boxes.push(&b);
                    scalar.push(s.test(&ray, &b));
                    // empty slots: never hit by a ray whose origin and direction fit the format
                    if o.iter().chain(d.iter()).all(|x| f.to_f64(f.from_f64(*x)).is_finite()) {
                        assert!(!s.test(&ray, &s.empty_box()).hit, "{name} {variant:?}: empty slot hit by d {d:?}");
                    }
                }
                let mut out = SlabOutSoa::with_len(scalar.len());
                s.batch(&rays, &boxes, &mut out);
                for (i, o) in scalar.iter().enumerate() {
                    assert_eq!(
                        (out.hit[i], f.to_bits(out.t_near[i]), f.to_bits(out.t_far[i])),
                        (o.hit, f.to_bits(o.t_near), f.to_bits(o.t_far)),
                        "{name} case {i}"
                    );
                }
            }
        });
    }
    let _ = Subnormals::Ieee;
}

/// Every recorded slab signal follows `SLAB_TABLE`: names in order, arithmetic rows recomputed
/// from their recorded operands, selects and the decision recomputed from their formulas.
#[test]
fn every_slab_signal_follows_the_stage_table() {
    let mut r = SplitMix64::new(0x51ab_0006);
    for name in ALL {
        with_format!(fmt(name), |f| {
            for v in ["plain", "conservative", "take-on-false", "embree"] {
                for _ in 0..2000 {
                    check_slab_table(f, name, v, &mut r);
                }
            }
        });
    }
}

fn check_slab_table<F: Format>(f: F, name: &str, v: &str, r: &mut SplitMix64) {
    use datapath::rti::Op;
    use datapath::slab::SLAB_TABLE;
    let sc = SlabConfig::named(v).unwrap();
    let s = Slab::new(f, sc);
    let (o, d, tmax, lo, hi) = random_case(r);
    let mut rec = Recorder::new();
    let ray = s.prepare_trace(o, d, 0.0, tmax, &mut rec);
    let b = s.store_box(lo, hi).unwrap_or_else(|_| s.empty_box());
    let out = s.trace(&ray, &b, &mut rec);
    let names: Vec<&str> = rec.signals.iter().map(|(n, _)| *n).collect();
    let want: Vec<&str> = SLAB_TABLE.iter().map(|d| d.name).collect();
    assert_eq!(names, want, "{name} {v}");
    let val = |n: &str| -> F::V {
        match n {
            "one" => f.one(),
            "ox" | "oy" | "oz" => ray.o[(n.as_bytes()[1] - b'x') as usize],
            "minx" | "miny" | "minz" => b.min[(n.as_bytes()[3] - b'x') as usize],
            "maxx" | "maxy" | "maxz" => b.max[(n.as_bytes()[3] - b'x') as usize],
            _ => rec.value(n).unwrap(),
        }
    };
    let flag = |n: &str| rec.flag(n).unwrap();
    let bits = |x| f.to_bits(x);
    // the conservative variant's guard, from its definition in values: a reciprocal of a
    // finite nonzero operand that is not normal, or a subtract of finite operands that is
    // infinite, is the canonical NaN (floats only)
    let layout = match f.kind() {
        datapath::format::FormatKind::Float(l) if sc.guard => Some(l),
        _ => None,
    };
    let nan_bits = layout.map(|l| l.canonical_nan());
    let fin = |x: F::V| f.to_f64(x).is_finite();
    for row in SLAB_TABLE.iter().filter(|d| d.op != Op::Logic) {
        let (a, b) = (val(row.a), val(row.b));
        let want = match row.op {
            Op::Sub => f.sub(a, b),
            Op::Mul => f.mul(a, b),
            Op::Div => f.div(a, b),
            _ => unreachable!(),
        };
        let guarded = match (layout, row.op) {
            (Some(_), Op::Sub) => fin(a) && fin(b) && f.to_f64(want).is_infinite(),
            (Some(l), Op::Div) => {
                let r = f.to_f64(want).abs();
                fin(b) && f.to_f64(b) != 0.0 && (r.is_infinite() || r < l.min_normal())
            }
            _ => false,
        };
        let want = if guarded { nan_bits.unwrap() } else { bits(want) };
        assert_eq!(bits(val(row.name)), want, "{name} {v}: {}", row.name);
    }
    // selects by sign, compare-selects, widening and decision
    let sel = |neg: bool, a: &str, b: &str| if neg { val(a) } else { val(b) };
    for (ax, inv, n, fr, lo_, hi_) in [
        ("negx", "inv_dx", "nearx", "farx", "tlox", "thix"),
        ("negy", "inv_dy", "neary", "fary", "tloy", "thiy"),
        ("negz", "inv_dz", "nearz", "farz", "tloz", "thiz"),
    ] {
        let neg = flag(ax);
        assert_eq!(neg, f.sign_bit(val(inv)));
        assert_eq!(bits(val(n)), bits(sel(neg, hi_, lo_)));
        assert_eq!(bits(val(fr)), bits(sel(neg, lo_, hi_)));
    }
    let near = |acc, x| match sc.nan {
        SlabNan::Ignore => {
            if f.lt(acc, x) {
                x
            } else {
                acc
            }
        }
        SlabNan::TakeOnFalse => {
            if f.le(x, acc) {
                acc
            } else {
                x
            }
        }
    };
    let far = |acc, x| match sc.nan {
        SlabNan::Ignore => {
            if f.lt(x, acc) {
                x
            } else {
                acc
            }
        }
        SlabNan::TakeOnFalse => {
            if f.le(acc, x) {
                acc
            } else {
                x
            }
        }
    };
    assert_eq!(bits(val("tn_x")), bits(near(ray.tmin, val("nearx"))));
    assert_eq!(bits(val("tn_xy")), bits(near(val("tn_x"), val("neary"))));
    assert_eq!(bits(val("tn_xyz")), bits(near(val("tn_xy"), val("nearz"))));
    assert_eq!(bits(val("tf_x")), bits(far(ray.tmax, val("farx"))));
    assert_eq!(bits(val("tf_xy")), bits(far(val("tf_x"), val("fary"))));
    assert_eq!(bits(val("tf_xyz")), bits(far(val("tf_xy"), val("farz"))));
    let (mut nw, mut fw) = (val("tn_xyz"), val("tf_xyz"));
    for _ in 0..sc.widen_ulps {
        nw = f.next_down(nw);
        fw = f.next_up(fw);
    }
    assert_eq!((bits(val("t_near")), bits(val("t_far"))), (bits(nw), bits(fw)));
    assert_eq!(flag("hit"), f.le(nw, fw));
    assert_eq!((out.hit, bits(out.t_near), bits(out.t_far)), (flag("hit"), bits(nw), bits(fw)));
}

/// Fixed point, plain variant: every disagreement with the exact decision (on the stored box)
/// lies within the derived band, or has a saturated reciprocal (|d| below 1/max, where 1 ⊘ d
/// saturates: the known hazard the directed variant removes). Band: the plane differences are
/// exact, 1 ⊘ d is off by at most one step s, the product by at most s more, so each axis's t is
/// within E = |b − o|·s + s of exact and a disagreement needs |t_far − t_near| <= 2·E_max.
#[test]
fn fixed_plain_disagreements_lie_within_the_derived_band() {
    for name in ["q8.24:divide", "q16.16:nearest+divide", "q12.20:divide"] {
        with_format!(fmt(name), |f| {
            let s = Slab::new(f, cfg(SlabNan::Ignore, DirPrep::Plain, 0));
            let step = f.ulp(0.0);
            let max = f.error_model().max;
            let mut r = SplitMix64::new(0x51ab_0007);
            let (mut n, mut wrong, mut saturated) = (0, 0, 0);
            for _ in 0..20_000 {
                let (o, d, tmax, lo, hi) = random_case(&mut r);
                let q = |x: f64| f.to_f64(f.from_f64(x));
                let (oq, dq) = (o.map(q), d.map(q));
                if o.iter().chain(d.iter()).any(|x| x.abs() >= max / 2.0) {
                    continue; // the ray does not fit the format
                }
                let Ok(b) = s.store_box(lo, hi) else { continue };
                let (bl, bh) = (b.min.map(|v| f.to_f64(v)), b.max.map(|v| f.to_f64(v)));
                // products beyond the range saturate: outside the model of the band
                let big = (0..3).any(|a| {
                    dq[a] != 0.0 && ((bl[a] - oq[a]) / dq[a]).abs().max(((bh[a] - oq[a]) / dq[a]).abs()) >= max / 2.0
                });
                if big {
                    continue;
                }
                let tq = q(tmax);
                let exact = slab_exact(oq, dq, 0.0, tq, bl, bh);
                let hit = s.test(&s.prepare(o, d, 0.0, tmax), &b).hit;
                n += 1;
                if hit == exact {
                    continue;
                }
                wrong += 1;
                if dq.iter().any(|&x| x == 0.0 || 1.0 / x.abs() >= max) {
                    saturated += 1;
                    continue;
                }
                let e =
                    (0..3).map(|a| (bl[a] - oq[a]).abs().max((bh[a] - oq[a]).abs()) * step + step).fold(0.0, f64::max);
                let g = golden::slab_f64(oq, dq, 0.0, tq, bl, bh);
                assert!(
                    (g.t_far - g.t_near).abs() <= 2.0 * e,
                    "{name}: disagreement outside the band: gap {} > 2·{e}; o {o:?} d {d:?} box {lo:?}..{hi:?}",
                    (g.t_far - g.t_near).abs()
                );
            }
            assert!(n > 10_000, "{name}: too few cases ({n})");
            eprintln!("{name}: {n} cases, {wrong} disagreements, {saturated} with a saturated reciprocal");
        });
    }
}
