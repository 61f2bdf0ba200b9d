//! Places: the variables, fields and elements that an assignment writes,
//! or that are read in place.

use crate::syntax::ast::{self, ExprKind};

use crate::lang::ir::{CharArray, Place, Step};
use crate::lang::value::Ty;

use super::{Compiler, Scope};

impl Compiler {
    pub(super) fn place(&mut self, e: &ast::Expr, scope: &mut Scope) -> Option<Place> {
        self.place_of(e, scope, true)
    }

    /// The place `e` names; `write` when it is to be assigned (a `const`
    /// is refused).
    pub(super) fn place_of(
        &mut self,
        e: &ast::Expr,
        scope: &mut Scope,
        write: bool,
    ) -> Option<Place> {
        match &e.kind {
            ExprKind::Ident(n) => {
                if let Some((ty, slot, true)) = scope.lookup_var(n) {
                    if self.globals[slot as usize].is_const && write {
                        self.err(
                            e.span,
                            format!("cannot assign to `{n}`: it is declared const"),
                        );
                        return None;
                    }
                    return Some(Place {
                        global: true,
                        slot,
                        path: Vec::new(),
                        ty,
                        chars: self.global_chars.get(&slot).cloned().map(Box::new),
                    });
                }
                if let Some((ty, slot)) = scope.lookup(n) {
                    if write && scope.consts.contains(&slot) {
                        self.err(
                            e.span,
                            format!("cannot assign to `{n}`: it is declared const"),
                        );
                        return None;
                    }
                    return Some(Place {
                        global: false,
                        slot,
                        path: Vec::new(),
                        ty,
                        chars: scope.chars_of(n).cloned().map(Box::new),
                    });
                }
                if let Some(&g) = self.global_names.get(n) {
                    let gv = &self.globals[g as usize];
                    if write && gv.is_const {
                        self.err(
                            e.span,
                            format!("cannot assign to `{n}`: it is declared const"),
                        );
                        return None;
                    }
                    return Some(Place {
                        global: true,
                        slot: g,
                        path: Vec::new(),
                        ty: gv.ty,
                        chars: self.global_chars.get(&g).cloned().map(Box::new),
                    });
                }
                let hint = self.value_hint(n, scope);
                self.err(e.span, format!("unknown identifier `{n}`{hint}"));
                None
            }
            ExprKind::Field(base, f) => {
                let mut p = self.place_of(base, scope, write)?;
                let (idx, ty) = self.field_of(p.ty, f)?;
                // A field declared as a `char` array, or none.
                p.chars = match p.ty {
                    Ty::Struct(s) => self.field_chars.get(&(s, idx)).map(|c| {
                        Box::new(CharArray {
                            name: written_place(e),
                            ..c.clone()
                        })
                    }),
                    _ => None,
                };
                p.path.push(Step::Field(idx));
                p.ty = ty;
                Some(p)
            }
            ExprKind::Index(base, index) => {
                let p = self.place_of(base, scope, write);
                let i = self.index(index, scope);
                let (mut p, i) = (p?, i?);
                let elem = self.elem_of(p.ty, e.span)?;
                // An element of an array of `char` arrays is one of them;
                // a string's character is none.
                if p.ty == Ty::Str {
                    p.chars = None;
                } else if let Some(c) = &mut p.chars {
                    c.name = written_place(e);
                }
                p.path.push(Step::Index(Box::new(i), e.span));
                p.ty = elem;
                Some(p)
            }
            _ => {
                self.err(e.span, "expected a variable or a field to assign to");
                None
            }
        }
    }

    pub(super) fn field_of(&mut self, ty: Ty, f: &ast::Name) -> Option<(u16, Ty)> {
        let found = match ty {
            t if t.is_vector() => ["x", "y", "z"][..t.dim()]
                .iter()
                .position(|c| *c == f.text)
                .map(|i| (i as u16, t.scalar())),
            Ty::Struct(s) => self.struct_fields[s as usize]
                .get(&f.text)
                .map(|&i| (i, self.structs[s as usize].fields[i as usize].1)),
            _ => None,
        };
        if found.is_none() {
            self.err(
                f.span,
                format!("{} has no field `{}`", self.type_name(ty), f.text),
            );
        }
        found
    }

    /// True when `e` is a chain of fields and indices with at least one
    /// index, on a variable: read through a place, without copying the
    /// whole variable.
    #[inline(never)]
    pub(super) fn indexes_a_variable(&self, e: &ast::Expr, scope: &Scope) -> bool {
        let mut indexed = false;
        let mut e = e;
        loop {
            match &e.kind {
                ExprKind::Index(b, _) => {
                    indexed = true;
                    e = b;
                }
                ExprKind::Field(b, _) => e = b,
                ExprKind::Ident(n) => {
                    return indexed
                        && (scope.lookup_var(n).is_some() || self.global_names.contains_key(n))
                }
                _ => return false,
            }
        }
    }

    /// Whether assigning to `p` is refused (a `const` variable).
    pub(super) fn is_const_place(&self, p: &Place, scope: &Scope) -> bool {
        if p.global {
            self.globals[p.slot as usize].is_const
        } else {
            scope.consts.contains(&p.slot)
        }
    }
}

/// A destination as the program writes it (`b`, `s.name`, `names[i]`),
/// for the error that a string does not fit there; an index other than a
/// name or a number is `…`.
fn written_place(e: &ast::Expr) -> String {
    match &e.kind {
        ExprKind::Ident(n) => n.clone(),
        ExprKind::Field(b, f) => format!("{}.{}", written_place(b), f.text),
        ExprKind::Index(b, i) => {
            let i = match &i.kind {
                ExprKind::Ident(n) => n.clone(),
                ExprKind::Int(k) => k.to_string(),
                _ => "…".to_string(),
            };
            format!("{}[{i}]", written_place(b))
        }
        _ => "…".to_string(),
    }
}
