//! Reference ray–box tests: an f64 slab test with its own NaN-free policy, and the exact
//! decision in rational arithmetic that judges every disagreement.
//!
//! The box is closed; the ray is `o + t·d` for t in the closed interval [tmin, tmax]. An axis
//! with d = 0 (either sign) constrains nothing when o lies within [min, max] on that axis
//! (the ray runs inside or on the face plane) and rejects the box otherwise. No NaN is formed.

use num_rational::BigRational;

/// Result of the f64 reference: entry and exit distances and the decision.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlabResult {
    /// The ray meets the closed box within [tmin, tmax].
    pub hit: bool,
    /// Entry distance (>= tmin).
    pub t_near: f64,
    /// Exit distance (<= tmax).
    pub t_far: f64,
}

/// f64 slab test: per axis t = (plane − o) / d with a true divide; zero components per the rule above.
pub fn slab_f64(o: [f64; 3], d: [f64; 3], tmin: f64, tmax: f64, min: [f64; 3], max: [f64; 3]) -> SlabResult {
    let mut near = tmin;
    let mut far = tmax;
    for a in 0..3 {
        if d[a] == 0.0 {
            if o[a] < min[a] || o[a] > max[a] {
                return SlabResult { hit: false, t_near: near, t_far: far };
            }
            continue;
        }
        let t0 = (min[a] - o[a]) / d[a];
        let t1 = (max[a] - o[a]) / d[a];
        let (lo, hi) = if t0 <= t1 { (t0, t1) } else { (t1, t0) };
        if lo > near {
            near = lo;
        }
        if hi < far {
            far = hi;
        }
    }
    SlabResult { hit: near <= far, t_near: near, t_far: far }
}

fn q(x: f64) -> BigRational {
    BigRational::from_float(x).expect("finite")
}

/// The exact decision (rational arithmetic): `None` (no decision) when an origin or direction
/// component is not finite or any input is NaN; ±∞ is allowed for tmin, tmax and for box
/// planes (an infinite plane bounds nothing on its side, and a box whose min is +∞ or max is
/// −∞ is empty).
pub fn slab_exact(o: [f64; 3], d: [f64; 3], tmin: f64, tmax: f64, min: [f64; 3], max: [f64; 3]) -> Option<bool> {
    if o.iter().chain(&d).any(|x| !x.is_finite())
        || tmin.is_nan()
        || tmax.is_nan()
        || min.iter().chain(&max).any(|x| x.is_nan())
    {
        return None;
    }
    Some(slab_exact_finite(o, d, tmin, tmax, min, max))
}

fn slab_exact_finite(o: [f64; 3], d: [f64; 3], tmin: f64, tmax: f64, min: [f64; 3], max: [f64; 3]) -> bool {
    // interval [near, far] of t; None = unbounded on that side
    let mut near: Option<BigRational> = if tmin.is_finite() { Some(q(tmin)) } else { None };
    let mut far: Option<BigRational> = if tmax.is_finite() { Some(q(tmax)) } else { None };
    if tmin == f64::INFINITY || tmax == f64::NEG_INFINITY {
        return false;
    }
    for a in 0..3 {
        if min[a] > max[a] || min[a] == f64::INFINITY || max[a] == f64::NEG_INFINITY {
            return false;
        }
        if d[a] == 0.0 {
            if o[a] < min[a] || o[a] > max[a] {
                return false;
            }
            continue;
        }
        let da = q(d[a]);
        let oa = q(o[a]);
        // plane distances; an infinite plane gives an unbounded side
        let t = |plane: f64| -> Option<BigRational> { plane.is_finite().then(|| (q(plane) - &oa) / &da) };
        let (t_min_plane, t_max_plane) = (t(min[a]), t(max[a]));
        // with d > 0 the min plane is the entry; with d < 0 the max plane is
        let (lo, hi) = if d[a] > 0.0 { (t_min_plane, t_max_plane) } else { (t_max_plane, t_min_plane) };
        if let Some(lo) = lo {
            if near.as_ref().is_none_or(|n| &lo > n) {
                near = Some(lo);
            }
        }
        if let Some(hi) = hi {
            if far.as_ref().is_none_or(|f| &hi < f) {
                far = Some(hi);
            }
        }
    }
    match (near, far) {
        (Some(n), Some(f)) => n <= f,
        _ => true,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const LO: [f64; 3] = [-1.0, -1.0, -1.0];
    const HI: [f64; 3] = [1.0, 1.0, 1.0];

    #[test]
    fn through_the_middle_and_beside() {
        let r = slab_f64([-3.0, 0.0, 0.0], [1.0, 0.0, 0.0], 0.0, f64::INFINITY, LO, HI);
        assert_eq!((r.hit, r.t_near, r.t_far), (true, 2.0, 4.0));
        assert!(slab_exact_finite([-3.0, 0.0, 0.0], [1.0, 0.0, 0.0], 0.0, f64::INFINITY, LO, HI));
        assert!(!slab_f64([-3.0, 2.0, 0.0], [1.0, 0.0, 0.0], 0.0, f64::INFINITY, LO, HI).hit);
        assert!(!slab_exact_finite([-3.0, 2.0, 0.0], [1.0, 0.0, 0.0], 0.0, f64::INFINITY, LO, HI));
    }

    #[test]
    fn grazing_a_face_in_its_plane_hits_the_closed_box() {
        for d in [[1.0, 0.0, 0.0], [1.0, -0.0, 0.0]] {
            assert!(slab_f64([-3.0, 1.0, 0.0], d, 0.0, f64::INFINITY, LO, HI).hit);
            assert!(slab_exact_finite([-3.0, 1.0, 0.0], d, 0.0, f64::INFINITY, LO, HI));
        }
        // touching an edge exactly
        assert!(slab_exact_finite([-3.0, 1.0, 1.0], [1.0, 0.0, 0.0], 0.0, f64::INFINITY, LO, HI));
        // the line x + y = 2 touches the corner (1, 1); x + y = 2.001 passes beside it
        assert!(slab_exact_finite([3.0, -1.0, 0.0], [-1.0, 1.0, 0.0], 0.0, f64::INFINITY, LO, HI));
        assert!(!slab_exact_finite([3.0, -0.999, 0.0], [-1.0, 1.0, 0.0], 0.0, f64::INFINITY, LO, HI));
    }

    #[test]
    fn non_finite_rays_have_no_decision() {
        for bad in [f64::INFINITY, f64::NEG_INFINITY, f64::NAN] {
            assert_eq!(slab_exact([bad, 0.0, 0.0], [1.0, 0.0, 0.0], 0.0, f64::INFINITY, LO, HI), None);
            assert_eq!(slab_exact([-3.0, 0.0, 0.0], [1.0, bad, 0.0], 0.0, f64::INFINITY, LO, HI), None);
        }
        assert_eq!(slab_exact([-3.0, 0.0, 0.0], [1.0, 0.0, 0.0], 0.0, f64::NAN, LO, HI), None);
        assert_eq!(slab_exact([-3.0, 0.0, 0.0], [1.0, 0.0, 0.0], 0.0, f64::INFINITY, LO, HI), Some(true));
        // an empty box (min +inf, max -inf) is missed
        let (e0, e1) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        assert_eq!(slab_exact([-3.0, 0.0, 0.0], [1.0, 0.0, 0.0], 0.0, f64::INFINITY, e0, e1), Some(false));
    }

    #[test]
    fn interval_limits_are_closed() {
        assert!(slab_exact_finite([-3.0, 0.0, 0.0], [1.0, 0.0, 0.0], 0.0, 2.0, LO, HI));
        assert!(!slab_exact_finite([-3.0, 0.0, 0.0], [1.0, 0.0, 0.0], 0.0, 1.999, LO, HI));
        assert!(slab_exact_finite([-3.0, 0.0, 0.0], [1.0, 0.0, 0.0], 4.0, 9.0, LO, HI));
        assert!(!slab_exact_finite([-3.0, 0.0, 0.0], [1.0, 0.0, 0.0], 4.001, 9.0, LO, HI));
    }
}
