//! `raypipe explain`: every stage signal of one RTI test (value and hex bits) beside the same
//! datapath evaluated in binary64 and the golden f64 result, or every signal of one slab test
//! beside the f64 reference and the exact decision — how one failing RTL case is debugged.
//! The trace is data ([`RtiTrace`], [`SlabTrace`]); the text and `--json` are two views of it.

use crate::judge::{faces, quantise};
use datapath::bound::RtiBound;
use datapath::format::{FloatLayout, FpOpts, Ieee, Soft};
use datapath::probe::{Recorder, Signal};
use datapath::rti::{stage_table, Op, Rti, RtiConfig};
use datapath::slab::Slab;
use datapath::Format;
use golden::{Ray64, Tri64};
use serde::Serialize;
use std::fmt::Write;

/// One value as the testbench sees it: the number (`%e`, or `true`/`false` for a flag) and the
/// hex bits it drives or probes.
#[derive(Clone, Debug, Serialize)]
pub struct Value {
    /// Signal or input name.
    pub name: String,
    /// The value in decimal (`inf`, `NaN`, or a flag's `true`/`false`).
    pub value: String,
    /// The encoding in hex (a flag: 0 or 1).
    pub bits: String,
}

/// One stage signal of the RTI trace.
#[derive(Clone, Debug, Serialize)]
pub struct RtiSignal {
    /// Stage.
    pub stage: u8,
    /// Signal name and the model's value.
    #[serde(flatten)]
    pub model: Value,
    /// The operation, as in the stage table (for a compare/logic row, its rule).
    pub op: String,
    /// A compare/logic row (a 1-bit signal).
    pub logic: bool,
    /// The same datapath in binary64 on the same quantised inputs.
    pub binary64: String,
    /// (model − binary64) in ulps of the format, when both are finite.
    pub diff_ulps: Option<f64>,
}

/// Every signal of one ray–triangle test.
#[derive(Clone, Debug, Serialize)]
pub struct RtiTrace {
    /// Format.
    pub format: String,
    /// Bits per value.
    pub width: u32,
    /// The quantised inputs.
    pub inputs: Vec<Value>,
    /// Every stage signal in stage-table order.
    pub signals: Vec<RtiSignal>,
    /// The model's outputs: valid, hit, t, u, v.
    pub model: Vec<Value>,
    /// The golden f64 Möller–Trumbore on the quantised inputs.
    pub golden: GoldenRti,
    /// The error bound's verdict.
    pub bound: BoundRti,
    /// The bank fault the model ran with (`--inject`), if any.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub injected: Option<String>,
}

/// The golden RTI result.
#[derive(Clone, Debug, Serialize)]
pub struct GoldenRti {
    /// Hit.
    pub hit: bool,
    /// t, u, v, det, |det|/(|d||e1||e2|), barycentric margin, edge distance (decimal strings).
    pub t: String,
    /// u.
    pub u: String,
    /// v.
    pub v: String,
    /// det.
    pub det: String,
    /// |det| / (|d| |e1| |e2|).
    pub det_rel: String,
    /// min(u, v, 1 − u − v).
    pub bary_margin: String,
    /// Distance of the hit point from the nearest edge.
    pub edge_dist: String,
}

/// The RTI error bound at this test.
#[derive(Clone, Debug, Serialize)]
pub struct BoundRti {
    /// Every compared quantity is farther from its threshold than its bound: the model must agree.
    pub decisive: bool,
    /// The reference hit decision `verify` judges by: the bound's when decisive, else the f64
    /// filter's, else exact rational arithmetic's on the quantised inputs.
    pub exact_hit: bool,
    /// What decided `exact_hit`: `bound`, `f64_filter`, `exact` or `golden_f64`.
    pub decided_by: crate::judge::DecidedBy,
    /// Bounds on |error| of det, up, vp, tp and t.
    pub det_err: f64,
    /// up.
    pub up_err: f64,
    /// vp.
    pub vp_err: f64,
    /// tp.
    pub tp_err: f64,
    /// t.
    pub t_err: f64,
}

fn num(x: f64) -> String {
    format!("{x:e}")
}

fn value<F: Format>(f: &F, name: &str, v: F::V) -> Value {
    Value { name: name.into(), value: num(f.to_f64(v)), bits: f.hex(v) }
}

fn flag(name: &str, b: bool) -> Value {
    Value { name: name.into(), value: b.to_string(), bits: (b as u8).to_string() }
}

/// The stage-by-stage trace of one ray–triangle test.
pub fn trace_rti<F: Format>(rti: &Rti<F>, ray: &Ray64, tri: &Tri64) -> RtiTrace {
    trace_rti_faulty(rti, ray, tri, None)
}

/// [`trace_rti`] of the model running with a fault of the bank (`verify --inject`; None: the
/// model itself).
pub fn trace_rti_faulty<F: Format>(
    rti: &Rti<F>,
    ray: &Ray64,
    tri: &Tri64,
    inject: Option<&'static faults::bank::Spec>,
) -> RtiTrace {
    let f = &rti.fmt;
    let (rq, tq) = quantise(rti, ray, tri);
    let mut rec = Recorder::new();
    let (mray, mtri) = (rti.ray(ray.o, ray.d, ray.tmin, ray.tmax), rti.tri(tri.v));
    let out = match inject {
        Some(spec) => rti.trace_faulty(&mray, &mtri, &mut rec, &faults::inject::Injected::new(spec)),
        None => rti.trace(&mray, &mtri, &mut rec),
    };
    // the same datapath in binary64 on the quantised inputs
    let twin_fmt = Ieee::new(Soft(FloatLayout::BINARY64), FpOpts { div: f.div_mode(), ..FpOpts::default() });
    let twin = Rti::new(twin_fmt, RtiConfig { cull: rti.cull, det_threshold: f.to_f64(rti.det_thr), tie: rti.tie });
    let mut trec = Recorder::new();
    twin.trace(&twin.ray(rq.o, rq.d, rq.tmin, rq.tmax), &twin.tri(tq.v), &mut trec);
    let mut inputs = Vec::new();
    for (n, v) in ["ox", "oy", "oz", "dx", "dy", "dz"].iter().zip(rq.o.iter().chain(rq.d.iter())) {
        inputs.push(value(f, n, f.from_f64(*v)));
    }
    for (k, p) in tq.v.iter().enumerate() {
        for (a, v) in p.iter().enumerate() {
            inputs.push(value(f, &format!("v{k}{}", ["x", "y", "z"][a]), f.from_f64(*v)));
        }
    }
    inputs.push(value(f, "tmin", f.from_f64(rq.tmin)));
    inputs.push(value(f, "tmax", f.from_f64(rq.tmax)));
    let mut signals = Vec::new();
    for d in stage_table(f.div_mode()) {
        let op = match d.op {
            Op::Sub => format!("{} - {}", d.a, d.b),
            Op::Add => format!("{} + {}", d.a, d.b),
            Op::Mul => format!("{} * {}", d.a, d.b),
            Op::Div => format!("{} / {}", d.a, d.b),
            Op::Logic => d.note.to_string(),
        };
        let logic = d.op == Op::Logic;
        match (rec.get(d.name), trec.get(d.name)) {
            (Some(Signal::Value(v)), Some(Signal::Value(w))) => {
                let (x, y) = (f.to_f64(v), f64::from_bits(w));
                let diff = (x.is_finite() && y.is_finite()).then(|| (x - y) / f.ulp(y));
                signals.push(RtiSignal {
                    stage: d.stage,
                    model: value(f, d.name, v),
                    op,
                    logic,
                    binary64: num(y),
                    diff_ulps: diff,
                });
            }
            (Some(Signal::Flag(b)), Some(Signal::Flag(c))) => {
                signals.push(RtiSignal {
                    stage: d.stage,
                    model: flag(d.name, b),
                    op,
                    logic,
                    binary64: c.to_string(),
                    diff_ulps: None,
                });
            }
            _ => {}
        }
    }
    let g = golden::intersect(&rq, &tq, faces(rti));
    let b = RtiBound::new(f.error_model(), f.div_mode(), rq.o, rq.d, tq.v);
    let v = b.verdict(rti.cull, f.to_f64(rti.det_thr), rq.tmin, rq.tmax);
    let (exact_hit, decided_by) = crate::judge::decide(rti, &rq, &tq, v, g.hit);
    RtiTrace {
        format: f.name(),
        width: f.width(),
        inputs,
        signals,
        model: vec![
            flag("valid", out.valid),
            flag("hit", out.hit),
            value(f, "t", out.t),
            value(f, "u", out.u),
            value(f, "v", out.v),
        ],
        golden: GoldenRti {
            hit: g.hit,
            t: num(g.t),
            u: num(g.u),
            v: num(g.v),
            det: num(g.det),
            det_rel: num(g.det_rel),
            bary_margin: num(g.bary_margin),
            edge_dist: num(g.edge_dist),
        },
        bound: BoundRti {
            decisive: v.decisive,
            exact_hit,
            decided_by,
            det_err: b.det.err(),
            up_err: b.up.err(),
            vp_err: b.vp.err(),
            tp_err: b.tp.err(),
            t_err: b.t_err,
        },
        injected: inject.map(|x| x.name.to_string()),
    }
}

/// The RTI trace as text.
pub fn render_rti(t: &RtiTrace) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "format {}  ({} bits per value)", t.format, t.width);
    if let Some(name) = &t.injected {
        let _ = writeln!(s, "injected fault: {name} (the model's signals below are the faulty datapath's)");
    }
    let _ = writeln!(s, "inputs (quantised; hex = the bits an RTL testbench drives):");
    for v in &t.inputs {
        let _ = writeln!(s, "  {:<5} {:>24} {}", v.name, v.value, v.bits);
    }
    let _ = writeln!(
        s,
        "\n{:>2}  {:<8} {:<18} {:>24} {:>17} {:>24} {:>10}",
        "st", "signal", "op", "model", "bits", "binary64 twin", "diff ulp"
    );
    for g in &t.signals {
        let op = if g.logic { "logic" } else { g.op.as_str() };
        let diff = match (g.diff_ulps, g.logic) {
            (Some(d), _) => format!("{d:.2}"),
            (None, true) if g.model.value != g.binary64 => "DIFFERS".into(),
            (None, true) => String::new(),
            (None, false) => "-".into(),
        };
        let _ = writeln!(
            s,
            "{:>2}  {:<8} {:<18} {:>24} {:>17} {:>24} {:>10}",
            g.stage, g.model.name, op, g.model.value, g.model.bits, g.binary64, diff
        );
    }
    let m = |n: &str| t.model.iter().find(|v| v.name == n).map_or("", |v| v.value.as_str()).to_string();
    let _ = writeln!(s, "\nmodel : hit {} valid {} t {} u {} v {}", m("hit"), m("valid"), m("t"), m("u"), m("v"));
    let g = &t.golden;
    let _ = writeln!(
        s,
        "golden: hit {} t {} u {} v {} det {} |det|/(|d||e1||e2|) {} barycentric margin {} edge distance {}",
        g.hit, g.t, g.u, g.v, g.det, g.det_rel, g.bary_margin, g.edge_dist
    );
    let b = &t.bound;
    let _ = writeln!(
        s,
        "bound : decisive {} (exact hit {}, decided by {}); |err| det <= {:.3e}, up <= {:.3e}, vp <= {:.3e}, tp <= {:.3e}, t <= {:.3e}",
        b.decisive, b.exact_hit, b.decided_by.words(), b.det_err, b.up_err, b.vp_err, b.tp_err, b.t_err
    );
    s
}

/// Every signal of one ray–box test.
#[derive(Clone, Debug, Serialize)]
pub struct SlabTrace {
    /// Format.
    pub format: String,
    /// Variant name.
    pub variant: String,
    /// The stored (outward-rounded) box: min x y z, max x y z.
    pub stored_box: Vec<Value>,
    /// Every signal in the order the model reports it (the stage table's order).
    pub signals: Vec<Value>,
    /// The model's outputs: hit, t_near, t_far.
    pub model: Vec<Value>,
    /// The f64 reference on the quantised ray and the original box: hit, t_near, t_far.
    pub golden_hit: bool,
    /// Its entry distance.
    pub golden_t_near: String,
    /// Its exit distance.
    pub golden_t_far: String,
    /// The exact decision (rational arithmetic); `None` when a quantised origin or direction
    /// component is not finite.
    pub exact_hit: Option<bool>,
}

/// The trace of one ray–box test.
pub fn trace_slab<F: Format>(
    s: &Slab<F>,
    variant: &str,
    ray: &Ray64,
    lo: [f64; 3],
    hi: [f64; 3],
) -> Result<SlabTrace, String> {
    let f = &s.fmt;
    let b = s.store_box(lo, hi).map_err(|e| e.to_string())?;
    let mut rec = Recorder::new();
    let r = s.prepare_trace(ray.o, ray.d, ray.tmin, ray.tmax, &mut rec);
    let out = s.trace(&r, &b, &mut rec);
    let names = ["minx", "miny", "minz", "maxx", "maxy", "maxz"];
    let stored_box = names.iter().zip(b.min.iter().chain(b.max.iter())).map(|(n, v)| value(f, n, *v)).collect();
    let signals = rec
        .signals
        .iter()
        .map(|(name, sig)| match sig {
            Signal::Value(v) => value(f, name, *v),
            Signal::Flag(x) => flag(name, *x),
        })
        .collect();
    let q = |x: f64| f.to_f64(f.from_f64(x));
    let (oq, dq) = (ray.o.map(q), ray.d.map(q));
    let g = golden::slab_f64(oq, dq, q(ray.tmin), q(ray.tmax), lo, hi);
    Ok(SlabTrace {
        format: f.name(),
        variant: variant.into(),
        stored_box,
        signals,
        model: vec![flag("hit", out.hit), value(f, "t_near", out.t_near), value(f, "t_far", out.t_far)],
        golden_hit: g.hit,
        golden_t_near: num(g.t_near),
        golden_t_far: num(g.t_far),
        exact_hit: golden::slab_exact(oq, dq, q(ray.tmin), q(ray.tmax), lo, hi),
    })
}

/// The slab trace as text.
pub fn render_slab(t: &SlabTrace) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "format {}  variant {}", t.format, t.variant);
    let _ = writeln!(s, "stored box (outward-rounded):");
    for v in &t.stored_box {
        let _ = writeln!(s, "  {:<8} {:>24} {:>17}", v.name, v.value, v.bits);
    }
    let _ = writeln!(s, "\n{:<8} {:>24} {:>17}", "signal", "value", "bits");
    for v in &t.signals {
        let _ = writeln!(s, "{:<8} {:>24} {:>17}", v.name, v.value, v.bits);
    }
    let m = |n: &str| t.model.iter().find(|v| v.name == n).map_or("", |v| v.value.as_str()).to_string();
    let _ = writeln!(s, "\nmodel : hit {} t_near {} t_far {}", m("hit"), m("t_near"), m("t_far"));
    let exact = match t.exact_hit {
        Some(e) => e.to_string(),
        None => "none (a quantised origin or direction component is not finite)".into(),
    };
    let _ = writeln!(
        s,
        "golden: hit {} t_near {} t_far {} (f64, quantised ray, original box); exact decision: hit {exact}",
        t.golden_hit, t.golden_t_near, t.golden_t_far
    );
    s
}
