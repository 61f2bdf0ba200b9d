//! The z-buffer renderer (`render::raster`) on a synthetic plant, against
//! tiny-skia filling the same triangles projected to 2D (issue 17, item 4).
//! `cargo build --release --example bench_raster`, then
//! `target/release/examples/bench_raster [SEGMENTS] [--runs N] [--radius R] [--size PIXELS] [--only zbuffer|skia|export] [--skia-max K] [--png FILE] [--export DIR]`
//!
//! The plant: SEGMENTS turtle segments (1,000,000 by default) as 8-sided
//! tubes with smooth normals (8 vertices and 16 triangles a segment,
//! segments 0.01 long, the trunk's radius 0.02 or `--radius R`), in
//! branches of 40 segments that wander and start from random points of
//! earlier branches, generated here from a fixed seed. Timed, best of N
//! (3 by default): the z-buffer picture at 1000×1000 (or `--size`; 2×2 samples a pixel,
//! one light) as pixels and as PNG bytes; tiny-skia filling each
//! triangle, projected by the same camera, as an antialiased path of its
//! look's colour, the way a painter's renderer draws them (all the
//! triangles, or `--skia-max K` of them and the time scaled). Peak memory:
//! run with `--only zbuffer` or `--only skia` under `/usr/bin/time -v`.
//! `--export DIR` writes the plant as `plant.obj` (with `plant.mtl`),
//! `plant.ply` and `plant.glb`, and its counts and bounds as `plant.json`,
//! for `benches/export_xcheck.py`.

mod common;

use std::time::Duration;

use common::best_of;
use glam::Vec3;
use subgram::render::raster::{self, Camera, RasterOptions, ViewSpec};
use subgram::scene3::{Look, Scene3, TriMesh};

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// A linear congruential generator, uniform in -1..1.
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 40) as f32 / (1u64 << 24) as f32) * 2.0 - 1.0
    }
}

/// The plant: branches of tubes, one mesh for stems and one for young
/// shoots (two looks).
fn plant(segments: usize, sides: usize, radius: f32) -> Scene3 {
    let mut rng = Lcg(2024);
    let mut stem = Look::colour("stem", 1, [110, 80, 50]);
    stem.specular = [0.2; 3];
    stem.shininess = 16.0;
    let shoot = Look::colour("shoot", 2, [70, 150, 60]);
    let mut meshes = vec![TriMesh::default(), TriMesh::default()];
    let per_branch = 40;
    let mut starts: Vec<(Vec3, Vec3, f32)> = vec![(Vec3::ZERO, Vec3::Y, radius)];
    let mut done = 0;
    let mut branch = 0usize;
    while done < segments {
        let pick = (rng.next().abs() * starts.len() as f32) as usize % starts.len();
        let (mut p, mut h, r0) = starts[pick];
        if branch > 0 {
            h = (h + Vec3::new(rng.next(), rng.next() * 0.5, rng.next())).normalize();
        }
        let m = &mut meshes[branch % 2];
        let n = per_branch.min(segments - done);
        let len = 0.01;
        let mut r = r0 * 0.9;
        // A frame across the heading, carried along the branch.
        let mut side = h.any_orthonormal_vector();
        let ring = |m: &mut TriMesh, p: Vec3, h: Vec3, side: Vec3, r: f32| {
            let other = h.cross(side);
            for k in 0..sides {
                let a = k as f32 / sides as f32 * std::f32::consts::TAU;
                let d = side * a.cos() + other * a.sin();
                m.positions.push(p + d * r);
                m.normals.push(d);
            }
        };
        ring(m, p, h, side, r);
        for _ in 0..n {
            h = (h + Vec3::new(rng.next(), rng.next(), rng.next()) * 0.15 + Vec3::Y * 0.03)
                .normalize();
            side = (side - h * side.dot(h)).normalize();
            p += h * len;
            r *= 0.995;
            let base = m.positions.len() as u32 - sides as u32;
            ring(m, p, h, side, r);
            for k in 0..sides as u32 {
                let k1 = (k + 1) % sides as u32;
                let (a, b) = (base + k, base + k1);
                let (c, d) = (a + sides as u32, b + sides as u32);
                m.triangles.push([a, b, d]);
                m.triangles.push([a, d, c]);
            }
            if starts.len() < 100_000 {
                starts.push((p, h, r));
            }
        }
        done += n;
        branch += 1;
    }
    Scene3 {
        looks: vec![stem, shoot],
        meshes,
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let runs = common::runs_arg(&args, 3);
    let segments: usize = args
        .get(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(1_000_000);
    let value = |flag: &str| {
        args.iter()
            .position(|a| a == flag)
            .and_then(|i| args.get(i + 1).cloned())
    };
    let only = value("--only");
    let size: u32 = value("--size").and_then(|v| v.parse().ok()).unwrap_or(1000);
    let skia_max: usize = value("--skia-max")
        .and_then(|v| v.parse().ok())
        .unwrap_or(usize::MAX);
    let t = std::time::Instant::now();
    let radius: f32 = value("--radius")
        .and_then(|v| v.parse().ok())
        .unwrap_or(0.02);
    let scene = plant(segments, 8, radius);
    println!(
        "plant: {segments} segments (radius {radius}), {} vertices, {} triangles, built in {:.0} ms; rayon threads {}",
        scene.vertex_count(),
        scene.triangle_count(),
        ms(t.elapsed()),
        rayon::current_num_threads()
    );
    if let Some(dir) = value("--export") {
        // The plant as OBJ+MTL, PLY and GLB, and what an independent
        // reader should find in them (benches/export_xcheck.py).
        let dir = std::path::Path::new(&dir);
        for name in ["plant.obj", "plant.ply", "plant.glb"] {
            let (d, r) = best_of(1, || subgram::export::write(&scene, &dir.join(name)));
            r.expect("exports");
            println!("export {name}: {:8.1} ms", ms(d));
        }
        let (lo, hi) = scene.bounds().expect("bounds");
        let summary = serde_json::json!({
            "vertices": scene.vertex_count(),
            "triangles": scene.triangle_count(),
            "looks": scene.looks.len(),
            "min": lo.to_array(),
            "max": hi.to_array(),
        });
        std::fs::write(dir.join("plant.json"), summary.to_string()).expect("writes");
        if only.as_deref() == Some("export") {
            return;
        }
    }
    let camera = Camera::from_view(
        &ViewSpec {
            dir: Vec3::new(-0.3, -0.2, -1.0),
            ..ViewSpec::default()
        },
        &mut scene.points(),
        size,
        size,
    )
    .expect("a camera");
    let opts = RasterOptions::new(camera);
    if only.as_deref() != Some("skia") {
        let (d, img) = best_of(runs, || raster::render(&scene, &opts).expect("renders"));
        println!("z-buffer, pixels:        {:8.1} ms", ms(d));
        let (d, png) = best_of(runs, || raster::render_png(&scene, &opts).expect("renders"));
        println!(
            "z-buffer, PNG bytes:     {:8.1} ms ({} bytes)",
            ms(d),
            png.len()
        );
        let drawn = img
            .pixels
            .chunks(4)
            .filter(|p| p[..3] != [255, 255, 255])
            .count();
        println!("  {drawn} pixels not background");
        if let Some(path) = value("--png") {
            std::fs::write(&path, &png).expect("writes the PNG");
        }
    }
    if only.as_deref() != Some("zbuffer") {
        // The same triangles projected by the same camera, each filled as
        // an antialiased tiny-skia path in its look's colour.
        let (d, filled) = best_of(runs, || {
            common::skia_fill(&scene, &camera, size, skia_max).1
        });
        let scale = scene.triangle_count() as f64 / filled.max(1) as f64;
        println!(
            "tiny-skia, {} triangles as paths: {:8.1} ms{}",
            filled,
            ms(d),
            if scale > 1.0 {
                format!(
                    " (scaled to all {}: {:.0} ms)",
                    scene.triangle_count(),
                    ms(d) * scale
                )
            } else {
                String::new()
            }
        );
    }
}
