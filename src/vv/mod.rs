//! Vertex-vertex systems (paper 001): a mesh as a graph rotation system,
//! every vertex with a cyclic list of its neighbours, edited by the
//! vertex-vertex algebra from programs in the `.lsys` language.
//!
//! A vv program is the third topology of the one production model: its
//! statements are the host built-ins of `host::VV_HOST`, checked by the
//! one checker and run by the one interpreter; [`run::VvRun`] is its
//! schedule (`Start`, then `StartEach`, `Step`, `EndEach` per step, with
//! the mesh's consistency checked after each).
//!
//! **Layer.** It uses `deadline`, `lang`, `limits`, `mesh`, `production`,
//! `surface`, `syntax`; it is used by `command`, `load`, `system`. Nothing
//! here names a layer above (see ARCHITECTURE.md, "Layers").

pub(crate) mod host;
pub(crate) mod mesh;
pub(crate) mod run;

use crate::lang;
use crate::production::{Checked, Entry};
use crate::syntax::ast::{ExprKind, Init, Item};
use crate::syntax::lex::{Tok, Token};
use crate::syntax::source::Front;
use crate::syntax::SourceError;
use crate::syntax::{parse, Diagnostic, Span};

pub use mesh::{Rotation, NULL};
pub use run::{VvError, VvProgram, VvRun};

/// This topology's entry in the loader's table.
pub(crate) const ENTRY: Entry = Entry {
    claims: is_vv,
    check: |front, _| from_front(front).map(|p| Box::new(p) as Checked),
};

/// True when preprocessed tokens are a vv program: `mesh NAME` that
/// starts a line or follows a `;` or `}` (a declaration of a set of
/// vertices, as in `int n; mesh S;`; a surface grammar's `mesh:` has a
/// colon).
pub(crate) fn is_vv(toks: &[Token]) -> bool {
    toks.windows(2).enumerate().any(|(k, w)| {
        let starts = w[0].line_start
            || (k > 0 && (toks[k - 1].tok.is_punct(";") || toks[k - 1].tok.is_punct("}")));
        starts && w[0].tok.is_ident("mesh") && matches!(&w[1].tok, Tok::Ident(n) if !is_type(n))
    })
}

fn is_type(n: &str) -> bool {
    matches!(
        n,
        "int" | "float" | "double" | "bool" | "V2f" | "V3f" | "V2d" | "V3d" | "long" | "char"
    )
}

/// Parses and checks preprocessed tokens as a vv program.
pub(crate) fn from_front(front: Front) -> Result<VvProgram, SourceError> {
    let eof = front.eof();
    let Front {
        sources, tokens, ..
    } = front;
    let fail = |sources, d: Vec<Diagnostic>| SourceError::Program {
        sources,
        diagnostics: d,
    };
    let predefined: Vec<&str> = lang::modules::PREDEFINED.iter().map(|(n, _)| *n).collect();
    let mut file = match parse::parse_file_as(&tokens, eof, &predefined, true) {
        Ok(f) => f,
        Err(d) => return Err(fail(sources, vec![d])),
    };
    let mut diags = Vec::new();
    // The first global `mesh` is the structure; a string initialiser
    // names its base mesh file.
    let mut structure = None;
    let mut globals = 0u16;
    for item in &mut file.items {
        match item {
            Item::Global(d) => {
                for v in &mut d.vars {
                    if structure.is_some() && d.ty.name == "mesh" {
                        if let Init::Expr(e) = &v.init {
                            if let ExprKind::Str(_) = &e.kind {
                                diags.push(Diagnostic::new(
                                    e.span,
                                    "only the structure, the first global `mesh`, reads a base \
                                     mesh file; build this set in `Start` or a step",
                                ));
                            }
                        }
                    }
                    if structure.is_none() && d.ty.name == "mesh" && v.dims.is_empty() {
                        let mut base = None;
                        if let Init::Expr(e) = &v.init {
                            if let ExprKind::Str(s) = &e.kind {
                                base = Some((s.clone(), e.span));
                                v.init = Init::None;
                            }
                        }
                        structure = Some((globals, v.name.text.clone(), v.name.span, base));
                    }
                    globals += 1;
                }
            }
            Item::Production(p) => diags.push(Diagnostic::new(
                p.span,
                "a vv program has no productions: its `Step: { ... }` block runs once per step",
            )),
            Item::Axiom { span, .. } => diags.push(Diagnostic::new(
                *span,
                "a vv program has no axiom: its mesh comes from `mesh S = \"file.obj\";` or is built in `Start`",
            )),
            _ => {}
        }
    }
    let Some((slot, name, span, base)) = structure else {
        diags.push(Diagnostic::new(
            Span::new(eof.file, 0, 0),
            "a vv program declares its mesh as a global, before any function: `mesh S;` or `mesh S = \"file.obj\";`",
        ));
        return Err(fail(sources, diags));
    };
    if !diags.is_empty() {
        return Err(fail(sources, diags));
    }
    let mut program =
        match lang::compile::compile_on(&file, lang::compile::Precision::Double, &host::VV_HOST) {
            Ok(p) => p,
            Err(mut d) => {
                for x in &mut d {
                    if x.span == Span::default() {
                        x.span = eof;
                    }
                }
                return Err(fail(sources, d));
            }
        };
    for (_, body, _) in &mut program.control {
        body.iter_mut()
            .for_each(|s| s.walk_mut(&mut host::specialise_node));
    }
    for f in &mut program.functions {
        f.body
            .iter_mut()
            .for_each(|s| s.walk_mut(&mut host::specialise_node));
    }
    // Globals are numbered in declaration order by the checker too.
    let structure = program
        .globals
        .iter()
        .position(|g| g.name == name)
        .map_or(slot, |i| i as u16);
    let warnings = program.warnings.clone();
    Ok(VvProgram {
        program,
        sources,
        warnings,
        structure,
        structure_name: (name, span),
        base,
        max_vertices: run::MAX_VV_VERTICES,
    })
}

impl Rotation {
    /// The rotation system of a half-edge mesh: its polygons as the mesh
    /// shows them (basic blocks as quads), ids in the mesh's vertex order;
    /// the members in id order.
    pub fn from_halfedge(m: &crate::mesh::Mesh) -> Result<(Rotation, Vec<u32>), String> {
        Rotation::from_soup(&m.to_quad_soup())
    }

    /// The half-edge mesh of the faces of `set` (Edmonds' orbits), its
    /// vertices in the order of `set`.
    pub fn to_halfedge(&self, set: &[u32]) -> Result<crate::mesh::Mesh, String> {
        crate::mesh::Mesh::from_soup(&self.to_soup(set)?).map_err(|e| e.to_string())
    }
}
