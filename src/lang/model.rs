//! What a program asks of the model folder it came with, through the
//! accessors `func`, `curveX`, `val` and their kin: the [`ModelData`]
//! trait, which `model::Model` implements. The language knows no model
//! file; it is handed one of these with the program.

use std::sync::Arc;

use super::value::Value;

/// The accessors of a model's functions, parameters and contours.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Accessor {
    Func,
    PFunc,
    TFunc,
    FuncTangent,
    Val,
    CurveX,
    CurveY,
    CurveZ,
    CurveXY,
    CurveXYZ,
    CurveNormal,
    CurveScale,
    CurveSetPoint,
    CurveRecalculate,
    CurveReset,
}

impl Accessor {
    /// True for the accessors that change the model: the contour
    /// editing functions, and `pfunc`, which in lpfg sets the function's
    /// interval for later calls of `tfunc` and `funcTangent` too.
    pub fn changes_the_model(self) -> bool {
        matches!(
            self,
            Accessor::PFunc
                | Accessor::CurveScale
                | Accessor::CurveSetPoint
                | Accessor::CurveRecalculate
                | Accessor::CurveReset
        )
    }
}

/// The accessors' names, for messages about a name the model lacks.
pub const ACCESSOR_NAMES: &[&str] = &[
    "func",
    "pfunc",
    "tfunc",
    "funcTangent",
    "val",
    "curveX",
    "curveY",
    "curveZ",
    "curveXY",
    "curveXYf",
    "curveXYd",
    "curveXYZ",
    "curveXYZf",
    "curveXYZd",
    "curveNormal",
    "curveScale",
    "curveSetPoint",
    "curveRecalculate",
    "curveReset",
];

/// A model folder's functions and contours as the evaluator calls them.
/// A program carries one ([`ModelRef`], in [`Program::model`](super::Program)); a run
/// that changes it (`curveSetPoint`, `pfunc`) changes its own copy,
/// made on the first change.
pub trait ModelData: std::fmt::Debug + Send + Sync + 'static {
    /// Evaluates accessor `f` on checked arguments.
    fn call(&self, f: Accessor, args: &[Value]) -> Result<Value, String>;
    /// Evaluates an accessor that changes the model
    /// ([`Accessor::changes_the_model`]); the others as `call` does.
    fn call_mut(&mut self, f: Accessor, args: &[Value]) -> Result<Value, String>;
    /// A copy, for a run's first change.
    fn boxed(&self) -> Box<dyn ModelData>;
    /// The model as `Any`, for the layers that know its type.
    fn into_any(self: Arc<Self>) -> Arc<dyn std::any::Any + Send + Sync>;
}

/// A program's model before the loader has given it one: it has no
/// function and no contour. The loader and every topology give each
/// program a model of their own (`model::Model`, lpfg's default circle at
/// least), so a run meets this one only in the language's own tests.
#[derive(Clone, Debug, Default)]
pub struct NoModel;

impl ModelData for NoModel {
    fn call(&self, f: Accessor, _: &[Value]) -> Result<Value, String> {
        Err(format!("`{f:?}`: the program has no model"))
    }

    fn call_mut(&mut self, f: Accessor, args: &[Value]) -> Result<Value, String> {
        self.call(f, args)
    }

    fn boxed(&self) -> Box<dyn ModelData> {
        Box::new(NoModel)
    }

    fn into_any(self: Arc<Self>) -> Arc<dyn std::any::Any + Send + Sync> {
        self
    }
}

/// A program's or a run's model: shared until a run changes it.
/// `Default` is a [`NoModel`].
#[derive(Clone, Debug)]
pub struct ModelRef(pub Arc<dyn ModelData>);

impl Default for ModelRef {
    fn default() -> ModelRef {
        ModelRef(Arc::new(NoModel))
    }
}

impl std::ops::Deref for ModelRef {
    type Target = dyn ModelData;

    fn deref(&self) -> &(dyn ModelData + 'static) {
        &*self.0
    }
}

impl ModelRef {
    /// The model, made this run's own (copied if another holds it), to
    /// change.
    pub fn make_mut(&mut self) -> &mut dyn ModelData {
        if Arc::get_mut(&mut self.0).is_none() {
            self.0 = Arc::from(self.0.boxed());
        }
        Arc::get_mut(&mut self.0).expect("a fresh copy has one owner")
    }
}
