//! What subgram does not do with lpfg's predefined modules: a warning for
//! each predefined module that a program puts into its word (the axiom or
//! a `produce`) and that the turtle does not act on, at its first place in
//! the program. Nothing a model asks for is dropped without a word.

use std::collections::HashMap;

use crate::lang::ir::{Program, St, Succ};
use crate::lang::Sym;
use crate::syntax::span::{Diagnostic, Span};

/// Why a predefined module is not acted on, and what the picture lacks.
fn gap(name: &str) -> Option<String> {
    let not_drawn = |what: &str| {
        Some(format!(
            "`{name}` is not drawn by subgram yet: {what} will be missing from the picture"
        ))
    };
    let no_effect = |why: &str| Some(format!("`{name}` has no effect in subgram yet: {why}"));
    match name {
        // `Surface` and `Surface3` draw the view file's Bézier surfaces.
        "BSurface" | "DSurface" | "DBSurfaceS" | "DBSurfaceM" => {
            not_drawn("the surfaces it draws (leaves, petals)")
        }
        "Mesh" | "Mesh3" => not_drawn("the meshes it draws"),
        "InitSurface" | "SurfacePoint" | "DrawSurface" => {
            not_drawn("the surface that `InitSurface`, `SurfacePoint` and `DrawSurface` define")
        }
        "Label" => not_drawn("the text it writes"),
        "Terrain" => not_drawn("the terrain"),
        "Orient" => not_drawn("the turtle's axes it draws"),
        // Generalized cylinders, their contours and the precision of
        // surfaces shape the 3D geometry (`draw::solid`).
        "ContourNormal" => {
            no_effect("subgram's generalized cylinders take their normals from the contour's shape")
        }
        "CurrentTexture" | "TextureVCoeff" => no_effect("subgram does not map textures"),
        "Camera" => no_effect("subgram fits the view to the drawing"),
        "PovRayStart" => no_effect("subgram does not write POV-Ray files"),
        "E1" | "E2" | "EA20" => Some(format!(
            "`{name}` {ENVIRONMENT_WARNING} (a model folder's `.e` file names one): its \
             parameters stay as the model produced them"
        )),
        _ => None,
    }
}

/// The words of the warning about communication modules without an
/// environment.
const ENVIRONMENT_WARNING: &str =
    "communicates with an environmental program, and this program has none";

/// True for the warning about communication modules that no environment
/// answers (the loader drops it for a model with a `.e` file).
pub fn is_environment_warning(message: &str) -> bool {
    message.contains(ENVIRONMENT_WARNING)
}

/// The warnings for `program`: one per predefined module that it puts into
/// its word and that subgram does not act on, at the module's first place
/// (the axiom or a `produce`), sorted by place.
pub fn warnings(program: &Program) -> Vec<Diagnostic> {
    let mut first: HashMap<Sym, Span> = HashMap::new();
    let mut note = |s: &Succ| {
        let e = first.entry(s.sym).or_insert(s.span);
        if (s.span.file.0, s.span.start) < (e.file.0, e.start) {
            *e = s.span;
        }
    };
    program.axiom.iter().for_each(&mut note);
    for rule in &program.rules {
        successors(&rule.body, &mut note);
    }
    for (_, body, _) in &program.control {
        successors(body, &mut note);
    }
    let mut places: Vec<(Span, Sym)> = first
        .into_iter()
        .filter(|(s, _)| program.alphabet.get(*s).builtin)
        .map(|(s, span)| (span, s))
        .collect();
    places.sort_by_key(|(span, _)| (span.file.0, span.start));
    // One warning per family (generalized cylinders, environmental
    // modules), at its first member.
    let mut families = Vec::new();
    let mut out = Vec::new();
    for (span, s) in places {
        let name = program.alphabet.name(s);
        let Some(message) = gap(name) else { continue };
        let family = family(name);
        if family != name && families.contains(&family) {
            continue;
        }
        families.push(family);
        out.push(Diagnostic::new(span, message));
    }
    out
}

/// Modules that one warning covers.
fn family(name: &str) -> &str {
    match name {
        "InitSurface" | "SurfacePoint" | "DrawSurface" => "L-system surface",
        "E1" | "E2" | "EA20" => "environment",
        _ => name,
    }
}

/// Calls `f` on every successor module of every `produce` in `body`.
fn successors(body: &[St], f: &mut impl FnMut(&Succ)) {
    for st in body {
        match st {
            St::Produce { modules, .. } => modules.iter().for_each(&mut *f),
            St::If(_, a, b) => {
                successors(std::slice::from_ref(a), f);
                if let Some(b) = b {
                    successors(std::slice::from_ref(b), f);
                }
            }
            St::Loop { body, .. } | St::ForAll { body, .. } => {
                successors(std::slice::from_ref(body), f)
            }
            St::Block(b) | St::Switch { body: b, .. } => successors(b, f),
            St::Expr(_)
            | St::Init(..)
            | St::Return
            | St::ReturnValue(_)
            | St::Break
            | St::Continue
            | St::SetEdit { .. } => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lang::modules::PREDEFINED;

    /// Every predefined module is either acted on by the turtle, part of
    /// derivation (branches, `Cut`, queries, the endmarker, mouse
    /// insertion, a Gillespie reaction's `Propensity`), or has a warning. A module added to the table without a
    /// decision fails here.
    #[test]
    fn every_predefined_module_is_drawn_handled_or_warned() {
        let handled_elsewhere = ["#", "Cut", "MouseIns", "MouseInsPos", "Propensity"];
        for (name, _) in PREDEFINED {
            let drawn = super::super::acts_on(name);
            let warned = gap(name).is_some();
            let elsewhere = handled_elsewhere.contains(name);
            assert!(
                [drawn, warned, elsewhere].iter().filter(|b| **b).count() == 1,
                "`{name}`: drawn {drawn}, warned {warned}, handled elsewhere {elsewhere}"
            );
        }
        // The modules subgram lacks are not in the table too.
        for (name, _) in crate::lang::modules::NOT_YET {
            assert!(PREDEFINED.iter().all(|(p, _)| p != name), "`{name}`");
        }
    }
}
