//! Every invariant of the half-edge mesh, checked.

use std::collections::HashSet;

use super::halfedge::{HalfEdgeId, Mesh, MeshError};

impl Mesh {
    /// Checks the invariants: twins, next/prev cycles, faces of three
    /// half-edges, face and vertex references, boundary loops, one fan per
    /// vertex (manifoldness), no doubled edges, orientation (each edge's two
    /// half-edges run in opposite directions). Names the first element that
    /// breaks one.
    pub fn validate(&self) -> Result<(), MeshError> {
        let bad = |m: String| Err(MeshError::new(m));
        for e in self.edges() {
            let h = e.halfedge();
            if self.to(h) == self.to(h.twin()) {
                return bad(format!("edge {} is a loop at vertex {}", e.0, self.to(h).0));
            }
            for h in [h, h.twin()] {
                let (n, p) = (self.next(h), self.prev(h));
                if self.prev(n) != h || self.next(p) != h {
                    return bad(format!("half-edge {}: next and prev do not agree", h.0));
                }
                if !self.is_edge(n.edge()) || !self.is_edge(p.edge()) {
                    return bad(format!("half-edge {} links to a removed edge", h.0));
                }
                if self.from(n) != self.to(h) {
                    return bad(format!(
                        "half-edge {}: its next does not start where it ends",
                        h.0
                    ));
                }
                match self.face(h) {
                    Some(f) => {
                        if !self.is_face(f) {
                            return bad(format!(
                                "half-edge {} belongs to removed face {}",
                                h.0, f.0
                            ));
                        }
                        if self.next(self.next(self.next(h))) != h {
                            return bad(format!("face {} is not a triangle", f.0));
                        }
                        if self.face(n) != Some(f) {
                            return bad(format!(
                                "face {}: its half-edges disagree on their face",
                                f.0
                            ));
                        }
                    }
                    None => {
                        if self.face(n).is_some() {
                            return bad(format!(
                                "boundary half-edge {} continues into a face",
                                h.0
                            ));
                        }
                    }
                }
            }
            if self.face(h).is_some() && self.face(h) == self.face(h.twin()) {
                return bad(format!("edge {} has the same face on both sides", e.0));
            }
        }
        for f in self.faces() {
            let h = self.face_halfedge(f);
            if !self.is_edge(h.edge()) || self.face(h) != Some(f) {
                return bad(format!(
                    "face {} points at a half-edge that is not its own",
                    f.0
                ));
            }
            let vs = self.face_vertices(f);
            if vs[0] == vs[1] || vs[1] == vs[2] || vs[0] == vs[2] {
                return bad(format!("face {} is degenerate", f.0));
            }
        }
        let mut degree = vec![0usize; self.v_alive.len()];
        let mut pairs = HashSet::new();
        for e in self.edges() {
            let (a, b) = self.edge_vertices(e);
            if !self.is_vertex(a) || !self.is_vertex(b) {
                return bad(format!("edge {} ends at a removed vertex", e.0));
            }
            degree[a.index()] += 1;
            degree[b.index()] += 1;
            if !pairs.insert((a.min(b), a.max(b))) {
                return bad(format!(
                    "vertices {} and {} are joined by two edges",
                    a.0, b.0
                ));
            }
        }
        for v in self.vertices() {
            match self.outgoing(v) {
                None => {
                    if degree[v.index()] != 0 {
                        return bad(format!(
                            "vertex {} has edges but no outgoing half-edge",
                            v.0
                        ));
                    }
                }
                Some(h) => {
                    if !self.is_edge(h.edge()) || self.from(h) != v {
                        return bad(format!(
                            "vertex {}: its outgoing half-edge does not leave it",
                            v.0
                        ));
                    }
                    // Walked here with `prev`, which takes any half-edge,
                    // and at most one step past the vertex's degree: the
                    // walkers assume what is checked here.
                    let (walked, boundary) = self.walk_checked(h, degree[v.index()] + 1);
                    if boundary && !self.is_boundary_halfedge(h) {
                        return bad(format!(
                            "vertex {} is on the boundary but does not point at its boundary half-edge",
                            v.0
                        ));
                    }
                    if walked != degree[v.index()] {
                        return bad(format!(
                            "vertex {} is non-manifold: a walk around it meets {walked} of its {} edges",
                            v.0,
                            degree[v.index()]
                        ));
                    }
                }
            }
        }
        Ok(())
    }

    /// Walks counter-clockwise around the tail of `out` (from the first
    /// half-edge after the boundary gap when `out` is a boundary one), at
    /// most `limit` steps: how many half-edges it meets, and whether one
    /// is on the boundary.
    fn walk_checked(&self, out: HalfEdgeId, limit: usize) -> (usize, bool) {
        let start = if self.is_boundary_halfedge(out) {
            self.prev(out).twin()
        } else {
            out
        };
        let (mut h, mut n, mut boundary) = (start, 0, false);
        loop {
            n += 1;
            boundary |= self.is_boundary_halfedge(h);
            h = self.prev(h).twin();
            if h == start || n >= limit {
                return (n, boundary);
            }
        }
    }

    /// A description of the mesh that ignores how elements are numbered:
    /// positions and levels of vertices, faces as rotated vertex triples,
    /// edges with their levels, all in terms of the original vertex ids.
    /// Two meshes with equal canonical forms are the same mesh.
    pub fn canonical(&self) -> Canonical {
        let mut faces: Vec<[u32; 3]> = self
            .faces()
            .map(|f| {
                let v = self.face_vertices(f).map(|v| v.0);
                let k = (0..3).min_by_key(|&i| v[i]).unwrap_or(0);
                [v[k], v[(k + 1) % 3], v[(k + 2) % 3]]
            })
            .collect();
        faces.sort_unstable();
        let mut edges: Vec<(u32, u32, u32)> = self
            .edges()
            .map(|e| {
                let (a, b) = self.edge_vertices(e);
                (a.0.min(b.0), a.0.max(b.0), self.edge_level(e))
            })
            .collect();
        edges.sort_unstable();
        let vertices = self
            .vertices()
            .map(|v| {
                (
                    v.0,
                    self.position(v).to_array().map(f64::to_bits),
                    self.vertex_level(v),
                )
            })
            .collect();
        Canonical {
            vertices,
            faces,
            edges,
        }
    }
}

/// See [`Mesh::canonical`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Canonical {
    pub vertices: Vec<(u32, [u64; 3], u32)>,
    pub faces: Vec<[u32; 3]>,
    pub edges: Vec<(u32, u32, u32)>,
}
