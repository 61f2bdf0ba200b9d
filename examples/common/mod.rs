//! Timing shared by the benchmark examples.

// Each benchmark uses part of this.
#![allow(dead_code)]

use std::time::{Duration, Instant};

/// The fastest of `runs` runs of `f`, and the last run's result.
pub fn best_of<T>(runs: usize, mut f: impl FnMut() -> T) -> (Duration, T) {
    let mut best = Duration::MAX;
    let mut last = None;
    for _ in 0..runs {
        let t = Instant::now();
        let r = f();
        best = best.min(t.elapsed());
        last = Some(r);
    }
    (best, last.expect("at least one run"))
}

/// The number after `--runs` in `args`, or `default`.
pub fn runs_arg(args: &[String], default: usize) -> usize {
    args.iter()
        .position(|a| a == "--runs")
        .and_then(|i| args.get(i + 1)?.parse().ok())
        .unwrap_or(default)
}

/// tiny-skia filling the triangles of `scene` projected by `camera`, each
/// an antialiased path in its look's diffuse colour on white (what a
/// painter's 2D renderer does with the same triangles), then stroking its
/// lines half a pixel wide, one path per mesh: at most `max` triangles and
/// lines in all. Returns the pixmap and how many were drawn.
pub fn skia_fill(
    scene: &subgram::scene3::Scene3,
    camera: &subgram::render::raster::Camera,
    size: u32,
    max: usize,
) -> (tiny_skia::Pixmap, usize) {
    let paints: Vec<tiny_skia::Paint> = scene
        .looks
        .iter()
        .map(|l| {
            let mut p = tiny_skia::Paint::default();
            let [r, g, b] = l.diffuse.map(|v| (v * 255.0) as u8);
            p.set_color_rgba8(r, g, b, 255);
            p.anti_alias = true;
            p
        })
        .collect();
    let mut pm = tiny_skia::Pixmap::new(size, size).expect("a pixmap");
    pm.fill(tiny_skia::Color::WHITE);
    let mut filled = 0;
    'all: for (k, m) in scene.meshes.iter().enumerate() {
        for t in &m.triangles {
            if filled >= max {
                break 'all;
            }
            filled += 1;
            let Some(p) = t
                .iter()
                .map(|&i| camera.pixel(m.positions[i as usize]))
                .collect::<Option<Vec<_>>>()
            else {
                continue;
            };
            let mut pb = tiny_skia::PathBuilder::new();
            pb.move_to(p[0].x, p[0].y);
            pb.line_to(p[1].x, p[1].y);
            pb.line_to(p[2].x, p[2].y);
            pb.close();
            if let Some(path) = pb.finish() {
                pm.fill_path(
                    &path,
                    &paints[k],
                    tiny_skia::FillRule::Winding,
                    tiny_skia::Transform::identity(),
                    None,
                );
            }
        }
    }
    // The lines (thin tubes) of each mesh as one stroked path, half a
    // pixel wide as the z-buffer draws them.
    let stroke = tiny_skia::Stroke {
        width: 0.5,
        ..Default::default()
    };
    for (k, m) in scene.meshes.iter().enumerate() {
        let mut pb = tiny_skia::PathBuilder::new();
        for l in &m.lines {
            if filled >= max {
                break;
            }
            filled += 1;
            if let (Some(a), Some(b)) = (camera.pixel(l.a), camera.pixel(l.b)) {
                pb.move_to(a.x, a.y);
                pb.line_to(b.x, b.y);
            }
        }
        if let Some(path) = pb.finish() {
            pm.stroke_path(
                &path,
                &paints[k],
                &stroke,
                tiny_skia::Transform::identity(),
                None,
            );
        }
    }
    (pm, filled)
}
