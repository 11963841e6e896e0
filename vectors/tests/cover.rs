//! Coverage of vector sets: counts merge exactly (two halves merged = one pass), no bin the
//! model marks unreachable is ever hit by the default sets, and the op unit's default sets
//! reach every reachable bin.

use vectors::cover::Coverage;
use vectors::gen::{generate, Request, Unit};
use vectors::read::set_rows;

fn req(unit: Unit, format: &str) -> Request {
    let mut r = Request::new(unit, format.parse().unwrap());
    r.count = 4;
    r.seed = 3;
    r.command = "test".into();
    r.slab_variant = if format.contains("ftz") || format.starts_with('q') { "plain" } else { "conservative" }.into();
    r
}

#[test]
fn halves_merged_equal_one_pass() {
    for (unit, format) in [(Unit::Rti, "fp16"), (Unit::Slab, "f32"), (Unit::Op, "bf16"), (Unit::Capture, "fp16")] {
        let set = generate(&req(unit, format)).unwrap();
        let rows = set_rows(&set).unwrap();
        let n = rows[0].len();
        let whole = Coverage::measure(&set.manifest, &rows).unwrap();
        let mut a = Coverage::model(&set.manifest);
        a.add_rows(&set.manifest, &rows, 0..n / 3).unwrap();
        let mut b = Coverage::model(&set.manifest);
        b.add_rows(&set.manifest, &rows, n / 3..n).unwrap();
        a.merge(&b).unwrap();
        assert_eq!(a, whole, "{unit:?} {format}");
        assert_eq!(whole.vectors as usize, n);
        // merging another format's coverage is refused
        let other = generate(&req(unit, "f32:ftz")).unwrap();
        let oc = Coverage::measure(&other.manifest, &set_rows(&other).unwrap()).unwrap();
        assert!(a.merge(&oc).is_err());
    }
}

#[test]
fn unreachable_bins_are_never_hit_and_op_sets_reach_every_other_bin() {
    for format in ["fp16", "f32", "bf16", "fp16:ftz", "f32:ftz+propagate", "e5m6:divide", "q8.24:divide", "q16.16"] {
        for unit in [Unit::Rti, Unit::Slab, Unit::Op, Unit::Capture] {
            if unit == Unit::Op && (format.starts_with("e5") || format.starts_with('q')) {
                continue;
            }
            let set = generate(&Request { count: 8, ..req(unit, format) }).unwrap();
            let c = Coverage::measure(&set.manifest, &set_rows(&set).unwrap()).unwrap();
            assert!(c.contradictions().is_empty(), "{unit:?} {format}: {:?}", c.contradictions());
            let (hit, bins) = c.totals();
            assert!(hit > 0 && hit <= bins);
            // every compare coverpoint of the unit is there, with its four outcomes
            let compares = c.coverpoints.iter().filter(|p| p.kind == "compare").count();
            // (rti: u_ok, v_ok, uv_ok, t_ok, tmin_ok, tmax_ok; op: a vs b under lt / le)
            let want = match unit {
                Unit::Rti => 6,
                Unit::Slab => 7,
                Unit::Op => 1,
                _ => 0,
            };
            assert_eq!(compares, want, "{unit:?} {format}");
            if unit == Unit::Op && !format.contains("ftz") {
                assert_eq!(hit, bins, "{format}: the op sets reach every reachable bin");
            }
        }
    }
}

/// Compare outcomes on hand-made slab rows (fp16, plain): a ray along +x from the origin, the
/// box's x slab [1, 2] (hit: t_near 1 < t_far 2), [1, 1] (1 = 1), [2, 1] (2 > 1), and tmin NaN
/// (the near selects compare NaN: unordered).
#[test]
fn compare_outcomes_by_hand() {
    let (one, two, nan, inf, m1) = (0x3c00u64, 0x4000, 0x7e00, 0x7c00, 0xbc00);
    let row = |tmin: u64, lo: u64, hi: u64| vec![0, 0, 0, one, 0, 0, tmin, inf, lo, m1, m1, hi, one, one];
    let ex = vectors::gen::Explicit {
        class: "hand".into(),
        covers: "hand-made rows".into(),
        origin: "test".into(),
        rows: vec![row(0, one, two), row(0, one, one), row(0, two, one), row(nan, one, two)],
    };
    let set =
        generate(&Request { explicit: Some(ex), slab_variant: "plain".into(), ..req(Unit::Slab, "fp16") }).unwrap();
    let c = Coverage::measure(&set.manifest, &set_rows(&set).unwrap()).unwrap();
    let counts = |sig: &str| -> Vec<u64> {
        c.coverpoints.iter().find(|p| p.signal.starts_with(sig)).unwrap().bins.iter().map(|b| b.count).collect()
    };
    // hit (t_near vs t_far): rows 1..3 give <, =, >; in row 4 the select keeps its NaN
    // accumulator (it takes x only when acc < x, false with a NaN), so t_near is NaN: unordered
    assert_eq!(counts("hit ("), [1, 1, 1, 1]);
    // tn_x (tmin vs nearx): 0 < 1 in rows 1..2, 0 < 2 in row 3, NaN in row 4
    assert_eq!(counts("tn_x ("), [3, 0, 0, 1]);
}

/// The default level-1 sets closed (`vectors --close`, default seed 1 and 64 per class): every
/// reachable bin of rti, each slab variant, op and capture in fp16 and f32, no bin marked
/// unreachable hit.
#[test]
fn closed_default_sets_reach_every_reachable_bin_in_fp16_and_f32() {
    for format in ["fp16", "f32"] {
        for (unit, variant) in [
            (Unit::Rti, "plain"),
            (Unit::Slab, "plain"),
            (Unit::Slab, "conservative"),
            (Unit::Slab, "take-on-false"),
            (Unit::Slab, "embree"),
            (Unit::Op, "plain"),
            (Unit::Capture, "plain"),
        ] {
            let r = Request { count: 64, seed: 1, slab_variant: variant.into(), ..req(unit, format) };
            let c = vectors::close::close(&r, vectors::close::DEFAULT_BUDGET).unwrap();
            let m = c.coverage.contradictions();
            assert!(m.is_empty(), "{unit:?} {variant} {format}: {m:?}");
            let (hit, bins) = c.coverage.totals();
            assert_eq!(hit, bins, "{unit:?} {variant} {format}: {} of {} bins", hit, bins);
            assert!(c.after.0 >= c.before.0);
        }
    }
}

/// The RTI unit's options change what is reachable after `valid` (backface culling: 1/det is
/// positive; a det threshold > 0: 1/det finite) and the capture unit's tie rule changes its
/// outputs: the closed fp16 sets with each option still reach every reachable bin.
#[test]
fn closed_sets_with_rti_options_reach_every_reachable_bin() {
    use datapath::rti::{Cull, RtiConfig, TieRule};
    let thr = RtiConfig { det_threshold: 0.001, ..RtiConfig::default() };
    for (unit, rti) in [
        (Unit::Rti, RtiConfig { cull: Cull::Backface, ..RtiConfig::default() }),
        (Unit::Rti, thr),
        (Unit::Rti, RtiConfig { cull: Cull::Backface, ..thr }),
        (Unit::Capture, RtiConfig { tie: TieRule::Last, ..RtiConfig::default() }),
    ] {
        let r = Request { count: 64, seed: 1, rti, ..req(unit, "fp16") };
        let c = vectors::close::close(&r, vectors::close::DEFAULT_BUDGET).unwrap();
        assert!(c.coverage.contradictions().is_empty(), "{unit:?} {rti:?}: {:?}", c.coverage.contradictions());
        let (hit, bins) = c.coverage.totals();
        assert_eq!(hit, bins, "{unit:?} {rti:?}: {hit} of {bins} bins");
    }
}

/// The closure's search hunts for the bins the model marks unreachable in the other formats
/// too (a hit one is a wrong reason): none is hit, and closing never loses coverage.
#[test]
fn the_closure_search_hits_no_unreachable_bin_in_other_formats() {
    for format in
        ["bf16", "e8m16", "e5m6:divide", "fp16:ftz", "f32:ftz+propagate", "q8.24", "q8.8:divide", "q16.16:wrap"]
    {
        for (unit, variant) in
            [(Unit::Rti, "plain"), (Unit::Slab, "plain"), (Unit::Slab, "embree"), (Unit::Capture, "plain")]
        {
            let r = Request { count: 16, slab_variant: variant.into(), ..req(unit, format) };
            let c = vectors::close::close(&r, 24_576).unwrap();
            let m = c.coverage.contradictions();
            assert!(m.is_empty(), "{unit:?} {variant} {format}: {m:?}");
            assert!(c.after.0 >= c.before.0, "{unit:?} {variant} {format}");
        }
    }
    let r = Request { slab_variant: "conservative".into(), ..req(Unit::Slab, "e5m6") };
    let c = vectors::close::close(&r, 24_576).unwrap();
    assert!(c.coverage.contradictions().is_empty(), "{:?}", c.coverage.contradictions());
}

/// Each row of the close class reaches a bin no earlier row of the set reached (the class
/// coverpoint aside), the closure does not depend on the thread count, and the closed set's
/// rows before the class are the request's set unchanged.
#[test]
fn every_closure_row_adds_a_bin_and_the_closure_is_deterministic() {
    let r = Request { count: 8, ..req(Unit::Rti, "fp16") };
    let c = vectors::close::close(&r, 40_960).unwrap();
    assert!(c.kept > 0);
    let m = &c.set.manifest;
    let close = m.closure.as_ref().expect("the closure is in the manifest");
    assert_eq!(close.class as usize, m.classes.len() - 1);
    assert_eq!(m.classes.last().unwrap().name, "close");
    assert_eq!(m.classes.last().unwrap().count, c.kept);
    let rows = set_rows(&c.set).unwrap();
    let n = rows[0].len();
    let base = n - c.kept;
    let plain = generate(&r).unwrap();
    assert_eq!(set_rows(&plain).unwrap()[0], rows[0][..base].to_vec());
    let mut cov = Coverage::model(m);
    cov.add_rows(m, &rows, 0..base).unwrap();
    for row in base..n {
        let before: Vec<Vec<u64>> = cov
            .coverpoints
            .iter()
            .filter(|p| p.kind != "class")
            .map(|p| p.bins.iter().map(|b| b.count).collect())
            .collect();
        cov.add_rows(m, &rows, row..row + 1).unwrap();
        let after: Vec<Vec<u64>> = cov
            .coverpoints
            .iter()
            .filter(|p| p.kind != "class")
            .map(|p| p.bins.iter().map(|b| b.count).collect())
            .collect();
        let new = before.iter().flatten().zip(after.iter().flatten()).any(|(b, a)| *b == 0 && *a > 0);
        assert!(new, "close row {} reaches no new bin", row - base);
    }
    let two = vectors::close::close(&Request { threads: 2, ..r.clone() }, 40_960).unwrap();
    assert_eq!(two.set.files, c.set.files);
    // a closed set is not closed again, a traverse set not at all
    assert!(vectors::close::close(&Request { closure: m.closure.as_ref().map(|_| explicit_close()), ..r }, 10).is_err());
}

fn explicit_close() -> vectors::gen::Explicit {
    vectors::gen::Explicit { class: "close".into(), covers: String::new(), origin: "test".into(), rows: Vec::new() }
}

/// Cancellation depth and slab events on hand-made rows. RTI fp16: v0 = (p1, -1, 0.5),
/// v1 = (1, 1, 2), v2 = (1.5, -1, 3), o = (1.25, 0, 0) with p1 = 1 - 2^-11 gives e1x = 2^-11
/// (11 bits lost), e1y = 1 + 1 (same signs), e1z = 1.5 (1 bit), e2x ~ 0.5 (1 bit), e2y = 0
/// (exact zero), e2z = 2.5 (0 bits), sx ~ 0.25 (2 bits); slab: the box x slabs of
/// `compare_outcomes_by_hand` against the origin 0.
#[test]
fn cancellation_and_events_by_hand() {
    let row = vec![
        0x3d00, 0, 0, 0, 0, 0x3c00, 0, 0x7c00, 0x3bff, 0xbc00, 0x3800, 0x3c00, 0x3c00, 0x4000, 0x3e00, 0xbc00, 0x4200,
    ];
    let ex =
        vectors::gen::Explicit { class: "hand".into(), covers: String::new(), origin: "test".into(), rows: vec![row] };
    let set = generate(&Request { closure: Some(ex), ..req(Unit::Rti, "fp16") }).unwrap();
    let rows = set_rows(&set).unwrap();
    let n = rows[0].len();
    let mut c = Coverage::model(&set.manifest);
    c.add_rows(&set.manifest, &rows, n - 1..n).unwrap();
    let bin = |sig: &str| -> usize {
        let p = c.coverpoints.iter().find(|p| p.kind == "cancellation" && p.signal == format!("{sig} (sub)")).unwrap();
        let hit: Vec<usize> = p.bins.iter().enumerate().filter(|(_, b)| b.count > 0).map(|(k, _)| k).collect();
        assert_eq!(hit.len(), 1, "{sig}: {hit:?}");
        hit[0]
    };
    assert_eq!(
        ["e1x", "e1y", "e1z", "e2x", "e2y", "e2z", "sx"].map(bin),
        [4, 0, 2, 2, 5, 1, 3],
        "bins: {:?}",
        vectors::cover::cancellation_bins(10)
    );
    // slab: origin 0 below each x slab [1, 2], [1, 1], [2, 1], [1, 2]; extents <, =, >, <
    let (one, two, inf, m1) = (0x3c00u64, 0x4000, 0x7c00, 0xbc00);
    let srow = |lo: u64, hi: u64| vec![0, 0, 0, one, 0, 0, 0, inf, lo, m1, m1, hi, one, one];
    let ex = vectors::gen::Explicit {
        class: "hand".into(),
        covers: String::new(),
        origin: "test".into(),
        rows: vec![srow(one, two), srow(one, one), srow(two, one), srow(0, two)],
    };
    let set =
        generate(&Request { explicit: Some(ex), slab_variant: "plain".into(), ..req(Unit::Slab, "fp16") }).unwrap();
    let c = Coverage::measure(&set.manifest, &set_rows(&set).unwrap()).unwrap();
    let counts = |sig: &str| -> Vec<u64> {
        c.coverpoints.iter().find(|p| p.signal == sig).unwrap().bins.iter().map(|b| b.count).collect()
    };
    assert_eq!(counts("origin against the box, axis x"), [3, 1, 0, 0, 0, 0]);
    assert_eq!(counts("box extent, axis x"), [2, 1, 1, 0]);
    assert_eq!(counts("origin against the box, axis y"), [0, 0, 4, 0, 0, 0]);
    // hits on [1, 2] and [0, 2] enter before they leave, [1, 1] touches, [2, 1] misses
    assert_eq!(counts("a hit's entry against its exit (tn_xyz vs tf_xyz)"), [2, 1, 0]);
    // RTI fp16, the triangle v0 = 0, v1 = (1, 0, 0), v2 = (0, 0, 1) and a ray along +y from
    // o: u = o.x, v = o.z, t = -o.y. A: o = 0 (the vertex v0, t = tmin = 0); B: o = (0.25, -2,
    // 0.5); C: o = (1, -2, 0) (the vertex v1); D: B with tmax = 2
    let rrow = |o: [u64; 3], tmax: u64| vec![o[0], o[1], o[2], 0, one, 0, 0, tmax, 0, 0, 0, one, 0, 0, 0, 0, one];
    let (q, h, m2) = (0x3400u64, 0x3800u64, 0xc000u64);
    let ex = vectors::gen::Explicit {
        class: "hand".into(),
        covers: String::new(),
        origin: "test".into(),
        rows: vec![rrow([0, 0, 0], inf), rrow([q, m2, h], inf), rrow([one, m2, 0], inf), rrow([q, m2, h], two)],
    };
    let set = generate(&Request { closure: Some(ex), ..req(Unit::Rti, "fp16") }).unwrap();
    let rows = set_rows(&set).unwrap();
    let n = rows[0].len();
    let mut c = Coverage::model(&set.manifest);
    c.add_rows(&set.manifest, &rows, n - 4..n).unwrap();
    let counts = |sig: &str| -> Vec<u64> {
        c.coverpoints.iter().find(|p| p.signal == sig).unwrap().bins.iter().map(|b| b.count).collect()
    };
    assert_eq!(counts("u of a valid hit"), [1, 2, 1, 0]);
    assert_eq!(counts("v of a valid hit"), [2, 2, 0, 0]);
    assert_eq!(counts("t of a valid hit against tmin and tmax"), [1, 2, 1, 0]);
}

/// Reading a written set row by row (`measure_dir`, what `raypipe cover` does) gives the
/// coverage of the set in memory; a changed data file is refused.
#[test]
fn streaming_a_set_from_disk_equals_measuring_it_in_memory() {
    let tmp = std::env::temp_dir().join(format!("raypipe-measure-dir-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&tmp);
    for (unit, format) in [(Unit::Rti, "fp16"), (Unit::Slab, "f32"), (Unit::Capture, "bf16"), (Unit::Op, "fp16")] {
        let set = generate(&req(unit, format)).unwrap();
        let dir = tmp.join(format!("{unit:?}"));
        vectors::write::write_set(&set, &dir).unwrap();
        let text = std::fs::read_to_string(dir.join("manifest.json")).unwrap();
        let m: vectors::manifest::Manifest = serde_json::from_str(&text).unwrap();
        let from_disk = Coverage::measure_dir(&dir, &m).unwrap();
        let in_memory = Coverage::measure(&set.manifest, &set_rows(&set).unwrap()).unwrap();
        assert_eq!(from_disk, in_memory, "{unit:?} {format}");
        // one digit changed in the inputs: the hash no longer matches
        let f = dir.join(&m.files[0].name);
        let mut t = std::fs::read_to_string(&f).unwrap().into_bytes();
        t[2] = if t[2] == b'0' { b'1' } else { b'0' };
        std::fs::write(&f, t).unwrap();
        assert!(Coverage::measure_dir(&dir, &m).unwrap_err().contains("sha256"), "{unit:?}");
    }
    let _ = std::fs::remove_dir_all(&tmp);
}

/// Merging: another slab variant (same unit, format and shape of bins) is refused by its
/// options; a closed set merges with an unclosed one, the class bins by name; a coverage file
/// holds several models and reads back equal, and a version-1 file (one model) still reads.
#[test]
fn options_classes_and_coverage_files() {
    let plain = generate(&Request { slab_variant: "plain".into(), ..req(Unit::Slab, "fp16") }).unwrap();
    let tof = generate(&Request { slab_variant: "take-on-false".into(), ..req(Unit::Slab, "fp16") }).unwrap();
    let cp = Coverage::measure(&plain.manifest, &set_rows(&plain).unwrap()).unwrap();
    let ct = Coverage::measure(&tof.manifest, &set_rows(&tof).unwrap()).unwrap();
    let err = cp.clone().merge(&ct).unwrap_err();
    assert!(err.contains("variant"), "{err}");
    // closed and unclosed: the sum has the class `close` with the closed set's count
    let open = generate(&req(Unit::Rti, "fp16")).unwrap();
    let row = vec![
        0x3d00, 0, 0, 0, 0, 0x3c00, 0, 0x7c00, 0x3bff, 0xbc00, 0x3800, 0x3c00, 0x3c00, 0x4000, 0x3e00, 0xbc00, 0x4200,
    ];
    let ex = vectors::gen::Explicit { rows: vec![row], ..explicit_close() };
    let closed = generate(&Request { closure: Some(ex), ..req(Unit::Rti, "fp16") }).unwrap();
    let co = Coverage::measure(&open.manifest, &set_rows(&open).unwrap()).unwrap();
    let cc = Coverage::measure(&closed.manifest, &set_rows(&closed).unwrap()).unwrap();
    let mut sum = co.clone();
    sum.merge(&cc).unwrap();
    let class = |c: &Coverage, name: &str| {
        let p = c.coverpoints.iter().find(|p| p.kind == "class").unwrap();
        p.bins.iter().find(|b| b.name == name).map(|b| b.count)
    };
    assert_eq!(class(&co, "close"), None);
    assert_eq!(class(&sum, "close"), class(&cc, "close"));
    assert_eq!(class(&cc, "close"), Some(1));
    assert_eq!(class(&sum, "random"), Some(class(&co, "random").unwrap() + class(&cc, "random").unwrap()));
    assert_eq!(sum.vectors, co.vectors + cc.vectors);
    // a file of two models reads back equal
    let text = vectors::cover_file::write(
        &[(plain.manifest.clone(), cp.clone()), (open.manifest.clone(), co.clone())],
        "test",
    );
    let back = vectors::cover_file::read(&text).unwrap();
    assert_eq!(back.len(), 2);
    assert_eq!((back[0].1.clone(), back[1].1.clone()), (cp.clone(), co.clone()));
    // version 1: manifest, vectors and counts at the top level
    let mut j: serde_json::Value = serde_json::from_str(&text).unwrap();
    let one = j["models"][1].take();
    let v1 = serde_json::json!({"kind": "raypipe coverage", "version": 1, "command": "t",
        "manifest": one["manifest"], "vectors": one["vectors"], "counts": one["counts"]});
    let back = vectors::cover_file::read(&v1.to_string()).unwrap();
    assert_eq!(back.len(), 1);
    assert_eq!(back[0].1, co);
    // counts that do not fit the manifest's model, an unknown version: errors
    let mut bad = v1.clone();
    bad["counts"][0] = serde_json::json!([1]);
    assert!(vectors::cover_file::read(&bad.to_string()).is_err());
    bad = v1;
    bad["version"] = 3.into();
    assert!(vectors::cover_file::read(&bad.to_string()).is_err());
}

/// Two levels, four leaves that are the same unit cube (every box of the tree is it): a ray
/// through the cube ties every pair of siblings.
fn stacked_tree() -> vectors::traverse::TreeInput {
    use datapath::bvh::NodeDesc;
    let (min, max) = ([0.0; 3], [1.0; 3]);
    let leaf = |id: u32| NodeDesc { children: None, leaf: id, min, max };
    let inner = |l: u32, r: u32| NodeDesc { children: Some([l, r]), leaf: 0, min, max };
    let nodes = vec![inner(1, 2), inner(3, 4), inner(5, 6), leaf(0), leaf(1), leaf(2), leaf(3)];
    vectors::traverse::TreeInput { name: "stacked".into(), nodes, root: 0 }
}

/// The traverse unit's path events by hand. A ray through the stacked cubes, N = 8: pass 1
/// takes the near (left) child at both levels (2 ties, near), pass 2 resumes level 1 (the
/// pass ended there: distance 0) and takes its far child (level 0 passed near), pass 3
/// resumes level 0 (from level 1: distance 1; far) and takes the new level 1 near, pass 4
/// resumes level 1 (distance 0) with level 0 in 11 (far, far): ties near 4, far 4. A ray
/// missing the root: no tie, no restart. The same counts streamed from disk.
#[test]
fn traverse_back_distances_and_ties_by_hand() {
    let f = |x: f64| (x as f32).to_bits() as u64;
    let through = [-1.0, 0.5, 0.5, 1.0, 0.0, 0.0, 0.0, f64::INFINITY].map(f).to_vec();
    let miss = [-1.0, 5.0, 0.5, 1.0, 0.0, 0.0, 0.0, f64::INFINITY].map(f).to_vec();
    let mut r = Request::new(Unit::Traverse, "f32".parse().unwrap());
    r.count = 1;
    r.command = "test".into();
    r.tree = Some(stacked_tree());
    r.leaves = 8;
    r.closure = Some(vectors::gen::Explicit { rows: vec![through, miss], ..explicit_close() });
    let set = generate(&r).unwrap();
    assert_eq!(set.manifest.params["levels"], 2);
    let rows = set_rows(&set).unwrap();
    let n = rows[0].len();
    let mut c = Coverage::model(&set.manifest);
    let counts = |c: &Coverage, sig: &str| -> Vec<u64> {
        c.coverpoints.iter().find(|p| p.signal.starts_with(sig)).unwrap().bins.iter().map(|b| b.count).collect()
    };
    c.add_rows(&set.manifest, &rows, n - 2..n - 1).unwrap();
    assert_eq!(counts(&c, "back-traversal distance"), [1, 1, 0, 0]);
    assert_eq!(counts(&c, "siblings both hit"), [0, 1, 1]);
    c.add_rows(&set.manifest, &rows, n - 1..n).unwrap();
    assert_eq!(counts(&c, "back-traversal distance"), [1, 1, 0, 0]);
    assert_eq!(counts(&c, "siblings both hit"), [1, 1, 1]);
    // two levels: a distance of 2 or more cannot happen, and the model says why
    let back = c.coverpoints.iter().find(|p| p.signal.starts_with("back-traversal")).unwrap();
    assert_eq!(back.bins.iter().map(|b| b.unreachable.is_some()).collect::<Vec<_>>(), [false, false, true, true]);
    // a lookup without the tree refuses a traverse row instead of counting nothing
    let mut hits = Vec::new();
    assert!(vectors::cover::RowBins::new(&set.manifest).hits(&rows, 0, &mut hits).unwrap_err().contains("tree"));
    // streamed from disk (the tree images read whole, the rays row by row): the same counts
    let dir = std::env::temp_dir().join(format!("raypipe-cover-traverse-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    vectors::write::write_set(&set, &dir).unwrap();
    let m: vectors::manifest::Manifest =
        serde_json::from_str(&std::fs::read_to_string(dir.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(Coverage::measure_dir(&dir, &m).unwrap(), Coverage::measure(&set.manifest, &rows).unwrap());
    let _ = std::fs::remove_dir_all(&dir);
}

/// The crosses after RTI's `valid`, by hand in fp16 (e1 = (2, 0, 0), e2 = (0, 2, 0) or
/// (1, 0, 0), (0, 1, 0); the algebra in `close.rs`'s templates): A, o = (0, 0, max/2), d = (0,
/// 0, -tiny): t' = 2 max = +inf, det = 4 tiny, 1/det = +inf, u' = 0, v' = -0 — valid, so t
/// crosses inf x inf and u, v zero x inf; B, o = (0, 0, 1), d = (0, tiny, -2^15): det = 2^15,
/// 1/det = 2^-15 (subnormal), t' = 1, u' = 0, v' = tiny — v crosses subnormal x subnormal,
/// t normal x subnormal, u zero x subnormal. A third row with det = 0 (not valid) counts in
/// none of them, and no bin the model marks unreachable is hit.
#[test]
fn crosses_after_valid_by_hand() {
    let (two, one, inf, half_max, tiny, neg) = (0x4000u64, 0x3c00u64, 0x7c00u64, 0x77ffu64, 1u64, 0x8000u64);
    let a = vec![0, 0, half_max, 0, 0, neg | tiny, 0, inf, 0, 0, 0, two, 0, 0, 0, two, 0];
    let b = vec![0, 0, one, 0, tiny, neg | 0x7800, 0, inf, 0, 0, 0, one, 0, 0, 0, one, 0];
    // d parallel to the triangle's plane (d = (1, 0, 0)): det = 0, not valid
    let c = vec![0, 0, one, one, 0, 0, 0, inf, 0, 0, 0, one, 0, 0, 0, one, 0];
    let ex = vectors::gen::Explicit { rows: vec![a, b, c], ..explicit_close() };
    let set = generate(&Request { closure: Some(ex), ..req(Unit::Rti, "fp16") }).unwrap();
    let rows = set_rows(&set).unwrap();
    let n = rows[0].len();
    let mut cov = Coverage::model(&set.manifest);
    cov.add_rows(&set.manifest, &rows, n - 3..n).unwrap();
    let hit = |sig: &str| -> Vec<String> {
        let p = cov.coverpoints.iter().find(|p| p.kind == "operand cross" && p.signal.starts_with(sig)).unwrap();
        assert!(p.bins.iter().all(|b| b.count == 0 || b.unreachable.is_none()), "{sig}: an unreachable bin hit");
        p.bins.iter().filter(|b| b.count > 0).map(|b| b.name.clone()).collect()
    };
    assert_eq!(hit("t (mul)"), ["normal x subnormal", "inf x inf"]);
    assert_eq!(hit("u (mul)"), ["zero x subnormal", "zero x inf"]);
    assert_eq!(hit("v (mul)"), ["zero x inf", "subnormal x subnormal"]);
    // what the model marks unreachable after valid, with the simple arguments
    let why = |sig: &str, bin: &str| {
        let p = cov.coverpoints.iter().find(|p| p.kind == "operand cross" && p.signal.starts_with(sig)).unwrap();
        p.bins.iter().find(|b| b.name == bin).unwrap().unreachable
    };
    assert_eq!(why("u (mul)", "inf x normal"), Some(vectors::cover::WHY_VALID_UV_INF_RECIP));
    assert_eq!(why("u (mul)", "normal x inf"), Some(vectors::cover::WHY_VALID_UV_TINY_DET));
    assert_eq!(why("t (mul)", "NaN x normal"), Some(vectors::cover::WHY_VALID_NUMBERS));
    assert_eq!(why("t (mul)", "inf x inf"), None);
}

/// Fixed-point operation events by hand, the op unit in q8.8 (divide mode, saturating; 1.0 is
/// 256 steps): 1 + 2 exact; 127 + 127 beyond the range (saturated); 0.5 x 0.5 exact (64
/// steps); 1 step x 1 step inexact (1/256 of a step); 1 / 3 inexact; 1 / 0 divide by zero. In
/// q8.8:wrap the same sum wraps; a sum is never inexact, and a saturating format never wraps.
#[test]
fn fixed_point_operation_events_by_hand() {
    let run = |format: &str, rows: Vec<Vec<u64>>| -> Vec<u64> {
        let k = rows.len();
        let ex = vectors::gen::Explicit { rows, ..explicit_close() };
        let set = generate(&Request { closure: Some(ex), ..req(Unit::Op, format) }).unwrap();
        let all = set_rows(&set).unwrap();
        let n = all[0].len();
        let mut c = Coverage::model(&set.manifest);
        c.add_rows(&set.manifest, &all, n - k..n).unwrap();
        assert!(c.contradictions().is_empty(), "{format}: {:?}", c.contradictions());
        let p = c.coverpoints.iter().find(|p| p.kind == "fixed-point event").unwrap();
        assert_eq!(p.bins.iter().map(|b| b.name.as_str()).collect::<Vec<_>>(), vectors::cover::FIXED_EVENT_BINS);
        p.bins.iter().map(|b| b.count).collect()
    };
    let (one, half, max) = (256u64, 128u64, 0x7fffu64);
    let (add, mul, div) = (0u64, 2u64, 3u64);
    let rows = vec![
        vec![add, one, 2 * one],
        vec![add, max, max],
        vec![mul, half, half],
        vec![mul, 1, 1],
        vec![div, one, 3 * one],
        vec![div, one, 0],
    ];
    // exact, inexact, saturated, wrapped, divide by zero
    assert_eq!(run("q8.8:divide", rows.clone()), [2, 2, 1, 0, 1]);
    assert_eq!(run("q8.8:divide+wrap", rows), [2, 2, 0, 1, 1]);
}

/// The op unit's compare outcome and operand crosses by hand (fp16): lt 1 < 2, le 2 = 2, lt
/// NaN (unordered), add 1 + inf (normal x inf), mul 0 x subnormal; the opcode coverpoint counts
/// each opcode. And RTI's sign tests (u_ok: 0 vs u'): the hand triangle of
/// `cancellation_and_events_by_hand` with u' = o.x = 0.25 (<), 0 (=), -0.25 (>).
#[test]
fn op_compares_crosses_and_rti_sign_tests_by_hand() {
    let (one, two, inf, nan, sub) = (0x3c00u64, 0x4000u64, 0x7c00u64, 0x7e00u64, 1u64);
    let rows = vec![vec![4, one, two], vec![5, two, two], vec![4, nan, one], vec![0, one, inf], vec![2, 0, sub]];
    let k = rows.len();
    let ex = vectors::gen::Explicit { rows, ..explicit_close() };
    let set = generate(&Request { closure: Some(ex), ..req(Unit::Op, "fp16") }).unwrap();
    let all = set_rows(&set).unwrap();
    let n = all[0].len();
    let mut c = Coverage::model(&set.manifest);
    c.add_rows(&set.manifest, &all, n - k..n).unwrap();
    let cp = |sig: &str| c.coverpoints.iter().find(|p| p.signal == sig).unwrap_or_else(|| panic!("{sig}"));
    let counts = |sig: &str| -> Vec<u64> { cp(sig).bins.iter().map(|b| b.count).collect() };
    assert_eq!(counts("cmp (a vs b, opcodes lt and le)"), [1, 1, 0, 1]);
    assert_eq!(counts("opcode"), [1, 0, 1, 0, 2, 1]);
    let hit =
        |sig: &str| -> Vec<String> { cp(sig).bins.iter().filter(|b| b.count > 0).map(|b| b.name.clone()).collect() };
    assert_eq!(hit("add: a x b"), ["normal x inf"]);
    assert_eq!(hit("mul: a x b"), ["zero x subnormal"]);
    assert_eq!(hit("lt: a x b"), ["normal x normal", "NaN x normal"]);
    // RTI: v0 = 0, v1 = (1, 0, 0), v2 = (0, 0, 1), d = (0, 1, 0): det = 1, u' = o.x
    let (q, mq) = (0x3400u64, 0xb400u64);
    let rrow = |ox: u64| vec![ox, 0xc000, 0, 0, one, 0, 0, inf, 0, 0, 0, one, 0, 0, 0, 0, one];
    let ex = vectors::gen::Explicit { rows: vec![rrow(q), rrow(0), rrow(mq)], ..explicit_close() };
    let set = generate(&Request { closure: Some(ex), ..req(Unit::Rti, "fp16") }).unwrap();
    let all = set_rows(&set).unwrap();
    let n = all[0].len();
    let mut c = Coverage::model(&set.manifest);
    c.add_rows(&set.manifest, &all, n - 3..n).unwrap();
    let p = c.coverpoints.iter().find(|p| p.signal == "u_ok (zero vs up)").unwrap();
    assert_eq!(p.bins.iter().map(|b| b.count).collect::<Vec<_>>(), [1, 1, 1, 0]);
}
