//! The kd-tree on CIE xy of a clustered-PCA model (Eq. 10): its nodes and the walk from the
//! root to a colour's leaf. Everything that picks a leaf answers as [`walk`] does.

use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Axis {
    #[serde(rename = "x")]
    X,
    #[serde(rename = "y")]
    Y,
}

/// A kd-tree node. A colour goes to `above` when its coordinate is ≥ `value` (Eq. 10).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase", deny_unknown_fields)]
pub enum Node {
    Split {
        axis: Axis,
        value: f64,
        below: usize,
        above: usize,
    },
    Leaf {
        leaf: usize,
    },
}

/// The tree's leaf for a chromaticity, node by node (Eq. 10).
pub fn walk(tree: &[Node], xy: [f64; 2]) -> usize {
    let mut i = 0;
    loop {
        match tree[i] {
            Node::Split {
                axis,
                value,
                below,
                above,
            } => {
                let v = if axis == Axis::X { xy[0] } else { xy[1] };
                i = if v >= value { above } else { below };
            }
            Node::Leaf { leaf } => return leaf,
        }
    }
}

/// Splits on the longest path from node `i` to a leaf (the tree is validated: no cycles).
pub fn depth(tree: &[Node], i: usize) -> usize {
    match tree[i] {
        Node::Split { below, above, .. } => 1 + depth(tree, below).max(depth(tree, above)),
        Node::Leaf { .. } => 0,
    }
}
