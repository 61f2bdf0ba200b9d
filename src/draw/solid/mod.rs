//! The turtle's 3D geometry: the same walk as the 2D drawing
//! (`draw::walk`), with a sink that makes shaded triangle meshes
//! ([`Scene3`]) instead of events.
//!
//! What each module makes (lpfg's manual, §5.5 to §5.8 and §8.1.3):
//!
//! * Lines (`F`, `G`, `LineTo`, ...) with `line style: cylinder` are tubes
//!   of the turtle's width (radius: half the width; `ScaleContour(p, q)`
//!   makes them elliptic) with `contour sides` sides. Unlike lpfg, which
//!   draws every segment as its own cylinder, a line that goes on from
//!   where the last one of the same turtle ended, turning by at most 90
//!   degrees, shares the ring at the joint: its plane is perpendicular to
//!   the bisector of the two directions, and its axes are carried along
//!   the path by parallel transport (the smallest rotation from one
//!   direction to the next), so a tube neither cracks nor twists when the
//!   turtle rolls. A sharper turn, a move, or the end of a branch ends the
//!   tube with a ring perpendicular to its last direction. A branch starts
//!   a tube of its own; the parent's tube goes on after `EB`. With
//!   `capped cylinders: on` tube ends are closed by discs. With
//!   `line style: polygon` a line is a flat band of the line width facing
//!   the default viewer (+z); with `pixel` (the default) lines make no
//!   triangles, unless [`SolidOptions::pixel_tubes`] gives the model units
//!   of a pixel, which makes them tubes of that many units per pixel of
//!   width.
//! * Generalized cylinders (`StartGC`, `F` ..., `PointGC`, `EndGC`; only
//!   with `line style: cylinder`, as in lpfg) sweep the current contour
//!   (`CurrentContour`, `BlendedContour`; contour 0 is lpfg's circle) in
//!   the turtle's own frame at each point: a contour point (x, y) lies at
//!   x·p/2 along the turtle's left and y·q/2 along its up vector, (p, q)
//!   the width or `ScaleContour`. Consecutive sections share their ring,
//!   and a section keeps its shape wherever the turtle rolls, which is the
//!   only twist there is: the manual describes no other correction. A
//!   contour is sampled at its own `samples:` when its file gives them,
//!   else at the view file's `contour sides` (or `ContourSides`), fixed
//!   when the cylinder starts. `PointGC` moves the cylinder's last section
//!   to the turtle without drawing. Closed contours are capped at
//!   `StartGC` and `EndGC` with `capped cylinders: on`, by a fan from the
//!   centroid, as lpfg does without `concave polygons: on`.
//! * `Surface(id, s)` and `Surface3(id, sx, sy, sz)`: each Bézier patch
//!   of the `.s` file placed as in the 2D drawing (contact point at the
//!   turtle, heading and up on the turtle's) and cut into s × t quads (the
//!   view file's `sdiv tdiv`, `SetUPrecision`/`SetVPrecision`, else lpfg's
//!   10 × 10; s runs down the rows of control points, t along a row, as in
//!   lpfg's own OBJ output), with normals from the patch's derivatives.
//! * `Sphere(r)`, `Sphere0()`: `contour sides` slices and (sides + 1) / 2
//!   stacks about the turtle's heading. `Circle(r)`, `Circle0()`: discs in
//!   the HL plane; `CircleFront(r)`, `CircleFront0()`: in the plane facing
//!   +z (lpfg's default viewer); `CircleB`, `CircleFrontB`: rings from
//!   r − w/2 to r + w/2. The `0` kinds have the line width as diameter.
//! * Polygons (`SP` ... `EP`, `Rhombus`, `Triangle`): flat, cut into n − 2
//!   triangles by ear clipping in their plane (a polygon of more than
//!   [`MAX_EAR_CLIPPING`] points, or one that is not simple, is fanned
//!   from its first point).
//!
//! Every vertex has a normal. Discs, polygons and surfaces are sheets with
//! one normal side: a renderer lights both sides, as lpfg does. Each
//! colour index is one [`Look`]: the model's material or colour map entry,
//! else the default palette; each look is one mesh.

use glam::{DQuat, DVec3, Vec3};

use super::{walk, DrawError, DrawOptions, Round, Shaping, Sink, Turtle};
use crate::lang::value::StructDef;
use crate::lang::Alphabet;
use crate::model::view::{LineStyle, DEFAULT_CONTOUR_SIDES, MAX_CONTOUR_SIDES, MIN_CONTOUR_SIDES};
use crate::model::{Colours, Contour, Model};
use crate::rewrite::Word;
use crate::scene3::{Line, Look, Scene3, TriMesh};

/// The default limit on the triangles of one scene: 40 million (about a
/// gigabyte with their vertices).
pub const MAX_TRIANGLES: usize = 40_000_000;
/// The default limit on the vertices of one scene.
pub const MAX_VERTICES: usize = 40_000_000;
/// Polygons with more points than this are fanned, not ear-clipped
/// (ear clipping takes time quadratic in the points).
pub const MAX_EAR_CLIPPING: usize = 1000;

/// Settings of the 3D geometry.
#[derive(Clone, Debug)]
pub struct SolidOptions {
    /// The line style; `None`: the model's view file's (`pixel` without
    /// one).
    pub line_style: Option<LineStyle>,
    /// In `pixel` line style, where lpfg draws lines a number of pixels
    /// wide, make them tubes anyway: their diameter is the line width
    /// times this many model units per pixel (the caller knows the
    /// picture's scale). `None`: such lines make no triangles.
    pub pixel_tubes: Option<f64>,
    /// Geometry for a picture with this many model units per pixel: a tube
    /// gets fewer sides where it is thin, enough that no side is wider than
    /// 1.5 pixels (at least 3, at most its own), and a tube less than a
    /// pixel across is only its axis, a line of [`TriMesh::lines`]; `None`
    /// (exports): every tube a tube of its own number of sides.
    pub picture_pixel: Option<f64>,
    /// Geometry for a picture whose scale the walk finds: `picture_pixel`
    /// is the extent of the turtle's lines (what [`super::line_bounds`]
    /// spans) over this many pixels, or 1 when they have no extent. The
    /// tubes are logged as the turtle goes and made once the extent is
    /// known, so the word is walked once instead of twice. Ignored when
    /// `picture_pixel` or `pixel_tubes` is given.
    pub fit_pixels: Option<f64>,
    /// More triangles than this stop the walk with an error.
    pub max_triangles: usize,
    /// More vertices than this stop the walk with an error.
    pub max_vertices: usize,
}

impl Default for SolidOptions {
    fn default() -> Self {
        SolidOptions {
            line_style: None,
            pixel_tubes: None,
            picture_pixel: None,
            fit_pixels: None,
            max_triangles: MAX_TRIANGLES,
            max_vertices: MAX_VERTICES,
        }
    }
}

/// Interprets `word` with the turtle and returns its 3D geometry: one
/// triangle mesh per colour or material.
pub fn solid(
    word: &Word,
    alphabet: &Alphabet,
    structs: &[StructDef],
    opts: &DrawOptions,
    sopts: &SolidOptions,
) -> Result<Scene3, DrawError> {
    let fit = sopts
        .fit_pixels
        .filter(|f| f.is_finite() && *f > 0.0 && sopts.picture_pixel.is_none());
    let fit = fit.filter(|_| sopts.pixel_tubes.is_none());
    if let Some(fit) = fit {
        let mut b = Builder::new(&opts.model, sopts);
        b.log = Some(Log::new(fit));
        let walked = walk(word, alphabet, structs, opts, None, &mut b).is_ok();
        if walked && b.finish().is_ok() && b.replay().is_ok() {
            return Ok(b.scene);
        }
        // A failure names its module only on a walk that makes the tubes
        // as it goes: find the scale as before and walk again, which fails
        // where it always did.
        let px = match super::line_bounds(word, alphabet, structs, opts)? {
            Some((lo, hi)) => pixel_of((hi - lo).max_element(), fit),
            None => 1.0,
        };
        let sopts = SolidOptions {
            picture_pixel: Some(px),
            fit_pixels: None,
            ..sopts.clone()
        };
        return solid(word, alphabet, structs, opts, &sopts);
    }
    let mut b = Builder::new(&opts.model, sopts);
    walk(word, alphabet, structs, opts, None, &mut b)?;
    b.finish().map_err(|message| DrawError {
        message: format!("at the end of the word, {message}"),
        module: None,
    })?;
    Ok(b.scene)
}

/// Model units a pixel, for lines spanning `extent` drawn `fit` pixels
/// across: 1 where they span nothing.
pub fn pixel_of(extent: f64, fit: f64) -> f64 {
    if extent.is_finite() && extent > 0.0 {
        extent / fit
    } else {
        1.0
    }
}

/// A tube segment as [`Builder::tube`] reads it from the turtle and the
/// branch.
#[derive(Clone, Copy, Debug)]
struct Seg {
    a: DVec3,
    b: DVec3,
    left: DVec3,
    up: DVec3,
    color: i64,
    scale: (f64, f64),
    sides: Option<u32>,
    /// The lines its mesh had when it was logged: where its line goes if
    /// it turns out thin at the final scale.
    lines: usize,
}

/// What a walk for a picture of unknown scale logs of its tubes, in order
/// ([`SolidOptions::fit_pixels`]): each tube, and each branch and each end
/// of a branch's tube, since they decide which tubes join.
struct Log {
    fit: f64,
    /// The box around the lines so far.
    lo: DVec3,
    hi: DVec3,
    /// The largest scale a tube was found thin at: the final scale must
    /// be at least this (it is, as the box only grows).
    px_used: f64,
    ops: Vec<Op>,
    segs: Vec<Seg>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Op {
    Tube,
    Push,
    Pop,
    End,
}

impl Log {
    fn new(fit: f64) -> Log {
        Log {
            fit,
            lo: DVec3::splat(f64::INFINITY),
            hi: DVec3::splat(f64::NEG_INFINITY),
            px_used: 0.0,
            ops: Vec::new(),
            segs: Vec::new(),
        }
    }

    /// The scale so far: at most the final one, 0 while the lines span
    /// nothing.
    fn pixel_so_far(&self) -> f64 {
        let extent = (self.hi - self.lo).max_element();
        if extent.is_finite() && extent > 0.0 {
            extent / self.fit
        } else {
            0.0
        }
    }
}

/// A cross-section: its distinct points and unit normals in the plane
/// (x along the turtle's left, y along its up vector).
#[derive(Clone, Debug, Default)]
struct Section {
    points: Vec<[f64; 2]>,
    normals: Vec<[f64; 2]>,
    closed: bool,
    /// The points run clockwise (lpfg's circle does): with them the
    /// triangles below face outwards.
    clockwise: bool,
}

impl Section {
    /// lpfg's circle of radius 1 with `sides` sides, from (0, 1)
    /// clockwise.
    fn circle(sides: u32) -> Section {
        let n = sides.max(MIN_CONTOUR_SIDES) as usize;
        let points: Vec<[f64; 2]> = (0..n)
            .map(|i| {
                let (s, c) = (std::f64::consts::TAU * i as f64 / n as f64).sin_cos();
                [s, c]
            })
            .collect();
        Section {
            normals: points.clone(),
            points,
            closed: true,
            clockwise: true,
        }
    }

    /// The section of `points` (a closed one without its repeated last
    /// point), normals from its neighbours, outwards for a closed one.
    fn of_points(points: Vec<[f64; 2]>, closed: bool) -> Section {
        let n = points.len();
        // Twice the signed area (shoelace); negative for clockwise.
        let area: f64 = (0..n)
            .map(|i| {
                let (p, q) = (points[i], points[(i + 1) % n]);
                p[0] * q[1] - q[0] * p[1]
            })
            .sum();
        let clockwise = area < 0.0;
        let side = if clockwise { 1.0 } else { -1.0 };
        let normals = (0..n)
            .map(|i| {
                let (prev, next) = if closed {
                    (points[(i + n - 1) % n], points[(i + 1) % n])
                } else {
                    (points[i.saturating_sub(1)], points[(i + 1).min(n - 1)])
                };
                let t = [next[0] - prev[0], next[1] - prev[1]];
                let len = (t[0] * t[0] + t[1] * t[1]).sqrt();
                if len > 0.0 {
                    [-side * t[1] / len, side * t[0] / len]
                } else {
                    [0.0, 0.0]
                }
            })
            .collect();
        Section {
            points,
            normals,
            closed,
            clockwise,
        }
    }
}

/// Which section a generalized cylinder's ring has: contours, blend and
/// the number of samples.
#[derive(Clone, Copy, Debug, PartialEq)]
struct SectionKey {
    contour: usize,
    contour2: usize,
    blend: f32,
    samples: u32,
}

/// A tube segment whose first ring is made and whose last ring waits for
/// the next segment (to be shared at the joint) or for the tube's end.
#[derive(Clone, Copy, Debug)]
struct Pending {
    mesh: u32,
    /// The first vertex of its first ring.
    ring: u32,
    end: DVec3,
    /// Unit direction.
    dir: DVec3,
    /// The ring axes carried along the tube, perpendicular to `dir`.
    left: DVec3,
    up: DVec3,
    scale: (f64, f64),
    sides: u32,
}

/// The last section of a generalized cylinder.
#[derive(Clone, Copy, Debug)]
struct GcPoint {
    /// The mesh its ring is in and its first vertex; `None` after
    /// `PointGC`, which moves it without making a ring.
    ring: Option<(u32, u32)>,
    pos: DVec3,
    head: DVec3,
    left: DVec3,
    up: DVec3,
    scale: (f64, f64),
    key: SectionKey,
}

/// What a branch of the turtle holds beside the turtle itself.
#[derive(Clone, Copy, Debug)]
struct Branch {
    tube: Option<Pending>,
    gc: Option<GcPoint>,
    /// This branch started inside a generalized cylinder: a `StartGC` in
    /// it starts a new one (lpfg).
    gc_branch: bool,
    contour: usize,
    contour2: usize,
    blend: f32,
    /// The contour's scale, (left, up): `SetWidth(w)` sets (w, w).
    scale: (f64, f64),
    /// `ContourSides`.
    sides: Option<u32>,
    /// `SetUPrecision`, `SetVPrecision`.
    precision: (Option<u32>, Option<u32>),
}

struct Builder<'m> {
    model: &'m Model,
    style: LineStyle,
    pixel_tubes: Option<f64>,
    picture_pixel: Option<f64>,
    sides: u32,
    capped: bool,
    scene: Scene3,
    /// The mesh of each colour index (mod 256), `u32::MAX` until used.
    mesh_of: Vec<u32>,
    triangles: usize,
    vertices: usize,
    max_triangles: usize,
    max_vertices: usize,
    cur: Branch,
    stack: Vec<Branch>,
    /// Tube sections by their number of sides.
    circles: Vec<Section>,
    /// Generalized cylinders' sections, the last few used.
    sections: Vec<(SectionKey, Section)>,
    /// Tubes logged for a scale found by the walk, `None` when they are
    /// made as it goes.
    log: Option<Log>,
    /// While a logged tube is made: the place of its line, should it be
    /// thin, among the lines its mesh had then.
    replaying: Option<usize>,
    /// The lines of logged tubes found thin at the final scale, with
    /// their meshes and places, to be put among the walk's.
    late: Vec<(u32, usize, Line)>,
}

/// In a picture, a tube less than this many pixels across is drawn as its
/// axis, one sample wide (a triangle so thin would cover samples only here
/// and there, and a plant's twigs would come out dotted).
const THIN: f64 = 1.0;

/// Directions shorter than this are no direction.
const TINY: f64 = 1e-12;

/// True when a shape around `c` of extent `r` has coordinates that single
/// precision holds.
fn fits(c: DVec3, r: f64) -> bool {
    (c.abs().max_element() + r.abs()) < f32::MAX as f64
}

/// A segment too short to have a direction: it makes no tube.
fn too_short(a: DVec3, b: DVec3) -> bool {
    (b - a).length() < TINY * (1.0 + a.abs().max_element())
}

/// Left and up axes perpendicular to the unit `dir`, as close to the
/// turtle's left as can be, with up = dir × left.
fn axes(dir: DVec3, left: DVec3, up: DVec3) -> (DVec3, DVec3) {
    let l = left - dir * left.dot(dir);
    let l = if l.length() > 1e-6 {
        l.normalize()
    } else {
        // The heading is along the turtle's left: take up's turn.
        let u = up - dir * up.dot(dir);
        if u.length() > 1e-6 {
            u.normalize().cross(dir)
        } else {
            dir.any_orthonormal_vector()
        }
    };
    (l, dir.cross(l))
}

impl<'m> Builder<'m> {
    fn new(model: &'m Model, sopts: &SolidOptions) -> Builder<'m> {
        let sides = match model.contour_sides {
            0 => DEFAULT_CONTOUR_SIDES,
            n => n.clamp(MIN_CONTOUR_SIDES, MAX_CONTOUR_SIDES),
        };
        Builder {
            model,
            style: sopts.line_style.unwrap_or(model.line_style),
            pixel_tubes: sopts.pixel_tubes.filter(|k| k.is_finite() && *k > 0.0),
            picture_pixel: sopts.picture_pixel.filter(|k| k.is_finite() && *k > 0.0),
            sides,
            capped: model.capped_cylinders,
            scene: Scene3::default(),
            mesh_of: vec![u32::MAX; 256],
            triangles: 0,
            vertices: 0,
            max_triangles: sopts.max_triangles,
            max_vertices: sopts.max_vertices,
            cur: Branch {
                tube: None,
                gc: None,
                gc_branch: false,
                contour: 0,
                contour2: 0,
                blend: 0.0,
                scale: (1.0, 1.0),
                sides: None,
                precision: (None, None),
            },
            stack: Vec::new(),
            circles: Vec::new(),
            sections: Vec::new(),
            log: None,
            replaying: None,
            late: Vec::new(),
        }
    }

    /// Makes the logged tubes at the scale of the whole walk's lines, on
    /// a branch state of their own (the walk's holds no tube), as the
    /// walk would have made them knowing the scale.
    fn replay(&mut self) -> Result<(), String> {
        let Some(log) = self.log.take() else {
            return Ok(());
        };
        let px = pixel_of((log.hi - log.lo).max_element(), log.fit);
        if px < log.px_used {
            return Err("the scale shrank".into());
        }
        self.picture_pixel = Some(px);
        self.stack.clear();
        self.cur.tube = None;
        self.cur.gc = None;
        // Thin tubes went into the meshes as lines on the walk; the ops
        // only say where the logged tubes join.
        if log.segs.is_empty() {
            return self.finish();
        }
        // Of a branch's state, making the tubes reads only its pending
        // tube: the branches keep that alone, where the walk kept all
        // (`push`, `pop`, `finish`, a tube at a time).
        let mut segs = log.segs.iter();
        let mut waiting: Vec<Pending> = Vec::new();
        let mut had: Vec<bool> = Vec::new();
        for op in &log.ops {
            match op {
                Op::Tube => {
                    let seg = segs.next().ok_or("a short log")?;
                    self.replaying = Some(seg.lines);
                    let made = self.tube_at(seg);
                    self.replaying = None;
                    made?
                }
                Op::Push => had.push(match self.cur.tube.take() {
                    Some(p) => {
                        waiting.push(p);
                        true
                    }
                    None => false,
                }),
                Op::Pop => {
                    self.end_tube()?;
                    if had.pop() == Some(true) {
                        self.cur.tube = waiting.pop();
                    }
                }
                Op::End => self.end_tube()?,
            }
        }
        self.end_tube()?;
        while let Some(h) = had.pop() {
            if h {
                self.cur.tube = waiting.pop();
                self.end_tube()?;
            }
        }
        self.place_late_lines();
        Ok(())
    }

    /// Puts the lines of logged tubes found thin at the final scale among
    /// the lines the walk made, each where a walk knowing the scale would
    /// have made it.
    fn place_late_lines(&mut self) {
        let late = std::mem::take(&mut self.late);
        for (k, mesh) in self.scene.meshes.iter_mut().enumerate() {
            let mine: Vec<(usize, Line)> = (late.iter())
                .filter(|(m, _, _)| *m as usize == k)
                .map(|&(_, at, line)| (at, line))
                .collect();
            let Some(&(_, filler)) = mine.first() else {
                continue;
            };
            // In place, from the back: the walk's lines from each place on
            // move up by the late lines at or before it.
            let lines = &mut mesh.lines;
            let mut end = lines.len();
            lines.resize(end + mine.len(), filler);
            for (j, &(at, line)) in mine.iter().enumerate().rev() {
                // Places only grow along the log; clamped all the same.
                let at = at.min(end);
                lines.copy_within(at..end, at + j + 1);
                lines[at + j] = line;
                end = at;
            }
        }
    }

    /// The look of colour index `k` (0 to 255).
    fn look(&self, k: usize) -> Look {
        let i = k as i64;
        match &self.model.colours {
            Some(Colours::Map(m)) => Look::colour(format!("colour{k}"), i, m[k]),
            Some(Colours::Materials(m)) => {
                let m = m[k];
                let f = |c: [u8; 3]| c.map(|b| b as f32 / 255.0);
                Look {
                    name: format!("material{k}"),
                    index: i,
                    ambient: f(m.ambient),
                    diffuse: f(m.diffuse),
                    specular: f(m.specular),
                    emission: f(m.emission),
                    shininess: (m.shininess as f32).min(128.0),
                    opacity: 1.0 - m.transparency as f32 / 255.0,
                }
            }
            None => {
                let c = crate::colour::palette(i);
                Look::colour(format!("colour{k}"), i, [c.0, c.1, c.2])
            }
        }
    }

    /// The mesh of colour index `color`, made on first use.
    fn mesh(&mut self, color: i64) -> u32 {
        let k = color.rem_euclid(256) as usize;
        if self.mesh_of[k] == u32::MAX {
            let look = self.look(k);
            self.scene.looks.push(look);
            self.scene.meshes.push(TriMesh::default());
            self.mesh_of[k] = (self.scene.meshes.len() - 1) as u32;
        }
        self.mesh_of[k]
    }

    /// Room for `v` more vertices and `t` more triangles, within the
    /// limits.
    fn room(&mut self, mesh: u32, v: usize, t: usize) -> Result<&mut TriMesh, String> {
        if self.vertices + v > self.max_vertices {
            return Err(format!(
                "takes the 3D geometry past its limit of {} vertices",
                self.max_vertices
            ));
        }
        if self.triangles + t > self.max_triangles {
            return Err(format!(
                "takes the 3D geometry past its limit of {} triangles",
                self.max_triangles
            ));
        }
        self.vertices += v;
        self.triangles += t;
        let m = &mut self.scene.meshes[mesh as usize];
        if m.positions.len() + v > u32::MAX as usize {
            return Err("makes a mesh of more than 2^32 vertices".into());
        }
        // Large meshes grow into huge pages (fewer page faults).
        m.positions.reserve(v);
        m.normals.reserve(v);
        m.triangles.reserve(t);
        Ok(m)
    }

    fn circle(&mut self, sides: u32) -> usize {
        if let Some(k) = self
            .circles
            .iter()
            .position(|s| s.points.len() == sides as usize)
        {
            return k;
        }
        self.circles.push(Section::circle(sides));
        self.circles.len() - 1
    }

    /// The section of `key`, made on first use (a few are kept).
    fn section(&mut self, key: SectionKey) -> usize {
        if let Some(k) = self.sections.iter().position(|(k, _)| *k == key) {
            return k;
        }
        if self.sections.len() >= 64 {
            self.sections.clear();
        }
        let sample = |id: usize| {
            let mut c = self.contour(id);
            if c.samples != key.samples as usize {
                c = std::borrow::Cow::Owned(c.resampled(key.samples as usize));
            }
            let mut pts: Vec<[f64; 2]> = c
                .vertices
                .iter()
                .map(|v| [v[0] as f64, v[1] as f64])
                .collect();
            if c.closed && pts.len() > 1 && pts.first() == pts.last() {
                pts.pop();
            }
            (pts, c.closed)
        };
        let (mut pts, closed) = sample(key.contour);
        if key.blend > 0.0 {
            let (other, _) = sample(key.contour2);
            let b = key.blend as f64;
            for (p, q) in pts.iter_mut().zip(&other) {
                *p = [p[0] * (1.0 - b) + q[0] * b, p[1] * (1.0 - b) + q[1] * b];
            }
        }
        self.sections.push((key, Section::of_points(pts, closed)));
        self.sections.len() - 1
    }

    /// Makes a ring of section `sec` (a circle when `tube`) centred at `c`
    /// with axes `l`, `u` scaled by half of `scale`: its first vertex.
    #[allow(clippy::too_many_arguments)]
    fn ring(
        &mut self,
        mesh: u32,
        tube: bool,
        sec: usize,
        c: DVec3,
        l: DVec3,
        u: DVec3,
        scale: (f64, f64),
    ) -> Result<u32, String> {
        let (sx, sy) = (0.5 * scale.0.abs(), 0.5 * scale.1.abs());
        if !fits(c, sx.max(sy) * 4.0) {
            return Err("makes a cylinder that reaches an infinite coordinate".into());
        }
        // Normals of a scaled section: the inverse scale (a zero scale
        // keeps the section's own).
        let (nx, ny) = if sx > 0.0 && sy > 0.0 {
            (1.0 / sx, 1.0 / sy)
        } else {
            (1.0, 1.0)
        };
        let (ls, us) = (l * sx, u * sy);
        let (ln, un) = (l * nx, u * ny);
        // The section is lent out of `self` while the mesh grows.
        fn slot<'a>(b: &'a mut Builder<'_>, tube: bool, sec: usize) -> &'a mut Section {
            if tube {
                &mut b.circles[sec]
            } else {
                &mut b.sections[sec].1
            }
        }
        let s = std::mem::take(slot(self, tube, sec));
        // Unit section normals stay unit under a uniform scale.
        let uniform = sx == sy;
        let result = self.room(mesh, s.points.len(), 0).map(|m| {
            let base = m.positions.len() as u32;
            for (p, q) in s.points.iter().zip(&s.normals) {
                m.positions.push((c + ls * p[0] + us * p[1]).as_vec3());
                let n = if uniform {
                    l * q[0] + u * q[1]
                } else {
                    (ln * q[0] + un * q[1]).normalize_or_zero()
                };
                m.normals.push(n.as_vec3());
            }
            base
        });
        *slot(self, tube, sec) = s;
        result
    }

    /// The quads between rings `a` and `b` of `n` points each.
    fn strip(
        &mut self,
        mesh: u32,
        a: u32,
        b: u32,
        n: u32,
        closed: bool,
        clockwise: bool,
    ) -> Result<(), String> {
        let quads = if closed { n } else { n.saturating_sub(1) };
        let m = self.room(mesh, 0, 2 * quads as usize)?;
        for i in 0..quads {
            let j = (i + 1) % n;
            let (ai, aj, bi, bj) = (a + i, a + j, b + i, b + j);
            if clockwise {
                m.triangles.push([ai, bj, aj]);
                m.triangles.push([ai, bi, bj]);
            } else {
                m.triangles.push([ai, aj, bj]);
                m.triangles.push([ai, bj, bi]);
            }
        }
        Ok(())
    }

    /// A disc closing the ring of section `sec` at `c`, facing `-h` at a
    /// start and `h` at an end: a fan from the centroid on vertices of
    /// its own.
    #[allow(clippy::too_many_arguments)]
    fn cap(
        &mut self,
        mesh: u32,
        tube: bool,
        sec: usize,
        c: DVec3,
        (l, u, h): (DVec3, DVec3, DVec3),
        scale: (f64, f64),
        start: bool,
    ) -> Result<(), String> {
        let s = if tube {
            &self.circles[sec]
        } else {
            &self.sections[sec].1
        };
        if !s.closed {
            return Ok(());
        }
        let (sx, sy) = (0.5 * scale.0.abs(), 0.5 * scale.1.abs());
        let n = s.points.len();
        let pts: Vec<DVec3> = s
            .points
            .iter()
            .map(|p| c + l * (sx * p[0]) + u * (sy * p[1]))
            .collect();
        // The centroid of the section's points, as lpfg takes it.
        let centre = pts.iter().copied().sum::<DVec3>() / n as f64;
        let flip = start != s.clockwise;
        let normal = if start { -h } else { h };
        self.fan(mesh, centre, normal, &pts, flip)
    }

    /// Ends the pending tube of the current branch: its last ring,
    /// perpendicular to its direction, and the cap.
    fn end_tube(&mut self) -> Result<(), String> {
        if let Some(log) = &mut self.log {
            log.ops.push(Op::End);
            return Ok(());
        }
        let Some(p) = self.cur.tube.take() else {
            return Ok(());
        };
        let sec = self.circle(p.sides);
        let b = self.ring(p.mesh, true, sec, p.end, p.left, p.up, p.scale)?;
        self.strip(p.mesh, p.ring, b, p.sides, true, true)?;
        if self.capped {
            self.cap(
                p.mesh,
                true,
                sec,
                p.end,
                (p.left, p.up, p.dir),
                p.scale,
                false,
            )?;
        }
        Ok(())
    }

    /// A tube segment from `a` to `b`.
    fn tube(&mut self, t: &Turtle, a: DVec3, b: DVec3) -> Result<(), String> {
        let seg = Seg {
            a,
            b,
            left: t.left,
            up: t.up,
            color: t.pen.color,
            scale: self.cur.scale,
            sides: self.cur.sides,
            lines: 0,
        };
        if self.log.is_none() {
            return self.tube_at(&seg);
        }
        self.log_tube(seg)
    }

    /// Logs a tube segment: as a line when it is thinner than a pixel at
    /// the scale so far (the final scale is at least that), else whole.
    #[inline]
    fn log_tube(&mut self, seg: Seg) -> Result<(), String> {
        let (a, b) = (seg.a, seg.b);
        if self.log.is_none() || too_short(a, b) {
            return Ok(());
        }
        // The tube's mesh is made now, where a walk that made the tube
        // would make it, so that the meshes come in the same order.
        let mesh = self.mesh(seg.color);
        let Some(log) = &mut self.log else {
            return Ok(());
        };
        let width = seg.scale.0.abs().max(seg.scale.1.abs());
        let px = log.pixel_so_far();
        if px > 0.0 && width / px < THIN && fits(a, 0.0) && fits(b, 0.0) {
            log.px_used = log.px_used.max(px);
            // A line at any scale from here on: made now, in the order a
            // walk knowing the scale makes the lines, and the tube it
            // follows ends here (logged).
            log.ops.push(Op::End);
            let line = Line {
                a: a.as_vec3(),
                b: b.as_vec3(),
                width: width as f32,
            };
            // A line counts as a triangle against the limit.
            self.room(mesh, 0, 1)?.lines.push(line);
        } else {
            log.ops.push(Op::Tube);
            let lines = self.scene.meshes[mesh as usize].lines.len();
            log.segs.push(Seg { lines, ..seg });
        }
        Ok(())
    }

    /// A tube segment as `seg` gives it.
    fn tube_at(&mut self, seg: &Seg) -> Result<(), String> {
        let (a, b) = (seg.a, seg.b);
        if too_short(a, b) {
            return Ok(());
        }
        let d = b - a;
        let dir = d / d.length();
        let scale = seg.scale;
        let mut sides = seg.sides.unwrap_or(self.sides);
        if let Some(px) = self.picture_pixel {
            // The circumference in pixels over 1.5 pixels a side.
            let across = scale.0.abs().max(scale.1.abs()) / px;
            if across < THIN {
                return self.thin(seg.color, a, b, scale.0.abs().max(scale.1.abs()));
            }
            let need = (std::f64::consts::PI * across / 1.5).ceil();
            if need.is_finite() && need < sides as f64 {
                sides = (need as u32).max(MIN_CONTOUR_SIDES);
            }
        }
        let mesh = self.mesh(seg.color);
        let sec = self.circle(sides);
        let joint = self
            .cur
            .tube
            .filter(|p| p.end == a && p.dir.dot(dir) >= 0.0);
        let (ring, left, up) = match joint {
            Some(p) => {
                self.cur.tube = None;
                // The joint's ring, perpendicular to the bisector, its axes
                // carried halfway.
                let n = (p.dir + dir).normalize();
                let half = DQuat::from_rotation_arc(p.dir, n);
                let (jl, ju) = (half * p.left, half * p.up);
                let old_sec = self.circle(p.sides);
                let r = self.ring(p.mesh, true, old_sec, a, jl, ju, p.scale)?;
                self.strip(p.mesh, p.ring, r, p.sides, true, true)?;
                let same = p.mesh == mesh && p.scale == scale && p.sides == sides;
                let start = if same {
                    r
                } else {
                    self.ring(mesh, true, sec, a, jl, ju, scale)?
                };
                let l = DQuat::from_rotation_arc(p.dir, dir) * p.left;
                // Keep the axes unit and perpendicular over long paths.
                let l = (l - dir * l.dot(dir)).normalize_or(l);
                (start, l, dir.cross(l))
            }
            None => {
                self.end_tube()?;
                let (l, u) = axes(dir, seg.left, seg.up);
                let r = self.ring(mesh, true, sec, a, l, u, scale)?;
                if self.capped {
                    self.cap(mesh, true, sec, a, (l, u, dir), scale, true)?;
                }
                (r, l, u)
            }
        };
        self.cur.tube = Some(Pending {
            mesh,
            ring,
            end: b,
            dir,
            left,
            up,
            scale,
            sides,
        });
        Ok(())
    }

    /// A tube thinner than a pixel in a picture: its axis, as a line of
    /// the mesh (see [`TriMesh::lines`]). A tube it follows ends here.
    fn thin(&mut self, color: i64, a: DVec3, b: DVec3, width: f64) -> Result<(), String> {
        self.end_tube()?;
        if !fits(a, 0.0) || !fits(b, 0.0) {
            return Err("makes a cylinder that reaches an infinite coordinate".into());
        }
        let mesh = self.mesh(color);
        let line = Line {
            a: a.as_vec3(),
            b: b.as_vec3(),
            width: width as f32,
        };
        // A line counts as a triangle against the limit.
        let replaying = self.replaying;
        let m = self.room(mesh, 0, 1)?;
        match replaying {
            Some(at) => self.late.push((mesh, at, line)),
            None => m.lines.push(line),
        }
        Ok(())
    }

    /// The section key of the current contour with `samples` samples.
    fn key(&self, samples: u32) -> SectionKey {
        SectionKey {
            contour: self.cur.contour,
            contour2: self.cur.contour2,
            blend: self.cur.blend,
            samples,
        }
    }

    /// Contour `id` of the model (checked), 0 lpfg's circle.
    fn contour(&self, id: usize) -> std::borrow::Cow<'_, Contour> {
        match self.model.contours.get(id) {
            Some(c) => std::borrow::Cow::Borrowed(c),
            // A model made in code may lack the circle that
            // `Model::read` puts first.
            None => std::borrow::Cow::Owned(Contour::default_circle()),
        }
    }

    /// The samples of a generalized cylinder starting now.
    fn gc_samples(&self) -> u32 {
        if let Some(s) = self.cur.sides {
            return s + 1;
        }
        let c = self.contour(self.cur.contour);
        if c.samples_given {
            c.samples as u32
        } else {
            self.sides + 1
        }
    }

    /// A generalized cylinder's section at the turtle: its ring in `mesh`.
    fn gc_ring(&mut self, mesh: u32, g: &GcPoint) -> Result<u32, String> {
        let sec = self.section(g.key);
        self.ring(mesh, false, sec, g.pos, g.left, g.up, g.scale)
    }

    fn gc_point(&self, t: &Turtle, key: SectionKey) -> GcPoint {
        GcPoint {
            ring: None,
            pos: t.pos,
            head: t.head,
            left: t.left,
            up: t.up,
            scale: self.cur.scale,
            key,
        }
    }

    /// A generalized cylinder's segment to the turtle.
    fn gc_segment(&mut self, t: &Turtle, last: GcPoint) -> Result<(), String> {
        let mesh = self.mesh(t.pen.color);
        let key = self.key(last.key.samples);
        let mut next = self.gc_point(t, key);
        let a = match last.ring {
            Some((m, r)) if m == mesh => r,
            // After `PointGC` or a change of colour, the last section's
            // ring in this mesh.
            _ => self.gc_ring(mesh, &last)?,
        };
        let b = self.gc_ring(mesh, &next)?;
        let sec = self.section(key);
        let (n, closed, cw) = {
            let s = &self.sections[sec].1;
            (s.points.len() as u32, s.closed, s.clockwise)
        };
        self.strip(mesh, a, b, n, closed, cw)?;
        next.ring = Some((mesh, b));
        self.cur.gc = Some(next);
        Ok(())
    }

    fn gc_cap(&mut self, t: &Turtle, g: &GcPoint, start: bool) -> Result<(), String> {
        if !self.capped {
            return Ok(());
        }
        let mesh = self.mesh(t.pen.color);
        let sec = self.section(g.key);
        self.cap(
            mesh,
            false,
            sec,
            g.pos,
            (g.left, g.up, g.head),
            g.scale,
            start,
        )
    }

    /// Ends what the current branch has open, at the end of the walk.
    fn finish(&mut self) -> Result<(), String> {
        self.end_tube()?;
        while let Some(b) = self.stack.pop() {
            self.cur = b;
            self.end_tube()?;
        }
        Ok(())
    }

    /// A fan of triangles from `centre` over the closed loop `pts`, on
    /// vertices of its own, all with the normal `normal`; `flip` turns
    /// every triangle the other way round.
    fn fan(
        &mut self,
        mesh: u32,
        centre: DVec3,
        normal: DVec3,
        pts: &[DVec3],
        flip: bool,
    ) -> Result<(), String> {
        let n = pts.len();
        let m = self.room(mesh, n + 1, n)?;
        let base = m.positions.len() as u32;
        m.positions.push(centre.as_vec3());
        m.positions.extend(pts.iter().map(|p| p.as_vec3()));
        m.normals
            .extend(std::iter::repeat_n(normal.as_vec3(), n + 1));
        for i in 0..n as u32 {
            let (p, q) = (base + 1 + i, base + 1 + (i + 1) % n as u32);
            m.triangles
                .push(if flip { [base, q, p] } else { [base, p, q] });
        }
        Ok(())
    }

    /// A fan of `pts` around `centre`, all facing `normal`, or a ring
    /// between `pts` and `inner` when given.
    fn flat_round(
        &mut self,
        mesh: u32,
        centre: DVec3,
        normal: DVec3,
        pts: &[DVec3],
        inner: Option<&[DVec3]>,
    ) -> Result<(), String> {
        let n = pts.len();
        let nv = normal.as_vec3();
        match inner {
            None => self.fan(mesh, centre, normal, pts, false)?,
            Some(inner) => {
                let m = self.room(mesh, 2 * n, 2 * n)?;
                let base = m.positions.len() as u32;
                m.positions.extend(pts.iter().map(|p| p.as_vec3()));
                m.positions.extend(inner.iter().map(|p| p.as_vec3()));
                m.normals.extend(std::iter::repeat_n(nv, 2 * n));
                for i in 0..n as u32 {
                    let j = (i + 1) % n as u32;
                    let (o, q) = (base, base + n as u32);
                    m.triangles.push([o + i, q + j, o + j]);
                    m.triangles.push([o + i, q + i, q + j]);
                }
            }
        }
        Ok(())
    }

    fn sphere(&mut self, mesh: u32, t: &Turtle, r: f64) -> Result<(), String> {
        let slices = self.cur.sides.unwrap_or(self.sides).max(3) as usize;
        let stacks = slices.div_ceil(2).max(2);
        let (h, l, u) = (t.head, t.left, t.up);
        let c = t.pos;
        let nv = 2 + (stacks - 1) * slices;
        let nt = 2 * slices * (stacks - 1);
        let m = self.room(mesh, nv, nt)?;
        let base = m.positions.len() as u32;
        let mut put = |dir: DVec3| {
            m.positions.push((c + dir * r).as_vec3());
            m.normals.push(dir.as_vec3());
        };
        put(h);
        for k in 1..stacks {
            let (s, co) = (std::f64::consts::PI * k as f64 / stacks as f64).sin_cos();
            for i in 0..slices {
                let (a, b) = (std::f64::consts::TAU * i as f64 / slices as f64).sin_cos();
                put(h * co + (l * a + u * b) * s);
            }
        }
        put(-h);
        let ring = |k: usize, i: usize| base + 1 + (k * slices + i % slices) as u32;
        let last = base + nv as u32 - 1;
        for i in 0..slices {
            m.triangles.push([base, ring(0, i + 1), ring(0, i)]);
            for k in 0..stacks - 2 {
                let (a, b, c2, d) = (
                    ring(k, i),
                    ring(k, i + 1),
                    ring(k + 1, i),
                    ring(k + 1, i + 1),
                );
                m.triangles.push([a, b, d]);
                m.triangles.push([a, d, c2]);
            }
            m.triangles
                .push([last, ring(stacks - 2, i), ring(stacks - 2, i + 1)]);
        }
        Ok(())
    }
}

/// Triangles of the simple polygon `pts` (its points' indices), wound
/// counter-clockwise about `normal`: ear clipping in its plane; a fan from
/// the first point past [`MAX_EAR_CLIPPING`] points or where no ear is
/// left (a polygon that crosses itself).
fn triangulate(pts: &[DVec3], normal: DVec3) -> Vec<[u32; 3]> {
    let n = pts.len();
    let mut out = Vec::with_capacity(n.saturating_sub(2));
    let fan = |from: &[u32], out: &mut Vec<[u32; 3]>| {
        for w in from[1..].windows(2) {
            out.push([from[0], w[0], w[1]]);
        }
    };
    let mut idx: Vec<u32> = (0..n as u32).collect();
    if n > MAX_EAR_CLIPPING {
        fan(&idx, &mut out);
        return out;
    }
    let e1 = normal.any_orthonormal_vector();
    let e2 = normal.cross(e1);
    let p2: Vec<[f64; 2]> = pts.iter().map(|p| [p.dot(e1), p.dot(e2)]).collect();
    let cross = |a: [f64; 2], b: [f64; 2], c: [f64; 2]| {
        (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
    };
    let inside = |p: [f64; 2], a: [f64; 2], b: [f64; 2], c: [f64; 2]| {
        cross(a, b, p) >= 0.0 && cross(b, c, p) >= 0.0 && cross(c, a, p) >= 0.0
    };
    while idx.len() > 3 {
        let m = idx.len();
        let ear = (0..m).find(|&i| {
            let (a, b, c) = (
                p2[idx[(i + m - 1) % m] as usize],
                p2[idx[i] as usize],
                p2[idx[(i + 1) % m] as usize],
            );
            cross(a, b, c) > 0.0
                && (0..m)
                    .filter(|&j| j != i && j != (i + m - 1) % m && j != (i + 1) % m)
                    .all(|j| {
                        let p = p2[idx[j] as usize];
                        p == a || p == b || p == c || !inside(p, a, b, c)
                    })
        });
        match ear {
            Some(i) => {
                out.push([idx[(i + m - 1) % m], idx[i], idx[(i + 1) % m]]);
                idx.remove(i);
            }
            None => {
                fan(&idx, &mut out);
                return out;
            }
        }
    }
    out.push([idx[0], idx[1], idx[2]]);
    out
}

impl Sink for Builder<'_> {
    fn line(&mut self, t: &Turtle, a: DVec3, b: DVec3) -> Result<(), String> {
        if let Some(log) = &mut self.log {
            log.lo = log.lo.min(a).min(b);
            log.hi = log.hi.max(a).max(b);
        }
        match self.style {
            LineStyle::Pixel => match self.pixel_tubes {
                Some(k) => {
                    let scale = self.cur.scale;
                    self.cur.scale = (scale.0 * k, scale.1 * k);
                    let made = self.tube(t, a, b);
                    self.cur.scale = scale;
                    made
                }
                None => Ok(()),
            },
            LineStyle::Cylinder => match self.cur.gc {
                Some(g) => self.gc_segment(t, g),
                None => self.tube(t, a, b),
            },
            LineStyle::Polygon => {
                // A band of the line's width facing +z, lpfg's default
                // viewer; none for a line along the view.
                let d = b - a;
                let side = d.cross(DVec3::Z);
                if side.length() < TINY * (1.0 + d.length()) {
                    return Ok(());
                }
                let side = side.normalize() * (0.5 * t.pen.width.abs());
                if !fits(a, side.length()) || !fits(b, side.length()) {
                    return Err("draws a band that reaches an infinite coordinate".into());
                }
                let mesh = self.mesh(t.pen.color);
                let m = self.room(mesh, 4, 2)?;
                let base = m.positions.len() as u32;
                for p in [a - side, a + side, b + side, b - side] {
                    m.positions.push(p.as_vec3());
                    m.normals.push(Vec3::Z);
                }
                m.triangles.push([base, base + 1, base + 2]);
                m.triangles.push([base, base + 2, base + 3]);
                Ok(())
            }
        }
    }

    fn round(&mut self, t: &Turtle, kind: Round, r: f64) -> Result<(), String> {
        let w = t.pen.width.abs();
        let r = if kind.is_dot() { 0.5 * t.pen.width } else { r };
        // lpfg draws no circle or sphere of a radius that is not positive.
        if r <= 0.0 {
            return Ok(());
        }
        if !fits(t.pos, r + w) {
            return Err("draws a circle that reaches an infinite coordinate".into());
        }
        let mesh = self.mesh(t.pen.color);
        if matches!(kind, Round::Sphere | Round::Sphere0) {
            return self.sphere(mesh, t, r);
        }
        let front = matches!(
            kind,
            Round::CircleFront | Round::CircleFront0 | Round::CircleFrontB
        );
        // The disc's plane: HL (normal up) or the screen's (normal +z).
        let (x, y, normal) = if front {
            (DVec3::X, DVec3::Y, DVec3::Z)
        } else {
            (t.left, t.head, t.up)
        };
        let n = self.cur.sides.unwrap_or(self.sides).max(3) as usize;
        let at = |radius: f64| -> Vec<DVec3> {
            (0..n)
                .map(|i| {
                    let (s, c) = (std::f64::consts::TAU * i as f64 / n as f64).sin_cos();
                    t.pos + (x * c + y * s) * radius
                })
                .collect()
        };
        if matches!(kind, Round::CircleB | Round::CircleFrontB) {
            let outer = at(r + 0.5 * w);
            let inner = at((r - 0.5 * w).max(0.0));
            self.flat_round(mesh, t.pos, normal, &outer, Some(&inner))
        } else {
            self.flat_round(mesh, t.pos, normal, &at(r), None)
        }
    }

    fn polygon(&mut self, t: &Turtle, points: Vec<DVec3>) -> Result<(), String> {
        // Newell's normal: the polygon's plane, its points counter-clockwise
        // about it.
        let n = points.len();
        let mut normal = DVec3::ZERO;
        for i in 0..n {
            let (p, q) = (points[i], points[(i + 1) % n]);
            normal += DVec3::new(
                (p.y - q.y) * (p.z + q.z),
                (p.z - q.z) * (p.x + q.x),
                (p.x - q.x) * (p.y + q.y),
            );
        }
        if !normal.is_finite() || normal.length() <= TINY {
            // No plane: a polygon without area has nothing to fill.
            return Ok(());
        }
        let normal = normal.normalize();
        if points.iter().any(|p| !fits(*p, 0.0)) {
            return Err("draws a polygon that reaches an infinite coordinate".into());
        }
        let tris = triangulate(&points, normal);
        let mesh = self.mesh(t.pen.color);
        let m = self.room(mesh, n, tris.len())?;
        let base = m.positions.len() as u32;
        m.positions.extend(points.iter().map(|p| p.as_vec3()));
        m.normals.extend(std::iter::repeat_n(normal.as_vec3(), n));
        m.triangles.extend(tris.iter().map(|t| t.map(|i| base + i)));
        Ok(())
    }

    fn surface(
        &mut self,
        t: &Turtle,
        s: &crate::model::Surface,
        scale: DVec3,
    ) -> Result<(), String> {
        // lpfg's s (`sdiv`, the U precision) runs down the rows of control
        // points, t (`tdiv`, V) along a row: its OBJ output of the test
        // surface has them so.
        let def = crate::model::surface::DEFAULT_DIVISIONS;
        let (ds, dt) = s.divisions.unwrap_or((def, def));
        let nv = self.cur.precision.0.unwrap_or(ds).max(1) as usize;
        let nu = self.cur.precision.1.unwrap_or(dt).max(1) as usize;
        let place = super::placement(s, t, scale);
        // Tangents map linearly: the placement less its translation.
        let origin = place.point([0.0; 3]);
        let mesh = self.mesh(t.pen.color);
        let per = (nu + 1) * (nv + 1);
        let m = self.room(mesh, per * s.patches.len(), 2 * nu * nv * s.patches.len())?;
        for patch in &s.patches {
            let base = m.positions.len() as u32;
            for j in 0..=nv {
                for i in 0..=nu {
                    let (u, v) = (i as f64 / nu as f64, j as f64 / nv as f64);
                    let (p, _, _) = patch.point_and_tangents(u, v);
                    // Derivatives just inside the patch, where a corner
                    // collapsed to a point still has a plane.
                    let e = 1e-3;
                    let (_, pu, pv) =
                        patch.point_and_tangents(u.clamp(e, 1.0 - e), v.clamp(e, 1.0 - e));
                    let tu = place.point(pu) - origin;
                    let tv = place.point(pv) - origin;
                    let q = place.point(p);
                    if !fits(q, 0.0) {
                        return Err("places a surface at an infinite coordinate".into());
                    }
                    m.positions.push(q.as_vec3());
                    m.normals.push(tu.cross(tv).normalize_or(t.up).as_vec3());
                }
            }
            let row = nu as u32 + 1;
            for j in 0..nv as u32 {
                for i in 0..nu as u32 {
                    let a = base + j * row + i;
                    let (b, c, d) = (a + 1, a + row + 1, a + row);
                    m.triangles.push([a, b, c]);
                    m.triangles.push([a, c, d]);
                }
            }
        }
        Ok(())
    }

    fn push(&mut self) {
        if let Some(log) = &mut self.log {
            log.ops.push(Op::Push);
        }
        // The parent's tube waits on the stack for the parent; the branch
        // starts its own. (One copy of the branch state: it is large.)
        self.stack.push(self.cur);
        self.cur.tube = None;
        self.cur.gc_branch = self.cur.gc.is_some();
    }

    fn pop(&mut self) -> Result<(), String> {
        self.end_tube()?;
        if let Some(log) = &mut self.log {
            log.ops.push(Op::Pop);
        }
        if let Some(b) = self.stack.pop() {
            self.cur = b;
        }
        Ok(())
    }

    fn shape(&mut self, t: &Turtle, cmd: Option<Shaping>, d: &[f64]) -> Result<(), String> {
        let arg = |k: usize| d.get(k).copied().unwrap_or(0.0);
        let contours = self.model.contours.len().max(1);
        let contour = |v: f64| -> Result<usize, String> {
            if v >= 0.0 && (v as usize) < contours {
                Ok(v as usize)
            } else {
                Err(format!(
                    "names contour {v}, but the model has contours 0 to {} (0 is lpfg's circle; `.con` and `.cset` files add the others)",
                    contours - 1
                ))
            }
        };
        let Some(cmd) = cmd else {
            // SetWidth: the contour's scale too, as in lpfg.
            let w = t.pen.width;
            self.cur.scale = (w, w);
            return Ok(());
        };
        let cylinder = self.style == LineStyle::Cylinder;
        match cmd {
            Shaping::StartGC if cylinder => {
                if self.cur.gc_branch {
                    self.cur.gc = None;
                    self.cur.gc_branch = false;
                }
                if self.cur.gc.is_none() {
                    self.end_tube()?;
                    let key = self.key(self.gc_samples());
                    let mut g = self.gc_point(t, key);
                    let mesh = self.mesh(t.pen.color);
                    g.ring = Some((mesh, self.gc_ring(mesh, &g)?));
                    self.gc_cap(t, &g, true)?;
                    self.cur.gc = Some(g);
                }
            }
            Shaping::PointGC => {
                if let Some(g) = self.cur.gc {
                    let mut p = self.gc_point(t, self.key(g.key.samples));
                    p.ring = None;
                    self.cur.gc = Some(p);
                }
            }
            Shaping::EndGC => {
                if let Some(g) = self.cur.gc.take() {
                    self.gc_cap(t, &g, false)?;
                }
            }
            Shaping::StartGC => {}
            Shaping::CurrentContour => {
                self.cur.contour = contour(arg(0))?;
                self.cur.blend = 0.0;
            }
            Shaping::BlendedContour => {
                self.cur.contour = contour(arg(0))?;
                self.cur.contour2 = contour(arg(1))?;
                self.cur.blend = arg(2).clamp(0.0, 1.0) as f32;
            }
            Shaping::ScaleContour => self.cur.scale = (arg(0), arg(1)),
            Shaping::ContourSides => {
                // No effect inside a generalized cylinder (manual 5.8).
                if self.cur.gc.is_none() {
                    let n = arg(0).clamp(MIN_CONTOUR_SIDES as f64, MAX_CONTOUR_SIDES as f64);
                    self.cur.sides = Some(n as u32);
                }
            }
            Shaping::SetUPrecision | Shaping::SetVPrecision => {
                let p = arg(0);
                // Zero goes back to the surface's own (manual 5.7).
                let v = (p >= 1.0)
                    .then(|| p.min(crate::model::view::MAX_SURFACE_DIVISIONS as f64) as u32);
                if cmd == Shaping::SetUPrecision {
                    self.cur.precision.0 = v;
                } else {
                    self.cur.precision.1 = v;
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::super::walk::walk_loops;
    use super::super::{tropism, DrawOptions, Events, TurtleView};
    use super::{Builder, SolidOptions};
    use crate::model::view::LineStyle;
    use glam::DVec3;

    /// The two loops against the full loop alone where the project's
    /// `draw::tests` do not reach: long runs of common modules (the full
    /// loop's hand-back), the 3D sink (whose `line` reads the turtle's frame),
    /// tropisms and the simple tropism (`bends`), and queries.
    #[test]
    fn the_two_loops_agree_in_3d_with_tropisms_queries_and_hand_backs() {
        let common = [
            "F(1)",
            "f(2)",
            "G(1)",
            "F",
            "Left(30)",
            "Right(45)",
            "Down(20)",
            "RollR(70)",
            "TurnAround",
            "SB",
            "EB",
            "SetColor(3)",
            "IncColor",
            "SetWidth(0.5)",
        ];
        let other = [
            "Circle(1)",
            "Sphere(0.5)",
            "MoveTo(1, 2, 0)",
            "LineRel3f(V3f(0.5, 0.25, 1))",
            "SP",
            "PP",
            "EP",
            "RotateHLU(V3f(0, 0, 1), 33)",
            "SetHead3f(V3f(0, 1, 1))",
            "Elasticity(0.2)",
            "Elasticity(0)",
            "SetTropismDirection3f(V3f(0, -1, 0))",
            "IncElasticity(0)",
            "GetPos(0, 0, 0)",
            "GetHead(0, 0, 0)",
            "SetCoordinateSystem(2)",
            "StartGC",
            "PointGC",
            "EndGC",
        ];
        let opts = DrawOptions {
            view: TurtleView {
                corrected_rotation: false,
                tropisms: tropism::Tropisms {
                    list: vec![
                        tropism::Tropism {
                            torque: false,
                            direction: DVec3::new(0.0, -1.0, 0.2),
                            angle: 0.5,
                            elasticity: 0.1,
                            step: 0.05,
                        },
                        tropism::Tropism {
                            torque: true,
                            direction: DVec3::X,
                            angle: 0.0,
                            elasticity: 0.2,
                            step: 0.1,
                        },
                    ],
                    simple: tropism::SimpleTropism {
                        direction: DVec3::new(0.3, -1.0, 0.0),
                        elasticity: 0.15,
                    },
                },
            },
            ..Default::default()
        };
        let mut next = crate::testing::xorshift(0xfeed_5eed);
        for round in 0..30 {
            // One module in 40 not common: runs of 32 and more are many.
            let word: Vec<&str> = (0..600)
                .map(|_| match next() % 40 {
                    0 => other[(next() % other.len() as u64) as usize],
                    _ => common[(next() % common.len() as u64) as usize],
                })
                .collect();
            let src = format!("derivation length: 0;\nAxiom: {};\n", word.join(" "));
            let loaded = crate::load_str_with("walk.lsys", &src, &[], crate::Precision::Double)
                .expect("loads");
            let p = &loaded.program;
            let w = crate::derive(p, Default::default()).expect("derives").word;
            let style = [LineStyle::Cylinder, LineStyle::Polygon][round % 2];
            let sopts = SolidOptions {
                line_style: Some(style),
                ..Default::default()
            };
            let [fast, full] = [true, false].map(|fast| {
                let mut queries = Vec::new();
                let mut events = Events::new(Vec::new());
                let drawn = walk_loops(
                    &w,
                    &p.alphabet,
                    &p.structs,
                    &opts,
                    Some(&mut queries),
                    &mut events,
                    fast,
                );
                let mut b = Builder::new(&opts.model, &sopts);
                let built = walk_loops(&w, &p.alphabet, &p.structs, &opts, None, &mut b, fast);
                let finished = b.finish();
                format!(
                    "{drawn:?} {:?} {queries:?} {built:?} {finished:?} {:?}",
                    events.into_inner(),
                    b.scene
                )
            });
            assert!(fast == full, "{src}");
        }
    }
}
