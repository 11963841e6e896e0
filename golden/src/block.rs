//! The golden tests on blocks: one ray against a block of triangles (or boxes) held as
//! coordinate columns, in SIMD f64 lanes (AVX-512F: 8, AVX2: 4, otherwise the compiler's
//! baseline), bit-identical to [`crate::intersect`] and [`crate::slab_f64`]: each lane runs the
//! same binary64 operations in the same order (no FMA, no reassociation); the loops are written
//! branch-free so that they vectorise, and only which instructions carry them differs by level.
//! One exception, in Rust's own rules: the sign and payload of a NaN result are not specified
//! (the compiler may swap the operands of a commutative operation, and x86 returns the first
//! NaN operand), so a NaN output equals the scalar one as a NaN, not in its bits. No decision
//! reads a NaN's bits.

use crate::{Faces, Ray64};

/// Instruction set a block runs on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Level {
    /// Whatever the compiler emits for the target's baseline (SSE2 on x86-64).
    Scalar,
    /// AVX2: 4 f64 lanes.
    Avx2,
    /// AVX-512F: 8 f64 lanes.
    Avx512,
}

/// Levels this machine can run, fastest last.
pub fn levels_here() -> Vec<Level> {
    let mut v = vec![Level::Scalar];
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx2") {
            v.push(Level::Avx2);
        }
        if std::arch::is_x86_feature_detected!("avx512f") {
            v.push(Level::Avx512);
        }
    }
    v
}

/// The fastest level this machine runs.
pub fn best_level() -> Level {
    *levels_here().last().expect("scalar is always there")
}

/// A block's triangles: columns x0 y0 z0 x1 y1 z1 x2 y2 z2 of equal length.
pub type TriCols<'a> = [&'a [f64]; 9];
/// A block's boxes: columns minx miny minz maxx maxy maxz of equal length.
pub type BoxCols<'a> = [&'a [f64]; 6];

/// [`crate::intersect`]'s `hit` and `t` for `ray` against every triangle of `tris`, into `hit`
/// and `t` (lengths equal to the columns'), on `level` (which must be in [`levels_here`]).
///
/// # Panics
/// If the lengths differ or `level` is not available here.
pub fn intersect_block(level: Level, ray: &Ray64, faces: Faces, tris: TriCols, hit: &mut [bool], t: &mut [f64]) {
    let n = hit.len();
    assert!(t.len() == n && tris.iter().all(|c| c.len() == n), "column lengths differ");
    match level {
        Level::Scalar => mt_body(ray, faces, tris, hit, t),
        #[cfg(target_arch = "x86_64")]
        Level::Avx2 => {
            assert!(std::arch::is_x86_feature_detected!("avx2"), "no AVX2 here");
            // SAFETY: AVX2 is present (checked above)
            unsafe { mt_avx2(ray, faces, tris, hit, t) }
        }
        #[cfg(target_arch = "x86_64")]
        Level::Avx512 => {
            assert!(std::arch::is_x86_feature_detected!("avx512f"), "no AVX-512F here");
            // SAFETY: AVX-512F is present (checked above)
            unsafe { mt_avx512(ray, faces, tris, hit, t) }
        }
        #[cfg(not(target_arch = "x86_64"))]
        _ => panic!("{level:?} is not available here"),
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn mt_avx2(ray: &Ray64, faces: Faces, tris: TriCols, hit: &mut [bool], t: &mut [f64]) {
    mt_body(ray, faces, tris, hit, t)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn mt_avx512(ray: &Ray64, faces: Faces, tris: TriCols, hit: &mut [bool], t: &mut [f64]) {
    mt_body(ray, faces, tris, hit, t)
}

/// The operations of [`crate::intersect`] that `hit` and `t` depend on, in its order.
#[inline(always)]
fn mt_body(ray: &Ray64, faces: Faces, c: TriCols, hit: &mut [bool], tout: &mut [f64]) {
    let [dx, dy, dz] = ray.d;
    let [ox, oy, oz] = ray.o;
    for i in 0..hit.len() {
        let (v0x, v0y, v0z) = (c[0][i], c[1][i], c[2][i]);
        let (e1x, e1y, e1z) = (c[3][i] - v0x, c[4][i] - v0y, c[5][i] - v0z);
        let (e2x, e2y, e2z) = (c[6][i] - v0x, c[7][i] - v0y, c[8][i] - v0z);
        // p = d × e2
        let (px, py, pz) = (dy * e2z - dz * e2y, dz * e2x - dx * e2z, dx * e2y - dy * e2x);
        let det = e1x * px + e1y * py + e1z * pz;
        let inv = 1.0 / det;
        let (sx, sy, sz) = (ox - v0x, oy - v0y, oz - v0z);
        let u = (sx * px + sy * py + sz * pz) * inv;
        // q = s × e1
        let (qx, qy, qz) = (sy * e1z - sz * e1y, sz * e1x - sx * e1z, sx * e1y - sy * e1x);
        let v = (dx * qx + dy * qy + dz * qz) * inv;
        let t = (e2x * qx + e2y * qy + e2z * qz) * inv;
        let w = 1.0 - u - v;
        let face_ok = if faces.cull { det > faces.det_threshold } else { det.abs() > faces.det_threshold };
        hit[i] = face_ok & det.is_finite() & (u >= 0.0) & (v >= 0.0) & (w >= 0.0) & (t >= ray.tmin) & (t <= ray.tmax);
        tout[i] = t;
    }
}

/// [`crate::slab_f64`] for `o`, `d`, `[tmin, tmax]` against every box of `boxes`: its `hit`,
/// `t_near` and `t_far` into the output slices, on `level` (which must be in [`levels_here`]).
///
/// # Panics
/// If the lengths differ or `level` is not available here.
#[allow(clippy::too_many_arguments)]
pub fn slab_block(
    level: Level,
    o: [f64; 3],
    d: [f64; 3],
    tmin: f64,
    tmax: f64,
    boxes: BoxCols,
    hit: &mut [bool],
    t_near: &mut [f64],
    t_far: &mut [f64],
) {
    let n = hit.len();
    assert!(t_near.len() == n && t_far.len() == n && boxes.iter().all(|c| c.len() == n), "column lengths differ");
    match level {
        Level::Scalar => slab_body(o, d, tmin, tmax, boxes, hit, t_near, t_far),
        #[cfg(target_arch = "x86_64")]
        Level::Avx2 => {
            assert!(std::arch::is_x86_feature_detected!("avx2"), "no AVX2 here");
            // SAFETY: AVX2 is present (checked above)
            unsafe { slab_avx2(o, d, tmin, tmax, boxes, hit, t_near, t_far) }
        }
        #[cfg(target_arch = "x86_64")]
        Level::Avx512 => {
            assert!(std::arch::is_x86_feature_detected!("avx512f"), "no AVX-512F here");
            // SAFETY: AVX-512F is present (checked above)
            unsafe { slab_avx512(o, d, tmin, tmax, boxes, hit, t_near, t_far) }
        }
        #[cfg(not(target_arch = "x86_64"))]
        _ => panic!("{level:?} is not available here"),
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[allow(clippy::too_many_arguments)]
fn slab_avx2(o: [f64; 3], d: [f64; 3], tmin: f64, tmax: f64, b: BoxCols, h: &mut [bool], n: &mut [f64], f: &mut [f64]) {
    slab_body(o, d, tmin, tmax, b, h, n, f)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
#[allow(clippy::too_many_arguments)]
fn slab_avx512(
    o: [f64; 3],
    d: [f64; 3],
    tmin: f64,
    tmax: f64,
    b: BoxCols,
    h: &mut [bool],
    n: &mut [f64],
    f: &mut [f64],
) {
    slab_body(o, d, tmin, tmax, b, h, n, f)
}

/// [`crate::slab_f64`] branch-free: an axis with d = 0 whose origin is outside the slab marks
/// the lane dead (the scalar code returns there), and a dead lane's near / far stay as they
/// were; `lo > near ? lo : near` and `hi < far ? hi : far` as in the scalar code (a NaN bound
/// is not taken).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn slab_body(
    o: [f64; 3],
    d: [f64; 3],
    tmin: f64,
    tmax: f64,
    b: BoxCols,
    hit: &mut [bool],
    t_near: &mut [f64],
    t_far: &mut [f64],
) {
    for i in 0..hit.len() {
        let mut near = tmin;
        let mut far = tmax;
        let mut dead = false;
        for a in 0..3 {
            let (lo_p, hi_p) = (b[a][i], b[a + 3][i]);
            if d[a] == 0.0 {
                dead |= (o[a] < lo_p) | (o[a] > hi_p);
            } else {
                let t0 = (lo_p - o[a]) / d[a];
                let t1 = (hi_p - o[a]) / d[a];
                let sw = t0 <= t1;
                let lo = if sw { t0 } else { t1 };
                let hi = if sw { t1 } else { t0 };
                let n2 = if lo > near { lo } else { near };
                let f2 = if hi < far { hi } else { far };
                near = if dead { near } else { n2 };
                far = if dead { far } else { f2 };
            }
        }
        hit[i] = !dead & (near <= far);
        t_near[i] = near;
        t_far[i] = far;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{intersect, slab_f64, Tri64};

    /// A small deterministic generator (the golden crate shares no code with datapath).
    struct Lcg(u64);
    impl Lcg {
        fn next(&mut self) -> u64 {
            self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            self.0 >> 11
        }
        /// Values that reach the edges: zeros of both signs, infinities, NaN, subnormals,
        /// huge and tiny magnitudes, integers (exact ties), ordinary values.
        fn value(&mut self) -> f64 {
            let r = self.next();
            match r % 16 {
                0 => 0.0,
                1 => -0.0,
                2 => f64::INFINITY,
                3 => f64::NEG_INFINITY,
                4 => f64::NAN,
                5 => f64::from_bits(self.next() & 0x000f_ffff_ffff_ffff),
                6 => f64::MAX / (1 + self.next() % 4) as f64,
                7 => ((self.next() % 9) as f64) - 4.0,
                _ => ((self.next() as f64) / (1u64 << 53) as f64 - 0.5) * 2f64.powi((self.next() % 40) as i32 - 20),
            }
        }
    }

    /// The encoding, with every NaN as one value (Rust leaves a NaN's sign and payload open).
    fn bits(x: f64) -> u64 {
        if x.is_nan() {
            u64::MAX
        } else {
            x.to_bits()
        }
    }

    #[test]
    fn blocks_match_the_scalar_golden_bit_for_bit_on_every_level() {
        let mut g = Lcg(7);
        for round in 0..4000 {
            // every fourth ray on edge values, the rest ordinary
            let v = |g: &mut Lcg| if round % 4 == 0 { g.value() } else { (g.next() % 2001) as f64 / 1000.0 - 1.0 };
            let ray = Ray64 {
                o: [v(&mut g), v(&mut g), v(&mut g)],
                d: [v(&mut g), v(&mut g), if round % 8 == 1 { 0.0 } else { v(&mut g) }],
                tmin: if round % 3 == 0 { 0.0 } else { v(&mut g) },
                tmax: if round % 5 == 0 { f64::INFINITY } else { v(&mut g) },
            };
            let n = 1 + (g.next() % 37) as usize;
            let tris: Vec<Tri64> =
                (0..n).map(|_| Tri64 { v: std::array::from_fn(|_| std::array::from_fn(|_| v(&mut g))) }).collect();
            let cols: [Vec<f64>; 9] = std::array::from_fn(|k| tris.iter().map(|t| t.v[k / 3][k % 3]).collect());
            let faces = Faces { cull: round % 2 == 0, det_threshold: if round % 7 == 0 { 0.25 } else { 0.0 } };
            let boxes: [Vec<f64>; 6] = std::array::from_fn(|k| {
                tris.iter()
                    .map(|t| if k < 3 { t.v[0][k].min(t.v[1][k]) } else { t.v[0][k - 3].max(t.v[1][k - 3]) })
                    .collect()
            });
            for level in levels_here() {
                let (mut hit, mut t) = (vec![false; n], vec![0.0; n]);
                intersect_block(level, &ray, faces, std::array::from_fn(|k| &cols[k][..]), &mut hit, &mut t);
                for (i, tri) in tris.iter().enumerate() {
                    let want = intersect(&ray, tri, faces);
                    assert_eq!(hit[i], want.hit, "{level:?} round {round} lane {i}");
                    assert_eq!(bits(t[i]), bits(want.t), "{level:?} round {round} lane {i}");
                }
                let (mut sh, mut sn, mut sf) = (vec![false; n], vec![0.0; n], vec![0.0; n]);
                slab_block(
                    level,
                    ray.o,
                    ray.d,
                    ray.tmin,
                    ray.tmax,
                    std::array::from_fn(|k| &boxes[k][..]),
                    &mut sh,
                    &mut sn,
                    &mut sf,
                );
                for i in 0..n {
                    let lo = [boxes[0][i], boxes[1][i], boxes[2][i]];
                    let hi = [boxes[3][i], boxes[4][i], boxes[5][i]];
                    let want = slab_f64(ray.o, ray.d, ray.tmin, ray.tmax, lo, hi);
                    assert_eq!(sh[i], want.hit, "{level:?} round {round} box {i}");
                    assert_eq!(bits(sn[i]), bits(want.t_near), "{level:?} round {round} box {i}");
                    assert_eq!(bits(sf[i]), bits(want.t_far), "{level:?} round {round} box {i}");
                }
            }
        }
    }
}
