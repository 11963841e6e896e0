//! The latency-reordered Möller–Trumbore ray–triangle intersection (RTI) pipeline.
//!
//! The classic test is 51 operations (9 sub, 2 cross products, 4 dot products, 1 divide, 3
//! multiplies by 1/det). This datapath keeps those operations and fixes their order and
//! grouping so that the longest path is short and the divide comes last:
//! subtracts in parallel, both cross products in parallel, the four dot products in parallel,
//! a division-free validity test (which clears the valid bit), then the divide. The stage
//! table [`stage_table`] is the contract; [`Rti::trace`] implements it and a test checks every
//! recorded signal against the table.
//!
//! Every operation is the format's rounded op; nothing is fused; dot products add as
//! `(x + y) + z`; comparisons are the format's IEEE ordered compares (NaN → false, −0 == +0).

use crate::fault::{Cmp, Fault, NoFault};
use crate::format::{DivMode, Format};
use crate::probe::{NoProbe, Probe};
pub use crate::stage::{Op, Rule, SigDef};
use crate::{record, record_flags};

/// A ray in the datapath's format: origin, direction and the accepted t interval.
#[derive(Clone, Copy, Debug, Default)]
pub struct Ray<V> {
    /// Origin.
    pub o: [V; 3],
    /// Direction (need not be normalised).
    pub d: [V; 3],
    /// Smallest accepted t (inclusive).
    pub tmin: V,
    /// Largest accepted t (inclusive).
    pub tmax: V,
}

/// A triangle in the datapath's format.
#[derive(Clone, Copy, Debug, Default)]
pub struct Tri<V> {
    /// Vertices v0, v1, v2.
    pub v: [[V; 3]; 3],
}

/// Output of one RTI test.
#[derive(Clone, Copy, Debug, Default)]
pub struct RtiOut<V> {
    /// Validity-stage result: det, barycentric and t-sign tests passed.
    pub valid: bool,
    /// `valid` and `tmin <= t <= tmax`.
    pub hit: bool,
    /// Distance along the ray (meaningful when `valid`).
    pub t: V,
    /// Barycentric weight of v1.
    pub u: V,
    /// Barycentric weight of v2.
    pub v: V,
}

/// Face culling.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Cull {
    /// Both faces: valid needs `|det| > threshold`.
    TwoSided,
    /// Back faces culled: valid needs `det > threshold` (front face: ray against the normal e1 × e2).
    Backface,
}

/// Which of two equal-t hits the min-capture unit keeps.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TieRule {
    /// Keep the earlier one in the stream (replace only when `t < best`).
    First,
    /// Keep the later one (replace when `t <= best`).
    Last,
}

/// Datapath options of an RTI unit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RtiConfig {
    /// Face culling.
    pub cull: Cull,
    /// det threshold (>= 0), converted into the format.
    pub det_threshold: f64,
    /// Min-capture tie rule.
    pub tie: TieRule,
}

impl Default for RtiConfig {
    fn default() -> Self {
        Self { cull: Cull::TwoSided, det_threshold: 0.0, tie: TieRule::First }
    }
}

const fn s(stage: u8, name: &'static str, op: Op, a: &'static str, b: &'static str) -> SigDef {
    SigDef { stage, name, op, a, b, note: "", rule: Rule::Arith }
}
const fn l(stage: u8, name: &'static str, rule: Rule, note: &'static str) -> SigDef {
    SigDef { stage, name, op: Op::Logic, a: "", b: "", note, rule }
}

/// Input signal names: ray origin, direction, t interval, triangle vertices, and the constant one.
pub const RTI_INPUTS: [&str; 17] =
    ["ox", "oy", "oz", "dx", "dy", "dz", "tmin", "tmax", "v0x", "v0y", "v0z", "v1x", "v1y", "v1z", "v2x", "v2y", "v2z"];

const STAGES_1_TO_7: [SigDef; 53] = [
    // stage 1: the nine subtracts, in parallel
    s(1, "e1x", Op::Sub, "v1x", "v0x"),
    s(1, "e1y", Op::Sub, "v1y", "v0y"),
    s(1, "e1z", Op::Sub, "v1z", "v0z"),
    s(1, "e2x", Op::Sub, "v2x", "v0x"),
    s(1, "e2y", Op::Sub, "v2y", "v0y"),
    s(1, "e2z", Op::Sub, "v2z", "v0z"),
    s(1, "sx", Op::Sub, "ox", "v0x"),
    s(1, "sy", Op::Sub, "oy", "v0y"),
    s(1, "sz", Op::Sub, "oz", "v0z"),
    // stage 2: the twelve products of p = d × e2 and q = s × e1
    s(2, "pxa", Op::Mul, "dy", "e2z"),
    s(2, "pxb", Op::Mul, "dz", "e2y"),
    s(2, "pya", Op::Mul, "dz", "e2x"),
    s(2, "pyb", Op::Mul, "dx", "e2z"),
    s(2, "pza", Op::Mul, "dx", "e2y"),
    s(2, "pzb", Op::Mul, "dy", "e2x"),
    s(2, "qxa", Op::Mul, "sy", "e1z"),
    s(2, "qxb", Op::Mul, "sz", "e1y"),
    s(2, "qya", Op::Mul, "sz", "e1x"),
    s(2, "qyb", Op::Mul, "sx", "e1z"),
    s(2, "qza", Op::Mul, "sx", "e1y"),
    s(2, "qzb", Op::Mul, "sy", "e1x"),
    // stage 3: the six cross-product subtracts
    s(3, "px", Op::Sub, "pxa", "pxb"),
    s(3, "py", Op::Sub, "pya", "pyb"),
    s(3, "pz", Op::Sub, "pza", "pzb"),
    s(3, "qx", Op::Sub, "qxa", "qxb"),
    s(3, "qy", Op::Sub, "qya", "qyb"),
    s(3, "qz", Op::Sub, "qza", "qzb"),
    // stage 4: the twelve dot-product multiplies: det = e1·p, up = s·p, vp = d·q, tp = e2·q
    s(4, "detx", Op::Mul, "e1x", "px"),
    s(4, "dety", Op::Mul, "e1y", "py"),
    s(4, "detz", Op::Mul, "e1z", "pz"),
    s(4, "upx", Op::Mul, "sx", "px"),
    s(4, "upy", Op::Mul, "sy", "py"),
    s(4, "upz", Op::Mul, "sz", "pz"),
    s(4, "vpx", Op::Mul, "dx", "qx"),
    s(4, "vpy", Op::Mul, "dy", "qy"),
    s(4, "vpz", Op::Mul, "dz", "qz"),
    s(4, "tpx", Op::Mul, "e2x", "qx"),
    s(4, "tpy", Op::Mul, "e2y", "qy"),
    s(4, "tpz", Op::Mul, "e2z", "qz"),
    // stage 5: first adds (x + y)
    s(5, "det_xy", Op::Add, "detx", "dety"),
    s(5, "up_xy", Op::Add, "upx", "upy"),
    s(5, "vp_xy", Op::Add, "vpx", "vpy"),
    s(5, "tp_xy", Op::Add, "tpx", "tpy"),
    // stage 6: second adds (+ z)
    s(6, "det", Op::Add, "det_xy", "detz"),
    s(6, "up", Op::Add, "up_xy", "upz"),
    s(6, "vp", Op::Add, "vp_xy", "vpz"),
    s(6, "tp", Op::Add, "tp_xy", "tpz"),
    // stage 7: uv = up + vp and the division-free validity test; the valid bit may be cleared here
    s(7, "uv", Op::Add, "up", "vp"),
    l(7, "det_ok", Rule::DetOk("det"), "two-sided: threshold < |det|; backface culling: threshold < det"),
    l(7, "u_ok", Rule::Oriented("zero", "up"), "det > 0 ? 0 <= up : up <= 0"),
    l(7, "v_ok", Rule::Oriented("zero", "vp"), "det > 0 ? 0 <= vp : vp <= 0"),
    l(7, "uv_ok", Rule::Oriented("uv", "det"), "det > 0 ? uv <= det : det <= uv"),
    l(7, "t_ok", Rule::Oriented("zero", "tp"), "det > 0 ? 0 <= tp : tp <= 0"),
];

const VALID: SigDef =
    l(7, "valid", Rule::All(&["det_ok", "u_ok", "v_ok", "uv_ok", "t_ok"]), "det_ok & u_ok & v_ok & uv_ok & t_ok");

const RECIP_TAIL: [SigDef; 7] = [
    s(8, "inv_det", Op::Div, "one", "det"),
    s(9, "t", Op::Mul, "tp", "inv_det"),
    s(9, "u", Op::Mul, "up", "inv_det"),
    s(9, "v", Op::Mul, "vp", "inv_det"),
    l(10, "tmin_ok", Rule::Le("tmin", "t"), "tmin <= t"),
    l(10, "tmax_ok", Rule::Le("t", "tmax"), "t <= tmax"),
    l(10, "hit", Rule::All(&["valid", "tmin_ok", "tmax_ok"]), "valid & tmin_ok & tmax_ok"),
];

const DIVIDE_TAIL: [SigDef; 6] = [
    s(8, "t", Op::Div, "tp", "det"),
    s(8, "u", Op::Div, "up", "det"),
    s(8, "v", Op::Div, "vp", "det"),
    l(9, "tmin_ok", Rule::Le("tmin", "t"), "tmin <= t"),
    l(9, "tmax_ok", Rule::Le("t", "tmax"), "t <= tmax"),
    l(9, "hit", Rule::All(&["valid", "tmin_ok", "tmax_ok"]), "valid & tmin_ok & tmax_ok"),
];

/// The stage table of the RTI datapath for a division mode, in the order signals are produced.
pub fn stage_table(div: DivMode) -> Vec<SigDef> {
    let mut t: Vec<SigDef> = STAGES_1_TO_7.to_vec();
    t.push(VALID);
    match div {
        DivMode::RecipMul => t.extend_from_slice(&RECIP_TAIL),
        DivMode::Divide => t.extend_from_slice(&DIVIDE_TAIL),
    }
    t
}

/// Number of pipeline stages (latency in cycles at one stage per cycle) for a division mode.
pub fn stage_count(div: DivMode) -> u8 {
    match div {
        DivMode::RecipMul => 10,
        DivMode::Divide => 9,
    }
}

/// The best hit a min-capture unit holds for one ray.
#[derive(Clone, Copy, Debug, Default)]
pub struct Capture<V> {
    /// True once any hit was captured.
    pub hit: bool,
    /// Nearest t.
    pub t: V,
    /// Its u.
    pub u: V,
    /// Its v.
    pub v: V,
    /// Its triangle id.
    pub id: u32,
}

/// An RTI unit in format `F`.
#[derive(Clone, Debug)]
pub struct Rti<F: Format> {
    /// Number format and its options.
    pub fmt: F,
    /// Face culling.
    pub cull: Cull,
    /// det threshold in the format.
    pub det_thr: F::V,
    /// Min-capture tie rule.
    pub tie: TieRule,
}

impl<F: Format> Rti<F> {
    /// An RTI unit with the given options.
    pub fn new(fmt: F, cfg: RtiConfig) -> Self {
        let det_thr = fmt.from_f64(cfg.det_threshold.max(0.0));
        Self { fmt, cull: cfg.cull, det_thr, tie: cfg.tie }
    }

    /// Converts an f64 ray into the format.
    pub fn ray(&self, o: [f64; 3], d: [f64; 3], tmin: f64, tmax: f64) -> Ray<F::V> {
        let f = &self.fmt;
        Ray { o: o.map(|x| f.from_f64(x)), d: d.map(|x| f.from_f64(x)), tmin: f.from_f64(tmin), tmax: f.from_f64(tmax) }
    }

    /// Converts an f64 triangle into the format.
    pub fn tri(&self, v: [[f64; 3]; 3]) -> Tri<F::V> {
        Tri { v: v.map(|p| p.map(|x| self.fmt.from_f64(x))) }
    }

    /// Runs one ray–triangle test through every stage, reporting each signal to the probe.
    #[inline(always)]
    pub fn trace<P: Probe<F::V>>(&self, ray: &Ray<F::V>, tri: &Tri<F::V>, p: &mut P) -> RtiOut<F::V> {
        self.trace_faulty(ray, tri, p, &NoFault)
    }

    /// [`Rti::trace`] with every arithmetic and compare site computed by `x` (a hardware
    /// fault; [`NoFault`] is the datapath itself). Sites are the signal names below.
    #[inline(always)]
    pub fn trace_faulty<P: Probe<F::V>, X: Fault<F>>(
        &self,
        ray: &Ray<F::V>,
        tri: &Tri<F::V>,
        p: &mut P,
        x: &X,
    ) -> RtiOut<F::V> {
        let f = &self.fmt;
        let sub = |s, a, b| x.arith(f, s, Op::Sub, a, b);
        let add = |s, a, b| x.arith(f, s, Op::Add, a, b);
        let mul = |s, a, b| x.arith(f, s, Op::Mul, a, b);
        let div = |s, a, b| x.arith(f, s, Op::Div, a, b);
        let lt = |s, a, b| x.compare(f, s, Cmp::Lt, a, b);
        let le = |s, a, b| x.compare(f, s, Cmp::Le, a, b);
        let [ox, oy, oz] = ray.o;
        let [dx, dy, dz] = ray.d;
        let [[v0x, v0y, v0z], [v1x, v1y, v1z], [v2x, v2y, v2z]] = tri.v;
        // stage 0, the input read (Format::read_input, the slab unit's stage 0 too): every
        // input below feeds an operation or a compare before anything else, and their NaN and
        // FTZ rules give the same bits on a raw input as on the read one, so the read is
        // implicit here (datapath/tests/nan_inputs.rs checks every signal both ways)
        // stage 1
        let e1x = sub("e1x", v1x, v0x);
        let e1y = sub("e1y", v1y, v0y);
        let e1z = sub("e1z", v1z, v0z);
        let e2x = sub("e2x", v2x, v0x);
        let e2y = sub("e2y", v2y, v0y);
        let e2z = sub("e2z", v2z, v0z);
        let sx = sub("sx", ox, v0x);
        let sy = sub("sy", oy, v0y);
        let sz = sub("sz", oz, v0z);
        record!(p; e1x, e1y, e1z, e2x, e2y, e2z, sx, sy, sz);
        // stage 2
        let pxa = mul("pxa", dy, e2z);
        let pxb = mul("pxb", dz, e2y);
        let pya = mul("pya", dz, e2x);
        let pyb = mul("pyb", dx, e2z);
        let pza = mul("pza", dx, e2y);
        let pzb = mul("pzb", dy, e2x);
        let qxa = mul("qxa", sy, e1z);
        let qxb = mul("qxb", sz, e1y);
        let qya = mul("qya", sz, e1x);
        let qyb = mul("qyb", sx, e1z);
        let qza = mul("qza", sx, e1y);
        let qzb = mul("qzb", sy, e1x);
        record!(p; pxa, pxb, pya, pyb, pza, pzb, qxa, qxb, qya, qyb, qza, qzb);
        // stage 3
        let px = sub("px", pxa, pxb);
        let py = sub("py", pya, pyb);
        let pz = sub("pz", pza, pzb);
        let qx = sub("qx", qxa, qxb);
        let qy = sub("qy", qya, qyb);
        let qz = sub("qz", qza, qzb);
        record!(p; px, py, pz, qx, qy, qz);
        // stage 4
        let detx = mul("detx", e1x, px);
        let dety = mul("dety", e1y, py);
        let detz = mul("detz", e1z, pz);
        let upx = mul("upx", sx, px);
        let upy = mul("upy", sy, py);
        let upz = mul("upz", sz, pz);
        let vpx = mul("vpx", dx, qx);
        let vpy = mul("vpy", dy, qy);
        let vpz = mul("vpz", dz, qz);
        let tpx = mul("tpx", e2x, qx);
        let tpy = mul("tpy", e2y, qy);
        let tpz = mul("tpz", e2z, qz);
        record!(p; detx, dety, detz, upx, upy, upz, vpx, vpy, vpz, tpx, tpy, tpz);
        // stage 5
        let det_xy = add("det_xy", detx, dety);
        let up_xy = add("up_xy", upx, upy);
        let vp_xy = add("vp_xy", vpx, vpy);
        let tp_xy = add("tp_xy", tpx, tpy);
        record!(p; det_xy, up_xy, vp_xy, tp_xy);
        // stage 6
        let det = add("det", det_xy, detz);
        let up = add("up", up_xy, upz);
        let vp = add("vp", vp_xy, vpz);
        let tp = add("tp", tp_xy, tpz);
        record!(p; det, up, vp, tp);
        // stage 7: validity without division
        let uv = add("uv", up, vp);
        record!(p; uv);
        let zero = f.zero();
        let det_ok = match self.cull {
            Cull::TwoSided => lt("det_ok", self.det_thr, f.abs(det)),
            Cull::Backface => lt("det_ok", self.det_thr, det),
        };
        let pos = lt("pos", zero, det);
        let u_ok = if pos { le("u_ok", zero, up) } else { le("u_ok", up, zero) };
        let v_ok = if pos { le("v_ok", zero, vp) } else { le("v_ok", vp, zero) };
        let uv_ok = if pos { le("uv_ok", uv, det) } else { le("uv_ok", det, uv) };
        let t_ok = if pos { le("t_ok", zero, tp) } else { le("t_ok", tp, zero) };
        let valid = det_ok & u_ok & v_ok & uv_ok & t_ok;
        record_flags!(p; det_ok, u_ok, v_ok, uv_ok, t_ok, valid);
        // stages 8-9 (8-10): the divide last
        let (t, u, v) = match f.div_mode() {
            DivMode::RecipMul => {
                let inv_det = div("inv_det", f.one(), det);
                record!(p; inv_det);
                (mul("t", tp, inv_det), mul("u", up, inv_det), mul("v", vp, inv_det))
            }
            DivMode::Divide => (div("t", tp, det), div("u", up, det), div("v", vp, det)),
        };
        record!(p; t, u, v);
        let tmin_ok = le("tmin_ok", ray.tmin, t);
        let tmax_ok = le("tmax_ok", t, ray.tmax);
        let hit = valid & tmin_ok & tmax_ok;
        record_flags!(p; tmin_ok, tmax_ok, hit);
        RtiOut { valid, hit, t, u, v }
    }

    /// One ray–triangle test without probing.
    #[inline(always)]
    pub fn test(&self, ray: &Ray<F::V>, tri: &Tri<F::V>) -> RtiOut<F::V> {
        self.trace(ray, tri, &mut NoProbe)
    }

    /// The min-capture unit: takes `out` for triangle `id` if it hits and is nearer than the
    /// held hit (`t < best` under [`TieRule::First`], `t <= best` under [`TieRule::Last`]).
    #[inline(always)]
    pub fn capture(&self, c: &mut Capture<F::V>, out: &RtiOut<F::V>, id: u32) {
        self.capture_faulty(c, out, id, &NoFault);
    }

    /// [`Rti::capture`] with its sites computed by `x`: the logic sites `hit` (the result's hit
    /// bit gating the unit) and `held` (a hit is held; the first hit is taken without a
    /// compare) and the compare site `take` (`t < best`, or `t <= best` under
    /// [`TieRule::Last`]).
    #[inline(always)]
    /// Returns whether it took `out`.
    pub fn capture_faulty<X: Fault<F>>(&self, c: &mut Capture<F::V>, out: &RtiOut<F::V>, id: u32, x: &X) -> bool {
        if !x.flag("hit", out.hit) {
            return false;
        }
        let take = !x.flag("held", c.hit)
            || match self.tie {
                TieRule::First => x.compare(&self.fmt, "take", Cmp::Lt, out.t, c.t),
                TieRule::Last => x.compare(&self.fmt, "take", Cmp::Le, out.t, c.t),
            };
        if take {
            *c = Capture { hit: true, t: out.t, u: out.u, v: out.v, id };
        }
        take
    }

    /// One ray against a stream of triangles (a leaf), ids `first_id..`: the nearest hit.
    pub fn leaf(&self, ray: &Ray<F::V>, tris: &TrisSoa<F::V>, first_id: u32) -> Capture<F::V> {
        let mut c = Capture::default();
        for i in 0..tris.len() {
            let o = self.test(ray, &tris.get(i));
            self.capture(&mut c, &o, first_id + i as u32);
        }
        c
    }

    /// The broadcast architecture: each triangle of the stream goes to every ray of the packet
    /// in turn; `out[r]` is ray r's min-capture unit (reset here). Same result as [`Rti::leaf`] per ray.
    ///
    /// # Panics
    /// If `out` is shorter than the packet.
    pub fn packet(&self, rays: &RaysSoa<F::V>, tris: &TrisSoa<F::V>, first_id: u32, out: &mut [Capture<F::V>]) {
        let n = rays.len();
        assert!(out.len() >= n, "min-capture buffer shorter than the ray packet");
        out[..n].fill(Capture::default());
        for i in 0..tris.len() {
            let tri = tris.get(i);
            for (r, c) in out[..n].iter_mut().enumerate() {
                let o = self.test(&rays.get(r), &tri);
                self.capture(c, &o, first_id + i as u32);
            }
        }
    }

    /// Pairwise batch over structure-of-arrays: ray i against triangle i into `out` slot i.
    /// Bit-identical to [`Rti::test`]; allocation-free.
    ///
    /// # Panics
    /// If the three batches differ in length.
    pub fn batch(&self, rays: &RaysSoa<F::V>, tris: &TrisSoa<F::V>, out: &mut HitsSoa<F::V>) {
        let n = rays.len();
        assert!(tris.len() == n && out.len() == n, "batch lengths differ");
        self.batch_from(rays, tris, out, 0);
    }

    /// [`Rti::batch`] from slot `from` on (the SIMD kernels' tail).
    ///
    /// # Panics
    /// If a column is shorter than the ray batch.
    pub fn batch_from(&self, rays: &RaysSoa<F::V>, tris: &TrisSoa<F::V>, out: &mut HitsSoa<F::V>, from: usize) {
        for i in from..rays.len() {
            self.batch_slot(rays, tris, out, i);
        }
    }

    /// [`Rti::batch`] on slot `i` alone (the SIMD kernels' tail and filter fall-through).
    ///
    /// # Panics
    /// If a column is shorter than `i + 1`.
    pub fn batch_slot(&self, rays: &RaysSoa<F::V>, tris: &TrisSoa<F::V>, out: &mut HitsSoa<F::V>, i: usize) {
        let o = self.test(&rays.get(i), &tris.get(i));
        out.hit[i] = o.hit;
        out.valid[i] = o.valid;
        out.t[i] = o.t;
        out.u[i] = o.u;
        out.v[i] = o.v;
    }
}

/// Rays as structure-of-arrays columns.
#[derive(Clone, Debug, Default)]
pub struct RaysSoa<V> {
    /// Origin columns.
    pub o: [Vec<V>; 3],
    /// Direction columns.
    pub d: [Vec<V>; 3],
    /// tmin column.
    pub tmin: Vec<V>,
    /// tmax column.
    pub tmax: Vec<V>,
}

impl<V: Copy> RaysSoa<V> {
    /// Empty columns with room for `n` rays.
    pub fn with_capacity(n: usize) -> Self {
        Self {
            o: std::array::from_fn(|_| Vec::with_capacity(n)),
            d: std::array::from_fn(|_| Vec::with_capacity(n)),
            tmin: Vec::with_capacity(n),
            tmax: Vec::with_capacity(n),
        }
    }
    /// Sets the number of rays (new slots hold `fill`), keeping the allocations.
    pub fn resize(&mut self, n: usize, fill: V) {
        self.o.iter_mut().chain(&mut self.d).for_each(|c| c.resize(n, fill));
        self.tmin.resize(n, fill);
        self.tmax.resize(n, fill);
    }
    /// Overwrites every ray with `r` (what [`Self::set`] of each index does, column by column).
    #[inline]
    pub fn fill(&mut self, r: &Ray<V>) {
        for k in 0..3 {
            self.o[k].fill(r.o[k]);
            self.d[k].fill(r.d[k]);
        }
        self.tmin.fill(r.tmin);
        self.tmax.fill(r.tmax);
    }
    /// Overwrites ray i.
    #[inline(always)]
    pub fn set(&mut self, i: usize, r: &Ray<V>) {
        for k in 0..3 {
            self.o[k][i] = r.o[k];
            self.d[k][i] = r.d[k];
        }
        self.tmin[i] = r.tmin;
        self.tmax[i] = r.tmax;
    }
    /// Number of rays.
    pub fn len(&self) -> usize {
        self.tmin.len()
    }
    /// True when empty.
    pub fn is_empty(&self) -> bool {
        self.tmin.is_empty()
    }
    /// Appends a ray.
    pub fn push(&mut self, r: &Ray<V>) {
        for k in 0..3 {
            self.o[k].push(r.o[k]);
            self.d[k].push(r.d[k]);
        }
        self.tmin.push(r.tmin);
        self.tmax.push(r.tmax);
    }
    /// Ray i.
    #[inline(always)]
    pub fn get(&self, i: usize) -> Ray<V> {
        Ray {
            o: [self.o[0][i], self.o[1][i], self.o[2][i]],
            d: [self.d[0][i], self.d[1][i], self.d[2][i]],
            tmin: self.tmin[i],
            tmax: self.tmax[i],
        }
    }
}

/// Triangles as structure-of-arrays columns: `v[vertex][axis]`.
#[derive(Clone, Debug, Default)]
pub struct TrisSoa<V> {
    /// Vertex coordinate columns.
    pub v: [[Vec<V>; 3]; 3],
}

impl<V: Copy> TrisSoa<V> {
    /// Empty columns with room for `n` triangles.
    pub fn with_capacity(n: usize) -> Self {
        Self { v: std::array::from_fn(|_| std::array::from_fn(|_| Vec::with_capacity(n))) }
    }
    /// Sets the number of triangles (new slots hold `fill`), keeping the allocations.
    pub fn resize(&mut self, n: usize, fill: V) {
        self.v.iter_mut().flatten().for_each(|c| c.resize(n, fill));
    }
    /// Overwrites triangle i.
    #[inline(always)]
    pub fn set(&mut self, i: usize, t: &Tri<V>) {
        for j in 0..3 {
            for k in 0..3 {
                self.v[j][k][i] = t.v[j][k];
            }
        }
    }
    /// Number of triangles.
    pub fn len(&self) -> usize {
        self.v[0][0].len()
    }
    /// True when empty.
    pub fn is_empty(&self) -> bool {
        self.v[0][0].is_empty()
    }
    /// Appends a triangle.
    pub fn push(&mut self, t: &Tri<V>) {
        for j in 0..3 {
            for k in 0..3 {
                self.v[j][k].push(t.v[j][k]);
            }
        }
    }
    /// Triangle i.
    #[inline(always)]
    pub fn get(&self, i: usize) -> Tri<V> {
        Tri { v: [0, 1, 2].map(|j| [self.v[j][0][i], self.v[j][1][i], self.v[j][2][i]]) }
    }
}

/// Batch outputs as structure-of-arrays columns.
#[derive(Clone, Debug, Default)]
pub struct HitsSoa<V> {
    /// Hit bits.
    pub hit: Vec<bool>,
    /// Valid bits.
    pub valid: Vec<bool>,
    /// t column.
    pub t: Vec<V>,
    /// u column.
    pub u: Vec<V>,
    /// v column.
    pub v: Vec<V>,
}

impl<V: Copy + Default> HitsSoa<V> {
    /// Output columns for `n` results.
    pub fn with_len(n: usize) -> Self {
        Self {
            hit: vec![false; n],
            valid: vec![false; n],
            t: vec![V::default(); n],
            u: vec![V::default(); n],
            v: vec![V::default(); n],
        }
    }
    /// Sets the number of result slots (new slots hold defaults), keeping the allocations.
    pub fn resize(&mut self, n: usize) {
        self.hit.resize(n, false);
        self.valid.resize(n, false);
        for c in [&mut self.t, &mut self.u, &mut self.v] {
            c.resize(n, V::default());
        }
    }
    /// Number of results.
    pub fn len(&self) -> usize {
        self.hit.len()
    }
    /// True when empty.
    pub fn is_empty(&self) -> bool {
        self.hit.is_empty()
    }
}
