//! Hostile input at the command line: a user's data is never lost (output paths are checked
//! before the work, only what raypipe wrote is replaced, an interrupt leaves nothing behind),
//! and every bad input is a clear error (exit 2), never a panic, an abort or a vacuous pass
//! (a run that proved nothing exits 3).

mod common;
use common::raypipe;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A fresh, empty temporary directory for one test.
fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("raypipe-bad-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn assert_exit(o: &Output, code: i32, needle: &str) {
    let (out, err) = (String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    assert_eq!(o.status.code(), Some(code), "stdout: {out}\nstderr: {err}");
    assert!(err.contains(needle) || out.contains(needle), "'{needle}' not in stdout {out} / stderr {err}");
    assert!(!err.contains("panicked"), "{err}");
}

/// Every file below `dir` with its contents.
fn snapshot(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut v = Vec::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            v.extend(snapshot(&p));
        } else {
            v.push((p.clone(), std::fs::read(&p).unwrap()));
        }
    }
    v.sort();
    v
}

#[test]
fn vectors_never_replaces_a_directory_it_did_not_write() {
    let d = scratch("vec-foreign");
    // a web app with its own manifest.json
    let app = d.join("app");
    std::fs::create_dir_all(app.join("assets")).unwrap();
    std::fs::write(app.join("manifest.json"), r#"{"name": "my web app", "start_url": "/"}"#).unwrap();
    std::fs::write(app.join("index.html"), "<html></html>").unwrap();
    std::fs::write(app.join("assets/logo.svg"), "<svg/>").unwrap();
    let before = snapshot(&app);
    let o = raypipe(&["vectors", "--unit", "op", "--format", "fp16", "--count", "2", "--out", s(&app)]);
    assert_exit(&o, 2, "not a vector set raypipe wrote");
    assert_eq!(snapshot(&app), before, "the directory was touched");
    // a real set with a file of the user's added to it is not replaced either
    let set = d.join("set");
    let ok = raypipe(&["vectors", "--unit", "op", "--format", "fp16", "--count", "2", "--out", s(&set)]);
    assert!(ok.status.success());
    std::fs::write(set.join("notes.txt"), "my notes").unwrap();
    let o = raypipe(&["vectors", "--unit", "op", "--format", "fp16", "--count", "3", "--out", s(&set)]);
    assert_exit(&o, 2, "notes.txt");
    assert_eq!(std::fs::read_to_string(set.join("notes.txt")).unwrap(), "my notes");
    // an earlier set alone is replaced, and an empty directory is used
    std::fs::remove_file(set.join("notes.txt")).unwrap();
    let o = raypipe(&["vectors", "--unit", "op", "--format", "fp16", "--count", "3", "--out", s(&set)]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let empty = d.join("empty");
    std::fs::create_dir(&empty).unwrap();
    assert!(raypipe(&["vectors", "--unit", "op", "--format", "fp16", "--count", "2", "--out", s(&empty)])
        .status
        .success());
    // a file where the directory should be
    let file = d.join("file");
    std::fs::write(&file, "x").unwrap();
    let o = raypipe(&["vectors", "--unit", "op", "--format", "fp16", "--count", "2", "--out", s(&file)]);
    assert_exit(&o, 2, "not a directory");
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "x");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn an_interrupted_write_leaves_nothing_and_its_leftover_is_cleaned() {
    let d = scratch("vec-partial");
    let set = d.join("set");
    // a leftover of an interrupted run (it holds raypipe's mark) is removed by the next run
    let partial = d.join(".set.raypipe-partial");
    std::fs::create_dir(&partial).unwrap();
    std::fs::write(partial.join(".raypipe-partial"), "").unwrap();
    std::fs::write(partial.join("rti_inputs.hex"), "half a set").unwrap();
    let o = raypipe(&["vectors", "--unit", "rti", "--format", "f32", "--count", "2", "--out", s(&set)]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(!partial.exists());
    // a directory of that name without the mark is someone else's: refused, kept
    std::fs::create_dir(&partial).unwrap();
    std::fs::write(partial.join("mine.txt"), "mine").unwrap();
    let o = raypipe(&["vectors", "--unit", "rti", "--format", "f32", "--count", "2", "--out", s(&set)]);
    assert_exit(&o, 2, "was not left by raypipe");
    assert_eq!(std::fs::read_to_string(partial.join("mine.txt")).unwrap(), "mine");
    std::fs::remove_dir_all(&partial).unwrap();
    // SIGINT at any moment of a run: no partial directory is left, and a set in place is whole
    for wait_ms in [5u64, 40, 120, 300, 600] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_raypipe"))
            .current_dir(std::env::temp_dir())
            .args([
                "vectors",
                "--unit",
                "slab",
                "--format",
                "e8m16",
                "--level",
                "2",
                "--count",
                "3000",
                "--out",
                s(&set),
            ])
            .spawn()
            .unwrap();
        std::thread::sleep(std::time::Duration::from_millis(wait_ms));
        let _ = Command::new("kill").args(["-INT", &child.id().to_string()]).status();
        let status = child.wait().unwrap();
        assert!(!partial.exists(), "SIGINT after {wait_ms} ms left {}", partial.display());
        if set.exists() {
            assert!(raypipe(&["vectors", "--check", s(&set)]).status.success(), "a half set after {wait_ms} ms");
        }
        assert!(status.success() || status.code() == Some(130) || status.code().is_none(), "{status:?}");
    }
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn output_paths_are_checked_before_the_work() {
    let d = scratch("outpaths");
    let file = d.join("a-file");
    std::fs::write(&file, "keep").unwrap();
    for args in [
        vec!["report", "--out", s(&file)],
        vec!["stats", "--svg", s(&file)],
        vec!["render", "--out", s(&file)],
        vec!["report", "--out", &format!("{}/below", s(&file))],
    ] {
        let o = raypipe(&args);
        assert_exit(&o, 2, "not a directory");
        assert!(o.stdout.is_empty(), "{args:?} did the work first");
    }
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "keep");
    // a user's render.png is never overwritten
    let mine = d.join("mine");
    std::fs::create_dir(&mine).unwrap();
    std::fs::write(mine.join("render.png"), "my picture").unwrap();
    let o = raypipe(&["render", "--width", "8", "--height", "8", "--out", s(&mine)]);
    assert_exit(&o, 2, "not written by raypipe");
    assert_eq!(std::fs::read_to_string(mine.join("render.png")).unwrap(), "my picture");
    // raypipe's own output is replaced on the next run
    let own = d.join("own");
    for _ in 0..2 {
        let o = raypipe(&["render", "--width", "8", "--height", "8", "--out", s(&own)]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    // a refused command leaves no empty directory behind
    for (args, dir) in [
        (vec!["render", "--format", "q8.24", "--variant", "conservative", "--out"], d.join("r-new")),
        (vec!["vectors", "--unit", "slab", "--format", "q8.24", "--variant", "conservative", "--out"], d.join("v-new")),
        (vec!["stats", "--leaf-sizes", "0", "--svg"], d.join("s-new")),
        (vec!["report", "--format", "nope", "--out"], d.join("p-new")),
    ] {
        let mut a = args.clone();
        a.push(s(&dir));
        let o = raypipe(&a);
        assert_eq!(o.status.code(), Some(2), "{a:?}");
        assert!(!dir.exists(), "{a:?} left {}", dir.display());
    }
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn sizes_that_cannot_be_served_are_refused_up_front() {
    let huge = "18446744073709551615";
    let big = "1000000000000";
    for args in [
        vec!["verify", "--rays", huge],
        vec!["verify", "--rays", big],
        vec!["traverse", "--rays", huge],
        vec!["traverse", "--rays", big],
        vec!["stats", "--rays", big],
        vec!["plan", "--rays", big],
        vec!["report", "--rays", big],
        vec!["speed", "--pairs", big],
        vec!["vectors", "--unit", "op", "--format", "f32", "--count", big, "--out", "/nonexistent-raypipe/x"],
    ] {
        let o = raypipe(&args);
        assert_exit(&o, 2, "at most");
    }
    // clap's own refusals are exit 2 as well
    assert_exit(&raypipe(&["verify", "--rays", "1e12"]), 2, "invalid value");
}

#[test]
fn a_non_utf8_argument_is_a_clear_error() {
    use std::os::unix::ffi::OsStrExt;
    let bad = std::ffi::OsStr::from_bytes(b"/tmp/raypipe-\xff\xfe");
    let o = Command::new(env!("CARGO_BIN_EXE_raypipe"))
        .current_dir(std::env::temp_dir())
        .args(["vectors", "--unit", "op", "--format", "f32", "--out"])
        .arg(bad)
        .output()
        .unwrap();
    assert_exit(&o, 2, "not valid UTF-8");
}

#[test]
fn contradictory_options_are_refused() {
    for (f, needle) in [
        ("fp16:ftz+ieee", "subnormals"),
        ("f32:divide+recip", "division"),
        ("q8.24:saturate+wrap", "overflow"),
        ("q8.24:floor+nearest", "rounding"),
    ] {
        assert_exit(&raypipe(&["verify", "--rays", "4", "--format", f]), 2, needle);
    }
    // explain checks both ends of the t interval
    let ray = "--ray=0,0,-1,0,0,1";
    let tri = "--tri=-1,-1,0,1,-1,0,0,1,0";
    for (tmin, tmax) in [("NaN", "1"), ("0", "NaN"), ("2", "1"), ("inf", "inf"), ("-inf", "-inf")] {
        let o = raypipe(&["explain", "--format", "f32", ray, tri, "--tmin", tmin, "--tmax", tmax]);
        assert_exit(&o, 2, "--t");
    }
    // a plan's leaf size and levels against explicit flags
    let d = scratch("plan-conflict");
    let plan = d.join("plan.json");
    let o = raypipe(&["plan", "--rays", "8", "--json"]);
    assert!(o.status.success());
    std::fs::write(&plan, &o.stdout).unwrap();
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let leaf = v["leaf_size"].as_u64().unwrap();
    let base = ["vectors", "--unit", "traverse", "--count", "2", "--plan", s(&plan), "--out"];
    let out = d.join("set");
    let other = (leaf % 8 + 1).to_string();
    let mut a: Vec<&str> = base.to_vec();
    a.extend([s(&out), "--leaf-size", &other]);
    assert_exit(&raypipe(&a), 2, "conflicts with the plan");
    let mut a: Vec<&str> = base.to_vec();
    a.extend([s(&out), "--levels", "255"]);
    assert_exit(&raypipe(&a), 2, "conflicts with the plan");
    // the plan's own values may be repeated
    let same = leaf.to_string();
    let mut a: Vec<&str> = base.to_vec();
    a.extend([s(&out), "--leaf-size", &same]);
    let o = raypipe(&a);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn a_run_that_proves_nothing_exits_3_and_plan_skips_collapsed_formats() {
    let d = scratch("degenerate");
    // every triangle degenerate (collinear vertices): no test can be decisive
    let obj = d.join("flat.obj");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nv 0 2 0\nf 1 2 3\nf 1 4 5\n").unwrap();
    let o = raypipe(&["verify", "--scene", s(&obj), "--rays", "16", "--format", "f32"]);
    assert_exit(&o, 3, "INCONCLUSIVE");
    let o = raypipe(&["verify", "--scene", s(&obj), "--rays", "16", "--format", "f32", "--json"]);
    assert_eq!(o.status.code(), Some(3));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["inconclusive"][0], "f32");
    // two tiny triangles: every one collapses in q4.2 (step 1/4), which agrees with the golden
    // by missing everything, and must not be chosen
    let tiny = d.join("tiny.obj");
    std::fs::write(
        &tiny,
        "v 0 0 0\nv 0.01 0 0\nv 0 0.01 0\nv 0.9 0.9 0.9\nv 0.91 0.9 0.9\nv 0.9 0.91 0.9\nf 1 2 3\nf 4 5 6\n",
    )
    .unwrap();
    let o = raypipe(&["plan", "--scene", s(&tiny), "--rays", "32", "--format", "q4.2,f32", "--budget", "1", "--json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let q = v["formats"].as_array().unwrap().iter().find(|f| f["format"] == "q4.2").unwrap();
    assert_eq!(q["collapsed_triangles"], 2);
    assert_eq!(q["meets_budget"], false);
    assert!(q["unusable"].as_str().unwrap().contains("collapses"));
    assert_eq!(v["smallest_within_budget"], "f32");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn conservative_misses_fail_stress_and_render_exits_by_its_promise() {
    // a variant that cannot keep its promise in a format is refused, not run
    assert_exit(
        &raypipe(&["render", "--format", "q8.24", "--variant", "conservative"]),
        2,
        "not conservative in q8.24",
    );
    assert_exit(
        &raypipe(&[
            "explain",
            "--unit",
            "slab",
            "--format",
            "fp16:ftz",
            "--variant",
            "conservative",
            "--ray=0,0,0,1,0,0",
            "--box=0,0,0,1,1,1",
        ]),
        2,
        "flush-to-zero",
    );
    // stress with the edge classes passes in every format the issue names, and says so
    let o = raypipe(&[
        "stress",
        "--format",
        "f32,fp16,bf16,e8m16,q8.24,q16.16,q1.15,q1.31",
        "--variant",
        "conservative,directed",
        "--count",
        "20",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stdout));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("property (no conservative or directed variant misses a box the exact decision hits): PASS"));
    assert!(out.contains("not run: the conservative slab variant is not conservative in q1.15"));
    // render of a conservative variant counts culled boxes, and they are 0
    let d = scratch("render-cons");
    let o = raypipe(&[
        "render",
        "--width",
        "24",
        "--height",
        "24",
        "--variant",
        "conservative",
        "--json",
        "--out",
        s(&d.join("r")),
    ]);
    assert!(o.status.success());
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!((v["conservative"].as_bool(), v["culled"].as_u64()), (Some(true), Some(0)));
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn explain_answers_for_any_finite_input() {
    for f in ["fp16", "f32", "bf16", "e5m2", "q8.24", "q16.16:divide"] {
        for v in ["1e6", "1e300", "-1e300", "5e-324"] {
            let ray = format!("--ray={v},0,0,1,{v},0");
            let o = raypipe(&["explain", "--unit", "slab", "--format", f, &ray, "--box=0,0,0,1,1,1"]);
            assert!(o.status.success(), "{f} {v}: {}", String::from_utf8_lossy(&o.stderr));
            let tri = format!("--tri=0,0,0,1,0,0,0,{v},1");
            let o = raypipe(&["explain", "--format", f, &ray, &tri]);
            assert!(o.status.success(), "{f} {v}: {}", String::from_utf8_lossy(&o.stderr));
        }
    }
    // a finite origin that overflows binary16 has no exact decision, and says so
    let o = raypipe(&["explain", "--unit", "slab", "--format", "fp16", "--ray=1e6,0,0,1,0,0", "--box=0,0,0,1,1,1"]);
    assert!(String::from_utf8_lossy(&o.stdout).contains("exact decision: hit none"));
}
