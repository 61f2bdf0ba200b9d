//! Vertex-vertex programs (paper 001): the paper's schemes against the
//! stellar grammars that implement the same schemes, the butterfly against
//! its mask built here, `synchronize` against the order of iteration, and
//! the error cases of Table 2.

use std::path::{Path, PathBuf};

use glam::DVec3;
use subgram::mesh::{io, shapes, PolygonSoup};
use subgram::{LoadOptions, Run, RunOptions, System};

use crate::support::scratch;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Runs `file` (a vv program or a surface grammar) `steps` steps on `mesh`
/// and gives its polygons.
fn run(file: &Path, mesh: &Path, steps: u64, defines: &[&str]) -> PolygonSoup {
    let opts = LoadOptions {
        defines: defines.iter().map(|d| d.to_string()).collect(),
        ..LoadOptions::default()
    };
    let system = subgram::load(file, &opts).unwrap_or_else(|e| panic!("{e}"));
    let ro = RunOptions {
        steps: Some(steps),
        base_mesh: Some(mesh.to_path_buf()),
        ..RunOptions::default()
    };
    match system.run(&ro).unwrap_or_else(|e| panic!("{e}")) {
        Run::Vv(v) => v.soup,
        Run::Surface(s) => s.mesh.to_quad_soup(),
        Run::Curve(_) | Run::Shapes(_) => panic!("{} is not a mesh program", file.display()),
    }
}

/// The same mesh up to the numbering of vertices and the first vertex of
/// each face: every vertex of `a` has one of `b` within `tol`, and the
/// faces map onto each other.
fn assert_same_mesh(a: &PolygonSoup, b: &PolygonSoup, tol: f64, what: &str) {
    assert_eq!(
        a.positions.len(),
        b.positions.len(),
        "{what}: vertex counts"
    );
    assert_eq!(a.faces.len(), b.faces.len(), "{what}: face counts");
    // Sort b's vertices by x so that each search looks at a window.
    let mut order: Vec<usize> = (0..b.positions.len()).collect();
    order.sort_by(|&i, &j| b.positions[i].x.total_cmp(&b.positions[j].x));
    let xs: Vec<f64> = order.iter().map(|&i| b.positions[i].x).collect();
    let mut map = vec![usize::MAX; a.positions.len()];
    let mut taken = vec![false; b.positions.len()];
    for (i, p) in a.positions.iter().enumerate() {
        let lo = xs.partition_point(|&x| x < p.x - tol);
        let hits: Vec<usize> = order[lo..]
            .iter()
            .take_while(|&&j| b.positions[j].x <= p.x + tol)
            .copied()
            .filter(|&j| (b.positions[j] - *p).abs().max_element() <= tol)
            .collect();
        assert_eq!(
            hits.len(),
            1,
            "{what}: vertex {i} at {p} has {} matches",
            hits.len()
        );
        assert!(!taken[hits[0]], "{what}: two vertices at {p}");
        taken[hits[0]] = true;
        map[i] = hits[0];
    }
    let canon = |f: &[u32]| {
        let k = (0..f.len()).min_by_key(|&k| f[k]).unwrap();
        let mut c: Vec<u32> = f[k..].to_vec();
        c.extend_from_slice(&f[..k]);
        c
    };
    let mut fa: Vec<Vec<u32>> = a
        .faces
        .iter()
        .map(|f| {
            canon(
                &f.iter()
                    .map(|&v| map[v as usize] as u32)
                    .collect::<Vec<_>>(),
            )
        })
        .collect();
    let mut fb: Vec<Vec<u32>> = b.faces.iter().map(canon).collect();
    fa.sort();
    fb.sort();
    assert_eq!(fa, fb, "{what}: faces");
}

fn vv(name: &str) -> PathBuf {
    root().join("lsystems/vv").join(name)
}

fn grammar(name: &str) -> PathBuf {
    root().join("lsystems/surfaces").join(name)
}

fn mesh(name: &str) -> PathBuf {
    root().join("lsystems/meshes").join(name)
}

#[test]
fn vv_loop_is_the_grammar_loop_closed_and_open() {
    for (m, steps) in [
        ("octahedron.obj", 3),
        ("tetrahedron.obj", 3),
        ("pentagon-patch.obj", 3),
    ] {
        let a = run(&vv("loop.lsys"), &mesh(m), steps, &[]);
        let b = run(&grammar("loop.lsys"), &mesh(m), steps, &[]);
        assert_same_mesh(&a, &b, 1e-12, &format!("Loop on {m}"));
    }
}

#[test]
fn vv_sqrt3_is_the_grammar_sqrt3_closed_and_open() {
    // Four steps on the open patch: two of each kind of boundary step.
    for (m, steps) in [("octahedron.obj", 3), ("pentagon-patch.obj", 4)] {
        let a = run(&vv("sqrt3.lsys"), &mesh(m), steps, &[]);
        let b = run(&grammar("sqrt3.lsys"), &mesh(m), steps, &[]);
        assert_same_mesh(&a, &b, 1e-12, &format!("sqrt3 on {m}"));
    }
}

/// A triangle grid with bumps: valence 6 inside, not planar.
fn bumpy_grid(dir: &Path) -> (PathBuf, PolygonSoup) {
    let mut soup = shapes::triangle_grid(8, 8);
    for (i, p) in soup.positions.iter_mut().enumerate() {
        p.z = ((i * 7919) % 13) as f64 / 13.0 - 0.5;
    }
    let path = dir.join("grid.obj");
    io::write(&path, &soup).unwrap();
    (path, soup)
}

#[test]
fn vv_butterfly_is_the_eight_point_mask_on_a_regular_region() {
    let dir = scratch("vv");
    let (path, base) = bumpy_grid(dir.path());
    let out = run(&vv("butterfly.lsys"), &path, 1, &[]);
    // The scheme interpolates: the old vertices come first, unmoved.
    assert_eq!(&out.positions[..base.positions.len()], &base.positions[..]);
    // Neighbours, counter-clockwise, from the base triangles.
    let n = base.positions.len();
    let mut next: Vec<Vec<(u32, u32)>> = vec![Vec::new(); n];
    for f in &base.faces {
        for k in 0..3 {
            // In triangle (a, b, c), c follows b around a.
            next[f[k] as usize].push((f[(k + 1) % 3], f[(k + 2) % 3]));
        }
    }
    let after = |a: u32, b: u32| {
        next[a as usize]
            .iter()
            .find(|(x, _)| *x == b)
            .map(|(_, c)| *c)
    };
    let before = |a: u32, b: u32| {
        next[a as usize]
            .iter()
            .find(|(_, c)| *c == b)
            .map(|(x, _)| *x)
    };
    let interior = |v: u32| {
        next[v as usize].len() == 6 && {
            let first = next[v as usize][0].0;
            let mut x = first;
            let mut k = 0;
            while let Some(y) = after(v, x) {
                x = y;
                k += 1;
                if x == first || k > 6 {
                    break;
                }
            }
            x == first && k == 6
        }
    };
    let w = 1.0 / 16.0;
    let pos = |v: u32| base.positions[v as usize];
    let mut checked = 0;
    for p in 0..n as u32 {
        for &(q, r) in &next[p as usize] {
            if p > q || !interior(p) || !interior(q) {
                continue;
            }
            let s = before(p, q).unwrap();
            let wings = [after(p, r), before(q, r), before(p, s), after(q, s)];
            let Some(t) = wings.iter().copied().collect::<Option<Vec<u32>>>() else {
                continue;
            };
            if ![r, s].iter().chain(&t).all(|&v| interior(v)) {
                continue;
            }
            let expected: DVec3 = 0.5 * (pos(p) + pos(q)) + 2.0 * w * (pos(r) + pos(s))
                - w * (pos(t[0]) + pos(t[1]) + pos(t[2]) + pos(t[3]));
            let hit = out.positions[n..]
                .iter()
                .any(|x| (*x - expected).abs().max_element() < 1e-12);
            assert!(
                hit,
                "no new vertex at the mask's point {expected} for edge ({p}, {q})"
            );
            checked += 1;
        }
    }
    // An 8 x 8 grid has 7 x 7 interior vertices; the edges whose whole
    // stencil is interior number in the dozens.
    assert!(checked > 40, "only {checked} edges checked");
}

/// Loop's step over the structure in its order, or (with `-D REVERSED`)
/// over the same vertices in the opposite order.
const LOOP_IN_ANY_ORDER: &str = r#"
mesh S;
double beta(int n) { return (5.0/8 - pow(3.0/8 + 0.25*cos(2*PI/n), 2)) / n; }
void insert(vertex p, vertex q, vertex x) {
  replace q with x in p;
  replace p with x in q;
  make {p, q} nb_of x;
}
Step: {
  mesh R;
#ifdef REVERSED
  vertex all[1000];
  int n = 0;
  forall p in S { all[n] = p; n++; }
  for (int i = n - 1; i >= 0; i--) add all[i] to R;
#else
  R = S;
#endif
  mesh NV;
  synchronize S;
  forall p in R
    forall q in 'p
      if (p < q) {
        vertex x;
        vertex r = nextto q in 'p;
        vertex s = prevto q in 'p;
        if (r == null || s == null) x$pos = 0.5 * ('p$pos + 'q$pos);
        else x$pos = 3.0/8 * ('p$pos + 'q$pos) + 1.0/8 * ('r$pos + 's$pos);
        insert(p, q, x);
        add x to NV;
      }
  forall p in R {
    int n = valence 'p;
    V3d sum = V3d(0, 0, 0);
    forall q in 'p sum += 'q$pos;
    if (!boundary('p)) p$pos = (1 - n * beta(n)) * 'p$pos + beta(n) * sum;
  }
  forall x in NV {
    vertex p = any in x;
    vertex q = nextto p in x;
    make {p, prevto x in p, nextto x in q, q, prevto x in q, nextto x in p} nb_of x;
  }
  merge S with NV;
}
"#;

#[test]
fn synchronize_makes_the_order_of_iteration_irrelevant_to_the_bit() {
    let dir = scratch("vv");
    let file = dir.path().join("order.lsys");
    std::fs::write(&file, LOOP_IN_ANY_ORDER).unwrap();
    for m in ["octahedron.obj", "pentagon-patch.obj", "torus.obj"] {
        let m = mesh(m);
        let forward = run(&file, &m, 1, &[]);
        let reversed = run(&file, &m, 1, &["REVERSED=1"]);
        // Different orders make the new vertices in different orders...
        assert_ne!(forward.positions, reversed.positions);
        // ...but the same mesh, to the last bit.
        assert_same_mesh(&forward, &reversed, 0.0, "the two orders");
    }
}

/// Runs a vv program from text; the first error, as the binary shows it.
fn error_of(text: &str) -> String {
    let dir = scratch("vv");
    let file = dir.path().join("t.lsys");
    std::fs::write(&file, text).unwrap();
    let system = subgram::load(&file, &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    assert!(matches!(system, System::Vv(_)));
    match system.run(&RunOptions::default()) {
        Ok(_) => panic!("no error from:\n{text}"),
        Err(e) => e.to_string(),
    }
}

/// A program on the tetrahedron whose `Step` is `body`.
fn program(body: &str) -> String {
    let tet = mesh("tetrahedron.obj");
    format!(
        "mesh S = \"{}\";\nStep: {{\n  vertex v = any in S_first();\n{body}\n}}\nvertex S_first() {{ forall v in S return v; return null; }}\n",
        tet.display()
    )
}

#[test]
fn table_2_error_cases_are_located_errors() {
    let cases: &[(&str, &str, &str)] = &[
        // Note 3: v in its own list, a vertex listed twice.
        (
            "  vertex a = any in v;\n  make {a, v} nb_of v;",
            "2:",
            "its own neighbourhood",
        ),
        (
            "  vertex a = any in v;\n  make {a, a} nb_of v;",
            "2:",
            "listed twice",
        ),
        // Note 5: x = v, or x already a neighbour.
        (
            "  vertex a = any in v;\n  replace a with v in v;",
            "2:",
            "x is v itself",
        ),
        (
            "  vertex a = any in v;\n  vertex b = nextto a in v;\n  replace a with b in v;",
            "3:",
            "is already a neighbour of",
        ),
        (
            "  vertex a = any in v;\n  splice v after a in v;",
            "2:",
            "x is v itself",
        ),
        (
            "  vertex a = any in v;\n  splice a before a in v;",
            "2:",
            "is already a neighbour of",
        ),
        (
            "  vertex a = any in v;\n  vertex b = nextto a in v;\n  splice b before a in v;",
            "3:",
            "is already a neighbour of",
        ),
        // The null vertex has no neighbourhood.
        ("  vertex a = any in null;", "1:", "null"),
        // 'v is for reading.
        (
            "  vertex a = any in v;\n  synchronize S;\n  erase a from 'v;",
            "3:",
            "synchronize",
        ),
        // A vertex made after the last synchronize has no old state.
        (
            "  synchronize S;\n  vertex x;\n  int n = valence 'x;",
            "3:",
            "synchroniz",
        ),
    ];
    for (body, line, needle) in cases {
        // The body starts on the program's line 4.
        let k: usize = line.trim_end_matches(':').parse().unwrap();
        let e = error_of(&program(body));
        assert!(e.contains(&format!("t.lsys:{}:", k + 3)), "{body}\n-> {e}");
        assert!(e.contains(needle), "{body}\n-> {e}");
        assert!(e.contains('^'), "{body}\n-> {e}");
    }
}

#[test]
fn table_2_null_and_no_effect_cases() {
    let dir = scratch("vv");
    // Notes 1, 2 and 4, and 5's "no effect": printed by the program.
    let body = r#"
  vertex a = any in v;
  vertex b = nextto a in v;
  vertex x;
  printf("%d ", any in x == null);              // note 1
  printf("%d ", nextto x in v == null);         // note 2
  printf("%d ", prevto x in v == null);         // note 2
  int n = valence v;
  erase x from v;                               // note 4
  printf("%d ", valence v == n);
  replace x with b in v;                        // note 5: x not in v*
  splice x after x in v;
  printf("%d ", valence v == n && is a in v && !(is x in v));
  printf("%d\n", valence x);
"#;
    let file = dir.path().join("t.lsys");
    std::fs::write(&file, program(body)).unwrap();
    let output = subgram::ProgramOutput::new();
    let system = subgram::load(&file, &LoadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
    let ro = RunOptions {
        output: output.clone(),
        ..RunOptions::default()
    };
    system.run(&ro).unwrap_or_else(|e| panic!("{e}"));
    let printed: String = output.take_text().into_iter().map(|(_, t)| t).collect();
    assert_eq!(printed.trim(), "1 1 1 1 1 0");
}

/// The program the README shows is the polyhedral subdivision of
/// `lsystems/vv/polyhedral.lsys`, and runs as printed.
#[test]
fn the_readme_program_runs_as_printed() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let section = &readme[readme.find("## Vertex-vertex programs").unwrap()..];
    let start = section.find("```c\n").unwrap() + 5;
    let text = &section[start..start + section[start..].find("```").unwrap()];
    let dir = scratch("vv");
    let file = dir.path().join("readme.lsys");
    std::fs::write(&file, text).unwrap();
    let a = run(&file, &mesh("octahedron.obj"), 2, &[]);
    let b = run(&vv("polyhedral.lsys"), &mesh("octahedron.obj"), 2, &[]);
    assert_same_mesh(&a, &b, 0.0, "the README's program");
    assert_eq!(a.faces.len(), 8 * 16);
}

/// The tissue example stays a sheet of cells: a disk (V - E + F = 1, one
/// boundary loop) whose cells keep a positive area in the plane, never
/// fewer from one step to the next, and none more than twice the area at
/// which a cell divides (0.1 in the file).
#[test]
fn the_tissue_grows_and_divides_into_proper_cells() {
    let file = vv("tissue.lsys");
    let system = subgram::load(&file, &LoadOptions::default()).unwrap();
    let mut cells = 0;
    for steps in 0..=10 {
        let Run::Vv(r) = system
            .run(&RunOptions::default().with_steps(steps))
            .unwrap()
        else {
            panic!("a vv program")
        };
        let info = &r.info;
        assert_eq!(info.euler_characteristic, 1, "step {steps}");
        assert_eq!(info.boundary_loops, 1, "step {steps}");
        assert!(info.faces >= cells, "step {steps}: fewer cells");
        cells = info.faces;
        for f in &r.soup.faces {
            let p = |i: usize| r.soup.positions[f[i % f.len()] as usize];
            let area: f64 = (0..f.len())
                .map(|i| p(i).x * p(i + 1).y - p(i + 1).x * p(i).y)
                .sum::<f64>()
                / 2.0;
            assert!(
                area > 0.0 && area <= 0.2,
                "step {steps}: a cell of area {area}"
            );
        }
    }
    assert!(cells > 16 * 4, "only {cells} cells after 10 steps");
}

/// A half-edge mesh becomes a rotation system and back, unchanged: closed
/// and open, triangles and quads.
#[test]
fn the_rotation_system_converts_to_and_from_the_half_edge_mesh() {
    use subgram::vv::Rotation;
    for m in [
        "cube.obj",
        "octahedron.obj",
        "torus.obj",
        "grid.obj",
        "pentagon-patch.obj",
    ] {
        let mesh = subgram::load_mesh(&self::mesh(m)).unwrap();
        let (rot, members) = Rotation::from_halfedge(&mesh).unwrap();
        assert_eq!(members.len(), mesh.vertex_count(), "{m}");
        rot.check(&members).unwrap_or_else(|e| panic!("{m}: {e}"));
        let back = rot.to_halfedge(&members).unwrap();
        // The same polygons on the same vertices (a quad's diagonal inside
        // the half-edge mesh is its own business).
        let (a, b) = (mesh.to_quad_soup(), back.to_quad_soup());
        assert_eq!(a.positions, b.positions, "{m}");
        assert_same_mesh(&a, &b, 0.0, m);
        assert_eq!(back.info().faces, mesh.info().faces, "{m}");
    }
}

/// A tetrahedron written as neighbour lists, divided k times: 4 * 4^k
/// triangles, 2 + 2 * 4^k vertices (Euler: V - E + F = 2 with E = 3F/2),
/// every vertex on the unit sphere.
#[test]
fn a_base_mesh_written_as_neighbour_lists() {
    let system = subgram::load(vv("geodesic.lsys"), &LoadOptions::default()).unwrap();
    for k in 0..=3u32 {
        let Run::Vv(r) = system
            .run(&RunOptions::default().with_steps(k as u64))
            .unwrap()
        else {
            panic!("a vv program")
        };
        let f = 4 * 4usize.pow(k);
        assert_eq!((r.info.faces, r.info.vertices), (f, 2 + f / 2), "k = {k}");
        for p in &r.soup.positions {
            assert!((p.length() - 1.0).abs() < 1e-12 || k == 0, "{p}");
        }
    }
}

/// `subdivide` prints what a vv program prints, as `derive` and `render` do.
#[test]
fn subdivide_prints_what_a_vv_program_prints() {
    let dir = scratch("vv");
    let file = dir.path().join("p.lsys");
    std::fs::write(
        &file,
        "mesh S;\nStart: { printf(\"hello\\n\"); }\nStep: { printf(\"step %d\\n\", StepNo()); }\n",
    )
    .unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_subgram"))
        .arg("subdivide")
        .arg(mesh("cube.obj"))
        .arg("--grammar")
        .arg(&file)
        .args(["-n", "2", "-o"])
        .arg(dir.path().join("out.obj"))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(
        String::from_utf8_lossy(&out.stdout),
        "hello\nstep 0\nstep 1\n"
    );
}

/// The butterfly program's boundary rules, checked by what they must
/// reproduce: on an open grid lifted onto a plane every new vertex lies on
/// the plane (the interior mask, the reflected wings and the four-point
/// rule all keep affine functions); along a straight boundary the
/// four-point rule reproduces a cubic at the midpoints whose stencil lies
/// on that side.
#[test]
fn vv_butterfly_boundary_rules_keep_planes_and_boundary_cubics() {
    let dir = scratch("vv");
    let plane = |p: DVec3| 0.2 * p.x + 0.3 * p.y + 0.1;
    let mut soup = shapes::triangle_grid(8, 4);
    for p in &mut soup.positions {
        p.z = plane(*p);
    }
    let path = dir.path().join("plane.obj");
    io::write(&path, &soup).unwrap();
    let out = run(&vv("butterfly.lsys"), &path, 2, &[]);
    assert!(out.positions.len() > soup.positions.len() * 4);
    for p in &out.positions {
        assert!((p.z - plane(*p)).abs() < 1e-12, "{p} is off the plane");
    }
    // One step: the lattice is reproduced too. Every new vertex off the
    // grid's sides sits at the midpoint of its edge (x a multiple of 1/16,
    // y of 1/8), which the interior mask keeps and a wrong ghost for a
    // missing wing (near the sides) would not.
    let out = run(&vv("butterfly.lsys"), &path, 1, &[]);
    let mut inner = 0;
    for p in &out.positions[soup.positions.len()..] {
        if p.x > 0.0 && p.x < 1.0 && p.y > 0.0 && p.y < 1.0 {
            let on = |t: f64| (t - t.round()).abs() < 1e-12;
            assert!(
                on(p.x * 16.0) && on(p.y * 8.0),
                "{p}: not an edge's midpoint"
            );
            inner += 1;
        }
    }
    assert!(inner > 60, "{inner}");

    let mut soup = shapes::triangle_grid(8, 4);
    for p in &mut soup.positions {
        p.z = p.x.powi(3);
    }
    let path = dir.path().join("cubic.obj");
    io::write(&path, &soup).unwrap();
    let out = run(&vv("butterfly.lsys"), &path, 1, &[]);
    let h = 1.0 / 8.0;
    let mut checked = 0;
    for p in &out.positions[soup.positions.len()..] {
        // A new vertex on the side y = 0 whose four-point stencil stays on
        // that side: the midpoints of the edges from x = h to x = 7h.
        if p.y == 0.0 && p.x > h && p.x < 1.0 - h {
            assert!((p.z - p.x.powi(3)).abs() < 1e-12, "{p}: not on the cubic");
            checked += 1;
        }
    }
    assert_eq!(checked, 6);
}

/// The triangle schemes refuse a mesh with larger faces at their check in
/// `Start`, instead of applying their masks to it.
#[test]
fn triangle_schemes_refuse_quads() {
    for f in [
        "loop.lsys",
        "butterfly.lsys",
        "modified-butterfly.lsys",
        "sqrt3.lsys",
        "polyhedral.lsys",
    ] {
        let system = subgram::load(vv(f), &LoadOptions::default()).unwrap();
        let ro = RunOptions {
            base_mesh: Some(mesh("cube.obj")),
            ..RunOptions::default()
        };
        let e = system
            .run(&ro)
            .err()
            .unwrap_or_else(|| panic!("{f} ran on quads"));
        assert!(e.to_string().contains("takes a triangle mesh"), "{f}: {e}");
    }
}

/// A step that leaves a vertex of the mesh without neighbours fails the
/// check after the step: a mesh's vertices lie on faces.
#[test]
fn a_vertex_without_neighbours_fails_the_check_after_a_step() {
    let text = format!(
        "mesh S = \"{}\";\nStep: {{ forall p in S forall q in p erase q from p; }}\n",
        mesh("tetrahedron.obj").display()
    );
    let e = error_of(&text);
    assert!(
        e.contains("after step 1") && e.contains("has no neighbours"),
        "{e}"
    );
}

/// The modified butterfly's new vertex of every edge, from the rules as
/// `lsystems/vv/modified-butterfly.lsys` states them (Zorin, Schröder and
/// Sweldens 1996 inside, VTK's choices at the boundary), computed here from
/// the base mesh's triangles: Zorin's s_j from the formula, the 8-point
/// mask, the four-point rule.
fn modified_butterfly_masks(base: &PolygonSoup) -> Vec<((u32, u32), DVec3)> {
    let n = base.positions.len();
    // In triangle (a, b, c), c follows b around a.
    let mut next: Vec<Vec<(u32, u32)>> = vec![Vec::new(); n];
    for f in &base.faces {
        assert_eq!(f.len(), 3);
        for k in 0..3 {
            next[f[k] as usize].push((f[(k + 1) % 3], f[(k + 2) % 3]));
        }
    }
    let after = |a: u32, b: u32| {
        next[a as usize]
            .iter()
            .find(|(x, _)| *x == b)
            .map(|(_, c)| *c)
    };
    let before = |a: u32, b: u32| {
        next[a as usize]
            .iter()
            .find(|(_, c)| *c == b)
            .map(|(x, _)| *x)
    };
    let triangles = |v: u32| next[v as usize].len();
    // On the boundary when some neighbour has no triangle on one side.
    let on_boundary = |v: u32| {
        next[v as usize]
            .iter()
            .any(|&(b, c)| before(v, b).is_none() || after(v, c).is_none())
    };
    let pos = |v: u32| base.positions[v as usize];
    let other_boundary_end = |p: u32, q: u32| -> u32 {
        // The boundary neighbour of p that is not q.
        next[p as usize]
            .iter()
            .flat_map(|&(b, c)| [b, c])
            .find(|&y| y != q && (after(p, y).is_none() || before(p, y).is_none()))
            .unwrap()
    };
    let eight_point = |p: u32, q: u32| {
        let r = after(p, q).unwrap();
        let s = before(p, q).unwrap();
        let t = [
            after(p, r).unwrap_or(s),
            before(q, r).unwrap_or(s),
            before(p, s).unwrap_or(r),
            after(q, s).unwrap_or(r),
        ];
        0.5 * (pos(p) + pos(q)) + 0.125 * (pos(r) + pos(s))
            - 0.0625 * t.iter().map(|&x| pos(x)).sum::<DVec3>()
    };
    let zorin = |j: usize, k: usize| -> f64 {
        let (j, k) = (j as f64, k as f64);
        match k as usize {
            3 => [5.0 / 12.0, -1.0 / 12.0, -1.0 / 12.0][j as usize],
            4 => [3.0 / 8.0, 0.0, -1.0 / 8.0, 0.0][j as usize],
            _ => {
                let a = std::f64::consts::TAU * j / k;
                (0.25 + a.cos() + 0.5 * (2.0 * a).cos()) / k
            }
        }
    };
    let end = |p: u32, q: u32| {
        if on_boundary(p) {
            return eight_point(p, q);
        }
        let k = triangles(p);
        let mut sum = 0.75 * pos(p);
        let mut x = q;
        for j in 0..k {
            sum += zorin(j, k) * pos(x);
            x = after(p, x).unwrap();
        }
        assert_eq!(x, q, "the ring around {p} closes");
        sum
    };
    let mut out = Vec::new();
    for p in 0..n as u32 {
        let mut nbrs: Vec<u32> = next[p as usize].iter().flat_map(|&(b, c)| [b, c]).collect();
        nbrs.sort();
        nbrs.dedup();
        for q in nbrs.into_iter().filter(|&q| q > p) {
            let x = if after(p, q).is_none() || before(p, q).is_none() {
                9.0 / 16.0 * (pos(p) + pos(q))
                    - 1.0 / 16.0 * (pos(other_boundary_end(p, q)) + pos(other_boundary_end(q, p)))
            } else {
                match (triangles(p) == 6, triangles(q) == 6) {
                    (true, true) => eight_point(p, q),
                    (false, true) => end(p, q),
                    (true, false) => end(q, p),
                    (false, false) => 0.5 * (end(p, q) + end(q, p)),
                }
            };
            out.push(((p, q), x));
        }
    }
    out
}

/// Modified butterfly (Zorin, Schröder and Sweldens 1996) as a vv program:
/// one step on meshes with valences 3, 4, 5, 6 and more, closed and open,
/// every new vertex against the mask built here from the stated rules, to
/// 1e-12, on positions moved at random so that no weight is hidden by
/// symmetry. VTK's filter is the peer of `benches/butterfly_xcheck.py`.
#[test]
fn vv_modified_butterfly_is_zorins_masks_with_vtks_boundary() {
    let dir = scratch("vv");
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut jiggle = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let mut grid = shapes::triangle_grid(5, 4);
    for p in &mut grid.positions {
        p.z = p.x * p.y;
    }
    let cases = [
        ("tetrahedron", io::read(&mesh("tetrahedron.obj")).unwrap()),
        ("octahedron", io::read(&mesh("octahedron.obj")).unwrap()),
        (
            "pentagon patch",
            io::read(&mesh("pentagon-patch.obj")).unwrap(),
        ),
        ("triangle grid", grid),
        ("bunny", io::read(&mesh("bunny.obj")).unwrap()),
    ];
    for (name, mut base) in cases {
        for p in &mut base.positions {
            *p += 0.1 * DVec3::new(jiggle(), jiggle(), jiggle());
        }
        let path = dir.path().join(format!("{}.obj", name.replace(' ', "-")));
        io::write(&path, &base).unwrap();
        let base = io::read(&path).unwrap(); // what the program reads
        let out = run(&vv("modified-butterfly.lsys"), &path, 1, &[]);
        let n = base.positions.len();
        assert_eq!(
            &out.positions[..n],
            &base.positions[..],
            "{name}: interpolates"
        );
        // Each new vertex's parent edge: its two old neighbours.
        let mut old_nbrs: Vec<Vec<u32>> = vec![Vec::new(); out.positions.len()];
        for f in &out.faces {
            for k in 0..f.len() {
                let (a, b) = (f[k], f[(k + 1) % f.len()]);
                if (a as usize) >= n && (b as usize) < n && !old_nbrs[a as usize].contains(&b) {
                    old_nbrs[a as usize].push(b);
                }
                if (b as usize) >= n && (a as usize) < n && !old_nbrs[b as usize].contains(&a) {
                    old_nbrs[b as usize].push(a);
                }
            }
        }
        let mut made = std::collections::HashMap::new();
        for (x, nb) in old_nbrs.iter().enumerate().skip(n) {
            assert_eq!(
                nb.len(),
                2,
                "{name}: new vertex {x}'s old neighbours {nb:?}"
            );
            made.insert((nb[0].min(nb[1]), nb[0].max(nb[1])), out.positions[x]);
        }
        let masks = modified_butterfly_masks(&base);
        assert_eq!(made.len(), masks.len(), "{name}: one new vertex an edge");
        for (edge, expected) in masks {
            let got = made[&edge];
            assert!(
                (got - expected).abs().max_element() < 1e-12,
                "{name}: edge {edge:?}: {got} against the mask's {expected}"
            );
        }
    }
}

/// `soup` with every vertex moved a little (a fixed sequence), written to
/// `dir/name.obj` and read back as the programs read it.
fn jiggled(dir: &Path, name: &str, mut soup: PolygonSoup, mut seed: u64) -> (PathBuf, PolygonSoup) {
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    for p in &mut soup.positions {
        *p += 0.1 * DVec3::new(next(), next(), next());
    }
    let path = dir.join(format!("{name}.obj"));
    io::write(&path, &soup).unwrap();
    let soup = io::read(&path).unwrap();
    (path, soup)
}

/// The dual vv programs (Doo-Sabin, Peters-Reif) are the stellar grammars
/// on closed meshes: quads, triangles, a torus, two steps, 1e-12, the
/// same faces.
#[test]
fn vv_doo_sabin_and_peters_reif_are_the_grammars_on_closed_meshes() {
    let dir = scratch("vv");
    for m in ["cube.obj", "octahedron.obj", "torus.obj"] {
        let (path, _) = jiggled(
            dir.path(),
            m.trim_end_matches(".obj"),
            io::read(&mesh(m)).unwrap(),
            7,
        );
        for (program, g) in [
            ("doo-sabin.lsys", "doo-sabin.lsys"),
            ("peters-reif.lsys", "peters.lsys"),
        ] {
            let a = run(&vv(program), &path, 2, &[]);
            let b = run(&grammar(g), &path, 2, &[]);
            assert_same_mesh(&a, &b, 1e-12, &format!("{program} on {m}"));
        }
    }
}

/// The points a dual program makes from `s`, one per face corner, by the
/// rules its comment states: `interior(face positions, k)` at a corner
/// with no boundary edge; at a corner p whose face has the boundary edge
/// p-q, 3/4 p + 1/4 q; with both its edges on the boundary,
/// 3/4 p + 1/8 (q + r).
fn dual_points(s: &PolygonSoup, interior: impl Fn(&[DVec3], usize) -> DVec3) -> Vec<DVec3> {
    let mut uses = std::collections::HashMap::new();
    for f in &s.faces {
        for k in 0..f.len() {
            let (a, b) = (f[k], f[(k + 1) % f.len()]);
            *uses.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    let on_boundary = |a: u32, b: u32| uses[&(a.min(b), a.max(b))] == 1;
    let mut out = Vec::new();
    for f in &s.faces {
        let n = f.len();
        let ps: Vec<DVec3> = f.iter().map(|&i| s.positions[i as usize]).collect();
        for k in 0..n {
            let (p, q, r) = (f[k], f[(k + 1) % n], f[(k + n - 1) % n]);
            let (pq, rp) = (on_boundary(p, q), on_boundary(r, p));
            let (pp, qq, rr) = (ps[k], ps[(k + 1) % n], ps[(k + n - 1) % n]);
            out.push(match (pq, rp) {
                (true, true) => 0.75 * pp + 0.125 * (qq + rr),
                (true, false) => 0.75 * pp + 0.25 * qq,
                (false, true) => 0.75 * pp + 0.25 * rr,
                (false, false) => interior(&ps, k),
            });
        }
    }
    out
}

/// One to one by position: every point of `want` has its own point of
/// `got`; the largest distance.
fn match_points(got: &[DVec3], want: &[DVec3]) -> f64 {
    assert_eq!(got.len(), want.len(), "point counts");
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

/// Faces a dual step makes from `s`: one per face, interior edge and
/// interior vertex, and one per boundary vertex on three faces or more;
/// and the boundary edges it has: Chaikin's polygon, two per boundary
/// edge, less one per boundary vertex on a single face.
fn dual_counts(s: &PolygonSoup) -> (usize, usize) {
    let mut uses = std::collections::HashMap::new();
    let mut faces_at = vec![0usize; s.positions.len()];
    for f in &s.faces {
        for k in 0..f.len() {
            let (a, b) = (f[k], f[(k + 1) % f.len()]);
            *uses.entry((a.min(b), a.max(b))).or_insert(0) += 1;
            faces_at[f[k] as usize] += 1;
        }
    }
    let mut boundary_v = vec![false; s.positions.len()];
    for (&(a, b), &n) in &uses {
        if n == 1 {
            boundary_v[a as usize] = true;
            boundary_v[b as usize] = true;
        }
    }
    let interior_e = uses.values().filter(|&&n| n == 2).count();
    let boundary_e = uses.len() - interior_e;
    let interior_v = boundary_v.iter().filter(|b| !**b).count();
    let wide = (0..s.positions.len())
        .filter(|&v| boundary_v[v] && faces_at[v] >= 3)
        .count();
    let single = (0..s.positions.len())
        .filter(|&v| boundary_v[v] && faces_at[v] == 1)
        .count();
    (
        s.faces.len() + interior_e + interior_v + wide,
        2 * boundary_e - single,
    )
}

fn boundary_edges(s: &PolygonSoup) -> usize {
    let mut uses = std::collections::HashMap::new();
    for f in &s.faces {
        for k in 0..f.len() {
            let (a, b) = (f[k], f[(k + 1) % f.len()]);
            *uses.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    uses.values().filter(|&&n| n == 1).count()
}

/// A dual scheme's point of corner `k` of a face (its corners' positions).
type CornerRule = dyn Fn(&[DVec3], usize) -> DVec3;

/// Doo-Sabin and Peters-Reif on open meshes: two steps on a quad grid
/// (whose corners lie on one face), the triangle patch (boundary vertices
/// on two to four faces) and a patch of a pentagon, a hexagon, quads and
/// triangles, every point against the rules computed here from the step's
/// input (1e-12), the faces counted, and the new boundary Chaikin's
/// polygon of the old (its edges counted; its points are among those
/// checked).
#[test]
fn vv_doo_sabin_and_peters_reif_on_open_meshes() {
    let dir = scratch("vv");
    let mixed = PolygonSoup {
        positions: [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.1],
            [2.0, 0.0, 0.0],
            [3.0, 0.0, 0.2],
            [0.0, 1.0, 0.1],
            [1.0, 1.0, 0.3],
            [2.0, 1.0, 0.2],
            [3.0, 1.0, 0.0],
            [0.5, 1.8, 0.0],
            [1.5, 2.1, 0.2],
            [2.5, 1.8, 0.1],
            [3.6, 0.5, 0.1],
            [1.5, 2.9, 0.0],
            [0.3, 2.6, 0.1],
            [-0.6, 0.5, 0.0],
            [2.6, 2.7, 0.2],
        ]
        .iter()
        .map(|&[x, y, z]| DVec3::new(x, y, z))
        .collect(),
        faces: vec![
            vec![0, 1, 5, 4],
            vec![1, 2, 6, 5],
            vec![2, 3, 11, 7, 6],
            vec![4, 5, 6, 10, 9, 8],
            vec![8, 9, 12, 13],
            vec![0, 4, 14],
            vec![4, 8, 13, 14],
            vec![6, 7, 10],
            vec![9, 10, 15, 12],
        ]
        .into(),
        ..PolygonSoup::default()
    };
    let averaging = |ps: &[DVec3], k: usize| {
        let n = ps.len();
        let (p, q, r) = (ps[k], ps[(k + 1) % n], ps[(k + n - 1) % n]);
        let centroid = ps.iter().sum::<DVec3>() / n as f64;
        0.25 * (p + 0.5 * (p + q) + 0.5 * (p + r) + centroid)
    };
    let mid_mid = |ps: &[DVec3], k: usize| {
        let n = ps.len();
        0.25 * (ps[(k + n - 1) % n] + 2.0 * ps[k] + ps[(k + 1) % n])
    };
    let cases = [
        ("grid", io::read(&mesh("grid.obj")).unwrap()),
        ("patch", io::read(&mesh("pentagon-patch.obj")).unwrap()),
        ("mixed", mixed),
    ];
    for (name, soup) in cases {
        let (path, base) = jiggled(dir.path(), name, soup, 11);
        let rules: [(&str, &CornerRule); 2] = [
            ("doo-sabin.lsys", &averaging),
            ("peters-reif.lsys", &mid_mid),
        ];
        for (program, interior) in rules {
            let what = format!("{program} on {name}");
            let one = run(&vv(program), &path, 1, &[]);
            let two = run(&vv(program), &path, 2, &[]);
            for (input, output, step) in [(&base, &one, 1), (&one, &two, 2)] {
                let d = match_points(&output.positions, &dual_points(input, interior));
                assert!(d < 1e-12, "{what}, step {step}: {d}");
                let (faces, bedges) = dual_counts(input);
                assert_eq!(output.faces.len(), faces, "{what}, step {step}: faces");
                assert_eq!(
                    boundary_edges(output),
                    bedges,
                    "{what}, step {step}: boundary"
                );
            }
        }
    }
}
