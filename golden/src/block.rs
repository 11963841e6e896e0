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

/// [`slab_block`]'s `hit`, and whether its interval is close to empty — `|t_far − t_near| ≤
/// close_rel · max(1, |t_near|, |t_far| if finite)`, each operation in binary64 — for every
/// box of `boxes`, into `hit` and `close`, on `level` (which must be in [`levels_here`]): the
/// same two flags as computing [`slab_block`] and then that formula, bit for bit, on every
/// input.
///
/// How, not what: with every direction component 0 or of magnitude in [2^-1000, 2^1000],
/// each quotient `(plane − o) / d` is first taken as `(plane − o) · RN(1/d)`: within 4u of
/// the true quotient's magnitude (u = 2^-53: one rounding in the reciprocal, one in the
/// product, one in the true quotient) where the product's magnitude is in [2^-1020, 2^1019],
/// both below 2^-1019 where it is smaller, and zeros, infinities of an infinite plane and NaNs
/// the same in both (d is finite and nonzero). A lane whose interval ends both lie within
/// ±2^1019 then takes no larger quotient in either computation, so its ends differ from the
/// true ones by at most E = 4u · (the lane's largest product magnitude) + 2^-1018 (min and max
/// move no value further than their operands); where the interval is further than a margin
/// of 2E (plus the roundings of the formula) from both thresholds the lane takes the flags;
/// every other lane (one with an infinite product among them, and every lane of a ray outside
/// that range) runs the true division.
///
/// # Panics
/// If the lengths differ, `close_rel` is not in [0, 1] or `level` is not available here.
#[allow(clippy::too_many_arguments)]
pub fn slab_block_flags(
    level: Level,
    o: [f64; 3],
    d: [f64; 3],
    tmin: f64,
    tmax: f64,
    boxes: BoxCols,
    close_rel: f64,
    hit: &mut [bool],
    close: &mut [bool],
) {
    let n = hit.len();
    assert!(close.len() == n && boxes.iter().all(|c| c.len() == n), "column lengths differ");
    assert!((0.0..=1.0).contains(&close_rel), "close_rel {close_rel} is not in [0, 1]");
    match level {
        Level::Scalar => flags_body(o, d, tmin, tmax, boxes, close_rel, hit, close),
        #[cfg(target_arch = "x86_64")]
        Level::Avx2 => {
            assert!(std::arch::is_x86_feature_detected!("avx2"), "no AVX2 here");
            // SAFETY: AVX2 is present (checked above)
            unsafe { flags_avx2(o, d, tmin, tmax, boxes, close_rel, hit, close) }
        }
        #[cfg(target_arch = "x86_64")]
        Level::Avx512 => {
            assert!(std::arch::is_x86_feature_detected!("avx512f"), "no AVX-512F here");
            // SAFETY: AVX-512F is present (checked above)
            unsafe { flags_avx512(o, d, tmin, tmax, boxes, close_rel, hit, close) }
        }
        #[cfg(not(target_arch = "x86_64"))]
        _ => panic!("{level:?} is not available here"),
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[allow(clippy::too_many_arguments)]
fn flags_avx2(o: [f64; 3], d: [f64; 3], t0: f64, t1: f64, b: BoxCols, c: f64, h: &mut [bool], cl: &mut [bool]) {
    flags_body(o, d, t0, t1, b, c, h, cl)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
#[allow(clippy::too_many_arguments)]
fn flags_avx512(o: [f64; 3], d: [f64; 3], t0: f64, t1: f64, b: BoxCols, c: f64, h: &mut [bool], cl: &mut [bool]) {
    flags_body(o, d, t0, t1, b, c, h, cl)
}

/// The close formula of [`slab_block_flags`] on an interval.
#[inline(always)]
fn close_of(near: f64, far: f64, close_rel: f64) -> bool {
    let scale = 1.0f64.max(near.abs()).max(if far.is_finite() { far.abs() } else { 0.0 });
    (far - near).abs() <= close_rel * scale
}

/// Lanes [`flags_body`] settles in one pass before the true division runs on the rest.
const FLAG_GROUP: usize = 64;

/// [`slab_block_flags`] on whatever instructions the caller's level allows.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn flags_body(
    o: [f64; 3],
    d: [f64; 3],
    tmin: f64,
    tmax: f64,
    b: BoxCols,
    close_rel: f64,
    hit: &mut [bool],
    close: &mut [bool],
) {
    // the true division on lanes `r` of the block
    let exact = |r: std::ops::Range<usize>, hit: &mut [bool], close: &mut [bool]| {
        #[cfg(test)]
        tests::DIVIDED.with(|c| c.set(c.get() + r.len()));
        for i in r {
            let bx: [&[f64]; 6] = std::array::from_fn(|k| &b[k][i..i + 1]);
            let (mut h, mut n, mut f) = ([false], [0.0], [0.0]);
            slab_body(o, d, tmin, tmax, bx, &mut h, &mut n, &mut f);
            hit[i] = h[0];
            close[i] = close_of(n[0], f[0], close_rel);
        }
    };
    let in_range = |x: f64| x == 0.0 || (x.abs() >= 2f64.powi(-1000) && x.abs() <= 2f64.powi(1000));
    if !d.iter().all(|&x| in_range(x)) {
        exact(0..hit.len(), hit, close);
        return;
    }
    let r = d.map(|x| 1.0 / x);
    // a group's box planes and flags as fixed arrays — a whole group's read and written in
    // place, the block's last partial group copied into local arrays (its lanes past the end
    // hold zeros and are not written back): the lane loop runs without bounds checks
    // and vectorises
    let mut ug = [false; FLAG_GROUP];
    // the usual ray has no zero direction component: then no axis is parallel and the group's
    // lanes run without the parallel-axis test (the same flags: `dead` stays false)
    let parallel = d.contains(&0.0);
    // (a macro, not a closure: a closure is compiled apart from the target-feature function
    // that inlines this one)
    macro_rules! group {
        ($bg:expr, $hg:expr, $cg:expr) => {
            if parallel {
                flags_group::<true>(o, d, r, tmin, tmax, $bg, close_rel, $hg, $cg, &mut ug);
            } else {
                flags_group::<false>(o, d, r, tmin, tmax, $bg, close_rel, $hg, $cg, &mut ug);
            }
        };
    }
    let mut g = 0;
    while g < hit.len() {
        let m = FLAG_GROUP.min(hit.len() - g);
        if m == FLAG_GROUP {
            let bg: [&[f64; FLAG_GROUP]; 6] =
                std::array::from_fn(|k| b[k][g..g + FLAG_GROUP].try_into().expect("a whole group"));
            let hg: &mut [bool; FLAG_GROUP] = (&mut hit[g..g + FLAG_GROUP]).try_into().expect("a whole group");
            let cg: &mut [bool; FLAG_GROUP] = (&mut close[g..g + FLAG_GROUP]).try_into().expect("a whole group");
            group!(bg, hg, cg);
        } else {
            // (made here, not per call: a block of whole groups zeroes none of it)
            let mut bl = [[0.0f64; FLAG_GROUP]; 6];
            let (mut hl, mut cl) = ([false; FLAG_GROUP], [false; FLAG_GROUP]);
            for (k, col) in bl.iter_mut().enumerate() {
                col[..m].copy_from_slice(&b[k][g..g + m]);
            }
            group!(bl.each_ref(), &mut hl, &mut cl);
            hit[g..g + m].copy_from_slice(&hl[..m]);
            close[g..g + m].copy_from_slice(&cl[..m]);
        }
        if ug[..m].iter().any(|&u| u) {
            for (j, _) in ug[..m].iter().enumerate().filter(|&(_, &u)| u) {
                exact(g + j..g + j + 1, hit, close);
            }
        }
        g += m;
    }
}

/// One group of [`flags_body`]'s lanes through the reciprocal products: per lane the two
/// flags (`hit`, `close`) and whether the lane is unsure (`unsure`: it must take the true
/// division). `PARALLEL`: some direction component is zero (without it none is, and the
/// parallel-axis test is left out). The interval's ends are taken as `min`/`max` of the two
/// quotients, NaN kept as the scalar code keeps it (`lo` the second quotient, `hi` the first,
/// when one is NaN); two equal quotients may give an end of the other zero's sign, which no
/// flag reads (`near <= far`, `|far − near|` and the magnitudes are the same for ±0).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn flags_group<const PARALLEL: bool>(
    o: [f64; 3],
    d: [f64; 3],
    r: [f64; 3],
    tmin: f64,
    tmax: f64,
    bg: [&[f64; FLAG_GROUP]; 6],
    close_rel: f64,
    hg: &mut [bool; FLAG_GROUP],
    cg: &mut [bool; FLAG_GROUP],
    ug: &mut [bool; FLAG_GROUP],
) {
    let (two_m50, two_m1000, two_1019) = (2f64.powi(-50), 2f64.powi(-1000), 2f64.powi(1019));
    for i in 0..FLAG_GROUP {
        let mut near = tmin;
        let mut far = tmax;
        let mut dead = false;
        // the largest quotient magnitude (infinite when a quotient is)
        let mut big = 0.0f64;
        for a in 0..3 {
            let (lo_p, hi_p) = (bg[a][i], bg[a + 3][i]);
            if PARALLEL && d[a] == 0.0 {
                dead |= (o[a] < lo_p) | (o[a] > hi_p);
            } else {
                let (t0, t1) = ((lo_p - o[a]) * r[a], (hi_p - o[a]) * r[a]);
                for m in [t0.abs(), t1.abs()] {
                    big = if m > big { m } else { big };
                }
                // lo = t0 <= t1 ? t0 : t1 and hi = t0 <= t1 ? t1 : t0, as min and max
                let lo = if t0 < t1 { t0 } else { t1 };
                let hi = if t1 > t0 { t1 } else { t0 };
                let n2 = if lo > near { lo } else { near };
                let f2 = if hi < far { hi } else { far };
                near = if dead { near } else { n2 };
                far = if dead { far } else { f2 };
            }
        }
        // E, doubled: 4u of the largest quotient plus 2^-1018 for the quotients below 2^-1020
        let e = big * two_m50 + two_m1000;
        let diff = far - near;
        let lhs = diff.abs();
        let scale = 1.0f64.max(near.abs()).max(if far.is_finite() { far.abs() } else { 0.0 });
        let rhs = close_rel * scale;
        let inside = (near.abs() < two_1019) & (far.abs() < two_1019);
        let hit_sure = diff.abs() > 4.0 * e;
        let close_sure = (lhs - rhs).abs() > 8.0 * e + two_m50 * (lhs + rhs);
        hg[i] = !dead & (near <= far);
        cg[i] = lhs <= rhs;
        ug[i] = !(inside & close_sure & (hit_sure | dead));
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

    thread_local! {
        /// Lanes [`slab_block_flags`] ran through the true division on this thread.
        pub(super) static DIVIDED: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
    }

    /// The definition of [`slab_block_flags`]: [`slab_f64`], then the close formula.
    fn flags_want(ray: &Ray64, lo: [f64; 3], hi: [f64; 3], close_rel: f64) -> (bool, bool) {
        let w = slab_f64(ray.o, ray.d, ray.tmin, ray.tmax, lo, hi);
        let scale = 1.0f64.max(w.t_near.abs()).max(if w.t_far.is_finite() { w.t_far.abs() } else { 0.0 });
        (w.hit, (w.t_far - w.t_near).abs() <= close_rel * scale)
    }

    /// The flags taken from the reciprocal products with no margin (what a filter that trusts
    /// every lane would answer).
    fn flags_unfiltered(ray: &Ray64, lo: [f64; 3], hi: [f64; 3], close_rel: f64) -> (bool, bool) {
        let (mut near, mut far) = (ray.tmin, ray.tmax);
        for a in 0..3 {
            if ray.d[a] == 0.0 {
                if ray.o[a] < lo[a] || ray.o[a] > hi[a] {
                    return (false, (far - near).abs() <= close_rel * 1.0f64.max(near.abs()).max(far.abs()));
                }
                continue;
            }
            let r = 1.0 / ray.d[a];
            let (t0, t1) = ((lo[a] - ray.o[a]) * r, (hi[a] - ray.o[a]) * r);
            let (l, h) = if t0 <= t1 { (t0, t1) } else { (t1, t0) };
            near = if l > near { l } else { near };
            far = if h < far { h } else { far };
        }
        let scale = 1.0f64.max(near.abs()).max(if far.is_finite() { far.abs() } else { 0.0 });
        (near <= far, (far - near).abs() <= close_rel * scale)
    }

    /// Boxes whose interval is at the edge of both flags: a corner the ray touches (t_near
    /// = t_far up to rounding), an interval of length close_rel × scale up to a few parts in
    /// 10^7, and ordinary boxes; plus edge values.
    fn edge_box(g: &mut Lcg, ray: &Ray64, close_rel: f64) -> ([f64; 3], [f64; 3]) {
        let f = |g: &mut Lcg| (g.next() as f64) / (1u64 << 53) as f64;
        let t = (f(g) * 4.0 + 0.01) * 2f64.powi((g.next() % 20) as i32 - 10);
        let p = |t: f64| -> [f64; 3] { std::array::from_fn(|a| ray.o[a] + t * ray.d[a]) };
        let big = 1e3 * (1.0 + t);
        let (a, b) = ((g.next() % 3) as usize, (g.next() % 3) as usize);
        let kind = g.next() % 4;
        let t_far = match kind {
            // a touching corner: enters by axis a at t, leaves by axis b at t
            0 => t,
            // an interval of about close_rel · max(1, t)
            1 => t + close_rel * t.max(1.0) * (1.0 + (f(g) - 0.5) * 1e-6),
            2 => t * (1.0 + (f(g) - 0.5) * 2f64.powi(-48)),
            _ => t + f(g),
        };
        let (pn, pf) = (p(t), p(t_far));
        let mut lo = [0.0; 3];
        let mut hi = [0.0; 3];
        for k in 0..3 {
            let s = ray.d[k] >= 0.0;
            // planes far away on every axis but the entering (a) and leaving (b) ones
            lo[k] = if k == a && s { pn[k] } else { ray.o[k].min(pn[k]).min(pf[k]) - big };
            hi[k] = if k == a && !s { pn[k] } else { ray.o[k].max(pn[k]).max(pf[k]) + big };
            if k == b && a != b {
                if s {
                    hi[k] = pf[k];
                } else {
                    lo[k] = pf[k];
                }
            }
        }
        if g.next().is_multiple_of(8) {
            let k = (g.next() % 6) as usize;
            let x = g.value();
            if k < 3 {
                lo[k] = x;
            } else {
                hi[k - 3] = x;
            }
        }
        (lo, hi)
    }

    #[test]
    fn slab_flags_equal_the_slab_test_and_the_close_formula_on_every_level() {
        let mut g = Lcg(11);
        DIVIDED.with(|c| c.set(0));
        // lanes where the unfiltered products answer otherwise (the corpus reaches the edges)
        let mut differ = 0;
        let mut lanes = 0;
        for round in 0..6000 {
            let close_rel = [1e-9, 0.0, 1.0, 1e-15][round % 4];
            let unit = |g: &mut Lcg| (g.next() % 2_000_001) as f64 / 1e6 - 1.0;
            let dir = |g: &mut Lcg| match g.next() % 16 {
                0 => 0.0,
                1 => -0.0,
                2 => g.value(),
                3 => 2f64.powi(-1000) * (1.0 + unit(g)),
                4 => 2f64.powi(999) * (1.0 + unit(g)),
                5 => f64::from_bits(g.next() & 0x000f_ffff_ffff_ffff),
                _ => unit(g) * 2f64.powi((g.next() % 40) as i32 - 20),
            };
            let ray = Ray64 {
                o: std::array::from_fn(|_| if round % 9 == 0 { g.value() } else { unit(&mut g) * 10.0 }),
                d: std::array::from_fn(|_| dir(&mut g)),
                tmin: if round % 3 == 0 {
                    0.0
                } else if round % 11 == 0 {
                    g.value()
                } else {
                    unit(&mut g)
                },
                tmax: if round % 5 == 0 {
                    f64::INFINITY
                } else if round % 13 == 0 {
                    g.value()
                } else {
                    1e30
                },
            };
            let n = 1 + (g.next() % 150) as usize;
            let boxes: Vec<([f64; 3], [f64; 3])> = (0..n)
                .map(|_| {
                    if g.next().is_multiple_of(5) {
                        let v = |g: &mut Lcg| if g.next().is_multiple_of(3) { g.value() } else { unit(g) * 4.0 };
                        let (a, b): ([f64; 3], [f64; 3]) =
                            (std::array::from_fn(|_| v(&mut g)), std::array::from_fn(|_| v(&mut g)));
                        (std::array::from_fn(|k| a[k].min(b[k])), std::array::from_fn(|k| a[k].max(b[k])))
                    } else {
                        edge_box(&mut g, &ray, close_rel)
                    }
                })
                .collect();
            let cols: [Vec<f64>; 6] =
                std::array::from_fn(|k| boxes.iter().map(|(lo, hi)| if k < 3 { lo[k] } else { hi[k - 3] }).collect());
            let want: Vec<(bool, bool)> = boxes.iter().map(|&(lo, hi)| flags_want(&ray, lo, hi, close_rel)).collect();
            lanes += n;
            differ += boxes
                .iter()
                .zip(&want)
                .filter(|(&(lo, hi), w)| flags_unfiltered(&ray, lo, hi, close_rel) != **w)
                .count();
            for level in levels_here() {
                let (mut hit, mut close) = (vec![false; n], vec![false; n]);
                slab_block_flags(
                    level,
                    ray.o,
                    ray.d,
                    ray.tmin,
                    ray.tmax,
                    std::array::from_fn(|k| &cols[k][..]),
                    close_rel,
                    &mut hit,
                    &mut close,
                );
                for i in 0..n {
                    assert_eq!((hit[i], close[i]), want[i], "{level:?} round {round} box {i}: {ray:?} {:?}", boxes[i]);
                }
            }
        }
        // the corpus must hold lanes a filter without its margins would get wrong, and most
        // lanes must be settled by the products (the filter is exercised, not bypassed)
        assert!(differ > 200, "only {differ} of {lanes} lanes separate the products from the division");
        let divided = DIVIDED.with(|c| c.get());
        let runs = lanes * levels_here().len();
        assert!(divided > differ && divided < runs - runs / 5, "{divided} of {runs} lanes divided");
    }

    #[test]
    fn slab_flags_hold_at_both_ends_of_the_exponent_range() {
        // rays from the origin (or beside it) whose touching corners and near-empty intervals
        // lie where the quotients are subnormal or about to overflow, against tmin and tmax at
        // the ends of the range
        let mut g = Lcg(23);
        let mut differ = 0;
        let mut lanes = 0;
        DIVIDED.with(|c| c.set(0));
        for round in 0..20000 {
            let close_rel = [1e-9, 0.0, 1.0][round % 3];
            let f = |g: &mut Lcg| (g.next() as f64) / (1u64 << 53) as f64 + 0.5;
            let sign = |g: &mut Lcg| if g.next().is_multiple_of(2) { 1.0 } else { -1.0 };
            let ray = Ray64 {
                o: std::array::from_fn(
                    |_| if g.next().is_multiple_of(4) { f64::from_bits(g.next() % 16) } else { 0.0 },
                ),
                d: std::array::from_fn(|_| sign(&mut g) * f(&mut g) * 2f64.powi((g.next() % 2001) as i32 - 1000)),
                tmin: [0.0, -0.0, -f64::MAX, f64::NEG_INFINITY, 2f64.powi(-1074)][(g.next() % 5) as usize],
                tmax: [f64::MAX, f64::INFINITY, 2f64.powi(1023) * 1.5, 2f64.powi(-1070)][(g.next() % 4) as usize],
            };
            let n = 1 + (g.next() % 40) as usize;
            let boxes: Vec<([f64; 3], [f64; 3])> = (0..n)
                .map(|_| {
                    // the entry and exit distances, each tiny, huge or in between
                    let t = |g: &mut Lcg| {
                        let e = match g.next() % 3 {
                            0 => (g.next() % 60) as i32 - 1080,
                            1 => (g.next() % 20) as i32 + 1005,
                            _ => (g.next() % 200) as i32 - 100,
                        };
                        f(g) * 2f64.powi(e)
                    };
                    let tn = t(&mut g);
                    let tf = match g.next() % 4 {
                        0 => tn,
                        1 => tn + close_rel * tn.max(1.0) * (1.0 + (f(&mut g) - 1.0) * 1e-6),
                        2 => tn * (1.0 + (f(&mut g) - 1.0) * 2f64.powi(-48)),
                        _ => t(&mut g),
                    };
                    let (a, b) = ((g.next() % 3) as usize, (g.next() % 3) as usize);
                    // every axis spans the ray from tn / 2 to 2 tf; the entering (a) and
                    // leaving (b) axes' planes then moved to tn and tf
                    let p = |t: f64| -> [f64; 3] { std::array::from_fn(|k| ray.o[k] + t * ray.d[k]) };
                    let (p0, p1) = (p(tn / 2.0), p(tf * 2.0));
                    let mut lo: [f64; 3] = std::array::from_fn(|k| p0[k].min(p1[k]));
                    let mut hi: [f64; 3] = std::array::from_fn(|k| p0[k].max(p1[k]));
                    for (k, t) in [(a, tn), (b, tf)] {
                        let p = ray.o[k] + t * ray.d[k];
                        if (k == a) == (ray.d[k] >= 0.0) {
                            lo[k] = p;
                        } else {
                            hi[k] = p;
                        }
                    }
                    for k in 0..3 {
                        if lo[k] > hi[k] {
                            std::mem::swap(&mut lo[k], &mut hi[k]);
                        }
                    }
                    (lo, hi)
                })
                .collect();
            let cols: [Vec<f64>; 6] =
                std::array::from_fn(|k| boxes.iter().map(|(lo, hi)| if k < 3 { lo[k] } else { hi[k - 3] }).collect());
            let want: Vec<(bool, bool)> = boxes.iter().map(|&(lo, hi)| flags_want(&ray, lo, hi, close_rel)).collect();
            differ += boxes
                .iter()
                .zip(&want)
                .filter(|(&(lo, hi), w)| flags_unfiltered(&ray, lo, hi, close_rel) != **w)
                .count();
            lanes += n;
            for level in levels_here() {
                let (mut hit, mut close) = (vec![false; n], vec![false; n]);
                let c = std::array::from_fn(|k| &cols[k][..]);
                slab_block_flags(level, ray.o, ray.d, ray.tmin, ray.tmax, c, close_rel, &mut hit, &mut close);
                for i in 0..n {
                    assert_eq!((hit[i], close[i]), want[i], "{level:?} round {round} box {i}: {ray:?} {:?}", boxes[i]);
                }
            }
        }
        assert!(differ > 100, "only {differ} lanes separate the products from the division");
        let divided = DIVIDED.with(|c| c.get());
        let runs = lanes * levels_here().len();
        assert!(divided > differ && divided < runs - runs / 5, "{divided} of {runs} lanes divided");
    }

    #[test]
    #[should_panic(expected = "close_rel")]
    fn slab_flags_refuse_a_close_rel_above_one() {
        let c = [0.0];
        let (mut h, mut cl) = ([false], [false]);
        slab_block_flags(Level::Scalar, [0.0; 3], [1.0; 3], 0.0, 1.0, [&c[..]; 6], 2.0, &mut h, &mut cl);
    }
}
