//! The stage models as SMT-LIB 2, generated from the stage tables ([`datapath::rti::stage_table`],
//! [`datapath::slab::SLAB_TABLE`]) and the format's contract ([`ieee::IeeeSmt`] for IEEE-like
//! floats, [`fixed::FixedSmt`] for fixed point).
//!
//! Naming: each unit input `x` is a declared constant `in_x` (its encoding as received) and
//! `x` is its stage-0 read; each stage signal is a nullary `define-fun` named as in the stage
//! table (values: bit-vectors of the format's width; flags: `Bool`). An arithmetic row's value
//! is `NAME!r` (and `NAME!q`, the reciprocal in `recip` division mode): for floats a declared
//! constant tied to its operands by an assertion (see [`ieee`]), for fixed point a defined
//! bit-vector function of them (see [`fixed`]). Nothing else is asserted: every model
//! of the declared inputs extends to exactly one model of the whole script, the datapath's.

mod directed;
pub mod fixed;
pub mod ieee;

use datapath::format::FormatKind;
use datapath::rti::{stage_table, Cull, Rti, RtiConfig, RTI_INPUTS};
use datapath::slab::{DirPrep, Slab, SlabConfig, SlabNan, SLAB_INPUTS, SLAB_TABLE};
use datapath::stage::{Op, Rule, SigDef};
use datapath::{AnyFormat, Format};
use fixed::FixedSmt;
use ieee::IeeeSmt;
use std::fmt::Write;

/// A format as SMT-LIB 2: an IEEE-like float or a fixed-point format.
#[derive(Clone, Copy, Debug)]
pub enum FormatSmt {
    /// IEEE-like float (`FloatingPoint` terms).
    Ieee(IeeeSmt),
    /// Signed fixed point (bit-vector functions).
    Fixed(FixedSmt),
}

impl FormatSmt {
    /// Width of an encoding in bits.
    pub fn width(&self) -> u32 {
        match self {
            Self::Ieee(x) => x.width(),
            Self::Fixed(x) => x.width(),
        }
    }
    /// A literal encoding.
    pub fn lit(&self, v: u64) -> String {
        match self {
            Self::Ieee(x) => x.lit(v),
            Self::Fixed(x) => x.lit(v),
        }
    }
    /// The bit-vector sort of one encoding.
    pub fn bv_sort(&self) -> String {
        match self {
            Self::Ieee(x) => x.bv_sort(),
            Self::Fixed(x) => x.bv_sort(),
        }
    }
    /// The helper functions (`rp_` prefix) every term of this format uses.
    pub fn prelude(&self) -> String {
        match self {
            Self::Ieee(x) => x.prelude(),
            Self::Fixed(x) => x.prelude(),
        }
    }
    /// The encoding of the datapath's 1.
    pub fn one(&self) -> u64 {
        match self {
            Self::Ieee(x) => x.one(),
            Self::Fixed(x) => x.one,
        }
    }
    /// The SMT-LIB logic of the emitted script.
    pub fn logic(&self) -> &'static str {
        match self {
            Self::Ieee(_) => "QF_BVFP",
            Self::Fixed(_) => "QF_BV",
        }
    }
    /// The IEEE form, if the format is a float.
    pub fn ieee(&self) -> Option<IeeeSmt> {
        match self {
            Self::Ieee(x) => Some(*x),
            Self::Fixed(_) => None,
        }
    }
    /// Emits `name` as the result of `op` (add, sub, mul) on operands given as (encoding, term
    /// taken as its value), see [`IeeeSmt::result`] and [`FixedSmt::result`].
    pub fn result(&self, out: &mut String, name: &str, op: Op, a: (&str, &str), b: (&str, &str)) {
        match self {
            Self::Ieee(x) => {
                let fop = match op {
                    Op::Add => "fp.add",
                    Op::Sub => "fp.sub",
                    _ => "fp.mul",
                };
                x.result(out, name, fop, a, b)
            }
            Self::Fixed(x) => {
                let fop = match op {
                    Op::Add => "rp_add",
                    Op::Sub => "rp_sub",
                    _ => "rp_mul",
                };
                x.result(out, name, fop, a.1, b.1)
            }
        }
    }
    /// Emits the terms of `name = a ÷ b` per the division mode; returns the quotient's term.
    pub fn div(&self, out: &mut String, name: &str, a: (&str, &str), b: (&str, &str)) -> String {
        match self {
            Self::Ieee(x) => x.div(out, name, a, b),
            Self::Fixed(x) => x.div(out, name, a.1, b.1),
        }
    }
}

/// The units `raypipe smt` emits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Unit {
    /// Ray–triangle intersection.
    Rti,
    /// Ray–box slab test.
    Slab,
    /// One operation (op code, a, b).
    Op,
}

impl std::str::FromStr for Unit {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "rti" => Ok(Unit::Rti),
            "slab" => Ok(Unit::Slab),
            "op" => Ok(Unit::Op),
            o => Err(format!("unknown unit '{o}' for SMT: rti, slab, op")),
        }
    }
}

/// What to emit.
#[derive(Clone, Debug)]
pub struct Request {
    /// Unit.
    pub unit: Unit,
    /// Format with its options.
    pub format: AnyFormat,
    /// RTI options.
    pub rti: RtiConfig,
    /// Slab variant name.
    pub variant: String,
    /// Slab mutation: widen by this many steps instead of the variant's number.
    pub widen: Option<i32>,
    /// Slab mutation: leave the guard out.
    pub no_guard: bool,
}

impl Request {
    /// The slab variant this request names, with its mutation, for format `f`.
    pub fn slab_config<F: Format>(&self, f: &F) -> Result<SlabConfig, String> {
        let mut cfg = SlabConfig::named_for(&self.variant, f)?;
        if let Some(w) = self.widen {
            cfg.widen_ulps = w;
        }
        if self.no_guard {
            cfg.guard = false;
        }
        Ok(cfg)
    }
}

/// A unit's emitted model: the script and the names a caller reads back.
#[derive(Clone, Debug)]
pub struct Model {
    /// The SMT-LIB 2 text (declarations, definitions, assertions; no `check-sat`).
    pub text: String,
    /// Input names, in the vector files' order (declared as `in_NAME`).
    pub inputs: Vec<String>,
    /// Stage signals in table order, with whether each is a flag.
    pub signals: Vec<(String, bool)>,
    /// The stage-table stage of each signal (same order as `signals`; the op unit's: 0).
    pub stages: Vec<u8>,
    /// Encoding width of a value.
    pub width: u32,
    /// The format as SMT.
    pub float: FormatSmt,
}

/// The SMT-LIB 2 model of a unit in a format, or why it cannot be emitted.
pub fn emit(req: &Request) -> Result<Model, String> {
    datapath::with_format!(&req.format, |f| emit_in(req, f, None))
}

/// The model of stages `lo..=hi` cut out of the unit, for proving a pipelined DUT stage by
/// stage: the signals of the stages before `lo` are declared constants (free, to be tied to the
/// DUT's registers), the signals of `lo..=hi` are defined from them (and from the inputs) as in
/// [`emit`], and the later stages' signals are listed in `signals` but not emitted.
pub fn emit_stage_range(req: &Request, lo: u8, hi: u8) -> Result<Model, String> {
    datapath::with_format!(&req.format, |f| emit_in(req, f, Some((lo, hi))))
}

/// The SMT form of the request's format (`f` is the format inside `req.format`).
fn float_of<F: Format>(req: &Request, f: &F) -> FormatSmt {
    match f.kind() {
        FormatKind::Float(lay) => {
            FormatSmt::Ieee(IeeeSmt { lay, ftz: f.flushes(), propagate: f.nan_propagates(), div: f.div_mode() })
        }
        FormatKind::Fixed { .. } => {
            let AnyFormat::Fixed(x) = req.format else { unreachable!("a fixed-point kind is AnyFormat::Fixed") };
            FormatSmt::Fixed(FixedSmt::of(&x))
        }
    }
}

fn emit_in<F: Format>(req: &Request, f: &F, cut: Option<(u8, u8)>) -> Result<Model, String> {
    let x = float_of(req, f);
    let mut e = Emitter {
        x,
        text: String::new(),
        signals: Vec::new(),
        flags: Vec::new(),
        stages: Vec::new(),
        cut,
        reads: Vec::new(),
    };
    let _ = writeln!(
        e.text,
        "; raypipe {} SMT-LIB 2 model of the {:?} unit in {}",
        env!("CARGO_PKG_VERSION"),
        req.unit,
        f.name()
    );
    let _ = writeln!(e.text, "(set-logic {})", x.logic());
    e.text.push_str(&x.prelude());
    let inputs: Vec<String> = match req.unit {
        Unit::Rti => {
            let rti = Rti::new(*f, req.rti);
            let _ = writeln!(e.text, "; rti: cull {:?}, det threshold {}", req.rti.cull, f.hex(rti.det_thr));
            let env = Env { thr: f.to_bits(rti.det_thr), cull: req.rti.cull, slab: None, delta: 0 };
            e.inputs(&RTI_INPUTS, &[]);
            for d in stage_table(f.div_mode()) {
                e.row(&d, &env)?;
            }
            RTI_INPUTS.iter().map(|s| s.to_string()).collect()
        }
        Unit::Slab => {
            let cfg = req.slab_config(f)?;
            if cfg.directed && cut.is_some() {
                return Err("the directed slab variant has no stage table of fixed shape: no stage range to cut".into());
            }
            let delta = f.to_bits(Slab::new(*f, cfg).delta());
            let _ = writeln!(e.text, "; slab variant {}: {cfg:?}", req.variant);
            let env = Env { thr: 0, cull: Cull::TwoSided, slab: Some(cfg), delta };
            // d is read by the table's own rows (dx, dy, dz)
            e.inputs(&SLAB_INPUTS, &["dx", "dy", "dz"]);
            if cfg.directed {
                let ends = directed::Ends {
                    top: e.x.lit(f.to_bits(f.from_f64(f64::INFINITY))),
                    bottom: e.x.lit(f.to_bits(f.from_f64(f64::NEG_INFINITY))),
                    no_one: f.to_f64(f.one()) != 1.0,
                };
                e.slab_directed(&env, &ends)?;
            } else {
                for d in SLAB_TABLE.iter() {
                    e.row(d, &env)?;
                }
            }
            SLAB_INPUTS.iter().map(|s| s.to_string()).collect()
        }
        Unit::Op => {
            e.op_unit();
            vec!["opcode".into(), "a".into(), "b".into()]
        }
    };
    Ok(Model {
        text: e.text,
        inputs,
        signals: e.signals.into_iter().zip(e.flags).collect(),
        stages: e.stages,
        width: x.width(),
        float: x,
    })
}

struct Env {
    thr: u64,
    cull: Cull,
    slab: Option<SlabConfig>,
    delta: u64,
}

struct Emitter {
    x: FormatSmt,
    text: String,
    signals: Vec<String>,
    flags: Vec<bool>,
    /// The stage of each signal.
    stages: Vec<u8>,
    /// Emitting stages `lo..=hi` only (see [`emit_stage_range`]).
    cut: Option<(u8, u8)>,
    /// Signals defined as an input's read, with the input (`in_x`).
    reads: Vec<(String, String)>,
}

impl Emitter {
    fn inputs(&mut self, names: &[&str], read_by_table: &[&str]) {
        let b = self.x.bv_sort();
        let _ = writeln!(self.text, "; inputs (encodings as received) and their stage-0 reads");
        for n in names {
            let _ = writeln!(self.text, "(declare-const in_{n} {b})");
        }
        for n in names.iter().filter(|n| !read_by_table.contains(n)) {
            let _ = writeln!(self.text, "(define-fun {n} () {b} (rp_read in_{n}))");
            self.reads.push((n.to_string(), format!("in_{n}")));
        }
        let _ = writeln!(self.text, "(define-fun one () {b} {})", self.x.lit(self.x.one()));
        let _ = writeln!(self.text, "(define-fun zero () {b} {})", self.x.lit(0));
    }

    fn value(&mut self, name: &str, term: &str) {
        let _ = writeln!(self.text, "(define-fun {name} () {} {term})", self.x.bv_sort());
        self.signals.push(name.into());
        self.flags.push(false);
    }

    fn flag(&mut self, name: &str, term: &str) {
        let _ = writeln!(self.text, "(define-fun {name} () Bool {term})");
        self.signals.push(name.into());
        self.flags.push(true);
    }

    /// An operand as (encoding, term taken as its value): an input's read as the input
    /// received (see [`IeeeSmt::result`]).
    fn operand<'a>(&'a self, s: &'a str) -> (&'a str, &'a str) {
        (s, self.reads.iter().find(|r| r.0 == s).map_or(s, |r| r.1.as_str()))
    }

    fn arith(&mut self, name: &str, op: Op, a: &str, b: &str) -> String {
        let (x, mut text) = (self.x, String::new());
        let (a, b) = (self.operand(a), self.operand(b));
        let r = match op {
            Op::Div => x.div(&mut text, name, a, b),
            Op::Add | Op::Sub | Op::Mul => {
                x.result(&mut text, &format!("{name}!r"), op, a, b);
                format!("{name}!r")
            }
            Op::Logic => unreachable!("a logic row has no arithmetic"),
        };
        self.text += &text;
        r
    }

    fn row(&mut self, d: &SigDef, env: &Env) -> Result<(), String> {
        let flag =
            matches!(d.rule, Rule::SignBit(_) | Rule::Le(..) | Rule::DetOk(_) | Rule::Oriented(..) | Rule::All(_));
        let at = self.signals.len();
        if let Some((lo, hi)) = self.cut {
            if !(lo..=hi).contains(&d.stage) {
                if d.stage < lo {
                    let sort = if flag { "Bool".to_string() } else { self.x.bv_sort() };
                    let _ = writeln!(self.text, "; stage {} {} (an earlier stage: tied to the DUT)", d.stage, d.name);
                    let _ = writeln!(self.text, "(declare-const {} {sort})", d.name);
                }
                self.signals.push(d.name.into());
                self.flags.push(flag);
                self.stages.push(d.stage);
                return Ok(());
            }
        }
        self.row_def(d, env)?;
        debug_assert_eq!(self.flags.get(at), Some(&flag), "{}: flag rule", d.name);
        self.stages.push(d.stage);
        Ok(())
    }

    fn row_def(&mut self, d: &SigDef, env: &Env) -> Result<(), String> {
        let guard = env.slab.is_some_and(|c| c.guard);
        let cnan = match self.x.ieee() {
            Some(x) => x.lit(x.lay.canonical_nan()),
            None if guard => return Err("the slab guard is a float rule; fixed point has none".into()),
            None => String::new(),
        };
        let _ = writeln!(self.text, "; stage {} {}", d.stage, d.name);
        match d.rule {
            Rule::Arith => {
                let r = self.arith(d.name, d.op, d.a, d.b);
                self.value(d.name, &r);
            }
            Rule::ArithGuardRecip => {
                let r = self.arith(d.name, d.op, d.a, d.b);
                let t = if guard { format!("(ite (rp_grecip {} {r}) {cnan} {r})", d.b) } else { r };
                self.value(d.name, &t);
            }
            Rule::ArithGuardSub => {
                let r = self.arith(d.name, d.op, d.a, d.b);
                let t = if guard { format!("(ite (rp_gsub {} {} {r}) {cnan} {r})", d.a, d.b) } else { r };
                self.value(d.name, &t);
            }
            Rule::Read(i) => {
                self.value(d.name, &format!("(rp_read {i})"));
                self.reads.push((d.name.to_string(), i.to_string()));
            }
            Rule::Prep(v) => {
                let cfg = env.slab.ok_or("Prep outside the slab unit")?;
                match cfg.prep {
                    DirPrep::Plain => self.value(d.name, v),
                    DirPrep::Embree => {
                        // |v| < δ ? (sign(v) ? 0 ⊖ δ : δ) : v
                        let delta = self.x.lit(env.delta);
                        let neg = format!("{}!negdelta", d.name);
                        self.x.result(&mut self.text, &neg, Op::Sub, ("zero", "zero"), (&delta, &delta));
                        let t = format!("(ite (rp_lt (rp_abs {v}) {delta}) (ite (rp_neg {v}) {neg} {delta}) {v})");
                        self.value(d.name, &t);
                    }
                }
            }
            Rule::SignBit(v) => self.flag(d.name, &format!("(rp_neg {v})")),
            Rule::Mux(c, a, b) => self.value(d.name, &format!("(ite {c} {a} {b})")),
            Rule::Le(a, b) => self.flag(d.name, &format!("(rp_le {a} {b})")),
            Rule::DetOk(det) => {
                let thr = self.x.lit(env.thr);
                let t = match env.cull {
                    Cull::TwoSided => format!("(rp_lt {thr} (rp_abs {det}))"),
                    Cull::Backface => format!("(rp_lt {thr} {det})"),
                };
                self.flag(d.name, &t);
            }
            Rule::Oriented(a, b) => {
                self.flag(d.name, &format!("(ite (rp_lt zero det) (rp_le {a} {b}) (rp_le {b} {a}))"));
            }
            Rule::All(fs) => self.flag(d.name, &format!("(and {})", fs.join(" "))),
            Rule::SelNear(acc, v) => {
                let cfg = env.slab.ok_or("SelNear outside the slab unit")?;
                let t = match cfg.nan {
                    SlabNan::Ignore => format!("(ite (rp_lt {acc} {v}) {v} {acc})"),
                    SlabNan::TakeOnFalse => format!("(ite (rp_le {v} {acc}) {acc} {v})"),
                };
                self.value(d.name, &t);
            }
            Rule::SelFar(acc, v) => {
                let cfg = env.slab.ok_or("SelFar outside the slab unit")?;
                let t = match cfg.nan {
                    SlabNan::Ignore => format!("(ite (rp_lt {v} {acc}) {v} {acc})"),
                    SlabNan::TakeOnFalse => format!("(ite (rp_le {acc} {v}) {acc} {v})"),
                };
                self.value(d.name, &t);
            }
            Rule::Widen(v, up) => {
                let cfg = env.slab.ok_or("Widen outside the slab unit")?;
                let step_up = up != (cfg.widen_ulps < 0);
                let f = if step_up { "rp_up" } else { "rp_down" };
                let mut t = v.to_string();
                for _ in 0..cfg.widen_ulps.unsigned_abs() {
                    t = format!("({f} {t})");
                }
                self.value(d.name, &t);
            }
        }
        Ok(())
    }

    /// The op unit: the four arithmetic results and two compares of (a, b), selected by the
    /// op code (0 add, 1 sub, 2 mul, 3 div, 4 lt, 5 le; result 0 for compares, cmp false for
    /// arithmetic). Its inputs are not read (the op unit applies the operations directly).
    fn op_unit(&mut self) {
        let b = self.x.bv_sort();
        let _ = writeln!(self.text, "(declare-const in_opcode (_ BitVec 4))");
        let _ = writeln!(self.text, "(declare-const in_a {b})");
        let _ = writeln!(self.text, "(declare-const in_b {b})");
        let _ = writeln!(self.text, "(define-fun one () {b} {})", self.x.lit(self.x.one()));
        for (name, op) in [("add", Op::Add), ("sub", Op::Sub), ("mul", Op::Mul), ("div", Op::Div)] {
            let r = self.arith(name, op, "in_a", "in_b");
            self.value(name, &r);
        }
        self.flag("lt", "(rp_lt in_a in_b)");
        self.flag("le", "(rp_le in_a in_b)");
        let z = self.x.lit(0);
        let code = |c: u64| format!("(= in_opcode {})", ieee::bv(c, 4));
        let result =
            format!("(ite {} add (ite {} sub (ite {} mul (ite {} div {z}))))", code(0), code(1), code(2), code(3));
        self.value("result", &result);
        self.flag("cmp", &format!("(ite {} lt (ite {} le false))", code(4), code(5)));
        self.stages = vec![0; self.signals.len()];
    }
}
