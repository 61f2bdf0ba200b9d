//! The items of a file: the dispatch on an item's first words, vv
//! properties, functions, enums, directives and module declarations.

use crate::syntax::ast::{
    ControlKind, DirectiveKind, Expr, FunctionDef, Item, Name, Param, Section,
};
use crate::syntax::lex::{Tok, Token};
use crate::syntax::span::{Diagnostic, Span};

use super::{PResult, Parser, QUALIFIERS};

impl<'t> Parser<'t> {
    /// item := module-decl | struct-decl | typedef | global-decl | directive
    ///       | axiom | ignore | consider | section | group | control | production
    pub(super) fn item(&mut self, items: &mut Vec<Item>) -> PResult<()> {
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
    pub(super) fn params(&mut self) -> PResult<Vec<Param>> {
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
    pub(super) fn dims(&mut self) -> PResult<Vec<Option<Expr>>> {
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
    pub(super) fn enum_body(&mut self, items: &mut Vec<Item>) -> PResult<()> {
        let (name, variants) = self.enum_parts()?;
        items.push(Item::Enum { name, variants });
        Ok(())
    }

    /// The name and the enumerators of an enum's body, from `enum`.
    #[allow(clippy::type_complexity)]
    pub(super) fn enum_parts(&mut self) -> PResult<(Option<Name>, Vec<(Name, Option<Expr>)>)> {
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
}
