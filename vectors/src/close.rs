//! Coverage closure (`raypipe vectors --close`): directed vectors for the empty bins of a set's
//! coverage model ([`crate::cover`]), found by a seeded, coverage-directed search and appended
//! to the set as one more class, `close`.
//!
//! The search, deterministic for a request and budget (no dependence on threads):
//! 1. Generate the set the request asks for and measure its coverage.
//! 2. Draw candidates in batches of [`BATCH`] from `SplitMix64(seed ^ CLOSE_SEED)`. A candidate
//!    is the input row of an earlier vector — one of the set's, a kept candidate (half the time
//!    once there are any) or a start row (`templates`: rti and slab in float formats) — with
//!    one to three of its inputs changed (`mutate`): an edge encoding of the field's kind or
//!    one 1 to 8 encodings beside it, a random encoding, another input of the same row (its
//!    bits, or its bits ± 1), its own negation, ± a power of two, a pair (a power of two and in
//!    another input the encoding below it, either sign: M + 1 bits cancel), the exponents of
//!    all float inputs or of one input group shifted together, or a value of a float value
//!    class still empty somewhere (± 1 to 8 encodings).
//! 3. Build each candidate's rows with the unit's model (the same rows the set's other classes
//!    get), take the bins it hits, and keep it when one of them is still empty; its bins count
//!    from then on, so a later candidate is kept only for a bin no kept row reached.
//! 4. Stop after `budget` candidates, or when [`STALL`] candidates in a row added nothing.
//!
//! What stays empty is a hole: reachable or not, the search did not find it (the report lists
//! them). The kept rows are given rows: `vectors --check` rebuilds the class from the set's own
//! input rows, not by repeating the search.

use crate::cover::{Coverage, RowBins, CROSS_CLASSES, FLOAT_BINS};
use crate::gen::{generate, Explicit, Request, Unit, VectorSet, OPCODES};
use crate::manifest::Kind;
use crate::read::set_rows;
use datapath::rng::SplitMix64;

/// Candidates built and measured together (one set generation per batch).
pub const BATCH: usize = 2048;
/// Candidates in a row without a new bin after which the search stops.
pub const STALL: u64 = 48 * BATCH as u64;
/// Mixed into the request's seed for the search's generator.
pub const CLOSE_SEED: u64 = 0xC105_E000_C0FE_0001;
/// The default candidate budget.
pub const DEFAULT_BUDGET: u64 = 400_000;

/// A closed set and what the closure did.
#[derive(Clone, Debug)]
pub struct Closed {
    /// The set with the `close` class appended (the request's set unchanged when no candidate
    /// was kept: then no class is appended).
    pub set: VectorSet,
    /// Coverage (bins hit, reachable bins) of the set before the closure.
    pub before: (u64, u64),
    /// Coverage after it.
    pub after: (u64, u64),
    /// Candidates measured.
    pub candidates: u64,
    /// Candidates kept (the `close` class's rows).
    pub kept: usize,
    /// The coverage of the closed set.
    pub coverage: Coverage,
}

/// The set `req` asks for, closed: see the module documentation.
pub fn close(req: &Request, budget: u64) -> Result<Closed, String> {
    if req.closure.is_some() || req.explicit.is_some() {
        return Err("--close applies to a generated set (not to given rows or an already closed set)".into());
    }
    let origin = format!(
        "raypipe vectors --close: coverage-directed search, seed {} ^ {CLOSE_SEED:#x}, budget {budget}",
        req.seed
    );
    let explicit = |rows: Vec<Vec<u64>>| {
        Explicit {
        class: "close".into(),
        covers: "coverage closure: each row reaches a bin of the coverage model that no earlier row of the set reached (found by a seeded search over edge encodings, copied operands and exponent shifts: docs/coverage.md)".into(),
        origin: origin.clone(),
        rows,
    }
    };
    // the coverage model with the (still empty) close class, as every batch's set has it; the
    // class coverpoint is not a reason to keep a candidate
    let with_class = generate(&Request { closure: Some(explicit(Vec::new())), ..req.clone() })?;
    let m = &with_class.manifest;
    let contents = set_rows(&with_class)?;
    let mut cov = Coverage::measure(m, &contents)?;
    // the request's set's coverage: the empty close class's bin is unreachable (a class without
    // vectors), so it adds nothing to the totals
    let before = cov.totals();
    let kinds: Vec<Kind> = m.files[0].fields.iter().skip(1).map(|x| x.kind.clone()).collect();
    let widths: Vec<u32> = m.files[0].fields.iter().skip(1).map(|x| x.width).collect();
    // an input's group: its name without a trailing axis letter (ox, oy, oz: o)
    let groups: Vec<String> = m.files[0]
        .fields
        .iter()
        .skip(1)
        .map(|x| x.name.strip_suffix(['x', 'y', 'z']).unwrap_or(&x.name).to_string())
        .collect();
    let names: Vec<String> = m.files[0].fields.iter().skip(1).map(|x| x.name.clone()).collect();
    let seeds: Vec<Vec<u64>> = contents[0].iter().map(|r| r[1..].to_vec()).collect();
    let starts = templates(req.unit, &kinds);
    if seeds.is_empty() {
        return Err("the set has no vectors to start the closure from".into());
    }
    let mut r = SplitMix64::new(req.seed ^ CLOSE_SEED);
    let mut kept: Vec<Vec<u64>> = Vec::new();
    let (mut candidates, mut since) = (0u64, 0u64);
    let base_rows = contents[0].len();
    let mut hits = Vec::new();
    while candidates < budget && since < STALL {
        let n = BATCH.min((budget - candidates) as usize);
        // the value classes still empty on some float signal
        let mut targets: Vec<usize> = cov
            .coverpoints
            .iter()
            .filter(|p| p.kind == "value class" && p.bins.len() == FLOAT_BINS.len())
            .flat_map(|p| p.bins.iter().enumerate().filter(|(_, b)| b.count == 0 && b.unreachable.is_none()))
            .map(|(k, _)| k)
            .collect();
        targets.sort_unstable();
        targets.dedup();
        // operand-cross bins still empty whose two operands are inputs: (input a, input b,
        // class of a, class of b)
        let pairs: Vec<(usize, usize, usize, usize)> = cov
            .coverpoints
            .iter()
            .filter(|p| p.kind == "operand cross")
            .filter_map(|p| {
                let (_, ops) = p.signal.split_once(": ")?;
                let (a, b) = ops.split_once(" x ")?;
                let (ia, ib) = (names.iter().position(|n| n == a)?, names.iter().position(|n| n == b)?);
                Some(
                    p.bins
                        .iter()
                        .enumerate()
                        .filter(|(_, b)| b.count == 0 && b.unreachable.is_none())
                        .map(move |(k, _)| (ia, ib, k / CROSS_CLASSES.len(), k % CROSS_CLASSES.len())),
                )
            })
            .flatten()
            .collect();
        let batch: Vec<Vec<u64>> = (0..n)
            .map(|_| {
                let from = match r.below(4) {
                    0 | 1 if !kept.is_empty() => &kept[r.below(kept.len() as u64) as usize],
                    0 if !starts.is_empty() => &starts[r.below(starts.len() as u64) as usize],
                    _ => &seeds[r.below(seeds.len() as u64) as usize],
                };
                if !pairs.is_empty() && r.below(8) == 0 {
                    // both operands of an empty cross bin given values of its classes
                    let (ia, ib, ca, cb) = pairs[r.below(pairs.len() as u64) as usize];
                    let mut x = from.clone();
                    if let (Kind::Ieee { exp, man }, Kind::Ieee { .. }) = (&kinds[ia], &kinds[ib]) {
                        x[ia] = cross_encoding(ca, *exp, *man, &mut r);
                        x[ib] = cross_encoding(cb, *exp, *man, &mut r);
                    }
                    return x;
                }
                mutate(from, &kinds, &widths, &groups, &targets, req.unit, &mut r)
            })
            .collect();
        let set = generate(&Request { closure: Some(explicit(batch.clone())), ..req.clone() })?;
        let rows = set_rows(&set)?;
        let bins = RowBins::new(&set.manifest).with_set(&rows)?;
        for (i, cand) in batch.into_iter().enumerate() {
            candidates += 1;
            since += 1;
            hits.clear();
            bins.hits(&rows, base_rows + i, &mut hits)?;
            if hits.iter().any(|&(p, b)| cov.coverpoints[p].bins[b].count == 0 && cov.coverpoints[p].kind != "class") {
                for &(p, b) in &hits {
                    cov.coverpoints[p].bins[b].count += 1;
                }
                cov.vectors += 1;
                kept.push(cand);
                since = 0;
            }
        }
    }
    let n_kept = kept.len();
    let set = generate(&Request { closure: (!kept.is_empty()).then(|| explicit(kept)), ..req.clone() })?;
    let coverage = Coverage::measure(&set.manifest, &set_rows(&set)?)?;
    Ok(Closed { before, after: coverage.totals(), candidates, kept: n_kept, coverage, set })
}

/// Start rows besides the set's own (slab: a ray whose t interval alone decides the result;
/// RTI: a triangle whose stage values
/// are single inputs, so one changed input moves one deep signal. Ray o = (0, 0, 0),
/// d = (0, 1, 0), t in [0, +inf); v0 = 0, v1 = (D, 0, 0), v2 = (0, 0, 1): then p = (1, 0, 0),
/// det = D, u' = o.x, v' = D o.z, t' = −D o.y, and u, v, t are o.x / D, o.z, −o.y (rounded):
/// the template itself (D = 1), with o.x or o.z the smallest normal (u or v at the smallest
/// normal), o.y = −max (t at the largest finite value), D = ±2^−emin (1/det at ±the smallest
/// normal) and D the value below 1 with o.y = −max (t' x (1/det) above the largest finite);
/// and three placements whose differences lose M + 1 bits (p.y, p.z, det_xy, u'_xy, v'_xy);
/// and two triangles for the crosses after `valid`: t' = +inf with 1/det = +inf (a subnormal
/// det), and v' subnormal with 1/det subnormal (det = 2^emax).
fn templates(unit: Unit, kinds: &[Kind]) -> Vec<Vec<u64>> {
    let Some(Kind::Ieee { exp, man }) = kinds.first() else { return Vec::new() };
    let (exp, man) = (*exp, *man);
    let bias = (1u64 << (exp - 1)) - 1;
    let sign = 1u64 << (exp + man);
    let pow2 = |k: i64| ((k + bias as i64) as u64) << man; // a normal power of two
    let one = pow2(0);
    let min_normal = 1u64 << man;
    let max = ((((1u64 << exp) - 2) << man) | ((1u64 << man) - 1)) | sign; // −max
    let inf = ((1u64 << exp) - 1) << man;
    if unit == Unit::Slab {
        // the origin inside [-1, 1]^3 with d = (+0, +0, +0): every axis enters at -inf and
        // leaves at +inf, so t_near and t_far are tmin and tmax widened; and the boxes' faces
        // at -0 with the origin at +0 (a -0 difference)
        let m1 = one | sign;
        return vec![
            vec![0, 0, 0, 0, 0, 0, 0, inf, m1, m1, m1, one, one, one],
            vec![0, 0, 0, one, one, one, 0, inf, sign, sign, sign, one, one, one],
        ];
    }
    if unit != Unit::Rti {
        return Vec::new();
    }
    // o, d, tmin, tmax, v0, v1, v2
    let base = vec![0, 0, 0, 0, one, 0, 0, inf, 0, 0, 0, one, 0, 0, 0, 0, one];
    let with = |changes: &[(usize, u64)]| {
        let mut b = base.clone();
        for &(i, v) in changes {
            b[i] = v;
        }
        b
    };
    let neg_emin = pow2(bias as i64 - 1); // 2^−emin = 2^(bias − 1)
    let two = pow2(1);
    let half_max = ((((1u64 << exp) - 3) << man) | ((1u64 << man) - 1)) & !sign; // max / 2
    vec![
        base.clone(),
        with(&[(0, min_normal)]),
        with(&[(2, min_normal)]),
        with(&[(1, max)]),
        with(&[(11, neg_emin)]),
        with(&[(11, neg_emin | sign)]),
        with(&[(1, max), (11, one - 1)]),
        // o.y = 1 and v1.z = 1: q.x = 1, so v'_x = d.x
        with(&[(1, one), (13, one)]),
        // cancellation of M + 1 bits (p1 = the value below 1): d = (1, 1, 1), v2 = (p1, 1, 1)
        // gives p.y = p1 - 1 and p.z = 1 - p1; o = (0, 0, 1), d = (p1, 1, 0), v1 = (1, 1, 0)
        // gives det_xy = 1 - p1 and v'_xy = 1 - p1
        with(&[(3, one), (5, one), (14, one - 1), (15, one)]),
        with(&[(2, one), (3, one - 1), (12, one)]),
        // and with o = (1, 1, 1): u'_xy = 1 - p1
        with(&[(0, one), (1, one), (2, one), (3, one - 1), (12, one)]),
        // after valid, t' infinite times an infinite 1/det: e1 = (2, 0, 0), e2 = (0, 2, 0),
        // o = (0, 0, max/2), d = (0, 0, -tiny): q = (0, max, 0), t' = 2 max = +inf, p = (2 tiny,
        // 0, 0), det = 4 tiny (subnormal, 1/det overflows), u' = 0, v' = -0
        vec![0, 0, half_max, 0, 0, sign | 1, 0, inf, 0, 0, 0, two, 0, 0, 0, two, 0],
        // after valid, v' subnormal times a subnormal 1/det: e1 = (1, 0, 0), e2 = (0, 1, 0),
        // o = (0, 0, 1), d = (0, tiny, -2^emax): p = (2^emax, 0, 0), det = 2^emax (1/det =
        // 2^-emax, subnormal), q = (0, 1, 0), t' = 1, u' = 0, v' = tiny
        vec![0, 0, one, 0, 1, pow2(bias as i64) | sign, 0, inf, 0, 0, 0, one, 0, 0, 0, one, 0],
    ]
}

/// `v`, or (half the time) the encoding 1 to 8 above or below it (within `mask`).
fn nudge(v: u64, mask: u64, r: &mut SplitMix64) -> u64 {
    if r.below(2) != 0 {
        return v;
    }
    let k = 1 + r.below(8);
    (if r.below(2) == 0 { v.wrapping_add(k) } else { v.wrapping_sub(k) }) & mask
}

/// An encoding of float value class `FLOAT_BINS[bin]` (a random one where the class has many).
fn class_encoding(bin: usize, exp: u32, man: u32, r: &mut SplitMix64) -> u64 {
    let sign = 1u64 << (exp + man);
    let s = if bin < 12 { (bin as u64 & 1) * sign } else { r.below(2) * sign };
    let top = (1u64 << exp) - 1;
    let mm = (1u64 << man) - 1;
    s | match bin / 2 {
        0 => 0,
        1 => 1 + r.below(mm),
        2 => 1 << man,
        3 => ((1 + r.below(top - 2)) << man) | r.below(mm + 1),
        4 => ((top - 1) << man) | mm,
        5 => top << man,
        _ if bin == 12 => (top << man) | (1 << (man - 1)),
        _ => (top << man) | (1 + r.below(mm)),
    }
}

/// An encoding of cross class `CROSS_CLASSES[c]` (zero, subnormal, normal, inf, NaN), either
/// sign.
fn cross_encoding(c: usize, exp: u32, man: u32, r: &mut SplitMix64) -> u64 {
    // the value-class bins of each cross class, in FLOAT_BINS order
    let bins: &[usize] = match c {
        0 => &[0, 1],
        1 => &[2, 3],
        2 => &[4, 5, 6, 7, 8, 9],
        3 => &[10, 11],
        _ => &[12, 13],
    };
    class_encoding(bins[r.below(bins.len() as u64) as usize], exp, man, r)
}

/// Edge encodings of a float field with `exp` exponent and `man` fraction bits: exponents 0,
/// 1, bias − 1, bias, bias + 1, all ones − 1 and all ones, each with fractions 0, 1, the top
/// bit, all but the top bit and all ones, both signs.
fn float_edges(exp: u32, man: u32) -> Vec<u64> {
    let top = (1u64 << exp) - 1;
    let bias = (1u64 << (exp - 1)) - 1;
    let mm = (1u64 << man) - 1;
    let mut v = Vec::new();
    for e in [0, 1, bias - 1, bias, bias + 1, top - 1, top] {
        for fr in [0, 1, 1 << (man - 1), mm >> 1, mm] {
            for s in [0, 1u64 << (exp + man)] {
                v.push(s | (e << man) | fr);
            }
        }
    }
    v
}

/// A candidate: `from` with one to three inputs changed (see the module documentation).
#[allow(clippy::too_many_arguments)]
fn mutate(
    from: &[u64],
    kinds: &[Kind],
    widths: &[u32],
    groups: &[String],
    targets: &[usize],
    unit: Unit,
    r: &mut SplitMix64,
) -> Vec<u64> {
    let mut x = from.to_vec();
    let n = x.len() as u64;
    let mask = |w: u32| if w >= 64 { u64::MAX } else { (1u64 << w) - 1 };
    for _ in 0..1 + r.below(3) {
        let i = r.below(n) as usize;
        let w = widths[i];
        match &kinds[i] {
            Kind::Ieee { exp, man } => {
                let (exp, man) = (*exp, *man);
                match r.below(11) {
                    8 | 9 if !targets.is_empty() => {
                        // a value of the class of a bin still empty, or (half the time) one 1
                        // to 8 encodings beside it
                        let t = targets[r.below(targets.len() as u64) as usize];
                        x[i] = class_encoding(t, exp, man, r);
                        x[i] = nudge(x[i], mask(w), r);
                    }
                    8 | 9 => x[i] = r.next_u64() & mask(w),
                    10 => {
                        // a pair: input i ± a power of two, another float input the encoding
                        // below it, of either sign (a − b or a + b loses M + 1 bits)
                        let j = r.below(n) as usize;
                        if j != i && kinds[j] == kinds[i] {
                            let e = 1 + r.below((1u64 << exp) - 2);
                            x[i] = (e << man) | (r.below(2) << (exp + man));
                            x[j] = (x[i] - 1) ^ (r.below(2) << (exp + man));
                        }
                    }
                    0 | 1 => {
                        // an edge encoding, or (half the time) one 1 to 8 encodings beside it
                        let e = float_edges(exp, man);
                        x[i] = e[r.below(e.len() as u64) as usize];
                        x[i] = nudge(x[i], mask(w), r);
                    }
                    2 => x[i] = r.next_u64() & mask(w),
                    3 => {
                        // another float input of the row, or it ± 1 (as an encoding)
                        let j = r.below(n) as usize;
                        if kinds[j] == kinds[i] {
                            x[i] = match r.below(3) {
                                0 => x[j],
                                1 => x[j].wrapping_add(1) & mask(w),
                                _ => x[j].wrapping_sub(1) & mask(w),
                            };
                        }
                    }
                    4 => x[i] ^= 1u64 << (exp + man),
                    5 => {
                        // ± a power of two, normal or subnormal (exact products and sums)
                        let k = r.below(u64::from(man) + (1u64 << exp) - 1);
                        let mag = if k < u64::from(man) { 1u64 << k } else { (k - u64::from(man) + 1) << man };
                        x[i] = mag | (r.below(2) << (exp + man));
                    }
                    _ => {
                        // the exponents of every finite nonzero float input, or of those of
                        // input i's group (its name without the axis letter: o, d, v0, min …),
                        // shifted by the same amount
                        let top = (1i64 << exp) - 1;
                        let d = r.below(2 * top as u64 + 1) as i64 - top;
                        let all = r.below(2) == 0;
                        for (j, (v, k)) in x.iter_mut().zip(kinds).enumerate() {
                            if !all && groups[j] != groups[i] {
                                continue;
                            }
                            if let Kind::Ieee { exp: e2, man: m2 } = k {
                                let e = ((*v >> m2) & ((1u64 << e2) - 1)) as i64;
                                if e == 0 || e == (1i64 << e2) - 1 {
                                    continue;
                                }
                                let ne = (e + d).clamp(1, (1i64 << e2) - 2) as u64;
                                *v = (*v & !(((1u64 << e2) - 1) << m2)) | (ne << m2);
                            }
                        }
                    }
                }
            }
            Kind::Fixed { .. } => {
                let m = mask(w);
                let max = m >> 1;
                x[i] = match r.below(5) {
                    0 => [0, 1, m, max, max + 1, max - 1, max + 2][r.below(7) as usize],
                    1 => r.next_u64() & m,
                    2 => {
                        let j = r.below(n) as usize;
                        if kinds[j] == kinds[i] {
                            x[j].wrapping_add(r.below(3).wrapping_sub(1)) & m
                        } else {
                            x[i]
                        }
                    }
                    3 => x[i].wrapping_neg() & m,
                    // a small magnitude: ±(1 to 255) steps
                    _ => {
                        let k = 1 + r.below(255);
                        if r.below(2) == 0 {
                            k
                        } else {
                            k.wrapping_neg() & m
                        }
                    }
                };
            }
            Kind::Flag => x[i] ^= 1,
            Kind::Uint => {
                x[i] = if unit == Unit::Op && i == 0 {
                    r.below(OPCODES.len() as u64)
                } else {
                    // an id: another id of the row, or a small one
                    let j = r.below(n) as usize;
                    if kinds[j] == Kind::Uint && r.below(2) == 0 {
                        x[j]
                    } else {
                        r.below(8)
                    }
                };
            }
        }
    }
    x
}
