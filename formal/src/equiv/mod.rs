//! Formal equivalence of a DUT with the model: yosys reads the DUT's Verilog and writes it as
//! SMT-LIB 2 (`write_smt2 -stbv`); each DUT output named like a model signal is proven equal to
//! that signal for every input (one query per output: the DUT's inputs tied to the model's,
//! the output asserted different; `unsat` is PROVEN).
//!
//! This module proves combinational DUTs (a DUT with registers is refused here); a pipelined
//! DUT is proven stage by stage from its row registers ([`stages`]). DUT input ports must be model inputs of the
//! same width (`ox`, `a`, ...); model inputs the DUT lacks stay free; DUT outputs that are not
//! model signals are listed and ignored.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

use crate::smt::Model;
use crate::solver::{check, Verdict};

pub mod abstraction;
pub mod stages;

/// The DUT: sources, top module and how to elaborate it.
#[derive(Clone, Debug, Default)]
pub struct Dut {
    /// Verilog source files (`.sv` read with `-sv`).
    pub rtl: Vec<PathBuf>,
    /// Include directories.
    pub incdirs: Vec<PathBuf>,
    /// Preprocessor defines (`NAME` or `NAME=VALUE`).
    pub defines: Vec<String>,
    /// The top module.
    pub top: String,
    /// Top-module parameters (name, value).
    pub params: Vec<(String, String)>,
}

/// A port of the DUT as yosys reports it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Port {
    /// Port name.
    pub name: String,
    /// Width in bits.
    pub width: u32,
}

/// The DUT as SMT-LIB: yosys's script, its module, inputs and outputs.
#[derive(Clone, Debug)]
pub struct DutSmt {
    /// The script yosys wrote.
    pub text: String,
    /// The top module's name in the script.
    pub module: String,
    /// Input ports.
    pub inputs: Vec<Port>,
    /// Output ports.
    pub outputs: Vec<Port>,
    /// Registers (a combinational DUT has none).
    pub registers: usize,
    /// The yosys version line.
    pub yosys: String,
}

/// Runs yosys on the DUT; `work` is a scratch directory. With parameters, the DUT is read
/// twice: once with `hierarchy -chparam` for its ports, then through a generated wrapper that
/// sets them as Verilog integer literals (yosys 0.23's `-chparam` values are unsigned, which
/// turns the signed comparisons of parameter-derived constants in HardFloat unsigned — a
/// multiplier read that way differs from Icarus on tiny products).
pub fn dut_smt(d: &Dut, work: &Path) -> Result<DutSmt, String> {
    let first = yosys_smt(d, &d.top, &[], work)?;
    if d.params.is_empty() {
        return Ok(first);
    }
    let wrap = work.join("raypipe_equiv_wrap.v");
    std::fs::write(&wrap, wrapper(d, &first)).map_err(|e| format!("{}: {e}", wrap.display()))?;
    let mut second = yosys_smt(d, WRAP, &[wrap], work)?;
    if second.inputs != first.inputs || second.outputs != first.outputs {
        return Err("internal: the parameter wrapper changed the DUT's ports".into());
    }
    second.module = WRAP.to_string();
    Ok(second)
}

/// The wrapper module's name.
pub const WRAP: &str = "raypipe_equiv_wrap";

/// A module that instantiates the DUT with its parameters and passes every port through.
fn wrapper(d: &Dut, ports: &DutSmt) -> String {
    let mut s = format!("module {WRAP} (");
    let names: Vec<&str> = ports.inputs.iter().chain(ports.outputs.iter()).map(|p| p.name.as_str()).collect();
    s += &names.join(", ");
    s += ");
";
    for p in &ports.inputs {
        let _ = writeln!(s, "  input [{}:0] {};", p.width - 1, p.name);
    }
    for p in &ports.outputs {
        let _ = writeln!(s, "  output [{}:0] {};", p.width - 1, p.name);
    }
    let params: Vec<String> = d.params.iter().map(|(k, v)| format!(".{k}({v})")).collect();
    let conns: Vec<String> = names.iter().map(|n| format!(".{n}({n})")).collect();
    let _ = writeln!(
        s,
        "  {} #({}) dut ({});
endmodule",
        d.top,
        params.join(", "),
        conns.join(", ")
    );
    s
}

/// The yosys script that reads the sources (and `extra` files) and elaborates `top`: flattened,
/// processes and flip-flops in the forms `write_smt2` and `write_rtlil` take.
/// `before_proc`: yosys lines run after `hierarchy`, before `proc`.
pub(crate) fn read_script(d: &Dut, top: &str, extra: &[PathBuf], before_proc: &str) -> Result<String, String> {
    for f in &d.rtl {
        if !f.is_file() {
            return Err(format!("--rtl {}: no such file", f.display()));
        }
    }
    if d.rtl.is_empty() {
        return Err("no --rtl source given".into());
    }
    let ok_name = |s: &str| !s.is_empty() && s.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '$');
    if !ok_name(&d.top) {
        return Err(format!("--top '{}' is not a module name", d.top));
    }
    let mut script = String::new();
    let mut read = String::from("read_verilog");
    for i in &d.incdirs {
        let s = i.display().to_string();
        if s.contains(char::is_whitespace) || s.contains('"') {
            return Err(format!("--incdir {s}: a directory without spaces or quotes"));
        }
        let _ = write!(read, " -I{s}");
    }
    for def in &d.defines {
        if !def.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '=') {
            return Err(format!("--define '{def}': a define is NAME or NAME=VALUE"));
        }
        let _ = write!(read, " -D{def}");
    }
    for f in d.rtl.iter().chain(extra) {
        let sv = if f.extension().is_some_and(|e| e == "sv") { " -sv" } else { "" };
        let _ = writeln!(script, "{}{sv} {}", read, quote(f));
    }
    let mut hier = format!("hierarchy -check -top {top}");
    if extra.is_empty() {
        for (k, v) in &d.params {
            if !ok_name(k) || v.is_empty() || !v.chars().all(|c| c.is_ascii_digit()) {
                return Err(format!("--param {k}={v}: NAME=VALUE with a decimal integer value"));
            }
            let _ = write!(hier, " -chparam {k} {v}");
        }
    }
    // registers as plain flip-flops without reset or enable logic (what write_smt2 reads):
    // an asynchronous reset becomes synchronous (async2sync), enables and synchronous resets
    // become multiplexers (dffunmap)
    let _ = writeln!(
        script,
        "{hier}\n{before_proc}proc\nflatten\nsetundef -undriven -zero\nopt -fast\nasync2sync\ndffunmap"
    );
    Ok(script)
}

/// Runs a yosys script in `work` (as `name`.ys).
pub(crate) fn run_yosys(script: &str, work: &Path, name: &str) -> Result<(), String> {
    let ys = work.join(format!("{name}.ys"));
    std::fs::write(&ys, script).map_err(|e| format!("{}: {e}", ys.display()))?;
    let run = Command::new("yosys")
        .arg("-q")
        .arg("-s")
        .arg(&ys)
        .output()
        .map_err(|e| format!("cannot run yosys ({e}): install it (Debian: apt-get install yosys)"))?;
    if !run.status.success() {
        let err = String::from_utf8_lossy(&run.stderr);
        let out = String::from_utf8_lossy(&run.stdout);
        return Err(format!("yosys could not read the DUT:\n{}{}", out.trim_end(), err.trim_end()));
    }
    Ok(())
}

/// A path quoted for a yosys script.
pub(crate) fn quote(p: &Path) -> String {
    format!("\"{}\"", p.display())
}

/// One yosys run: the sources (and `extra` files) elaborated under `top`, written as SMT-LIB.
fn yosys_smt(d: &Dut, top: &str, extra: &[PathBuf], work: &Path) -> Result<DutSmt, String> {
    let text = write_smt2(read_script(d, top, extra, "")?, work, "equiv", "dut")?;
    parse(&text, top)
}

/// Runs `script` with `write_smt2 -stbv` appended (to `work/out.smt2`; the script as
/// `work/tag.ys`) and returns what yosys wrote.
pub(crate) fn write_smt2(mut script: String, work: &Path, tag: &str, out: &str) -> Result<String, String> {
    let out = work.join(format!("{out}.smt2"));
    let _ = writeln!(script, "write_smt2 -stbv {}", quote(&out));
    run_yosys(&script, work, tag)?;
    std::fs::read_to_string(&out).map_err(|e| format!("{}: {e}", out.display()))
}

/// The top module's name in yosys's SMT-LIB output.
pub(crate) fn top_module(text: &str) -> Result<String, String> {
    Ok(text
        .lines()
        .find_map(|l| l.strip_prefix("; yosys-smt2-topmod "))
        .ok_or("yosys wrote no top module")?
        .split_whitespace()
        .next()
        .unwrap_or_default()
        .to_string())
}

/// A scratch file's path as yosys's `tee -o` takes it (as is: no quotes, so no space).
pub(crate) fn bare_path(p: &Path) -> Result<String, String> {
    let f = p.display().to_string();
    if f.contains(|c: char| c.is_whitespace() || c == '"') {
        return Err(format!("the scratch directory {f} has a space or a quote in its path: set TMPDIR"));
    }
    Ok(f)
}

/// Reads the ports and registers of `top` from yosys's comments in `text`.
pub fn parse(text: &str, top: &str) -> Result<DutSmt, String> {
    let mut module = None;
    let (mut inputs, mut outputs, mut registers) = (Vec::new(), Vec::new(), 0);
    let mut current = String::new();
    for line in text.lines() {
        let Some(rest) = line.strip_prefix("; yosys-smt2-") else { continue };
        let mut w = rest.split_whitespace();
        match w.next() {
            Some("module") => current = w.next().unwrap_or_default().to_string(),
            Some(kind @ ("input" | "output")) if current == top => {
                let name = w.next().unwrap_or_default().to_string();
                let width = w.next().and_then(|x| x.parse().ok()).ok_or(format!("yosys port line '{line}'"))?;
                let p = Port { name, width };
                if kind == "input" {
                    inputs.push(p)
                } else {
                    outputs.push(p)
                }
                module = Some(current.clone());
            }
            Some("register") if current == top => registers += 1,
            _ => {}
        }
    }
    let module = module.ok_or(format!("yosys wrote no ports for module {top}"))?;
    let yosys = text.lines().next().unwrap_or_default().trim_start_matches("; ").to_string();
    Ok(DutSmt { text: text.to_string(), module, inputs, outputs, registers, yosys })
}

/// One output's verdict.
#[derive(Clone, Debug)]
pub struct OutputProof {
    /// The output (and model signal) name.
    pub name: String,
    /// The solver's verdict (`unsat`: equal for every input).
    pub verdict: Verdict,
    /// A counterexample: the DUT's input values, the DUT's and the model's output values.
    pub witness: Option<Witness>,
}

/// A counterexample of one output.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Witness {
    /// DUT inputs (name, value).
    pub inputs: Vec<(String, u64)>,
    /// The DUT's output value.
    pub dut: u64,
    /// The model's signal value.
    pub model: u64,
}

/// How DUT and model fit: the outputs compared, the outputs ignored.
#[derive(Clone, Debug)]
pub struct Plan {
    /// Outputs compared with the model signal of the same name.
    pub compared: Vec<String>,
    /// DUT outputs that are not model signals.
    pub ignored: Vec<String>,
}

/// Checks the DUT's ports against the model; the outputs to compare.
pub fn plan(m: &Model, d: &DutSmt) -> Result<Plan, String> {
    if d.registers > 0 {
        return Err(format!(
            "{} has {} registers: without --stage-row a DUT must be combinational (a pipelined DUT: name its row registers with --set DIR --stage-row, docs/proofs.md)",
            d.module, d.registers
        ));
    }
    for p in &d.inputs {
        let Some(w) = input_width(m, &p.name) else {
            return Err(format!("DUT input '{}' is not a model input (model inputs: {})", p.name, m.inputs.join(", ")));
        };
        if w != p.width {
            return Err(format!("DUT input '{}' has {} bits, the model's has {w}", p.name, p.width));
        }
    }
    let mut compared = Vec::new();
    let mut ignored = Vec::new();
    for p in &d.outputs {
        match m.signals.iter().find(|s| s.0 == p.name) {
            Some(&(_, flag)) => {
                let w = if flag { 1 } else { m.width };
                if w != p.width {
                    return Err(format!("DUT output '{}' has {} bits, the model's signal has {w}", p.name, p.width));
                }
                compared.push(p.name.clone());
            }
            None => ignored.push(p.name.clone()),
        }
    }
    if compared.is_empty() {
        return Err(format!(
            "no DUT output is named like a model signal (model signals: {})",
            m.signals.iter().map(|s| s.0.as_str()).collect::<Vec<_>>().join(", ")
        ));
    }
    Ok(Plan { compared, ignored })
}

/// The width of model input `name` (its `in_NAME` declaration), if the model has it.
fn input_width(m: &Model, name: &str) -> Option<u32> {
    if !m.inputs.iter().any(|n| n == name) {
        return None;
    }
    let decl = format!("(declare-const in_{name} (_ BitVec ");
    let at = m.text.find(&decl)? + decl.len();
    m.text[at..].split(')').next()?.trim().parse().ok()
}

/// Appends yosys's SMT-LIB script to a query, without its `set-*` commands (the query sets
/// its own logic and options).
pub(crate) fn push_script(q: &mut String, yosys_text: &str) {
    for line in yosys_text.lines().filter(|l| !l.starts_with("(set-")) {
        q.push_str(line);
        q.push('\n');
    }
}

/// The query for one output: satisfiable exactly when some input makes it differ.
pub fn query(m: &Model, d: &DutSmt, output: &str) -> String {
    let md = &d.module;
    let mut q = m.text.clone();
    q += "\n; ---- the DUT, as yosys wrote it\n";
    push_script(&mut q, &d.text);
    let _ = writeln!(q, "; ---- miter: the DUT's inputs are the model's; output {output} differs");
    let _ = writeln!(q, "(declare-const rp_dut |{md}_s|)");
    let _ = writeln!(q, "(assert (|{md}_h| rp_dut))");
    let _ = writeln!(q, "(assert (|{md}_u| rp_dut))");
    for p in &d.inputs {
        let _ = writeln!(q, "(assert (= (|{md}_n {}| rp_dut) in_{}))", p.name, p.name);
    }
    let _ = writeln!(q, "(assert (not (= (|{md}_n {output}| rp_dut) {output})))");
    q
}

/// Proves every compared output; `solver` and `timeout_s` as for [`check`].
pub fn prove(m: &Model, d: &DutSmt, plan: &Plan, solver: &str, timeout_s: f64) -> Result<Vec<OutputProof>, String> {
    let mut out = Vec::new();
    for name in &plan.compared {
        let q = query(m, d, name);
        let mut values: Vec<String> = d.inputs.iter().map(|p| format!("in_{}", p.name)).collect();
        values.push(format!("(|{}_n {name}| rp_dut)", d.module));
        values.push(name.clone());
        let v = check(&q, solver, timeout_s, &values)?;
        let witness = (v.result == "sat").then(|| Witness {
            inputs: d.inputs.iter().map(|p| (p.name.clone(), v.value(&format!("in_{}", p.name)))).collect(),
            dut: v.value(&format!("(|{}_n {name}| rp_dut)", d.module)),
            model: v.value(name),
        });
        out.push(OutputProof { name: name.clone(), verdict: v, witness });
    }
    Ok(out)
}

/// A Verilog testbench that drives the DUT with a witness's inputs and prints every output
/// (`name=hex` lines), for replaying a counterexample in a simulator.
pub fn replay_bench(d: &Dut, ds: &DutSmt, w: &Witness) -> String {
    let mut s = String::from("module raypipe_equiv_replay;\n");
    for p in &ds.inputs {
        let v = w.inputs.iter().find(|(n, _)| *n == p.name).map_or(0, |x| x.1);
        let _ = writeln!(s, "  reg [{}:0] {} = {}'h{v:x};", p.width - 1, p.name, p.width);
    }
    for p in &ds.outputs {
        let _ = writeln!(s, "  wire [{}:0] {};", p.width - 1, p.name);
    }
    let params: Vec<String> = d.params.iter().map(|(k, v)| format!(".{k}({v})")).collect();
    let ports: Vec<String> =
        ds.inputs.iter().chain(ds.outputs.iter()).map(|p| format!(".{}({})", p.name, p.name)).collect();
    let _ = writeln!(
        s,
        "  {} {}dut ({});",
        d.top,
        if params.is_empty() { String::new() } else { format!("#({}) ", params.join(", ")) },
        ports.join(", ")
    );
    s += "  initial begin\n    #1;\n";
    for p in &ds.outputs {
        let _ = writeln!(s, "    $display(\"{}=%h\", {});", p.name, p.name);
    }
    s += "    $finish;\n  end\nendmodule\n";
    s
}

/// Replays a witness in Icarus Verilog: the DUT's output values by name.
pub fn replay_icarus(d: &Dut, ds: &DutSmt, w: &Witness, work: &Path) -> Result<Vec<(String, u64)>, String> {
    let tb = work.join("replay.v");
    std::fs::write(&tb, replay_bench(d, ds, w)).map_err(|e| format!("{}: {e}", tb.display()))?;
    let vvp = work.join("replay.vvp");
    let mut c = Command::new("iverilog");
    c.arg("-g2012").arg("-o").arg(&vvp).arg("-s").arg("raypipe_equiv_replay");
    for i in &d.incdirs {
        c.arg(format!("-I{}", i.display()));
    }
    for def in &d.defines {
        c.arg(format!("-D{def}"));
    }
    c.args(&d.rtl).arg(&tb);
    let o = c.output().map_err(|e| format!("cannot run iverilog ({e})"))?;
    if !o.status.success() {
        return Err(format!("iverilog: {}", String::from_utf8_lossy(&o.stderr).trim_end()));
    }
    let o = Command::new("vvp").arg("-n").arg(&vvp).output().map_err(|e| format!("cannot run vvp ({e})"))?;
    let text = String::from_utf8_lossy(&o.stdout);
    let mut vals = Vec::new();
    for line in text.lines() {
        if let Some((n, v)) = line.split_once('=') {
            if let Ok(x) = u64::from_str_radix(v.trim(), 16) {
                vals.push((n.trim().to_string(), x));
            }
        }
    }
    Ok(vals)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ports_and_registers_are_read_from_yosys_comments() {
        let text = "; SMT-LIBv2 description generated by Yosys 0.23\n; yosys-smt2-module sub\n; yosys-smt2-input q 4\n; yosys-smt2-module top\n; yosys-smt2-input a 16\n; yosys-smt2-output y 16\n; yosys-smt2-register r 3\n";
        let d = parse(text, "top").unwrap();
        assert_eq!(d.module, "top");
        assert_eq!(d.inputs, [Port { name: "a".into(), width: 16 }]);
        assert_eq!(d.outputs, [Port { name: "y".into(), width: 16 }]);
        assert_eq!(d.registers, 1);
        assert!(parse(text, "other").is_err());
    }
}
