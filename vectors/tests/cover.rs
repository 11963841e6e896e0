//! Coverage of vector sets: counts merge exactly (two halves merged = one pass), no bin the
//! model marks unreachable is ever hit by the default sets, and the op unit's default sets
//! reach every reachable bin.

use datapath::rti::RtiConfig;
use vectors::cover::Coverage;
use vectors::gen::{generate, Request, Unit};
use vectors::read::set_rows;

fn req(unit: Unit, format: &str) -> Request {
    Request {
        unit,
        format: format.parse().unwrap(),
        count: 4,
        seed: 3,
        level: 1,
        command: "test".into(),
        rti: RtiConfig::default(),
        slab_variant: if format.contains("ftz") { "plain" } else { "conservative" }.into(),
        tree: None,
        leaves: 8,
        max_levels: 64,
        explicit: None,
        threads: 1,
    }
}

#[test]
fn halves_merged_equal_one_pass() {
    for (unit, format) in [(Unit::Rti, "fp16"), (Unit::Slab, "f32"), (Unit::Op, "bf16"), (Unit::Capture, "fp16")] {
        let set = generate(&req(unit, format)).unwrap();
        let rows = set_rows(&set).unwrap();
        let n = rows[0].len();
        let whole = Coverage::measure(&set.manifest, &rows).unwrap();
        let mut a = Coverage::model(&set.manifest);
        a.add_rows(&set.manifest, &rows, 0..n / 3).unwrap();
        let mut b = Coverage::model(&set.manifest);
        b.add_rows(&set.manifest, &rows, n / 3..n).unwrap();
        a.merge(&b).unwrap();
        assert_eq!(a, whole, "{unit:?} {format}");
        assert_eq!(whole.vectors as usize, n);
        // merging another format's coverage is refused
        let other = generate(&req(unit, "f32:ftz")).unwrap();
        let oc = Coverage::measure(&other.manifest, &set_rows(&other).unwrap()).unwrap();
        assert!(a.merge(&oc).is_err());
    }
}

#[test]
fn unreachable_bins_are_never_hit_and_op_sets_reach_every_other_bin() {
    for format in ["fp16", "f32", "bf16", "fp16:ftz", "f32:ftz+propagate", "e5m6:divide"] {
        for unit in [Unit::Rti, Unit::Slab, Unit::Op, Unit::Capture] {
            if unit == Unit::Op && format.starts_with("e5") {
                continue;
            }
            let set = generate(&Request { count: 8, ..req(unit, format) }).unwrap();
            let c = Coverage::measure(&set.manifest, &set_rows(&set).unwrap()).unwrap();
            assert!(c.contradictions().is_empty(), "{unit:?} {format}: {:?}", c.contradictions());
            let (hit, bins) = c.totals();
            assert!(hit > 0 && hit <= bins);
            if unit == Unit::Op && !format.contains("ftz") {
                assert_eq!(hit, bins, "{format}: the op sets reach every reachable bin");
            }
        }
    }
}
