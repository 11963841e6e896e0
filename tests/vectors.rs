//! Vector sets: written deterministically and atomically, read back bit for bit against the
//! models, and a set with one flipped bit is caught.

use datapath::rti::RtiConfig;
use std::path::PathBuf;
use vectors::gen::{check_set, generate, write_set, Request, Unit};

fn req(unit: Unit, format: &str, count: usize) -> Request {
    Request {
        unit,
        format: format.parse().unwrap(),
        count,
        seed: 7,
        level: 1,
        command: "test".into(),
        rti: RtiConfig::default(),
        slab_variant: "conservative".into(),
    }
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("raypipe-vec-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

#[test]
fn every_unit_and_format_round_trips() {
    for unit in [Unit::Rti, Unit::Slab, Unit::Op] {
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
    for unit in [Unit::Rti, Unit::Slab, Unit::Op] {
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
    assert_eq!(names, ["subnormal", "inf_nan"], "fixed point has no subnormals or inf/NaN");
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
    assert!("traverse".parse::<Unit>().unwrap_err().contains("no vector writer yet"));
    assert!("bvh".parse::<Unit>().unwrap_err().contains("unknown unit"));
    assert!(generate(&req(Unit::Rti, "f32", 0)).unwrap_err().contains("at least 1"));
    assert!(generate(&Request { level: 2, ..req(Unit::Rti, "f32", 1) }).unwrap_err().contains("level 2"));
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
