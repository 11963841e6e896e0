//! Fault injection: a hardware bug as a change to what one named site of a stage model
//! computes. A model calls its fault at every arithmetic site (the stage table's signal names:
//! `e1x`, `pxa`, `det_xy`, `inv_det`, `t`, …) and every compare site (`det_ok`, `pos`, `u_ok`,
//! `v_ok`, `uv_ok`, `t_ok`, `tmin_ok`, `tmax_ok`, and the min-capture unit's `take`), every
//! logic bit that steers the datapath (the slab unit's sign selects `negx`…, its guard
//! decisions, the traversal's history updates, [`Logic`]) and every grid step (the slab unit's
//! widening); with [`NoFault`]
//! (`ON == false`) each call is the format's own operation and the model's code is what it
//! was without the hook. The fault models themselves (which site, which bug) live
//! in the `faults` crate.

use crate::stage::Op;
use crate::Format;

/// The comparison a compare site makes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cmp {
    /// a < b (false when either is NaN).
    Lt,
    /// a <= b (false when either is NaN).
    Le,
}

impl Cmp {
    /// `a self b` in format `f` (the operands read as the format reads them).
    #[inline(always)]
    pub fn eval<F: Format>(self, f: &F, a: F::V, b: F::V) -> bool {
        match self {
            Cmp::Lt => f.lt(a, b),
            Cmp::Le => f.le(a, b),
        }
    }
}

/// `a op b` in format `f`, as the fault-free datapath computes it (`Op::Logic` is no
/// arithmetic: it gives `a`).
#[inline(always)]
pub fn fault_free<F: Format>(f: &F, op: Op, a: F::V, b: F::V) -> F::V {
    match op {
        Op::Sub => f.sub(a, b),
        Op::Add => f.add(a, b),
        Op::Mul => f.mul(a, b),
        Op::Div => f.div(a, b),
        Op::Logic => a,
    }
}

/// One grid step of `v` in format `f`, as the fault-free datapath takes it: IEEE nextUp when
/// `up`, else nextDown.
#[inline(always)]
pub fn step_free<F: Format>(f: &F, up: bool, v: F::V) -> F::V {
    if up {
        f.next_up(v)
    } else {
        f.next_down(v)
    }
}

/// What a unit's control logic computes: the bits that steer it, the orderings of the
/// distances it holds, the limits it counts to; fault-free, or with a bug. Every method's
/// default is the fault-free logic.
pub trait Logic {
    /// The bit logic site `site` produces where the fault-free logic produces `v`.
    #[inline(always)]
    fn flag(&self, _site: &'static str, v: bool) -> bool {
        v
    }
    /// The ordering site `site`: `a < b` on distances held as binary64 (false when either is
    /// NaN).
    #[inline(always)]
    fn less(&self, _site: &'static str, a: f64, b: f64) -> bool {
        a < b
    }
    /// The limit counting site `site` compares with, where the fault-free logic uses `v`.
    #[inline(always)]
    fn limit(&self, _site: &'static str, v: usize) -> usize {
        v
    }
}

/// What a model's sites compute: the fault-free datapath, or one with a bug.
pub trait Fault<F: Format>: Logic {
    /// False for [`NoFault`].
    const ON: bool;
    /// The value arithmetic site `site` produces from its operands (`op` names the
    /// fault-free operation, [`fault_free`]).
    fn arith(&self, f: &F, site: &'static str, op: Op, a: F::V, b: F::V) -> F::V;
    /// The bit compare site `site` produces (fault-free: `cmp.eval(f, a, b)`).
    fn compare(&self, f: &F, site: &'static str, cmp: Cmp, a: F::V, b: F::V) -> bool;
    /// The grid step site `site` produces from `v`: fault-free, IEEE nextUp (`up`) or
    /// nextDown of `v` in format `f` (see `slab::STEP_RULES`).
    #[inline(always)]
    fn step(&self, f: &F, _site: &'static str, up: bool, v: F::V) -> F::V {
        step_free(f, up, v)
    }
}

/// The fault-free datapath: every site is the format's own operation.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoFault;

impl Logic for NoFault {}

impl<F: Format> Fault<F> for NoFault {
    const ON: bool = false;
    #[inline(always)]
    fn arith(&self, f: &F, _: &'static str, op: Op, a: F::V, b: F::V) -> F::V {
        fault_free(f, op, a, b)
    }
    #[inline(always)]
    fn compare(&self, f: &F, _: &'static str, cmp: Cmp, a: F::V, b: F::V) -> bool {
        cmp.eval(f, a, b)
    }
}

#[cfg(test)]
mod tests {
    use super::{Logic, NoFault};

    /// The fault-free control logic is the identity on bits and limits and the IEEE `<` on
    /// distances (false when either is NaN), at every site.
    #[test]
    fn the_fault_free_logic_is_the_plain_logic() {
        let vals = [f64::NEG_INFINITY, -1.0, -0.0, 0.0, 1e-300, 1.0, 2.0, f64::INFINITY, f64::NAN];
        for a in vals {
            for b in vals {
                assert_eq!(NoFault.less("site", a, b), a < b, "{a} < {b}");
            }
        }
        for v in [0usize, 1, 2, 7, 64, usize::MAX] {
            assert_eq!(NoFault.limit("n_limit", v), v);
        }
        for v in [false, true] {
            assert_eq!(NoFault.flag("take", v), v);
        }
    }
}
