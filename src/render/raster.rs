//! The z-buffer renderer of shaded 3D geometry ([`Scene3`]): a camera
//! (parallel or perspective, from lpfg's view file or fitted to the
//! geometry), triangles depth-tested per sample on a supersampled grid,
//! and OpenGL's fixed-function lighting of each [`Look`], two-sided, flat
//! or smooth, evaluated per sample.
//!
//! Rendering is deferred. The raster pass writes, per sample, one `u64`
//! key: the sample's depth (an `f32` in 0..=1, whose bits order as the
//! numbers do) above the triangle's global index. A sample keeps the
//! smallest key, so the nearest triangle wins and, at equal depth, the
//! first one; that is a minimum over all triangles, so the picture does
//! not depend on the order triangles are drawn in. Large scenes are
//! rasterised in contiguous chunks of triangles on rayon's pool, each
//! into its own key buffer, and the buffers are merged by that same
//! minimum: the picture does not depend on the number of threads, to the
//! bit. A triangle that covers no sample centre costs one bounding-box
//! test, so millions of sub-pixel triangles stay cheap. The resolve pass
//! then shades each pixel from its samples' triangles (once per pixel when
//! all its samples show one triangle) and averages them.
//!
//! Edge functions are evaluated in `f64` from each edge's lexicographically
//! smaller end, so the two triangles of a shared edge see exactly opposite
//! values and no sample falls between them.

use glam::{DVec2, Vec3};
use rayon::prelude::*;

use super::{check_size, Item, Outline, RenderError, Rgba, Scene};
use crate::scene3::{Line, Look, Scene3};

/// How the picture is projected.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Projection {
    /// Orthographic (lpfg's default).
    #[default]
    Parallel,
    /// A pinhole camera.
    Perspective,
}

/// A camera: an orthonormal frame at `eye`, a projection, the depth range
/// kept, and the image it draws into.
///
/// A world point `p` has eye coordinates `e = ((p-eye)·right,
/// (p-eye)·up, (p-eye)·dir)` (`e.z` the distance in front of the eye). In
/// parallel projection its normalised device coordinates are `(e.x /
/// (h·aspect), e.y / h)`, in perspective `(e.x / (e.z·h·aspect), e.y /
/// (e.z·h))`, with `h` = [`Camera::half_height`] and `aspect` = width /
/// height, as OpenGL's `glOrtho` and `gluPerspective` after `gluLookAt`
/// give them. Pixel coordinates are `((x + 1) / 2 · width, (1 - y) / 2 ·
/// height)`, y down, pixel `(i, j)` covering `i..i+1`, `j..j+1`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub eye: Vec3,
    /// Screen right, screen up and the viewing direction: orthonormal.
    pub right: Vec3,
    pub up: Vec3,
    pub dir: Vec3,
    pub projection: Projection,
    /// Parallel: half the visible height in world units. Perspective: the
    /// tangent of half the vertical field of view.
    pub half_height: f32,
    /// The depth range drawn, as distances along `dir` from the eye
    /// (`near` > 0 in perspective).
    pub near: f32,
    pub far: f32,
    pub width: u32,
    pub height: u32,
}

/// Where a camera looks from and how much it shows: lpfg's view-file
/// settings (§8.1 of its manual), or a mesh's named view.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewSpec {
    /// The viewing direction (any length) and the world direction that is
    /// up on screen.
    pub dir: Vec3,
    pub up: Vec3,
    pub projection: Projection,
    /// The vertical field of view in degrees (perspective).
    pub fov: f32,
    /// The fraction of the window the box fills (lpfg's `scale:`, 0.9 by
    /// default).
    pub scale: f32,
    /// The point looked at, relative to the centre of the box.
    pub pan: Vec3,
    /// The distance from the eye to the point looked at; `None`: far
    /// enough to see the whole box (lpfg's formula).
    pub shift: Option<f32>,
    /// The box to frame (`box:`); `None`: the geometry's bounds.
    pub bounds: Option<(Vec3, Vec3)>,
    /// `front distance:` and `back distance:`, both or none.
    pub clip: Option<(f32, f32)>,
    /// Frame the geometry's own outline on screen (its vertices projected)
    /// instead of its bounding box: the tight fit of mesh pictures.
    pub tight: bool,
}

impl Default for ViewSpec {
    /// lpfg's defaults: looking down -z with y up, parallel, fov 45°,
    /// scale 0.9, fitted to the geometry.
    fn default() -> Self {
        ViewSpec {
            dir: Vec3::NEG_Z,
            up: Vec3::Y,
            projection: Projection::Parallel,
            fov: 45.0,
            scale: 0.9,
            pan: Vec3::ZERO,
            shift: None,
            bounds: None,
            clip: None,
            tight: false,
        }
    }
}

/// The orthonormal frame (right, up, dir) of a direction and an up
/// vector; an up parallel to the direction is replaced by another axis.
fn frame(dir: Vec3, up: Vec3) -> Option<(Vec3, Vec3, Vec3)> {
    let dir = dir.try_normalize()?;
    let right = [up, Vec3::Y, Vec3::Z, Vec3::X]
        .iter()
        .find_map(|u| dir.cross(*u).try_normalize())?;
    Some((right, right.cross(dir), dir))
}

impl Camera {
    /// A camera at `eye` looking at `target` with `up` up on screen;
    /// `None` when the frame is degenerate or a value is not finite.
    #[allow(clippy::too_many_arguments)]
    pub fn look_at(
        eye: Vec3,
        target: Vec3,
        up: Vec3,
        projection: Projection,
        half_height: f32,
        (near, far): (f32, f32),
        width: u32,
        height: u32,
    ) -> Option<Camera> {
        let (right, up, dir) = frame(target - eye, up)?;
        let ok = eye.is_finite()
            && half_height.is_finite()
            && half_height > 0.0
            && near.is_finite()
            && far.is_finite()
            && far > near
            && (projection == Projection::Parallel || near > 0.0);
        ok.then_some(Camera {
            eye,
            right,
            up,
            dir,
            projection,
            half_height,
            near,
            far,
            width,
            height,
        })
    }

    /// The camera that `spec` describes for geometry with the given bounds
    /// (or vertices, for a tight fit), in an image of `width`×`height`.
    ///
    /// Following lpfg: the box's half extents `hw`, `hh` across the view
    /// (its eight corners in the view frame); with `z = 1 / scale`, a
    /// parallel view shows a half height of `hh·z`, or `hw·z / aspect`
    /// when the box is the wider; the eye stands `hw·z / tan(fov/2) +
    /// 0.525·diagonal` before the centre (or `shift`), and in perspective
    /// the half field of view has the tangent `z·tan(fov/2)` (over the
    /// wider side). The depth range is the centre's ±0.525 diagonals (or
    /// half the clipping distances).
    pub fn from_view(
        spec: &ViewSpec,
        points: &mut dyn Iterator<Item = Vec3>,
        width: u32,
        height: u32,
    ) -> Result<Camera, RenderError> {
        check_size(width, height)?;
        let (right, up, dir) = frame(spec.dir, spec.up).ok_or_else(|| {
            RenderError::new("the view direction must be a finite, non-zero vector")
        })?;
        let aspect = width as f32 / height as f32;
        let scale = if spec.scale.is_finite() && spec.scale > 1e-4 {
            spec.scale
        } else {
            0.9
        };
        let z = 1.0 / scale;
        if spec.tight {
            return Ok(Self::tight((right, up, dir), points, scale, width, height));
        }
        let (lo, hi) = match spec.bounds {
            Some(b) => b,
            None => points
                .fold(None, |acc: Option<(Vec3, Vec3)>, p| {
                    Some(acc.map_or((p, p), |(lo, hi)| (lo.min(p), hi.max(p))))
                })
                .ok_or_else(|| RenderError::new("nothing to draw: the scene has no vertex"))?,
        };
        let centre = (lo + hi) * 0.5;
        let (mut hw, mut hh) = (0.0f32, 0.0f32);
        for k in 0..8 {
            let c = Vec3::new(
                if k & 1 == 0 { lo.x } else { hi.x },
                if k & 2 == 0 { lo.y } else { hi.y },
                if k & 4 == 0 { lo.z } else { hi.z },
            ) - centre;
            hw = hw.max(c.dot(right).abs());
            hh = hh.max(c.dot(up).abs());
        }
        const MIN_DIM: f32 = 0.1;
        if hw == 0.0 {
            hw = MIN_DIM * hh;
        }
        if hh == 0.0 {
            hh = MIN_DIM * hw;
        }
        if hw == 0.0 {
            (hw, hh) = (MIN_DIM, MIN_DIM);
        }
        let mut half_depth = 0.525 * (hi - lo).length();
        if half_depth == 0.0 {
            half_depth = 0.5;
        }
        if let Some((front, back)) = spec.clip {
            half_depth = ((back - front) * 0.5).abs().max(1e-6);
        }
        let fov = spec.fov.clamp(1e-3, 179.0).to_radians();
        let tan = (fov * 0.5).tan();
        let shift = match spec.shift {
            Some(s) if s.is_finite() && s > 0.0 => s,
            _ => hw * z / tan + half_depth,
        };
        let target = centre + spec.pan;
        let eye = target - dir * shift;
        let wide = aspect > hw / hh;
        let (projection, half_height) = match spec.projection {
            Projection::Parallel if wide => (Projection::Parallel, hh * z),
            Projection::Parallel => (Projection::Parallel, hw * z / aspect),
            Projection::Perspective if wide => (Projection::Perspective, z * tan),
            Projection::Perspective => (Projection::Perspective, z * tan / aspect),
        };
        let near = (shift - half_depth).max(1e-3 * shift.max(1e-3));
        let far = (shift + half_depth).max(near * 1.001);
        Camera::look_at(
            eye,
            target,
            up,
            projection,
            half_height,
            (near, far),
            width,
            height,
        )
        .ok_or_else(|| RenderError::new("the view cannot be set up: a value is not finite"))
    }

    /// A parallel camera that fits the vertices' outline on screen into the
    /// image, `scale` of its smaller side (the mesh pictures' fit).
    fn tight(
        (right, up, dir): (Vec3, Vec3, Vec3),
        points: &mut dyn Iterator<Item = Vec3>,
        scale: f32,
        width: u32,
        height: u32,
    ) -> Camera {
        let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        for p in points {
            let e = Vec3::new(p.dot(right), p.dot(up), p.dot(dir));
            lo = lo.min(e);
            hi = hi.max(e);
        }
        if !(lo.is_finite() && hi.is_finite()) {
            (lo, hi) = (Vec3::ZERO, Vec3::ZERO);
        }
        let (w, h) = (width as f32, height as f32);
        let m = (1.0 - scale) * 0.5 * w.min(h);
        let avail = DVec2::new((w - 2.0 * m).max(1.0) as f64, (h - 2.0 * m).max(1.0) as f64);
        let ext = hi - lo;
        let px_per_unit = super::fit_scale(avail, DVec2::new(ext.x as f64, ext.y as f64)) as f32;
        let mid = (lo + hi) * 0.5;
        let pad = ext.z * 0.01 + 1e-6 * (1.0 + lo.z.abs().max(hi.z.abs()));
        let eye = right * mid.x + up * mid.y + dir * (lo.z - pad);
        Camera {
            eye,
            right,
            up,
            dir,
            projection: Projection::Parallel,
            half_height: h * 0.5 / px_per_unit,
            near: 0.0,
            far: ext.z + 2.0 * pad,
            width,
            height,
        }
    }

    /// The eye coordinates of a world point: right, up, and the distance
    /// in front of the eye.
    pub fn eye_coords(&self, p: Vec3) -> Vec3 {
        let d = p - self.eye;
        Vec3::new(d.dot(self.right), d.dot(self.up), d.dot(self.dir))
    }

    /// The pixel position of a world point (y down) and its depth, 0 at
    /// the near plane and 1 at the far one (in perspective, affine in the
    /// inverse distance, as a z-buffer keeps it); `None` behind the eye in
    /// perspective.
    pub fn pixel(&self, p: Vec3) -> Option<Vec3> {
        let e = self.eye_coords(p);
        let aspect = self.width as f32 / self.height as f32;
        let (x, y, depth) = match self.projection {
            Projection::Parallel => (
                e.x / (self.half_height * aspect),
                e.y / self.half_height,
                (e.z - self.near) / (self.far - self.near),
            ),
            Projection::Perspective => {
                if e.z <= 0.0 {
                    return None;
                }
                let s = 1.0 / (e.z * self.half_height);
                (
                    e.x * s / aspect,
                    e.y * s,
                    self.far * (e.z - self.near) / (e.z * (self.far - self.near)),
                )
            }
        };
        Some(Vec3::new(
            (x + 1.0) * 0.5 * self.width as f32,
            (1.0 - y) * 0.5 * self.height as f32,
            depth,
        ))
    }

    /// The unit vector from a world point towards the viewer.
    fn towards_viewer(&self, p: Vec3) -> Vec3 {
        match self.projection {
            Projection::Parallel => -self.dir,
            Projection::Perspective => (self.eye - p).normalize_or(-self.dir),
        }
    }
}

/// A light, as OpenGL's fixed-function lighting has it. Directional
/// lights only; `direction` points towards the light in eye coordinates
/// (x right, y up, z towards the viewer): lpfg's stationary lights.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Light {
    pub direction: Vec3,
    pub ambient: [f32; 3],
    pub diffuse: [f32; 3],
    pub specular: [f32; 3],
}

impl Default for Light {
    /// lpfg's default light: from the viewer, white, and its ambient 1 as
    /// lpfg's manual gives it.
    fn default() -> Self {
        Light {
            direction: Vec3::Z,
            ambient: [1.0; 3],
            diffuse: [1.0; 3],
            specular: [1.0; 3],
        }
    }
}

/// OpenGL's colour of a surface of `look` whose unit normal, in eye
/// coordinates, is `n`, under directional `lights` and the global
/// ambient light, without a local viewer: emission + ambient·global +
/// Σ (ambient·La + diffuse·Ld·max(0, n·l) + specular·Ls·max(0, n·h)^s,
/// the last only where n·l > 0, h the unit half-way vector of l and
/// (0, 0, 1)), each channel clamped to 0..=1.
pub fn lighting(look: &Look, n: Vec3, lights: &[Light], global_ambient: [f32; 3]) -> [f32; 3] {
    let mut c = [0.0f32; 3];
    for k in 0..3 {
        c[k] = look.emission[k] + look.ambient[k] * global_ambient[k];
    }
    for l in lights {
        let Some(dir) = l.direction.try_normalize() else {
            continue;
        };
        let diffuse = n.dot(dir).max(0.0);
        let specular = if diffuse > 0.0 && look.specular != [0.0; 3] {
            let h = (dir + Vec3::Z).normalize_or_zero();
            n.dot(h).max(0.0).powf(look.shininess)
        } else {
            0.0
        };
        for (k, ck) in c.iter_mut().enumerate() {
            *ck += look.ambient[k] * l.ambient[k]
                + look.diffuse[k] * l.diffuse[k] * diffuse
                + look.specular[k] * l.specular[k] * specular;
        }
    }
    c.map(|v| v.clamp(0.0, 1.0))
}

/// How the colour of a point follows from its normal.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Shading {
    /// Lit by the lights (the default).
    #[default]
    Lit,
    /// The look's diffuse colour plus its emission, unlit: lpfg's
    /// `render mode: filled` (its default), where OpenGL's lighting is off.
    Unlit,
    /// A normal map: the unit normal of the visible side, `(n + 1) / 2` as
    /// red, green and blue.
    Normals,
    /// Reflection lines: the view direction mirrored in the surface, read
    /// against a room of parallel black and white stripes.
    Reflection,
}

impl Shading {
    /// By name: `lit`, `normals` or `reflection`.
    pub fn from_name(name: &str) -> Option<Shading> {
        match name {
            "lit" => Some(Shading::Lit),
            "normals" => Some(Shading::Normals),
            "reflection" => Some(Shading::Reflection),
            _ => None,
        }
    }
}

/// Polygon outlines drawn over the picture: where the polygon seen at a
/// sample differs from the one seen at a neighbouring sample (or the
/// background), so edges are hidden where surfaces hide them.
#[derive(Clone, Debug, PartialEq)]
pub struct Wireframe {
    pub color: Rgba,
    /// The polygon of each triangle, numbered over the scene's meshes in
    /// order (the triangles of mesh 0, then of mesh 1, …).
    pub polygons: Vec<u32>,
    /// Lines a sample wide on both sides of an edge (`true`), or on one
    /// side only (half as wide).
    pub wide: bool,
}

/// Everything a picture of a [`Scene3`] needs besides the scene.
#[derive(Clone, Debug, PartialEq)]
pub struct RasterOptions {
    pub camera: Camera,
    pub background: Rgba,
    /// Lights in eye coordinates.
    pub lights: Vec<Light>,
    /// OpenGL's global ambient light (0.2 by default).
    pub global_ambient: [f32; 3],
    pub shading: Shading,
    /// Samples per pixel side (1 to 4): 2 gives 4 samples a pixel. A huge
    /// image gets fewer, so that its buffers stay within 2^26 samples
    /// (512 MiB).
    pub samples: u32,
    /// The look of each mesh's back faces (OpenGL's `GL_BACK` material);
    /// `None`: the same look on both sides. Back faces are lit with the
    /// flipped normal either way.
    pub back_looks: Option<Vec<Look>>,
    pub wireframe: Option<Wireframe>,
}

impl RasterOptions {
    /// lpfg's defaults for a camera: white background, one light from the
    /// viewer, global ambient 0.2, lit, 2×2 samples a pixel.
    pub fn new(camera: Camera) -> RasterOptions {
        RasterOptions {
            camera,
            background: Rgba(255, 255, 255, 255),
            lights: vec![Light::default()],
            global_ambient: [0.2; 3],
            shading: Shading::Lit,
            samples: 2,
            back_looks: None,
            wireframe: None,
        }
    }
}

/// The most triangles one picture takes (indices must leave room for the
/// "no triangle" key).
pub const MAX_TRIANGLES: usize = u32::MAX as usize - 1;

/// Checks that `scene` can be drawn: a look per mesh, at least one
/// triangle, finite positions and normals, indices in range, one normal
/// per vertex or none.
pub fn validate(scene: &Scene3) -> Result<(), RenderError> {
    if scene.looks.len() != scene.meshes.len() {
        return Err(RenderError::new(format!(
            "the scene has {} looks for {} meshes",
            scene.looks.len(),
            scene.meshes.len()
        )));
    }
    let triangles = scene.triangle_count();
    let lines = scene.line_count();
    if triangles == 0 && lines == 0 {
        return Err(RenderError::new(
            "nothing to draw: the scene has no triangle",
        ));
    }
    if triangles + lines > MAX_TRIANGLES {
        return Err(RenderError::new(format!(
            "the scene has {triangles} triangles and {lines} lines, more than the {MAX_TRIANGLES} one picture takes"
        )));
    }
    for (k, m) in scene.meshes.iter().enumerate() {
        let name = &scene.looks[k].name;
        if let Some(v) = m.positions.iter().position(|p| !p.is_finite()) {
            let p = m.positions[v];
            return Err(RenderError::new(format!(
                "vertex {v} of mesh {k} (`{name}`) has a non-finite position ({}, {}, {})",
                p.x, p.y, p.z
            )));
        }
        if !m.normals.is_empty() && m.normals.len() != m.positions.len() {
            return Err(RenderError::new(format!(
                "mesh {k} (`{name}`) has {} normals for {} vertices",
                m.normals.len(),
                m.positions.len()
            )));
        }
        if let Some(l) = m
            .lines
            .iter()
            .position(|l| !(l.a.is_finite() && l.b.is_finite() && l.width.is_finite()))
        {
            return Err(RenderError::new(format!(
                "line {l} of mesh {k} (`{name}`) has a non-finite end or width"
            )));
        }
        if let Some(v) = m.normals.iter().position(|n| !n.is_finite()) {
            return Err(RenderError::new(format!(
                "vertex {v} of mesh {k} (`{name}`) has a non-finite normal"
            )));
        }
        let n = m.positions.len();
        if let Some((t, tri)) = m
            .triangles
            .iter()
            .enumerate()
            .find(|(_, t)| t.iter().any(|&i| i as usize >= n))
        {
            return Err(RenderError::new(format!(
                "triangle {t} of mesh {k} (`{name}`) refers to vertex {}, but the mesh has {n} vertices",
                tri.iter().find(|&&i| i as usize >= n).copied().unwrap_or(0)
            )));
        }
    }
    Ok(())
}

/// A projected vertex, in sample units (sample centres at integers).
#[derive(Clone, Copy, Debug)]
struct Screen {
    x: f32,
    y: f32,
    /// Depth 0..=1; NaN where the vertex cannot be projected (behind the
    /// eye or out of the depth range).
    z: f32,
    /// 1 / distance (perspective) or 1 (parallel), for perspective-correct
    /// interpolation.
    inv_w: f32,
}

/// What the passes share: the scene projected.
struct Frame<'a> {
    scene: &'a Scene3,
    opts: &'a RasterOptions,
    /// The first global triangle index of each mesh, and the total last.
    tri_start: Vec<u32>,
    /// The first global index of each mesh's lines, and the total last:
    /// lines are numbered after every triangle.
    line_start: Vec<u32>,
    /// The first projected vertex of each mesh.
    vert_start: Vec<usize>,
    screen: Vec<Screen>,
    /// Samples per pixel side, and the sample grid's size.
    s: u32,
    sw: usize,
    sh: usize,
}

impl<'a> Frame<'a> {
    fn new(scene: &'a Scene3, opts: &'a RasterOptions) -> Frame<'a> {
        let cam = &opts.camera;
        // Fewer samples a pixel for a huge image, so that the buffers stay
        // within MAX_SAMPLES (8 bytes each).
        let pixels = cam.width as usize * cam.height as usize;
        let s = (1..=opts.samples.clamp(1, 4))
            .rev()
            .find(|s| pixels * (s * s) as usize <= MAX_SAMPLES)
            .unwrap_or(1);
        let (sw, sh) = ((cam.width * s) as usize, (cam.height * s) as usize);
        let mut tri_start = Vec::with_capacity(scene.meshes.len() + 1);
        let mut vert_start = Vec::with_capacity(scene.meshes.len() + 1);
        let (mut t, mut v) = (0u32, 0usize);
        for m in &scene.meshes {
            tri_start.push(t);
            vert_start.push(v);
            t += m.triangles.len() as u32;
            v += m.positions.len();
        }
        tri_start.push(t);
        vert_start.push(v);
        let mut line_start = Vec::with_capacity(scene.meshes.len() + 1);
        for m in &scene.meshes {
            line_start.push(t);
            t += m.lines.len() as u32;
        }
        line_start.push(t);
        let sf = s as f32;
        let project = |p: &Vec3| project(cam, sf, *p);
        let mut screen = Vec::with_capacity(v);
        for m in &scene.meshes {
            if m.positions.len() >= 1 << 16 {
                let start = screen.len();
                screen.resize(
                    start + m.positions.len(),
                    Screen {
                        x: 0.0,
                        y: 0.0,
                        z: 0.0,
                        inv_w: 0.0,
                    },
                );
                screen[start..]
                    .par_chunks_mut(1 << 14)
                    .zip(m.positions.par_chunks(1 << 14))
                    .for_each(|(out, ps)| {
                        for (o, p) in out.iter_mut().zip(ps) {
                            *o = project(p);
                        }
                    });
            } else {
                screen.extend(m.positions.iter().map(project));
            }
        }
        Frame {
            scene,
            opts,
            tri_start,
            line_start,
            vert_start,
            screen,
            s,
            sw,
            sh,
        }
    }

    /// The mesh of a global line index and the index within it.
    fn locate_line(&self, id: u32) -> (usize, usize) {
        let k = self.line_start.partition_point(|&s| s <= id) - 1;
        (k, (id - self.line_start[k]) as usize)
    }

    /// The mesh of a global triangle index and the index within it.
    fn locate(&self, id: u32) -> (usize, usize) {
        let k = self.tri_start.partition_point(|&s| s <= id) - 1;
        (k, (id - self.tri_start[k]) as usize)
    }

    /// Rasterises the triangles and lines with global indices in `range`
    /// into a depth and triangle buffer.
    fn raster_range(&self, range: std::ops::Range<usize>, depth: &mut [f32], ids: &mut [u32]) {
        let triangles = *self.tri_start.last().unwrap_or(&0) as usize;
        // Triangles first, then lines: each sample keeps the first of equal
        // depths, so the smallest index, as the merge of threads' buffers
        // does.
        let tris = range.start..range.end.min(triangles);
        if !tris.is_empty() {
            self.raster_triangles(tris, depth, ids);
        }
        if range.end > triangles {
            let sf = self.s as f32;
            let cam = &self.opts.camera;
            let lines = range.start.max(triangles)..range.end;
            let mut k = self.locate_line(lines.start as u32).0;
            for id in lines {
                while self.line_start[k + 1] as usize <= id {
                    k += 1;
                }
                let l = self.scene.meshes[k].lines[id - self.line_start[k] as usize];
                let (a, b) = (project(cam, sf, l.a), project(cam, sf, l.b));
                // The width in samples where the line starts.
                let side = project(cam, sf, l.a + cam.up * l.width);
                let width = (side.x - a.x).hypot(side.y - a.y);
                raster_line(depth, ids, self.sw, self.sh, [a, b], width, id as u32);
            }
        }
    }

    /// The triangles of `range` (global indices).
    fn raster_triangles(&self, range: std::ops::Range<usize>, depth: &mut [f32], ids: &mut [u32]) {
        let mut k = self.locate(range.start as u32).0;
        let mut id = range.start;
        while id < range.end {
            while self.tri_start[k + 1] as usize <= id {
                k += 1;
            }
            let m = &self.scene.meshes[k];
            let base = self.vert_start[k];
            let first = id - self.tri_start[k] as usize;
            let last = (range.end - self.tri_start[k] as usize).min(m.triangles.len());
            for (t, tri) in m.triangles[first..last].iter().enumerate() {
                let v = tri.map(|i| self.screen[base + i as usize]);
                raster_triangle(depth, ids, self.sw, self.sh, v, (id + t) as u32);
            }
            id += last - first;
        }
    }

    /// Every sample's nearest triangle (`NO_TRIANGLE` where none), the
    /// smallest (depth, index) over all triangles that cover it.
    fn raster(&self) -> Vec<u32> {
        let total = *self.line_start.last().unwrap_or(&0) as usize;
        let n = self.sw * self.sh;
        let (mut depth, mut ids) = buffers(n);
        // One more pair of buffers per thread, within 2·MAX_SAMPLES in all.
        let threads = rayon::current_num_threads()
            .clamp(1, 8)
            .min((2 * MAX_SAMPLES / n).max(1));
        if total < 1 << 16 || threads == 1 {
            self.raster_range(0..total, &mut depth, &mut ids);
            return ids;
        }
        let chunk = total.div_ceil(threads);
        let mut others: Vec<(Vec<f32>, Vec<u32>)> = Vec::new();
        rayon::scope(|scope| {
            others.resize_with(threads - 1, Default::default);
            for (j, (d, i)) in others.iter_mut().enumerate() {
                let range = (j + 1) * chunk..((j + 2) * chunk).min(total);
                scope.spawn(move |_| {
                    (*d, *i) = buffers(n);
                    self.raster_range(range, d, i);
                });
            }
            self.raster_range(0..chunk.min(total), &mut depth, &mut ids);
        });
        // The smallest (depth, index) wins, whichever chunk drew it.
        depth
            .par_chunks_mut(1 << 14)
            .zip(ids.par_chunks_mut(1 << 14))
            .enumerate()
            .for_each(|(c, (d, i))| {
                let at = c << 14;
                for (od, oi) in &others {
                    let (od, oi) = (&od[at..at + d.len()], &oi[at..at + i.len()]);
                    for k in 0..d.len() {
                        if (od[k], oi[k]) < (d[k], i[k]) {
                            d[k] = od[k];
                            i[k] = oi[k];
                        }
                    }
                }
            });
        ids
    }
}

/// A depth and a triangle buffer of `n` samples, nothing drawn, in huge
/// pages: a line or a tall triangle steps from row to row, a page apart
/// with small pages.
fn buffers(n: usize) -> (Vec<f32>, Vec<u32>) {
    let mut depth = crate::huge::with_capacity(n);
    depth.resize(n, FAR);
    let mut ids = crate::huge::with_capacity(n);
    ids.resize(n, NO_TRIANGLE);
    (depth, ids)
}

/// The most samples a picture's depth and triangle buffers hold (8 bytes
/// each): 2×2 samples a pixel up to 4096×4096 pixels, fewer beyond.
const MAX_SAMPLES: usize = 1 << 26;

/// The depth buffer's value where nothing was drawn: just past the far
/// plane (1), so that `d < FAR` keeps every depth in 0..=1.
const FAR: f32 = 1.000_000_1;

/// The triangle buffer's value where nothing was drawn.
const NO_TRIANGLE: u32 = u32::MAX;

/// The smallest integer at least `v` (`v` finite and within `i32`),
/// without a call to `ceilf` on targets without SSE4.1.
#[inline(always)]
fn ceil_i(v: f32) -> i32 {
    let i = v as i32;
    if (i as f32) < v {
        i + 1
    } else {
        i
    }
}

/// The largest integer at most `v` (as [`ceil_i`]).
#[inline(always)]
fn floor_i(v: f32) -> i32 {
    let i = v as i32;
    if (i as f32) > v {
        i - 1
    } else {
        i
    }
}

/// Where `p` lands on the sample grid of `sf` samples a pixel side (sample
/// centres at integers), NaN where it is not in view.
fn project(cam: &Camera, sf: f32, p: Vec3) -> Screen {
    match cam.pixel(p) {
        Some(q) if (-1e-6..=1.0 + 1e-6).contains(&q.z) && q.x.is_finite() && q.y.is_finite() => {
            let inv_w = match cam.projection {
                Projection::Parallel => 1.0,
                Projection::Perspective => 1.0 / cam.eye_coords(p).z,
            };
            Screen {
                x: q.x * sf - 0.5,
                y: q.y * sf - 0.5,
                z: q.z.clamp(0.0, 1.0) + 0.0,
                inv_w,
            }
        }
        _ => Screen {
            x: f32::NAN,
            y: f32::NAN,
            z: f32::NAN,
            inv_w: f32::NAN,
        },
    }
}

/// One line into the key buffer, one sample wide: the samples nearest to
/// evenly spaced points of it, one per sample step along its longer axis,
/// both ends included, with the depth interpolated as a triangle's is;
/// for a tube `width` samples across, under one, each sample with the
/// chance that the tube covers it. A
/// NaN end (not in view) drops it; it is clipped to the grid first, so the
/// steps are at most the grid's width and height.
fn raster_line(
    depth: &mut [f32],
    ids: &mut [u32],
    sw: usize,
    sh: usize,
    [a, b]: [Screen; 2],
    width: f32,
    id: u32,
) {
    if [a.x, a.y, a.z, b.x, b.y, b.z, width]
        .iter()
        .any(|v| v.is_nan())
    {
        return;
    }
    let (dx, dy, dz) = (b.x - a.x, b.y - a.y, b.z - a.z);
    // Liang–Barsky against the grid, half a sample beyond its centres.
    let (mut t0, mut t1) = (0.0f32, 1.0f32);
    for (p, q) in [
        (-dx, a.x + 0.5),
        (dx, sw as f32 - 0.5 - a.x),
        (-dy, a.y + 0.5),
        (dy, sh as f32 - 0.5 - a.y),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return;
            }
        } else {
            let r = q / p;
            if !r.is_finite() {
                return;
            }
            if p < 0.0 {
                t0 = t0.max(r);
            } else {
                t1 = t1.min(r);
            }
        }
    }
    if t0 > t1 {
        return;
    }
    let steps = (dx.abs().max(dy.abs()) * (t1 - t0)).ceil().max(1.0) as usize;
    let inv = (t1 - t0) / steps as f32;
    // The chance that the tube covers a sample drawn: its area over the
    // samples drawn (steps + 1, both ends), at most one; a hash of the
    // line and the step draws the lot, so the samples taken do not depend
    // on the order of drawing or the threads.
    let area = width * dx.hypot(dy) * (t1 - t0);
    let chance = (area / (steps + 1) as f32).min(1.0);
    let threshold = (chance as f64 * 4_294_967_296.0) as u64;
    for i in 0..=steps {
        if threshold < 1 << 32 && (lot(id, i as u32) as u64) >= threshold {
            continue;
        }
        let t = t0 + i as f32 * inv;
        // The nearest sample, halves rounded up; clipping keeps the point
        // within half a sample of the grid, so the sums are not negative
        // and truncation rounds.
        let (x, y) = ((a.x + dx * t + 0.5) as usize, (a.y + dy * t + 0.5) as usize);
        if x >= sw || y >= sh {
            continue;
        }
        let d = a.z + dz * t;
        let k = y * sw + x;
        if d >= 0.0 && d < depth[k] {
            depth[k] = d;
            ids[k] = id;
        }
    }
}

/// A well-mixed number from a line's index and a step along it
/// (splitmix64's finaliser).
fn lot(id: u32, step: u32) -> u32 {
    let mut z = ((id as u64) << 32 | step as u64).wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    (z ^ (z >> 31)) as u32
}

/// One triangle into the key buffer. `v` in sample units (sample centres
/// at integers); a NaN coordinate (unprojectable vertex) drops it.
///
/// Each row starts from the edge functions evaluated exactly there in
/// `f64` (from the canonical coefficients) and rounded to `f32`; a sample
/// adds its column offset times the edge's `x` coefficient. Rounding is
/// symmetric, so the two triangles of a shared edge still see exactly
/// opposite values at every sample, and no sample is lost between them.
#[inline]
fn raster_triangle(
    depth: &mut [f32],
    ids: &mut [u32],
    sw: usize,
    sh: usize,
    v: [Screen; 3],
    id: u32,
) {
    let lo_x = v[0].x.min(v[1].x).min(v[2].x).max(-1.0);
    let hi_x = v[0].x.max(v[1].x).max(v[2].x).min(sw as f32);
    let lo_y = v[0].y.min(v[1].y).min(v[2].y).max(-1.0);
    let hi_y = v[0].y.max(v[1].y).max(v[2].y).min(sh as f32);
    // NaN fails these too.
    if !(lo_x <= hi_x && lo_y <= hi_y) {
        return;
    }
    let (x0, x1) = (ceil_i(lo_x).max(0), floor_i(hi_x).min(sw as i32 - 1));
    let (y0, y1) = (ceil_i(lo_y).max(0), floor_i(hi_y).min(sh as i32 - 1));
    if x0 > x1 || y0 > y1 || v.iter().any(|p| p.z.is_nan()) {
        return;
    }
    let p = v.map(|q| (q.x as f64, q.y as f64));
    let area = (p[1].0 - p[0].0) * (p[2].1 - p[0].1) - (p[1].1 - p[0].1) * (p[2].0 - p[0].0);
    if area == 0.0 || !area.is_finite() {
        return;
    }
    let orient = area.signum();
    // Edge k is opposite vertex k: its function is that vertex's
    // barycentric weight times the area.
    let e = [
        edge(p[1], p[2], orient),
        edge(p[2], p[0], orient),
        edge(p[0], p[1], orient),
    ];
    // The depth plane z = dzx·x + dzy·y + dzc, from the weights.
    let inv = 1.0 / area.abs();
    let z = [v[0].z as f64, v[1].z as f64, v[2].z as f64];
    let dzx = (e[0].0 * z[0] + e[1].0 * z[1] + e[2].0 * z[2]) * inv;
    let dzy = (e[0].1 * z[0] + e[1].1 * z[1] + e[2].1 * z[2]) * inv;
    let dzc = (e[0].2 * z[0] + e[1].2 * z[1] + e[2].2 * z[2]) * inv;
    let a = [e[0].0 as f32, e[1].0 as f32, e[2].0 as f32];
    let dz = dzx as f32;
    let fx0 = x0 as f64;
    for y in y0..=y1 {
        let fy = y as f64;
        let r = [
            (e[0].0 * fx0 + e[0].1 * fy + e[0].2) as f32,
            (e[1].0 * fx0 + e[1].1 * fy + e[1].2) as f32,
            (e[2].0 * fx0 + e[2].1 * fy + e[2].2) as f32,
        ];
        let zr = (dzx * fx0 + dzy * fy + dzc) as f32;
        let span = y as usize * sw + x0 as usize..=y as usize * sw + x1 as usize;
        let (zs, is) = (&mut depth[span.clone()], &mut ids[span]);
        // Branch-free, so that it vectorises: a sample takes the triangle
        // where it is inside and nearer (an earlier triangle keeps a tie).
        for (k, (zk, ik)) in zs.iter_mut().zip(is.iter_mut()).enumerate() {
            let fk = k as f32;
            let w0 = r[0] + fk * a[0];
            let w1 = r[1] + fk * a[1];
            let w2 = r[2] + fk * a[2];
            let d = zr + fk * dz;
            let take = (w0 >= 0.0) & (w1 >= 0.0) & (w2 >= 0.0) & (d >= 0.0) & (d < *zk);
            *zk = if take { d } else { *zk };
            *ik = if take { id } else { *ik };
        }
    }
}

/// The edge function of the edge from `a` to `b` as (A, B, C) with
/// `A·x + B·y + C` = the cross product (b - a) × (p - a), times `orient`:
/// computed from the lexicographically smaller end, so that the edge
/// `b → a` of a neighbour gets the exact negation.
#[inline]
fn edge(a: (f64, f64), b: (f64, f64), orient: f64) -> (f64, f64, f64) {
    let (p, q, s) = if a <= b {
        (a, b, orient)
    } else {
        (b, a, -orient)
    };
    let (ca, cb) = (p.1 - q.1, q.0 - p.0);
    let cc = -(ca * p.0 + cb * p.1);
    (ca * s, cb * s, cc * s)
}

/// Stripes per unit of the mirrored view direction's height.
const STRIPES: f32 = 6.0;

impl Frame<'_> {
    /// The colour of triangle `id` at sample position `(x, y)` (sample
    /// units, centres at integers), opaque.
    fn shade(&self, id: u32, x: f32, y: f32) -> [f32; 3] {
        if id >= *self.tri_start.last().unwrap_or(&0) {
            let (k, l) = self.locate_line(id);
            return line_colour(self.scene, self.opts, k, &self.scene.meshes[k].lines[l]);
        }
        let (k, t) = self.locate(id);
        let m = &self.scene.meshes[k];
        let tri = m.triangles[t];
        let w = if m.normals.is_empty() {
            [1.0 / 3.0; 3]
        } else {
            let base = self.vert_start[k];
            barycentric(tri.map(|i| self.screen[base + i as usize]), x, y)
        };
        colour(self.scene, self.opts, k, tri, w)
    }

    /// The polygon a sample shows (`u32::MAX` for the background) when
    /// there is a wireframe.
    fn polygon(&self, w: &Wireframe, id: u32) -> u32 {
        if id == NO_TRIANGLE {
            u32::MAX
        } else {
            w.polygons.get(id as usize).copied().unwrap_or(u32::MAX - 1)
        }
    }

    /// The premultiplied RGBA8 pixels.
    fn resolve(&self, keys: &[u32]) -> Vec<u8> {
        let cam = &self.opts.camera;
        let (w, h) = (cam.width as usize, cam.height as usize);
        let s = self.s as usize;
        let bg = self.opts.background;
        let bg_alpha = bg.3 as f32 / 255.0;
        let bgp = [
            bg.0 as f32 / 255.0 * bg_alpha,
            bg.1 as f32 / 255.0 * bg_alpha,
            bg.2 as f32 / 255.0 * bg_alpha,
            bg_alpha,
        ];
        let edge = self.opts.wireframe.as_ref().map(|wf| {
            let c = wf.color;
            (wf, [c.0, c.1, c.2].map(|v| v as f32 / 255.0))
        });
        let inv = 1.0 / (s * s) as f32;
        // The bytes of a pixel whose samples all show the background, summed
        // as any pixel's samples are.
        let bg_bytes = {
            let mut sum = [0.0f32; 4];
            for _ in 0..s * s {
                for (a, b) in sum.iter_mut().zip(bgp) {
                    *a += b;
                }
            }
            sum.map(|v| to_byte(v * inv * 255.0))
        };
        let triangles = *self.tri_start.last().unwrap_or(&0);
        let mut out = vec![0u8; w * h * 4];
        out.par_chunks_mut(w * 4).enumerate().for_each(|(py, row)| {
            // Shading once per pixel and triangle, at the pixel's centre
            // (as multisampling does): the distinct triangles of a pixel's
            // samples, at most s² of them.
            let mut seen: Vec<(u32, [f32; 3])> = Vec::with_capacity(s * s);
            // A line's colour is the same wherever it is seen (it does not
            // depend on the pixel): the last few of a row are kept.
            let mut lines = [(NO_TRIANGLE, [0.0f32; 3]); LINE_CACHE];
            let centre = (s as f32 - 1.0) * 0.5;
            for px in 0..w {
                // A pixel of background only: the background's bytes.
                if edge.is_none()
                    && (0..s).all(|j| {
                        let at = (py * s + j) * self.sw + px * s;
                        keys[at..at + s].iter().all(|&k| k == NO_TRIANGLE)
                    })
                {
                    row[px * 4..px * 4 + 4].copy_from_slice(&bg_bytes);
                    continue;
                }
                seen.clear();
                let mut sum = [0.0f32; 4];
                let (cx, cy) = ((px * s) as f32 + centre, (py * s) as f32 + centre);
                for j in 0..s {
                    for i in 0..s {
                        let (sx, sy) = (px * s + i, py * s + j);
                        let key = keys[sy * self.sw + sx];
                        if let Some((wf, ec)) = &edge {
                            let g = self.polygon(wf, key);
                            let differs = |dx: isize, dy: isize| {
                                let (nx, ny) = (sx as isize + dx, sy as isize + dy);
                                if nx < 0
                                    || ny < 0
                                    || nx >= self.sw as isize
                                    || ny >= self.sh as isize
                                {
                                    return false;
                                }
                                self.polygon(wf, keys[ny as usize * self.sw + nx as usize]) != g
                            };
                            let on_edge = differs(1, 0)
                                || differs(0, 1)
                                || (wf.wide && (differs(-1, 0) || differs(0, -1)));
                            if on_edge {
                                sum[0] += ec[0];
                                sum[1] += ec[1];
                                sum[2] += ec[2];
                                sum[3] += 1.0;
                                continue;
                            }
                        }
                        if key == NO_TRIANGLE {
                            for (a, b) in sum.iter_mut().zip(bgp) {
                                *a += b;
                            }
                            continue;
                        }
                        let id = key;
                        let c = if id >= triangles {
                            let slot = &mut lines[id as usize % LINE_CACHE];
                            if slot.0 != id {
                                *slot = (id, self.shade(id, cx, cy));
                            }
                            slot.1
                        } else {
                            match seen.iter().find(|(t, _)| *t == id) {
                                Some((_, c)) => *c,
                                None => {
                                    let c = self.shade(id, cx, cy);
                                    seen.push((id, c));
                                    c
                                }
                            }
                        };
                        sum[0] += c[0];
                        sum[1] += c[1];
                        sum[2] += c[2];
                        sum[3] += 1.0;
                    }
                }
                for (k, v) in sum.iter().enumerate() {
                    row[px * 4 + k] = to_byte(v * inv * 255.0);
                }
            }
        });
        out
    }
}

/// The perspective-correct barycentric weights of sample position
/// `(x, y)` in a projected triangle (extrapolated outside it).
fn barycentric(s: [Screen; 3], x: f32, y: f32) -> [f32; 3] {
    let area = (s[1].x - s[0].x) * (s[2].y - s[0].y) - (s[1].y - s[0].y) * (s[2].x - s[0].x);
    if area == 0.0 || !area.is_finite() {
        return [1.0 / 3.0; 3];
    }
    let w = |a: Screen, b: Screen| ((b.x - a.x) * (y - a.y) - (b.y - a.y) * (x - a.x)) / area;
    let lin = [w(s[1], s[2]), w(s[2], s[0]), w(s[0], s[1])];
    let p = [
        lin[0] * s[0].inv_w,
        lin[1] * s[1].inv_w,
        lin[2] * s[2].inv_w,
    ];
    let sum = p[0] + p[1] + p[2];
    if sum == 0.0 || !sum.is_finite() {
        return lin;
    }
    p.map(|v| v / sum)
}

/// The colour of triangle `tri` of mesh `k` at the point of barycentric
/// weights `w` (they interpolate its vertex normals, where it has them):
/// lit, two-sided (a face turned away from the viewer is lit with the
/// flipped normal, and with its back look where there is one), or the
/// normal map or reflection lines.
fn colour(scene: &Scene3, opts: &RasterOptions, k: usize, tri: [u32; 3], w: [f32; 3]) -> [f32; 3] {
    let m = &scene.meshes[k];
    let cam = &opts.camera;
    let [a, b, c] = tri.map(|i| m.positions[i as usize]);
    let geometric = (b - a).cross(c - a);
    let centroid = (a + b + c) / 3.0;
    let back = geometric.dot(cam.towards_viewer(centroid)) < 0.0;
    let flat = geometric.normalize_or_zero();
    let mut n = if m.normals.is_empty() {
        flat
    } else {
        (m.normals[tri[0] as usize] * w[0]
            + m.normals[tri[1] as usize] * w[1]
            + m.normals[tri[2] as usize] * w[2])
            .normalize_or(flat)
    };
    if back {
        n = -n;
    }
    lit(scene, opts, k, n, back)
}

/// The colour of line `line` of mesh `k` (a tube thinner than a sample):
/// lit as the side of the tube that faces the viewer, whose normal is the
/// direction to the viewer made perpendicular to the line.
fn line_colour(scene: &Scene3, opts: &RasterOptions, k: usize, line: &Line) -> [f32; 3] {
    let (a, b) = (line.a, line.b);
    let v = opts.camera.towards_viewer((a + b) * 0.5);
    let t = (b - a).normalize_or_zero();
    let n = (v - t * t.dot(v)).normalize_or(v);
    lit(scene, opts, k, n, false)
}

/// `v` rounded to the nearest integer (halves away from zero) and clamped
/// to 0..=255, as `v.round().clamp(0.0, 255.0) as u8` (0 for NaN), without
/// a call to `roundf` on targets without SSE4.1.
#[inline(always)]
pub(super) fn to_byte(v: f32) -> u8 {
    let v = v.clamp(0.0, 255.0);
    // Exact: the integer part and the fraction of a number below 2^23.
    let t = v as u32;
    (t + u32::from(v - t as f32 >= 0.5)) as u8
}

/// The lines' colours a row of [`Frame::resolve`] keeps, by line index.
const LINE_CACHE: usize = 32;

/// The colour of a point of mesh `k` whose unit normal, turned to the
/// viewer, is `n`; `back`: the point is on the side that faced away.
fn lit(scene: &Scene3, opts: &RasterOptions, k: usize, n: Vec3, back: bool) -> [f32; 3] {
    let cam = &opts.camera;
    match opts.shading {
        Shading::Lit => {
            let look = match (&opts.back_looks, back) {
                (Some(b), true) => b.get(k).unwrap_or(&scene.looks[k]),
                _ => &scene.looks[k],
            };
            let eye_n = Vec3::new(n.dot(cam.right), n.dot(cam.up), -n.dot(cam.dir));
            lighting(look, eye_n, &opts.lights, opts.global_ambient)
        }
        Shading::Unlit => {
            let look = &scene.looks[k];
            [0, 1, 2].map(|i| (look.diffuse[i] + look.emission[i]).clamp(0.0, 1.0))
        }
        Shading::Normals => ((n + Vec3::ONE) * 0.5).to_array(),
        Shading::Reflection => reflection(n, cam.dir, cam.up),
    }
}

/// The colour of the stripe that the view direction `dir`, mirrored in a
/// surface of unit normal `n` (its visible side), meets: stripes run
/// across the screen's `up` direction, so a plane facing the viewer shows
/// one colour.
pub fn reflection(n: Vec3, dir: Vec3, up: Vec3) -> [f32; 3] {
    let r = dir - 2.0 * dir.dot(n) * n;
    let stripe = ((r.dot(up) + 1.0) * STRIPES).floor() as i64;
    if stripe.rem_euclid(2) == 0 {
        [250.0 / 255.0; 3]
    } else {
        [30.0 / 255.0, 34.0 / 255.0, 44.0 / 255.0]
    }
}

/// A rendered picture: premultiplied RGBA8 pixels, row by row from the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<u8>,
}

impl Image {
    /// The pixel at column `x`, row `y` (premultiplied RGBA).
    pub fn pixel(&self, x: u32, y: u32) -> [u8; 4] {
        let i = (y as usize * self.width as usize + x as usize) * 4;
        [
            self.pixels[i],
            self.pixels[i + 1],
            self.pixels[i + 2],
            self.pixels[i + 3],
        ]
    }

    /// Encodes the picture as PNG.
    pub fn encode_png(&self) -> Result<Vec<u8>, RenderError> {
        let size = tiny_skia::IntSize::from_wh(self.width, self.height)
            .ok_or_else(|| RenderError::new("cannot make an image of that size"))?;
        let pm = tiny_skia::Pixmap::from_vec(self.pixels.clone(), size)
            .ok_or_else(|| RenderError::new("cannot make an image of that size"))?;
        pm.encode_png()
            .map_err(|e| RenderError::new(format!("cannot encode the PNG: {e}")))
    }
}

/// Draws `scene` with the z-buffer (after [`validate`]). Triangles are not
/// clipped: one with a corner before the near plane or past the far one
/// is left out (a camera from [`Camera::from_view`] keeps the whole box
/// between them, unless a `shift` puts the eye inside it).
pub fn render(scene: &Scene3, opts: &RasterOptions) -> Result<Image, RenderError> {
    let cam = &opts.camera;
    check_size(cam.width, cam.height)?;
    validate(scene)?;
    if let Some(w) = &opts.wireframe {
        if w.polygons.len() != scene.triangle_count() {
            return Err(RenderError::new(format!(
                "the wireframe names polygons for {} triangles, but the scene has {}",
                w.polygons.len(),
                scene.triangle_count()
            )));
        }
    }
    // Between the phases: nothing more once the run's deadline passed.
    let deadline = || crate::deadline::check(crate::deadline::current()).map_err(RenderError::new);
    deadline()?;
    let frame = Frame::new(scene, opts);
    deadline()?;
    let ids = frame.raster();
    deadline()?;
    let pixels = frame.resolve(&ids);
    deadline()?;
    Ok(Image {
        width: cam.width,
        height: cam.height,
        pixels,
    })
}

/// Draws `scene` with the z-buffer and encodes it as PNG.
pub fn render_png(scene: &Scene3, opts: &RasterOptions) -> Result<Vec<u8>, RenderError> {
    render(scene, opts)?.encode_png()
}

/// `scene` as flat-shaded triangles for the SVG backend: each triangle
/// lit at its centroid (with its own normal, or its vertex normals'
/// mean), painted back to front by the depth of its centroid; a line is
/// a stroke as wide as its tube, placed by the depth of its middle. Where
/// triangles cross, or a far triangle's centroid lies before a near
/// one's, that order is wrong: SVG has no depth test, so the picture is an
/// approximation that the PNG is not. Each triangle is outlined in its own
/// colour (0.5 px) to close the antialiased seams between neighbours;
/// with a wireframe, the outlines are its colour.
pub fn polygons(scene: &Scene3, opts: &RasterOptions) -> Result<Scene, RenderError> {
    let cam = &opts.camera;
    check_size(cam.width, cam.height)?;
    validate(scene)?;
    let mut faces: Vec<(f32, Item)> = Vec::with_capacity(scene.triangle_count());
    for (k, m) in scene.meshes.iter().enumerate() {
        for tri in &m.triangles {
            let corners = tri.map(|i| m.positions[i as usize]);
            let Some(px) = in_view(cam, &corners) else {
                continue;
            };
            let area = (px[1].x - px[0].x) * (px[2].y - px[0].y)
                - (px[1].y - px[0].y) * (px[2].x - px[0].x);
            if area == 0.0 || !area.is_finite() {
                continue;
            }
            let c = colour(scene, opts, k, *tri, [1.0 / 3.0; 3]);
            let [r, g, b] = c.map(|v| (v * 255.0).round() as u8);
            let color = Rgba(r, g, b, 255);
            let outline = match &opts.wireframe {
                Some(w) => Outline {
                    color: w.color,
                    width: 0.6,
                },
                None => Outline { color, width: 0.5 },
            };
            let depth = corners.iter().map(|p| cam.eye_coords(*p).z).sum::<f32>();
            faces.push((
                depth,
                Item::Polygon {
                    points: px
                        .iter()
                        .map(|q| DVec2::new(q.x as f64, q.y as f64))
                        .collect(),
                    color,
                    outline: Some(outline),
                },
            ));
        }
    }
    for (k, m) in scene.meshes.iter().enumerate() {
        for line in &m.lines {
            let Some(px) = in_view(cam, &[line.a, line.b, line.a + cam.up * line.width]) else {
                continue;
            };
            let [r, g, b] = line_colour(scene, opts, k, line).map(|v| (v * 255.0).round() as u8);
            let depth = (cam.eye_coords(line.a).z + cam.eye_coords(line.b).z) * 1.5;
            // As wide as the tube: an antialiased stroke's coverage is its
            // ink.
            let width = (px[2] - px[0]).truncate().length() as f64;
            faces.push((
                depth,
                Item::Polyline {
                    points: px[..2]
                        .iter()
                        .map(|q| DVec2::new(q.x as f64, q.y as f64))
                        .collect(),
                    color: Rgba(r, g, b, 255),
                    width,
                },
            ));
        }
    }
    faces.sort_by(|a, b| b.0.total_cmp(&a.0));
    Ok(Scene {
        width: cam.width,
        height: cam.height,
        background: opts.background,
        items: faces.into_iter().map(|(_, i)| i).collect(),
    })
}

/// The pixels of `points`, `None` unless every one is within the depth
/// range drawn.
fn in_view(cam: &Camera, points: &[Vec3]) -> Option<Vec<Vec3>> {
    points
        .iter()
        .map(|p| {
            cam.pixel(*p)
                .filter(|q| (-1e-6..=1.0 + 1e-6).contains(&q.z))
        })
        .collect()
}

/// Draws `scene` as an SVG document of depth-sorted shaded triangles (see
/// [`polygons`]).
pub fn render_svg(scene: &Scene3, opts: &RasterOptions) -> Result<String, RenderError> {
    Ok(super::svg::render(&polygons(scene, opts)?))
}

#[cfg(test)]
mod tests {
    use super::to_byte;

    /// `to_byte` is the standard library's rounding and clamping, on every
    /// `f32` from -2 to 258 in steps of 1/4096 (every half among them),
    /// around each half by one unit in the last place, and on the
    /// specials.
    #[test]
    fn bytes_round_as_the_standard_library_rounds() {
        let std = |v: f32| v.round().clamp(0.0, 255.0) as u8;
        let mut values = vec![
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            -0.0,
            0.0,
            f32::MAX,
            f32::MIN,
            f32::MIN_POSITIVE,
            0.5f32.next_down(),
            254.5,
            255.49998,
            255.5,
        ];
        for k in -8192..=(258 * 4096) {
            let v = k as f32 / 4096.0;
            values.extend([v, v.next_up(), v.next_down()]);
        }
        for v in values {
            assert_eq!(to_byte(v), std(v), "{v:e}");
        }
    }
}
