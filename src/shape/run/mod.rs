//! The shape topology's schedule: paper 003's Algorithm 1 on a tree of
//! shapes, with `Subdivide` waiting for its smoothing group (Algorithm 4).
//!
//! A derivation alternates two phases until no shape is left to rewrite:
//! 1. every pending shape is rewritten (one applicable rule, chosen with
//!    its probability) until it is terminal, removed, expanded into
//!    children, or waiting at a `Subdivide`;
//! 2. the waiting shapes form their smoothing groups (a named group from
//!    the `smoothingGroup` attribute, with every terminal shape of that
//!    name; or the connected waiting shapes), each group is welded,
//!    subdivided with its protected boundary, and its slices go back to
//!    their shapes by the face tags; then each waiting shape's successor
//!    runs.
//!
//! Phase 1 only ends when every shape is terminal or waiting, which is
//! Algorithm 4's ready check for every group at once. The result does not
//! depend on which pending shape is taken first: a shape's random numbers
//! come from a generator seeded with the run's seed and the shape's place
//! in the tree (not from a shared stream), and everything that is written
//! out walks the tree in order.
//!
//! - [`tree`]: the result, a tree of shapes ([`ShapeTree`], [`Node`],
//!   [`State`]), and its order
//! - [`rewrite`]: phase 1: a pending shape rewritten by one of its rules,
//!   the expressions of a shape evaluated, new shapes made, the faces
//!   the shapes hold counted
//! - [`exec`]: the operations of a successor run on the current shape
//!   (scope rules, insert, extrude, lot, ...), and what they made
//! - [`split`]: split and repeat: the layout of the parts and the cuts
//! - [`comp`]: component splits
//! - [`smoothing`]: phase 2: the smoothing groups of the waiting shapes
//!   welded, subdivided and handed back to their shapes
//!
//! It uses the other parts of `shape` (`geom`, `grammar`, `host`,
//! `smooth`), `lang`, `mesh`, `surface`, `syntax::span` and `deadline`;
//! nothing above.

mod comp;
mod exec;
mod rewrite;
mod smoothing;
mod split;
mod tree;

#[cfg(test)]
mod tests;

pub use tree::{GroupReport, Node, ShapeTree, State};

use std::collections::{HashMap, HashSet};
use std::sync::Arc;

use glam::DVec3;

use crate::deadline::Deadline;
use crate::lang::eval::{Env, Interp};
use crate::lang::random::Random;
use crate::lang::value::Value;
use crate::syntax::span::Span;

use super::geom::{Geometry, Points, Scope};
use super::{COp, ShapeGrammar};

/// The largest number of shapes a derivation may make (all of them, not
/// only the terminal ones), unless `SUBGRAM_MAX_SHAPES` says otherwise.
pub const MAX_SHAPES: usize = 1_000_000;
pub const MAX_SHAPES_VAR: &str = "SUBGRAM_MAX_SHAPES";

/// The most faces (with edges and points of lower-dimensional shapes) all
/// the shapes of a derivation may hold together, parents included: each
/// shape keeps its own copy of its geometry, so a rule that makes many
/// children of one large mesh would otherwise exhaust memory (about 70
/// bytes a face).
pub const MAX_FACES: usize = 10_000_000;

/// The most faces a smoothing group's subdivision may make (the surface
/// grammar's face limit for `Subdivide`): a few seconds and about 1 GB
/// with the shapes' copies.
pub const MAX_SMOOTH_FACES: usize = 2_000_000;

/// The most face cuts one split may make: a split cuts the shape at its
/// planes one after another, so its work is the shape's faces times its
/// planes.
pub const MAX_SPLIT_WORK: usize = 20_000_000;

/// The most rounds of smoothing (phase 2 of the schedule) a derivation may
/// run: a `Subdivide` whose successor subdivides again without end (`A -->
/// Subdivide(0) { A }`) would otherwise run until the shape limit, each
/// round walking the whole tree.
pub const MAX_ROUNDS: usize = 1000;

/// A waiting shape's `Subdivide`.
struct Wait<'g> {
    node: u32,
    steps: usize,
    scheme: &'g smooth_scheme::Scheme,
    body: &'g [COp],
    frame: Vec<Value>,
    span: Span,
}

pub(crate) mod smooth_scheme {
    /// A subdivision scheme a `Subdivide` names, checked at load.
    #[derive(Debug)]
    pub struct Scheme {
        pub name: String,
        pub grammar: crate::surface::Grammar,
    }
}

/// Why a derivation stopped: the place in the grammar and what happened.
#[derive(Clone, Debug, PartialEq)]
pub struct ShapeError {
    pub span: Span,
    pub message: String,
}

impl ShapeError {
    fn at(span: Span, message: impl Into<String>) -> ShapeError {
        ShapeError {
            span,
            message: message.into(),
        }
    }
}

type R<T> = Result<T, ShapeError>;

/// Settings of a derivation.
#[derive(Clone, Debug)]
pub struct ShapeOptions {
    pub seed: u32,
    pub max_shapes: usize,
    /// The most faces, edges and points all shapes hold ([`MAX_FACES`]).
    pub max_faces: usize,
    /// Take pending shapes last-in first-out (the default) or first-in
    /// first-out; the result is the same, which a test checks.
    pub fifo: bool,
    /// Keep each smoothing group's welded and subdivided meshes in its
    /// report (for cross-checks).
    pub keep_meshes: bool,
}

impl Default for ShapeOptions {
    fn default() -> Self {
        ShapeOptions {
            seed: 1,
            max_shapes: MAX_SHAPES,
            max_faces: MAX_FACES,
            fifo: false,
            keep_meshes: false,
        }
    }
}

/// The state a successor's operations act on.
#[derive(Clone, Debug)]
struct Cur {
    scope: Scope,
    geom: Arc<Geometry>,
    group: Option<Arc<str>>,
    colour: Option<[u8; 3]>,
    split: (i64, i64),
    comp: (i64, i64),
}

impl Cur {
    /// The state a shape's successor starts from: the shape as it is.
    fn of(node: &Node) -> Cur {
        Cur {
            scope: node.scope,
            geom: node.geom.clone(),
            group: node.group.clone(),
            colour: node.colour,
            split: node.split,
            comp: node.comp,
        }
    }
}

/// The generators `ran()` and its kin read, seeded from a shape's key.
fn random_of(key: u64) -> Random {
    Random::new(Some((key ^ (key >> 32)) as u32))
}

struct Deriver<'g> {
    g: &'g ShapeGrammar,
    opts: ShapeOptions,
    deadline: &'g Deadline,
    nodes: Vec<Node>,
    roots: Vec<u32>,
    points: Points,
    pending: std::collections::VecDeque<u32>,
    waiting: Vec<Wait<'g>>,
    loose: HashSet<u32>,
    /// For each cut (wall) id, the planes of the later splits of shapes
    /// holding a face of that wall, in the order they ran: the weld refines
    /// the wall's faces on both sides by them, so the two sides match.
    seam_planes: HashMap<u32, Vec<(DVec3, f64)>>,
    next_cut: u32,
    interp: Interp<'static>,
    env: Env,
    groups: Vec<GroupReport>,
    ticks: u32,
    /// The faces, edges and points the shapes hold (see [`MAX_FACES`]).
    held: usize,
}

fn mix(a: u64, b: u64) -> u64 {
    // splitmix64 of a combination: a fixed, well-spread hash of a path.
    let mut z = a ^ b.wrapping_mul(0x9E37_79B9_7F4A_7C15).rotate_left(17);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Derives the grammar's shapes.
pub fn derive(g: &ShapeGrammar, opts: &ShapeOptions, deadline: &Deadline) -> R<ShapeTree> {
    let mut d = Deriver {
        g,
        opts: opts.clone(),
        deadline,
        nodes: Vec::new(),
        roots: Vec::new(),
        points: Points::default(),
        pending: Default::default(),
        waiting: Vec::new(),
        loose: HashSet::new(),
        seam_planes: HashMap::new(),
        next_cut: 1,
        interp: Interp::new(&[]),
        env: Env::with_model(Vec::new(), crate::model::default_ref()),
        groups: Vec::new(),
        ticks: 0,
        held: 0,
    };
    // The axiom: its operations act on an empty shape at the origin.
    let mut frame = g.attr_init.clone();
    frame.resize(g.axiom_frame.max(frame.len()), Value::Void);
    let mut cur = Cur {
        scope: Scope::world(),
        geom: Arc::new(Geometry::empty(3)),
        group: None,
        colour: None,
        split: (0, 1),
        comp: (0, 1),
    };
    d.env.random = Random::new(Some(opts.seed));
    let made = d.exec(u32::MAX, &g.axiom, &mut cur, &mut frame, g.attr_base_axiom)?;
    let _ = made;
    let mut rounds = 0;
    loop {
        while let Some(n) = if d.opts.fifo {
            d.pending.pop_front()
        } else {
            d.pending.pop_back()
        } {
            d.rewrite(n)?;
        }
        if d.waiting.is_empty() {
            break;
        }
        rounds += 1;
        let span = d.waiting[0].span;
        if rounds > MAX_ROUNDS {
            return Err(ShapeError::at(
                span,
                format!(
                    "the derivation ran {MAX_ROUNDS} rounds of smoothing; does a \
                     `Subdivide`'s successor subdivide again without end?"
                ),
            ));
        }
        d.deadline.check().map_err(|m| ShapeError::at(span, m))?;
        d.smooth_all()?;
    }
    Ok(ShapeTree {
        nodes: d.nodes,
        roots: d.roots,
        points: d.points,
        groups: d.groups,
    })
}
