//! Plane cuts of a geometry (pieces on both sides, solids closed again
//! with caps) and splits across parallel planes.

use std::collections::{HashMap, HashSet};

use glam::DVec3;

use super::geometry::{newell, Face, Geometry};
use super::points::Points;
use super::PointId;

pub(super) fn check_plane(n: DVec3, d: f64, eps: f64) -> Result<(), String> {
    if !n.is_finite() || n.length_squared() == 0.0 || !d.is_finite() || !eps.is_finite() {
        return Err(format!(
            "a cut plane needs a finite non-zero normal and offset (got normal ({}, {}, {}), offset {d})",
            n.x, n.y, n.z
        ));
    }
    Ok(())
}

fn seam_pair(cut: u32) -> Result<(u32, u32), String> {
    if cut == 0 || cut > (u32::MAX - 1) / 2 {
        return Err(format!("cut number {cut} is out of range"));
    }
    Ok((2 * cut, 2 * cut + 1))
}

/// One node of a face's ring while it is split: a vertex, or the point
/// where an edge crosses the plane.
#[derive(Clone, Copy)]
struct Node {
    id: PointId,
    /// For a vertex: -1 below, 0 on, 1 above. Unused for a crossing.
    side: i8,
    /// For a crossing: Some(true) from above to below, Some(false) from
    /// below to above.
    down: Option<bool>,
    /// Where a crossing lies along the cut line, and the tie-break for two
    /// crossings at one on-plane vertex.
    key: (f64, f64),
}

/// Splits one polygon (any shape) by the plane: every piece on each side.
/// On-plane vertices count as infinitesimally below for the topology (so
/// every crossing is proper) and stand for their own crossing points.
pub(super) fn split_polygon(
    points: &mut Points,
    face: &Face,
    (n, d): (DVec3, f64),
    s: &[f64],
    side: &[i8],
    below: &mut Vec<Face>,
    above: &mut Vec<Face>,
) -> Result<(), String> {
    let pts = &face.pts;
    let m = pts.len();
    let dir = n.cross(newell(points, pts));
    let mut ring: Vec<Node> = Vec::with_capacity(m * 2);
    for i in 0..m {
        let j = (i + 1) % m;
        ring.push(Node {
            id: pts[i],
            side: side[i],
            down: None,
            key: (0.0, 0.0),
        });
        let (bi, bj) = (side[i] <= 0, side[j] <= 0);
        if bi == bj {
            continue;
        }
        let (lo, hi) = if bi { (i, j) } else { (j, i) };
        let (id, tie) = if side[lo] == 0 {
            let v = points.get(pts[lo]);
            (pts[lo], dir.dot(points.get(pts[hi]) - v) / s[hi])
        } else {
            (points.cut(pts[i], pts[j], n, d)?, 0.0)
        };
        ring.push(Node {
            id,
            side: 0,
            down: Some(!bi),
            key: (dir.dot(points.get(id)), tie),
        });
    }
    let mut crossings: Vec<usize> = (0..ring.len())
        .filter(|&i| ring[i].down.is_some())
        .collect();
    if !crossings.len().is_multiple_of(2) {
        return Err("a face crosses a cut plane an odd number of times".into());
    }
    crossings.sort_by(|&a, &b| {
        let (ka, kb) = (ring[a].key, ring[b].key);
        ka.0.total_cmp(&kb.0).then(ka.1.total_cmp(&kb.1))
    });
    let mut partner = vec![usize::MAX; ring.len()];
    for pair in crossings.chunks(2) {
        partner[pair[0]] = pair[1];
        partner[pair[1]] = pair[0];
    }
    let len = ring.len();
    for (entering_down, side_sign, out) in [(true, -1i8, &mut *below), (false, 1i8, &mut *above)] {
        let mut visited = vec![false; len];
        for start in 0..len {
            if ring[start].down != Some(entering_down) || visited[start] {
                continue;
            }
            let mut piece: Vec<PointId> = Vec::new();
            let mut strict = false;
            let mut i = start;
            let mut steps = 0usize;
            loop {
                visited[i] = true;
                piece.push(ring[i].id);
                i = (i + 1) % len;
                while ring[i].down != Some(!entering_down) {
                    if ring[i].down.is_none() {
                        piece.push(ring[i].id);
                        strict |= ring[i].side == side_sign;
                    }
                    i = (i + 1) % len;
                    steps += 1;
                    if steps > 4 * len {
                        return Err("a face could not be split by a cut plane".into());
                    }
                }
                visited[i] = true;
                piece.push(ring[i].id);
                let j = partner[i];
                if j >= len || ring[j].down != Some(entering_down) {
                    return Err(
                        "a face could not be split by a cut plane (is it self-intersecting?)"
                            .into(),
                    );
                }
                if j == start {
                    break;
                }
                if visited[j] {
                    return Err(
                        "a face could not be split by a cut plane (is it self-intersecting?)"
                            .into(),
                    );
                }
                i = j;
                steps += 1;
                if steps > 4 * len {
                    return Err("a face could not be split by a cut plane".into());
                }
            }
            dedup_ring(&mut piece);
            if strict && piece.len() >= 3 {
                out.push(Face {
                    pts: piece,
                    seam: face.seam,
                });
            }
        }
    }
    Ok(())
}

/// Removes consecutive repeats, around the end too.
pub(super) fn dedup_ring(poly: &mut Vec<PointId>) {
    poly.dedup();
    while poly.len() > 1 && poly.first() == poly.last() {
        poly.pop();
    }
}

/// Cuts `geom` by the plane {x : n·x = d}: (below = {n·x <= d}, above).
///
/// Vertices within `eps` of the plane are on it and belong to both sides
/// without a cut. Faces of any shape are split into all their pieces. A
/// polyhedron (dim 3) is closed again with caps: the loops of its cut
/// outline, seam `2 cut` with normal +n below and the same ids reversed,
/// seam `2 cut + 1`, above. A cap with a hole is refused; an outline that
/// does not close (an open input mesh) gets no cap. Faces (dim 2) share
/// the cut points and get no caps; edges (dim 1) are split; points (dim 0)
/// go by side, on-plane ones below.
pub(crate) fn plane_cut(
    points: &mut Points,
    geom: &Geometry,
    n: DVec3,
    d: f64,
    cut: u32,
    eps: f64,
) -> Result<(Geometry, Geometry), String> {
    check_plane(n, d, eps)?;
    let (seam_below, seam_above) = seam_pair(cut)?;
    let eps = eps.abs();
    let mut below = Geometry::empty(geom.dim);
    let mut above = Geometry::empty(geom.dim);
    let sd = |points: &Points, p: PointId| n.dot(points.get(p)) - d;
    let side_of = |s: f64| -> i8 {
        if s > eps {
            1
        } else if s < -eps {
            -1
        } else {
            0
        }
    };
    for &v in &geom.verts {
        points.check(v)?;
        if side_of(sd(points, v)) <= 0 {
            below.verts.push(v);
        } else {
            above.verts.push(v);
        }
    }
    for &[a, b] in &geom.edges {
        points.check(a)?;
        points.check(b)?;
        let (sa, sb) = (side_of(sd(points, a)), side_of(sd(points, b)));
        if sa * sb < 0 {
            let c = points.cut(a, b, n, d)?;
            if sa < 0 {
                below.edges.push([a, c]);
                above.edges.push([c, b]);
            } else {
                above.edges.push([a, c]);
                below.edges.push([c, b]);
            }
        } else if sa > 0 || sb > 0 {
            above.edges.push([a, b]);
        } else {
            below.edges.push([a, b]);
        }
    }
    // A solid with no vertex strictly on one side is not cut: it lies on
    // the other side whole (a piece thinner than `eps`, all of its
    // vertices on the plane, goes below), with no caps.
    if geom.dim >= 3 {
        let mut strictly = [false; 2];
        for f in &geom.faces {
            for &p in &f.pts {
                points.check(p)?;
                match side_of(sd(points, p)) {
                    -1 => strictly[0] = true,
                    1 => strictly[1] = true,
                    _ => {}
                }
            }
        }
        if !strictly[0] || !strictly[1] {
            let whole = if strictly[1] { &mut above } else { &mut below };
            whole.faces = geom
                .faces
                .iter()
                .filter(|f| f.pts.len() >= 3)
                .cloned()
                .collect();
            return Ok((below, above));
        }
    }
    for face in &geom.faces {
        for &p in &face.pts {
            points.check(p)?;
        }
        if face.pts.len() < 3 {
            continue;
        }
        let s: Vec<f64> = face.pts.iter().map(|&p| sd(points, p)).collect();
        let side: Vec<i8> = s.iter().map(|&x| side_of(x)).collect();
        let has_below = side.contains(&-1);
        let has_above = side.contains(&1);
        if !has_below && !has_above {
            // In the plane: a solid's face goes to the side it bounds.
            if geom.dim >= 3 && newell(points, &face.pts).dot(n) < 0.0 {
                above.faces.push(face.clone());
            } else {
                below.faces.push(face.clone());
            }
        } else if !has_above {
            below.faces.push(face.clone());
        } else if !has_below {
            above.faces.push(face.clone());
        } else {
            split_polygon(
                points,
                face,
                (n, d),
                &s,
                &side,
                &mut below.faces,
                &mut above.faces,
            )?;
        }
    }
    if geom.dim >= 3 && !below.faces.is_empty() && !above.faces.is_empty() {
        // On the plane: within eps, or a cut point (off by rounding only).
        let on = |p: PointId| {
            let slack = eps.max(1e-12 * (1.0 + d.abs() + points.get(p).abs().max_element()));
            sd(points, p).abs() <= slack
        };
        let caps = cap_loops(points, &below.faces, n, on);
        for lp in caps {
            let o = newell(points, &lp).dot(n);
            if o < 0.0 {
                return Err(format!(
                    "cut {cut} would leave a cap with a hole (the plane crosses the shape around \
                     an opening); caps with holes are not supported"
                ));
            }
            if o == 0.0 {
                continue;
            }
            let mut rev = lp.clone();
            rev.reverse();
            below.faces.push(Face {
                pts: lp,
                seam: seam_below,
            });
            above.faces.push(Face {
                pts: rev,
                seam: seam_above,
            });
        }
    }
    Ok((below, above))
}

/// The loops that close `faces` (a solid's part on one side) in the cut
/// plane of normal `n`: the in-plane edges no other face uses the other
/// way, reversed and chained. Where outlines meet at a point, each loop
/// turns as far left as it can, so that the loops stay apart. Chains that
/// do not close are left out.
fn cap_loops(
    points: &Points,
    faces: &[Face],
    n: DVec3,
    on: impl Fn(PointId) -> bool,
) -> Vec<Vec<PointId>> {
    let mut directed = HashSet::new();
    for f in faces {
        let m = f.pts.len();
        for i in 0..m {
            directed.insert((f.pts[i], f.pts[(i + 1) % m]));
        }
    }
    let mut edges: Vec<(PointId, PointId)> = Vec::new();
    let mut out: HashMap<PointId, Vec<usize>> = HashMap::new();
    for f in faces {
        let m = f.pts.len();
        for i in 0..m {
            let (u, v) = (f.pts[i], f.pts[(i + 1) % m]);
            if u != v && on(u) && on(v) && !directed.contains(&(v, u)) {
                out.entry(v).or_default().push(edges.len());
                edges.push((v, u));
            }
        }
    }
    let mut used = vec![false; edges.len()];
    let mut loops = Vec::new();
    for e in 0..edges.len() {
        if used[e] {
            continue;
        }
        let start = edges[e].0;
        let mut lp = vec![start];
        let mut cur = e;
        let mut closed = false;
        for _ in 0..=edges.len() {
            used[cur] = true;
            let (from, to) = edges[cur];
            if to == start {
                closed = true;
                break;
            }
            lp.push(to);
            let din = points.get(to) - points.get(from);
            let turn = |k: usize| {
                let dout = points.get(edges[k].1) - points.get(to);
                n.dot(din.cross(dout)).atan2(din.dot(dout))
            };
            let candidates = out.get(&to).map(Vec::as_slice).unwrap_or(&[]);
            let best = candidates
                .iter()
                .copied()
                .filter(|&k| !used[k])
                .max_by(|&a, &b| turn(a).total_cmp(&turn(b)));
            match best {
                Some(k) => cur = k,
                None => break,
            }
        }
        if closed && lp.len() >= 3 {
            loops.push(lp);
        }
    }
    loops
}

/// The plane {x : n·x = d} of a split at distance `c` from `origin` along
/// `axis`: the normal is `axis` normalised. [`split`] cuts with exactly
/// these planes, so a caller that records them (for [`weld`](fn@super::weld)'s seam
/// refinement) gets the same bits.
pub(crate) fn plane_of(origin: DVec3, axis: DVec3, c: f64) -> (DVec3, f64) {
    let n = axis.normalize_or_zero();
    (n, n.dot(origin) + c)
}

/// The distance within which a split's plane at offset `d` takes vertices
/// as on it.
pub(super) fn split_eps(d: f64) -> f64 {
    1e-9 * (1.0 + d.abs())
}

/// Splits `geom` across planes normal to `axis` (unit) at distances `cuts`
/// (increasing) from `origin`: `cuts.len() + 1` pieces, lowest first, made
/// sequentially (the whole at the first plane, the part above it at the
/// next, ...). Piece i and piece i + 1 share cut `first_cut + i`. Pieces may
/// be empty.
pub(crate) fn split(
    points: &mut Points,
    geom: &Geometry,
    origin: DVec3,
    axis: DVec3,
    cuts: &[f64],
    first_cut: u32,
) -> Result<Vec<Geometry>, String> {
    if !origin.is_finite() || !axis.is_finite() || axis.length_squared() == 0.0 {
        return Err("a split needs a finite origin and a non-zero axis".into());
    }
    for w in cuts.windows(2) {
        if w[0] > w[1] {
            return Err(format!(
                "split positions must increase ({} comes before {})",
                w[0], w[1]
            ));
        }
    }
    if let Some(c) = cuts.iter().find(|c| !c.is_finite()) {
        return Err(format!("split position {c} is not finite"));
    }
    let mut pieces = Vec::with_capacity(cuts.len() + 1);
    let mut rest = geom.clone();
    for (i, &c) in cuts.iter().enumerate() {
        let cut = u32::try_from(i)
            .ok()
            .and_then(|i| first_cut.checked_add(i))
            .ok_or_else(|| "too many cuts".to_string())?;
        let (n, d) = plane_of(origin, axis, c);
        let (lo, hi) = plane_cut(points, &rest, n, d, cut, split_eps(d))?;
        pieces.push(lo);
        rest = hi;
    }
    pieces.push(rest);
    Ok(pieces)
}
