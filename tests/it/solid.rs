//! The turtle's 3D geometry (`draw::solid`): tubes, generalized cylinders,
//! Bézier surfaces, spheres, discs, polygons, looks and limits. Expected
//! values are computed here, independently of the implementation: the
//! turtle's frames by the rotations of the manual (§5.2: `Left` about U,
//! `Up` about L, `RollR` about H) written out in [`Frame`], Bézier points
//! and tangents by de Casteljau's construction, counts from the manual's
//! definitions (§5.5: a sphere has `contour sides` slices and (sides + 1)
//! / 2 stacks; §8.1.3: 16 sides by default) and from the tessellation
//! that `draw/solid/` documents (a ring of `sides` points per joint, two
//! triangles per side and segment, a fan per cap).

use std::path::PathBuf;

use glam::{DVec3, Vec3};
use subgram::draw::solid::SolidOptions;
use subgram::model::view::LineStyle;
use subgram::model::Model;
use subgram::scene3::{Scene3, TriMesh};
use subgram::{LoadOptions, System};

use crate::support::{load_text, root, scratch};

/// The turtle as the manual moves it, written out for the tests.
#[derive(Clone, Copy, Debug)]
struct Frame {
    p: DVec3,
    h: DVec3,
    l: DVec3,
    u: DVec3,
}

impl Frame {
    /// lpfg's turtle at the start: at the origin, heading +y, left −x, up
    /// +z.
    fn start() -> Frame {
        Frame {
            p: DVec3::ZERO,
            h: DVec3::Y,
            l: DVec3::NEG_X,
            u: DVec3::Z,
        }
    }
    fn forward(&mut self, d: f64) {
        self.p += self.h * d;
    }
    /// `Left(a)`: H turns towards L about U.
    fn left(&mut self, a: f64) {
        let (s, c) = a.to_radians().sin_cos();
        (self.h, self.l) = (self.h * c + self.l * s, self.l * c - self.h * s);
    }
    /// `Up(a)`: H turns towards U about L.
    fn up(&mut self, a: f64) {
        let (s, c) = a.to_radians().sin_cos();
        (self.h, self.u) = (self.h * c + self.u * s, self.u * c - self.h * s);
    }
    /// `RollR(a)`: L turns towards U about H.
    fn roll_r(&mut self, a: f64) {
        let (s, c) = a.to_radians().sin_cos();
        (self.l, self.u) = (self.l * c + self.u * s, self.u * c - self.l * s);
    }
}

fn cylinders(sides: u32, capped: bool) -> Model {
    Model {
        line_style: LineStyle::Cylinder,
        contour_sides: sides,
        capped_cylinders: capped,
        ..Model::default()
    }
}

/// The 3D geometry of a program given as text, drawn with `model`'s
/// settings.
fn solid_of(src: &str, model: Model) -> Scene3 {
    let mut c = load_text(src);
    c.set_model(model);
    let mut run = c.run(Default::default()).unwrap_or_else(|e| panic!("{e}"));
    run.solid(&SolidOptions::default())
        .unwrap_or_else(|e| panic!("{e}"))
}

fn models(name: &str) -> PathBuf {
    root().join("tests/data/models").join(name)
}

/// A program of a model folder in tests/data/models, loaded with the
/// folder's files, and its geometry.
fn model_solid(path: PathBuf) -> (subgram::Curve, Scene3) {
    let c = match subgram::load(&path, &LoadOptions::default()) {
        Ok(System::Curve(c)) => c,
        Ok(_) => panic!("{} is not an L-system", path.display()),
        Err(e) => panic!("{} does not load:\n{e}", path.display()),
    };
    let scene = c
        .solid(Default::default(), &SolidOptions::default())
        .unwrap_or_else(|e| panic!("{e}"));
    (c, scene)
}

fn only_mesh(s: &Scene3) -> &TriMesh {
    assert_eq!(s.meshes.len(), 1, "one look, one mesh");
    &s.meshes[0]
}

fn d(v: Vec3) -> DVec3 {
    v.as_dvec3()
}

/// Every triangle's face normal agrees with the mean of its vertices'
/// normals: the winding faces the side the normals give. (Each vertex's
/// normal alone may lean past 90 degrees where a coarse section turns
/// sharply.)
fn assert_wound_with_normals(m: &TriMesh) {
    assert_eq!(m.normals.len(), m.positions.len());
    for t in &m.triangles {
        let [a, b, c] = t.map(|i| d(m.positions[i as usize]));
        let face = (b - a).cross(c - a);
        let mean: DVec3 = t.iter().map(|&i| d(m.normals[i as usize])).sum();
        assert!(
            face.dot(mean) > 0.0,
            "triangle {t:?} is wound against its normals"
        );
    }
}

/// The index of the vertex nearest to `p`, and its distance.
fn nearest(m: &TriMesh, p: DVec3) -> (usize, f64) {
    m.positions
        .iter()
        .enumerate()
        .map(|(i, q)| (i, d(*q).distance(p)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .expect("a vertex")
}

#[test]
fn tube_rings_lie_on_the_turtles_frames_and_are_shared_at_joints() {
    let scene = solid_of(
        "derivation length: 0;\nAxiom: SetWidth(0.5) F(1) Left(30) F(2) Up(40) F(1.5);\n",
        cylinders(8, false),
    );
    let m = only_mesh(&scene);
    // Four rings (start, two joints, end) of 8 points; two triangles per
    // side and segment: the joints' rings are shared, so nothing cracks.
    assert_eq!(m.positions.len(), 4 * 8);
    assert_eq!(m.triangles.len(), 3 * 2 * 8);
    let mut f = Frame::start();
    let mut centres = vec![f.p];
    let h0 = f.h;
    f.forward(1.0);
    centres.push(f.p);
    f.left(30.0);
    let h1 = f.h;
    f.forward(2.0);
    centres.push(f.p);
    f.up(40.0);
    let h2 = f.h;
    f.forward(1.5);
    centres.push(f.p);
    // Each ring's plane: perpendicular to the heading at the ends, to the
    // bisector of the two headings at a joint.
    let planes = [h0, (h0 + h1).normalize(), (h1 + h2).normalize(), h2];
    for k in 0..4 {
        let ring = &m.positions[8 * k..8 * k + 8];
        let centre = ring.iter().map(|v| d(*v)).sum::<DVec3>() / 8.0;
        assert!(
            centre.distance(centres[k]) < 1e-5,
            "ring {k} centred at {centre}"
        );
        for (i, v) in ring.iter().enumerate() {
            let r = d(*v) - centres[k];
            // Radius: half the width.
            assert!((r.length() - 0.25).abs() < 1e-5, "ring {k} point {i}: {r}");
            assert!(
                r.dot(planes[k]).abs() < 1e-5,
                "ring {k} point {i} off its plane"
            );
            // Smooth normals: radial.
            let n = d(m.normals[8 * k + i]);
            assert!(n.distance(r / 0.25) < 1e-5, "ring {k} normal {i}: {n}");
        }
    }
    // The first ring starts on the turtle's up vector (lpfg's circle
    // starts at (0, 1) in left/up coordinates).
    assert!(d(m.positions[0]).distance(DVec3::Z * 0.25) < 1e-6);
    // Each triangle joins two consecutive rings.
    for t in &m.triangles {
        let rings: Vec<u32> = t.iter().map(|i| i / 8).collect();
        let (lo, hi) = (rings.iter().min().unwrap(), rings.iter().max().unwrap());
        assert_eq!(hi - lo, 1, "triangle {t:?} spans rings {rings:?}");
    }
    assert_wound_with_normals(m);
}

#[test]
fn a_roll_between_segments_does_not_twist_a_tube() {
    let scene = solid_of(
        "derivation length: 0;\nAxiom: SetWidth(0.5) F(1) RollR(90) F(1) RollL(30) F(1);\n",
        cylinders(8, false),
    );
    let m = only_mesh(&scene);
    assert_eq!(m.positions.len(), 4 * 8);
    // The path is straight: each ring is the one before moved by the
    // heading, point for point, whatever the turtle's roll.
    for k in 1..4 {
        for i in 0..8 {
            let (a, b) = (d(m.positions[8 * (k - 1) + i]), d(m.positions[8 * k + i]));
            assert!((b - a).distance(DVec3::Y) < 1e-6, "ring {k} point {i}");
        }
    }
}

#[test]
fn a_sharp_turn_a_move_and_a_colour_end_or_split_the_tube() {
    // Over 90 degrees: two tubes of two rings each.
    let s = solid_of(
        "derivation length: 0;\nAxiom: F(1) Left(120) F(1);\n",
        cylinders(8, false),
    );
    let m = only_mesh(&s);
    assert_eq!((m.positions.len(), m.triangles.len()), (4 * 8, 2 * 2 * 8));
    let mut f = Frame::start();
    f.forward(1.0);
    let (p1, h0) = (f.p, f.h);
    f.left(120.0);
    let h1 = f.h;
    // The first tube ends perpendicular to its heading, the second starts
    // perpendicular to its own.
    for (k, h) in [(1, h0), (2, h1)] {
        for v in &m.positions[8 * k..8 * k + 8] {
            assert!((d(*v) - p1).dot(h).abs() < 1e-6);
        }
    }
    // A move without drawing: two tubes.
    let s = solid_of(
        "derivation length: 0;\nAxiom: F(1) f(1) F(1);\n",
        cylinders(8, false),
    );
    let m = only_mesh(&s);
    assert_eq!((m.positions.len(), m.triangles.len()), (4 * 8, 2 * 2 * 8));
    // A new colour at a joint: the joint's ring in each mesh.
    let s = solid_of(
        "derivation length: 0;\nAxiom: F(1) IncColor() F(1);\n",
        cylinders(8, false),
    );
    assert_eq!(s.meshes.len(), 2);
    for m in &s.meshes {
        assert_eq!((m.positions.len(), m.triangles.len()), (2 * 8, 2 * 8));
    }
    let shared: Vec<Vec3> = s.meshes[0].positions[8..].to_vec();
    assert_eq!(shared, s.meshes[1].positions[..8].to_vec());
}

#[test]
fn tube_counts_with_branches_and_caps() {
    let src = "derivation length: 0;\nAxiom: F(1) SB() Left(45) F(1) EB() F(1);\n";
    // The main axis is one tube of three rings through the branch point;
    // the branch is a tube of two rings of its own.
    let s = solid_of(src, cylinders(8, false));
    let m = only_mesh(&s);
    assert_eq!((m.positions.len(), m.triangles.len()), (5 * 8, 3 * 2 * 8));
    // Caps: a fan of 8 triangles around a centre, on 9 vertices of its
    // own, at each of the four ends.
    let s = solid_of(src, cylinders(8, true));
    let m = only_mesh(&s);
    assert_eq!(
        (m.positions.len(), m.triangles.len()),
        (5 * 8 + 4 * 9, 3 * 2 * 8 + 4 * 8)
    );
    assert_wound_with_normals(m);
    // N segments with lpfg's default of 16 sides (the model sets none):
    // N + 1 rings, 2 × 16 × N triangles, and two caps.
    let n = 10;
    let src = format!(
        "derivation length: 0;\nAxiom: {};\n",
        vec!["F(1)"; n].join(" ")
    );
    let s = solid_of(&src, cylinders(0, true));
    let m = only_mesh(&s);
    assert_eq!(
        (m.positions.len(), m.triangles.len()),
        ((n + 1) * 16 + 2 * 17, 2 * 16 * n + 2 * 16)
    );
}

#[test]
fn lines_in_pixel_style_make_no_triangles_and_spheres_have_the_manuals_sections() {
    // No view file: pixel lines (nothing), lpfg's 16 contour sides.
    let s = solid_of(
        "derivation length: 0;\nAxiom: F(1) Sphere(2) f(5) SetWidth(3) Sphere0();\n",
        Model::default(),
    );
    let m = only_mesh(&s);
    // 16 slices, (16 + 1) / 2 = 8 stacks: two poles and 7 rings of 16
    // points; 16 triangles at each pole and 2 × 16 per band between rings.
    let (v, t) = (2 + 7 * 16, 2 * 16 + 2 * 16 * 6);
    assert_eq!((m.positions.len(), m.triangles.len()), (2 * v, 2 * t));
    let centres = [DVec3::new(0.0, 1.0, 0.0), DVec3::new(0.0, 6.0, 0.0)];
    // `Sphere(2)`: radius 2; `Sphere0` with width 3: diameter 3.
    for (k, (c, r)) in centres.iter().zip([2.0, 1.5]).enumerate() {
        for i in 0..v {
            let p = d(m.positions[k * v + i]) - *c;
            assert!((p.length() - r).abs() < 1e-5, "sphere {k} point {i}");
            assert!(d(m.normals[k * v + i]).distance(p / r) < 1e-5);
        }
    }
    assert_wound_with_normals(m);
}

#[test]
fn discs_lie_in_the_hl_plane_or_face_the_viewer() {
    let s = solid_of(
        "derivation length: 0;\nAxiom: Up(90) Circle(1) f(3) CircleFront(0.5) f(3) SetWidth(0.2) CircleB(1);\n",
        cylinders(8, false),
    );
    let m = only_mesh(&s);
    // Two fans of 8 triangles on 9 vertices, a ring of 16 triangles on 16.
    assert_eq!(
        (m.positions.len(), m.triangles.len()),
        (9 + 9 + 16, 8 + 8 + 16)
    );
    let mut f = Frame::start();
    f.up(90.0);
    // `Circle(1)`: in the plane of H and L, its normal U.
    for i in 0..9 {
        let p = d(m.positions[i]) - f.p;
        assert!(p.dot(f.u).abs() < 1e-6);
        assert!(i == 0 || (p.length() - 1.0).abs() < 1e-6);
        assert!(d(m.normals[i]).distance(f.u) < 1e-6);
    }
    // `CircleFront(0.5)`: in the plane z = const, facing +z.
    f.forward(3.0);
    for i in 9..18 {
        let p = d(m.positions[i]) - f.p;
        assert!(p.z.abs() < 1e-6 && (i == 9 || (p.length() - 0.5).abs() < 1e-6));
        assert_eq!(m.normals[i], Vec3::Z);
    }
    // `CircleB(1)` with width 0.2: from radius 0.9 to 1.1.
    f.forward(3.0);
    let mut radii: Vec<f64> = (18..34)
        .map(|i| (d(m.positions[i]) - f.p).length())
        .collect();
    radii.sort_by(f64::total_cmp);
    assert!((radii[0] - 0.9).abs() < 1e-6 && (radii[7] - 0.9).abs() < 1e-6);
    assert!((radii[8] - 1.1).abs() < 1e-6 && (radii[15] - 1.1).abs() < 1e-6);
}

#[test]
fn a_concave_polygon_is_cut_into_n_minus_2_triangles_that_tile_it() {
    // An L-shaped hexagon of area 3, starting next to its reflex corner
    // (-1, 1): a fan from the first point would cover the notch.
    let pts = [(-1, 2), (-1, 1), (-2, 1), (-2, 0), (0, 0), (0, 2)];
    let body: String = pts
        .iter()
        .map(|(x, y)| format!("MoveTo({x}, {y}, 0) PP() "))
        .collect();
    let s = solid_of(
        &format!("derivation length: 0;\nAxiom: SP() {body}EP();\n"),
        Model::default(),
    );
    let m = only_mesh(&s);
    assert_eq!(m.triangles.len(), pts.len() - 2);
    let normal = d(m.normals[0]);
    let mut area = 0.0;
    for t in &m.triangles {
        let [a, b, c] = t.map(|i| d(m.positions[i as usize]));
        let twice = (b - a).cross(c - a);
        // Every triangle turns the same way: none overlaps another.
        assert!(twice.dot(normal) > 0.0, "triangle {t:?} is flipped");
        area += twice.length() / 2.0;
    }
    // The shoelace area of the hexagon, by hand: 2 × 1 + 1 × 1.
    assert!((area - 3.0).abs() < 1e-9, "the triangles cover {area}");
    assert!(normal.distance(DVec3::Z) < 1e-9 || normal.distance(-DVec3::Z) < 1e-9);
}

/// The point of a cubic Bézier curve at `t` by de Casteljau's
/// construction, and its derivative (3 × the difference of the last two
/// intermediate points).
fn casteljau(pts: [DVec3; 4], t: f64) -> (DVec3, DVec3) {
    let lerp = |a: DVec3, b: DVec3| a + (b - a) * t;
    let a = [
        lerp(pts[0], pts[1]),
        lerp(pts[1], pts[2]),
        lerp(pts[2], pts[3]),
    ];
    let b = [lerp(a[0], a[1]), lerp(a[1], a[2])];
    (lerp(b[0], b[1]), (b[1] - b[0]) * 3.0)
}

/// A patch's point at (u along a row, v down the rows) and its tangents.
fn patch_point(net: &[[DVec3; 4]; 4], u: f64, v: f64) -> (DVec3, DVec3, DVec3) {
    let rows: Vec<(DVec3, DVec3)> = net.iter().map(|r| casteljau(*r, u)).collect();
    let (p, pv) = casteljau([rows[0].0, rows[1].0, rows[2].0, rows[3].0], v);
    let (pu, _) = casteljau([rows[0].1, rows[1].1, rows[2].1, rows[3].1], v);
    (p, pu, pv)
}

#[test]
fn bezier_patches_are_tessellated_on_the_turtles_frame() {
    let (c, scene) = model_solid(models("solid/leaf.l"));
    let m = only_mesh(&scene);
    let model = c.model();
    let surface = &model.surfaces[0];
    // `surface: leaf.s 2 4 2`: each patch cut 4 × 2, so 5 × 3 points and
    // 2 × 4 × 2 triangles per patch.
    assert_eq!(surface.patches.len(), 2);
    assert_eq!((m.positions.len(), m.triangles.len()), (2 * 15, 2 * 16));
    // The turtle of `f(2) RollR(30) Left(20) Up(50)`.
    let mut f = Frame::start();
    f.forward(2.0);
    f.roll_r(30.0);
    f.left(20.0);
    f.up(50.0);
    // `Surface(leaf, 1.5)` with the view file's scale 2 and `SIZE: 4`:
    // 1.5 × 2 / 4. The file's heading is +y and its up +z, so its left
    // (up × heading) is −x; the contact point is the origin. Its heading
    // goes on the turtle's, its left on the turtle's, its up on the
    // turtle's.
    let k = 1.5 * 2.0 / 4.0;
    let linear = |q: DVec3| (f.h * q.y - f.l * q.x + f.u * q.z) * k;
    let place = |q: DVec3| f.p + linear(q);
    for patch in &surface.patches {
        let net: [[DVec3; 4]; 4] = patch.points.map(|r| r.map(DVec3::from_array));
        // s (`sdiv`, 4) down the rows of control points, t (`tdiv`, 2)
        // along a row, as lpfg's own OBJ output of this surface has them
        // (see `lpfg_draws_the_same_cylinder_and_surface`): every grid
        // point is a vertex.
        for i in 0..=4 {
            for j in 0..=2 {
                let (p, _, _) = patch_point(&net, j as f64 / 2.0, i as f64 / 4.0);
                let (_, dist) = nearest(m, place(p));
                assert!(
                    dist < 1e-5,
                    "patch {} at s {i}/4, t {j}/2: off by {dist}",
                    patch.name
                );
            }
        }
        for (u, v) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0), (0.5, 0.5)] {
            let (p, pu, pv) = patch_point(&net, u, v);
            let (i, dist) = nearest(m, place(p));
            assert!(
                dist < 1e-5,
                "patch {} at ({u}, {v}): off by {dist}",
                patch.name
            );
            if (u, v) == (0.5, 0.5) {
                // The normal is perpendicular to both placed tangents.
                let n = d(m.normals[i]);
                assert!((n.length() - 1.0).abs() < 1e-5);
                for t in [linear(pu), linear(pv)] {
                    assert!(n.dot(t.normalize()).abs() < 1e-5, "normal {n} against {t}");
                }
            }
        }
    }
}

#[test]
fn a_generalized_cylinder_keeps_its_section_on_a_twisting_path() {
    let (c, scene) = model_solid(models("solid/gc.l"));
    let m = only_mesh(&scene);
    let model = c.model();
    let contour = &model.contours[1];
    assert_eq!(contour.name, "section");
    // `samples: 9`: 9 points, the last the first again, so 8 a ring; five
    // rings (`StartGC` and four `F`), four strips of 16 triangles, and a
    // cap of 8 triangles on 9 vertices at each end (`capped cylinders: on`).
    assert_eq!(contour.vertices.len(), 9);
    assert_eq!(
        (m.positions.len(), m.triangles.len()),
        (5 * 8 + 2 * 9, 4 * 16 + 2 * 8)
    );
    // The rings, computed here: at the turtle after each `F`, a contour
    // point (x, y) at x × 0.8 / 2 along left and y × 0.4 / 2 along up
    // (`ScaleContour(0.8, 0.4)`).
    let mut f = Frame::start();
    let mut frames = vec![f];
    for _ in 0..4 {
        f.forward(1.0);
        frames.push(f);
        f.roll_r(40.0);
        f.left(15.0);
    }
    // Each expected point is a vertex: the section's shape in every frame.
    let mut which = std::collections::HashMap::new();
    for (k, f) in frames.iter().enumerate() {
        for (i, v) in contour.vertices[..8].iter().enumerate() {
            let p = f.p + f.l * (v[0] as f64 * 0.4) + f.u * (v[1] as f64 * 0.2);
            let (at, dist) = nearest(m, p);
            assert!(dist < 1e-5, "ring {k} point {i} off by {dist}");
            which.insert(at, (k, i));
        }
    }
    // No flip: every strip triangle joins points of consecutive rings
    // whose places on the contour are next to each other.
    let mut strips = 0;
    for t in &m.triangles {
        let Some(ks) = t
            .iter()
            .map(|v| which.get(&(*v as usize)).copied())
            .collect::<Option<Vec<_>>>()
        else {
            continue;
        };
        let rings: Vec<usize> = ks.iter().map(|x| x.0).collect();
        if rings.iter().min() == rings.iter().max() {
            continue;
        }
        strips += 1;
        assert_eq!(rings.iter().max().unwrap() - rings.iter().min().unwrap(), 1);
        for a in &ks {
            for b in &ks {
                let gap = (a.1 + 8 - b.1) % 8;
                assert!(gap <= 1 || gap == 7, "triangle {t:?} joins {ks:?}");
            }
        }
    }
    assert_eq!(strips, 4 * 16);
    // The contour runs counter-clockwise, lpfg's circle clockwise: either
    // way the triangles face where the normals point.
    assert_wound_with_normals(m);
}

#[test]
fn colours_choose_materials_or_map_entries() {
    let (_, s) = model_solid(models("solid/looks.l"));
    // `SetColor(3)`, `IncColor()`, `SetColor(3)`: two looks, in the order
    // first used; the record of material 3 in material.mat (written by
    // the tests' README) is transparency 51, ambient (10, 20, 30), diffuse
    // (200, 100, 50), emission (1, 2, 3), specular (255, 128, 0),
    // shininess 64.
    assert_eq!(s.looks.len(), 2);
    let f = |c: [u8; 3]| c.map(|b| b as f32 / 255.0);
    let l = &s.looks[0];
    assert_eq!((l.name.as_str(), l.index), ("material3", 3));
    assert_eq!(l.ambient, f([10, 20, 30]));
    assert_eq!(l.diffuse, f([200, 100, 50]));
    assert_eq!(l.emission, f([1, 2, 3]));
    assert_eq!(l.specular, f([255, 128, 0]));
    assert_eq!(l.shininess, 64.0);
    assert_eq!(l.opacity, 1.0 - 51.0 / 255.0);
    assert_eq!(s.looks[1].diffuse, f([0, 255, 0]));
    // The sphere and the second disc in material 3; the view file's 6
    // sides: a sphere of 6 slices and 3 stacks (2 × 6 × 2 triangles),
    // discs of 6.
    assert_eq!(s.meshes[0].triangles.len(), 24 + 6);
    assert_eq!(s.meshes[1].triangles.len(), 6);
    // A colour map: entry 3 of colours.map is (3, 21, 252), entry 4
    // (4, 28, 251) (written as (i, 7i mod 256, 255 − i)).
    let (_, s) = model_solid(models("solid-map/looks.l"));
    assert_eq!(s.looks.len(), 2);
    let l = &s.looks[0];
    assert_eq!(
        (l.name.as_str(), l.ambient, l.diffuse),
        ("colour3", f([3, 21, 252]), f([3, 21, 252]))
    );
    assert_eq!(l.specular, [0.0; 3]);
    assert_eq!(s.looks[1].diffuse, f([4, 28, 251]));
}

#[test]
fn a_runaway_word_stops_at_the_limit_and_huge_widths_are_refused() {
    let c = load_text(
        "module A;\nderivation length: 12;\nAxiom: A;\nA -> A A\ninterpretation:\nA -> Sphere(1) f(1)\n",
    );
    let mut run = c.run(Default::default()).unwrap();
    let e = run
        .solid(&SolidOptions {
            max_triangles: 10_000,
            ..Default::default()
        })
        .expect_err("4096 spheres of 224 triangles are over 10,000")
        .to_string();
    assert!(e.contains("past its limit of 10000 triangles"), "{e}");
    assert!(e.contains("`Sphere`"), "{e}");
    let mut c = load_text("derivation length: 0;\nAxiom: SetWidth(3e38) F(1);\n");
    c.set_model(cylinders(8, false));
    let mut run = c.run(Default::default()).unwrap();
    let e = run.solid(&SolidOptions::default()).unwrap_err().to_string();
    assert!(e.contains("infinite coordinate"), "{e}");
}

#[test]
fn a_generalized_cylinder_goes_on_into_branches_and_from_pointgc() {
    // Contour 0, lpfg's circle, sampled at 8 + 1 points: 8 a ring.
    let gc = |body: &str| {
        solid_of(
            &format!("derivation length: 0;\nAxiom: {body};\n"),
            cylinders(8, false),
        )
    };
    // The branch draws from the cylinder's section where it started, and
    // after `EB` the cylinder goes on from there too (lpfg): four rings
    // (start, branch point, the branch's end, the axis' end), three
    // strips.
    let s = gc("StartGC() F(1) SB() Left(30) F(1) EB() F(1) EndGC()");
    let m = only_mesh(&s);
    assert_eq!((m.positions.len(), m.triangles.len()), (4 * 8, 3 * 16));
    // `PointGC` moves the section without drawing: the strip after it
    // starts at the turtle there.
    let s = gc("StartGC() F(1) f(1) PointGC() F(1) EndGC()");
    let m = only_mesh(&s);
    assert_eq!(m.triangles.len(), 2 * 16);
    let ys: Vec<f32> = m
        .positions
        .iter()
        .map(|p| (p.y * 1e4).round() / 1e4)
        .collect();
    for y in [0.0, 1.0, 2.0, 3.0] {
        assert_eq!(
            ys.iter().filter(|v| **v == y).count(),
            8,
            "a ring at y = {y}"
        );
    }
    // lpfg draws no circle or sphere of a radius that is not positive.
    let s = gc("Circle(0) Sphere(-1) CircleB(0) SetWidth(0) Sphere0()");
    assert_eq!(s.triangle_count(), 0);
    // Outside `cylinder` style, lpfg ignores generalized cylinders.
    let s = solid_of(
        "derivation length: 0;\nAxiom: StartGC() F(1) EndGC();\n",
        Model::default(),
    );
    assert_eq!(s.triangle_count(), 0);
}

#[test]
fn tubes_follow_the_path_that_tropism_bends() {
    let path = models("solid-tropism");
    let c = match subgram::load(&path, &LoadOptions::default()) {
        Ok(System::Curve(c)) => c,
        _ => panic!("loads"),
    };
    let mut run = c.run(Default::default()).unwrap();
    let s = run.solid(&SolidOptions::default()).unwrap();
    let events = run.events().unwrap();
    let mut points: Vec<DVec3> = Vec::new();
    for e in &events {
        for (a, b) in e.segments() {
            points.extend([a, b]);
        }
    }
    // The bend is real: the path leaves the y axis.
    assert!(points.iter().any(|p| p.x > 0.1), "{points:?}");
    let m = only_mesh(&s);
    // Six rings on the axis (five segments, through the branch point),
    // three on the branch.
    assert_eq!(m.positions.len(), 9 * 8);
    for ring in m.positions.chunks(8) {
        let centre = ring.iter().map(|v| d(*v)).sum::<DVec3>() / 8.0;
        let on = points.iter().any(|p| p.distance(centre) < 1e-5);
        assert!(on, "a ring centred at {centre}, off the turtle's path");
        for v in ring {
            assert!((d(*v).distance(centre) - 0.1).abs() < 1e-5);
        }
    }
}

/// The vertices and the number of triangles (a quad counted as two) of an
/// OBJ file that lpfg wrote.
fn lpfg_obj(path: PathBuf) -> (Vec<DVec3>, usize) {
    let text = std::fs::read_to_string(&path).unwrap();
    let mut v = Vec::new();
    let mut triangles = 0;
    for line in text.lines() {
        let w: Vec<&str> = line.split_whitespace().collect();
        match w.first() {
            Some(&"v") => v.push(DVec3::new(
                w[1].parse().unwrap(),
                w[2].parse().unwrap(),
                w[3].parse().unwrap(),
            )),
            Some(&"f") => triangles += w.len() - 3,
            _ => {}
        }
    }
    (v, triangles)
}

/// lpfg's own geometry of `gc.l` and `leaf.l`, written by lpfg (vlab
/// commit 9bf820d, under Xvfb: `lpfg -w 400 400 view.v section.con
/// material.mat leaf.s PROGRAM.l -out PROGRAM.obj`) into
/// tests/data/models/solid/lpfg/ with six significant digits: the same
/// points (lpfg shares the vertices that subgram repeats for caps and
/// between patches) and the same number of triangles.
#[test]
fn lpfg_draws_the_same_cylinder_and_surface() {
    for program in ["gc", "leaf"] {
        let (_, scene) = model_solid(models(&format!("solid/{program}.l")));
        let m = only_mesh(&scene);
        let (theirs, triangles) = lpfg_obj(models(&format!("solid/lpfg/{program}.obj")));
        assert_eq!(m.triangles.len(), triangles, "{program}");
        for p in &theirs {
            let (_, dist) = nearest(m, *p);
            assert!(
                dist < 1e-5,
                "{program}: lpfg's vertex {p} is {dist} from ours"
            );
        }
        for q in &m.positions {
            let dist = theirs
                .iter()
                .map(|p| p.distance(d(*q)))
                .fold(f64::MAX, f64::min);
            assert!(
                dist < 1e-5,
                "{program}: our vertex {q} is {dist} from lpfg's"
            );
        }
    }
}

#[test]
fn a_blended_contour_lies_between_its_two_and_a_missing_one_is_an_error() {
    let path = models("solid/missing-contour.l");
    let c = match subgram::load(&path, &LoadOptions::default()) {
        Ok(System::Curve(c)) => c,
        _ => panic!("loads"),
    };
    let mut run = c.run(Default::default()).unwrap();
    let e = run.solid(&SolidOptions::default()).unwrap_err().to_string();
    // The model has contours 0 (lpfg's circle) and 1 (`section`).
    assert!(
        e.contains("module 2 of the interpreted word, `CurrentContour`, names contour 5, but the model has contours 0 to 1"),
        "{e}"
    );
    // `BlendedContour(section, 0, 0.25)` is 3/4 of `section` (9 samples,
    // 8 a ring) and 1/4 of lpfg's circle sampled alike, point by point:
    // (sin, cos) of i/8 turns.
    let (c, s) = model_solid(models("solid/blend.l"));
    let m = only_mesh(&s);
    let model = c.model();
    let section = &model.contours[1];
    for (k, y) in [(0, 0.0), (1, 1.0)] {
        for i in 0..8 {
            let (sn, cs) = (std::f64::consts::TAU * i as f64 / 8.0).sin_cos();
            let v = section.vertices[i];
            let (x, z) = (
                0.75 * v[0] as f64 + 0.25 * sn,
                0.75 * v[1] as f64 + 0.25 * cs,
            );
            // `ScaleContour(2, 2)`: a contour unit is one unit; left is
            // −x, up +z.
            let p = DVec3::new(-x, y, z);
            let (_, dist) = nearest(m, p);
            assert!(dist < 1e-5, "ring {k} point {i} off by {dist}");
        }
    }
}

#[test]
fn negative_integer_parameters_are_numbers_not_nans() {
    // Manual 5.3: `SetColor(n)` with n < 1 is ignored, so the sphere keeps
    // colour 1. (A negative int in the word once read as a NaN.)
    let s = solid_of(
        "derivation length: 0;\nAxiom: SetColor(-1) Sphere(1);\n",
        Model::default(),
    );
    assert_eq!(s.looks[0].index, 1);
    let mut c = load_text("derivation length: 0;\nAxiom: CurrentContour(-1);\n");
    c.set_model(cylinders(8, false));
    let e = c
        .solid(Default::default(), &SolidOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("names contour -1, but the model has contours 0 to 0"),
        "{e}"
    );
}

#[test]
fn pixel_lines_become_tubes_only_when_asked_with_the_size_of_a_pixel() {
    let src = "derivation length: 0;\nAxiom: SetWidth(3) F(1) F(1);\n";
    let mut c = load_text(src);
    c.set_model(Model::default());
    let none = c
        .solid(Default::default(), &SolidOptions::default())
        .unwrap();
    assert_eq!(none.triangle_count(), 0);
    // 3 pixels at 0.01 units a pixel: radius 0.015; lpfg's 16 sides.
    let s = c
        .solid(
            Default::default(),
            &SolidOptions {
                pixel_tubes: Some(0.01),
                ..Default::default()
            },
        )
        .unwrap();
    let m = only_mesh(&s);
    assert_eq!((m.positions.len(), m.triangles.len()), (3 * 16, 2 * 2 * 16));
    for (k, ring) in m.positions.chunks(16).enumerate() {
        for v in ring {
            let r = d(*v) - DVec3::new(0.0, k as f64, 0.0);
            assert!((r.length() - 0.015).abs() < 1e-7 && r.y.abs() < 1e-7);
        }
    }
}

/// For a picture (`SolidOptions::picture_pixel`), a tube has just enough
/// sides that none is wider than 1.5 pixels: ⌈π·d/1.5⌉ for a diameter of
/// d pixels, at least 3 and at most the model's 16. A segment between two
/// rings of n points is 2n triangles.
#[test]
fn a_picture_gives_thin_tubes_fewer_sides() {
    for (width, sides) in [(1.0, 3), (1.2, 3), (3.0, 7), (10.0, 16)] {
        let mut c = load_text(&format!(
            "derivation length: 0;\nAxiom: SetWidth({width}) F(10);\n"
        ));
        c.set_model(cylinders(16, false));
        let mut run = c.run(Default::default()).unwrap();
        let picture = run
            .solid(&SolidOptions {
                picture_pixel: Some(1.0),
                ..Default::default()
            })
            .unwrap();
        assert_eq!(picture.triangle_count(), 2 * sides, "width {width} px");
        // An export keeps the model's sides.
        let export = run.solid(&SolidOptions::default()).unwrap();
        assert_eq!(export.triangle_count(), 2 * 16, "width {width}");
    }
}

/// For a picture, a tube less than a pixel across is its axis: one line
/// from the segment's start to its end, no triangle; an export keeps the
/// tube, and refuses a picture's geometry.
#[test]
fn a_picture_keeps_a_tube_under_a_pixel_as_its_axis() {
    let mut c = load_text("derivation length: 0;\nAxiom: SetWidth(0.9) F(10) Left(90) F(5);\n");
    c.set_model(cylinders(16, false));
    let mut run = c.run(Default::default()).unwrap();
    let picture = run
        .solid(&SolidOptions {
            picture_pixel: Some(1.0),
            ..Default::default()
        })
        .unwrap();
    assert_eq!(picture.triangle_count(), 0);
    let lines: Vec<subgram::scene3::Line> = picture
        .meshes
        .iter()
        .flat_map(|m| m.lines.clone())
        .collect();
    // The turtle starts at the origin heading along +y; Left(90) turns it
    // towards -x (lpfg's turtle, manual 5.1).
    let want = [
        [Vec3::ZERO, Vec3::new(0.0, 10.0, 0.0)],
        [Vec3::new(0.0, 10.0, 0.0), Vec3::new(-5.0, 10.0, 0.0)],
    ];
    assert_eq!(lines.len(), 2);
    for (got, want) in lines.iter().zip(want) {
        for (g, w) in [got.a, got.b].iter().zip(want) {
            assert!((*g - w).length() < 1e-5, "{got:?} against {want:?}");
        }
        // The tube's diameter, SetWidth's.
        assert!((got.width - 0.9).abs() < 1e-6, "{got:?}");
    }
    let export = run.solid(&SolidOptions::default()).unwrap();
    assert_eq!(export.line_count(), 0);
    assert_eq!(
        export.triangle_count(),
        2 * 2 * 16,
        "two segments of 16 sides"
    );
    let tmp = scratch("solid-lines");
    let dir = tmp.path();
    let err = subgram::export::write(&picture, &dir.join("p.obj")).unwrap_err();
    assert!(err.to_string().contains("lines"), "{err}");
    assert!(!dir.join("p.obj").exists());
}

/// A mesh's triangles as their corners' coordinates, sorted: the same
/// set of triangles whatever their order and numbering.
fn triangle_set(m: &TriMesh) -> Vec<[[u32; 3]; 3]> {
    let mut t: Vec<[[u32; 3]; 3]> = m
        .triangles
        .iter()
        .map(|tri| tri.map(|i| m.positions[i as usize].to_array().map(f32::to_bits)))
        .collect();
    t.sort_unstable();
    t
}

/// The geometry of a picture whose scale the walk finds
/// (`SolidOptions::fit_pixels`, one walk, tubes logged and made at the
/// end) is the geometry made knowing the scale beforehand (the extent of
/// the lines from a first walk): the same meshes in the same order, the
/// same lines, the same triangles; and a failure names the same module.
#[test]
fn a_picture_found_in_one_walk_is_the_one_made_knowing_its_scale() {
    // A plant whose trunk is thick and whose twigs are thin, with a
    // generalized cylinder, a polygon and a sphere among its tubes, in
    // three colours: the first segments are logged whole (the lines span
    // little yet), later ones as lines.
    let plant = "module A(float, float);\nderivation length: 9;\n\
        Axiom: SetColor(2) SetWidth(3) F(20) StartGC F(5) Left(10) F(5) EndGC \
        SetColor(3) SP() f(2) PP() Left(90) f(2) PP() Left(90) f(2) PP() EP() \
        SetColor(2) A(10, 2);\n\
        production:\n\
        A(l, w) -> SetWidth(w) F(l) RollR(137.5) SB() Left(32) A(l*0.78, w*0.55) EB() \
        Right(18) SetColor(4) A(l*0.86, w*0.7) Sphere(w)\n";
    let fit = 0.9 * 300.0;
    for (src, capped) in [(plant, true), (plant, false)] {
        let mut c = load_text(src);
        c.set_model(cylinders(8, capped));
        let mut run = c.run(Default::default()).unwrap();
        let found = run
            .solid(&SolidOptions {
                fit_pixels: Some(fit),
                ..Default::default()
            })
            .unwrap();
        let (lo, hi) = run.line_bounds().unwrap().unwrap();
        let px = (hi - lo).max_element() / fit;
        let known = run
            .solid(&SolidOptions {
                picture_pixel: Some(px),
                ..Default::default()
            })
            .unwrap();
        assert!(found.line_count() > 100, "{} lines", found.line_count());
        assert!(
            found.triangle_count() > 100,
            "{} triangles",
            found.triangle_count()
        );
        assert_eq!(found.looks, known.looks);
        assert_eq!(found.meshes.len(), known.meshes.len());
        for (m, n) in found.meshes.iter().zip(&known.meshes) {
            assert!(m.lines == n.lines);
            assert_eq!(m.positions.len(), n.positions.len());
            assert!(triangle_set(m) == triangle_set(n));
        }
        // Past the triangle limit: the one-walk run gives up its log and
        // fails as the walk that knows its scale does, at the same module.
        let limit = known.triangle_count() / 2;
        let mut err = |sopts: SolidOptions| {
            run.solid(&SolidOptions {
                max_triangles: limit,
                ..sopts
            })
            .unwrap_err()
            .to_string()
        };
        let one = err(SolidOptions {
            fit_pixels: Some(fit),
            ..Default::default()
        });
        assert!(one.contains("limit of"), "{one}");
        let two = err(SolidOptions {
            picture_pixel: Some(px),
            ..Default::default()
        });
        assert_eq!(one, two);
    }
}
