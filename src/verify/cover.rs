//! `verify --cover FILE`: the functional coverage of a verify run's tests — per format the RTI
//! unit's model and one slab model per variant the format accepts — counted in a pass of its
//! own over the engine's shard of the rays (`crate::cover_run`), so the run's report is the
//! same with or without it.
//!
//! The `directed` slab variant has no coverage model (its stage signals depend on the data, so
//! it has no vector set) and is not counted.
//!
//! Rows: class `scene` (the class bins of these models hold the one class); the RTI inputs are
//! the ray (origin, direction, tmin, tmax) and the triangle as the format rounds them (what the
//! run's model sees); the slab inputs are the same ray's encodings and the triangle's bounding
//! box as the slab unit stores it (rounded outward; an unstorable box: the empty-slot box), as
//! the run's slab pass tests it; outputs and stage signals are the fault-free model's (an
//! `--inject`ed fault does not change the coverage: it measures the stimulus).

use super::chunk::{test_list, tests_per_ray, tri_box};
use super::VerifyConfig;
use crate::cover_run::{CoverAcc, Rows};
use crate::scene::Scene;
use datapath::rti::Rti;
use datapath::slab::{Slab, SlabConfig};
use datapath::{with_format, Format};
use vectors::cover::{Coverage, RowBins};
use vectors::manifest::Manifest;

/// The class of every verify row.
const CLASS: (&str, &str) =
    ("scene", "the ray-triangle tests of raypipe verify on a scene (its rays, each against its test list)");

/// The coverage of every model of the run over the engine's shard of the rays, in the run's
/// order: per format, RTI, then the slab variants.
pub fn cover(cfg: &VerifyConfig, scene: &Scene, command: &str) -> Result<Vec<(Manifest, Coverage)>, String> {
    let mut out = Vec::new();
    for f in &cfg.formats {
        out.extend(with_format!(*f, |ff| cover_format(ff, *f, cfg, scene, command))?);
    }
    Ok(out)
}

fn cover_format<F: Format + 'static>(
    f: F,
    any: datapath::AnyFormat,
    cfg: &VerifyConfig,
    scene: &Scene,
    command: &str,
) -> Result<Vec<(Manifest, Coverage)>, String>
where
    F::V: 'static + Default + Send + Sync,
{
    let tests = (cfg.rays as usize).saturating_mul(tests_per_ray(scene, cfg.sample));
    let classes = [(CLASS.0, CLASS.1, tests)];
    let rti = Rti::new(f, cfg.rti);
    let mut models = vec![crate::cover_run::rti_model(any, cfg.rti, &classes, command)?];
    // every variant the run tests that has a coverage model (`directed`, whose signal set
    // depends on the data, has none: its rows are not a vector set's)
    let mut variants: Vec<(&str, Slab<F>)> = Vec::new();
    for name in SlabConfig::variants_for(&f) {
        if let Ok(m) = crate::cover_run::slab_model(any, name, &classes, command) {
            models.push(m);
            variants.push((name, Slab::new(f, SlabConfig::named(name).expect("built-in variant"))));
        }
    }
    let tris: Vec<_> = scene.tris.iter().map(|t| rti.tri(t.v)).collect();
    // box storage does not depend on the variant (as in the run's slab pass)
    let boxes: Vec<_> = match variants.first() {
        Some((_, s)) => scene
            .tris
            .iter()
            .map(|t| {
                let b = tri_box(&t.v);
                s.store_box([b[0], b[1], b[2]], [b[3], b[4], b[5]]).unwrap_or_else(|_| s.empty_box())
            })
            .collect(),
        None => Vec::new(),
    };
    let gen = scene.ray_gen(cfg.seed);
    let bins: Vec<RowBins> = models.iter().map(|m| RowBins::new(&m.manifest)).collect();
    let progress = engine::Progress::new(cfg.engine.shard_items(cfg.rays), "rays (coverage)", !cfg.progress);
    progress.message(format!("{} coverage", f.name()));
    let acc = engine::run(
        &cfg.engine,
        cfg.rays,
        &progress,
        || (Rows::default(), Vec::new()),
        |(rows, list), range| {
            let mut acc = CoverAcc::new(models.len());
            for i in range {
                let (ray, target) = gen.ray(scene, i);
                test_list(scene.tris.len(), cfg.sample, cfg.seed, i, target, list);
                let mray = rti.ray(ray.o, ray.d, ray.tmin, ray.tmax);
                let sray = [ray.o[0], ray.o[1], ray.o[2], ray.d[0], ray.d[1], ray.d[2], ray.tmin, ray.tmax]
                    .map(|x| f.from_f64(x));
                for &t in list.iter() {
                    rows.rti((&models[0], &bins[0]), &rti, 0, &mray, &tris[t as usize], &mut acc.0[0]);
                    for (k, (_, s)) in variants.iter().enumerate() {
                        rows.slab((&models[k + 1], &bins[k + 1]), s, 0, sray, &boxes[t as usize], &mut acc.0[k + 1]);
                    }
                }
            }
            acc
        },
    );
    progress.finish();
    Ok(crate::cover_run::finish(&models, acc))
}
