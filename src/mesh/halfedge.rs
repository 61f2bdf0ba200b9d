//! The half-edge mesh: typed ids, flat arrays of indices, and per-element
//! attributes (a refinement level on every vertex, edge and face, the step
//! that made each vertex, block and transversal marks). The state of a
//! grammar's run (its step, its current level, the positions written for
//! the next step) lives with the run, in `surface::run`.
//!
//! Half-edges come in pairs: `h` and `h ^ 1` are twins, and edge `e` is the
//! pair `2e`, `2e + 1`. A boundary half-edge has no face. Every vertex keeps
//! one outgoing half-edge; a boundary vertex keeps its outgoing boundary
//! half-edge, so that walks around it start at the boundary.

use std::fmt;

use glam::DVec3;

/// `he_face` of a boundary half-edge.
pub(crate) const NO_FACE: u32 = u32::MAX;

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
    pub(crate) v_out: Vec<Option<HalfEdgeId>>,
    pub(crate) pos: Vec<DVec3>,
    pub(crate) v_level: Vec<u32>,
    /// The step of the grammar run that made the vertex (0: the base mesh
    /// and `init:` rules).
    pub(crate) v_step: Vec<u32>,
    pub(crate) v_alive: Vec<bool>,
    /// The sharpness of each vertex, as OpenSubdiv has it: 0 smooth, a
    /// positive number a corner for that many more levels, infinite a
    /// corner for ever. New vertices get 0.
    pub(crate) v_sharp: Column<f64>,
    // Half-edges, in twin pairs.
    pub(crate) he_to: Vec<VertexId>,
    pub(crate) he_next: Vec<HalfEdgeId>,
    pub(crate) he_prev: Vec<HalfEdgeId>,
    /// The face of each half-edge, `NO_FACE` on the boundary.
    pub(crate) he_face: Vec<u32>,
    // Edges.
    pub(crate) e_level: Vec<u32>,
    pub(crate) e_alive: Vec<bool>,
    /// The internal edge of a basic block of a tri-quad mesh.
    pub(crate) e_block: Vec<bool>,
    /// Made by an edge split, joining the new vertex to a vertex opposite
    /// the split edge, and not flipped since.
    pub(crate) e_transversal: Vec<bool>,
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
    pub(crate) f_level: Vec<u32>,
    pub(crate) f_alive: Vec<bool>,
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
            .filter(|v| self.v_alive[v.index()])
    }

    pub fn edges(&self) -> impl Iterator<Item = EdgeId> + '_ {
        (0..self.e_alive.len() as u32)
            .map(EdgeId)
            .filter(|e| self.e_alive[e.index()])
    }

    pub fn faces(&self) -> impl Iterator<Item = FaceId> + '_ {
        (0..self.f_alive.len() as u32)
            .map(FaceId)
            .filter(|f| self.f_alive[f.index()])
    }

    pub fn is_vertex(&self, v: VertexId) -> bool {
        self.v_alive.get(v.index()).copied().unwrap_or(false)
    }

    pub fn is_edge(&self, e: EdgeId) -> bool {
        self.e_alive.get(e.index()).copied().unwrap_or(false)
    }

    pub fn is_face(&self, f: FaceId) -> bool {
        self.f_alive.get(f.index()).copied().unwrap_or(false)
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
            + size(&self.v_level)
            + size(&self.v_step)
            + size(&self.v_alive)
            + self.v_sharp.stored_bytes();
        let h = size(&self.he_to) + size(&self.he_next) + size(&self.he_prev) + size(&self.he_face);
        let e = size(&self.e_level)
            + size(&self.e_alive)
            + size(&self.e_block)
            + size(&self.e_transversal)
            + self.e_sharp.stored_bytes();
        let f = size(&self.f_he)
            + size(&self.f_level)
            + size(&self.f_alive)
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
        self.v_level[v.index()]
    }

    pub fn edge_level(&self, e: EdgeId) -> u32 {
        self.e_level[e.index()]
    }

    pub fn face_level(&self, f: FaceId) -> u32 {
        self.f_level[f.index()]
    }

    /// The face's tag: that of the soup face it was cut from
    /// ([`Mesh::from_soup_tagged`]), 0 for an untagged mesh.
    pub fn tag(&self, f: FaceId) -> u32 {
        self.f_tag.get(f.index())
    }

    pub fn set_vertex_level(&mut self, v: VertexId, l: u32) {
        self.v_level[v.index()] = l;
    }

    pub fn set_edge_level(&mut self, e: EdgeId, l: u32) {
        self.e_level[e.index()] = l;
    }

    /// True for the internal edge of a basic block (tri-quad meshes).
    pub fn is_block_edge(&self, e: EdgeId) -> bool {
        self.e_block[e.index()]
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
        if !self.creased {
            return 0;
        }
        self.outgoing_halfedges(v)
            .filter(|h| self.is_sharp_edge(h.edge()) && !self.is_boundary_edge(h.edge()))
            .count()
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

    /// The step of a grammar run that made the vertex (0: the base mesh).
    pub fn vertex_step(&self, v: VertexId) -> u32 {
        self.v_step[v.index()]
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
            if !self.e_block[h.edge().index()] {
                return false;
            }
            any = true;
        }
        any
    }

    /// True for an edge that an edge split drew from the new vertex to a
    /// vertex opposite the split edge, and that no flip has touched since.
    pub fn is_transversal_edge(&self, e: EdgeId) -> bool {
        self.e_transversal[e.index()]
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

    #[inline]
    pub fn prev(&self, h: HalfEdgeId) -> HalfEdgeId {
        self.he_prev[h.index()]
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
        self.v_out[v.index()]
    }

    pub fn is_boundary_halfedge(&self, h: HalfEdgeId) -> bool {
        self.he_face[h.index()] == NO_FACE
    }

    pub fn is_boundary_edge(&self, e: EdgeId) -> bool {
        let h = e.halfedge();
        self.is_boundary_halfedge(h) || self.is_boundary_halfedge(h.twin())
    }

    pub fn is_boundary_vertex(&self, v: VertexId) -> bool {
        self.v_out[v.index()].is_some_and(|h| self.is_boundary_halfedge(h))
    }

    /// The next (`forward`) or previous vertex along the boundary through
    /// `v`, in the direction of the faces' half-edges: the boundary edge
    /// `v -> bnext(v)` and `bprev(v) -> v` run along a face. None off the
    /// boundary.
    pub fn boundary_neighbour(&self, v: VertexId, forward: bool) -> Option<VertexId> {
        let out = self.v_out[v.index()].filter(|&h| self.is_boundary_halfedge(h))?;
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
        self.outgoing_halfedges(a).find(|&h| self.to(h) == b)
    }

    /// The face `vs` (its corners counter-clockwise, from any of them),
    /// if there is one. The three vertices are walked around in turn, so
    /// the cost is three times the smallest of their valences: a triangle
    /// at a vertex of huge valence is found from its other corners.
    pub fn find_face(&self, vs: [VertexId; 3]) -> Option<FaceId> {
        let mut walks = vs.map(|v| self.outgoing_halfedges(v));
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
        let start = self.v_out.get(v.index()).copied().flatten().map(|h| {
            if self.is_boundary_halfedge(h) {
                self.prev(h).twin()
            } else {
                h
            }
        });
        OutgoingIter {
            mesh: self,
            start,
            cur: start,
        }
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
        crate::huge::grow(&mut self.v_level, vertices);
        crate::huge::grow(&mut self.v_step, vertices);
        crate::huge::grow(&mut self.v_alive, vertices);
        self.v_sharp.reserve(vertices);
        crate::huge::grow(&mut self.he_next, 2 * edges);
        crate::huge::grow(&mut self.he_prev, 2 * edges);
        crate::huge::grow(&mut self.he_to, 2 * edges);
        crate::huge::grow(&mut self.he_face, 2 * edges);
        crate::huge::grow(&mut self.e_level, edges);
        crate::huge::grow(&mut self.e_alive, edges);
        crate::huge::grow(&mut self.e_block, edges);
        crate::huge::grow(&mut self.e_transversal, edges);
        self.e_sharp.reserve(edges);
        crate::huge::grow(&mut self.f_he, faces);
        crate::huge::grow(&mut self.f_level, faces);
        crate::huge::grow(&mut self.f_alive, faces);
        self.f_tag.reserve(faces);
    }

    /// A new vertex at `p`, made in grammar step `step`.
    pub(crate) fn new_vertex(&mut self, p: DVec3, level: u32, step: u32) -> VertexId {
        if let Some(i) = self.free_v.pop() {
            let k = i as usize;
            self.v_out[k] = None;
            self.pos[k] = p;
            self.v_level[k] = level;
            self.v_step[k] = step;
            self.v_alive[k] = true;
            self.v_sharp.set(k, 0.0);
            return VertexId(i);
        }
        self.v_out.push(None);
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
            self.e_level[k] = level;
            self.e_alive[k] = true;
            self.e_block[k] = false;
            self.e_transversal[k] = false;
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
                self.he_prev.push(dummy);
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

    /// A new face with tag `tag`: that of the face it is cut from.
    pub(crate) fn new_face(&mut self, h: HalfEdgeId, level: u32, tag: u32) -> FaceId {
        if let Some(i) = self.free_f.pop() {
            self.f_he[i as usize] = h;
            self.f_level[i as usize] = level;
            self.f_alive[i as usize] = true;
            self.f_tag.set(i as usize, tag);
            return FaceId(i);
        }
        self.f_he.push(h);
        self.f_level.push(level);
        self.f_alive.push(true);
        self.f_tag.push(tag);
        FaceId(self.f_alive.len() as u32 - 1)
    }

    pub(crate) fn delete_vertex(&mut self, v: VertexId) {
        self.v_alive[v.index()] = false;
        self.v_out[v.index()] = None;
        self.free_v.push(v.0);
    }

    pub(crate) fn delete_edge(&mut self, e: EdgeId) {
        self.e_alive[e.index()] = false;
        self.free_e.push(e.0);
    }

    pub(crate) fn delete_face(&mut self, f: FaceId) {
        self.f_alive[f.index()] = false;
        self.free_f.push(f.0);
    }

    #[inline]
    pub(crate) fn link(&mut self, a: HalfEdgeId, b: HalfEdgeId) {
        self.he_next[a.index()] = b;
        self.he_prev[b.index()] = a;
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

    /// The level of a face: one more than its highest vertex (paper 000, §6).
    pub(crate) fn face_level_from_vertices(&self, vs: [VertexId; 3]) -> u32 {
        vs.iter()
            .map(|v| self.v_level[v.index()])
            .max()
            .unwrap_or(0)
            + 1
    }

    /// Points `v`'s outgoing half-edge at its boundary one, if it has one.
    pub(crate) fn fix_outgoing(&mut self, v: VertexId) {
        let Some(start) = self.v_out[v.index()] else {
            return;
        };
        let mut h = start;
        loop {
            if self.is_boundary_halfedge(h) {
                self.v_out[v.index()] = Some(h);
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
    cur: Option<HalfEdgeId>,
}

impl Iterator for OutgoingIter<'_> {
    type Item = HalfEdgeId;

    fn next(&mut self) -> Option<HalfEdgeId> {
        let h = self.cur?;
        // Counter-clockwise around the origin: the previous half-edge of
        // h's face comes into the vertex; its twin leaves it.
        let n = self.mesh.prev(h).twin();
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
    use super::Column;

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
