//! `subgram check`: every diagnostic of a file, or one line that says what it holds.

use super::common::load_options;
use crate::error::Error;
use crate::load::load;
use crate::system::System;

/// `subgram check FILE [-D NAME=VALUE]…`: reports every diagnostic, or one
/// line that says what the file holds.
pub fn check(file: &str, defines: &[String], double: bool) -> Result<String, Error> {
    let opts = load_options(defines, double, &Default::default());
    let system = load(file, &opts)?;
    let ok = match &system {
        System::Surface(s) => format!(
            "{file}: ok (a surface grammar of {})",
            counted(s.grammar.rules.len(), "rule", "rules")
        ),
        System::Curve(c) => {
            use crate::syntax::ast::Section;
            let p = &c.program;
            let of = |s: Section| p.rules.iter().filter(|r| r.section == s).count();
            let mut parts = vec![counted(
                of(Section::Productions),
                "production",
                "productions",
            )];
            for (s, one, many) in [
                (
                    Section::Decomposition,
                    "decomposition rule",
                    "decomposition rules",
                ),
                (
                    Section::Interpretation,
                    "interpretation rule",
                    "interpretation rules",
                ),
            ] {
                if of(s) > 0 {
                    parts.push(counted(of(s), one, many));
                }
            }
            // The program's own modules: those it declares, or, in the
            // single-character notation, those its rules and axiom name;
            // not lpfg's predefined ones.
            let own = p.alphabet.kinds.iter().filter(|k| !k.builtin).count();
            parts.push(counted(own, "module of its own", "modules of its own"));
            format!("{file}: ok ({})", parts.join(", "))
        }
        System::Vv(v) => format!(
            "{file}: ok (a vv program of {})",
            counted(v.program.program.functions.len(), "function", "functions")
        ),
        System::Shapes(s) => format!(
            "{file}: ok (a shape grammar of {})",
            counted(s.rules(), "rule", "rules")
        ),
    };
    // Warnings first, each with its line and caret, then the verdict.
    let mut out: Vec<String> = system.warnings();
    out.push(ok);
    Ok(out.join("\n\n"))
}

/// `1 rule`, `2 rules`.
fn counted(n: usize, one: &str, many: &str) -> String {
    format!("{n} {}", if n == 1 { one } else { many })
}
