//! `vectors --check`: a whole set against what this raypipe writes. The model is re-run on
//! every input row ([`crate::read::check_rows`]); the manifest is regenerated from the set's own
//! unit, format, level, seed, options and (traverse) tree and compared field by field; the
//! generated HDL packages are regenerated from the manifest and compared byte for byte; and, for
//! a set written by this raypipe version, the input rows too (a minimal set's rows must be rows
//! of the full set, in order). The first difference is named.

use crate::gen::{generate, Request, Unit};
use crate::manifest::{Manifest, SCHEMA};
use crate::traverse::TreeInput;
use datapath::bvh::{NodeDesc, LEAF_FLAG};
use datapath::rti::{Cull, RtiConfig, TieRule};
use datapath::{with_format, AnyFormat, Format};
use std::path::Path;

/// Checks the set in `dir`; returns the number of vectors (rays for traverse) checked.
pub fn check_set(dir: &Path) -> Result<usize, String> {
    let path = dir.join("manifest.json");
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let m: Manifest = serde_json::from_str(&text).map_err(|e| format!("manifest.json: {e}"))?;
    if m.schema != SCHEMA {
        return Err(format!("manifest.json: field schema is {}, this raypipe reads {SCHEMA}", m.schema));
    }
    let unit: Unit = m.unit.parse().map_err(|e| format!("manifest.json: field unit: {e}"))?;
    let any: AnyFormat = m.format.parse().map_err(|e| format!("manifest.json: field format: {e}"))?;
    let contents = crate::read::read_files(dir, &m)?;
    // the manifest this raypipe writes for the same unit, format, level, seed and options
    let regen = generate(&request_from(&m, unit, any, &contents)?)?;
    compare_manifests(&m, &regen.manifest)?;
    let n = crate::read::check_rows(&m, unit, any, &contents)?;
    // the HDL packages are a function of the manifest
    for (name, want) in
        [("raypipe_pkg.sv", crate::hdl::sv_package(&m)), ("raypipe_pkg.vhd", crate::hdl::vhdl_package(&m))]
    {
        let p = dir.join(name);
        let got = std::fs::read_to_string(&p).map_err(|e| format!("{}: {e}", p.display()))?;
        if let Some((k, (a, b))) = got.lines().zip(want.lines()).enumerate().find(|(_, (a, b))| a != b) {
            return Err(format!("{name} line {}: '{a}' differs from the manifest's '{b}'", k + 1));
        }
        if got.lines().count() != want.lines().count() {
            return Err(format!(
                "{name}: {} lines, the manifest's package has {}",
                got.lines().count(),
                want.lines().count()
            ));
        }
    }
    // the AXI4-Stream wrapper, when the set has one, is a function of its map and the manifest
    crate::axis::check_files(dir, &m)?;
    // inputs: what this raypipe draws from the seed (the same version only; traverse rays are
    // drawn from the original scene, which the set does not hold)
    if unit != Unit::Traverse && m.raypipe_version == env!("CARGO_PKG_VERSION") {
        for (name, want) in &regen.files {
            let got = std::fs::read_to_string(dir.join(name)).map_err(|e| format!("{name}: {e}"))?;
            let per_vector = m
                .files
                .iter()
                .position(|f| &f.name == name)
                .is_some_and(|i| i < 2 || m.files[i].role == crate::hdl::STAGE_ROLE);
            if m.minimal.is_some() && per_vector {
                // a minimal set keeps some rows of the full set, in their order
                let mut full = want.lines();
                if let Some((k, _)) = got.lines().enumerate().find(|(_, line)| !full.any(|w| w == *line)) {
                    return Err(format!(
                        "{name} line {}: not a row of the full set this raypipe writes for seed {} (in order)",
                        k + 1,
                        m.seed
                    ));
                }
                continue;
            }
            if let Some((k, _)) = got.lines().zip(want.lines()).enumerate().find(|(_, (a, b))| a != b) {
                return Err(format!(
                    "{name} line {}: differs from what this raypipe writes for seed {}",
                    k + 1,
                    m.seed
                ));
            }
        }
    }
    Ok(n)
}

/// The request that wrote `m` (the tree of a traverse set rebuilt from its BRAM images).
fn request_from(m: &Manifest, unit: Unit, format: AnyFormat, contents: &[Vec<Vec<u64>>]) -> Result<Request, String> {
    let opt = |k: &str| m.options.get(k).map(String::as_str);
    let param = |k: &str| m.params.get(k).copied().ok_or(format!("manifest.json: params has no {k}"));
    let rti = if unit == Unit::Rti { rti_from_options(&m.options)? } else { RtiConfig::default() };
    let count = if m.count > 0 { m.count } else { m.classes.iter().map(|c| c.count).max().unwrap_or(0).max(1) };
    let (tree, leaves, max_levels) = if unit == Unit::Traverse {
        let tree = with_format!(format, |f| tree_from_banks(&f, m, contents))?;
        (Some(tree), param("leaves")? as usize, param("max_levels")? as usize)
    } else {
        (None, 8, 64)
    };
    Ok(Request {
        unit,
        format,
        count,
        seed: m.seed,
        level: m.level,
        threads: 1,
        command: m.command.clone(),
        rti,
        slab_variant: opt("variant").unwrap_or("plain").to_string(),
        tree,
        leaves,
        max_levels,
        explicit: explicit_from(m, unit, contents)?,
        closure: closure_from(m, contents)?,
    })
}

/// The RTI options a manifest's `options` name (cull, det_threshold, tie).
pub(crate) fn rti_from_options(options: &std::collections::BTreeMap<String, String>) -> Result<RtiConfig, String> {
    let opt = |k: &str| options.get(k).map(String::as_str);
    let thr = opt("det_threshold").and_then(|s| s.split_whitespace().next()).unwrap_or("0");
    Ok(RtiConfig {
        cull: if opt("cull") == Some("Backface") { Cull::Backface } else { Cull::TwoSided },
        det_threshold: thr.parse().map_err(|_| format!("manifest.json: options.det_threshold '{thr}'"))?,
        tie: if opt("tie") == Some("Last") { TieRule::Last } else { TieRule::First },
    })
}

/// A set with a coverage-closure class (`raypipe vectors --close`): its rows are given (the
/// search that found them is not repeated), so the regenerated set takes them from the set.
fn closure_from(m: &Manifest, contents: &[Vec<Vec<u64>>]) -> Result<Option<crate::gen::Explicit>, String> {
    let Some(cl) = &m.closure else { return Ok(None) };
    let class = m
        .classes
        .get(cl.class as usize)
        .filter(|_| cl.class as usize + 1 == m.classes.len())
        .ok_or("manifest.json: field closure: its class is not the last class")?;
    let rows = contents.first().ok_or("the set has no input file")?;
    // op rows keep (opcode, a, b); the others drop the class column only
    Ok(Some(crate::gen::Explicit {
        class: class.name.clone(),
        covers: class.covers.clone(),
        origin: cl.origin.clone(),
        rows: rows.iter().filter(|r| r.first() == Some(&u64::from(cl.class))).map(|r| r[1..].to_vec()).collect(),
    }))
}

/// A set whose manifest names an `origin` holds given input rows (one class): they are what
/// the regenerated set is built from (the class field dropped).
fn explicit_from(m: &Manifest, unit: Unit, contents: &[Vec<Vec<u64>>]) -> Result<Option<crate::gen::Explicit>, String> {
    let Some(origin) = &m.origin else { return Ok(None) };
    if unit != Unit::Slab || m.classes.len() != 1 {
        return Err("manifest.json: field origin: given input rows are a one-class slab set".into());
    }
    let rows = contents.first().ok_or("the set has no input file")?;
    Ok(Some(crate::gen::Explicit {
        class: m.classes[0].name.clone(),
        covers: m.classes[0].covers.clone(),
        origin: origin.clone(),
        rows: rows.iter().map(|r| r.iter().skip(1).copied().collect()).collect(),
    }))
}

/// The traverse set's tree from its root row and level banks, in the breadth-first order the
/// layout assigns pair indices in (so laying it out again gives the same banks).
fn tree_from_banks<F: Format>(f: &F, m: &Manifest, contents: &[Vec<Vec<u64>>]) -> Result<TreeInput, String> {
    let (root, banks) = crate::read::tree_images(m, contents)?;
    let levels = banks.len();
    let node = |row: &[u64]| -> Result<(NodeDesc, u32), String> {
        if row.len() < 7 {
            return Err("a tree row has fewer than 7 fields".into());
        }
        let v = |i: usize| f.to_f64(f.from_bits(row[i]));
        let addr = row[6] as u32;
        let leaf = addr & LEAF_FLAG != 0;
        let d = NodeDesc {
            children: None,
            leaf: if leaf { addr & !LEAF_FLAG } else { 0 },
            min: [v(0), v(1), v(2)],
            max: [v(3), v(4), v(5)],
        };
        Ok((d, if leaf { u32::MAX } else { addr }))
    };
    let (root_node, root_pair) = node(root)?;
    let mut nodes = vec![root_node];
    // (node index, level, pair index) of inner nodes whose children are still to be placed
    let mut frontier = Vec::new();
    if root_pair != u32::MAX {
        frontier.push((0usize, 0usize, 0usize));
    }
    while let Some(&(at, level, pair)) = frontier.first() {
        frontier.remove(0);
        let bad = |why: String| format!("malformed tree images: {why}");
        let (left, right) = banks.get(level).ok_or_else(|| {
            bad(format!("an address of level {} points below the set's {levels} levels", level.wrapping_sub(1)))
        })?;
        let mut kids = [0u32; 2];
        for (side, bank) in [left, right].into_iter().enumerate() {
            let row = bank.get(pair).ok_or_else(|| {
                bad(format!(
                    "an address word of level {} points to pair {pair}, level {level} has {} rows",
                    level.wrapping_sub(1),
                    bank.len()
                ))
            })?;
            let (d, next) = node(row)?;
            kids[side] = nodes.len() as u32;
            if next != u32::MAX {
                frontier.push((nodes.len(), level + 1, next as usize));
            }
            nodes.push(d);
        }
        nodes[at].children = Some(kids);
    }
    let scene = m.options.get("scene").cloned().unwrap_or_default();
    Ok(TreeInput { name: scene, nodes, root: 0 })
}

/// Field-by-field comparison of the set's manifest with the regenerated one (every field but
/// the generator's version, commit and the data hashes, rows and counts, which the data check covers).
fn compare_manifests(m: &Manifest, want: &Manifest) -> Result<(), String> {
    let diff = |field: &str, got: String, exp: String| -> Result<(), String> {
        if got == exp {
            Ok(())
        } else {
            Err(format!("manifest.json: field {field} is {got}, this raypipe writes {exp} for this set"))
        }
    };
    let j = |v: &dyn Json| v.json();
    // another unit's manifest over these files shows first as other file names
    if names(&m.files) != names(&want.files) {
        return Err(format!(
            "manifest.json: field files lists {}, but unit {} (field unit) writes {}",
            j(&names(&m.files)),
            m.unit,
            j(&names(&want.files))
        ));
    }
    diff("unit", j(&m.unit), j(&want.unit))?;
    diff("format", j(&m.format), j(&want.format))?;
    diff("level", j(&m.level), j(&want.level))?;
    diff("count", j(&m.count), j(&want.count))?;
    for (k, v) in &want.contract {
        diff(&format!("contract.{k}"), j(&m.contract.get(k)), j(&Some(v)))?;
    }
    diff("contract", j(&m.contract.keys().collect::<Vec<_>>()), j(&want.contract.keys().collect::<Vec<_>>()))?;
    for (k, v) in &want.options {
        diff(&format!("options.{k}"), j(&m.options.get(k)), j(&Some(v)))?;
    }
    diff("options", j(&m.options.keys().collect::<Vec<_>>()), j(&want.options.keys().collect::<Vec<_>>()))?;
    for (k, v) in &want.params {
        diff(&format!("params.{k}"), j(&m.params.get(k)), j(&Some(v)))?;
    }
    diff("params", j(&m.params.keys().collect::<Vec<_>>()), j(&want.params.keys().collect::<Vec<_>>()))?;
    diff("latency", j(&m.latency), j(&want.latency))?;
    for (i, s) in want.stages.iter().enumerate() {
        diff(&format!("stages[{i}]"), j(&m.stages.get(i)), j(&Some(s)))?;
    }
    diff("stages (length)", j(&m.stages.len()), j(&want.stages.len()))?;
    diff("acceptable_values", j(&m.acceptable_values), j(&want.acceptable_values))?;
    diff("files (names)", j(&names(&m.files)), j(&names(&want.files)))?;
    for (i, (a, b)) in m.files.iter().zip(&want.files).enumerate() {
        diff(&format!("files[{i}].role"), j(&a.role), j(&b.role))?;
        diff(&format!("files[{i}].width"), j(&a.width), j(&b.width))?;
        diff(&format!("files[{i}].digits"), j(&a.digits), j(&b.digits))?;
        for (k, fb) in b.fields.iter().enumerate() {
            diff(&format!("files[{i}].fields[{k}]"), j(&a.fields.get(k)), j(&Some(fb)))?;
        }
        diff(&format!("files[{i}].fields (length)"), j(&a.fields.len()), j(&b.fields.len()))?;
    }
    diff("classes (length)", j(&m.classes.len()), j(&want.classes.len()))?;
    for (i, (a, b)) in m.classes.iter().zip(&want.classes).enumerate() {
        diff(&format!("classes[{i}].id"), j(&a.id), j(&b.id))?;
        diff(&format!("classes[{i}].name"), j(&a.name), j(&b.name))?;
        diff(&format!("classes[{i}].covers"), j(&a.covers), j(&b.covers))?;
    }
    Ok(())
}

fn names(files: &[crate::manifest::File]) -> Vec<&str> {
    files.iter().map(|f| f.name.as_str()).collect()
}

/// Anything serde can print, for the comparison's messages.
trait Json {
    fn json(&self) -> String;
}

impl<T: serde::Serialize> Json for T {
    fn json(&self) -> String {
        serde_json::to_string(self).unwrap_or_else(|e| format!("<{e}>"))
    }
}
