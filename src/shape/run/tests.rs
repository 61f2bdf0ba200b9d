//! Tests of a whole derivation: the order of rewriting, and the limits on
//! a smoothing group's faces and on the faces the shapes hold.

use super::*;

fn grammar(text: &str) -> ShapeGrammar {
    let front = crate::syntax::source::front("t.lsys", text.to_string(), &[]).unwrap();
    super::super::from_front(front, None).unwrap_or_else(|e| panic!("{e}"))
}

fn obj(g: &ShapeGrammar, fifo: bool, seed: u32) -> String {
    let opts = ShapeOptions {
        seed,
        fifo,
        ..Default::default()
    };
    let never = Deadline::after(std::time::Duration::from_secs(3600));
    let t = derive(g, &opts, &never).unwrap_or_else(|e| panic!("{}", e.message));
    super::super::output::obj(g, &t, "t.mtl").0
}

/// Algorithm 1 chooses "a shape" to rewrite: taking the newest first or
/// the oldest first gives the same model, bit for bit, stochastic
/// rules and smoothing groups included.
#[test]
fn the_order_of_rewriting_does_not_matter() {
    let text = "axiom: lot(20, 12) Lot\n\
         Lot --> extrude(9) Mass\n\
         Mass --> comp(f) { top : Roof | side : Facade | bottom : NIL }\n\
         Facade --> split(y) { ~3 : Floor }*\n\
         Floor --> split(x) { ~2.5 : Tile }*\n\
         1 : Tile ~> extrude(-0.2) Dark : 0.6\n\
         2 : Tile ~> split(x) { ~1 : Wall | ~1 : Lit(ran(1)) } : 0.4\n\
         Roof --> split(x) { ~1 : R | ~1 : R }\n\
         R --> Subdivide(1) { Done(ran(1)) }\n\
         Done(k) --> t(0, k, 0)\n";
    let g = grammar(text);
    for seed in [1, 2, 3] {
        assert_eq!(obj(&g, false, seed), obj(&g, true, seed));
    }
    assert_ne!(obj(&g, false, 1), obj(&g, false, 2));
}

fn derive_err(g: &ShapeGrammar, opts: &ShapeOptions) -> ShapeError {
    let never = Deadline::after(std::time::Duration::from_secs(3600));
    match derive(g, opts, &never) {
        Ok(_) => panic!("the derivation succeeded"),
        Err(e) => e,
    }
}

/// The text at a span of the grammar.
fn at(g: &ShapeGrammar, span: Span) -> String {
    let text = &g.sources.get(span.file).text;
    text[span.start as usize..span.end as usize].to_string()
}

/// A smoothing group's subdivision stops at its scheme's face limit,
/// which load sets to at most MAX_SMOOTH_FACES, with the message at
/// the `Subdivide`. √3 on a box: 12 triangles, then 36, then 108 (3
/// per triangle a step, by hand), past a limit of 100.
#[test]
fn subdivision_stops_at_the_face_limit() {
    let mut g = grammar("axiom: s(1, 1, 1) i(\"box\") A\nA --> Subdivide(2) { B }\n");
    assert_eq!(g.schemes[0].grammar.max_faces, MAX_SMOOTH_FACES);
    g.schemes[0].grammar.max_faces = 100;
    let e = derive_err(&g, &ShapeOptions::default());
    assert!(e.message.contains("past the limit of 100"), "{}", e.message);
    assert_eq!(at(&g, e.span), "Subdivide(2) { B }");
    g.schemes[0].grammar.max_faces = 108;
    obj(&g, false, 1);
}

/// The faces all shapes hold together are bounded: a box's 6 faces in
/// the axiom's shape and each child's copy are 6 each, 18 in all, so a
/// limit of 17 stops at the third shape, at its symbol, and 18 does not.
#[test]
fn held_faces_are_bounded() {
    let g = grammar("axiom: s(1, 1, 1) i(\"box\") A\nA --> B C\n");
    let opts = ShapeOptions {
        max_faces: 17,
        ..Default::default()
    };
    let e = derive_err(&g, &opts);
    assert!(e.message.contains("hold 18 faces"), "{}", e.message);
    assert_eq!(at(&g, e.span), "C");
    let opts = ShapeOptions {
        max_faces: 18,
        ..Default::default()
    };
    let never = Deadline::after(std::time::Duration::from_secs(3600));
    derive(&g, &opts, &never).unwrap_or_else(|e| panic!("{}", e.message));
}
