//! `subgram reverse`: exact inverses, partitions, odd lengths, details,
//! inputs and their errors, and a real traced outline.

use glam::DVec2;
use subgram::reverse::{self, Contour, Phase, ReverseOptions, Scheme};

use crate::support::*;

fn contour(points: Vec<DVec2>, closed: bool) -> Contour {
    Contour {
        points,
        closed,
        source: "test".into(),
    }
}

fn opts(steps: usize, phase: Phase, details: bool) -> ReverseOptions {
    ReverseOptions {
        steps,
        phase,
        details,
    }
}

/// A closed polygon with dyadic coordinates: Chaikin's weights keep them
/// exact, so the inverse can be checked with `==`.
fn dyadic_polygon(n: usize) -> Vec<DVec2> {
    (0..n)
        .map(|i| {
            let t = i as f64;
            DVec2::new(
                ((t * 7.0) % 13.0) - 6.0,
                ((t * 5.0) % 11.0) - 5.0 + 0.5 * (i % 3) as f64,
            )
        })
        .collect()
}

#[test]
fn chaikin_then_reverse_is_exact_for_both_partitions() {
    let s = Scheme::builtin(true);
    let coarse = dyadic_polygon(9);
    for steps in 1..=3 {
        let fine = s.forward(&coarse, steps).unwrap();
        // Matrix (8) built here agrees with the scheme's forward group.
        assert_eq!(fine, iterate(&coarse, steps, chaikin_closed));
        let r = reverse::reverse(
            &s,
            &contour(fine.clone(), true),
            &opts(steps, Phase::Fixed(0), false),
        )
        .unwrap();
        assert_eq!(r.coarse, coarse, "phase 0, {steps} steps");
        // The same fine curve starting one point later pairs with phase 1.
        if steps == 1 {
            let mut shifted = fine.clone();
            shifted.rotate_right(1);
            let r = reverse::reverse(
                &s,
                &contour(shifted, true),
                &opts(1, Phase::Fixed(1), false),
            )
            .unwrap();
            assert_eq!(r.coarse, coarse, "phase 1");
        }
    }
}

#[test]
fn auto_phase_finds_the_aligned_partition() {
    let s = Scheme::builtin(true);
    let coarse = dyadic_polygon(10);
    let mut fine = s.forward(&coarse, 1).unwrap();
    fine.rotate_right(1);
    let c = contour(fine, true);
    let r = reverse::reverse(&s, &c, &opts(1, Phase::Auto, false)).unwrap();
    assert_eq!(r.steps[0].phase, 1);
    assert_eq!(r.coarse, coarse);
    // The wrong partition is measurably worse.
    let wrong = reverse::reverse(&s, &c, &opts(1, Phase::Fixed(0), false)).unwrap();
    assert!(reverse::report(&s, &c, &wrong).unwrap().reverse.rms > 1e-3);
    assert_eq!(reverse::report(&s, &c, &r).unwrap().reverse.rms, 0.0);
}

#[test]
fn open_chaikin_then_reverse_is_exact() {
    let s = Scheme::builtin(false);
    let coarse: Vec<DVec2> = dyadic_polygon(8);
    for steps in 1..=3 {
        let fine = s.forward(&coarse, steps).unwrap();
        assert_eq!(
            fine,
            iterate(&coarse, steps, chaikin_open),
            "the forward group is matrix (27)"
        );
        let r =
            reverse::reverse(&s, &contour(fine, false), &opts(steps, Phase::Auto, false)).unwrap();
        assert_eq!(r.coarse, coarse, "{steps} steps");
    }
    // Any data, not only dyadic: exact up to rounding.
    let wavy: Vec<DVec2> = (0..11)
        .map(|i| DVec2::new(i as f64 * 0.731, (i as f64 * 1.3).sin()))
        .collect();
    let fine = s.forward(&wavy, 2).unwrap();
    let r = reverse::reverse(&s, &contour(fine, false), &opts(2, Phase::Auto, false)).unwrap();
    assert_points_eq(&r.coarse, &wavy, 1e-12);
}

#[test]
fn odd_levels_drop_their_flattest_point_and_details_restore_it() {
    let s = Scheme::builtin(true);
    // 13 points on a circle plus one exactly on a chord: the flattest.
    let mut pts: Vec<DVec2> = (0..13)
        .map(|i| {
            let t = i as f64 / 13.0 * std::f64::consts::TAU;
            DVec2::new(t.cos(), t.sin()) * 10.0
        })
        .collect();
    let mid = (pts[4] + pts[5]) * 0.5;
    pts.insert(5, mid);
    pts.push(DVec2::new(10.0, -0.3)); // 15 points: odd
    let c = contour(pts.clone(), true);
    let r = reverse::reverse(&s, &c, &opts(1, Phase::Auto, true)).unwrap();
    assert!(r.steps[0].dropped);
    assert_eq!((r.steps[0].fine, r.coarse.len()), (14, 7));
    let d = r.details.unwrap();
    assert_eq!(d.levels[0].dropped, Some((5, [mid.x, mid.y])));
    let back = reverse::reconstruct(&s, &r.coarse, &d, None).unwrap();
    assert_points_eq(&back, &pts, 1e-9);
}

#[test]
fn a_contour_too_short_for_the_steps_is_refused() {
    let s = Scheme::builtin(true);
    let c = contour(dyadic_polygon(12), true);
    let e = reverse::reverse(&s, &c, &opts(3, Phase::Auto, false)).unwrap_err();
    assert_eq!(
        e.to_string(),
        "after 2 step(s) the contour has 3 points; step 3 needs at least 6: ask for fewer steps"
    );
}

/// The horse silhouette of scikit-image (CC0, see tests/data/README.md):
/// a real outline traced from a raster, reduced like the leaf of Fig. 9.
#[test]
fn a_traced_outline_reduces_and_restores_losslessly() {
    let c = reverse::input::read(&root().join("tests/data/horse.png")).unwrap();
    assert!(c.closed);
    assert!(
        (2000..4000).contains(&c.points.len()),
        "{} points",
        c.points.len()
    );
    let s = Scheme::builtin(true);
    let r = reverse::reverse(&s, &c, &opts(4, Phase::Auto, true)).unwrap();
    let counts: Vec<usize> = r.steps.iter().map(|st| st.coarse).collect();
    assert_eq!(*counts.last().unwrap(), r.coarse.len());
    assert!(r.coarse.len() * 16 <= c.points.len() + 16);
    let rep = reverse::report(&s, &c, &r).unwrap();
    // Reverse subdivision beats decimation at the same number of points.
    assert!(
        rep.reverse.rms * 1.3 < rep.decimation.rms,
        "{:?} vs {:?}",
        rep.reverse,
        rep.decimation
    );
    assert!(
        rep.reverse.rms < 1.0,
        "within a pixel on average: {:?}",
        rep.reverse
    );
    let d = r.details.unwrap();
    let back = reverse::reconstruct(&s, &r.coarse, &d, None).unwrap();
    assert_points_eq(&back, &c.points, 1e-9);
    // Intermediate levels have the sizes the steps reported.
    for k in 1..4 {
        let lvl = reverse::reconstruct(&s, &r.coarse, &d, Some(k)).unwrap();
        let st = &r.steps[4 - k];
        assert_eq!(lvl.len(), st.fine + st.dropped as usize, "level {k}");
    }
}

#[test]
fn tracing_a_disc_gives_its_circle() {
    // A disc of radius 40 drawn here with tiny-skia, traced back.
    let mut pm = tiny_skia::Pixmap::new(120, 100).unwrap();
    pm.fill(tiny_skia::Color::WHITE);
    let mut paint = tiny_skia::Paint::default();
    paint.set_color_rgba8(0, 0, 0, 255);
    paint.anti_alias = true;
    let path = tiny_skia::PathBuilder::from_circle(60.0, 50.0, 40.0).unwrap();
    pm.fill_path(
        &path,
        &paint,
        tiny_skia::FillRule::Winding,
        tiny_skia::Transform::identity(),
        None,
    );
    let c = reverse::input::read_png("disc.png", &pm.encode_png().unwrap()).unwrap();
    // Pixel centres sit at integer coordinates, so the disc's centre is at
    // (59.5, 49.5) with y flipped: (59.5, 99 - 49.5).
    let centre = DVec2::new(59.5, 49.5);
    for p in &c.points {
        let r = p.distance(centre);
        assert!((r - 40.0).abs() < 0.6, "{p} is {r} from the centre");
    }
    let area = subgram::reverse::trace::signed_area2(&c.points).abs() / 2.0;
    let want = std::f64::consts::PI * 1600.0;
    assert!((area - want).abs() / want < 0.01, "area {area}");
}

#[test]
fn svg_shapes_are_read() {
    let svg = r#"<svg xmlns="http://www.w3.org/2000/svg">
      <polyline points="0,0 1,1"/>
      <path d="M 10 10 l 5 0 v 5 H 10 z"/>
      <polygon points="0,0 4,0 4,4 0,4 -1,2"/>
    </svg>"#;
    let c = reverse::input::read_svg("t.svg", svg).unwrap();
    // The polygon has the most points; y is flipped.
    assert!(c.closed);
    assert_eq!(c.points[1], DVec2::new(4.0, 0.0));
    assert_eq!(c.points[2], DVec2::new(4.0, -4.0));
    let path_only = r#"<svg><path d="M10,10 l5,0 v5 h-5 Z"/></svg>"#;
    let c = reverse::input::read_svg("p.svg", path_only).unwrap();
    assert_eq!(
        c.points,
        vec![
            DVec2::new(10.0, -10.0),
            DVec2::new(15.0, -10.0),
            DVec2::new(15.0, -15.0),
            DVec2::new(10.0, -15.0)
        ]
    );
    assert!(c.closed);
}

#[test]
fn bad_inputs_get_clear_errors_naming_the_file_and_line() {
    let dir = std::env::temp_dir().join(format!("subgram-rev-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let cases: &[(&str, &[u8], &str)] = &[
        ("empty.txt", b"", "empty.txt: error: the file has no points"),
        (
            "one.txt",
            b"1 2\n",
            "one.txt: error: the contour has 1 point(s); at least 3 are needed",
        ),
        (
            "text.csv",
            b"x,y\n1,2\n3,abc\n",
            "text.csv:3:3: error: expected two numbers `x y`, but `abc` is not a number\n  |\n3 | 3,abc\n  |   ^^^",
        ),
        (
            "nan.txt",
            b"1 2\nNaN 3\n4 5\n",
            "nan.txt:2:1: error: the point (NaN, 3) is not finite\n  |\n2 | NaN 3\n  | ^^^",
        ),
        (
            "none.svg",
            b"<svg><circle r=\"3\"/></svg>",
            "none.svg: error: the SVG has no usable polygon, polyline or path",
        ),
        (
            "curve.svg",
            b"<svg>\n<path d=\"M0 0 C 1 1 2 2 3 3\"/></svg>",
            "curve.svg:2:15: error: path command `C` (a curve) is not supported",
        ),
        (
            "broken.png",
            b"\x89PNG\r\n\x1a\nnot really",
            "broken.png: error: cannot read the PNG image",
        ),
        (
            "blank.png",
            b"",
            "blank.png: error: cannot read the PNG image",
        ),
    ];
    for (name, bytes, want) in cases {
        let p = dir.join(name);
        std::fs::write(&p, bytes).unwrap();
        let e = reverse::input::read(&p).unwrap_err().to_string();
        let e = e.replace(&format!("{}/", dir.display()), "");
        assert!(e.starts_with(want), "{name}: {e}");
    }
}

#[test]
fn the_command_writes_coarse_points_report_figure_and_details() {
    let dir = std::env::temp_dir().join(format!("subgram-rev-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("coarse.csv");
    let fig = dir.join("fig.svg");
    let det = dir.join("d.json");
    let horse = root().join("tests/data/horse.png");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_subgram"))
        .args([
            "reverse",
            horse.to_str().unwrap(),
            "-n",
            "3",
            "-o",
            out.to_str().unwrap(),
        ])
        .args([
            "--report",
            "--format",
            "json",
            "--figure",
            fig.to_str().unwrap(),
            "--details",
            det.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["steps"].as_array().unwrap().len(), 3);
    assert!(v["reverse"]["rms"].as_f64().unwrap() < v["decimation"]["rms"].as_f64().unwrap());
    assert!(std::fs::read_to_string(&fig).unwrap().contains("<circle"));
    let back = dir.join("back.txt");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_subgram"))
        .args([
            "reconstruct",
            out.to_str().unwrap(),
            "--details",
            det.to_str().unwrap(),
            "-o",
            back.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let input = reverse::input::read(&horse).unwrap();
    let restored = reverse::input::read(&back).unwrap();
    assert_points_eq(&restored.points, &input.points, 1e-9);
}
