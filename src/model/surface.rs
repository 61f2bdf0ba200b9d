//! Bézier surfaces drawn in vlab's surface editor (bezieredit), `.s`
//! files: a header (the bounding box, the contact point, the end point,
//! the heading and up vectors, the size) and patches of 4×4 control points
//! of bicubic Bézier patches.
//!
//! lpfg draws `Surface(id, s)` with the surface's contact point at the
//! turtle, its heading and up vectors on the turtle's, scaled by s divided
//! by `SIZE:`.

use super::error::ModelError as Error;
use super::text::{number, words, Lines};

pub type V3 = [f64; 3];

/// One bicubic Bézier patch: its name and its control points, row by row.
#[derive(Clone, Debug, PartialEq)]
pub struct Patch {
    pub name: String,
    pub points: [[V3; 4]; 4],
}

/// A surface file.
#[derive(Clone, Debug, PartialEq)]
pub struct Surface {
    /// The file's stem: lpfg names the surface by it.
    pub name: String,
    pub file: String,
    pub contact: V3,
    pub end: V3,
    pub heading: V3,
    pub up: V3,
    pub size: f64,
    /// The view file's scale for this surface (`surface: leaf.s 2`).
    pub scale: f64,
    /// The view file's divisions of each patch along s (down the rows of
    /// control points) and t (along a row); lpfg's default, 10 × 10, when
    /// `None`.
    pub divisions: Option<(u32, u32)>,
    pub patches: Vec<Patch>,
}

/// lpfg's divisions of a patch along s and t when the view file gives none.
pub const DEFAULT_DIVISIONS: u32 = 10;

/// Reads `KEY X: x Y: y Z: z` (the key may be several words).
fn labelled(lines: &mut Lines<'_>, key: &str) -> Result<V3, Error> {
    let ws = lines.keyed(key)?;
    let mut v = [0.0; 3];
    for (k, label) in ["X:", "Y:", "Z:"].iter().enumerate() {
        match ws.get(2 * k) {
            Some(w) if w.text.eq_ignore_ascii_case(label) => {}
            Some(w) => {
                return Err(lines.error(*w, format!("expected `{label}`, found `{}`", w.text)))
            }
            None => return Err(lines.error_at_end(format!("expected `{label}` and a number"))),
        }
        v[k] = number(
            lines,
            &ws,
            2 * k + 1,
            &format!("the {} coordinate", &label[..1]),
        )?;
    }
    Ok(v)
}

/// Reads a `.s` file; `name` is the surface's name (the file's stem).
pub fn read_s(path: &str, name: &str, text: &str) -> Result<Surface, Error> {
    let mut lines = Lines::new(path, text);
    let line = lines.next_line("the bounding box (six numbers)")?;
    let ws = words(line);
    for i in 0..6 {
        number(&lines, &ws, i, "a bound of the surface's box")?;
    }
    let contact = labelled(&mut lines, "CONTACT POINT")?;
    let end = labelled(&mut lines, "END POINT")?;
    let heading = labelled(&mut lines, "HEADING")?;
    let up = labelled(&mut lines, "UP")?;
    let ws = lines.keyed("SIZE:")?;
    let size = number(&lines, &ws, 0, "the size")?;
    if size <= 0.0 {
        return Err(lines.error(ws[0], "the size must be positive"));
    }
    let mut patches = Vec::new();
    while !lines.at_end() {
        let pname = lines.next_line("a patch")?.trim().to_string();
        let ws = lines.keyed("TOP COLOR:")?;
        let _ = ws;
        for key in ["AL:", "L:", "BL:"] {
            lines.keyed(key)?;
        }
        let mut points = [[[0.0; 3]; 4]; 4];
        for (r, row) in points.iter_mut().enumerate() {
            let line = lines.next_line(&format!("row {} of patch `{pname}`", r + 1))?;
            let ws = words(line);
            for (c, p) in row.iter_mut().enumerate() {
                for (k, v) in p.iter_mut().enumerate() {
                    *v = number(&lines, &ws, 3 * c + k, "a control point's coordinate")?;
                }
            }
            super::text::no_more(&lines, &ws, 12, "the row's four points")?;
        }
        lines.spend(1, "patches")?;
        patches.push(Patch {
            name: pname,
            points,
        });
    }
    if patches.is_empty() {
        return Err(lines.error_at_end("the surface has no patch after its header"));
    }
    Ok(Surface {
        name: name.to_string(),
        file: path.to_string(),
        contact,
        end,
        heading,
        up,
        size,
        scale: 1.0,
        divisions: None,
        patches,
    })
}

/// The Bernstein polynomials of degree 3 at `t`.
fn bernstein(t: f64) -> [f64; 4] {
    let s = 1.0 - t;
    [s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t]
}

/// The derivatives of the Bernstein polynomials of degree 3 at `t`.
fn bernstein_derivative(t: f64) -> [f64; 4] {
    let s = 1.0 - t;
    [
        -3.0 * s * s,
        3.0 * s * s - 6.0 * t * s,
        6.0 * t * s - 3.0 * t * t,
        3.0 * t * t,
    ]
}

impl Patch {
    /// The point at (u, v) and the partial derivatives there along u and
    /// along v.
    pub fn point_and_tangents(&self, u: f64, v: f64) -> (V3, V3, V3) {
        let (bu, bv) = (bernstein(u), bernstein(v));
        let (du, dv) = (bernstein_derivative(u), bernstein_derivative(v));
        let (mut p, mut pu, mut pv) = ([0.0; 3], [0.0; 3], [0.0; 3]);
        for (r, row) in self.points.iter().enumerate() {
            for (c, q) in row.iter().enumerate() {
                let (w, wu, wv) = (bv[r] * bu[c], bv[r] * du[c], dv[r] * bu[c]);
                for k in 0..3 {
                    p[k] += w * q[k];
                    pu[k] += wu * q[k];
                    pv[k] += wv * q[k];
                }
            }
        }
        (p, pu, pv)
    }

    /// The point at (u, v) in \[0,1\]²: u along a row, v down the rows.
    pub fn point(&self, u: f64, v: f64) -> V3 {
        let (bu, bv) = (bernstein(u), bernstein(v));
        let mut p = [0.0; 3];
        for (r, row) in self.points.iter().enumerate() {
            for (c, q) in row.iter().enumerate() {
                let w = bv[r] * bu[c];
                for k in 0..3 {
                    p[k] += w * q[k];
                }
            }
        }
        p
    }
}

impl Surface {
    /// The surface as triangles in its own frame, each patch cut into
    /// `n`×`n` quads, each quad into two triangles.
    pub fn triangles(&self, n: usize) -> Vec<[V3; 3]> {
        let n = n.max(1);
        let mut out = Vec::with_capacity(self.patches.len() * n * n * 2);
        for p in &self.patches {
            let grid: Vec<Vec<V3>> = (0..=n)
                .map(|i| {
                    (0..=n)
                        .map(|j| p.point(j as f64 / n as f64, i as f64 / n as f64))
                        .collect()
                })
                .collect();
            for i in 0..n {
                for j in 0..n {
                    let (a, b, c, d) = (
                        grid[i][j],
                        grid[i][j + 1],
                        grid[i + 1][j + 1],
                        grid[i + 1][j],
                    );
                    out.push([a, b, c]);
                    out.push([a, c, d]);
                }
            }
        }
        out
    }
}
