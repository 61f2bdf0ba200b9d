//! subgram as a library: load a `.lsys` file, run it, and print what it
//! made: a curve's word and points, or a surface grammar's mesh.
//!
//! `cargo run --example usage [FILE.lsys [STEPS]]`; by default Chaikin's
//! curve, `lsystems/curves/chaikin-13.lsys`, two steps.

use std::process::ExitCode;

use subgram::{LoadOptions, Run, RunOptions};

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // A problem in the file reads `file:line:col: error: ...`, the
            // line and a caret.
            eprintln!("{e}");
            ExitCode::FAILURE
        }
    }
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let file = args.next().unwrap_or_else(|| {
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/lsystems/curves/chaikin-13.lsys"
        )
        .to_string()
    });
    let steps = match args.next() {
        Some(n) => n.parse()?,
        None => 2,
    };

    let system = subgram::load(&file, &LoadOptions::default())?;
    match system.run(&RunOptions::default().with_steps(steps))? {
        Run::Curve(mut curve) => {
            println!(
                "after {} steps, {} modules:",
                curve.step(),
                curve.word().len()
            );
            println!("{}", curve.text());
            // The points the turtle draws, joined into polylines.
            for (i, line) in curve.polylines()?.iter().enumerate() {
                println!("polyline {i}, {} points:", line.len());
                for p in line {
                    println!("  {:.4} {:.4} {:.4}", p.x, p.y, p.z);
                }
            }
        }
        Run::Shapes(shapes) => {
            // A shape grammar: its tree of shapes.
            let c = shapes.counts();
            println!(
                "{} shapes, {} terminal, {} faces",
                c.shapes, c.terminal_shapes, c.faces
            );
        }
        Run::Vv(vv) => {
            // A vertex-vertex program: its mesh's polygons.
            println!("after {} steps:\n{}", vv.steps, vv.info);
        }
        Run::Surface(surface) => {
            println!("after {} steps:\n{}", surface.steps, surface.mesh.info());
            let soup = surface.mesh.to_quad_soup();
            println!(
                "{} points, {} faces",
                soup.positions.len(),
                soup.faces.len()
            );
        }
    }
    Ok(())
}
