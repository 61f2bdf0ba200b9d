//! Details files read with every value's place: a small JSON reader that
//! keeps byte ranges, so that a wrong field, a shift out of range or a
//! detail that overflows is reported at its line and column, with a caret.

use std::ops::Range;
use std::path::Path;

use super::input::{read_bounded, utf8_text};
use super::{Details, LevelDetails, DETAILS_FORMAT};
use crate::error::Error;

/// JSON nesting deeper than this is refused (a details file needs 5).
const MAX_DEPTH: usize = 64;

/// A JSON value and the bytes it spans.
#[derive(Debug)]
struct Node {
    at: Range<usize>,
    value: Value,
}

#[derive(Debug)]
enum Value {
    Null,
    Bool(bool),
    /// The number's text; read as a float or a whole number on demand.
    Number,
    String(String),
    Array(Vec<Node>),
    /// Members with the ranges of their keys.
    Object(Vec<(String, Range<usize>, Node)>),
}

struct Reader<'a> {
    name: &'a str,
    text: &'a str,
    pos: usize,
    depth: usize,
}

impl Reader<'_> {
    fn error(&self, at: Range<usize>, message: impl Into<String>) -> Error {
        Error::in_text(self.name, self.text, at, message)
    }

    fn here(&self) -> Range<usize> {
        let len = self.text[self.pos..]
            .chars()
            .next()
            .map_or(0, char::len_utf8);
        self.pos..self.pos + len
    }

    fn peek(&self) -> Option<u8> {
        self.text.as_bytes().get(self.pos).copied()
    }

    fn skip_space(&mut self) {
        while matches!(self.peek(), Some(b' ' | b'\t' | b'\n' | b'\r')) {
            self.pos += 1;
        }
    }

    fn expected(&self, what: &str) -> Error {
        match self.text[self.pos..].chars().next() {
            Some(c) => self.error(self.here(), format!("expected {what}, found `{c}`")),
            None => self.error(
                self.pos..self.pos,
                format!("expected {what}, found the end of the file"),
            ),
        }
    }

    fn value(&mut self) -> Result<Node, Error> {
        self.skip_space();
        let start = self.pos;
        let value = match self.peek() {
            Some(b'{') => self.nested(|r| r.object())?,
            Some(b'[') => self.nested(|r| r.array())?,
            Some(b'"') => Value::String(self.string()?),
            Some(b'-' | b'0'..=b'9') => {
                self.number()?;
                Value::Number
            }
            Some(b't') if self.text[self.pos..].starts_with("true") => {
                self.pos += 4;
                Value::Bool(true)
            }
            Some(b'f') if self.text[self.pos..].starts_with("false") => {
                self.pos += 5;
                Value::Bool(false)
            }
            Some(b'n') if self.text[self.pos..].starts_with("null") => {
                self.pos += 4;
                Value::Null
            }
            _ => return Err(self.expected("a JSON value")),
        };
        Ok(Node {
            at: start..self.pos,
            value,
        })
    }

    fn nested(
        &mut self,
        f: impl FnOnce(&mut Self) -> Result<Value, Error>,
    ) -> Result<Value, Error> {
        if self.depth == MAX_DEPTH {
            return Err(self.error(
                self.here(),
                format!("the JSON nests deeper than {MAX_DEPTH} levels; a details file needs 5"),
            ));
        }
        self.depth += 1;
        let v = f(self);
        self.depth -= 1;
        v
    }

    fn object(&mut self) -> Result<Value, Error> {
        self.pos += 1; // {
        let mut members: Vec<(String, Range<usize>, Node)> = Vec::new();
        self.skip_space();
        if self.peek() == Some(b'}') {
            self.pos += 1;
            return Ok(Value::Object(members));
        }
        loop {
            self.skip_space();
            if self.peek() != Some(b'"') {
                return Err(self.expected("a key in quotes"));
            }
            let key_start = self.pos;
            let key = self.string()?;
            let key_at = key_start..self.pos;
            if members.iter().any(|(k, _, _)| *k == key) {
                return Err(self.error(key_at, format!("`{key}` appears twice in this object")));
            }
            self.skip_space();
            if self.peek() != Some(b':') {
                return Err(self.expected("`:`"));
            }
            self.pos += 1;
            let v = self.value()?;
            members.push((key, key_at, v));
            self.skip_space();
            match self.peek() {
                Some(b',') => self.pos += 1,
                Some(b'}') => {
                    self.pos += 1;
                    return Ok(Value::Object(members));
                }
                _ => return Err(self.expected("`,` or `}`")),
            }
        }
    }

    fn array(&mut self) -> Result<Value, Error> {
        self.pos += 1; // [
        let mut items = Vec::new();
        self.skip_space();
        if self.peek() == Some(b']') {
            self.pos += 1;
            return Ok(Value::Array(items));
        }
        loop {
            items.push(self.value()?);
            self.skip_space();
            match self.peek() {
                Some(b',') => self.pos += 1,
                Some(b']') => {
                    self.pos += 1;
                    return Ok(Value::Array(items));
                }
                _ => return Err(self.expected("`,` or `]`")),
            }
        }
    }

    fn string(&mut self) -> Result<String, Error> {
        let open = self.pos;
        self.pos += 1; // "
        let mut out = String::new();
        loop {
            let rest = &self.text[self.pos..];
            let Some(c) = rest.chars().next() else {
                return Err(self.error(open..open + 1, "this string is never closed"));
            };
            match c {
                '"' => {
                    self.pos += 1;
                    return Ok(out);
                }
                '\\' => {
                    let esc = rest[1..].chars().next();
                    let simple = match esc {
                        Some('"') => Some('"'),
                        Some('\\') => Some('\\'),
                        Some('/') => Some('/'),
                        Some('b') => Some('\u{8}'),
                        Some('f') => Some('\u{c}'),
                        Some('n') => Some('\n'),
                        Some('r') => Some('\r'),
                        Some('t') => Some('\t'),
                        _ => None,
                    };
                    if let Some(s) = simple {
                        out.push(s);
                        self.pos += 2;
                    } else if esc == Some('u') {
                        let at = self.pos..self.pos + 6;
                        let hex = rest.get(2..6).and_then(|h| u32::from_str_radix(h, 16).ok());
                        let Some(unit) = hex else {
                            return Err(self.error(at, "`\\u` needs four hexadecimal digits"));
                        };
                        self.pos += 6;
                        // A surrogate pair is two escapes; a lone half is
                        // replaced, as serde_json would refuse it.
                        let c = if (0xD800..0xDC00).contains(&unit)
                            && self.text[self.pos..].starts_with("\\u")
                        {
                            let low = self
                                .text
                                .get(self.pos + 2..self.pos + 6)
                                .and_then(|h| u32::from_str_radix(h, 16).ok())
                                .filter(|l| (0xDC00..0xE000).contains(l));
                            match low {
                                Some(l) => {
                                    self.pos += 6;
                                    char::from_u32(0x10000 + ((unit - 0xD800) << 10) + (l - 0xDC00))
                                }
                                None => None,
                            }
                        } else {
                            char::from_u32(unit)
                        };
                        let Some(c) = c else {
                            return Err(self.error(at, "this `\\u` escape is not a character"));
                        };
                        out.push(c);
                    } else {
                        let len = 1 + esc.map_or(0, char::len_utf8);
                        return Err(self.error(self.pos..self.pos + len, "not a JSON escape"));
                    }
                }
                c if (c as u32) < 0x20 => {
                    return Err(self.error(
                        self.here(),
                        "a control character inside a string: write it as an escape",
                    ))
                }
                c => {
                    out.push(c);
                    self.pos += c.len_utf8();
                }
            }
        }
    }

    /// JSON's number grammar: -?(0|[1-9][0-9]*)(.[0-9]+)?([eE][+-]?[0-9]+)?
    fn number(&mut self) -> Result<(), Error> {
        let b = self.text.as_bytes();
        let start = self.pos;
        let mut i = self.pos;
        let digits = |i: &mut usize| {
            let s = *i;
            while *i < b.len() && b[*i].is_ascii_digit() {
                *i += 1;
            }
            *i > s
        };
        if b[i] == b'-' {
            i += 1;
        }
        let int_start = i;
        let ok = digits(&mut i) && !(b[int_start] == b'0' && i - int_start > 1);
        let ok =
            ok && (i >= b.len() || b[i] != b'.' || {
                i += 1;
                digits(&mut i)
            }) && (i >= b.len() || !matches!(b[i], b'e' | b'E') || {
                i += 1;
                if i < b.len() && matches!(b[i], b'+' | b'-') {
                    i += 1;
                }
                digits(&mut i)
            });
        // A number runs to the next delimiter.
        let mut end = i;
        while end < b.len() && !matches!(b[end], b',' | b']' | b'}' | b' ' | b'\t' | b'\n' | b'\r')
        {
            end += 1;
        }
        if !ok || end != i {
            // `end` is at an ASCII delimiter or the end: a char boundary.
            let shown = &self.text[start..end];
            return Err(self.error(start..end, format!("`{shown}` is not a JSON number")));
        }
        self.pos = i;
        Ok(())
    }
}

/// Where each value of a details file is, for messages about them.
#[derive(Clone, Debug, Default)]
struct Places {
    whole: Range<usize>,
    format: Range<usize>,
    scheme: Range<usize>,
    coarse_points: Range<usize>,
    levels: Range<usize>,
    level: Vec<LevelPlaces>,
}

#[derive(Clone, Debug, Default)]
struct LevelPlaces {
    shift: Range<usize>,
    details: Range<usize>,
    detail: Vec<Range<usize>>,
    dropped: Range<usize>,
}

/// A place in a details file that a message can be about.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Place {
    /// The whole file.
    File,
    Format,
    CoarsePoints,
    Levels,
    /// Level `k` (0 the coarsest): its `details` array.
    Details(usize),
    /// Level `k`'s `shift`.
    Shift(usize),
    /// Detail `i` of level `k`.
    Detail(usize, usize),
    /// Level `k`'s `dropped` point.
    Dropped(usize),
    /// The scheme the details were made with.
    Scheme,
}

/// A details file as read: the details and the text they came from.
#[derive(Clone, Debug)]
pub struct DetailsFile {
    pub details: Details,
    name: String,
    text: String,
    places: Places,
}

impl DetailsFile {
    /// Reads a details file of at most `max_bytes`.
    pub fn read(path: &Path, max_bytes: u64) -> Result<DetailsFile, Error> {
        let name = path.display().to_string();
        let bytes = read_bounded(path, max_bytes)?;
        let text = utf8_text(&name, bytes, "a details file")?;
        DetailsFile::parse(&name, text)
    }

    /// Reads details from `text`, named `name` in messages. Every number
    /// must be finite, every shift below its level's point count and every
    /// dropped point's index at most that count.
    pub fn parse(name: &str, text: String) -> Result<DetailsFile, Error> {
        let (details, places) = {
            let mut r = Reader {
                name,
                text: &text,
                pos: 0,
                depth: 0,
            };
            let root = r.value()?;
            r.skip_space();
            if r.pos < text.len() {
                return Err(r.error(r.here(), "text after the end of the JSON value"));
            }
            decode(&r, &root)?
        };
        Ok(DetailsFile {
            details,
            name: name.to_string(),
            text,
            places,
        })
    }

    /// An error about `place`, at its line and column.
    pub fn error(&self, place: Place, message: impl Into<String>) -> Error {
        let p = &self.places;
        let level = |k: usize| p.level.get(k);
        let at = match place {
            Place::File => p.whole.clone(),
            Place::Format => p.format.clone(),
            Place::Scheme => p.scheme.clone(),
            Place::CoarsePoints => p.coarse_points.clone(),
            Place::Levels => p.levels.clone(),
            Place::Details(k) => level(k).map_or(p.levels.clone(), |l| l.details.clone()),
            Place::Shift(k) => level(k).map_or(p.levels.clone(), |l| l.shift.clone()),
            Place::Dropped(k) => level(k).map_or(p.levels.clone(), |l| l.dropped.clone()),
            Place::Detail(k, i) => level(k).map_or(p.levels.clone(), |l| {
                l.detail.get(i).cloned().unwrap_or(l.details.clone())
            }),
        };
        Error::in_text(&self.name, &self.text, at, message)
    }
}

fn kind(v: &Value) -> &'static str {
    match v {
        Value::Null => "null",
        Value::Bool(_) => "a boolean",
        Value::Number => "a number",
        Value::String(_) => "a string",
        Value::Array(_) => "an array",
        Value::Object(_) => "an object",
    }
}

fn decode(r: &Reader, root: &Node) -> Result<(Details, Places), Error> {
    let Value::Object(members) = &root.value else {
        return Err(r.error(
            root.at.clone(),
            format!("a details file is a JSON object, not {}", kind(&root.value)),
        ));
    };
    let field = |key: &str| -> Result<&Node, Error> {
        members
            .iter()
            .find(|(k, _, _)| k == key)
            .map(|(_, _, v)| v)
            .ok_or_else(|| {
                r.error(
                    root.at.start..root.at.start + 1,
                    format!("this details file has no `{key}`"),
                )
            })
    };
    let string = |n: &Node, what: &str| match &n.value {
        Value::String(s) => Ok(s.clone()),
        v => Err(r.error(
            n.at.clone(),
            format!("`{what}` must be a string, not {}", kind(v)),
        )),
    };
    let format = field("format")?;
    let format_text = string(format, "format")?;
    let version = field("version")?;
    if format_text != DETAILS_FORMAT || whole(r, version, "version")? != 1 {
        return Err(r.error(
            format.at.start..version.at.end.max(format.at.end),
            format!("not a subgram details file: expected format `{DETAILS_FORMAT}` version 1"),
        ));
    }
    let scheme_node = field("scheme")?;
    let scheme = string(scheme_node, "scheme")?;
    let closed_node = field("closed")?;
    let Value::Bool(closed) = closed_node.value else {
        return Err(r.error(
            closed_node.at.clone(),
            format!(
                "`closed` must be true or false, not {}",
                kind(&closed_node.value)
            ),
        ));
    };
    let coarse = field("coarse_points")?;
    let coarse_points = whole(r, coarse, "coarse_points")?;
    let levels_node = field("levels")?;
    let Value::Array(level_nodes) = &levels_node.value else {
        return Err(r.error(
            levels_node.at.clone(),
            format!(
                "`levels` must be an array, not {}",
                kind(&levels_node.value)
            ),
        ));
    };
    let mut places = Places {
        whole: root.at.start..root.at.start + 1,
        format: format.at.clone(),
        scheme: scheme_node.at.clone(),
        coarse_points: coarse.at.clone(),
        levels: levels_node.at.start..levels_node.at.start + 1,
        level: Vec::new(),
    };
    let mut levels = Vec::with_capacity(level_nodes.len());
    for node in level_nodes {
        let (level, lp) = decode_level(r, node)?;
        levels.push(level);
        places.level.push(lp);
    }
    Ok((
        Details {
            format: format_text,
            version: 1,
            scheme,
            closed,
            coarse_points,
            levels,
        },
        places,
    ))
}

fn decode_level(r: &Reader, node: &Node) -> Result<(LevelDetails, LevelPlaces), Error> {
    let Value::Object(members) = &node.value else {
        return Err(r.error(
            node.at.clone(),
            format!(
                "a level is an object with `shift`, `details` and `dropped`, not {}",
                kind(&node.value)
            ),
        ));
    };
    let field = |key: &str| {
        members
            .iter()
            .find(|(k, _, _)| k == key)
            .map(|(_, _, v)| v)
            .ok_or_else(|| {
                r.error(
                    node.at.start..node.at.start + 1,
                    format!("this level has no `{key}`"),
                )
            })
    };
    let shift_node = field("shift")?;
    let details_node = field("details")?;
    let Value::Array(items) = &details_node.value else {
        return Err(r.error(
            details_node.at.clone(),
            format!(
                "`details` must be an array of [dx, dy] pairs, not {}",
                kind(&details_node.value)
            ),
        ));
    };
    let mut details = Vec::with_capacity(items.len());
    let mut detail = Vec::with_capacity(items.len());
    for item in items {
        details.push(pair(r, item, "a detail")?);
        detail.push(item.at.clone());
    }
    let n = details.len();
    let shift = whole(r, shift_node, "shift")?;
    if shift >= n.max(1) {
        return Err(r.error(
            shift_node.at.clone(),
            format!(
                "`shift` is {shift}, but this level has {n} point(s): a shift must be below that"
            ),
        ));
    }
    let dropped_node = field("dropped")?;
    let dropped = match &dropped_node.value {
        Value::Null => None,
        Value::Array(v) if v.len() == 2 => {
            let i = whole(r, &v[0], "the dropped point's index")?;
            if i > n {
                return Err(r.error(
                    v[0].at.clone(),
                    format!("the dropped point's index is {i}, but this level has {n} point(s): it goes back at {n} at most"),
                ));
            }
            Some((i, pair(r, &v[1], "the dropped point")?))
        }
        other => {
            return Err(r.error(
                dropped_node.at.clone(),
                format!(
                    "`dropped` must be null or [index, [x, y]], not {}",
                    kind(other)
                ),
            ))
        }
    };
    Ok((
        LevelDetails {
            shift,
            details,
            dropped,
        },
        LevelPlaces {
            shift: shift_node.at.clone(),
            details: details_node.at.start..details_node.at.start + 1,
            detail,
            dropped: dropped_node.at.clone(),
        },
    ))
}

/// A whole number from 0.
fn whole(r: &Reader, n: &Node, what: &str) -> Result<usize, Error> {
    let text = &r.text[n.at.clone()];
    match n.value {
        Value::Number => text.parse::<usize>().map_err(|_| {
            let why = if text.parse::<u128>().is_ok() {
                format!(
                    "`{what}` is {text}, beyond the largest whole number, {}",
                    usize::MAX
                )
            } else {
                format!("`{what}` must be a whole number from 0, not {text}")
            };
            r.error(n.at.clone(), why)
        }),
        _ => Err(r.error(
            n.at.clone(),
            format!(
                "`{what}` must be a whole number from 0, not {}",
                kind(&n.value)
            ),
        )),
    }
}

/// A finite number.
fn number(r: &Reader, n: &Node, what: &str) -> Result<f64, Error> {
    let Value::Number = n.value else {
        return Err(r.error(
            n.at.clone(),
            format!("{what} must be a number, not {}", kind(&n.value)),
        ));
    };
    let text = &r.text[n.at.clone()];
    match text.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(r.error(
            n.at.clone(),
            format!("{text} is beyond the range of floating-point numbers (about ±1.8e308)"),
        )),
    }
}

/// `[x, y]` with finite numbers.
fn pair(r: &Reader, n: &Node, what: &str) -> Result<[f64; 2], Error> {
    match &n.value {
        Value::Array(v) if v.len() == 2 => Ok([number(r, &v[0], "x")?, number(r, &v[1], "y")?]),
        Value::Array(v) => Err(r.error(
            n.at.clone(),
            format!("{what} is [x, y], two numbers, not {} value(s)", v.len()),
        )),
        other => Err(r.error(
            n.at.clone(),
            format!("{what} is [x, y], two numbers, not {}", kind(other)),
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn err(text: &str) -> String {
        DetailsFile::parse("d.json", text.to_string())
            .unwrap_err()
            .to_string()
    }

    const GOOD: &str = r#"{"format": "subgram-details", "version": 1, "scheme": "builtin:chaikin",
 "closed": true, "coarse_points": 3,
 "levels": [{"shift": 1, "details": [[0, 0.5], [1e-3, -2], [0, 0], [1, 1], [2, 2], [3, 3]], "dropped": [6, [7.5, -1]]}]}"#;

    #[test]
    fn a_details_file_reads_as_serde_would() {
        let d = DetailsFile::parse("d.json", GOOD.to_string()).unwrap();
        let want: Details = serde_json::from_str(GOOD).unwrap();
        assert_eq!(d.details, want);
    }

    #[test]
    fn every_wrong_value_is_located() {
        let cases = [
            (GOOD.replace("\"shift\": 1", "\"shift\": 18446744073709551615"),
             "d.json:3:23: error: `shift` is 18446744073709551615, but this level has 6 point(s)"),
            (GOOD.replace("[1, 1]", "[1.7e308, 1e400]"),
             "d.json:3:78: error: 1e400 is beyond the range of floating-point numbers"),
            (GOOD.replace("\"shift\": 1", "\"shift\": -1"),
             "d.json:3:23: error: `shift` must be a whole number from 0, not -1"),
            (GOOD.replace("[6, [", "[9, ["),
             "d.json:3:105: error: the dropped point's index is 9"),
            (GOOD.replace("\"version\": 1", "\"version\": 2"),
             "d.json:1:12: error: not a subgram details file"),
            (GOOD.replace("[0, 0.5]", "[0, 0.5, 1]"),
             "d.json:3:38: error: a detail is [x, y], two numbers, not 3 value(s)"),
            (GOOD.replace("1e-3", "01"), "d.json:3:49: error: `01` is not a JSON number"),
            (GOOD.replace("true", "\"yes\""), "d.json:2:12: error: `closed` must be true or false"),
            (GOOD.replace("]}]}", "]}]"), "d.json:3:120: error: expected `,` or `}`, found the end"),
            (format!("{GOOD} x"), "d.json:3:122: error: text after the end of the JSON value"),
            ("[".repeat(100), "d.json:1:65: error: the JSON nests deeper than 64 levels"),
        ];
        for (text, want) in cases {
            let e = err(&text);
            assert!(e.starts_with(want), "{want}\n{e}");
            assert!(e.contains('^'), "{e}");
        }
    }

    #[test]
    fn places_point_at_their_values() {
        let d = DetailsFile::parse("d.json", GOOD.to_string()).unwrap();
        let e = d.error(Place::Detail(0, 3), "this one").to_string();
        assert!(e.starts_with("d.json:3:68: error: this one"), "{e}");
        let e = d.error(Place::CoarsePoints, "that").to_string();
        assert!(e.starts_with("d.json:2:35: error: that"), "{e}");
    }
}
