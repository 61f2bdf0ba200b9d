//! Shaded 3D geometry ([`Scene3`]) to files other programs read: Wavefront
//! OBJ with its MTL (one `usemtl` per look, `vn` where a mesh has
//! normals), PLY (binary little-endian, a colour per vertex from its
//! look's diffuse colour) and binary glTF 2.0 (`.glb`: one mesh with one
//! triangle primitive per look, each with a metallic-roughness material
//! made from the look). Every file is written atomically, an OBJ and its
//! MTL both or neither.
//!
//! The glTF JSON is written with `serde_json` by hand rather than through
//! a glTF crate: the document is a dozen fixed objects, and the layout
//! rules the Khronos validator checks (4-byte aligned chunks and buffer
//! views, `byteLength`s, `min`/`max` of every `POSITION` accessor, unit
//! normals) are easier to see here than behind a crate's builder.

use std::io::Write;
use std::path::Path;

use glam::Vec3;
use serde_json::{json, Value};

use crate::error::Error;
use crate::render::raster::validate;
use crate::scene3::{Look, Scene3};

/// The formats a scene is exported to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Obj,
    Ply,
    Glb,
}

impl Format {
    /// By the path's extension (`.obj`, `.ply`, `.glb`, any case).
    pub fn from_path(path: &Path) -> Option<Format> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "obj" => Some(Format::Obj),
            "ply" => Some(Format::Ply),
            "glb" => Some(Format::Glb),
            _ => None,
        }
    }
}

/// Writes `scene` in the format of `path`'s extension (an OBJ with its MTL
/// beside it, same name, `.mtl`).
pub fn write(scene: &Scene3, path: &Path) -> Result<(), Error> {
    match Format::from_path(path) {
        Some(Format::Obj) => write_obj(scene, path),
        Some(Format::Ply) => write_ply(scene, path),
        Some(Format::Glb) => write_glb(scene, path),
        None => Err(Error::Usage(format!(
            "{}: unknown 3D format: expected a file ending in .obj, .ply or .glb",
            path.display()
        ))),
    }
}

/// Refuses a scene that cannot be exported: no triangle, non-finite
/// coordinates, indices out of range (the renderer's checks), or lines,
/// which only a picture's geometry has.
fn check(scene: &Scene3) -> Result<(), Error> {
    let lines = scene.line_count();
    if lines > 0 {
        return Err(Error::Failed(format!(
            "cannot export the scene: it has {lines} lines, the thin tubes of a picture's geometry; make the geometry without `picture_pixel` to export it"
        )));
    }
    validate(scene).map_err(|e| Error::Failed(format!("cannot export the scene: {e}")))
}

/// The looks' names made fit for OBJ, MTL and glTF: no white space, and
/// unique (a repeated name gets `-2`, `-3`, …).
fn names(looks: &[Look]) -> Vec<String> {
    let mut out: Vec<String> = Vec::with_capacity(looks.len());
    for (k, l) in looks.iter().enumerate() {
        let base: String = if l.name.trim().is_empty() {
            format!("look{k}")
        } else {
            l.name
                .chars()
                .map(|c| if c.is_whitespace() { '_' } else { c })
                .collect()
        };
        let mut name = base.clone();
        let mut n = 2;
        while out.contains(&name) {
            name = format!("{base}-{n}");
            n += 1;
        }
        out.push(name);
    }
    out
}

/// The OBJ text (with `mtllib mtl_name`) and the MTL text of `scene`.
/// Vertices are numbered over all meshes in order; a mesh with normals
/// writes `f a//a …`, one without `f a b c`.
pub fn obj_text(scene: &Scene3, mtl_name: &str) -> (String, String) {
    use std::fmt::Write as _;
    let names = names(&scene.looks);
    let mut obj = String::new();
    let _ = writeln!(
        obj,
        "# subgram: {} vertices, {} triangles, {} looks\nmtllib {mtl_name}",
        scene.vertex_count(),
        scene.triangle_count(),
        scene.looks.len()
    );
    let mut base = 1usize;
    for (m, name) in scene.meshes.iter().zip(&names) {
        if m.triangles.is_empty() && m.positions.is_empty() {
            continue;
        }
        let _ = writeln!(obj, "o {name}\nusemtl {name}");
        for p in &m.positions {
            let _ = writeln!(obj, "v {} {} {}", p.x, p.y, p.z);
        }
        for n in &m.normals {
            let _ = writeln!(obj, "vn {} {} {}", n.x, n.y, n.z);
        }
        let smooth = !m.normals.is_empty();
        for t in &m.triangles {
            let [a, b, c] = t.map(|i| i as usize + base);
            if smooth {
                let _ = writeln!(obj, "f {a}//{a} {b}//{b} {c}//{c}");
            } else {
                let _ = writeln!(obj, "f {a} {b} {c}");
            }
        }
        base += m.positions.len();
    }
    let mut mtl = String::from("# subgram: one material per look\n");
    for (l, name) in scene.looks.iter().zip(&names) {
        let rgb = |c: [f32; 3]| format!("{} {} {}", c[0], c[1], c[2]);
        let _ = writeln!(
            mtl,
            "\nnewmtl {name}\nKa {}\nKd {}\nKs {}\nKe {}\nNs {}\nd {}\nillum 2",
            rgb(l.ambient),
            rgb(l.diffuse),
            rgb(l.specular),
            rgb(l.emission),
            l.shininess,
            l.opacity
        );
    }
    (obj, mtl)
}

/// Writes `scene` as `path` (OBJ) and the MTL beside it (`.mtl`), both or
/// neither.
pub fn write_obj(scene: &Scene3, path: &Path) -> Result<(), Error> {
    check(scene)?;
    let mtl = path.with_extension("mtl");
    let mtl_name = mtl
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "scene.mtl".into());
    let (obj, mtl_text) = obj_text(scene, &mtl_name);
    crate::files::atomic::write_all_atomic(&[(path, obj.as_bytes()), (&mtl, mtl_text.as_bytes())])
        .map_err(|(p, e)| Error::write(p, e))
}

/// The byte of a colour channel 0..=1.
fn byte(v: f32) -> u8 {
    (v.clamp(0.0, 1.0) * 255.0).round() as u8
}

/// Writes the binary little-endian PLY of `scene` to `w`: `x y z` as
/// floats, `nx ny nz` when every mesh has normals, `red green blue` as
/// bytes (the look's diffuse colour), then the triangles as lists of
/// `uint` indices into the vertices of all meshes in order.
pub fn write_ply_to(scene: &Scene3, w: &mut dyn Write) -> std::io::Result<()> {
    let normals = scene
        .meshes
        .iter()
        .all(|m| m.positions.is_empty() || !m.normals.is_empty());
    write!(
        w,
        "ply\nformat binary_little_endian 1.0\ncomment subgram: {} looks, colours from their \
         diffuse\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\n",
        scene.looks.len(),
        scene.vertex_count()
    )?;
    if normals {
        w.write_all(b"property float nx\nproperty float ny\nproperty float nz\n")?;
    }
    write!(
        w,
        "property uchar red\nproperty uchar green\nproperty uchar blue\nelement face {}\n\
         property list uchar uint vertex_indices\nend_header\n",
        scene.triangle_count()
    )?;
    for (m, l) in scene.meshes.iter().zip(&scene.looks) {
        let rgb = l.diffuse.map(byte);
        for (k, p) in m.positions.iter().enumerate() {
            for v in p.to_array() {
                w.write_all(&v.to_le_bytes())?;
            }
            if normals {
                for v in m.normals[k].to_array() {
                    w.write_all(&v.to_le_bytes())?;
                }
            }
            w.write_all(&rgb)?;
        }
    }
    let mut base = 0u32;
    for m in &scene.meshes {
        for t in &m.triangles {
            w.write_all(&[3])?;
            for i in t {
                w.write_all(&(i + base).to_le_bytes())?;
            }
        }
        base += m.positions.len() as u32;
    }
    Ok(())
}

/// Writes `scene` as a binary PLY file (see [`write_ply_to`]).
pub fn write_ply(scene: &Scene3, path: &Path) -> Result<(), Error> {
    check(scene)?;
    if scene.vertex_count() > u32::MAX as usize {
        return Err(Error::Failed(
            "cannot export the scene: PLY's uint indices hold at most 4294967295 vertices".into(),
        ));
    }
    crate::files::atomic::write_atomic_with(path, |w| write_ply_to(scene, w))
        .map_err(|e| Error::write(path, e))
}

/// glTF's component types and targets.
const FLOAT: u32 = 5126;
const UNSIGNED_INT: u32 = 5125;
const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;
const TRIANGLES: u32 = 4;
const LINES: u32 = 1;

/// The binary glTF 2.0 of `scene`: a 12-byte header, a JSON chunk padded
/// with spaces and a BIN chunk padded with zeros to 4 bytes. One node
/// holds one mesh whose primitives are the looks with triangles, each with
/// `POSITION` (with its `min` and `max`), `NORMAL` where the mesh has unit
/// normals, `u32` indices and a material: base colour the look's diffuse
/// and opacity, emissive its emission, not metallic, roughness
/// `sqrt(2 / (shininess + 2))` (the usual match of a Blinn-Phong exponent),
/// double-sided as lpfg lights both sides.
pub fn glb_bytes(scene: &Scene3) -> Result<Vec<u8>, Error> {
    glb_bytes_with_edges(scene, &[])
}

/// [`glb_bytes`], with each mesh's `edges` (in its own numbering, as
/// `render::mesh::soup_scene3_edges` gives them) as a second primitive of
/// mode `LINES` over the same positions, with the material of the
/// triangles: a mesh's polygon edges, for a viewer's wireframe. A mesh
/// without edges, or past the end of `edges`, has none.
pub fn glb_bytes_with_edges(scene: &Scene3, edges: &[Vec<[u32; 2]>]) -> Result<Vec<u8>, Error> {
    check(scene)?;
    if let Some((k, e)) = edges.iter().enumerate().find(|(k, e)| {
        let n = scene.meshes.get(*k).map_or(0, |m| m.positions.len()) as u32;
        e.iter().flatten().any(|&i| i >= n)
    }) {
        return Err(Error::Failed(format!(
            "cannot export the scene: mesh {k} has an edge with an index out of range ({} edges)",
            e.len()
        )));
    }
    let names = names(&scene.looks);
    let mut bin: Vec<u8> = Vec::new();
    let mut views: Vec<Value> = Vec::new();
    let mut accessors: Vec<Value> = Vec::new();
    let mut primitives: Vec<Value> = Vec::new();
    let mut materials: Vec<Value> = Vec::new();
    let mut view = |bin: &mut Vec<u8>, bytes: &[u8], target: u32| -> usize {
        let offset = bin.len();
        bin.extend_from_slice(bytes);
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        views.push(json!({
            "buffer": 0,
            "byteOffset": offset,
            "byteLength": bytes.len(),
            "target": target,
        }));
        views.len() - 1
    };
    for (k, ((m, l), name)) in scene
        .meshes
        .iter()
        .zip(&scene.looks)
        .zip(&names)
        .enumerate()
    {
        if m.triangles.is_empty() {
            continue;
        }
        let (lo, hi) = m.bounds().unwrap_or((Vec3::ZERO, Vec3::ZERO));
        let floats = |vs: &[Vec3]| -> Vec<u8> {
            let mut out = Vec::with_capacity(vs.len() * 12);
            for v in vs {
                for x in v.to_array() {
                    out.extend_from_slice(&x.to_le_bytes());
                }
            }
            out
        };
        let pv = view(&mut bin, &floats(&m.positions), ARRAY_BUFFER);
        accessors.push(json!({
            "bufferView": pv,
            "componentType": FLOAT,
            "count": m.positions.len(),
            "type": "VEC3",
            "min": lo.to_array(),
            "max": hi.to_array(),
        }));
        let mut attributes = json!({ "POSITION": accessors.len() - 1 });
        let unit: Option<Vec<Vec3>> = if m.normals.is_empty() {
            None
        } else {
            m.normals.iter().map(|n| n.try_normalize()).collect()
        };
        if let Some(normals) = unit {
            let nv = view(&mut bin, &floats(&normals), ARRAY_BUFFER);
            accessors.push(json!({
                "bufferView": nv,
                "componentType": FLOAT,
                "count": normals.len(),
                "type": "VEC3",
            }));
            attributes["NORMAL"] = json!(accessors.len() - 1);
        }
        let mut indices: Vec<u8> = Vec::with_capacity(m.triangles.len() * 12);
        for i in m.triangles.iter().flatten() {
            indices.extend_from_slice(&i.to_le_bytes());
        }
        let iv = view(&mut bin, &indices, ELEMENT_ARRAY_BUFFER);
        accessors.push(json!({
            "bufferView": iv,
            "componentType": UNSIGNED_INT,
            "count": m.triangles.len() * 3,
            "type": "SCALAR",
        }));
        let triangles = accessors.len() - 1;
        let lines = match edges.get(k).filter(|e| !e.is_empty()) {
            Some(e) => {
                let mut bytes: Vec<u8> = Vec::with_capacity(e.len() * 8);
                for i in e.iter().flatten() {
                    bytes.extend_from_slice(&i.to_le_bytes());
                }
                let ev = view(&mut bin, &bytes, ELEMENT_ARRAY_BUFFER);
                accessors.push(json!({
                    "bufferView": ev,
                    "componentType": UNSIGNED_INT,
                    "count": e.len() * 2,
                    "type": "SCALAR",
                }));
                Some(accessors.len() - 1)
            }
            None => None,
        };
        let opacity = l.opacity.clamp(0.0, 1.0);
        let mut material = json!({
            "name": name,
            "pbrMetallicRoughness": {
                "baseColorFactor": [
                    l.diffuse[0].clamp(0.0, 1.0),
                    l.diffuse[1].clamp(0.0, 1.0),
                    l.diffuse[2].clamp(0.0, 1.0),
                    opacity,
                ],
                "metallicFactor": 0.0,
                "roughnessFactor": (2.0 / (l.shininess.max(0.0) + 2.0)).sqrt(),
            },
            "emissiveFactor": l.emission.map(|v| v.clamp(0.0, 1.0)),
            "doubleSided": true,
        });
        if opacity < 1.0 {
            material["alphaMode"] = json!("BLEND");
        }
        materials.push(material);
        primitives.push(json!({
            "attributes": attributes,
            "indices": triangles,
            "material": materials.len() - 1,
            "mode": TRIANGLES,
        }));
        if let Some(lines) = lines {
            primitives.push(json!({
                "attributes": { "POSITION": attributes["POSITION"] },
                "indices": lines,
                "material": materials.len() - 1,
                "mode": LINES,
            }));
        }
    }
    let doc = json!({
        "asset": { "version": "2.0", "generator": "subgram" },
        "scene": 0,
        "scenes": [{ "nodes": [0] }],
        "nodes": [{ "mesh": 0, "name": "subgram" }],
        "meshes": [{ "name": "subgram", "primitives": primitives }],
        "materials": materials,
        "buffers": [{ "byteLength": bin.len() }],
        "bufferViews": views,
        "accessors": accessors,
    });
    let mut text = serde_json::to_vec(&doc).map_err(|e| Error::Failed(e.to_string()))?;
    while !text.len().is_multiple_of(4) {
        text.push(b' ');
    }
    let total = 12 + 8 + text.len() + 8 + bin.len();
    let total = u32::try_from(total).map_err(|_| {
        Error::Failed(format!(
            "cannot export the scene: a GLB file holds at most 4 GiB, and this one would take \
             {total} bytes"
        ))
    })?;
    let mut out = Vec::with_capacity(total as usize);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&total.to_le_bytes());
    out.extend_from_slice(&(text.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&text);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin);
    Ok(out)
}

/// Writes `scene` as a binary glTF file (see [`glb_bytes`]).
pub fn write_glb(scene: &Scene3, path: &Path) -> Result<(), Error> {
    let bytes = glb_bytes(scene)?;
    crate::files::atomic::write_atomic(path, &bytes).map_err(|e| Error::write(path, e))
}
