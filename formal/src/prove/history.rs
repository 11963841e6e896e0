//! `history-equals-stack`: the 2-bit ray-history traversal returns the same first N leaves as
//! the ordered stack traversal, for every tree shape of at most D levels and every outcome of
//! the box tests — proven by an exhaustive, explicit-state search over the real control logic.
//!
//! **The abstraction.** Both traversals see a box test only as `Option<f64>` (miss, or hit at
//! an entry distance) and use entries only to order two siblings: the right child is nearer
//! exactly when `right < left` (so ties and NaN go left). A pair of sibling tests is therefore
//! one of six classes, each represented by one pair of values: both miss; left only; right
//! only; both hit with `right < left` (entries 1, 0); both hit with equal entries (0, 0); both
//! hit with `left < right` (0, 1). Every `f64` pair falls in one class, NaN with either
//! sibling behaving as a tie (`<` is false), and a test the tester reports as a miss because
//! of a NaN is the miss class. With `--nan` the search also offers the NaN pairs themselves
//! (NaN, 0), (0, NaN) and (NaN, NaN), which checks that claim instead of assuming it. The
//! environment additionally chooses, for every hit child, leaf or inner node (inner only above
//! the deepest level). The tests are deterministic: a box gives the same answer on every pass,
//! which is what lets the history re-walk its path from the root.
//!
//! **The search.** The history side is `datapath::bvh::history_pass_faulty`, the very function
//! `history_traverse` loops over, run one pass at a time on a complete `HwTree` of D levels
//! whose pairs the environment decides when a pass first tests them (the pass is rerun once
//! per choice). The stack side is the ordered stack traversal advanced to its next *terminal*
//! (a leaf popped, or an inner node whose children both miss). After every pass the two must
//! agree: the pass emitted the stack's leaf, or ended at the stack's dead end. When the
//! history stops, the stack must have emitted N leaves or have nothing left.
//!
//! **Why a finite search covers every tree.** States are merged at pass boundaries on (the
//! history register, leaves emitted, the stack, the decided pairs of the ancestors and
//! descendants of the stack's nodes). The pairs left out belong to finished subtrees and to
//! subtrees under missed children; the stack never tests them again, and a history pass that
//! tests one ends the search as a failure (it re-entered finished work). So two merged states
//! have the same futures, and the search visits every reachable state once: it terminates,
//! and a complete search without a failure covers every environment — every tree of at most D
//! levels with every outcome, since a shallower tree is a deeper layout whose lower levels are
//! never reached (the register's unused levels stay 00).
//!
//! A failure is replayed on a concrete tree (every undecided pair: a left leaf hit, a right
//! miss) through `history_traverse_faulty` and `golden::bvh::stack_traverse`; it is a
//! counterexample when their leaves differ, and otherwise proves nothing (unknown).

use std::collections::{HashMap, HashSet};
use std::time::Instant;

use datapath::bvh::{
    hist, history_pass_faulty, history_traverse_faulty, Bank, HwTree, Level, StacklessResult, LEAF_FLAG,
};
use datapath::fault::Logic;

/// A node: depth (0 = root) and index at that depth; the children of (d, i) are (d + 1, 2i)
/// and (d + 1, 2i + 1), and their pair is stored at level d, pair index i.
type Node = (u8, u32);

/// The box-test answer for one child, by order class.
#[derive(Clone, Copy, PartialEq, Eq, Hash, Debug)]
enum Ent {
    Miss,
    Lo,
    Hi,
    Nan,
}

impl Ent {
    fn value(self) -> Option<f64> {
        match self {
            Ent::Miss => None,
            Ent::Lo => Some(0.0),
            Ent::Hi => Some(1.0),
            Ent::Nan => Some(f64::NAN),
        }
    }
    fn name(self) -> &'static str {
        match self {
            Ent::Miss => "miss",
            Ent::Lo => "0",
            Ent::Hi => "1",
            Ent::Nan => "NaN",
        }
    }
}

/// The environment's answer for one pair: both entries and whether each child is a leaf.
#[derive(Clone, Copy, PartialEq, Eq, Hash, Debug)]
struct Pair {
    ent: [Ent; 2],
    leaf: [bool; 2],
}

impl Pair {
    fn code(self) -> u32 {
        let e = |x: Ent| x as u32;
        e(self.ent[0]) | e(self.ent[1]) << 2 | (self.leaf[0] as u32) << 4 | (self.leaf[1] as u32) << 5
    }
}

/// A history-traversal mutant the proof must refute (`None`: the traversal as built).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mutant {
    /// The control logic as built.
    None,
    /// Resume at the shallowest level in 10 instead of the deepest.
    ResumeShallowest,
    /// After 10 → 11 the deeper levels are not reset to 00.
    NoResetDeeper,
    /// A level where both children hit is not marked 10 (the farther child is never taken).
    NoMarkSplit,
    /// One pass only (no level is seen in 10 after a pass).
    OnePass,
    /// A level with one child hit is not marked 01 — equivalent on the leaves: 01 and 00 take
    /// the same choice on a one-hit level, so the proof holds and only the final register differs.
    NoMarkPass,
    /// Equal entries take the right child first (`right <= left`).
    TiesRight,
}

impl Mutant {
    /// Every mutant name, for messages.
    pub const NAMES: &'static str =
        "resume-shallowest, no-reset-deeper, no-mark-split, one-pass, ties-right, no-mark-pass";

    /// Parses a mutant name.
    pub fn parse(s: &str) -> Result<Self, String> {
        Ok(match s {
            "resume-shallowest" => Mutant::ResumeShallowest,
            "no-reset-deeper" => Mutant::NoResetDeeper,
            "no-mark-split" => Mutant::NoMarkSplit,
            "one-pass" => Mutant::OnePass,
            "no-mark-pass" => Mutant::NoMarkPass,
            "ties-right" => Mutant::TiesRight,
            _ => return Err(format!("unknown history mutant '{s}': {}", Self::NAMES)),
        })
    }
}

impl Logic for Mutant {
    fn flag(&self, site: &'static str, v: bool) -> bool {
        match (self, site) {
            (Mutant::ResumeShallowest, "resume") | (Mutant::NoResetDeeper, "reset_deeper") => false,
            (Mutant::NoMarkPass, "mark_pass") | (Mutant::NoMarkSplit, "mark_split") => false,
            (Mutant::OnePass, "more") => false,
            _ => v,
        }
    }
    fn less(&self, _site: &'static str, a: f64, b: f64) -> bool {
        match self {
            Mutant::TiesRight => a <= b,
            _ => a < b,
        }
    }
}

/// What the search established.
#[derive(Clone, Debug)]
pub struct HistoryProof {
    /// `PROVEN`, `COUNTEREXAMPLE` or `UNKNOWN`.
    pub status: &'static str,
    /// The theorem (when proven) or what failed.
    pub statement: String,
    /// Per (levels, N): merged states visited.
    pub cases: Vec<(usize, usize, u64)>,
    /// The counterexample tree and both traversals' leaves, when one was found.
    pub counterexample: Option<String>,
    /// Wall time, seconds.
    pub seconds: f64,
}

/// Proves `history-equals-stack` for every tree of at most `depth` levels and every N in
/// `1..=n_max` (N = 0 returns nothing on both sides by definition and is checked too).
/// The result is the same for every number of `threads`.
pub fn prove(depth: usize, n_max: usize, nan: bool, mutant: Mutant, threads: usize) -> Result<HistoryProof, String> {
    // the merged states grow about 20x per level: depth 6 with N <= 4 is 1.2e8 states
    // (4 GB on one thread, 6.7 GB on two); depth 7 or depth 6 with N > 4 would not fit
    if !(1..=6).contains(&depth) {
        return Err(format!(
            "--depth must be 1..=6 levels, got {depth} (each level multiplies the search by about 20: depth 6 takes ~4 GB)"
        ));
    }
    if !(1..=8).contains(&n_max) {
        return Err(format!("--n must be 1..=8 leaves, got {n_max}"));
    }
    if depth == 6 && n_max > 4 {
        return Err(format!("--n {n_max} at depth 6 would need tens of GB; depth 6 takes N <= 4, depth 5 up to 8"));
    }
    let t0 = Instant::now();
    let mut cases = Vec::new();
    // the root alone: a miss returns nothing, a leaf returns itself, N = 0 nothing
    for n in 0..=n_max {
        for root in [None, Some(Ent::Lo)] {
            let fail = replay_root_leaf(n, root, mutant);
            if let Some(f) = fail {
                return Ok(finish(t0, "COUNTEREXAMPLE", "the root alone".into(), cases, Some(f)));
            }
        }
    }
    // one search per (levels, N), largest first over `threads` workers; reported in order
    let mut order: Vec<(usize, usize)> = (1..=depth).flat_map(|l| (1..=n_max).map(move |n| (l, n))).collect();
    order.reverse();
    let next = std::sync::atomic::AtomicUsize::new(0);
    let results = std::sync::Mutex::new(Vec::new());
    std::thread::scope(|sc| {
        for _ in 0..threads.clamp(1, order.len()) {
            let (order, next, results) = (&order, &next, &results);
            std::thread::Builder::new()
                .stack_size(1 << 30) // the search recurses once per pass
                .spawn_scoped(sc, move || loop {
                    let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    let Some(&(levels, n)) = order.get(i) else { break };
                    let r = search(levels, n, nan, mutant);
                    results.lock().expect("a worker panicked").push(((levels, n), r));
                })
                .expect("cannot start a search thread");
        }
    });
    let mut results = results.into_inner().expect("a worker panicked");
    results.sort_by_key(|r| r.0);
    let mut failure = None;
    for ((levels, n), (states, fail)) in results {
        cases.push((levels, n, states));
        if failure.is_none() {
            failure = fail;
        }
    }
    if let Some((status, what, detail)) = failure {
        return Ok(finish(t0, status, what, cases, Some(detail)));
    }
    let theorem = format!(
        "for every binary tree of 1 to {depth} levels (the root an inner node, a leaf or missed), every outcome of its box tests ({}) and every N in 0..={n_max}, the 2-bit history traversal{} ends each pass at the ordered stack traversal's next leaf or dead end, so it returns the stack traversal's first N leaves in the same order",
        if nan { "the six order classes and the NaN pairs" } else { "the six order classes of a sibling pair" },
        if mutant == Mutant::None { String::new() } else { format!(" (mutant {mutant:?})") },
    );
    Ok(finish(t0, "PROVEN", theorem, cases, None))
}

/// One (levels, N) search: merged states visited, and the failure (status, what, tree) if any.
fn search(levels: usize, n: usize, nan: bool, mutant: Mutant) -> (u64, Option<(&'static str, String, String)>) {
    let mut s = Search::new(levels, n, nan, mutant);
    let root = Joint {
        r: StacklessResult { state: vec![hist::NEW; levels], box_tests: 1, ..Default::default() },
        prev_end: None,
        know: HashMap::new(),
        stack: vec![(0, 0)],
        trail: None,
    };
    // the root is an inner node and was hit: it is the stack's only node
    let outcome = s.step(root);
    let states = s.visited.len() as u64;
    (
        states,
        outcome.err().map(|fail| {
            let (status, detail) = s.replay(&fail);
            (status, format!("{} ({} levels, N = {n})", fail.reason, levels), detail)
        }),
    )
}

fn finish(
    t0: Instant,
    status: &'static str,
    statement: String,
    cases: Vec<(usize, usize, u64)>,
    counterexample: Option<String>,
) -> HistoryProof {
    HistoryProof { status, statement, cases, counterexample, seconds: t0.elapsed().as_secs_f64() }
}

/// The root-only trees through the real traversals (None: the root missed).
fn replay_root_leaf(n: usize, root: Option<Ent>, mutant: Mutant) -> Option<String> {
    let hw = HwTree::<u32> { root_box: 0, root_addr: LEAF_FLAG | 7, levels: Vec::new() };
    let e = root.and_then(Ent::value);
    let got = history_traverse_faulty(&hw, n, |_| e, &mutant).leaves;
    let tree = golden::bvh::Tree { nodes: vec![golden::bvh::Node::Leaf { leaf: 7 }], root: Some(0) };
    let want = golden::bvh::stack_traverse(&tree, n, |_| e).leaves;
    (got != want).then(|| {
        format!("root leaf {}, N = {n}: history {got:?}, stack {want:?}", if e.is_some() { "hit" } else { "missed" })
    })
}

/// A search state at a pass boundary.
#[derive(Clone)]
struct Joint {
    /// The history traversal's state (register, leaves, ...).
    r: StacklessResult,
    prev_end: Option<usize>,
    /// Every decided pair, by its parent node.
    know: HashMap<Node, Pair>,
    /// The stack traversal's stack.
    stack: Vec<Node>,
    /// Decisions, newest first (for the counterexample; shared between branches).
    trail: Trail,
}

/// A terminal of a traversal: a leaf, or the node whose children both missed.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Terminal {
    Leaf(Node),
    DeadEnd(Node),
}

/// Why the search stopped.
struct Fail {
    reason: String,
    trail: Trail,
}

/// Every decision made on the way to a state, newest first.
type Trail = Option<std::rc::Rc<Link>>;

/// One decision of a [`Trail`] and the ones before it.
struct Link {
    v: Node,
    p: Pair,
    before: Trail,
}

struct Search {
    levels: usize,
    n: usize,
    nan: bool,
    mutant: Mutant,
    tree: HwTree<u32>,
    visited: HashSet<Key>,
}

/// A merge key (see [`Search::key`]).
#[derive(Clone, PartialEq, Eq, Hash)]
enum Key {
    Packed([u64; 4]),
    Whole(Vec<u32>),
}

fn code(v: Node) -> u32 {
    (v.0 as u32) << 24 | v.1
}

fn decode(c: u32) -> Node {
    ((c >> 24) as u8, c & 0xff_ffff)
}

/// `a` is an ancestor-or-self of `b`.
fn covers(a: Node, b: Node) -> bool {
    a.0 <= b.0 && b.1 >> (b.0 - a.0) == a.1
}

impl Search {
    fn new(levels: usize, n: usize, nan: bool, mutant: Mutant) -> Self {
        let mut tree = HwTree { root_box: code((0, 0)), root_addr: 0, levels: Vec::new() };
        for k in 0..levels {
            let pairs = 1u32 << k;
            let bank = |side: u32| Bank {
                boxes: (0..pairs).map(|p| code((k as u8 + 1, 2 * p + side))).collect(),
                addr: (0..pairs).map(|p| 2 * p + side).collect(),
            };
            tree.levels.push(Level { left: bank(0), right: bank(1) });
        }
        Search { levels, n, nan, mutant, tree, visited: HashSet::new() }
    }

    /// Every answer the environment may give for the pair under `v`.
    fn choices(&self, v: Node) -> Vec<Pair> {
        use Ent::*;
        let mut ents = vec![[Miss, Miss], [Lo, Miss], [Miss, Lo], [Hi, Lo], [Lo, Lo], [Lo, Hi]];
        if self.nan {
            ents.extend([[Nan, Lo], [Lo, Nan], [Nan, Nan]]);
        }
        let inner_ok = (v.0 as usize) + 1 < self.levels;
        let kinds: &[bool] = if inner_ok { &[true, false] } else { &[true] };
        let mut out = Vec::new();
        for ent in ents {
            let opts = |e: Ent| if e == Miss { &[true][..] } else { kinds };
            for &l in opts(ent[0]) {
                for &r in opts(ent[1]) {
                    out.push(Pair { ent, leaf: [l, r] });
                }
            }
        }
        out
    }

    /// Records the decision in `j` and in the tree's address words.
    fn decide(&mut self, j: &mut Joint, v: Node, p: Pair) {
        j.know.insert(v, p);
        j.trail = Some(std::rc::Rc::new(Link { v, p, before: j.trail.take() }));
        let lv = &mut self.tree.levels[v.0 as usize];
        for (side, bank) in [&mut lv.left, &mut lv.right].into_iter().enumerate() {
            let child = (v.0 + 1, 2 * v.1 + side as u32);
            bank.addr[v.1 as usize] = if p.leaf[side] { LEAF_FLAG | code(child) } else { child.1 };
        }
    }

    /// The merge key: register, leaves, stack and the pairs of the stack's ancestors and
    /// descendants, packed into 256 bits when they fit (trees of at most 7 levels and at most
    /// 9 such pairs; always so for the traversal as built), else kept whole.
    fn key(&self, j: &Joint) -> Key {
        let mut kept: Vec<(u32, u32)> = j
            .know
            .iter()
            .filter(|(&v, _)| j.stack.iter().any(|&s| covers(v, s) || covers(s, v)))
            .map(|(&v, &p)| {
                // a child neither on the way to a stack node nor under one is finished work or
                // a miss: whether it is a leaf only decides how a pass that takes it fails
                let mut p = p;
                for side in 0..2 {
                    let c = (v.0 + 1, 2 * v.1 + side as u32);
                    if !j.stack.iter().any(|&s| covers(c, s) || covers(s, c)) {
                        p.leaf[side] = true;
                    }
                }
                (code(v), p.code())
            })
            .collect();
        kept.sort_unstable();
        let h = j.r.state.iter().fold(0u32, |a, &s| a << 2 | s as u32);
        let e = j.r.leaves.len() as u32;
        if self.levels <= 7 && j.stack.len() <= 8 && kept.len() <= 9 && e < 16 {
            // 10 bits a node: depth (3) and index (7)
            let node = |c: u32| (c >> 24) << 7 | (c & 0x7f);
            let mut w = [0u64; 4];
            let mut at = 0usize;
            let mut put = |v: u32, bits: usize| {
                let v = v as u64;
                w[at / 64] |= v << (at % 64);
                if at % 64 + bits > 64 {
                    w[at / 64 + 1] |= v >> (64 - at % 64);
                }
                at += bits;
            };
            put(h, 14);
            put(e, 4);
            put(j.stack.len() as u32, 4);
            for &v in &j.stack {
                put(node(code(v)), 10);
            }
            put(kept.len() as u32, 4);
            for &(v, p) in &kept {
                put(node(v), 10);
                put(p, 6);
            }
            return Key::Packed(w);
        }
        let mut k = vec![h, e, j.stack.len() as u32];
        k.extend(j.stack.iter().map(|&v| code(v)));
        k.extend(kept.into_iter().flat_map(|(a, b)| [a, b]));
        Key::Whole(k)
    }

    /// From a pass boundary: run the next history pass, then the stack to its next terminal.
    fn step(&mut self, j: Joint) -> Result<(), Fail> {
        if !self.visited.insert(self.key(&j)) {
            return Ok(());
        }
        let mut r = j.r.clone();
        let mut prev_end = j.prev_end;
        let (mut need, mut forbidden, mut last) = (None, None, None);
        let before = r.leaves.len();
        let n_limit = self.mutant.limit("n_limit", self.n);
        let more = {
            let (know, stack) = (&j.know, &j.stack);
            let test = |&b: &u32| -> Option<f64> {
                let v = decode(b);
                let parent = (v.0 - 1, v.1 >> 1);
                last = Some(parent);
                let fresh = stack.iter().any(|&s| covers(s, parent));
                let kept = stack.iter().any(|&s| covers(parent, s));
                match know.get(&parent) {
                    Some(p) if fresh || kept => p.ent[(v.1 & 1) as usize].value(),
                    None if fresh => {
                        need.get_or_insert(parent);
                        None
                    }
                    _ => {
                        forbidden.get_or_insert(parent);
                        None
                    }
                }
            };
            history_pass_faulty(&self.tree, n_limit, test, &mut r, &mut prev_end, &self.mutant)
        };
        r.back_distances.clear();
        r.ties = [0; 2];
        if let Some(v) = forbidden {
            return Err(Fail {
                reason: format!("a history pass tested the children of node {v:?}, in finished or missed work"),
                trail: j.trail,
            });
        }
        if let Some(v) = need {
            for p in self.choices(v) {
                let mut j2 = j.clone();
                self.decide(&mut j2, v, p);
                self.step(j2)?;
            }
            return Ok(());
        }
        let event = if r.leaves.len() > before {
            Terminal::Leaf(decode(r.leaves[r.leaves.len() - 1]))
        } else {
            Terminal::DeadEnd(last.expect("a pass tests at least the root's children"))
        };
        let next = Joint { r, prev_end, ..j };
        self.advance(next, event, more)
    }

    /// Advances the stack traversal of `j` to its next terminal and compares it with where the
    /// history pass ended (`event`; `more`: another pass follows).
    fn advance(&mut self, mut j: Joint, event: Terminal, more: bool) -> Result<(), Fail> {
        let mut stack = j.stack.clone();
        let terminal = loop {
            let Some(v) = stack.pop() else { break None };
            let is_leaf = v.0 > 0 && j.know[&(v.0 - 1, v.1 >> 1)].leaf[(v.1 & 1) as usize];
            if is_leaf {
                break Some(Terminal::Leaf(v));
            }
            let Some(&p) = j.know.get(&v) else {
                // the stack tests a pair no pass has tested yet: every answer
                for p in self.choices(v) {
                    let mut j2 = j.clone();
                    self.decide(&mut j2, v, p);
                    self.advance(j2, event, more)?;
                }
                return Ok(());
            };
            let (l, r) = ((v.0 + 1, 2 * v.1), (v.0 + 1, 2 * v.1 + 1));
            match (p.ent[0].value(), p.ent[1].value()) {
                (Some(el), Some(er)) => {
                    let (near, far) = if er < el { (r, l) } else { (l, r) };
                    stack.push(far);
                    stack.push(near);
                }
                (Some(_), None) => stack.push(l),
                (None, Some(_)) => stack.push(r),
                (None, None) => break Some(Terminal::DeadEnd(v)),
            }
        };
        if terminal != Some(event) {
            return Err(Fail {
                reason: format!(
                    "a history pass ended at {event:?}, the stack traversal's next terminal is {terminal:?}"
                ),
                trail: j.trail,
            });
        }
        j.stack = stack;
        // finished and missed work is never tested again (a pass that does fails): forget it
        let st = &j.stack;
        j.know.retain(|&v, _| st.iter().any(|&s| covers(v, s) || covers(s, v)));
        let emitted = j.r.leaves.len();
        if more {
            if emitted >= self.n {
                return Err(Fail { reason: format!("the history goes on after {emitted} leaves"), trail: j.trail });
            }
            return self.step(j);
        }
        if emitted < self.n && !j.stack.is_empty() {
            return Err(Fail {
                reason: format!(
                    "the history stops after {emitted} of {} leaves while the stack still holds {:?}",
                    self.n, j.stack
                ),
                trail: j.trail,
            });
        }
        Ok(())
    }

    /// Replays a failure's environment on a concrete tree through both real traversals.
    fn replay(&self, f: &Fail) -> (&'static str, String) {
        let mut know: HashMap<Node, Pair> = HashMap::new();
        let mut t = &f.trail;
        while let Some(link) = t {
            know.entry(link.v).or_insert(link.p);
            t = &link.before;
        }
        let fill = Pair { ent: [Ent::Lo, Ent::Miss], leaf: [true, true] };
        let pair = |v: Node| know.get(&v).copied().unwrap_or(fill);
        // golden tree: every node of the layout that is reachable through inner nodes
        let mut nodes = Vec::new();
        let mut ids: HashMap<Node, u32> = HashMap::new();
        let mut entry: Vec<Option<f64>> = Vec::new();
        let mut todo = vec![((0u8, 0u32), Some(0.0), false)];
        while let Some((v, e, leaf)) = todo.pop() {
            ids.insert(v, nodes.len() as u32);
            nodes.push((v, leaf));
            entry.push(e);
            if !leaf && (v.0 as usize) < self.levels {
                let p = pair(v);
                for side in 0..2u32 {
                    todo.push(((v.0 + 1, 2 * v.1 + side), p.ent[side as usize].value(), p.leaf[side as usize]));
                }
            }
        }
        let gnodes = nodes
            .iter()
            .map(|&(v, leaf)| {
                if leaf || v.0 as usize == self.levels {
                    golden::bvh::Node::Leaf { leaf: code(v) }
                } else {
                    golden::bvh::Node::Inner { left: ids[&(v.0 + 1, 2 * v.1)], right: ids[&(v.0 + 1, 2 * v.1 + 1)] }
                }
            })
            .collect();
        let gt = golden::bvh::Tree { nodes: gnodes, root: Some(0) };
        let want = golden::bvh::stack_traverse(&gt, self.n, |i| entry[i as usize]).leaves;
        // the hardware layout: the same pairs
        let mut hw = self.tree.clone();
        for k in 0..self.levels {
            for p in 0..1u32 << k {
                let pr = pair((k as u8, p));
                let lv = &mut hw.levels[k];
                for (side, bank) in [&mut lv.left, &mut lv.right].into_iter().enumerate() {
                    let child = (k as u8 + 1, 2 * p + side as u32);
                    let leaf = pr.leaf[side] || k + 1 == self.levels;
                    bank.addr[p as usize] = if leaf { LEAF_FLAG | code(child) } else { child.1 };
                }
            }
        }
        let got = history_traverse_faulty(
            &hw,
            self.n,
            |&b| {
                let v = decode(b);
                if v.0 == 0 {
                    return Some(0.0);
                }
                pair((v.0 - 1, v.1 >> 1)).ent[(v.1 & 1) as usize].value()
            },
            &self.mutant,
        )
        .leaves;
        let mut text = String::from("tree (node = depth.index; children of d.i are d+1.2i and d+1.2i+1):\n");
        let mut decided: Vec<_> = know.iter().collect();
        decided.sort_by_key(|(v, _)| **v);
        for (v, p) in decided {
            let kind = |s: usize| {
                if p.ent[s] == Ent::Miss {
                    "miss".to_string()
                } else {
                    format!("hit at {} ({})", p.ent[s].name(), if p.leaf[s] { "leaf" } else { "inner" })
                }
            };
            text += &format!("  {}.{}: left {}, right {}\n", v.0, v.1, kind(0), kind(1));
        }
        text += "  every other inner node: left leaf hit at 0, right miss\n";
        let show =
            |ls: &[u32]| ls.iter().map(|&c| format!("{}.{}", c >> 24, c & 0xff_ffff)).collect::<Vec<_>>().join(", ");
        text += &format!("N = {}: history [{}], stack [{}]", self.n, show(&got), show(&want));
        if got != want {
            ("COUNTEREXAMPLE", text)
        } else {
            ("UNKNOWN", text + "\n(the leaves agree on this tree: the failure above proves nothing either way)")
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_depths_are_proven_and_mutants_refuted() {
        let p = prove(3, 3, true, Mutant::None, 2).unwrap();
        assert_eq!(p.status, "PROVEN", "{p:?}");
        for m in
            [Mutant::ResumeShallowest, Mutant::NoResetDeeper, Mutant::NoMarkSplit, Mutant::OnePass, Mutant::TiesRight]
        {
            let p = prove(3, 3, false, m, 2).unwrap();
            assert_eq!(p.status, "COUNTEREXAMPLE", "{m:?}: {p:?}");
            let cx = p.counterexample.unwrap();
            let (h, s) = cx.rsplit_once("history [").unwrap().1.split_once("], stack [").unwrap();
            assert_ne!(h, s.trim_end_matches(']'), "{m:?}: {cx}");
        }
        // 01 is informational: the same choices as 00 on a one-hit level
        assert_eq!(prove(3, 3, false, Mutant::NoMarkPass, 1).unwrap().status, "PROVEN");
    }
}
