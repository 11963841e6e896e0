//! The checked-in C header is what cbindgen makes of the sources now (not stale).

use std::path::Path;

#[test]
fn the_checked_in_header_is_what_cbindgen_generates() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let cfg = cbindgen::Config::from_file(dir.join("cbindgen.toml")).expect("cbindgen.toml");
    let mut now = Vec::new();
    cbindgen::Builder::new()
        .with_config(cfg)
        .with_src(dir.join("src/lib.rs"))
        .generate()
        .expect("cbindgen generates the header")
        .write(&mut now);
    let path = dir.join("include/raypipe.h");
    if std::env::var_os("RAYPIPE_BLESS_HEADER").is_some() {
        std::fs::write(&path, &now).unwrap();
    }
    let have = std::fs::read(&path).unwrap_or_default();
    assert!(
        have == now,
        "capi/include/raypipe.h is stale: regenerate it with RAYPIPE_BLESS_HEADER=1 cargo test -p raypipe-capi --test header"
    );
}
