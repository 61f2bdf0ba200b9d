//! The half-edge mesh: building, invariants, the stellar operators with
//! their levels and inverses, refusals, random sequences, quads and info.

use glam::DVec3;
use subgram::mesh::shapes;
use subgram::mesh::{EdgeId, FaceId, Mesh, PolygonSoup, VertexId};

use crate::support::scratch;

fn soup(positions: &[[f64; 3]], faces: &[&[u32]]) -> PolygonSoup {
    PolygonSoup {
        positions: positions.iter().map(|p| DVec3::from_array(*p)).collect(),
        faces: faces.iter().map(|f| f.to_vec()).collect(),
        ..Default::default()
    }
}

/// Two triangles sharing the edge 0-1: (0,1,2) above, (1,0,3) below.
fn diamond() -> Mesh {
    let s = soup(
        &[[0., 0., 0.], [1., 0., 0.], [0.5, 1., 0.], [0.5, -1., 0.]],
        &[&[0, 1, 2], &[1, 0, 3]],
    );
    Mesh::from_soup(&s).unwrap()
}

fn tetrahedron() -> Mesh {
    let s = soup(
        &[[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]],
        &[&[0, 2, 1], &[0, 1, 3], &[1, 2, 3], &[2, 0, 3]],
    );
    Mesh::from_soup(&s).unwrap()
}

fn edge_between(m: &Mesh, a: u32, b: u32) -> EdgeId {
    m.find_halfedge(VertexId(a), VertexId(b))
        .expect("joined")
        .edge()
}

fn ring(m: &Mesh, v: VertexId) -> Vec<u32> {
    m.one_ring(v).map(|w| w.0).collect()
}

#[test]
fn building_gives_valid_meshes_with_the_right_counts() {
    for (s, v, e, f) in [
        (shapes::icosahedron(), 12, 30, 20),
        (shapes::icosphere(2), 162, 480, 320),
        (shapes::triangle_grid(3, 2), 12, 23, 12),
    ] {
        let m = Mesh::from_soup(&s).unwrap();
        m.validate().unwrap();
        assert_eq!(
            (m.vertex_count(), m.edge_count(), m.face_count()),
            (v, e, f)
        );
    }
}

#[test]
fn one_rings_are_ordered_and_boundary_aware() {
    let m = diamond();
    // Vertex 0: counter-clockwise from across the first face to the
    // boundary: 3 then 1 then 2... the walk crosses faces only.
    let r = ring(&m, VertexId(0));
    assert_eq!(r.len(), 3);
    assert!(m.is_boundary_vertex(VertexId(0)));
    let pos = |v: u32| m.position(VertexId(v));
    // Consecutive neighbours are counter-clockwise around vertex 0.
    for w in r.windows(2) {
        let (a, b) = (pos(w[0]) - pos(0), pos(w[1]) - pos(0));
        assert!(
            a.x * b.y - a.y * b.x > 0.0,
            "{r:?} is not counter-clockwise"
        );
    }
    // Consecutive neighbours share a face.
    for w in r.windows(2) {
        assert!(m.find_halfedge(VertexId(w[0]), VertexId(w[1])).is_some());
    }
    // An interior vertex of a closed mesh: a full cycle.
    let t = tetrahedron();
    assert_eq!(ring(&t, VertexId(3)).len(), 3);
    assert_eq!(
        t.edge_faces(edge_between(&t, 0, 1))
            .iter()
            .flatten()
            .count(),
        2
    );
}

#[test]
fn face_split_counts_rings_and_levels() {
    let mut m = tetrahedron();
    let f = FaceId(0);
    let corners = m.face_vertices(f);
    let v = m.face_split(f, DVec3::new(0.3, 0.3, 0.0)).unwrap();
    m.validate().unwrap();
    assert_eq!(
        (m.vertex_count(), m.edge_count(), m.face_count()),
        (5, 9, 6)
    );
    assert_eq!(m.vertex_level(v), 1, "max(0, 0, 0) + 1");
    let mut r = ring(&m, v);
    r.sort();
    let mut c: Vec<u32> = corners.iter().map(|c| c.0).collect();
    c.sort();
    assert_eq!(r, c);
    for w in corners {
        assert_eq!(
            m.edge_level(edge_between(&m, v.0, w.0)),
            1,
            "the level of the common vertex"
        );
    }
    for f in m.vertex_faces(v) {
        assert_eq!(m.face_level(f), 2);
    }
}

#[test]
fn edge_split_counts_rings_and_levels() {
    let mut m = diamond();
    let e = edge_between(&m, 0, 1);
    m.set_edge_level(e, 3);
    m.set_vertex_level(VertexId(2), 5);
    let v = m.edge_split(e, DVec3::new(0.5, 0.0, 0.0)).unwrap();
    m.validate().unwrap();
    assert_eq!(
        (m.vertex_count(), m.edge_count(), m.face_count()),
        (5, 8, 4)
    );
    assert_eq!(m.vertex_level(v), 1);
    assert_eq!(m.valence(v), 4);
    assert_eq!(
        m.edge_level(edge_between(&m, 0, v.0)),
        5,
        "bisection: 3 + 2"
    );
    assert_eq!(m.edge_level(edge_between(&m, v.0, 1)), 5);
    assert_eq!(
        m.edge_level(edge_between(&m, v.0, 2)),
        6,
        "transversal: l(2) + 1"
    );
    assert_eq!(
        m.edge_level(edge_between(&m, v.0, 3)),
        1,
        "transversal: l(3) + 1"
    );
    assert!(m.find_halfedge(VertexId(0), VertexId(1)).is_none());
}

#[test]
fn boundary_edge_split_makes_two_triangles_from_one() {
    let s = soup(&[[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]], &[&[0, 1, 2]]);
    let mut m = Mesh::from_soup(&s).unwrap();
    let v = m
        .edge_split(edge_between(&m, 0, 1), DVec3::new(0.5, 0.0, 0.0))
        .unwrap();
    m.validate().unwrap();
    assert_eq!(
        (m.vertex_count(), m.edge_count(), m.face_count()),
        (4, 5, 2)
    );
    assert!(m.is_boundary_vertex(v));
    assert_eq!(ring(&m, v).len(), 3);
    assert_eq!(m.edge_level(edge_between(&m, v.0, 2)), 1);
    assert_eq!(m.info().boundary_loops, 1);
}

#[test]
fn edge_flip_turns_the_diagonal_and_raises_its_level() {
    let mut m = diamond();
    let e = edge_between(&m, 0, 1);
    m.edge_flip(e).unwrap();
    m.validate().unwrap();
    assert!(m.find_halfedge(VertexId(2), VertexId(3)).is_some());
    assert!(m.find_halfedge(VertexId(0), VertexId(1)).is_none());
    assert_eq!(m.edge_level(e), 1);
    assert_eq!(
        (m.vertex_count(), m.edge_count(), m.face_count()),
        (4, 5, 2)
    );
}

#[test]
fn every_operator_followed_by_its_inverse_gives_the_same_mesh() {
    let base = Mesh::from_soup(&shapes::icosphere(1)).unwrap();
    let before = base.canonical();
    // Face split, then face weld.
    let mut m = base.clone();
    let v = m.face_split(FaceId(7), DVec3::new(0.1, 0.2, 0.3)).unwrap();
    m.face_weld(v).unwrap();
    m.validate().unwrap();
    assert_eq!(m.canonical(), before);
    // Edge split, then edge weld.
    let mut m = base.clone();
    let e = EdgeId(11);
    let (a, _) = m.edge_vertices(e);
    let v = m.edge_split(e, DVec3::ZERO).unwrap();
    m.edge_weld(v, a).unwrap();
    m.validate().unwrap();
    assert_eq!(m.canonical(), before);
    // A flip twice gives the same connectivity, the level raised twice.
    let mut m = base.clone();
    m.edge_flip(EdgeId(5)).unwrap();
    m.edge_flip(EdgeId(5)).unwrap();
    m.validate().unwrap();
    let mut c = m.canonical();
    for x in &mut c.edges {
        if Some((x.0, x.1))
            == Some({
                let (a, b) = base.edge_vertices(EdgeId(5));
                (a.0.min(b.0), a.0.max(b.0))
            })
        {
            assert_eq!(x.2, 2);
            x.2 = 0;
        }
    }
    assert_eq!(c, before);
    // The boundary versions.
    let s = shapes::triangle_grid(2, 2);
    let open = Mesh::from_soup(&s).unwrap();
    let before = open.canonical();
    let mut m = open.clone();
    let e = m.edges().find(|&e| m.is_boundary_edge(e)).unwrap();
    let (a, b) = m.edge_vertices(e);
    let v = m.edge_split(e, DVec3::new(9.0, 9.0, 0.0)).unwrap();
    m.validate().unwrap();
    m.edge_weld(v, b).unwrap();
    m.validate().unwrap();
    assert_eq!(m.canonical(), before, "boundary edge {}-{}", a.0, b.0);
}

#[test]
fn refusals_name_the_reason_and_leave_the_mesh_unchanged() {
    let mut m = diamond();
    let before = m.canonical();
    let boundary = edge_between(&m, 0, 2);
    assert_eq!(m.edge_flip(boundary).unwrap_err().message, {
        let (a, b) = m.edge_vertices(boundary);
        assert_eq!((a.0.min(b.0), a.0.max(b.0)), (0, 2));
        // Messages count vertices from 1, as mesh files do.
        format!(
                "edge flip: the edge between vertices {} and {} is on the boundary and cannot be flipped",
                a.0 + 1,
                b.0 + 1
            )
    });
    assert_eq!(
        m.face_weld(VertexId(0)).unwrap_err().message,
        "face weld: vertex 1 is on the boundary"
    );
    assert_eq!(
        m.edge_weld(VertexId(2), VertexId(0)).unwrap_err().message,
        "edge weld: vertex 3 has valence 2, but a boundary vertex of valence 3 is needed"
    );
    assert_eq!(m.canonical(), before);
    let mut t = tetrahedron();
    let before = t.canonical();
    let e = edge_between(&t, 0, 1);
    assert_eq!(t.edge_flip(e).unwrap_err().message, {
        let (a, b) = t.edge_vertices(e);
        format!(
                "edge flip: flipping the edge between vertices {} and {} would duplicate the edge between vertices 3 and 4",
                a.0 + 1,
                b.0 + 1
            )
    });
    assert_eq!(
        t.face_weld(VertexId(3)).unwrap_err().message,
        "face weld: welding vertex 4 would make a triangle that already exists (a doubled face)"
    );
    let ico = Mesh::from_soup(&shapes::icosahedron()).unwrap();
    let mut i2 = ico.clone();
    assert_eq!(
        i2.face_weld(VertexId(0)).unwrap_err().message,
        "face weld: vertex 1 has valence 5, but only a vertex of valence 3 can be welded into a face"
    );
    assert_eq!(
        i2.edge_weld(VertexId(0), VertexId(1)).unwrap_err().message,
        "edge weld: vertex 1 has valence 5, but an interior vertex of valence 4 is needed"
    );
    assert_eq!(i2.canonical(), ico.canonical());
    assert_eq!(t.canonical(), before);
}

#[test]
fn broken_meshes_are_refused_with_the_element_named() {
    let p = [
        [0., 0., 0.],
        [1., 0., 0.],
        [0., 1., 0.],
        [0., 0., 1.],
        [1., 1., 1.],
        [2., 0., 0.],
        [2., 1., 0.],
    ];
    let cases: &[(&[&[u32]], &str)] = &[
        (
            &[&[0, 1, 2], &[1, 0, 3], &[0, 1, 4]],
            "face 3 is shared by three or more faces",
        ),
        (
            &[&[0, 1, 2], &[0, 1, 3]],
            "is used in the same direction by two faces (inconsistent orientation)",
        ),
        (&[&[0, 1, 2], &[0, 5, 6]], "vertex 1 is a bow-tie"),
        (
            &[&[0, 1, 1]],
            "face 1 is degenerate: it uses vertex 2 twice",
        ),
        (
            &[&[0, 1, 9]],
            "face 1 refers to vertex 10, but there are only 7 vertices",
        ),
        (&[&[0, 1, 2], &[3, 4]], "face 2 has 2 vertices"),
        (
            // A closed pocket of two faces: splitting an edge would join
            // two vertices twice.
            &[&[0, 1, 2], &[0, 2, 1]],
            "faces 1 and 2 share the same three vertices 1, 2 and 3",
        ),
    ];
    for (faces, want) in cases {
        let e = Mesh::from_soup(&soup(&p, faces)).unwrap_err().message;
        assert!(e.contains(want), "{e}");
    }
    let mut s = soup(&p, &[&[0, 1, 2]]);
    s.positions[1].y = f64::NAN;
    s.vertex_lines = vec![3, 4, 5, 6, 7, 8, 9];
    let e = Mesh::from_soup(&s).unwrap_err().message;
    assert_eq!(e, "vertex 2 (line 4) has a non-finite coordinate");
    let mut s = soup(&p, &[&[0, 1, 2], &[0, 1, 3]]);
    s.face_lines = vec![10, 11];
    let e = Mesh::from_soup(&s).unwrap_err().message;
    assert!(
        e.contains("of face 2 (line 11)") && e.contains("face 1 (line 10)"),
        "{e}"
    );
    let flat = soup(&[[0., 0., 0.], [1., 0., 0.], [2., 0., 0.]], &[&[0, 1, 2]]);
    assert!(Mesh::from_soup(&flat)
        .unwrap_err()
        .message
        .contains("zero area"));
}

/// A small deterministic generator for the property test.
struct Rng(u64);

impl Rng {
    fn below(&mut self, n: usize) -> usize {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 % n as u64) as usize
    }
}

#[test]
fn random_operator_sequences_keep_every_invariant() {
    for (seed, s) in [
        (1u64, shapes::icosphere(1)),
        (7, shapes::triangle_grid(4, 3)),
        (99, shapes::quad_grid(3, 3)),
    ] {
        let mut m = Mesh::from_soup(&s).unwrap();
        let mut rng = Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1);
        let mut applied = 0;
        for step in 0..400 {
            let before = m.canonical();
            let faces: Vec<FaceId> = m.faces().collect();
            let edges: Vec<EdgeId> = m.edges().collect();
            let verts: Vec<VertexId> = m.vertices().collect();
            let r = match rng.below(5) {
                0 => m
                    .face_split(faces[rng.below(faces.len())], DVec3::splat(step as f64))
                    .map(|_| ()),
                1 => m
                    .edge_split(edges[rng.below(edges.len())], DVec3::splat(-(step as f64)))
                    .map(|_| ()),
                2 => m.edge_flip(edges[rng.below(edges.len())]),
                3 => m.face_weld(verts[rng.below(verts.len())]).map(|_| ()),
                _ => {
                    let v = verts[rng.below(verts.len())];
                    let n = m.one_ring(v).next().unwrap_or(v);
                    m.edge_weld(v, n).map(|_| ())
                }
            };
            match r {
                Ok(()) => applied += 1,
                Err(_) => assert_eq!(m.canonical(), before, "a refused operator changed the mesh"),
            }
            if let Err(e) = m.validate() {
                panic!("seed {seed}, step {step}: {e}");
            }
            let info = m.info();
            assert_eq!(
                info.euler_characteristic,
                Mesh::from_soup(&s).unwrap().info().euler_characteristic
            );
        }
        assert!(applied > 100, "only {applied} operators applied");
    }
}

#[test]
fn quads_become_basic_blocks_and_come_back() {
    let s = shapes::quad_grid(3, 2);
    let m = Mesh::from_soup(&s).unwrap();
    m.validate().unwrap();
    assert_eq!(m.face_count(), 12);
    let blocks = m.edges().filter(|&e| m.is_block_edge(e)).count();
    assert_eq!(blocks, 6);
    // Levels of paper 000, section 7: internal 0, external 1, vertices 0.
    for e in m.edges() {
        assert_eq!(m.edge_level(e), if m.is_block_edge(e) { 0 } else { 1 });
    }
    assert!(m.vertices().all(|v| m.vertex_level(v) == 0));
    let back = m.to_quad_soup();
    assert_eq!(back.faces.len(), 6);
    let mut a: Vec<Vec<u32>> = s.faces.iter().map(canonical_cycle).collect();
    let mut b: Vec<Vec<u32>> = back.faces.iter().map(canonical_cycle).collect();
    a.sort();
    b.sort();
    assert_eq!(a, b);
    // A pentagon is fanned from its first vertex: three triangles.
    let pent = soup(
        &[
            [0., 0., 0.],
            [1., 0., 0.],
            [1.5, 1., 0.],
            [0.5, 1.5, 0.],
            [-0.5, 1., 0.],
        ],
        &[&[0, 1, 2, 3, 4]],
    );
    let m = Mesh::from_soup(&pent).unwrap();
    assert_eq!(m.face_count(), 3);
    assert_eq!(m.valence(VertexId(0)), 4);
}

fn canonical_cycle(f: &[u32]) -> Vec<u32> {
    let k = (0..f.len()).min_by_key(|&i| f[i]).unwrap();
    (0..f.len()).map(|i| f[(k + i) % f.len()]).collect()
}

#[test]
fn info_reports_topology() {
    let torus = Mesh::from_soup(&shapes::quad_torus(8, 6)).unwrap();
    let i = torus.info();
    assert_eq!(
        (
            i.euler_characteristic,
            i.genus,
            i.boundary_loops,
            i.components
        ),
        (0, Some(1), 0, 1)
    );
    assert_eq!(i.quads, 48);
    let sphere = Mesh::from_soup(&shapes::icosphere(1)).unwrap().info();
    assert_eq!((sphere.euler_characteristic, sphere.genus), (2, Some(0)));
    assert_eq!(sphere.valences.get(&5), Some(&12));
    assert_eq!(sphere.valences.get(&6), Some(&30));
    let disc = Mesh::from_soup(&shapes::triangle_grid(2, 2))
        .unwrap()
        .info();
    assert_eq!(
        (disc.euler_characteristic, disc.genus, disc.boundary_loops),
        (1, Some(0), 1)
    );
    // A stray vertex on no face is reported, not counted as a sphere.
    let s = soup(
        &[[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [5., 5., 5.]],
        &[&[0, 1, 2]],
    );
    let i = Mesh::from_soup(&s).unwrap().info();
    assert_eq!(
        (
            i.vertices,
            i.isolated_vertices,
            i.components,
            i.euler_characteristic,
            i.genus
        ),
        (4, 1, 1, 1, Some(0))
    );
}

/// One Loop-style refinement, topology only: split every edge, then flip
/// the new edges that join an old vertex to a new one... the decomposition
/// of paper 000, §6: flip the edges whose level is the current level - 1.
#[test]
fn split_then_flip_is_quadrisection() {
    let mut m = Mesh::from_soup(&shapes::icosahedron()).unwrap();
    let old: Vec<EdgeId> = m.edges().collect();
    for e in old {
        let (a, b) = m.edge_vertices(e);
        let p = (m.position(a) + m.position(b)) * 0.5;
        m.edge_split(e, p).unwrap();
    }
    // After the splits: transversal edges from old vertices (level 0 + 1 = 1)
    // join a new vertex to an old one across a face, and those are flipped.
    let flip: Vec<EdgeId> = m
        .edges()
        .filter(|&e| {
            let (a, b) = m.edge_vertices(e);
            m.edge_level(e) == 1
                && m.vertex_level(a).min(m.vertex_level(b)) == 0
                && m.vertex_level(a).max(m.vertex_level(b)) == 1
        })
        .collect();
    for e in flip {
        m.edge_flip(e).unwrap();
    }
    m.validate().unwrap();
    assert_eq!(
        (m.vertex_count(), m.edge_count(), m.face_count()),
        (42, 120, 80)
    );
    let i = m.info();
    assert_eq!(i.valences.get(&5), Some(&12));
    assert_eq!(i.valences.get(&6), Some(&30));
}

fn bin(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_subgram"))
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn mesh_commands_info_convert_and_render() {
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let torus = root.join("lsystems/meshes/torus.obj");
    let o = bin(&["mesh", "info", torus.to_str().unwrap(), "--format", "json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["genus"], 1);
    assert_eq!(v["quads"], 96);
    let o = bin(&["mesh", "info", torus.to_str().unwrap()]);
    assert!(String::from_utf8_lossy(&o.stdout).contains("Euler characteristic 0, genus 1"));
    let tmp = scratch("mesh-cli");
    let dir = tmp.path();
    for ext in ["off", "ply", "obj"] {
        let out = dir.join(format!("t.{ext}"));
        let o = bin(&[
            "mesh",
            "convert",
            torus.to_str().unwrap(),
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let back = subgram::mesh::io::read(&out).unwrap();
        assert_eq!(back.faces.len(), 96, "{ext}: the quads come back");
        let m = Mesh::from_soup(&back).unwrap();
        assert_eq!(m.info().genus, Some(1));
    }
    let png = dir.join("t.png");
    let o = bin(&[
        "render",
        torus.to_str().unwrap(),
        "-o",
        png.to_str().unwrap(),
        "--view",
        "top",
        "--size",
        "200x150",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let pm = tiny_skia::Pixmap::decode_png(&std::fs::read(&png).unwrap()).unwrap();
    assert_eq!((pm.width(), pm.height()), (200, 150));
    let o = bin(&[
        "render",
        torus.to_str().unwrap(),
        "-o",
        png.to_str().unwrap(),
        "--view",
        "xy",
    ]);
    assert_eq!(o.status.code(), Some(2));
    // A broken mesh names the file, the line and the element.
    let bad = dir.join("bad.obj");
    std::fs::write(
        &bad,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\n",
    )
    .unwrap();
    let o = bin(&["mesh", "info", bad.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert!(
        err.contains("bad.obj:6:1: error: the edge between vertices 1 and 2 of face 2 (line 6)")
            && err.contains("6 | f 1 2 4\n  | ^^^^^^^"),
        "{err}"
    );
    assert!(err.contains("inconsistent orientation"), "{err}");
}

/// The tag of the face on corners `vs` (any order).
fn tag_of(m: &Mesh, vs: [u32; 3]) -> u32 {
    let mut want = vs;
    want.sort();
    let f = m
        .faces()
        .find(|&f| {
            let mut c = m.face_vertices(f).map(|v| v.0);
            c.sort();
            c == want
        })
        .unwrap_or_else(|| panic!("no face {vs:?}"));
    m.tag(f)
}

/// Tags as the operators' documentation defines them, on the diamond
/// (0,1,2) above the edge 0-1 tagged 7 and (1,0,3) below it tagged 9:
/// a face split's three faces keep the split face's tag; an edge split's
/// halves keep the tag of the face they were cut from; a flip keeps each
/// face's tag on the new face with its corner 0 (resp. 1) and its old
/// edge 2-0 (resp. 3-1); a weld gives the merged faces back their tags.
#[test]
fn tags_are_handed_down_by_the_stellar_operators() {
    let s = soup(
        &[[0., 0., 0.], [1., 0., 0.], [0.5, 1., 0.], [0.5, -1., 0.]],
        &[&[0, 1, 2], &[1, 0, 3]],
    );
    let base = Mesh::from_soup_tagged(&s, &[7, 9]).unwrap();
    assert_eq!((tag_of(&base, [0, 1, 2]), tag_of(&base, [0, 1, 3])), (7, 9));
    // Untagged meshes have tag 0; a tag list of the wrong length is refused.
    let plain = Mesh::from_soup(&s).unwrap();
    assert!(plain.faces().all(|f| plain.tag(f) == 0));
    let e = Mesh::from_soup_tagged(&s, &[7]).unwrap_err();
    assert_eq!(e.message, "1 tags were given for 2 faces");

    let mut m = base.clone();
    let f = m.faces().find(|&f| m.tag(f) == 7).unwrap();
    let v = m.face_split(f, DVec3::new(0.5, 0.3, 0.0)).unwrap();
    for g in m.vertex_faces(v) {
        assert_eq!(m.tag(g), 7);
    }
    assert_eq!(tag_of(&m, [0, 1, 3]), 9);
    m.face_weld(v).unwrap();
    assert_eq!((tag_of(&m, [0, 1, 2]), tag_of(&m, [0, 1, 3])), (7, 9));

    for keep in [0, 1] {
        let mut m = base.clone();
        let v = m
            .edge_split(edge_between(&m, 0, 1), DVec3::new(0.5, 0.0, 0.0))
            .unwrap();
        m.validate().unwrap();
        let v4 = v.0;
        assert_eq!(tag_of(&m, [0, v4, 2]), 7);
        assert_eq!(tag_of(&m, [v4, 1, 2]), 7);
        assert_eq!(tag_of(&m, [0, v4, 3]), 9);
        assert_eq!(tag_of(&m, [v4, 1, 3]), 9);
        m.edge_weld(v, VertexId(keep)).unwrap();
        m.validate().unwrap();
        assert_eq!(
            (tag_of(&m, [0, 1, 2]), tag_of(&m, [0, 1, 3])),
            (7, 9),
            "welded towards vertex {keep}"
        );
    }

    // The edge's first half-edge runs 0 -> 1 in face (0,1,2): a = 0,
    // b = 1, c = 2, d = 3.
    let mut m = base.clone();
    let e = edge_between(&m, 0, 1);
    assert_eq!(m.edge_vertices(e), (VertexId(0), VertexId(1)));
    m.edge_flip(e).unwrap();
    assert_eq!(tag_of(&m, [3, 2, 0]), 7);
    assert_eq!(tag_of(&m, [2, 3, 1]), 9);

    // A boundary edge split and its weld.
    let mut m = base.clone();
    let v = m
        .edge_split(edge_between(&m, 1, 2), DVec3::new(0.75, 0.5, 0.0))
        .unwrap();
    assert!(m.vertex_faces(v).all(|g| m.tag(g) == 7));
    m.edge_weld(v, VertexId(2)).unwrap();
    assert_eq!((tag_of(&m, [0, 1, 2]), tag_of(&m, [0, 1, 3])), (7, 9));
}

/// Tags come back with the soup: per triangle, and per polygon where
/// blocks merge into quads; a block whose halves have different tags
/// stays two triangles.
#[test]
fn soups_come_back_with_their_tags() {
    let s = shapes::quad_grid(2, 1);
    let m = Mesh::from_soup_tagged(&s, &[4, 5]).unwrap();
    let (tris, tags) = m.to_soup_tagged();
    assert_eq!(tris.faces.len(), 4);
    for (f, t) in tris.faces.iter().zip(&tags) {
        // Quad 0 has x < 0.5 everywhere, quad 1 x >= 0.5.
        let left = f.iter().all(|&v| tris.positions[v as usize].x <= 0.5);
        let right = f.iter().all(|&v| tris.positions[v as usize].x >= 0.5);
        assert_eq!(*t, if left && !right { 4 } else { 5 }, "{f:?}");
    }
    let (quads, tags) = m.to_quad_soup_tagged();
    assert_eq!(quads, m.to_quad_soup());
    assert_eq!(quads.faces.len(), 2);
    let mut got: Vec<(Vec<u32>, u32)> = quads.faces.iter().map(canonical_cycle).zip(tags).collect();
    got.sort();
    let mut want: Vec<(Vec<u32>, u32)> = s.faces.iter().map(canonical_cycle).zip([4, 5]).collect();
    want.sort();
    assert_eq!(got, want);
    // √2 bisection of quad 0's block makes its external edges internal
    // edges of the next blocks; the one it shares with the triangle on
    // its right then joins a triangle tagged 4 to one tagged 5: without
    // tags the two merge into a quad, with them they stay triangles.
    let s = PolygonSoup {
        faces: vec![s.faces[0].to_vec(), vec![1, 2, 5], vec![1, 5, 4]].into(),
        ..s
    };
    let mut m = Mesh::from_soup_tagged(&s, &[4, 6, 5]).unwrap();
    let diagonal = m
        .edges()
        .find(|&e| m.is_block_edge(e) && m.edge_faces(e).iter().flatten().all(|&f| m.tag(f) == 4))
        .unwrap();
    let policy = subgram::mesh::Split {
        blocks: subgram::mesh::BlockSplit::Bisection,
        ..Default::default()
    };
    m.edge_split_with(diagonal, DVec3::new(0.25, 0.5, 0.0), &policy)
        .unwrap();
    let shared = edge_between(&m, 1, 4);
    assert!(m.is_block_edge(shared));
    let (q, t) = m.to_quad_soup_tagged();
    let untagged = m.to_quad_soup();
    let shared_faces = |faces: &subgram::mesh::Faces| {
        faces
            .iter()
            .filter(|f| f.contains(&1) && f.contains(&4))
            .count()
    };
    assert_eq!(shared_faces(&untagged.faces), 1, "merged into one quad");
    assert_eq!(shared_faces(&q.faces), 2, "kept as two triangles");
    for (f, tag) in q.faces.iter().zip(&t) {
        if f.contains(&1) && f.contains(&4) {
            assert_eq!(f.len(), 3);
            assert!(*tag == 4 || *tag == 5);
        }
    }
}

/// The README's storage figure for the half-edge mesh is what the arrays
/// hold: `Mesh::bytes_per_face` on a large closed triangle mesh (an
/// icosphere of 81,920 faces, where V/F is within 0.01% of its limit
/// 1/2), to a tenth of a byte.
#[test]
fn the_readme_states_the_mesh_storage_per_face_that_the_arrays_take() {
    let m = Mesh::from_soup(&shapes::icosphere(6)).unwrap();
    assert_eq!(m.face_count(), 81_920);
    let readme = std::fs::read_to_string(crate::support::root().join("README.md")).unwrap();
    let at = readme
        .find(" bytes a face, positions double-buffered")
        .expect("the README states the storage per face");
    let stated: f64 = readme[..at]
        .rsplit('(')
        .next()
        .unwrap()
        .trim()
        .parse()
        .unwrap();
    let actual = m.bytes_per_face();
    assert!(
        (stated - actual).abs() < 0.1,
        "README says {stated} bytes a face, the arrays take {actual:.2}"
    );
}
