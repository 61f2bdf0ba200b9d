//! Mesh files: reading OBJ, OFF and PLY (ASCII or binary little-endian) into
//! a checked [`PolygonSoup`], and writing a soup as OBJ, OFF or ASCII PLY.
//!
//! Reading never panics on bad input: every problem is a [`MeshFileError`]
//! that names the file and, for text, the line. Vertex and face numbers in
//! messages follow the file's own convention: 1-based in OBJ, 0-based in OFF
//! and PLY. A soup that reads without error has finite coordinates, faces of
//! at least three distinct, in-range vertices, and at least one face.
//!
//! Coordinates are written with `{:?}`, the shortest text that parses back to
//! the same `f64`, so a soup written and read again is bit-for-bit the same.

use std::borrow::Cow;
use std::path::Path;

use glam::DVec3;

use super::soup::{MeshFileError, PolygonSoup};

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

/// Reads the mesh file at `path`, its format chosen by extension.
pub fn read(path: &Path) -> Result<PolygonSoup, MeshFileError> {
    let name = path.display().to_string();
    let format = format_of(&name, path)?;
    let bytes = std::fs::read(path)
        .map_err(|e| error(&name, None, format!("cannot read the file: {e}")))?;
    read_str(&name, format, &bytes)
}

/// Reads a mesh in `format` from `bytes`; `name` is the file name for
/// messages.
pub fn read_str(name: &str, format: Format, bytes: &[u8]) -> Result<PolygonSoup, MeshFileError> {
    let raw = match format {
        Format::Obj => obj::parse(name, bytes)?,
        Format::Off => off::parse(name, bytes)?,
        Format::Ply => ply::parse(name, bytes)?,
    };
    raw.finish(name)
}

/// Writes `soup` to `path` atomically, its format chosen by extension (PLY
/// is written as ASCII).
pub fn write(path: &Path, soup: &PolygonSoup) -> Result<(), MeshFileError> {
    let name = path.display().to_string();
    let format = format_of(&name, path)?;
    crate::atomic::write_atomic(path, &to_bytes(format, soup))
        .map_err(|e| error(&name, None, format!("cannot write the file: {e}")))
}

/// The text of `soup` in `format` (PLY as ASCII).
pub fn to_bytes(format: Format, soup: &PolygonSoup) -> Vec<u8> {
    let text = match format {
        Format::Obj => write_obj(soup),
        Format::Off => write_off(soup),
        Format::Ply => write_ply(soup),
    };
    text.into_bytes()
}

// ---------------------------------------------------------------------------
// Shared reading helpers

/// An error about file `name`, at `line` where one applies.
fn error(name: &str, line: Option<usize>, message: impl Into<String>) -> MeshFileError {
    MeshFileError {
        path: name.to_string(),
        line,
        message: message.into(),
    }
}

/// A recorded line number as an optional one (0 means unknown).
fn known(line: usize) -> Option<usize> {
    (line > 0).then_some(line)
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
        Err(e) => {
            let good = &bytes[..e.valid_up_to()];
            let line = first_line + good.iter().filter(|&&b| b == b'\n').count();
            Err(error(
                name,
                Some(line),
                "the file is not UTF-8 text (an invalid byte on this line)",
            ))
        }
    }
}

/// The part of `line` before any `#` comment.
fn strip_comment(line: &str) -> &str {
    line.split('#').next().unwrap_or(line)
}

/// The number of lines in `text`, at least 1 (for errors at the end).
fn last_line(text: &str) -> usize {
    text.lines().count().max(1)
}

/// A number, or "expected a number, found `tok`".
fn parse_number(name: &str, line: Option<usize>, tok: &str) -> Result<f64, MeshFileError> {
    tok.parse::<f64>()
        .map_err(|_| error(name, line, format!("expected a number, found `{tok}`")))
}

/// A whole number that counts `what`.
fn parse_count(
    name: &str,
    line: Option<usize>,
    tok: &str,
    what: &str,
) -> Result<usize, MeshFileError> {
    tok.parse::<usize>().map_err(|_| {
        error(
            name,
            line,
            format!("expected the number of {what}, found `{tok}`"),
        )
    })
}

/// A vertex index as written (no base applied).
fn parse_index(name: &str, line: Option<usize>, tok: &str) -> Result<i64, MeshFileError> {
    tok.parse::<i64>().map_err(|_| {
        error(
            name,
            line,
            format!("expected a vertex index, found `{tok}`"),
        )
    })
}

/// A position from the first three of `toks` (further values are ignored).
fn parse_position(name: &str, line: usize, toks: &[&str]) -> Result<DVec3, MeshFileError> {
    let line = known(line);
    if toks.len() < 3 {
        return Err(error(
            name,
            line,
            format!("a vertex needs 3 coordinates (x y z), found {}", toks.len()),
        ));
    }
    Ok(DVec3::new(
        parse_number(name, line, toks[0])?,
        parse_number(name, line, toks[1])?,
        parse_number(name, line, toks[2])?,
    ))
}

/// A mesh as parsed, before its faces are checked: face indices are
/// 0-based but may be out of range.
struct Raw {
    positions: Vec<DVec3>,
    vertex_lines: Vec<usize>,
    faces: Vec<Vec<i64>>,
    face_lines: Vec<usize>,
    /// How the file numbers vertices and faces (1 in OBJ, 0 otherwise).
    base: i64,
}

impl Raw {
    /// An empty mesh numbering from `base`.
    fn new(base: i64) -> Raw {
        Raw {
            positions: Vec::new(),
            vertex_lines: Vec::new(),
            faces: Vec::new(),
            face_lines: Vec::new(),
            base,
        }
    }

    /// Adds a vertex read on `line`.
    fn push_vertex(&mut self, p: DVec3, line: usize) {
        self.positions.push(p);
        self.vertex_lines.push(line);
    }

    /// Adds a face read on `line`.
    fn push_face(&mut self, face: Vec<i64>, line: usize) {
        self.faces.push(face);
        self.face_lines.push(line);
    }

    /// Checks the mesh and turns it into a soup.
    fn finish(self, name: &str) -> Result<PolygonSoup, MeshFileError> {
        self.check_vertices(name)?;
        let faces = (0..self.faces.len())
            .map(|f| self.check_face(name, f))
            .collect::<Result<Vec<_>, _>>()?;
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

    /// Refuses non-finite coordinates.
    fn check_vertices(&self, name: &str) -> Result<(), MeshFileError> {
        match self.positions.iter().position(|p| !p.is_finite()) {
            Some(v) => Err(error(
                name,
                known(self.vertex_lines[v]),
                format!(
                    "vertex {} has a non-finite coordinate",
                    v as i64 + self.base
                ),
            )),
            None => Ok(()),
        }
    }

    /// Face `f` with at least three distinct, in-range vertices.
    fn check_face(&self, name: &str, f: usize) -> Result<Vec<u32>, MeshFileError> {
        let face = &self.faces[f];
        let line = known(self.face_lines[f]);
        let number = f as i64 + self.base;
        let fail = |message: String| Err(error(name, line, message));
        if face.len() < 3 {
            return fail(format!(
                "face {number} has {} vertices, but a face needs at least 3",
                face.len()
            ));
        }
        let n = self.positions.len();
        let mut out = Vec::with_capacity(face.len());
        for &i in face {
            match usize::try_from(i).ok().filter(|&i| i < n) {
                Some(i) => out.push(u32::try_from(i).map_err(|_| {
                    error(name, line, "the mesh has too many vertices (over 2^32)")
                })?),
                None => {
                    return fail(format!(
                        "face {number} refers to vertex {}, but there are only {n} vertices",
                        i.saturating_add(self.base)
                    ))
                }
            }
        }
        let mut sorted = out.clone();
        sorted.sort_unstable();
        if let Some(w) = sorted.windows(2).find(|w| w[0] == w[1]) {
            return fail(format!(
                "face {number} repeats vertex {} (a degenerate face)",
                i64::from(w[0]) + self.base
            ));
        }
        Ok(out)
    }
}

// ---------------------------------------------------------------------------
// OBJ

mod obj {
    //! Wavefront OBJ: `v` and `f` statements; everything else is ignored.

    use super::*;

    /// Parses OBJ text into a raw mesh.
    pub(super) fn parse(name: &str, bytes: &[u8]) -> Result<Raw, MeshFileError> {
        let text = utf8(name, bytes, 1)?;
        let mut raw = Raw::new(1);
        for (line, content) in logical_lines(text) {
            let toks: Vec<&str> = content.split_whitespace().collect();
            match toks.first().copied() {
                Some("v") => raw.push_vertex(parse_position(name, line, &toks[1..])?, line),
                Some("f") | Some("fo") => {
                    let face = parse_face(name, line, &toks[1..], &raw)?;
                    raw.push_face(face, line);
                }
                // vt, vn, vp, o, g, s, usemtl, mtllib, l, p, free-form
                // geometry: nothing this reader needs.
                _ => {}
            }
        }
        Ok(raw)
    }

    /// The lines of `text` without comments, with backslash-continued lines
    /// joined, each with its first line number.
    fn logical_lines(text: &str) -> Vec<(usize, Cow<'_, str>)> {
        let mut out = Vec::new();
        let mut pending: Option<(usize, String)> = None;
        for (i, raw) in text.lines().enumerate() {
            let content = strip_comment(raw).trim_end();
            let (body, continues) = match content.strip_suffix('\\') {
                Some(b) => (b, true),
                None => (content, false),
            };
            match pending.take() {
                Some((start, mut acc)) => {
                    acc.push(' ');
                    acc.push_str(body);
                    if continues {
                        pending = Some((start, acc));
                    } else {
                        out.push((start, Cow::Owned(acc)));
                    }
                }
                None if continues => pending = Some((i + 1, body.to_string())),
                None => out.push((i + 1, Cow::Borrowed(body))),
            }
        }
        if let Some((start, acc)) = pending {
            out.push((start, Cow::Owned(acc)));
        }
        out
    }

    /// The 0-based vertices of an `f` statement (forms `i`, `i/t`, `i//n`,
    /// `i/t/n`; negative indices count back from the last vertex so far).
    fn parse_face(
        name: &str,
        line: usize,
        toks: &[&str],
        raw: &Raw,
    ) -> Result<Vec<i64>, MeshFileError> {
        let number = raw.faces.len() + 1;
        let count = raw.positions.len();
        toks.iter()
            .map(|tok| {
                let first = tok.split('/').next().unwrap_or(tok);
                let i = parse_index(name, Some(line), first)?;
                resolve(name, line, number, count, i)
            })
            .collect()
    }

    /// A written OBJ index as 0-based, refusing 0 and indices before the
    /// first vertex.
    fn resolve(
        name: &str,
        line: usize,
        face: usize,
        count: usize,
        i: i64,
    ) -> Result<i64, MeshFileError> {
        let fail = |message: String| Err(error(name, Some(line), message));
        if i > 0 {
            return Ok(i - 1);
        }
        if i == 0 {
            return fail(format!(
                "face {face} refers to vertex 0, but OBJ indices start at 1"
            ));
        }
        let resolved = count as i64 + i;
        if resolved < 0 {
            return fail(format!(
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

    /// A non-empty line's number and words.
    type Line<'a> = (usize, Vec<&'a str>);

    /// Parses OFF text into a raw mesh.
    pub(super) fn parse(name: &str, bytes: &[u8]) -> Result<Raw, MeshFileError> {
        let text = utf8(name, bytes, 1)?;
        let end = last_line(text);
        let mut lines = text
            .lines()
            .enumerate()
            .map(|(i, l)| (i + 1, strip_comment(l).split_whitespace().collect()))
            .filter(|(_, toks): &Line| !toks.is_empty());
        let (line, counts) = counts(name, &mut lines, end)?;
        let nv = parse_count(name, Some(line), counts[0], "vertices")?;
        let nf = parse_count(name, Some(line), counts[1], "faces")?;
        let mut raw = Raw::new(0);
        for v in 0..nv {
            let (line, toks) = lines
                .next()
                .ok_or_else(|| ends_early(name, end, v, nv, "vertices"))?;
            raw.push_vertex(parse_position(name, line, &toks)?, line);
        }
        for f in 0..nf {
            let (line, toks) = lines
                .next()
                .ok_or_else(|| ends_early(name, end, f, nf, "faces"))?;
            raw.push_face(parse_face(name, line, f, &toks)?, line);
        }
        match lines.next() {
            Some((line, toks)) => Err(error(
                name,
                Some(line),
                format!(
                    "unexpected `{}` after the {nf} declared faces",
                    toks.join(" ")
                ),
            )),
            None => Ok(raw),
        }
    }

    /// "the file ends after 3 of the 8 declared vertices".
    fn ends_early(name: &str, end: usize, got: usize, want: usize, what: &str) -> MeshFileError {
        error(
            name,
            Some(end),
            format!("the file ends after {got} of the {want} declared {what}"),
        )
    }

    /// The counts line (after an optional header), with at least two words.
    fn counts<'a>(
        name: &str,
        lines: &mut impl Iterator<Item = Line<'a>>,
        end: usize,
    ) -> Result<Line<'a>, MeshFileError> {
        let expected = "expected the counts line `vertices faces edges`";
        let (line, toks) = lines
            .next()
            .ok_or_else(|| error(name, Some(end), format!("the file is empty: {expected}")))?;
        let (line, toks) = if is_header(toks[0]) {
            check_header(name, line, &toks)?;
            if toks.len() > 1 {
                (line, toks[1..].to_vec())
            } else {
                lines
                    .next()
                    .ok_or_else(|| error(name, Some(end), format!("the file ends: {expected}")))?
            }
        } else if toks[0].parse::<f64>().is_err() {
            return Err(error(
                name,
                Some(line),
                format!(
                    "expected an `OFF` header or the counts line, found `{}`",
                    toks[0]
                ),
            ));
        } else {
            (line, toks)
        };
        if toks.len() < 2 {
            return Err(error(
                name,
                Some(line),
                format!("{expected}, found `{}`", toks.join(" ")),
            ));
        }
        Ok((line, toks))
    }

    /// Whether `tok` is an OFF keyword such as `OFF`, `COFF` or `STCNOFF`.
    fn is_header(tok: &str) -> bool {
        tok.strip_suffix("OFF")
            .is_some_and(|prefix| prefix.chars().all(|c| "STCN4n".contains(c)))
    }

    /// Refuses the OFF variants this reader does not handle.
    fn check_header(name: &str, line: usize, toks: &[&str]) -> Result<(), MeshFileError> {
        let refuse = |message: &str| Err(error(name, Some(line), message));
        if toks[0].contains('4') {
            return refuse("4OFF (four coordinates per vertex) is not supported");
        }
        if toks[0].contains('n') {
            return refuse("nOFF (any number of coordinates per vertex) is not supported");
        }
        if toks.get(1) == Some(&"BINARY") {
            return refuse("binary OFF is not supported");
        }
        Ok(())
    }

    /// Face `f`: `k i1 .. ik`, further values (colours) ignored.
    fn parse_face(
        name: &str,
        line: usize,
        f: usize,
        toks: &[&str],
    ) -> Result<Vec<i64>, MeshFileError> {
        let k = toks[0].parse::<usize>().map_err(|_| {
            let found = toks[0];
            let message = format!("expected the number of vertices of face {f}, found `{found}`");
            error(name, Some(line), message)
        })?;
        let listed = toks.len() - 1;
        if listed < k {
            return Err(error(
                name,
                Some(line),
                format!("face {f} declares {k} vertices but lists {listed}"),
            ));
        }
        toks[1..=k]
            .iter()
            .map(|tok| parse_index(name, Some(line), tok))
            .collect()
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
    struct Property {
        name: String,
        kind: Kind,
    }

    /// A declared element with its instance count and header line.
    #[derive(Clone, Debug)]
    struct Element {
        name: String,
        count: usize,
        props: Vec<Property>,
        line: usize,
    }

    /// The parsed header.
    struct Header {
        binary: bool,
        elements: Vec<Element>,
        /// The line of `end_header`.
        end_line: usize,
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
        Skip,
    }

    /// Parses a PLY file into a raw mesh.
    pub(super) fn parse(name: &str, bytes: &[u8]) -> Result<Raw, MeshFileError> {
        let header = parse_header(name, bytes)?;
        let body = &bytes[header.body..];
        if header.binary {
            let mut src = Binary {
                bytes: body,
                pos: 0,
            };
            read_elements(name, &header, &mut src)
        } else {
            let text = utf8(name, body, header.end_line + 1)?;
            let mut src = Ascii::new(text, header.end_line);
            let raw = read_elements(name, &header, &mut src)?;
            src.check_end(name)?;
            Ok(raw)
        }
    }

    // -- header

    /// Reads the header lines up to `end_header`.
    fn parse_header(name: &str, bytes: &[u8]) -> Result<Header, MeshFileError> {
        let mut pos = 0;
        let mut line = 0;
        let mut format = None;
        let mut elements: Vec<Element> = Vec::new();
        loop {
            if pos >= bytes.len() {
                let message = if line == 0 {
                    "the file is empty: expected a PLY header"
                } else {
                    "the header ends without an `end_header` line"
                };
                return Err(error(name, Some(line.max(1)), message));
            }
            let end = bytes[pos..]
                .iter()
                .position(|&b| b == b'\n')
                .map_or(bytes.len(), |k| pos + k);
            line += 1;
            let raw = &bytes[pos..end];
            let raw = raw.strip_suffix(b"\r").unwrap_or(raw);
            pos = end + 1;
            if line == 1 {
                if raw.trim_ascii() != b"ply" {
                    return Err(error(
                        name,
                        Some(1),
                        "not a PLY file: the first line must be `ply`",
                    ));
                }
                continue;
            }
            let text = std::str::from_utf8(raw)
                .map_err(|_| error(name, Some(line), "the PLY header is not text"))?;
            let toks: Vec<&str> = text.split_whitespace().collect();
            match toks.first().copied() {
                None | Some("comment") | Some("obj_info") => {}
                Some("end_header") => break,
                Some("format") => format = Some(parse_format(name, line, &toks)?),
                Some("element") => elements.push(parse_element(name, line, &toks)?),
                Some("property") => {
                    let element = elements.last_mut().ok_or_else(|| {
                        error(name, Some(line), "a `property` line before any `element`")
                    })?;
                    element.props.push(parse_property(name, line, &toks)?);
                }
                Some(other) => {
                    return Err(error(
                        name,
                        Some(line),
                        format!("unknown PLY header line `{other}`"),
                    ))
                }
            }
        }
        let binary =
            format.ok_or_else(|| error(name, Some(line), "the PLY header has no `format` line"))?;
        Ok(Header {
            binary,
            elements,
            end_line: line,
            body: pos.min(bytes.len()),
        })
    }

    /// `format ascii 1.0` (false) or `format binary_little_endian 1.0`
    /// (true).
    fn parse_format(name: &str, line: usize, toks: &[&str]) -> Result<bool, MeshFileError> {
        match toks.get(1).copied() {
            Some("ascii") => Ok(false),
            Some("binary_little_endian") => Ok(true),
            Some("binary_big_endian") => Err(error(
                name,
                Some(line),
                "big-endian binary PLY is not supported; convert it to ascii or binary_little_endian",
            )),
            Some(other) => Err(error(
                name,
                Some(line),
                format!("unknown PLY format `{other}`: expected ascii or binary_little_endian"),
            )),
            None => Err(error(
                name,
                Some(line),
                "expected `format ascii 1.0` or `format binary_little_endian 1.0`",
            )),
        }
    }

    /// `element NAME COUNT`.
    fn parse_element(name: &str, line: usize, toks: &[&str]) -> Result<Element, MeshFileError> {
        let [_, element, count] = toks else {
            return Err(error(name, Some(line), "expected `element NAME COUNT`"));
        };
        Ok(Element {
            name: element.to_string(),
            count: parse_count(name, Some(line), count, &format!("`{element}` elements"))?,
            props: Vec::new(),
            line,
        })
    }

    /// `property TYPE NAME` or `property list COUNT_TYPE ITEM_TYPE NAME`.
    fn parse_property(name: &str, line: usize, toks: &[&str]) -> Result<Property, MeshFileError> {
        let scalar = |t: &str| {
            Scalar::parse(t)
                .ok_or_else(|| error(name, Some(line), format!("unknown PLY property type `{t}`")))
        };
        let (prop, kind) =
            match toks {
                [_, "list", count, item, prop] => (
                    prop,
                    Kind::List {
                        count: scalar(count)?,
                        item: scalar(item)?,
                    },
                ),
                [_, ty, prop] if *ty != "list" => (prop, Kind::Scalar(scalar(ty)?)),
                _ => return Err(error(
                    name,
                    Some(line),
                    "expected `property TYPE NAME` or `property list COUNT_TYPE ITEM_TYPE NAME`",
                )),
            };
        Ok(Property {
            name: prop.to_string(),
            kind,
        })
    }

    /// The role of `el`, checking that vertices have x, y, z and faces a
    /// list of integer vertex indices.
    fn role(name: &str, el: &Element) -> Result<Role, MeshFileError> {
        let fail = |message: String| Err(error(name, Some(el.line), message));
        match el.name.as_str() {
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
            _ => Ok(Role::Skip),
        }
    }

    // -- data

    /// A source of property values: ASCII words or binary data.
    trait Values {
        /// The next value, read as type `ty`; `None` where the data ends.
        fn next(&mut self, name: &str, ty: Scalar) -> Result<Option<f64>, MeshFileError>;
        /// The line of the next value (the last line at the end; `None` in
        /// binary data).
        fn line(&self) -> Option<usize>;
    }

    /// ASCII data: whitespace-separated words with their lines.
    struct Ascii<'a> {
        words: Vec<(usize, &'a str)>,
        pos: usize,
        end: usize,
    }

    impl<'a> Ascii<'a> {
        /// The words of `text`, whose first line follows `header_end`.
        fn new(text: &'a str, header_end: usize) -> Ascii<'a> {
            let mut end = header_end;
            let mut words = Vec::new();
            for (i, l) in text.lines().enumerate() {
                end = header_end + i + 1;
                words.extend(l.split_whitespace().map(|w| (end, w)));
            }
            Ascii {
                words,
                pos: 0,
                end: end.max(1),
            }
        }

        /// Refuses words left after the declared elements.
        fn check_end(&self, name: &str) -> Result<(), MeshFileError> {
            match self.words.get(self.pos) {
                Some(&(line, w)) => Err(error(
                    name,
                    Some(line),
                    format!("unexpected `{w}` after the declared elements"),
                )),
                None => Ok(()),
            }
        }
    }

    impl Values for Ascii<'_> {
        fn next(&mut self, name: &str, _ty: Scalar) -> Result<Option<f64>, MeshFileError> {
            let Some(&(line, w)) = self.words.get(self.pos) else {
                return Ok(None);
            };
            self.pos += 1;
            parse_number(name, Some(line), w).map(Some)
        }

        fn line(&self) -> Option<usize> {
            Some(self.words.get(self.pos).map_or(self.end, |&(l, _)| l))
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

        fn line(&self) -> Option<usize> {
            None
        }
    }

    /// Reads every element's instances in header order.
    fn read_elements(
        name: &str,
        header: &Header,
        src: &mut dyn Values,
    ) -> Result<Raw, MeshFileError> {
        if !header.elements.iter().any(|e| e.name == "vertex") {
            return Err(error(
                name,
                Some(header.end_line),
                "the PLY header declares no `vertex` element",
            ));
        }
        let mut raw = Raw::new(0);
        for el in &header.elements {
            let role = role(name, el)?;
            for i in 0..el.count {
                read_instance(name, el, role, i, src, &mut raw)?;
            }
        }
        Ok(raw)
    }

    /// Reads instance `i` of `el`, keeping what its role needs.
    fn read_instance(
        name: &str,
        el: &Element,
        role: Role,
        i: usize,
        src: &mut dyn Values,
        raw: &mut Raw,
    ) -> Result<(), MeshFileError> {
        let line = src.line().unwrap_or(0);
        let mut xyz = [0.0; 3];
        let mut face = Vec::new();
        for (p, prop) in el.props.iter().enumerate() {
            match prop.kind {
                Kind::Scalar(ty) => {
                    let v = value(name, el, i, src, ty)?;
                    if let Role::Vertex(ix) = role {
                        for k in (0..3).filter(|&k| ix[k] == p) {
                            xyz[k] = v;
                        }
                    }
                }
                Kind::List { count, item } => {
                    let n = value(name, el, i, src, count)?;
                    let n = whole(n).ok_or_else(|| {
                        error(
                            name,
                            src.line(),
                            format!("a list length must be a whole number, found {n}"),
                        )
                    })?;
                    let keep = matches!(role, Role::Face(fp) if fp == p);
                    for _ in 0..n {
                        let v = value(name, el, i, src, item)?;
                        if keep {
                            face.push(index(name, src, v)?);
                        }
                    }
                }
            }
        }
        match role {
            Role::Vertex(_) => raw.push_vertex(DVec3::from(xyz), line),
            Role::Face(_) => raw.push_face(face, line),
            Role::Skip => {}
        }
        Ok(())
    }

    /// The next value, or an error saying where the data ended.
    fn value(
        name: &str,
        el: &Element,
        i: usize,
        src: &mut dyn Values,
        ty: Scalar,
    ) -> Result<f64, MeshFileError> {
        src.next(name, ty)?.ok_or_else(|| {
            let data = if src.line().is_some() {
                "file"
            } else {
                "binary data"
            };
            error(
                name,
                src.line(),
                format!(
                    "the {data} ends after {i} of the {} declared `{}` elements",
                    el.count, el.name
                ),
            )
        })
    }

    /// `v` as a non-negative whole number, if it is one.
    fn whole(v: f64) -> Option<u64> {
        (v >= 0.0 && v.fract() == 0.0 && v <= u64::MAX as f64).then_some(v as u64)
    }

    /// `v` as a vertex index (range is checked later).
    fn index(name: &str, src: &dyn Values, v: f64) -> Result<i64, MeshFileError> {
        if v.fract() == 0.0 && v.abs() <= i64::MAX as f64 {
            Ok(v as i64)
        } else {
            Err(error(
                name,
                src.line(),
                format!("expected a vertex index, found {v}"),
            ))
        }
    }
}

// ---------------------------------------------------------------------------
// Writing

/// Appends one face's indices (plus `base`) to `out`, space-separated.
fn push_indices(out: &mut String, face: &[u32], base: u64) {
    for &i in face {
        out.push(' ');
        out.push_str(&(u64::from(i) + base).to_string());
    }
    out.push('\n');
}

/// Appends `x y z` with exactly round-tripping coordinates.
fn push_position(out: &mut String, p: DVec3) {
    out.push_str(&format!("{:?} {:?} {:?}\n", p.x, p.y, p.z));
}

/// OBJ text: `v` lines then 1-based `f` lines.
fn write_obj(soup: &PolygonSoup) -> String {
    let mut out = format!(
        "# subgram mesh: {} vertices, {} faces\n",
        soup.positions.len(),
        soup.faces.len()
    );
    for &p in &soup.positions {
        out.push_str("v ");
        push_position(&mut out, p);
    }
    for face in &soup.faces {
        out.push('f');
        push_indices(&mut out, face, 1);
    }
    out
}

/// OFF text: header, counts, vertices, `k i1 .. ik` faces.
fn write_off(soup: &PolygonSoup) -> String {
    let mut out = format!("OFF\n{} {} 0\n", soup.positions.len(), soup.faces.len());
    for &p in &soup.positions {
        push_position(&mut out, p);
    }
    for face in &soup.faces {
        out.push_str(&face.len().to_string());
        push_indices(&mut out, face, 0);
    }
    out
}

/// ASCII PLY text with double coordinates and a `vertex_indices` list
/// (uchar counts where every face has at most 255 vertices).
fn write_ply(soup: &PolygonSoup) -> String {
    let longest = soup.faces.iter().map(Vec::len).max().unwrap_or(0);
    let count_type = if longest <= 255 { "uchar" } else { "uint" };
    let mut out = format!(
        "ply\nformat ascii 1.0\ncomment written by subgram\n\
         element vertex {}\nproperty double x\nproperty double y\nproperty double z\n\
         element face {}\nproperty list {count_type} uint vertex_indices\nend_header\n",
        soup.positions.len(),
        soup.faces.len()
    );
    for &p in &soup.positions {
        push_position(&mut out, p);
    }
    for face in &soup.faces {
        out.push_str(&face.len().to_string());
        push_indices(&mut out, face, 0);
    }
    out
}
