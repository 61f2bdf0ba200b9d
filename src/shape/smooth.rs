//! Subdivide of a smoothing group (paper 003, §4.2): the group's faces,
//! welded into one polygon soup, are subdivided as one mesh by a surface
//! grammar, with the faces and vertices it shares with shapes outside the
//! group protected (Algorithm 2 with Algorithm 3's sets), and each output
//! face tagged with the member shape whose face it was cut from.
//!
//! The schemes are the project's own grammars (`lsystems/surfaces/`),
//! run by the one grammar engine: `Subdivide` is a grammar run on a mesh
//! built from the welded soup, with the protection passed to the run.
#![allow(dead_code)]

use crate::mesh::{Mesh, PolygonSoup, VertexId};
use crate::surface::{Grammar, Protection};
use crate::Deadline;

/// The subdivision schemes `Subdivide` knows by name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Scheme {
    /// Kobbelt's √3 (the paper's choice, CGAL's `Sqrt3_subdivision`).
    Sqrt3,
    /// Loop's triangle quadrisection.
    Loop,
    /// Catmull-Clark on a tri-quad mesh; output quads.
    CatmullClark,
}

/// The names of the schemes, in the order messages list them.
pub(crate) const SCHEME_NAMES: [&str; 3] = ["sqrt3", "loop", "catmull-clark"];

impl Scheme {
    /// The scheme called `name`, if there is one.
    pub(crate) fn from_name(name: &str) -> Option<Scheme> {
        match name {
            "sqrt3" => Some(Scheme::Sqrt3),
            "loop" => Some(Scheme::Loop),
            "catmull-clark" => Some(Scheme::CatmullClark),
            _ => None,
        }
    }

    /// The grammar file's name and text, built into the program.
    fn source(self) -> (&'static str, &'static str) {
        match self {
            Scheme::Sqrt3 => (
                "sqrt3.lsys",
                include_str!("../../lsystems/surfaces/sqrt3.lsys"),
            ),
            Scheme::Loop => (
                "loop.lsys",
                include_str!("../../lsystems/surfaces/loop.lsys"),
            ),
            Scheme::CatmullClark => (
                "catmull-clark.lsys",
                include_str!("../../lsystems/surfaces/catmull-clark.lsys"),
            ),
        }
    }

    /// The checked grammar. Its `mesh:` line is not used.
    pub(crate) fn grammar(self) -> Result<Grammar, String> {
        let (name, text) = self.source();
        crate::surface::load_str(name, text, &[]).map_err(|e| e.to_string())
    }
}

/// The grammar of the scheme called `name` ("sqrt3", "loop",
/// "catmull-clark"), or a message listing the names.
pub(crate) fn scheme(name: &str) -> Result<Grammar, String> {
    match Scheme::from_name(name) {
        Some(s) => s.grammar(),
        None => Err(format!(
            "unknown subdivision scheme `{name}`: expected {}, {} or {}",
            SCHEME_NAMES[0], SCHEME_NAMES[1], SCHEME_NAMES[2]
        )),
    }
}

/// A subdivided smoothing group.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Smoothed {
    /// The subdivided mesh: triangles for √3 and Loop, the blocks as
    /// quads for Catmull-Clark (as `subgram subdivide` writes them).
    pub soup: PolygonSoup,
    /// Each output face: the tag of the input face it was cut from.
    pub tags: Vec<u32>,
    /// Each output vertex: the input vertex it is, when it is one and
    /// its position is bit for bit the input one (protected vertices
    /// always are); `None` for a new or moved vertex.
    pub origin: Vec<Option<u32>>,
}

/// Subdivides `soup` by `steps` steps of `grammar`, leaving the protected
/// faces and vertices as they are (see [`Protection`]: no face point in a
/// protected face, no shift of a protected vertex or of a corner of a
/// protected face, no edge split or flipped next to a protected face or
/// between two protected vertices). `tags` gives each soup face's tag,
/// which the faces cut from it keep; `protected_face` and
/// `protected_vertex` are by soup face and soup vertex. A protected
/// polygon protects all the triangles the mesh makes of it.
///
/// With nothing protected this is [`Grammar::run`] on the soup's mesh,
/// bit for bit. A soup that is not an oriented 2-manifold, a grammar that
/// refuses the mesh, a limit or the deadline give a message, never a
/// panic.
pub(crate) fn subdivide(
    grammar: &Grammar,
    soup: &PolygonSoup,
    tags: &[u32],
    protected_vertex: &[bool],
    protected_face: &[bool],
    steps: usize,
    deadline: &Deadline,
) -> Result<Smoothed, String> {
    let (nv, nf) = (soup.positions.len(), soup.faces.len());
    if tags.len() != nf || protected_face.len() != nf || protected_vertex.len() != nv {
        return Err(format!(
            "subdivide: {nv} vertices and {nf} faces, but {} tags, {} face and {} vertex protection flags",
            tags.len(),
            protected_face.len(),
            protected_vertex.len()
        ));
    }
    let mut mesh = Mesh::from_soup_tagged(soup, tags)
        .map_err(|e| format!("subdivide: the group's welded mesh is refused: {e}"))?;
    // The mesh's faces come in the soup's order; its vertices are the
    // soup's, with the same ids.
    let ranges = Mesh::soup_face_ranges(soup);
    let mut faces = vec![false; ranges.last().map_or(0, |r| r.end as usize)];
    for (range, _) in ranges.iter().zip(protected_face).filter(|(_, &p)| p) {
        for f in range.clone() {
            faces[f as usize] = true;
        }
    }
    let protection = Protection {
        faces,
        vertices: protected_vertex.to_vec(),
    };
    let mut run = grammar
        .start_protected(&mut mesh, protection)
        .map_err(|e| grammar.render_error(&e))?;
    run.set_deadline(Some(*deadline));
    run.steps(steps, |_| {})
        .map_err(|e| grammar.render_error(&e))?;
    let (out, tags, verts) = mesh.quad_soup_tagged_with_vertices();
    let origin = verts
        .iter()
        .zip(&out.positions)
        .map(|(&v, p)| {
            let VertexId(j) = v;
            let same = soup
                .positions
                .get(j as usize)
                .is_some_and(|q| q.to_array().map(f64::to_bits) == p.to_array().map(f64::to_bits));
            same.then_some(j)
        })
        .collect();
    Ok(Smoothed {
        soup: out,
        tags,
        origin,
    })
}
