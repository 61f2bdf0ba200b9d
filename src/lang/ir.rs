//! The checked program: names resolved to slots, types known, rules grouped.
//!
//! Nothing here knows about strings of modules. A [`Rule`]'s predecessor is a
//! list of [`Pattern`]s per role; the topology that matches it (a word today,
//! a mesh later) lives in `rewrite`.

use crate::syntax::ast::{BinOp, ContextKind, ControlKind, Section, SetEditOp};
use crate::syntax::span::Span;

use super::modules::{Alphabet, Sym};
use super::value::{StructDef, Ty, Value};
use crate::syntax::span::Diagnostic;

#[derive(Clone, Debug)]
pub enum Ex {
    Const(Value),
    Local(u16),
    Global(u16),
    /// A vector component or a struct field.
    Field(Box<Ex>, u16),
    Neg(Box<Ex>),
    Not(Box<Ex>),
    /// The span locates a division by zero.
    Bin(BinOp, Box<Ex>, Box<Ex>, Span),
    /// Short-circuit `&&` (`and == true`) and `||`.
    Logic(bool, Box<Ex>, Box<Ex>),
    Cond(Box<Ex>, Box<Ex>, Box<Ex>),
    Convert(Ty, Box<Ex>),
    /// Reads a place whose path indexes an array (`a[i].x`), without
    /// copying the whole variable.
    Load(Place),
    /// `e[i]` of a value that is not a variable (a function's result);
    /// the span locates an index out of range.
    Index(Box<Ex>, Box<Ex>, Span),
    /// A user-defined function: its number in `Program::functions`, the
    /// arguments, and the places to which the parameters passed by
    /// reference (arrays, `float &x`) are written back after the call,
    /// by parameter number.
    CallUser {
        id: u16,
        args: Vec<Ex>,
        back: Vec<(u16, Place)>,
        span: Span,
    },
    Assign(Place, Option<BinOp>, Box<Ex>, Ty),
    IncDec(Place, i8, bool),
    Call(Func, Vec<Ex>, Span),
    MakeV2(Box<Ex>, Box<Ex>),
    MakeV3(Box<Ex>, Box<Ex>, Box<Ex>),
    MakeStruct(Vec<Ex>),
    /// A context test: the modules to match and the places their parameters go.
    InContext(ContextKind, Vec<Pattern>, Vec<Place>),
    /// `let slot = a in body`: binds a local, then evaluates the body (an
    /// inlined `define` function's parameter).
    Let(u16, Box<Ex>, Box<Ex>),
    /// `sum(w in SET where COND)`, `avg(...)`, `count(...)`: the members
    /// of a set, which the topology lists, go into local `slot` one at a
    /// time; those that pass `cond` are counted and their `value` summed.
    Fold {
        op: FoldOp,
        slot: u16,
        set: Box<Ex>,
        cond: Option<Box<Ex>>,
        /// What is summed (absent for `count`) and its type.
        value: Option<(Box<Ex>, Ty)>,
    },
}

/// What a [`Ex::Fold`] computes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FoldOp {
    Sum,
    Avg,
    Count,
}

/// An assignable location: a variable and a path of fields and indices.
#[derive(Clone, Debug)]
pub struct Place {
    pub global: bool,
    pub slot: u16,
    pub path: Vec<Step>,
    pub ty: Ty,
    /// The declared `char` array this place is (`char b[4]`), or whose
    /// strings it holds (`char names[3][16]`): a string written into it
    /// must fit. `None` for every other place, and for a `char *`.
    pub chars: Option<Box<CharArray>>,
}

/// A declared `char` array: the most bytes a string written into it may
/// take, its terminating NUL included, and how the error that one does
/// not fit names it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CharArray {
    /// The declared size (`4` for `char b[4]`): room for one character
    /// fewer.
    pub size: usize,
    /// The destination as written (`b`, `s.name`, `names[i]`).
    pub name: String,
    /// Its declaration (`char b[4]`).
    pub decl: String,
}

impl CharArray {
    /// The error when `what` writes `v` here and a string of it does not
    /// fit with its terminating NUL (an array of strings is checked
    /// string by string); `None` when all fit.
    pub fn overflow(&self, what: &str, v: &Value) -> Option<String> {
        super::stdio::overflow_in(what, v, self.size, &self.name, &self.decl)
    }
}

/// One step into a value: a field (or vector component), or an element
/// of an array (the span locates an index out of range).
#[derive(Clone, Debug)]
pub enum Step {
    Field(u16),
    Index(Box<Ex>, Span),
}

#[derive(Clone, Copy, Debug)]
pub enum Func {
    Math1(fn(f64) -> f64),
    Math2(fn(f64, f64) -> f64),
    AbsInt,
    MinInt,
    MaxInt,
    Length,
    Normalized,
    Dot,
    Cross,
    StepNo,
    UseGroup,
    /// `UseView(v)`: view `v` is drawn too.
    UseView,
    /// `Environment()` (true) or `NoEnvironment()`: whether the
    /// interpretation that answers query modules runs before the next
    /// steps (manual 6.1.3).
    Environment(bool),
    CurrentGroup,
    Forward,
    Backward,
    IsForward,
    Stop,
    /// `ran`, `rand`, `drand48`, their seeding, the Gillespie time.
    Random(super::random::Op),
    NoOp,
    /// An accessor of the model's files (`func`, `curveX`, `val`, …),
    /// evaluated by the [`ModelData`](super::model::ModelData) of the run.
    Model(super::model::Accessor),
    /// C's standard input and output (`printf`, `fopen`, `strlen`, …);
    /// see [`super::stdio`].
    Io(super::stdio::IoFunc),
    /// What lpfg's interactive functions give in a batch run: no mouse, no
    /// menu choice, the default camera and view volume.
    Batch(Batch),
    /// A built-in of the topology the program runs on, by its number in
    /// the topology's [`HostTable`](super::builtins::HostTable); the
    /// [`Host`](super::eval::Host) evaluates it.
    Host(u16),
}

/// lpfg's functions of the mouse, the menu and the views (manual 6.4,
/// 6.5), as a run without a window answers them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Batch {
    /// `GetMouseStatus()`: no view clicked (`viewNum` -1), no button down,
    /// pushed or released, every position zero.
    MouseStatus,
    /// `UserMenuChoice()`: -1, no choice made.
    MenuChoice,
    /// `GetCameraPosition(view)`: lpfg's default view (`dir: 0 0 -1`,
    /// `up: 0 1 0`): the camera at (0, 0, 1) looking at the origin, scale 1.
    CameraPosition,
    /// `vvXmin` … `vvZmin` (0, 1, 2: x, y, z): -1.
    ViewMin(u8),
    /// `vvXmax` … `vvZmax`: 1.
    ViewMax(u8),
    /// `vvScale`: 1.
    ViewScale,
}

#[derive(Clone, Debug)]
pub enum St {
    Expr(Ex),
    /// Store the value of an expression into a fresh local.
    Init(u16, Ex),
    If(Ex, Box<St>, Option<Box<St>>),
    Loop {
        cond: Option<Ex>,
        body: Box<St>,
        step: Option<Ex>,
        /// `do { } while`: test after the body.
        test_after: bool,
        span: Span,
    },
    Block(Vec<St>),
    Produce {
        modules: Vec<Succ>,
        last: bool,
    },
    Return,
    /// `return e;` in a function.
    ReturnValue(Ex),
    Break,
    Continue,
    /// `switch`: runs `body` from the statement that the value's label
    /// points at (`cases`, sorted by value, then `default`, else nothing);
    /// a `break` ends it.
    Switch {
        value: Ex,
        cases: Vec<(i64, u32)>,
        default: Option<u32>,
        body: Vec<St>,
    },
    /// vv's `forall x in S`: local `slot` takes each member of the set (or
    /// neighbour of the vertex) that `set` gives, as the topology lists
    /// them when the loop starts; `break` and `continue` as in C.
    ForAll {
        slot: u16,
        set: Ex,
        body: Box<St>,
        span: Span,
    },
    /// vv's `add`, `remove`, `merge`: the set at `place` changed in place.
    SetEdit {
        place: Place,
        op: SetEditOp,
        elem: Ex,
    },
}

/// A successor module: a symbol and argument expressions of its types.
#[derive(Clone, Debug)]
pub struct Succ {
    pub sym: Sym,
    pub args: Vec<Ex>,
    /// The declared type of each argument (the arguments convert to it).
    pub types: Vec<Ty>,
    pub span: Span,
}

/// A module pattern in a predecessor: the symbol and the locals it binds.
#[derive(Clone, Debug)]
pub struct Pattern {
    pub sym: Sym,
    /// One local slot per parameter.
    pub slots: Vec<u16>,
    /// The type of each parameter.
    pub types: Vec<Ty>,
    /// Predefined modules with overloads match only modules whose
    /// parameters take this many slots.
    pub width: Option<usize>,
}

/// Which modules context matching looks at (`ignore:` / `consider:`).
#[derive(Clone, Debug, Default, PartialEq)]
pub enum Filter {
    #[default]
    All,
    /// The modules, sorted, without repeats; shared by the rules that
    /// follow the list, not copied into each.
    Ignore(std::sync::Arc<[Sym]>),
    Consider(std::sync::Arc<[Sym]>),
}

impl Filter {
    /// True when context matching skips module `s`. SB and EB are never
    /// skipped; callers check them before asking.
    pub fn skips(&self, s: Sym) -> bool {
        match self {
            Filter::All => false,
            Filter::Ignore(v) => v.binary_search(&s).is_ok(),
            Filter::Consider(v) => v.binary_search(&s).is_err(),
        }
    }
}

/// A production, decomposition rule or interpretation rule.
#[derive(Clone, Debug)]
pub struct Rule {
    pub new_left: Vec<Pattern>,
    pub left: Vec<Pattern>,
    pub strict: Vec<Pattern>,
    pub right: Vec<Pattern>,
    pub new_right: Vec<Pattern>,
    pub filter: Filter,
    pub body: Vec<St>,
    pub frame_size: usize,
    pub section: Section,
    pub group: i64,
    /// The view (`vgroup`) of an interpretation rule; 0 for the main view.
    pub vgroup: i64,
    pub span: Span,
    /// The rule as written, for messages: `P(vl) < P(v) > P(vr)`.
    pub label: String,
    /// Set when the body is a single `produce` of affine combinations.
    pub stencil: Option<super::stencil::Stencil>,
}

#[derive(Clone, Debug)]
pub struct GlobalVar {
    pub name: String,
    pub ty: Ty,
    pub is_const: bool,
    pub init: Option<Ex>,
}

/// A user-defined C function, checked.
#[derive(Clone, Debug)]
pub struct Function {
    pub name: String,
    pub params: Vec<Ty>,
    pub ret: Ty,
    pub body: Vec<St>,
    pub frame_size: usize,
    /// The values its parameters and local variables hold at most (an
    /// array counts its elements), for the limit on live frames.
    pub frame_values: usize,
    /// The closing brace: where a function that must return a value and
    /// reaches its end without one is reported.
    pub end: Span,
    /// A constructor's value, computed once its body has ended (it returns
    /// no value itself): the struct made of its fields' locals.
    pub result: Option<Ex>,
    /// A method's struct, written back to its first parameter (by
    /// reference) once its body has ended: the struct made of its fields'
    /// locals.
    pub this_back: Option<Ex>,
}

/// A checked, executable program.
#[derive(Clone, Debug)]
pub struct Program {
    pub alphabet: Alphabet,
    pub structs: Vec<StructDef>,
    pub globals: Vec<GlobalVar>,
    /// User-defined functions, called by `Ex::CallUser`.
    pub functions: Vec<Function>,
    pub axiom: Vec<Succ>,
    /// The directives, each with the span of the whole directive.
    pub derivation_length: Option<(Ex, Span)>,
    pub ring: Option<(Ex, Span)>,
    pub decomposition_depth: Option<(Ex, Span)>,
    pub interpretation_depth: Option<(Ex, Span)>,
    /// `angle:`: the turn of `+ - & ^ \ /` and of `Left()` without argument.
    pub angle: Option<(Ex, Span)>,
    pub rules: Vec<Rule>,
    pub control: Vec<(ControlKind, Vec<St>, usize)>,
    /// The numbers of the Gillespie groups (`ggroup N:`, manual 7.2),
    /// whose steps apply one reaction (`rewrite/gillespie.rs`), each with
    /// the span of its first `ggroup`.
    pub gillespie_groups: Vec<(i64, Span)>,
    /// What `check` reports without refusing the program.
    pub warnings: Vec<Diagnostic>,
    /// The functions, contours and colours of the model folder the program
    /// came with (empty for a program alone).
    pub model: super::model::ModelRef,
    /// `float` is single precision (lpfg's): what the turtle writes into
    /// `float` parameters (query modules' answers) is rounded to it.
    pub single: bool,
    /// The properties a vv program declares (`vertex float conc = 1;`),
    /// in the order of their numbers after each owner's built-in ones.
    pub properties: Vec<PropertyDef>,
}

/// A declared property of every element of an owner (vertex, edge, mesh).
#[derive(Clone, Debug)]
pub struct PropertyDef {
    /// The owner's number in the topology's `HostProperties::owners`.
    pub owner: u8,
    pub name: String,
    pub ty: Ty,
    /// Its number among its owner's properties (built-in ones first).
    pub index: u16,
    /// The value every new element starts with (the type's zero without
    /// an initialiser), a constant expression.
    pub init: Ex,
    pub span: Span,
}

impl Program {
    pub fn rules_of(&self, section: Section) -> impl Iterator<Item = (usize, &Rule)> {
        self.rules
            .iter()
            .enumerate()
            .filter(move |(_, r)| r.section == section)
    }
}

impl Ex {
    /// Calls `f` on `self` and on every expression inside it, each parent
    /// before its children, in the order they are written.
    pub fn walk(&self, f: &mut impl FnMut(&Ex)) {
        f(self);
        match self {
            Ex::Const(_) | Ex::Local(_) | Ex::Global(_) => {}
            Ex::Field(a, _) | Ex::Neg(a) | Ex::Not(a) | Ex::Convert(_, a) => a.walk(f),
            Ex::Bin(_, a, b, _)
            | Ex::Logic(_, a, b)
            | Ex::MakeV2(a, b)
            | Ex::Let(_, a, b)
            | Ex::Index(a, b, _) => {
                a.walk(f);
                b.walk(f);
            }
            Ex::Cond(a, b, c) | Ex::MakeV3(a, b, c) => {
                a.walk(f);
                b.walk(f);
                c.walk(f);
            }
            Ex::Load(p) | Ex::IncDec(p, _, _) => p.walk(f),
            Ex::Assign(p, _, a, _) => {
                p.walk(f);
                a.walk(f);
            }
            Ex::CallUser { args, back, .. } => {
                args.iter().for_each(|a| a.walk(f));
                back.iter().for_each(|(_, p)| p.walk(f));
            }
            Ex::Call(_, args, _) | Ex::MakeStruct(args) => args.iter().for_each(|a| a.walk(f)),
            Ex::InContext(_, _, places) => places.iter().for_each(|p| p.walk(f)),
            Ex::Fold {
                set, cond, value, ..
            } => {
                set.walk(f);
                if let Some(c) = cond {
                    c.walk(f);
                }
                if let Some((v, _)) = value {
                    v.walk(f);
                }
            }
        }
    }

    /// Calls `f` on every expression inside `self`, children before their
    /// parent, `self` last: for the specialisations of a topology, which
    /// rewrite nodes in place.
    pub fn walk_mut(&mut self, f: &mut impl FnMut(&mut Ex)) {
        match self {
            Ex::Const(_) | Ex::Local(_) | Ex::Global(_) => {}
            Ex::Field(a, _) | Ex::Neg(a) | Ex::Not(a) | Ex::Convert(_, a) => a.walk_mut(f),
            Ex::Bin(_, a, b, _)
            | Ex::Logic(_, a, b)
            | Ex::MakeV2(a, b)
            | Ex::Let(_, a, b)
            | Ex::Index(a, b, _) => {
                a.walk_mut(f);
                b.walk_mut(f);
            }
            Ex::Cond(a, b, c) | Ex::MakeV3(a, b, c) => {
                a.walk_mut(f);
                b.walk_mut(f);
                c.walk_mut(f);
            }
            Ex::Load(p) | Ex::IncDec(p, _, _) => p.walk_mut(f),
            Ex::Assign(p, _, a, _) => {
                p.walk_mut(f);
                a.walk_mut(f);
            }
            Ex::CallUser { args, back, .. } => {
                args.iter_mut().for_each(|a| a.walk_mut(f));
                back.iter_mut().for_each(|(_, p)| p.walk_mut(f));
            }
            Ex::Call(_, args, _) | Ex::MakeStruct(args) => {
                args.iter_mut().for_each(|a| a.walk_mut(f))
            }
            Ex::InContext(_, _, places) => places.iter_mut().for_each(|p| p.walk_mut(f)),
            Ex::Fold {
                set, cond, value, ..
            } => {
                set.walk_mut(f);
                if let Some(c) = cond {
                    c.walk_mut(f);
                }
                if let Some((v, _)) = value {
                    v.walk_mut(f);
                }
            }
        }
        f(self);
    }
}

impl Place {
    /// Calls [`Ex::walk`]'s `f` on the index expressions of the path.
    pub fn walk(&self, f: &mut impl FnMut(&Ex)) {
        for s in &self.path {
            if let Step::Index(e, _) = s {
                e.walk(f);
            }
        }
    }

    /// Calls `f` on the index expressions of the place's path.
    pub fn walk_mut(&mut self, f: &mut impl FnMut(&mut Ex)) {
        for s in &mut self.path {
            if let Step::Index(e, _) = s {
                e.walk_mut(f);
            }
        }
    }
}

impl St {
    /// Calls [`Ex::walk_mut`]'s `f` on every expression of the statement.
    pub fn walk_mut(&mut self, f: &mut impl FnMut(&mut Ex)) {
        match self {
            St::Expr(e) | St::Init(_, e) | St::ReturnValue(e) => e.walk_mut(f),
            St::If(c, a, b) => {
                c.walk_mut(f);
                a.walk_mut(f);
                if let Some(b) = b {
                    b.walk_mut(f);
                }
            }
            St::Loop {
                cond, body, step, ..
            } => {
                if let Some(c) = cond {
                    c.walk_mut(f);
                }
                body.walk_mut(f);
                if let Some(s) = step {
                    s.walk_mut(f);
                }
            }
            St::Block(b) => b.iter_mut().for_each(|s| s.walk_mut(f)),
            St::Produce { modules, .. } => modules
                .iter_mut()
                .for_each(|m| m.args.iter_mut().for_each(|a| a.walk_mut(f))),
            St::Return | St::Break | St::Continue => {}
            St::Switch { value, body, .. } => {
                value.walk_mut(f);
                body.iter_mut().for_each(|s| s.walk_mut(f));
            }
            St::ForAll { set, body, .. } => {
                set.walk_mut(f);
                body.walk_mut(f);
            }
            St::SetEdit { place, elem, .. } => {
                place.walk_mut(f);
                elem.walk_mut(f);
            }
        }
    }
}
