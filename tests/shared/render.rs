//! Pictures of the corpus programs: the SVG's structure against what the
//! word implies, and a PNG against one that was looked at.

use subgram::render::{png, svg};
use subgram::FigureOptions;

use crate::corpus;
use crate::golden::{self, Kind};
use crate::support::*;

#[test]
fn koch_svg_has_one_segment_per_f() {
    let s = figure(&corpus("01-quadratic-Koch.l"), FigureOptions::default());
    let (segments, circles, polygons) = svg_counts(&svg::render(&s));
    assert_eq!((segments, circles, polygons), (4096, 0, 0));
}

#[test]
fn b_spline_svg_has_a_sphere_and_a_line_per_point() {
    // Interpretation: P -> MoveTo2f Sphere, P < E > P -> Line2f.
    let s = figure(&corpus("B-spline.l"), FigureOptions::default());
    let (segments, circles, _) = svg_counts(&svg::render(&s));
    assert_eq!((segments, circles), (32, 32));
}

#[test]
fn png_matches_the_stored_fern() {
    let s = figure(&corpus("07-fractal-ferns.l"), sized(240, 240));
    golden::check(
        "tests/golden/07-fractal-ferns.png",
        &png::render(&s).unwrap(),
        Kind::Png,
    );
}
