//! `subdivide --limit` (issue 43, item 2): limit positions and normals
//! from the stencils `analyze` measures, against Catmull-Clark's and
//! Loop's published limit masks (positions) and against normals estimated
//! from a much finer subdivision (the faces around the nearest vertex six
//! steps on), computed here.

use glam::DVec3;
use subgram::mesh::{io, shapes, Mesh, PolygonSoup};

use crate::support::*;

fn subdivided(
    file: &str,
    base: &PolygonSoup,
    steps: usize,
) -> (subgram::surface::Grammar, PolygonSoup) {
    let g = subgram::surface::load_file(&lsys(file), &[]).unwrap_or_else(|e| panic!("{e}"));
    let mut m = Mesh::from_soup(base).unwrap();
    g.run(&mut m, steps, |_| {})
        .unwrap_or_else(|e| panic!("{}", g.render_error(&e)));
    let soup = m.to_quad_soup();
    (g, soup)
}

fn limit(
    g: &subgram::surface::Grammar,
    soup: &PolygonSoup,
) -> subgram::analyze::limit::LimitSurface {
    let d = subgram::Deadline::after(std::time::Duration::from_secs(300));
    subgram::analyze::limit::limit_surface(g, soup, d).unwrap_or_else(|e| panic!("{e}"))
}

/// Each vertex's neighbours across edges and, on quads, across faces.
fn neighbours(s: &PolygonSoup) -> Vec<(Vec<u32>, Vec<u32>)> {
    let mut out = vec![(Vec::new(), Vec::new()); s.positions.len()];
    for f in &s.faces {
        let k = f.len();
        for c in 0..k {
            let (v, next) = (f[c] as usize, f[(c + 1) % k]);
            if !out[v].0.contains(&next) {
                out[v].0.push(next);
            }
            if k == 4 {
                out[v].1.push(f[(c + 2) % k]);
            }
        }
    }
    out
}

/// Area-weighted normals of the faces around each vertex of `fine`, at
/// the vertex of `fine` nearest each of `points`.
fn fine_normals(fine: &PolygonSoup, points: &[DVec3]) -> Vec<DVec3> {
    let mut n = vec![DVec3::ZERO; fine.positions.len()];
    for f in &fine.faces {
        let p: Vec<DVec3> = f.iter().map(|&i| fine.positions[i as usize]).collect();
        let a: DVec3 = (0..p.len()).map(|k| p[k].cross(p[(k + 1) % p.len()])).sum();
        for &i in f {
            n[i as usize] += a;
        }
    }
    points
        .iter()
        .map(|q| {
            let (i, _) = fine
                .positions
                .iter()
                .enumerate()
                .min_by(|a, b| a.1.distance(*q).total_cmp(&b.1.distance(*q)))
                .unwrap();
            n[i].normalize()
        })
        .collect()
}

fn jittered_cube() -> PolygonSoup {
    jitter(
        io::read(&lsys("meshes/cube.obj")).unwrap(),
        0x9E37_79B9_7F4A_7C15,
    )
}

/// Catmull-Clark: the limit of a vertex of valence n is
/// (n^2 v + 4 (sum of its edge neighbours) + (sum of its face neighbours))
/// / (n (n + 5)) (Halstead, Kass and DeRose 1993); one step on a jittered
/// cube (valences 3 and 4), every vertex to 1e-9. The normals agree with
/// those of six steps more to 0.1 degree, and the positions with that
/// mesh's nearest vertices to 1e-3.
#[test]
fn catmull_clark_limit_is_halsteads_mask_and_the_fine_surfaces_normal() {
    let base = jittered_cube();
    let (g, soup) = subdivided("surfaces/catmull-clark.lsys", &base, 1);
    let lim = limit(&g, &soup);
    let nb = neighbours(&soup);
    for (v, (edges, faces)) in nb.iter().enumerate() {
        let n = edges.len() as f64;
        let sum = |xs: &[u32]| {
            xs.iter()
                .map(|&i| soup.positions[i as usize])
                .sum::<DVec3>()
        };
        let want = (n * n * soup.positions[v] + 4.0 * sum(edges) + sum(faces)) / (n * (n + 5.0));
        let d = lim.positions[v].distance(want);
        assert!(d < 1e-9, "vertex {v} (valence {n}): {d}");
    }
    let (_, fine) = subdivided("surfaces/catmull-clark.lsys", &base, 7);
    check_against_fine(&lim, &fine, "Catmull-Clark");
}

fn check_against_fine(lim: &subgram::analyze::limit::LimitSurface, fine: &PolygonSoup, what: &str) {
    let est = fine_normals(fine, &lim.positions);
    for (k, (n, e)) in lim.normals.iter().zip(&est).enumerate() {
        let angle = n.dot(*e).clamp(-1.0, 1.0).acos().to_degrees();
        assert!(angle < 0.1, "{what}: vertex {k}: {angle} degrees");
    }
    for p in &lim.positions {
        let d = fine
            .positions
            .iter()
            .map(|q| q.distance(*p))
            .fold(f64::INFINITY, f64::min);
        assert!(d < 1e-3, "{what}: {p} is {d} from the fine mesh");
    }
}

/// Loop: the limit of a vertex of valence n is (1 - n chi) v + chi (sum of
/// its neighbours), chi = 1 / (3 / (8 beta) + n), beta Loop's (Loop 1987);
/// one step on a jittered octahedron (valences 4 and 6) and icosahedron
/// (5 and 6), every vertex to 1e-9; normals and positions against six
/// steps more, as for Catmull-Clark.
#[test]
fn loop_limit_is_loops_mask_and_the_fine_surfaces_normal() {
    let beta =
        |n: f64| (5.0 / 8.0 - (3.0 / 8.0 + 0.25 * (std::f64::consts::TAU / n).cos()).powi(2)) / n;
    for (name, base) in [
        (
            "octahedron",
            jitter(io::read(&lsys("meshes/octahedron.obj")).unwrap(), 7),
        ),
        ("icosahedron", jitter(shapes::icosahedron(), 11)),
    ] {
        let (g, soup) = subdivided("surfaces/loop.lsys", &base, 1);
        let lim = limit(&g, &soup);
        for (v, (edges, _)) in neighbours(&soup).iter().enumerate() {
            let n = edges.len() as f64;
            let chi = 1.0 / (3.0 / (8.0 * beta(n)) + n);
            let sum: DVec3 = edges.iter().map(|&i| soup.positions[i as usize]).sum();
            let want = (1.0 - n * chi) * soup.positions[v] + chi * sum;
            let d = lim.positions[v].distance(want);
            assert!(d < 1e-9, "{name}: vertex {v} (valence {n}): {d}");
        }
        let (_, fine) = subdivided("surfaces/loop.lsys", &base, 7);
        check_against_fine(&lim, &fine, name);
    }
}

/// What `--limit` refuses: an open mesh, a dual scheme.
#[test]
fn limit_refuses_what_it_has_no_stencils_for() {
    let (g, soup) = subdivided("surfaces/catmull-clark.lsys", &shapes::quad_grid(3, 3), 1);
    let d = subgram::Deadline::after(std::time::Duration::from_secs(60));
    let e = subgram::analyze::limit::limit_surface(&g, &soup, d)
        .unwrap_err()
        .to_string();
    assert!(e.contains("on a boundary"), "{e}");
    let (g, soup) = subdivided("surfaces/doo-sabin.lsys", &jittered_cube(), 1);
    let e = subgram::analyze::limit::limit_surface(&g, &soup, d)
        .unwrap_err()
        .to_string();
    assert!(e.contains("dual"), "{e}");
}

/// The command writes what the library computes: an OBJ with a `vn` per
/// vertex and faces `v//v`, a PLY with `nx ny nz`; both read back as the
/// same mesh; a vv program is refused as a usage error.
#[test]
fn subdivide_limit_writes_normals_in_obj_and_ply() {
    let dir = scratch("limit");
    let run = |out: &str, grammar: &str| {
        std::process::Command::new(env!("CARGO_BIN_EXE_subgram"))
            .args(["subdivide", "--limit", "-n", "1", "--grammar"])
            .arg(lsys(grammar))
            .arg(lsys("meshes/octahedron.obj"))
            .arg("-o")
            .arg(dir.path().join(out))
            .output()
            .unwrap()
    };
    let o = run("a.obj", "surfaces/loop.lsys");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(dir.path().join("a.obj")).unwrap();
    let count = |p: &str| text.lines().filter(|l| l.starts_with(p)).count();
    assert_eq!((count("v "), count("vn "), count("f ")), (18, 18, 32));
    assert!(text
        .lines()
        .filter(|l| l.starts_with("f "))
        .all(|l| l.contains("//")));
    for l in text.lines().filter(|l| l.starts_with("vn ")) {
        let n: Vec<f64> = l
            .split_whitespace()
            .skip(1)
            .map(|x| x.parse().unwrap())
            .collect();
        assert!(
            (n[0] * n[0] + n[1] * n[1] + n[2] * n[2] - 1.0).abs() < 1e-12,
            "{l}"
        );
    }
    let o = run("a.ply", "surfaces/loop.lsys");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let ply = std::fs::read_to_string(dir.path().join("a.ply")).unwrap();
    assert!(ply.contains("property double nx\nproperty double ny\nproperty double nz\n"));
    let a = io::read(&dir.path().join("a.obj")).unwrap();
    let b = io::read(&dir.path().join("a.ply")).unwrap();
    assert_eq!(a.positions, b.positions);
    let o = run("b.obj", "vv/loop.lsys");
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--limit is for surface grammars"));
}
