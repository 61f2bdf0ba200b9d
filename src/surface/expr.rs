//! Expressions of surface grammars: checked and compiled to a small tree
//! over frame slots, then evaluated against a mesh. Mesh elements are
//! values; a vertex used in arithmetic stands for its position.

use glam::DVec3;

use crate::mesh::{Mesh, VertexId};
use crate::syntax::ast::{BinOp, Expr, ExprKind, UnOp};
use crate::syntax::span::{Diagnostic, Span};

use super::grammar::FunctionDef;

/// Static types.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum T {
    Num,
    Vec,
    Bool,
    Vertex,
    Edge,
    Face,
    Set,
}

impl T {
    fn name(self) -> &'static str {
        match self {
            T::Num => "a number",
            T::Vec => "a point",
            T::Bool => "a condition",
            T::Vertex => "a vertex",
            T::Edge => "an edge",
            T::Face => "a face",
            T::Set => "a set of vertices",
        }
    }
}

/// A set of vertices to sum over.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SetKind {
    /// The one-ring of a vertex.
    Ring,
    /// The neighbours along the boundary.
    BoundaryRing,
    /// The vertices of an edge or a face.
    Verts,
}

#[derive(Clone, Debug)]
pub enum X {
    Num(f64),
    Slot(u16),
    Current,
    /// The number of the step being run (0 in `init:` rules).
    Step,
    /// An edge's first or second vertex (`tail`, `head`).
    EdgeEnd(bool, Box<X>),
    /// The next or previous vertex along the boundary (`bnext`, `bprev`).
    BoundaryStep(bool, Box<X>),
    Level(Box<X>),
    Pos(Box<X>),
    Valence(Box<X>),
    IsBoundary(Box<X>),
    IsBlock(Box<X>),
    IsTransversal(Box<X>),
    IsNew(Box<X>),
    IsCentre(Box<X>),
    /// The average position of an edge's or a face's vertices.
    AvgOf(Box<X>),
    Set(SetKind, Box<X>),
    Gather {
        op: u8,
        slot: u16,
        set: Box<X>,
        cond: Option<Box<X>>,
    },
    Bin(BinOp, Box<X>, Box<X>),
    /// `l(slot) OP c`, the most common condition, evaluated in one step.
    LevelVsCurrent(BinOp, u16),
    And(Box<X>, Box<X>),
    Or(Box<X>, Box<X>),
    Neg(Box<X>),
    Not(Box<X>),
    Cond(Box<X>, Box<X>, Box<X>),
    Math1(fn(f64) -> f64, Box<X>),
    Math2(fn(f64, f64) -> f64, Box<X>, Box<X>),
    Let(u16, Box<X>, Box<X>),
    MakeVec(Box<X>, Box<X>, Box<X>),
}

/// A one-ring condition evaluated without the frame.
#[derive(Clone, Copy)]
enum Fast {
    All,
    New(bool),
    Level(BinOp),
}

/// A value at run time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Val {
    N(f64),
    P(DVec3),
    B(bool),
    V(VertexId),
    /// An edge by its end vertices (captured before a split), level,
    /// whether it was on the boundary, whether it was a basic block's
    /// internal edge, and whether it was a transversal edge.
    E(VertexId, VertexId, u32, bool, bool, bool),
    /// A face by its vertices (captured before a split), level, whether
    /// one of its edges was on the boundary and whether one was a basic
    /// block's internal edge.
    F([VertexId; 3], u32, bool, bool),
    /// A set: its kind and the element it belongs to.
    S(SetKind, SetOf),
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SetOf {
    V(VertexId),
    E(VertexId, VertexId),
    F([VertexId; 3]),
}

/// Compiles expressions; keeps the functions of the grammar.
pub struct Compiler<'g> {
    functions: &'g [FunctionDef],
    scopes: Vec<(String, T, u16)>,
    next: u16,
    pub max_slots: u16,
    depth: usize,
    /// Function calls inlined so far.
    inlined: usize,
    /// Where `block` or `center` was first used, if either was.
    pub block_used_at: Option<Span>,
    /// Where `center` was first used, if it was.
    pub centre_used_at: Option<Span>,
}

type C = Result<(X, T), Diagnostic>;

/// Function calls are inlined; past this many in one rule, a grammar whose
/// functions call each other twice over would take exponential time.
const MAX_INLINED_CALLS: usize = 10_000;

fn err<A>(span: Span, m: impl Into<String>) -> Result<A, Diagnostic> {
    Err(Diagnostic::new(span, m))
}

impl<'g> Compiler<'g> {
    pub fn new(functions: &'g [FunctionDef]) -> Compiler<'g> {
        Compiler {
            functions,
            scopes: Vec::new(),
            next: 0,
            max_slots: 0,
            depth: 0,
            inlined: 0,
            block_used_at: None,
            centre_used_at: None,
        }
    }

    /// Declares a named slot (a rule's element), returning it.
    pub fn bind(&mut self, name: &str, t: T, span: Span) -> Result<u16, Diagnostic> {
        let s = self.reserve(1, span)?;
        self.scopes.push((name.to_string(), t, s));
        Ok(s)
    }

    /// Reserves `n` frame slots, returning the first. Slots are freed in
    /// stack order: a slot lives while the expression compiled after it is
    /// evaluated, so later, disjoint expressions reuse it.
    fn reserve(&mut self, n: usize, span: Span) -> Result<u16, Diagnostic> {
        let s = self.next;
        match u16::try_from(s as usize + n) {
            Ok(next) if next < u16::MAX => {
                self.next = next;
                self.max_slots = self.max_slots.max(next);
                Ok(s)
            }
            _ => err(span, "this expression needs too many variables"),
        }
    }

    fn unbind(&mut self, n: usize) {
        for _ in 0..n {
            self.scopes.pop();
        }
    }

    /// Compiles `e` and checks it has type `want`.
    pub fn compile_as(&mut self, e: &Expr, want: T) -> Result<X, Diagnostic> {
        let (x, t) = self.compile(e)?;
        match (t, want) {
            (a, b) if a == b => Ok(x),
            (T::Vertex, T::Vec) => Ok(X::Pos(Box::new(x))),
            _ => err(
                e.span,
                format!("expected {}, but this is {}", want.name(), t.name()),
            ),
        }
    }

    /// Converts a vertex to its position for arithmetic.
    fn arith(x: X, t: T) -> (X, T) {
        if t == T::Vertex {
            (X::Pos(Box::new(x)), T::Vec)
        } else {
            (x, t)
        }
    }

    pub fn compile(&mut self, e: &Expr) -> C {
        let span = e.span;
        Ok(match &e.kind {
            ExprKind::Int(i) => (X::Num(*i as f64), T::Num),
            ExprKind::Float(f) => (X::Num(*f), T::Num),
            ExprKind::Ident(n) => {
                if let Some((_, t, s)) = self.scopes.iter().rev().find(|(m, _, _)| m == n) {
                    return Ok((X::Slot(*s), *t));
                }
                match n.as_str() {
                    "c" => (X::Current, T::Num),
                    "step" => (X::Step, T::Num),
                    "PI" | "M_PI" => (X::Num(std::f64::consts::PI), T::Num),
                    "true" => (X::Num(1.0), T::Bool),
                    "false" => (X::Num(0.0), T::Bool),
                    _ => return err(span, format!("unknown identifier `{n}`")),
                }
            }
            ExprKind::Unary(op, a) => {
                let (x, t) = self.compile(a)?;
                let (x, t) = Self::arith(x, t);
                match (op, t) {
                    (UnOp::Neg, T::Num | T::Vec) => (X::Neg(Box::new(x)), t),
                    (UnOp::Plus, T::Num | T::Vec) => (x, t),
                    (UnOp::Not, T::Bool) => (X::Not(Box::new(x)), T::Bool),
                    _ => {
                        return err(
                            span,
                            format!("type error: this operator does not apply to {}", t.name()),
                        )
                    }
                }
            }
            ExprKind::Binary(op, a, b) => {
                let (xa, ta) = self.compile(a)?;
                let (xb, tb) = self.compile(b)?;
                let (xa, ta) = Self::arith(xa, ta);
                let (xb, tb) = Self::arith(xb, tb);
                use BinOp::*;
                let t = match (op, ta, tb) {
                    (And | Or, T::Bool, T::Bool) => {
                        let x = if *op == And {
                            X::And(Box::new(xa), Box::new(xb))
                        } else {
                            X::Or(Box::new(xa), Box::new(xb))
                        };
                        return Ok((x, T::Bool));
                    }
                    (Add | Sub | Mul | Div | Rem, T::Num, T::Num) => T::Num,
                    (Add | Sub, T::Vec, T::Vec) => T::Vec,
                    (Mul, T::Num, T::Vec) | (Mul, T::Vec, T::Num) | (Div, T::Vec, T::Num) => T::Vec,
                    (Lt | Le | Gt | Ge | Eq | Ne, T::Num, T::Num) => T::Bool,
                    _ => {
                        return err(
                            span,
                            format!(
                                "type error: cannot apply `{}` to {} and {}",
                                op.symbol(),
                                ta.name(),
                                tb.name()
                            ),
                        )
                    }
                };
                if t == T::Bool {
                    if let (X::Level(l), X::Current) = (&xa, &xb) {
                        if let X::Slot(s) = **l {
                            return Ok((X::LevelVsCurrent(*op, s), T::Bool));
                        }
                    }
                }
                (X::Bin(*op, Box::new(xa), Box::new(xb)), t)
            }
            ExprKind::Cond(c, a, b) => {
                let xc = self.compile_as(c, T::Bool)?;
                let (xa, ta) = self.compile(a)?;
                let (xa, ta) = Self::arith(xa, ta);
                let xb = self.compile_as(b, ta)?;
                (X::Cond(Box::new(xc), Box::new(xa), Box::new(xb)), ta)
            }
            ExprKind::Gather { op, var, set, cond } => {
                let xs = self.compile_as(set, T::Set)?;
                let slot = self.bind(&var.text, T::Vertex, var.span)?;
                let xc = match cond {
                    Some(c) => self.compile_as(c, T::Bool).map(|x| Some(Box::new(x))),
                    None => Ok(None),
                };
                self.unbind(1);
                self.next = slot;
                let xc = xc?;
                let code = match op.text.as_str() {
                    "sum" => 0,
                    "avg" => 1,
                    _ => 2,
                };
                let t = if code == 2 { T::Num } else { T::Vec };
                (
                    X::Gather {
                        op: code,
                        slot,
                        set: Box::new(xs),
                        cond: xc,
                    },
                    t,
                )
            }
            ExprKind::Call(name, args) => return self.call(&name.text, name.span, args, span),
            _ => {
                return err(
                    span,
                    "this kind of expression is not available in surface grammars",
                )
            }
        })
    }

    fn call(&mut self, name: &str, nspan: Span, args: &[Expr], span: Span) -> C {
        let one = |c: &mut Self| -> C {
            if args.len() != 1 {
                return err(span, format!("`{name}` takes one argument"));
            }
            c.compile(&args[0])
        };
        // The one argument, which must be one of `allowed`; else `what`.
        let element = |c: &mut Self, allowed: &[T], what: &str| -> Result<Box<X>, Diagnostic> {
            let (x, t) = one(c)?;
            if allowed.contains(&t) {
                Ok(Box::new(x))
            } else {
                err(span, what)
            }
        };
        let math1: Option<fn(f64) -> f64> = match name {
            "cos" => Some(f64::cos),
            "sin" => Some(f64::sin),
            "tan" => Some(f64::tan),
            "sqrt" => Some(f64::sqrt),
            "exp" => Some(f64::exp),
            "log" => Some(f64::ln),
            "fabs" | "abs" => Some(f64::abs),
            "floor" => Some(f64::floor),
            "ceil" => Some(f64::ceil),
            _ => None,
        };
        if let Some(f) = math1 {
            if args.len() != 1 {
                return err(span, format!("`{name}` takes one argument"));
            }
            let x = self.compile_as(&args[0], T::Num)?;
            return Ok((X::Math1(f, Box::new(x)), T::Num));
        }
        let math2: Option<fn(f64, f64) -> f64> = match name {
            "pow" => Some(f64::powf),
            "min" => Some(f64::min),
            "max" => Some(f64::max),
            "atan2" => Some(f64::atan2),
            _ => None,
        };
        if let Some(f) = math2 {
            if args.len() != 2 {
                return err(span, format!("`{name}` takes two arguments"));
            }
            let a = self.compile_as(&args[0], T::Num)?;
            let b = self.compile_as(&args[1], T::Num)?;
            return Ok((X::Math2(f, Box::new(a), Box::new(b)), T::Num));
        }
        match name {
            "l" => {
                let (x, t) = one(self)?;
                if !matches!(t, T::Vertex | T::Edge | T::Face) {
                    return err(
                        span,
                        format!("`l` takes a vertex, an edge or a face, not {}", t.name()),
                    );
                }
                Ok((X::Level(Box::new(x)), T::Num))
            }
            "pos" => Ok((
                X::Pos(element(self, &[T::Vertex], "`pos` takes a vertex")?),
                T::Vec,
            )),
            "valence" | "deg" => Ok((
                X::Valence(element(self, &[T::Vertex], &format!("`{name}` takes a vertex"))?),
                T::Num,
            )),
            "boundary" => Ok((
                X::IsBoundary(element(
                    self,
                    &[T::Vertex, T::Edge, T::Face],
                    "`boundary` takes a vertex, an edge or a face",
                )?),
                T::Bool,
            )),
            "block" => {
                let (x, t) = one(self)?;
                if !matches!(t, T::Edge | T::Face) {
                    return err(
                        span,
                        "`block` takes an edge (true for the internal edge of a basic block) \
                         or a face (true for half of a block)",
                    );
                }
                self.block_used_at.get_or_insert(span);
                Ok((X::IsBlock(Box::new(x)), T::Bool))
            }
            "transversal" => Ok((
                X::IsTransversal(element(
                    self,
                    &[T::Edge],
                    "`transversal` takes an edge: true for an edge that an edge split drew to an opposite vertex",
                )?),
                T::Bool,
            )),
            "tail" | "head" => Ok((
                X::EdgeEnd(
                    name == "head",
                    element(self, &[T::Edge], &format!("`{name}` takes an edge"))?,
                ),
                T::Vertex,
            )),
            "bnext" | "bprev" => Ok((
                X::BoundaryStep(
                    name == "bnext",
                    element(self, &[T::Vertex], &format!("`{name}` takes a boundary vertex"))?,
                ),
                T::Vertex,
            )),
            "new" => Ok((
                X::IsNew(element(
                    self,
                    &[T::Vertex],
                    "`new` takes a vertex: true for a vertex made in this step",
                )?),
                T::Bool,
            )),
            "center" | "centre" => {
                let (x, t) = one(self)?;
                if t != T::Vertex {
                    return err(
                        span,
                        format!(
                            "`{name}` takes a vertex: true for the centre of a dual block, \
                             whose edges are all internal edges of blocks"
                        ),
                    );
                }
                self.block_used_at.get_or_insert(span);
                self.centre_used_at.get_or_insert(span);
                Ok((X::IsCentre(Box::new(x)), T::Bool))
            }
            "ring" | "N1" | "boundary_ring" => {
                let (x, t) = one(self)?;
                if t != T::Vertex {
                    return err(span, format!("`{name}` takes a vertex"));
                }
                let k = if name == "boundary_ring" {
                    SetKind::BoundaryRing
                } else {
                    SetKind::Ring
                };
                Ok((X::Set(k, Box::new(x)), T::Set))
            }
            "verts" => Ok((
                X::Set(
                    SetKind::Verts,
                    element(self, &[T::Edge, T::Face], "`verts` takes an edge or a face")?,
                ),
                T::Set,
            )),
            "avg" => {
                let (x, t) = one(self)?;
                match t {
                    T::Edge | T::Face => Ok((X::AvgOf(Box::new(x)), T::Vec)),
                    T::Set => {
                        let slot = self.reserve(1, span)?;
                        self.next = slot;
                        Ok((
                            X::Gather {
                                op: 1,
                                slot,
                                set: Box::new(x),
                                cond: None,
                            },
                            T::Vec,
                        ))
                    }
                    _ => err(
                        span,
                        format!(
                            "`avg` takes an edge, a face or a set of vertices, not {}",
                            t.name()
                        ),
                    ),
                }
            }
            "V3f" | "point" => {
                if args.len() != 3 {
                    return err(span, format!("`{name}` takes three numbers"));
                }
                let xs: Vec<X> = args
                    .iter()
                    .map(|a| self.compile_as(a, T::Num))
                    .collect::<Result<_, _>>()?;
                let mut it = xs.into_iter();
                let (a, b, c) = (
                    it.next().expect("3"),
                    it.next().expect("3"),
                    it.next().expect("3"),
                );
                Ok((X::MakeVec(Box::new(a), Box::new(b), Box::new(c)), T::Vec))
            }
            _ => {
                let Some(f) = self.functions.iter().find(|f| f.name == name) else {
                    return err(nspan, format!("unknown function `{name}`"));
                };
                if f.params.len() != args.len() {
                    return err(
                        span,
                        format!(
                            "`{name}` takes {} argument(s), but {} were given",
                            f.params.len(),
                            args.len()
                        ),
                    );
                }
                if self.depth > 32 {
                    return err(
                        span,
                        format!("`{name}` calls itself too deeply; functions may not recurse"),
                    );
                }
                self.inlined += 1;
                if self.inlined > MAX_INLINED_CALLS {
                    return err(
                        span,
                        format!(
                            "the functions called here expand to more than {MAX_INLINED_CALLS} calls; \
                             name a shared value with a parameter instead of calling a function twice"
                        ),
                    );
                }
                // Inline: the parameters get slots reserved before the
                // arguments are compiled, so no argument's temporaries can
                // overwrite a parameter set before it; then the body.
                let first = self.reserve(args.len(), span)?;
                let result = self.inline(f, args, first);
                self.next = first;
                result
            }
        }
    }

    /// The body of `f` with its parameters, from slot `first` on, bound to
    /// `args`.
    fn inline(&mut self, f: &FunctionDef, args: &[Expr], first: u16) -> C {
        let mut lets = Vec::with_capacity(args.len());
        for a in args {
            lets.push(self.compile(a)?);
        }
        let saved: Vec<(String, T, u16)> = std::mem::take(&mut self.scopes);
        for (i, (p, (_, t))) in f.params.iter().zip(&lets).enumerate() {
            self.scopes.push((p.clone(), *t, first + i as u16));
        }
        self.depth += 1;
        let body = self.compile(&f.body);
        self.depth -= 1;
        self.scopes = saved;
        let (mut x, t) = body.map_err(|d| {
            // The caret points into the body; name the function once, at
            // the innermost call.
            if d.message.contains(" (in `") {
                d
            } else {
                Diagnostic::new(d.span, format!("{} (in `{}`)", d.message, f.name))
            }
        })?;
        for (i, (a, _)) in lets.into_iter().enumerate().rev() {
            x = X::Let(first + i as u16, Box::new(a), Box::new(x));
        }
        Ok((x, t))
    }
}

/// Evaluates compiled expressions against a mesh.
pub struct Eval<'m> {
    pub mesh: &'m Mesh,
    pub current: u32,
}

/// A vertex that does not exist: a position of NaN, which the rule that
/// asked reports as not finite.
const NO_VERTEX: Val = Val::N(f64::NAN);

impl Eval<'_> {
    pub fn eval(&self, x: &X, frame: &mut [Val]) -> Val {
        match x {
            X::Num(n) => Val::N(*n),
            X::Slot(s) => frame[*s as usize],
            X::Current => Val::N(self.current as f64),
            X::Step => Val::N(self.mesh.step as f64),
            X::EdgeEnd(head, a) => match self.eval(a, frame) {
                Val::E(p, q, ..) => Val::V(if *head { q } else { p }),
                _ => NO_VERTEX,
            },
            X::BoundaryStep(forward, a) => match self.eval(a, frame) {
                Val::V(v) => self
                    .mesh
                    .boundary_neighbour(v, *forward)
                    .map_or(NO_VERTEX, Val::V),
                _ => NO_VERTEX,
            },
            X::Level(a) => Val::N(match self.eval(a, frame) {
                Val::V(v) => self.mesh.vertex_level(v) as f64,
                Val::E(_, _, l, _, _, _) => l as f64,
                Val::F(_, l, _, _) => l as f64,
                _ => f64::NAN,
            }),
            X::Pos(a) => match self.eval(a, frame) {
                Val::V(v) => Val::P(self.mesh.position(v)),
                other => other,
            },
            X::Valence(a) => match self.eval(a, frame) {
                Val::V(v) => Val::N(self.mesh.valence(v) as f64),
                _ => Val::N(f64::NAN),
            },
            X::IsBoundary(a) => Val::B(match self.eval(a, frame) {
                Val::V(v) => self.mesh.is_boundary_vertex(v),
                Val::E(_, _, _, b, _, _) => b,
                Val::F(_, _, b, _) => b,
                _ => false,
            }),
            X::IsBlock(a) => Val::B(match self.eval(a, frame) {
                Val::E(_, _, _, _, b, _) => b,
                Val::F(_, _, _, b) => b,
                _ => false,
            }),
            X::IsTransversal(a) => {
                Val::B(matches!(self.eval(a, frame), Val::E(_, _, _, _, _, true)))
            }
            X::IsNew(a) => Val::B(match self.eval(a, frame) {
                Val::V(v) => self.mesh.is_new_vertex(v),
                _ => false,
            }),
            X::IsCentre(a) => Val::B(match self.eval(a, frame) {
                Val::V(v) => self.mesh.is_block_centre(v),
                _ => false,
            }),
            X::AvgOf(a) => match self.eval(a, frame) {
                Val::E(p, q, _, _, _, _) => {
                    Val::P((self.mesh.position(p) + self.mesh.position(q)) * 0.5)
                }
                Val::F(vs, ..) => {
                    Val::P(vs.iter().map(|v| self.mesh.position(*v)).sum::<DVec3>() / 3.0)
                }
                _ => Val::P(DVec3::NAN),
            },
            X::Set(k, a) => {
                let of = match self.eval(a, frame) {
                    Val::V(v) => SetOf::V(v),
                    Val::E(p, q, _, _, _, _) => SetOf::E(p, q),
                    Val::F(vs, ..) => SetOf::F(vs),
                    // No element (bnext of an interior vertex): no set, and
                    // whatever is made from it is not finite.
                    _ => return NO_VERTEX,
                };
                Val::S(*k, of)
            }
            X::Gather {
                op,
                slot,
                set,
                cond,
            } => {
                let Val::S(kind, of) = self.eval(set, frame) else {
                    return if *op == 2 {
                        Val::N(f64::NAN)
                    } else {
                        Val::P(DVec3::NAN)
                    };
                };
                let mut sum = DVec3::ZERO;
                let mut count = 0usize;
                // The common conditions on a one-ring, tested without the
                // frame: none, `l(w) OP c`, `new(w)` and `!new(w)`.
                let fast = match cond.as_deref() {
                    None => Some(Fast::All),
                    Some(X::LevelVsCurrent(op, s)) if s == slot => Some(Fast::Level(*op)),
                    Some(X::IsNew(a)) if matches!(**a, X::Slot(s) if s == *slot) => {
                        Some(Fast::New(true))
                    }
                    Some(X::Not(n)) if matches!(&**n, X::IsNew(a) if matches!(**a, X::Slot(s) if s == *slot)) => {
                        Some(Fast::New(false))
                    }
                    _ => None,
                };
                let c = self.current;
                let keep = |f: Fast, w: VertexId| match f {
                    Fast::All => true,
                    Fast::New(b) => self.mesh.is_new_vertex(w) == b,
                    Fast::Level(op) => {
                        let l = self.mesh.vertex_level(w);
                        match op {
                            BinOp::Lt => l < c,
                            BinOp::Le => l <= c,
                            BinOp::Gt => l > c,
                            BinOp::Ge => l >= c,
                            BinOp::Eq => l == c,
                            _ => l != c,
                        }
                    }
                };
                if let (Some(fast), SetKind::Ring, SetOf::V(v)) = (fast, kind, of) {
                    for w in self.mesh.one_ring(v) {
                        if keep(fast, w) {
                            sum += self.mesh.position(w);
                            count += 1;
                        }
                    }
                    return match op {
                        0 => Val::P(sum),
                        1 => Val::P(if count > 0 {
                            sum / count as f64
                        } else {
                            DVec3::NAN
                        }),
                        _ => Val::N(count as f64),
                    };
                }
                let mut visit = |w: VertexId, frame: &mut [Val]| {
                    frame[*slot as usize] = Val::V(w);
                    let ok = match cond {
                        Some(c) => matches!(self.eval(c, frame), Val::B(true)),
                        None => true,
                    };
                    if ok {
                        sum += self.mesh.position(w);
                        count += 1;
                    }
                };
                match (kind, of) {
                    (SetKind::Ring, SetOf::V(v)) => {
                        for w in self.mesh.one_ring(v) {
                            visit(w, frame);
                        }
                    }
                    (SetKind::BoundaryRing, SetOf::V(v)) => {
                        for h in self.mesh.outgoing_halfedges(v) {
                            if self.mesh.is_boundary_edge(h.edge()) {
                                visit(self.mesh.to(h), frame);
                            }
                        }
                    }
                    (_, SetOf::E(p, q)) => {
                        visit(p, frame);
                        visit(q, frame);
                    }
                    (_, SetOf::F(vs)) => {
                        for w in vs {
                            visit(w, frame);
                        }
                    }
                    _ => {}
                }
                match op {
                    0 => Val::P(sum),
                    1 => Val::P(if count > 0 {
                        sum / count as f64
                    } else {
                        DVec3::NAN
                    }),
                    _ => Val::N(count as f64),
                }
            }
            X::Bin(op, a, b) => {
                let (va, vb) = (self.eval(a, frame), self.eval(b, frame));
                use BinOp::*;
                match (va, vb) {
                    (Val::N(x), Val::N(y)) => match op {
                        Add => Val::N(x + y),
                        Sub => Val::N(x - y),
                        Mul => Val::N(x * y),
                        Div => Val::N(x / y),
                        Rem => Val::N(x.rem_euclid(y)),
                        Lt => Val::B(x < y),
                        Le => Val::B(x <= y),
                        Gt => Val::B(x > y),
                        Ge => Val::B(x >= y),
                        Eq => Val::B(x == y),
                        Ne => Val::B(x != y),
                        _ => Val::N(f64::NAN),
                    },
                    (Val::P(x), Val::P(y)) => Val::P(if *op == Add { x + y } else { x - y }),
                    (Val::N(s), Val::P(p)) | (Val::P(p), Val::N(s)) if *op == Mul => Val::P(p * s),
                    (Val::P(p), Val::N(s)) => Val::P(p / s),
                    _ => Val::N(f64::NAN),
                }
            }
            X::LevelVsCurrent(op, s) => {
                let l = match frame[*s as usize] {
                    Val::V(v) => self.mesh.vertex_level(v),
                    Val::E(_, _, l, _, _, _) => l,
                    Val::F(_, l, _, _) => l,
                    _ => return Val::B(false),
                };
                let c = self.current;
                Val::B(match op {
                    BinOp::Lt => l < c,
                    BinOp::Le => l <= c,
                    BinOp::Gt => l > c,
                    BinOp::Ge => l >= c,
                    BinOp::Eq => l == c,
                    BinOp::Ne => l != c,
                    _ => false,
                })
            }
            X::And(a, b) => Val::B(
                matches!(self.eval(a, frame), Val::B(true))
                    && matches!(self.eval(b, frame), Val::B(true)),
            ),
            X::Or(a, b) => Val::B(
                matches!(self.eval(a, frame), Val::B(true))
                    || matches!(self.eval(b, frame), Val::B(true)),
            ),
            X::Neg(a) => match self.eval(a, frame) {
                Val::N(n) => Val::N(-n),
                Val::P(p) => Val::P(-p),
                other => other,
            },
            X::Not(a) => Val::B(!matches!(self.eval(a, frame), Val::B(true))),
            X::Cond(c, a, b) => {
                if matches!(self.eval(c, frame), Val::B(true)) {
                    self.eval(a, frame)
                } else {
                    self.eval(b, frame)
                }
            }
            X::Math1(f, a) => match self.eval(a, frame) {
                Val::N(n) => Val::N(f(n)),
                _ => Val::N(f64::NAN),
            },
            X::Math2(f, a, b) => match (self.eval(a, frame), self.eval(b, frame)) {
                (Val::N(x), Val::N(y)) => Val::N(f(x, y)),
                _ => Val::N(f64::NAN),
            },
            X::Let(s, a, body) => {
                let v = self.eval(a, frame);
                frame[*s as usize] = v;
                self.eval(body, frame)
            }
            X::MakeVec(a, b, c) => match (
                self.eval(a, frame),
                self.eval(b, frame),
                self.eval(c, frame),
            ) {
                (Val::N(x), Val::N(y), Val::N(z)) => Val::P(DVec3::new(x, y, z)),
                _ => Val::P(DVec3::NAN),
            },
        }
    }
}
