//! `raypipe cover`: the functional coverage of vector sets — every input, expected output and
//! stage signal's bins (value classes, flags, classes), merged over the sets given, with the
//! holes listed (docs/coverage.md).

use super::prelude::*;

/// The options of `raypipe cover`.
#[derive(clap::Args, Clone)]
pub struct Args {
    /// Vector set directories or coverage files (`ops --cover`) of one unit, format and options
    /// (their counts are added).
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
    let mut total: Option<vectors::cover::Coverage> = None;
    for dir in &a.sets {
        // a coverage file (`ops --cover`), or a vector set's directory
        let c = if dir.is_file() {
            let text = std::fs::read_to_string(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
            vectors::cover_file::read(&text).map_err(|e| format!("{}: {e}", dir.display()))?.1
        } else {
            let path = dir.join("manifest.json");
            let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
            let m: vectors::manifest::Manifest =
                serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))?;
            vectors::cover::Coverage::measure_dir(dir, &m).map_err(|e| format!("{}: {e}", dir.display()))?
        };
        match &mut total {
            None => total = Some(c),
            Some(t) => t.merge(&c).map_err(|e| format!("{}: {e}", dir.display()))?,
        }
    }
    let c = total.expect("at least one set");
    let (hit, bins) = c.totals();
    let pct = if bins == 0 { 0.0 } else { 100.0 * hit as f64 / bins as f64 };
    let holes: Vec<String> = c
        .coverpoints
        .iter()
        .flat_map(|p| {
            p.bins.iter().filter(|b| b.count == 0 && b.unreachable.is_none()).map(move |b| {
                let stage = p.stage.map_or(String::new(), |s| format!(" (stage {s})"));
                format!("{} {}{stage}: {}", p.role, p.signal, b.name)
            })
        })
        .collect();
    let contradictions = c.contradictions();
    if !contradictions.is_empty() {
        return Err(format!(
            "a bin marked unreachable was hit (the coverage model is wrong): {}",
            contradictions.join("; ")
        ));
    }
    let now = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_secs());
    if let Some(u) = &a.ucis {
        vectors::outdir::atomic_write(u, c.ucis_xml(&vectors::cover::utc(now), &command_as_typed()).as_bytes())?;
    }
    if let Some(h) = &a.html {
        let page = vectors::cover_html::page(&c, &command_as_typed(), &vectors::cover::utc(now));
        vectors::outdir::atomic_write(h, page.as_bytes())?;
    }
    let unreachable = c.coverpoints.iter().flat_map(|p| &p.bins).filter(|b| b.unreachable.is_some()).count();
    let j = serde_json::json!({
        "command": command_as_typed(),
        "sets": a.sets.iter().map(|d| d.display().to_string()).collect::<Vec<_>>(),
        "unit": c.unit,
        "format": c.format,
        "vectors": c.vectors,
        "bins_hit": hit,
        "bins": bins,
        "bins_unreachable": unreachable,
        "percent": pct,
        "holes": holes,
        "coverpoints": c.coverpoints,
    });
    emit(a.json, &j, |_| {
        let mut s = format!(
            "coverage of {} set(s), unit {}, format {}: {} vectors; {hit} of {bins} reachable bins hit ({pct:.1} %); {unreachable} bins unreachable (reasons in --json)\n",
            a.sets.len(),
            c.unit,
            c.format,
            c.vectors
        );
        let mut last = String::new();
        for p in &c.coverpoints {
            if p.role != last {
                s += &format!("  {}:\n", p.role);
                last = p.role.clone();
            }
            let h = p.bins.iter().filter(|b| b.count > 0).count();
            let stage = p.stage.map_or(String::new(), |x| format!(" [{x}]"));
            s += &format!("    {}{stage} ({}): {h}/{}\n", p.signal, p.kind, p.bins.len());
        }
        let shown = if a.holes == 0 { holes.len() } else { a.holes.min(holes.len()) };
        if !holes.is_empty() {
            s += &format!("empty bins ({} of {} shown):\n", shown, holes.len());
            for h in &holes[..shown] {
                s += &format!("  {h}\n");
            }
        }
        s
    })?;
    Ok(match a.fail_under {
        Some(p) if pct < p => {
            eprintln!("coverage {pct:.1} % is under --fail-under {p}");
            Outcome::Fail
        }
        _ => Outcome::Pass,
    })
}
