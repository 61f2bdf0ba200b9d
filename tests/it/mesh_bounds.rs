//! Bounds on mesh input: counts in headers checked against the data, the
//! size of a file, the valences a grammar run may make; linear work on
//! long polygons; every refusal located, with exit code 1, quickly, and
//! nothing left behind.

use std::path::{Path, PathBuf};
use std::process::Output;
use std::time::{Duration, Instant};

use subgram::mesh::io::{self, Format};
use subgram::mesh::{Mesh, PolygonSoup, VertexId};

use crate::support::scratch;

/// Runs the binary in `dir` with `env` set, timing it.
fn bin(dir: &Path, args: &[&str], env: &[(&str, &str)]) -> (Output, Duration) {
    let t = Instant::now();
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_subgram"))
        .current_dir(dir)
        .args(args)
        .env_remove("SUBGRAM_MAX_VALENCE")
        .env_remove("SUBGRAM_MAX_MESH_BYTES")
        .envs(env.iter().copied())
        .output()
        .unwrap();
    (o, t.elapsed())
}

/// The folder's entries, by name.
fn entries(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// Writes `bytes` as `dir/name`, runs `subgram mesh convert` on it to
/// `out.obj`, and returns stderr after checking exit code 1, that the
/// run took under `within`, and that nothing was written.
fn refused(dir: &Path, name: &str, bytes: &[u8], env: &[(&str, &str)], within: u64) -> String {
    let input = dir.join(name);
    std::fs::write(&input, bytes).unwrap();
    let (o, took) = bin(dir, &["mesh", "convert", name, "out.obj"], env);
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(o.status.code(), Some(1), "{name}: {err}");
    assert!(took < Duration::from_secs(within), "{name} took {took:?}");
    assert_eq!(entries(dir), vec![name.to_string()], "{name}: {err}");
    std::fs::remove_file(&input).unwrap();
    err
}

/// The octahedron of `lsystems/meshes`.
fn octahedron() -> Mesh {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    Mesh::from_soup(&io::read(&root.join("lsystems/meshes/octahedron.obj")).unwrap()).unwrap()
}

/// Asserts that `msg` contains every one of `parts`.
fn assert_mentions(msg: &str, parts: &[&str]) {
    for part in parts {
        assert!(msg.contains(part), "`{part}` is not in the message:\n{msg}");
    }
}

const TET_BIN_HEADER: &str = "\
ply
format binary_little_endian 1.0
element vertex 4
property float x
property float y
property float z
element face 4
property list uchar int vertex_indices
end_header
";

/// The tetrahedron's binary data for [`TET_BIN_HEADER`].
fn tet_binary_data() -> Vec<u8> {
    let mut d = Vec::new();
    for p in [
        [0.0f32, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ] {
        for c in p {
            d.extend(c.to_le_bytes());
        }
    }
    for f in [[0i32, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]] {
        d.push(3);
        for i in f {
            d.extend(i.to_le_bytes());
        }
    }
    d
}

const TET_PLY: &str = "\
ply
format ascii 1.0
element vertex 4
property float x
property float y
property float z
element face 4
property list uchar int vertex_indices
end_header
0 0 0
1 0 0
0 1 0
0 0 1
3 0 2 1
3 0 1 3
3 0 3 2
3 1 2 3
";

// ---------------------------------------------------------------------------
// Counts in headers

#[test]
fn bounds_ply_element_without_properties_and_a_huge_count() {
    // Once a hang in every command that reads a mesh: nothing is read per
    // instance, so the count alone drove the loop.
    let tmp = scratch("bounds-no-properties");
    let dir = tmp.path();
    let element = "element e 18446744073709551615\n";
    let ascii = TET_PLY.replace(
        "element vertex 4\n",
        &format!("{element}element vertex 4\n"),
    );
    let err = refused(dir, "ascii.ply", ascii.as_bytes(), &[], 10);
    assert_mentions(
        &err,
        &[
            "ascii.ply:3:11: error: the `e` element declares 18446744073709551615 instances \
             but no properties to read for them; declare its properties, or a count of 0",
            "3 | element e 18446744073709551615\n  |           ^^^^^^^^^^^^^^^^^^^^",
        ],
    );
    let mut binary = TET_BIN_HEADER
        .replace("end_header\n", &format!("{element}end_header\n"))
        .into_bytes();
    binary.extend(tet_binary_data());
    let err = refused(dir, "binary.ply", &binary, &[], 10);
    assert_mentions(&err, &["binary.ply:9:11: error: the `e` element declares"]);
    // With no instances it is harmless.
    let empty = TET_PLY.replace("element vertex 4\n", "element e 0\nelement vertex 4\n");
    let soup = io::read_str("t.ply", Format::Ply, empty.as_bytes()).unwrap();
    assert_eq!(soup.faces.len(), 4);
}

#[test]
fn bounds_binary_ply_counts_past_the_data() {
    let data = tet_binary_data();
    let with = |header: String, data: &[u8]| {
        let mut bytes = header.into_bytes();
        bytes.extend(data);
        io::read_str("t.ply", Format::Ply, &bytes)
            .unwrap_err()
            .to_string()
    };
    let t = Instant::now();
    // Fixed-size instances: refused before any is read.
    let header = TET_BIN_HEADER.replace("vertex 4", "vertex 18446744073709551615");
    assert_mentions(
        &with(header, &data),
        &[
            "t.ply:3:16: error: the binary data ends after 8 of the 18446744073709551615 \
           declared `vertex` elements",
        ],
    );
    // Instances with lists: each takes a byte at least, so the loop ends
    // with the data.
    let header = TET_BIN_HEADER.replace("face 4", "face 4000000000");
    assert_mentions(
        &with(header, &data),
        &["t.ply:7:14: error: the binary data ends after 4 of the 4000000000 declared `face` elements"],
    );
    // A list longer than the data left: refused before its items are read.
    let header = TET_BIN_HEADER.replace("uchar int", "uint int");
    let mut long = data[..48].to_vec();
    long.extend(u32::MAX.to_le_bytes());
    long.extend([0; 64]);
    assert_mentions(
        &with(header, &long),
        &["t.ply:7:14: error: the binary data ends after 0 of the 4 declared `face` elements"],
    );
    assert!(t.elapsed() < Duration::from_secs(5), "{:?}", t.elapsed());
}

#[test]
fn bounds_ascii_counts_past_the_data() {
    let t = Instant::now();
    let huge = TET_PLY.replace("vertex 4", "vertex 18446744073709551615");
    let msg = io::read_str("t.ply", Format::Ply, huge.as_bytes())
        .unwrap_err()
        .to_string();
    assert_mentions(
        &msg,
        &["t.ply:17:8: error: the file ends after 9 of the 18446744073709551615 declared `vertex` elements"],
    );
    let list = TET_PLY.replace("3 1 2 3\n", "4294967295 1 2 3\n");
    let msg = io::read_str("t.ply", Format::Ply, list.as_bytes())
        .unwrap_err()
        .to_string();
    assert_mentions(
        &msg,
        &["t.ply:17:17: error: the file ends after 3 of the 4 declared `face` elements"],
    );
    let off = "OFF\n18446744073709551615 18446744073709551615 0\n0 0 0\n";
    let msg = io::read_str("t.off", Format::Off, off.as_bytes())
        .unwrap_err()
        .to_string();
    assert_mentions(
        &msg,
        &["t.off:3:6: error: the file ends after 1 of the 18446744073709551615 declared vertices"],
    );
    let off = "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n18446744073709551615 0 1 2\n";
    let msg = io::read_str("t.off", Format::Off, off.as_bytes())
        .unwrap_err()
        .to_string();
    assert_mentions(
        &msg,
        &[
            "t.off:6:1: error: face 0 declares 18446744073709551615 vertices but lists 3",
            "6 | 18446744073709551615 0 1 2\n  | ^^^^^^^^^^^^^^^^^^^^",
        ],
    );
    assert!(t.elapsed() < Duration::from_secs(5), "{:?}", t.elapsed());
}

// ---------------------------------------------------------------------------
// Located messages

#[test]
fn bounds_mesh_errors_show_the_line_and_a_caret() {
    let tmp = scratch("bounds-located");
    let dir = tmp.path();
    let err = refused(
        dir,
        "m.obj",
        b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n",
        &[],
        10,
    );
    assert_eq!(
        err,
        "m.obj:4:7: error: face 1 refers to vertex 7, but there are only 3 vertices\n  \
         |\n4 | f 1 2 7\n  |       ^\n"
    );
    let err = refused(
        dir,
        "m.off",
        b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2x\n",
        &[],
        10,
    );
    assert_eq!(
        err,
        "m.off:6:7: error: expected a vertex index, found `2x`\n  |\n6 | 3 0 1 2x\n  |       ^^\n"
    );
    let err = refused(
        dir,
        "m.ply",
        TET_PLY.replace("1 0 0\n", "1 0 zero\n").as_bytes(),
        &[],
        10,
    );
    assert_eq!(
        err,
        "m.ply:11:5: error: expected a number, found `zero`\n   |\n11 | 1 0 zero\n   |     ^^^^\n"
    );
    let mut bytes = TET_BIN_HEADER.replace("float z", "float z w").into_bytes();
    bytes.extend(tet_binary_data());
    let err = refused(dir, "b.ply", &bytes, &[], 10);
    assert_eq!(
        err,
        "b.ply:6:1: error: expected `property TYPE NAME` or `property list COUNT_TYPE ITEM_TYPE NAME`\n  \
         |\n6 | property float z w\n  | ^^^^^^^^^^^^^^^^^^\n"
    );
    // What the half-edge mesh refuses, at the line of the element.
    let bowtie = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv -1 0 0\nv 0 -1 0\nf 1 2 3\nf 1 4 5\n";
    let err = refused(dir, "bowtie.obj", bowtie, &[], 10);
    assert_eq!(
        err,
        "bowtie.obj:1:1: error: vertex 1 (line 1) is a bow-tie: two separate fans of faces meet \
         there (non-manifold)\n  |\n1 | v 0 0 0\n  | ^^^^^^^\n"
    );
    // Invalid UTF-8, at its byte, the line shown with U+FFFD.
    let err = refused(dir, "u.obj", b"v 0 0 0\nv 1 \xff\xfe 0\n", &[], 10);
    assert_eq!(
        err,
        "u.obj:2:5: error: the file is not UTF-8 text (an invalid byte on this line)\n  \
         |\n2 | v 1 \u{fffd}\u{fffd} 0\n  |     ^\n"
    );
    let mut bytes = TET_BIN_HEADER
        .replace("element face", "element f@ce")
        .into_bytes();
    let at = bytes.iter().position(|&b| b == b'@').unwrap();
    bytes[at] = 0xff;
    let err = refused(dir, "h.ply", &bytes, &[], 10);
    assert_mentions(&err, &["h.ply:7:10: error: the PLY header is not text"]);
}

// ---------------------------------------------------------------------------
// The size of a file

#[test]
fn bounds_files_larger_than_the_limit_are_refused_before_reading() {
    let tmp = scratch("bounds-size");
    let dir = tmp.path();
    let limit = [("SUBGRAM_MAX_MESH_BYTES", "100")];
    let err = refused(dir, "big.ply", TET_PLY.as_bytes(), &limit, 10);
    assert_mentions(
        &err,
        &[
            "big.ply: error: the file is 210 bytes, more than the limit of 100 bytes for a mesh \
           file; set SUBGRAM_MAX_MESH_BYTES to a larger number of bytes to read it",
        ],
    );
    let bad = [("SUBGRAM_MAX_MESH_BYTES", "2G")];
    let err = refused(dir, "tet.ply", TET_PLY.as_bytes(), &bad, 10);
    assert_mentions(
        &err,
        &["SUBGRAM_MAX_MESH_BYTES must be a whole number of bytes, found `2G`"],
    );
    // A device that cannot hold a mesh of the format is refused at its
    // first bytes: `/dev/zero` gives NUL bytes, and OBJ files are text.
    std::os::unix::fs::symlink("/dev/zero", dir.join("zero.obj")).unwrap();
    let (o, took) = bin(dir, &["mesh", "convert", "zero.obj", "out.obj"], &[]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(took < Duration::from_secs(10), "{took:?}");
    assert_mentions(
        &err,
        &["zero.obj: error: byte 1 is a NUL byte, and OBJ files are text"],
    );
    std::fs::remove_file(dir.join("zero.obj")).unwrap();
    // A stream of text that never ends is read up to the limit only: the
    // input is the child's standard input, fed with vertex lines until the
    // child stops reading.
    std::os::unix::fs::symlink("/dev/stdin", dir.join("stream.obj")).unwrap();
    let t = Instant::now();
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_subgram"))
        .current_dir(dir)
        .args(["mesh", "convert", "stream.obj", "out.obj"])
        .env_remove("SUBGRAM_MAX_MESH_BYTES")
        .env("SUBGRAM_MAX_MESH_BYTES", "1048576")
        .stdin(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let feeder = std::thread::spawn(move || {
        use std::io::Write;
        let line = b"v 0 0 0\n".repeat(4096);
        // Until the child has read what it wants and closed the pipe.
        while stdin.write_all(&line).is_ok() {}
    });
    let o = child.wait_with_output().unwrap();
    let took = t.elapsed();
    feeder.join().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(took < Duration::from_secs(10), "{took:?}");
    assert_mentions(
        &err,
        &["stream.obj: error: the file goes on, more than the limit of 1048576 bytes (1 MiB) for a \
           mesh file; set SUBGRAM_MAX_MESH_BYTES"],
    );
    assert_eq!(entries(dir), vec!["stream.obj".to_string()]);
    assert_eq!(io::MAX_FILE_BYTES, 2 << 30);
}

// ---------------------------------------------------------------------------
// Long polygons

/// A convex polygon of `n` vertices on the unit circle.
fn circle(n: usize) -> PolygonSoup {
    let positions = (0..n)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            glam::DVec3::new(a.cos(), a.sin(), 0.0)
        })
        .collect();
    PolygonSoup {
        positions,
        faces: vec![(0..n as u32).collect()].into(),
        ..PolygonSoup::default()
    }
}

#[test]
fn bounds_a_polygon_of_600000_vertices_is_checked_in_linear_time() {
    // Once checked pairwise for repeated vertices: 1.8e11 comparisons.
    let t = Instant::now();
    let mut soup = circle(600_000);
    let m = Mesh::from_soup(&soup).unwrap();
    assert_eq!(m.face_count(), 599_998);
    assert_eq!(m.max_valence(), Some((VertexId(0), 599_999)));
    soup.faces[0][599_999] = 17;
    let e = Mesh::from_soup(&soup).unwrap_err();
    assert_eq!(e.message, "face 1 is degenerate: it uses vertex 18 twice");
    // The reader, on the same polygon as text with the repeat at its end.
    let mut text = String::new();
    for p in &soup.positions {
        text.push_str(&format!("v {} {} 0\n", p.x, p.y));
    }
    text.push('f');
    for i in &soup.faces[0] {
        text.push_str(&format!(" {}", i + 1));
    }
    let msg = io::read_str("c.obj", Format::Obj, text.as_bytes())
        .unwrap_err()
        .to_string();
    // The caret under the last word, in a window of the 4 MB line.
    let col = text.len() - text.rfind('\n').unwrap() - 2;
    assert_mentions(
        &msg,
        &[
            &format!("c.obj:600001:{col}: error: face 1 repeats vertex 18 (a degenerate face)"),
            " 599998 599999 18\n",
        ],
    );
    assert!(msg.ends_with(" ^^"), "{msg}");
    assert!(t.elapsed() < Duration::from_secs(60), "{:?}", t.elapsed());
}

// ---------------------------------------------------------------------------
// Valences in grammar runs

/// Two face splits a step: valences grow fourfold each step.
const TWO_SPLITS: &str = "\
derivation length: 6;
F(f) -> V(v = avg(f)) || E^3 F^3;
F(f) -> V(v = avg(f)) || E^3 F^3;
";

#[test]
fn bounds_valences_that_explode_stop_the_run() {
    let g = subgram::surface::load_str("two.lsys", TWO_SPLITS, &[]).unwrap();
    assert_eq!(g.max_valence, 1000);
    let t = Instant::now();
    let mut m = octahedron();
    let e = g.run(&mut m, 6, |_| {}).unwrap_err();
    // Each split doubles the valence of the octahedron's vertices: 4 · 2^8.
    assert_eq!(
        g.render_error(&e),
        "two.lsys:3:1: error: at step 4, rule `F(f) -> V(v = avg(f)) || E^3 F^3`: vertex 1 has \
         valence 1024 after this rule, more than the limit of 1000; a grammar whose valences \
         keep growing slows down without end (set SUBGRAM_MAX_VALENCE to a larger number to \
         allow more)\n  |\n3 | F(f) -> V(v = avg(f)) || E^3 F^3;\n  | \
         ^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^^"
    );
    assert!(t.elapsed() < Duration::from_secs(20), "{:?}", t.elapsed());
    // The library's limit.
    let mut g = g;
    g.max_valence = 20;
    let mut m = octahedron();
    let e = g.run(&mut m, 6, |_| {}).unwrap_err();
    assert!(
        e.message.starts_with("at step 2, rule")
            && e.message
                .contains("valence 32 after this rule, more than the limit of 20"),
        "{}",
        e.message
    );
}

#[test]
fn bounds_valence_limit_allows_twice_the_base_mesh() {
    // A double cone of 80 triangles: √3 doubles its apexes' valence of 40
    // for a moment (face split, then flips), past a limit of 50 but not
    // past twice the base mesh's highest valence.
    let g = subgram::surface::load_file(
        &PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("lsystems/surfaces/sqrt3-printed.lsys"),
        &[],
    )
    .unwrap();
    let mut g = g;
    g.max_valence = 50;
    let mut soup = circle(40);
    soup.positions.push(glam::DVec3::new(0.0, 0.0, 1.0));
    soup.positions.push(glam::DVec3::new(0.0, 0.0, -1.0));
    soup.faces = (0..40u32)
        .flat_map(|i| [vec![40, i, (i + 1) % 40], vec![41, (i + 1) % 40, i]])
        .collect();
    let mut m = Mesh::from_soup(&soup).unwrap();
    assert_eq!(m.max_valence(), Some((VertexId(40), 40)));
    g.run(&mut m, 1, |_| {})
        .unwrap_or_else(|e| panic!("{}", g.render_error(&e)));
    m.validate().unwrap();
}

#[test]
fn bounds_valence_limit_from_the_command_line() {
    let tmp = scratch("bounds-valence");
    let dir = tmp.path();
    let octahedron =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("lsystems/meshes/octahedron.obj");
    std::fs::write(dir.join("two.lsys"), TWO_SPLITS).unwrap();
    let args = [
        "subdivide",
        octahedron.to_str().unwrap(),
        "--grammar",
        "two.lsys",
        "-o",
        "out.obj",
    ];
    let (o, took) = bin(dir, &args, &[]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(took < Duration::from_secs(20), "{took:?}");
    assert_mentions(
        &err,
        &[
            "two.lsys:3:1: error: at step 4, rule",
            "more than the limit of 1000",
            "(set SUBGRAM_MAX_VALENCE to a larger number to allow more)",
        ],
    );
    let (o, _) = bin(dir, &args, &[("SUBGRAM_MAX_VALENCE", "100")]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert_mentions(
        &err,
        &[
            "at step 3, rule",
            "valence 128 after this rule, more than the limit of 100",
        ],
    );
    let (o, _) = bin(dir, &args, &[("SUBGRAM_MAX_VALENCE", "many")]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert_mentions(
        &err,
        &["SUBGRAM_MAX_VALENCE must be a whole number, found `many`"],
    );
    assert_eq!(entries(dir), vec!["two.lsys".to_string()]);
}

#[test]
fn bounds_find_face_walks_from_every_corner() {
    let m = octahedron();
    for f in m.faces() {
        let [a, b, c] = m.face_vertices(f);
        for vs in [[a, b, c], [b, c, a], [c, a, b]] {
            assert_eq!(m.find_face(vs), Some(f));
        }
        assert_eq!(m.find_face([a, c, b]), None);
    }
    // A triangle at a vertex of valence 99,999 is found from its corners
    // of valence 3 (the fan is walked a few steps at most).
    let m = Mesh::from_soup(&circle(100_000)).unwrap();
    let t = Instant::now();
    for f in m.faces().take(20_000) {
        assert_eq!(m.find_face(m.face_vertices(f)), Some(f));
    }
    assert!(t.elapsed() < Duration::from_secs(5), "{:?}", t.elapsed());
}
