//! Stage-by-stage equivalence of a pipelined DUT with the model, from the registers that hold
//! its rows.
//!
//! The DUT names, for every stage of the stage table (or run of stages), the registers that
//! hold the row after it: an inputs part laid out like the set's `in_row` and a stage-signal
//! part laid out like its `stg_row` ([`Row`]). Each row is proven from the previous one:
//!
//! * **One edge** (the row registered from the previous row's registers through
//!   combinational logic): one transition of the DUT from a free state. The previous row's
//!   registers are cut (free values; yosys `cutpoint`), the model's inputs and earlier signals
//!   are tied to them, and each signal of the stage is proven equal to its field of the next
//!   row one edge later. A free previous row includes unreachable ones, so this proves more
//!   than the pipeline needs (and a counterexample may start from a row no input produces).
//! * **Several edges** (a sequential operation inside the stage, e.g. a bank of iterative
//!   dividers): bounded model checking from reset. Cycle 0 has `rst_n` low, later cycles high;
//!   the checked transaction enters (`in_valid` high) at a free cycle c of 1..=P (P = edges −
//!   1 by default, so every phase of a round-robin bank of up to P units is covered), any other
//!   cycle may carry another transaction (`in_valid` and data free); the previous row's
//!   registers are cut and tied to the model at the cycle the transaction reaches them, and the
//!   next row is compared `edges` edges later.
//! * **Carried fields**: in each step the inputs (as the model reads them) and the earlier
//!   stages' signals of the next row equal the previous row's.
//! * **Ports**: `out_row`'s fields equal the same-named signals of the last row and `stg_row`
//!   equals its stage-signal register.
//!
//! By induction along the pipeline, a transaction's `out_row` and `stg_row` are the model's.
//! Not proven here: that `out_valid` rises with the transaction's row (the HDL kit's
//! simulation checks the latency), and a DUT whose rows are not registers (a stage without a
//! row register can be merged into the next: a row may follow several stages).

use std::fmt::Write as _;
use std::path::Path;

use super::abstraction::{self, Abstraction, Plan};
use super::{bare_path, push_script, quote, read_script, run_yosys, top_module, write_smt2, Dut};
use crate::smt::{emit_stage_range, Model, Request};
use crate::solver::{check, Verdict};

/// A field's place in a row (bits `lsb + width - 1 ..= lsb`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FieldPos {
    /// Field name (a model input, signal or output).
    pub name: String,
    /// Least significant bit.
    pub lsb: u32,
    /// Width.
    pub width: u32,
}

/// The set's row layouts (from its manifest).
#[derive(Clone, Debug, Default)]
pub struct Layout {
    /// `in_row` fields.
    pub inputs: Vec<FieldPos>,
    /// `in_row` width.
    pub in_w: u32,
    /// `stg_row` fields.
    pub stages: Vec<FieldPos>,
    /// `stg_row` width.
    pub stg_w: u32,
    /// `out_row` fields.
    pub outputs: Vec<FieldPos>,
    /// `out_row` width.
    pub out_w: u32,
}

/// Where the DUT holds one row.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Row {
    /// The table stage after which the row is registered (`None`: the input register, which
    /// holds `in_row` as received).
    pub after: Option<u8>,
    /// The register of the inputs part (`in_row` layout), if the DUT keeps one.
    pub inputs: Option<String>,
    /// The register of the stage-signal part (`stg_row` layout), if the DUT keeps one.
    pub stages: Option<String>,
    /// Clock edges from the previous row (the input register: from the `in_row` port).
    pub edges: u32,
}

/// Parses `in=REG` (the input register) or `K=[IN]:[STG][@EDGES]` (the row after stage K).
pub fn parse_row(spec: &str) -> Result<Row, String> {
    let bad = || format!("--stage-row '{spec}': in=REG or K=[IN_REG]:[STG_REG][@EDGES]");
    let (k, rest) = spec.split_once('=').ok_or_else(bad)?;
    let (regs, edges) = match rest.split_once('@') {
        Some((r, e)) => (r, e.parse::<u32>().ok().filter(|&e| (1..=200).contains(&e)).ok_or_else(bad)?),
        None => (rest, 1),
    };
    let name = |s: &str| -> Result<Option<String>, String> {
        if s.is_empty() {
            return Ok(None);
        }
        if !s.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '.' || c == '[' || c == ']') {
            return Err(bad());
        }
        Ok(Some(s.to_string()))
    };
    if k == "in" {
        let inputs = name(regs)?.ok_or_else(bad)?;
        return Ok(Row { after: None, inputs: Some(inputs), stages: None, edges });
    }
    let after = Some(k.parse::<u8>().map_err(|_| bad())?);
    let (i, s) = regs.split_once(':').ok_or_else(bad)?;
    let (inputs, stages) = (name(i)?, name(s)?);
    if stages.is_none() {
        return Err(format!("--stage-row '{spec}': the row after a stage needs its stage-signal register"));
    }
    Ok(Row { after, inputs, stages, edges })
}

/// What one query proves.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Goal {
    /// A stage signal of the row (its name).
    Signal(String),
    /// The carried fields of the row.
    Carried,
    /// `out_row` and `stg_row` from the last row.
    Ports,
    /// An abstracted module alone equals its operation (the group's index, the statement).
    Module(usize, String),
    /// `out_valid` rises exactly with the transactions' rows: the latency (edges) and the
    /// entry cycles checked.
    Latency(u32, u32),
}

/// One query's verdict.
#[derive(Clone, Debug)]
pub struct StepProof {
    /// The stages the step computes (`None`: the input register or the ports).
    pub stages: Option<(u8, u8)>,
    /// How: `one edge`, `bmc N edges`, `ports`.
    pub method: String,
    /// What it proves.
    pub goal: Goal,
    /// The solver's verdict.
    pub verdict: Verdict,
    /// Values read back on a counterexample (the model's inputs, the DUT's and the model's
    /// value of the signal, the injection cycle).
    pub witness: Vec<(String, u64)>,
}

/// A prepared DUT: its elaborated netlist and the widths of its named wires.
pub struct Netlist {
    /// The RTLIL file yosys wrote.
    pub rtlil: std::path::PathBuf,
    /// Wire widths by name.
    pub wires: Vec<(String, u32)>,
    /// The DUT it was elaborated from.
    pub dut: Dut,
    /// The `--abstract` options.
    pub abstractions: Vec<Abstraction>,
    /// yosys's dump of the cells of the abstracted modules (before flattening).
    pub cells: String,
}

/// Elaborates the DUT once (yosys), for the per-step queries.
pub fn elaborate(d: &Dut, abs: &[Abstraction], work: &Path) -> Result<Netlist, String> {
    if !d.params.is_empty() {
        return Err("a pipelined DUT takes its parameters from the set's package here (no --param)".into());
    }
    let cells_file = work.join("cells.txt");
    let mut script = read_script(d, &d.top, &[], &abstraction::list_cells(abs, &cells_file)?)?;
    let il = work.join("base.il");
    let _ = writeln!(script, "write_rtlil {}", quote(&il));
    run_yosys(&script, work, "base")?;
    let text = std::fs::read_to_string(&il).map_err(|e| format!("{}: {e}", il.display()))?;
    let mut wires = Vec::new();
    for line in text.lines() {
        let w: Vec<&str> = line.split_whitespace().collect();
        // "wire width N [attributes...] \name" inside the top module
        // (no width: one bit)
        if w.first() == Some(&"wire") {
            if let Some(name) = w.last().and_then(|n| n.strip_prefix('\\')) {
                let width =
                    w.iter().position(|x| *x == "width").and_then(|i| w.get(i + 1)).and_then(|x| x.parse().ok());
                wires.push((name.to_string(), width.unwrap_or(1)));
            }
        }
    }
    let cells = if abs.is_empty() {
        String::new()
    } else {
        std::fs::read_to_string(&cells_file).map_err(|e| format!("{}: {e}", cells_file.display()))?
    };
    Ok(Netlist { rtlil: il, wires, dut: d.clone(), abstractions: abs.to_vec(), cells })
}

impl Netlist {
    fn width(&self, name: &str) -> Option<u32> {
        self.wires.iter().find(|(n, _)| n == name).map(|x| x.1)
    }
}

/// Checks the rows against the netlist and the layout; the rows in pipeline order.
pub fn check_rows(rows: &[Row], n: &Netlist, lay: &Layout, model: &Model) -> Result<Vec<Row>, String> {
    for p in ["rst_n", "in_valid", "in_row", "out_row", "stg_row"] {
        if n.width(p).is_none() {
            return Err(format!("the DUT has no port {p} (the HDL kit's ports: clk, rst_n, in_valid, in_row, out_valid, out_row, stg_row)"));
        }
    }
    if n.width("in_row") != Some(lay.in_w)
        || n.width("stg_row") != Some(lay.stg_w)
        || n.width("out_row") != Some(lay.out_w)
    {
        return Err(format!(
            "the DUT's in_row/out_row/stg_row widths ({:?}/{:?}/{:?}) are not the set's ({}/{}/{})",
            n.width("in_row"),
            n.width("out_row"),
            n.width("stg_row"),
            lay.in_w,
            lay.out_w,
            lay.stg_w
        ));
    }
    let mut rows = rows.to_vec();
    rows.sort_by_key(|r| r.after.map_or(-1, i32::from));
    for w in rows.windows(2) {
        if w[0].after == w[1].after {
            return Err(format!("two --stage-row for {}", w[0].after.map_or("in".into(), |k| k.to_string())));
        }
    }
    for r in rows.iter_mut() {
        // an inputs register nothing reads is removed by yosys: the row has no inputs part
        if r.inputs.as_deref().is_some_and(|name| n.width(name).is_none()) && r.after.is_some() {
            r.inputs = None;
        }
        for (reg, want) in [(&r.inputs, lay.in_w), (&r.stages, lay.stg_w)] {
            if let Some(name) = reg {
                match n.width(name) {
                    Some(w) if w == want => {}
                    Some(w) => return Err(format!("register {name} has {w} bits; its row has {want}")),
                    None => return Err(format!("the DUT has no register {name} after elaboration")),
                }
            }
        }
    }
    let last_stage = *model.stages.iter().max().ok_or("the model has no stage")?;
    let first_stage = *model.stages.iter().min().unwrap_or(&0);
    let staged: Vec<u8> = rows.iter().filter_map(|r| r.after).collect();
    if staged.last() != Some(&last_stage) {
        return Err(format!("no --stage-row for the last stage ({last_stage}): the row the outputs come from"));
    }
    if staged.first().is_some_and(|&k| k < first_stage) {
        return Err(format!("--stage-row {}: the table's stages are {first_stage}..={last_stage}", staged[0]));
    }
    Ok(rows)
}

fn extract(term: &str, f: &FieldPos) -> String {
    format!("((_ extract {} {}) {term})", f.lsb + f.width - 1, f.lsb)
}

/// The model's value for a DUT field (flags: a 1-bit vector vs. a Bool).
fn as_model(bits: &str, flag: bool) -> String {
    if flag {
        format!("(= #b1 {bits})")
    } else {
        bits.to_string()
    }
}

struct Step<'a> {
    prev: Option<&'a Row>,
    next: &'a Row,
    lo: u8,
    hi: u8,
    /// Edges from the `in_valid` cycle to the previous row (0: the port).
    arrive: u32,
}

impl Step<'_> {
    fn bmc(&self) -> bool {
        self.next.edges > 1
    }
}

/// A step's DUT as SMT-LIB: the module's name, the script and, for a one-edge step, the next
/// value of each bit of the next row's registers as a function of the current state.
struct StepDut {
    module: String,
    text: String,
    /// (register, bit) → name of a `define-fun` from the state to the bit's next value (Bool).
    next_bits: Vec<((String, u32), String)>,
    /// The abstracted instances in the step (indices into the plan's instances).
    present: Vec<usize>,
}

/// The yosys run for one step: the netlist with the previous row's registers cut and
/// everything that does not feed the kept wires removed; for a one-edge step the flip-flops
/// are split into single bits, and the next value of each is read from the transition
/// relation (so a query on one field does not carry the logic of the others).
#[allow(clippy::too_many_arguments)]
fn step_smt(
    n: &Netlist,
    plan: &Plan,
    cut: &[&str],
    next: &[&str],
    keep: &[&str],
    ports: bool,
    bits: bool,
    work: &Path,
    tag: &str,
) -> Result<StepDut, String> {
    let mut s = format!("read_rtlil {}\n", quote(&n.rtlil));
    for c in cut {
        let _ = writeln!(s, "cutpoint w:{c}");
    }
    if !plan.instances.is_empty() && !next.is_empty() {
        // which abstracted instances feed the next row (one yosys run to list the cone)
        let list = work.join(format!("{tag}-cone.txt"));
        let f = bare_path(&list)?;
        run_yosys(&(s.clone() + &Plan::cone_script(next, &f)), work, &format!("{tag}-cone"))?;
        let listing = std::fs::read_to_string(&list).map_err(|e| format!("{f}: {e}"))?;
        s += &plan.step_script(&plan.in_cone(&listing));
    }
    let _ = writeln!(s, "setattr -set keep 1 {}", keep.iter().map(|k| format!("w:{k}")).collect::<Vec<_>>().join(" "));
    if !ports {
        s += "delete -output o:*\n";
    }
    s += "opt_clean\n";
    if bits {
        s += "simplemap t:$dff\nopt_clean\n";
    }
    let text = write_smt2(s, work, tag, tag)?;
    let module = top_module(&text)?;
    let mut body = format!("; ---- the DUT ({tag}), as yosys wrote it\n");
    push_script(&mut body, &text);
    let mut next_bits = Vec::new();
    if bits {
        // the transition relation's conjuncts: `(= NEXT(state) (|m#k| next_state)) ; cell \reg [bit]`
        let head = format!("(define-fun |{module}_t| ");
        let mut inside = false;
        for line in text.lines() {
            if line.starts_with(&head) {
                inside = true;
                continue;
            }
            if !inside {
                continue;
            }
            if line.starts_with("))") {
                break;
            }
            let Some((term, comment)) = line.trim().split_once(" ; ") else { continue };
            let Some(conj) = term.strip_prefix("(= ").and_then(|x| x.strip_suffix(" next_state))")) else { continue };
            let Some(at) = conj.rfind(" (|") else { continue };
            let lhs = &conj[..at];
            let mut w = comment.split_whitespace().skip(1);
            let (Some(reg), Some(bit)) = (w.next(), w.next()) else { continue };
            let (Some(reg), Some(bit)) =
                (reg.strip_prefix('\\'), bit.strip_prefix('[').and_then(|b| b.strip_suffix(']')))
            else {
                continue;
            };
            let Ok(bit) = bit.parse::<u32>() else { continue };
            let name = format!("rp_next!{}", next_bits.len());
            let _ = writeln!(body, "(define-fun {name} ((state |{module}_s|)) Bool {lhs})");
            next_bits.push(((reg.to_string(), bit), name));
        }
    }
    let present = plan.present(&module, &body);
    Ok(StepDut { module, text: body, next_bits, present })
}

/// The verdicts of a stage-by-stage proof and the abstraction it used.
pub struct Proof {
    /// The module-alone proofs of the abstractions, then every step's queries and the ports'.
    pub steps: Vec<StepProof>,
    /// The instances abstracted and those left concrete.
    pub plan: Plan,
    /// With [`Settings::whole_input`]: the first differing stage signal's query again, from the
    /// `in_row` port through every earlier stage (one transaction, entering at cycle 1 after
    /// reset), so that a witness is a whole input row.
    pub whole: Option<StepProof>,
}

/// How a stage-by-stage proof runs.
#[derive(Clone, Debug, Default)]
pub struct Settings {
    /// Entry cycles of a several-edge step (default: its edges − 1).
    pub phases: Option<u32>,
    /// Prove only these signals (empty: every signal, the carried fields, the ports).
    pub only: Vec<String>,
    /// Solver (`auto`, `bitwuzla`, `cvc5`, `z3`).
    pub solver: String,
    /// Seconds per query (0: no limit).
    pub timeout_s: f64,
    /// Queries at once.
    pub threads: usize,
    /// Use an abstraction whose module-alone proof did not finish (never a refuted one): the
    /// result is then conditional on those modules.
    pub trust_unfinished: bool,
    /// Search a whole-input counterexample for the first stage signal found to differ
    /// ([`Proof::whole`]).
    pub whole_input: bool,
}

/// Proves the DUT's rows stage by stage.
pub fn prove(
    req: &Request,
    n: &Netlist,
    rows: &[Row],
    lay: &Layout,
    set: &Settings,
    work: &Path,
) -> Result<Proof, String> {
    let (phases, only, solver, timeout_s, threads) =
        (set.phases, set.only.as_slice(), set.solver.as_str(), set.timeout_s, set.threads);
    let full = crate::smt::emit(req)?;
    if let Some(o) = only.iter().find(|o| !full.signals.iter().any(|s| &s.0 == *o)) {
        return Err(format!("--outputs {o}: not a stage signal of the {:?} model", req.unit));
    }
    let rows = check_rows(rows, n, lay, &full)?;
    // operator abstraction: each group's module proven alone first (a group not proven stays
    // concrete), then cut out of the steps
    if let Some(m) = abstraction::unmatched(&n.abstractions, &n.cells).first() {
        return Err(format!("--abstract {m}: no cell of the DUT instantiates module {m}"));
    }
    if !n.abstractions.is_empty() && full.float.ieee().is_none() {
        return Err(
            "--abstract states a module equal to an IEEE operation rounded to nearest-even; the format is fixed point"
                .into(),
        );
    }
    let mut plan = abstraction::plan(&n.abstractions, &n.cells, &|w| n.width(w), full.float.width());
    let module_proofs = justify(&mut plan, n, &full, set, work)?;
    let first_stage = *full.stages.iter().min().unwrap_or(&0);
    // the steps: each row from the previous one
    let mut steps = Vec::new();
    let mut arrive = 0u32;
    let mut prev: Option<&Row> = None;
    for r in &rows {
        let lo = prev.and_then(|p| p.after).map_or(first_stage, |k| k + 1);
        if let Some(hi) = r.after {
            if hi < lo {
                return Err(format!("--stage-row {hi}: follows the row after stage {}", lo - 1));
            }
            steps.push(Step { prev, next: r, lo, hi, arrive });
        }
        arrive += r.edges;
        prev = Some(r);
    }
    // with --outputs, the steps after the last one holding a signal asked for are not needed
    // (an earlier step's read invariant is: it is carried forward)
    if !only.is_empty() {
        let last = steps.iter().rposition(|s| {
            full.signals
                .iter()
                .zip(&full.stages)
                .any(|((name, _), st)| (s.lo..=s.hi).contains(st) && only.contains(name))
        });
        steps.truncate(last.map_or(0, |k| k + 1));
    }
    // the DUT of each step (one yosys run each)
    let mut duts = Vec::new();
    for (i, s) in steps.iter().enumerate() {
        let cut: Vec<&str> =
            s.prev.map(|p| p.inputs.iter().chain(&p.stages).map(String::as_str).collect()).unwrap_or_default();
        let next: Vec<&str> = s.next.inputs.iter().chain(&s.next.stages).map(String::as_str).collect();
        let mut keep = cut.clone();
        keep.extend(&next);
        if s.bmc() || s.prev.is_none() {
            keep.extend(["rst_n", "in_valid", "in_row"]);
        }
        duts.push(step_smt(n, &plan, &cut, &next, &keep, false, !s.bmc(), work, &format!("step{i}"))?);
    }
    let last = rows.last().expect("checked: a last row");
    let cut_last: Vec<&str> = last.inputs.iter().chain(&last.stages).map(String::as_str).collect();
    let mut keep_last = cut_last.clone();
    keep_last.extend(["out_row", "stg_row"]);
    // (the ports are proven only in a whole proof, not with --outputs)
    let ports_dut = if only.is_empty() {
        Some(step_smt(n, &Plan::default(), &cut_last, &[], &keep_last, true, false, work, "ports")?)
    } else {
        None
    };

    // the inputs each row holds as read (rp_read(x) = x), proven step by step from the
    // previous row's (a DUT may read its inputs in stage 0 and rely on that later)
    // (each step's model emitted once, for its invariant and its queries)
    let models = steps.iter().map(|s| emit_stage_range(req, s.lo, s.hi)).collect::<Result<Vec<_>, _>>()?;
    let mut read_ok: Vec<Vec<String>> = Vec::new();
    for (i, s) in steps.iter().enumerate() {
        let prev_read: &[String] = if i == 0 { &[] } else { &read_ok[i - 1] };
        let q = Query::new(&models[i], &full, s, &duts[i], &plan, prev_read, lay, phases);
        read_ok.push(invariant(&q, s, solver, timeout_s)?);
    }

    // one query per signal of each step, one for its carried fields, one for the ports
    struct Job {
        step: Option<usize>,
        goal: Goal,
    }
    let mut jobs = Vec::new();
    for (i, s) in steps.iter().enumerate() {
        for (name, st) in full.signals.iter().map(|x| &x.0).zip(&full.stages) {
            if (s.lo..=s.hi).contains(st) && (only.is_empty() || only.contains(name)) {
                jobs.push(Job { step: Some(i), goal: Goal::Signal(name.clone()) });
            }
        }
        if only.is_empty() {
            jobs.push(Job { step: Some(i), goal: Goal::Carried });
        }
    }
    // the latency: the rows' edges from in_row (the last row's fields are on out_row)
    let latency: u32 = rows.iter().map(|r| r.edges).sum();
    let entries = phases.unwrap_or_else(|| rows.iter().map(|r| r.edges.saturating_sub(1)).max().unwrap_or(1)).max(1);
    if only.is_empty() {
        jobs.push(Job { step: None, goal: Goal::Ports });
    }
    // (the latency always: a small circuit)
    jobs.push(Job { step: None, goal: Goal::Latency(latency, entries) });
    let valid_dut =
        step_smt(n, &Plan::default(), &[], &[], &["rst_n", "in_valid", "out_valid"], false, false, work, "valid")?;
    let progress = std::io::IsTerminal::is_terminal(&std::io::stderr());
    let results = par_map(&jobs, threads, |job| {
        let r = match job.step {
            Some(i) => {
                let s = &steps[i];
                let prev_read: &[String] = if i == 0 { &[] } else { &read_ok[i - 1] };
                Query::new(&models[i], &full, s, &duts[i], &plan, prev_read, lay, phases)
                    .run(&job.goal, solver, timeout_s)
            }
            None => match &job.goal {
                Goal::Latency(l, p) => run_latency(&valid_dut, *l, *p, solver, timeout_s),
                _ => run_ports(last, ports_dut.as_ref().expect("a whole proof"), lay, solver, timeout_s),
            },
        };
        if progress {
            if let Ok(p) = &r {
                eprintln!(
                    "equiv: {} {}: {} ({:.1} s)",
                    job.step.map_or("ports".into(), |i| format!("stage {}", steps[i].lo)),
                    goal_file(&job.goal),
                    p.verdict.result,
                    p.verdict.seconds
                );
            }
        }
        r
    });
    let mut all = module_proofs;
    for r in results {
        all.push(r?);
    }
    // a whole-input counterexample for the first signal that differs (jobs are in table order)
    let mut whole = None;
    if set.whole_input {
        let first = jobs.iter().zip(&all[all.len() - jobs.len()..]).find_map(|(job, p)| match (&job.goal, job.step) {
            (Goal::Signal(name), Some(i)) if p.verdict.result == "sat" => Some((i, name.clone())),
            _ => None,
        });
        if let Some((i, name)) = first {
            let s = &steps[i];
            let row = Row { edges: s.arrive + s.next.edges, ..s.next.clone() };
            let step = Step { prev: None, next: &row, lo: first_stage, hi: s.hi, arrive: 0 };
            let next: Vec<&str> = row.inputs.iter().chain(&row.stages).map(String::as_str).collect();
            let mut keep = next.clone();
            keep.extend(["rst_n", "in_valid", "in_row"]);
            let dut = step_smt(n, &plan, &[], &next, &keep, false, !step.bmc(), work, "whole")?;
            let model = emit_stage_range(req, first_stage, s.hi)?;
            let mut q = Query::new(&model, &full, &step, &dut, &plan, &[], lay, Some(1));
            q.single = true;
            whole = Some(q.run(&Goal::Signal(name), solver, timeout_s)?);
        }
    }
    Ok(Proof { steps: all, plan, whole })
}

/// `f` over `items` on `threads` threads; the results in order.
fn par_map<T: Sync, R: Send>(items: &[T], threads: usize, f: impl Fn(&T) -> R + Sync) -> Vec<R> {
    let queue = std::sync::Mutex::new(0usize);
    let results: std::sync::Mutex<Vec<Option<R>>> = std::sync::Mutex::new((0..items.len()).map(|_| None).collect());
    std::thread::scope(|sc| {
        for _ in 0..threads.max(1) {
            sc.spawn(|| loop {
                let j = {
                    let mut q = queue.lock().expect("queue");
                    let j = *q;
                    *q += 1;
                    j
                };
                let Some(item) = items.get(j) else { break };
                let r = f(item);
                results.lock().expect("results")[j] = Some(r);
            });
        }
    });
    results.into_inner().expect("results").into_iter().map(|r| r.expect("every item ran")).collect()
}

/// Proves each abstraction group's module alone; a group not proven (a counterexample, a
/// timeout) leaves its instances concrete.
fn justify(plan: &mut Plan, n: &Netlist, m: &Model, set: &Settings, work: &Path) -> Result<Vec<StepProof>, String> {
    let (solver, timeout_s, threads) = (set.solver.as_str(), set.timeout_s, set.threads);
    let groups: Vec<usize> = (0..plan.groups.len()).collect();
    let p: &Plan = plan;
    let proofs = par_map(&groups, threads, |&g| -> Result<StepProof, String> {
        let group = &p.groups[g];
        let (q, values) = abstraction::justification(p, group, &n.dut, m, work, &format!("module{g}"))?;
        let terms: Vec<String> = values.iter().map(|v| v.1.clone()).collect();
        let v = check_kept(&q, solver, timeout_s, &terms, &format!("module{g}"))?;
        let witness = if v.result == "sat" {
            values.iter().map(|(label, t)| (label.clone(), v.value(t))).collect()
        } else {
            Vec::new()
        };
        Ok(StepProof {
            stages: None,
            method: format!("the module alone, every a and b ({} instances)", group.instances.len()),
            goal: Goal::Module(g, p.statement(group)),
            verdict: v,
            witness,
        })
    })
    .into_iter()
    .collect::<Result<Vec<_>, _>>()?;
    for pr in &proofs {
        let Goal::Module(g, _) = &pr.goal else { continue };
        if pr.verdict.result != "unsat" && !(set.trust_unfinished && pr.verdict.result == "unknown") {
            let why = if pr.verdict.result == "sat" {
                let w: Vec<String> = pr.witness.iter().map(|(k, v)| format!("{k}={v:#x}")).collect();
                format!("its module alone is not the operation ({})", w.join(" "))
            } else {
                format!("its module alone was not proven the operation ({})", pr.verdict.result)
            };
            plan.drop_group(*g, &why);
        }
    }
    Ok(proofs)
}

/// The inputs of `s`'s next row that hold read values in every state the step reaches from
/// a previous row whose `prev_read` inputs do (a Houdini-style fixpoint: drop the fields a
/// counterexample violates and ask again).
fn invariant(q: &Query, s: &Step, solver: &str, timeout_s: f64) -> Result<Vec<String>, String> {
    let Some(reg) = &s.next.inputs else { return Ok(Vec::new()) };
    let (full, lay) = (q.full, q.lay);
    let mut cand: Vec<String> =
        full.inputs.iter().filter(|x| lay.inputs.iter().any(|f| &f.name == *x)).cloned().collect();
    while !cand.is_empty() {
        let terms: Vec<(String, String)> = cand
            .iter()
            .map(|name| {
                let f = lay.inputs.iter().find(|f| &f.name == name).expect("filtered");
                let v = q.next_field(reg, f);
                (name.clone(), format!("(ite (= {v} (rp_read {v})) #b1 #b0)"))
            })
            .collect();
        let goal = format!("(or {})", terms.iter().map(|(_, t)| format!("(= {t} #b0)")).collect::<Vec<_>>().join(" "));
        let values: Vec<String> = terms.iter().map(|(_, t)| t.clone()).collect();
        let v = check_kept(&q.script(&goal), solver, timeout_s, &values, &format!("stage{}-read", s.lo))?;
        match v.result.as_str() {
            "unsat" => return Ok(cand),
            "sat" => {
                let bad: Vec<String> = terms.iter().filter(|(_, t)| v.value(t) == 0).map(|(n, _)| n.clone()).collect();
                if bad.is_empty() {
                    return Ok(Vec::new());
                }
                cand.retain(|c| !bad.contains(c));
            }
            _ => return Ok(Vec::new()),
        }
    }
    Ok(cand)
}

/// Splits a step into the script common to its queries and the goal.
struct Query<'a> {
    m: &'a Model,
    full: &'a Model,
    s: &'a Step<'a>,
    dut: &'a StepDut,
    plan: &'a Plan,
    lay: &'a Layout,
    prev_read: &'a [String],
    p: u32,
    /// One transaction only: `in_valid` low in every cycle but the entry cycle.
    single: bool,
}

impl<'a> Query<'a> {
    #[allow(clippy::too_many_arguments)]
    fn new(
        m: &'a Model,
        full: &'a Model,
        s: &'a Step<'a>,
        dut: &'a StepDut,
        plan: &'a Plan,
        prev_read: &'a [String],
        lay: &'a Layout,
        phases: Option<u32>,
    ) -> Self {
        let p = phases.unwrap_or(s.next.edges.saturating_sub(1)).max(1);
        Query { m, full, s, dut, plan, lay, prev_read, p, single: false }
    }

    fn nx(&self, reg: &str, st: &str) -> String {
        format!("(|{}_n {reg}| {st})", self.dut.module)
    }

    fn cycles(&self) -> Vec<u32> {
        if self.s.bmc() {
            (1..=self.p).collect()
        } else {
            vec![0]
        }
    }

    fn at_prev(&self, c: u32) -> u32 {
        if self.s.bmc() {
            c + self.s.arrive
        } else {
            0
        }
    }

    fn at_next(&self, c: u32) -> u32 {
        if self.s.bmc() {
            c + self.s.arrive + self.s.next.edges
        } else {
            1
        }
    }

    /// A term over the injection cycle: `f(c)` for the cycle the transaction entered.
    fn over_c(&self, f: &dyn Fn(u32) -> String) -> String {
        let cycles = self.cycles();
        let mut t = f(*cycles.last().expect("a cycle"));
        for &c in cycles.iter().rev().skip(1) {
            t = format!("(ite (= rp_c (_ bv{c} 16)) {} {t})", f(c));
        }
        t
    }

    /// A field of a previous-row register (or of the in_row port), when the transaction is there.
    fn prev_field(&self, reg: &str, f: &FieldPos) -> String {
        self.over_c(&|c| extract(&self.nx(reg, &format!("rp_s{}", self.at_prev(c))), f))
    }

    /// A field of a next-row register, when the transaction is there.
    fn next_field(&self, reg: &str, f: &FieldPos) -> String {
        if self.s.bmc() {
            return self.over_c(&|c| extract(&self.nx(reg, &format!("rp_s{}", self.at_next(c))), f));
        }
        // one edge: the bits' next values from the current state
        let bits: Vec<String> = (f.lsb..f.lsb + f.width)
            .rev()
            .map(|b| match self.dut.next_bits.iter().find(|((r, k), _)| r == reg && *k == b) {
                Some((_, name)) => format!("(ite ({name} rp_s0) #b1 #b0)"),
                // a bit yosys made constant: the wire's value
                None => format!("((_ extract {b} {b}) {})", self.nx(reg, "rp_s0")),
            })
            .collect();
        if bits.len() == 1 {
            bits[0].clone()
        } else {
            format!("(concat {})", bits.join(" "))
        }
    }

    fn prev_regs(&self) -> (Option<String>, Option<String>) {
        match self.s.prev {
            Some(r) => (r.inputs.clone(), r.stages.clone()),
            None => (Some("in_row".to_string()), None),
        }
    }

    /// The model, the DUT, the states and the ties; then `goal` asserted.
    fn script(&self, goal: &str) -> String {
        let (s, md) = (self.s, &self.dut.module);
        let mut q = self.m.text.clone();
        q += &self.dut.text;
        let states = if s.bmc() { self.p + s.arrive + s.next.edges } else { 0 };
        for t in 0..=states {
            let _ = writeln!(q, "(declare-const rp_s{t} |{md}_s|)\n(assert (|{md}_h| rp_s{t}))");
            if t > 0 {
                let _ = writeln!(q, "(assert (|{md}_t| rp_s{} rp_s{t}))", t - 1);
            }
        }
        let sts: Vec<String> = (0..=states).map(|t| format!("rp_s{t}")).collect();
        q += &self.plan.assumptions(md, &self.dut.present, &sts);
        if s.bmc() {
            let p = self.p;
            let _ = writeln!(q, "(declare-const rp_c (_ BitVec 16))");
            let _ = writeln!(q, "(assert (bvule #x0001 rp_c))\n(assert (bvule rp_c (_ bv{p} 16)))");
            // (yosys writes a 1-bit wire as a Bool)
            let _ = writeln!(q, "(assert (not {}))", self.nx("rst_n", "rp_s0"));
            for t in 1..=states {
                let _ = writeln!(q, "(assert {})", self.nx("rst_n", &format!("rp_s{t}")));
                if t <= p {
                    let _ =
                        writeln!(q, "(assert (=> (= rp_c (_ bv{t} 16)) {}))", self.nx("in_valid", &format!("rp_s{t}")));
                }
                if self.single {
                    let v = self.nx("in_valid", &format!("rp_s{t}"));
                    let _ = writeln!(q, "(assert (=> (not (= rp_c (_ bv{t} 16))) (not {v})))");
                }
            }
        }
        let (prev_in, prev_stg) = self.prev_regs();
        let _ = writeln!(q, "; ---- the model's inputs and earlier signals tied to the previous row");
        let field = |list: &[FieldPos], name: &str| list.iter().find(|f| f.name == name).cloned();
        if let Some(reg) = &prev_in {
            for name in &self.m.inputs {
                let Some(f) = field(&self.lay.inputs, name) else { continue };
                let v = self.prev_field(reg, &f);
                let _ = writeln!(q, "(assert (= in_{name} {v}))");
                if self.prev_read.contains(name) {
                    let _ = writeln!(q, "(assert (= in_{name} (rp_read in_{name})))");
                }
            }
        }
        for ((name, flag), st) in self.full.signals.iter().zip(&self.full.stages) {
            if *st >= s.lo {
                continue;
            }
            let (Some(reg), Some(f)) = (&prev_stg, field(&self.lay.stages, name)) else { continue };
            let _ = writeln!(q, "(assert (= {name} {}))", as_model(&self.prev_field(reg, &f), *flag));
        }
        let _ = writeln!(q, "; ---- the goal, negated\n(assert {goal})");
        q
    }

    fn run(&self, goal: &Goal, solver: &str, timeout_s: f64) -> Result<StepProof, String> {
        let s = self.s;
        let field = |list: &[FieldPos], name: &str| list.iter().find(|f| f.name == name).cloned();
        let next_stg = s.next.stages.as_deref().expect("checked: a stage register");
        let mut values: Vec<String> = self.m.inputs.iter().map(|n| format!("in_{n}")).collect();
        // labels of the values read back (the DUT's and the model's value of a signal)
        let mut labels: Vec<String> = values.clone();
        let (prev_in, prev_stg) = self.prev_regs();
        let goal_term = match goal {
            Goal::Signal(name) => {
                let f = field(&self.lay.stages, name).ok_or(format!("stg_row has no field {name}"))?;
                let flag = self.full.signals.iter().find(|x| &x.0 == name).is_some_and(|x| x.1);
                let dut_val = self.next_field(next_stg, &f);
                values.push(dut_val.clone());
                values.push(if flag { format!("(ite {name} #b1 #b0)") } else { name.clone() });
                labels.push(format!("dut {name}"));
                labels.push(format!("model {name}"));
                format!("(not (= {name} {}))", as_model(&dut_val, flag))
            }
            Goal::Carried => {
                let mut ors = Vec::new();
                if let (Some(pi), Some(ni)) = (&prev_in, &s.next.inputs) {
                    for name in &self.m.inputs {
                        let Some(f) = field(&self.lay.inputs, name) else { continue };
                        let (a, b) = (self.prev_field(pi, &f), self.next_field(ni, &f));
                        ors.push(format!("(not (= (rp_read {a}) (rp_read {b})))"));
                    }
                }
                if let Some(ps) = &prev_stg {
                    for (name, st) in self.full.signals.iter().map(|x| &x.0).zip(&self.full.stages) {
                        if *st >= s.lo {
                            continue;
                        }
                        let Some(f) = field(&self.lay.stages, name) else { continue };
                        ors.push(format!("(not (= {} {}))", self.prev_field(ps, &f), self.next_field(next_stg, &f)));
                    }
                }
                if ors.is_empty() {
                    "false".to_string()
                } else {
                    format!("(or {})", ors.join(" "))
                }
            }
            Goal::Ports | Goal::Module(..) | Goal::Latency(..) => {
                unreachable!("ports are run_ports', modules justify's, the latency run_latency's")
            }
        };
        if s.bmc() {
            values.push("rp_c".into());
            labels.push("entry cycle".into());
        }
        let v = check_kept(
            &self.script(&goal_term),
            solver,
            timeout_s,
            &values,
            &format!("stage{}-{}", s.lo, goal_file(goal)),
        )?;
        let witness = if v.result == "sat" {
            values.iter().zip(&labels).map(|(k, l)| (l.clone(), v.value(k))).collect()
        } else {
            Vec::new()
        };
        Ok(StepProof {
            stages: Some((s.lo, s.hi)),
            method: if s.bmc() {
                format!("bmc from reset, {} edges, {} entry cycles", s.next.edges, self.p)
            } else {
                "one edge".into()
            },
            goal: goal.clone(),
            verdict: v,
            witness,
        })
    }
}

fn goal_file(g: &Goal) -> String {
    match g {
        Goal::Signal(s) => s.clone(),
        Goal::Carried => "carried".into(),
        Goal::Ports => "ports".into(),
        Goal::Latency(..) => "latency".into(),
        Goal::Module(g, _) => format!("module{g}"),
    }
}

/// [`check`], writing the query to `$RAYPIPE_KEEP_QUERIES/NAME.smt2` when that directory is
/// set (to rerun a query by hand); a solver that fails on a query gives verdict `error`.
fn check_kept(q: &str, solver: &str, timeout_s: f64, values: &[String], name: &str) -> Result<Verdict, String> {
    if let Some(dir) = std::env::var_os("RAYPIPE_KEEP_QUERIES") {
        let p = Path::new(&dir).join(format!("{name}.smt2"));
        std::fs::write(&p, q).map_err(|e| format!("{}: {e}", p.display()))?;
    }
    match check(q, solver, timeout_s, values) {
        Ok(v) => Ok(v),
        Err(e) if e.starts_with("solver driver failed") => Ok(Verdict {
            result: format!("error: {e}"),
            solver: solver.into(),
            version: String::new(),
            seconds: 0.0,
            values: Vec::new(),
        }),
        Err(e) => Err(e),
    }
}

/// `out_valid` against `in_valid` by bounded model checking from reset: cycle 0 has `rst_n`
/// low, cycles 1..=P + L high, `in_valid` free in every cycle; `out_valid` is low in cycles
/// 1..=L (nothing entered before reset was released) and in cycle c + L equals `in_valid` in
/// cycle c, for c in 1..=P.
fn run_latency(dut: &StepDut, l: u32, p: u32, solver: &str, timeout_s: f64) -> Result<StepProof, String> {
    let md = &dut.module;
    let nx = |w: &str, t: u32| format!("(|{md}_n {w}| rp_s{t})");
    let mut q = format!("(set-logic QF_BV)\n{}", dut.text);
    for t in 0..=p + l {
        let _ = writeln!(q, "(declare-const rp_s{t} |{md}_s|)\n(assert (|{md}_h| rp_s{t}))");
        if t > 0 {
            let _ = writeln!(q, "(assert (|{md}_t| rp_s{} rp_s{t}))\n(assert {})", t - 1, nx("rst_n", t));
        }
    }
    let _ = writeln!(q, "(assert (not {}))", nx("rst_n", 0));
    let mut ors: Vec<String> = (1..=l).map(|t| nx("out_valid", t)).collect();
    ors.extend((1..=p).map(|c| format!("(not (= {} {}))", nx("out_valid", c + l), nx("in_valid", c))));
    let _ = writeln!(q, "(assert (or {}))", ors.join(" "));
    let v = check_kept(&q, solver, timeout_s, &[], "latency")?;
    Ok(StepProof {
        stages: None,
        method: format!("bmc from reset, {} cycles", p + l),
        goal: Goal::Latency(l, p),
        verdict: v,
        witness: Vec::new(),
    })
}

fn run_ports(last: &Row, dut: &StepDut, lay: &Layout, solver: &str, timeout_s: f64) -> Result<StepProof, String> {
    let (md, dtext) = (&dut.module, &dut.text);
    let nx = |reg: &str| format!("(|{md}_n {reg}| rp_s0)");
    let stg = last.stages.as_deref().expect("checked: a stage register");
    let mut q = format!("(set-logic QF_BV)\n{dtext}");
    let _ = writeln!(q, "(declare-const rp_s0 |{md}_s|)\n(assert (|{md}_h| rp_s0))");
    let mut ors = vec![format!("(not (= {} {}))", nx("stg_row"), nx(stg))];
    for f in &lay.outputs {
        let g = lay.stages.iter().find(|x| x.name == f.name).ok_or(format!(
            "out_row field {} is not a stage signal (the ports proof compares out_row with the last row)",
            f.name
        ))?;
        ors.push(format!("(not (= {} {}))", extract(&nx("out_row"), f), extract(&nx(stg), g)));
    }
    let _ = writeln!(q, "(assert (or {}))", ors.join(" "));
    let v = check_kept(&q, solver, timeout_s, &[], "ports")?;
    Ok(StepProof { stages: None, method: "ports".into(), goal: Goal::Ports, verdict: v, witness: Vec::new() })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn row_specs_parse_and_bad_ones_are_refused() {
        assert_eq!(
            parse_row("in=ri0").unwrap(),
            Row { after: None, inputs: Some("ri0".into()), stages: None, edges: 1 }
        );
        assert_eq!(
            parse_row("0=ri1:rs1@14").unwrap(),
            Row { after: Some(0), inputs: Some("ri1".into()), stages: Some("rs1".into()), edges: 14 }
        );
        assert_eq!(
            parse_row("5=:rs6").unwrap(),
            Row { after: Some(5), inputs: None, stages: Some("rs6".into()), edges: 1 }
        );
        for bad in ["", "in=", "3", "3=ri", "3=ri:", "x=a:b", "3=a:b@0", "3=a b:c", "3=a:b@x"] {
            assert!(parse_row(bad).is_err(), "{bad}");
        }
    }
}
