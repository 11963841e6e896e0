//! Which stimulus classes reach a bin: the default level-1 set of a coverage model's unit,
//! format and options (seed 1, [`PER_CLASS`] vectors per class), measured row by row with each
//! row's class, so that the holes of any set, run or live recording can be listed with the
//! classes that reach them (`raypipe cover`, text, JSON and HTML). A hole no default class
//! reaches is one for the closure (`raypipe vectors … --close`).

use crate::cover::{Coverage, RowBins};
use crate::gen::{generate, Request, Unit};
use crate::read::set_rows;
use std::collections::BTreeMap;

/// Vectors per class of the default set measured (`raypipe vectors`'s default count).
pub const PER_CLASS: usize = 64;

/// (file role, coverpoint signal, bin name) → the names of the classes whose rows reach it,
/// in class order.
pub type ReachMap = BTreeMap<(String, String, String), Vec<String>>;

/// The classes of the default level-1 set of `c`'s unit, format and options that reach each
/// of its bins. The traverse unit's default set needs its tree (not in a coverage model): an
/// error.
pub fn reach(c: &Coverage) -> Result<ReachMap, String> {
    let unit: Unit = c.unit.parse()?;
    if unit == Unit::Traverse {
        return Err("the traverse unit's default set needs the scene's tree".into());
    }
    let format = c.format.parse().map_err(|e| format!("format {}: {e}", c.format))?;
    let mut req = Request::new(unit, format);
    req.count = PER_CLASS;
    req.command = "raypipe cover (the classes that reach each bin)".into();
    if matches!(unit, Unit::Rti | Unit::Capture) {
        req.rti = crate::check::rti_from_options(&c.options)?;
    }
    if let Some(v) = c.options.get("variant") {
        req.slab_variant = v.clone();
    }
    let set = generate(&req)?;
    let m = &set.manifest;
    let rows = set_rows(&set)?;
    let model = Coverage::model(m);
    let bins = RowBins::new(m).with_set(&rows)?;
    let mut hits = Vec::new();
    let mut out = ReachMap::new();
    for row in 0..rows.first().map_or(0, |r| r.len()) {
        let class = rows[0][row].first().and_then(|&k| m.classes.get(k as usize)).map_or("?", |c| c.name.as_str());
        hits.clear();
        bins.hits(&rows, row, &mut hits)?;
        for &(p, b) in &hits {
            let (cp, bin) = (&model.coverpoints[p], &model.coverpoints[p].bins[b]);
            if cp.kind == "class" {
                continue;
            }
            let names = out.entry((cp.role.clone(), cp.signal.clone(), bin.name.clone())).or_default();
            if !names.iter().any(|n| n == class) {
                names.push(class.to_string());
            }
        }
    }
    Ok(out)
}

/// The words for a hole's stimulus: the classes that reach it, or the closure.
pub fn hint(map: &ReachMap, role: &str, signal: &str, bin: &str) -> String {
    match map.get(&(role.to_string(), signal.to_string(), bin.to_string())) {
        Some(c) if !c.is_empty() => {
            let shown: Vec<&str> = c.iter().take(4).map(String::as_str).collect();
            let more = if c.len() > 4 { format!(" (+{} more)", c.len() - 4) } else { String::new() };
            format!("class {}{more}", shown.join(", "))
        }
        _ => "no default class: vectors --close".into(),
    }
}
