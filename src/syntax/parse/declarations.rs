//! Declarations: type references, structs with their members, methods and
//! constructors, typedefs, variables and initializer lists.

use crate::syntax::ast::{
    Ctor, Declarator, Expr, ExprKind, FunctionDef, Init, Item, StructBody, TypeRef, VarDecl,
};
use crate::syntax::span::Diagnostic;

use super::{PResult, Parser, QUALIFIERS};

impl<'t> Parser<'t> {
    pub(super) fn type_ref(&mut self) -> PResult<TypeRef> {
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

    /// struct-decl := 'struct' NAME struct-body ';'
    pub(super) fn struct_decl(&mut self, items: &mut Vec<Item>) -> PResult<()> {
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
    pub(super) fn typedef(&mut self, items: &mut Vec<Item>) -> PResult<()> {
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
    pub(super) fn var_decl(&mut self) -> PResult<VarDecl> {
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
}
