//! Texture coordinates through a surface grammar (issue 43, item 1):
//! reading and writing them (OBJ `vt`, PLY `texcoord` and `u v`), and
//! `subdivide --fvar-linear` on Catmull-Clark and Loop. Expected values
//! come from elsewhere than the code under test: the grammar's ordinary
//! run on positions (its rules are affine with weights from the topology
//! alone, so they commute with taking x and y of every point), a run on
//! each side of a seam as a mesh of its own, and linear interpolation
//! written out here. Blender's modifier is compared in
//! benches/uv_xcheck.py.

use std::collections::HashMap;
use std::path::Path;

use glam::{DVec2, DVec3};
use subgram::command::{self, SubdivideArgs};
use subgram::mesh::{io, shapes, FaceUvs, Mesh, PolygonSoup};

use crate::support::*;

/// Writes `soup` with a texture coordinate per corner (`uv(face, corner
/// index in the face, vertex)`) as OBJ, equal (vertex, value) pairs
/// sharing a `vt`.
fn write_obj(path: &Path, soup: &PolygonSoup, uv: impl Fn(usize, usize, u32) -> DVec2) {
    let mut text = String::new();
    for p in &soup.positions {
        text += &format!("v {:?} {:?} {:?}\n", p.x, p.y, p.z);
    }
    let mut index: HashMap<(u32, [u64; 2]), usize> = HashMap::new();
    let mut vts = Vec::new();
    let mut faces = String::new();
    for (k, f) in soup.faces.iter().enumerate() {
        faces += "f";
        for (j, &v) in f.iter().enumerate() {
            let t = uv(k, j, v);
            let n = index.len();
            let i = *index
                .entry((v, [t.x.to_bits(), t.y.to_bits()]))
                .or_insert_with(|| {
                    vts.push(t);
                    n
                });
            faces += &format!(" {}/{}", v + 1, i + 1);
        }
        faces += "\n";
    }
    for t in &vts {
        text += &format!("vt {:?} {:?}\n", t.x, t.y);
    }
    std::fs::write(path, text + &faces).unwrap();
}

fn args(mesh: &Path, grammar: &str, steps: u64, out: &Path, mode: Option<&str>) -> SubdivideArgs {
    SubdivideArgs {
        mesh: Some(mesh.display().to_string()),
        grammar: lsys(grammar).display().to_string(),
        steps: Some(steps),
        output: out.display().to_string(),
        defines: Vec::new(),
        view: None,
        shading: None,
        no_wireframe: false,
        seed: None,
        timeout: None,
        force: false,
        limit: false,
        fvar_linear: mode.map(str::to_string),
        no_uvs: false,
        program_output: subgram::ProgramOutput::new(),
    }
}

/// Runs `subdivide` and reads the output back with its coordinates.
fn subdivide(a: &SubdivideArgs) -> (PolygonSoup, FaceUvs) {
    command::subdivide(a, |_| {}).unwrap_or_else(|e| panic!("{e}"));
    let (_, soup, read) = io::read_with_uvs(Path::new(&a.output)).unwrap();
    (soup, read.uvs.expect("the output has texture coordinates"))
}

/// The mesh `soup` run `steps` steps of a grammar, as the command writes
/// it (positions only).
fn positions_run(grammar: &str, soup: &PolygonSoup, steps: usize) -> PolygonSoup {
    let g = subgram::surface::load_file(&lsys(grammar), &[]).unwrap();
    let mut m = Mesh::from_soup(soup).unwrap();
    g.run(&mut m, steps, |_| {}).unwrap();
    m.to_quad_soup()
}

/// Each face's corner values, starting from its smallest (by bits), so
/// that faces compare whatever corner they start at.
fn cycles(soup: &PolygonSoup, value: impl Fn(usize, usize) -> DVec2) -> Vec<Vec<[i64; 2]>> {
    let q = |p: DVec2| [(p.x * 1e9).round() as i64, (p.y * 1e9).round() as i64];
    let mut out: Vec<Vec<[i64; 2]>> = soup
        .faces
        .iter()
        .enumerate()
        .map(|(k, f)| {
            let c: Vec<[i64; 2]> = (0..f.len()).map(|j| q(value(k, j))).collect();
            let r = (0..c.len()).min_by_key(|&i| c[i]).unwrap();
            (0..c.len()).map(|i| c[(r + i) % c.len()]).collect()
        })
        .collect();
    out.sort();
    out
}

fn corner_uv<'a>(soup: &'a PolygonSoup, uvs: &'a FaceUvs) -> impl Fn(usize, usize) -> DVec2 + 'a {
    move |k, j| uvs.face(&soup.faces, k).nth(j).unwrap()
}

fn xy(soup: &PolygonSoup) -> impl Fn(usize, usize) -> DVec2 + '_ {
    move |k, j| soup.positions[soup.faces[k][j] as usize].truncate()
}

#[test]
fn texture_coordinates_read_and_write_back() {
    let dir = scratch("uvs-io");
    let soup = jitter(shapes::quad_grid(3, 2), 5);
    let obj = dir.path().join("grid.obj");
    write_obj(&obj, &soup, |k, j, _| {
        DVec2::new(k as f64 + 0.25 * j as f64, 0.5 - j as f64)
    });
    let (_, read, uvs) = io::read_with_uvs(&obj).unwrap();
    let uvs = uvs.uvs.unwrap();
    assert_eq!(read.faces, soup.faces);
    assert_eq!(
        uvs.face(&read.faces, 4).nth(3),
        Some(DVec2::new(4.75, -2.5))
    );
    // Written as OBJ and as PLY (a face's texcoord list), read back the same.
    for name in ["again.obj", "again.ply"] {
        let out = dir.path().join(name);
        io::write_with_attributes(&out, &read, None, Some(&uvs), &[]).unwrap();
        let (_, back, back_uvs) = io::read_with_uvs(&out).unwrap();
        let back_uvs = back_uvs.uvs.unwrap();
        assert_eq!(back.faces, read.faces, "{name}");
        for k in 0..read.faces.len() {
            let a: Vec<DVec2> = uvs.face(&read.faces, k).collect();
            let b: Vec<DVec2> = back_uvs.face(&back.faces, k).collect();
            assert_eq!(a, b, "{name}, face {k}");
        }
    }
    // PLY with a coordinate per vertex (`u v`).
    let ply = dir.path().join("vertex.ply");
    std::fs::write(
        &ply,
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
         property float z\nproperty float u\nproperty float v\nelement face 1\n\
         property list uchar int vertex_indices\nend_header\n\
         0 0 0 0.5 0.25\n1 0 0 1 0\n0 1 0 0 1\n3 0 1 2\n",
    )
    .unwrap();
    let (_, s, uvs) = io::read_with_uvs(&ply).unwrap();
    let got: Vec<DVec2> = uvs.uvs.unwrap().face(&s.faces, 0).collect();
    assert_eq!(
        got,
        [
            DVec2::new(0.5, 0.25),
            DVec2::new(1.0, 0.0),
            DVec2::new(0.0, 1.0)
        ]
    );
}

/// Coordinates that are not whole are dropped with a warning at their
/// place; the mesh itself reads as before (and a plain read ignores them).
#[test]
fn bad_texture_coordinates_are_located() {
    let dir = scratch("uvs-bad");
    let cases = [
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\nf 1/1 2/1 3/1\nf 2 4 3\n",
            "bad.obj:7:1",
            "face 2 has no texture coordinate at its corner 1",
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/9 3/1\n",
            "bad.obj:5:7",
            "refers to texture coordinate 9, but 1 `vt` lines precede it",
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 nan\nf 1/1 2/1 3/1\n",
            "bad.obj:4:4",
            "finite",
        ),
    ];
    for (text, at, what) in cases {
        let path = dir.path().join("bad.obj");
        std::fs::write(&path, text).unwrap();
        let (_, soup, read) = io::read_with_uvs(&path).unwrap();
        let w = read.warning.expect("a warning");
        assert!(read.uvs.is_none(), "{w}");
        assert!(
            w.contains(&format!("{at}: warning: ")) && w.contains(what) && w.contains('^'),
            "{w}"
        );
        assert_eq!(io::read(&path).unwrap(), soup);
    }
}

/// Without seams and with `none`, the layout is the mesh seen from above:
/// every corner's coordinates are its vertex's x and y after the run.
#[test]
fn without_seams_the_coordinates_follow_the_positions() {
    let dir = scratch("uvs-follow");
    for (grammar, base) in [
        ("surfaces/catmull-clark.lsys", shapes::quad_grid(3, 3)),
        ("surfaces/loop.lsys", shapes::triangle_grid(3, 3)),
    ] {
        let base = jitter(base, 11);
        let mesh = dir.path().join("base.obj");
        write_obj(&mesh, &base, |_, _, v| {
            base.positions[v as usize].truncate()
        });
        let out = dir.path().join("out.obj");
        let (soup, uvs) = subdivide(&args(&mesh, grammar, 2, &out, Some("none")));
        let mut worst = 0.0f64;
        for k in 0..soup.faces.len() {
            for (j, t) in uvs.face(&soup.faces, k).enumerate() {
                let p = soup.positions[soup.faces[k][j] as usize];
                worst = worst.max((t - p.truncate()).abs().max_element());
            }
        }
        assert!(worst < 1e-12, "{grammar}: {worst}");
    }
}

/// A seam is a boundary of the layout: with `none`, each side's
/// coordinates are what the grammar makes of that side as a mesh of its
/// own (its boundary rules along the seam).
#[test]
fn a_seam_is_a_boundary_with_the_boundary_rules() {
    let dir = scratch("uvs-seam");
    for (grammar, base) in [
        ("surfaces/catmull-clark.lsys", shapes::quad_grid(4, 3)),
        ("surfaces/loop.lsys", shapes::triangle_grid(4, 3)),
    ] {
        let base = jitter(base, 3);
        // The left half (faces whose first corner has i < 2 in the grid)
        // keeps x y; the right half is moved 10 along u: a seam between.
        let right = |k: usize| {
            let f = &base.faces[k];
            let c: f64 = f.iter().map(|&v| (v % 5) as f64).sum::<f64>() / f.len() as f64;
            c > 2.0
        };
        let shift = |k: usize| if right(k) { 10.0 } else { 0.0 };
        let mesh = dir.path().join("base.obj");
        write_obj(&mesh, &base, |k, _, v| {
            base.positions[v as usize].truncate() + DVec2::new(shift(k), 0.0)
        });
        let out = dir.path().join("out.obj");
        let (soup, uvs) = subdivide(&args(&mesh, grammar, 2, &out, Some("none")));
        let got = cycles(&soup, corner_uv(&soup, &uvs));
        // Each side as its own mesh, run on positions.
        let mut want = Vec::new();
        for side in [false, true] {
            let mut half = base.clone();
            half.faces.retain(|_| true);
            let faces: Vec<Vec<u32>> = (0..base.faces.len())
                .filter(|&k| right(k) == side)
                .map(|k| base.faces[k].to_vec())
                .collect();
            let part = compact(&base.positions, &faces);
            let run = positions_run(grammar, &part, 2);
            let dx = if side { 10.0 } else { 0.0 };
            want.extend(cycles(&run, |k, j| xy(&run)(k, j) + DVec2::new(dx, 0.0)));
        }
        want.sort();
        assert_eq!(got.len(), want.len(), "{grammar}");
        assert!(
            got == want,
            "{grammar}: the coordinates differ from the halves' runs"
        );
    }
}

/// The soup of `faces` over the positions they use.
fn compact(positions: &[DVec3], faces: &[Vec<u32>]) -> PolygonSoup {
    let mut index = HashMap::new();
    let mut s = PolygonSoup::default();
    for f in faces {
        let g: Vec<u32> = f
            .iter()
            .map(|&v| {
                *index.entry(v).or_insert_with(|| {
                    s.positions.push(positions[v as usize]);
                    s.positions.len() as u32 - 1
                })
            })
            .collect();
        s.faces.push(g);
    }
    s
}

/// `all`: linear interpolation, written out here: a quad's children are
/// (corner, edge midpoint, centroid, edge midpoint); a triangle's under
/// Catmull-Clark the same with its centroid, under Loop its three corner
/// triangles and the middle one.
#[test]
fn all_is_linear_interpolation() {
    let dir = scratch("uvs-all");
    let cube = cube_cross();
    for (grammar, base, loop_scheme) in [
        ("surfaces/catmull-clark.lsys", cube.clone(), false),
        ("surfaces/catmull-clark.lsys", cube.fanned(), false),
        ("surfaces/loop.lsys", cube.fanned(), true),
    ] {
        let base_uv = |k: usize, j: usize| cross_uv(&base, k, j);
        let mesh = dir.path().join("cube.obj");
        write_obj(&mesh, &base, |k, j, _| base_uv(k, j));
        let out = dir.path().join("out.obj");
        let (soup, uvs) = subdivide(&args(&mesh, grammar, 2, &out, Some("all")));
        let got = cycles(&soup, corner_uv(&soup, &uvs));
        // The base faces' corner values, split twice.
        let mut faces: Vec<Vec<DVec2>> = (0..base.faces.len())
            .map(|k| (0..base.faces[k].len()).map(|j| base_uv(k, j)).collect())
            .collect();
        for _ in 0..2 {
            faces = faces.iter().flat_map(|f| split(f, loop_scheme)).collect();
        }
        let flat = PolygonSoup {
            faces: (0..faces.len())
                .map(|k| (0..faces[k].len() as u32).collect::<Vec<u32>>())
                .collect(),
            ..PolygonSoup::default()
        };
        let want = cycles(&flat, |k, j| faces[k][j]);
        assert!(
            got == want,
            "{grammar} ({} faces): not linear",
            base.faces.len()
        );
    }
}

/// One step of linear interpolation of a face's corner values.
fn split(f: &[DVec2], loop_scheme: bool) -> Vec<Vec<DVec2>> {
    let n = f.len();
    let mid = |j: usize| (f[j] + f[(j + 1) % n]) * 0.5;
    if loop_scheme {
        let mut out: Vec<Vec<DVec2>> = (0..3)
            .map(|j| vec![f[j], mid(j), mid((j + 2) % 3)])
            .collect();
        out.push(vec![mid(0), mid(1), mid(2)]);
        return out;
    }
    let c = f.iter().copied().sum::<DVec2>() / n as f64;
    (0..n)
        .map(|j| vec![f[j], mid(j), c, mid((j + n - 1) % n)])
        .collect()
}

/// A cube, jiggled, whose faces are laid out as a cross: seams along
/// seven edges.
fn cube_cross() -> PolygonSoup {
    let mut s = PolygonSoup::default();
    for z in [-1.0, 1.0] {
        for y in [-1.0, 1.0] {
            for x in [-1.0, 1.0] {
                s.positions.push(DVec3::new(x, y, z));
            }
        }
    }
    for f in [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [1, 3, 7, 5],
        [3, 2, 6, 7],
        [2, 0, 4, 6],
    ] {
        s.faces.push(f);
    }
    jitter(s, 7)
}

/// The cross layout's value at corner `j` of face `k` of the cube or of
/// its fan of triangles (a quad `q` is triangles `2q`, `2q + 1`: corners
/// 0 1 2 and 0 2 3).
fn cross_uv(s: &PolygonSoup, k: usize, j: usize) -> DVec2 {
    let cell = [
        (1.0, 0.0),
        (1.0, 2.0),
        (1.0, 1.0),
        (2.0, 1.0),
        (1.0, 3.0),
        (0.0, 1.0),
    ];
    let corner = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];
    let (q, c) = if s.faces.len() == 6 {
        (k, j)
    } else {
        (k / 2, if k.is_multiple_of(2) { j } else { [0, 2, 3][j] })
    };
    let (cx, cy) = cell[q];
    let (a, b) = corner[c];
    // Uneven cells, so that no average hides behind a symmetry.
    DVec2::new(
        (cx + a) / 4.0 + 0.01 * q as f64,
        (cy + b) / 4.0 + 0.003 * (c * c) as f64,
    )
}

/// Which values stay where they are after a step, by OpenSubdiv's rules:
/// every value on a seam under `boundaries`; a value of a single face
/// (a corner of the layout) under `corners-only` and on; where three or
/// more values meet under `corners-plus1`; under `none`, none of them.
#[test]
fn the_choices_keep_the_values_they_name() {
    let dir = scratch("uvs-keep");
    let base = cube_cross();
    let mesh = dir.path().join("cube.obj");
    write_obj(&mesh, &base, |k, j, _| cross_uv(&base, k, j));
    // Each base vertex's values and the faces that hold each.
    let mut values: HashMap<u32, HashMap<[u64; 2], usize>> = HashMap::new();
    for (k, f) in base.faces.iter().enumerate() {
        for (j, &v) in f.iter().enumerate() {
            let t = cross_uv(&base, k, j);
            *values
                .entry(v)
                .or_default()
                .entry([t.x.to_bits(), t.y.to_bits()])
                .or_default() += 1;
        }
    }
    let out = dir.path().join("out.obj");
    for mode in ["none", "corners-only", "corners-plus1", "boundaries"] {
        let (soup, uvs) = subdivide(&args(
            &mesh,
            "surfaces/catmull-clark.lsys",
            1,
            &out,
            Some(mode),
        ));
        // A base vertex's point is the corner of the child faces whose
        // value came from it: find each base value among the output's.
        let mut kept = 0;
        let mut should = 0;
        for (v, vals) in &values {
            for (t, &faces) in vals {
                let stays = match mode {
                    "none" => false,
                    "corners-only" => faces == 1,
                    "corners-plus1" => faces == 1 || vals.len() > 2,
                    _ => true,
                };
                let t = DVec2::new(f64::from_bits(t[0]), f64::from_bits(t[1]));
                let found = (0..soup.faces.len()).any(|k| uvs.face(&soup.faces, k).any(|u| u == t));
                assert_eq!(found, stays, "{mode}: base vertex {v}, value {t}");
                should += stays as usize;
                kept += found as usize;
            }
        }
        assert_eq!(kept, should, "{mode}");
        assert!(mode == "none" || kept > 0, "{mode} kept nothing");
    }
}

#[test]
fn what_cannot_carry_coordinates_says_so() {
    let dir = scratch("uvs-refuse");
    let base = shapes::icosahedron();
    let mesh = dir.path().join("ico.obj");
    // A seam: each face its own chart.
    write_obj(&mesh, &base, |k, j, _| DVec2::new(k as f64, j as f64));
    let out = dir.path().join("out.obj");
    // √3's boundary rules change its topology at the seams.
    let e = command::subdivide(
        &args(&mesh, "surfaces/sqrt3.lsys", 1, &out, Some("none")),
        |_| {},
    )
    .expect_err("refused")
    .to_string();
    assert!(e.contains("--no-uvs") && e.contains("seams"), "{e}");
    assert!(!out.exists());
    // A grammar without crease rules cannot keep values linear.
    let e = command::subdivide(&args(&mesh, "surfaces/sqrt3.lsys", 1, &out, None), |_| {})
        .expect_err("refused")
        .to_string();
    assert!(
        e.contains("--fvar-linear boundaries") && e.contains("crease rules"),
        "{e}"
    );
    // --no-uvs subdivides without them.
    let mut a = args(&mesh, "surfaces/sqrt3.lsys", 1, &out, None);
    a.no_uvs = true;
    command::subdivide(&a, |_| {}).unwrap();
    let (_, _, read) = io::read_with_uvs(&out).unwrap();
    assert!(read.uvs.is_none() && read.warning.is_none());
    // OFF keeps none, and says so.
    let off = dir.path().join("out.off");
    let warnings =
        command::subdivide(&args(&mesh, "surfaces/loop.lsys", 1, &off, None), |_| {}).unwrap();
    assert!(
        warnings.iter().any(|w| w.contains("texture coordinates")),
        "{warnings:?}"
    );
    // Where they cannot follow, the output says it lost them.
    for (grammar, output, limit) in [
        ("vv/loop.lsys", "vv.obj", false),
        ("surfaces/loop.lsys", "limit.obj", true),
        ("surfaces/loop.lsys", "scene.glb", false),
    ] {
        let out = dir.path().join(output);
        let mut a = args(&mesh, grammar, 1, &out, None);
        a.limit = limit;
        let warnings = command::subdivide(&a, |_| {}).unwrap();
        assert!(
            warnings
                .iter()
                .any(|w| w.contains("texture coordinates of")),
            "{grammar} -> {output}: {warnings:?}"
        );
    }
    // A dual scheme is refused before it runs.
    let e = command::subdivide(
        &args(&mesh, "surfaces/doo-sabin.lsys", 1, &out, Some("none")),
        |_| {},
    )
    .expect_err("refused")
    .to_string();
    assert!(e.contains("dual scheme") && e.contains("--no-uvs"), "{e}");
    // An unknown choice.
    let e = command::subdivide(
        &args(&mesh, "surfaces/loop.lsys", 1, &out, Some("smooth")),
        |_| {},
    )
    .expect_err("refused")
    .to_string();
    assert!(
        e.contains("corners-plus1") && e.contains("`--fvar-linear smooth`"),
        "{e}"
    );
}
