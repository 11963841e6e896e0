//! `raypipe prove history-equals-stack` from the command line: PROVEN exits 0 with its theorem,
//! a mutant's counterexample exits 1 and shows the two traversals' different leaves, and a
//! request that does not apply exits 2. (The solver-backed properties are tested in
//! python/tests/test_prove.py, where the solvers are installed.)

mod common;
use common::raypipe;

#[test]
fn history_equals_stack_is_proven_for_four_levels() {
    let o = raypipe(&["prove", "history-equals-stack", "--depth", "4", "--n", "4", "--nan", "--json"]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(j["status"], "PROVEN");
    assert!(j["statement"].as_str().unwrap().contains("first N leaves"));
    // one search per (levels, N), each visiting states
    let states = j["states"].as_array().unwrap();
    assert_eq!(states.len(), 16);
    assert!(states.iter().all(|s| s["states"].as_u64().unwrap() > 0));
    // the thread count does not change the result
    let o1 =
        raypipe(&["prove", "history-equals-stack", "--depth", "4", "--n", "4", "--nan", "--json", "--threads", "1"]);
    let j1: serde_json::Value = serde_json::from_slice(&o1.stdout).unwrap();
    assert_eq!(j1["states"], j["states"]);
}

#[test]
fn every_history_mutant_but_the_informational_one_is_refuted() {
    for m in ["resume-shallowest", "no-reset-deeper", "no-mark-split", "one-pass", "ties-right"] {
        let o = raypipe(&["prove", "history-equals-stack", "--depth", "3", "--mutant", m]);
        let out = String::from_utf8_lossy(&o.stdout);
        assert_eq!(o.status.code(), Some(1), "{m}: {out}");
        assert!(out.contains("COUNTEREXAMPLE"), "{m}: {out}");
        // the replay through the real traversals: both leaf lists, and they differ
        let last = out.lines().rev().find(|l| l.starts_with("N = ")).unwrap();
        let (h, s) = last.split_once(": history [").unwrap().1.split_once("], stack [").unwrap();
        assert_ne!(h, s.trim_end_matches(']'), "{m}: {out}");
    }
    // 01 only informs: the leaves are the same without it
    let o = raypipe(&["prove", "history-equals-stack", "--depth", "3", "--mutant", "no-mark-pass"]);
    assert_eq!(o.status.code(), Some(0));
}

#[test]
fn history_requests_that_do_not_apply_exit_2() {
    for args in [
        &["prove", "history-equals-stack", "--format", "fp16"][..],
        &["prove", "history-equals-stack", "--no-guard"],
        &["prove", "history-equals-stack", "--depth", "0"],
        &["prove", "history-equals-stack", "--depth", "7"],
        &["prove", "history-equals-stack", "--depth", "6", "--n", "5"],
        &["prove", "history-equals-stack", "--n", "9"],
        &["prove", "history-equals-stack", "--mutant", "nope"],
        &["prove", "slab-never-misses", "--mutant", "one-pass"],
        &["prove", "no-such-property"],
    ] {
        let o = raypipe(args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
    }
}

#[test]
fn the_directed_slab_never_misses_in_small_formats_without_a_solver() {
    // the directed variant's lemma is enumerated (no SMT): e5m6 (12-bit float), q4.4 (fixed point)
    for f in ["e5m6", "q4.4"] {
        let o = raypipe(&["prove", "slab-never-misses", "--variant", "directed", "--format", f, "--json"]);
        assert_eq!(o.status.code(), Some(0), "{f}: {}", String::from_utf8_lossy(&o.stderr));
        let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        assert_eq!(j["status"], "PROVEN");
        assert_eq!(j["solver"], "enumeration");
        assert!(j["steps"][0]["query"].as_str().unwrap().contains("pairs enumerated"));
    }
    // what the directed variant does not take
    for args in [
        &["prove", "slab-never-misses", "--variant", "directed", "--no-guard"][..],
        &["prove", "slab-never-misses", "--variant", "directed", "--format", "f32"],
        &["prove", "slab-never-misses", "--variant", "directed", "--format", "fp16:ftz"],
    ] {
        let o = raypipe(args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", String::from_utf8_lossy(&o.stderr));
    }
}
