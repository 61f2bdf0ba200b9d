//! A copy of a geometry moved by an affine map, on new points.

use std::collections::HashMap;

use glam::{DAffine3, DMat3};

use super::geometry::{Face, Geometry};
use super::points::Points;
use super::PointId;

/// A copy of `geom` moved by `m`, on new points (a moved shape no longer
/// shares vertices). A mirroring transform reverses the faces so that they
/// still face outwards.
pub(crate) fn transform(
    points: &mut Points,
    geom: &Geometry,
    m: &DAffine3,
) -> Result<Geometry, String> {
    let mat: DMat3 = m.matrix3;
    if !mat.is_finite() || !m.translation.is_finite() {
        return Err("a transformation with a non-finite entry".into());
    }
    let mut map: HashMap<PointId, PointId> = HashMap::new();
    let mut moved = |points: &mut Points, p: PointId| -> Result<PointId, String> {
        if let Some(&q) = map.get(&p) {
            return Ok(q);
        }
        points.check(p)?;
        let q = points.add(m.transform_point3(points.get(p)))?;
        map.insert(p, q);
        Ok(q)
    };
    let flip = mat.determinant() < 0.0;
    let mut out = Geometry::empty(geom.dim);
    for f in &geom.faces {
        let mut pts = Vec::with_capacity(f.pts.len());
        for &p in &f.pts {
            pts.push(moved(points, p)?);
        }
        if flip {
            pts.reverse();
        }
        out.faces.push(Face { pts, seam: f.seam });
    }
    for &[a, b] in &geom.edges {
        out.edges.push([moved(points, a)?, moved(points, b)?]);
    }
    for &v in &geom.verts {
        out.verts.push(moved(points, v)?);
    }
    Ok(out)
}
