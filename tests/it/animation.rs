//! Animations (`render -o growth.gif`, `.apng`, `-o 'frames/step-{n}.png'`)
//! decoded by the `gif` and `png` crates' own readers, which share no code
//! with the encoding: one frame per step (or per `.a` frame), frames that
//! differ, one camera for all, the delay `--fps` asks; and `command::frames`,
//! the library function behind them.

use std::path::Path;

use subgram::command::{self, FrameGeometry, FrameOptions};

use crate::support::*;

/// A decoded animation: its frames as straight RGBA, and each frame's
/// delay in seconds.
struct Decoded {
    width: u32,
    height: u32,
    frames: Vec<Vec<u8>>,
    delays: Vec<f64>,
}

fn decode_gif(path: &Path) -> Decoded {
    let mut opts = gif::DecodeOptions::new();
    opts.set_color_output(gif::ColorOutput::RGBA);
    let mut d = opts.read_info(std::fs::File::open(path).unwrap()).unwrap();
    let (width, height) = (d.width() as u32, d.height() as u32);
    let (mut frames, mut delays) = (Vec::new(), Vec::new());
    while let Some(f) = d.read_next_frame().unwrap() {
        // Every frame covers the whole picture.
        assert_eq!(
            (f.left, f.top, f.width as u32, f.height as u32),
            (0, 0, width, height)
        );
        frames.push(f.buffer.to_vec());
        delays.push(f.delay as f64 / 100.0);
    }
    Decoded {
        width,
        height,
        frames,
        delays,
    }
}

fn decode_apng(path: &Path) -> Decoded {
    let d = png::Decoder::new(std::fs::File::open(path).unwrap());
    let mut r = d.read_info().unwrap();
    let info = r.info();
    let (width, height) = (info.width, info.height);
    let count = info.animation_control().expect("an acTL chunk").num_frames;
    assert_eq!(info.color_type, png::ColorType::Rgba);
    let (mut frames, mut delays) = (Vec::new(), Vec::new());
    for _ in 0..count {
        let mut buf = vec![0; r.output_buffer_size()];
        r.next_frame(&mut buf).unwrap();
        let fc = r.info().frame_control().expect("an fcTL chunk");
        assert_eq!(
            (fc.x_offset, fc.y_offset, fc.width, fc.height),
            (0, 0, width, height)
        );
        delays.push(fc.delay_num as f64 / fc.delay_den as f64);
        frames.push(buf);
    }
    Decoded {
        width,
        height,
        frames,
        delays,
    }
}

/// The box (x0, y0, x1, y1, inclusive) of the pixels that differ from the
/// picture's top-left pixel (the background) by more than `tol` in some
/// channel; `None` for a blank picture.
fn ink_box(rgba: &[u8], width: u32, tol: u8) -> Option<(u32, u32, u32, u32)> {
    let bg = &rgba[..4];
    let mut b: Option<(u32, u32, u32, u32)> = None;
    for (i, p) in rgba.chunks_exact(4).enumerate() {
        if p.iter().zip(bg).any(|(a, c)| a.abs_diff(*c) > tol) {
            let (x, y) = (i as u32 % width, i as u32 / width);
            b = Some(match b {
                None => (x, y, x, y),
                Some((x0, y0, x1, y1)) => (x0.min(x), y0.min(y), x1.max(x), y1.max(y)),
            });
        }
    }
    b
}

fn inside(a: (u32, u32, u32, u32), b: (u32, u32, u32, u32), slack: u32) -> bool {
    a.0 + slack >= b.0 && a.1 + slack >= b.1 && a.2 <= b.2 + slack && a.3 <= b.3 + slack
}

fn run_ok(dir: &Path, args: &[&str]) {
    let out = subgram_in(dir, args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

fn run_usage_error(dir: &Path, args: &[&str]) -> String {
    let out = subgram_in(dir, args);
    assert_eq!(
        out.status.code(),
        Some(2),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn files_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn a_gif_has_a_frame_per_step_seen_by_one_camera() {
    let dir = scratch("anim-gif");
    let koch = lsys("abop/koch-snowflake.lsys");
    let koch = koch.to_str().unwrap();
    run_ok(
        dir.path(),
        &[
            "render", koch, "-n", "3", "--size", "300x300", "--fps", "10", "-o", "koch.gif",
        ],
    );
    let d = decode_gif(&dir.path().join("koch.gif"));
    assert_eq!((d.width, d.height), (300, 300));
    // Steps 0, 1, 2 and 3.
    assert_eq!(d.frames.len(), 4);
    // --fps 10: a tenth of a second each.
    assert!(d.delays.iter().all(|&t| t == 0.1), "{:?}", d.delays);
    for k in 1..4 {
        assert_ne!(
            d.frames[k - 1],
            d.frames[k],
            "frames {} and {k} are the same",
            k - 1
        );
    }
    // The snowflake only grows (each step's sides are three times as long,
    // from the same corner): with one camera, each frame's ink lies within
    // the last frame's, and the first triangle (side 1 of 27) is small, not
    // scaled up to fill the picture as a still of step 0 is.
    let boxes: Vec<_> = d
        .frames
        .iter()
        .map(|f| ink_box(f, d.width, 40).expect("ink"))
        .collect();
    let last = boxes[3];
    for b in &boxes {
        assert!(inside(*b, last, 1), "{b:?} is not inside {last:?}");
    }
    let (w0, wn) = (boxes[0].2 - boxes[0].0, last.2 - last.0);
    assert!(wn > 250 && w0 * 10 < wn, "first {w0} px wide, last {wn}");
}

#[test]
fn an_apngs_last_frame_is_the_still_picture() {
    // The drawing only grows, so the frames' common box is the last
    // step's, the box of `render -o still.png`: the last frame is that
    // picture, to the bit.
    let dir = scratch("anim-apng");
    let koch = lsys("abop/koch-snowflake.lsys");
    let koch = koch.to_str().unwrap();
    run_ok(
        dir.path(),
        &[
            "render", koch, "-n", "2", "--size", "200x160", "--fps", "5", "-o", "k.apng",
        ],
    );
    run_ok(
        dir.path(),
        &[
            "render",
            koch,
            "-n",
            "2",
            "--size",
            "200x160",
            "-o",
            "still.png",
        ],
    );
    let d = decode_apng(&dir.path().join("k.apng"));
    assert_eq!((d.width, d.height, d.frames.len()), (200, 160, 3));
    assert!(d.delays.iter().all(|&t| t == 0.2), "{:?}", d.delays);
    let still = png::Decoder::new(std::fs::File::open(dir.path().join("still.png")).unwrap());
    let mut r = still.read_info().unwrap();
    let mut buf = vec![0; r.output_buffer_size()];
    r.next_frame(&mut buf).unwrap();
    assert_eq!(d.frames[2], buf);
    assert_ne!(d.frames[0], d.frames[1]);
}

#[test]
fn a_surface_grammar_animates_its_levels_in_the_base_meshs_frame() {
    // Catmull-Clark shrinks the cube towards its limit surface: the
    // camera fits every level, so the base mesh (level 0) fills the
    // picture and the later levels lie inside it.
    let dir = scratch("anim-surface");
    let cc = lsys("surfaces/catmull-clark.lsys");
    run_ok(
        dir.path(),
        &[
            "render",
            cc.to_str().unwrap(),
            "-n",
            "2",
            "--size",
            "200x200",
            "-o",
            "cc.apng",
        ],
    );
    let d = decode_apng(&dir.path().join("cc.apng"));
    assert_eq!(d.frames.len(), 3);
    // Four frames a second by default.
    assert!(d.delays.iter().all(|&t| t == 0.25), "{:?}", d.delays);
    let boxes: Vec<_> = d
        .frames
        .iter()
        .map(|f| ink_box(f, 200, 8).unwrap())
        .collect();
    // The margin is 4% of 200 px: the base cube's outline (taller than
    // wide in the iso view) touches it at the top and the bottom.
    assert!(boxes[0].1 <= 9 && boxes[0].3 >= 190, "{:?}", boxes[0]);
    for b in &boxes[1..] {
        assert!(
            inside(*b, boxes[0], 0),
            "{b:?} is not inside {:?}",
            boxes[0]
        );
        assert!(b.2 - b.0 < boxes[0].2 - boxes[0].0, "{b:?} is not smaller");
    }
    assert_ne!(d.frames[1], d.frames[2]);
}

#[test]
fn the_models_animation_file_chooses_the_frames_and_their_interval() {
    // anim.a: first frame 1, last frame 5, step 2, swap interval 20
    // (hundredths of a second); the derivation length is 6.
    let dir = scratch("anim-model");
    let model = root().join("tests/data/models/growth");
    let model = model.to_str().unwrap();
    run_ok(
        dir.path(),
        &["render", model, "--size", "120x120", "-o", "g.gif"],
    );
    let d = decode_gif(&dir.path().join("g.gif"));
    assert_eq!(d.frames.len(), 3);
    assert!(d.delays.iter().all(|&t| t == 0.2), "{:?}", d.delays);
    // --fps overrides the swap interval.
    run_ok(
        dir.path(),
        &[
            "render", model, "--size", "120x120", "--fps", "2", "-o", "g.gif",
        ],
    );
    assert!(decode_gif(&dir.path().join("g.gif"))
        .delays
        .iter()
        .all(|&t| t == 0.5));
    // The frames are steps 1, 3 and 5: stills say so by their names.
    std::fs::create_dir(dir.path().join("f")).unwrap();
    run_ok(
        dir.path(),
        &["render", model, "--size", "120x120", "-o", "f/s{n}.svg"],
    );
    assert_eq!(
        files_in(&dir.path().join("f")),
        ["s1.svg", "s3.svg", "s5.svg"]
    );
}

#[test]
fn stills_are_one_file_a_step_named_by_the_step() {
    let dir = scratch("anim-stills");
    std::fs::create_dir(dir.path().join("frames")).unwrap();
    let chaikin = lsys("curves/chaikin-13.lsys");
    run_ok(
        dir.path(),
        &[
            "render",
            chaikin.to_str().unwrap(),
            "-n",
            "10",
            "--size",
            "64x64",
            "-o",
            "frames/step-{n}.png",
        ],
    );
    // Padded to the last step's two digits, so the names sort.
    let want: Vec<String> = (0..=10).map(|k| format!("step-{k:02}.png")).collect();
    assert_eq!(files_in(&dir.path().join("frames")), want);
    for name in &want {
        let d =
            png::Decoder::new(std::fs::File::open(dir.path().join("frames").join(name)).unwrap());
        let r = d.read_info().unwrap();
        assert_eq!((r.info().width, r.info().height), (64, 64));
    }
}

#[test]
fn a_run_that_fails_writes_no_frame() {
    // Step 4 divides an integer by zero: steps 0 to 3 were drawn, and
    // none of them is written.
    let dir = scratch("anim-fails");
    std::fs::write(
        dir.path().join("fails.lsys"),
        "module A(int);\nderivation length: 5;\nAxiom: A(0);\nA(n) : { if (n < 3) \
         produce F(1) Left(30) A(n + 1); else produce F(1 / (n - 3)) A(n + 1); }\n",
    )
    .unwrap();
    std::fs::create_dir(dir.path().join("out")).unwrap();
    for output in ["out/f-{n}.png", "out/f.gif"] {
        let out = subgram_in(dir.path(), &["render", "fails.lsys", "-o", output]);
        assert_eq!(
            out.status.code(),
            Some(1),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(String::from_utf8_lossy(&out.stderr).contains("division by zero"));
        assert!(files_in(&dir.path().join("out")).is_empty());
    }
}

#[test]
fn bad_animation_outputs_are_usage_errors_that_write_nothing() {
    let dir = scratch("anim-bad");
    let koch = lsys("abop/koch-snowflake.lsys");
    let koch = koch.to_str().unwrap();
    let e = run_usage_error(dir.path(), &["render", koch, "-o", "k.webp"]);
    assert!(
        e.contains("animated WebP is not written") && e.contains(".gif or .apng"),
        "{e}"
    );
    let e = run_usage_error(dir.path(), &["render", koch, "-o", "k-{n}.gif"]);
    assert!(
        e.contains("{n} names one still a frame, as .png or .svg"),
        "{e}"
    );
    let e = run_usage_error(dir.path(), &["render", koch, "-o", "missing/k-{n}.png"]);
    assert!(
        e.contains("the folder missing does not exist; create it first"),
        "{e}"
    );
    let e = run_usage_error(dir.path(), &["render", koch, "--fps", "0", "-o", "k.gif"]);
    assert!(e.contains("--fps 0"), "{e}");
    let e = run_usage_error(dir.path(), &["render", koch, "--each", "-o", "k.gif"]);
    assert!(e.contains("leave out --each"), "{e}");
    let shapes = lsys("shapes/building.lsys");
    let e = run_usage_error(
        dir.path(),
        &["render", shapes.to_str().unwrap(), "-o", "s.gif"],
    );
    assert!(e.contains("a shape grammar has no steps to animate"), "{e}");
    let cube = lsys("meshes/cube.obj");
    let e = run_usage_error(
        dir.path(),
        &["render", cube.to_str().unwrap(), "-o", "c.gif"],
    );
    assert!(e.contains("it has no steps to animate"), "{e}");
    assert!(
        files_in(dir.path()).is_empty(),
        "{:?}",
        files_in(dir.path())
    );
}

#[test]
fn a_still_is_never_written_over_an_input() {
    // The program's own name is one of the stills' (step 2).
    let dir = scratch("anim-input");
    let text = std::fs::read_to_string(lsys("abop/koch-snowflake.lsys")).unwrap();
    std::fs::write(dir.path().join("p-2.svg"), &text).unwrap();
    let e = run_usage_error(
        dir.path(),
        &["render", "p-2.svg", "-n", "3", "-o", "p-{n}.svg"],
    );
    assert!(e.contains("writing it would replace the input"), "{e}");
    assert_eq!(files_in(dir.path()), ["p-2.svg"]);
    assert_eq!(
        std::fs::read_to_string(dir.path().join("p-2.svg")).unwrap(),
        text
    );
}

#[test]
fn frames_share_one_camera_in_the_library() {
    // command::frames, as the live page calls it: a vv program's steps as
    // 3D frames, each with the same camera.
    let system = subgram::load(lsys("vv/tissue.lsys"), &Default::default()).unwrap();
    let opts = FrameOptions {
        run: subgram::RunOptions::default().with_steps(3),
        size: (100, 100),
        ..Default::default()
    };
    let mut heard = Vec::new();
    let frames = command::frames(&system, &opts, |p| heard.push(p.step)).unwrap();
    assert_eq!(
        frames.frames.iter().map(|f| f.step).collect::<Vec<_>>(),
        [0, 1, 2, 3]
    );
    assert_eq!(heard, [0, 1, 2, 3]);
    let cameras: Vec<_> = frames
        .frames
        .iter()
        .map(|f| match &f.geometry {
            FrameGeometry::Solid(s) => s.raster.camera,
            FrameGeometry::Flat(_) => panic!("a vv program's frame is 3D"),
        })
        .collect();
    assert!(cameras.iter().all(|c| *c == cameras[0]));
    // Each frame's geometry can be exported as the page does.
    for f in &frames.frames {
        let FrameGeometry::Solid(s) = &f.geometry else {
            unreachable!()
        };
        assert!(subgram::export::glb_bytes(&s.scene)
            .unwrap()
            .starts_with(b"glTF"));
    }
}

#[test]
fn frames_past_the_limits_are_refused_while_the_run_goes() {
    // 40 steps of 4000×4000 pixels: the 34th frame passes 2 GiB of RGBA,
    // and the run stops there with the limit's message, not at the end.
    let dir = scratch("anim-limits");
    std::fs::write(
        dir.path().join("still.lsys"),
        "derivation length: 40;\nAxiom: F(1);\n",
    )
    .unwrap();
    let e = run_usage_error(
        dir.path(),
        &["render", "still.lsys", "--size", "4000x4000", "-o", "s.gif"],
    );
    assert!(
        e.contains("34 frames of 4000x4000 pixels are too many"),
        "{e}"
    );
    assert!(e.contains("at most 1000 frames and 2 GiB of pixels"), "{e}");
    assert_eq!(files_in(dir.path()), ["still.lsys"]);
}

#[test]
fn a_3d_frame_with_nothing_drawn_yet_is_the_background() {
    // Step 0 is the axiom `A()`, which draws nothing; steps 1 and 2 draw
    // tubes, shaded by the z-buffer.
    let dir = scratch("anim-empty");
    std::fs::write(
        dir.path().join("grow.lsys"),
        "derivation length: 2;\nmodule A();\nAxiom: SetWidth(0.2) A();\nA() : { produce F(1) A(); }\n",
    )
    .unwrap();
    std::fs::create_dir(dir.path().join("f")).unwrap();
    run_ok(
        dir.path(),
        &[
            "render",
            "grow.lsys",
            "--solid",
            "--size",
            "80x80",
            "-o",
            "f/{n}.png",
        ],
    );
    run_ok(
        dir.path(),
        &[
            "render",
            "grow.lsys",
            "--solid",
            "--size",
            "80x80",
            "-o",
            "g.apng",
        ],
    );
    let d = decode_apng(&dir.path().join("g.apng"));
    assert_eq!(d.frames.len(), 3);
    assert_eq!(ink_box(&d.frames[0], 80, 0), None);
    let (a, b) = (
        ink_box(&d.frames[1], 80, 8).unwrap(),
        ink_box(&d.frames[2], 80, 8).unwrap(),
    );
    // The second tube doubles the plant's height in the one camera.
    assert!(
        inside(a, b, 0) && (b.3 - b.1) > (a.3 - a.1) * 3 / 2,
        "{a:?} {b:?}"
    );
    let still = png::Decoder::new(std::fs::File::open(dir.path().join("f/0.png")).unwrap());
    let mut r = still.read_info().unwrap();
    let mut buf = vec![0; r.output_buffer_size()];
    r.next_frame(&mut buf).unwrap();
    assert!(buf.chunks_exact(4).all(|p| p == [255, 255, 255, 255]));
}

#[test]
fn animation_files_read_as_lpfgs_manual_and_vlabs_models_write_them() {
    use subgram::model::view::{read_a, Animation};
    // As vlab's own models write it (monopodial's, leaf-rnd's): `last
    // frame: -1` is up to the derivation length; `frame numbers:` is not
    // in the manual's list, a note.
    let text = "double buffer: on\nclear between frames: on\nscale between frames: off\n\
                new view between frames: off\nhcenter between frames: off\nswap interval: 1\n\
                first frame: 1\nlast frame: -1\nstep: 1\nframe numbers: consecutive\n";
    let mut notes = Vec::new();
    let a = read_a("anim.a", text, &mut notes).unwrap();
    assert_eq!(
        a,
        Animation {
            first_frame: 1,
            swap_interval: 1.0,
            ..Animation::default()
        }
    );
    assert_eq!(notes.len(), 1);
    assert!(notes[0].message.contains("`frame numbers:`"));
    let a = read_a(
        "a.a",
        "first frame: 2\nlast frame: 9\nstep: 3\nscale between frames: on\n",
        &mut notes,
    )
    .unwrap();
    assert_eq!(
        (a.first_frame, a.last_frame, a.step, a.scale_between_frames),
        (2, Some(9), 3, true)
    );
    for bad in [
        "step: 0\n",
        "first frame: 1.5\n",
        "swap interval: -2\n",
        "double buffer: maybe\n",
    ] {
        let e = read_a("bad.a", bad, &mut notes).unwrap_err().to_string();
        assert!(e.starts_with("bad.a:1:"), "{bad}: {e}");
    }
}
