//! Mesh files: reading OBJ, OFF and PLY (ASCII or binary little-endian) into
//! a checked [`PolygonSoup`](super::PolygonSoup), and writing a soup as OBJ,
//! OFF or ASCII PLY.
//!
//! Reading never panics on bad input: every problem is a [`MeshFileError`]
//! that names the file and, for text (and a binary PLY file's header), the
//! line and the column, shown with the line and a caret. Vertex and face
//! numbers in messages follow the file's own convention: 1-based in OBJ,
//! 0-based in OFF and PLY. A soup that reads without error has finite
//! coordinates, faces of at least three distinct, in-range vertices, and at
//! least one face.
//!
//! Bounds: a file larger than [`max_file_bytes`] (2 GiB unless
//! `SUBGRAM_MAX_MESH_BYTES` says otherwise) is refused before it is read;
//! every count a file declares is checked against the data that is there
//! before anything is looped over or set aside for it; all work is linear
//! in the file's size, or `n log n` in a face's.
//!
//! Coordinates are written with `{:?}`, the shortest text that parses back to
//! the same `f64`, so a soup written and read again is bit-for-bit the same.
//!
//! The folder holds one concept per file:
//!
//! - this file: the limit on a file's size, the [`Format`]s and the choice
//!   of one by extension;
//! - `read`: [`read`], [`read_mesh`] and [`read_str`], and reading a
//!   file's bytes within the limit;
//! - `write`: [`write()`], [`write_with_sharpness`], [`write_with_corner_normals`], [`write_mesh`] and
//!   [`to_bytes`], and what the writers of every format read (a soup, or
//!   a mesh's triangles in place);
//! - `text`: what the readers share: errors placed on a line and a word,
//!   UTF-8, comments and numbers;
//! - `raw`: a mesh as parsed, and the check of its faces that turns it
//!   into a soup;
//! - `creases`: sharpness from a file, and the `.creases` file beside a
//!   mesh ([`CREASES_EXTENSION`]);
//! - `obj`: reading and writing Wavefront OBJ;
//! - `off`: reading and writing OFF;
//! - `ply`: reading PLY (ASCII and binary little-endian) and writing
//!   ASCII PLY.
//!
//! It uses the mesh's `soup`, `halfedge` and `build`, and the crate's
//! `files`, `atomic`, `limits` and `deadline`; nothing above.

use std::path::Path;

use super::soup::MeshFileError;

mod creases;
mod obj;
mod off;
mod ply;
mod raw;
mod read;
mod text;
mod write;

pub use creases::CREASES_EXTENSION;
pub use raw::UvRead;
pub use read::{mentions_uvs, read, read_mesh, read_str, read_with_uvs};
pub use write::{
    to_bytes, write, write_mesh, write_with_attributes, write_with_corner_normals,
    write_with_normals, write_with_sharpness,
};

use text::error;

/// The largest mesh file [`read`] reads unless the environment variable
/// [`MAX_FILE_BYTES_VAR`] sets another limit: 2 GiB, about 40 million
/// triangles of OBJ text, the scale of a grammar run's face limit.
pub const MAX_FILE_BYTES: u64 = 2 << 30;

/// The environment variable that sets the largest mesh file read, as a
/// number of bytes: `SUBGRAM_MAX_MESH_BYTES=8000000000 subgram mesh info
/// big.ply`.
pub const MAX_FILE_BYTES_VAR: &str = "SUBGRAM_MAX_MESH_BYTES";

/// A mesh file format, chosen by file extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Format {
    /// Wavefront OBJ (`.obj`).
    Obj,
    /// Object File Format (`.off`).
    Off,
    /// Polygon File Format (`.ply`).
    Ply,
}

impl Format {
    /// The format named by the extension of `p` (case-insensitive), if any.
    pub fn from_path(p: &Path) -> Option<Format> {
        let ext = p.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "obj" => Some(Format::Obj),
            "off" => Some(Format::Off),
            "ply" => Some(Format::Ply),
            _ => None,
        }
    }

    /// The format's usual name, for messages.
    pub fn name(self) -> &'static str {
        match self {
            Format::Obj => "OBJ",
            Format::Off => "OFF",
            Format::Ply => "PLY",
        }
    }
}

/// The largest mesh file [`read`] reads, in bytes: `SUBGRAM_MAX_MESH_BYTES`
/// when it is set, else [`MAX_FILE_BYTES`]; a message when the variable is
/// not a whole number.
pub fn max_file_bytes() -> Result<u64, String> {
    crate::limits::from_env(
        MAX_FILE_BYTES_VAR,
        MAX_FILE_BYTES,
        "a whole number of bytes",
    )
}

/// The format for `path`, or an error listing the supported ones.
fn format_of(name: &str, path: &Path) -> Result<Format, MeshFileError> {
    Format::from_path(path).ok_or_else(|| {
        let what = match path.extension() {
            Some(e) => format!("unknown mesh format `.{}`", e.to_string_lossy()),
            None => "the file name has no extension".to_string(),
        };
        error(
            name,
            None,
            format!("{what}: expected a file ending in .obj, .off or .ply"),
        )
    })
}
