//! Pictures: the SVG's structure against what the word implies, PNGs
//! against images that were looked at, fitting, and failures.

use subgram::render::{self, png, svg, Item, RenderOptions, Scene};
use subgram::{DeriveOptions, FigureOptions};

use crate::golden::{self, Kind};
use crate::support::*;

#[test]
fn paper_program_1_draws_lines_and_circles() {
    // 32 points: LineTo2f from the origin to the first point, then one
    // line per point, and one Circle per point.
    let s = figure(&lsys("paper/000-program1.lsys"), FigureOptions::default());
    let (segments, circles, _) = svg_counts(&svg::render(&s));
    assert_eq!((segments, circles), (32, 32));
}

#[test]
fn polygons_come_from_sp_pp_ep() {
    let src = "derivation length: 0;\nAxiom: SP PP F(1) Left(90) PP F(1) Left(90) PP EP \
               MoveTo(5, 0, 0) SP PP F(1) Left(120) PP F(1) Left(120) PP EP;\n";
    let l = load_text(src);
    let s = l.figure(&FigureOptions::default()).unwrap();
    let (segments, _, polygons) = svg_counts(&svg::render(&s));
    assert_eq!((segments, polygons), (4, 2));
}

#[test]
fn each_draws_every_step_side_by_side() {
    let opts = FigureOptions {
        each: true,
        derive: DeriveOptions::default().with_steps(3),
        ..sized(1200, 300)
    };
    let s = figure(&lsys("curves/chaikin-13.lsys"), opts);
    // One closed curve per step: 6, 12, 24 and 48 segments.
    let (segments, _, _) = svg_counts(&svg::render(&s));
    assert_eq!(segments, 6 + 12 + 24 + 48);
    // Panel k lies in the k-th quarter of the width.
    let mut seen = [false; 4];
    for item in &s.items {
        if let Item::Polyline { points, .. } = item {
            let k = (points[0].x / 300.0) as usize;
            assert!(
                points.iter().all(|p| (p.x / 300.0) as usize == k),
                "a curve crosses panels"
            );
            seen[k] = true;
        }
    }
    assert_eq!(seen, [true; 4]);
}

#[test]
fn the_drawing_is_fitted_inside_the_margin() {
    for (w, h) in [(800, 800), (800, 300), (300, 800)] {
        let s = figure(&lsys("abop/koch-snowflake.lsys"), sized(w, h));
        let m = 0.04 * w.min(h) as f64;
        let (mut lo, mut hi) = (glam::DVec2::splat(f64::MAX), glam::DVec2::splat(f64::MIN));
        for item in &s.items {
            if let Item::Polyline { points, .. } = item {
                for p in points {
                    lo = lo.min(*p);
                    hi = hi.max(*p);
                }
            }
        }
        let eps = 1e-6;
        assert!(lo.x >= m - eps && lo.y >= m - eps, "{w}x{h}: {lo}");
        assert!(
            hi.x <= w as f64 - m + eps && hi.y <= h as f64 - m + eps,
            "{w}x{h}: {hi}"
        );
        // It fills the available room in one direction, and is centred.
        let fill_x = (hi.x - lo.x) / (w as f64 - 2.0 * m);
        let fill_y = (hi.y - lo.y) / (h as f64 - 2.0 * m);
        assert!(
            (fill_x.max(fill_y) - 1.0).abs() < 1e-9,
            "{w}x{h}: {fill_x} {fill_y}"
        );
        assert!(((lo.x + hi.x) / 2.0 - w as f64 / 2.0).abs() < 1e-9);
        assert!(((lo.y + hi.y) / 2.0 - h as f64 / 2.0).abs() < 1e-9);
    }
}

#[test]
fn circles_stay_round_at_any_aspect_ratio() {
    let s = figure(&lsys("paper/000-program1.lsys"), sized(900, 300));
    let doc = svg::render(&s);
    assert!(doc.contains("<circle"));
    assert!(!doc.contains("<ellipse"));
    // The PNG disc is as wide as it is tall.
    let disc = s
        .items
        .iter()
        .find_map(|i| match i {
            Item::Disc { c, r, .. } => Some((*c, *r)),
            _ => None,
        })
        .unwrap();
    let one = Scene {
        items: vec![Item::Disc {
            c: glam::DVec2::new(50.0, 50.0),
            r: 20.0,
            color: render::Rgba(0, 0, 0, 255),
        }],
        width: 100,
        height: 100,
        background: render::Rgba(255, 255, 255, 255),
    };
    let _ = disc;
    let pm = tiny_skia::Pixmap::decode_png(&png::render(&one).unwrap()).unwrap();
    let dark = |x: u32, y: u32| pm.pixel(x, y).unwrap().red() < 128;
    let width = (0..100).filter(|&x| dark(x, 50)).count();
    let height = (0..100).filter(|&y| dark(50, y)).count();
    assert_eq!(width, height);
    assert!((39..=41).contains(&width), "{width}");
}

#[test]
fn png_and_svg_draw_the_same_scene() {
    let s = figure(&lsys("curves/chaikin-13.lsys"), sized(200, 200));
    let doc = svg::render(&s);
    let pm = tiny_skia::Pixmap::decode_png(&png::render(&s).unwrap()).unwrap();
    assert_eq!((pm.width(), pm.height()), (200, 200));
    assert!(doc.contains("width=\"200\"") && doc.contains("viewBox=\"0 0 200 200\""));
    // Every circle centre of the SVG is painted in the PNG.
    for part in doc.split("<circle").skip(1) {
        let num = |key: &str| -> f64 {
            let at = part.find(key).unwrap() + key.len();
            part[at..].split('"').next().unwrap().parse().unwrap()
        };
        let (x, y) = (num("cx=\""), num("cy=\""));
        let p = pm.pixel(x as u32, y as u32).unwrap();
        assert!(
            p.red() < 250 || p.green() < 250 || p.blue() < 250,
            "({x}, {y}) is blank"
        );
    }
}

#[test]
fn png_matches_the_stored_chaikin_figure() {
    let s = figure(&lsys("curves/chaikin-13.lsys"), sized(240, 240));
    golden::check(
        "tests/golden/chaikin-13.png",
        &png::render(&s).unwrap(),
        Kind::Png,
    );
}

#[test]
fn png_matches_the_stored_kolam() {
    let s = figure(&lsys("figures/fig10-kolam.lsys"), sized(240, 240));
    golden::check(
        "tests/golden/fig10-kolam.png",
        &png::render(&s).unwrap(),
        Kind::Png,
    );
}

/// A Koch curve (a thin pen, 4^8 segments: the scene's polyline is inked
/// in bands), then lines (`G`) that join it and lines that do not, colour
/// and width changes and back, a pen wider than a pixel, discs, dots,
/// rings, a polygon and a Rhombus, moves without drawing, and branches.
const MANY_EVENTS: &str = "derivation length: 8;\n\
    Axiom: SetWidth(0.5) F(1) Right(90) G(1) SetColor(3) G(1) SetColor(1) G(1) \
    SetWidth(4) G(2) Left(45) G(2) SetWidth(0.5) G(1) Circle(3) G(1) Circle0 \
    f(2) G(1) CircleB(2) SB Left(30) SetColor(5) G(3) EB G(1) \
    SP PP G(2) Left(120) PP G(2) Left(120) PP EP MoveTo(-5, -3, 2) G(2) Rhombus(2, 1) \
    SetWidth(0) G(1) Up(40) G(2);\n\
    F(x) -> F(x/3) Left(60) F(x/3) Right(120) F(x/3) Left(60) F(x/3);\n";

#[test]
fn a_picture_painted_as_the_turtle_walks_is_the_scenes_to_the_bit() {
    let l = load_text(MANY_EVENTS);
    let views = [
        (render::View::Xy, false),
        (render::View::Xz, true),
        (render::View::Yz, false),
    ];
    for (k, (view, units)) in views.into_iter().enumerate() {
        {
            let mut opts = sized(700 - 100 * k as u32, 500);
            opts.render.view = view;
            opts.render.widths_in_units = units;
            let scene = l.figure(&opts).unwrap();
            let lines: usize = scene
                .items
                .iter()
                .map(|i| match i {
                    Item::Polyline { points, .. } => points.len() - 1,
                    _ => 0,
                })
                .sum();
            assert!(lines > 65_536 && scene.items.len() > 10, "{lines}");
            let what = format!("{view:?}, widths in units {units}");
            paints_as_the_scene(&l, &opts, &png::render(&scene).unwrap(), &what);
        }
    }
    // With `each`, one panel a step, and a height fitted to them.
    let opts = FigureOptions {
        each: true,
        derive: DeriveOptions::default().with_steps(2),
        render: RenderOptions {
            fit_height: true,
            ..RenderOptions::default()
        },
        ..FigureOptions::default()
    };
    let scene = l.figure(&opts).unwrap();
    assert!(scene.height < 800, "{}", scene.height);
    assert!(l.png_figures(&opts).unwrap().main == png::render(&scene).unwrap());
}

/// Paths that the turtle keeps apart and the layout joins into one line
/// (the later path's first point left out, so that the laid-out points
/// fall behind the drawn ones): colours 12 apart are one colour of the
/// default palette, and a move of 1e-13 is no distance in pixels. Between
/// them, paths that stay apart (another colour, a move of half a unit),
/// and a disc; the Koch curves make the lines long enough to be painted in
/// bands, each of which passes over the chunks of points outside its rows.
#[test]
fn paths_the_layout_joins_are_painted_as_the_scene_paints_them() {
    let l = load_text(
        "derivation length: 7;\n\
         Axiom: SetColor(1) F(1) SetColor(13) F(1) f(1e-13) Right(60) F(1) SetColor(25) \
         G(1) SetColor(2) G(1) f(0.5) G(1) Circle(0.2) F(1) SetColor(14) F(1) Left(90) \
         SetColor(2) SetWidth(0.3) F(1) f(1e-14) F(1) SetWidth(3) F(1) f(1e-13) F(1) \
         SetColor(3) F(1);\n\
         F(x) -> F(x/3) Left(60) F(x/3) Right(120) F(x/3) Left(60) F(x/3);\n",
    );
    let opts = sized(300, 260);
    let scene = l.figure(&opts).unwrap();
    let lines: Vec<usize> = (scene.items.iter())
        .filter_map(|i| match i {
            Item::Polyline { points, .. } => Some(points.len()),
            _ => None,
        })
        .collect();
    // The turtle draws thirteen paths; the layout joins them into seven
    // lines: three Koch curves (4^7 segments each) and a `G`; two lines of
    // a `G` each; two Koch curves after the disc; two in another width;
    // two with a pen wider than a pixel (stroked by tiny-skia); one in
    // another colour.
    let p = &l.program;
    let mut d = subgram::Derivation::new(p, DeriveOptions::default()).unwrap();
    while d.has_next() {
        d.next_step().unwrap();
    }
    let word = d.interpret().unwrap();
    let events = subgram::draw::draw(&word, &p.alphabet, &p.structs, &Default::default()).unwrap();
    let paths = (events.iter())
        .filter(|e| matches!(e, subgram::draw::Event::Path { .. }))
        .count();
    assert_eq!(paths, 13);
    let koch = |n: usize| n * 16384 + 1;
    assert_eq!(
        lines,
        [koch(3) + 1, 2, 2, koch(2), koch(2), koch(2), koch(1)]
    );
    paints_as_the_scene(&l, &opts, &png::render(&scene).unwrap(), "joins");
}

/// `A` quadruples each step, so the last step rewrites 2^16 modules and
/// more (and so is written in parts, which the turtle walks as they are
/// written); the axiom's lines, discs, branches and pens end up spread
/// through the word, 4^8 `A`s apart. `SetColor(-1)`, which changes no
/// colour, holds a slot that reads as a NaN: the walk checks the modules
/// from the part that holds it on, one by one.
const SPREAD: &str = "module A;\nmodule X(float);\nderivation length: 8;\n\
    Axiom: SetWidth(0.5) A F(1) Right(90) F(1) SetColor(3) A F(1) Circle(0.3) F(2) A \
    SetColor(-1) \
    SB Left(30) F(1) EB SetWidth(3) F(1) A SetWidth(0.5) Left(45) F(1) A F(1) A;\n\
    A -> A A A A;\n";

/// The picture the turtle paints as it walks the last step's word while
/// the step writes it is the scene's, in pools of one to three threads; a
/// module of that word the turtle cannot draw, and a last step that fails
/// part of the way, fail as the scene does.
#[test]
fn a_picture_walked_as_the_last_step_is_written_is_the_scenes() {
    let l = load_text(SPREAD);
    let opts = sized(300, 200);
    let before_last = derive(&l, DeriveOptions::default().with_steps(7)).word;
    assert!(before_last.len() > 65_536, "{}", before_last.len());
    let scene = l.figure(&opts).unwrap();
    let png = png::render(&scene).unwrap();
    paints_as_the_scene(&l, &opts, &png, "spread");
    // The same word made by a compiled body: the parts are rewritten apart
    // and then copied into the new word after its first part.
    let body = SPREAD.replace(
        "A -> A A A A;",
        "A : { float x; x = 2; if (x > 1) produce A A A A; }",
    );
    let l = load_text(&body);
    paints_as_the_scene(&l, &opts, &png, "spread, a compiled body");
    for src in [
        // A surface the model does not have, near the word's end.
        SPREAD.replace("Left(45) F(1) A", "Left(45) F(1) Surface(2, 1) A"),
        // A value that is not finite in the last step (1e40 is past the
        // largest `float`), at the end of the word.
        SPREAD.replace(
            "F(1) A;\nA -> A A A A;",
            "F(1) A X(1);\nA -> A A A A;\nX(x) -> X(x * 1e5);",
        ),
    ] {
        let l = load_text(&src);
        let scene = l.figure(&opts).map(|_| ()).unwrap_err().to_string();
        for threads in [1, 2, 3] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let painted = pool
                .install(|| l.png_figures(&opts))
                .map(|_| ())
                .unwrap_err();
            assert_eq!(painted.to_string(), scene, "{threads} threads: {src}");
        }
    }
}

/// The picture painted from the walk (`png_figures`) is `expected`, the
/// scene's PNG, in pools of one to three threads (one band of rows, or a
/// band on each thread).
fn paints_as_the_scene(l: &subgram::Curve, opts: &FigureOptions, expected: &[u8], what: &str) {
    for threads in [1, 2, 3] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let painted = pool.install(|| l.png_figures(opts)).unwrap();
        assert!(
            painted.main == expected,
            "{what}, {threads} threads: the pictures differ"
        );
    }
}

#[test]
fn a_picture_painted_as_the_turtle_walks_fails_as_the_scene_does() {
    for src in [
        "module A;\nderivation length: 1;\nAxiom: A;\n",
        "derivation length: 0;\nAxiom: F(1) MoveTo(1e308, 0, 0) F(1) Left(90) MoveTo(-1e308, 0, 0) F(1);\n",
        "derivation length: 0;\nAxiom: F(1) F(0/0);\n",
    ] {
        let l = load_text(src);
        let (a, b) = (FigureOptions::default(), FigureOptions::default());
        let scene = l.figure(&a).map(|_| ()).unwrap_err().to_string();
        let painted = l.png_figures(&b).map(|_| ()).unwrap_err().to_string();
        assert_eq!(painted, scene, "{src}");
    }
    // A size out of range and a module that fails: the module is told
    // first, on either path (a reviewer found the picture told the size).
    let l = load_text(
        "derivation length: 0;
Axiom: F(1) Surface(2, 1);
",
    );
    for (w, h) in [(0, 10), (30_000, 10), (800, 800)] {
        let opts = sized(w, h);
        let scene = l.figure(&opts).map(|_| ()).unwrap_err().to_string();
        let painted = l.png_figures(&opts).map(|_| ()).unwrap_err().to_string();
        assert_eq!(painted, scene, "{w}x{h}");
        assert!(scene.contains("Surface"), "{scene}");
    }
    // With nothing wrong but the size, both tell the size.
    let l = load_text("derivation length: 0;\nAxiom: F(1);\n");
    let scene = l.figure(&sized(0, 10)).map(|_| ()).unwrap_err().to_string();
    let painted = (l.png_figures(&sized(0, 10)).map(|_| ()).unwrap_err()).to_string();
    assert_eq!(painted, scene);
    assert!(scene.contains("0x10"), "{scene}");
}

#[test]
fn an_empty_drawing_is_an_error() {
    let l = load_text("module A;\nderivation length: 1;\nAxiom: A;\n");
    let e = l.figure(&FigureOptions::default()).unwrap_err();
    assert_eq!(
        e.to_string(),
        "nothing to draw: after interpretation the word has no drawing modules (F, LineTo2f, Circle, ...)"
    );
}

#[test]
fn a_nan_coordinate_is_an_error() {
    let nan = subgram::draw::Event::Path {
        points: vec![glam::DVec3::ZERO, glam::DVec3::new(f64::NAN, 0.0, 0.0)],
        pen: subgram::draw::Pen {
            color: 1,
            width: 1.0,
        },
    };
    let e = render::scene(&[vec![nan]], &RenderOptions::default()).unwrap_err();
    assert!(
        e.message.contains("NaN or infinite coordinate"),
        "{}",
        e.message
    );
}

fn subgram_bin(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_subgram"))
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn render_writes_png_and_svg_files() {
    let tmp = scratch("render");
    let dir = tmp.path();
    let f = lsys("curves/chaikin-13.lsys");
    for ext in ["png", "svg"] {
        let out = dir.join(format!("c.{ext}"));
        let o = subgram_bin(&[
            "render",
            f.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--size",
            "300x200",
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let bytes = std::fs::read(&out).unwrap();
        if ext == "png" {
            let pm = tiny_skia::Pixmap::decode_png(&bytes).unwrap();
            assert_eq!((pm.width(), pm.height()), (300, 200));
        } else {
            assert!(String::from_utf8(bytes).unwrap().starts_with("<svg"));
        }
    }
    // Only the two outputs: no temporary files left behind.
    assert_eq!(std::fs::read_dir(dir).unwrap().count(), 2);
}

#[test]
fn a_failed_render_leaves_no_file() {
    let tmp = scratch("render-fail");
    let dir = tmp.path();
    let bad = dir.join("empty.lsys");
    std::fs::write(&bad, "module A;\nAxiom: A;\n").unwrap();
    let out = dir.join("x.png");
    let o = subgram_bin(&["render", bad.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("nothing to draw"));
    assert!(!out.exists());
    let o = subgram_bin(&[
        "render",
        bad.to_str().unwrap(),
        "-o",
        dir.join("x.jpg").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(
        std::fs::read_dir(dir).unwrap().count(),
        1,
        "only the input remains"
    );
}

/// The 3D turtle: `Up(90)` pitches the heading from +y to +z, so the first
/// segment runs along z; `--view` chooses the plane it is projected on.
#[test]
fn the_view_projects_the_3d_turtle() {
    let l = load_text("derivation length: 0;\nAxiom: Up(90) F(1) Left(90) F(1);\n");
    let word = subgram::Derivation::new(&l.program, Default::default())
        .unwrap()
        .word
        .clone();
    let events = subgram::draw::draw(
        &word,
        &l.program.alphabet,
        &l.program.structs,
        &Default::default(),
    )
    .unwrap();
    let segments: Vec<_> = events.iter().flat_map(|e| e.segments()).collect();
    let [(a0, b0), (a1, b1)] = segments[..] else {
        panic!("{events:?}");
    };
    assert!((b0 - a0).abs_diff_eq(glam::DVec3::Z, 1e-12), "{}", b0 - a0);
    assert!(
        (b1 - a1).abs_diff_eq(glam::DVec3::NEG_X, 1e-12),
        "{}",
        b1 - a1
    );
    for (view, first_len) in [(render::View::Xy, 0.0), (render::View::Xz, 1.0)] {
        let opts = RenderOptions {
            view,
            ..RenderOptions::default()
        };
        let s = render::scene(std::slice::from_ref(&events), &opts).unwrap();
        let Item::Polyline { points, .. } = &s.items[0] else {
            panic!("expected a polyline")
        };
        let first = points[0].distance(points[1]);
        let second = points[1].distance(points[2]);
        assert!(
            (first - first_len * second).abs() < 1e-6,
            "{view:?}: {first} vs {second}"
        );
    }
}

/// A 100×100 scene on white with one square from (20, 20) to (80, 80).
fn square_scene(outline: Option<render::Outline>, background: render::Rgba) -> Scene {
    let p = |x: f64, y: f64| glam::DVec2::new(x, y);
    Scene {
        width: 100,
        height: 100,
        background,
        items: vec![Item::Polygon {
            points: vec![p(20.0, 20.0), p(80.0, 20.0), p(80.0, 80.0), p(20.0, 80.0)],
            color: render::Rgba(200, 210, 220, 255),
            outline,
        }],
    }
}

#[test]
fn both_backends_stroke_a_polygon_outline_over_its_fill() {
    let white = render::Rgba(255, 255, 255, 255);
    let pen = render::Outline {
        color: render::Rgba(10, 20, 30, 255),
        width: 4.0,
    };
    let rgb = |s: &Scene, x: u32, y: u32| {
        let pm = tiny_skia::Pixmap::decode_png(&png::render(s).unwrap()).unwrap();
        let c = pm.pixel(x, y).unwrap().demultiply();
        [c.red(), c.green(), c.blue()]
    };
    let (plain, outlined) = (square_scene(None, white), square_scene(Some(pen), white));
    // On the edge, the outline covers the fill and reaches outside it.
    assert_eq!(rgb(&plain, 50, 19), [255, 255, 255]);
    assert_eq!(rgb(&outlined, 50, 20), [10, 20, 30]);
    assert_eq!(rgb(&outlined, 50, 19), [10, 20, 30]);
    // Inside, the fill is untouched.
    assert_eq!(rgb(&plain, 50, 50), [200, 210, 220]);
    assert_eq!(rgb(&outlined, 50, 50), [200, 210, 220]);
    let doc = svg::render(&outlined);
    assert_eq!(doc.matches("<polygon").count(), 1);
    for attr in [
        "points=\"20,20 80,20 80,80 20,80\"",
        "fill=\"#c8d2dc\"",
        "stroke=\"#0a141e\"",
        "stroke-width=\"4\"",
        "stroke-linejoin=\"round\"",
    ] {
        assert!(doc.contains(attr), "{attr} missing in {doc}");
    }
    assert!(!svg::render(&plain).contains("stroke"));
    // Polygons fill by the even-odd rule, as in the PNG: set on the root.
    let root = &doc[..doc.find('>').unwrap()];
    assert!(root.contains("fill-rule=\"evenodd\""), "{root}");
}

#[test]
fn an_svg_background_keeps_its_opacity() {
    let half = svg::render(&square_scene(None, render::Rgba(255, 0, 0, 128)));
    assert!(
        half.contains("fill=\"#ff0000\" fill-opacity=\"0.5\""),
        "{half}"
    );
    let opaque = svg::render(&square_scene(None, render::Rgba(255, 0, 0, 255)));
    assert!(!opaque.contains("fill-opacity"), "{opaque}");
    let none = svg::render(&square_scene(None, render::Rgba(0, 0, 0, 0)));
    assert!(!none.contains("<rect"), "{none}");
}

/// The coverage of thin lines in a PNG against the exact coverage of the
/// same strokes: the scene's polylines stroked one pixel wide by tiny-skia
/// without antialiasing at 8x8 samples per pixel, each pixel the mean of its
/// samples. A Koch island whose segments shrink to a few pixels, then to
/// fractions of one, where a curve passes a pixel many times.
#[test]
fn thin_lines_cover_pixels_as_the_strokes_do() {
    let src = "derivation length: 5;\nAxiom: Right(90) F(1);\n\
               F(v) : { produce F(v) Left(90) F(v) Right(90) F(v) Right(90) F(v) \
               F(v) Left(90) F(v) Left(90) F(v) Right(90) F(v); }\n";
    let l = load_text(src);
    for (steps, mean_bound) in [(2, 0.35), (3, 0.8), (4, 1.2), (5, 1.8)] {
        let opts = FigureOptions {
            derive: DeriveOptions {
                steps: Some(steps),
                ..Default::default()
            },
            render: RenderOptions {
                width: 240,
                height: 240,
                ..Default::default()
            },
            ..Default::default()
        };
        let scene = l.figure(&opts).unwrap();
        let got = tiny_skia::Pixmap::decode_png(&png::render(&scene).unwrap()).unwrap();
        let k = 8u32;
        let mut fine = tiny_skia::Pixmap::new(240 * k, 240 * k).unwrap();
        fine.fill(tiny_skia::Color::WHITE);
        for item in &scene.items {
            let Item::Polyline { points, color, .. } = item else {
                panic!("only polylines expected: {item:?}");
            };
            let mut pb = tiny_skia::PathBuilder::new();
            pb.move_to(points[0].x as f32 * k as f32, points[0].y as f32 * k as f32);
            for q in &points[1..] {
                pb.line_to(q.x as f32 * k as f32, q.y as f32 * k as f32);
            }
            let mut paint = tiny_skia::Paint::default();
            paint.set_color_rgba8(color.0, color.1, color.2, color.3);
            paint.anti_alias = false;
            let stroke = tiny_skia::Stroke {
                width: k as f32,
                line_cap: tiny_skia::LineCap::Butt,
                line_join: tiny_skia::LineJoin::Round,
                ..Default::default()
            };
            let path = pb.finish().unwrap();
            fine.stroke_path(&path, &paint, &stroke, Default::default(), None);
        }
        let (mut error, mut ink, mut exact_ink) = (0.0, 0.0, 0.0);
        for y in 0..240 {
            for x in 0..240 {
                let mut sum = 0.0;
                for j in 0..k {
                    for i in 0..k {
                        sum += fine.pixel(x * k + i, y * k + j).unwrap().red() as f64;
                    }
                }
                let exact = sum / (k * k) as f64;
                let drawn = got.pixel(x, y).unwrap().red() as f64;
                error += (drawn - exact).abs();
                ink += 255.0 - drawn;
                exact_ink += 255.0 - exact;
            }
        }
        let mean = error / (240.0 * 240.0);
        assert!(
            mean < mean_bound,
            "{steps} steps: mean difference {mean} from the exact coverage"
        );
        let ratio = ink / exact_ink;
        assert!(
            (0.9..1.1).contains(&ratio),
            "{steps} steps: {ratio} of the exact coverage's ink"
        );
    }
}
