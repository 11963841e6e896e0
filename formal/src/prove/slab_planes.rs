//! `slab-never-misses` by exhaustive enumeration of the per-plane lemma, for float formats of
//! at most 16 bits (every pair of encodings: 2^32 for fp16 and bf16).
//!
//! **Lemma (per plane).** For finite `d` and a plane difference `diff = b ⊖ o` of finite `b`,
//! `o`, let `t_c` be the stage-2 product the model forms, `(b ⊖ o) ⊗ (1 ⊘ d)` with the
//! variant's guard. If `t_c` is not NaN then, for every real `b − o` that rounds to `diff`,
//! `nextDown^w(t_c) <= (b − o)/d <= nextUp^w(t_c)` (`w` the variant's widening); for `d = ±0`,
//! the near plane's product (`diff <= 0` for `+0`, `diff >= 0` for `−0`) is NaN or −∞ and the
//! far plane's NaN or +∞.
//!
//! The set of reals that round to `diff` is over-approximated by its rounding interval
//! `[(prev + diff)/2, (diff + next)/2]` (`prev`, `next` the neighbouring values; a zero or
//! subnormal difference of two format values is exact; an overflowed `±∞` stands for
//! `[max + ulp(max)/2, 2·max]`), so the enumeration over `(diff, d)` pairs covers every
//! `(b, o, d)`. Every value of such a format is a binary64 value and every product of two of
//! them (at most 2 × 26 significant bits, exponents within binary64's range for at most 9
//! exponent bits) is exact in binary64, so the comparisons are exact.
//!
//! **Composition.** The compare unit's `Ignore` chain from a finite `tmin` keeps the largest
//! non-NaN near candidate (the smallest far one), and nextDown^w / nextUp^w are monotone, so
//! `t_near = nextDown^w(max(tmin, near_x, near_y, near_z)) <= max(tmin, L_x, L_y, L_z)` and
//! `t_far >= min(tmax, H_x, H_y, H_z)`: an exact non-empty interval is a hit (docs/proofs.md).

use datapath::format::{FloatLayout, FormatKind};
use datapath::slab::{guarded_recip, guarded_sub, DirPrep, SlabConfig, SlabNan};
use datapath::Format;

/// A pair where the lemma fails.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Violation {
    /// The plane difference's encoding.
    pub diff: u64,
    /// The direction component's encoding.
    pub d: u64,
    /// The product's encoding.
    pub t: u64,
}

/// Result of the enumeration.
#[derive(Clone, Debug)]
pub struct Enumerated {
    /// (diff, d) pairs checked.
    pub pairs: u64,
    /// The first violation in (d, diff) encoding order, if any.
    pub violation: Option<Violation>,
}

/// Whether the enumeration covers format `f` (a float of at most 16 bits with at most 9
/// exponent bits and IEEE subnormals), or why not.
pub fn covers<F: Format>(f: &F) -> Result<(), String> {
    match f.kind() {
        FormatKind::Float(l) if l.width() <= 16 && l.exp_bits <= 9 && !f.flushes() => Ok(()),
        FormatKind::Float(l) if l.width() <= 16 && l.exp_bits <= 9 => {
            Err(format!("{}: under flush-to-zero the conservative variant is refused", f.name()))
        }
        FormatKind::Float(l) => Err(format!(
            "{}: exhaustive enumeration covers floats of at most 16 bits with at most 9 exponent bits (this has {} and {})",
            f.name(),
            l.width(),
            l.exp_bits
        )),
        FormatKind::Fixed { .. } => Err(format!("{}: fixed point is not covered", f.name())),
    }
}

/// The reals a subtraction rounds to encoding `b` (value `x`) of float format `f` (layout
/// `l`): its rounding interval; a zero or subnormal difference of two format values is exact;
/// ±inf stands for an overflow, `[max + ulp(max)/2, 2·max]`.
pub(crate) fn rounding_interval<F: Format>(f: &F, l: FloatLayout, b: u64, x: f64) -> (f64, f64) {
    let max = l.max_finite();
    if x.is_infinite() {
        let ovf = max + l.ulp(max) / 2.0;
        return if x > 0.0 { (ovf, 2.0 * max) } else { (-2.0 * max, -ovf) };
    }
    if l.is_zero(b) || l.is_subnormal(b) {
        return (x, x);
    }
    let v = f.from_bits(b);
    let (p, q) = (f.to_f64(f.next_down(v)), f.to_f64(f.next_up(v)));
    let lo = if p.is_infinite() { x - l.ulp(max) / 2.0 } else { (p + x) / 2.0 };
    let hi = if q.is_infinite() { x + l.ulp(max) / 2.0 } else { (x + q) / 2.0 };
    (lo, hi)
}

/// Checks the lemma on every (diff, d) pair of format `f` with variant `cfg`, on `threads`
/// threads (the result does not depend on them).
pub fn enumerate<F: Format>(f: &F, cfg: SlabConfig, threads: usize) -> Result<Enumerated, String> {
    covers(f)?;
    let FormatKind::Float(l) = f.kind() else { unreachable!() };
    if cfg.nan != SlabNan::Ignore || cfg.prep != DirPrep::Plain || cfg.widen_ulps < 0 || cfg.directed {
        return Err("the lemma is stated for the Ignore comparator, plain preparation and widening >= 0".into());
    }
    let n = 1u64 << l.width();
    let w = cfg.widen_ulps as u32;
    let guard = cfg.guard;
    // every non-NaN encoding with its value
    let values: Vec<(u64, f64)> = (0..n).filter(|&b| !l.is_nan(b)).map(|b| (b, f.to_f64(f.from_bits(b)))).collect();
    // the rounding interval of each difference value
    let interval = |b: u64, x: f64| rounding_interval(f, l, b, x);
    let ds: Vec<(u64, f64)> = values.iter().copied().filter(|(_, x)| x.is_finite()).collect();
    let threads = threads.max(1);
    let chunk = ds.len().div_ceil(threads);
    let one = f.one();
    let results: Vec<Option<Violation>> = std::thread::scope(|s| {
        let handles: Vec<_> = ds
            .chunks(chunk)
            .map(|part| {
                let values = &values;
                let interval = &interval;
                s.spawn(move || {
                    for &(db, dx) in part {
                        let dv = f.from_bits(db);
                        let mut r = f.div(one, dv);
                        if guard && guarded_recip(l, db, f.to_bits(r)) {
                            r = f.from_bits(l.canonical_nan());
                        }
                        for &(bb, bx) in values {
                            // an infinite difference of finite operands is the guard's case
                            let mut diff = f.from_bits(bb);
                            if guard && bx.is_infinite() && guarded_sub(l, 0, 0, bb) {
                                diff = f.from_bits(l.canonical_nan());
                            }
                            let t = f.mul(diff, r);
                            if f.is_nan(t) {
                                continue;
                            }
                            let (down, up) = (0..w).fold((t, t), |(a, b), _| (f.next_down(a), f.next_up(b)));
                            let (lo, hi) = (f.to_f64(down), f.to_f64(up));
                            let ok = if dx == 0.0 {
                                // d = +0: the near plane has diff <= 0; d = -0: diff >= 0
                                let neg_d = f.sign_bit(dv);
                                let near = if neg_d { bx >= 0.0 } else { bx <= 0.0 };
                                let far = if neg_d { bx <= 0.0 } else { bx >= 0.0 };
                                (!near || lo == f64::NEG_INFINITY) && (!far || hi == f64::INFINITY)
                            } else {
                                let (blo, bhi) = interval(bb, bx);
                                // lo <= (b - o)/d <= hi for every b - o in [blo, bhi]
                                if dx > 0.0 {
                                    lo * dx <= blo && hi * dx >= bhi
                                } else {
                                    lo * dx >= bhi && hi * dx <= blo
                                }
                            };
                            if !ok {
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
