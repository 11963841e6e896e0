//! Classic Möller–Trumbore in f64, in the textbook operation order (divide first, then the
//! barycentric tests), with the hit point's barycentric margin and the determinant's size.

/// A ray in f64.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray64 {
    /// Origin.
    pub o: [f64; 3],
    /// Direction.
    pub d: [f64; 3],
    /// Smallest accepted t (inclusive).
    pub tmin: f64,
    /// Largest accepted t (inclusive).
    pub tmax: f64,
}

/// A triangle in f64.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tri64 {
    /// Vertices.
    pub v: [[f64; 3]; 3],
}

/// Result of the reference test.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MtResult {
    /// The ray meets the triangle within [tmin, tmax].
    pub hit: bool,
    /// Distance along the ray to the triangle's plane (NaN if det is 0).
    pub t: f64,
    /// Barycentric weight of v1.
    pub u: f64,
    /// Barycentric weight of v2.
    pub v: f64,
    /// The determinant e1·(d × e2).
    pub det: f64,
    /// |det| / (|d|·|e1|·|e2|): the sine-like conditioning of the test (0 = ray in the plane).
    pub det_rel: f64,
    /// min(u, v, 1 − u − v): positive inside, negative outside; the distance to the nearest
    /// edge in barycentric units.
    pub bary_margin: f64,
    /// Distance in scene units from the plane point to the nearest edge line (signed like the margin).
    pub edge_dist: f64,
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

/// Face test options of the reference.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Faces {
    /// Reject back faces: a hit needs det > threshold (otherwise |det| > threshold).
    pub cull: bool,
    /// det threshold (>= 0).
    pub det_threshold: f64,
}

/// Intersects `ray` with `tri` under the face options.
pub fn intersect(ray: &Ray64, tri: &Tri64, faces: Faces) -> MtResult {
    let [v0, v1, v2] = tri.v;
    let e1 = sub(v1, v0);
    let e2 = sub(v2, v0);
    let p = cross(ray.d, e2);
    let det = dot(e1, p);
    let inv = 1.0 / det;
    let s = sub(ray.o, v0);
    let u = dot(s, p) * inv;
    let q = cross(s, e1);
    let v = dot(ray.d, q) * inv;
    let t = dot(e2, q) * inv;
    let w = 1.0 - u - v;
    let face_ok = if faces.cull { det > faces.det_threshold } else { det.abs() > faces.det_threshold };
    let hit = face_ok && det.is_finite() && u >= 0.0 && v >= 0.0 && w >= 0.0 && t >= ray.tmin && t <= ray.tmax;
    let bary_margin = u.min(v).min(w);
    // heights of the triangle over each edge: 2·area / |edge|
    let area2 = norm(cross(e1, e2));
    let e3 = sub(v2, v1);
    let edge_dist = [(u, norm(e2)), (v, norm(e1)), (w, norm(e3))]
        .iter()
        .map(|&(b, len)| if len > 0.0 { b * area2 / len } else { 0.0 })
        .fold(f64::INFINITY, f64::min);
    let scale = norm(ray.d) * norm(e1) * norm(e2);
    let det_rel = if scale > 0.0 { det.abs() / scale } else { 0.0 };
    MtResult { hit, t, u, v, det, det_rel, bary_margin, edge_dist }
}

/// The exact Möller–Trumbore decision (no rounding anywhere): the ray hits when
/// `|det| > threshold` (culling: `det > threshold`), the barycentrics are in the closed
/// triangle and `tmin <= t <= tmax`, all decided on det-scaled quantities
/// (u' = s·p, v' = d·q, t' = e2·q against 0 and det). `None` when an input is not finite
/// (tmax may be +∞). The same decision as [`intersect_exact_rational`]: in 128-bit integers
/// when the inputs allow ([`exact_in_integers`]), else in rational arithmetic.
pub fn intersect_exact(ray: &Ray64, tri: &Tri64, faces: Faces) -> Option<bool> {
    exact_in_integers(ray, tri, faces).or_else(|| intersect_exact_rational(ray, tri, faces))
}

/// Whether the exact decision has its inputs: every coordinate, tmin and the threshold finite,
/// tmax not NaN (it may be +∞).
fn exact_inputs_finite(ray: &Ray64, tri: &Tri64, faces: Faces) -> bool {
    ray.o.iter().chain(&ray.d).chain(tri.v.iter().flatten()).all(|x| x.is_finite())
        && ray.tmin.is_finite()
        && !ray.tmax.is_nan()
        && faces.det_threshold.is_finite()
}

/// `x = m · 2^e` exactly, `m` odd (or 0, with e = 0); `x` finite.
fn dyadic(x: f64) -> (i64, i32) {
    let b = x.to_bits();
    let (exp, frac) = (((b >> 52) & 0x7ff) as i32, (b & ((1 << 52) - 1)) as i64);
    let (m, e) = if exp == 0 { (frac, -1074) } else { (frac | 1 << 52, exp - 1075) };
    if m == 0 {
        return (0, 0);
    }
    let tz = m.trailing_zeros();
    let m = m >> tz;
    (if x < 0.0 { -m } else { m }, e + tz as i32)
}

/// Bits in the integers of [`exact_in_integers`]: positions and directions as integers below
/// 2^39 in magnitude keep every product of three (and the sums the decision reads) below 2^126.
const INT_BITS: u32 = 39;

/// [`intersect_exact_rational`]'s decision in 128-bit integers, or `None` when the inputs do
/// not allow it (an input not finite, or the positions — vertices and origin — or the
/// direction components not all integers below 2^39 once scaled by one power of two per
/// group). With positions `P·2^a` and direction `D·2^b` (P, D integers), det, u' and v' are
/// integers times 2^(2a + b) and t' an integer times 2^(3a), each computed exactly (below 2^126);
/// the threshold, tmin and tmax (`m·2^e`) are compared with them exactly, in big integers where a
/// product would not fit.
pub fn exact_in_integers(ray: &Ray64, tri: &Tri64, faces: Faces) -> Option<bool> {
    use num_bigint::BigInt;
    if !exact_inputs_finite(ray, tri, faces) {
        return None;
    }
    // one scale per group: its smallest exponent; every value an integer below 2^INT_BITS
    let scale = |xs: &[f64]| -> Option<(Vec<i128>, i32)> {
        let ds: Vec<(i64, i32)> = xs.iter().map(|&x| dyadic(x)).collect();
        let e0 = ds.iter().filter(|d| d.0 != 0).map(|d| d.1).min().unwrap_or(0);
        let mut out = Vec::with_capacity(xs.len());
        for &(m, e) in &ds {
            let sh = (e - e0) as u32;
            let bits = 64 - m.unsigned_abs().leading_zeros();
            if m != 0 && bits + sh > INT_BITS {
                return None;
            }
            out.push(if m == 0 { 0 } else { (m as i128) << sh });
        }
        Some((out, e0))
    };
    let pos: Vec<f64> = tri.v.iter().flatten().chain(&ray.o).copied().collect();
    let (p, a) = scale(&pos)?;
    let (dv, b) = scale(&ray.d)?;
    let v = |k: usize| [p[3 * k], p[3 * k + 1], p[3 * k + 2]];
    let (v0, v1, v2, o) = (v(0), v(1), v(2), v(3));
    let d = [dv[0], dv[1], dv[2]];
    let sub = |x: [i128; 3], y: [i128; 3]| [x[0] - y[0], x[1] - y[1], x[2] - y[2]];
    let cross =
        |x: [i128; 3], y: [i128; 3]| [x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2], x[0] * y[1] - x[1] * y[0]];
    let dot = |x: [i128; 3], y: [i128; 3]| x[0] * y[0] + x[1] * y[1] + x[2] * y[2];
    let (e1, e2, s) = (sub(v1, v0), sub(v2, v0), sub(o, v0));
    let pv = cross(d, e2);
    let qv = cross(s, e1);
    let (det, u, w, t) = (dot(e1, pv), dot(s, pv), dot(d, qv), dot(e2, qv));
    // the exact values: det, u', v' are these times 2^(2a + b), t' times 2^(3a)
    let (ed, et) = (2 * a + b, 3 * a);
    // x·2^ex against y·2^ey (y = m·2^e of an f64), exactly
    let cmp = |x: &BigInt, ex: i32, y: f64| -> std::cmp::Ordering {
        let (m, e) = dyadic(y);
        let (mut l, mut r) = (x.clone(), BigInt::from(m));
        if ex >= e {
            l <<= (ex - e) as usize;
        } else {
            r <<= (e - ex) as usize;
        }
        l.cmp(&r)
    };
    let big = |x: i128| BigInt::from(x);
    let thr = faces.det_threshold;
    let face_ok = if thr == 0.0 {
        if faces.cull {
            det > 0
        } else {
            det != 0
        }
    } else if faces.cull {
        cmp(&big(det), ed, thr).is_gt()
    } else {
        cmp(&big(det.abs()), ed, thr).is_gt()
    };
    if !face_ok || det == 0 {
        return Some(false);
    }
    // divide through by det's sign
    let sg = det.signum();
    let (u, w, t, det) = (u * sg, w * sg, t * sg, det * sg);
    if u < 0 || w < 0 || u + w > det {
        return Some(false);
    }
    // t' against tmin·det and tmax·det: t'·2^et against (m·det)·2^(e + ed)
    let t_vs = |lim: f64| -> std::cmp::Ordering {
        let (m, e) = dyadic(lim);
        let rhs = BigInt::from(m) * big(det);
        let (mut l, mut r) = (big(t), rhs);
        if et >= e + ed {
            l <<= (et - e - ed) as usize;
        } else {
            r <<= (e + ed - et) as usize;
        }
        l.cmp(&r)
    };
    let lo_ok = if ray.tmin == 0.0 { t >= 0 } else { t_vs(ray.tmin).is_ge() };
    let hi_ok = ray.tmax.is_infinite() || t_vs(ray.tmax).is_le();
    Some(lo_ok && hi_ok)
}

/// The exact Möller–Trumbore decision of [`intersect_exact`] in rational arithmetic on every
/// input.
pub fn intersect_exact_rational(ray: &Ray64, tri: &Tri64, faces: Faces) -> Option<bool> {
    use num_rational::BigRational;
    use num_traits::{Signed, Zero};
    if !exact_inputs_finite(ray, tri, faces) {
        return None;
    }
    let q = |x: f64| BigRational::from_float(x).expect("finite");
    let v3 = |p: [f64; 3]| p.map(q);
    let sub3 =
        |a: &[BigRational; 3], b: &[BigRational; 3]| -> [BigRational; 3] { std::array::from_fn(|i| &a[i] - &b[i]) };
    let cross3 = |a: &[BigRational; 3], b: &[BigRational; 3]| -> [BigRational; 3] {
        [&a[1] * &b[2] - &a[2] * &b[1], &a[2] * &b[0] - &a[0] * &b[2], &a[0] * &b[1] - &a[1] * &b[0]]
    };
    let dot3 =
        |a: &[BigRational; 3], b: &[BigRational; 3]| -> BigRational { &a[0] * &b[0] + &a[1] * &b[1] + &a[2] * &b[2] };
    let [v0, v1, v2] = tri.v.map(v3);
    let (o, d) = (v3(ray.o), v3(ray.d));
    let e1 = sub3(&v1, &v0);
    let e2 = sub3(&v2, &v0);
    let p = cross3(&d, &e2);
    let det = dot3(&e1, &p);
    let s = sub3(&o, &v0);
    let qv = cross3(&s, &e1);
    let (u, v, t) = (dot3(&s, &p), dot3(&d, &qv), dot3(&e2, &qv));
    let thr = q(faces.det_threshold);
    let face_ok = if faces.cull { det > thr } else { det.abs() > thr };
    if !face_ok || det.is_zero() {
        return Some(false);
    }
    // divide through by det's sign: compare u, v, u + v, t against 0, det and the t interval
    let sgn =
        if det.is_positive() { BigRational::from_integer(1.into()) } else { BigRational::from_integer((-1).into()) };
    let (u, v, t, det) = (&u * &sgn, &v * &sgn, &t * &sgn, &det * &sgn);
    let zero = BigRational::zero();
    let in_t = t >= q(ray.tmin) * &det && (ray.tmax.is_infinite() || t <= q(ray.tmax) * &det);
    Some(u >= zero && v >= zero && &u + &v <= det && in_t)
}

/// Nearest hit of `ray` over `tris`: (index, t); on equal t the lower index wins.
pub fn closest_hit(ray: &Ray64, tris: &[Tri64], faces: Faces) -> Option<(usize, f64)> {
    let mut best: Option<(usize, f64)> = None;
    for (i, t) in tris.iter().enumerate() {
        let r = intersect(ray, t, faces);
        if r.hit && best.is_none_or(|(_, bt)| r.t < bt) {
            best = Some((i, r.t));
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_tri() -> Tri64 {
        Tri64 { v: [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] }
    }

    #[test]
    fn hits_the_plane_at_the_expected_point() {
        let ray = Ray64 { o: [0.25, 0.25, 2.0], d: [0.0, 0.0, -1.0], tmin: 0.0, tmax: f64::INFINITY };
        let r = intersect(&ray, &unit_tri(), Faces::default());
        assert!(r.hit);
        assert_eq!((r.t, r.u, r.v), (2.0, 0.25, 0.25));
        assert_eq!(r.bary_margin, 0.25);
        assert_eq!(r.edge_dist, 0.25);
        assert_eq!(r.det_rel, 1.0);
    }

    #[test]
    fn the_exact_decision_includes_edges_and_decides_what_f64_cannot() {
        let t = unit_tri();
        let down = |x: f64, y: f64| Ray64 { o: [x, y, 2.0], d: [0.0, 0.0, -1.0], tmin: 0.0, tmax: f64::INFINITY };
        let f = Faces::default();
        // on the hypotenuse u + v = 1 exactly, on a vertex, just outside
        assert_eq!(intersect_exact(&down(0.5, 0.5), &t, f), Some(true));
        assert_eq!(intersect_exact(&down(0.0, 1.0), &t, f), Some(true));
        assert_eq!(intersect_exact(&down(0.5, 0.5 + f64::EPSILON), &t, f), Some(false));
        // a point 2^-54 outside the hypotenuse (one ulp of 0.25): f64 computes w = (1 - u) - v
        // with 1 - u = 0.75 - 2^-54 a tie that rounds to 0.75, so w = 0 and it reports a hit
        let e = (-54f64).exp2();
        assert!(intersect(&down(0.25 + e, 0.75), &t, f).hit, "f64 rounds it in");
        assert_eq!(intersect_exact(&down(0.25 + e, 0.75), &t, f), Some(false));
        // t interval, culling, threshold, non-finite input
        assert_eq!(intersect_exact(&Ray64 { tmax: 2.0, ..down(0.2, 0.2) }, &t, f), Some(true));
        assert_eq!(intersect_exact(&Ray64 { tmax: 1.5, ..down(0.2, 0.2) }, &t, f), Some(false));
        let below = Ray64 { o: [0.25, 0.25, -2.0], d: [0.0, 0.0, 1.0], tmin: 0.0, tmax: f64::INFINITY };
        assert_eq!(intersect_exact(&below, &t, f), Some(true));
        assert_eq!(intersect_exact(&below, &t, Faces { cull: true, det_threshold: 0.0 }), Some(false));
        assert_eq!(intersect_exact(&down(0.2, 0.2), &t, Faces { cull: false, det_threshold: 1.0 }), Some(false));
        assert_eq!(intersect_exact(&down(f64::NAN, 0.2), &t, f), None);
    }

    #[test]
    fn misses_outside_and_behind_and_culls_back_faces() {
        let t = unit_tri();
        let outside = Ray64 { o: [0.75, 0.75, 2.0], d: [0.0, 0.0, -1.0], tmin: 0.0, tmax: f64::INFINITY };
        let r = intersect(&outside, &t, Faces::default());
        assert!(!r.hit && r.bary_margin < 0.0);
        let behind = Ray64 { o: [0.25, 0.25, 2.0], d: [0.0, 0.0, 1.0], tmin: 0.0, tmax: f64::INFINITY };
        assert!(!intersect(&behind, &t, Faces::default()).hit);
        // from below the ray sees the back face (normal +z)
        let below = Ray64 { o: [0.25, 0.25, -2.0], d: [0.0, 0.0, 1.0], tmin: 0.0, tmax: f64::INFINITY };
        assert!(intersect(&below, &t, Faces::default()).hit);
        assert!(!intersect(&below, &t, Faces { cull: true, det_threshold: 0.0 }).hit);
    }

    #[test]
    fn closest_hit_takes_the_nearest_and_the_first_on_ties() {
        let near = Tri64 { v: [[-1.0, -1.0, 1.0], [3.0, -1.0, 1.0], [-1.0, 3.0, 1.0]] };
        let ray = Ray64 { o: [0.25, 0.25, 2.0], d: [0.0, 0.0, -1.0], tmin: 0.0, tmax: f64::INFINITY };
        assert_eq!(closest_hit(&ray, &[unit_tri(), near, near], Faces::default()), Some((1, 1.0)));
    }

    /// The integer path decides as the rational arithmetic does, on every input it takes:
    /// rays and triangles on coarse grids (values with 3 to 24 significant bits, so that the
    /// decisions tie often: vertices on the ray, u' or v' = 0, u' + v' = det, t' = tmin·det),
    /// spread over exponents, zeros of both signs, subnormals and huge values, thresholds
    /// and t limits of every kind, both face rules; and it takes most of the coarse inputs.
    #[test]
    fn the_integer_path_decides_as_rational_arithmetic() {
        struct G(u64);
        impl G {
            fn next(&mut self) -> u64 {
                self.0 ^= self.0 << 13;
                self.0 ^= self.0 >> 7;
                self.0 ^= self.0 << 17;
                self.0
            }
            fn val(&mut self, bits: i32, spread: u64, wild: bool) -> f64 {
                match self.next() % if wild { 23 } else { 1 << 20 } {
                    0 => 0.0,
                    1 => -0.0,
                    2 => f64::from_bits(self.next() & 0x000f_ffff_ffff_ffff),
                    3 => 1e300 * ((self.next() % 5) as f64 - 2.0),
                    _ => {
                        let m = (self.next() % (1u64 << bits)) as f64 - (1u64 << (bits - 1)) as f64;
                        m * 2f64.powi((self.next() % spread) as i32 - (spread / 2) as i32 - bits)
                    }
                }
            }
        }
        let mut g = G(0x9e37_79b9_7f4a_7c15);
        let (mut taken, mut total, mut hits) = (0, 0, 0);
        for round in 0..12_000u64 {
            let wild = round % 4 == 0;
            let bits = 3 + (round % 22) as i32;
            let spread = [2, 8, 30, 300][(round / 22 % 4) as usize];
            // a few shared values, so that vertices and the origin coincide or line up
            let pool: Vec<f64> = (0..6).map(|_| g.val(bits, spread, wild)).collect();
            let pick = |g: &mut G| {
                let k = g.next();
                if k.is_multiple_of(3) {
                    pool[(k / 3 % 6) as usize]
                } else {
                    g.val(bits, spread, wild)
                }
            };
            let v3 = |g: &mut G| -> [f64; 3] { [pick(g), pick(g), pick(g)] };
            let tri = Tri64 { v: [v3(&mut g), v3(&mut g), v3(&mut g)] };
            let (mut o, mut d) = (v3(&mut g), v3(&mut g));
            if round % 4 == 2 {
                // the origin on the triangle's plane, at a vertex, on an edge or inside: t' = 0
                let w = [0.0, 0.5, 1.0, 0.25];
                let (al, be) = (w[(g.next() % 4) as usize], w[(g.next() % 4) as usize] / 2.0);
                let [v0, v1, v2] = tri.v;
                o = std::array::from_fn(|k| v0[k] + al * (v1[k] - v0[k]) + be * (v2[k] - v0[k]));
            }
            if round % 2 == 1 {
                // aimed at a point of the triangle's plane on a coarse barycentric grid (its
                // vertices, edges, inside and just outside): t = 1 there when d is exact
                let w = [0.0, 0.25, 0.5, 0.75, 1.0, 1.25, -0.25];
                let (al, be) = (w[(g.next() % 7) as usize], w[(g.next() % 7) as usize]);
                let [v0, v1, v2] = tri.v;
                let p: [f64; 3] = std::array::from_fn(|k| v0[k] + al * (v1[k] - v0[k]) + be * (v2[k] - v0[k]));
                d = std::array::from_fn(|k| p[k] - o[k]);
            }
            let lim = |k: u64| [0.0, -0.0, 1.0, 0.5, 3.0, f64::INFINITY, 1e-310, -2.0][(k % 8) as usize];
            let ray = Ray64 { o, d, tmin: lim(g.next()), tmax: lim(g.next()) };
            let thr = [0.0, 0.0, 2f64.powi(-20), 0.75][(round / 2 % 4) as usize];
            let faces = Faces { cull: round % 2 == 0, det_threshold: thr };
            let want = intersect_exact_rational(&ray, &tri, faces);
            total += 1;
            if let Some(got) = exact_in_integers(&ray, &tri, faces) {
                taken += 1;
                hits += got as u32;
                assert_eq!(Some(got), want, "{ray:?} {tri:?} {faces:?}");
            }
            assert_eq!(intersect_exact(&ray, &tri, faces), want);
        }
        assert!(taken * 5 > total * 2, "the integer path took {taken} of {total}");
        assert!(hits > 300, "only {hits} hits");
    }
}
