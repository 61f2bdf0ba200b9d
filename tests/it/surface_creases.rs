//! Creases in surface grammars (issue 15, part 2): sharpness kept by the
//! stellar operators and lowered by one per step, and the crease rules of
//! `catmull-clark.lsys` and `loop.lsys` against masks computed here. The
//! expected positions come from the curve and vertex masks written out in
//! each test (the cubic B-spline curve rules 1/2 1/2 and 1/8 3/4 1/8,
//! Loop's smooth masks, OpenSubdiv's blend of (1 - s) smooth + s sharp),
//! never from the grammar engine.

use glam::DVec3;
use subgram::mesh::{io, shapes, EdgeId, Mesh, VertexId};

use crate::support::*;

fn grammar(file: &str) -> subgram::surface::Grammar {
    subgram::surface::load_file(&lsys(file), &[]).unwrap_or_else(|e| panic!("{e}"))
}

fn run(g: &subgram::surface::Grammar, base: &Mesh, steps: usize) -> Mesh {
    let mut m = base.clone();
    g.run(&mut m, steps, |_| {})
        .unwrap_or_else(|e| panic!("{}", g.render_error(&e)));
    m.validate().unwrap();
    m
}

fn edge(m: &Mesh, a: u32, b: u32) -> EdgeId {
    m.find_halfedge(VertexId(a), VertexId(b))
        .unwrap_or_else(|| panic!("no edge {a}-{b}"))
        .edge()
}

/// Marks the closed polygon `loop_` (vertex ids) with sharpness `s`.
fn crease(m: &mut Mesh, loop_: &[u32], s: f64) {
    for k in 0..loop_.len() {
        let e = edge(m, loop_[k], loop_[(k + 1) % loop_.len()]);
        m.set_edge_sharpness(e, s).unwrap();
    }
}

/// `k` steps of cubic B-spline subdivision of a closed polygon: each old
/// point becomes 1/8 a + 3/4 v + 1/8 b, each edge gets its midpoint.
fn bspline(mut p: Vec<DVec3>, k: usize) -> Vec<DVec3> {
    for _ in 0..k {
        let n = p.len();
        let mut q = Vec::with_capacity(2 * n);
        for i in 0..n {
            let (a, v, b) = (p[(i + n - 1) % n], p[i], p[(i + 1) % n]);
            q.push(0.125 * a + 0.75 * v + 0.125 * b);
            q.push(0.5 * (v + b));
        }
        p = q;
    }
    p
}

/// The largest distance from a point of `want` to the nearest vertex of
/// `m` that has two sharp edges, and the number of those vertices.
fn crease_distance(m: &Mesh, want: &[DVec3]) -> (f64, usize) {
    let on: Vec<DVec3> = m
        .vertices()
        .filter(|&v| m.sharp_edge_count(v) == 2)
        .map(|v| m.position(v))
        .collect();
    let worst = want
        .iter()
        .map(|p| {
            on.iter()
                .map(|q| q.distance(*p))
                .fold(f64::INFINITY, f64::min)
        })
        .fold(0.0, f64::max);
    (worst, on.len())
}

fn octahedron(seed: u64) -> Mesh {
    let soup = io::read(&lsys("meshes/octahedron.obj")).unwrap();
    Mesh::from_soup(&jitter(soup, seed)).unwrap()
}

fn cube(seed: u64) -> Mesh {
    let soup = io::read(&lsys("meshes/cube.obj")).unwrap();
    Mesh::from_soup(&jitter(soup, seed)).unwrap()
}

/// The octahedron's equator (0-based ids of `meshes/octahedron.obj`).
const EQUATOR: [u32; 4] = [0, 2, 1, 3];
/// The cube's top rim (`meshes/cube.obj`, z = 1).
const RIM: [u32; 4] = [4, 5, 7, 6];

#[test]
fn loop_crease_is_the_cubic_bspline_of_its_polygon() {
    let g = grammar("surfaces/loop.lsys");
    let mut base = octahedron(5);
    crease(&mut base, &EQUATOR, f64::INFINITY);
    let polygon: Vec<DVec3> = EQUATOR
        .iter()
        .map(|&v| base.position(VertexId(v)))
        .collect();
    for k in 1..=4 {
        let m = run(&g, &base, k);
        let want = bspline(polygon.clone(), k);
        let (worst, count) = crease_distance(&m, &want);
        // The crease is 4 * 2^k edges long, every point on it.
        assert_eq!(count, want.len(), "step {k}");
        assert_eq!(
            m.edges().filter(|&e| m.is_sharp_edge(e)).count(),
            want.len()
        );
        assert!(worst < 1e-12, "step {k}: {worst}");
    }
}

#[test]
fn catmull_clark_crease_is_the_cubic_bspline_of_its_polygon() {
    let g = grammar("surfaces/catmull-clark.lsys");
    let mut base = cube(9);
    crease(&mut base, &RIM, f64::INFINITY);
    let polygon: Vec<DVec3> = RIM.iter().map(|&v| base.position(VertexId(v))).collect();
    for k in 1..=3 {
        let m = run(&g, &base, k);
        let want = bspline(polygon.clone(), k);
        let (worst, count) = crease_distance(&m, &want);
        assert_eq!(count, want.len(), "step {k}");
        assert!(worst < 1e-12, "step {k}: {worst}");
    }
}

#[test]
fn corners_stay_where_they_are() {
    // Loop: a vertex of infinite sharpness, and one with three sharp edges.
    let g = grammar("surfaces/loop.lsys");
    let mut base = octahedron(21);
    base.set_vertex_sharpness(VertexId(4), f64::INFINITY)
        .unwrap();
    for b in [0, 2, 3] {
        let e = edge(&base, 5, b);
        base.set_edge_sharpness(e, f64::INFINITY).unwrap();
    }
    let m = run(&g, &base, 3);
    for v in [4, 5] {
        assert_eq!(
            m.position(VertexId(v)),
            base.position(VertexId(v)),
            "vertex {v}"
        );
    }
    // A smooth vertex moves: the check above can fail.
    assert!(m.position(VertexId(1)).distance(base.position(VertexId(1))) > 1e-3);
    // Catmull-Clark: the cube's corner 7 with its three edges sharp.
    let g = grammar("surfaces/catmull-clark.lsys");
    let mut base = cube(4);
    for b in [3, 5, 6] {
        let e = edge(&base, 7, b);
        base.set_edge_sharpness(e, f64::INFINITY).unwrap();
    }
    let m = run(&g, &base, 3);
    assert_eq!(m.position(VertexId(7)), base.position(VertexId(7)));
    assert!(m.position(VertexId(0)).distance(base.position(VertexId(0))) > 1e-3);
}

/// OpenSubdiv's uniform rule: s = 2 is sharp for two levels, then smooth.
#[test]
fn sharpness_two_is_sharp_for_two_steps_then_smooth() {
    for (file, base, polygon) in [
        ("surfaces/loop.lsys", octahedron(3), &EQUATOR),
        ("surfaces/catmull-clark.lsys", cube(3), &RIM),
    ] {
        let g = grammar(file);
        let (mut two, mut inf) = (base.clone(), base.clone());
        crease(&mut two, polygon, 2.0);
        crease(&mut inf, polygon, f64::INFINITY);
        let a = run(&g, &two, 2);
        let b = run(&g, &inf, 2);
        // The same positions as a crease for ever, bit for bit.
        let pa: Vec<DVec3> = a.vertices().map(|v| a.position(v)).collect();
        let pb: Vec<DVec3> = b.vertices().map(|v| b.position(v)).collect();
        assert_eq!(pa, pb, "{file}");
        // Sharpness 2 -> 1 -> 0; infinite stays.
        assert!(a.edges().all(|e| a.edge_sharpness(e) == 0.0), "{file}");
        assert!(!a.has_sharpness());
        let sharp_b = b.edges().filter(|&e| b.is_sharp_edge(e)).count();
        assert_eq!(sharp_b, 4 << 2, "{file}");
        assert!(b
            .edges()
            .filter(|&e| b.is_sharp_edge(e))
            .all(|e| b.edge_sharpness(e) == f64::INFINITY));
        // The third step is smooth: that of the creased mesh made smooth.
        let one = run(&g, &two, 1);
        assert!(one
            .edges()
            .filter(|&e| one.is_sharp_edge(e))
            .all(|e| one.edge_sharpness(e) == 1.0));
        let c = run(&g, &two, 3);
        let mut smooth = b.clone();
        let edges: Vec<EdgeId> = smooth.edges().collect();
        for e in edges {
            smooth.set_edge_sharpness(e, 0.0).unwrap();
        }
        let d = run(&g, &smooth, 1);
        let pc: Vec<DVec3> = c.vertices().map(|v| c.position(v)).collect();
        let pd: Vec<DVec3> = d.vertices().map(|v| d.position(v)).collect();
        assert_eq!(pc, pd, "{file}");
        // And a crease for ever differs there.
        let e = run(&g, &inf, 3);
        let pe: Vec<DVec3> = e.vertices().map(|v| e.position(v)).collect();
        assert_ne!(pc, pe);
    }
}

/// Loop on a semi-sharp edge s = 1/2 between two smooth ends: OpenSubdiv
/// takes s of the midpoint and 1 - s of Loop's edge mask (3/8, 3/8, 1/8,
/// 1/8); an end with that one sharp edge keeps Loop's smooth vertex mask.
/// A vertex whose two edges are 1/2 takes 1/2 of 3/4 v + 1/8 (a + b) and
/// 1/2 of Loop's vertex mask (OpenSubdiv's fractional weight: the mean of
/// the sharpnesses that drop to 0, 1/2).
#[test]
fn loop_semi_sharp_blends_half_and_half() {
    let g = grammar("surfaces/loop.lsys");
    let mut base = octahedron(17);
    let s = 0.5;
    let (a, b) = (VertexId(0), VertexId(2));
    base.set_edge_sharpness(edge(&base, 0, 2), s).unwrap();
    let old = base.vertex_count() as u32;
    let m = run(&g, &base, 1);
    let p = |v: VertexId| base.position(v);
    let h = base.find_halfedge(a, b).unwrap();
    let c = base.to(base.next(h));
    let d = base.to(base.next(h.twin()));
    let smooth = 0.375 * (p(a) + p(b)) + 0.125 * (p(c) + p(d));
    let want = s * 0.5 * (p(a) + p(b)) + (1.0 - s) * smooth;
    let mid = m
        .one_ring(a)
        .find(|&w| w.0 >= old && m.find_halfedge(w, b).is_some())
        .unwrap();
    assert!(m.position(mid).distance(want) < 1e-12);
    let loop_vertex = |v: VertexId| {
        let n = base.valence(v) as f64;
        let beta =
            (5.0 / 8.0 - (3.0 / 8.0 + 0.25 * (2.0 * std::f64::consts::PI / n).cos()).powi(2)) / n;
        (1.0 - n * beta) * p(v) + beta * base.one_ring(v).map(p).sum::<DVec3>()
    };
    // One sharp edge: a dart, smooth.
    assert!(m.position(a).distance(loop_vertex(a)) < 1e-12);
    // Two semi-sharp edges at vertex 0: 0-2 and 0-3.
    let mut base2 = base.clone();
    base2.set_edge_sharpness(edge(&base2, 0, 3), s).unwrap();
    let m = run(&g, &base2, 1);
    let crease = 0.75 * p(a) + 0.125 * (p(b) + p(VertexId(3)));
    let want = s * crease + (1.0 - s) * loop_vertex(a);
    assert!(m.position(a).distance(want) < 1e-12);
}

/// Catmull-Clark on a semi-sharp edge s = 0.3 of a quad mesh: the edge
/// point is 0.3 of the midpoint and 0.7 of (a + b + two face points) / 4.
#[test]
fn catmull_clark_semi_sharp_edge_point() {
    let g = grammar("surfaces/catmull-clark.lsys");
    let mut base = cube(8);
    let s = 0.3;
    base.set_edge_sharpness(edge(&base, 0, 1), s).unwrap();
    let m = run(&g, &base, 1);
    let p = |i: u32| base.position(VertexId(i));
    // The quads on either side of 0-1: 0 2 3 1 (z = -1) and 0 1 5 4 (y = -1).
    let f1 = (p(0) + p(2) + p(3) + p(1)) / 4.0;
    let f2 = (p(0) + p(1) + p(5) + p(4)) / 4.0;
    let smooth = (p(0) + p(1) + f1 + f2) / 4.0;
    let want = s * 0.5 * (p(0) + p(1)) + (1.0 - s) * smooth;
    // The new vertices joined to both ends: the edge point and, across
    // the quads' diagonals, the two face points.
    let old = base.vertex_count() as u32;
    let mut d: Vec<f64> = m
        .one_ring(VertexId(0))
        .filter(|&w| w.0 >= old && m.find_halfedge(w, VertexId(1)).is_some())
        .map(|w| m.position(w).distance(want))
        .collect();
    d.sort_by(f64::total_cmp);
    assert_eq!(d.len(), 3);
    assert!(d[0] < 1e-12 && d[1] > 1e-3, "{d:?}");
}

#[test]
fn splits_keep_sharpness_and_flips_refuse_it() {
    let mut m = Mesh::from_soup(&shapes::icosahedron()).unwrap();
    let e = m.edges().next().unwrap();
    let (a, b) = m.edge_vertices(e);
    m.set_edge_sharpness(e, 2.5).unwrap();
    let v = m.edge_split(e, DVec3::ZERO).unwrap();
    for h in m.outgoing_halfedges(v) {
        let w = m.to(h);
        let want = if w == a || w == b { 2.5 } else { 0.0 };
        assert_eq!(m.edge_sharpness(h.edge()), want, "edge {v}-{w}");
    }
    assert_eq!(m.vertex_sharpness(v), 0.0);
    // A flip of a half is refused, and leaves the mesh as it was.
    let half = edge(&m, a.0, v.0);
    let before = m.clone();
    let err = m.edge_flip(half).unwrap_err();
    assert!(err.message.contains("is sharp"), "{}", err.message);
    assert_eq!(m, before);
    // Welding restores the edge with its sharpness.
    let back = m.edge_weld(v, a).unwrap();
    assert_eq!(m.edge_sharpness(back), 2.5);
    m.validate().unwrap();
    // A face split draws smooth edges.
    let f = m.faces().next().unwrap();
    let c = m.face_split(f, DVec3::ZERO).unwrap();
    assert!(m.outgoing_halfedges(c).all(|h| !m.is_sharp_edge(h.edge())));
    // Bad values are refused.
    assert!(m.set_edge_sharpness(back, -1.0).is_err());
    assert!(m.set_edge_sharpness(back, f64::NAN).is_err());
    assert!(m.set_vertex_sharpness(a, -0.5).is_err());
}

fn write(dir: &std::path::Path, name: &str, text: &str) -> std::path::PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn sharpness_is_read_from_ply_edges_and_creases_files() {
    let m = io::read_mesh(&lsys("meshes/creased-cube.ply")).unwrap();
    // The file's edge element, 0-based.
    for (a, b, s) in [
        (4, 5, f64::INFINITY),
        (5, 7, f64::INFINITY),
        (7, 6, f64::INFINITY),
        (6, 4, f64::INFINITY),
        (1, 5, 2.0),
        (0, 1, 0.5),
    ] {
        assert_eq!(m.edge_sharpness(edge(&m, a, b)), s, "{a}-{b}");
    }
    assert_eq!(m.edges().filter(|&e| m.is_sharp_edge(e)).count(), 6);
    let m = io::read_mesh(&lsys("meshes/creased-octahedron.obj")).unwrap();
    // The .creases file beside it, counted from 1.
    assert_eq!(m.vertex_sharpness(VertexId(4)), f64::INFINITY);
    assert_eq!(m.edge_sharpness(edge(&m, 4, 0)), 1.5);
    assert_eq!(m.edge_sharpness(edge(&m, 0, 2)), f64::INFINITY);
    assert_eq!(m.edges().filter(|&e| m.is_sharp_edge(e)).count(), 5);
    // Without the file, nothing is sharp; an OFF mesh reads one too, and
    // counts its vertices from 1 there as well.
    let tmp = scratch("creases-read");
    let dir = tmp.path();
    let off = write(
        dir,
        "t.off",
        "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n",
    );
    assert!(!io::read_mesh(&off).unwrap().has_sharpness());
    write(
        dir,
        "t.creases",
        "# comment\ne 1 2 3 # the first edge\n\nv 4 0.25\n",
    );
    let m = io::read_mesh(&off).unwrap();
    assert_eq!(m.edge_sharpness(edge(&m, 0, 1)), 3.0);
    assert_eq!(m.vertex_sharpness(VertexId(3)), 0.25);
}

#[test]
fn grammar_functions_read_sharpness() {
    // A grammar that moves each vertex by what the functions give, so the
    // positions say what they read.
    let tmp = scratch("creases-fns");
    let dir = tmp.path();
    let g = write(
        dir,
        "g.lsys",
        "mesh: \"m.obj\";\nderivation length: 1;\n\
         V(v; creases(v) == 2) -> V(v = v + point(sharpness(v), creases(v), \
         count(w in crease_ring(v))));\n\
         V(v; creases(v) != 2 && sharp(v)) -> V(v = v + point(crease_weight(v), 100, 0));\n",
    );
    let mut m = octahedron(0);
    crease(&mut m, &EQUATOR, 1.0);
    m.set_vertex_sharpness(VertexId(4), 0.75).unwrap();
    let base = m.clone();
    let gr = subgram::surface::load_file(&g, &[]).unwrap();
    let out = run(&gr, &m, 1);
    for v in EQUATOR {
        let d = out.position(VertexId(v)) - base.position(VertexId(v));
        assert_eq!(d, DVec3::new(0.0, 2.0, 2.0), "vertex {v}");
    }
    // Vertex 5 (id 4): a corner by its own sharpness 3/4, which drops to
    // 0 here: OpenSubdiv's weight is 3/4.
    let d = out.position(VertexId(4)) - base.position(VertexId(4));
    assert_eq!(d, DVec3::new(0.75, 100.0, 0.0));
    // The top and bottom vertices have no sharp edge.
    let d = out.position(VertexId(5)) - base.position(VertexId(5));
    assert_eq!(d, DVec3::ZERO);
}

#[test]
fn crease_weight_follows_opensubdiv() {
    // OpenSubdiv's fractional weight (Sdc::Crease, uniform creasing): 1
    // while the vertex's rule holds one level down, else the mean of the
    // sharpnesses in (0, 1] at it, at most 1.
    let tmp = scratch("creases-weight");
    let dir = tmp.path();
    write(
        dir,
        "g.lsys",
        "mesh: \"m.obj\";\nderivation length: 1;\n\
         V(v) -> V(v = point(crease_weight(v), 0, 0));\n",
    );
    let gr = subgram::surface::load_file(&dir.join("g.lsys"), &[]).unwrap();
    let weight = |sharp: &[(u32, u32, f64)], vs: f64| {
        let mut m = octahedron(0);
        for &(a, b, s) in sharp {
            let e = edge(&m, a, b);
            m.set_edge_sharpness(e, s).unwrap();
        }
        m.set_vertex_sharpness(VertexId(0), vs).unwrap();
        run(&gr, &m, 1).position(VertexId(0)).x
    };
    // Vertex 0's edges go to 2, 3, 4 and 5.
    assert_eq!(weight(&[], 0.0), 0.0); // smooth
    assert_eq!(weight(&[(0, 2, 0.5)], 0.0), 0.0); // a dart is smooth
    assert_eq!(weight(&[(0, 2, 3.0), (0, 3, 2.0)], 0.0), 1.0); // crease stays
    assert_eq!(weight(&[(0, 2, 0.5), (0, 3, 5.0)], 0.0), 0.5); // to a dart
    assert_eq!(weight(&[(0, 2, 0.5), (0, 3, 0.25)], 0.0), 0.375); // mean
    assert_eq!(weight(&[(0, 2, 1.0), (0, 3, 1.0)], 0.0), 1.0); // 1 -> 0
                                                               // Three sharp edges, one of which drops: corner to crease, 0.5.
    assert_eq!(weight(&[(0, 2, 4.0), (0, 3, 4.0), (0, 4, 0.5)], 0.0), 0.5);
    // A vertex of sharpness 0.25 with no sharp edge: 0.25.
    assert_eq!(weight(&[], 0.25), 0.25);
    // And of sharpness 2: still a corner one level down.
    assert_eq!(weight(&[], 2.0), 1.0);
}

/// `k` steps of cubic B-spline subdivision of an open polygon whose ends
/// are corners: they stay; inner points become 1/8 a + 3/4 v + 1/8 b;
/// every edge gets its midpoint.
fn bspline_open(mut p: Vec<DVec3>, k: usize) -> Vec<DVec3> {
    for _ in 0..k {
        let n = p.len();
        let mut q = Vec::with_capacity(2 * n - 1);
        for i in 0..n {
            q.push(if i == 0 || i == n - 1 {
                p[i]
            } else {
                0.125 * p[i - 1] + 0.75 * p[i] + 0.125 * p[i + 1]
            });
            if i + 1 < n {
                q.push(0.5 * (p[i] + p[i + 1]));
            }
        }
        p = q;
    }
    p
}

/// A crease across an open grid, from boundary to boundary: its ends are
/// corners (a boundary is a crease for ever, so three sharp edges meet
/// there) and stay; the rest follows the open cubic B-spline.
#[test]
fn a_crease_that_meets_the_boundary_ends_in_corners() {
    for (file, soup) in [
        ("surfaces/loop.lsys", shapes::triangle_grid(4, 3)),
        ("surfaces/catmull-clark.lsys", shapes::quad_grid(4, 3)),
    ] {
        let g = grammar(file);
        let mut base = Mesh::from_soup(&jitter(soup, 13)).unwrap();
        // Row j = 1 of the 5 x 4 vertices: ids 5 to 9.
        let row: Vec<u32> = (5..10).collect();
        for w in row.windows(2) {
            let e = edge(&base, w[0], w[1]);
            base.set_edge_sharpness(e, f64::INFINITY).unwrap();
        }
        let polygon: Vec<DVec3> = row.iter().map(|&v| base.position(VertexId(v))).collect();
        for k in 1..=3 {
            let m = run(&g, &base, k);
            let want = bspline_open(polygon.clone(), k);
            for end in [5, 9] {
                assert_eq!(
                    m.position(VertexId(end)),
                    base.position(VertexId(end)),
                    "{file}: step {k}, end {end}"
                );
            }
            let inner = &want[1..want.len() - 1];
            let (worst, count) = crease_distance(&m, inner);
            assert_eq!(count, inner.len(), "{file}: step {k}");
            assert!(worst < 1e-12, "{file}: step {k}: {worst}");
        }
        // Without the crease the ends move along the boundary curve.
        let m = run(
            &g,
            &Mesh::from_soup(&jitter(shapes::quad_grid(4, 3), 13)).unwrap(),
            1,
        );
        assert_ne!(m.position(VertexId(5)), base.position(VertexId(5)));
    }
}

/// OpenSubdiv's Chaikin rule for the half at `v` of an edge of sharpness
/// `s`, written out here from its documentation: smooth stays smooth,
/// infinite infinite; where another semi-sharp edge meets `v`, 3/4 s +
/// 1/4 (the mean of the other semi-sharp edges' sharpness) - 1, else s -
/// 1; never below 0.
fn chaikin_child(s: f64, others: &[f64]) -> f64 {
    if s <= 0.0 || s.is_infinite() {
        return s.max(0.0);
    }
    let semi: Vec<f64> = others
        .iter()
        .copied()
        .filter(|x| *x > 0.0 && x.is_finite())
        .collect();
    let s = if semi.is_empty() {
        s
    } else {
        0.75 * s + 0.25 * semi.iter().sum::<f64>() / semi.len() as f64
    };
    (s - 1.0).max(0.0)
}

/// Every sharp edge of `after` (one step of a grammar from `before`) holds
/// the Chaikin value of its parent at its old end: the half (x, n), n new,
/// has parent (x, z) in `before`, z the far end of n's other sharp half.
/// Returns how many edges were checked.
fn check_chaikin_step(before: &Mesh, after: &Mesh, what: &str) -> usize {
    let old = |v: VertexId| before.is_vertex(v);
    let mut checked = 0;
    for e in after.edges() {
        // A quad's diagonal (Catmull-Clark's blocks) joins an old corner
        // to a face point: not a half of an old edge.
        if after.is_block_edge(e) {
            continue;
        }
        let s = after.edge_sharpness(e);
        let (a, b) = after.edge_vertices(e);
        let (x, n) = match (old(a), old(b)) {
            (true, false) => (a, b),
            (false, true) => (b, a),
            _ => continue,
        };
        // n is new on the edge x-z of `before`: its old neighbours are x
        // and z (its other neighbours are new in both schemes).
        let Some(z) = after
            .outgoing_halfedges(n)
            .map(|h| after.to(h))
            .find(|&z| z != x && old(z))
        else {
            continue;
        };
        let parent = before.find_halfedge(x, z).unwrap().edge();
        let ps = before.edge_sharpness(parent);
        if ps <= 0.0 {
            continue;
        }
        let others: Vec<f64> = before
            .outgoing_halfedges(x)
            .filter(|h| h.edge() != parent)
            .map(|h| before.edge_sharpness(h.edge()))
            .collect();
        let want = chaikin_child(ps, &others);
        assert!(
            (s - want).abs() < 1e-12,
            "{what}: the half at {x} of edge {x}-{z} (sharpness {ps}, others {others:?}) \
             has {s}, Chaikin gives {want}"
        );
        checked += 1;
    }
    checked
}

/// OpenSubdiv's Chaikin creasing (`creasing: chaikin;`, which
/// `-D CHAIKIN=1` turns on in the shipped grammars): a rim of four edges
/// of different sharpness on the cube (Catmull-Clark) and an equator on
/// the octahedron (Loop); after each of three steps every sharp half holds
/// the rule's value computed here from the step before, and the two
/// halves of one edge differ where its ends see different neighbours.
#[test]
fn chaikin_creasing_softens_each_half_by_its_ends_neighbours() {
    let defines = ["CHAIKIN=1".to_string()];
    for (file, base, ring, values) in [
        (
            "surfaces/catmull-clark.lsys",
            cube(7),
            RIM,
            [0.8, 3.0, 2.0, 1.5],
        ),
        (
            "surfaces/loop.lsys",
            octahedron(7),
            EQUATOR,
            [2.5, 0.6, 1.7, 3.2],
        ),
    ] {
        let g = subgram::surface::load_file(&lsys(file), &defines).unwrap();
        let mut m = base.clone();
        for k in 0..4 {
            let e = edge(&m, ring[k], ring[(k + 1) % 4]);
            m.set_edge_sharpness(e, values[k]).unwrap();
        }
        let mut before = m.clone();
        let mut uneven = false;
        for steps in 1..=3 {
            let after = run(&g, &m, steps);
            let n = check_chaikin_step(&before, &after, &format!("{file}, step {steps}"));
            assert!(
                n >= 8 || steps == 3,
                "{file}, step {steps}: only {n} halves checked"
            );
            if steps == 1 {
                // The halves of the rim's first edge, at its two ends.
                let s: Vec<f64> = after
                    .edges()
                    .map(|e| after.edge_sharpness(e))
                    .filter(|s| *s > 0.0)
                    .collect();
                let distinct = s
                    .iter()
                    .map(|x| (x * 1e9) as i64)
                    .collect::<std::collections::BTreeSet<_>>();
                uneven = distinct.len() > 4;
            }
            before = after;
        }
        assert!(uneven, "{file}: the halves all took the same values");
    }
}

/// Where the methods differ, the positions follow: on the cube with a rim
/// of sharpness 0.8 on one edge and 3 on the other three, uniform
/// creasing blends the corner between the two (0.8 of its crease rule:
/// the 0.8 edge dies) and the 0.8 edge's point between midpoint and
/// smooth point (0.8), while Chaikin's keeps the edge sharp one level
/// down at both ends (3/4 0.8 + 1/4 3 - 1 = 0.35), so the corner takes
/// the crease rule 3/4 v + 1/8 (a + b) whole and the edge point is the
/// midpoint: masks computed here.
#[test]
fn chaikin_creasing_keeps_a_weak_edge_next_to_strong_ones() {
    let mut m = cube(3);
    for k in 0..4 {
        let e = edge(&m, RIM[k], RIM[(k + 1) % 4]);
        m.set_edge_sharpness(e, if k == 0 { 0.8 } else { 3.0 })
            .unwrap();
    }
    let p = |v: u32| m.position(VertexId(v));
    let (v0, v1, v3) = (RIM[0], RIM[1], RIM[3]);
    let crease_point = 0.75 * p(v0) + 0.125 * (p(v1) + p(v3));
    let midpoint = 0.5 * (p(v0) + p(v1));
    let has = |out: &Mesh, q: DVec3| out.vertices().any(|v| out.position(v).distance(q) < 1e-12);
    let chaikin = subgram::surface::load_file(
        &lsys("surfaces/catmull-clark.lsys"),
        &["CHAIKIN=1".to_string()],
    )
    .unwrap();
    let out = run(&chaikin, &m, 1);
    assert!(
        has(&out, crease_point),
        "Chaikin: the corner takes the crease rule"
    );
    assert!(
        has(&out, midpoint),
        "Chaikin: the weak edge's point is its midpoint"
    );
    assert!((out.position(VertexId(v0)) - crease_point).length() < 1e-12);
    let uniform = grammar("surfaces/catmull-clark.lsys");
    let out = run(&uniform, &m, 1);
    assert!(
        !has(&out, crease_point) && !has(&out, midpoint),
        "uniform blends both"
    );
    assert!((out.position(VertexId(v0)) - crease_point).length() > 1e-3);
}
