//! The half-edge mesh: typed ids, flat arrays of indices, and per-element
//! attributes (a refinement level on every vertex and edge, and on every
//! face through its corners, the step that made each vertex, block and
//! transversal marks). The state of a
//! grammar's run (its step, its current level, the positions written for
//! the next step) lives with the run, in `surface::run`.
//!
//! Half-edges come in pairs: `h` and `h ^ 1` are twins, and edge `e` is the
//! pair `2e`, `2e + 1`. A boundary half-edge has no face. Every vertex keeps
//! one outgoing half-edge; a boundary vertex keeps its outgoing boundary
//! half-edge, so that walks around it start at the boundary.

use std::collections::BTreeMap;
use std::fmt;

use glam::DVec3;

/// `he_face` of a boundary half-edge.
pub(crate) const NO_FACE: u32 = u32::MAX;

/// `v_out` of a vertex without edges.
pub(crate) const NO_HALFEDGE: u32 = u32::MAX;

pub(crate) use super::packed::{Bits, Narrow};

macro_rules! id {
    ($(#[$m:meta])* $name:ident) => {
        $(#[$m])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
        pub struct $name(pub u32);

        impl $name {
            #[inline]
            pub fn index(self) -> usize {
                self.0 as usize
            }
        }

        /// Counted from 1, as mesh files count: vertex 1 is the first `v`
        /// line of an OBJ file.
        impl std::fmt::Display for $name {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                write!(f, "{}", self.0 as u64 + 1)
            }
        }
    };
}

id!(
    /// A vertex.
    VertexId
);
id!(
    /// A half-edge; its twin is `HalfEdgeId(h ^ 1)`.
    HalfEdgeId
);
id!(
    /// An edge: the half-edges `2e` and `2e + 1`.
    EdgeId
);
id!(
    /// A face (a triangle).
    FaceId
);

impl HalfEdgeId {
    #[inline]
    pub fn twin(self) -> HalfEdgeId {
        HalfEdgeId(self.0 ^ 1)
    }

    #[inline]
    pub fn edge(self) -> EdgeId {
        EdgeId(self.0 >> 1)
    }
}

impl EdgeId {
    /// The edge's first half-edge.
    #[inline]
    pub fn halfedge(self) -> HalfEdgeId {
        HalfEdgeId(self.0 << 1)
    }
}

/// Why an operation was refused or a mesh is invalid. The mesh is left as
/// it was.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshError {
    pub message: String,
    /// The line of the mesh file that holds the face or vertex at fault,
    /// where [`Mesh::from_soup`] knows it.
    pub line: Option<usize>,
}

impl MeshError {
    pub fn new(m: impl Into<String>) -> MeshError {
        MeshError {
            message: m.into(),
            line: None,
        }
    }

    /// The error, about the element on `line` of the mesh file.
    pub fn at(self, line: Option<usize>) -> MeshError {
        MeshError { line, ..self }
    }
}

impl fmt::Display for MeshError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for MeshError {}

/// A triangle mesh with levels. Storage is structure-of-arrays; removed
/// elements are marked dead and their slots reused.
///
/// A mesh holds geometry, topology and per-element attributes only, so two
/// equal meshes behave alike under any grammar; a run's state is not part
/// of it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    // Vertices.
    /// One outgoing half-edge of each vertex, [`NO_HALFEDGE`] for none.
    pub(crate) v_out: Vec<u32>,
    pub(crate) pos: Vec<DVec3>,
    pub(crate) v_level: Narrow,
    /// The step of the grammar run that made the vertex (0: the base mesh
    /// and `init:` rules).
    pub(crate) v_step: Narrow,
    pub(crate) v_alive: Bits,
    /// The sharpness of each vertex, as OpenSubdiv has it: 0 smooth, a
    /// positive number a corner for that many more levels, infinite a
    /// corner for ever. New vertices get 0.
    pub(crate) v_sharp: Column<f64>,
    // Half-edges, in twin pairs.
    pub(crate) he_to: Vec<VertexId>,
    /// The next half-edge of each one's face, or of its boundary loop.
    /// The previous one is not stored: all faces are triangles, so it is
    /// the next one's next, and a boundary half-edge's is found by turning
    /// around its tail ([`Mesh::prev`]).
    pub(crate) he_next: Vec<HalfEdgeId>,
    /// The face of each half-edge, `NO_FACE` on the boundary.
    pub(crate) he_face: Vec<u32>,
    // Edges.
    pub(crate) e_level: Narrow,
    pub(crate) e_alive: Bits,
    /// The internal edge of a basic block of a tri-quad mesh.
    pub(crate) e_block: Bits,
    /// Made by an edge split, joining the new vertex to a vertex opposite
    /// the split edge, and not flipped since.
    pub(crate) e_transversal: Bits,
    /// The sharpness of each edge (OpenSubdiv's): 0 smooth, a positive
    /// number a crease for that many more levels (semi-sharp below 1),
    /// infinite a crease for ever. The halves of a split edge inherit it;
    /// edges that splits draw are 0, and a flip refuses a sharp edge.
    pub(crate) e_sharp: Column<f64>,
    /// False while no edge or vertex has been given a positive sharpness
    /// (or since the last `decrement_sharpness` left none): the crease
    /// queries answer at once on the meshes that have no creases.
    pub(crate) creased: bool,
    // Faces.
    pub(crate) f_he: Vec<HalfEdgeId>,
    /// A face's level is one more than its highest corner's (paper 000,
    /// §6), so it is not stored, except here: the faces around a vertex
    /// whose level [`Mesh::set_vertex_level`] changed keep the level they
    /// had until an operator remakes them, and those levels, where they
    /// differ from the derived one, are kept by face slot.
    pub(crate) f_level_kept: BTreeMap<u32, u32>,
    pub(crate) f_alive: Bits,
    /// A number the caller gives each face of the soup
    /// ([`Mesh::from_soup_tagged`]; 0 otherwise), handed down by the
    /// stellar operators to the faces cut from it: which part of a welded
    /// group of shapes a face belongs to.
    pub(crate) f_tag: Column<u32>,
    // Free slots.
    pub(crate) free_v: Vec<u32>,
    pub(crate) free_e: Vec<u32>,
    pub(crate) free_f: Vec<u32>,
    /// The first polygon of more than four sides in the soup the mesh was
    /// built from, which was fanned into triangles: where the mesh came
    /// from, so that schemes that read quads can refuse those triangles.
    pub(crate) fanned: Option<FannedPolygon>,
    /// Every polygon of five or more sides of the soup, as its fan of
    /// triangles, until a polygon split ([`Mesh::polygon_split_with`])
    /// joins its corners to a centre; `fan_of` maps each of its
    /// triangles' slots to its index here.
    pub(crate) fans: Vec<Fan>,
    pub(crate) fan_of: std::collections::BTreeMap<u32, u32>,
    /// Each vertex's origin key, while [`Mesh::track_origins`] is on
    /// (empty otherwise): a base vertex's is given, a split's new vertex's
    /// is made from the keys of the corners of what was split (see
    /// [`origin_key`]). Two runs of one grammar on meshes of the same
    /// faces (a mesh and its UV layout, cut open at seams) give the
    /// vertices they make for the same element the same key.
    pub(crate) v_key: Vec<u64>,
}

/// The origin key of a vertex made by splitting an element whose corners
/// have the keys `parents` (two for an edge, three for a face), whatever
/// their order.
pub fn origin_key(parents: &[u64]) -> u64 {
    let mut sorted = [0u64; 3];
    let n = parents.len().min(3);
    sorted[..n].copy_from_slice(&parents[..n]);
    sorted[..n].sort_unstable();
    let mut h = 0x243F_6A88_85A3_08D3 ^ n as u64;
    for &k in &sorted[..n] {
        h = mix64(h ^ k);
    }
    h
}

/// SplitMix64's finaliser: every bit of the result depends on every bit
/// of `x`.
pub fn mix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// How semi-sharp creases soften from one level to the next: OpenSubdiv's
/// creasing methods (`Sdc::Options::CreasingMethod`). A surface grammar
/// chooses one with `creasing: chaikin;` (uniform without it).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Creasing {
    /// Every sharpness drops by one a level (`CREASE_UNIFORM`).
    #[default]
    Uniform,
    /// An edge's sharpness at each end follows Chaikin's rule over the
    /// semi-sharp edges there (`CREASE_CHAIKIN`): see [`child_sharpness`].
    Chaikin,
}

/// The sharpness one level down of the half, at vertex `v`, of an edge of
/// sharpness `s`, given the sharpness of every edge at `v` (`s`'s edge
/// among them), as OpenSubdiv defines its creasing methods: smooth stays
/// smooth and infinite infinite; [`Creasing::Uniform`] gives `s - 1`;
/// [`Creasing::Chaikin`], where two or more of the edges at `v` are
/// semi-sharp (above 0, finite), gives `3/4 s + 1/4 a - 1`, `a` the mean of
/// the other semi-sharp edges' sharpness, and `s - 1` where `s`'s edge is
/// the only one. Never below 0.
pub fn child_sharpness(method: Creasing, s: f64, at_v: impl Iterator<Item = f64>) -> f64 {
    if s <= 0.0 {
        return 0.0;
    }
    if s.is_infinite() {
        return s;
    }
    let (mut sum, mut count, mut edges) = (0.0, 0usize, 0usize);
    for x in at_v {
        edges += 1;
        if x > 0.0 && x.is_finite() {
            sum += x;
            count += 1;
        }
    }
    let s = if method == Creasing::Chaikin && edges >= 2 && count > 1 {
        0.75 * s + 0.25 * ((sum - s) / (count - 1) as f64)
    } else {
        s
    };
    (s - 1.0).max(0.0)
}

/// A polygon of five or more sides of the soup the mesh was built from,
/// fanned into triangles from its first corner: its corners in order and
/// the triangles `(c0, c(i+1), c(i+2))` of its fan, first to last.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Fan {
    pub(crate) corners: Vec<VertexId>,
    pub(crate) faces: Vec<FaceId>,
}

/// A polygon of more than four sides that [`Mesh::from_soup`] fanned into
/// triangles.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FannedPolygon {
    /// Its index among the soup's faces, from 0.
    pub face: usize,
    /// Its number of sides.
    pub sides: usize,
    /// The 1-based line of the file it was read from, when known.
    pub line: Option<usize>,
}

impl Mesh {
    // ----- counts and iteration -------------------------------------

    pub fn vertex_count(&self) -> usize {
        self.v_alive.len() - self.free_v.len()
    }

    pub fn edge_count(&self) -> usize {
        self.e_alive.len() - self.free_e.len()
    }

    pub fn face_count(&self) -> usize {
        self.f_alive.len() - self.free_f.len()
    }

    pub fn vertices(&self) -> impl Iterator<Item = VertexId> + '_ {
        (0..self.v_alive.len() as u32)
            .map(VertexId)
            .filter(|v| self.v_alive.get(v.index()))
    }

    pub fn edges(&self) -> impl Iterator<Item = EdgeId> + '_ {
        (0..self.e_alive.len() as u32)
            .map(EdgeId)
            .filter(|e| self.e_alive.get(e.index()))
    }

    pub fn faces(&self) -> impl Iterator<Item = FaceId> + '_ {
        (0..self.f_alive.len() as u32)
            .map(FaceId)
            .filter(|f| self.f_alive.get(f.index()))
    }

    pub fn is_vertex(&self, v: VertexId) -> bool {
        self.v_alive.get_or_false(v.index())
    }

    pub fn is_edge(&self, e: EdgeId) -> bool {
        self.e_alive.get_or_false(e.index())
    }

    pub fn is_face(&self, f: FaceId) -> bool {
        self.f_alive.get_or_false(f.index())
    }

    /// Bytes of storage per face, for the benchmark's report: the arrays'
    /// lengths times their elements' sizes (sharpness and tags count only
    /// where stored).
    pub fn bytes_per_face(&self) -> f64 {
        self.bytes() as f64 / self.face_count().max(1) as f64
    }

    /// Bytes of the mesh's arrays (their lengths, not their capacities).
    pub fn bytes(&self) -> usize {
        fn size<T>(v: &[T]) -> usize {
            std::mem::size_of_val(v)
        }
        let v = size(&self.v_out)
            + size(&self.pos)
            + self.v_level.bytes()
            + self.v_step.bytes()
            + self.v_alive.bytes()
            + self.v_sharp.stored_bytes();
        let h = size(&self.he_to) + size(&self.he_next) + size(&self.he_face);
        let e = self.e_level.bytes()
            + self.e_alive.bytes()
            + self.e_block.bytes()
            + self.e_transversal.bytes()
            + self.e_sharp.stored_bytes();
        let f = size(&self.f_he)
            + self.f_level_kept.len() * 2 * std::mem::size_of::<u32>()
            + self.f_alive.bytes()
            + self.f_tag.stored_bytes();
        v + h + e + f
    }

    // ----- element data ----------------------------------------------

    #[inline]
    pub fn position(&self, v: VertexId) -> DVec3 {
        self.pos[v.index()]
    }

    pub fn set_position(&mut self, v: VertexId, p: DVec3) {
        self.pos[v.index()] = p;
    }

    pub fn vertex_level(&self, v: VertexId) -> u32 {
        self.v_level.get(v.index())
    }

    pub fn edge_level(&self, e: EdgeId) -> u32 {
        self.e_level.get(e.index())
    }

    /// One more than the level of the face's highest corner, unless
    /// [`Mesh::set_vertex_level`] changed a corner's level since an
    /// operator last made the face: then the level it had.
    pub fn face_level(&self, f: FaceId) -> u32 {
        if let Some(&l) = self.f_level_kept.get(&f.0) {
            return l;
        }
        self.face_level_from_vertices(self.face_vertices(f))
    }

    /// The face's tag: that of the soup face it was cut from
    /// ([`Mesh::from_soup_tagged`]), 0 for an untagged mesh.
    pub fn tag(&self, f: FaceId) -> u32 {
        self.f_tag.get(f.index())
    }

    /// Sets a vertex's level. The faces around it keep their levels (and
    /// edges theirs): the next operator that remakes a face gives it one
    /// more than its highest corner's.
    pub fn set_vertex_level(&mut self, v: VertexId, l: u32) {
        let faces: Vec<(FaceId, u32)> = self
            .vertex_faces(v)
            .map(|f| (f, self.face_level(f)))
            .collect();
        self.v_level.set(v.index(), l);
        for (f, old) in faces {
            if self.face_level_from_vertices(self.face_vertices(f)) == old {
                self.f_level_kept.remove(&f.0);
            } else {
                self.f_level_kept.insert(f.0, old);
            }
        }
    }

    pub fn set_edge_level(&mut self, e: EdgeId, l: u32) {
        self.e_level.set(e.index(), l);
    }

    /// True for the internal edge of a basic block (tri-quad meshes).
    pub fn is_block_edge(&self, e: EdgeId) -> bool {
        self.e_block.get(e.index())
    }

    /// The edge's sharpness: 0 smooth, positive creased (see
    /// [`Mesh::decrement_sharpness`]), `f64::INFINITY` sharp for ever.
    pub fn edge_sharpness(&self, e: EdgeId) -> f64 {
        self.e_sharp.get(e.index())
    }

    /// The vertex's sharpness: 0 smooth, positive a corner.
    pub fn vertex_sharpness(&self, v: VertexId) -> f64 {
        self.v_sharp.get(v.index())
    }

    /// True for an edge of positive sharpness.
    #[inline]
    pub fn is_sharp_edge(&self, e: EdgeId) -> bool {
        self.e_sharp.get(e.index()) > 0.0
    }

    /// Sets an edge's sharpness; refused for a negative or NaN value. (A
    /// boundary edge may carry one too; boundary rules keep a boundary a
    /// curve whatever it is.)
    pub fn set_edge_sharpness(&mut self, e: EdgeId, s: f64) -> Result<(), MeshError> {
        if !self.is_edge(e) {
            return Err(MeshError::new(format!("edge {e} does not exist")));
        }
        if s.is_nan() || s < 0.0 {
            return Err(MeshError::new(format!(
                "a sharpness is 0 or more (or `inf`), not {s}"
            )));
        }
        self.e_sharp.set(e.index(), s);
        self.creased |= s > 0.0;
        Ok(())
    }

    /// Sets a vertex's sharpness; refused for a negative or NaN value.
    pub fn set_vertex_sharpness(&mut self, v: VertexId, s: f64) -> Result<(), MeshError> {
        if !self.is_vertex(v) {
            return Err(MeshError::new(format!("vertex {v} does not exist")));
        }
        if s.is_nan() || s < 0.0 {
            return Err(MeshError::new(format!(
                "a sharpness is 0 or more (or `inf`), not {s}"
            )));
        }
        self.v_sharp.set(v.index(), s);
        self.creased |= s > 0.0;
        Ok(())
    }

    /// True when some edge or vertex has positive sharpness.
    pub fn has_sharpness(&self) -> bool {
        self.creased && self.edges().any(|e| self.is_sharp_edge(e))
            || self.vertices().any(|v| self.v_sharp.get(v.index()) > 0.0)
    }

    /// False when no edge or vertex can be sharp (nothing was given a
    /// sharpness, or every one has dropped to 0); true says only that some
    /// may be.
    #[inline]
    pub fn has_sharpness_flag(&self) -> bool {
        self.creased
    }

    /// The number of sharp edges at `v` that are not on the boundary (a
    /// boundary is a crease of its own: the grammars' boundary rules keep
    /// it a curve).
    pub fn sharp_edge_count(&self, v: VertexId) -> usize {
        if !self.creased || self.e_sharp.all_default() {
            return 0;
        }
        self.outgoing_halfedges(v)
            .filter(|h| self.is_sharp_edge(h.edge()) && !self.is_boundary_edge(h.edge()))
            .count()
    }

    /// One level of `method`: a vertex's sharpness drops by one (both
    /// methods); an edge's by one ([`Creasing::Uniform`]), or
    /// ([`Creasing::Chaikin`]) by [`child_sharpness`] at its end that
    /// `old` says was there before the step, from the sharpness of the
    /// edges at that end as the step left them (a split edge's halves
    /// keep their parent's, so these are the parent level's values). An
    /// edge with both ends old or neither takes the uniform rule.
    pub fn soften_sharpness(&mut self, method: Creasing, old: impl Fn(VertexId) -> bool) {
        if method == Creasing::Uniform || !self.creased {
            self.decrement_sharpness();
            return;
        }
        let mut next: Vec<(EdgeId, f64)> = Vec::new();
        for e in self.edges() {
            let s = self.edge_sharpness(e);
            if s <= 0.0 || s.is_infinite() {
                continue;
            }
            let (a, b) = self.edge_vertices(e);
            let at = match (old(a), old(b)) {
                (true, false) => Some(a),
                (false, true) => Some(b),
                _ => None,
            };
            let child = match at {
                Some(v) => child_sharpness(
                    Creasing::Chaikin,
                    s,
                    self.outgoing_halfedges(v)
                        .map(|h| self.edge_sharpness(h.edge())),
                ),
                None => (s - 1.0).max(0.0),
            };
            next.push((e, child));
        }
        for (e, s) in next {
            self.e_sharp.set(e.index(), s);
        }
        let v = self.v_sharp.stored_mut();
        for s in v.iter_mut() {
            if *s > 0.0 {
                *s = (*s - 1.0).max(0.0);
            }
        }
        self.creased = self.has_sharpness();
    }

    /// One level of OpenSubdiv's uniform rule: every positive sharpness,
    /// of an edge or a vertex, drops by one, to 0 at the least; infinite
    /// stays infinite. A surface grammar's run calls it at the end of
    /// every step.
    pub fn decrement_sharpness(&mut self) {
        if !self.creased {
            return;
        }
        let (e, v) = (self.e_sharp.stored_mut(), self.v_sharp.stored_mut());
        for s in e.iter_mut().chain(v.iter_mut()) {
            if *s > 0.0 {
                *s = (*s - 1.0).max(0.0);
            }
        }
        self.creased = self.has_sharpness();
    }

    /// Makes every vertex, and every edge that is neither a basic block's
    /// internal edge nor a diagonal of a fanned polygon, sharp for ever:
    /// a crease-aware grammar's rules then interpolate linearly (corners
    /// stay, edges split at their midpoints, faces at their centroids).
    pub fn sharpen_everything(&mut self) {
        let vertices: Vec<VertexId> = self.vertices().collect();
        for v in vertices {
            self.v_sharp.set(v.index(), f64::INFINITY);
        }
        let edges: Vec<EdgeId> = self.edges().collect();
        for e in edges {
            let inside_fan = match self.edge_faces(e) {
                [Some(f), Some(g)] => {
                    let k = self.fan_of.get(&f.0);
                    k.is_some() && k == self.fan_of.get(&g.0)
                }
                _ => false,
            };
            if !self.is_block_edge(e) && !inside_fan {
                self.e_sharp.set(e.index(), f64::INFINITY);
            }
        }
        self.creased = true;
    }

    /// The step of a grammar run that made the vertex (0: the base mesh).
    pub fn vertex_step(&self, v: VertexId) -> u32 {
        self.v_step.get(v.index())
    }

    /// The first polygon of more than four sides in the soup the mesh was
    /// built from, which [`Mesh::from_soup`] fanned into triangles.
    pub fn fanned_polygon(&self) -> Option<FannedPolygon> {
        self.fanned
    }

    /// Makes every vertex one of the base mesh (step 0) for a new run.
    pub(crate) fn reset_vertex_steps(&mut self) {
        self.v_step.fill(0);
    }

    /// True for the centre of a dual basic block: a vertex all of whose
    /// edges are internal edges of blocks (paper 000, §6, Fig. 12b).
    pub fn is_block_centre(&self, v: VertexId) -> bool {
        let mut any = false;
        for h in self.outgoing_halfedges(v) {
            if !self.e_block.get(h.edge().index()) {
                return false;
            }
            any = true;
        }
        any
    }

    /// True for an edge that an edge split drew from the new vertex to a
    /// vertex opposite the split edge, and that no flip has touched since.
    pub fn is_transversal_edge(&self, e: EdgeId) -> bool {
        self.e_transversal.get(e.index())
    }

    // ----- half-edge navigation ------------------------------------

    #[inline]
    pub fn to(&self, h: HalfEdgeId) -> VertexId {
        self.he_to[h.index()]
    }

    #[inline]
    pub fn from(&self, h: HalfEdgeId) -> VertexId {
        self.he_to[h.twin().index()]
    }

    #[inline]
    pub fn next(&self, h: HalfEdgeId) -> HalfEdgeId {
        self.he_next[h.index()]
    }

    /// The half-edge before `h` in its face, or in its boundary loop. A
    /// face's is its next one's next (all faces are triangles); a boundary
    /// half-edge's is the boundary half-edge into its tail, found by
    /// turning around the tail through its faces.
    #[inline]
    pub fn prev(&self, h: HalfEdgeId) -> HalfEdgeId {
        if self.he_face[h.index()] != NO_FACE {
            self.next(self.next(h))
        } else {
            self.after_gap(h).twin()
        }
    }

    /// For a boundary half-edge `b` leaving `v`: the first half-edge
    /// leaving `v` counter-clockwise after the boundary gap, the one whose
    /// twin is the boundary half-edge into `v`. Found by turning clockwise
    /// from `b` (`next(twin(g))` is the half-edge leaving `v` before `g`)
    /// until the face side ends; a manifold vertex has one gap.
    /// On a broken mesh (`validate`'s input) the turn stops after as many
    /// steps as there are half-edges.
    fn after_gap(&self, b: HalfEdgeId) -> HalfEdgeId {
        let mut g = self.next(b.twin());
        let mut steps = self.he_to.len();
        while self.he_face[g.twin().index()] != NO_FACE && steps > 0 {
            g = self.next(g.twin());
            steps -= 1;
        }
        g
    }

    #[inline]
    pub fn face(&self, h: HalfEdgeId) -> Option<FaceId> {
        let f = self.he_face[h.index()];
        (f != NO_FACE).then_some(FaceId(f))
    }

    pub fn face_halfedge(&self, f: FaceId) -> HalfEdgeId {
        self.f_he[f.index()]
    }

    /// An outgoing half-edge of `v` (the boundary one for boundary vertices).
    pub fn outgoing(&self, v: VertexId) -> Option<HalfEdgeId> {
        let h = self.v_out[v.index()];
        (h != NO_HALFEDGE).then_some(HalfEdgeId(h))
    }

    /// Sets `v`'s outgoing half-edge.
    #[inline]
    pub(crate) fn set_outgoing(&mut self, v: VertexId, h: Option<HalfEdgeId>) {
        self.v_out[v.index()] = h.map_or(NO_HALFEDGE, |h| h.0);
    }

    pub fn is_boundary_halfedge(&self, h: HalfEdgeId) -> bool {
        self.he_face[h.index()] == NO_FACE
    }

    pub fn is_boundary_edge(&self, e: EdgeId) -> bool {
        let h = e.halfedge();
        self.is_boundary_halfedge(h) || self.is_boundary_halfedge(h.twin())
    }

    pub fn is_boundary_vertex(&self, v: VertexId) -> bool {
        self.outgoing(v)
            .is_some_and(|h| self.is_boundary_halfedge(h))
    }

    /// The next (`forward`) or previous vertex along the boundary through
    /// `v`, in the direction of the faces' half-edges: the boundary edge
    /// `v -> bnext(v)` and `bprev(v) -> v` run along a face. None off the
    /// boundary.
    pub fn boundary_neighbour(&self, v: VertexId, forward: bool) -> Option<VertexId> {
        let out = self.outgoing(v).filter(|&h| self.is_boundary_halfedge(h))?;
        // `out` runs v -> w with no face, so its twin w -> v runs along a
        // face: w is the previous vertex. The boundary half-edge before
        // `out` in the loop runs u -> v; its twin v -> u is along a face.
        Some(if forward {
            self.from(self.prev(out))
        } else {
            self.to(out)
        })
    }

    /// The two end vertices of an edge.
    pub fn edge_vertices(&self, e: EdgeId) -> (VertexId, VertexId) {
        let h = e.halfedge();
        (self.from(h), self.to(h))
    }

    /// The half-edge from `a` to `b`, if they are joined.
    pub fn find_halfedge(&self, a: VertexId, b: VertexId) -> Option<HalfEdgeId> {
        self.outgoing_any_order(a).find(|&h| self.to(h) == b)
    }

    /// The face `vs` (its corners counter-clockwise, from any of them),
    /// if there is one. The three vertices are walked around in turn, so
    /// the cost is three times the smallest of their valences: a triangle
    /// at a vertex of huge valence is found from its other corners.
    pub fn find_face(&self, vs: [VertexId; 3]) -> Option<FaceId> {
        let mut walks = vs.map(|v| self.outgoing_any_order(v));
        loop {
            for (k, walk) in walks.iter_mut().enumerate() {
                // A face at `vs` is met around each of its corners, so a
                // walk that ends without it means there is none.
                let h = walk.next()?;
                if self.to(h) == vs[(k + 1) % 3] && self.to(self.next(h)) == vs[(k + 2) % 3] {
                    if let Some(f) = self.face(h) {
                        return Some(f);
                    }
                }
            }
        }
    }

    /// The vertex of highest valence and its valence (`None` without
    /// edges), in one pass over the edges.
    pub fn max_valence(&self) -> Option<(VertexId, usize)> {
        let mut count = vec![0u32; self.v_alive.len()];
        for e in self.edges() {
            let h = e.halfedge();
            count[self.to(h).index()] += 1;
            count[self.to(h.twin()).index()] += 1;
        }
        let (v, &n) = count.iter().enumerate().rev().max_by_key(|&(_, n)| *n)?;
        (n > 0).then_some((VertexId(v as u32), n as usize))
    }

    // ----- walkers ----------------------------------------------------

    /// The half-edges leaving `v`, in counter-clockwise order. For a
    /// boundary vertex the walk crosses faces only: it starts at the edge
    /// after the boundary gap and ends with the outgoing boundary half-edge.
    pub fn outgoing_halfedges(&self, v: VertexId) -> OutgoingIter<'_> {
        let out = self
            .v_out
            .get(v.index())
            .filter(|&&h| h != NO_HALFEDGE)
            .map(|&h| HalfEdgeId(h));
        let (start, last) = match out {
            Some(h) if self.is_boundary_halfedge(h) => (Some(self.after_gap(h)), Some(h)),
            _ => (out, None),
        };
        OutgoingIter {
            mesh: self,
            start,
            last,
            cur: start,
        }
    }

    /// The half-edges leaving `v`, clockwise from its outgoing one: all of
    /// them, as [`Mesh::outgoing_halfedges`] gives them, in another order,
    /// with no walk to a boundary vertex's gap first (which the
    /// counter-clockwise order needs), for searches that stop at what
    /// they look for. From a half-edge `h` leaving `v`, the next one
    /// clockwise is `next(twin(h))`; a boundary vertex's walk starts at
    /// its outgoing boundary half-edge and ends at the one whose twin is
    /// on the boundary.
    pub(crate) fn outgoing_any_order(&self, v: VertexId) -> impl Iterator<Item = HalfEdgeId> + '_ {
        let start = self
            .v_out
            .get(v.index())
            .filter(|&&h| h != NO_HALFEDGE)
            .map(|&h| HalfEdgeId(h));
        let mut cur = start;
        std::iter::from_fn(move || {
            let h = cur?;
            let t = h.twin();
            cur = if self.is_boundary_halfedge(t) {
                None
            } else {
                Some(self.next(t)).filter(|&n| Some(n) != start)
            };
            Some(h)
        })
    }

    /// The one-ring of `v`: its neighbours in counter-clockwise order.
    pub fn one_ring(&self, v: VertexId) -> impl Iterator<Item = VertexId> + '_ {
        self.outgoing_halfedges(v).map(move |h| self.to(h))
    }

    pub fn valence(&self, v: VertexId) -> usize {
        self.outgoing_halfedges(v).count()
    }

    /// The faces around `v`, counter-clockwise.
    pub fn vertex_faces(&self, v: VertexId) -> impl Iterator<Item = FaceId> + '_ {
        self.outgoing_halfedges(v).filter_map(move |h| self.face(h))
    }

    /// The half-edges of a face, starting at its recorded one.
    pub fn face_halfedges(&self, f: FaceId) -> [HalfEdgeId; 3] {
        let h0 = self.f_he[f.index()];
        let h1 = self.next(h0);
        [h0, h1, self.next(h1)]
    }

    /// The vertices of a face, counter-clockwise: where each of its
    /// half-edges starts (read from the twin, which lies next to it).
    #[inline]
    pub fn face_vertices(&self, f: FaceId) -> [VertexId; 3] {
        self.face_halfedges(f).map(|h| self.from(h))
    }

    pub fn face_edges(&self, f: FaceId) -> [EdgeId; 3] {
        self.face_halfedges(f).map(|h| h.edge())
    }

    /// The faces on either side of an edge (none on a boundary side).
    pub fn edge_faces(&self, e: EdgeId) -> [Option<FaceId>; 2] {
        let h = e.halfedge();
        [self.face(h), self.face(h.twin())]
    }

    /// The centroid of a face (current positions).
    pub fn face_centroid(&self, f: FaceId) -> DVec3 {
        let [a, b, c] = self.face_vertices(f);
        (self.position(a) + self.position(b) + self.position(c)) / 3.0
    }

    // ----- allocation ----------------------------------------------------

    /// Makes room for this many more vertices, edges and faces, so that a
    /// refinement step does not grow its arrays piece by piece.
    pub fn reserve(&mut self, vertices: usize, edges: usize, faces: usize) {
        crate::huge::grow(&mut self.v_out, vertices);
        crate::huge::grow(&mut self.pos, vertices);
        self.v_level.reserve(vertices);
        self.v_step.reserve(vertices);
        self.v_alive.reserve(vertices);
        self.v_sharp.reserve(vertices);
        crate::huge::grow(&mut self.he_next, 2 * edges);
        crate::huge::grow(&mut self.he_to, 2 * edges);
        crate::huge::grow(&mut self.he_face, 2 * edges);
        self.e_level.reserve(edges);
        self.e_alive.reserve(edges);
        self.e_block.reserve(edges);
        self.e_transversal.reserve(edges);
        self.e_sharp.reserve(edges);
        crate::huge::grow(&mut self.f_he, faces);
        self.f_alive.reserve(faces);
        self.f_tag.reserve(faces);
    }

    /// Starts giving every vertex an origin key: each vertex now in the
    /// mesh `base(v)`, each one a split makes from then on the
    /// [`origin_key`] of what it split.
    pub fn track_origins(&mut self, base: impl Fn(VertexId) -> u64) {
        self.v_key = (0..self.v_alive.len() as u32)
            .map(|v| base(VertexId(v)))
            .collect();
    }

    /// The vertex's origin key, while [`Mesh::track_origins`] is on.
    pub fn origin(&self, v: VertexId) -> Option<u64> {
        self.v_key.get(v.index()).copied()
    }

    /// Gives `v`, just made by splitting an element with `corners`, its
    /// origin key, while keys are tracked.
    pub(crate) fn set_origin(&mut self, v: VertexId, corners: &[VertexId]) {
        if self.v_key.is_empty() {
            return;
        }
        let mut keys = [0u64; 3];
        for (k, c) in keys.iter_mut().zip(corners) {
            *k = self.v_key[c.index()];
        }
        self.v_key[v.index()] = origin_key(&keys[..corners.len()]);
    }

    /// A new vertex at `p`, made in grammar step `step`.
    pub(crate) fn new_vertex(&mut self, p: DVec3, level: u32, step: u32) -> VertexId {
        if !self.v_key.is_empty() && self.free_v.is_empty() {
            self.v_key.push(0);
        }
        if let Some(i) = self.free_v.pop() {
            let k = i as usize;
            self.v_out[k] = NO_HALFEDGE;
            self.pos[k] = p;
            self.v_level.set(k, level);
            self.v_step.set(k, step);
            self.v_alive.set(k, true);
            self.v_sharp.set(k, 0.0);
            return VertexId(i);
        }
        self.v_out.push(NO_HALFEDGE);
        self.pos.push(p);
        self.v_level.push(level);
        self.v_step.push(step);
        self.v_alive.push(true);
        self.v_sharp.push(0.0);
        VertexId(self.v_alive.len() as u32 - 1)
    }

    /// A new edge from `a` to `b`; returns the half-edge a -> b. Links are
    /// left for the caller to set.
    pub(crate) fn new_edge(&mut self, a: VertexId, b: VertexId, level: u32) -> HalfEdgeId {
        let e = if let Some(i) = self.free_e.pop() {
            let k = i as usize;
            self.e_level.set(k, level);
            self.e_alive.set(k, true);
            self.e_block.set(k, false);
            self.e_transversal.set(k, false);
            self.e_sharp.set(k, 0.0);
            EdgeId(i)
        } else {
            self.e_level.push(level);
            self.e_alive.push(true);
            self.e_block.push(false);
            self.e_transversal.push(false);
            self.e_sharp.push(0.0);
            let e = EdgeId(self.e_alive.len() as u32 - 1);
            let dummy = HalfEdgeId(0);
            for _ in 0..2 {
                self.he_to.push(VertexId(0));
                self.he_next.push(dummy);
                self.he_face.push(NO_FACE);
            }
            e
        };
        let h = e.halfedge();
        self.he_to[h.index()] = b;
        self.he_to[h.twin().index()] = a;
        self.he_face[h.index()] = NO_FACE;
        self.he_face[h.twin().index()] = NO_FACE;
        h
    }

    /// A new face with tag `tag`: that of the face it is cut from. Its
    /// level is one more than its highest corner's.
    pub(crate) fn new_face(&mut self, h: HalfEdgeId, tag: u32) -> FaceId {
        if let Some(i) = self.free_f.pop() {
            self.f_he[i as usize] = h;
            self.face_remade(FaceId(i));
            self.f_alive.set(i as usize, true);
            self.f_tag.set(i as usize, tag);
            return FaceId(i);
        }
        self.f_he.push(h);
        self.f_alive.push(true);
        self.f_tag.push(tag);
        FaceId(self.f_alive.len() as u32 - 1)
    }

    pub(crate) fn delete_vertex(&mut self, v: VertexId) {
        self.v_alive.set(v.index(), false);
        self.v_out[v.index()] = NO_HALFEDGE;
        self.free_v.push(v.0);
    }

    pub(crate) fn delete_edge(&mut self, e: EdgeId) {
        self.e_alive.set(e.index(), false);
        self.free_e.push(e.0);
    }

    pub(crate) fn delete_face(&mut self, f: FaceId) {
        self.face_remade(f);
        self.f_alive.set(f.index(), false);
        self.free_f.push(f.0);
    }

    /// Makes `b` the half-edge after `a`.
    #[inline]
    pub(crate) fn link(&mut self, a: HalfEdgeId, b: HalfEdgeId) {
        self.he_next[a.index()] = b;
    }

    /// Makes `h0 -> h1 -> h2` a face cycle of face `f`.
    pub(crate) fn set_triangle(
        &mut self,
        f: FaceId,
        h0: HalfEdgeId,
        h1: HalfEdgeId,
        h2: HalfEdgeId,
    ) {
        self.link(h0, h1);
        self.link(h1, h2);
        self.link(h2, h0);
        for h in [h0, h1, h2] {
            self.he_face[h.index()] = f.0;
        }
        self.f_he[f.index()] = h0;
    }

    /// An operator made face `f` anew: its level is one more than its
    /// highest corner's again.
    #[inline]
    pub(crate) fn face_remade(&mut self, f: FaceId) {
        if !self.f_level_kept.is_empty() {
            self.f_level_kept.remove(&f.0);
        }
    }

    /// The level of a face: one more than its highest vertex (paper 000, §6).
    pub(crate) fn face_level_from_vertices(&self, vs: [VertexId; 3]) -> u32 {
        vs.iter()
            .map(|v| self.v_level.get(v.index()))
            .max()
            .unwrap_or(0)
            + 1
    }

    /// Points `v`'s outgoing half-edge at its boundary one, if it has one.
    pub(crate) fn fix_outgoing(&mut self, v: VertexId) {
        let Some(start) = self.outgoing(v) else {
            return;
        };
        let mut h = start;
        loop {
            if self.is_boundary_halfedge(h) {
                self.set_outgoing(v, Some(h));
                return;
            }
            h = self.prev(h).twin();
            if h == start {
                return;
            }
        }
    }
}

/// Iterates the half-edges leaving a vertex, counter-clockwise.
pub struct OutgoingIter<'m> {
    mesh: &'m Mesh,
    start: Option<HalfEdgeId>,
    /// A boundary vertex's outgoing boundary half-edge, where the walk
    /// ends; none for an interior vertex, whose walk ends back at `start`.
    last: Option<HalfEdgeId>,
    cur: Option<HalfEdgeId>,
}

impl Iterator for OutgoingIter<'_> {
    type Item = HalfEdgeId;

    #[inline]
    fn next(&mut self) -> Option<HalfEdgeId> {
        let h = self.cur?;
        if Some(h) == self.last {
            self.cur = None;
            return Some(h);
        }
        // Counter-clockwise around the origin: the previous half-edge of
        // h's face (a triangle: its next one's next) comes into the
        // vertex; its twin leaves it.
        let m = self.mesh;
        debug_assert!(
            !m.is_boundary_halfedge(h),
            "a boundary vertex keeps its boundary half-edge as its outgoing one"
        );
        let n = m.next(m.next(h)).twin();
        self.cur = if Some(n) == self.start { None } else { Some(n) };
        Some(h)
    }
}

/// A per-element column whose elements all hold the default value (0)
/// until one is given another: only then is it stored, whole. Sharpness
/// and tags are 0 on most meshes, and a large mesh need not carry a number
/// per element for them.
#[derive(Clone, Debug, Default)]
pub(crate) struct Column<T> {
    /// Empty while every element holds the default; else one per element.
    stored: Vec<T>,
    len: usize,
}

impl<T: Copy + Default + PartialEq> Column<T> {
    /// `len` elements holding the default.
    pub(crate) fn defaults(len: usize) -> Column<T> {
        Column {
            stored: Vec::new(),
            len,
        }
    }

    /// A column of these values (kept only if some is not the default).
    pub(crate) fn from_vec(values: Vec<T>) -> Column<T> {
        let len = values.len();
        if values.iter().all(|&x| x == T::default()) {
            Column::defaults(len)
        } else {
            Column {
                stored: values,
                len,
            }
        }
    }

    /// True while every element holds the default.
    #[inline]
    pub(crate) fn all_default(&self) -> bool {
        self.stored.is_empty()
    }

    #[inline]
    pub(crate) fn get(&self, i: usize) -> T {
        debug_assert!(i < self.len);
        if self.stored.is_empty() {
            T::default()
        } else {
            self.stored[i]
        }
    }

    #[inline]
    pub(crate) fn set(&mut self, i: usize, x: T) {
        assert!(i < self.len, "element {i} of {}", self.len);
        if self.stored.is_empty() {
            if x == T::default() {
                return;
            }
            self.stored = vec![T::default(); self.len];
        }
        self.stored[i] = x;
    }

    #[inline]
    pub(crate) fn push(&mut self, x: T) {
        if !self.stored.is_empty() || x != T::default() {
            if self.stored.is_empty() {
                self.stored = vec![T::default(); self.len];
            }
            self.stored.push(x);
        }
        self.len += 1;
    }

    /// Room for `additional` more elements, where they are stored.
    fn reserve(&mut self, additional: usize) {
        if !self.stored.is_empty() {
            crate::huge::grow(&mut self.stored, additional);
        }
    }

    /// The bytes the stored values take.
    fn stored_bytes(&self) -> usize {
        std::mem::size_of_val(&self.stored[..])
    }

    /// The stored values: every element's, or none while all are the
    /// default.
    pub(crate) fn stored_mut(&mut self) -> &mut [T] {
        &mut self.stored
    }
}

/// Columns are equal when every element holds the same value, however
/// they are kept.
impl<T: Copy + Default + PartialEq> PartialEq for Column<T> {
    fn eq(&self, other: &Column<T>) -> bool {
        self.len == other.len && (0..self.len).all(|i| self.get(i) == other.get(i))
    }
}

#[cfg(test)]
mod tests {
    use super::{Column, EdgeId, FaceId, HalfEdgeId, Mesh, VertexId};
    use crate::mesh::shapes;
    use glam::DVec3;
    use std::collections::HashMap;

    /// The live half-edges of `m`.
    fn live(m: &Mesh) -> Vec<HalfEdgeId> {
        m.edges()
            .flat_map(|e| [e.halfedge(), e.halfedge().twin()])
            .collect()
    }

    /// `prev` and the ring walk against what the test builds from `next`
    /// alone: the half-edge whose next is `h`, found by searching them
    /// all, and each vertex's outgoing half-edges in counter-clockwise
    /// order, found by following that inverse (the walk turns with the
    /// twin of the half-edge before), from the one after the boundary gap.
    fn check_prev_and_rings(m: &Mesh) {
        let hs = live(m);
        let before = |h: HalfEdgeId| -> HalfEdgeId {
            let found: Vec<HalfEdgeId> = hs.iter().copied().filter(|&g| m.next(g) == h).collect();
            assert_eq!(found.len(), 1, "one half-edge before {h:?}");
            found[0]
        };
        for &h in &hs {
            assert_eq!(m.prev(h), before(h), "prev of {h:?}");
        }
        for v in m.vertices() {
            let leaving: Vec<HalfEdgeId> = hs.iter().copied().filter(|&h| m.from(h) == v).collect();
            let walked: Vec<HalfEdgeId> = m.outgoing_halfedges(v).collect();
            assert_eq!(walked.len(), leaving.len(), "valence of {v:?}");
            // The first after the gap: the one whose twin is a boundary
            // half-edge; any one for an interior vertex, so start where
            // the walk starts.
            let first = leaving
                .iter()
                .copied()
                .find(|&h| m.is_boundary_halfedge(h.twin()))
                .unwrap_or(walked[0]);
            let mut expect = vec![first];
            while expect.len() < leaving.len() {
                let h = *expect.last().expect("one");
                expect.push(before(h).twin());
            }
            assert_eq!(walked, expect, "ring of {v:?}");
            let mut any: Vec<HalfEdgeId> = m.outgoing_any_order(v).collect();
            any.sort_unstable();
            let mut sorted = leaving.clone();
            sorted.sort_unstable();
            assert_eq!(any, sorted, "the same half-edges in any order at {v:?}");
            if let Some(&out) = walked.last() {
                if m.is_boundary_vertex(v) {
                    assert!(m.is_boundary_halfedge(out), "ends at the boundary");
                }
            }
        }
    }

    #[test]
    fn prev_and_the_ring_walk_agree_with_the_next_links_through_splits_flips_and_welds() {
        // A grid has boundary vertices of valence 2 to 4 and corners.
        let mut m = Mesh::from_soup(&shapes::triangle_grid(4, 3)).expect("a grid");
        m.validate().expect("valid");
        check_prev_and_rings(&m);
        // Split every boundary edge and some interior ones, flip, weld.
        let boundary: Vec<EdgeId> = m.edges().filter(|&e| m.is_boundary_edge(e)).collect();
        let mut made = Vec::new();
        for e in boundary.into_iter().step_by(2) {
            let (a, b) = m.edge_vertices(e);
            let p = (m.position(a) + m.position(b)) * 0.5;
            made.push(m.edge_split(e, p).expect("split"));
            check_prev_and_rings(&m);
        }
        let interior: Vec<EdgeId> = m.edges().filter(|&e| !m.is_boundary_edge(e)).collect();
        for &e in interior.iter().take(5) {
            let (a, b) = m.edge_vertices(e);
            made.push(
                m.edge_split(e, (m.position(a) + m.position(b)) * 0.5)
                    .expect("split"),
            );
        }
        let f = m.faces().next().expect("a face");
        let centre = m.face_split(f, m.face_centroid(f)).expect("face split");
        check_prev_and_rings(&m);
        m.face_weld(centre).expect("a face split welds back");
        check_prev_and_rings(&m);
        let centre = m.face_split(f, m.face_centroid(f)).expect("face split");
        let flips: Vec<EdgeId> = m.edges().filter(|&e| m.is_transversal_edge(e)).collect();
        let mut flipped = 0;
        for e in flips {
            if m.edge_flip(e).is_ok() {
                flipped += 1;
            }
        }
        assert!(flipped > 0);
        check_prev_and_rings(&m);
        m.validate().expect("valid");
        assert!(m.is_vertex(centre));
        // Weld boundary midpoints back where they still have valence 3.
        let mut welded = 0;
        for v in made {
            if m.is_vertex(v) && m.is_boundary_vertex(v) {
                let keep = m.boundary_neighbour(v, true).expect("on the boundary");
                if m.edge_weld(v, keep).is_ok() {
                    welded += 1;
                    check_prev_and_rings(&m);
                }
            }
        }
        assert!(welded > 0);
        m.validate().expect("valid");
        // A closed mesh: every half-edge has a face.
        let s = Mesh::from_soup(&shapes::icosahedron()).expect("closed");
        check_prev_and_rings(&s);
        // A lone triangle: a boundary loop of three.
        let mut soup = crate::mesh::PolygonSoup {
            positions: vec![DVec3::ZERO, DVec3::X, DVec3::Y],
            ..Default::default()
        };
        soup.faces.push([0u32, 1, 2]);
        let t = Mesh::from_soup(&soup).expect("a triangle");
        check_prev_and_rings(&t);
        assert_eq!(t.valence(VertexId(0)), 2);
    }

    /// The test's own record of face levels, as a mesh stored them when
    /// every face had its level in an array: by face slot, the corners
    /// the face had (from its smallest vertex id on) and its level, set
    /// to one more than its highest corner's when an operator made it
    /// (a slot that is new, or whose corners changed), and kept
    /// otherwise, whatever the corners' levels do later.
    type Stored = HashMap<FaceId, ([VertexId; 3], u32)>;

    /// Brings `stored` up to date after one operation on `m` and compares
    /// every face's level with it.
    fn follow_face_levels(m: &Mesh, stored: &mut Stored) {
        let mut now = Stored::new();
        for f in m.faces() {
            let mut vs = m.face_vertices(f);
            let first = (0..3).min_by_key(|&i| vs[i]).expect("three corners");
            vs.rotate_left(first);
            let level = match stored.get(&f) {
                Some(&(was, l)) if was == vs => l,
                _ => vs.iter().map(|&v| m.vertex_level(v)).max().expect("three") + 1,
            };
            now.insert(f, (vs, level));
        }
        *stored = now;
        for f in m.faces() {
            assert_eq!(m.face_level(f), stored[&f].1, "level of face {f:?}");
        }
    }

    #[test]
    fn face_levels_are_what_an_array_set_by_the_operators_holds_through_splits_flips_welds_and_set_vertex_level(
    ) {
        let mut m = Mesh::from_soup(&shapes::triangle_grid(5, 4)).expect("a grid");
        let mut stored = Stored::new();
        follow_face_levels(&m, &mut stored);
        assert!(m.faces().all(|f| m.face_level(f) == 1));
        let original = m.clone();
        // Raised corners: their faces keep level 1 until an operator
        // makes them again.
        let (a, b) = (VertexId(7), VertexId(12));
        m.set_vertex_level(a, 5);
        follow_face_levels(&m, &mut stored);
        m.set_vertex_level(b, 300);
        follow_face_levels(&m, &mut stored);
        assert!(m.vertex_faces(a).all(|f| m.face_level(f) == 1));
        // Setting them back leaves nothing kept: the mesh is the one it
        // was.
        m.set_vertex_level(b, 0);
        m.set_vertex_level(a, 0);
        follow_face_levels(&m, &mut stored);
        assert_eq!(m, original);
        m.set_vertex_level(a, 5);
        m.set_vertex_level(b, 2);
        follow_face_levels(&m, &mut stored);
        // Operators around them and elsewhere.
        let at_a: Vec<EdgeId> = m.outgoing_halfedges(a).map(|h| h.edge()).collect();
        for &e in at_a.iter().take(2) {
            let (p, q) = m.edge_vertices(e);
            m.edge_split(e, (m.position(p) + m.position(q)) * 0.5)
                .expect("split");
            follow_face_levels(&m, &mut stored);
        }
        // A split vertex's level moves after its faces were made.
        let made = VertexId(m.v_alive.len() as u32 - 1);
        m.set_vertex_level(made, 9);
        follow_face_levels(&m, &mut stored);
        let transversals: Vec<EdgeId> = m.edges().filter(|&e| m.is_transversal_edge(e)).collect();
        let mut flipped = 0;
        for e in transversals {
            if m.edge_flip(e).is_ok() {
                flipped += 1;
                follow_face_levels(&m, &mut stored);
            }
        }
        assert!(flipped > 0);
        let f = m.vertex_faces(b).next().expect("a face at b");
        let centre = m.face_split(f, m.face_centroid(f)).expect("face split");
        follow_face_levels(&m, &mut stored);
        m.set_vertex_level(b, 1);
        follow_face_levels(&m, &mut stored);
        m.face_weld(centre).expect("welds back");
        follow_face_levels(&m, &mut stored);
        // A weld frees slots that later operators reuse.
        let boundary: Vec<EdgeId> = m.edges().filter(|&e| m.is_boundary_edge(e)).collect();
        let e = boundary[1];
        let (p, q) = m.edge_vertices(e);
        let v = m
            .edge_split(e, (m.position(p) + m.position(q)) * 0.5)
            .expect("split");
        follow_face_levels(&m, &mut stored);
        m.set_vertex_level(q, 4);
        follow_face_levels(&m, &mut stored);
        let keep = m.boundary_neighbour(v, true).expect("on the boundary");
        m.edge_weld(v, keep).expect("weld");
        follow_face_levels(&m, &mut stored);
        let f = m.faces().nth(3).expect("a face");
        m.face_split(f, m.face_centroid(f)).expect("reuses slots");
        follow_face_levels(&m, &mut stored);
        m.validate().expect("valid");
        // Some face kept a level its corners no longer give, and some
        // has the level its corners give.
        let derived = |f: FaceId| {
            m.face_vertices(f)
                .iter()
                .map(|&v| m.vertex_level(v))
                .max()
                .expect("three")
                + 1
        };
        assert!(m.faces().any(|f| m.face_level(f) != derived(f)));
        assert!(m
            .faces()
            .any(|f| m.face_level(f) == derived(f) && derived(f) > 1));
    }

    #[test]
    fn a_column_is_stored_only_once_an_element_differs_from_0() {
        let mut c: Column<f64> = Column::defaults(3);
        c.set(1, 0.0);
        c.push(0.0);
        assert!(c.stored_mut().is_empty());
        assert_eq!((0..4).map(|i| c.get(i)).collect::<Vec<_>>(), [0.0; 4]);
        c.set(2, 1.5);
        c.push(2.0);
        assert_eq!(c.stored_mut(), [0.0, 0.0, 1.5, 0.0, 2.0]);
        // Equality is element by element, however the columns are kept.
        let mut d: Column<f64> = Column::defaults(5);
        assert_ne!(c, d);
        d.set(2, 1.5);
        d.set(4, 2.0);
        assert_eq!(c, d);
        assert_eq!(Column::<u32>::from_vec(vec![0, 0]), Column::defaults(2));
        assert_ne!(Column::<u32>::from_vec(vec![0, 1]), Column::defaults(2));
    }
}
