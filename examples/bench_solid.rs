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

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let runs = common::runs_arg(&args, 3);
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
}
