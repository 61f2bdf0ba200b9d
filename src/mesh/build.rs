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

use super::halfedge::{
    Bits, Column, EdgeId, FaceId, FannedPolygon, HalfEdgeId, Mesh, MeshError, Narrow, VertexId,
};
use super::soup::{Faces, PolygonSoup};

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

/// A counting sort of items `0..n` by a key below `nv`: the bounds of
/// each key's bucket (`nv + 1` of them) and the items' values, bucket by
/// bucket, in item order within each.
fn bucket<T: Copy + Default>(
    nv: usize,
    n: usize,
    item: impl Fn(usize) -> (u32, T),
) -> (Vec<u32>, Vec<T>) {
    let mut start = vec![0u32; nv + 1];
    for i in 0..n {
        start[item(i).0 as usize + 1] += 1;
    }
    for k in 0..nv {
        start[k + 1] += start[k];
    }
    let mut fill = start.clone();
    let mut out = vec![T::default(); n];
    for i in 0..n {
        let (k, v) = item(i);
        out[fill[k as usize] as usize] = v;
        fill[k as usize] += 1;
    }
    (start, out)
}

impl Mesh {
    /// The live vertices in order, numbered from 0: each slot's number
    /// (`u32::MAX` for a dead slot), their positions and their ids.
    fn live_vertices(&self) -> (Vec<u32>, Vec<glam::DVec3>, Vec<VertexId>) {
        let mut index = vec![u32::MAX; self.v_alive.len()];
        let mut positions = Vec::with_capacity(self.vertex_count());
        let mut verts = Vec::with_capacity(self.vertex_count());
        for v in self.vertices() {
            index[v.index()] = positions.len() as u32;
            positions.push(self.position(v));
            verts.push(v);
        }
        (index, positions, verts)
    }

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
        let mut m = Mesh::build_triangles(soup, tags)?;
        m.record_fans(soup);
        Ok(m)
    }

    /// Records each polygon of five or more sides of `soup` as the fan of
    /// triangles the build made of it ([`Mesh::soup_face_ranges`]), for a
    /// face split that takes the polygon whole.
    fn record_fans(&mut self, soup: &PolygonSoup) {
        for (fi, range) in Mesh::soup_face_ranges(soup).into_iter().enumerate() {
            let corners = &soup.faces[fi];
            if corners.len() < 5 {
                continue;
            }
            let k = self.fans.len() as u32;
            for f in range.clone() {
                self.fan_of.insert(f, k);
            }
            self.fans.push(super::halfedge::Fan {
                corners: corners.iter().map(|&c| VertexId(c)).collect(),
                faces: range.map(FaceId).collect(),
            });
        }
    }

    fn build_triangles(soup: &PolygonSoup, tags: Option<&[u32]>) -> Result<Mesh, MeshError> {
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
        // The triangles, flat: corner `3t + k` is vertex `k` of triangle
        // `t`, and the half-edge leaving it runs to corner `3t + (k+1) % 3`.
        // Each triangle keeps its source face and which of its edges are
        // diagonals (internal to a quad or a fan).
        let mut corner: Vec<u32> = Vec::with_capacity(soup.faces.len() * 6);
        let mut source: Vec<u32> = Vec::with_capacity(soup.faces.len() * 2);
        let mut diagonal: Vec<[bool; 3]> = Vec::with_capacity(soup.faces.len() * 2);
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
                corner.extend([f[0], f[i], f[i + 1]]);
                source.push(fi as u32);
                diagonal.push([!first, false, !last]);
            }
        }
        let nt = source.len();
        // Half-edge ids are u32 and there are at most two per corner.
        if corner.len() > (u32::MAX / 2) as usize {
            return Err(MeshError::new(format!(
                "the mesh has {nt} triangles; at most {} can be built",
                u32::MAX / 6
            )));
        }
        let src = |t: usize| source[t] as usize;
        let head = |c: usize| corner[c - c % 3 + (c % 3 + 1) % 3];

        // Two triangles on the same three vertices close a pocket that no
        // stellar operator can keep simple (a split would join two vertices
        // twice). Triangles are bucketed by their smallest vertex and
        // sorted within a bucket by the other two, then by number; the
        // triangle reported is the first that repeats an earlier one.
        let sorted = |t: usize| {
            let mut key = [corner[3 * t], corner[3 * t + 1], corner[3 * t + 2]];
            key.sort_unstable();
            key
        };
        let (start, mut slot) = bucket(nv, nt, |t| {
            let [lo, mid, hi] = sorted(t);
            (lo, ((mid as u128) << 64) | ((hi as u128) << 32) | t as u128)
        });
        let mut repeat: Option<(usize, usize)> = None;
        for w in start.windows(2) {
            let b = &mut slot[w[0] as usize..w[1] as usize];
            if b.len() < 2 {
                continue;
            }
            b.sort_unstable();
            for pair in b.windows(2) {
                if pair[0] >> 32 == pair[1] >> 32 {
                    let t = pair[1] as u32 as usize;
                    if repeat.is_none_or(|(first, _)| t < first) {
                        repeat = Some((t, pair[0] as u32 as usize));
                    }
                }
            }
        }
        if let Some((t, earlier)) = repeat {
            // A polygon's own triangles never share their three vertices,
            // so the two come from different faces.
            let (fi, other) = (src(t), src(earlier));
            let key = sorted(t);
            return Err(MeshError::new(format!(
                "faces {}{} and {}{} share the same three vertices {}, {} and {}",
                other + 1,
                at_line(soup, other),
                fi + 1,
                at_line(soup, fi),
                key[0] + 1,
                key[1] + 1,
                key[2] + 1
            ))
            .at(soup.face_line(fi)));
        }
        drop(slot);

        // Edges: the corners bucketed by the smaller end of their
        // half-edge and sorted within a bucket by the larger end, then by
        // corner, so that the corners on one edge lie together in the
        // order the triangles list them. The first of them makes the edge
        // (its half-edge `2e` runs the way that corner does); an edge
        // used twice in one direction is refused at the first corner
        // that does so, as a walk through the triangles in order would.
        let (start, mut slot) = bucket(nv, corner.len(), |c| {
            let (a, b) = (corner[c], head(c));
            (a.min(b), ((a.max(b) as u64) << 32) | c as u64)
        });
        // For each corner, the first corner on its edge.
        let mut he: Vec<u32> = vec![0; corner.len()];
        // (corner at fault, the earlier corner the same way, whether the
        // other way was taken before it too)
        let mut clash: Option<(usize, usize, bool)> = None;
        for (lo, w) in start.windows(2).enumerate() {
            let b = &mut slot[w[0] as usize..w[1] as usize];
            b.sort_unstable();
            let mut i = 0;
            while i < b.len() {
                let hi = b[i] >> 32;
                let c0 = b[i] as u32;
                // The first corner running lo -> hi and hi -> lo.
                let mut first = [None::<usize>; 2];
                let mut faulted = false;
                while i < b.len() && b[i] >> 32 == hi {
                    let c = b[i] as u32 as usize;
                    he[c] = c0;
                    let way = usize::from(corner[c] as usize != lo);
                    match first[way] {
                        None => first[way] = Some(c),
                        Some(earlier) if !faulted => {
                            faulted = true;
                            if clash.is_none_or(|(at, _, _)| c < at) {
                                clash = Some((c, earlier, first[1 - way].is_some()));
                            }
                        }
                        Some(_) => {}
                    }
                    i += 1;
                }
            }
        }
        drop(slot);
        drop(start);
        if let Some((c, earlier, three)) = clash {
            let (fi, other) = (src(c / 3), src(earlier / 3));
            let why = if three {
                "is shared by three or more faces (non-manifold)"
            } else {
                "is used in the same direction by two faces (inconsistent orientation)"
            };
            return Err(MeshError::new(format!(
                "the edge between vertices {} and {} of face {}{} {why}; the other face is face {}{}",
                corner[c] + 1,
                head(c) + 1,
                fi + 1,
                at_line(soup, fi),
                other + 1,
                at_line(soup, other)
            ))
            .at(soup.face_line(fi)));
        }
        // Edge ids in the order their first corners come; `he[c]` becomes
        // the half-edge of corner `c`. A corner's first corner comes no
        // later than itself, so it has its half-edge already.
        let mut ne = 0u32;
        for c in 0..corner.len() {
            let c0 = he[c] as usize;
            he[c] = if c0 == c {
                ne += 1;
                2 * (ne - 1)
            } else if corner[c0] == corner[c] {
                he[c0]
            } else {
                he[c0] ^ 1
            };
        }
        let ne = ne as usize;
        let mut m = Mesh {
            fanned,
            v_out: vec![super::halfedge::NO_HALFEDGE; nv],
            pos: soup.positions.clone(),
            v_level: Narrow::filled(nv, 0),
            v_step: Narrow::filled(nv, 0),
            v_alive: Bits::filled(nv, true),
            v_sharp: Column::defaults(nv),
            he_to: vec![VertexId(0); 2 * ne],
            he_next: vec![HalfEdgeId(0); 2 * ne],
            he_face: vec![super::halfedge::NO_FACE; 2 * ne],
            e_level: Narrow::filled(ne, 0),
            e_alive: Bits::filled(ne, true),
            e_block: Bits::filled(ne, false),
            e_transversal: Bits::filled(ne, false),
            e_sharp: Column::defaults(ne),
            f_he: Vec::with_capacity(nt),
            f_level_kept: Default::default(),
            f_alive: Bits::filled(nt, true),
            f_tag: match tags {
                Some(t) => Column::from_vec(source.iter().map(|&fi| t[fi as usize]).collect()),
                None => Column::defaults(nt),
            },
            ..Mesh::default()
        };
        for (c, &h) in he.iter().enumerate() {
            if h & 1 == 0 {
                // The corner that made the edge: the first on it, and the
                // only one running its way.
                let e = (h >> 1) as usize;
                let (t, k) = (c / 3, c % 3);
                let diag = diagonal[t][k];
                m.he_to[h as usize] = VertexId(head(c));
                m.he_to[h as usize + 1] = VertexId(corner[c]);
                m.e_level.set(e, if diag { 0 } else { outer_level });
                m.e_block.set(e, diag && soup.faces[src(t)].len() == 4);
            }
            m.he_face[h as usize] = (c / 3) as u32;
        }
        for (t, hs) in he.chunks_exact(3).enumerate() {
            let hs = [HalfEdgeId(hs[0]), HalfEdgeId(hs[1]), HalfEdgeId(hs[2])];
            m.link(hs[0], hs[1]);
            m.link(hs[1], hs[2]);
            m.link(hs[2], hs[0]);
            m.f_he.push(hs[0]);
            for (k, h) in hs.iter().enumerate() {
                m.v_out[corner[3 * t + k] as usize] = h.0;
            }
        }
        drop(he);
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
                m.v_out[v] = b.0;
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
        // Every vertex is at level 0, so every face is at level 1.
        Ok(m)
    }

    /// The mesh as triangles, with dead slots removed.
    pub fn to_soup(&self) -> PolygonSoup {
        // What `soup_with(|_| false)` gives, without the tags and vertices
        // it gives with it. With no dead vertex slot, a soup vertex is its
        // mesh vertex: the positions are copied whole.
        let mut corners = Vec::with_capacity(3 * self.face_count());
        let positions = if self.free_v.is_empty() {
            for f in self.faces() {
                corners.extend(self.face_vertices(f).map(|v| v.0));
            }
            self.pos.clone()
        } else {
            let mut index = vec![u32::MAX; self.v_alive.len()];
            let mut positions = Vec::with_capacity(self.vertex_count());
            for v in self.vertices() {
                index[v.index()] = positions.len() as u32;
                positions.push(self.position(v));
            }
            for f in self.faces() {
                corners.extend(self.face_vertices(f).map(|v| index[v.index()]));
            }
            positions
        };
        PolygonSoup {
            positions,
            faces: Faces::uniform(3, corners),
            ..PolygonSoup::default()
        }
    }

    /// [`Mesh::to_soup`] and the tag of each of its faces.
    pub fn to_soup_tagged(&self) -> (PolygonSoup, Vec<u32>) {
        let (soup, tags, _) = self.soup_with(|_| false);
        (soup, tags)
    }

    /// Reads the mesh as plain triangles: no basic blocks, and, on a base
    /// mesh (every vertex at level 0), every edge at level 0, as if each
    /// quad had been given as two triangles. Schemes for triangle meshes
    /// run on quad input this way; a polygon of more than four sides is
    /// its fan's triangles for them (a face split takes each alone).
    pub fn forget_blocks(&mut self) {
        self.fans.clear();
        self.fan_of.clear();
        let base = self.vertices().all(|v| self.vertex_level(v) == 0);
        let edges: Vec<EdgeId> = self.edges().collect();
        for e in edges {
            self.e_block.set(e.index(), false);
            if base {
                self.e_level.set(e.index(), 0);
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

    /// The mesh as a soup (basic blocks merged into polygons unless
    /// `triangles`) with what of its sharpness a file can carry: each sharp
    /// edge of the soup's polygons as two soup vertices and a sharpness.
    /// The second part counts what cannot be written that way: sharp
    /// vertices, and sharp edges that are a quad's diagonal or end at a
    /// vertex the soup leaves out (a dual block's centre).
    pub fn to_soup_with_sharpness(&self, triangles: bool) -> (PolygonSoup, SoupSharpness) {
        let (soup, _, vertices) = if triangles {
            self.soup_with(|_| false)
        } else {
            self.soup_with(|e| self.is_block_edge(e))
        };
        if !self.has_sharpness_flag() {
            return (soup, SoupSharpness::default());
        }
        let mut index = vec![u32::MAX; self.v_alive.len()];
        for (i, v) in vertices.iter().enumerate() {
            index[v.index()] = i as u32;
        }
        let out = self.soup_sharpness(&index, triangles);
        (soup, out)
    }

    /// The sharpness of [`Mesh::to_soup_with_sharpness`], for a soup whose
    /// vertex of each mesh vertex is `index` (`u32::MAX`: left out).
    pub(crate) fn soup_sharpness(&self, index: &[u32], triangles: bool) -> SoupSharpness {
        let mut out = SoupSharpness::default();
        if !self.has_sharpness_flag() {
            return out;
        }
        for e in self.edges() {
            let s = self.edge_sharpness(e);
            if s <= 0.0 {
                continue;
            }
            let (a, b) = self.edge_vertices(e);
            let (a, b) = (index[a.index()], index[b.index()]);
            if a == u32::MAX || b == u32::MAX || (!triangles && self.is_block_edge(e)) {
                out.edges_left_out += 1;
            } else {
                out.edges.push((a, b, s));
            }
        }
        out.vertices_left_out = self
            .vertices()
            .filter(|&v| self.vertex_sharpness(v) > 0.0)
            .count();
        out
    }

    /// True when [`Mesh::to_quad_soup`] joins some faces into a polygon
    /// (a basic block with both its triangles); false when it gives the
    /// triangles as they are, the same soup as [`Mesh::to_soup`].
    pub(crate) fn quad_soup_merges(&self) -> bool {
        self.edges()
            .any(|e| self.is_block_edge(e) && matches!(self.edge_faces(e), [Some(_), Some(_)]))
    }

    /// [`Mesh::to_quad_soup`] and the tag of each of its faces. A basic
    /// block whose triangles have different tags (a √2 bisection's block
    /// across two tagged quads) stays two triangles, so that every
    /// polygon has the one tag of all its triangles.
    pub fn to_quad_soup_tagged(&self) -> (PolygonSoup, Vec<u32>) {
        let (soup, tags, _) = self.quad_soup_tagged_with_vertices();
        (soup, tags)
    }

    /// [`Mesh::to_quad_soup`], and the mesh vertex of each soup vertex.
    pub(crate) fn quad_soup_with_vertices(&self) -> (PolygonSoup, Vec<VertexId>) {
        let (soup, _, vertices) = self.soup_with(|e| self.is_block_edge(e));
        (soup, vertices)
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

    /// [`Mesh::soup_with`] where no face has two `merge` edges (a mesh of
    /// basic blocks, as a primal quad scheme leaves it), so that every
    /// region is one face or two: each pair is met at its smaller face and
    /// its border walked directly, with no union-find or region lists.
    /// None where some face has two `merge` edges between faces.
    #[allow(clippy::type_complexity)]
    fn soup_of_pairs(
        &self,
        merge: &impl Fn(EdgeId) -> bool,
    ) -> Option<(PolygonSoup, Vec<u32>, Vec<VertexId>)> {
        // The half-edge of each face that its pair's diagonal runs along.
        let mut diagonal = vec![HalfEdgeId(u32::MAX); self.f_alive.len()];
        let mut any = false;
        for e in self.edges() {
            if !merge(e) {
                continue;
            }
            let h = e.halfedge();
            let (Some(f), Some(g)) = (self.face(h), self.face(h.twin())) else {
                continue;
            };
            if diagonal[f.index()].0 != u32::MAX || diagonal[g.index()].0 != u32::MAX {
                return None;
            }
            diagonal[f.index()] = h;
            diagonal[g.index()] = h.twin();
            any = true;
        }
        if !any {
            return None;
        }
        // Every vertex of a face is a corner of its polygon (a pair's four
        // or a triangle's three), so every live vertex stays.
        let (index, positions, verts) = self.live_vertices();
        let mut faces = Faces::with_capacity(self.face_count() / 2, 2 * self.face_count());
        let mut tags = Vec::with_capacity(self.face_count() / 2);
        for f in self.faces() {
            let d = diagonal[f.index()];
            let tri = |faces: &mut Faces, tags: &mut Vec<u32>, g: FaceId| {
                faces.push(self.face_vertices(g).map(|v| index[v.index()]));
                tags.push(self.tag(g));
            };
            if d.0 == u32::MAX {
                tri(&mut faces, &mut tags, f);
                continue;
            }
            let g = self.face(d.twin()).expect("a pair");
            if g.0 < f.0 {
                continue; // met at g, its smaller face
            }
            // The border is f's half-edges after the diagonal, then g's
            // after its twin; the general walk starts it at the first of
            // f's half-edges (from its recorded one) that is not the
            // diagonal.
            let (n1, n2) = (self.next(d), self.prev(d));
            let (m1, m2) = (self.next(d.twin()), self.prev(d.twin()));
            let mut quad = [self.from(n1), self.from(n2), self.from(m1), self.from(m2)];
            if self.face_halfedge(f) == n1 {
                // f's half-edges run n1, n2, d: the walk starts at n1.
            } else if self.face_halfedge(f) == d {
                // d, n1, n2: starts at n1.
            } else {
                // n2, d, n1: starts at n2.
                quad.rotate_left(1);
            }
            let distinct = (0..4).all(|i| (i + 1..4).all(|j| quad[i] != quad[j]));
            if distinct {
                faces.push(quad.map(|v| index[v.index()]));
                tags.push(self.tag(f));
            } else {
                tri(&mut faces, &mut tags, f);
                tri(&mut faces, &mut tags, g);
            }
        }
        let soup = PolygonSoup {
            positions,
            faces,
            ..PolygonSoup::default()
        };
        Some((soup, tags, verts))
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
        if let Some(out) = self.soup_of_pairs(&merge) {
            return out;
        }
        // Regions by union-find over the faces; a region's root is its
        // smallest face.
        let nf = self.f_alive.len();
        let mut parent: Vec<u32> = Vec::new();
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
            if parent.is_empty() {
                parent = (0..nf as u32).collect();
            }
            let (a, b) = (root(&mut parent, f.0), root(&mut parent, g.0));
            if a != b {
                parent[a.max(b) as usize] = a.min(b);
            }
        }
        let merged_any = parent.iter().enumerate().any(|(i, &p)| p as usize != i);
        if !merged_any {
            let (index, positions, verts) = self.live_vertices();
            let mut corners = Vec::with_capacity(3 * self.face_count());
            let mut tags = Vec::with_capacity(self.face_count());
            for f in self.faces() {
                let [a, b, c] = self.face_vertices(f);
                corners.extend([index[a.index()], index[b.index()], index[c.index()]]);
                tags.push(self.tag(f));
            }
            let soup = PolygonSoup {
                positions,
                faces: Faces::uniform(3, corners),
                ..PolygonSoup::default()
            };
            return (soup, tags, verts);
        }
        // Every face's region, and the faces of each region in order, by
        // a counting sort on the root.
        for f in 0..nf as u32 {
            let r = root(&mut parent, f);
            parent[f as usize] = r;
        }
        let region = |h: HalfEdgeId| self.face(h).map(|f| parent[f.index()]);
        let mut first = vec![0u32; nf + 1];
        for f in self.faces() {
            first[parent[f.index()] as usize + 1] += 1;
        }
        for k in 0..nf {
            first[k + 1] += first[k];
        }
        let mut fill = first.clone();
        let mut members = vec![FaceId(0); first[nf] as usize];
        for f in self.faces() {
            let r = parent[f.index()] as usize;
            members[fill[r] as usize] = f;
            fill[r] += 1;
        }
        drop(fill);
        // The polygons, flat: polygon `i` is `corners[ends[i - 1]..ends[i]]`.
        let mut corners: Vec<VertexId> = Vec::with_capacity(members.len() * 2);
        let mut ends: Vec<usize> = Vec::with_capacity(members.len());
        let mut tags: Vec<u32> = Vec::with_capacity(members.len());
        let mut border: Vec<HalfEdgeId> = Vec::new();
        let mut loop_vs: Vec<VertexId> = Vec::new();
        let mut sorted: Vec<VertexId> = Vec::new();
        // A region's faces kept as triangles.
        let triangles = |faces: &[FaceId],
                         corners: &mut Vec<VertexId>,
                         ends: &mut Vec<usize>,
                         tags: &mut Vec<u32>| {
            for &g in faces {
                corners.extend(self.face_vertices(g));
                ends.push(corners.len());
                tags.push(self.tag(g));
            }
        };
        for f in self.faces() {
            let r = parent[f.index()];
            // A region is met first at its root, its smallest face.
            if r != f.0 {
                continue;
            }
            let faces = &members[first[r as usize] as usize..first[r as usize + 1] as usize];
            if faces.len() == 1 {
                triangles(faces, &mut corners, &mut ends, &mut tags);
                continue;
            }
            // The region's border: half-edges whose twin lies outside it.
            border.clear();
            border.extend(
                faces
                    .iter()
                    .flat_map(|&g| self.face_halfedges(g))
                    .filter(|&h| region(h.twin()) != Some(r)),
            );
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
                triangles(faces, &mut corners, &mut ends, &mut tags);
                continue;
            }
            loop_vs.clear();
            let mut h = border[0];
            let mut ok = true;
            for _ in 0..border.len() {
                loop_vs.push(self.from(h));
                // The next border half-edge turns about `to(h)` inside
                // the region.
                let mut g = self.next(h);
                let mut turns = 0;
                while region(g.twin()) == Some(r) {
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
            sorted.clear();
            sorted.extend_from_slice(&loop_vs);
            sorted.sort_unstable();
            sorted.dedup();
            if ok && h == border[0] && sorted.len() == border.len() {
                corners.extend_from_slice(&loop_vs);
                ends.push(corners.len());
                tags.push(self.tag(faces[0]));
            } else {
                triangles(faces, &mut corners, &mut ends, &mut tags);
            }
        }
        // Vertices inside a merged polygon are left out; all others stay.
        let mut index = vec![0u32; self.v_alive.len()];
        for &f in &members {
            for v in self.face_vertices(f) {
                index[v.index()] = u32::MAX;
            }
        }
        for v in &corners {
            index[v.index()] = 0;
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
        let mut faces = Faces::with_capacity(ends.len(), corners.len());
        let mut face = Vec::new();
        let mut start = 0;
        for &end in &ends {
            face.clear();
            face.extend(corners[start..end].iter().map(|v| index[v.index()]));
            faces.push(&face);
            start = end;
        }
        soup.faces = faces;
        (soup, tags, verts)
    }
}

#[cfg(test)]
pub(crate) mod tests {
    //! The implementations before issue 16 (a hash map per edge, and a
    //! vector per region), kept as the oracle: the sorted build and the
    //! flat soups must give the same meshes, errors and soups.

    use std::collections::HashMap;

    use super::*;
    use crate::mesh::shapes;

    impl Mesh {
        fn build_reference(soup: &PolygonSoup, tags: Option<&[u32]>) -> Result<Mesh, MeshError> {
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
            let mut tris: Vec<([u32; 3], usize, [bool; 3])> =
                Vec::with_capacity(soup.faces.len() * 2);
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
                if let Some(k) = crate::mesh::soup::first_repeat(f) {
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
                            m.e_block
                                .set(h.edge().index(), diag[k] && soup.faces[*fi].len() == 4);
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
                                let other =
                                    m.face(h).map(|f| face_of_source[f.index()]).unwrap_or(0);
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
                let f = m.new_face(hs[0], tags.map_or(0, |t| t[*fi]));
                face_of_source.push(*fi);
                m.set_triangle(f, hs[0], hs[1], hs[2]);
                for (k, h) in hs.iter().enumerate() {
                    m.v_out[tri[k] as usize] = h.0;
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
                    m.v_out[v] = b.0;
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
            Ok(m)
        }

        fn soup_with_reference(
            &self,
            merge: impl Fn(EdgeId) -> bool,
        ) -> (PolygonSoup, Vec<u32>, Vec<VertexId>) {
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
                let (index, positions, verts) = self.live_vertices();
                let mut soup = PolygonSoup {
                    positions,
                    ..Default::default()
                };
                soup.faces = self
                    .faces()
                    .map(|f| {
                        self.face_vertices(f)
                            .iter()
                            .map(|v| index[v.index()])
                            .collect::<Vec<u32>>()
                    })
                    .collect();
                let tags = self.faces().map(|f| self.tag(f)).collect();
                return (soup, tags, verts);
            }
            let region =
                |parent: &mut [u32], h: HalfEdgeId| self.face(h).map(|f| root(parent, f.0));
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
                .map(|p| p.iter().map(|v| index[v.index()]).collect::<Vec<u32>>())
                .collect();
            (soup, tags, verts)
        }
    }

    /// splitmix64: a small deterministic generator for the cases.
    struct Rng(u64);

    impl Rng {
        fn next(&mut self) -> u64 {
            self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            z ^ (z >> 31)
        }

        fn below(&mut self, n: usize) -> usize {
            (self.next() % n as u64) as usize
        }
    }

    /// A quad grid with some pairs of neighbouring quads joined into
    /// hexagons, so that polygons get fanned.
    fn hexagon_grid() -> PolygonSoup {
        let mut s = shapes::quad_grid(4, 3);
        let (a, b) = (s.faces[0].to_vec(), s.faces[1].to_vec());
        // Quads (p0 p1 p2 p3) and (p1 q1 q2 p2) share edge p1 p2.
        let shared: Vec<u32> = a.iter().copied().filter(|v| b.contains(v)).collect();
        assert_eq!(shared.len(), 2, "neighbouring quads");
        let mut hex = Vec::new();
        for (i, &v) in a.iter().enumerate() {
            hex.push(v);
            if v == shared[0] || v == shared[1] {
                let w = a[(i + 1) % 4];
                if shared.contains(&w) {
                    // Walk b from v's successor round to w.
                    let j = b.iter().position(|&x| x == v).unwrap();
                    let mut k = (j + 1) % 4;
                    while b[k] != w {
                        hex.push(b[k]);
                        k = (k + 1) % 4;
                    }
                }
            }
        }
        assert_eq!(hex.len(), 6);
        let mut faces = s.faces.to_vecs();
        faces.splice(0..2, [hex]);
        s.faces = faces.into();
        s
    }

    fn bases() -> Vec<PolygonSoup> {
        vec![
            shapes::icosahedron(),
            shapes::icosphere(2),
            shapes::quad_torus(5, 6),
            shapes::quad_grid(4, 3),
            shapes::triangle_grid(3, 4),
            hexagon_grid(),
        ]
    }

    /// `soup` with a few random changes: faces dropped (boundaries,
    /// bow-ties, fans split), reversed (orientation), turned (other
    /// diagonals), repeated (pockets, edges of three faces), reordered,
    /// or new triangles on random vertices; lines on every face and vertex
    /// in half of the cases.
    fn mutate(rng: &mut Rng, soup: &PolygonSoup) -> (PolygonSoup, Vec<u32>) {
        let mut s = soup.clone();
        let mut faces = s.faces.to_vecs();
        for _ in 0..rng.below(4) {
            let n = faces.len();
            let i = rng.below(n);
            match rng.below(7) {
                0 | 1 if n > 1 => {
                    faces.remove(i);
                }
                2 => faces[i].reverse(),
                3 => {
                    let k = rng.below(faces[i].len());
                    faces[i].rotate_left(k);
                }
                4 => {
                    let mut f = faces[i].clone();
                    if rng.below(2) == 0 {
                        f.reverse();
                    }
                    let at = rng.below(n + 1);
                    faces.insert(at, f);
                }
                5 => {
                    let j = rng.below(n);
                    faces.swap(i, j);
                }
                _ => {
                    let nv = s.positions.len();
                    let f = vec![
                        rng.below(nv) as u32,
                        rng.below(nv) as u32,
                        rng.below(nv) as u32,
                    ];
                    faces.insert(rng.below(n + 1), f);
                }
            }
        }
        s.faces = faces.into();
        if rng.below(2) == 0 {
            s.face_lines = (0..s.faces.len()).map(|i| 100 + i).collect();
            s.vertex_lines = (0..s.positions.len()).map(|i| 1 + i).collect();
        }
        let tags = (0..s.faces.len()).map(|_| rng.below(3) as u32).collect();
        (s, tags)
    }

    /// The fast soups of `m` agree with the reference walk, for merges of
    /// every kind. The surface grammars' tests use it too.
    pub(crate) fn soups_agree(m: &Mesh) {
        assert_eq!(m.to_soup(), m.soup_with_reference(|_| false).0);
        assert_eq!(m.soup_with(|_| false), m.soup_with_reference(|_| false));
        let block = |e: EdgeId| m.is_block_edge(e);
        assert_eq!(m.soup_with(block), m.soup_with_reference(block));
        let same_tag = |e: EdgeId| {
            m.is_block_edge(e)
                && match m.edge_faces(e) {
                    [Some(f), Some(g)] => m.tag(f) == m.tag(g),
                    _ => true,
                }
        };
        assert_eq!(m.soup_with(same_tag), m.soup_with_reference(same_tag));
        // Regions of any shape: every third edge merged.
        let every_third = |e: EdgeId| e.0.is_multiple_of(3);
        assert_eq!(m.soup_with(every_third), m.soup_with_reference(every_third));
    }

    #[test]
    fn sorted_build_matches_the_hash_map_build() {
        let mut rng = Rng(16);
        let mut built = 0;
        let mut refused: HashMap<String, usize> = HashMap::new();
        for base in bases() {
            for _ in 0..150 {
                let (soup, tags) = mutate(&mut rng, &base);
                let new = Mesh::build_triangles(&soup, Some(&tags));
                assert_eq!(new, Mesh::build_reference(&soup, Some(&tags)));
                assert_eq!(
                    Mesh::build_triangles(&soup, None),
                    Mesh::build_reference(&soup, None)
                );
                match new {
                    Ok(m) => {
                        built += 1;
                        soups_agree(&m);
                    }
                    Err(e) => {
                        // The kind of refusal: the message without numbers.
                        let kind: String =
                            e.message.chars().filter(|c| !c.is_ascii_digit()).collect();
                        *refused.entry(kind).or_default() += 1;
                    }
                }
            }
        }
        // Both sides of the comparison were exercised: meshes built, and
        // refusals of each kind the build makes after its per-face checks.
        assert!(built > 200, "{built} built");
        for kind in [
            "share the same three vertices",
            "(non-manifold); the other face",
            "(inconsistent orientation)",
            "is a bow-tie",
            "its faces form more than one fan",
        ] {
            assert!(
                refused.keys().any(|k| k.contains(kind)),
                "no case refused with {kind:?}: {refused:?}"
            );
        }
    }

    #[test]
    fn soups_match_after_splits_and_flips() {
        let mut rng = Rng(61);
        for base in bases() {
            let mut m = Mesh::from_soup(&base).unwrap();
            for _ in 0..10 {
                let e = EdgeId(rng.below(m.e_alive.len()) as u32);
                if rng.below(2) == 0 {
                    let (a, b) = m.edge_vertices(e);
                    let p = (m.position(a) + m.position(b)) * 0.5;
                    m.edge_split(e, p).unwrap();
                } else {
                    // A flip may be refused; the mesh is then unchanged.
                    let _ = m.edge_flip(e);
                }
            }
            soups_agree(&m);
        }
    }
}

/// The sharpness [`Mesh::to_soup_with_sharpness`] finds for a soup.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SoupSharpness {
    /// Sharp edges of the soup's polygons: two soup vertices (from 0) and
    /// the sharpness.
    pub edges: Vec<(u32, u32, f64)>,
    /// Sharp edges no polygon edge carries (quad diagonals, edges to a
    /// vertex the soup leaves out).
    pub edges_left_out: usize,
    /// Sharp vertices (no mesh format subgram writes carries them).
    pub vertices_left_out: usize,
}
