//! The binary operators on values: the common cases of numbers and points
//! on a fast path, and all of them.

use crate::syntax::ast::BinOp;

use super::super::value::Value;

/// The common cases of [`binary`], numbers and points, without moving the
/// values: the same results, fewer steps.
#[inline]
pub(super) fn float_binary(op: BinOp, x: &Value, y: &Value) -> Option<Value> {
    use BinOp::*;
    let float = |a: f64, b: f64| -> Option<Value> {
        Some(match op {
            Add => Value::Float(a + b),
            Sub => Value::Float(a - b),
            Mul => Value::Float(a * b),
            Div => Value::Float(a / b),
            Lt => Value::Bool(a < b),
            Le => Value::Bool(a <= b),
            Gt => Value::Bool(a > b),
            Ge => Value::Bool(a >= b),
            Eq => Value::Bool(a == b),
            Ne => Value::Bool(a != b),
            _ => return None,
        })
    };
    Some(match (x, y) {
        (Value::Int(a), Value::Int(b)) => match op {
            Add => Value::Int(a.wrapping_add(*b)),
            Sub => Value::Int(a.wrapping_sub(*b)),
            Mul => Value::Int(a.wrapping_mul(*b)),
            Div if *b != 0 => Value::Int(a.wrapping_div(*b)),
            Rem if *b != 0 => Value::Int(a.wrapping_rem(*b)),
            Lt => Value::Bool(a < b),
            Le => Value::Bool(a <= b),
            Gt => Value::Bool(a > b),
            Ge => Value::Bool(a >= b),
            Eq => Value::Bool(a == b),
            Ne => Value::Bool(a != b),
            _ => return None,
        },
        (Value::Int(a), Value::Float(b)) => return float(*a as f64, *b),
        (Value::Float(a), Value::Int(b)) => return float(*a, *b as f64),
        (Value::Float(a), Value::Float(b)) => return float(*a, *b),
        (Value::V3(a), Value::V3(b)) => match op {
            Add => Value::V3(*a + *b),
            Sub => Value::V3(*a - *b),
            _ => return None,
        },
        (Value::Float(s), Value::V3(p)) | (Value::V3(p), Value::Float(s)) if op == Mul => {
            Value::V3(*p * *s)
        }
        (Value::V3(p), Value::Float(s)) if op == Div => Value::V3(*p / *s),
        _ => return None,
    })
}

/// Applies a binary operator to two values whose types were checked.
pub fn binary(op: BinOp, x: Value, y: Value) -> Result<Value, String> {
    use BinOp::*;
    use Value::*;
    let x = if let Bool(b) = x { Int(b as i64) } else { x };
    let y = if let Bool(b) = y { Int(b as i64) } else { y };
    Ok(match (op, x, y) {
        // Elements: by identity (not by the flags of how they were read),
        // ordered by id.
        (Eq, Elem(a), Elem(b)) => Bool(a.kind == b.kind && a.ids == b.ids),
        (Ne, Elem(a), Elem(b)) => Bool(!(a.kind == b.kind && a.ids == b.ids)),
        (Lt, Elem(a), Elem(b)) => Bool(a.ids[0] < b.ids[0]),
        (Le, Elem(a), Elem(b)) => Bool(a.ids[0] <= b.ids[0]),
        (Gt, Elem(a), Elem(b)) => Bool(a.ids[0] > b.ids[0]),
        (Ge, Elem(a), Elem(b)) => Bool(a.ids[0] >= b.ids[0]),
        (Add, Int(a), Int(b)) => Int(a.wrapping_add(b)),
        (Sub, Int(a), Int(b)) => Int(a.wrapping_sub(b)),
        (Mul, Int(a), Int(b)) => Int(a.wrapping_mul(b)),
        (Div, Int(_), Int(0)) | (Rem, Int(_), Int(0)) => {
            return Err("integer division by zero".into())
        }
        (Div, Int(a), Int(b)) => Int(a.wrapping_div(b)),
        (Rem, Int(a), Int(b)) => Int(a.wrapping_rem(b)),
        (BitAnd, Int(a), Int(b)) => Int(a & b),
        (BitOr, Int(a), Int(b)) => Int(a | b),
        (BitXor, Int(a), Int(b)) => Int(a ^ b),
        // C leaves a shift by a negative count or by the width or more
        // undefined; here it is an error rather than a guess.
        (Shl | Shr, Int(_), Int(b)) if !(0..64).contains(&b) => {
            return Err(format!("a shift by {b} bits (C allows 0 to 63 here)"))
        }
        (Shl, Int(a), Int(b)) => Int(a.wrapping_shl(b as u32)),
        (Shr, Int(a), Int(b)) => Int(a >> b),
        (Lt, Int(a), Int(b)) => Bool(a < b),
        (Le, Int(a), Int(b)) => Bool(a <= b),
        (Gt, Int(a), Int(b)) => Bool(a > b),
        (Ge, Int(a), Int(b)) => Bool(a >= b),
        (Eq, Int(a), Int(b)) => Bool(a == b),
        (Ne, Int(a), Int(b)) => Bool(a != b),
        (Add, V2(a), V2(b)) => V2(a + b),
        (Sub, V2(a), V2(b)) => V2(a - b),
        (Add, V3(a), V3(b)) => V3(a + b),
        (Sub, V3(a), V3(b)) => V3(a - b),
        (Mul, V2(a), V2(b)) => Float(a.dot(b)),
        (Mul, V3(a), V3(b)) => Float(a.dot(b)),
        (Rem, V3(a), V3(b)) => V3(a.cross(b)),
        (Eq, V2(a), V2(b)) => Bool(a == b),
        (Ne, V2(a), V2(b)) => Bool(a != b),
        (Eq, V3(a), V3(b)) => Bool(a == b),
        (Ne, V3(a), V3(b)) => Bool(a != b),
        (Mul, V2(a), s) | (Mul, s, V2(a)) => V2(a * s.as_f64()),
        (Mul, V3(a), s) | (Mul, s, V3(a)) => V3(a * s.as_f64()),
        (Div, V2(a), s) => V2(a / s.as_f64()),
        (Div, V3(a), s) => V3(a / s.as_f64()),
        (op, a, b) => {
            let (a, b) = (a.as_f64(), b.as_f64());
            match op {
                Add => Float(a + b),
                Sub => Float(a - b),
                Mul => Float(a * b),
                Div => Float(a / b),
                Rem => Float(a % b),
                Lt => Bool(a < b),
                Le => Bool(a <= b),
                Gt => Bool(a > b),
                Ge => Bool(a >= b),
                Eq => Bool(a == b),
                Ne => Bool(a != b),
                _ => {
                    return Err(format!(
                        "operator `{}` does not apply to these values",
                        op.symbol()
                    ))
                }
            }
        }
    })
}
