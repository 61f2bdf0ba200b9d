//! Mesh files: reading OBJ, OFF and PLY (ASCII or binary little-endian) into
//! a checked [`PolygonSoup`], and writing a soup as OBJ, OFF or ASCII PLY.
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

use std::io::{self, Read, Write};
use std::ops::Range;
use std::path::Path;

use glam::DVec3;

use super::build::SoupSharpness;
use super::halfedge::Mesh;
use super::soup::{first_repeat, Faces, MeshFileError, Place, PolygonSoup};

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

/// Reads the mesh file at `path`, its format chosen by extension. A file
/// larger than [`max_file_bytes`] is refused: a regular file by its size
/// before it is read, anything else (a device, a pipe) as soon as reading
/// passes the limit.
pub fn read(path: &Path) -> Result<PolygonSoup, MeshFileError> {
    let name = path.display().to_string();
    let format = format_of(&name, path)?;
    let limit = max_file_bytes().map_err(|m| error(&name, None, m))?;
    let bytes = read_bounded_as(&name, path, limit, Some(format))?;
    read_str(&name, format, &bytes)
}

/// Reads the mesh file at `path` (see [`read`]) and builds the half-edge
/// mesh, refusing what is not an oriented 2-manifold (see
/// [`Mesh::from_soup`]). A refusal that names a face or vertex shows its
/// line, which is read from the file again for the message.
///
/// Sharpness (creases, OpenSubdiv's numbers) comes from the file where
/// its format carries it, a PLY `edge` element with `vertex1`, `vertex2`
/// and a `crease` or `sharpness` property, and from a file beside the mesh
/// with the extension `.creases` (see [`CREASES_EXTENSION`]), which is
/// read after it for any format.
pub fn read_mesh(path: &Path) -> Result<Mesh, MeshFileError> {
    let name = path.display().to_string();
    let format = format_of(&name, path)?;
    let limit = max_file_bytes().map_err(|m| error(&name, None, m))?;
    let bytes = read_bounded_as(&name, path, limit, Some(format))?;
    let (soup, marks) = match format {
        Format::Ply => ply::parse_with_sharpness(&name, &bytes)?,
        _ => (read_str(&name, format, &bytes)?, Vec::new()),
    };
    drop(bytes);
    check_deadline(&name, 0)?;
    let mut mesh = build_mesh(path, &soup)?;
    check_deadline(&name, 0)?;
    apply_sharpness(&mut mesh, &marks, 0)?;
    let side = path.with_extension(CREASES_EXTENSION);
    if side.is_file() {
        let marks = read_creases(&side, limit)?;
        apply_sharpness(&mut mesh, &marks, 1)?;
    }
    Ok(mesh)
}

/// The extension of the file of creases beside a mesh: `cube.creases`
/// beside `cube.obj`. Its lines are `e A B S` (the edge between vertices A
/// and B has sharpness S) and `v A S` (vertex A has sharpness S), vertices
/// counted from 1 whatever the mesh's format, S a number of 0 or more or
/// `inf`; `#` starts a comment. A later line for the same edge or vertex
/// wins.
pub const CREASES_EXTENSION: &str = "creases";

/// A sharpness a file gives: an edge by its two vertices or a vertex, as
/// the file numbers them, and where to point for each of them.
struct Mark {
    ends: Vec<i64>,
    sharpness: f64,
    /// An error placed at each vertex number, for messages about it.
    at: Vec<MeshFileError>,
    /// What the file calls the mark, for messages without a line (binary
    /// PLY data): "edge 3"; empty where the message's line shows it.
    what: String,
}

/// `e` with `message`.
fn saying(e: &MeshFileError, message: String) -> MeshFileError {
    MeshFileError {
        message,
        ..e.clone()
    }
}

/// Gives the mesh the sharpness of `marks`, whose vertices the file
/// counts from `base`.
fn apply_sharpness(mesh: &mut Mesh, marks: &[Mark], base: i64) -> Result<(), MeshFileError> {
    use super::halfedge::VertexId;
    let n = mesh.vertex_count();
    for m in marks {
        let what = if m.what.is_empty() {
            String::new()
        } else {
            format!("{}: ", m.what)
        };
        let mut vs = Vec::with_capacity(2);
        for (k, &i) in m.ends.iter().enumerate() {
            let v = i - base;
            if v < 0 || v >= n as i64 {
                return Err(saying(
                    &m.at[k],
                    format!(
                        "{what}vertex {i} is out of range: the mesh has {n} vertices, numbered \
                         from {base}"
                    ),
                ));
            }
            vs.push(VertexId(v as u32));
        }
        let done = match vs[..] {
            [a, b] => match mesh.find_halfedge(a, b) {
                Some(h) if mesh.is_block_edge(h.edge()) => {
                    return Err(saying(
                        &m.at[0],
                        format!(
                            "{what}vertices {} and {} are opposite corners of a quad, not the \
                             ends of an edge of the polygon mesh",
                            m.ends[0], m.ends[1]
                        ),
                    ))
                }
                Some(h) => mesh.set_edge_sharpness(h.edge(), m.sharpness),
                None => {
                    return Err(saying(
                        &m.at[0],
                        format!(
                            "{what}vertices {} and {} are not joined by an edge of the mesh",
                            m.ends[0], m.ends[1]
                        ),
                    ))
                }
            },
            _ => mesh.set_vertex_sharpness(vs[0], m.sharpness),
        };
        done.map_err(|e| saying(&m.at[m.at.len() - 1], format!("{what}{}", e.message)))?;
    }
    Ok(())
}

/// A sharpness as written: a number of 0 or more, or `inf`.
fn sharpness_value(s: f64) -> Result<f64, String> {
    if s.is_nan() || s < 0.0 {
        Err(format!(
            "a sharpness is a number of 0 or more, or `inf` (sharp for ever), not {s}"
        ))
    } else {
        Ok(s)
    }
}

/// Reads a `.creases` file (see [`CREASES_EXTENSION`]).
fn read_creases(path: &Path, limit: u64) -> Result<Vec<Mark>, MeshFileError> {
    let name = path.display().to_string();
    let bytes = read_bounded(&name, path, limit)?;
    let text = utf8(&name, &bytes, 1)?;
    let mut marks = Vec::new();
    for (i, raw) in text.split('\n').enumerate() {
        let line = Line {
            no: i + 1,
            text: raw.strip_suffix('\r').unwrap_or(raw),
        };
        let toks: Vec<&str> = strip_comment(line.text).split_whitespace().collect();
        let Some(&kind) = toks.first() else { continue };
        let want = match kind {
            "e" => 4,
            "v" => 3,
            _ => {
                return Err(line.at(
                    &name,
                    kind,
                    format!(
                        "expected `e A B SHARPNESS` (an edge) or `v A SHARPNESS` (a vertex), \
                         found `{kind}`"
                    ),
                ))
            }
        };
        if toks.len() < want {
            return Err(line.end(
                &name,
                if kind == "e" {
                    "expected `e A B SHARPNESS`: two vertex numbers and a sharpness"
                } else {
                    "expected `v A SHARPNESS`: a vertex number and a sharpness"
                },
            ));
        }
        if let Some(extra) = toks.get(want) {
            return Err(line.at(
                &name,
                extra,
                format!("unexpected `{extra}` after the sharpness"),
            ));
        }
        let mut ends = Vec::new();
        let mut at = Vec::new();
        for t in &toks[1..want - 1] {
            match t.parse::<i64>() {
                Ok(i) if i >= 1 => ends.push(i),
                _ => {
                    return Err(line.at(
                        &name,
                        t,
                        format!("expected a vertex number, counted from 1, found `{t}`"),
                    ))
                }
            }
            at.push(line.at(&name, t, ""));
        }
        let st = toks[want - 1];
        let s = st
            .parse::<f64>()
            .map_err(|_| line.at(&name, st, format!("expected a sharpness, found `{st}`")))?;
        let sharpness = sharpness_value(s).map_err(|m| line.at(&name, st, m))?;
        at.push(line.at(&name, st, ""));
        marks.push(Mark {
            what: String::new(),
            ends,
            sharpness,
            at,
        });
    }
    Ok(marks)
}

/// The half-edge mesh of `soup`, read from `path`.
fn build_mesh(path: &Path, soup: &PolygonSoup) -> Result<Mesh, MeshFileError> {
    Mesh::from_soup(soup).map_err(|e| {
        let name = path.display().to_string();
        let line = e.line.and_then(|no| {
            let limit = max_file_bytes().ok()?;
            let bytes = read_bounded(&name, path, limit).ok()?;
            let text = utf8(&name, &bytes, 1).ok()?;
            let line = Source { text, first: 1 }.line(no)?;
            Some(line.whole(&name, &e.message))
        });
        line.unwrap_or_else(|| error(&name, None, e.message))
    })
}

/// Every 65,536 lines or elements: an error once the run's deadline (see
/// [`crate::deadline::current`]) has passed.
fn check_deadline(name: &str, count: usize) -> Result<(), MeshFileError> {
    if count.is_multiple_of(1 << 16) {
        if let Some(d) = crate::deadline::current().filter(|d| d.passed()) {
            return Err(error(name, None, d.message()));
        }
    }
    Ok(())
}

/// Reads a mesh in `format` from `bytes`; `name` is the file name for
/// messages.
pub fn read_str(name: &str, format: Format, bytes: &[u8]) -> Result<PolygonSoup, MeshFileError> {
    match format {
        Format::Obj => obj::parse(name, bytes),
        Format::Off => off::parse(name, bytes),
        Format::Ply => ply::parse(name, bytes),
    }
}

/// Writes `soup` to `path` atomically, its format chosen by extension (PLY
/// is written as ASCII).
pub fn write(path: &Path, soup: &PolygonSoup) -> Result<(), MeshFileError> {
    write_with_sharpness(path, soup, &[])
}

/// Writes `soup` to `path` as [`write()`] does, with the sharp `edges` (two
/// soup vertices, from 0, and a sharpness) where the format carries them:
/// a PLY `edge` element with `vertex1`, `vertex2` and `crease`, which
/// [`read_mesh`] reads back. OBJ and OFF have no place for them; the
/// caller says so.
pub fn write_with_sharpness(
    path: &Path,
    soup: &PolygonSoup,
    edges: &[(u32, u32, f64)],
) -> Result<(), MeshFileError> {
    write_streamed(path, soup, edges)
}

/// Writes the mesh `m` to `path` as [`write_with_sharpness`] writes
/// [`Mesh::to_soup_with_sharpness`]`(triangles)`, the same bytes, and
/// gives that sharpness. Where the soup would be the mesh's triangles as
/// they are (`triangles`, or no basic block to merge), they are written
/// straight from the mesh: no copy of a large mesh is made.
pub fn write_mesh(path: &Path, m: &Mesh, triangles: bool) -> Result<SoupSharpness, MeshFileError> {
    if triangles || !m.quad_soup_merges() {
        let view = MeshTriangles::new(m);
        let sharp = m.soup_sharpness(&view.index, triangles);
        write_streamed(path, &view, &sharp.edges)?;
        Ok(sharp)
    } else {
        let (soup, sharp) = m.to_soup_with_sharpness(triangles);
        write_streamed(path, &soup, &sharp.edges)?;
        Ok(sharp)
    }
}

/// Writes `s` to `path` atomically, piece by piece, in the format of the
/// path's extension.
fn write_streamed(
    path: &Path,
    s: &dyn Polygons,
    edges: &[(u32, u32, f64)],
) -> Result<(), MeshFileError> {
    let name = path.display().to_string();
    let format = format_of(&name, path)?;
    crate::atomic::write_atomic_with(path, |w| write_polygons(w, format, s, edges))
        .map_err(|e| error(&name, None, format!("cannot write the file: {e}")))
}

/// The text of `soup` in `format` (PLY as ASCII).
pub fn to_bytes(format: Format, soup: &PolygonSoup) -> Vec<u8> {
    let mut out = Vec::new();
    write_polygons(&mut out, format, soup, &[]).expect("writing to memory");
    out
}

// ---------------------------------------------------------------------------
// Reading a file

/// The bytes of the file at `path`, or an error when there are more than
/// `limit` of them.
fn read_bounded(name: &str, path: &Path, limit: u64) -> Result<Vec<u8>, MeshFileError> {
    read_bounded_as(name, path, limit, None)
}

/// [`read_bounded`]; a stream (a device, a pipe) in `format` is also
/// checked as it is read, so that what cannot be a mesh of that format
/// (`/dev/zero`: NUL bytes in a text format, a PLY file without its
/// `ply` line) is refused at once instead of after reading up to the limit.
fn read_bounded_as(
    name: &str,
    path: &Path,
    limit: u64,
    format: Option<Format>,
) -> Result<Vec<u8>, MeshFileError> {
    let cannot = |e: std::io::Error| error(name, None, format!("cannot read the file: {e}"));
    let file = crate::files::open(path).map_err(cannot)?;
    let size = file.size();
    if let Some(size) = size.filter(|&s| s > limit) {
        return Err(too_large(name, Some(size), limit));
    }
    let room = size.map_or(0, |s| usize::try_from(s).unwrap_or(0).saturating_add(1));
    let mut bytes = Vec::with_capacity(room);
    let mut file = file.take(limit.saturating_add(1));
    match (size, format) {
        (None, Some(format)) => {
            // A stream: read in chunks, and look at each as it comes.
            let mut chunk = vec![0u8; 1 << 20];
            loop {
                let n = file.read(&mut chunk).map_err(cannot)?;
                if n == 0 {
                    break;
                }
                let start = bytes.len();
                bytes.extend_from_slice(&chunk[..n]);
                if let Some(m) = stream_problem(format, &bytes, start) {
                    return Err(error(name, None, m));
                }
            }
        }
        _ => {
            file.read_to_end(&mut bytes).map_err(cannot)?;
        }
    }
    if bytes.len() as u64 > limit {
        return Err(too_large(name, None, limit));
    }
    Ok(bytes)
}

/// Why the first bytes of a stream, `bytes` (the new ones from `start`),
/// cannot be a mesh in `format`, if they cannot.
fn stream_problem(format: Format, bytes: &[u8], start: usize) -> Option<String> {
    match format {
        Format::Ply => {
            let head = &bytes[..bytes.len().min(3)];
            (head != &b"ply"[..head.len()])
                .then(|| "a PLY file starts with a line `ply`, and this one does not".to_string())
        }
        _ => bytes[start..].iter().position(|&b| b == 0).map(|i| {
            format!(
                "byte {} is a NUL byte, and {} files are text",
                start + i + 1,
                format.name()
            )
        }),
    }
}

/// "the file is 3 GiB, more than the limit of ...", naming the limit and
/// how to raise it; `size` is `None` for a stream read up to the limit.
fn too_large(name: &str, size: Option<u64>, limit: u64) -> MeshFileError {
    let what = match size {
        Some(s) => format!("the file is {}", bytes_text(s)),
        None => "the file goes on".to_string(),
    };
    error(
        name,
        None,
        format!(
            "{what}, more than the limit of {} for a mesh file; \
             set {MAX_FILE_BYTES_VAR} to a larger number of bytes to read it",
            bytes_text(limit)
        ),
    )
}

/// `n` bytes for a person: "2147483648 bytes (2 GiB)".
fn bytes_text(n: u64) -> String {
    let units = [
        (1u64 << 40, "TiB"),
        (1 << 30, "GiB"),
        (1 << 20, "MiB"),
        (1 << 10, "KiB"),
    ];
    match units.iter().find(|&&(u, _)| n >= u) {
        Some(&(u, unit)) => {
            let v = format!("{:.1}", n as f64 / u as f64);
            let v = v.strip_suffix(".0").unwrap_or(&v);
            format!("{n} bytes ({v} {unit})")
        }
        None => format!("{n} bytes"),
    }
}

// ---------------------------------------------------------------------------
// Shared reading helpers

/// An error about file `name`, at `line` where one applies, with nothing
/// to show on it (binary data, or the whole file at fault).
fn error(name: &str, line: Option<usize>, message: impl Into<String>) -> MeshFileError {
    MeshFileError {
        path: name.to_string(),
        line,
        place: None,
        message: message.into(),
    }
}

/// A recorded line number as an optional one (0 means unknown).
fn known(line: usize) -> Option<usize> {
    (line > 0).then_some(line)
}

/// A line of a text file (or of a PLY header): its 1-based number and its
/// text without the newline.
#[derive(Clone, Copy, Debug)]
struct Line<'a> {
    no: usize,
    text: &'a str,
}

impl Line<'_> {
    /// An error about `part` of this line, a slice of its text (a word);
    /// about the whole statement where `part` is not one (a word of OBJ
    /// lines joined by a backslash).
    fn at(&self, name: &str, part: &str, message: impl Into<String>) -> MeshFileError {
        let range = match offset_in(self.text, part) {
            Some(start) => start..start + part.len(),
            None => statement(self.text),
        };
        self.at_range(name, range, message)
    }

    /// An error about the whole statement on this line.
    fn whole(&self, name: &str, message: impl Into<String>) -> MeshFileError {
        self.at_range(name, statement(self.text), message)
    }

    /// An error just after the last word of this line: where a file ends
    /// too early.
    fn end(&self, name: &str, message: impl Into<String>) -> MeshFileError {
        let n = self.text.trim_end().len();
        self.at_range(name, n..n, message)
    }

    fn at_range(
        &self,
        name: &str,
        range: Range<usize>,
        message: impl Into<String>,
    ) -> MeshFileError {
        MeshFileError {
            path: name.to_string(),
            line: Some(self.no),
            place: Some(Place {
                text: self.text.to_string(),
                start: range.start,
                end: range.end,
            }),
            message: message.into(),
        }
    }
}

/// Where `part` starts in `text`, when it is a slice of it.
fn offset_in(text: &str, part: &str) -> Option<usize> {
    let start = (part.as_ptr() as usize).checked_sub(text.as_ptr() as usize)?;
    (start + part.len() <= text.len()).then_some(start)
}

/// The bytes of a line's statement: from its first word to its last one
/// before any comment.
fn statement(text: &str) -> Range<usize> {
    let body = strip_comment(text);
    let start = body.len() - body.trim_start().len();
    start..body.trim_end().len().max(start)
}

/// A text that a mesh was read from, for messages about its faces after
/// it is read: the text and the number of its first line.
#[derive(Clone, Copy)]
struct Source<'a> {
    text: &'a str,
    first: usize,
}

impl<'a> Source<'a> {
    /// Line `no`, if the text holds it (a walk over the text, made for
    /// messages only).
    fn line(&self, no: usize) -> Option<Line<'a>> {
        let text = self.text.lines().nth(no.checked_sub(self.first)?)?;
        Some(Line { no, text })
    }

    /// The last line: where a file that ends too early ends.
    fn last(&self) -> Line<'a> {
        let (count, text) = self.text.lines().fold((0, ""), |(n, _), l| (n + 1, l));
        Line {
            no: (self.first + count).saturating_sub(1).max(1),
            text,
        }
    }
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

/// `bytes` as UTF-8 text (a leading byte-order mark dropped); `first_line`
/// is the line number the bytes start on.
fn utf8<'a>(name: &str, bytes: &'a [u8], first_line: usize) -> Result<&'a str, MeshFileError> {
    match std::str::from_utf8(bytes) {
        Ok(text) => Ok(text.strip_prefix('\u{feff}').unwrap_or(text)),
        Err(e) => Err(not_text(
            name,
            bytes,
            e.valid_up_to(),
            first_line,
            "the file is not UTF-8 text (an invalid byte on this line)",
        )),
    }
}

/// An error at byte `bad` of `bytes`, the first byte that is not UTF-8;
/// `first_line` is the line number the bytes start on. The line is shown
/// with the invalid bytes as U+FFFD, the caret under the first.
fn not_text(
    name: &str,
    bytes: &[u8],
    bad: usize,
    first_line: usize,
    message: &str,
) -> MeshFileError {
    let good = &bytes[..bad];
    let start = good.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
    let end = bytes[bad..]
        .iter()
        .position(|&b| b == b'\n')
        .map_or(bytes.len(), |i| bad + i);
    let line = first_line + good.iter().filter(|&&b| b == b'\n').count();
    let text = String::from_utf8_lossy(&bytes[start..end]);
    // The bytes before `bad` are UTF-8, so they keep their offsets.
    let col = bad - start;
    MeshFileError {
        path: name.to_string(),
        line: Some(line),
        place: Some(Place {
            text: text.trim_end_matches('\r').to_string(),
            start: col,
            end: col + '\u{fffd}'.len_utf8(),
        }),
        message: message.to_string(),
    }
}

/// The part of `line` before any `#` comment.
fn strip_comment(line: &str) -> &str {
    line.split('#').next().unwrap_or(line)
}

/// A number, or "expected a number, found `tok`" at it.
fn parse_number(name: &str, line: &Line, tok: &str) -> Result<f64, MeshFileError> {
    tok.parse::<f64>()
        .map_err(|_| line.at(name, tok, format!("expected a number, found `{tok}`")))
}

/// A whole number that counts `what`.
fn parse_count(name: &str, line: &Line, tok: &str, what: &str) -> Result<usize, MeshFileError> {
    tok.parse::<usize>().map_err(|_| {
        line.at(
            name,
            tok,
            format!("expected the number of {what}, found `{tok}`"),
        )
    })
}

/// A vertex index as written (no base applied).
fn parse_index(name: &str, line: &Line, tok: &str) -> Result<i64, MeshFileError> {
    tok.parse::<i64>()
        .map_err(|_| line.at(name, tok, format!("expected a vertex index, found `{tok}`")))
}

/// A position from the first three of `toks` (further values are ignored);
/// `raw` numbers it in messages.
fn parse_position<'a>(
    name: &str,
    line: &Line,
    mut toks: impl Iterator<Item = &'a str>,
    raw: &Raw,
) -> Result<DVec3, MeshFileError> {
    let found = [toks.next(), toks.next(), toks.next()];
    let [Some(x), Some(y), Some(z)] = found else {
        let n = found.iter().flatten().count();
        return Err(line.whole(
            name,
            format!("a vertex needs 3 coordinates (x y z), found {n}"),
        ));
    };
    let p = DVec3::new(
        parse_number(name, line, x)?,
        parse_number(name, line, y)?,
        parse_number(name, line, z)?,
    );
    if let Some(k) = (0..3).find(|&k| !p[k].is_finite()) {
        return Err(line.at(name, [x, y, z][k], raw.non_finite(raw.positions.len())));
    }
    Ok(p)
}

/// A mesh as parsed, before its faces are checked: face indices are
/// 0-based but may be out of range.
struct Raw {
    positions: Vec<DVec3>,
    vertex_lines: Vec<usize>,
    /// Every face's vertices, one face after another.
    indices: Vec<i64>,
    /// Where each face's vertices start in `indices`, and where the last
    /// one's end.
    starts: Vec<usize>,
    face_lines: Vec<usize>,
    /// Which word of its line each face's first vertex is (for messages).
    face_words: Vec<u32>,
    /// How the file numbers vertices and faces (1 in OBJ, 0 otherwise).
    base: i64,
    /// Sharpness the file gives (a PLY `edge` element's).
    marks: Vec<Mark>,
}

impl Raw {
    /// An empty mesh numbering from `base`.
    fn new(base: i64) -> Raw {
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
    fn push_vertex(&mut self, p: DVec3, line: usize) {
        self.positions.push(p);
        self.vertex_lines.push(line);
    }

    /// Ends the face whose vertices were pushed onto `indices` since the
    /// last one: read on `line`, its first vertex the `word`-th word there.
    fn end_face(&mut self, line: usize, word: u32) {
        self.starts.push(self.indices.len());
        self.face_lines.push(line);
        self.face_words.push(word);
    }

    /// The number of faces so far.
    fn face_count(&self) -> usize {
        self.face_lines.len()
    }

    /// "vertex 3 has a non-finite coordinate", for vertex `v` (0-based).
    fn non_finite(&self, v: usize) -> String {
        format!(
            "vertex {} has a non-finite coordinate",
            v as i64 + self.base
        )
    }

    /// Checks the mesh and turns it into a soup; `source` is the text it
    /// was read from, to show the lines of faces at fault.
    fn finish(self, name: &str, source: Option<Source>) -> Result<PolygonSoup, MeshFileError> {
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

// ---------------------------------------------------------------------------
// OBJ

mod obj {
    //! Wavefront OBJ: `v` and `f` statements; everything else is ignored.

    use super::*;

    /// Parses OBJ text into a checked soup.
    pub(super) fn parse(name: &str, bytes: &[u8]) -> Result<PolygonSoup, MeshFileError> {
        let text = utf8(name, bytes, 1)?;
        let mut raw = Raw::new(1);
        let mut lines = text.lines().enumerate();
        let mut joined = String::new();
        while let Some((i, first)) = lines.next() {
            check_deadline(name, i)?;
            let line = Line {
                no: i + 1,
                text: first,
            };
            let mut content = strip_comment(first).trim_end();
            if content.ends_with('\\') {
                // A backslash at the end continues the statement on the
                // next line.
                joined.clear();
                loop {
                    match content.strip_suffix('\\') {
                        Some(body) => {
                            joined.push_str(body);
                            joined.push(' ');
                            match lines.next() {
                                Some((_, next)) => content = strip_comment(next).trim_end(),
                                None => break,
                            }
                        }
                        None => {
                            joined.push_str(content);
                            break;
                        }
                    }
                }
                content = &joined;
            }
            let mut toks = content.split_whitespace();
            match toks.next() {
                Some("v") => {
                    let p = parse_position(name, &line, toks, &raw)?;
                    raw.push_vertex(p, line.no);
                }
                Some("f") | Some("fo") => {
                    parse_face(name, &line, toks, &mut raw)?;
                    raw.end_face(line.no, 1);
                }
                // vt, vn, vp, o, g, s, usemtl, mtllib, l, p, free-form
                // geometry: nothing this reader needs.
                _ => {}
            }
        }
        raw.finish(name, Some(Source { text, first: 1 }))
    }

    /// Pushes the 0-based vertices of an `f` statement (forms `i`, `i/t`,
    /// `i//n`, `i/t/n`; negative indices count back from the last vertex so
    /// far).
    fn parse_face<'a>(
        name: &str,
        line: &Line,
        toks: impl Iterator<Item = &'a str>,
        raw: &mut Raw,
    ) -> Result<(), MeshFileError> {
        let number = raw.face_count() + 1;
        let count = raw.positions.len();
        for tok in toks {
            let first = tok.split('/').next().unwrap_or(tok);
            let i = parse_index(name, line, first)?;
            let i = resolve(number, count, i).map_err(|m| line.at(name, tok, m))?;
            raw.indices.push(i);
        }
        Ok(())
    }

    /// A written OBJ index as 0-based, refusing 0 and indices before the
    /// first vertex.
    fn resolve(face: usize, count: usize, i: i64) -> Result<i64, String> {
        if i > 0 {
            return Ok(i - 1);
        }
        if i == 0 {
            return Err(format!(
                "face {face} refers to vertex 0, but OBJ indices start at 1"
            ));
        }
        let resolved = count as i64 + i;
        if resolved < 0 {
            return Err(format!(
                "face {face} refers to vertex {i}, but only {count} vertices precede it"
            ));
        }
        Ok(resolved)
    }
}

// ---------------------------------------------------------------------------
// OFF

mod off {
    //! OFF: an optional header (`OFF`, `COFF`, `NOFF`, `STCNOFF`, ...), the
    //! counts, one vertex per line, one face per line.

    use super::*;

    /// Parses OFF text into a checked soup.
    pub(super) fn parse(name: &str, bytes: &[u8]) -> Result<PolygonSoup, MeshFileError> {
        let text = utf8(name, bytes, 1)?;
        let source = Source { text, first: 1 };
        let mut lines = text
            .lines()
            .enumerate()
            .map(|(i, l)| Line { no: i + 1, text: l })
            .filter(|l| strip_comment(l.text).split_whitespace().next().is_some());
        let (line, counts) = counts(name, &mut lines, source)?;
        let nv = parse_count(name, &line, counts[0], "vertices")?;
        let nf = parse_count(name, &line, counts[1], "faces")?;
        let mut raw = Raw::new(0);
        // Room for what the counts declare, as far as the text can hold it
        // (a vertex takes 6 bytes or more, a face 8): a count is checked
        // against the lines that are there as they are read.
        raw.positions.reserve(nv.min(text.len() / 6));
        raw.face_lines.reserve(nf.min(text.len() / 8));
        for v in 0..nv {
            check_deadline(name, v)?;
            let line = lines
                .next()
                .ok_or_else(|| ends_early(name, source, v, nv, "vertices"))?;
            let p = parse_position(
                name,
                &line,
                strip_comment(line.text).split_whitespace(),
                &raw,
            )?;
            raw.push_vertex(p, line.no);
        }
        let mut toks = Vec::new();
        for f in 0..nf {
            check_deadline(name, f)?;
            let line = lines
                .next()
                .ok_or_else(|| ends_early(name, source, f, nf, "faces"))?;
            toks.clear();
            toks.extend(strip_comment(line.text).split_whitespace());
            parse_face(name, &line, f, &toks, &mut raw)?;
            raw.end_face(line.no, 1);
        }
        if let Some(line) = lines.next() {
            let words: Vec<&str> = strip_comment(line.text).split_whitespace().collect();
            return Err(line.whole(
                name,
                format!(
                    "unexpected `{}` after the {nf} declared faces",
                    words.join(" ")
                ),
            ));
        }
        raw.finish(name, Some(source))
    }

    /// "the file ends after 3 of the 8 declared vertices", where it ends.
    fn ends_early(
        name: &str,
        source: Source,
        got: usize,
        want: usize,
        what: &str,
    ) -> MeshFileError {
        source.last().end(
            name,
            format!("the file ends after {got} of the {want} declared {what}"),
        )
    }

    /// The counts line (after an optional header), with at least two words.
    fn counts<'a>(
        name: &str,
        lines: &mut impl Iterator<Item = Line<'a>>,
        source: Source<'a>,
    ) -> Result<(Line<'a>, Vec<&'a str>), MeshFileError> {
        let expected = "expected the counts line `vertices faces edges`";
        let words = |l: &Line<'a>| -> Vec<&'a str> {
            let text: &'a str = l.text;
            strip_comment(text).split_whitespace().collect()
        };
        let line = lines.next().ok_or_else(|| {
            source
                .last()
                .end(name, format!("the file is empty: {expected}"))
        })?;
        let toks = words(&line);
        let (line, toks) = if is_header(toks[0]) {
            check_header(name, &line, &toks)?;
            if toks.len() > 1 {
                (line, toks[1..].to_vec())
            } else {
                let next = lines.next().ok_or_else(|| {
                    source
                        .last()
                        .end(name, format!("the file ends: {expected}"))
                })?;
                let toks = words(&next);
                (next, toks)
            }
        } else if toks[0].parse::<f64>().is_err() {
            return Err(line.at(
                name,
                toks[0],
                format!(
                    "expected an `OFF` header or the counts line, found `{}`",
                    toks[0]
                ),
            ));
        } else {
            (line, toks)
        };
        if toks.len() < 2 {
            return Err(line.whole(name, format!("{expected}, found `{}`", toks.join(" "))));
        }
        Ok((line, toks))
    }

    /// Whether `tok` is an OFF keyword such as `OFF`, `COFF` or `STCNOFF`.
    fn is_header(tok: &str) -> bool {
        tok.strip_suffix("OFF")
            .is_some_and(|prefix| prefix.chars().all(|c| "STCN4n".contains(c)))
    }

    /// Refuses the OFF variants this reader does not handle.
    fn check_header(name: &str, line: &Line, toks: &[&str]) -> Result<(), MeshFileError> {
        if toks[0].contains('4') {
            return Err(line.at(
                name,
                toks[0],
                "4OFF (four coordinates per vertex) is not supported",
            ));
        }
        if toks[0].contains('n') {
            return Err(line.at(
                name,
                toks[0],
                "nOFF (any number of coordinates per vertex) is not supported",
            ));
        }
        if let Some(&word @ "BINARY") = toks.get(1) {
            return Err(line.at(name, word, "binary OFF is not supported"));
        }
        Ok(())
    }

    /// Pushes face `f`: `k i1 .. ik`, further values (colours) ignored.
    fn parse_face(
        name: &str,
        line: &Line,
        f: usize,
        toks: &[&str],
        raw: &mut Raw,
    ) -> Result<(), MeshFileError> {
        let found = toks[0];
        let k = found.parse::<usize>().map_err(|_| {
            let message = format!("expected the number of vertices of face {f}, found `{found}`");
            line.at(name, found, message)
        })?;
        let listed = toks.len() - 1;
        if listed < k {
            return Err(line.at(
                name,
                found,
                format!("face {f} declares {k} vertices but lists {listed}"),
            ));
        }
        for tok in &toks[1..=k] {
            raw.indices.push(parse_index(name, line, tok)?);
        }
        Ok(())
    }
}

// ---------------------------------------------------------------------------
// PLY

mod ply {
    //! PLY: a text header declaring elements and their properties, then the
    //! data as ASCII words or little-endian binary. The `vertex` element
    //! gives positions (x, y, z), the `face` element a list of vertex
    //! indices; every other element and property is read and dropped.

    use super::*;

    /// A scalar property type.
    #[derive(Clone, Copy, Debug, PartialEq, Eq)]
    enum Scalar {
        I8,
        U8,
        I16,
        U16,
        I32,
        U32,
        F32,
        F64,
    }

    impl Scalar {
        /// The type named `s` in either spelling (`int` or `int32`).
        fn parse(s: &str) -> Option<Scalar> {
            Some(match s {
                "char" | "int8" => Scalar::I8,
                "uchar" | "uint8" => Scalar::U8,
                "short" | "int16" => Scalar::I16,
                "ushort" | "uint16" => Scalar::U16,
                "int" | "int32" => Scalar::I32,
                "uint" | "uint32" => Scalar::U32,
                "float" | "float32" => Scalar::F32,
                "double" | "float64" => Scalar::F64,
                _ => return None,
            })
        }

        /// Its size in bytes in binary data.
        fn size(self) -> usize {
            match self {
                Scalar::I8 | Scalar::U8 => 1,
                Scalar::I16 | Scalar::U16 => 2,
                Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
                Scalar::F64 => 8,
            }
        }

        /// Whether it holds whole numbers.
        fn is_integer(self) -> bool {
            !matches!(self, Scalar::F32 | Scalar::F64)
        }

        /// Decodes little-endian `b` (exactly `size()` bytes).
        fn decode_le(self, b: &[u8]) -> f64 {
            let mut buf = [0u8; 8];
            buf[..b.len()].copy_from_slice(b);
            let [b0, b1, b2, b3, ..] = buf;
            match self {
                Scalar::I8 => f64::from(b0 as i8),
                Scalar::U8 => f64::from(b0),
                Scalar::I16 => f64::from(i16::from_le_bytes([b0, b1])),
                Scalar::U16 => f64::from(u16::from_le_bytes([b0, b1])),
                Scalar::I32 => f64::from(i32::from_le_bytes([b0, b1, b2, b3])),
                Scalar::U32 => f64::from(u32::from_le_bytes([b0, b1, b2, b3])),
                Scalar::F32 => f64::from(f32::from_le_bytes([b0, b1, b2, b3])),
                Scalar::F64 => f64::from_le_bytes(buf),
            }
        }
    }

    /// A property's type: one scalar, or a list with its count type.
    #[derive(Clone, Copy, Debug)]
    enum Kind {
        Scalar(Scalar),
        List { count: Scalar, item: Scalar },
    }

    /// A declared property.
    #[derive(Clone, Debug)]
    struct Property<'a> {
        name: &'a str,
        kind: Kind,
    }

    /// A declared element with its instance count and header line.
    #[derive(Clone, Debug)]
    struct Element<'a> {
        name: &'a str,
        count: usize,
        props: Vec<Property<'a>>,
        line: Line<'a>,
        /// The count as written on `line`, for messages.
        count_word: &'a str,
    }

    impl Element<'_> {
        /// The fewest bytes an instance takes in binary data (its scalars
        /// and its lists' counts), and whether every instance takes that
        /// many (no lists).
        fn least_size(&self) -> (usize, bool) {
            let mut fixed = true;
            let size = self
                .props
                .iter()
                .map(|p| match p.kind {
                    Kind::Scalar(s) => s.size(),
                    Kind::List { count, .. } => {
                        fixed = false;
                        count.size()
                    }
                })
                .sum();
            (size, fixed)
        }
    }

    /// The parsed header.
    struct Header<'a> {
        binary: bool,
        elements: Vec<Element<'a>>,
        /// The `end_header` line.
        end: Line<'a>,
        /// The byte offset where the data starts.
        body: usize,
    }

    /// What an element contributes to the mesh.
    #[derive(Clone, Copy)]
    enum Role {
        /// Positions, with the indices of the x, y and z properties.
        Vertex([usize; 3]),
        /// Faces, with the index of the vertex list property.
        Face(usize),
        /// Sharp edges, with the indices of `vertex1`, `vertex2` and the
        /// sharpness (`crease` or `sharpness`).
        Edge([usize; 3]),
        Skip,
    }

    /// Parses a PLY file into a checked soup.
    pub(super) fn parse(name: &str, bytes: &[u8]) -> Result<PolygonSoup, MeshFileError> {
        parse_with_sharpness(name, bytes).map(|(soup, _)| soup)
    }

    /// Parses a PLY file into a checked soup and the sharpness of its
    /// `edge` element, if it has one with a `crease` or `sharpness`
    /// property.
    pub(super) fn parse_with_sharpness(
        name: &str,
        bytes: &[u8],
    ) -> Result<(PolygonSoup, Vec<Mark>), MeshFileError> {
        let header = parse_header(name, bytes)?;
        let body = &bytes[header.body..];
        if header.binary {
            let mut src = Binary {
                bytes: body,
                pos: 0,
            };
            let mut raw = read_elements(name, &header, &mut src)?;
            let marks = std::mem::take(&mut raw.marks);
            Ok((raw.finish(name, None)?, marks))
        } else {
            let first = header.end.no + 1;
            let text = utf8(name, body, first)?;
            let mut src = Ascii::new(text, header.end);
            let mut raw = read_elements(name, &header, &mut src)?;
            src.check_end(name)?;
            let marks = std::mem::take(&mut raw.marks);
            Ok((raw.finish(name, Some(Source { text, first }))?, marks))
        }
    }

    // -- header

    /// Reads the header lines up to `end_header`.
    fn parse_header<'a>(name: &str, bytes: &'a [u8]) -> Result<Header<'a>, MeshFileError> {
        let mut pos = 0;
        let mut last: Option<Line<'a>> = None;
        let mut format = None;
        let mut elements: Vec<Element<'a>> = Vec::new();
        let end = loop {
            let no = last.map_or(1, |l| l.no + 1);
            if pos >= bytes.len() {
                return Err(match last {
                    None => Line { no: 1, text: "" }
                        .end(name, "the file is empty: expected a PLY header"),
                    Some(l) => l.end(name, "the header ends without an `end_header` line"),
                });
            }
            let stop = bytes[pos..]
                .iter()
                .position(|&b| b == b'\n')
                .map_or(bytes.len(), |k| pos + k);
            let raw = &bytes[pos..stop];
            let raw = raw.strip_suffix(b"\r").unwrap_or(raw);
            pos = stop + 1;
            if no == 1 && raw.trim_ascii() != b"ply" {
                let text = String::from_utf8_lossy(raw);
                let line = Line { no, text: &text };
                return Err(line.whole(name, "not a PLY file: the first line must be `ply`"));
            }
            let text = std::str::from_utf8(raw).map_err(|e| {
                not_text(name, raw, e.valid_up_to(), no, "the PLY header is not text")
            })?;
            let line = Line { no, text };
            last = Some(line);
            if no == 1 {
                continue;
            }
            let toks: Vec<&'a str> = text.split_whitespace().collect();
            match toks.first().copied() {
                None | Some("comment") | Some("obj_info") => {}
                Some("end_header") => break line,
                Some("format") => format = Some(parse_format(name, &line, &toks)?),
                Some("element") => elements.push(parse_element(name, line, &toks)?),
                Some("property") => {
                    let element = elements.last_mut().ok_or_else(|| {
                        line.at(name, toks[0], "a `property` line before any `element`")
                    })?;
                    element.props.push(parse_property(name, &line, &toks)?);
                }
                Some(other) => {
                    return Err(line.at(name, other, format!("unknown PLY header line `{other}`")))
                }
            }
        };
        let binary =
            format.ok_or_else(|| end.whole(name, "the PLY header has no `format` line"))?;
        Ok(Header {
            binary,
            elements,
            end,
            body: pos.min(bytes.len()),
        })
    }

    /// `format ascii 1.0` (false) or `format binary_little_endian 1.0`
    /// (true).
    fn parse_format(name: &str, line: &Line, toks: &[&str]) -> Result<bool, MeshFileError> {
        match toks.get(1).copied() {
            Some("ascii") => Ok(false),
            Some("binary_little_endian") => Ok(true),
            Some(big @ "binary_big_endian") => Err(line.at(
                name,
                big,
                "big-endian binary PLY is not supported; convert it to ascii or binary_little_endian",
            )),
            Some(other) => Err(line.at(
                name,
                other,
                format!("unknown PLY format `{other}`: expected ascii or binary_little_endian"),
            )),
            None => Err(line.whole(
                name,
                "expected `format ascii 1.0` or `format binary_little_endian 1.0`",
            )),
        }
    }

    /// `element NAME COUNT`.
    fn parse_element<'a>(
        name: &str,
        line: Line<'a>,
        toks: &[&'a str],
    ) -> Result<Element<'a>, MeshFileError> {
        let &[_, element, count] = toks else {
            return Err(line.whole(name, "expected `element NAME COUNT`"));
        };
        Ok(Element {
            name: element,
            count: parse_count(name, &line, count, &format!("`{element}` elements"))?,
            props: Vec::new(),
            line,
            count_word: count,
        })
    }

    /// `property TYPE NAME` or `property list COUNT_TYPE ITEM_TYPE NAME`.
    fn parse_property<'a>(
        name: &str,
        line: &Line,
        toks: &[&'a str],
    ) -> Result<Property<'a>, MeshFileError> {
        let scalar = |t: &str| {
            Scalar::parse(t)
                .ok_or_else(|| line.at(name, t, format!("unknown PLY property type `{t}`")))
        };
        let (prop, kind) =
            match *toks {
                [_, "list", count, item, prop] => (
                    prop,
                    Kind::List {
                        count: scalar(count)?,
                        item: scalar(item)?,
                    },
                ),
                [_, ty, prop] if ty != "list" => (prop, Kind::Scalar(scalar(ty)?)),
                _ => return Err(line.whole(
                    name,
                    "expected `property TYPE NAME` or `property list COUNT_TYPE ITEM_TYPE NAME`",
                )),
            };
        Ok(Property { name: prop, kind })
    }

    /// The role of `el`, checking that vertices have x, y, z and faces a
    /// list of integer vertex indices.
    fn role(name: &str, el: &Element) -> Result<Role, MeshFileError> {
        let fail = |message: String| Err(el.line.at(name, el.name, message));
        match el.name {
            "vertex" => {
                let mut ix = [0; 3];
                for (k, axis) in ["x", "y", "z"].into_iter().enumerate() {
                    match el.props.iter().position(|p| p.name == axis) {
                        Some(i) if matches!(el.props[i].kind, Kind::Scalar(_)) => ix[k] = i,
                        Some(_) => return fail(format!("the vertex property `{axis}` is a list")),
                        None => {
                            return fail(format!("the `vertex` element has no `{axis}` property"))
                        }
                    }
                }
                Ok(Role::Vertex(ix))
            }
            "face" => {
                let found = el
                    .props
                    .iter()
                    .position(|p| p.name == "vertex_indices" || p.name == "vertex_index");
                match found.map(|i| (i, el.props[i].kind)) {
                    Some((i, Kind::List { item, .. })) if item.is_integer() => Ok(Role::Face(i)),
                    Some(_) => {
                        fail("the face property `vertex_indices` must be a list of integers".into())
                    }
                    None => fail("the `face` element has no `vertex_indices` list property".into()),
                }
            }
            "edge" => {
                let Some(si) = el
                    .props
                    .iter()
                    .position(|p| p.name == "crease" || p.name == "sharpness")
                else {
                    return Ok(Role::Skip);
                };
                if !matches!(el.props[si].kind, Kind::Scalar(_)) {
                    return fail(format!(
                        "the edge property `{}` is a list, not one number",
                        el.props[si].name
                    ));
                }
                let mut ix = [0, 0, si];
                for (k, end) in ["vertex1", "vertex2"].into_iter().enumerate() {
                    match el.props.iter().position(|p| p.name == end) {
                        Some(i) if matches!(el.props[i].kind, Kind::Scalar(t) if t.is_integer()) => {
                            ix[k] = i
                        }
                        Some(_) => {
                            return fail(format!(
                                "the edge property `{end}` must be one integer, a vertex index"
                            ))
                        }
                        None => {
                            return fail(format!(
                                "the `edge` element gives a `{}` but no `{end}` property: an \
                                 edge's sharpness needs `vertex1` and `vertex2`",
                                el.props[si].name
                            ))
                        }
                    }
                }
                Ok(Role::Edge(ix))
            }
            _ => Ok(Role::Skip),
        }
    }

    // -- data

    /// A source of property values: ASCII words or binary data.
    trait Values {
        /// The next value, read as type `ty`; `None` where the data ends.
        fn next(&mut self, name: &str, ty: Scalar) -> Result<Option<f64>, MeshFileError>;
        /// The line of the next value and which word of it the value is
        /// (0 and 0 in binary data).
        fn position(&mut self) -> (usize, u32);
        /// An error about the value read last (about the file, in binary
        /// data).
        fn at_last(&self, name: &str, message: String) -> MeshFileError;
        /// "the file ends after 3 of the 4 declared `face` elements": where
        /// text ends; at the count in the header for binary data.
        fn ended(&self, name: &str, el: &Element, got: usize) -> MeshFileError;
        /// The bytes left, in binary data.
        fn bytes_left(&self) -> Option<usize>;
    }

    /// ASCII data: whitespace-separated words, read as they are needed.
    struct Ascii<'a> {
        /// The lines not yet reached, `None` after the last.
        ahead: Option<&'a str>,
        /// The line being read, and what is left of it.
        line: Line<'a>,
        rest: &'a str,
        /// Which word of `line` starts `rest`.
        word: u32,
        /// The word read last and its line.
        last: Option<(Line<'a>, &'a str)>,
    }

    impl<'a> Ascii<'a> {
        /// The words of `text`, which follows the header's last line `end`.
        fn new(text: &'a str, end: Line<'a>) -> Ascii<'a> {
            Ascii {
                ahead: (!text.is_empty()).then_some(text),
                line: end,
                rest: "",
                word: 0,
                last: None,
            }
        }

        /// Moves to the start of the next word; false where the data ends.
        fn seek(&mut self) -> bool {
            loop {
                let rest = self.rest.trim_start();
                if !rest.is_empty() {
                    self.rest = rest;
                    return true;
                }
                let Some(text) = self.ahead else {
                    self.rest = "";
                    return false;
                };
                let (line, ahead) = match text.find('\n') {
                    Some(i) => (&text[..i], Some(&text[i + 1..]).filter(|t| !t.is_empty())),
                    None => (text, None),
                };
                let line = line.strip_suffix('\r').unwrap_or(line);
                self.ahead = ahead;
                self.line = Line {
                    no: self.line.no + 1,
                    text: line,
                };
                self.rest = line;
                self.word = 0;
            }
        }

        /// The next word and its line.
        fn take(&mut self) -> Option<(Line<'a>, &'a str)> {
            if !self.seek() {
                return None;
            }
            let end = self
                .rest
                .find(char::is_whitespace)
                .unwrap_or(self.rest.len());
            let w = &self.rest[..end];
            self.rest = &self.rest[end..];
            self.word = self.word.saturating_add(1);
            self.last = Some((self.line, w));
            self.last
        }

        /// Refuses words left after the declared elements.
        fn check_end(&mut self, name: &str) -> Result<(), MeshFileError> {
            match self.take() {
                Some((line, w)) => Err(line.at(
                    name,
                    w,
                    format!("unexpected `{w}` after the declared elements"),
                )),
                None => Ok(()),
            }
        }
    }

    impl Values for Ascii<'_> {
        fn next(&mut self, name: &str, _ty: Scalar) -> Result<Option<f64>, MeshFileError> {
            match self.take() {
                Some((line, w)) => parse_number(name, &line, w).map(Some),
                None => Ok(None),
            }
        }

        fn position(&mut self) -> (usize, u32) {
            self.seek();
            (self.line.no, self.word)
        }

        fn at_last(&self, name: &str, message: String) -> MeshFileError {
            match self.last {
                Some((line, w)) => line.at(name, w, message),
                None => self.line.end(name, message),
            }
        }

        fn ended(&self, name: &str, el: &Element, got: usize) -> MeshFileError {
            self.line.end(
                name,
                format!(
                    "the file ends after {got} of the {} declared `{}` elements",
                    el.count, el.name
                ),
            )
        }

        fn bytes_left(&self) -> Option<usize> {
            None
        }
    }

    /// Little-endian binary data.
    struct Binary<'a> {
        bytes: &'a [u8],
        pos: usize,
    }

    impl Values for Binary<'_> {
        fn next(&mut self, _name: &str, ty: Scalar) -> Result<Option<f64>, MeshFileError> {
            let end = self.pos + ty.size();
            let Some(b) = self.bytes.get(self.pos..end) else {
                return Ok(None);
            };
            self.pos = end;
            Ok(Some(ty.decode_le(b)))
        }

        fn position(&mut self) -> (usize, u32) {
            (0, 0)
        }

        fn at_last(&self, name: &str, message: String) -> MeshFileError {
            error(name, None, message)
        }

        fn ended(&self, name: &str, el: &Element, got: usize) -> MeshFileError {
            el.line.at(
                name,
                el.count_word,
                format!(
                    "the binary data ends after {got} of the {} declared `{}` elements",
                    el.count, el.name
                ),
            )
        }

        fn bytes_left(&self) -> Option<usize> {
            Some(self.bytes.len() - self.pos)
        }
    }

    /// Reads every element's instances in header order. A count is checked
    /// against the data before it is looped over: an element without
    /// properties may have no instances, and in binary data elements of a
    /// fixed size must fit in the bytes left; every other instance reads
    /// at least one word or byte, so a loop ends where the data does.
    fn read_elements<V: Values>(
        name: &str,
        header: &Header,
        src: &mut V,
    ) -> Result<Raw, MeshFileError> {
        if !header.elements.iter().any(|e| e.name == "vertex") {
            return Err(header
                .end
                .whole(name, "the PLY header declares no `vertex` element"));
        }
        let mut raw = Raw::new(0);
        for el in &header.elements {
            let role = role(name, el)?;
            if el.props.is_empty() {
                if el.count > 0 {
                    return Err(el.line.at(
                        name,
                        el.count_word,
                        format!(
                            "the `{}` element declares {} instances but no properties to read \
                             for them; declare its properties, or a count of 0",
                            el.name, el.count
                        ),
                    ));
                }
                continue;
            }
            let (least, fixed) = el.least_size();
            if let Some(left) = src.bytes_left() {
                if fixed && el.count > left / least {
                    return Err(src.ended(name, el, left / least));
                }
            }
            if let Role::Vertex(_) = role {
                let room = src.bytes_left().map_or(0, |left| left / least);
                raw.positions.reserve(el.count.min(room));
                raw.vertex_lines.reserve(el.count.min(room));
            }
            for i in 0..el.count {
                check_deadline(name, i)?;
                read_instance(name, el, role, i, src, &mut raw)?;
            }
        }
        Ok(raw)
    }

    /// Reads instance `i` of `el`, keeping what its role needs.
    fn read_instance<V: Values>(
        name: &str,
        el: &Element,
        role: Role,
        i: usize,
        src: &mut V,
        raw: &mut Raw,
    ) -> Result<(), MeshFileError> {
        let (line, _) = src.position();
        let mut xyz = [0.0; 3];
        let mut face_at = (line, 0);
        let mut edge = [0.0; 3];
        let mut edge_at = Vec::new();
        for (p, prop) in el.props.iter().enumerate() {
            match prop.kind {
                Kind::Scalar(ty) => {
                    let v = value(name, el, i, src, ty)?;
                    if let Role::Edge(ix) = role {
                        for k in (0..3).filter(|&k| ix[k] == p) {
                            if k == 2 {
                                sharpness_value(v)
                                    .map_err(|m| src.at_last(name, format!("edge {i}: {m}")))?;
                            }
                            edge[k] = v;
                            edge_at.push((k, src.at_last(name, String::new())));
                        }
                    }
                    if let Role::Vertex(ix) = role {
                        for k in (0..3).filter(|&k| ix[k] == p) {
                            if !v.is_finite() {
                                return Err(src.at_last(name, raw.non_finite(raw.positions.len())));
                            }
                            xyz[k] = v;
                        }
                    }
                }
                Kind::List { count, item } => {
                    let keep = matches!(role, Role::Face(fp) if fp == p);
                    if keep {
                        face_at = src.position();
                    }
                    let n = value(name, el, i, src, count)?;
                    let n = whole(n).ok_or_else(|| {
                        src.at_last(
                            name,
                            format!("a list length must be a whole number, found {n}"),
                        )
                    })?;
                    // A list longer than the binary data left ends it.
                    if let Some(left) = src.bytes_left() {
                        if n > (left / item.size()) as u64 {
                            return Err(src.ended(name, el, i));
                        }
                    }
                    for _ in 0..n {
                        let v = value(name, el, i, src, item)?;
                        if keep {
                            raw.indices.push(index(name, src, v)?);
                        }
                    }
                }
            }
        }
        match role {
            Role::Vertex(_) => raw.push_vertex(DVec3::from(xyz), line),
            Role::Face(_) => raw.end_face(face_at.0, face_at.1.saturating_add(1)),
            Role::Edge(_) => {
                edge_at.sort_by_key(|(k, _)| *k);
                let at: Vec<MeshFileError> = edge_at.into_iter().map(|(_, e)| e).collect();
                let mut ends = Vec::with_capacity(2);
                for k in 0..2 {
                    ends.push(index(name, src, edge[k]).map_err(|e| saying(&at[k], e.message))?);
                }
                raw.marks.push(Mark {
                    ends,
                    sharpness: edge[2],
                    at,
                    what: format!("edge {i}"),
                });
            }
            Role::Skip => {}
        }
        Ok(())
    }

    /// The next value, or an error saying where the data ended.
    fn value<V: Values>(
        name: &str,
        el: &Element,
        i: usize,
        src: &mut V,
        ty: Scalar,
    ) -> Result<f64, MeshFileError> {
        match src.next(name, ty)? {
            Some(v) => Ok(v),
            None => Err(src.ended(name, el, i)),
        }
    }

    /// `v` as a non-negative whole number, if it is one.
    fn whole(v: f64) -> Option<u64> {
        (v >= 0.0 && v.fract() == 0.0 && v <= u64::MAX as f64).then_some(v as u64)
    }

    /// `v` as a vertex index (range is checked later).
    fn index<V: Values>(name: &str, src: &V, v: f64) -> Result<i64, MeshFileError> {
        if v.fract() == 0.0 && v.abs() <= i64::MAX as f64 {
            Ok(v as i64)
        } else {
            Err(src.at_last(name, format!("expected a vertex index, found {v}")))
        }
    }
}

// ---------------------------------------------------------------------------
// Writing

/// What the writers read: the positions and the polygons of a soup, or of
/// a mesh's triangles read in place ([`MeshTriangles`]), so that a large
/// mesh is written without a copy of it.
trait Polygons {
    fn vertex_count(&self) -> usize;
    fn face_count(&self) -> usize;
    /// The most corners of any face (0 without faces).
    fn longest(&self) -> usize;
    /// Calls `f` on every position in order, stopping at an error.
    fn each_position(&self, f: &mut dyn FnMut(DVec3) -> io::Result<()>) -> io::Result<()>;
    /// Calls `f` on every face's corners in order, stopping at an error.
    fn each_face(&self, f: &mut dyn FnMut(&[u32]) -> io::Result<()>) -> io::Result<()>;
}

impl Polygons for PolygonSoup {
    fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    fn face_count(&self) -> usize {
        self.faces.len()
    }

    fn longest(&self) -> usize {
        match self.faces.arity() {
            Some(n) => n,
            None => self.faces.iter().map(<[u32]>::len).max().unwrap_or(0),
        }
    }

    fn each_position(&self, f: &mut dyn FnMut(DVec3) -> io::Result<()>) -> io::Result<()> {
        self.positions.iter().try_for_each(|&p| f(p))
    }

    fn each_face(&self, f: &mut dyn FnMut(&[u32]) -> io::Result<()>) -> io::Result<()> {
        self.faces.iter().try_for_each(f)
    }
}

/// A mesh's triangles as [`Mesh::to_soup`] gives them (its live vertices
/// and faces in order), read from the mesh as they are written.
struct MeshTriangles<'m> {
    mesh: &'m Mesh,
    /// The soup vertex of each vertex slot (`u32::MAX` for a dead slot).
    index: Vec<u32>,
    vertices: usize,
}

impl<'m> MeshTriangles<'m> {
    fn new(mesh: &'m Mesh) -> MeshTriangles<'m> {
        let mut index = vec![u32::MAX; mesh.v_alive.len()];
        let mut vertices = 0;
        for v in mesh.vertices() {
            index[v.index()] = vertices as u32;
            vertices += 1;
        }
        MeshTriangles {
            mesh,
            index,
            vertices,
        }
    }
}

impl Polygons for MeshTriangles<'_> {
    fn vertex_count(&self) -> usize {
        self.vertices
    }

    fn face_count(&self) -> usize {
        self.mesh.face_count()
    }

    fn longest(&self) -> usize {
        if self.mesh.face_count() > 0 {
            3
        } else {
            0
        }
    }

    fn each_position(&self, f: &mut dyn FnMut(DVec3) -> io::Result<()>) -> io::Result<()> {
        self.mesh
            .vertices()
            .try_for_each(|v| f(self.mesh.position(v)))
    }

    fn each_face(&self, f: &mut dyn FnMut(&[u32]) -> io::Result<()>) -> io::Result<()> {
        self.mesh.faces().try_for_each(|g| {
            let [a, b, c] = self.mesh.face_vertices(g);
            f(&[
                self.index[a.index()],
                self.index[b.index()],
                self.index[c.index()],
            ])
        })
    }
}

/// Writes one face's indices (plus `base`), each after a space, and a
/// newline.
fn put_indices(w: &mut dyn Write, face: &[u32], base: u64) -> io::Result<()> {
    // Decimal digits by hand into one buffer per face: the same text as
    // `to_string` of each, without an allocation per index.
    let mut buf = [0u8; 256];
    let mut n = 0;
    for &i in face {
        if n + 22 > buf.len() {
            w.write_all(&buf[..n])?;
            n = 0;
        }
        buf[n] = b' ';
        n += 1;
        let mut x = u64::from(i) + base;
        let mut digits = [0u8; 20];
        let mut k = digits.len();
        loop {
            k -= 1;
            digits[k] = b'0' + (x % 10) as u8;
            x /= 10;
            if x == 0 {
                break;
            }
        }
        let d = &digits[k..];
        buf[n..n + d.len()].copy_from_slice(d);
        n += d.len();
    }
    buf[n] = b'\n';
    w.write_all(&buf[..n + 1])
}

/// Writes `x y z` with exactly round-tripping coordinates.
fn put_position(w: &mut dyn Write, p: DVec3) -> io::Result<()> {
    writeln!(w, "{:?} {:?} {:?}", p.x, p.y, p.z)
}

/// OBJ: `v` lines then 1-based `f` lines.
fn write_obj(w: &mut dyn Write, s: &dyn Polygons) -> io::Result<()> {
    writeln!(
        w,
        "# subgram mesh: {} vertices, {} faces",
        s.vertex_count(),
        s.face_count()
    )?;
    s.each_position(&mut |p| {
        w.write_all(b"v ")?;
        put_position(w, p)
    })?;
    s.each_face(&mut |f| {
        w.write_all(b"f")?;
        put_indices(w, f, 1)
    })
}

/// OFF: header, counts, vertices, `k i1 .. ik` faces.
fn write_off(w: &mut dyn Write, s: &dyn Polygons) -> io::Result<()> {
    write!(w, "OFF\n{} {} 0\n", s.vertex_count(), s.face_count())?;
    s.each_position(&mut |p| put_position(w, p))?;
    s.each_face(&mut |f| {
        write!(w, "{}", f.len())?;
        put_indices(w, f, 0)
    })
}

/// ASCII PLY with double coordinates and a `vertex_indices` list (uchar
/// counts where every face has at most 255 vertices), and after the faces
/// an `edge` element where `edges` has any: `vertex1`, `vertex2` and the
/// sharpness as `crease` (`inf` for ever).
fn write_ply(w: &mut dyn Write, s: &dyn Polygons, edges: &[(u32, u32, f64)]) -> io::Result<()> {
    let count_type = if s.longest() <= 255 { "uchar" } else { "uint" };
    write!(
        w,
        "ply\nformat ascii 1.0\ncomment written by subgram\n\
         element vertex {}\nproperty double x\nproperty double y\nproperty double z\n\
         element face {}\nproperty list {count_type} uint vertex_indices\n",
        s.vertex_count(),
        s.face_count()
    )?;
    if !edges.is_empty() {
        write!(
            w,
            "element edge {}\nproperty int vertex1\nproperty int vertex2\n\
             property double crease\n",
            edges.len()
        )?;
    }
    w.write_all(b"end_header\n")?;
    s.each_position(&mut |p| put_position(w, p))?;
    s.each_face(&mut |f| {
        write!(w, "{}", f.len())?;
        put_indices(w, f, 0)
    })?;
    for &(a, b, sharp) in edges {
        writeln!(w, "{a} {b} {sharp:?}")?;
    }
    Ok(())
}

/// Writes `s` in `format`, with the sharp `edges` where the format
/// carries them (PLY).
fn write_polygons(
    w: &mut dyn Write,
    format: Format,
    s: &dyn Polygons,
    edges: &[(u32, u32, f64)],
) -> io::Result<()> {
    match format {
        Format::Obj => write_obj(w, s),
        Format::Off => write_off(w, s),
        Format::Ply => write_ply(w, s, edges),
    }
}
