//! Subdivide of a welded group (`shape::smooth`), outside `cargo test`.
//!
//! `cargo run --release --example smooth_xcheck IN.obj OUT.obj STEPS [SCHEME]`
//! subdivides the mesh in IN.obj with nothing protected (SCHEME: sqrt3,
//! the default, loop or catmull-clark) and writes OUT.obj; the output
//! faces' tags (the input face each came from, counted from 0) go to
//! OUT.obj.tags, one a line. `benches/shapes_xcheck.py` compares the
//! output with CGAL's.
//!
//! `cargo run --release --example smooth_xcheck --shapes FILE.lsys DIR`
//! derives a shape grammar and writes each smoothing group K as
//! `DIR/group-K-welded.obj` (the welded mesh, its polygons cut into
//! triangles as the half-edge mesh cuts them: quads along their first
//! diagonal, larger polygons in a fan from their first corner),
//! `DIR/group-K-ours.obj` (its subdivision in the derivation) and
//! `DIR/group-K-info.txt` (`steps protected-faces scheme`).
//!
//! `smooth_xcheck --obj-copy IN.obj OUT.obj` is the shape benchmark's
//! reference: an OBJ read into arrays and written back by a hand loop.
//!
//! `cargo run --release --example smooth_xcheck --bench` times one √3 step
//! through `subdivide` (soup in, soup out) against `Grammar::run` on the
//! same mesh, in the same run, on a 224 x 224 torus cut into 100,352
//! triangles: best of 5 each.

use std::path::Path;
use std::time::Instant;

use subgram::mesh::{io, shapes, Mesh};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().map(String::as_str) == Some("--bench") {
        bench();
        return;
    }
    if args.first().map(String::as_str) == Some("--obj-copy") && args.len() == 3 {
        obj_copy(Path::new(&args[1]), Path::new(&args[2]));
        return;
    }
    if args.first().map(String::as_str) == Some("--shapes") && args.len() == 3 {
        groups(Path::new(&args[1]), Path::new(&args[2]));
        return;
    }
    if args.len() < 3 {
        eprintln!("usage: smooth_xcheck IN.obj OUT.obj STEPS [SCHEME] | smooth_xcheck --bench");
        std::process::exit(2);
    }
    let soup = io::read(Path::new(&args[0])).unwrap_or_else(|e| fail(&e.to_string()));
    let steps: usize = args[2]
        .parse()
        .unwrap_or_else(|_| fail("STEPS must be a whole number"));
    let g = subgram::smooth_scheme(args.get(3).map_or("sqrt3", String::as_str))
        .unwrap_or_else(|e| fail(&e));
    let n = soup.faces.len();
    let tags: Vec<u32> = (0..n as u32).collect();
    let (out, tags, _) = subgram::smooth_subdivide(
        &g,
        &soup,
        &tags,
        &vec![false; soup.positions.len()],
        &vec![false; n],
        steps,
    )
    .unwrap_or_else(|e| fail(&e));
    io::write(Path::new(&args[1]), &out).unwrap_or_else(|e| fail(&e.to_string()));
    let lines: Vec<String> = tags.iter().map(u32::to_string).collect();
    std::fs::write(format!("{}.tags", args[1]), lines.join("\n") + "\n")
        .unwrap_or_else(|e| fail(&e.to_string()));
}

fn groups(file: &Path, dir: &Path) {
    let groups = subgram::shape_groups(file, 1).unwrap_or_else(|e| fail(&e.to_string()));
    std::fs::create_dir_all(dir).unwrap_or_else(|e| fail(&e.to_string()));
    for (k, g) in groups.iter().enumerate() {
        let welded = &g.welded;
        let tris = welded.fanned();
        let at = |name: &str| dir.join(format!("group-{}-{name}", k + 1));
        io::write(&at("welded.obj"), &tris).unwrap_or_else(|e| fail(&e.to_string()));
        io::write(&at("ours.obj"), &g.subdivided).unwrap_or_else(|e| fail(&e.to_string()));
        let info = format!("{} {} {}\n", g.steps, g.protected_faces, g.scheme);
        std::fs::write(at("info.txt"), info).unwrap_or_else(|e| fail(&e.to_string()));
    }
    println!("{} groups written to {}", groups.len(), dir.display());
}

/// The shape benchmark's reference: a hand loop that reads an OBJ's `v`,
/// `f`, `g` and `usemtl` lines into arrays and writes them back in the same
/// form, with no checks: the floor of files in and out for that output.
fn obj_copy(input: &Path, output: &Path) {
    use std::fmt::Write as _;
    let text = std::fs::read_to_string(input).unwrap_or_else(|e| fail(&e.to_string()));
    let mut pos: Vec<[f64; 3]> = Vec::new();
    let mut faces: Vec<(usize, Vec<u32>)> = Vec::new();
    let mut names: Vec<String> = Vec::new();
    for line in text.lines() {
        let mut w = line.split_ascii_whitespace();
        match w.next() {
            Some("v") => {
                let mut p = [0.0; 3];
                for c in &mut p {
                    *c = w.next().and_then(|x| x.parse().ok()).unwrap_or(0.0);
                }
                pos.push(p);
            }
            Some("g") | Some("usemtl") => names.push(line.to_string()),
            Some("f") => faces.push((names.len(), w.filter_map(|x| x.parse().ok()).collect())),
            _ => {}
        }
    }
    let mut out = String::with_capacity(text.len());
    for p in &pos {
        let _ = writeln!(out, "v {} {} {}", p[0], p[1], p[2]);
    }
    let mut named = 0;
    for (k, f) in &faces {
        while named < *k {
            out.push_str(&names[named]);
            out.push('\n');
            named += 1;
        }
        out.push('f');
        for i in f {
            let _ = write!(out, " {i}");
        }
        out.push('\n');
    }
    std::fs::write(output, out).unwrap_or_else(|e| fail(&e.to_string()));
}

fn fail(m: &str) -> ! {
    eprintln!("smooth_xcheck: {m}");
    std::process::exit(1)
}

fn best_of(runs: usize, mut f: impl FnMut()) -> f64 {
    (0..runs)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64()
        })
        .fold(f64::MAX, f64::min)
}

fn bench() {
    let soup = shapes::quad_torus(224, 224).fanned();
    let g = subgram::smooth_scheme("sqrt3").expect("sqrt3");
    let n = soup.faces.len();
    let tags: Vec<u32> = (0..n as u32).collect();
    let (pv, pf) = (vec![false; soup.positions.len()], vec![false; n]);
    let runs = 5;
    let mut faces = 0;
    let t_sub = best_of(runs, || {
        let (out, _, _) = subgram::smooth_subdivide(&g, &soup, &tags, &pv, &pf, 1).expect("runs");
        faces = out.faces.len();
    });
    let base = Mesh::from_soup(&soup).expect("valid");
    let t_run = best_of(runs, || {
        let mut m = base.clone();
        g.run(&mut m, 1, |_| {}).expect("runs");
    });
    let t_full = best_of(runs, || {
        let mut m = Mesh::from_soup(&soup).expect("valid");
        g.run(&mut m, 1, |_| {}).expect("runs");
        std::hint::black_box(m.to_quad_soup());
    });
    println!("sqrt(3), one step, {n} -> {faces} triangles, best of {runs}:");
    println!(
        "  subdivide (soup -> tagged mesh, run, tagged soup):   {:.1} ms",
        t_sub * 1e3
    );
    println!(
        "  Grammar::run on a built mesh (clone + run):          {:.1} ms",
        t_run * 1e3
    );
    println!(
        "  from_soup + Grammar::run + to_quad_soup:              {:.1} ms",
        t_full * 1e3
    );
    println!(
        "  ratio subdivide / run: {:.2}; subdivide / (build + run + soup): {:.2}",
        t_sub / t_run,
        t_sub / t_full
    );
}
