//! A successor's operations run on the current shape, and what they made
//! of it ([`Made`]).

use std::sync::Arc;

use glam::{DAffine3, DMat3, DVec3};

use crate::lang::value::Value;
use crate::shape::geom::{self, Geometry, Points};
use crate::shape::{COp, X};
use crate::syntax::span::Span;

use super::{Cur, Deriver, ShapeError, Wait, R};

impl<'g> Deriver<'g> {
    /// Runs a successor's operations on `cur` for shape `n` (the axiom's
    /// for `u32::MAX`). `attr_base` is where the attributes start in
    /// `frame`.
    pub(super) fn exec(
        &mut self,
        n: u32,
        ops: &'g [COp],
        cur: &mut Cur,
        frame: &mut [Value],
        attr_base: usize,
    ) -> R<Made> {
        let depth = if n == u32::MAX {
            0
        } else {
            self.nodes[n as usize].depth
        };
        let mut made = Made::Nothing;
        let mut stack: Vec<(Cur, Vec<Value>)> = Vec::new();
        let nattrs = self.g.attr_names.len();
        for op in ops {
            match op {
                COp::Symbol { symbol, args, span } => {
                    let mut params = Vec::with_capacity(args.len());
                    for a in args {
                        params.push(self.num(a, frame, cur, depth)?);
                    }
                    let attrs = frame[attr_base..attr_base + nattrs].to_vec();
                    self.new_node(n, *symbol, params, attrs, cur, *span)?;
                    made = made.or(Made::Children);
                }
                COp::Nil => return Ok(made.or(Made::Removed)),
                COp::Push => {
                    stack.push((cur.clone(), frame[attr_base..attr_base + nattrs].to_vec()))
                }
                COp::Pop(span) => {
                    let Some((c, a)) = stack.pop() else {
                        return Err(ShapeError::at(
                            *span,
                            "`]` without a `[` before it in this successor",
                        ));
                    };
                    *cur = c;
                    frame[attr_base..attr_base + nattrs].clone_from_slice(&a);
                }
                COp::Translate(v, rel, span) => {
                    let t = relative(self.vec3(v, frame, cur, depth)?, rel, cur.scope.size);
                    let d =
                        cur.scope.axes[0] * t.x + cur.scope.axes[1] * t.y + cur.scope.axes[2] * t.z;
                    if d != DVec3::ZERO {
                        cur.scope.origin += d;
                        far(cur.scope.origin, "the scope's origin", *span)?;
                        cur.geom = Arc::new(self.moved(
                            &cur.geom,
                            &DAffine3::from_translation(d),
                            *span,
                        )?);
                    }
                }
                COp::Rotate(v, span) => {
                    let a = self.vec3(v, frame, cur, depth)?;
                    if a != DVec3::ZERO {
                        let axes = cur.scope.axes;
                        let rot = DMat3::from_axis_angle(axes[0], a.x.to_radians())
                            * DMat3::from_axis_angle(axes[1], a.y.to_radians())
                            * DMat3::from_axis_angle(axes[2], a.z.to_radians());
                        let o = cur.scope.origin;
                        let f = DAffine3::from_translation(o)
                            * DAffine3::from_mat3(rot)
                            * DAffine3::from_translation(-o);
                        cur.scope.axes = [rot * axes[0], rot * axes[1], rot * axes[2]];
                        cur.geom = Arc::new(self.moved(&cur.geom, &f, *span)?);
                    }
                }
                COp::Scale(v, rel, span) => {
                    let s = relative(self.vec3(v, frame, cur, depth)?, rel, cur.scope.size);
                    if s.min_element() < 0.0 {
                        return Err(ShapeError::at(
                            *span,
                            format!("a scope's size is not negative; this asks for {s}"),
                        ));
                    }
                    far(s, "the scope's size", *span)?;
                    let old = cur.scope.size;
                    let ratio = |i: usize| if old[i] > 0.0 { s[i] / old[i] } else { 1.0 };
                    let (rx, ry, rz) = (ratio(0), ratio(1), ratio(2));
                    cur.scope.size = s;
                    if (rx, ry, rz) != (1.0, 1.0, 1.0) && !cur.geom.is_empty() {
                        let ax = cur.scope.axes;
                        let m = DMat3::from_cols(ax[0], ax[1], ax[2]);
                        let o = cur.scope.origin;
                        let f = DAffine3::from_translation(o)
                            * DAffine3::from_mat3(
                                m * DMat3::from_diagonal(DVec3::new(rx, ry, rz)) * m.transpose(),
                            )
                            * DAffine3::from_translation(-o);
                        cur.geom = Arc::new(self.moved(&cur.geom, &f, *span)?);
                    }
                }
                COp::Extrude(h, span) => {
                    let h = self.num(h, frame, cur, depth)?;
                    if h.abs() > geom::MAX_COORD {
                        return Err(ShapeError::at(
                            *span,
                            format!(
                                "this extrudes by {}, beyond the {:e} that shapes stay within",
                                geom::show(h),
                                geom::MAX_COORD
                            ),
                        ));
                    }
                    if cur.geom.dim != 2 {
                        return Err(ShapeError::at(
                            *span,
                            format!(
                                "`extrude` takes a 2D shape (a face or a lot); this one is {}D",
                                cur.geom.dim
                            ),
                        ));
                    }
                    let normal = normal_of(&self.points, &cur.geom);
                    // The scope axis closest to the face's normal grows.
                    let k = (0..3)
                        .max_by(|&a, &b| {
                            cur.scope.axes[a]
                                .dot(normal)
                                .abs()
                                .total_cmp(&cur.scope.axes[b].dot(normal).abs())
                        })
                        .unwrap_or(1);
                    let dir = if cur.scope.axes[k].dot(normal) < 0.0 {
                        -cur.scope.axes[k]
                    } else {
                        cur.scope.axes[k]
                    };
                    cur.geom = Arc::new(
                        geom::extrude(&mut self.points, &cur.geom, dir, h)
                            .map_err(|m| ShapeError::at(*span, m))?,
                    );
                    cur.scope = geom::bounding_scope(&self.points, &cur.geom, cur.scope.axes);
                }
                COp::Insert(kind, span) => {
                    let s = cur.scope;
                    let g = match kind {
                        crate::shape::Insert::Box => geom::box_in(&mut self.points, &s),
                        crate::shape::Insert::Cylinder(k) => {
                            let k = self.num(k, frame, cur, depth)?;
                            if !(3.0..=1024.0).contains(&k) {
                                return Err(ShapeError::at(*span, format!("a cylinder has 3 to 1024 sides; this asks for {k}")));
                            }
                            geom::cylinder_in(&mut self.points, &s, k as usize)
                        }
                        crate::shape::Insert::Sphere(a, b) => {
                            let a = self.num(a, frame, cur, depth)?;
                            let b = self.num(b, frame, cur, depth)?;
                            if !(3.0..=1024.0).contains(&a) || !(2.0..=1024.0).contains(&b) {
                                return Err(ShapeError::at(*span, format!(
                                    "a sphere has 3 to 1024 slices and 2 to 1024 stacks; this asks for {a} and {b}"
                                )));
                            }
                            geom::sphere_in(&mut self.points, &s, a as usize, b as usize)
                        }
                        crate::shape::Insert::Mesh(soup) => geom::mesh_in(&mut self.points, &s, soup),
                    }
                    .map_err(|m| ShapeError::at(*span, m))?;
                    cur.geom = Arc::new(g);
                }
                COp::Colour(c) => cur.colour = Some(*c),
                COp::ColourRgb(v) => {
                    let c = self.vec3(v, frame, cur, depth)?;
                    let b = |x: f64| (x.clamp(0.0, 1.0) * 255.0).round() as u8;
                    cur.colour = Some([b(c.x), b(c.y), b(c.z)]);
                }
                COp::Set(slot, e, ty) => {
                    let v = self.eval(e, frame, cur, depth)?.convert(*ty);
                    frame[attr_base + *slot as usize] = v;
                }
                COp::SetGroup(name) => cur.group = name.clone(),
                COp::Lot(w, dd, span) => {
                    let w = self.num(w, frame, cur, depth)?;
                    let dz = self.num(dd, frame, cur, depth)?;
                    if w <= 0.0 || dz <= 0.0 {
                        return Err(ShapeError::at(
                            *span,
                            format!("a lot's sides are positive; this asks for {w} by {dz}"),
                        ));
                    }
                    let o = cur.scope.origin;
                    let (x, z) = (DVec3::X, DVec3::Z);
                    let corners = [o + z * dz, o + x * w + z * dz, o + x * w, o];
                    self.lot(cur, &corners, *span)?;
                }
                COp::Polygon(coords, span) => {
                    let mut c = Vec::with_capacity(coords.len() / 2);
                    for pair in coords.chunks(2) {
                        let x = self.num(&pair[0], frame, cur, depth)?;
                        let z = self.num(&pair[1], frame, cur, depth)?;
                        c.push(cur.scope.origin + DVec3::new(x, 0.0, z));
                    }
                    self.lot(cur, &c, *span)?;
                }
                COp::Split {
                    axis,
                    parts,
                    repeat,
                    parallel,
                    span,
                } => {
                    self.split(
                        n,
                        cur,
                        frame,
                        attr_base,
                        *axis,
                        parts,
                        *repeat,
                        parallel.as_deref(),
                        *span,
                    )?;
                    made = made.or(Made::Children);
                }
                COp::Comp { kind, parts, span } => {
                    self.comp(n, cur, frame, attr_base, *kind, parts, *span)?;
                    made = made.or(Made::Children);
                }
                COp::Subdivide {
                    steps,
                    scheme,
                    body,
                    span,
                } => {
                    if n == u32::MAX {
                        return Err(ShapeError::at(
                            *span,
                            "the axiom cannot subdivide; give its shape a symbol and a rule",
                        ));
                    }
                    let k = self.num(steps, frame, cur, depth)?;
                    if !(0.0..=16.0).contains(&k) || k.fract() != 0.0 {
                        return Err(ShapeError::at(
                            *span,
                            format!("`Subdivide` takes 0 to 16 steps; this asks for {k}"),
                        ));
                    }
                    if cur.geom.dim < 2 || cur.geom.is_empty() {
                        return Err(ShapeError::at(
                            *span,
                            "`Subdivide` smooths faces; this shape has none",
                        ));
                    }
                    let old = self.nodes[n as usize].geom.elements();
                    self.hold(old, cur.geom.elements(), *span)?;
                    let node = &mut self.nodes[n as usize];
                    node.scope = cur.scope;
                    node.geom = cur.geom.clone();
                    node.group = cur.group.clone();
                    node.colour = cur.colour;
                    node.attrs = frame[attr_base..attr_base + nattrs].to_vec();
                    self.waiting.push(Wait {
                        node: n,
                        steps: k as usize,
                        scheme: &self.g.schemes[*scheme],
                        body,
                        frame: frame.to_vec(),
                        span: *span,
                    });
                    return Ok(Made::Waiting);
                }
            }
        }
        if n == u32::MAX && made == Made::Nothing {
            // An axiom without a symbol.
            return Ok(made);
        }
        Ok(made)
    }

    fn vec3(&mut self, v: &[X; 3], frame: &mut [Value], cur: &Cur, depth: u32) -> R<DVec3> {
        Ok(DVec3::new(
            self.num(&v[0], frame, cur, depth)?,
            self.num(&v[1], frame, cur, depth)?,
            self.num(&v[2], frame, cur, depth)?,
        ))
    }

    fn moved(&mut self, g: &Geometry, f: &DAffine3, span: Span) -> R<Geometry> {
        geom::transform(&mut self.points, g, f).map_err(|m| ShapeError::at(span, m))
    }

    /// The current shape becomes a polygon in the ground plane: scope x
    /// along its first edge, y up.
    fn lot(&mut self, cur: &mut Cur, corners: &[DVec3], span: Span) -> R<()> {
        let g = geom::polygon(&mut self.points, corners).map_err(|m| ShapeError::at(span, m))?;
        let n = normal_of(&self.points, &g);
        if n == DVec3::ZERO {
            return Err(ShapeError::at(
                span,
                "a lot's corners enclose no area (they lie on a line, or the outline \
                 crosses itself)",
            ));
        }
        if n.y <= 0.0 {
            return Err(ShapeError::at(
                span,
                "a lot's corners go counter-clockwise seen from above (+y)",
            ));
        }
        let x = (corners[1] - corners[0]).normalize_or_zero();
        let x = if x == DVec3::ZERO { DVec3::X } else { x };
        let y = DVec3::Y;
        let z = x.cross(y);
        cur.geom = Arc::new(g);
        cur.scope = geom::bounding_scope(&self.points, &cur.geom, [x, y, z]);
        Ok(())
    }
}

/// `v` with the coordinates written relative (`'0.5`) taken as fractions of
/// the scope's `size`.
fn relative(v: DVec3, rel: &[bool; 3], size: DVec3) -> DVec3 {
    DVec3::new(
        if rel[0] { v.x * size.x } else { v.x },
        if rel[1] { v.y * size.y } else { v.y },
        if rel[2] { v.z * size.z } else { v.z },
    )
}

/// Refuses a scope's origin, size or an extrusion's height beyond
/// [`geom::MAX_COORD`], where the shapes' arithmetic would overflow.
fn far(v: DVec3, what: &str, span: Span) -> R<()> {
    if !v.is_finite() || v.abs().max_element() > geom::MAX_COORD {
        return Err(ShapeError::at(
            span,
            format!(
                "this makes {what} ({}, {}, {}), beyond the {:e} that shapes stay within",
                geom::show(v.x),
                geom::show(v.y),
                geom::show(v.z),
                geom::MAX_COORD
            ),
        ));
    }
    Ok(())
}

/// The direction a 2D shape faces: the sum of its faces' vector areas.
fn normal_of(points: &Points, g: &Geometry) -> DVec3 {
    g.faces
        .iter()
        .fold(DVec3::ZERO, |n, f| n + geom::newell(points, &f.pts))
        .normalize_or_zero()
}

/// What a successor did to its shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Made {
    Nothing,
    Children,
    Removed,
    Waiting,
}

impl Made {
    fn or(self, other: Made) -> Made {
        match (self, other) {
            (Made::Nothing, x) => x,
            (x, Made::Nothing) => x,
            (Made::Children, x) => {
                if x == Made::Removed {
                    Made::Children
                } else {
                    x
                }
            }
            (x, _) => x,
        }
    }
}
