//! A mesh as parsed, before its faces are checked, and the check that
//! turns it into a polygon soup.

use glam::DVec3;

use crate::mesh::soup::{first_repeat, Faces, MeshFileError, PolygonSoup};

use super::creases::Mark;
use super::text::{error, known, strip_comment, Source};

/// A mesh as parsed, before its faces are checked: face indices are
/// 0-based but may be out of range.
pub(super) struct Raw {
    pub(super) positions: Vec<DVec3>,
    pub(super) vertex_lines: Vec<usize>,
    /// Every face's vertices, one face after another.
    pub(super) indices: Vec<i64>,
    /// Where each face's vertices start in `indices`, and where the last
    /// one's end.
    starts: Vec<usize>,
    pub(super) face_lines: Vec<usize>,
    /// Which word of its line each face's first vertex is (for messages).
    face_words: Vec<u32>,
    /// How the file numbers vertices and faces (1 in OBJ, 0 otherwise).
    base: i64,
    /// Sharpness the file gives (a PLY `edge` element's).
    pub(super) marks: Vec<Mark>,
}

impl Raw {
    /// An empty mesh numbering from `base`.
    pub(super) fn new(base: i64) -> Raw {
        Raw {
            positions: Vec::new(),
            vertex_lines: Vec::new(),
            indices: Vec::new(),
            starts: vec![0],
            face_lines: Vec::new(),
            face_words: Vec::new(),
            base,
            marks: Vec::new(),
        }
    }

    /// Adds a vertex read on `line`.
    pub(super) fn push_vertex(&mut self, p: DVec3, line: usize) {
        self.positions.push(p);
        self.vertex_lines.push(line);
    }

    /// Ends the face whose vertices were pushed onto `indices` since the
    /// last one: read on `line`, its first vertex the `word`-th word there.
    pub(super) fn end_face(&mut self, line: usize, word: u32) {
        self.starts.push(self.indices.len());
        self.face_lines.push(line);
        self.face_words.push(word);
    }

    /// The number of faces so far.
    pub(super) fn face_count(&self) -> usize {
        self.face_lines.len()
    }

    /// "vertex 3 has a non-finite coordinate", for vertex `v` (0-based).
    pub(super) fn non_finite(&self, v: usize) -> String {
        format!(
            "vertex {} has a non-finite coordinate",
            v as i64 + self.base
        )
    }

    /// Checks the mesh and turns it into a soup; `source` is the text it
    /// was read from, to show the lines of faces at fault.
    pub(super) fn finish(
        self,
        name: &str,
        source: Option<Source>,
    ) -> Result<PolygonSoup, MeshFileError> {
        if let Some(v) = self.positions.iter().position(|p| !p.is_finite()) {
            let line = self.vertex_lines[v];
            let located = source.and_then(|s| s.line(line));
            let message = self.non_finite(v);
            return Err(match located {
                Some(l) => l.whole(name, message),
                None => error(name, known(line), message),
            });
        }
        let mut faces = Faces::with_capacity(self.face_count(), self.indices.len());
        for f in 0..self.face_count() {
            faces.push(self.check_face(name, source, f)?);
        }
        if faces.is_empty() {
            return Err(error(name, None, "the mesh has no faces"));
        }
        Ok(PolygonSoup {
            positions: self.positions,
            faces,
            face_lines: self.face_lines,
            vertex_lines: self.vertex_lines,
        })
    }

    /// Face `f` with at least three distinct, in-range vertices.
    fn check_face(
        &self,
        name: &str,
        source: Option<Source>,
        f: usize,
    ) -> Result<Vec<u32>, MeshFileError> {
        let face = &self.indices[self.starts[f]..self.starts[f + 1]];
        let number = f as i64 + self.base;
        // At the face's `k`-th vertex, or at the whole face.
        let fail = |k: Option<usize>, message: String| {
            let line = self.face_lines[f];
            let Some(l) = source.and_then(|s| s.line(line)) else {
                return Err(error(name, known(line), message));
            };
            let word = k.map(|k| self.face_words[f] as usize + k);
            Err(
                match word.and_then(|w| strip_comment(l.text).split_whitespace().nth(w)) {
                    Some(tok) => l.at(name, tok, message),
                    None => l.whole(name, message),
                },
            )
        };
        if face.len() < 3 {
            return fail(
                None,
                format!(
                    "face {number} has {} vertices, but a face needs at least 3",
                    face.len()
                ),
            );
        }
        let n = self.positions.len();
        let mut out = Vec::with_capacity(face.len());
        for (k, &i) in face.iter().enumerate() {
            match usize::try_from(i).ok().filter(|&i| i < n) {
                Some(i) => match u32::try_from(i) {
                    Ok(i) => out.push(i),
                    Err(_) => {
                        return fail(Some(k), "the mesh has too many vertices (over 2^32)".into())
                    }
                },
                None => {
                    return fail(
                        Some(k),
                        format!(
                            "face {number} refers to vertex {}, but there are only {n} vertices",
                            i.saturating_add(self.base)
                        ),
                    )
                }
            }
        }
        if let Some(k) = first_repeat(&out) {
            return fail(
                Some(k),
                format!(
                    "face {number} repeats vertex {} (a degenerate face)",
                    i64::from(out[k]) + self.base
                ),
            );
        }
        Ok(out)
    }
}
