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

use glam::DVec3;

use crate::lang::builtins::{Builtin, HostTable, SigError};
use crate::lang::eval::{Host, RuntimeError};
use crate::lang::ir::{Ex, FoldOp, Func};
use crate::lang::value::{Elem, Ty, Value};
use crate::mesh::{EdgeId, Mesh, VertexId};
use crate::syntax::ast::BinOp;

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

fn one(a: &[Ty], kinds: &[u8], what: &str) -> Result<(), SigError> {
    match a {
        [Ty::Elem(k)] if kinds.contains(k) => Ok(()),
        [_] => Err(SigError::Message(what.into())),
        _ => Err(SigError::Arity(1)),
    }
}

const V: Ty = Ty::Elem(VERTEX);

static FUNCTIONS: &[Builtin] = &[
    Builtin {
        name: "l",
        resolve: |a| {
            one(
                a,
                &[VERTEX, EDGE, FACE],
                "`l` takes a vertex, an edge or a face",
            )?;
            Ok((Func::Host(id::LEVEL), Ty::Int))
        },
    },
    Builtin {
        name: "pos",
        resolve: |a| {
            one(a, &[VERTEX], "`pos` takes a vertex")?;
            Ok((Func::Host(id::POS), Ty::V3d))
        },
    },
    Builtin {
        name: "valence",
        resolve: |a| {
            one(a, &[VERTEX], "`valence` takes a vertex")?;
            Ok((Func::Host(id::VALENCE), Ty::Int))
        },
    },
    Builtin {
        name: "deg",
        resolve: |a| {
            one(a, &[VERTEX], "`deg` takes a vertex")?;
            Ok((Func::Host(id::VALENCE), Ty::Int))
        },
    },
    Builtin {
        name: "boundary",
        resolve: |a| {
            one(
                a,
                &[VERTEX, EDGE, FACE],
                "`boundary` takes a vertex, an edge or a face",
            )?;
            Ok((Func::Host(id::BOUNDARY), Ty::Bool))
        },
    },
    Builtin {
        name: "block",
        resolve: |a| {
            one(
                a,
                &[EDGE, FACE],
                "`block` takes an edge (true for the internal edge of a basic block) \
                 or a face (true for half of a block)",
            )?;
            Ok((Func::Host(id::BLOCK), Ty::Bool))
        },
    },
    Builtin {
        name: "lone",
        resolve: |a| {
            one(
                a,
                &[EDGE, FACE],
                "`lone` takes a face (true for a triangle in no basic block) or an edge (true \
                 for an edge of such a triangle; on the boundary only its first boundary edge)",
            )?;
            Ok((Func::Host(id::LONE), Ty::Bool))
        },
    },
    Builtin {
        name: "transversal",
        resolve: |a| {
            one(
                a,
                &[EDGE],
                "`transversal` takes an edge: true for an edge that an edge split drew to an \
                 opposite vertex",
            )?;
            Ok((Func::Host(id::TRANSVERSAL), Ty::Bool))
        },
    },
    Builtin {
        name: "new",
        resolve: |a| {
            one(
                a,
                &[VERTEX],
                "`new` takes a vertex: true for a vertex made in this step",
            )?;
            Ok((Func::Host(id::NEW), Ty::Bool))
        },
    },
    Builtin {
        name: "center",
        resolve: |a| {
            one(
                a,
                &[VERTEX],
                "`center` takes a vertex: true for the centre of a dual block, whose edges are \
                 all internal edges of blocks",
            )?;
            Ok((Func::Host(id::CENTER), Ty::Bool))
        },
    },
    Builtin {
        name: "centre",
        resolve: |a| {
            one(
                a,
                &[VERTEX],
                "`centre` takes a vertex: true for the centre of a dual block, whose edges are \
                 all internal edges of blocks",
            )?;
            Ok((Func::Host(id::CENTER), Ty::Bool))
        },
    },
    Builtin {
        name: "avg",
        resolve: |a| {
            one(
                a,
                &[EDGE, FACE],
                "`avg` takes an edge, a face or a set of vertices",
            )?;
            Ok((Func::Host(id::AVG_OF), Ty::V3d))
        },
    },
    Builtin {
        name: "ring",
        resolve: |a| {
            one(a, &[VERTEX], "`ring` takes a vertex")?;
            Ok((Func::Host(id::RING), Ty::Elem(SET)))
        },
    },
    Builtin {
        name: "N1",
        resolve: |a| {
            one(a, &[VERTEX], "`N1` takes a vertex")?;
            Ok((Func::Host(id::RING), Ty::Elem(SET)))
        },
    },
    Builtin {
        name: "boundary_ring",
        resolve: |a| {
            one(a, &[VERTEX], "`boundary_ring` takes a vertex")?;
            Ok((Func::Host(id::BOUNDARY_RING), Ty::Elem(SET)))
        },
    },
    Builtin {
        name: "verts",
        resolve: |a| {
            one(a, &[EDGE, FACE], "`verts` takes an edge or a face")?;
            Ok((Func::Host(id::VERTS), Ty::Elem(SET)))
        },
    },
    Builtin {
        name: "tail",
        resolve: |a| {
            one(a, &[EDGE], "`tail` takes an edge")?;
            Ok((Func::Host(id::TAIL), V))
        },
    },
    Builtin {
        name: "head",
        resolve: |a| {
            one(a, &[EDGE], "`head` takes an edge")?;
            Ok((Func::Host(id::HEAD), V))
        },
    },
    Builtin {
        name: "bnext",
        resolve: |a| {
            one(a, &[VERTEX], "`bnext` takes a boundary vertex")?;
            Ok((Func::Host(id::BNEXT), V))
        },
    },
    Builtin {
        name: "bprev",
        resolve: |a| {
            one(a, &[VERTEX], "`bprev` takes a boundary vertex")?;
            Ok((Func::Host(id::BPREV), V))
        },
    },
    Builtin {
        name: "sharp",
        resolve: |a| {
            one(
                a,
                &[VERTEX, EDGE],
                "`sharp` takes an edge (true for a crease: sharpness above 0) or a vertex \
                 (true for a corner by its own sharpness)",
            )?;
            Ok((Func::Host(id::SHARP), Ty::Bool))
        },
    },
    Builtin {
        name: "sharpness",
        resolve: |a| match a {
            [V, V] => Ok((Func::Host(id::SHARPNESS_BETWEEN), Ty::Double)),
            [_, _] => Err(SigError::Message(
                "`sharpness` of two vertices is that of the edge between them: it takes two \
                 vertices"
                    .into(),
            )),
            _ => {
                one(
                    a,
                    &[VERTEX, EDGE],
                    "`sharpness` takes an edge or a vertex (0 smooth, more for a crease or a \
                     corner, `inf` for ever), or two vertices",
                )?;
                Ok((Func::Host(id::SHARPNESS), Ty::Double))
            }
        },
    },
    Builtin {
        name: "creases",
        resolve: |a| {
            one(
                a,
                &[VERTEX],
                "`creases` takes a vertex: the number of sharp edges at it (off the boundary)",
            )?;
            Ok((Func::Host(id::CREASES), Ty::Int))
        },
    },
    Builtin {
        name: "crease_ring",
        resolve: |a| {
            one(
                a,
                &[VERTEX],
                "`crease_ring` takes a vertex: its neighbours across sharp edges (off the \
                 boundary)",
            )?;
            Ok((Func::Host(id::CREASE_RING), Ty::Elem(SET)))
        },
    },
    Builtin {
        name: "crease_weight",
        resolve: |a| {
            one(
                a,
                &[VERTEX],
                "`crease_weight` takes a vertex: the weight of its crease or corner rule at this \
                 level",
            )?;
            Ok((Func::Host(id::CREASE_WEIGHT), Ty::Double))
        },
    },
    Builtin {
        name: "point",
        resolve: |a| match a {
            [x, y, z] if x.is_numeric() && y.is_numeric() && z.is_numeric() => {
                Ok((Func::Host(id::POINT), Ty::V3d))
            }
            [_, _, _] => Err(SigError::Message("`point` takes three numbers".into())),
            _ => Err(SigError::Arity(3)),
        },
    },
    // What adaptive refinement selects by (`adaptive;`), read from the
    // positions as they are when the rule starts.
    Builtin {
        name: "area",
        resolve: |a| {
            one(
                a,
                &[EDGE, FACE],
                "`area` takes a face (its area) or an edge (the area of the faces beside it: \
                 a block's, for its internal edge)",
            )?;
            Ok((Func::Host(id::AREA), Ty::Double))
        },
    },
    Builtin {
        name: "length",
        resolve: |a| {
            one(
                a,
                &[EDGE],
                "`length` takes an edge (for the length of a vector, use `Length`)",
            )?;
            Ok((Func::Host(id::LENGTH), Ty::Double))
        },
    },
    Builtin {
        name: "angle",
        resolve: |a| {
            one(
                a,
                &[EDGE],
                "`angle` takes an edge: the angle in degrees between the normals of the two \
                 faces beside it (0 on the boundary)",
            )?;
            Ok((Func::Host(id::ANGLE), Ty::Double))
        },
    },
    Builtin {
        name: "refined",
        resolve: |a| {
            one(
                a,
                &[VERTEX],
                "`refined` takes a vertex: true when every face around it has a corner made \
                 in this step",
            )?;
            Ok((Func::Host(id::REFINED), Ty::Bool))
        },
    },
];

/// The table of the stellar topology.
pub static SURFACE_HOST: HostTable = HostTable {
    name: "surface grammar",
    elements: &["a vertex", "an edge", "a face", "a set of vertices"],
    functions: FUNCTIONS,
    values: &[
        ("c", Func::Host(id::CURRENT), Ty::Int),
        ("step", Func::Host(id::STEP), Ty::Int),
    ],
    arith: |k| (k == VERTEX).then_some((Func::Host(id::POS), Ty::V3d)),
    members: |k| (k == SET).then_some(VERTEX),
    types: &[],
    zero: |_| Value::Void,
    fresh: |_| None,
    properties: None,
};

/// The mesh as a rule's expressions see it while the rule runs.
#[derive(Clone, Copy)]
pub struct MeshHost<'m> {
    pub mesh: &'m Mesh,
    /// `c`, the current level when the rule started.
    pub current: u32,
    /// The step being run (0 in `init:` rules): `step`, and the vertices
    /// it made are `new`.
    pub step: u32,
}

fn cmp(op: i64, l: u32, c: u32) -> bool {
    match op {
        0 => l < c,
        1 => l <= c,
        2 => l > c,
        3 => l >= c,
        4 => l == c,
        _ => l != c,
    }
}

fn op_code(op: BinOp) -> Option<i64> {
    Some(match op {
        BinOp::Lt => 0,
        BinOp::Le => 1,
        BinOp::Gt => 2,
        BinOp::Ge => 3,
        BinOp::Eq => 4,
        BinOp::Ne => 5,
        _ => return None,
    })
}

impl MeshHost<'_> {
    fn level(&self, v: &Value) -> Option<u32> {
        match v {
            Value::Elem(e) => self.elem_level(e),
            _ => None,
        }
    }

    fn elem_level(&self, e: &Elem) -> Option<u32> {
        Some(match e.kind {
            VERTEX => self.mesh.vertex_level(VertexId(e.ids[0])),
            EDGE => e.ids[2],
            FACE => e.ids[3],
            _ => return None,
        })
    }

    /// A bool built-in on an element (`boundary`, `block`, `transversal`,
    /// `new`, `center`), read without values.
    fn test(&self, f: u16, e: &Elem) -> bool {
        let flag = |bit: u8| e.flags & bit != 0;
        let v = VertexId(e.ids[0]);
        match (f, e.kind) {
            (id::BOUNDARY, VERTEX) => self.mesh.is_boundary_vertex(v),
            (id::BOUNDARY, EDGE | FACE) => flag(ON_BOUNDARY),
            (id::BLOCK, EDGE | FACE) => flag(IN_BLOCK),
            (id::TRANSVERSAL, EDGE) => flag(TRANSVERSAL),
            (id::NEW, VERTEX) => self.is_new(v),
            (id::CENTER, VERTEX) => self.mesh.is_block_centre(v),
            (id::SHARP, EDGE) => flag(SHARP_EDGE),
            (id::SHARP, VERTEX) => self.mesh.vertex_sharpness(v) > 0.0,
            _ => false,
        }
    }

    /// `lone(x)`: a face in no basic block; an edge of such a face, where
    /// a face with more than one boundary edge counts only the first of
    /// them (in the face's own order), so that splitting the lone boundary
    /// edges splits each lone triangle once. Read from the mesh as it
    /// stands (a rule's conditions are tested before it changes anything).
    fn lone(&self, e: &Elem) -> bool {
        let m = self.mesh;
        let lone_face =
            |f: crate::mesh::FaceId| !m.face_edges(f).iter().any(|&x| m.is_block_edge(x));
        match e.kind {
            FACE => m
                .find_face([VertexId(e.ids[0]), VertexId(e.ids[1]), VertexId(e.ids[2])])
                .is_some_and(lone_face),
            EDGE => {
                let Some(h) = m.find_halfedge(VertexId(e.ids[0]), VertexId(e.ids[1])) else {
                    return false;
                };
                let edge = h.edge();
                m.edge_faces(edge).into_iter().flatten().any(|f| {
                    lone_face(f)
                        && (!m.is_boundary_edge(edge)
                            || m.face_edges(f).into_iter().find(|&x| m.is_boundary_edge(x))
                                == Some(edge))
                })
            }
            _ => false,
        }
    }

    fn is_new(&self, v: VertexId) -> bool {
        self.mesh.vertex_step(v) == self.step
    }

    /// A sum, average or count over the one-ring of `v`, with filter `f`:
    /// 0 all, 1 new, 2 not new, 10 + op `l(w) OP c`.
    fn ring_fold(&self, v: VertexId, fold: i64, f: i64) -> Value {
        let mut sum = DVec3::ZERO;
        let mut count = 0i64;
        for w in self.mesh.one_ring(v) {
            let keep = match f {
                0 => true,
                1 => self.is_new(w),
                2 => !self.is_new(w),
                _ => cmp(f - 10, self.mesh.vertex_level(w), self.current),
            };
            if keep {
                sum += self.mesh.position(w);
                count += 1;
            }
        }
        match fold {
            0 => Value::V3(sum),
            1 => Value::V3(sum / count as f64),
            _ => Value::Int(count),
        }
    }
}

impl MeshHost<'_> {
    /// The point built-in `f` gives for element `x` (`pos`, `avg` of an
    /// edge or a face, a sum or average over a one-ring with `args`), or
    /// None when `x` is not what it takes.
    #[inline]
    fn point(&self, f: u16, x: &Value, args: [i64; 2]) -> Option<DVec3> {
        let Value::Elem(e) = x else { return None };
        let m = self.mesh;
        let at = |i: u32| m.position(VertexId(i));
        match (f, e.kind) {
            (id::POS, VERTEX) => Some(at(e.ids[0])),
            (id::AVG_OF, EDGE) => Some((at(e.ids[0]) + at(e.ids[1])) * 0.5),
            (id::AVG_OF, FACE) => Some((at(e.ids[0]) + at(e.ids[1]) + at(e.ids[2])) / 3.0),
            (id::RING_FOLD, VERTEX) => match self.ring_fold(VertexId(e.ids[0]), args[0], args[1]) {
                Value::V3(p) => Some(p),
                _ => None,
            },
            _ => None,
        }
    }
}

impl Host for MeshHost<'_> {
    fn call(&mut self, f: u16, args: &[Value]) -> Result<Value, String> {
        let m = self.mesh;
        let elem = match args.first() {
            Some(Value::Elem(e)) => Some(*e),
            _ => None,
        };
        let v = || {
            elem.filter(|e| e.kind == VERTEX)
                .map(|e| VertexId(e.ids[0]))
        };
        let flag = |bit: u8| Value::Bool(elem.is_some_and(|e| e.flags & bit != 0));
        Ok(match f {
            id::LEVEL => self
                .level(&args[0])
                .map_or(Value::Int(-1), |l| Value::Int(l as i64)),
            id::POS => match v() {
                Some(v) => Value::V3(m.position(v)),
                None => Value::V3(DVec3::NAN),
            },
            id::VALENCE => match v() {
                Some(v) => Value::Int(m.valence(v) as i64),
                None => Value::Int(0),
            },
            id::BOUNDARY => match elem {
                Some(e) if e.kind == VERTEX => {
                    Value::Bool(m.is_boundary_vertex(VertexId(e.ids[0])))
                }
                _ => flag(ON_BOUNDARY),
            },
            id::BLOCK => flag(IN_BLOCK),
            id::TRANSVERSAL => flag(TRANSVERSAL),
            id::NEW => Value::Bool(v().is_some_and(|v| self.is_new(v))),
            id::CENTER => Value::Bool(v().is_some_and(|v| m.is_block_centre(v))),
            id::AVG_OF => match elem {
                Some(e) if e.kind == EDGE => Value::V3(
                    (m.position(VertexId(e.ids[0])) + m.position(VertexId(e.ids[1]))) * 0.5,
                ),
                Some(e) if e.kind == FACE => Value::V3(
                    e.ids[..3]
                        .iter()
                        .map(|&i| m.position(VertexId(i)))
                        .sum::<DVec3>()
                        / 3.0,
                ),
                _ => Value::V3(DVec3::NAN),
            },
            id::RING | id::BOUNDARY_RING | id::VERTS => match elem {
                Some(e) if e.kind != SET => {
                    let k = match f {
                        id::RING => RING,
                        id::BOUNDARY_RING => BOUNDARY_RING,
                        _ => VERTS,
                    };
                    Value::Elem(Elem {
                        kind: SET,
                        flags: k | (e.kind << 4),
                        ids: e.ids,
                    })
                }
                _ => return Err("this is not an element of the mesh".into()),
            },
            id::TAIL | id::HEAD => match elem {
                Some(e) if e.kind == EDGE => {
                    vertex_value(VertexId(e.ids[(f == id::HEAD) as usize]))
                }
                _ => return Err("this is not an edge of the mesh".into()),
            },
            id::BNEXT | id::BPREV => match v() {
                Some(v) => match m.boundary_neighbour(v, f == id::BNEXT) {
                    Some(w) => vertex_value(w),
                    None => {
                        return Err(format!(
                            "`{}` of vertex {v}: the vertex is not on the boundary, so it has \
                             no neighbour along the boundary",
                            if f == id::BNEXT { "bnext" } else { "bprev" }
                        ))
                    }
                },
                None => return Err("this is not a vertex of the mesh".into()),
            },
            id::AREA => match elem {
                Some(e) if e.kind == FACE => Value::Float(triangle_area(
                    m,
                    [e.ids[0], e.ids[1], e.ids[2]].map(VertexId),
                )),
                Some(e) if e.kind == EDGE => Value::Float(
                    edge_faces(m, &e)
                        .into_iter()
                        .flatten()
                        .map(|vs| triangle_area(m, vs))
                        .sum(),
                ),
                _ => Value::Float(f64::NAN),
            },
            id::LENGTH => match elem {
                Some(e) if e.kind == EDGE => Value::Float(
                    m.position(VertexId(e.ids[0]))
                        .distance(m.position(VertexId(e.ids[1]))),
                ),
                _ => Value::Float(f64::NAN),
            },
            id::ANGLE => match elem {
                Some(e) if e.kind == EDGE => match edge_faces(m, &e) {
                    [Some(f), Some(g)] => {
                        // A degenerate face has no normal: no angle.
                        let (n, k) = (triangle_normal(m, f), triangle_normal(m, g));
                        let cos = n.dot(k).clamp(-1.0, 1.0);
                        let none = n == DVec3::ZERO || k == DVec3::ZERO;
                        Value::Float(if none { 0.0 } else { cos.acos().to_degrees() })
                    }
                    _ => Value::Float(0.0),
                },
                _ => Value::Float(f64::NAN),
            },
            id::REFINED => Value::Bool(v().is_some_and(|v| {
                let mut any = false;
                for f in m.vertex_faces(v) {
                    if !m.face_vertices(f).iter().any(|&w| self.is_new(w)) {
                        return false;
                    }
                    any = true;
                }
                any
            })),
            id::SHARP => match elem {
                Some(e) if e.kind == VERTEX => {
                    Value::Bool(m.vertex_sharpness(VertexId(e.ids[0])) > 0.0)
                }
                _ => flag(SHARP_EDGE),
            },
            id::SHARPNESS => Value::Float(match elem {
                Some(e) if e.kind == VERTEX => m.vertex_sharpness(VertexId(e.ids[0])),
                Some(e) if e.kind == EDGE && e.flags & SHARP_EDGE != 0 => {
                    m.edge_sharpness(EdgeId(e.ids[3]))
                }
                _ => 0.0,
            }),
            id::SHARPNESS_BETWEEN => {
                let end = |x: &Value| match x {
                    Value::Elem(e) if e.kind == VERTEX => Some(VertexId(e.ids[0])),
                    _ => None,
                };
                let between = end(&args[0])
                    .zip(end(&args[1]))
                    .and_then(|(a, b)| m.find_halfedge(a, b));
                Value::Float(between.map_or(0.0, |h| m.edge_sharpness(h.edge())))
            }
            id::CREASES => Value::Int(v().map_or(0, |v| m.sharp_edge_count(v) as i64)),
            id::CREASE_RING => match v() {
                Some(v) => Value::Elem(Elem {
                    kind: SET,
                    flags: CREASE_RING | (VERTEX << 4),
                    ids: [v.0, 0, 0, 0],
                }),
                None => return Err("this is not a vertex of the mesh".into()),
            },
            id::CREASE_WEIGHT => Value::Float(v().map_or(0.0, |v| crease_weight(m, v))),
            id::CURRENT => Value::Int(self.current as i64),
            id::STEP => Value::Int(self.step as i64),
            id::LONE => Value::Bool(elem.is_some_and(|e| self.lone(&e))),
            id::POINT => Value::V3(DVec3::new(
                args[0].as_f64(),
                args[1].as_f64(),
                args[2].as_f64(),
            )),
            id::LEVEL_VS_CURRENT => Value::Bool(
                self.level(&args[0])
                    .is_some_and(|l| cmp(args[1].as_i64(), l, self.current)),
            ),
            id::RING_FOLD => match v() {
                Some(v) => self.ring_fold(v, args[1].as_i64(), args[2].as_i64()),
                None => match args[1].as_i64() {
                    2 => Value::Int(0),
                    _ => Value::V3(DVec3::NAN),
                },
            },
            _ => Value::Void,
        })
    }

    fn members(&mut self, set: &Value, out: &mut Vec<Value>) {
        let Value::Elem(s) = set else { return };
        if s.kind != SET {
            return;
        }
        let m = self.mesh;
        let (k, of) = (s.flags & 0xF, s.flags >> 4);
        match (k, of) {
            (RING, VERTEX) => out.extend(m.one_ring(VertexId(s.ids[0])).map(vertex_value)),
            (BOUNDARY_RING, VERTEX) => {
                for h in m.outgoing_halfedges(VertexId(s.ids[0])) {
                    if m.is_boundary_edge(h.edge()) {
                        out.push(vertex_value(m.to(h)));
                    }
                }
            }
            (CREASE_RING, VERTEX) => {
                for h in m.outgoing_halfedges(VertexId(s.ids[0])) {
                    if m.is_sharp_edge(h.edge()) && !m.is_boundary_edge(h.edge()) {
                        out.push(vertex_value(m.to(h)));
                    }
                }
            }
            (_, EDGE) => out.extend(s.ids[..2].iter().map(|&i| vertex_value(VertexId(i)))),
            (_, FACE) => out.extend(s.ids[..3].iter().map(|&i| vertex_value(VertexId(i)))),
            _ => {}
        }
    }
}

/// The corners of the faces beside edge value `e` (none for an edge that
/// is no longer in the mesh), each counter-clockwise.
fn edge_faces(m: &Mesh, e: &Elem) -> [Option<[VertexId; 3]>; 2] {
    let (p, q) = (VertexId(e.ids[0]), VertexId(e.ids[1]));
    let Some(h) = m.find_halfedge(p, q) else {
        return [None, None];
    };
    [h, h.twin()].map(|h| m.face(h).map(|f| m.face_vertices(f)))
}

fn triangle_area(m: &Mesh, vs: [VertexId; 3]) -> f64 {
    let [a, b, c] = vs.map(|v| m.position(v));
    0.5 * (b - a).cross(c - a).length()
}

/// The unit normal of a triangle (zero for a degenerate one).
fn triangle_normal(m: &Mesh, vs: [VertexId; 3]) -> DVec3 {
    let [a, b, c] = vs.map(|v| m.position(v));
    (b - a).cross(c - a).normalize_or_zero()
}

/// OpenSubdiv's rule of a vertex from its own sharpness and the
/// sharpness of its edges: 0 smooth (no sharp edge, or one: a dart), 1
/// crease (two), 2 corner (three or more, or a sharp vertex).
fn vertex_rule(vertex: f64, edges: impl Iterator<Item = f64>) -> u8 {
    if vertex > 0.0 {
        return 2;
    }
    match edges.filter(|&s| s > 0.0).count() {
        0 | 1 => 0,
        2 => 1,
        _ => 2,
    }
}

/// The weight of `v`'s crease or corner rule at this level, as OpenSubdiv
/// blends its vertex rules (boundary edges count as sharp for ever): 1 where the vertex's rule (see
/// [`vertex_rule`]) is the same one level down, with every sharpness one
/// less; else the mean of the sharpnesses (of the vertex and of its edges)
/// that drop to 0 at this level, at most 1, so that the mask is that
/// weight of this level's rule and the rest of the next level's. 0 for a
/// smooth vertex.
pub fn crease_weight(m: &Mesh, v: VertexId) -> f64 {
    if !m.has_sharpness_flag() {
        return 0.0;
    }
    let child = |s: f64| (s - 1.0).max(0.0);
    let sv = m.vertex_sharpness(v);
    // A boundary edge is sharp for ever, as in OpenSubdiv: a boundary
    // vertex is a crease, and a corner where an interior crease meets it.
    let edges = || {
        m.outgoing_halfedges(v).map(|h| {
            if m.is_boundary_edge(h.edge()) {
                f64::INFINITY
            } else {
                m.edge_sharpness(h.edge())
            }
        })
    };
    let parent = vertex_rule(sv, edges());
    if parent == 0 {
        return 0.0;
    }
    if vertex_rule(child(sv), edges().map(child)) == parent {
        return 1.0;
    }
    let (mut sum, mut n) = (0.0, 0);
    for s in std::iter::once(sv).chain(edges()) {
        if s > 0.0 && child(s) <= 0.0 {
            sum += s;
            n += 1;
        }
    }
    if n == 0 {
        0.0
    } else {
        (sum / n as f64).min(1.0)
    }
}

/// Rewrites the two forms every scheme evaluates for every element into
/// fused built-ins: `l(x) OP c` and a fold over `ring(v)` whose value is
/// the member's position and whose condition is absent, `l(w) OP c`,
/// `new(w)` or `!new(w)`. Everything else is left to the interpreter.
pub fn specialise(e: &mut Ex) {
    // Children first, so that a fused condition inside a fold is seen.
    e.walk_mut(&mut |x| {
        if let Some(fused) = fused(x) {
            *x = fused;
        }
    });
}

fn host_call(e: &Ex, f: u16) -> Option<&[Ex]> {
    match e {
        Ex::Call(Func::Host(g), args, _) if *g == f => Some(args),
        _ => None,
    }
}

fn is_local(e: &Ex, slot: u16) -> bool {
    matches!(e, Ex::Local(s) if *s == slot)
}

fn int(i: i64) -> Ex {
    Ex::Const(Value::Int(i))
}

fn fused(e: &Ex) -> Option<Ex> {
    match e {
        // l(x) OP c
        Ex::Bin(op, a, b, span) => {
            let code = op_code(*op)?;
            let x = host_call(a, id::LEVEL)?;
            host_call(b, id::CURRENT)?;
            Some(Ex::Call(
                Func::Host(id::LEVEL_VS_CURRENT),
                vec![x[0].clone(), int(code)],
                *span,
            ))
        }
        Ex::Fold {
            op,
            slot,
            set,
            cond,
            value,
        } => {
            let ring = host_call(set, id::RING)?;
            if let Some((v, _)) = value {
                let p = host_call(v, id::POS)?;
                if !is_local(&p[0], *slot) {
                    return None;
                }
            }
            let filter = match cond.as_deref() {
                None => 0,
                Some(c) => {
                    if let Some(a) = host_call(c, id::NEW) {
                        if !is_local(&a[0], *slot) {
                            return None;
                        }
                        1
                    } else if let Ex::Not(n) = c {
                        let a = host_call(n, id::NEW)?;
                        if !is_local(&a[0], *slot) {
                            return None;
                        }
                        2
                    } else {
                        let a = host_call(c, id::LEVEL_VS_CURRENT)?;
                        if !is_local(&a[0], *slot) {
                            return None;
                        }
                        let Ex::Const(Value::Int(code)) = a[1] else {
                            return None;
                        };
                        10 + code
                    }
                }
            };
            let fold = match op {
                FoldOp::Sum => 0,
                FoldOp::Avg => 1,
                FoldOp::Count => 2,
            };
            Some(Ex::Call(
                Func::Host(id::RING_FOLD),
                vec![ring[0].clone(), int(fold), int(filter)],
                crate::syntax::span::Span::default(),
            ))
        }
        _ => None,
    }
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

/// The vertex or element a guard leaf reads: the rule's element, or an end
/// of it (`tail(e)`, `head(e)`).
#[derive(Clone, Copy, Debug)]
pub enum Path {
    Elem,
    End(bool),
}

/// A guard recognised in the checked IR and tested without the
/// interpreter where it can be: leaves that read the rule's element (its
/// marks, its level against `c`, whether it or an end of it is new), and
/// leaves that do not depend on the element at all (`step % 2 == 0`),
/// which the interpreter evaluates once per rule and the guard remembers.
/// The same meaning as the expression it came from, as a curve stencil is
/// for its body.
#[derive(Clone, Debug)]
pub enum Guard {
    /// `l(x) OP c`, by the operator's code.
    Level(i64, Path),
    /// A built-in that takes the element (or an end) and gives a bool.
    Test(u16, Path),
    /// An integer built-in of a vertex (`valence`, `creases`) against a
    /// constant: the built-in, the operator's code, the constant.
    Count(u16, i64, i64, Path),
    /// An expression that reads no element.
    Invariant(Box<Ex>),
    Not(Box<Guard>),
    And(Box<Guard>, Box<Guard>),
    Or(Box<Guard>, Box<Guard>),
}

fn path(e: &Ex, slot: u16) -> Option<Path> {
    match e {
        Ex::Local(s) if *s == slot => Some(Path::Elem),
        Ex::Call(Func::Host(f @ (id::TAIL | id::HEAD)), args, _) => match args.as_slice() {
            [Ex::Local(s)] if *s == slot => Some(Path::End(*f == id::HEAD)),
            _ => None,
        },
        _ => None,
    }
}

/// True when `e` reads no local and no element: its value is the same for
/// every element a rule tests.
fn invariant(e: &Ex) -> bool {
    let mut ok = true;
    e.walk(&mut |x| match x {
        Ex::Local(_) | Ex::Global(_) | Ex::Assign(..) | Ex::IncDec(..) | Ex::InContext(..) => {
            ok = false
        }
        Ex::Call(Func::Host(f), ..) if !matches!(*f, id::CURRENT | id::STEP) => ok = false,
        Ex::Call(Func::Random(_) | Func::UseGroup | Func::Stop, ..) => ok = false,
        _ => {}
    });
    ok
}

impl Guard {
    /// The guard of condition `e` on the element in local `slot`, if `e`
    /// has that form. A guard that is only invariant leaves is not worth
    /// one: None.
    pub fn of(e: &Ex, slot: u16) -> Option<Guard> {
        let g = Guard::leaf(e, slot)?;
        (!g.is_invariant()).then_some(g)
    }

    fn is_invariant(&self) -> bool {
        match self {
            Guard::Invariant(_) => true,
            Guard::Level(..) | Guard::Test(..) | Guard::Count(..) => false,
            Guard::Not(a) => a.is_invariant(),
            Guard::And(a, b) | Guard::Or(a, b) => a.is_invariant() && b.is_invariant(),
        }
    }

    fn leaf(e: &Ex, slot: u16) -> Option<Guard> {
        if invariant(e) {
            return Some(Guard::Invariant(Box::new(e.clone())));
        }
        Some(match e {
            Ex::Call(Func::Host(id::LEVEL_VS_CURRENT), args, _) => match args.as_slice() {
                [x, Ex::Const(Value::Int(op))] => Guard::Level(*op, path(x, slot)?),
                _ => return None,
            },
            Ex::Call(
                Func::Host(
                    f @ (id::BOUNDARY
                    | id::BLOCK
                    | id::TRANSVERSAL
                    | id::NEW
                    | id::CENTER
                    | id::SHARP),
                ),
                args,
                _,
            ) => match args.as_slice() {
                [x] => Guard::Test(*f, path(x, slot)?),
                _ => return None,
            },
            Ex::Bin(op, a, b, _) => match (op_code(*op), &**a, &**b) {
                (
                    Some(code),
                    Ex::Call(Func::Host(f @ (id::VALENCE | id::CREASES)), args, _),
                    Ex::Const(Value::Int(k)),
                ) => match args.as_slice() {
                    [x] => Guard::Count(*f, code, *k, path(x, slot)?),
                    _ => return None,
                },
                _ => return None,
            },
            Ex::Not(a) => Guard::Not(Box::new(Guard::leaf(a, slot)?)),
            Ex::Logic(and, a, b) => {
                let (a, b) = (
                    Box::new(Guard::leaf(a, slot)?),
                    Box::new(Guard::leaf(b, slot)?),
                );
                if *and {
                    Guard::And(a, b)
                } else {
                    Guard::Or(a, b)
                }
            }
            // A call of an inlined function of no parameters, such as
            // `even()`, is an invariant above; with parameters bound to
            // the element it is left to the interpreter.
            _ => return None,
        })
    }

    /// True when the guard is false for every element of a mesh with no
    /// sharpness (`sharp(x)`, `creases(v) >= 2`, in a conjunction), and it
    /// has no leaf the interpreter evaluates (which could fail): a rule
    /// with such a guard matches nothing there, so it need not look.
    pub fn never_without_creases(&self) -> bool {
        fn no_invariant(g: &Guard) -> bool {
            match g {
                Guard::Invariant(_) => false,
                Guard::Level(..) | Guard::Test(..) | Guard::Count(..) => true,
                Guard::Not(a) => no_invariant(a),
                Guard::And(a, b) | Guard::Or(a, b) => no_invariant(a) && no_invariant(b),
            }
        }
        fn never(g: &Guard) -> bool {
            match g {
                Guard::Test(id::SHARP, _) => true,
                Guard::Count(id::CREASES, op, k, _) => !match op {
                    0 => 0 < *k,
                    1 => 0 <= *k,
                    2 => 0 > *k,
                    3 => 0 >= *k,
                    4 => 0 == *k,
                    _ => 0 != *k,
                },
                Guard::And(a, b) => never(a) || never(b),
                Guard::Or(a, b) => never(a) && never(b),
                _ => false,
            }
        }
        no_invariant(self) && never(self)
    }

    pub fn test(&self, ev: &mut dyn Evaluate<'_>, elem: &Elem) -> Result<bool, RuntimeError> {
        Ok(match self {
            Guard::Level(op, p) => {
                let host = ev.host();
                host.elem_level(&Guard::at(*p, elem))
                    .is_some_and(|l| cmp(*op, l, host.current))
            }
            Guard::Test(f, p) => ev.host().test(*f, &Guard::at(*p, elem)),
            Guard::Count(f, op, k, p) => {
                let host = ev.host();
                // What the call gives for something that is not a vertex.
                let n = vertex_of(&Guard::at(*p, elem)).map_or(0, |v| match *f {
                    id::VALENCE => host.mesh.valence(v) as i64,
                    _ => host.mesh.sharp_edge_count(v) as i64,
                });
                match op {
                    0 => n < *k,
                    1 => n <= *k,
                    2 => n > *k,
                    3 => n >= *k,
                    4 => n == *k,
                    _ => n != *k,
                }
            }
            Guard::Invariant(x) => {
                let key = &**x as *const Ex as usize;
                if let Some((_, b)) = ev.memo().invariants.iter().find(|(k, _)| *k == key) {
                    *b
                } else {
                    let b = ev.eval(x)?.truthy();
                    ev.memo().invariants.push((key, b));
                    b
                }
            }
            Guard::Not(a) => !a.test(ev, elem)?,
            Guard::And(a, b) => a.test(ev, elem)? && b.test(ev, elem)?,
            Guard::Or(a, b) => a.test(ev, elem)? || b.test(ev, elem)?,
        })
    }

    /// The element a leaf reads. An end of something that is not an edge
    /// is no element: the leaf reads as false, as `l` and the tests do
    /// for values that are not theirs.
    fn at(p: Path, elem: &Elem) -> Elem {
        match p {
            Path::Elem => *elem,
            Path::End(head) if elem.kind == EDGE => vertex(VertexId(elem.ids[head as usize])),
            Path::End(_) => Elem {
                kind: u8::MAX,
                flags: 0,
                ids: [0; 4],
            },
        }
    }
}

/// An assignment that is a weighted sum of points the host gives for the
/// rule's elements (`pos(v)`, `avg(e)`, a sum or average over a one-ring),
/// whose weights depend only on integers the host gives for the element
/// (its valence, a count over its ring) and on constants. Recognised in
/// the checked IR: the integers are computed for every element, the
/// weights by the interpreter once per distinct set of integers, and the
/// points summed. The same meaning as the expression it came from, as a
/// curve stencil is for its body; only the order of the floating-point
/// products may differ (`s / n` is `(1 / n) * s`).
#[derive(Clone, Debug)]
pub struct Affine {
    /// The locals the expression binds, in order, with their values and
    /// whether they read the element (else they are functions of the
    /// earlier ones and constants).
    lets: Vec<(u16, Ex, bool)>,
    /// Per point: its weight's factors (each a scalar expression, divided
    /// by when `true`), a constant factor, and the host built-in with its
    /// local and constant arguments.
    terms: Vec<Term>,
}

#[derive(Clone, Debug)]
struct Term {
    factors: Vec<(Ex, bool)>,
    scale: f64,
    f: u16,
    slot: u16,
    args: [i64; 2],
}

/// The built-ins that give a point for an element.
fn point_call(e: &Ex) -> Option<(u16, u16, [i64; 2])> {
    match e {
        Ex::Call(Func::Host(f @ (id::POS | id::AVG_OF)), args, _) => match args.as_slice() {
            [Ex::Local(s)] => Some((*f, *s, [0, 0])),
            _ => None,
        },
        Ex::Call(Func::Host(id::RING_FOLD), args, _) => match args.as_slice() {
            [Ex::Local(s), Ex::Const(Value::Int(fold @ (0 | 1))), Ex::Const(Value::Int(filter))] => {
                Some((id::RING_FOLD, *s, [*fold, *filter]))
            }
            _ => None,
        },
        _ => None,
    }
}

/// True when `e` is a scalar that reads no element: constants, locals
/// (the integers bound by the lets) and arithmetic on them.
fn scalar(e: &Ex) -> bool {
    let mut ok = true;
    e.walk(&mut |x| match x {
        Ex::Call(Func::Host(f), ..) if !matches!(*f, id::CURRENT | id::STEP) => ok = false,
        Ex::Global(_)
        | Ex::Assign(..)
        | Ex::IncDec(..)
        | Ex::InContext(..)
        | Ex::Fold { .. }
        | Ex::MakeV2(..)
        | Ex::MakeV3(..)
        | Ex::MakeStruct(..)
        | Ex::Call(Func::Random(_) | Func::UseGroup | Func::Stop, ..) => ok = false,
        _ => {}
    });
    ok
}

impl Affine {
    /// The weighted sum `e` is, if it is one.
    pub fn of(e: &Ex) -> Option<Affine> {
        let mut a = Affine {
            lets: Vec::new(),
            terms: Vec::new(),
        };
        a.collect(e, &mut Vec::new(), 1.0, &mut Vec::new())?;
        let keys = a.lets.iter().filter(|l| l.2).count();
        (keys <= MAX_KEY && a.terms.len() <= MAX_TERMS && a.in_order()).then_some(a)
    }

    /// True when evaluating the lets that read the element first, then
    /// the others, then the factors, gives each local the value the
    /// interpreter's order gives it. Not so when a let that reads the
    /// element reads one that does not (`h(v, valence(v) * a)` inside a
    /// function of `a`), nor when a factor or a let's value binds a local
    /// of its own (an inlined call, a fold) in a slot that one of the lets
    /// holds: sibling calls reuse slots.
    fn in_order(&self) -> bool {
        let held: Vec<u16> = self.lets.iter().map(|l| l.0).collect();
        let later: Vec<u16> = self.lets.iter().filter(|l| !l.2).map(|l| l.0).collect();
        let mut ok = true;
        for (_, a, reads) in &self.lets {
            a.walk(&mut |x| match x {
                Ex::Local(s) if *reads && later.contains(s) => ok = false,
                Ex::Let(s, ..) | Ex::Fold { slot: s, .. } if held.contains(s) => ok = false,
                _ => {}
            });
        }
        for t in &self.terms {
            for (x, _) in &t.factors {
                x.walk(&mut |x| match x {
                    Ex::Let(s, ..) | Ex::Fold { slot: s, .. } if held.contains(s) => ok = false,
                    _ => {}
                });
            }
        }
        ok
    }

    /// Adds the terms of `scale * factors * e`. `alias` maps the locals
    /// of inlined parameters bound to another local to that local, so
    /// that nothing needs copying per element.
    fn collect(
        &mut self,
        e: &Ex,
        factors: &mut Vec<(Ex, bool)>,
        scale: f64,
        alias: &mut Vec<(u16, u16)>,
    ) -> Option<()> {
        if let Some((f, slot, args)) = point_call(e) {
            self.terms.push(Term {
                factors: factors.clone(),
                scale,
                f,
                slot: resolve(slot, alias),
                args,
            });
            return Some(());
        }
        match e {
            Ex::Let(s, a, body) => {
                // Two calls side by side may reuse a slot; the weights are
                // evaluated after all the lets, so a slot bound twice is
                // left to the interpreter.
                if alias.iter().any(|(a, _)| a == s) {
                    return None;
                }
                if let Ex::Local(x) = **a {
                    alias.push((*s, resolve(x, alias)));
                } else {
                    // A let that reads the element is computed for every
                    // element; one that does not is a function of the
                    // others and of constants.
                    let reads = !scalar(a);
                    if reads && !integer_host(a) {
                        return None;
                    }
                    self.lets.push((*s, subst(a, alias), reads));
                    // The let's own slot is no alias any more.
                    alias.push((*s, *s));
                }
                self.collect(body, factors, scale, alias)
            }
            Ex::Bin(BinOp::Add, a, b, _) => {
                self.collect(a, factors, scale, alias)?;
                self.collect(b, factors, scale, alias)
            }
            Ex::Bin(BinOp::Sub, a, b, _) => {
                self.collect(a, factors, scale, alias)?;
                self.collect(b, factors, -scale, alias)
            }
            Ex::Neg(a) => self.collect(a, factors, -scale, alias),
            Ex::Bin(BinOp::Mul, a, b, _) => {
                let (k, x) = if scalar(a) {
                    (a, b)
                } else if scalar(b) {
                    (b, a)
                } else {
                    return None;
                };
                factors.push((subst(k, alias), false));
                let r = self.collect(x, factors, scale, alias);
                factors.pop();
                r
            }
            Ex::Bin(BinOp::Div, a, b, _) if scalar(b) => {
                factors.push((subst(b, alias), true));
                let r = self.collect(a, factors, scale, alias);
                factors.pop();
                r
            }
            _ => None,
        }
    }

    /// The point, with the rule's elements bound in the evaluator's frame;
    /// None where the weights are not numbers (the general path then says
    /// what they are).
    pub fn eval(&self, ev: &mut dyn Evaluate<'_>) -> Result<Option<Value>, RuntimeError> {
        let mut key = [0i64; MAX_KEY];
        let mut k = 0;
        for (s, a, reads) in &self.lets {
            if *reads {
                let v = ev.eval(a)?;
                // The whole value is the key: a let that reads the element
                // may be a float (`valence(v) / 8.0`) or a bool
                // (`valence(v) > 6`), and its type is the same for every
                // element. Anything else is left to the interpreter.
                key[k] = match v {
                    Value::Int(i) => i,
                    Value::Bool(b) => b as i64,
                    Value::Float(f) => f.to_bits() as i64,
                    _ => return Ok(None),
                };
                k += 1;
                ev.frame()[*s as usize] = v;
            }
        }
        let form = self as *const Affine as usize;
        let found = ev
            .memo()
            .weights
            .iter()
            .find(|w| w.form == form && w.key == key)
            .map(|w| w.w);
        let weights = match found {
            Some(w) => w,
            None => {
                // Every let that reads the element is in the key: the
                // weights below depend on the key alone.
                for (s, a, reads) in &self.lets {
                    if !*reads {
                        let v = ev.eval(a)?;
                        ev.frame()[*s as usize] = v;
                    }
                }
                let mut w = [0.0; MAX_TERMS];
                for (t, wt) in self.terms.iter().zip(w.iter_mut()) {
                    *wt = t.scale;
                    for (x, inverse) in &t.factors {
                        let k = match ev.eval(x)? {
                            Value::Int(i) => i as f64,
                            Value::Float(f) => f,
                            Value::Bool(b) => b as i64 as f64,
                            _ => return Ok(None),
                        };
                        *wt = if *inverse { *wt / k } else { *wt * k };
                    }
                }
                let memo = ev.memo();
                if memo.weights.len() < MAX_MEMO {
                    memo.weights.push(Weights { form, key, w });
                }
                w
            }
        };
        let host = ev.host();
        let frame = ev.frame();
        let mut p = DVec3::ZERO;
        for (t, w) in self.terms.iter().zip(weights) {
            match host.point(t.f, &frame[t.slot as usize], t.args) {
                Some(q) => p += w * q,
                None => return Ok(None),
            }
        }
        Ok(Some(Value::V3(p)))
    }
}

/// The local an alias stands for.
fn resolve(slot: u16, alias: &[(u16, u16)]) -> u16 {
    alias
        .iter()
        .rev()
        .find(|(a, _)| *a == slot)
        .map_or(slot, |(_, b)| *b)
}

/// `e` with aliased locals replaced by what they stand for; a let or a
/// fold inside `e` that binds a slot hides the alias of that slot.
fn subst(e: &Ex, alias: &[(u16, u16)]) -> Ex {
    let mut e = e.clone();
    rewrite(&mut e, &mut alias.to_vec());
    e
}

fn rewrite(e: &mut Ex, alias: &mut Vec<(u16, u16)>) {
    match e {
        Ex::Local(s) => *s = resolve(*s, alias),
        Ex::Let(s, a, body) => {
            rewrite(a, alias);
            alias.push((*s, *s));
            rewrite(body, alias);
            alias.pop();
        }
        Ex::Fold {
            slot,
            set,
            cond,
            value,
            ..
        } => {
            rewrite(set, alias);
            alias.push((*slot, *slot));
            if let Some(c) = cond {
                rewrite(c, alias);
            }
            if let Some((v, _)) = value {
                rewrite(v, alias);
            }
            alias.pop();
        }
        Ex::Field(a, _) | Ex::Neg(a) | Ex::Not(a) | Ex::Convert(_, a) => rewrite(a, alias),
        Ex::Assign(_, _, a, _) => rewrite(a, alias),
        Ex::Bin(_, a, b, _) | Ex::Logic(_, a, b) | Ex::MakeV2(a, b) => {
            rewrite(a, alias);
            rewrite(b, alias);
        }
        Ex::Cond(a, b, c) | Ex::MakeV3(a, b, c) => {
            rewrite(a, alias);
            rewrite(b, alias);
            rewrite(c, alias);
        }
        Ex::Call(_, args, _) | Ex::MakeStruct(args) => {
            args.iter_mut().for_each(|a| rewrite(a, alias))
        }
        // Arrays and user functions are not part of surface grammars.
        Ex::Const(_)
        | Ex::Global(_)
        | Ex::IncDec(..)
        | Ex::InContext(..)
        | Ex::Load(_)
        | Ex::Index(..)
        | Ex::CallUser { .. } => {}
    }
}

/// A let that reads an integer of the element: `valence(v)`, a count over
/// its ring, arithmetic on those.
fn integer_host(e: &Ex) -> bool {
    let mut ok = true;
    e.walk(&mut |x| match x {
        Ex::Call(Func::Host(id::RING_FOLD), args, _) => {
            if !matches!(args.get(1), Some(Ex::Const(Value::Int(2)))) {
                ok = false
            }
        }
        Ex::Call(Func::Host(f), ..) => {
            if !matches!(
                *f,
                id::VALENCE | id::LEVEL | id::CURRENT | id::STEP | id::CREASES
            ) {
                ok = false
            }
        }
        Ex::Const(_) | Ex::Local(_) | Ex::Bin(..) | Ex::Neg(_) | Ex::Convert(..) => {}
        _ => ok = false,
    });
    ok
}
