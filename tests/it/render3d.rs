//! `subgram render` of an L-system in 3D (issue 17): a model whose view
//! file asks for tubes or shading is drawn by the z-buffer with its
//! lights; `--solid` and `--lines` choose; `.obj`, `.ply` and `.glb`
//! outputs export the same geometry the library builds.

use std::path::PathBuf;
use std::process::Command;

use crate::support::{root, scratch};

fn model(name: &str) -> PathBuf {
    root().join("tests/data/models/solid").join(name)
}

fn subgram(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_subgram"))
        .args(args)
        .output()
        .unwrap()
}

fn png(path: &PathBuf) -> tiny_skia::Pixmap {
    tiny_skia::Pixmap::decode_png(&std::fs::read(path).unwrap()).unwrap()
}

fn luminance(p: tiny_skia::PremultipliedColorU8) -> f64 {
    0.2126 * p.red() as f64 + 0.7152 * p.green() as f64 + 0.0722 * p.blue() as f64
}

/// A model with `line style: cylinder` is drawn in 3D. With `render mode:
/// shaded` the sphere `Sphere(1)` is lit by lpfg's default light from the
/// viewer, so (Lambert) its middle, facing the light, is brighter than a
/// point near its rim, where the surface turns away; in lpfg's default
/// `filled` mode, and in the 2D drawing (`--lines`), the disc has one
/// colour.
#[test]
fn a_model_that_asks_for_tubes_is_drawn_in_3d_shaded_as_its_render_mode_says() {
    let tmp = scratch("r3d-shaded");
    let dir = tmp.path();
    for f in ["looks.l", "material.mat"] {
        std::fs::copy(model(f), dir.join(f)).unwrap();
    }
    let draw = |view: &str, extra: &[&str], out: &str| {
        std::fs::write(dir.join("view.v"), view).unwrap();
        let out = dir.join(out);
        let mut args = vec![
            "render",
            "looks.l",
            "-o",
            out.to_str().unwrap(),
            "--size",
            "300x300",
        ];
        args.extend_from_slice(extra);
        let o = Command::new(env!("CARGO_BIN_EXE_subgram"))
            .current_dir(dir)
            .args(&args)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        png(&out)
    };
    let spread = |pm: &tiny_skia::Pixmap| {
        // The sphere is the first of three shapes one above the other (f(3)
        // between them): the lowest in the picture. The pixels of the
        // middle column's lowest run that is not background.
        let bg = pm.pixel(0, 0).unwrap();
        let x = pm.width() / 2;
        let run: Vec<f64> = (0..pm.height())
            .rev()
            .map(|y| pm.pixel(x, y).unwrap())
            .skip_while(|p| *p == bg)
            .take_while(|p| *p != bg)
            .map(luminance)
            .collect();
        assert!(run.len() > 10, "the sphere is drawn: {} pixels", run.len());
        let inner = &run[run.len() / 8..run.len() - run.len() / 8];
        let mid = inner[inner.len() / 2];
        let rim = inner[0].min(inner[inner.len() - 1]);
        (mid, rim)
    };
    let shaded = "line style: cylinder\nrender mode: shaded\n";
    let (mid, rim) = spread(&draw(shaded, &[], "shaded.png"));
    assert!(mid > rim + 20.0, "lit: middle {mid}, near the rim {rim}");
    let (mid, rim) = spread(&draw("line style: cylinder\n", &[], "filled.png"));
    assert!(
        (mid - rim).abs() < 1.0,
        "filled: middle {mid}, near the rim {rim}"
    );
    let (mid, rim) = spread(&draw(shaded, &["--lines"], "flat.png"));
    assert!(
        (mid - rim).abs() < 1.0,
        "2D: middle {mid}, near the rim {rim}"
    );
}

/// `-o plant.obj|ply|glb` writes the geometry `Curve::solid` builds: the
/// same numbers of vertices and triangles, read back from each file.
#[test]
fn render_exports_the_geometry_the_library_builds() {
    let tmp = scratch("r3d-export");
    let dir = tmp.path();
    let f = model("leaf.l");
    let curve = match subgram::load(&f, &Default::default()).unwrap() {
        subgram::System::Curve(c) => c,
        _ => panic!("a curve"),
    };
    let scene = curve
        .solid(Default::default(), &Default::default())
        .unwrap();
    let (v, t) = (scene.vertex_count(), scene.triangle_count());
    assert!(t > 0);
    for ext in ["obj", "ply", "glb"] {
        let out = dir.join(format!("leaf.{ext}"));
        let o = subgram(&["render", f.to_str().unwrap(), "-o", out.to_str().unwrap()]);
        assert!(
            o.status.success(),
            "{ext}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let bytes = std::fs::read(&out).unwrap();
        match ext {
            "obj" => {
                let text = String::from_utf8(bytes).unwrap();
                assert_eq!(text.lines().filter(|l| l.starts_with("v ")).count(), v);
                assert_eq!(text.lines().filter(|l| l.starts_with("f ")).count(), t);
                assert!(dir.join("leaf.mtl").exists());
            }
            "ply" => {
                let head = String::from_utf8_lossy(&bytes[..bytes.len().min(512)]).into_owned();
                assert!(head.contains(&format!("element vertex {v}")), "{head}");
                assert!(head.contains(&format!("element face {t}")), "{head}");
            }
            _ => {
                assert_eq!(&bytes[..4], b"glTF");
                let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
                let json: serde_json::Value =
                    serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
                let mut verts = 0;
                let mut indices = 0;
                for p in json["meshes"][0]["primitives"].as_array().unwrap() {
                    let acc = &json["accessors"];
                    verts += acc[p["attributes"]["POSITION"].as_u64().unwrap() as usize]["count"]
                        .as_u64()
                        .unwrap();
                    indices += acc[p["indices"].as_u64().unwrap() as usize]["count"]
                        .as_u64()
                        .unwrap();
                }
                assert_eq!((verts as usize, indices as usize), (v, 3 * t));
            }
        }
    }
}

#[test]
fn what_3d_drawing_refuses() {
    let tmp = scratch("r3d-refuse");
    let dir = tmp.path();
    let looks = model("looks.l");
    let o = subgram(&[
        "render",
        looks.to_str().unwrap(),
        "--each",
        "-o",
        dir.join("e.png").to_str().unwrap(),
    ]);
    assert_eq!(
        o.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(String::from_utf8_lossy(&o.stderr).contains("--lines"));
    // A surface grammar's mesh is written as `subdivide` writes it (issue
    // 40, item 7; tests/it/mistakes.rs compares the bytes).
    let grammar = crate::support::lsys("surfaces/loop.lsys");
    let o = subgram(&[
        "render",
        grammar.to_str().unwrap(),
        "-o",
        dir.join("g.glb").to_str().unwrap(),
    ]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(std::fs::read(dir.join("g.glb"))
        .unwrap()
        .starts_with(b"glTF"));
    std::fs::remove_file(dir.join("g.glb")).unwrap();
    let o = subgram(&[
        "render",
        looks.to_str().unwrap(),
        "--view",
        "sideways",
        "-o",
        dir.join("v.png").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(
        std::fs::read_dir(dir).unwrap().count(),
        0,
        "nothing written"
    );
}
