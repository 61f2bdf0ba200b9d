//! Meshes: polygon soups from files, the half-edge mesh with levels, the
//! stellar operators and validation: geometry and topology only.
//!
//! **Layer.** It uses `deadline`, `files`, `huge`, `limits`, `syntax`; it is
//! used by `analyze`, `command`, `error`, `render`, `shape`, `surface`,
//! `system`, `vv`. Nothing here names a layer above (see ARCHITECTURE.md,
//! "Layers").

pub mod build;
pub mod folds;
pub mod halfedge;
pub mod info;
pub mod io;
mod packed;
pub mod pairing;
pub mod shapes;
pub mod soup;
pub mod stellar;
mod two_blocks;
pub mod validate;

pub use build::SoupSharpness;
pub use halfedge::{
    child_sharpness, Creasing, EdgeId, FaceId, FannedPolygon, HalfEdgeId, Mesh, MeshError, VertexId,
};
pub use soup::{FaceUvs, Faces, MeshFileError, Place, PolygonSoup};
pub use stellar::{BlockSplit, Split};
