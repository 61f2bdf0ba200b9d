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
///
/// Displayed as `path:line:col: error: message`, the line and a caret
/// where the file has a line to show (text files, and the header of a
/// binary PLY file), as `path: error: message` where the whole file is at
/// fault or the problem lies in binary data.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshFileError {
    pub path: String,
    /// The 1-based line, where one applies.
    pub line: Option<usize>,
    /// What the caret marks on `line`.
    pub place: Option<Place>,
    pub message: String,
}

/// A place on a line of a file: the line's text and the byte range of it
/// that a message is about.
#[derive(Clone, Debug, PartialEq)]
pub struct Place {
    /// The line, without its newline; invalid UTF-8 is shown as U+FFFD.
    pub text: String,
    pub start: usize,
    pub end: usize,
}

impl std::fmt::Display for MeshFileError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match (self.line, &self.place) {
            (Some(l), Some(p)) => f.write_str(&crate::error::render_line(
                &self.path,
                l,
                &p.text,
                p.start..p.end,
                &self.message,
            )),
            (Some(l), None) => write!(f, "{}:{}: error: {}", self.path, l, self.message),
            (None, _) => write!(f, "{}: error: {}", self.path, self.message),
        }
    }
}

impl std::error::Error for MeshFileError {}

impl PolygonSoup {
    /// The soup with every polygon cut into a fan of triangles from its
    /// first corner: the triangles [`Mesh::from_soup`](crate::mesh::Mesh::from_soup)
    /// makes of it (a quad along its first diagonal). Each triangle keeps
    /// its polygon's line.
    pub fn fanned(&self) -> PolygonSoup {
        let mut faces = Vec::with_capacity(self.faces.len() * 2);
        let mut face_lines = Vec::new();
        for (k, f) in self.faces.iter().enumerate() {
            for i in 1..f.len().saturating_sub(1) {
                faces.push(vec![f[0], f[i], f[i + 1]]);
                if let Some(&l) = self.face_lines.get(k) {
                    face_lines.push(l);
                }
            }
        }
        PolygonSoup {
            positions: self.positions.clone(),
            faces,
            face_lines,
            vertex_lines: self.vertex_lines.clone(),
        }
    }

    /// The line of face `f` for messages (None when unknown).
    pub fn face_line(&self, f: usize) -> Option<usize> {
        self.face_lines.get(f).copied().filter(|&l| l > 0)
    }

    /// The line of vertex `v` for messages (None when unknown).
    pub fn vertex_line(&self, v: usize) -> Option<usize> {
        self.vertex_lines.get(v).copied().filter(|&l| l > 0)
    }
}

/// The first position in `face` whose vertex came before it: pairwise for
/// the short faces of most meshes, through a set for long ones, so that a
/// polygon of any size is checked in linear time.
pub(crate) fn first_repeat(face: &[u32]) -> Option<usize> {
    if face.len() <= 16 {
        return (1..face.len()).find(|&k| face[..k].contains(&face[k]));
    }
    let mut seen = std::collections::HashSet::with_capacity(face.len());
    face.iter().position(|&v| !seen.insert(v))
}
