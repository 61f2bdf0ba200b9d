//! The shape topology's host built-ins: identifiers that read the shape a
//! rule is rewriting (CityEngine's `scope.sx`, `split.index`, ...). The
//! parser joins `scope . sx` into one identifier token
//! ([`super::grammar::shape_tokens`]), so these are plain names to the
//! checker.

use glam::DVec3;

use crate::lang::builtins::HostTable;
use crate::lang::ir::Func;
use crate::lang::value::{Ty, Value};

use super::geom::Scope;

pub(crate) mod id {
    pub const SX: u16 = 0;
    pub const SY: u16 = 1;
    pub const SZ: u16 = 2;
    pub const TX: u16 = 3;
    pub const TY: u16 = 4;
    pub const TZ: u16 = 5;
    pub const SPLIT_INDEX: u16 = 6;
    pub const SPLIT_TOTAL: u16 = 7;
    pub const COMP_INDEX: u16 = 8;
    pub const COMP_TOTAL: u16 = 9;
    pub const DEPTH: u16 = 10;
    pub const FACES: u16 = 11;
}

const D: Ty = Ty::Double;

/// The shape grammar's table: no element types (a rule's predecessor is a
/// symbol with numeric parameters), the scope and split identifiers.
pub static SHAPE_HOST: HostTable = HostTable {
    name: "shape grammar",
    elements: &[],
    functions: &[],
    values: &[
        ("scope.sx", Func::Host(id::SX), D),
        ("scope.sy", Func::Host(id::SY), D),
        ("scope.sz", Func::Host(id::SZ), D),
        ("scope.tx", Func::Host(id::TX), D),
        ("scope.ty", Func::Host(id::TY), D),
        ("scope.tz", Func::Host(id::TZ), D),
        ("split.index", Func::Host(id::SPLIT_INDEX), Ty::Int),
        ("split.total", Func::Host(id::SPLIT_TOTAL), Ty::Int),
        ("comp.index", Func::Host(id::COMP_INDEX), Ty::Int),
        ("comp.total", Func::Host(id::COMP_TOTAL), Ty::Int),
        ("shape.depth", Func::Host(id::DEPTH), Ty::Int),
        ("shape.faces", Func::Host(id::FACES), Ty::Int),
    ],
    arith: |_| None,
    members: |_| None,
    types: &[],
    zero: |_| Value::Void,
    fresh: |_| None,
    properties: None,
};

/// What the identifiers read: the current shape's scope and place.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct ShapeHost {
    pub origin: DVec3,
    pub size: DVec3,
    pub split: (i64, i64),
    pub comp: (i64, i64),
    pub depth: i64,
    pub faces: i64,
}

impl ShapeHost {
    pub fn of(scope: &Scope) -> ShapeHost {
        ShapeHost {
            origin: scope.origin,
            size: scope.size,
            ..ShapeHost::default()
        }
    }
}

impl crate::lang::eval::Host for ShapeHost {
    fn call(&mut self, f: u16, _args: &[Value]) -> Result<Value, String> {
        Ok(match f {
            id::SX => Value::Float(self.size.x),
            id::SY => Value::Float(self.size.y),
            id::SZ => Value::Float(self.size.z),
            id::TX => Value::Float(self.origin.x),
            id::TY => Value::Float(self.origin.y),
            id::TZ => Value::Float(self.origin.z),
            id::SPLIT_INDEX => Value::Int(self.split.0),
            id::SPLIT_TOTAL => Value::Int(self.split.1),
            id::COMP_INDEX => Value::Int(self.comp.0),
            id::COMP_TOTAL => Value::Int(self.comp.1),
            id::DEPTH => Value::Int(self.depth),
            id::FACES => Value::Int(self.faces),
            _ => return Err(format!("no shape built-in number {f}")),
        })
    }
}
