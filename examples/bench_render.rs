//! Rendering 1,048,576 segments (a Koch snowflake curve, 10 steps) to PNG
//! and to SVG. `cargo run --release --example bench_render`
//!
//! Reported: derivation, turtle interpretation, layout, PNG encoding and SVG
//! writing separately, with a reference measured in the same run: tiny-skia
//! stroking the same points as one path, with no engine around it.

mod common;

use std::time::Duration;

use common::best_of;
use subgram::render::{png, svg, Item};
use subgram::{Derivation, DeriveOptions};

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

fn main() {
    let runs = 3;
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
    assert_eq!(events.len(), 1 << 20);
    let opts = subgram::render::RenderOptions::default();
    let (t_layout, scene) = best_of(runs, || {
        subgram::render::scene(std::slice::from_ref(&events), &opts).unwrap()
    });
    let (t_png, png_bytes) = best_of(runs, || png::render(&scene).unwrap());
    let (t_svg, svg_text) = best_of(runs, || svg::render(&scene));

    // Reference: the same points stroked directly with tiny-skia.
    let points: Vec<glam::DVec2> = scene
        .items
        .iter()
        .flat_map(|i| match i {
            Item::Polyline { points, .. } => points.clone(),
            _ => Vec::new(),
        })
        .collect();
    let (t_ref, _) = best_of(runs, || {
        let mut pm = tiny_skia::Pixmap::new(800, 800).unwrap();
        pm.fill(tiny_skia::Color::WHITE);
        let mut pb = tiny_skia::PathBuilder::new();
        pb.move_to(points[0].x as f32, points[0].y as f32);
        for q in &points[1..] {
            pb.line_to(q.x as f32, q.y as f32);
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
    });

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
