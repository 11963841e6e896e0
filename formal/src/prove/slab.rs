//! `slab-never-misses`: every finite input whose exact (real-number) slab interval is
//! non-empty is a model hit.
//!
//! The query is the emitted slab model plus: every input finite, `min <= max` on each axis,
//! `tmin <= tmax`, the exact interval `[max(tmin, L_x, L_y, L_z), min(tmax, H_x, H_y, H_z)]`
//! non-empty, and `hit` false. `L_a`, `H_a` are the exact entry and exit distances of axis
//! `a` (`(b − o)/d` of its two planes, ordered by the sign of `d`); an axis with `d = ±0`
//! is no constraint when `min <= o <= max` and empties the interval otherwise. The exact
//! comparisons `n1/d1 <= n2/d2` are cross-multiplied (`n1·d2 <= n2·d1`, denominators made
//! positive) in a wider `FloatingPoint` sort in which every difference of two format values
//! and every product of such a difference with a format value is exact (binary64 for
//! formats with at most 5 exponent bits, binary128 for 6), so no rounding enters the
//! statement: it is a statement about real numbers.

use super::Proof;
use crate::smt::{emit, Model, Request, Unit};
use crate::solver::{self, Verdict};
use datapath::format::{FloatLayout, FormatKind};
use datapath::Format;
use std::fmt::Write;

/// The exact sort `(E, S)` for a layout: every difference of two values times a value is
/// exact in it (None: no standard sort is wide enough).
pub fn exact_sort(l: FloatLayout) -> Option<(u32, u32)> {
    // values are k·2^(emin − M) with |k| < 2^span, span = emax + 1 − emin + M
    let span = (l.emax() + 1 - l.emin()) as u32 + l.man_bits;
    // a difference has at most span + 1 significant bits, a product with a value M + 1 more
    let need = span + 1 + l.man_bits + 1;
    if need <= 53 {
        Some((11, 53))
    } else if need <= 113 {
        Some((15, 113))
    } else {
        None
    }
}

/// [`exact_sort`], or why the layout has none.
fn exact_sort_for(lay: FloatLayout) -> Result<(u32, u32), String> {
    exact_sort(lay).ok_or_else(|| {
        format!(
            "no exact sort: a difference of two values of e{}m{} times a value needs more than 113 bits (binary128); not provable this way",
            lay.exp_bits, lay.man_bits
        )
    })
}

/// The theorem in words.
pub const THEOREM: &str = "for every input whose 14 encodings are finite (no NaN, no infinity), with min <= max on each axis and tmin <= tmax, if the exact real-number slab interval [max(tmin, L_x, L_y, L_z), min(tmax, H_x, H_y, H_z)] is non-empty (an axis with d = +-0 and min <= o <= max imposes no constraint; with o outside it empties the interval), the model reports hit";

/// The query: satisfiable exactly when some input is an exact hit the model misses.
pub fn query(m: &Model, lay: FloatLayout) -> Result<String, String> {
    let (ee, ss) = exact_sort_for(lay)?;
    let mut q = m.text.clone();
    let x = |t: &str| format!("((_ to_fp {ee} {ss}) RNE (rp_fp {t}))");
    let _ = writeln!(q, "; ---- slab-never-misses: the exact interval is non-empty and the model misses");
    let _ = writeln!(q, "; exact values in (_ FloatingPoint {ee} {ss}): every difference and product below is exact");
    for n in &m.inputs {
        let _ = writeln!(q, "(assert (rp_finite in_{n}))");
    }
    for a in ["x", "y", "z"] {
        let _ = writeln!(q, "(assert (fp.leq (rp_fp in_min{a}) (rp_fp in_max{a})))");
    }
    let _ = writeln!(q, "(assert (fp.leq (rp_fp in_tmin) (rp_fp in_tmax)))");
    let sort = format!("(_ FloatingPoint {ee} {ss})");
    for n in &m.inputs {
        let _ = writeln!(q, "(define-fun x_{n} () {sort} {})", x(&format!("in_{n}")));
    }
    let one = format!("((_ to_fp {ee} {ss}) RNE 1.0)");
    // lower ends (num, den, zero-axis) and upper ends
    let mut lower = vec![("x_tmin".to_string(), one.clone(), "false".to_string())];
    let mut upper = vec![("x_tmax".to_string(), one.clone(), "false".to_string())];
    for a in ["x", "y", "z"] {
        let (o, d, lo, hi) = (format!("x_o{a}"), format!("x_d{a}"), format!("x_min{a}"), format!("x_max{a}"));
        let pos = format!("(fp.isPositive {d})");
        let sub = |p: &str, q: &str| format!("(fp.sub RNE {p} {q})");
        // d > 0: L = (min − o)/d, H = (max − o)/d; d < 0: L = (o − max)/(−d), H = (o − min)/(−d)
        let den = format!("(ite {pos} {d} (fp.neg {d}))");
        let ln = format!("(ite {pos} {} {})", sub(&lo, &o), sub(&o, &hi));
        let hn = format!("(ite {pos} {} {})", sub(&hi, &o), sub(&o, &lo));
        let _ = writeln!(q, "(define-fun zero_{a} () Bool (fp.isZero {d}))");
        let _ = writeln!(q, "(define-fun den_{a} () {sort} {den})");
        let _ = writeln!(q, "(define-fun ln_{a} () {sort} {ln})");
        let _ = writeln!(q, "(define-fun hn_{a} () {sort} {hn})");
        lower.push((format!("ln_{a}"), format!("den_{a}"), format!("zero_{a}")));
        upper.push((format!("hn_{a}"), format!("den_{a}"), format!("zero_{a}")));
    }
    let mut conds = Vec::new();
    for a in ["x", "y", "z"] {
        conds.push(format!("(=> zero_{a} (and (fp.leq x_min{a} x_o{a}) (fp.leq x_o{a} x_max{a})))"));
    }
    for (n1, d1, z1) in &lower {
        for (n2, d2, z2) in &upper {
            conds.push(format!("(or {z1} {z2} (fp.leq (fp.mul RNE {n1} {d2}) (fp.mul RNE {n2} {d1})))"));
        }
    }
    let _ = writeln!(q, "(define-fun exact_hit () Bool (and\n  {}))", conds.join("\n  "));
    let _ = writeln!(q, "(assert exact_hit)");
    let _ = writeln!(q, "(assert (not hit))");
    Ok(q)
}

/// The per-axis lemma for axis `a` ("x", "y" or "z"), widening `w` steps: satisfiable exactly
/// when, for finite `o`, `d`, `min <= max` of that axis, the axis's slab is non-empty and a
/// non-NaN stage-3 candidate widened as stage 5 widens (`near` by `w` nextDowns, `far` by `w`
/// nextUps) lies on the wrong side of its exact plane distance: `near` above the exact entry
/// `L`, or `far` below the exact exit `H` (for `d = ±0` with `min <= o <= max`: `near` not
/// −∞ or `far` not +∞).
pub fn lemma_query(m: &Model, lay: FloatLayout, a: &str, w: u32) -> Result<String, String> {
    let (ee, ss) = exact_sort_for(lay)?;
    let mut q = m.text.clone();
    let x = |t: &str| format!("((_ to_fp {ee} {ss}) RNE (rp_fp {t}))");
    let _ = writeln!(
        q,
        "; ---- slab-never-misses, axis {a}: a widened candidate on the wrong side of its exact plane distance"
    );
    for n in [format!("o{a}"), format!("d{a}"), format!("min{a}"), format!("max{a}")] {
        let _ = writeln!(q, "(assert (rp_finite in_{n}))");
    }
    let _ = writeln!(q, "(assert (fp.leq (rp_fp in_min{a}) (rp_fp in_max{a})))");
    let (o, d, lo, hi) =
        (x(&format!("in_o{a}")), x(&format!("in_d{a}")), x(&format!("in_min{a}")), x(&format!("in_max{a}")));
    let widen = |f: &str, v: &str| (0..w).fold(v.to_string(), |t, _| format!("({f} {t})"));
    let nw = widen("rp_down", &format!("near{a}"));
    let fw = widen("rp_up", &format!("far{a}"));
    let ninf = m.float.lit(lay.inf(true));
    let pinf = m.float.lit(lay.inf(false));
    let mul = |v: &str| format!("(fp.mul RNE {} {d})", x(v));
    let sub = |p: &str, r: &str| format!("(fp.sub RNE {p} {r})");
    // d > 0: L = (min − o)/d, so near·d <= min − o; H = (max − o)/d, so far·d >= max − o.
    // d < 0 flips both: L = (max − o)/d, near·d >= max − o; H = (min − o)/d, far·d <= min − o.
    let near_ok = format!(
        "(or (rp_isnan near{a}) (ite (fp.isZero {d}) (= {nw} {ninf}) (ite (fp.isPositive {d}) (fp.leq {} {}) (fp.geq {} {}))))",
        mul(&nw),
        sub(&lo, &o),
        mul(&nw),
        sub(&hi, &o)
    );
    let far_ok = format!(
        "(or (rp_isnan far{a}) (ite (fp.isZero {d}) (= {fw} {pinf}) (ite (fp.isPositive {d}) (fp.geq {} {}) (fp.leq {} {}))))",
        mul(&fw),
        sub(&hi, &o),
        mul(&fw),
        sub(&lo, &o)
    );
    let nonempty = format!("(or (not (fp.isZero {d})) (and (fp.leq {lo} {o}) (fp.leq {o} {hi})))");
    let _ = writeln!(q, "(assert {nonempty})");
    let _ = writeln!(q, "(assert (not (and {near_ok} {far_ok})))");
    Ok(q)
}

/// Proves `slab-never-misses` for the slab variant and format of `req`: the per-axis lemma
/// ([`lemma_query`], one query per axis) and the composition (docs/proofs.md) give the
/// theorem; when a lemma fails, the whole query ([`query`]) looks for a real miss, which is
/// the counterexample.
pub fn prove(req: &Request, solver: &str, timeout_s: f64, threads: usize) -> Result<Proof, String> {
    if req.unit != Unit::Slab {
        return Err("slab-never-misses is a property of the slab unit".into());
    }
    if req.variant == "directed" {
        return prove_directed(req, threads);
    }
    let (lay, cfg) = datapath::with_format!(&req.format, |f| {
        match f.kind() {
        FormatKind::Float(l) => Ok((l, req.slab_config(f)?)),
        FormatKind::Fixed { .. } => Err(format!(
            "slab-never-misses: {} is fixed point; the proof covers float formats (fixed point is the directed variant's, not emitted yet)",
            f.name()
        )),
    }
    })?;
    if cfg.nan != datapath::slab::SlabNan::Ignore || cfg.prep != datapath::slab::DirPrep::Plain || cfg.widen_ulps < 0 {
        return Err(format!(
            "slab-never-misses is proven for the Ignore comparator, plain direction preparation and widening >= 0 (the conservative variant and its mutants); {} is none of them",
            req.variant
        ));
    }
    let m = emit(req)?;
    let names: Vec<String> = m.inputs.iter().map(|n| format!("in_{n}")).collect();
    let mut steps = Vec::new();
    let mut failed = false;
    let enumerable = datapath::with_format!(&req.format, |f| super::slab_planes::covers(f));
    if enumerable.is_ok() {
        // the lemma by exhaustive enumeration (the SMT form of it does not finish: docs/proofs.md)
        let t0 = std::time::Instant::now();
        let e = datapath::with_format!(&req.format, |f| super::slab_planes::enumerate(f, cfg, threads))?;
        failed = e.violation.is_some();
        let what = match e.violation {
            None => format!("lemma, every plane: {} (diff, d) pairs enumerated", e.pairs),
            Some(v) => format!(
                "lemma, every plane: fails at diff {:#x}, d {:#x} (product {:#x}) of {} pairs",
                v.diff, v.d, v.t, e.pairs
            ),
        };
        let v = Verdict {
            result: if failed { "sat" } else { "unsat" }.into(),
            solver: "enumeration".into(),
            version: env!("CARGO_PKG_VERSION").into(),
            seconds: t0.elapsed().as_secs_f64(),
            values: Vec::new(),
        };
        steps.push((what, v));
    } else {
        for a in ["x", "y", "z"] {
            let left = remaining(timeout_s, &steps);
            let v = solver::check(&lemma_query(&m, lay, a, cfg.widen_ulps as u32)?, solver, left, &[])?;
            let r = v.result.clone();
            steps.push((format!("lemma, axis {a} (SMT)"), v));
            if r != "unsat" {
                failed = true;
                break;
            }
        }
    }
    let mut witness = Vec::new();
    if failed && steps.last().is_some_and(|(_, v)| v.result == "sat") {
        let left = remaining(timeout_s, &steps);
        let v = solver::check(&query(&m, lay)?, solver, left, &names)?;
        if v.result == "sat" {
            witness = m.inputs.iter().cloned().zip(names.iter().map(|n| v.value(n))).collect();
        }
        steps.push(("whole unit (SMT): an exact hit the model misses".into(), v));
    }
    let last = &steps.iter().rev().find(|(_, v)| v.solver != "enumeration").unwrap_or(&steps[0]).1;
    let result = if !failed {
        "unsat"
    } else if last.result == "sat" && !witness.is_empty() {
        "sat"
    } else {
        "unknown"
    };
    let verdict = Verdict {
        result: result.into(),
        solver: last.solver.clone(),
        version: last.version.clone(),
        seconds: steps.iter().map(|(_, v)| v.seconds).sum(),
        values: Vec::new(),
    };
    Ok(Proof {
        property: "slab-never-misses".into(),
        format: req.format.name(),
        theorem: THEOREM.into(),
        verdict,
        witness,
        steps,
    })
}

/// The directed variant: its per-plane lemma by exhaustive enumeration
/// (`slab_directed`) and the written composition. A lemma failure is not by itself a miss, and
/// the directed variant is not emitted as SMT yet: it proves nothing (unknown).
fn prove_directed(req: &Request, threads: usize) -> Result<Proof, String> {
    if req.widen.is_some() || req.no_guard {
        return Err("the directed variant has no widening or guard to change".into());
    }
    let t0 = std::time::Instant::now();
    let e = datapath::with_format!(&req.format, |f| {
        let cfg = datapath::slab::SlabConfig::named_for("directed", f)?;
        super::slab_directed::enumerate(f, cfg, threads)
    })?;
    let what = match e.violation {
        None => format!("lemma, every plane: {} (de, d) pairs enumerated", e.pairs),
        Some(v) => format!(
            "lemma, every plane: fails at de {:#x}, d {:#x} (bound {:#x}) of {} pairs: no SMT model of the directed variant yet to look for a real miss",
            v.diff, v.d, v.t, e.pairs
        ),
    };
    let v = Verdict {
        result: if e.violation.is_some() { "unknown" } else { "unsat" }.into(),
        solver: "enumeration".into(),
        version: env!("CARGO_PKG_VERSION").into(),
        seconds: t0.elapsed().as_secs_f64(),
        values: Vec::new(),
    };
    Ok(Proof {
        property: "slab-never-misses".into(),
        format: req.format.name(),
        theorem: THEOREM.into(),
        verdict: v.clone(),
        witness: Vec::new(),
        steps: vec![(what, v)],
    })
}

/// Seconds left of `timeout_s` after `steps` (0: no limit).
fn remaining(timeout_s: f64, steps: &[(String, Verdict)]) -> f64 {
    if timeout_s == 0.0 {
        return 0.0;
    }
    (timeout_s - steps.iter().map(|(_, v)| v.seconds).sum::<f64>()).max(1.0)
}
