//! The three vlab model folders of `$SUBGRAM_SHARED/corpus/vlab-models`:
//! each is found and read as lpfg reads it, and the colours of subgram's
//! pictures are those of lpfg's own pictures (`lpfg-picture.png`).

use std::collections::HashMap;
use std::path::PathBuf;

use subgram::model::{self, Model};
use subgram::{LoadOptions, System};

use crate::shared;

fn folder(name: &str) -> PathBuf {
    let p = shared().join("corpus/vlab-models").join(name);
    assert!(
        p.is_dir(),
        "{} is missing from the shared corpus",
        p.display()
    );
    p
}

/// The pixels of a PNG file, as RGB, with their counts.
fn colours(png_bytes: &[u8]) -> (tiny_skia::Pixmap, Vec<([u8; 3], usize)>) {
    let pm = tiny_skia::Pixmap::decode_png(png_bytes).expect("a PNG");
    let mut count: HashMap<[u8; 3], usize> = HashMap::new();
    for p in pm.pixels() {
        let c = p.demultiply();
        *count.entry([c.red(), c.green(), c.blue()]).or_default() += 1;
    }
    let mut v: Vec<_> = count.into_iter().collect();
    v.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
    (pm, v)
}

fn lpfg_picture(name: &str) -> Vec<([u8; 3], usize)> {
    let bytes = std::fs::read(folder(name).join("lpfg-picture.png")).unwrap();
    colours(&bytes).1
}

fn model_of(name: &str) -> Model {
    let files = model::find(&folder(name)).unwrap().expect("a model folder");
    Model::read(&files.files).unwrap_or_else(|e| panic!("{name}: {e}"))
}

#[test]
fn monopodial_renders_with_lpfgs_background_and_leaf_colour() {
    let System::Curve(c) = subgram::load(folder("monopodial"), &LoadOptions::default()).unwrap()
    else {
        panic!("a curve")
    };
    // The specifications' lpfg line: material.mat, view.v, anim.a,
    // functions.fset beside lsystem.l; two functions, numbered 1 and 2.
    let m = &*c.model();
    assert_eq!(m.functions.len(), 2);
    assert_eq!(m.defines()[..2], ["internode_length=1", "leaf_length=2"]);
    let tmp = crate::support::scratch("mono");
    let a = subgram::command::RenderArgs::new(
        folder("monopodial").display().to_string(),
        tmp.path().join("mono.png").display().to_string(),
    );
    subgram::command::render(&a, |_| {}).unwrap();
    let ours = std::fs::read(&a.output).unwrap();
    let (_, ours) = colours(&ours);
    let theirs = lpfg_picture("monopodial");
    // The background is lpfg's, to the byte: material 0's emission.
    assert_eq!(ours[0].0, theirs[0].0);
    // The leaves (material 2, lit by the view file's three lights) come
    // out within 2 of a shade lpfg draws for them; lpfg shades its
    // cylinders, subgram draws the side that faces the viewer.
    let leaf = ours[1].0;
    assert!(
        theirs
            .iter()
            .any(|(c, n)| *n > 100 && (0..3).all(|k| c[k].abs_diff(leaf[k]) <= 2)),
        "subgram's leaf colour {leaf:?} is not among lpfg's: {:?}",
        &theirs[..12]
    );
}

#[test]
fn leaf_rnd_has_lpfgs_colours_and_its_leaf_surface() {
    let m = model_of("leaf-rnd");
    // lpfg's picture: the background, then the leaves (material 2) are its
    // two most common colours; the stem is material 1.
    let theirs = lpfg_picture("leaf-rnd");
    let p = m.palette().expect("material.mat");
    let c = m.colours.as_ref().unwrap();
    assert_eq!(c.background(), theirs[0].0);
    assert_eq!(p[2], theirs[1].0);
    assert!(
        theirs.iter().any(|(c, _)| *c == p[1]),
        "stem colour {:?}",
        p[1]
    );
    // view.v names leaf.s, surface 0: one patch.
    assert_eq!(m.surfaces.len(), 1);
    assert_eq!(m.surfaces[0].name, "leaf");
    assert_eq!(m.surfaces[0].patches.len(), 1);
    assert!(m.defines().contains(&"leaf=0".to_string()));
}

#[test]
fn lychnis_names_the_parameter_file_its_command_line_lacks() {
    // Lychnis's specifications run `lpfg ... contours.cset aging.vset`, and
    // the folder has no aging.vset: that is the first thing said.
    let e = subgram::load(folder("Lychnis"), &LoadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("specifications:24:"), "{e}");
    assert!(e.contains("names `aging.vset`, but"), "{e}");
}

#[test]
fn lychnis_files_read_without_the_missing_one() {
    // Everything else of the folder reads: the timelines (four, numbered
    // after the two functions of functions.fset), the contour, the two
    // surfaces of plant.v.
    let dir = folder("Lychnis");
    let files: Vec<PathBuf> = [
        "material.mat",
        "plant.v",
        "plant.a",
        "functions.tset",
        "functions.fset",
        "contours.cset",
    ]
    .iter()
    .map(|f| dir.join(f))
    .collect();
    let m = Model::read(&files).unwrap();
    let d = m.defines();
    for want in [
        "INTERNODE_LENGTH=3",
        "AGING=6",
        "calyx=1",
        "petal=0",
        "leaf=1",
    ] {
        assert!(d.contains(&want.to_string()), "{want} not in {d:?}");
    }
}
