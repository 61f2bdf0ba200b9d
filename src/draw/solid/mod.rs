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
//!
//! The folder holds one concept per file:
//!
//! - this file: the entry point ([`solid`], [`SolidOptions`], [`pixel_of`],
//!   the limits) and the builder of a walk's geometry (`Builder`: a
//!   branch's state, one mesh per look, room within the limits);
//! - `sink`: what each module makes: lines in each line style, circles
//!   and spheres, polygons, surfaces, branches, and the modules that shape
//!   the geometry;
//! - `tubes`: tubes along the turtle's lines, their rings shared at the
//!   joints, their ends, and tubes thinner than a pixel as lines;
//! - `tube_log`: the tubes a walk for a picture of unknown scale logs,
//!   made once the scale is known;
//! - `sections`: cross-sections, and the rings, strips and caps made of
//!   them;
//! - `cylinders`: generalized cylinders: their contours and sections at
//!   the turtle, segments and caps;
//! - `shapes`: fans, discs and rings, spheres, and polygons cut into
//!   triangles;
//! - `tests`: the walk's two loops compared in 3D.
//!
//! It uses `colour`, `lang`, `model`, `rewrite`, `scene3` and the rest of
//! `draw`; nothing above.

mod cylinders;
mod sections;
mod shapes;
mod sink;
mod tube_log;
mod tubes;

#[cfg(test)]
mod tests;

use glam::DVec3;

use super::{walk, DrawError, DrawOptions};
use crate::lang::value::StructDef;
use crate::lang::Alphabet;
use crate::model::view::{LineStyle, DEFAULT_CONTOUR_SIDES, MAX_CONTOUR_SIDES, MIN_CONTOUR_SIDES};
use crate::model::{Colours, Model};
use crate::rewrite::Word;
use crate::scene3::{Line, Look, Scene3, TriMesh};
use cylinders::GcPoint;
use sections::{Section, SectionKey};
use tube_log::Log;
use tubes::Pending;

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
    /// The mesh of each colour index (mod 256), `u32::MAX` until used;
    /// from 256 on, the unlit look of each for pixel-wide lines.
    mesh_of: Vec<u32>,
    /// Pixel-wide lines keep their colour-map entry's colour unlit, as
    /// lpfg draws lines in its shaded modes: an lpfg model with a colour
    /// map (or lpfg's default map), not materials.
    unlit_lines: bool,
    /// A pixel-wide line is being made: its tube takes the unlit look.
    in_line: bool,
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
            mesh_of: vec![u32::MAX; 512],
            unlit_lines: model.lpfg && !matches!(model.colours, Some(Colours::Materials(_))),
            in_line: false,
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
            None if self.model.lpfg => Look::colour(
                format!("colour{k}"),
                i,
                crate::model::lpfg_default_colour(i),
            ),
            None => {
                let c = crate::colour::palette(i);
                Look::colour(format!("colour{k}"), i, [c.0, c.1, c.2])
            }
        }
    }

    /// The mesh of colour index `color`, made on first use.
    fn mesh(&mut self, color: i64) -> u32 {
        let c = color.rem_euclid(256) as usize;
        let unlit = self.in_line && self.unlit_lines;
        let k = c + if unlit { 256 } else { 0 };
        if self.mesh_of[k] == u32::MAX {
            let mut look = self.look(c);
            if unlit {
                // Emission alone: every light leaves it its colour.
                look = Look {
                    name: format!("{}-line", look.name),
                    emission: look.diffuse,
                    ambient: [0.0; 3],
                    diffuse: [0.0; 3],
                    specular: [0.0; 3],
                    ..look
                };
            }
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

    /// Ends what the current branch has open, at the end of the walk.
    fn finish(&mut self) -> Result<(), String> {
        self.end_tube()?;
        while let Some(b) = self.stack.pop() {
            self.cur = b;
            self.end_tube()?;
        }
        Ok(())
    }
}
