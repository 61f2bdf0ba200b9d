//! Limit positions and normals of a subdivided mesh (`subdivide --limit`,
//! issue 43, item 2), from the scheme's own eigen-analysis: the limit
//! stencil (the left eigenvector of 1) and the two tangent stencils (left
//! eigenvectors of the subdominant λ1 = λ2) that [`super::surface`]
//! measures through the engine around a vertex of each valence present.
//! No table of masks is written here: the weights are those `analyze`
//! reports for the grammar that made the mesh.
//!
//! A stencil's places `(sector, i, j)` are read on the mesh around each
//! vertex: the centre, its edge neighbours `(t, 1, 0)` in order around it
//! and, on quads, the vertex across each face `(t, 1, 1)`. The tangents'
//! cross product is the normal, turned to the side the faces around the
//! vertex face.

use std::collections::HashMap;

use glam::DVec3;

use crate::mesh::PolygonSoup;
use crate::surface::Grammar;
use crate::{Deadline, Error};

use super::surface::{analyze_at, LabelWeight};

/// Every vertex of a mesh at its limit position, with its limit normal
/// (unit length).
#[derive(Clone, Debug)]
pub struct LimitSurface {
    pub positions: Vec<DVec3>,
    pub normals: Vec<DVec3>,
}

/// One vertex's neighbourhood in the stencils' order: its edge neighbours
/// around it and, on quads, the vertex across the face after each one.
struct Ring {
    edges: Vec<u32>,
    across: Vec<Option<u32>>,
}

/// The ring of every vertex of `s`, `None` on the boundary. Faces are
/// counter-clockwise: in face (v, a, ..., b), b comes after a around v.
fn rings(s: &PolygonSoup) -> Vec<Option<Ring>> {
    let n = s.positions.len();
    // For each vertex: next corner -> (previous corner, the corner across).
    let mut after: Vec<HashMap<u32, (u32, Option<u32>)>> = vec![HashMap::new(); n];
    for f in s.faces.iter() {
        let k = f.len();
        for c in 0..k {
            let across = (k == 4).then(|| f[(c + 2) % k]);
            after[f[c] as usize].insert(f[(c + 1) % k], (f[(c + k - 1) % k], across));
        }
    }
    (0..n)
        .map(|v| {
            let around = &after[v];
            let &first = around.keys().min()?;
            let (mut edges, mut across) = (Vec::new(), Vec::new());
            let mut e = first;
            loop {
                let &(next, d) = around.get(&e)?;
                edges.push(e);
                across.push(d);
                e = next;
                if e == first {
                    break;
                }
                if edges.len() > around.len() {
                    return None;
                }
            }
            (edges.len() == around.len()).then_some(Ring { edges, across })
        })
        .collect()
}

/// The vertex at `place` of `ring` around `v`, valence `n`.
fn at(v: u32, ring: &Ring, w: &LabelWeight) -> Option<u32> {
    let n = ring.edges.len();
    match (w.i, w.j) {
        (i, j) if i == 0.0 && j == 0.0 => Some(v),
        (i, j) if i == 1.0 && j == 0.0 => Some(ring.edges[w.sector % n]),
        (i, j) if i == 1.0 && j == 1.0 => ring.across[w.sector % n],
        _ => None,
    }
}

/// The limit positions and normals of `soup`, the output of the surface
/// grammar `g`, by the stencils `analyze` measures for `g` at the
/// valences of `soup`'s vertices. Refused: a dual or adaptive grammar, a
/// mesh with a boundary (limit rules there are the boundary curve's, not
/// measured), and a valence whose analysis gives no limit or no pair of
/// tangent stencils.
pub fn limit_surface(
    g: &Grammar,
    soup: &PolygonSoup,
    deadline: Deadline,
) -> Result<LimitSurface, Error> {
    let refuse = |m: String| Err(Error::Failed(format!("--limit: {m}")));
    if g.dual_at.is_some() || g.adaptive.is_some() {
        return refuse(
            "a dual or adaptive grammar has no limit stencils around a vertex (only primal \
             schemes, such as Catmull-Clark and Loop, have them here)"
                .into(),
        );
    }
    let quads = g.block_used_at.is_some();
    let sides = if quads { 4 } else { 3 };
    if let Some(f) = soup.faces.iter().position(|f| f.len() != sides) {
        return refuse(format!(
            "the stencils are measured on {}, and face {} has {} sides",
            if quads { "quads" } else { "triangles" },
            f + 1,
            soup.faces[f].len()
        ));
    }
    let rings = rings(soup);
    if let Some(v) = rings.iter().position(Option::is_none) {
        return refuse(format!(
            "vertex {} is on a boundary: limit positions and normals are computed for \
             interior vertices only (a closed mesh), from the stencils `analyze` measures",
            v + 1
        ));
    }
    let rings: Vec<Ring> = rings.into_iter().map(Option::unwrap).collect();
    let mut valences: Vec<usize> = rings.iter().map(|r| r.edges.len()).collect();
    valences.sort_unstable();
    valences.dedup();
    if let Some(&n) = valences.first().filter(|&&n| n < 3) {
        return refuse(format!(
            "a vertex has valence {n}; a stencil needs 3 or more"
        ));
    }
    let report = analyze_at(g, "", deadline, &valences, &mut |_, _| {})?;
    let mut stencils = HashMap::new();
    for v in report.valences {
        if let Some(why) = v.skipped {
            return refuse(format!("valence {}: {why}", v.n));
        }
        if v.limit.is_empty() || v.tangents.len() != 2 {
            return refuse(format!(
                "valence {}: the analysis gives no limit stencil or no pair of tangent \
                 stencils (λ1 = λ2 real)",
                v.n
            ));
        }
        stencils.insert(v.n, (v.limit, v.tangents));
    }
    let p = |i: u32| soup.positions[i as usize];
    let mut positions = Vec::with_capacity(rings.len());
    let mut normals = Vec::with_capacity(rings.len());
    for (v, ring) in rings.iter().enumerate() {
        let v = v as u32;
        let (limit, tangents) = &stencils[&ring.edges.len()];
        let apply = |weights: &[LabelWeight]| -> Result<DVec3, Error> {
            let mut sum = DVec3::ZERO;
            for w in weights {
                let Some(x) = at(v, ring, w) else {
                    return Err(Error::Failed(format!(
                        "--limit: the stencil at valence {} reaches ({}, {}, {}), beyond the \
                         vertex's first ring",
                        ring.edges.len(),
                        w.sector,
                        w.i,
                        w.j
                    )));
                };
                sum += w.weight * p(x);
            }
            Ok(sum)
        };
        positions.push(apply(limit)?);
        let normal = apply(&tangents[0])?.cross(apply(&tangents[1])?);
        // The side the faces around v face: the sum of their corners'
        // cross products.
        let n = ring.edges.len();
        let facing: DVec3 = (0..n)
            .map(|k| (p(ring.edges[k]) - p(v)).cross(p(ring.edges[(k + 1) % n]) - p(v)))
            .sum();
        let normal = normal.normalize_or_zero();
        normals.push(if normal.dot(facing) < 0.0 {
            -normal
        } else {
            normal
        });
    }
    Ok(LimitSurface { positions, normals })
}
