use subgram::mesh::{shapes, Mesh};
fn main() {
    let base = Mesh::from_soup(&shapes::quad_torus(316, 316)).unwrap();
    let g = subgram::surface::load_file(
        std::path::Path::new("lsystems/surfaces/catmull-clark.lsys"),
        &[],
    )
    .unwrap();
    for _ in 0..15 {
        let mut m = base.clone();
        let t = std::time::Instant::now();
        g.run(&mut m, 1, |_| {}).unwrap();
        eprintln!("{:.1}", t.elapsed().as_secs_f64() * 1e3);
    }
}
