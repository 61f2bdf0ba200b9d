//! A viewing aid for the turtle's 3D geometry: a model folder (or an
//! `.l`/`.lsys` file) run and its `Scene3` written as a plain OBJ, one
//! group per look, with vertex normals; no materials (the exporters of
//! issue 17 write those). Prints the counts and bounds.
//!
//! `cargo run --release --example solid_obj -- MODEL OUT.obj [cylinder]`
//! (`cylinder` forces `line style: cylinder`).

use std::io::Write;

use subgram::draw::solid::SolidOptions;
use subgram::model::view::LineStyle;
use subgram::{LoadOptions, System};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let (input, out) = match (args.get(1), args.get(2)) {
        (Some(i), Some(o)) => (i, o),
        _ => return Err("usage: solid_obj MODEL OUT.obj [cylinder]".into()),
    };
    let System::Curve(curve) = subgram::load(input, &LoadOptions::default())? else {
        return Err("not an L-system".into());
    };
    let mut run = curve.run(Default::default())?;
    let sopts = SolidOptions {
        line_style: (args.get(3).map(String::as_str) == Some("cylinder"))
            .then_some(LineStyle::Cylinder),
        ..Default::default()
    };
    let t = std::time::Instant::now();
    let scene = run.solid(&sopts)?;
    let took = t.elapsed();
    let mut f = std::io::BufWriter::new(std::fs::File::create(out)?);
    let mut base = 1;
    for (look, m) in scene.looks.iter().zip(&scene.meshes) {
        writeln!(f, "g {}", look.name)?;
        writeln!(f, "# diffuse {:?}", look.diffuse)?;
        for p in &m.positions {
            writeln!(f, "v {} {} {}", p.x, p.y, p.z)?;
        }
        for n in &m.normals {
            writeln!(f, "vn {} {} {}", n.x, n.y, n.z)?;
        }
        for t in &m.triangles {
            let [a, b, c] = t.map(|i| i as usize + base);
            writeln!(f, "f {a}//{a} {b}//{b} {c}//{c}")?;
        }
        base += m.positions.len();
    }
    println!(
        "{} looks, {} vertices, {} triangles, bounds {:?}, built in {:.1} ms",
        scene.looks.len(),
        scene.vertex_count(),
        scene.triangle_count(),
        scene.bounds(),
        took.as_secs_f64() * 1e3
    );
    Ok(())
}
