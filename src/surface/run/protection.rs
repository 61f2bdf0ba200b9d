//! The parts of a mesh a run leaves as they are: the [`Protection`] a
//! caller gives, and the [`Protected`] sets a run reads it as.

use glam::DVec3;

use crate::mesh::{EdgeId, FaceId, Mesh, VertexId};

/// The parts of a mesh a run leaves as they are (paper 003, §4.2.2: the
/// faces and vertices a smoothing group shares with shapes outside it).
/// No rule matches a protected face, or a face whose three corners are
/// protected vertices (Algorithm 3 for the mesh's triangles); a vertex
/// that is protected or lies
/// on a protected face; an edge with a protected face on either side, or
/// whose two ends are protected. So no face point is put in a protected
/// face, none of its vertices moves, no edge is drawn in it or split on
/// its border, and no edge next to it flips (Algorithm 2 with the sets of
/// Algorithm 3). Protected elements are never rewritten, so their ids and
/// positions stay as they were through the run.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Protection {
    /// By [`FaceId`] index; faces past its end are not protected.
    pub faces: Vec<bool>,
    /// By [`VertexId`] index; vertices past its end are not protected.
    pub vertices: Vec<bool>,
}

/// A [`Protection`] as a run reads it.
#[derive(Debug, Default)]
pub(super) struct Protected {
    face: Vec<bool>,
    vertex: Vec<bool>,
    /// Protected, or a corner of a protected face: never moved.
    fixed: Vec<bool>,
    /// The protected faces with their corners and the fixed vertices with
    /// their positions, as the run found them (for a debug check).
    faces: Vec<(FaceId, [VertexId; 3])>,
    positions: Vec<(VertexId, DVec3)>,
}

impl Protected {
    /// Checks `p` against `mesh`: every protected element must exist.
    pub(super) fn new(p: Protection, mesh: &Mesh) -> Result<Protected, String> {
        if let Some(f) = p
            .faces
            .iter()
            .enumerate()
            .position(|(i, &on)| on && !mesh.is_face(FaceId(i as u32)))
        {
            return Err(format!(
                "face {} is protected but is not a face of the mesh",
                f + 1
            ));
        }
        if let Some(v) = p
            .vertices
            .iter()
            .enumerate()
            .position(|(i, &on)| on && !mesh.is_vertex(VertexId(i as u32)))
        {
            return Err(format!(
                "vertex {} is protected but is not a vertex of the mesh",
                v + 1
            ));
        }
        let mut fixed = p.vertices.clone();
        fixed.resize(mesh.v_alive.len(), false);
        let mut faces = Vec::new();
        for (i, &on) in p.faces.iter().enumerate() {
            if on {
                let f = FaceId(i as u32);
                let vs = mesh.face_vertices(f);
                for v in vs {
                    fixed[v.index()] = true;
                }
                faces.push((f, vs));
            }
        }
        let positions = (0..fixed.len())
            .filter(|&i| fixed[i])
            .map(|i| (VertexId(i as u32), mesh.position(VertexId(i as u32))))
            .collect();
        Ok(Protected {
            face: p.faces,
            vertex: p.vertices,
            fixed,
            faces,
            positions,
        })
    }

    #[inline]
    fn face(&self, f: FaceId) -> bool {
        self.face.get(f.index()).copied().unwrap_or(false)
    }

    /// A face rule may match `f`: it is not protected, and not all its
    /// corners are protected vertices. The second is Algorithm 3's rule
    /// (a face whose vertices are all protected is protected) for the
    /// triangles being subdivided, whatever polygons the protection was
    /// given for: a face point in such a triangle would join three
    /// spokes whose ends never move and whose edges never flip, and a
    /// later step that flips all three (√3 next to a protected boundary
    /// edge) would join two new vertices twice.
    #[inline]
    pub(super) fn face_free(&self, mesh: &Mesh, f: FaceId) -> bool {
        let protected = |v: VertexId| self.vertex.get(v.index()).copied().unwrap_or(false);
        !self.face(f) && !mesh.face_vertices(f).into_iter().all(protected)
    }

    /// A vertex rule may match `v`.
    #[inline]
    pub(super) fn vertex_free(&self, v: VertexId) -> bool {
        !self.fixed.get(v.index()).copied().unwrap_or(false)
    }

    /// An edge rule may match `e`.
    pub(super) fn edge_free(&self, mesh: &Mesh, e: EdgeId) -> bool {
        let protected = |v: VertexId| self.vertex.get(v.index()).copied().unwrap_or(false);
        let (a, b) = mesh.edge_vertices(e);
        !(protected(a) && protected(b)
            || mesh.edge_faces(e).iter().flatten().any(|&f| self.face(f)))
    }

    /// True while every protected face has its corners and every fixed
    /// vertex its position, bit for bit.
    pub(super) fn intact(&self, mesh: &Mesh) -> bool {
        self.faces.iter().all(|&(f, vs)| {
            mesh.is_face(f) && {
                let now = mesh.face_vertices(f);
                (0..3).any(|k| (0..3).all(|i| now[(k + i) % 3] == vs[i]))
            }
        }) && self.positions.iter().all(|&(v, p)| {
            mesh.is_vertex(v)
                && mesh.position(v).to_array().map(f64::to_bits) == p.to_array().map(f64::to_bits)
        })
    }
}
