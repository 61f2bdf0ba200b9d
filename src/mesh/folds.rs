//! Folds of a subdivided surface, measured against the mesh it came from:
//! the largest angle between the normals of two faces that share an edge,
//! and the faces that point away from the base surface where they came
//! from. A smooth scheme's largest angle falls with each level, and none
//! of its faces turns over; a vertex where the scheme is not C1 keeps a
//! crease however far it is refined (issue 43, item 5).
//!
//! The base mesh is built with a tag on each triangle
//! ([`Mesh::from_soup_tagged`], the triangle's index), which the stellar
//! operators hand down, so that every face of the refined mesh knows the
//! base triangle it lies in.

use glam::DVec3;

use super::halfedge::{Mesh, VertexId};

/// What [`folds`] measured.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Folds {
    /// The largest angle, in degrees, between the normals of two faces
    /// across an interior edge (0 where the surface is flat).
    pub max_dihedral: f64,
    /// Faces whose normal points away (a negative dot product) from the
    /// base surface's normal at the base triangle they came from.
    pub flipped: usize,
    pub faces: usize,
    /// The largest angle across the edges at the vertices `folds` was
    /// given (the original vertices of valence 3 and 4, say, which keep
    /// their numbers through a run): where a vertex is not C1, this one
    /// does not fall.
    pub max_dihedral_at: f64,
}

/// The base surface's normal at each base triangle, by tag: the sum of
/// its corners' vertex normals (each the sum of the cross products of the
/// faces around the vertex), so a noisy triangle borrows its neighbours'
/// direction. `None` for a tag no face of `base` carries.
pub fn base_normals(base: &Mesh) -> Vec<Option<DVec3>> {
    let slots = base.vertices().map(|v| v.index() + 1).max().unwrap_or(0);
    let mut at_vertex = vec![DVec3::ZERO; slots];
    for f in base.faces() {
        let n = face_cross(base, base.face_vertices(f));
        for v in base.face_vertices(f) {
            at_vertex[v.index()] += n;
        }
    }
    let tags = base.faces().map(|f| base.tag(f) as usize + 1).max();
    let mut out = vec![None; tags.unwrap_or(0)];
    for f in base.faces() {
        let n: DVec3 = base
            .face_vertices(f)
            .iter()
            .map(|v| at_vertex[v.index()].normalize_or_zero())
            .sum();
        out[base.tag(f) as usize] = Some(n);
    }
    out
}

fn face_cross(m: &Mesh, [a, b, c]: [VertexId; 3]) -> DVec3 {
    let (a, b, c) = (m.position(a), m.position(b), m.position(c));
    (b - a).cross(c - a)
}

/// The folds of `refined`, whose faces carry the tags of the base
/// triangles whose normals `normals` holds ([`base_normals`]);
/// `Folds::max_dihedral_at` over the edges at `at`.
pub fn folds(refined: &Mesh, normals: &[Option<DVec3>], at: &[VertexId]) -> Folds {
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
        let base = normals.get(refined.tag(f) as usize).copied().flatten();
        if base.is_some_and(|b| n.dot(b) < 0.0) {
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
