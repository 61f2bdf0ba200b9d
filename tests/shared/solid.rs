//! The 3D geometry of the vlab models `monopodial/` and `leaf-rnd/`
//! (`line style: cylinder`, materials): stems become tubes and leaves
//! Bézier surfaces. The expected counts come from the interpreted word
//! (how many `F` and `Surface` modules it holds) and the tessellation
//! that `draw/solid/` documents: lpfg's 16 contour sides (neither view
//! file sets them), tubes that go on through branch points, 10 × 10 quads
//! per patch (the view file gives no divisions); the bounds from the
//! turtle's own lines (the 2D drawing of the same word).

use subgram::draw::solid::SolidOptions;
use subgram::draw::Event;
use subgram::scene3::Scene3;
use subgram::{LoadOptions, System};

use crate::shared;

/// The model's curve: its geometry, and the number of modules of each
/// name in `names` in its interpreted word, and its 2D events.
fn model(name: &str, names: &[&str]) -> (Scene3, Vec<usize>, Vec<Event>) {
    let dir = shared().join("corpus/vlab-models").join(name);
    let System::Curve(c) =
        subgram::load(&dir, &LoadOptions::default()).unwrap_or_else(|e| panic!("{name}: {e}"))
    else {
        panic!("{name} is an L-system")
    };
    let mut run = c.run(Default::default()).unwrap();
    let word = run.interpreted().unwrap();
    let p = &c.program;
    let counts = names
        .iter()
        .map(|n| {
            word.modules(&p.alphabet, &p.structs)
                .filter(|(s, _)| p.alphabet.name(*s) == *n)
                .count()
        })
        .collect();
    let scene = run.solid(&SolidOptions::default()).unwrap();
    let events = run.events().unwrap();
    (scene, counts, events)
}

/// The bounds of the turtle's lines.
fn line_bounds(events: &[Event]) -> (glam::DVec3, glam::DVec3) {
    let mut pts = events
        .iter()
        .flat_map(|e| e.segments())
        .flat_map(|(a, b)| [a, b]);
    let first = pts.next().expect("lines");
    pts.fold((first, first), |(lo, hi), p| (lo.min(p), hi.max(p)))
}

#[test]
fn monopodial_has_tubes_for_its_stem_and_leaves() {
    let (s, counts, events) = model("monopodial", &["F", "IncColor"]);
    let (f, leaves) = (counts[0], counts[1]);
    assert!(f > 100 && leaves > 50, "{f} segments, {leaves} leaves");
    // Material 1 for the stem, 2 for the leaves (`IncColor`).
    let names: Vec<&str> = s.looks.iter().map(|l| l.name.as_str()).collect();
    assert_eq!(names, ["material1", "material2"]);
    // Every segment is 16 × 2 triangles; the stem is one tube through its
    // branch points and each leaf a tube of its own, each with a ring
    // more than its segments.
    assert_eq!(s.triangle_count(), 32 * f);
    assert_eq!(s.vertex_count(), 16 * (f + 1 + leaves));
    // Around the lines by the tubes' radius (`SetWidth(0.05)`) at most.
    let (lo, hi) = line_bounds(&events);
    let (a, b) = s.bounds().unwrap();
    for k in 0..3 {
        assert!((a[k] as f64 - lo[k]) <= 1e-6 && lo[k] - a[k] as f64 <= 0.025 + 1e-6);
        assert!((hi[k] - b[k] as f64) <= 1e-6 && b[k] as f64 - hi[k] <= 0.025 + 1e-6);
    }
}

#[test]
fn leaf_rnd_has_a_tube_stem_and_surface_leaves() {
    let (s, counts, events) = model("leaf-rnd", &["F", "Surface"]);
    let (f, leaves) = (counts[0], counts[1]);
    assert_eq!(leaves, 21, "ten pairs of leaflets and the terminal one");
    let names: Vec<&str> = s.looks.iter().map(|l| l.name.as_str()).collect();
    assert_eq!(names, ["material1", "material2"]);
    // The stem: one tube of f segments. The leaves: `leaf.s` has one
    // patch, cut 10 × 10: 121 vertices, 200 triangles each.
    let (stem, leaf) = (&s.meshes[0], &s.meshes[1]);
    assert_eq!(
        (stem.positions.len(), stem.triangles.len()),
        (16 * (f + 1), 32 * f)
    );
    assert_eq!(
        (leaf.positions.len(), leaf.triangles.len()),
        (121 * leaves, 200 * leaves)
    );
    // The leaves reach well beyond the stem's line on both sides.
    let (lo, hi) = line_bounds(&events);
    let (a, b) = leaf.bounds().unwrap();
    assert!(
        lo.x.abs() < 1e-9 && hi.x.abs() < 1e-9,
        "the stem is straight up"
    );
    assert!(a.x < -2.5 && b.x > 2.5, "leaves from {a} to {b}");
    assert!(
        b.y as f64 > hi.y,
        "the terminal leaflet is above the stem's top"
    );
}
