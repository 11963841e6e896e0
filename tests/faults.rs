//! `raypipe faults`: the bank against generated and written vector sets, its JSON, exit codes
//! and refusals.

mod common;
use common::raypipe;

use std::path::PathBuf;
use std::process::{Command, Output};

fn json(o: &Output) -> serde_json::Value {
    serde_json::from_slice(&o.stdout).unwrap_or_else(|e| panic!("{e}: {}", String::from_utf8_lossy(&o.stdout)))
}

/// The applicable non-benign faults a campaign's JSON says no vector detects.
fn escaped(v: &serde_json::Value) -> Vec<String> {
    v["faults"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|f| f["applicable"] == true && f["benign"] == false && f["detected"] == false)
        .map(|f| f["name"].as_str().unwrap().to_string())
        .collect()
}

/// `raypipe faults ARGS --outputs-only --json`: exit code and JSON.
fn campaign(args: &[&str]) -> (Option<i32>, serde_json::Value) {
    let mut all = vec!["faults"];
    all.extend_from_slice(args);
    all.extend(["--outputs-only", "--json"]);
    let o = raypipe(&all);
    (o.status.code(), json(&o))
}

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("raypipe-faults-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// Every fault's verdict, without the command that wrote the set.
fn verdicts(v: &serde_json::Value) -> Vec<(String, bool, bool, bool, u64)> {
    v["faults"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| {
            (
                f["name"].as_str().unwrap().to_string(),
                f["detected"].as_bool().unwrap(),
                f["benign"].as_bool().unwrap(),
                f["applicable"].as_bool().unwrap(),
                f["vectors"].as_u64().unwrap(),
            )
        })
        .collect()
}

#[test]
fn the_exit_code_is_the_verdict_and_the_json_names_every_fault() {
    for fmt in ["f32", "fp16"] {
        for probes in [false, true] {
            let mut args = vec!["faults", "--format", fmt, "--count", "16", "--json"];
            if !probes {
                args.push("--outputs-only");
            }
            let o = raypipe(&args);
            let v = json(&o);
            let escaped = v["escaped"].as_u64().unwrap();
            assert_eq!(o.status.code(), Some(if escaped == 0 { 0 } else { 1 }), "{fmt}");
            let faults = v["faults"].as_array().unwrap();
            assert!(faults.len() >= 30);
            let counted: Vec<_> = faults.iter().filter(|f| f["applicable"] == true && f["benign"] == false).collect();
            assert_eq!(counted.iter().filter(|f| f["detected"] == false).count() as u64, escaped);
            // a wired-backwards subtractor cannot escape any set
            let swap = faults.iter().find(|f| f["name"] == "rti.e1x.swap").unwrap();
            assert_eq!(swap["detected"], true);
            let first = swap["first_vector"].as_u64().unwrap();
            assert_eq!(swap["catching"][0].as_u64(), Some(first));
            // the probes see at least what the outputs see
            if probes {
                let o2 = json(&raypipe(&["faults", "--format", fmt, "--count", "16", "--json", "--outputs-only"]));
                assert!(v["detected"].as_u64() >= o2["detected"].as_u64());
            }
        }
    }
}

#[test]
fn a_written_set_gives_the_verdicts_of_the_generated_one() {
    let dir = temp_dir("set");
    let w = raypipe(&[
        "vectors",
        "--unit",
        "rti",
        "--format",
        "fp16",
        "--count",
        "8",
        "--seed",
        "7",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(w.status.success(), "{}", String::from_utf8_lossy(&w.stderr));
    let from_dir = json(&raypipe(&["faults", "--set", dir.to_str().unwrap(), "--json", "--outputs-only"]));
    let generated =
        json(&raypipe(&["faults", "--format", "fp16", "--count", "8", "--seed", "7", "--json", "--outputs-only"]));
    assert_eq!(verdicts(&from_dir), verdicts(&generated));
    assert_eq!(from_dir["set_seed"], 7);
    // a set whose rows were changed is refused, not measured
    let inputs = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.file_name().unwrap().to_str().unwrap().contains("input"))
        .expect("an input file");
    let mut text = std::fs::read_to_string(&inputs).unwrap();
    let last = text.pop().unwrap();
    text.push(if last == '0' { '1' } else { '0' });
    std::fs::write(&inputs, text).unwrap();
    let o = raypipe(&["faults", "--set", dir.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", String::from_utf8_lossy(&o.stdout));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_requests_are_refused_with_exit_2() {
    for args in [
        &["faults", "--unit", "nope"][..],
        &["faults", "--unit", "rti", "--scene", "/nonexistent.obj"],
        &["faults", "--unit", "slab", "--variant", "directed"],
        &["faults", "--unit", "slab", "--variant", "nope"],
        &["faults", "--set", "/nonexistent/raypipe-set"],
        &["faults", "--set", "/tmp", "--format", "f32"],
        &["faults", "--count", "1000000"],
    ] {
        let o = raypipe(args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", String::from_utf8_lossy(&o.stdout));
        assert!(!o.stderr.is_empty(), "{args:?}: a message");
    }
}

/// The guarantee of docs/faults.md: the default level-1 RTI sets detect every applicable
/// non-benign fault of the bank from the outputs alone, in f32 and fp16.
#[test]
fn the_default_rti_sets_detect_the_whole_bank_from_the_outputs() {
    for fmt in ["f32", "fp16"] {
        for seed in ["1", "2", "3"] {
            let (code, v) = campaign(&["--format", fmt, "--seed", seed]);
            let escaped = escaped(&v);
            assert!(escaped.is_empty(), "{fmt} seed {seed}: {escaped:?} escape");
            assert_eq!(code, Some(0));
            assert!(v["detected"].as_u64().unwrap() >= 32);
        }
    }
}

/// The same guarantee for the slab unit, in every variant a vector set supports: the default
/// level-1 slab sets detect every applicable non-benign fault from the outputs (hit, t_near,
/// t_far) alone, in f32 and fp16; and every slab fault applies in some variant.
#[test]
fn the_default_slab_sets_detect_the_whole_bank_from_the_outputs() {
    let mut applies: std::collections::BTreeMap<String, bool> = Default::default();
    for variant in ["plain", "conservative", "take-on-false", "embree"] {
        for fmt in ["f32", "fp16"] {
            for seed in ["1", "2", "3"] {
                let (code, v) = campaign(&["--unit", "slab", "--variant", variant, "--format", fmt, "--seed", seed]);
                let faults = v["faults"].as_array().unwrap();
                let escaped = escaped(&v);
                assert!(escaped.is_empty(), "{variant} {fmt} seed {seed}: {escaped:?} escape");
                assert_eq!(code, Some(0));
                assert!(v["detected"].as_u64().unwrap() >= 20, "{variant} {fmt}");
                for f in faults {
                    assert!(f["name"].as_str().unwrap().starts_with("slab."));
                    *applies.entry(f["name"].as_str().unwrap().to_string()).or_default() |= f["applicable"] == true;
                    // a benign verdict carries its argument
                    assert_eq!(f["benign"] == true, f["benign_why"].is_string(), "{}", f["name"]);
                }
            }
        }
    }
    assert!(applies.len() >= 25);
    let never: Vec<_> = applies.iter().filter(|(_, &a)| !a).map(|(n, _)| n).collect();
    assert!(never.is_empty(), "slab faults no variant reaches: {never:?}");
}

/// The min-capture unit's default sets detect its whole bank from the outputs (hit, t, u, v,
/// id) under either tie rule, in f32 and fp16.
#[test]
fn the_default_capture_sets_detect_the_whole_bank_from_the_outputs() {
    for tie in ["first", "last"] {
        for fmt in ["f32", "fp16"] {
            for seed in ["1", "2"] {
                let (code, v) = campaign(&["--unit", "capture", "--tie", tie, "--format", fmt, "--seed", seed]);
                assert_eq!(code, Some(0), "{tie} {fmt} {seed}");
                assert_eq!(v["escaped"], 0);
                let faults = v["faults"].as_array().unwrap();
                assert!(faults.len() >= 6 && faults.iter().all(|f| f["applicable"] == true && f["detected"] == true));
            }
        }
    }
}

/// The traverse unit's default sets (built-in scene) detect its whole bank from the compared
/// outputs (count, leaves, final history; not the implementation-defined passes and box tests).
#[test]
fn the_default_traverse_sets_detect_the_whole_bank_from_the_outputs() {
    for fmt in ["f32", "fp16"] {
        let (code, v) = campaign(&["--unit", "traverse", "--format", fmt]);
        assert_eq!(code, Some(0), "{fmt}");
        let faults = v["faults"].as_array().unwrap();
        assert!(faults.len() >= 8 && faults.iter().all(|f| f["applicable"] == true && f["detected"] == true), "{fmt}");
    }
}

/// A fault seen only in a field the kit does not compare is not a detection: the RTI t, u, v
/// only count where valid is 1 (care_when), so with outputs only the campaign cannot detect
/// more than with the stage probes, and every catching vector of a t-only fault is valid.
#[test]
fn the_campaign_compares_what_the_testbench_compares() {
    let v = json(&raypipe(&["faults", "--format", "f32", "--count", "16", "--outputs-only", "--json"]));
    let f = v["faults"].as_array().unwrap().iter().find(|f| f["name"] == "rti.t.rz").unwrap().clone();
    let dir = temp_dir("care");
    let w = raypipe(&["vectors", "--unit", "rti", "--format", "f32", "--count", "16", "--out", dir.to_str().unwrap()]);
    assert!(w.status.success());
    let expected = std::fs::read_to_string(dir.join("rti_expected.hex")).unwrap();
    let rows: Vec<&str> = expected.lines().collect();
    // valid is the most significant bit of the expected row (valid, hit, t, u, v)
    for k in f["catching"].as_array().unwrap() {
        let row = rows[k.as_u64().unwrap() as usize];
        let top = u8::from_str_radix(&row[..1], 16).unwrap();
        let width = 2 + 3 * 32;
        let valid_bit = (width - 1) % 4;
        assert_eq!((top >> valid_bit) & 1, 1, "vector {k} catches rti.t.rz with valid = 0");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The op unit's default sets (every pair of special operands per op code plus random ones)
/// detect its whole applicable bank, in the default (reciprocal-multiply, canonical NaN)
/// formats, with a true divider, and with NaN propagation (where the other rounding modes are
/// not modelled and say so).
#[test]
fn the_default_op_sets_detect_the_whole_bank() {
    for fmt in ["f32", "fp16", "f32:divide", "bf16", "fp16:propagate", "f32:ftz", "fp16:ftz"] {
        let o = raypipe(&["faults", "--unit", "op", "--format", fmt, "--json"]);
        let v = json(&o);
        assert_eq!(o.status.code(), Some(0), "{fmt}");
        let faults = v["faults"].as_array().unwrap();
        assert!(faults.len() >= 14);
        assert!(faults.iter().all(|f| f["detected"] == true || f["applicable"] == false), "{fmt}");
        let nan = faults.iter().find(|f| f["name"] == "op.add.nan").unwrap();
        assert_eq!(nan["applicable"], true, "{fmt}: the NaN rule fault applies in every float format");
        let na = faults.iter().filter(|f| f["applicable"] == false).count();
        // propagate: the six rounding faults are not modelled; FTZ: the two flush faults are the
        // datapath itself
        let want = if fmt.ends_with("propagate") {
            6
        } else if fmt.ends_with("ftz") {
            2
        } else {
            0
        };
        assert_eq!(na, want, "{fmt}");
    }
}

/// `vectors --minimal`: a set far smaller than the default one that detects every fault the
/// default set detects; `vectors --check` accepts it, and refuses it once its manifest claims a
/// fault it does not detect.
#[test]
fn a_minimal_set_keeps_the_detections_and_check_holds_it_to_them() {
    for unit in ["rti", "slab", "capture", "op"] {
        let dir = temp_dir(&format!("min-{unit}"));
        let o = raypipe(&[
            "vectors",
            "--unit",
            unit,
            "--format",
            "fp16",
            "--count",
            "16",
            "--minimal",
            "--out",
            dir.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{unit}: {}", String::from_utf8_lossy(&o.stderr));
        let m: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("manifest.json")).unwrap()).unwrap();
        let kept = m["files"][0]["rows"].as_u64().unwrap();
        let from = m["minimal"]["from_vectors"].as_u64().unwrap();
        assert!(kept > 0 && kept * 10 < from, "{unit}: {kept} of {from}");
        // the class counts add up to the rows kept
        assert_eq!(m["classes"].as_array().unwrap().iter().map(|c| c["count"].as_u64().unwrap()).sum::<u64>(), kept);
        // it detects what the full set detects
        let full = json(&raypipe(&[
            "faults",
            "--unit",
            unit,
            "--format",
            "fp16",
            "--count",
            "16",
            "--outputs-only",
            "--json",
        ]));
        let cut = json(&raypipe(&["faults", "--set", dir.to_str().unwrap(), "--outputs-only", "--json"]));
        let detected = |v: &serde_json::Value| -> Vec<String> {
            v["faults"]
                .as_array()
                .unwrap()
                .iter()
                .filter(|f| f["detected"] == true)
                .map(|f| f["name"].as_str().unwrap().to_string())
                .collect()
        };
        assert_eq!(detected(&full), detected(&cut), "{unit}");
        let c = raypipe(&["vectors", "--check", dir.to_str().unwrap()]);
        assert!(c.status.success(), "{unit}: {}", String::from_utf8_lossy(&c.stderr));
        assert!(String::from_utf8_lossy(&c.stdout).contains("a minimal set"));
        // a claim it cannot keep: a benign fault (never detected from the outputs)
        if unit == "rti" {
            let mut m2 = m.clone();
            m2["minimal"]["detects"].as_array_mut().unwrap().push("rti.pos.loose".into());
            std::fs::write(dir.join("manifest.json"), serde_json::to_string_pretty(&m2).unwrap()).unwrap();
            let c = raypipe(&["vectors", "--check", dir.to_str().unwrap()]);
            assert_eq!(c.status.code(), Some(2));
            assert!(
                String::from_utf8_lossy(&c.stderr).contains("rti.pos.loose"),
                "{}",
                String::from_utf8_lossy(&c.stderr)
            );
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

/// NaN inputs are random NaN encodings (sign, quiet or signaling, payload), so a NaN-rule bug
/// in one subtractor shows on its stage probe, in a canonical and a propagating format; on the
/// compared outputs it is benign (the bank's argument), so outputs-only campaigns say benign.
#[test]
fn nan_payload_inputs_expose_the_nan_rule_on_the_probes() {
    for fmt in ["f32", "fp16:propagate"] {
        let v = json(&raypipe(&["faults", "--format", fmt, "--json"]));
        let f = v["faults"].as_array().unwrap().iter().find(|f| f["name"] == "rti.e1x.nan").unwrap().clone();
        assert_eq!(f["detected"], true, "{fmt}");
        assert_eq!(f["benign"], true);
        assert_eq!(f["first_class"], "inf_nan", "{fmt}");
        // the coverage that mattered: the first vector's rarest bins, fewest vectors first, and
        // one of them a NaN on a stage signal (that is what the fault needs)
        let bins: Vec<&str> = f["first_bins"].as_array().unwrap().iter().map(|b| b.as_str().unwrap()).collect();
        assert!(!bins.is_empty() && bins.len() <= 3, "{bins:?}");
        let n = |b: &str| -> u64 { b.rsplit_once(" (").unwrap().1.split(' ').next().unwrap().parse().unwrap() };
        assert!(bins.windows(2).all(|w| n(w[0]) <= n(w[1])), "{bins:?}");
        let all: Vec<String> = v["faults"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|g| g["detected"] == true)
            .flat_map(|g| g["first_bins"].as_array().unwrap().iter().map(|b| b.as_str().unwrap().to_string()))
            .collect();
        assert!(all.iter().any(|b| b.contains("NaN")), "{fmt}: {all:?}");
        let (_, o) = campaign(&["--format", fmt]);
        let f = o["faults"].as_array().unwrap().iter().find(|f| f["name"] == "rti.e1x.nan").unwrap().clone();
        assert_eq!(f["detected"], false, "{fmt}: benign on the compared outputs");
    }
}

/// A reader that closes the pipe early (`raypipe … | head`) ends raypipe quietly: no panic
/// message, killed by SIGPIPE as any Unix tool is.
#[cfg(unix)]
#[test]
fn a_closed_stdout_pipe_is_not_a_panic() {
    use std::io::Read;
    use std::os::unix::process::ExitStatusExt;
    use std::process::Stdio;
    let mut child = Command::new(env!("CARGO_BIN_EXE_raypipe"))
        .current_dir(std::env::temp_dir())
        .args(["faults", "--unit", "op", "--json"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run raypipe");
    let mut first = [0u8; 16];
    child.stdout.take().unwrap().read_exact(&mut first).unwrap(); // then the pipe closes
    let mut err = String::new();
    child.stderr.take().unwrap().read_to_string(&mut err).unwrap();
    let status = child.wait().unwrap();
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(status.signal(), Some(libc_sigpipe()), "{status:?}");
}

#[cfg(unix)]
fn libc_sigpipe() -> i32 {
    13 // SIGPIPE on Linux and the BSDs
}

/// Under FTZ the default RTI sets detect the whole applicable bank from the outputs too; the
/// flush faults are the FTZ datapath itself and say so.
#[test]
fn ftz_rti_sets_detect_the_applicable_bank() {
    for fmt in ["f32:ftz", "fp16:ftz"] {
        let (code, v) = campaign(&["--format", fmt]);
        assert_eq!(code, Some(0), "{fmt}: {:?}", escaped(&v));
        let na: Vec<_> = v["faults"].as_array().unwrap().iter().filter(|f| f["applicable"] == false).collect();
        assert_eq!(na.len(), 2, "{fmt}");
        assert!(na.iter().all(|f| f["not_applicable"].as_str().unwrap().contains("the fault is the datapath")));
    }
}
