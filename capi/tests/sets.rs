//! Through the C ABI, every row of generated vector sets (rti, slab in every variant, op; IEEE,
//! FTZ, custom and fixed-point formats; RTI options) evaluates to the set's expected row and
//! stage row, one test at a time and in batches; the handle's stage names are the set's.

use datapath::rti::{Cull, RtiConfig, TieRule};
use raypipe_capi::*;
use std::ffi::{CStr, CString};
use vectors::gen::{generate, Request, Unit};
use vectors::read::set_rows;

fn request(unit: Unit, format: &str, rti: RtiConfig, variant: &str) -> Request {
    Request {
        unit,
        format: format.parse().unwrap(),
        count: 6,
        seed: 11,
        level: 1,
        command: "capi test".into(),
        rti,
        slab_variant: variant.into(),
        tree: None,
        leaves: 8,
        max_levels: 64,
        explicit: None,
        closure: None,
        threads: 1,
    }
}

fn unit(name: &str, format: &str, options: &str) -> *mut RpUnit {
    let (n, f, o) = (CString::new(name).unwrap(), CString::new(format).unwrap(), CString::new(options).unwrap());
    let mut u = std::ptr::null_mut();
    // SAFETY: valid strings and out pointer
    let rc = unsafe { rp_unit_new(n.as_ptr(), f.as_ptr(), o.as_ptr(), &mut u) };
    assert_eq!(rc, RP_OK, "{name} {format} {options}: {:?}", unsafe { CStr::from_ptr(rp_last_error()) });
    u
}

/// Every row of the set through `rp_eval` (outputs and stages) and `rp_eval_batch`.
fn check(u: *mut RpUnit, req: &Request, what: &str) {
    let set = generate(req).unwrap();
    let files = set_rows(&set).unwrap();
    let (inputs, expected) = (&files[0], &files[1]);
    // SAFETY: a live handle throughout
    let (ni, no, ns) = unsafe { (rp_unit_inputs(u), rp_unit_outputs(u), rp_unit_stages(u)) };
    assert!(!inputs.is_empty(), "{what}: an empty set");
    let mut all_in = Vec::new();
    for (k, row) in inputs.iter().enumerate() {
        // the class column first, then the unit's inputs
        let x = &row[1..];
        assert_eq!(x.len(), ni, "{what}");
        let (mut out, mut st) = (vec![0u64; no], vec![0u64; ns.max(1)]);
        let stages = if ns > 0 { st.as_mut_ptr() } else { std::ptr::null_mut() };
        // SAFETY: lengths as passed
        let rc = unsafe { rp_eval(u, x.as_ptr(), x.len(), out.as_mut_ptr(), out.len(), stages, st.len()) };
        assert_eq!(rc, RP_OK, "{what} row {k}");
        assert_eq!(out, expected[k], "{what} row {k}: outputs");
        if ns > 0 {
            assert_eq!(st, files[2][k], "{what} row {k}: stage signals");
        }
        all_in.extend_from_slice(x);
    }
    // the output widths are the expected file's fields
    let file = set.manifest.files.iter().find(|f| f.name.ends_with("_expected.hex")).expect("an expected file");
    let ow: Vec<u32> = (0..no).map(|i| unsafe { rp_unit_output_width(u, i) }).collect();
    assert_eq!(ow, file.fields.iter().map(|f| f.width).collect::<Vec<_>>(), "{what}: output widths");
    // SAFETY: one past the end
    assert_eq!(unsafe { rp_unit_output_width(u, no) }, 0);
    let n = inputs.len();
    let mut out = vec![0u64; n * no];
    // SAFETY: lengths as passed
    let rc = unsafe { rp_eval_batch(u, n, all_in.as_ptr(), all_in.len(), out.as_mut_ptr(), out.len()) };
    assert_eq!(rc, RP_OK, "{what} batch");
    for k in 0..n {
        assert_eq!(out[k * no..(k + 1) * no], expected[k][..], "{what} batch row {k}");
    }
    // the stage names are the stage file's columns
    if ns > 0 {
        let names: Vec<String> = (0..ns)
            // SAFETY: i < ns, a live handle
            .map(|i| unsafe { CStr::from_ptr(rp_unit_stage_name(u, i)) }.to_str().unwrap().to_string())
            .collect();
        let m = &set.manifest;
        let file = m.files.iter().find(|f| f.name.ends_with("_stages.hex")).expect("a stage file");
        let want: Vec<String> = file.fields.iter().map(|f| f.name.clone()).collect();
        assert_eq!(names, want, "{what}: stage names");
        // and their widths the fields' widths
        let widths: Vec<u32> = (0..ns).map(|i| unsafe { rp_unit_stage_width(u, i) }).collect();
        let want_w: Vec<u32> = file.fields.iter().map(|f| f.width).collect();
        assert_eq!(widths, want_w, "{what}: stage widths");
        // SAFETY: one past the end
        assert!(unsafe { rp_unit_stage_name(u, ns) }.is_null());
    }
}

const FORMATS: [&str; 8] = ["f32", "fp16", "bf16", "e8m16", "e5m10:ftz", "f32:ftz+divide", "q8.24:divide", "q16.16"];

#[test]
fn rti_rows_are_the_sets_rows() {
    for f in FORMATS {
        for (opts, cfg) in [
            ("", RtiConfig::default()),
            (
                "--cull --det-threshold 0.001 --tie last",
                RtiConfig { cull: Cull::Backface, det_threshold: 0.001, tie: TieRule::Last },
            ),
        ] {
            let u = unit("rti", f, opts);
            check(u, &request(Unit::Rti, f, cfg, "plain"), &format!("rti {f} {opts}"));
            // SAFETY: freed once
            unsafe { rp_unit_free(u) };
        }
    }
}

#[test]
fn slab_rows_are_the_sets_rows_in_every_variant() {
    for f in FORMATS {
        for v in ["plain", "conservative", "directed", "take-on-false", "embree"] {
            let ok = datapath::with_format!(f.parse::<datapath::AnyFormat>().unwrap(), |fm| {
                datapath::slab::SlabConfig::named_for(v, &fm).is_ok()
            });
            if !ok {
                continue;
            }
            let u = unit("slab", f, &format!("--variant {v}"));
            if v == "directed" {
                directed(u, f);
            } else {
                check(u, &request(Unit::Slab, f, RtiConfig::default(), v), &format!("slab {f} {v}"));
            }
            // SAFETY: freed once
            unsafe { rp_unit_free(u) };
        }
    }
}

/// The directed variant has no vector sets (its signal set depends on the data): on the plain
/// set's input rows, its outputs are the slab model's (`Slab::test`) one at a time and in a
/// batch, and a request for its stage signals is refused.
fn directed(u: *mut RpUnit, f: &str) {
    use datapath::slab::{Aabb, Slab, SlabConfig};
    use datapath::Format;
    let set = generate(&request(Unit::Slab, f, RtiConfig::default(), "plain")).unwrap();
    let inputs = &set_rows(&set).unwrap()[0];
    let any: datapath::AnyFormat = f.parse().unwrap();
    let mut all = Vec::new();
    let mut want = Vec::new();
    for row in inputs {
        let x = &row[1..];
        let w: [u64; 3] = datapath::with_format!(any, |fm| {
            let s = Slab::new(fm, SlabConfig::named_for("directed", &fm).unwrap());
            let v = |i: usize| s.fmt.from_bits(x[i]);
            let r = s.prepare_faulty(
                [v(0), v(1), v(2)],
                [v(3), v(4), v(5)],
                v(6),
                v(7),
                &mut datapath::probe::NoProbe,
                &datapath::fault::NoFault,
            );
            let o = s.test(&r, &Aabb { min: [v(8), v(9), v(10)], max: [v(11), v(12), v(13)] });
            [o.hit as u64, s.fmt.to_bits(o.t_near), s.fmt.to_bits(o.t_far)]
        });
        let mut out = [0u64; 3];
        // SAFETY: lengths as passed
        assert_eq!(unsafe { rp_slab(u, x.as_ptr(), out.as_mut_ptr(), std::ptr::null_mut()) }, RP_OK);
        assert_eq!(out, w, "slab {f} directed");
        let mut st = [0u64; 64];
        // SAFETY: lengths as passed
        assert_eq!(unsafe { rp_slab(u, x.as_ptr(), out.as_mut_ptr(), st.as_mut_ptr()) }, RP_ERR_UNIT);
        all.extend_from_slice(x);
        want.extend_from_slice(&w);
    }
    // SAFETY: a live handle
    assert_eq!(unsafe { rp_unit_stages(u) }, 0);
    let mut out = vec![0u64; want.len()];
    // SAFETY: lengths as passed
    let rc = unsafe { rp_eval_batch(u, inputs.len(), all.as_ptr(), all.len(), out.as_mut_ptr(), out.len()) };
    assert_eq!(rc, RP_OK);
    assert_eq!(out, want, "slab {f} directed batch");
}

#[test]
fn op_rows_are_the_sets_rows() {
    for f in FORMATS {
        let u = unit("op", f, "");
        check(u, &request(Unit::Op, f, RtiConfig::default(), "plain"), &format!("op {f}"));
        // SAFETY: freed once
        unsafe { rp_unit_free(u) };
    }
}
