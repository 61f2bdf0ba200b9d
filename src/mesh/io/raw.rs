//! A mesh as parsed, before its faces are checked, and the check that
//! turns it into a polygon soup.

use glam::{DVec2, DVec3};

use crate::mesh::soup::{first_repeat, FaceUvs, Faces, MeshFileError, PolygonSoup};

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
    /// Texture coordinates as read (OBJ `vt`, a PLY face's `texcoord`).
    pub(super) uv_values: Vec<DVec2>,
    /// The texture coordinate of each corner in `indices`, 0-based and
    /// checked against `uv_values` when read, or [`NO_UV`]; empty while
    /// no corner has one.
    pub(super) uv_indices: Vec<i64>,
    /// A texture coordinate per vertex (PLY `u v`), used where the faces
    /// give none of their own.
    pub(super) vertex_uvs: Vec<DVec2>,
    /// Texture coordinates are read only when asked for: a reader that
    /// wants none reads a file as it always has.
    pub(super) want_uvs: bool,
    /// The first problem with the texture coordinates (a `vt` line that is
    /// not two numbers, a corner's index out of range, a face without
    /// them where others have them): they are dropped with a warning,
    /// since the mesh itself is good.
    pub(super) uv_problem: Option<MeshFileError>,
}

/// What a read gave of a file's texture coordinates: the coordinates,
/// or a warning that they were dropped and why (`path:line:col: warning:
/// ...` with the line and a caret), or neither.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct UvRead {
    pub uvs: Option<FaceUvs>,
    pub warning: Option<String>,
}

/// A corner without a texture coordinate.
pub(super) const NO_UV: i64 = i64::MIN;

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
            uv_values: Vec::new(),
            uv_indices: Vec::new(),
            vertex_uvs: Vec::new(),
            want_uvs: false,
            uv_problem: None,
        }
    }

    /// Keeps the first problem with the texture coordinates.
    pub(super) fn uv_problem(&mut self, e: MeshFileError) {
        self.uv_problem.get_or_insert(e);
    }

    /// Where the face being read starts in `indices`.
    pub(super) fn face_start(&self) -> usize {
        self.starts.last().copied().unwrap_or(0)
    }

    /// Gives the corners of the face being read their texture coordinates,
    /// `values` in order (one a corner).
    pub(super) fn push_face_uvs(&mut self, values: impl Iterator<Item = DVec2>) {
        let start = self.face_start();
        self.uv_indices.resize(start, NO_UV);
        for v in values {
            self.uv_indices.push(self.uv_values.len() as i64);
            self.uv_values.push(v);
        }
    }

    /// Records corner `indices[k]`'s texture coordinate (`NO_UV` for
    /// none), the corners before it without one.
    pub(super) fn push_corner_uv(&mut self, uv: i64) {
        if uv == NO_UV && self.uv_indices.is_empty() {
            return;
        }
        let k = self.indices.len() - 1;
        if self.uv_indices.len() < k {
            self.uv_indices.resize(k, NO_UV);
        }
        self.uv_indices.push(uv);
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
        self.finish_with_uvs(name, source).map(|(soup, _)| soup)
    }

    /// [`Raw::finish`], and the texture coordinates of the faces' corners
    /// where the reader asked for them (`want_uvs`) and the file gives
    /// them: every corner of every face has one, else they are dropped
    /// with a warning that points at the first face without.
    pub(super) fn finish_with_uvs(
        mut self,
        name: &str,
        source: Option<Source>,
    ) -> Result<(PolygonSoup, UvRead), MeshFileError> {
        let uvs = if self.want_uvs {
            self.take_uvs(name, source)
        } else {
            UvRead::default()
        };
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
        let soup = PolygonSoup {
            positions: self.positions,
            faces,
            face_lines: self.face_lines,
            vertex_lines: self.vertex_lines,
        };
        Ok((soup, uvs))
    }

    /// The corners' texture coordinates, when some corner has one: each
    /// face's own (`uv_indices`), else each vertex's (`vertex_uvs`); a
    /// warning instead where they are not whole.
    fn take_uvs(&mut self, name: &str, source: Option<Source>) -> UvRead {
        let dropped = |e: MeshFileError| {
            UvRead {
            uvs: None,
            warning: Some(format!(
                "{}\n(the texture coordinates are not used; `--no-uvs` says so without this warning)",
                e.to_string().replacen(": error: ", ": warning: ", 1)
            )),
        }
        };
        if let Some(e) = self.uv_problem.take() {
            return dropped(e);
        }
        if self.uv_indices.is_empty() {
            if self.vertex_uvs.is_empty() {
                return UvRead::default();
            }
            // One per vertex: a corner's is its vertex's (its range is
            // checked with the face).
            let corners = self
                .indices
                .iter()
                .map(|&i| i.clamp(0, u32::MAX as i64) as u32);
            return UvRead {
                uvs: Some(FaceUvs {
                    corners: corners.collect(),
                    values: std::mem::take(&mut self.vertex_uvs),
                }),
                warning: None,
            };
        }
        self.uv_indices.resize(self.indices.len(), NO_UV);
        if let Some(k) = self.uv_indices.iter().position(|&t| t == NO_UV) {
            let f = self.starts.partition_point(|&s| s <= k) - 1;
            let line = self.face_lines[f];
            let message = format!(
                "face {} has no texture coordinate at its corner {}, but other faces have \
                 them: give every corner one (`f v/vt`), or none",
                f as i64 + self.base,
                k - self.starts[f] + 1
            );
            return dropped(match source.and_then(|s| s.line(line)) {
                Some(l) => l.whole(name, message),
                None => error(name, known(line), message),
            });
        }
        let corners = self.uv_indices.iter().map(|&t| t as u32).collect();
        UvRead {
            uvs: Some(FaceUvs {
                values: std::mem::take(&mut self.uv_values),
                corners,
            }),
            warning: None,
        }
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
