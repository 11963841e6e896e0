//! The C side: `capi/tests/c/check.c` (hand-worked results, batch against single tests, every
//! error path) and the worked example `capi/examples/demo.c`, compiled with the system's C
//! compiler against the static library and the checked-in header, run, and judged.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The directory holding this build's `libraypipe_capi.a` (the test binary is in its `deps`).
fn lib_dir() -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    exe.parent().and_then(Path::parent).unwrap().to_path_buf()
}

/// Builds this crate's static library in this test's profile and target directory (`cargo
/// test` builds the crate as an rlib only), once per test binary.
fn static_lib() -> PathBuf {
    static BUILT: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();
    BUILT
        .get_or_init(|| {
            let dir = lib_dir();
            let profile = dir.file_name().unwrap().to_str().unwrap().to_string();
            let mut cmd = Command::new(env!("CARGO"));
            cmd.args(["build", "-q", "-p", "raypipe-capi", "--lib"]);
            match profile.as_str() {
                "debug" => {}
                "release" => {
                    cmd.arg("--release");
                }
                p => {
                    cmd.args(["--profile", p]);
                }
            }
            cmd.env("CARGO_TARGET_DIR", dir.parent().unwrap());
            let st = cmd.status().expect("cargo runs");
            assert!(st.success(), "cargo build -p raypipe-capi failed");
            dir.join("libraypipe_capi.a")
        })
        .clone()
}

/// Compiles `src` into a temporary executable and runs it: (exit success, stdout).
fn build_and_run(src: &str, name: &str) -> (bool, String) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let lib = static_lib();
    assert!(lib.exists(), "no {}", lib.display());
    let out = std::env::temp_dir().join(format!("raypipe-capi-{}-{name}", std::process::id()));
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    let st = Command::new(&cc)
        .args(["-std=c11", "-O2", "-Wall", "-Wextra", "-Werror", "-I"])
        .arg(dir.join("include"))
        .arg(dir.join(src))
        .arg(&lib)
        .args(["-lpthread", "-ldl", "-lm", "-o"])
        .arg(&out)
        .status()
        .unwrap_or_else(|e| panic!("{cc}: {e}"));
    assert!(st.success(), "{cc} failed on {src}");
    let run = Command::new(&out).output().unwrap();
    let _ = std::fs::remove_file(&out);
    (run.status.success(), String::from_utf8_lossy(&run.stdout).into_owned())
}

#[test]
fn the_c_checks_pass() {
    let (ok, text) = build_and_run("tests/c/check.c", "check");
    let last = text.lines().last().unwrap_or("");
    assert!(ok && last.ends_with(" passed, 0 failed"), "{text}");
    let passed: usize = last.split(' ').next().unwrap().parse().unwrap();
    assert!(passed > 1000, "{text}");
}

#[test]
fn the_worked_example_runs() {
    let (ok, text) = build_and_run("examples/demo.c", "demo");
    assert!(ok, "{text}");
    assert!(text.contains("rti f32 valid 1 hit 1 t 3f800000 u 3e800000 v 3e800000"), "{text}");
    assert!(text.contains("batch of 1000: last t 3f800000"), "{text}");
    assert!(text.contains("rp_unit_new(\"f33\") = 1:"), "{text}");
}
