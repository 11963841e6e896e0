//! Vector sets: written deterministically and atomically, read back bit for bit against the
//! models, and a set with one flipped bit is caught.

use datapath::rti::RtiConfig;
use std::path::PathBuf;
use vectors::check::check_set;
use vectors::gen::{generate, Request, Unit};
use vectors::traverse::TreeInput;
use vectors::write::write_set;

fn req(unit: Unit, format: &str, count: usize) -> Request {
    Request {
        unit,
        format: format.parse().unwrap(),
        count,
        seed: 7,
        level: 1,
        command: "test".into(),
        rti: RtiConfig::default(),
        // conservative where the format keeps its promise (IEEE floats with subnormals)
        slab_variant: if format.starts_with('q') || format.contains("ftz") { "plain" } else { "conservative" }.into(),
        tree: (unit == Unit::Traverse).then(builtin_tree),
        leaves: 8,
        max_levels: 64,
        explicit: None,
        closure: None,
        threads: 1,
    }
}

/// A BVH over 64 overlapping boxes on a jittered 4 x 4 x 4 grid in [-1, 1]³ (median splits on the
/// longest axis of the centres; leaf ids in box order): the shape of a scene's tree, built here
/// so that the vectors crate tests without the CLI's scene code.
fn builtin_tree() -> TreeInput {
    use datapath::bvh::NodeDesc;
    let mut r = datapath::rng::SplitMix64::new(0x7472_6565);
    let boxes: Vec<([f64; 3], [f64; 3])> = (0..64)
        .map(|i| {
            let c: [f64; 3] = std::array::from_fn(|a| {
                let k = [i % 4, i / 4 % 4, i / 16][a] as f64;
                (k - 1.5) * 0.5 + r.range(-0.05, 0.05)
            });
            let h = r.range(0.2, 0.3);
            (c.map(|x| x - h), c.map(|x| x + h))
        })
        .collect();
    fn build(boxes: &[([f64; 3], [f64; 3])], ids: &mut [usize], nodes: &mut Vec<NodeDesc>) -> u32 {
        let lo: [f64; 3] = std::array::from_fn(|a| ids.iter().map(|&i| boxes[i].0[a]).fold(f64::INFINITY, f64::min));
        let hi: [f64; 3] =
            std::array::from_fn(|a| ids.iter().map(|&i| boxes[i].1[a]).fold(f64::NEG_INFINITY, f64::max));
        let at = nodes.len() as u32;
        nodes.push(NodeDesc { children: None, leaf: ids[0] as u32, min: lo, max: hi });
        if ids.len() > 1 {
            let axis = (0..3).max_by(|&a, &b| (hi[a] - lo[a]).total_cmp(&(hi[b] - lo[b]))).unwrap();
            let centre = |i: usize| boxes[i].0[axis] + boxes[i].1[axis];
            ids.sort_by(|&x, &y| centre(x).total_cmp(&centre(y)).then(x.cmp(&y)));
            let (l, r) = ids.split_at_mut(ids.len() / 2);
            let left = build(boxes, l, nodes);
            let right = build(boxes, r, nodes);
            nodes[at as usize].children = Some([left, right]);
        }
        at
    }
    let mut ids: Vec<usize> = (0..boxes.len()).collect();
    let mut nodes = Vec::new();
    build(&boxes, &mut ids, &mut nodes);
    TreeInput { name: "grid64".into(), nodes, root: 0 }
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("raypipe-vec-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

#[test]
fn every_unit_and_format_round_trips() {
    for unit in [Unit::Rti, Unit::Slab, Unit::Op, Unit::Traverse, Unit::Capture] {
        for format in ["f32", "fp16", "bf16", "e8m16", "q8.24:divide", "fp16:ftz"] {
            let set = generate(&req(unit, format, 6)).unwrap();
            let dir = tmp(&format!("{unit:?}-{}", format.replace(':', "_")));
            write_set(&set, &dir).unwrap();
            let n = check_set(&dir).unwrap_or_else(|e| panic!("{unit:?} {format}: {e}"));
            assert_eq!(n, set.manifest.files[0].rows);
            // every row has exactly the manifest's digit count, lowercase hex only
            for f in &set.manifest.files {
                let text = std::fs::read_to_string(dir.join(&f.name)).unwrap();
                assert!(text.lines().all(|l| l.len() == f.digits as usize
                    && l.chars().all(|c| c.is_ascii_hexdigit() && !c.is_ascii_uppercase())));
                // fields tile the row exactly
                let mut lsb = 0;
                for field in f.fields.iter().rev() {
                    assert_eq!(field.lsb, lsb);
                    lsb += field.width;
                }
                assert_eq!(lsb, f.width);
            }
            std::fs::remove_dir_all(&dir).unwrap();
        }
    }
}

#[test]
fn the_same_request_writes_the_same_bytes() {
    for unit in [Unit::Rti, Unit::Slab, Unit::Op, Unit::Traverse, Unit::Capture] {
        let a = generate(&req(unit, "fp16", 5)).unwrap();
        let b = generate(&req(unit, "fp16", 5)).unwrap();
        assert_eq!(a.files, b.files);
        let (da, db) = (tmp(&format!("det-a-{unit:?}")), tmp(&format!("det-b-{unit:?}")));
        write_set(&a, &da).unwrap();
        write_set(&b, &db).unwrap();
        for f in std::fs::read_dir(&da).unwrap() {
            let name = f.unwrap().file_name();
            assert_eq!(std::fs::read(da.join(&name)).unwrap(), std::fs::read(db.join(&name)).unwrap(), "{name:?}");
        }
        let c = generate(&Request { seed: 8, ..req(unit, "fp16", 5) }).unwrap();
        if unit != Unit::Op || c.manifest.classes[1].count > 0 {
            assert_ne!(a.files, c.files, "another seed must give other vectors");
        }
    }
}

#[test]
fn every_class_is_covered_and_counted() {
    let set = generate(&req(Unit::Rti, "f32", 3)).unwrap();
    assert!(set.manifest.classes.iter().all(|c| c.count == 3), "{:?}", set.manifest.classes);
    let fixed = generate(&req(Unit::Rti, "q8.24:divide", 3)).unwrap();
    let names: Vec<_> = fixed.manifest.classes.iter().filter(|c| c.count == 0).map(|c| c.name.as_str()).collect();
    assert_eq!(
        names,
        ["subnormal", "inf_nan", "tiny_products", "t_subnormal"],
        "fixed point has no subnormals or inf/NaN"
    );
    let total: usize = set.manifest.classes.iter().map(|c| c.count).sum();
    assert_eq!(total, set.manifest.files[0].rows);
}

#[test]
fn a_flipped_bit_is_caught() {
    let set = generate(&req(Unit::Rti, "fp16", 4)).unwrap();
    let dir = tmp("flip");
    write_set(&set, &dir).unwrap();
    let path = dir.join("rti_expected.hex");
    let text = std::fs::read_to_string(&path).unwrap();
    // flip the lowest bit of the t field of line 3 (u and v are below it: t's lsb from the manifest)
    let m = &set.manifest.files[1];
    let t = m.fields.iter().find(|f| f.name == "t").unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let digits = m.digits as usize;
    let bit = t.lsb as usize;
    let pos = digits - 1 - bit / 4;
    let mut chars: Vec<char> = lines[2].chars().collect();
    let v = chars[pos].to_digit(16).unwrap() ^ (1 << (bit % 4));
    chars[pos] = char::from_digit(v, 16).unwrap();
    lines[2] = chars.into_iter().collect();
    let flipped = lines.join("\n") + "\n";
    std::fs::write(&path, &flipped).unwrap();
    assert!(check_set(&dir).unwrap_err().contains("sha256"));
    // with a matching hash the model comparison itself catches it
    let mut manifest: vectors::manifest::Manifest =
        serde_json::from_str(&std::fs::read_to_string(dir.join("manifest.json")).unwrap()).unwrap();
    use sha2::Digest;
    manifest.files[1].sha256 = sha2::Sha256::digest(flipped.as_bytes()).iter().map(|b| format!("{b:02x}")).collect();
    std::fs::write(dir.join("manifest.json"), serde_json::to_string_pretty(&manifest).unwrap()).unwrap();
    let e = check_set(&dir).unwrap_err();
    assert!(e.contains("rti_expected.hex line 3: field t differs"), "{e}");
}

#[test]
fn bad_requests_are_clear_errors() {
    assert!(generate(&Request { tree: None, ..req(Unit::Traverse, "f32", 1) }).unwrap_err().contains("BVH"));
    assert!(generate(&Request { max_levels: 3, ..req(Unit::Traverse, "f32", 1) })
        .unwrap_err()
        .contains("level pipelines"));
    assert!(generate(&Request { leaves: 0, ..req(Unit::Traverse, "f32", 1) }).unwrap_err().contains("--leaves"));
    assert!("bvh".parse::<Unit>().unwrap_err().contains("unknown unit"));
    assert!(generate(&req(Unit::Rti, "f32", 0)).unwrap_err().contains("at least 1"));
    assert!(generate(&Request { level: 3, ..req(Unit::Rti, "f32", 1) }).unwrap_err().contains("level 3"));
    assert!(generate(&Request { level: 0, ..req(Unit::Rti, "f32", 1) }).unwrap_err().contains("level 0"));
    assert!(generate(&Request { slab_variant: "directed".into(), ..req(Unit::Slab, "f32", 1) })
        .unwrap_err()
        .contains("directed"));
    // a directory that is not a vector set is never replaced
    let dir = tmp("user-dir");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("notes.txt"), "mine").unwrap();
    let set = generate(&req(Unit::Op, "fp16", 1)).unwrap();
    assert!(write_set(&set, &dir).unwrap_err().contains("not a vector set"));
    assert_eq!(std::fs::read_to_string(dir.join("notes.txt")).unwrap(), "mine");
    // an unwritable location
    let file = tmp("a-file");
    std::fs::write(&file, "x").unwrap();
    assert!(write_set(&set, &file.join("sub")).is_err());
    // rewriting a set replaces it and leaves no partial directory behind
    let d = tmp("rewrite");
    write_set(&set, &d).unwrap();
    write_set(&set, &d).unwrap();
    // (only this set's own temporary name: other tests write sets concurrently)
    let name = d.file_name().unwrap().to_string_lossy().into_owned();
    let partial = d.parent().unwrap().join(format!(".{name}.partial-{}", std::process::id()));
    assert!(!partial.exists(), "{} left behind", partial.display());
    assert!(check_set(&d).is_ok());
}

#[test]
fn hdl_packages_match_the_manifest() {
    let set = generate(&req(Unit::Slab, "e8m16", 2)).unwrap();
    let sv = vectors::hdl::sv_package(&set.manifest);
    let vhd = vectors::hdl::vhdl_package(&set.manifest);
    assert!(sv.contains("package raypipe_slab_pkg;") && sv.contains("localparam int LATENCY = 7;"));
    assert!(sv.contains("localparam int SLAB_INPUTS_W = 358;")); // 8 + 14 x 25
    assert!(sv.contains("logic [7:0] class_id;") && sv.contains("logic [24:0] t_near;"));
    assert!(vhd.contains("r.class_id := row(357 downto 350);"), "{vhd}");
    assert!(vhd.contains("r.maxz := row(24 downto 0);"));
    // every field appears in both packages with its width
    for f in &set.manifest.files {
        for fld in &f.fields {
            let name = if fld.name == "class" { "class_id" } else { fld.name.as_str() };
            assert!(sv.contains(&format!("logic [{}:0] {name};", fld.width - 1)), "{name}");
            assert!(
                vhd.contains(&format!("r.{name} := row({} downto {});", fld.lsb + fld.width - 1, fld.lsb)),
                "{name}"
            );
        }
    }
    let dir = tmp("pkgs");
    write_set(&set, &dir).unwrap();
    assert_eq!(std::fs::read_to_string(dir.join("raypipe_pkg.sv")).unwrap(), sv);
    assert!(dir.join("raypipe_pkg.vhd").is_file());
}

/// Two levels, four unit-cube leaves along x (ids 0..3 at x = 0, 2, 4, 6), root → (A, B),
/// A → (leaf 0, leaf 1), B → (leaf 2, leaf 3).
fn line_tree() -> TreeInput {
    use datapath::bvh::NodeDesc;
    let cube = |x: f64| ([x, 0.0, 0.0], [x + 1.0, 1.0, 1.0]);
    let leaf =
        |id: u32| NodeDesc { children: None, leaf: id, min: cube(2.0 * id as f64).0, max: cube(2.0 * id as f64).1 };
    let inner = |l: u32, r: u32, lo: f64, hi: f64| NodeDesc {
        children: Some([l, r]),
        leaf: 0,
        min: [lo, 0.0, 0.0],
        max: [hi, 1.0, 1.0],
    };
    let nodes =
        vec![inner(1, 2, 0.0, 7.0), inner(3, 4, 0.0, 3.0), inner(5, 6, 4.0, 7.0), leaf(0), leaf(1), leaf(2), leaf(3)];
    TreeInput { name: "line".into(), nodes, root: 0 }
}

#[test]
fn traverse_rows_match_a_hand_traced_history() {
    // a ray along +x through all four leaves: passes 1..4 emit leaves 0, 1, 2, 3; pass 1 sets
    // level 0 and level 1 to 10, pass 2 turns level 1 to 11 (leaf 1), pass 3 turns level 0 to
    // 11 and restarts level 1 (B: 10, leaf 2), pass 4 turns it to 11 (leaf 3); no 10 is left.
    // Box tests: the root once, then 2 per level per pass = 1 + 4 x 2 x 2.
    let f: datapath::format::Ieee<datapath::format::F32Native> = match "f32".parse().unwrap() {
        datapath::AnyFormat::F32(f) => f,
        _ => unreachable!(),
    };
    let ray = [-1.0, 0.5, 0.5, 1.0, 0.0, 0.0, 0.0, f64::INFINITY];
    let row = vectors::traverse::expected_for(f, "plain", &line_tree(), 8, 4, ray).unwrap();
    assert_eq!(row, [4, 0, 1, 2, 3, 0, 0, 0, 0, 4, 17, 0b11, 0b11]);
    // N = 2 stops after leaf 1 with level 0 still 10 (the far subtree unexplored)
    let row = vectors::traverse::expected_for(f, "plain", &line_tree(), 2, 4, ray).unwrap();
    assert_eq!(row, [2, 0, 1, 2, 9, 0b10, 0b11]);
    // the opposite direction visits them in reverse
    let back = [8.0, 0.5, 0.5, -1.0, 0.0, 0.0, 0.0, f64::INFINITY];
    let row = vectors::traverse::expected_for(f, "plain", &line_tree(), 8, 4, back).unwrap();
    assert_eq!(&row[..5], [4, 3, 2, 1, 0]);
    // a ray that misses the root: one box test, no pass
    let miss = [-1.0, 5.0, 0.5, 1.0, 0.0, 0.0, 0.0, f64::INFINITY];
    let row = vectors::traverse::expected_for(f, "plain", &line_tree(), 8, 4, miss).unwrap();
    assert_eq!(row, [0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0]);
    // one level pipeline cannot hold this tree
    assert!(vectors::traverse::expected_for(f, "plain", &line_tree(), 8, 1, ray).unwrap_err().contains("2 levels"));
}

#[test]
fn traverse_sets_cover_every_class_and_catch_bad_images() {
    let set = generate(&req(Unit::Traverse, "f32", 3)).unwrap();
    assert!(set.manifest.classes.iter().all(|c| c.count == 3), "{:?}", set.manifest.classes);
    let levels = set.manifest.params["levels"] as usize;
    // the root image, then a left and a right bank per level
    let names: Vec<_> = set.manifest.files.iter().map(|f| f.name.as_str()).collect();
    assert_eq!(names.len(), 3 + 2 * levels);
    assert!(names.contains(&"tree_root.hex") && names.contains(&format!("tree_l{}_right.hex", levels - 1).as_str()));
    let dir = tmp("trav-bad");
    write_set(&set, &dir).unwrap();
    assert_eq!(check_set(&dir).unwrap(), 27);
    // an address word of level 0 pointing past level 1's rows is a clear error, not a panic
    let rewrite = |file: &str, f: &dyn Fn(&str) -> String| {
        let path = dir.join(file);
        let text = std::fs::read_to_string(&path).unwrap();
        let new: String =
            text.lines().enumerate().map(|(i, l)| if i == 0 { f(l) } else { l.to_string() } + "\n").collect();
        std::fs::write(&path, &new).unwrap();
        let mut m: vectors::manifest::Manifest =
            serde_json::from_str(&std::fs::read_to_string(dir.join("manifest.json")).unwrap()).unwrap();
        use sha2::Digest;
        let e = m.files.iter_mut().find(|x| x.name == file).unwrap();
        e.sha256 = sha2::Sha256::digest(new.as_bytes()).iter().map(|b| format!("{b:02x}")).collect();
        std::fs::write(dir.join("manifest.json"), serde_json::to_string_pretty(&m).unwrap()).unwrap();
    };
    rewrite("tree_l0_left.hex", &|l| format!("{}7fffffff", &l[..l.len() - 8]));
    let e = check_set(&dir).unwrap_err();
    assert!(e.contains("malformed tree images") && e.contains("level 0"), "{e}");
    write_set(&set, &dir).unwrap();
    // a flipped history bit in the expected rows names the field
    rewrite("traverse_expected.hex", &|l| {
        let last = u8::from_str_radix(&l[l.len() - 1..], 16).unwrap() ^ 1;
        format!("{}{last:x}", &l[..l.len() - 1])
    });
    let e = check_set(&dir).unwrap_err();
    assert!(e.contains(&format!("field hist_{} differs", levels - 1)), "{e}");
}

#[test]
fn one_and_two_threads_write_the_same_bytes() {
    for unit in [Unit::Rti, Unit::Slab, Unit::Op, Unit::Traverse, Unit::Capture] {
        for level in [1, 2] {
            let one = generate(&Request { level, threads: 1, ..req(unit, "f32", 5) }).unwrap();
            let two = generate(&Request { level, threads: 2, ..req(unit, "f32", 5) }).unwrap();
            assert_eq!(one.files, two.files, "{unit:?} level {level}");
            assert_eq!(one.manifest.classes, two.manifest.classes);
        }
    }
}

#[test]
fn level_2_crosses_the_classes() {
    // rti: the 17 level-1 classes, then 11 placements x 5 modifiers, every one filled in a float format
    let set = generate(&Request { level: 2, ..req(Unit::Rti, "fp16", 2) }).unwrap();
    let c = &set.manifest.classes;
    assert_eq!(c.len(), 17 + 11 * 5);
    assert!(c.iter().all(|c| c.count == 2), "{c:?}");
    assert!(c.iter().any(|c| c.name == "edge+subnormal") && c.iter().any(|c| c.name == "needle+huge"));
    // level 1's classes keep their ids and names
    let l1 = generate(&req(Unit::Rti, "fp16", 2)).unwrap();
    assert_eq!(
        l1.manifest.classes.iter().map(|c| &c.name).collect::<Vec<_>>(),
        c[..17].iter().map(|c| &c.name).collect::<Vec<_>>()
    );
    // in fixed point the crossings with subnormal and inf/NaN do not apply
    let fx = generate(&Request { level: 2, ..req(Unit::Rti, "q8.24:divide", 2) }).unwrap();
    let empty: Vec<_> = fx.manifest.classes.iter().filter(|c| c.count == 0).map(|c| c.name.clone()).collect();
    // level 1: subnormal, inf_nan, tiny_products, t_subnormal; level 2: every placement with
    // subnormal or inf_nan (11 x 2), tiny_products and t_subnormal with the other 3 modifiers
    assert_eq!(empty.len(), 4 + 11 * 2 + 2 * 3, "{empty:?}");
    assert!(empty.iter().all(|n| n.contains("subnormal") || n.contains("inf_nan") || n.contains("tiny_products")));
    // slab and op gain crossed classes; the set still checks bit for bit
    let slab = generate(&Request { level: 2, ..req(Unit::Slab, "f32", 3) }).unwrap();
    assert_eq!(slab.manifest.classes.len(), 13 + 7);
    assert!(slab.manifest.classes.iter().all(|c| c.count == 3), "{:?}", slab.manifest.classes);
    // fixed point: the float-only slab classes are empty
    let fxs = generate(&req(Unit::Slab, "q8.24", 3)).unwrap();
    let empty: Vec<_> = fxs.manifest.classes.iter().filter(|c| c.count == 0).map(|c| c.name.as_str()).collect();
    assert_eq!(empty, ["inf_nan", "ties", "subnormal_gap"]);
    let op = generate(&Request { level: 2, ..req(Unit::Op, "fp16", 8) }).unwrap();
    assert!(op.manifest.classes[2].name == "ties" && op.manifest.classes[2].count > 0);
    assert!(op.manifest.classes[3].name == "special_x_random" && op.manifest.classes[3].count > 0);
    let trav = generate(&Request { level: 2, ..req(Unit::Traverse, "f32", 2) }).unwrap();
    assert_eq!(trav.manifest.classes.len(), 9 + 5 * 4 - 1);
    assert!(trav.manifest.classes.iter().any(|c| c.name == "axis+tie" && c.count == 2), "{:?}", trav.manifest.classes);
    for (i, set) in [slab, op, trav].iter().enumerate() {
        let dir = tmp(&format!("level2-{i}"));
        write_set(set, &dir).unwrap();
        assert!(check_set(&dir).is_ok());
    }
}

/// `--check` checks the whole set: a changed manifest parameter, a stale HDL package, a cut
/// files list or another unit is named, never a panic and never a pass.
#[test]
fn check_names_the_first_difference_in_any_file() {
    use serde_json::Value;
    type Edit = fn(&mut Value);
    let json_cases: [(&str, Unit, Edit, &str); 9] = [
        ("latency", Unit::Slab, |m| m["latency"] = 3.into(), "field latency"),
        ("width", Unit::Rti, |m| m["files"][1]["fields"][2]["width"] = 17.into(), "files[1].fields[2]"),
        ("exp", Unit::Op, |m| m["params"]["exp"] = 6.into(), "params.exp"),
        ("max_levels", Unit::Traverse, |m| m["params"]["max_levels"] = 99.into(), "MAX_LEVELS"),
        ("empty files", Unit::Rti, |m| m["files"] = Value::Array(vec![]), "field files lists"),
        (
            "cut files",
            Unit::Slab,
            |m| {
                m["files"].as_array_mut().unwrap().truncate(1);
            },
            "field files lists",
        ),
        ("unit", Unit::Slab, |m| m["unit"] = "rti".into(), "field unit"),
        ("contract", Unit::Rti, |m| m["contract"]["rounding"] = "toward zero".into(), "contract.rounding"),
        ("class", Unit::Slab, |m| m["classes"][2]["count"] = 5.into(), "class 2"),
    ];
    for (what, unit, edit, want) in json_cases {
        let set = generate(&req(unit, "fp16", 4)).unwrap();
        let dir = tmp(&format!("check-{}", what.replace(' ', "_")));
        write_set(&set, &dir).unwrap();
        assert!(check_set(&dir).is_ok(), "{what}: the unchanged set must pass");
        let p = dir.join("manifest.json");
        let mut m: Value = serde_json::from_str(&std::fs::read_to_string(&p).unwrap()).unwrap();
        edit(&mut m);
        std::fs::write(&p, serde_json::to_string_pretty(&m).unwrap()).unwrap();
        let e = check_set(&dir).expect_err(what);
        assert!(e.contains(want), "{what}: {e}");
    }
    // the generated packages are compared too
    for (file, from, to, want) in [
        ("raypipe_pkg.sv", "localparam int LATENCY = 7;", "localparam int LATENCY = 3;", "raypipe_pkg.sv line"),
        (
            "raypipe_pkg.vhd",
            "constant LATENCY : natural := 7;",
            "constant LATENCY : natural := 3;",
            "raypipe_pkg.vhd line",
        ),
    ] {
        let set = generate(&req(Unit::Slab, "f32", 3)).unwrap();
        let dir = tmp(&format!("check-{file}"));
        write_set(&set, &dir).unwrap();
        let p = dir.join(file);
        let text = std::fs::read_to_string(&p).unwrap();
        assert!(text.contains(from), "{file}");
        std::fs::write(&p, text.replacen(from, to, 1)).unwrap();
        let e = check_set(&dir).unwrap_err();
        assert!(e.contains(want), "{file}: {e}");
    }
    // an input row changed by hand (a valid row, hash updated) is not what the seed draws
    let set = generate(&req(Unit::Op, "fp16", 3)).unwrap();
    let dir = tmp("check-input");
    write_set(&set, &dir).unwrap();
    let p = dir.join("manifest.json");
    let mut m: Value = serde_json::from_str(&std::fs::read_to_string(&p).unwrap()).unwrap();
    m["seed"] = 12345.into();
    std::fs::write(&p, serde_json::to_string_pretty(&m).unwrap()).unwrap();
    assert!(check_set(&dir).unwrap_err().contains("seed 12345"));
    // not JSON, or a manifest without a field
    std::fs::write(&p, "{\"schema\": 2}").unwrap();
    assert!(check_set(&dir).unwrap_err().contains("manifest.json"));
}

/// The capture unit on a hand-traced leaf: hits at t = 2 (id 5), 1 (id 6), a nearer miss at
/// 0.5 (id 7) and a tie at 1 (id 8): the tie rule `first` keeps id 6, `last` takes id 8; the
/// miss is never taken.
#[test]
fn the_capture_unit_follows_its_tie_rule_on_a_hand_traced_leaf() {
    use datapath::fault::NoFault;
    use datapath::rti::{Rti, TieRule};
    let f = datapath::format::Ieee::new(datapath::format::F32Native, datapath::format::FpOpts::default());
    let b = |x: f32| x.to_bits() as u64;
    let row = [
        [1, b(2.0), b(0.1), b(0.2), 5],
        [1, b(1.0), b(0.3), b(0.4), 6],
        [0, b(0.5), b(0.5), b(0.5), 7],
        [1, b(1.0), b(0.6), b(0.7), 8],
    ]
    .concat();
    for (tie, id, u, v, takes) in
        [(TieRule::First, 6, 0.3, 0.4, [1, 1, 0, 0]), (TieRule::Last, 8, 0.6, 0.7, [1, 1, 0, 1])]
    {
        let rti = Rti::new(f, RtiConfig { tie, ..RtiConfig::default() });
        let [out, stages] = vectors::capture::out_rows(&rti, &row, &NoFault);
        assert_eq!(out, vec![1, b(1.0), b(u), b(v), id], "{tie:?}");
        assert_eq!(stages.len(), 4 * 6);
        assert_eq!([stages[0], stages[6], stages[12], stages[18]], takes.map(|x: u64| x), "{tie:?}");
        // after slot 0 the state holds t = 2, id 5; after slot 2 (the miss) still slot 1's
        assert_eq!(&stages[1..6], &[1, b(2.0), b(0.1), b(0.2), 5]);
        assert_eq!(&stages[13..18], &[1, b(1.0), b(0.3), b(0.4), 6]);
    }
}

/// The slab unit's input read: a NaN ray input of any sign and payload gives the rows of the
/// canonical NaN, under `propagate` the rows of the same NaN quieted (payload kept, never the
/// canonical NaN's), and under FTZ a subnormal ray input the rows of zero of its sign (the
/// reference DUTs' `conv`); the stored box is not converted.
#[test]
fn the_slab_input_read_canonicalizes_or_quiets_nans_and_flushes_ftz_subnormals() {
    use datapath::fault::NoFault;
    use datapath::slab::{Slab, SlabConfig};
    let rows = |fmt: &str, bits: &[u64]| {
        let any: datapath::AnyFormat = fmt.parse().unwrap();
        datapath::with_format!(any, |f| {
            let s = Slab::new(f, SlabConfig::named("plain").unwrap());
            vectors::gen::slab_out_rows(&s, bits, &NoFault)
        })
    };
    let b = |x: f32| x.to_bits() as u64;
    let base = [
        b(0.5),
        b(0.1),
        b(-0.2),
        b(1.0),
        b(0.25),
        b(0.5),
        b(0.0),
        b(f32::INFINITY),
        b(-1.0),
        b(-1.0),
        b(-1.0),
        b(1.0),
        b(1.0),
        b(1.0),
    ];
    let mut canon = base;
    canon[1] = 0x7fc0_0000;
    for payload in [0xffc0_1234u64, 0x7f80_0001, 0xff80_0042] {
        let mut p = base;
        p[1] = payload;
        assert_eq!(rows("f32", &p), rows("f32", &canon), "f32 {payload:#x}");
        let mut quiet = base;
        quiet[1] = payload | 0x0040_0000;
        assert_eq!(rows("f32:propagate", &p), rows("f32:propagate", &quiet), "f32:propagate {payload:#x}");
        assert_ne!(rows("f32:propagate", &p), rows("f32:propagate", &canon), "f32:propagate {payload:#x}");
    }
    let mut sub = base;
    sub[3] = 0x8000_0003; // -3 least steps
    let mut zero = base;
    zero[3] = 0x8000_0000;
    assert_eq!(rows("f32:ftz", &sub), rows("f32:ftz", &zero));
    assert_ne!(rows("f32", &sub), rows("f32", &zero));
}

/// A set of given rows (a proof's counterexample): written with its origin, accepted by
/// `check_set`, which rebuilds it from its own rows; a wrong expected bit is caught; only the
/// slab unit takes given rows.
#[test]
fn given_rows_make_a_checked_one_class_set() {
    // fp16: a ray along +x from the origin into the box [1, 2] x [-1, 1] x [-1, 1]; t in [0, inf]
    let one = 0x3c00u64;
    let row = vec![0, 0, 0, one, 0, 0, 0, 0x7c00, one, 0xbc00, 0xbc00, 0x4000, one, one];
    let ex = vectors::gen::Explicit {
        class: "smt".into(),
        covers: "a given row".into(),
        origin: "test".into(),
        rows: vec![row.clone(), row],
    };
    let set = generate(&Request { explicit: Some(ex.clone()), ..req(Unit::Slab, "fp16", 1) }).unwrap();
    assert_eq!(set.manifest.origin.as_deref(), Some("test"));
    assert_eq!(set.manifest.classes.len(), 1);
    assert_eq!((set.manifest.classes[0].name.as_str(), set.manifest.classes[0].count), ("smt", 2));
    let expected = &set.files.iter().find(|(n, _)| n == "slab_expected.hex").unwrap().1;
    // hit = 1, t_near = 1.0 and t_far = 2.0 widened by the conservative variant's 4 steps:
    // 0x3c00 - 4 and 0x4000 + 4
    assert_eq!(expected.lines().next().unwrap(), "13bfc4004");
    let dir = tmp("given");
    write_set(&set, &dir).unwrap();
    assert_eq!(check_set(&dir).unwrap(), 2);
    // the expected hit bit cleared, the hash made to match: the model comparison catches it
    let path = dir.join("slab_expected.hex");
    let text = std::fs::read_to_string(&path).unwrap().replacen("13bfc4004", "03bfc4004", 1);
    std::fs::write(&path, &text).unwrap();
    let mut m: vectors::manifest::Manifest =
        serde_json::from_str(&std::fs::read_to_string(dir.join("manifest.json")).unwrap()).unwrap();
    m.files[1].sha256 = vectors::write::sha256_hex(text.as_bytes());
    std::fs::write(dir.join("manifest.json"), serde_json::to_string_pretty(&m).unwrap()).unwrap();
    assert!(check_set(&dir).is_err());
    assert!(generate(&Request { explicit: Some(ex), ..req(Unit::Rti, "fp16", 1) }).unwrap_err().contains("slab"));
}
