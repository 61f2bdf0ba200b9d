//! The quad schemes of paper 000, §8, built on basic blocks: Doo-Sabin and
//! Peters (dual blocks), and 4-8 (bisection). Expected positions come from
//! the published masks, computed here from the input polygons.

use glam::DVec3;
use subgram::mesh::{shapes, Mesh, PolygonSoup};

use crate::support::*;

fn grammar(file: &str) -> subgram::surface::Grammar {
    subgram::surface::load_file(&lsys(file), &[]).unwrap_or_else(|e| panic!("{e}"))
}

fn run(file: &str, soup: &PolygonSoup, steps: usize) -> PolygonSoup {
    let g = grammar(file);
    let mut m = Mesh::from_soup(soup).unwrap();
    g.run(&mut m, steps, |_| {})
        .unwrap_or_else(|e| panic!("{}", g.render_error(&e)));
    m.validate().unwrap();
    m.to_quad_soup()
}

fn cube() -> PolygonSoup {
    // Every corner moved, so that no mask can hide behind symmetry.
    jitter(
        subgram::mesh::io::read(&lsys("meshes/cube.obj")).unwrap(),
        0x9E37_79B9_7F4A_7C15,
    )
}

/// For every corner of every polygon, `rule(polygon positions, corner
/// index)`: the points a dual scheme makes.
fn per_corner(s: &PolygonSoup, rule: impl Fn(&[DVec3], usize) -> DVec3) -> Vec<DVec3> {
    let mut out = Vec::new();
    for f in &s.faces {
        let ps: Vec<DVec3> = f.iter().map(|&i| s.positions[i as usize]).collect();
        for k in 0..ps.len() {
            out.push(rule(&ps, k));
        }
    }
    out
}

/// Matches `got` to `want` one to one by position; returns the largest
/// distance.
fn match_points(got: &[DVec3], want: &[DVec3]) -> f64 {
    assert_eq!(got.len(), want.len(), "vertex counts");
    let mut used = vec![false; got.len()];
    let mut worst = 0.0f64;
    for w in want {
        let (i, d) = got
            .iter()
            .enumerate()
            .filter(|(i, _)| !used[*i])
            .map(|(i, g)| (i, g.distance(*w)))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .expect("a point left");
        used[i] = true;
        worst = worst.max(d);
    }
    worst
}

/// Doo and Sabin's weights for corner `k` of an n-gon: α0 = 1/4 + 5/(4n),
/// αj = (3 + 2 cos(2πj/n)) / (4n).
fn doo_sabin_alpha(ps: &[DVec3], k: usize) -> DVec3 {
    let n = ps.len();
    (0..n)
        .map(|j| {
            let w = if j == 0 {
                0.25 + 5.0 / (4.0 * n as f64)
            } else {
                (3.0 + 2.0 * (std::f64::consts::TAU * j as f64 / n as f64).cos()) / (4.0 * n as f64)
            };
            ps[(k + j) % n] * w
        })
        .sum()
}

/// The averaging form: the corner, the midpoints of its two edges and the
/// centroid, a quarter each.
fn doo_sabin_average(ps: &[DVec3], k: usize) -> DVec3 {
    let n = ps.len();
    let (a, next, prev) = (ps[k], ps[(k + 1) % n], ps[(k + n - 1) % n]);
    let centroid = ps.iter().sum::<DVec3>() / n as f64;
    (a + (a + next) * 0.5 + (a + prev) * 0.5 + centroid) * 0.25
}

#[test]
fn doo_sabin_grammar_equals_the_published_quad_mask() {
    let base = cube();
    let one = run("surfaces/doo-sabin.lsys", &base, 1);
    // One face per face, edge and vertex of the cube.
    assert_eq!(one.faces.len(), 6 + 12 + 8);
    assert_eq!(one.positions.len(), 24);
    let want = per_corner(&base, |ps, k| {
        // 9/16 the corner, 3/16 its two neighbours, 1/16 the opposite one.
        assert_eq!(ps.len(), 4);
        ps[k] * (9.0 / 16.0)
            + (ps[(k + 1) % 4] + ps[(k + 3) % 4]) * (3.0 / 16.0)
            + ps[(k + 2) % 4] * (1.0 / 16.0)
    });
    let d = match_points(&one.positions, &want);
    assert!(d < 1e-12, "{d}");
    // On quads the published α weights are the same mask.
    let alpha = per_corner(&base, doo_sabin_alpha);
    assert!(match_points(&one.positions, &alpha) < 1e-12);
}

#[test]
fn doo_sabin_grammar_on_triangles_is_the_averaging_form() {
    let base = cube();
    let one = run("surfaces/doo-sabin.lsys", &base, 1);
    let two = run("surfaces/doo-sabin.lsys", &base, 2);
    assert_eq!(two.positions.len(), 4 * 24);
    // The second step meets the cube's corners as triangles.
    assert_eq!(one.faces.iter().filter(|f| f.len() == 3).count(), 8);
    let want = per_corner(&one, doo_sabin_average);
    let d = match_points(&two.positions, &want);
    assert!(d < 1e-12, "{d}");
    // On a triangle the averaging form gives 7/12, 5/24, 5/24, where the
    // α weights give 2/3, 1/6, 1/6: the points differ by |(b + c)/2 - a| / 12.
    for f in one.faces.iter().filter(|f| f.len() == 3) {
        let ps: Vec<DVec3> = f.iter().map(|&i| one.positions[i as usize]).collect();
        for k in 0..3 {
            let gap = doo_sabin_average(&ps, k).distance(doo_sabin_alpha(&ps, k));
            let predicted = ((ps[(k + 1) % 3] + ps[(k + 2) % 3]) * 0.5 - ps[k]).length() / 12.0;
            assert!((gap - predicted).abs() < 1e-12);
            assert!(gap > 1e-3, "the two forms differ on triangles");
        }
    }
}

/// Triangles become dual blocks at initialization: one step on a jittered
/// icosahedron gives the averaging form on every triangle (Doo-Sabin) and
/// (a + 2b + c)/4 (Peters).
#[test]
fn dual_schemes_on_triangle_meshes() {
    let base = jitter(shapes::icosahedron(), 0x2545_F491_4F6C_DD1D);
    let ds = run("surfaces/doo-sabin.lsys", &base, 1);
    // A face per face (20), edge (30) and vertex (12).
    assert_eq!(ds.faces.len(), 62);
    let d = match_points(&ds.positions, &per_corner(&base, doo_sabin_average));
    assert!(d < 1e-12, "{d}");
    let pe = run("surfaces/peters.lsys", &base, 1);
    let mid_mid = |ps: &[DVec3], k: usize| (ps[(k + 2) % 3] + ps[k] * 2.0 + ps[(k + 1) % 3]) * 0.25;
    let d = match_points(&pe.positions, &per_corner(&base, mid_mid));
    assert!(d < 1e-12, "{d}");
}

/// The output polygons themselves: one Doo-Sabin step on the cube gives,
/// for every input face, a polygon through that face's corner points in
/// the face's own order (so with its orientation); for every edge a quad,
/// and for every vertex a triangle.
#[test]
fn doo_sabin_polygons_follow_the_input_faces() {
    let base = cube();
    let one = run("surfaces/doo-sabin.lsys", &base, 1);
    let want = per_corner(&base, doo_sabin_average);
    // Output vertex index of each (face, corner) point.
    let index: Vec<usize> = want
        .iter()
        .map(|w| {
            let (i, d) = one
                .positions
                .iter()
                .enumerate()
                .map(|(i, p)| (i, p.distance(*w)))
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .unwrap();
            assert!(d < 1e-12);
            i
        })
        .collect();
    let mut k = 0;
    for f in &base.faces {
        let ring: Vec<u32> = (0..f.len()).map(|j| index[k + j] as u32).collect();
        k += f.len();
        let found = one.faces.iter().any(|g| {
            g.len() == ring.len()
                && (0..g.len()).any(|r| (0..g.len()).all(|j| g[(r + j) % g.len()] == ring[j]))
        });
        assert!(
            found,
            "face {f:?}: no output polygon {ring:?} in the same order"
        );
    }
    let sizes = |n: usize| one.faces.iter().filter(|g| g.len() == n).count();
    assert_eq!((sizes(4), sizes(3)), (6 + 12, 8));
}

#[test]
fn peters_grammar_is_two_mid_edge_steps() {
    let base = cube();
    let mid_mid = |ps: &[DVec3], k: usize| {
        let n = ps.len();
        (ps[(k + n - 1) % n] + ps[k] * 2.0 + ps[(k + 1) % n]) * 0.25
    };
    let one = run("surfaces/peters.lsys", &base, 1);
    assert_eq!(one.faces.len(), 26);
    let d = match_points(&one.positions, &per_corner(&base, mid_mid));
    assert!(d < 1e-12, "{d}");
    let two = run("surfaces/peters.lsys", &base, 2);
    let d = match_points(&two.positions, &per_corner(&one, mid_mid));
    assert!(d < 1e-12, "{d}");
}

#[test]
fn dual_schemes_refuse_open_meshes() {
    for file in ["surfaces/doo-sabin.lsys", "surfaces/peters.lsys"] {
        let g = grammar(file);
        let mut m = Mesh::from_soup(&shapes::quad_grid(3, 3)).unwrap();
        let before = m.clone();
        let e = g.run(&mut m, 1, |_| {}).unwrap_err();
        let text = g.render_error(&e);
        assert!(text.contains("runs on closed meshes only"), "{text}");
        assert!(text.contains("is on a boundary"), "{text}");
        assert!(
            text.contains("blocks: dual"),
            "the caret is on the declaration: {text}"
        );
        assert_eq!(m, before, "refused before anything changed");
    }
}

/// Output merges only basic blocks (two triangles) and dual blocks (fans
/// around a centre); other regions joined by block edges keep their
/// triangles, so the file is a valid mesh. A region that covers a whole
/// closed surface has no border at all.
#[test]
fn output_merges_only_block_shaped_regions() {
    let cube = subgram::mesh::io::read(&lsys("meshes/cube.obj")).unwrap();
    for (text, steps) in [
        // Every edge ends up a block edge: one region, no border.
        (
            "F(f) -> V(v = avg(f)) || E^3 F^3;\nE(e; !block(e)) | F^2 -> E || F^2;\n",
            2,
        ),
        // Regions of many triangles that are neither blocks nor fans.
        (
            "F(f; block(f)) -> V(v = avg(f)) || E^3 F^3;\nE(e; !block(e)) | F^2 -> E || F^2;\n",
            1,
        ),
    ] {
        let g = subgram::surface::load_str("g.lsys", text, &[]).unwrap_or_else(|e| panic!("{e}"));
        let mut m = Mesh::from_soup(&cube).unwrap();
        g.run(&mut m, steps, |_| {}).unwrap();
        let soup = m.to_quad_soup();
        let back = Mesh::from_soup(&soup).unwrap_or_else(|e| panic!("{text}: {}", e.message));
        back.validate().unwrap();
        let info = back.info();
        assert_eq!(
            (info.boundary_loops, info.euler_characteristic),
            (0, 2),
            "{text}"
        );
    }
}

/// Paper 004's two-scale coefficients of the C4 four-directional box
/// spline, over 64.
const C4: [[f64; 7]; 7] = [
    [0., 0., 1., 2., 1., 0., 0.],
    [0., 2., 6., 8., 6., 2., 0.],
    [1., 6., 14., 18., 14., 6., 1.],
    [2., 8., 18., 24., 18., 8., 2.],
    [1., 6., 14., 18., 14., 6., 1.],
    [0., 2., 6., 8., 6., 2., 0.],
    [0., 0., 1., 2., 1., 0., 0.],
];

/// Two bisections on a regular grid: the impulse response of one vertex
/// (its height) is the C4 box spline's table. The grid's coordinates are
/// its indices, centred on that vertex, so each output vertex's position
/// says where it sits on the finer grid (the scheme reproduces linear
/// functions away from the boundary, which is too far to reach the mask).
#[test]
fn four_eight_grammar_gives_the_c4_box_spline() {
    for file in ["surfaces/four-eight.lsys", "surfaces/c4.lsys"] {
        box_spline_table(file);
    }
}

fn box_spline_table(file: &str) {
    let n = 16;
    let mut grid = shapes::quad_grid(n, n);
    for p in &mut grid.positions {
        *p = ((*p * n as f64).round() - DVec3::new(8.0, 8.0, 0.0)) * DVec3::new(1.0, 1.0, 0.0);
    }
    let centre = 8 * (n + 1) + 8;
    assert_eq!(grid.positions[centre], DVec3::ZERO);
    let mut impulse = grid.clone();
    impulse.positions[centre].z = 1.0;
    let g = grammar(file);
    let mut a = Mesh::from_soup(&grid).unwrap();
    let mut b = Mesh::from_soup(&impulse).unwrap();
    g.run(&mut a, 2, |_| {}).unwrap();
    g.run(&mut b, 2, |_| {}).unwrap();
    a.validate().unwrap();
    // Two bisections are one quadrisection: four times the vertices.
    assert_eq!(a.vertex_count(), (2 * n + 1) * (2 * n + 1));
    assert_eq!(a.to_quad_soup().faces.len(), 4 * n * n);
    let mut seen = 0;
    let mut total = 0.0;
    for v in a.vertices() {
        let p = a.position(v);
        let (u, w) = (p.x * 2.0, p.y * 2.0);
        let weight = b.position(v).z;
        total += weight;
        if u.abs() <= 3.0 && w.abs() <= 3.0 {
            assert!((u - u.round()).abs() < 1e-9 && (w - w.round()).abs() < 1e-9);
            let want = C4[(u.round() + 3.0) as usize][(w.round() + 3.0) as usize] / 64.0;
            assert!(
                (weight - want).abs() < 1e-12,
                "at ({u}, {w}): {weight} where the table has {want}"
            );
            seen += 1;
        } else {
            assert!(weight.abs() < 1e-12, "outside the mask at ({u}, {w})");
        }
    }
    assert_eq!(seen, 49);
    // The table sums to 256/64: four fine points per coarse one.
    assert!((total - 4.0).abs() < 1e-12);
}

#[test]
fn block_rules_are_checked() {
    let e = subgram::surface::load_str(
        "g.lsys",
        "blocks: trisection;\nF(f) -> V(v = avg(f)) || E^3 F^3;\n",
        &[],
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("g.lsys:1:9"), "{e}");
    assert!(e.contains("`quadrisection`, `bisection` or `dual`"), "{e}");
    let e = subgram::surface::load_str(
        "g.lsys",
        "F(f) -> V(v = avg(f)) || E^3 F^3;\ninit: E(e; block(e)) | F^2 -> V(v = avg(e)) || E^4 F^4;\n",
        &[],
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("g.lsys:2:1"), "{e}");
    assert!(e.contains("come before the other rules"), "{e}");
    let e = subgram::surface::load_str("g.lsys", "E(e; center(e)) | F^2 -> E || F^2;\n", &[])
        .unwrap_err()
        .to_string();
    assert!(e.contains("g.lsys:1:6"), "{e}");
    assert!(e.contains("`center` takes a vertex"), "{e}");
}

/// Every grammar in lsystems/surfaces runs on the mesh it names, for its
/// derivation length, and leaves a valid mesh.
#[test]
fn every_surface_grammar_runs_on_its_own_mesh() {
    let dir = lsys("surfaces");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "lsys"))
        .collect();
    files.sort();
    assert!(files.len() >= 7, "{files:?}");
    for path in files {
        let g = subgram::surface::load_file(&path, &[]).unwrap_or_else(|e| panic!("{e}"));
        let (mesh, _) = g.mesh.clone().expect("names its base mesh");
        let soup = subgram::mesh::io::read(&dir.join(mesh)).unwrap();
        let mut m = Mesh::from_soup(&soup).unwrap();
        let n = g.length.expect("has a derivation length") as usize;
        g.run(&mut m, n, |_| {})
            .unwrap_or_else(|e| panic!("{}: {}", path.display(), g.render_error(&e)));
        m.validate().unwrap();
        assert!(m.face_count() > soup.faces.len(), "{}", path.display());
    }
}

/// Conditions and assignments are evaluated in parallel; the result does
/// not depend on how many threads there are, to the last bit.
#[test]
fn parallel_evaluation_gives_the_same_bits_on_one_thread() {
    let soup = shapes::icosphere(4);
    let run_on = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let g = grammar("surfaces/loop.lsys");
            let mut m = Mesh::from_soup(&soup).unwrap();
            g.run(&mut m, 2, |_| {}).unwrap();
            m.to_soup()
        })
    };
    let (one, four) = (run_on(1), run_on(4));
    assert_eq!(one.faces, four.faces);
    assert!(one.positions.len() > 40_000, "big enough to be split up");
    for (a, b) in one.positions.iter().zip(&four.positions) {
        assert_eq!(
            a.to_array().map(f64::to_bits),
            b.to_array().map(f64::to_bits)
        );
    }
}

/// A pentagonal pyramid: a pentagon and five triangles, closed.
fn pentagon_pyramid() -> PolygonSoup {
    PolygonSoup {
        positions: vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.3, 0.8, 0.0),
            DVec3::new(0.5, 1.3, 0.0),
            DVec3::new(-0.3, 0.8, 0.0),
            DVec3::new(0.5, 0.5, 1.0),
        ],
        faces: vec![
            vec![0, 4, 3, 2, 1],
            vec![0, 1, 5],
            vec![1, 2, 5],
            vec![2, 3, 5],
            vec![3, 4, 5],
            vec![4, 0, 5],
        ]
        .into(),
        ..PolygonSoup::default()
    }
}

/// A pentagon is fanned into triangles on input; a grammar that reads
/// quads and has no face split to take the polygon whole (4-8) would take
/// the fan's triangles for faces, so it refuses by name.
#[test]
fn block_grammars_without_a_face_split_refuse_fanned_polygons() {
    let soup = pentagon_pyramid();
    let g = grammar("surfaces/four-eight.lsys");
    let mut m = Mesh::from_soup(&soup).unwrap();
    let e = g.run(&mut m, 1, |_| {}).unwrap_err();
    let text = g.render_error(&e);
    assert!(text.contains("face 1 has 5 sides"), "{text}");
    // Loop reads everything as triangles and runs.
    let g = grammar("surfaces/loop.lsys");
    let mut m = Mesh::from_soup(&soup).unwrap();
    g.run(&mut m, 1, |_| {}).unwrap();
}

/// Catmull and Clark's rules on any polygon, as OpenSubdiv has them,
/// computed here from the input polygons: the face point is the centroid
/// of the face's corners; an interior edge's point the average of its ends
/// and its two face points, a boundary edge's its midpoint; an interior
/// vertex of valence n goes to (n - 2)/n v + (sum of its n neighbours +
/// sum of its n face points)/n^2, a boundary vertex to 3/4 v + 1/8 (a + b)
/// of its boundary neighbours.
fn catmull_clark_points(s: &PolygonSoup) -> Vec<DVec3> {
    let p = |i: u32| s.positions[i as usize];
    let centroid = |f: &[u32]| f.iter().map(|&i| p(i)).sum::<DVec3>() / f.len() as f64;
    let mut out: Vec<DVec3> = s.faces.iter().map(centroid).collect();
    // Each edge's faces (by index), in a map from (min, max).
    let mut edges: std::collections::BTreeMap<(u32, u32), Vec<usize>> = Default::default();
    for (k, f) in s.faces.iter().enumerate() {
        for j in 0..f.len() {
            let (a, b) = (f[j], f[(j + 1) % f.len()]);
            edges.entry((a.min(b), a.max(b))).or_default().push(k);
        }
    }
    for (&(a, b), fs) in &edges {
        out.push(match fs.as_slice() {
            [f, g] => (p(a) + p(b) + out[*f] + out[*g]) / 4.0,
            [_] => (p(a) + p(b)) / 2.0,
            _ => panic!("a non-manifold edge"),
        });
    }
    for v in 0..s.positions.len() as u32 {
        let nbrs: Vec<(u32, usize)> = edges
            .iter()
            .filter(|((a, b), _)| *a == v || *b == v)
            .map(|(&(a, b), fs)| (if a == v { b } else { a }, fs.len()))
            .collect();
        let faces: Vec<usize> = (0..s.faces.len())
            .filter(|&k| s.faces[k].contains(&v))
            .collect();
        let boundary: Vec<u32> = nbrs
            .iter()
            .filter(|(_, n)| *n == 1)
            .map(|(w, _)| *w)
            .collect();
        out.push(if boundary.is_empty() {
            let n = nbrs.len() as f64;
            assert_eq!(nbrs.len(), faces.len());
            let ring = nbrs.iter().map(|(w, _)| p(*w)).sum::<DVec3>()
                + faces.iter().map(|&k| out[k]).sum::<DVec3>();
            p(v) * ((n - 2.0) / n) + ring / (n * n)
        } else {
            assert_eq!(boundary.len(), 2);
            p(v) * 0.75 + (p(boundary[0]) + p(boundary[1])) * 0.125
        });
    }
    out
}

/// Catmull-Clark on polygons of 5 to 7 sides, closed (a pentagonal
/// pyramid, a prism of two hexagons) and open (a heptagon ringed by
/// quads), positions jittered: one step is Catmull and Clark's rules
/// computed here (every point, 1e-12), and every polygon becomes as many
/// quads as it has sides. `benches/ngon_xcheck.py` holds three levels to
/// Blender's modifier.
#[test]
fn catmull_clark_takes_polygons_of_any_number_of_sides() {
    let ring = |n: usize, r: f64, z: f64| -> Vec<DVec3> {
        (0..n)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / n as f64;
                DVec3::new(r * a.cos(), r * a.sin(), z)
            })
            .collect()
    };
    let hexagonal_prism = {
        let mut positions = ring(6, 1.0, 0.0);
        positions.extend(ring(6, 1.0, 1.0));
        let mut faces = vec![vec![5, 4, 3, 2, 1, 0], vec![6, 7, 8, 9, 10, 11]];
        faces.extend((0..6u32).map(|i| vec![i, (i + 1) % 6, 6 + (i + 1) % 6, 6 + i]));
        PolygonSoup {
            positions,
            faces: faces.into(),
            ..PolygonSoup::default()
        }
    };
    let ringed_heptagon = {
        let mut positions = ring(7, 1.0, 0.2);
        positions.extend(ring(7, 2.0, 0.0));
        let mut faces = vec![(0..7u32).collect::<Vec<_>>()];
        faces.extend((0..7u32).map(|i| vec![i, 7 + i, 7 + (i + 1) % 7, (i + 1) % 7]));
        PolygonSoup {
            positions,
            faces: faces.into(),
            ..PolygonSoup::default()
        }
    };
    for (name, soup) in [
        ("pentagonal pyramid", pentagon_pyramid()),
        ("hexagonal prism", hexagonal_prism),
        ("ringed heptagon", ringed_heptagon),
    ] {
        let base = jitter(soup, 0x9E37_79B9_7F4A_7C15);
        let one = run("surfaces/catmull-clark.lsys", &base, 1);
        let sides: usize = base.faces.iter().map(|f| f.len()).sum();
        assert_eq!(one.faces.len(), sides, "{name}: a quad per corner");
        assert!(one.faces.iter().all(|f| f.len() == 4), "{name}: quads");
        let d = match_points(&one.positions, &catmull_clark_points(&base));
        assert!(d < 1e-12, "{name}: {d}");
        // The next step is the quad rules on the result.
        let two = run("surfaces/catmull-clark.lsys", &base, 2);
        let d = match_points(&two.positions, &catmull_clark_points(&one));
        assert!(d < 1e-12, "{name}, step 2: {d}");
    }
}

/// The dual schemes take a polygon whole too (their `init:` face split):
/// one step on the jittered pentagonal pyramid gives the averaging form at
/// every corner of the pentagon and of the triangles (Doo-Sabin), and
/// (a + 2b + c)/4 (Peters), with a polygon per face, edge and vertex.
#[test]
fn dual_schemes_take_polygons_of_any_number_of_sides() {
    let base = jitter(pentagon_pyramid(), 0x2545_F491_4F6C_DD1D);
    let ds = run("surfaces/doo-sabin.lsys", &base, 1);
    assert_eq!(ds.faces.len(), 6 + 10 + 6);
    let d = match_points(&ds.positions, &per_corner(&base, doo_sabin_average));
    assert!(d < 1e-12, "{d}");
    let pe = run("surfaces/peters.lsys", &base, 1);
    let mid_mid = |ps: &[DVec3], k: usize| {
        let n = ps.len();
        (ps[(k + n - 1) % n] + ps[k] * 2.0 + ps[(k + 1) % n]) * 0.25
    };
    let d = match_points(&pe.positions, &per_corner(&base, mid_mid));
    assert!(d < 1e-12, "{d}");
}

/// What an `init:` vertex rule writes is current before the first step.
#[test]
fn init_vertex_rules_take_effect_before_the_first_step() {
    let g = subgram::surface::load_str(
        "g.lsys",
        "init: V(v) -> V(v = 2*v);\nE(e) | F^2 -> V(v = avg(e)) || E^4 F^4;\n",
        &[],
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let base = Mesh::from_soup(&shapes::icosahedron()).unwrap();
    let mut m = base.clone();
    g.run(&mut m, 1, |_| {}).unwrap();
    for v in base.vertices() {
        assert!(m.position(v).distance(base.position(v) * 2.0) < 1e-12);
    }
    for e in base.edges() {
        let (a, b) = base.edge_vertices(e);
        let mid = base.position(a) + base.position(b);
        assert!(
            m.vertices().any(|w| m.position(w).distance(mid) < 1e-12),
            "the split saw the doubled positions"
        );
    }
}

/// `bnext` of an interior vertex is no vertex: the rule fails with a
/// message that says why, instead of reading some other vertex.
#[test]
fn boundary_walks_off_the_boundary_are_errors() {
    for body in [
        "bnext(v)",
        "avg(ring(bprev(v)))",
        "v + count(w in ring(bnext(v)))*v",
    ] {
        let text = format!("V(v) -> V(v = {body});\n");
        let g = subgram::surface::load_str("g.lsys", &text, &[]).unwrap_or_else(|e| panic!("{e}"));
        let mut m = Mesh::from_soup(&shapes::icosahedron()).unwrap();
        let e = g.run(&mut m, 1, |_| {}).unwrap_err();
        let msg = g.render_error(&e);
        // The caret is at the walk that left the boundary.
        let at = text.find('b').unwrap() + 1;
        assert!(msg.contains(&format!("g.lsys:1:{at}")), "{msg}");
        assert!(msg.contains("not on the boundary"), "{msg}");
    }
}

/// A run continued by one step, twice, is a run of two steps, for every
/// grammar: init rules run once, `step` and `new(v)` continue.
#[test]
fn running_twice_continues_the_steps() {
    for (g, mesh) in [
        ("doo-sabin", "cube"),
        ("peters", "cube"),
        ("four-eight", "torus"),
        ("sqrt3", "grid"),
        ("catmull-clark", "cube"),
        ("loop", "octahedron"),
    ] {
        let gr = grammar(&format!("surfaces/{g}.lsys"));
        let soup = subgram::mesh::io::read(&lsys(&format!("meshes/{mesh}.obj"))).unwrap();
        let base = Mesh::from_soup(&soup).unwrap();
        let mut a = base.clone();
        gr.run(&mut a, 2, |_| {}).unwrap();
        let mut b = base.clone();
        let mut run = gr.start(&mut b).unwrap();
        run.steps(1, |_| {}).unwrap();
        run.steps(1, |_| {}).unwrap();
        assert_eq!(run.step(), 2, "{g}");
        let (sa, sb) = (a.to_quad_soup(), b.to_quad_soup());
        assert_eq!(sa.faces, sb.faces, "{g}");
        assert_eq!(sa.positions, sb.positions, "{g}");
    }
}
