//! Scenes and rays: the built-in scene (the Cornell box from its published measurements plus
//! procedural meshes), OBJ loading through `tobj` with clear errors, the exact power-of-two
//! normalisation into the unit cube, and seeded ray generation.

use datapath::rng::SplitMix64;
use golden::{Ray64, Tri64};
use std::fmt;
use std::path::Path;

/// A triangle soup in f64, normalised so that every coordinate lies in [-1, 1].
#[derive(Clone, Debug)]
pub struct Scene {
    /// Name for reports.
    pub name: String,
    /// Triangles after normalisation.
    pub tris: Vec<Tri64>,
    /// The power of two the source coordinates were multiplied by (exact in binary floating point).
    pub scale: f64,
}

/// Why a scene could not be used.
#[derive(Debug, Clone, PartialEq)]
pub enum SceneError {
    /// The file is missing or unreadable.
    Io(String),
    /// The OBJ parser rejected the file.
    Malformed(String),
    /// The file holds no triangles.
    NoTriangles(String),
    /// A vertex coordinate is NaN or infinite.
    NonFinite(String),
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SceneError::Io(m) => write!(f, "cannot read scene: {m}"),
            SceneError::Malformed(m) => write!(f, "malformed OBJ: {m}"),
            SceneError::NoTriangles(p) => write!(f, "scene {p} has no triangles"),
            SceneError::NonFinite(m) => write!(f, "scene has a non-finite coordinate: {m}"),
        }
    }
}

impl std::error::Error for SceneError {}

type Quad = [[f64; 3]; 4];

/// The Cornell box (Cornell Program of Computer Graphics measurements, in mm): walls, light,
/// and the two blocks, as quads.
const CORNELL: [Quad; 16] = [
    [[552.8, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 559.2], [549.6, 0.0, 559.2]], // floor
    [[343.0, 548.0, 227.0], [343.0, 548.0, 332.0], [213.0, 548.0, 332.0], [213.0, 548.0, 227.0]], // light
    [[556.0, 548.8, 0.0], [556.0, 548.8, 559.2], [0.0, 548.8, 559.2], [0.0, 548.8, 0.0]], // ceiling
    [[549.6, 0.0, 559.2], [0.0, 0.0, 559.2], [0.0, 548.8, 559.2], [556.0, 548.8, 559.2]], // back wall
    [[0.0, 0.0, 559.2], [0.0, 0.0, 0.0], [0.0, 548.8, 0.0], [0.0, 548.8, 559.2]], // green wall
    [[552.8, 0.0, 0.0], [549.6, 0.0, 559.2], [556.0, 548.8, 559.2], [556.0, 548.8, 0.0]], // red wall
    [[130.0, 165.0, 65.0], [82.0, 165.0, 225.0], [240.0, 165.0, 272.0], [290.0, 165.0, 114.0]], // short block
    [[290.0, 0.0, 114.0], [290.0, 165.0, 114.0], [240.0, 165.0, 272.0], [240.0, 0.0, 272.0]],
    [[130.0, 0.0, 65.0], [130.0, 165.0, 65.0], [290.0, 165.0, 114.0], [290.0, 0.0, 114.0]],
    [[82.0, 0.0, 225.0], [82.0, 165.0, 225.0], [130.0, 165.0, 65.0], [130.0, 0.0, 65.0]],
    [[240.0, 0.0, 272.0], [240.0, 165.0, 272.0], [82.0, 165.0, 225.0], [82.0, 0.0, 225.0]],
    [[423.0, 330.0, 247.0], [265.0, 330.0, 296.0], [314.0, 330.0, 456.0], [472.0, 330.0, 406.0]], // tall block
    [[423.0, 0.0, 247.0], [423.0, 330.0, 247.0], [472.0, 330.0, 406.0], [472.0, 0.0, 406.0]],
    [[472.0, 0.0, 406.0], [472.0, 330.0, 406.0], [314.0, 330.0, 456.0], [314.0, 0.0, 456.0]],
    [[314.0, 0.0, 456.0], [314.0, 330.0, 456.0], [265.0, 330.0, 296.0], [265.0, 0.0, 296.0]],
    [[265.0, 0.0, 296.0], [265.0, 330.0, 296.0], [423.0, 330.0, 247.0], [423.0, 0.0, 247.0]],
];

fn quads(q: &[Quad]) -> Vec<Tri64> {
    q.iter().flat_map(|[a, b, c, d]| [Tri64 { v: [*a, *b, *c] }, Tri64 { v: [*a, *c, *d] }]).collect()
}

/// A closed icosphere (subdivided icosahedron, 20·4^level triangles).
pub fn icosphere(center: [f64; 3], radius: f64, level: u32) -> Vec<Tri64> {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut verts: Vec<[f64; 3]> = vec![
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ];
    let mut faces: Vec<[usize; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    let unit = |p: [f64; 3]| {
        let n = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        [p[0] / n, p[1] / n, p[2] / n]
    };
    verts.iter_mut().for_each(|v| *v = unit(*v));
    for _ in 0..level {
        let mut cache = std::collections::HashMap::new();
        let mut mid = |a: usize, b: usize, verts: &mut Vec<[f64; 3]>| -> usize {
            *cache.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let (p, q) = (verts[a], verts[b]);
                verts.push(unit([(p[0] + q[0]) / 2.0, (p[1] + q[1]) / 2.0, (p[2] + q[2]) / 2.0]));
                verts.len() - 1
            })
        };
        let mut next = Vec::with_capacity(faces.len() * 4);
        for [a, b, c] in faces {
            let ab = mid(a, b, &mut verts);
            let bc = mid(b, c, &mut verts);
            let ca = mid(c, a, &mut verts);
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        faces = next;
    }
    let place = |p: [f64; 3]| [center[0] + radius * p[0], center[1] + radius * p[1], center[2] + radius * p[2]];
    faces.iter().map(|f| Tri64 { v: f.map(|i| place(verts[i])) }).collect()
}

/// A fan of needle triangles (long and very thin): the ill-conditioned case.
pub fn needles(apex: [f64; 3], len: f64, count: usize) -> Vec<Tri64> {
    (0..count)
        .map(|i| {
            let a = i as f64 * std::f64::consts::PI / count as f64;
            let w = len * 1e-3 * (1.0 + i as f64);
            let tip = [apex[0] + len * a.cos(), apex[1] + len * a.sin(), apex[2]];
            Tri64 { v: [apex, tip, [tip[0], tip[1] + w, tip[2] + w]] }
        })
        .collect()
}

impl Scene {
    /// The built-in scene: the Cornell box (32 triangles), a closed icosphere (320) on the floor
    /// and a fan of 16 needle triangles in front of the back wall.
    pub fn builtin() -> Scene {
        let mut tris = quads(&CORNELL);
        tris.extend(icosphere([400.0, 80.0, 120.0], 80.0, 2));
        tris.extend(needles([100.0, 300.0, 500.0], 200.0, 16));
        Self::normalised("builtin (cornell box + icosphere + needles)".into(), tris)
    }

    /// Loads a Wavefront OBJ file (polygons triangulated as fans; materials ignored).
    pub fn load_obj(path: &Path) -> Result<Scene, SceneError> {
        if !path.is_file() {
            return Err(SceneError::Io(format!("{}: no such file", path.display())));
        }
        let file = std::fs::File::open(path).map_err(|e| SceneError::Io(format!("{}: {e}", path.display())))?;
        let name = path.file_name().map_or_else(|| path.display().to_string(), |n| n.to_string_lossy().into_owned());
        Self::parse_obj(&name, &mut std::io::BufReader::new(file))
    }

    /// Reads a Wavefront OBJ from `reader` (what [`Scene::load_obj`] does with a file; the
    /// fuzz target `obj` feeds it arbitrary bytes). `name` names the scene and the errors.
    pub fn parse_obj(name: &str, reader: &mut impl std::io::BufRead) -> Result<Scene, SceneError> {
        let opts =
            tobj::LoadOptions { triangulate: true, single_index: false, ignore_points: true, ignore_lines: true };
        // only positions and faces matter: the rest (texture coordinates, normals, materials,
        // groups) is dropped before tobj sees it, and with it the index paths tobj does not
        // check (a hostile texture index made it panic under fuzzing)
        let mut bytes = Vec::new();
        reader.read_to_end(&mut bytes).map_err(|e| SceneError::Io(format!("{name}: {e}")))?;
        let text = String::from_utf8_lossy(&bytes);
        let mut kept = String::with_capacity(text.len());
        for line in text.lines() {
            let mut words = line.split_whitespace();
            match words.next() {
                Some("v") => {
                    kept.push_str(line.trim());
                    kept.push('\n');
                }
                Some("f") => {
                    kept.push('f');
                    for w in words {
                        kept.push(' ');
                        kept.push_str(w.split('/').next().unwrap_or(""));
                    }
                    kept.push('\n');
                }
                _ => {}
            }
        }
        let (models, _) = tobj::load_obj_buf(&mut kept.as_bytes(), &opts, |_| Err(tobj::LoadError::OpenFileFailed))
            .map_err(|e| SceneError::Malformed(format!("{name}: {e}")))?;
        let path = std::path::Path::new(name);
        let mut tris = Vec::new();
        for m in &models {
            let p = &m.mesh.positions;
            let idx = &m.mesh.indices;
            for f in idx.chunks_exact(3) {
                let mut v = [[0.0; 3]; 3];
                for (k, &i) in f.iter().enumerate() {
                    let i = i as usize * 3;
                    let Some(c) = p.get(i..i + 3) else {
                        return Err(SceneError::Malformed(format!("{}: face index out of range", path.display())));
                    };
                    for a in 0..3 {
                        if !c[a].is_finite() {
                            return Err(SceneError::NonFinite(format!(
                                "{}: vertex {} has {}",
                                path.display(),
                                i / 3 + 1,
                                c[a]
                            )));
                        }
                        v[k][a] = c[a] as f64;
                    }
                }
                tris.push(Tri64 { v });
            }
        }
        if tris.is_empty() {
            return Err(SceneError::NoTriangles(path.display().to_string()));
        }
        Ok(Self::normalised(name.to_string(), tris))
    }

    /// Scales by the power of two that brings the largest |coordinate| into (1/2, 1].
    fn normalised(name: String, mut tris: Vec<Tri64>) -> Scene {
        let m = tris.iter().flat_map(|t| t.v.iter().flatten()).fold(0.0f64, |m, x| m.max(x.abs()));
        let scale = if m > 0.0 { 2f64.powi(-(m.log2().ceil() as i32)) } else { 1.0 };
        for t in &mut tris {
            for p in &mut t.v {
                for x in p.iter_mut() {
                    *x *= scale;
                }
            }
        }
        Scene { name, tris, scale }
    }

    /// Axis-aligned bounds of the scene.
    pub fn bounds(&self) -> ([f64; 3], [f64; 3]) {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in self.tris.iter().flat_map(|t| t.v.iter()) {
            for a in 0..3 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
        (lo, hi)
    }

    /// `n` seeded rays: alternately aimed (from a random point in the origin box
    /// ([`origin_bounds`]: the bounds, flat axes widened) towards a random
    /// barycentric point of a random triangle, barycentrics in [-0.1, 1.1] so edges and misses
    /// are exercised) and incoherent (random origin, uniformly random direction). Each ray
    /// carries the index of the triangle it was aimed at (or a random one).
    pub fn rays(&self, n: usize, seed: u64) -> Vec<(Ray64, usize)> {
        let g = self.ray_gen(seed);
        (0..n as u64).map(|i| g.ray(self, i)).collect()
    }

    /// The generator of [`Scene::rays`] for `seed`, to make any ray by its index.
    pub fn ray_gen(&self, seed: u64) -> RayGen {
        RayGen { seed, bounds: origin_bounds(self.bounds()) }
    }
}

/// An axis of the scene's bounds thinner than the largest extent over this is degenerate.
pub const FLAT_RATIO: f64 = 64.0;

/// The box ray origins are drawn from: the scene's bounds, with every degenerate axis (extent
/// below the largest extent / [`FLAT_RATIO`], a flat scene's normal axis) widened to half the
/// largest extent around its centre (1 when every extent is 0), so that rays aimed at a flat
/// scene do not lie in its plane. Other axes keep the bounds exactly.
pub fn origin_bounds((lo, hi): ([f64; 3], [f64; 3])) -> ([f64; 3], [f64; 3]) {
    let ext = (0..3).map(|a| hi[a] - lo[a]).fold(0.0, f64::max);
    let pad = if ext > 0.0 { ext / 4.0 } else { 0.5 };
    let (mut lo, mut hi) = (lo, hi);
    for a in 0..3 {
        if (hi[a] - lo[a]) * FLAT_RATIO < ext || ext == 0.0 {
            let c = (lo[a] + hi[a]) / 2.0;
            (lo[a], hi[a]) = (c - pad, c + pad);
        }
    }
    (lo, hi)
}

/// Makes ray `i` of a scene's seeded ray set without the rays before it.
#[derive(Clone, Copy, Debug)]
pub struct RayGen {
    seed: u64,
    bounds: ([f64; 3], [f64; 3]),
}

impl RayGen {
    /// Ray `i` of the seeded ray set (see [`Scene::rays`]) and its target triangle: drawn from
    /// `SplitMix64::for_item(seed, RAY_STREAM, i)` alone.
    pub fn ray(&self, scene: &Scene, i: u64) -> (Ray64, usize) {
        let mut r = SplitMix64::for_item(self.seed, RAY_STREAM, i);
        let (lo, hi) = self.bounds;
        let o = [0, 1, 2].map(|a| r.range(lo[a], hi[a]));
        let target = r.below(scene.tris.len() as u64) as usize;
        let d = if i.is_multiple_of(2) {
            let t = &scene.tris[target];
            let (b1, b2) = (r.range(-0.1, 1.1), r.range(-0.1, 1.1));
            let (b1, b2) = if b1 + b2 > 1.2 { (1.0 - b1, 1.0 - b2) } else { (b1, b2) };
            let b0 = 1.0 - b1 - b2;
            let p = [0, 1, 2].map(|a| b0 * t.v[0][a] + b1 * t.v[1][a] + b2 * t.v[2][a]);
            [p[0] - o[0], p[1] - o[1], p[2] - o[2]]
        } else {
            let z = r.range(-1.0, 1.0);
            let phi = r.range(0.0, 2.0 * std::f64::consts::PI);
            let s = (1.0 - z * z).sqrt();
            [s * phi.cos(), s * phi.sin(), z]
        };
        (Ray64 { o, d, tmin: 0.0, tmax: f64::INFINITY }, target)
    }
}

/// Stream number of the scene's rays in [`SplitMix64::for_item`].
pub const RAY_STREAM: u64 = 0x7261_7973; // "rays"

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn builtin_scene_is_normalised_exactly() {
        let s = Scene::builtin();
        assert_eq!(s.tris.len(), 32 + 320 + 16);
        assert_eq!(s.scale, 2f64.powi(-10));
        // 559.2 * 2^-10 is exact: scaling back gives the published coordinate
        assert_eq!(s.tris[0].v[2][2] / s.scale, 559.2);
        let (lo, hi) = s.bounds();
        assert!(lo.iter().chain(hi.iter()).all(|x| x.abs() <= 1.0));
    }

    #[test]
    fn rays_are_deterministic_per_seed() {
        let s = Scene::builtin();
        let a = s.rays(8, 7);
        let b = s.rays(8, 7);
        let c = s.rays(8, 8);
        assert_eq!(a.iter().map(|(r, _)| r.d).collect::<Vec<_>>(), b.iter().map(|(r, _)| r.d).collect::<Vec<_>>());
        assert_ne!(a[0].0.d, c[0].0.d);
    }

    #[test]
    fn icosphere_is_closed() {
        // every edge is shared by exactly two faces
        let tris = icosphere([0.0; 3], 1.0, 2);
        let mut edges = std::collections::HashMap::new();
        let key = |p: [f64; 3]| p.map(|x| (x * 1e9).round() as i64);
        for t in &tris {
            for k in 0..3 {
                let (a, b) = (key(t.v[k]), key(t.v[(k + 1) % 3]));
                *edges.entry(if a < b { (a, b) } else { (b, a) }).or_insert(0) += 1;
            }
        }
        assert_eq!(tris.len(), 320);
        assert!(edges.values().all(|&n| n == 2));
    }
}
