//! Coverage-guided fuzzing of the stackless traversals: the bytes shape a binary tree and the
//! box tester's answers (hit, entry with ties, NaN and signed zeros); the 2-bit history and the
//! 1-bit trail must return the stack traversal's leaves in the same order for every N.
//! Run: `cargo fuzz run traverse -s none` (from the repository root; stable toolchain).
#![no_main]

use datapath::bvh::{history_traverse, trail_traverse, HwTree, NodeDesc};
use golden::bvh::{stack_traverse, Node, Tree};
use libfuzzer_sys::fuzz_target;

struct Bytes<'a>(&'a [u8], usize);

impl Bytes<'_> {
    fn next(&mut self) -> u8 {
        let b = self.0.get(self.1).copied().unwrap_or(0);
        self.1 += 1;
        b
    }
}

fn grow(nodes: &mut Vec<NodeDesc>, leaves: usize, bytes: &mut Bytes, next_leaf: &mut u32) -> u32 {
    let me = nodes.len() as u32;
    nodes.push(NodeDesc { children: None, leaf: *next_leaf, min: [0.0; 3], max: [0.0; 3] });
    if leaves <= 1 {
        *next_leaf += 1;
        return me;
    }
    let left = 1 + bytes.next() as usize % (leaves - 1);
    let l = grow(nodes, left, bytes, next_leaf);
    let r = grow(nodes, leaves - left, bytes, next_leaf);
    nodes[me as usize].children = Some([l, r]);
    me
}

fuzz_target!(|data: &[u8]| {
    let mut bytes = Bytes(data, 0);
    let leaves = 1 + bytes.next() as usize % 48;
    let mut nodes = Vec::new();
    let mut next_leaf = 0;
    grow(&mut nodes, leaves, &mut bytes, &mut next_leaf);
    let vals = [None, Some(0.0), Some(-0.0), Some(0.5), Some(1.0), Some(1.0), Some(f64::NAN), Some(f64::INFINITY)];
    let outcome: Vec<Option<f64>> = (0..nodes.len()).map(|_| vals[bytes.next() as usize % vals.len()]).collect();
    let tree = Tree {
        nodes: nodes
            .iter()
            .map(|n| match n.children {
                Some([l, r]) => Node::Inner { left: l, right: r },
                None => Node::Leaf { leaf: n.leaf },
            })
            .collect(),
        root: Some(0),
    };
    let hw = HwTree::build(&nodes, 0, 64, |i, _| Ok::<u32, String>(i)).expect("a tree of <= 48 leaves fits 64 levels");
    for n in 1..=leaves + 1 {
        let want = stack_traverse(&tree, n, |i| outcome[i as usize]);
        assert_eq!(history_traverse(&hw, n, |&i| outcome[i as usize]).leaves, want.leaves, "history, N = {n}");
        assert_eq!(trail_traverse(&hw, n, |&i| outcome[i as usize]).leaves, want.leaves, "trail, N = {n}");
    }
});
