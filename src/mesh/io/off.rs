//! OFF: an optional header (`OFF`, `COFF`, `NOFF`, `STCNOFF`, ...), the
//! counts, one vertex per line, one face per line.
//!
//! The writer writes the header, the counts, the vertices and `k i1 .. ik`
//! faces.

use std::io::{self, Write};

use crate::mesh::soup::{MeshFileError, PolygonSoup};

use super::raw::Raw;
use super::read::check_deadline;
use super::text::{parse_count, parse_index, parse_position, strip_comment, utf8, Line, Source};
use super::write::{put_indices, put_position, Polygons};

/// Parses OFF text into a checked soup.
pub(super) fn parse(name: &str, bytes: &[u8]) -> Result<PolygonSoup, MeshFileError> {
    let text = utf8(name, bytes, 1)?;
    let source = Source { text, first: 1 };
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| Line { no: i + 1, text: l })
        .filter(|l| strip_comment(l.text).split_whitespace().next().is_some());
    let (line, counts) = counts(name, &mut lines, source)?;
    let nv = parse_count(name, &line, counts[0], "vertices")?;
    let nf = parse_count(name, &line, counts[1], "faces")?;
    let mut raw = Raw::new(0);
    // Room for what the counts declare, as far as the text can hold it
    // (a vertex takes 6 bytes or more, a face 8): a count is checked
    // against the lines that are there as they are read.
    raw.positions.reserve(nv.min(text.len() / 6));
    raw.face_lines.reserve(nf.min(text.len() / 8));
    for v in 0..nv {
        check_deadline(name, v)?;
        let line = lines
            .next()
            .ok_or_else(|| ends_early(name, source, v, nv, "vertices"))?;
        let p = parse_position(
            name,
            &line,
            strip_comment(line.text).split_whitespace(),
            &raw,
        )?;
        raw.push_vertex(p, line.no);
    }
    let mut toks = Vec::new();
    for f in 0..nf {
        check_deadline(name, f)?;
        let line = lines
            .next()
            .ok_or_else(|| ends_early(name, source, f, nf, "faces"))?;
        toks.clear();
        toks.extend(strip_comment(line.text).split_whitespace());
        parse_face(name, &line, f, &toks, &mut raw)?;
        raw.end_face(line.no, 1);
    }
    if let Some(line) = lines.next() {
        let words: Vec<&str> = strip_comment(line.text).split_whitespace().collect();
        return Err(line.whole(
            name,
            format!(
                "unexpected `{}` after the {nf} declared faces",
                words.join(" ")
            ),
        ));
    }
    raw.finish(name, Some(source))
}

/// "the file ends after 3 of the 8 declared vertices", where it ends.
fn ends_early(name: &str, source: Source, got: usize, want: usize, what: &str) -> MeshFileError {
    source.last().end(
        name,
        format!("the file ends after {got} of the {want} declared {what}"),
    )
}

/// The counts line (after an optional header), with at least two words.
fn counts<'a>(
    name: &str,
    lines: &mut impl Iterator<Item = Line<'a>>,
    source: Source<'a>,
) -> Result<(Line<'a>, Vec<&'a str>), MeshFileError> {
    let expected = "expected the counts line `vertices faces edges`";
    let words = |l: &Line<'a>| -> Vec<&'a str> {
        let text: &'a str = l.text;
        strip_comment(text).split_whitespace().collect()
    };
    let line = lines.next().ok_or_else(|| {
        source
            .last()
            .end(name, format!("the file is empty: {expected}"))
    })?;
    let toks = words(&line);
    let (line, toks) = if is_header(toks[0]) {
        check_header(name, &line, &toks)?;
        if toks.len() > 1 {
            (line, toks[1..].to_vec())
        } else {
            let next = lines.next().ok_or_else(|| {
                source
                    .last()
                    .end(name, format!("the file ends: {expected}"))
            })?;
            let toks = words(&next);
            (next, toks)
        }
    } else if toks[0].parse::<f64>().is_err() {
        return Err(line.at(
            name,
            toks[0],
            format!(
                "expected an `OFF` header or the counts line, found `{}`",
                toks[0]
            ),
        ));
    } else {
        (line, toks)
    };
    if toks.len() < 2 {
        return Err(line.whole(name, format!("{expected}, found `{}`", toks.join(" "))));
    }
    Ok((line, toks))
}

/// Whether `tok` is an OFF keyword such as `OFF`, `COFF` or `STCNOFF`.
fn is_header(tok: &str) -> bool {
    tok.strip_suffix("OFF")
        .is_some_and(|prefix| prefix.chars().all(|c| "STCN4n".contains(c)))
}

/// Refuses the OFF variants this reader does not handle.
fn check_header(name: &str, line: &Line, toks: &[&str]) -> Result<(), MeshFileError> {
    if toks[0].contains('4') {
        return Err(line.at(
            name,
            toks[0],
            "4OFF (four coordinates per vertex) is not supported",
        ));
    }
    if toks[0].contains('n') {
        return Err(line.at(
            name,
            toks[0],
            "nOFF (any number of coordinates per vertex) is not supported",
        ));
    }
    if let Some(&word @ "BINARY") = toks.get(1) {
        return Err(line.at(name, word, "binary OFF is not supported"));
    }
    Ok(())
}

/// Pushes face `f`: `k i1 .. ik`, further values (colours) ignored.
fn parse_face(
    name: &str,
    line: &Line,
    f: usize,
    toks: &[&str],
    raw: &mut Raw,
) -> Result<(), MeshFileError> {
    let found = toks[0];
    let k = found.parse::<usize>().map_err(|_| {
        let message = format!("expected the number of vertices of face {f}, found `{found}`");
        line.at(name, found, message)
    })?;
    let listed = toks.len() - 1;
    if listed < k {
        return Err(line.at(
            name,
            found,
            format!("face {f} declares {k} vertices but lists {listed}"),
        ));
    }
    for tok in &toks[1..=k] {
        raw.indices.push(parse_index(name, line, tok)?);
    }
    Ok(())
}

/// OFF: header, counts, vertices, `k i1 .. ik` faces.
pub(super) fn write_off(w: &mut dyn Write, s: &dyn Polygons) -> io::Result<()> {
    write!(w, "OFF\n{} {} 0\n", s.vertex_count(), s.face_count())?;
    s.each_position(&mut |p| put_position(w, p))?;
    s.each_face(&mut |f| {
        write!(w, "{}", f.len())?;
        put_indices(w, f, 0)
    })
}
