//! The kd-tree on CIE xy of a clustered-PCA model (Eq. 10): its nodes, and [`Tree`], which
//! owns every way of going through them (the walk from the root to a colour's leaf, the list
//! of splits, the boxes the splits cut the plane into). Everything that picks a leaf answers
//! as [`Tree::walk`] does; no other module takes a split node apart.

use serde::{Deserialize, Serialize};

/// The most splits on a path from the root to a leaf, in a model file or a compact texture's
/// text (docs/compact.md; `SCS_MAX_DEPTH` of include/specconv_spectrum.h): readers walk a tree
/// with a fixed stack. specconv's models are 3 to 6 splits deep.
pub const MAX_DEPTH: usize = 64;

/// The coordinate of CIE xy a split compares.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Axis {
    /// x, written `"x"` in model files.
    #[serde(rename = "x")]
    X,
    /// y, written `"y"` in model files.
    #[serde(rename = "y")]
    Y,
}

impl Axis {
    /// The coordinate's index in an xy pair: 0 for x, 1 for y.
    #[inline(always)]
    pub fn index(self) -> usize {
        match self {
            Axis::X => 0,
            Axis::Y => 1,
        }
    }
}

/// A kd-tree node. A colour goes to `above` when its coordinate is ≥ `value` (Eq. 10).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase", deny_unknown_fields)]
pub enum Node {
    /// A split (see [`Split`], which has the same fields).
    Split {
        /// The coordinate compared.
        axis: Axis,
        /// The threshold: a coordinate ≥ `value` goes above.
        value: f64,
        /// The index of the node for coordinates below `value` (and NaN).
        below: usize,
        /// The index of the node for coordinates ≥ `value`.
        above: usize,
    },
    /// A leaf: a cluster of the model.
    Leaf {
        /// The cluster's index in the model's `leaves`.
        leaf: usize,
    },
}

/// A split node's content: a colour goes to node `above` when its coordinate on `axis` is
/// ≥ `value`, else to node `below` (Eq. 10; NaN goes below).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Split {
    /// The coordinate compared.
    pub axis: Axis,
    /// The threshold.
    pub value: f64,
    /// The index of the node for coordinates below `value` (and NaN).
    pub below: usize,
    /// The index of the node for coordinates ≥ `value`.
    pub above: usize,
}

impl Split {
    /// The coordinate of `xy` that this split compares.
    #[inline(always)]
    pub fn coordinate(&self, xy: [f64; 2]) -> f64 {
        xy[self.axis.index()]
    }

    /// Whether `xy` goes to `above`.
    #[inline(always)]
    pub fn goes_above(&self, xy: [f64; 2]) -> bool {
        self.coordinate(xy) >= self.value
    }
}

impl From<Split> for Node {
    fn from(s: Split) -> Node {
        Node::Split {
            axis: s.axis,
            value: s.value,
            below: s.below,
            above: s.above,
        }
    }
}

impl Node {
    /// The split at this node; `None` at a leaf.
    #[inline(always)]
    pub fn split(&self) -> Option<Split> {
        match *self {
            Node::Split {
                axis,
                value,
                below,
                above,
            } => Some(Split {
                axis,
                value,
                below,
                above,
            }),
            Node::Leaf { .. } => None,
        }
    }

    /// The leaf (cluster) index at this node; `None` at a split.
    #[inline(always)]
    pub fn leaf(&self) -> Option<usize> {
        match *self {
            Node::Leaf { leaf } => Some(leaf),
            Node::Split { .. } => None,
        }
    }
}

/// The tree's nodes, node 0 the root. In a model file it is the plain list of nodes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(transparent)]
pub struct Tree {
    nodes: Vec<Node>,
}

impl From<Vec<Node>> for Tree {
    fn from(nodes: Vec<Node>) -> Tree {
        Tree { nodes }
    }
}

impl std::ops::Deref for Tree {
    type Target = [Node];
    fn deref(&self) -> &[Node] {
        &self.nodes
    }
}

impl Tree {
    /// One leaf, cluster 0: where training starts.
    pub fn single_leaf() -> Tree {
        Tree::from(vec![Node::Leaf { leaf: 0 }])
    }

    /// The nodes, to edit by hand (tests that damage a model).
    pub fn nodes_mut(&mut self) -> &mut Vec<Node> {
        &mut self.nodes
    }

    /// The split at node `i`; `None` at a leaf.
    #[inline(always)]
    pub fn split(&self, i: usize) -> Option<Split> {
        self.nodes[i].split()
    }

    /// The split list: every split with its node index, in the order of the nodes.
    pub fn splits(&self) -> impl Iterator<Item = (usize, Split)> + '_ {
        self.nodes
            .iter()
            .enumerate()
            .filter_map(|(i, node)| Some((i, node.split()?)))
    }

    /// The leaf of a chromaticity, node by node (Eq. 10).
    pub fn walk(&self, xy: [f64; 2]) -> usize {
        self.path(xy, |_, _, _| {})
    }

    /// The walk of `xy` from the root, calling `visit(node, split, went_above)` at every split
    /// on the way; returns the leaf.
    #[inline]
    pub fn path(&self, xy: [f64; 2], mut visit: impl FnMut(usize, &Split, bool)) -> usize {
        let mut i = 0;
        while let Some(s) = self.split(i) {
            let up = s.goes_above(xy);
            visit(i, &s, up);
            i = if up { s.above } else { s.below };
        }
        self.nodes[i]
            .leaf()
            .expect("a node that does not split is a leaf")
    }

    /// Splits on the longest path from the root to a leaf (the tree is validated: no cycles,
    /// at most [`MAX_DEPTH`]). A loop, not a recursion: its stack is the heap's.
    pub fn depth(&self) -> usize {
        let (mut stack, mut deepest) = (vec![(0usize, 0usize)], 0);
        while let Some((i, d)) = stack.pop() {
            match self.split(i) {
                Some(s) => stack.extend([(s.below, d + 1), (s.above, d + 1)]),
                None => deepest = deepest.max(d),
            }
        }
        deepest
    }

    /// Every split with the box [x₀, x₁] × [y₀, y₁] of the chromaticities that reach it, when
    /// each split `i` above it also lets through the colours within `margin(i)` of its line on
    /// the other side (0 everywhere: the hard switch's boxes). Depth first.
    pub fn boxes(&self, margin: impl Fn(usize) -> f64) -> Vec<(usize, Split, [f64; 4])> {
        let inf = f64::INFINITY;
        let mut stack = vec![(0usize, [-inf, inf, -inf, inf])];
        let mut out = Vec::new();
        while let Some((i, bx)) = stack.pop() {
            let Some(s) = self.split(i) else { continue };
            let k = s.axis.index();
            let (mut lower, mut upper) = (bx, bx);
            lower[2 * k + 1] = lower[2 * k + 1].min(s.value + margin(i));
            upper[2 * k] = upper[2 * k].max(s.value - margin(i));
            stack.extend([(s.below, lower), (s.above, upper)]);
            out.push((i, s, bx));
        }
        out
    }

    /// Splits the node of cluster `leaf` at `value` on `axis`: the colours below go to a new
    /// node of cluster `new[0]`, those above to one of cluster `new[1]` (training).
    pub fn split_leaf(&mut self, leaf: usize, axis: Axis, value: f64, new: [usize; 2]) {
        let node = self
            .nodes
            .iter()
            .position(|n| n.leaf() == Some(leaf))
            .expect("every cluster has a node");
        let (below, above) = (self.nodes.len(), self.nodes.len() + 1);
        self.nodes[node] = Split {
            axis,
            value,
            below,
            above,
        }
        .into();
        self.nodes.extend(new.map(|leaf| Node::Leaf { leaf }));
    }

    /// Gives every leaf the number `number[old]` (training numbers its clusters at the end).
    pub fn renumber_leaves(&mut self, number: &[usize]) {
        for node in &mut self.nodes {
            if let Node::Leaf { leaf } = node {
                *leaf = number[*leaf];
            }
        }
    }

    /// Every node reachable from the root exactly once, every one of `leaves` leaves used
    /// exactly once, split values finite, at most [`MAX_DEPTH`] splits from the root to a leaf
    /// (the checks of a model file and of a compact texture's text). Time linear in the nodes.
    pub fn validate(&self, leaves: usize) -> Result<(), String> {
        let mut seen_node = vec![false; self.nodes.len()];
        let mut seen_leaf = vec![false; leaves];
        let mut stack = vec![(0usize, 0usize)];
        if self.nodes.is_empty() {
            return Err("the tree has no nodes".into());
        }
        while let Some((i, depth)) = stack.pop() {
            if depth > MAX_DEPTH {
                return Err(format!(
                    "the tree is deeper than {MAX_DEPTH} splits (node {i}); no reader walks deeper"
                ));
            }
            if i >= self.nodes.len() {
                return Err(format!("the tree refers to node {i}, which does not exist"));
            }
            if std::mem::replace(&mut seen_node[i], true) {
                return Err(format!(
                    "node {i} is reached twice: the tree has a cycle or shared child"
                ));
            }
            match self.nodes[i] {
                Node::Leaf { leaf } => {
                    if leaf >= leaves {
                        return Err(format!(
                            "node {i} refers to leaf {leaf}, which does not exist"
                        ));
                    }
                    if std::mem::replace(&mut seen_leaf[leaf], true) {
                        return Err(format!("leaf {leaf} is used by two nodes"));
                    }
                }
                Node::Split {
                    value,
                    below,
                    above,
                    ..
                } => {
                    if !value.is_finite() {
                        return Err(format!("node {i} splits at a value that is not finite"));
                    }
                    stack.extend([(below, depth + 1), (above, depth + 1)]);
                }
            }
        }
        if let Some(i) = seen_node.iter().position(|s| !s) {
            return Err(format!("node {i} is not reachable from the root"));
        }
        if let Some(k) = seen_leaf.iter().position(|s| !s) {
            return Err(format!("leaf {k} is not used by the tree"));
        }
        Ok(())
    }
}
