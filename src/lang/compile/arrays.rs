//! Arrays: the array types (made once), the dimensions a declarator
//! writes after a name, and indexing.

use std::collections::HashMap;

use crate::syntax::ast::{self, ExprKind, Init};
use crate::syntax::parse::MAX_NESTING;
use crate::syntax::span::Span;

use crate::lang::ir::Ex;
use crate::lang::value::{StructDef, Ty};

use super::{Compiler, Scope, MAX_DECLARED};

impl Compiler {
    pub(super) fn is_array(&self, ty: Ty) -> bool {
        matches!(ty, Ty::Struct(i) if self.structs[i as usize].elem.is_some())
    }

    /// The number of fields (or elements) of a struct type; 0 otherwise.
    pub(super) fn fields_of(&self, ty: Ty) -> usize {
        match ty {
            Ty::Struct(i) => self.structs[i as usize].fields.len(),
            _ => 0,
        }
    }

    /// The element type of an array (a string's elements are `char`s,
    /// ints), or the error that `ty` has none.
    pub(super) fn elem_of(&mut self, ty: Ty, span: Span) -> Option<Ty> {
        match ty {
            Ty::Struct(i) if self.structs[i as usize].elem.is_some() => {
                self.structs[i as usize].elem
            }
            Ty::Str => Some(Ty::Int),
            _ => {
                self.err(
                    span,
                    format!(
                        "{} is not an array: it cannot be indexed",
                        self.type_name(ty)
                    ),
                );
                None
            }
        }
    }

    /// An array index: an integer.
    #[inline(never)]
    pub(super) fn index(&mut self, e: &ast::Expr, scope: &mut Scope) -> Option<Ex> {
        let (x, t) = self.expr(e, scope)?;
        if !matches!(t, Ty::Int | Ty::Bool) {
            self.err(
                e.span,
                format!(
                    "an array index must be an integer, found {}",
                    self.type_name(t)
                ),
            );
            return None;
        }
        Some(x)
    }

    /// The array type of `len` elements of `elem` (`None`: any length, a
    /// parameter's `float a[]`), made once.
    pub(super) fn array_type(&mut self, elem: Ty, len: Option<usize>, span: Span) -> Option<Ty> {
        if let Some(&id) = self.array_types.get(&(elem, len)) {
            return Some(Ty::Struct(id));
        }
        let (values, depth) = match elem {
            Ty::Struct(i) => self.struct_shapes[i as usize],
            _ => (1, 0),
        };
        let total = values.saturating_mul(len.unwrap_or(0)).saturating_add(1);
        if total > MAX_ARRAY_VALUES {
            self.err(
                span,
                format!("this array holds more than {MAX_ARRAY_VALUES} values, the limit"),
            );
            return None;
        }
        if depth + 1 > MAX_NESTING {
            self.err(
                span,
                format!("arrays nest more than {MAX_NESTING} levels deep"),
            );
            return None;
        }
        if self.structs.len() >= MAX_DECLARED {
            self.too_many(MAX_DECLARED, "structs and array types", span);
            return None;
        }
        let elem_name = self.type_name(elem);
        let (head, tail) = match elem_name.find('[') {
            Some(k) if self.is_array(elem) => (&elem_name[..k], &elem_name[k..]),
            _ => (elem_name.as_str(), ""),
        };
        let dim = len.map(|n| n.to_string()).unwrap_or_default();
        let name = format!("{head}[{dim}]{tail}");
        let id = self.structs.len() as u16;
        self.array_types.insert((elem, len), id);
        self.struct_names.insert(name.clone(), id);
        self.struct_fields.push(HashMap::new());
        self.struct_shapes.push((total, depth + 1));
        self.structs.push(StructDef {
            name,
            fields: vec![(String::new(), elem); len.unwrap_or(0)],
            elem: Some(elem),
        });
        Some(Ty::Struct(id))
    }

    /// `ty` with the dimensions written after a name (`float a[3][2]`: 3
    /// arrays of 2 floats); a `char` array is a string. A first `[]` takes
    /// its length from `init_len` (the initializer's), or stays open (a
    /// parameter's).
    #[inline(never)]
    pub(super) fn with_dims(
        &mut self,
        mut ty: Ty,
        base: &ast::TypeRef,
        dims: &[Option<ast::Expr>],
        init_len: Option<usize>,
        span: Span,
    ) -> Option<Ty> {
        let mut dims = dims;
        if base.name == "char" && !base.pointer && !dims.is_empty() {
            ty = Ty::Str;
            dims = &dims[..dims.len() - 1];
        }
        let mut lens = Vec::with_capacity(dims.len());
        for (k, d) in dims.iter().enumerate() {
            lens.push(match d {
                Some(e) => {
                    let n = self.const_int(e, "an array size")?;
                    if n <= 0 {
                        self.err(e.span, format!("an array size must be positive, found {n}"));
                        return None;
                    }
                    Some(n as usize)
                }
                None if k == 0 => init_len,
                None => {
                    self.err(
                        span,
                        "only an array's first dimension may be left empty (`[]`)",
                    );
                    return None;
                }
            });
        }
        for len in lens.into_iter().rev() {
            ty = self.array_type(ty, len, span)?;
        }
        Some(ty)
    }

    /// The type a declarator gives its variable: `char *s` is a string,
    /// `FILE *f` a handle, `float a[3]` an array.
    #[inline(never)]
    pub(super) fn declarator_type(
        &mut self,
        base: Ty,
        tref: &ast::TypeRef,
        d: &ast::Declarator,
    ) -> Option<Ty> {
        let mut base = base;
        if d.pointer || tref.pointer {
            base = match tref.name.as_str() {
                "char" => Ty::Str,
                "FILE" => Ty::Int,
                _ => {
                    self.err(
                        d.name.span,
                        format!(
                            "pointers are not supported (`{} *{}`); use an array, or a reference parameter",
                            tref.name, d.name.text
                        ),
                    );
                    return None;
                }
            };
        }
        if base == Ty::Void {
            self.err(d.name.span, "a variable cannot have type void");
            return None;
        }
        let init_len = match &d.init {
            Init::List(items, _) => Some(items.len()),
            Init::Expr(ast::Expr {
                kind: ExprKind::Str(s),
                ..
            }) => Some(s.len() + 1),
            _ => None,
        };
        if d.dims.first().is_some_and(|d| d.is_none()) && init_len.is_none() {
            self.err(
                d.name.span,
                format!("`{}[]` needs a size or an initializer list", d.name.text),
            );
            return None;
        }
        let char_tref;
        let tref = if d.pointer && tref.name == "char" {
            char_tref = ast::TypeRef {
                pointer: true,
                ..tref.clone()
            };
            &char_tref
        } else {
            tref
        };
        self.with_dims(base, tref, &d.dims, init_len, d.name.span)
    }
}

/// The most values an array may hold (counting those of its elements).
const MAX_ARRAY_VALUES: usize = 1 << 22;
