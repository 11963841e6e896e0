//! `raypipe cover`: the functional coverage of vector sets — every input, expected output and
//! stage signal's bins (value classes, flags, classes), merged over the sets given, with the
//! holes listed (docs/coverage.md).

use super::prelude::*;

/// The options of `raypipe cover`.
#[derive(clap::Args, Clone)]
pub struct Args {
    /// Vector set directories or coverage files (`--cover` of ops, verify, stress); the counts of
    /// one unit, format and options are added, each such model reported on its own.
    #[arg(required = true)]
    pub sets: Vec<PathBuf>,
    /// Fail (exit 1) when fewer than this percentage of the bins are hit.
    #[arg(long)]
    pub fail_under: Option<f64>,
    /// List at most this many empty bins (0: all).
    #[arg(long, default_value_t = 20)]
    pub holes: usize,
    /// Also write the coverage as UCIS 1.0 XML to FILE (read by pyucis and coverage tools).
    #[arg(long)]
    pub ucis: Option<PathBuf>,
    /// Also write the coverage as one HTML page to FILE (per stage, bins hit / reachable; the
    /// holes listed).
    #[arg(long)]
    pub html: Option<PathBuf>,
    /// Print the coverage as JSON (every coverpoint and bin count).
    #[arg(long)]
    pub json: bool,
}

/// Runs `raypipe cover`.
pub fn run(a: Args) -> Result<Outcome, String> {
    if let Some(p) = a.fail_under {
        if !(0.0..=100.0).contains(&p) {
            return Err(format!("--fail-under must be a percentage in 0..=100, got {p}"));
        }
    }
    if let Some(u) = &a.ucis {
        // before the work: a file raypipe did not write is never replaced
        check_written_path("--ucis", u, "writtenBy=\"raypipe ")?;
    }
    if let Some(h) = &a.html {
        check_written_path("--html", h, vectors::cover_html::GENERATOR)?;
        if a.ucis.as_ref() == Some(h) {
            return Err("--html and --ucis name the same file".into());
        }
    }
    // every input's models, merged by model (unit, format, options) in the order first met
    let mut models: Vec<vectors::cover::Coverage> = Vec::new();
    for dir in &a.sets {
        // a coverage file (`--cover` of ops, verify, stress), or a vector set's directory
        let found = if !dir.exists() {
            return Err(format!("{}: no such coverage file or vector set", dir.display()));
        } else if dir.is_file() {
            let text = std::fs::read_to_string(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
            vectors::cover_file::read(&text)
                .map_err(|e| format!("{}: {e}", dir.display()))?
                .into_iter()
                .map(|x| x.1)
                .collect()
        } else {
            let path = dir.join("manifest.json");
            let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
            let m: vectors::manifest::Manifest =
                serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))?;
            vec![vectors::cover::Coverage::measure_dir(dir, &m).map_err(|e| format!("{}: {e}", dir.display()))?]
        };
        for c in found {
            match models.iter_mut().find(|t| t.same_model(&c)) {
                Some(t) => t.merge(&c).map_err(|e| format!("{}: {e}", dir.display()))?,
                None => models.push(c),
            }
        }
    }
    for c in &models {
        let contradictions = c.contradictions();
        if !contradictions.is_empty() {
            return Err(format!(
                "{}: a bin marked unreachable was hit (the coverage model is wrong): {}",
                c.title(),
                contradictions.join("; ")
            ));
        }
    }
    let now = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_secs());
    if let Some(u) = &a.ucis {
        let x = vectors::cover::ucis_xml_all(&models, &vectors::cover::utc(now), &command_as_typed());
        vectors::outdir::atomic_write(u, x.as_bytes())?;
    }
    // the stimulus classes that reach each bin, for the models with holes (the traverse unit's
    // default set needs its tree: no classes named there)
    let reach: Vec<Option<vectors::cover_reach::ReachMap>> = models
        .iter()
        .map(|c| {
            let (hit, bins) = c.totals();
            if hit < bins {
                vectors::cover_reach::reach(c).ok()
            } else {
                None
            }
        })
        .collect();
    if let Some(h) = &a.html {
        let page = vectors::cover_html::page_all(&models, &reach, &command_as_typed(), &vectors::cover::utc(now));
        vectors::outdir::atomic_write(h, page.as_bytes())?;
    }
    let reports: Vec<Report> = models.iter().zip(&reach).map(|(c, r)| Report::of(c, r.as_ref())).collect();
    let (hit, bins) = reports.iter().fold((0, 0), |(h, b), r| (h + r.hit, b + r.bins));
    let pct = percent(hit, bins);
    let mut j = serde_json::json!({
        "command": command_as_typed(),
        "sets": a.sets.iter().map(|d| d.display().to_string()).collect::<Vec<_>>(),
        "bins_hit": hit,
        "bins": bins,
        "percent": pct,
        "models": reports.iter().map(|r| r.json(r.cov)).collect::<Vec<_>>(),
    });
    if let [r] = &reports[..] {
        // one model: its fields at the top level too
        for (k, v) in r.json(r.cov).as_object().expect("an object") {
            j[k] = v.clone();
        }
    }
    emit(a.json, &j, |_| {
        let mut s = String::new();
        for r in &reports {
            s += &r.text(a.sets.len(), a.holes);
        }
        if reports.len() > 1 {
            s += &format!("{} models: {hit} of {bins} reachable bins hit ({pct:.1} %)\n", reports.len());
        }
        s
    })?;
    let under: Vec<String> = match a.fail_under {
        Some(p) => reports.iter().filter(|r| r.pct < p).map(|r| format!("{} {:.1} %", r.cov.title(), r.pct)).collect(),
        None => Vec::new(),
    };
    Ok(if under.is_empty() {
        Outcome::Pass
    } else {
        eprintln!("coverage under --fail-under {}: {}", a.fail_under.unwrap_or(0.0), under.join(", "));
        Outcome::Fail
    })
}

fn percent(hit: u64, bins: u64) -> f64 {
    if bins == 0 {
        0.0
    } else {
        100.0 * hit as f64 / bins as f64
    }
}

/// One model's numbers and holes.
struct Report<'a> {
    cov: &'a vectors::cover::Coverage,
    hit: u64,
    bins: u64,
    pct: f64,
    unreachable: usize,
    holes: Vec<String>,
    /// Per hole: the default classes that reach it, or the closure.
    stimulus: Vec<String>,
}

impl<'a> Report<'a> {
    fn of(c: &'a vectors::cover::Coverage, reach: Option<&vectors::cover_reach::ReachMap>) -> Self {
        let (hit, bins) = c.totals();
        let (holes, stimulus) = c
            .coverpoints
            .iter()
            .flat_map(|p| {
                p.bins.iter().filter(|b| b.count == 0 && b.unreachable.is_none()).map(move |b| {
                    let stage = p.stage.map_or(String::new(), |s| format!(" (stage {s})"));
                    let hint = match reach {
                        Some(r) => vectors::cover_reach::hint(r, &p.role, &p.signal, &b.name),
                        None => "vectors --close".into(),
                    };
                    (format!("{} {}{stage}: {}", p.role, p.signal, b.name), hint)
                })
            })
            .unzip();
        Report {
            cov: c,
            hit,
            bins,
            pct: percent(hit, bins),
            unreachable: c.coverpoints.iter().flat_map(|p| &p.bins).filter(|b| b.unreachable.is_some()).count(),
            holes,
            stimulus,
        }
    }

    fn json(&self, c: &vectors::cover::Coverage) -> serde_json::Value {
        serde_json::json!({
            "unit": c.unit,
            "format": c.format,
            "variant": c.options.get("variant"),
            "vectors": c.vectors,
            "bins_hit": self.hit,
            "bins": self.bins,
            "bins_unreachable": self.unreachable,
            "percent": self.pct,
            "holes": self.holes,
            "hole_stimulus": self.stimulus,
            "coverpoints": c.coverpoints,
        })
    }

    fn text(&self, inputs: usize, show: usize) -> String {
        let c = self.cov;
        let variant = c.options.get("variant").map_or(String::new(), |v| format!(", variant {v}"));
        let mut s = format!(
            "coverage of {inputs} set(s), unit {}, format {}{variant}: {} vectors; {} of {} reachable bins hit ({:.1} %); {} bins unreachable (reasons in --json)\n",
            c.unit, c.format, c.vectors, self.hit, self.bins, self.pct, self.unreachable
        );
        let mut last = String::new();
        for p in &c.coverpoints {
            if p.role != last {
                s += &format!("  {}:\n", p.role);
                last = p.role.clone();
            }
            // hit / reachable (the unreachable bins, if any, named after)
            let h = p.bins.iter().filter(|b| b.count > 0).count();
            let reachable = p.bins.iter().filter(|b| b.unreachable.is_none()).count();
            let unreachable = p.bins.len() - reachable;
            let stage = p.stage.map_or(String::new(), |x| format!(" [{x}]"));
            let note = if unreachable > 0 { format!(" (+{unreachable} unreachable)") } else { String::new() };
            s += &format!("    {}{stage} ({}): {h}/{reachable}{note}\n", p.signal, p.kind);
        }
        let shown = if show == 0 { self.holes.len() } else { show.min(self.holes.len()) };
        if !self.holes.is_empty() {
            s += &format!("empty bins ({} of {} shown):\n", shown, self.holes.len());
            for (h, st) in self.holes[..shown].iter().zip(&self.stimulus) {
                s += &format!("  {h}  [{st}]\n");
            }
        }
        s
    }
}
