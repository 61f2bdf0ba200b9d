//! Stellar subdivision grammars (paper 000): rules over faces, edges and
//! vertices with levels, run on the half-edge mesh.
//!
//! The loader tells a grammar from a curve L-system by its syntax;
//! [`load_str`] and [`load_file`] read text as a grammar whatever it says.
//!
//! **Layer.** It uses `deadline`, `lang`, `limits`, `mesh`, `model`,
//! `production`, `syntax`; it is used by `analyze`, `command`, `load`,
//! `shape`, `system`, `vv`. Nothing here names a layer above (see
//! ARCHITECTURE.md, "Layers").

pub(crate) mod grammar;
pub(crate) mod host;
pub(crate) mod run;
pub mod uvs;

use std::path::Path;

use crate::production::{Checked, Entry};
use crate::syntax::lex::Token;
use crate::syntax::source::{self, Front};
use crate::syntax::SourceError;
use crate::syntax::Span;

pub use run::{Grammar, GrammarRun, Protection, RunError, StepCounts};

/// This topology's entry in the loader's table.
pub(crate) const ENTRY: Entry = Entry {
    claims: is_surface,
    check: |front, _| from_front(front).map(|g| Box::new(g) as Checked),
};

/// True when preprocessed tokens are a surface grammar: a `mesh:` directive
/// at the start of a line, or a rule in paper 000's form on one line: `F(`,
/// `E(` or `V(` at the start of the line, then `->` and a successor context
/// `||` outside parentheses. (In a curve L-system `||` is C's "or", inside a
/// module's parentheses or in a condition before the arrow; with `angle:`,
/// `|` is the turtle's turn, so such files are curves.)
pub(crate) fn is_surface(toks: &[Token]) -> bool {
    let directive = |name: &str| {
        toks.windows(2)
            .any(|w| w[0].line_start && w[0].tok.is_ident(name) && w[1].tok.is_punct(":"))
    };
    grammar::is_surface(toks)
        || (!directive("angle") && (0..toks.len()).any(|i| is_rule_at(toks, i)))
}

/// A surface rule starts at token `i`: see [`is_surface`].
fn is_rule_at(toks: &[Token], i: usize) -> bool {
    let t = &toks[i];
    let element = t.tok.is_ident("F") || t.tok.is_ident("E") || t.tok.is_ident("V");
    if !t.line_start || !element || !toks.get(i + 1).is_some_and(|n| n.tok.is_punct("(")) {
        return false;
    }
    let (mut depth, mut arrow) = (0usize, false);
    for n in toks[i + 1..].iter().take_while(|n| !n.line_start) {
        if n.tok.is_punct("(") {
            depth += 1;
        } else if n.tok.is_punct(")") {
            depth = depth.saturating_sub(1);
        } else if depth == 0 {
            if n.tok.is_punct(";") || n.tok.is_punct("{") {
                return false;
            }
            arrow |= n.tok.is_punct("->");
            if arrow && n.tok.is_punct("||") {
                return true;
            }
        }
    }
    false
}

/// Parses and checks preprocessed tokens as a surface grammar.
pub(crate) fn from_front(front: Front) -> Result<Grammar, SourceError> {
    from_front_with(front, true)
}

/// [`from_front`], with or without the specialisations of the IR.
pub(crate) fn from_front_with(front: Front, specialise: bool) -> Result<Grammar, SourceError> {
    let eof = front.eof();
    let Front {
        sources, tokens, ..
    } = front;
    // A rule's text for messages and reports, its whitespace folded.
    let text_of = |s: Span| {
        let text = &sources.get(s.file).text;
        let end = (s.end as usize).min(text.len());
        let t = text.get(s.start as usize..end).unwrap_or_default();
        t.split_whitespace().collect::<Vec<_>>().join(" ")
    };
    let file = match grammar::parse(&tokens, eof, text_of) {
        Ok(f) => f,
        Err(e) => return Err(SourceError::at(&sources, e)),
    };
    run::compile_with(&file, sources, specialise).map_err(|(sources, diagnostics)| {
        SourceError::Program {
            sources,
            diagnostics,
        }
    })
}

/// Checks text as a surface grammar. `defines` are `NAME=VALUE`
/// overrides; `name` is the file name in messages.
pub fn load_str(name: &str, text: &str, defines: &[String]) -> Result<Grammar, SourceError> {
    from_front(source::front(name, text.to_string(), defines)?)
}

/// Reads and checks a surface grammar file.
pub fn load_file(path: &Path, defines: &[String]) -> Result<Grammar, SourceError> {
    let text = source::read(path)?;
    from_front(source::front(&path.display().to_string(), text, defines)?)
}

#[cfg(test)]
mod tests {
    use std::path::PathBuf;

    use super::*;
    use crate::mesh::{io, Mesh};

    /// A mesh that each scheme has subdivided gives the same soups by the
    /// fast walk as by the reference one (`mesh::build`'s tests check the
    /// same after splits and flips).
    #[test]
    fn soups_match_after_grammars() {
        use crate::mesh::shapes;
        let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("lsystems/surfaces");
        for (grammar, base) in [
            ("catmull-clark.lsys", shapes::quad_torus(6, 5)),
            ("doo-sabin.lsys", shapes::quad_torus(6, 5)),
            ("four-eight.lsys", shapes::quad_grid(4, 4)),
            ("loop.lsys", shapes::icosphere(1)),
            ("sqrt3.lsys", shapes::icosphere(1)),
        ] {
            let g = load_file(&root.join(grammar), &[]).unwrap();
            let tags: Vec<u32> = (0..base.faces.len()).map(|i| (i % 2) as u32).collect();
            let mut m = Mesh::from_soup_tagged(&base, &tags).unwrap();
            g.run(&mut m, 2, |_| {}).unwrap();
            crate::mesh::build::tests::soups_agree(&m);
        }
    }

    /// Runs the grammar `steps` steps on its own mesh, with or without the
    /// specialisations, protecting every third face and every fourth
    /// vertex of the base mesh when `protect` says so. A run may fail: a
    /// scheme whose rules assume whole steps can meet a configuration
    /// that protection made and refuse it (Doo-Sabin's flips).
    fn run_protected(
        name: &str,
        text: &str,
        specialise: bool,
        steps: usize,
        protect: bool,
    ) -> Result<Mesh, String> {
        let front = source::front(name, text.to_string(), &[]).unwrap();
        let g = from_front_with(front, specialise).unwrap_or_else(|e| panic!("{e}"));
        let (mesh, _) = g.mesh.clone().expect("the grammar names its mesh");
        let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("lsystems/surfaces");
        // With the sharpness its file or the `.creases` file beside it gives.
        let mut m = io::read_mesh(&dir.join(mesh)).unwrap();
        let ran = match protect {
            false => g.run(&mut m, steps, |_| {}),
            true => {
                let protection = Protection {
                    faces: (0..m.face_count()).map(|i| i % 3 == 0).collect(),
                    vertices: (0..m.vertex_count()).map(|i| i % 4 == 0).collect(),
                };
                g.start_protected(&mut m, protection)
                    .and_then(|mut r| r.steps(steps, |_| {}))
            }
        };
        ran.map(|()| m)
            .map_err(|e| format!("{name}: {}", g.render_error(&e)))
    }

    /// The fused built-ins, guards and affine assignments mean what the
    /// expressions they came from mean: every grammar in `lsystems/`,
    /// run through the interpreter alone, gives the same mesh, with
    /// positions equal to 1e-12 (the weights may multiply in another
    /// order); with parts of the mesh protected too, since what a
    /// protection leaves out must be left out by every path.
    #[test]
    fn specialisations_give_what_the_interpreter_gives() {
        let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("lsystems/surfaces");
        let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "lsys"))
            .collect();
        files.sort();
        assert!(files.len() >= 7);
        let mut cases: Vec<(String, String)> = files
            .iter()
            .map(|f| (f.display().to_string(), std::fs::read_to_string(f).unwrap()))
            .collect();
        // The crease rules, on meshes with creases (sharp, semi-sharp and
        // corners: the `Count` guards, folds over `crease_ring`).
        for (file, mesh, creased) in [
            ("catmull-clark.lsys", "cube.obj", "creased-cube.ply"),
            ("loop.lsys", "octahedron.obj", "creased-octahedron.obj"),
        ] {
            let text = std::fs::read_to_string(dir.join(file)).unwrap();
            assert!(text.contains(mesh));
            cases.push((format!("{file} on {creased}"), text.replace(mesh, creased)));
        }
        // Forms the files do not use: differences, negations, divisions,
        // weights from counts and levels, guards on edge ends and on the
        // step alone.
        cases.push((
            "forms.lsys".into(),
            "mesh: \"../meshes/octahedron.obj\";\n\
             define w(v, n) = 2*v - avg(ring(v)) / n - -(0.25*v);\n\
             F(f; step % 2 == 1 || !boundary(f)) -> V(v = avg(f) / 1) || E^3 F^3;\n\
             E(e; !new(tail(e)) && l(head(e)) < c) | F^2 -> E || F^2;\n\
             V(v; !new(v)) -> V(v = w(v, count(u in ring(v) where l(u) <= c)) / 2.5);\n"
                .into(),
        ));
        // Weights from lets that read the element but are not integers:
        // each value is its own key (cube.obj's vertices have valences 4
        // and 5, then 8 and 10).
        cases.push((
            "float-and-bool-keys.lsys".into(),
            "mesh: \"../meshes/cube.obj\";\n\
             define g(v, k) = k * v + (1 - k) * avg(ring(v));\n\
             define h(v, b) = (b ? 0.25 : 0.75) * v + (b ? 0.75 : 0.25) * avg(ring(v));\n\
             F(f) -> V(v = avg(f)) || E^3 F^3;\n\
             V(v; !new(v)) -> V(v = g(v, valence(v) / 8.0));\n\
             V(v; !new(v)) -> V(v = h(v, valence(v) > 9));\n"
                .into(),
        ));
        // Lets the weights cannot take in their own order: a call in one
        // term reusing the slot of a parameter the next term reads, and a
        // parameter that reads the element computed from one that does
        // not.
        cases.push((
            "slots-and-order.lsys".into(),
            "mesh: \"../meshes/cube.obj\";\n\
             define a(m) = m;\n\
             define f(n, v) = n * v;\n\
             define g(v) = a(2) * v - f(valence(v), v) / 8;\n\
             define h(v, n) = n * 0.01 * v;\n\
             define k(v, a) = h(v, valence(v) * a);\n\
             F(f) -> V(v = avg(f)) || E^3 F^3;\n\
             V(v; !new(v)) -> V(v = g(v));\n\
             V(v; !new(v)) -> V(v = k(v, c + 1));\n"
                .into(),
        ));
        for ((name, text), protect) in cases.iter().flat_map(|c| [(c, false), (c, true)]) {
            let (a, b) = match (
                run_protected(name, text, false, 2, protect),
                run_protected(name, text, true, 2, protect),
            ) {
                (Ok(a), Ok(b)) => (a, b),
                (Err(a), Err(b)) if protect => {
                    assert_eq!(a, b);
                    continue;
                }
                (a, b) => panic!("{name}: {:?} and {:?}", a.err(), b.err()),
            };
            assert_eq!(a.vertex_count(), b.vertex_count(), "{name}");
            assert_eq!(a.face_count(), b.face_count(), "{name}");
            let scale = a
                .vertices()
                .map(|v| a.position(v).abs().max_element())
                .fold(1.0, f64::max);
            for v in a.vertices() {
                let d = (a.position(v) - b.position(v)).abs().max_element();
                assert!(d <= 1e-12 * scale, "{name}: vertex {v} differs by {d}");
            }
        }
    }
}
