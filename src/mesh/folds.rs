//! Folds of a subdivided surface, measured against the mesh it came from:
//! the largest angle between the normals of two faces that share an edge,
//! and the faces that point away from the base surface where they came
//! from. A smooth scheme's largest angle falls with each level, and none
//! of its faces turns over; a vertex where the scheme is not C1 keeps a
//! crease however far it is refined (issue 43, item 5).
//!
//! A refined face is compared with the base triangle nearest to it (a
//! grid of cells, [`TriangleIndex`]), whose normal is smoothed over its
//! corners' neighbourhoods.

use glam::DVec3;

use super::halfedge::{Mesh, VertexId};

/// What [`folds`] measured.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Folds {
    /// The largest angle, in degrees, between the normals of two faces
    /// across an interior edge (0 where the surface is flat).
    pub max_dihedral: f64,
    /// Faces whose normal points away (a negative dot product) from the
    /// base surface's normal at the base triangle nearest them.
    pub flipped: usize,
    pub faces: usize,
    /// The largest angle across the edges at the vertices `folds` was
    /// given (the original vertices of valence 3 and 4, say, which keep
    /// their numbers through a run): where a vertex is not C1, this one
    /// does not fall.
    pub max_dihedral_at: f64,
}

/// The base mesh as [`folds`] reads it: its triangles in a grid for
/// nearest-point queries, and each triangle's smoothed normal: the sum of
/// its corners' unit vertex normals (each vertex's the sum of the cross
/// products of the faces around it), so a noisy triangle borrows its
/// neighbours' direction.
pub struct Base {
    index: TriangleIndex,
    normals: Vec<DVec3>,
}

impl Base {
    pub fn new(base: &Mesh) -> Base {
        let slots = base.vertices().map(|v| v.index() + 1).max().unwrap_or(0);
        let mut at_vertex = vec![DVec3::ZERO; slots];
        for f in base.faces() {
            let n = face_cross(base, base.face_vertices(f));
            for v in base.face_vertices(f) {
                at_vertex[v.index()] += n;
            }
        }
        let normals = base
            .faces()
            .map(|f| {
                base.face_vertices(f)
                    .iter()
                    .map(|v| at_vertex[v.index()].normalize_or_zero())
                    .sum()
            })
            .collect();
        Base {
            index: TriangleIndex::new(base),
            normals,
        }
    }
}

fn face_cross(m: &Mesh, [a, b, c]: [VertexId; 3]) -> DVec3 {
    let (a, b, c) = (m.position(a), m.position(b), m.position(c));
    (b - a).cross(c - a)
}

/// The folds of `refined` against `base`: a face is flipped when its
/// normal points away from the smoothed normal of the base triangle
/// nearest its centroid; `Folds::max_dihedral_at` is over the edges at
/// `at`.
pub fn folds(refined: &Mesh, base: &Base, at: &[VertexId]) -> Folds {
    let mut out = Folds {
        faces: refined.face_count(),
        ..Folds::default()
    };
    let dihedral = |e| match refined.edge_faces(e) {
        [Some(f), Some(g)] => {
            let a = face_cross(refined, refined.face_vertices(f));
            let b = face_cross(refined, refined.face_vertices(g));
            Some(a.angle_between(b).to_degrees()).filter(|x| x.is_finite())
        }
        _ => None,
    };
    for e in refined.edges() {
        if let Some(angle) = dihedral(e) {
            out.max_dihedral = out.max_dihedral.max(angle);
        }
    }
    for &v in at {
        for h in refined.outgoing_halfedges(v) {
            if let Some(angle) = dihedral(h.edge()) {
                out.max_dihedral_at = out.max_dihedral_at.max(angle);
            }
        }
    }
    for f in refined.faces() {
        let n = face_cross(refined, refined.face_vertices(f));
        let centre = refined.face_centroid(f);
        let near = base.index.nearest(centre).map(|(_, i)| base.normals[i]);
        if near.is_some_and(|b| n.dot(b) < 0.0) {
            out.flipped += 1;
        }
    }
    out
}

/// The basic blocks (quads) around an interior vertex of a tri-quad mesh:
/// its faces, less one for each block's internal edge at it (that
/// block's two triangles are one quad). C4's vertex rule needs at least 3
/// (paper 004: a vertex of valence 2k in the 4-8 mesh; `c4.lsys` says why
/// k = 2 is not C1). `None` for a boundary vertex.
pub fn blocks_at(m: &Mesh, v: VertexId) -> Option<usize> {
    if m.is_boundary_vertex(v) {
        return None;
    }
    let faces = m.vertex_faces(v).count();
    let internal = m
        .outgoing_halfedges(v)
        .filter(|h| m.is_block_edge(h.edge()))
        .count();
    Some(faces - internal)
}

/// Triangles in a uniform grid of cells, for nearest-point queries.
pub struct TriangleIndex {
    tris: Vec<[DVec3; 3]>,
    lo: DVec3,
    cell: f64,
    dims: [usize; 3],
    cells: Vec<Vec<u32>>,
}

impl TriangleIndex {
    /// The index of `m`'s triangles.
    pub fn new(m: &Mesh) -> TriangleIndex {
        let tris: Vec<[DVec3; 3]> = m
            .faces()
            .map(|f| m.face_vertices(f).map(|v| m.position(v)))
            .collect();
        let (mut lo, mut hi) = (DVec3::splat(f64::MAX), DVec3::splat(f64::MIN));
        for t in &tris {
            for p in t {
                lo = lo.min(*p);
                hi = hi.max(*p);
            }
        }
        let n = (tris.len() as f64 / 2.0).cbrt().max(1.0);
        let cell = (hi - lo).max_element() / n;
        let dims = ((hi - lo) / cell).to_array().map(|x| x as usize + 1);
        let mut cells = vec![Vec::new(); dims[0] * dims[1] * dims[2]];
        for (i, t) in tris.iter().enumerate() {
            let a = t[0].min(t[1]).min(t[2]);
            let b = t[0].max(t[1]).max(t[2]);
            let (ca, cb) = (((a - lo) / cell).to_array(), ((b - lo) / cell).to_array());
            for x in ca[0] as usize..=(cb[0] as usize).min(dims[0] - 1) {
                for y in ca[1] as usize..=(cb[1] as usize).min(dims[1] - 1) {
                    for z in ca[2] as usize..=(cb[2] as usize).min(dims[2] - 1) {
                        cells[(x * dims[1] + y) * dims[2] + z].push(i as u32);
                    }
                }
            }
        }
        TriangleIndex {
            tris,
            lo,
            cell,
            dims,
            cells,
        }
    }

    /// The distance from `p` to the nearest triangle.
    pub fn distance(&self, p: DVec3) -> f64 {
        self.nearest(p).map_or(f64::MAX, |(d, _)| d)
    }

    /// The distance from `p` to the nearest triangle, and that triangle's
    /// place in the order `Mesh::faces` gave them: cells in growing
    /// shells, until the best distance is within the shell's reach.
    pub fn nearest(&self, p: DVec3) -> Option<(f64, usize)> {
        let c = ((p - self.lo) / self.cell)
            .to_array()
            .map(|x| x.floor() as i64);
        let mut best: Option<(f64, usize)> = None;
        for k in 0i64.. {
            for x in c[0] - k..=c[0] + k {
                for y in c[1] - k..=c[1] + k {
                    for z in c[2] - k..=c[2] + k {
                        let shell = (x - c[0]).abs().max((y - c[1]).abs()).max((z - c[2]).abs());
                        if shell != k {
                            continue;
                        }
                        let ok = |v: i64, d: usize| v >= 0 && (v as usize) < d;
                        if !(ok(x, self.dims[0]) && ok(y, self.dims[1]) && ok(z, self.dims[2])) {
                            continue;
                        }
                        let cell = &self.cells
                            [(x as usize * self.dims[1] + y as usize) * self.dims[2] + z as usize];
                        for &i in cell {
                            let d = point_triangle(p, &self.tris[i as usize]);
                            if best.is_none_or(|(b, j)| (d, i as usize) < (b, j)) {
                                best = Some((d, i as usize));
                            }
                        }
                    }
                }
            }
            if best.is_some_and(|(b, _)| b <= k as f64 * self.cell)
                || k as usize > self.dims.iter().sum::<usize>()
            {
                return best;
            }
        }
        best
    }
}

/// The distance from `p` to triangle `t` (Ericson, Real-Time Collision
/// Detection, 5.1.5: the closest point by the Voronoi regions).
fn point_triangle(p: DVec3, t: &[DVec3; 3]) -> f64 {
    let [a, b, c] = *t;
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return p.distance(a);
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return p.distance(b);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return p.distance(a + ab * (d1 / (d1 - d3)));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return p.distance(c);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return p.distance(a + ac * (d2 / (d2 - d6)));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        return p.distance(b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))));
    }
    let denom = 1.0 / (va + vb + vc);
    p.distance(a + ab * (vb * denom) + ac * (vc * denom))
}
