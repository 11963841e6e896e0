//! `raypipe prove history-equals-stack` and `rti-bound` from the command line: PROVEN exits 0
//! with its theorem, a mutant's counterexample exits 1 and shows the two traversals' different
//! leaves (history) or a whole RTI input outside the mutated bound that `raypipe explain`
//! replays (rti-bound), and a request that does not apply exits 2. (The solver-backed properties are tested in
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

#[test]
fn rti_bound_is_proven_for_a_small_format_and_its_mutants_are_refuted() {
    let o = raypipe(&["prove", "rti-bound", "--format", "e5m6", "--json"]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(j["status"], "PROVEN");
    let ops: Vec<&str> = j["lemmas"].as_array().unwrap().iter().map(|l| l["op"].as_str().unwrap()).collect();
    assert_eq!(ops, ["add", "sub", "mul", "recip"]);
    // every finite pair: (2^12 − 2·2^6)² = 3968² pairs of e5m6, split into finite and not
    for l in &j["lemmas"].as_array().unwrap()[..3] {
        let n = l["pairs"].as_u64().unwrap() + l["not_finite"].as_u64().unwrap();
        assert_eq!(n, 3968 * 3968, "{l}");
        assert!(l["worst_ratio"].as_f64().unwrap() < 1.0);
    }
    let o = raypipe(&["prove", "rti-bound", "--format", "e5m6:divide", "--json", "--threads", "1"]);
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!((o.status.code(), j["lemmas"][3]["op"].as_str()), (Some(0), Some("div")));
    for (m, format) in [("no-eta", "e5m6"), ("u-sixteenth", "fp16")] {
        let o = raypipe(&["prove", "rti-bound", "--format", format, "--mutant", m, "--json"]);
        assert_eq!(o.status.code(), Some(1), "{m}: {}", String::from_utf8_lossy(&o.stderr));
        let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        assert_eq!(j["status"], "COUNTEREXAMPLE");
        let bad: Vec<&serde_json::Value> =
            j["witness"].as_array().unwrap().iter().filter(|c| c["holds"] == false).collect();
        assert!(!bad.is_empty(), "{m}: {j}");
        // the printed command replays the input: the model's t' is the witness's, and the
        // exact t' (the binary64 twin is exact here: one product of two fp16 values) differs
        // from it by more than the mutated bound
        let cmd = j["explain"].as_str().unwrap();
        let args: Vec<&str> = cmd.split_whitespace().skip(1).chain(["--json"]).collect();
        let e = raypipe(&args);
        assert_eq!(e.status.code(), Some(0), "{cmd}");
        let ej: serde_json::Value = serde_json::from_slice(&e.stdout).unwrap();
        let tp = ej["signals"].as_array().unwrap().iter().find(|s| s["name"] == "tp").unwrap();
        let w = bad.iter().find(|c| c["quantity"] == "tp").expect("t' outside");
        let bits = |s: &str| u64::from_str_radix(s.trim_start_matches("0x"), 16).unwrap();
        assert_eq!(bits(tp["bits"].as_str().unwrap()), bits(w["model_bits"].as_str().unwrap()), "{m}: {tp}");
        let model: f64 = tp["value"].as_str().unwrap().parse().unwrap();
        assert!((model - w["exact"].as_f64().unwrap()).abs() > w["bound"].as_f64().unwrap());
    }
}

#[test]
fn rti_bound_requests_that_do_not_apply_exit_2() {
    for args in [
        &["prove", "rti-bound", "--format", "bf16"][..],
        &["prove", "rti-bound", "--format", "f32"],
        &["prove", "rti-bound", "--format", "fp16:ftz"],
        &["prove", "rti-bound", "--format", "q8.8"],
        &["prove", "rti-bound", "--format", "nope"],
        &["prove", "rti-bound", "--variant", "conservative"],
        &["prove", "rti-bound", "--no-guard"],
        &["prove", "rti-bound", "--mutant", "ties-right"],
        &["prove", "rti-bound", "--out", "target/never-written"],
    ] {
        let o = raypipe(args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
    }
}
