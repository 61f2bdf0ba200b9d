//! Reading contours: point lists (CSV or whitespace `x y`, header allowed),
//! SVG (`polygon`, `polyline`, `path` with M/L/H/V/Z), and PNG silhouettes.
//!
//! Every file is read once, and at most [`MAX_INPUT_BYTES`] of it (unless
//! the caller raises the limit), so a huge file or a device such as
//! `/dev/zero` is refused before it fills memory. Errors in text files are
//! located: `file:line:col: error: message`, the line and a caret.

use std::io::Read;
use std::ops::Range;
use std::path::Path;

use glam::DVec2;

use super::trace;
use crate::error::Error;

/// The default size limit of the files `reverse` and `reconstruct` read
/// (contours, SVG and PNG files, details files): 64 MiB, room for a contour
/// of about 1.5 million points. The binary raises it with
/// `--max-input-size`.
pub const MAX_INPUT_BYTES: u64 = 64 << 20;

/// The largest PNG silhouette traced, in pixels (8192 × 8192): tracing
/// needs the image's bytes (one a pixel for a grey image, up to four for
/// colour with alpha) and about 1.3 bytes a pixel more.
pub const MAX_IMAGE_PIXELS: u64 = 8192 * 8192;

/// The option of the binary that raises [`MAX_INPUT_BYTES`], for messages.
pub const RAISE_INPUT_LIMIT: &str = "--max-input-size";

/// What the readers return when a file is refused: a [`crate::Error`],
/// located (`file:line:col`, the line and a caret) where the file has lines.
pub type InputError = Error;

/// A contour: its points, whether it is closed, and where it came from.
#[derive(Clone, Debug, PartialEq)]
pub struct Contour {
    pub points: Vec<DVec2>,
    pub closed: bool,
    /// A description for reports, e.g. "traced from horse.png".
    pub source: String,
}

/// `n` bytes for a person: "64 MiB", "1.5 GiB", "300 bytes".
pub fn human_bytes(n: u64) -> String {
    const UNITS: [&str; 4] = ["KiB", "MiB", "GiB", "TiB"];
    if n < 1024 {
        return format!("{n} bytes");
    }
    let mut v = n as f64 / 1024.0;
    let mut u = 0;
    while v >= 1024.0 && u + 1 < UNITS.len() {
        v /= 1024.0;
        u += 1;
    }
    if v.fract() == 0.0 {
        format!("{v} {}", UNITS[u])
    } else {
        format!("{v:.1} {}", UNITS[u])
    }
}

/// The whole of the file at `path`, refused when it holds more than
/// `max_bytes`: the size is checked before reading where the file system
/// knows it, and the read stops one byte past the limit where it does not
/// (pipes, devices).
pub fn read_bounded(path: &Path, max_bytes: u64) -> Result<Vec<u8>, Error> {
    let name = path.display().to_string();
    let cannot = |e: std::io::Error| Error::file(&name, format!("cannot read the file: {e}"));
    let too_big = |size: Option<u64>| {
        let what = match size {
            Some(s) => format!("is {}", human_bytes(s)),
            None => "holds more than that".to_string(),
        };
        Error::file(
            &name,
            format!(
                "the file is larger than the input size limit of {} ({max_bytes} bytes): it {what}; \
                 raise the limit with {RAISE_INPUT_LIMIT} (e.g. {RAISE_INPUT_LIMIT} {})",
                human_bytes(max_bytes),
                suggestion(size.unwrap_or(max_bytes.saturating_mul(4)))
            ),
        )
    };
    if path.is_dir() {
        return Err(Error::file(&name, "this is a folder, not a file"));
    }
    let file = crate::files::open(path).map_err(cannot)?;
    if let Some(len) = file.size().filter(|&len| len > max_bytes) {
        return Err(too_big(Some(len)));
    }
    let mut bytes = Vec::new();
    file.take(max_bytes.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(cannot)?;
    if bytes.len() as u64 > max_bytes {
        return Err(too_big(None));
    }
    Ok(bytes)
}

/// A limit that holds `size`, as `--max-input-size` takes it: "256M".
fn suggestion(size: u64) -> String {
    let mib = size.div_ceil(1 << 20).next_power_of_two().max(1);
    if mib >= 1024 && mib.is_multiple_of(1024) {
        format!("{}G", mib / 1024)
    } else {
        format!("{mib}M")
    }
}

/// The bytes as UTF-8 text; invalid UTF-8 is an error at its line and
/// column. A leading byte-order mark is left in the text.
pub fn utf8_text(name: &str, bytes: Vec<u8>, what: &str) -> Result<String, Error> {
    String::from_utf8(bytes).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        let bad = e.as_bytes()[at];
        let shown = String::from_utf8_lossy(e.as_bytes());
        // The lossy text has the same prefix; U+FFFD takes three bytes.
        Error::in_text(
            name,
            &shown,
            at..at + 3,
            format!("{what} must be UTF-8 text, but byte 0x{bad:02X} here is not UTF-8"),
        )
    })
}

/// Reads a contour with the default size limit; see [`read_with_limit`].
pub fn read(path: &Path) -> Result<Contour, Error> {
    read_with_limit(path, MAX_INPUT_BYTES)
}

/// Reads a contour with a PNG silhouette read the default way; see
/// [`read_with`].
pub fn read_with_limit(path: &Path, max_bytes: u64) -> Result<Contour, Error> {
    read_with(path, max_bytes, &Silhouette::default())
}

/// Reads a contour; the format follows the file's extension (`.svg`,
/// `.png`, anything else is a point list). Point lists are closed. A file
/// larger than `max_bytes` is refused before it is read whole; a PNG
/// image is traced as `silhouette` says.
pub fn read_with(path: &Path, max_bytes: u64, silhouette: &Silhouette) -> Result<Contour, Error> {
    let name = path.display().to_string();
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let bytes = read_bounded(path, max_bytes)?;
    let c = match ext.as_str() {
        "png" => read_png_with(&name, &bytes, silhouette)?,
        "svg" => read_svg(&name, &utf8_text(&name, bytes, "an SVG file")?)?,
        _ => read_points(&name, &utf8_text(&name, bytes, "a point list")?)?,
    };
    if c.points.len() < 3 {
        return Err(Error::file(
            &name,
            format!(
                "the contour has {} point(s); at least 3 are needed",
                c.points.len()
            ),
        ));
    }
    Ok(c)
}

/// The fields of a line: runs of characters between commas, semicolons and
/// white space, with their byte ranges in the line.
fn fields(line: &str) -> Vec<(Range<usize>, &str)> {
    let sep = |c: char| c == ',' || c == ';' || c.is_whitespace() || c == '\u{feff}';
    let mut out = Vec::new();
    let mut start = None;
    for (i, c) in line.char_indices() {
        match (sep(c), start) {
            (true, Some(s)) => {
                out.push((s..i, &line[s..i]));
                start = None;
            }
            (false, None) => start = Some(i),
            _ => {}
        }
    }
    if let Some(s) = start {
        out.push((s..line.len(), &line[s..]));
    }
    out
}

/// `x y` per line, separated by commas, semicolons or whitespace. A first
/// line that is not numbers is a header; `#` and `//` start comments. A
/// line holds one point: anything after its two numbers is an error.
pub fn read_points(name: &str, text: &str) -> Result<Contour, Error> {
    let mut points = Vec::new();
    let mut header_seen = false;
    let mut offset = 0;
    for raw in text.split_inclusive('\n') {
        let line_start = offset;
        offset += raw.len();
        // The line without its comment.
        let cut = [raw.find("//"), raw.find('#')]
            .into_iter()
            .flatten()
            .min()
            .unwrap_or(raw.len());
        let fs = fields(&raw[..cut]);
        if fs.is_empty() {
            continue;
        }
        let at = |r: &Range<usize>| line_start + r.start..line_start + r.end;
        let nums: Vec<Option<f64>> = fs.iter().map(|(_, f)| f.parse::<f64>().ok()).collect();
        if points.is_empty() && !header_seen && nums.iter().all(Option::is_none) {
            header_seen = true;
            continue; // a header such as `x,y`
        }
        if let Some(k) = nums.iter().take(2).position(Option::is_none) {
            let (r, f) = &fs[k];
            return Err(Error::in_text(
                name,
                text,
                at(r),
                format!("expected two numbers `x y`, but `{f}` is not a number"),
            ));
        }
        if fs.len() < 2 {
            let (r, f) = &fs[0];
            return Err(Error::in_text(
                name,
                text,
                at(r),
                format!("expected two numbers `x y`, found only `{f}`"),
            ));
        }
        if fs.len() > 2 {
            let (r, f) = &fs[2];
            return Err(Error::in_text(
                name,
                text,
                at(r),
                format!("`{f}` follows the two numbers `x y`: a line holds one point"),
            ));
        }
        let (x, y) = (nums[0].unwrap_or(0.0), nums[1].unwrap_or(0.0));
        if !x.is_finite() || !y.is_finite() {
            let k = if x.is_finite() { 1 } else { 0 };
            return Err(Error::in_text(
                name,
                text,
                at(&fs[k].0),
                format!("the point ({x}, {y}) is not finite"),
            ));
        }
        points.push(DVec2::new(x, y));
    }
    if points.is_empty() {
        return Err(Error::file(name, "the file has no points"));
    }
    Ok(Contour {
        points,
        closed: true,
        source: format!("points from {name}"),
    })
}

/// The byte offset of roxmltree's 1-based row and column (in characters).
fn offset_of(text: &str, row: u32, col: u32) -> usize {
    let line_start = if row <= 1 {
        0
    } else {
        text.match_indices('\n')
            .nth(row as usize - 2)
            .map_or(text.len(), |(i, _)| i + 1)
    };
    text[line_start..]
        .char_indices()
        .nth(col.saturating_sub(1) as usize)
        .map_or(text.len(), |(i, _)| line_start + i)
}

/// Where the characters of an attribute's value are in the document: its
/// value's own bytes when they are written without entities, else the
/// whole attribute.
struct Attr<'a> {
    value: &'a str,
    /// The document offset of `value[0]`, when the value is verbatim.
    verbatim: Option<usize>,
    whole: Range<usize>,
}

impl Attr<'_> {
    fn at(&self, r: Range<usize>) -> Range<usize> {
        match self.verbatim {
            Some(o) => o + r.start..o + r.end,
            None => self.whole.clone(),
        }
    }
}

/// The largest `polygon`, `polyline` or `path` of an SVG document. SVG's y
/// axis points down; it is flipped so that pictures stay upright.
pub fn read_svg(name: &str, text: &str) -> Result<Contour, Error> {
    let doc = roxmltree::Document::parse(text).map_err(|e| {
        let pos = e.pos();
        let at = offset_of(text, pos.row, pos.col);
        Error::in_text(
            name,
            text,
            at..at + 1,
            format!("not a valid SVG (XML) document: {e}"),
        )
    })?;
    let mut best: Option<(Vec<DVec2>, bool)> = None;
    for node in doc.descendants().filter(|n| n.is_element()) {
        let tag = node.tag_name().name();
        let key = match tag {
            "polygon" | "polyline" => "points",
            "path" => "d",
            _ => continue,
        };
        let Some(a) = node.attribute_node(key) else {
            continue;
        };
        let vr = a.range_value();
        let attr = Attr {
            value: a.value(),
            verbatim: (text.get(vr.clone()) == Some(a.value())).then_some(vr.start),
            whole: a.range(),
        };
        let found = if tag == "path" {
            parse_path(name, text, &attr)?
        } else {
            (parse_point_attr(name, text, &attr)?, tag == "polygon")
        };
        if found.0.len() >= 2 && best.as_ref().is_none_or(|(b, _)| found.0.len() > b.len()) {
            best = Some(found);
        }
    }
    let Some((mut points, mut closed)) = best else {
        return Err(Error::file(
            name,
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

/// The numbers of an attribute's value with their byte ranges in it:
/// separated by commas or spaces, or by a sign.
fn numbers(
    name: &str,
    text: &str,
    attr: &Attr,
    range: Range<usize>,
) -> Result<Vec<(f64, Range<usize>)>, Error> {
    let s = &attr.value[range.clone()];
    let mut out = Vec::new();
    let mut start: Option<usize> = None;
    let mut flush = |from: usize, to: usize| -> Result<(), Error> {
        let r = range.start + from..range.start + to;
        let word = &s[from..to];
        let v: f64 = word.parse().map_err(|_| {
            Error::in_text(
                name,
                text,
                attr.at(r.clone()),
                format!("`{word}` is not a number"),
            )
        })?;
        if !v.is_finite() {
            return Err(Error::in_text(
                name,
                text,
                attr.at(r),
                format!("`{word}` is not a finite number"),
            ));
        }
        out.push((v, r));
        Ok(())
    };
    for (i, c) in s.char_indices() {
        if c == ',' || c.is_whitespace() {
            if let Some(st) = start.take() {
                flush(st, i)?;
            }
        } else if (c == '-' || c == '+')
            && start.is_some_and(|st| st < i && !s[..i].ends_with(['e', 'E']))
        {
            flush(start.unwrap_or(i), i)?;
            start = Some(i);
        } else if start.is_none() {
            start = Some(i);
        }
    }
    if let Some(st) = start {
        flush(st, s.len())?;
    }
    Ok(out)
}

fn parse_point_attr(name: &str, text: &str, attr: &Attr) -> Result<Vec<DVec2>, Error> {
    let v = numbers(name, text, attr, 0..attr.value.len())?;
    if v.len() % 2 != 0 {
        let r = v.last().map_or(0..attr.value.len(), |(_, r)| r.clone());
        return Err(Error::in_text(
            name,
            text,
            attr.at(r),
            "the `points` attribute has an odd number of coordinates: this one has no partner",
        ));
    }
    Ok(v.chunks(2).map(|c| DVec2::new(c[0].0, c[1].0)).collect())
}

/// A path of straight segments: M m L l H h V v Z z (implicit repeats
/// too). Of several subpaths, the one with the most points is kept.
fn parse_path(name: &str, text: &str, attr: &Attr) -> Result<(Vec<DVec2>, bool), Error> {
    let d = attr.value;
    let fail = |r: Range<usize>, m: String| Error::in_text(name, text, attr.at(r), m);
    // Split into commands, each with the range of its numbers.
    let mut groups: Vec<(char, usize, Range<usize>)> = Vec::new();
    for (i, c) in d.char_indices() {
        if c.is_ascii_alphabetic() && c != 'e' && c != 'E' {
            if let Some(g) = groups.last_mut() {
                g.2.end = i;
            }
            groups.push((c, i, i + 1..d.len()));
        } else if groups.is_empty() && !c.is_whitespace() {
            return Err(fail(
                i..i + c.len_utf8(),
                "a path must start with a command such as M".into(),
            ));
        }
    }
    let mut best: (Vec<DVec2>, bool) = (Vec::new(), false);
    let mut pts: Vec<DVec2> = Vec::new();
    let mut closed = false;
    let mut cur = DVec2::ZERO;
    let mut start = DVec2::ZERO;
    let keep = |pts: &mut Vec<DVec2>, closed: &mut bool, best: &mut (Vec<DVec2>, bool)| {
        if pts.len() > best.0.len() {
            *best = (std::mem::take(pts), *closed);
        }
        pts.clear();
        *closed = false;
    };
    for (cmd, at, args) in groups {
        let v = numbers(name, text, attr, args.clone())?;
        let rel = cmd.is_ascii_lowercase();
        let here = at..at + 1;
        let upper = cmd.to_ascii_uppercase();
        if v.is_empty() && upper != 'Z' {
            return Err(fail(here, format!("path command {cmd} needs numbers")));
        }
        let finite = |next: DVec2, r: &Range<usize>| {
            if next.is_finite() {
                Ok(next)
            } else {
                Err(fail(
                    r.clone(),
                    format!(
                        "the path's point reaches ({}, {}): its coordinates overflow",
                        next.x, next.y
                    ),
                ))
            }
        };
        match upper {
            'M' | 'L' => {
                if v.len() % 2 != 0 {
                    let r = v[v.len() - 1].1.clone();
                    return Err(fail(
                        r,
                        format!("path command {cmd} needs pairs of numbers: this one has no partner"),
                    ));
                }
                for (k, c) in v.chunks(2).enumerate() {
                    let base = if rel { cur } else { DVec2::ZERO };
                    cur = finite(base + DVec2::new(c[0].0, c[1].0), &c[1].1)?;
                    if k == 0 && upper == 'M' {
                        // A new subpath.
                        keep(&mut pts, &mut closed, &mut best);
                        start = cur;
                    }
                    pts.push(cur);
                }
            }
            'H' => {
                for (x, r) in &v {
                    let nx = if rel { cur.x + x } else { *x };
                    cur = finite(DVec2::new(nx, cur.y), r)?;
                    pts.push(cur);
                }
            }
            'V' => {
                for (y, r) in &v {
                    let ny = if rel { cur.y + y } else { *y };
                    cur = finite(DVec2::new(cur.x, ny), r)?;
                    pts.push(cur);
                }
            }
            'Z' => {
                if let Some((_, r)) = v.first() {
                    return Err(fail(r.clone(), "path command Z takes no numbers".into()));
                }
                closed = true;
                cur = start;
            }
            other => {
                return Err(fail(
                    here,
                    format!("path command `{other}` (a curve) is not supported: flatten curves to line segments first"),
                ))
            }
        }
    }
    keep(&mut pts, &mut closed, &mut best);
    Ok(best)
}

/// Whether the light side of `field` (values at or above `t`) is the
/// shape: the side that does not touch the image's border, or, where both
/// or neither do, the side with fewer pixels.
fn light_is_the_shape(grey: &impl Fn(usize, usize) -> f64, w: usize, h: usize, t: f64) -> bool {
    let border = (0..w)
        .flat_map(|x| [(x, 0), (x, h - 1)])
        .chain((0..h).flat_map(|y| [(0, y), (w - 1, y)]));
    let (mut dark_edge, mut light_edge) = (false, false);
    for (x, y) in border {
        if grey(x, y) < t {
            dark_edge = true;
        } else {
            light_edge = true;
        }
    }
    match (dark_edge, light_edge) {
        (true, false) => true,
        (false, true) => false,
        _ => {
            let dark = (0..h)
                .flat_map(|y| (0..w).map(move |x| (x, y)))
                .filter(|&(x, y)| grey(x, y) < t)
                .count();
            dark > w * h - dark
        }
    }
}

/// Width and height from a PNG's header, when it has one.
fn png_size(bytes: &[u8]) -> Option<(u64, u64)> {
    if bytes.len() < 24 || &bytes[..8] != b"\x89PNG\r\n\x1a\n" || &bytes[12..16] != b"IHDR" {
        return None;
    }
    let be = |b: &[u8]| u32::from_be_bytes([b[0], b[1], b[2], b[3]]) as u64;
    Some((be(&bytes[16..20]), be(&bytes[20..24])))
}

/// Which side of a PNG image's threshold is the shape.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Side {
    /// The side that does not touch the image's border; where both or
    /// neither do, the one with fewer pixels.
    #[default]
    Auto,
    /// The pixels darker than the threshold (a dark shape on a light
    /// ground).
    Dark,
    /// The pixels as light as the threshold or lighter (`--invert`).
    Light,
}

/// How a PNG silhouette is read: the grey level (0 black … 1 white) that
/// separates shape from ground, and which side is the shape.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Silhouette {
    pub threshold: f64,
    pub side: Side,
}

impl Default for Silhouette {
    fn default() -> Self {
        Silhouette {
            threshold: 0.5,
            side: Side::Auto,
        }
    }
}

/// Traces a PNG silhouette the default way; see [`read_png_with`].
pub fn read_png(name: &str, bytes: &[u8]) -> Result<Contour, Error> {
    read_png_with(name, bytes, &Silhouette::default())
}

/// Traces the largest closed outline of the shape in a PNG image, with
/// sub-pixel marching squares at the threshold. Transparent pixels count as
/// white. The shape is the side `silhouette` names; the image's frame is
/// never returned as the outline: a shape that reaches all four edges is
/// refused with a message.
pub fn read_png_with(name: &str, bytes: &[u8], silhouette: &Silhouette) -> Result<Contour, Error> {
    let t = silhouette.threshold;
    if !(t > 0.0 && t < 1.0) {
        return Err(Error::file(
            name,
            format!("the threshold is {t}; it must lie strictly between 0 (black) and 1 (white)"),
        ));
    }
    if let Some((w, h)) = png_size(bytes) {
        if w * h > MAX_IMAGE_PIXELS {
            return Err(Error::file(
                name,
                format!(
                    "the image is {w}×{h} pixels, more than the {} million pixels a silhouette may have: scale it down",
                    MAX_IMAGE_PIXELS / 1_000_000
                ),
            ));
        }
    }
    let img = super::image::Image::decode(bytes)
        .map_err(|e| Error::file(name, format!("cannot read the PNG image: {e}")))?;
    let (w, h) = (img.w, img.h);
    // A pixel's colour over white, then its luminance in 0..1.
    let grey = |x: usize, y: usize| img.grey(x, y);
    let light = match silhouette.side {
        Side::Dark => false,
        Side::Light => true,
        Side::Auto => light_is_the_shape(&grey, w, h, t),
    };
    // The tracer follows the dark side (below the level, outside white):
    // a light shape is traced on the negative image.
    let level = if light { 1.0 - t } else { t };
    let value = |x: usize, y: usize| if light { 1.0 - grey(x, y) } else { grey(x, y) };
    let deadline = crate::deadline::current();
    let largest = trace::largest_contour(value, w, h, level, 1.0, deadline)
        .map_err(|m| Error::file(name, m))?;
    let Some(mut best) = largest else {
        let (shade, than) = if light {
            ("light", "as light as")
        } else {
            ("dark", "darker than")
        };
        return Err(Error::file(
            name,
            format!(
                "the image has no {shade} shape to trace (nothing {than} the threshold {t}; --threshold moves it)"
            ),
        ));
    };
    // The outline of a shape that fills the image runs along its frame.
    let (lo, hi) = best.iter().fold(
        (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    );
    if lo.x <= 0.0 && lo.y <= 0.0 && hi.x >= (w - 1) as f64 && hi.y >= (h - 1) as f64 {
        let other = if light { "dark" } else { "light" };
        return Err(Error::file(
            name,
            format!(
                "the {} shape reaches all four edges of the image, so its outline would be the image's frame; \
                 if the shape is the {other} side, say so (`--invert` for a light shape), or crop the image",
                if light { "light" } else { "dark" }
            ),
        ));
    }
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
