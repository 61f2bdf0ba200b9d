//! Run-time values of the language and their static types.

use std::fmt;

use glam::{DVec2, DVec3};

/// Static type of an expression, a variable or a module parameter.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Ty {
    Int,
    /// C's `float`: single precision, as in lpfg. Its values are `f64`s
    /// that a single-precision float represents exactly: converting to it
    /// rounds ([`Value::convert`]), and the checker converts wherever C
    /// rounds. A program run with floats in double precision has no
    /// `Float` anywhere: its `float` is `Double`.
    Float,
    /// C's `double`.
    Double,
    Bool,
    /// `V2f`: two single-precision components.
    V2,
    /// `V3f`.
    V3,
    /// `V2d`: two double-precision components.
    V2d,
    /// `V3d`.
    V3d,
    /// Index into `Program::structs`.
    Struct(u16),
    Str,
    Void,
    /// An element of a topology: its kind, numbered by the topology's
    /// [`HostTable`](super::builtins::HostTable) (a mesh's vertex, edge,
    /// face or set of vertices).
    Elem(u8),
}

impl Ty {
    pub fn is_numeric(self) -> bool {
        matches!(self, Ty::Int | Ty::Float | Ty::Double | Ty::Bool)
    }

    /// `float` or `double`.
    pub fn is_floating(self) -> bool {
        matches!(self, Ty::Float | Ty::Double)
    }

    pub fn is_vector(self) -> bool {
        matches!(self, Ty::V2 | Ty::V3 | Ty::V2d | Ty::V3d)
    }

    /// The number of components of a vector type (0 for other types).
    pub fn dim(self) -> usize {
        match self {
            Ty::V2 | Ty::V2d => 2,
            Ty::V3 | Ty::V3d => 3,
            _ => 0,
        }
    }

    /// Single precision: `float`, `V2f`, `V3f`. Values of these types are
    /// rounded to `f32` where C rounds them.
    pub fn is_single(self) -> bool {
        matches!(self, Ty::Float | Ty::V2 | Ty::V3)
    }

    /// The scalar type of a vector's components (`float` for `V2f`,
    /// `double` for `V2d`); other types are their own scalar.
    pub fn scalar(self) -> Ty {
        match self {
            Ty::V2 | Ty::V3 => Ty::Float,
            Ty::V2d | Ty::V3d => Ty::Double,
            t => t,
        }
    }

    /// The double-precision type of a single-precision one (`double` for
    /// `float`, `V2d` for `V2f`); other types are left as they are.
    pub fn widened(self) -> Ty {
        match self {
            Ty::Float => Ty::Double,
            Ty::V2 => Ty::V2d,
            Ty::V3 => Ty::V3d,
            t => t,
        }
    }

    /// The wider of two numeric or vector types of the same kind, as C's
    /// usual arithmetic conversions choose (`double` over `float` over
    /// `int`; `V2d` over `V2f`).
    pub fn wider(self, other: Ty) -> Ty {
        let rank = |t: Ty| match t {
            Ty::Double | Ty::V2d | Ty::V3d => 3,
            Ty::Float | Ty::V2 | Ty::V3 => 2,
            Ty::Int => 1,
            _ => 0,
        };
        if rank(other) > rank(self) {
            other
        } else {
            self
        }
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
    Str(std::sync::Arc<str>),
    Void,
    /// An element of a topology, as its topology captured it.
    Elem(Elem),
    /// A set of a topology's elements held by value (vv's `mesh S`),
    /// shared until one holder changes it.
    Set(std::sync::Arc<IdSet>),
}

/// A set of element ids (vertex ids of a vv program's `mesh`): the ids in
/// the order they were added, each once, with a bitmap for membership.
/// Adding and testing are O(1); removing is O(n).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct IdSet {
    items: Vec<u32>,
    bits: Vec<u64>,
}

impl IdSet {
    pub fn new() -> IdSet {
        IdSet::default()
    }

    /// The ids, in the order they were added.
    pub fn ids(&self) -> &[u32] {
        &self.items
    }

    pub fn len(&self) -> usize {
        self.items.len()
    }

    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    pub fn contains(&self, id: u32) -> bool {
        self.bits
            .get(id as usize / 64)
            .is_some_and(|w| w & (1 << (id % 64)) != 0)
    }

    /// Adds `id`; false when it was there.
    pub fn insert(&mut self, id: u32) -> bool {
        if self.contains(id) {
            return false;
        }
        let w = id as usize / 64;
        if w >= self.bits.len() {
            self.bits.resize(w + 1, 0);
        }
        self.bits[w] |= 1 << (id % 64);
        self.items.push(id);
        true
    }

    /// Removes `id`; false when it was not there.
    pub fn remove(&mut self, id: u32) -> bool {
        if !self.contains(id) {
            return false;
        }
        self.bits[id as usize / 64] &= !(1 << (id % 64));
        if let Some(i) = self.items.iter().position(|&x| x == id) {
            self.items.remove(i);
        }
        true
    }

    /// Adds the ids of `other` that are not here, in its order.
    pub fn merge(&mut self, other: &IdSet) {
        for &id in &other.items {
            self.insert(id);
        }
    }
}

impl FromIterator<u32> for IdSet {
    fn from_iter<I: IntoIterator<Item = u32>>(iter: I) -> IdSet {
        let mut s = IdSet::new();
        for id in iter {
            s.insert(id);
        }
        s
    }
}

/// An element of a topology (a mesh vertex, edge or face, a set of them):
/// a kind and a small payload that only the topology's built-ins read.
/// The language passes it around and never looks inside.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Elem {
    pub kind: u8,
    pub flags: u8,
    pub ids: [u32; 4],
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

    /// Converts a value to `ty` as C does for numbers: to `float` (and
    /// `V2f`, `V3f`) rounds to single precision. Other values pass.
    pub fn convert(self, ty: Ty) -> Value {
        match (ty, &self) {
            (Ty::Int, Value::Float(_) | Value::Bool(_)) => Value::Int(self.as_i64()),
            (Ty::Float, Value::Int(_) | Value::Bool(_) | Value::Float(_)) => {
                Value::Float(round32(self.as_f64()))
            }
            (Ty::Double, Value::Int(_) | Value::Bool(_)) => Value::Float(self.as_f64()),
            (Ty::V2 | Ty::V3, Value::V2(_) | Value::V3(_)) => self.round32(),
            (Ty::Bool, Value::Int(_) | Value::Float(_)) => Value::Bool(self.truthy()),
            _ => self,
        }
    }

    /// The zero value of a type, as C leaves an initialised global.
    pub fn zero(ty: Ty, structs: &[StructDef]) -> Value {
        match ty {
            Ty::Int => Value::Int(0),
            Ty::Float | Ty::Double => Value::Float(0.0),
            Ty::Bool => Value::Bool(false),
            Ty::V2 | Ty::V2d => Value::V2(DVec2::ZERO),
            Ty::V3 | Ty::V3d => Value::V3(DVec3::ZERO),
            Ty::Struct(id) => Value::Struct(
                structs[id as usize]
                    .fields
                    .iter()
                    .map(|(_, t)| Value::zero(*t, structs))
                    .collect(),
            ),
            Ty::Str => Value::Str("".into()),
            Ty::Void | Ty::Elem(_) => Value::Void,
        }
    }

    /// Rounds a float, or each component of a vector, to the nearest
    /// single-precision float, as C does when it stores into a `float`.
    /// Other values pass unchanged.
    pub fn round32(self) -> Value {
        match self {
            Value::Float(x) => Value::Float(round32(x)),
            Value::V2(v) => Value::V2(DVec2::new(round32(v.x), round32(v.y))),
            Value::V3(v) => Value::V3(DVec3::new(round32(v.x), round32(v.y), round32(v.z))),
            other => other,
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
            Value::Elem(e) => write!(f, "element {}", e.ids[0]),
            Value::Set(s) => write!(f, "a set of {} elements", s.len()),
        }
    }
}

/// `x` rounded to the nearest single-precision float (ties to even), as an
/// `f64`. Overflow gives an infinity, as in C.
#[inline]
pub fn round32(x: f64) -> f64 {
    x as f32 as f64
}

/// A user `struct` declaration.
#[derive(Clone, Debug)]
pub struct StructDef {
    pub name: String,
    pub fields: Vec<(String, Ty)>,
    /// An array type (`float[3]`) is a struct whose fields are its
    /// elements, all of this type, unnamed; `float[]` (a parameter that
    /// takes an array of any length) has no fields.
    pub elem: Option<Ty>,
}

/// `MouseStatus` (manual 7.4), the first of lpfg's predefined structs.
pub const MOUSE_STATUS: u16 = 0;
/// `CameraPosition` (manual 6.4), the second.
pub const CAMERA_POSITION: u16 = 1;
/// `EA20Array` (manual 5.13), the third: the 20 floats that module `EA20`
/// exchanges with an environmental program, an array type.
pub const EA20_ARRAY: u16 = 2;

/// lpfg's predefined struct types, which every program has before its own:
/// `MouseStatus` and `CameraPosition`, with the manual's fields and their
/// precisions (`V3d` positions of the mouse, `V3f` and `float` of the
/// camera).
pub fn predefined_structs() -> Vec<StructDef> {
    let def = |name: &str, fields: &[(&str, Ty)]| StructDef {
        name: name.to_string(),
        fields: fields.iter().map(|(n, t)| (n.to_string(), *t)).collect(),
        elem: None,
    };
    vec![
        def(
            "MouseStatus",
            &[
                ("viewNum", Ty::Int),
                ("viewX", Ty::Int),
                ("viewY", Ty::Int),
                ("atFront", Ty::V3d),
                ("atRear", Ty::V3d),
                ("atMiddle", Ty::V3d),
                ("lbDown", Ty::Bool),
                ("lbPushed", Ty::Bool),
                ("lbReleased", Ty::Bool),
            ],
        ),
        def(
            "CameraPosition",
            &[
                ("position", Ty::V3),
                ("lookat", Ty::V3),
                ("head", Ty::V3),
                ("left", Ty::V3),
                ("up", Ty::V3),
                ("scale", Ty::Float),
            ],
        ),
        StructDef {
            name: "EA20Array".to_string(),
            fields: (0..20).map(|_| (String::new(), Ty::Float)).collect(),
            elem: Some(Ty::Float),
        },
    ]
}

/// The number of `f64` slots a value of type `ty` takes in a word.
pub fn width(ty: Ty, structs: &[StructDef]) -> usize {
    match ty {
        Ty::V2 | Ty::V2d => 2,
        Ty::V3 | Ty::V3d => 3,
        Ty::Struct(id) => structs[id as usize]
            .fields
            .iter()
            .map(|(_, t)| width(*t, structs))
            .sum(),
        Ty::Void | Ty::Elem(_) => 0,
        _ => 1,
    }
}

/// Appends the slots of `v`. Integers keep all their bits; strings are
/// interned and stored by number.
pub fn encode(v: &Value, out: &mut Vec<f64>) {
    match v {
        Value::Int(i) => out.push(f64::from_bits(*i as u64)),
        Value::Float(f) => out.push(*f),
        Value::Bool(b) => out.push(*b as u8 as f64),
        Value::V2(p) => out.extend_from_slice(&[p.x, p.y]),
        Value::V3(p) => out.extend_from_slice(&[p.x, p.y, p.z]),
        Value::Struct(fs) => fs.iter().for_each(|f| encode(f, out)),
        Value::Str(s) => out.push(f64::from_bits(intern(s) as u64)),
        Value::Void | Value::Elem(_) | Value::Set(_) => {}
    }
}

/// Reads a value of type `ty` from the front of `slots`; returns it and the
/// number of slots it took.
pub fn decode(ty: Ty, slots: &[f64], structs: &[StructDef]) -> (Value, usize) {
    let at = |i: usize| slots.get(i).copied().unwrap_or(0.0);
    match ty {
        Ty::Int => (Value::Int(at(0).to_bits() as i64), 1),
        Ty::Float | Ty::Double => (Value::Float(at(0)), 1),
        Ty::Bool => (Value::Bool(at(0) != 0.0), 1),
        Ty::V2 | Ty::V2d => (Value::V2(DVec2::new(at(0), at(1))), 2),
        Ty::V3 | Ty::V3d => (Value::V3(DVec3::new(at(0), at(1), at(2))), 3),
        Ty::Struct(id) => {
            let mut used = 0;
            let mut fs = Vec::new();
            for (_, t) in &structs[id as usize].fields {
                let (v, n) = decode(*t, slots.get(used..).unwrap_or(&[]), structs);
                fs.push(v);
                used += n;
            }
            (Value::Struct(fs.into_boxed_slice()), used)
        }
        Ty::Str => (Value::Str(interned(at(0).to_bits() as usize)), 1),
        Ty::Void | Ty::Elem(_) => (Value::Void, 0),
    }
}

/// Decodes the parameters of a module whose types are `tys`.
pub fn decode_all(tys: &[Ty], mut slots: &[f64], structs: &[StructDef]) -> Vec<Value> {
    let mut out = Vec::with_capacity(tys.len());
    for t in tys {
        let (v, n) = decode(*t, slots, structs);
        out.push(v);
        slots = slots.get(n..).unwrap_or(&[]);
    }
    out
}

static STRINGS: std::sync::Mutex<Vec<std::sync::Arc<str>>> = std::sync::Mutex::new(Vec::new());

fn intern(s: &std::sync::Arc<str>) -> usize {
    let mut table = STRINGS.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(i) = table.iter().position(|t| **t == **s) {
        return i;
    }
    table.push(s.clone());
    table.len() - 1
}

fn interned(i: usize) -> std::sync::Arc<str> {
    let table = STRINGS.lock().unwrap_or_else(|e| e.into_inner());
    table.get(i).cloned().unwrap_or_else(|| "".into())
}
