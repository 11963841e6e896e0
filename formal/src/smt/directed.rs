//! The directed slab variant as SMT-LIB 2: stage 0 of the slab table (reads, preparation,
//! reciprocals), then the bounds `datapath::slab::Slab::trace_directed` forms, every signal
//! defined for every input (an axis read as parallel keeps its signals but adds no constraint,
//! which is how the model skips it).
//!
//! Per axis `a` (names with the suffix `_x`, `_y`, `_z`): `inv_lo`/`inv_hi` = nextDown / nextUp
//! of `inv_d` (in a fixed format without 1, both the saturation value of d's sign); `par` =
//! d reads as ±0; `inside` = `min <= o <= max`; the entry plane `pe` (max when `inv_d` is
//! negative, else min) and exit plane `px`; `de = pe ⊖ o`, `dxp = px ⊖ o`, each bracketed by one
//! step down and up; the entry bound's factors (`xe`: `de_hi` when negative, else `de_lo`; `inve`:
//! `inv_hi` when `xe` is negative, else `inv_lo`) and the exit bound's (`xx`: `dx_lo` when
//! negative, else `dx_hi`; `invx`: `inv_lo` when `xx` is negative, else `inv_hi`); an unbounded
//! factor (a lower end equal to the most negative value, an upper end equal to the most
//! positive) makes `entry` the most negative value and `exit` the most positive; otherwise
//! `entry = nextDown(xe ⊗ inve)`, `exit = nextUp(xx ⊗ invx)`. `near`/`far` accumulate from
//! `tmin`/`tmax` with the variant's comparator over the axes not parallel; `outside` = some
//! parallel axis with o outside; `hit = !outside && t_near <= t_far`.

use super::{Emitter, Env};
use datapath::slab::{SlabNan, SLAB_TABLE};
use datapath::stage::Op;

/// The directed variant's format constants: the most positive and most negative encodings
/// (±∞ for floats, the saturation values for fixed point) and whether 1 is representable.
pub(super) struct Ends {
    /// The most positive value's literal.
    pub top: String,
    /// The most negative value's literal.
    pub bottom: String,
    /// The format holds no 1 (q1.F): both reciprocal bounds are the saturation value.
    pub no_one: bool,
}

impl Emitter {
    /// Emits the directed slab variant (stage 0 from the table, then the bounds).
    pub(super) fn slab_directed(&mut self, env: &Env, ends: &Ends) -> Result<(), String> {
        let cfg = env.slab.ok_or("the directed variant is a slab variant")?;
        for d in SLAB_TABLE.iter().filter(|d| d.stage == 0) {
            self.row(d, env)?;
        }
        let (top, bottom) = (ends.top.as_str(), ends.bottom.as_str());
        let axes = ["x", "y", "z"];
        let _ = std::fmt::Write::write_str(&mut self.text, "; directed: 1/d bounds and parallel flags\n");
        for a in axes {
            if ends.no_one {
                let end = format!("(ite (rp_neg d{a}) {bottom} {top})");
                self.value(&format!("inv_lo{a}"), &end);
                self.value(&format!("inv_hi{a}"), &end);
            } else {
                self.value(&format!("inv_lo{a}"), &format!("(rp_down inv_d{a})"));
                self.value(&format!("inv_hi{a}"), &format!("(rp_up inv_d{a})"));
            }
        }
        for a in axes {
            self.flag(&format!("par{a}"), &format!("(and (rp_le d{a} zero) (rp_le zero d{a}))"));
        }
        let sel = |near: bool, acc: &str, v: &str| match (cfg.nan, near) {
            (SlabNan::Ignore, true) => format!("(ite (rp_lt {acc} {v}) {v} {acc})"),
            (SlabNan::Ignore, false) => format!("(ite (rp_lt {v} {acc}) {v} {acc})"),
            (SlabNan::TakeOnFalse, true) => format!("(ite (rp_le {v} {acc}) {acc} {v})"),
            (SlabNan::TakeOnFalse, false) => format!("(ite (rp_le {acc} {v}) {acc} {v})"),
        };
        let (mut near, mut far) = ("tmin".to_string(), "tmax".to_string());
        let mut outside = Vec::new();
        for a in axes {
            let _ = std::fmt::Write::write_str(&mut self.text, &format!("; directed: axis {a}\n"));
            let n = |s: &str| format!("{s}_{a}");
            self.flag(&n("inside"), &format!("(and (rp_le min{a} o{a}) (rp_le o{a} max{a}))"));
            self.flag(&n("neg"), &format!("(rp_neg inv_d{a})"));
            let neg = n("neg");
            self.value(&n("pe"), &format!("(ite {neg} max{a} min{a})"));
            self.value(&n("px"), &format!("(ite {neg} min{a} max{a})"));
            let de = self.arith(&n("de"), Op::Sub, &n("pe"), &format!("o{a}"));
            self.value(&n("de"), &de);
            let dxp = self.arith(&n("dxp"), Op::Sub, &n("px"), &format!("o{a}"));
            self.value(&n("dxp"), &dxp);
            for (s, f, v) in [
                ("de_lo", "rp_down", "de"),
                ("de_hi", "rp_up", "de"),
                ("dx_lo", "rp_down", "dxp"),
                ("dx_hi", "rp_up", "dxp"),
            ] {
                self.value(&n(s), &format!("({f} {})", n(v)));
            }
            let up_inf = |v: &str| format!("(= {v} {top})");
            let lo_inf = |v: &str| format!("(= {v} {bottom})");
            let (de_lo, de_hi, dx_lo, dx_hi) = (n("de_lo"), n("de_hi"), n("dx_lo"), n("dx_hi"));
            let (ilo, ihi) = (format!("inv_lo{a}"), format!("inv_hi{a}"));
            self.value(&n("xe"), &format!("(ite {neg} {de_hi} {de_lo})"));
            self.flag(&n("xe_inf"), &format!("(ite {neg} {} {})", up_inf(&de_hi), lo_inf(&de_lo)));
            let xe = n("xe");
            self.value(&n("inve"), &format!("(ite (rp_neg {xe}) {ihi} {ilo})"));
            self.flag(&n("inve_inf"), &format!("(ite (rp_neg {xe}) {} {})", up_inf(&ihi), lo_inf(&ilo)));
            self.value(&n("xx"), &format!("(ite {neg} {dx_lo} {dx_hi})"));
            self.flag(&n("xx_inf"), &format!("(ite {neg} {} {})", lo_inf(&dx_lo), up_inf(&dx_hi)));
            let xx = n("xx");
            self.value(&n("invx"), &format!("(ite (rp_neg {xx}) {ilo} {ihi})"));
            self.flag(&n("invx_inf"), &format!("(ite (rp_neg {xx}) {} {})", lo_inf(&ilo), up_inf(&ihi)));
            let pe = self.arith(&n("prod_e"), Op::Mul, &xe, &n("inve"));
            let px = self.arith(&n("prod_x"), Op::Mul, &xx, &n("invx"));
            self.value(
                &format!("entry_{a}"),
                &format!("(ite (or {} {}) {bottom} (rp_down {pe}))", n("xe_inf"), n("inve_inf")),
            );
            self.value(
                &format!("exit_{a}"),
                &format!("(ite (or {} {}) {top} (rp_up {px}))", n("xx_inf"), n("invx_inf")),
            );
            let par = format!("par{a}");
            self.value(&n("near"), &format!("(ite {par} {near} {})", sel(true, &near, &format!("entry_{a}"))));
            self.value(&n("far"), &format!("(ite {par} {far} {})", sel(false, &far, &format!("exit_{a}"))));
            near = n("near");
            far = n("far");
            outside.push(format!("(and {par} (not {}))", n("inside")));
        }
        self.value("t_near", &near);
        self.value("t_far", &far);
        self.flag("outside", &format!("(or {})", outside.join(" ")));
        self.flag("hit", "(and (not outside) (rp_le t_near t_far))");
        // (the table's stage-0 rows carry their stage; the bounds are stage 1)
        let n = self.signals.len();
        self.stages.resize(n, 1);
        Ok(())
    }
}
