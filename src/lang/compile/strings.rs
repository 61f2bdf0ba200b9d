//! C strings: declared `char` arrays and the strings written into them,
//! checked to fit; C's standard I/O and string functions.

use crate::syntax::ast::{self, ExprKind, Init};
use crate::syntax::span::Span;

use crate::lang::ir::{CharArray, Ex, Func};
use crate::lang::value::{Ty, Value};

use super::{Compiler, Scope, Typed};

impl Compiler {
    /// The `char` array that a declarator declares (`char b[4]`,
    /// `char names[3][16]`, `char s[] = "abc"`): its size is the last
    /// dimension, or the length of the literal that initialises it and its
    /// NUL. `None` for any other declarator, for a `char *`, and for a
    /// size that is not a constant (C's variable-length array: its strings
    /// are not checked); a size of 0 or less is an error.
    #[inline(never)]
    pub(super) fn char_array(
        &mut self,
        tref: &ast::TypeRef,
        pointer: bool,
        name: &ast::Name,
        dims: &[Option<ast::Expr>],
        init: &Init,
    ) -> Option<CharArray> {
        if tref.name != "char" || tref.pointer || pointer {
            return None;
        }
        let (last, outer) = dims.split_last()?;
        let size = match last {
            Some(e) => {
                let n = self.quiet_const_int(e)?;
                if n <= 0 {
                    self.err(e.span, format!("an array size must be positive, found {n}"));
                    return None;
                }
                usize::try_from(n).ok()?
            }
            None if outer.is_empty() => match init {
                Init::Expr(ast::Expr {
                    kind: ExprKind::Str(s),
                    ..
                }) => crate::lang::stdio::unescape(s).len() + 1,
                _ => return None,
            },
            None => return None,
        };
        let mut decl = format!("char {}", name.text);
        for (k, d) in outer.iter().enumerate() {
            let n = match d {
                Some(e) => self.quiet_const_int(e).map(|n| n.to_string()),
                None if k == 0 => match init {
                    Init::List(items, _) => Some(items.len().to_string()),
                    _ => None,
                },
                None => None,
            };
            decl.push_str(&format!("[{}]", n.unwrap_or_default()));
        }
        decl.push_str(&format!("[{size}]"));
        Some(CharArray {
            size,
            name: name.text.clone(),
            decl,
        })
    }

    /// A declared `char` array's initializer, checked to fit ([`Self::fit`]).
    pub(super) fn fit_init(
        &mut self,
        init: Option<Ex>,
        chars: Option<&CharArray>,
        written: &Init,
    ) -> Option<Ex> {
        match (init, chars, written) {
            (Some(ex), Some(c), Init::Expr(e)) => self.fit(ex, c, "the initializer", e.span),
            (Some(ex), Some(c), Init::List(_, span)) => self.fit(ex, c, "the initializer", *span),
            (init, ..) => init,
        }
    }

    /// `part`, the value that initialises field `k` of a struct `ty`,
    /// checked to fit when the field is a `char` array ([`Self::fit`]).
    pub(super) fn fit_field(&mut self, ty: Ty, k: usize, part: Ex, span: Span) -> Option<Ex> {
        let Ty::Struct(s) = ty else {
            return Some(part);
        };
        match u16::try_from(k)
            .ok()
            .and_then(|k| self.field_chars.get(&(s, k)))
            .cloned()
        {
            Some(c) => self.fit(part, &c, "the initializer", span),
            None => Some(part),
        }
    }

    /// `value`, the string (or array of strings) that `what` writes into
    /// the declared `char` array `c`, checked to fit there with its
    /// terminating NUL: now when `value` is a constant (a string that does
    /// not fit is reported at `span`, and gives `None`), else when it
    /// runs, an error located at `span`.
    pub(super) fn fit(&mut self, value: Ex, c: &CharArray, what: &str, span: Span) -> Option<Ex> {
        if let Some(v) = self.const_written(&value) {
            if let Some(m) = c.overflow(what, &v) {
                self.err(span, m);
                return None;
            }
            return Some(value);
        }
        let text = |s: &str| Ex::Const(Value::Str(s.into()));
        Some(Ex::Call(
            Func::Io(crate::lang::stdio::IoFunc::Fit),
            vec![
                value,
                Ex::Const(Value::Int(c.size as i64)),
                text(what),
                text(&c.name),
                text(&c.decl),
            ],
            span,
        ))
    }

    /// C's standard I/O and string functions; `None` for another name.
    #[inline(never)]
    pub(super) fn stdio_call(
        &mut self,
        name: &ast::Name,
        args: &[ast::Expr],
        span: Span,
        scope: &mut Scope,
    ) -> Option<Typed> {
        use crate::lang::stdio::IoFunc;
        let n = name.text.as_str();
        // (function, fixed leading argument types, whether more follow, result)
        let (f, fixed, varargs, ret): (IoFunc, &[Ty], bool, Ty) = match n {
            "printf" | "Printf" => (IoFunc::Printf, &[Ty::Str], true, Ty::Int),
            "fprintf" => (IoFunc::Fprintf, &[Ty::Int, Ty::Str], true, Ty::Int),
            "sprintf" => (IoFunc::Format, &[Ty::Str, Ty::Str], true, Ty::Str),
            "puts" => (IoFunc::Puts, &[Ty::Str], false, Ty::Int),
            "fputs" => (IoFunc::Fputs, &[Ty::Str, Ty::Int], false, Ty::Int),
            "fopen" => (IoFunc::Fopen, &[Ty::Str, Ty::Str], false, Ty::Int),
            "fclose" => (IoFunc::Fclose, &[Ty::Int], false, Ty::Int),
            "fflush" => (IoFunc::Fflush, &[Ty::Int], false, Ty::Int),
            "strlen" => (IoFunc::Strlen, &[Ty::Str], false, Ty::Int),
            "strcmp" => (IoFunc::Strcmp, &[Ty::Str, Ty::Str], false, Ty::Int),
            "strcpy" => (IoFunc::Concat, &[Ty::Str, Ty::Str], false, Ty::Str),
            "strcat" => (IoFunc::Concat, &[Ty::Str, Ty::Str], false, Ty::Str),
            "strncpy" => (
                IoFunc::Strncpy,
                &[Ty::Str, Ty::Str, Ty::Int],
                false,
                Ty::Str,
            ),
            "strncat" => (
                IoFunc::Strncat,
                &[Ty::Str, Ty::Str, Ty::Int],
                false,
                Ty::Str,
            ),
            "snprintf" => (
                IoFunc::Snprintf,
                &[Ty::Str, Ty::Int, Ty::Str],
                true,
                Ty::Str,
            ),
            "scanf" | "fscanf" | "sscanf" | "fgets" | "fgetc" | "getc" | "fread" | "gets"
            | "getchar" => {
                self.err(
                    name.span,
                    format!("`{n}` reads input, which a program may not do here"),
                );
                return Some(None);
            }
            _ => return None,
        };
        let count_ok = if varargs {
            args.len() >= fixed.len()
        } else {
            args.len() == fixed.len()
        };
        if !count_ok {
            let more = if varargs { " or more" } else { "" };
            self.err(
                span,
                format!(
                    "`{n}` takes {}{more} argument(s), but {} were given",
                    fixed.len(),
                    args.len()
                ),
            );
            return Some(None);
        }
        // `sprintf`, `strcpy`, `strcat` and their `n` forms write their
        // first argument.
        let target = if matches!(
            n,
            "sprintf" | "strcpy" | "strcat" | "snprintf" | "strncpy" | "strncat"
        ) {
            let p = self.place(&args[0], scope);
            match p {
                Some(p) if p.ty == Ty::Str => Some(p),
                Some(p) => {
                    let t = self.type_name(p.ty);
                    self.err(
                        args[0].span,
                        format!("`{n}` writes a string (a `char` array), found {t}"),
                    );
                    return Some(None);
                }
                None => return Some(None),
            }
        } else {
            None
        };
        let mut exs = Vec::with_capacity(args.len());
        let mut ok = true;
        // The functions that append, and `snprintf` (which may write
        // nothing), read it too.
        let skip = usize::from(matches!(n, "sprintf" | "strcpy" | "strncpy"));
        for (k, a) in args.iter().enumerate().skip(skip) {
            let Some((x, t)) = self.expr(a, scope) else {
                ok = false;
                continue;
            };
            let want = fixed.get(k).copied();
            let fits = match want {
                Some(Ty::Str) => t == Ty::Str,
                Some(w) => t.is_numeric() && w.is_numeric(),
                None => t.is_numeric() || t == Ty::Str,
            };
            if !fits {
                let found = self.type_name(t);
                let m = match want {
                    Some(w) => format!(
                        "type mismatch in argument {} of `{n}`: expected {}, found {found}",
                        k + 1,
                        if w == Ty::Str {
                            "a string".to_string()
                        } else {
                            self.type_name(w)
                        }
                    ),
                    // Vectors and structs have fields to print; a
                    // topology's element (a vv vertex, a set) has none.
                    None if matches!(t, Ty::Elem(_)) => {
                        format!("`{n}` prints numbers and strings, not {found}")
                    }
                    None => format!(
                        "`{n}` prints numbers and strings, not {found}; print its fields (`v.x`)"
                    ),
                };
                self.err(a.span, m);
                ok = false;
                continue;
            }
            exs.push(x);
        }
        if !ok {
            return Some(None);
        }
        // A declared `char` array takes only what fits in it.
        let chars = target.as_ref().and_then(|p| p.chars.as_deref()).cloned();
        let call = match (n, &chars) {
            ("strcpy", _) => exs.pop()?,
            // `strncpy` writes its count of bytes, however short the
            // string: the count must fit.
            ("strncpy", Some(c)) => {
                if let Some(Value::Int(k)) = self.const_value(&exs[1], 0) {
                    if k > c.size as i64 {
                        self.err(
                            span,
                            format!(
                                "strncpy writes {k} bytes into `{}` (it always writes its count, \
                                 padding with NULs), declared `{}` (room for {} bytes)",
                                c.name, c.decl, c.size
                            ),
                        );
                        return Some(None);
                    }
                }
                exs.push(Ex::Const(Value::Int(c.size as i64)));
                exs.push(Ex::Const(Value::Str(c.name.as_str().into())));
                exs.push(Ex::Const(Value::Str(c.decl.as_str().into())));
                Ex::Call(Func::Io(f), exs, span)
            }
            _ => Ex::Call(Func::Io(f), exs, span),
        };
        let call = match &chars {
            Some(c) if n != "strncpy" => match self.fit(call, c, n, span) {
                Some(x) => x,
                None => return Some(None),
            },
            _ => call,
        };
        Some(Some(match target {
            Some(p) => (Ex::Assign(p, None, Box::new(call), Ty::Str), Ty::Str),
            None => (call, ret),
        }))
    }
}
