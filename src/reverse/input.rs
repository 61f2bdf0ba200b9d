//! Reading contours: point lists (CSV or whitespace `x y`, header allowed),
//! SVG (`polygon`, `polyline`, `path` with M/L/H/V/Z), and PNG silhouettes.

use std::path::Path;

use glam::DVec2;

use super::trace;

/// A contour: its points, whether it is closed, and where it came from.
#[derive(Clone, Debug, PartialEq)]
pub struct Contour {
    pub points: Vec<DVec2>,
    pub closed: bool,
    /// A description for reports, e.g. "traced from horse.png".
    pub source: String,
}

/// A problem with an input file, with the line where one applies.
#[derive(Clone, Debug, PartialEq)]
pub struct InputError {
    pub path: String,
    pub line: Option<usize>,
    pub message: String,
}

impl std::fmt::Display for InputError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.line {
            Some(l) => write!(f, "{}:{}: error: {}", self.path, l, self.message),
            None => write!(f, "{}: error: {}", self.path, self.message),
        }
    }
}

impl std::error::Error for InputError {}

fn err(path: &str, line: Option<usize>, message: impl Into<String>) -> InputError {
    InputError {
        path: path.to_string(),
        line,
        message: message.into(),
    }
}

/// Reads a contour; the format follows the file's extension (`.svg`,
/// `.png`, anything else is a point list). Point lists are closed.
pub fn read(path: &Path) -> Result<Contour, InputError> {
    let name = path.display().to_string();
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let bytes =
        std::fs::read(path).map_err(|e| err(&name, None, format!("cannot read the file: {e}")))?;
    let c = match ext.as_str() {
        "png" => read_png(&name, &bytes)?,
        "svg" => {
            let text = String::from_utf8(bytes)
                .map_err(|_| err(&name, None, "the SVG file is not UTF-8 text"))?;
            read_svg(&name, &text)?
        }
        _ => {
            let text = String::from_utf8(bytes)
                .map_err(|_| err(&name, None, "the point list is not UTF-8 text"))?;
            read_points(&name, &text)?
        }
    };
    if c.points.len() < 3 {
        return Err(err(
            &name,
            None,
            format!(
                "the contour has {} point(s); at least 3 are needed",
                c.points.len()
            ),
        ));
    }
    Ok(c)
}

/// `x y` per line, separated by commas, semicolons or whitespace. A first
/// line that is not numbers is a header; `#` and `//` start comments.
pub fn read_points(name: &str, text: &str) -> Result<Contour, InputError> {
    let mut points = Vec::new();
    let mut header_seen = false;
    for (k, raw) in text.lines().enumerate() {
        let line = raw.split("//").next().unwrap_or("");
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let fields: Vec<&str> = line
            .split(|c: char| c == ',' || c == ';' || c.is_whitespace())
            .filter(|f| !f.is_empty())
            .collect();
        let nums: Vec<Result<f64, _>> = fields.iter().map(|f| f.parse::<f64>()).collect();
        let numeric = nums.len() >= 2 && nums[..2].iter().all(|n| n.is_ok());
        if !numeric {
            if points.is_empty() && !header_seen && fields.iter().all(|f| f.parse::<f64>().is_err())
            {
                header_seen = true;
                continue; // a header such as `x,y`
            }
            let bad = fields
                .iter()
                .find(|f| f.parse::<f64>().is_err())
                .copied()
                .unwrap_or(line);
            return Err(err(
                name,
                Some(k + 1),
                if fields.len() < 2 {
                    format!("expected two numbers `x y`, found `{line}`")
                } else {
                    format!("expected two numbers `x y`, but `{bad}` is not a number")
                },
            ));
        }
        let (x, y) = (
            nums[0].clone().unwrap_or(0.0),
            nums[1].clone().unwrap_or(0.0),
        );
        if !x.is_finite() || !y.is_finite() {
            return Err(err(
                name,
                Some(k + 1),
                format!("the point ({x}, {y}) is not finite"),
            ));
        }
        points.push(DVec2::new(x, y));
    }
    if points.is_empty() {
        return Err(err(name, None, "the file has no points"));
    }
    Ok(Contour {
        points,
        closed: true,
        source: format!("points from {name}"),
    })
}

/// The largest `polygon`, `polyline` or `path` of an SVG document. SVG's y
/// axis points down; it is flipped so that pictures stay upright.
pub fn read_svg(name: &str, text: &str) -> Result<Contour, InputError> {
    let doc = roxmltree::Document::parse(text).map_err(|e| {
        let pos = e.pos();
        err(
            name,
            Some(pos.row as usize),
            format!("not a valid SVG (XML) document: {e}"),
        )
    })?;
    let mut best: Option<(Vec<DVec2>, bool)> = None;
    for node in doc.descendants().filter(|n| n.is_element()) {
        let line = doc.text_pos_at(node.range().start).row as usize;
        let found = match node.tag_name().name() {
            "polygon" | "polyline" => {
                let pts = parse_point_attr(name, line, node.attribute("points").unwrap_or(""))?;
                Some((pts, node.tag_name().name() == "polygon"))
            }
            "path" => Some(parse_path(name, line, node.attribute("d").unwrap_or(""))?),
            _ => None,
        };
        if let Some((pts, closed)) = found {
            if pts.len() >= 2 && best.as_ref().is_none_or(|(b, _)| pts.len() > b.len()) {
                best = Some((pts, closed));
            }
        }
    }
    let Some((mut points, mut closed)) = best else {
        return Err(err(
            name,
            None,
            "the SVG has no usable polygon, polyline or path with at least two points",
        ));
    };
    if points.len() > 2 && points.first() == points.last() {
        points.pop();
        closed = true;
    }
    for p in &mut points {
        p.y = -p.y;
    }
    Ok(Contour {
        points,
        closed,
        source: format!("the largest shape in {name}"),
    })
}

fn numbers(name: &str, line: usize, s: &str) -> Result<Vec<f64>, InputError> {
    // Numbers separated by commas or spaces; a sign may also separate them.
    let mut out = Vec::new();
    let mut cur = String::new();
    let flush = |cur: &mut String, out: &mut Vec<f64>| -> Result<(), InputError> {
        if !cur.is_empty() {
            let v: f64 = cur
                .parse()
                .map_err(|_| err(name, Some(line), format!("`{cur}` is not a number")))?;
            if !v.is_finite() {
                return Err(err(
                    name,
                    Some(line),
                    format!("`{cur}` is not a finite number"),
                ));
            }
            out.push(v);
            cur.clear();
        }
        Ok(())
    };
    for c in s.chars() {
        if c == ',' || c.is_whitespace() {
            flush(&mut cur, &mut out)?;
        } else if (c == '-' || c == '+') && !cur.is_empty() && !cur.ends_with(['e', 'E']) {
            flush(&mut cur, &mut out)?;
            cur.push(c);
        } else {
            cur.push(c);
        }
    }
    flush(&mut cur, &mut out)?;
    Ok(out)
}

fn parse_point_attr(name: &str, line: usize, s: &str) -> Result<Vec<DVec2>, InputError> {
    let v = numbers(name, line, s)?;
    if v.len() % 2 != 0 {
        return Err(err(
            name,
            Some(line),
            "the `points` attribute has an odd number of coordinates",
        ));
    }
    Ok(v.chunks(2).map(|c| DVec2::new(c[0], c[1])).collect())
}

/// A path of straight segments: M m L l H h V v Z z (implicit repeats too).
fn parse_path(name: &str, line: usize, d: &str) -> Result<(Vec<DVec2>, bool), InputError> {
    let mut pts = Vec::new();
    let mut closed = false;
    let mut cur = DVec2::ZERO;
    let mut start = DVec2::ZERO;
    // Split into (command, numbers) groups.
    let mut groups: Vec<(char, String)> = Vec::new();
    for c in d.chars() {
        if c.is_ascii_alphabetic() && c != 'e' && c != 'E' {
            groups.push((c, String::new()));
        } else if let Some(g) = groups.last_mut() {
            g.1.push(c);
        } else if !c.is_whitespace() {
            return Err(err(
                name,
                Some(line),
                "a path must start with a command such as M",
            ));
        }
    }
    for (cmd, args) in groups {
        let v = numbers(name, line, &args)?;
        let rel = cmd.is_ascii_lowercase();
        let base = |cur: DVec2| if rel { cur } else { DVec2::ZERO };
        match cmd.to_ascii_uppercase() {
            'M' | 'L' => {
                if v.len() % 2 != 0 || v.is_empty() {
                    return Err(err(name, Some(line), format!("path command {cmd} needs pairs of numbers")));
                }
                for (k, c) in v.chunks(2).enumerate() {
                    cur = base(cur) + DVec2::new(c[0], c[1]);
                    if k == 0 && cmd.eq_ignore_ascii_case(&'M') {
                        if !pts.is_empty() {
                            // A second subpath: keep the longer one.
                            break;
                        }
                        start = cur;
                    }
                    pts.push(cur);
                }
            }
            'H' => {
                for x in v {
                    cur = DVec2::new(if rel { cur.x + x } else { x }, cur.y);
                    pts.push(cur);
                }
            }
            'V' => {
                for y in v {
                    cur = DVec2::new(cur.x, if rel { cur.y + y } else { y });
                    pts.push(cur);
                }
            }
            'Z' => {
                closed = true;
                cur = start;
            }
            other => {
                return Err(err(
                    name,
                    Some(line),
                    format!("path command `{other}` (a curve) is not supported: flatten curves to line segments first"),
                ))
            }
        }
    }
    Ok((pts, closed))
}

/// Traces the largest closed outline of the dark shape in a PNG image, with
/// sub-pixel marching squares at mid-grey. Transparent pixels count as white.
pub fn read_png(name: &str, bytes: &[u8]) -> Result<Contour, InputError> {
    let pm = tiny_skia::Pixmap::decode_png(bytes)
        .map_err(|e| err(name, None, format!("cannot read the PNG image: {e}")))?;
    let (w, h) = (pm.width() as usize, pm.height() as usize);
    let field: Vec<f64> = pm
        .pixels()
        .iter()
        .map(|p| {
            // Premultiplied colour over white, then luminance in 0..1.
            let c = p.demultiply();
            let a = c.alpha() as f64 / 255.0;
            let lum =
                (0.2126 * c.red() as f64 + 0.7152 * c.green() as f64 + 0.0722 * c.blue() as f64)
                    / 255.0;
            a * lum + (1.0 - a)
        })
        .collect();
    let loops = trace::contours(&field, w, h, 0.5, 1.0);
    let Some(mut best) = loops.into_iter().max_by(|a, b| {
        trace::signed_area2(a)
            .abs()
            .total_cmp(&trace::signed_area2(b).abs())
    }) else {
        return Err(err(
            name,
            None,
            "the image has no dark shape to trace (nothing darker than mid-grey)",
        ));
    };
    // Image rows grow downwards; flip so that the outline stands upright.
    for p in &mut best {
        p.y = (h as f64 - 1.0) - p.y;
    }
    Ok(Contour {
        source: format!("traced from {name} ({} points)", best.len()),
        points: best,
        closed: true,
    })
}
