//! The SMT solver driver: raypipe hands a script to `raypipe_solve.py` (bitwuzla, cvc5 or
//! z3 through their PyPI packages) on the Python the environment names (`RAYPIPE_PYTHON`,
//! else `python3`) and reads back the verdict, the solver, its version and the time.

use std::io::Write;
use std::process::{Command, Stdio};

/// The driver's source (run as a program; `formal/py/raypipe_solve.py`).
pub const DRIVER: &str = include_str!("../py/raypipe_solve.py");

/// A solver's verdict on a script's assertions.
#[derive(Clone, Debug, PartialEq)]
pub struct Verdict {
    /// `sat`, `unsat` or `unknown`.
    pub result: String,
    /// Solver name.
    pub solver: String,
    /// Solver version.
    pub version: String,
    /// Wall time of parse and check, seconds.
    pub seconds: f64,
    /// Values of the requested terms (sat only).
    pub values: Vec<(String, u64)>,
}

impl Verdict {
    /// The value read back for `name` (0 when none was).
    pub fn value(&self, name: &str) -> u64 {
        self.values.iter().find(|(n, _)| n == name).map_or(0, |(_, v)| *v)
    }
}

/// Checks `script` with `solver` (`auto`, `bitwuzla`, `cvc5`, `z3`) within `timeout_s`
/// seconds (0: none), reading `values` back when it is satisfiable.
pub fn check(script: &str, solver: &str, timeout_s: f64, values: &[String]) -> Result<Verdict, String> {
    let python = std::env::var("RAYPIPE_PYTHON").unwrap_or_else(|_| "python3".into());
    static SEQ: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let seq = SEQ.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("raypipe-solve-{}-{seq}", std::process::id()));
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let driver = dir.join("raypipe_solve.py");
    std::fs::write(&driver, DRIVER).map_err(|e| format!("{}: {e}", driver.display()))?;
    let req = serde_json::json!({"solver": solver, "script": script, "timeout_s": timeout_s, "values": values});
    let mut child = Command::new(&python)
        .arg(&driver)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| format!("cannot run {python} (set RAYPIPE_PYTHON to a Python with bitwuzla or cvc5): {e}"))?;
    {
        let mut stdin = child.stdin.take().ok_or("no stdin")?;
        stdin.write_all(req.to_string().as_bytes()).map_err(|e| format!("solver driver: {e}"))?;
    }
    let out = child.wait_with_output().map_err(|e| format!("solver driver: {e}"))?;
    let _ = std::fs::remove_dir_all(&dir);
    if !out.status.success() {
        let err = String::from_utf8_lossy(&out.stderr);
        let last = err.lines().rev().find(|l| !l.trim().is_empty()).unwrap_or("");
        if last.contains("ModuleNotFoundError") {
            return Err(format!(
                "no SMT solver for {python}: {last} (pip install bitwuzla cvc5, or set RAYPIPE_PYTHON)"
            ));
        }
        return Err(format!("solver driver failed: {last}"));
    }
    let v: serde_json::Value =
        serde_json::from_slice(&out.stdout).map_err(|e| format!("solver driver printed no verdict: {e}"))?;
    let s = |k: &str| v[k].as_str().unwrap_or("").to_string();
    let values = v["values"]
        .as_object()
        .map(|m| m.iter().map(|(k, x)| (k.clone(), x.as_u64().unwrap_or(0))).collect())
        .unwrap_or_default();
    Ok(Verdict {
        result: s("result"),
        solver: s("solver"),
        version: s("version"),
        seconds: v["seconds"].as_f64().unwrap_or(0.0),
        values,
    })
}
