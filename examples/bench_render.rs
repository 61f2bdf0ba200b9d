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
//! 3. Other pictures through the command line, each against a process
//!    that only derives it: two branching plants of about a million
//!    modules, lpfg's ABOP bush, and a dense tree of a million paths.
//!
//! `--runs N` keeps the best of N runs (3 by default); the commands of
//! sections 2 and 3 alternate round by round, and their medians and the
//! median of the rounds' ratios are printed beside the bests.

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
    others(runs);
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

/// This benchmark's own path and the `subgram` binary beside it; `None`,
/// said once, when the binary has not been built.
fn binaries() -> Option<(std::path::PathBuf, std::path::PathBuf)> {
    let exe = std::env::current_exe().unwrap();
    let bin = exe.parent()?.parent()?.join("subgram");
    if !bin.exists() {
        static SAID: std::sync::Once = std::sync::Once::new();
        SAID.call_once(|| {
            println!(
                "\n{} is missing: run `cargo build --release` first",
                bin.display()
            )
        });
        return None;
    }
    Some((exe, bin))
}

/// Runs each of `cmds` (a program, its arguments before the file, and the
/// file its output goes to: the PNG's by `-o`, the others' by stdout) on
/// `file`, one after another, `runs` rounds; every command's time in
/// every round. The last run's output is removed before the clock starts
/// (freeing 119 MB of page cache is not the command's work).
fn rounds(
    runs: usize,
    dir: &std::path::Path,
    file: &std::path::Path,
    cmds: &[(&std::path::Path, &[&str], &str)],
) -> Vec<Vec<Duration>> {
    let mut times = vec![Vec::new(); cmds.len()];
    for _ in 0..runs {
        for (k, (program, args, out)) in cmds.iter().enumerate() {
            let target = dir.join(out);
            let _ = std::fs::remove_file(&target);
            let started = std::time::Instant::now();
            let mut cmd = std::process::Command::new(program);
            cmd.args(*args).arg(file);
            if out.ends_with(".png") {
                cmd.arg("-o").arg(&target);
            } else {
                cmd.stdout(std::fs::File::create(&target).unwrap());
            }
            let ok = cmd.status().unwrap().success();
            times[k].push(started.elapsed());
            assert!(ok, "{} {args:?} failed", program.display());
        }
    }
    times
}

fn best(times: &[Duration]) -> Duration {
    times.iter().copied().min().unwrap()
}

fn median(times: &[Duration]) -> Duration {
    let mut t = times.to_vec();
    t.sort();
    t[t.len() / 2]
}

/// The median over the rounds of `a`'s time over `b`'s.
fn median_ratio(a: &[Duration], b: &[Duration]) -> f64 {
    let mut r: Vec<f64> = a
        .iter()
        .zip(b)
        .map(|(x, y)| x.as_secs_f64() / y.as_secs_f64())
        .collect();
    r.sort_by(f64::total_cmp);
    r[r.len() / 2]
}

/// Section 3: other pictures through the command line, each against a
/// process that only derives it, alternating round by round: branching
/// plants of about a million modules and a dense tree of a million paths.
/// What `render` of other words costs, so that a change to the walk or
/// the ink can be checked against them, not only against the island.
fn others(runs: usize) {
    let programs = [
        (
            "plant (stencil), 17 steps",
            "module A(float, float);\nderivation length: 17;\n\
             Axiom: SetColor(2) A(1, 0.05);\nproduction:\n\
             A(l, w) -> SetWidth(w) F(l) RollR(137.5) SB() Left(32) A(l*0.78, w*0.7) EB() \
             Right(18) A(l*0.86, w*0.8)\n",
        ),
        (
            "guarded branching, 11 steps",
            "module A(float, float);\nderivation length: 11;\nAxiom: A(1, 1);\n\
             production:\nA(l, w) : { if (l > 0.01) produce F(l) SB() Left(30) \
             A(l * 0.7, w * 0.7) EB() SB() Right(25) A(l * 0.6, w * 0.7) EB() \
             A(l * 0.9, w * 0.9); }\n",
        ),
        (
            "ABOP bush, 9 steps",
            "angle: 22.5;\nderivation length: 9;\nAxiom: X;\nX -> F-[[X]+X]+F[+FX]-X\nF -> FF\n",
        ),
        (
            "dense tree, 13 steps",
            "angle: 25;\nderivation length: 13;\nAxiom: F;\nF -> F[+F][-F]\n",
        ),
    ];
    let Some((exe, bin)) = binaries() else {
        return;
    };
    let dir = std::env::temp_dir().join(format!("subgram-bench-others-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    println!("\nother pictures through the command line, {runs} rounds alternating: best / median");
    for (name, src) in programs {
        let file = dir.join("program.lsys");
        std::fs::write(&file, src).unwrap();
        let cmds: [(&std::path::Path, &[&str], &str); 2] = [
            (&exe, &["--derive-only"], "derived.txt"),
            (&bin, &["render"], "picture.png"),
        ];
        let t = rounds(runs, &dir, &file, &cmds);
        println!(
            "  {name:<28} render {:>7.1} / {:>7.1} ms; derivation alone {:>6.1} / {:>6.1} ms; the rounds' median ratio {:.2}x",
            ms(best(&t[1])),
            ms(median(&t[1])),
            ms(best(&t[0])),
            ms(median(&t[0])),
            median_ratio(&t[1], &t[0])
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
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
    drop(d);
    // What `render` does in all, in this process (the derivation, the
    // turtle walking the last step's word as the step writes it, the
    // painting), alternating run by run with the derivation alone.
    let (mut t_whole, mut t_alone) = (Vec::new(), Vec::new());
    for _ in 0..runs {
        let started = std::time::Instant::now();
        let png = loaded.png_figures(&Default::default()).unwrap();
        t_whole.push(started.elapsed());
        drop(png);
        let started = std::time::Instant::now();
        let mut d = Derivation::new(p, DeriveOptions::default()).unwrap();
        while d.has_next() {
            d.next_step().unwrap();
        }
        t_alone.push(started.elapsed());
        drop(d);
    }

    let Some((exe, bin)) = binaries() else {
        return;
    };
    // The four commands alternate round by round, so that each round's
    // ratios compare runs made in the same seconds (this machine's speed
    // swings by 2x within minutes).
    let cmds: [(&std::path::Path, &[&str], &str); 4] = [
        (&exe, &["--derive-only"], "derived.txt"),
        (&bin, &["derive", "--format", "text"], "island.txt"),
        (&bin, &["derive", "--format", "json"], "island.json"),
        (&bin, &["render"], "island.png"),
    ];
    let times = rounds(runs, &dir, &file, &cmds);
    let len = |out: &str| std::fs::metadata(dir.join(out)).map_or(0, |m| m.len());
    let (text_len, json_len) = (len("island.txt"), len("island.json"));
    let _ = std::fs::remove_dir_all(&dir);
    let [t_process, t_text, t_json, t_render] = [0, 1, 2, 3].map(|k| best(&times[k]));
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
        "  a process that only reads the file and derives {:.1} ms best, {:.1} median; best to best: render {:.2}x, derive --format text {:.2}x, --format json {:.2}x",
        ms(t_process),
        ms(median(&times[0])),
        t_render.as_secs_f64() / t_process.as_secs_f64(),
        t_text.as_secs_f64() / t_process.as_secs_f64(),
        t_json.as_secs_f64() / t_process.as_secs_f64(),
    );
    for (k, what) in [
        (1, "derive --format text"),
        (2, "derive --format json"),
        (3, "render"),
    ] {
        println!(
            "    {what:<22} {:>7.1} ms median; the median of the rounds' ratios to the process that only derives {:.2}x",
            ms(median(&times[k])),
            median_ratio(&times[k], &times[0])
        );
    }
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
        "  in this process, alternating: derive and PNG (`Curve::png_figures`) {:.1} ms median, {:.1} best; the derivation alone {:.1} ms median, {:.1} best; the median of the runs' ratios {:.2}x",
        ms(median(&t_whole)),
        ms(best(&t_whole)),
        ms(median(&t_alone)),
        ms(best(&t_alone)),
        median_ratio(&t_whole, &t_alone)
    );
    println!(
        "  in this process: PNG of the laid-out scene {:.1} ms; tiny-skia stroking its segments as one path {:.1} ms ({:.2}x)",
        ms(t_png),
        ms(t_skia),
        t_skia.as_secs_f64() / t_png.as_secs_f64()
    );
}
