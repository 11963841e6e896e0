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

/// The exact Möller–Trumbore decision in rational arithmetic (no rounding anywhere): the ray
/// hits when `|det| > threshold` (culling: `det > threshold`), the barycentrics are in the closed
/// triangle and `tmin <= t <= tmax`, all decided on det-scaled quantities
/// (u' = s·p, v' = d·q, t' = e2·q against 0 and det). `None` when an input is not finite
/// (tmax may be +∞).
pub fn intersect_exact(ray: &Ray64, tri: &Tri64, faces: Faces) -> Option<bool> {
    use num_rational::BigRational;
    use num_traits::{Signed, Zero};
    let finite = ray.o.iter().chain(&ray.d).chain(tri.v.iter().flatten()).all(|x| x.is_finite())
        && ray.tmin.is_finite()
        && !ray.tmax.is_nan()
        && faces.det_threshold.is_finite();
    if !finite {
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
}
