//! Scene → BVH: `obvhs` builds the binary tree (its topology only); the boxes are recomputed in
//! f64 from the scene's own triangles (a leaf's box is the exact bounds of its triangles, an
//! inner box the union of its children), so no f32 rounding of the builder can leave a triangle
//! outside its box. Depth is computed here (`obvhs`'s `max_depth` is only a stack-size hint).

use crate::scene::Scene;
use datapath::bvh::NodeDesc;
use glam::Vec3A;
use obvhs::bvh2::builder::build_bvh2_from_tris;
use obvhs::triangle::Triangle;
use obvhs::BvhBuildParams;
use std::time::Duration;

/// A scene's BVH before hardware layout.
#[derive(Clone, Debug)]
pub struct SceneBvh {
    /// Nodes; node 0 is the root.
    pub nodes: Vec<NodeDesc>,
    /// Triangles of each leaf, by leaf id.
    pub leaf_tris: Vec<Vec<u32>>,
    /// Levels below the root (0 for a single leaf).
    pub depth: usize,
}

impl SceneBvh {
    /// The same tree for the golden stack traversal.
    pub fn golden_tree(&self) -> golden::bvh::Tree {
        vectors::traverse::golden_tree(&self.nodes, 0)
    }

    /// The hardware layout for `levels` level pipelines, each entry naming its node (the box
    /// tester looks the stored box up by node index).
    pub fn layout_ids(&self, levels: usize) -> Result<datapath::bvh::HwTree<u32>, String> {
        datapath::bvh::HwTree::build(&self.nodes, 0, levels, |i, _| Ok::<u32, String>(i)).map_err(|e| e.to_string())
    }
}

/// The work a ray does in traversal order up to the leaf holding its nearest hit (every leaf
/// it reaches when it hits nothing): the thesis's experiments count this work.
#[derive(Clone, Debug)]
pub struct NearestWork {
    /// Leaves visited, in traversal order, up to and including the nearest hit's.
    pub leaves: Vec<u32>,
    /// A triangle was hit.
    pub hit: bool,
    /// The 2-bit history traversal of those leaves (passes, box tests, back distances).
    pub history: datapath::bvh::StacklessResult,
}

impl SceneBvh {
    /// The golden f64 slab test of `ray` against node `i`'s box: its entry distance on a hit.
    pub fn box_test<'a>(&'a self, ray: &'a golden::Ray64) -> impl Fn(u32) -> Option<f64> + 'a {
        move |i: u32| {
            let n = &self.nodes[i as usize];
            let r = golden::slab_f64(ray.o, ray.d, ray.tmin, ray.tmax, n.min, n.max);
            r.hit.then_some(r.t_near)
        }
    }

    /// Box entries the traversal core stores in BRAM: the root and both children of every
    /// inner node.
    pub fn bram_boxes(&self) -> u64 {
        1 + 2 * self.nodes.iter().filter(|n| n.children.is_some()).count() as u64
    }

    /// [`NearestWork`] of `ray`, boxes and triangles tested by the golden f64 tests.
    pub fn nearest_work(&self, hw: &datapath::bvh::HwTree<u32>, scene: &Scene, ray: &golden::Ray64) -> NearestWork {
        let test = self.box_test(ray);
        let all = datapath::bvh::history_traverse(hw, usize::MAX, |&i| test(i));
        // the nearest hit over every leaf reached, and the position of its leaf
        let mut best: Option<(usize, f64)> = None;
        for (k, &leaf) in all.leaves.iter().enumerate() {
            for &t in &self.leaf_tris[leaf as usize] {
                let r = golden::intersect(ray, &scene.tris[t as usize], golden::Faces::default());
                if r.hit && best.is_none_or(|(_, bt)| r.t < bt) {
                    best = Some((k, r.t));
                }
            }
        }
        let upto = best.map_or(all.leaves.len(), |(k, _)| k + 1);
        let history = datapath::bvh::history_traverse(hw, upto.max(1), |&i| test(i));
        let mut leaves = all.leaves;
        leaves.truncate(upto);
        NearestWork { leaves, hit: best.is_some(), history }
    }
}

fn bounds(tris: &[golden::Tri64], ids: &[u32]) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for &i in ids {
        for p in &tris[i as usize].v {
            for a in 0..3 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
    }
    (lo, hi)
}

/// Builds the BVH with at most `leaf_size` triangles per leaf (1..=255).
pub fn build(scene: &Scene, leaf_size: u32) -> SceneBvh {
    let tris: Vec<Triangle> = scene
        .tris
        .iter()
        .map(|t| {
            let v = |k: usize| Vec3A::new(t.v[k][0] as f32, t.v[k][1] as f32, t.v[k][2] as f32);
            Triangle { v0: v(0), v1: v(1), v2: v(2) }
        })
        .collect();
    let params = BvhBuildParams { max_prims_per_leaf: leaf_size.clamp(1, 255), ..BvhBuildParams::medium_build() };
    let bvh = build_bvh2_from_tris(&tris, params, &mut Duration::default());
    let mut nodes = Vec::with_capacity(bvh.nodes.len());
    let mut leaf_tris = Vec::new();
    // depth-first copy from obvhs's root (index 0), children at first_index and first_index + 1
    fn copy(
        bvh: &obvhs::bvh2::Bvh2,
        scene: &Scene,
        i: usize,
        nodes: &mut Vec<NodeDesc>,
        leaf_tris: &mut Vec<Vec<u32>>,
    ) -> (u32, usize) {
        let n = &bvh.nodes[i];
        let me = nodes.len() as u32;
        nodes.push(NodeDesc { children: None, leaf: 0, min: [0.0; 3], max: [0.0; 3] });
        if n.prim_count > 0 {
            let first = n.first_index as usize;
            let ids: Vec<u32> = bvh.primitive_indices[first..first + n.prim_count as usize].to_vec();
            let (min, max) = bounds(&scene.tris, &ids);
            nodes[me as usize] = NodeDesc { children: None, leaf: leaf_tris.len() as u32, min, max };
            leaf_tris.push(ids);
            return (me, 0);
        }
        let (l, dl) = copy(bvh, scene, n.first_index as usize, nodes, leaf_tris);
        let (r, dr) = copy(bvh, scene, n.first_index as usize + 1, nodes, leaf_tris);
        let (a, b) = (nodes[l as usize], nodes[r as usize]);
        nodes[me as usize] = NodeDesc {
            children: Some([l, r]),
            leaf: 0,
            min: std::array::from_fn(|k| a.min[k].min(b.min[k])),
            max: std::array::from_fn(|k| a.max[k].max(b.max[k])),
        };
        (me, 1 + dl.max(dr))
    }
    let (_, depth) = copy(&bvh, scene, 0, &mut nodes, &mut leaf_tris);
    SceneBvh { nodes, leaf_tris, depth }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_triangle_is_in_exactly_one_leaf_and_inside_its_boxes() {
        let scene = Scene::builtin();
        for leaf_size in [1, 4, 8] {
            let b = build(&scene, leaf_size);
            let mut seen = vec![0; scene.tris.len()];
            for (leaf, ids) in b.leaf_tris.iter().enumerate() {
                assert!(!ids.is_empty() && ids.len() <= leaf_size as usize);
                let node = b.nodes.iter().find(|n| n.children.is_none() && n.leaf == leaf as u32).unwrap();
                for &t in ids {
                    seen[t as usize] += 1;
                    for p in &scene.tris[t as usize].v {
                        assert!((0..3).all(|a| node.min[a] <= p[a] && p[a] <= node.max[a]));
                    }
                }
            }
            assert!(seen.iter().all(|&c| c == 1));
            // inner boxes contain their children
            for n in &b.nodes {
                if let Some(c) = n.children {
                    for ch in c {
                        let ch = &b.nodes[ch as usize];
                        assert!((0..3).all(|a| n.min[a] <= ch.min[a] && ch.max[a] <= n.max[a]));
                    }
                }
            }
            assert!(b.depth >= (scene.tris.len() as f64 / leaf_size as f64).log2().floor() as usize);
        }
    }
}
