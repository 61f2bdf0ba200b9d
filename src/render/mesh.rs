//! Pictures of polygon meshes: a smooth- or flat-shaded orthographic view.
//!
//! The mesh is projected along the view direction and fitted into the
//! image with a margin (uniform scale, centred). The PNG is drawn by the
//! z-buffer renderer ([`super::raster`]), the one that draws plants: the
//! polygons are fanned into a [`Scene3`] (one mesh per face colour, each
//! polygon with its own vertices; their normals are the area-weighted
//! normals of the faces around each corner that meet it across edges that
//! are neither sharp nor folded past 35°, so a smooth surface is shaded
//! smoothly and a cube keeps its edges, or with `smooth` off each
//! polygon's Newell normal, one flat shade), and the wireframe is drawn where the polygon seen
//! changes from one sample to the next, so hidden edges stay hidden. The
//! SVG paints the polygons back to front (painter's algorithm, by mean
//! depth) in the same colours, flat. Each face gets OpenGL's lighting of
//! a warm clay from a key light (with a soft highlight) and a weak fill
//! light that are fixed relative to the viewer, so every view is lit the
//! same way; faces seen from behind (the inside of an open mesh) are a
//! cool blue-grey.

use glam::{DVec2, DVec3};

use glam::Vec3;

use super::raster::{self, Light, RasterOptions, ViewSpec, Wireframe};
use super::{check_size, svg, Fit, Item, Outline, RenderError, Rgba, Scene};
use crate::mesh::PolygonSoup;
use crate::scene3::{Look, Scene3, TriMesh};

/// The colour of faces seen from the front: a warm clay, the neutral
/// matte that modelling tools show an unpainted surface in (Blender's
/// matcap and MeshLab's default are greys of this kind), warm so that the
/// key light's shading reads as form, not as a tint.
const FRONT_BASE: DVec3 = DVec3::new(0.80, 0.70, 0.58);
/// The colour of faces seen from behind (the inside of an open mesh): a
/// cool blue-grey, set apart from the clay.
const BACK_BASE: DVec3 = DVec3::new(0.56, 0.64, 0.76);
/// The default look's highlight: a soft sheen of the key light that shows
/// how a smooth surface curves.
const SHEEN: f32 = 0.22;
const SHININESS: f32 = 24.0;
/// The largest angle between two faces' normals across an edge that
/// smooth shading smooths over: a fold sharper than this stays a fold
/// (a cube's edges, a coarse base mesh's), as 3D tools' auto-smooth does.
const SMOOTH_ANGLE_DEGREES: f64 = 35.0;
/// The colours of a vv program's cells (ColorBrewer's Set3, soft and
/// told apart): each cell one, neighbours different where eight do.
const CELL_COLOURS: [Rgba; 8] = [
    Rgba(141, 211, 199, 255),
    Rgba(255, 237, 160, 255),
    Rgba(190, 186, 218, 255),
    Rgba(251, 128, 114, 255),
    Rgba(128, 177, 211, 255),
    Rgba(253, 180, 98, 255),
    Rgba(179, 222, 105, 255),
    Rgba(252, 205, 229, 255),
];
/// The light every face gets, whatever its orientation (OpenGL's global
/// ambient light).
const AMBIENT: f32 = 0.40;
/// The strength of the key light (upper left, in front of the viewer).
const KEY: f32 = 0.62;
/// The strength of the fill light (lower right, in front of the viewer).
const FILL: f32 = 0.22;
/// The colour of the wireframe edges (a dark warm brown).
const EDGE: Rgba = Rgba(58, 46, 38, 255);
/// The width of the seam-closing outline drawn in the face colour when the
/// wireframe is off, so antialiased neighbours leave no light cracks (SVG).
const SEAM_WIDTH: f64 = 0.7;

/// How a mesh is looked at and how the picture is laid out.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshView {
    pub width: u32,
    pub height: u32,
    pub background: Rgba,
    /// Draw the polygon edges as thin dark lines.
    pub wireframe: bool,
    /// The viewing direction, from the eye towards the scene (any length).
    pub direction: DVec3,
    /// The world direction that points up on screen (projected; any length).
    pub up: DVec3,
    /// Margin on every side, as a fraction of the smaller image side.
    pub margin: f64,
    /// The colour of each face (a shape grammar's shapes); empty: the
    /// default blue for every face.
    pub face_colours: Vec<Rgba>,
    /// How faces are coloured.
    pub shading: Shading,
    /// Lit from vertex normals, smooth across faces (not across a sharp
    /// edge or a fold); `false`: one flat shade per face. The PNG only
    /// (the SVG's polygons are flat), and lit shading only.
    pub smooth: bool,
    /// Edges between soup vertices that smooth shading does not smooth
    /// over (a mesh's sharp edges), either way round.
    pub sharp_edges: Vec<(u32, u32)>,
}

pub use super::raster::Shading;

impl Default for MeshView {
    /// 800×800 on white with edges, the "iso" view, 4% margin.
    fn default() -> Self {
        let (direction, up) = iso();
        MeshView {
            width: 800,
            height: 800,
            background: Rgba(255, 255, 255, 255),
            wireframe: true,
            direction,
            up,
            margin: 0.04,
            face_colours: Vec::new(),
            shading: Shading::Lit,
            smooth: true,
            sharp_edges: Vec::new(),
        }
    }
}

/// The default three-quarter view: from the front (-y), right (+x) and
/// above (+z), with +z up on screen.
fn iso() -> (DVec3, DVec3) {
    (DVec3::new(-1.0, 1.6, -1.1).normalize(), DVec3::Z)
}

/// The named views accepted by `--view`: "front" (looking along +y),
/// "back", "left" (looking along +x), "right", "top" (looking down -z with
/// +y up), "bottom" and "iso" (the default). Returns (direction, up).
pub fn view_direction(name: &str) -> Option<(DVec3, DVec3)> {
    match name.to_ascii_lowercase().as_str() {
        "front" => Some((DVec3::Y, DVec3::Z)),
        "back" => Some((DVec3::NEG_Y, DVec3::Z)),
        "left" => Some((DVec3::X, DVec3::Z)),
        "right" => Some((DVec3::NEG_X, DVec3::Z)),
        "top" => Some((DVec3::NEG_Z, DVec3::Y)),
        "bottom" => Some((DVec3::Z, DVec3::NEG_Y)),
        "iso" => Some(iso()),
        _ => None,
    }
}

/// An orthonormal viewer frame: screen right, screen up, and depth (the
/// viewing direction, larger is farther).
#[derive(Clone, Copy, Debug)]
struct Camera {
    right: DVec3,
    up: DVec3,
    dir: DVec3,
}

impl Camera {
    /// The frame of a view, or None when its direction is zero or not finite.
    /// An `up` parallel to the direction is replaced by another axis.
    fn new(view: &MeshView) -> Option<Camera> {
        let dir = view.direction.try_normalize()?;
        let candidates = [view.up, DVec3::Z, DVec3::Y, DVec3::X];
        let right = candidates
            .iter()
            .find_map(|u| dir.cross(*u).try_normalize())?;
        let up = right.cross(dir);
        Some(Camera { right, up, dir })
    }

    /// The frame of a view, falling back to the default view when the
    /// direction is unusable.
    fn or_default(view: &MeshView) -> Camera {
        Camera::new(view)
            .or_else(|| Camera::new(&MeshView::default()))
            .unwrap_or(Camera {
                right: DVec3::X,
                up: DVec3::Y,
                dir: DVec3::NEG_Z,
            })
    }

    /// Screen-plane coordinates (y up) of a point.
    fn plane(&self, p: DVec3) -> DVec2 {
        DVec2::new(p.dot(self.right), p.dot(self.up))
    }

    /// The unit vector towards the key light.
    fn key_light(&self) -> DVec3 {
        (-0.45 * self.right + 0.75 * self.up - 0.55 * self.dir).normalize()
    }
}

/// The unit vector towards the key light of a view, in world coordinates:
/// a face whose normal points along it is the brightest.
pub fn light_direction(view: &MeshView) -> DVec3 {
    Camera::or_default(view).key_light()
}

/// Fits the screen-plane bounding box of the vertices that faces use into
/// the whole image.
fn fit(soup: &PolygonSoup, cam: &Camera, view: &MeshView) -> Fit {
    let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    for p in used_vertices(soup)
        .map(|p| cam.plane(p))
        .filter(|p| p.is_finite())
    {
        lo = lo.min(p);
        hi = hi.max(p);
    }
    if !(lo.is_finite() && hi.is_finite()) {
        (lo, hi) = (DVec2::ZERO, DVec2::ZERO);
    }
    let margin = if view.margin.is_finite() {
        view.margin.clamp(0.0, 0.45)
    } else {
        0.04
    };
    let (w, h) = (view.width as f64, view.height as f64);
    Fit::new(lo, hi, 0.0, w, h, margin)
}

/// The vertices that faces refer to (valid indices only): what a mesh
/// picture's camera frames (and the page's).
pub fn used_vertices(soup: &PolygonSoup) -> impl Iterator<Item = DVec3> + '_ {
    soup.faces
        .iter()
        .flatten()
        .filter_map(|&i| soup.positions.get(i as usize).copied())
}

/// The pixel positions of all vertices of `soup` in the picture `view`
/// would draw (y down, origin at the top left corner).
pub fn project(view: &MeshView, soup: &PolygonSoup) -> Vec<DVec2> {
    let cam = Camera::or_default(view);
    let fit = fit(soup, &cam, view);
    soup.positions
        .iter()
        .map(|&p| fit.pixel(cam.plane(p)))
        .collect()
}

/// Checks that `soup` can be drawn with `view`: a sane image size, a usable
/// direction, at least one face, finite positions and valid indices.
pub fn validate(soup: &PolygonSoup, view: &MeshView) -> Result<(), RenderError> {
    check_size(view.width, view.height)?;
    if Camera::new(view).is_none() {
        return Err(RenderError::new(
            "the view direction must be a finite, non-zero vector",
        ));
    }
    if soup.faces.is_empty() {
        return Err(RenderError::new("nothing to draw: the mesh has no faces"));
    }
    if let Some(v) = soup.positions.iter().position(|p| !p.is_finite()) {
        let p = soup.positions[v];
        return Err(RenderError::new(format!(
            "vertex {v}{} has a non-finite position ({}, {}, {})",
            at_line(soup.vertex_line(v)),
            p.x,
            p.y,
            p.z
        )));
    }
    check_indices(soup)
}

/// Every face index must name a vertex.
fn check_indices(soup: &PolygonSoup) -> Result<(), RenderError> {
    let n = soup.positions.len();
    for (f, face) in soup.faces.iter().enumerate() {
        if let Some(&i) = face.iter().find(|&&i| i as usize >= n) {
            return Err(RenderError::new(format!(
                "face {f}{} refers to vertex {i}, but the mesh has {n} vertices",
                at_line(soup.face_line(f))
            )));
        }
    }
    Ok(())
}

/// " (line N)" when the line is known.
fn at_line(line: Option<usize>) -> String {
    line.map(|l| format!(" (line {l})")).unwrap_or_default()
}

/// The picture of `soup` seen with `view`, after [`validate`]: one shaded
/// polygon per drawable face, back to front.
pub fn scene(soup: &PolygonSoup, view: &MeshView) -> Result<Scene, RenderError> {
    validate(soup, view)?;
    Ok(unchecked_scene(soup, view))
}

/// The scene without the checks: faces that cannot be drawn are left out,
/// and a view with an unusable direction is drawn from the default one.
fn unchecked_scene(soup: &PolygonSoup, view: &MeshView) -> Scene {
    Scene {
        width: view.width,
        height: view.height,
        background: view.background,
        items: faces(soup, view),
    }
}

/// Renders the mesh as a PNG image, with the z-buffer (after [`validate`]).
pub fn render_png(soup: &PolygonSoup, view: &MeshView) -> Result<Vec<u8>, RenderError> {
    validate(soup, view)?;
    crate::deadline::check(crate::deadline::current()).map_err(RenderError::new)?;
    let (scene, polygons, back) = scene3(soup, view);
    if scene.triangle_count() == 0 {
        return Err(RenderError::new(
            "nothing to draw: every face of the mesh has zero area",
        ));
    }
    let opts = raster_options(soup, view, polygons, back)?;
    raster::render_png(&scene, &opts)
}

/// Renders the mesh as an SVG document that looks like the PNG: one
/// `<polygon>` per drawable face, back to front. It does not check its
/// input (see [`validate`]): faces that cannot be drawn are left out, and a
/// view with an unusable direction is drawn from the default one.
pub fn render_svg(soup: &PolygonSoup, view: &MeshView) -> String {
    svg::render(&unchecked_scene(soup, view))
}

/// One face ready to paint, with what orders it.
struct Shaded {
    item: Item,
    depth: f64,
    back: bool,
}

/// The drawable faces of `soup` as scene polygons, shaded and sorted back
/// to front (farther first; at equal depth a back face first). Faces with
/// fewer than three vertices, invalid indices or zero area are left out.
fn faces(soup: &PolygonSoup, view: &MeshView) -> Vec<Item> {
    let cam = Camera::or_default(view);
    let fit = fit(soup, &cam, view);
    let edge = if view.wireframe {
        Some(Outline {
            color: EDGE,
            width: edge_width(view),
        })
    } else {
        None
    };
    let mut faces: Vec<Shaded> = soup
        .faces
        .iter()
        .enumerate()
        .filter_map(|(k, face)| {
            let base = view
                .face_colours
                .get(k)
                .map(|c| DVec3::new(c.0 as f64, c.1 as f64, c.2 as f64) / 255.0);
            shade_face(soup, face, &cam, &fit, edge, base, view.shading)
        })
        .collect();
    faces.sort_by(|a, b| b.depth.total_cmp(&a.depth).then(b.back.cmp(&a.back)));
    faces.into_iter().map(|f| f.item).collect()
}

/// The shaded, projected face, or None when it cannot be drawn. Its outline
/// is `edge`, or without a wireframe a thin seam closer in its own colour.
fn shade_face(
    soup: &PolygonSoup,
    face: &[u32],
    cam: &Camera,
    fit: &Fit,
    edge: Option<Outline>,
    base: Option<DVec3>,
    shading: Shading,
) -> Option<Shaded> {
    let corners: Vec<DVec3> = face
        .iter()
        .map(|&i| soup.positions.get(i as usize).copied())
        .collect::<Option<_>>()?;
    if corners.len() < 3 || corners.iter().any(|p| !p.is_finite()) {
        return None;
    }
    let normal = newell_normal(&corners).try_normalize()?;
    let back = normal.dot(cam.dir) > 0.0;
    let seen = if back { -normal } else { normal };
    let depth = corners.iter().map(|p| p.dot(cam.dir)).sum::<f64>() / corners.len() as f64;
    let color = match shading {
        Shading::Lit => shade(seen, back, cam, base),
        Shading::Unlit => {
            let c = face_look(base, back)
                .diffuse
                .map(|v| (v * 255.0).round() as u8);
            Rgba(c[0], c[1], c[2], 255)
        }
        Shading::Normals => {
            let c = (seen + DVec3::ONE) * 127.5;
            Rgba(c.x.round() as u8, c.y.round() as u8, c.z.round() as u8, 255)
        }
        Shading::Reflection => {
            let c = raster::reflection(seen.as_vec3(), cam.dir.as_vec3(), cam.up.as_vec3());
            let [r, g, b] = c.map(|v| (v * 255.0).round() as u8);
            Rgba(r, g, b, 255)
        }
    };
    let outline = edge.unwrap_or(Outline {
        color,
        width: SEAM_WIDTH,
    });
    Some(Shaded {
        item: Item::Polygon {
            points: corners.iter().map(|&p| fit.pixel(cam.plane(p))).collect(),
            color,
            outline: Some(outline),
        },
        depth,
        back,
    })
}

/// Twice the vector area of a polygon (Newell's method): its direction is
/// the normal of the counter-clockwise side, zero for a degenerate face.
fn newell_normal(corners: &[DVec3]) -> DVec3 {
    let origin = corners[0];
    let mut n = DVec3::ZERO;
    for (k, &a) in corners.iter().enumerate() {
        let b = corners[(k + 1) % corners.len()];
        n += (a - origin).cross(b - origin);
    }
    let extent = corners
        .iter()
        .map(|p| (*p - origin).length_squared())
        .fold(0.0, f64::max);
    if n.length_squared() <= 1e-24 * extent * extent {
        DVec3::ZERO
    } else {
        n
    }
}

/// The flat colour of a face whose visible side has unit normal `seen`:
/// the lighting the PNG gives it.
fn shade(seen: DVec3, back: bool, cam: &Camera, base: Option<DVec3>) -> Rgba {
    let look = face_look(base, back);
    let n = Vec3::new(
        seen.dot(cam.right) as f32,
        seen.dot(cam.up) as f32,
        -seen.dot(cam.dir) as f32,
    );
    let c = raster::lighting(&look, n, &lights(), [AMBIENT; 3]).map(|v| (v * 255.0).round() as u8);
    Rgba(c[0], c[1], c[2], 255)
}

/// The key and fill lights, in eye coordinates (fixed to the viewer); the
/// key light alone makes a highlight.
fn lights() -> Vec<Light> {
    let light = |d: Vec3, strength: f32, sheen: f32| Light {
        direction: d.normalize(),
        ambient: [0.0; 3],
        diffuse: [strength; 3],
        specular: [sheen; 3],
    };
    vec![
        light(Vec3::new(-0.45, 0.75, 0.55), KEY, 1.0),
        light(Vec3::new(0.6, -0.3, 0.7), FILL, 0.0),
    ]
}

/// The look of a face of colour `base` (the default blue when none), on
/// its back the warm grey, or its colour darkened.
fn face_look(base: Option<DVec3>, back: bool) -> Look {
    let c = match base {
        Some(c) if back => c * 0.6,
        Some(c) => c,
        None if back => BACK_BASE,
        None => FRONT_BASE,
    };
    let c = c.as_vec3().to_array();
    Look {
        name: String::new(),
        index: 0,
        ambient: c,
        diffuse: c,
        specular: [SHEEN; 3],
        emission: [0.0; 3],
        shininess: SHININESS,
        opacity: 1.0,
    }
}

/// A colour for each face of `soup`, from `CELL_COLOURS` (ColorBrewer Set3): each face the
/// first colour none of its neighbours (faces sharing an edge) took
/// before it, in face order (greedy colouring), or by its number when
/// its neighbours took all eight.
pub fn cell_colours(soup: &PolygonSoup) -> Vec<Rgba> {
    use std::collections::HashMap;
    let mut by_edge: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
    for (f, face) in soup.faces.iter().enumerate() {
        for (k, &a) in face.iter().enumerate() {
            let b = face[(k + 1) % face.len()];
            by_edge.entry((a.min(b), a.max(b))).or_default().push(f);
        }
    }
    let mut colour: Vec<Option<usize>> = vec![None; soup.faces.len()];
    for (f, face) in soup.faces.iter().enumerate() {
        let mut taken = [false; CELL_COLOURS.len()];
        for (k, &a) in face.iter().enumerate() {
            let b = face[(k + 1) % face.len()];
            for &g in &by_edge[&(a.min(b), a.max(b))] {
                if let Some(c) = colour[g] {
                    taken[c] = true;
                }
            }
        }
        colour[f] = Some(
            taken
                .iter()
                .position(|t| !t)
                .unwrap_or(f % CELL_COLOURS.len()),
        );
    }
    colour
        .into_iter()
        .map(|c| CELL_COLOURS[c.unwrap_or(0)])
        .collect()
}

/// Whether `soup` is a sheet of cells rather than a surface: some face
/// has more than four sides (a vv tissue; subdivision makes triangles and
/// quads).
pub fn has_cells(soup: &PolygonSoup) -> bool {
    soup.faces.iter().any(|f| f.len() > 4)
}

/// Whether every vertex that a face of `soup` uses has one z (a mesh in
/// the xy plane, as a tissue of cells is): seen best from the top.
pub fn is_flat_in_z(soup: &PolygonSoup) -> bool {
    let mut zs = used_vertices(soup).map(|p| p.z);
    let Some(z0) = zs.next() else { return false };
    let (mut lo, mut hi) = (z0, z0);
    for z in zs {
        (lo, hi) = (lo.min(z), hi.max(z));
    }
    let (mut a, mut b) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    for p in used_vertices(soup) {
        (a, b) = (a.min(p.truncate()), b.max(p.truncate()));
    }
    let extent = (b - a).max_element();
    extent > 0.0 && (hi - lo) <= 1e-9 * extent
}

/// The normal of each corner of each face for smooth shading: the sum of
/// the area-weighted normals (Newell's vectors) of the faces around the
/// corner's vertex that reach it across edges of two faces which are not
/// `sharp` and fold by at most [`SMOOTH_ANGLE_DEGREES`]; `None` for a
/// face that cannot be drawn. A face alone at its vertex keeps its own
/// normal.
fn corner_normals(
    soup: &PolygonSoup,
    newell: &[Option<DVec3>],
    sharp: &[(u32, u32)],
) -> CornerNormals {
    use std::collections::HashSet;
    let sharp: HashSet<(u32, u32)> = sharp.iter().map(|&(a, b)| (a.min(b), a.max(b))).collect();
    // Corners numbered face after face.
    let mut first = Vec::with_capacity(soup.faces.len() + 1);
    let mut n = 0;
    for face in soup.faces.iter() {
        first.push(n);
        n += face.len();
    }
    first.push(n);
    let mut parent: Vec<usize> = (0..n).collect();
    fn root(parent: &mut [usize], mut c: usize) -> usize {
        while parent[c] != c {
            parent[c] = parent[parent[c]];
            c = parent[c];
        }
        c
    }
    // Each side of an edge: the edge, its face, the corner of its first
    // end and of its second; sorted by edge (no map, no allocation per
    // edge: a million faces take a few hundred milliseconds).
    let mut sides: Vec<((u32, u32), usize, usize, usize)> = Vec::with_capacity(n);
    for (f, face) in soup.faces.iter().enumerate() {
        if newell[f].is_none() {
            continue;
        }
        for k in 0..face.len() {
            let (a, b) = (face[k], face[(k + 1) % face.len()]);
            let j = (k + 1) % face.len();
            let (ca, cb) = (first[f] + k, first[f] + j);
            let ends = if a <= b { (ca, cb) } else { (cb, ca) };
            sides.push(((a.min(b), a.max(b)), f, ends.0, ends.1));
        }
    }
    sides.sort_unstable_by_key(|s| s.0);
    let cos = SMOOTH_ANGLE_DEGREES.to_radians().cos();
    for list in sides.chunk_by(|x, y| x.0 == y.0) {
        let [(key, f, fa, fb), (_, g, ga, gb)] = list else {
            continue;
        };
        if sharp.contains(key) {
            continue;
        }
        let (Some(nf), Some(ng)) = (newell[*f], newell[*g]) else {
            continue;
        };
        if nf.normalize().dot(ng.normalize()) < cos {
            continue;
        }
        for (x, y) in [(*fa, *ga), (*fb, *gb)] {
            let (rx, ry) = (root(&mut parent, x), root(&mut parent, y));
            parent[rx] = ry;
        }
    }
    let mut sum = vec![DVec3::ZERO; n];
    for (f, face) in soup.faces.iter().enumerate() {
        let Some(nf) = newell[f] else { continue };
        for k in 0..face.len() {
            let r = root(&mut parent, first[f] + k);
            sum[r] += nf;
        }
    }
    let mut normals = vec![DVec3::ZERO; n];
    for (f, face) in soup.faces.iter().enumerate() {
        let Some(own) = newell[f].map(DVec3::normalize) else {
            continue;
        };
        for k in 0..face.len() {
            let r = root(&mut parent, first[f] + k);
            normals[first[f] + k] = sum[r].try_normalize().unwrap_or(own);
        }
    }
    CornerNormals { first, normals }
}

/// The normal of every corner, face after face (see [`corner_normals`]).
struct CornerNormals {
    /// Where each face's corners start in `normals`, and the end.
    first: Vec<usize>,
    normals: Vec<DVec3>,
}

impl CornerNormals {
    /// The normals of face `f`'s corners.
    fn of(&self, f: usize) -> &[DVec3] {
        &self.normals[self.first[f]..self.first[f + 1]]
    }
}

/// Each face's Newell vector (twice its vector area), or `None` for a face
/// that cannot be drawn (fewer than three corners, an index out of range,
/// a coordinate not finite, no area).
fn newell_vectors(soup: &PolygonSoup) -> Vec<Option<DVec3>> {
    // One buffer for every face's corners.
    let mut corners: Vec<DVec3> = Vec::new();
    soup.faces
        .iter()
        .map(|face| {
            corners.clear();
            for &i in face {
                corners.push(*soup.positions.get(i as usize)?);
            }
            if corners.len() < 3 || corners.iter().any(|p| !p.is_finite()) {
                return None;
            }
            let n = newell_normal(&corners);
            n.try_normalize().map(|_| n)
        })
        .collect()
}

/// The faces of `soup` as a [`Scene3`] for the z-buffer: one mesh per face
/// colour (in the order first used), each polygon fanned from its first
/// corner with its own copies of its vertices and its Newell normal as
/// their normals, so a polygon (even a warped one) is one flat shade as in
/// the SVG. Also the polygon of each triangle (for the wireframe) and each
/// mesh's back look. Faces that cannot be drawn are left out.
pub fn scene3(soup: &PolygonSoup, view: &MeshView) -> (Scene3, Vec<u32>, Vec<Look>) {
    let mut scene = Scene3::default();
    let mut back = Vec::new();
    let mut keys: Vec<Option<Rgba>> = Vec::new();
    let mut polygons: Vec<Vec<u32>> = Vec::new();
    let newell = newell_vectors(soup);
    let smooth = (view.smooth && view.shading == Shading::Lit)
        .then(|| corner_normals(soup, &newell, &view.sharp_edges));
    for (f, face) in soup.faces.iter().enumerate() {
        let Some(normal) = newell[f].map(DVec3::normalize) else {
            continue;
        };
        let corners: Vec<DVec3> = face.iter().map(|&i| soup.positions[i as usize]).collect();
        let key = view.face_colours.get(f).copied();
        let k = match keys.iter().position(|c| *c == key) {
            Some(k) => k,
            None => {
                let base = key.map(|c| DVec3::new(c.0 as f64, c.1 as f64, c.2 as f64) / 255.0);
                let mut look = face_look(base, false);
                look.name = format!("face{}", keys.len());
                let mut b = face_look(base, true);
                b.name = format!("{}-back", look.name);
                keys.push(key);
                scene.looks.push(look);
                back.push(b);
                scene.meshes.push(TriMesh::default());
                polygons.push(Vec::new());
                keys.len() - 1
            }
        };
        let m = &mut scene.meshes[k];
        let start = m.positions.len() as u32;
        m.positions.extend(corners.iter().map(|p| p.as_vec3()));
        match smooth.as_ref().map(|s| s.of(f)) {
            Some(normals) => m.normals.extend(normals.iter().map(|n| n.as_vec3())),
            None => m
                .normals
                .extend(std::iter::repeat_n(normal.as_vec3(), corners.len())),
        }
        for j in 1..corners.len() as u32 - 1 {
            m.triangles.push([start, start + j, start + j + 1]);
            polygons[k].push(f as u32);
        }
    }
    (scene, polygons.concat(), back)
}

/// The faces of `soup` as a [`Scene3`] for export: one mesh per face
/// colour (the default blue without colours), each polygon fanned from its
/// first corner over the soup's own vertices (renumbered per mesh, shared
/// between faces), no normals. Faces with fewer than three corners or an
/// index out of range are left out.
pub fn soup_scene3(soup: &PolygonSoup, face_colours: &[Rgba]) -> Scene3 {
    let mut scene = Scene3::default();
    let mut keys: Vec<Option<Rgba>> = Vec::new();
    let mut maps: Vec<std::collections::HashMap<u32, u32>> = Vec::new();
    let n = soup.positions.len();
    for (f, face) in soup.faces.iter().enumerate() {
        if face.len() < 3 || face.iter().any(|&i| i as usize >= n) {
            continue;
        }
        let key = face_colours.get(f).copied();
        let k = match keys.iter().position(|c| *c == key) {
            Some(k) => k,
            None => {
                let base = key.map(|c| DVec3::new(c.0 as f64, c.1 as f64, c.2 as f64) / 255.0);
                let mut look = face_look(base, false);
                look.name = match key {
                    Some(c) => format!("colour-{}", &c.hex()[1..]),
                    None => "surface".into(),
                };
                keys.push(key);
                scene.looks.push(look);
                scene.meshes.push(TriMesh::default());
                maps.push(Default::default());
                keys.len() - 1
            }
        };
        let m = &mut scene.meshes[k];
        let map = &mut maps[k];
        let local: Vec<u32> = face
            .iter()
            .map(|&i| {
                *map.entry(i).or_insert_with(|| {
                    m.positions.push(soup.positions[i as usize].as_vec3());
                    m.positions.len() as u32 - 1
                })
            })
            .collect();
        for j in 1..local.len() - 1 {
            m.triangles.push([local[0], local[j], local[j + 1]]);
        }
    }
    scene
}

/// The faces of `soup` for a viewer (the live page's GLB): shaded as
/// [`scene3`] shades them for the z-buffer (the view's face colours,
/// smooth corner normals split at sharp edges and folds, or each face's
/// own), with a vertex shared by every face whose corner there has the
/// same normal, so that a smooth surface sends each vertex once; and each
/// mesh's polygon edges in its own numbering (the wireframe, without the
/// fans' diagonals).
pub fn viewer_scene3(soup: &PolygonSoup, view: &MeshView) -> (Scene3, Vec<Vec<[u32; 2]>>) {
    use std::collections::HashMap;
    let newell = newell_vectors(soup);
    let smooth = (view.smooth && view.shading == Shading::Lit)
        .then(|| corner_normals(soup, &newell, &view.sharp_edges));
    let mut scene = Scene3::default();
    let mut keys: Vec<Option<Rgba>> = Vec::new();
    // Per mesh: each soup vertex's first copy (`u32::MAX`: none yet), and
    // the copies with other normals (few: along sharp edges and folds).
    let mut firsts: Vec<Vec<u32>> = Vec::new();
    let mut others: Vec<HashMap<(u32, [u32; 3]), u32>> = Vec::new();
    // Each polygon side: the soup's ends (so that an edge between faces
    // whose corners are different copies is drawn once) and the copies.
    let mut edges: Vec<Vec<([u32; 2], [u32; 2])>> = Vec::new();
    for (f, face) in soup.faces.iter().enumerate() {
        let Some(normal) = newell[f].map(DVec3::normalize) else {
            continue;
        };
        let key = view.face_colours.get(f).copied();
        let k = match keys.iter().position(|c| *c == key) {
            Some(k) => k,
            None => {
                let base = key.map(|c| DVec3::new(c.0 as f64, c.1 as f64, c.2 as f64) / 255.0);
                let mut look = face_look(base, false);
                look.name = format!("face{}", keys.len());
                keys.push(key);
                scene.looks.push(look);
                scene.meshes.push(TriMesh::default());
                firsts.push(vec![u32::MAX; soup.positions.len()]);
                others.push(HashMap::new());
                edges.push(Vec::new());
                keys.len() - 1
            }
        };
        let corner_normals = smooth.as_ref().map(|s| s.of(f));
        let m = &mut scene.meshes[k];
        let (first, other) = (&mut firsts[k], &mut others[k]);
        let local: Vec<u32> = face
            .iter()
            .enumerate()
            .map(|(c, &i)| {
                let n = corner_normals.map_or(normal, |ns| ns[c]).as_vec3();
                let bits = n.to_array().map(f32::to_bits);
                let at = first[i as usize];
                if at != u32::MAX && m.normals[at as usize].to_array().map(f32::to_bits) == bits {
                    return at;
                }
                let copy = |m: &mut TriMesh| {
                    m.positions.push(soup.positions[i as usize].as_vec3());
                    m.normals.push(n);
                    m.positions.len() as u32 - 1
                };
                if at == u32::MAX {
                    let at = copy(m);
                    first[i as usize] = at;
                    return at;
                }
                *other.entry((i, bits)).or_insert_with(|| copy(m))
            })
            .collect();
        for j in 1..local.len() - 1 {
            m.triangles.push([local[0], local[j], local[j + 1]]);
        }
        for j in 0..local.len() {
            let next = (j + 1) % local.len();
            let (a, b) = (face[j], face[next]);
            edges[k].push(([a.min(b), a.max(b)], [local[j], local[next]]));
        }
    }
    let edges = edges
        .into_iter()
        .map(|mut list| {
            list.sort_unstable_by_key(|e| e.0);
            list.dedup_by_key(|e| e.0);
            list.into_iter()
                .map(|(_, [a, b])| [a.min(b), a.max(b)])
                .collect()
        })
        .collect();
    (scene, edges)
}

/// The z-buffer's settings for a picture of `soup` seen with `view`: the
/// tight fit of the view's direction, the key and fill lights, the back
/// looks and the wireframe.
pub fn raster_options(
    soup: &PolygonSoup,
    view: &MeshView,
    polygons: Vec<u32>,
    back: Vec<Look>,
) -> Result<RasterOptions, RenderError> {
    let camera = camera(view, &mut used_vertices(soup).map(|p| p.as_vec3()))?;
    Ok(raster_options_with(camera, view, polygons, back))
}

/// The camera of a mesh picture seen with `view` that frames `points` (the
/// vertices of one mesh, or of every frame of an animation): the view's
/// direction, the tight fit of the points' outline within the margin.
pub fn camera(
    view: &MeshView,
    points: &mut dyn Iterator<Item = Vec3>,
) -> Result<raster::Camera, RenderError> {
    let cam = Camera::or_default(view);
    let margin = if view.margin.is_finite() {
        view.margin.clamp(0.0, 0.45)
    } else {
        0.04
    };
    let spec = ViewSpec {
        dir: cam.dir.as_vec3(),
        up: cam.up.as_vec3(),
        scale: (1.0 - 2.0 * margin) as f32,
        tight: true,
        ..ViewSpec::default()
    };
    raster::Camera::from_view(&spec, points, view.width, view.height)
}

/// The z-buffer's settings for a mesh picture with `camera`: the key and
/// fill lights, the view's background and shading, the back looks and the
/// wireframe of [`scene3`]'s `polygons`.
pub fn raster_options_with(
    camera: raster::Camera,
    view: &MeshView,
    polygons: Vec<u32>,
    back: Vec<Look>,
) -> RasterOptions {
    RasterOptions {
        background: view.background,
        lights: lights(),
        global_ambient: [AMBIENT; 3],
        shading: view.shading,
        back_looks: Some(back),
        wireframe: view.wireframe.then_some(Wireframe {
            color: EDGE,
            polygons,
            wide: edge_width(view) >= 0.8,
        }),
        ..RasterOptions::new(camera)
    }
}

/// The width of edge strokes: thin, growing slowly with the image.
fn edge_width(view: &MeshView) -> f64 {
    (view.width.min(view.height) as f64 / 800.0).clamp(0.6, 3.0)
}
