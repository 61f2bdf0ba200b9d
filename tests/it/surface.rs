//! Surface grammars against the published masks: the expected positions
//! are computed here from the base mesh with the masks of Loop and
//! Kobbelt, not by the grammar engine.

use glam::DVec3;
use subgram::mesh::{shapes, Mesh, PolygonSoup, VertexId};

use crate::support::*;

fn grammar(file: &str) -> subgram::surface::Grammar {
    subgram::surface::load_file(&lsys(file), &[]).unwrap_or_else(|e| panic!("{e}"))
}

fn run(file: &str, base: &Mesh) -> Mesh {
    let g = grammar(file);
    let mut m = base.clone();
    g.run(&mut m, 1, |_| {})
        .unwrap_or_else(|e| panic!("{}", g.render_error(&e)));
    m.validate().unwrap();
    m
}

/// The new vertex adjacent to all of `parents` (ids above `old_count`).
fn child(m: &Mesh, parents: &[VertexId], old_count: u32) -> VertexId {
    m.one_ring(parents[0])
        .filter(|w| w.0 >= old_count)
        .find(|w| {
            parents[1..]
                .iter()
                .all(|p| m.find_halfedge(*w, *p).is_some())
        })
        .expect("a child vertex")
}

fn loop_beta(n: f64) -> f64 {
    (5.0 / 8.0 - (3.0 / 8.0 + 0.25 * (2.0 * std::f64::consts::PI / n).cos()).powi(2)) / n
}

#[test]
fn loop_grammar_equals_loop_masks_on_a_closed_mesh() {
    let base = Mesh::from_soup(&jitter(shapes::icosphere(1), 3)).unwrap();
    let old = base.vertex_count() as u32;
    let m = run("surfaces/loop.lsys", &base);
    assert_eq!(m.face_count(), 4 * base.face_count());
    let p = |v: VertexId| base.position(v);
    let mut worst: f64 = 0.0;
    // Old vertices: (1 - n beta) v + beta sum(neighbours), Loop's beta.
    for v in base.vertices() {
        let n = base.valence(v) as f64;
        let b = loop_beta(n);
        let want = (1.0 - n * b) * p(v) + b * base.one_ring(v).map(p).sum::<DVec3>();
        worst = worst.max(m.position(v).distance(want));
    }
    // Edge points: 3/8, 3/8, 1/8, 1/8.
    for e in base.edges() {
        let h = e.halfedge();
        let (a, b) = (base.from(h), base.to(h));
        let c = base.to(base.next(h));
        let d = base.to(base.next(h.twin()));
        let want = 0.375 * (p(a) + p(b)) + 0.125 * (p(c) + p(d));
        worst = worst.max(m.position(child(&m, &[a, b], old)).distance(want));
    }
    assert!(
        worst < 1e-12,
        "largest difference from Loop's masks: {worst}"
    );
}

#[test]
fn loop_grammar_follows_the_boundary_curve_rules() {
    let base = Mesh::from_soup(&jitter(shapes::triangle_grid(4, 3), 11)).unwrap();
    let old = base.vertex_count() as u32;
    let m = run("surfaces/loop.lsys", &base);
    let p = |v: VertexId| base.position(v);
    for v in base.vertices() {
        let want = if base.is_boundary_vertex(v) {
            // 3/4 v + 1/8 (a + b) of the boundary neighbours.
            let nb: Vec<VertexId> = base
                .outgoing_halfedges(v)
                .filter(|h| base.is_boundary_edge(h.edge()))
                .map(|h| base.to(h))
                .collect();
            assert_eq!(nb.len(), 2);
            0.75 * p(v) + 0.125 * (p(nb[0]) + p(nb[1]))
        } else {
            let n = base.valence(v) as f64;
            let b = loop_beta(n);
            (1.0 - n * b) * p(v) + b * base.one_ring(v).map(p).sum::<DVec3>()
        };
        assert!(m.position(v).distance(want) < 1e-12, "vertex {}", v.0);
    }
    for e in base.edges() {
        let h = e.halfedge();
        let (a, b) = (base.from(h), base.to(h));
        let want = if base.is_boundary_edge(e) {
            0.5 * (p(a) + p(b))
        } else {
            let c = base.to(base.next(h));
            let d = base.to(base.next(h.twin()));
            0.375 * (p(a) + p(b)) + 0.125 * (p(c) + p(d))
        };
        assert!(
            m.position(child(&m, &[a, b], old)).distance(want) < 1e-12,
            "edge {}",
            e.0
        );
    }
}

#[test]
fn sqrt3_grammar_equals_kobbelts_masks() {
    let base = Mesh::from_soup(&jitter(shapes::icosphere(1), 5)).unwrap();
    let old = base.vertex_count() as u32;
    let m = run("surfaces/sqrt3.lsys", &base);
    assert_eq!(m.face_count(), 3 * base.face_count());
    let p = |v: VertexId| base.position(v);
    for v in base.vertices() {
        let n = base.valence(v) as f64;
        let a = (4.0 - 2.0 * (2.0 * std::f64::consts::PI / n).cos()) / 9.0;
        let want = (1.0 - a) * p(v) + a / n * base.one_ring(v).map(p).sum::<DVec3>();
        assert!(m.position(v).distance(want) < 1e-12, "vertex {}", v.0);
        assert_eq!(
            m.valence(v),
            base.valence(v),
            "old vertices keep their valence after the flips"
        );
    }
    for f in base.faces() {
        let vs = base.face_vertices(f);
        let want = (p(vs[0]) + p(vs[1]) + p(vs[2])) / 3.0;
        assert!(
            m.position(child(&m, &vs, old)).distance(want) < 1e-12,
            "face {}",
            f.0
        );
    }
    // Two steps: every face splits in three and the old edges turn.
    let g = grammar("surfaces/sqrt3.lsys");
    let mut two = base.clone();
    g.run(&mut two, 2, |_| {}).unwrap();
    two.validate().unwrap();
    assert_eq!(two.face_count(), 9 * base.face_count());
}

#[test]
fn sqrt3_with_boundary_rules_equals_the_printed_rules_on_closed_meshes() {
    let base = Mesh::from_soup(&jitter(shapes::icosphere(1), 9)).unwrap();
    let (g, printed) = (
        grammar("surfaces/sqrt3.lsys"),
        grammar("surfaces/sqrt3-printed.lsys"),
    );
    let (mut a, mut b) = (base.clone(), base.clone());
    g.run(&mut a, 3, |_| {}).unwrap();
    printed.run(&mut b, 3, |_| {}).unwrap();
    assert_eq!(a.face_count(), 27 * base.face_count());
    assert_eq!(a.vertex_count(), b.vertex_count());
    for v in a.vertices() {
        assert!(a.position(v).distance(b.position(v)) < 1e-12);
    }
}

/// The boundary loop from `start`, following the faces' direction.
fn boundary_loop(m: &Mesh, start: VertexId) -> Vec<VertexId> {
    let mut out = vec![start];
    let mut v = m.boundary_neighbour(start, true).unwrap();
    while v != start {
        out.push(v);
        v = m.boundary_neighbour(v, true).unwrap();
    }
    out
}

/// Kobbelt's boundary rule: boundary vertices stay in odd steps; in even
/// steps each boundary edge is split in three, and the boundary polygon
/// p_i becomes the ternary cubic B-spline refinement
/// (4 p_i-1 + 19 p_i + 4 p_i+1)/27, (p_i-1 + 16 p_i + 10 p_i+1)/27,
/// (10 p_i + 16 p_i+1 + p_i+2)/27.
#[test]
fn sqrt3_grammar_follows_kobbelts_boundary_rule() {
    let base = Mesh::from_soup(&jitter(shapes::triangle_grid(4, 4), 3)).unwrap();
    let g = grammar("surfaces/sqrt3.lsys");
    let start = base
        .vertices()
        .find(|&v| base.is_boundary_vertex(v))
        .unwrap();
    let ring = boundary_loop(&base, start);
    assert_eq!(ring.len(), 16);
    let mut one = base.clone();
    g.run(&mut one, 1, |_| {}).unwrap();
    one.validate().unwrap();
    assert_eq!(one.face_count(), 3 * base.face_count());
    assert_eq!(
        boundary_loop(&one, start),
        ring,
        "odd steps keep the boundary"
    );
    for &v in &ring {
        assert_eq!(one.position(v), base.position(v));
    }
    let mut two = base.clone();
    g.run(&mut two, 2, |_| {}).unwrap();
    two.validate().unwrap();
    assert_eq!(two.face_count(), 9 * base.face_count());
    let fine = boundary_loop(&two, start);
    assert_eq!(fine.len(), 3 * ring.len());
    let n = ring.len();
    let p = |i: usize| base.position(ring[i % n]);
    for i in 0..n {
        assert_eq!(
            fine[3 * i],
            ring[i],
            "old vertices keep their place in the loop"
        );
        let want = [
            (p(i + n - 1) * 4.0 + p(i) * 19.0 + p(i + 1) * 4.0) / 27.0,
            (p(i + n - 1) + p(i) * 16.0 + p(i + 1) * 10.0) / 27.0,
            (p(i) * 10.0 + p(i + 1) * 16.0 + p(i + 2)) / 27.0,
        ];
        for (k, w) in want.iter().enumerate() {
            let got = two.position(fine[3 * i + k]);
            assert!(
                got.distance(*w) < 1e-12,
                "boundary point {}: {got} vs {w}",
                3 * i + k
            );
        }
    }
}

#[test]
fn grammar_errors_point_at_the_rule() {
    let bad = subgram::surface::load_str("g.lsys", "F(f) -> V(v = avg(f)) || E^4 F^4;\n", &[])
        .unwrap_err()
        .to_string();
    assert!(
        bad.starts_with("g.lsys:1:1: error: this is not one of the rules of paper 000"),
        "{bad}"
    );
    let bad = subgram::surface::load_str("g.lsys", "V(v; l(v) < c) -> V(v = v + 1);\n", &[])
        .unwrap_err()
        .to_string();
    assert!(
        bad.contains("g.lsys:1:25: error: type error: cannot apply `+` to V3d and int"),
        "{bad}"
    );
    let bad = subgram::surface::load_str("g.lsys", "V(v) -> V(v = smooth(v));\n", &[])
        .unwrap_err()
        .to_string();
    assert!(bad.contains("unknown function `smooth`"), "{bad}");
    let bad = subgram::surface::load_str("g.lsys", "E(e) | F^3 -> E || F^2;\n", &[])
        .unwrap_err()
        .to_string();
    assert!(bad.contains("not one of the rules"), "{bad}");
}

/// The new vertex whose old neighbours are exactly `parents`.
fn child_of_exactly(m: &Mesh, parents: &[VertexId], old_count: u32) -> VertexId {
    let mut want: Vec<u32> = parents.iter().map(|p| p.0).collect();
    want.sort();
    m.vertices()
        .filter(|w| w.0 >= old_count)
        .find(|&w| {
            let mut olds: Vec<u32> = m
                .one_ring(w)
                .filter(|u| u.0 < old_count)
                .map(|u| u.0)
                .collect();
            olds.sort();
            olds == want
        })
        .expect("a child vertex")
}

/// Catmull and Clark's rules, computed from the quads of the base mesh:
/// face points are centroids, edge points average the edge's ends and its
/// two face points, and a vertex of valence n moves to
/// (n - 2)/n v + 1/n^2 (sum of edge neighbours + sum of face points);
/// on the boundary, 3/4 v + 1/8 (a + b) and edge midpoints.
fn check_catmull_clark(soup: &PolygonSoup) {
    let base = Mesh::from_soup(soup).unwrap();
    let old = base.vertex_count() as u32;
    let m = run("surfaces/catmull-clark.lsys", &base);
    let p = |i: u32| soup.positions[i as usize];
    let centroid = |q: &[u32]| q.iter().map(|&i| p(i)).sum::<DVec3>() / q.len() as f64;
    let faces_of = |v: u32| soup.faces.iter().filter(move |q| q.contains(&v));
    let boundary = |a: u32, b: u32| faces_of(a).filter(|q| q.contains(&b)).count() == 1;
    let mut worst: f64 = 0.0;
    for q in &soup.faces {
        let n = q.len();
        let fp = child_of_exactly(&m, &q.iter().map(|&i| VertexId(i)).collect::<Vec<_>>(), old);
        worst = worst.max(m.position(fp).distance(centroid(q)));
        for k in 0..n {
            let (a, b) = (q[k], q[(k + 1) % n]);
            let ep = child_of_exactly(&m, &[VertexId(a), VertexId(b)], old);
            let want = if boundary(a, b) {
                (p(a) + p(b)) / 2.0
            } else {
                let fs: DVec3 = faces_of(a).filter(|g| g.contains(&b)).map(centroid).sum();
                (p(a) + p(b) + fs) / 4.0
            };
            worst = worst.max(m.position(ep).distance(want));
        }
    }
    for v in 0..old {
        let mut nbrs: Vec<u32> = Vec::new();
        for q in faces_of(v) {
            let n = q.len();
            let k = q.iter().position(|&i| i == v).unwrap();
            for w in [q[(k + 1) % n], q[(k + n - 1) % n]] {
                if !nbrs.contains(&w) {
                    nbrs.push(w);
                }
            }
        }
        let on_boundary: Vec<u32> = nbrs.iter().copied().filter(|&w| boundary(v, w)).collect();
        let want = if on_boundary.is_empty() {
            let n = nbrs.len() as f64;
            let e: DVec3 = nbrs.iter().map(|&w| p(w)).sum();
            let f: DVec3 = faces_of(v).map(centroid).sum();
            (n - 2.0) / n * p(v) + (e + f) / (n * n)
        } else {
            0.75 * p(v) + 0.125 * (p(on_boundary[0]) + p(on_boundary[1]))
        };
        worst = worst.max(m.position(VertexId(v)).distance(want));
    }
    assert!(
        worst < 1e-12,
        "largest difference from Catmull-Clark: {worst}"
    );
    assert_eq!(
        m.to_quad_soup().faces.len(),
        soup.faces.iter().map(|q| q.len()).sum::<usize>(),
        "the output is quads, one per corner of the input"
    );
    assert!(m.to_quad_soup().faces.iter().all(|q| q.len() == 4));
}

#[test]
fn catmull_clark_grammar_on_regular_quads() {
    check_catmull_clark(&jitter(shapes::quad_torus(6, 5), 17));
}

#[test]
fn catmull_clark_grammar_at_extraordinary_vertices_and_boundaries() {
    let cube = subgram::mesh::io::read(&lsys("meshes/cube.obj")).unwrap();
    check_catmull_clark(&jitter(cube, 23));
    check_catmull_clark(&jitter(shapes::quad_grid(4, 3), 29));
}

/// The published regular masks, 9/16, 3/32, 1/64 and 3/8, 1/16, read off a
/// flat regular grid with one vertex moved: the output is linear in it.
#[test]
fn catmull_clark_regular_masks_by_impulse() {
    let mut s = shapes::quad_torus(8, 8);
    let base_positions = s.positions.clone();
    let centre = 3 * 8 + 3;
    s.positions[centre] += DVec3::new(0.0, 0.0, 1.0);
    let moved = Mesh::from_soup(&s).unwrap();
    let flat = Mesh::from_soup(&PolygonSoup {
        positions: base_positions,
        ..s.clone()
    })
    .unwrap();
    let (a, b) = (
        run("surfaces/catmull-clark.lsys", &moved),
        run("surfaces/catmull-clark.lsys", &flat),
    );
    let weight = |v: VertexId| (a.position(v) - b.position(v)).z;
    let c = VertexId(centre as u32);
    assert!((weight(c) - 9.0 / 16.0).abs() < 1e-12, "{}", weight(c));
    let old = flat.vertex_count() as u32;
    for w in flat
        .one_ring(c)
        .filter(|w| flat.is_block_edge(flat.find_halfedge(c, *w).unwrap().edge()))
    {
        // A diagonal neighbour: it gets 1/64 from the centre.
        assert!((weight(w) - 1.0 / 64.0).abs() < 1e-12);
    }
    for h in flat
        .outgoing_halfedges(c)
        .filter(|h| !flat.is_block_edge(h.edge()))
    {
        let w = flat.to(h);
        assert!(
            (weight(w) - 3.0 / 32.0).abs() < 1e-12,
            "edge neighbour {}",
            weight(w)
        );
        let ep = child_of_exactly(&a, &[c, w], old);
        assert!(
            (weight(ep) - 3.0 / 8.0).abs() < 1e-12,
            "edge point {}",
            weight(ep)
        );
    }
}

#[test]
fn surface_grammars_run_under_every_command() {
    let bin = |args: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_subgram"))
            .args(args)
            .output()
            .unwrap()
    };
    let loop_file = lsys("surfaces/loop.lsys");
    let f = loop_file.to_str().unwrap();
    let o = bin(&["check", f]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stdout).contains("a surface grammar of 10 rules"));
    // Three Loop steps of the octahedron: 8 * 4^3 faces, valences 4 and 6.
    let o = bin(&["derive", f, "--format", "json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["faces"], 512);
    assert_eq!(v["valences"]["4"], 6);
    let tmp = scratch("surface-cli");
    let dir = tmp.path();
    let png = dir.join("loop.png");
    let o = bin(&[
        "render",
        f,
        "-o",
        png.to_str().unwrap(),
        "-n",
        "1",
        "--size",
        "120x100",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(tiny_skia::Pixmap::decode_png(&std::fs::read(&png).unwrap()).is_ok());
    let cube = lsys("meshes/cube.obj");
    let out = dir.join("cc.obj");
    let cc = lsys("surfaces/catmull-clark.lsys");
    let o = bin(&[
        "subdivide",
        cube.to_str().unwrap(),
        "--grammar",
        cc.to_str().unwrap(),
        "-n",
        "2",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let back = subgram::mesh::io::read(&out).unwrap();
    assert_eq!(back.faces.len(), 6 * 16);
    assert!(
        back.faces.iter().all(|f| f.len() == 4),
        "Catmull-Clark gives quads"
    );
    // A bad grammar: the message points at the rule. `v * v` is the dot
    // product of two points in L+C, a number, where a point is expected.
    let bad = dir.join("bad.lsys");
    std::fs::write(&bad, "mesh: \"x.obj\";\nV(v) -> V(v = v * v);\n").unwrap();
    let o = bin(&["check", bad.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr)
        .contains("bad.lsys:2:15: error: type mismatch: expected V3d, found double"));
}

/// Valences and how many vertices have each.
fn valences(m: &Mesh) -> std::collections::BTreeMap<usize, usize> {
    let mut h = std::collections::BTreeMap::new();
    for v in m.vertices() {
        *h.entry(m.one_ring(v).count()).or_insert(0) += 1;
    }
    h
}

fn run_steps(g: &subgram::surface::Grammar, base: &Mesh, steps: usize) -> Mesh {
    let mut m = base.clone();
    g.run(&mut m, steps, |_| {})
        .unwrap_or_else(|e| panic!("{}", g.render_error(&e)));
    m.validate().unwrap();
    m
}

#[test]
fn loop_grammar_stays_a_quadrisection_for_six_steps() {
    // Each Loop step quadrisects every triangle: the base vertices keep
    // their valence, every new vertex has valence 6, and the counts follow
    // F' = 4F, E' = 2E + 3F, V' = V + E.
    let g = grammar("surfaces/loop.lsys");
    let base = Mesh::from_soup(&jitter(shapes::icosahedron(), 3)).unwrap();
    let m = run_steps(&g, &base, 6);
    let (mut v, mut e, mut f) = (12, 30, 20);
    for _ in 0..6 {
        (v, e, f) = (v + e, 2 * e + 3 * f, 4 * f);
    }
    assert_eq!(
        (m.vertex_count(), m.edge_count(), m.face_count()),
        (v, e, f)
    );
    let want: std::collections::BTreeMap<usize, usize> = [(5, 12), (6, v - 12)].into();
    assert_eq!(valences(&m), want);
}

#[test]
fn loop_grammar_keeps_a_flat_grid_flat_and_unfolded() {
    // On a planar grid the limit surface lies in the convex hull of the
    // control points, the unit square, and no triangle turns over.
    let g = grammar("surfaces/loop.lsys");
    for soup in [shapes::triangle_grid(3, 3), shapes::quad_grid(3, 3)] {
        let m = run_steps(&g, &Mesh::from_soup(&soup).unwrap(), 5);
        assert_eq!(m.face_count(), 18 * 4usize.pow(5));
        for v in m.vertices() {
            let p = m.position(v);
            assert!(
                (-1e-12..=1.0 + 1e-12).contains(&p.x) && (-1e-12..=1.0 + 1e-12).contains(&p.y),
                "vertex {v} at {p} is outside the unit square"
            );
        }
        for f in m.faces() {
            let [a, b, c] = m.face_vertices(f).map(|v| m.position(v));
            let z = (b - a).cross(c - a).z;
            assert!(z > 0.0, "face {f:?} is folded over (signed area {z})");
        }
    }
}

/// The soup with every quad written as the two triangles `from_soup`
/// would cut it into.
fn as_triangles(s: &PolygonSoup) -> PolygonSoup {
    s.fanned()
}

#[test]
fn triangle_schemes_read_quads_as_two_triangles() {
    // √3 and Loop are schemes for triangle meshes: a mesh given with quads
    // must subdivide exactly as the same mesh given as triangles, and Loop
    // writes only triangles.
    let torus = jitter(shapes::quad_torus(6, 4), 11);
    for (file, steps) in [("surfaces/sqrt3.lsys", 2), ("surfaces/loop.lsys", 2)] {
        let g = grammar(file);
        let quads = run_steps(&g, &Mesh::from_soup(&torus).unwrap(), steps);
        let tris = run_steps(&g, &Mesh::from_soup(&as_triangles(&torus)).unwrap(), steps);
        assert_eq!(quads.canonical(), tris.canonical(), "{file}");
        assert!(
            quads.to_quad_soup().faces.iter().all(|f| f.len() == 3),
            "{file} wrote a quad"
        );
    }
    // A regular torus stays regular under √3.
    let g = grammar("surfaces/sqrt3.lsys");
    let m = run_steps(&g, &Mesh::from_soup(&torus).unwrap(), 2);
    assert_eq!(valences(&m), [(6, m.vertex_count())].into());
}

#[test]
fn catmull_clark_grammar_on_triangles_and_mixed_meshes() {
    // Triangles are split at their centroids, and their spokes become the
    // next quads' internal edges, as a quad's do.
    check_catmull_clark(&jitter(shapes::icosahedron(), 31));
    // A square pyramid: four triangles and a quad.
    let pyramid = PolygonSoup {
        positions: vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(0.5, 0.5, 0.8),
        ],
        faces: vec![
            vec![0, 3, 2, 1],
            vec![0, 1, 4],
            vec![1, 2, 4],
            vec![2, 3, 4],
            vec![3, 0, 4],
        ]
        .into(),
        ..PolygonSoup::default()
    };
    check_catmull_clark(&jitter(pyramid, 37));
    // An open grid with one quad cut to a triangle: boundary rules meet it.
    let mut open = shapes::quad_grid(3, 2);
    let (a, b, c) = (open.faces[0][0], open.faces[0][1], open.faces[0][2]);
    let mut faces = open.faces.to_vecs();
    faces[0] = vec![a, b, c];
    open.faces = faces.into();
    check_catmull_clark(&jitter(open, 41));
}

#[test]
fn four_eight_refuses_a_mesh_with_triangles() {
    let g = grammar("surfaces/four-eight.lsys");
    let mut m = Mesh::from_soup(&shapes::icosahedron()).unwrap();
    let e = g.run(&mut m, 1, |_| {}).unwrap_err();
    let text = g.render_error(&e);
    assert!(text.contains("needs a mesh of quads"), "{text}");
    assert!(text.contains("is not half of a quad"), "{text}");
    assert!(text.contains("four-eight.lsys:"), "{text}");
}

#[test]
fn a_run_past_the_face_limit_stops_with_an_error() {
    let mut g = grammar("surfaces/loop.lsys");
    g.max_faces = 1000;
    let mut m = Mesh::from_soup(&shapes::icosahedron()).unwrap();
    let e = g.run(&mut m, 5, |_| {}).unwrap_err();
    // 20 · 4^2 = 320 faces; the next step's splits would make 1280.
    assert!(
        e.message.contains("at step 3")
            && e.message
                .contains("would make 1280 faces, past the limit of 1000"),
        "{}",
        e.message
    );
}

#[test]
fn grammar_functions_are_checked() {
    let load = |text: &str| {
        subgram::surface::load_str("g.lsys", text, &[])
            .unwrap_err()
            .to_string()
    };
    let rule = "V(v) -> V(v = f(v));\n";
    let bad = load(&format!("define f(x) = f(x);\n{rule}"));
    assert!(bad.contains("functions may not recurse"), "{bad}");
    assert_eq!(bad.matches("(in `").count(), 1, "{bad}");
    // Each function calls the one before twice: 2^20 calls inlined.
    let mut text = String::from("define f0(x) = x;\n");
    for i in 1..=20 {
        text += &format!("define f{i}(x) = f{}(x) + f{}(x);\n", i - 1, i - 1);
    }
    text += "V(v) -> V(v = f20(v));\n";
    let bad = load(&text);
    assert!(bad.contains("expand to more than 10000 calls"), "{bad}");
    // A chain of functions, each calling the one before once inside a
    // body 40 levels deep: nested 4000 calls deep, it would be 160,000
    // levels deep and overflow the checker's stack. The nesting limit of
    // the language (100 levels) counts through inlined functions, so the
    // chain is refused where it passes 100 levels, inside `f27` of 32;
    // three links (about 90 levels) still check.
    let chain = |n: usize| {
        let mut text = String::from("define f0(x) = x;\n");
        for i in 1..n {
            text += &format!(
                "define f{i}(x) = {}f{}(x){};\n",
                "-(".repeat(20),
                i - 1,
                ")".repeat(20)
            );
        }
        text + &format!("V(v) -> V(v = f{}(v));\n", n - 1)
    };
    // (On a large stack, as the binary gives the checker.)
    let (ok, bad) = std::thread::Builder::new()
        .stack_size(256 << 20)
        .spawn(move || {
            (
                subgram::surface::load_str("g.lsys", &chain(3), &[]).is_ok(),
                load(&chain(4000)),
            )
        })
        .unwrap()
        .join()
        .unwrap();
    assert!(ok);
    assert!(
        bad.contains("error: this is nested more than 100 levels deep once the functions it calls are inlined"),
        "{bad}"
    );
    // Locals are numbered with u16: calls nested 16 deep with 4200
    // parameters each need more than 65,535 of them, which must be an
    // error, not slots that wrap onto others (an index out of bounds).
    // Each parameter's binding is a level of nesting around the body, so
    // the nesting limit refuses it first.
    let params: Vec<String> = (0..4200).map(|i| format!("p{i}")).collect();
    let params = params.join(", ");
    let mut text = format!("define g0(v, {params}) = v;\n");
    for k in 1..16 {
        text += &format!("define g{k}(v, {params}) = g{}(v, {params});\n", k - 1);
    }
    text += &format!("V(v) -> V(v = g15(v, {}));\n", vec!["1"; 4200].join(", "));
    let bad = load(&text);
    assert!(
        bad.contains("g.lsys:17:15: error: this is nested more than 100 levels deep"),
        "{bad}"
    );
    let bad = load(&format!("define f(x) = x;\ndefine f(y) = y;\n{rule}"));
    assert!(
        bad.contains("g.lsys:2:8: error: function `f` is already defined above"),
        "{bad}"
    );
    let bad = load(&format!("define f(x, x) = x;\n{rule}"));
    assert!(bad.contains("`f` already has a parameter `x`"), "{bad}");
    let bad = load(&format!("derivation length: 2.5;\n{rule}"));
    assert!(bad.contains("a whole number of steps"), "{bad}");
    let bad = load("derivation length: 2;\n");
    assert!(bad.contains("expected at least one rule"), "{bad}");
}

#[test]
fn deep_function_nesting_reuses_frame_slots() {
    // Sixteen levels of single calls with three parameters each: the
    // values must pass through intact (v + 16 · (1, 2, 3)).
    let mut text = String::from("define g0(p, a, b) = p + point(1, 2, 3) * (1 + 0*a*b);\n");
    for i in 1..=16 {
        text += &format!(
            "define g{i}(p, a, b) = g{}(p, a + 1, b) + point(1, 2, 3);\n",
            i - 1
        );
    }
    text += "V(v) -> V(v = g15(v, 0, 1));\n";
    let g = subgram::surface::load_str("g.lsys", &text, &[]).unwrap_or_else(|e| panic!("{e}"));
    let base = Mesh::from_soup(&shapes::icosahedron()).unwrap();
    let m = run_steps(&g, &base, 1);
    for v in m.vertices() {
        let d = m.position(v) - base.position(v);
        assert!((d - DVec3::new(16.0, 32.0, 48.0)).length() < 1e-12, "{d}");
    }
}

/// Protection (paper 003, §4.2.2 and Algorithm 2 with protected sets): a
/// protected face gets no face point and keeps its corners, which do not
/// move. On the octahedron (8 faces), one step of √3 with face 0
/// protected splits the 7 others in three: 7·3 + 1 = 22 faces, where
/// 24 are made without protection.
#[test]
fn protected_faces_are_not_subdivided() {
    use subgram::mesh::FaceId;
    use subgram::surface::Protection;
    let g = grammar("surfaces/sqrt3.lsys");
    let base =
        Mesh::from_soup(&subgram::mesh::io::read(&lsys("meshes/octahedron.obj")).unwrap()).unwrap();
    let f = FaceId(0);
    let corners = base.face_vertices(f);
    let mut m = base.clone();
    let protection = Protection {
        faces: vec![true],
        vertices: vec![],
    };
    let mut run = g.start_protected(&mut m, protection).unwrap();
    run.steps(1, |_| {}).unwrap();
    m.validate().unwrap();
    assert_eq!(m.face_count(), 22);
    assert!(m.is_face(f));
    let now = m.face_vertices(f);
    assert!((0..3).any(|k| (0..3).all(|i| now[(k + i) % 3] == corners[i])));
    for v in corners {
        assert_eq!(m.position(v), base.position(v), "corner {v} moved");
    }
    // Without protection: 24 faces, and the corners move.
    let mut free = base.clone();
    g.run(&mut free, 1, |_| {}).unwrap();
    assert_eq!(free.face_count(), 24);
    assert!(corners
        .iter()
        .all(|&v| free.position(v) != base.position(v)));
}

/// A protected vertex keeps its position; edges at it still split, so
/// Loop's counts are those of a whole step: the octahedron's 6 vertices
/// and 12 edges give 18 vertices, then 18 + 48 = 66.
#[test]
fn protected_vertices_do_not_move() {
    use subgram::surface::Protection;
    let g = grammar("surfaces/loop.lsys");
    let base =
        Mesh::from_soup(&subgram::mesh::io::read(&lsys("meshes/octahedron.obj")).unwrap()).unwrap();
    let mut m = base.clone();
    let protection = Protection {
        faces: vec![],
        vertices: vec![true],
    };
    let mut run = g.start_protected(&mut m, protection).unwrap();
    run.steps(2, |_| {}).unwrap();
    m.validate().unwrap();
    assert_eq!(m.vertex_count(), 66);
    assert_eq!(m.position(VertexId(0)), base.position(VertexId(0)));
    assert_ne!(m.position(VertexId(1)), base.position(VertexId(1)));
    // Protecting what is not there is an error, not a panic.
    let mut m = base.clone();
    let e = g
        .start_protected(
            &mut m,
            Protection {
                faces: vec![false; 8].into_iter().chain([true]).collect(),
                vertices: vec![],
            },
        )
        .unwrap_err();
    assert_eq!(
        e.message,
        "face 9 is protected but is not a face of the mesh"
    );
}
