//! The RTI unit's vectors: its coverage classes (placements × modifiers), the case of a class,
//! and the expected rows of a case (outputs and stage signals).

use super::*;
use datapath::fault::{Fault, NoFault};
use datapath::probe::Recorder;
use datapath::rng::SplitMix64;
use datapath::rti::{Ray, Rti, Tri};
use datapath::Format;

/// Geometric RTI classes (level 1 ids 0-5, 8 and 12-16): how the triangle and ray are placed.
pub(crate) const RTI_GEOMETRY: [(usize, &str, &str); 12] = [
    (0, "random", "ray aimed at a random barycentric point in [-0.3, 1.3]^2 of a random triangle in [-1, 1]^3"),
    (1, "edge", "aimed exactly at a point of an edge (one barycentric 0)"),
    (2, "vertex", "aimed exactly at a vertex"),
    (3, "near_parallel", "direction within ~1e-3 of the triangle's plane (|det| -> 0)"),
    (4, "degenerate", "collinear vertices (zero area)"),
    (5, "needle", "long triangle 1e-3 wide"),
    (8, "t_near_zero", "origin on the triangle's plane (t = 0)"),
    (
        12,
        "t_at_limits",
        "a random placement the model finds valid with a number t, then the t interval ending on that t: tmax = t (a hit only if the compare is t <= tmax), or tmin = the next value above t (a miss only if the tmin compare is made)",
    ),
    (13, "point_triangle", "all three vertices at one point: det, u', v' and t' are zero, so only the det check rejects it"),
    (
        14,
        "ties",
        "v0 = 0, e2.y = 0 and d.z = 0, so p.x = d.y * e2.z and p.y = -d.x * e2.z are exact; e1, o (so s), and e2.x, e2.z, d.x, d.y odd integers of a, be and bd bits scaled by powers of two (a = floor((p + 1) / 2), bd = floor((p + 2 - a) / 2), be = p + 2 - a - bd for a float of p significant bits): detx = e1.x * p.x and upy = s.y * p.y span p or p + 1 bits and, at p + 1, fall exactly halfway between two values (round-half-even vs half-away)",
    ),
    (
        15,
        "tiny_products",
        "a random placement with the origin and vertices scaled by 2^floor((emin - 1) / 2) (floats only): stage-2 and stage-3 results fall into the subnormal range",
    ),
    (
        16,
        "t_subnormal",
        "a random placement with the origin and vertices scaled by L = 2^(ceil(emin / 3) + 1) and the direction by L * 2^(2 - emin) (floats only): t near 2^(emin - 2), a subnormal, with det, u' and t' normal",
    ),
];

/// Value modifiers of the RTI classes (level 1 ids 6, 7, 9, 10, 11), applied after placement.
pub(crate) const RTI_MODIFIERS: [(usize, &str, &str); 5] = [
    (6, "huge", "coordinates scaled by 2^12"),
    (7, "tiny", "coordinates scaled by 2^-12"),
    (9, "signed_zero", "some coordinates +0 or -0"),
    (10, "subnormal", "some inputs the format's smallest subnormals, written as raw encodings also in FTZ formats (floats only)"),
    (11, "inf_nan", "some inputs +inf, -inf or NaN (floats only; a NaN is a random NaN encoding: either sign, quiet or signaling, random payload)"),
];

/// One RTI coverage class: a placement plus at most one modifier.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RtiCross {
    pub(crate) geom: usize,
    pub(crate) scale: f64,
    pub(crate) signed_zero: bool,
    pub(crate) special: Option<Special>,
    /// Index into RTI_GEOMETRY and RTI_MODIFIERS (None: plain placement).
    pub(crate) names: (usize, Option<usize>),
}

impl RtiCross {
    pub(crate) fn describe(&self) -> (String, String) {
        let (g, m) = self.names;
        match (g, m) {
            (0, Some(m)) => (RTI_MODIFIERS[m].1.into(), RTI_MODIFIERS[m].2.into()),
            (g, None) => (RTI_GEOMETRY[g].1.into(), RTI_GEOMETRY[g].2.into()),
            (g, Some(m)) => (
                format!("{}+{}", RTI_GEOMETRY[g].1, RTI_MODIFIERS[m].1),
                format!("{}; and {}", RTI_GEOMETRY[g].2, RTI_MODIFIERS[m].2),
            ),
        }
    }
}

/// The RTI classes of a level, in class-id order: level 1 as the seventeen named classes (ids
/// 0-16), level 2 adds every placement other than random crossed with every modifier.
pub(crate) fn rti_crosses(level: u32) -> Vec<RtiCross> {
    let cross = |g: usize, m: Option<usize>| {
        let id = m.map(|m| RTI_MODIFIERS[m].0);
        RtiCross {
            geom: RTI_GEOMETRY[g].0,
            scale: match id {
                Some(6) => 4096.0,
                Some(7) => 1.0 / 4096.0,
                _ => 1.0,
            },
            signed_zero: id == Some(9),
            special: match id {
                Some(10) => Some(Special::Subnormal),
                Some(11) => Some(Special::InfNan),
                _ => None,
            },
            names: (g, m),
        }
    };
    let mut v: Vec<RtiCross> = (0..17)
        .map(|id| match RTI_GEOMETRY.iter().position(|g| g.0 == id) {
            Some(g) => cross(g, None),
            None => cross(0, RTI_MODIFIERS.iter().position(|m| m.0 == id)),
        })
        .collect();
    if level >= 2 {
        for g in 1..RTI_GEOMETRY.len() {
            for m in 0..RTI_MODIFIERS.len() {
                v.push(cross(g, Some(m)));
            }
        }
    }
    v
}

pub(crate) fn rti_case(cross: RtiCross, r: &mut SplitMix64) -> [f64; 17] {
    let class = cross.geom;
    let p = |r: &mut SplitMix64| [r.range(-1.0, 1.0), r.range(-1.0, 1.0), r.range(-1.0, 1.0)];
    let mut v = [p(r), p(r), p(r)];
    let o = p(r);
    let (mut b1, mut b2) = (r.range(-0.3, 1.3), r.range(-0.3, 1.3));
    match class {
        1 => match r.below(3) {
            0 => b1 = 0.0,
            1 => b2 = 0.0,
            _ => b2 = 1.0 - b1,
        },
        2 => {
            let k = r.below(3);
            (b1, b2) = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)][k as usize];
        }
        13 => v = [v[0]; 3],
        4 => {
            let t = r.range(-1.0, 2.0);
            v[2] = std::array::from_fn(|a| v[0][a] + t * (v[1][a] - v[0][a]));
        }
        5 => {
            let w = 1e-3;
            v[2] = std::array::from_fn(|a| v[1][a] + w * r.range(-1.0, 1.0));
        }
        _ => {}
    }
    let b0 = 1.0 - b1 - b2;
    let target: [f64; 3] = std::array::from_fn(|a| b0 * v[0][a] + b1 * v[1][a] + b2 * v[2][a]);
    let mut o = o;
    let mut d: [f64; 3] = std::array::from_fn(|a| target[a] - o[a]);
    if class == 3 {
        // move the origin into the plane, then lift it slightly off
        let e1: [f64; 3] = std::array::from_fn(|a| v[1][a] - v[0][a]);
        let e2: [f64; 3] = std::array::from_fn(|a| v[2][a] - v[0][a]);
        let s = r.range(-1.0, 1.0);
        let t = r.range(-1.0, 1.0);
        o = std::array::from_fn(|a| target[a] + s * e1[a] + t * e2[a]);
        let n = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]];
        let eps = 1e-3 * r.range(-1.0, 1.0);
        o = std::array::from_fn(|a| o[a] + eps * n[a]);
        d = std::array::from_fn(|a| target[a] - o[a]);
    }
    if class == 8 {
        o = target;
        d = p(r);
    }
    let scale = cross.scale;
    let mut x = [0.0; 17];
    for a in 0..3 {
        x[a] = o[a] * scale;
        x[3 + a] = d[a] * scale;
        for k in 0..3 {
            x[8 + 3 * k + a] = v[k][a] * scale;
        }
    }
    x[6] = 0.0;
    x[7] = if r.below(4) == 0 { r.range(0.0, 3.0) * scale } else { f64::INFINITY };
    if cross.signed_zero {
        for xi in x.iter_mut() {
            if r.below(3) == 0 {
                *xi = if r.below(2) == 0 { 0.0 } else { -0.0 };
            }
        }
    }
    x
}

/// Model rows for one RTI vector: inputs, expected outputs, stage signals.
/// The ray and triangle of a case's 17 f64 inputs (o, d, tmin, tmax, v0, v1, v2) in format `f`.
pub(crate) fn rti_inputs<F: Format>(f: &F, x: &[f64; 17]) -> (Ray<F::V>, Tri<F::V>) {
    rti_case_of(f, &x.map(|v| f.to_bits(f.from_f64(v))))
}

/// The ray and triangle of an RTI input row's 17 encodings (o, d, tmin, tmax, v0, v1, v2).
pub fn rti_case_of<F: Format>(f: &F, bits: &[u64]) -> (Ray<F::V>, Tri<F::V>) {
    let v = |i: usize| f.from_bits(bits[i]);
    (
        Ray { o: [v(0), v(1), v(2)], d: [v(3), v(4), v(5)], tmin: v(6), tmax: v(7) },
        Tri { v: [[v(8), v(9), v(10)], [v(11), v(12), v(13)], [v(14), v(15), v(16)]] },
    )
}

/// The expected row (valid, hit, t, u, v) and the stage row of one RTI test with every site
/// computed by `x` (`NoFault`: the rows a set holds).
pub fn rti_out_rows<F: Format, X: Fault<F>>(rti: &Rti<F>, ray: &Ray<F::V>, tri: &Tri<F::V>, x: &X) -> [Vec<u64>; 2] {
    let f = &rti.fmt;
    let mut rec = Recorder::new();
    let out = rti.trace_faulty(ray, tri, &mut rec, x);
    [vec![out.valid as u64, out.hit as u64, f.to_bits(out.t), f.to_bits(out.u), f.to_bits(out.v)], signals(f, &rec)]
}

pub(crate) fn rti_rows<F: Format>(rti: &Rti<F>, class: u64, bits: &[u64]) -> [Vec<u64>; 3] {
    let (ray, tri) = rti_case_of(&rti.fmt, bits);
    let [expected, stages] = rti_out_rows(rti, &ray, &tri, &NoFault);
    let mut inputs = vec![class];
    inputs.extend_from_slice(bits);
    [inputs, expected, stages]
}
