//! The `traverse` unit: a BVH in the thesis's hardware layout as per-level, per-bank BRAM
//! images, a ray stream, and per ray the expected first-N leaves, pass and box-test counts and
//! the final 2-bit history of every level (the 2-bit ray history traversal with the slab unit
//! as the box tester, cross-checked against the golden stack traversal when written).
//!
//! Coverage classes are *observed*: candidate rays come from named generators and a ray counts
//! for a class only when its traversal shows the property (a tie between siblings, a leaf at
//! the deepest level, three or more passes, the N limit reached, ...).

use crate::manifest::Kind;
use crate::rows::{is_float, Layout, Rows};
use datapath::bvh::{hist, history_traverse_faulty, HwTree, Level, NodeDesc, StacklessResult, LEAF_FLAG};
use datapath::fault::{Logic, NoFault};
use datapath::rng::SplitMix64;
use datapath::slab::{Aabb, Slab, SlabConfig};
use datapath::Format;
use std::collections::BTreeMap;

/// A scene's BVH before hardware layout, as the vector writer takes it.
#[derive(Clone, Debug)]
pub struct TreeInput {
    /// Scene name (recorded in the manifest).
    pub name: String,
    /// Nodes with exact f64 boxes.
    pub nodes: Vec<NodeDesc>,
    /// Root node index.
    pub root: u32,
}

/// Coverage classes of the traverse unit.
pub const TRAVERSE_CLASSES: [(&str, &str); 9] = [
    ("primary", "camera rays from in front of the scene (looking +z)"),
    ("random", "origin inside the scene bounds, uniform random direction"),
    ("miss", "origin outside the root box, pointing away: the root test misses"),
    ("tie", "both children of a pair hit with equal entry t (the left is taken first) on the ray's path"),
    ("deepest", "a leaf at the tree's deepest level is emitted (the deepest path)"),
    ("restarts", "three or more passes from the root"),
    ("n_limit", "the traversal stops at N leaves"),
    ("axis", "axis-parallel direction (two direction components +0 or -0)"),
    ("inf_nan", "one ray input +inf, -inf or NaN (floats only)"),
];

/// Level 2: rays of generator `g` (a level-1 class) that also show property `k`.
const CROSS_GENERATORS: [usize; 5] = [0, 1, 4, 7, 8];
const CROSS_PROPERTIES: [usize; 4] = [3, 4, 5, 6];

/// The classes of a level as (generator, extra property): level 1 each class on its own,
/// level 2 adds every generator crossed with every observed property.
fn crosses(level: u32) -> Vec<(usize, Option<usize>)> {
    let mut v: Vec<_> = (0..TRAVERSE_CLASSES.len()).map(|c| (c, None)).collect();
    if level >= 2 {
        for g in CROSS_GENERATORS {
            for k in CROSS_PROPERTIES {
                if g != k {
                    v.push((g, Some(k)));
                }
            }
        }
    }
    v
}

/// Class names and descriptions of a level, in class-id order.
pub(crate) fn classes(level: u32) -> Vec<(String, String)> {
    crosses(level)
        .into_iter()
        .map(|(g, k)| match k {
            None => (TRAVERSE_CLASSES[g].0.into(), TRAVERSE_CLASSES[g].1.into()),
            Some(k) => (
                format!("{}+{}", TRAVERSE_CLASSES[g].0, TRAVERSE_CLASSES[k].0),
                format!("{}; and {}", TRAVERSE_CLASSES[g].1, TRAVERSE_CLASSES[k].1),
            ),
        })
        .collect()
}

/// Address word width of a bank entry.
const ADDR_W: u32 = 32;

fn depth_of(nodes: &[NodeDesc], root: u32) -> (Vec<u32>, u32) {
    // depth of every node (root 0) and the depth of the deepest leaf
    let mut depth = vec![0u32; nodes.len()];
    let mut stack = vec![root];
    let mut deepest = 0;
    while let Some(i) = stack.pop() {
        match nodes[i as usize].children {
            Some(c) => {
                for k in c {
                    depth[k as usize] = depth[i as usize] + 1;
                    stack.push(k);
                }
            }
            None => deepest = deepest.max(depth[i as usize]),
        }
    }
    (depth, deepest)
}

/// What one ray did.
struct Observed {
    result: StacklessResult,
    tie: bool,
    deepest: bool,
}

/// Runs one ray (format bits of o, d, tmin, tmax) through the history traversal, its control
/// logic computed by `x`.
fn run<F: Format, X: Logic>(
    s: &Slab<F>,
    hw: &HwTree<Aabb<F::V>>,
    n: usize,
    bits: &[u64],
    leaf_depth: &BTreeMap<u32, u32>,
    deepest: u32,
    x: &X,
) -> Observed {
    let f = &s.fmt;
    let q = |i: usize| f.to_f64(f.from_bits(bits[i]));
    let ray = s.prepare([q(0), q(1), q(2)], [q(3), q(4), q(5)], q(6), q(7));
    let mut tie = false;
    let mut calls = 0usize; // call 0 tests the root, then (left, right) pairs
    let mut left: Option<F::V> = None;
    let result = history_traverse_faulty(
        hw,
        n,
        |b| {
            let o = s.test(&ray, b);
            let t = o.hit.then_some(o.t_near);
            if calls > 0 && calls % 2 == 1 {
                left = t;
            } else if let (true, Some(a), Some(b)) = (calls > 0, left, t) {
                tie |= f.le(a, b) && f.le(b, a);
            }
            calls += 1;
            t.map(|v| f.to_f64(v))
        },
        x,
    );
    let deep = result.leaves.iter().any(|l| leaf_depth.get(l) == Some(&deepest));
    Observed { result, tie, deepest: deep }
}

/// Candidate ray of a class (f64: o, d, tmin, tmax).
fn candidate(class: usize, r: &mut SplitMix64, lo: [f64; 3], hi: [f64; 3], deep_box: ([f64; 3], [f64; 3])) -> [f64; 8] {
    let c: [f64; 3] = std::array::from_fn(|a| (lo[a] + hi[a]) / 2.0);
    let ext = (0..3).map(|a| hi[a] - lo[a]).fold(0.0, f64::max).max(1e-6);
    let inside = |r: &mut SplitMix64| -> [f64; 3] { std::array::from_fn(|a| r.range(lo[a], hi[a])) };
    let sphere = |r: &mut SplitMix64| -> [f64; 3] {
        let z = r.range(-1.0, 1.0);
        let phi = r.range(0.0, std::f64::consts::TAU);
        let s = (1.0 - z * z).sqrt();
        [s * phi.cos(), s * phi.sin(), z]
    };
    let (o, d) = match class {
        0 => {
            let eye = [c[0], c[1], lo[2] - 1.5 * ext];
            ([eye[0], eye[1], eye[2]], [r.range(-0.4, 0.4), r.range(-0.4, 0.4), 1.0])
        }
        2 => {
            let dir = sphere(r);
            let o: [f64; 3] = std::array::from_fn(|a| c[a] + dir[a] * 2.0 * ext);
            (o, dir)
        }
        3 => {
            // origin inside the scene: siblings that both contain it tie at t = tmin
            (inside(r), sphere(r))
        }
        4 => {
            let o = if r.below(2) == 0 { inside(r) } else { std::array::from_fn(|a| c[a] + sphere(r)[a] * 2.0 * ext) };
            let target: [f64; 3] = std::array::from_fn(|a| r.range(deep_box.0[a], deep_box.1[a]));
            (o, std::array::from_fn(|a| target[a] - o[a]))
        }
        7 => {
            let mut d = [0.0f64; 3];
            let a = r.below(3) as usize;
            d[a] = if r.below(2) == 0 { 1.0 } else { -1.0 };
            for (b, v) in d.iter_mut().enumerate() {
                if b != a && r.below(2) == 0 {
                    *v = -0.0;
                }
            }
            (inside(r), d)
        }
        _ => (inside(r), sphere(r)),
    };
    let mut x = [o[0], o[1], o[2], d[0], d[1], d[2], 0.0, f64::INFINITY];
    if class == 8 {
        let i = r.below(8) as usize;
        x[i] = [f64::INFINITY, f64::NEG_INFINITY, f64::NAN][r.below(3) as usize];
    }
    x
}

fn keeps(class: usize, o: &Observed, n: usize) -> bool {
    match class {
        2 => o.result.passes == 0,
        3 => o.tie,
        4 => o.deepest,
        5 => o.result.passes >= 3,
        6 => o.result.leaves.len() == n,
        _ => true,
    }
}

/// The expected row of one ray.
fn expected_row(o: &StacklessResult, n: usize, depth: usize) -> Vec<u64> {
    let mut row = vec![o.leaves.len() as u64];
    row.extend((0..n).map(|i| o.leaves.get(i).map_or(0, |&l| l as u64)));
    row.push(o.passes.min(u16::MAX as u64));
    row.push(o.box_tests.min(u32::MAX as u64));
    row.extend((0..depth).map(|l| o.state.get(l).map_or(hist::NEW, |&s| s) as u64));
    row
}

/// Layout of the expected file.
pub(crate) fn expected_layout(n: usize, depth: usize) -> Layout {
    let mut l = vec![("count".to_string(), "out", Kind::Uint, 8, None)];
    l.extend((0..n).map(|i| (format!("leaf_{i}"), "out", Kind::Uint, 32, None)));
    l.push(("passes".into(), "out", Kind::Uint, 16, None));
    l.push(("box_tests".into(), "out", Kind::Uint, 32, None));
    l.extend((0..depth).map(|i| (format!("hist_{i}"), "out", Kind::Uint, 2, None)));
    Layout(l)
}

fn entry_layout(k: &Kind, w: u32) -> Layout {
    let mut l: Vec<_> = ["minx", "miny", "minz", "maxx", "maxy", "maxz"]
        .iter()
        .map(|n| (n.to_string(), "in", k.clone(), w, None))
        .collect();
    l.push(("addr".into(), "in", Kind::Uint, ADDR_W, None));
    Layout(l)
}

fn entry_bits<F: Format>(f: &F, b: &Aabb<F::V>, addr: u32) -> Vec<u64> {
    let mut v: Vec<u64> = b.min.iter().chain(b.max.iter()).map(|&x| f.to_bits(x)).collect();
    v.push(addr as u64);
    v
}

/// Everything the traverse unit adds to a set.
pub(crate) struct TraverseParts {
    pub files: Vec<Rows>,
    pub counts: Vec<usize>,
    pub params: BTreeMap<String, u64>,
    pub options: BTreeMap<String, String>,
}

/// Ray stream input names.
pub(crate) const RAY_INPUTS: [&str; 8] = ["ox", "oy", "oz", "dx", "dy", "dz", "tmin", "tmax"];

/// Builds the traverse files for format `f`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn generate<F: Format>(
    f: F,
    variant: &str,
    tree: &TreeInput,
    n: usize,
    max_levels: usize,
    count: usize,
    seed: u64,
    level: u32,
    rays_layout: Layout,
    closure: Option<&crate::gen::Explicit>,
) -> Result<TraverseParts, String> {
    if n == 0 || n > 255 {
        return Err(format!("--leaves must be 1..=255, got {n}"));
    }
    let sc = SlabConfig::named_for(variant, &f)?;
    if sc.directed {
        return Err("the traverse unit's box tester supports plain, conservative, take-on-false and embree".into());
    }
    let s = Slab::new(f, sc);
    let hw: HwTree<Aabb<F::V>> = HwTree::build(&tree.nodes, tree.root, max_levels, |_, nd| s.store_box(nd.min, nd.max))
        .map_err(|e| e.to_string())?;
    let depth = hw.depth();
    let (node_depth, deepest) = depth_of(&tree.nodes, tree.root);
    let leaf_depth: BTreeMap<u32, u32> = tree
        .nodes
        .iter()
        .enumerate()
        .filter(|(_, nd)| nd.children.is_none())
        .map(|(i, nd)| (nd.leaf, node_depth[i]))
        .collect();
    let deep_node = (0..tree.nodes.len())
        .find(|&i| tree.nodes[i].children.is_none() && node_depth[i] == deepest)
        .ok_or("tree has no leaf")?;
    let deep_box = (tree.nodes[deep_node].min, tree.nodes[deep_node].max);
    let root = &tree.nodes[tree.root as usize];
    let golden = golden_tree(&tree.nodes, tree.root);
    let w = f.width();
    let k = crate::rows::kind_of(&f);
    let mut files = vec![
        Rows::new("traverse_rays.hex", "inputs: the ray stream", rays_layout),
        Rows::new("traverse_expected.hex", "expected outputs per ray", expected_layout(n, depth)),
        Rows::new("tree_root.hex", "BRAM image: the root entry (box, address word)", entry_layout(&k, w)),
    ];
    files[2].push(&entry_bits(&f, &hw.root_box, hw.root_addr));
    for (l, Level { left, right }) in hw.levels.iter().enumerate() {
        for (side, bank) in [("left", left), ("right", right)] {
            let mut rows = Rows::new(
                &format!("tree_l{l}_{side}.hex"),
                "BRAM image: one level's bank, row = pair index",
                entry_layout(&k, w),
            );
            for (b, &a) in bank.boxes.iter().zip(&bank.addr) {
                rows.push(&entry_bits(&f, b, a));
            }
            files.push(rows);
        }
    }
    let crosses = crosses(level);
    let float = is_float(&f);
    // a ray's rows (class c), once the hardware traversal is checked against the stack
    // traversal: it must visit the same leaves, in order
    let rows_of = |c: usize, bits: &[u64], o: &Observed| -> Result<Vec<Vec<u64>>, String> {
        let xs = |i: usize| f.to_f64(f.from_bits(bits[i]));
        let ray = s.prepare([xs(0), xs(1), xs(2)], [xs(3), xs(4), xs(5)], xs(6), xs(7));
        let g = golden::bvh::stack_traverse(&golden, n, |i| {
            let nd = &tree.nodes[i as usize];
            let b = s.store_box(nd.min, nd.max).ok()?;
            let out = s.test(&ray, &b);
            out.hit.then(|| f.to_f64(out.t_near))
        });
        if g.leaves != o.result.leaves {
            return Err(format!(
                "history traversal differs from the stack traversal (class {c}, ray {bits:x?}): {:?} vs {:?}",
                o.result.leaves, g.leaves
            ));
        }
        let mut row = vec![c as u64];
        row.extend_from_slice(bits);
        Ok(vec![row, expected_row(&o.result, n, depth)])
    };
    let mut per_class = crate::rows::per_class_rows(seed, crosses.len(), count, |c, r| {
        let (gen, keep) = crosses[c];
        if gen == 8 && !float {
            return Ok(None);
        }
        for _ in 0..400 {
            let x = candidate(gen, r, root.min, root.max, deep_box);
            let bits: Vec<u64> = x.iter().map(|&v| f.to_bits(f.from_f64(v))).collect();
            let o = run(&s, &hw, n, &bits, &leaf_depth, deepest, &NoFault);
            if !keeps(gen, &o, n) || !keep.is_none_or(|k| keeps(k, &o, n)) {
                continue;
            }
            return rows_of(c, &bits, &o).map(Some);
        }
        Ok(None) // the class is rare or impossible on this tree: its count says so
    })?;
    if let Some(cl) = closure {
        let c = crosses.len();
        let mut rows = Vec::with_capacity(cl.rows.len());
        for bits in &cl.rows {
            if bits.len() != RAY_INPUTS.len() {
                return Err(format!("a closure ray has {} fields, not {}", bits.len(), RAY_INPUTS.len()));
            }
            let bits: Vec<u64> = bits.iter().map(|&b| f.to_bits(f.from_bits(b))).collect();
            let o = run(&s, &hw, n, &bits, &leaf_depth, deepest, &NoFault);
            rows.push(rows_of(c, &bits, &o)?);
        }
        per_class.push(rows);
    }
    let counts = crate::rows::push_rows(&mut files[..2], per_class);
    let mut params = BTreeMap::new();
    params.insert("leaves".into(), n as u64);
    params.insert("levels".into(), depth as u64);
    params.insert("max_levels".into(), max_levels as u64);
    params.insert("slab_guard".into(), sc.guard as u64);
    params.insert("slab_take_on_false".into(), (sc.nan == datapath::slab::SlabNan::TakeOnFalse) as u64);
    params.insert("slab_embree".into(), (sc.prep == datapath::slab::DirPrep::Embree) as u64);
    params.insert("slab_delta".into(), f.to_bits(s.delta()));
    params.insert("slab_widen_ulps".into(), u64::try_from(sc.widen_ulps).map_err(|_| "negative widening")?);
    let mut options = BTreeMap::new();
    options.insert("scene".into(), tree.name.clone());
    options.insert("variant".into(), variant.to_string());
    crate::rows::slab_options(&mut options, &sc);
    options.insert("input_read".into(), crate::rows::input_read(&f));
    options.insert(
        "traversal".into(),
        "2-bit ray history, restart from the root (raypipe README, section 'BVH traversal: the 2-bit ray history'); the right child is nearer only when its entry t_near is less than the left's (format compare), ties and NaN go left".into(),
    );
    options.insert(
        "address_word".into(),
        "bit 31 set: a leaf, bits 30..0 its id; clear: the pair index of the child's children at the next level; the root entry's address word is pair 0 of level 0 (or a leaf)".into(),
    );
    options.insert(
        "history".into(),
        "hist_k: level k's final 2-bit state, 00 new, 01 one child hit, 10 both hit and the nearer being explored, 11 the farther taken".into(),
    );
    Ok(TraverseParts { files, counts, params, options })
}

/// The same tree for the golden stack traversal (node indices kept).
pub fn golden_tree(nodes: &[NodeDesc], root: u32) -> golden::bvh::Tree {
    use golden::bvh::Node;
    golden::bvh::Tree {
        nodes: nodes
            .iter()
            .map(|n| match n.children {
                Some([l, r]) => Node::Inner { left: l, right: r },
                None => Node::Leaf { leaf: n.leaf },
            })
            .collect(),
        root: Some(root),
    }
}

/// The unpacked rows of one level's (left, right) bank images.
pub type BankRows = (Vec<Vec<u64>>, Vec<Vec<u64>>);

/// Rebuilds the tree from a set's BRAM images (rows of unpacked fields) and re-runs every ray:
/// the expected rows.
pub(crate) fn recheck<F: Format>(
    f: F,
    variant: &str,
    n: usize,
    root: &[u64],
    banks: &[BankRows],
    rays: &[Vec<u64>],
) -> Result<Vec<Vec<u64>>, String> {
    let s = Slab::new(f, SlabConfig::named(variant)?);
    let hw = tree_from_images(&s, root, banks)?;
    Ok(rays.iter().map(|ray| ray_row(&s, &hw, n, &ray[1..], &NoFault)).collect())
}

/// The tree a set's BRAM images hold (rows of unpacked fields: the root entry, then per level
/// the left and right banks), every address word checked to point at a row of the next level.
pub fn tree_from_images<F: Format>(
    s: &Slab<F>,
    root: &[u64],
    banks: &[BankRows],
) -> Result<HwTree<Aabb<F::V>>, String> {
    let f = &s.fmt;
    let entry = |row: &[u64]| -> (Aabb<F::V>, u32) {
        let v = |i: usize| f.from_bits(row[i]);
        (Aabb { min: [v(0), v(1), v(2)], max: [v(3), v(4), v(5)] }, row[6] as u32)
    };
    let (root_box, root_addr) = entry(root);
    let levels = banks
        .iter()
        .map(|(l, r)| {
            let bank = |rows: &Vec<Vec<u64>>| {
                let (boxes, addr) = rows.iter().map(|x| entry(x)).unzip();
                datapath::bvh::Bank { boxes, addr }
            };
            Level { left: bank(l), right: bank(r) }
        })
        .collect();
    let hw = HwTree { root_box, root_addr, levels };
    // every address word must point at a row of the next level (or be a leaf)
    let bad = |what: String| Err(format!("malformed tree images: {what}"));
    if root_addr & LEAF_FLAG == 0 && (root_addr != 0 || hw.levels.is_empty()) {
        return bad(format!("root address word {root_addr:#x} is neither a leaf nor pair 0 of level 0"));
    }
    for (l, lv) in hw.levels.iter().enumerate() {
        if lv.left.addr.len() != lv.right.addr.len() {
            return bad(format!("level {l}: the banks have different row counts"));
        }
        let next = hw.levels.get(l + 1).map_or(0, |x| x.left.addr.len());
        for &a in lv.left.addr.iter().chain(&lv.right.addr) {
            if a & LEAF_FLAG == 0 && a as usize >= next {
                return bad(format!("level {l}: address word {a:#x} points past level {}'s {next} rows", l + 1));
            }
        }
    }
    Ok(hw)
}

/// The expected row of one ray (`bits`: o, d, tmin, tmax encodings) on `hw`, first `n`
/// leaves, with the traversal's control logic computed by `x` (`NoFault`: the rows a set holds).
pub fn ray_row<F: Format, X: Logic>(s: &Slab<F>, hw: &HwTree<Aabb<F::V>>, n: usize, bits: &[u64], x: &X) -> Vec<u64> {
    let empty = BTreeMap::new();
    expected_row(&run(s, hw, n, bits, &empty, u32::MAX, x).result, n, hw.depth())
}

/// The expected `traverse_expected.hex` fields of one f64 ray on `tree` in format `f`: count,
/// N leaf ids (0-padded), passes, box tests, and each level's final 2-bit history state.
pub fn expected_for<F: Format>(
    f: F,
    variant: &str,
    tree: &TreeInput,
    n: usize,
    max_levels: usize,
    ray: [f64; 8],
) -> Result<Vec<u64>, String> {
    let s = Slab::new(f, SlabConfig::named(variant)?);
    let hw: HwTree<Aabb<F::V>> = HwTree::build(&tree.nodes, tree.root, max_levels, |_, nd| s.store_box(nd.min, nd.max))
        .map_err(|e| e.to_string())?;
    let bits: Vec<u64> = ray.iter().map(|&v| f.to_bits(f.from_f64(v))).collect();
    let empty = BTreeMap::new();
    Ok(expected_row(&run(&s, &hw, n, &bits, &empty, u32::MAX, &NoFault).result, n, hw.depth()))
}

/// What a ray's traversal did that its expected row does not hold: the back-traversal
/// distance of each restart and the ties between siblings (coverage events; [`PathReplay`]).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct PathEvents {
    /// Per restart, the levels between where the previous pass ended and where the next one
    /// turns to the farther child.
    pub back_distances: Vec<u32>,
    /// Ties (both children hit at equal entry t): `[nearer (left) taken, farther (right) taken]`.
    pub ties: [u64; 2],
}

type ReplayFn = dyn Fn(&[u64]) -> PathEvents + Send + Sync;

/// A traverse set's tree and slab tester, rebuilt from its BRAM images, that re-runs a ray of
/// the set: the path events of its traversal (the same traversal as the set's expected rows).
pub struct PathReplay(Box<ReplayFn>);

impl PathReplay {
    /// The replay of the traverse set with manifest `m` and rows `contents` (its files in
    /// manifest order; the per-vector files may be empty, the tree images must be whole).
    pub fn from_set(m: &crate::manifest::Manifest, contents: &[Vec<Vec<u64>>]) -> Result<Self, String> {
        let any: datapath::AnyFormat = m.format.parse().map_err(|e| format!("manifest.json: field format: {e}"))?;
        let n = m.params.get("leaves").copied().ok_or("manifest has no leaves parameter")? as usize;
        let variant = m.options.get("variant").map_or("plain", |s| s.as_str()).to_string();
        let (root, images) = crate::read::tree_images(m, contents)?;
        let banks: Vec<BankRows> = images.into_iter().map(|(a, b)| (a.clone(), b.clone())).collect();
        datapath::with_format!(any, |f| {
            let s = Slab::new(f, SlabConfig::named(&variant)?);
            let hw = tree_from_images(&s, root, &banks)?;
            let empty = BTreeMap::new();
            Ok(PathReplay(Box::new(move |bits: &[u64]| {
                let r = run(&s, &hw, n, bits, &empty, u32::MAX, &NoFault).result;
                PathEvents { back_distances: r.back_distances, ties: r.ties }
            })))
        })
    }

    /// The path events of the ray with input row `ray` (class id, then o, d, tmin, tmax).
    pub fn events(&self, ray: &[u64]) -> PathEvents {
        match ray.get(1..) {
            Some(bits) if bits.len() == RAY_INPUTS.len() => (self.0)(bits),
            _ => PathEvents::default(),
        }
    }
}
