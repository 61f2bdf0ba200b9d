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
    // Of two subpaths, the one with more points; the other is not appended.
    let two = r#"<svg><path d="M0,0 L1,0 L1,1 Z M5,5 l1,0 l0,1 l-1,0 Z"/></svg>"#;
    let c = reverse::input::read_svg("two.svg", two).unwrap();
    assert_eq!(
        c.points,
        vec![
            DVec2::new(5.0, -5.0),
            DVec2::new(6.0, -5.0),
            DVec2::new(6.0, -6.0),
            DVec2::new(5.0, -6.0)
        ]
    );
    assert!(c.closed);
}

#[test]
fn bad_inputs_get_clear_errors_naming_the_file_and_line() {
    let tmp = scratch("rev");
    let dir = tmp.path();
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
    let tmp = scratch("rev-cli");
    let dir = tmp.path();
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

// ---------------------------------------------------------------------
// Bad inputs through the binary (issue 11): each finishes fast, exits
// with 1 (or 2 for usage errors), says where, and leaves no file behind.

/// What a run of the binary gave.
pub struct Ran {
    pub code: Option<i32>,
    pub stdout: String,
    pub stderr: String,
    pub seconds: f64,
}

/// Runs the binary in `dir`; a run that takes more than a minute is killed
/// and fails the test (they all take well under a second).
pub fn run_in(dir: &std::path::Path, args: &[&str]) -> Ran {
    use std::io::Read;
    let start = std::time::Instant::now();
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_subgram"))
        .args(args)
        .current_dir(dir)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("the binary runs");
    let mut out = child.stdout.take().unwrap();
    let mut err = child.stderr.take().unwrap();
    let t_out = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = out.read_to_string(&mut s);
        s
    });
    let t_err = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = err.read_to_string(&mut s);
        s
    });
    let status = loop {
        if let Some(st) = child.try_wait().unwrap() {
            break st;
        }
        if start.elapsed() > std::time::Duration::from_secs(60) {
            let _ = child.kill();
            let _ = child.wait();
            panic!(
                "`subgram {}` did not finish within a minute",
                args.join(" ")
            );
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
    };
    Ran {
        code: status.code(),
        stdout: t_out.join().unwrap(),
        stderr: t_err.join().unwrap(),
        seconds: start.elapsed().as_secs_f64(),
    }
}

/// The names in `dir`, sorted.
pub fn files_in(dir: &std::path::Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// Runs `args` in a folder holding `inputs`, expects exit code `code` and
/// a message that begins with `message` (and has the line and caret when
/// `caret`), and checks that only the inputs are left.
fn refused(name: &str, inputs: &[(&str, &[u8])], args: &[&str], code: i32, message: &str) -> Ran {
    let tmp = scratch(name);
    let dir = tmp.path();
    for (f, bytes) in inputs {
        std::fs::write(dir.join(f), bytes).unwrap();
    }
    let r = run_in(dir, args);
    assert_eq!(r.code, Some(code), "{name}: {}", r.stderr);
    assert!(
        r.stderr.starts_with(message),
        "{name}: expected\n{message}\ngot\n{}",
        r.stderr
    );
    let mut want: Vec<String> = inputs.iter().map(|(f, _)| f.to_string()).collect();
    want.sort();
    assert_eq!(files_in(dir), want, "{name}: a file was left behind");
    assert!(r.seconds < 30.0, "{name}: {} s", r.seconds);
    r
}

const CIRCLE_64: fn() -> String = || {
    (0..64)
        .map(|i| {
            let t = i as f64 / 64.0 * std::f64::consts::TAU;
            format!("{} {}\n", 1000.0 * t.cos(), 1000.0 * t.sin())
        })
        .collect()
};

#[test]
fn a_closed_contour_with_one_far_spike_reverses_at_once() {
    // The flattest-point search measured the spike against a tiny grid and
    // searched rings of cells out to it: it never finished.
    let tmp = scratch("spike");
    let dir = tmp.path();
    std::fs::write(
        dir.join("spike.txt"),
        "0 0\n1 0\n1 1\n0.5 1.0000001\n0 1\n0 0.5\n1e9 1e9\n",
    )
    .unwrap();
    let r = run_in(
        dir,
        &[
            "reverse",
            "spike.txt",
            "-n",
            "1",
            "-o",
            "out.csv",
            "--report",
        ],
    );
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    assert!(r.stdout.contains("step 1: 6 -> 3 points"), "{}", r.stdout);
    assert!(r.seconds < 10.0, "{} s", r.seconds);
}

#[test]
fn segments_longer_than_1e154_are_measured_without_nan() {
    // Their squared lengths overflow: the report gave NaN after searching
    // the whole grid. Now distances are scaled, and finite.
    let tmp = scratch("huge");
    let dir = tmp.path();
    let pts =
        "0 0\n1e155 0\n1e155 1e155\n0 1e155\n-1e155 1e155\n-1e155 0\n-1e155 -1e155\n0 -1e155\n";
    std::fs::write(dir.join("huge.txt"), pts).unwrap();
    let r = run_in(
        dir,
        &[
            "reverse", "huge.txt", "-n", "1", "-o", "out.csv", "--report", "--format", "json",
        ],
    );
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    let v: serde_json::Value = serde_json::from_str(&r.stdout).unwrap();
    for k in ["reverse", "decimation"] {
        for m in ["max", "mean", "rms"] {
            let x = v[k][m].as_f64().unwrap_or(f64::NAN);
            assert!(x.is_finite() && x > 1e153, "{k} {m}: {}", v[k][m]);
        }
    }
}

#[test]
fn a_scheme_that_sends_every_point_to_the_origin_finishes() {
    let scheme = "module P(V2f);\nring L-system: 1;\nderivation length: 1;\nAxiom: P(V2f(0,0));\n\
                  group 1:\nP(vl) < P(va) P(vb) > P(vr) -> P(V2f(0,0))\n\
                  group 2:\nP(v) -> P(V2f(0,0)) P(V2f(0,0))\n";
    let tmp = scratch("origin");
    let dir = tmp.path();
    std::fs::write(dir.join("origin.lsys"), scheme).unwrap();
    std::fs::write(dir.join("c.txt"), CIRCLE_64()).unwrap();
    let r = run_in(
        dir,
        &[
            "reverse",
            "c.txt",
            "-n",
            "3",
            "-o",
            "out.csv",
            "--scheme",
            "origin.lsys",
            "--report",
        ],
    );
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    assert!(r.stdout.contains("rms 1000.000000"), "{}", r.stdout);
}

#[test]
fn svg_coordinates_that_overflow_are_an_error_at_their_place() {
    let svg =
        b"<svg><path d=\"M 0 0 l 1e308 0 l 1e308 0 l 0 1e308 l 0 1e308 l -1e308 0 z\"/></svg>";
    refused(
        "svg-overflow",
        &[("ovf.svg", svg)],
        &["reverse", "ovf.svg", "-n", "1", "-o", "out.csv", "--report"],
        1,
        "ovf.svg:1:39: error: the path's point reaches (inf, 0): its coordinates overflow\n  |\n\
         1 | <svg><path d=\"M 0 0 l 1e308 0 l 1e308 0 l 0 1e308 l 0 1e308 l -1e308 0 z\"/></svg>\n  \
         |                                       ^\n",
    );
}

#[test]
fn a_point_line_with_a_third_field_is_an_error_at_the_field() {
    refused(
        "third-field",
        &[("p.txt", b"0 0\n1 0\n1 2 foo\n0 1\n")],
        &["reverse", "p.txt", "-n", "1", "-o", "out.csv"],
        1,
        "p.txt:3:5: error: `foo` follows the two numbers `x y`: a line holds one point\n  |\n3 | 1 2 foo\n  |     ^^^\n",
    );
}

#[test]
fn invalid_utf8_and_unreadable_pictures_are_reported_with_the_file() {
    refused(
        "utf8",
        &[("p.txt", b"0 0\n1 0\n1 \xff1\n0 1\n")],
        &["reverse", "p.txt", "-n", "1", "-o", "out.csv"],
        1,
        "p.txt:3:3: error: a point list must be UTF-8 text, but byte 0xFF here is not UTF-8\n  |\n3 | 1 \u{fffd}1\n  |   ^\n",
    );
    refused(
        "utf8-svg",
        &[("s.svg", b"<svg>\n<polygon points=\"0,0 1,0 \xe9\"/></svg>")],
        &["reverse", "s.svg", "-n", "1", "-o", "out.csv"],
        1,
        "s.svg:2:26: error: an SVG file must be UTF-8 text, but byte 0xE9 here is not UTF-8\n",
    );
    refused(
        "png",
        &[("scan.png", b"\x89PNG\r\n\x1a\nnot really")],
        &["reverse", "scan.png", "-n", "1", "-o", "out.csv"],
        1,
        "scan.png: error: cannot read the PNG image:",
    );
    // A PNG header that claims 100000 x 100000 pixels is refused unread.
    let mut big = b"\x89PNG\r\n\x1a\n\0\0\0\x0dIHDR".to_vec();
    big.extend(100_000u32.to_be_bytes());
    big.extend(100_000u32.to_be_bytes());
    big.extend([8, 6, 0, 0, 0, 0, 0, 0, 0]);
    refused(
        "png-huge",
        &[("huge.png", &big)],
        &["reverse", "huge.png", "-n", "1", "-o", "out.csv"],
        1,
        "huge.png: error: the image is 100000×100000 pixels, more than the 67 million pixels a silhouette may have: scale it down",
    );
}

#[test]
fn details_with_a_huge_shift_or_values_near_the_limit_are_refused_at_their_place() {
    let tmp = scratch("details-src");
    let dir = tmp.path();
    std::fs::write(dir.join("c.txt"), CIRCLE_64()).unwrap();
    let r = run_in(
        dir,
        &[
            "reverse",
            "c.txt",
            "-n",
            "2",
            "-o",
            "coarse.txt",
            "--details",
            "d.json",
        ],
    );
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    let coarse = std::fs::read(dir.join("coarse.txt")).unwrap();
    let good: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("d.json")).unwrap()).unwrap();
    let pretty = |v: &serde_json::Value| serde_json::to_string_pretty(v).unwrap();

    // `file:line:col` of the first `needle` in `text`, and its line.
    let place = |text: &str, needle: &str| {
        let at = text.find(needle).unwrap();
        let line = text[..at].matches('\n').count() + 1;
        let start = text[..at].rfind('\n').map_or(0, |i| i + 1);
        let end = text[at..].find('\n').map_or(text.len(), |i| at + i);
        (
            format!("d.json:{line}:{}", at - start + 1),
            line,
            text[start..end].to_string(),
        )
    };

    let mut shift = good.clone();
    shift["levels"][0]["shift"] = serde_json::json!(u64::MAX);
    let text = pretty(&shift);
    let (at, line, shown) = place(&text, "18446744073709551615");
    let r = refused(
        "details-shift",
        &[("coarse.txt", &coarse), ("d.json", text.as_bytes())],
        &["reconstruct", "coarse.txt", "--details", "d.json", "-o", "back.txt"],
        1,
        &format!(
            "{at}: error: `shift` is 18446744073709551615, but this level has 32 point(s): a shift must be below that\n    |\n{line} | {shown}\n    |                ^^^^^^^^^^^^^^^^^^^^\n"
        ),
    );
    assert!(!r.stderr.contains("inf"));

    // Each value is finite, their sum is not: the first detail of level 1
    // makes a point near f64::MAX, which level 2 subdivides to 1.275e308
    // at index 2 * shift, and a second detail there overflows.
    let mut big = good.clone();
    let shift = good["levels"][0]["shift"].as_u64().unwrap() as usize;
    big["levels"][0]["details"][0] = serde_json::json!([1.7e308, 1.7e308]);
    big["levels"][1]["details"][2 * shift] = serde_json::json!([1.6e308, 1.6e308]);
    let text = serde_json::to_string(&big).unwrap();
    let at = format!("d.json:1:{}", text.find("[1.6e+308,1.6e+308]").unwrap() + 1);
    refused(
        "details-overflow",
        &[("coarse.txt", &coarse), ("d.json", text.as_bytes())],
        &["reconstruct", "coarse.txt", "--details", "d.json", "-o", "back.txt"],
        1,
        &format!("{at}: error: this detail overflows: added to the subdivided point [1.2749999999999999e308, 1.2749999999999999e308] it gives [inf, inf], and a restored point must be finite\n"),
    );

    // A count that is not a whole number, and broken JSON.
    let text = pretty(&good).replacen("\"coarse_points\": 16", "\"coarse_points\": 16.5", 1);
    refused(
        "details-fraction",
        &[("coarse.txt", &coarse), ("d.json", text.as_bytes())],
        &["reconstruct", "coarse.txt", "--details", "d.json", "-o", "back.txt"],
        1,
        "d.json:3:20: error: `coarse_points` must be a whole number from 0, not 16.5\n  |\n3 |   \"coarse_points\": 16.5,\n  |                    ^^^^\n",
    );
    let text = pretty(&good).replacen("\"version\": 1", "\"version\": 1,,", 1);
    let (_, line, shown) = place(&text, ",,");
    let col = shown.find(",,").unwrap() + 2;
    refused(
        "details-syntax",
        &[("coarse.txt", &coarse), ("d.json", text.as_bytes())],
        &[
            "reconstruct",
            "coarse.txt",
            "--details",
            "d.json",
            "-o",
            "back.txt",
        ],
        1,
        &format!("d.json:{line}:{col}: error: expected a key in quotes, found `,`\n"),
    );
}

#[test]
fn a_scheme_that_produces_nothing_is_an_error() {
    let scheme = "module P(V2f);\nring L-system: 1;\nderivation length: 1;\nAxiom: P(V2f(0,0));\n\
                  group 1:\nP(va) P(vb) : { produce; }\n\
                  group 2:\nP(v) -> P(v) P(v)\n";
    let circle = CIRCLE_64();
    refused(
        "nothing",
        &[("nothing.lsys", scheme.as_bytes()), ("c.txt", circle.as_bytes())],
        &["reverse", "c.txt", "-n", "1", "-o", "out.csv", "--scheme", "nothing.lsys"],
        1,
        "nothing.lsys: error: the scheme's group 1 (the reverse step) turned 64 points into none: it must produce `P` modules\n",
    );
}

#[test]
fn details_that_overflow_are_refused_and_nothing_is_written() {
    // Reverse Chaikin keeps these points finite, but the details between
    // levels would be 1e308 - (-1e308).
    let pts = "1e308 0\n0 1e308\n-1e308 0\n0 -1e308\n1e308 1e308\n-1e308 -1e308\n";
    let r = refused(
        "details-inf",
        &[("p.txt", pts.as_bytes())],
        &[
            "reverse",
            "p.txt",
            "-n",
            "1",
            "-o",
            "out.csv",
            "--details",
            "d.json",
            "--figure",
            "f.svg",
        ],
        1,
        "error: ",
    );
    assert!(
        r.stderr.contains("not finite") || r.stderr.contains("overflows"),
        "{}",
        r.stderr
    );
}

#[test]
fn reverse_writes_all_of_its_outputs_or_none() {
    let circle = CIRCLE_64();
    // The details cannot be written (no such folder): the coarse polygon
    // is not left behind either.
    refused(
        "all-or-none",
        &[("c.txt", circle.as_bytes())],
        &[
            "reverse",
            "c.txt",
            "-n",
            "1",
            "-o",
            "out.csv",
            "--details",
            "no/such/d.json",
        ],
        1,
        "error: cannot write `no/such/d.json`: ",
    );
    refused(
        "all-or-none-fig",
        &[("c.txt", circle.as_bytes())],
        &[
            "reverse",
            "c.txt",
            "-n",
            "1",
            "-o",
            "out.csv",
            "--details",
            "d.json",
            "--figure",
            "no/f.png",
        ],
        1,
        "error: cannot write `no/f.png`: ",
    );
    // The figure's name is a folder: renamed last, it fails, and the two
    // files renamed before it are removed again.
    let tmp = scratch("all-or-none-dir");
    let dir = tmp.path();
    std::fs::write(dir.join("c.txt"), &circle).unwrap();
    std::fs::create_dir(dir.join("f.svg")).unwrap();
    let r = run_in(
        dir,
        &[
            "reverse",
            "c.txt",
            "-n",
            "1",
            "-o",
            "out.csv",
            "--details",
            "d.json",
            "--figure",
            "f.svg",
        ],
    );
    assert_eq!(r.code, Some(1), "{}", r.stderr);
    assert!(
        r.stderr.starts_with("error: cannot write `f.svg`"),
        "{}",
        r.stderr
    );
    assert_eq!(files_in(dir), vec!["c.txt", "f.svg"]);
    // And with everything in order, all three are there.
    std::fs::remove_dir(dir.join("f.svg")).unwrap();
    let r = run_in(
        dir,
        &[
            "reverse",
            "c.txt",
            "-n",
            "1",
            "-o",
            "out.csv",
            "--details",
            "d.json",
            "--figure",
            "f.svg",
        ],
    );
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    assert_eq!(files_in(dir), vec!["c.txt", "d.json", "f.svg", "out.csv"]);
}

#[test]
fn inputs_larger_than_the_limit_are_refused_before_they_are_read() {
    // /dev/zero never ends: the read stops one byte past the limit.
    let tmp = scratch("dev-zero");
    let dir = tmp.path();
    let r = run_in(dir, &["reverse", "/dev/zero", "-n", "1", "-o", "out.csv"]);
    assert_eq!(r.code, Some(1));
    assert_eq!(
        r.stderr.trim_end(),
        "/dev/zero: error: the file is larger than the input size limit of 64 MiB (67108864 bytes): \
         it holds more than that; raise the limit with --max-input-size (e.g. --max-input-size 256M)"
    );
    assert!(files_in(dir).is_empty());
    let r = run_in(
        dir,
        &[
            "reconstruct",
            "/dev/zero",
            "--details",
            "/dev/zero",
            "-o",
            "out.txt",
        ],
    );
    assert_eq!(r.code, Some(1));
    assert!(
        r.stderr.contains("input size limit of 64 MiB"),
        "{}",
        r.stderr
    );
    // A regular file is measured before it is opened for reading.
    let circle = CIRCLE_64();
    refused(
        "limit",
        &[("c.txt", circle.as_bytes())],
        &["reverse", "c.txt", "-n", "1", "-o", "out.csv", "--max-input-size", "1K"],
        1,
        &format!(
            "c.txt: error: the file is larger than the input size limit of 1 KiB (1024 bytes): it is {}; \
             raise the limit with --max-input-size (e.g. --max-input-size 1M)",
            reverse::input::human_bytes(circle.len() as u64)
        ),
    );
    let tmp = scratch("limit-raised");
    let dir = tmp.path();
    std::fs::write(dir.join("c.txt"), &circle).unwrap();
    let r = run_in(
        dir,
        &[
            "reverse",
            "c.txt",
            "-n",
            "1",
            "-o",
            "out.csv",
            "--max-input-size",
            "1M",
        ],
    );
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    let r = run_in(
        &std::env::temp_dir(),
        &[
            "reverse",
            "c.txt",
            "-n",
            "1",
            "-o",
            "o.csv",
            "--max-input-size",
            "lots",
        ],
    );
    assert_eq!(r.code, Some(2), "{}", r.stderr);
}

#[test]
fn a_report_beyond_floating_point_is_refused() {
    // A forward scheme that throws every point to the far side: the
    // distances are beyond f64::MAX.
    let text = "module P(V2f);\nring L-system: 1;\nderivation length: 1;\nAxiom: P(V2f(0,0));\n\
                group 1:\nP(vl) < P(va) P(vb) > P(vr) -> P(va)\n\
                group 2:\nP(v) -> P(V2f(-1.7e308, 0)) P(V2f(-1.7e308, 0))\n";
    let s = Scheme {
        loaded: subgram::load_str_with("far.lsys", text, &[], subgram::Precision::Double).unwrap(),
        name: "far.lsys".into(),
        closed: true,
        deadline: None,
    };
    let pts: Vec<DVec2> = (0..8).map(|i| DVec2::new(1.7e308, i as f64)).collect();
    let c = contour(pts, true);
    let r = reverse::reverse(&s, &c, &opts(1, Phase::Fixed(0), false)).unwrap();
    let e = reverse::report(&s, &c, &r).unwrap_err().to_string();
    assert!(
        e.starts_with("the reconstruction error cannot be measured"),
        "{e}"
    );
}

#[test]
fn a_scheme_whose_reverse_step_does_not_reduce_is_an_error() {
    // Group 1 copies the points: without the check, `-n` steps would each
    // reconstruct the whole contour, for as many steps as asked.
    let scheme = "module P(V2f);\nring L-system: 1;\nderivation length: 1;\nAxiom: P(V2f(0,0));\n\
                  group 1:\nP(v) -> P(v)\n\
                  group 2:\nP(v) -> P(v)\n";
    let circle = CIRCLE_64();
    refused(
        "same",
        &[("same.lsys", scheme.as_bytes()), ("c.txt", circle.as_bytes())],
        &["reverse", "c.txt", "-n", "1000000", "-o", "out.csv", "--scheme", "same.lsys"],
        1,
        "same.lsys: error: at step 1, the scheme's group 1 (the reverse step) turned 64 points into 64: a reverse step must leave fewer points than it is given, and at least 3 for a coarse polygon\n",
    );
}

#[test]
fn noise_stops_at_the_measurement_budget_and_fixed_phases_still_run() {
    // 20,000 random points: the reconstruction is far from most of them,
    // and each distance search visits a long stretch of boxes.
    let mut seed = 12345u64;
    let mut next = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64 * 1000.0
    };
    let noise: String = (0..20_000)
        .map(|_| format!("{} {}\n", next(), next()))
        .collect();
    let r = refused(
        "noise",
        &[("noise.txt", noise.as_bytes())],
        &["reverse", "noise.txt", "-n", "4", "-o", "out.csv"],
        1,
        "error: choosing the phase (--phase auto): measuring the distance of 20000 points to a polyline of 20000 segments needs more than ",
    );
    assert!(
        r.stderr
            .contains("--phase 0 or --phase 1 chooses without measuring"),
        "{}",
        r.stderr
    );
    let tmp = scratch("noise-fixed");
    let dir = tmp.path();
    std::fs::write(dir.join("noise.txt"), &noise).unwrap();
    let r = run_in(
        dir,
        &[
            "reverse",
            "noise.txt",
            "-n",
            "4",
            "--phase",
            "0",
            "-o",
            "out.csv",
        ],
    );
    assert_eq!(r.code, Some(0), "{}", r.stderr);
}

/// tests/data/horse.png with every pixel inverted (over white first, as
/// transparent pixels count as white): a light horse on a dark ground.
fn inverted_horse() -> tiny_skia::Pixmap {
    let bytes = std::fs::read(root().join("tests/data/horse.png")).unwrap();
    let mut pm = tiny_skia::Pixmap::decode_png(&bytes).unwrap();
    for p in pm.pixels_mut() {
        let c = p.demultiply();
        let a = c.alpha() as u32;
        let over = |v: u8| ((v as u32 * a + 255 * (255 - a)) / 255) as u8;
        *p = tiny_skia::ColorU8::from_rgba(
            255 - over(c.red()),
            255 - over(c.green()),
            255 - over(c.blue()),
            255,
        )
        .premultiply();
    }
    pm
}

/// The binary reverses the light horse as it reverses the dark one, with
/// the side found by itself or given by `--invert`, at `--threshold`.
#[test]
fn reverse_reads_a_light_silhouette_through_the_binary() {
    let tmp = scratch("rev-light");
    let dir = tmp.path();
    let light = dir.join("light.png");
    std::fs::write(&light, inverted_horse().encode_png().unwrap()).unwrap();
    let horse = root().join("tests/data/horse.png");
    let coarse = |input: &std::path::Path, extra: &[&str], out: &str| {
        let out = dir.join(out);
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_subgram"))
            .args(["reverse", input.to_str().unwrap(), "-n", "3", "-o"])
            .arg(&out)
            .args(extra)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        reverse::input::read(&out).unwrap().points
    };
    // The same points up to the last bits: 1 − l interpolates as l does,
    // not bit for bit.
    let want = coarse(&horse, &[], "dark.txt");
    assert_points_eq(&coarse(&light, &[], "auto.txt"), &want, 1e-9);
    let told = coarse(&light, &["--invert", "--threshold", "0.5"], "told.txt");
    assert_points_eq(&told, &want, 1e-9);
    assert!(want.len() > 100, "a horse, not a frame");
}

/// The horse of scikit-image as a light silhouette on a dark ground (each
/// pixel of tests/data/horse.png inverted here): the light side is the
/// shape, found because the dark side touches the image's border, and
/// its outline is the horse's, point for point (luminance l at level 1/2
/// and 1 − l at level 1/2 cross at the same places).
#[test]
fn a_light_silhouette_on_a_dark_ground_traces_the_shape_not_the_frame() {
    let bytes = std::fs::read(root().join("tests/data/horse.png")).unwrap();
    let original = reverse::input::read_png("horse.png", &bytes).unwrap();
    let pm = inverted_horse();
    let inverted = pm.encode_png().unwrap();
    let (w, h) = (pm.width() as f64, pm.height() as f64);
    let traced = reverse::input::read_png("inverted.png", &inverted).unwrap();
    assert_eq!(traced.points.len(), original.points.len());
    assert_points_eq(&traced.points, &original.points, 1e-9);
    let (lo, hi) = traced.points.iter().fold(
        (DVec2::splat(f64::MAX), DVec2::splat(f64::MIN)),
        |(a, b), &p| (a.min(p), b.max(p)),
    );
    assert!(lo.x > 0.0 && lo.y > 0.0 && hi.x < w - 1.0 && hi.y < h - 1.0);
    // Told which side: the same again; told the wrong side, the dark ground
    // reaches every edge and is refused rather than traced as the frame.
    let light = reverse::input::Silhouette {
        side: reverse::input::Side::Light,
        ..Default::default()
    };
    let told = reverse::input::read_png_with("inverted.png", &inverted, &light).unwrap();
    assert_points_eq(&told.points, &original.points, 1e-9);
    let dark = reverse::input::Silhouette {
        side: reverse::input::Side::Dark,
        ..Default::default()
    };
    let e = reverse::input::read_png_with("inverted.png", &inverted, &dark)
        .unwrap_err()
        .to_string();
    assert!(e.contains("reaches all four edges"), "{e}");
    assert!(e.contains("--invert"), "{e}");
}

/// A shape that spans the image from edge to edge on both axes (a cross)
/// is never answered with the image's frame.
#[test]
fn a_shape_reaching_every_edge_is_refused_not_framed() {
    let mut pm = tiny_skia::Pixmap::new(60, 40).unwrap();
    pm.fill(tiny_skia::Color::WHITE);
    let mut paint = tiny_skia::Paint::default();
    paint.set_color_rgba8(0, 0, 0, 255);
    let id = tiny_skia::Transform::identity();
    pm.fill_rect(
        tiny_skia::Rect::from_xywh(0.0, 15.0, 60.0, 10.0).unwrap(),
        &paint,
        id,
        None,
    );
    pm.fill_rect(
        tiny_skia::Rect::from_xywh(25.0, 0.0, 10.0, 40.0).unwrap(),
        &paint,
        id,
        None,
    );
    let e = reverse::input::read_png("cross.png", &pm.encode_png().unwrap())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("cross.png") && e.contains("all four edges"),
        "{e}"
    );
    // A threshold outside (0, 1) is refused.
    let bad = reverse::input::Silhouette {
        threshold: 1.5,
        ..Default::default()
    };
    let e = reverse::input::read_png_with("cross.png", &pm.encode_png().unwrap(), &bad)
        .unwrap_err()
        .to_string();
    assert!(e.contains("threshold"), "{e}");
}

/// The threshold moves the traced outline: a grey disc (level 0.6) on
/// white is found at threshold 0.7 and absent at 0.5.
#[test]
fn the_threshold_chooses_the_grey_level() {
    let mut pm = tiny_skia::Pixmap::new(80, 80).unwrap();
    pm.fill(tiny_skia::Color::WHITE);
    let mut paint = tiny_skia::Paint::default();
    paint.set_color_rgba8(153, 153, 153, 255);
    let path = tiny_skia::PathBuilder::from_circle(40.0, 40.0, 25.0).unwrap();
    pm.fill_path(
        &path,
        &paint,
        tiny_skia::FillRule::Winding,
        tiny_skia::Transform::identity(),
        None,
    );
    let png = pm.encode_png().unwrap();
    let at = |t: f64| {
        reverse::input::read_png_with(
            "grey.png",
            &png,
            &reverse::input::Silhouette {
                threshold: t,
                ..Default::default()
            },
        )
    };
    let c = at(0.7).unwrap();
    // The shoelace area of the outline, as the radius of a circle.
    let p = &c.points;
    let twice: f64 = (0..p.len())
        .map(|i| p[i].perp_dot(p[(i + 1) % p.len()]))
        .sum();
    let r = (twice.abs() / 2.0 / std::f64::consts::PI).sqrt();
    assert!((r - 25.0).abs() < 1.0, "radius {r}");
    let e = at(0.5).unwrap_err().to_string();
    assert!(e.contains("no dark shape"), "{e}");
}
