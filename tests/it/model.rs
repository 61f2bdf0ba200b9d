//! Model folders: the L-system found in a folder, the files read beside
//! it, the names they define, and the accessors' values. The expected
//! values come from lpfg (its output on the same folder, recorded below)
//! and from hand computations written out here, independent of the
//! implementation.

use std::path::{Path, PathBuf};

use subgram::model::{self, Colours, Model};
use subgram::{LoadOptions, System, Value};

use crate::support::{root, scratch};

fn models(name: &str) -> PathBuf {
    root().join("tests/data/models").join(name)
}

fn curve(path: &Path) -> subgram::Curve {
    match subgram::load(path, &LoadOptions::default()) {
        Ok(System::Curve(c)) => c,
        Ok(_) => panic!("{} is not a curve", path.display()),
        Err(e) => panic!("{} does not load:\n{e}", path.display()),
    }
}

/// The first parameter of every module, as numbers, in word order.
fn values(c: &subgram::Curve) -> Vec<f64> {
    let d = subgram::derive(&c.program, Default::default())
        .unwrap_or_else(|e| panic!("{}", c.error(e)));
    d.word
        .modules(&c.program.alphabet, &c.program.structs)
        .map(|(_, ps)| match ps.first() {
            Some(Value::Float(x)) => *x,
            Some(Value::Int(i)) => *i as f64,
            other => panic!("expected a number, found {other:?}"),
        })
        .collect()
}

/// lpfg's final string for `tests/data/models/accessors`, made with
/// `/work/shared/tools/lpfg/run_lpfg.sh tests/data/models/accessors OUT`
/// (lpfg at vlab commit 9bf820d), printed with 8 significant digits.
const LPFG_ACCESSORS: [f64; 32] = [
    0.00001831837,
    0.2765322,
    0.49998987,
    0.866097,
    0.99998164,
    0.00001831837,
    0.99998164,
    0.6053002,
    0.56556773,
    0.1132247,
    0.60999066,
    0.9999267,
    0.5,
    0.9325383,
    1.227512,
    2.5,
    7.0,
    -0.6666667,
    0.0,
    1.0463466e-6,
    -0.6666667,
    0.6666667,
    3.692761e-6,
    -0.5263883,
    -0.38077423,
    1.3093805,
    0.23166777,
    3.8328328,
    0.16716722,
    0.5893559,
    2.0782385,
    0.6053002,
];

#[test]
fn accessors_give_lpfgs_values() {
    let c = curve(&models("accessors"));
    let got = values(&c);
    assert_eq!(got.len(), LPFG_ACCESSORS.len());
    for (i, (g, w)) in got.iter().zip(LPFG_ACCESSORS).enumerate() {
        // Functions are computed as lpfg does, in single precision: they
        // agree to lpfg's printed digits. Contours sum the spline's basis
        // in another order than lpfg's matrix product: within 1e-5.
        assert!(
            (g - w).abs() <= 1e-5 * w.abs().max(1.0),
            "value {i}: subgram {g}, lpfg {w}"
        );
    }
}

/// The cubic B-spline basis N(k, t) over `knots`, by the Cox–de Boor
/// recursion, written out for the test.
fn basis(knots: &[f64], k: usize, t: usize, u: f64) -> f64 {
    if t == 1 {
        return if knots[k] <= u && u < knots[k + 1] {
            1.0
        } else {
            0.0
        };
    }
    let mut s = 0.0;
    let d1 = knots[k + t - 1] - knots[k];
    if d1 > 0.0 {
        s += (u - knots[k]) / d1 * basis(knots, k, t - 1, u);
    }
    let d2 = knots[k + t] - knots[k + 1];
    if d2 > 0.0 {
        s += (knots[k + t] - u) / d2 * basis(knots, k + 1, t - 1, u);
    }
    s
}

#[test]
fn functions_follow_the_clamped_b_spline_by_hand() {
    let c = curve(&models("accessors"));
    let got = values(&c);
    // `rise` has 4 points: one span, so its curve is the Bézier cubic of
    // (0,0) (0.3,0.1) (0.6,0.9) (1,1). At the parameter 1/2 the Bernstein
    // weights are 1/8 3/8 3/8 1/8: x = (0 + 0.9 + 1.8 + 1)/8 = 0.4625 and
    // y = (0 + 0.3 + 2.7 + 1)/8 = 0.5. func(rise, 0.4625) is the third value.
    assert!((got[2] - 0.5).abs() < 5e-4, "{}", got[2]);
    // The ends: y of the first and last points (x clamped outside [0,1]).
    assert!(got[0].abs() < 1e-3 && got[5].abs() < 1e-3);
    assert!((got[4] - 1.0).abs() < 1e-3 && (got[6] - 1.0).abs() < 1e-3);
    // `bump` has 5 points: knots 0 0 0 0 1 2 2 2 2. At u = 1 (the middle
    // knot) the basis is 0, 1/4, 1/2, 1/4, 0: x = 0.25/4 + 0.5/2 + 0.75/4
    // = 0.5 and y = 1/4 + 0 + 1/4 = 0.5; the test's basis agrees.
    let knots = [0.0, 0.0, 0.0, 0.0, 1.0, 2.0, 2.0, 2.0, 2.0];
    let w: Vec<f64> = (0..5).map(|k| basis(&knots, k, 4, 1.0)).collect();
    assert_eq!(w, vec![0.0, 0.25, 0.5, 0.25, 0.0]);
    let m = load_model("accessors");
    let bump = &m.functions[1];
    assert_eq!(bump.name, "bump");
    // Its 20 samples are 1/19 apart and x = 0.5 falls halfway between two:
    // lpfg interpolates linearly there, a chord of the curve, off by up to
    // |y''| h² / 8 (about 7e-3 for this bend).
    let y = bump.value(0.5).unwrap() as f64;
    assert!((y - 0.5).abs() < 1e-2, "{y}");
    // tfunc maps the timeline [2, 20] onto [0,1]: tfunc(grow, 12.5) is
    // func at (12.5 - 2) / 18; beyond the end it is the last value.
    let grow = &m.functions[2];
    assert_eq!((grow.low, grow.up), (2.0, 20.0));
    assert_eq!(grow.timeline_value(12.5), grow.value(10.5 / 18.0));
    assert!((got[11] - 1.0).abs() < 1e-3);
    // The parameters of the .vset.
    assert_eq!((got[15], got[16]), (2.5, 7.0));
}

#[test]
fn contours_by_hand() {
    let c = curve(&models("accessors"));
    let got = values(&c);
    // `ring` is closed with control points (1,0) (0,1) (-1,0) (0,-1); lpfg
    // starts a closed contour with copies of its last three points, so its
    // first span is (0,1) (-1,0) (0,-1) (1,0), which starts at
    // ((0,1) + 4(-1,0) + (0,-1)) / 6 = (-2/3, 0). The contour is symmetric
    // under quarter turns, so a quarter of its length on it is the next
    // span's start, (0, -2/3), and half of it is (2/3, 0).
    let near = |a: f64, b: f64| (a - b).abs() < 1e-4;
    assert!(near(got[17], -2.0 / 3.0) && near(got[18], 0.0));
    assert!(near(got[19], 0.0) && near(got[20], -2.0 / 3.0));
    assert!(near(got[21], 2.0 / 3.0) && near(got[22], 0.0));
    // An open contour ends 1/1000 of a span short of its last span's end
    // (lpfg samples each span at 0, 1/1000, …, 999/1000); `blade`'s last
    // span is (0.5,2) (1,3) (1,4) (1,4), whose end (t = 1, weights 0 1/6
    // 4/6 1/6) is ((1,3) + 4(1,4) + (1,4)) / 6 = (1, 23/6); the tangent
    // there is (0, 1/2), so the contour ends 1/2000 short of it.
    let m = load_model("accessors");
    let blade = m.contours.iter().find(|c| c.name == "blade").unwrap();
    let end = blade.point(1.0);
    assert!(
        (end[0] - 1.0).abs() < 1e-3 && (end[1] as f64 - 23.0 / 6.0).abs() < 2e-3,
        "{end:?}"
    );
}

fn load_model(name: &str) -> Model {
    let files = model::find(&models(name)).unwrap().unwrap();
    Model::read(&files.files).unwrap()
}

#[test]
fn names_are_numbered_as_lpfg_numbers_them() {
    let m = load_model("accessors");
    // Functions from 1: the .fset's, the .tset's, the .vset's, then each
    // .func; contours from 0, lpfg's default circle first.
    let d = m.defines();
    for want in [
        "rise=1",
        "bump=2",
        "grow=3",
        "LEN=4",
        "WIDTH=5",
        "lone=6",
        "def_contour=0",
        "ring=1",
        "wave=2",
        "blade=3",
    ] {
        assert!(d.contains(&want.to_string()), "{want} not in {d:?}");
    }
}

#[test]
fn a_folder_a_program_in_it_and_main_find_the_same_model() {
    let dir = models("accessors");
    let by_dir = model::find(&dir).unwrap().unwrap();
    let by_file = model::find(&dir.join("lsystem.l")).unwrap().unwrap();
    assert_eq!(by_dir, by_file);
    assert_eq!(by_dir.lsystem, dir.join("lsystem.l"));
    // The specifications name 6 files besides the program.
    assert_eq!(by_dir.files.len(), 6);
    // A `.lsys` file is a program alone.
    assert!(model::find(&root().join("lsystems/curves/chaikin-13.lsys"))
        .unwrap()
        .is_none());
}

#[test]
fn materials_and_colour_maps_by_the_manual() {
    // A material record: index, transparency, ambient, diffuse, emission,
    // specular, shininess (VLABToolsManual §4.4).
    let mut bytes = vec![0u8; 30];
    bytes[..15].copy_from_slice(&[0, 0, 1, 2, 3, 10, 20, 30, 100, 150, 200, 0, 0, 0, 0]);
    bytes[15..].copy_from_slice(&[5, 0, 50, 0, 0, 100, 100, 0, 0, 0, 0, 0, 0, 0, 0]);
    let m = model::colours::read_mat("m.mat", &bytes).unwrap();
    // The background is material 0's emission.
    assert_eq!(m.background(), [100, 150, 200]);
    // Lit by the default light, from the viewer, white: emission +
    // ambient × (0.2 global + 1) + diffuse × 1. Material 5: red
    // 50 × 1.2 + 100 = 160, green 100, blue 0.
    assert_eq!(m.colour(5, &[]), [160, 100, 0]);
    // An index the file does not set keeps the default material:
    // ambient 0.2, diffuse 0.8: 0.2 × 1.2 + 0.8 = 1.04, white.
    assert_eq!(m.colour(7, &[]), [255, 255, 255]);
    // A colour map: 256 RGB triplets.
    let mut map = vec![0u8; 768];
    map[3..6].copy_from_slice(&[1, 2, 3]);
    let c = model::colours::read_map("c.map", &map).unwrap();
    assert!(matches!(c, Colours::Map(_)));
    assert_eq!(
        (c.colour(1, &[]), c.colour(257, &[])),
        ([1, 2, 3], [1, 2, 3])
    );
}

#[test]
fn a_model_without_the_named_function_says_which_files_it_read() {
    let dir = models("missing-function");
    let e = subgram::load(&dir, &LoadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("lsystem.l:"), "{e}");
    assert!(e.contains("`stem` names no function"), "{e}");
    assert!(e.contains("`functions.fset`"), "{e}");
}

#[test]
fn surfaces_are_placed_on_the_turtle() {
    use glam::DVec3;
    use subgram::draw::Event;
    let c = curve(&models("surface"));
    let mut run = c.run(Default::default()).unwrap();
    let polygons: Vec<Vec<DVec3>> = run
        .events()
        .unwrap()
        .into_iter()
        .filter_map(|e| match e {
            Event::Polygon { points, .. } => Some(points),
            _ => None,
        })
        .collect();
    assert_eq!(polygons.len(), 2, "one patch, drawn twice");
    let has = |ps: &[DVec3], want: DVec3| {
        assert!(
            ps.iter().any(|p| p.distance(want) < 1e-9),
            "{want} not among {ps:?}"
        )
    };
    // `Surface(square, 2)`, `surface: square.s 3`, `SIZE: 2`: the surface
    // is scaled by 2 × 3 / 2 = 3; the turtle's frame is the surface's
    // (heading +y, up +z). Corners (-1,0,0), (1,0,0), (-1,3,0) and the
    // last row's middle, with Bernstein weights 1/8 3/8 3/8 1/8:
    // x = (-1 - 0.99 + 0.99 + 1)/8 = 0, z = (0 + 3 + 3 + 0)/8 = 0.75.
    let first = &polygons[0];
    has(first, DVec3::new(-3.0, 0.0, 0.0));
    has(first, DVec3::new(3.0, 0.0, 0.0));
    has(first, DVec3::new(-3.0, 9.0, 0.0));
    has(first, DVec3::new(0.0, 9.0, 2.25));
    // After `f(10) Left(90)` the turtle is at (0,10,0) heading -x, its
    // left -y; `Surface(square, 1)` scales by 1.5. The corner (-1,0,0) is
    // one unit to the surface's left: (0, 10 - 1.5, 0); (-1,3,0) is three
    // units ahead too: (-4.5, 8.5, 0).
    let second = &polygons[1];
    has(second, DVec3::new(0.0, 8.5, 0.0));
    has(second, DVec3::new(-4.5, 8.5, 0.0));
}

#[test]
fn a_surface_the_model_lacks_is_an_error() {
    let dir = models("surface");
    let text = "#include <lpfgall.h>\nderivation length: 0;\nAxiom: Surface(1, 1);\n";
    let folder = scratch("model");
    let tmp = folder.path();
    for f in ["square.s", "view.v"] {
        std::fs::copy(dir.join(f), tmp.join(f)).unwrap();
    }
    std::fs::write(tmp.join("lsystem.l"), text).unwrap();
    let c = curve(tmp);
    let e = c
        .run(Default::default())
        .unwrap()
        .events()
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("draws surface 1, but the model has surfaces 0 to 0"),
        "{e}"
    );
}

#[test]
fn specifications_name_the_files_and_a_missing_one_is_an_error() {
    let folder = scratch("spec");
    let tmp = folder.path();
    let src = models("accessors");
    for f in ["lsystem.l", "functions.fset"] {
        std::fs::copy(src.join(f), tmp.join(f)).unwrap();
    }
    std::fs::write(
        tmp.join("specifications"),
        "lsystem.l\n*\nmodel:\n\tgenerate:\n\t\tlpfg -rmode cont lsystem.l functions.fset params.vset\n",
    )
    .unwrap();
    let e = subgram::load(tmp, &LoadOptions::default())
        .unwrap_err()
        .to_string();
    // The caret is under the missing file's name on the lpfg line.
    assert!(e.contains("specifications:5:"), "{e}");
    assert!(e.contains("names `params.vset`, but"), "{e}");
    assert!(
        e.lines()
            .last()
            .unwrap()
            .trim_start()
            .trim_start_matches('|')
            .trim()
            == "^^^^^^^^^^^",
        "{e}"
    );
}

#[test]
fn check_warns_about_view_commands_not_an_environmental_program() {
    let folder = scratch("notes");
    let tmp = folder.path();
    std::fs::copy(
        root().join("tests/data/bad/common/model.l"),
        tmp.join("lsystem.l"),
    )
    .unwrap();
    std::fs::write(
        tmp.join("view.v"),
        "// a comment\nshadow map: on\nlight: V: 0 0 1\nzoom: 3\nline style: wireframe\nz buffer: on\n",
    )
    .unwrap();
    std::fs::write(
        tmp.join("field.e"),
        "executable: field\ncommunication type: files\n",
    )
    .unwrap();
    let out = subgram::command::check(&tmp.display().to_string(), &[], false).unwrap();
    // `light:` is acted on, and `z buffer:` (3D pictures always test
    // depth); `shadow map:` is named as not acted on, at its line; `zoom:`
    // is not a command of the manual.
    assert!(
        out.contains("view.v:2:1: warning: subgram does not act on `shadow map:`"),
        "{out}"
    );
    assert!(
        !out.contains("`light:`") && !out.contains("`z buffer:`"),
        "{out}"
    );
    assert!(
        out.contains("view.v:4:1: warning: `zoom:` is not a view-file command"),
        "{out}"
    );
    // A `.e` file sets up the model's environment, which is started for a
    // run, not for a check: nothing to warn about.
    assert!(!out.contains("field.e"), "{out}");
    // lpfg says "Invalid line style" and keeps its default (pixel lines);
    // vlab's own 03-sierpinski-collide has this line.
    assert!(
        out.contains("view.v:5:13: warning: not a line style (`pixel`, `polygon` or `cylinder`)"),
        "{out}"
    );
    assert!(
        out.lines().last().unwrap().contains(": ok (1 production, "),
        "{out}"
    );
}

/// lpfg's final string for `tests/data/models/editing` (run_lpfg.sh, vlab
/// commit 9bf820d): a contour scaled, a point moved, recalculated, reset
/// (which keeps the samples until the next recalculation, as in lpfg),
/// and `pfunc` setting the interval that a later `tfunc` uses.
const LPFG_EDITING: [f64; 9] = [
    -0.6666667,
    -1.3333334,
    -0.6666667,
    -0.53746164,
    -1.3333334,
    -0.6666667,
    0.49998987,
    0.49998987,
    0.49998987,
];

#[test]
fn contours_and_intervals_change_as_in_lpfg() {
    let c = curve(&models("editing"));
    let got = values(&c);
    assert_eq!(got.len(), LPFG_EDITING.len());
    for (i, (g, w)) in got.iter().zip(LPFG_EDITING).enumerate() {
        assert!(
            (g - w).abs() <= 1e-5 * w.abs().max(1.0),
            "value {i}: subgram {g}, lpfg {w}"
        );
    }
    // Scaling x by 2 doubles the contour's first sample, -2/3 (see
    // contours_by_hand): -4/3.
    assert!((got[1] + 4.0 / 3.0).abs() < 1e-6);
    // The program's model is not changed by a run: a second run starts
    // from the files' contour.
    assert_eq!(values(&c), got);
}

#[test]
fn a_control_point_out_of_range_is_named() {
    let mut m = load_model("editing");
    let args = [
        Value::Int(1),
        Value::Int(7),
        Value::Float(0.0),
        Value::Float(0.0),
        Value::Float(0.0),
    ];
    let e = m
        .call_mut(model::Accessor::CurveSetPoint, &args)
        .unwrap_err();
    assert!(
        e.contains("contour `ring` has control points 0 to 6"),
        "{e}"
    );
    assert!(e.contains("the three copies that close it first"), "{e}");
    let e = m
        .call_mut(model::Accessor::CurveReset, &[Value::Int(0)])
        .unwrap_err();
    assert!(e.contains("default circle"), "{e}");
}

#[test]
fn a_file_may_hold_only_so_many_points() {
    // 20,001 parameters: one more than a file may hold (MAX_FILE_POINTS).
    let text: String = (0..=model::text::MAX_FILE_POINTS)
        .map(|i| format!("#define P{i} {i}\n"))
        .collect();
    let e = model::functions::read_vset("big.vset", &text)
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("big.vset:20001:1: error: the file holds more than 20000 parameters"),
        "{e}"
    );
    // A contour of more control points than one may have.
    let e = model::contours::read_con("big.con", "cver 1 3\nname: c\npoints: 1001 1001\n")
        .unwrap_err()
        .to_string();
    assert!(e.contains("must be from 1 to 1000"), "{e}");
}

/// `EA20(EA20Array)` (manual 5.13): the array type exists and the module
/// takes it, so a model that talks to an environmental program through
/// EA20 runs, with the warning that no environmental program runs (its
/// array comes back unchanged).
#[test]
fn ea20_arrays_are_modules_with_a_warning() {
    let src = "EA20Array ea = {1, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 4};\n\
               derivation length: 1;\nAxiom: EA20(ea) A;\nmodule A;\n\
               EA20(x) < A : { produce A F(x[0] + x[19]); }\n";
    let system = subgram::load_text("ea.l", src, &LoadOptions::default()).unwrap();
    let warnings = system.warnings();
    assert!(
        warnings
            .iter()
            .any(|w| w.contains("`EA20`") && w.contains("environmental program")),
        "{warnings:?}"
    );
    let l = match system {
        System::Curve(c) => c,
        System::Surface(_) | System::Vv(_) | System::Shapes(_) => panic!("a curve"),
    };
    let d = l.derive(Default::default()).unwrap();
    assert_eq!(
        l.word_text(&d.word),
        "EA20({1, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 4}) A F(5)"
    );
}

/// A folder with two view files: the turtle reads the one the model's
/// `specifications` name, as the model's other files are read, not the
/// first by name.
#[test]
fn the_turtle_reads_the_view_file_the_specifications_name() {
    let folder = scratch("two-views");
    let tmp = folder.path();
    std::fs::write(
        tmp.join("lsystem.l"),
        "derivation length: 1;\nmodule A;\nAxiom: A;\nA : { produce F(1) A; }\n",
    )
    .unwrap();
    std::fs::write(tmp.join("specifications"), "model:\n\tlpfg lsystem.l b.v\n").unwrap();
    // a.v comes first by name, and its tropism cannot be read.
    std::fs::write(tmp.join("a.v"), "tropism: T: 0 0 0\n").unwrap();
    std::fs::write(tmp.join("b.v"), "corrected rotation: on\n").unwrap();
    let out = subgram::command::check(&tmp.display().to_string(), &[], false).unwrap();
    assert!(!out.contains("a.v"), "{out}");
    assert!(out.lines().last().unwrap().contains(": ok ("), "{out}");
}

/// lpfg refuses an L+C program without `#include <lpfgall.h>`; subgram
/// runs it and says so, at the program's first line (issue 37).
#[test]
fn a_program_without_lpfgall_is_run_with_a_warning() {
    let folder = scratch("noinclude");
    let tmp = folder.path();
    std::fs::write(
        tmp.join("lsystem.l"),
        "derivation length: 1;\nAxiom: F(1);\nF(x) : { produce F(x) F(x); }\n",
    )
    .unwrap();
    let out = subgram::command::check(&tmp.display().to_string(), &[], false).unwrap();
    assert!(
        out.contains("lsystem.l:1:1: warning: no `#include <lpfgall.h>`: lpfg refuses"),
        "{out}"
    );
    std::fs::write(
        tmp.join("lsystem.l"),
        "#include <lpfgall.h>\nderivation length: 1;\nAxiom: F(1);\nF(x) : { produce F(x) F(x); }\n",
    )
    .unwrap();
    let out = subgram::command::check(&tmp.display().to_string(), &[], false).unwrap();
    assert!(!out.contains("lpfgall"), "{out}");
}

/// The RGB pixels of `subgram render PROGRAM -o PROGRAM.png`.
fn rendered(program: &Path) -> Vec<[u8; 3]> {
    let png = program.with_extension("png");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_subgram"))
        .args([
            "render",
            program.to_str().unwrap(),
            "-o",
            png.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    rgb_pixels(&png)
}

/// The RGB pixels of a PNG file.
fn rgb_pixels(path: &Path) -> Vec<[u8; 3]> {
    let d = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let mut r = d.read_info().unwrap();
    let mut buf = vec![0; r.output_buffer_size()];
    let info = r.next_frame(&mut buf).unwrap();
    let step = info.color_type.samples();
    buf[..info.buffer_size()]
        .chunks(step)
        .map(|p| [p[0], p[1], p[2]])
        .collect()
}

/// Without a colour file lpfg uses its own map, index 0 black (the
/// background) and every other index white (vlab's lpfg, colormap.h; its
/// picture of the corpus's 03-snowflake is white lines on black): an
/// lpfg program (`.l`) is drawn so. subgram's own files keep their white
/// page and palette.
#[test]
fn an_lpfg_program_without_a_colour_file_is_white_on_black() {
    let dir = scratch("lpfg-colours");
    let text = "#include <lpfgall.h>\nderivation length: 2;\nAxiom: F(1);\n\
                F(v) : { produce F(v) Left(60) F(v) Right(120) F(v) Left(60) F(v); }\n";
    for (name, background, ink) in [
        ("koch.l", [0u8, 0, 0], [255u8, 255, 255]),
        ("koch.lsys", [255, 255, 255], [24, 24, 24]),
    ] {
        let program = dir.path().join(name);
        std::fs::write(&program, text).unwrap();
        let pixels = rendered(&program);
        assert_eq!(pixels[0], background, "{name}: the corner");
        let near = |p: [u8; 3], c: [u8; 3]| (i32::from(p[0]) - i32::from(c[0])).abs() < 64;
        let inked = pixels.iter().filter(|&&p| near(p, ink)).count();
        assert!(
            inked > 200,
            "{name}: {inked} pixels near the line's colour {ink:?}"
        );
        assert!(
            pixels.contains(&ink),
            "{name}: no pixel of the line's colour {ink:?}"
        );
        // Antialiased lines: only greys between the two.
        assert!(
            pixels.iter().all(|p| p[0] == p[1] && p[1] == p[2]),
            "{name}"
        );
    }
}

/// In lpfg's shaded modes a pixel-wide line keeps its colour-map entry
/// (lpfg's picture of such a model: 255,191,0 exactly, made with
/// ../shared/tools/lpfg); subgram lit it like a tube facing the viewer
/// (255,255,0).
#[test]
fn a_line_in_shaded_mode_keeps_its_map_colour() {
    let dir = scratch("shaded-lines");
    let mut map = vec![255u8; 768];
    map[..6].copy_from_slice(&[0, 0, 0, 255, 191, 0]);
    std::fs::write(dir.path().join("color.map"), &map).unwrap();
    std::fs::write(dir.path().join("view.v"), "render mode: shaded\n").unwrap();
    let program = dir.path().join("plant.l");
    std::fs::write(
        &program,
        "#include <lpfgall.h>\nderivation length: 3;\nmodule A();\n\
         Axiom: SetColor(1) SetWidth(3) A();\n\
         A() : { produce F(1) SB() Left(30) A() EB() SB() Right(30) A() EB() F(1) A(); }\n",
    )
    .unwrap();
    let pixels = rendered(&program);
    let mut counts: std::collections::HashMap<[u8; 3], usize> = Default::default();
    for p in pixels.iter().filter(|p| **p != [0, 0, 0]) {
        *counts.entry(*p).or_default() += 1;
    }
    let (&most, _) = counts.iter().max_by_key(|(_, n)| **n).unwrap();
    assert_eq!(most, [255, 191, 0], "{counts:?}");
    assert!(!counts.contains_key(&[255, 255, 0]), "a lit line");
}
