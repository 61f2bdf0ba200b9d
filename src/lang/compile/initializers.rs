//! Initial values: a declaration's initializer, a value built from its
//! parts, `{...}` lists, and the value of a variable that nothing
//! initialises.

use crate::syntax::ast::{self, ExprKind, Init};
use crate::syntax::span::Span;

use crate::lang::ir::Ex;
use crate::lang::value::{Ty, Value};

use super::{pt_index, Compiler, Scope};

/// The most elements of an array whose structs a constructor builds, one
/// call each.
const MAX_BUILT_ELEMENTS: usize = 1 << 16;

impl Compiler {
    /// The expression that initialises a variable of type `ty`, declared
    /// at `at`.
    pub(super) fn initializer(
        &mut self,
        ty: Ty,
        init: &Init,
        at: Span,
        scope: &mut Scope,
    ) -> Option<Ex> {
        let has_ctor = match ty {
            Ty::Struct(si) => self.ctors.contains_key(&self.structs[si as usize].name),
            _ => false,
        };
        match init {
            // `S s;` and `S s(1, 2);` call `S`'s constructors; the structs
            // of a plain struct or an array are built by theirs.
            Init::None => match self.default_value(ty, at) {
                // A struct or an array holding elements starts with the
                // topology's zeros; a lone element is made by the caller
                // (`vertex v;` in a body creates one).
                Ex::Const(_) if !matches!(ty, Ty::Struct(_)) || !self.holds_elements(ty) => None,
                built => Some(built),
            },
            Init::Ctor(args, span) if has_ctor => {
                let name = ast::Name {
                    text: self.structs[pt_index(ty)].name.clone(),
                    span: *span,
                };
                self.ctor_call(ty, &name, args, *span, scope).map(|t| t.0)
            }
            Init::Expr(e) => {
                let (ex, et) = self.expr(e, scope)?;
                self.coerce(ex, et, ty, e.span)
            }
            Init::List(items, span)
                if self.is_array(ty)
                    || items.iter().any(|i| matches!(i.kind, ExprKind::List(_))) =>
            {
                self.list_init(ty, items, *span, scope)
            }
            Init::List(items, span)
                if matches!(ty, Ty::Struct(_)) && items.len() < self.fields_of(ty) =>
            {
                self.list_init(ty, items, *span, scope)
            }
            Init::Ctor(args, span) | Init::List(args, span) => {
                let mut exs = Vec::new();
                for a in args {
                    exs.push(self.expr(a, scope)?);
                }
                self.construct(ty, exs, args, *span)
            }
        }
    }

    /// `V2f v(1, 2)`, `V3f(x, y, z)`, `Data d = {1, 0}`, `int n(3)`.
    pub(super) fn construct(
        &mut self,
        ty: Ty,
        mut exs: Vec<(Ex, Ty)>,
        args: &[ast::Expr],
        span: Span,
    ) -> Option<Ex> {
        let want = self.parts_of(ty);
        if exs.len() == 1 && (exs[0].1 == ty || ty.is_vector() && exs[0].1.dim() == ty.dim()) {
            let (ex, from) = exs.pop().expect("one");
            return self.coerce(ex, from, ty, span);
        }
        if exs.len() != want.len() {
            self.err(
                span,
                format!(
                    "{} takes {} value(s) here, but {} were given",
                    self.type_name(ty),
                    want.len(),
                    exs.len()
                ),
            );
            return None;
        }
        let mut parts = Vec::new();
        for (k, ((ex, et), (w, a))) in exs.into_iter().zip(want.iter().zip(args)).enumerate() {
            let part = self.coerce(ex, et, *w, a.span)?;
            parts.push(self.fit_field(ty, k, part, a.span)?);
        }
        assemble(ty, parts)
    }

    /// `{1, 2, 3}` for an array or a struct, nested lists for their
    /// elements; missing elements are zero, as in C.
    #[inline(never)]
    fn list_init(
        &mut self,
        ty: Ty,
        items: &[ast::Expr],
        span: Span,
        scope: &mut Scope,
    ) -> Option<Ex> {
        let want = self.parts_of(ty);
        if items.len() > want.len() || (!matches!(ty, Ty::Struct(_)) && items.len() != want.len()) {
            self.err(
                span,
                format!(
                    "{} takes {} value(s) here, but {} were given",
                    self.type_name(ty),
                    want.len(),
                    items.len()
                ),
            );
            return None;
        }
        let mut parts = Vec::with_capacity(want.len());
        let mut ok = true;
        for (k, w) in want.iter().enumerate() {
            let part = match items.get(k) {
                None => Some(Ex::Const(Value::zero(*w, &self.structs))),
                Some(ast::Expr {
                    kind: ExprKind::List(inner),
                    span,
                }) => self
                    .list_init(*w, inner, *span, scope)
                    .and_then(|x| self.fit_field(ty, k, x, *span)),
                Some(e) => self
                    .expr(e, scope)
                    .and_then(|(x, t)| self.coerce(x, t, *w, e.span))
                    .and_then(|x| self.fit_field(ty, k, x, e.span)),
            };
            match part {
                Some(p) => parts.push(p),
                None => ok = false,
            }
        }
        if !ok {
            return None;
        }
        assemble(ty, parts)
    }

    /// Zero of type `ty`, with the topology's own zero for its elements
    /// (vv: the null vertex, an empty set) inside structs and arrays too;
    /// [`Value::zero`] knows no topology and leaves them void, which a
    /// set edit ignored (`add v to sets[1]` did nothing).
    pub(super) fn zero(&self, ty: Ty) -> Value {
        match ty {
            Ty::Elem(k) => (self.host.zero)(k),
            Ty::Struct(id) if self.holds_elements(ty) => Value::Struct(
                self.structs[id as usize]
                    .fields
                    .iter()
                    .map(|(_, t)| self.zero(*t))
                    .collect(),
            ),
            _ => Value::zero(ty, &self.structs),
        }
    }

    /// Whether a value of type `ty` holds elements of the topology.
    fn holds_elements(&self, ty: Ty) -> bool {
        match ty {
            Ty::Elem(_) => true,
            Ty::Struct(id) => {
                let def = &self.structs[id as usize];
                match def.elem {
                    Some(t) => self.holds_elements(t),
                    None => def.fields.iter().any(|(_, t)| self.holds_elements(*t)),
                }
            }
            _ => false,
        }
    }

    /// The value a variable of type `ty` starts with when nothing
    /// initialises it, as C++ makes it: for a struct with a constructor
    /// without parameters, what that constructor makes; for another struct
    /// or an array, its fields or elements made so; otherwise zero (a
    /// constant).
    pub(super) fn default_value(&mut self, ty: Ty, span: Span) -> Ex {
        let Ty::Struct(si) = ty else {
            return Ex::Const(self.zero(ty));
        };
        let zero = |c: &Compiler| Ex::Const(c.zero(ty));
        if self.ctors.is_empty() {
            return zero(self);
        }
        let def = &self.structs[si as usize];
        let id = self.ctors.get(&def.name).and_then(|ids| {
            ids.iter()
                .copied()
                .find(|&id| self.user_fns[id as usize].params.is_empty())
        });
        if let Some(id) = id {
            return Ex::CallUser {
                id,
                args: Vec::new(),
                back: Vec::new(),
                span,
            };
        }
        let fields: Vec<Ty> = def.fields.iter().map(|f| f.1).collect();
        if fields.len() > MAX_BUILT_ELEMENTS {
            // Only the first field tells whether the elements of a long
            // array are built: they all have its type.
            if matches!(
                fields.first().map(|&t| self.default_value(t, span)),
                Some(Ex::Const(_)) | None
            ) {
                return zero(self);
            }
            self.err(
                span,
                format!(
                    "an array of more than {MAX_BUILT_ELEMENTS} structs with constructors is not supported"
                ),
            );
            return zero(self);
        }
        let parts: Vec<Ex> = fields
            .iter()
            .map(|&t| self.default_value(t, span))
            .collect();
        if parts.iter().all(|p| matches!(p, Ex::Const(_))) {
            return zero(self);
        }
        Ex::MakeStruct(parts)
    }
}

/// A value of type `ty` built from its parts (see `Compiler::parts_of`),
/// already converted to their types.
fn assemble(ty: Ty, parts: Vec<Ex>) -> Option<Ex> {
    let mut it = parts.into_iter();
    Some(match ty {
        Ty::V2 | Ty::V2d => Ex::MakeV2(Box::new(it.next()?), Box::new(it.next()?)),
        Ty::V3 | Ty::V3d => Ex::MakeV3(
            Box::new(it.next()?),
            Box::new(it.next()?),
            Box::new(it.next()?),
        ),
        Ty::Struct(_) => Ex::MakeStruct(it.collect()),
        _ => it.last()?,
    })
}
