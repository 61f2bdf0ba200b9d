//! Surface grammars against the published masks: the expected positions
//! are computed here from the base mesh with the masks of Loop and
//! Kobbelt, not by the grammar engine.

use glam::DVec3;
use subgram::mesh::{shapes, Mesh, PolygonSoup, VertexId};

use crate::support::*;

struct Rng(u64);

impl Rng {
    fn unit(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// The soup with every position moved at random, so that masks cannot hide.
fn jitter(mut s: PolygonSoup, seed: u64) -> PolygonSoup {
    let mut r = Rng(seed);
    for p in &mut s.positions {
        *p += DVec3::new(r.unit(), r.unit(), r.unit()) * 0.3 - 0.15;
    }
    s
}

fn grammar(file: &str) -> subgram::surface::Grammar {
    subgram::surface::load_file(&lsys(file), &[]).unwrap_or_else(|e| panic!("{}", e.render()))
}

fn run(file: &str, base: &Mesh) -> Mesh {
    let g = grammar(file);
    let mut m = base.clone();
    g.run(&mut m, 1, |_| {})
        .unwrap_or_else(|e| panic!("{}", g.render_error(&e)));
    m.validate().unwrap();
    m
}

/// The new vertex adjacent to all of `parents` (ids above `old_count`).
fn child(m: &Mesh, parents: &[VertexId], old_count: u32) -> VertexId {
    m.one_ring(parents[0])
        .filter(|w| w.0 >= old_count)
        .find(|w| {
            parents[1..]
                .iter()
                .all(|p| m.find_halfedge(*w, *p).is_some())
        })
        .expect("a child vertex")
}

fn loop_beta(n: f64) -> f64 {
    (5.0 / 8.0 - (3.0 / 8.0 + 0.25 * (2.0 * std::f64::consts::PI / n).cos()).powi(2)) / n
}

#[test]
fn loop_grammar_equals_loop_masks_on_a_closed_mesh() {
    let base = Mesh::from_soup(&jitter(shapes::icosphere(1), 3)).unwrap();
    let old = base.vertex_count() as u32;
    let m = run("surfaces/loop.lsys", &base);
    assert_eq!(m.face_count(), 4 * base.face_count());
    let p = |v: VertexId| base.position(v);
    let mut worst: f64 = 0.0;
    // Old vertices: (1 - n beta) v + beta sum(neighbours), Loop's beta.
    for v in base.vertices() {
        let n = base.valence(v) as f64;
        let b = loop_beta(n);
        let want = (1.0 - n * b) * p(v) + b * base.one_ring(v).map(p).sum::<DVec3>();
        worst = worst.max(m.position(v).distance(want));
    }
    // Edge points: 3/8, 3/8, 1/8, 1/8.
    for e in base.edges() {
        let h = e.halfedge();
        let (a, b) = (base.from(h), base.to(h));
        let c = base.to(base.next(h));
        let d = base.to(base.next(h.twin()));
        let want = 0.375 * (p(a) + p(b)) + 0.125 * (p(c) + p(d));
        worst = worst.max(m.position(child(&m, &[a, b], old)).distance(want));
    }
    assert!(
        worst < 1e-12,
        "largest difference from Loop's masks: {worst}"
    );
}

#[test]
fn loop_grammar_follows_the_boundary_curve_rules() {
    let base = Mesh::from_soup(&jitter(shapes::triangle_grid(4, 3), 11)).unwrap();
    let old = base.vertex_count() as u32;
    let m = run("surfaces/loop.lsys", &base);
    let p = |v: VertexId| base.position(v);
    for v in base.vertices() {
        let want = if base.is_boundary_vertex(v) {
            // 3/4 v + 1/8 (a + b) of the boundary neighbours.
            let nb: Vec<VertexId> = base
                .outgoing_halfedges(v)
                .filter(|h| base.is_boundary_edge(h.edge()))
                .map(|h| base.to(h))
                .collect();
            assert_eq!(nb.len(), 2);
            0.75 * p(v) + 0.125 * (p(nb[0]) + p(nb[1]))
        } else {
            let n = base.valence(v) as f64;
            let b = loop_beta(n);
            (1.0 - n * b) * p(v) + b * base.one_ring(v).map(p).sum::<DVec3>()
        };
        assert!(m.position(v).distance(want) < 1e-12, "vertex {}", v.0);
    }
    for e in base.edges() {
        let h = e.halfedge();
        let (a, b) = (base.from(h), base.to(h));
        let want = if base.is_boundary_edge(e) {
            0.5 * (p(a) + p(b))
        } else {
            let c = base.to(base.next(h));
            let d = base.to(base.next(h.twin()));
            0.375 * (p(a) + p(b)) + 0.125 * (p(c) + p(d))
        };
        assert!(
            m.position(child(&m, &[a, b], old)).distance(want) < 1e-12,
            "edge {}",
            e.0
        );
    }
}

#[test]
fn sqrt3_grammar_equals_kobbelts_masks() {
    let base = Mesh::from_soup(&jitter(shapes::icosphere(1), 5)).unwrap();
    let old = base.vertex_count() as u32;
    let m = run("surfaces/sqrt3.lsys", &base);
    assert_eq!(m.face_count(), 3 * base.face_count());
    let p = |v: VertexId| base.position(v);
    for v in base.vertices() {
        let n = base.valence(v) as f64;
        let a = (4.0 - 2.0 * (2.0 * std::f64::consts::PI / n).cos()) / 9.0;
        let want = (1.0 - a) * p(v) + a / n * base.one_ring(v).map(p).sum::<DVec3>();
        assert!(m.position(v).distance(want) < 1e-12, "vertex {}", v.0);
        assert_eq!(
            m.valence(v),
            base.valence(v),
            "old vertices keep their valence after the flips"
        );
    }
    for f in base.faces() {
        let vs = base.face_vertices(f);
        let want = (p(vs[0]) + p(vs[1]) + p(vs[2])) / 3.0;
        assert!(
            m.position(child(&m, &vs, old)).distance(want) < 1e-12,
            "face {}",
            f.0
        );
    }
    // Two steps: every face splits in three and the old edges turn.
    let g = grammar("surfaces/sqrt3.lsys");
    let mut two = base.clone();
    g.run(&mut two, 2, |_| {}).unwrap();
    two.validate().unwrap();
    assert_eq!(two.face_count(), 9 * base.face_count());
}

#[test]
fn grammar_errors_point_at_the_rule() {
    let bad = subgram::surface::load_str("g.lsys", "F(f) -> V(v = avg(f)) || E^4 F^4;\n", &[])
        .unwrap_err()
        .render();
    assert!(
        bad.starts_with("g.lsys:1:1: error: this is not one of the rules of paper 000"),
        "{bad}"
    );
    let bad = subgram::surface::load_str("g.lsys", "V(v; l(v) < c) -> V(v = v + 1);\n", &[])
        .unwrap_err()
        .render();
    assert!(
        bad.contains("g.lsys:1:25: error: type error: cannot apply `+` to a point and a number"),
        "{bad}"
    );
    let bad = subgram::surface::load_str("g.lsys", "V(v) -> V(v = smooth(v));\n", &[])
        .unwrap_err()
        .render();
    assert!(bad.contains("unknown function `smooth`"), "{bad}");
    let bad = subgram::surface::load_str("g.lsys", "E(e) | F^3 -> E || F^2;\n", &[])
        .unwrap_err()
        .render();
    assert!(bad.contains("not one of the rules"), "{bad}");
}
