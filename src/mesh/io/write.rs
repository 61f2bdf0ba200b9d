//! Writing a mesh file: [`write()`], [`write_with_sharpness`],
//! [`write_mesh`] and [`to_bytes`], and what the writers of every format
//! read: a soup, or a mesh's triangles read in place.

use std::io::{self, Write};
use std::path::Path;

use glam::DVec3;

use crate::mesh::build::SoupSharpness;
use crate::mesh::halfedge::Mesh;
use crate::mesh::soup::{FaceUvs, MeshFileError, PolygonSoup};

use super::obj::write_obj;
use super::off::write_off;
use super::ply::write_ply;
use super::text::error;
use super::{format_of, Format};

/// Writes `soup` to `path` atomically, its format chosen by extension (PLY
/// is written as ASCII).
pub fn write(path: &Path, soup: &PolygonSoup) -> Result<(), MeshFileError> {
    write_with_sharpness(path, soup, &[])
}

/// Writes `soup` to `path` as [`write()`] does, with a unit normal per
/// vertex where the format has a place for it: `vn` lines in OBJ (each
/// face's corners `v//v`), `nx ny nz` in PLY's vertex element. OFF has
/// none; the caller says so.
pub fn write_with_normals(
    path: &Path,
    soup: &PolygonSoup,
    normals: &[DVec3],
) -> Result<(), MeshFileError> {
    assert_eq!(normals.len(), soup.positions.len(), "a normal per vertex");
    write_with_attributes(path, soup, Some(normals), None, &[])
}

/// Writes `soup` to `path` as [`write()`] does, with a unit normal per
/// face corner: `values`, the first one a vertex (what PLY's vertex
/// element keeps), and `corners`, an index into them for each corner of
/// the faces in order. OBJ writes every value as a `vn` line and the
/// corners `v//n`; PLY the first one a vertex, as [`write_with_normals`].
pub fn write_with_corner_normals(
    path: &Path,
    soup: &PolygonSoup,
    values: &[DVec3],
    corners: &[u32],
) -> Result<(), MeshFileError> {
    assert!(
        values.len() >= soup.positions.len(),
        "a normal per vertex first"
    );
    assert_eq!(
        corners.len(),
        soup.faces.indices().len(),
        "a normal per corner"
    );
    let s = WithNormals {
        soup,
        normals: Some(values),
        normal_corners: Some(corners),
        uvs: None,
    };
    write_streamed(path, &s, &[])
}

/// Writes `soup` to `path` as [`write()`] does, with `normals` (one a
/// vertex, see [`write_with_normals`]) and the corners' texture
/// coordinates `uvs` where the format has a place for them: `vt` lines
/// and `f v/t` corners in OBJ, a face's `texcoord` list (u and v of each
/// corner, as MeshLab writes it) in PLY; and the sharp `edges` as
/// [`write_with_sharpness`] writes them. OFF has no place for texture
/// coordinates; the caller says so.
pub fn write_with_attributes(
    path: &Path,
    soup: &PolygonSoup,
    normals: Option<&[DVec3]>,
    uvs: Option<&FaceUvs>,
    edges: &[(u32, u32, f64)],
) -> Result<(), MeshFileError> {
    if let Some(n) = normals {
        assert_eq!(n.len(), soup.positions.len(), "a normal per vertex");
    }
    if let Some(t) = uvs {
        assert_eq!(
            t.corners.len(),
            soup.faces.indices().len(),
            "a texture coordinate per corner"
        );
    }
    write_streamed(
        path,
        &WithNormals {
            soup,
            normals,
            normal_corners: None,
            uvs,
        },
        edges,
    )
}

/// Writes `soup` to `path` as [`write()`] does, with the sharp `edges` (two
/// soup vertices, from 0, and a sharpness) where the format carries them:
/// a PLY `edge` element with `vertex1`, `vertex2` and `crease`, which
/// [`read_mesh`](super::read_mesh) reads back. OBJ and OFF have no place
/// for them; the caller says so.
pub fn write_with_sharpness(
    path: &Path,
    soup: &PolygonSoup,
    edges: &[(u32, u32, f64)],
) -> Result<(), MeshFileError> {
    write_streamed(path, soup, edges)
}

/// Writes the mesh `m` to `path` as [`write_with_sharpness`] writes
/// [`Mesh::to_soup_with_sharpness`]`(triangles)`, the same bytes, and
/// gives that sharpness. Where the soup would be the mesh's triangles as
/// they are (`triangles`, or no basic block to merge), they are written
/// straight from the mesh: no copy of a large mesh is made.
pub fn write_mesh(path: &Path, m: &Mesh, triangles: bool) -> Result<SoupSharpness, MeshFileError> {
    if triangles || !m.quad_soup_merges() {
        let view = MeshTriangles::new(m);
        let sharp = m.soup_sharpness(&view.index, triangles);
        write_streamed(path, &view, &sharp.edges)?;
        Ok(sharp)
    } else {
        let (soup, sharp) = m.to_soup_with_sharpness(triangles);
        write_streamed(path, &soup, &sharp.edges)?;
        Ok(sharp)
    }
}

/// Writes `s` to `path` atomically, piece by piece, in the format of the
/// path's extension.
fn write_streamed(
    path: &Path,
    s: &dyn Polygons,
    edges: &[(u32, u32, f64)],
) -> Result<(), MeshFileError> {
    let name = path.display().to_string();
    let format = format_of(&name, path)?;
    crate::files::atomic::write_atomic_with(path, |w| write_polygons(w, format, s, edges))
        .map_err(|e| error(&name, None, format!("cannot write the file: {e}")))
}

/// The text of `soup` in `format` (PLY as ASCII).
pub fn to_bytes(format: Format, soup: &PolygonSoup) -> Vec<u8> {
    let mut out = Vec::new();
    write_polygons(&mut out, format, soup, &[]).expect("writing to memory");
    out
}

// ---------------------------------------------------------------------------
// Writing

/// What the writers read: the positions and the polygons of a soup, or of
/// a mesh's triangles read in place ([`MeshTriangles`]), so that a large
/// mesh is written without a copy of it.
pub(super) trait Polygons {
    fn vertex_count(&self) -> usize;
    fn face_count(&self) -> usize;
    /// The most corners of any face (0 without faces).
    fn longest(&self) -> usize;
    /// Calls `f` on every position in order, stopping at an error.
    fn each_position(&self, f: &mut dyn FnMut(DVec3) -> io::Result<()>) -> io::Result<()>;
    /// Calls `f` on every face's corners in order, stopping at an error.
    fn each_face(&self, f: &mut dyn FnMut(&[u32]) -> io::Result<()>) -> io::Result<()>;
    /// A normal per vertex, in order, when there are normals (then, with
    /// [`Polygons::normal_corners`], more normals that corners name).
    fn normals(&self) -> Option<&[DVec3]> {
        None
    }
    /// Each face corner's normal, an index into [`Polygons::normals`];
    /// `None`: each corner has its vertex's.
    fn normal_corners(&self) -> Option<&[u32]> {
        None
    }
    /// The texture coordinates of the faces' corners, when there are some.
    fn uvs(&self) -> Option<&FaceUvs> {
        None
    }
}

/// A soup with a normal per vertex, or texture coordinates per corner, or
/// both.
struct WithNormals<'a> {
    soup: &'a PolygonSoup,
    normals: Option<&'a [DVec3]>,
    /// Each face corner's normal, an index into `normals` (else a vertex's
    /// own).
    normal_corners: Option<&'a [u32]>,
    uvs: Option<&'a FaceUvs>,
}

impl Polygons for WithNormals<'_> {
    fn vertex_count(&self) -> usize {
        self.soup.vertex_count()
    }

    fn face_count(&self) -> usize {
        self.soup.face_count()
    }

    fn longest(&self) -> usize {
        self.soup.longest()
    }

    fn each_position(&self, f: &mut dyn FnMut(DVec3) -> io::Result<()>) -> io::Result<()> {
        self.soup.each_position(f)
    }

    fn each_face(&self, f: &mut dyn FnMut(&[u32]) -> io::Result<()>) -> io::Result<()> {
        self.soup.each_face(f)
    }

    fn normals(&self) -> Option<&[DVec3]> {
        self.normals
    }

    fn normal_corners(&self) -> Option<&[u32]> {
        self.normal_corners
    }

    fn uvs(&self) -> Option<&FaceUvs> {
        self.uvs
    }
}

impl Polygons for PolygonSoup {
    fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    fn face_count(&self) -> usize {
        self.faces.len()
    }

    fn longest(&self) -> usize {
        match self.faces.arity() {
            Some(n) => n,
            None => self.faces.iter().map(<[u32]>::len).max().unwrap_or(0),
        }
    }

    fn each_position(&self, f: &mut dyn FnMut(DVec3) -> io::Result<()>) -> io::Result<()> {
        self.positions.iter().try_for_each(|&p| f(p))
    }

    fn each_face(&self, f: &mut dyn FnMut(&[u32]) -> io::Result<()>) -> io::Result<()> {
        self.faces.iter().try_for_each(f)
    }
}

/// A mesh's triangles as [`Mesh::to_soup`] gives them (its live vertices
/// and faces in order), read from the mesh as they are written.
struct MeshTriangles<'m> {
    mesh: &'m Mesh,
    /// The soup vertex of each vertex slot (`u32::MAX` for a dead slot).
    index: Vec<u32>,
    vertices: usize,
}

impl<'m> MeshTriangles<'m> {
    fn new(mesh: &'m Mesh) -> MeshTriangles<'m> {
        let mut index = vec![u32::MAX; mesh.v_alive.len()];
        let mut vertices = 0;
        for v in mesh.vertices() {
            index[v.index()] = vertices as u32;
            vertices += 1;
        }
        MeshTriangles {
            mesh,
            index,
            vertices,
        }
    }
}

impl Polygons for MeshTriangles<'_> {
    fn vertex_count(&self) -> usize {
        self.vertices
    }

    fn face_count(&self) -> usize {
        self.mesh.face_count()
    }

    fn longest(&self) -> usize {
        if self.mesh.face_count() > 0 {
            3
        } else {
            0
        }
    }

    fn each_position(&self, f: &mut dyn FnMut(DVec3) -> io::Result<()>) -> io::Result<()> {
        self.mesh
            .vertices()
            .try_for_each(|v| f(self.mesh.position(v)))
    }

    fn each_face(&self, f: &mut dyn FnMut(&[u32]) -> io::Result<()>) -> io::Result<()> {
        self.mesh.faces().try_for_each(|g| {
            let [a, b, c] = self.mesh.face_vertices(g);
            f(&[
                self.index[a.index()],
                self.index[b.index()],
                self.index[c.index()],
            ])
        })
    }
}

/// Writes one face's indices (plus `base`), each after a space, and a
/// newline.
pub(super) fn put_indices(w: &mut dyn Write, face: &[u32], base: u64) -> io::Result<()> {
    // Decimal digits by hand into one buffer per face: the same text as
    // `to_string` of each, without an allocation per index.
    let mut buf = [0u8; 256];
    let mut n = 0;
    for &i in face {
        if n + 22 > buf.len() {
            w.write_all(&buf[..n])?;
            n = 0;
        }
        buf[n] = b' ';
        n += 1;
        let mut x = u64::from(i) + base;
        let mut digits = [0u8; 20];
        let mut k = digits.len();
        loop {
            k -= 1;
            digits[k] = b'0' + (x % 10) as u8;
            x /= 10;
            if x == 0 {
                break;
            }
        }
        let d = &digits[k..];
        buf[n..n + d.len()].copy_from_slice(d);
        n += d.len();
    }
    buf[n] = b'\n';
    w.write_all(&buf[..n + 1])
}

/// Writes `x y z` with exactly round-tripping coordinates.
pub(super) fn put_position(w: &mut dyn Write, p: DVec3) -> io::Result<()> {
    writeln!(w, "{:?} {:?} {:?}", p.x, p.y, p.z)
}

/// Writes `s` in `format`, with the sharp `edges` where the format
/// carries them (PLY).
fn write_polygons(
    w: &mut dyn Write,
    format: Format,
    s: &dyn Polygons,
    edges: &[(u32, u32, f64)],
) -> io::Result<()> {
    match format {
        Format::Obj => write_obj(w, s),
        Format::Off => write_off(w, s),
        Format::Ply => write_ply(w, s, edges),
    }
}
