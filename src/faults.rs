//! `raypipe faults`: the fault bank against a vector set (generated, or read from a directory),
//! printed as a detection table.

use faults::Campaign;
use std::path::Path;

/// The manifest of the set in `dir`.
fn manifest_of(dir: &Path) -> Result<vectors::manifest::Manifest, String> {
    let path = dir.join("manifest.json");
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))
}

/// The campaign over the set in `dir` with manifest `m` (rows checked against their hashes).
fn on_set(dir: &Path, m: &vectors::manifest::Manifest, outputs_only: bool) -> Result<Campaign, String> {
    let rows = vectors::read::read_files(dir, m)?;
    faults::run(m, &rows, outputs_only)
}

/// The campaign over the set in `dir` (its manifest and rows, checked against their hashes).
pub fn on_dir(dir: &Path, outputs_only: bool) -> Result<Campaign, String> {
    on_set(dir, &manifest_of(dir)?, outputs_only)
}

/// For a minimal set (its manifest says so): the campaign over it, which must detect every
/// fault the manifest names; the number of them. `None` for a full set.
pub fn check_minimal(dir: &Path) -> Result<Option<usize>, String> {
    let m = manifest_of(dir)?;
    let Some(min) = &m.minimal else { return Ok(None) };
    let c = on_set(dir, &m, min.outputs_only)?;
    let missed: Vec<&str> = min
        .detects
        .iter()
        .filter(|name| !c.faults.iter().any(|o| o.name == name.as_str() && o.detected))
        .map(|s| s.as_str())
        .collect();
    if !missed.is_empty() {
        return Err(format!(
            "{}: a minimal set that no longer detects {} (its manifest says it does)",
            dir.display(),
            missed.join(", ")
        ));
    }
    Ok(Some(min.detects.len()))
}

/// The campaign over the set `req` generates (in memory).
pub fn on_request(req: &vectors::gen::Request, outputs_only: bool) -> Result<Campaign, String> {
    let set = vectors::gen::generate(req)?;
    let rows = vectors::read::set_rows(&set)?;
    faults::run(&set.manifest, &rows, outputs_only)
}

/// The detection table.
pub fn render(c: &Campaign) -> String {
    let mut s = format!(
        "raypipe faults: unit {}, format {}, {} vectors (set: level {}, seed {}, `{}`), compared: {}\n\n",
        c.unit,
        c.format,
        c.vectors,
        c.set_level,
        c.set_seed,
        c.set_command,
        if !c.outputs_only {
            "outputs and every stage probe"
        } else {
            match c.unit.as_str() {
                "slab" => "outputs only (hit, t_near, t_far)",
                "capture" => "outputs only (hit, t, u, v, id)",
                "op" => "outputs (result, cmp; the unit has no stage probes)",
                "traverse" => {
                    "outputs only (count, leaves, final history; not the implementation-defined passes and box tests)"
                }
                _ => "outputs only (valid, hit, t, u, v)",
            }
        }
    );
    s += &format!("{:<24} {:<10} {:>8}  {:<16} what\n", "fault", "detected", "vectors", "first class");
    for o in &c.faults {
        let state = match (o.applicable, o.detected, o.benign) {
            (false, _, _) => "n/a",
            (true, true, _) => "yes",
            (true, false, true) => "benign",
            (true, false, false) => "ESCAPED",
        };
        s += &format!(
            "{:<24} {:<10} {:>8}  {:<16} {}{}\n",
            o.name,
            state,
            o.vectors,
            o.first_class.as_deref().unwrap_or("-"),
            o.what,
            o.not_applicable.as_deref().map(|w| format!(" [{w}]")).unwrap_or_default()
        );
        if !o.first_bins.is_empty() {
            s += &format!("{:<24}   first vector's rarest bins: {}\n", "", o.first_bins.join("; "));
        }
    }
    let applicable = c.faults.iter().filter(|o| o.applicable && !o.benign).count();
    s += &format!(
        "\ndetected {} of {} applicable non-benign faults; escaped {}; benign {}; not applicable {}\n",
        c.detected,
        applicable,
        c.escaped,
        c.faults.iter().filter(|o| o.applicable && o.benign).count(),
        c.faults.iter().filter(|o| !o.applicable).count()
    );
    s += if c.complete() {
        "property: PASS (the set detects every applicable non-benign fault)\n"
    } else {
        "property: FAIL (some hardware faults escape this set: it needs the input classes that catch them)\n"
    };
    s
}
