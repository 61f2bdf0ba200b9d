//! A polygon soup: positions and faces as index lists, as mesh files hold
//! them. Files are read into a soup, checked, then built into a half-edge
//! mesh; a mesh is written back through a soup.

use glam::DVec3;

/// Positions and polygons (counter-clockwise index lists, any size >= 3).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PolygonSoup {
    pub positions: Vec<DVec3>,
    pub faces: Vec<Vec<u32>>,
    /// The 1-based source line of each face, when it came from a text file
    /// (0 when unknown), so that errors can point at it.
    pub face_lines: Vec<usize>,
    /// The 1-based source line of each vertex (0 when unknown).
    pub vertex_lines: Vec<usize>,
}

/// A problem with a mesh file or with the mesh it describes.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshFileError {
    pub path: String,
    /// The 1-based line, where one applies.
    pub line: Option<usize>,
    pub message: String,
}

impl std::fmt::Display for MeshFileError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.line {
            Some(l) => write!(f, "{}:{}: error: {}", self.path, l, self.message),
            None => write!(f, "{}: error: {}", self.path, self.message),
        }
    }
}

impl std::error::Error for MeshFileError {}

impl PolygonSoup {
    /// The line of face `f` for messages (None when unknown).
    pub fn face_line(&self, f: usize) -> Option<usize> {
        self.face_lines.get(f).copied().filter(|&l| l > 0)
    }

    /// The line of vertex `v` for messages (None when unknown).
    pub fn vertex_line(&self, v: usize) -> Option<usize> {
        self.vertex_lines.get(v).copied().filter(|&l| l > 0)
    }
}
