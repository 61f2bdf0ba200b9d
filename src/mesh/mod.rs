//! Meshes: polygon soups from files, the half-edge mesh with levels, the
//! stellar operators, validation, and pictures.

pub mod build;
pub mod draw;
pub mod halfedge;
pub mod info;
pub mod io;
pub mod shapes;
pub mod soup;
pub mod stellar;
pub mod validate;

pub use halfedge::{BlockSplit, EdgeId, FaceId, HalfEdgeId, Mesh, MeshError, VertexId};
pub use soup::{MeshFileError, PolygonSoup};
