//! The event counts the throughput model runs on, from real traversals of a scene at one leaf
//! size: per leaf its triangles and the rays that test it (the leaf node intersection sets the
//! RTI accelerator is fed), per ray its traversal passes, and the tree's BRAM entries.
//!
//! A ray's work is [`crate::bvh::SceneBvh::nearest_work`]: the leaves it reaches in traversal
//! order up to the one holding its nearest hit (all of them when it hits nothing), as in the
//! thesis's experiments (figures 3-1 and 3-2, `raypipe stats`).

use crate::bvh::SceneBvh;
use crate::scene::Scene;
use golden::Ray64;
use serde::Serialize;

/// The events of `rays` rays on one tree.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SceneEvents {
    /// Triangles per leaf at most (the build parameter).
    pub leaf_size: u32,
    /// Tree levels below the root.
    pub depth: usize,
    /// Rays traced.
    pub rays: u64,
    /// Rays with a hit.
    pub rays_hit: u64,
    /// Triangles of each leaf, by leaf id.
    pub leaf_tris: Vec<u32>,
    /// Rays that test each leaf, by leaf id.
    pub leaf_rays: Vec<u64>,
    /// Traversal passes summed over the rays: restarts + 1 per ray, and 1 for a ray whose root
    /// test misses (it still takes its slot in the first level pipeline).
    pub passes: u64,
    /// Box entries the traversal core stores in BRAM: the root and both children of every
    /// inner node.
    pub bram_boxes: u64,
}

impl SceneEvents {
    /// RTI tests the rays need: every ray against every triangle of every leaf it tests.
    pub fn rti_tests(&self) -> u64 {
        self.leaf_tris.iter().zip(&self.leaf_rays).map(|(&t, &r)| t as u64 * r).sum()
    }

    /// Mean traversal passes per ray.
    pub fn passes_per_ray(&self) -> f64 {
        self.passes as f64 / self.rays.max(1) as f64
    }
}

/// One chunk's share: rays hit, passes, and rays per leaf.
#[derive(Default)]
struct EventsAcc {
    c: engine::Counts<2>,
    leaf_rays: engine::Tally,
}

impl engine::Merge for EventsAcc {
    fn merge(&mut self, o: Self) {
        self.c.merge(o.c);
        self.leaf_rays.merge(o.leaf_rays);
    }
}

/// The events of rays `ray(0..rays)` on `b` (laid out for at most 256 levels), on the engine:
/// identical for any thread count and chunk size.
pub fn gather(
    eng: &engine::Engine,
    scene: &Scene,
    b: &SceneBvh,
    leaf_size: u32,
    rays: u64,
    ray: impl Fn(u64) -> Ray64 + Sync,
) -> Result<SceneEvents, String> {
    use engine::Merge as _;
    let hw = b.layout_ids(256)?;
    let bar = engine::Progress::new(rays, "rays", true);
    let acc = engine::run(
        eng,
        rays,
        &bar,
        || (),
        |_, range| {
            let mut acc = EventsAcc::default();
            for k in range {
                let w = b.nearest_work(&hw, scene, &ray(k));
                acc.c.0[0] += w.hit as u64;
                acc.c.0[1] += w.history.passes.max(1);
                for &leaf in &w.leaves {
                    acc.leaf_rays.add(leaf as usize, 1);
                }
            }
            acc
        },
    );
    let mut leaf_rays = engine::Tally(vec![0; b.leaf_tris.len()]);
    leaf_rays.merge(acc.leaf_rays);
    Ok(SceneEvents {
        leaf_size,
        depth: b.depth,
        rays,
        rays_hit: acc.c.0[0],
        leaf_tris: b.leaf_tris.iter().map(|t| t.len() as u32).collect(),
        leaf_rays: leaf_rays.0,
        passes: acc.c.0[1],
        bram_boxes: b.bram_boxes(),
    })
}
