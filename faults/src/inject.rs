//! A bank fault as a [`Fault`] the stage models run with: every site computes what the
//! fault-free datapath computes, except the fault's site, which computes the bug. Other
//! rounding modes and the fused multiply-add are exact (`rustc_apfloat`) for binary32,
//! binary16 and bfloat16 with either subnormal mode and the canonical NaN rule; in other
//! formats such a fault is not modelled (and a campaign says so).

use crate::bank::{Kind, Mode, Spec};
use datapath::fault::{fault_free, step_free, Cmp, Fault, Logic};
use datapath::format::{DivMode, FormatKind};
use datapath::rti::Op;
use datapath::Format;
use rustc_apfloat::ieee::{BFloat, Half, Single};
use rustc_apfloat::{Float, Round};
use std::cell::Cell;

/// One bank fault, injected; remembers whether its site was reached and could be modelled.
#[derive(Debug)]
pub struct Injected {
    spec: Spec,
    /// A fused fault's product site's operands (as encodings) in the current test.
    operands: Cell<Option<(u64, u64)>>,
    reached: Cell<bool>,
    unmodelled: Cell<bool>,
    /// The fault is what this format's datapath does anyway (a flush in an FTZ format).
    inherent: Cell<bool>,
}

impl Injected {
    /// `spec`, ready to inject.
    pub fn new(spec: &Spec) -> Self {
        Self {
            spec: *spec,
            operands: Cell::new(None),
            reached: Cell::new(false),
            unmodelled: Cell::new(false),
            inherent: Cell::new(false),
        }
    }
    /// Forgets the current test's operands (call before each test).
    pub fn next_test(&self) {
        self.operands.set(None);
    }
    /// The fault's site was computed at least once.
    pub fn reached(&self) -> bool {
        self.reached.get()
    }
    /// The fault could not be modelled in this format (its site then computed the fault-free
    /// value).
    pub fn unmodelled(&self) -> bool {
        self.unmodelled.get()
    }
    /// The fault is the format's own rule here (a subnormal flush in an FTZ format): no
    /// vector can tell it from the datapath.
    pub fn inherent(&self) -> bool {
        self.inherent.get()
    }
    fn hit<T>(&self, fallback: T, v: Option<T>) -> T {
        v.unwrap_or_else(|| {
            self.unmodelled.set(true);
            fallback
        })
    }
}

impl Logic for Injected {
    fn flag(&self, site: &'static str, v: bool) -> bool {
        if site != self.spec.site {
            return v;
        }
        self.reached.set(true);
        match self.spec.kind {
            Kind::Stuck(s) => s,
            _ => v,
        }
    }
    fn less(&self, site: &'static str, a: f64, b: f64) -> bool {
        if site != self.spec.site {
            return a < b;
        }
        self.reached.set(true);
        match self.spec.kind {
            Kind::TieSwap => a <= b,
            Kind::Swap => b < a,
            _ => a < b,
        }
    }
    fn limit(&self, site: &'static str, v: usize) -> usize {
        if site != self.spec.site {
            return v;
        }
        self.reached.set(true);
        match self.spec.kind {
            Kind::OffByOne => v.saturating_add(1),
            _ => v,
        }
    }
}

impl<F: Format> Fault<F> for Injected {
    const ON: bool = true;
    fn arith(&self, f: &F, site: &'static str, op: Op, a: F::V, b: F::V) -> F::V {
        if let Kind::Fused { product, .. } = self.spec.kind {
            if site == product {
                self.operands.set(Some((f.to_bits(a), f.to_bits(b))));
            }
        }
        let r = fault_free(f, op, a, b);
        if site != self.spec.site {
            return r;
        }
        self.reached.set(true);
        match self.spec.kind {
            Kind::Swap => fault_free(f, op, b, a),
            Kind::FirstTwice => fault_free(f, op, a, a),
            // a ⊗ (1 ⊘ b) datapaths: the fault is the reciprocal unit's rounding
            Kind::Round(m) if op == Op::Div && f.div_mode() == DivMode::RecipMul => {
                let rec = exact(f, Op::Div, f.one(), b, None, m);
                self.hit(r, rec.map(|q| f.mul(a, q)))
            }
            Kind::Round(m) => self.hit(r, exact(f, op, a, b, None, m)),
            Kind::NanRule => match f.kind() {
                FormatKind::Float(l) if f.is_nan(r) => {
                    let first = [a, b].into_iter().find(|&v| f.is_nan(v));
                    let quiet = 1u64 << (l.man_bits - 1);
                    match (f.nan_propagates(), first) {
                        (true, _) => f.from_bits(l.canonical_nan()),
                        (false, Some(v)) => f.from_bits(f.to_bits(v) | quiet),
                        (false, None) => r,
                    }
                }
                FormatKind::Float(_) => r,
                _ => self.hit(r, None),
            },
            Kind::Fused { first, .. } => {
                let p = self.operands.get();
                let addend = if first { b } else { a };
                let v = p.and_then(|(x, y)| exact(f, Op::Mul, f.from_bits(x), f.from_bits(y), Some(addend), None));
                self.hit(r, v)
            }
            Kind::Flush if f.flushes() => {
                self.inherent.set(true);
                r
            }
            Kind::Flush => match f.kind() {
                FormatKind::Float(l) if l.is_subnormal(f.to_bits(r)) => f.from_bits(f.to_bits(r) & l.sign_mask()),
                FormatKind::Float(_) => r,
                _ => self.hit(r, None),
            },
            _ => r,
        }
    }
    fn compare(&self, f: &F, site: &'static str, cmp: Cmp, a: F::V, b: F::V) -> bool {
        let r = cmp.eval(f, a, b);
        if site != self.spec.site {
            return r;
        }
        self.reached.set(true);
        match self.spec.kind {
            Kind::Strict => f.lt(a, b),
            Kind::Loose => f.le(a, b),
            Kind::Stuck(v) => v,
            Kind::TieSwap => match cmp {
                Cmp::Lt => f.le(a, b),
                Cmp::Le => f.lt(a, b),
            },
            Kind::Unordered => r || f.is_nan(a) || f.is_nan(b),
            Kind::Swap => cmp.eval(f, b, a),
            _ => r,
        }
    }
    fn step(&self, f: &F, site: &'static str, up: bool, v: F::V) -> F::V {
        let r = step_free(f, up, v);
        if site != self.spec.site {
            return r;
        }
        self.reached.set(true);
        match self.spec.kind {
            Kind::Bypass => v,
            Kind::TwosStep => match f.kind() {
                FormatKind::Float(_) => {
                    let mask = u64::MAX >> (64 - f.width());
                    let b = f.to_bits(v);
                    f.from_bits(if up { b.wrapping_add(1) } else { b.wrapping_sub(1) } & mask)
                }
                _ => self.hit(r, None),
            },
            _ => r,
        }
    }
}

/// `a op b` rounded in `mode` (or, with `c`, the fused a × b + c rounded to nearest-even),
/// with the format's operand read, FTZ and canonical NaN rules; `None` where the format has no
/// exact model here (not binary32 / binary16 / bfloat16, or the propagate NaN rule).
fn exact<F: Format>(f: &F, op: Op, a: F::V, b: F::V, c: Option<F::V>, mode: impl Into<Option<Mode>>) -> Option<F::V> {
    let FormatKind::Float(l) = f.kind() else { return None };
    if f.nan_propagates() {
        return None;
    }
    let read = |v: F::V| {
        let x = f.to_bits(v);
        if f.flushes() && l.is_subnormal(x) {
            x & l.sign_mask()
        } else {
            x
        }
    };
    let round = match mode.into() {
        None => Round::NearestTiesToEven,
        Some(Mode::TowardZero) => Round::TowardZero,
        Some(Mode::TowardPositive) => Round::TowardPositive,
        Some(Mode::TowardNegative) => Round::TowardNegative,
        Some(Mode::NearestTiesToAway) => Round::NearestTiesToAway,
    };
    let (x, y, z) = (read(a), read(b), c.map(read));
    let r = match (l.exp_bits, l.man_bits) {
        (8, 23) => apply::<Single>(op, x, y, z, round),
        (5, 10) => apply::<Half>(op, x, y, z, round),
        (8, 7) => apply::<BFloat>(op, x, y, z, round),
        _ => return None,
    }?;
    let r = if l.is_nan(r) {
        l.canonical_nan()
    } else if f.flushes() && l.is_subnormal(r) {
        r & l.sign_mask()
    } else {
        r
    };
    Some(f.from_bits(r))
}

fn apply<T: Float>(op: Op, x: u64, y: u64, z: Option<u64>, round: Round) -> Option<u64> {
    let (a, b) = (T::from_bits(x as u128), T::from_bits(y as u128));
    let r = match (op, z) {
        (Op::Mul, Some(c)) => a.mul_add_r(b, T::from_bits(c as u128), round),
        (_, Some(_)) => return None,
        (Op::Add, None) => a.add_r(b, round),
        (Op::Sub, None) => a.sub_r(b, round),
        (Op::Mul, None) => a.mul_r(b, round),
        (Op::Div, None) => a.div_r(b, round),
        (Op::Logic, None) => return None,
    };
    Some(r.value.to_bits() as u64)
}
