//! Component splits: which faces a [`Selector`] takes, the faces, edges
//! and vertices of a shape with their scopes, and the scopes fitted
//! around geometry (a lot's, a bounding box).

use std::collections::HashSet;

use glam::DVec3;

use super::geometry::{newell, Geometry, Scope};
use super::points::Points;
use super::PointId;

/// Which faces a component split takes, by the direction of their normal in
/// the shape's scope.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum Selector {
    Front,
    Back,
    Left,
    Right,
    Top,
    Bottom,
    /// Front, back, left and right.
    Side,
    /// Top and bottom.
    Horizontal,
    /// The same as `Side`.
    Vertical,
    All,
}

impl Selector {
    pub fn parse(s: &str) -> Option<Selector> {
        Some(match s {
            "front" => Selector::Front,
            "back" => Selector::Back,
            "left" => Selector::Left,
            "right" => Selector::Right,
            "top" => Selector::Top,
            "bottom" => Selector::Bottom,
            "side" => Selector::Side,
            "horizontal" => Selector::Horizontal,
            "vertical" => Selector::Vertical,
            "all" => Selector::All,
            _ => return None,
        })
    }

    /// The direction a normal (in the scope's frame) faces, by its dominant
    /// component: +z front, -z back, -x left, +x right, +y top, -y bottom;
    /// on ties y wins, then z, then x.
    pub fn classify(n: DVec3) -> Selector {
        let a = n.abs();
        if a.y >= a.z && a.y >= a.x {
            if n.y >= 0.0 {
                Selector::Top
            } else {
                Selector::Bottom
            }
        } else if a.z >= a.x {
            if n.z >= 0.0 {
                Selector::Front
            } else {
                Selector::Back
            }
        } else if n.x >= 0.0 {
            Selector::Right
        } else {
            Selector::Left
        }
    }

    /// Whether a face classified as `c` is selected.
    pub fn takes(self, c: Selector) -> bool {
        match self {
            Selector::All => true,
            Selector::Side | Selector::Vertical => matches!(
                c,
                Selector::Front | Selector::Back | Selector::Left | Selector::Right
            ),
            Selector::Horizontal => matches!(c, Selector::Top | Selector::Bottom),
            s => s == c,
        }
    }
}

/// A frame with x along `x` and z along `z` (made orthogonal), y = z × x,
/// fitted around `pts`: origin at the minimum corner, size the extent.
fn frame_around(points: &Points, pts: &[PointId], x: DVec3, z: DVec3) -> Option<Scope> {
    let z = z.try_normalize()?;
    let x = (x - x.dot(z) * z).try_normalize()?;
    let y = z.cross(x);
    Some(fit(points, pts.iter().copied(), [x, y, z]))
}

fn fit(points: &Points, pts: impl Iterator<Item = PointId>, axes: [DVec3; 3]) -> Scope {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for p in pts {
        let q = points.get(p);
        let l = DVec3::new(q.dot(axes[0]), q.dot(axes[1]), q.dot(axes[2]));
        lo = lo.min(l);
        hi = hi.max(l);
    }
    if !lo.is_finite() || !hi.is_finite() {
        return Scope {
            origin: DVec3::ZERO,
            axes,
            size: DVec3::ZERO,
        };
    }
    Scope {
        origin: lo.x * axes[0] + lo.y * axes[1] + lo.z * axes[2],
        axes,
        size: hi - lo,
    }
}

/// The scope of a lot (faces, dim 2, made by the axiom): x along the first
/// face's first edge, y the faces' normal (Newell, summed), z = x × y,
/// fitted around the faces (size.y = 0). None for faces without area.
pub(crate) fn lot_scope(points: &Points, geom: &Geometry) -> Option<Scope> {
    let f = geom.faces.first()?;
    let y = geom
        .faces
        .iter()
        .map(|f| newell(points, &f.pts))
        .sum::<DVec3>()
        .try_normalize()?;
    let m = f.pts.len();
    let edge = (0..m)
        .map(|i| points.get(f.pts[(i + 1) % m]) - points.get(f.pts[i]))
        .find(|e| e.length_squared() > 0.0)?;
    let x = (edge - edge.dot(y) * y).try_normalize()?;
    let mut s = fit(points, geom.point_ids(), [x, y, x.cross(y)]);
    s.size.y = 0.0;
    Some(s)
}

/// The faces of `geom` that `sel` takes, each as a one-face geometry (dim
/// 2, the same point ids) with its scope: x along the face's first edge,
/// z its normal (Newell), y = z × x, fitted around the face (size.z = 0).
/// Degenerate faces (no area) are left out.
pub(crate) fn comp_faces(
    points: &Points,
    geom: &Geometry,
    scope: &Scope,
    sel: Selector,
) -> Vec<(Geometry, Scope)> {
    let mut out = Vec::new();
    for f in &geom.faces {
        let n = newell(points, &f.pts);
        if !n.is_finite() || n.length_squared() == 0.0 {
            continue;
        }
        let local = DVec3::new(
            n.dot(scope.axes[0]),
            n.dot(scope.axes[1]),
            n.dot(scope.axes[2]),
        );
        if !sel.takes(Selector::classify(local)) {
            continue;
        }
        let m = f.pts.len();
        let edge = (0..m)
            .map(|i| points.get(f.pts[(i + 1) % m]) - points.get(f.pts[i]))
            .find(|e| e.length_squared() > 0.0);
        let Some(edge) = edge else { continue };
        let Some(mut s) = frame_around(points, &f.pts, edge, n) else {
            continue;
        };
        s.size.z = 0.0;
        let mut g = Geometry::empty(2);
        g.faces.push(f.clone());
        out.push((g, s));
    }
    out
}

/// The unique undirected edges of `geom` (of its faces, or its edges), in
/// first-seen order, each a one-edge geometry (dim 1) with a scope whose x
/// runs along the edge (y the parent's y made orthogonal where it can be).
pub(crate) fn comp_edges(
    points: &Points,
    geom: &Geometry,
    scope: &Scope,
) -> Vec<(Geometry, Scope)> {
    let mut seen = HashSet::new();
    let mut list = Vec::new();
    for f in &geom.faces {
        let m = f.pts.len();
        for i in 0..m {
            list.push([f.pts[i], f.pts[(i + 1) % m]]);
        }
    }
    list.extend(geom.edges.iter().copied());
    let mut out = Vec::new();
    for [a, b] in list {
        if a == b || !seen.insert((a.min(b), a.max(b))) {
            continue;
        }
        let (pa, pb) = (points.get(a), points.get(b));
        let Some(x) = (pb - pa).try_normalize() else {
            continue;
        };
        let y = [
            scope.axes[1],
            scope.axes[2],
            scope.axes[0],
            DVec3::Y,
            DVec3::Z,
        ]
        .into_iter()
        .find_map(|c| (c - c.dot(x) * x).try_normalize())
        .unwrap_or(DVec3::Y);
        let z = x.cross(y);
        let mut g = Geometry::empty(1);
        g.edges.push([a, b]);
        out.push((
            g,
            Scope {
                origin: pa,
                axes: [x, y, z],
                size: DVec3::new((pb - pa).length(), 0.0, 0.0),
            },
        ));
    }
    out
}

/// Every point of `geom` once (first-use order), each a one-point geometry
/// (dim 0) with the parent's axes, at the point, of size 0.
pub(crate) fn comp_vertices(
    points: &Points,
    geom: &Geometry,
    scope: &Scope,
) -> Vec<(Geometry, Scope)> {
    geom.unique_points()
        .into_iter()
        .map(|p| {
            let mut g = Geometry::empty(0);
            g.verts.push(p);
            (
                g,
                Scope {
                    origin: points.get(p),
                    axes: scope.axes,
                    size: DVec3::ZERO,
                },
            )
        })
        .collect()
}

/// The box on `axes` around `geom` (origin at its minimum corner); an empty
/// geometry gives a scope at the world origin of size 0.
pub(crate) fn bounding_scope(points: &Points, geom: &Geometry, axes: [DVec3; 3]) -> Scope {
    fit(points, geom.point_ids(), axes)
}
