//! From a polygon soup to a half-edge mesh, and back.
//!
//! Triangles are taken as they are. A quad becomes a basic block: two
//! triangles split along its first diagonal (vertices 0 and 2), the
//! diagonal recorded as the block's internal edge. A polygon of more than
//! four sides is triangulated as a fan from its first vertex, and the first
//! such polygon is recorded ([`Mesh::fanned_polygon`]). When the mesh
//! has quads, its levels follow paper 000, §7 for tri-quad meshes: internal
//! (diagonal) edges 0, the polygons' own edges 1; a triangle mesh has every
//! edge at level 0. Vertices start at level 0, faces one above their
//! vertices.

use std::collections::HashMap;

use super::halfedge::{EdgeId, FaceId, FannedPolygon, HalfEdgeId, Mesh, MeshError, VertexId};
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
    /// Polygons of more than four sides are fanned into triangles, and the
    /// first of them is recorded as [`Mesh::fanned_polygon`].
    pub fn from_soup(soup: &PolygonSoup) -> Result<Mesh, MeshError> {
        Mesh::build(soup, None)
    }

    /// [`Mesh::from_soup`], with a tag for each face of the soup: every
    /// triangle made from face `i` (both halves of a quad, a polygon's
    /// fan) gets `tags[i]`, and the stellar operators hand it down to the
    /// faces cut from them ([`Mesh::tag`]).
    pub fn from_soup_tagged(soup: &PolygonSoup, tags: &[u32]) -> Result<Mesh, MeshError> {
        if tags.len() != soup.faces.len() {
            return Err(MeshError::new(format!(
                "{} tags were given for {} faces",
                tags.len(),
                soup.faces.len()
            )));
        }
        Mesh::build(soup, Some(tags))
    }

    /// The faces [`Mesh::from_soup`] makes from each face of `soup`: face
    /// `i` of `n` sides becomes the `n - 2` faces with ids in the `i`-th
    /// range (a triangle itself, a quad's two block triangles, a polygon's
    /// fan), since the mesh's faces are made in the soup's order.
    pub(crate) fn soup_face_ranges(soup: &PolygonSoup) -> Vec<std::ops::Range<u32>> {
        let mut next = 0u32;
        soup.faces
            .iter()
            .map(|f| {
                let start = next;
                next += f.len().saturating_sub(2) as u32;
                start..next
            })
            .collect()
    }

    fn build(soup: &PolygonSoup, tags: Option<&[u32]>) -> Result<Mesh, MeshError> {
        let nv = soup.positions.len();
        for (i, p) in soup.positions.iter().enumerate() {
            if !p.is_finite() {
                return Err(MeshError::new(format!(
                    "vertex {}{} has a non-finite coordinate",
                    i + 1,
                    vertex_at_line(soup, i)
                ))
                .at(soup.vertex_line(i)));
            }
        }
        if soup.faces.is_empty() {
            return Err(MeshError::new("the mesh has no faces"));
        }
        let fanned = soup
            .faces
            .iter()
            .position(|f| f.len() > 4)
            .map(|fi| FannedPolygon {
                face: fi,
                sides: soup.faces[fi].len(),
                line: soup.face_line(fi),
            });
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
                ))
                .at(soup.face_line(fi)));
            }
            if let Some(k) = f.iter().position(|&v| v as usize >= nv) {
                return Err(MeshError::new(format!(
                    "face {}{} refers to vertex {}, but there are only {nv} vertices",
                    fi + 1,
                    at_line(soup, fi),
                    f[k] as usize + 1
                ))
                .at(soup.face_line(fi)));
            }
            if let Some(k) = super::soup::first_repeat(f) {
                return Err(MeshError::new(format!(
                    "face {}{} is degenerate: it uses vertex {} twice",
                    fi + 1,
                    at_line(soup, fi),
                    f[k] as usize + 1
                ))
                .at(soup.face_line(fi)));
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
                ))
                .at(soup.face_line(fi)));
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
                    ))
                    .at(soup.face_line(*fi)));
                }
            }
            seen.insert(key, *fi);
        }
        let mut m = Mesh {
            fanned,
            ..Mesh::default()
        };
        for p in &soup.positions {
            m.new_vertex(*p, 0, 0);
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
                            ))
                            .at(soup.face_line(*fi)));
                        }
                        h
                    }
                };
                hs[k] = h;
            }
            let level = 1;
            let f = m.new_face(hs[0], level, tags.map_or(0, |t| t[*fi]));
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
                    ))
                    .at(soup.vertex_line(v.index())));
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
                ))
                .at(soup.vertex_line(v)));
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
        self.soup_with(|_| false).0
    }

    /// [`Mesh::to_soup`] and the tag of each of its faces.
    pub fn to_soup_tagged(&self) -> (PolygonSoup, Vec<u32>) {
        let (soup, tags, _) = self.soup_with(|_| false);
        (soup, tags)
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

    /// The mesh with basic blocks merged back into polygons: quads for
    /// primal blocks, and for dual blocks the polygon around each centre.
    pub fn to_quad_soup(&self) -> PolygonSoup {
        self.soup_with(|e| self.is_block_edge(e)).0
    }

    /// [`Mesh::to_quad_soup`] and the tag of each of its faces. A basic
    /// block whose triangles have different tags (a √2 bisection's block
    /// across two tagged quads) stays two triangles, so that every
    /// polygon has the one tag of all its triangles.
    pub fn to_quad_soup_tagged(&self) -> (PolygonSoup, Vec<u32>) {
        let (soup, tags, _) = self.quad_soup_tagged_with_vertices();
        (soup, tags)
    }

    /// [`Mesh::to_quad_soup_tagged`], and the mesh vertex of each soup
    /// vertex.
    pub(crate) fn quad_soup_tagged_with_vertices(&self) -> (PolygonSoup, Vec<u32>, Vec<VertexId>) {
        self.soup_with(|e| {
            self.is_block_edge(e)
                && match self.edge_faces(e) {
                    [Some(f), Some(g)] => self.tag(f) == self.tag(g),
                    _ => true,
                }
        })
    }

    /// The mesh with the faces on either side of each `merge` edge joined
    /// into polygons. A region of faces joined this way becomes one polygon
    /// when its border is a single loop through distinct vertices (a
    /// basic block's two triangles, or a dual block's fan around its
    /// centre); otherwise its triangles are kept. Vertices inside a
    /// polygon (a dual block's centre) are left out. Also gives each
    /// polygon's tag (that of its first triangle) and each soup vertex's
    /// mesh vertex.
    fn soup_with(&self, merge: impl Fn(EdgeId) -> bool) -> (PolygonSoup, Vec<u32>, Vec<VertexId>) {
        // Regions by union-find over the faces.
        let mut parent: Vec<u32> = (0..self.f_alive.len() as u32).collect();
        fn root(parent: &mut [u32], mut f: u32) -> u32 {
            while parent[f as usize] != f {
                let g = parent[parent[f as usize] as usize];
                parent[f as usize] = g;
                f = g;
            }
            f
        }
        for e in self.edges() {
            if !merge(e) {
                continue;
            }
            let [Some(f), Some(g)] = self.edge_faces(e) else {
                continue;
            };
            let (a, b) = (root(&mut parent, f.0), root(&mut parent, g.0));
            if a != b {
                parent[a.max(b) as usize] = a.min(b);
            }
        }
        let merged_any = parent.iter().enumerate().any(|(i, &p)| p as usize != i);
        if !merged_any {
            let mut index = vec![u32::MAX; self.v_alive.len()];
            let mut soup = PolygonSoup::default();
            let mut verts = Vec::with_capacity(self.vertex_count());
            for v in self.vertices() {
                index[v.index()] = soup.positions.len() as u32;
                soup.positions.push(self.position(v));
                verts.push(v);
            }
            soup.faces = self
                .faces()
                .map(|f| {
                    self.face_vertices(f)
                        .iter()
                        .map(|v| index[v.index()])
                        .collect()
                })
                .collect();
            let tags = self.faces().map(|f| self.tag(f)).collect();
            return (soup, tags, verts);
        }
        let region = |parent: &mut [u32], h: HalfEdgeId| self.face(h).map(|f| root(parent, f.0));
        let mut polygons: Vec<Vec<VertexId>> = Vec::new();
        let mut tags: Vec<u32> = Vec::new();
        let mut done = vec![false; self.f_alive.len()];
        let mut members: Vec<Vec<FaceId>> = vec![Vec::new(); self.f_alive.len()];
        for f in self.faces() {
            members[root(&mut parent, f.0) as usize].push(f);
        }
        for f in self.faces() {
            let r = root(&mut parent, f.0);
            if done[r as usize] {
                continue;
            }
            done[r as usize] = true;
            let faces = &members[r as usize];
            if faces.len() == 1 {
                polygons.push(self.face_vertices(f).to_vec());
                tags.push(self.tag(f));
                continue;
            }
            // The region's border: half-edges whose twin lies outside it.
            let border: Vec<HalfEdgeId> = faces
                .iter()
                .flat_map(|&g| self.face_halfedges(g))
                .filter(|&h| region(&mut parent, h.twin()) != Some(r))
                .collect();
            // Only a basic block (two triangles) or a dual block (a fan
            // whose centre is on every face and not on the border) becomes
            // one polygon; any other region keeps its triangles.
            let block_shape = !border.is_empty()
                && (faces.len() == 2 || {
                    let first = self.face_vertices(faces[0]);
                    first.iter().any(|&c| {
                        faces.iter().all(|&g| self.face_vertices(g).contains(&c))
                            && border.iter().all(|&h| self.from(h) != c && self.to(h) != c)
                    })
                });
            if !block_shape {
                polygons.extend(faces.iter().map(|&g| self.face_vertices(g).to_vec()));
                tags.extend(faces.iter().map(|&g| self.tag(g)));
                continue;
            }
            let mut loop_vs = Vec::with_capacity(border.len());
            let mut h = border[0];
            let mut ok = true;
            for _ in 0..border.len() {
                loop_vs.push(self.from(h));
                // The next border half-edge turns about `to(h)` inside
                // the region.
                let mut g = self.next(h);
                let mut turns = 0;
                while region(&mut parent, g.twin()) == Some(r) {
                    g = self.next(g.twin());
                    turns += 1;
                    if turns > faces.len() {
                        ok = false;
                        break;
                    }
                }
                h = g;
                if !ok {
                    break;
                }
            }
            let mut sorted = loop_vs.clone();
            sorted.sort_unstable();
            sorted.dedup();
            if ok && h == border[0] && sorted.len() == border.len() {
                polygons.push(loop_vs);
                tags.push(self.tag(faces[0]));
            } else {
                polygons.extend(faces.iter().map(|&g| self.face_vertices(g).to_vec()));
                tags.extend(faces.iter().map(|&g| self.tag(g)));
            }
        }
        // Vertices inside a merged polygon are left out; all others stay.
        let mut index = vec![0u32; self.v_alive.len()];
        for f in self.faces() {
            for v in self.face_vertices(f) {
                index[v.index()] = u32::MAX;
            }
        }
        for p in &polygons {
            for v in p {
                index[v.index()] = 0;
            }
        }
        let mut soup = PolygonSoup::default();
        let mut verts = Vec::new();
        for v in self.vertices() {
            if index[v.index()] == 0 {
                index[v.index()] = soup.positions.len() as u32;
                soup.positions.push(self.position(v));
                verts.push(v);
            }
        }
        soup.faces = polygons
            .into_iter()
            .map(|p| p.iter().map(|v| index[v.index()]).collect())
            .collect();
        (soup, tags, verts)
    }
}
