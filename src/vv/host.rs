//! The rotation-system topology as the language sees it: vertices, sets of
//! vertices (`mesh S`), directed edges and the mesh itself as element
//! values; the vertex-vertex algebra of paper 001 (Tables 1 and 2) as host
//! built-ins in one table beside the library's maths; properties read
//! `v$pos` and written `v$pos = x`. Bodies are checked by `lang::compile`
//! and run by `lang::eval` against a [`VvHost`].
//!
//! The parser reads vv's statements as calls of these built-ins: `make {a,
//! b} nb_of v` is `make(v, a, b)`, `nextto x in v` is `nextto(x, v)`, `'v`
//! is `old(v)`, `(p, q)` is `edge(p, q)`.

use glam::{DVec2, DVec3};

use crate::lang::builtins::{Builtin, HostProperties, HostTable, SigError};
use crate::lang::eval::Host;
use crate::lang::ir::{Ex, Func};
use crate::lang::value::{Elem, IdSet, Ty, Value};

use super::mesh::{Rotation, NULL};

/// Element kinds.
pub const VERTEX: u8 = 0;
/// A set of vertices, vv's `mesh` type.
pub const SET: u8 = 1;
/// A directed edge `(p, q)`.
pub const EDGE: u8 = 2;
/// The mesh as a whole, `mesh$name`.
pub const MESH: u8 = 3;

/// A vertex read as `'v`: its state at the last `synchronize`.
const OLD: u8 = 1;

/// Host built-in numbers.
pub mod id {
    pub const NEW: u16 = 0;
    pub const OLD: u16 = 1;
    pub const VALENCE: u16 = 2;
    pub const IS_IN: u16 = 3;
    pub const ANY: u16 = 4;
    pub const NEXTTO: u16 = 5;
    pub const PREVTO: u16 = 6;
    pub const MAKE: u16 = 7;
    pub const ERASE: u16 = 8;
    pub const REPLACE: u16 = 9;
    pub const SPLICE_AFTER: u16 = 10;
    pub const SPLICE_BEFORE: u16 = 11;
    pub const SYNCHRONIZE: u16 = 12;
    pub const EDGE: u16 = 13;
    pub const CHECK: u16 = 14;
    pub const GET: u16 = 15;
    pub const SET: u16 = 16;
    pub const NULL: u16 = 17;
    pub const MESH: u16 = 18;
    pub const BOUNDARY: u16 = 19;
    pub const SIZE: u16 = 20;
    pub const ERROR: u16 = 23;
    pub const TRIANGLES: u16 = 24;
    pub const MEMBER: u16 = 21;
    pub const FORALL: u16 = 22;
    // Specialisations (see `specialise`): a read of the old state fused
    // into the read, a position read or written as such.
    pub const POS: u16 = 100;
    pub const POS_OLD: u16 = 101;
    pub const GET_OLD: u16 = 102;
    pub const SET_POS: u16 = 103;
    pub const VALENCE_OLD: u16 = 104;
    pub const NEXTTO_OLD: u16 = 105;
    pub const PREVTO_OLD: u16 = 106;
    pub const IS_IN_OLD: u16 = 107;
    pub const ANY_OLD: u16 = 108;
}

const V: Ty = Ty::Elem(VERTEX);

/// The vertex with id `v` (and the generation of its slot).
pub fn vertex(v: u32, gen: u32) -> Value {
    Value::Elem(Elem {
        kind: VERTEX,
        flags: 0,
        ids: [v, gen, 0, 0],
    })
}

/// The null vertex.
pub fn null() -> Value {
    vertex(NULL, 0)
}

/// Checks that every argument is a vertex.
fn vertices(a: &[Ty], n: usize, usage: &str) -> Result<(), SigError> {
    if a.len() != n {
        return Err(SigError::Arity(n));
    }
    if a.iter().all(|t| *t == V) {
        Ok(())
    } else {
        Err(SigError::Message(usage.into()))
    }
}

macro_rules! vv {
    ($name:literal, $n:expr, $id:expr, $ty:expr, $usage:literal) => {
        Builtin {
            name: $name,
            resolve: |a| {
                vertices(a, $n, $usage)?;
                Ok((Func::Host($id), $ty))
            },
        }
    };
}

/// A built-in of one set of vertices.
macro_rules! on_set {
    ($name:literal, $id:expr, $ty:expr, $usage:literal) => {
        Builtin {
            name: $name,
            resolve: |a| match a {
                [Ty::Elem(SET)] => Ok((Func::Host($id), $ty)),
                [_] => Err(SigError::Message($usage.into())),
                _ => Err(SigError::Arity(1)),
            },
        }
    };
}

static FUNCTIONS: &[Builtin] = &[
    vv!("$new", 0, id::NEW, V, "`vertex v;` creates a vertex"),
    // What `add v to S` adds: the checker passes it through this, which
    // refuses the null vertex (a set of ids holds no null).
    vv!("$member", 1, id::MEMBER, V, "`add v to S` takes a vertex"),
    // What `forall x in v` goes over, when it is a vertex: the checker
    // passes it through this, which refuses a vertex with no
    // neighbourhood to list (the null vertex, `'v` before a
    // `synchronize`) instead of looping over nothing.
    vv!(
        "$forall",
        1,
        id::FORALL,
        V,
        "`forall x in v` takes a vertex"
    ),
    vv!("old", 1, id::OLD, V, "`'v` (or `old(v)`) takes a vertex"),
    vv!(
        "valence",
        1,
        id::VALENCE,
        Ty::Int,
        "`valence v` takes a vertex"
    ),
    vv!(
        "is_in",
        2,
        id::IS_IN,
        Ty::Bool,
        "`is x in v` takes two vertices"
    ),
    vv!("any", 1, id::ANY, V, "`any in v` takes a vertex"),
    vv!(
        "nextto",
        2,
        id::NEXTTO,
        V,
        "`nextto x in v` takes two vertices"
    ),
    vv!(
        "prevto",
        2,
        id::PREVTO,
        V,
        "`prevto x in v` takes two vertices"
    ),
    Builtin {
        name: "make",
        resolve: |a| {
            if a.is_empty() || a.iter().any(|t| *t != V) {
                return Err(SigError::Message(
                    "`make {a, b, c} nb_of v` takes vertices".into(),
                ));
            }
            Ok((Func::Host(id::MAKE), Ty::Void))
        },
    },
    vv!(
        "erase",
        2,
        id::ERASE,
        Ty::Void,
        "`erase x from v` takes two vertices"
    ),
    vv!(
        "replace",
        3,
        id::REPLACE,
        Ty::Void,
        "`replace a with x in v` takes three vertices"
    ),
    vv!(
        "splice_after",
        3,
        id::SPLICE_AFTER,
        Ty::Void,
        "`splice x after a in v` takes three vertices"
    ),
    vv!(
        "splice_before",
        3,
        id::SPLICE_BEFORE,
        Ty::Void,
        "`splice x before a in v` takes three vertices"
    ),
    on_set!(
        "synchronize",
        id::SYNCHRONIZE,
        Ty::Void,
        "`synchronize S` takes a set of vertices (a `mesh`)"
    ),
    on_set!(
        "check",
        id::CHECK,
        Ty::Void,
        "`check(S)` takes a set of vertices (a `mesh`)"
    ),
    on_set!(
        "size",
        id::SIZE,
        Ty::Int,
        "`size(S)` takes a set of vertices (a `mesh`)"
    ),
    vv!(
        "edge",
        2,
        id::EDGE,
        Ty::Elem(EDGE),
        "`(p, q)` takes two vertices"
    ),
    on_set!(
        "triangles",
        id::TRIANGLES,
        Ty::Bool,
        "`triangles(S)` takes a set of vertices (a `mesh`)"
    ),
    Builtin {
        name: "error",
        resolve: |a| match a {
            [Ty::Str] => Ok((Func::Host(id::ERROR), Ty::Void)),
            [_] => Err(SigError::Message(
                "`error(\"message\")` takes a string".into(),
            )),
            _ => Err(SigError::Arity(1)),
        },
    },
    vv!(
        "boundary",
        1,
        id::BOUNDARY,
        Ty::Bool,
        "`boundary(v)` takes a vertex"
    ),
];

static PROPERTIES: HostProperties = HostProperties {
    owners: &["vertex", "edge", "mesh"],
    owner_of: |k| match k {
        VERTEX => Some(0),
        EDGE => Some(1),
        MESH => Some(2),
        _ => None,
    },
    builtin: &[(0, "pos", Ty::V3d)],
    get: id::GET,
    set: id::SET,
};

/// The vertex-vertex topology's table.
pub static VV_HOST: HostTable = HostTable {
    name: "vv program",
    elements: &["a vertex", "a set of vertices", "an edge", "the mesh"],
    functions: FUNCTIONS,
    values: &[
        ("null", Func::Host(id::NULL), V),
        ("mesh", Func::Host(id::MESH), Ty::Elem(MESH)),
    ],
    arith: |_| None,
    members: |k| match k {
        SET | VERTEX => Some(VERTEX),
        _ => None,
    },
    types: &[("vertex", VERTEX), ("mesh", SET)],
    zero: |k| match k {
        VERTEX => null(),
        SET => Value::Set(Default::default()),
        _ => Value::Void,
    },
    fresh: |k| (k == VERTEX).then_some(Func::Host(id::NEW)),
    properties: Some(&PROPERTIES),
};

/// How a declared property's value is stored: its type, its first slot
/// in its owner's row and its width.
#[derive(Clone, Copy, Debug)]
pub struct Layout {
    pub ty: Ty,
    pub index: usize,
}

/// The properties of a program, by owner (vertex, edge, mesh), in the
/// order of their numbers after the built-in ones; `index` is the mesh's
/// number of the property.
#[derive(Clone, Debug, Default)]
pub struct Layouts {
    pub vertex: Vec<Layout>,
    pub edge: Vec<Layout>,
    pub mesh: Vec<Layout>,
}

/// The number of `f64`s a property of type `ty` takes.
pub fn width(ty: Ty) -> usize {
    match ty {
        Ty::V2 | Ty::V2d => 2,
        Ty::V3 | Ty::V3d => 3,
        _ => 1,
    }
}

/// The largest magnitude of an `int` property: properties are stored as
/// `f64`s, which hold every integer up to 2^53 exactly.
pub const MAX_INT_PROPERTY: i64 = 1 << 53;

/// Refuses a value that a property's slots would not hold exactly: an
/// `int` beyond ±2^53.
pub fn storable(v: &Value) -> Result<(), String> {
    match v {
        Value::Int(i) if i.unsigned_abs() > MAX_INT_PROPERTY as u64 => Err(format!(
            "an `int` property holds whole numbers up to 2^53 = {MAX_INT_PROPERTY} in \
             magnitude; this is {i}"
        )),
        _ => Ok(()),
    }
}

/// A value of a property's type as slots.
pub fn encode(v: &Value, out: &mut [f64]) {
    match v {
        Value::Int(i) => out[0] = *i as f64,
        Value::Float(f) => out[0] = *f,
        Value::Bool(b) => out[0] = *b as u8 as f64,
        Value::V2(p) => out[..2].copy_from_slice(&[p.x, p.y]),
        Value::V3(p) => out[..3].copy_from_slice(&[p.x, p.y, p.z]),
        _ => {}
    }
}

/// Slots as a value of type `ty`.
pub fn decode(ty: Ty, s: &[f64]) -> Value {
    match ty {
        Ty::Int => Value::Int(s[0] as i64),
        Ty::Bool => Value::Bool(s[0] != 0.0),
        Ty::V2 | Ty::V2d => Value::V2(DVec2::new(s[0], s[1])),
        Ty::V3 | Ty::V3d => Value::V3(DVec3::new(s[0], s[1], s[2])),
        _ => Value::Float(s[0]),
    }
}

/// A position to store: a finite vector.
fn finite_position(value: &Value) -> Result<DVec3, String> {
    let p = match value {
        Value::V3(p) => *p,
        _ => DVec3::NAN,
    };
    if p.is_finite() {
        Ok(p)
    } else {
        Err(format!(
            "a vertex position must be finite; this is ({}, {}, {})",
            p.x, p.y, p.z
        ))
    }
}

/// The rotation system as a body sees it while it runs.
pub struct VvHost<'a> {
    pub mesh: &'a mut Rotation,
    pub layouts: &'a Layouts,
    /// `vertex v;` beyond this many live vertices is an error.
    pub max_vertices: usize,
    /// `make`'s list, reused from call to call.
    pub list: Vec<u32>,
    /// A neighbourhood of more vertices than this is an error: queries
    /// and edits scan a neighbourhood, so a valence that grows without
    /// end makes a run quadratic.
    pub max_valence: usize,
}

/// Whether a value is a vertex (not an edge or the mesh).
fn is_vertex(v: &Value) -> bool {
    matches!(v, Value::Elem(e) if e.kind == VERTEX)
}

/// The vertex an argument holds, and whether it was read as `'v`.
fn vert(v: &Value) -> (u32, bool) {
    match v {
        Value::Elem(e) if e.kind == VERTEX => (e.ids[0], e.flags & OLD != 0),
        _ => (NULL, false),
    }
}

impl VvHost<'_> {
    fn value(&self, v: u32) -> Value {
        if v == NULL {
            null()
        } else {
            vertex(v, self.mesh.generation(v).unwrap_or(0))
        }
    }

    /// Refuses a neighbourhood of `v` past the valence limit.
    fn bounded(&self, v: u32) -> Result<(), String> {
        let n = self.mesh.valence(v, false)?;
        if n > self.max_valence {
            return Err(format!(
                "vertex {v} would have {n} neighbours, more than the {} allowed \
                 (`SUBGRAM_MAX_VALENCE=N` in the environment sets the bound)",
                self.max_valence
            ));
        }
        Ok(())
    }

    /// An edited vertex: its current state (`'v` cannot be edited).
    fn current(&self, v: &Value, what: &str) -> Result<u32, String> {
        let (v, old) = vert(v);
        if old {
            return Err(format!(
                "{what}: `'v` is the state the last `synchronize` kept; edit `v` itself"
            ));
        }
        Ok(v)
    }

    fn get(&self, target: &Value, index: usize) -> Result<Value, String> {
        let Value::Elem(e) = target else {
            return Ok(Value::Void);
        };
        let old = e.flags & OLD != 0;
        match e.kind {
            VERTEX if index == 0 => Ok(Value::V3(self.mesh.pos(e.ids[0], old)?)),
            VERTEX => {
                let l = self.layouts.vertex[index - 1];
                let s = self.mesh.vertex_property(e.ids[0], l.index, old)?;
                Ok(decode(l.ty, s))
            }
            EDGE => {
                let l = self.layouts.edge[index];
                match self.mesh.edge_property(e.ids[0], e.ids[2], l.index, old)? {
                    Some(s) => Ok(decode(l.ty, s)),
                    None if old => Err(format!(
                        "the edge ({}, {}) was not in the mesh at the last `synchronize`: \
                         {} was not a neighbour of {}",
                        e.ids[0], e.ids[2], e.ids[2], e.ids[0]
                    )),
                    None => Err(format!(
                        "the edge ({}, {}) is not in the mesh: {} is not a neighbour of {}",
                        e.ids[0], e.ids[2], e.ids[2], e.ids[0]
                    )),
                }
            }
            _ => {
                let l = self.layouts.mesh[index];
                Ok(decode(l.ty, self.mesh.mesh_property(l.index)?))
            }
        }
    }

    fn set(&mut self, target: &Value, index: usize, value: &Value) -> Result<(), String> {
        let Value::Elem(e) = target else {
            return Ok(());
        };
        if e.flags & OLD != 0 {
            return Err(if e.kind == EDGE {
                "`('p, q)$...` is the state the last `synchronize` kept; assign to `(p, q)$...`"
            } else {
                "`'v$...` is the state the last `synchronize` kept; assign to `v$...`"
            }
            .into());
        }
        let mut buf = [0.0; 3];
        storable(value)?;
        match e.kind {
            VERTEX if index == 0 => {
                let p = finite_position(value)?;
                self.mesh.set_pos(e.ids[0], p)
            }
            VERTEX => {
                let l = self.layouts.vertex[index - 1];
                encode(value, &mut buf);
                self.mesh
                    .set_vertex_property(e.ids[0], l.index, &buf[..width(l.ty)])
            }
            EDGE => {
                let l = self.layouts.edge[index];
                encode(value, &mut buf);
                self.mesh
                    .set_edge_property(e.ids[0], e.ids[2], l.index, &buf[..width(l.ty)])
            }
            _ => {
                let l = self.layouts.mesh[index];
                encode(value, &mut buf);
                self.mesh.set_mesh_property(l.index, &buf[..width(l.ty)])
            }
        }
    }
}

impl Host for VvHost<'_> {
    fn call(&mut self, f: u16, args: &[Value]) -> Result<Value, String> {
        let arg = |i: usize| args.get(i).map_or((NULL, false), vert);
        Ok(match f {
            id::NEW => {
                if self.mesh.len() >= self.max_vertices {
                    return Err(format!(
                        "a vertex beyond the {} the mesh may hold (`SUBGRAM_MAX_VERTICES=N` in the environment sets the bound)",
                        self.max_vertices
                    ));
                }
                let v = self.mesh.new_vertex();
                self.value(v)
            }
            id::MEMBER => {
                let (v, old) = arg(0);
                if v == NULL {
                    return Err("`add v to S`: the null vertex cannot be a member of a set".into());
                }
                if !self.mesh.is_alive(v) {
                    return Err(format!("`add v to S`: vertex {v} no longer exists"));
                }
                // `add 'v to S` adds the vertex itself.
                let _ = old;
                self.value(v)
            }
            id::FORALL => {
                let (v, old) = arg(0);
                self.mesh.neighbours(v, old)?;
                args[0].clone()
            }
            id::OLD => match args.first() {
                Some(Value::Elem(e)) => Value::Elem(Elem {
                    flags: e.flags | OLD,
                    ..*e
                }),
                _ => null(),
            },
            id::VALENCE => {
                let (v, old) = arg(0);
                Value::Int(self.mesh.valence(v, old)? as i64)
            }
            id::IS_IN => {
                let ((x, _), (v, old)) = (arg(0), arg(1));
                Value::Bool(self.mesh.is_in(x, v, old)?)
            }
            id::ANY => {
                let (v, old) = arg(0);
                let a = self.mesh.any(v, old)?;
                self.value(a)
            }
            id::NEXTTO | id::PREVTO => {
                let ((x, _), (v, old)) = (arg(0), arg(1));
                let n = if f == id::NEXTTO {
                    self.mesh.nextto(x, v, old)?
                } else {
                    self.mesh.prevto(x, v, old)?
                };
                self.value(n)
            }
            id::MAKE => {
                let v = self.current(&args[0], "`make`")?;
                let mut list = std::mem::take(&mut self.list);
                list.clear();
                list.extend(args[1..].iter().map(|a| vert(a).0));
                let n = list.iter().filter(|&&x| x != NULL).count();
                if n > self.max_valence && self.mesh.is_alive(v) {
                    return Err(format!(
                        "vertex {v} would have {n} neighbours, more than the {} allowed \
                         (`SUBGRAM_MAX_VALENCE=N` in the environment sets the bound)",
                        self.max_valence
                    ));
                }
                let made = self.mesh.make(v, &list);
                self.list = list;
                made?;
                Value::Void
            }
            id::ERASE => {
                let v = self.current(&args[1], "`erase`")?;
                self.mesh.erase(arg(0).0, v)?;
                Value::Void
            }
            id::REPLACE => {
                let v = self.current(&args[2], "`replace`")?;
                self.mesh.replace(arg(0).0, arg(1).0, v)?;
                Value::Void
            }
            id::SPLICE_AFTER | id::SPLICE_BEFORE => {
                let v = self.current(&args[2], "`splice`")?;
                if f == id::SPLICE_AFTER {
                    self.mesh.splice_after(arg(0).0, arg(1).0, v)?;
                } else {
                    self.mesh.splice_before(arg(0).0, arg(1).0, v)?;
                }
                self.bounded(v)?;
                Value::Void
            }
            id::SYNCHRONIZE => {
                if let Some(Value::Set(s)) = args.first() {
                    self.mesh.synchronize(s.ids())?;
                }
                Value::Void
            }
            id::CHECK => {
                if let Some(Value::Set(s)) = args.first() {
                    self.mesh.check(s.ids())?;
                }
                Value::Void
            }
            id::SIZE => match args.first() {
                Some(Value::Set(s)) => Value::Int(s.len() as i64),
                _ => Value::Int(0),
            },
            id::EDGE => {
                // `('p, q)` is the edge as the last `synchronize` kept it:
                // its properties live with `p`'s neighbourhood.
                let ((p, old), (q, _)) = (arg(0), arg(1));
                if p == NULL || q == NULL {
                    return Err("an edge `(p, q)` of the null vertex".into());
                }
                Value::Elem(Elem {
                    kind: EDGE,
                    flags: if old { OLD } else { 0 },
                    ids: [p, 0, q, 0],
                })
            }
            id::BOUNDARY => {
                let (v, old) = arg(0);
                Value::Bool(self.mesh.is_open(v, old)?)
            }
            // `specialise` cannot tell an edge's or the mesh's property 0
            // (their first declared one) from a vertex's `pos`.
            id::POS | id::POS_OLD if !is_vertex(&args[0]) => {
                let t = match &args[0] {
                    Value::Elem(e) if f == id::POS_OLD => Value::Elem(Elem {
                        flags: e.flags | OLD,
                        ..*e
                    }),
                    other => other.clone(),
                };
                self.get(&t, 0)?
            }
            id::SET_POS if !is_vertex(&args[0]) => {
                self.set(&args[0], 0, &args[1])?;
                args[1].clone()
            }
            id::POS | id::POS_OLD => {
                let (v, old) = arg(0);
                Value::V3(self.mesh.pos(v, old || f == id::POS_OLD)?)
            }
            id::SET_POS => {
                let v = self.current(&args[0], "`v$pos = ...`")?;
                let p = finite_position(&args[1])?;
                self.mesh.set_pos(v, p)?;
                args[1].clone()
            }
            id::GET_OLD => {
                let t = match &args[0] {
                    Value::Elem(e) => Value::Elem(Elem {
                        flags: e.flags | OLD,
                        ..*e
                    }),
                    other => other.clone(),
                };
                self.get(&t, args[1].as_i64() as usize)?
            }
            id::VALENCE_OLD => Value::Int(self.mesh.valence(arg(0).0, true)? as i64),
            id::ANY_OLD => {
                let a = self.mesh.any(arg(0).0, true)?;
                self.value(a)
            }
            id::NEXTTO_OLD => {
                let n = self.mesh.nextto(arg(0).0, arg(1).0, true)?;
                self.value(n)
            }
            id::PREVTO_OLD => {
                let n = self.mesh.prevto(arg(0).0, arg(1).0, true)?;
                self.value(n)
            }
            id::IS_IN_OLD => Value::Bool(self.mesh.is_in(arg(0).0, arg(1).0, true)?),
            id::GET => self.get(&args[0], args[1].as_i64() as usize)?,
            id::SET => {
                self.set(&args[0], args[1].as_i64() as usize, &args[2])?;
                args[2].clone()
            }
            id::TRIANGLES => match args.first() {
                Some(Value::Set(s)) => Value::Bool(self.mesh.all_triangles(s.ids())),
                _ => Value::Bool(false),
            },
            id::ERROR => {
                return Err(match args.first() {
                    Some(Value::Str(m)) => m.to_string(),
                    _ => "error".into(),
                })
            }
            id::NULL => null(),
            id::MESH => Value::Elem(Elem {
                kind: MESH,
                flags: 0,
                ids: [0; 4],
            }),
            _ => Value::Void,
        })
    }

    fn members(&mut self, set: &Value, out: &mut Vec<Value>) {
        match set {
            Value::Set(s) => out.extend(s.ids().iter().map(|&v| self.value(v))),
            Value::Elem(e) if e.kind == VERTEX => {
                let old = e.flags & OLD != 0;
                let mesh = &*self.mesh;
                if let Ok(ns) = mesh.neighbours(e.ids[0], old) {
                    out.extend(
                        ns.iter()
                            .map(|&v| vertex(v, mesh.generation(v).unwrap_or(0))),
                    );
                }
            }
            _ => {}
        }
    }
}

/// Rewrites the checked program's expressions for speed, meaning the
/// same: `f('v)` of a query or selection becomes one call that reads the
/// old state, and `v$pos` (read or written) a call of its own. A
/// specialisation of the IR, as the surface grammars' are.
/// `walk_mut` calls it on every node of a body, children first.
pub fn specialise_node(e: &mut Ex) {
    if let Some(f) = fused(e) {
        *e = f;
    }
}

fn host_args(e: &Ex, f: u16) -> Option<&[Ex]> {
    match e {
        Ex::Call(Func::Host(g), args, _) if *g == f => Some(args),
        _ => None,
    }
}

/// The vertex `'x` reads, when `e` is `old(x)`.
fn old_of(e: &Ex) -> Option<&Ex> {
    match host_args(e, id::OLD)? {
        [x] => Some(x),
        _ => None,
    }
}

fn fused(e: &Ex) -> Option<Ex> {
    let Ex::Call(Func::Host(f), args, span) = e else {
        return None;
    };
    let call = |g: u16, args: Vec<Ex>| Some(Ex::Call(Func::Host(g), args, *span));
    let pos = |k: &Ex| matches!(k, Ex::Const(Value::Int(0)));
    match (*f, &args[..]) {
        (id::NULL, []) => Some(Ex::Const(null())),
        (id::GET, [t, k]) => match (old_of(t), pos(k)) {
            (Some(x), true) => call(id::POS_OLD, vec![x.clone()]),
            (Some(x), false) => call(id::GET_OLD, vec![x.clone(), k.clone()]),
            (None, true) => call(id::POS, vec![t.clone()]),
            (None, false) => None,
        },
        (id::SET, [t, k, v]) if pos(k) && old_of(t).is_none() => {
            call(id::SET_POS, vec![t.clone(), v.clone()])
        }
        (id::VALENCE, [v]) => call(id::VALENCE_OLD, vec![old_of(v)?.clone()]),
        (id::ANY, [v]) => call(id::ANY_OLD, vec![old_of(v)?.clone()]),
        (id::NEXTTO, [x, v]) => call(id::NEXTTO_OLD, vec![x.clone(), old_of(v)?.clone()]),
        (id::PREVTO, [x, v]) => call(id::PREVTO_OLD, vec![x.clone(), old_of(v)?.clone()]),
        (id::IS_IN, [x, v]) => call(id::IS_IN_OLD, vec![x.clone(), old_of(v)?.clone()]),
        _ => None,
    }
}

/// The set of vertex ids a value holds (empty for any other value).
pub fn set_ids(v: &Value) -> &[u32] {
    match v {
        Value::Set(s) => s.ids(),
        _ => &[],
    }
}

/// A set of vertices as a value.
pub fn set_value(ids: impl IntoIterator<Item = u32>) -> Value {
    Value::Set(std::sync::Arc::new(ids.into_iter().collect::<IdSet>()))
}
