//! The z-buffer renderer of 3D scenes (`render::raster`): depth order of
//! crossing surfaces, OpenGL's lighting formula, the camera against
//! matrices built here with glam's OpenGL-convention constructors, lpfg's
//! framing, independence from the thread count, SVG order, and refusals.

use glam::{Mat4, Vec3, Vec4};
use subgram::render::raster::{
    self, lighting, render, Camera, Light, Projection, RasterOptions, Shading, ViewSpec,
};
use subgram::render::Rgba;
use subgram::scene3::{Line, Look, Scene3, TriMesh};

/// A look that shows exactly its emission (no ambient, diffuse or
/// specular reflection), so a pixel's colour is known without lighting.
fn glowing(name: &str, rgb: [u8; 3]) -> Look {
    let mut l = Look::colour(name, 0, [0, 0, 0]);
    l.ambient = [0.0; 3];
    l.diffuse = [0.0; 3];
    l.emission = rgb.map(|v| v as f32 / 255.0);
    l
}

/// A quad of two triangles over the corners in order.
fn quad(corners: [Vec3; 4]) -> TriMesh {
    TriMesh {
        positions: corners.to_vec(),
        normals: Vec::new(),
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        lines: Vec::new(),
    }
}

fn scene(parts: Vec<(Look, TriMesh)>) -> Scene3 {
    let (looks, meshes) = parts.into_iter().unzip();
    Scene3 { looks, meshes }
}

/// A camera on the +z axis looking down -z with y up, at distance 10,
/// seeing -2..2 in parallel projection (or 45° in perspective).
fn down_z(projection: Projection, size: u32) -> Camera {
    let half = match projection {
        Projection::Parallel => 2.0,
        Projection::Perspective => (22.5f32).to_radians().tan(),
    };
    Camera::look_at(
        Vec3::new(0.0, 0.0, 10.0),
        Vec3::ZERO,
        Vec3::Y,
        projection,
        half,
        (5.0, 15.0),
        size,
        size,
    )
    .expect("a camera")
}

/// The un-premultiplied colour of an opaque pixel.
fn rgb(img: &raster::Image, x: u32, y: u32) -> [u8; 3] {
    let p = img.pixel(x, y);
    [p[0], p[1], p[2]]
}

/// The pixel holding the projection of `p`.
fn pixel_of(cam: &Camera, p: Vec3) -> (u32, u32) {
    let q = cam.pixel(p).expect("in front of the eye");
    (q.x.floor() as u32, q.y.floor() as u32)
}

#[test]
fn the_nearer_of_two_crossing_quads_shows_on_each_side_of_their_crossing() {
    // Quad A lies in the plane z = 0.5·x, quad B in z = -0.5·x (y free):
    // they cross along the y axis. The camera looks down -z, so the nearer
    // surface at (x, y) is the one with the larger z: A where x > 0, B
    // where x < 0, computed here from the plane equations.
    let za = |x: f32| 0.5 * x;
    let zb = |x: f32| -0.5 * x;
    let plane = |z: &dyn Fn(f32) -> f32| {
        quad([
            Vec3::new(-1.5, -1.5, z(-1.5)),
            Vec3::new(1.5, -1.5, z(1.5)),
            Vec3::new(1.5, 1.5, z(1.5)),
            Vec3::new(-1.5, 1.5, z(-1.5)),
        ])
    };
    let red = [220, 30, 30];
    let blue = [30, 30, 220];
    // Both orders of the meshes: the depth test, not the order, decides.
    for flip in [false, true] {
        let mut parts = vec![
            (glowing("a", red), plane(&za)),
            (glowing("b", blue), plane(&zb)),
        ];
        if flip {
            parts.reverse();
        }
        let sc = scene(parts);
        for projection in [Projection::Parallel, Projection::Perspective] {
            let cam = down_z(projection, 120);
            let img = render(&sc, &RasterOptions::new(cam)).expect("renders");
            for x in [-1.2f32, -0.6, -0.2, 0.2, 0.6, 1.2] {
                for y in [-1.0f32, 0.0, 0.7] {
                    let expect = if za(x) > zb(x) { red } else { blue };
                    // The point seen is on the nearer plane.
                    let z = za(x).max(zb(x));
                    let (px, py) = pixel_of(&cam, Vec3::new(x, y, z));
                    assert_eq!(
                        rgb(&img, px, py),
                        expect,
                        "{projection:?}, flip {flip}, at x {x}, y {y}"
                    );
                }
            }
        }
    }
}

#[test]
fn a_flat_quad_gets_the_colour_of_opengls_lighting_formula() {
    // A quad facing +z (towards the viewer), a directional light at 60°
    // from its normal. OpenGL's fixed-function formula, computed here:
    // emission + ambient·global + ambient·La + diffuse·Ld·cos θ
    // + specular·Ls·(n·h)^shininess, h the half-way vector of the light
    // and the viewer (0, 0, 1), so n·h = cos(θ/2).
    let theta = 60f32.to_radians();
    let light = Light {
        direction: Vec3::new(theta.sin(), 0.0, theta.cos()),
        ambient: [0.1, 0.2, 0.0],
        diffuse: [0.9, 0.6, 0.8],
        specular: [0.5, 0.5, 0.5],
    };
    let mut look = Look::colour("leaf", 3, [0, 0, 0]);
    look.ambient = [0.3, 0.5, 0.2];
    look.diffuse = [0.4, 0.7, 0.3];
    look.specular = [0.2, 0.3, 0.1];
    look.emission = [0.05, 0.0, 0.02];
    look.shininess = 10.0;
    let global = 0.2f32;
    let expect: Vec<u8> = (0..3)
        .map(|k| {
            let c = look.emission[k]
                + look.ambient[k] * global
                + look.ambient[k] * light.ambient[k]
                + look.diffuse[k] * light.diffuse[k] * theta.cos()
                + look.specular[k] * light.specular[k] * (theta / 2.0).cos().powf(10.0);
            (c.clamp(0.0, 1.0) * 255.0).round() as u8
        })
        .collect();
    let front = quad([
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(1.0, 1.0, 0.0),
        Vec3::new(-1.0, 1.0, 0.0),
    ]);
    // The same quad wound the other way faces away: lit two-sided, with
    // the flipped normal, it looks the same.
    let mut back = front.clone();
    back.triangles = vec![[0, 2, 1], [0, 3, 2]];
    for mesh in [front, back] {
        let sc = scene(vec![(look.clone(), mesh)]);
        let cam = down_z(Projection::Parallel, 40);
        let opts = RasterOptions {
            lights: vec![light],
            ..RasterOptions::new(cam)
        };
        let img = render(&sc, &opts).expect("renders");
        let got = rgb(&img, 20, 20);
        for k in 0..3 {
            assert!(
                (got[k] as i32 - expect[k] as i32).abs() <= 1,
                "channel {k}: {got:?} against {expect:?}"
            );
        }
    }
    // The library's formula on its own: a light behind the surface adds
    // no diffuse and no specular.
    let away = Light {
        direction: Vec3::new(0.0, 0.0, -1.0),
        ..light
    };
    let c = lighting(&look, Vec3::Z, &[away], [global; 3]);
    for (k, ck) in c.iter().enumerate() {
        let only = look.emission[k] + look.ambient[k] * (global + light.ambient[k]);
        assert!((ck - only).abs() < 1e-6);
    }
}

#[test]
fn a_point_lands_on_the_pixel_the_opengl_matrices_give() {
    // gluLookAt then gluPerspective / glOrtho, as glam builds them
    // (`look_at_rh`, `perspective_rh_gl`, `orthographic_rh_gl`), then the
    // viewport: pixel = ((x + 1) / 2 · w, (1 - y) / 2 · h), y down.
    let (w, h) = (160u32, 100u32);
    let aspect = w as f32 / h as f32;
    let eye = Vec3::new(3.0, -4.0, 5.0);
    let target = Vec3::new(0.5, 0.2, -0.3);
    let up = Vec3::new(0.1, 0.0, 1.0);
    let (near, far) = (2.0, 20.0);
    let fovy = 40f32.to_radians();
    let half = 1.7;
    let view = Mat4::look_at_rh(eye, target, up);
    let cases = [
        (
            Projection::Perspective,
            (fovy / 2.0).tan(),
            Mat4::perspective_rh_gl(fovy, aspect, near, far),
        ),
        (
            Projection::Parallel,
            half,
            Mat4::orthographic_rh_gl(-half * aspect, half * aspect, -half, half, near, far),
        ),
    ];
    let points = [
        Vec3::new(0.5, 0.2, -0.3),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(-0.7, 1.1, 0.4),
        Vec3::new(0.2, -0.9, -1.0),
    ];
    for (projection, half_height, proj) in cases {
        let cam = Camera::look_at(eye, target, up, projection, half_height, (near, far), w, h)
            .expect("a camera");
        for p in points {
            let clip = proj * view * Vec4::new(p.x, p.y, p.z, 1.0);
            let ndc = clip.truncate() / clip.w;
            let want = Vec3::new(
                (ndc.x + 1.0) * 0.5 * w as f32,
                (1.0 - ndc.y) * 0.5 * h as f32,
                (ndc.z + 1.0) * 0.5,
            );
            let got = cam.pixel(p).expect("in front");
            assert!(
                (got - want).abs().max_element() < 2e-3,
                "{projection:?} {p}: {got} against {want}"
            );
        }
        // A small square around the first off-centre point, facing the
        // eye, is drawn where the matrices put the point.
        let p = points[2];
        let (r, u) = (cam.right * 0.1, cam.up * 0.1);
        let sq = quad([p - r - u, p + r - u, p + r + u, p - r + u]);
        let sc = scene(vec![(glowing("dot", [0, 200, 0]), sq)]);
        let img = render(&sc, &RasterOptions::new(cam)).expect("renders");
        let clip = proj * view * p.extend(1.0);
        let ndc = clip.truncate() / clip.w;
        let (x, y) = (
            ((ndc.x + 1.0) * 0.5 * w as f32) as u32,
            ((1.0 - ndc.y) * 0.5 * h as f32) as u32,
        );
        assert_eq!(rgb(&img, x, y), [0, 200, 0], "{projection:?}");
        assert_eq!(rgb(&img, x + 8, y), [255, 255, 255], "{projection:?}");
    }
}

#[test]
fn lpfgs_default_view_fills_scale_of_the_window_with_the_box() {
    // lpfg's manual (§8.1.1): the view looks down -z with y up, and
    // `scale: s` sets the size of the image, 1.0 for full size (0.9 by
    // default). A box twice as tall as wide in a square window: its
    // height spans 0.9 of the window, centred.
    let points = [Vec3::new(-1.0, -2.0, 0.0), Vec3::new(1.0, 2.0, 0.5)];
    let cam = Camera::from_view(&ViewSpec::default(), &mut points.iter().copied(), 100, 100)
        .expect("a camera");
    let top = cam.pixel(Vec3::new(0.0, 2.0, 0.25)).expect("seen");
    let bottom = cam.pixel(Vec3::new(0.0, -2.0, 0.25)).expect("seen");
    let right = cam.pixel(Vec3::new(1.0, 0.0, 0.25)).expect("seen");
    assert!((top.y - 5.0).abs() < 1e-3, "{top}");
    assert!((bottom.y - 95.0).abs() < 1e-3, "{bottom}");
    assert!((right.x - (50.0 + 45.0 / 2.0)).abs() < 1e-3, "{right}");
    // `scale: 1` fills the window; the whole box lies between the
    // clipping planes.
    let full = ViewSpec {
        scale: 1.0,
        ..ViewSpec::default()
    };
    let cam = Camera::from_view(&full, &mut points.iter().copied(), 100, 100).expect("a camera");
    assert!(cam.pixel(Vec3::new(0.0, 2.0, 0.0)).expect("seen").y.abs() < 1e-3);
    for z in [0.0, 0.5] {
        let d = cam.pixel(Vec3::new(0.0, 0.0, z)).expect("seen").z;
        assert!((0.0..=1.0).contains(&d), "depth {d}");
    }
    // Perspective: the box's centre is on the axis, at the image centre.
    let persp = ViewSpec {
        projection: Projection::Perspective,
        ..ViewSpec::default()
    };
    let cam = Camera::from_view(&persp, &mut points.iter().copied(), 100, 100).expect("a camera");
    let c = cam.pixel(Vec3::new(0.0, 0.0, 0.25)).expect("seen");
    assert!(
        (c.x - 50.0).abs() < 1e-3 && (c.y - 50.0).abs() < 1e-3,
        "{c}"
    );
}

/// A scene of many small triangles scattered over the view, from a fixed
/// linear congruential sequence.
fn confetti(n: usize) -> Scene3 {
    let mut seed = 12345u64;
    let mut next = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((seed >> 33) as f32 / (1u64 << 31) as f32) * 2.0 - 1.0
    };
    let mut meshes = vec![TriMesh::default(), TriMesh::default()];
    for k in 0..n {
        let m = &mut meshes[k % 2];
        let c = Vec3::new(next() * 1.8, next() * 1.8, next());
        let s = 0.02 + 0.05 * next().abs();
        let start = m.positions.len() as u32;
        m.positions.push(c);
        m.positions.push(c + Vec3::new(s, 0.0, next() * s));
        m.positions.push(c + Vec3::new(0.0, s, next() * s));
        m.triangles.push([start, start + 1, start + 2]);
    }
    let mut a = Look::colour("a", 1, [200, 120, 40]);
    a.specular = [0.5; 3];
    a.shininess = 20.0;
    Scene3 {
        looks: vec![a, Look::colour("b", 2, [40, 160, 90])],
        meshes,
    }
}

/// `sc` drawn by a pool of `threads` threads.
fn on_threads(threads: usize, sc: &Scene3, opts: &RasterOptions) -> raster::Image {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a pool")
        .install(|| render(sc, opts).expect("renders"))
}

#[test]
fn the_picture_does_not_depend_on_the_number_of_threads() {
    // 100,000 triangles: past the size from which triangles are
    // rasterised in chunks, one key buffer per thread.
    let sc = confetti(100_000);
    let cam = down_z(Projection::Parallel, 200);
    let opts = RasterOptions::new(cam);
    let on = |threads: usize| on_threads(threads, &sc, &opts);
    let one = on(1);
    assert_eq!(one, on(2));
    assert_eq!(one, on(5));
    // And it drew something of both colours.
    let lit = one
        .pixels
        .chunks(4)
        .filter(|p| p[..3] != [255, 255, 255])
        .count();
    assert!(lit > 200 * 200 / 2, "{lit} pixels drawn");
}

/// Lines in the plane of a quad tie with it in depth at every sample
/// they share. The quad, numbered first, keeps those samples, on one
/// thread as on several (where a thread's lines meet another's triangle
/// only when the buffers are merged, by the smaller depth and index).
#[test]
fn lines_tied_with_a_triangle_give_the_same_picture_on_any_number_of_threads() {
    let green = glowing("green", [0, 255, 0]);
    let red = glowing("red", [255, 0, 0]);
    let plane = quad([
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(1.0, 1.0, 0.0),
        Vec3::new(-1.0, 1.0, 0.0),
    ]);
    // 70,000 short lines at z = 0 over the picture: past the size from
    // which the work is cut into chunks, one per thread.
    let mut lines = Vec::new();
    for k in 0..70_000u32 {
        let x = -1.9 + 3.8 * ((k as u64 * 7919) % 1000) as f32 / 1000.0;
        let y = -1.9 + 3.8 * ((k as u64 * 104_729) % 997) as f32 / 997.0;
        lines.push(Line {
            a: Vec3::new(x, y, 0.0),
            b: Vec3::new(x + 0.05, y + 0.02, 0.0),
            width: 0.1,
        });
    }
    let sc = scene(vec![
        (green, plane),
        (
            red,
            TriMesh {
                lines,
                ..Default::default()
            },
        ),
    ]);
    let opts = RasterOptions::new(down_z(Projection::Parallel, 100));
    let on = |threads: usize| on_threads(threads, &sc, &opts);
    let one = on(1);
    assert_eq!(one, on(2));
    assert_eq!(one, on(3));
    // Inside the quad only its green shows; outside it, the red lines.
    let (inside, outside) = (rgb(&one, 50, 50), rgb(&one, 3, 3));
    assert_eq!(inside, [0, 255, 0]);
    let reds = (0..100)
        .flat_map(|y| (0..20).map(move |x| (x, y)))
        .filter(|&(x, y)| rgb(&one, x, y)[1] < 255)
        .count();
    assert!(
        reds > 100,
        "{reds} pixels of red lines outside the quad ({outside:?})"
    );
    for y in 30..70 {
        for x in 30..70 {
            assert_eq!(rgb(&one, x, y)[0], 0, "red inside the quad at ({x}, {y})");
        }
    }
}

#[test]
fn svg_paints_triangles_back_to_front() {
    let near = quad([
        Vec3::new(-1.0, -1.0, 1.0),
        Vec3::new(1.0, -1.0, 1.0),
        Vec3::new(1.0, 1.0, 1.0),
        Vec3::new(-1.0, 1.0, 1.0),
    ]);
    let far = quad([
        Vec3::new(-1.5, -0.5, -1.0),
        Vec3::new(0.5, -0.5, -1.0),
        Vec3::new(0.5, 1.5, -1.0),
        Vec3::new(-1.5, 1.5, -1.0),
    ]);
    // The near quad first in the scene: the SVG must still paint it last.
    let sc = scene(vec![
        (glowing("near", [255, 0, 0]), near),
        (glowing("far", [0, 0, 255]), far),
    ]);
    let opts = RasterOptions::new(down_z(Projection::Parallel, 100));
    let svg = raster::polygons(&sc, &opts).expect("draws");
    let colours: Vec<Rgba> = svg
        .items
        .iter()
        .map(|i| match i {
            subgram::render::Item::Polygon { color, .. } => *color,
            other => panic!("not a polygon: {other:?}"),
        })
        .collect();
    assert_eq!(
        colours,
        vec![
            Rgba(0, 0, 255, 255),
            Rgba(0, 0, 255, 255),
            Rgba(255, 0, 0, 255),
            Rgba(255, 0, 0, 255)
        ]
    );
    let text = raster::render_svg(&sc, &opts).expect("draws");
    assert_eq!(text.matches("<polygon").count(), 4);
}

#[test]
fn shading_modes_colour_by_the_normal() {
    // A quad facing the viewer (+z): its normal map colour is
    // (n + 1) / 2 = (0.5, 0.5, 1).
    let sc = scene(vec![(
        Look::colour("q", 0, [10, 20, 30]),
        quad([
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(-1.0, 1.0, 0.0),
        ]),
    )]);
    let opts = RasterOptions {
        shading: Shading::Normals,
        ..RasterOptions::new(down_z(Projection::Parallel, 40))
    };
    let img = render(&sc, &opts).expect("renders");
    assert_eq!(rgb(&img, 20, 20), [128, 128, 255]);
    // Unlit (lpfg's `render mode: filled`): the look's own colour.
    let opts = RasterOptions {
        shading: Shading::Unlit,
        ..opts
    };
    assert_eq!(
        rgb(&render(&sc, &opts).expect("renders"), 20, 20),
        [10, 20, 30]
    );
}

#[test]
fn smooth_normals_are_interpolated() {
    // One triangle whose vertex normals lean left, up and right: lit by a
    // light from the viewer, the middle is brighter than near a corner
    // whose normal leans away, and a flat copy (no normals) is uniform.
    let n = |x: f32, y: f32| Vec3::new(x, y, 1.0).normalize();
    let tri = TriMesh {
        positions: vec![
            Vec3::new(-1.5, -1.5, 0.0),
            Vec3::new(1.5, -1.5, 0.0),
            Vec3::new(0.0, 1.5, 0.0),
        ],
        normals: vec![n(-2.0, -2.0), n(2.0, -2.0), n(0.0, 2.0)],
        triangles: vec![[0, 1, 2]],
        lines: Vec::new(),
    };
    let mut look = Look::colour("s", 0, [200, 200, 200]);
    look.ambient = [0.0; 3];
    let cam = down_z(Projection::Parallel, 80);
    let opts = RasterOptions {
        global_ambient: [0.0; 3],
        ..RasterOptions::new(cam)
    };
    let img = render(&scene(vec![(look.clone(), tri.clone())]), &opts).expect("renders");
    let (cx, cy) = pixel_of(&cam, Vec3::new(0.0, -0.5, 0.0));
    let (kx, ky) = pixel_of(&cam, Vec3::new(-1.2, -1.35, 0.0));
    assert!(rgb(&img, cx, cy)[0] > rgb(&img, kx, ky)[0] + 40);
    // The centroid's normal is the mean of the three: (0, -2/3·…, …)
    // normalised; its diffuse term under a light from the viewer is its
    // z, computed here.
    let mean = (tri.normals[0] + tri.normals[1] + tri.normals[2]).normalize();
    let (gx, gy) = pixel_of(&cam, Vec3::new(0.0, -0.5, 0.0));
    let want = (200.0 / 255.0 * mean.z * 255.0).round() as i32;
    assert!((rgb(&img, gx, gy)[0] as i32 - want).abs() <= 2);
    let flat = TriMesh {
        normals: Vec::new(),
        ..tri
    };
    let img = render(&scene(vec![(look, flat)]), &opts).expect("renders");
    assert_eq!(rgb(&img, cx, cy), rgb(&img, kx, ky));
}

#[test]
fn bad_scenes_are_refused_with_a_message() {
    let cam = down_z(Projection::Parallel, 40);
    let opts = RasterOptions::new(cam);
    let err = |sc: &Scene3| render(sc, &opts).expect_err("refused").message;
    assert!(err(&Scene3::default()).contains("nothing to draw"));
    let mut nan = quad([Vec3::ZERO, Vec3::X, Vec3::ONE, Vec3::Y]);
    nan.positions[2].y = f32::NAN;
    let m = err(&scene(vec![(Look::colour("leaf", 0, [0; 3]), nan)]));
    assert!(
        m.contains("vertex 2") && m.contains("non-finite") && m.contains("leaf"),
        "{m}"
    );
    let mut far = quad([Vec3::ZERO, Vec3::X, Vec3::ONE, Vec3::Y]);
    far.triangles.push([0, 1, 9]);
    let m = err(&scene(vec![(Look::colour("x", 0, [0; 3]), far)]));
    assert!(m.contains("refers to vertex 9"), "{m}");
    let mut normals = quad([Vec3::ZERO, Vec3::X, Vec3::ONE, Vec3::Y]);
    normals.normals = vec![Vec3::Z];
    assert!(err(&scene(vec![(Look::colour("x", 0, [0; 3]), normals)])).contains("1 normals"));
    // A degenerate view is refused too.
    assert!(Camera::look_at(
        Vec3::ZERO,
        Vec3::ZERO,
        Vec3::Y,
        Projection::Parallel,
        1.0,
        (0.0, 1.0),
        10,
        10
    )
    .is_none());
    let bad = ViewSpec {
        dir: Vec3::ZERO,
        ..ViewSpec::default()
    };
    assert!(Camera::from_view(&bad, &mut [Vec3::ZERO, Vec3::ONE].into_iter(), 10, 10).is_err());
    assert!(Camera::from_view(&ViewSpec::default(), &mut std::iter::empty(), 10, 10).is_err());
    assert!(Camera::from_view(&ViewSpec::default(), &mut [Vec3::ONE].into_iter(), 0, 10).is_err());
}

#[test]
fn the_view_files_camera_commands_are_kept() {
    use subgram::model::view::{read_v, RenderMode};
    let text = "projection: perspective\nscale factor: 0.8\n\
                view: 0 dir: 1 0 0 up: 0 0 1 fov: 30 shift: 12\n\
                box: 0 -1 1 -2 2 0 3\nfront distance: -4\nback distance: 5\n\
                render mode: shaded\nview: 1 dir: 0 1 0\n";
    let mut notes = Vec::new();
    let v = read_v("view.v", text, &mut notes).expect("reads");
    let c = &v.camera;
    assert!(c.perspective);
    assert_eq!(c.scale, Some(0.8));
    assert_eq!(c.dir, Some([1.0, 0.0, 0.0]));
    assert_eq!(c.up, Some([0.0, 0.0, 1.0]));
    assert_eq!((c.fov, c.shift), (Some(30.0), Some(12.0)));
    assert_eq!(c.bbox, Some([-1.0, 1.0, -2.0, 2.0, 0.0, 3.0]));
    assert_eq!((c.front, c.back), (Some(-4.0), Some(5.0)));
    assert_eq!(c.render_mode, RenderMode::Shaded);
    // View 1 (multiple views) is left out with a note at its number.
    assert_eq!(notes.len(), 1, "{notes:?}");
    assert!(notes[0].message.contains("only view 0"));
    // The renderer's view: the box framed from +x looking along it.
    let spec = c.spec();
    assert_eq!(spec.projection, Projection::Perspective);
    assert_eq!((spec.scale, spec.fov, spec.shift), (0.8, 30.0, Some(12.0)));
    assert_eq!(spec.clip, Some((-4.0, 5.0)));
    let cam = Camera::from_view(&spec, &mut std::iter::empty(), 100, 100).expect("a camera");
    // The eye stands `shift` before the box's centre (0, 0, 1.5).
    assert!(
        (cam.eye - Vec3::new(-12.0, 0.0, 1.5)).length() < 1e-4,
        "{}",
        cam.eye
    );
    // The deprecated form: rotations about x, y, z in degrees. 90° about
    // x turns the default direction (0, 0, -1) to (0, 1, 0) and the up
    // (0, 1, 0) to (0, 0, 1): (x, y cos - z sin, y sin + z cos).
    let mut notes = Vec::new();
    let v = read_v("view.v", "view: 0 90 0 0 0.5 1 2 3\n", &mut notes).expect("reads");
    let d = v.camera.dir.expect("a direction");
    let u = v.camera.up.expect("an up");
    for (a, b) in d
        .iter()
        .zip([0.0, 1.0, 0.0])
        .chain(u.iter().zip([0.0, 0.0, 1.0]))
    {
        assert!((a - b).abs() < 1e-12, "{d:?} {u:?}");
    }
    assert_eq!(
        (v.camera.scale, v.camera.pan),
        (Some(0.5), Some([1.0, 2.0, 3.0]))
    );
    // Malformed values are errors at their place.
    for (bad, col) in [
        ("view: 0 dir: 1 x 0\n", 16),
        ("box: 0 1 -1 0 1 0 1\n", 8),
        ("scale: 0\n", 8),
        ("view: 0 tilt: 3\n", 9),
    ] {
        let e = read_v("view.v", bad, &mut Vec::new())
            .expect_err("refused")
            .to_string();
        assert!(e.starts_with(&format!("view.v:1:{col}:")), "{bad}: {e}");
    }
    // Lights keep their specular colour; none gives lpfg's default light.
    let v = read_v(
        "view.v",
        "light: V: 0 1 0 S: 0.5 0.4 0.3\n",
        &mut Vec::new(),
    )
    .expect("reads");
    let l = subgram::render::view_file::raster_lights(&v.lights);
    assert_eq!(l[0].specular, [0.5, 0.4, 0.3]);
    assert_eq!(l[0].direction, Vec3::Y);
    assert_eq!(
        subgram::render::view_file::raster_lights(&[]),
        vec![Light::default()]
    );
}

/// A line (a tube thinner than a pixel) is drawn one sample wide without a
/// gap: every pixel column it crosses shows it, and the rows around it do
/// not. It hides behind a nearer quad and shows before a farther one. Lit,
/// its normal is the direction to the viewer made perpendicular to it: for
/// a line across the view, the view direction itself, so its colour is
/// OpenGL's formula for that normal.
#[test]
fn a_line_is_drawn_one_sample_wide_lit_as_the_tube_side_facing_the_viewer() {
    let size = 64;
    let cam = down_z(Projection::Parallel, size);
    let red = Look::colour("red", 1, [200, 40, 40]);
    // A shallow diagonal from (-1.9, -0.3) to (1.9, 0.2), at z = 0.
    let (a, b) = (Vec3::new(-1.9, -0.3, 0.0), Vec3::new(1.9, 0.2, 0.0));
    let line = TriMesh {
        // 0.2 wide: 6.4 samples, so it takes every sample on its axis.
        lines: vec![Line { a, b, width: 0.2 }],
        ..Default::default()
    };
    let light = Light {
        direction: Vec3::new(0.3, 0.4, 1.0).normalize(),
        ambient: [0.0; 3],
        diffuse: [1.0; 3],
        specular: [0.0; 3],
    };
    let mut opts = RasterOptions::new(cam);
    opts.lights = vec![light];
    let img = render(&scene(vec![(red.clone(), line.clone())]), &opts).unwrap();
    let want = lighting(&red, Vec3::Z, &opts.lights, opts.global_ambient)
        .map(|v| (v * 255.0).round() as i32);
    let (x0, _) = pixel_of(&cam, a);
    let (x1, _) = pixel_of(&cam, b);
    for x in x0 + 1..x1 {
        // The line's row at this column's centre.
        let t = ((x as f32 + 0.5) / size as f32 * 4.0 - 2.0 - a.x) / (b.x - a.x);
        let p = a + (b - a) * t;
        let (_, y) = pixel_of(&cam, p);
        // Two sample columns a pixel, one sample of each on the line: the
        // column's pixels near the line hold two of their four samples in
        // all, the line's colour mixed with white in that proportion.
        let ink: f32 = (y.saturating_sub(2)..=y + 2)
            .map(|y| {
                let c = rgb(&img, x, y);
                (255.0 - c[1] as f32) / (255.0 - want[1] as f32)
            })
            .sum();
        assert!(
            (ink - 0.5).abs() < 0.02,
            "column {x}: {ink} pixels of ink near row {y}, not half a pixel"
        );
        for far in [y.saturating_sub(3), y + 3] {
            assert_eq!(rgb(&img, x, far), [255, 255, 255], "column {x}, row {far}");
        }
    }
    // Behind a quad at z = 1 (nearer the eye at z = 10), in front of one at
    // z = -1: the green quad covers the middle of the picture.
    let green = glowing("green", [0, 255, 0]);
    let centre = pixel_of(&cam, Vec3::new(0.0, a.y + (b.y - a.y) * 0.5, 0.0));
    for (z, line_shows) in [(1.0f32, false), (-1.0, true)] {
        let q = quad([
            Vec3::new(-0.5, -1.0, z),
            Vec3::new(0.5, -1.0, z),
            Vec3::new(0.5, 1.0, z),
            Vec3::new(-0.5, 1.0, z),
        ]);
        let img = render(
            &scene(vec![(green.clone(), q), (red.clone(), line.clone())]),
            &opts,
        )
        .unwrap();
        let near: Vec<[u8; 3]> = (centre.1 - 1..=centre.1 + 1)
            .map(|y| rgb(&img, centre.0, y))
            .collect();
        let red_there = near.iter().any(|c| c[1] < 200);
        assert_eq!(red_there, line_shows, "quad at z = {z}: {near:?}");
    }
}

/// A line thinner than a sample takes each sample on its axis with the
/// chance that its tube covers it: the ink of many such lines is their
/// tubes' area. 150 horizontal lines 180 samples long (1.27 samples
/// apart, so no two share a sample), `w` samples wide, drawn in white on
/// black: each pixel of 2×2 samples is lit by a quarter per sample taken,
/// so the picture's light adds up to 180·w·150/4 pixels (within a few
/// percent; the lots are a hash, the same on every run).
#[test]
fn lines_under_a_sample_wide_leave_ink_in_proportion_to_their_width() {
    let size = 100u32;
    // 4 world units over 100 pixels: 50 samples a unit.
    let cam = down_z(Projection::Parallel, size);
    let white = glowing("white", [255, 255, 255]);
    let ink = |w_samples: f32| -> f64 {
        let width = w_samples / 50.0;
        let lines = (0..150)
            .map(|k| {
                let y = -1.9 + 3.8 * (k as f32 + 0.5) / 150.0;
                Line {
                    a: Vec3::new(-1.8, y, 0.0),
                    b: Vec3::new(1.8, y, 0.0),
                    width,
                }
            })
            .collect();
        let mut opts = RasterOptions::new(cam);
        opts.background = Rgba(0, 0, 0, 255);
        let img = render(
            &scene(vec![(
                white.clone(),
                TriMesh {
                    lines,
                    ..Default::default()
                },
            )]),
            &opts,
        )
        .unwrap();
        img.pixels.chunks(4).map(|p| p[1] as f64 / 255.0).sum()
    };
    for w in [0.1f32, 0.3, 0.6] {
        // 3.6 units = 180 samples long.
        let want = (180.0 * w as f64) * 150.0 / 4.0;
        let got = ink(w);
        assert!(
            (got - want).abs() < 0.06 * want,
            "{w} samples wide: {got} pixels of ink, expected {want}"
        );
    }
}
