//! `raypipe cover` from the command line: the report and its JSON, merging sets, --fail-under,
//! and bad input (exit 2).

mod common;
use common::raypipe;

fn set(dir: &std::path::Path, args: &[&str]) {
    let mut a = vec!["vectors"];
    a.extend_from_slice(args);
    let out = dir.display().to_string();
    a.extend(["--out", &out]);
    let o = raypipe(&a);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// `raypipe cover --json ARGS…`, which must succeed.
fn cover_json(args: &[&str]) -> serde_json::Value {
    let mut v = vec!["cover", "--json"];
    v.extend_from_slice(args);
    let o = raypipe(&v);
    assert!(o.status.success(), "{args:?}: {}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).unwrap()
}

/// Runs raypipe, which must succeed: its stdout as JSON (null when it printed none).
fn run_json(args: &[&str]) -> serde_json::Value {
    let o = raypipe(args);
    assert!(o.status.success(), "{args:?}: {}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).unwrap_or(serde_json::Value::Null)
}

#[test]
fn cover_reports_merges_and_gates() {
    let tmp = std::env::temp_dir().join(format!("raypipe-cover-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&tmp);
    std::fs::create_dir_all(&tmp).unwrap();
    let (a, b, f32set) = (tmp.join("a"), tmp.join("b"), tmp.join("f32"));
    set(&a, &["--unit", "op", "--format", "fp16", "--count", "2", "--seed", "1"]);
    set(&b, &["--unit", "op", "--format", "fp16", "--count", "2", "--seed", "2"]);
    set(&f32set, &["--unit", "op", "--format", "f32", "--count", "2"]);
    let json = cover_json;
    let (sa, sb) = (a.display().to_string(), b.display().to_string());
    let ja = json(&[&sa]);
    let jb = json(&[&sb]);
    let jab = json(&[&sa, &sb]);
    // merged counts are the sums, bin by bin
    assert_eq!(jab["vectors"].as_u64().unwrap(), ja["vectors"].as_u64().unwrap() + jb["vectors"].as_u64().unwrap());
    let bins = |j: &serde_json::Value| -> Vec<u64> {
        j["coverpoints"]
            .as_array()
            .unwrap()
            .iter()
            .flat_map(|p| p["bins"].as_array().unwrap().iter().map(|b| b["count"].as_u64().unwrap()))
            .collect()
    };
    let sum: Vec<u64> = bins(&ja).iter().zip(bins(&jb)).map(|(x, y)| x + y).collect();
    assert_eq!(bins(&jab), sum);
    // the op unit's default set reaches every reachable bin; result's "other NaN" is unreachable
    assert_eq!(ja["bins_hit"], ja["bins"]);
    assert!(ja["bins_unreachable"].as_u64().unwrap() >= 1);
    assert!(raypipe(&["cover", &sa, "--fail-under", "100"]).status.success());
    // an rti set does not reach everything: --fail-under 100 fails it (exit 1)
    let r = tmp.join("rti");
    set(&r, &["--unit", "rti", "--format", "fp16", "--count", "1"]);
    let o = raypipe(&["cover", &r.display().to_string(), "--fail-under", "100"]);
    assert_eq!(o.status.code(), Some(1));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("empty bins") && text.contains("reachable bins hit"), "{text}");
    // each hole names the default set's classes that reach it: a hole names no class exactly
    // when the default set (64 per class, seed 1), written and measured on its own, misses it too
    let jr = json(&[&r.display().to_string()]);
    let (holes, stim) = (jr["holes"].as_array().unwrap(), jr["hole_stimulus"].as_array().unwrap());
    assert_eq!(holes.len(), stim.len());
    let d = tmp.join("rti-default");
    set(&d, &["--unit", "rti", "--format", "fp16"]);
    let jd = json(&[&d.display().to_string()]);
    let default_holes: Vec<&serde_json::Value> = jd["holes"].as_array().unwrap().iter().collect();
    let mut named = 0;
    for (h, st) in holes.iter().zip(stim) {
        let st = st.as_str().unwrap();
        assert_eq!(st.starts_with("no default class"), default_holes.contains(&h), "{h}: {st}");
        named += usize::from(st.starts_with("class "));
    }
    assert!(named > 0);
    // sets of two formats: two models, each reported on its own
    let two = json(&[&sa, &f32set.display().to_string()]);
    let formats: Vec<&str> = two["models"].as_array().unwrap().iter().map(|m| m["format"].as_str().unwrap()).collect();
    assert_eq!(formats, ["fp16", "f32"]);
    assert!(two.get("coverpoints").is_none(), "several models have no top-level coverpoints");
    // bad input: a percentage out of range, no set
    for args in [
        vec!["cover".to_string(), sa.clone(), "--fail-under".to_string(), "101".to_string()],
        vec!["cover".to_string(), tmp.join("none").display().to_string()],
    ] {
        let v: Vec<&str> = args.iter().map(String::as_str).collect();
        let o = raypipe(&v);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(!err.contains("panicked"));
    }
    // --ucis: written, replaced when raypipe wrote it, never over a stranger's file
    let x = tmp.join("cov.xml");
    let xs = x.display().to_string();
    for _ in 0..2 {
        assert!(raypipe(&["cover", &sa, "--ucis", &xs]).status.success());
    }
    let text = std::fs::read_to_string(&x).unwrap();
    assert!(text.starts_with("<?xml") && text.contains("writtenBy=\"raypipe ") && text.contains("<coverpointBin"));
    let mine = tmp.join("mine.xml");
    std::fs::write(&mine, "mine").unwrap();
    let o = raypipe(&["cover", &sa, "--ucis", &mine.display().to_string()]);
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(std::fs::read_to_string(&mine).unwrap(), "mine");
    // traverse: leaves returned, passes and each level's history state, one bin per ray each
    let t = tmp.join("trav");
    set(&t, &["--unit", "traverse", "--format", "fp16", "--count", "2"]);
    let jt = json(&[&t.display().to_string()]);
    let rays = jt["vectors"].as_u64().unwrap();
    let points = jt["coverpoints"].as_array().unwrap();
    let sum =
        |p: &serde_json::Value| p["bins"].as_array().unwrap().iter().map(|b| b["count"].as_u64().unwrap()).sum::<u64>();
    for kind in ["leaves returned", "passes", "history state"] {
        let ps: Vec<&serde_json::Value> = points.iter().filter(|p| p["kind"] == kind).collect();
        assert!(!ps.is_empty(), "{kind}");
        assert!(ps.iter().all(|p| sum(p) == rays), "{kind}");
    }
    let _ = std::fs::remove_dir_all(&tmp);
}

/// `vectors --close`: the closed set reaches every reachable bin (`cover --fail-under 100`
/// passes it; slab conservative and traverse in fp16 and f32), `vectors --check` accepts it,
/// and --close is refused where it does not apply (exit 2: with --check or --minimal, a budget
/// over the limit).
#[test]
fn vectors_close_from_the_command_line() {
    let tmp = std::env::temp_dir().join(format!("raypipe-close-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&tmp);
    std::fs::create_dir_all(&tmp).unwrap();
    let s = tmp.join("slab");
    let o = raypipe(&[
        "vectors",
        "--unit",
        "slab",
        "--variant",
        "conservative",
        "--format",
        "fp16",
        "--close",
        "--out",
        &s.display().to_string(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("coverage closure:") && text.contains("close "), "{text}");
    let ss = s.display().to_string();
    assert!(raypipe(&["cover", &ss, "--fail-under", "100"]).status.success());
    // --json: the closure's numbers, the classes (close last)
    let sj = tmp.join("slab-json");
    let o = raypipe(&[
        "vectors",
        "--unit",
        "slab",
        "--format",
        "fp16",
        "--close",
        "--close-budget",
        "20000",
        "--json",
        "--out",
        &sj.display().to_string(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let c = &j["closure"];
    assert!(c["bins_hit_after"].as_u64().unwrap() > c["bins_hit_before"].as_u64().unwrap());
    assert!(c["candidates"].as_u64().unwrap() <= 20000);
    assert_eq!(j["classes"].as_array().unwrap().last().unwrap()["name"], "close");
    assert_eq!(j["classes"].as_array().unwrap().last().unwrap()["count"], c["kept"]);
    let o = raypipe(&["vectors", "--check", &sj.display().to_string(), "--json"]);
    let j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(j["vectors"].as_u64().unwrap() > 0);
    // the HTML view: no holes in the closed set, some in the set without the close class
    let h = tmp.join("cov.html");
    let hs = h.display().to_string();
    for _ in 0..2 {
        assert!(raypipe(&["cover", &ss, "--html", &hs]).status.success());
    }
    let page = std::fs::read_to_string(&h).unwrap();
    assert!(page.contains("None: every reachable bin is hit") && page.contains("class=\"b un\""), "{}", &page[..400]);
    let open = tmp.join("open");
    let os = open.display().to_string();
    let o = raypipe(&["vectors", "--unit", "slab", "--variant", "conservative", "--format", "fp16", "--out", &os]);
    assert!(o.status.success());
    assert!(raypipe(&["cover", &os, "--html", &hs]).status.success());
    let page = std::fs::read_to_string(&h).unwrap();
    assert!(page.contains("<h2>Holes (") && page.contains("class=\"b hole\""));
    let mine = tmp.join("mine.html");
    std::fs::write(&mine, "<html>mine</html>").unwrap();
    let o = raypipe(&["cover", &ss, "--html", &mine.display().to_string()]);
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(std::fs::read_to_string(&mine).unwrap(), "<html>mine</html>");
    assert!(raypipe(&["vectors", "--check", &ss]).status.success());
    let m: serde_json::Value = serde_json::from_slice(&std::fs::read(s.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(m["classes"].as_array().unwrap().last().unwrap()["name"], "close");
    assert!(m["closure"]["origin"].as_str().unwrap().contains("seed"));
    // traverse (built-in scene): every closure ray is also checked against the stack traversal
    for format in ["fp16", "f32"] {
        let t = tmp.join(format!("trav-{format}"));
        let ts = t.display().to_string();
        let o = raypipe(&["vectors", "--unit", "traverse", "--format", format, "--close", "--out", &ts]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        assert!(raypipe(&["cover", &ts, "--fail-under", "100"]).status.success(), "traverse {format}");
        assert!(raypipe(&["vectors", "--check", &ts]).status.success());
    }
    for args in [
        vec!["vectors", "--unit", "rti", "--close", "--check", "x"],
        vec!["vectors", "--unit", "rti", "--close", "--minimal"],
        vec!["vectors", "--unit", "rti", "--close", "--close-budget", "1000000000"],
    ] {
        let out = tmp.join("x").display().to_string();
        let mut v = args.clone();
        v.extend(["--out", &out]);
        let o = raypipe(&v);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(!err.contains("panicked"));
        assert!(!tmp.join("x").exists());
    }
    let _ = std::fs::remove_dir_all(&tmp);
}

/// `ops --cover FILE`: the sweep's coverage as a file `raypipe cover` reads; two shards' files
/// merged equal the one-pass file bin by bin, a file merges with a vector set of the same unit
/// and format, and a file raypipe did not write is refused before any work (exit 2).
#[test]
fn ops_cover_files_merge_like_one_pass() {
    let tmp = std::env::temp_dir().join(format!("raypipe-opscover-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&tmp);
    std::fs::create_dir_all(&tmp).unwrap();
    let p = |n: &str| tmp.join(n).display().to_string();
    let ops = |extra: &[&str]| {
        let mut v = vec!["ops", "--format", "fp16", "--op", "mul", "--count", "30000", "--quiet"];
        v.extend_from_slice(extra);
        let o = raypipe(&v);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    };
    ops(&["--cover", &p("whole.json")]);
    ops(&["--cover", &p("s0.json"), "--shard", "0/2", "--partial", &p("p0.json")]);
    ops(&["--cover", &p("s1.json"), "--shard", "1/2", "--partial", &p("p1.json")]);
    let json = cover_json;
    let whole = json(&[&p("whole.json")]);
    let merged = json(&[&p("s0.json"), &p("s1.json")]);
    assert_eq!(whole["vectors"], 30000);
    assert_eq!(whole["coverpoints"], merged["coverpoints"]);
    assert_eq!(whole["vectors"], merged["vectors"]);
    // the result coverpoint counts every row once
    let result = whole["coverpoints"].as_array().unwrap().iter().find(|c| c["signal"] == "result").unwrap();
    let sum: u64 = result["bins"].as_array().unwrap().iter().map(|b| b["count"].as_u64().unwrap()).sum();
    assert_eq!(sum, 30000);
    // with a vector set of the same unit and format
    let set = tmp.join("set");
    let o =
        raypipe(&["vectors", "--unit", "op", "--format", "fp16", "--count", "2", "--out", &set.display().to_string()]);
    assert!(o.status.success());
    let both = json(&[&p("whole.json"), &set.display().to_string()]);
    assert!(both["vectors"].as_u64().unwrap() > 30000);
    // a stranger's file is not replaced
    std::fs::write(tmp.join("mine.json"), "{}").unwrap();
    let o = raypipe(&["ops", "--format", "fp16", "--op", "mul", "--count", "10", "--cover", &p("mine.json")]);
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(std::fs::read_to_string(tmp.join("mine.json")).unwrap(), "{}");
    let _ = std::fs::remove_dir_all(&tmp);
}

/// The count of bin `bin` of coverpoint `signal` in `role` of a `cover --json` model.
fn bin_count(model: &serde_json::Value, role: &str, signal: &str, bin: &str) -> u64 {
    let p = model["coverpoints"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["role"] == role && p["signal"] == signal)
        .unwrap_or_else(|| panic!("no coverpoint {role} {signal}"));
    p["bins"].as_array().unwrap().iter().find(|b| b["name"] == bin).map_or(0, |b| b["count"].as_u64().unwrap())
}

/// `verify --cover` and `stress --cover`: one model per unit, format and slab variant; every test
/// of the run counted once, its hit flag as the run's own (SIMD, judged) pass counted it; the
/// shards' files merged equal the one-pass file; a run's file merges with a vector set of the
/// same model (class bins by name); a file raypipe did not write is refused before the work.
#[test]
fn verify_and_stress_cover_count_every_test_and_merge_like_one_pass() {
    let tmp = std::env::temp_dir().join(format!("raypipe-runcover-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&tmp);
    std::fs::create_dir_all(&tmp).unwrap();
    let p = |n: &str| tmp.join(n).display().to_string();
    let run = run_json;
    let cover = cover_json;
    let verify = ["verify", "--rays", "40", "--format", "fp16", "--quiet"];
    let rep = run(&[&verify[..], &["--json", "--cover", &p("v.json")]].concat());
    let c = cover(&[&p("v.json")]);
    let models = c["models"].as_array().unwrap();
    // rti and the slab variants with a coverage model (directed has none)
    let names: Vec<String> = models
        .iter()
        .map(|m| format!("{} {}", m["unit"].as_str().unwrap(), m["variant"].as_str().unwrap_or("")))
        .collect();
    assert_eq!(names, ["rti ", "slab plain", "slab conservative", "slab take-on-false", "slab embree"]);
    let f = &rep["formats"][0];
    assert_eq!(models[0]["vectors"], f["tests"]);
    assert_eq!(bin_count(&models[0], "expected outputs", "hit", "1"), f["model_hits"].as_u64().unwrap());
    assert_eq!(bin_count(&models[0], "inputs", "class", "scene"), f["tests"].as_u64().unwrap());
    for m in &models[1..] {
        let r = rep["slab"].as_array().unwrap().iter().find(|r| r["variant"] == m["variant"]).unwrap();
        let n = |k: &str| r[k].as_u64().unwrap();
        assert_eq!(m["vectors"], r["tests"]);
        assert_eq!(
            bin_count(m, "expected outputs", "hit", "1"),
            n("exact_hits") - n("false_misses") + n("false_hits"),
            "{}",
            m["variant"]
        );
    }
    // two shards' files merged equal the one pass
    run(&[&verify[..], &["--shard", "0/2", "--partial", &p("p0.json"), "--cover", &p("s0.json")]].concat());
    run(&[&verify[..], &["--shard", "1/2", "--partial", &p("p1.json"), "--cover", &p("s1.json")]].concat());
    let merged = cover(&[&p("s0.json"), &p("s1.json")]);
    assert_eq!(merged["models"], c["models"]);
    // with a vector set of the same model: the set's classes and `scene` side by side
    let set = tmp.join("set");
    rti_set(&set);
    let both = cover(&[&p("v.json"), &set.display().to_string()]);
    let rti = &both["models"][0];
    assert_eq!(both["models"].as_array().unwrap().len(), 5);
    assert_eq!(bin_count(rti, "inputs", "class", "scene"), f["tests"].as_u64().unwrap());
    assert!(bin_count(rti, "inputs", "class", "random") > 0);
    assert!(rti["vectors"].as_u64().unwrap() > f["tests"].as_u64().unwrap());
    // stress: the stress classes are the class bins, each class's tests counted
    let st = run(&[
        "stress",
        "--count",
        "12",
        "--format",
        "fp16",
        "--variant",
        "plain,conservative,directed",
        "--quiet",
        "--json",
        "--cover",
        &p("st.json"),
    ]);
    let sc = cover(&[&p("st.json")]);
    let sm = sc["models"].as_array().unwrap();
    assert_eq!(sm.len(), 3, "rti, plain, conservative (directed has no model)");
    for r in st["rti"].as_array().unwrap() {
        assert_eq!(bin_count(&sm[0], "inputs", "class", r["class"].as_str().unwrap()), r["tests"].as_u64().unwrap());
    }
    for m in &sm[1..] {
        for r in st["slab"].as_array().unwrap().iter().filter(|r| r["variant"] == m["variant"]) {
            assert_eq!(bin_count(m, "inputs", "class", r["class"].as_str().unwrap()), r["tests"].as_u64().unwrap());
        }
        let hits: u64 = st["slab"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|r| r["variant"] == m["variant"])
            .map(|r| {
                let n = |k: &str| r[k].as_u64().unwrap();
                n("exact_hits") - n("false_misses") + n("false_hits") + n("undecided_hits")
            })
            .sum();
        assert_eq!(bin_count(m, "expected outputs", "hit", "1"), hits, "{}", m["variant"]);
    }
    // a stranger's file is refused before the work, and kept
    std::fs::write(tmp.join("mine.json"), "{}").unwrap();
    for args in [
        vec!["verify", "--rays", "4", "--quiet", "--cover", &p("mine.json")],
        vec!["stress", "--count", "2", "--quiet", "--cover", &p("mine.json")],
    ] {
        let o = raypipe(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        assert_eq!(std::fs::read_to_string(tmp.join("mine.json")).unwrap(), "{}");
    }
    let _ = std::fs::remove_dir_all(&tmp);
}

/// The default rti fp16 set (one vector per class).
fn rti_set(dir: &std::path::Path) {
    set(dir, &["--unit", "rti", "--format", "fp16", "--count", "1"]);
}

/// `traverse --cover`: one traverse model per format on the run's BVH; every ray counted once;
/// rays with a restart (two or more passes) are the rays that reach a back-traversal distance
/// bin; the shards' files merged equal the one-pass file, which merges with a vector set of the
/// built-in scene; the directed variant (no traverse model) is refused before the run.
#[test]
fn traverse_cover_counts_every_ray_and_merges_like_one_pass() {
    let tmp = std::env::temp_dir().join(format!("raypipe-travcover-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&tmp);
    std::fs::create_dir_all(&tmp).unwrap();
    let p = |n: &str| tmp.join(n).display().to_string();
    let run = run_json;
    let trav = ["traverse", "--rays", "600", "--format", "fp16,f32", "--quiet"];
    let rep = run(&[&trav[..], &["--json", "--cover", &p("t.json")]].concat());
    let c = cover_json(&[&p("t.json")]);
    let models = c["models"].as_array().unwrap();
    assert_eq!(models.len(), 2);
    for (m, row) in models.iter().zip(rep["rows"].as_array().unwrap()) {
        assert_eq!(m["unit"], "traverse");
        assert_eq!(m["format"], row["format"]);
        assert_eq!(m["vectors"], row["rays"]);
        let passes = |b: &str| bin_count(m, "expected outputs", "passes", b);
        let restarted = passes("2") + passes("3 or more");
        assert!(restarted > 0, "{}", m["format"]);
        let back: Vec<u64> = ["0", "1", "2", "3 or more"]
            .iter()
            .map(|b| bin_count(m, "events", "back-traversal distance of a restart (levels)", b))
            .collect();
        // each restarted ray reaches one to four distance bins, and no other ray reaches any
        let total: u64 = back.iter().sum();
        assert!(restarted <= total && total <= 4 * restarted, "{back:?} vs {restarted}");
        // the report's restarts: at least one per restarted ray
        assert!(row["restarts"].as_u64().unwrap() >= restarted);
        let ties: Vec<u64> = ["no tie", "tie, the nearer (left) child taken", "tie, the farther (right) child taken"]
            .iter()
            .map(|b| bin_count(m, "events", "siblings both hit at equal entry t (a tie) on the path", b))
            .collect();
        // every ray is counted in the tie coverpoint: in `no tie` or in one or both tie bins
        let rays = m["vectors"].as_u64().unwrap();
        assert!(ties[0] + ties[1].max(ties[2]) <= rays && rays <= ties.iter().sum::<u64>(), "{ties:?} of {rays}");
    }
    // two shards' files merged equal the one pass
    run(&[&trav[..], &["--shard", "0/2", "--partial", &p("p0.json"), "--cover", &p("s0.json")]].concat());
    run(&[&trav[..], &["--shard", "1/2", "--partial", &p("p1.json"), "--cover", &p("s1.json")]].concat());
    assert_eq!(cover_json(&[&p("s0.json"), &p("s1.json")])["models"], c["models"]);
    // with the built-in scene's traverse set: one model, the set's classes beside `scene`
    let set = p("set");
    let o = raypipe(&["vectors", "--unit", "traverse", "--format", "fp16", "--count", "2", "--out", &set]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let both = cover_json(&[&p("t.json"), &set]);
    let fp16 = &both["models"][0];
    assert_eq!(bin_count(fp16, "inputs", "class", "scene"), 600);
    assert!(bin_count(fp16, "inputs", "class", "primary") > 0);
    // directed: refused before the run (exit 2), nothing written
    let o = raypipe(&["traverse", "--rays", "10", "--variant", "directed", "--cover", &p("d.json")]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("directed"));
    assert!(!tmp.join("d.json").exists());
    // a file raypipe did not write is never replaced: refused before the run (exit 2), unchanged
    std::fs::write(tmp.join("mine.json"), "my notes").unwrap();
    let o = raypipe(&["traverse", "--rays", "10", "--quiet", "--cover", &p("mine.json")]);
    assert_eq!(o.status.code(), Some(2), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(std::fs::read_to_string(tmp.join("mine.json")).unwrap(), "my notes");
    let _ = std::fs::remove_dir_all(&tmp);
}
