//! The stress suite at small counts: its guarantees hold per class (conservative variants never
//! miss in float formats with IEEE subnormals, the directed variant never misses in any
//! non-wrapping format), undecidable inputs are counted apart, and it is deterministic.

use raypipe::stress::{stress, StressConfig, RTI_STRESS, SLAB_STRESS};

fn cfg(formats: &[&str], variants: &[&str], count: usize) -> StressConfig {
    StressConfig::new(
        formats.iter().map(|f| f.parse().unwrap()).collect(),
        variants.iter().map(|v| v.to_string()).collect(),
        count,
        9,
    )
}

/// Every format the issue names, in every variant that promises conservativeness, across every
/// slab class (the edge classes included): zero false misses, and the classes are not vacuous.
#[test]
fn conservative_and_directed_slabs_never_miss_under_stress() {
    let formats = ["f32", "fp16", "bf16", "e8m16", "q8.24", "q16.16", "q1.15", "q1.31", "f32:ftz", "q8.24:divide"];
    let r = stress(&cfg(&formats, &["plain", "conservative", "directed"], 60)).unwrap();
    assert!(r.passed, "{:?}", r.slab.iter().filter(|x| x.conservative && x.false_misses > 0).collect::<Vec<_>>());
    // conservative is refused in fixed point and under FTZ; directed runs everywhere here
    let n_conservative = formats.iter().filter(|f| !f.starts_with('q') && !f.contains("ftz")).count();
    assert_eq!(r.slab.len(), (2 * formats.len() + n_conservative) * SLAB_STRESS.len());
    assert_eq!(r.refused.len(), formats.len() - n_conservative);
    for x in &r.slab {
        if x.variant != "plain" {
            assert!(x.conservative, "{x:?}");
            assert_eq!(x.false_misses, 0, "{x:?}");
        }
        let float = !x.format.starts_with('q');
        if x.class == "inf_nan" && float {
            assert_eq!(x.undecided, x.tests, "{x:?}");
        } else if !["zero_inf_d", "mixed_edges"].contains(&x.class.as_str()) {
            assert_eq!(x.undecided, 0, "{x:?}");
        }
    }
    // the edge classes produce exact hits in every format (a miss there would be seen) ...
    for class in ["subnormal_d", "tiny_d", "huge_d", "near_max", "max_planes"] {
        for f in formats {
            let row = r.slab.iter().find(|x| x.class == class && x.format == f && x.variant == "directed").unwrap();
            assert!(row.exact_hits > 0, "{row:?}");
        }
    }
    // ... and the plain variant misses there: the classes reach the edges the guard handles
    for class in ["subnormal_d", "near_max"] {
        for f in ["f32", "fp16", "bf16"] {
            let row = r.slab.iter().find(|x| x.class == class && x.format == f && x.variant == "plain").unwrap();
            assert!(row.false_misses > 0, "{row:?}");
        }
    }
    // directed in saturating fixed point: plain misses at the saturating subtracts
    let sat = r.slab.iter().find(|x| x.class == "near_max" && x.format == "q8.24" && x.variant == "plain").unwrap();
    assert!(sat.false_misses > 0, "{sat:?}");
    // the plain variant misses grazing rays somewhere, and the conservative ones pay with false hits
    assert!(r.slab.iter().any(|x| x.variant == "plain" && x.false_misses > 0), "{:?}", r.slab);
    assert!(r.slab.iter().any(|x| x.variant == "conservative" && x.false_hits > 0));
}

/// A variant that promises conservativeness is refused where it cannot keep it: named in
/// the report, never run, and the wrapping fixed point refuses `directed`.
#[test]
fn refused_pairs_are_named_and_not_run() {
    let r = stress(&cfg(&["q8.24:wrap", "fp16:ftz"], &["conservative", "directed"], 5)).unwrap();
    assert_eq!(r.refused.len(), 3, "{:?}", r.refused);
    assert!(r.refused.iter().any(|w| w.contains("directed") && w.contains("q8.24:wrap")));
    assert!(r.slab.iter().all(|x| x.format == "fp16:ftz" && x.variant == "directed"));
    assert!(stress(&cfg(&["f32"], &["no-such-variant"], 5)).unwrap_err().contains("unknown slab variant"));
}

#[test]
fn rti_classes_count_failures_cracks_and_undecided_inputs() {
    let r = stress(&cfg(&["f32", "bf16"], &[], 30)).unwrap();
    assert_eq!(r.rti.len(), 2 * RTI_STRESS.len());
    for x in &r.rti {
        assert!(x.tests >= 30, "{x:?}");
        assert!(x.false_misses + x.false_hits <= x.tests - x.undecided);
        match x.class.as_str() {
            "inf_nan" => assert_eq!(x.undecided, x.tests, "{x:?}"),
            _ => assert_eq!(x.undecided, 0, "{x:?}"),
        }
        if !["shared_edge", "shared_vertex", "inside_closed"].contains(&x.class.as_str()) {
            assert_eq!(x.cracks, 0, "only watertightness classes count cracks");
        }
    }
    // rays aimed exactly at shared edges are where rounding decides: the model disagrees there
    let edge = r.rti.iter().find(|x| x.class == "shared_edge" && x.format == "f32").unwrap();
    assert!(edge.false_misses + edge.false_hits > 0, "{edge:?}");
    // subnormal products flush the determinant: misses, never false hits
    let sub = r.rti.iter().find(|x| x.class == "subnormal" && x.format == "f32").unwrap();
    assert!(sub.false_misses > 0 && sub.false_hits == 0, "{sub:?}");
}

#[test]
fn the_suite_is_deterministic_and_thread_independent() {
    let c = cfg(&["fp16"], &["plain"], 20);
    let on = |threads, chunk| {
        stress(&StressConfig { engine: engine::Engine { threads, chunk, shard: engine::Shard::ALL }, ..c.clone() })
            .unwrap()
    };
    let one = on(1, 1 << 20);
    for (t, ch) in [(2, 64), (3, 7), (2, 1)] {
        assert_eq!(serde_json::to_string(&one).unwrap(), serde_json::to_string(&on(t, ch)).unwrap(), "{t} {ch}");
    }
    let other = stress(&StressConfig { seed: 10, ..c.clone() }).unwrap();
    assert_ne!(serde_json::to_string(&one).unwrap(), serde_json::to_string(&other).unwrap());
    assert!(stress(&StressConfig { count: 0, ..c }).unwrap_err().contains("--count"));
}
