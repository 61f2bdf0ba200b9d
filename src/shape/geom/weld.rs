//! A smoothing group's faces welded into one polygon soup ([`Welded`]),
//! its walls refined so that both sides match.

use std::collections::{HashMap, HashSet};

use glam::DVec3;

use crate::mesh::PolygonSoup;

use super::cut::{check_plane, dedup_ring, split_eps, split_polygon};
use super::geometry::{Face, Geometry};
use super::points::Points;
use super::PointId;

/// A smoothing group's faces gathered into one polygon soup.
#[derive(Clone, Debug, Default)]
pub(crate) struct Welded {
    /// Positions of the used points, faces (polygons, counter-clockwise).
    pub soup: PolygonSoup,
    /// Soup vertex -> its point.
    pub point_of: Vec<PointId>,
    /// Soup face -> the index of its member shape in the group.
    pub tags: Vec<u32>,
    /// Soup vertex: shared with a shape outside the group.
    pub protected_vertex: Vec<bool>,
    /// Soup face: all its vertices protected.
    pub protected_face: Vec<bool>,
}

/// The cut ids of a geometry's seam faces (its caps), each once, in
/// increasing order.
pub(crate) fn seams_of(geom: &Geometry) -> impl Iterator<Item = u32> {
    let ks: std::collections::BTreeSet<u32> = geom
        .faces
        .iter()
        .filter(|f| f.seam >= 2)
        .map(|f| f.seam / 2)
        .collect();
    ks.into_iter()
}

/// `faces` with every face of a cut k that has planes in `seam_planes`
/// cut by those planes in order, both pieces kept: the two sides of a wall
/// cut later on one side only get the same pieces with the same ids.
fn refine(
    points: &mut Points,
    faces: &[Face],
    seam_planes: &HashMap<u32, Vec<(DVec3, f64)>>,
) -> Result<Vec<Face>, String> {
    let mut out = Vec::with_capacity(faces.len());
    for f in faces {
        for &p in &f.pts {
            points.check(p)?;
        }
        let planes = match seam_planes.get(&(f.seam / 2)) {
            Some(pl) if f.seam >= 2 && !pl.is_empty() => pl,
            _ => {
                out.push(f.clone());
                continue;
            }
        };
        let mut pieces = vec![f.clone()];
        for &(n, d) in planes {
            let eps = split_eps(d);
            check_plane(n, d, eps)?;
            let mut next = Vec::with_capacity(pieces.len() + 1);
            for piece in pieces {
                if piece.pts.len() < 3 {
                    continue;
                }
                let s: Vec<f64> = piece
                    .pts
                    .iter()
                    .map(|&p| n.dot(points.get(p)) - d)
                    .collect();
                let side: Vec<i8> = s
                    .iter()
                    .map(|&x| {
                        if x > eps {
                            1
                        } else if x < -eps {
                            -1
                        } else {
                            0
                        }
                    })
                    .collect();
                if side.contains(&-1) && side.contains(&1) {
                    let mut below = Vec::new();
                    split_polygon(points, &piece, (n, d), &s, &side, &mut below, &mut next)?;
                    next.extend(below);
                } else {
                    next.push(piece);
                }
            }
            pieces = next;
        }
        out.extend(pieces);
    }
    Ok(out)
}

/// A polygon's cycle written from its smallest id, for comparing cycles
/// whatever vertex they start at.
fn cycle_key(poly: &[PointId]) -> Vec<PointId> {
    let Some(start) = (0..poly.len()).min_by_key(|&i| poly[i]) else {
        return Vec::new();
    };
    poly[start..]
        .iter()
        .chain(&poly[..start])
        .copied()
        .collect()
}

/// The members' faces as one soup.
///
/// First every face of a cut k (members' and `others'`) is refined by the
/// planes `seam_planes` records for k (the later splits that crossed a
/// shape holding a part of k's wall), in order, so that both sides of the
/// wall have the same pieces; every face is resolved (no T-junctions).
/// Then a member's face of cut k is dropped when another member holds the
/// same cycle reversed (an internal wall of the group) and k is not loose;
/// every other face is kept (a wall towards a shape outside the group or
/// removed, or a part of a wall the other side does not cover). For a
/// loose cut both faces of each mirrored pair stay, and the members on
/// the upper side (seam 2k + 1) get their own copies of those faces'
/// points that no member without cut-k faces holds (a zero-width slit,
/// attached where another member holds the points). Points used by
/// `others` are protected.
pub(crate) fn weld(
    points: &mut Points,
    members: &[&Geometry],
    others: &[&Geometry],
    loose: &HashSet<u32>,
    seam_planes: &HashMap<u32, Vec<(DVec3, f64)>>,
) -> Result<Welded, String> {
    if members.len() > u32::MAX as usize {
        return Err("too many shapes in a smoothing group".into());
    }
    // The points of the shapes outside the group, their walls refined.
    let mut other_points = HashSet::new();
    for g in others {
        if g.faces
            .iter()
            .any(|f| f.seam >= 2 && seam_planes.contains_key(&(f.seam / 2)))
        {
            let faces = refine(points, &g.faces, seam_planes)?;
            other_points.extend(faces.iter().flat_map(|f| f.pts.iter().copied()));
        } else {
            other_points.extend(g.faces.iter().flat_map(|f| f.pts.iter().copied()));
        }
        other_points.extend(g.edges.iter().flat_map(|e| e.iter().copied()));
        other_points.extend(g.verts.iter().copied());
    }
    // The members' faces, refined and resolved.
    let mut kept: Vec<Vec<Face>> = Vec::with_capacity(members.len());
    let mut buf = Vec::new();
    for g in members {
        let mut fs = Vec::new();
        for f in refine(points, &g.faces, seam_planes)? {
            points.resolve(&f.pts, &mut buf);
            dedup_ring(&mut buf);
            if buf.len() >= 3 {
                fs.push(Face {
                    pts: buf.clone(),
                    seam: f.seam,
                });
            }
        }
        kept.push(fs);
    }
    // Mirrored pairs: a cut-k face of one member whose reversed cycle
    // another member holds as a cut-k face.
    let mut cycles: HashMap<(u32, Vec<PointId>), Vec<usize>> = HashMap::new();
    for (i, fs) in kept.iter().enumerate() {
        for f in fs.iter().filter(|f| f.seam >= 2) {
            cycles
                .entry((f.seam / 2, cycle_key(&f.pts)))
                .or_default()
                .push(i);
        }
    }
    let mut mirrored: Vec<Vec<bool>> = Vec::with_capacity(kept.len());
    for (i, fs) in kept.iter().enumerate() {
        let mut m = Vec::with_capacity(fs.len());
        for f in fs {
            let hit = f.seam >= 2 && {
                let mut rev = f.pts.clone();
                rev.reverse();
                cycles
                    .get(&(f.seam / 2, cycle_key(&rev)))
                    .is_some_and(|who| who.iter().any(|&j| j != i))
            };
            m.push(hit);
        }
        mirrored.push(m);
    }
    // Loose cuts with mirrored pairs: the upper side gets its own copies of
    // the pairs' points.
    let mut loose_cuts: Vec<u32> = Vec::new();
    for (fs, m) in kept.iter().zip(&mirrored) {
        for (f, &hit) in fs.iter().zip(m) {
            if hit && loose.contains(&(f.seam / 2)) && !loose_cuts.contains(&(f.seam / 2)) {
                loose_cuts.push(f.seam / 2);
            }
        }
    }
    loose_cuts.sort_unstable();
    for k in loose_cuts {
        let with_cut: Vec<bool> = kept
            .iter()
            .map(|fs| fs.iter().any(|f| f.seam / 2 == k && f.seam >= 2))
            .collect();
        let mut held = HashSet::new();
        for (i, fs) in kept.iter().enumerate() {
            if !with_cut[i] {
                for f in fs {
                    held.extend(f.pts.iter().copied());
                }
            }
        }
        let mut upper = Vec::new();
        let mut dup: HashMap<PointId, PointId> = HashMap::new();
        for (i, fs) in kept.iter().enumerate() {
            let mut any = false;
            for (f, &hit) in fs.iter().zip(&mirrored[i]) {
                if !hit || f.seam != 2 * k + 1 {
                    continue;
                }
                any = true;
                for &p in &f.pts {
                    if !held.contains(&p) && !dup.contains_key(&p) {
                        let q = points.add(points.get(p))?;
                        dup.insert(p, q);
                    }
                }
            }
            if any {
                upper.push(i);
            }
        }
        for i in upper {
            for f in &mut kept[i] {
                for p in &mut f.pts {
                    if let Some(&q) = dup.get(p) {
                        *p = q;
                    }
                }
            }
        }
    }
    let mut w = Welded::default();
    let mut index: HashMap<PointId, u32> = HashMap::new();
    for (i, (fs, m)) in kept.into_iter().zip(mirrored).enumerate() {
        for (f, hit) in fs.into_iter().zip(m) {
            if hit && !loose.contains(&(f.seam / 2)) {
                continue;
            }
            let mut face = Vec::with_capacity(f.pts.len());
            for p in f.pts {
                let v = match index.get(&p) {
                    Some(&v) => v,
                    None => {
                        let v = w.point_of.len() as u32;
                        index.insert(p, v);
                        w.point_of.push(p);
                        w.soup.positions.push(points.get(p));
                        w.protected_vertex.push(other_points.contains(&p));
                        v
                    }
                };
                face.push(v);
            }
            w.protected_face
                .push(face.iter().all(|&v| w.protected_vertex[v as usize]));
            w.soup.faces.push(face);
            w.tags.push(i as u32);
        }
    }
    w.soup.face_lines = vec![0; w.soup.faces.len()];
    w.soup.vertex_lines = vec![0; w.soup.positions.len()];
    Ok(w)
}
