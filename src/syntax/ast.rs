//! The syntax tree of an `.lsys` file: plain data, no geometry, no types
//! resolved. `lang::compile` turns it into an executable program.

use super::span::Span;

#[derive(Clone, Debug, PartialEq)]
pub struct Name {
    pub text: String,
    pub span: Span,
}

/// A type as written: `int`, `float`, `V2f`, or a struct/typedef name.
#[derive(Clone, Debug, PartialEq)]
pub struct TypeRef {
    pub name: String,
    pub span: Span,
    /// Written with a `*`: `char *s` (a string), `FILE *f`, `float *a` (a
    /// parameter that takes an array).
    pub pointer: bool,
    /// Written with C++'s `&`: a parameter passed by reference.
    pub reference: bool,
}

#[derive(Clone, Debug, PartialEq)]
pub struct File {
    pub items: Vec<Item>,
    /// The file uses the single-character turtle of The Algorithmic Beauty
    /// of Plants (it has an `angle:` directive): `F+F[-X]` is a module list,
    /// and undeclared modules are declared from their use.
    pub abop: bool,
}

#[derive(Clone, Debug, PartialEq)]
pub enum Item {
    /// `module P(V2f);`
    Module {
        name: Name,
        params: Vec<TypeRef>,
    },
    /// `struct Data { float length, area; float v[3]; };`: each field with
    /// its array dimensions, the enums declared inside, the constructors.
    Struct {
        name: Name,
        body: StructBody,
    },
    /// `typedef float real;`
    Typedef {
        ty: TypeRef,
        name: Name,
    },
    /// `V2f v1(0, 0), v2(0, 1);`, `const int Delay = 2;`
    Global(VarDecl),
    /// `derivation length: expr;` and the other `key: expr;` directives.
    Directive {
        kind: DirectiveKind,
        expr: Expr,
        span: Span,
    },
    /// `Axiom: P(v1) P(v2);`
    Axiom {
        modules: Vec<ModuleCall>,
        span: Span,
    },
    /// `ignore: A B;` (`consider == false`) or `consider: A B;`.
    ContextFilter {
        consider: bool,
        names: Vec<Name>,
        span: Span,
    },
    /// `production:`, `decomposition:` or `interpretation:`.
    Section {
        section: Section,
        span: Span,
    },
    /// `group 1:`, or `ggroup 1:` (`gillespie`, manual 7.2); `endgroup`
    /// is `Group { id: 0 }`.
    Group {
        id: i64,
        gillespie: bool,
        span: Span,
    },
    /// `vgroup 1:` (or `window 1:`): the interpretation rules of a view
    /// (manual 7.3); `endvgroup` is `VGroup { id: 0 }`.
    VGroup {
        id: i64,
        span: Span,
    },
    /// `Start: { ... }` and friends.
    Control {
        kind: ControlKind,
        body: Block,
        span: Span,
    },
    Production(Production),
    /// `float f(float x, V2f p) { ... }`, or a declaration without a body
    /// (`float f(float);`).
    Function(FunctionDef),
    /// `enum Kind { A, B = 5, C };`
    Enum {
        name: Option<Name>,
        variants: Vec<(Name, Option<Expr>)>,
    },
    /// A vv program's property of every vertex, directed edge or of the
    /// mesh: `vertex float conc = 1;`, `edge int kind;`, `mesh int cells;`.
    Property {
        /// `vertex`, `edge` or `mesh`.
        owner: Name,
        ty: TypeRef,
        name: Name,
        init: Option<Expr>,
    },
}

/// An enum's enumerators, each with its value if one is written.
pub type Enumerators = Vec<(Name, Option<Expr>)>;

/// What a struct's braces hold.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StructBody {
    /// Each field with its array dimensions.
    pub fields: Vec<(TypeRef, Name, Vec<Option<Expr>>)>,
    /// `enum { A, B } kind;`: enums declared inside, whose enumerators are
    /// constants, also as `Struct::A`.
    pub enums: Vec<(Option<Name>, Enumerators)>,
    pub ctors: Vec<Ctor>,
    /// Methods: functions whose body sees the fields by their names.
    pub methods: Vec<FunctionDef>,
}

/// A C++ constructor: `S(float x) : v(x), n(2) { body }`.
#[derive(Clone, Debug, PartialEq)]
pub struct Ctor {
    pub name: Name,
    pub params: Vec<Param>,
    /// The initialiser list: each field with its arguments and the span of
    /// the parenthesised arguments.
    pub inits: Vec<(Name, Vec<Expr>, Span)>,
    pub body: Block,
}

/// A user-defined C function.
#[derive(Clone, Debug, PartialEq)]
pub struct FunctionDef {
    pub ret: TypeRef,
    pub name: Name,
    pub params: Vec<Param>,
    /// `None` for a forward declaration.
    pub body: Option<Block>,
}

/// A function parameter: `float x`, `float a[]`, `int m[3][3]`, `V2f &p`.
#[derive(Clone, Debug, PartialEq)]
pub struct Param {
    pub ty: TypeRef,
    /// Absent in a declaration such as `float f(float);`.
    pub name: Option<Name>,
    /// Array dimensions; `None` for `[]`.
    pub dims: Vec<Option<Expr>>,
    /// Written with `const` (`const char *s`).
    pub is_const: bool,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DirectiveKind {
    DerivationLength,
    /// `angle: 90;`, the turning angle of `+ - & ^ \ /`.
    Angle,
    Ring,
    MaximumDepth,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Section {
    Productions,
    Decomposition,
    Interpretation,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ControlKind {
    Start,
    StartEach,
    EndEach,
    End,
    /// A vv program's `Step: { ... }`, once per derivation step.
    Step,
}

#[derive(Clone, Debug, PartialEq)]
pub struct VarDecl {
    pub ty: TypeRef,
    pub is_const: bool,
    /// `static`: a local keeps its value from call to call.
    pub is_static: bool,
    pub vars: Vec<Declarator>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Declarator {
    pub name: Name,
    /// Array dimensions (`float a[3][2]`); `None` for `[]`, sized by the
    /// initializer.
    pub dims: Vec<Option<Expr>>,
    /// Written `*name`: a pointer (a string or a file handle).
    pub pointer: bool,
    pub init: Init,
}

#[derive(Clone, Debug, PartialEq)]
pub enum Init {
    None,
    /// `= expr`
    Expr(Expr),
    /// `v(0, 1)`: constructor arguments.
    Ctor(Vec<Expr>, Span),
    /// `= {1, 0}`: an aggregate initializer.
    List(Vec<Expr>, Span),
}

/// A module with argument expressions: in an axiom or a successor.
#[derive(Clone, Debug, PartialEq)]
pub struct ModuleCall {
    pub name: Name,
    pub args: Vec<Expr>,
}

/// A module with formal parameter names: in a predecessor or a context test.
#[derive(Clone, Debug, PartialEq)]
pub struct PatModule {
    pub name: Name,
    pub params: Vec<Name>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Production {
    pub new_left: Vec<PatModule>,
    pub left: Vec<PatModule>,
    pub strict: Vec<PatModule>,
    pub right: Vec<PatModule>,
    pub new_right: Vec<PatModule>,
    pub body: Body,
    /// The predecessor, for messages.
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub enum Body {
    Block(Block),
    /// `pred -> succ`: the paper's one-line form, same as `{ produce succ; }`.
    Arrow(Vec<ModuleCall>, Span),
}

#[derive(Clone, Debug, PartialEq)]
pub struct Block {
    pub stmts: Vec<Stmt>,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub enum Stmt {
    Expr(Expr),
    Decl(VarDecl),
    If {
        cond: Expr,
        then: Box<Stmt>,
        els: Option<Box<Stmt>>,
    },
    While {
        cond: Expr,
        body: Box<Stmt>,
        /// The `while` keyword.
        span: Span,
    },
    DoWhile {
        body: Box<Stmt>,
        cond: Expr,
        span: Span,
    },
    For {
        init: Option<Box<Stmt>>,
        cond: Option<Expr>,
        step: Option<Expr>,
        body: Box<Stmt>,
        span: Span,
    },
    Block(Block),
    /// `produce ...;` (`last == true`) or `nproduce ...;`.
    Produce {
        modules: Vec<ModuleCall>,
        last: bool,
        span: Span,
    },
    /// `return;` or `return expr;`
    Return(Option<Expr>, Span),
    Break(Span),
    Continue(Span),
    /// `switch (value) { ... }`: the body's statements, among them its
    /// `case` and `default` labels.
    Switch {
        value: Expr,
        body: Vec<Stmt>,
        /// The `switch` keyword.
        span: Span,
    },
    /// `case expr:`, a label directly in a `switch`'s body.
    Case(Expr, Span),
    /// `default:`, a label directly in a `switch`'s body.
    Default(Span),
    /// vv's `forall x in S body`: `var` takes each member of the set (or
    /// each neighbour of the vertex) `set` holds when the loop starts.
    Forall {
        var: Name,
        set: Expr,
        body: Box<Stmt>,
        span: Span,
    },
    /// vv's `add v to S;`, `remove v from S;`, `merge S with T;`: the set
    /// `set` (a variable) changed in place by `elem`.
    SetEdit {
        op: SetEditOp,
        elem: Expr,
        set: Expr,
        span: Span,
    },
    Empty,
}

/// What a [`Stmt::SetEdit`] does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SetEditOp {
    Add,
    Remove,
    Merge,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BinOp {
    Add,
    Sub,
    Mul,
    Div,
    Rem,
    Lt,
    Le,
    Gt,
    Ge,
    Eq,
    Ne,
    And,
    Or,
    BitAnd,
    BitOr,
    BitXor,
    Shl,
    Shr,
}

impl BinOp {
    pub fn symbol(self) -> &'static str {
        match self {
            BinOp::Add => "+",
            BinOp::Sub => "-",
            BinOp::Mul => "*",
            BinOp::Div => "/",
            BinOp::Rem => "%",
            BinOp::Lt => "<",
            BinOp::Le => "<=",
            BinOp::Gt => ">",
            BinOp::Ge => ">=",
            BinOp::Eq => "==",
            BinOp::Ne => "!=",
            BinOp::And => "&&",
            BinOp::Or => "||",
            BinOp::BitAnd => "&",
            BinOp::BitOr => "|",
            BinOp::BitXor => "^",
            BinOp::Shl => "<<",
            BinOp::Shr => ">>",
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UnOp {
    Neg,
    Plus,
    Not,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ContextKind {
    Left,
    Right,
    NewLeft,
    NewRight,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Expr {
    pub kind: ExprKind,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub enum ExprKind {
    Int(i64),
    /// A floating literal; `true` when it has an `f` suffix (a `float`,
    /// its value the nearest single-precision one), else a `double`.
    Float(f64, bool),
    Str(String),
    Ident(String),
    Unary(UnOp, Box<Expr>),
    Binary(BinOp, Box<Expr>, Box<Expr>),
    /// `lhs = rhs` (`op == None`) or `lhs op= rhs`.
    Assign(Option<BinOp>, Box<Expr>, Box<Expr>),
    /// `++x` / `--x` (`prefix`) or `x++` / `x--`; `delta` is +1 or -1.
    IncDec {
        target: Box<Expr>,
        delta: i8,
        prefix: bool,
    },
    Cond(Box<Expr>, Box<Expr>, Box<Expr>),
    Call(Name, Vec<Expr>),
    Method(Box<Expr>, Name, Vec<Expr>),
    Field(Box<Expr>, Name),
    /// `a[i]`
    Index(Box<Expr>, Box<Expr>),
    /// `{1, 2}` inside an aggregate initializer.
    List(Vec<Expr>),
    Cast(TypeRef, Box<Expr>),
    InContext(ContextKind, Vec<PatModule>),
    /// `sum(w in SET where COND)` (also `avg`, `count`): an aggregate over
    /// the members of a set, for topologies whose elements have sets (a
    /// mesh vertex's one-ring).
    Gather {
        op: Name,
        var: Name,
        set: Box<Expr>,
        cond: Option<Box<Expr>>,
    },
    /// vv's `v$pos`, `(p, q)$w`, `mesh$cells`: a property of an element.
    Prop(Box<Expr>, Name),
}

/// `define f(a, b) = expr;`: a function whose body is inlined at each
/// call, its parameters taking the types of the arguments.
#[derive(Clone, Debug, PartialEq)]
pub struct Define {
    pub name: String,
    pub params: Vec<String>,
    pub body: Expr,
    pub span: Span,
}
