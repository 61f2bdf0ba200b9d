//! Wavefront OBJ: `v` and `f` statements; everything else is ignored.
//!
//! The writer writes `v` lines then 1-based `f` lines.

use std::io::{self, Write};

use crate::mesh::soup::{MeshFileError, PolygonSoup};

use super::raw::Raw;
use super::read::check_deadline;
use super::text::{parse_index, parse_position, strip_comment, utf8, Line, Source};
use super::write::{put_indices, put_position, Polygons};

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

/// OBJ: `v` lines then 1-based `f` lines.
pub(super) fn write_obj(w: &mut dyn Write, s: &dyn Polygons) -> io::Result<()> {
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
    if let Some(normals) = s.normals() {
        for &n in normals {
            w.write_all(b"vn ")?;
            put_position(w, n)?;
        }
        return s.each_face(&mut |f| {
            w.write_all(b"f")?;
            for &i in f {
                write!(w, " {0}//{0}", u64::from(i) + 1)?;
            }
            w.write_all(b"\n")
        });
    }
    s.each_face(&mut |f| {
        w.write_all(b"f")?;
        put_indices(w, f, 1)
    })
}
