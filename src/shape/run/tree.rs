//! The result of a derivation: the tree of shapes, each shape's state, the
//! reports of the smoothing groups, and the tree's order.

use std::sync::Arc;

use crate::lang::value::Value;
use crate::mesh::PolygonSoup;
use crate::shape::geom::{Geometry, Points, Scope};

/// A shape's place in the derivation.
#[derive(Clone, Debug, PartialEq)]
pub enum State {
    /// Not rewritten yet.
    Pending,
    /// Rewritten into children.
    Expanded,
    /// Terminal: no rule applies, or its rule made no child.
    Leaf,
    /// Removed by `NIL`.
    Removed,
    /// At a `Subdivide`, waiting for its smoothing group.
    Waiting,
}

/// A shape of the tree.
#[derive(Clone, Debug)]
pub struct Node {
    pub symbol: u32,
    pub params: Vec<f64>,
    pub attrs: Vec<Value>,
    /// The `smoothingGroup` attribute.
    pub group: Option<Arc<str>>,
    pub colour: Option<[u8; 3]>,
    pub scope: Scope,
    /// Shared until a shape changes it: a child made by a symbol holds its
    /// parent's geometry without a copy.
    pub geom: Arc<Geometry>,
    /// `u32::MAX` for the axiom's shapes.
    pub parent: u32,
    pub children: Vec<u32>,
    /// The shape's place in the tree, hashed: it seeds its random numbers.
    pub key: u64,
    pub depth: u32,
    pub split: (i64, i64),
    pub comp: (i64, i64),
    pub state: State,
}

/// A finished derivation: the tree and the points its shapes share.
#[derive(Debug)]
pub struct ShapeTree {
    pub nodes: Vec<Node>,
    pub roots: Vec<u32>,
    pub points: Points,
    /// The smoothing groups subdivided: (members, faces before, faces
    /// after, protected faces).
    pub groups: Vec<GroupReport>,
}

#[derive(Clone, Debug)]
pub struct GroupReport {
    pub members: usize,
    pub faces_in: usize,
    pub faces_out: usize,
    pub protected_faces: usize,
    pub protected_vertices: usize,
    pub scheme: String,
    pub steps: usize,
    /// The welded group and its subdivision, with `keep_meshes`.
    pub meshes: Option<Box<(PolygonSoup, PolygonSoup)>>,
}

impl ShapeTree {
    /// Every shape in tree order (parents before children, children in the
    /// order they were made).
    pub fn in_order(&self) -> Vec<u32> {
        tree_order(&self.nodes, &self.roots)
    }

    /// The terminal shapes with geometry, in tree order.
    pub fn leaves(&self) -> Vec<u32> {
        self.in_order()
            .into_iter()
            .filter(|&n| self.nodes[n as usize].state == State::Leaf)
            .collect()
    }
}

/// Every shape in tree order: parents before children, children in the
/// order they were made; with an explicit stack, for trees of any depth.
pub(super) fn tree_order(nodes: &[Node], roots: &[u32]) -> Vec<u32> {
    let mut out = Vec::with_capacity(nodes.len());
    let mut stack: Vec<u32> = roots.iter().rev().copied().collect();
    while let Some(n) = stack.pop() {
        out.push(n);
        stack.extend(nodes[n as usize].children.iter().rev().copied());
    }
    out
}
