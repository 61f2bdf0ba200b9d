//! The one table of built-in functions: lpfg's maths and library functions,
//! then the host built-ins of the topology a program runs on (a mesh's
//! `l(x)`, `valence(v)`, `ring(v)`, …). The checker sees functions only
//! through this table, so `fabs`, `%`, `/` and division by zero mean the
//! same in a curve and in a surface grammar.

use super::ir::{Batch, Func};
use super::random::Op;
use super::value::{Ty, Value, CAMERA_POSITION, MOUSE_STATUS};

/// Why a call does not fit a built-in's signature.
#[derive(Clone, Debug, PartialEq)]
pub enum SigError {
    /// It takes this many arguments.
    Arity(usize),
    /// Argument `i` should be a number.
    NotNumber(usize),
    /// Anything else, said in full.
    Message(String),
}

/// How a built-in resolves argument types to an implementation and a
/// result type, or why they do not fit.
pub type Resolve = fn(&[Ty]) -> Result<(Func, Ty), SigError>;

/// A built-in function: its name and how it resolves the argument types to
/// an implementation and a result type.
#[derive(Clone, Copy)]
pub struct Builtin {
    pub name: &'static str,
    pub resolve: Resolve,
}

/// What a topology adds to the language: its element types, its host
/// built-ins, the values it names with plain identifiers, how an element
/// reads in arithmetic and what a set holds.
pub struct HostTable {
    /// What a program of this topology is called in messages.
    pub name: &'static str,
    /// The element kinds of [`Ty::Elem`], as messages name them ("a vertex").
    pub elements: &'static [&'static str],
    pub functions: &'static [Builtin],
    /// Identifiers that read a value of the host (`c`, the current level).
    pub values: &'static [(&'static str, Func, Ty)],
    /// The built-in that gives an element's value in arithmetic (a mesh
    /// vertex stands for its position), with the value's type.
    pub arith: fn(u8) -> Option<(Func, Ty)>,
    /// The element kind a set of kind `k` holds, if `k` is a set.
    pub members: fn(u8) -> Option<u8>,
    /// Element kinds that programs name as types (vv's `vertex`, `mesh`).
    pub types: &'static [(&'static str, u8)],
    /// The value of a variable of element kind `k` declared without an
    /// initialiser: a global's, and a local's unless `fresh` makes one.
    pub zero: fn(u8) -> Value,
    /// The built-in a local of element kind `k` declared without an
    /// initialiser calls (vv's `vertex v;` creates a vertex).
    pub fresh: fn(u8) -> Option<Func>,
    /// Properties of elements (`v$pos`), where the topology has them.
    pub properties: Option<&'static HostProperties>,
}

/// Properties a topology's elements carry, read `e$name` and written
/// `e$name = x`: built-in ones and those a program declares
/// (`vertex float conc;`).
pub struct HostProperties {
    /// What declares a property for each owner: `vertex`, `edge`, `mesh`.
    pub owners: &'static [&'static str],
    /// The owner whose properties an element of kind `k` has.
    pub owner_of: fn(u8) -> Option<u8>,
    /// Built-in properties: owner, name, type. They take the first
    /// numbers of their owner, in this order; declared ones follow.
    pub builtin: &'static [(u8, &'static str, Ty)],
    /// The host built-ins that read (`element, number`) and write
    /// (`element, number, value`, giving the value) a property.
    pub get: u16,
    pub set: u16,
}

impl HostTable {
    pub fn function(&self, name: &str) -> Option<&Builtin> {
        self.functions.iter().find(|b| b.name == name)
    }

    pub fn value(&self, name: &str) -> Option<(Func, Ty)> {
        self.values
            .iter()
            .find(|(n, _, _)| *n == name)
            .map(|(_, f, t)| (*f, *t))
    }

    pub fn element_name(&self, kind: u8) -> &'static str {
        self.elements
            .get(kind as usize)
            .copied()
            .unwrap_or("an element")
    }
}

/// Words of modules have no elements and no host built-ins beyond the
/// library: their contexts are matched by the predecessor and by
/// `InLeftContext` and its kin, which are syntax.
pub static WORD_HOST: HostTable = HostTable {
    name: "L-system",
    elements: &[],
    functions: &[],
    values: &[],
    arith: |_| None,
    members: |_| None,
    types: &[],
    zero: |_| Value::Void,
    fresh: |_| None,
    properties: None,
};

/// C's single-precision maths functions of [`LIBRARY`]: each is its
/// double-precision twin's name and `f`, and gives a `float` whatever its
/// argument.
pub const FLOAT_FUNCTIONS: &[&str] = &[
    "sinf", "cosf", "tanf", "asinf", "acosf", "atanf", "sinhf", "coshf", "tanhf", "sqrtf", "cbrtf",
    "expf", "logf", "log10f", "log2f", "fabsf", "floorf", "ceilf", "roundf", "truncf", "atan2f",
    "powf", "fmodf", "hypotf", "fminf", "fmaxf",
];

/// True for `expf`, `sqrtf` and the other [`FLOAT_FUNCTIONS`].
pub fn is_float_function(name: &str) -> bool {
    FLOAT_FUNCTIONS.contains(&name)
}

/// Looks a function up: the library first, then the host's table.
pub fn lookup<'h>(name: &str, host: &'h HostTable) -> Option<&'h Builtin> {
    LIBRARY
        .iter()
        .find(|b| b.name == name)
        .or_else(|| host.function(name))
}

fn numbers(args: &[Ty], n: usize) -> Result<(), SigError> {
    if args.len() != n {
        return Err(SigError::Arity(n));
    }
    match args.iter().position(|t| !t.is_numeric()) {
        Some(i) => Err(SigError::NotNumber(i)),
        None => Ok(()),
    }
}

macro_rules! math1 {
    ($name:literal, $f:expr) => {
        Builtin {
            name: $name,
            resolve: |a| {
                numbers(a, 1)?;
                Ok((Func::Math1($f), Ty::Float))
            },
        }
    };
}

macro_rules! math2 {
    ($name:literal, $f:expr) => {
        Builtin {
            name: $name,
            resolve: |a| {
                numbers(a, 2)?;
                Ok((Func::Math2($f), Ty::Float))
            },
        }
    };
}

/// A function of one view number (manual 6.4).
macro_rules! view {
    ($name:literal, $b:expr, $t:expr) => {
        Builtin {
            name: $name,
            resolve: |a| {
                numbers(a, 1)?;
                Ok((Func::Batch($b), $t))
            },
        }
    };
}

macro_rules! nullary {
    ($name:literal, $f:expr, $t:expr) => {
        Builtin {
            name: $name,
            resolve: |a| {
                if a.is_empty() {
                    Ok(($f, $t))
                } else {
                    Err(SigError::Arity(0))
                }
            },
        }
    };
}

/// An accessor of the model's files: `n` number arguments (the first an
/// id that the model's names `#define`).
macro_rules! model {
    ($name:literal, $acc:ident, $n:expr, $t:expr) => {
        Builtin {
            name: $name,
            resolve: |a| {
                numbers(a, $n)?;
                Ok((Func::Model(super::model::Accessor::$acc), $t))
            },
        }
    };
}

/// A random function of `random.rs` taking `$n` numbers.
macro_rules! random {
    ($name:literal, $n:literal, $op:expr, $t:expr) => {
        Builtin {
            name: $name,
            resolve: |a| {
                numbers(a, $n)?;
                Ok((Func::Random($op), $t))
            },
        }
    };
}

fn vector(a: &[Ty], name: &str) -> Result<Ty, SigError> {
    match a {
        [t] if t.is_vector() => Ok(*t),
        _ => Err(SigError::Message(format!(
            "`{name}` takes one vector argument"
        ))),
    }
}

fn int_or_float(a: &[Ty], n: usize, int: Func, float: Func) -> Result<(Func, Ty), SigError> {
    numbers(a, n)?;
    Ok(if a.iter().all(|t| *t == Ty::Int) {
        (int, Ty::Int)
    } else {
        (float, Ty::Float)
    })
}

/// lpfg's maths and library functions, the same for every topology.
pub static LIBRARY: &[Builtin] = &[
    math1!("sin", f64::sin),
    math1!("cos", f64::cos),
    math1!("tan", f64::tan),
    math1!("asin", f64::asin),
    math1!("acos", f64::acos),
    math1!("atan", f64::atan),
    math1!("sinh", f64::sinh),
    math1!("cosh", f64::cosh),
    math1!("tanh", f64::tanh),
    math1!("sqrt", f64::sqrt),
    math1!("cbrt", f64::cbrt),
    math1!("exp", f64::exp),
    math1!("log", f64::ln),
    math1!("log10", f64::log10),
    math1!("log2", f64::log2),
    math1!("exp2", f64::exp2),
    math1!("fabs", f64::abs),
    math1!("floor", f64::floor),
    math1!("ceil", f64::ceil),
    math1!("round", f64::round),
    math1!("trunc", f64::trunc),
    math2!("atan2", f64::atan2),
    math2!("pow", f64::powf),
    math2!("fmod", |a: f64, b: f64| a % b),
    math2!("hypot", f64::hypot),
    math2!("fmin", f64::min),
    math2!("fmax", f64::max),
    // C's single-precision functions: the argument rounded to a float, the
    // float function (Rust's f32 functions are the platform's libm ones,
    // as lpfg's program calls them), the result a float's value.
    math1!("sinf", |x: f64| f64::from((x as f32).sin())),
    math1!("cosf", |x: f64| f64::from((x as f32).cos())),
    math1!("tanf", |x: f64| f64::from((x as f32).tan())),
    math1!("asinf", |x: f64| f64::from((x as f32).asin())),
    math1!("acosf", |x: f64| f64::from((x as f32).acos())),
    math1!("atanf", |x: f64| f64::from((x as f32).atan())),
    math1!("sinhf", |x: f64| f64::from((x as f32).sinh())),
    math1!("coshf", |x: f64| f64::from((x as f32).cosh())),
    math1!("tanhf", |x: f64| f64::from((x as f32).tanh())),
    math1!("sqrtf", |x: f64| f64::from((x as f32).sqrt())),
    math1!("cbrtf", |x: f64| f64::from((x as f32).cbrt())),
    math1!("expf", |x: f64| f64::from((x as f32).exp())),
    math1!("logf", |x: f64| f64::from((x as f32).ln())),
    math1!("log10f", |x: f64| f64::from((x as f32).log10())),
    math1!("log2f", |x: f64| f64::from((x as f32).log2())),
    math1!("fabsf", |x: f64| f64::from((x as f32).abs())),
    math1!("floorf", |x: f64| f64::from((x as f32).floor())),
    math1!("ceilf", |x: f64| f64::from((x as f32).ceil())),
    math1!("roundf", |x: f64| f64::from((x as f32).round())),
    math1!("truncf", |x: f64| f64::from((x as f32).trunc())),
    math2!("atan2f", |y: f64, x: f64| f64::from(
        (y as f32).atan2(x as f32)
    )),
    math2!("powf", |x: f64, y: f64| f64::from(
        (x as f32).powf(y as f32)
    )),
    math2!("fmodf", |x: f64, y: f64| f64::from((x as f32) % (y as f32))),
    math2!("hypotf", |x: f64, y: f64| f64::from(
        (x as f32).hypot(y as f32)
    )),
    math2!("fminf", |x: f64, y: f64| f64::from(
        (x as f32).min(y as f32)
    )),
    math2!("fmaxf", |x: f64, y: f64| f64::from(
        (x as f32).max(y as f32)
    )),
    Builtin {
        name: "abs",
        resolve: |a| int_or_float(a, 1, Func::AbsInt, Func::Math1(f64::abs)),
    },
    Builtin {
        name: "min",
        resolve: |a| int_or_float(a, 2, Func::MinInt, Func::Math2(f64::min)),
    },
    Builtin {
        name: "max",
        resolve: |a| int_or_float(a, 2, Func::MaxInt, Func::Math2(f64::max)),
    },
    Builtin {
        name: "Length",
        resolve: |a| vector(a, "Length").map(|t| (Func::Length, t.scalar())),
    },
    Builtin {
        name: "Normalize",
        resolve: |a| vector(a, "Normalize").map(|t| (Func::Normalized, t)),
    },
    Builtin {
        name: "Dot",
        resolve: |a| match a {
            [x, y] if x.is_vector() && x.dim() == y.dim() => Ok((Func::Dot, x.wider(*y).scalar())),
            _ => Err(SigError::Message(
                "`Dot` takes two vectors of the same type".into(),
            )),
        },
    },
    Builtin {
        name: "Cross",
        resolve: |a| match a {
            [x, y] if x.dim() == 3 && y.dim() == 3 => Ok((Func::Cross, x.wider(*y))),
            [x, y] if x == y && x.is_vector() => {
                Err(SigError::Message("`Cross` takes two V3f vectors".into()))
            }
            _ => Err(SigError::Message(
                "`Cross` takes two vectors of the same type".into(),
            )),
        },
    },
    nullary!("StepNo", Func::StepNo, Ty::Int),
    nullary!("CurrentGroup", Func::CurrentGroup, Ty::Int),
    nullary!("Forward", Func::Forward, Ty::Void),
    nullary!("Backward", Func::Backward, Ty::Void),
    nullary!("IsForward", Func::IsForward, Ty::Bool),
    nullary!("Stop", Func::Stop, Ty::Void),
    nullary!("RunSimulation", Func::NoOp, Ty::Void),
    nullary!("PauseSimulation", Func::NoOp, Ty::Void),
    nullary!("DisplayFrame", Func::NoOp, Ty::Void),
    nullary!("Environment", Func::Environment(true), Ty::Void),
    nullary!("NoEnvironment", Func::Environment(false), Ty::Void),
    Builtin {
        name: "UseGroup",
        resolve: |a| {
            numbers(a, 1)?;
            Ok((Func::UseGroup, Ty::Void))
        },
    },
    model!("func", Func, 2, Ty::Float),
    model!("pfunc", PFunc, 4, Ty::Float),
    model!("tfunc", TFunc, 2, Ty::Float),
    model!("funcTangent", FuncTangent, 2, Ty::V2),
    model!("val", Val, 1, Ty::Float),
    model!("curveX", CurveX, 2, Ty::Float),
    model!("curveY", CurveY, 2, Ty::Float),
    model!("curveZ", CurveZ, 2, Ty::Float),
    model!("curveXY", CurveXY, 2, Ty::V2),
    model!("curveXYf", CurveXY, 2, Ty::V2),
    model!("curveXYd", CurveXY, 2, Ty::V2d),
    model!("curveXYZ", CurveXYZ, 2, Ty::V3),
    model!("curveXYZf", CurveXYZ, 2, Ty::V3),
    model!("curveXYZd", CurveXYZ, 2, Ty::V3d),
    model!("curveNormal", CurveNormal, 2, Ty::V3),
    model!("curveScale", CurveScale, 4, Ty::Void),
    model!("curveSetPoint", CurveSetPoint, 5, Ty::Void),
    model!("curveRecalculate", CurveRecalculate, 1, Ty::Void),
    model!("curveReset", CurveReset, 1, Ty::Void),
    random!("ran", 1, Op::Ran, Ty::Double),
    random!("sran", 1, Op::SRan, Ty::Void),
    random!("rand", 0, Op::Rand, Ty::Int),
    random!("random", 0, Op::Rand, Ty::Int),
    random!("srand", 1, Op::SRand, Ty::Void),
    random!("srandom", 1, Op::SRand, Ty::Void),
    random!("drand48", 0, Op::Drand48, Ty::Double),
    random!("lrand48", 0, Op::Lrand48, Ty::Int),
    random!("mrand48", 0, Op::Mrand48, Ty::Int),
    random!("srand48", 1, Op::SRand48, Ty::Void),
    random!("GillespieTime", 0, Op::GillespieTime, Ty::Double),
    random!("SeedGillespie", 1, Op::SeedGillespie, Ty::Void),
    random!("ResetGillespie", 0, Op::ResetGillespie, Ty::Void),
    // Mouse, menu and views (manual 6.4, 6.5): a batch run has no window.
    nullary!(
        "GetMouseStatus",
        Func::Batch(Batch::MouseStatus),
        Ty::Struct(MOUSE_STATUS)
    ),
    nullary!("UserMenuChoice", Func::Batch(Batch::MenuChoice), Ty::Int),
    nullary!("UserMenuClear", Func::NoOp, Ty::Void),
    Builtin {
        name: "UserMenuItem",
        resolve: |a| match a {
            [Ty::Str, t] if t.is_numeric() => Ok((Func::NoOp, Ty::Void)),
            [_, _] => Err(SigError::Message(
                "`UserMenuItem` takes a label (a string) and an id (an integer)".to_string(),
            )),
            _ => Err(SigError::Arity(2)),
        },
    },
    view!(
        "GetCameraPosition",
        Batch::CameraPosition,
        Ty::Struct(CAMERA_POSITION)
    ),
    Builtin {
        name: "UseView",
        resolve: |a| {
            numbers(a, 1)?;
            Ok((Func::UseView, Ty::Void))
        },
    },
    view!("vvXmin", Batch::ViewMin(0), Ty::Float),
    view!("vvYmin", Batch::ViewMin(1), Ty::Float),
    view!("vvZmin", Batch::ViewMin(2), Ty::Float),
    view!("vvXmax", Batch::ViewMax(0), Ty::Float),
    view!("vvYmax", Batch::ViewMax(1), Ty::Float),
    view!("vvZmax", Batch::ViewMax(2), Ty::Float),
    view!("vvScale", Batch::ViewScale, Ty::Float),
];

#[cfg(test)]
mod tests {
    use super::*;

    /// Every float function is in the library with its double twin, which
    /// `--double` calls instead.
    #[test]
    fn float_functions_have_double_twins() {
        for f in FLOAT_FUNCTIONS {
            assert!(LIBRARY.iter().any(|b| b.name == *f), "{f}");
            let twin = &f[..f.len() - 1];
            assert!(LIBRARY.iter().any(|b| b.name == twin), "{twin}");
        }
    }
}
