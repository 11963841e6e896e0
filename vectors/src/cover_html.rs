//! The coverage as one self-contained HTML page (`raypipe cover --html`): per file role and
//! stage, each coverpoint's bins hit of its reachable bins as a bar, every bin as a cell (hit
//! with its count, empty, or unreachable with its reason as the cell's title), and the holes
//! listed first with the stimulus classes that reach them (or the command that closes them),
//! and the bins hit of the reachable ones per stage.

use crate::cover::Coverage;
use crate::cover_reach::{hint, ReachMap};

/// The marker line that says raypipe wrote a page (an existing file without it is never
/// replaced).
pub const GENERATOR: &str = "<meta name=\"generator\" content=\"raypipe cover\">";

fn esc(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// The page for coverage `c`, measured by `command` at `written` (UTC).
pub fn page(c: &Coverage, command: &str, written: &str) -> String {
    page_all(std::slice::from_ref(c), &[None], command, written)
}

/// One page for the coverage of several models (a `verify` or `stress` run's), one section per
/// model as [`page`] draws it; `reach[k]` (when given) names the classes that reach model k's
/// holes ([`crate::cover_reach`]).
pub fn page_all(covs: &[Coverage], reach: &[Option<ReachMap>], command: &str, written: &str) -> String {
    let mut s = format!("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n{GENERATOR}\n<meta charset=\"utf-8\">\n");
    let titles: Vec<String> = covs.iter().map(|c| c.title()).collect();
    s += &format!("<title>raypipe coverage: {}</title>\n", esc(&titles.join(", ")));
    s += "<style>\nbody{font:14px sans-serif;margin:1.5em}table{border-collapse:collapse;margin:.5em 0 1.5em}\
td,th{border:1px solid #ccc;padding:2px 6px;vertical-align:top}th{background:#eee;text-align:left}\
.bar{width:120px;height:10px;background:#f3c0c0;display:inline-block}.bar i{display:block;height:10px;background:#5a5}\
.b{display:inline-block;margin:1px;padding:0 4px;border-radius:3px;font-size:12px}.hit{background:#cfc}\
.hole{background:#f99;font-weight:bold}.un{background:#ddd;color:#777}\n</style>\n</head>\n<body>\n";
    for (k, c) in covs.iter().enumerate() {
        s += &section(c, reach.get(k).and_then(Option::as_ref), command, written);
    }
    s += "</body>\n</html>\n";
    s
}

/// One model's section: title, totals, holes, the coverpoints per file role.
fn section(c: &Coverage, reach: Option<&ReachMap>, command: &str, written: &str) -> String {
    let (hit, bins) = c.totals();
    let pct = if bins == 0 { 0.0 } else { 100.0 * hit as f64 / bins as f64 };
    let variant = c.options.get("variant").map_or(String::new(), |v| format!(", variant {}", esc(v)));
    let mut s = format!(
        "<h1>Coverage: unit {}, format {}{variant}</h1>\n<p>{} vectors; <b>{hit} of {bins} reachable bins hit ({pct:.1} %)</b>; {} bins unreachable (grey; the reason is the cell's title). Written {} UTC by <code>{}</code>.</p>\n",
        esc(&c.unit),
        esc(&c.format),
        c.vectors,
        c.coverpoints.iter().flat_map(|p| &p.bins).filter(|b| b.unreachable.is_some()).count(),
        esc(written),
        esc(command)
    );
    let holes: Vec<(String, String, String)> = c
        .coverpoints
        .iter()
        .flat_map(|p| {
            p.bins.iter().filter(|b| b.count == 0 && b.unreachable.is_none()).map(move |b| {
                let stage = p.stage.map_or(String::new(), |x| format!(" (stage {x})"));
                let stimulus = reach.map_or(String::new(), |r| hint(r, &p.role, &p.signal, &b.name));
                (format!("{} {}{stage}", p.role, p.signal), b.name.clone(), stimulus)
            })
        })
        .collect();
    if holes.is_empty() {
        s += "<h2>Holes</h2>\n<p>None: every reachable bin is hit.</p>\n";
    } else {
        s += &format!(
            "<h2>Holes ({})</h2>\n<p>Reachable bins no vector hit, each with the stimulus classes of the unit's default level-1 set that reach it (seed 1, {} per class). <code>raypipe vectors … --close</code> writes the set with a class <code>close</code> of directed vectors found for them (docs/coverage.md).</p>\n<table><tr><th>coverpoint</th><th>empty bin</th><th>reached by</th></tr>\n",
            holes.len(),
            crate::cover_reach::PER_CLASS
        );
        for (p, b, h) in &holes {
            s += &format!("<tr><td>{}</td><td>{}</td><td>{}</td></tr>\n", esc(p), esc(b), esc(h));
        }
        s += "</table>\n";
    }
    // per stage: bins hit of the reachable ones (inputs and events: no stage)
    let mut stages: std::collections::BTreeMap<Option<u8>, (usize, usize)> = Default::default();
    for p in &c.coverpoints {
        let e = stages.entry(p.stage).or_default();
        e.0 += p.bins.iter().filter(|b| b.unreachable.is_none() && b.count > 0).count();
        e.1 += p.bins.iter().filter(|b| b.unreachable.is_none()).count();
    }
    s += "<h2>Per stage</h2>\n<table><tr><th>stage</th><th>hit / reachable</th></tr>\n";
    for (st, (h, r)) in &stages {
        let w = if *r == 0 { 100.0 } else { 100.0 * *h as f64 / *r as f64 };
        s += &format!(
            "<tr><td>{}</td><td><span class=\"bar\"><i style=\"width:{w:.0}%\"></i></span> {h} / {r}</td></tr>\n",
            st.map_or("- (inputs, events)".into(), |x| x.to_string())
        );
    }
    s += "</table>\n";
    let mut role = String::new();
    for p in &c.coverpoints {
        if p.role != role {
            if !role.is_empty() {
                s += "</table>\n";
            }
            role = p.role.clone();
            s += &format!(
                "<h2>{}</h2>\n<table><tr><th>stage</th><th>coverpoint</th><th>kind</th><th>hit / reachable</th><th>bins</th></tr>\n",
                esc(&role)
            );
        }
        let reach = p.bins.iter().filter(|b| b.unreachable.is_none()).count();
        let h = p.bins.iter().filter(|b| b.unreachable.is_none() && b.count > 0).count();
        let w = if reach == 0 { 100.0 } else { 100.0 * h as f64 / reach as f64 };
        let cells: String = p
            .bins
            .iter()
            .map(|b| match (b.unreachable, b.count) {
                (Some(why), _) => format!("<span class=\"b un\" title=\"{}\">{}</span>", esc(why), esc(&b.name)),
                (None, 0) => format!("<span class=\"b hole\">{}</span>", esc(&b.name)),
                (None, n) => format!("<span class=\"b hit\" title=\"{n} hits\">{} {n}</span>", esc(&b.name)),
            })
            .collect();
        s += &format!(
            "<tr><td>{}</td><td>{}</td><td>{}</td><td><span class=\"bar\"><i style=\"width:{w:.0}%\"></i></span> {h} / {reach}</td><td>{cells}</td></tr>\n",
            p.stage.map_or("-".into(), |x| x.to_string()),
            esc(&p.signal),
            esc(&p.kind)
        );
    }
    if !role.is_empty() {
        s += "</table>\n";
    }
    s
}
