//! The extrusion of faces (dim 2) into a polyhedron.

use std::collections::HashMap;

use glam::DVec3;

use super::geometry::{newell, Face, Geometry};
use super::points::Points;
use super::primitives::quad;
use super::{show, PointId};

/// Extrudes faces (dim 2) by `h` along unit `dir` into a polyhedron: the
/// base faces reversed on the original ids, the top faces on new points
/// moved by h·dir, a quad on every boundary edge (an edge of one face).
/// The faces point outwards for either sign of `h`.
pub(crate) fn extrude(
    points: &mut Points,
    geom: &Geometry,
    dir: DVec3,
    h: f64,
) -> Result<Geometry, String> {
    if geom.dim != 2 {
        return Err(format!(
            "only faces can be extruded (this shape has dimension {})",
            geom.dim
        ));
    }
    if !h.is_finite() || !dir.is_finite() || h == 0.0 || dir.length_squared() == 0.0 {
        return Err(format!(
            "an extrusion needs a finite non-zero height and direction (got {h})"
        ));
    }
    let offset = dir * h;
    let mut total = DVec3::ZERO;
    for f in &geom.faces {
        for &p in &f.pts {
            points.check(p)?;
        }
        total += newell(points, &f.pts);
    }
    let orient = total.dot(offset);
    if geom.faces.is_empty() {
        return Ok(Geometry::empty(3));
    }
    if !orient.is_finite() {
        return Err(format!(
            "an extrusion of {} makes a solid too large to measure",
            show(h)
        ));
    }
    if orient == 0.0 {
        return Err("the extrusion direction lies in the plane of the faces".into());
    }
    let up = orient > 0.0;
    let mut top_of: HashMap<PointId, PointId> = HashMap::new();
    let mut count: HashMap<(PointId, PointId), u32> = HashMap::new();
    for f in &geom.faces {
        let m = f.pts.len();
        for i in 0..m {
            let (a, b) = (f.pts[i], f.pts[(i + 1) % m]);
            *count.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    let mut out = Geometry::empty(3);
    let mut sides = Vec::new();
    let mut tops = Vec::new();
    for f in &geom.faces {
        let mut top = Vec::with_capacity(f.pts.len());
        for &p in &f.pts {
            let t = match top_of.get(&p) {
                Some(&t) => t,
                None => {
                    let t = points.add(points.get(p) + offset)?;
                    top_of.insert(p, t);
                    t
                }
            };
            top.push(t);
        }
        let m = f.pts.len();
        for i in 0..m {
            let (a, b) = (f.pts[i], f.pts[(i + 1) % m]);
            if count.get(&(a.min(b), a.max(b))) != Some(&1) {
                continue;
            }
            let (ta, tb) = (top[i], top[(i + 1) % m]);
            sides.push(if up {
                quad(a, b, tb, ta)
            } else {
                quad(b, a, ta, tb)
            });
        }
        let mut base = f.pts.clone();
        if up {
            base.reverse();
        } else {
            top.reverse();
        }
        out.faces.push(Face {
            pts: base,
            seam: f.seam,
        });
        tops.push(Face {
            pts: top,
            seam: f.seam,
        });
    }
    out.faces.extend(tops);
    out.faces.extend(sides);
    Ok(out)
}
