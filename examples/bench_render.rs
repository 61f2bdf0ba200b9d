//! Rendering and word output, against the derivation they follow.
//! `cargo build --release && cargo run --release --example bench_render`
//!
//! 1. 1,048,576 segments (a Koch snowflake curve, 10 steps) to PNG and to
//!    SVG: derivation, turtle interpretation, layout, PNG and SVG
//!    separately, with a reference measured in the same run: tiny-skia
//!    stroking the same points as one path, with no engine around it.
//! 2. The quadratic Koch island of lpfg's corpus at 7 steps (3,894,711
//!    modules, 2,097,152 segments; issue 16, items 1 and 2) through the
//!    command line, files in and out, each against the derivation alone in
//!    this process: `subgram derive --format text` and `--format json`
//!    into a file, and `subgram render` to an 800x800 PNG; in this
//!    process, the PNG of the derived word (what `render` does after
//!    deriving) and the PNG of the laid-out scene; and
//!    tiny-skia stroking the island's segments as one path.
//!
//! `--runs N` keeps the best of N runs (3 by default).

mod common;

use std::time::Duration;

use common::best_of;
use subgram::render::{png, svg, Item};
use subgram::{Derivation, DeriveOptions};

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if let Some(i) = args.iter().position(|a| a == "--derive-only") {
        derive_only(&args[i + 1]);
        return;
    }
    let runs = common::runs_arg(&args, 3);
    snowflake(runs);
    island(runs);
}

/// The reference process for `render`'s: reads the file, derives it, and
/// exits (the same start, file reading and fresh memory as a command's
/// derivation, and nothing after it).
fn derive_only(file: &str) {
    let src = std::fs::read_to_string(file).unwrap();
    let loaded = subgram::load_str(file, &src, &[]).expect("loads");
    let mut d = Derivation::new(&loaded.program, DeriveOptions::default()).unwrap();
    while d.has_next() {
        d.next_step().unwrap();
    }
    assert!(!d.word.is_empty());
}

fn snowflake(runs: usize) {
    let src = "derivation length: 10;\nAxiom: F(1);\n\
               F(x) -> F(x) Left(60) F(x) Right(120) F(x) Left(60) F(x)\n";
    let loaded = subgram::load_str("koch.lsys", src, &[]).expect("loads");
    let p = &loaded.program;

    let (t_derive, word) = best_of(runs, || {
        let mut d = Derivation::new(p, DeriveOptions::default()).unwrap();
        while d.has_next() {
            d.next_step().unwrap();
        }
        d.interpret().unwrap()
    });
    let (t_draw, events) = best_of(runs, || {
        subgram::draw::draw(&word, &p.alphabet, &p.structs, &Default::default()).unwrap()
    });
    let segments: usize = events.iter().map(|e| e.segments().count()).sum();
    assert_eq!(segments, 1 << 20);
    let opts = subgram::render::RenderOptions::default();
    let (t_layout, scene) = best_of(runs, || {
        subgram::render::scene(std::slice::from_ref(&events), &opts).unwrap()
    });
    let (t_png, png_bytes) = best_of(runs, || png::render(&scene).unwrap());
    let (t_svg, svg_text) = best_of(runs, || svg::render(&scene));

    let (t_ref, _) = best_of(runs, || stroke_alone(&scene));
    println!("1,048,576 segments, 800x800, best of {runs}");
    println!("  derive + interpret      {:>8.1} ms", ms(t_derive));
    println!("  turtle -> events        {:>8.1} ms", ms(t_draw));
    println!("  fit + layout            {:>8.1} ms", ms(t_layout));
    println!(
        "  PNG raster + encode     {:>8.1} ms  ({} KiB)",
        ms(t_png),
        png_bytes.len() / 1024
    );
    println!(
        "  SVG write               {:>8.1} ms  ({} KiB)",
        ms(t_svg),
        svg_text.len() / 1024
    );
    println!(
        "  reference: tiny-skia alone, same points, PNG  {:>8.1} ms",
        ms(t_ref)
    );
    println!(
        "  total to PNG {:.1} ms, to SVG {:.1} ms",
        ms(t_derive + t_draw + t_layout + t_png),
        ms(t_derive + t_draw + t_layout + t_svg)
    );
}

/// tiny-skia stroking every polyline point of `scene` as one path (a pen
/// of one pixel, antialiased) and encoding the PNG: the reference.
fn stroke_alone(scene: &subgram::render::Scene) -> Vec<u8> {
    let mut pm = tiny_skia::Pixmap::new(scene.width, scene.height).unwrap();
    pm.fill(tiny_skia::Color::WHITE);
    let mut pb = tiny_skia::PathBuilder::new();
    for item in &scene.items {
        if let Item::Polyline { points, .. } = item {
            pb.move_to(points[0].x as f32, points[0].y as f32);
            for q in &points[1..] {
                pb.line_to(q.x as f32, q.y as f32);
            }
        }
    }
    let path = pb.finish().unwrap();
    let mut paint = tiny_skia::Paint::default();
    paint.set_color_rgba8(0, 0, 0, 255);
    paint.anti_alias = true;
    let stroke = tiny_skia::Stroke::default();
    pm.stroke_path(
        &path,
        &paint,
        &stroke,
        tiny_skia::Transform::identity(),
        None,
    );
    pm.encode_png().unwrap()
}

/// The quadratic Koch island (lpfg corpus `01-quadratic-Koch.l`, same
/// rules) at 7 steps through the command line.
fn island(runs: usize) {
    let src = "derivation length: 7;\nAxiom: Right(90) F(1.0);\n\
               F(v) : { produce F(v) Left(90) F(v) Right(90) F(v) Right(90) F(v) \
               F(v) Left(90) F(v) Left(90) F(v) Right(90) F(v); }\n";
    let dir = std::env::temp_dir().join(format!("subgram-bench-render-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("island.lsys");
    std::fs::write(&file, src).unwrap();
    let loaded = subgram::load_str("island.lsys", src, &[]).expect("loads");
    let p = &loaded.program;
    // The first derivation in this process meets fresh memory, as a
    // command's does; the best of the later runs reuses memory.
    let started = std::time::Instant::now();
    let mut first = Derivation::new(p, DeriveOptions::default()).unwrap();
    while first.has_next() {
        first.next_step().unwrap();
    }
    let t_first = started.elapsed();
    drop(first);
    let (t_derive, d) = best_of(runs, || {
        let mut d = Derivation::new(p, DeriveOptions::default()).unwrap();
        while d.has_next() {
            d.next_step().unwrap();
        }
        d
    });
    let word = &d.word;
    assert_eq!(word.len(), 3_894_711);
    let events = subgram::draw::draw(word, &p.alphabet, &p.structs, &Default::default()).unwrap();
    let scene = subgram::render::scene(&[events], &Default::default()).unwrap();
    let (t_skia, _) = best_of(runs, || stroke_alone(&scene));
    let (t_png, _) = best_of(runs, || png::render(&scene).unwrap());
    // What `render` does after deriving: the turtle walks the word once,
    // keeping its lines' points and finding the box; the points are laid
    // out in place and painted.
    let (t_walked, _) = best_of(runs, || {
        png::word(
            word,
            &p.alphabet,
            &p.structs,
            &Default::default(),
            &Default::default(),
        )
        .unwrap()
    });

    // A walk that only finds the box, for comparison.
    let (t_box, _) = best_of(runs, || {
        subgram::draw::line_bounds(word, &p.alphabet, &p.structs, &Default::default()).unwrap()
    });

    let exe = std::env::current_exe().unwrap();
    let bin = exe
        .parent()
        .and_then(|d| d.parent())
        .unwrap()
        .join("subgram");
    if !bin.exists() {
        println!(
            "\n{} is missing: run `cargo build --release` first",
            bin.display()
        );
        return;
    }
    // Each run writes a new file: the last run's output is removed before
    // the clock starts (freeing 119 MB of page cache is not the command's
    // work, nor the derivation's it is compared with).
    let process = |program: &std::path::Path, args: &[&str], out: &str| {
        let target = dir.join(out);
        let mut best = std::time::Duration::MAX;
        for _ in 0..runs {
            let _ = std::fs::remove_file(&target);
            let started = std::time::Instant::now();
            let stdout = std::fs::File::create(&target).unwrap();
            let mut cmd = std::process::Command::new(program);
            cmd.args(args).arg(&file);
            if out.ends_with(".png") {
                cmd.arg("-o").arg(&target);
            } else {
                cmd.stdout(stdout);
            }
            let ok = cmd.status().unwrap().success();
            best = best.min(started.elapsed());
            assert!(ok, "{} {args:?} failed", program.display());
        }
        (best, std::fs::metadata(&target).unwrap().len())
    };
    let cli = |args: &[&str], out: &str| process(&bin, args, out);
    let (t_process, _) = process(&exe, &["--derive-only"], "derived.txt");
    let (t_text, text_len) = cli(&["derive", "--format", "text"], "island.txt");
    let (t_json, json_len) = cli(&["derive", "--format", "json"], "island.json");
    let (t_render, _) = cli(&["render"], "island.png");
    let _ = std::fs::remove_dir_all(&dir);

    println!("\nquadratic Koch island, 7 steps: 3,894,711 modules, best of {runs}");
    println!(
        "  derivation in this process: first run (fresh memory) {:.1} ms, best of the rest {:.1} ms",
        ms(t_first),
        ms(t_derive)
    );
    let row = |what: &str, t: Duration, size: String| {
        println!(
            "  {what:<28} {:>8.1} ms  {:>5.2}x the first run, {:>5.2}x the best  {size}",
            ms(t),
            t.as_secs_f64() / t_first.as_secs_f64(),
            t.as_secs_f64() / t_derive.as_secs_f64(),
        )
    };
    row(
        "subgram derive --format text",
        t_text,
        format!("({} MB)", text_len >> 20),
    );
    row(
        "subgram derive --format json",
        t_json,
        format!("({} MB)", json_len >> 20),
    );
    row("subgram render -o PNG", t_render, String::new());
    println!(
        "  a process that only reads the file and derives {:.1} ms: render {:.2}x, derive --format text {:.2}x, --format json {:.2}x",
        ms(t_process),
        t_render.as_secs_f64() / t_process.as_secs_f64(),
        t_text.as_secs_f64() / t_process.as_secs_f64(),
        t_json.as_secs_f64() / t_process.as_secs_f64(),
    );
    println!(
        "  in this process: the PNG of the derived word (what `render` does after deriving) {:.1} ms ({:.2}x the derivation's first run, {:.2}x the best)",
        ms(t_walked),
        t_walked.as_secs_f64() / t_first.as_secs_f64(),
        t_walked.as_secs_f64() / t_derive.as_secs_f64()
    );
    println!(
        "    a walk of the turtle that only finds the drawing's box {:.1} ms",
        ms(t_box)
    );
    println!(
        "  in this process: PNG of the laid-out scene {:.1} ms; tiny-skia stroking its segments as one path {:.1} ms ({:.2}x)",
        ms(t_png),
        ms(t_skia),
        t_skia.as_secs_f64() / t_png.as_secs_f64()
    );
}
