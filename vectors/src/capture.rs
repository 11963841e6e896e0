//! The `capture` unit: the min-capture unit fed one ray's leaf of [`SLOTS`] RTI results in
//! stream order. Each vector starts from the reset state (no hit held: hit 0, t, u, v +0 and
//! id 0) and takes the results one per stage: slot k's result is taken when its hit bit is 1
//! and either no hit is held or its t wins the compare with the held t (`t < held` under the
//! tie rule `first`, `t <= held` under `last`, IEEE ordered compares: −0 = +0). The output is
//! the held state after the last slot; the stage row holds each slot's take bit and the state
//! after it.

use crate::manifest::Kind;
use crate::rows::Layout;
use datapath::fault::Fault;
use datapath::rng::SplitMix64;
use datapath::rti::{Capture, Rti, RtiOut};
use datapath::Format;

/// RTI results per vector (one leaf of the thesis's default size).
pub const SLOTS: usize = 4;

/// Fields of one slot of an input row, in order.
const SLOT_FIELDS: [&str; 5] = ["hit", "t", "u", "v", "id"];

/// Coverage classes of the capture unit.
pub const CLASSES: [(&str, &str); 7] = [
    ("random", "each slot a hit with probability 1/2, t uniform in [0, 4), u and v in [0, 1], random ids"),
    ("ties", "every slot a hit, two to four of them with the same t encoding (different u, v, id): the tie rule decides"),
    ("zero_ties", "every slot a hit at t = +0 or -0 (or one positive t): ties of zeros of either sign"),
    ("misses_nearer", "slot 0 a hit at t in [1, 4); later slots misses carrying t in [0, 1) (nearer than the held hit), or hits farther away"),
    ("sorted", "every slot a hit, t strictly ascending or strictly descending"),
    ("first_late", "the first hit in slot 1, 2 or 3 at t > 0 (misses before it with random t), later hits random"),
    ("extremes", "every slot a hit at t from +inf, the largest finite value, the least positive value, the least normal, +0, -0 and 1"),
];

/// The input row layout: class, then per slot hit, t, u, v, id.
pub(crate) fn input_layout(k: &Kind, w: u32) -> Layout {
    let mut l = vec![("class".to_string(), "in", Kind::Uint, 8, None)];
    for s in 0..SLOTS {
        for name in SLOT_FIELDS {
            let (kind, width) = match name {
                "hit" => (Kind::Flag, 1),
                "id" => (Kind::Uint, 32),
                _ => (k.clone(), w),
            };
            l.push((format!("{name}{s}"), "in", kind, width, None));
        }
    }
    Layout(l)
}

/// The expected output layout: the held state after the last slot.
pub(crate) fn output_layout(k: &Kind, w: u32) -> Layout {
    let at = Some(SLOTS as u8);
    Layout(vec![
        ("hit".into(), "out", Kind::Flag, 1, at),
        ("t".into(), "out", k.clone(), w, at),
        ("u".into(), "out", k.clone(), w, at),
        ("v".into(), "out", k.clone(), w, at),
        ("id".into(), "out", Kind::Uint, 32, at),
    ])
}

/// The stage layout: per slot s (stage s + 1) `take{s}` and the state after it
/// (`c{s}_hit`, `c{s}_t`, `c{s}_u`, `c{s}_v`, `c{s}_id`).
pub(crate) fn stage_layout(k: &Kind, w: u32) -> Layout {
    let mut l = Vec::new();
    for s in 0..SLOTS {
        let at = Some(s as u8 + 1);
        l.push((format!("take{s}"), "out", Kind::Flag, 1, at));
        l.push((format!("c{s}_hit"), "out", Kind::Flag, 1, at));
        for name in ["t", "u", "v"] {
            l.push((format!("c{s}_{name}"), "out", k.clone(), w, at));
        }
        l.push((format!("c{s}_id"), "out", Kind::Uint, 32, at));
    }
    Layout(l)
}

/// The stage table: (stage, signal, what it is).
pub fn stage_table() -> Vec<(u8, String, String)> {
    let mut v = Vec::new();
    for s in 0..SLOTS {
        let at = s as u8 + 1;
        v.push((
            at,
            format!("take{s}"),
            format!("hit{s} & (!c{p}_hit | t{s} < c{p}_t)  (t{s} <= c{p}_t under the tie rule last)", p = prev(s)),
        ));
        v.push((at, format!("c{s}_hit"), format!("take{s} ? 1 : c{}_hit", prev(s))));
        for name in ["t", "u", "v", "id"] {
            v.push((at, format!("c{s}_{name}"), format!("take{s} ? {name}{s} : c{}_{name}", prev(s))));
        }
    }
    v
}

fn prev(s: usize) -> String {
    if s == 0 {
        "reset".into()
    } else {
        format!("{}", s - 1)
    }
}

/// The input row (without its class) of one vector of class `class`: per slot hit, t, u, v, id.
pub(crate) fn case<F: Format>(f: &F, class: usize, r: &mut SplitMix64) -> Vec<u64> {
    let e = datapath::format::edges(f);
    let mut hit = [true; SLOTS];
    let mut t: [f64; SLOTS] = std::array::from_fn(|_| r.range(0.0, 4.0));
    match class {
        0 => hit = std::array::from_fn(|_| r.below(2) == 0),
        1 => {
            let shared = r.range(0.0, 4.0);
            let n = 2 + r.below(3) as usize;
            let mut slots = [0, 1, 2, 3];
            for i in (1..SLOTS).rev() {
                slots.swap(i, r.below(i as u64 + 1) as usize);
            }
            for &s in &slots[..n] {
                t[s] = shared;
            }
        }
        2 => {
            for x in t.iter_mut() {
                *x = [0.0, -0.0, 0.0, -0.0, r.range(0.0, 4.0)][r.below(5) as usize];
            }
        }
        3 => {
            t[0] = r.range(1.0, 4.0);
            for s in 1..SLOTS {
                hit[s] = r.below(3) == 0;
                t[s] = if hit[s] { r.range(t[0], 8.0) } else { r.range(0.0, 1.0) };
            }
        }
        4 => {
            t.sort_by(f64::total_cmp);
            for s in 1..SLOTS {
                if t[s] <= t[s - 1] {
                    t[s] = t[s - 1] + 0.25;
                }
            }
            if r.below(2) == 0 {
                t.reverse();
            }
        }
        5 => {
            let first = 1 + r.below(3) as usize;
            hit[..first].fill(false);
            t[first] = r.range(0.5, 4.0);
            for h in hit.iter_mut().skip(first + 1) {
                *h = r.below(2) == 0;
            }
        }
        _ => {
            let vals = [f64::INFINITY, e.max, e.least, e.min_normal, 0.0, -0.0, 1.0];
            for x in t.iter_mut() {
                *x = vals[r.below(vals.len() as u64) as usize];
            }
        }
    }
    let mut row = Vec::with_capacity(SLOTS * SLOT_FIELDS.len());
    for s in 0..SLOTS {
        let q = |x: f64| f.to_bits(f.from_f64(x));
        row.extend([hit[s] as u64, q(t[s]), q(r.range(0.0, 1.0)), q(r.range(0.0, 1.0)), r.next_u64() & 0xffff_ffff]);
    }
    row
}

/// The expected row (hit, t, u, v, id) and the stage row of one capture vector (`bits`: the
/// input row without its class) with every site of the min-capture unit computed by `x`
/// (`NoFault`: the rows a set holds). The RTI unit's format and tie rule are the unit's.
pub fn out_rows<F: Format, X: Fault<F>>(rti: &Rti<F>, bits: &[u64], x: &X) -> [Vec<u64>; 2] {
    let f = &rti.fmt;
    let mut c = Capture::<F::V>::default();
    let mut stages = Vec::with_capacity(SLOTS * 6);
    let state = |c: &Capture<F::V>| [c.hit as u64, f.to_bits(c.t), f.to_bits(c.u), f.to_bits(c.v), c.id as u64];
    for s in 0..SLOTS {
        let b = &bits[s * SLOT_FIELDS.len()..];
        let hit = b[0] != 0;
        let out = RtiOut { valid: hit, hit, t: f.from_bits(b[1]), u: f.from_bits(b[2]), v: f.from_bits(b[3]) };
        let took = rti.capture_faulty(&mut c, &out, b[4] as u32, x);
        stages.push(took as u64);
        stages.extend(state(&c));
    }
    [state(&c).to_vec(), stages]
}
