//! The primitives inserted in a scope (box, cylinder, sphere, a mesh) and
//! planar polygons, on new points.

use glam::DVec3;

use crate::mesh::PolygonSoup;

use super::geometry::{Face, Geometry, Scope};
use super::points::Points;
use super::PointId;

/// The most segments (or slices, stacks) a round primitive may have.
pub(crate) const MAX_SEGMENTS: usize = 1 << 16;

fn check_scope(scope: &Scope) -> bool {
    scope.origin.is_finite()
        && scope.axes.iter().all(|a| a.is_finite())
        && scope.size.is_finite()
        && scope.size.min_element() > 0.0
}

pub(super) fn quad(a: PointId, b: PointId, c: PointId, e: PointId) -> Face {
    Face {
        pts: vec![a, b, c, e],
        seam: 0,
    }
}

fn solid(faces: Vec<Face>, scope: &Scope) -> Geometry {
    let mut g = Geometry::empty(3);
    g.faces = faces;
    if !scope.is_right_handed() {
        for f in &mut g.faces {
            f.pts.reverse();
        }
    }
    g
}

/// A box filling the scope: 6 quads, counter-clockwise from outside, each
/// side face starting at its bottom edge (so that its `comp` scope has y up).
/// A scope with a zero (or non-finite) size gives an empty geometry.
pub(crate) fn box_in(points: &mut Points, scope: &Scope) -> Result<Geometry, String> {
    if !check_scope(scope) {
        return Ok(Geometry::empty(3));
    }
    let mut c = [0; 8];
    for (k, slot) in c.iter_mut().enumerate() {
        let l = DVec3::new(
            (k & 1) as f64 * scope.size.x,
            ((k >> 1) & 1) as f64 * scope.size.y,
            ((k >> 2) & 1) as f64 * scope.size.z,
        );
        *slot = points.add(scope.to_world(l))?;
    }
    let faces = vec![
        quad(c[4], c[5], c[7], c[6]), // front +z
        quad(c[1], c[0], c[2], c[3]), // back -z
        quad(c[5], c[1], c[3], c[7]), // right +x
        quad(c[0], c[4], c[6], c[2]), // left -x
        quad(c[6], c[7], c[3], c[2]), // top +y
        quad(c[0], c[1], c[5], c[4]), // bottom -y
    ];
    Ok(solid(faces, scope))
}

fn check_segments(what: &str, k: usize, min: usize) -> Result<(), String> {
    if k < min || k > MAX_SEGMENTS {
        return Err(format!(
            "{what} must be between {min} and {MAX_SEGMENTS} (got {k})"
        ));
    }
    Ok(())
}

/// A cylinder in the scope: its axis along the scope's y, its base the
/// ellipse inscribed in the scope's x-z rectangle, `segments` sides; n-gon
/// caps and quads around.
pub(crate) fn cylinder_in(
    points: &mut Points,
    scope: &Scope,
    segments: usize,
) -> Result<Geometry, String> {
    check_segments("a cylinder's segments", segments, 3)?;
    if !check_scope(scope) {
        return Ok(Geometry::empty(3));
    }
    let (rx, rz, h) = (scope.size.x / 2.0, scope.size.z / 2.0, scope.size.y);
    let mut bottom = Vec::with_capacity(segments);
    let mut top = Vec::with_capacity(segments);
    for i in 0..segments {
        let a = std::f64::consts::TAU * i as f64 / segments as f64;
        // Counter-clockwise seen from +y: x = cos, z = -sin.
        let (x, z) = (rx + rx * a.cos(), rz - rz * a.sin());
        bottom.push(points.add(scope.to_world(DVec3::new(x, 0.0, z)))?);
        top.push(points.add(scope.to_world(DVec3::new(x, h, z)))?);
    }
    let mut faces = Vec::with_capacity(segments + 2);
    for i in 0..segments {
        let j = (i + 1) % segments;
        faces.push(quad(bottom[i], bottom[j], top[j], top[i]));
    }
    let mut b = bottom.clone();
    b.reverse();
    faces.push(Face { pts: top, seam: 0 });
    faces.push(Face { pts: b, seam: 0 });
    Ok(solid(faces, scope))
}

/// A UV sphere (an ellipsoid) inscribed in the scope: `slices` around the
/// scope's y, `stacks` from pole to pole; triangles at the poles, quads
/// elsewhere.
pub(crate) fn sphere_in(
    points: &mut Points,
    scope: &Scope,
    slices: usize,
    stacks: usize,
) -> Result<Geometry, String> {
    check_segments("a sphere's slices", slices, 3)?;
    check_segments("a sphere's stacks", stacks, 2)?;
    if !check_scope(scope) {
        return Ok(Geometry::empty(3));
    }
    let r = scope.size / 2.0;
    let at = |polar: f64, az: f64| {
        let (sp, cp) = polar.sin_cos();
        r + DVec3::new(r.x * sp * az.cos(), r.y * cp, -r.z * sp * az.sin())
    };
    let north = points.add(scope.to_world(r + DVec3::new(0.0, r.y, 0.0)))?;
    let south = points.add(scope.to_world(r - DVec3::new(0.0, r.y, 0.0)))?;
    let mut rings = Vec::with_capacity(stacks - 1);
    for k in 1..stacks {
        let polar = std::f64::consts::PI * k as f64 / stacks as f64;
        let mut ring = Vec::with_capacity(slices);
        for i in 0..slices {
            let az = std::f64::consts::TAU * i as f64 / slices as f64;
            ring.push(points.add(scope.to_world(at(polar, az)))?);
        }
        rings.push(ring);
    }
    let mut faces = Vec::new();
    // Azimuth grows counter-clockwise seen from +y; polar grows downwards.
    for i in 0..slices {
        let j = (i + 1) % slices;
        faces.push(Face {
            pts: vec![north, rings[0][i], rings[0][j]],
            seam: 0,
        });
        for k in 0..rings.len() - 1 {
            let (u, l) = (&rings[k], &rings[k + 1]);
            faces.push(quad(u[i], l[i], l[j], u[j]));
        }
        let last = &rings[rings.len() - 1];
        faces.push(Face {
            pts: vec![south, last[j], last[i]],
            seam: 0,
        });
    }
    Ok(solid(faces, scope))
}

/// A polygon soup fitted into the scope: its bounding box mapped onto the
/// scope's box (a zero extent maps to the scope's origin plane), on new
/// points.
pub(crate) fn mesh_in(
    points: &mut Points,
    scope: &Scope,
    soup: &PolygonSoup,
) -> Result<Geometry, String> {
    if soup.positions.is_empty() || !check_scope_finite(scope) {
        return Ok(Geometry::empty(3));
    }
    if soup.positions.iter().any(|p| !p.is_finite()) {
        return Err("the mesh has a vertex that is not finite".into());
    }
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for &p in &soup.positions {
        lo = lo.min(p);
        hi = hi.max(p);
    }
    let ext = hi - lo;
    let scale = |e: f64, s: f64| if e > 0.0 { s / e } else { 0.0 };
    let k = DVec3::new(
        scale(ext.x, scope.size.x),
        scale(ext.y, scope.size.y),
        scale(ext.z, scope.size.z),
    );
    let mut ids = Vec::with_capacity(soup.positions.len());
    for &p in &soup.positions {
        ids.push(points.add(scope.to_world((p - lo) * k))?);
    }
    let mut g = Geometry::empty(3);
    for (f, face) in soup.faces.iter().enumerate() {
        let mut pts = Vec::with_capacity(face.len());
        for &i in face {
            let id = ids.get(i as usize).ok_or_else(|| {
                format!(
                    "face {} of the mesh uses vertex {i}, which does not exist",
                    f + 1
                )
            })?;
            pts.push(*id);
        }
        if pts.len() >= 3 {
            g.faces.push(Face { pts, seam: 0 });
        }
    }
    if !scope.is_right_handed() {
        for f in &mut g.faces {
            f.pts.reverse();
        }
    }
    Ok(g)
}

fn check_scope_finite(scope: &Scope) -> bool {
    scope.origin.is_finite()
        && scope.axes.iter().all(|a| a.is_finite())
        && scope.size.is_finite()
        && scope.size.min_element() >= 0.0
}

/// One planar polygon (dim 2) on new points at world positions `corners`.
pub(crate) fn polygon(points: &mut Points, corners: &[DVec3]) -> Result<Geometry, String> {
    if corners.len() < 3 {
        return Err(format!(
            "a polygon needs at least 3 corners (got {})",
            corners.len()
        ));
    }
    let mut pts = Vec::with_capacity(corners.len());
    for &c in corners {
        pts.push(points.add(c)?);
    }
    let mut g = Geometry::empty(2);
    g.faces.push(Face { pts, seam: 0 });
    Ok(g)
}

/// One planar polygon (dim 2) with corners given in the scope's frame.
pub(crate) fn polygon_in(
    points: &mut Points,
    scope: &Scope,
    corners: &[DVec3],
) -> Result<Geometry, String> {
    let world: Vec<DVec3> = corners.iter().map(|&c| scope.to_world(c)).collect();
    polygon(points, &world)
}
