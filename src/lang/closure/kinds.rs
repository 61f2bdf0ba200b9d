//! The kinds of values at run time (integer, floating, boolean) and the
//! compiled expressions of each kind: reads of the frame and of globals,
//! conversions, and the binary operators.

use crate::syntax::ast::BinOp;
use crate::syntax::span::Span;

use crate::lang::value::{round32, Ty, Value};

use super::{rt, BE, FE, IE, UE};

/// The kind of a value at run time: `Value::Int`, `Value::Float`,
/// `Value::Bool`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Kind {
    I,
    F,
    B,
}

pub(super) fn kind_of(ty: Ty) -> Option<Kind> {
    match ty {
        Ty::Int => Some(Kind::I),
        Ty::Float | Ty::Double => Some(Kind::F),
        Ty::Bool => Some(Kind::B),
        _ => None,
    }
}

/// An operand read without a call: a local or a number, as `f64`.
#[derive(Clone, Copy)]
pub(super) enum Leaf {
    Float(usize),
    Int(usize),
    Const(f64),
}

impl Leaf {
    #[inline(always)]
    pub(super) fn get(self, frame: &[u64]) -> f64 {
        match self {
            Leaf::Float(s) => f64::from_bits(frame[s]),
            Leaf::Int(s) => frame[s] as i64 as f64,
            Leaf::Const(x) => x,
        }
    }
}

/// A compiled expression of its kind.
pub(super) enum C {
    I(IE),
    F(FE),
    B(BE),
}

impl C {
    pub(super) fn kind(&self) -> Kind {
        match self {
            C::I(_) => Kind::I,
            C::F(_) => Kind::F,
            C::B(_) => Kind::B,
        }
    }

    /// `Value::as_f64`.
    pub(super) fn f(self) -> FE {
        match self {
            C::F(f) => f,
            C::I(f) => Box::new(move |cx| Ok(f(cx)? as f64)),
            C::B(f) => Box::new(move |cx| Ok(f(cx)? as i64 as f64)),
        }
    }

    /// `Value::as_i64`.
    pub(super) fn i(self) -> IE {
        match self {
            C::I(f) => f,
            C::F(f) => Box::new(move |cx| Ok(f(cx)? as i64)),
            C::B(f) => Box::new(move |cx| Ok(f(cx)? as i64)),
        }
    }

    /// `Value::truthy`.
    pub(super) fn b(self) -> BE {
        match self {
            C::B(f) => f,
            C::I(f) => Box::new(move |cx| Ok(f(cx)? != 0)),
            C::F(f) => Box::new(move |cx| Ok(f(cx)? != 0.0)),
        }
    }

    /// The value's 64 bits as the frame holds them: an `f64`'s bits, an
    /// `i64`'s, 0 or 1.
    pub(super) fn bits(self) -> UE {
        match self {
            C::F(f) => Box::new(move |cx| Ok(f(cx)?.to_bits())),
            C::I(f) => Box::new(move |cx| Ok(f(cx)? as u64)),
            C::B(f) => Box::new(move |cx| Ok(f(cx)? as u64)),
        }
    }
}

/// Reads a frame slot of kind `k`.
pub(super) fn read(k: Kind, s: usize) -> C {
    match k {
        Kind::F => C::F(Box::new(move |cx| Ok(f64::from_bits(cx.m.frame[s])))),
        Kind::I => C::I(Box::new(move |cx| Ok(cx.m.frame[s] as i64))),
        Kind::B => C::B(Box::new(move |cx| Ok(cx.m.frame[s] != 0))),
    }
}

/// Reads a global of kind `k` (a global's value always has its type's
/// variant: initialisers and assignments convert to it).
pub(super) fn read_global(k: Kind, s: usize) -> C {
    match k {
        Kind::F => C::F(Box::new(move |cx| Ok(cx.env.globals[s].as_f64()))),
        Kind::I => C::I(Box::new(move |cx| Ok(cx.env.globals[s].as_i64()))),
        Kind::B => C::B(Box::new(move |cx| Ok(cx.env.globals[s].truthy()))),
    }
}

pub(super) fn value_of(k: Kind, bits: u64) -> Value {
    match k {
        Kind::F => Value::Float(f64::from_bits(bits)),
        Kind::I => Value::Int(bits as i64),
        Kind::B => Value::Bool(bits != 0),
    }
}

/// `Value::convert` to `ty` of a value of kind `c.kind()`: the kind of
/// the result is `ty`'s.
pub(super) fn convert(ty: Ty, c: C) -> Option<C> {
    Some(match (ty, c) {
        (Ty::Int, c) => C::I(c.i()),
        (Ty::Float, c) => {
            let f = c.f();
            C::F(Box::new(move |cx| Ok(round32(f(cx)?))))
        }
        (Ty::Double, c) => C::F(c.f()),
        (Ty::Bool, c) => C::B(c.b()),
        _ => return None,
    })
}

/// A binary operator on compiled operands, as `eval::binary` (and its fast
/// path `float_binary`) computes it on values of these kinds; `span`
/// locates its errors.
pub(super) fn bin(op: BinOp, a: C, b: C, span: Option<Span>) -> Option<C> {
    use BinOp::*;
    let integral = a.kind() != Kind::F && b.kind() != Kind::F;
    if integral {
        // Booleans count as integers (`binary` turns them into ints).
        let (a, b) = (a.i(), b.i());
        macro_rules! int {
            ($f:expr) => {
                C::I(Box::new(move |cx| {
                    let x = a(cx)?;
                    let y = b(cx)?;
                    $f(x, y)
                }))
            };
        }
        macro_rules! cmp {
            ($f:expr) => {
                C::B(Box::new(move |cx| {
                    let x = a(cx)?;
                    let y = b(cx)?;
                    Ok($f(x, y))
                }))
            };
        }
        let zero = move || rt(span, "integer division by zero");
        let shift = move |y: i64| rt(span, format!("a shift by {y} bits (C allows 0 to 63 here)"));
        return Some(match op {
            Add => int!(|x: i64, y| Ok(x.wrapping_add(y))),
            Sub => int!(|x: i64, y| Ok(x.wrapping_sub(y))),
            Mul => int!(|x: i64, y| Ok(x.wrapping_mul(y))),
            Div => int!(|x: i64, y| if y == 0 {
                Err(zero())
            } else {
                Ok(x.wrapping_div(y))
            }),
            Rem => int!(|x: i64, y| if y == 0 {
                Err(zero())
            } else {
                Ok(x.wrapping_rem(y))
            }),
            BitAnd => int!(|x: i64, y| Ok(x & y)),
            BitOr => int!(|x: i64, y| Ok(x | y)),
            BitXor => int!(|x: i64, y| Ok(x ^ y)),
            Shl => int!(|x: i64, y: i64| if (0..64).contains(&y) {
                Ok(x.wrapping_shl(y as u32))
            } else {
                Err(shift(y))
            }),
            Shr => int!(|x: i64, y: i64| if (0..64).contains(&y) {
                Ok(x >> y)
            } else {
                Err(shift(y))
            }),
            Lt => cmp!(|x, y| x < y),
            Le => cmp!(|x, y| x <= y),
            Gt => cmp!(|x, y| x > y),
            Ge => cmp!(|x, y| x >= y),
            Eq => cmp!(|x, y| x == y),
            Ne => cmp!(|x, y| x != y),
            And | Or => return None,
        });
    }
    let (a, b) = (a.f(), b.f());
    macro_rules! flt {
        ($f:expr) => {
            C::F(Box::new(move |cx| {
                let x = a(cx)?;
                let y = b(cx)?;
                Ok($f(x, y))
            }))
        };
    }
    macro_rules! cmp {
        ($f:expr) => {
            C::B(Box::new(move |cx| {
                let x = a(cx)?;
                let y = b(cx)?;
                Ok($f(x, y))
            }))
        };
    }
    Some(match op {
        Add => flt!(|x: f64, y: f64| x + y),
        Sub => flt!(|x: f64, y: f64| x - y),
        Mul => flt!(|x: f64, y: f64| x * y),
        Div => flt!(|x: f64, y: f64| x / y),
        Rem => flt!(|x: f64, y: f64| x % y),
        Lt => cmp!(|x: f64, y: f64| x < y),
        Le => cmp!(|x: f64, y: f64| x <= y),
        Gt => cmp!(|x: f64, y: f64| x > y),
        Ge => cmp!(|x: f64, y: f64| x >= y),
        Eq => cmp!(|x: f64, y: f64| x == y),
        Ne => cmp!(|x: f64, y: f64| x != y),
        _ => return None,
    })
}
