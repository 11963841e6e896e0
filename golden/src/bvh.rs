//! Reference BVH traversal: an ordered stack traversal of a binary tree, generic over the box
//! tester, returning the first N leaves in the order a ray reaches them.
//!
//! Rules (the contract the hardware traversal must reproduce):
//! - the root's box is tested first; a miss ends the traversal;
//! - at an inner node both children are tested; if both hit, the nearer is visited first and
//!   the farther pushed; *nearer* means the right child's entry is strictly less than the
//!   left's (`right < left`), so equal entries and NaN entries visit the left child first;
//! - a leaf is emitted when it is visited; the traversal stops after N leaves.

/// A node of a binary tree (boxes live with the tester).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Node {
    /// Inner node with its two children (node indices).
    Inner {
        /// Left child.
        left: u32,
        /// Right child.
        right: u32,
    },
    /// Leaf with its leaf id.
    Leaf {
        /// Leaf id.
        leaf: u32,
    },
}

/// A binary tree: nodes and the root index (`None` for an empty tree).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Tree {
    /// Nodes.
    pub nodes: Vec<Node>,
    /// Root node.
    pub root: Option<u32>,
}

/// The leaves reached and the work done.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Traversal {
    /// Leaf ids in visiting order (at most N).
    pub leaves: Vec<u32>,
    /// Box tests performed.
    pub box_tests: u64,
}

/// Ordered stack traversal; `test(node)` returns the node's entry distance when its box is hit.
pub fn stack_traverse(tree: &Tree, n: usize, mut test: impl FnMut(u32) -> Option<f64>) -> Traversal {
    let mut out = Traversal::default();
    let Some(root) = tree.root else { return out };
    if n == 0 {
        return out;
    }
    out.box_tests += 1;
    if test(root).is_none() {
        return out;
    }
    let mut stack = vec![root];
    while let Some(id) = stack.pop() {
        match tree.nodes[id as usize] {
            Node::Leaf { leaf } => {
                out.leaves.push(leaf);
                if out.leaves.len() == n {
                    break;
                }
            }
            Node::Inner { left, right } => {
                out.box_tests += 2;
                match (test(left), test(right)) {
                    (Some(el), Some(er)) => {
                        let (near, far) = if er < el { (right, left) } else { (left, right) };
                        stack.push(far);
                        stack.push(near);
                    }
                    (Some(_), None) => stack.push(left),
                    (None, Some(_)) => stack.push(right),
                    (None, None) => {}
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tree() -> Tree {
        // 0: root(1, 2); 1: inner(3, 4); 2: leaf 20; 3: leaf 30; 4: leaf 40
        Tree {
            nodes: vec![
                Node::Inner { left: 1, right: 2 },
                Node::Inner { left: 3, right: 4 },
                Node::Leaf { leaf: 20 },
                Node::Leaf { leaf: 30 },
                Node::Leaf { leaf: 40 },
            ],
            root: Some(0),
        }
    }

    #[test]
    fn nearer_first_and_ties_go_left() {
        let entry = [0.0, 2.0, 1.0, 5.0, 3.0];
        let t = stack_traverse(&tree(), 10, |i| Some(entry[i as usize]));
        assert_eq!(t.leaves, [20, 40, 30]);
        assert_eq!(t.box_tests, 5);
        let t = stack_traverse(&tree(), 10, |_| Some(1.0));
        assert_eq!(t.leaves, [30, 40, 20]);
        let t = stack_traverse(&tree(), 10, |i| if i == 2 { Some(f64::NAN) } else { Some(1.0) });
        assert_eq!(t.leaves, [30, 40, 20]);
    }

    #[test]
    fn first_n_misses_and_empty() {
        let t = stack_traverse(&tree(), 1, |i| Some(i as f64));
        assert_eq!(t.leaves, [30]);
        assert!(stack_traverse(&tree(), 5, |i| if i == 0 { None } else { Some(0.0) }).leaves.is_empty());
        assert!(stack_traverse(&Tree::default(), 5, |_| Some(0.0)).leaves.is_empty());
        let t = stack_traverse(&tree(), 5, |i| if i == 1 { None } else { Some(0.0) });
        assert_eq!(t.leaves, [20]);
    }
}
