//! Run-time values of the language and their static types.

use std::fmt;

use glam::{DVec2, DVec3};

/// Static type of an expression, a variable or a module parameter.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Ty {
    Int,
    Float,
    Bool,
    V2,
    V3,
    /// Index into `Program::structs`.
    Struct(u16),
    Str,
    Void,
}

impl Ty {
    pub fn is_numeric(self) -> bool {
        matches!(self, Ty::Int | Ty::Float | Ty::Bool)
    }

    pub fn is_vector(self) -> bool {
        matches!(self, Ty::V2 | Ty::V3)
    }
}

/// A value. Vectors are double precision whatever `f`/`d` the source wrote.
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    Int(i64),
    Float(f64),
    Bool(bool),
    V2(DVec2),
    V3(DVec3),
    Struct(Box<[Value]>),
    Str(std::rc::Rc<str>),
    Void,
}

impl Value {
    pub fn as_f64(&self) -> f64 {
        match self {
            Value::Int(i) => *i as f64,
            Value::Float(f) => *f,
            Value::Bool(b) => *b as i64 as f64,
            _ => f64::NAN,
        }
    }

    pub fn as_i64(&self) -> i64 {
        match self {
            Value::Int(i) => *i,
            Value::Float(f) => *f as i64,
            Value::Bool(b) => *b as i64,
            _ => 0,
        }
    }

    pub fn truthy(&self) -> bool {
        match self {
            Value::Int(i) => *i != 0,
            Value::Float(f) => *f != 0.0,
            Value::Bool(b) => *b,
            _ => true,
        }
    }

    /// Converts a value to `ty` as C does for numbers; other values pass.
    pub fn convert(self, ty: Ty) -> Value {
        match (ty, &self) {
            (Ty::Int, Value::Float(_) | Value::Bool(_)) => Value::Int(self.as_i64()),
            (Ty::Float, Value::Int(_) | Value::Bool(_)) => Value::Float(self.as_f64()),
            (Ty::Bool, Value::Int(_) | Value::Float(_)) => Value::Bool(self.truthy()),
            _ => self,
        }
    }

    /// The zero value of a type, as C leaves an initialised global.
    pub fn zero(ty: Ty, structs: &[StructDef]) -> Value {
        match ty {
            Ty::Int => Value::Int(0),
            Ty::Float => Value::Float(0.0),
            Ty::Bool => Value::Bool(false),
            Ty::V2 => Value::V2(DVec2::ZERO),
            Ty::V3 => Value::V3(DVec3::ZERO),
            Ty::Struct(id) => Value::Struct(
                structs[id as usize]
                    .fields
                    .iter()
                    .map(|(_, t)| Value::zero(*t, structs))
                    .collect(),
            ),
            Ty::Str => Value::Str("".into()),
            Ty::Void => Value::Void,
        }
    }

    /// True when a float or a vector component is NaN or infinite.
    pub fn is_non_finite(&self) -> bool {
        match self {
            Value::Float(f) => !f.is_finite(),
            Value::V2(v) => !v.is_finite(),
            Value::V3(v) => !v.is_finite(),
            Value::Struct(fs) => fs.iter().any(Value::is_non_finite),
            _ => false,
        }
    }
}

impl fmt::Display for Value {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Value::Int(i) => write!(f, "{i}"),
            Value::Float(x) => write!(f, "{x}"),
            Value::Bool(b) => write!(f, "{b}"),
            Value::V2(v) => write!(f, "({}, {})", v.x, v.y),
            Value::V3(v) => write!(f, "({}, {}, {})", v.x, v.y, v.z),
            Value::Struct(fs) => {
                f.write_str("{")?;
                for (i, v) in fs.iter().enumerate() {
                    if i > 0 {
                        f.write_str(", ")?;
                    }
                    write!(f, "{v}")?;
                }
                f.write_str("}")
            }
            Value::Str(s) => write!(f, "\"{s}\""),
            Value::Void => f.write_str("void"),
        }
    }
}

/// A user `struct` declaration.
#[derive(Clone, Debug)]
pub struct StructDef {
    pub name: String,
    pub fields: Vec<(String, Ty)>,
}
