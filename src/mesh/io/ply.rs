//! PLY: a text header declaring elements and their properties, then the
//! data as ASCII words or little-endian binary. The `vertex` element
//! gives positions (x, y, z), the `face` element a list of vertex
//! indices; every other element and property is read and dropped.
//!
//! The writer writes ASCII PLY.

use std::io::{self, Write};

use glam::{DVec2, DVec3};

use crate::mesh::soup::{MeshFileError, PolygonSoup};

use super::creases::{saying, sharpness_value, Mark};
use super::raw::{Raw, UvRead};
use super::read::check_deadline;
use super::text::{error, not_text, parse_count, parse_number, utf8, Line, Source};
use super::write::{put_indices, put_position, Polygons};

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
    /// Positions, with the indices of the x, y and z properties, and of
    /// a texture coordinate's two (`u v`, `s t` or `texture_u
    /// texture_v`) where there are.
    Vertex([usize; 3], Option<[usize; 2]>),
    /// Faces, with the index of the vertex list property, and of a
    /// `texcoord` list (u and v of each corner) where there is one.
    Face(usize, Option<usize>),
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
    parse_as(name, bytes, false).map(|(soup, marks, _)| (soup, marks))
}

/// Parses a PLY file into a checked soup, the sharpness of its `edge`
/// element, and its corners' texture coordinates: a face's `texcoord`
/// list, else a vertex's `u v` (or `s t`, `texture_u texture_v`).
pub(super) fn parse_all(
    name: &str,
    bytes: &[u8],
) -> Result<(PolygonSoup, Vec<Mark>, UvRead), MeshFileError> {
    parse_as(name, bytes, true)
}

/// Parses a PLY file; texture coordinates only where `uvs` asks for
/// them (else their properties are read and dropped, as always).
fn parse_as(
    name: &str,
    bytes: &[u8],
    uvs: bool,
) -> Result<(PolygonSoup, Vec<Mark>, UvRead), MeshFileError> {
    let header = parse_header(name, bytes)?;
    let body = &bytes[header.body..];
    if header.binary {
        let mut src = Binary {
            bytes: body,
            pos: 0,
        };
        let mut raw = read_elements(name, &header, &mut src, uvs)?;
        let marks = std::mem::take(&mut raw.marks);
        let (soup, uvs) = raw.finish_with_uvs(name, None)?;
        Ok((soup, marks, uvs))
    } else {
        let first = header.end.no + 1;
        let text = utf8(name, body, first)?;
        let mut src = Ascii::new(text, header.end);
        let mut raw = read_elements(name, &header, &mut src, uvs)?;
        src.check_end(name)?;
        let marks = std::mem::take(&mut raw.marks);
        let (soup, uvs) = raw.finish_with_uvs(name, Some(Source { text, first }))?;
        Ok((soup, marks, uvs))
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
                None => {
                    Line { no: 1, text: "" }.end(name, "the file is empty: expected a PLY header")
                }
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
        let text = std::str::from_utf8(raw)
            .map_err(|e| not_text(name, raw, e.valid_up_to(), no, "the PLY header is not text"))?;
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
    let binary = format.ok_or_else(|| end.whole(name, "the PLY header has no `format` line"))?;
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
        Scalar::parse(t).ok_or_else(|| line.at(name, t, format!("unknown PLY property type `{t}`")))
    };
    let (prop, kind) = match *toks {
        [_, "list", count, item, prop] => (
            prop,
            Kind::List {
                count: scalar(count)?,
                item: scalar(item)?,
            },
        ),
        [_, ty, prop] if ty != "list" => (prop, Kind::Scalar(scalar(ty)?)),
        _ => {
            return Err(line.whole(
                name,
                "expected `property TYPE NAME` or `property list COUNT_TYPE ITEM_TYPE NAME`",
            ))
        }
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
                    None => return fail(format!("the `vertex` element has no `{axis}` property")),
                }
            }
            let scalar = |n: &str| {
                el.props
                    .iter()
                    .position(|p| p.name == n && matches!(p.kind, Kind::Scalar(_)))
            };
            let uv = [("u", "v"), ("s", "t"), ("texture_u", "texture_v")]
                .into_iter()
                .find_map(|(u, v)| Some([scalar(u)?, scalar(v)?]));
            Ok(Role::Vertex(ix, uv))
        }
        "face" => {
            let found = el
                .props
                .iter()
                .position(|p| p.name == "vertex_indices" || p.name == "vertex_index");
            match found.map(|i| (i, el.props[i].kind)) {
                Some((i, Kind::List { item, .. })) if item.is_integer() => {
                    let uv = el
                        .props
                        .iter()
                        .position(|p| p.name == "texcoord" && matches!(p.kind, Kind::List { .. }));
                    Ok(Role::Face(i, uv))
                }
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
    uvs: bool,
) -> Result<Raw, MeshFileError> {
    if !header.elements.iter().any(|e| e.name == "vertex") {
        return Err(header
            .end
            .whole(name, "the PLY header declares no `vertex` element"));
    }
    let mut raw = Raw::new(0);
    raw.want_uvs = uvs;
    for el in &header.elements {
        let role = match role(name, el)? {
            Role::Vertex(ix, _) if !uvs => Role::Vertex(ix, None),
            Role::Face(ix, _) if !uvs => Role::Face(ix, None),
            r => r,
        };
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
        if let Role::Vertex(..) = role {
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
    let mut uv = [0.0; 2];
    let mut face_at = (line, 0);
    let mut texcoords: Vec<f64> = Vec::new();
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
                if let Role::Vertex(ix, uv_ix) = role {
                    for k in (0..3).filter(|&k| ix[k] == p) {
                        if !v.is_finite() {
                            return Err(src.at_last(name, raw.non_finite(raw.positions.len())));
                        }
                        xyz[k] = v;
                    }
                    for k in (0..2).filter(|&k| uv_ix.is_some_and(|t| t[k] == p)) {
                        if !v.is_finite() {
                            raw.uv_problem(src.at_last(
                                name,
                                format!("vertex {i} has a non-finite texture coordinate"),
                            ));
                        }
                        uv[k] = v;
                    }
                }
            }
            Kind::List { count, item } => {
                let keep = matches!(role, Role::Face(fp, _) if fp == p);
                let texture = matches!(role, Role::Face(_, Some(tp)) if tp == p);
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
                    if texture {
                        if !v.is_finite() {
                            raw.uv_problem(src.at_last(
                                name,
                                format!("face {i} has a non-finite texture coordinate"),
                            ));
                        }
                        texcoords.push(v);
                    }
                }
            }
        }
    }
    match role {
        Role::Vertex(_, uv_ix) => {
            raw.push_vertex(DVec3::from(xyz), line);
            if uv_ix.is_some() {
                raw.vertex_uvs.push(DVec2::from(uv));
            }
        }
        Role::Face(_, None) => raw.end_face(face_at.0, face_at.1.saturating_add(1)),
        Role::Face(_, Some(_)) => {
            let corners = raw.indices.len() - raw.face_start();
            if texcoords.len() == 2 * corners {
                raw.push_face_uvs(texcoords.chunks_exact(2).map(|t| DVec2::new(t[0], t[1])));
            } else {
                raw.uv_problem(src.at_last(
                    name,
                    format!(
                        "face {i} has {corners} corners but {} texture coordinate values: \
                         `texcoord` holds u and v of each corner",
                        texcoords.len()
                    ),
                ));
            }
            raw.end_face(face_at.0, face_at.1.saturating_add(1));
        }
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

// -- writing

/// ASCII PLY with double coordinates and a `vertex_indices` list (uchar
/// counts where every face has at most 255 vertices), and after the faces
/// an `edge` element where `edges` has any: `vertex1`, `vertex2` and the
/// sharpness as `crease` (`inf` for ever).
pub(super) fn write_ply(
    w: &mut dyn Write,
    s: &dyn Polygons,
    edges: &[(u32, u32, f64)],
) -> io::Result<()> {
    let count_type = if s.longest() <= 255 { "uchar" } else { "uint" };
    let uv_count_type = if 2 * s.longest() <= 255 {
        "uchar"
    } else {
        "uint"
    };
    let normals = s.normals();
    let uvs = s.uvs();
    write!(
        w,
        "ply\nformat ascii 1.0\ncomment written by subgram\n\
         element vertex {}\nproperty double x\nproperty double y\nproperty double z\n{}\
         element face {}\nproperty list {count_type} uint vertex_indices\n{}",
        s.vertex_count(),
        if normals.is_some() {
            "property double nx\nproperty double ny\nproperty double nz\n"
        } else {
            ""
        },
        s.face_count(),
        if uvs.is_some() {
            format!("property list {uv_count_type} double texcoord\n")
        } else {
            String::new()
        }
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
    match normals {
        Some(normals) => {
            let mut k = 0;
            s.each_position(&mut |p| {
                let n = normals[k];
                k += 1;
                writeln!(
                    w,
                    "{:?} {:?} {:?} {:?} {:?} {:?}",
                    p.x, p.y, p.z, n.x, n.y, n.z
                )
            })?
        }
        None => s.each_position(&mut |p| put_position(w, p))?,
    }
    match uvs {
        None => s.each_face(&mut |f| {
            write!(w, "{}", f.len())?;
            put_indices(w, f, 0)
        })?,
        Some(uvs) => {
            let mut corner = 0;
            s.each_face(&mut |f| {
                write!(w, "{}", f.len())?;
                for i in f {
                    write!(w, " {i}")?;
                }
                write!(w, " {}", 2 * f.len())?;
                for _ in f {
                    let t = uvs.values[uvs.corners[corner] as usize];
                    corner += 1;
                    write!(w, " {:?} {:?}", t.x, t.y)?;
                }
                w.write_all(b"\n")
            })?
        }
    }
    for &(a, b, sharp) in edges {
        writeln!(w, "{a} {b} {sharp:?}")?;
    }
    Ok(())
}
