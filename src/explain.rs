//! `raypipe explain`: every stage signal of one RTI test (value and hex bits) beside the same
//! datapath evaluated in binary64 and the golden f64 result — how one failing RTL case is debugged.

use crate::judge::{faces, quantise};
use datapath::bound::RtiBound;
use datapath::format::{FloatLayout, FpOpts, Ieee, Soft};
use datapath::probe::{Recorder, Signal};
use datapath::rti::{stage_table, Op, Rti, RtiConfig};
use datapath::Format;
use golden::{Ray64, Tri64};
use std::fmt::Write;

/// Renders the stage-by-stage trace of one test.
pub fn explain<F: Format>(rti: &Rti<F>, ray: &Ray64, tri: &Tri64) -> String {
    let f = &rti.fmt;
    let (rq, tq) = quantise(rti, ray, tri);
    let mut rec = Recorder::new();
    let out = rti.trace(&rti.ray(ray.o, ray.d, ray.tmin, ray.tmax), &rti.tri(tri.v), &mut rec);
    // the same datapath in binary64 on the quantised inputs
    let twin_fmt = Ieee::new(Soft(FloatLayout::BINARY64), FpOpts { div: f.div_mode(), ..FpOpts::default() });
    let twin = Rti::new(twin_fmt, RtiConfig { cull: rti.cull, det_threshold: f.to_f64(rti.det_thr), tie: rti.tie });
    let mut trec = Recorder::new();
    twin.trace(&twin.ray(rq.o, rq.d, rq.tmin, rq.tmax), &twin.tri(tq.v), &mut trec);

    let mut s = String::new();
    let _ = writeln!(s, "format {}  ({} bits per value)", f.name(), f.width());
    let _ = writeln!(s, "inputs (quantised; hex = the bits an RTL testbench drives):");
    let names = ["ox", "oy", "oz", "dx", "dy", "dz"];
    let vals: Vec<f64> = rq.o.iter().chain(rq.d.iter()).copied().collect();
    for (n, v) in names.iter().zip(vals) {
        let _ = writeln!(s, "  {n:<5} {:>24} {}", format!("{v:e}"), f.hex(f.from_f64(v)));
    }
    for (k, p) in tq.v.iter().enumerate() {
        for (a, v) in p.iter().enumerate() {
            let _ = writeln!(s, "  v{k}{}   {:>24} {}", ["x", "y", "z"][a], format!("{v:e}"), f.hex(f.from_f64(*v)));
        }
    }
    let _ = writeln!(
        s,
        "\n{:>2}  {:<8} {:<18} {:>24} {:>17} {:>24} {:>10}",
        "st", "signal", "op", "model", "bits", "binary64 twin", "diff ulp"
    );
    for d in stage_table(f.div_mode()) {
        let opstr = match d.op {
            Op::Sub => format!("{} - {}", d.a, d.b),
            Op::Add => format!("{} + {}", d.a, d.b),
            Op::Mul => format!("{} * {}", d.a, d.b),
            Op::Div => format!("{} / {}", d.a, d.b),
            Op::Logic => "logic".to_string(),
        };
        match (rec.get(d.name), trec.get(d.name)) {
            (Some(Signal::Value(v)), Some(Signal::Value(w))) => {
                let (x, y) = (f.to_f64(v), f64::from_bits(w));
                let diff =
                    if x.is_finite() && y.is_finite() { format!("{:.2}", (x - y) / f.ulp(y)) } else { "-".into() };
                let _ = writeln!(
                    s,
                    "{:>2}  {:<8} {:<18} {:>24} {:>17} {:>24} {:>10}",
                    d.stage,
                    d.name,
                    opstr,
                    format!("{x:e}"),
                    f.hex(v),
                    format!("{y:e}"),
                    diff
                );
            }
            (Some(Signal::Flag(b)), Some(Signal::Flag(c))) => {
                let _ = writeln!(
                    s,
                    "{:>2}  {:<8} {:<18} {:>24} {:>17} {:>24} {:>10}",
                    d.stage,
                    d.name,
                    opstr,
                    b,
                    b as u8,
                    c,
                    if b == c { "" } else { "DIFFERS" }
                );
            }
            _ => {}
        }
    }
    let g = golden::intersect(&rq, &tq, faces(rti));
    let b = RtiBound::new(f.error_model(), f.div_mode(), rq.o, rq.d, tq.v);
    let v = b.verdict(rti.cull, f.to_f64(rti.det_thr), rq.tmin, rq.tmax);
    let _ = writeln!(
        s,
        "\nmodel : hit {} valid {} t {:e} u {:e} v {:e}",
        out.hit,
        out.valid,
        f.to_f64(out.t),
        f.to_f64(out.u),
        f.to_f64(out.v)
    );
    let _ = writeln!(s, "golden: hit {} t {:e} u {:e} v {:e} det {:e} |det|/(|d||e1||e2|) {:.3e} barycentric margin {:.3e} edge distance {:.3e}", g.hit, g.t, g.u, g.v, g.det, g.det_rel, g.bary_margin, g.edge_dist);
    let _ = writeln!(
        s,
        "bound : decisive {} (exact hit {}); |err| det <= {:.3e}, u' <= {:.3e}, v' <= {:.3e}, t' <= {:.3e}, t <= {:.3e}",
        v.decisive,
        v.hit,
        b.det.err(),
        b.up.err(),
        b.vp.err(),
        b.tp.err(),
        b.t_err
    );
    s
}

/// Renders every slab signal of one ray–box test (value and hex bits), the f64 reference and
/// the exact decision.
pub fn explain_slab<F: Format>(
    s: &datapath::slab::Slab<F>,
    ray: &Ray64,
    lo: [f64; 3],
    hi: [f64; 3],
) -> Result<String, String> {
    let f = &s.fmt;
    let b = s.store_box(lo, hi).map_err(|e| e.to_string())?;
    let mut rec = Recorder::new();
    let r = s.prepare_trace(ray.o, ray.d, ray.tmin, ray.tmax, &mut rec);
    let out = s.trace(&r, &b, &mut rec);
    let mut t = String::new();
    let _ = writeln!(t, "format {}  variant {:?}", f.name(), s.cfg);
    let _ = writeln!(
        t,
        "stored box (outward-rounded): min {:?} max {:?}",
        b.min.map(|v| f.to_f64(v)),
        b.max.map(|v| f.to_f64(v))
    );
    let _ = writeln!(
        t,
        "  bits min {} {} {}  max {} {} {}",
        f.hex(b.min[0]),
        f.hex(b.min[1]),
        f.hex(b.min[2]),
        f.hex(b.max[0]),
        f.hex(b.max[1]),
        f.hex(b.max[2])
    );
    let _ = writeln!(t, "\n{:<8} {:>24} {:>17}", "signal", "value", "bits");
    for (name, sig) in &rec.signals {
        match sig {
            Signal::Value(v) => {
                let _ = writeln!(t, "{:<8} {:>24} {:>17}", name, format!("{:e}", f.to_f64(*v)), f.hex(*v));
            }
            Signal::Flag(x) => {
                let _ = writeln!(t, "{:<8} {:>24} {:>17}", name, x, *x as u8);
            }
        }
    }
    let q = |x: f64| f.to_f64(f.from_f64(x));
    let (oq, dq) = (ray.o.map(q), ray.d.map(q));
    let g = golden::slab_f64(oq, dq, q(ray.tmin), q(ray.tmax), lo, hi);
    let exact = match golden::slab_exact(oq, dq, q(ray.tmin), q(ray.tmax), lo, hi) {
        Some(e) => e.to_string(),
        None => "none (a quantised origin or direction component is not finite)".into(),
    };
    let _ = writeln!(t, "\nmodel : hit {} t_near {:e} t_far {:e}", out.hit, f.to_f64(out.t_near), f.to_f64(out.t_far));
    let _ = writeln!(
        t,
        "golden: hit {} t_near {:e} t_far {:e} (f64, quantised ray, original box); exact decision: hit {}",
        g.hit, g.t_near, g.t_far, exact
    );
    Ok(t)
}
