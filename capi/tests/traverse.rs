//! The traverse unit through the C ABI: the tree loaded from a written set's BRAM images
//! reproduces every ray's expected row; a changed image, a set of another unit and a missing
//! directory are clear errors.

use datapath::bvh::NodeDesc;
use datapath::rti::RtiConfig;
use raypipe_capi::*;
use std::ffi::{CStr, CString};
use vectors::gen::{generate, Request, Unit};
use vectors::read::set_rows;
use vectors::traverse::TreeInput;
use vectors::write::write_set;

/// A balanced tree of 16 leaves: unit cubes spaced along x and y, inner boxes their unions.
fn tree() -> TreeInput {
    fn build(nodes: &mut Vec<NodeDesc>, lo: u32, hi: u32) -> u32 {
        if hi - lo == 1 {
            let (x, y) = ((lo % 4) as f64 * 1.5 - 3.0, (lo / 4) as f64 * 1.5 - 3.0);
            nodes.push(NodeDesc { children: None, leaf: lo, min: [x, y, -0.5], max: [x + 1.0, y + 1.0, 0.5] });
            return nodes.len() as u32 - 1;
        }
        let mid = (lo + hi) / 2;
        let (a, b) = (build(nodes, lo, mid), build(nodes, mid, hi));
        let (na, nb) = (nodes[a as usize], nodes[b as usize]);
        let min = std::array::from_fn(|k| na.min[k].min(nb.min[k]));
        let max = std::array::from_fn(|k| na.max[k].max(nb.max[k]));
        nodes.push(NodeDesc { children: Some([a, b]), leaf: 0, min, max });
        nodes.len() as u32 - 1
    }
    let mut nodes = Vec::new();
    let root = build(&mut nodes, 0, 16);
    TreeInput { name: "grid of 16 cubes".into(), nodes, root }
}

fn request(format: &str) -> Request {
    Request {
        unit: Unit::Traverse,
        format: format.parse().unwrap(),
        count: 6,
        seed: 3,
        level: 1,
        command: "capi traverse test".into(),
        rti: RtiConfig::default(),
        slab_variant: "plain".into(),
        tree: Some(tree()),
        leaves: 8,
        max_levels: 64,
        explicit: None,
        closure: None,
        threads: 1,
    }
}

fn open(dir: &std::path::Path) -> (i32, *mut RpUnit) {
    let d = CString::new(dir.to_str().unwrap()).unwrap();
    let mut u = std::ptr::null_mut();
    // SAFETY: a valid string and out pointer
    let rc = unsafe { rp_traverse_open(d.as_ptr(), &mut u) };
    (rc, u)
}

fn last_error() -> String {
    // SAFETY: rp_last_error is always a valid string
    unsafe { CStr::from_ptr(rp_last_error()) }.to_string_lossy().into_owned()
}

#[test]
fn the_tree_of_a_written_set_reproduces_every_ray() {
    for fmt in ["f32", "fp16", "e8m16"] {
        let set = generate(&request(fmt)).unwrap();
        let rows = set_rows(&set).unwrap();
        let dir = std::env::temp_dir().join(format!("raypipe-capi-trav-{}-{fmt}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        write_set(&set, &dir).unwrap();
        let (rc, u) = open(&dir);
        assert_eq!(rc, RP_OK, "{fmt}: {}", last_error());
        // SAFETY: a live handle
        let (ni, no, ns) = unsafe { (rp_unit_inputs(u), rp_unit_outputs(u), rp_unit_stages(u)) };
        assert_eq!((ni, ns), (8, 0));
        let (rays, want) = (&rows[0], &rows[1]);
        assert!(rays.len() > 10, "{fmt}: {} rays", rays.len());
        let mut all = Vec::new();
        for (k, ray) in rays.iter().enumerate() {
            let mut out = vec![0u64; no];
            // SAFETY: lengths as passed
            let rc = unsafe { rp_eval(u, ray[1..].as_ptr(), 8, out.as_mut_ptr(), no, std::ptr::null_mut(), 0) };
            assert_eq!(rc, RP_OK, "{fmt} ray {k}: {}", last_error());
            assert_eq!(out, want[k], "{fmt} ray {k}");
            all.extend_from_slice(&ray[1..]);
        }
        let mut out = vec![0u64; rays.len() * no];
        // SAFETY: lengths as passed
        let rc = unsafe { rp_eval_batch(u, rays.len(), all.as_ptr(), all.len(), out.as_mut_ptr(), out.len()) };
        assert_eq!(rc, RP_OK);
        assert_eq!(out, want.concat(), "{fmt} batch");
        // SAFETY: freed once
        unsafe { rp_unit_free(u) };

        // a bank image changed after writing: refused, naming the file
        let bank = dir.join("tree_l0_left.hex");
        let mut text = std::fs::read_to_string(&bank).unwrap();
        text = text.replacen('0', "1", 1);
        std::fs::write(&bank, text).unwrap();
        let (rc, u) = open(&dir);
        assert!(rc == RP_ERR_ARGUMENT && u.is_null(), "{fmt}: a changed image was accepted");
        assert!(last_error().contains("tree_l0_left.hex"), "{}", last_error());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

#[test]
fn other_sets_and_bad_paths_are_clear_errors() {
    let (rc, _) = open(std::path::Path::new("/nonexistent/raypipe-set"));
    assert_eq!(rc, RP_ERR_ARGUMENT);
    assert!(last_error().contains("manifest.json"), "{}", last_error());
    let mut rti = request("f32");
    rti.unit = Unit::Rti;
    rti.tree = None;
    let dir = std::env::temp_dir().join(format!("raypipe-capi-trav-rti-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    write_set(&generate(&rti).unwrap(), &dir).unwrap();
    let (rc, _) = open(&dir);
    assert_eq!(rc, RP_ERR_ARGUMENT);
    assert!(last_error().contains("not traverse"), "{}", last_error());
    std::fs::remove_dir_all(&dir).unwrap();
    let mut u = std::ptr::null_mut();
    // SAFETY: null is an error code, not a crash
    assert_eq!(unsafe { rp_traverse_open(std::ptr::null(), &mut u) }, RP_ERR_NULL);
}

#[test]
fn a_batch_whose_output_room_is_not_its_rows_is_refused() {
    use raypipe_capi::unit::Unit as U;
    let set = generate(&request("f32")).unwrap();
    let dir = std::env::temp_dir().join(format!("raypipe-capi-trav-room-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    write_set(&set, &dir).unwrap();
    let u = U::open_set(&dir).unwrap();
    let rows = set_rows(&set).unwrap();
    let input: Vec<u64> = rows[0].iter().take(3).flat_map(|r| r[1..].to_vec()).collect();
    let no = u.outputs();
    let mut exact = vec![0u64; 3 * no];
    u.batch(&input, &mut exact).unwrap();
    assert_eq!(exact, rows[1][..3].concat());
    for room in [3 * no - 1, 3 * no + 1, 4 * no, 0] {
        let mut out = vec![0u64; room];
        let e = u.batch(&input, &mut out).unwrap_err();
        assert!(e.contains("take") && e.contains(&room.to_string()), "{room}: {e}");
    }
    for (unit, fmt) in [("rti", "f32"), ("slab", "fp16"), ("op", "bf16")] {
        let u = U::new(unit, fmt, "").unwrap();
        let (ni, no) = (u.kind.inputs(), u.outputs());
        let input = vec![0u64; 2 * ni];
        assert!(u.batch(&input, &mut vec![0u64; 2 * no]).is_ok(), "{unit}");
        assert!(u.batch(&input, &mut vec![0u64; 2 * no - 1]).is_err(), "{unit}");
        assert!(u.batch(&input, &mut vec![0u64; 3 * no]).is_err(), "{unit}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
