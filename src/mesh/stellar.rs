//! The stellar operators of paper 000, §5: face split and weld, edge split
//! and weld, edge flip. Each checks what it needs first and refuses an
//! illegal case with an error, leaving the mesh unchanged; levels follow
//! paper 000, §6. What a split records beyond geometry and levels (the
//! step that made the new vertex, the basic blocks it marks) is given by
//! the caller as a [`Split`] policy.

use glam::DVec3;

use super::halfedge::{EdgeId, FaceId, HalfEdgeId, Mesh, MeshError, VertexId, NO_FACE};

/// What splitting the internal edge of a basic block does to the blocks
/// (paper 000, §6).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BlockSplit {
    /// Primal quadrisection (Fig. 12a): the four edges at the new vertex
    /// become the internal edges of the next blocks.
    #[default]
    Quadrisection,
    /// √2 bisection on 4-8 meshes (Fig. 8): the block's four external
    /// edges become the internal edges of the next blocks.
    Bisection,
    /// Dual quadrisection (Fig. 12b): blocks are fans of triangles around
    /// a centre; splitting an internal edge marks the edges at the new
    /// vertex, as in primal quadrisection.
    Dual,
}

/// How a face or edge split marks what it makes: the policy of the grammar
/// run that calls it. The default (step 0, quadrisection, no blocks from
/// face splits) is that of [`Mesh::face_split`] and [`Mesh::edge_split`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Split {
    /// The step of the grammar run; the new vertex records it.
    pub step: u32,
    /// What splitting a basic block's internal edge makes of the block.
    pub blocks: BlockSplit,
    /// Triangles in no block join the blocks: a face split makes its three
    /// spokes internal edges of blocks, as splitting a block's internal
    /// edge does, so that a lone triangle joins a quad mesh's primal
    /// quadrisection (Catmull-Clark on triangles); a boundary split of a
    /// lone triangle makes its two halves one block, the new edge inside
    /// it the internal edge (the triangles `Mesh::match_blocks` leaves on
    /// the boundary). Set while a grammar that reads blocks runs.
    pub lone_triangles_join_blocks: bool,
    /// Adaptive 4-8 refinement (with [`BlockSplit::Bisection`]): an
    /// external edge of a split block becomes the internal edge of a block
    /// only once the face across it has it as its refinement edge too
    /// ([`Mesh::refinement_edge`]), so that a mark always means a
    /// complete diamond. Where every block is split in a step, the marks
    /// at the end of the step are those of plain bisection.
    pub adaptive: bool,
}

impl Mesh {
    /// The refinement edge of face `f` on a 4-8 mesh (a triangulated
    /// quadrangulation refined by bisection, `blocks: bisection`): the
    /// edge that splitting it would split. That is its block's internal
    /// edge where it has one; a face without one was made by a bisection
    /// whose other side is still coarser (an incomplete diamond), and its
    /// refinement edge is the one opposite its newest vertex, the vertex
    /// that bisection made (newest vertex bisection). Vertices are
    /// numbered in the order they are made while no slot is reused, which
    /// adaptive runs check ([`Mesh::reuses_vertex_slots`]).
    pub fn refinement_edge(&self, f: FaceId) -> EdgeId {
        let hs = self.face_halfedges(f);
        if let Some(h) = hs.iter().find(|h| self.e_block.get(h.edge().index())) {
            return h.edge();
        }
        // The edge opposite the corner `from(h)` is `next(h)`.
        let newest = hs
            .into_iter()
            .max_by_key(|&h| self.from(h).0)
            .expect("a face has three half-edges");
        self.next(newest).edge()
    }

    /// True when `e` is the refinement edge of a face beside it
    /// ([`Mesh::refinement_edge`]): a diamond's diagonal, complete or not.
    pub fn is_refinement_edge(&self, e: EdgeId) -> bool {
        self.edge_faces(e)
            .into_iter()
            .flatten()
            .any(|f| self.refinement_edge(f) == e)
    }

    /// For a refinement edge `e`: `None` when its diamond is complete
    /// (every face beside it has it as its refinement edge), else the
    /// refinement edge of the first face beside it that does not: the
    /// edge whose split makes the diamond complete (paper 000, §9: the
    /// refinement spreads to the neighbours as far as the rules need).
    pub fn bisection_blocker(&self, e: EdgeId) -> Option<EdgeId> {
        self.edge_faces(e)
            .into_iter()
            .flatten()
            .map(|f| self.refinement_edge(f))
            .find(|&r| r != e)
    }

    /// True when a vertex slot freed by a weld waits for reuse, so that a
    /// new vertex would not have the highest number.
    pub fn reuses_vertex_slots(&self) -> bool {
        !self.free_v.is_empty()
    }

    /// Face split: a new vertex `v` inside triangle `abc` joined to its
    /// three corners.
    ///
    /// ```text
    ///        c                 c
    ///       / \               /|\
    ///      /   \             / | \
    ///     /  f  \    ->     /  v  \
    ///    /       \         / /   \ \
    ///   a---------b       a---------b
    /// ```
    ///
    /// Levels: `l(v) = max(l(a), l(b), l(c)) + 1`; the three new edges get
    /// `l(v)`, the level of their common vertex; the faces `l(v) + 1`.
    /// The three faces keep `f`'s tag (`f` itself is the one on `ab`).
    /// The default [`Split`]: see [`Mesh::face_split_with`].
    pub fn face_split(&mut self, f: FaceId, p: DVec3) -> Result<VertexId, MeshError> {
        self.face_split_with(f, p, &Split::default())
    }

    /// [`Mesh::face_split`] under `policy`: the new vertex records
    /// `policy.step`, and with `policy.lone_triangles_join_blocks` the three
    /// new edges become internal edges of basic blocks.
    pub fn face_split_with(
        &mut self,
        f: FaceId,
        p: DVec3,
        policy: &Split,
    ) -> Result<VertexId, MeshError> {
        if !self.is_face(f) {
            return Err(MeshError::new(format!(
                "face split: face {} does not exist",
                f
            )));
        }
        let [h0, h1, h2] = self.face_halfedges(f);
        let [a, b, c] = self.face_vertices(f);
        let lv = self.face_level_from_vertices([a, b, c]);
        let v = self.new_vertex(p, lv, policy.step);
        self.set_origin(v, &[a, b, c]);
        let va = self.new_edge(v, a, lv);
        let vb = self.new_edge(v, b, lv);
        let vc = self.new_edge(v, c, lv);
        let tag = self.f_tag.get(f.index());
        let f1 = self.new_face(h1, tag);
        let f2 = self.new_face(h2, tag);
        self.set_triangle(f, h0, vb.twin(), va);
        self.set_triangle(f1, h1, vc.twin(), vb);
        self.set_triangle(f2, h2, va.twin(), vc);
        self.set_outgoing(v, Some(va));
        self.face_remade(f);
        if policy.lone_triangles_join_blocks {
            for s in [va, vb, vc] {
                self.e_block.set(s.edge().index(), true);
            }
        }
        Ok(v)
    }

    /// The polygon of five or more sides whose fan of triangles holds `f`,
    /// while the fan is as the build made it: its index, and whether `f`
    /// is its first triangle (the one a polygon split starts from).
    pub(crate) fn fan_at(&self, f: FaceId) -> Option<(usize, bool)> {
        let k = *self.fan_of.get(&f.0)? as usize;
        let fan = &self.fans[k];
        let c = &fan.corners;
        let whole = fan.faces.iter().enumerate().all(|(i, &t)| {
            self.is_face(t) && {
                let mut got = self.face_vertices(t);
                let mut want = [c[0], c[i + 1], c[i + 2]];
                got.sort();
                want.sort();
                got == want
            }
        });
        whole.then_some((k, fan.faces[0] == f))
    }

    /// The centroid of fan polygon `k`'s corners.
    pub(crate) fn fan_centroid(&self, k: usize) -> DVec3 {
        let c = &self.fans[k].corners;
        c.iter().map(|&v| self.position(v)).sum::<DVec3>() / c.len() as f64
    }

    /// Polygon split: a new vertex `v` inside a polygon of five or more
    /// sides (fan `k`, see [`Mesh::fan_at`]) joined to all its corners: a
    /// face split of the fan's first triangle, then a flip of each of the
    /// fan's diagonals in turn, each of which becomes a spoke.
    ///
    /// ```text
    ///       c3 ---- c2              c3 ---- c2
    ///      /  ` .    \             /  \    /  \
    ///    c4      ` .  c1    ->   c4 --- v --- c1
    ///      \        ` |            \  /    \  /
    ///       c5 ---- c0              c5 ---- c0
    /// ```
    ///
    /// (one of the fan's diagonals drawn, c0-c3: each diagonal c0-ci
    /// flips into the spoke v-c(i+1); v-c0, v-c1 and v-c2 come from the
    /// face split of the triangle c0 c1 c2).
    ///
    /// The spokes get the level of `v`, as a face split's, and with
    /// `policy.lone_triangles_join_blocks` become internal edges of
    /// blocks, so that the polygon becomes as many quads as it has sides
    /// (Catmull-Clark's first step on a polygon). Everything is checked
    /// before the mesh changes; afterwards the polygon is no longer a fan.
    pub(crate) fn polygon_split_with(
        &mut self,
        k: usize,
        p: DVec3,
        policy: &Split,
    ) -> Result<VertexId, MeshError> {
        let fan = self.fans[k].clone();
        let first = fan.faces[0];
        if self.fan_at(first) != Some((k, true)) {
            return Err(MeshError::new(format!(
                "polygon split: the polygon of {} sides on vertices {}, {}, ... was changed \
                 since it was read",
                fan.corners.len(),
                fan.corners[0],
                fan.corners[1]
            )));
        }
        let c0 = fan.corners[0];
        let mut diagonals = Vec::with_capacity(fan.corners.len() - 3);
        for &c in &fan.corners[2..fan.corners.len() - 1] {
            let e = self
                .find_halfedge(c0, c)
                .map(|h| h.edge())
                .filter(|&e| !self.is_sharp_edge(e) && !self.is_boundary_edge(e))
                .ok_or_else(|| {
                    MeshError::new(format!(
                        "polygon split: the diagonal between vertices {c0} and {c} is missing, \
                         sharp or on the boundary"
                    ))
                })?;
            diagonals.push(e);
        }
        let v = self.face_split_with(first, p, policy)?;
        let lv = self.vertex_level(v);
        for e in diagonals {
            self.edge_flip(e)?;
            self.e_level.set(e.index(), lv);
            if policy.lone_triangles_join_blocks {
                self.e_block.set(e.index(), true);
            }
        }
        for f in &fan.faces {
            self.fan_of.remove(&f.0);
        }
        Ok(v)
    }

    /// Face weld, the inverse of face split: removes an interior vertex of
    /// valence 3 and merges its three triangles. The merged face reuses
    /// the slot, and keeps the tag, of the first face around the vertex.
    ///
    /// ```text
    ///        c                 c
    ///       /|\               / \
    ///      / | \             /   \
    ///     /  v  \    ->     /     \
    ///    / /   \ \         /       \
    ///   a---------b       a---------b
    /// ```
    pub fn face_weld(&mut self, v: VertexId) -> Result<FaceId, MeshError> {
        if !self.is_vertex(v) {
            return Err(MeshError::new(format!(
                "face weld: vertex {} does not exist",
                v
            )));
        }
        if self.is_boundary_vertex(v) {
            return Err(MeshError::new(format!(
                "face weld: vertex {} is on the boundary",
                v
            )));
        }
        let out: Vec<HalfEdgeId> = self.outgoing_halfedges(v).collect();
        if out.len() != 3 {
            return Err(MeshError::new(format!(
                "face weld: vertex {} has valence {}, but only a vertex of valence 3 can be welded into a face",
                v,
                out.len()
            )));
        }
        let outer: Vec<HalfEdgeId> = out.iter().map(|&h| self.next(h)).collect();
        let across: Vec<Option<FaceId>> = outer.iter().map(|&o| self.face(o.twin())).collect();
        if across[0].is_some() && across[0] == across[1] && across[1] == across[2] {
            return Err(MeshError::new(format!(
                "face weld: welding vertex {} would make a triangle that already exists (a doubled face)",
                v
            )));
        }
        let faces: Vec<FaceId> = out.iter().filter_map(|&h| self.face(h)).collect();
        let keep = faces[0];
        for &h in &out {
            self.delete_edge(h.edge());
        }
        for &g in &faces[1..] {
            self.delete_face(g);
        }
        self.delete_vertex(v);
        self.set_triangle(keep, outer[0], outer[1], outer[2]);
        for &o in &outer {
            let a = self.from(o);
            self.set_outgoing(a, Some(o));
            self.fix_outgoing(a);
        }
        self.face_remade(keep);
        Ok(keep)
    }

    /// Edge split: a new vertex `v` on edge `ab`, joined to the vertices
    /// opposite the edge (one for a boundary edge).
    ///
    /// ```text
    ///        c                 c
    ///       / \               /|\
    ///      /   \             / | \
    ///     a-----b    ->     a--v--b
    ///      \   /             \ | /
    ///       \ /               \|/
    ///        d                 d
    /// ```
    ///
    /// Sharpness: `av` and `vb` keep that of `ab`; the transversals are 0.
    ///
    /// Levels: `l(v) = max(l(a), l(b)) + 1`; the bisection edges `av`, `vb`
    /// get `l(ab) + 2`; the transversal edges `vc`, `vd` get `l(c) + 1` and
    /// `l(d) + 1`, and are marked transversal. Splitting the internal edge
    /// of a basic block makes the four edges at `v` internal edges of
    /// blocks (primal quadrisection, the default [`Split`]: see
    /// [`Mesh::edge_split_with`]).
    ///
    /// Tags: each of the two faces on a side of the edge is cut in two;
    /// both halves have its tag (the half at `a` keeps its slot).
    pub fn edge_split(&mut self, e: EdgeId, p: DVec3) -> Result<VertexId, MeshError> {
        self.edge_split_with(e, p, &Split::default())
    }

    /// [`Mesh::edge_split`] under `policy`: the new vertex records
    /// `policy.step`, and splitting a block's internal edge marks the next
    /// blocks as `policy.blocks` says.
    pub fn edge_split_with(
        &mut self,
        e: EdgeId,
        p: DVec3,
        policy: &Split,
    ) -> Result<VertexId, MeshError> {
        if !self.is_edge(e) {
            return Err(MeshError::new(format!(
                "edge split: edge {} does not exist",
                e
            )));
        }
        // h runs a -> b inside a face; t is its twin.
        let mut h = e.halfedge();
        if self.face(h).is_none() {
            h = h.twin();
        }
        let t = h.twin();
        let (a, b) = (self.from(h), self.to(h));
        let le = self.e_level.get(e.index());
        let was_block = self.e_block.get(e.index());
        let lv = self.v_level.get(a.index()).max(self.v_level.get(b.index())) + 1;
        let (h_bc, h_ca) = (self.next(h), self.prev(h));
        // Read before anything changes: on the boundary, `prev` turns
        // around b through its faces.
        let (t_next, t_prev) = (self.next(t), self.prev(t));
        let c = self.to(h_bc);
        let f1 = self.face(h).expect("h has a face");
        let boundary = self.face(t).is_none();
        let lone = boundary
            && policy.lone_triangles_join_blocks
            && !self.face_edges(f1).iter().any(|&x| self.is_block_edge(x));
        if !boundary && self.to(self.next(t)) == c {
            // Both faces are a, b, c: the two spokes would join v to c twice.
            return Err(MeshError::new(format!(
                "edge split: both faces of the edge between vertices {} and {} have the same third vertex {}",
                a, b, c
            )));
        }
        let v = self.new_vertex(p, lv, policy.step);
        self.set_origin(v, &[a, b]);
        // h becomes a -> v, t becomes v -> a.
        self.he_to[h.index()] = v;
        self.he_to[t.index()] = a;
        self.e_level.set(e.index(), le + 2);
        self.e_block.set(e.index(), false);
        self.e_transversal.set(e.index(), false);
        let g = self.new_edge(v, b, le + 2); // v -> b
                                             // Both halves keep the edge's sharpness (OpenSubdiv's child edges);
                                             // the transversals below are drawn across faces and stay smooth.
        self.e_sharp
            .set(g.edge().index(), self.e_sharp.get(e.index()));
        let k = self.new_edge(v, c, self.v_level.get(c.index()) + 1); // v -> c
        self.e_transversal.set(k.edge().index(), true);
        if lone {
            self.e_block.set(k.edge().index(), true);
        }
        let f2 = self.new_face(g, self.f_tag.get(f1.index()));
        self.set_triangle(f1, h, k, h_ca);
        self.set_triangle(f2, g, h_bc, k.twin());
        if boundary {
            // The boundary loop ... -> (b -> a) -> ... becomes
            // ... -> (b -> v) -> (v -> a) -> ...
            let (tp, tn) = (t_prev, t_next);
            let gt = g.twin();
            self.he_face[gt.index()] = NO_FACE;
            self.he_face[t.index()] = NO_FACE;
            self.link(tp, gt);
            self.link(gt, t);
            self.link(t, tn);
            self.set_outgoing(v, Some(t));
            if self.outgoing(b) == Some(t) {
                self.set_outgoing(b, Some(gt));
            }
        } else {
            let f3 = self.face(t).expect("interior edge");
            let (t_ad, t_db) = (t_next, t_prev);
            let d = self.to(t_ad);
            let m = self.new_edge(v, d, self.v_level.get(d.index()) + 1); // v -> d
            self.e_transversal.set(m.edge().index(), true);
            let f4 = self.new_face(g.twin(), self.f_tag.get(f3.index()));
            self.set_triangle(f3, t, t_ad, m.twin());
            self.set_triangle(f4, g.twin(), m, t_db);
            self.set_outgoing(v, Some(g));
            if self.outgoing(b) == Some(t) {
                self.set_outgoing(b, Some(g.twin()));
            }
            // Faces a-d-v and v-d-b (f4 is new).
            self.face_remade(f3);
        }
        // Faces a-v-c and v-b-c (f2 is new).
        self.face_remade(f1);
        if was_block {
            match policy.blocks {
                BlockSplit::Quadrisection | BlockSplit::Dual => {
                    // A basic block split at its centre: its four spokes
                    // become the internal edges of the four quads that
                    // splitting the block's external edges completes
                    // (primal quadrisection, paper 000, Fig. 12a).
                    // The new vertex has three or four edges.
                    let mut spokes = [None; 4];
                    for (slot, h) in spokes.iter_mut().zip(self.outgoing_halfedges(v)) {
                        *slot = Some(h.edge());
                    }
                    for s in spokes.into_iter().flatten() {
                        self.e_block.set(s.index(), true);
                    }
                }
                BlockSplit::Bisection => {
                    // The block's external edges, each now opposite the new
                    // vertex, become the internal edges of the next blocks
                    // (√2 bisection of 4-8 meshes, Fig. 8).
                    let mut faces = [None; 4];
                    for (slot, f) in faces.iter_mut().zip(self.vertex_faces(v)) {
                        *slot = Some(f);
                    }
                    for f in faces.into_iter().flatten() {
                        for h in self.face_halfedges(f) {
                            if self.from(h) != v && self.to(h) != v {
                                // Adaptive: only a complete diamond is
                                // marked; the face across may still be
                                // half of a coarser block.
                                let complete = !policy.adaptive
                                    || self
                                        .face(h.twin())
                                        .is_none_or(|g| self.refinement_edge(g) == h.edge());
                                if complete {
                                    self.e_block.set(h.edge().index(), true);
                                }
                            }
                        }
                    }
                }
            }
        }
        Ok(v)
    }

    /// Edge weld, the inverse of edge split: removes `v` (interior of
    /// valence 4, or boundary of valence 3) and joins `keep` to the
    /// neighbour opposite it, restoring the split edge with level
    /// `l(v, keep) - 2`. Tags: each merged face takes the tag of its half
    /// on `keep`'s side (`keep-c-b` that of `v-keep-c`, `b-d-keep` that
    /// of `v-d-keep` below). On the boundary the one merged face reuses
    /// the slot, and keeps the tag, of the first face counter-clockwise
    /// around `v` from its boundary gap.
    ///
    /// ```text
    ///        c                 c
    ///       /|\               / \
    ///      / | \             /   \
    ///  keep--v--b    ->  keep-----b
    ///      \ | /             \   /
    ///       \|/               \ /
    ///        d                 d
    /// ```
    pub fn edge_weld(&mut self, v: VertexId, keep: VertexId) -> Result<EdgeId, MeshError> {
        if !self.is_vertex(v) {
            return Err(MeshError::new(format!(
                "edge weld: vertex {} does not exist",
                v
            )));
        }
        let out: Vec<HalfEdgeId> = self.outgoing_halfedges(v).collect();
        let boundary = self.is_boundary_vertex(v);
        let want = if boundary { 3 } else { 4 };
        if out.len() != want {
            return Err(MeshError::new(format!(
                "edge weld: vertex {} has valence {}, but a{} vertex of valence {want} is needed",
                v,
                out.len(),
                if boundary { " boundary" } else { "n interior" }
            )));
        }
        let Some(ka) = out.iter().position(|&h| self.to(h) == keep) else {
            return Err(MeshError::new(format!(
                "edge weld: vertex {} is not a neighbour of vertex {}",
                keep, v
            )));
        };
        if boundary {
            // Outgoing order: n0 (across the first face), n1, n2 (boundary).
            if ka == 1 {
                return Err(MeshError::new(format!(
                    "edge weld: vertex {} is not on the boundary next to vertex {}",
                    keep, v
                )));
            }
            let (n0, n1, n2) = (self.to(out[0]), self.to(out[1]), self.to(out[2]));
            if self.find_halfedge(n0, n2).is_some() {
                return Err(MeshError::new(format!(
                    "edge weld: vertices {} and {} are already joined",
                    n0, n2
                )));
            }
            let _ = n1;
            let (o1, o2) = (self.next(out[0]), self.next(out[1]));
            let f = self.face(out[0]).expect("first outgoing has a face");
            let g = self.face(out[1]).expect("second outgoing has a face");
            // Reuse the edge v-n0: its face side becomes n2 -> n0, its
            // boundary side n0 -> n2.
            let x = out[0];
            let bin = x.twin(); // n0 -> v, boundary
            let bout = out[2]; // v -> n2, boundary
            let (bp, bn) = (self.prev(bin), self.next(bout));
            let le = self.e_level.get(x.edge().index()).saturating_sub(2);
            // The restored edge is as sharp as the sharper of its halves.
            let sharp = self
                .e_sharp
                .get(x.edge().index())
                .max(self.e_sharp.get(bout.edge().index()));
            self.e_sharp.set(x.edge().index(), sharp);
            self.delete_edge(out[1].edge());
            self.delete_edge(out[2].edge());
            self.delete_face(g);
            self.delete_vertex(v);
            self.he_to[x.index()] = n0;
            self.he_to[bin.index()] = n2;
            self.e_level.set(x.edge().index(), le);
            self.e_transversal.set(x.edge().index(), false);
            self.set_triangle(f, o1, o2, x);
            self.he_face[bin.index()] = NO_FACE;
            self.link(bp, bin);
            self.link(bin, bn);
            for w in [n0, n1, n2] {
                let any = if w == n0 {
                    bin
                } else if w == n1 {
                    o2
                } else {
                    x
                };
                self.set_outgoing(w, Some(any));
                self.fix_outgoing(w);
            }
            self.face_remade(f);
            return Ok(x.edge());
        }
        // Interior: rotate so that out = [v->a, v->c, v->b, v->d].
        let o: Vec<HalfEdgeId> = (0..4).map(|i| out[(ka + i) % 4]).collect();
        let (a, c, b, d) = (self.to(o[0]), self.to(o[1]), self.to(o[2]), self.to(o[3]));
        if self.find_halfedge(a, b).is_some() {
            return Err(MeshError::new(format!(
                "edge weld: vertices {} and {} are already joined",
                a, b
            )));
        }
        let _ = (c, d);
        let (o_ac, o_cb, o_bd, o_da) = (
            self.next(o[0]),
            self.next(o[1]),
            self.next(o[2]),
            self.next(o[3]),
        );
        let faces: Vec<FaceId> = o.iter().map(|&h| self.face(h).expect("interior")).collect();
        let le = self.e_level.get(o[0].edge().index()).saturating_sub(2);
        // Reuse edge v-a: x = a -> b, x' = b -> a.
        let x = o[0].twin(); // was a -> v
                             // The restored edge is as sharp as the sharper of its halves.
        let sharp = self
            .e_sharp
            .get(o[0].edge().index())
            .max(self.e_sharp.get(o[2].edge().index()));
        self.e_sharp.set(x.edge().index(), sharp);
        self.delete_edge(o[1].edge());
        self.delete_edge(o[2].edge());
        self.delete_edge(o[3].edge());
        self.delete_face(faces[2]);
        self.delete_face(faces[3]);
        self.delete_vertex(v);
        self.he_to[x.index()] = b;
        self.he_to[x.twin().index()] = a;
        self.e_level.set(x.edge().index(), le);
        self.e_transversal.set(x.edge().index(), false);
        self.set_triangle(faces[0], o_ac, o_cb, x.twin());
        self.set_triangle(faces[1], o_bd, o_da, x);
        // faces[1] was v-c-b; it is now b-d-a, whose half on a's side was
        // v-d-a, faces[3].
        self.f_tag
            .set(faces[1].index(), self.f_tag.get(faces[3].index()));
        for (w, h) in [(a, x), (b, x.twin()), (c, o_cb), (d, o_da)] {
            self.set_outgoing(w, Some(h));
            self.fix_outgoing(w);
        }
        for f in [faces[0], faces[1]] {
            self.face_remade(f);
        }
        Ok(x.edge())
    }

    /// Edge flip: the diagonal of the quad around an interior edge turns.
    ///
    /// ```text
    ///        c                 c
    ///       / \               /|\
    ///      /   \             / | \
    ///     a-----b    ->     a  |  b
    ///      \   /             \ | /
    ///       \ /               \|/
    ///        d                 d
    /// ```
    ///
    /// Level: the flipped edge gets its parent's level plus one. Refused for
    /// a boundary edge, for a sharp edge (a crease stays where it is, so a
    /// grammar's flips must not match one) and when `c` and `d` are
    /// already joined. The flipped edge, never sharp, stays smooth.
    ///
    /// Tags: the faces keep their slots and their tags. The face that was
    /// `a-b-c` (the side of the edge's first half-edge running `a -> b`)
    /// becomes `d-c-a` and keeps its tag; the face that was `b-a-d`
    /// becomes `c-d-b` and keeps its own. Each new face is half of each
    /// old one, so when the two old faces carry different tags (two
    /// shapes of a welded group) which new face gets which tag is a
    /// choice: the one that keeps corner `a` (resp. `b`) and the old
    /// face's edge `c-a` (resp. `d-b`).
    pub fn edge_flip(&mut self, e: EdgeId) -> Result<(), MeshError> {
        if !self.is_edge(e) {
            return Err(MeshError::new(format!(
                "edge flip: edge {} does not exist",
                e
            )));
        }
        if self.is_boundary_edge(e) {
            let (a, b) = self.edge_vertices(e);
            return Err(MeshError::new(format!(
                "edge flip: the edge between vertices {a} and {b} is on the boundary and cannot be flipped"
            )));
        }
        if self.is_sharp_edge(e) {
            let (a, b) = self.edge_vertices(e);
            return Err(MeshError::new(format!(
                "edge flip: the edge between vertices {a} and {b} is sharp (sharpness {}) and \
                 cannot be flipped: a flip would move the crease off its curve",
                self.e_sharp.get(e.index())
            )));
        }
        let h = e.halfedge();
        let t = h.twin();
        let (a, b) = (self.from(h), self.to(h));
        let (h_bc, h_ca) = (self.next(h), self.prev(h));
        let (t_ad, t_db) = (self.next(t), self.prev(t));
        let (c, d) = (self.to(h_bc), self.to(t_ad));
        if c == d || self.find_halfedge(c, d).is_some() {
            return Err(MeshError::new(format!(
                "edge flip: flipping the edge between vertices {} and {} would duplicate the edge between vertices {} and {}",
                a, b, c, d
            )));
        }
        let (f1, f2) = (
            self.face(h).expect("interior"),
            self.face(t).expect("interior"),
        );
        self.he_to[h.index()] = c; // d -> c
        self.he_to[t.index()] = d; // c -> d
        self.set_triangle(f1, t_ad, h, h_ca);
        self.set_triangle(f2, t_db, h_bc, t);
        if self.outgoing(a) == Some(h) {
            self.set_outgoing(a, Some(t_ad));
        }
        if self.outgoing(b) == Some(t) {
            self.set_outgoing(b, Some(h_bc));
        }
        self.e_level.set(e.index(), self.e_level.get(e.index()) + 1);
        self.e_block.set(e.index(), false);
        self.e_transversal.set(e.index(), false);
        // The faces are now d-c-a and c-d-b.
        self.face_remade(f1);
        self.face_remade(f2);
        Ok(())
    }
}
