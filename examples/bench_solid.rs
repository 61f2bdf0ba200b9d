//! Building the 3D geometry of a plant of about a million turtle segments
//! (issue 17, item 4): `cargo run --release --example bench_solid`.
//!
//! The plant: `A -> F F F F [+A] [-A]` for 18 steps, 1,048,572 segments
//! in tubes of four segments (five rings, the three inner ones shared at
//! the joints) and width 0.1, in `line style: cylinder`. Timed, best of
//! N (`--runs N`, 3 by default): the 2D events of the same word (the
//! turtle alone, for reference) and `draw::solid::solid` with 16 sides
//! (lpfg's default) and 8 sides; the counts and the memory the scene
//! holds are printed with them.
//!
//! Then the whole path of `subgram render MODEL -o plant.png --size
//! 1000x1000` on a model folder (`--model DIR`; by default a binary plant
//! of 1,048,575 segments in `line style: cylinder`, written to the system's
//! temporary folder), phase by phase in-process, beside tiny-skia drawing
//! the same geometry in 2D, triangles filled and thin tubes' lines stroked
//! as antialiased paths (`--skia-max K` of them, the time scaled to all), and the binary itself as a user runs it
//! (`target/release/subgram`, when it has been built). `--whole` runs only
//! this part.

mod common;

use std::sync::Arc;
use std::time::Duration;

use common::best_of;
use subgram::draw::solid::{solid, SolidOptions};
use subgram::draw::DrawOptions;
use subgram::model::view::LineStyle;
use subgram::model::Model;
use subgram::{Derivation, DeriveOptions};

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// A binary plant of 1,048,575 tube segments (20 steps), as a model
/// folder: its L-system and a view file asking for shaded cylinders.
const PLANT: &str = "// A binary plant of 1,048,575 segments.
#include <lpfgall.h>
module A(float, float);
derivation length: 20;
Axiom: SetColor(2) A(1, 0.05);
production:
A(l, w) :
{
  produce SetWidth(w) F(l) RollR(137.5) SB() Left(32) A(l*0.78, w*0.7) EB()
          Right(18) A(l*0.86, w*0.8);
}
";
const PLANT_VIEW: &str = "line style: cylinder
z buffer: on
render mode: shaded
light: V: 5 3 1 D: 0.3 0.5 0.3
light: V: 0 -1 0 D: 0.8 0.7 0.3
";

/// The whole path of `render MODEL -o plant.png` in-process, phase by
/// phase, then tiny-skia on the same geometry and the binary.
fn whole_path(args: &[String], runs: usize) {
    use std::time::Instant;
    use subgram::render::raster;
    let value = |flag: &str| {
        args.iter()
            .position(|a| a == flag)
            .and_then(|i| args.get(i + 1).cloned())
    };
    let size: u32 = 1000;
    let dir = match value("--model") {
        Some(d) => std::path::PathBuf::from(d),
        None => {
            let d = std::env::temp_dir().join("subgram-bench-plant");
            std::fs::create_dir_all(&d).expect("makes the model folder");
            std::fs::write(d.join("lsystem.l"), PLANT).expect("writes the L-system");
            std::fs::write(d.join("view.v"), PLANT_VIEW).expect("writes the view file");
            d
        }
    };
    let out = std::env::temp_dir().join("subgram-bench-plant.png");
    println!(
        "\nwhole path of `render {} -o plant.png --size {size}x{size}`, best of {runs}:",
        dir.display()
    );
    let mut best = [Duration::MAX; 8];
    let names = [
        "load",
        "derive",
        "(no second walk for the picture's scale)",
        "turtle -> Scene3, scale found on the way",
        "camera fit",
        "z-buffer to pixels",
        "PNG encoding",
        "write",
    ];
    let mut kept = None;
    for _ in 0..runs {
        let mut t = Instant::now();
        let mut lap = |k: usize, best: &mut [Duration; 8]| {
            best[k] = best[k].min(t.elapsed());
            t = Instant::now();
        };
        let sys = subgram::load(&dir, &Default::default()).expect("loads the model");
        lap(0, &mut best);
        let subgram::System::Curve(c) = &sys else {
            panic!("the model is not an L-system")
        };
        let mut run = c.run(DeriveOptions::default()).expect("derives");
        lap(1, &mut best);
        lap(2, &mut best);
        // The picture's scale found by the walk that makes the geometry,
        // as `render` does.
        let scene = run
            .solid(&SolidOptions {
                fit_pixels: Some(0.9 * size as f64),
                ..Default::default()
            })
            .expect("makes the geometry");
        drop(run);
        lap(3, &mut best);
        let model = &*c.model();
        let opts = model
            .camera
            .raster_options(&model.lights, scene.bounds(), size, size)
            .expect("a camera");
        lap(4, &mut best);
        let img = raster::render(&scene, &opts).expect("renders");
        lap(5, &mut best);
        let png = img.encode_png().expect("encodes");
        lap(6, &mut best);
        std::fs::write(&out, &png).expect("writes the PNG");
        lap(7, &mut best);
        kept = Some((scene, opts));
    }
    let total: Duration = best.iter().sum();
    for (n, d) in names.iter().zip(best) {
        println!("  {n:30} {:8.1} ms", ms(d));
    }
    println!("  {:30} {:8.1} ms (sum of the bests)", "all", ms(total));
    let (scene, opts) = kept.expect("at least one run");
    println!(
        "  the scene: {} vertices, {} triangles, {} lines (tubes under a pixel across)",
        scene.vertex_count(),
        scene.triangle_count(),
        scene.line_count()
    );
    let skia_max: usize = value("--skia-max")
        .and_then(|v| v.parse().ok())
        .unwrap_or(500_000);
    let (d, filled) = best_of(runs, || {
        common::skia_fill(&scene, &opts.camera, size, skia_max).1
    });
    let scale = (scene.triangle_count() + scene.line_count()) as f64 / filled.max(1) as f64;
    println!(
        "  tiny-skia drawing {filled} of them as 2D paths: {:.1} ms, scaled to all: {:.0} ms ({:.1}x the z-buffer)",
        ms(d),
        ms(d) * scale,
        ms(d) * scale / ms(best[5])
    );
    let bin = std::env::current_exe()
        .ok()
        .and_then(|e| Some(e.parent()?.parent()?.join("subgram")))
        .filter(|b| b.exists());
    match bin {
        Some(bin) => {
            let (d, status) = best_of(runs, || {
                std::process::Command::new(&bin)
                    .arg("render")
                    .arg(&dir)
                    .arg("-o")
                    .arg(&out)
                    .args(["--size", "1000x1000"])
                    .status()
                    .expect("runs the binary")
            });
            assert!(status.success(), "the binary failed");
            println!(
                "  `{} render` as a user runs it: {:.1} ms",
                bin.display(),
                ms(d)
            );
        }
        None => println!("  (build the binary, `cargo build --release`, to time it too)"),
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let runs = common::runs_arg(&args, 3);
    if args.iter().any(|a| a == "--whole") {
        whole_path(&args, runs);
        return;
    }
    let src = "module A;\nderivation length: 18;\nAxiom: SetWidth(0.1) A;\n\
               A -> F(1) F(1) F(1) F(1) SB() Left(30) A EB() SB() Right(30) RollR(90) A EB()\n";
    let loaded = subgram::load_str("plant.lsys", src, &[]).expect("loads");
    let p = &loaded.program;
    let mut d = Derivation::new(p, DeriveOptions::default()).unwrap();
    while d.has_next() {
        d.next_step().unwrap();
    }
    let word = d.interpret().unwrap();
    let (t_events, events) = best_of(runs, || {
        subgram::draw::draw(&word, &p.alphabet, &p.structs, &Default::default()).unwrap()
    });
    let segments: usize = events.iter().map(|e| e.segments().count()).sum();
    drop(events);
    println!(
        "plant of {} modules, {segments} segments, best of {runs}",
        word.len()
    );
    println!("  turtle -> 2D events            {:8.1} ms", ms(t_events));
    for sides in [16, 8] {
        let opts = DrawOptions {
            model: Arc::new(Model {
                line_style: LineStyle::Cylinder,
                contour_sides: sides,
                ..Model::default()
            }),
            ..Default::default()
        };
        let (t, scene) = best_of(runs, || {
            solid(
                &word,
                &p.alphabet,
                &p.structs,
                &opts,
                &SolidOptions::default(),
            )
            .unwrap()
        });
        let bytes: usize = scene
            .meshes
            .iter()
            .map(|m| {
                m.positions.capacity() * 12
                    + m.normals.capacity() * 12
                    + m.triangles.capacity() * 12
            })
            .sum();
        println!(
            "  turtle -> Scene3, {sides:2} sides    {:8.1} ms  ({} vertices, {} triangles, {:.0} MiB, {:.1} ns per segment)",
            ms(t),
            scene.vertex_count(),
            scene.triangle_count(),
            bytes as f64 / (1 << 20) as f64,
            t.as_secs_f64() * 1e9 / segments as f64
        );
    }
    whole_path(&args, runs);
}
