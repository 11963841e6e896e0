//! The command line: the main job passes, JSON is well formed, and every bad input gives a
//! clear error and exit code 2 (never a panic).

mod common;
use common::raypipe;

use std::path::PathBuf;
use std::process::Output;

fn text(o: &Output) -> (String, String) {
    (String::from_utf8_lossy(&o.stdout).into_owned(), String::from_utf8_lossy(&o.stderr).into_owned())
}

/// A file in a fresh temporary directory.
fn temp_file(name: &str, contents: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("raypipe-cli-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, contents).unwrap();
    p
}

/// The JSON a successful run printed.
fn success_json(o: &Output) -> serde_json::Value {
    let (out, err) = text(o);
    assert!(o.status.success(), "{err}");
    serde_json::from_str(&out).unwrap()
}

fn assert_clear_error(o: &Output, needle: &str) {
    let (out, err) = text(o);
    assert_eq!(o.status.code(), Some(2), "stdout: {out}\nstderr: {err}");
    assert!(err.contains(needle), "stderr lacks '{needle}': {err}");
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn verify_prints_a_table_per_format_and_passes() {
    let o = raypipe(&["verify", "--rays", "48"]);
    let (out, err) = text(&o);
    assert!(o.status.success(), "{out}\n{err}");
    for f in ["f32", "fp16", "bf16", "e8m16", "q8.24:divide"] {
        assert!(out.lines().any(|l| l.starts_with(f)), "no row for {f}:\n{out}");
    }
    assert!(out.contains("property: PASS"));
    assert!(out.contains("seed 1"));
}

#[test]
fn verify_json_has_every_format() {
    let o = raypipe(&["verify", "--rays", "32", "--seed", "9", "--format", "f32,e5m10:ftz", "--json"]);
    assert!(o.status.success());
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("valid JSON");
    assert_eq!(v["seed"], 9);
    assert_eq!(v["passed"], true);
    let names: Vec<&str> = v["formats"].as_array().unwrap().iter().map(|f| f["format"].as_str().unwrap()).collect();
    assert_eq!(names, ["f32", "e5m10:ftz"]);
    let f32 = &v["formats"][0];
    assert_eq!(f32["tests"], 32 * 368);
    assert!(f32["decisive"].as_u64().unwrap() > 32 * 368 * 9 / 10);
}

#[test]
fn verify_loads_an_obj_scene() {
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n";
    let p = temp_file("tetra.obj", obj);
    let o = raypipe(&["verify", "--scene", p.to_str().unwrap(), "--rays", "64", "--format", "f32"]);
    let (out, err) = text(&o);
    assert!(o.status.success(), "{out}\n{err}");
    assert!(out.contains("tetra.obj (4 triangles"), "{out}");
}

#[test]
fn missing_obj_is_a_clear_error() {
    assert_clear_error(&raypipe(&["verify", "--scene", "/nonexistent/scene.obj"]), "no such file");
}

#[test]
fn malformed_obj_is_a_clear_error() {
    let p = temp_file("bad.obj", "v 0 0 0\nv 1 0 zero\nv 0 1 0\nf 1 2 3\n");
    assert_clear_error(&raypipe(&["verify", "--scene", p.to_str().unwrap()]), "malformed OBJ");
    let p = temp_file("badindex.obj", "v 0 0 0\nv 1 0 0\nf 1 2 7\n");
    assert_clear_error(&raypipe(&["verify", "--scene", p.to_str().unwrap()]), "OBJ");
}

#[test]
fn nan_and_inf_coordinates_are_clear_errors() {
    let p = temp_file("nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n");
    assert_clear_error(&raypipe(&["verify", "--scene", p.to_str().unwrap()]), "non-finite");
    let p = temp_file("inf.obj", "v 0 0 0\nv 1 0 0\nv 0 inf 0\nf 1 2 3\n");
    assert_clear_error(&raypipe(&["verify", "--scene", p.to_str().unwrap()]), "non-finite");
    let tri = "0,0,0,1,0,0,0,1,0";
    assert_clear_error(&raypipe(&["explain", "--format", "f32", "--ray", "0,0,1,0,0,NaN", "--tri", tri]), "finite");
    assert_clear_error(
        &raypipe(&["explain", "--format", "f32", "--ray", "0,0,1,0,0,-1", "--tri", "0,0,0,1,0,0,0,inf,0"]),
        "finite",
    );
}

#[test]
fn obj_without_triangles_is_a_clear_error() {
    let p = temp_file("empty.obj", "# only vertices\nv 0 0 0\nv 1 0 0\n");
    assert_clear_error(&raypipe(&["verify", "--scene", p.to_str().unwrap()]), "no triangles");
}

#[test]
fn unknown_format_is_a_clear_error() {
    let o = raypipe(&["verify", "--format", "f24"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o).1.contains("unknown format 'f24'"));
    let o = raypipe(&["explain", "--format", "fp16:fast", "--ray", "0,0,1,0,0,-1", "--tri", "0,0,0,1,0,0,0,1,0"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o).1.contains("unknown format option 'fast'"));
}

#[test]
fn explain_wrong_arity_and_bad_options_are_clear_errors() {
    assert_clear_error(
        &raypipe(&["explain", "--format", "f32", "--ray", "0,0,1", "--tri", "0,0,0,1,0,0,0,1,0"]),
        "expected 6",
    );
    assert_clear_error(
        &raypipe(&["explain", "--format", "f32", "--ray", "0,0,1,0,0,-1", "--tri", "0,0,0,1,0,0,0,1"]),
        "expected 9",
    );
    assert_clear_error(
        &raypipe(&[
            "explain",
            "--format",
            "f32",
            "--ray",
            "0,0,1,0,0,-1",
            "--tri",
            "0,0,0,1,0,0,0,1,0",
            "--det-threshold",
            "-1",
        ]),
        "det-threshold",
    );
    assert_eq!(raypipe(&["verify", "--rays", "0"]).status.code(), Some(2));
}

#[test]
fn explain_prints_every_stage_signal_with_bits() {
    let o = raypipe(&["explain", "--format", "fp16", "--ray", "0.25,0.25,1,0,0,-1", "--tri", "0,0,0,1,0,0,0,1,0"]);
    let (out, err) = text(&o);
    assert!(o.status.success(), "{err}");
    for sig in ["e1x", "pxa", "qzb", "det_xy", "uv", "valid", "inv_det", "hit"] {
        assert!(out.lines().any(|l| l.split_whitespace().nth(1) == Some(sig)), "no {sig} row:\n{out}");
    }
    // fp16 1.0 is 0x3c00; t = 1 here
    assert!(out.lines().any(|l| l.split_whitespace().nth(1) == Some("t") && l.contains("3c00")), "{out}");
    assert!(out.contains("golden: hit true t 1e0"), "{out}");
}

#[test]
fn stages_prints_the_stage_table() {
    let o = raypipe(&["stages"]);
    let out = text(&o).0;
    assert!(o.status.success());
    assert!(out.contains("| 8 | `inv_det` | div | one ÷ det |"), "{out}");
    assert_eq!(raypipe(&["stages", "--div", "fast"]).status.code(), Some(2));
}

#[test]
fn explain_slab_prints_the_stage_signals_and_the_exact_decision() {
    // origin on the x = -0.5 face, direction +0 in x: 0 x inf = NaN, ignored by the plain variant
    let args = [
        "explain",
        "--unit",
        "slab",
        "--format",
        "fp16",
        "--ray",
        "-0.5,0.25,0.25,0,1,1",
        "--box",
        "-0.5,-0.5,-0.5,0.5,0.5,0.5",
    ];
    let o = raypipe(&args);
    let (out, err) = text(&o);
    assert!(o.status.success(), "{err}");
    assert!(out.lines().any(|l| l.starts_with("tlox") && l.ends_with("7e00")), "{out}");
    assert!(out.contains("model : hit true") && out.contains("exact decision: hit true"), "{out}");
    let mut bad = args.to_vec();
    let last = bad.len() - 1;
    bad[last] = "1,1,1,0,0,0";
    assert_clear_error(&raypipe(&bad), "box min exceeds max");
    let mut v = args.to_vec();
    v.extend(["--variant", "sloppy"]);
    assert_clear_error(&raypipe(&v), "unknown slab variant");
    assert_clear_error(
        &raypipe(&["explain", "--unit", "bvh", "--format", "f32", "--ray", "0,0,0,1,0,0"]),
        "unknown unit",
    );
    assert_clear_error(
        &raypipe(&["explain", "--unit", "slab", "--format", "f32", "--ray", "0,0,0,1,0,0"]),
        "needs --box",
    );
}

#[test]
fn verify_json_has_the_slab_table() {
    let o = raypipe(&["verify", "--rays", "16", "--format", "f32,fp16", "--json"]);
    assert!(o.status.success());
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let slab = v["slab"].as_array().unwrap();
    assert_eq!(slab.len(), 2 * 5);
    for r in slab {
        assert_eq!(r["tests"], 16 * 368);
        if r["conservative"] == true {
            assert_eq!(r["false_misses"], 0, "{r}");
        }
    }
    assert!(slab.iter().any(|r| r["variant"] == "conservative" && r["format"] == "fp16" && r["conservative"] == true));
}

#[test]
fn traverse_matches_the_stack_traversal_and_reports_json() {
    let o = raypipe(&["traverse", "--rays", "2000", "--format", "f32,fp16", "--json"]);
    let (out, err) = text(&o);
    assert!(o.status.success(), "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["passed"], true);
    for row in v["rows"].as_array().unwrap() {
        assert_eq!(row["rays"], 2000);
        assert_eq!(row["history_mismatches"], 0);
        assert_eq!(row["trail_mismatches"], 0);
        assert!(row["leaves"].as_u64().unwrap() > 1000, "{row}");
    }
    let o = raypipe(&["traverse", "--rays", "100", "--variant", "directed", "--n", "1", "--leaf-size", "1"]);
    assert!(o.status.success());
    assert!(text(&o).0.contains("equivalence: PASS"));
}

#[test]
fn traverse_bad_input_is_a_clear_error() {
    assert_clear_error(
        &raypipe(&["traverse", "--levels", "3", "--rays", "10"]),
        "but the hardware has 3 level pipelines",
    );
    assert_clear_error(&raypipe(&["traverse", "--variant", "fast", "--rays", "10"]), "unknown slab variant");
    assert_clear_error(&raypipe(&["traverse", "--scene", "/nonexistent.obj"]), "no such file");
    assert_eq!(raypipe(&["traverse", "--leaf-size", "0"]).status.code(), Some(2));
    assert_eq!(raypipe(&["traverse", "--format", "f99"]).status.code(), Some(2));
}

#[test]
fn stats_reports_the_thesis_figures_and_writes_svgs() {
    let dir = std::env::temp_dir().join(format!("raypipe-cli-{}-svg", std::process::id()));
    let o = raypipe(&["stats", "--rays", "500", "--leaf-sizes", "1,4", "--json", "--svg", dir.to_str().unwrap()]);
    let (out, err) = text(&o);
    assert!(o.status.success(), "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let rows = v["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 2);
    for r in rows {
        let backs: u64 = r["back_traversals"].as_array().unwrap().iter().map(|x| x.as_u64().unwrap()).sum();
        assert_eq!(backs, 500, "every ray lands in one back-traversal bin");
        assert!(r["rays_per_leaf"].as_f64().unwrap() >= 1.0);
        assert!(r["restart_overhead"].as_f64().unwrap() >= 1.0);
    }
    // the same rays hit whatever the leaf size
    assert_eq!(rows[0]["rays_hit"], rows[1]["rays_hit"]);
    for f in [
        "fig3-1_rays_per_leaf.svg",
        "fig3-2_wasted_rti.svg",
        "fig3-4_no_back_traversal.svg",
        "fig3-5_back_distance.svg",
        "restart_overhead.svg",
    ] {
        let svg = std::fs::read_to_string(dir.join(f)).unwrap();
        assert!(svg.starts_with("<svg") && svg.contains("<polyline"), "{f}");
    }
    assert_eq!(raypipe(&["stats", "--leaf-sizes", "0"]).status.code(), Some(2));
    assert_clear_error(&raypipe(&["stats", "--scene", "/nonexistent.obj"]), "no such file");
}

#[test]
fn render_writes_the_image_and_the_diff() {
    let dir = std::env::temp_dir().join(format!("raypipe-cli-{}-render", std::process::id()));
    let o = raypipe(&[
        "render",
        "--format",
        "f32",
        "--width",
        "48",
        "--height",
        "32",
        "--out",
        dir.to_str().unwrap(),
        "--json",
    ]);
    let v = success_json(&o);
    assert_eq!(v["pixels"], 48 * 32);
    assert!(v["golden_hits"].as_u64().unwrap() > 300);
    // f32 on this scene: no holes at this resolution
    assert_eq!(v["holes"], 0, "{v}");
    for f in ["render.png", "diff.png"] {
        let bytes = std::fs::read(dir.join(f)).unwrap();
        assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "{f}");
    }
    assert_eq!(raypipe(&["render", "--width", "0"]).status.code(), Some(2));
    assert_clear_error(
        &raypipe(&["render", "--variant", "x", "--width", "4", "--height", "4"]),
        "unknown slab variant",
    );
    // the camera: given in full (and echoed back), or refused with a clear error
    let o = raypipe(&[
        "render",
        "--width",
        "8",
        "--height",
        "6",
        "--eye",
        "0.5,0.3,-2",
        "--look-at",
        "0.5,0.3,0",
        "--up",
        "0,1,0",
        "--fov",
        "30",
        "--out",
        dir.to_str().unwrap(),
        "--json",
    ]);
    let v = success_json(&o);
    assert_eq!(v["camera"]["eye"], serde_json::json!([0.5, 0.3, -2.0]));
    assert_eq!(v["camera"]["look_at"], serde_json::json!([0.5, 0.3, 0.0]));
    assert_eq!(v["camera"]["fov"], 30.0);
    for (args, needle) in [
        (&["--eye", "1,1,1", "--look-at", "1,1,1"][..], "same point"),
        (&["--up", "0,0,0"][..], "--up is zero"),
        (&["--eye", "0,5,0", "--look-at", "0,0,0"][..], "parallel"),
        (&["--fov", "180"][..], "--fov 180"),
        (&["--fov", "-5"][..], "--fov -5"),
        (&["--eye", "1,2"][..], "expected 3"),
        (&["--look-at", "1,x,2"][..], "not a number"),
        (&["--eye", "inf,0,0"][..], "finite"),
    ] {
        let mut a = vec!["render", "--width", "4", "--height", "4"];
        a.extend_from_slice(args);
        assert_clear_error(&raypipe(&a), needle);
    }
}

#[test]
fn vectors_traverse_takes_a_scene_and_refuses_what_it_cannot_use() {
    let obj = temp_file("two.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nv 3 0 0\nv 2 1 1\nf 1 2 3\nf 4 5 6\n");
    let out = std::env::temp_dir().join(format!("raypipe-cli-{}-travset", std::process::id()));
    let o = raypipe(
        &["vectors", "--unit", "traverse", "--count", "2", "--scene", obj.to_str().unwrap(), "--out"]
            .into_iter()
            .chain([out.to_str().unwrap()])
            .collect::<Vec<_>>(),
    );
    let (stdout, err) = text(&o);
    assert!(o.status.success(), "{stdout}\n{err}");
    assert!(stdout.contains("unit traverse") && stdout.contains("primary 2"), "{stdout}");
    let o = raypipe(&["vectors", "--check", out.to_str().unwrap()]);
    assert!(o.status.success(), "{:?}", text(&o));
    // a scene for a unit that draws its own cases, a missing scene, a tree too deep
    assert_clear_error(
        &raypipe(&["vectors", "--unit", "rti", "--scene", obj.to_str().unwrap(), "--out", "/tmp/x"]),
        "--scene is for unit traverse",
    );
    assert_clear_error(
        &raypipe(&["vectors", "--unit", "traverse", "--scene", "/nonexistent.obj", "--out", "/tmp/x"]),
        "nonexistent",
    );
    assert_clear_error(
        &raypipe(&["vectors", "--unit", "traverse", "--levels", "1", "--out", "/tmp/x"]),
        "level pipelines",
    );
}

#[test]
fn vectors_wrapper_axis_writes_the_map_and_wrapper_and_refuses_bad_maps() {
    let dir = std::env::temp_dir().join(format!("raypipe-cli-{}-axis", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let set = dir.join("set");
    let s = set.to_str().unwrap();
    let o = raypipe(&["vectors", "--unit", "op", "--format", "fp16", "--count", "2", "--wrapper", "axis", "--out", s]);
    assert!(o.status.success(), "{:?}", text(&o));
    let map: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(set.join("axis_map.json")).unwrap()).unwrap();
    // op inputs: class (not on tdata), opcode 4, a 16, b 16: packed from bit 0 in file order
    let lsbs: Vec<(String, u64)> = map["s_axis_tdata"]["fields"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| (f["name"].as_str().unwrap().to_string(), f["lsb"].as_u64().unwrap()))
        .collect();
    assert_eq!(lsbs, [("opcode".to_string(), 0), ("a".to_string(), 4), ("b".to_string(), 20)]);
    assert_eq!(map["s_axis_tdata"]["width"], 40);
    let wrap = std::fs::read_to_string(set.join("raypipe_axis_wrap.sv")).unwrap();
    assert!(wrap.contains("module raypipe_axis_wrap") && wrap.contains("s_axis_tdata[4 +: 16]"), "{wrap}");
    // the set with its wrapper re-checks, and may be written again in place
    let o = raypipe(&["vectors", "--check", s]);
    assert!(o.status.success(), "{:?}", text(&o));
    let o = raypipe(&["vectors", "--unit", "op", "--format", "fp16", "--count", "2", "--wrapper", "axis", "--out", s]);
    assert!(o.status.success(), "{:?}", text(&o));
    // a hand-edited wrapper is not its map's
    std::fs::write(set.join("raypipe_axis_wrap.sv"), wrap.replace("s_axis_tdata[4 +: 16]", "s_axis_tdata[5 +: 16]"))
        .unwrap();
    assert_clear_error(&raypipe(&["vectors", "--check", s]), "raypipe_axis_wrap.sv line");
    // a user map: overlapping fields, and a map that does not parse, are refused before writing
    let mut bad = map.clone();
    bad["s_axis_tdata"]["fields"][1]["lsb"] = serde_json::json!(0);
    let bad_path = dir.join("bad.json");
    std::fs::write(&bad_path, bad.to_string()).unwrap();
    let other = dir.join("other");
    let o = raypipe(&[
        "vectors",
        "--unit",
        "op",
        "--format",
        "fp16",
        "--count",
        "2",
        "--wrapper",
        "axis",
        "--axis-map",
        bad_path.to_str().unwrap(),
        "--out",
        other.to_str().unwrap(),
    ]);
    assert_clear_error(&o, "fields opcode and a share bit 0");
    assert!(!other.exists(), "nothing is written for a refused map");
    std::fs::write(&bad_path, "{").unwrap();
    let o = raypipe(&[
        "vectors",
        "--unit",
        "op",
        "--wrapper",
        "axis",
        "--axis-map",
        bad_path.to_str().unwrap(),
        "--out",
        other.to_str().unwrap(),
    ]);
    assert_clear_error(&o, "--axis-map");
    // traverse has no stream wrapper; --axis-map needs --wrapper
    assert_clear_error(
        &raypipe(&["vectors", "--unit", "traverse", "--wrapper", "axis", "--out", other.to_str().unwrap()]),
        "streaming units",
    );
    let o = raypipe(&[
        "vectors",
        "--unit",
        "op",
        "--axis-map",
        bad_path.to_str().unwrap(),
        "--out",
        other.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{:?}", text(&o));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn vectors_do_not_depend_on_the_thread_count() {
    let out = std::env::temp_dir().join(format!("raypipe-cli-{}-threads", std::process::id()));
    let mut sets = Vec::new();
    for t in ["1", "2"] {
        let _ = std::fs::remove_dir_all(&out);
        let o = raypipe(&[
            "vectors",
            "--unit",
            "rti",
            "--format",
            "fp16",
            "--level",
            "2",
            "--count",
            "3",
            "--threads",
            t,
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{:?}", text(&o));
        let mut files: Vec<(String, Vec<u8>)> = std::fs::read_dir(&out)
            .unwrap()
            .map(|e| {
                let e = e.unwrap();
                (e.file_name().to_string_lossy().into_owned(), std::fs::read(e.path()).unwrap())
            })
            .collect();
        files.sort();
        sets.push(files);
    }
    assert_eq!(sets[0], sets[1]);
    let manifest = String::from_utf8(sets[0].iter().find(|f| f.0 == "manifest.json").unwrap().1.clone()).unwrap();
    assert!(!manifest.contains("--threads"), "the thread count is not part of the recorded command");
}

#[test]
fn plan_stress_report_and_speed_refuse_bad_input_clearly() {
    assert_clear_error(&raypipe(&["stress", "--count", "0"]), "--count");
    assert_clear_error(
        &raypipe(&["stress", "--count", "1", "--format", "f32", "--variant", "nope"]),
        "unknown slab variant",
    );
    assert_clear_error(&raypipe(&["stress", "--count", "1", "--format", "f77"]), "f77");
    assert_clear_error(
        &raypipe(&["report", "--rays", "1", "--stress-count", "1", "--format", "f32", "--variant", "nope"]),
        "unknown slab variant",
    );
    assert_clear_error(&raypipe(&["report", "--scene", "/nonexistent.obj"]), "nonexistent");
    assert_clear_error(&raypipe(&["plan", "--pipelines", "0"]), "--pipelines");
    assert_clear_error(&raypipe(&["plan", "--budget=-1"]), "--budget");
    assert_clear_error(&raypipe(&["plan", "--scene", "/nonexistent.obj"]), "nonexistent");
    assert_clear_error(&raypipe(&["speed", "--pairs", "4"]), "--pairs");
    assert_clear_error(&raypipe(&["plan", "--bram-bits=-3"]), "--bram-bits");
    assert_clear_error(&raypipe(&["plan", "--dram-bytes", "0"]), "--dram-bytes");
    assert_clear_error(&raypipe(&["arch", "--dram-bytes", "0"]), "--dram-bytes");
    assert_clear_error(&raypipe(&["arch", "--rti-mhz", "0"]), "--rti-mhz");
    assert_clear_error(&raypipe(&["arch", "--leaf-sizes", "0"]), "--leaf-sizes");
    assert_clear_error(&raypipe(&["arch", "--sweep-pipelines", "0"]), "--sweep-pipelines");
    assert_clear_error(&raypipe(&["arch", "--scene", "/nonexistent.obj"]), "nonexistent");
}

/// `raypipe arch`: one estimate per (leaf size, pipeline count), an optimum per pipeline count
/// (the least total time among its rows), and the calibration's peak.
#[test]
fn arch_prints_figure_3_3_as_json_and_svg() {
    let dir = std::env::temp_dir().join(format!("raypipe-cli-{}-arch", std::process::id()));
    let o = raypipe(&[
        "arch",
        "--rays",
        "500",
        "--leaf-sizes",
        "1,4,16",
        "--sweep-pipelines",
        "2,8",
        "--svg",
        dir.to_str().unwrap(),
        "--json",
    ]);
    assert!(o.status.success(), "{:?}", text(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let rows = v["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 3 * 2);
    for opt in v["optima"].as_array().unwrap() {
        let n = opt["pipelines"].as_u64().unwrap();
        let least = rows
            .iter()
            .filter(|r| r["pipelines"] == n)
            .map(|r| r["total_s"].as_f64().unwrap())
            .fold(f64::INFINITY, f64::min);
        assert_eq!(opt["total_s"].as_f64().unwrap(), least);
    }
    // 16 pipelines (the default) at 100 MHz, 4 buffers, a triangle every 4 cycles: 1.6 G/s
    assert_eq!(v["calibration"]["peak_rti_rate"].as_f64().unwrap(), 1.6e9);
    assert_eq!(v["seed"], 1);
    for f in raypipe::arch::SVG_FILES {
        assert!(std::fs::read_to_string(dir.join(f)).unwrap().starts_with("<svg"), "{f}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn plan_and_stress_print_json() {
    let o = raypipe(&["plan", "--rays", "8", "--format", "f32,fp16", "--json"]);
    assert!(o.status.success(), "{:?}", text(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["formats"].as_array().unwrap().len(), 2);
    assert_eq!(v["history_bits"].as_u64().unwrap(), 2 * v["level_pipelines"].as_u64().unwrap());
    let o = raypipe(&["stress", "--count", "3", "--format", "fp16", "--variant", "directed", "--json"]);
    assert!(o.status.success(), "{:?}", text(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(v["slab"].as_array().unwrap().iter().all(|r| r["false_misses"] == 0));
    assert_eq!(v["seed"], 1);
}

#[test]
fn verify_and_vectors_follow_a_plan() {
    let dir = std::env::temp_dir().join(format!("raypipe-cli-{}-plan", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let o = raypipe(&["plan", "--rays", "16", "--format", "bf16,f32", "--budget", "0", "--json"]);
    assert!(o.status.success(), "{:?}", text(&o));
    let plan = dir.join("plan.json");
    std::fs::write(&plan, &o.stdout).unwrap();
    let p: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let within: Vec<String> = p["formats"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|f| f["meets_budget"] == true)
        .map(|f| f["format"].as_str().unwrap().to_string())
        .collect();
    assert!(!within.is_empty());
    // verify runs exactly the formats within budget
    let o = raypipe(&["verify", "--rays", "8", "--plan", plan.to_str().unwrap()]);
    let (out, _) = text(&o);
    assert!(o.status.success(), "{out}");
    for f in ["bf16", "f32"] {
        assert_eq!(out.lines().any(|l| l.starts_with(&format!("{f} "))), within.contains(&f.to_string()), "{out}");
    }
    // vectors take the narrowest format and the plan's level pipelines
    let set = dir.join("set");
    let o = raypipe(&[
        "vectors",
        "--unit",
        "traverse",
        "--count",
        "1",
        "--plan",
        plan.to_str().unwrap(),
        "--out",
        set.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{:?}", text(&o));
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(set.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(m["format"], p["smallest_within_budget"]);
    assert_eq!(m["params"]["max_levels"], p["level_pipelines"]);
    // a plan for another scene, or a file that is not a plan
    let obj = temp_file("other.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    assert_clear_error(
        &raypipe(&["verify", "--plan", plan.to_str().unwrap(), "--scene", obj.to_str().unwrap()]),
        "the plan was made for scene",
    );
    let bad = temp_file("bad.json", "{}");
    assert_clear_error(&raypipe(&["verify", "--plan", bad.to_str().unwrap()]), "not a plan");
}

#[test]
fn speed_fractions_are_each_rows_rate_over_the_one_peak_it_prints() {
    let o = raypipe(&["speed", "--pairs", "64", "--json"]);
    assert!(o.status.success(), "{:?}", text(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let peak = v["peak_gops"].as_f64().unwrap() * 1e9;
    // the binary16 peak exists only where AVX512-FP16 does, and then binary16 rows use it
    let peak16 = v["peak16_gops"].as_f64().map(|p| p * 1e9);
    let rows = v["rows"].as_array().unwrap();
    assert!(rows.len() >= 10 && peak > 0.0);
    for r in rows {
        let (m, ops, frac) =
            (r["mtests_per_s"].as_f64().unwrap(), r["ops"].as_f64().unwrap(), r["fraction_of_peak"].as_f64().unwrap());
        let fp16 = r["name"].as_str().unwrap().contains("fp16");
        if r["peak"] == "none" {
            // f64 and end-to-end rows: a rate, no op count, no fraction
            assert!(m > 0.0 && ops == 0.0 && frac == 0.0, "{r}");
            continue;
        }
        let against = match (r["peak"].as_str().unwrap(), peak16) {
            ("binary32", _) => {
                assert!(!(fp16 && peak16.is_some()), "{r}");
                peak
            }
            ("binary16", Some(p)) if fp16 => p,
            _ => panic!("unexpected peak: {r}"),
        };
        let want = m * 1e6 * ops / against;
        assert!((frac - want).abs() <= 1e-9 * want.max(1e-12), "{r}");
        assert!(frac > 0.0 && frac < 1.5, "{r}");
    }
    // the binary's allocator staggers columns, so both placements are measured
    let names: Vec<&str> = rows.iter().map(|r| r["name"].as_str().unwrap()).collect();
    for row in ["golden mt f64 block", "error bound f64 block", "engine: verify f32 end to end"] {
        assert!(names.iter().any(|n| n.starts_with(row)), "{row} missing from {names:?}");
    }
    // the engine's rate over the f32 kernel's, per thread count, from the rows of this run
    let rate = |name: &str| rows.iter().find(|r| r["name"] == name).unwrap()["mtests_per_s"].as_f64().unwrap();
    let f32k = rate("rti f32 kernel (dispatch)");
    let e = v["engine_over_f32_kernel"].as_array().unwrap();
    assert!(!e.is_empty());
    for pair in e {
        let (t, f) = (pair[0].as_u64().unwrap(), pair[1].as_f64().unwrap());
        let row = names
            .iter()
            .find(|n| n.starts_with("engine: verify f32") && n.ends_with(&format!(", {t} thread(s)")))
            .unwrap();
        // serde_json parses floats to within one ulp (no float_roundtrip feature): equal up to that
        let want = rate(row) / f32k;
        assert!((f - want).abs() <= 1e-12 * want, "{t} threads: {f} vs {want}");
    }
    for kernel in ["rti", "slab"] {
        for place in ["staggered columns", "columns at one page offset"] {
            let want = format!("{kernel} f32 kernel, 128 Ki pairs, {place}");
            assert!(names.contains(&want.as_str()), "{want} missing from {names:?}");
        }
    }
}

/// `speed --cap` measures as a narrower machine would: every dispatch (the f32 / fp16 kernels
/// it names) stays within the cap, the cap is in the JSON, and an unknown cap is refused.
#[test]
fn speed_cap_limits_every_kernel_it_names() {
    let o = raypipe(&["speed", "--pairs", "64", "--cap", "scalar", "--json"]);
    assert!(o.status.success(), "{:?}", text(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["cap"], "scalar");
    assert_eq!(v["kernels"], serde_json::json!(["Scalar", "Scalar"]));
    let o = raypipe(&["speed", "--pairs", "64", "--cap", "avx2"]);
    assert!(o.status.success(), "{:?}", text(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("kernels (capped at avx2): f32 "), "{out}");
    assert!(!out.contains("Avx512"), "{out}");
    assert_clear_error(&raypipe(&["speed", "--cap", "avx3"]), "--cap");
}

/// `verify --cap` changes the instructions, not the report: the same counts, errors and
/// explain lines under every cap (timing fields aside).
#[test]
fn verify_cap_changes_no_result() {
    let untimed = |args: &[&str]| -> serde_json::Value {
        let mut v = vec!["verify", "--rays", "48", "--format", "f32,fp16,e8m16", "--json", "--quiet"];
        v.extend_from_slice(args);
        let o = raypipe(&v);
        assert!(o.status.success(), "{:?}", text(&o));
        let mut j: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        for part in ["formats", "slab"] {
            for f in j[part].as_array_mut().unwrap() {
                let f = f.as_object_mut().unwrap();
                f.remove("mtests_per_s");
                f.remove("judged_mtests_per_s");
            }
        }
        j
    };
    let wide = untimed(&[]);
    for cap in ["scalar", "avx2"] {
        assert_eq!(untimed(&["--cap", cap]), wide, "--cap {cap}");
    }
    assert_clear_error(&raypipe(&["verify", "--cap", "avx3"]), "--cap");
}

/// Shell completions and man pages come from the same clap definitions as the parser: every
/// command is in them, and the scripts parse in the shells installed here.
#[test]
fn completions_and_man_pages_cover_every_command() {
    let commands = [
        "verify", "explain", "traverse", "ops", "merge", "arch", "stats", "render", "vectors", "faults", "plan",
        "report", "speed", "stress", "stages",
    ];
    for shell in ["bash", "zsh", "fish", "elvish", "powershell"] {
        let o = raypipe(&["completions", shell]);
        let (out, err) = text(&o);
        assert!(o.status.success(), "{shell}: {err}");
        for c in commands {
            assert!(out.contains(c), "{shell} completions lack {c}");
        }
        // a shell that is installed checks the script's syntax
        let sh = match shell {
            "bash" | "zsh" => Some(shell),
            _ => None,
        };
        if let Some(sh) = sh {
            let dir = std::env::temp_dir().join(format!("raypipe-cli-{}-compl", std::process::id()));
            std::fs::create_dir_all(&dir).unwrap();
            let f = dir.join(format!("raypipe.{sh}"));
            std::fs::write(&f, &out).unwrap();
            if let Ok(st) = std::process::Command::new(sh).arg("-n").arg(&f).status() {
                assert!(st.success(), "{sh} -n rejects the completion script");
            }
        }
    }
    let (page, _) = text(&raypipe(&["man"]));
    assert!(page.starts_with(".ie") || page.contains(".TH raypipe 1"), "{page}");
    for c in commands {
        assert!(page.contains(c), "the man page lacks {c}");
        let o = raypipe(&["man", c]);
        let (sub, err) = text(&o);
        assert!(o.status.success(), "man {c}: {err}");
        assert!(sub.contains(&format!(".TH raypipe-{c} 1")), "man {c}: {sub}");
    }
    assert!(text(&raypipe(&["man", "render"])).0.contains("look\\-at"));
    assert_clear_error(&raypipe(&["man", "nope"]), "no command 'nope'");
    assert_eq!(raypipe(&["completions", "tcsh"]).status.code(), Some(2));
}

/// `--help` names every value a choice accepts.
#[test]
fn help_lists_every_accepted_value() {
    let help = |c: &str| text(&raypipe(&[c, "--help"])).0;
    let v = help("vectors");
    for unit in ["rti", "slab", "op", "traverse", "capture"] {
        assert!(v.contains(unit), "vectors --help lacks unit {unit}");
    }
    for c in ["render", "explain", "traverse"] {
        let h = help(c);
        for variant in datapath::slab::SLAB_VARIANTS {
            assert!(h.contains(variant), "{c} --help lacks slab variant {variant}");
        }
    }
    assert!(help("speed").contains("avx512fp16"));
    assert!(help("completions").contains("fish"));
}
