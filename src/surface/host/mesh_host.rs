//! [`MeshHost`]: the mesh as a rule's expressions see it, answering the
//! host built-ins, with the geometry they read (areas, normals) and
//! OpenSubdiv's crease weights.

use glam::DVec3;

use crate::lang::eval::Host;
use crate::lang::value::{Elem, Value};
use crate::mesh::{child_sharpness, Creasing, EdgeId, Mesh, VertexId};
use crate::syntax::ast::BinOp;

use super::{
    id, vertex_value, BOUNDARY_RING, CREASE_RING, EDGE, FACE, IN_BLOCK, ON_BOUNDARY, RING, SET,
    SHARP_EDGE, TRANSVERSAL, VERTEX, VERTS,
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
    /// How creases soften: `crease_weight` and `next_sharpness` read the
    /// next level's sharpness by it.
    pub creasing: Creasing,
}

pub(super) fn cmp(op: i64, l: u32, c: u32) -> bool {
    match op {
        0 => l < c,
        1 => l <= c,
        2 => l > c,
        3 => l >= c,
        4 => l == c,
        _ => l != c,
    }
}

pub(super) fn op_code(op: BinOp) -> Option<i64> {
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

    pub(super) fn elem_level(&self, e: &Elem) -> Option<u32> {
        Some(match e.kind {
            VERTEX => self.mesh.vertex_level(VertexId(e.ids[0])),
            EDGE => e.ids[2],
            FACE => e.ids[3],
            _ => return None,
        })
    }

    /// A bool built-in on an element (`boundary`, `block`, `transversal`,
    /// `new`, `center`), read without values.
    pub(super) fn test(&self, f: u16, e: &Elem) -> bool {
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
    pub(super) fn point(&self, f: u16, x: &Value, args: [i64; 2]) -> Option<DVec3> {
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
            id::NEXT_SHARPNESS => {
                let end = |x: &Value| match x {
                    Value::Elem(e) if e.kind == VERTEX => Some(VertexId(e.ids[0])),
                    _ => None,
                };
                Value::Float(match (end(&args[0]), end(&args[1])) {
                    (Some(a), Some(b)) => match m.find_halfedge(a, b) {
                        Some(h) => child_sharpness(
                            self.creasing,
                            m.edge_sharpness(h.edge()),
                            m.outgoing_halfedges(a).map(|g| m.edge_sharpness(g.edge())),
                        ),
                        None => 0.0,
                    },
                    _ => 0.0,
                })
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
            id::CREASE_WEIGHT => {
                Value::Float(v().map_or(0.0, |v| crease_weight(m, v, self.creasing)))
            }
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
///
/// With [`Creasing::Chaikin`] the edges' next sharpness at `v` is
/// [`child_sharpness`]'s, and the transition is the edges (and the vertex)
/// sharp now and smooth one level down, as OpenSubdiv weighs its
/// non-uniform methods.
pub fn crease_weight(m: &Mesh, v: VertexId, creasing: Creasing) -> f64 {
    if !m.has_sharpness_flag() {
        return 0.0;
    }
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
    let child = |s: f64| child_sharpness(creasing, s, edges());
    let vertex_child = (sv - 1.0).max(0.0);
    if vertex_rule(vertex_child, edges().map(child)) == parent {
        return 1.0;
    }
    let (mut sum, mut n) = (0.0, 0);
    let pairs = std::iter::once((sv, vertex_child)).chain(edges().map(|s| (s, child(s))));
    for (s, next) in pairs {
        if s > 0.0 && next <= 0.0 {
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
