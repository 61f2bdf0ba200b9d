//! The rotation-system mesh of vertex-vertex systems (paper 001, §2): an
//! arena of vertices, each with the cyclic list of its neighbours, its
//! position and properties, and the old state that `synchronize` freezes;
//! the operations of Table 2 with the cases of its notes 1–5; the
//! consistency check and the faces by Edmonds' permutation technique
//! (§2.1); conversion from and to polygon soups.
//!
//! A neighbourhood lists its vertices counter-clockwise seen from the
//! outside. A boundary vertex's neighbourhood is *open*: its neighbours run
//! counter-clockwise from the first to the last, and the wedge from the
//! last back to the first is no face (the gap), which is always kept after
//! the last element:
//!
//! ```text
//!   closed, v* = [a, b, c, d]          open, v* = [a, b, c]
//!
//!          b                                 b
//!        / | \                             / | \
//!       c--v--a                           c--v--a
//!        \ | /                             gap
//!          d                          (no face from c round to a)
//! ```
//!
//! Vertex ids are `u32` indices into the arena, ordered as the paper's
//! universe `U` is (`x < v`); [`NULL`] is the null vertex. Errors are
//! `String`s that name the operation and the case; the caller puts the
//! place in the program in front.
//!
//! The folder holds one concept per file:
//!
//! - this file: the [`Rotation`] arena (its slots, columns and fields),
//!   the names of the operations for messages, and the checks on the
//!   arguments of every operation;
//! - [`query`]: the queries and selections of Table 2 (`valence`, `is x in
//!   v`, `v*`, `boundary`, `any`, `nextto`, `prevto`);
//! - [`edit`]: editing a neighbourhood (`make`, `erase`, `replace`,
//!   `splice`) with the refusals of notes 3–5;
//! - [`property`]: declaring and reading vertex, edge and mesh properties
//!   and positions;
//! - [`lifetime`]: making, reserving and freeing vertices, and
//!   `synchronize`'s old state;
//! - [`faces`]: the consistency check and the faces and holes by Edmonds'
//!   technique;
//! - [`soup`]: conversion from and to polygon soups;
//! - `tests`: the unit tests of the whole system.
//!
//! It uses `crate::mesh` (polygon soups); nothing above.

use glam::DVec3;

mod edit;
mod faces;
mod lifetime;
mod property;
mod query;
mod soup;
#[cfg(test)]
mod tests;

/// The null vertex: what selections return where the paper says so, and
/// the mark of the gap in a list given to [`Rotation::make`].
pub const NULL: u32 = u32::MAX;

/// A vertex-vertex system: every vertex's cyclic neighbourhood, position
/// and properties, with the old state of the last `synchronize`.
///
/// Vertices live in slots that are reused after [`Rotation::free`]; a
/// slot's generation counts its frees, so that a handle holding `(id,
/// generation)` can tell that its vertex is gone ([`Rotation::is_live`]).
/// A freed slot keeps the capacity of its lists, so that creating,
/// editing and freeing vertices allocates nothing once the arena has
/// grown to its working size.
///
/// Properties are columns of `f64`s declared with a width and a default:
/// on vertices ([`Rotation::add_vertex_property`]), on directed edges
/// ([`Rotation::add_edge_property`]: the value of edge `(v, x)` is kept
/// with `v`'s neighbour list, slot by slot) and on the mesh
/// ([`Rotation::add_mesh_property`]).
#[derive(Clone, Debug, Default)]
pub struct Rotation {
    /// Edits of the topology so far (vertices made or freed, lists
    /// changed), so that a run can tell whether a block changed anything.
    edits: u64,
    alive: Vec<bool>,
    gen: Vec<u32>,
    nbs: Vec<Vec<u32>>,
    open: Vec<bool>,
    pos: Vec<DVec3>,
    /// Per vertex, `nbs.len() * edge_width` values: the edge properties of
    /// `(v, nbs[k])` at `k * edge_width`.
    edges: Vec<Vec<f64>>,
    /// Whether the old state below is that of the last synchronize that
    /// included the vertex (false for a vertex created since).
    synced: Vec<bool>,
    old_nbs: Vec<Vec<u32>>,
    old_open: Vec<bool>,
    old_pos: Vec<DVec3>,
    old_edges: Vec<Vec<f64>>,
    vprops: Vec<Column>,
    efields: Vec<Field>,
    /// One edge's values when every edge property holds its default.
    edge_default: Vec<f64>,
    mfields: Vec<Field>,
    mdata: Vec<f64>,
    free: Vec<u32>,
    live: usize,
    /// Scratch for `retain`.
    marks: Vec<bool>,
    /// Scratch for `make`'s test of long lists for repeats.
    scratch: Vec<u32>,
}

/// A vertex property: `width` values per slot.
#[derive(Clone, Debug)]
struct Column {
    width: usize,
    default: Vec<f64>,
    cur: Vec<f64>,
    old: Vec<f64>,
}

/// Where a property's values lie in an edge's (or the mesh's) values.
#[derive(Clone, Copy, Debug)]
struct Field {
    offset: usize,
    width: usize,
}

/// An operation's name in messages, and what the null vertex lacks for it.
#[derive(Clone, Copy)]
struct Op {
    name: &'static str,
    null: &'static str,
}

const fn op(name: &'static str, null: &'static str) -> Op {
    Op { name, null }
}

const NB: &str = "has no neighbourhood";
const PROPS: &str = "has no properties";
const IS_IN: Op = op("is x in v", NB);
const VALENCE: Op = op("valence v", NB);
const NEIGHBOURS: Op = op("forall x in v", NB);
const BOUNDARY: Op = op("boundary(v)", NB);
const ANY: Op = op("any in v", NB);
const NEXTTO: Op = op("nextto x in v", NB);
const PREVTO: Op = op("prevto x in v", NB);
const MAKE: Op = op("make {…} nb_of v", NB);
const ERASE: Op = op("erase x from v", NB);
const REPLACE: Op = op("replace a with x in v", NB);
const AFTER: Op = op("splice x after a in v", NB);
const BEFORE: Op = op("splice x before a in v", NB);
const POS: Op = op("v$pos", "has no position");
const VPROP: Op = op("v$property", PROPS);
const EPROP: Op = op("edge property", PROPS);
const SYNC: Op = op("synchronize", "cannot be synchronized");
const FREE: Op = op("free", "cannot be freed");

/// The capacity a neighbour list gets when it first needs one: room for
/// the valences of most meshes, so that a new vertex's list is allocated
/// once.
const FIRST_CAPACITY: usize = 8;

/// The position of `x` in `list`: a plain scan, for lists of a few
/// vertices.
#[inline]
fn find(list: &[u32], x: u32) -> Option<usize> {
    list.iter().position(|&y| y == x)
}

impl Rotation {
    /// An empty system with no vertices and no properties.
    pub fn new() -> Rotation {
        Rotation::default()
    }

    /// The number of vertices alive.
    pub fn len(&self) -> usize {
        self.live
    }

    /// Whether no vertex is alive.
    pub fn is_empty(&self) -> bool {
        self.live == 0
    }

    /// The number of slots, alive or free: every id is below it.
    pub fn slots(&self) -> usize {
        self.alive.len()
    }

    /// The vertices alive, in id order.
    pub fn members_alive(&self) -> impl Iterator<Item = u32> + '_ {
        self.alive
            .iter()
            .enumerate()
            .filter(|(_, &a)| a)
            .map(|(i, _)| i as u32)
    }

    /// How many edits of the topology were made so far.
    pub fn topology_edits(&self) -> u64 {
        self.edits
    }

    /// Whether every face of `set` (every orbit that is not a hole) is a
    /// triangle; assumes a consistent set.
    pub fn all_triangles(&self, set: &[u32]) -> bool {
        set.iter().all(|&u| {
            self.nbs[u as usize].iter().all(|&v| {
                // The face through (u, v) is (u, v, w), w before u around
                // v, when v's corner there is not its gap.
                match self.prevto(u, v, false) {
                    Ok(w) if w != NULL => self.prevto(v, w, false) == Ok(u),
                    _ => true,
                }
            })
        })
    }

    /// Whether `v` is alive and has an old state (`synchronize` took it
    /// since it was made).
    pub fn has_old(&self, v: u32) -> bool {
        self.is_alive(v) && self.synced[v as usize]
    }

    /// Whether `v` is a vertex alive now (false for [`NULL`]).
    pub fn is_alive(&self, v: u32) -> bool {
        self.alive.get(v as usize).copied().unwrap_or(false)
    }

    /// The generation of `v`'s slot: how many times it has been freed;
    /// `None` for [`NULL`] and ids never handed out.
    pub fn generation(&self, v: u32) -> Option<u32> {
        self.gen.get(v as usize).copied()
    }

    /// Whether a handle `(v, gen)` taken when `v` was alive still names
    /// that vertex: false once it has been freed, even if its slot has been
    /// reused.
    pub fn is_live(&self, v: u32, gen: u32) -> bool {
        self.is_alive(v) && self.gen[v as usize] == gen
    }

    // ----- checks on arguments -----------------------------------------

    /// The slot of `v`, which must be alive (and synchronized to read its
    /// old state).
    #[inline]
    fn slot(&self, v: u32, old: bool, op: Op) -> Result<usize, String> {
        let i = v as usize;
        if i < self.alive.len() && self.alive[i] && (!old || self.synced[i]) {
            Ok(i)
        } else {
            Err(self.slot_error(v, op))
        }
    }

    #[cold]
    #[inline(never)]
    fn slot_error(&self, v: u32, op: Op) -> String {
        let name = op.name;
        if v == NULL {
            format!("`{name}`: the null vertex {}", op.null)
        } else if v as usize >= self.alive.len() {
            format!("`{name}`: vertex {v} does not exist")
        } else if !self.alive[v as usize] {
            format!("`{name}`: vertex {v} no longer exists")
        } else {
            format!("`{name}`: vertex {v} was not synchronized, so it has no old state")
        }
    }

    /// Checks a vertex `x` that is to be stored in `v`'s neighbourhood.
    #[inline]
    fn storable(&self, x: u32, v: u32, op: Op) -> Result<(), String> {
        if x != v && self.is_alive(x) {
            Ok(())
        } else {
            Err(self.storable_error(x, v, op))
        }
    }

    #[cold]
    #[inline(never)]
    fn storable_error(&self, x: u32, v: u32, op: Op) -> String {
        let name = op.name;
        if x == NULL {
            format!("`{name}`: x is the null vertex, which cannot be a neighbour")
        } else if x == v {
            format!("`{name}`: x is v itself (vertex {v}); a vertex is not its own neighbour")
        } else if x as usize >= self.alive.len() {
            format!("`{name}`: x is vertex {x}, which does not exist")
        } else {
            format!("`{name}`: x is vertex {x}, which no longer exists")
        }
    }

    #[inline]
    fn state(&self, i: usize, old: bool) -> (&[u32], bool) {
        if old {
            (&self.old_nbs[i], self.old_open[i])
        } else {
            (&self.nbs[i], self.open[i])
        }
    }
}
