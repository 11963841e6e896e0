//! The RTI model against its own contract: every recorded stage signal equals the stage table's
//! operation on its recorded operands; probing changes nothing; batch = scalar bit for bit;
//! packet = leaf = a plain min-capture loop; tie rules, culling, threshold and NaN policy.

mod common;

use datapath::format::DivMode;
use datapath::probe::{NoProbe, Recorder, Signal};
use datapath::rng::SplitMix64;
use datapath::rti::{
    stage_count, stage_table, Capture, Cull, HitsSoa, Op, Ray, RaysSoa, Rti, RtiConfig, TieRule, Tri, TrisSoa,
    RTI_INPUTS,
};
use datapath::{with_format, Format};

const SEED: u64 = 0x0071_0002;

fn build<F: Format>(f: &F, raw: &[u64; 17]) -> (Ray<F::V>, Tri<F::V>) {
    let v = |i: usize| f.from_bits(raw[i]);
    let ray = Ray { o: [v(0), v(1), v(2)], d: [v(3), v(4), v(5)], tmin: v(6), tmax: v(7) };
    let tri = Tri { v: [[v(8), v(9), v(10)], [v(11), v(12), v(13)], [v(14), v(15), v(16)]] };
    (ray, tri)
}

fn check_trace<F: Format>(rti: &Rti<F>, raw: &[u64; 17]) -> Result<(), String> {
    let f = &rti.fmt;
    let (ray, tri) = build(f, raw);
    let mut rec = Recorder::new();
    let out = rti.trace(&ray, &tri, &mut rec);
    let table = stage_table(f.div_mode());
    let names: Vec<&str> = rec.signals.iter().map(|(n, _)| *n).collect();
    let want: Vec<&str> = table.iter().map(|d| d.name).collect();
    if names != want {
        return Err(format!("recorded signals {names:?} differ from the stage table {want:?}"));
    }
    let lookup = |n: &str| -> F::V {
        if n == "one" {
            return f.one();
        }
        if let Some(i) = RTI_INPUTS.iter().position(|x| *x == n) {
            return f.from_bits(raw[i]);
        }
        rec.value(n).unwrap_or_else(|| panic!("operand {n} neither input nor earlier signal"))
    };
    let bits = |v: F::V| f.to_bits(v);
    let flag = |n: &str| rec.flag(n).unwrap();
    for d in &table {
        let expect = match d.op {
            Op::Sub => Signal::Value(f.sub(lookup(d.a), lookup(d.b))),
            Op::Add => Signal::Value(f.add(lookup(d.a), lookup(d.b))),
            Op::Mul => Signal::Value(f.mul(lookup(d.a), lookup(d.b))),
            Op::Div => Signal::Value(f.div(lookup(d.a), lookup(d.b))),
            Op::Logic => {
                let z = f.zero();
                let det = lookup("det");
                let pos = f.lt(z, det);
                let sign_ok = |x: F::V| if pos { f.le(z, x) } else { f.le(x, z) };
                Signal::Flag(match d.name {
                    "det_ok" => match rti.cull {
                        Cull::TwoSided => f.lt(rti.det_thr, f.abs(det)),
                        Cull::Backface => f.lt(rti.det_thr, det),
                    },
                    "u_ok" => sign_ok(lookup("up")),
                    "v_ok" => sign_ok(lookup("vp")),
                    "uv_ok" => {
                        if pos {
                            f.le(lookup("uv"), det)
                        } else {
                            f.le(det, lookup("uv"))
                        }
                    }
                    "t_ok" => sign_ok(lookup("tp")),
                    "valid" => flag("det_ok") & flag("u_ok") & flag("v_ok") & flag("uv_ok") & flag("t_ok"),
                    "tmin_ok" => f.le(ray.tmin, lookup("t")),
                    "tmax_ok" => f.le(lookup("t"), ray.tmax),
                    "hit" => flag("valid") & flag("tmin_ok") & flag("tmax_ok"),
                    other => return Err(format!("unknown logic signal {other}")),
                })
            }
        };
        let same = match (expect, rec.get(d.name).unwrap()) {
            (Signal::Value(a), Signal::Value(b)) => bits(a) == bits(b),
            (Signal::Flag(a), Signal::Flag(b)) => a == b,
            _ => false,
        };
        if !same {
            return Err(format!(
                "stage {} signal {}: recorded {:?}, table gives {:?}",
                d.stage,
                d.name,
                rec.get(d.name),
                expect
            ));
        }
    }
    // the outputs are the last-stage signals, and probing changed nothing
    let plain = rti.trace(&ray, &tri, &mut NoProbe);
    for (name, v, p) in [("t", out.t, plain.t), ("u", out.u, plain.u), ("v", out.v, plain.v)] {
        if bits(v) != bits(lookup(name)) || bits(v) != bits(p) {
            return Err(format!("output {name} differs from its stage signal or from the unprobed run"));
        }
    }
    if out.valid != flag("valid") || out.hit != flag("hit") || plain.hit != out.hit || plain.valid != out.valid {
        return Err("valid/hit differ from their stage signals or from the unprobed run".into());
    }
    Ok(())
}

#[test]
fn every_stage_signal_follows_the_stage_table() {
    let mut r = SplitMix64::new(SEED);
    for any in common::formats() {
        for cfg in [RtiConfig::default(), RtiConfig { cull: Cull::Backface, det_threshold: 1e-3, tie: TieRule::Last }] {
            with_format!(any, |f| {
                let rti = Rti::new(f, cfg);
                for _ in 0..3000 {
                    let raw = common::raw_inputs(&mut r, &any);
                    if let Err(e) = check_trace(&rti, &raw) {
                        panic!("{} {:?}: {e}\ninputs {:x?}", rti.fmt.name(), cfg, raw);
                    }
                }
            });
        }
    }
}

#[test]
fn stage_table_has_the_51_operations_plus_the_uv_add() {
    for div in [DivMode::RecipMul, DivMode::Divide] {
        let t = stage_table(div);
        let count = |op: Op| t.iter().filter(|d| d.op == op).count();
        let (adds, subs, muls, divs) = (count(Op::Add), count(Op::Sub), count(Op::Mul), count(Op::Div));
        assert_eq!(subs, 9 + 6, "9 edge/origin subtracts + 6 cross-product subtracts");
        assert_eq!(adds, 8 + 1, "8 dot-product adds + u'+v'");
        match div {
            DivMode::RecipMul => assert_eq!((muls, divs), (12 + 12 + 3, 1)),
            DivMode::Divide => assert_eq!((muls, divs), (12 + 12, 3)),
        }
        if div == DivMode::RecipMul {
            assert_eq!(adds + subs + muls + divs, 52, "the classic 51 + the u'+v' add of the division-free test");
        }
        // the valid bit is decided before any division
        let valid_stage = t.iter().find(|d| d.name == "valid").unwrap().stage;
        assert!(t.iter().filter(|d| d.op == Op::Div).all(|d| d.stage > valid_stage));
        // the latency the vector manifests state: the table's last stage (documented: 10 with
        // the reciprocal, 9 with the divider)
        assert_eq!(stage_count(div), t.iter().map(|d| d.stage).max().unwrap());
        assert_eq!(stage_count(div), if div == DivMode::RecipMul { 10 } else { 9 });
    }
}

#[test]
fn batch_equals_scalar_bit_for_bit() {
    let mut r = SplitMix64::new(SEED ^ 1);
    for any in common::formats() {
        with_format!(any, |f| {
            let rti = Rti::new(f, RtiConfig::default());
            let (mut rays, mut tris) = (RaysSoa::default(), TrisSoa::default());
            let mut scalar = Vec::new();
            for _ in 0..5000 {
                let (ray, tri) = build(&rti.fmt, &common::raw_inputs(&mut r, &any));
                rays.push(&ray);
                tris.push(&tri);
                scalar.push(rti.test(&ray, &tri));
            }
            let mut out = HitsSoa::with_len(rays.len());
            rti.batch(&rays, &tris, &mut out);
            let b = |v| rti.fmt.to_bits(v);
            for (i, s) in scalar.iter().enumerate() {
                assert_eq!(
                    (out.hit[i], out.valid[i], b(out.t[i]), b(out.u[i]), b(out.v[i])),
                    (s.hit, s.valid, b(s.t), b(s.u), b(s.v)),
                    "{} case {i}",
                    rti.fmt.name()
                );
            }
        });
    }
}

#[test]
fn packet_equals_leaf_equals_a_plain_min_capture_loop() {
    let mut r = SplitMix64::new(SEED ^ 2);
    for any in common::formats() {
        with_format!(any, |f| {
            for tie in [TieRule::First, TieRule::Last] {
                let rti = Rti::new(f, RtiConfig { tie, ..RtiConfig::default() });
                let mut tris = TrisSoa::default();
                let mut plain_tris = Vec::new();
                for _ in 0..40 {
                    let (_, t) = common::aimed_case(&mut r);
                    let t = rti.tri(t.v);
                    tris.push(&t);
                    plain_tris.push(t);
                    if r.below(4) == 0 {
                        tris.push(&t); // an exact duplicate: a tie
                        plain_tris.push(t);
                    }
                }
                let mut rays = RaysSoa::default();
                for _ in 0..16 {
                    let (ray, _) = common::aimed_case(&mut r);
                    rays.push(&rti.ray(ray.o, ray.d, ray.tmin, ray.tmax));
                }
                let mut caps = vec![Capture::default(); rays.len()];
                rti.packet(&rays, &tris, 100, &mut caps);
                let b = |v| rti.fmt.to_bits(v);
                for (k, cap) in caps.iter().enumerate() {
                    let ray = rays.get(k);
                    let leaf = rti.leaf(&ray, &tris, 100);
                    // a plain loop written from the tie rule
                    let mut best: Option<(u32, f64)> = None;
                    for (i, t) in plain_tris.iter().enumerate() {
                        let o = rti.test(&ray, t);
                        if !o.hit {
                            continue;
                        }
                        let tv = rti.fmt.to_f64(o.t);
                        let take = match best {
                            None => true,
                            Some((_, bt)) => match tie {
                                TieRule::First => tv < bt,
                                TieRule::Last => tv <= bt,
                            },
                        };
                        if take {
                            best = Some((100 + i as u32, tv));
                        }
                    }
                    assert_eq!((cap.hit, cap.id, b(cap.t)), (leaf.hit, leaf.id, b(leaf.t)), "packet vs leaf");
                    assert_eq!(cap.hit, best.is_some());
                    if let Some((id, _)) = best {
                        assert_eq!(cap.id, id, "{} {tie:?}", rti.fmt.name());
                    }
                }
            }
        });
    }
}

#[test]
fn tie_rule_picks_the_first_or_last_of_equal_hits() {
    for any in common::formats() {
        with_format!(any, |f| {
            for (tie, want) in [(TieRule::First, 0), (TieRule::Last, 2)] {
                let rti = Rti::new(f, RtiConfig { tie, ..RtiConfig::default() });
                let tri = rti.tri([[-0.5, -0.5, 0.25], [0.5, -0.5, 0.25], [0.0, 0.5, 0.25]]);
                let mut tris = TrisSoa::default();
                for _ in 0..3 {
                    tris.push(&tri);
                }
                let ray = rti.ray([0.0, 0.0, 1.0], [0.0, 0.0, -1.0], 0.0, f64::INFINITY);
                let c = rti.leaf(&ray, &tris, 0);
                assert!(c.hit);
                assert_eq!(c.id, want, "{} {tie:?}", rti.fmt.name());
                assert_eq!(rti.fmt.to_f64(c.t), 0.75);
            }
        });
    }
}

#[test]
fn culling_and_det_threshold() {
    for any in common::formats() {
        with_format!(any, |f| {
            // counter-clockwise seen from +z: normal +z; a ray going -z sees the front face
            let v = [[-0.5, -0.5, 0.0], [0.5, -0.5, 0.0], [0.0, 0.5, 0.0]];
            let two = Rti::new(f, RtiConfig::default());
            let cull = Rti::new(f, RtiConfig { cull: Cull::Backface, ..RtiConfig::default() });
            let down = two.ray([0.0, 0.0, 1.0], [0.0, 0.0, -1.0], 0.0, f64::INFINITY);
            let up = two.ray([0.0, 0.0, -1.0], [0.0, 0.0, 1.0], 0.0, f64::INFINITY);
            let t = two.tri(v);
            assert!(two.test(&down, &t).hit && two.test(&up, &t).hit, "{}", two.fmt.name());
            assert!(cull.test(&down, &t).hit && !cull.test(&up, &t).hit, "{}", cull.fmt.name());
            // det = e1·(d × e2) = 1 here; a threshold of 2 rejects it, 0.5 keeps it
            let hi = Rti::new(f, RtiConfig { det_threshold: 2.0, ..RtiConfig::default() });
            let lo = Rti::new(f, RtiConfig { det_threshold: 0.5, ..RtiConfig::default() });
            assert!(!hi.test(&down, &t).hit && lo.test(&down, &t).hit, "{}", hi.fmt.name());
            // behind the origin and outside the t interval
            let behind = two.ray([0.0, 0.0, -1.0], [0.0, 0.0, -1.0], 0.0, f64::INFINITY);
            assert!(!two.test(&behind, &t).hit);
            let short = two.ray([0.0, 0.0, 1.0], [0.0, 0.0, -1.0], 0.0, 0.5);
            let o = two.test(&short, &t);
            assert!(o.valid && !o.hit);
        });
    }
}

#[test]
fn nan_in_any_input_never_hits() {
    for any in common::formats().into_iter().filter(|f| f.name().starts_with(['f', 'b', 'e'])) {
        with_format!(any, |f| {
            let rti = Rti::new(f, RtiConfig::default());
            let nan = rti.fmt.from_f64(f64::NAN);
            let good = rti.ray([0.1, 0.1, 1.0], [0.0, 0.0, -1.0], 0.0, f64::INFINITY);
            let tri = rti.tri([[-0.5, -0.5, 0.0], [0.5, -0.5, 0.0], [0.0, 0.5, 0.0]]);
            assert!(rti.test(&good, &tri).hit);
            for (i, input) in RTI_INPUTS.iter().enumerate() {
                let (mut ray, mut t) = (good, tri);
                match i {
                    0..=2 => ray.o[i] = nan,
                    3..=5 => ray.d[i - 3] = nan,
                    6 => ray.tmin = nan,
                    7 => ray.tmax = nan,
                    _ => t.v[(i - 8) / 3][(i - 8) % 3] = nan,
                }
                assert!(!rti.test(&ray, &t).hit, "{}: NaN in input {} hits", rti.fmt.name(), input);
            }
        });
    }
}

/// The structure-of-arrays columns: resize fills every column, set writes lane i of every
/// column (get reads it back), fill writes every lane, len / is_empty follow.
#[test]
fn soa_columns_resize_set_get() {
    let ray = |k: u32| Ray { o: [k, k + 1, k + 2], d: [k + 3, k + 4, k + 5], tmin: k + 6, tmax: k + 7 };
    let mut rs = RaysSoa::<u32>::default();
    assert!(rs.is_empty());
    rs.resize(3, 9);
    assert_eq!((rs.len(), rs.is_empty()), (3, false));
    assert!([&rs.o[0], &rs.o[1], &rs.o[2], &rs.d[0], &rs.d[1], &rs.d[2], &rs.tmin, &rs.tmax]
        .iter()
        .all(|c| c.as_slice() == [9, 9, 9]));
    rs.set(1, &ray(10));
    let g = rs.get(1);
    assert_eq!((g.o, g.d, g.tmin, g.tmax), ([10, 11, 12], [13, 14, 15], 16, 17));
    assert_eq!(rs.get(0).o, [9, 9, 9]);
    // fill: every lane as set writes it, the length kept
    rs.fill(&ray(30));
    assert_eq!(rs.len(), 3);
    for i in 0..3 {
        let g = rs.get(i);
        assert_eq!((g.o, g.d, g.tmin, g.tmax), ([30, 31, 32], [33, 34, 35], 36, 37), "lane {i}");
    }
    let tri = |k: u32| Tri { v: [[k, k + 1, k + 2], [k + 3, k + 4, k + 5], [k + 6, k + 7, k + 8]] };
    let mut ts = TrisSoa::<u32>::default();
    assert!(ts.is_empty());
    ts.resize(2, 5);
    assert_eq!((ts.len(), ts.is_empty()), (2, false));
    assert!(ts.v.iter().flatten().all(|c| c.as_slice() == [5, 5]));
    ts.set(0, &tri(20));
    assert_eq!(ts.get(0).v, tri(20).v);
    assert_eq!(ts.get(1).v, [[5; 3]; 3]);
    let mut hs = HitsSoa::<u32>::with_len(0);
    assert!(hs.is_empty());
    hs.resize(4);
    assert_eq!((hs.len(), hs.is_empty()), (4, false));
    assert_eq!((hs.hit.len(), hs.valid.len(), hs.t.len(), hs.u.len(), hs.v.len()), (4, 4, 4, 4, 4));
}
