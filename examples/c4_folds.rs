//! Folds of C4 (`lsystems/surfaces/c4.lsys`) on scanned meshes (issue 43,
//! item 5): the largest dihedral angle after 2, 4, 6 and 8 steps, and the
//! faces that point away from the base surface, with Loop beside it.
//!
//! `cargo run --release --example c4_folds [MESH...] [--steps 2,4,6,8]`
//! (default: `lsystems/meshes/bunny.obj` and `lsystems/meshes/armadillo.off`)
//!
//! A face is flipped when its normal points away from the smoothed normal
//! (the sum of its corners' vertex normals) of the base triangle nearest
//! to it ([`subgram::mesh::folds`]). Besides the largest dihedral angle
//! of the whole mesh, the largest across the edges at the original
//! interior vertices of valence 3 and 4 (which keep their numbers): where
//! the pairing leaves one in two blocks, that angle does not fall. It
//! also counts the interior vertices the pairing leaves in fewer than 3
//! blocks.

use std::path::{Path, PathBuf};

use subgram::mesh::{folds, io, Mesh};
use subgram::surface::load_file;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn main() {
    let mut meshes = Vec::new();
    let mut steps = vec![2usize, 4, 6, 8];
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        if a == "--steps" {
            let s = args.next().expect("--steps 2,4,6,8");
            steps = s.split(',').map(|x| x.parse().expect("a number")).collect();
        } else {
            meshes.push(PathBuf::from(a));
        }
    }
    if meshes.is_empty() {
        meshes = ["bunny.obj", "armadillo.off"]
            .iter()
            .map(|m| root().join("lsystems/meshes").join(m))
            .collect();
    }
    for path in &meshes {
        measure(path, &steps);
    }
}

fn measure(path: &Path, steps: &[usize]) {
    let soup = io::read(path).unwrap_or_else(|e| panic!("{e}"));
    let base = Mesh::from_soup(&soup).unwrap_or_else(|e| panic!("{e}"));
    let surface = folds::Base::new(&base);
    // The interior vertices of valence 3 and 4: those a pairing may leave
    // in two blocks.
    let low: Vec<_> = base
        .vertices()
        .filter(|&v| !base.is_boundary_vertex(v) && base.valence(v) <= 4)
        .collect();
    println!(
        "{}: {} vertices, {} faces",
        path.display(),
        base.vertex_count(),
        base.face_count()
    );
    for scheme in ["c4", "loop"] {
        let g = load_file(
            &root().join(format!("lsystems/surfaces/{scheme}.lsys")),
            &[],
        )
        .unwrap_or_else(|e| panic!("{e}"));
        let fail = |e: subgram::surface::RunError| -> ! { panic!("{}", g.render_error(&e)) };
        let mut m = base.clone();
        // The run goes on from one count of steps to the next; Loop's
        // step is a level, C4's two are one.
        let mut run = g.start(&mut m).unwrap_or_else(|e| fail(e));
        if scheme == "c4" {
            let m = run.mesh();
            let few = m
                .vertices()
                .filter(|&v| folds::blocks_at(m, v).is_some_and(|k| k < 3))
                .count();
            println!("  c4 pairing: {few} interior vertices in fewer than 3 blocks");
        }
        let mut done = 0;
        for &s in steps {
            let n = if scheme == "loop" { s / 2 } else { s };
            run.steps(n - done, |_| {}).unwrap_or_else(|e| fail(e));
            done = n;
            let f = folds::folds(run.mesh(), &surface, &low);
            println!(
                "  {scheme:4} {n} steps: {:>8} faces, max dihedral {:6.2}°, at valence 3 and 4 \
                 {:6.2}°, {} flipped",
                f.faces, f.max_dihedral, f.max_dihedral_at, f.flipped
            );
        }
    }
}
