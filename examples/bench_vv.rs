//! Loop subdivision as a vv program (lsystems/vv/loop.lsys) against the
//! stellar grammar's Loop (lsystems/surfaces/loop.lsys), one level on an
//! icosphere of 81,920 triangles, the whole path from indexed faces to
//! indexed faces: the soup built into the structure, the step, the faces
//! traced back into a soup. `igl.loop` is timed on the same file by
//! `benches/peers.py`. `cargo run --release --example bench_vv [OUT_DIR]`

mod common;

use std::path::PathBuf;

use subgram::mesh::{io, shapes, Mesh, PolygonSoup};
use subgram::{LoadOptions, RunOptions, System};

/// The best time of `runs` runs of `f`, in seconds, and its last result.
fn best_of<T>(runs: usize, f: impl FnMut() -> T) -> (f64, T) {
    let (t, r) = common::best_of(runs, f);
    (t.as_secs_f64(), r)
}

fn main() {
    let out = PathBuf::from(
        std::env::args()
            .skip(1)
            .find(|a| !a.starts_with("--"))
            .unwrap_or_else(|| "/tmp/subgram-bench".into()),
    );
    std::fs::create_dir_all(&out).expect("output folder");
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let runs = 7;
    let sphere = shapes::icosphere(6);
    io::write(&out.join("icosphere6.obj"), &sphere).expect("write");

    // `--only-vv`: the vv program alone, for a profiler.
    if std::env::args().any(|a| a == "--only-vv") {
        let System::Vv(v) =
            subgram::load(root.join("lsystems/vv/loop.lsys"), &LoadOptions::default())
                .expect("loads")
        else {
            panic!("a vv program")
        };
        for _ in 0..runs {
            v.run_soup(&sphere, &RunOptions::default().with_steps(1))
                .expect("runs");
        }
        return;
    }
    let g = subgram::surface::load_file(&root.join("lsystems/surfaces/loop.lsys"), &[])
        .expect("grammar");
    let (tg, grammar) = best_of(runs, || {
        let mut m = Mesh::from_soup(&sphere).expect("valid");
        g.run(&mut m, 1, |_| {}).expect("runs");
        m.to_soup()
    });

    let System::Vv(v) =
        subgram::load(root.join("lsystems/vv/loop.lsys"), &LoadOptions::default()).expect("loads")
    else {
        panic!("a vv program")
    };
    let (tv, vv): (f64, PolygonSoup) = best_of(runs, || {
        v.run_soup(&sphere, &RunOptions::default().with_steps(1))
            .expect("runs")
            .soup
    });
    io::write(&out.join("icosphere6-vvloop.obj"), &vv).expect("write");

    // A hand loop over the same soup, the floor for this work: one edge
    // table, the masks, the faces.
    let (th, hand) = best_of(runs, || hand_loop(&sphere));

    println!(
        "Loop, {} -> {} triangles, indexed faces to indexed faces, best of {runs}:",
        sphere.faces.len(),
        vv.faces.len()
    );
    println!("  vv program:      {:7.1} ms", tv * 1e3);
    println!(
        "  stellar grammar: {:7.1} ms   (vv / grammar = {:.2})",
        tg * 1e3,
        tv / tg
    );
    println!(
        "  hand loop:       {:7.1} ms   (vv / hand = {:.2})",
        th * 1e3,
        tv / th
    );
    assert_eq!(grammar.faces.len(), vv.faces.len());
    assert_eq!(hand.faces.len(), vv.faces.len());
}

/// Loop subdivision of a closed triangle soup written directly: an edge
/// map, Loop's masks, four triangles per triangle.
fn hand_loop(s: &PolygonSoup) -> PolygonSoup {
    use std::collections::HashMap;
    let n = s.positions.len();
    let mut edge: HashMap<(u32, u32), u32> = HashMap::with_capacity(s.faces.len() * 2);
    let mut opposite: Vec<[u32; 2]> = Vec::new();
    let mut ends: Vec<(u32, u32)> = Vec::new();
    let mut ring: Vec<Vec<u32>> = vec![Vec::new(); n];
    for f in &s.faces {
        for k in 0..3 {
            let (a, b, c) = (f[k], f[(k + 1) % 3], f[(k + 2) % 3]);
            let key = (a.min(b), a.max(b));
            match edge.get(&key) {
                Some(&e) => opposite[(e as usize) - n][1] = c,
                None => {
                    edge.insert(key, (n + ends.len()) as u32);
                    ends.push(key);
                    opposite.push([c, u32::MAX]);
                    ring[a as usize].push(b);
                    ring[b as usize].push(a);
                }
            }
        }
    }
    let p = &s.positions;
    let mut positions = Vec::with_capacity(n + ends.len());
    for (v, r) in ring.iter().enumerate() {
        let k = r.len() as f64;
        let beta =
            (5.0 / 8.0 - (3.0 / 8.0 + 0.25 * (2.0 * std::f64::consts::PI / k).cos()).powi(2)) / k;
        let sum: glam::DVec3 = r.iter().map(|&w| p[w as usize]).sum();
        positions.push((1.0 - k * beta) * p[v] + beta * sum);
    }
    for (e, &(a, b)) in ends.iter().enumerate() {
        let [c, d] = opposite[e];
        positions.push(
            0.375 * (p[a as usize] + p[b as usize]) + 0.125 * (p[c as usize] + p[d as usize]),
        );
    }
    let mut faces = subgram::mesh::Faces::with_capacity(s.faces.len() * 4, s.faces.len() * 12);
    for f in &s.faces {
        let m = |k: usize| {
            let (a, b) = (f[k], f[(k + 1) % 3]);
            edge[&(a.min(b), a.max(b))]
        };
        let (m0, m1, m2) = (m(0), m(1), m(2));
        faces.push([f[0], m0, m2]);
        faces.push([f[1], m1, m0]);
        faces.push([f[2], m2, m1]);
        faces.push([m0, m1, m2]);
    }
    PolygonSoup {
        positions,
        faces,
        ..Default::default()
    }
}
