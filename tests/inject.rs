//! `verify --inject`: the RTI model run with a fault of the bank (a model wrong on purpose)
//! must fail `verify`, with its violations counted and the first one named with an `explain`
//! command that reproduces it; the reference side of the run does not change.

mod common;
use common::raypipe;

use common::{untimed, untimed_value};
use raypipe::scene::Scene;
use raypipe::verify::{verify, VerifyConfig};

fn cfg(inject: Option<&str>) -> VerifyConfig {
    let mut c =
        VerifyConfig::new(vec!["f32".parse().unwrap(), "fp16".parse().unwrap()], 48, 3, Default::default(), 512);
    c.inject = inject.map(|n| faults::bank::by_name(n).unwrap());
    c
}

#[test]
fn an_injected_fault_fails_verify_and_names_itself() {
    let scene = Scene::builtin();
    let clean = verify(&cfg(None), &scene);
    assert!(clean.passed && clean.injected.is_none());
    assert!(clean.formats.iter().all(|f| f.violations == 0 && f.decisive > 0));
    // both kinds of violation come first somewhere: a wrong hit/miss, a t beyond its bound
    let mut kinds = [false; 2];
    for name in ["rti.e1x.swap", "rti.uv.first", "rti.sy.swap"] {
        let c = cfg(Some(name));
        let r = verify(&c, &scene);
        assert!(!r.passed, "{name}");
        assert_eq!(r.outcome(), raypipe::Outcome::Fail, "{name}");
        assert_eq!(r.injected.as_deref(), Some(name));
        for (f, g) in r.formats.iter().zip(&clean.formats) {
            assert!(f.violations > 0 && f.false_hits + f.false_misses > 0, "{name} {}", f.format);
            let first = f.first_violation.as_deref().unwrap();
            let kind = if first.starts_with("hit/miss: model ") { 0 } else { 1 };
            assert!(kind == 0 || first.starts_with("t error "), "{first}");
            kinds[kind] = true;
            assert!(first.contains(&format!("--inject {name}")), "{first}");
            // the reference side does not depend on the model
            assert_eq!((f.tests, f.decisive, f.golden_hits, f.exact), (g.tests, g.decisive, g.golden_hits, g.exact));
            assert_ne!(f.model_hits + f.false_hits, g.model_hits + g.false_hits, "{name} {}", f.format);
        }
        // one thread or two, the same report
        let mut one = c.clone();
        one.engine = engine::Engine { threads: 1, chunk: 5, shard: engine::Shard::ALL };
        assert_eq!(untimed(&verify(&one, &scene)), untimed(&r), "{name}");
    }
    assert_eq!(kinds, [true, true]);
}

#[test]
fn the_cli_injects_names_refuses_and_explains() {
    let o = raypipe(&["verify", "--format", "f32", "--rays", "32", "--inject", "rti.e1x.swap", "--quiet"]);
    assert_eq!(o.status.code(), Some(1));
    let text = String::from_utf8(o.stdout).unwrap();
    assert!(text.contains("injected fault: rti.e1x.swap (stage 1: e1.x wired as v0.x − v1.x"), "{text}");
    let j = raypipe(&["verify", "--format", "f32", "--rays", "32", "--inject", "rti.e1x.swap", "--quiet", "--json"]);
    assert_eq!(j.status.code(), Some(1));
    let v: serde_json::Value = serde_json::from_slice(&j.stdout).unwrap();
    assert_eq!(v["injected"], "rti.e1x.swap");
    // the first violation's explain command shows the same disagreement: faulty model, exact hit
    let first = v["formats"][0]["first_violation"].as_str().unwrap();
    let cmd = first.split("raypipe explain ").nth(1).unwrap().split("  #").next().unwrap();
    let mut args: Vec<&str> = vec!["explain"];
    args.extend(cmd.split_whitespace());
    args.push("--json");
    let e = raypipe(&args);
    assert_eq!(e.status.code(), Some(0), "{}", String::from_utf8_lossy(&e.stderr));
    let t: serde_json::Value = serde_json::from_slice(&e.stdout).unwrap();
    assert_eq!(t["injected"], "rti.e1x.swap");
    let model_hit = t["model"].as_array().unwrap().iter().find(|x| x["name"] == "hit").unwrap()["value"].clone();
    assert_ne!(model_hit.as_str().unwrap() == "true", t["bound"]["exact_hit"].as_bool().unwrap(), "{t}");
    assert!(t["bound"]["decisive"].as_bool().unwrap());
    // without the fault the same test agrees
    let clean = raypipe(&args[..args.len() - 3].iter().copied().chain(["--json"]).collect::<Vec<_>>());
    let t: serde_json::Value = serde_json::from_slice(&clean.stdout).unwrap();
    assert!(t.get("injected").is_none());
    let model_hit = t["model"].as_array().unwrap().iter().find(|x| x["name"] == "hit").unwrap()["value"].clone();
    assert_eq!(model_hit.as_str().unwrap() == "true", t["bound"]["exact_hit"].as_bool().unwrap(), "{t}");
    // refusals: exit 2 before any work
    for bad in [
        vec!["verify", "--rays", "8", "--inject", "rti.no.such"],
        vec!["verify", "--rays", "8", "--inject", "slab.lox.swap"],
        vec![
            "explain",
            "--unit",
            "slab",
            "--format",
            "f32",
            "--ray",
            "0,0,0,1,1,1",
            "--box",
            "0,0,0,1,1,1",
            "--inject",
            "rti.e1x.swap",
        ],
    ] {
        let o = raypipe(&bad);
        assert_eq!(o.status.code(), Some(2), "{bad:?}");
        assert!(String::from_utf8_lossy(&o.stderr).contains("--inject"), "{bad:?}");
    }
}

/// Sharded runs of an injected model merge into the unsharded injected run; an injected
/// shard does not merge with a clean one.
#[test]
fn injected_shards_merge_into_the_injected_run() {
    let d = std::env::temp_dir().join(format!("raypipe-inject-shards-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    let run = ["verify", "--rays", "40", "--format", "f32", "--quiet", "--json"];
    let fault = ["--inject", "rti.uv.first"];
    let base: Vec<&str> = run.iter().chain(&fault).copied().collect();
    let part = |k: u32, inject: bool| {
        let p = d.join(format!("p{k}{inject}.json")).display().to_string();
        let shard = format!("{k}/2");
        let mut a: Vec<&str> = if inject { base.clone() } else { run.to_vec() };
        a.extend(["--shard", &shard, "--partial", &p]);
        let o = raypipe(&a);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        p
    };
    let (a, b, clean) = (part(0, true), part(1, true), part(1, false));
    let untimed_json = |o: &std::process::Output| untimed_value(serde_json::from_slice(&o.stdout).unwrap());
    let whole = raypipe(&base);
    let merged = raypipe(&["merge", "--json", &a, &b]);
    assert_eq!(merged.status.code(), Some(1));
    assert_eq!(whole.status.code(), Some(1));
    let m = untimed_json(&merged);
    assert_eq!(m["injected"], "rti.uv.first");
    assert_eq!(m, untimed_json(&whole));
    let mixed = raypipe(&["merge", "--json", &a, &clean]);
    assert_eq!(mixed.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&mixed.stderr).contains("differs"), "{}", String::from_utf8_lossy(&mixed.stderr));
    std::fs::remove_dir_all(&d).unwrap();
}
