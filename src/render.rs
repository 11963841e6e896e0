//! `raypipe render`: a ray through both units as the hardware does it — history traversal with
//! the format's slab unit → the leaves' triangles streamed through the format's RTI min-capture
//! → the closest hit — against the golden closest hit (f64 stack traversal with the f64 slab
//! test, f64 Möller–Trumbore), written as a shaded PNG and a diff PNG.

use crate::bvh::build;
use crate::camera::Camera;
use crate::scene::Scene;
use datapath::bvh::history_traverse_into;
use datapath::rti::{Capture, Rti, RtiConfig};
use datapath::slab::{Slab, SlabConfig};
use datapath::Format;
use golden::bvh::stack_traverse;
use golden::{intersect, slab_f64, Faces, Ray64};
use serde::Serialize;

/// Per-image counts.
#[derive(Clone, Debug, Serialize)]
pub struct RenderReport {
    /// Format.
    pub format: String,
    /// Slab variant.
    pub variant: String,
    /// Width × height.
    pub pixels: u64,
    /// Pixels the golden hits.
    pub golden_hits: u64,
    /// Golden hits the pipeline misses (holes).
    pub holes: u64,
    /// Pipeline hits where the golden misses.
    pub false_hits: u64,
    /// Both hit, different triangles.
    pub other_triangle: u64,
    /// Golden hits whose closest triangle's leaf the pipeline traversal never reached (a box on
    /// the way missed by the slab unit).
    pub culled: u64,
    /// The slab variant promises never to miss in this format (then `culled` must be 0).
    pub conservative: bool,
    /// The camera the image was taken with.
    pub camera: Camera,
}

impl RenderReport {
    /// Why the culling check proved nothing: a conservative variant, but no pixel's ray hits
    /// the scene, so no box lay on the way to a hit.
    pub fn vacuous(&self) -> Option<String> {
        (self.conservative && self.golden_hits == 0)
            .then(|| "no pixel's ray hits the scene: no box lay on the way to a hit".to_string())
    }

    /// The exit outcome: a conservative variant that culled fails; one that saw no hit is
    /// inconclusive.
    pub fn outcome(&self) -> crate::Outcome {
        if self.conservative && self.culled > 0 {
            crate::Outcome::Fail
        } else if self.vacuous().is_some() {
            crate::Outcome::Inconclusive
        } else {
            crate::Outcome::Pass
        }
    }
}

/// The files [`render`] writes (checked before the work starts).
pub const FILES: [&str; 2] = ["render.png", "diff.png"];

fn png(out: &vectors::outdir::OutDir, name: &str, w: u32, h: u32, rgb: &[u8]) -> Result<(), String> {
    let mut bytes = Vec::new();
    {
        let mut enc = ::png::Encoder::new(&mut bytes, w, h);
        enc.set_color(::png::ColorType::Rgb);
        enc.set_depth(::png::BitDepth::Eight);
        let mut wr = enc.write_header().map_err(|e| e.to_string())?;
        wr.write_image_data(rgb).map_err(|e| e.to_string())?;
    }
    out.write(name, &bytes).map(|_| ())
}

fn shade(scene: &Scene, tri: usize, d: [f64; 3]) -> u8 {
    let t = &scene.tris[tri];
    let e1: [f64; 3] = std::array::from_fn(|a| t.v[1][a] - t.v[0][a]);
    let e2: [f64; 3] = std::array::from_fn(|a| t.v[2][a] - t.v[0][a]);
    let n = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]];
    let nl = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt().max(1e-300);
    let dl = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt().max(1e-300);
    let c = ((n[0] * d[0] + n[1] * d[1] + n[2] * d[2]) / (nl * dl)).abs();
    (40.0 + 215.0 * c) as u8
}

/// Renders `width × height` primary rays from `camera`; writes `render.png` and `diff.png`
/// into `out`.
#[allow(clippy::too_many_arguments)]
pub fn render<F: Format>(
    f: F,
    variant: &str,
    scene: &Scene,
    camera: &Camera,
    width: u32,
    height: u32,
    leaf_size: u32,
    out: &vectors::outdir::OutDir,
) -> Result<RenderReport, String> {
    camera.check()?;
    let sc = SlabConfig::named_for(variant, &f)?;
    let slab = Slab::new(f, sc);
    let rti = Rti::new(f, RtiConfig::default());
    let b = build(scene, leaf_size);
    let hw = b.layout_ids(256)?;
    let tree = b.golden_tree();
    let boxes: Vec<_> =
        b.nodes.iter().map(|n| slab.store_box(n.min, n.max)).collect::<Result<_, _>>().map_err(|e| e.to_string())?;
    let tris: Vec<_> = scene.tris.iter().map(|t| rti.tri(t.v)).collect();
    let mut img = vec![0u8; (width * height * 3) as usize];
    let mut diff = vec![0u8; (width * height * 3) as usize];
    let mut rep = RenderReport {
        format: f.name(),
        variant: variant.to_string(),
        pixels: width as u64 * height as u64,
        golden_hits: 0,
        holes: 0,
        false_hits: 0,
        other_triangle: 0,
        culled: 0,
        conservative: sc.is_conservative(&f),
        camera: *camera,
    };
    let mut leaf_of = vec![u32::MAX; scene.tris.len()];
    for (l, tris) in b.leaf_tris.iter().enumerate() {
        for &t in tris {
            leaf_of[t as usize] = l as u32;
        }
    }
    // each box test of a ray computed once over the history traversal's passes (its leaves
    // unchanged: datapath::box_memo)
    let mut memo = datapath::box_memo::BoxMemo::new(boxes.len());
    let mut hres = datapath::bvh::StacklessResult::default();
    for j in 0..height {
        for i in 0..width {
            let ray = Ray64 { o: camera.eye, d: camera.ray_dir(i, j, width, height), tmin: 0.0, tmax: f64::INFINITY };
            // the pipeline: slab-unit traversal, then the leaves' triangles through the min-capture
            let sr = slab.prepare(ray.o, ray.d, ray.tmin, ray.tmax);
            memo.next_ray();
            history_traverse_into(
                &hw,
                usize::MAX,
                |&n| {
                    memo.get_or(n, || {
                        let o = slab.test(&sr, &boxes[n as usize]);
                        o.hit.then(|| f.to_f64(o.t_near))
                    })
                },
                &mut hres,
            );
            let leaves = &hres.leaves;
            let mray = rti.ray(ray.o, ray.d, ray.tmin, ray.tmax);
            let mut cap = Capture::default();
            for &leaf in leaves {
                for &t in &b.leaf_tris[leaf as usize] {
                    let o = rti.test(&mray, &tris[t as usize]);
                    rti.capture(&mut cap, &o, t);
                }
            }
            // the golden: f64 stack traversal and f64 triangle tests
            let gl = stack_traverse(&tree, usize::MAX, |n| {
                let nd = &b.nodes[n as usize];
                let r = slab_f64(ray.o, ray.d, ray.tmin, ray.tmax, nd.min, nd.max);
                r.hit.then_some(r.t_near)
            })
            .leaves;
            let mut best: Option<(u32, f64)> = None;
            for &leaf in &gl {
                for &t in &b.leaf_tris[leaf as usize] {
                    let r = intersect(&ray, &scene.tris[t as usize], Faces::default());
                    if r.hit && best.is_none_or(|(bt, bd)| r.t < bd || (r.t == bd && t < bt)) {
                        best = Some((t, r.t));
                    }
                }
            }
            if let Some((g, _)) = best {
                rep.culled += !leaves.contains(&leaf_of[g as usize]) as u64;
            }
            let p = ((j * width + i) * 3) as usize;
            let model = cap.hit.then_some(cap.id);
            if let Some(t) = model {
                let s = shade(scene, t as usize, ray.d);
                img[p..p + 3].copy_from_slice(&[s, s, s]);
            }
            rep.golden_hits += best.is_some() as u64;
            let px: [u8; 3] = match (best, model) {
                (Some(_), None) => {
                    rep.holes += 1;
                    [255, 0, 0]
                }
                (None, Some(_)) => {
                    rep.false_hits += 1;
                    [0, 128, 255]
                }
                (Some((g, _)), Some(m)) if g != m => {
                    rep.other_triangle += 1;
                    [255, 200, 0]
                }
                (Some((g, _)), Some(_)) => {
                    let s = shade(scene, g as usize, ray.d) / 3;
                    [s, s, s]
                }
                (None, None) => [0, 0, 0],
            };
            diff[p..p + 3].copy_from_slice(&px);
        }
    }
    png(out, "render.png", width, height, &img)?;
    png(out, "diff.png", width, height, &diff)?;
    Ok(rep)
}
