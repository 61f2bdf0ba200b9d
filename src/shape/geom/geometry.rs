//! A shape's geometry ([`Face`], [`Geometry`]), its frame ([`Scope`]) and
//! the normal of a polygon by Newell's method.

use std::collections::HashSet;

use glam::DVec3;

use super::points::Points;
use super::PointId;

/// A polygon of a shape.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Face {
    /// Counter-clockwise seen from outside (3D) or from the side the
    /// normal points to (2D).
    pub pts: Vec<PointId>,
    /// 0: the shape's own surface. 2k: the cap cut k made on its lower
    /// side, 2k + 1: the same cap on its upper side (the same ids,
    /// reversed).
    pub seam: u32,
}

/// A shape's geometry: a polyhedron (dim 3) or faces (dim 2), edges (dim 1)
/// or points (dim 0).
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Geometry {
    pub dim: u8,
    pub faces: Vec<Face>,
    pub edges: Vec<[PointId; 2]>,
    pub verts: Vec<PointId>,
}

impl Geometry {
    pub fn empty(dim: u8) -> Geometry {
        Geometry {
            dim,
            faces: Vec::new(),
            edges: Vec::new(),
            verts: Vec::new(),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.faces.is_empty() && self.edges.is_empty() && self.verts.is_empty()
    }

    /// Every point id the geometry uses, once per use (faces, then edges,
    /// then points).
    pub fn point_ids(&self) -> impl Iterator<Item = PointId> + '_ {
        self.faces
            .iter()
            .flat_map(|f| f.pts.iter().copied())
            .chain(self.edges.iter().flat_map(|e| e.iter().copied()))
            .chain(self.verts.iter().copied())
    }

    /// Every point id the geometry uses, once, in first-use order.
    pub fn unique_points(&self) -> Vec<PointId> {
        let mut seen = HashSet::new();
        self.point_ids().filter(|&p| seen.insert(p)).collect()
    }

    pub fn face_count(&self) -> usize {
        self.faces.len()
    }

    /// Its elements: faces, edges and points, what a shape holds.
    pub fn elements(&self) -> usize {
        self.faces.len() + self.edges.len() + self.verts.len()
    }
}

/// A shape's frame: origin, orthonormal right-handed axes x, y, z and the
/// size along them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Scope {
    pub origin: DVec3,
    pub axes: [DVec3; 3],
    pub size: DVec3,
}

impl Scope {
    /// The world frame at the origin, of size 0.
    pub fn world() -> Scope {
        Scope {
            origin: DVec3::ZERO,
            axes: [DVec3::X, DVec3::Y, DVec3::Z],
            size: DVec3::ZERO,
        }
    }

    /// The coordinates of world point `p` in the scope's frame.
    pub fn local(&self, p: DVec3) -> DVec3 {
        let v = p - self.origin;
        DVec3::new(
            v.dot(self.axes[0]),
            v.dot(self.axes[1]),
            v.dot(self.axes[2]),
        )
    }

    /// The world point at coordinates `l` in the scope's frame (named
    /// `to_world` because `world()` makes the world scope).
    pub fn to_world(self, l: DVec3) -> DVec3 {
        self.origin + l.x * self.axes[0] + l.y * self.axes[1] + l.z * self.axes[2]
    }

    pub(super) fn is_right_handed(&self) -> bool {
        self.axes[0].cross(self.axes[1]).dot(self.axes[2]) >= 0.0
    }
}

/// The polygon's normal by Newell's method (its length is twice the area).
pub(crate) fn newell(points: &Points, poly: &[PointId]) -> DVec3 {
    let m = poly.len();
    let mut n = DVec3::ZERO;
    for i in 0..m {
        let a = points.get(poly[i]);
        let b = points.get(poly[(i + 1) % m]);
        n += DVec3::new(
            (a.y - b.y) * (a.z + b.z),
            (a.z - b.z) * (a.x + b.x),
            (a.x - b.x) * (a.y + b.y),
        );
    }
    n
}
