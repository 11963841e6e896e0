//! The stackless traversals (2-bit ray history, 1-bit restart trail) against the ordered stack
//! traversal of `golden`: the same leaves in the same order, for every N, with the same box
//! tester — on balanced, degenerate (chain) and random trees, with ties, NaN and signed-zero
//! entry distances, rays hitting one child, both or none; and with the real slab unit.

use datapath::bvh::{
    hist, history_traverse, history_traverse_into, trail_traverse, BvhError, HwTree, NodeDesc, StacklessResult,
};
use datapath::rng::SplitMix64;
use datapath::slab::{Slab, SlabConfig};
use datapath::{with_format, AnyFormat, Format};
use golden::bvh::{stack_traverse, Node, Tree};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed};

#[derive(Clone, Copy, Debug)]
enum Shape {
    Balanced,
    Chain,
    Random,
}

/// A tree with `leaves` leaves: node 0 is the root; leaf ids are 100 + k. Leaf boxes are random
/// in [-1, 1]^3, inner boxes the union of their children.
fn make_tree(leaves: usize, shape: Shape, r: &mut SplitMix64) -> Vec<NodeDesc> {
    fn build(nodes: &mut Vec<NodeDesc>, count: usize, shape: Shape, r: &mut SplitMix64, next_leaf: &mut u32) -> u32 {
        let me = nodes.len() as u32;
        nodes.push(NodeDesc { children: None, leaf: 0, min: [0.0; 3], max: [0.0; 3] });
        if count == 1 {
            let c: [f64; 3] = std::array::from_fn(|_| r.range(-1.0, 1.0));
            let e: [f64; 3] = std::array::from_fn(|_| if r.below(8) == 0 { 0.0 } else { r.range(0.0, 0.3) });
            nodes[me as usize] = NodeDesc {
                children: None,
                leaf: *next_leaf,
                min: std::array::from_fn(|a| c[a] - e[a]),
                max: std::array::from_fn(|a| c[a] + e[a]),
            };
            *next_leaf += 1;
            return me;
        }
        let left_count = match shape {
            Shape::Balanced => count / 2,
            Shape::Chain => 1,
            Shape::Random => 1 + r.below(count as u64 - 1) as usize,
        };
        let (a, b) = if matches!(shape, Shape::Chain) && r.below(2) == 0 {
            (count - 1, 1)
        } else {
            (left_count, count - left_count)
        };
        let l = build(nodes, a, shape, r, next_leaf);
        let rr = build(nodes, b, shape, r, next_leaf);
        let (ln, rn) = (nodes[l as usize], nodes[rr as usize]);
        nodes[me as usize] = NodeDesc {
            children: Some([l, rr]),
            leaf: 0,
            min: std::array::from_fn(|k| ln.min[k].min(rn.min[k])),
            max: std::array::from_fn(|k| ln.max[k].max(rn.max[k])),
        };
        me
    }
    let mut nodes = Vec::new();
    let mut next = 100;
    build(&mut nodes, leaves, shape, r, &mut next);
    nodes
}

fn golden_tree(nodes: &[NodeDesc]) -> Tree {
    Tree {
        nodes: nodes
            .iter()
            .map(|n| match n.children {
                Some([l, r]) => Node::Inner { left: l, right: r },
                None => Node::Leaf { leaf: n.leaf },
            })
            .collect(),
        root: Some(0),
    }
}

fn depth(nodes: &[NodeDesc], i: u32) -> usize {
    match nodes[i as usize].children {
        Some([l, r]) => 1 + depth(nodes, l).max(depth(nodes, r)),
        None => 0,
    }
}

/// Checks both stackless traversals against the stack traversal for every N.
fn check_all_n(nodes: &[NodeDesc], outcome: &dyn Fn(u32) -> Option<f64>) -> Result<(), String> {
    let g = golden_tree(nodes);
    let hw = HwTree::build(nodes, 0, 64, |i, _| Ok::<u32, String>(i)).map_err(|e| e.to_string())?;
    let leaves = nodes.iter().filter(|n| n.children.is_none()).count();
    // one result reused for every N (as the ray loops run it), holding junk at first
    let mut reused = StacklessResult {
        leaves: vec![99; 50],
        passes: 7,
        box_tests: 9,
        back_distances: vec![3; 9],
        ties: [1, 2],
        state: vec![hist::DONE; 70],
    };
    for n in 1..=leaves + 2 {
        let want = stack_traverse(&g, n, outcome);
        let h = history_traverse(&hw, n, |&i| outcome(i));
        let t = trail_traverse(&hw, n, |&i| outcome(i));
        history_traverse_into(&hw, n, |&i| outcome(i), &mut reused);
        if reused != h {
            return Err(format!("history N={n} into a reused result: {reused:?} vs {h:?}"));
        }
        // with each box test remembered (datapath::box_memo, as `traverse` and `render` run
        // it): the same result, counted box tests included, and each box tested at most once
        let mut memo = datapath::box_memo::BoxMemo::new(nodes.len());
        let mut tested = vec![0u32; nodes.len()];
        let hm = history_traverse(&hw, n, |&i| {
            memo.get_or(i, || {
                tested[i as usize] += 1;
                outcome(i)
            })
        });
        if hm != h || tested.iter().any(|&c| c > 1) {
            return Err(format!("history N={n} with the memo: {hm:?} vs {h:?}, tests per box {tested:?}"));
        }
        if h.leaves != want.leaves {
            return Err(format!("history N={n}: {:?} vs stack {:?}", h.leaves, want.leaves));
        }
        if t.leaves != want.leaves {
            return Err(format!("trail N={n}: {:?} vs stack {:?}", t.leaves, want.leaves));
        }
        if !want.leaves.is_empty() && h.passes == 0 {
            return Err("history counted no pass".into());
        }
        // both restart from the root after every pass but the last, and each restart resumes
        // at a level of the tree: passes = restarts + 1, every back distance within the depth
        for (name, r) in [("history", &h), ("trail", &t)] {
            if r.passes > 0 && r.passes as usize != r.back_distances.len() + 1 {
                return Err(format!("{name} N={n}: {} passes, {} restarts", r.passes, r.back_distances.len()));
            }
            if let Some(d) = r.back_distances.iter().find(|&&d| d as usize > hw.depth()) {
                return Err(format!("{name} N={n}: back distance {d} deeper than the tree ({})", hw.depth()));
            }
        }
        // the 1-bit trail retraces the 2-bit history's passes (and so its choices at ties)
        if (t.passes, &t.back_distances, t.ties) != (h.passes, &h.back_distances, h.ties) {
            return Err(format!(
                "trail N={n}: passes {} back distances {:?} ties {:?}, history {} {:?} {:?}",
                t.passes, t.back_distances, t.ties, h.passes, h.back_distances, h.ties
            ));
        }
    }
    Ok(())
}

/// Entry outcomes drawn from a small set so that ties, NaN and ±0 are frequent.
fn synthetic(seed: u64, nodes: usize, miss_rate: u64) -> Vec<Option<f64>> {
    let mut r = SplitMix64::new(seed);
    let vals = [0.0, -0.0, 0.5, 1.0, 1.0, 2.0, f64::NAN, f64::INFINITY];
    (0..nodes)
        .map(|_| if r.below(100) < miss_rate { None } else { Some(vals[r.below(vals.len() as u64) as usize]) })
        .collect()
}

fn config() -> Config {
    let cases = std::env::var("PROPTEST_CASES").ok().and_then(|c| c.parse().ok()).unwrap_or(1000);
    Config { cases, rng_seed: RngSeed::Fixed(0x7a3e_0001), failure_persistence: None, ..Config::default() }
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn stackless_equals_stack_with_ties_and_nans(leaves in 1usize..40, shape in 0u8..3, seed in any::<u64>(), miss in 0u64..60) {
        let shape = [Shape::Balanced, Shape::Chain, Shape::Random][shape as usize];
        let mut r = SplitMix64::new(seed);
        let nodes = make_tree(leaves, shape, &mut r);
        let out = synthetic(seed ^ 0x55, nodes.len(), miss);
        let outcome = |i: u32| out[i as usize];
        if let Err(e) = check_all_n(&nodes, &outcome) {
            return Err(TestCaseError::fail(format!("{shape:?} {leaves} leaves: {e}")));
        }
    }

    #[test]
    fn stackless_equals_stack_with_the_slab_unit(leaves in 1usize..64, shape in 0u8..3, seed in any::<u64>(), fmt in 0usize..4) {
        let shape = [Shape::Balanced, Shape::Chain, Shape::Random][shape as usize];
        let name = ["f32", "fp16", "bf16", "q8.24:divide"][fmt];
        let any: AnyFormat = name.parse().unwrap();
        let mut r = SplitMix64::new(seed);
        let nodes = make_tree(leaves, shape, &mut r);
        let o: [f64; 3] = std::array::from_fn(|_| r.range(-1.5, 1.5));
        let d: [f64; 3] = std::array::from_fn(|_| if r.below(6) == 0 { 0.0 } else { r.range(-1.0, 1.0) });
        let res = with_format!(any, |f| {
            let s = Slab::new(f, SlabConfig::named(if seed % 2 == 0 { "plain" } else { "conservative" }).unwrap());
            let ray = s.prepare(o, d, 0.0, f64::INFINITY);
            let boxes: Vec<_> = nodes.iter().map(|n| s.store_box(n.min, n.max).unwrap()).collect();
            let outcome = |i: u32| {
                let out = s.test(&ray, &boxes[i as usize]);
                out.hit.then(|| f.to_f64(out.t_near))
            };
            check_all_n(&nodes, &outcome)
        });
        if let Err(e) = res {
            return Err(TestCaseError::fail(format!("{name} {shape:?} {leaves} leaves: {e}")));
        }
    }
}

#[test]
fn a_tree_deeper_than_the_hardware_is_a_clear_error() {
    let mut r = SplitMix64::new(3);
    let nodes = make_tree(20, Shape::Chain, &mut r);
    let d = depth(&nodes, 0);
    assert_eq!(d, 19);
    let ok = HwTree::build(&nodes, 0, d, |i, _| Ok::<u32, String>(i));
    assert_eq!(ok.unwrap().depth(), d);
    let err = HwTree::build(&nodes, 0, d - 1, |i, _| Ok::<u32, String>(i)).unwrap_err();
    assert_eq!(err, BvhError::TooDeep { depth: d, max: d - 1 });
    assert!(err.to_string().contains("needs 19 levels but the hardware has 18"));
    // malformed: a child index out of range, a node reached twice
    let mut bad = nodes.clone();
    bad[0].children = Some([1, 999]);
    assert!(matches!(HwTree::build(&bad, 0, 64, |i, _| Ok::<u32, String>(i)), Err(BvhError::Malformed(_))));
    let mut twice = nodes.clone();
    twice[0].children = Some([1, 1]);
    assert!(matches!(HwTree::build(&twice, 0, 64, |i, _| Ok::<u32, String>(i)), Err(BvhError::Malformed(_))));
}

#[test]
fn single_leaf_and_missed_root() {
    let leaf = [NodeDesc { children: None, leaf: 7, min: [0.0; 3], max: [1.0; 3] }];
    let hw = HwTree::build(&leaf, 0, 4, |i, _| Ok::<u32, String>(i)).unwrap();
    assert_eq!(history_traverse(&hw, 3, |_| Some(0.0)).leaves, [7]);
    assert_eq!(trail_traverse(&hw, 3, |_| Some(0.0)).leaves, [7]);
    assert!(history_traverse(&hw, 3, |_| None).leaves.is_empty());
    let mut r = SplitMix64::new(4);
    let nodes = make_tree(9, Shape::Random, &mut r);
    let hw = HwTree::build(&nodes, 0, 64, |i, _| Ok::<u32, String>(i)).unwrap();
    let h = history_traverse(&hw, 5, |i| if *i == 0 { None } else { Some(1.0) });
    assert!(h.leaves.is_empty() && h.passes == 0 && h.box_tests == 1);
    // every leaf hit, all entries equal: left-first depth-first order, one pass per leaf
    let all = history_traverse(&hw, 100, |_| Some(1.0));
    let g = stack_traverse(&golden_tree(&nodes), 100, |_| Some(1.0));
    assert_eq!(all.leaves, g.leaves);
    assert_eq!(all.leaves.len(), 9);
    assert_eq!(all.passes, 9);
    assert_eq!(all.back_distances.len(), 8);
}

#[test]
fn history_states_are_the_thesis_encoding() {
    use datapath::bvh::hist;
    assert_eq!((hist::NEW, hist::PASS, hist::SPLIT, hist::DONE), (0b00, 0b01, 0b10, 0b11));
    // a balanced 4-leaf tree, everything hit, N = 1: the path took the near child twice
    let mut r = SplitMix64::new(5);
    let nodes = make_tree(4, Shape::Balanced, &mut r);
    let hw = HwTree::build(&nodes, 0, 8, |i, _| Ok::<u32, String>(i)).unwrap();
    let h = history_traverse(&hw, 1, |_| Some(0.0));
    assert_eq!(h.state, [hist::SPLIT, hist::SPLIT]);
    let h = history_traverse(&hw, 4, |_| Some(0.0));
    assert_eq!(h.state, [hist::DONE, hist::DONE]);
    // every pair a tie: passes 1-4 take near, near | near, far | far, near | far, far
    assert_eq!(h.ties, [4, 4]);
    assert_eq!(trail_traverse(&hw, 4, |_| Some(0.0)).ties, [4, 4]);
    // distinct entries (node index as t): no tie
    assert_eq!(history_traverse(&hw, 4, |&i| Some(i as f64)).ties, [0, 0]);
    // -0 and +0 are equal entries: a tie
    assert_eq!(history_traverse(&hw, 1, |&i| Some(if i % 2 == 0 { -0.0 } else { 0.0 })).ties, [2, 0]);
    // only the right child of the root hit: 01 at level 0
    let right = nodes[0].children.unwrap()[1];
    let h = history_traverse(&hw, 4, |&i| if i == nodes[0].children.unwrap()[0] { None } else { Some(0.0) });
    assert_eq!(h.state[0], hist::PASS);
    assert_eq!(h.leaves.len(), 2);
    let _ = right;
    let _ = Format::name(&match "f32".parse::<AnyFormat>().unwrap() {
        AnyFormat::F32(f) => f,
        _ => unreachable!(),
    });
}

#[test]
fn layout_with_real_boxes_in_a_narrow_storage_format() {
    // boxes stored in fp16 (outward-rounded) inside the level banks, tested by the f32 slab unit
    let f32_fmt = match "f32".parse::<AnyFormat>().unwrap() {
        AnyFormat::F32(f) => f,
        _ => unreachable!(),
    };
    let fp16 = match "fp16".parse::<AnyFormat>().unwrap() {
        AnyFormat::F16(f) => f,
        _ => unreachable!(),
    };
    let s = Slab::new(f32_fmt, SlabConfig::named("conservative").unwrap());
    let mut r = SplitMix64::new(11);
    for _ in 0..50 {
        let nodes = make_tree(1 + r.below(40) as usize, Shape::Random, &mut r);
        let hw = HwTree::build(&nodes, 0, 64, |_, n| s.store_box_via(&fp16, n.min, n.max)).unwrap();
        let stored: Vec<_> = nodes.iter().map(|n| s.store_box_via(&fp16, n.min, n.max).unwrap()).collect();
        // every bank entry contains its node's original box
        for lv in &hw.levels {
            for bank in [&lv.left, &lv.right] {
                for b in &bank.boxes {
                    assert!((0..3).all(|a| b.min[a] <= b.max[a]));
                }
            }
        }
        for _ in 0..20 {
            let o: [f64; 3] = std::array::from_fn(|_| r.range(-1.5, 1.5));
            let d: [f64; 3] = std::array::from_fn(|_| r.range(-1.0, 1.0));
            let ray = s.prepare(o, d, 0.0, f64::INFINITY);
            let on_box = |b: &datapath::slab::Aabb<f32>| {
                let out = s.test(&ray, b);
                out.hit.then_some(out.t_near as f64)
            };
            let g = stack_traverse(&golden_tree(&nodes), 8, |i| on_box(&stored[i as usize]));
            assert_eq!(history_traverse(&hw, 8, on_box).leaves, g.leaves);
            assert_eq!(trail_traverse(&hw, 8, on_box).leaves, g.leaves);
        }
    }
}

/// The history traversal under the `resume` fault (the pass resumes at the *shallowest* level
/// in state 10 instead of the deepest), traced by hand on a balanced 8-leaf tree where every
/// box is hit at the same entry t (so the left child is always the nearer):
///
/// | pass | resume | path (level 0, 1, 2) | leaf | history after |
/// |---|---|---|---|---|
/// | 1 | – | near, near, near | 0 | 10 10 10 |
/// | 2 | level 0 | far (→ 11, deeper → 00), near, near | 4 | 11 10 10 |
/// | 3 | level 1 | far, far (→ 11, deeper → 00), near | 6 | 11 11 10 |
/// | 4 | level 2 | far, far, far (→ 11) | 7 | 11 11 11 |
///
/// Every pass ends at a leaf on level 2, so the back distances are 2 − 0, 2 − 1, 2 − 2.
#[test]
fn the_resume_fault_skips_the_subtrees_the_hand_trace_says() {
    use datapath::bvh::history_traverse_faulty;
    use datapath::fault::{Logic, NoFault};
    struct Shallowest;
    impl Logic for Shallowest {
        fn flag(&self, site: &'static str, v: bool) -> bool {
            if site == "resume" {
                false
            } else {
                v
            }
        }
    }
    let inner = |l, r| NodeDesc { children: Some([l, r]), leaf: 0, min: [0.0; 3], max: [1.0; 3] };
    let leaf = |id| NodeDesc { children: None, leaf: id, min: [0.0; 3], max: [1.0; 3] };
    let mut nodes = vec![inner(1, 2), inner(3, 4), inner(5, 6)];
    nodes.extend((0..4).map(|k| inner(7 + 2 * k, 8 + 2 * k)));
    nodes.extend((0..8).map(leaf));
    let hw = HwTree::build(&nodes, 0, 8, |i, _| Ok::<u32, String>(i)).unwrap();
    let all = |_: &u32| Some(0.0);
    let good = history_traverse_faulty(&hw, 100, all, &NoFault);
    assert_eq!(good.leaves, (0..8).collect::<Vec<u32>>());
    let bad = history_traverse_faulty(&hw, 100, all, &Shallowest);
    assert_eq!(bad.leaves, [0, 4, 6, 7]);
    assert_eq!(bad.passes, 4);
    assert_eq!(bad.back_distances, [2, 1, 0]);
    assert_eq!(bad.box_tests, 1 + 4 * 6);
    assert_eq!(bad.state, [hist::DONE; 3]);
}
