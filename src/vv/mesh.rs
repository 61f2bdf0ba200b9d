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

use glam::DVec3;

use crate::mesh::PolygonSoup;

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

    // ----- declarations ------------------------------------------------

    /// Declares a vertex property of `width` values; every vertex, those
    /// alive now included, starts with `default`. Returns its index.
    ///
    /// # Panics
    /// If `default` does not hold `width` values (a caller's mistake).
    pub fn add_vertex_property(&mut self, width: usize, default: &[f64]) -> usize {
        assert_eq!(default.len(), width, "a property's default has its width");
        let slots = self.slots();
        let mut cur = Vec::with_capacity(slots * width);
        for _ in 0..slots {
            cur.extend_from_slice(default);
        }
        self.vprops.push(Column {
            width,
            default: default.to_vec(),
            old: cur.clone(),
            cur,
        });
        self.vprops.len() - 1
    }

    /// Declares a property of directed edges, `width` values each; every
    /// edge, those there now included, starts with `default`. Returns its
    /// index.
    ///
    /// # Panics
    /// If `default` does not hold `width` values (a caller's mistake).
    pub fn add_edge_property(&mut self, width: usize, default: &[f64]) -> usize {
        assert_eq!(default.len(), width, "a property's default has its width");
        let before = self.edge_default.len();
        let after = before + width;
        // Widen every edge's values: the new field goes at the end of each.
        for (lists, values) in [
            (&self.nbs, &mut self.edges),
            (&self.old_nbs, &mut self.old_edges),
        ] {
            for (list, vals) in lists.iter().zip(values.iter_mut()) {
                let mut wide = Vec::with_capacity(list.len() * after);
                for k in 0..list.len() {
                    wide.extend_from_slice(&vals[k * before..(k + 1) * before]);
                    wide.extend_from_slice(default);
                }
                *vals = wide;
            }
        }
        self.efields.push(Field {
            offset: before,
            width,
        });
        self.edge_default.extend_from_slice(default);
        self.efields.len() - 1
    }

    /// Declares a mesh property of `width` values, set to `default`.
    /// Returns its index.
    ///
    /// # Panics
    /// If `default` does not hold `width` values (a caller's mistake).
    pub fn add_mesh_property(&mut self, width: usize, default: &[f64]) -> usize {
        assert_eq!(default.len(), width, "a property's default has its width");
        self.mfields.push(Field {
            offset: self.mdata.len(),
            width,
        });
        self.mdata.extend_from_slice(default);
        self.mfields.len() - 1
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

    // ----- queries -----------------------------------------------------

    /// `valence v`: the number of `v`'s neighbours.
    #[inline]
    pub fn valence(&self, v: u32, old: bool) -> Result<usize, String> {
        let i = self.slot(v, old, VALENCE)?;
        Ok(self.state(i, old).0.len())
    }

    /// `is x in v`: whether `x` is a neighbour of `v` (false for [`NULL`]).
    #[inline]
    pub fn is_in(&self, x: u32, v: u32, old: bool) -> Result<bool, String> {
        let i = self.slot(v, old, IS_IN)?;
        Ok(find(self.state(i, old).0, x).is_some())
    }

    /// `v*`: `v`'s neighbours counter-clockwise; an open neighbourhood from
    /// its first to its last.
    #[inline]
    pub fn neighbours(&self, v: u32, old: bool) -> Result<&[u32], String> {
        let i = self.slot(v, old, NEIGHBOURS)?;
        Ok(self.state(i, old).0)
    }

    /// Whether `v`'s neighbourhood is open (`v` lies on the boundary).
    #[inline]
    pub fn is_open(&self, v: u32, old: bool) -> Result<bool, String> {
        let i = self.slot(v, old, BOUNDARY)?;
        Ok(self.state(i, old).1)
    }

    // ----- selection ---------------------------------------------------

    /// `any in v`: a neighbour of `v` (the first of an open
    /// neighbourhood); [`NULL`] if `v` has none (note 1).
    #[inline]
    pub fn any(&self, v: u32, old: bool) -> Result<u32, String> {
        let i = self.slot(v, old, ANY)?;
        Ok(self.state(i, old).0.first().copied().unwrap_or(NULL))
    }

    /// `nextto x in v`: the neighbour that follows `x` counter-clockwise;
    /// [`NULL`] if `x` is not a neighbour (note 2) or is the last of an
    /// open neighbourhood (the gap follows it).
    #[inline]
    pub fn nextto(&self, x: u32, v: u32, old: bool) -> Result<u32, String> {
        let i = self.slot(v, old, NEXTTO)?;
        let (list, open) = self.state(i, old);
        Ok(match find(list, x) {
            None => NULL,
            Some(k) if k + 1 < list.len() => list[k + 1],
            Some(_) if open => NULL,
            Some(_) => list[0],
        })
    }

    /// `prevto x in v`: the neighbour that precedes `x` counter-clockwise;
    /// [`NULL`] if `x` is not a neighbour (note 2) or is the first of an
    /// open neighbourhood (the gap precedes it).
    #[inline]
    pub fn prevto(&self, x: u32, v: u32, old: bool) -> Result<u32, String> {
        let i = self.slot(v, old, PREVTO)?;
        let (list, open) = self.state(i, old);
        Ok(match find(list, x) {
            None => NULL,
            Some(k) if k > 0 => list[k - 1],
            Some(_) if open => NULL,
            Some(_) => list[list.len() - 1],
        })
    }

    /// Makes room for `additional` more vertices, so that creating them
    /// moves no arrays (free slots count).
    pub fn reserve(&mut self, additional: usize) {
        let extra = additional.saturating_sub(self.free.len());
        self.alive.reserve(extra);
        self.gen.reserve(extra);
        self.nbs.reserve(extra);
        self.open.reserve(extra);
        self.pos.reserve(extra);
        self.edges.reserve(extra);
        self.synced.reserve(extra);
        self.old_nbs.reserve(extra);
        self.old_open.reserve(extra);
        self.old_pos.reserve(extra);
        self.old_edges.reserve(extra);
        for c in &mut self.vprops {
            c.cur.reserve(extra * c.width);
            c.old.reserve(extra * c.width);
        }
    }

    // ----- editing -----------------------------------------------------

    /// `vertex v`: a new vertex with no neighbours, at the origin, its
    /// properties at their defaults and no old state. Reuses a freed slot
    /// (and its lists' capacity) when there is one.
    pub fn new_vertex(&mut self) -> u32 {
        self.edits += 1;
        self.live += 1;
        if let Some(v) = self.free.pop() {
            let i = v as usize;
            self.alive[i] = true;
            self.open[i] = false;
            self.pos[i] = DVec3::ZERO;
            self.synced[i] = false;
            for c in &mut self.vprops {
                c.cur[i * c.width..(i + 1) * c.width].copy_from_slice(&c.default);
            }
            return v;
        }
        let v = self.alive.len() as u32;
        self.alive.push(true);
        self.gen.push(0);
        self.nbs.push(Vec::new());
        self.open.push(false);
        self.pos.push(DVec3::ZERO);
        self.edges.push(Vec::new());
        self.synced.push(false);
        self.old_nbs.push(Vec::new());
        self.old_open.push(false);
        self.old_pos.push(DVec3::ZERO);
        self.old_edges.push(Vec::new());
        for c in &mut self.vprops {
            c.cur.extend_from_slice(&c.default);
            c.old.extend_from_slice(&c.default);
        }
        v
    }

    /// `make {…} nb_of v`: sets `v`'s neighbourhood to `list`, its edge
    /// properties to their defaults.
    ///
    /// [`NULL`] entries mark the gap of a boundary vertex: they must form
    /// one run, read cyclically; they are dropped, the neighbourhood is
    /// open and begins after the gap (`{p, NULL, q, r}` gives the open
    /// `[q, r, p]`). A list of nothing but null vertices leaves `v` with no
    /// neighbours. Refused (note 3) if `v` is in the list or a vertex is
    /// listed twice.
    pub fn make(&mut self, v: u32, list: &[u32]) -> Result<(), String> {
        self.edits += 1;
        let i = self.slot(v, false, MAKE)?;
        let n = list.len();
        let (mut runs, mut start, mut count) = (0, 0, 0);
        for (k, &x) in list.iter().enumerate() {
            if x == NULL {
                continue;
            }
            if x == v {
                return Err(format!(
                    "`{}`: v (vertex {v}) is listed in its own neighbourhood",
                    MAKE.name
                ));
            }
            if !self.is_alive(x) {
                return Err(self.listed_error(x));
            }
            count += 1;
            if list[(k + n - 1) % n] == NULL {
                runs += 1;
                start = k;
            }
        }
        if runs > 1 {
            return Err(format!(
                "`{}`: the list has more than one gap (its null vertices form {runs} runs); \
                 an open neighbourhood has one",
                MAKE.name
            ));
        }
        if let Some(x) = self.repeated(list) {
            return Err(format!("`{}`: vertex {x} is listed twice", MAKE.name));
        }
        let nb = &mut self.nbs[i];
        nb.clear();
        if nb.capacity() < count {
            nb.reserve_exact(count.max(FIRST_CAPACITY));
        }
        if count == n {
            nb.extend_from_slice(list);
        } else {
            nb.extend(
                list[start..]
                    .iter()
                    .chain(&list[..start])
                    .copied()
                    .filter(|&x| x != NULL),
            );
        }
        self.open[i] = count > 0 && count < n;
        let vals = &mut self.edges[i];
        vals.clear();
        for _ in 0..count {
            vals.extend_from_slice(&self.edge_default);
        }
        Ok(())
    }

    #[cold]
    fn listed_error(&self, x: u32) -> String {
        if x as usize >= self.alive.len() {
            format!(
                "`{}`: the list holds vertex {x}, which does not exist",
                MAKE.name
            )
        } else {
            format!(
                "`{}`: the list holds vertex {x}, which no longer exists",
                MAKE.name
            )
        }
    }

    /// A vertex other than [`NULL`] that `list` holds twice: the first
    /// repeat in list order for short lists, the smallest repeated id
    /// (found by sorting a copy) for long ones.
    fn repeated(&mut self, list: &[u32]) -> Option<u32> {
        if list.len() <= 32 {
            return list
                .iter()
                .enumerate()
                .find(|&(k, &x)| x != NULL && list[..k].contains(&x))
                .map(|(_, &x)| x);
        }
        self.scratch.clear();
        self.scratch
            .extend(list.iter().copied().filter(|&x| x != NULL));
        self.scratch.sort_unstable();
        self.scratch.windows(2).find(|w| w[0] == w[1]).map(|w| w[0])
    }

    /// `erase x from v`: removes `x` and the edge's properties from `v`'s
    /// neighbourhood; no effect if `x` is not there (note 4). A
    /// neighbourhood left empty is closed.
    #[inline]
    pub fn erase(&mut self, x: u32, v: u32) -> Result<(), String> {
        self.edits += 1;
        let i = self.slot(v, false, ERASE)?;
        if let Some(k) = find(&self.nbs[i], x) {
            self.nbs[i].remove(k);
            let w = self.edge_default.len();
            if w > 0 {
                self.edges[i].drain(k * w..(k + 1) * w);
            }
            if self.nbs[i].is_empty() {
                self.open[i] = false;
            }
        }
        Ok(())
    }

    /// `replace a with x in v`: `x` takes `a`'s place, with the edge
    /// properties' defaults; no effect if `a` is not a neighbour, refused
    /// if `x` is `v` or already a neighbour (note 5), or is the null or a
    /// dead vertex.
    #[inline]
    pub fn replace(&mut self, a: u32, x: u32, v: u32) -> Result<(), String> {
        self.edits += 1;
        let i = self.slot(v, false, REPLACE)?;
        self.storable(x, v, REPLACE)?;
        let Some(k) = find(&self.nbs[i], a) else {
            return Ok(());
        };
        if find(&self.nbs[i], x).is_some() {
            return Err(already(REPLACE, x, v));
        }
        self.nbs[i][k] = x;
        let w = self.edge_default.len();
        if w > 0 {
            self.edges[i][k * w..(k + 1) * w].copy_from_slice(&self.edge_default);
        }
        Ok(())
    }

    /// `splice x after a in v`: inserts `x` right after `a`,
    /// counter-clockwise, with the edge properties' defaults; after the
    /// last of an open neighbourhood, `x` becomes the last (the gap stays
    /// after it). No effect if `a` is not a neighbour, refused if `x` is
    /// `v` or already a neighbour (note 5), or is the null or a dead
    /// vertex.
    #[inline]
    pub fn splice_after(&mut self, x: u32, a: u32, v: u32) -> Result<(), String> {
        self.splice(x, a, v, 1, AFTER)
    }

    /// `splice x before a in v`: inserts `x` right before `a`; before the
    /// first of an open neighbourhood, `x` becomes the first. Otherwise as
    /// [`Rotation::splice_after`].
    #[inline]
    pub fn splice_before(&mut self, x: u32, a: u32, v: u32) -> Result<(), String> {
        self.splice(x, a, v, 0, BEFORE)
    }

    #[inline]
    fn splice(&mut self, x: u32, a: u32, v: u32, shift: usize, op: Op) -> Result<(), String> {
        self.edits += 1;
        let i = self.slot(v, false, op)?;
        self.storable(x, v, op)?;
        let Some(k) = find(&self.nbs[i], a) else {
            return Ok(());
        };
        if find(&self.nbs[i], x).is_some() {
            return Err(already(op, x, v));
        }
        let at = k + shift;
        if self.nbs[i].capacity() == 0 {
            self.nbs[i].reserve_exact(FIRST_CAPACITY);
        }
        self.nbs[i].insert(at, x);
        let w = self.edge_default.len();
        if w > 0 {
            let vals = &mut self.edges[i];
            let end = vals.len();
            vals.extend_from_slice(&self.edge_default);
            vals.copy_within(at * w..end, (at + 1) * w);
            vals[at * w..(at + 1) * w].copy_from_slice(&self.edge_default);
        }
        Ok(())
    }

    // ----- positions and properties ------------------------------------

    /// `v$pos` (or `'v$pos` with `old`).
    #[inline]
    pub fn pos(&self, v: u32, old: bool) -> Result<DVec3, String> {
        let i = self.slot(v, old, POS)?;
        Ok(if old { self.old_pos[i] } else { self.pos[i] })
    }

    /// Sets `v$pos`.
    #[inline]
    pub fn set_pos(&mut self, v: u32, p: DVec3) -> Result<(), String> {
        let i = self.slot(v, false, POS)?;
        self.pos[i] = p;
        Ok(())
    }

    /// The values of vertex property `idx` of `v`.
    pub fn vertex_property(&self, v: u32, idx: usize, old: bool) -> Result<&[f64], String> {
        let i = self.slot(v, old, VPROP)?;
        let c = self
            .vprops
            .get(idx)
            .ok_or_else(|| format!("there is no vertex property {idx}"))?;
        let data = if old { &c.old } else { &c.cur };
        Ok(&data[i * c.width..(i + 1) * c.width])
    }

    /// Sets vertex property `idx` of `v`.
    pub fn set_vertex_property(&mut self, v: u32, idx: usize, vals: &[f64]) -> Result<(), String> {
        let i = self.slot(v, false, VPROP)?;
        let c = self
            .vprops
            .get_mut(idx)
            .ok_or_else(|| format!("there is no vertex property {idx}"))?;
        if vals.len() != c.width {
            return Err(width_error("vertex", idx, c.width, vals.len()));
        }
        c.cur[i * c.width..(i + 1) * c.width].copy_from_slice(vals);
        Ok(())
    }

    /// The values of edge property `idx` of the directed edge `(v, x)`;
    /// `None` if `x` is not a neighbour of `v`.
    pub fn edge_property(
        &self,
        v: u32,
        x: u32,
        idx: usize,
        old: bool,
    ) -> Result<Option<&[f64]>, String> {
        let i = self.slot(v, old, EPROP)?;
        let f = self.edge_field(idx)?;
        let (list, vals) = if old {
            (&self.old_nbs[i], &self.old_edges[i])
        } else {
            (&self.nbs[i], &self.edges[i])
        };
        let w = self.edge_default.len();
        Ok(find(list, x).map(|k| &vals[k * w + f.offset..k * w + f.offset + f.width]))
    }

    /// Sets edge property `idx` of the directed edge `(v, x)`; refused if
    /// `x` is not a neighbour of `v`.
    pub fn set_edge_property(
        &mut self,
        v: u32,
        x: u32,
        idx: usize,
        vals: &[f64],
    ) -> Result<(), String> {
        let i = self.slot(v, false, EPROP)?;
        let f = self.edge_field(idx)?;
        if vals.len() != f.width {
            return Err(width_error("edge", idx, f.width, vals.len()));
        }
        let Some(k) = find(&self.nbs[i], x) else {
            return Err(format!(
                "`{}`: vertex {x} is not a neighbour of vertex {v}, so there is no edge \
                 ({v}, {x})",
                EPROP.name
            ));
        };
        let at = k * self.edge_default.len() + f.offset;
        self.edges[i][at..at + f.width].copy_from_slice(vals);
        Ok(())
    }

    fn edge_field(&self, idx: usize) -> Result<Field, String> {
        self.efields
            .get(idx)
            .copied()
            .ok_or_else(|| format!("there is no edge property {idx}"))
    }

    /// The values of mesh property `idx`.
    pub fn mesh_property(&self, idx: usize) -> Result<&[f64], String> {
        let f = self.mesh_field(idx)?;
        Ok(&self.mdata[f.offset..f.offset + f.width])
    }

    /// Sets mesh property `idx`.
    pub fn set_mesh_property(&mut self, idx: usize, vals: &[f64]) -> Result<(), String> {
        let f = self.mesh_field(idx)?;
        if vals.len() != f.width {
            return Err(width_error("mesh", idx, f.width, vals.len()));
        }
        self.mdata[f.offset..f.offset + f.width].copy_from_slice(vals);
        Ok(())
    }

    fn mesh_field(&self, idx: usize) -> Result<Field, String> {
        self.mfields
            .get(idx)
            .copied()
            .ok_or_else(|| format!("there is no mesh property {idx}"))
    }

    // ----- coordination and lifetime -------------------------------------

    /// `synchronize S`: copies the current state of every vertex of `set`
    /// (neighbours, openness, position, vertex and edge properties) to its
    /// old state, which the `old` readings return until the next
    /// synchronize that includes it. Refused, with nothing copied, if a
    /// member is the null or a dead vertex.
    pub fn synchronize(&mut self, set: &[u32]) -> Result<(), String> {
        for &v in set {
            self.slot(v, false, SYNC)?;
        }
        for &v in set {
            let i = v as usize;
            self.old_nbs[i].clear();
            self.old_nbs[i].extend_from_slice(&self.nbs[i]);
            self.old_open[i] = self.open[i];
            self.old_pos[i] = self.pos[i];
            self.old_edges[i].clear();
            self.old_edges[i].extend_from_slice(&self.edges[i]);
            for c in &mut self.vprops {
                let r = i * c.width..(i + 1) * c.width;
                c.old[r.clone()].copy_from_slice(&c.cur[r]);
            }
            self.synced[i] = true;
        }
        Ok(())
    }

    /// Frees `v`: its slot goes to the free list, its generation moves on,
    /// so handles to it are stale. Its neighbours' lists are not touched.
    pub fn free(&mut self, v: u32) -> Result<(), String> {
        self.edits += 1;
        let i = self.slot(v, false, FREE)?;
        self.alive[i] = false;
        self.gen[i] = self.gen[i].wrapping_add(1);
        self.nbs[i].clear();
        self.open[i] = false;
        self.edges[i].clear();
        self.synced[i] = false;
        self.old_nbs[i].clear();
        self.old_edges[i].clear();
        self.free.push(v);
        self.live -= 1;
        Ok(())
    }

    /// Frees every vertex alive that `live` does not hold, in id order
    /// (entries that are not alive are ignored).
    pub fn retain(&mut self, live: &[u32]) {
        self.marks.clear();
        self.marks.resize(self.alive.len(), false);
        for &v in live {
            if let Some(m) = self.marks.get_mut(v as usize) {
                *m = true;
            }
        }
        for i in 0..self.alive.len() {
            if self.alive[i] && !self.marks[i] {
                // Alive, so free cannot refuse.
                let _ = self.free(i as u32);
            }
        }
    }

    // ----- structure -----------------------------------------------------

    /// The consistency check of the vertex-vertex system over `set`, with
    /// the first problem found (members in id order, neighbours in list
    /// order): every member alive and listed once; the set closed (every
    /// neighbour of a member a member); no vertex its own neighbour or
    /// listed twice; symmetry (`u ∈ v*` iff `v ∈ u*`); and a 2-manifold
    /// face structure: every orbit of Edmonds' technique is a face (no
    /// corner in a gap, at least 3 vertices, none twice) or a hole (every
    /// corner in a gap, at least 3 vertices).
    pub fn check(&self, set: &[u32]) -> Result<(), String> {
        // The order of the orbits does not matter to a check.
        self.trace(set, false, |_, _| {})
    }

    /// The faces of the polygonal interpretation of `set` (Edmonds'
    /// technique, §2.1), each counter-clockwise seen from the outside and
    /// starting at its smallest vertex, ordered by their first two
    /// vertices. Refused as [`Rotation::check`] refuses.
    pub fn faces(&self, set: &[u32]) -> Result<Vec<Vec<u32>>, String> {
        self.orbits(set, false)
    }

    /// The holes (boundary loops) of `set`, each as its orbit runs
    /// (clockwise seen from the outside), starting at its smallest vertex,
    /// ordered by their first two vertices. Refused as [`Rotation::check`]
    /// refuses.
    pub fn holes(&self, set: &[u32]) -> Result<Vec<Vec<u32>>, String> {
        self.orbits(set, true)
    }

    fn orbits(&self, set: &[u32], holes: bool) -> Result<Vec<Vec<u32>>, String> {
        let mut out = Vec::new();
        self.trace(set, true, |hole, vs| {
            if hole == holes {
                out.push(vs.to_vec());
            }
        })?;
        Ok(out)
    }

    /// Checks `set` and hands every orbit to `each` (whether it is a hole,
    /// its vertices from its smallest one), ordered by their first two
    /// vertices.
    ///
    /// The orbit of the directed edge `(u, v)` continues with `(v, w)`,
    /// `w` the vertex before `u` in `v`'s list read cyclically, which with
    /// counter-clockwise lists traces a face counter-clockwise. The corner
    /// `(u, v, w)` lies in `v`'s gap when `v` is open and `u` is its first.
    ///
    /// Members are taken in id order, so an orbit is met first at its
    /// smallest vertex, and from there along its edges in the order of
    /// their other ends. Each step checks the vertex it comes to (alive, in
    /// the set, listing the vertex it came from); every directed edge is
    /// walked once.
    ///
    /// With `ordered` false the orbits come in no particular order (the
    /// edges of a member in the order of its list), which is all a check
    /// needs.
    fn trace(
        &self,
        set: &[u32],
        ordered: bool,
        mut each: impl FnMut(bool, &[u32]),
    ) -> Result<(), String> {
        const NONE: u32 = u32::MAX;
        let slots = self.alive.len();
        // Each member's first directed edge in `seen_edge`; NONE for the
        // vertices outside the set.
        let mut offset = vec![NONE; slots];
        for &v in set {
            if !self.is_alive(v) {
                let what = if v == NULL {
                    "the null vertex".to_string()
                } else if v as usize >= slots {
                    format!("vertex {v}, which does not exist")
                } else {
                    format!("vertex {v}, which no longer exists")
                };
                return Err(format!("`check`: the set holds {what}"));
            }
            if offset[v as usize] != NONE {
                return Err(format!("`check`: the set holds vertex {v} twice"));
            }
            offset[v as usize] = 0;
        }
        let sorted;
        let members = if !ordered || set.is_sorted() {
            set
        } else {
            sorted = {
                let mut m = set.to_vec();
                m.sort_unstable();
                m
            };
            &sorted[..]
        };
        let mut total = 0usize;
        for &u in members {
            let list = &self.nbs[u as usize];
            if total + list.len() >= NONE as usize {
                return Err("`check`: the set has too many edges".into());
            }
            offset[u as usize] = total as u32;
            total += list.len();
            if let Some(x) = self.loop_or_repeat(u, list) {
                return Err(if x == u {
                    format!("vertex {u} lists itself as a neighbour")
                } else {
                    format!("vertex {u} lists vertex {x} twice")
                });
            }
        }
        let mut stamp = vec![0u32; slots];
        let mut seen_edge = vec![false; total];
        let mut orbit = Vec::new();
        let mut order: Vec<(u32, usize)> = Vec::new();
        let mut count = 0u32;
        for &u in members {
            let start = &self.nbs[u as usize];
            order.clear();
            order.extend(start.iter().enumerate().map(|(p, &v)| (v, p)));
            if ordered {
                order.sort_unstable();
            }
            for &(v, p) in &order {
                if seen_edge[offset[u as usize] as usize + p] {
                    continue;
                }
                count = count.wrapping_add(1).max(1);
                orbit.clear();
                let (mut a, mut pa) = (u, p);
                let (mut gap_at, mut face_at, mut twice) = (NULL, NULL, NULL);
                loop {
                    seen_edge[offset[a as usize] as usize + pa] = true;
                    if stamp[a as usize] == count && twice == NULL {
                        twice = a;
                    }
                    stamp[a as usize] = count;
                    orbit.push(a);
                    let b = self.nbs[a as usize][pa];
                    if offset.get(b as usize).is_none_or(|&o| o == NONE) {
                        return Err(if self.is_alive(b) {
                            format!("vertex {a} lists vertex {b}, which is not in the set")
                        } else {
                            format!("vertex {a} lists vertex {b}, which no longer exists")
                        });
                    }
                    let list = &self.nbs[b as usize];
                    let Some(q) = find(list, a) else {
                        return Err(format!(
                            "vertex {a} lists {b} as a neighbour but {b} does not list {a}"
                        ));
                    };
                    if q == 0 && self.open[b as usize] {
                        gap_at = if gap_at == NULL { b } else { gap_at };
                    } else {
                        face_at = if face_at == NULL { b } else { face_at };
                    }
                    let pw = if q == 0 { list.len() - 1 } else { q - 1 };
                    (a, pa) = (b, pw);
                    if (a, pa) == (u, p) {
                        break;
                    }
                    if seen_edge[offset[a as usize] as usize + pa] || orbit.len() > total {
                        return Err(format!(
                            "the orbit of edge ({u}, {v}) does not close: the neighbourhoods \
                             are not a rotation system"
                        ));
                    }
                }
                if gap_at != NULL && face_at != NULL {
                    return Err(format!(
                        "the faces and the boundary disagree on the loop through edge ({u}, \
                         {v}): vertex {gap_at}'s neighbourhood is open there but vertex \
                         {face_at}'s is not"
                    ));
                }
                let hole = gap_at != NULL;
                if orbit.len() < 3 {
                    return Err(if hole {
                        format!("edge ({u}, {v}) borders no face: both its sides are boundary")
                    } else {
                        format!(
                            "the face through edge ({u}, {v}) has only 2 vertices: a face \
                             needs at least 3"
                        )
                    });
                }
                if twice != NULL {
                    return Err(format!(
                        "the {} through edge ({u}, {v}) passes vertex {twice} twice",
                        if hole { "boundary" } else { "face" }
                    ));
                }
                each(hole, &orbit);
            }
        }
        Ok(())
    }

    /// `u` itself or a vertex that `list`, `u`'s neighbours, holds twice:
    /// pairwise for the short lists of most meshes, by sorting a copy for
    /// long ones.
    fn loop_or_repeat(&self, u: u32, list: &[u32]) -> Option<u32> {
        if list.len() <= 16 {
            return list
                .iter()
                .enumerate()
                .find(|&(k, &x)| x == u || list[..k].contains(&x))
                .map(|(_, &x)| x);
        }
        if list.contains(&u) {
            return Some(u);
        }
        let mut copy = list.to_vec();
        copy.sort_unstable();
        copy.windows(2).find(|w| w[0] == w[1]).map(|w| w[0])
    }

    // ----- polygon soups -------------------------------------------------

    /// The system built from the counter-clockwise polygons of `soup`
    /// (any size from 3): vertex `i` of the soup is vertex `i` here, at
    /// its position; the second value lists the vertices in id order.
    ///
    /// At a corner `(…, a, v, b, …)` of a polygon, `a` immediately follows
    /// `b` in `v`'s counter-clockwise list; each vertex's corners link into
    /// one fan, open (a boundary vertex, its first the fan's start) or
    /// closed. Refused: polygons of fewer than 3 vertices, a vertex twice
    /// in a polygon, an index out of range, a directed edge used by two
    /// polygons (orientations that disagree, or more than two polygons at
    /// an edge) and a vertex whose polygons form more than one fan. A
    /// vertex in no polygon has no neighbours.
    pub fn from_soup(soup: &PolygonSoup) -> Result<(Rotation, Vec<u32>), String> {
        let n = soup.positions.len();
        if n >= NULL as usize {
            return Err(format!("the mesh has {n} vertices, too many"));
        }
        let face = |f: usize| match soup.face_line(f) {
            Some(l) => format!("face {} (line {l})", f + 1),
            None => format!("face {}", f + 1),
        };
        // Corners sorted by vertex: `start[v]..start[v + 1]`.
        let mut start = vec![0usize; n + 1];
        for (fi, f) in soup.faces.iter().enumerate() {
            if f.len() < 3 {
                return Err(format!(
                    "{} has {} vertices; a face needs at least 3",
                    face(fi),
                    f.len()
                ));
            }
            if let Some(&v) = f.iter().find(|&&v| v as usize >= n) {
                return Err(format!(
                    "{} refers to vertex {}, but there are only {n} vertices",
                    face(fi),
                    v as usize + 1
                ));
            }
            if let Some(k) = crate::mesh::soup::first_repeat(f) {
                return Err(format!(
                    "{} uses vertex {} twice",
                    face(fi),
                    f[k] as usize + 1
                ));
            }
            for &v in f {
                start[v as usize + 1] += 1;
            }
        }
        for v in 0..n {
            start[v + 1] += start[v];
        }
        /// A corner at a vertex: `a` follows `b` there; from polygon `face`.
        #[derive(Clone, Copy)]
        struct Corner {
            b: u32,
            a: u32,
            face: usize,
        }
        let mut fill = start.clone();
        let mut corners = vec![
            Corner {
                b: 0,
                a: 0,
                face: 0
            };
            start[n]
        ];
        for (fi, f) in soup.faces.iter().enumerate() {
            let k = f.len();
            for j in 0..k {
                let v = f[j] as usize;
                corners[fill[v]] = Corner {
                    b: f[(j + 1) % k],
                    a: f[(j + k - 1) % k],
                    face: fi,
                };
                fill[v] += 1;
            }
        }
        // Each directed edge (v, b) once.
        for v in 0..n {
            let cs = &mut corners[start[v]..start[v + 1]];
            cs.sort_unstable_by_key(|c| (c.b, c.face));
            if let Some(w) = cs.windows(2).find(|w| w[0].b == w[1].b) {
                return Err(format!(
                    "{} and {} both run from vertex {} to vertex {}: their orientations \
                     disagree, or more than two faces meet at that edge",
                    face(w[0].face),
                    face(w[1].face),
                    v + 1,
                    w[0].b as usize + 1
                ));
            }
        }
        // One fan per vertex.
        let mut rot = Rotation::new();
        let mut has_pred = vec![false; start[n]];
        for v in 0..n {
            let id = rot.new_vertex();
            rot.pos[id as usize] = soup.positions[v];
            let (s, e) = (start[v], start[v + 1]);
            let cs = &corners[s..e];
            let next = |x: u32| cs.binary_search_by_key(&x, |c| c.b).ok();
            for c in cs {
                if let Some(k) = next(c.a) {
                    has_pred[s + k] = true;
                }
            }
            let mut starts = (0..cs.len()).filter(|&k| !has_pred[s + k]);
            let first = starts.next();
            let open = first.is_some();
            let bow_tie = || {
                format!(
                    "vertex {} is a bow-tie: its faces form more than one fan, so the mesh is \
                     not a 2-manifold there",
                    v + 1
                )
            };
            if starts.next().is_some() {
                return Err(bow_tie());
            }
            if cs.is_empty() {
                continue;
            }
            let k0 = first.unwrap_or(0);
            let list = &mut rot.nbs[v];
            list.push(cs[k0].b);
            let mut k = k0;
            let mut walked = 1;
            loop {
                let a = cs[k].a;
                if a == cs[k0].b {
                    break; // closed, back at the start
                }
                list.push(a);
                match next(a) {
                    Some(j) if walked < cs.len() => {
                        k = j;
                        walked += 1;
                    }
                    _ => break, // open: `a` is the last
                }
            }
            if walked != cs.len() {
                return Err(bow_tie());
            }
            rot.open[v] = open;
        }
        let members = (0..n as u32).collect();
        Ok((rot, members))
    }

    /// `set` as a polygon soup: the positions in `set`'s order and the
    /// faces of [`Rotation::faces`] by position in `set`.
    pub fn to_soup(&self, set: &[u32]) -> Result<PolygonSoup, String> {
        self.to_soup_and_holes(set).map(|(soup, _)| soup)
    }

    /// [`Rotation::to_soup`], and the number of holes, from one walk.
    pub fn to_soup_and_holes(&self, set: &[u32]) -> Result<(PolygonSoup, usize), String> {
        let mut index = vec![0u32; self.alive.len()];
        for (k, &v) in set.iter().enumerate() {
            if let Some(i) = index.get_mut(v as usize) {
                *i = k as u32;
            }
        }
        let mut faces = crate::mesh::Faces::new();
        let mut holes = 0;
        self.trace(set, true, |hole, vs| {
            if hole {
                holes += 1;
            } else {
                faces.push(vs.iter().map(|&v| index[v as usize]).collect::<Vec<u32>>());
            }
        })?;
        let soup = PolygonSoup {
            positions: set.iter().map(|&v| self.pos[v as usize]).collect(),
            faces,
            ..Default::default()
        };
        Ok((soup, holes))
    }
}

#[cold]
fn already(op: Op, x: u32, v: u32) -> String {
    format!(
        "`{}`: vertex {x} is already a neighbour of vertex {v}",
        op.name
    )
}

#[cold]
fn width_error(kind: &str, idx: usize, width: usize, got: usize) -> String {
    format!("{kind} property {idx} holds {width} values, not {got}")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes::{icosphere, quad_grid};

    /// A system of `n` vertices with no neighbours.
    fn vertices(n: usize) -> (Rotation, Vec<u32>) {
        let mut r = Rotation::new();
        let vs = (0..n).map(|_| r.new_vertex()).collect();
        (r, vs)
    }

    fn nbs(r: &Rotation, v: u32) -> Vec<u32> {
        r.neighbours(v, false).unwrap().to_vec()
    }

    /// A polygon rotated to start at its smallest vertex.
    fn canonical(f: &[u32]) -> Vec<u32> {
        let k = (0..f.len()).min_by_key(|&k| f[k]).unwrap();
        f[k..].iter().chain(&f[..k]).copied().collect()
    }

    fn canonical_faces<F: AsRef<[u32]>>(faces: impl IntoIterator<Item = F>) -> Vec<Vec<u32>> {
        let mut out: Vec<Vec<u32>> = faces.into_iter().map(|f| canonical(f.as_ref())).collect();
        out.sort();
        out
    }

    /// The number of undirected edges: half the directed ones.
    fn edge_count(r: &Rotation, set: &[u32]) -> usize {
        set.iter()
            .map(|&v| r.valence(v, false).unwrap())
            .sum::<usize>()
            / 2
    }

    /// Newell's normal of a polygon.
    fn normal(r: &Rotation, f: &[u32]) -> DVec3 {
        let p = |k: usize| r.pos(f[k % f.len()], false).unwrap();
        (0..f.len()).map(|k| p(k).cross(p(k + 1))).sum()
    }

    fn centroid(r: &Rotation, f: &[u32]) -> DVec3 {
        f.iter().map(|&v| r.pos(v, false).unwrap()).sum::<DVec3>() / f.len() as f64
    }

    /// Every face's normal points away from `centre`: the faces run
    /// counter-clockwise seen from the outside.
    fn assert_outward(r: &Rotation, faces: &[Vec<u32>], centre: DVec3) {
        for f in faces {
            assert!(
                normal(r, f).dot(centroid(r, f) - centre) > 0.0,
                "face {f:?} runs clockwise"
            );
        }
    }

    fn cube() -> PolygonSoup {
        let positions = [
            (0., 0., 0.),
            (1., 0., 0.),
            (1., 1., 0.),
            (0., 1., 0.),
            (0., 0., 1.),
            (1., 0., 1.),
            (1., 1., 1.),
            (0., 1., 1.),
        ];
        PolygonSoup {
            positions: positions
                .iter()
                .map(|&(x, y, z)| DVec3::new(x, y, z))
                .collect(),
            // Bottom, top, y = 0, y = 1, x = 0, x = 1; outward normals are
            // checked by `assert_outward`.
            faces: vec![
                vec![0, 3, 2, 1],
                vec![4, 5, 6, 7],
                vec![0, 1, 5, 4],
                vec![2, 3, 7, 6],
                vec![0, 4, 7, 3],
                vec![1, 2, 6, 5],
            ]
            .into(),
            ..Default::default()
        }
    }

    fn octahedron() -> PolygonSoup {
        // 0 = +x, 1 = -x, 2 = +y, 3 = -y, 4 = +z, 5 = -z; one triangle per
        // octant, (x, y, z) turned over where an odd number of signs is
        // negative (a reflection reverses orientation).
        let positions = vec![
            DVec3::X,
            -DVec3::X,
            DVec3::Y,
            -DVec3::Y,
            DVec3::Z,
            -DVec3::Z,
        ];
        let mut faces = Vec::new();
        for sx in 0..2u32 {
            for sy in 0..2u32 {
                for sz in 0..2u32 {
                    let (x, y, z) = (sx, 2 + sy, 4 + sz);
                    faces.push(if (sx + sy + sz) % 2 == 0 {
                        vec![x, y, z]
                    } else {
                        vec![x, z, y]
                    });
                }
            }
        }
        PolygonSoup {
            positions,
            faces: faces.into(),
            ..Default::default()
        }
    }

    // ----- Table 2: queries and selection -------------------------------

    #[test]
    fn queries_and_selection_on_a_closed_neighbourhood() {
        let (mut r, v) = vertices(5);
        r.make(v[0], &[v[1], v[2], v[3]]).unwrap();
        assert_eq!(r.valence(v[0], false), Ok(3));
        assert_eq!(r.is_in(v[2], v[0], false), Ok(true));
        assert_eq!(r.is_in(v[4], v[0], false), Ok(false));
        assert_eq!(r.is_in(NULL, v[0], false), Ok(false));
        assert_eq!(r.any(v[0], false), Ok(v[1]));
        assert_eq!(r.is_open(v[0], false), Ok(false));
        // Cyclic: after the last comes the first, before the first the last.
        assert_eq!(r.nextto(v[1], v[0], false), Ok(v[2]));
        assert_eq!(r.nextto(v[3], v[0], false), Ok(v[1]));
        assert_eq!(r.prevto(v[1], v[0], false), Ok(v[3]));
        assert_eq!(r.prevto(v[3], v[0], false), Ok(v[2]));
        // Note 2: the null vertex for a vertex not in the neighbourhood.
        assert_eq!(r.nextto(v[4], v[0], false), Ok(NULL));
        assert_eq!(r.prevto(v[4], v[0], false), Ok(NULL));
        assert_eq!(r.nextto(NULL, v[0], false), Ok(NULL));
        // Note 1: the null vertex from an empty neighbourhood.
        assert_eq!(r.any(v[4], false), Ok(NULL));
        assert_eq!(r.valence(v[4], false), Ok(0));
    }

    #[test]
    fn a_single_neighbour_follows_and_precedes_itself() {
        let (mut r, v) = vertices(2);
        r.make(v[0], &[v[1]]).unwrap();
        assert_eq!(r.nextto(v[1], v[0], false), Ok(v[1]));
        assert_eq!(r.prevto(v[1], v[0], false), Ok(v[1]));
    }

    #[test]
    fn selection_on_an_open_neighbourhood_stops_at_the_gap() {
        let (mut r, v) = vertices(4);
        // `{p, NULL, q, r}`: the gap lies between p and q, so the open list
        // runs q, r, p.
        r.make(v[0], &[v[1], NULL, v[2], v[3]]).unwrap();
        assert_eq!(nbs(&r, v[0]), [v[2], v[3], v[1]]);
        assert_eq!(r.is_open(v[0], false), Ok(true));
        assert_eq!(r.any(v[0], false), Ok(v[2]));
        assert_eq!(r.nextto(v[2], v[0], false), Ok(v[3]));
        assert_eq!(r.nextto(v[3], v[0], false), Ok(v[1]));
        assert_eq!(
            r.nextto(v[1], v[0], false),
            Ok(NULL),
            "last: the gap follows"
        );
        assert_eq!(
            r.prevto(v[2], v[0], false),
            Ok(NULL),
            "first: the gap precedes"
        );
        assert_eq!(r.prevto(v[1], v[0], false), Ok(v[3]));
    }

    // ----- make (note 3) --------------------------------------------------

    #[test]
    fn make_takes_one_run_of_null_vertices_read_cyclically() {
        let (mut r, v) = vertices(4);
        // A run at both ends is one run across the wrap.
        r.make(v[0], &[NULL, v[1], v[2], NULL]).unwrap();
        assert_eq!(nbs(&r, v[0]), [v[1], v[2]]);
        assert_eq!(r.is_open(v[0], false), Ok(true));
        r.make(v[0], &[NULL, NULL, v[3]]).unwrap();
        assert_eq!(nbs(&r, v[0]), [v[3]]);
        assert_eq!(r.is_open(v[0], false), Ok(true));
        // Nothing but the null vertex: no neighbours, closed.
        r.make(v[0], &[NULL]).unwrap();
        assert_eq!(nbs(&r, v[0]), [] as [u32; 0]);
        assert_eq!(r.is_open(v[0], false), Ok(false));
        // A list without gaps closes an open neighbourhood.
        r.make(v[0], &[v[1], NULL]).unwrap();
        r.make(v[0], &[v[3], v[1]]).unwrap();
        assert_eq!(nbs(&r, v[0]), [v[3], v[1]]);
        assert_eq!(r.is_open(v[0], false), Ok(false));
        assert_eq!(
            r.make(v[0], &[v[1], NULL, v[2], NULL]),
            Err(
                "`make {…} nb_of v`: the list has more than one gap (its null vertices form 2 \
                 runs); an open neighbourhood has one"
                    .into()
            )
        );
    }

    #[test]
    fn make_refuses_v_itself_and_repeats() {
        let (mut r, v) = vertices(4);
        r.make(v[0], &[v[1], v[2]]).unwrap();
        assert_eq!(
            r.make(v[0], &[v[1], v[0], v[2]]),
            Err("`make {…} nb_of v`: v (vertex 0) is listed in its own neighbourhood".into())
        );
        assert_eq!(
            r.make(v[0], &[v[1], v[2], v[3], v[2]]),
            Err("`make {…} nb_of v`: vertex 2 is listed twice".into())
        );
        // A refused make leaves the neighbourhood as it was.
        assert_eq!(nbs(&r, v[0]), [v[1], v[2]]);
        // Long lists are checked by sorting.
        let (mut r, v) = vertices(60);
        let mut list: Vec<u32> = v[1..].to_vec();
        list.push(v[40]);
        assert_eq!(
            r.make(v[0], &list),
            Err("`make {…} nb_of v`: vertex 40 is listed twice".into())
        );
        list.pop();
        r.make(v[0], &list).unwrap();
        assert_eq!(r.valence(v[0], false), Ok(59));
    }

    #[test]
    fn make_refuses_dead_and_unknown_vertices() {
        let (mut r, v) = vertices(3);
        r.free(v[2]).unwrap();
        assert_eq!(
            r.make(v[0], &[v[1], v[2]]),
            Err("`make {…} nb_of v`: the list holds vertex 2, which no longer exists".into())
        );
        assert_eq!(
            r.make(v[0], &[v[1], 7]),
            Err("`make {…} nb_of v`: the list holds vertex 7, which does not exist".into())
        );
        assert_eq!(
            r.make(NULL, &[v[1]]),
            Err("`make {…} nb_of v`: the null vertex has no neighbourhood".into())
        );
        assert_eq!(
            r.make(v[2], &[v[1]]),
            Err("`make {…} nb_of v`: vertex 2 no longer exists".into())
        );
    }

    // ----- erase (note 4) -------------------------------------------------

    #[test]
    fn erase_removes_or_does_nothing() {
        let (mut r, v) = vertices(5);
        r.make(v[0], &[v[1], v[2], v[3]]).unwrap();
        r.erase(v[2], v[0]).unwrap();
        assert_eq!(nbs(&r, v[0]), [v[1], v[3]]);
        // Note 4: no effect if x is not a neighbour.
        r.erase(v[4], v[0]).unwrap();
        r.erase(NULL, v[0]).unwrap();
        assert_eq!(nbs(&r, v[0]), [v[1], v[3]]);
        // An open neighbourhood emptied is closed.
        r.make(v[4], &[v[1], NULL]).unwrap();
        r.erase(v[1], v[4]).unwrap();
        assert_eq!(r.valence(v[4], false), Ok(0));
        assert_eq!(r.is_open(v[4], false), Ok(false));
        assert_eq!(
            r.erase(v[1], NULL),
            Err("`erase x from v`: the null vertex has no neighbourhood".into())
        );
    }

    // ----- replace (note 5) ------------------------------------------------

    #[test]
    fn replace_substitutes_in_place() {
        let (mut r, v) = vertices(6);
        r.make(v[0], &[v[1], v[2], NULL, v[3]]).unwrap();
        assert_eq!(nbs(&r, v[0]), [v[3], v[1], v[2]]);
        r.replace(v[1], v[4], v[0]).unwrap();
        assert_eq!(nbs(&r, v[0]), [v[3], v[4], v[2]]);
        assert_eq!(r.is_open(v[0], false), Ok(true), "openness unchanged");
        // Note 5: no effect if a is not a neighbour.
        r.replace(v[5], v[1], v[0]).unwrap();
        r.replace(NULL, v[1], v[0]).unwrap();
        assert_eq!(nbs(&r, v[0]), [v[3], v[4], v[2]]);
        // Note 5: refused if x = v or x is a neighbour already.
        assert_eq!(
            r.replace(v[4], v[0], v[0]),
            Err(
                "`replace a with x in v`: x is v itself (vertex 0); a vertex is not its own \
                 neighbour"
                    .into()
            )
        );
        assert_eq!(
            r.replace(v[4], v[2], v[0]),
            Err("`replace a with x in v`: vertex 2 is already a neighbour of vertex 0".into())
        );
        assert_eq!(
            r.replace(v[4], v[4], v[0]),
            Err("`replace a with x in v`: vertex 4 is already a neighbour of vertex 0".into())
        );
        assert_eq!(
            r.replace(v[4], NULL, v[0]),
            Err(
                "`replace a with x in v`: x is the null vertex, which cannot be a neighbour".into()
            )
        );
        r.free(v[5]).unwrap();
        assert_eq!(
            r.replace(v[4], v[5], v[0]),
            Err("`replace a with x in v`: x is vertex 5, which no longer exists".into())
        );
        assert_eq!(nbs(&r, v[0]), [v[3], v[4], v[2]]);
    }

    // ----- splice (note 5) -------------------------------------------------

    #[test]
    fn splice_inserts_after_and_before() {
        let (mut r, v) = vertices(7);
        r.make(v[0], &[v[1], v[2], v[3]]).unwrap();
        r.splice_after(v[4], v[1], v[0]).unwrap();
        assert_eq!(nbs(&r, v[0]), [v[1], v[4], v[2], v[3]]);
        r.splice_before(v[5], v[1], v[0]).unwrap();
        // Before the first of a closed list: cyclically between 3 and 1.
        assert_eq!(nbs(&r, v[0]), [v[5], v[1], v[4], v[2], v[3]]);
        assert_eq!(r.prevto(v[1], v[0], false), Ok(v[5]));
        assert_eq!(r.nextto(v[3], v[0], false), Ok(v[5]));
        // Note 5: no effect if a is not a neighbour.
        r.splice_after(v[6], NULL, v[0]).unwrap();
        r.splice_before(v[6], v[6], v[0]).unwrap();
        assert_eq!(r.valence(v[0], false), Ok(5));
        // Note 5: refused if x = v or x is a neighbour already.
        assert_eq!(
            r.splice_after(v[0], v[1], v[0]),
            Err(
                "`splice x after a in v`: x is v itself (vertex 0); a vertex is not its own \
                 neighbour"
                    .into()
            )
        );
        assert_eq!(
            r.splice_before(v[2], v[1], v[0]),
            Err("`splice x before a in v`: vertex 2 is already a neighbour of vertex 0".into())
        );
        assert_eq!(
            r.splice_before(NULL, v[1], v[0]),
            Err(
                "`splice x before a in v`: x is the null vertex, which cannot be a neighbour"
                    .into()
            )
        );
        assert_eq!(r.valence(v[0], false), Ok(5));
    }

    #[test]
    fn splice_at_the_gap_extends_an_open_neighbourhood() {
        let (mut r, v) = vertices(5);
        r.make(v[0], &[v[1], v[2], NULL]).unwrap();
        // After the last: the new vertex is the last, the gap after it.
        r.splice_after(v[3], v[2], v[0]).unwrap();
        assert_eq!(nbs(&r, v[0]), [v[1], v[2], v[3]]);
        assert_eq!(r.nextto(v[3], v[0], false), Ok(NULL));
        // Before the first: the new vertex is the first.
        r.splice_before(v[4], v[1], v[0]).unwrap();
        assert_eq!(nbs(&r, v[0]), [v[4], v[1], v[2], v[3]]);
        assert_eq!(r.prevto(v[4], v[0], false), Ok(NULL));
        assert_eq!(r.any(v[0], false), Ok(v[4]));
        assert_eq!(r.is_open(v[0], false), Ok(true));
    }

    // ----- dead, null and unsynchronized vertices --------------------------

    #[test]
    fn every_operation_refuses_null_dead_and_unknown_vertices() {
        let (mut r, v) = vertices(3);
        r.make(v[0], &[v[1], v[2]]).unwrap();
        r.free(v[1]).unwrap();
        type Call = fn(&mut Rotation, u32) -> Result<(), String>;
        let calls: [(&str, Call); 12] = [
            ("is x in v", |r, v| r.is_in(0, v, false).map(drop)),
            ("valence v", |r, v| r.valence(v, false).map(drop)),
            ("forall x in v", |r, v| r.neighbours(v, false).map(drop)),
            ("any in v", |r, v| r.any(v, false).map(drop)),
            ("nextto x in v", |r, v| r.nextto(0, v, false).map(drop)),
            ("prevto x in v", |r, v| r.prevto(0, v, false).map(drop)),
            ("make {…} nb_of v", |r, v| r.make(v, &[0])),
            ("erase x from v", |r, v| r.erase(0, v)),
            ("replace a with x in v", |r, v| r.replace(0, 2, v)),
            ("splice x after a in v", |r, v| r.splice_after(2, 0, v)),
            ("splice x before a in v", |r, v| r.splice_before(2, 0, v)),
            ("v$pos", |r, v| r.set_pos(v, DVec3::ONE)),
        ];
        for (name, call) in calls {
            let null = if name == "v$pos" {
                "has no position"
            } else {
                "has no neighbourhood"
            };
            assert_eq!(
                call(&mut r, NULL),
                Err(format!("`{name}`: the null vertex {null}"))
            );
            assert_eq!(
                call(&mut r, v[1]),
                Err(format!("`{name}`: vertex 1 no longer exists"))
            );
            assert_eq!(
                call(&mut r, 9),
                Err(format!("`{name}`: vertex 9 does not exist"))
            );
        }
        assert_eq!(
            r.free(v[1]),
            Err("`free`: vertex 1 no longer exists".into())
        );
        assert_eq!(
            r.free(NULL),
            Err("`free`: the null vertex cannot be freed".into())
        );
        // Old state exists only after a synchronize.
        assert_eq!(
            r.nextto(v[1], v[0], true),
            Err("`nextto x in v`: vertex 0 was not synchronized, so it has no old state".into())
        );
        assert_eq!(
            r.pos(v[2], true),
            Err("`v$pos`: vertex 2 was not synchronized, so it has no old state".into())
        );
    }

    #[test]
    fn a_freed_slot_is_reused_and_old_handles_go_stale() {
        let (mut r, v) = vertices(3);
        let gen = r.generation(v[1]).unwrap();
        assert!(r.is_live(v[1], gen));
        r.set_pos(v[1], DVec3::ONE).unwrap();
        r.make(v[1], &[v[0], v[2]]).unwrap();
        r.free(v[1]).unwrap();
        assert!(!r.is_live(v[1], gen));
        assert_eq!(r.len(), 2);
        let w = r.new_vertex();
        assert_eq!(w, v[1], "the freed slot is reused");
        assert!(!r.is_live(v[1], gen), "the old handle stays stale");
        assert!(r.is_live(w, r.generation(w).unwrap()));
        assert_eq!(r.generation(w), Some(gen + 1));
        // A fresh vertex in the old slot: no neighbours, closed, at zero.
        assert_eq!(r.valence(w, false), Ok(0));
        assert_eq!(r.pos(w, false), Ok(DVec3::ZERO));
        assert_eq!(r.len(), 3);
        assert!(!r.is_live(NULL, 0));
        assert_eq!(r.generation(NULL), None);
    }

    #[test]
    fn retain_frees_what_is_not_kept() {
        let (mut r, v) = vertices(5);
        r.retain(&[v[1], v[3], NULL]);
        assert_eq!(r.members_alive().collect::<Vec<_>>(), [v[1], v[3]]);
        assert_eq!(r.len(), 2);
    }

    // ----- properties ------------------------------------------------------

    #[test]
    fn vertex_and_mesh_properties_start_at_their_defaults() {
        let (mut r, v) = vertices(2);
        // Declared after vertices exist: they get the default too.
        let colour = r.add_vertex_property(3, &[0.5, 0.25, 1.0]);
        let w = r.new_vertex();
        for x in [v[0], v[1], w] {
            assert_eq!(
                r.vertex_property(x, colour, false),
                Ok(&[0.5, 0.25, 1.0][..])
            );
        }
        r.set_vertex_property(w, colour, &[1.0, 2.0, 3.0]).unwrap();
        assert_eq!(
            r.vertex_property(w, colour, false),
            Ok(&[1.0, 2.0, 3.0][..])
        );
        assert_eq!(
            r.vertex_property(v[0], colour, false),
            Ok(&[0.5, 0.25, 1.0][..])
        );
        assert_eq!(
            r.set_vertex_property(w, colour, &[1.0]),
            Err("vertex property 0 holds 3 values, not 1".into())
        );
        assert_eq!(
            r.vertex_property(w, 4, false),
            Err("there is no vertex property 4".into())
        );
        // A reused slot starts again from the default.
        r.free(w).unwrap();
        let w2 = r.new_vertex();
        assert_eq!(w2, w);
        assert_eq!(
            r.vertex_property(w2, colour, false),
            Ok(&[0.5, 0.25, 1.0][..])
        );
        let m = r.add_mesh_property(2, &[1.0, -1.0]);
        let n = r.add_mesh_property(1, &[4.0]);
        assert_eq!(r.mesh_property(m), Ok(&[1.0, -1.0][..]));
        r.set_mesh_property(n, &[5.0]).unwrap();
        assert_eq!(r.mesh_property(n), Ok(&[5.0][..]));
        assert_eq!(r.mesh_property(m), Ok(&[1.0, -1.0][..]));
    }

    #[test]
    fn edge_properties_stay_with_their_edges() {
        let (mut r, v) = vertices(6);
        let w = r.add_edge_property(2, &[7.0, 8.0]);
        r.make(v[0], &[v[1], v[2], v[3]]).unwrap();
        let get = |r: &Rotation, x: u32, idx| {
            r.edge_property(v[0], x, idx, false)
                .unwrap()
                .map(<[f64]>::to_vec)
        };
        assert_eq!(get(&r, v[2], w), Some(vec![7.0, 8.0]));
        r.set_edge_property(v[0], v[2], w, &[1.0, 2.0]).unwrap();
        r.set_edge_property(v[0], v[3], w, &[3.0, 4.0]).unwrap();
        // splice: the new edge gets the default, the others keep theirs.
        r.splice_after(v[4], v[2], v[0]).unwrap();
        assert_eq!(get(&r, v[2], w), Some(vec![1.0, 2.0]));
        assert_eq!(get(&r, v[4], w), Some(vec![7.0, 8.0]));
        assert_eq!(get(&r, v[3], w), Some(vec![3.0, 4.0]));
        r.splice_before(v[5], v[1], v[0]).unwrap();
        assert_eq!(get(&r, v[5], w), Some(vec![7.0, 8.0]));
        assert_eq!(get(&r, v[2], w), Some(vec![1.0, 2.0]));
        // replace: the default in the replaced slot.
        r.erase(v[1], v[0]).unwrap();
        r.replace(v[2], v[1], v[0]).unwrap();
        assert_eq!(get(&r, v[1], w), Some(vec![7.0, 8.0]));
        assert_eq!(get(&r, v[2], w), None);
        assert_eq!(get(&r, v[3], w), Some(vec![3.0, 4.0]));
        // erase drops the edge's values.
        r.erase(v[4], v[0]).unwrap();
        assert_eq!(nbs(&r, v[0]), [v[5], v[1], v[3]]);
        assert_eq!(get(&r, v[3], w), Some(vec![3.0, 4.0]));
        // A second property declared now: the first keeps its values.
        let u = r.add_edge_property(1, &[9.0]);
        assert_eq!(get(&r, v[3], w), Some(vec![3.0, 4.0]));
        assert_eq!(get(&r, v[3], u), Some(vec![9.0]));
        r.set_edge_property(v[0], v[3], u, &[-1.0]).unwrap();
        assert_eq!(get(&r, v[3], w), Some(vec![3.0, 4.0]));
        assert_eq!(
            r.set_edge_property(v[0], v[2], w, &[0.0, 0.0]),
            Err(
                "`edge property`: vertex 2 is not a neighbour of vertex 0, so there is no \
                 edge (0, 2)"
                    .into()
            )
        );
        assert_eq!(
            r.set_edge_property(v[0], v[3], u, &[0.0, 0.0]),
            Err("edge property 1 holds 1 values, not 2".into())
        );
        // make resets every edge to the defaults.
        r.make(v[0], &[v[3], v[5]]).unwrap();
        assert_eq!(get(&r, v[3], w), Some(vec![7.0, 8.0]));
        assert_eq!(get(&r, v[3], u), Some(vec![9.0]));
    }

    // ----- synchronize ------------------------------------------------------

    #[test]
    fn the_old_state_is_what_synchronize_copied() {
        let (mut r, v) = vertices(5);
        let p = r.add_vertex_property(1, &[0.0]);
        let e = r.add_edge_property(1, &[0.0]);
        r.make(v[0], &[v[1], v[2], NULL]).unwrap();
        r.set_pos(v[0], DVec3::new(1.0, 2.0, 3.0)).unwrap();
        r.set_vertex_property(v[0], p, &[5.0]).unwrap();
        r.set_edge_property(v[0], v[2], e, &[6.0]).unwrap();
        r.synchronize(&[v[0]]).unwrap();
        // Later edits change the current state only.
        r.make(v[0], &[v[3], v[2], v[4]]).unwrap();
        r.set_pos(v[0], DVec3::ZERO).unwrap();
        r.set_vertex_property(v[0], p, &[-5.0]).unwrap();
        r.set_edge_property(v[0], v[2], e, &[-6.0]).unwrap();
        assert_eq!(r.neighbours(v[0], true), Ok(&[v[1], v[2]][..]));
        assert_eq!(r.is_open(v[0], true), Ok(true));
        assert_eq!(r.is_open(v[0], false), Ok(false));
        assert_eq!(r.nextto(v[2], v[0], true), Ok(NULL));
        assert_eq!(r.nextto(v[2], v[0], false), Ok(v[4]));
        assert_eq!(r.prevto(v[2], v[0], true), Ok(v[1]));
        assert_eq!(r.valence(v[0], true), Ok(2));
        assert_eq!(r.is_in(v[3], v[0], true), Ok(false));
        assert_eq!(r.any(v[0], true), Ok(v[1]));
        assert_eq!(r.pos(v[0], true), Ok(DVec3::new(1.0, 2.0, 3.0)));
        assert_eq!(r.vertex_property(v[0], p, true), Ok(&[5.0][..]));
        assert_eq!(r.edge_property(v[0], v[2], e, true), Ok(Some(&[6.0][..])));
        assert_eq!(r.edge_property(v[0], v[2], e, false), Ok(Some(&[-6.0][..])));
        // A second synchronize takes the new state.
        r.synchronize(&[v[0]]).unwrap();
        assert_eq!(r.neighbours(v[0], true), Ok(&[v[3], v[2], v[4]][..]));
        assert_eq!(r.pos(v[0], true), Ok(DVec3::ZERO));
    }

    #[test]
    fn synchronize_refuses_a_dead_member_and_copies_nothing() {
        let (mut r, v) = vertices(3);
        r.free(v[2]).unwrap();
        assert_eq!(
            r.synchronize(&[v[0], v[2]]),
            Err("`synchronize`: vertex 2 no longer exists".into())
        );
        assert!(r.pos(v[0], true).is_err(), "v0 was not copied");
        assert_eq!(
            r.synchronize(&[NULL]),
            Err("`synchronize`: the null vertex cannot be synchronized".into())
        );
        // A vertex freed and created again has no old state.
        r.synchronize(&[v[1]]).unwrap();
        r.free(v[1]).unwrap();
        let w = r.new_vertex();
        assert!(r.valence(w, true).is_err());
    }

    /// One step of smoothing: every vertex moves to the average of its
    /// neighbours, reading old positions (`old`) or current ones.
    fn smooth(r: &mut Rotation, order: &[u32], old: bool) {
        if old {
            r.synchronize(order).unwrap();
        }
        for &v in order {
            let list = r.neighbours(v, old).unwrap().to_vec();
            let sum: DVec3 = list.iter().map(|&x| r.pos(x, old).unwrap()).sum();
            r.set_pos(v, sum / list.len() as f64).unwrap();
        }
    }

    #[test]
    fn reading_the_old_state_makes_iteration_order_irrelevant() {
        let (base, members) = Rotation::from_soup(&icosphere(1)).unwrap();
        let forward = members.clone();
        let mut shuffled = members.clone();
        shuffled.reverse();
        shuffled.rotate_left(17);
        let run = |order: &[u32], old: bool| {
            let mut r = base.clone();
            smooth(&mut r, order, old);
            smooth(&mut r, order, old);
            members
                .iter()
                .map(|&v| r.pos(v, false).unwrap().to_array().map(f64::to_bits))
                .collect::<Vec<_>>()
        };
        assert_eq!(run(&forward, true), run(&shuffled, true));
        // Reading the current positions instead, the order shows.
        assert_ne!(run(&forward, false), run(&shuffled, false));
    }

    /// One step of the paper's polyhedral subdivision (§3.2), written with
    /// the operations of Table 2: a vertex at the midpoint of every edge
    /// (Fig. 3's insertion), then every new vertex joined to the new
    /// vertices of the two triangles beside its edge. Returns the new set.
    ///
    /// For the edge p–q with the triangles (p, q, r) and (q, p, s), the new
    /// vertex x gets the counter-clockwise list [p, u, w, q, y, z] (u on
    /// p–s, w on s–q, y on q–r, z on r–p): at p, u precedes x and z follows
    /// it; at q, y precedes x and w follows it.
    fn polyhedral(r: &mut Rotation, set: &[u32]) -> Vec<u32> {
        r.synchronize(set).unwrap();
        let mut all = set.to_vec();
        let mut new = Vec::new();
        for &p in set {
            for k in 0..r.valence(p, true).unwrap() {
                let q = r.neighbours(p, true).unwrap()[k];
                if p < q {
                    let x = r.new_vertex();
                    let mid = (r.pos(p, true).unwrap() + r.pos(q, true).unwrap()) / 2.0;
                    r.set_pos(x, mid).unwrap();
                    r.replace(q, x, p).unwrap();
                    r.replace(p, x, q).unwrap();
                    r.make(x, &[p, q]).unwrap();
                    new.push(x);
                }
            }
        }
        for &x in &new {
            let p = r.any(x, false).unwrap();
            let q = r.nextto(p, x, false).unwrap();
            let list = [
                p,
                r.prevto(x, p, false).unwrap(),
                r.nextto(x, q, false).unwrap(),
                q,
                r.prevto(x, q, false).unwrap(),
                r.nextto(x, p, false).unwrap(),
            ];
            r.make(x, &list).unwrap();
        }
        all.extend(new);
        all
    }

    #[test]
    fn polyhedral_subdivision_runs_on_the_operations() {
        let (mut r, set) = Rotation::from_soup(&octahedron()).unwrap();
        let all = polyhedral(&mut r, &set);
        r.check(&all).unwrap();
        let faces = r.faces(&all).unwrap();
        // Each triangle in four: V = 6 + 12 edges, E = 2 * 12 + 3 * 8,
        // F = 4 * 8.
        assert_eq!((all.len(), edge_count(&r, &all), faces.len()), (18, 48, 32));
        assert!(faces.iter().all(|f| f.len() == 3));
        assert_outward(&r, &faces, DVec3::ZERO);
        // A new vertex has valence 6, an old one keeps its 4.
        for &v in &all {
            assert_eq!(r.valence(v, false), Ok(if v < 6 { 4 } else { 6 }));
        }
        let all = polyhedral(&mut r, &all);
        r.check(&all).unwrap();
        assert_eq!(r.faces(&all).unwrap().len(), 128);
    }

    // ----- steady state ----------------------------------------------------

    /// Every capacity the system holds.
    fn capacities(r: &Rotation) -> Vec<usize> {
        let mut c = vec![
            r.alive.capacity(),
            r.nbs.capacity(),
            r.edges.capacity(),
            r.old_nbs.capacity(),
            r.old_edges.capacity(),
            r.pos.capacity(),
            r.free.capacity(),
        ];
        for lists in [&r.nbs, &r.old_nbs] {
            c.extend(lists.iter().map(Vec::capacity));
        }
        for vals in [&r.edges, &r.old_edges] {
            c.extend(vals.iter().map(Vec::capacity));
        }
        c.extend(
            r.vprops
                .iter()
                .flat_map(|p| [p.cur.capacity(), p.old.capacity()]),
        );
        c
    }

    #[test]
    fn creating_editing_and_freeing_allocates_nothing_once_warm() {
        let (mut r, ring) = vertices(8);
        r.add_vertex_property(3, &[0.0; 3]);
        r.add_edge_property(2, &[0.0; 2]);
        let round = |r: &mut Rotation| {
            for k in 0..40 {
                let made: Vec<u32> = (0..3).map(|_| r.new_vertex()).collect();
                for (j, &c) in made.iter().enumerate() {
                    let n = 3 + (k + j) % 4;
                    r.make(c, &ring[..n]).unwrap();
                    r.splice_after(ring[7], ring[1], c).unwrap();
                    r.erase(ring[0], c).unwrap();
                    r.replace(ring[2], ring[6], c).unwrap();
                    r.set_pos(c, DVec3::splat(k as f64)).unwrap();
                }
                r.synchronize(&made).unwrap();
                for &c in made.iter().rev().skip(k % 2) {
                    r.free(c).unwrap();
                }
                if k % 2 == 1 {
                    r.free(made[2]).unwrap();
                }
            }
        };
        round(&mut r);
        let warm = capacities(&r);
        round(&mut r);
        assert_eq!(capacities(&r), warm);
        assert_eq!(r.len(), 8);
    }

    #[test]
    fn reserved_room_takes_new_vertices_without_moving_arrays() {
        let (mut r, _) = vertices(3);
        r.add_vertex_property(2, &[0.0; 2]);
        r.reserve(100);
        let outer = |r: &Rotation| {
            [
                r.alive.capacity(),
                r.nbs.capacity(),
                r.old_nbs.capacity(),
                r.pos.capacity(),
                r.old_pos.capacity(),
                r.vprops[0].cur.capacity(),
            ]
        };
        let before = outer(&r);
        assert!(before.iter().all(|&c| c >= 103));
        for _ in 0..100 {
            r.new_vertex();
        }
        assert_eq!(outer(&r), before);
    }

    // ----- Edmonds' technique and the check ---------------------------------

    #[test]
    fn a_tetrahedron_made_by_hand_has_four_faces() {
        let (mut r, v) = vertices(4);
        let at = [(1., 1., 1.), (1., -1., -1.), (-1., 1., -1.), (-1., -1., 1.)];
        for (k, &(x, y, z)) in at.iter().enumerate() {
            r.set_pos(v[k], DVec3::new(x, y, z)).unwrap();
        }
        // The outward counter-clockwise faces are (0,1,2), (0,3,1),
        // (0,2,3), (1,3,2) (checked below by their normals). At a corner
        // (a, v, b) of a face, a follows b in v's list: at 0, 2 follows 1
        // (face 012), 1 follows 3 (031), 3 follows 2 (023): [1, 2, 3]. The
        // same for the others.
        r.make(v[0], &[v[1], v[2], v[3]]).unwrap();
        r.make(v[1], &[v[0], v[3], v[2]]).unwrap();
        r.make(v[2], &[v[0], v[1], v[3]]).unwrap();
        r.make(v[3], &[v[1], v[0], v[2]]).unwrap();
        r.check(&v).unwrap();
        let faces = r.faces(&v).unwrap();
        assert_eq!(faces, [[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]]);
        assert_outward(&r, &faces, DVec3::ZERO);
        assert_eq!(r.holes(&v), Ok(vec![]));
        // Euler: V - E + F = 4 - 6 + 4 = 2.
        assert_eq!(edge_count(&r, &v), 6);
    }

    #[test]
    fn a_cube_has_six_quads() {
        let soup = cube();
        let (r, set) = Rotation::from_soup(&soup).unwrap();
        r.check(&set).unwrap();
        let faces = r.faces(&set).unwrap();
        assert_eq!(faces.len(), 6);
        assert!(faces.iter().all(|f| f.len() == 4));
        assert_eq!(canonical_faces(&faces), canonical_faces(&soup.faces));
        assert_outward(&r, &faces, DVec3::splat(0.5));
        assert!(set.iter().all(|&v| r.valence(v, false) == Ok(3)));
        assert!(set.iter().all(|&v| r.is_open(v, false) == Ok(false)));
        // Euler: 8 - 12 + 6 = 2.
        assert_eq!(edge_count(&r, &set), 12);
        assert_eq!(r.holes(&set), Ok(vec![]));
    }

    #[test]
    fn an_octahedron_has_eight_triangles() {
        let soup = octahedron();
        let (r, set) = Rotation::from_soup(&soup).unwrap();
        let faces = r.faces(&set).unwrap();
        assert_eq!(faces.len(), 8);
        assert_eq!(canonical_faces(&faces), canonical_faces(&soup.faces));
        assert_outward(&r, &faces, DVec3::ZERO);
        assert!(set.iter().all(|&v| r.valence(v, false) == Ok(4)));
        // Euler: 6 - 12 + 8 = 2.
        assert_eq!(edge_count(&r, &set), 12);
    }

    #[test]
    fn a_three_by_three_grid_has_nine_quads_and_one_hole() {
        // Vertex (i, j) of the 4 x 4 grid points is 4j + i.
        let soup = quad_grid(3, 3);
        let (r, set) = Rotation::from_soup(&soup).unwrap();
        r.check(&set).unwrap();
        let faces = r.faces(&set).unwrap();
        assert_eq!(faces.len(), 9);
        assert_eq!(canonical_faces(&faces), canonical_faces(&soup.faces));
        // The grid lies in z = 0: counter-clockwise seen from +z.
        for f in &faces {
            assert!(normal(&r, f).z > 0.0);
        }
        // The hole runs round the 12 boundary vertices the other way:
        // up the side x = 0, along y = 1, down x = 1, back along y = 0.
        assert_eq!(
            r.holes(&set),
            Ok(vec![vec![0, 4, 8, 12, 13, 14, 15, 11, 7, 3, 2, 1]])
        );
        // The inner points 5, 6, 9, 10 are closed, the others open; a
        // corner has valence 2.
        for &v in &set {
            let (i, j) = (v % 4, v / 4);
            let inner = (1..3).contains(&i) && (1..3).contains(&j);
            assert_eq!(r.is_open(v, false), Ok(!inner));
        }
        assert_eq!(r.neighbours(0, false), Ok(&[1, 4][..]));
        assert_eq!(r.nextto(4, 0, false), Ok(NULL));
        // Euler of a disc: 16 - 24 + 9 = 1.
        assert_eq!(edge_count(&r, &set), 24);
    }

    #[test]
    fn faces_come_in_a_fixed_order_from_their_smallest_vertex() {
        let (r, set) = Rotation::from_soup(&cube()).unwrap();
        let faces = r.faces(&set).unwrap();
        for f in &faces {
            assert_eq!(f[0], *f.iter().min().unwrap());
        }
        let keys: Vec<_> = faces.iter().map(|f| (f[0], f[1])).collect();
        let mut sorted = keys.clone();
        sorted.sort();
        assert_eq!(keys, sorted);
        // The same set in another order gives the same faces.
        let mut rev = set.clone();
        rev.reverse();
        assert_eq!(r.faces(&rev), Ok(faces));
    }

    #[test]
    fn to_soup_and_back_keeps_the_faces() {
        for soup in [cube(), quad_grid(3, 2), icosphere(1)] {
            let (r, set) = Rotation::from_soup(&soup).unwrap();
            // Number the soup in another order, so that the ids change.
            let mut order = set.clone();
            order.reverse();
            order.rotate_left(3);
            let out = r.to_soup(&order).unwrap();
            assert_eq!(out.positions[0], r.pos(order[0], false).unwrap());
            let (back, set2) = Rotation::from_soup(&out).unwrap();
            let renumbered: Vec<Vec<u32>> = back
                .faces(&set2)
                .unwrap()
                .iter()
                .map(|f| f.iter().map(|&k| order[k as usize]).collect())
                .collect();
            assert_eq!(
                canonical_faces(&renumbered),
                canonical_faces(r.faces(&set).unwrap())
            );
            assert_eq!(
                back.holes(&set2).unwrap().len(),
                r.holes(&set).unwrap().len()
            );
        }
    }

    #[test]
    fn an_icosphere_satisfies_euler() {
        // icosphere(2): 20 * 16 = 320 triangles, 162 vertices.
        let (r, set) = Rotation::from_soup(&icosphere(2)).unwrap();
        let f = r.faces(&set).unwrap().len();
        let e = edge_count(&r, &set);
        assert_eq!((set.len(), e, f), (162, 480, 320));
        assert_eq!(set.len() as i64 - e as i64 + f as i64, 2);
    }

    #[test]
    fn from_soup_refuses_bow_ties_and_flipped_faces() {
        let soup = |faces: Vec<Vec<u32>>| PolygonSoup {
            positions: vec![DVec3::ZERO; 6],
            faces: faces.into(),
            ..Default::default()
        };
        // Two triangles that meet only at vertex 0.
        assert_eq!(
            Rotation::from_soup(&soup(vec![vec![0, 1, 2], vec![0, 3, 4]])).err(),
            Some(
                "vertex 1 is a bow-tie: its faces form more than one fan, so the mesh is not \
                 a 2-manifold there"
                    .into()
            )
        );
        // Two fans that close round vertex 0 (two cones sharing their tip).
        let cones = vec![vec![0, 1, 2], vec![0, 2, 1], vec![0, 3, 4], vec![0, 4, 3]];
        let err = Rotation::from_soup(&soup(cones)).err().unwrap();
        assert!(err.starts_with("vertex 1 is a bow-tie"), "{err}");
        // The second triangle turned over: both run 2 -> 0.
        let mut flipped = soup(vec![vec![0, 1, 2], vec![0, 3, 2]]);
        flipped.face_lines = vec![4, 5];
        assert_eq!(
            Rotation::from_soup(&flipped).err(),
            Some(
                "face 1 (line 4) and face 2 (line 5) both run from vertex 3 to vertex 1: \
                 their orientations disagree, or more than two faces meet at that edge"
                    .into()
            )
        );
        assert_eq!(
            Rotation::from_soup(&soup(vec![vec![0, 1]])).err(),
            Some("face 1 has 2 vertices; a face needs at least 3".into())
        );
        assert_eq!(
            Rotation::from_soup(&soup(vec![vec![0, 1, 0, 2]])).err(),
            Some("face 1 uses vertex 1 twice".into())
        );
        assert_eq!(
            Rotation::from_soup(&soup(vec![vec![0, 1, 9]])).err(),
            Some("face 1 refers to vertex 10, but there are only 6 vertices".into())
        );
        // An isolated vertex is allowed: no neighbours.
        let (r, set) = Rotation::from_soup(&soup(vec![vec![0, 1, 2]])).unwrap();
        assert_eq!(r.valence(5, false), Ok(0));
        assert_eq!(r.faces(&set).unwrap(), [[0, 1, 2]]);
        assert_eq!(r.holes(&set).unwrap(), [[0, 2, 1]]);
    }

    #[test]
    fn check_names_the_first_asymmetry() {
        let (mut r, v) = vertices(8);
        r.make(v[3], &[v[7]]).unwrap();
        assert_eq!(
            r.check(&v),
            Err("vertex 3 lists 7 as a neighbour but 7 does not list 3".into())
        );
        assert_eq!(
            r.check(&v[..4]),
            Err("vertex 3 lists vertex 7, which is not in the set".into())
        );
        r.free(v[7]).unwrap();
        assert_eq!(
            r.check(&v[..7]),
            Err("vertex 3 lists vertex 7, which no longer exists".into())
        );
        assert_eq!(
            r.check(&v),
            Err("`check`: the set holds vertex 7, which no longer exists".into())
        );
        assert_eq!(
            r.check(&[v[0], v[0]]),
            Err("`check`: the set holds vertex 0 twice".into())
        );
        assert_eq!(
            r.check(&[NULL]),
            Err("`check`: the set holds the null vertex".into())
        );
    }

    #[test]
    fn check_refuses_what_is_not_a_two_manifold() {
        // An edge alone, closed at both ends: a "face" of 2 vertices.
        let (mut r, v) = vertices(2);
        r.make(v[0], &[v[1]]).unwrap();
        r.make(v[1], &[v[0]]).unwrap();
        assert_eq!(
            r.check(&v),
            Err("the face through edge (0, 1) has only 2 vertices: a face needs at least 3".into())
        );
        // The same edge open at both ends: boundary on both sides.
        r.make(v[0], &[v[1], NULL]).unwrap();
        r.make(v[1], &[v[0], NULL]).unwrap();
        assert_eq!(
            r.check(&v),
            Err("edge (0, 1) borders no face: both its sides are boundary".into())
        );
        // A triangle with one corner open and two closed: faces and gaps
        // on one orbit.
        let (mut r, v) = vertices(3);
        r.make(v[0], &[v[1], v[2], NULL]).unwrap();
        r.make(v[1], &[v[2], v[0]]).unwrap();
        r.make(v[2], &[v[0], v[1]]).unwrap();
        assert_eq!(
            r.check(&v),
            Err(
                "the faces and the boundary disagree on the loop through edge (0, 2): vertex \
                 0's neighbourhood is open there but vertex 2's is not"
                    .into()
            )
        );
        // Closed, it is a pillow of two triangles: V - E + F = 3 - 3 + 2.
        r.make(v[0], &[v[1], v[2]]).unwrap();
        r.check(&v).unwrap();
        assert_eq!(r.faces(&v), Ok(vec![vec![0, 1, 2], vec![0, 2, 1]]));
        // A dangling vertex 3 hung on 0: the face round it meets 0 twice.
        let w = r.new_vertex();
        r.splice_after(w, v[1], v[0]).unwrap();
        r.make(w, &[v[0]]).unwrap();
        let mut all = v.clone();
        all.push(w);
        assert_eq!(
            r.check(&all),
            Err("the face through edge (0, 1) passes vertex 0 twice".into())
        );
        assert!(r.faces(&all).is_err());
    }

    #[test]
    fn check_refuses_loops_and_repeats_that_bypass_the_editing_operations() {
        let (mut r, v) = vertices(3);
        r.nbs[0] = vec![v[0]];
        assert_eq!(
            r.check(&v),
            Err("vertex 0 lists itself as a neighbour".into())
        );
        r.nbs[0] = vec![v[1], v[1]];
        r.nbs[1] = vec![v[0]];
        assert_eq!(r.check(&v), Err("vertex 0 lists vertex 1 twice".into()));
    }
}
