//! Sharded runs: `--shard K/N --partial FILE` on every shard, then `raypipe merge`, equals the
//! unsharded run (timings aside) for several N and any merge order; every bad partial set is
//! refused with exit 2 and nothing merged.

mod common;
use common::raypipe;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("raypipe-shard-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn json(o: &Output) -> serde_json::Value {
    assert!(o.status.code().is_some_and(|c| c <= 1), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).unwrap_or_else(|e| panic!("{e}: {}", String::from_utf8_lossy(&o.stdout)))
}

/// The report without its timings (rates differ between any two runs).
fn untimed(mut v: serde_json::Value) -> serde_json::Value {
    for key in ["formats", "slab"] {
        for r in v[key].as_array_mut().unwrap() {
            let r = r.as_object_mut().unwrap();
            r.remove("mtests_per_s");
            r.remove("judged_mtests_per_s");
        }
    }
    v
}

const RUN: [&str; 7] = ["verify", "--rays", "200", "--format", "f32,fp16,q8.24:divide", "--quiet", "--json"];

fn shards(d: &Path, n: u64, extra: &[&str]) -> Vec<String> {
    (0..n)
        .map(|k| {
            let p = d.join(format!("part{k}of{n}.json")).display().to_string();
            let shard = format!("{k}/{n}");
            let mut a = RUN.to_vec();
            a.extend(["--shard", &shard, "--partial", &p]);
            a.extend(extra);
            let o = raypipe(&a);
            assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
            p
        })
        .collect()
}

/// Runs `base` as shards 0..n with partials in `d` (named after `tag`), in the given order.
fn run_shards(d: &Path, base: &[&str], n: u64, tag: &str) -> Vec<String> {
    (0..n)
        .map(|k| {
            let p = d.join(format!("{tag}{k}of{n}.json")).display().to_string();
            let shard = format!("{k}/{n}");
            let mut a = base.to_vec();
            a.extend(["--shard", &shard, "--partial", &p]);
            let o = raypipe(&a);
            assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
            p
        })
        .collect()
}

fn merge(parts: &[String]) -> Output {
    let mut a = vec!["merge", "--json"];
    a.extend(parts.iter().map(String::as_str));
    raypipe(&a)
}

#[test]
fn merged_shards_equal_the_unsharded_run() {
    let d = dir("equal");
    let whole = untimed(json(&raypipe(&RUN)));
    assert!(whole["formats"][0]["tests"].as_u64().unwrap() > 0);
    for n in [1, 2, 3, 5] {
        let mut parts = shards(&d, n, &[]);
        assert_eq!(untimed(json(&merge(&parts))), whole, "{n} shards");
        parts.reverse();
        assert_eq!(untimed(json(&merge(&parts))), whole, "{n} shards, reversed");
    }
    // more shards than chunks: some shards run nothing, the merge is still the whole
    let parts = shards(&d, 20, &["--chunk", "64"]);
    let mut whole64 = RUN.to_vec();
    whole64.extend(["--chunk", "64"]);
    assert_eq!(untimed(json(&merge(&parts))), untimed(json(&raypipe(&whole64))));
    // the exit code is the unsharded run's, and the text report too (timings aside)
    let o = merge(&shards(&d, 2, &[]));
    assert_eq!(o.status.code(), raypipe(&RUN).status.code());
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn a_slurm_array_task_names_its_shard() {
    let d = dir("slurm");
    let p = d.join("t1.json");
    let mut a = RUN.to_vec();
    a.extend(["--shard", "slurm", "--partial", p.to_str().unwrap()]);
    let o = Command::new(env!("CARGO_BIN_EXE_raypipe"))
        .current_dir(std::env::temp_dir())
        .args(&a)
        .env("SLURM_ARRAY_TASK_ID", "1")
        .env("SLURM_ARRAY_TASK_COUNT", "2")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&p).unwrap()).unwrap();
    assert_eq!((v["shard"]["k"].as_u64(), v["shard"]["n"].as_u64()), (Some(1), Some(2)));
    // outside a Slurm task
    let o = Command::new(env!("CARGO_BIN_EXE_raypipe"))
        .current_dir(std::env::temp_dir())
        .args(&a)
        .env_remove("SLURM_ARRAY_TASK_ID")
        .env_remove("SLURM_ARRAY_TASK_COUNT")
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("SLURM_ARRAY_TASK_ID"));
    std::fs::remove_dir_all(&d).unwrap();
}

fn refused(o: &Output, needle: &str) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains(needle), "stderr lacks '{needle}': {err}");
    assert!(o.stdout.is_empty(), "nothing is merged: {}", String::from_utf8_lossy(&o.stdout));
}

#[test]
fn bad_shards_and_partials_are_refused() {
    let d = dir("bad");
    let parts = shards(&d, 3, &[]);
    // a missing and a duplicated shard
    refused(&merge(&parts[..2]), "missing shard(s) 2/3");
    refused(&merge(&[parts[0].clone(), parts[1].clone(), parts[1].clone(), parts[2].clone()]), "given twice");
    // another run: other seed, other shard count
    let other = d.join("other");
    std::fs::create_dir_all(&other).unwrap();
    let seeds = shards(&other, 3, &["--seed", "9"]);
    refused(&merge(&[parts[0].clone(), parts[1].clone(), seeds[2].clone()]), "options differs");
    let two = shards(&other, 2, &[]);
    refused(&merge(&[parts[0].clone(), two[1].clone()]), "shard count differs");
    // another scene
    let obj = d.join("tri.obj");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let scene = shards(&other, 3, &["--scene", obj.to_str().unwrap()]);
    refused(&merge(&[parts[0].clone(), parts[1].clone(), scene[2].clone()]), "differs");
    // another version, a corrupt and a truncated file
    let text = std::fs::read_to_string(&parts[2]).unwrap();
    let old = d.join("old.json");
    std::fs::write(
        &old,
        text.replacen(&format!("\"version\":\"{}\"", env!("CARGO_PKG_VERSION")), "\"version\":\"0.0.1\"", 1),
    )
    .unwrap();
    refused(&merge(&[parts[0].clone(), parts[1].clone(), old.display().to_string()]), "digest");
    std::fs::write(&old, reseal(&std::fs::read_to_string(&old).unwrap())).unwrap();
    refused(&merge(&[parts[0].clone(), parts[1].clone(), old.display().to_string()]), "version");
    let cut = d.join("cut.json");
    std::fs::write(&cut, &text[..text.len() / 2]).unwrap();
    refused(&merge(&[parts[0].clone(), parts[1].clone(), cut.display().to_string()]), "not a raypipe partial");
    // K >= N, N = 0, a shard without a partial file, a partial over a file raypipe did not write
    let p = d.join("x.json");
    let ps = p.to_str().unwrap();
    refused(&raypipe(&["verify", "--shard", "3/3", "--partial", ps]), "below N");
    refused(&raypipe(&["verify", "--shard", "0/0", "--partial", ps]), "at least 1");
    refused(&raypipe(&["verify", "--shard", "0/2"]), "--partial");
    let mine = d.join("mine.json");
    std::fs::write(&mine, "{\"my\": \"data\"}").unwrap();
    refused(&raypipe(&["verify", "--shard", "0/2", "--partial", mine.to_str().unwrap()]), "not replacing it");
    assert_eq!(std::fs::read_to_string(&mine).unwrap(), "{\"my\": \"data\"}");
    refused(&raypipe(&["merge", mine.to_str().unwrap()]), "not a raypipe partial");
    std::fs::remove_dir_all(&d).unwrap();
}

/// The digest rule of docs/cluster.md, written from the docs: the file without its final
/// newline ends with the member `,"digest":"<64 hex>"}`; the SHA-256 of the text before that
/// member followed by `}` is the digest.
fn reseal(text: &str) -> String {
    use sha2::Digest as _;
    let t = text.trim_end_matches('\n');
    let at = t.rfind(",\"digest\":\"").expect("a digest member");
    let body = format!("{}}}", &t[..at]);
    let hex: String = sha2::Sha256::digest(body.as_bytes()).iter().map(|b| format!("{b:02x}")).collect();
    format!("{},\"digest\":\"{hex}\"}}\n", &t[..at])
}

/// Edits the partial at `path` through its JSON `data` and writes it back, resealed or not.
fn edit(path: &str, to: &Path, seal: bool, f: impl FnOnce(&mut serde_json::Value)) -> String {
    let text = std::fs::read_to_string(path).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    f(&mut v["data"]);
    let digest = v.as_object_mut().unwrap().remove("digest").expect("raypipe writes a digest");
    // the digest member last again, as raypipe writes it
    let body = serde_json::to_string(&v).unwrap();
    let edited = format!("{},\"digest\":{digest}}}\n", body.strip_suffix('}').unwrap());
    std::fs::write(to, if seal { reseal(&edited) } else { edited }).unwrap();
    to.display().to_string()
}

/// A partial damaged or edited after it was written is refused by its digest (exit 2, naming
/// the file); one whose digest was recomputed but whose content is inconsistent is refused by
/// the consistency rules: violations without a first-violation record, a first-violation
/// record without violations (a failing shard edited into a pass), counts that do not add up
/// to the shard's tests, a histogram whose total differs from its count.
#[test]
fn tampered_partials_are_refused() {
    let d = dir("tamper");
    let run = ["verify", "--rays", "64", "--format", "f32", "--quiet", "--json", "--shard", "0/1", "--partial"];
    let clean = d.join("clean.json").display().to_string();
    let mut a = run.to_vec();
    a.push(&clean);
    assert!(raypipe(&a).status.success());
    let failing = d.join("failing.json").display().to_string();
    let mut a = run.to_vec();
    a.extend([failing.as_str(), "--inject", "rti.e1x.swap"]);
    let o = raypipe(&a);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // the untouched partials merge, the clean one passes and the injected one fails
    assert_eq!(merge(std::slice::from_ref(&clean)).status.code(), Some(0));
    assert_eq!(merge(std::slice::from_ref(&failing)).status.code(), Some(1));
    // the sealing rule of the docs reproduces raypipe's own digest
    let text = std::fs::read_to_string(&clean).unwrap();
    assert_eq!(reseal(&text), text);
    let rti = |v: &mut serde_json::Value| v["formats"][0]["rti"].clone();
    assert!(
        rti(&mut serde_json::from_str::<serde_json::Value>(&text).unwrap()["data"])["counts"]["violations"].is_u64()
    );
    // five more violations, digest left as it was: the digest refuses it
    let add5 = |v: &mut serde_json::Value| {
        let c = &mut v["formats"][0]["rti"]["counts"]["violations"];
        *c = (c.as_u64().unwrap() + 5).into();
    };
    let t = d.join("t1.json");
    refused(&merge(&[edit(&clean, &t, false, add5)]), &format!("{}: refused: its digest does not match", t.display()));
    // the same with the digest recomputed: no first-violation record
    refused(&merge(&[edit(&clean, &t, true, add5)]), "violations counted but the first-violation record is missing");
    // a failing shard edited to pass: the violations zeroed, the record left
    let zero = |v: &mut serde_json::Value| v["formats"][0]["rti"]["counts"]["violations"] = 0.into();
    refused(
        &merge(&[edit(&failing, &t, true, zero)]),
        "0 violations counted but the first-violation record is present",
    );
    // (with the record removed too, the partial is a consistent forgery: docs/cluster.md says
    // the digest and the rules do not stop someone who edits on purpose)
    // one test fewer than the shard's rays make
    let fewer = |v: &mut serde_json::Value| {
        let c = &mut v["formats"][0]["rti"]["counts"]["tests"];
        *c = (c.as_u64().unwrap() - 1).into();
    };
    refused(&merge(&[edit(&clean, &t, true, fewer)]), "RTI tests, but the shard's rays make");
    // a histogram count one more than its buckets hold
    let hist = |v: &mut serde_json::Value| {
        let c = &mut v["formats"][0]["rti"]["ulps"]["count"];
        *c = (c.as_u64().unwrap() + 1).into();
    };
    refused(&merge(&[edit(&clean, &t, true, hist)]), "a histogram's buckets hold");
    // a slab count: more false misses than exact hits
    let slab = |v: &mut serde_json::Value| {
        let c = &mut v["formats"][0]["slab"][0][2]["counts"];
        c["false_misses"] = (c["exact_hits"].as_u64().unwrap() + 1).into();
    };
    refused(&merge(&[edit(&clean, &t, true, slab)]), "slab counts do not fit");
    // partials of the previous formats (1: no digest; 2: positional counters) are refused by
    // their version, whatever their digest
    for old in [1, 2] {
        let v = d.join(format!("v{old}.json"));
        let t = text.replacen("\"raypipe_partial\":3", &format!("\"raypipe_partial\":{old}"), 1);
        std::fs::write(&v, reseal(&t)).unwrap();
        refused(&merge(&[v.display().to_string()]), &format!("partial format {old}; this raypipe reads format 3 only"));
    }
    // a counter the format does not name is refused
    let extra = |v: &mut serde_json::Value| v["formats"][0]["rti"]["counts"]["bonus"] = 1.into();
    refused(&merge(&[edit(&clean, &t, true, extra)]), "unknown field `bonus`");
    // an untouched partial re-serialised the same way (members in the same order) still merges
    let same = d.join("same.json");
    assert_eq!(merge(&[edit(&clean, &same, true, |_| ())]).status.code(), Some(0));
    std::fs::remove_dir_all(&d).unwrap();
}

/// `raypipe ops` sharded and merged equals one pass; what it cannot run is refused.
#[test]
fn ops_sweeps_shard_and_merge() {
    let d = dir("ops");
    let base = ["ops", "--format", "fp16:ftz+divide", "--op", "div", "--count", "300000", "--quiet", "--json"];
    let whole = json(&raypipe(&base));
    assert_eq!((whole["tests"].as_u64(), whole["mismatches"].as_u64()), (Some(300000), Some(0)));
    for n in [2u64, 3] {
        let parts = run_shards(&d, &base, n, "ops");
        assert_eq!(json(&merge(&parts)), whole, "{n} shards");
    }
    // an exhaustive shard: 2^32 / 4096 pairs of chunk 0 mod 4096 (one chunk of 65536 pairs: a = 0)
    let p = d.join("ex.json");
    let o = raypipe(&[
        "ops",
        "--format",
        "bf16",
        "--op",
        "mul",
        "--exhaustive",
        "--shard",
        "0/65536",
        "--partial",
        p.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&p).unwrap()).unwrap();
    assert_eq!(v["data"]["counts"], serde_json::json!([65536, 0]));
    refused(&raypipe(&["ops", "--format", "f32", "--op", "add", "--exhaustive"]), "16-bit");
    refused(&raypipe(&["ops", "--format", "e8m16", "--op", "add"]), "oracle covers");
    refused(&raypipe(&["ops", "--format", "fp16:propagate", "--op", "add"]), "propagate");
    refused(&raypipe(&["ops", "--format", "fp16", "--op", "pow"]), "unknown --op");
    refused(&raypipe(&["ops", "--format", "fp16", "--op", "add", "--count", "0"]), "--count");
    std::fs::remove_dir_all(&d).unwrap();
}

/// `raypipe traverse` sharded and merged equals one pass (its report is all counts).
#[test]
fn traverse_shards_and_merges() {
    let d = dir("traverse");
    let base = ["traverse", "--rays", "3000", "--format", "f32,fp16", "--quiet", "--json"];
    let whole = json(&raypipe(&base));
    assert_eq!(whole["rows"][0]["rays"].as_u64(), Some(3000));
    for n in [2u64, 7] {
        let mut parts = run_shards(&d, &base, n, "tr");
        parts.rotate_left(1);
        assert_eq!(json(&merge(&parts)), whole, "{n} shards");
    }
    std::fs::remove_dir_all(&d).unwrap();
}

/// `raypipe stress` sharded and merged equals one pass (its report is all counts).
#[test]
fn stress_shards_and_merges() {
    let d = dir("stress");
    let base = [
        "stress",
        "--count",
        "40",
        "--format",
        "fp16,q8.24:divide",
        "--variant",
        "conservative,plain",
        "--quiet",
        "--json",
    ];
    let whole = json(&raypipe(&base));
    for n in [2u64, 5] {
        let mut parts = run_shards(&d, &base, n, "st");
        parts.reverse();
        assert_eq!(json(&merge(&parts)), whole, "{n} shards");
    }
    std::fs::remove_dir_all(&d).unwrap();
}

/// `raypipe report` sharded and merged equals one pass: every count and error figure (the time
/// per test, and so the Pareto marks, are measurements of each run).
#[test]
fn report_shards_and_merges() {
    let d = dir("report");
    let out = d.join("whole");
    let o = out.to_str().unwrap();
    let base = [
        "report",
        "--rays",
        "24",
        "--stress-count",
        "6",
        "--format",
        "f32,bf16,q8.24:divide",
        "--variant",
        "plain,conservative",
        "--json",
    ];
    let mut whole_args = base.to_vec();
    whole_args.extend(["--out", o]);
    // the timings, and the command line and machine that name where they were taken, differ
    let untimed = |mut v: serde_json::Value| {
        let o = v.as_object_mut().unwrap();
        assert!(o.remove("command").is_some_and(|c| c.as_str().is_some_and(|c| c.starts_with("raypipe "))));
        assert!(o.remove("machine").is_some());
        for p in v["points"].as_array_mut().unwrap() {
            let p = p.as_object_mut().unwrap();
            p.remove("ns_per_test");
            p.remove("pareto");
        }
        v
    };
    let whole = untimed(json(&raypipe(&whole_args)));
    assert!(whole["points"].as_array().unwrap().len() >= 6);
    let merged_dir = d.join("merged");
    for n in [2, 3] {
        let parts = run_shards(&d, &base, n, "rep");
        let mut a = vec!["merge", "--json", "--out", merged_dir.to_str().unwrap()];
        a.extend(parts.iter().rev().map(String::as_str));
        assert_eq!(untimed(json(&raypipe(&a))), whole, "{n} shards");
    }
    assert!(merged_dir.join("report.md").exists());
    // --out is for report partials only
    let v = run_shards(&d, &RUN, 1, "v");
    refused(&raypipe(&["merge", "--out", merged_dir.to_str().unwrap(), &v[0]]), "report");
    std::fs::remove_dir_all(&d).unwrap();
}

/// A traverse shard over a BVH of one leaf merges as inconclusive (exit 3), and the same
/// partial with `inconclusive` edited away (digest recomputed) is refused.
#[test]
fn a_vacuous_traverse_shard_stays_inconclusive() {
    let d = dir("vacuous");
    let obj = d.join("one.obj");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let p = d.join("t.json").display().to_string();
    let o = raypipe(&[
        "traverse",
        "--scene",
        obj.to_str().unwrap(),
        "--rays",
        "64",
        "--quiet",
        "--shard",
        "0/1",
        "--partial",
        &p,
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let m = merge(std::slice::from_ref(&p));
    assert_eq!(m.status.code(), Some(3), "{}", String::from_utf8_lossy(&m.stdout));
    let j = raypipe(&["merge", "--json", &p]);
    assert_eq!(j.status.code(), Some(3));
    let jv: serde_json::Value = serde_json::from_slice(&j.stdout).unwrap();
    assert!(jv["inconclusive"].is_string(), "{jv}");
    let t = d.join("t2.json");
    let text = std::fs::read_to_string(&p).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    v["data"]["inconclusive"] = serde_json::Value::Null;
    let digest = v.as_object_mut().unwrap().remove("digest").unwrap();
    let body = serde_json::to_string(&v).unwrap();
    let edited = format!("{},\"digest\":{digest}}}\n", body.strip_suffix('}').unwrap());
    std::fs::write(&t, reseal(&edited)).unwrap();
    refused(&merge(&[t.display().to_string()]), "inconclusive is None but the tree and rows say");
    std::fs::remove_dir_all(&d).unwrap();
}
