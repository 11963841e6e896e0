//! The BVH in the thesis's hardware layout and its stackless traversals.
//!
//! Layout (thesis ch. 5): one subtree-level pipeline per tree level, each with two memory
//! banks. Level `k` holds, for every inner node at depth `k`, the pair of its children: the
//! left child in the left bank and the right child in the right bank, at the same address
//! (the pair index). A bank entry is the child's box and its address word: for an inner child
//! the pair index of *its* children at level `k + 1`; for a leaf, [`LEAF_FLAG`] (the MSB) set
//! and the leaf id in the low 31 bits.
//!
//! Traversals return the first N leaves in the order of the ordered stack traversal
//! (`golden::bvh::stack_traverse`): nearer child first, the right child nearer only when its
//! entry is strictly less than the left's (ties and NaN go left).

use std::fmt;

/// Address MSB: the entry is a leaf.
pub const LEAF_FLAG: u32 = 1 << 31;

/// A node of a binary BVH as built in software, before layout.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NodeDesc {
    /// Children (node indices) of an inner node; `None` for a leaf.
    pub children: Option<[u32; 2]>,
    /// Leaf id (ignored for inner nodes).
    pub leaf: u32,
    /// Box lower corner.
    pub min: [f64; 3],
    /// Box upper corner.
    pub max: [f64; 3],
}

/// Why a tree cannot be laid out.
#[derive(Clone, Debug, PartialEq)]
pub enum BvhError {
    /// The tree has more levels than the hardware has level pipelines / history width.
    TooDeep {
        /// Levels the tree needs.
        depth: usize,
        /// Levels available.
        max: usize,
    },
    /// A leaf id does not fit in 31 bits.
    LeafIdTooLarge(u32),
    /// A child index points outside the node array, or a node is reached twice.
    Malformed(String),
    /// A box cannot be stored in the box format.
    Box(String),
}

impl fmt::Display for BvhError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            BvhError::TooDeep { depth, max } => {
                write!(
                    f,
                    "tree needs {depth} levels but the hardware has {max} level pipelines (history width {} bits)",
                    2 * max
                )
            }
            BvhError::LeafIdTooLarge(id) => write!(f, "leaf id {id} does not fit in 31 bits"),
            BvhError::Malformed(m) => write!(f, "malformed tree: {m}"),
            BvhError::Box(m) => write!(f, "box cannot be stored: {m}"),
        }
    }
}

impl std::error::Error for BvhError {}

/// One memory bank of a level: boxes and address words.
#[derive(Clone, Debug, Default)]
pub struct Bank<B> {
    /// Boxes, by pair index.
    pub boxes: Vec<B>,
    /// Address words, by pair index.
    pub addr: Vec<u32>,
}

/// One tree level: the left and right banks.
#[derive(Clone, Debug, Default)]
pub struct Level<B> {
    /// Left children.
    pub left: Bank<B>,
    /// Right children.
    pub right: Bank<B>,
}

/// A BVH in the hardware layout, boxes of type `B`.
#[derive(Clone, Debug)]
pub struct HwTree<B> {
    /// The root's box.
    pub root_box: B,
    /// The root's address word (pair 0 of level 0, or a leaf).
    pub root_addr: u32,
    /// Levels 0.. (level k holds the children of depth-k nodes).
    pub levels: Vec<Level<B>>,
}

impl<B: Clone> HwTree<B> {
    /// Lays out `nodes` (rooted at `root`) for at most `max_levels` level pipelines, storing
    /// every node's box with `store(node index, node)` (e.g. the slab unit's conservative storage).
    pub fn build<E: fmt::Display>(
        nodes: &[NodeDesc],
        root: u32,
        max_levels: usize,
        mut store: impl FnMut(u32, &NodeDesc) -> Result<B, E>,
    ) -> Result<Self, BvhError> {
        let get =
            |i: u32| nodes.get(i as usize).ok_or_else(|| BvhError::Malformed(format!("node index {i} out of range")));
        let mut boxed = |i: u32, n: &NodeDesc| store(i, n).map_err(|e| BvhError::Box(e.to_string()));
        let leaf_addr = |n: &NodeDesc| {
            if n.leaf >= LEAF_FLAG {
                Err(BvhError::LeafIdTooLarge(n.leaf))
            } else {
                Ok(LEAF_FLAG | n.leaf)
            }
        };
        let r = get(root)?;
        let root_box = boxed(root, r)?;
        let mut seen = vec![false; nodes.len()];
        seen[root as usize] = true;
        let Some(rc) = r.children else {
            return Ok(HwTree { root_box, root_addr: leaf_addr(r)?, levels: Vec::new() });
        };
        let mut levels: Vec<Level<B>> = Vec::new();
        let mut frontier: Vec<[u32; 2]> = vec![rc]; // pairs at the current level, by pair index
        while !frontier.is_empty() {
            if levels.len() == max_levels {
                // count the remaining depth for the message
                let mut depth = levels.len();
                let mut f = frontier.clone();
                while !f.is_empty() {
                    depth += 1;
                    f = f.iter().flatten().filter_map(|&c| nodes.get(c as usize).and_then(|n| n.children)).collect();
                }
                return Err(BvhError::TooDeep { depth, max: max_levels });
            }
            let mut level = Level {
                left: Bank { boxes: Vec::new(), addr: Vec::new() },
                right: Bank { boxes: Vec::new(), addr: Vec::new() },
            };
            let mut next = Vec::new();
            for pair in &frontier {
                for (side, &c) in pair.iter().enumerate() {
                    let n = get(c)?;
                    if std::mem::replace(&mut seen[c as usize], true) {
                        return Err(BvhError::Malformed(format!("node {c} is reached twice")));
                    }
                    let addr = match n.children {
                        None => leaf_addr(n)?,
                        Some(cc) => {
                            next.push(cc);
                            (next.len() - 1) as u32
                        }
                    };
                    let bank = if side == 0 { &mut level.left } else { &mut level.right };
                    bank.boxes.push(boxed(c, n)?);
                    bank.addr.push(addr);
                }
            }
            levels.push(level);
            frontier = next;
        }
        Ok(HwTree { root_box, root_addr: 0, levels })
    }
}

impl<B> HwTree<B> {
    /// Number of levels (level pipelines needed).
    pub fn depth(&self) -> usize {
        self.levels.len()
    }
}

/// The 2-bit ray history states of one level.
pub mod hist {
    /// 00: the ray has not traversed this level on its current path.
    pub const NEW: u8 = 0b00;
    /// 01: one child was hit here; pass through to it.
    pub const PASS: u8 = 0b01;
    /// 10: both children were hit here; the nearer is being explored.
    pub const SPLIT: u8 = 0b10;
    /// 11: both children were hit and the nearer subtree is done; the farther is taken.
    pub const DONE: u8 = 0b11;
}

/// The result of a stackless traversal.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct StacklessResult {
    /// Leaf ids in visiting order (at most N).
    pub leaves: Vec<u32>,
    /// Passes from the root (restarts + 1; 0 when the root missed).
    pub passes: u64,
    /// Box tests performed (the root once, two per level visited).
    pub box_tests: u64,
    /// Per restart: the distance in levels between the level where the previous pass ended
    /// and the level where the next one turns to the farther child (the thesis's back-traversal
    /// distance, fig. 3-5).
    pub back_distances: Vec<u32>,
    /// Pairs where both children hit with equal entry t (a tie; compared as numbers, so -0 =
    /// +0), counted per choice made there: `[the nearer (left) child taken, the farther (right)
    /// child taken]`. Ties go left first; the right is taken on resuming the pair (10 → 11) or
    /// passing through it in 11 (the trail: its bit set).
    pub ties: [u64; 2],
    /// The final per-level state (2-bit history or 1-bit trail).
    pub state: Vec<u8>,
}

impl StacklessResult {
    /// Empty, with a state of `depth` levels in 00 (the buffers kept).
    fn reset(&mut self, depth: usize) {
        // every field named: a new one must be reset here too
        let StacklessResult { leaves, passes, box_tests, back_distances, ties, state } = self;
        leaves.clear();
        (*passes, *box_tests, *ties) = (0, 0, [0; 2]);
        back_distances.clear();
        state.clear();
        state.resize(depth, hist::NEW);
    }
}

/// The ray's entry into the tree: tests the root box; a miss, N = 0 or a root leaf (emitted)
/// finishes the ray (false); otherwise the passes begin (true).
fn enter<B>(t: &HwTree<B>, n: usize, test: &mut impl FnMut(&B) -> Option<f64>, r: &mut StacklessResult) -> bool {
    if n == 0 {
        return false;
    }
    r.box_tests += 1;
    if test(&t.root_box).is_none() {
        return false;
    }
    if t.root_addr & LEAF_FLAG != 0 {
        r.passes = 1;
        r.leaves.push(t.root_addr & !LEAF_FLAG);
        return false;
    }
    true
}

/// One pass from the root: at each level the pair of children is tested and `choose(level,
/// left entry, right entry)` picks the side to follow (`None` ends the pass at a dead end); a
/// leaf reached is emitted. Returns the level where the pass ended.
fn pass<B>(
    t: &HwTree<B>,
    test: &mut impl FnMut(&B) -> Option<f64>,
    box_tests: &mut u64,
    leaves: &mut Vec<u32>,
    mut choose: impl FnMut(usize, Option<f64>, Option<f64>) -> Option<usize>,
) -> usize {
    let mut idx = t.root_addr;
    let mut level = 0;
    loop {
        *box_tests += 2;
        let (el, er) = test_pair(t, level, idx, test);
        let Some(side) = choose(level, el, er) else { return level };
        let a = addr_of(t, level, idx, side);
        if a & LEAF_FLAG != 0 {
            leaves.push(a & !LEAF_FLAG);
            return level;
        }
        idx = a;
        level += 1;
    }
}

/// Tests the pair at `level`/`idx`: (left hit entry, right hit entry).
fn test_pair<B>(
    t: &HwTree<B>,
    level: usize,
    idx: u32,
    test: &mut impl FnMut(&B) -> Option<f64>,
) -> (Option<f64>, Option<f64>) {
    let lv = &t.levels[level];
    (test(&lv.left.boxes[idx as usize]), test(&lv.right.boxes[idx as usize]))
}

/// Nearer/farther side (0 = left, 1 = right) of a pair where both children hit.
fn near_far(el: f64, er: f64) -> (usize, usize) {
    if er < el {
        (1, 0)
    } else {
        (0, 1)
    }
}

fn addr_of<B>(t: &HwTree<B>, level: usize, idx: u32, side: usize) -> u32 {
    let lv = &t.levels[level];
    if side == 0 {
        lv.left.addr[idx as usize]
    } else {
        lv.right.addr[idx as usize]
    }
}

/// The thesis's 2-bit-per-level ray history traversal: restart from the root instead of a
/// stack. Per level, on each pass (see [`hist`]):
///
/// | state | both hit | one hit | none hit |
/// |---|---|---|---|
/// | 00 NEW | go near, → 10 | go to it, → 01 | end the pass |
/// | 01 PASS | – | go to it | – |
/// | 10 SPLIT, the deepest 10 at pass start | go far, → 11, deeper levels → 00 | – | – |
/// | 10 SPLIT, not the deepest | go near | – | – |
/// | 11 DONE | go far | – | – |
///
/// A pass ends at a leaf (emitted) or at a level with no hit. The traversal ends after N
/// leaves or when no level is in state 10 at the end of a pass.
pub fn history_traverse<B>(t: &HwTree<B>, n: usize, test: impl FnMut(&B) -> Option<f64>) -> StacklessResult {
    history_traverse_faulty(t, n, test, &crate::fault::NoFault)
}

/// [`history_traverse`] with its control logic computed by `x` (a hardware fault;
/// [`crate::fault::NoFault`] is the traversal itself). Sites: the ordering `near` (the right
/// child is nearer when its entry t < the left's), the logic bits `mark_split` (a level where
/// both children hit goes to 10), `mark_pass` (one child hit goes to 01), `resume` (the pass
/// resumes at the deepest 10; false: the shallowest), `reset_deeper` (after 10 → 11 the deeper
/// levels go to 00) and `more` (a level is in 10 after the pass, so another pass follows), and
/// the limit `n_limit` (the traversal ends after this many leaves).
pub fn history_traverse_faulty<B, X: crate::fault::Logic>(
    t: &HwTree<B>,
    n: usize,
    test: impl FnMut(&B) -> Option<f64>,
    x: &X,
) -> StacklessResult {
    let mut r = StacklessResult::default();
    history_traverse_faulty_into(t, n, test, x, &mut r);
    r
}

/// [`history_traverse`] into `r`, whose previous contents are dropped and whose buffers are
/// reused (no allocation once they have grown: a ray loop's form).
pub fn history_traverse_into<B>(t: &HwTree<B>, n: usize, test: impl FnMut(&B) -> Option<f64>, r: &mut StacklessResult) {
    history_traverse_faulty_into(t, n, test, &crate::fault::NoFault, r)
}

/// [`history_traverse_faulty`] into `r` (as [`history_traverse_into`]).
pub fn history_traverse_faulty_into<B, X: crate::fault::Logic>(
    t: &HwTree<B>,
    n: usize,
    mut test: impl FnMut(&B) -> Option<f64>,
    x: &X,
    r: &mut StacklessResult,
) {
    r.reset(t.depth());
    if !enter(t, n, &mut test, r) {
        return;
    }
    let n_limit = x.limit("n_limit", n);
    let mut prev_end = None;
    while history_pass_faulty(t, n_limit, &mut test, r, &mut prev_end, x) {}
}

/// One pass of [`history_traverse_faulty`] from the root, on a ray whose root box was hit
/// and whose state `r` holds the history between passes (`prev_end`: the level where the
/// previous pass ended). True when another pass follows: fewer than `n_limit` leaves and a
/// level in 10. The box tests and choices are exactly those of the whole traversal, which
/// is this function in a loop (the formal proof drives it pass by pass).
pub fn history_pass_faulty<B, X: crate::fault::Logic>(
    t: &HwTree<B>,
    n_limit: usize,
    mut test: impl FnMut(&B) -> Option<f64>,
    r: &mut StacklessResult,
    prev_end: &mut Option<usize>,
    x: &X,
) -> bool {
    // (nearer, farther) side of a pair where both children hit
    let near_far = |el: f64, er: f64| if x.less("near", er, el) { (1, 0) } else { (0, 1) };
    let h = &mut r.state;
    r.passes += 1;
    let resume = if x.flag("resume", true) {
        h.iter().rposition(|&s| s == hist::SPLIT)
    } else {
        h.iter().position(|&s| s == hist::SPLIT)
    };
    if let (Some(end), Some(k)) = (*prev_end, resume) {
        r.back_distances.push(end.abs_diff(k) as u32);
    }
    let ties = &mut r.ties;
    let mut tie = |a: f64, b: f64, far: bool| {
        if a == b {
            ties[far as usize] += 1;
        }
    };
    let end = pass(t, &mut test, &mut r.box_tests, &mut r.leaves, |level, el, er| {
        match (h[level], el, er) {
            (hist::NEW, Some(a), Some(b)) => {
                if x.flag("mark_split", true) {
                    h[level] = hist::SPLIT;
                }
                tie(a, b, false);
                Some(near_far(a, b).0)
            }
            (hist::NEW, Some(_), None) | (hist::PASS, Some(_), None) => {
                if x.flag("mark_pass", true) {
                    h[level] = hist::PASS;
                }
                Some(0)
            }
            (hist::NEW, None, Some(_)) | (hist::PASS, None, Some(_)) => {
                if x.flag("mark_pass", true) {
                    h[level] = hist::PASS;
                }
                Some(1)
            }
            (hist::SPLIT, Some(a), Some(b)) if resume == Some(level) => {
                h[level] = hist::DONE;
                if x.flag("reset_deeper", true) {
                    h[level + 1..].fill(hist::NEW);
                }
                tie(a, b, true);
                Some(near_far(a, b).1)
            }
            (hist::SPLIT, Some(a), Some(b)) => {
                tie(a, b, false);
                Some(near_far(a, b).0)
            }
            (hist::DONE, Some(a), Some(b)) => {
                tie(a, b, true);
                Some(near_far(a, b).1)
            }
            // NEW with no hit: dead end. Other combinations cannot occur with a
            // deterministic tester; they end the pass as a dead end too.
            _ => None,
        }
    });
    *prev_end = Some(end);
    r.leaves.len() < n_limit && x.flag("more", r.state.contains(&hist::SPLIT))
}

/// Laine's restart trail (HPG 2010), one bit per level: 0 = take the nearer child, 1 = take the
/// farther (or the only hit) child. A single hit sets the bit (no alternative remains); a level
/// with no hit ends the pass and sets its bit. After a pass, the deepest 0 at or above the level
/// where it ended becomes 1 and every deeper bit 0; no such 0 ends the traversal.
pub fn trail_traverse<B>(t: &HwTree<B>, n: usize, mut test: impl FnMut(&B) -> Option<f64>) -> StacklessResult {
    let mut r = StacklessResult { state: vec![0; t.depth()], ..Default::default() };
    if !enter(t, n, &mut test, &mut r) {
        return r;
    }
    let trail = &mut r.state;
    loop {
        r.passes += 1;
        let end = pass(t, &mut test, &mut r.box_tests, &mut r.leaves, |level, el, er| match (el, er) {
            (Some(a), Some(b)) => {
                let (near, far) = near_far(a, b);
                if a == b {
                    r.ties[trail[level] as usize] += 1;
                }
                Some(if trail[level] == 0 { near } else { far })
            }
            (Some(_), None) => {
                trail[level] = 1;
                Some(0)
            }
            (None, Some(_)) => {
                trail[level] = 1;
                Some(1)
            }
            (None, None) => {
                trail[level] = 1;
                None
            }
        });
        if r.leaves.len() == n {
            break;
        }
        match trail[..=end].iter().rposition(|&b| b == 0) {
            Some(k) => {
                r.back_distances.push((end - k) as u32);
                trail[k] = 1;
                trail[k + 1..].fill(0);
            }
            None => break,
        }
    }
    r
}
