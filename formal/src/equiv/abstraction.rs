//! Operator abstraction: an arithmetic module of the DUT (a multiplier, an adder) replaced, in
//! every step of a stage-by-stage proof, by the IEEE operation it computes, and that replacement
//! justified by proving the module alone equal to the operation for every pair of operands.
//!
//! `--abstract MODULE=OP` names a module with input ports `a`, `b` and output port `y` (IEEE
//! encodings of the set's format) and its operation: `mul` (y = a × b) or `add` (y = a + b;
//! a − b where the module has a port `sub` tied to 1), rounded to nearest-even once, a NaN
//! result encoded as the format contract's NaN rule says (`rp_nanres`). An instance is
//! abstracted when it is a cell of the top module whose every other port is tied to a constant
//! (a rounding-mode port, `sub`; an output port other than `y` that is connected disqualifies
//! it). The instances of one module elaborated with the same parameters (one yosys module) and
//! tied to the same constants share one justification: the module elaborated alone, its
//! constant ports asserted to those constants, `a` and `b` free, and `y` ≠ the operation
//! `unsat`. In a step, each abstracted instance's `y` is cut (a free value per cycle) and
//! assumed equal to the operation on its `a` and `b`; the rest of its logic is gone from the
//! query. A step proven so is proven for the DUT only if its justification is (the report
//! says so); an instance that does not qualify stays concrete (and is listed with the reason).

use std::fmt::Write as _;
use std::path::Path;

use super::{bare_path, push_script, read_script, top_module, write_smt2, Dut};
use crate::smt::Model;

/// The operation an abstracted module computes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Op {
    /// y = a × b.
    Mul,
    /// y = a + b (a − b with `sub` tied to 1).
    Add,
}

/// One `--abstract MODULE=OP`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Abstraction {
    /// The module's name in the sources.
    pub module: String,
    /// Its operation.
    pub op: Op,
}

/// Parses `MODULE=OP` (OP: mul, add).
pub fn parse(spec: &str) -> Result<Abstraction, String> {
    let (m, op) = spec.split_once('=').ok_or(format!("--abstract {spec}: MODULE=OP (OP: mul or add)"))?;
    if m.is_empty() || !m.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
        return Err(format!("--abstract {spec}: '{m}' is not a module name"));
    }
    let op = match op {
        "mul" => Op::Mul,
        "add" => Op::Add,
        _ => return Err(format!("--abstract {spec}: operation '{op}' (mul or add)")),
    };
    Ok(Abstraction { module: m.to_string(), op })
}

/// An abstracted instance (a cell of the top module; its flattened wires are `NAME.a`,
/// `NAME.b`, `NAME.y`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Instance {
    /// The cell's name.
    pub name: String,
    /// Index of its `--abstract`.
    pub abs: usize,
    /// The justification group it belongs to.
    pub group: usize,
    /// a − b rather than a + b (an `add` module's `sub` tied to 1).
    pub sub: bool,
}

/// The instances one module-alone proof justifies.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Group {
    /// Index of its `--abstract`.
    pub abs: usize,
    /// yosys's name for the module with its parameters.
    pub cell_type: String,
    /// Ports tied to constants: (port, bits, most significant first).
    pub consts: Vec<(String, String)>,
    /// The instances' names.
    pub instances: Vec<String>,
}

/// The DUT's abstracted instances and those left concrete.
#[derive(Clone, Debug, Default)]
pub struct Plan {
    /// The `--abstract` options.
    pub abstractions: Vec<Abstraction>,
    /// Abstracted instances.
    pub instances: Vec<Instance>,
    /// Justification groups.
    pub groups: Vec<Group>,
    /// Instances of an abstracted module left concrete, with the reason.
    pub concrete: Vec<(String, String)>,
}

/// The yosys lines (after `hierarchy`, before `proc`) that list the candidate cells in `file`.
pub fn list_cells(abs: &[Abstraction], file: &Path) -> Result<String, String> {
    if abs.is_empty() {
        return Ok(String::new());
    }
    let f = bare_path(file)?;
    let pats: Vec<String> = abs.iter().map(|a| format!("t:*{}*", a.module)).collect();
    Ok(format!("tee -q -o {f} dump {}\n", pats.join(" ")))
}

/// Whether yosys's cell type `t` is module `m` (plain or with parameters).
fn is_module(t: &str, m: &str) -> bool {
    t == format!("\\{m}")
        || (t.starts_with("$paramod") && (t.ends_with(&format!("\\{m}")) || t.contains(&format!("\\{m}\\"))))
}

/// An RTLIL constant `N'BITS` of 0s and 1s: its bits.
fn const_bits(v: &str) -> Option<String> {
    let (n, bits) = v.split_once('\'')?;
    let n: usize = n.parse().ok()?;
    (bits.len() == n && !bits.is_empty() && bits.chars().all(|c| c == '0' || c == '1')).then(|| bits.to_string())
}

/// Decides, from yosys's dump of the candidate cells and the flattened netlist's wires, which
/// instances are abstracted (`width`: the format's width).
pub fn plan(abs: &[Abstraction], dump: &str, wire_width: &dyn Fn(&str) -> Option<u32>, width: u32) -> Plan {
    let mut p = Plan { abstractions: abs.to_vec(), ..Plan::default() };
    let cells = cells(dump);
    for (t, name, conns) in &cells {
        let Some(ai) = abs.iter().position(|a| is_module(t, &a.module)) else { continue };
        let mut why = None;
        if cells.iter().filter(|c| &c.1 == name).count() > 1 {
            why = Some("its name is not unique among the cells (a cell of a submodule?)".to_string());
        }
        for port in ["a", "b", "y"] {
            let wire = format!("{name}.{port}");
            if why.is_none() && wire_width(&wire) != Some(width) {
                why = Some(format!("no {width}-bit wire {wire} in the flattened netlist (not a cell of the top module, or port {port} missing)"));
            }
        }
        let mut consts = Vec::new();
        for (port, value) in conns {
            if ["a", "b", "y"].contains(&port.as_str()) {
                continue;
            }
            match const_bits(value) {
                Some(bits) => consts.push((port.clone(), bits)),
                None => {
                    why.get_or_insert(format!("port {port} is not tied to a constant ({value})"));
                }
            }
        }
        consts.sort();
        let sub = abs[ai].op == Op::Add && consts.iter().any(|(k, v)| k == "sub" && v == "1");
        if let Some(why) = why {
            p.concrete.push((name.clone(), why));
            continue;
        }
        let g = match p.groups.iter().position(|g| g.abs == ai && &g.cell_type == t && g.consts == consts) {
            Some(g) => g,
            None => {
                p.groups.push(Group { abs: ai, cell_type: t.clone(), consts, instances: Vec::new() });
                p.groups.len() - 1
            }
        };
        p.groups[g].instances.push(name.clone());
        p.instances.push(Instance { name: name.clone(), abs: ai, group: g, sub });
    }
    p.instances.sort_by(|a, b| a.name.cmp(&b.name));
    p
}

/// The `--abstract` modules no cell of the DUT instantiates (a misspelt name).
pub fn unmatched(abs: &[Abstraction], dump: &str) -> Vec<String> {
    let cells = cells(dump);
    abs.iter().filter(|a| !cells.iter().any(|c| is_module(&c.0, &a.module))).map(|a| a.module.clone()).collect()
}

/// A dumped cell: type, name, connections (port, value).
type Cell = (String, String, Vec<(String, String)>);

/// The cells of yosys's `dump`.
fn cells(dump: &str) -> Vec<Cell> {
    let mut cells: Vec<Cell> = Vec::new();
    for line in dump.lines() {
        let w: Vec<&str> = line.split_whitespace().collect();
        match w.as_slice() {
            ["cell", t, n] => cells.push((t.to_string(), n.trim_start_matches('\\').to_string(), Vec::new())),
            ["connect", port, value @ ..] => {
                if let Some(c) = cells.last_mut() {
                    c.2.push((port.trim_start_matches('\\').to_string(), value.join(" ")));
                }
            }
            _ => {}
        }
    }
    cells
}

/// The IEEE operation an instance is assumed to compute: the value (a FloatingPoint term) of
/// `a`, `b`.
fn op_term(op: Op, sub: bool, a: &str, b: &str) -> String {
    let f = match (op, sub) {
        (Op::Mul, _) => "fp.mul",
        (Op::Add, false) => "fp.add",
        (Op::Add, true) => "fp.sub",
    };
    format!("({f} RNE (rp_fp {a}) (rp_fp {b}))")
}

/// The assumption that `y` is the operation on `a`, `b` (bit-vector terms).
pub fn assume(op: Op, sub: bool, a: &str, b: &str, y: &str) -> String {
    format!("(rp_res {y} {} {a} {b})", op_term(op, sub, a, b))
}

impl Plan {
    /// The instance's operation.
    pub fn op(&self, i: &Instance) -> Op {
        self.abstractions[i.abs].op
    }

    /// A group's statement in words, e.g. `raypipe_hf_mul (rm=000): y = a × b`.
    pub fn statement(&self, g: &Group) -> String {
        let a = &self.abstractions[g.abs];
        let consts: Vec<String> = g.consts.iter().map(|(k, v)| format!("{k}={v}")).collect();
        let sub = g.consts.iter().any(|(k, v)| k == "sub" && v == "1");
        let op = match (a.op, sub) {
            (Op::Mul, _) => "a × b",
            (Op::Add, false) => "a + b",
            (Op::Add, true) => "a − b",
        };
        let tied = if consts.is_empty() { String::new() } else { format!(" ({})", consts.join(", ")) };
        format!("{}{tied}: y = {op}, rounded to nearest-even", a.module)
    }

    /// The yosys lines (after the previous row is cut) that list, in `file`, the wires feeding
    /// the registers `next` (the cone stops at the cut).
    pub fn cone_script(next: &[&str], file: &str) -> String {
        let mut s = String::from("select -set rp_cone");
        for (i, n) in next.iter().enumerate() {
            let _ = write!(s, " w:{n}");
            if i > 0 {
                s += " %u";
            }
        }
        let _ = write!(s, " %ci*\ntee -q -o {file} select -list @rp_cone\n");
        s
    }

    /// The instances with a wire in yosys's listing of a cone (`module/wire` per line; an
    /// instance's port wires are aliases of the signals they connect, so its inner wires tell).
    pub fn in_cone(&self, listing: &str) -> Vec<usize> {
        let wires: std::collections::HashSet<&str> =
            listing.lines().filter_map(|l| l.split_once('/').map(|x| x.1.trim())).collect();
        (0..self.instances.len())
            .filter(|&k| {
                let pre = format!("{}.", self.instances[k].name);
                wires.iter().any(|w| w.starts_with(&pre))
            })
            .collect()
    }

    /// The yosys lines of a step for the instances `ks` (those feeding its next row): their
    /// `a`, `b`, `y` kept, their `y` cut.
    pub fn step_script(&self, ks: &[usize]) -> String {
        let mut s = String::new();
        for &k in ks {
            let n = &self.instances[k].name;
            let _ = writeln!(s, "setattr -set keep 1 w:{n}.a w:{n}.b w:{n}.y\ncutpoint w:{n}.y");
        }
        s
    }

    /// The abstracted instances present in a step's SMT (`module`, `text`): indices into
    /// `instances`.
    pub fn present(&self, module: &str, text: &str) -> Vec<usize> {
        let f = |i: &Instance, p: &str| format!("|{module}_n {}.{p}|", i.name);
        (0..self.instances.len())
            .filter(|&k| ["a", "b", "y"].iter().all(|p| text.contains(&f(&self.instances[k], p))))
            .collect()
    }

    /// The assumptions for the instances `present` at the states `states`.
    pub fn assumptions(&self, module: &str, present: &[usize], states: &[String]) -> String {
        let mut s = String::new();
        for &k in present {
            let i = &self.instances[k];
            let _ = writeln!(s, "; {} abstracted: {}", i.name, self.statement(&self.groups[i.group]));
            for st in states {
                let t = |p: &str| format!("(|{module}_n {}.{p}| {st})", i.name);
                let _ = writeln!(s, "(assert {})", assume(self.op(i), i.sub, &t("a"), &t("b"), &t("y")));
            }
        }
        s
    }

    /// Leaves group `g`'s instances concrete (its justification failed: `why`).
    pub fn drop_group(&mut self, g: usize, why: &str) {
        let (gone, kept): (Vec<Instance>, Vec<Instance>) = self.instances.drain(..).partition(|i| i.group == g);
        self.instances = kept;
        self.concrete.extend(gone.into_iter().map(|i| (i.name, why.to_string())));
    }
}

/// A group's justification query: the module elaborated alone (yosys), its constant ports set,
/// `y` ≠ the operation asserted. Returns the query and the terms to read back (a, b, the
/// module's y, the operation's y).
pub fn justification(
    p: &Plan,
    g: &Group,
    d: &Dut,
    m: &Model,
    work: &Path,
    tag: &str,
) -> Result<(String, Vec<(String, String)>), String> {
    let s = read_script(d, &d.top, &[], &format!("hierarchy -top {}\n", g.cell_type))?;
    let text = write_smt2(s, work, tag, tag)?;
    let module = top_module(&text)?;
    let n = |p: &str| format!("(|{module}_n {p}| rp_s0)");
    let mut q = String::new();
    let _ = writeln!(q, "(set-logic QF_BVFP)");
    q += &m.float.prelude();
    let _ = writeln!(q, "; ---- {} alone, as yosys wrote it", p.abstractions[g.abs].module);
    push_script(&mut q, &text);
    let _ = writeln!(q, "(declare-const rp_s0 |{module}_s|)\n(assert (|{module}_h| rp_s0))");
    for (port, bits) in &g.consts {
        if !text.contains(&format!("|{module}_n {port}|")) {
            continue; // a port the module does not read
        }
        if bits.len() == 1 {
            let _ = writeln!(q, "(assert (= {} {}))", n(port), if bits == "1" { "true" } else { "false" });
        } else {
            let _ = writeln!(q, "(assert (= {} #b{bits}))", n(port));
        }
    }
    let w = m.float.width();
    let sub = g.consts.iter().any(|(k, v)| k == "sub" && v == "1");
    let _ = writeln!(q, "(declare-const rp_op (_ BitVec {w}))");
    let _ = writeln!(q, "(assert {})", assume(p.abstractions[g.abs].op, sub, &n("a"), &n("b"), "rp_op"));
    let _ = writeln!(q, "(assert (not (= {} rp_op)))", n("y"));
    let values = vec![
        ("a".into(), n("a")),
        ("b".into(), n("b")),
        ("module y".into(), n("y")),
        ("operation y".into(), "rp_op".into()),
    ];
    Ok((q, values))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn specs_parse_and_bad_ones_are_refused() {
        assert_eq!(parse("raypipe_hf_mul=mul").unwrap(), Abstraction { module: "raypipe_hf_mul".into(), op: Op::Mul });
        for bad in ["", "m", "=mul", "m=div", "a b=mul", "m=", "m.x=add"] {
            assert!(parse(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn cells_tied_to_constants_are_abstracted_and_grouped() {
        let dump = "\
  cell $paramod$abc\\hf_mul \\u_one
    connect \\y \\t1
    connect \\rm 3'000
    connect \\b \\r [15:0]
    connect \\a \\r [31:16]
  end
  cell $paramod$abc\\hf_mul \\u_rup
    connect \\y \\t2
    connect \\rm 3'011
    connect \\b \\r [15:0]
    connect \\a \\r [31:16]
  end
  cell $paramod$abc\\hf_mul \\u_var
    connect \\y \\t3
    connect \\rm \\mode
    connect \\b \\r [15:0]
    connect \\a \\r [31:16]
  end
  cell \\hf_mulx \\u_other
    connect \\y \\t4
  end
  cell \\hf_mul \\u_gone
    connect \\y \\t6
  end
  cell $paramod$abc\\hf_add \\u_sub
    connect \\y \\t5
    connect \\sub 1'1
    connect \\b \\r [15:0]
    connect \\a \\r [31:16]
  end
";
        let abs = [parse("hf_mul=mul").unwrap(), parse("hf_add=add").unwrap()];
        let widths = |w: &str| (!w.starts_with("u_gone.")).then_some(16);
        let p = plan(&abs, dump, &widths, 16);
        let names: Vec<&str> = p.instances.iter().map(|i| i.name.as_str()).collect();
        assert_eq!(names, ["u_one", "u_rup", "u_sub"]);
        assert!(p.instances[2].sub && !p.instances[0].sub);
        // one group per module and constants: the rounding mode 011 is its own
        assert_eq!(p.groups.len(), 3);
        assert_eq!(p.groups[0].consts, [("rm".to_string(), "000".to_string())]);
        assert_eq!(p.groups[1].consts, [("rm".to_string(), "011".to_string())]);
        let why: Vec<&str> = p.concrete.iter().map(|c| c.0.as_str()).collect();
        assert_eq!(why, ["u_var", "u_gone"]);
        assert!(p.concrete[0].1.contains("not tied to a constant"));
        assert!(p.concrete[1].1.contains("no 16-bit wire u_gone.a"));
        assert_eq!(p.statement(&p.groups[2]), "hf_add (sub=1): y = a − b, rounded to nearest-even");
        let typo = [parse("hf_mul=mul").unwrap(), parse("hf_mull=mul").unwrap()];
        assert_eq!(unmatched(&typo, dump), ["hf_mull"]);
    }
}
