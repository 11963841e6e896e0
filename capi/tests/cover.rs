//! The live coverage recorder through the C ABI: recording a vector set's input rows gives the
//! coverage `raypipe cover` measures from the set's own files (every bin but the class bins,
//! which hold `live`), for rti, slab and op with options; the file it writes reads back; every
//! error path returns its code and never replaces a file raypipe did not write.

use datapath::rti::{Cull, RtiConfig, TieRule};
use raypipe_capi::*;
use std::ffi::{CStr, CString};
use vectors::cover::Coverage;
use vectors::gen::{generate, Request, Unit};
use vectors::read::set_rows;

fn recorder(unit: &str, format: &str, options: &str) -> Result<*mut RpCover, (i32, String)> {
    let (n, f, o) = (CString::new(unit).unwrap(), CString::new(format).unwrap(), CString::new(options).unwrap());
    let mut c = std::ptr::null_mut();
    // SAFETY: valid strings and out pointer
    let rc = unsafe { rp_cover_new(n.as_ptr(), f.as_ptr(), o.as_ptr(), &mut c) };
    if rc == RP_OK {
        Ok(c)
    } else {
        Err((rc, last()))
    }
}

fn last() -> String {
    // SAFETY: a static or thread-local NUL-terminated string
    unsafe { CStr::from_ptr(rp_last_error()) }.to_str().unwrap().to_string()
}

/// Every coverpoint but the class bins.
fn without_class(c: &Coverage) -> Vec<(String, Vec<u64>)> {
    c.coverpoints
        .iter()
        .filter(|p| p.kind != "class")
        .map(|p| (p.signal.clone(), p.bins.iter().map(|b| b.count).collect()))
        .collect()
}

#[test]
fn recording_a_sets_rows_measures_the_sets_coverage() {
    let dir = std::env::temp_dir().join(format!("raypipe-capi-cover-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let cases: [(Unit, &str, &str, RtiConfig, &str); 5] = [
        (Unit::Rti, "fp16", "", RtiConfig::default(), "plain"),
        (
            Unit::Rti,
            "q8.24:divide",
            "--cull --det-threshold 0.001 --tie last",
            RtiConfig { cull: Cull::Backface, det_threshold: 0.001, tie: TieRule::Last },
            "plain",
        ),
        (Unit::Slab, "f32", "--variant conservative", RtiConfig::default(), "conservative"),
        (Unit::Slab, "bf16", "--variant embree", RtiConfig::default(), "embree"),
        (Unit::Op, "e8m16", "", RtiConfig::default(), "plain"),
    ];
    for (k, (unit, format, options, rti, variant)) in cases.into_iter().enumerate() {
        let mut req = Request::new(unit, format.parse().unwrap());
        req.count = 4;
        req.rti = rti;
        req.slab_variant = variant.into();
        let set = generate(&req).unwrap();
        let rows = set_rows(&set).unwrap();
        let want = Coverage::measure(&set.manifest, &rows).unwrap();
        let name = format!("{unit:?}").to_lowercase();
        let c = recorder(&name, format, options).unwrap_or_else(|e| panic!("{name} {format}: {e:?}"));
        for r in &rows[0] {
            // the C ABI's row: the set's input row without its class column
            let x = &r[1..];
            // SAFETY: a live recorder, x.len() values
            assert_eq!(unsafe { rp_cover_add(c, x.as_ptr(), x.len()) }, RP_OK, "{}", last());
        }
        // SAFETY: a live recorder
        assert_eq!(unsafe { rp_cover_rows(c) }, rows[0].len() as u64);
        let path = dir.join(format!("live{k}.json"));
        let p = CString::new(path.to_str().unwrap()).unwrap();
        // SAFETY: a live recorder, a path string
        assert_eq!(unsafe { rp_cover_write(c, p.as_ptr()) }, RP_OK, "{}", last());
        let got = vectors::cover_file::read(&std::fs::read_to_string(&path).unwrap()).unwrap();
        assert_eq!(got.len(), 1);
        let (m, g) = &got[0];
        assert_eq!(m.options, set.manifest.options, "{name} {format}: the recorder's model is the set's");
        assert_eq!(without_class(g), without_class(&want), "{name} {format} {options}");
        assert_eq!(g.vectors, want.vectors);
        let class = g.coverpoints.iter().find(|p| p.kind == "class").unwrap();
        assert_eq!(class.bins.len(), 1);
        assert_eq!((class.bins[0].name.as_str(), class.bins[0].count), ("live", want.vectors));
        // the recording merges with the set (class bins by name)
        let mut sum = g.clone();
        sum.merge(&want).unwrap();
        assert_eq!(sum.vectors, 2 * want.vectors);
        // SAFETY: freed once
        unsafe { rp_cover_free(c) };
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn recorder_errors_are_codes() {
    assert_eq!(recorder("traverse", "fp16", "").unwrap_err().0, RP_ERR_ARGUMENT);
    assert_eq!(recorder("slab", "fp16", "--variant directed").unwrap_err().0, RP_ERR_ARGUMENT);
    assert_eq!(recorder("rti", "fp99", "").unwrap_err().0, RP_ERR_ARGUMENT);
    let c = recorder("rti", "fp16", "").unwrap();
    let row = [0u64; 17];
    // SAFETY: every pointer below is valid or deliberately null
    unsafe {
        assert_eq!(rp_cover_add(c, row.as_ptr(), 16), RP_ERR_LENGTH);
        assert_eq!(rp_cover_add(c, std::ptr::null(), 17), RP_ERR_NULL);
        assert_eq!(rp_cover_add(std::ptr::null(), row.as_ptr(), 17), RP_ERR_NULL);
        let wide = [0x1_0000u64; 17];
        assert_eq!(rp_cover_add(c, wide.as_ptr(), 17), RP_ERR_ARGUMENT);
        assert_eq!(rp_cover_rows(c), 0, "a refused row is not counted");
        assert_eq!(rp_cover_add(c, row.as_ptr(), 17), RP_OK);
        assert_eq!(rp_cover_rows(c), 1);
        assert_eq!(rp_cover_rows(std::ptr::null()), 0);
        assert_eq!(rp_cover_write(c, std::ptr::null()), RP_ERR_NULL);
        // a stranger's file is kept
        let mine = std::env::temp_dir().join(format!("raypipe-capi-mine-{}.json", std::process::id()));
        std::fs::write(&mine, "mine").unwrap();
        let p = CString::new(mine.to_str().unwrap()).unwrap();
        assert_eq!(rp_cover_write(c, p.as_ptr()), RP_ERR_ARGUMENT);
        assert!(last().contains("not replacing"), "{}", last());
        assert_eq!(std::fs::read_to_string(&mine).unwrap(), "mine");
        let _ = std::fs::remove_file(&mine);
        rp_cover_free(c);
        rp_cover_free(std::ptr::null_mut());
    }
}
