//! Shared helpers of the root crate's tests: running the `raypipe` binary, reports without
//! their timings, and (re-exported from `datapath/tests/common`) the formats under test and
//! seeded case generators.
#![allow(dead_code)]

#[path = "../../datapath/tests/common/mod.rs"]
mod cases;
#[allow(unused_imports)]
pub use cases::*;

use std::process::{Command, Output};

/// Runs the `raypipe` binary with `args` in the temporary directory (so a relative path never
/// lands in the source tree) and returns its output.
pub fn raypipe(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_raypipe"))
        .current_dir(std::env::temp_dir())
        .args(args)
        .output()
        .expect("run raypipe")
}

/// A report as JSON without its timing fields (`mtests_per_s`, `judged_mtests_per_s` at any
/// depth): what two runs of the same work must agree on.
pub fn untimed<T: serde::Serialize>(r: &T) -> serde_json::Value {
    untimed_value(serde_json::to_value(r).unwrap())
}

/// [`untimed`] of JSON already parsed.
pub fn untimed_value(mut v: serde_json::Value) -> serde_json::Value {
    fn strip(v: &mut serde_json::Value) {
        match v {
            serde_json::Value::Object(m) => {
                m.remove("mtests_per_s");
                m.remove("judged_mtests_per_s");
                m.values_mut().for_each(strip);
            }
            serde_json::Value::Array(a) => a.iter_mut().for_each(strip),
            _ => {}
        }
    }
    strip(&mut v);
    v
}
