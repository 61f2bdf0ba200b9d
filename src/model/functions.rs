//! Functions drawn in vlab's function editor: a single function (`.func`),
//! a gallery of them (`.fset`), timelines (`.tset`), and the parameters of
//! a `.vset` file, which lpfg keeps in the same numbered list.
//!
//! A function's curve is the uniform cubic B-spline of its control points
//! with the end points interpolated (knots 0,0,0,0,1,…,n−2,n−2,n−2,n−2),
//! whose parameter d runs over \[0,1\]. As lpfg does, the curve is sampled
//! once: sample i holds y at x = i/(samples−1), the parameter of that x
//! found by bisection to within 0.01/samples, and a value between samples
//! is interpolated linearly. The arithmetic is lpfg's single precision.
//! The editor's `flip:` setting changes only how the editor shows the
//! function; lpfg reads and ignores it, and so does this reader.

use super::error::ModelError as Error;
use super::text::{count, no_more, number, words, Lines, MAX_POINTS};

/// The fewest and the most samples lpfg takes (it clamps `samples:`).
const MIN_SAMPLES: i64 = 10;
const MAX_SAMPLES: i64 = 1000;

/// One entry of the numbered list of functions.
#[derive(Clone, Debug, PartialEq)]
pub struct Function {
    pub name: String,
    /// The file it came from, for messages.
    pub file: String,
    pub kind: Kind,
    /// The interval that `tfunc` maps onto \[0,1\] (a timeline's start and
    /// end; \[0,1\] for other functions).
    pub low: f32,
    pub up: f32,
}

#[derive(Clone, Debug, PartialEq)]
pub enum Kind {
    /// A drawn function: its sampled values and tangents.
    Curve {
        values: Vec<f32>,
        tangents: Vec<[f32; 2]>,
    },
    /// A parameter of a `.vset` file, read with `val`.
    Parameter(f32),
}

impl Function {
    /// The value at `x`, clamped to \[0,1\] (`func`).
    pub fn value(&self, x: f32) -> Option<f32> {
        let Kind::Curve { values, .. } = &self.kind else {
            return None;
        };
        Some(interpolate(values, clamp01(x), |a, w1, b, w2| {
            w1 * a + w2 * b
        }))
    }

    /// The tangent at `x`, clamped to \[0,1\] after `x` is mapped from the
    /// function's interval (`funcTangent`).
    pub fn tangent(&self, x: f32) -> Option<[f32; 2]> {
        let Kind::Curve { tangents, .. } = &self.kind else {
            return None;
        };
        let v = clamp01((x - self.low) / (self.up - self.low));
        Some(interpolate(tangents, v, |a, w1, b, w2| {
            [w1 * a[0] + w2 * b[0], w1 * a[1] + w2 * b[1]]
        }))
    }

    /// The value at `x` of the function's interval (`tfunc`).
    pub fn timeline_value(&self, x: f32) -> Option<f32> {
        self.value((x - self.low) / (self.up - self.low))
    }
}

fn clamp01(x: f32) -> f32 {
    if x < 0.0 {
        0.0
    } else if x > 1.0 {
        1.0
    } else if x.is_nan() {
        0.0
    } else {
        x
    }
}

/// lpfg's look-up in a table of samples: linear between the two samples
/// around `v` (in \[0,1\]), the last sample at 1.
fn interpolate<T: Copy>(table: &[T], v: f32, mix: impl Fn(T, f32, T, f32) -> T) -> T {
    let last = table.len() - 1;
    let index = v * last as f32;
    let i = (index.floor() as usize).min(last);
    if i == last {
        return table[i];
    }
    let w1 = 1.0 - index + i as f32;
    let w2 = index - i as f32;
    mix(table[i], w1, table[i + 1], w2)
}

/// The knot `j` of the clamped uniform cubic B-spline over `n + 1` control
/// points: 0 four times, then 1, 2, …, and n − 2 four times.
fn knot(j: usize, n: usize) -> usize {
    if j < 4 {
        0
    } else if j > n {
        n - 2
    } else {
        j - 3
    }
}

/// The B-spline basis function N(k, t) at `u` (Cox–de Boor), in single
/// precision; a zero-length knot span contributes nothing.
fn basis(k: usize, t: usize, u: f32, n: usize) -> f32 {
    if t == 1 {
        return if knot(k, n) as f32 <= u && u < knot(k + 1, n) as f32 {
            1.0
        } else {
            0.0
        };
    }
    let mut sum = 0.0f32;
    let uk = knot(k, n);
    let div = knot(k + t - 1, n) - uk;
    if div != 0 {
        sum = (u - uk as f32) / div as f32 * basis(k, t - 1, u, n);
    }
    let ukt = knot(k + t, n);
    let div = ukt - knot(k + 1, n);
    if div != 0 {
        sum += (ukt as f32 - u) / div as f32 * basis(k + 1, t - 1, u, n);
    }
    sum
}

/// The curve's point at parameter `d` in \[0,1\].
pub(crate) fn point(pts: &[[f32; 2]], d: f32) -> [f32; 2] {
    let n = pts.len() - 1;
    let u = d * (n - 2) as f32;
    let mut s = [0.0f32; 2];
    for (k, p) in pts.iter().enumerate() {
        // Outside its knots a basis function is exactly 0: skipping it
        // changes no bit of the sum.
        if u < knot(k, n) as f32 || u >= knot(k + 4, n) as f32 {
            continue;
        }
        let b = basis(k, 4, u, n);
        s[0] += p[0] * b;
        s[1] += p[1] * b;
    }
    s
}

/// The curve's derivative at parameter `d`: each basis function's
/// derivative from the two of degree one lower (the coefficient 3/span is
/// computed in double precision, as lpfg's `3.` literal makes it).
fn tangent_at(pts: &[[f32; 2]], d: f32) -> [f32; 2] {
    let n = pts.len() - 1;
    let u = d * (n - 2) as f32;
    let mut s = [0.0f32; 2];
    for (k, p) in pts.iter().enumerate() {
        // The derivative's two terms lie within knots k to k + 4.
        if u < knot(k, n) as f32 || u >= knot(k + 4, n) as f32 {
            continue;
        }
        let mut prime = 0.0f32;
        let span = knot(k + 3, n) as i64 - knot(k, n) as i64;
        if span > 0 {
            prime = (prime as f64 + (3.0 / span as f64) * basis(k, 3, u, n) as f64) as f32;
        }
        let span = knot(k + 4, n) as i64 - knot(k + 1, n) as i64;
        if span > 0 {
            prime = (prime as f64 - (3.0 / span as f64) * basis(k + 1, 3, u, n) as f64) as f32;
        }
        s[0] += p[0] * prime;
        s[1] += p[1] * prime;
    }
    s
}

/// The parameter whose point has x = `x`, by bisection to within
/// `tolerance`; the control points' x rise from 0 to 1, so x rises with
/// the parameter and 64 halvings always suffice.
fn parameter_of(pts: &[[f32; 2]], x: f32, tolerance: f32) -> f32 {
    let (mut low, mut high) = (0.0f32, 1.0f32);
    let mut check = 0.5f32;
    for _ in 0..64 {
        check = (low + high) / 2.0;
        let px = point(pts, check)[0];
        if px > x {
            high = check;
        } else {
            low = check;
        }
        if (px - x).abs() <= tolerance {
            break;
        }
    }
    check
}

/// The sampled table of a function with control points `pts`.
pub(crate) fn sample(pts: &[[f32; 2]], samples: usize) -> Kind {
    let tolerance = 0.01f32 / samples as f32;
    let mut values = Vec::with_capacity(samples);
    let mut tangents = Vec::with_capacity(samples);
    for i in 0..samples {
        let d = parameter_of(pts, i as f32 / (samples - 1) as f32, tolerance);
        values.push(point(pts, d)[1]);
        tangents.push(tangent_at(pts, d));
    }
    Kind::Curve { values, tangents }
}

/// Reads one function in the editor's format (`fver 1 1`, `name:`,
/// `samples:`, optional `flip:` and background lines, `points:` and the
/// points, each `x y` or `x y multiplicity`).
fn read_function(lines: &mut Lines<'_>, file: &str, low: f32, up: f32) -> Result<Function, Error> {
    let ws = lines.keyed("fver")?;
    let major = count(lines, &ws, 0, "the major version", 0, 99)?;
    let minor = count(lines, &ws, 1, "the minor version", 0, 99)?;
    if (major, minor) != (1, 1) {
        return Err(lines.error(
            ws[0],
            format!("function format version {major} {minor} is not known: expected `fver 1 1`"),
        ));
    }
    let (name, at) = lines.keyed_text("name:")?;
    check_name(lines, name, at, "a function")?;
    let name = name.to_string();
    let ws = lines.keyed("samples:")?;
    let samples = count(lines, &ws, 0, "the number of samples", 1, i64::MAX)?;
    no_more(lines, &ws, 1, "the number of samples")?;
    let samples = samples.clamp(MIN_SAMPLES, MAX_SAMPLES) as usize;
    // Optional lines before `points:`: flip, background, its offset.
    while let Some(next) = lines.peek() {
        let first = words(next).first().map(|w| w.text.to_ascii_lowercase());
        match first.as_deref() {
            Some("flip:") | Some("background:") | Some("backgroundxy:") => {
                lines.next_line("`points:`")?;
            }
            _ => break,
        }
    }
    let ws = lines.keyed("points:")?;
    let n = count(lines, &ws, 0, "the number of points", 4, MAX_POINTS as i64)?;
    no_more(lines, &ws, 1, "the number of points")?;
    let mut pts: Vec<[f32; 2]> = Vec::new();
    let mut last_x = 0.0f32;
    for i in 0..n {
        let line = lines.next_line(&format!("point {} of {n} of function `{name}`", i + 1))?;
        let ws = words(line);
        let x = number(lines, &ws, 0, "the point's x")? as f32;
        let y = number(lines, &ws, 1, "the point's y")? as f32;
        let m = if ws.len() > 2 {
            count(lines, &ws, 2, "the point's multiplicity", 1, 3)?
        } else {
            1
        };
        no_more(lines, &ws, 3, "the point")?;
        let bad_x = if i == 0 && x != 0.0 {
            Some("the first point's x must be 0".to_string())
        } else if i == n - 1 && x != 1.0 {
            Some("the last point's x must be 1".to_string())
        } else if x < last_x {
            Some(format!(
                "the points' x must not decrease: {x} comes after {last_x}"
            ))
        } else {
            None
        };
        if let Some(m) = bad_x {
            return Err(lines.error(
                ws[0],
                format!("{m} (the function editor keeps x in [0,1], rising)"),
            ));
        }
        last_x = x;
        lines.spend(m as usize, "control points")?;
        for _ in 0..m {
            pts.push([x, y]);
        }
    }
    Ok(Function {
        kind: sample(&pts, samples),
        name,
        file: file.to_string(),
        low,
        up,
    })
}

/// A name that lpfg turns into a `#define`: a C identifier.
fn check_name(lines: &Lines<'_>, name: &str, at: usize, what: &str) -> Result<(), Error> {
    let ok = name
        .chars()
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
    if ok {
        Ok(())
    } else if name.is_empty() {
        Err(lines.error_at_end(format!("{what} needs a name here")))
    } else {
        Err(lines.error_at(
            at,
            at + name.len(),
            format!("`{name}` cannot name {what}: the program reads it as an identifier, so it must be letters, digits and `_`, not starting with a digit"),
        ))
    }
}

/// Reads a `.func` file: one function.
pub fn read_func(path: &str, text: &str) -> Result<Vec<Function>, Error> {
    let mut lines = Lines::new(path, text);
    let f = read_function(&mut lines, path, 0.0, 1.0)?;
    trailing(&mut lines)?;
    Ok(vec![f])
}

/// Reads the `items: n` line of a set.
fn items(lines: &mut Lines<'_>) -> Result<usize, Error> {
    let ws = lines.keyed("items:")?;
    let n = count(lines, &ws, 0, "the number of items", 0, 10_000)?;
    no_more(lines, &ws, 1, "the number of items")?;
    Ok(n as usize)
}

fn header(lines: &mut Lines<'_>, key: &str, version: (i64, i64)) -> Result<(), Error> {
    let ws = lines.keyed(key)?;
    let major = count(lines, &ws, 0, "the major version", 0, 99)?;
    let minor = count(lines, &ws, 1, "the minor version", 0, 99)?;
    if (major, minor) != version {
        return Err(lines.error(
            ws[0],
            format!(
                "version {major} {minor} is not known: expected `{key} {} {}`",
                version.0, version.1
            ),
        ));
    }
    Ok(())
}

fn trailing(lines: &mut Lines<'_>) -> Result<(), Error> {
    if lines.at_end() {
        return Ok(());
    }
    let line = lines.next_line("")?;
    let w = words(line)[0];
    Err(lines.error(w, format!("unexpected `{}` after the last item", w.text)))
}

/// Reads a `.fset` file (`funcgalleryver 1 1`, `items: n`, n functions).
pub fn read_fset(path: &str, text: &str) -> Result<Vec<Function>, Error> {
    let mut lines = Lines::new(path, text);
    header(&mut lines, "funcgalleryver", (1, 1))?;
    let n = items(&mut lines)?;
    let mut out = Vec::with_capacity(n);
    for _ in 0..n {
        out.push(read_function(&mut lines, path, 0.0, 1.0)?);
    }
    trailing(&mut lines)?;
    Ok(out)
}

/// Reads a `.tset` file (`timeEdit 1 2`, `items: n`, then per timeline
/// `start:`, `end:`, `name:`, optional `color:`, `startLabel:`,
/// `endLabel:`, the function between `timelineFunceditFileStart:` and
/// `timelineFunceditFileEnd:`).
pub fn read_tset(path: &str, text: &str) -> Result<Vec<Function>, Error> {
    let mut lines = Lines::new(path, text);
    header(&mut lines, "timeEdit", (1, 2))?;
    let n = items(&mut lines)?;
    let mut out = Vec::with_capacity(n);
    for _ in 0..n {
        let ws = lines.keyed("start:")?;
        let low = number(&lines, &ws, 0, "the timeline's start")? as f32;
        let ws = lines.keyed("end:")?;
        let up = number(&lines, &ws, 0, "the timeline's end")? as f32;
        if up == low {
            return Err(lines.error(
                ws[0],
                "the timeline's end equals its start: it has no length",
            ));
        }
        lines.keyed_text("name:")?;
        // color:, startLabel:, endLabel: in any order, each optional.
        loop {
            let line = lines.next_line("`timelineFunceditFileStart:`")?;
            let w = words(line)[0];
            match w.text.to_ascii_lowercase().as_str() {
                "color:" | "startlabel:" | "endlabel:" => continue,
                "timelinefunceditfilestart:" => break,
                _ => {
                    return Err(lines.error(
                        w,
                        format!("expected `timelineFunceditFileStart:`, found `{}`", w.text),
                    ))
                }
            }
        }
        out.push(read_function(&mut lines, path, low, up)?);
        lines.keyed("timelineFunceditFileEnd:")?;
    }
    trailing(&mut lines)?;
    Ok(out)
}

/// Reads a `.vset` file: `#define NAME value` lines (blank lines allowed).
pub fn read_vset(path: &str, text: &str) -> Result<Vec<Function>, Error> {
    let mut lines = Lines::new(path, text);
    let mut out = Vec::new();
    while !lines.at_end() {
        let line = lines.next_line("a `#define`")?;
        let ws = words(line);
        if ws[0].text != "#define" {
            return Err(lines.error(
                ws[0],
                format!("expected `#define NAME value`, found `{}`", ws[0].text),
            ));
        }
        let Some(name) = ws.get(1) else {
            return Err(lines.error_at_end("expected the parameter's name after `#define`"));
        };
        check_name(&lines, name.text, name.start, "a parameter")?;
        let v = number(&lines, &ws, 2, "the parameter's value")? as f32;
        no_more(&lines, &ws, 3, "the parameter's value")?;
        lines.spend(1, "parameters")?;
        out.push(Function {
            name: name.text.to_string(),
            file: path.to_string(),
            kind: Kind::Parameter(v),
            low: 0.0,
            up: 1.0,
        });
    }
    Ok(out)
}
