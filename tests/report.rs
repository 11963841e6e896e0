//! `raypipe report`: every variant gets a point, the Pareto front is exactly the undominated
//! points per unit, and the files are written.

use raypipe::scene::Scene;
use raypipe::time_vs_error::{report, write, ReportConfig};

#[test]
fn points_pareto_front_and_files() {
    let cfg = ReportConfig {
        formats: ["f32", "bf16"].iter().map(|f| f.parse().unwrap()).collect(),
        variants: vec!["plain".into(), "directed".into()],
        rays: 8,
        stress_count: 4,
        seed: 2,
        engine: engine::Engine::new(16),
    };
    let r = report(&cfg, &[Scene::builtin()]).unwrap();
    assert_eq!(r.points.len(), 2 + 2 * 2);
    for p in &r.points {
        assert!(p.tests > 0 && p.ns_per_test > 0.0, "{p:?}");
        let rate = (p.false_misses + p.false_hits) as f64 / p.tests as f64;
        assert_eq!(p.error_rate, rate);
        let dominated = r.points.iter().any(|q| {
            q.unit == p.unit
                && q.ns_per_test <= p.ns_per_test
                && q.error_rate <= p.error_rate
                && (q.ns_per_test < p.ns_per_test || q.error_rate < p.error_rate)
        });
        assert_eq!(p.pareto, !dominated, "{p:?}");
    }
    for unit in ["rti", "slab"] {
        assert!(r.points.iter().any(|p| p.unit == unit && p.pareto), "every unit has a front");
    }
    // the directed slab never misses, so all its error is false hits
    assert!(r.points.iter().filter(|p| p.variant.ends_with("directed")).all(|p| p.false_misses == 0));
    let dir = std::env::temp_dir().join(format!("raypipe-report-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let files = write(&r, &vectors::outdir::OutDir::check(&dir, &raypipe::time_vs_error::FILES).unwrap()).unwrap();
    assert_eq!(files.len(), 4);
    assert!(std::fs::read_to_string(dir.join("report.md")).unwrap().contains("| rti | f32 | 32 |"));
    // every point drawn, and named: beside its dot, or in the line under the plot
    for unit in ["rti", "slab"] {
        let svg = std::fs::read_to_string(dir.join(format!("report_{unit}.svg"))).unwrap();
        let pts: Vec<&str> = r.points.iter().filter(|p| p.unit == unit).map(|p| p.variant.as_str()).collect();
        assert_eq!(svg.matches("<circle").count(), pts.len(), "{unit}");
        let texts: Vec<&str> =
            svg.split("<text").skip(1).filter_map(|t| t.split(['>', '<']).nth(1)).map(str::trim).collect();
        let crowded: Vec<&str> = texts
            .iter()
            .filter_map(|t| t.strip_prefix("not labelled (crowded): "))
            .flat_map(|l| l.split(", "))
            .collect();
        for v in &pts {
            assert!(texts.contains(v) || crowded.contains(v), "{unit}: {v} not named in {texts:?}");
        }
    }
    assert!(report(&ReportConfig { rays: 0, ..cfg.clone() }, &[Scene::builtin()]).is_err());
    assert!(report(&ReportConfig { variants: vec!["nope".into()], ..cfg }, &[Scene::builtin()]).is_err());
}
