//! Recursive-descent parser from preprocessed tokens to [`ast::File`].
//!
//! Every function parses one production of the grammar, shown in its doc
//! comment. Errors say what was expected and what was found, at the token.
//!
//! - [`cursor`]: the token cursor (peeking, eating and expecting tokens,
//!   names) and the lookahead that tells a declaration
//! - [`nesting`]: how deeply the syntax tree may nest ([`MAX_NESTING`]),
//!   measured while parsing
//! - [`items`]: the items of a file: module declarations, functions,
//!   enums, directives, vv properties
//! - [`declarations`]: types, structs (members, methods, constructors),
//!   typedefs and variable declarations
//! - [`productions`]: productions: predecessors, module calls and the
//!   single-character turtle
//! - [`statements`]: blocks and statements, `switch` and its labels
//! - [`vv`]: the statements and queries of vertex-vertex programs
//! - [`expressions`]: expressions, by precedence, and argument lists
//!
//! It uses `ast`, `lex` and `span` of `syntax`; nothing above.

mod cursor;
mod declarations;
mod expressions;
mod items;
mod nesting;
mod productions;
mod statements;
mod vv;

pub use nesting::MAX_NESTING;

use std::collections::HashSet;

use super::ast::*;
use super::lex::{Tok, Token};
use super::span::{Diagnostic, Span};

/// Names that start a declaration in statement or item position.
const TYPE_KEYWORDS: &[&str] = &[
    "int", "float", "double", "bool", "V2f", "V2d", "V3f", "V3d", "long", "unsigned", "char",
    "short", "signed", "void", "FILE", "size_t",
];

/// The types a vv program adds.
const VV_TYPES: &[&str] = &["vertex", "mesh"];

/// Words that may come before a declaration's type and mean nothing here.
const QUALIFIERS: &[&str] = &[
    "static", "inline", "extern", "const", "register", "volatile",
];

pub struct Parser<'t> {
    toks: &'t [Token],
    pos: usize,
    /// Single-character turtle mode, switched on by `angle:`.
    abop: bool,
    /// Names that are never split into characters in that mode.
    whole_names: HashSet<String>,
    /// The last character of a split identifier, read in its place.
    split_last: Option<(usize, Name)>,
    /// How deeply expressions and statements are nested right now: the
    /// number of syntax-tree levels above the node being parsed.
    depth: usize,
    /// The deepest level reached since [`Parser::measure`] last started
    /// measuring. A node built around an operand parsed before it (`a +
    /// b`, `a.x`, `c ? a : b`, `a = b`) moves that operand one level down,
    /// so the operand's deepest level is what must stay under the limit.
    peak: usize,
    /// Struct, enum and typedef names seen so far.
    type_names: HashSet<String>,
    /// Declared and predefined module names: a line that starts with one
    /// is a production, not a declaration (`B P(vl) < P(v) : ...`).
    module_names: HashSet<String>,
    /// A vertex-vertex program (paper 001): `vertex` and `mesh` are types,
    /// and vv's statements and expressions are read.
    vv: bool,
    eof: Span,
}

type PResult<T> = Result<T, Diagnostic>;

impl<'t> Parser<'t> {
    /// A parser of the language's expressions over `toks`, for the parsers
    /// of other rule forms (surface grammars), which share its cursor, its
    /// messages and its expressions.
    pub(crate) fn new(toks: &'t [Token], eof: Span) -> Parser<'t> {
        Parser {
            toks,
            pos: 0,
            abop: false,
            whole_names: HashSet::new(),
            split_last: None,
            depth: 0,
            peak: 0,
            type_names: HashSet::new(),
            module_names: HashSet::new(),
            vv: false,
            eof,
        }
    }
}

/// `Shape::Circle` as one name token (an enumerator declared in a struct,
/// `Struct::Enum` as a type): no other use of `::` is part of the language.
fn scoped_names(toks: &[Token]) -> Vec<Token> {
    let mut out: Vec<Token> = Vec::with_capacity(toks.len());
    let mut k = 0;
    while k < toks.len() {
        if let (Some(Tok::Ident(a)), Some(Tok::Ident(b))) =
            (out.last().map(|t| &t.tok), toks.get(k + 1).map(|t| &t.tok))
        {
            if toks[k].tok.is_punct("::") {
                let joined = format!("{a}::{b}");
                let last = out.last_mut().expect("checked");
                last.span = last.span.to(toks[k + 1].span);
                last.tok = Tok::Ident(joined);
                k += 2;
                continue;
            }
        }
        out.push(toks[k].clone());
        k += 1;
    }
    out
}

pub fn parse_file(toks: &[Token], eof: Span, predefined: &[&str]) -> PResult<File> {
    parse_file_as(toks, eof, predefined, false)
}

/// Parses a file, as a vertex-vertex program when `vv` is set.
pub fn parse_file_as(toks: &[Token], eof: Span, predefined: &[&str], vv: bool) -> PResult<File> {
    let scoped;
    let toks = if toks.iter().any(|t| t.tok.is_punct("::")) {
        scoped = scoped_names(toks);
        &scoped[..]
    } else {
        toks
    };
    // `angle:` anywhere switches on the single-character turtle.
    let abop = toks
        .windows(2)
        .any(|w| w[0].line_start && w[0].tok.is_ident("angle") && w[1].tok.is_punct(":"));
    let mut whole_names: HashSet<String> = predefined.iter().map(|s| s.to_string()).collect();
    for w in toks.windows(2) {
        if let (Tok::Ident(m), Tok::Ident(n)) = (&w[0].tok, &w[1].tok) {
            if m == "module" {
                whole_names.insert(n.clone());
            }
        }
    }
    let module_names = whole_names.clone();
    let mut p = Parser {
        toks,
        pos: 0,
        abop,
        whole_names,
        module_names,
        split_last: None,
        depth: 0,
        peak: 0,
        type_names: if vv {
            VV_TYPES.iter().map(|s| s.to_string()).collect()
        } else {
            HashSet::new()
        },
        vv,
        eof,
    };
    let mut items = Vec::new();
    while !p.at_end() {
        p.item(&mut items)?;
    }
    Ok(File { items, abop })
}
