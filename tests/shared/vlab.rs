//! The five vlab model folders of `$SUBGRAM_SHARED/corpus/vlab-models`:
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

/// The open models (`open-01-ulam-collide`, `open-06-canalization`): their
/// `.e` files name vlab's honda81, which subgram runs built in; lpfg's word
/// (`lpfg-string.txt.gz`, made by lpfg with vlab's honda81) is theirs,
/// module by module, every parameter within 1e-5 relative.
fn open_model_gives_lpfgs_word(name: &str) {
    use std::io::Read;
    let System::Curve(c) = subgram::load(folder(name), &LoadOptions::default()).unwrap() else {
        panic!("a curve")
    };
    let d = c.derive(Default::default()).unwrap();
    let ours = c.word_text(&d.word).replace(", ", ",");
    let gz = std::fs::read(folder(name).join("lpfg-string.txt.gz")).unwrap();
    let mut theirs = String::new();
    flate2::read::GzDecoder::new(&gz[..])
        .read_to_string(&mut theirs)
        .unwrap();
    let split = |t: &str| -> (String, Vec<f64>) {
        let (n, rest) = t.split_once('(').unwrap_or((t, ""));
        let v = rest
            .trim_end_matches(')')
            .split(',')
            .filter(|s| !s.is_empty())
            .map(|s| s.parse().unwrap())
            .collect();
        (n.to_string(), v)
    };
    let ours: Vec<_> = ours.split_whitespace().map(split).collect();
    let theirs: Vec<_> = theirs.split_whitespace().map(split).collect();
    assert_eq!(ours.len(), theirs.len(), "{name}");
    for (i, (a, b)) in ours.iter().zip(&theirs).enumerate() {
        assert_eq!(a.0, b.0, "{name}: module {i}");
        assert_eq!(a.1.len(), b.1.len(), "{name}: module {i}");
        for (x, y) in a.1.iter().zip(&b.1) {
            assert!(
                (x - y).abs() <= 1e-5 * x.abs().max(y.abs()).max(1.0),
                "{name}: module {i} ({}): {x} and lpfg's {y}",
                a.0
            );
        }
    }
}

#[test]
fn ulam_collide_gives_lpfgs_word() {
    open_model_gives_lpfgs_word("open-01-ulam-collide");
}

#[test]
fn canalization_gives_lpfgs_word() {
    open_model_gives_lpfgs_word("open-06-canalization");
}

/// The colours of subgram's picture of an open model and of lpfg's: the
/// background is lpfg's, and every colour that covers more than 1% of
/// subgram's picture is within 3 of one that covers more than 0.1% of
/// lpfg's (the model's colour map entries, as lpfg draws them).
fn open_model_picture_has_lpfgs_colours(name: &str) {
    let tmp = crate::support::scratch("open-picture");
    let a = subgram::command::RenderArgs::new(
        folder(name).display().to_string(),
        tmp.path().join("p.png").display().to_string(),
    );
    subgram::command::render(&a, |_| {}).unwrap();
    let (pm, ours) = colours(&std::fs::read(&a.output).unwrap());
    let theirs = lpfg_picture(name);
    assert_eq!(ours[0].0, theirs[0].0, "{name}: background");
    let total: usize = theirs.iter().map(|c| c.1).sum();
    let n = (pm.width() * pm.height()) as usize;
    for (c, count) in ours.iter().filter(|(_, k)| *k * 100 > n) {
        assert!(
            theirs
                .iter()
                .any(|(t, k)| *k * 1000 > total && (0..3).all(|i| t[i].abs_diff(c[i]) <= 3)),
            "{name}: subgram's colour {c:?} ({count} pixels) is not lpfg's"
        );
    }
}

#[test]
fn ulam_collide_picture_has_lpfgs_colours() {
    open_model_picture_has_lpfgs_colours("open-01-ulam-collide");
}

#[test]
fn canalization_picture_has_lpfgs_colours() {
    open_model_picture_has_lpfgs_colours("open-06-canalization");
}
