//! The fault bank: one [`Spec`] per hardware bug, each a one-line change to one site of a
//! stage model (the site names are the stage table's signal names, see
//! `datapath::rti::Rti::trace_faulty`).

/// A rounding mode other than the datapath's nearest-even.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// Toward zero (truncation).
    TowardZero,
    /// Toward +∞.
    TowardPositive,
    /// Toward −∞.
    TowardNegative,
    /// To nearest, ties away from zero (a round-half-up adder on magnitudes).
    NearestTiesToAway,
}

/// How a fault changes its site.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// The arithmetic site's operands are swapped (a − b computed as b − a).
    Swap,
    /// The arithmetic site's second operand is replaced by its first (a wrong mux select).
    FirstTwice,
    /// The arithmetic site rounds in another mode (same operands, same rules otherwise).
    Round(Mode),
    /// The adder site takes the product of `product`'s operands unrounded: the adder and the
    /// multiplier that feeds it (its first operand when `first`, else its second) fused into
    /// one multiply-add, rounded once.
    Fused {
        /// The multiplier site whose rounding is lost.
        product: &'static str,
        /// The product is the adder's first operand.
        first: bool,
    },
    /// The arithmetic site flushes a subnormal result to zero of its sign (FTZ in one stage).
    Flush,
    /// The compare site is strict where it should not be (a ≤ b computed as a < b).
    Strict,
    /// The compare site is loose where it should be strict (a < b computed as a ≤ b).
    Loose,
    /// The compare site's output is stuck at this value (a check left out, or tied off).
    Stuck(bool),
}

/// One fault of the bank.
#[derive(Clone, Copy, Debug)]
pub struct Spec {
    /// Unique name: `unit.site.kind`.
    pub name: &'static str,
    /// The unit it is injected into (`rti`).
    pub unit: &'static str,
    /// The site it changes (a signal name of the unit's stage table).
    pub site: &'static str,
    /// The change.
    pub kind: Kind,
    /// The RTL bug it stands for, in one line.
    pub what: &'static str,
    /// When the outputs (valid, hit, t, u, v) are identical to the fault-free unit's on every
    /// input: the argument. Such a fault may still show on a stage probe.
    pub benign: Option<&'static str>,
}

const fn rti(name: &'static str, site: &'static str, kind: Kind, what: &'static str) -> Spec {
    Spec { name, unit: "rti", site, kind, what, benign: None }
}

/// Every fault of the bank.
pub const BANK: &[Spec] = &[
    rti("rti.e1x.swap", "e1x", Kind::Swap, "stage 1: e1.x wired as v0.x − v1.x (operand order of one subtractor)"),
    rti("rti.e2z.swap", "e2z", Kind::Swap, "stage 1: e2.z wired as v0.z − v2.z"),
    rti("rti.sy.swap", "sy", Kind::Swap, "stage 1: s.y wired as v0.y − o.y"),
    rti("rti.px.swap", "px", Kind::Swap, "stage 3: p.x = pxb − pxa (one cross-product component negated)"),
    rti("rti.qz.swap", "qz", Kind::Swap, "stage 3: q.z = qzb − qza"),
    rti(
        "rti.pya.first",
        "pya",
        Kind::FirstTwice,
        "stage 2: pya = d.z × d.z (the multiplier's second operand mux selects the first)",
    ),
    rti("rti.uv.first", "uv", Kind::FirstTwice, "stage 7: u + v computed as u + u"),
    rti("rti.pxa.rz", "pxa", Kind::Round(Mode::TowardZero), "stage 2: multiplier pxa truncates (rounds toward zero)"),
    rti("rti.qyb.rz", "qyb", Kind::Round(Mode::TowardZero), "stage 2: multiplier qyb truncates"),
    rti(
        "rti.detx.rna",
        "detx",
        Kind::Round(Mode::NearestTiesToAway),
        "stage 4: multiplier detx rounds half away from zero",
    ),
    rti(
        "rti.upy.rna",
        "upy",
        Kind::Round(Mode::NearestTiesToAway),
        "stage 4: multiplier upy rounds half away from zero",
    ),
    rti(
        "rti.e1y.rna",
        "e1y",
        Kind::Round(Mode::NearestTiesToAway),
        "stage 1: subtractor e1y rounds half away from zero",
    ),
    rti("rti.tp.rup", "tp", Kind::Round(Mode::TowardPositive), "stage 6: adder t' rounds toward +∞"),
    rti("rti.up_xy.rdn", "up_xy", Kind::Round(Mode::TowardNegative), "stage 5: adder up_xy rounds toward −∞"),
    rti(
        "rti.t.rz",
        "t",
        Kind::Round(Mode::TowardZero),
        "output t: the final multiplier (divider under :divide) truncates",
    ),
    rti(
        "rti.inv_det.rz",
        "inv_det",
        Kind::Round(Mode::TowardZero),
        "reciprocal 1/det truncates (reciprocal-multiply datapaths)",
    ),
    rti(
        "rti.det_xy.fma",
        "det_xy",
        Kind::Fused { product: "detx", first: true },
        "stages 4-5 fused: det_xy = fma(e1.x, p.x, dety) (detx never rounded)",
    ),
    rti(
        "rti.vp.fma",
        "vp",
        Kind::Fused { product: "vpz", first: false },
        "stages 4-6 fused: v' = fma(d.z, q.z, vp_xy) (vpz never rounded)",
    ),
    rti(
        "rti.t.ftz",
        "t",
        Kind::Flush,
        "output t flushes a subnormal result to zero (an FTZ multiplier or divider in one stage)",
    ),
    rti("rti.qx.ftz", "qx", Kind::Flush, "stage 3: subtractor q.x flushes a subnormal result to zero"),
    rti("rti.u_ok.strict", "u_ok", Kind::Strict, "stage 7: u' ≥ 0 tested as u' > 0 (an edge hit is lost)"),
    rti("rti.v_ok.strict", "v_ok", Kind::Strict, "stage 7: v' ≥ 0 tested as v' > 0"),
    rti("rti.uv_ok.strict", "uv_ok", Kind::Strict, "stage 7: u' + v' ≤ det tested as u' + v' < det"),
    rti("rti.t_ok.strict", "t_ok", Kind::Strict, "stage 7: t' ≥ 0 tested as t' > 0"),
    rti("rti.tmin_ok.strict", "tmin_ok", Kind::Strict, "t interval: tmin ≤ t tested as tmin < t"),
    rti("rti.tmax_ok.strict", "tmax_ok", Kind::Strict, "t interval: t ≤ tmax tested as t < tmax"),
    rti("rti.det_ok.loose", "det_ok", Kind::Loose, "stage 7: threshold < |det| tested as threshold ≤ |det|"),
    Spec {
        name: "rti.pos.loose",
        unit: "rti",
        site: "pos",
        kind: Kind::Loose,
        what: "stage 7: the det sign select tests 0 ≤ det instead of 0 < det",
        benign: Some(
            "the selects differ only when det is ±0, and then det_ok is false (the threshold is ≥ 0, \
             so neither thr < |±0| nor thr < ±0 holds), valid and hit are false whatever the selects \
             give, and t, u, v do not read them; the u_ok, v_ok, uv_ok, t_ok probes do show it",
        ),
    },
    rti("rti.t_ok.stuck1", "t_ok", Kind::Stuck(true), "stage 7: the t' ≥ 0 check left out (hits behind the origin)"),
    rti("rti.uv_ok.stuck1", "uv_ok", Kind::Stuck(true), "stage 7: the u' + v' ≤ det check left out"),
    rti("rti.det_ok.stuck1", "det_ok", Kind::Stuck(true), "stage 7: the det threshold check left out"),
    rti("rti.tmax_ok.stuck1", "tmax_ok", Kind::Stuck(true), "t interval: the tmax compare tied off"),
    rti("rti.tmin_ok.stuck1", "tmin_ok", Kind::Stuck(true), "t interval: the tmin compare tied off"),
];

/// The fault named `name`.
pub fn by_name(name: &str) -> Option<&'static Spec> {
    BANK.iter().find(|s| s.name == name)
}
