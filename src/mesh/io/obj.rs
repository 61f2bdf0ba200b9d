//! Wavefront OBJ: `v`, `vt` and `f` statements; everything else is
//! ignored.
//!
//! The writer writes `v` lines (and `vt`, `vn` where there are texture
//! coordinates or normals) then 1-based `f` lines.

use std::io::{self, Write};

use glam::DVec2;

use crate::mesh::soup::{MeshFileError, PolygonSoup};

use super::raw::{Raw, UvRead, NO_UV};
use super::read::check_deadline;
use super::text::{parse_index, parse_number, parse_position, strip_comment, utf8, Line, Source};
use super::write::{put_indices, put_position, Polygons};

/// Parses OBJ text into a checked soup.
pub(super) fn parse(name: &str, bytes: &[u8]) -> Result<PolygonSoup, MeshFileError> {
    parse_as(name, bytes, false).map(|(soup, _)| soup)
}

/// Parses OBJ text into a checked soup and its corners' texture
/// coordinates (`vt` lines and `f v/vt` corners), when it has them.
pub(super) fn parse_with_uvs(
    name: &str,
    bytes: &[u8],
) -> Result<(PolygonSoup, UvRead), MeshFileError> {
    parse_as(name, bytes, true)
}

/// Parses OBJ text; texture coordinates only where `uvs` asks for them
/// (else `vt` lines and the `/t` of corners are ignored, as always).
fn parse_as(name: &str, bytes: &[u8], uvs: bool) -> Result<(PolygonSoup, UvRead), MeshFileError> {
    let text = utf8(name, bytes, 1)?;
    let mut raw = Raw::new(1);
    raw.want_uvs = uvs;
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
            Some("vt") if raw.want_uvs => {
                let uv = parse_texture(name, &line, toks).unwrap_or_else(|e| {
                    raw.uv_problem(e);
                    DVec2::ZERO
                });
                raw.uv_values.push(uv);
            }
            Some("f") | Some("fo") => {
                parse_face(name, &line, toks, &mut raw)?;
                raw.end_face(line.no, 1);
            }
            // vn, vp, o, g, s, usemtl, mtllib, l, p, free-form
            // geometry: nothing this reader needs.
            _ => {}
        }
    }
    raw.finish_with_uvs(name, Some(Source { text, first: 1 }))
}

/// A `vt` statement's `u` and `v` (`v` 0 where it is left out; a third
/// value, `w`, is ignored).
fn parse_texture<'a>(
    name: &str,
    line: &Line,
    mut toks: impl Iterator<Item = &'a str>,
) -> Result<DVec2, MeshFileError> {
    let Some(u) = toks.next() else {
        return Err(line.end(name, "a texture coordinate needs a value: `vt u v`"));
    };
    let u_at = u;
    let u = parse_number(name, line, u)?;
    let v = match toks.next() {
        Some(v) => parse_number(name, line, v)?,
        None => 0.0,
    };
    if !(u.is_finite() && v.is_finite()) {
        return Err(line.at(name, u_at, "a texture coordinate must be finite"));
    }
    Ok(DVec2::new(u, v))
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
    let textures = raw.uv_values.len();
    for tok in toks {
        let mut parts = tok.split('/');
        let first = parts.next().unwrap_or(tok);
        let i = parse_index(name, line, first)?;
        let i = resolve(number, count, i).map_err(|m| line.at(name, tok, m))?;
        raw.indices.push(i);
        if !raw.want_uvs {
            continue;
        }
        let uv = match parts.next().filter(|t| !t.is_empty()) {
            Some(t) => {
                let k = parse_index(name, line, t)
                    .map_err(|_| {
                        line.at(
                            name,
                            tok,
                            format!("expected a texture coordinate index, found `{t}`"),
                        )
                    })
                    .and_then(|k| {
                        resolve_texture(number, textures, k).map_err(|m| line.at(name, tok, m))
                    });
                k.unwrap_or_else(|e| {
                    raw.uv_problem(e);
                    NO_UV
                })
            }
            None => NO_UV,
        };
        raw.push_corner_uv(uv);
    }
    Ok(())
}

/// A written `vt` index as 0-based, checked against the `vt` lines so far
/// (negative indices count back from the last).
fn resolve_texture(face: usize, count: usize, i: i64) -> Result<i64, String> {
    let resolved = if i > 0 { i - 1 } else { count as i64 + i };
    if i == 0 || resolved < 0 || resolved >= count as i64 {
        return Err(format!(
            "face {face} refers to texture coordinate {i}, but {count} `vt` lines precede it"
        ));
    }
    Ok(resolved)
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

/// OBJ: `v` lines (then `vt` and `vn` lines where there are texture
/// coordinates or normals), then 1-based `f` lines: `v`, `v/t`, `v//n` or
/// `v/t/n` corners.
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
    let uvs = s.uvs();
    if let Some(uvs) = uvs {
        for t in &uvs.values {
            writeln!(w, "vt {:?} {:?}", t.x, t.y)?;
        }
    }
    let normals = s.normals();
    if let Some(normals) = normals {
        for &n in normals {
            w.write_all(b"vn ")?;
            put_position(w, n)?;
        }
    }
    if uvs.is_none() && normals.is_none() {
        return s.each_face(&mut |f| {
            w.write_all(b"f")?;
            put_indices(w, f, 1)
        });
    }
    let normal_corners = s.normal_corners();
    let mut corner = 0;
    s.each_face(&mut |f| {
        w.write_all(b"f")?;
        for &i in f {
            let v = u64::from(i) + 1;
            let n = normal_corners.map_or(v, |c| u64::from(c[corner]) + 1);
            match uvs {
                Some(uvs) => {
                    let t = u64::from(uvs.corners[corner]) + 1;
                    if normals.is_some() {
                        write!(w, " {v}/{t}/{n}")?;
                    } else {
                        write!(w, " {v}/{t}")?;
                    }
                }
                None => write!(w, " {v}//{n}")?,
            }
            corner += 1;
        }
        w.write_all(b"\n")
    })
}
