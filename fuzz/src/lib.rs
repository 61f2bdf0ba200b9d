//! The bodies of the fuzz targets, one function per target, each taking
//! the fuzzer's bytes. They are the only place where a target's code path
//! is written down: the cargo-fuzz targets (`fuzz/fuzz_targets/*.rs`) call
//! them, and the stable `cargo test` at the project root compiles this
//! same file as a module (`tests/it/fuzz_replay.rs`, `#[path]`) to replay
//! the seed corpora and the minimised findings through them. So this file
//! uses nothing but `std`, `subgram`, `glam` and `serde_json`, which the
//! root package's tests can use too.
//!
//! A body returns normally whatever the input is; a panic, an abort, a
//! timeout or running out of memory is a finding. The checks that
//! `assert!` are properties the README promises (a mesh written and read
//! again is the same; a built or subdivided mesh validates).
//!
//! Limits are small on purpose, so that each execution is quick: a few
//! derivation steps, a few thousand modules, a small fixed base mesh and a
//! face limit of a few thousand.

#![allow(dead_code)]

use glam::DVec2;
use subgram::mesh::io::{self, Format};
use subgram::mesh::{shapes, Mesh, PolygonSoup};
use subgram::render::{self, RenderOptions};
use subgram::reverse::input::{self as contour_input, Contour};
use subgram::reverse::{self, Details, Phase, ReverseOptions, Scheme};
use subgram::{DeriveOptions, LoadOptions, System};

/// A target's body.
pub type Body = fn(&[u8]);

/// The names of the targets, as in `fuzz/Cargo.toml`, with their bodies.
pub const TARGETS: &[(&str, Body)] = &[
    ("lsys_check", lsys_check),
    ("lsys_derive", lsys_derive),
    ("mesh_read", mesh_read),
    ("surface_run", surface_run),
    ("contour_reverse", contour_reverse),
    ("details_reconstruct", details_reconstruct),
    ("model_files", model_files),
    ("vv_run", vv_run),
    ("shape_derive", shape_derive),
    ("serve_request", serve_request),
];

/// Steps of a curve derivation.
pub const CURVE_STEPS: u64 = 3;
/// The longest word a derivation, decomposition or interpretation may make.
pub const MAX_MODULES: usize = 2_000;
/// The most faces a surface rule may make.
pub const MAX_FACES: usize = 2_000;
/// The most points of a coarse contour built for a details file.
pub const MAX_COARSE: usize = 4_096;

/// Text as the library takes it: invalid UTF-8 is replaced, as a user's
/// editor would show it (the loader takes `&str`; reading files as UTF-8
/// is not what is fuzzed here).
fn text(data: &[u8]) -> std::borrow::Cow<'_, str> {
    String::from_utf8_lossy(data)
}

/// (a) Lexing, preprocessing, parsing and checking a `.lsys` text, curve
/// L-system or surface grammar, through the public facade; errors and
/// warnings are rendered with their `file:line:col`, line and caret.
pub fn lsys_check(data: &[u8]) {
    let text = text(data);
    match subgram::load_text("fuzz.lsys", &text, &LoadOptions::default()) {
        Ok(system) => {
            for w in system.warnings() {
                std::hint::black_box(w);
            }
        }
        Err(e) => {
            std::hint::black_box(e.to_string());
        }
    }
}

/// (b) A curve L-system loaded, derived a few steps with a small module
/// limit, printed as text and JSON, interpreted, and drawn: its 3D
/// geometry (checked), turtle events, the scene fitted to a small picture,
/// and its SVG.
pub fn lsys_derive(data: &[u8]) {
    let text = text(data);
    let Ok(System::Curve(curve)) = subgram::load_text("fuzz.lsys", &text, &LoadOptions::default())
    else {
        return;
    };
    let opts = DeriveOptions::default()
        .with_steps(CURVE_STEPS)
        .with_max_modules(MAX_MODULES);
    let mut run = match curve.run(opts) {
        Ok(run) => run,
        Err(e) => {
            std::hint::black_box(e.to_string());
            return;
        }
    };
    std::hint::black_box(run.text());
    std::hint::black_box(run.json());
    // The 3D geometry, lines as tubes, within a small limit: every index
    // names a vertex, every vertex has a normal, every number is finite.
    let sopts = subgram::draw::solid::SolidOptions {
        line_style: Some(subgram::model::view::LineStyle::Cylinder),
        max_triangles: 200_000,
        max_vertices: 200_000,
        pixel_tubes: None,
        picture_pixel: None,
        fit_pixels: None,
    };
    match run.solid(&sopts) {
        Ok(scene) => {
            for m in &scene.meshes {
                assert_eq!(m.normals.len(), m.positions.len());
                assert!(m.positions.iter().chain(&m.normals).all(|p| p.is_finite()));
                let n = m.positions.len() as u32;
                assert!(m.triangles.iter().flatten().all(|i| *i < n));
            }
        }
        Err(e) => {
            std::hint::black_box(e.to_string());
        }
    }
    // A picture's geometry, its scale found by the walk that makes it, is
    // the geometry made knowing the scale beforehand: the same meshes in
    // the same order, the same lines, as many triangles and vertices; or
    // the same error.
    let fit = 90.0;
    let found = run.solid(&subgram::draw::solid::SolidOptions {
        fit_pixels: Some(fit),
        ..sopts.clone()
    });
    let px = match run.line_bounds() {
        Ok(Some((lo, hi))) => subgram::draw::solid::pixel_of((hi - lo).max_element(), fit),
        _ => 1.0,
    };
    let known = run.solid(&subgram::draw::solid::SolidOptions {
        picture_pixel: Some(px),
        ..sopts
    });
    match (found, known) {
        (Ok(a), Ok(b)) => {
            assert_eq!(a.looks.len(), b.looks.len());
            for (x, y) in a.looks.iter().zip(&b.looks) {
                assert_eq!(x.name, y.name);
            }
            for (m, n) in a.meshes.iter().zip(&b.meshes) {
                assert_eq!(m.positions.len(), n.positions.len());
                assert_eq!(m.triangles.len(), n.triangles.len());
                assert!(m.lines == n.lines);
            }
        }
        (Err(a), Err(b)) => assert_eq!(a.to_string(), b.to_string()),
        (a, b) => panic!("{:?} against {:?}", a.err(), b.err()),
    }
    let events = match run.events() {
        Ok(ev) => ev,
        Err(e) => {
            std::hint::black_box(e.to_string());
            return;
        }
    };
    let small = RenderOptions {
        width: 64,
        height: 64,
        ..RenderOptions::default()
    };
    if let Ok(scene) = render::scene(&[events], &small) {
        std::hint::black_box(render::svg::render(&scene));
    }
}

/// (c) The bytes read as OBJ, as OFF and as PLY (ASCII or binary); a soup
/// that reads is written in each format and read back to the same
/// positions and faces, built into a half-edge mesh (which must validate),
/// described and turned back into a soup.
pub fn mesh_read(data: &[u8]) {
    for format in [Format::Obj, Format::Off, Format::Ply] {
        let soup = match io::read_str("fuzz", format, data) {
            Ok(s) => s,
            Err(e) => {
                std::hint::black_box(e.to_string());
                continue;
            }
        };
        for out in [Format::Obj, Format::Off, Format::Ply] {
            let bytes = io::to_bytes(out, &soup);
            let again = io::read_str("again", out, &bytes).unwrap_or_else(|e| {
                panic!("a soup written as {} does not read back: {e}", out.name())
            });
            assert_eq!(
                again.positions,
                soup.positions,
                "positions after {}",
                out.name()
            );
            assert_eq!(again.faces, soup.faces, "faces after {}", out.name());
        }
        build(&soup);
    }
}

/// A soup built into a mesh; a mesh that builds must validate.
fn build(soup: &PolygonSoup) {
    match Mesh::from_soup(soup) {
        Ok(mesh) => {
            if let Err(e) = mesh.validate() {
                panic!("a mesh built from a soup does not validate: {}", e.message);
            }
            std::hint::black_box(mesh.info().to_string());
            std::hint::black_box(mesh.to_quad_soup());
        }
        Err(e) => {
            std::hint::black_box(e.message);
        }
    }
}

/// The base mesh of a surface run: an icosahedron (closed triangles), a
/// 3×3 quad torus (closed quads, blocks) or a 2×2 quad grid (open), chosen
/// by the input's length.
pub fn base_mesh(data: &[u8]) -> PolygonSoup {
    match data.len() % 3 {
        0 => shapes::icosahedron(),
        1 => shapes::quad_torus(3, 3),
        _ => shapes::quad_grid(2, 2),
    }
}

/// (d) A surface grammar loaded and run on a small fixed mesh for its
/// derivation length clamped to 1..=2 steps, with a face limit of
/// [`MAX_FACES`]. Whether the run succeeds or stops with an error, the
/// mesh must validate (a refused operator leaves the mesh as it was); it is
/// then described, turned into polygons and drawn into a scene.
pub fn surface_run(data: &[u8]) {
    let text = text(data);
    let Ok(System::Surface(mut surface)) =
        subgram::load_text("fuzz.lsys", &text, &LoadOptions::default())
    else {
        return;
    };
    surface.grammar.max_faces = MAX_FACES;
    let steps = surface.grammar.length.unwrap_or(1).clamp(1, 2) as usize;
    let Ok(mut mesh) = Mesh::from_soup(&base_mesh(data)) else {
        panic!("the fixed base mesh does not build");
    };
    if let Err(e) = surface.run_on(&mut mesh, steps, None, |p| {
        std::hint::black_box(p);
    }) {
        std::hint::black_box(e.to_string());
    }
    if let Err(e) = mesh.validate() {
        panic!(
            "a mesh after a surface run does not validate: {}",
            e.message
        );
    }
    std::hint::black_box(mesh.info().to_string());
    let soup = mesh.to_quad_soup();
    let view = render::mesh::MeshView {
        width: 64,
        height: 64,
        ..Default::default()
    };
    if let Ok(scene) = render::mesh::scene(&soup, &view) {
        std::hint::black_box(scene);
    }
}

/// The most vertices a vv program may make in a fuzz run.
pub const MAX_VV_VERTICES: usize = 20_000;

/// (h) A vv program loaded and run on the fixed base mesh of
/// [`base_mesh`] (or the one it builds in `Start`) for its derivation
/// length clamped to 1..=2 steps, with at most [`MAX_VV_VERTICES`]
/// vertices; whether it succeeds or stops with an error, what it made is
/// described, and its polygons drawn into a scene.
pub fn vv_run(data: &[u8]) {
    let text = text(data);
    let Ok(System::Vv(mut vv)) = subgram::load_text("fuzz.lsys", &text, &LoadOptions::default())
    else {
        return;
    };
    vv.program.max_vertices = MAX_VV_VERTICES;
    let opts = subgram::RunOptions::default().with_steps(1 + data.len() as u64 % 2);
    match vv.run_soup(&base_mesh(data), &opts) {
        Ok(run) => {
            std::hint::black_box(run.info.to_string());
            draw_small(&run.soup);
        }
        Err(e) => {
            std::hint::black_box(e.to_string());
        }
    }
}

/// The contours the bytes make as a point list, an SVG document and a PNG
/// image, each with at least the 3 points `reverse::input::read` asks.
pub fn contours(data: &[u8]) -> Vec<Contour> {
    let mut found = Vec::new();
    let mut keep = |r: Result<Contour, contour_input::InputError>| match r {
        Ok(c) if c.points.len() >= 3 => found.push(c),
        Ok(_) => {}
        Err(e) => {
            std::hint::black_box(e.to_string());
        }
    };
    if let Ok(text) = std::str::from_utf8(data) {
        keep(contour_input::read_points("fuzz.txt", text));
        keep(contour_input::read_svg("fuzz.svg", text));
    }
    keep(contour_input::read_png("fuzz.png", data));
    found
}

/// (e) Contour inputs (point lists, SVG, PNG) and reverse subdivision:
/// two levels (one below 12 points) with the built-in scheme, the automatic phase and details
/// (open instead of closed when the input's length is odd, as `--open`),
/// then the report, the figure's events, the coarse polygon written out,
/// and the reconstruction from the details.
pub fn contour_reverse(data: &[u8]) {
    for mut contour in contours(data) {
        if data.len() % 2 == 1 {
            contour.closed = false;
        }
        let scheme = Scheme::builtin(contour.closed);
        let opts = ReverseOptions {
            steps: if contour.points.len() >= 12 { 2 } else { 1 },
            phase: Phase::Auto,
            details: true,
        };
        let r = match reverse::reverse(&scheme, &contour, &opts) {
            Ok(r) => r,
            Err(e) => {
                std::hint::black_box(e.to_string());
                continue;
            }
        };
        std::hint::black_box(reverse::format_points(
            &r.coarse,
            contour.closed,
            std::path::Path::new("coarse.csv"),
        ));
        match reverse::report(&scheme, &contour, &r) {
            Ok(rep) => std::hint::black_box(rep.to_string()),
            Err(e) => std::hint::black_box(e.to_string()),
        };
        if let Ok(rec) = scheme.forward(&r.coarse, r.steps.len()) {
            std::hint::black_box(reverse::figure_events(&contour, &r.coarse, &rec));
        }
        if let Some(d) = &r.details {
            match reverse::reconstruct(&scheme, &r.coarse, d, None) {
                Ok(p) => std::hint::black_box(p.len()),
                Err(e) => std::hint::black_box(e.to_string().len()),
            };
        }
    }
}

/// A details file (JSON, as `reverse --details` writes it) read and used
/// to reconstruct, with the built-in scheme, from a regular polygon of its
/// `coarse_points` (at most [`MAX_COARSE`]): every level, then the first.
pub fn details_reconstruct(data: &[u8]) {
    let Ok(d) = serde_json::from_slice::<Details>(data) else {
        return;
    };
    if d.coarse_points > MAX_COARSE {
        return;
    }
    let n = d.coarse_points;
    let coarse: Vec<DVec2> = (0..n)
        .map(|i| {
            let a = i as f64 / n.max(1) as f64 * std::f64::consts::TAU;
            DVec2::new(a.cos(), a.sin())
        })
        .collect();
    let scheme = Scheme::builtin(d.closed);
    for upto in [None, Some(1)] {
        match reverse::reconstruct(&scheme, &coarse, &d, upto) {
            Ok(p) => {
                std::hint::black_box(reverse::format_points(
                    &p,
                    d.closed,
                    std::path::Path::new("restored.txt"),
                ));
            }
            Err(e) => {
                std::hint::black_box(e.to_string());
            }
        }
    }
}

/// (g) A model file of lpfg's folders: the first byte chooses the format
/// (`.fset`, `.func`, `.tset`, `.vset`, `.cset`, `.con`, `.s`, `.v`, `.a`,
/// `.map`, `.mat`), the rest is the file. What reads is evaluated: every
/// function at a few x (clamped, NaN and infinities too), every contour's
/// points and normals, scaled, edited and recalculated, every surface's
/// triangles, every colour lit by the file's lights.
pub fn model_files(data: &[u8]) {
    use subgram::model::{colours, contours, functions, surface, view};
    let Some((&kind, rest)) = data.split_first() else {
        return;
    };
    let text = text(rest);
    let xs = [-1.0f32, 0.0, 0.3, 0.5, 1.0, 2.0, f32::NAN, f32::INFINITY];
    let funcs = |r: Result<Vec<functions::Function>, subgram::model::ModelError>| match r {
        Ok(fs) => {
            for f in fs {
                for x in xs {
                    std::hint::black_box((f.value(x), f.tangent(x), f.timeline_value(x)));
                }
            }
        }
        Err(e) => {
            std::hint::black_box(e.to_string());
        }
    };
    let conts = |r: Result<Vec<contours::Contour>, subgram::model::ModelError>| match r {
        Ok(cs) => {
            for mut c in cs {
                for x in xs {
                    std::hint::black_box((c.point(x), c.normal(x)));
                }
                c.scale([2.0, 0.5, f32::NAN]);
                c.set_point(0, [1.0, 1.0, 1.0]);
                c.recalculate();
                c.reset();
                std::hint::black_box(c.point(0.5));
            }
        }
        Err(e) => {
            std::hint::black_box(e.to_string());
        }
    };
    let mut notes = Vec::new();
    match kind % 11 {
        0 => funcs(functions::read_fset("fuzz.fset", &text)),
        1 => funcs(functions::read_func("fuzz.func", &text)),
        2 => funcs(functions::read_tset("fuzz.tset", &text)),
        3 => funcs(functions::read_vset("fuzz.vset", &text)),
        4 => conts(contours::read_cset("fuzz.cset", &text)),
        5 => conts(contours::read_con("fuzz.con", &text)),
        6 => match surface::read_s("fuzz.s", "fuzz", &text) {
            Ok(s) => {
                std::hint::black_box(s.triangles(3));
            }
            Err(e) => {
                std::hint::black_box(e.to_string());
            }
        },
        7 => match view::read_v("fuzz.v", &text, &mut notes) {
            Ok(v) => {
                let mut map = vec![0u8; 768];
                map.iter_mut().zip(rest).for_each(|(m, b)| *m = *b);
                for c in [
                    colours::read_map("m", &map),
                    colours::read_mat("m", &map[..750]),
                ] {
                    let c = c.expect("well-sized colour files read");
                    for i in [-1, 0, 1, 255, 256] {
                        std::hint::black_box(c.colour(i, &v.lights));
                    }
                }
            }
            Err(e) => {
                std::hint::black_box(e.to_string());
            }
        },
        8 => {
            let _ = std::hint::black_box(
                view::read_a("fuzz.a", &text, &mut notes).map_err(|e| e.to_string()),
            );
        }
        9 => {
            let _ = std::hint::black_box(
                colours::read_map("fuzz.map", rest).map_err(|e| e.to_string()),
            );
        }
        _ => {
            let _ = std::hint::black_box(
                colours::read_mat("fuzz.mat", rest).map_err(|e| e.to_string()),
            );
        }
    }
    std::hint::black_box(notes);
}

/// The most shapes a shape grammar may make in a fuzz run.
pub const MAX_SHAPES: usize = 2_000;

/// (i) A shape grammar (paper 003) loaded, checked and derived with at
/// most [`MAX_SHAPES`] shapes and a deadline of two seconds, from the
/// input's length as the seed; whether it succeeds or stops with an
/// error, its tree is written as text and JSON, its terminal shapes as an
/// OBJ with its MTL, and its coloured faces drawn into a scene.
pub fn shape_derive(data: &[u8]) {
    let text = text(data);
    let Ok(System::Shapes(shapes)) =
        subgram::load_text("fuzz.lsys", &text, &LoadOptions::default())
    else {
        return;
    };
    let opts = subgram::RunOptions {
        seed: Some(data.len() as u32),
        max_shapes: Some(MAX_SHAPES),
        deadline: Some(subgram::Deadline::after(std::time::Duration::from_secs(2))),
        ..Default::default()
    };
    match shapes.derive(&opts) {
        Ok(run) => {
            std::hint::black_box(shapes.tree_text(&run));
            std::hint::black_box(shapes.groups_text(&run));
            std::hint::black_box(shapes.tree_json(&run));
            std::hint::black_box(shapes.obj(&run, "fuzz.mtl"));
            draw_small(&run.soup);
        }
        Err(e) => {
            std::hint::black_box(e.to_string());
        }
    }
}

/// Draws a soup as a 64 x 64 scene, as the binary would, and drops it.
fn draw_small(soup: &subgram::mesh::PolygonSoup) {
    let view = render::mesh::MeshView {
        width: 64,
        height: 64,
        ..Default::default()
    };
    if let Ok(scene) = render::mesh::scene(soup, &view) {
        std::hint::black_box(scene);
    }
}

/// The port that `serve_request`'s server pretends to listen on: `$PORT`
/// in an input stands for it.
pub const SERVE_PORT: u16 = 8080;

/// (j) `subgram serve`'s answer to one connection, without a socket
/// (`subgram::serve::App::exchange`: the server's own HTTP/1.1 reading of
/// the request, then its checks and routes), on a scratch copy of a small
/// program with saving on, under the small limits above. The input is the
/// bytes the client sends; in it `$TOKEN` stands for the run's token
/// (which the fuzzer cannot guess), `$PORT` for [`SERVE_PORT`] and `$LEN`
/// for the length of what follows the head, so that inputs get past the
/// checks. What must hold: the output is an HTTP/1.1 reply with the
/// status returned; every reply says `nosniff`; a refusal is JSON with
/// `ok: false`; nothing is answered 200 unless `Host` names the server,
/// nor on the API without the token.
pub fn serve_request(data: &[u8]) {
    use std::sync::atomic::{AtomicUsize, Ordering};
    use subgram::serve::{App, Limits, ServeOptions, TOKEN_HEADER};
    static RUN: AtomicUsize = AtomicUsize::new(0);

    let dir = std::env::temp_dir().join(format!(
        "subgram-fuzz-serve-{}-{}",
        std::process::id(),
        RUN.fetch_add(1, Ordering::Relaxed)
    ));
    std::fs::create_dir_all(&dir).expect("a scratch folder");
    let program = dir.join("prog.lsys");
    std::fs::write(
        &program,
        "angle: 60;\nderivation length: 2;\nAxiom: F--F--F;\nF -> F+F--F+F\n",
    )
    .expect("a scratch program");
    let opts = ServeOptions {
        path: program,
        port: SERVE_PORT,
        save: true,
        limits: Limits {
            max_modules: MAX_MODULES,
            max_steps: CURVE_STEPS,
            timeout: std::time::Duration::from_secs(2),
            ..Limits::default()
        },
        defines: Vec::new(),
        double: false,
    };
    let app = App::new(opts, SERVE_PORT).expect("the scratch program reads");
    let mut input = replace(data, b"$TOKEN", app.token().as_bytes());
    input = replace(&input, b"$PORT", SERVE_PORT.to_string().as_bytes());
    if let Some(at) = input.windows(4).position(|w| w == b"\r\n\r\n") {
        let length = (input.len() - at - 4).to_string();
        let head = replace(&input[..at], b"$LEN", length.as_bytes());
        input = [&head[..], &input[at..]].concat();
    }
    let mut output = Vec::new();
    let (head, reply) = app.exchange(&mut &input[..], &mut output);
    let _ = std::fs::remove_dir_all(&dir);

    let output = String::from_utf8_lossy(&output);
    let status_line = format!("HTTP/1.1 {} ", reply.status);
    assert!(
        output.starts_with(&status_line)
            || (output.starts_with("HTTP/1.1 100 Continue\r\n\r\n")
                && output[25..].starts_with(&status_line)),
        "{output}"
    );
    assert_eq!(reply.header("X-Content-Type-Options"), Some("nosniff"));
    assert!((200..600).contains(&reply.status), "{}", reply.status);
    if reply.status != 200 {
        let v: serde_json::Value = serde_json::from_slice(&reply.body).expect("a refusal is JSON");
        assert_eq!(v["ok"], false, "{v}");
        assert!(v["message"].is_string(), "{v}");
        return;
    }
    let head = head.expect("a request answered 200 was read");
    let values = |name: &str| -> Vec<&str> {
        head.headers
            .iter()
            .filter(|(n, _)| n.eq_ignore_ascii_case(name))
            .map(|(_, v)| v.trim())
            .collect()
    };
    let host = values("Host");
    let ours = [
        format!("127.0.0.1:{SERVE_PORT}"),
        format!("localhost:{SERVE_PORT}"),
    ];
    assert!(
        host.len() == 1 && ours.iter().any(|o| o.eq_ignore_ascii_case(host[0])),
        "answered 200 for Host {host:?}"
    );
    if head.url.starts_with("/api/") {
        assert_eq!(
            values(TOKEN_HEADER),
            [app.token()],
            "answered the API without the token"
        );
    }
}

/// `bytes` with every `from` replaced by `to`.
fn replace(bytes: &[u8], from: &[u8], to: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i..].starts_with(from) {
            out.extend_from_slice(to);
            i += from.len();
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    out
}
