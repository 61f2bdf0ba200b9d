//! Mesh files: reading OBJ, OFF and PLY (ASCII and binary), writing them
//! back exactly, and refusing bad files with located messages.

use std::path::Path;

use glam::DVec3;
use subgram::mesh::io::{self, Format};
use subgram::mesh::PolygonSoup;

use crate::support::scratch;

// ---------------------------------------------------------------------------
// Helpers

/// Reads `text` as `format`, panicking with the message on failure.
fn read(name: &str, format: Format, bytes: &[u8]) -> PolygonSoup {
    io::read_str(name, format, bytes).unwrap_or_else(|e| panic!("{e}"))
}

fn obj(text: &str) -> PolygonSoup {
    read("t.obj", Format::Obj, text.as_bytes())
}

fn off(text: &str) -> PolygonSoup {
    read("t.off", Format::Off, text.as_bytes())
}

fn ply(bytes: &[u8]) -> PolygonSoup {
    read("t.ply", Format::Ply, bytes)
}

/// The Display text of the error reading `bytes`, panicking if it reads.
fn error(name: &str, format: Format, bytes: &[u8]) -> String {
    match io::read_str(name, format, bytes) {
        Ok(soup) => panic!("{name} read without error: {soup:?}"),
        Err(e) => e.to_string(),
    }
}

fn obj_error(text: &str) -> String {
    error("t.obj", Format::Obj, text.as_bytes())
}

fn off_error(text: &str) -> String {
    error("t.off", Format::Off, text.as_bytes())
}

fn ply_error(bytes: &[u8]) -> String {
    error("t.ply", Format::Ply, bytes)
}

/// Asserts that `msg` contains every one of `parts`.
fn assert_mentions(msg: &str, parts: &[&str]) {
    for part in parts {
        assert!(msg.contains(part), "`{part}` is not in the message:\n{msg}");
    }
}

fn faces(soup: &PolygonSoup) -> Vec<Vec<u32>> {
    soup.faces.to_vecs()
}

/// Positions as bit patterns, for exact comparisons (telling -0.0 from 0.0).
fn bits(soup: &PolygonSoup) -> Vec<[u64; 3]> {
    soup.positions
        .iter()
        .map(|p| p.to_array().map(f64::to_bits))
        .collect()
}

// ---------------------------------------------------------------------------
// Meshes

const TET_POSITIONS: [[f64; 3]; 4] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
];

fn tet_faces() -> Vec<Vec<u32>> {
    vec![vec![0, 2, 1], vec![0, 1, 3], vec![0, 3, 2], vec![1, 2, 3]]
}

fn tet_positions() -> Vec<DVec3> {
    TET_POSITIONS.iter().map(|&p| DVec3::from(p)).collect()
}

const TET_OBJ: &str = "\
# a tetrahedron
v 0 0 0
v 1 0 0
v 0 1 0
v 0 0 1
f 1 3 2
f 1 2 4
f 1 4 3
f 2 3 4
";

fn cube_faces() -> Vec<Vec<u32>> {
    vec![
        vec![0, 3, 2, 1],
        vec![4, 5, 6, 7],
        vec![0, 1, 5, 4],
        vec![1, 2, 6, 5],
        vec![2, 3, 7, 6],
        vec![3, 0, 4, 7],
    ]
}

fn cube_positions() -> Vec<DVec3> {
    let corners = [
        [0, 0, 0],
        [1, 0, 0],
        [1, 1, 0],
        [0, 1, 0],
        [0, 0, 1],
        [1, 0, 1],
        [1, 1, 1],
        [0, 1, 1],
    ];
    corners
        .iter()
        .map(|c| DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64))
        .collect()
}

const CUBE_OFF: &str = "\
OFF
# a cube of quads
8 6 12
0 0 0
1 0 0
1 1 0
0 1 0
0 0 1
1 0 1
1 1 1
0 1 1
4 0 3 2 1
4 4 5 6 7
4 0 1 5 4
4 1 2 6 5
4 2 3 7 6
4 3 0 4 7
";

/// A square pyramid: a quad base and four triangles.
fn mixed_soup() -> PolygonSoup {
    PolygonSoup {
        positions: vec![
            DVec3::new(0.1, -0.0, 1.0 / 3.0),
            DVec3::new(1e-300, 123_456_789.123_456_79, -2.5e17),
            DVec3::new(5e-324, f64::MAX, f64::MIN_POSITIVE),
            DVec3::new(-0.3, 0.7, std::f64::consts::PI),
            DVec3::new(0.5, 0.5, 1.0 + f64::EPSILON),
        ],
        faces: vec![
            vec![0, 3, 2, 1],
            vec![0, 1, 4],
            vec![1, 2, 4],
            vec![2, 3, 4],
            vec![3, 0, 4],
        ]
        .into(),
        face_lines: Vec::new(),
        vertex_lines: Vec::new(),
    }
}

// ---------------------------------------------------------------------------
// OBJ

#[test]
fn mesh_io_obj_tetrahedron() {
    let soup = obj(TET_OBJ);
    assert_eq!(soup.positions, tet_positions());
    assert_eq!(faces(&soup), tet_faces());
    assert_eq!(soup.vertex_lines, vec![2, 3, 4, 5]);
    assert_eq!(soup.face_lines, vec![6, 7, 8, 9]);
}

#[test]
fn mesh_io_obj_every_index_form_and_ignored_statements() {
    let text = "\
mtllib tet.mtl
o tet

g body
s 1
usemtl red
v 0 0 0
v 1 0 0 1.0
v 0 1 0 0.5 0.25 0.125
v 0 0 1
vt 0 0
vt 1 0
vt 0 1
vn 0 0 1
vp 0.5
f 1 3/2 2//1   # a comment after data
f 1/1/1 2/2/1 4/3/1
l 1 2
p 3
f 1//1 4//1 3//1
f 2/1 3/2 4/3
";
    let soup = obj(text);
    assert_eq!(soup.positions, tet_positions());
    assert_eq!(faces(&soup), tet_faces());
    assert_eq!(soup.face_lines, vec![16, 17, 20, 21]);
}

#[test]
fn mesh_io_obj_negative_indices() {
    let text = "\
v 0 0 0
v 1 0 0
v 0 1 0
f -3 -1 -2
v 0 0 1
f -4 -3 -1
f -4/1 -1/1/1 -2//1
f -3 -2 -1
";
    let soup = obj(text);
    assert_eq!(faces(&soup), tet_faces());
}

#[test]
fn mesh_io_obj_line_continuation_and_crlf() {
    let text = "v 0 0 0\r\nv 1 \\\r\n 0 0\r\nv 0 1 0\r\nv 0 0 1\r\n\
                f 1 3 2\r\nf 1 2 \\\n4\r\nf 1 4 3\r\nf 2 3 4\r\n";
    let soup = obj(text);
    assert_eq!(soup.positions, tet_positions());
    assert_eq!(faces(&soup), tet_faces());
    assert_eq!(soup.vertex_lines, vec![1, 2, 4, 5]);
    assert_eq!(soup.face_lines, vec![6, 7, 9, 10]);
}

// ---------------------------------------------------------------------------
// OFF

#[test]
fn mesh_io_off_cube_of_quads() {
    let soup = off(CUBE_OFF);
    assert_eq!(soup.positions, cube_positions());
    assert_eq!(faces(&soup), cube_faces());
    assert_eq!(soup.vertex_lines[0], 4);
    assert_eq!(soup.face_lines, vec![12, 13, 14, 15, 16, 17]);
}

#[test]
fn mesh_io_off_without_header_and_with_comments() {
    let text = "# no header\n\n4 4 6 # counts\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n\
                3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
    let soup = off(text);
    assert_eq!(soup.positions, tet_positions());
    assert_eq!(faces(&soup), tet_faces());
}

#[test]
fn mesh_io_off_colour_variants_ignore_extra_values() {
    let text = "COFF\n4 4 0\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n\
                0 1 0 0 0 255 255\n0 0 1 9 9 9 255\n\
                3 0 2 1 1.0 0.0 0.0\n3 0 1 3 0 1 0\n3 0 3 2\n3 1 2 3 0.5 0.5 0.5 1\n";
    let soup = off(text);
    assert_eq!(soup.positions, tet_positions());
    assert_eq!(faces(&soup), tet_faces());
    let normals = "NOFF\n4 4 0\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n0 0 1 0 0 1\n\
                   3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
    assert_eq!(faces(&off(normals)), tet_faces());
}

#[test]
fn mesh_io_off_counts_on_the_header_line() {
    let text = "OFF 4 4 6\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
    assert_eq!(faces(&off(text)), tet_faces());
}

// ---------------------------------------------------------------------------
// PLY

const TET_PLY: &str = "\
ply
format ascii 1.0
comment a tetrahedron
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

#[test]
fn mesh_io_ply_ascii_tetrahedron() {
    let soup = ply(TET_PLY.as_bytes());
    assert_eq!(soup.positions, tet_positions());
    assert_eq!(faces(&soup), tet_faces());
    assert_eq!(soup.vertex_lines, vec![11, 12, 13, 14]);
    assert_eq!(soup.face_lines, vec![15, 16, 17, 18]);
}

#[test]
fn mesh_io_ply_ascii_skips_extra_elements_and_properties() {
    let text = "\
ply
format ascii 1.0
obj_info made by hand
element material 2
property uchar red
property list uint8 float32 weights
element vertex 4
property double nx
property float64 z
property int16 id
property double y
property double x
element face 4
property uchar flags
property list uint8 int32 vertex_index
property list uchar float texcoord
element edge 1
property int vertex1
property int vertex2
end_header
255 2 0.5 0.5
0 0
9 0 1 0 0
9 0 2 0 1
9 0 3 1 0
9 1 4 0 0
7 3 0 2 1 6 0 0 1 0 0 1
7 3 0 1 3 0
7 3 0 3 2 0
7 3 1 2 3 2 0.5 0.5
0 1
";
    let soup = ply(text.as_bytes());
    assert_eq!(soup.positions, tet_positions());
    assert_eq!(faces(&soup), tet_faces());
    assert_eq!(soup.face_lines, vec![27, 28, 29, 30]);
}

/// Little-endian binary PLY data.
#[derive(Default)]
struct Bin(Vec<u8>);

impl Bin {
    fn f32(&mut self, v: f32) -> &mut Self {
        self.0.extend(v.to_le_bytes());
        self
    }
    fn f64(&mut self, v: f64) -> &mut Self {
        self.0.extend(v.to_le_bytes());
        self
    }
    fn u8(&mut self, v: u8) -> &mut Self {
        self.0.push(v);
        self
    }
    fn i8(&mut self, v: i8) -> &mut Self {
        self.0.extend(v.to_le_bytes());
        self
    }
    fn u16(&mut self, v: u16) -> &mut Self {
        self.0.extend(v.to_le_bytes());
        self
    }
    fn i32(&mut self, v: i32) -> &mut Self {
        self.0.extend(v.to_le_bytes());
        self
    }
    fn u32(&mut self, v: u32) -> &mut Self {
        self.0.extend(v.to_le_bytes());
        self
    }
}

/// `header` followed by `data`.
fn binary_ply(header: &str, data: &Bin) -> Vec<u8> {
    let mut bytes = header.as_bytes().to_vec();
    bytes.extend(&data.0);
    bytes
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

fn tet_binary_data() -> Bin {
    let mut d = Bin::default();
    for p in TET_POSITIONS {
        d.f32(p[0] as f32).f32(p[1] as f32).f32(p[2] as f32);
    }
    for f in tet_faces() {
        d.u8(f.len() as u8);
        for i in f {
            d.i32(i as i32);
        }
    }
    d
}

#[test]
fn mesh_io_ply_binary_little_endian() {
    let soup = ply(&binary_ply(TET_BIN_HEADER, &tet_binary_data()));
    assert_eq!(soup.positions, tet_positions());
    assert_eq!(faces(&soup), tet_faces());
    assert_eq!(soup.face_lines, vec![0; 4]);
    assert_eq!(soup.vertex_lines, vec![0; 4]);
}

#[test]
fn mesh_io_ply_binary_skips_elements_of_every_type() {
    let header = "\
ply\r
format binary_little_endian 1.0\r
comment CRLF header, extra elements before and after\r
element camera 2\r
property char a\r
property uchar b\r
property short c\r
property ushort d\r
property int e\r
property uint f\r
property float g\r
property double h\r
property list ushort int16 path\r
element vertex 4\r
property uint8 red\r
property float64 x\r
property float64 y\r
property float64 z\r
property list uint8 float32 normal\r
element face 4\r
property list uint32 uint32 vertex_indices\r
property int8 flag\r
element edge 2\r
property int vertex1\r
property int vertex2\r
end_header\r
";
    let mut d = Bin::default();
    for k in 0..2 {
        d.i8(-1).u8(2).0.extend(3i16.to_le_bytes());
        d.u16(4).i32(-5).u32(6).f32(7.5).f64(8.25);
        d.u16(k + 1);
        for _ in 0..=k {
            d.0.extend((-9i16).to_le_bytes());
        }
    }
    for p in TET_POSITIONS {
        d.u8(200).f64(p[0]).f64(p[1]).f64(p[2]);
        d.u8(3).f32(0.0).f32(0.0).f32(1.0);
    }
    for f in tet_faces() {
        d.u32(f.len() as u32);
        for i in f {
            d.u32(i);
        }
        d.i8(-3);
    }
    d.i32(0).i32(1).i32(2).i32(3);
    let soup = ply(&binary_ply(header, &d));
    assert_eq!(soup.positions, tet_positions());
    assert_eq!(faces(&soup), tet_faces());
}

// ---------------------------------------------------------------------------
// Round trips and files

/// Writes `soup` as `format` and reads it back.
fn round_trip(format: Format, soup: &PolygonSoup) -> PolygonSoup {
    let bytes = io::to_bytes(format, soup);
    read("rt", format, &bytes)
}

#[test]
fn mesh_io_round_trips_are_exact() {
    let soup = mixed_soup();
    for format in [Format::Obj, Format::Off, Format::Ply] {
        let back = round_trip(format, &soup);
        assert_eq!(bits(&back), bits(&soup), "{format:?} positions");
        assert_eq!(back.faces, soup.faces, "{format:?} faces");
        assert_eq!(back.face_lines.len(), soup.faces.len());
        assert_eq!(back.vertex_lines.len(), soup.positions.len());
    }
}

#[test]
fn mesh_io_round_trip_of_read_meshes() {
    for soup in [obj(TET_OBJ), off(CUBE_OFF)] {
        for format in [Format::Obj, Format::Off, Format::Ply] {
            let back = round_trip(format, &soup);
            assert_eq!(back.positions, soup.positions);
            assert_eq!(back.faces, soup.faces);
        }
    }
}

#[test]
fn mesh_io_writes_files_atomically_and_reads_them_back() {
    let tmp = scratch("mesh-io-atomic");
    let dir = tmp.path();
    let soup = mixed_soup();
    let names = ["m.obj", "m.OFF", "m.Ply"];
    for name in names {
        let path = dir.join(name);
        io::write(&path, &soup).unwrap_or_else(|e| panic!("{e}"));
        // Writing again replaces the file.
        io::write(&path, &soup).unwrap_or_else(|e| panic!("{e}"));
        let back = io::read(&path).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(bits(&back), bits(&soup), "{name}");
        assert_eq!(back.faces, soup.faces, "{name}");
    }
    let mut left: Vec<String> = std::fs::read_dir(dir)
        .expect("cannot list the scratch directory")
        .map(|e| {
            e.expect("a directory entry")
                .file_name()
                .to_string_lossy()
                .into_owned()
        })
        .collect();
    left.sort();
    assert_eq!(
        left,
        vec!["m.OFF", "m.Ply", "m.obj"],
        "temporary files left"
    );
}

#[test]
fn mesh_io_format_from_path() {
    assert_eq!(Format::from_path(Path::new("a/b.obj")), Some(Format::Obj));
    assert_eq!(Format::from_path(Path::new("B.OFF")), Some(Format::Off));
    assert_eq!(Format::from_path(Path::new("c.pLy")), Some(Format::Ply));
    assert_eq!(Format::from_path(Path::new("d.stl")), None);
    assert_eq!(Format::from_path(Path::new("obj")), None);
}

// ---------------------------------------------------------------------------
// Errors: files

#[test]
fn mesh_io_error_unreadable_file() {
    let tmp = scratch("mesh-io-unreadable");
    let dir = tmp.path();
    let path = dir.join("missing.obj");
    let msg = io::read(&path).expect_err("a missing file").to_string();
    assert_mentions(
        &msg,
        &[&format!("{}: error: cannot read the file", path.display())],
    );
}

#[test]
fn mesh_io_error_unknown_extension() {
    let msg = io::read(Path::new("mesh.stl"))
        .expect_err("stl")
        .to_string();
    assert_mentions(
        &msg,
        &[
            "mesh.stl: error: unknown mesh format `.stl`",
            ".obj, .off or .ply",
        ],
    );
    let msg = io::read(Path::new("mesh"))
        .expect_err("no extension")
        .to_string();
    assert_mentions(
        &msg,
        &[
            "mesh: error: the file name has no extension",
            ".obj, .off or .ply",
        ],
    );
    let msg = io::write(Path::new("out.stl"), &mixed_soup())
        .expect_err("stl")
        .to_string();
    assert_mentions(
        &msg,
        &["out.stl: error: unknown mesh format", ".obj, .off or .ply"],
    );
}

#[test]
fn mesh_io_error_unwritable_file() {
    let tmp = scratch("mesh-io-unwritable");
    let dir = tmp.path();
    let path = dir.join("no/such/dir/m.obj");
    let msg = io::write(&path, &mixed_soup())
        .expect_err("no directory")
        .to_string();
    assert_mentions(
        &msg,
        &[&format!("{}: error: cannot write the file", path.display())],
    );
}

#[test]
fn mesh_io_error_not_utf8() {
    let msg = error("t.obj", Format::Obj, b"v 0 0 0\nv 1 \xff 0\n");
    assert_mentions(&msg, &["t.obj:2:5: error: ", "not UTF-8"]);
    let msg = error("t.off", Format::Off, b"OFF\n1 1 0\n\xfe\n");
    assert_mentions(&msg, &["t.off:3:1: error: ", "not UTF-8"]);
    let mut bytes = TET_PLY.as_bytes().to_vec();
    bytes.extend(b"\xc0\n");
    assert_mentions(&ply_error(&bytes), &["t.ply:19:1: error: ", "not UTF-8"]);
}

// ---------------------------------------------------------------------------
// Errors: numbers and coordinates

#[test]
fn mesh_io_error_malformed_numbers() {
    let msg = obj_error("v 0 0 0\nv 1 abc 0\n");
    assert_mentions(&msg, &["t.obj:2:5: error: expected a number, found `abc`"]);
    let msg = off_error("OFF\n4 4 0\n0 0 0\n1 0 0\n0 1,5 0\n");
    assert_mentions(&msg, &["t.off:5:3: error: expected a number, found `1,5`"]);
    let msg = off_error("OFF\nfour 4 0\n");
    assert_mentions(
        &msg,
        &["t.off:2:1: error: expected the number of vertices, found `four`"],
    );
    let msg = ply_error(TET_PLY.replace("0 0 1\n", "0 0 x1\n").as_bytes());
    assert_mentions(&msg, &["t.ply:14:5: error: expected a number, found `x1`"]);
    let msg = obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 three\n");
    assert_mentions(
        &msg,
        &["t.obj:4:7: error: expected a vertex index, found `three`"],
    );
    let msg = obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 /3\n");
    assert_mentions(
        &msg,
        &["t.obj:4:7: error: expected a vertex index, found ``"],
    );
    let msg = off_error("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2.5\n");
    assert_mentions(
        &msg,
        &["t.off:6:7: error: expected a vertex index, found `2.5`"],
    );
}

#[test]
fn mesh_io_error_too_few_coordinates() {
    let msg = obj_error("v 0 0 0\n\nv 1 2\n");
    assert_mentions(
        &msg,
        &["t.obj:3:1: error: a vertex needs 3 coordinates (x y z), found 2"],
    );
    let msg = off_error("OFF\n3 1 0\n0 0 0\n1 0\n0 1 0\n3 0 1 2\n");
    assert_mentions(&msg, &["t.off:4:1: error: a vertex needs 3 coordinates"]);
}

#[test]
fn mesh_io_error_non_finite_coordinates() {
    let msg = obj_error("v 0 0 0\nv 1 0 0\nv 0 nan 0\nf 1 2 3\n");
    assert_mentions(
        &msg,
        &["t.obj:3:5: error: vertex 3 has a non-finite coordinate"],
    );
    let msg = obj_error("v 0 0 0\nv 1 0 1e999\nv 0 1 0\nf 1 2 3\n");
    assert_mentions(
        &msg,
        &["t.obj:2:7: error: vertex 2 has a non-finite coordinate"],
    );
    let msg = off_error("OFF\n3 1 0\n0 0 0\n1 0 0\ninf 1 0\n3 0 1 2\n");
    assert_mentions(
        &msg,
        &["t.off:5:1: error: vertex 2 has a non-finite coordinate"],
    );
    let mut d = tet_binary_data();
    d.0[4..8].copy_from_slice(&f32::NAN.to_le_bytes());
    let msg = ply_error(&binary_ply(TET_BIN_HEADER, &d));
    assert_mentions(
        &msg,
        &["t.ply: error: vertex 0 has a non-finite coordinate"],
    );
}

// ---------------------------------------------------------------------------
// Errors: faces

#[test]
fn mesh_io_error_face_with_fewer_than_three_vertices() {
    let msg = obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2\n");
    assert_mentions(
        &msg,
        &["t.obj:5:1: error: face 2 has 2 vertices, but a face needs at least 3"],
    );
    let msg = off_error("OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n2 0 1\n");
    assert_mentions(&msg, &["t.off:7:1: error: face 1 has 2 vertices"]);
    let text = TET_PLY.replace("3 0 3 2\n", "0\n");
    assert_mentions(
        &ply_error(text.as_bytes()),
        &["t.ply:17:1: error: face 2 has 0 vertices"],
    );
}

#[test]
fn mesh_io_error_out_of_range_indices() {
    let cube = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n";
    let text = format!("{cube}f 1 2 3 4\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 12 7\n");
    let msg = obj_error(&text);
    assert_mentions(
        &msg,
        &["t.obj:13:7: error: face 5 refers to vertex 12, but there are only 8 vertices"],
    );
    let msg = obj_error(&format!("{cube}f 1 2 3\nf 0 1 2\n"));
    assert_mentions(
        &msg,
        &["t.obj:10:3: error: face 2 refers to vertex 0, but OBJ indices start at 1"],
    );
    let msg = obj_error(&format!("v 0 0 0\nv 1 0 0\nf -1 -2 -3\n{cube}"));
    assert_mentions(
        &msg,
        &["t.obj:3:9: error: face 1 refers to vertex -3, but only 2 vertices precede it"],
    );
    let msg = off_error(&CUBE_OFF.replace("4 2 3 7 6", "4 2 3 8 6"));
    assert_mentions(
        &msg,
        &["t.off:16:7: error: face 4 refers to vertex 8, but there are only 8 vertices"],
    );
    let msg = off_error(&CUBE_OFF.replace("4 2 3 7 6", "4 2 3 -1 6"));
    assert_mentions(
        &msg,
        &["t.off:16:7: error: face 4 refers to vertex -1, but there are only 8 vertices"],
    );
    let msg = ply_error(TET_PLY.replace("3 1 2 3\n", "3 1 2 4\n").as_bytes());
    assert_mentions(
        &msg,
        &["t.ply:18:7: error: face 3 refers to vertex 4, but there are only 4 vertices"],
    );
    let mut d = tet_binary_data();
    let len = d.0.len();
    d.0[len - 4..].copy_from_slice(&(-7i32).to_le_bytes());
    let msg = ply_error(&binary_ply(TET_BIN_HEADER, &d));
    assert_mentions(
        &msg,
        &["t.ply: error: face 3 refers to vertex -7, but there are only 4 vertices"],
    );
}

#[test]
fn mesh_io_error_repeated_vertex() {
    let msg = obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n# next\nf 1 2 2\n");
    assert_mentions(
        &msg,
        &["t.obj:6:7: error: face 2 repeats vertex 2 (a degenerate face)"],
    );
    let msg = obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 3 -1\n");
    assert_mentions(&msg, &["t.obj:4:7: error: face 1 repeats vertex 3"]);
    let msg = off_error(&CUBE_OFF.replace("4 4 5 6 7", "4 4 5 4 7"));
    assert_mentions(&msg, &["t.off:13:7: error: face 1 repeats vertex 4"]);
    let msg = ply_error(TET_PLY.replace("3 0 1 3\n", "3 0 1 0\n").as_bytes());
    assert_mentions(&msg, &["t.ply:16:7: error: face 1 repeats vertex 0"]);
}

#[test]
fn mesh_io_error_empty_mesh() {
    let msg = obj_error("v 0 0 0\nv 1 0 0\nv 0 1 0\n");
    assert_mentions(&msg, &["t.obj: error: the mesh has no faces"]);
    assert_mentions(&obj_error(""), &["t.obj: error: the mesh has no faces"]);
    let msg = off_error("OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n");
    assert_mentions(&msg, &["t.off: error: the mesh has no faces"]);
    let header = TET_PLY.replace("element face 4", "element face 0");
    let header = &header[..header.find("end_header\n").map_or(0, |i| i + 11)];
    let text = format!("{header}0 0 0\n1 0 0\n0 1 0\n0 0 1\n");
    assert_mentions(
        &ply_error(text.as_bytes()),
        &["t.ply: error: the mesh has no faces"],
    );
}

// ---------------------------------------------------------------------------
// Errors: counts and structure

#[test]
fn mesh_io_error_off_counts() {
    let msg = off_error("OFF\n8 6 12\n0 0 0\n1 0 0\n");
    assert_mentions(
        &msg,
        &["t.off:4:6: error: the file ends after 2 of the 8 declared vertices"],
    );
    let cut = CUBE_OFF.replace("4 3 0 4 7\n", "");
    assert_mentions(
        &off_error(&cut),
        &["t.off:16:10: error: the file ends after 5 of the 6 declared faces"],
    );
    let more = format!("{CUBE_OFF}3 0 1 2\n");
    assert_mentions(
        &off_error(&more),
        &["t.off:18:1: error: unexpected `3 0 1 2` after the 6 declared faces"],
    );
    let short = CUBE_OFF.replace("4 0 1 5 4", "4 0 1 5");
    assert_mentions(
        &off_error(&short),
        &["t.off:14:1: error: face 2 declares 4 vertices but lists 3"],
    );
    assert_mentions(
        &off_error("OFF\n"),
        &["t.off:1:4: error: the file ends: expected the counts line"],
    );
    assert_mentions(
        &off_error("# only a comment\n"),
        &["t.off:1:17: error: the file is empty"],
    );
    assert_mentions(
        &off_error("OFF\n8\n"),
        &["t.off:2:1: error: expected the counts line"],
    );
    assert_mentions(
        &off_error("PLY\n1 1 0\n"),
        &["t.off:1:1: error: expected an `OFF` header or the counts line, found `PLY`"],
    );
    assert_mentions(
        &off_error("4OFF\n1 1 0\n"),
        &["t.off:1:1: error: 4OFF", "not supported"],
    );
    assert_mentions(
        &off_error("OFF BINARY\n"),
        &["t.off:1:5: error: binary OFF is not supported"],
    );
}

#[test]
fn mesh_io_error_ply_counts() {
    let cut = TET_PLY.replace("3 1 2 3\n", "");
    assert_mentions(
        &ply_error(cut.as_bytes()),
        &["t.ply:17:8: error: the file ends after 3 of the 4 declared `face` elements"],
    );
    let cut = TET_PLY.replace("3 1 2 3\n", "3 1 2\n");
    assert_mentions(
        &ply_error(cut.as_bytes()),
        &["t.ply:18:6: error: the file ends after 3 of the 4 declared `face` elements"],
    );
    let more = format!("{TET_PLY}3 0 1 2\n");
    assert_mentions(
        &ply_error(more.as_bytes()),
        &["t.ply:19:1: error: unexpected `3` after the declared elements"],
    );
    // Binary data that ends early is refused at the count in the header.
    let bytes = binary_ply(TET_BIN_HEADER, &tet_binary_data());
    for cut in [bytes.len() - 1, bytes.len() - 17] {
        let msg = ply_error(&bytes[..cut]);
        assert_mentions(
            &msg,
            &[
                "t.ply:7:14: error: the binary data ends after",
                "7 | element face 4\n  |              ^",
            ],
        );
    }
    let msg = ply_error(&bytes[..bytes.len() - 1]);
    assert_mentions(&msg, &["ends after 3 of the 4 declared `face` elements"]);
    let msg = ply_error(&bytes[..TET_BIN_HEADER.len() + 20]);
    assert_mentions(
        &msg,
        &["t.ply:3:16: error: the binary data ends after 1 of the 4 declared `vertex` elements"],
    );
}

#[test]
fn mesh_io_error_ply_header() {
    let big = TET_PLY.replace("format ascii 1.0", "format binary_big_endian 1.0");
    assert_mentions(
        &ply_error(big.as_bytes()),
        &["t.ply:2:8: error: big-endian binary PLY is not supported"],
    );
    assert_mentions(
        &ply_error(b"solid cube\n"),
        &["t.ply:1:1: error: not a PLY file"],
    );
    assert_mentions(&ply_error(b""), &["t.ply:1:1: error: the file is empty"]);
    let no_end = &TET_PLY[..TET_PLY.find("end_header").unwrap_or(0)];
    assert_mentions(
        &ply_error(no_end.as_bytes()),
        &["t.ply:9:39: error: the header ends without an `end_header` line"],
    );
    let no_format = TET_PLY.replace("format ascii 1.0\n", "");
    assert_mentions(
        &ply_error(no_format.as_bytes()),
        &["t.ply:9:1: error: the PLY header has no `format` line"],
    );
    let weird = TET_PLY.replace("format ascii 1.0", "format utf16 1.0");
    assert_mentions(
        &ply_error(weird.as_bytes()),
        &["t.ply:2:8: error: unknown PLY format `utf16`"],
    );
    let no_z = TET_PLY.replace("property float z\n", "");
    assert_mentions(
        &ply_error(no_z.as_bytes()),
        &["t.ply:4:9: error: the `vertex` element has no `z` property"],
    );
    let bad_type = TET_PLY.replace("property float y", "property real y");
    assert_mentions(
        &ply_error(bad_type.as_bytes()),
        &["t.ply:6:10: error: unknown PLY property type `real`"],
    );
    let no_list = TET_PLY.replace("vertex_indices", "corners");
    assert_mentions(
        &ply_error(no_list.as_bytes()),
        &["t.ply:8:9: error: the `face` element has no `vertex_indices` list property"],
    );
    let float_list = TET_PLY.replace("uchar int vertex", "uchar float vertex");
    assert_mentions(
        &ply_error(float_list.as_bytes()),
        &["t.ply:8:9: error: ", "must be a list of integers"],
    );
    let early = TET_PLY.replace("comment a tetrahedron", "property float w");
    assert_mentions(
        &ply_error(early.as_bytes()),
        &["t.ply:3:1: error: a `property` line before any `element`"],
    );
    let bad_count = TET_PLY.replace("element face 4", "element face four");
    assert_mentions(
        &ply_error(bad_count.as_bytes()),
        &["t.ply:8:14: error: expected the number of `face` elements, found `four`"],
    );
    let unknown = TET_PLY.replace("comment a tetrahedron", "colour red");
    assert_mentions(
        &ply_error(unknown.as_bytes()),
        &["t.ply:3:1: error: unknown PLY header line `colour`"],
    );
    let no_vertex = "ply\nformat ascii 1.0\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n";
    assert_mentions(
        &ply_error(no_vertex.as_bytes()),
        &["t.ply:5:1: error: the PLY header declares no `vertex` element"],
    );
    let bad_len = TET_PLY.replace("3 0 3 2\n", "2.5 0 3 2\n");
    assert_mentions(
        &ply_error(bad_len.as_bytes()),
        &["t.ply:17:1: error: a list length must be a whole number, found 2.5"],
    );
}
