//! One Loop-style refinement, topology only, on a mesh of about a million
//! triangles: split every edge, then flip the edges that join an old vertex
//! to a new one across a face. `cargo run --release --example bench_mesh`
//!
//! Also timed in the same run, as references: building the half-edge mesh
//! from the polygon soup, and a plain copy of the mesh's arrays; then
//! reading the same mesh from files (OBJ, OFF, ASCII and binary PLY),
//! written to a temporary folder and removed afterwards.

mod common;

use std::time::Instant;

use subgram::mesh::io::{self, Format};
use subgram::mesh::{shapes, EdgeId, Mesh, PolygonSoup};

fn main() {
    let soup = shapes::icosphere(8);
    let t = Instant::now();
    let base = Mesh::from_soup(&soup).expect("valid");
    let t_build = t.elapsed();
    let t = Instant::now();
    let copy = base.clone();
    let t_copy = t.elapsed();
    drop(copy);
    let faces = base.face_count();
    let mut best_split = f64::MAX;
    let mut best_flip = f64::MAX;
    let mut result = None;
    for _ in 0..3 {
        let mut m = base.clone();
        let t = Instant::now();
        let old: Vec<EdgeId> = m.edges().collect();
        // Each split adds a vertex, three edges and two faces.
        m.reserve(old.len(), 3 * old.len(), 2 * old.len());
        for e in old {
            let (a, b) = m.edge_vertices(e);
            let p = (m.position(a) + m.position(b)) * 0.5;
            m.edge_split(e, p).expect("split");
        }
        let split = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let flip: Vec<EdgeId> = m
            .edges()
            .filter(|&e| {
                let (a, b) = m.edge_vertices(e);
                let (la, lb) = (m.vertex_level(a), m.vertex_level(b));
                m.edge_level(e) == 1 && la.min(lb) == 0 && la.max(lb) == 1
            })
            .collect();
        for e in flip {
            m.edge_flip(e).expect("flip");
        }
        let fl = t.elapsed().as_secs_f64();
        best_split = best_split.min(split);
        best_flip = best_flip.min(fl);
        result = Some(m);
    }
    let m = result.expect("ran");
    m.validate().expect("valid after refinement");
    assert_eq!(m.face_count(), faces * 4);
    println!(
        "icosphere: {faces} triangles -> {} (best of 3)",
        m.face_count()
    );
    println!(
        "  build half-edge mesh from soup   {:>8.1} ms (reference)",
        t_build.as_secs_f64() * 1e3
    );
    println!(
        "  clone the mesh's arrays          {:>8.1} ms (reference)",
        t_copy.as_secs_f64() * 1e3
    );
    println!(
        "  split every edge                 {:>8.1} ms",
        best_split * 1e3
    );
    println!(
        "  flip old-new edges               {:>8.1} ms",
        best_flip * 1e3
    );
    println!(
        "  total refinement                 {:>8.1} ms, {:.0} ns per new face",
        (best_split + best_flip) * 1e3,
        (best_split + best_flip) * 1e9 / (3 * faces) as f64
    );
    println!(
        "  storage: {:.1} bytes per face before, {:.1} after",
        base.bytes_per_face(),
        m.bytes_per_face()
    );
    read_files(&soup);
}

/// Times reading `soup` back from each file format (best of 3).
fn read_files(soup: &PolygonSoup) {
    let dir = std::env::temp_dir().join(format!("subgram-bench-mesh-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a temporary folder");
    let files = [
        ("mesh.obj", io::to_bytes(Format::Obj, soup)),
        ("mesh.off", io::to_bytes(Format::Off, soup)),
        ("ascii.ply", io::to_bytes(Format::Ply, soup)),
        ("binary.ply", binary_ply(soup)),
    ];
    println!("reading {} faces from files (best of 3):", soup.faces.len());
    for (name, bytes) in &files {
        let path = dir.join(name);
        std::fs::write(&path, bytes).expect("write a bench file");
        let (t, read) = common::best_of(3, || io::read(&path).expect("reads"));
        assert_eq!(read.faces.len(), soup.faces.len());
        println!(
            "  {name:<12} {:>6.1} MB {:>8.1} ms",
            bytes.len() as f64 / 1e6,
            t.as_secs_f64() * 1e3
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `soup` as binary little-endian PLY with double coordinates.
fn binary_ply(soup: &PolygonSoup) -> Vec<u8> {
    let mut out = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\n\
         property double x\nproperty double y\nproperty double z\n\
         element face {}\nproperty list uchar uint vertex_indices\nend_header\n",
        soup.positions.len(),
        soup.faces.len()
    )
    .into_bytes();
    for p in &soup.positions {
        for c in [p.x, p.y, p.z] {
            out.extend(c.to_le_bytes());
        }
    }
    for f in &soup.faces {
        out.push(f.len() as u8);
        for &i in f {
            out.extend(i.to_le_bytes());
        }
    }
    out
}
