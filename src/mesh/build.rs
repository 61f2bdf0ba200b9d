//! From a polygon soup to a half-edge mesh, and back.
//!
//! Triangles are taken as they are. A quad becomes a basic block: two
//! triangles split along its first diagonal (vertices 0 and 2), the
//! diagonal recorded as the block's internal edge. A polygon of more than
//! four sides is triangulated as a fan from its first vertex. When the mesh
//! has quads, its levels follow paper 000, §7 for tri-quad meshes: internal
//! (diagonal) edges 0, the polygons' own edges 1; a triangle mesh has every
//! edge at level 0. Vertices start at level 0, faces one above their
//! vertices.

use std::collections::HashMap;

use super::halfedge::{EdgeId, FaceId, HalfEdgeId, Mesh, MeshError, VertexId};
use super::soup::PolygonSoup;

fn at_line(soup: &PolygonSoup, face: usize) -> String {
    match soup.face_line(face) {
        Some(l) => format!(" (line {l})"),
        None => String::new(),
    }
}

fn vertex_at_line(soup: &PolygonSoup, v: usize) -> String {
    match soup.vertex_line(v) {
        Some(l) => format!(" (line {l})"),
        None => String::new(),
    }
}

impl Mesh {
    /// Builds a mesh, refusing anything that is not an oriented 2-manifold:
    /// out-of-range indices, non-finite coordinates, degenerate faces, edges
    /// with three or more faces, inconsistent orientation, and bow-tie
    /// vertices. Each message names the face or vertex and its line.
    pub fn from_soup(soup: &PolygonSoup) -> Result<Mesh, MeshError> {
        let nv = soup.positions.len();
        for (i, p) in soup.positions.iter().enumerate() {
            if !p.is_finite() {
                return Err(MeshError::new(format!(
                    "vertex {}{} has a non-finite coordinate",
                    i + 1,
                    vertex_at_line(soup, i)
                )));
            }
        }
        if soup.faces.is_empty() {
            return Err(MeshError::new("the mesh has no faces"));
        }
        let quads = soup.faces.iter().any(|f| f.len() == 4);
        let outer_level = if quads { 1 } else { 0 };
        // (triangle, source face, which of its edges are diagonals)
        let mut tris: Vec<([u32; 3], usize, [bool; 3])> = Vec::with_capacity(soup.faces.len() * 2);
        for (fi, f) in soup.faces.iter().enumerate() {
            if f.len() < 3 {
                return Err(MeshError::new(format!(
                    "face {}{} has {} vertices; a face needs at least 3",
                    fi + 1,
                    at_line(soup, fi),
                    f.len()
                )));
            }
            for (k, &v) in f.iter().enumerate() {
                if v as usize >= nv {
                    return Err(MeshError::new(format!(
                        "face {}{} refers to vertex {}, but there are only {nv} vertices",
                        fi + 1,
                        at_line(soup, fi),
                        v as usize + 1
                    )));
                }
                if f[..k].contains(&v) {
                    return Err(MeshError::new(format!(
                        "face {}{} is degenerate: it uses vertex {} twice",
                        fi + 1,
                        at_line(soup, fi),
                        v as usize + 1
                    )));
                }
            }
            // A face of zero area.
            let p = |i: usize| soup.positions[f[i] as usize];
            let mut area = glam::DVec3::ZERO;
            for i in 1..f.len() - 1 {
                area += (p(i) - p(0)).cross(p(i + 1) - p(0));
            }
            if area.length_squared() == 0.0 {
                return Err(MeshError::new(format!(
                    "face {}{} is degenerate: it has zero area",
                    fi + 1,
                    at_line(soup, fi)
                )));
            }
            for i in 1..f.len() - 1 {
                // Fan from vertex 0: edge (0, i) is internal unless i == 1,
                // edge (i + 1, 0) unless it is the last one.
                let first = i == 1;
                let last = i + 1 == f.len() - 1;
                tris.push(([f[0], f[i], f[i + 1]], fi, [!first, false, !last]));
            }
        }
        // Two triangles on the same three vertices close a pocket that no
        // stellar operator can keep simple (a split would join two vertices
        // twice).
        let mut seen: HashMap<[u32; 3], usize> = HashMap::with_capacity(tris.len());
        for (tri, fi, _) in &tris {
            let mut key = *tri;
            key.sort_unstable();
            if let Some(&other) = seen.get(&key) {
                if other != *fi {
                    return Err(MeshError::new(format!(
                        "faces {}{} and {}{} share the same three vertices {}, {} and {}",
                        other + 1,
                        at_line(soup, other),
                        fi + 1,
                        at_line(soup, *fi),
                        key[0] + 1,
                        key[1] + 1,
                        key[2] + 1
                    )));
                }
            }
            seen.insert(key, *fi);
        }
        let mut m = Mesh::default();
        for p in &soup.positions {
            m.new_vertex(*p, 0);
        }
        let mut edges: HashMap<(u32, u32), HalfEdgeId> = HashMap::with_capacity(tris.len() * 2);
        let mut face_of_source: Vec<usize> = Vec::with_capacity(tris.len());
        for (tri, fi, diag) in &tris {
            let mut hs = [HalfEdgeId(0); 3];
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                let key = (a.min(b), a.max(b));
                let h = match edges.get(&key) {
                    None => {
                        let level = if diag[k] { 0 } else { outer_level };
                        let h = m.new_edge(VertexId(a), VertexId(b), level);
                        m.e_block[h.edge().index()] = diag[k] && soup.faces[*fi].len() == 4;
                        edges.insert(key, h);
                        h
                    }
                    Some(&h0) => {
                        let h = if m.to(h0) == VertexId(b) {
                            h0
                        } else {
                            h0.twin()
                        };
                        if m.face(h).is_some() {
                            let other = m.face(h).map(|f| face_of_source[f.index()]).unwrap_or(0);
                            let why = if m.face(h.twin()).is_some() {
                                "is shared by three or more faces (non-manifold)"
                            } else {
                                "is used in the same direction by two faces (inconsistent orientation)"
                            };
                            return Err(MeshError::new(format!(
                                "the edge between vertices {} and {} of face {}{} {why}; the other face is face {}{}",
                                a + 1,
                                b + 1,
                                fi + 1,
                                at_line(soup, *fi),
                                other + 1,
                                at_line(soup, other)
                            )));
                        }
                        h
                    }
                };
                hs[k] = h;
            }
            let level = 1;
            let f = m.new_face(hs[0], level);
            face_of_source.push(*fi);
            m.set_triangle(f, hs[0], hs[1], hs[2]);
            for (k, h) in hs.iter().enumerate() {
                m.v_out[tri[k] as usize] = Some(*h);
            }
        }
        // Link the boundary: each boundary half-edge continues with the
        // boundary half-edge leaving its end vertex; two of those make a
        // bow-tie.
        let mut boundary_out: Vec<Option<HalfEdgeId>> = vec![None; nv];
        for h in (0..m.he_to.len() as u32).map(HalfEdgeId) {
            if m.face(h).is_none() {
                let v = m.from(h);
                if boundary_out[v.index()].is_some() {
                    return Err(MeshError::new(format!(
                        "vertex {}{} is a bow-tie: two separate fans of faces meet there (non-manifold)",
                        v.index() + 1,
                        vertex_at_line(soup, v.index())
                    )));
                }
                boundary_out[v.index()] = Some(h);
            }
        }
        for h in (0..m.he_to.len() as u32).map(HalfEdgeId) {
            if m.face(h).is_none() {
                let n = boundary_out[m.to(h).index()]
                    .expect("a boundary edge ends at a boundary vertex");
                m.link(h, n);
            }
        }
        for (v, b) in boundary_out.iter().enumerate() {
            if let Some(b) = b {
                m.v_out[v] = Some(*b);
            }
        }
        // An interior vertex whose faces form two or more cycles.
        let mut degree = vec![0usize; nv];
        for h in (0..m.he_to.len() as u32).map(HalfEdgeId) {
            degree[m.from(h).index()] += 1;
        }
        for (v, &deg) in degree.iter().enumerate() {
            let walked = m.outgoing_halfedges(VertexId(v as u32)).count();
            if walked != deg {
                return Err(MeshError::new(format!(
                    "vertex {}{} is non-manifold: its faces form more than one fan",
                    v + 1,
                    vertex_at_line(soup, v)
                )));
            }
        }
        for f in 0..m.f_alive.len() {
            let vs = m.face_vertices(FaceId(f as u32));
            m.f_level[f] = m.face_level_from_vertices(vs);
        }
        Ok(m)
    }

    /// The mesh as triangles, with dead slots removed.
    pub fn to_soup(&self) -> PolygonSoup {
        self.soup_with(|_| false)
    }

    /// Reads the mesh as plain triangles: no basic blocks, and, on a base
    /// mesh (every vertex at level 0), every edge at level 0, as if each
    /// quad had been given as two triangles. Schemes for triangle meshes
    /// run on quad input this way.
    pub fn forget_blocks(&mut self) {
        let base = self.vertices().all(|v| self.vertex_level(v) == 0);
        let edges: Vec<EdgeId> = self.edges().collect();
        for e in edges {
            self.e_block[e.index()] = false;
            if base {
                self.e_level[e.index()] = 0;
            }
        }
    }

    /// The first face that is not half of a basic block, if any: a
    /// triangle of the input rather than half of a quad.
    pub fn face_outside_blocks(&self) -> Option<FaceId> {
        self.faces()
            .find(|&f| !self.face_edges(f).iter().any(|&e| self.is_block_edge(e)))
    }

    /// The mesh with basic blocks merged back into quads.
    pub fn to_quad_soup(&self) -> PolygonSoup {
        self.soup_with(|e| self.is_block_edge(e))
    }

    fn soup_with(&self, merge: impl Fn(EdgeId) -> bool) -> PolygonSoup {
        let mut index = vec![u32::MAX; self.v_alive.len()];
        let mut soup = PolygonSoup::default();
        for v in self.vertices() {
            index[v.index()] = soup.positions.len() as u32;
            soup.positions.push(self.position(v));
        }
        let mut done = vec![false; self.f_alive.len()];
        for f in self.faces() {
            if done[f.index()] {
                continue;
            }
            done[f.index()] = true;
            let hs = self.face_halfedges(f);
            let merged = hs.iter().find_map(|&h| {
                let g = self.face(h.twin())?;
                (merge(h.edge()) && !done[g.index()]).then_some((h, g))
            });
            let verts: Vec<u32> = match merged {
                Some((h, g)) => {
                    done[g.index()] = true;
                    // Quad: from(h), opposite in g, to(h), opposite in f.
                    let opp_g = self.to(self.next(h.twin()));
                    let opp_f = self.to(self.next(h));
                    [self.from(h), opp_g, self.to(h), opp_f]
                        .iter()
                        .map(|v| index[v.index()])
                        .collect()
                }
                None => self
                    .face_vertices(f)
                    .iter()
                    .map(|v| index[v.index()])
                    .collect(),
            };
            soup.faces.push(verts);
        }
        soup
    }
}
