//! Adaptive 4-8 refinement (`adaptive;`, issue 15 part 3): the mesh stays
//! a conforming 4-8 mesh after every step, selecting every block is
//! uniform refinement to the bit, and a guard that selects a region
//! refines there and in the neighbours the closure needs, counted by hand.

use glam::DVec3;
use subgram::mesh::{shapes, Mesh, PolygonSoup};
use subgram::surface::Grammar;

use crate::support::*;

fn grammar_file(file: &str, defines: &[&str]) -> Grammar {
    let defines: Vec<String> = defines.iter().map(|d| d.to_string()).collect();
    subgram::surface::load_file(&lsys(file), &defines).unwrap_or_else(|e| panic!("{e}"))
}

fn grammar_text(text: &str) -> Grammar {
    subgram::surface::load_str("g.lsys", text, &[]).unwrap_or_else(|e| panic!("{e}"))
}

/// Everything the 4-8 structure and conformity require of `m`:
/// * the half-edge mesh is valid (`validate`);
/// * every face has at most one edge marked as a block's internal edge,
///   and a marked interior edge is the refinement edge of both its faces
///   (a mark is a complete diamond);
/// * a face without a mark is half of an incomplete diamond: the face
///   across its refinement edge has another refinement edge;
/// * as a polygon soup, no edge is used by more than two faces and the
///   number of boundary edges is `boundary_edges` (closed stays closed);
/// * no vertex lies on the open segment of an edge of a face around a
///   neighbour (a T-junction would put one there).
fn assert_conforming(m: &Mesh, boundary_edges: Option<usize>, what: &str) {
    m.validate()
        .unwrap_or_else(|e| panic!("{what}: {}", e.message));
    for f in m.faces() {
        let marked: Vec<_> = m
            .face_edges(f)
            .into_iter()
            .filter(|&e| m.is_block_edge(e))
            .collect();
        assert!(marked.len() <= 1, "{what}: face {f} has {marked:?} marked");
        let r = m.refinement_edge(f);
        if let Some(&e) = marked.first() {
            assert_eq!(r, e, "{what}: face {f}");
            for g in m.edge_faces(e).into_iter().flatten() {
                assert_eq!(m.refinement_edge(g), e, "{what}: a mark that is no diamond");
            }
        } else {
            let across = m.edge_faces(r).into_iter().flatten().find(|&g| g != f);
            if let Some(g) = across {
                assert_ne!(
                    m.refinement_edge(g),
                    r,
                    "{what}: a complete diamond without its mark"
                );
            }
        }
    }
    // Edges counted on the soup: no more than two faces on an edge.
    let soup = m.to_soup();
    let mut uses = std::collections::HashMap::new();
    for f in &soup.faces {
        for k in 0..f.len() {
            let (a, b) = (f[k], f[(k + 1) % f.len()]);
            *uses.entry((a.min(b), a.max(b))).or_insert(0usize) += 1;
        }
    }
    assert!(uses.values().all(|&n| n <= 2), "{what}: an edge in 3 faces");
    if let Some(b) = boundary_edges {
        assert_eq!(
            uses.values().filter(|&&n| n == 1).count(),
            b,
            "{what}: boundary edges"
        );
    }
    // T-junctions: a vertex on an edge of a face at one of its neighbours.
    for e in m.edges() {
        let (a, b) = m.edge_vertices(e);
        let (pa, pb) = (m.position(a), m.position(b));
        let near: Vec<_> = [a, b]
            .into_iter()
            .flat_map(|v| m.vertex_faces(v).collect::<Vec<_>>())
            .flat_map(|f| m.face_vertices(f))
            .collect();
        for w in near {
            if w == a || w == b {
                continue;
            }
            let p = m.position(w);
            let t = (p - pa).dot(pb - pa) / (pb - pa).length_squared();
            let off = (pa + (pb - pa) * t).distance(p);
            assert!(
                !(0.0..=1.0).contains(&t) || off > 1e-9 * pa.distance(pb),
                "{what}: vertex {w} lies on the edge {a}-{b}"
            );
        }
    }
}

/// The marks, positions (bits) and faces of `m`, by id: what must agree
/// to the bit.
/// Runs `a` and `b` on `soup` side by side for `steps` steps and checks
/// that their meshes are the same, to the bit, after every step; the face
/// count at the end.
fn in_step(a: &Grammar, b: &Grammar, soup: &PolygonSoup, steps: usize, what: &str) -> usize {
    let mut ma = Mesh::from_soup(soup).unwrap();
    let mut mb = ma.clone();
    let mut ra = a.start(&mut ma).unwrap();
    let mut rb = b.start(&mut mb).unwrap();
    for step in 1..=steps {
        ra.steps(1, |_| {}).unwrap();
        rb.steps(1, |_| {}).unwrap();
        assert!(
            fingerprint(ra.mesh()) == fingerprint(rb.mesh()),
            "{what}, step {step}: differs"
        );
    }
    ra.mesh().face_count()
}

fn fingerprint(m: &Mesh) -> (Vec<[u64; 3]>, Vec<[u32; 3]>, Vec<bool>) {
    let pos = m
        .vertices()
        .map(|v| m.position(v).to_array().map(f64::to_bits))
        .collect();
    let faces = m.faces().map(|f| m.face_vertices(f).map(|v| v.0)).collect();
    let marks = m.edges().map(|e| m.is_block_edge(e)).collect();
    (pos, faces, marks)
}

fn torus_obj() -> PolygonSoup {
    subgram::mesh::io::read(&lsys("meshes/torus.obj")).unwrap()
}

/// Selecting every block (a radius that holds the whole mesh) is
/// four-eight.lsys, to the bit, after every step: on the closed torus, on
/// an open grid (the boundary rule) and on a jittered torus.
#[test]
fn all_selected_is_uniform_to_the_bit() {
    let uniform = grammar_file("surfaces/four-eight.lsys", &[]);
    let adaptive = grammar_file("surfaces/four-eight-adaptive.lsys", &["R=1e9"]);
    let meshes = [
        ("torus", torus_obj()),
        ("grid", shapes::quad_grid(5, 4)),
        ("jittered torus", jitter(shapes::quad_torus(6, 4), 7)),
    ];
    for (name, soup) in meshes {
        in_step(
            &uniform,
            &adaptive,
            &soup,
            6,
            &format!("{name}: adaptive with everything selected"),
        );
    }
}

/// The example grammar refines near its point, and the mesh is a
/// conforming 4-8 mesh after every step; the closed torus stays closed,
/// and the grid keeps a boundary that only grows by the boundary splits.
#[test]
fn conforming_after_every_step() {
    for (defines, soup, closed) in [
        (vec![], torus_obj(), true),
        (
            vec!["PX=0.3", "PY=0.6", "R=0.3"],
            shapes::quad_grid(6, 6),
            false,
        ),
        (
            vec!["PX=0.9", "PY=0.4", "PZ=0.2", "R=0.5"],
            jitter(shapes::quad_torus(8, 6), 11),
            true,
        ),
    ] {
        let g = grammar_file("surfaces/four-eight-adaptive.lsys", &defines);
        let mut m = Mesh::from_soup(&soup).unwrap();
        let mut run = g.start(&mut m).unwrap();
        let mut faces = run.mesh().face_count();
        for step in 1..=7 {
            run.steps(1, |_| {}).unwrap();
            let m = run.mesh();
            let boundary = closed.then_some(0);
            assert_conforming(m, boundary, &format!("{defines:?}, step {step}"));
            assert!(m.face_count() >= faces);
            faces = m.face_count();
        }
        // Adaptive: fewer than half the faces of seven uniform bisections
        // (2^7 times the triangles).
        assert!(
            faces < soup.faces.len() * 2 * 128 / 2,
            "{defines:?}: {faces}"
        );
        assert!(faces > soup.faces.len() * 2, "{defines:?}: nothing refined");
    }
}

/// On the 4 × 4 grid in the unit square (16 quads, 32 triangles, 25
/// vertices), step 1 selects the block of the quad A = [0, ¼]², step 2
/// the right side of A, x = 0.25. Counted by hand:
/// * step 1 splits A's diagonal: one vertex (A's centre) and two faces,
///   34 faces and 26 vertices;
/// * step 2: x is the refinement edge of A's right triangle, but the
///   triangle across it is still half of the block B = [¼, ½] × [0, ¼],
///   so B's diagonal is split first (a vertex at B's centre, two faces),
///   then x (a vertex at the average of the diamond's corners (¼, 0),
///   (¼, ¼), A's centre and B's centre, which is (¼, ⅛); two faces):
///   38 faces and 28 vertices.
///
/// No vertex is smoothed in either step: no interior vertex has all its
/// faces split (`refined`), so the new vertices are where the averages say.
#[test]
fn a_guard_refines_its_region_and_the_closure_its_neighbours() {
    let g = grammar_text(
        "mesh: \"x.obj\";\nblocks: bisection;\nadaptive;\n\
         define at(e, x, y) = Length(avg(e) - point(x, y, 0)) < 0.01;\n\
         define wanted(e) = step == 1 ? at(e, 0.125, 0.125) : at(e, 0.25, 0.125);\n\
         E(e; block(e) && wanted(e)) | F^2 -> V(v = avg(ring(v))) || E^4 F^4;\n\
         E(e; block(e) && wanted(e)) | F -> V(v = avg(e)) || E^3 F^2;\n\
         V(v; !new(v) && refined(v)) | interior -> V(v = 0.5*v + 0.5*avg(w in ring(v) where !new(w)));\n",
    );
    let mut m = Mesh::from_soup(&shapes::quad_grid(4, 4)).unwrap();
    assert_eq!((m.face_count(), m.vertex_count()), (32, 25));
    let mut run = g.start(&mut m).unwrap();
    run.steps(1, |_| {}).unwrap();
    assert_eq!(
        (run.mesh().face_count(), run.mesh().vertex_count()),
        (34, 26)
    );
    assert_conforming(run.mesh(), Some(16), "step 1");
    run.steps(1, |_| {}).unwrap();
    let m = run.mesh();
    assert_eq!((m.face_count(), m.vertex_count()), (38, 28));
    assert_conforming(m, Some(16), "step 2");
    let has = |p: DVec3| m.vertices().any(|v| m.position(v) == p);
    for p in [
        DVec3::new(0.125, 0.125, 0.0),
        DVec3::new(0.375, 0.125, 0.0),
        DVec3::new(0.25, 0.125, 0.0),
    ] {
        assert!(has(p), "no vertex at {p}");
    }
    // The grid's 25 vertices are where they were.
    for j in 0..=4 {
        for i in 0..=4 {
            assert!(has(DVec3::new(i as f64 / 4.0, j as f64 / 4.0, 0.0)));
        }
    }
}

/// `area(e)` of a block's internal edge is the block's area: the grid's
/// quads have area 1/16 = 0.0625, a bisection halves a block, and a
/// boundary edge's area is its one face's. A threshold of 0.05 selects
/// every block in step 1 (64 faces, as uniform) and none after (blocks of
/// 0.03125); 0.03 selects every block in step 1 and in step 2 the 24
/// interior diamonds (the grid's interior edges, 0.03125) but not the 16
/// boundary half-diamonds (0.015625): 64 + 24 × 2 = 112 faces; then none.
#[test]
fn an_area_threshold_stops_where_blocks_get_small() {
    for (t, want) in [(0.05, [64, 64, 64]), (0.03, [64, 112, 112])] {
        let g = grammar_text(&format!(
            "mesh: \"x.obj\";\nblocks: bisection;\nadaptive;\n\
             E(e; block(e) && area(e) > {t}) | F^2 -> V(v = avg(ring(v))) || E^4 F^4;\n\
             E(e; block(e) && area(e) > {t}) | F -> V(v = avg(e)) || E^3 F^2;\n"
        ));
        let mut m = Mesh::from_soup(&shapes::quad_grid(4, 4)).unwrap();
        let mut run = g.start(&mut m).unwrap();
        for (k, n) in want.into_iter().enumerate() {
            run.steps(1, |_| {}).unwrap();
            assert_eq!(run.mesh().face_count(), n, "threshold {t}, step {}", k + 1);
            assert_conforming(run.mesh(), Some(16), "area");
        }
    }
}

/// `length(e)` and `angle(e)`: the grid's diagonals are √2/4 ≈ 0.354
/// long, so `length(e) > 0.35` selects them all and `length(e) > 0.36`
/// none. A grid folded by 45° along x = ½ (z = x - ½ beyond it) has
/// planar quads, so no block's triangles make an angle; after one uniform
/// step (`step == 1`) the diamonds are the old quad edges, and only the
/// four on the fold line have triangles on both sides of it, at 45°: they
/// alone are split in step 2, 64 + 4 × 2 = 72 faces.
#[test]
fn length_and_angle_guards() {
    // The boundary keeps its 16 edges: no boundary edge is a diamond's
    // diagonal before step 2, and none is selected there.
    let run = |guard: &str, soup: &PolygonSoup, steps: usize| {
        let g = grammar_text(&format!(
            "mesh: \"x.obj\";\nblocks: bisection;\nadaptive;\n\
             E(e; block(e) && ({guard})) | F^2 -> V(v = avg(ring(v))) || E^4 F^4;\n\
             E(e; block(e) && ({guard})) | F -> V(v = avg(e)) || E^3 F^2;\n"
        ));
        let mut m = Mesh::from_soup(soup).unwrap();
        g.run(&mut m, steps, |_| {}).unwrap();
        assert_conforming(&m, Some(16), guard);
        m.face_count()
    };
    let grid = shapes::quad_grid(4, 4);
    assert_eq!(run("length(e) > 0.35", &grid, 1), 64);
    assert_eq!(run("length(e) > 0.36", &grid, 1), 32);
    let mut folded = grid.clone();
    for p in &mut folded.positions {
        p.z = (p.x - 0.5).max(0.0);
    }
    assert_eq!(run("angle(e) > 1", &folded, 1), 32);
    assert_eq!(run("step == 1 || angle(e) > 1", &folded, 2), 72);
    assert_eq!(
        run(
            "step == 1 || angle(e) > 44.99 && angle(e) < 45.01",
            &folded,
            2
        ),
        72
    );
}

/// The closure reaches the boundary. On the 4 × 4 grid: step 1 splits
/// every block (64 faces); step 2 the diamond on x = ¼, y ∈ [0, ¼], the
/// right side of the corner quad A = [0, ¼]² (66 faces); step 3 selects
/// the edge from (¼, 0) to A's centre (⅛, ⅛), which the triangle at the
/// new vertex (¼, ⅛) would split next, but across it lies the triangle of
/// the boundary half-diamond on y = 0, x ∈ [0, ¼]: that boundary edge is
/// split first (one face more), then the selected edge (two): 69 faces.
/// Without a boundary split rule the run says what it needed.
#[test]
fn the_closure_splits_boundary_half_diamonds() {
    let text = |with_boundary: bool| {
        format!(
            "mesh: \"x.obj\";\nblocks: bisection;\nadaptive;\n\
             define at(e, x, y) = Length(avg(e) - point(x, y, 0)) < 0.01;\n\
             define wanted(e) = step == 1 || step == 2 && at(e, 0.25, 0.125) \
             || step == 3 && at(e, 0.1875, 0.0625);\n\
             E(e; block(e) && wanted(e)) | F^2 -> V(v = avg(ring(v))) || E^4 F^4;\n{}",
            if with_boundary {
                "E(e; block(e) && wanted(e)) | F -> V(v = avg(e)) || E^3 F^2;\n"
            } else {
                ""
            }
        )
    };
    let g = grammar_text(&text(true));
    let mut m = Mesh::from_soup(&shapes::quad_grid(4, 4)).unwrap();
    let mut run = g.start(&mut m).unwrap();
    for (step, (faces, boundary)) in [(64, 16), (66, 16), (69, 17)].into_iter().enumerate() {
        run.steps(1, |_| {}).unwrap();
        assert_eq!(run.mesh().face_count(), faces, "step {}", step + 1);
        assert_conforming(run.mesh(), Some(boundary), "boundary closure");
    }
    // The boundary vertex the closure made is the edge's midpoint.
    let m = run.mesh();
    assert!(m
        .vertices()
        .any(|v| m.position(v) == DVec3::new(0.125, 0.0, 0.0)));

    let g = grammar_text(&text(false));
    let mut m = Mesh::from_soup(&shapes::quad_grid(4, 4)).unwrap();
    let err = g.run(&mut m, 3, |_| {}).unwrap_err();
    let msg = g.render_error(&err);
    assert!(
        msg.contains("at step 3")
            && msg.contains("split first, but no boundary split rule is written next to this one"),
        "{msg}"
    );
    assert!(msg.contains("g.lsys:6:"), "{msg}");
}

/// Guards of every kind at random places: conforming after every step, on
/// the closed torus (closed stays closed) and on the open grid.
#[test]
fn random_guards_stay_conforming() {
    let mut seed = 0x2545_F491_4F6C_DD1Du64;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    for k in 0..8 {
        let (x, y, z, r) = (next() * 2.0 - 1.0, next() * 2.0 - 1.0, next() * 0.4, next());
        let guard = match k % 4 {
            0 => format!("Length(avg(e) - point({x}, {y}, {z})) < {r}"),
            1 => format!("Dot(avg(e) - point({x}, {y}, {z}), point(1, 0.5, 0.25)) > 0"),
            2 => format!("step < 3 || angle(e) > {}", 2.0 + 10.0 * r),
            _ => format!("area(e) > {} && avg(e).x > {x}", 0.002 * r),
        };
        let g = grammar_text(&format!(
            "mesh: \"x.obj\";\nblocks: bisection;\nadaptive;\n\
             E(e; block(e) && ({guard})) | F^2 -> V(v = avg(ring(v))) || E^4 F^4;\n\
             E(e; block(e) && ({guard})) | F -> V(v = avg(e)) || E^3 F^2;\n\
             V(v; !new(v) && refined(v)) | interior -> \
             V(v = 0.5*v + 0.5*avg(w in ring(v) where !new(w)));\n"
        ));
        for (soup, closed) in [
            (jitter(shapes::quad_torus(8, 6), k), true),
            (shapes::quad_grid(5, 5), false),
        ] {
            let mut m = Mesh::from_soup(&soup).unwrap();
            let mut run = g.start(&mut m).unwrap();
            for step in 1..=6 {
                run.steps(1, |_| {}).unwrap();
                assert_conforming(
                    run.mesh(),
                    closed.then_some(0),
                    &format!("{guard}, step {step}"),
                );
            }
        }
    }
}

/// `adaptive: incremental;` tests only the diamonds at the vertices made
/// since the step before. Where a guard reads only positions that never
/// move (no vertex rule) and not the step, a diamond that was not selected
/// when it appeared never is, so the result is `adaptive;`'s, to the bit;
/// where every block is selected it is `four-eight.lsys`'s.
#[test]
fn incremental_matching_agrees_where_it_must() {
    let text = |how: &str, guard: &str, smooth: bool| {
        format!(
            "mesh: \"x.obj\";\nblocks: bisection;\n{how}\n\
             E(e; block(e) && ({guard})) | F^2 -> V(v = avg(ring(v))) || E^4 F^4;\n\
             E(e; block(e) && ({guard})) | F -> V(v = avg(e)) || E^3 F^2;\n{}",
            if smooth {
                "V(v; !new(v) && refined(v)) | interior -> \
                 V(v = 0.5*v + 0.5*avg(w in ring(v) where !new(w)));\n"
            } else {
                ""
            }
        )
    };
    for (guard, smooth, soup) in [
        (
            "Length(avg(e) - point(0.3, 0.6, 0)) < 0.2",
            false,
            shapes::quad_grid(6, 6),
        ),
        (
            "area(e) > 0.004 && avg(e).x > 0.2",
            false,
            jitter(shapes::quad_torus(8, 6), 3),
        ),
        ("true", true, jitter(shapes::quad_torus(8, 6), 5)),
        ("true", true, shapes::quad_grid(5, 4)),
    ] {
        let full = grammar_text(&text("adaptive;", guard, smooth));
        let incr = grammar_text(&text("adaptive: incremental;", guard, smooth));
        let faces = in_step(&full, &incr, &soup, 7, &format!("{guard}: incremental"));
        assert!(faces > 2 * soup.faces.len(), "{guard}");
    }
    // Selecting everything, with smoothing, is uniform refinement.
    let uniform = grammar_file("surfaces/four-eight.lsys", &[]);
    let incr = grammar_text(&text("adaptive: incremental;", "true", true));
    let mut a = Mesh::from_soup(&torus_obj()).unwrap();
    let mut b = a.clone();
    uniform.run(&mut a, 5, |_| {}).unwrap();
    incr.run(&mut b, 5, |_| {}).unwrap();
    assert!(fingerprint(&a) == fingerprint(&b));
}

/// What incremental matching gives up: a guard that turns true later for
/// an old diamond (here, only from step 3 on) is never tested again, so
/// nothing is refined; `adaptive;` splits every block at step 3.
#[test]
fn incremental_matching_does_not_look_back() {
    let text = |how: &str| {
        format!(
            "mesh: \"x.obj\";\nblocks: bisection;\n{how}\n\
             E(e; block(e) && step >= 3) | F^2 -> V(v = avg(ring(v))) || E^4 F^4;\n\
             E(e; block(e) && step >= 3) | F -> V(v = avg(e)) || E^3 F^2;\n"
        )
    };
    let count = |how: &str| {
        let g = grammar_text(&text(how));
        let mut m = Mesh::from_soup(&shapes::quad_grid(4, 4)).unwrap();
        g.run(&mut m, 3, |_| {}).unwrap();
        m.face_count()
    };
    assert_eq!(count("adaptive;"), 64);
    assert_eq!(count("adaptive: incremental;"), 32);
}

/// `area(f)`: the grid's triangles have area 1/32 = 0.03125, so a face
/// split guarded by `area(f) > 0.03` splits all 32 (96 faces) and one
/// guarded by `area(f) > 0.032` none.
#[test]
fn area_of_a_face() {
    for (t, want) in [(0.03, 96), (0.032, 32)] {
        let g = grammar_text(&format!(
            "mesh: \"x.obj\";\nF(f; area(f) > {t}) -> V(v = avg(f)) || E^3 F^3;\n"
        ));
        let mut m = Mesh::from_soup(&shapes::quad_grid(4, 4)).unwrap();
        g.run(&mut m, 1, |_| {}).unwrap();
        assert_eq!(m.face_count(), want, "threshold {t}");
    }
}

/// The C4 scheme on the scanned bunny (c4.lsys: pairing by a maximum
/// matching, then 4-8 bisection): with `adaptive;` and every block
/// selected it is c4.lsys to the bit after each of three steps; refined
/// near one of its vertices it stays a conforming, closed 4-8 mesh.
#[test]
fn bunny_adaptive_c4() {
    let rules = |guard: &str| {
        format!(
            "mesh: \"x.obj\";\nblocks: bisection;\nadaptive;\ninit: match_blocks;\n\
             define velh(v) = 0.5*v + 0.5*avg(w in ring(v) where !new(w));\n\
             E(e; block(e) && ({guard})) | F^2 -> V(v = avg(ring(v))) || E^4 F^4;\n\
             V(v; !new(v) && refined(v)) | interior -> V(v = velh(v));\n"
        )
    };
    let soup = subgram::mesh::io::read(&lsys("meshes/bunny.obj")).unwrap();
    let uniform = grammar_file("surfaces/c4.lsys", &[]);
    let all = grammar_text(&rules("true"));
    in_step(
        &uniform,
        &all,
        &soup,
        3,
        "bunny: adaptive with everything selected, against c4.lsys",
    );
    let p = soup.positions[0];
    let near = grammar_text(&rules(&format!(
        "Length(avg(e) - point({}, {}, {})) < 1.5",
        p.x, p.y, p.z
    )));
    let mut m = Mesh::from_soup(&soup).unwrap();
    let mut run = near.start(&mut m).unwrap();
    let mut last = run.mesh().face_count();
    for step in 1..=4 {
        run.steps(1, |_| {}).unwrap();
        assert_conforming(run.mesh(), Some(0), &format!("bunny, step {step}"));
        assert!(
            run.mesh().face_count() > last,
            "step {step} refined nothing"
        );
        last = run.mesh().face_count();
    }
    assert!(last < soup.faces.len() * 16 / 2, "{last}");
}
