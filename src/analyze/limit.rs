//! Limit positions and normals of a subdivided mesh (`subdivide --limit`,
//! issue 43, item 2), from the scheme's own eigen-analysis: the limit
//! stencil (the left eigenvector of 1) and the tangent stencils of each
//! side that [`super::star`] measures through the engine around a vertex
//! of each kind present (its valence, whether it is on the boundary, which
//! of its edges are sharp for ever, whether it is a sharp vertex). No
//! table of masks is written here: the weights are the grammar's.
//!
//! A stencil's places `(sector, i, j)` are read on the mesh around each
//! vertex: the centre, its edge neighbours `(t, 1, 0)` in order around it
//! (counter-clockwise; a boundary vertex's from the boundary edge with no
//! face before it, an interior vertex's with a sharp edge from its first
//! sharp edge, as the measured fan has them) and, on quads, the vertex
//! across each face `(t, 1, 1)`. Each side's tangents' cross product is
//! its normal, turned to the side its faces face. A vertex with one side
//! has one normal; on a crease or at a corner each side has its own, and
//! every face corner gets its side's ([`LimitSurface::corner_normals`]).

use std::collections::{BTreeMap, HashMap};

use glam::DVec3;

use crate::mesh::{Mesh, PolygonSoup};
use crate::surface::Grammar;
use crate::{Deadline, Error};

use super::star::{star_stencils, StarStencils};
use super::surface::{LabelWeight, Star};

/// Every vertex of a mesh (in the order of [`Mesh::to_quad_soup`]) at its
/// limit position, with its limit normals (unit length).
#[derive(Clone, Debug)]
pub struct LimitSurface {
    pub positions: Vec<DVec3>,
    /// One normal a vertex: its limit normal, or where its sides have
    /// their own (a crease, a corner), the mean of theirs, normalised.
    pub normals: Vec<DVec3>,
    /// The normal of each face corner (the faces' corners in order), an
    /// index into [`LimitSurface::normal_values`]: its side's.
    pub corner_normals: Vec<u32>,
    /// The vertices' `normals` first, then the sides' own normals of the
    /// vertices that have more than one side.
    pub normal_values: Vec<DVec3>,
    /// Vertices (soup indices) on some side of which the eigenvalues do
    /// not show the scheme C1 (see [`super::star`]).
    pub not_c1: Vec<u32>,
    /// For each vertex, the largest over its sides of the next eigenvalue's
    /// modulus over the smaller tangent eigenvalue: about the factor by
    /// which a normal estimated from the faces of a finer mesh approaches
    /// the limit normal with each step (1/2 at a regular vertex; 3/4 on a
    /// Loop boundary vertex of 4 faces, 0.64 at a Catmull-Clark dart of 4).
    pub ratio: Vec<f64>,
}

/// One vertex's neighbourhood in the stencils' order: its edge neighbours
/// around it and, on quads, the vertex across the face after each one.
struct Ring {
    edges: Vec<u32>,
    across: Vec<Option<u32>>,
    open: bool,
}

impl Ring {
    /// Faces around the vertex.
    fn n(&self) -> usize {
        self.across.len()
    }

    /// The edge neighbour `t` (modulo the faces on a closed ring).
    fn edge(&self, t: usize) -> u32 {
        if self.open {
            self.edges[t]
        } else {
            self.edges[t % self.n()]
        }
    }

    /// The vertex at the place of `w`, turned by `rot` sectors.
    fn at(&self, v: u32, rot: usize, w: &LabelWeight) -> Option<u32> {
        let t = w.sector + rot;
        match (w.i, w.j) {
            (i, j) if i == 0.0 && j == 0.0 => Some(v),
            (i, j) if i == 1.0 && j == 0.0 => {
                if self.open {
                    self.edges.get(t).copied()
                } else {
                    Some(self.edge(t))
                }
            }
            (i, j) if i == 1.0 && j == 1.0 => {
                if self.open {
                    *self.across.get(t)?
                } else {
                    self.across[t % self.n()]
                }
            }
            _ => None,
        }
    }
}

/// The ring of every vertex of `s`; `Err(v)` for a vertex whose faces do
/// not make one fan. Faces are counter-clockwise: in face (v, a, ..., b),
/// b comes after a around v.
fn rings(s: &PolygonSoup) -> Result<Vec<Ring>, usize> {
    let n = s.positions.len();
    // For each vertex: next corner -> (previous corner, the corner across).
    let mut after: Vec<HashMap<u32, (u32, Option<u32>)>> = vec![HashMap::new(); n];
    for f in s.faces.iter() {
        let k = f.len();
        for c in 0..k {
            let across = (k == 4).then(|| f[(c + 2) % k]);
            if after[f[c] as usize]
                .insert(f[(c + 1) % k], (f[(c + k - 1) % k], across))
                .is_some()
            {
                return Err(f[c] as usize);
            }
        }
    }
    (0..n)
        .map(|v| {
            let around = &after[v];
            let ends: Vec<u32> = around.values().map(|&(b, _)| b).collect();
            let starts: Vec<u32> = around
                .keys()
                .copied()
                .filter(|a| !ends.contains(a))
                .collect();
            let (first, open) = match starts.as_slice() {
                [] => (*around.keys().min().ok_or(v)?, false),
                [a] => (*a, true),
                _ => return Err(v),
            };
            let (mut edges, mut across) = (vec![first], Vec::new());
            let mut e = first;
            while let Some(&(next, d)) = around.get(&e) {
                across.push(d);
                e = next;
                if e == first || across.len() > around.len() {
                    break;
                }
                edges.push(e);
            }
            if across.len() != around.len() || (!open && e != first) {
                return Err(v);
            }
            Ok(Ring {
                edges,
                across,
                open,
            })
        })
        .collect()
}

/// The limit positions and normals of `m`, the output of the surface
/// grammar `g`, by the stencils [`star_stencils`] measures for `g` around
/// each kind of vertex `m` has. Refused, naming a vertex where there is
/// one: a dual or adaptive grammar; faces other than the grammar's; a
/// sharpness that is not infinite (a semi-sharp crease left after the
/// run); a vertex whose faces do not make one fan; a kind of vertex whose
/// analysis gives no limit or tangent stencils.
pub fn limit_surface(g: &Grammar, m: &Mesh, deadline: Deadline) -> Result<LimitSurface, Error> {
    let refuse = |msg: String| Err(Error::Failed(format!("--limit: {msg}")));
    if g.dual_at.is_some() || g.adaptive.is_some() {
        return refuse(
            "a dual or adaptive grammar has no limit stencils around a vertex (only primal \
             schemes, such as Catmull-Clark and Loop, have them here)"
                .into(),
        );
    }
    let (soup, verts) = m.quad_soup_with_vertices();
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
    let rings = match rings(&soup) {
        Ok(r) => r,
        Err(v) => {
            return refuse(format!(
                "the faces around vertex {} do not make one fan (a non-manifold or isolated \
                 vertex)",
                v + 1
            ))
        }
    };
    // Each vertex's star, and how far its ring is turned from the fan's.
    let mut kinds: Vec<(Star, usize)> = Vec::with_capacity(rings.len());
    for (v, ring) in rings.iter().enumerate() {
        let mv = verts[v];
        let s = m.vertex_sharpness(mv);
        if s > 0.0 && s.is_finite() {
            return refuse(format!(
                "vertex {} has sharpness {s} after the run: limit positions are computed for \
                 smooth vertices and infinitely sharp creases and corners only, not for \
                 semi-sharp ones (run more steps, or make it `inf`)",
                v + 1
            ));
        }
        let n = ring.n();
        let mut sharp = Vec::new();
        for t in 0..ring.edges.len() {
            let w = verts[ring.edges[t] as usize];
            let Some(h) = m.find_halfedge(mv, w) else {
                continue;
            };
            let e = h.edge();
            let s = m.edge_sharpness(e);
            if s <= 0.0 || m.is_boundary_edge(e) {
                continue;
            }
            if s.is_finite() {
                return refuse(format!(
                    "the edge from vertex {} to vertex {} has sharpness {s} after the run: \
                     limit positions are computed for smooth vertices and infinitely sharp \
                     creases and corners only, not for semi-sharp ones (run more steps, or \
                     make it `inf`)",
                    v + 1,
                    ring.edges[t] + 1
                ));
            }
            sharp.push(t);
        }
        if !ring.open && n < 3 {
            return refuse(format!(
                "vertex {} has {n} faces around it; a stencil needs 3 or more",
                v + 1
            ));
        }
        let rot = if ring.open {
            0
        } else {
            sharp.first().copied().unwrap_or(0)
        };
        let mut sharp: Vec<usize> = sharp.iter().map(|&t| (t + n - rot) % n).collect();
        sharp.sort_unstable();
        let star = Star {
            n,
            open: ring.open,
            sharp,
            corner: s > 0.0,
        };
        kinds.push((star, rot));
    }
    let mut stencils: BTreeMap<Star, StarStencils> = BTreeMap::new();
    for (star, _) in &kinds {
        if stencils.contains_key(star) {
            continue;
        }
        match star_stencils(g, star, deadline)? {
            Ok(s) => {
                stencils.insert(star.clone(), s);
            }
            Err(why) => {
                let v = kinds.iter().position(|(s, _)| s == star).unwrap_or(0);
                return refuse(format!("vertex {} ({}): {why}", v + 1, describe(star)));
            }
        }
    }
    let p = |i: u32| soup.positions[i as usize];
    let mut positions = Vec::with_capacity(rings.len());
    let mut normals = Vec::with_capacity(rings.len());
    let mut side_normals: Vec<Vec<(usize, usize, DVec3)>> = Vec::with_capacity(rings.len());
    let mut not_c1 = Vec::new();
    let mut ratio = Vec::with_capacity(rings.len());
    for (v, (ring, (star, rot))) in rings.iter().zip(&kinds).enumerate() {
        let v = v as u32;
        let st = &stencils[star];
        let apply = |weights: &[LabelWeight]| -> Result<DVec3, Error> {
            let mut sum = DVec3::ZERO;
            for w in weights.iter().filter(|w| w.weight != 0.0) {
                let Some(x) = ring.at(v, *rot, w) else {
                    return Err(Error::Failed(format!(
                        "--limit: the stencil of vertex {} ({}) reaches ({}, {}, {}), beyond \
                         its first ring",
                        v + 1,
                        describe(star),
                        w.sector,
                        w.i,
                        w.j
                    )));
                };
                sum += w.weight * p(x);
            }
            Ok(sum)
        };
        positions.push(apply(&st.limit)?);
        let mut mine = Vec::new();
        let mut worst: f64 = 0.0;
        for side in &st.sides {
            let normal = apply(&side.tangents[0])?
                .cross(apply(&side.tangents[1])?)
                .normalize_or_zero();
            // The side the side's faces face: the sum of their corners'
            // cross products.
            let facing: DVec3 = (side.first..side.first + side.sectors)
                .map(|k| {
                    let k = k + rot;
                    (p(ring.edge(k)) - p(v)).cross(p(ring.edge(k + 1)) - p(v))
                })
                .sum();
            let normal = if normal.dot(facing) < 0.0 {
                -normal
            } else {
                normal
            };
            mine.push((side.first + rot, side.sectors, normal));
            if !side.c1 && not_c1.last() != Some(&v) {
                not_c1.push(v);
            }
            let low = side.eigenvalues[0].min(side.eigenvalues[1]);
            worst = worst.max(side.next / low);
        }
        ratio.push(worst);
        normals.push(mine.iter().map(|s| s.2).sum::<DVec3>().normalize_or_zero());
        side_normals.push(mine);
    }
    // Each corner's side: the sector its face is, around its vertex.
    let mut normal_values = normals.clone();
    let mut first_side = vec![0u32; rings.len()];
    for (v, sides) in side_normals.iter().enumerate() {
        if sides.len() > 1 {
            first_side[v] = normal_values.len() as u32;
            normal_values.extend(sides.iter().map(|s| s.2));
        }
    }
    let mut corner_normals = Vec::with_capacity(soup.faces.indices().len());
    for f in soup.faces.iter() {
        let k = f.len();
        for c in 0..k {
            let v = f[c] as usize;
            let sides = &side_normals[v];
            if sides.len() <= 1 {
                corner_normals.push(v as u32);
                continue;
            }
            let ring = &rings[v];
            let n = ring.n();
            let t = (0..n)
                .find(|&t| ring.edge(t) == f[(c + 1) % k])
                .unwrap_or(0);
            let s = sides
                .iter()
                .position(|&(first, count, _)| (t + n - first % n) % n < count)
                .unwrap_or(0);
            corner_normals.push(first_side[v] + s as u32);
        }
    }
    Ok(LimitSurface {
        positions,
        normals,
        corner_normals,
        normal_values,
        not_c1,
        ratio,
    })
}

/// A star in words, for messages.
fn describe(s: &Star) -> String {
    let kind = if s.open && s.sharp.is_empty() {
        "on the boundary".to_string()
    } else if s.is_corner() {
        "a corner".to_string()
    } else if s.sharp.len() == 2 {
        "on a crease".to_string()
    } else if s.sharp.len() == 1 {
        "a dart".to_string()
    } else {
        "smooth".to_string()
    };
    format!("{} faces, {kind}", s.n)
}
