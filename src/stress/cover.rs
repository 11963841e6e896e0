//! `stress --cover FILE`: the functional coverage of the stress suite's cases — per format the
//! RTI unit's model and one slab model per variant run — counted in a pass of its own over the
//! engine's shard of the cases (`crate::cover_run`), so the suite's report is the same with or
//! without it.
//!
//! The class bins are the stress classes (`RTI_STRESS`, `SLAB_STRESS`: a row's class is the
//! class of its case). RTI rows: each candidate triangle of a case, the ray and triangle as the
//! format rounds them. Slab rows: the case's ray encodings and its box as the slab unit stores
//! it (a case whose box cannot be stored is not a test and is not counted). The `directed` slab
//! variant has no coverage model (its stage signals depend on the data) and is not counted.

use super::{case_rng, rti_case, slab_case, StressConfig, RTI_STRESS, SLAB_STRESS};
use crate::cover_run::{CoverAcc, Rows};
use crate::scene::icosphere;
use datapath::rti::{Rti, RtiConfig};
use datapath::slab::{Slab, SlabConfig};
use datapath::{with_format, AnyFormat, Format};
use vectors::cover::{Coverage, RowBins};
use vectors::manifest::Manifest;

/// The coverage of every model of the suite over the engine's shard of the cases, in the
/// suite's order: per format, RTI, then the variants the format accepts.
pub fn cover(cfg: &StressConfig, command: &str) -> Result<Vec<(Manifest, Coverage)>, String> {
    let mut out = Vec::new();
    for f in &cfg.formats {
        out.push(with_format!(*f, |ff| cover_rti(ff, *f, cfg, command))?);
        for v in &cfg.variants {
            let named = SlabConfig::named(v)?;
            let Ok(sc) = with_format!(*f, |ff| named.for_format(v, &ff)) else { continue };
            if let Some(c) = with_format!(*f, |ff| cover_slab(ff, *f, sc, v, cfg, command))? {
                out.push(c);
            }
        }
    }
    Ok(out)
}

/// Runs `classes × count` cases of unit stream `unit` (1 RTI, 2 slab) as the suite does (item
/// j is case `j mod count` of class `j / count`) through `case`, which counts its rows.
fn run_cases(
    cfg: &StressConfig,
    unit: u64,
    classes: usize,
    what: String,
    case: impl Fn(usize, &mut datapath::rng::SplitMix64, &mut Rows, &mut CoverAcc) + Sync + Send,
) -> CoverAcc {
    let count = cfg.count as u64;
    let items = classes as u64 * count;
    let progress = engine::Progress::new(cfg.engine.shard_items(items), "cases (coverage)", !cfg.progress);
    progress.message(what);
    let acc = engine::run(&cfg.engine, items, &progress, Rows::default, |rows, range| {
        let mut acc = CoverAcc::new(1);
        for j in range {
            let class = (j / count) as usize;
            let mut r = case_rng(cfg.seed, unit, class, j % count);
            case(class, &mut r, rows, &mut acc);
        }
        acc
    });
    progress.finish();
    acc
}

fn classes(table: &[(&'static str, &'static str)], count: usize) -> Vec<(&'static str, &'static str, usize)> {
    table.iter().map(|&(n, c)| (n, c, count)).collect()
}

fn cover_rti<F: Format>(
    f: F,
    any: AnyFormat,
    cfg: &StressConfig,
    command: &str,
) -> Result<(Manifest, Coverage), String> {
    let rti = Rti::new(f, RtiConfig::default());
    let run = crate::cover_run::rti_model(any, RtiConfig::default(), &classes(&RTI_STRESS, cfg.count), command)?;
    let sphere = icosphere([0.0; 3], 1.0, 2);
    let em = f.error_model();
    let min_normal = match f.kind() {
        datapath::format::FormatKind::Float(l) => l.min_normal(),
        datapath::format::FormatKind::Fixed { .. } => em.eta,
    };
    let bins = RowBins::new(&run.manifest);
    let acc = run_cases(cfg, 1, RTI_STRESS.len(), format!("rti {} coverage", f.name()), |class, r, rows, acc| {
        let case = rti_case(class, r, &sphere, min_normal, em.max);
        let mray = rti.ray(case.ray.o, case.ray.d, case.ray.tmin, case.ray.tmax);
        for t in &case.tris {
            rows.rti((&run, &bins), &rti, class as u64, &mray, &rti.tri(t.v), &mut acc.0[0]);
        }
    });
    Ok(crate::cover_run::finish(std::slice::from_ref(&run), acc).remove(0))
}

fn cover_slab<F: Format>(
    f: F,
    any: AnyFormat,
    sc: SlabConfig,
    variant: &str,
    cfg: &StressConfig,
    command: &str,
) -> Result<Option<(Manifest, Coverage)>, String> {
    let Ok(run) = crate::cover_run::slab_model(any, variant, &classes(&SLAB_STRESS, cfg.count), command) else {
        return Ok(None);
    };
    let s = Slab::new(f, sc);
    let edges = datapath::format::edges(&f);
    let q = |x: f64| f.to_f64(f.from_f64(x));
    let bins = RowBins::new(&run.manifest);
    let what = format!("slab {} {variant} coverage", f.name());
    let acc = run_cases(cfg, 2, SLAB_STRESS.len(), what, |class, r, rows, acc| {
        // as the suite: the box corners as the format holds them, stored
        let (x, lo, hi) = slab_case(class, r, edges);
        let Ok(b) = s.store_box(lo.map(q), hi.map(q)) else { return };
        rows.slab((&run, &bins), &s, class as u64, x.map(|v| f.from_f64(v)), &b, &mut acc.0[0]);
    });
    Ok(Some(crate::cover_run::finish(std::slice::from_ref(&run), acc).remove(0)))
}
