//! A polygon soup: positions and faces as index lists, as mesh files hold
//! them. Files are read into a soup, checked, then built into a half-edge
//! mesh; a mesh is written back through a soup.

use glam::{DVec2, DVec3};

/// Positions and polygons (counter-clockwise index lists, any size >= 3).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PolygonSoup {
    pub positions: Vec<DVec3>,
    pub faces: Faces,
    /// The 1-based source line of each face, when it came from a text file
    /// (0 when unknown), so that errors can point at it.
    pub face_lines: Vec<usize>,
    /// The 1-based source line of each vertex (0 when unknown).
    pub vertex_lines: Vec<usize>,
}

/// Texture coordinates of a soup's face corners (OBJ `vt` with `f v/vt`,
/// PLY `u v` per vertex or a face's `texcoord` list): `corners` runs
/// parallel to the soup's [`Faces::indices`], one index into `values` a
/// corner. Two corners at one vertex with different values make a seam.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FaceUvs {
    pub values: Vec<DVec2>,
    pub corners: Vec<u32>,
}

impl FaceUvs {
    /// The values of face `k` of `faces`'s corners, in order.
    pub fn face<'a>(&'a self, faces: &Faces, k: usize) -> impl Iterator<Item = DVec2> + 'a {
        self.corners[faces.range(k)]
            .iter()
            .map(|&i| self.values[i as usize])
    }
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
        let at = self
            .place
            .as_ref()
            .map(|p| (p.text.as_str(), p.start..p.end));
        crate::syntax::write_file_problem(f, &self.path, self.line, at, &self.message)
    }
}

impl std::error::Error for MeshFileError {}

impl PolygonSoup {
    /// The soup with every polygon cut into a fan of triangles from its
    /// first corner: the triangles [`Mesh::from_soup`](crate::mesh::Mesh::from_soup)
    /// makes of it (a quad along its first diagonal). Each triangle keeps
    /// its polygon's line.
    pub fn fanned(&self) -> PolygonSoup {
        let mut faces = Faces::with_capacity(self.faces.len() * 2, self.faces.len() * 6);
        let mut face_lines = Vec::new();
        for (k, f) in self.faces.iter().enumerate() {
            for i in 1..f.len().saturating_sub(1) {
                faces.push([f[0], f[i], f[i + 1]]);
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

/// A soup's polygons, flat: the corners of every face one after another
/// in one array of indices, as a mesh file lists them. While every face
/// has the same number of corners (a triangle or a quad mesh) that number
/// is all there is to know of where faces begin; once sizes differ, the
/// end of each face in the array is kept too.
///
/// It reads like a `Vec<Vec<u32>>`: `faces[k]` is face `k`'s corners as a
/// slice, `iter()` gives the slices in order, `push` adds a face.
#[derive(Clone, Default)]
pub struct Faces {
    indices: Vec<u32>,
    /// The end of each face in `indices`, kept only once two faces differ
    /// in size (empty while they all have `arity` corners).
    ends: Vec<usize>,
    /// The number of corners of every face, while `ends` is empty.
    arity: usize,
    len: usize,
}

impl Faces {
    pub fn new() -> Faces {
        Faces::default()
    }

    /// Room for `faces` faces with `corners` corners in all.
    pub fn with_capacity(faces: usize, corners: usize) -> Faces {
        let _ = faces;
        Faces {
            indices: Vec::with_capacity(corners),
            ..Faces::default()
        }
    }

    /// Faces of `arity` corners each, from their corners one after another
    /// (`indices.len()` a multiple of `arity`, which is at least 1).
    pub fn uniform(arity: usize, indices: Vec<u32>) -> Faces {
        assert!(
            arity > 0 && indices.len().is_multiple_of(arity),
            "whole faces"
        );
        Faces {
            len: indices.len() / arity,
            indices,
            ends: Vec::new(),
            arity,
        }
    }

    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Every face's corners, one face after another.
    pub fn indices(&self) -> &[u32] {
        &self.indices
    }

    /// The number of corners every face has, when they all have the same
    /// (None for no faces or faces of different sizes).
    pub fn arity(&self) -> Option<usize> {
        (self.ends.is_empty() && self.len > 0).then_some(self.arity)
    }

    /// Where face `k` lies in `indices`.
    #[inline]
    pub(crate) fn range(&self, k: usize) -> std::ops::Range<usize> {
        if self.ends.is_empty() {
            k * self.arity..(k + 1) * self.arity
        } else {
            (if k == 0 { 0 } else { self.ends[k - 1] })..self.ends[k]
        }
    }

    pub fn get(&self, k: usize) -> Option<&[u32]> {
        (k < self.len).then(|| &self.indices[self.range(k)])
    }

    /// Adds a face at the end.
    pub fn push(&mut self, face: impl AsRef<[u32]>) {
        let face = face.as_ref();
        if self.ends.is_empty() {
            if self.len == 0 {
                self.arity = face.len();
            } else if face.len() != self.arity {
                self.ends = (1..=self.len).map(|k| k * self.arity).collect();
            }
        }
        self.indices.extend_from_slice(face);
        if !self.ends.is_empty() {
            self.ends.push(self.indices.len());
        }
        self.len += 1;
    }

    /// The faces in order, each as a slice of its corners.
    pub fn iter(&self) -> FacesIter<'_> {
        FacesIter {
            faces: self,
            front: 0,
            back: self.len,
        }
    }

    /// The faces in order, each as a mutable slice of its corners.
    pub fn iter_mut(&mut self) -> impl Iterator<Item = &mut [u32]> + '_ {
        let mut rest: &mut [u32] = &mut self.indices;
        let (ends, arity) = (&self.ends, self.arity);
        let mut start = 0;
        (0..self.len).map(move |k| {
            let end = if ends.is_empty() {
                (k + 1) * arity
            } else {
                ends[k]
            };
            let (face, tail) = std::mem::take(&mut rest).split_at_mut(end - start);
            rest = tail;
            start = end;
            face
        })
    }

    /// Keeps the faces for which `keep` holds, in order.
    pub fn retain(&mut self, mut keep: impl FnMut(&[u32]) -> bool) {
        let old = std::mem::take(self);
        for f in old.iter().filter(|f| keep(f)) {
            self.push(f);
        }
    }

    /// The faces as one vector each.
    pub fn to_vecs(&self) -> Vec<Vec<u32>> {
        self.iter().map(<[u32]>::to_vec).collect()
    }
}

impl std::ops::Index<usize> for Faces {
    type Output = [u32];

    fn index(&self, k: usize) -> &[u32] {
        assert!(k < self.len, "face {k} of {}", self.len);
        &self.indices[self.range(k)]
    }
}

impl std::ops::IndexMut<usize> for Faces {
    fn index_mut(&mut self, k: usize) -> &mut [u32] {
        assert!(k < self.len, "face {k} of {}", self.len);
        let r = self.range(k);
        &mut self.indices[r]
    }
}

/// Faces are equal when they list the same polygons, however they are kept.
impl PartialEq for Faces {
    fn eq(&self, other: &Faces) -> bool {
        self.len == other.len && self.iter().eq(other.iter())
    }
}

impl std::fmt::Debug for Faces {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_list().entries(self.iter()).finish()
    }
}

impl<F: AsRef<[u32]>> FromIterator<F> for Faces {
    fn from_iter<I: IntoIterator<Item = F>>(iter: I) -> Faces {
        let mut faces = Faces::new();
        faces.extend(iter);
        faces
    }
}

impl<F: AsRef<[u32]>> Extend<F> for Faces {
    fn extend<I: IntoIterator<Item = F>>(&mut self, iter: I) {
        for f in iter {
            self.push(f);
        }
    }
}

impl From<Vec<Vec<u32>>> for Faces {
    fn from(v: Vec<Vec<u32>>) -> Faces {
        v.into_iter().collect()
    }
}

impl<'a> IntoIterator for &'a Faces {
    type Item = &'a [u32];
    type IntoIter = FacesIter<'a>;

    fn into_iter(self) -> FacesIter<'a> {
        self.iter()
    }
}

/// The faces of a [`Faces`], in order.
#[derive(Clone)]
pub struct FacesIter<'a> {
    faces: &'a Faces,
    front: usize,
    back: usize,
}

impl<'a> Iterator for FacesIter<'a> {
    type Item = &'a [u32];

    #[inline]
    fn next(&mut self) -> Option<&'a [u32]> {
        if self.front == self.back {
            return None;
        }
        let r = self.faces.range(self.front);
        self.front += 1;
        Some(&self.faces.indices[r])
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let n = self.back - self.front;
        (n, Some(n))
    }
}

impl DoubleEndedIterator for FacesIter<'_> {
    fn next_back(&mut self) -> Option<Self::Item> {
        if self.front == self.back {
            return None;
        }
        self.back -= 1;
        Some(&self.faces.indices[self.faces.range(self.back)])
    }
}

impl ExactSizeIterator for FacesIter<'_> {}

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

#[cfg(test)]
mod tests {
    use super::*;

    /// The faces as lists, written out by hand for each case.
    fn lists(f: &Faces) -> Vec<Vec<u32>> {
        f.iter().map(<[u32]>::to_vec).collect()
    }

    #[test]
    fn same_sized_faces_keep_no_ends_and_mixed_ones_do() {
        let mut f = Faces::new();
        f.push([0, 1, 2]);
        f.push(vec![2, 1, 3]);
        assert_eq!(f.arity(), Some(3));
        assert_eq!(f.indices(), [0, 1, 2, 2, 1, 3]);
        // A quad after two triangles: every face keeps its end from now on.
        f.push([3, 4, 5, 6]);
        f.push([6, 5, 7]);
        assert_eq!(f.arity(), None);
        assert_eq!(f.len(), 4);
        assert_eq!(
            lists(&f),
            [
                vec![0, 1, 2],
                vec![2, 1, 3],
                vec![3, 4, 5, 6],
                vec![6, 5, 7]
            ]
        );
        assert_eq!(&f[2], [3, 4, 5, 6]);
        assert_eq!(f.get(3), Some(&[6, 5, 7][..]));
        assert_eq!(f.get(4), None);
        assert_eq!(
            f.iter().rev().map(<[u32]>::len).collect::<Vec<_>>(),
            [3, 4, 3, 3]
        );
    }

    #[test]
    fn editing_in_place_and_retaining() {
        let mut f: Faces = vec![vec![0, 1, 2], vec![3, 4, 5, 6], vec![7, 8, 9]].into();
        for face in f.iter_mut() {
            face.reverse();
        }
        f[0][0] = 10;
        assert_eq!(lists(&f), [vec![10, 1, 0], vec![6, 5, 4, 3], vec![9, 8, 7]]);
        // Dropping the quad leaves triangles only: kept without ends, and
        // equal to the same triangles pushed one by one.
        f.retain(|face| face.len() == 3);
        assert_eq!(f.arity(), Some(3));
        let same: Faces = [[10, 1, 0], [9, 8, 7]].into_iter().collect();
        assert_eq!(f, same);
        assert_ne!(f, Faces::uniform(3, vec![10, 1, 0]));
        assert!(Faces::new().is_empty());
        assert_eq!(Faces::new().arity(), None);
    }

    #[test]
    fn fanned_soup_cuts_polygons_from_their_first_corner() {
        let soup = PolygonSoup {
            positions: vec![DVec3::ZERO; 6],
            faces: vec![vec![0, 1, 2, 3, 4], vec![0, 4, 5]].into(),
            face_lines: vec![7, 8],
            ..PolygonSoup::default()
        };
        let f = soup.fanned();
        // A pentagon makes 3 triangles (0 1 2, 0 2 3, 0 3 4), a triangle 1.
        assert_eq!(
            lists(&f.faces),
            [vec![0, 1, 2], vec![0, 2, 3], vec![0, 3, 4], vec![0, 4, 5]]
        );
        assert_eq!(f.face_lines, [7, 7, 7, 8]);
    }
}
