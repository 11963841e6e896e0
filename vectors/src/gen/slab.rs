//! The slab unit's vectors: its coverage classes (ray placements × box shapes), the case of a
//! class and its edge refinements (limits, ties, subnormal gaps), and the expected rows.

use super::slab_rays;
use super::*;
use datapath::fault::{Fault, NoFault};
use datapath::format::FormatKind;
use datapath::probe::Recorder;
use datapath::rng::SplitMix64;
use datapath::slab::{Aabb, Slab, SlabConfig};
use datapath::Format;

/// Slab ray placements (level 1 ids 0-3).
pub(crate) const SLAB_RAYS: [(&str, &str); 11] = [
    ("random", "random ray and box in [-1, 1]^3"),
    ("face_signed_zero", "origin on a face plane, one direction component +0 or -0"),
    ("grazing", "aimed at a face, edge or corner point of the box"),
    ("inside", "origin inside the box"),
    ("edge_d", "a direction component of 1 to 8 least steps (subnormal: 1/d overflows), 1 to 64 least normals, or within 2^4 of the maximum (1/d subnormal), the box's slab on that axis where the ray meets it at t in [0.5, 4]"),
    ("near_max", "box planes near +-max on one axis, the origin near the other end or on the near plane, the direction component huge or near 1: plane minus origin overflows (floats) or saturates (fixed point)"),
    ("t_interval", "a random, face or inside placement with tmin one of -0, +0, -inf, a negative, a positive, a subnormal of either sign, and tmax one of -0, +0, NaN, +inf, a negative, a positive, a subnormal"),
    ("zero_t", "origin on the entry face plane of one axis and the exit face plane of another (inside on the third), tmin and tmax each +0 or -0: zero distances tie with zero limits of the other sign"),
    ("t_at_limits", "a placement the model finds hit with number limits, then the interval ending on them: tmax = the unwidened t_near stepped 2 * widen_ulps steps toward -inf, or tmin = the unwidened t_far stepped as far toward +inf (after widening t_near = t_far: a hit only if the decision is <=)"),
    ("ties", "floats: either one axis with the origin at 0, 1/d of significand m (odd part m'), 3m' of p + 1 bits and both planes 3 * 2^s: the products lo * inv_d and hi * inv_d fall exactly halfway between two values; or one axis with d = +-2^j, both planes in [0.5, 1 - 9u) and the origin +-(2k + 1) * u / 2 (u the step in [0.5, 1), k < 8): both subtracts fall exactly halfway; the other axes hold the origin inside with small d"),
    ("subnormal_gap", "floats: one axis with both planes and the origin small subnormal encodings (1 to 16 least steps, either sign; written as raw encodings also in FTZ formats), d on it +-1 (t subnormal) or 1 to 8 least normals (t near 1); the other axes hold the origin inside with small d"),
];
pub(crate) const SLAB_ZERO: (&str, &str) = ("zero_extent", "box of zero extent on one or more axes");
pub(crate) const SLAB_SPECIAL: (&str, &str) =
    ("inf_nan", "ray inputs +inf, -inf or NaN (floats only; a NaN is a random NaN encoding: either sign, quiet or signaling, random payload)");

/// One slab coverage class: a ray placement, a zero-extent box, special inputs.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SlabCross {
    pub(crate) ray: usize,
    pub(crate) zero_box: bool,
    pub(crate) special: bool,
}

impl SlabCross {
    pub(crate) fn describe(&self) -> (String, String) {
        let mut parts: Vec<(&str, &str)> = Vec::new();
        if self.ray > 0 || (!self.zero_box && !self.special) {
            parts.push(SLAB_RAYS[self.ray]);
        }
        if self.zero_box {
            parts.push(SLAB_ZERO);
        }
        if self.special {
            parts.push(SLAB_SPECIAL);
        }
        (
            parts.iter().map(|p| p.0).collect::<Vec<_>>().join("+"),
            parts.iter().map(|p| p.1).collect::<Vec<_>>().join("; and "),
        )
    }
}

/// The slab classes of a level: level 1 the thirteen named classes (ids 0-12), level 2 adds each
/// special placement with a zero-extent box and with special inputs, and the two together.
pub(crate) fn slab_crosses(level: u32) -> Vec<SlabCross> {
    let c = |ray, zero_box, special| SlabCross { ray, zero_box, special };
    let mut v = vec![c(0, false, false), c(1, false, false), c(2, false, false), c(3, false, false)];
    v.push(c(0, true, false));
    v.push(c(0, false, true));
    v.push(c(4, false, false));
    v.push(c(5, false, false));
    for ray in 6..SLAB_RAYS.len() {
        v.push(c(ray, false, false));
    }
    if level >= 2 {
        for ray in 1..4 {
            v.push(c(ray, true, false));
            v.push(c(ray, false, true));
        }
        v.push(c(0, true, true));
    }
    v
}

pub(crate) fn slab_case(cross: SlabCross, r: &mut SplitMix64, e: datapath::format::Edges) -> [f64; 14] {
    let (mut lo, mut hi) = slab_rays::random_box(r, 1.0, [0.0; 3], cross.zero_box);
    let mut o: [f64; 3] = std::array::from_fn(|_| r.range(-2.0, 2.0));
    let mut d: [f64; 3] = std::array::from_fn(|_| r.range(-1.0, 1.0));
    match cross.ray {
        1 => slab_rays::origin_on_face(r, &lo, &hi, &mut o, &mut d),
        2 => d = slab_rays::toward_surface(r, &lo, &hi, &o),
        3 => o = slab_rays::inside(r, &lo, &hi),
        4 => {
            // the ray crosses the other axes' slabs around t = tm; axis a's slab where the ray
            // meets it at t in [t1, t2] (q1.F holds t < 1)
            let cap = (e.max / 2.0).min(4.0);
            let (t1, t2) = (r.range(0.125, 0.5) * cap, r.range(0.5, 1.0) * cap);
            let tm = (t1 + t2) / 2.0;
            let a = r.below(3) as usize;
            for b in (0..3).filter(|&b| b != a) {
                let p = r.range(lo[b], hi[b]);
                d[b] = r.range(-0.05, 0.05);
                o[b] = p - d[b] * tm;
            }
            let s = if r.below(2) == 0 { 1.0 } else { -1.0 };
            d[a] = s * match r.below(3) {
                0 => e.least * (1 + r.below(8)) as f64,
                1 => e.min_normal * r.range(1.0, 64.0),
                _ => e.max * (-r.range(0.0, 4.0)).exp2(),
            };
            o[a] = 0.0;
            let (x, y) = (d[a] * t1, d[a] * t2);
            // a huge d puts the slab beyond the range: then near one unit instead (t ~ 1/|d|)
            let (x, y) =
                if y.abs() > e.max / 2.0 { (s * 0.5f64.min(e.max / 4.0), s * 1f64.min(e.max / 2.0)) } else { (x, y) };
            (lo[a], hi[a]) = (x.min(y), x.max(y));
        }
        5 => {
            let a = r.below(3) as usize;
            let s = if r.below(2) == 0 { 1.0 } else { -1.0 };
            let tm = (e.max / 4.0).min(2.0) * r.range(0.25, 1.0);
            let mode = r.below(3);
            if mode < 2 {
                let (x, y) = (r.range(0.3, 0.9) * e.max, r.range(0.3, 0.9) * e.max);
                (lo[a], hi[a]) = if s > 0.0 { (x.min(y), x.max(y)) } else { (-x.max(y), -x.min(y)) };
                o[a] = -s * r.range(0.3, 0.95) * e.max;
                // a huge d (1/d subnormal), or one near 1: the overflowed difference alone
                // decides the axis
                d[a] = if mode == 0 {
                    (((lo[a] + hi[a]) / 2.0 - o[a]) / tm).clamp(-e.max, e.max)
                } else {
                    s * r.range(0.5, 2.0).min(e.max)
                };
            } else {
                (lo[a], hi[a]) = (-r.range(0.55, 0.95) * e.max, r.range(0.55, 0.95) * e.max);
                o[a] = if s > 0.0 { lo[a] } else { hi[a] };
                let far = if s > 0.0 { hi[a] } else { lo[a] };
                d[a] = ((far - o[a]) / (1.1 * tm)).clamp(-e.max, e.max);
            }
            for b in (0..3).filter(|&b| b != a) {
                d[b] = r.range(-1.0, 1.0) * (hi[b] - lo[b]) / tm;
                o[b] = (lo[b] + hi[b]) / 2.0 - d[b] * tm;
            }
        }
        6 => {
            let base = SlabCross { ray: [0, 1, 3][r.below(3) as usize], ..cross };
            let mut x = slab_case(base, r, e);
            let sub = e.least * (1 + r.below(4)) as f64;
            x[6] =
                [-0.0, 0.0, f64::NEG_INFINITY, -r.range(0.0, 2.0), r.range(0.0, 2.0), sub, -sub][r.below(7) as usize];
            x[7] =
                [-0.0, 0.0, f64::NAN, f64::INFINITY, -r.range(0.0, 2.0), r.range(0.0, 3.0), sub][r.below(7) as usize];
            return x;
        }
        7 => {
            let a = r.below(3) as usize;
            for b in 0..3 {
                o[b] = r.range(lo[b], hi[b]);
                while d[b] == 0.0 {
                    d[b] = r.range(-1.0, 1.0);
                }
            }
            // on the entry face of axis a and the exit face of another axis b
            let b = (a + 1 + r.below(2) as usize) % 3;
            o[a] = if d[a] > 0.0 { lo[a] } else { hi[a] };
            o[b] = if d[b] > 0.0 { hi[b] } else { lo[b] };
            let z = |r: &mut SplitMix64| if r.below(2) == 0 { 0.0 } else { -0.0 };
            let (tmin, tmax) = (z(r), z(r));
            return [o[0], o[1], o[2], d[0], d[1], d[2], tmin, tmax, lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]];
        }
        8..=10 => {
            // placed here; t_at_limits, ties and subnormal_gap set their values on the
            // format's encodings (slab_special_bits)
            let base = SlabCross { ray: [0, 2, 3][r.below(3) as usize], ..cross };
            return slab_case(base, r, e);
        }
        _ => {}
    }
    if cross.special {
        let i = r.below(6) as usize;
        let v = [f64::INFINITY, f64::NEG_INFINITY, f64::NAN][r.below(3) as usize];
        if i < 3 {
            o[i] = v;
        } else {
            d[i - 3] = v;
        }
    }
    let tmax = if r.below(4) == 0 { r.range(0.0, 3.0) } else { f64::INFINITY };
    [o[0], o[1], o[2], d[0], d[1], d[2], 0.0, tmax, lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]]
}

/// The t_at_limits class on a placement's encodings: when the unwidened unit hits with number
/// limits tn <= tf, the interval is made to end on them (`tmax` = tn stepped 2W times toward
/// −∞, or `tmin` = tf stepped 2W times toward +∞, W = widen_ulps); `None` otherwise.
pub(crate) fn slab_at_limits<F: Format>(s: &Slab<F>, bits: &[u64], r: &mut SplitMix64) -> Option<Vec<u64>> {
    let f = &s.fmt;
    let bare = Slab::new(*f, SlabConfig { widen_ulps: 0, ..s.cfg });
    let [out, _] = slab_out_rows(&bare, bits, &NoFault);
    let (tn, tf) = (f.from_bits(out[1]), f.from_bits(out[2]));
    let number = |v: F::V| !f.is_nan(v) && f.to_f64(v).is_finite();
    if out[0] == 0 || !number(tn) || !number(tf) {
        return None;
    }
    let steps = 2 * s.cfg.widen_ulps.max(0);
    let mut b = bits.to_vec();
    if r.below(2) == 0 {
        let t = (0..steps).fold(tn, |t, _| f.next_down(t));
        b[7] = f.to_bits(t);
    } else {
        let t = (0..steps).fold(tf, |t, _| f.next_up(t));
        b[6] = f.to_bits(t);
    }
    Some(b)
}

/// Puts the origin inside the box with a small direction component on every axis but `a`
/// (encodings of a slab input row), so that axis `a` alone sets t_near and t_far.
pub(crate) fn slab_others_inside<F: Format>(f: &F, a: usize, r: &mut SplitMix64, bits: &mut [u64]) {
    for b in (0..3).filter(|&b| b != a) {
        let (lo, hi) = (f.to_f64(f.from_bits(bits[8 + b])), f.to_f64(f.from_bits(bits[11 + b])));
        bits[b] = f.to_bits(f.from_f64(r.range(lo, hi)));
        bits[3 + b] = f.to_bits(f.from_f64(r.range(-0.05, 0.05)));
    }
}

/// The ties class on a float placement's encodings (see the class description).
pub(crate) fn slab_ties<F: Format>(f: &F, r: &mut SplitMix64, bits: &mut [u64]) {
    let FormatKind::Float(l) = f.kind() else { return };
    let p = l.man_bits as i32 + 1;
    let a = r.below(3) as usize;
    slab_others_inside(f, a, r, bits);
    let sign = |r: &mut SplitMix64| if r.below(2) == 0 { 1.0 } else { -1.0 };
    if r.below(2) == 0 {
        // products: 1 ⊘ d of significand m, odd part m' with 3m' of p + 1 bits (at most 64 tries)
        for _ in 0..64 {
            let d = f.from_f64(sign(r) * r.range(0.5, 2.0));
            let inv = f.to_f64(f.div(f.one(), d)).abs();
            let m = (inv.to_bits() & ((1 << 52) - 1)) | (1 << 52);
            let odd = m >> m.trailing_zeros();
            if 64 - (3 * odd).leading_zeros() as i32 == p + 1 {
                let s = (-2 - r.below(2) as i32) as f64;
                let (x1, x2) = (3.0 * s.exp2(), 3.0 * (s + 1.0).exp2());
                let (lo, hi) = if r.below(2) == 0 { (x1, x2) } else { (-x2, -x1) };
                bits[a] = f.to_bits(f.zero());
                bits[3 + a] = f.to_bits(d);
                bits[8 + a] = f.to_bits(f.from_f64(lo));
                bits[11 + a] = f.to_bits(f.from_f64(hi));
                return;
            }
        }
    }
    // subtracts: planes in [0.5, 1 - 9u), origin ±(2k + 1)u/2
    let u = (-p as f64).exp2();
    let half = 1u64 << (p - 1);
    let pick = |r: &mut SplitMix64| (half + 9 + r.below(half - 18)) as f64 * u;
    let (x, y) = (pick(r), pick(r));
    let (lo, hi) = (x.min(y), if x == y { x + u } else { x.max(y) });
    let o = sign(r) * (2 * r.below(8) + 1) as f64 * u / 2.0;
    bits[a] = f.to_bits(f.from_f64(o));
    bits[3 + a] = f.to_bits(f.from_f64(sign(r) * (r.below(3) as f64 - 1.0).exp2()));
    bits[8 + a] = f.to_bits(f.from_f64(lo));
    bits[11 + a] = f.to_bits(f.from_f64(hi));
}

/// The subnormal_gap class on a float placement's encodings (see the class description).
pub(crate) fn slab_subnormal_gap<F: Format>(f: &F, r: &mut SplitMix64, bits: &mut [u64]) {
    let FormatKind::Float(l) = f.kind() else { return };
    let a = r.below(3) as usize;
    slab_others_inside(f, a, r, bits);
    // a signed multiple of the least subnormal step, as its raw encoding
    let mut k = || (1 + r.below(16) as i64) * if r.below(2) == 0 { 1 } else { -1 };
    let enc = |k: i64| if k < 0 { l.sign_mask() | k.unsigned_abs() } else { k as u64 };
    let (x, y, o) = (k(), k(), k());
    bits[a] = enc(o);
    bits[8 + a] = enc(x.min(y));
    bits[11 + a] = enc(x.max(y));
    let s = if r.below(2) == 0 { 1.0 } else { -1.0 };
    let d = if r.below(2) == 0 { 1.0 } else { l.min_normal() * r.range(1.0, 8.0) };
    bits[3 + a] = f.to_bits(f.from_f64(s * d));
}

/// The expected row (hit, t_near, t_far) and the stage row of one slab test on an input row's
/// 14 encodings (o, d, tmin, tmax, box min, box max) with every site computed by `x`
/// (`NoFault`: the rows a set holds).
pub fn slab_out_rows<F: Format, X: Fault<F>>(s: &Slab<F>, bits: &[u64], x: &X) -> [Vec<u64>; 2] {
    let f = &s.fmt;
    let v = |i: usize| f.from_bits(bits[i]);
    let mut rec = Recorder::new();
    let ray = s.prepare_faulty([v(0), v(1), v(2)], [v(3), v(4), v(5)], v(6), v(7), &mut rec, x);
    let b = Aabb { min: [v(8), v(9), v(10)], max: [v(11), v(12), v(13)] };
    let out = s.trace_faulty(&ray, &b, &mut rec, x);
    [vec![out.hit as u64, f.to_bits(out.t_near), f.to_bits(out.t_far)], signals(f, &rec)]
}

/// Model rows for one slab vector.
pub(crate) fn slab_rows<F: Format>(s: &Slab<F>, class: u64, bits: &[u64]) -> [Vec<u64>; 3] {
    let [expected, stages] = slab_out_rows(s, bits, &NoFault);
    let mut inputs = vec![class];
    inputs.extend_from_slice(bits);
    [inputs, expected, stages]
}
