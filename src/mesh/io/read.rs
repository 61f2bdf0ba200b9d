//! Reading a mesh file: [`read`], [`read_mesh`] and [`read_str`], and the
//! bytes of a file within the limit on a mesh file's size.

use std::io::Read;
use std::path::Path;

use crate::mesh::halfedge::Mesh;
use crate::mesh::soup::{MeshFileError, PolygonSoup};

use super::raw::UvRead;

use super::creases::{apply_sharpness, read_creases, CREASES_EXTENSION};
use super::text::{error, utf8, Source};
use super::{format_of, max_file_bytes, obj, off, ply, Format, MAX_FILE_BYTES_VAR};

/// Reads the mesh file at `path`, its format chosen by extension. A file
/// larger than [`max_file_bytes`] is refused: a regular file by its size
/// before it is read, anything else (a device, a pipe) as soon as reading
/// passes the limit.
pub fn read(path: &Path) -> Result<PolygonSoup, MeshFileError> {
    let name = path.display().to_string();
    let format = format_of(&name, path)?;
    let limit = max_file_bytes().map_err(|m| error(&name, None, m))?;
    let bytes = read_bounded_as(&name, path, limit, Some(format))?;
    read_str(&name, format, &bytes)
}

/// Reads the mesh file at `path` (see [`read`]) and builds the half-edge
/// mesh, refusing what is not an oriented 2-manifold (see
/// [`Mesh::from_soup`]). A refusal that names a face or vertex shows its
/// line, which is read from the file again for the message.
///
/// Sharpness (creases, OpenSubdiv's numbers) comes from the file where
/// its format carries it, a PLY `edge` element with `vertex1`, `vertex2`
/// and a `crease` or `sharpness` property, and from a file beside the mesh
/// with the extension `.creases` (see [`CREASES_EXTENSION`]), which is
/// read after it for any format.
pub fn read_mesh(path: &Path) -> Result<Mesh, MeshFileError> {
    let name = path.display().to_string();
    let format = format_of(&name, path)?;
    let limit = max_file_bytes().map_err(|m| error(&name, None, m))?;
    let bytes = read_bounded_as(&name, path, limit, Some(format))?;
    let (soup, marks) = match format {
        Format::Ply => ply::parse_with_sharpness(&name, &bytes)?,
        _ => (read_str(&name, format, &bytes)?, Vec::new()),
    };
    drop(bytes);
    finish_mesh(path, &name, &soup, &marks, limit)
}

/// Reads the mesh file at `path` as [`read_mesh`] does, and the texture
/// coordinates of its faces' corners where it has them (OBJ `vt` with `f
/// v/vt`; PLY a face's `texcoord` list or a vertex's `u v`), or a warning
/// that they are not whole and are dropped; also the soup the mesh was
/// built from, whose faces the coordinates follow.
pub fn read_with_uvs(path: &Path) -> Result<(Mesh, PolygonSoup, UvRead), MeshFileError> {
    let name = path.display().to_string();
    let format = format_of(&name, path)?;
    let limit = max_file_bytes().map_err(|m| error(&name, None, m))?;
    let bytes = read_bounded_as(&name, path, limit, Some(format))?;
    let (soup, marks, uvs) = match format {
        Format::Ply => ply::parse_all(&name, &bytes)?,
        Format::Obj => {
            let (soup, uvs) = obj::parse_with_uvs(&name, &bytes)?;
            (soup, Vec::new(), uvs)
        }
        Format::Off => (off::parse(&name, &bytes)?, Vec::new(), UvRead::default()),
    };
    drop(bytes);
    let mesh = finish_mesh(path, &name, &soup, &marks, limit)?;
    Ok((mesh, soup, uvs))
}

/// True when the mesh file at `path` gives texture coordinates (an OBJ
/// `vt` line; a PLY `texcoord` property or a vertex's `u`/`s`): a look at
/// the text, for a command that drops them to say so. False where the
/// file cannot be read (reading it proper reports why).
pub fn mentions_uvs(path: &Path) -> bool {
    let name = path.display().to_string();
    let Ok(format) = format_of(&name, path) else {
        return false;
    };
    let Ok(limit) = max_file_bytes() else {
        return false;
    };
    let Ok(bytes) = read_bounded(&name, path, limit) else {
        return false;
    };
    let starts = |line: &[u8], word: &[u8]| {
        let line = line.trim_ascii_start();
        line.starts_with(word) && line.get(word.len()).is_none_or(|c| c.is_ascii_whitespace())
    };
    match format {
        Format::Obj => bytes.split(|&b| b == b'\n').any(|l| starts(l, b"vt")),
        Format::Ply => {
            let end = bytes
                .windows(10)
                .position(|w| w == b"end_header")
                .unwrap_or(bytes.len());
            bytes[..end].split(|&b| b == b'\n').any(|l| {
                let words: Vec<&[u8]> = l.split(|b| b.is_ascii_whitespace()).collect();
                words.first() == Some(&&b"property"[..])
                    && matches!(words.last(), Some(&w) if [&b"texcoord"[..], b"u", b"s", b"texture_u"].contains(&w))
            })
        }
        Format::Off => false,
    }
}

/// The half-edge mesh of `soup`, read from `path`, with the sharpness of
/// `marks` and of the `.creases` file beside it.
fn finish_mesh(
    path: &Path,
    name: &str,
    soup: &PolygonSoup,
    marks: &[super::creases::Mark],
    limit: u64,
) -> Result<Mesh, MeshFileError> {
    check_deadline(name, 0)?;
    let mut mesh = build_mesh(path, soup)?;
    check_deadline(name, 0)?;
    apply_sharpness(&mut mesh, marks, 0)?;
    let side = path.with_extension(CREASES_EXTENSION);
    if side.is_file() {
        let marks = read_creases(&side, limit)?;
        apply_sharpness(&mut mesh, &marks, 1)?;
    }
    Ok(mesh)
}

/// The half-edge mesh of `soup`, read from `path`.
fn build_mesh(path: &Path, soup: &PolygonSoup) -> Result<Mesh, MeshFileError> {
    Mesh::from_soup(soup).map_err(|e| {
        let name = path.display().to_string();
        let line = e.line.and_then(|no| {
            let limit = max_file_bytes().ok()?;
            let bytes = read_bounded(&name, path, limit).ok()?;
            let text = utf8(&name, &bytes, 1).ok()?;
            let line = Source { text, first: 1 }.line(no)?;
            Some(line.whole(&name, &e.message))
        });
        line.unwrap_or_else(|| error(&name, None, e.message))
    })
}

/// Every 65,536 lines or elements: an error once the run's deadline (see
/// [`crate::deadline::current`]) has passed.
pub(super) fn check_deadline(name: &str, count: usize) -> Result<(), MeshFileError> {
    if count.is_multiple_of(1 << 16) {
        if let Some(d) = crate::deadline::current().filter(|d| d.passed()) {
            return Err(error(name, None, d.message()));
        }
    }
    Ok(())
}

/// Reads a mesh in `format` from `bytes`; `name` is the file name for
/// messages.
pub fn read_str(name: &str, format: Format, bytes: &[u8]) -> Result<PolygonSoup, MeshFileError> {
    match format {
        Format::Obj => obj::parse(name, bytes),
        Format::Off => off::parse(name, bytes),
        Format::Ply => ply::parse(name, bytes),
    }
}

// ---------------------------------------------------------------------------
// Reading a file

/// The bytes of the file at `path`, or an error when there are more than
/// `limit` of them.
pub(super) fn read_bounded(name: &str, path: &Path, limit: u64) -> Result<Vec<u8>, MeshFileError> {
    read_bounded_as(name, path, limit, None)
}

/// [`read_bounded`]; a stream (a device, a pipe) in `format` is also
/// checked as it is read, so that what cannot be a mesh of that format
/// (`/dev/zero`: NUL bytes in a text format, a PLY file without its
/// `ply` line) is refused at once instead of after reading up to the limit.
fn read_bounded_as(
    name: &str,
    path: &Path,
    limit: u64,
    format: Option<Format>,
) -> Result<Vec<u8>, MeshFileError> {
    let cannot = |e: std::io::Error| error(name, None, format!("cannot read the file: {e}"));
    let file = crate::files::open(path).map_err(cannot)?;
    let size = file.size();
    if let Some(size) = size.filter(|&s| s > limit) {
        return Err(too_large(name, Some(size), limit));
    }
    let room = size.map_or(0, |s| usize::try_from(s).unwrap_or(0).saturating_add(1));
    let mut bytes = Vec::with_capacity(room);
    let mut file = file.take(limit.saturating_add(1));
    match (size, format) {
        (None, Some(format)) => {
            // A stream: read in chunks, and look at each as it comes.
            let mut chunk = vec![0u8; 1 << 20];
            loop {
                let n = file.read(&mut chunk).map_err(cannot)?;
                if n == 0 {
                    break;
                }
                let start = bytes.len();
                bytes.extend_from_slice(&chunk[..n]);
                if let Some(m) = stream_problem(format, &bytes, start) {
                    return Err(error(name, None, m));
                }
            }
        }
        _ => {
            file.read_to_end(&mut bytes).map_err(cannot)?;
        }
    }
    if bytes.len() as u64 > limit {
        return Err(too_large(name, None, limit));
    }
    Ok(bytes)
}

/// Why the first bytes of a stream, `bytes` (the new ones from `start`),
/// cannot be a mesh in `format`, if they cannot.
fn stream_problem(format: Format, bytes: &[u8], start: usize) -> Option<String> {
    match format {
        Format::Ply => {
            let head = &bytes[..bytes.len().min(3)];
            (head != &b"ply"[..head.len()])
                .then(|| "a PLY file starts with a line `ply`, and this one does not".to_string())
        }
        _ => bytes[start..].iter().position(|&b| b == 0).map(|i| {
            format!(
                "byte {} is a NUL byte, and {} files are text",
                start + i + 1,
                format.name()
            )
        }),
    }
}

/// "the file is 3 GiB, more than the limit of ...", naming the limit and
/// how to raise it; `size` is `None` for a stream read up to the limit.
fn too_large(name: &str, size: Option<u64>, limit: u64) -> MeshFileError {
    let what = match size {
        Some(s) => format!("the file is {}", bytes_text(s)),
        None => "the file goes on".to_string(),
    };
    error(
        name,
        None,
        format!(
            "{what}, more than the limit of {} for a mesh file; \
             set {MAX_FILE_BYTES_VAR} to a larger number of bytes to read it",
            bytes_text(limit)
        ),
    )
}

/// `n` bytes for a person: "2147483648 bytes (2 GiB)".
fn bytes_text(n: u64) -> String {
    let units = [
        (1u64 << 40, "TiB"),
        (1 << 30, "GiB"),
        (1 << 20, "MiB"),
        (1 << 10, "KiB"),
    ];
    match units.iter().find(|&&(u, _)| n >= u) {
        Some(&(u, unit)) => {
            let v = format!("{:.1}", n as f64 / u as f64);
            let v = v.strip_suffix(".0").unwrap_or(&v);
            format!("{n} bytes ({v} {unit})")
        }
        None => format!("{n} bytes"),
    }
}
