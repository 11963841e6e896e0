//! Reference ray–box tests: an f64 slab test with its own NaN-free policy, and the exact
//! decision in rational arithmetic that judges every disagreement.
//!
//! The box is closed; the ray is `o + t·d` for t in the closed interval [tmin, tmax]. An axis
//! with d = 0 (either sign) constrains nothing when o lies within [min, max] on that axis
//! (the ray runs inside or on the face plane) and rejects the box otherwise. No NaN is formed.

use num_bigint::{BigInt, Sign};
#[cfg(test)]
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

#[cfg(test)]
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
    slab_exact_in::<Filtered>(o, d, tmin, tmax, min, max)
}

/// The exact numbers the decision runs on: a finite f64's value, a plane distance
/// `(plane − o) / dir` (all finite, `dir` nonzero) and their order, each exact.
trait Exact: Sized {
    /// A finite f64, exactly.
    fn of(x: f64) -> Self;
    /// `(plane − o) / dir`, exactly.
    fn distance(plane: f64, o: f64, dir: f64) -> Self;
    /// `self > o`, exactly.
    fn gt(&self, o: &Self) -> bool;
}

/// The decision on finite origin and direction, no NaN, in the exact numbers `T`.
fn slab_exact_in<T: Exact>(o: [f64; 3], d: [f64; 3], tmin: f64, tmax: f64, min: [f64; 3], max: [f64; 3]) -> bool {
    // interval [near, far] of t; None = unbounded on that side
    let mut near: Option<T> = if tmin.is_finite() { Some(T::of(tmin)) } else { None };
    let mut far: Option<T> = if tmax.is_finite() { Some(T::of(tmax)) } else { None };
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
        // plane distances; an infinite plane gives an unbounded side
        let t = |plane: f64| plane.is_finite().then(|| T::distance(plane, o[a], d[a]));
        let (t_min_plane, t_max_plane) = (t(min[a]), t(max[a]));
        // with d > 0 the min plane is the entry; with d < 0 the max plane is
        let (lo, hi) = if d[a] > 0.0 { (t_min_plane, t_max_plane) } else { (t_max_plane, t_min_plane) };
        if let Some(lo) = lo {
            if near.as_ref().is_none_or(|n| lo.gt(n)) {
                near = Some(lo);
            }
        }
        if let Some(hi) = hi {
            if far.as_ref().is_none_or(|f| f.gt(&hi)) {
                far = Some(hi);
            }
        }
    }
    match (near, far) {
        (Some(n), Some(f)) => !n.gt(&f),
        _ => true,
    }
}

/// An exact rational `n / d` with `d > 0`, never reduced (compared by cross-multiplying: no
/// gcd, which dominated the reduced rationals' cost).
#[derive(Clone, Debug)]
struct Frac {
    n: BigInt,
    d: BigInt,
}

/// A finite f64 as `m · 2^e` exactly (m an integer of at most 53 bits, its sign the value's).
fn dyadic(x: f64) -> (i64, i64) {
    let bits = x.to_bits();
    let exp = ((bits >> 52) & 0x7ff) as i64;
    let frac = (bits & ((1u64 << 52) - 1)) as i64;
    let (m, e) = if exp == 0 { (frac, -1074) } else { (frac | (1i64 << 52), exp - 1075) };
    (if x.is_sign_negative() { -m } else { m }, e)
}

/// `m · 2^(e − base)` as an integer (`e >= base`).
fn scaled(m: i64, e: i64, base: i64) -> BigInt {
    BigInt::from(m) << (e - base) as usize
}

impl Exact for Frac {
    fn of(x: f64) -> Frac {
        let (m, e) = dyadic(x);
        let base = e.min(0);
        Frac { n: scaled(m, e, base), d: BigInt::from(1) << (-base) as usize }
    }

    /// The difference of two dyadics at their smaller exponent, over the direction's mantissa,
    /// the exponents moved to the side that keeps them non-negative.
    fn distance(plane: f64, o: f64, dir: f64) -> Frac {
        let ((pm, pe), (om, oe), (dm, de)) = (dyadic(plane), dyadic(o), dyadic(dir));
        let base = pe.min(oe);
        let diff = scaled(pm, pe, base) - scaled(om, oe, base);
        // (diff · 2^base) / (dm · 2^de) = diff · 2^(base − de) / dm
        let shift = base - de;
        let (n, d) = if shift >= 0 {
            (diff << shift as usize, BigInt::from(dm))
        } else {
            (diff, BigInt::from(dm) << (-shift) as usize)
        };
        if d.sign() == Sign::Minus {
            Frac { n: -n, d: -d }
        } else {
            Frac { n, d }
        }
    }

    /// Cross-multiplied (both denominators positive).
    fn gt(&self, o: &Frac) -> bool {
        &self.n * &o.d > &o.n * &self.d
    }
}

/// An exact number as a binary64 interval that holds it, with what it was made from: two
/// intervals apart decide an order at once; overlapping ones (or a tie) fall back to the
/// exact fractions ([`Frac`]), made then — CGAL's filter-then-exact. Two numbers made from the
/// same inputs (bit for bit) are equal without either.
#[derive(Clone, Debug)]
struct Filtered {
    lo: f64,
    hi: f64,
    /// `[x]` for a finite f64, `[plane, o, dir]` for a plane distance.
    src: Src,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Src {
    Value(u64),
    Distance([u64; 3]),
}

impl Filtered {
    fn exact(&self) -> Frac {
        match self.src {
            Src::Value(x) => Frac::of(f64::from_bits(x)),
            Src::Distance([p, o, d]) => Frac::distance(f64::from_bits(p), f64::from_bits(o), f64::from_bits(d)),
        }
    }
}

impl Exact for Filtered {
    fn of(x: f64) -> Filtered {
        Filtered { lo: x, hi: x, src: Src::Value(x.to_bits()) }
    }

    /// q = RN(RN(plane − o) / dir) is within 2.01u·|q| + 2^-1074 of the distance (u = 2^-53:
    /// one rounding in the difference, exact when it is subnormal; one in the quotient, at
    /// most 2^-1075 when that is subnormal); the interval is q ∓ (2^-50·|q| + 2^-1060), its
    /// ends rounded to nearest (each moves by at most u of itself, well inside the slack).
    /// A difference or quotient that overflows gives the whole line.
    fn distance(plane: f64, o: f64, dir: f64) -> Filtered {
        let q = (plane - o) / dir;
        let (lo, hi) = if q.is_finite() {
            let rad = q.abs() * 2f64.powi(-50) + 2f64.powi(-1060);
            (q - rad, q + rad)
        } else {
            (f64::NEG_INFINITY, f64::INFINITY)
        };
        Filtered { lo, hi, src: Src::Distance([plane.to_bits(), o.to_bits(), dir.to_bits()]) }
    }

    fn gt(&self, o: &Filtered) -> bool {
        if self.src == o.src {
            return false;
        }
        if self.lo > o.hi {
            return true;
        }
        if self.hi < o.lo {
            return false;
        }
        self.exact().gt(&o.exact())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The reduced rationals (`BigRational`) the unreduced fractions replaced: the arithmetic
    /// `slab_exact` is held to.
    impl Exact for BigRational {
        fn of(x: f64) -> Self {
            q(x)
        }
        fn distance(plane: f64, o: f64, dir: f64) -> Self {
            (q(plane) - q(o)) / q(dir)
        }
        fn gt(&self, o: &Self) -> bool {
            self > o
        }
    }

    /// A finite f64 from a small set of edge magnitudes (zeros of both signs, subnormals, the
    /// largest values, powers of two, values one ulp apart) or an ordinary one.
    fn edge(s: &mut u64) -> f64 {
        *s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        let r = *s >> 11;
        let u = (r as f64) / (1u64 << 53) as f64;
        let sign = if r & 1 == 0 { 1.0 } else { -1.0 };
        sign * match r % 11 {
            0 => 0.0,
            1 => 5e-324 * ((r >> 8) % 5) as f64,
            2 => f64::MAX * (0.5 + u / 2.0),
            3 => 2f64.powi(((r >> 8) % 200) as i32 - 100),
            4 => 1.0 + f64::EPSILON * ((r >> 8) % 3) as f64,
            5 => 1e-300 * u,
            _ => 4.0 * u,
        }
    }

    /// The unreduced fractions decide every case as the reduced rationals do: flat boxes (min =
    /// max on an axis), rays in a face plane, grazing edges, and values from subnormal to the
    /// largest finite, with infinite interval ends and planes.
    #[test]
    fn unreduced_fractions_decide_as_rationals() {
        let mut s = 7u64;
        let mut hits = [0usize; 2];
        for i in 0..20000 {
            let o: [f64; 3] = std::array::from_fn(|_| edge(&mut s));
            let mut d: [f64; 3] = std::array::from_fn(|_| edge(&mut s));
            let mut lo: [f64; 3] = std::array::from_fn(|_| edge(&mut s));
            let mut hi: [f64; 3] = std::array::from_fn(|a| if i % 3 == 0 { lo[a] } else { edge(&mut s) });
            for a in 0..3 {
                if lo[a] > hi[a] {
                    std::mem::swap(&mut lo[a], &mut hi[a]);
                }
            }
            if i % 5 == 1 {
                // aim at a box corner: grazing cases
                d = std::array::from_fn(|a| hi[a] - o[a]);
            }
            if i % 7 == 2 {
                hi[i % 3] = f64::INFINITY;
            }
            let tmin = if i % 4 == 0 { f64::NEG_INFINITY } else { edge(&mut s).abs() * 0.0 };
            let tmax = if i % 2 == 0 { f64::INFINITY } else { edge(&mut s).abs() };
            if d.iter().any(|x| !x.is_finite()) {
                continue;
            }
            let want = slab_exact_in::<BigRational>(o, d, tmin, tmax, lo, hi);
            assert_eq!(slab_exact(o, d, tmin, tmax, lo, hi), Some(want), "{o:?} {d:?} {tmin} {tmax} {lo:?} {hi:?}");
            hits[want as usize] += 1;
        }
        assert!(hits[0] > 1000 && hits[1] > 1000, "{hits:?}");
    }

    /// Every plane distance's interval holds the exact fraction (checked exactly), on edge
    /// magnitudes from subnormal to the largest finite; and the filter decides most orders of
    /// ordinary distances without the fractions.
    #[test]
    fn filter_intervals_hold_the_exact_distance() {
        let mut s = 11u64;
        let mut decided = 0;
        for i in 0..20000 {
            let (p, o) = (edge(&mut s), edge(&mut s));
            let d = edge(&mut s);
            if d == 0.0 {
                continue;
            }
            let f = Filtered::distance(p, o, d);
            let x = Frac::distance(p, o, d);
            if f.lo.is_finite() {
                assert!(!Frac::of(f.lo).gt(&x), "lo {:e} above ({p:e} - {o:e}) / {d:e}", f.lo);
            }
            if f.hi.is_finite() {
                assert!(!x.gt(&Frac::of(f.hi)), "hi {:e} below ({p:e} - {o:e}) / {d:e}", f.hi);
            }
            // against a second distance: the filtered order is the exact one
            let (p2, o2, d2) = (edge(&mut s), if i % 2 == 0 { o } else { edge(&mut s) }, edge(&mut s));
            if d2 == 0.0 {
                continue;
            }
            let g = Filtered::distance(p2, o2, d2);
            assert_eq!(
                f.gt(&g),
                x.gt(&Frac::distance(p2, o2, d2)),
                "({p:e} - {o:e}) / {d:e} vs ({p2:e} - {o2:e}) / {d2:e}"
            );
            decided += (f.lo > g.hi || f.hi < g.lo) as usize;
        }
        assert!(decided > 10000, "the filter decided only {decided}");
    }

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
