//! The first scenes a user tries and the runs that prove nothing: a flat scene (one triangle,
//! one quad, a floor) gives ordinary decisive tests; a traversal over a BVH of one leaf, a
//! stats run whose BVHs are all one leaf and a conservative render that hits nothing say so
//! and exit 3.

mod common;
use common::raypipe;

use std::path::PathBuf;
use std::process::Command;

/// A file in a fresh temporary directory.
fn scene(name: &str, obj: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("raypipe-seams-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, obj).unwrap();
    p
}

const ONE_TRIANGLE: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
const ONE_QUAD: &str = "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3 4\n";
/// A 4 x 4 grid floor in y = 2 (flat along y, off the origin).
fn floor() -> String {
    let mut s = String::new();
    for j in 0..5 {
        for i in 0..5 {
            s += &format!("v {} 2 {}\n", i as f64 - 2.0, j as f64 * 0.5);
        }
    }
    for j in 0..4 {
        for i in 0..4 {
            let a = j * 5 + i + 1;
            s += &format!("f {} {} {} {}\n", a, a + 1, a + 6, a + 5);
        }
    }
    s
}

/// `verify` on a flat scene: every format's tests are mostly decisive and the run passes
/// (exit 0). Before origins were drawn from padded bounds every aimed ray lay in the plane:
/// decisive 0, exit 3.
#[test]
fn flat_scenes_give_decisive_tests() {
    for (name, obj) in
        [("one.obj", ONE_TRIANGLE.to_string()), ("quad.obj", ONE_QUAD.to_string()), ("floor.obj", floor())]
    {
        let p = scene(name, &obj);
        let o = raypipe(&["verify", "--scene", p.to_str().unwrap(), "--rays", "200", "--quiet", "--json"]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(0), "{name}: {err}");
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        for f in v["formats"].as_array().unwrap() {
            let (tests, decisive) = (f["tests"].as_u64().unwrap(), f["decisive"].as_u64().unwrap());
            assert!(tests > 0 && decisive * 4 > tests * 3, "{name} {}: {decisive} of {tests} decisive", f["format"]);
            assert!(f["golden_hits"].as_u64().unwrap() > 0, "{name} {}: no hit", f["format"]);
        }
        assert!(v["inconclusive"].as_array().unwrap().is_empty());
    }
}

/// The origin box widens only the flat axis, and the same seed gives the same rays.
#[test]
fn origins_of_a_flat_scene_leave_its_plane_deterministically() {
    let p = scene("one-det.obj", ONE_TRIANGLE);
    let run = || {
        let o = raypipe(&[
            "verify",
            "--scene",
            p.to_str().unwrap(),
            "--rays",
            "64",
            "--format",
            "f32",
            "--quiet",
            "--json",
        ]);
        let mut v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        for key in ["formats", "slab"] {
            for r in v[key].as_array_mut().unwrap() {
                let r = r.as_object_mut().unwrap();
                r.remove("mtests_per_s");
                r.remove("judged_mtests_per_s");
            }
        }
        v
    };
    assert_eq!(run(), run());
    let (lo, hi) = raypipe::scene::origin_bounds(([0.0, 0.0, 0.0], [1.0, 1.0, 0.0]));
    assert_eq!((lo, hi), ([0.0, 0.0, -0.25], [1.0, 1.0, 0.25]));
    // a box that is not flat is kept exactly; a point becomes a unit box around it
    assert_eq!(raypipe::scene::origin_bounds(([0.0; 3], [1.0, 2.0, 0.5])), ([0.0; 3], [1.0, 2.0, 0.5]));
    assert_eq!(raypipe::scene::origin_bounds(([3.0; 3], [3.0; 3])), ([2.5; 3], [3.5; 3]));
}

/// `traverse` over a BVH of one leaf compares nothing: exit 3 with the reason, in text and
/// JSON; `stats` whose BVHs are all one leaf measures no traversal: exit 3. A scene of two
/// triangles in two leaves passes (exit 0).
#[test]
fn a_traversal_that_exercised_nothing_is_inconclusive() {
    for obj in [ONE_TRIANGLE, "v 0 0 0\nv 0 0 0\nv 0 0 0\nf 1 2 3\n"] {
        let p = scene("leaf.obj", obj);
        let o = raypipe(&["traverse", "--scene", p.to_str().unwrap(), "--quiet"]);
        let out = String::from_utf8_lossy(&o.stdout);
        assert_eq!(o.status.code(), Some(3), "{out}{}", String::from_utf8_lossy(&o.stderr));
        assert!(out.contains("equivalence: INCONCLUSIVE: the BVH is one leaf"), "{out}");
        assert!(!out.contains("PASS"), "{out}");
        let o = raypipe(&["traverse", "--scene", p.to_str().unwrap(), "--quiet", "--json"]);
        assert_eq!(o.status.code(), Some(3));
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        assert!(v["inconclusive"].as_str().unwrap().contains("0 inner levels"), "{v}");
        let o = raypipe(&["stats", "--scene", p.to_str().unwrap(), "--rays", "64", "--quiet"]);
        assert_eq!(o.status.code(), Some(3), "{}", String::from_utf8_lossy(&o.stdout));
        assert!(String::from_utf8_lossy(&o.stdout).contains("INCONCLUSIVE: the BVH is one leaf"));
    }
    let p = scene("two.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 5 0 0\nv 6 0 0\nv 5 1 0\nf 1 2 3\nf 4 5 6\n");
    let o = raypipe(&["traverse", "--scene", p.to_str().unwrap(), "--leaf-size", "1", "--quiet", "--json"]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(v["depth"].as_u64().unwrap() >= 1 && v["inconclusive"].is_null(), "{v}");
}

/// A conservative render whose camera sees nothing judged no culling: exit 3.
#[test]
fn a_render_that_hits_nothing_is_inconclusive() {
    let p = scene("render.obj", ONE_TRIANGLE);
    let out = std::env::temp_dir().join(format!("raypipe-seams-{}-render", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let args = |look: &str| {
        let mut a = vec!["render", "--scene", p.to_str().unwrap(), "--variant", "conservative", "--width", "16"];
        a.extend(["--height", "16", "--eye", "0.2,0.2,5", "--look-at", look, "--out", out.to_str().unwrap()]);
        a.iter().map(|s| s.to_string()).collect::<Vec<_>>()
    };
    let run = |a: Vec<String>| {
        let _ = std::fs::remove_dir_all(&out);
        Command::new(env!("CARGO_BIN_EXE_raypipe")).args(a).output().unwrap()
    };
    let o = run(args("0.2,0.2,0"));
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let o = run(args("0.2,0.2,10"));
    assert_eq!(o.status.code(), Some(3), "{}", String::from_utf8_lossy(&o.stdout));
    assert!(String::from_utf8_lossy(&o.stdout).contains("culling check: INCONCLUSIVE"));
    let _ = std::fs::remove_dir_all(&out);
}

/// `explain` reports the reference decision `verify` judges by and names what decided it. On
/// these vertex- and edge-aimed threshold cases the f64 evaluation of the error bound says
/// miss, exact rational arithmetic on the quantised inputs says hit: `explain` must say hit,
/// decided by exact arithmetic (it used to print the f64 evaluation as the "exact hit").
#[test]
fn explain_reports_the_exact_decision_where_f64_is_wrong() {
    use datapath::Format as _;
    let cases = [
        (
            "f32",
            "0.9618558883666992,0.1701918989419937,-0.7856403589248657,-0.39487239718437195,0.1563703864812851,0.924180805683136",
            "0.5047459602355957,0.26268208026885986,0.9887862801551819,0.6292210221290588,0.39044249057769775,-0.7117053866386414,-0.6500075459480286,0.3023029565811157,-0.26717060804367065",
        ),
        (
            "q8.24:divide",
            "0.5783219337463379,0.17947542667388916,-0.5704593658447266,-0.11114555597305298,-0.16622716188430786,-0.049610137939453125",
            "0.36472541093826294,0.501389741897583,-0.46935516595840454,0.5696273446083069,-0.4748932123184204,-0.7707838416099548,0.2916174530982971,0.9670970439910889,-0.5619288682937622",
        ),
    ];
    for (fmt, ray, tri) in cases {
        let nums = |s: &str| s.split(',').map(|x| x.parse::<f64>().unwrap()).collect::<Vec<_>>();
        let (r, t) = (nums(ray), nums(tri));
        let ray64 = golden::Ray64 { o: [r[0], r[1], r[2]], d: [r[3], r[4], r[5]], tmin: 0.0, tmax: f64::INFINITY };
        let tri64 = golden::Tri64 { v: [[t[0], t[1], t[2]], [t[3], t[4], t[5]], [t[6], t[7], t[8]]] };
        // the case is what it claims: exact rationals hit, the f64 evaluation of the bound misses
        let any: datapath::AnyFormat = fmt.parse().unwrap();
        let (exact, f64_hit) = datapath::with_format!(any, |f| {
            let rti = datapath::rti::Rti::new(f, datapath::rti::RtiConfig::default());
            let (rq, tq) = raypipe::judge::quantise(&rti, &ray64, &tri64);
            let b = datapath::bound::RtiBound::new(f.error_model(), f.div_mode(), rq.o, rq.d, tq.v);
            let v = b.verdict(rti.cull, f.to_f64(rti.det_thr), rq.tmin, rq.tmax);
            assert!(!v.decisive);
            (golden::intersect_exact(&rq, &tq, raypipe::judge::faces(&rti)), v.hit)
        });
        assert_eq!((exact, f64_hit), (Some(true), false), "{fmt}");
        let o = raypipe(&["explain", "--format", fmt, "--ray", ray, "--tri", tri, "--json"]);
        assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        assert_eq!(v["bound"]["exact_hit"], true, "{fmt}: {}", v["bound"]);
        assert_eq!(v["bound"]["decided_by"], "exact", "{fmt}: {}", v["bound"]);
        let o = raypipe(&["explain", "--format", fmt, "--ray", ray, "--tri", tri]);
        let text = String::from_utf8_lossy(&o.stdout);
        assert!(text.contains("(exact hit true, decided by exact rational arithmetic)"), "{text}");
    }
}
