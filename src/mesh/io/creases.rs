//! Sharpness from a file: the marks a PLY `edge` element or a `.creases`
//! file gives, their check, and putting them on the mesh.

use std::path::Path;

use crate::mesh::halfedge::Mesh;
use crate::mesh::soup::MeshFileError;

use super::read::read_bounded;
use super::text::{strip_comment, utf8, Line};

/// The extension of the file of creases beside a mesh: `cube.creases`
/// beside `cube.obj`. Its lines are `e A B S` (the edge between vertices A
/// and B has sharpness S) and `v A S` (vertex A has sharpness S), vertices
/// counted from 1 whatever the mesh's format, S a number of 0 or more or
/// `inf`; `#` starts a comment. A later line for the same edge or vertex
/// wins.
pub const CREASES_EXTENSION: &str = "creases";

/// A sharpness a file gives: an edge by its two vertices or a vertex, as
/// the file numbers them, and where to point for each of them.
pub(super) struct Mark {
    pub(super) ends: Vec<i64>,
    pub(super) sharpness: f64,
    /// An error placed at each vertex number, for messages about it.
    pub(super) at: Vec<MeshFileError>,
    /// What the file calls the mark, for messages without a line (binary
    /// PLY data): "edge 3"; empty where the message's line shows it.
    pub(super) what: String,
}

/// `e` with `message`.
pub(super) fn saying(e: &MeshFileError, message: String) -> MeshFileError {
    MeshFileError {
        message,
        ..e.clone()
    }
}

/// Gives the mesh the sharpness of `marks`, whose vertices the file
/// counts from `base`.
pub(super) fn apply_sharpness(
    mesh: &mut Mesh,
    marks: &[Mark],
    base: i64,
) -> Result<(), MeshFileError> {
    use crate::mesh::halfedge::VertexId;
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
pub(super) fn sharpness_value(s: f64) -> Result<f64, String> {
    if s.is_nan() || s < 0.0 {
        Err(format!(
            "a sharpness is a number of 0 or more, or `inf` (sharp for ever), not {s}"
        ))
    } else {
        Ok(s)
    }
}

/// Reads a `.creases` file (see [`CREASES_EXTENSION`]).
pub(super) fn read_creases(path: &Path, limit: u64) -> Result<Vec<Mark>, MeshFileError> {
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
