//! Subdivide of a smoothing group (paper 003, §4.2): the group's faces,
//! welded into one polygon soup, are subdivided as one mesh by a surface
//! grammar, with the faces and vertices it shares with shapes outside the
//! group protected (Algorithm 2 with Algorithm 3's sets), and each output
//! face tagged with the member shape whose face it was cut from.
//!
//! The schemes are the project's own grammars (`lsystems/surfaces/`),
//! run by the one grammar engine: `Subdivide` is a grammar run on a mesh
//! built from the welded soup, with the protection passed to the run.
#![allow(dead_code)]

use crate::mesh::{Mesh, PolygonSoup, VertexId};
use crate::surface::{Grammar, Protection};
use crate::Deadline;

/// The subdivision schemes `Subdivide` knows by name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Scheme {
    /// Kobbelt's √3 (the paper's choice, CGAL's `Sqrt3_subdivision`).
    Sqrt3,
    /// Loop's triangle quadrisection.
    Loop,
    /// Catmull-Clark on a tri-quad mesh; output quads.
    CatmullClark,
}

/// The names of the schemes, in the order messages list them.
pub(crate) const SCHEME_NAMES: [&str; 3] = ["sqrt3", "loop", "catmull-clark"];

impl Scheme {
    /// The scheme called `name`, if there is one.
    pub(crate) fn from_name(name: &str) -> Option<Scheme> {
        match name {
            "sqrt3" => Some(Scheme::Sqrt3),
            "loop" => Some(Scheme::Loop),
            "catmull-clark" => Some(Scheme::CatmullClark),
            _ => None,
        }
    }

    /// The grammar file's name and text, built into the program.
    fn source(self) -> (&'static str, &'static str) {
        match self {
            Scheme::Sqrt3 => (
                "sqrt3.lsys",
                include_str!("../../lsystems/surfaces/sqrt3.lsys"),
            ),
            Scheme::Loop => (
                "loop.lsys",
                include_str!("../../lsystems/surfaces/loop.lsys"),
            ),
            Scheme::CatmullClark => (
                "catmull-clark.lsys",
                include_str!("../../lsystems/surfaces/catmull-clark.lsys"),
            ),
        }
    }

    /// The checked grammar. Its `mesh:` line is not used.
    pub(crate) fn grammar(self) -> Result<Grammar, String> {
        let (name, text) = self.source();
        crate::surface::load_str(name, text, &[]).map_err(|e| e.to_string())
    }
}

/// The grammar of the scheme called `name` ("sqrt3", "loop",
/// "catmull-clark"), or a message listing the names.
pub(crate) fn scheme(name: &str) -> Result<Grammar, String> {
    match Scheme::from_name(name) {
        Some(s) => s.grammar(),
        None => Err(format!(
            "unknown subdivision scheme `{name}`: expected {}, {} or {}",
            SCHEME_NAMES[0], SCHEME_NAMES[1], SCHEME_NAMES[2]
        )),
    }
}

/// A subdivided smoothing group.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Smoothed {
    /// The subdivided mesh: triangles for √3 and Loop, the blocks as
    /// quads for Catmull-Clark (as `subgram subdivide` writes them).
    pub soup: PolygonSoup,
    /// Each output face: the tag of the input face it was cut from.
    pub tags: Vec<u32>,
    /// Each output vertex: the input vertex it is, when it is one and
    /// its position is bit for bit the input one (protected vertices
    /// always are); `None` for a new or moved vertex.
    pub origin: Vec<Option<u32>>,
}

/// Subdivides `soup` by `steps` steps of `grammar`, leaving the protected
/// faces and vertices as they are (see [`Protection`]: no face point in a
/// protected face, no shift of a protected vertex or of a corner of a
/// protected face, no edge split or flipped next to a protected face or
/// between two protected vertices). `tags` gives each soup face's tag,
/// which the faces cut from it keep; `protected_face` and
/// `protected_vertex` are by soup face and soup vertex. A protected
/// polygon protects all the triangles the mesh makes of it.
///
/// With nothing protected this is [`Grammar::run`] on the soup's mesh,
/// bit for bit. A soup that is not an oriented 2-manifold, a grammar that
/// refuses the mesh, a limit or the deadline give a message, never a
/// panic.
pub(crate) fn subdivide(
    grammar: &Grammar,
    soup: &PolygonSoup,
    tags: &[u32],
    protected_vertex: &[bool],
    protected_face: &[bool],
    steps: usize,
    deadline: &Deadline,
) -> Result<Smoothed, String> {
    let (nv, nf) = (soup.positions.len(), soup.faces.len());
    if tags.len() != nf || protected_face.len() != nf || protected_vertex.len() != nv {
        return Err(format!(
            "subdivide: {nv} vertices and {nf} faces, but {} tags, {} face and {} vertex protection flags",
            tags.len(),
            protected_face.len(),
            protected_vertex.len()
        ));
    }
    let mut mesh = Mesh::from_soup_tagged(soup, tags).map_err(|e| {
        format!(
            "subdivide: the group's welded mesh is refused: {e} (the faces of a smoothing \
                 group make one oriented surface: shapes that overlap, such as a mass and a \
                 face taken from it by `comp`, or one shape made twice, are smoothed in \
                 groups of their own, named by `set(smoothingGroup, ...)`)"
        )
    })?;
    // The mesh's faces come in the soup's order; its vertices are the
    // soup's, with the same ids.
    let ranges = Mesh::soup_face_ranges(soup);
    let mut faces = vec![false; ranges.last().map_or(0, |r| r.end as usize)];
    for (range, _) in ranges.iter().zip(protected_face).filter(|(_, &p)| p) {
        for f in range.clone() {
            faces[f as usize] = true;
        }
    }
    let protection = Protection {
        faces,
        vertices: protected_vertex.to_vec(),
    };
    let mut run = grammar
        .start_protected(&mut mesh, protection)
        .map_err(|e| grammar.render_error(&e))?;
    run.set_deadline(Some(*deadline));
    run.steps(steps, |_| {})
        .map_err(|e| grammar.render_error(&e))?;
    let (out, tags, verts) = mesh.quad_soup_tagged_with_vertices();
    let origin = verts
        .iter()
        .zip(&out.positions)
        .map(|(&v, p)| {
            let VertexId(j) = v;
            let same = soup
                .positions
                .get(j as usize)
                .is_some_and(|q| q.to_array().map(f64::to_bits) == p.to_array().map(f64::to_bits));
            same.then_some(j)
        })
        .collect();
    Ok(Smoothed {
        soup: out,
        tags,
        origin,
    })
}

#[cfg(test)]
mod tests {
    use std::time::Duration;

    use glam::DVec3;

    use super::*;
    use crate::mesh::shapes;

    fn forever() -> Deadline {
        Deadline::after(Duration::from_secs(3600))
    }

    fn soup(positions: Vec<DVec3>, faces: Vec<Vec<u32>>) -> PolygonSoup {
        PolygonSoup {
            positions,
            faces: faces.into(),
            ..Default::default()
        }
    }

    /// The cube of `lsystems/meshes/cube.obj`: six quads, counter-clockwise
    /// seen from outside.
    fn cube_quads() -> PolygonSoup {
        let positions = (0..8)
            .map(|i| {
                let c = |b: u32| if i >> b & 1 == 1 { 1.0 } else { -1.0 };
                DVec3::new(c(0), c(1), c(2))
            })
            .collect();
        let faces = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        soup(positions, faces.iter().map(|f| f.to_vec()).collect())
    }

    /// The same cube with each quad cut along its first diagonal.
    fn cube_triangles() -> PolygonSoup {
        cube_quads().fanned()
    }

    /// Two unit cubes stacked along y and welded: what splitting a
    /// 1 x 2 x 1 box in two welds back to. Vertex `(x, y, z)` is
    /// `4y + 2z + x`; ten quads, the two on the side x = 1 last.
    fn stacked_cubes() -> PolygonSoup {
        let id = |x: u32, y: u32, z: u32| 4 * y + 2 * z + x;
        let positions = (0..12u32)
            .map(|i| DVec3::new((i & 1) as f64, (i / 4) as f64, (i >> 1 & 1) as f64))
            .collect();
        let mut faces = vec![
            vec![id(0, 0, 0), id(1, 0, 0), id(1, 0, 1), id(0, 0, 1)],
            vec![id(0, 2, 0), id(0, 2, 1), id(1, 2, 1), id(1, 2, 0)],
        ];
        for k in 0..2 {
            faces.push(vec![
                id(0, k, 0),
                id(0, k, 1),
                id(0, k + 1, 1),
                id(0, k + 1, 0),
            ]);
            faces.push(vec![
                id(0, k, 0),
                id(0, k + 1, 0),
                id(1, k + 1, 0),
                id(1, k, 0),
            ]);
            faces.push(vec![
                id(0, k, 1),
                id(1, k, 1),
                id(1, k + 1, 1),
                id(0, k + 1, 1),
            ]);
        }
        for k in 0..2 {
            faces.push(vec![
                id(1, k, 0),
                id(1, k + 1, 0),
                id(1, k + 1, 1),
                id(1, k, 1),
            ]);
        }
        soup(positions, faces)
    }

    /// A flat triangle grid whose interior vertices are moved about in
    /// the plane, so that no two triangles are alike.
    fn jittered_triangle_grid(n: usize) -> PolygonSoup {
        let mut s = shapes::triangle_grid(n, n);
        for (i, p) in s.positions.iter_mut().enumerate() {
            let inside = p.x > 0.0 && p.x < 1.0 && p.y > 0.0 && p.y < 1.0;
            if inside {
                let t = i as f64;
                *p += DVec3::new((t * 1.7).sin(), (t * 2.3).cos(), 0.0) * (0.25 / n as f64);
            }
        }
        s
    }

    fn unprotected(s: &PolygonSoup, steps: usize, g: &Grammar) -> Smoothed {
        let tags: Vec<u32> = (0..s.faces.len() as u32).collect();
        let (pv, pf) = (vec![false; s.positions.len()], vec![false; s.faces.len()]);
        subdivide(g, s, &tags, &pv, &pf, steps, &forever()).unwrap_or_else(|e| panic!("{e}"))
    }

    /// Nothing protected: the same run as the grammar's own on the same
    /// mesh, positions and faces bit for bit.
    #[test]
    fn without_protection_it_is_the_grammars_run() {
        let cases: [(&str, usize); 3] = [("sqrt3", 3), ("loop", 2), ("catmull-clark", 2)];
        let meshes = [
            ("box of 12 triangles", cube_triangles()),
            ("box of 6 quads", cube_quads()),
            ("open triangle grid", shapes::triangle_grid(3, 3)),
            ("open quad grid", shapes::quad_grid(3, 3)),
        ];
        for (name, most) in cases {
            let g = scheme(name).unwrap();
            for (what, s) in &meshes {
                for steps in 1..=most {
                    let got = unprotected(s, steps, &g);
                    let mut m = Mesh::from_soup(s).unwrap();
                    g.run(&mut m, steps, |_| {}).unwrap();
                    let want = m.to_quad_soup();
                    assert!(
                        got.soup == want,
                        "{name}, {what}, {steps} steps: the soups differ"
                    );
                    assert_eq!(got.tags.len(), want.faces.len());
                }
            }
        }
    }

    /// `poly` is among `faces` (as the same cycle, from any corner), with
    /// tag `tag`.
    fn has_face(faces: &crate::mesh::Faces, tags: &[u32], poly: &[u32], tag: u32) -> bool {
        faces.iter().zip(tags).any(|(f, &t)| {
            t == tag
                && f.len() == poly.len()
                && (0..f.len()).any(|k| (0..f.len()).all(|i| f[(k + i) % f.len()] == poly[i]))
        })
    }

    /// One side of two welded cubes protected (its six vertices, and the
    /// two quads all of whose corners those are): after 1, 2 and 3 steps
    /// the protected vertices are where they were, bit for bit, and the
    /// protected quads are still faces with the same corners in the same
    /// order (as two triangles for the triangle schemes, as the quad for
    /// Catmull-Clark); the rest was subdivided and moved.
    #[test]
    fn protected_faces_and_vertices_are_left_as_they_are() {
        let s = stacked_cubes();
        // Every quad faces away from the middle of the box.
        let mid = DVec3::new(0.5, 1.0, 0.5);
        for f in &s.faces {
            let p = |k: usize| s.positions[f[k] as usize];
            let n = (p(1) - p(0)).cross(p(2) - p(0));
            assert!(n.dot(p(0) - mid) > 0.0, "{f:?} faces inwards");
        }
        let tags: Vec<u32> = (0..s.faces.len() as u32).map(|i| 100 + i).collect();
        let (pv, pf) = wall_at_x1(&s);
        assert_eq!(pf.iter().filter(|&&p| p).count(), 2);
        for name in SCHEME_NAMES {
            let g = scheme(name).unwrap();
            for steps in 1..=3 {
                let out = subdivide(&g, &s, &tags, &pv, &pf, steps, &forever())
                    .unwrap_or_else(|e| panic!("{name}: {e}"));
                let at = format!("{name}, {steps} steps");
                // Output vertex of each input vertex that is still there.
                let mut index = vec![None; s.positions.len()];
                for (k, o) in out.origin.iter().enumerate() {
                    if let Some(j) = o {
                        index[*j as usize] = Some(k as u32);
                    }
                }
                for (j, _) in pv.iter().enumerate().filter(|(_, &p)| p) {
                    let k = index[j].unwrap_or_else(|| panic!("{at}: vertex {j} moved"));
                    assert_eq!(out.soup.positions[k as usize], s.positions[j]);
                }
                let quads = name == "catmull-clark";
                for (i, f) in s.faces.iter().enumerate().filter(|(i, _)| pf[*i]) {
                    let f: Vec<u32> = f.iter().map(|&v| index[v as usize].unwrap()).collect();
                    let want = if quads {
                        vec![f.clone()]
                    } else {
                        vec![vec![f[0], f[1], f[2]], vec![f[0], f[2], f[3]]]
                    };
                    for p in want {
                        assert!(
                            has_face(&out.soup.faces, &out.tags, &p, tags[i]),
                            "{at}: protected face {i} lost its part {p:?}"
                        );
                    }
                }
                // The rest changed: no unprotected input vertex is where it
                // was, and there are more faces.
                for (j, _) in pv.iter().enumerate().filter(|(_, &p)| !p) {
                    assert!(index[j].is_none(), "{at}: vertex {j} did not move");
                }
                assert!(out.soup.faces.len() > 2 * s.faces.len(), "{at}");
                let m = Mesh::from_soup(&out.soup).unwrap_or_else(|e| panic!("{at}: {e}"));
                m.validate().unwrap();
            }
        }
    }

    /// Faces per tag: Loop cuts every triangle in four and Catmull-Clark
    /// every quad in four quads, each step (known counts, 4^n); √3 on a
    /// closed mesh splits every face in three and its flips trade halves
    /// between two faces, one face each (3^n). Every input face keeps its
    /// share, so the counts add up to the output's faces.
    #[test]
    fn every_input_face_keeps_its_share_of_faces() {
        let cases = [
            ("loop", cube_triangles(), 4usize),
            ("catmull-clark", cube_quads(), 4),
            ("sqrt3", cube_triangles(), 3),
        ];
        for (name, s, k) in cases {
            let g = scheme(name).unwrap();
            for steps in 1..=3u32 {
                let out = unprotected(&s, steps as usize, &g);
                let mut count = vec![0usize; s.faces.len()];
                for &t in &out.tags {
                    count[t as usize] += 1;
                }
                let each = k.pow(steps);
                assert!(
                    count.iter().all(|&c| c == each),
                    "{name}, {steps} steps: {count:?}, expected {each} each"
                );
                assert_eq!(count.iter().sum::<usize>(), out.soup.faces.len());
                if name == "catmull-clark" {
                    assert!(out.soup.faces.iter().all(|f| f.len() == 4));
                }
            }
        }
    }

    /// Twice the signed area of polygon `p` in the xy plane.
    fn area2(p: &[DVec3]) -> f64 {
        (0..p.len())
            .map(|i| {
                let (a, b) = (p[i], p[(i + 1) % p.len()]);
                a.x * b.y - a.y * b.x
            })
            .sum()
    }

    /// `p` clipped to the counter-clockwise triangle `t` (Sutherland and
    /// Hodgman), in the xy plane.
    fn clip(p: &[DVec3], t: [DVec3; 3]) -> Vec<DVec3> {
        let mut out = p.to_vec();
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            let side = |q: DVec3| (b.x - a.x) * (q.y - a.y) - (b.y - a.y) * (q.x - a.x);
            let input = std::mem::take(&mut out);
            for k in 0..input.len() {
                let (c, d) = (input[k], input[(k + 1) % input.len()]);
                let (sc, sd) = (side(c), side(d));
                if sc >= 0.0 {
                    out.push(c);
                }
                if (sc >= 0.0) != (sd >= 0.0) {
                    out.push(c + (d - c) * (sc / (sc - sd)));
                }
            }
        }
        out
    }

    /// √3's tags on a flat open grid, one step. A face split's faces lie
    /// inside the face they were cut from, but a flip turns the edge
    /// between two of them, and each of the two faces it makes lies half
    /// in one input face and half in the other: no output face of a
    /// flipped pair is inside one input face, so "contained in the face
    /// with its tag" would be false whichever tag it got. What holds is
    /// that every output face overlaps the input face whose tag it has
    /// (with positive area): each has the centroid of its tagged face as
    /// a corner, or lies inside it. A tag from any face that is not one
    /// of the two would fail.
    #[test]
    fn sqrt3_faces_overlap_the_face_whose_tag_they_have() {
        let s = jittered_triangle_grid(4);
        let g = scheme("sqrt3").unwrap();
        let out = unprotected(&s, 1, &g);
        assert_eq!(out.soup.faces.len(), 3 * s.faces.len());
        for (f, &t) in out.soup.faces.iter().zip(&out.tags) {
            let poly: Vec<DVec3> = f.iter().map(|&v| out.soup.positions[v as usize]).collect();
            let input = &s.faces[t as usize];
            let tri = [0, 1, 2].map(|k| s.positions[input[k] as usize]);
            assert!(area2(&tri) > 0.0 && area2(&poly) > 0.0);
            let shared = area2(&clip(&poly, tri));
            assert!(
                shared > 1e-3 * area2(&poly),
                "output face {f:?} does not overlap input face {t}: {shared}"
            );
        }
    }

    /// Protection as the shapes make it (vertices shared with shapes
    /// outside the group; the faces all of whose corners those are), drawn
    /// at random over closed and open meshes of triangles and quads: every
    /// scheme runs three steps without refusing anything, the result is an
    /// oriented 2-manifold (checked on the connectivity alone, with
    /// positions in general position), and the protected vertices are
    /// where they were. √3's masks are affine whatever the connectivity
    /// (their weights are normalised by the counts they read), so on the
    /// flat grids no face of its output is folded over.
    #[test]
    fn any_protection_gives_a_valid_mesh() {
        let meshes = [
            (stacked_cubes(), false),
            (cube_triangles(), false),
            (shapes::icosphere(1), false),
            (shapes::quad_grid(4, 3), true),
            (jittered_triangle_grid(4), true),
        ];
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut random = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        };
        for name in SCHEME_NAMES {
            let g = scheme(name).unwrap();
            for (s, flat) in &meshes {
                for density in [1, 2, 3, 4, 5, 6, 7, 8, 1, 3, 5, 7] {
                    let pv: Vec<bool> = (0..s.positions.len())
                        .map(|_| random() % 10 < density)
                        .collect();
                    let pf: Vec<bool> = s
                        .faces
                        .iter()
                        .map(|f| f.iter().all(|&v| pv[v as usize]))
                        .collect();
                    let tags = vec![0; s.faces.len()];
                    let at = format!("{name}, protected {pv:?}");
                    let out = subdivide(&g, s, &tags, &pv, &pf, 3, &forever())
                        .unwrap_or_else(|e| panic!("{at}: {e}"));
                    let general = PolygonSoup {
                        positions: (0..out.soup.positions.len())
                            .map(|_| {
                                let mut c = || (random() % 1_000_003) as f64;
                                DVec3::new(c(), c(), c())
                            })
                            .collect(),
                        ..out.soup.clone()
                    };
                    Mesh::from_soup(&general)
                        .and_then(|m| m.validate())
                        .unwrap_or_else(|e| panic!("{at}: {e}"));
                    let kept = out.origin.iter().flatten().filter(|&&j| pv[j as usize]);
                    assert_eq!(kept.count(), pv.iter().filter(|&&p| p).count(), "{at}");
                    if *flat && name == "sqrt3" {
                        for f in &out.soup.faces {
                            let p: Vec<DVec3> =
                                f.iter().map(|&v| out.soup.positions[v as usize]).collect();
                            assert!(area2(&p) > 0.0, "{at}: face {f:?} is folded");
                        }
                    }
                }
            }
        }
    }

    /// Subdivision commutes with translation: every mask is an affine
    /// combination, protected runs included, where a vertex next to a
    /// protected face can have fewer new neighbours or an odd valence
    /// than a whole step gives (Loop's and Catmull-Clark's rules are
    /// written so that their weights sum to one for any count).
    /// The vertices on the plane x = 1 and the faces all of whose corners
    /// are there: the wall a neighbouring shape shares, protected.
    fn wall_at_x1(s: &PolygonSoup) -> (Vec<bool>, Vec<bool>) {
        let pv: Vec<bool> = s.positions.iter().map(|p| p.x == 1.0).collect();
        let pf = s
            .faces
            .iter()
            .map(|f| f.iter().all(|&v| pv[v as usize]))
            .collect();
        (pv, pf)
    }

    #[test]
    fn protected_runs_commute_with_translation() {
        let s = stacked_cubes();
        let (pv, pf) = wall_at_x1(&s);
        let off = DVec3::new(10.0, -3.0, 7.0);
        let moved = PolygonSoup {
            positions: s.positions.iter().map(|&p| p + off).collect(),
            ..s.clone()
        };
        let tags = vec![0; s.faces.len()];
        for name in SCHEME_NAMES {
            let g = scheme(name).unwrap();
            for steps in 1..=3 {
                let a = subdivide(&g, &s, &tags, &pv, &pf, steps, &forever()).unwrap();
                let b = subdivide(&g, &moved, &tags, &pv, &pf, steps, &forever()).unwrap();
                assert_eq!(a.soup.faces, b.soup.faces, "{name}");
                for (p, q) in a.soup.positions.iter().zip(&b.soup.positions) {
                    let d = (*p + off - *q).abs().max_element();
                    assert!(d < 1e-12, "{name}, {steps} steps: {p} + {off} is not {q}");
                }
            }
        }
    }

    #[test]
    fn bad_groups_and_names_are_messages() {
        let g = scheme("sqrt3").unwrap();
        let d = forever();
        // Three faces on one edge: not a 2-manifold.
        let fin = soup(
            vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::NEG_Y, DVec3::Z],
            vec![vec![0, 1, 2], vec![1, 0, 3], vec![0, 1, 4]],
        );
        let e = subdivide(&g, &fin, &[0; 3], &[false; 5], &[false; 3], 1, &d).unwrap_err();
        assert!(e.contains("three or more faces"), "{e}");
        // Flags that do not fit the soup.
        let c = cube_quads();
        let e = subdivide(&g, &c, &[0; 6], &[false; 8], &[false; 5], 1, &d).unwrap_err();
        assert!(e.contains("6 faces"), "{e}");
        // A polygon of five sides: Catmull-Clark takes it whole, a quad a
        // corner.
        let cc = scheme("catmull-clark").unwrap();
        let pent = soup(
            (0..5)
                .map(|k| {
                    let a = k as f64 * std::f64::consts::TAU / 5.0;
                    DVec3::new(a.cos(), a.sin(), 0.0)
                })
                .collect(),
            vec![vec![0, 1, 2, 3, 4]],
        );
        let out = subdivide(&cc, &pent, &[0], &[false; 5], &[false], 1, &d).unwrap();
        assert_eq!(out.soup.faces.len(), 5);
        assert!(out.soup.faces.iter().all(|f| f.len() == 4));
        assert_eq!(out.tags, vec![0; 5]);
        // A deadline that has passed.
        let past = Deadline::after(Duration::ZERO);
        let e = subdivide(&g, &c, &[0; 6], &[false; 8], &[false; 6], 1, &past).unwrap_err();
        assert!(e.contains("time limit"), "{e}");
        let e = scheme("butterfly").unwrap_err();
        assert!(e.contains("sqrt3, loop or catmull-clark"), "{e}");
    }

    /// The triangles the mesh makes of each soup face are the ids
    /// `soup_face_ranges` gives: a protected polygon is all of them.
    #[test]
    fn soup_faces_map_to_their_triangles() {
        let mut s = stacked_cubes();
        let pent = (0..5).map(|k| 12 + k).collect::<Vec<u32>>();
        for k in 0..5 {
            let a = k as f64 * std::f64::consts::TAU / 5.0;
            s.positions.push(DVec3::new(5.0 + a.cos(), a.sin(), 0.0));
        }
        s.faces.push(pent);
        let tags: Vec<u32> = (0..s.faces.len() as u32).collect();
        let m = Mesh::from_soup_tagged(&s, &tags).unwrap();
        let ranges = Mesh::soup_face_ranges(&s);
        assert_eq!(ranges.last().unwrap().end as usize, m.face_count());
        for (i, r) in ranges.iter().enumerate() {
            assert_eq!(r.len(), s.faces[i].len() - 2);
            for f in r.clone() {
                let f = crate::mesh::FaceId(f);
                assert_eq!(m.tag(f), i as u32);
                for v in m.face_vertices(f) {
                    assert!(s.faces[i].contains(&v.0));
                }
            }
        }
    }
}
