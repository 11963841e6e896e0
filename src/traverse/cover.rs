//! `traverse --cover FILE`: the functional coverage of a traverse run's rays — per format the
//! traverse unit's model (`vectors::cover`) on the run's BVH — counted in a pass of its own over
//! the engine's shard of the rays (`crate::cover_run`), so the run's report is the same with or
//! without it.
//!
//! Rows: class `scene`; the inputs are the ray (origin, direction, tmin, tmax) as the format
//! rounds it, the expected row is the 2-bit history traversal's with the run's slab variant as
//! the box tester, on the tree of the model's own BRAM images (the run's BVH, boxes stored as
//! the slab unit stores them), and the path events (back-traversal distances, ties) come from
//! the same ray re-run on that tree.

use super::{CameraRays, TraverseConfig};
use crate::cover_run::{CoverAcc, Rows};
use crate::scene::Scene;
use datapath::slab::{Slab, SlabConfig};
use datapath::{with_format, Format};
use vectors::cover::Coverage;
use vectors::manifest::Manifest;

/// The class of every traverse row.
const CLASS: (&str, &str) =
    ("scene", "the rays of raypipe traverse on a scene (half primary from a camera in front, half random)");

/// The coverage of the run's traverse model per format, over the engine's shard of the rays,
/// in the run's format order.
pub fn cover(cfg: &TraverseConfig, scene: &Scene, command: &str) -> Result<Vec<(Manifest, Coverage)>, String> {
    let b = crate::bvh::build(scene, cfg.leaf_size);
    let tree = vectors::traverse::TreeInput { name: scene.name.clone(), nodes: b.nodes, root: 0 };
    let gen = CameraRays::new(scene, cfg.rays, cfg.seed);
    let mut out = Vec::new();
    for f in &cfg.formats {
        out.push(with_format!(*f, |ff| cover_format(ff, *f, cfg, &tree, &gen, command))?);
    }
    Ok(out)
}

fn cover_format<F: Format>(
    f: F,
    any: datapath::AnyFormat,
    cfg: &TraverseConfig,
    tree: &vectors::traverse::TreeInput,
    gen: &CameraRays,
    command: &str,
) -> Result<(Manifest, Coverage), String> {
    let classes = [(CLASS.0, CLASS.1, cfg.rays)];
    let model =
        crate::cover_run::traverse_model(any, &cfg.variant, tree.clone(), (cfg.n, cfg.levels), &classes, command)?;
    let s = Slab::new(f, SlabConfig::named(&cfg.variant)?);
    // the tree the model's images hold (the rows' expected values and the replay agree on it)
    let (root, images) = model.tree_images()?;
    let banks: Vec<_> = images.into_iter().map(|(l, r)| (l.clone(), r.clone())).collect();
    let hw = vectors::traverse::tree_from_images(&s, root, &banks)?;
    let bins = model.row_bins()?;
    let progress = engine::Progress::new(cfg.engine.shard_items(cfg.rays as u64), "rays (coverage)", !cfg.progress);
    progress.message(format!("{} coverage", f.name()));
    let acc = engine::run(&cfg.engine, cfg.rays as u64, &progress, Rows::default, |rows, range| {
        let mut acc = CoverAcc::new(1);
        for k in range {
            let ray = gen.ray(k);
            let bits = [ray.o[0], ray.o[1], ray.o[2], ray.d[0], ray.d[1], ray.d[2], ray.tmin, ray.tmax]
                .map(|x| f.to_bits(f.from_f64(x)));
            rows.traverse((&model, &bins), &s, &hw, cfg.n, 0, &bits, &mut acc.0[0]);
        }
        acc
    });
    progress.finish();
    Ok(crate::cover_run::finish(std::slice::from_ref(&model), acc).remove(0))
}
