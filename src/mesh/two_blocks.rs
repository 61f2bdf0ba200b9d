//! Vertices in two blocks, split into three: the last step of the
//! pairing (paper 004's preprocess) for C4 (issue 43, item 5).
//!
//! An interior vertex `v` in two basic blocks (two quads: a vertex of
//! valence 3 on a block's diagonal, or of valence 4 on two) becomes a
//! vertex of valence 4 in the 4-8 mesh, where C4's subdominant eigenvalue
//! is 1/4, no more than the next one, and the surface keeps a crease
//! however far it is refined. The pairing avoids such vertices where the
//! matching allows; where it does not (a tetrahedron, an octahedron, 8 of
//! the bunny's 1,839 vertices), the two quads are cut into five, which
//! leaves `v` in three and every other vertex in as many as before or
//! more, and no new vertex in fewer than three:
//!
//! ```text
//!   Q1 = v a w b, Q2 = v b u a: the two quads at v share its edges va
//!   and vb; Q2's internal edge is v u (one of the two has its internal
//!   edge at v). New points: ma on va, mb on vb (midpoints), c at the
//!   midpoint of Q1's internal edge (v w or a b).
//!
//!   Q1 -> v ma c mb,  a w c ma,  c w b mb      (v in 3 quads,
//!   Q2 -> mb b u v,   u a ma v                  ma, mb, c in 3 each)
//! ```
//!
//! Every new triangle lies inside an old one (each quad's internal edge
//! is on an old edge or inside an old triangle, and Q2 keeps v u), so the
//! mesh's shape, its area and its original vertices (places and numbers)
//! stay; the new vertices come after them. The two edges split are `v`'s
//! own, inside Q1 ∪ Q2, so nothing outside the two quads changes: no
//! T-junction, no triangle left alone.

use glam::DVec3;

use super::halfedge::{FaceId, Mesh, MeshError, VertexId};
use super::soup::PolygonSoup;

/// A polygon of the mesh as the cutting sees it.
#[derive(Clone, Debug)]
enum Poly {
    /// A block: the quad's corners, its internal edge from corner 0 to
    /// corner 2, and the tags of its triangles `q0 q1 q2` and `q0 q2 q3`.
    Block { quad: [u32; 4], tags: [u32; 2] },
    /// A triangle in no block (on the boundary, for the grammar's split).
    Lone([u32; 3], u32),
}

impl Poly {
    fn corners(&self) -> &[u32] {
        match self {
            Poly::Block { quad, .. } => quad,
            Poly::Lone(t, _) => t,
        }
    }

    /// A block's two triangles with their tags.
    fn triangles(quad: [u32; 4], tags: [u32; 2]) -> [([u32; 3], u32); 2] {
        [
            ([quad[0], quad[1], quad[2]], tags[0]),
            ([quad[0], quad[2], quad[3]], tags[1]),
        ]
    }
}

impl Mesh {
    /// Cuts the two quads around every interior vertex in two blocks into
    /// five (see the module's comment), on a base mesh whose triangles
    /// are all in blocks but those left on the boundary. Returns how many
    /// vertices were so split; the mesh is rebuilt only when one was, its
    /// blocks, tags and sharpness kept (a split edge's halves keep its
    /// sharpness). A vertex whose two polygons are not two quads that
    /// share its two edges (one is a lone triangle) is left as it is.
    pub(crate) fn split_two_block_vertices(&mut self) -> Result<usize, MeshError> {
        let two: Vec<VertexId> = self
            .vertices()
            .filter(|&v| super::folds::blocks_at(self, v) == Some(2))
            .collect();
        let slots = self.vertices().map(|v| v.index() + 1).max().unwrap_or(0);
        if two.is_empty() || slots != self.vertex_count() {
            return Ok(0);
        }
        let mut polys = self.block_polygons();
        let mut positions: Vec<DVec3> = self.vertices().map(|v| self.position(v)).collect();
        let mut at: Vec<Vec<usize>> = vec![Vec::new(); slots];
        for (i, p) in polys.iter().enumerate() {
            for &c in p.corners() {
                at[c as usize].push(i);
            }
        }
        let mut alive = vec![true; polys.len()];
        // The edges split, by their ends, with the midpoint.
        let mut halves: Vec<((u32, u32), u32)> = Vec::new();
        let mut split = 0;
        for v in two {
            let v = v.0;
            let here: Vec<usize> = at[v as usize]
                .iter()
                .copied()
                .filter(|&i| alive[i])
                .collect();
            let blocks: Vec<([u32; 4], [u32; 2])> = here
                .iter()
                .filter_map(|&i| match polys[i] {
                    Poly::Block { quad, tags } => Some((quad, tags)),
                    Poly::Lone(..) => None,
                })
                .collect();
            let [first, second] = blocks[..] else {
                continue;
            };
            // Q2: a block whose internal edge is at v (one is: v's faces
            // less its internal edges are 2, and it has 3 faces or more).
            let at_v = |q: [u32; 4]| q[0] == v || q[2] == v;
            let ((q1, tags1), (q2, tags2)) = if at_v(second.0) {
                (first, second)
            } else {
                (second, first)
            };
            let [_, a, w, b] = from_corner(q1, v);
            let u = from_corner(q2, v)[2];
            if from_corner(q2, v) != [v, b, u, a] || !at_v(q2) {
                continue;
            }
            let p = |i: u32| positions[i as usize];
            let (ma, mb, c) = (
                positions.len() as u32,
                positions.len() as u32 + 1,
                positions.len() as u32 + 2,
            );
            // The centre on Q1's internal edge: every new triangle lies in
            // an old one, so the mesh's shape is what it was.
            positions.extend([
                (p(v) + p(a)) * 0.5,
                (p(v) + p(b)) * 0.5,
                (p(q1[0]) + p(q1[2])) * 0.5,
            ]);
            at.extend([Vec::new(), Vec::new(), Vec::new()]);
            halves.push(((v, a), ma));
            halves.push(((v, b), mb));
            // The old triangles, and the old edge each new vertex is on,
            // for the tag of each new triangle (the old one it lies in).
            let old: Vec<([u32; 3], u32)> = Poly::triangles(q1, tags1)
                .into_iter()
                .chain(Poly::triangles(q2, tags2))
                .collect();
            let carrier = |x: u32| match x {
                _ if x == ma => [v, a],
                _ if x == mb => [v, b],
                _ if x == c => [q1[0], q1[2]],
                _ => [x, x],
            };
            let tag_of = |t: [u32; 3]| {
                old.iter()
                    .find(|(o, _)| t.iter().flat_map(|&x| carrier(x)).all(|x| o.contains(&x)))
                    .map_or(old[0].1, |&(_, tag)| tag)
            };
            for i in here {
                alive[i] = false;
            }
            // Each quad's internal edge (corner 0 to 2) lies on an old edge
            // or inside an old triangle; Q2's old internal edge v u stays.
            for quad in [
                [v, ma, c, mb],
                [a, w, c, ma],
                [c, w, b, mb],
                [mb, b, u, v],
                [u, a, ma, v],
            ] {
                let tags = Poly::triangles(quad, [0, 0]).map(|(t, _)| tag_of(t));
                for &k in &quad {
                    at[k as usize].push(polys.len());
                }
                polys.push(Poly::Block { quad, tags });
                alive.push(true);
            }
            split += 1;
        }
        if split == 0 {
            return Ok(0);
        }
        // The soup: every block as its two triangles (each with its tag),
        // its internal edge marked again once the mesh is built; lone
        // triangles alone.
        let mut soup = PolygonSoup {
            positions,
            ..PolygonSoup::default()
        };
        let mut tags = Vec::new();
        let mut diagonals = Vec::new();
        for (p, _) in polys.iter().zip(&alive).filter(|(_, &a)| a) {
            match *p {
                Poly::Block { quad, tags: t } => {
                    for (tri, tag) in Poly::triangles(quad, t) {
                        soup.faces.push(tri);
                        tags.push(tag);
                    }
                    diagonals.push((quad[0], quad[2]));
                }
                Poly::Lone(t, tag) => {
                    soup.faces.push(t);
                    tags.push(tag);
                }
            }
        }
        let mut m = Mesh::from_soup_tagged(&soup, &tags)?;
        let edge = |m: &Mesh, a: u32, b: u32| {
            m.find_halfedge(VertexId(a), VertexId(b))
                .map(|h| h.edge())
                .ok_or_else(|| MeshError::new(format!("no edge between {a} and {b} after the cut")))
        };
        for (a, b) in diagonals {
            let e = edge(&m, a, b)?;
            m.e_block.set(e.index(), true);
        }
        for e in self.edges() {
            let s = self.edge_sharpness(e);
            if s == 0.0 {
                continue;
            }
            let (a, b) = self.edge_vertices(e);
            let (a, b) = (a.0, b.0);
            let mid = halves
                .iter()
                .find(|((p, q), _)| (*p, *q) == (a, b) || (*q, *p) == (a, b))
                .map(|&(_, mid)| mid);
            let parts = match mid {
                Some(mid) => vec![(a, mid), (mid, b)],
                None => vec![(a, b)],
            };
            for (p, q) in parts {
                let e = edge(&m, p, q)?;
                m.set_edge_sharpness(e, s)?;
            }
        }
        for v in self.vertices() {
            let s = self.vertex_sharpness(v);
            if s != 0.0 {
                m.set_vertex_sharpness(v, s)?;
            }
        }
        *self = m;
        Ok(split)
    }

    /// Every face as the cutting sees it: a block's two triangles once, as
    /// one polygon (listed at the lower face id), each other triangle
    /// alone.
    fn block_polygons(&self) -> Vec<Poly> {
        let mut out = Vec::new();
        for f in self.faces() {
            let hs = self.face_halfedges(f);
            let inner = hs.iter().find(|h| self.is_block_edge(h.edge()));
            let tri = |g: FaceId| self.face_vertices(g).map(|v| v.0);
            match inner.and_then(|&h| Some((h, self.face(h.twin())?))) {
                Some((h, g)) => {
                    if g.index() < f.index() {
                        continue;
                    }
                    // f = p q x, g = q p y: the quad p y q x.
                    let (p, q) = (self.from(h).0, self.to(h).0);
                    let x = self.to(self.next(h)).0;
                    let y = self.to(self.next(h.twin())).0;
                    out.push(Poly::Block {
                        quad: [p, y, q, x],
                        tags: [self.tag(g), self.tag(f)],
                    });
                }
                None => out.push(Poly::Lone(tri(f), self.tag(f))),
            }
        }
        out
    }
}

/// The quad's corners turned so that `v` comes first.
fn from_corner(q: [u32; 4], v: u32) -> [u32; 4] {
    let i = q.iter().position(|&c| c == v).unwrap_or(0);
    [q[i], q[(i + 1) % 4], q[(i + 2) % 4], q[(i + 3) % 4]]
}
