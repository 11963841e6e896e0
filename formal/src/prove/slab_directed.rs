//! `slab-never-misses` for the **directed** slab variant by exhaustive enumeration of its
//! per-plane lemma, for formats of at most 16 bits: IEEE-like floats with at most 9 exponent
//! bits and no flush-to-zero, and saturating fixed point (q8.8, q1.15, …).
//!
//! **Lemma (per plane).** For a direction component `d` the model does not read as ±0 (its
//! stage 0 gives `inv_d = 1 ⊘ d` and the bounds `inv_lo`, `inv_hi`, via
//! `Slab::prepare_faulty`), and a computed plane difference `de = b ⊖ o`, let `t_entry` and
//! `t_exit` be the bounds stage 2 forms from `de` as the entry plane and as the exit plane
//! (`Slab::trace_directed`). For every real `δ = b − o` whose computed difference is `de`:
//! `t_entry ≤ δ / d` or `t_entry` is the format's most negative value (−∞, or the most negative
//! fixed-point encoding), and `t_exit ≥ δ / d` or `t_exit` is the most positive value.
//!
//! The reals whose difference computes to `de`: a float's rounding interval (as in
//! `slab_planes`; ±∞ stands for an overflow), a fixed-point `de` itself when it is not an end
//! of the range, and everything beyond it when it is (saturation). Every value of these
//! formats and every product of two is exact in binary64, so each comparison is exact.
//!
//! **Composition.** Stage 4 keeps `t_near = max(tmin, t_entry_x, …)` and `t_far = min(tmax,
//! t_exit_x, …)` (the `Ignore` chain; no NaN arises from finite inputs: a product whose factor
//! is an unbounded end is not formed). An axis the model reads as parallel adds no constraint
//! when `min ≤ o ≤ max` and forces a miss otherwise, which is also the exact interval's rule.
//! Since `tmin` and `tmax` are format values, `max(tmin, most negative) = tmin`: the lemma gives
//! `t_near ≤ max(tmin, L_x, L_y, L_z)` and `t_far ≥ min(tmax, H_x, H_y, H_z)`, so an exact
//! non-empty interval is a hit (`t_near ≤ t_far`, no final widening in this variant).

use datapath::format::FormatKind;
use datapath::slab::{Slab, SlabConfig};
use datapath::Format;

use super::slab_planes::{Enumerated, Violation};

/// Whether the enumeration covers format `f` for the directed variant, or why not.
pub fn covers<F: Format>(f: &F) -> Result<(), String> {
    match f.kind() {
        FormatKind::Float(l) if l.width() <= 16 && l.exp_bits <= 9 && !f.flushes() => Ok(()),
        FormatKind::Float(l) if l.width() <= 16 && l.exp_bits <= 9 => Err(format!(
            "{}: the directed lemma's rounding intervals assume IEEE subnormals (no flush-to-zero)",
            f.name()
        )),
        FormatKind::Float(l) => Err(format!(
            "{}: exhaustive enumeration covers floats of at most 16 bits with at most 9 exponent bits (this has {} and {})",
            f.name(),
            l.width(),
            l.exp_bits
        )),
        FormatKind::Fixed { .. } if f.wraps() => {
            Err(format!("{}: a wrapping fixed-point format is not conservative (directed refuses it)", f.name()))
        }
        FormatKind::Fixed { .. } if f.width() <= 16 => Ok(()),
        FormatKind::Fixed { .. } => {
            Err(format!("{}: exhaustive enumeration covers fixed-point formats of at most 16 bits", f.name()))
        }
    }
}

/// The entry and exit bounds the directed variant forms from plane difference `de` with the
/// stage-0 values of one axis (`inv_d`, `inv_lo`, `inv_hi`), as `Slab::trace_directed` does.
pub fn bounds<F: Format>(f: &F, de: F::V, inv_d: F::V, inv_lo: F::V, inv_hi: F::V) -> (F::V, F::V) {
    let (top, bottom) = (f.from_f64(f64::INFINITY), f.from_f64(f64::NEG_INFINITY));
    let up_inf = |v: F::V| f.to_bits(v) == f.to_bits(top);
    let lo_inf = |v: F::V| f.to_bits(v) == f.to_bits(bottom);
    let neg = f.sign_bit(inv_d);
    let (lo, hi) = (f.next_down(de), f.next_up(de));
    let (x_e, x_e_inf) = if neg { (hi, up_inf(hi)) } else { (lo, lo_inf(lo)) };
    let (inv_e, inv_e_inf) = if f.sign_bit(x_e) { (inv_hi, up_inf(inv_hi)) } else { (inv_lo, lo_inf(inv_lo)) };
    let (x_x, x_x_inf) = if neg { (lo, lo_inf(lo)) } else { (hi, up_inf(hi)) };
    let (inv_x, inv_x_inf) = if f.sign_bit(x_x) { (inv_lo, lo_inf(inv_lo)) } else { (inv_hi, up_inf(inv_hi)) };
    let t_entry = if x_e_inf || inv_e_inf { bottom } else { f.next_down(f.mul(x_e, inv_e)) };
    let t_exit = if x_x_inf || inv_x_inf { top } else { f.next_up(f.mul(x_x, inv_x)) };
    (t_entry, t_exit)
}

/// Checks the lemma on every (de, d) pair of format `f`, on `threads` threads (the result
/// does not depend on them).
pub fn enumerate<F: Format>(f: &F, cfg: SlabConfig, threads: usize) -> Result<Enumerated, String> {
    enumerate_with(f, cfg, threads, bounds::<F>)
}

/// The entry and exit bounds from (de, inv_d, inv_lo, inv_hi), as [`bounds`].
type BoundsFn<F> = fn(
    &F,
    <F as Format>::V,
    <F as Format>::V,
    <F as Format>::V,
    <F as Format>::V,
) -> (<F as Format>::V, <F as Format>::V);

/// [`enumerate`] with the bounds computed by `bounds` (a mutant in the tests).
fn enumerate_with<F: Format>(
    f: &F,
    cfg: SlabConfig,
    threads: usize,
    bounds: BoundsFn<F>,
) -> Result<Enumerated, String> {
    covers(f)?;
    if !cfg.directed {
        return Err("internal: the directed lemma is for the directed variant".into());
    }
    let slab = Slab::new(*f, cfg);
    let n = 1u64 << f.width();
    let (top, bottom) = (f.from_f64(f64::INFINITY), f.from_f64(f64::NEG_INFINITY));
    let (hi_v, lo_v) = (f.to_f64(top), f.to_f64(bottom));
    // every non-NaN encoding, its value, and the reals whose computed difference it is
    let values: Vec<(u64, f64, f64, f64)> = (0..n)
        .filter(|&b| !f.is_nan(f.from_bits(b)))
        .map(|b| {
            let v = f.from_bits(b);
            let x = f.to_f64(v);
            let (lo, hi) = if let FormatKind::Float(l) = f.kind() {
                super::slab_planes::rounding_interval(f, l, b, x)
            } else if x == hi_v {
                // saturated high: the exact difference is at least the largest value
                (x, f64::INFINITY)
            } else if x == lo_v {
                (f64::NEG_INFINITY, x)
            } else {
                (x, x)
            };
            (b, x, lo, hi)
        })
        .collect();
    // every direction component the model does not read as parallel, with its stage-0 values
    let zero = f.zero();
    let one = f.one();
    let ds: Vec<(u64, f64, [F::V; 3])> = (0..n)
        .filter(|&b| !f.is_nan(f.from_bits(b)))
        .filter_map(|b| {
            let d = f.from_bits(b);
            let x = f.to_f64(d);
            if !x.is_finite() {
                return None;
            }
            let r = slab.prepare_encoded([zero; 3], [d, one, one], zero, zero);
            (!r.parallel[0]).then_some((b, x, [r.inv_d[0], r.inv_lo[0], r.inv_hi[0]]))
        })
        .collect();
    let threads = threads.max(1);
    let chunk = ds.len().div_ceil(threads).max(1);
    let results: Vec<Option<Violation>> = std::thread::scope(|s| {
        let handles: Vec<_> = ds
            .chunks(chunk)
            .map(|part| {
                let values = &values;
                s.spawn(move || {
                    for &(db, dx, [inv_d, inv_lo, inv_hi]) in part {
                        for &(bb, _, lo, hi) in values {
                            let (te, tx) = bounds(f, f.from_bits(bb), inv_d, inv_lo, inv_hi);
                            let (e, x) = (f.to_f64(te), f.to_f64(tx));
                            // e <= delta/d for every delta in [lo, hi]: the smallest quotient is
                            // lo/d for d > 0, hi/d for d < 0 (products exact in binary64)
                            let entry_ok = e == lo_v || if dx > 0.0 { e * dx <= lo } else { e * dx >= hi };
                            let exit_ok = x == hi_v || if dx > 0.0 { x * dx >= hi } else { x * dx <= lo };
                            if !(entry_ok && exit_ok) || e.is_nan() || x.is_nan() {
                                let t = if entry_ok { tx } else { te };
                                return Some(Violation { diff: bb, d: db, t: f.to_bits(t) });
                            }
                        }
                    }
                    None
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().expect("enumeration thread")).collect()
    });
    let pairs = (ds.len() * values.len()) as u64;
    Ok(Enumerated { pairs, violation: results.into_iter().flatten().next() })
}

#[cfg(test)]
mod tests {
    use super::*;
    use datapath::probe::{Recorder, Signal};
    use datapath::rng::SplitMix64;
    use datapath::slab::Aabb;

    /// The lemma's `bounds` are the model's: `trace_directed`'s entry_x / exit_x probes on a
    /// ray from the origin with both x planes at the difference (so `de = b ⊖ 0 = b`).
    fn bounds_are_the_models<F: Format>(f: F) {
        let slab = Slab::new(f, SlabConfig::named_for("directed", &f).unwrap());
        let mut r = SplitMix64::new(5);
        let n = 1u64 << f.width();
        let zero = f.zero();
        let one = f.one();
        let mut checked = 0;
        for _ in 0..20_000 {
            let (de, d) = (f.from_bits(r.next_u64() % n), f.from_bits(r.next_u64() % n));
            if f.is_nan(de) || f.is_nan(d) || !f.to_f64(d).is_finite() {
                continue;
            }
            let ray = slab.prepare_encoded([zero; 3], [d, one, one], zero, zero);
            if ray.parallel[0] {
                continue;
            }
            let b = Aabb { min: [de, zero, zero], max: [de, zero, zero] };
            let mut p = Recorder::new();
            slab.trace_directed(&ray, &b, &mut p);
            let (te, tx) = bounds(&f, de, ray.inv_d[0], ray.inv_lo[0], ray.inv_hi[0]);
            let get = |name: &str| match p.get(name) {
                Some(Signal::Value(v)) => f.to_bits(v),
                other => panic!("{name}: {other:?}"),
            };
            assert_eq!((get("entry_x"), get("exit_x")), (f.to_bits(te), f.to_bits(tx)), "de {de:?} d {d:?}");
            checked += 1;
        }
        assert!(checked > 10_000);
    }

    /// The lemma can fail: without the outward step after each product it does.
    #[test]
    fn a_bound_without_the_outward_step_fails_the_lemma() {
        fn no_step<F: Format>(f: &F, de: F::V, inv_d: F::V, lo: F::V, hi: F::V) -> (F::V, F::V) {
            let (te, tx) = bounds(f, de, inv_d, lo, hi);
            let (top, bottom) = (f.from_f64(f64::INFINITY), f.from_f64(f64::NEG_INFINITY));
            let back = |t: F::V, end: F::V, up: bool| {
                if f.to_bits(t) == f.to_bits(end) {
                    t
                } else if up {
                    f.next_up(t)
                } else {
                    f.next_down(t)
                }
            };
            (back(te, bottom, true), back(tx, top, false))
        }
        for name in ["e5m6", "q4.4"] {
            let any: datapath::AnyFormat = name.parse().unwrap();
            datapath::with_format!(&any, |f| {
                let cfg = SlabConfig::named_for("directed", f).unwrap();
                assert!(enumerate(f, cfg, 2).unwrap().violation.is_none(), "{name}");
                assert!(enumerate_with(f, cfg, 2, no_step).unwrap().violation.is_some(), "{name}");
            });
        }
    }

    #[test]
    fn the_lemmas_bounds_are_the_models() {
        for name in ["fp16", "bf16", "q8.8", "e5m6"] {
            let any: datapath::AnyFormat = name.parse().unwrap();
            datapath::with_format!(&any, |f| bounds_are_the_models(*f));
        }
    }
}
