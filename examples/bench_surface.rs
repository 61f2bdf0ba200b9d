//! Subdivision through the grammar engine, timed; the peers are timed by
//! `benches/peers.py` in the same session, on the meshes this program
//! writes. `cargo run --release --example bench_surface [OUT_DIR]`
//!
//! - Loop (lsystems/surfaces/loop.lsys), one level, on an icosphere of
//!   81,920 triangles;
//! - Catmull-Clark (lsystems/surfaces/catmull-clark.lsys), one level, on a
//!   316 x 316 quad torus;
//! - sqrt(3) (lsystems/surfaces/sqrt3.lsys), one level, on the icosphere
//!   (CGAL's time on the same file comes from `benches/xcheck.py`).
//!
//! Each is also timed whole, from an indexed face list to an indexed face
//! list, as igl.loop and Blender are: building the half-edge mesh
//! (`Mesh::from_soup`), the grammar, and the faces out (`to_soup`, or
//! `to_quad_soup` for Catmull-Clark), each part best of the runs, with a
//! copy of the output's arrays as the reference for the last part, and
//! the three in one go (`whole`), best of the runs. `benches/peers.py
//! --faces` runs this and igl.loop and Blender on the same files, round
//! after round.

mod common;

use std::path::PathBuf;
use std::time::Instant;

use subgram::mesh::{io, shapes, Mesh};

fn best_of(runs: usize, base: &Mesh, g: &subgram::surface::Grammar) -> (f64, Mesh) {
    let mut best = f64::MAX;
    let mut last = None;
    for _ in 0..runs {
        let mut m = base.clone();
        let t = Instant::now();
        g.run(&mut m, 1, |_| {}).expect("runs");
        best = best.min(t.elapsed().as_secs_f64());
        last = Some(m);
    }
    (best, last.expect("one run"))
}

/// Times soup -> mesh -> grammar -> soup, each part best of `runs`, and
/// prints the parts, their sum and the reference copy.
fn faces_to_faces(
    name: &str,
    runs: usize,
    soup: &subgram::mesh::PolygonSoup,
    g: &subgram::surface::Grammar,
    quads: bool,
) {
    let (t_build, base) = common::best_of(runs, || Mesh::from_soup(soup).expect("valid"));
    let (t_run, m) = best_of(runs, &base, g);
    let t_run = std::time::Duration::from_secs_f64(t_run);
    let (t_out, out) = common::best_of(runs, || if quads { m.to_quad_soup() } else { m.to_soup() });
    // The reference: copying the output's arrays (positions and indices,
    // one list per face, as a soup holds them).
    let (t_copy, copy) = common::best_of(runs, || out.clone());
    assert_eq!(copy.faces.len(), out.faces.len());
    // The whole chain in one go, as a user's call runs it.
    let (t_whole, whole) = common::best_of(runs, || {
        let mut m = Mesh::from_soup(soup).expect("valid");
        g.run(&mut m, 1, |_| {}).expect("runs");
        if quads {
            m.to_quad_soup()
        } else {
            m.to_soup()
        }
    });
    assert_eq!(whole, out);
    let ms = |d: std::time::Duration| d.as_secs_f64() * 1e3;
    println!(
        "{name}, faces to faces ({} -> {} faces), best of {runs} each part:",
        soup.faces.len(),
        out.faces.len()
    );
    println!("  from_soup      {:>8.1} ms", ms(t_build));
    println!("  grammar        {:>8.1} ms", ms(t_run));
    println!(
        "  {:<14} {:>8.1} ms ({:.2}x a copy of its arrays, {:.1} ms)",
        if quads { "to_quad_soup" } else { "to_soup" },
        ms(t_out),
        t_out.as_secs_f64() / t_copy.as_secs_f64(),
        ms(t_copy)
    );
    println!("  total          {:>8.1} ms", ms(t_build + t_run + t_out));
    println!(
        "  whole          {:>8.1} ms (the three in one go)",
        ms(t_whole)
    );
}

fn main() {
    let arg = std::env::args().nth(1);
    if arg.as_deref().is_some_and(|a| a.starts_with('-')) {
        // Not a folder to fill: `--help` once became one.
        println!("usage: bench_surface [OUT_DIR] (default /tmp/subgram-bench)");
        return;
    }
    let out = PathBuf::from(arg.unwrap_or_else(|| "/tmp/subgram-bench".into()));
    std::fs::create_dir_all(&out).expect("output folder");
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let runs = 7;

    let sphere = shapes::icosphere(6);
    io::write(&out.join("icosphere6.obj"), &sphere).expect("write");
    let base = Mesh::from_soup(&sphere).expect("valid");
    let g = subgram::surface::load_file(&root.join("lsystems/surfaces/loop.lsys"), &[])
        .expect("grammar");
    let (t, m) = best_of(runs, &base, &g);
    io::write(&out.join("icosphere6-loop.obj"), &m.to_soup()).expect("write");
    println!(
        "Loop grammar: {} -> {} triangles, best of {runs}: {:.1} ms",
        base.face_count(),
        m.face_count(),
        t * 1e3
    );

    faces_to_faces("Loop", runs, &sphere, &g, false);

    // Where the memory of `subdivide -n 3` goes: the mesh's own arrays
    // after three levels, against the output as an indexed face list.
    let mut m = base.clone();
    g.run(&mut m, 3, |_| {}).expect("runs");
    let mb = |b: usize| b as f64 / 1e6;
    println!(
        "Loop, 3 levels: {} triangles; the mesh's arrays {:.0} MB ({:.1} bytes per face); \
         the output indexed (3 f64 a vertex, 3 u32 a face) {:.0} MB",
        m.face_count(),
        mb(m.bytes()),
        m.bytes_per_face(),
        mb(m.vertex_count() * 24 + m.face_count() * 12)
    );
    drop(m);

    let g = subgram::surface::load_file(&root.join("lsystems/surfaces/sqrt3.lsys"), &[])
        .expect("grammar");
    let (t, m) = best_of(runs, &base, &g);
    println!(
        "sqrt(3) grammar: {} -> {} triangles, best of {runs}: {:.1} ms",
        base.face_count(),
        m.face_count(),
        t * 1e3
    );

    let torus = shapes::quad_torus(316, 316);
    io::write(&out.join("torus316.obj"), &torus).expect("write");
    let base = Mesh::from_soup(&torus).expect("valid");
    let g = subgram::surface::load_file(&root.join("lsystems/surfaces/catmull-clark.lsys"), &[])
        .expect("grammar");
    let (t, m) = best_of(runs, &base, &g);
    io::write(&out.join("torus316-cc.obj"), &m.to_quad_soup()).expect("write");
    println!(
        "Catmull-Clark grammar: {} -> {} quads, best of {runs}: {:.1} ms",
        torus.faces.len(),
        m.to_quad_soup().faces.len(),
        t * 1e3
    );
    faces_to_faces("Catmull-Clark", runs, &torus, &g, true);
}
