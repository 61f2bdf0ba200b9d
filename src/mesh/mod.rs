//! Meshes: polygon soups from files, the half-edge mesh with levels, the
//! stellar operators, validation, and pictures.

pub mod draw;
pub mod io;
pub mod soup;

pub use soup::{MeshFileError, PolygonSoup};
