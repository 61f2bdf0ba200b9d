//! Contours drawn in vlab's contour editor (cuspy): one per `.con` file,
//! or a gallery of them in a `.cset` file.
//!
//! A contour of type `or`/`cr` (regular, open or closed) is the uniform
//! cubic B-spline of its control points, each repeated as many times as
//! its multiplicity says; a closed one starts with copies of its last three
//! points, so that it closes smoothly. As lpfg does, each span of the
//! spline is sampled at 1000 parameter steps, the polyline is measured,
//! and `samples` points (8 when the file does not say) are placed along it
//! at equal arc length; `curveX` and its kin interpolate linearly between
//! those. Types `oe`/`ce` (end points interpolated, an older format) use
//! the clamped B-spline at equal parameter steps instead. The normal at a
//! sample is the unit tangent turned a quarter to the left (z × t).

use super::error::ModelError as Error;
use super::text::{count, no_more, number, words, Lines, MAX_POINTS};

/// lpfg's default number of samples, and its bounds.
const DEFAULT_SAMPLES: usize = 8;
const MIN_SAMPLES: i64 = 3;
const MAX_SAMPLES: i64 = 10_000;

/// Parameter steps per spline span when a contour is measured.
const STEPS_PER_SPAN: usize = 1000;

/// A contour ready for look-ups: its samples at equal arc length.
#[derive(Clone, Debug, PartialEq)]
pub struct Contour {
    pub name: String,
    pub file: String,
    pub closed: bool,
    /// Control points with multiplicities expanded (and, for a closed
    /// regular contour, its last three points first).
    pub controls: Vec<[f32; 3]>,
    /// The control points as the file gives them, for `curveReset`.
    pub original: Vec<[f32; 3]>,
    pub end_points: bool,
    pub samples: usize,
    /// The file gives `samples:` (format 1 3); otherwise lpfg samples a
    /// generalized cylinder's contour at its `contour sides`.
    pub samples_given: bool,
    pub vertices: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
}

type V3 = [f32; 3];

fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn scale(a: V3, s: f32) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}
fn distance(a: V3, b: V3) -> f32 {
    let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
}
fn lerp(a: V3, b: V3, r: f32) -> V3 {
    add(scale(a, 1.0 - r), scale(b, r))
}

impl Contour {
    /// lpfg's default contour, number 0: a circle of radius 1 through
    /// (0,1), sampled at `samples` points (the last one the first again).
    pub fn default_circle() -> Contour {
        let n = DEFAULT_SAMPLES;
        let mut vertices = vec![[0.0f32; 3]; n];
        let step = std::f32::consts::PI / (0.5 * (n - 1) as f32);
        for (i, v) in vertices.iter_mut().enumerate().take(n - 1) {
            *v = [(step * i as f32).sin(), (step * i as f32).cos(), 0.0];
        }
        vertices[n - 1] = vertices[0];
        Contour {
            name: "def_contour".into(),
            file: String::new(),
            closed: true,
            controls: Vec::new(),
            original: Vec::new(),
            end_points: false,
            samples: n,
            samples_given: false,
            normals: vertices.clone(),
            vertices,
        }
    }

    /// The point at normalised arc length `s` (clamped to \[0,1\]).
    pub fn point(&self, s: f32) -> V3 {
        let s = if s.is_nan() { 0.0 } else { s.clamp(0.0, 1.0) };
        let last = self.vertices.len() - 1;
        let at = s as f64 * last as f64;
        let i = (at as usize).min(last);
        let w = (at - i as f64) as f32;
        if i < last {
            lerp(self.vertices[i], self.vertices[i + 1], w)
        } else {
            self.vertices[i]
        }
    }

    /// The normal at normalised arc length `s` (clamped to \[0,1\]).
    pub fn normal(&self, s: f32) -> V3 {
        let s = if s.is_nan() { 0.0 } else { s.clamp(0.0, 1.0) };
        let last = self.normals.len() - 1;
        let at = s * last as f32;
        let i = (at as usize).min(last);
        let w = at - i as f32;
        if i < last {
            lerp(self.normals[i], self.normals[i + 1], w)
        } else {
            self.normals[i]
        }
    }

    /// `curveScale`: scales the control points and recomputes the samples.
    pub fn scale(&mut self, s: [f32; 3]) {
        for p in &mut self.controls {
            *p = [p[0] * s[0], p[1] * s[1], p[2] * s[2]];
        }
        self.calculate();
    }

    /// `curveSetPoint`: moves control point `i` (counted in the expanded
    /// list: multiplicities repeated, and a closed contour's three leading
    /// copies first); the samples stay until [`Contour::recalculate`].
    pub fn set_point(&mut self, i: usize, p: [f32; 3]) -> bool {
        match self.controls.get_mut(i) {
            Some(slot) => {
                *slot = p;
                true
            }
            None => false,
        }
    }

    /// `curveRecalculate`: the samples from the current control points.
    pub fn recalculate(&mut self) {
        self.calculate();
    }

    /// The contour sampled at `samples` points (at least 2) instead; the
    /// default circle stays a circle.
    pub fn resampled(&self, samples: usize) -> Contour {
        let samples = samples.max(2);
        let mut c = self.clone();
        c.samples = samples;
        if self.controls.is_empty() {
            // The default circle: `samples` points, the last the first.
            let step = std::f32::consts::PI / (0.5 * (samples - 1) as f32);
            c.vertices = (0..samples)
                .map(|i| {
                    let a = step * (i % (samples - 1)) as f32;
                    [a.sin(), a.cos(), 0.0]
                })
                .collect();
            c.normals = c.vertices.clone();
        } else {
            c.calculate();
        }
        c
    }

    /// `curveReset`: the file's control points back; as in lpfg, the
    /// samples stay until [`Contour::recalculate`].
    pub fn reset(&mut self) {
        self.controls = self.original.clone();
    }

    /// Computes the samples from the control points.
    fn calculate(&mut self) {
        if self.end_points {
            let n = self.samples;
            let pts = &self.controls;
            let mut v = vec![pts[0]; n];
            for (i, slot) in v.iter_mut().enumerate().take(n - 1).skip(1) {
                *slot = clamped_point(pts, i as f32 / (n - 1) as f32);
            }
            v[n - 1] = *pts.last().expect("at least four points");
            self.vertices = v;
            self.normals = vec![[0.0; 3]; n];
            return;
        }
        let (mut curve, mut normals) = (Vec::new(), Vec::new());
        for w in self.controls.windows(4) {
            for i in 0..STEPS_PER_SPAN {
                let t = i as f32 / STEPS_PER_SPAN as f32;
                let (p, n) = span_point(w, t);
                curve.push(p);
                normals.push(n);
            }
        }
        if self.closed {
            curve.push(curve[0]);
            normals.push(normals[0]);
        }
        let (v, n) = by_arc_length(&curve, &normals, self.samples);
        self.vertices = v;
        self.normals = n;
        fill_zero_normals(&mut self.normals);
    }
}

/// The point and normal of the uniform cubic B-spline span of `w` (four
/// control points) at `t` in [0,1).
fn span_point(w: &[V3], t: f32) -> (V3, V3) {
    let (t2, t3) = (t * t, t * t * t);
    // The uniform cubic B-spline basis, and its derivative.
    let b = [
        (-t3 + 3.0 * t2 - 3.0 * t + 1.0) / 6.0,
        (3.0 * t3 - 6.0 * t2 + 4.0) / 6.0,
        (-3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0) / 6.0,
        t3 / 6.0,
    ];
    let d = [
        (-3.0 * t2 + 6.0 * t - 3.0) / 6.0,
        (9.0 * t2 - 12.0 * t) / 6.0,
        (-9.0 * t2 + 6.0 * t + 3.0) / 6.0,
        3.0 * t2 / 6.0,
    ];
    let mut p = [0.0f32; 3];
    let mut tan = [0.0f32; 3];
    for k in 0..4 {
        p = add(p, scale(w[k], b[k]));
        tan = add(tan, scale(w[k], d[k]));
    }
    let len = (tan[0] * tan[0] + tan[1] * tan[1] + tan[2] * tan[2]).sqrt();
    let normal = if len < 1e-4 {
        [0.0; 3]
    } else {
        let u = scale(tan, 1.0 / len);
        // (0,0,1) × u
        [-u[1], u[0], 0.0]
    };
    (p, normal)
}

/// `n` points of the polyline `pts` at equal arc length, the first and
/// the last at its ends, and the normals interpolated alike.
fn by_arc_length(pts: &[V3], nrm: &[V3], n: usize) -> (Vec<V3>, Vec<V3>) {
    let mut total: f32 = pts.windows(2).map(|w| distance(w[0], w[1])).sum();
    if total < 1e-4 {
        total = 1e-4;
    }
    let mut at = vec![0.0f32; pts.len()];
    for i in 1..pts.len() - 1 {
        at[i] = at[i - 1] + distance(pts[i - 1], pts[i]) / total;
    }
    let last = pts.len() - 1;
    at[last] = 1.0;
    let mut v = vec![pts[0]; n];
    let mut m = vec![nrm[0]; n];
    let divisions = n - 1;
    let mut j = 1;
    for i in 1..divisions {
        let t = i as f32 / divisions as f32;
        // The first sample at or past t, and the one before it.
        while j < last && at[j] < t {
            j += 1;
        }
        let k = j - 1;
        let span = at[k + 1] - at[k];
        let r = if span > 0.0 { (t - at[k]) / span } else { 0.0 };
        v[i] = lerp(pts[k], pts[k + 1], r);
        m[i] = lerp(nrm[k], nrm[k + 1], r);
    }
    v[divisions] = pts[last];
    m[divisions] = nrm[last];
    (v, m)
}

/// A zero normal takes the previous one (the first takes the first
/// non-zero one), as lpfg does for cusps.
fn fill_zero_normals(n: &mut [V3]) {
    let null = |v: &V3| v.iter().all(|c| *c == 0.0);
    if null(&n[0]) {
        if let Some(first) = n.iter().find(|v| !null(v)).copied() {
            n[0] = first;
        }
    }
    for i in 1..n.len() {
        if null(&n[i]) {
            n[i] = n[i - 1];
        }
    }
}

/// The clamped cubic B-spline (end points interpolated) of `pts` at `d`.
fn clamped_point(pts: &[V3], d: f32) -> V3 {
    let xy: Vec<[f32; 2]> = pts.iter().map(|p| [p[0], p[1]]).collect();
    let z: Vec<[f32; 2]> = pts.iter().map(|p| [p[2], 0.0]).collect();
    let a = super::functions::point(&xy, d);
    let b = super::functions::point(&z, d);
    [a[0], a[1], b[0]]
}

/// Reads one contour (`cver 1 1`, `1 2` or `1 3`).
fn read_contour(lines: &mut Lines<'_>, file: &str) -> Result<Contour, Error> {
    let ws = lines.keyed("cver")?;
    let major = count(lines, &ws, 0, "the major version", 0, 99)?;
    let minor = count(lines, &ws, 1, "the minor version", 0, 99)?;
    if major != 1 || !(1..=3).contains(&minor) {
        return Err(lines.error(
            ws[0],
            format!("contour format version {major} {minor} is not known: expected `cver 1 1`, `1 2` or `1 3`"),
        ));
    }
    let (name, _) = lines.keyed_text("name:")?;
    let name = name.split_whitespace().next().unwrap_or("").to_string();
    if name.is_empty() {
        return Err(lines.error_at_end("a contour needs a name here"));
    }
    let ws = lines.keyed("points:")?;
    let n1 = count(
        lines,
        &ws,
        0,
        "the number of distinct points",
        1,
        MAX_POINTS as i64,
    )?;
    let n2 = count(
        lines,
        &ws,
        1,
        "the number of points with multiplicities",
        4,
        MAX_POINTS as i64,
    )?;
    no_more(lines, &ws, 2, "the numbers of points")?;
    // Then the type, `samples:` (1 3), optional background and marker
    // lines, and the points (lpfg's order, which cuspy writes).
    let ws = lines.keyed("type:")?;
    let kind = ws.first().map(|w| w.text);
    let (closed, end_points) = match (minor, kind) {
        (1, Some("open")) => (false, false),
        (1, Some("closed")) => (true, false),
        (2..=3, Some("or")) => (false, false),
        (2..=3, Some("cr")) => (true, false),
        (2..=3, Some("oe")) => (false, true),
        (2..=3, Some("ce")) => (true, true),
        _ => {
            let expected = if minor == 1 {
                "`open` or `closed`"
            } else {
                "a contour type `or`, `cr`, `oe` or `ce`"
            };
            return Err(match ws.first() {
                Some(w) => lines.error(*w, format!("expected {expected}, found `{}`", w.text)),
                None => lines.error_at_end(format!("expected {expected}")),
            });
        }
    };
    no_more(lines, &ws, 1, "the type")?;
    let samples = if minor == 3 {
        let ws = lines.keyed("samples:")?;
        let s = count(lines, &ws, 0, "the number of samples", 1, i64::MAX)?;
        no_more(lines, &ws, 1, "the number of samples")?;
        s.clamp(MIN_SAMPLES, MAX_SAMPLES) as usize
    } else {
        DEFAULT_SAMPLES
    };
    skip_optional(lines, &["background:", "backgroundxy:"])?;
    if lines
        .peek()
        .is_some_and(|l| l.trim_start().starts_with("markers:"))
    {
        let ws = lines.keyed("markers:")?;
        let m = count(lines, &ws, 0, "the number of markers", 0, MAX_POINTS as i64)?;
        for _ in 0..m {
            lines.next_line("a marker")?;
        }
    }
    let pts = read_points(lines, n1, n2, &name)?;
    let mut controls = pts;
    if closed {
        if end_points {
            controls.push(controls[0]);
        } else {
            let n = controls.len();
            let tail: Vec<V3> = controls[n - 3..].to_vec();
            controls.splice(0..0, tail);
        }
    }
    let mut c = Contour {
        name,
        file: file.to_string(),
        closed,
        original: controls.clone(),
        controls,
        end_points,
        samples,
        samples_given: minor == 3,
        vertices: Vec::new(),
        normals: Vec::new(),
    };
    c.calculate();
    Ok(c)
}

fn skip_optional(lines: &mut Lines<'_>, keys: &[&str]) -> Result<(), Error> {
    while let Some(next) = lines.peek() {
        let first = words(next)[0].text.to_ascii_lowercase();
        if keys.contains(&first.as_str()) {
            lines.next_line("")?;
        } else {
            break;
        }
    }
    Ok(())
}

/// Reads `n1` lines `x y z multiplicity` whose multiplicities add up to `n2`.
fn read_points(lines: &mut Lines<'_>, n1: i64, n2: i64, name: &str) -> Result<Vec<V3>, Error> {
    let mut pts = Vec::new();
    for i in 0..n1 {
        let line = lines.next_line(&format!("point {} of {n1} of contour `{name}`", i + 1))?;
        let ws = words(line);
        let x = number(lines, &ws, 0, "the point's x")? as f32;
        let y = number(lines, &ws, 1, "the point's y")? as f32;
        let z = number(lines, &ws, 2, "the point's z")? as f32;
        let m = count(lines, &ws, 3, "the point's multiplicity", 1, 3)?;
        no_more(lines, &ws, 4, "the point's multiplicity")?;
        lines.spend(m as usize, "control points")?;
        for _ in 0..m {
            pts.push([x, y, z]);
        }
        if pts.len() as i64 > n2 {
            return Err(lines.error(
                ws[3],
                format!("the multiplicities add up to more than the {n2} points that `points:` announces"),
            ));
        }
    }
    if (pts.len() as i64) < n2 {
        return Err(lines.error_at_end(format!(
            "the multiplicities add up to {}, but `points:` announces {n2}",
            pts.len()
        )));
    }
    Ok(pts)
}

/// Reads a `.con` file: one contour.
pub fn read_con(path: &str, text: &str) -> Result<Vec<Contour>, Error> {
    let mut lines = Lines::new(path, text);
    let c = read_contour(&mut lines, path)?;
    Ok(vec![c])
}

/// Reads a `.cset` file (`contourgalleryver 1 1`, `items: n`, n contours).
pub fn read_cset(path: &str, text: &str) -> Result<Vec<Contour>, Error> {
    let mut lines = Lines::new(path, text);
    let ws = lines.keyed("contourgalleryver")?;
    let major = count(&lines, &ws, 0, "the major version", 0, 99)?;
    let minor = count(&lines, &ws, 1, "the minor version", 0, 99)?;
    if (major, minor) != (1, 1) {
        return Err(lines.error(ws[0], "expected `contourgalleryver 1 1`"));
    }
    let ws = lines.keyed("items:")?;
    let n = count(&lines, &ws, 0, "the number of items", 1, 10_000)?;
    let mut out = Vec::new();
    for _ in 0..n {
        out.push(read_contour(&mut lines, path)?);
    }
    Ok(out)
}
