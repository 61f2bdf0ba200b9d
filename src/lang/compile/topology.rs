//! A topology's elements in the language: properties (`v$x`), `forall`,
//! set edits (`add`, `remove`, `merge`) and aggregates (`sum`, `avg`,
//! `count`).

use crate::syntax::ast::{self, BinOp, ExprKind, Item};
use crate::syntax::span::Span;

use crate::lang::ir::{Ex, FoldOp, Func, St};
use crate::lang::value::{Ty, Value};

use super::{Compiler, DeclaredProp, Scope, Typed};

impl Compiler {
    /// The properties a vv program declares, numbered after their owner's
    /// built-in ones.
    pub(super) fn property_decls(&mut self, file: &ast::File) {
        for item in &file.items {
            let Item::Property {
                owner, ty, name, ..
            } = item
            else {
                continue;
            };
            let Some(props) = self.host.properties else {
                self.err(
                    owner.span,
                    format!("a {} has no properties", self.host.name),
                );
                continue;
            };
            let Some(o) = props.owners.iter().position(|n| *n == owner.text) else {
                continue;
            };
            let o = o as u8;
            let Some(t) = self.resolve_type(ty) else {
                continue;
            };
            if !(t.is_numeric() || t.is_vector()) {
                self.err(
                    ty.span,
                    format!(
                        "a property holds a number or a vector; {} is neither",
                        self.type_name(t)
                    ),
                );
                continue;
            }
            let taken = props
                .builtin
                .iter()
                .any(|(bo, n, _)| *bo == o && *n == name.text)
                || self
                    .props
                    .iter()
                    .any(|p| p.owner == o && p.name == name.text);
            if taken {
                self.err(
                    name.span,
                    format!(
                        "{} property `{}` is already declared",
                        owner.text, name.text
                    ),
                );
                continue;
            }
            let index = props.builtin.iter().filter(|(bo, _, _)| *bo == o).count()
                + self.props.iter().filter(|p| p.owner == o).count();
            self.props.push(DeclaredProp {
                owner: o,
                name: name.text.clone(),
                ty: t,
                index: index as u16,
            });
        }
    }

    /// A property of an element of type `target_ty`: its owner, number and
    /// type; an error at `name` if it has none of that name.
    pub(super) fn property(
        &mut self,
        target_ty: Ty,
        name: &ast::Name,
        at: Span,
    ) -> Option<(u8, u16, Ty)> {
        let owner = match (self.host.properties, target_ty) {
            (Some(p), Ty::Elem(k)) => (p.owner_of)(k).map(|o| (p, o)),
            _ => None,
        };
        let Some((props, o)) = owner else {
            self.err(
                at,
                format!(
                    "`$` reads a property of a vertex, an edge or the mesh; this is {}",
                    self.type_name(target_ty)
                ),
            );
            return None;
        };
        let mut index = 0u16;
        for (bo, n, t) in props.builtin {
            if *bo == o {
                if *n == name.text {
                    return Some((o, index, *t));
                }
                index += 1;
            }
        }
        if let Some(p) = self
            .props
            .iter()
            .find(|p| p.owner == o && p.name == name.text)
        {
            return Some((o, p.index, p.ty));
        }
        let owner_name = props.owners[o as usize];
        self.err(
            name.span,
            format!(
                "{owner_name} property `{}` is not declared; declare it as `{owner_name} float {};`",
                name.text, name.text
            ),
        );
        None
    }

    /// `e$name = rhs` and `e$name op= rhs`: the topology's property
    /// setter, which gives the value stored.
    pub(super) fn assign_property(
        &mut self,
        op: Option<BinOp>,
        lhs: &ast::Expr,
        rhs: &ast::Expr,
        span: Span,
        scope: &mut Scope,
    ) -> Typed {
        let ExprKind::Prop(target, name) = &lhs.kind else {
            return None;
        };
        let (tx, tt) = self.expr(target, scope)?;
        let (_, index, ty) = self.property(tt, name, lhs.span)?;
        let props = self.host.properties?;
        let value = match op {
            None => rhs.clone(),
            Some(o) => ast::Expr {
                kind: ExprKind::Binary(o, Box::new(lhs.clone()), Box::new(rhs.clone())),
                span,
            },
        };
        let (vx, vt) = self.expr(&value, scope)?;
        let vx = self.coerce(vx, vt, ty, rhs.span)?;
        Some((
            Ex::Call(
                Func::Host(props.set),
                vec![tx, Ex::Const(Value::Int(index as i64)), vx],
                span,
            ),
            ty,
        ))
    }

    /// `forall x in S body`: `x` takes each member of a set, or each
    /// neighbour of a vertex (its members as the topology lists them).
    pub(super) fn forall(
        &mut self,
        var: &ast::Name,
        set: &ast::Expr,
        body: &ast::Stmt,
        span: Span,
        scope: &mut Scope,
    ) -> Option<St> {
        let (sx, st) = self.expr(set, scope)?;
        let member = match st {
            Ty::Elem(k) => (self.host.members)(k),
            _ => None,
        };
        let Some(member) = member else {
            self.err(
                set.span,
                format!(
                    "`forall` goes over a set or a vertex's neighbours; this is {}",
                    self.type_name(st)
                ),
            );
            return None;
        };
        // A topology may check what a loop goes over (vv: a vertex that
        // has a neighbourhood to list) through its built-in `$forall`,
        // which gives it back; a host's `members` lists nothing otherwise.
        let sx = match self.host.function("$forall").map(|b| (b.resolve)(&[st])) {
            Some(Ok((f, _))) => Ex::Call(f, vec![sx], set.span),
            _ => sx,
        };
        scope.push();
        let slot = self.local(scope, &var.text, Ty::Elem(member), var.span);
        scope.loops += 1;
        let b = self.sub_stmt(body, scope);
        scope.loops -= 1;
        scope.pop();
        Some(St::ForAll {
            slot,
            set: sx,
            body: Box::new(b),
            span,
        })
    }

    /// `add v to S`, `remove v from S`, `merge S with T`: `S` must be a
    /// variable (or a field or element of one) holding a set.
    pub(super) fn set_edit(
        &mut self,
        op: ast::SetEditOp,
        elem: &ast::Expr,
        set: &ast::Expr,
        span: Span,
        scope: &mut Scope,
    ) -> Option<St> {
        let place = self.place(set, scope);
        let ex = self.expr(elem, scope);
        let (place, (ex, et)) = (place?, ex?);
        let member = match place.ty {
            Ty::Elem(k) => (self.host.members)(k),
            _ => None,
        };
        let word = match op {
            ast::SetEditOp::Add => "add",
            ast::SetEditOp::Remove => "remove",
            ast::SetEditOp::Merge => "merge",
        };
        // A set's members are of another kind than the set; a vertex's
        // members are its neighbours, and a vertex is not a set to edit.
        let is_set = matches!(place.ty, Ty::Elem(k) if member != Some(k));
        let Some(member) = member.filter(|_| is_set) else {
            self.err(
                set.span,
                format!(
                    "`{word}` changes a set (a `mesh` variable); this is {}",
                    self.type_name(place.ty)
                ),
            );
            return None;
        };
        let want = match op {
            ast::SetEditOp::Merge => place.ty,
            _ => Ty::Elem(member),
        };
        if et != want {
            self.err(
                elem.span,
                format!(
                    "`{word}` takes {} here; this is {}",
                    self.type_name(want),
                    self.type_name(et)
                ),
            );
            return None;
        }
        let _ = span;
        // A topology may refuse what joins a set (vv: the null vertex)
        // through its built-in `$member`, which gives the element back.
        let ex = match (op, self.host.function("$member")) {
            (ast::SetEditOp::Add, Some(b)) => match (b.resolve)(&[et]) {
                Ok((f, _)) => Ex::Call(f, vec![ex], elem.span),
                Err(_) => ex,
            },
            _ => ex,
        };
        Some(St::SetEdit {
            place,
            op,
            elem: ex,
        })
    }

    /// `sum(w in SET where COND)`: the variable is a local while the
    /// condition is checked.
    pub(super) fn gather(
        &mut self,
        op: &ast::Name,
        var: Option<&ast::Name>,
        set: &ast::Expr,
        cond: Option<&ast::Expr>,
        scope: &mut Scope,
    ) -> Typed {
        let (sx, st) = self.expr(set, scope)?;
        self.fold(op, sx, st, set.span, var, cond, scope)
    }

    #[allow(clippy::too_many_arguments)]
    pub(super) fn fold(
        &mut self,
        op: &ast::Name,
        set: Ex,
        set_ty: Ty,
        set_span: Span,
        var: Option<&ast::Name>,
        cond: Option<&ast::Expr>,
        scope: &mut Scope,
    ) -> Typed {
        let fold_op = match op.text.as_str() {
            "sum" => FoldOp::Sum,
            "avg" => FoldOp::Avg,
            "count" => FoldOp::Count,
            other => {
                self.err(
                    op.span,
                    format!("unknown aggregate `{other}`: expected sum, avg or count"),
                );
                return None;
            }
        };
        let member = match set_ty {
            Ty::Elem(k) => (self.host.members)(k),
            _ => None,
        };
        let Some(member) = member else {
            let what = if self.host.elements.is_empty() {
                format!("a {} has no sets to sum over", self.host.name)
            } else {
                format!(
                    "`{}` sums over a set, such as `ring(v)`; this is {}",
                    op.text,
                    self.type_name(set_ty)
                )
            };
            self.err(set_span, what);
            return None;
        };
        if scope.next == u16::MAX {
            self.err(set_span, "this expression needs too many variables");
            return None;
        }
        // As for `forall`: the topology may check what is folded over.
        let set = match self
            .host
            .function("$forall")
            .map(|b| (b.resolve)(&[set_ty]))
        {
            Some(Ok((f, _))) => Ex::Call(f, vec![set], set_span),
            _ => set,
        };
        let mark = (scope.vars.len(), scope.next);
        let name = var.map_or("", |v| v.text.as_str());
        let slot = self.local(scope, name, Ty::Elem(member), op.span);
        let cond = match cond {
            Some(c) => self.condition(c, scope).map(|x| Some(Box::new(x))),
            None => Some(None),
        };
        let value = match fold_op {
            FoldOp::Count => Some(None),
            _ => {
                let (x, t) = self.arith(Ex::Local(slot), Ty::Elem(member), op.span);
                if t.is_numeric() || t.is_vector() {
                    Some(Some((Box::new(x), t)))
                } else {
                    self.err(
                        op.span,
                        format!(
                            "`{}` adds up values, but {} has no value to add",
                            op.text,
                            self.type_name(Ty::Elem(member))
                        ),
                    );
                    None
                }
            }
        };
        scope.truncate(mark.0);
        scope.next = mark.1;
        let (cond, value) = (cond?, value?);
        let ty = match (&value, fold_op) {
            (Some((_, t)), FoldOp::Sum) => *t,
            (Some((_, t)), FoldOp::Avg) if t.is_vector() => *t,
            (Some(_), FoldOp::Avg) => self.prec(Ty::Float),
            _ => Ty::Int,
        };
        Some((
            Ex::Fold {
                op: fold_op,
                slot,
                set: Box::new(set),
                cond,
                value,
            },
            ty,
        ))
    }
}
