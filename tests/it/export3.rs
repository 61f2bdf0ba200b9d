//! Exporting 3D scenes (`subgram::export`): OBJ+MTL and PLY read back by
//! subgram's own mesh reader and by a parser here, GLB's container,
//! JSON and binary chunk checked against the glTF 2.0 specification's
//! layout rules, refusals, atomic writes, and `subdivide -o x.glb`.

use std::path::Path;

use glam::Vec3;
use serde_json::Value;
use subgram::export::{glb_bytes, obj_text, write, write_glb, write_obj, write_ply};
use subgram::scene3::{Look, Scene3, TriMesh};

use crate::support::scratch;

/// A tetrahedron with unit vertex normals (look 0) and a quad without
/// normals (look 1, with a specular part and a name with a space).
fn two_looks() -> Scene3 {
    let tet = [
        Vec3::new(1.0, 1.0, 1.0),
        Vec3::new(1.0, -1.0, -1.0),
        Vec3::new(-1.0, 1.0, -1.0),
        Vec3::new(-1.0, -1.0, 1.0),
    ];
    let mut shiny = Look::colour("petal pink", 7, [230, 120, 160]);
    shiny.specular = [0.5, 0.5, 0.5];
    shiny.shininess = 30.0;
    Scene3 {
        looks: vec![Look::colour("colour2", 2, [40, 160, 60]), shiny],
        meshes: vec![
            TriMesh {
                positions: tet.to_vec(),
                normals: tet.iter().map(|p| p.normalize()).collect(),
                triangles: vec![[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]],
                lines: Vec::new(),
            },
            TriMesh {
                positions: vec![
                    Vec3::new(2.0, 0.0, 0.0),
                    Vec3::new(3.0, 0.0, 0.0),
                    Vec3::new(3.0, 0.5, 2.5),
                    Vec3::new(2.0, 0.5, 2.5),
                ],
                normals: Vec::new(),
                triangles: vec![[0, 1, 2], [0, 2, 3]],
                lines: Vec::new(),
            },
        ],
    }
}

/// Every vertex of the scene in order, and every triangle with indices
/// into that list.
fn flat(scene: &Scene3) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let mut ps = Vec::new();
    let mut ts = Vec::new();
    for m in &scene.meshes {
        let base = ps.len() as u32;
        ps.extend(&m.positions);
        ts.extend(m.triangles.iter().map(|t| t.map(|i| i + base)));
    }
    (ps, ts)
}

#[test]
fn obj_and_mtl_hold_the_geometry_and_the_looks() {
    let sc = two_looks();
    let (ps, ts) = flat(&sc);
    let tmp = scratch("export3-two-obj");
    let path = tmp.path().join("two.obj");
    write_obj(&sc, &path).expect("writes");
    // subgram's own reader: the same vertices and triangles.
    let soup = subgram::mesh::io::read(&path).expect("reads back");
    assert_eq!(soup.positions.len(), ps.len());
    for (a, b) in soup.positions.iter().zip(&ps) {
        assert_eq!(a.as_vec3(), *b);
    }
    let faces: Vec<Vec<u32>> = soup.faces.iter().map(|f| f.to_vec()).collect();
    assert_eq!(faces, ts.iter().map(|t| t.to_vec()).collect::<Vec<_>>());
    // Parsed here: a `usemtl` per look before its faces, `vn` for the
    // mesh with normals, `a//a` references there.
    let text = std::fs::read_to_string(&path).expect("text");
    assert!(text.contains("mtllib two.mtl"));
    let usemtl: Vec<&str> = text
        .lines()
        .filter_map(|l| l.strip_prefix("usemtl "))
        .collect();
    assert_eq!(usemtl, ["colour2", "petal_pink"]);
    assert_eq!(text.lines().filter(|l| l.starts_with("vn ")).count(), 4);
    assert!(text.contains("f 1//1 2//2 3//3"));
    assert!(text.contains("f 5 6 7"));
    // The MTL: the looks' colours.
    let mtl = std::fs::read_to_string(path.with_extension("mtl")).expect("the mtl");
    let block = mtl.split("newmtl petal_pink").nth(1).expect("the petal");
    let kd: Vec<f32> = block
        .lines()
        .find_map(|l| l.strip_prefix("Kd "))
        .expect("Kd")
        .split_whitespace()
        .map(|v| v.parse().expect("a number"))
        .collect();
    assert_eq!(kd, [230.0 / 255.0, 120.0 / 255.0, 160.0 / 255.0]);
    assert!(block.contains("Ns 30"));
    // `obj_text` is what the file holds.
    assert_eq!(obj_text(&sc, "two.mtl").0, text);
}

#[test]
fn ply_holds_positions_and_a_colour_per_vertex() {
    let sc = two_looks();
    let (ps, ts) = flat(&sc);
    let tmp = scratch("export3-two-ply");
    let path = tmp.path().join("two.ply");
    write_ply(&sc, &path).expect("writes");
    let soup = subgram::mesh::io::read(&path).expect("reads back");
    assert_eq!(soup.positions.len(), ps.len());
    for (a, b) in soup.positions.iter().zip(&ps) {
        assert_eq!(a.as_vec3(), *b);
    }
    assert_eq!(soup.faces.len(), ts.len());
    // Parsed here: the header, then x y z as floats and r g b as bytes
    // per vertex (no normals, as one mesh has none).
    let bytes = std::fs::read(&path).expect("bytes");
    let end = b"end_header\n";
    let at = bytes
        .windows(end.len())
        .position(|w| w == end)
        .expect("a header")
        + end.len();
    let header = std::str::from_utf8(&bytes[..at]).expect("text");
    assert!(header.contains("format binary_little_endian 1.0"));
    assert!(header.contains("element vertex 8\n"));
    assert!(header.contains("element face 6\n"));
    assert!(!header.contains("nx"));
    let stride = 12 + 3;
    for (k, p) in ps.iter().enumerate() {
        let v = &bytes[at + k * stride..at + (k + 1) * stride];
        let f = |i: usize| f32::from_le_bytes(v[i * 4..i * 4 + 4].try_into().expect("4 bytes"));
        assert_eq!(Vec3::new(f(0), f(1), f(2)), *p);
        let want: [u8; 3] = if k < 4 {
            [40, 160, 60]
        } else {
            [230, 120, 160]
        };
        assert_eq!(&v[12..15], &want);
    }
    let faces = at + ps.len() * stride;
    assert_eq!(bytes.len(), faces + ts.len() * 13);
}

/// The GLB's JSON and binary chunks, after checking the container:
/// magic, version 2, total length, chunk types, 4-byte padding.
fn chunks(bytes: &[u8]) -> (Value, Vec<u8>) {
    let u32_at = |i: usize| u32::from_le_bytes(bytes[i..i + 4].try_into().expect("4 bytes"));
    assert_eq!(&bytes[0..4], b"glTF");
    assert_eq!(u32_at(4), 2);
    assert_eq!(u32_at(8) as usize, bytes.len());
    let json_len = u32_at(12) as usize;
    assert_eq!(&bytes[16..20], b"JSON");
    assert_eq!(json_len % 4, 0);
    let json: Value = serde_json::from_slice(&bytes[20..20 + json_len]).expect("JSON");
    let bin_at = 20 + json_len;
    let bin_len = u32_at(bin_at) as usize;
    assert_eq!(&bytes[bin_at + 4..bin_at + 8], b"BIN\0");
    assert_eq!(bin_len % 4, 0);
    assert_eq!(bin_at + 8 + bin_len, bytes.len());
    (json, bytes[bin_at + 8..].to_vec())
}

fn floats(bin: &[u8], offset: usize, count: usize) -> Vec<f32> {
    (0..count)
        .map(|k| {
            f32::from_le_bytes(
                bin[offset + 4 * k..offset + 4 * k + 4]
                    .try_into()
                    .expect("4"),
            )
        })
        .collect()
}

#[test]
fn glb_follows_the_gltf_layout_and_holds_the_scene() {
    let sc = two_looks();
    let bytes = glb_bytes(&sc).expect("exports");
    let (doc, bin) = chunks(&bytes);
    assert_eq!(doc["asset"]["version"], "2.0");
    assert_eq!(
        doc["buffers"][0]["byteLength"].as_u64(),
        Some(bin.len() as u64)
    );
    let views = doc["bufferViews"].as_array().expect("views");
    for v in views {
        let (off, len) = (
            v["byteOffset"].as_u64().expect("offset") as usize,
            v["byteLength"].as_u64().expect("length") as usize,
        );
        assert_eq!(off % 4, 0, "aligned view");
        assert!(off + len <= bin.len());
    }
    let prims = doc["meshes"][0]["primitives"]
        .as_array()
        .expect("primitives");
    assert_eq!(prims.len(), 2, "one primitive per look");
    let acc = |i: &Value| &doc["accessors"][i.as_u64().expect("index") as usize];
    let view_of = |a: &Value| &views[a["bufferView"].as_u64().expect("view") as usize];
    for (k, (p, m)) in prims.iter().zip(&sc.meshes).enumerate() {
        assert_eq!(p["mode"], 4);
        assert_eq!(p["material"].as_u64(), Some(k as u64));
        let pos = acc(&p["attributes"]["POSITION"]);
        assert_eq!(pos["componentType"], 5126);
        assert_eq!(pos["type"], "VEC3");
        assert_eq!(pos["count"].as_u64(), Some(m.positions.len() as u64));
        // min and max are the positions' bounds, computed here.
        let (lo, hi) = m.positions.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(*p), hi.max(*p)),
        );
        let arr = |v: &Value| -> Vec<f32> {
            v.as_array()
                .expect("array")
                .iter()
                .map(|x| x.as_f64().expect("number") as f32)
                .collect()
        };
        assert_eq!(arr(&pos["min"]), lo.to_array());
        assert_eq!(arr(&pos["max"]), hi.to_array());
        let pv = view_of(pos);
        assert_eq!(
            pv["byteLength"].as_u64(),
            Some(12 * m.positions.len() as u64)
        );
        let stored = floats(
            &bin,
            pv["byteOffset"].as_u64().expect("offset") as usize,
            3 * m.positions.len(),
        );
        let want: Vec<f32> = m.positions.iter().flat_map(|p| p.to_array()).collect();
        assert_eq!(stored, want);
        // Normals only where the mesh has them.
        assert_eq!(
            p["attributes"].get("NORMAL").is_some(),
            !m.normals.is_empty()
        );
        let ind = acc(&p["indices"]);
        assert_eq!(ind["componentType"], 5125);
        assert_eq!(ind["type"], "SCALAR");
        assert_eq!(ind["count"].as_u64(), Some(3 * m.triangles.len() as u64));
        let iv = view_of(ind);
        assert_eq!(iv["target"], 34963);
        let off = iv["byteOffset"].as_u64().expect("offset") as usize;
        let idx: Vec<u32> = (0..3 * m.triangles.len())
            .map(|k| u32::from_le_bytes(bin[off + 4 * k..off + 4 * k + 4].try_into().expect("4")))
            .collect();
        assert_eq!(
            idx,
            m.triangles.iter().flatten().copied().collect::<Vec<_>>()
        );
    }
    let pink = &doc["materials"][1];
    assert_eq!(pink["name"], "petal_pink");
    let base: Vec<f64> = pink["pbrMetallicRoughness"]["baseColorFactor"]
        .as_array()
        .expect("colour")
        .iter()
        .map(|v| v.as_f64().expect("number"))
        .collect();
    let want = [230.0 / 255.0, 120.0 / 255.0, 160.0 / 255.0, 1.0];
    for (a, b) in base.iter().zip(want) {
        assert!((a - b).abs() < 1e-6);
    }
    assert_eq!(pink["doubleSided"], true);
    // Written atomically to the named file.
    let tmp = scratch("export3-two-glb");
    let path = tmp.path().join("two.glb");
    write_glb(&sc, &path).expect("writes");
    assert_eq!(std::fs::read(&path).expect("bytes"), bytes);
}

#[test]
fn exports_refuse_bad_scenes_and_leave_no_file() {
    let tmp = scratch("export3-refusals");
    let dir = tmp.path();
    let mut nan = two_looks();
    nan.meshes[1].positions[2].z = f32::NAN;
    for (scene, what) in [(Scene3::default(), "no triangle"), (nan, "non-finite")] {
        for name in ["x.obj", "x.ply", "x.glb"] {
            let path = dir.join(name);
            let e = write(&scene, &path).expect_err("refused").to_string();
            assert!(e.contains(what), "{name}: {e}");
            assert!(!path.exists());
        }
    }
    assert!(!dir.join("x.mtl").exists());
    // An unwritable place: an error naming the file, nothing left.
    let missing = dir.join("no-such-folder").join("x.glb");
    let e = write(&two_looks(), &missing)
        .expect_err("refused")
        .to_string();
    assert!(e.contains("x.glb"), "{e}");
    let e = write(&two_looks(), &dir.join("no-such-folder").join("x.obj"))
        .expect_err("refused")
        .to_string();
    assert!(e.contains("x."), "{e}");
    assert!(std::fs::read_dir(dir).expect("the folder").next().is_none());
    assert!(write(&two_looks(), Path::new("x.stl")).is_err());
}

#[test]
fn subdivide_writes_a_glb() {
    let tmp = scratch("export3-cube-glb");
    let out = tmp.path().join("cube.glb");
    let root = crate::support::root();
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_subgram"))
        .args(["subdivide", "--grammar"])
        .arg(root.join("lsystems/surfaces/catmull-clark.lsys"))
        .arg(root.join("lsystems/meshes/cube.obj"))
        .args(["-n", "1", "-o"])
        .arg(&out)
        .output()
        .expect("the binary runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (doc, _) = chunks(&std::fs::read(&out).expect("written"));
    // One Catmull-Clark step on a cube: 24 quads, fanned into 48
    // triangles, over 26 vertices (8 corners, 12 edge points, 6 face
    // points).
    let prim = &doc["meshes"][0]["primitives"][0];
    let count = |k: &Value| doc["accessors"][k.as_u64().expect("index") as usize]["count"].as_u64();
    assert_eq!(count(&prim["indices"]), Some(48 * 3));
    assert_eq!(count(&prim["attributes"]["POSITION"]), Some(26));
}
