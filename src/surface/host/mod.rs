//! The stellar topology as the language sees it: mesh vertices, edges,
//! faces and sets of vertices as element values, and the host built-ins
//! (`l(x)`, `valence(v)`, `ring(v)`, `block(e)`, …) in one table beside the
//! library's maths. Expressions are checked by `lang::compile` and run by
//! `lang::eval` against a [`MeshHost`].
//!
//! Two forms that every scheme evaluates for every element are fused into
//! one built-in each after checking (see [`specialise`]): `l(x) OP c` and
//! a sum, average or count over a one-ring with no condition, `l(w) OP c`,
//! `new(w)` or `!new(w)`. They are specialisations of the shared IR, as the
//! curve stencils are: the same meaning, fewer interpreter steps.
//!
//! The folder, one concept a file:
//! - [`builtins`]: the host built-ins' signatures and the table of the
//!   stellar topology, [`SURFACE_HOST`];
//! - [`mesh_host`]: [`MeshHost`], which answers the built-ins on the
//!   mesh, and the geometry and crease weights they read;
//! - [`fusion`]: the fused built-ins [`specialise`] rewrites the IR into;
//! - [`guard`]: conditions tested without the interpreter ([`Guard`]);
//! - [`affine`]: assignments that are weighted sums of points
//!   ([`Affine`]).
//!
//! Here: element kinds, built-in numbers, the marks of element values and
//! the values themselves, and what the specialised forms need of the
//! evaluator that runs a rule ([`Evaluate`], [`Memo`]).
//!
//! It uses `lang`, `mesh` and `syntax`; nothing above.

use crate::lang::eval::RuntimeError;
use crate::lang::ir::Ex;
use crate::lang::value::{Elem, Value};
use crate::mesh::{EdgeId, VertexId};

mod affine;
mod builtins;
mod fusion;
mod guard;
mod mesh_host;

pub use affine::Affine;
pub use builtins::SURFACE_HOST;
pub use fusion::specialise;
pub use guard::Guard;
pub use mesh_host::MeshHost;

/// Element kinds.
pub const VERTEX: u8 = 0;
pub const EDGE: u8 = 1;
pub const FACE: u8 = 2;
pub const SET: u8 = 3;

/// Host built-in numbers.
pub mod id {
    pub const LEVEL: u16 = 0;
    pub const POS: u16 = 1;
    pub const VALENCE: u16 = 2;
    pub const BOUNDARY: u16 = 3;
    pub const BLOCK: u16 = 4;
    pub const TRANSVERSAL: u16 = 5;
    pub const NEW: u16 = 6;
    pub const CENTER: u16 = 7;
    pub const AVG_OF: u16 = 8;
    pub const RING: u16 = 9;
    pub const BOUNDARY_RING: u16 = 10;
    pub const VERTS: u16 = 11;
    pub const TAIL: u16 = 12;
    pub const HEAD: u16 = 13;
    pub const BNEXT: u16 = 14;
    pub const BPREV: u16 = 15;
    pub const CURRENT: u16 = 16;
    pub const STEP: u16 = 17;
    pub const POINT: u16 = 18;
    pub const SHARP: u16 = 19;
    pub const SHARPNESS: u16 = 20;
    pub const CREASES: u16 = 21;
    pub const CREASE_RING: u16 = 22;
    pub const CREASE_WEIGHT: u16 = 23;
    /// `sharpness(v, w)`: of the edge between two vertices.
    pub const SHARPNESS_BETWEEN: u16 = 24;
    pub const LONE: u16 = 25;
    /// `next_sharpness(v, w)`: the edge's sharpness one level down, at `v`.
    pub const NEXT_SHARPNESS: u16 = 26;
    /// Guards of adaptive refinement: sizes and shape of the mesh now.
    pub const AREA: u16 = 30;
    pub const LENGTH: u16 = 31;
    pub const ANGLE: u16 = 32;
    pub const REFINED: u16 = 33;
    /// Fused `l(x) OP c`: the element and the operator's code.
    pub const LEVEL_VS_CURRENT: u16 = 100;
    /// Fused fold over a one-ring: the vertex, the fold and the filter.
    pub const RING_FOLD: u16 = 101;
}

/// Edge and face flags.
const ON_BOUNDARY: u8 = 1;
const IN_BLOCK: u8 = 2;
const TRANSVERSAL: u8 = 4;
/// An edge of positive sharpness.
const SHARP_EDGE: u8 = 8;

/// Set kinds, in the low bits of a set's flags; the element the set
/// belongs to is in the high bits.
const RING: u8 = 0;
const BOUNDARY_RING: u8 = 1;
const VERTS: u8 = 2;
const CREASE_RING: u8 = 3;

pub fn vertex(v: VertexId) -> Elem {
    Elem {
        kind: VERTEX,
        flags: 0,
        ids: [v.0, 0, 0, 0],
    }
}

fn vertex_value(v: VertexId) -> Value {
    Value::Elem(vertex(v))
}

/// An edge by its end vertices, captured before a split, with its level,
/// marks and id. The id reads the edge's sharpness while its rule runs:
/// a split leaves it on the half at `p`, which keeps the sharpness, and
/// sharpness changes only between steps.
#[allow(clippy::too_many_arguments)] // the marks an edge value captures
pub fn edge(
    p: VertexId,
    q: VertexId,
    level: u32,
    boundary: bool,
    block: bool,
    transversal: bool,
    sharp: bool,
    id: EdgeId,
) -> Elem {
    let flags = (boundary as u8 * ON_BOUNDARY)
        | (block as u8 * IN_BLOCK)
        | (transversal as u8 * TRANSVERSAL)
        | (sharp as u8 * SHARP_EDGE);
    Elem {
        kind: EDGE,
        flags,
        ids: [p.0, q.0, level, id.0],
    }
}

/// A face by its vertices, captured before a split, with its level and
/// whether one of its edges is on the boundary or a block's internal edge.
pub fn face(vs: [VertexId; 3], level: u32, boundary: bool, block: bool) -> Elem {
    Elem {
        kind: FACE,
        flags: (boundary as u8 * ON_BOUNDARY) | (block as u8 * IN_BLOCK),
        ids: [vs[0].0, vs[1].0, vs[2].0, level],
    }
}

/// The vertex of a vertex value.
pub fn vertex_of(e: &Elem) -> Option<VertexId> {
    (e.kind == VERTEX).then_some(VertexId(e.ids[0]))
}

/// The vertices of a face value.
pub fn face_vertices(e: &Elem) -> Option<[VertexId; 3]> {
    (e.kind == FACE).then_some([VertexId(e.ids[0]), VertexId(e.ids[1]), VertexId(e.ids[2])])
}

/// The id of an edge value.
pub fn edge_id(e: &Elem) -> Option<EdgeId> {
    (e.kind == EDGE).then_some(EdgeId(e.ids[3]))
}

/// The end vertices of an edge value.
pub fn edge_vertices(e: &Elem) -> Option<(VertexId, VertexId)> {
    (e.kind == EDGE).then_some((VertexId(e.ids[0]), VertexId(e.ids[1])))
}

/// What the specialised forms below need from the evaluator that runs a
/// rule: the interpreter for the parts they leave to it, the host, and
/// the rule's locals.
pub trait Evaluate<'m> {
    /// Runs `e` through the interpreter on the current locals.
    fn eval(&mut self, e: &Ex) -> Result<Value, RuntimeError>;
    fn host(&self) -> MeshHost<'m>;
    fn frame(&mut self) -> &mut [Value];
    /// What this evaluator remembers between elements: invariant guard
    /// leaves (by address) and weights (by rule address and integer key).
    fn memo(&mut self) -> &mut Memo;
}

/// Values a specialised form computed once and may reuse while the same
/// rule runs with the same `c` and step.
#[derive(Default)]
pub struct Memo {
    invariants: Vec<(usize, bool)>,
    weights: Vec<Weights>,
}

/// The weights of one affine form for one key.
struct Weights {
    form: usize,
    key: [i64; MAX_KEY],
    w: [f64; MAX_TERMS],
}

/// Affine forms with more integer lets or more points than these are left
/// to the interpreter; so are keys past `MAX_MEMO` distinct ones.
const MAX_KEY: usize = 8;
const MAX_TERMS: usize = 8;
const MAX_MEMO: usize = 256;
