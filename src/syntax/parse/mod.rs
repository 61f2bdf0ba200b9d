//! Recursive-descent parser from preprocessed tokens to [`ast::File`].
//!
//! Every function parses one production of the grammar, shown in its doc
//! comment. Errors say what was expected and what was found, at the token.

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

/// How deeply expressions and statements may nest: the height of the
/// syntax tree, counting every level that the checker and the interpreter
/// recurse through (an operator, a call, a field, a cast, a parenthesis, a
/// statement, a block). Deeper programs are refused with a message rather
/// than overflowing the stack later; a chain that the grammar nests
/// (`a = b = c`, `x ? y : x ? y : z`, `a + b + c`, `v.x.y`) counts one
/// level per link.
pub const MAX_NESTING: usize = 100;

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

impl<'t> Parser<'t> {
    pub(crate) fn at_end(&self) -> bool {
        self.pos >= self.toks.len()
    }

    pub(crate) fn peek(&self) -> Option<&'t Token> {
        self.toks.get(self.pos)
    }

    pub(crate) fn peek_at(&self, k: usize) -> Option<&'t Token> {
        self.toks.get(self.pos + k)
    }

    pub(crate) fn peek_punct(&self, p: &str) -> bool {
        self.peek().is_some_and(|t| t.tok.is_punct(p))
    }

    pub(crate) fn peek_ident(&self, s: &str) -> bool {
        self.peek().is_some_and(|t| t.tok.is_ident(s))
    }

    pub(crate) fn span_here(&self) -> Span {
        self.peek().map(|t| t.span).unwrap_or(self.eof)
    }

    pub(crate) fn prev_span(&self) -> Span {
        self.pos
            .checked_sub(1)
            .and_then(|i| self.toks.get(i))
            .map(|t| t.span)
            .unwrap_or(self.eof)
    }

    pub(crate) fn bump(&mut self) -> &'t Token {
        let t = &self.toks[self.pos];
        self.pos += 1;
        t
    }

    pub(crate) fn found(&self) -> String {
        match self.peek() {
            Some(t) => t.tok.describe(),
            None => "the end of the file".to_string(),
        }
    }

    pub(crate) fn error<T>(&self, expected: &str) -> PResult<T> {
        Err(Diagnostic::new(
            self.span_here(),
            format!("expected {expected}, found {}", self.found()),
        ))
    }

    pub(crate) fn eat_punct(&mut self, p: &str) -> bool {
        if self.peek_punct(p) {
            self.pos += 1;
            true
        } else {
            false
        }
    }

    pub(crate) fn expect_punct(&mut self, p: &str, what: &str) -> PResult<Span> {
        if self.peek_punct(p) {
            Ok(self.bump().span)
        } else {
            self.error(&format!("`{p}` {what}"))
        }
    }

    pub(crate) fn name(&mut self, what: &str) -> PResult<Name> {
        if let Some((at, last)) = self.split_last.take() {
            if at == self.pos {
                self.pos += 1;
                return Ok(last);
            }
        }
        match self.peek() {
            Some(Token {
                tok: Tok::Ident(s),
                span,
                ..
            }) => {
                self.pos += 1;
                Ok(Name {
                    text: s.clone(),
                    span: *span,
                })
            }
            _ => self.error(what),
        }
    }

    fn is_type_name(&self, s: &str) -> bool {
        TYPE_KEYWORDS.contains(&s) || self.type_names.contains(s)
    }

    /// True when `propensity` at the cursor starts a Gillespie statement,
    /// not an expression about a variable of that name.
    fn at_propensity(&self) -> bool {
        !self.peek_at(1).is_some_and(|t| {
            ["=", "+=", "-=", "*=", "/=", "++", "--", ".", "[", ";", ","]
                .iter()
                .any(|p| t.tok.is_punct(p))
        })
    }

    /// True when the tokens at the cursor begin a declaration:
    /// `const ...`, `static ...`, `struct Name ...`, `TYPE name`, `TYPE
    /// *name`, or `Name name` (unless `Name` is a module: a production).
    fn at_declaration(&self) -> bool {
        match (self.peek().map(|t| &t.tok), self.peek_at(1).map(|t| &t.tok)) {
            (Some(Tok::Ident(a)), _) if QUALIFIERS.contains(&a.as_str()) => true,
            (Some(Tok::Ident(a)), Some(Tok::Ident(_))) => {
                !matches!(
                    a.as_str(),
                    "produce"
                        | "nproduce"
                        | "return"
                        | "else"
                        | "if"
                        | "while"
                        | "do"
                        | "propensity"
                ) && (self.is_type_name(a) || !self.module_names.contains(a))
            }
            (Some(Tok::Ident(a)), Some(Tok::Punct("*" | "&"))) => {
                self.is_type_name(a)
                    && self
                        .peek_at(2)
                        .is_some_and(|t| matches!(t.tok, Tok::Ident(_)))
            }
            _ => false,
        }
    }

    // ----- items -------------------------------------------------------

    /// item := module-decl | struct-decl | typedef | global-decl | directive
    ///       | axiom | ignore | consider | section | group | control | production
    fn item(&mut self, items: &mut Vec<Item>) -> PResult<()> {
        if self.eat_punct(";") {
            return Ok(()); // a stray `;` between items
        }
        let t = self.peek().expect("not at end");
        let start = t.span;
        if let Tok::Ident(word) = &t.tok {
            let next_colon = self.peek_at(1).is_some_and(|n| n.tok.is_punct(":"));
            match word.as_str() {
                "module" => return self.module_decl(items),
                "struct" | "class" if self.peek_at(2).is_some_and(|n| n.tok.is_punct("{")) => {
                    return self.struct_decl(items)
                }
                "typedef" => return self.typedef(items),
                "derivation" if self.peek_at(1).is_some_and(|n| n.tok.is_ident("length")) => {
                    self.pos += 2;
                    return self.directive(items, DirectiveKind::DerivationLength, start);
                }
                "angle" if next_colon => {
                    self.pos += 1;
                    return self.directive(items, DirectiveKind::Angle, start);
                }
                "maximum" if self.peek_at(1).is_some_and(|n| n.tok.is_ident("depth")) => {
                    self.pos += 2;
                    return self.directive(items, DirectiveKind::MaximumDepth, start);
                }
                "ring" if self.peek_at(1).is_some_and(|n| n.tok.is_ident("L")) => {
                    // ring L-system: expr;
                    self.pos += 2;
                    self.expect_punct("-", "in `ring L-system:`")?;
                    if !self.peek_ident("system") {
                        return self.error("`system` in `ring L-system:`");
                    }
                    self.pos += 1;
                    return self.directive(items, DirectiveKind::Ring, start);
                }
                "Axiom" | "axiom" if next_colon => {
                    self.pos += 2;
                    let mut modules = Vec::new();
                    while !self.eat_punct(";") {
                        if !self.at_module() {
                            return self.error("a module or the `;` that ends the axiom");
                        }
                        self.module_call_into(&mut modules)?;
                    }
                    items.push(Item::Axiom {
                        modules,
                        span: start,
                    });
                    return Ok(());
                }
                "ignore" | "consider" if next_colon => {
                    self.pos += 2;
                    let mut names = Vec::new();
                    while !self.peek_punct(";") {
                        if self.at_end() {
                            return self.error("`;` after the module list");
                        }
                        if self.peek_punct("#") {
                            let t = self.bump();
                            names.push(Name {
                                text: "#".into(),
                                span: t.span,
                            });
                        } else {
                            names.push(self.name("a module name")?);
                        }
                    }
                    self.pos += 1;
                    items.push(Item::ContextFilter {
                        consider: word == "consider",
                        names,
                        span: start,
                    });
                    return Ok(());
                }
                "production" | "productions" | "decomposition" | "interpretation" if next_colon => {
                    self.pos += 2;
                    let section = match word.as_str() {
                        "decomposition" => Section::Decomposition,
                        "interpretation" => Section::Interpretation,
                        _ => Section::Productions,
                    };
                    items.push(Item::Section {
                        section,
                        span: start,
                    });
                    return Ok(());
                }
                "group" | "ggroup" => {
                    let gillespie = word == "ggroup";
                    self.pos += 1;
                    let id = match self.peek().map(|t| &t.tok) {
                        Some(Tok::Int(i)) => *i,
                        _ => return self.error("a group number (an integer constant)"),
                    };
                    self.pos += 1;
                    self.expect_punct(":", "after the group number")?;
                    items.push(Item::Group {
                        id,
                        gillespie,
                        span: start,
                    });
                    return Ok(());
                }
                // `window N:` as lpfg's translator reads it; `window` alone
                // may be a name.
                "vgroup" | "window"
                    if word == "vgroup"
                        || (matches!(self.peek_at(1).map(|t| &t.tok), Some(Tok::Int(_)))
                            && self.peek_at(2).is_some_and(|t| t.tok.is_punct(":"))) =>
                {
                    self.pos += 1;
                    let id = match self.peek().map(|t| &t.tok) {
                        Some(Tok::Int(i)) => *i,
                        _ => {
                            return self.error(
                                "a view number (an integer constant, or a view name from the view file)",
                            )
                        }
                    };
                    self.pos += 1;
                    self.expect_punct(":", "after the view number")?;
                    items.push(Item::VGroup { id, span: start });
                    return Ok(());
                }
                "endvgroup" | "endwindow" => {
                    self.pos += 1;
                    self.eat_punct(":");
                    self.eat_punct(";");
                    items.push(Item::VGroup { id: 0, span: start });
                    return Ok(());
                }
                "endgroup" => {
                    self.pos += 1;
                    self.eat_punct(":");
                    self.eat_punct(";");
                    items.push(Item::Group {
                        id: 0,
                        gillespie: false,
                        span: start,
                    });
                    return Ok(());
                }
                "Start" | "StartEach" | "EndEach" | "End" | "Step"
                    if next_colon && (word != "Step" || self.vv) =>
                {
                    self.pos += 2;
                    let kind = match word.as_str() {
                        "Start" => ControlKind::Start,
                        "StartEach" => ControlKind::StartEach,
                        "EndEach" => ControlKind::EndEach,
                        "Step" => ControlKind::Step,
                        _ => ControlKind::End,
                    };
                    let body = self.block()?;
                    self.eat_punct(";");
                    items.push(Item::Control {
                        kind,
                        body,
                        span: start,
                    });
                    return Ok(());
                }
                "vertex" | "edge" | "mesh"
                    if self.vv
                        && self.peek_at(1).is_some_and(|t| match &t.tok {
                            Tok::Ident(n) => self.is_type_name(n),
                            _ => false,
                        }) =>
                {
                    return self.property(items);
                }
                _ => {}
            }
            if word == "enum"
                && (self.peek_at(1).is_some_and(|t| t.tok.is_punct("{"))
                    || self.peek_at(2).is_some_and(|t| t.tok.is_punct("{")))
            {
                return self.enum_decl(items);
            }
            if self.at_declaration() {
                if let Some(k) = self.function_ahead() {
                    return self.function(items, k);
                }
                let decl = self.var_decl()?;
                self.expect_punct(";", "after the declaration")?;
                items.push(Item::Global(decl));
                return Ok(());
            }
        }
        let prod = self.production()?;
        items.push(Item::Production(prod));
        Ok(())
    }

    /// property := ('vertex' | 'edge' | 'mesh') TYPE NAME [ '=' expr ] ';'
    fn property(&mut self, items: &mut Vec<Item>) -> PResult<()> {
        let owner = self.name("vertex, edge or mesh")?;
        let ty = self.type_ref()?;
        let name = self.name("the property's name")?;
        let init = if self.eat_punct("=") {
            Some(self.expr()?)
        } else {
            None
        };
        self.expect_punct(";", "after the property")?;
        items.push(Item::Property {
            owner,
            ty,
            name,
            init,
        });
        Ok(())
    }

    /// When the tokens at the cursor begin a function definition or
    /// declaration (`float f(float x) {`, `static inline V2f g(V2f);`,
    /// `void h();`), the offset of its name. `V2f v(0, 1);` is a variable.
    fn function_ahead(&self) -> Option<usize> {
        let mut k = 0;
        while self.peek_at(k).is_some_and(|t| {
            QUALIFIERS.iter().any(|q| t.tok.is_ident(q))
                || t.tok.is_ident("struct")
                || t.tok.is_ident("enum")
        }) {
            k += 1;
        }
        // The type: one or more words (`unsigned int`), then `*`s, then
        // the name.
        let is_ident = |k: usize| {
            self.peek_at(k)
                .is_some_and(|t| matches!(t.tok, Tok::Ident(_)))
        };
        let mut words = 0;
        while is_ident(k) {
            k += 1;
            words += 1;
        }
        let mut stars = 0;
        while self
            .peek_at(k)
            .is_some_and(|t| t.tok.is_punct("*") || t.tok.is_punct("&"))
        {
            k += 1;
            stars += 1;
        }
        let name = if stars > 0 && words >= 1 && is_ident(k) {
            k
        } else if stars == 0 && words >= 2 {
            k - 1
        } else {
            return None;
        };
        if !self.peek_at(name + 1).is_some_and(|t| t.tok.is_punct("(")) {
            return None;
        }
        // After the parenthesised list: `{` (a body), or `;` when the list
        // is empty or starts with a type (a declaration).
        let mut depth = 0;
        let mut j = self.pos + name + 1;
        while let Some(t) = self.toks.get(j) {
            if t.tok.is_punct("(") {
                depth += 1;
            } else if t.tok.is_punct(")") {
                depth -= 1;
                if depth == 0 {
                    let next = self.toks.get(j + 1);
                    if next.is_some_and(|t| t.tok.is_punct("{")) {
                        return Some(name);
                    }
                    let first = self.toks.get(self.pos + name + 2).map(|t| &t.tok);
                    let typed = match first {
                        Some(Tok::Punct(")")) => true,
                        Some(Tok::Ident(w)) => {
                            self.is_type_name(w) || w == "const" || w == "struct"
                        }
                        _ => false,
                    };
                    return (typed && next.is_some_and(|t| t.tok.is_punct(";"))).then_some(name);
                }
            }
            j += 1;
        }
        None
    }

    /// function := QUALIFIERS TYPE NAME '(' [param {',' param}] ')' ( block | ';' )
    /// param := TYPE [NAME] { '[' [expr] ']' }
    fn function(&mut self, items: &mut Vec<Item>, name_at: usize) -> PResult<()> {
        let end = self.pos + name_at;
        while self
            .peek()
            .is_some_and(|t| QUALIFIERS.iter().any(|q| t.tok.is_ident(q)))
        {
            self.pos += 1;
        }
        let ret = self.type_ref()?;
        if self.pos != end {
            return self.error("the function's name");
        }
        let name = self.name("the function's name")?;
        self.expect_punct("(", "after the function's name")?;
        let params = self.params()?;
        let body = if self.eat_punct(";") {
            None
        } else {
            Some(self.block()?)
        };
        items.push(Item::Function(FunctionDef {
            ret,
            name,
            params,
            body,
        }));
        Ok(())
    }

    /// params := ( 'void' | [param {',' param}] ) ')'   (the `(` is consumed)
    fn params(&mut self) -> PResult<Vec<Param>> {
        let mut params = Vec::new();
        if self.peek_ident("void") && self.peek_at(1).is_some_and(|t| t.tok.is_punct(")")) {
            self.pos += 1;
        }
        if !self.eat_punct(")") {
            loop {
                let start = self.pos;
                let ty = self.type_ref()?;
                let is_const = self.toks[start..self.pos]
                    .iter()
                    .any(|t| t.tok.is_ident("const"));
                let pname = match self.peek().map(|t| &t.tok) {
                    Some(Tok::Ident(_)) => Some(self.name("a parameter name")?),
                    _ => None,
                };
                let dims = self.dims()?;
                params.push(Param {
                    ty,
                    name: pname,
                    dims,
                    is_const,
                });
                if self.eat_punct(")") {
                    break;
                }
                self.expect_punct(",", "or `)` between the function's parameters")?;
            }
        }
        Ok(params)
    }

    /// dims := { '[' [expr] ']' }
    fn dims(&mut self) -> PResult<Vec<Option<Expr>>> {
        let mut dims = Vec::new();
        while self.eat_punct("[") {
            if self.eat_punct("]") {
                dims.push(None);
            } else {
                dims.push(Some(self.expr()?));
                self.expect_punct("]", "to close the array size")?;
            }
        }
        Ok(dims)
    }

    /// enum-decl := 'enum' [NAME] '{' NAME ['=' expr] {',' NAME ['=' expr]} [','] '}' ';'
    fn enum_decl(&mut self, items: &mut Vec<Item>) -> PResult<()> {
        self.enum_body(items)?;
        self.expect_punct(";", "after the enum declaration")?;
        Ok(())
    }

    /// 'enum' [NAME] '{' NAME ['=' expr] {',' NAME ['=' expr]} [','] '}'
    fn enum_body(&mut self, items: &mut Vec<Item>) -> PResult<()> {
        let (name, variants) = self.enum_parts()?;
        items.push(Item::Enum { name, variants });
        Ok(())
    }

    /// The name and the enumerators of an enum's body, from `enum`.
    #[allow(clippy::type_complexity)]
    fn enum_parts(&mut self) -> PResult<(Option<Name>, Vec<(Name, Option<Expr>)>)> {
        self.pos += 1;
        let name = if self.peek_punct("{") {
            None
        } else {
            let n = self.name("the enum's name")?;
            self.type_names.insert(n.text.clone());
            Some(n)
        };
        self.expect_punct("{", "to open the enum")?;
        let mut variants = Vec::new();
        while !self.eat_punct("}") {
            let v = self.name("an enumerator name or `}`")?;
            let value = if self.eat_punct("=") {
                Some(self.cond_expr()?)
            } else {
                None
            };
            variants.push((v, value));
            if !self.eat_punct(",") {
                self.expect_punct("}", "or `,` after the enumerator")?;
                break;
            }
        }
        Ok((name, variants))
    }

    /// directive := KEY ':' expr ';'
    fn directive(&mut self, items: &mut Vec<Item>, kind: DirectiveKind, span: Span) -> PResult<()> {
        self.expect_punct(":", "after the directive name")?;
        let expr = self.expr()?;
        self.expect_punct(";", "after the directive's value")?;
        items.push(Item::Directive {
            kind,
            expr,
            span: span.to(self.prev_span()),
        });
        Ok(())
    }

    /// module-decl := 'module' NAME [ '(' TYPE {',' TYPE} ')' ] ';'   e.g. `module P(V2f);`
    fn module_decl(&mut self, items: &mut Vec<Item>) -> PResult<()> {
        self.pos += 1;
        loop {
            let name = self.name("a module name after `module`")?;
            let mut params = Vec::new();
            if self.eat_punct("(") && !self.eat_punct(")") {
                {
                    loop {
                        params.push(self.type_ref()?);
                        // `module A(int /*id*/)` is fine; `module A(int id)` is not.
                        if let Some(Token {
                            tok: Tok::Ident(n),
                            span,
                            ..
                        }) = self.peek()
                        {
                            return Err(Diagnostic::new(
                                *span,
                                format!("module parameters have types but no names: remove `{n}`"),
                            ));
                        }
                        if self.eat_punct(")") {
                            break;
                        }
                        self.expect_punct(",", "or `)` in the module's parameter types")?;
                    }
                }
            }
            items.push(Item::Module { name, params });
            if !self.eat_punct(",") {
                break;
            }
        }
        self.expect_punct(";", "after the module declaration")?;
        Ok(())
    }

    fn type_ref(&mut self) -> PResult<TypeRef> {
        while self.eat_ident("const") || self.eat_ident("volatile") {}
        if !self.eat_ident("struct") {
            self.eat_ident("enum");
        }
        let n = self.name("a type name")?;
        let mut name = n.text;
        // `unsigned int`, `long long`, `unsigned char`, `long double`: the
        // last word decides (`unsigned` and `signed` alone are ints).
        while matches!(name.as_str(), "unsigned" | "signed" | "long" | "short")
            && self.peek().is_some_and(|t| {
                ["int", "long", "short", "char", "double"]
                    .iter()
                    .any(|w| t.tok.is_ident(w))
            })
        {
            name = self.name("a type name")?.text;
        }
        self.eat_ident("const");
        let (mut pointer, mut reference) = (false, false);
        loop {
            if self.eat_punct("*") {
                pointer = true;
            } else if self.eat_punct("&") {
                reference = true;
            } else {
                break;
            }
            self.eat_ident("const");
        }
        Ok(TypeRef {
            name,
            span: n.span,
            pointer,
            reference,
        })
    }

    pub(crate) fn eat_ident(&mut self, s: &str) -> bool {
        if self.peek_ident(s) {
            self.pos += 1;
            true
        } else {
            false
        }
    }

    /// struct-decl := 'struct' NAME struct-body ';'
    fn struct_decl(&mut self, items: &mut Vec<Item>) -> PResult<()> {
        self.pos += 1;
        let name = self.name("a struct name")?;
        self.type_names.insert(name.text.clone());
        let body = self.struct_body(Some(&name.text))?;
        self.expect_punct(";", "after the struct declaration")?;
        items.push(Item::Struct { name, body });
        Ok(())
    }

    /// struct-body := '{' { member } '}'
    /// member := TYPE NAME dims {',' NAME dims} ';'
    ///         | 'enum' [NAME] '{' ... '}' [NAME {',' NAME}] ';'
    ///         | NAME '(' params ')' [':' NAME '(' args ')' {',' ...}] block   (a constructor)
    ///         | TYPE NAME '(' params ')' ['const'] block   (a method)
    ///         | ('public' | 'private' | 'protected') ':'
    fn struct_body(&mut self, struct_name: Option<&str>) -> PResult<StructBody> {
        self.expect_punct("{", "to open the struct body")?;
        let mut body = StructBody::default();
        while !self.eat_punct("}") {
            if self.at_end() {
                return self.error("`}` to close the struct");
            }
            if ["public", "private", "protected"]
                .iter()
                .any(|w| self.peek_ident(w))
                && self.peek_at(1).is_some_and(|t| t.tok.is_punct(":"))
            {
                self.pos += 2;
                continue;
            }
            if self.peek_punct("~") {
                return Err(Diagnostic::new(
                    self.span_here(),
                    "destructors are not supported: a struct here is a plain value",
                ));
            }
            let is_ctor = struct_name.is_some_and(|n| self.peek_ident(n))
                && self.peek_at(1).is_some_and(|t| t.tok.is_punct("("));
            if is_ctor {
                body.ctors.push(self.constructor()?);
                continue;
            }
            let ty = if self.peek_ident("enum")
                && (self.peek_at(1).is_some_and(|t| t.tok.is_punct("{"))
                    || self.peek_at(2).is_some_and(|t| t.tok.is_punct("{")))
            {
                let (name, variants) = self.enum_parts()?;
                let ty = TypeRef {
                    name: name.as_ref().map_or("int", |n| &n.text).to_string(),
                    span: name.as_ref().map_or(self.prev_span(), |n| n.span),
                    pointer: false,
                    reference: false,
                };
                body.enums.push((name, variants));
                if self.eat_punct(";") {
                    continue;
                }
                ty
            } else {
                self.type_ref()?
            };
            if self.peek_at(1).is_some_and(|t| t.tok.is_punct("(")) {
                body.methods.push(self.method(ty)?);
                continue;
            }
            loop {
                let f = self.name("a field name")?;
                let dims = self.dims()?;
                body.fields.push((ty.clone(), f, dims));
                if !self.eat_punct(",") {
                    break;
                }
            }
            self.expect_punct(";", "after the field declaration")?;
        }
        Ok(body)
    }

    /// method := TYPE NAME '(' params ')' ['const'] block   (the type is read)
    fn method(&mut self, ret: TypeRef) -> PResult<FunctionDef> {
        let name = self.name("the method's name")?;
        self.pos += 1;
        let params = self.params()?;
        self.eat_ident("const");
        if !self.peek_punct("{") {
            return Err(Diagnostic::new(
                self.span_here(),
                format!(
                    "expected the body of method `{}` here: methods are defined inside their struct",
                    name.text
                ),
            ));
        }
        let body = self.block()?;
        self.eat_punct(";");
        Ok(FunctionDef {
            ret,
            name,
            params,
            body: Some(body),
        })
    }

    /// constructor := NAME '(' params ')' [':' NAME '(' args ')' {',' NAME '(' args ')'}] block
    fn constructor(&mut self) -> PResult<Ctor> {
        let name = self.name("the constructor's name")?;
        self.pos += 1;
        let params = self.params()?;
        let mut inits = Vec::new();
        if self.eat_punct(":") {
            loop {
                let field = self.name("a field to initialise")?;
                self.expect_punct("(", "after the field's name in the initialiser list")?;
                let open = self.prev_span();
                let args = self.args(")")?;
                inits.push((field, args, open.to(self.prev_span())));
                if !self.eat_punct(",") {
                    break;
                }
            }
        }
        if self.peek_punct(";") {
            return Err(Diagnostic::new(
                self.span_here(),
                "a constructor needs its body here, e.g. `{}`: declarations of constructors defined elsewhere are not supported",
            ));
        }
        let body = self.block()?;
        self.eat_punct(";");
        Ok(Ctor {
            name,
            params,
            inits,
            body,
        })
    }

    /// typedef := 'typedef' TYPE NAME ';'
    fn typedef(&mut self, items: &mut Vec<Item>) -> PResult<()> {
        self.pos += 1;
        let braces_at = |k: usize| self.peek_at(k).is_some_and(|t| t.tok.is_punct("{"));
        if (self.peek_ident("struct") || self.peek_ident("enum")) && (braces_at(1) || braces_at(2))
        {
            return self.typedef_of_a_body(items);
        }
        let ty = self.type_ref()?;
        let name = self.name("the new type name")?;
        self.type_names.insert(name.text.clone());
        self.expect_punct(";", "after the typedef")?;
        items.push(Item::Typedef { ty, name });
        Ok(())
    }

    /// typedef := 'typedef' ('struct' | 'enum') [TAG] BODY NAME ';'  — C's
    /// way to name a struct or an enum: both names name the type.
    fn typedef_of_a_body(&mut self, items: &mut Vec<Item>) -> PResult<()> {
        let is_struct = self.bump().tok.is_ident("struct");
        let tag = if self.peek_punct("{") {
            None
        } else {
            Some(self.name("a struct or enum name")?)
        };
        if is_struct {
            if let Some(t) = &tag {
                self.type_names.insert(t.text.clone());
            }
            let body = self.struct_body(tag.as_ref().map(|t| t.text.as_str()))?;
            let name = self.name("the new type name")?;
            self.type_names.insert(name.text.clone());
            self.expect_punct(";", "after the typedef")?;
            items.push(Item::Struct {
                name: name.clone(),
                body,
            });
            if let Some(tag) = tag {
                if tag.text != name.text {
                    let span = name.span;
                    items.push(Item::Typedef {
                        ty: TypeRef {
                            name: name.text,
                            span,
                            pointer: false,
                            reference: false,
                        },
                        name: tag,
                    });
                }
            }
            return Ok(());
        }
        // An enum: its body, then the name of the type.
        let mut body = Vec::new();
        // Back to `enum`, which `enum_body` reads again.
        self.pos -= 1 + usize::from(tag.is_some());
        self.enum_body(&mut body)?;
        let name = self.name("the new type name")?;
        self.type_names.insert(name.text.clone());
        self.expect_punct(";", "after the typedef")?;
        if let Some(Item::Enum { variants, .. }) = body.pop() {
            items.push(Item::Enum {
                name: Some(name),
                variants,
            });
        }
        Ok(())
    }

    /// var-decl := {QUALIFIER} TYPE declarator {',' declarator}
    /// declarator := ['*'] NAME { '[' [expr] ']' } [ '(' args ')' | '=' expr | '=' init-list ]
    fn var_decl(&mut self) -> PResult<VarDecl> {
        let (mut is_const, mut is_static) = (false, false);
        while let Some(q) = self
            .peek()
            .and_then(|t| QUALIFIERS.iter().find(|q| t.tok.is_ident(q)))
        {
            self.pos += 1;
            is_const |= *q == "const";
            is_static |= *q == "static";
        }
        let type_start = self.pos;
        let ty = self.type_ref()?;
        is_const |= self.toks[type_start..self.pos]
            .iter()
            .any(|t| t.tok.is_ident("const"));
        let mut vars = Vec::new();
        loop {
            let mut pointer = false;
            while self.eat_punct("*") {
                pointer = true;
            }
            let name = self.name("a variable name")?;
            let dims = self.dims()?;
            let init = if self.peek_punct("(") {
                let open = self.bump().span;
                let args = self.args(")")?;
                Init::Ctor(args, open.to(self.prev_span()))
            } else if self.eat_punct("=") {
                if self.peek_punct("{") {
                    let open = self.bump().span;
                    let args = self.init_list()?;
                    Init::List(args, open.to(self.prev_span()))
                } else {
                    Init::Expr(self.assign_expr()?)
                }
            } else {
                Init::None
            };
            vars.push(Declarator {
                name,
                dims,
                pointer,
                init,
            });
            if !self.eat_punct(",") {
                break;
            }
        }
        Ok(VarDecl {
            ty,
            is_const,
            is_static,
            vars,
        })
    }

    /// init-list := [ item {',' item} [','] ] '}'   (the `{` is consumed)
    /// item := expr | '{' init-list
    fn init_list(&mut self) -> PResult<Vec<Expr>> {
        let mut out = Vec::new();
        loop {
            if self.eat_punct("}") {
                return Ok(out);
            }
            if self.peek_punct("{") {
                let open = self.bump().span;
                self.descend()?;
                let inner = self.init_list();
                self.ascend();
                out.push(Expr {
                    kind: ExprKind::List(inner?),
                    span: open.to(self.prev_span()),
                });
            } else {
                out.push(self.assign_expr()?);
            }
            if !self.eat_punct(",") {
                self.expect_punct("}", "or `,` in the initializer list")?;
                return Ok(out);
            }
        }
    }

    /// args := [ expr {',' expr} ] CLOSE   (the opening bracket is consumed)
    fn args(&mut self, close: &str) -> PResult<Vec<Expr>> {
        let mut args = Vec::new();
        if self.eat_punct(close) {
            return Ok(args);
        }
        loop {
            args.push(self.assign_expr()?);
            if self.eat_punct(close) {
                return Ok(args);
            }
            if !self.peek_punct(",") {
                return self.error(&format!("`,` or `{close}` in the argument list"));
            }
            self.pos += 1;
        }
    }

    // ----- productions --------------------------------------------------

    /// production := predecessor ( ':' block | '->' successor )
    /// predecessor := [pats '<<'] [pats '<'] pats ['>' pats] ['>>' pats]
    ///
    /// e.g. `P(vl) < P(v) > P(vr) : { produce ...; }`
    fn production(&mut self) -> PResult<Production> {
        let start = self.span_here();
        let mut groups: Vec<Vec<PatModule>> = vec![Vec::new()];
        let mut seps: Vec<(&'static str, Span)> = Vec::new();
        loop {
            let Some(t) = self.peek() else {
                return self.error("`:` after the production's predecessor");
            };
            match &t.tok {
                Tok::Punct(p @ ("<" | ">" | "<<" | ">>")) => {
                    seps.push((p, t.span));
                    groups.push(Vec::new());
                    self.pos += 1;
                }
                Tok::Punct(":") | Tok::Punct("->") => break,
                Tok::Ident(_) | Tok::Punct("#") => {
                    let group = groups.last_mut().expect("non-empty");
                    if let Some(names) = self.abop_split() {
                        group.extend(names.into_iter().map(|name| PatModule {
                            name,
                            params: Vec::new(),
                        }));
                    }
                    let m = self.pat_module()?;
                    groups.last_mut().expect("non-empty").push(m);
                }
                Tok::Punct(p) if self.abop && abop_punct(p).is_some() => {
                    let span = t.span;
                    self.pos += 1;
                    for n in abop_punct(p).expect("checked") {
                        groups.last_mut().expect("non-empty").push(PatModule {
                            name: Name {
                                text: n.to_string(),
                                span,
                            },
                            params: Vec::new(),
                        });
                    }
                }
                _ => {
                    return self.error(
                        "a module, `<`, `>`, `<<`, `>>` or `:` in the production's predecessor",
                    )
                }
            }
        }
        let pred_span = start.to(self.prev_span());
        let mut prod = Production {
            new_left: Vec::new(),
            left: Vec::new(),
            strict: Vec::new(),
            right: Vec::new(),
            new_right: Vec::new(),
            body: Body::Arrow(Vec::new(), pred_span),
            span: pred_span,
        };
        // Assign the groups by their separators, in the fixed order
        // new-left << left < strict > right >> new-right.
        let order = ["<<", "<", "", ">", ">>"];
        let mut slot = 0; // index into order of the current group
        let mut groups = groups.into_iter();
        let mut current = groups.next().expect("one group");
        // The first group is strict unless a `<<` or `<` follows it.
        let first_sep = seps.first().map(|s| s.0);
        slot = match first_sep {
            Some("<<") => 0,
            Some("<") => 1,
            _ => 2,
        }
        .max(slot);
        for (i, (sep, span)) in seps.iter().enumerate() {
            let target = match slot {
                0 => &mut prod.new_left,
                1 => &mut prod.left,
                2 => &mut prod.strict,
                3 => &mut prod.right,
                _ => &mut prod.new_right,
            };
            *target = std::mem::take(&mut current);
            current = groups.next().expect("one group per separator");
            let next_slot = match *sep {
                "<<" => 1,
                "<" => 2,
                ">" => 3,
                ">>" => 4,
                _ => unreachable!(),
            };
            // After `<<`, the next group is left context only if a `<` follows.
            let next_slot = if *sep == "<<" && seps.get(i + 1).map(|s| s.0) != Some("<") {
                2
            } else {
                next_slot
            };
            if next_slot <= slot || (slot < 2 && next_slot > 2) {
                return Err(Diagnostic::new(
                    *span,
                    format!(
                        "unexpected `{sep}`: the predecessor must read `new-left << left < strict > right >> new-right`, each part optional but the strict predecessor"
                    ),
                ));
            }
            slot = next_slot;
        }
        let _ = order;
        let target = match slot {
            0 => &mut prod.new_left,
            1 => &mut prod.left,
            2 => &mut prod.strict,
            3 => &mut prod.right,
            _ => &mut prod.new_right,
        };
        *target = current;
        if prod.strict.is_empty() {
            return Err(Diagnostic::new(
                pred_span,
                "expected a strict predecessor: at least one module between the contexts",
            ));
        }
        if self.eat_punct("->") {
            let arrow = self.prev_span();
            let line_end = self.line_end();
            let succ = self.module_calls_until(line_end)?;
            self.eat_punct(";");
            prod.body = Body::Arrow(succ, arrow);
        } else {
            self.expect_punct(":", "after the predecessor")?;
            if self.peek_punct("{") {
                prod.body = Body::Block(self.block()?);
                self.eat_punct(";");
            } else {
                // `A(t) : produce A(t+1);`: one statement as the body.
                let start = self.span_here();
                let s = self.stmt_or_end()?;
                prod.body = Body::Block(Block {
                    stmts: vec![s],
                    span: start.to(self.prev_span()),
                });
            }
        }
        Ok(prod)
    }

    /// The index of the first token after the current line, at paren depth 0.
    fn line_end(&self) -> usize {
        let mut j = self.pos;
        let mut depth = 0i32;
        while let Some(t) = self.toks.get(j) {
            if j > self.pos && t.line_start && depth == 0 {
                break;
            }
            if t.tok.is_punct("(") {
                depth += 1;
            } else if t.tok.is_punct(")") {
                depth -= 1;
            } else if t.tok.is_punct(";") && depth == 0 {
                break;
            }
            j += 1;
        }
        j
    }

    /// pat-module := NAME [ '(' [NAME {',' NAME}] ')' ] | '#'
    fn pat_module(&mut self) -> PResult<PatModule> {
        if self.peek_punct("#") {
            let t = self.bump();
            return Ok(PatModule {
                name: Name {
                    text: "#".into(),
                    span: t.span,
                },
                params: Vec::new(),
            });
        }
        let name = self.name("a module name")?;
        let mut params = Vec::new();
        if self.eat_punct("(") && !self.eat_punct(")") {
            loop {
                params.push(self.name("a parameter name in the module pattern")?);
                if self.eat_punct(")") {
                    break;
                }
                self.expect_punct(",", "or `)` between the pattern's parameters")?;
            }
        }
        Ok(PatModule { name, params })
    }

    /// A module list up to (not including) one of `stops`.
    /// module-call := NAME [ '(' args ')' ] | '#'
    fn module_calls(&mut self, stops: &[&str], allow_close: bool) -> PResult<Vec<ModuleCall>> {
        let mut out = Vec::new();
        loop {
            let Some(t) = self.peek() else {
                return self.error(&format!("`{}`", stops[0]));
            };
            if stops.iter().any(|s| t.tok.is_punct(s)) || (allow_close && t.tok.is_punct("}")) {
                return Ok(out);
            }
            self.module_call_into(&mut out)?;
        }
    }

    fn module_calls_until(&mut self, end: usize) -> PResult<Vec<ModuleCall>> {
        let mut out = Vec::new();
        while self.pos < end {
            self.module_call_into(&mut out)?;
        }
        Ok(out)
    }

    fn at_module(&self) -> bool {
        match self.peek().map(|t| &t.tok) {
            Some(Tok::Ident(_)) | Some(Tok::Punct("#")) => true,
            Some(Tok::Punct(p)) => self.abop && abop_punct(p).is_some(),
            _ => false,
        }
    }

    /// In turtle mode, an identifier such as `FX` that names no declared or
    /// predefined module stands for one module per character. Consumes all
    /// characters but the last and returns them; the caller parses the last
    /// one with its arguments.
    fn abop_split(&mut self) -> Option<Vec<Name>> {
        if !self.abop {
            return None;
        }
        let t = self.peek()?;
        let Tok::Ident(s) = &t.tok else { return None };
        if s.len() < 2 || self.whole_names.contains(s) || !s.is_ascii() {
            return None;
        }
        let start = t.span.start as usize;
        let file = t.span.file;
        let names: Vec<Name> = s
            .char_indices()
            .map(|(k, c)| Name {
                text: c.to_string(),
                span: Span::new(file, start + k, start + k + 1),
            })
            .collect();
        // Replace the token by its last character, so the usual parsing of
        // `X(args)` applies to it.
        let last = names.last().cloned()?;
        self.split_last = Some((self.pos, last));
        Some(names[..names.len() - 1].to_vec())
    }

    /// One module, or in turtle mode possibly several (`FX`, `--`).
    fn module_call_into(&mut self, out: &mut Vec<ModuleCall>) -> PResult<()> {
        if self.abop {
            if let Some(Tok::Punct(p)) = self.peek().map(|t| &t.tok) {
                if let Some(names) = abop_punct(p) {
                    let span = self.bump().span;
                    for (k, n) in names.iter().enumerate() {
                        let args = if k + 1 == names.len()
                            && self.peek_punct("(")
                            && !self.toks[self.pos].space_before
                        {
                            self.pos += 1;
                            self.args(")")?
                        } else {
                            Vec::new()
                        };
                        out.push(ModuleCall {
                            name: Name {
                                text: n.to_string(),
                                span,
                            },
                            args,
                        });
                    }
                    return Ok(());
                }
            }
            if let Some(names) = self.abop_split() {
                out.extend(names.into_iter().map(|name| ModuleCall {
                    name,
                    args: Vec::new(),
                }));
            }
        }
        out.push(self.module_call()?);
        Ok(())
    }

    fn module_call(&mut self) -> PResult<ModuleCall> {
        if self.peek_punct("#") {
            let t = self.bump();
            return Ok(ModuleCall {
                name: Name {
                    text: "#".into(),
                    span: t.span,
                },
                args: Vec::new(),
            });
        }
        if !matches!(self.peek().map(|t| &t.tok), Some(Tok::Ident(_))) {
            let turtle = match self.peek().map(|t| &t.tok) {
                Some(Tok::Punct(p)) if !self.abop && abop_punct(p).is_some() => Some(p.to_string()),
                _ => None,
            };
            let mut e: PResult<ModuleCall> =
                self.error("a module (a name, optionally with arguments in parentheses)");
            if let (Some(p), Err(d)) = (turtle, e.as_mut()) {
                d.message.push_str(&format!(
                    "; `{p}` is a turtle command of the single-character notation (The \
                     Algorithmic Beauty of Plants), which `angle: DEGREES;` at the start of a \
                     line switches on"
                ));
            }
            return e;
        }
        let name = self.name("a module name")?;
        let args = if self.eat_punct("(") {
            self.args(")")?
        } else {
            Vec::new()
        };
        Ok(ModuleCall { name, args })
    }

    // ----- statements ---------------------------------------------------

    /// block := '{' { stmt } '}'
    fn block(&mut self) -> PResult<Block> {
        let open = self.expect_punct("{", "to open the block")?;
        let mut stmts = Vec::new();
        loop {
            if self.eat_punct("}") {
                return Ok(Block {
                    stmts,
                    span: open.to(self.prev_span()),
                });
            }
            if self.at_end() {
                return Err(Diagnostic::new(
                    open,
                    "unclosed `{`: expected `}` before the end of the file",
                ));
            }
            stmts.push(self.stmt()?);
        }
    }

    fn too_deep<T>(&self, at: Span) -> PResult<T> {
        Err(Diagnostic::new(
            at,
            format!(
                "this is nested more than {MAX_NESTING} levels deep; split it into simpler parts"
            ),
        ))
    }

    /// Goes one level deeper, to parse the children of a node; [`ascend`]
    /// comes back. (Plain calls rather than a closure: every stack frame
    /// counts on a deep parse in a debug build.)
    ///
    /// [`ascend`]: Parser::ascend
    pub(crate) fn descend(&mut self) -> PResult<()> {
        if self.depth + 1 > MAX_NESTING {
            return self.too_deep(self.span_here());
        }
        self.depth += 1;
        self.peak = self.peak.max(self.depth);
        Ok(())
    }

    pub(crate) fn ascend(&mut self) {
        self.depth -= 1;
    }

    /// Starts measuring the deepest level that the parse which follows
    /// reaches; [`reached`] ends it with the level, given what this
    /// returned.
    ///
    /// [`reached`]: Parser::reached
    fn measure(&mut self) -> usize {
        std::mem::replace(&mut self.peak, self.depth)
    }

    fn reached(&mut self, outer: usize) -> usize {
        let reached = self.peak;
        self.peak = outer.max(reached);
        reached
    }

    /// A node is built around an operand whose deepest level was
    /// `reached`: everything in it moves one level down. The error points
    /// at `at`, the operator that makes the node.
    fn wrap(&mut self, reached: usize, at: Span) -> PResult<usize> {
        if reached + 1 > MAX_NESTING {
            return self.too_deep(at);
        }
        self.peak = self.peak.max(reached + 1);
        Ok(reached + 1)
    }

    fn stmt(&mut self) -> PResult<Stmt> {
        self.descend()?;
        let r = self.stmt_inner();
        self.ascend();
        r
    }

    fn stmt_inner(&mut self) -> PResult<Stmt> {
        let t = self.peek().expect("checked by caller");
        if t.tok.is_punct("{") {
            return Ok(Stmt::Block(self.block()?));
        }
        if t.tok.is_punct(";") {
            self.pos += 1;
            return Ok(Stmt::Empty);
        }
        if let Tok::Ident(w) = &t.tok {
            match w.as_str() {
                "produce" | "nproduce" => {
                    self.pos += 1;
                    let last = w == "produce";
                    let modules = if self.peek_punct("(")
                        && self
                            .peek_at(1)
                            .is_some_and(|t| matches!(t.tok, Tok::Ident(_)))
                        && self.peek_at(2).is_some_and(|t| t.tok.is_punct("("))
                    {
                        // `produce( G(x) );` as in the manual's examples.
                        self.pos += 1;
                        let m = self.module_calls(&[")"], false)?;
                        self.pos += 1;
                        m
                    } else {
                        self.module_calls(&[";"], true)?
                    };
                    // Velho's listings omit the `;` before `}`.
                    if !self.peek_punct("}") {
                        self.expect_punct(";", "after the successor")?;
                    }
                    return Ok(Stmt::Produce {
                        modules,
                        last,
                        span: t.span,
                    });
                }
                "propensity" if self.at_propensity() => {
                    // `propensity E produce W;` (manual 7.2) is lpfg's
                    // `nproduce Propensity(E) W;`: a Gillespie step reads
                    // the reactions back from the successor.
                    self.pos += 1;
                    let value = self.expr()?;
                    if !self.eat_ident("produce") {
                        return self.error("`produce` after the propensity");
                    }
                    let mut modules = vec![ModuleCall {
                        name: Name {
                            text: "Propensity".into(),
                            span: t.span,
                        },
                        args: vec![value],
                    }];
                    modules.extend(self.module_calls(&[";"], true)?);
                    if !self.peek_punct("}") {
                        self.expect_punct(";", "after the successor")?;
                    }
                    return Ok(Stmt::Produce {
                        modules,
                        last: false,
                        span: t.span,
                    });
                }
                "if" => {
                    self.pos += 1;
                    let cond = self.expr()?;
                    let then = Box::new(self.stmt_or_end()?);
                    let els = if self.eat_ident("else") {
                        Some(Box::new(self.stmt_or_end()?))
                    } else {
                        None
                    };
                    return Ok(Stmt::If { cond, then, els });
                }
                "while" => {
                    self.pos += 1;
                    let cond = self.expr()?;
                    let body = Box::new(self.stmt_or_end()?);
                    return Ok(Stmt::While {
                        cond,
                        body,
                        span: t.span,
                    });
                }
                "do" => {
                    self.pos += 1;
                    let body = Box::new(self.stmt_or_end()?);
                    if !self.eat_ident("while") {
                        return self.error("`while` after the body of `do`");
                    }
                    let cond = self.expr()?;
                    self.expect_punct(";", "after `do ... while (...)`")?;
                    return Ok(Stmt::DoWhile {
                        body,
                        cond,
                        span: t.span,
                    });
                }
                "for" => {
                    self.pos += 1;
                    self.expect_punct("(", "after `for`")?;
                    let init = if self.eat_punct(";") {
                        None
                    } else {
                        let s = if self.at_declaration() {
                            Stmt::Decl(self.var_decl()?)
                        } else {
                            Stmt::Expr(self.expr()?)
                        };
                        self.expect_punct(";", "after the loop's initialisation")?;
                        Some(Box::new(s))
                    };
                    let cond = if self.peek_punct(";") {
                        None
                    } else {
                        Some(self.expr()?)
                    };
                    self.expect_punct(";", "after the loop condition")?;
                    let step = if self.peek_punct(")") {
                        None
                    } else {
                        Some(self.expr()?)
                    };
                    self.expect_punct(")", "to close the `for` header")?;
                    let body = Box::new(self.stmt_or_end()?);
                    return Ok(Stmt::For {
                        init,
                        cond,
                        step,
                        body,
                        span: t.span,
                    });
                }
                "return" => {
                    self.pos += 1;
                    let value = if !self.peek_punct(";") && !self.peek_punct("}") {
                        Some(self.expr()?)
                    } else {
                        None
                    };
                    self.eat_punct(";");
                    return Ok(Stmt::Return(value, t.span));
                }
                "switch" | "case" | "default"
                    if w != "default" || self.peek_at(1).is_some_and(|n| n.tok.is_punct(":")) =>
                {
                    return self.switch_part();
                }
                "break" | "continue" => {
                    self.pos += 1;
                    self.expect_punct(";", &format!("after `{w}`"))?;
                    return Ok(if w == "break" {
                        Stmt::Break(t.span)
                    } else {
                        Stmt::Continue(t.span)
                    });
                }
                _ => {}
            }
            if self.vv {
                if let Some(s) = self.vv_stmt(w)? {
                    return Ok(s);
                }
            }
            if self.at_declaration() {
                let d = self.var_decl()?;
                self.expect_punct(";", "after the declaration")?;
                return Ok(Stmt::Decl(d));
            }
        }
        let e = self.expr()?;
        if !self.peek_punct("}") {
            self.expect_punct(";", "after the expression")?;
        }
        Ok(Stmt::Expr(e))
    }

    /// The statements of the vertex-vertex algebra (paper 001, Tables 1
    /// and 2), when `word` at the cursor starts one:
    ///
    /// ```text
    /// forall NAME in expr stmt        add expr to expr ;
    /// remove expr from expr ;          merge expr with expr ;
    /// synchronize expr ;               make '{' expr {',' expr} '}' nb_of expr ;
    /// erase expr from expr ;           replace expr with expr in expr ;
    /// splice expr (after | before) expr in expr ;
    /// ```
    ///
    /// The editing statements are calls of the topology's built-ins
    /// (`make(v, a, b, c)`, `erase(x, v)`, …). A word followed by `(` or an
    /// assignment is not a keyword here. Out of `stmt_inner`, so that its
    /// frame stays small.
    #[inline(never)]
    fn vv_stmt(&mut self, w: &str) -> PResult<Option<Stmt>> {
        let next = self.peek_at(1).map(|t| &t.tok);
        // A constant after the word is a wrong operand of the statement
        // (`add 3 to S`), for the checker to name, not an expression.
        let operand = matches!(
            next,
            Some(Tok::Ident(_) | Tok::Punct("'") | Tok::Int(_) | Tok::Float { .. } | Tok::Str(_))
        ) || (w == "make" && matches!(next, Some(Tok::Punct("{"))));
        if !operand {
            return Ok(None);
        }
        let span = self.span_here();
        let call =
            |name: &str, args: Vec<Expr>, end: Span| Stmt::Expr(call_of(name, span, args, end));
        let s = match w {
            "forall" => {
                self.pos += 1;
                let var = self.name("the loop variable after `forall`")?;
                if !self.eat_ident("in") {
                    return self.error("`in` after `forall x`");
                }
                let set = match self.set_before_edge() {
                    Some(set) => set,
                    None => self.expr()?,
                };
                let body = Box::new(self.stmt_or_end()?);
                return Ok(Some(Stmt::Forall {
                    var,
                    set,
                    body,
                    span,
                }));
            }
            "add" | "remove" | "merge" => {
                self.pos += 1;
                let elem = self.expr()?;
                let (op, word) = match w {
                    "add" => (SetEditOp::Add, "to"),
                    "remove" => (SetEditOp::Remove, "from"),
                    _ => (SetEditOp::Merge, "with"),
                };
                if !self.eat_ident(word) {
                    return self.error(&format!("`{word}` in `{w} ... {word} ...`"));
                }
                // `merge S with T` changes S: the set edited comes first.
                let other = self.expr()?;
                let (elem, set) = if op == SetEditOp::Merge {
                    (other, elem)
                } else {
                    (elem, other)
                };
                Stmt::SetEdit {
                    op,
                    elem,
                    set,
                    span,
                }
            }
            "synchronize" => {
                self.pos += 1;
                let set = self.expr()?;
                call("synchronize", vec![set], self.prev_span())
            }
            "make" => {
                self.pos += 1;
                self.expect_punct(
                    "{",
                    "after `make`: the neighbours, as in `make {a, b, c} nb_of v`",
                )?;
                let mut args = vec![];
                let mut list = self.args("}")?;
                if !self.eat_ident("nb_of") {
                    return self
                        .error("`nb_of` after the neighbour list, as in `make {a, b, c} nb_of v`");
                }
                args.push(self.expr()?);
                args.append(&mut list);
                call("make", args, self.prev_span())
            }
            "erase" => {
                self.pos += 1;
                let x = self.expr()?;
                if !self.eat_ident("from") {
                    return self.error("`from` in `erase x from v`");
                }
                let v = self.expr()?;
                call("erase", vec![x, v], self.prev_span())
            }
            "replace" => {
                self.pos += 1;
                let a = self.expr()?;
                if !self.eat_ident("with") {
                    return self.error("`with` in `replace a with x in v`");
                }
                let x = self.expr()?;
                if !self.eat_ident("in") {
                    return self.error("`in` in `replace a with x in v`");
                }
                let v = self.expr()?;
                call("replace", vec![a, x, v], self.prev_span())
            }
            "splice" => {
                self.pos += 1;
                let x = self.expr()?;
                let name = if self.eat_ident("after") {
                    "splice_after"
                } else if self.eat_ident("before") {
                    "splice_before"
                } else {
                    return self.error("`after` or `before` in `splice x after a in v`");
                };
                let a = self.expr()?;
                if !self.eat_ident("in") {
                    return self.error("`in` in `splice x after a in v`");
                }
                let v = self.expr()?;
                call(name, vec![x, a, v], self.prev_span())
            }
            _ => return Ok(None),
        };
        if !self.peek_punct("}") {
            self.expect_punct(";", &format!("after the `{w}` statement"))?;
        }
        Ok(Some(s))
    }

    /// The set of `forall x in S (x, y)$w = 1;` or `forall y in 'x (x,
    /// y)$w = 1;`: a name (or `'name`) followed by a parenthesis whose
    /// close is followed by `$` is the set, and the parenthesis is the
    /// body's edge, not a call (a property is never a set to go over).
    fn set_before_edge(&mut self) -> Option<Expr> {
        let old = self.peek().is_some_and(|t| t.tok.is_punct("'"));
        let k = old as usize;
        let (name, span) = match self.peek_at(k).map(|t| (&t.tok, t.span)) {
            Some((Tok::Ident(n), span)) => (n.clone(), span),
            _ => return None,
        };
        if !self.peek_at(k + 1).is_some_and(|t| t.tok.is_punct("(")) {
            return None;
        }
        let mut depth = 0usize;
        let mut j = k + 1;
        loop {
            let t = self.peek_at(j)?;
            if t.tok.is_punct("(") {
                depth += 1;
            } else if t.tok.is_punct(")") {
                depth -= 1;
                if depth == 0 {
                    break;
                }
            }
            j += 1;
        }
        if !self.peek_at(j + 1).is_some_and(|t| t.tok.is_punct("$")) {
            return None;
        }
        let start = self.span_here();
        self.pos += k + 1;
        let ident = Expr {
            kind: ExprKind::Ident(name),
            span,
        };
        Some(if old {
            Expr {
                kind: ExprKind::Call(
                    Name {
                        text: "old".into(),
                        span: start,
                    },
                    vec![ident],
                ),
                span: start.to(span),
            }
        } else {
            ident
        })
    }

    /// switch := 'switch' expr ( '{' { stmt } '}' | { label } stmt ), whose
    /// labels are statements of the body; or one of those labels. Out of
    /// `stmt_inner`, so that its frame stays small.
    #[inline(never)]
    fn switch_part(&mut self) -> PResult<Stmt> {
        let span = self.bump().span;
        if !self.toks[self.pos - 1].tok.is_ident("switch") {
            self.pos -= 1;
            return self.label();
        }
        let value = self.expr()?;
        let mut body = Vec::new();
        if !self.peek_punct("{") {
            // `switch (n) case 1: stmt;`: labels and one statement.
            while self.peek_ident("case")
                || (self.peek_ident("default")
                    && self.peek_at(1).is_some_and(|t| t.tok.is_punct(":")))
            {
                body.push(self.stmt()?);
            }
            body.push(self.stmt_or_end()?);
            return Ok(Stmt::Switch { value, body, span });
        }
        let open = self.bump().span;
        while !self.eat_punct("}") {
            if self.at_end() {
                return Err(Diagnostic::new(
                    open,
                    "unclosed `{`: expected `}` before the end of the file",
                ));
            }
            body.push(self.stmt()?);
        }
        Ok(Stmt::Switch { value, body, span })
    }

    /// label := 'case' cond ':' | 'default' ':', a statement of a
    /// `switch`'s body. Out of `stmt_inner`, so that its frame stays small.
    #[inline(never)]
    fn label(&mut self) -> PResult<Stmt> {
        let t = self.bump();
        if t.tok.is_ident("default") {
            self.pos += 1;
            return Ok(Stmt::Default(t.span));
        }
        let value = self.cond_expr()?;
        self.expect_punct(":", "after the `case` label's value")?;
        Ok(Stmt::Case(value, t.span))
    }

    fn stmt_or_end(&mut self) -> PResult<Stmt> {
        if self.at_end() {
            return self.error("a statement");
        }
        self.stmt()
    }

    // ----- expressions --------------------------------------------------

    pub fn expr(&mut self) -> PResult<Expr> {
        self.assign_expr()
    }

    /// assign := cond [ ('=' | '+=' | '-=' | '*=' | '/=' | '%=' | '<<=' | '>>=') assign ]
    fn assign_expr(&mut self) -> PResult<Expr> {
        let outer = self.measure();
        let lhs = self.cond_expr()?;
        let reached = self.reached(outer);
        let op = match self.peek().map(|t| &t.tok) {
            Some(Tok::Punct("=")) => Some(None),
            Some(Tok::Punct("+=")) => Some(Some(BinOp::Add)),
            Some(Tok::Punct("-=")) => Some(Some(BinOp::Sub)),
            Some(Tok::Punct("*=")) => Some(Some(BinOp::Mul)),
            Some(Tok::Punct("/=")) => Some(Some(BinOp::Div)),
            Some(Tok::Punct("%=")) => Some(Some(BinOp::Rem)),
            Some(Tok::Punct("<<=")) => Some(Some(BinOp::Shl)),
            Some(Tok::Punct(">>=")) => Some(Some(BinOp::Shr)),
            _ => None,
        };
        if let Some(op) = op {
            self.wrap(reached, self.span_here())?;
            self.pos += 1;
            self.descend()?;
            let rhs = self.assign_expr()?;
            self.ascend();
            let span = lhs.span.to(rhs.span);
            return Ok(Expr {
                kind: ExprKind::Assign(op, Box::new(lhs), Box::new(rhs)),
                span,
            });
        }
        Ok(lhs)
    }

    /// cond := binary(0) [ '?' expr ':' cond ]
    fn cond_expr(&mut self) -> PResult<Expr> {
        let outer = self.measure();
        let c = self.binary(0)?;
        let reached = self.reached(outer);
        if self.peek_punct("?") {
            self.wrap(reached, self.span_here())?;
            self.pos += 1;
            self.descend()?;
            let a = self.expr()?;
            self.expect_punct(":", "in the conditional expression `c ? a : b`")?;
            let b = self.cond_expr()?;
            self.ascend();
            let span = c.span.to(b.span);
            return Ok(Expr {
                kind: ExprKind::Cond(Box::new(c), Box::new(a), Box::new(b)),
                span,
            });
        }
        Ok(c)
    }

    /// Precedence climbing over the C binary operators. A chain `a + b +
    /// c` is a left-deep tree: each operator moves what came before it one
    /// level down.
    fn binary(&mut self, min_prec: u8) -> PResult<Expr> {
        let outer = self.measure();
        let mut lhs = self.unary()?;
        let mut reached = self.reached(outer);
        loop {
            let Some((op, prec)) = self.peek().and_then(|t| binop_of(&t.tok)) else {
                return Ok(lhs);
            };
            if prec < min_prec {
                return Ok(lhs);
            }
            reached = self.wrap(reached, self.span_here())?;
            self.pos += 1;
            let outer = self.measure();
            self.descend()?;
            let rhs = self.binary(prec + 1)?;
            self.ascend();
            reached = reached.max(self.reached(outer));
            let span = lhs.span.to(rhs.span);
            lhs = Expr {
                kind: ExprKind::Binary(op, Box::new(lhs), Box::new(rhs)),
                span,
            };
        }
    }

    /// unary := ('-' | '+' | '!' | '++' | '--') unary | '(' TYPE ')' unary | postfix
    ///
    /// Every operand goes through here, one level below its parent.
    fn unary(&mut self) -> PResult<Expr> {
        self.descend()?;
        let r = self.unary_inner();
        self.ascend();
        r
    }

    fn unary_inner(&mut self) -> PResult<Expr> {
        let Some(t) = self.peek() else {
            return self.error("an expression");
        };
        let start = t.span;
        let op = match &t.tok {
            Tok::Punct("-") => Some(UnOp::Neg),
            Tok::Punct("+") => Some(UnOp::Plus),
            Tok::Punct("!") => Some(UnOp::Not),
            _ => None,
        };
        if let Some(op) = op {
            self.pos += 1;
            let e = self.unary()?;
            let span = start.to(e.span);
            return Ok(Expr {
                kind: ExprKind::Unary(op, Box::new(e)),
                span,
            });
        }
        if self.vv {
            if let Some(e) = self.vv_query()? {
                return Ok(e);
            }
        }
        if t.tok.is_punct("++") || t.tok.is_punct("--") {
            self.pos += 1;
            let e = self.unary()?;
            let span = start.to(e.span);
            return Ok(Expr {
                kind: ExprKind::IncDec {
                    target: Box::new(e),
                    delta: if t.tok.is_punct("++") { 1 } else { -1 },
                    prefix: true,
                },
                span,
            });
        }
        // A cast: `(int) expr`
        if t.tok.is_punct("(") {
            if let (
                Some(Token {
                    tok: Tok::Ident(n), ..
                }),
                Some(close),
            ) = (self.peek_at(1), self.peek_at(2))
            {
                if close.tok.is_punct(")") && self.is_type_name(n) {
                    self.pos += 1;
                    let ty = self.type_ref()?;
                    self.pos += 1;
                    let e = self.unary()?;
                    let span = start.to(e.span);
                    return Ok(Expr {
                        kind: ExprKind::Cast(ty, Box::new(e)),
                        span,
                    });
                }
            }
        }
        self.postfix()
    }

    /// The query and selection operations of the vertex-vertex algebra,
    /// when one starts at the cursor: `is x in v`, `valence v`, `any in
    /// v`, `nextto x in v`, `prevto x in v`, each a call of the topology's
    /// built-in (`is_in(x, v)`, `valence(v)`, …); their operands are unary
    /// expressions. A word followed by `(` is a plain call.
    #[inline(never)]
    fn vv_query(&mut self) -> PResult<Option<Expr>> {
        let Some(Tok::Ident(w)) = self.peek().map(|t| &t.tok) else {
            return Ok(None);
        };
        let name = match w.as_str() {
            "is" => "is_in",
            "valence" => "valence",
            "any" => "any",
            "nextto" => "nextto",
            "prevto" => "prevto",
            _ => return Ok(None),
        };
        let next = self.peek_at(1).map(|t| &t.tok);
        if !matches!(next, Some(Tok::Ident(_)) | Some(Tok::Punct("'"))) {
            return Ok(None);
        }
        let span = self.bump().span;
        let mut args = Vec::new();
        if name != "any" {
            args.push(self.unary()?);
        }
        if name != "valence" && !self.eat_ident("in") {
            return self.error(&format!("`in` in `{w} ... in v`"));
        }
        if name != "valence" {
            args.push(self.unary()?);
        }
        Ok(Some(call_of(name, span, args, self.prev_span())))
    }

    /// postfix := primary { '.' NAME [ '(' args ')' ] | '++' | '--' }, a
    /// left-deep chain like a binary operator's.
    fn postfix(&mut self) -> PResult<Expr> {
        let outer = self.measure();
        let mut e = self.primary()?;
        let mut reached = self.reached(outer);
        loop {
            if self.peek_punct(".")
                || self.peek_punct("++")
                || self.peek_punct("--")
                || self.peek_punct("[")
            {
                reached = self.wrap(reached, self.span_here())?;
            }
            if self.vv && self.peek_punct("$") {
                reached = self.wrap(reached, self.span_here())?;
                self.pos += 1;
                let name = self.name("a property name after `$`, as in `v$pos`")?;
                let span = e.span.to(name.span);
                e = Expr {
                    kind: ExprKind::Prop(Box::new(e), name),
                    span,
                };
            } else if self.peek_punct("[") {
                let (indexed, r) = self.index_of(e)?;
                e = indexed;
                reached = reached.max(r);
            } else if self.eat_punct(".") {
                let name = self.name("a field or method name after `.`")?;
                if self.eat_punct("(") {
                    let outer = self.measure();
                    let args = self.args(")")?;
                    reached = reached.max(self.reached(outer));
                    let span = e.span.to(self.prev_span());
                    e = Expr {
                        kind: ExprKind::Method(Box::new(e), name, args),
                        span,
                    };
                } else {
                    let span = e.span.to(name.span);
                    e = Expr {
                        kind: ExprKind::Field(Box::new(e), name),
                        span,
                    };
                }
            } else if self.peek_punct("++") || self.peek_punct("--") {
                let t = self.bump();
                let span = e.span.to(t.span);
                e = Expr {
                    kind: ExprKind::IncDec {
                        target: Box::new(e),
                        delta: if t.tok.is_punct("++") { 1 } else { -1 },
                        prefix: false,
                    },
                    span,
                };
            } else {
                return Ok(e);
            }
        }
    }

    /// `e[i]`: the index of `e`, at `[`; with the deepest level the index
    /// reached. Out of `postfix`, so that its frame stays small.
    #[inline(never)]
    fn index_of(&mut self, e: Expr) -> PResult<(Expr, usize)> {
        self.pos += 1;
        let outer = self.measure();
        self.descend()?;
        let index = self.expr();
        self.ascend();
        let index = index?;
        let reached = self.reached(outer);
        self.expect_punct("]", "to close the index")?;
        let span = e.span.to(self.prev_span());
        Ok((
            Expr {
                kind: ExprKind::Index(Box::new(e), Box::new(index)),
                span,
            },
            reached,
        ))
    }

    /// primary := NUMBER | STRING | NAME | NAME '(' args ')' | '(' expr ')'
    ///          | InLeftContext '(' pats ')' | ...
    fn primary(&mut self) -> PResult<Expr> {
        let Some(t) = self.peek() else {
            return self.error("an expression");
        };
        let span = t.span;
        let kind = match &t.tok {
            Tok::Int(i) => {
                self.pos += 1;
                ExprKind::Int(*i)
            }
            Tok::Float { value: f, single } => {
                self.pos += 1;
                ExprKind::Float(*f, *single)
            }
            Tok::Str(s) => {
                self.pos += 1;
                ExprKind::Str(s.clone())
            }
            Tok::Punct("'") if self.vv => {
                // `'v`: the vertex as the last `synchronize` left it; `'a[i]`
                // and `'g.v` of a vertex in an array or a struct (`$` and
                // calls bind outside: `'v$pos` is the old position).
                self.pos += 1;
                let outer = self.measure();
                let mut v = self.primary()?;
                let mut reached = self.reached(outer);
                loop {
                    let field = self.peek_punct(".")
                        && matches!(self.peek_at(1).map(|t| &t.tok), Some(Tok::Ident(_)))
                        && !self.peek_at(2).is_some_and(|t| t.tok.is_punct("("));
                    if self.peek_punct("[") {
                        reached = self.wrap(reached, self.span_here())?;
                        let (indexed, r) = self.index_of(v)?;
                        v = indexed;
                        reached = reached.max(r);
                    } else if field {
                        reached = self.wrap(reached, self.span_here())?;
                        self.pos += 1;
                        let name = self.name("a field name after `.`")?;
                        let span = v.span.to(name.span);
                        v = Expr {
                            kind: ExprKind::Field(Box::new(v), name),
                            span,
                        };
                    } else {
                        break;
                    }
                }
                ExprKind::Call(
                    Name {
                        text: "old".into(),
                        span,
                    },
                    vec![v],
                )
            }
            Tok::Punct("(") if self.vv => {
                // `(p, q)`: the directed edge from p to q, as in `(p, q)$w`.
                self.pos += 1;
                let e = self.expr()?;
                if self.eat_punct(",") {
                    let f = self.expr()?;
                    self.expect_punct(")", "to close the edge `(p, q)`")?;
                    ExprKind::Call(
                        Name {
                            text: "edge".into(),
                            span,
                        },
                        vec![e, f],
                    )
                } else {
                    self.expect_punct(")", "to close the parenthesis")?;
                    return Ok(Expr {
                        kind: e.kind,
                        span: span.to(self.prev_span()),
                    });
                }
            }
            Tok::Punct("(") => {
                self.pos += 1;
                let e = self.expr()?;
                self.expect_punct(")", "to close the parenthesis")?;
                return Ok(Expr {
                    kind: e.kind,
                    span: span.to(self.prev_span()),
                });
            }
            Tok::Ident(n)
                if matches!(n.as_str(), "sum" | "avg" | "count")
                    && self.peek_at(1).is_some_and(|t| t.tok.is_punct("("))
                    && self
                        .peek_at(2)
                        .is_some_and(|t| matches!(t.tok, Tok::Ident(_)))
                    && self.peek_at(3).is_some_and(|t| t.tok.is_ident("in")) =>
            {
                // sum(w in ring(v) where l(w) == c)
                let op = self.name("sum, avg or count")?;
                self.pos += 1;
                let var = self.name("a variable name")?;
                self.pos += 1;
                let set = self.expr()?;
                let cond = if self.eat_ident("where") {
                    Some(Box::new(self.expr()?))
                } else {
                    None
                };
                self.expect_punct(")", "to close the sum")?;
                ExprKind::Gather {
                    op,
                    var,
                    set: Box::new(set),
                    cond,
                }
            }
            Tok::Ident(n) => {
                let name = self.name("a name")?;
                let ctx = match n.as_str() {
                    "InLeftContext" => Some(ContextKind::Left),
                    "InRightContext" => Some(ContextKind::Right),
                    "InNewLeftContext" => Some(ContextKind::NewLeft),
                    "InNewRightContext" => Some(ContextKind::NewRight),
                    _ => None,
                };
                if let Some(kind) = ctx {
                    self.expect_punct("(", "after the context test")?;
                    let mut pats = Vec::new();
                    while !self.eat_punct(")") {
                        if self.at_end() {
                            return self.error("`)` to close the context test");
                        }
                        pats.push(self.pat_module()?);
                    }
                    if pats.is_empty() {
                        return Err(Diagnostic::new(
                            name.span,
                            format!("`{n}` needs at least one module to test, e.g. `{n}(A(x))`"),
                        ));
                    }
                    ExprKind::InContext(kind, pats)
                } else if self.eat_punct("(") {
                    let args = self.args(")")?;
                    ExprKind::Call(name, args)
                } else {
                    ExprKind::Ident(n.clone())
                }
            }
            _ => return self.error("an expression"),
        };
        Ok(Expr {
            kind,
            span: span.to(self.prev_span()),
        })
    }
}

/// A call of the built-in `name` written from `span` to `end` (vv's
/// statements and queries are calls of the topology's built-ins).
fn call_of(name: &str, span: Span, args: Vec<Expr>, end: Span) -> Expr {
    Expr {
        kind: ExprKind::Call(
            Name {
                text: name.into(),
                span,
            },
            args,
        ),
        span: span.to(end),
    }
}

/// The turtle modules of The Algorithmic Beauty of Plants' characters.
/// A doubled operator such as `--` is lexed as one token and means two.
fn abop_punct(p: &str) -> Option<&'static [&'static str]> {
    Some(match p {
        "+" => &["Left"],
        "-" => &["Right"],
        "++" => &["Left", "Left"],
        "--" => &["Right", "Right"],
        "&" => &["Down"],
        "&&" => &["Down", "Down"],
        "^" => &["Up"],
        "\\" => &["RollL"],
        "/" => &["RollR"],
        "|" => &["TurnAround"],
        "||" => &["TurnAround", "TurnAround"],
        "[" => &["SB"],
        "]" => &["EB"],
        _ => return None,
    })
}

fn binop_of(t: &Tok) -> Option<(BinOp, u8)> {
    let Tok::Punct(p) = t else { return None };
    Some(match *p {
        "||" => (BinOp::Or, 1),
        "&&" => (BinOp::And, 2),
        "|" => (BinOp::BitOr, 3),
        "^" => (BinOp::BitXor, 4),
        "&" => (BinOp::BitAnd, 5),
        "==" => (BinOp::Eq, 6),
        "!=" => (BinOp::Ne, 6),
        "<" => (BinOp::Lt, 7),
        ">" => (BinOp::Gt, 7),
        "<=" => (BinOp::Le, 7),
        ">=" => (BinOp::Ge, 7),
        "<<" => (BinOp::Shl, 8),
        ">>" => (BinOp::Shr, 8),
        "+" => (BinOp::Add, 9),
        "-" => (BinOp::Sub, 9),
        "*" => (BinOp::Mul, 10),
        "/" => (BinOp::Div, 10),
        "%" => (BinOp::Rem, 10),
        _ => return None,
    })
}
