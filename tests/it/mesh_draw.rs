//! Pictures of meshes: sizes, fitting, shading, hidden faces, the SVG's
//! structure, the named views and the failures.

use std::collections::HashMap;

use glam::{DVec2, DVec3};
use subgram::mesh::PolygonSoup;
use subgram::render::mesh::{
    light_direction, project, render_png, render_svg, scene, view_direction, MeshView,
};
use subgram::render::{Item, Rgba};
use tiny_skia::Pixmap;

/// A soup without source lines.
fn soup(positions: Vec<DVec3>, faces: Vec<Vec<u32>>) -> PolygonSoup {
    PolygonSoup {
        positions,
        faces: faces.into(),
        ..PolygonSoup::default()
    }
}

/// The unit cube [0,1]^3 as 6 outward quads; vertex i is (i&1, i>>1&1, i>>2).
fn cube() -> PolygonSoup {
    let positions = (0..8)
        .map(|i| DVec3::new((i & 1) as f64, (i >> 1 & 1) as f64, (i >> 2) as f64))
        .collect();
    soup(positions, CUBE_FACES.iter().map(|f| f.to_vec()).collect())
}

/// The cube's faces: -z, +z, -y, +y, -x, +x.
const CUBE_FACES: [[u32; 4]; 6] = [
    [0, 2, 3, 1],
    [4, 5, 7, 6],
    [0, 1, 5, 4],
    [2, 6, 7, 3],
    [0, 4, 6, 2],
    [1, 3, 7, 5],
];

/// The outward normals of [`CUBE_FACES`].
const CUBE_NORMALS: [DVec3; 6] = [
    DVec3::NEG_Z,
    DVec3::Z,
    DVec3::NEG_Y,
    DVec3::Y,
    DVec3::NEG_X,
    DVec3::X,
];

/// The octahedron with vertices ±x, ±y, ±z (in that order), outward faces.
fn octahedron() -> PolygonSoup {
    let positions = vec![
        DVec3::X,
        DVec3::NEG_X,
        DVec3::Y,
        DVec3::NEG_Y,
        DVec3::Z,
        DVec3::NEG_Z,
    ];
    let mut faces = Vec::new();
    for sx in [0u32, 1] {
        for sy in [2u32, 3] {
            for sz in [4u32, 5] {
                let flips = (sx & 1) + (sy & 1) + (sz & 1);
                faces.push(if flips % 2 == 0 {
                    vec![sx, sy, sz]
                } else {
                    vec![sx, sz, sy]
                });
            }
        }
    }
    soup(positions, faces)
}

/// The octahedron split `levels` times into four triangles each, with every
/// vertex pushed onto the unit sphere.
fn sphere(levels: usize) -> PolygonSoup {
    let mut s = octahedron();
    for _ in 0..levels {
        let mut mids: HashMap<(u32, u32), u32> = HashMap::new();
        let mut faces = Vec::new();
        for f in &s.faces {
            let (a, b, c) = (f[0], f[1], f[2]);
            let mut mid = |p: u32, q: u32| {
                *mids.entry((p.min(q), p.max(q))).or_insert_with(|| {
                    let m = (s.positions[p as usize] + s.positions[q as usize]) * 0.5;
                    s.positions.push(m);
                    s.positions.len() as u32 - 1
                })
            };
            let (ab, bc, ca) = (mid(a, b), mid(b, c), mid(c, a));
            faces.extend([
                vec![a, ab, ca],
                vec![ab, b, bc],
                vec![ca, bc, c],
                vec![ab, bc, ca],
            ]);
        }
        s.faces = faces.into();
    }
    for p in &mut s.positions {
        *p = p.normalize();
    }
    s
}

/// The lower half of `sphere(3)`: an open bowl whose inside (the back of
/// its faces) shows from above.
fn bowl() -> PolygonSoup {
    let mut s = sphere(3);
    let positions = s.positions.clone();
    s.faces
        .retain(|f| f.iter().map(|&i| positions[i as usize].z).sum::<f64>() < 0.0);
    s
}

fn sized(width: u32, height: u32) -> MeshView {
    MeshView {
        width,
        height,
        ..MeshView::default()
    }
}

fn named(name: &str) -> MeshView {
    let (direction, up) = view_direction(name).expect("a known view name");
    MeshView {
        direction,
        up,
        ..MeshView::default()
    }
}

fn png(s: &PolygonSoup, view: &MeshView) -> Pixmap {
    let bytes = render_png(s, view).expect("the mesh renders");
    Pixmap::decode_png(&bytes).expect("the PNG decodes")
}

/// The colour at a pixel (the pictures here are opaque).
fn rgb(pm: &Pixmap, x: u32, y: u32) -> [u8; 3] {
    let c = pm.pixel(x, y).expect("inside the image").demultiply();
    [c.red(), c.green(), c.blue()]
}

fn is_background(c: [u8; 3]) -> bool {
    c == [255, 255, 255]
}

/// Mean brightness (0..765) of the 5×5 pixels around `p`.
fn brightness(pm: &Pixmap, p: DVec2) -> f64 {
    let (cx, cy) = (p.x.round() as i64, p.y.round() as i64);
    let mut sum = 0.0;
    for dy in -2..=2 {
        for dx in -2..=2 {
            let c = rgb(pm, (cx + dx) as u32, (cy + dy) as u32);
            sum += c.iter().map(|&v| v as f64).sum::<f64>();
        }
    }
    sum / 25.0
}

/// The bounding box (min, max corners, inclusive) of non-background pixels.
fn ink_box(pm: &Pixmap) -> (DVec2, DVec2) {
    let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    for y in 0..pm.height() {
        for x in 0..pm.width() {
            if !is_background(rgb(pm, x, y)) {
                let p = DVec2::new(x as f64, y as f64);
                lo = lo.min(p);
                hi = hi.max(p);
            }
        }
    }
    (lo, hi)
}

/// The pixel centre of a cube face in `view`.
fn face_centre(view: &MeshView, s: &PolygonSoup, face: usize) -> DVec2 {
    let px = project(view, s);
    CUBE_FACES[face]
        .iter()
        .map(|&i| px[i as usize])
        .sum::<DVec2>()
        / 4.0
}

fn render_error(s: &PolygonSoup, view: &MeshView) -> String {
    render_png(s, view).expect_err("the render fails").message
}

#[test]
fn png_has_the_requested_size() {
    for (w, h) in [(800, 800), (320, 200), (97, 311)] {
        let pm = png(&cube(), &sized(w, h));
        assert_eq!((pm.width(), pm.height()), (w, h));
    }
}

#[test]
fn corners_show_the_background() {
    let view = MeshView {
        background: Rgba(10, 200, 30, 255),
        ..sized(300, 200)
    };
    let pm = png(&sphere(2), &view);
    for (x, y) in [(0, 0), (299, 0), (0, 199), (299, 199)] {
        assert_eq!(rgb(&pm, x, y), [10, 200, 30], "corner ({x}, {y})");
    }
}

#[test]
fn projection_fills_the_fitted_area_and_is_centred() {
    for (w, h) in [(400, 400), (600, 300), (300, 600)] {
        let view = sized(w, h);
        let px = project(&view, &sphere(2));
        let lo = px.iter().fold(DVec2::INFINITY, |a, &p| a.min(p));
        let hi = px.iter().fold(DVec2::NEG_INFINITY, |a, &p| a.max(p));
        let mid = (lo + hi) * 0.5;
        assert!((mid - DVec2::new(w as f64, h as f64) * 0.5).length() < 1e-9);
        let margin = 0.04 * w.min(h) as f64;
        let avail = DVec2::new(w as f64, h as f64) - 2.0 * margin;
        let ext = hi - lo;
        assert!(ext.x <= avail.x + 1e-9 && ext.y <= avail.y + 1e-9);
        let fill = (ext.x / avail.x).max(ext.y / avail.y);
        assert!((fill - 1.0).abs() < 1e-9, "{w}x{h}: fills {fill}");
    }
}

#[test]
fn shape_pixels_are_centred_and_fill_the_fitted_area() {
    for (w, h) in [(400, 400), (500, 260)] {
        let pm = png(&sphere(3), &sized(w, h));
        let (lo, hi) = ink_box(&pm);
        let mid = (lo + hi + DVec2::ONE) * 0.5;
        let centre = DVec2::new(w as f64, h as f64) * 0.5;
        assert!((mid - centre).abs().max_element() < 2.0, "{w}x{h}: {mid}");
        // The sphere's outline is round: it spans the smaller available side.
        let avail = w.min(h) as f64 * (1.0 - 2.0 * 0.04);
        let ext = hi - lo + DVec2::ONE;
        assert!((ext.max_element() - avail).abs() < 5.0, "{w}x{h}: {ext}");
        assert!((ext.x - ext.y).abs() < 4.0, "{w}x{h}: round, {ext}");
        // Inside the outline there are no holes.
        for y in (lo.y as u32 + 20)..(hi.y as u32 - 20) {
            let x = (lo.x + hi.x) as u32 / 2;
            assert!(!is_background(rgb(&pm, x, y)), "hole at ({x}, {y})");
        }
    }
}

#[test]
fn a_face_towards_the_light_is_brighter_than_one_facing_away() {
    let view = MeshView::default();
    let s = cube();
    let pm = png(&s, &view);
    let light = light_direction(&view);
    let dir = view.direction.normalize();
    // The faces seen from the default view, with their brightness.
    let mut seen: Vec<(f64, f64)> = (0..6)
        .filter(|&f| CUBE_NORMALS[f].dot(dir) < -0.1)
        .map(|f| {
            (
                CUBE_NORMALS[f].dot(light),
                brightness(&pm, face_centre(&view, &s, f)),
            )
        })
        .collect();
    assert_eq!(seen.len(), 3, "the default view shows three cube faces");
    seen.sort_by(|a, b| a.0.total_cmp(&b.0));
    assert!(seen[0].0 < 0.0 && seen[2].0 > 0.5, "{seen:?}");
    assert!(seen[2].1 > seen[0].1 + 60.0, "lit vs unlit: {seen:?}");
    assert!(seen[2].1 > seen[1].1 && seen[1].1 > seen[0].1, "{seen:?}");
    // Ambient light: the face turned away from the light is not black.
    assert!(seen[0].1 > 150.0, "{seen:?}");
}

#[test]
fn the_top_of_the_cube_is_up_and_lit_in_the_default_view() {
    let view = MeshView::default();
    let s = cube();
    let px = project(&view, &s);
    // +z is up on screen: every top vertex is above its bottom vertex.
    for i in 0..4 {
        assert!(px[i + 4].y < px[i].y - 10.0);
    }
    let pm = png(&s, &view);
    let top = brightness(&pm, face_centre(&view, &s, 1));
    for f in [2, 5] {
        assert!(top > brightness(&pm, face_centre(&view, &s, f)));
    }
}

#[test]
fn back_faces_are_hidden() {
    let view = MeshView::default();
    let dir = view.direction.normalize();
    let full = cube();
    let mut front_only = cube();
    front_only.faces = (0..6)
        .filter(|&f| CUBE_NORMALS[f].dot(dir) < 0.0)
        .map(|f| CUBE_FACES[f].to_vec())
        .collect();
    let (a, b) = (png(&full, &view), png(&front_only, &view));
    for f in 0..6 {
        let c = face_centre(&view, &full, f).round();
        let (x, y) = (c.x as u32, c.y as u32);
        assert_eq!(rgb(&a, x, y), rgb(&b, x, y), "face {f}'s centre");
    }
}

#[test]
fn a_face_seen_from_behind_has_another_tint() {
    // One square in the xz plane, facing -y (towards the front view's eye).
    let square = soup(
        vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 1.0),
            DVec3::new(0.0, 0.0, 1.0),
        ],
        vec![vec![0, 1, 2, 3]],
    );
    let front = png(&square, &named("front"));
    let back = png(&square, &named("back"));
    let (f, b) = (rgb(&front, 400, 400), rgb(&back, 400, 400));
    assert!(!is_background(f) && !is_background(b));
    assert_ne!(f, b);
    // Front faces are a warm clay, back faces a cool blue-grey.
    assert!(f[0] > f[2], "{f:?}");
    assert!(b[2] > b[0], "{b:?}");
}

#[test]
fn degenerate_faces_are_skipped() {
    let mut s = cube();
    s.positions.push(DVec3::new(0.5, 0.5, 0.5));
    s.faces.push(vec![0, 0, 1]); // repeated vertex
    s.faces.push(vec![0, 8, 7]); // collinear along the diagonal
    s.faces.push(vec![3, 3, 3, 3]); // a point
    let with = png(&s, &MeshView::default());
    let without = png(&cube(), &MeshView::default());
    assert_eq!(with.data(), without.data());
    assert_eq!(
        render_svg(&s, &MeshView::default())
            .matches("<polygon")
            .count(),
        6
    );
}

#[test]
fn svg_has_one_polygon_per_face() {
    for s in [cube(), octahedron(), sphere(2)] {
        let doc = render_svg(&s, &MeshView::default());
        assert!(doc.starts_with("<svg"), "{}", &doc[..40]);
        assert_eq!(doc.matches("<polygon").count(), s.faces.len());
        assert!(doc.contains("width=\"800\"") && doc.contains("height=\"800\""));
    }
}

#[test]
fn svg_coordinates_have_at_most_two_decimals() {
    let doc = render_svg(&sphere(2), &sized(333, 217));
    let mut numbers = 0;
    for part in doc.split("points=\"").skip(1) {
        let pts = &part[..part.find('"').expect("a closed attribute")];
        for n in pts.split([' ', ',']) {
            let decimals = n.split_once('.').map_or(0, |(_, d)| d.len());
            assert!(decimals <= 2, "{n}");
            assert!(n.parse::<f64>().is_ok(), "{n}");
            numbers += 1;
        }
    }
    assert_eq!(numbers, 2 * 3 * sphere(2).faces.len());
}

#[test]
fn svg_fills_match_the_png_shades() {
    let view = MeshView::default();
    let s = cube();
    let doc = render_svg(&s, &view);
    let pm = png(&s, &view);
    for f in [1, 2, 5] {
        let c = face_centre(&view, &s, f).round();
        let [r, g, b] = rgb(&pm, c.x as u32, c.y as u32);
        let fill = format!("fill=\"{}\"", Rgba(r, g, b, 255).hex());
        assert!(doc.contains(&fill), "face {f}: {fill} missing");
    }
}

#[test]
fn view_names_give_unit_directions_and_ups() {
    for name in ["front", "back", "left", "right", "top", "bottom", "iso"] {
        let (d, up) = view_direction(name).expect(name);
        assert!((d.length() - 1.0).abs() < 1e-12, "{name}");
        assert!(
            d.cross(up).length() > 0.5,
            "{name}: up is not along the view"
        );
    }
    assert_eq!(view_direction("front").map(|v| v.0), Some(DVec3::Y));
    assert_eq!(view_direction("top"), Some((DVec3::NEG_Z, DVec3::Y)));
    assert_eq!(view_direction("iso"), {
        let v = MeshView::default();
        Some((v.direction, v.up))
    });
    assert_eq!(view_direction("sideways"), None);
}

#[test]
fn top_view_of_a_cube_is_an_axis_aligned_square() {
    let view = named("top");
    let px = project(&view, &cube());
    // The bottom and top vertex of each column land on the same pixel.
    for i in 0..4 {
        assert!((px[i] - px[i + 4]).length() < 1e-9);
    }
    let (a, b, c, d) = (px[0], px[1], px[3], px[2]); // (0,0) (1,0) (1,1) (0,1)
    assert!((a.y - b.y).abs() < 1e-9 && (c.y - d.y).abs() < 1e-9);
    assert!((a.x - d.x).abs() < 1e-9 && (b.x - c.x).abs() < 1e-9);
    assert!(((b.x - a.x) - (a.y - d.y)).abs() < 1e-9, "square");
    // +x to the right, +y up on screen (not mirrored).
    assert!(b.x > a.x + 100.0 && d.y < a.y - 100.0);
    let pm = png(&cube(), &view);
    let (lo, hi) = ink_box(&pm);
    let ext = hi - lo + DVec2::ONE;
    assert!((ext.x - ext.y).abs() <= 1.0, "{ext}");
}

#[test]
fn side_views_are_upright_and_not_mirrored() {
    let s = cube();
    // (view, the world axis to the right on screen)
    for (name, right) in [
        ("front", DVec3::X),
        ("back", DVec3::NEG_X),
        ("left", DVec3::NEG_Y),
        ("right", DVec3::Y),
    ] {
        let px = project(&named(name), &s);
        let screen = |i: usize| px[i];
        // Vertex 0 is the origin; 4 is +z, so it is above.
        assert!(screen(4).y < screen(0).y - 100.0, "{name}: +z is up");
        let along = |i: usize| s.positions[i].dot(right);
        let (p, q) = (0, if right.x != 0.0 { 1 } else { 2 });
        assert_eq!(
            screen(q).x > screen(p).x,
            along(q) > along(p),
            "{name}: {right} is to the right"
        );
    }
}

#[test]
fn errors_name_the_problem() {
    let empty = soup(vec![DVec3::ZERO], vec![]);
    assert_eq!(
        render_error(&empty, &MeshView::default()),
        "nothing to draw: the mesh has no faces"
    );
    let mut nan = cube();
    nan.positions[3].y = f64::NAN;
    let m = render_error(&nan, &MeshView::default());
    assert!(m.contains("vertex 3") && m.contains("non-finite"), "{m}");
    let mut inf = cube();
    inf.positions[6].z = f64::INFINITY;
    assert!(render_error(&inf, &MeshView::default()).contains("vertex 6"));
    let mut bad_index = cube();
    bad_index.faces.push(vec![0, 1, 42]);
    let m = render_error(&bad_index, &MeshView::default());
    assert!(m.contains("face 6") && m.contains("42"), "{m}");
    for (w, h) in [(0, 10), (10, 0), (20_001, 10), (10, 20_001)] {
        let m = render_error(&cube(), &sized(w, h));
        assert!(
            m.contains(&format!("{w}x{h}")) && m.contains("20000"),
            "{m}"
        );
    }
    let zero_dir = MeshView {
        direction: DVec3::ZERO,
        ..MeshView::default()
    };
    assert!(render_error(&cube(), &zero_dir).contains("direction"));
}

#[test]
fn wireframe_darkens_the_edges_and_can_be_turned_off() {
    let view = MeshView::default();
    let plain = MeshView {
        wireframe: false,
        ..MeshView::default()
    };
    let s = cube();
    let (with, without) = (png(&s, &view), png(&s, &plain));
    // The middle of the edge between the top and the front face.
    let px = project(&view, &s);
    let m = ((px[4] + px[5]) * 0.5).round();
    let (e, p) = (
        rgb(&with, m.x as u32, m.y as u32),
        rgb(&without, m.x as u32, m.y as u32),
    );
    let sum = |c: [u8; 3]| c.iter().map(|&v| v as u32).sum::<u32>();
    assert!(sum(e) + 60 < sum(p), "edge {e:?} vs plain {p:?}");
    assert!(render_svg(&s, &plain).contains("stroke-width=\"0.7\""));
}

#[test]
fn a_mesh_is_a_scene_of_outlined_polygons_back_to_front() {
    let s = sphere(1);
    let view = MeshView::default();
    let sc = scene(&s, &view).expect("the mesh draws");
    assert_eq!(
        (sc.width, sc.height, sc.background),
        (800, 800, view.background)
    );
    assert_eq!(sc.items.len(), s.faces.len());
    let px = project(&view, &s);
    let dir = view.direction.normalize();
    // The pixel outline of each face, and its depth, to find the items.
    let faces: Vec<(Vec<DVec2>, f64)> = s
        .faces
        .iter()
        .map(|f| {
            let pts = f.iter().map(|&i| px[i as usize]).collect();
            let depth = f
                .iter()
                .map(|&i| s.positions[i as usize].dot(dir))
                .sum::<f64>()
                / 3.0;
            (pts, depth)
        })
        .collect();
    let mut depths = Vec::new();
    for item in &sc.items {
        let Item::Polygon {
            points,
            color,
            outline,
        } = item
        else {
            panic!("not a polygon: {item:?}");
        };
        let (_, depth) = faces
            .iter()
            .find(|(pts, _)| pts == points)
            .expect("every polygon is a projected face");
        depths.push(*depth);
        let o = outline.expect("a wireframe outline");
        assert_ne!(o.color, *color, "the wireframe is darker than the face");
        assert!(o.width > 0.0);
    }
    assert!(
        depths.windows(2).all(|d| d[0] >= d[1]),
        "back to front: {depths:?}"
    );
    // Without the wireframe, each face is outlined in its own colour.
    let plain = MeshView {
        wireframe: false,
        ..MeshView::default()
    };
    for item in scene(&s, &plain).expect("draws").items {
        let Item::Polygon { color, outline, .. } = item else {
            panic!("not a polygon");
        };
        assert_eq!(outline.map(|o| o.color), Some(color));
    }
    // The PNG is the z-buffer's picture of the same polygons, fanned.
    let (scene3, polygons, back) = subgram::render::mesh::scene3(&s, &view);
    assert_eq!(scene3.triangle_count(), s.faces.len());
    let opts = subgram::render::mesh::raster_options(&s, &view, polygons, back).expect("a camera");
    assert_eq!(
        render_png(&s, &view).expect("renders"),
        subgram::render::raster::render_png(&scene3, &opts).expect("renders")
    );
    let empty = soup(vec![DVec3::ZERO], vec![]);
    assert!(scene(&empty, &view).is_err());
}

/// The pictures a person looked at, against the stored ones in
/// `tests/golden/mesh/` (240×240; `UPDATE_GOLDEN=1` rewrites them).
#[test]
fn example_pictures() {
    let small = |view: MeshView| MeshView {
        width: 240,
        height: 240,
        ..view
    };
    let pictures = [
        ("cube-iso", cube(), MeshView::default()),
        ("cube-top", cube(), named("top")),
        ("cube-front", cube(), named("front")),
        ("octahedron-iso", octahedron(), MeshView::default()),
        ("sphere-iso", sphere(3), MeshView::default()),
        ("sphere-top", sphere(3), named("top")),
        ("bowl-iso", bowl(), MeshView::default()),
        (
            "sphere-plain",
            sphere(4),
            MeshView {
                wireframe: false,
                ..MeshView::default()
            },
        ),
    ];
    let mut failures = Vec::new();
    for (name, s, view) in pictures {
        let view = small(view);
        let bytes = render_png(&s, &view).expect("renders");
        let path = format!("tests/golden/mesh/{name}.png");
        failures.extend(crate::golden::compare(&path, &bytes, crate::golden::Kind::Png).err());
    }
    crate::golden::assert_all(failures);
}
