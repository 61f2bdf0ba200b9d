//! The geometry kernel of shape grammars (paper 003): points shared by every
//! shape of a derivation, a shape's geometry (faces, edges or points), its
//! scope, plane cuts and splits with caps, primitives, extrusion, component
//! selection and the welding of a smoothing group into one polygon soup.
//!
//! Shapes hold [`PointId`]s into one [`Points`]; two shapes that hold the
//! same id share that vertex. Cuts are made once per edge and plane, so the
//! shapes on both sides of a cut, and siblings cut by the same plane, share
//! the cut points; [`Points::resolve`] inserts the cut points that lie on a
//! polygon's edges so that neighbours meet without T-junctions.
//!
//! Nothing here panics on bad input: degenerate geometry gives an empty
//! result or an `Err` with a message.
//!
//! - [`points`]: [`Points`], the points of a derivation, and the cut
//!   points shared by the shapes on both sides of a cut
//! - [`geometry`]: a shape's [`Geometry`] (its [`Face`]s, edges or
//!   points), its [`Scope`] and Newell's normal
//! - [`cut`]: plane cuts with their caps, and splits across planes
//! - [`primitives`]: the primitives inserted in a scope (box, cylinder,
//!   sphere, mesh) and polygons
//! - [`extrude`](mod@extrude): the extrusion of faces into a solid
//! - [`comp`]: component selection ([`Selector`]: faces, edges,
//!   vertices) and the scopes fitted around geometry
//! - [`transform`](mod@transform): a geometry moved by an affine map, on new points
//! - [`weld`](mod@weld): a smoothing group's faces welded into one polygon soup
//!
//! It uses `mesh` (for the welded soup) and nothing else of the crate.

#![allow(dead_code)]

mod comp;
mod cut;
mod extrude;
mod geometry;
mod points;
mod primitives;
mod transform;
mod weld;

#[cfg(test)]
mod tests;

pub(crate) use comp::{bounding_scope, comp_edges, comp_faces, comp_vertices, Selector};
pub(crate) use cut::{plane_of, split};
pub(crate) use extrude::extrude;
pub(crate) use geometry::{newell, Face, Geometry, Scope};
pub(crate) use points::Points;
pub(crate) use primitives::{box_in, cylinder_in, mesh_in, polygon, sphere_in};
pub(crate) use transform::transform;
pub(crate) use weld::{seams_of, weld};

/// The index of a point in [`Points`].
pub(crate) type PointId = u32;

/// A number for a message: plain, or in scientific notation when it is
/// very large or very small (1e308 is not 309 digits).
pub(crate) fn show(x: f64) -> String {
    if x != 0.0 && x.is_finite() && !(1e-4..1e9).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// The largest coordinate a point may have: far beyond any model (in
/// metres, the orbit of Neptune is 4.5e12), near enough to zero that areas,
/// volumes and normals of shapes stay finite and precise.
pub(crate) const MAX_COORD: f64 = 1e15;
