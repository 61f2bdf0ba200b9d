//! What adaptive 4-8 refinement buys, and what it costs.
//! `cargo run --release --example adaptive_4_8 [MESH] [REFERENCE_STEPS] [SCHEME]`
//! (SCHEME: `four-eight`, the default, or `c4` for triangle meshes such as
//! `lsystems/meshes/bunny.obj`)
//!
//! 1. Faces against distance to the limit surface. The limit is
//!    approximated by `REFERENCE_STEPS` uniform bisections of
//!    `lsystems/surfaces/four-eight.lsys` (default 10 on the quad torus).
//!    For each uniform level, and for adaptive runs whose blocks are
//!    split while the angle between their triangles' normals passes a
//!    threshold (`angle(e) > D`, after one uniform step, because a planar
//!    quad's triangles make no angle), the table gives the faces and the
//!    largest distance from an output vertex or face centroid to the
//!    nearest point of the reference surface.
//! 2. Time against mesh size: a region of fixed size in faces (a radius
//!    shrinking with the grid) refined 8 times on quad grids of growing
//!    size: what a run takes, and the faces it made, matching every
//!    element (`adaptive;`) or from work lists (`adaptive: incremental;`).

use std::path::PathBuf;
use std::time::Instant;

use glam::DVec3;
use subgram::mesh::folds::TriangleIndex;
use subgram::mesh::{io, shapes, Mesh};
use subgram::surface::{load_file, load_str, Grammar};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn run(g: &Grammar, base: &Mesh, steps: usize) -> Mesh {
    let mut m = base.clone();
    g.run(&mut m, steps, |_| {})
        .unwrap_or_else(|e| panic!("{}", g.render_error(&e)));
    m
}

/// The adaptive grammar with `guard` selecting blocks.
fn adaptive(guard: &str) -> Grammar {
    adaptive_as("adaptive;", guard)
}

/// [`adaptive`] with `how`: `adaptive;` or `adaptive: incremental;`.
fn adaptive_as(how: &str, guard: &str) -> Grammar {
    let text = format!(
        "mesh: \"x.obj\";\nblocks: bisection;\n{how}\n\
         init: match_blocks;\n\
         define velh(v) = 0.5*v + 0.5*avg(w in ring(v) where !new(w));\n\
         E(e; block(e) && ({guard})) | F^2 -> V(v = avg(ring(v))) || E^4 F^4;\n\
         E(e; block(e) && ({guard})) | F -> V(v = avg(e)) || E^3 F^2;\n\
         V(v; !new(v) && refined(v)) | interior -> V(v = velh(v));\n"
    );
    load_str("adaptive.lsys", &text, &[]).unwrap_or_else(|e| panic!("{e}"))
}

/// The largest distance from a vertex or face centroid of `m` to `limit`,
/// over the points within `within` of `centre` (all with `None`).
fn error(m: &Mesh, limit: &TriangleIndex, within: Option<(DVec3, f64)>) -> f64 {
    let vs = m.vertices().map(|v| m.position(v));
    let cs = m.faces().map(|f| m.face_centroid(f));
    vs.chain(cs)
        .filter(|p| within.is_none_or(|(c, r)| p.distance(c) < r))
        .map(|p| limit.distance(p))
        .fold(0.0, f64::max)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mesh = args
        .first()
        .map(PathBuf::from)
        .unwrap_or_else(|| root().join("lsystems/meshes/torus.obj"));
    let reference: usize = args.get(1).map_or(10, |s| s.parse().expect("a number"));
    // The uniform scheme: four-eight.lsys, or c4.lsys (pairing first) for
    // triangle meshes; the adaptive grammars pair first too, which does
    // nothing on a quad mesh.
    let scheme = args.get(2).map_or("four-eight", |s| s.as_str());
    let base = io::read_mesh(&mesh).unwrap_or_else(|e| panic!("{e}"));
    let uniform = load_file(
        &root().join(format!("lsystems/surfaces/{scheme}.lsys")),
        &[],
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let t = Instant::now();
    let limit = run(&uniform, &base, reference);
    let index = TriangleIndex::new(&limit);
    println!(
        "{}: {} faces; reference: {reference} uniform bisections, {} faces ({:.1} s)",
        mesh.display(),
        base.face_count(),
        limit.face_count(),
        t.elapsed().as_secs_f64()
    );
    println!("\n| run | faces | max distance to the reference |\n|---|---:|---:|");
    for k in 0..=reference.saturating_sub(2) {
        let m = run(&uniform, &base, k);
        println!(
            "| uniform, {k} bisections | {} | {:.2e} |",
            m.face_count(),
            error(&m, &index, None)
        );
    }
    for d in [8.0, 4.0, 2.0, 1.0] {
        for steps in [4, 6, 8] {
            if steps + 2 > reference {
                continue;
            }
            let g = adaptive(&format!("step == 1 || angle(e) > {d}"));
            let m = run(&g, &base, steps);
            println!(
                "| adaptive, angle > {d}°, {steps} steps | {} | {:.2e} |",
                m.face_count(),
                error(&m, &index, None)
            );
        }
    }
    // Near a point: after `u` uniform steps, blocks within R of P
    // refined; the distance measured within `b` of P (what view-dependent
    // refinement needs), against uniform levels measured in the same
    // ball. The vertices on the border of the refined region are not
    // smoothed, and their neighbours inside read them, so positions
    // differ from uniform refinement's in a band along the border, a few
    // of the border's diamonds wide; the ball is kept out of it.
    // R and the ball in proportion to the mesh: 1 and 0.3 on the torus,
    // whose bounding box has a diagonal of 4.
    let diagonal = {
        let (mut lo, mut hi) = (DVec3::splat(f64::MAX), DVec3::splat(f64::MIN));
        for v in base.vertices() {
            lo = lo.min(base.position(v));
            hi = hi.max(base.position(v));
        }
        lo.distance(hi)
    };
    let (p, r, b, u) = (
        base.position(subgram::mesh::VertexId(0)),
        diagonal / 4.0,
        0.3 * diagonal / 4.0,
        4,
    );
    let ball = Some((p, b));
    println!(
        "\nWithin {b} of {p} ({u} uniform steps, then blocks within {r} of it refined):\n\n\
         | run | faces | max distance to the reference in the ball |\n|---|---:|---:|"
    );
    for k in 0..=reference.saturating_sub(2) {
        let m = run(&uniform, &base, k);
        println!(
            "| uniform, {k} bisections | {} | {:.2e} |",
            m.face_count(),
            error(&m, &index, ball)
        );
    }
    let g = adaptive(&format!(
        "step <= {u} || Length(avg(e) - point({}, {}, {})) < {r}",
        p.x, p.y, p.z
    ));
    for steps in u + 1..=reference.saturating_sub(2) {
        let m = run(&g, &base, steps);
        println!(
            "| adaptive near the point, {steps} steps | {} | {:.2e} |",
            m.face_count(),
            error(&m, &index, ball)
        );
    }

    println!(
        "\nA region of fixed size in faces refined 8 times, on quad grids:\n\n\
         | grid | matching | base faces | faces after | start + step 1 (ms) | steps 2-8 (ms) | steps 2-8, ms per 1000 faces made |\n\
         |---|---|---:|---:|---:|---:|---:|"
    );
    for n in [32, 64, 128, 256, 512] {
        let base = Mesh::from_soup(&shapes::quad_grid(n, n)).expect("a grid");
        // Blocks within 3 cells of the centre.
        let r = 3.0 / n as f64;
        for how in ["adaptive;", "adaptive: incremental;"] {
            let g = adaptive_as(how, &format!("Length(avg(e) - point(0.5, 0.5, 0)) < {r}"));
            // The start and the first step test every block; the time
            // of the other seven is what should follow the faces made.
            let (mut first, mut rest) = (f64::MAX, f64::MAX);
            let (mut faces, mut after_first) = (0, 0);
            for _ in 0..3 {
                let mut m = base.clone();
                let t = Instant::now();
                let mut run = g.start(&mut m).expect("starts");
                run.steps(1, |_| {}).expect("runs");
                first = first.min(t.elapsed().as_secs_f64());
                after_first = run.mesh().face_count();
                let t = Instant::now();
                run.steps(7, |_| {}).expect("runs");
                rest = rest.min(t.elapsed().as_secs_f64());
                faces = run.mesh().face_count();
            }
            println!(
                "| {n} × {n} | `{how}` | {} | {faces} | {:.1} | {:.1} | {:.2} |",
                base.face_count(),
                first * 1e3,
                rest * 1e3,
                rest * 1e6 / (faces - after_first) as f64
            );
        }
    }
}
