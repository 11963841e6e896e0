//! Error bounds of the RTI datapath, written next to the arithmetic they bound (pbrt-v4 style,
//! but as a per-case running bound rather than a worst case).
//!
//! Model of one rounded operation of a format (see [`ErrorModel`]):
//! `|fl(x ∘ y) − (x ∘ y)| <= u·|fl(x ∘ y)| + eta`, for a multiply or divide, and with
//! `add_eta` instead of `eta` for an add/subtract (IEEE gradual underflow adds exactly in the
//! subnormal range, fixed point adds exactly; FTZ can lose up to the smallest normal). This holds
//! whenever no magnitude exceeds `max`.
//!
//! [`RtiBound`] mirrors the datapath of [`crate::rti`] operation for operation, carrying for each
//! signal its exact value `v` (evaluated in f64), the sum of absolute monomials `a`, and an upper
//! bound `e` on |computed − exact| for the format:
//! - input:      e = 0 (inputs are already in the format; the reference sees the same values)
//! - x ± y:      e = ex + ey + u·(|x ± y| + ex + ey) + add_eta
//! - x × y:      e = |x|·ey + |y|·ex + ex·ey + u·(|x·y| + …) + eta
//! - t = t'/det: with D = |det| − e_det > 0, |t'ₘ/detₘ − t| <= (e_t' + |t|·e_det) / D =: Δ₁; then
//!   recip-mul adds (2u + u²)·(|t| + Δ₁) + eta·(|t'| + e_t')·(1 + u) + eta, divide adds u·(|t| + Δ₁) + eta.
//!
//! The f64 evaluation of `v` is itself off by at most ~10·2⁻⁵³·a; `F64_SLACK·a` is added to every
//! bound. A case is *decisive* when every sign the validity test reads is larger than its bound:
//! then the model's hit/miss must equal the exact one, and |t_model − t| <= `t_err`.

use crate::format::{DivMode, ErrorModel};
use crate::rti::Cull;

/// Relative slack covering the f64 evaluation of the exact values.
pub const F64_SLACK: f64 = 1.0 / (1u64 << 45) as f64;

/// A signal's exact value, its absolute-monomial sum and its error bound.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Bnd {
    /// Exact value (f64 evaluation).
    pub v: f64,
    /// Sum of the absolute values of its monomials.
    pub a: f64,
    /// Upper bound on |computed − exact| in the format.
    pub e: f64,
}

impl Bnd {
    /// Bound for use in decisions: `e` plus the f64 evaluation slack.
    pub fn err(&self) -> f64 {
        self.e + F64_SLACK * self.a
    }
}

struct Ctx {
    em: ErrorModel,
    overflow: bool,
}

// Every step is branch-free (flags or-ed, results selected) so that `verdict_block`'s loop
// vectorises; the scalar and block paths run this same code.
impl Ctx {
    #[inline(always)]
    fn check(&mut self, b: Bnd) -> Bnd {
        let m = b.v.abs() + b.e;
        // NaN or above the largest magnitude
        self.overflow |= !(m <= self.em.max);
        b
    }
    #[inline(always)]
    fn input(&mut self, x: f64) -> Bnd {
        self.check(Bnd { v: x, a: x.abs(), e: 0.0 })
    }
    #[inline(always)]
    fn addsub(&mut self, x: Bnd, y: Bnd, sub: bool) -> Bnd {
        let v = if sub { x.v - y.v } else { x.v + y.v };
        let e0 = x.e + y.e;
        let e = e0 + self.em.u * (v.abs() + e0) + self.em.add_eta;
        self.check(Bnd { v, a: x.a + y.a, e })
    }
    #[inline(always)]
    fn add(&mut self, x: Bnd, y: Bnd) -> Bnd {
        self.addsub(x, y, false)
    }
    #[inline(always)]
    fn sub(&mut self, x: Bnd, y: Bnd) -> Bnd {
        self.addsub(x, y, true)
    }
    #[inline(always)]
    fn mul(&mut self, x: Bnd, y: Bnd) -> Bnd {
        let v = x.v * y.v;
        let e0 = x.v.abs() * y.e + y.v.abs() * x.e + x.e * y.e;
        let e = e0 + self.em.u * (v.abs() + e0) + self.em.eta;
        self.check(Bnd { v, a: x.a * y.a, e })
    }
}

/// Running error bounds of every RTI signal the decision and the outputs depend on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RtiBound {
    /// det = e1·(d × e2).
    pub det: Bnd,
    /// u' = s·(d × e2).
    pub up: Bnd,
    /// v' = d·(s × e1).
    pub vp: Bnd,
    /// t' = e2·(s × e1).
    pub tp: Bnd,
    /// u' + v'.
    pub uv: Bnd,
    /// Bound on |t_model − t| (infinite when det is not decisive).
    pub t_err: f64,
    /// Bound on |u_model − u|.
    pub u_err: f64,
    /// Bound on |v_model − v|.
    pub v_err: f64,
    /// Some magnitude may exceed the format's range: no bound holds.
    pub overflow: bool,
}

/// The exact decision the bound predicts and whether the model must reproduce it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Verdict {
    /// Every compared quantity is farther from its threshold than its error bound.
    pub decisive: bool,
    /// The exact (f64-evaluated) hit decision.
    pub hit: bool,
}

impl RtiBound {
    /// Bounds for one ray (origin, direction) and triangle given as the format's values in f64.
    #[inline(always)]
    pub fn new(em: ErrorModel, div: DivMode, o: [f64; 3], d: [f64; 3], v: [[f64; 3]; 3]) -> Self {
        let mut c = Ctx { em, overflow: false };
        let o = o.map(|x| c.input(x));
        let d = d.map(|x| c.input(x));
        let v = v.map(|p| p.map(|x| c.input(x)));
        let e1: [Bnd; 3] = std::array::from_fn(|k| c.sub(v[1][k], v[0][k]));
        let e2: [Bnd; 3] = std::array::from_fn(|k| c.sub(v[2][k], v[0][k]));
        let s: [Bnd; 3] = std::array::from_fn(|k| c.sub(o[k], v[0][k]));
        let mut cross = |a: [Bnd; 3], b: [Bnd; 3]| -> [Bnd; 3] {
            let xa = c.mul(a[1], b[2]);
            let xb = c.mul(a[2], b[1]);
            let ya = c.mul(a[2], b[0]);
            let yb = c.mul(a[0], b[2]);
            let za = c.mul(a[0], b[1]);
            let zb = c.mul(a[1], b[0]);
            [c.sub(xa, xb), c.sub(ya, yb), c.sub(za, zb)]
        };
        let p = cross(d, e2);
        let q = cross(s, e1);
        let mut dot = |a: [Bnd; 3], b: [Bnd; 3]| -> Bnd {
            let x = c.mul(a[0], b[0]);
            let y = c.mul(a[1], b[1]);
            let z = c.mul(a[2], b[2]);
            let xy = c.add(x, y);
            c.add(xy, z)
        };
        let det = dot(e1, p);
        let up = dot(s, p);
        let vp = dot(d, q);
        let tp = dot(e2, q);
        let uv = c.add(up, vp);
        let denom = det.v.abs() - det.err();
        // det not clear of zero (denom <= 0): the quotient is unbounded
        let ok = !(denom <= 0.0);
        let quot = |num: Bnd, c: &mut Ctx| -> f64 {
            let q = num.v / det.v;
            let d1 = (num.err() + q.abs() * det.err()) / denom;
            let mag = q.abs() + d1;
            let u = em.u;
            let extra = match div {
                DivMode::RecipMul => {
                    c.overflow |= ok & (1.0 / denom > em.max);
                    (2.0 * u + u * u) * mag + em.eta * (num.v.abs() + num.err()) * (1.0 + u) + em.eta
                }
                DivMode::Divide => u * mag + em.eta,
            };
            c.overflow |= ok & (mag + extra > em.max);
            if ok {
                d1 + extra
            } else {
                f64::INFINITY
            }
        };
        let t_err = quot(tp, &mut c);
        let u_err = quot(up, &mut c);
        let v_err = quot(vp, &mut c);
        Self { det, up, vp, tp, uv, t_err, u_err, v_err, overflow: c.overflow }
    }

    /// Exact t (f64 evaluation).
    pub fn t(&self) -> f64 {
        self.tp.v / self.det.v
    }

    /// The exact decision and whether it is decisive for the model with these options.
    #[inline(always)]
    pub fn verdict(&self, cull: Cull, det_threshold: f64, tmin: f64, tmax: f64) -> Verdict {
        let clear = |x: f64, b: f64| x.abs() > b;
        let det_q = match cull {
            Cull::TwoSided => self.det.v.abs() - det_threshold,
            Cull::Backface => self.det.v - det_threshold,
        };
        let pos = self.det.v > 0.0;
        let sgn = |x: f64| if pos { x } else { -x };
        let det_ok = det_q > 0.0;
        let u_ok = sgn(self.up.v) >= 0.0;
        let v_ok = sgn(self.vp.v) >= 0.0;
        let uv_ok = sgn(self.det.v - self.uv.v) >= 0.0;
        let t_ok = sgn(self.tp.v) >= 0.0;
        let valid = det_ok & u_ok & v_ok & uv_ok & t_ok;
        let decisive = !self.overflow
            & clear(det_q, self.det.err())
            & clear(self.det.v, self.det.err())
            & clear(self.up.v, self.up.err())
            & clear(self.vp.v, self.vp.err())
            & clear(self.det.v - self.uv.v, self.det.err() + self.uv.err())
            & clear(self.tp.v, self.tp.err());
        let t = self.t();
        // a valid case also decides t against the finite ends of [tmin, tmax]
        let hit = valid & (t >= tmin) & (t <= tmax);
        let t_clear =
            (!tmin.is_finite() | clear(t - tmin, self.t_err)) & (!tmax.is_finite() | clear(t - tmax, self.t_err));
        Verdict { decisive: decisive & (!valid | t_clear), hit }
    }
}

/// One ray against a block of triangles: each lane's [`RtiBound::new`] and
/// [`RtiBound::verdict`], the same code as one case, run over coordinate columns in f64 lanes.
#[derive(Clone, Copy, Debug)]
pub struct BlockRay {
    /// Origin (the format's values in f64).
    pub o: [f64; 3],
    /// Direction.
    pub d: [f64; 3],
    /// Smallest accepted t.
    pub tmin: f64,
    /// Largest accepted t.
    pub tmax: f64,
}

/// The options every lane of a block shares.
#[derive(Clone, Copy, Debug)]
pub struct BlockOpts {
    /// The format's rounding model.
    pub em: ErrorModel,
    /// Division mode.
    pub div: DivMode,
    /// Face culling.
    pub cull: Cull,
    /// det threshold (the format's value in f64).
    pub det_threshold: f64,
}

/// Per lane: the verdict's `decisive` and `hit`, and the bound `t_err`, for `ray` against
/// triangle columns x0 y0 z0 x1 y1 z1 x2 y2 z2, on AVX-512F lanes, AVX2 lanes or the baseline
/// (the widest the machine has within `cap`); bit-identical to [`RtiBound::new`] +
/// [`RtiBound::verdict`] on each lane (same operations, same order; the level changes only the
/// instructions).
///
/// # Panics
/// If the column lengths differ.
pub fn verdict_block(
    cap: crate::simd::Kernel,
    opts: BlockOpts,
    ray: BlockRay,
    tris: [&[f64]; 9],
    decisive: &mut [bool],
    hit: &mut [bool],
    t_err: &mut [f64],
) {
    use crate::simd::Kernel;
    let n = hit.len();
    assert!(decisive.len() == n && t_err.len() == n && tris.iter().all(|c| c.len() == n), "column lengths differ");
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::is_x86_feature_detected as has;
        if cap >= Kernel::Avx512 && has!("avx512f") {
            // SAFETY: AVX-512F is present (checked above)
            return unsafe { block_avx512(opts, ray, tris, decisive, hit, t_err) };
        }
        if cap >= Kernel::Avx2 && has!("avx2") {
            // SAFETY: AVX2 is present (checked above)
            return unsafe { block_avx2(opts, ray, tris, decisive, hit, t_err) };
        }
    }
    let _ = cap;
    block_body(opts, ray, tris, decisive, hit, t_err)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn block_avx512(o: BlockOpts, r: BlockRay, c: [&[f64]; 9], dec: &mut [bool], hit: &mut [bool], te: &mut [f64]) {
    block_body(o, r, c, dec, hit, te)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn block_avx2(o: BlockOpts, r: BlockRay, c: [&[f64]; 9], dec: &mut [bool], hit: &mut [bool], te: &mut [f64]) {
    block_body(o, r, c, dec, hit, te)
}

#[inline(always)]
fn block_body(o: BlockOpts, r: BlockRay, c: [&[f64]; 9], dec: &mut [bool], hit: &mut [bool], te: &mut [f64]) {
    for i in 0..hit.len() {
        let v = [[c[0][i], c[1][i], c[2][i]], [c[3][i], c[4][i], c[5][i]], [c[6][i], c[7][i], c[8][i]]];
        let b = RtiBound::new(o.em, o.div, r.o, r.d, v);
        let vd = b.verdict(o.cull, o.det_threshold, r.tmin, r.tmax);
        dec[i] = vd.decisive;
        hit[i] = vd.hit;
        te[i] = b.t_err;
    }
}
