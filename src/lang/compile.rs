//! Name resolution and type checking: [`ast::File`] to [`Program`].
//!
//! Every problem found is reported; compilation goes on after an error so
//! that `subgram check` can list all of them at once.

use std::collections::{HashMap, HashSet};
use std::rc::Rc;

use crate::syntax::ast::{self, BinOp, ExprKind, Init, Item, Section, UnOp};
use crate::syntax::parse::MAX_NESTING;
use crate::syntax::span::{Diagnostic, Span};

use super::builtins::{self, HostTable, SigError, LIBRARY, WORD_HOST};
use super::ir::*;
use super::modules::{Alphabet, Signature, Sym};
use super::value::{StructDef, Ty, Value};

/// How a program computes C's `float` (and `V2f`, `V3f`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Precision {
    /// Single precision, as lpfg compiles L+C: every `float` result and
    /// every conversion to `float` is rounded where C rounds it.
    #[default]
    Single,
    /// Every `float` is a `double`: for precision work, and for topologies
    /// whose coordinates are doubles (surface grammars).
    Double,
}

/// Compiles a program whose `float` has the given precision.
pub fn compile_with(file: &ast::File, precision: Precision) -> Result<Program, Vec<Diagnostic>> {
    compile_on(file, precision, &WORD_HOST)
}

/// Compiles a whole program (functions, globals, control blocks) for a
/// topology whose elements and built-ins `host` lists: words, or a vv
/// program's rotation system.
pub fn compile_on(
    file: &ast::File,
    precision: Precision,
    host: &'static HostTable,
) -> Result<Program, Vec<Diagnostic>> {
    let mut c = Compiler::new(host, Vec::new());
    c.single = precision == Precision::Single;
    // The predefined structs' single-precision fields follow too.
    if !c.single {
        for d in &mut c.structs {
            for (_, t) in &mut d.fields {
                *t = t.widened();
            }
        }
    }
    c.declarations(file);
    if file.abop {
        c.declare_from_use(file);
    }
    let mut program = c.rules_and_directives(file);
    if c.diags.is_empty() {
        c.warnings.sort_by_key(|d| (d.span.file.0, d.span.start));
        program.warnings = c.warnings;
        Ok(program)
    } else {
        c.diags.sort_by_key(|d| (d.span.file.0, d.span.start));
        Err(c.diags)
    }
}

/// Compiles the guards and successor expressions of rules on a topology
/// other than words (a surface grammar's conditions and assignments): the
/// same checker as curve bodies, with the topology's elements and host
/// built-ins from its [`HostTable`], and `define` functions inlined.
pub struct RuleCompiler {
    c: Compiler,
    scope: Scope,
}

impl RuleCompiler {
    pub fn new(host: &'static HostTable, functions: &[ast::Define]) -> RuleCompiler {
        RuleCompiler {
            c: Compiler::new(host, functions.to_vec()),
            scope: Scope::rule(),
        }
    }

    /// A fresh rule: no locals bound, the inlining budget renewed.
    pub fn start_rule(&mut self) {
        self.scope = Scope::rule();
        self.c.inlined = 0;
    }

    /// Binds `name` to a new local of type `ty`: the predecessor's element.
    pub fn bind(&mut self, name: &str, ty: Ty) -> u16 {
        self.scope.declare(name, ty)
    }

    /// Compiles `e`, which must have type `want` (an element used as a
    /// number or a vector reads as one, a number converts as in C).
    pub fn expr_as(&mut self, e: &ast::Expr, want: Ty) -> Option<Ex> {
        let (ex, ty) = self.c.expr(e, &mut self.scope)?;
        if want == Ty::Bool {
            return self.c.condition_of(ex, ty, e.span);
        }
        self.c.coerce(ex, ty, want, e.span)
    }

    /// Compiles `e` whatever its type.
    pub fn expr(&mut self, e: &ast::Expr) -> Option<(Ex, Ty)> {
        self.c.expr(e, &mut self.scope)
    }

    /// The locals the rule compiled so far needs.
    pub fn frame_size(&self) -> usize {
        self.scope.max as usize
    }

    /// The errors and the warnings found so far, taken.
    pub fn take_diagnostics(&mut self) -> (Vec<Diagnostic>, Vec<Diagnostic>) {
        (
            std::mem::take(&mut self.c.diags),
            std::mem::take(&mut self.c.warnings),
        )
    }
}

struct Compiler {
    alphabet: Alphabet,
    structs: Vec<StructDef>,
    typedefs: HashMap<String, Ty>,
    globals: Vec<GlobalVar>,
    global_names: HashMap<String, u16>,
    diags: Vec<Diagnostic>,
    warnings: Vec<Diagnostic>,
    /// The topology's elements and built-ins.
    host: &'static HostTable,
    /// `define` functions, inlined where they are called, shared so that
    /// inlining one does not copy its body.
    functions: Rc<[ast::Define]>,
    /// Each function's index in `functions`, by name (the first of a name).
    function_names: HashMap<String, usize>,
    /// How many expressions enclose the one being compiled, counting those
    /// of the functions being inlined.
    depth: usize,
    /// Functions being inlined, innermost last (they may not recurse).
    inlining: Vec<usize>,
    /// Calls inlined in the current rule.
    inlined: usize,
    /// Each struct's index by name, its fields' indices by name, and its
    /// size: the values it holds and how deeply structs nest in it.
    struct_names: HashMap<String, u16>,
    struct_fields: Vec<HashMap<String, u16>>,
    struct_shapes: Vec<(usize, usize)>,
    /// The values the globals and `static` locals hold in all.
    global_values: usize,
    /// The limits on counts already reported: each is reported once.
    counts_reported: HashSet<&'static str>,
    /// Where a division of two integers was compiled.
    int_divisions: Vec<Span>,
    /// Parameters of the functions being inlined whose argument is a
    /// division of integer constants that truncates, with that division:
    /// the truncation warning follows them into the body.
    truncating: Vec<(u16, Ex)>,
    /// `float` is single precision (lpfg's); otherwise every `float`,
    /// `V2f` and `V3f` is read as `double`, `V2d`, `V3d`.
    single: bool,
    /// The properties the program declares, by owner and name (vv).
    props: Vec<DeclaredProp>,
    /// User-defined C functions' signatures, by number, and their numbers
    /// by name.
    user_fns: Vec<UserSig>,
    user_fn_names: HashMap<String, u16>,
    /// "Did you mean" hints given so far: past [`MAX_HINTS`] none is
    /// looked for (a million misspelt names cost a million searches).
    hints: usize,
    /// `enum` constants; those declared in a struct also as `S::NAME`.
    enum_consts: HashMap<String, i64>,
    /// Enumerators declared in a struct that `NAME` alone names (no
    /// enumerator outside structs has that name), and those that more than
    /// one struct declares, which only `S::NAME` names.
    struct_enums: HashSet<String>,
    ambiguous_enums: HashSet<String>,
    /// Each struct's constructors (user functions), by the struct's name.
    ctors: HashMap<String, Vec<u16>>,
    /// Struct methods (user functions whose first parameter is the struct,
    /// by reference), by the struct's number and the method's name.
    methods: HashMap<(u16, String), u16>,
    /// The array types made so far, by element type and length.
    array_types: HashMap<(Ty, Option<usize>), u16>,
    /// The globals (and `static` locals) declared as `char` arrays, by
    /// slot: the strings written into them must fit.
    global_chars: HashMap<u16, CharArray>,
    /// The struct fields declared as `char` arrays, by struct and field.
    field_chars: HashMap<(u16, u16), CharArray>,
}

/// A user-defined function as its callers see it.
#[derive(Clone, Debug)]
struct UserSig {
    name: String,
    /// Each parameter's type, and whether it is passed by reference (an
    /// array, or C++'s `float &x`): written back to the caller's variable.
    params: Vec<(Ty, bool)>,
    ret: Ty,
    span: Span,
    /// Whether a body has been given.
    defined: bool,
}

/// The most elements of an array whose structs a constructor builds, one
/// call each.
const MAX_BUILT_ELEMENTS: usize = 1 << 16;

/// The most user-defined functions a program may declare (each is
/// numbered with a `u16`).
const MAX_USER_FUNCTIONS: usize = u16::MAX as usize;

/// Function calls are inlined; past this many in one rule, functions that
/// call each other twice over would take exponential time.
const MAX_INLINED_CALLS: usize = 10_000;

/// Functions calling functions nest no deeper than this (as in the
/// surface grammars' checker before the one language): each level adds a
/// body's nesting to the checked expression, which the checker, the
/// specialisations and the interpreter walk recursively.
const MAX_INLINE_DEPTH: usize = 32;

/// The most "did you mean" hints one program's check looks for (as many
/// as the errors shown).
const MAX_HINTS: usize = 100;

/// Local variables of one body, with nested block scopes.
#[derive(Default)]
struct Scope {
    vars: Vec<(String, Ty, u16)>,
    /// Where each name is in `vars`, innermost last: a lookup does not
    /// walk the body's variables.
    by_name: HashMap<String, Vec<usize>>,
    marks: Vec<usize>,
    /// Slots of `const` locals.
    consts: HashSet<u16>,
    next: u16,
    max: u16,
    loops: u32,
    /// `switch`es around the statement being checked: `break` may end one.
    switches: u32,
    in_rule: bool,
    /// Names before this index are not visible (the caller's locals,
    /// inside an inlined function's body).
    barrier: usize,
    /// The body asked for more locals than slots can number.
    full: bool,
    /// ... and that has been reported.
    full_reported: bool,
    /// Indices in `vars` of `static` locals, whose slots are globals'.
    statics: HashSet<usize>,
    /// In a function: its return type and name.
    ret: Option<(Ty, String)>,
    /// The values its locals hold in all (an array counts its elements).
    values: usize,
    /// The locals declared as `char` arrays, by index in `vars`.
    chars: HashMap<usize, CharArray>,
}

/// The most local variables one body may have (their slots are `u16`s).
const MAX_LOCALS: usize = u16::MAX as usize;

/// The most modules, globals, structs, or fields in one struct, that a
/// program may declare: each is numbered with a `u16`.
const MAX_DECLARED: usize = u16::MAX as usize;

/// The most values a struct may hold, counting those of the structs
/// inside it: every value of the type is built that large.
const MAX_STRUCT_VALUES: usize = 1 << 16;

impl Scope {
    fn rule() -> Scope {
        Scope {
            in_rule: true,
            ..Scope::default()
        }
    }

    fn push(&mut self) {
        self.marks.push(self.vars.len());
    }

    fn pop(&mut self) {
        let m = self.marks.pop().expect("balanced scopes");
        self.truncate(m);
    }

    /// Forgets the variables from the `len`th on.
    fn truncate(&mut self, len: usize) {
        self.statics.retain(|&i| i < len);
        if !self.chars.is_empty() {
            self.chars.retain(|&i, _| i < len);
        }
        for (name, _, _) in self.vars.drain(len.min(self.vars.len())..) {
            if let Some(at) = self.by_name.get_mut(&name) {
                at.pop();
                if at.is_empty() {
                    self.by_name.remove(&name);
                }
            }
        }
    }

    /// Names `slot`, already reserved, `name`.
    fn bind(&mut self, name: &str, ty: Ty, slot: u16) {
        self.by_name
            .entry(name.to_string())
            .or_default()
            .push(self.vars.len());
        self.vars.push((name.to_string(), ty, slot));
    }

    /// Reserves `n` slots and returns the first; `None` when they would
    /// not fit.
    fn reserve(&mut self, n: usize) -> Option<u16> {
        if self.next as usize + n > MAX_LOCALS {
            self.full = true;
            return None;
        }
        let first = self.next;
        self.next += n as u16;
        self.max = self.max.max(self.next);
        Some(first)
    }

    /// A new local; when the slots have run out, slot 0 stands in and
    /// `full` is set for the caller to report.
    fn declare(&mut self, name: &str, ty: Ty) -> u16 {
        let slot = self.reserve(1).unwrap_or(0);
        self.bind(name, ty, slot);
        slot
    }

    fn lookup(&self, name: &str) -> Option<(Ty, u16)> {
        match self.lookup_var(name) {
            Some((t, s, false)) => Some((t, s)),
            _ => None,
        }
    }

    /// A variable's type and slot, and whether the slot is a global's (a
    /// `static` local).
    fn lookup_var(&self, name: &str) -> Option<(Ty, u16, bool)> {
        let &i = self.by_name.get(name)?.last()?;
        if i < self.barrier {
            return None;
        }
        let (_, t, s) = &self.vars[i];
        Some((*t, *s, self.statics.contains(&i)))
    }

    /// The `char` array that the visible variable `name` was declared
    /// as, when it was: the last one bound (a `static` local's is the
    /// compiler's, by its global slot).
    fn chars_of(&self, name: &str) -> Option<&CharArray> {
        let &i = self.by_name.get(name)?.last()?;
        if i < self.barrier {
            return None;
        }
        self.chars.get(&i)
    }

    /// Marks the variable bound last as declared `chars`.
    fn set_chars(&mut self, chars: Option<CharArray>) {
        if let (Some(c), Some(i)) = (chars, self.vars.len().checked_sub(1)) {
            self.chars.insert(i, c);
        }
    }

    /// Names global `slot` `name` in this scope: a `static` local.
    fn bind_static(&mut self, name: &str, ty: Ty, slot: u16) {
        self.statics.insert(self.vars.len());
        self.bind(name, ty, slot);
    }

    /// Whether `name` is declared, visible or not.
    fn has(&self, name: &str) -> bool {
        self.by_name.contains_key(name)
    }
}

type Typed = Option<(Ex, Ty)>;

/// A property declared by the program, as the checker knows it.
struct DeclaredProp {
    owner: u8,
    name: String,
    ty: Ty,
    index: u16,
}

impl Compiler {
    fn new(host: &'static HostTable, functions: Vec<ast::Define>) -> Compiler {
        let mut function_names = HashMap::new();
        for (i, f) in functions.iter().enumerate() {
            function_names.entry(f.name.clone()).or_insert(i);
        }
        // lpfg's predefined structs come first, known by name like the
        // user's.
        let structs = super::value::predefined_structs();
        let struct_names = structs
            .iter()
            .enumerate()
            .map(|(i, d)| (d.name.clone(), i as u16))
            .collect();
        let struct_fields = structs
            .iter()
            .map(|d| {
                d.fields
                    .iter()
                    .enumerate()
                    .map(|(i, (n, _))| (n.clone(), i as u16))
                    .collect()
            })
            .collect();
        let struct_shapes = structs.iter().map(|d| (1 + d.fields.len(), 1)).collect();
        Compiler {
            alphabet: Alphabet::new(),
            structs,
            typedefs: HashMap::new(),
            globals: Vec::new(),
            global_names: HashMap::new(),
            diags: Vec::new(),
            warnings: Vec::new(),
            host,
            functions: functions.into(),
            function_names,
            depth: 0,
            struct_names,
            struct_fields,
            struct_shapes,
            global_values: 0,
            counts_reported: HashSet::new(),
            inlining: Vec::new(),
            inlined: 0,
            int_divisions: Vec::new(),
            truncating: Vec::new(),
            user_fns: Vec::new(),
            user_fn_names: HashMap::new(),
            hints: 0,
            enum_consts: HashMap::new(),
            struct_enums: HashSet::new(),
            ambiguous_enums: HashSet::new(),
            ctors: HashMap::new(),
            methods: HashMap::new(),
            array_types: HashMap::new(),
            global_chars: HashMap::new(),
            field_chars: HashMap::new(),
            single: false,
            props: Vec::new(),
        }
    }

    /// A type as this program computes it: without single precision,
    /// `float`, `V2f` and `V3f` are `double`, `V2d` and `V3d`.
    fn prec(&self, ty: Ty) -> Ty {
        if self.single {
            ty
        } else {
            ty.widened()
        }
    }

    /// A value of single-precision type `ty` rounded as C rounds the
    /// result of `float` arithmetic or a conversion to `float`; values of
    /// other types are left as they are.
    fn round(&self, ex: Ex, ty: Ty) -> Ex {
        if ty.is_single() {
            fold_unary(Ex::Convert(ty, Box::new(ex)))
        } else {
            ex
        }
    }

    fn err(&mut self, span: Span, msg: impl Into<String>) {
        self.diags.push(Diagnostic::new(span, msg));
    }

    /// Reports that more than `limit` `what` are declared, at the first
    /// one too many only.
    fn too_many(&mut self, limit: usize, what: &'static str, span: Span) {
        if self.counts_reported.insert(what) {
            self.err(span, format!("more than {limit} {what} are declared"));
        }
    }

    /// Warns when `ex` is a division of integer constants that truncates
    /// and its value is about to be used as a floating-point number.
    /// Also where the division is of integer variables (`(n - 2)/n`), which
    /// C truncates as well, and which a surface grammar written before the
    /// one language meant as a fraction.
    fn check_truncation(&mut self, ex: &Ex) {
        // An inlined function's value is its body's.
        if let Ex::Let(_, _, body) = ex {
            return self.check_truncation(body);
        }
        // A division of integer variables.
        if let Ex::Bin(BinOp::Div, a, b, span) = ex {
            let constants = matches!(
                (&**a, &**b),
                (Ex::Const(Value::Int(_)), Ex::Const(Value::Int(_)))
            );
            if !constants && self.int_divisions.contains(span) {
                let at = Diagnostic::new(
                    *span,
                    "this divides integers, which truncates (C's arithmetic), and its value is \
                     then used as a floating-point number; write one operand as a float (`2.0`, \
                     or `(float) n`) if a fraction is meant",
                );
                if !self.warnings.contains(&at) {
                    self.warnings.push(at);
                }
                return;
            }
        }
        let Some(ex) = self.truncated_division(ex) else {
            return;
        };
        if let Ex::Bin(BinOp::Div, a, b, span) = &ex {
            if let (Ex::Const(Value::Int(x)), Ex::Const(Value::Int(y))) = (&**a, &**b) {
                // Wrapping, as the interpreter divides: `i64::MIN / -1`
                // overflows, and it does not truncate.
                if *y != 0 && x.wrapping_rem(*y) != 0 {
                    let at = Diagnostic::new(
                        *span,
                        format!(
                            "`{x}/{y}` is {} in integer arithmetic; write {x}.0/{y}",
                            x.wrapping_div(*y)
                        ),
                    );
                    if !self.warnings.contains(&at) {
                        self.warnings.push(at);
                    }
                }
            }
        }
    }

    /// The division of integer constants `ex` is, negated or not, or
    /// the one an inlined parameter `ex` was bound to.
    fn truncated_division(&self, ex: &Ex) -> Option<Ex> {
        match ex {
            Ex::Neg(a) => self.truncated_division(a),
            Ex::Local(s) => self
                .truncating
                .iter()
                .rev()
                .find(|(t, _)| t == s)
                .map(|(_, d)| d.clone()),
            Ex::Bin(BinOp::Div, a, b, _)
                if matches!(
                    (&**a, &**b),
                    (Ex::Const(Value::Int(_)), Ex::Const(Value::Int(_)))
                ) =>
            {
                Some(ex.clone())
            }
            _ => None,
        }
    }

    /// An element in arithmetic reads as its value (a mesh vertex as its
    /// position); anything else is left as it is.
    fn arith(&self, ex: Ex, ty: Ty, span: Span) -> (Ex, Ty) {
        if let Ty::Elem(k) = ty {
            if let Some((f, t)) = (self.host.arith)(k) {
                return (Ex::Call(f, vec![ex], span), self.prec(t));
            }
        }
        (ex, ty)
    }

    /// A checked expression used as a condition.
    fn condition_of(&mut self, ex: Ex, ty: Ty, span: Span) -> Option<Ex> {
        if !ty.is_numeric() {
            self.err(
                span,
                format!(
                    "expected a condition (a number or bool), found {}",
                    self.type_name(ty)
                ),
            );
            return None;
        }
        Some(ex)
    }

    fn type_name(&self, ty: Ty) -> String {
        match ty {
            Ty::Int => "int".into(),
            Ty::Float => "float".into(),
            Ty::Double => "double".into(),
            Ty::Bool => "bool".into(),
            Ty::V2 => "V2f".into(),
            Ty::V3 => "V3f".into(),
            Ty::V2d => "V2d".into(),
            Ty::V3d => "V3d".into(),
            Ty::Struct(i) => self.structs[i as usize].name.clone(),
            Ty::Str => "string".into(),
            Ty::Void => "void".into(),
            Ty::Elem(k) => self.host.element_name(k).into(),
        }
    }

    fn resolve_type(&mut self, t: &ast::TypeRef) -> Option<Ty> {
        let ty = match t.name.as_str() {
            // `char *s` is a string; a `FILE *` is a handle, an int.
            "char" if t.pointer => Ty::Str,
            "int" | "long" | "unsigned" | "short" | "signed" | "char" | "size_t" | "FILE" => {
                Ty::Int
            }
            "float" => self.prec(Ty::Float),
            "double" => Ty::Double,
            "bool" => Ty::Bool,
            "V2f" => self.prec(Ty::V2),
            "V3f" => self.prec(Ty::V3),
            "V2d" => Ty::V2d,
            "V3d" => Ty::V3d,
            "void" => Ty::Void,
            other => {
                if let Some(&(_, k)) = self.host.types.iter().find(|(n, _)| *n == other) {
                    Ty::Elem(k)
                } else if let Some(t) = self.typedefs.get(other) {
                    *t
                } else if let Some(&i) = self.struct_names.get(other) {
                    Ty::Struct(i)
                } else {
                    self.err(
                        t.span,
                        format!("unknown type `{other}`: expected int, float, double, bool, V2f, V3f, a declared struct or enum"),
                    );
                    return None;
                }
            }
        };
        Some(ty)
    }

    /// First pass: structs, typedefs and modules, so order does not matter.
    fn declarations(&mut self, file: &ast::File) {
        for item in &file.items {
            match item {
                Item::Struct { name, body } => {
                    for (e, variants) in &body.enums {
                        self.enum_decl(e.as_ref(), variants, Some(&name.text));
                    }
                    let fields = &body.fields;
                    if self.struct_names.contains_key(&name.text) {
                        self.err(
                            name.span,
                            format!("struct `{}` is already declared", name.text),
                        );
                        continue;
                    }
                    if self.structs.len() >= MAX_DECLARED {
                        self.too_many(MAX_DECLARED, "structs", name.span);
                        continue;
                    }
                    let mut fs: Vec<(String, Ty)> = Vec::new();
                    let mut index: HashMap<String, u16> = HashMap::new();
                    // The struct itself, then its fields'.
                    let (mut values, mut depth) = (1usize, 1usize);
                    for (t, n, dims) in fields {
                        if index.contains_key(&n.text) {
                            self.err(
                                n.span,
                                format!("struct `{}` already has a field `{}`", name.text, n.text),
                            );
                            continue;
                        }
                        if fs.len() >= MAX_DECLARED {
                            self.err(
                                n.span,
                                format!(
                                    "more than {MAX_DECLARED} fields are declared in struct `{}`",
                                    name.text
                                ),
                            );
                            break;
                        }
                        if let Some(ty) = self
                            .resolve_type(t)
                            .and_then(|ty| self.with_dims(ty, t, dims, None, n.span))
                        {
                            let (v, d) = match ty {
                                Ty::Struct(i) => self.struct_shapes[i as usize],
                                _ => (1, 0),
                            };
                            values = values.saturating_add(v);
                            depth = depth.max(d + 1);
                            if let Some(c) = self.char_array(t, false, n, dims, &Init::None) {
                                self.field_chars
                                    .insert((self.structs.len() as u16, fs.len() as u16), c);
                            }
                            index.insert(n.text.clone(), fs.len() as u16);
                            fs.push((n.text.clone(), ty));
                        }
                    }
                    let problem = if depth > MAX_NESTING {
                        Some(format!(
                            "structs nest more than {MAX_NESTING} levels deep in `{}`",
                            name.text
                        ))
                    } else if values > MAX_STRUCT_VALUES {
                        Some(format!(
                            "struct `{}` holds more than {MAX_STRUCT_VALUES} values, counting those of the structs inside it",
                            name.text
                        ))
                    } else {
                        None
                    };
                    if let Some(m) = problem {
                        // Declared empty, so that its uses are not errors too.
                        self.err(name.span, m);
                        (fs, index, values, depth) = (Vec::new(), HashMap::new(), 1, 1);
                    }
                    self.struct_names
                        .insert(name.text.clone(), self.structs.len() as u16);
                    self.struct_fields.push(index);
                    self.struct_shapes.push((values, depth));
                    self.structs.push(StructDef {
                        name: name.text.clone(),
                        fields: fs,
                        elem: None,
                    });
                    for c in &body.ctors {
                        self.ctor_sig(name, c);
                    }
                    for m in &body.methods {
                        self.method_sig(name, m);
                    }
                }
                Item::Typedef { ty, name } => {
                    if let Some(t) = self.resolve_type(ty) {
                        self.typedefs.insert(name.text.clone(), t);
                    }
                }
                Item::Enum { name, variants } => self.enum_decl(name.as_ref(), variants, None),
                Item::Function(def) => self.function_sig(def),
                Item::Module { name, params } => {
                    if let Some(s) = self.alphabet.lookup(&name.text) {
                        let what = if self.alphabet.get(s).builtin {
                            "is a predefined module and cannot be redeclared"
                        } else {
                            "is already declared"
                        };
                        self.err(name.span, format!("module `{}` {what}", name.text));
                        continue;
                    }
                    let tys: Vec<Ty> = params.iter().filter_map(|p| self.resolve_type(p)).collect();
                    if self.alphabet.kinds.len() >= MAX_DECLARED {
                        let limit = MAX_DECLARED - super::modules::PREDEFINED.len();
                        self.too_many(limit, "modules", name.span);
                        continue;
                    }
                    if tys.len() == params.len() {
                        self.alphabet.declare(&name.text, tys);
                    }
                }
                _ => {}
            }
        }
    }

    /// The properties a vv program declares, numbered after their owner's
    /// built-in ones.
    fn property_decls(&mut self, file: &ast::File) {
        for item in &file.items {
            let Item::Property {
                owner, ty, name, ..
            } = item
            else {
                continue;
            };
            let Some(props) = self.host.properties else {
                self.err(
                    owner.span,
                    format!("a {} has no properties", self.host.name),
                );
                continue;
            };
            let Some(o) = props.owners.iter().position(|n| *n == owner.text) else {
                continue;
            };
            let o = o as u8;
            let Some(t) = self.resolve_type(ty) else {
                continue;
            };
            if !(t.is_numeric() || t.is_vector()) {
                self.err(
                    ty.span,
                    format!(
                        "a property holds a number or a vector; {} is neither",
                        self.type_name(t)
                    ),
                );
                continue;
            }
            let taken = props
                .builtin
                .iter()
                .any(|(bo, n, _)| *bo == o && *n == name.text)
                || self
                    .props
                    .iter()
                    .any(|p| p.owner == o && p.name == name.text);
            if taken {
                self.err(
                    name.span,
                    format!(
                        "{} property `{}` is already declared",
                        owner.text, name.text
                    ),
                );
                continue;
            }
            let index = props.builtin.iter().filter(|(bo, _, _)| *bo == o).count()
                + self.props.iter().filter(|p| p.owner == o).count();
            self.props.push(DeclaredProp {
                owner: o,
                name: name.text.clone(),
                ty: t,
                index: index as u16,
            });
        }
    }

    /// A property of an element of type `target_ty`: its owner, number and
    /// type; an error at `name` if it has none of that name.
    fn property(&mut self, target_ty: Ty, name: &ast::Name, at: Span) -> Option<(u8, u16, Ty)> {
        let owner = match (self.host.properties, target_ty) {
            (Some(p), Ty::Elem(k)) => (p.owner_of)(k).map(|o| (p, o)),
            _ => None,
        };
        let Some((props, o)) = owner else {
            self.err(
                at,
                format!(
                    "`$` reads a property of a vertex, an edge or the mesh; this is {}",
                    self.type_name(target_ty)
                ),
            );
            return None;
        };
        let mut index = 0u16;
        for (bo, n, t) in props.builtin {
            if *bo == o {
                if *n == name.text {
                    return Some((o, index, *t));
                }
                index += 1;
            }
        }
        if let Some(p) = self
            .props
            .iter()
            .find(|p| p.owner == o && p.name == name.text)
        {
            return Some((o, p.index, p.ty));
        }
        let owner_name = props.owners[o as usize];
        self.err(
            name.span,
            format!(
                "{owner_name} property `{}` is not declared; declare it as `{owner_name} float {};`",
                name.text, name.text
            ),
        );
        None
    }

    /// Turtle mode (The Algorithmic Beauty of Plants): a module used but not
    /// declared is declared with as many float parameters as its first use.
    fn declare_from_use(&mut self, file: &ast::File) {
        fn stmts(ss: &[ast::Stmt], out: &mut Vec<(String, usize)>) {
            for s in ss {
                match s {
                    ast::Stmt::Produce { modules, .. } => {
                        out.extend(modules.iter().map(|m| (m.name.text.clone(), m.args.len())))
                    }
                    ast::Stmt::Block(b) => stmts(&b.stmts, out),
                    ast::Stmt::If { then, els, .. } => {
                        stmts(std::slice::from_ref(then), out);
                        if let Some(e) = els {
                            stmts(std::slice::from_ref(e), out);
                        }
                    }
                    ast::Stmt::While { body, .. }
                    | ast::Stmt::DoWhile { body, .. }
                    | ast::Stmt::For { body, .. } => stmts(std::slice::from_ref(body), out),
                    ast::Stmt::Switch { body, .. } => stmts(body, out),
                    _ => {}
                }
            }
        }
        let mut used: Vec<(String, usize)> = Vec::new();
        for item in &file.items {
            match item {
                Item::Axiom { modules, .. } => {
                    used.extend(modules.iter().map(|m| (m.name.text.clone(), m.args.len())))
                }
                Item::Production(p) => {
                    for m in p
                        .new_left
                        .iter()
                        .chain(&p.left)
                        .chain(&p.strict)
                        .chain(&p.right)
                        .chain(&p.new_right)
                    {
                        used.push((m.name.text.clone(), m.params.len()));
                    }
                    match &p.body {
                        ast::Body::Arrow(succ, _) => {
                            used.extend(succ.iter().map(|m| (m.name.text.clone(), m.args.len())))
                        }
                        ast::Body::Block(b) => stmts(&b.stmts, &mut used),
                    }
                }
                _ => {}
            }
        }
        for (name, arity) in used {
            if self.alphabet.lookup(&name).is_none() {
                if self.alphabet.kinds.len() >= MAX_DECLARED {
                    let limit = MAX_DECLARED - super::modules::PREDEFINED.len();
                    self.too_many(limit, "modules", Span::default());
                    return;
                }
                let f = self.prec(Ty::Float);
                self.alphabet.declare(&name, vec![f; arity]);
            }
        }
    }

    fn rules_and_directives(&mut self, file: &ast::File) -> Program {
        let mut program = Program {
            alphabet: Alphabet::new(),
            structs: Vec::new(),
            globals: Vec::new(),
            functions: Vec::new(),
            axiom: Vec::new(),
            derivation_length: None,
            ring: None,
            decomposition_depth: None,
            interpretation_depth: None,
            angle: None,
            rules: Vec::new(),
            control: Vec::new(),
            gillespie_groups: Vec::new(),
            warnings: Vec::new(),
            model: Default::default(),
            single: self.single,
            properties: Vec::new(),
        };
        self.property_decls(file);
        // Group numbers seen with `group` (false) and `ggroup` (true), and
        // where first.
        let mut group_kinds: Vec<(i64, bool, Span)> = Vec::new();
        let mut section = Section::Productions;
        let mut group = 0i64;
        let mut vgroup = 0i64;
        let mut filter = Filter::All;
        let mut axiom_seen = false;
        for item in &file.items {
            match item {
                Item::Global(decl) => self.global(decl),
                Item::Directive { kind, expr, span } => {
                    let mut scope = Scope::default();
                    let Some((ex, ty)) = self.expr(expr, &mut scope) else {
                        continue;
                    };
                    if !ty.is_numeric() {
                        self.err(
                            expr.span,
                            format!(
                                "expected a number, found a value of type {}",
                                self.type_name(ty)
                            ),
                        );
                        continue;
                    }
                    let slot = match kind {
                        ast::DirectiveKind::DerivationLength => &mut program.derivation_length,
                        ast::DirectiveKind::Angle => &mut program.angle,
                        ast::DirectiveKind::Ring => &mut program.ring,
                        ast::DirectiveKind::MaximumDepth => match section {
                            Section::Interpretation => &mut program.interpretation_depth,
                            _ => &mut program.decomposition_depth,
                        },
                    };
                    if slot.is_some() {
                        self.err(*span, "this directive is given twice");
                    }
                    *slot = Some((ex, *span));
                }
                Item::Axiom { modules, span } => {
                    if axiom_seen {
                        self.err(*span, "the axiom is given twice");
                    }
                    axiom_seen = true;
                    self.check_branches(modules, "the axiom");
                    let mut scope = Scope::default();
                    program.axiom = self.successors(modules, &mut scope);
                }
                Item::ContextFilter {
                    consider, names, ..
                } => {
                    let mut syms = Vec::new();
                    for n in names {
                        match self.alphabet.lookup(&n.text) {
                            Some(s) => syms.push(s),
                            None => self.err(n.span, format!("undeclared module `{}` in the module list; declare it with `module {}(...);`", n.text, n.text)),
                        }
                    }
                    syms.sort();
                    syms.dedup();
                    filter = if names.is_empty() {
                        Filter::All
                    } else if *consider {
                        Filter::Consider(syms.into())
                    } else {
                        Filter::Ignore(syms.into())
                    };
                }
                Item::Section { section: s, .. } => {
                    section = *s;
                    group = 0;
                    vgroup = 0;
                }
                Item::Group {
                    id,
                    gillespie,
                    span,
                } => {
                    group = *id;
                    if *gillespie && *id <= 0 {
                        self.err(
                            *span,
                            "a Gillespie group needs a number greater than 0: group 0 is the default group",
                        );
                    } else if *id != 0 {
                        self.group_kind(*id, *gillespie, *span, &mut group_kinds);
                    }
                }
                Item::VGroup { id, .. } => vgroup = *id,
                Item::Control { kind, body, .. } => {
                    let mut scope = Scope::default();
                    let stmts = self.block_stmts(&body.stmts, &mut scope);
                    program.control.push((*kind, stmts, scope.max as usize));
                }
                Item::Production(p) => {
                    let gillespie = group_kinds.iter().any(|(g, k, _)| *g == group && *k);
                    if gillespie && (!p.new_left.is_empty() || !p.new_right.is_empty()) {
                        self.err(
                            p.span,
                            format!(
                                "a production of a Gillespie group (`ggroup {group}:`) cannot \
                                 have a new context (`<<` or `>>`): a Gillespie step rewrites \
                                 one module in place (manual 7.2)"
                            ),
                        );
                    }
                    if let Some(mut rule) = self.rule(p, section, group, &filter) {
                        rule.vgroup = vgroup;
                        program.rules.push(rule);
                    }
                }
                Item::Property {
                    owner,
                    ty,
                    name,
                    init,
                } => {
                    // The same name may be a property of each owner.
                    let o = self
                        .host
                        .properties
                        .and_then(|ps| ps.owners.iter().position(|n| *n == owner.text));
                    let Some(p) = self
                        .props
                        .iter()
                        .find(|p| Some(p.owner as usize) == o && p.name == name.text)
                    else {
                        continue;
                    };
                    let (owner, pty, index) = (p.owner, p.ty, p.index);
                    let _ = ty;
                    let value = match init {
                        Some(e) => {
                            let mut scope = Scope::default();
                            let Some((x, t)) = self.expr(e, &mut scope) else {
                                continue;
                            };
                            let Some(x) = self.coerce(x, t, pty, e.span) else {
                                continue;
                            };
                            x
                        }
                        None => Ex::Const(Value::zero(pty, &self.structs)),
                    };
                    program.properties.push(PropertyDef {
                        owner,
                        name: name.text.clone(),
                        ty: pty,
                        index,
                        init: value,
                        span: name.span,
                    });
                }
                Item::Module { .. }
                | Item::Struct { .. }
                | Item::Typedef { .. }
                | Item::Enum { .. }
                | Item::Function(_) => {}
            }
        }
        program.gillespie_groups = group_kinds
            .iter()
            .filter(|(_, g, _)| *g)
            .map(|(id, _, span)| (*id, *span))
            .collect();
        program.functions = self.function_bodies(file);
        // A word needs an axiom; other topologies have their structure.
        if !axiom_seen && std::ptr::eq(self.host, &WORD_HOST) {
            let end = file
                .items
                .last()
                .map(|_| Span::default())
                .unwrap_or_default();
            self.err(
                end,
                "the program has no axiom: add a line such as `Axiom: A(1);`",
            );
        }
        program.alphabet = self.alphabet.clone();
        program.structs = self.structs.clone();
        program.globals = std::mem::take(&mut self.globals);
        program
    }

    fn global(&mut self, decl: &ast::VarDecl) {
        let Some(base) = self.resolve_type(&decl.ty) else {
            return;
        };
        for d in &decl.vars {
            let Some(ty) = self.declarator_type(base, &decl.ty, d) else {
                continue;
            };
            let chars = self.char_array(&decl.ty, d.pointer, &d.name, &d.dims, &d.init);
            let mut scope = Scope::default();
            let init = match (ty, &d.init) {
                (Ty::Elem(k), Init::None) => Some(Ex::Const((self.host.zero)(k))),
                _ => self.initializer(ty, &d.init, d.name.span, &mut scope),
            };
            let init = self.fit_init(init, chars.as_ref(), &d.init);
            if scope.max > 0 {
                self.err(d.name.span, "a global initializer cannot declare variables");
            }
            if self.global_names.contains_key(&d.name.text) {
                self.err(
                    d.name.span,
                    format!("`{}` is already declared", d.name.text),
                );
                continue;
            }
            // A variable may be named like a module (`V2f f(6, 0);`): in
            // L+C modules appear only in predecessors, successors and the
            // axiom, variables only in expressions.
            if self.globals.len() >= MAX_DECLARED {
                self.too_many(MAX_DECLARED, "global variables", d.name.span);
                continue;
            }
            self.count_global_values(ty, d.name.span);
            self.global_names
                .insert(d.name.text.clone(), self.globals.len() as u16);
            if let Some(c) = chars {
                self.global_chars.insert(self.globals.len() as u16, c);
            }
            self.globals.push(GlobalVar {
                name: d.name.text.clone(),
                ty,
                is_const: decl.is_const,
                init,
            });
        }
    }

    /// The expression that initialises a variable of type `ty`, declared
    /// at `at`.
    fn initializer(&mut self, ty: Ty, init: &Init, at: Span, scope: &mut Scope) -> Option<Ex> {
        let has_ctor = match ty {
            Ty::Struct(si) => self.ctors.contains_key(&self.structs[si as usize].name),
            _ => false,
        };
        match init {
            // `S s;` and `S s(1, 2);` call `S`'s constructors; the structs
            // of a plain struct or an array are built by theirs.
            Init::None => match self.default_value(ty, at) {
                // A struct or an array holding elements starts with the
                // topology's zeros; a lone element is made by the caller
                // (`vertex v;` in a body creates one).
                Ex::Const(_) if !matches!(ty, Ty::Struct(_)) || !self.holds_elements(ty) => None,
                built => Some(built),
            },
            Init::Ctor(args, span) if has_ctor => {
                let name = ast::Name {
                    text: self.structs[pt_index(ty)].name.clone(),
                    span: *span,
                };
                self.ctor_call(ty, &name, args, *span, scope).map(|t| t.0)
            }
            Init::Expr(e) => {
                let (ex, et) = self.expr(e, scope)?;
                self.coerce(ex, et, ty, e.span)
            }
            Init::List(items, span)
                if self.is_array(ty)
                    || items.iter().any(|i| matches!(i.kind, ExprKind::List(_))) =>
            {
                self.list_init(ty, items, *span, scope)
            }
            Init::List(items, span)
                if matches!(ty, Ty::Struct(_)) && items.len() < self.fields_of(ty) =>
            {
                self.list_init(ty, items, *span, scope)
            }
            Init::Ctor(args, span) | Init::List(args, span) => {
                let mut exs = Vec::new();
                for a in args {
                    exs.push(self.expr(a, scope)?);
                }
                self.construct(ty, exs, args, *span)
            }
        }
    }

    /// `V2f v(1, 2)`, `V3f(x, y, z)`, `Data d = {1, 0}`, `int n(3)`.
    fn construct(
        &mut self,
        ty: Ty,
        mut exs: Vec<(Ex, Ty)>,
        args: &[ast::Expr],
        span: Span,
    ) -> Option<Ex> {
        let want = self.parts_of(ty);
        if exs.len() == 1 && (exs[0].1 == ty || ty.is_vector() && exs[0].1.dim() == ty.dim()) {
            let (ex, from) = exs.pop().expect("one");
            return self.coerce(ex, from, ty, span);
        }
        if exs.len() != want.len() {
            self.err(
                span,
                format!(
                    "{} takes {} value(s) here, but {} were given",
                    self.type_name(ty),
                    want.len(),
                    exs.len()
                ),
            );
            return None;
        }
        let mut parts = Vec::new();
        for (k, ((ex, et), (w, a))) in exs.into_iter().zip(want.iter().zip(args)).enumerate() {
            let part = self.coerce(ex, et, *w, a.span)?;
            parts.push(self.fit_field(ty, k, part, a.span)?);
        }
        assemble(ty, parts)
    }

    /// The types of the values that build a `ty`: a vector's components,
    /// a struct's fields, or `ty` itself.
    fn parts_of(&self, ty: Ty) -> Vec<Ty> {
        match ty {
            t if t.is_vector() => vec![t.scalar(); t.dim()],
            Ty::Struct(i) => self.structs[i as usize]
                .fields
                .iter()
                .map(|f| f.1)
                .collect(),
            t => vec![t],
        }
    }

    /// Converts `ex` of type `from` to `to`, or reports a type error.
    fn coerce(&mut self, ex: Ex, from: Ty, to: Ty, span: Span) -> Option<Ex> {
        if from == to {
            return Some(ex);
        }
        let (ex, from) = if matches!(to, Ty::Elem(_)) {
            (ex, from)
        } else {
            self.arith(ex, from, span)
        };
        if from == to {
            return Some(ex);
        }
        if from.is_numeric() && to.is_numeric() {
            if from == Ty::Int && to.is_floating() {
                self.check_truncation(&ex);
            }
            // To `float`, the conversion rounds to single precision.
            return Some(fold_unary(Ex::Convert(to, Box::new(ex))));
        }
        if from.is_vector() && from.dim() == to.dim() {
            // `V2d` to `V2f` rounds each component; the other way is exact.
            return Some(fold_unary(Ex::Convert(to, Box::new(ex))));
        }
        self.err(
            span,
            format!(
                "type mismatch: expected {}, found {}",
                self.type_name(to),
                self.type_name(from)
            ),
        );
        None
    }

    /// Records group `id` as a Gillespie group or a regular one; the two
    /// kinds share the numbers (manual 7.2), so one number cannot be both.
    fn group_kind(
        &mut self,
        id: i64,
        gillespie: bool,
        span: Span,
        seen: &mut Vec<(i64, bool, Span)>,
    ) {
        if let Some(&(_, was, _)) = seen.iter().find(|(g, _, _)| *g == id) {
            if was != gillespie {
                let (this, other) = if gillespie {
                    ("ggroup", "group")
                } else {
                    ("group", "ggroup")
                };
                self.err(
                    span,
                    format!(
                        "`{this} {id}:` reuses the number of an earlier `{other} {id}:`: a \
                         regular group and a Gillespie group cannot have the same number"
                    ),
                );
            }
            return;
        }
        seen.push((id, gillespie, span));
    }

    fn rule(
        &mut self,
        p: &ast::Production,
        section: Section,
        group: i64,
        filter: &Filter,
    ) -> Option<Rule> {
        let mut scope = Scope::rule();
        let mut ok = true;
        let mut pats =
            |c: &mut Compiler, list: &[ast::PatModule], scope: &mut Scope| -> Vec<Pattern> {
                let mut out = Vec::with_capacity(list.len());
                for m in list {
                    match c.pattern(m, scope) {
                        Some(pat) => out.push(pat),
                        None => ok = false,
                    }
                }
                out
            };
        let new_left = pats(self, &p.new_left, &mut scope);
        let left = pats(self, &p.left, &mut scope);
        let strict = pats(self, &p.strict, &mut scope);
        let right = pats(self, &p.right, &mut scope);
        let new_right = pats(self, &p.new_right, &mut scope);
        if !ok {
            // The body's names depend on the predecessor: checking it now
            // would only repeat the predecessor's error.
            return None;
        }
        let body = match &p.body {
            ast::Body::Block(b) => self.block_stmts(&b.stmts, &mut scope),
            ast::Body::Arrow(succ, _) => {
                self.check_branches(succ, "the successor");
                let modules = self.successors(succ, &mut scope);
                vec![St::Produce {
                    modules,
                    last: true,
                }]
            }
        };
        let label = pattern_label(p);
        let mut rule = Rule {
            new_left,
            left,
            strict,
            right,
            new_right,
            filter: filter.clone(),
            body,
            frame_size: scope.max as usize,
            section,
            group,
            vgroup: 0,
            span: p.span,
            label,
            stencil: None,
        };
        rule.stencil = super::stencil::Stencil::compile(&rule);
        Some(rule)
    }

    /// A predecessor module: each parameter becomes a local of the module's type.
    fn pattern(&mut self, m: &ast::PatModule, scope: &mut Scope) -> Option<Pattern> {
        let (sym, tys, width) = self.module_params(&m.name, m.params.len())?;
        let mut slots = Vec::new();
        for (n, t) in m.params.iter().zip(tys.iter().copied()) {
            if scope.has(&n.text) {
                self.err(
                    n.span,
                    format!(
                        "the parameter name `{}` is used twice in this predecessor",
                        n.text
                    ),
                );
                return None;
            }
            slots.push(self.local(scope, &n.text, t, n.span));
        }
        Some(Pattern {
            sym,
            slots,
            types: tys,
            width,
        })
    }

    /// A warning at a `]` that closes no branch of `modules`, or at the
    /// first `[` that is never closed (`X -> F-[[X]+X]+F[+FX-X`): the
    /// derivation runs, but the turtle's branches are not what was meant.
    fn check_branches(&mut self, modules: &[ast::ModuleCall], what: &str) {
        let mut open: Vec<Span> = Vec::new();
        for m in modules {
            match m.name.text.as_str() {
                "SB" | "[" => open.push(m.name.span),
                "EB" | "]" if open.pop().is_none() => {
                    let at = Diagnostic::new(
                        m.name.span,
                        format!("this `]` closes no branch: the brackets of {what} do not balance"),
                    );
                    self.warnings.push(at);
                    return;
                }
                _ => {}
            }
        }
        if let Some(&first) = open.first() {
            let n = open.len();
            let more = if n > 1 {
                format!(" ({n} branches are left open)")
            } else {
                String::new()
            };
            let at = Diagnostic::new(
                first,
                format!("this `[` is never closed: the brackets of {what} do not balance{more}"),
            );
            self.warnings.push(at);
        }
    }

    /// The names a value may have here, sorted: the visible locals, the
    /// globals, enumerators, the host's values and the language's
    /// constants (for "did you mean").
    fn value_names(&self, scope: &Scope) -> Vec<String> {
        let mut names: Vec<String> = scope.vars[scope.barrier.min(scope.vars.len())..]
            .iter()
            .map(|(n, _, _)| n.clone())
            .chain(self.global_names.keys().cloned())
            .chain(self.enum_consts.keys().cloned())
            .chain(self.host.values.iter().map(|(n, _, _)| n.to_string()))
            .chain(
                [
                    "true", "false", "M_PI", "PI", "M_PI_2", "M_E", "M_SQRT2", "RAND_MAX", "NULL",
                    "stdout", "stderr",
                ]
                .map(String::from),
            )
            .collect();
        names.sort();
        names.dedup();
        names
    }

    /// The functions a call may name, sorted: the library's, the host's,
    /// the program's own and C's input and output (for "did you mean").
    fn function_names(&self) -> Vec<String> {
        let mut names: Vec<String> = builtins::LIBRARY
            .iter()
            .map(|b| b.name.to_string())
            .chain(self.host.functions.iter().map(|b| b.name.to_string()))
            .chain(self.user_fn_names.keys().cloned())
            .chain(
                [
                    "printf", "fprintf", "sprintf", "snprintf", "puts", "fputs", "fopen", "fclose",
                    "fflush", "strlen", "strcmp", "strcpy", "strcat", "strncpy", "strncat",
                ]
                .map(String::from),
            )
            .collect();
        names.sort();
        names.dedup();
        names
    }

    /// True while fewer than [`MAX_HINTS`] hints were looked for; counts
    /// this one.
    fn hint_allowed(&mut self) -> bool {
        self.hints += 1;
        self.hints <= MAX_HINTS
    }

    /// "; did you mean `x`?" for a value's name that is not known.
    fn value_hint(&mut self, name: &str, scope: &Scope) -> String {
        if !self.hint_allowed() {
            return String::new();
        }
        let names = self.value_names(scope);
        super::suggest::hint(name, names.iter().map(String::as_str))
    }

    /// "; did you mean `Apex`?" for a module name that is not declared,
    /// from the modules the program declares and the predefined ones.
    fn module_hint(&mut self, name: &str) -> String {
        if !self.hint_allowed() {
            return String::new();
        }
        let mut names: Vec<&str> = self
            .alphabet
            .kinds
            .iter()
            .map(|k| k.name.as_str())
            .collect();
        names.sort_unstable();
        names.dedup();
        super::suggest::hint(name, names)
    }

    /// The module `name` and its parameter types for `count` parameters.
    fn module_params(
        &mut self,
        name: &ast::Name,
        count: usize,
    ) -> Option<(Sym, Vec<Ty>, Option<usize>)> {
        let Some(sym) = self.alphabet.lookup(&name.text) else {
            let hint = self.module_hint(&name.text);
            let mut m =
                super::modules::undeclared(&name.text, &vec!["float"; count].join(", "), &hint);
            if name.text == "Step" && count == 0 {
                // `Step:` is a block only in a vv program.
                m.push_str(
                    "; a `Step:` block belongs to a vertex-vertex program, which declares \
                     its mesh first: `mesh S = \"base.obj\";`",
                );
            }
            self.err(name.span, m);
            return None;
        };
        match &self.alphabet.get(sym).sig {
            Signature::Fixed(tys) => {
                if tys.len() != count {
                    let decl = tys
                        .iter()
                        .map(|t| self.type_name(*t))
                        .collect::<Vec<_>>()
                        .join(", ");
                    self.err(
                        name.span,
                        format!(
                            "module `{}` is declared with {} parameter(s) ({}) but {} are given here",
                            name.text,
                            tys.len(),
                            decl,
                            count
                        ),
                    );
                    return None;
                }
                Some((sym, tys.iter().map(|t| self.prec(*t)).collect(), None))
            }
            Signature::Overloads(ovs) => match ovs.iter().find(|o| o.len() == count) {
                Some(o) => {
                    let w = o
                        .iter()
                        .map(|t| super::value::width(*t, &self.structs))
                        .sum();
                    Some((sym, o.iter().map(|t| self.prec(*t)).collect(), Some(w)))
                }
                None => {
                    let counts: Vec<String> = ovs.iter().map(|o| o.len().to_string()).collect();
                    self.err(
                        name.span,
                        format!(
                            "predefined module `{}` takes {} parameter(s), but {} are given here",
                            name.text,
                            counts.join(" or "),
                            count
                        ),
                    );
                    None
                }
            },
        }
    }

    fn successors(&mut self, modules: &[ast::ModuleCall], scope: &mut Scope) -> Vec<Succ> {
        // Sized exactly: a program may hold hundreds of thousands of rules.
        let mut out = Vec::with_capacity(modules.len());
        for m in modules {
            let mut args = Vec::with_capacity(m.args.len());
            let mut ok = true;
            for a in &m.args {
                match self.expr(a, scope) {
                    Some(t) => args.push(t),
                    None => ok = false,
                }
            }
            if !ok {
                continue;
            }
            let Some(sym) = self.alphabet.lookup(&m.name.text) else {
                let types: Vec<String> = args.iter().map(|(_, t)| self.type_name(*t)).collect();
                let hint = self.module_hint(&m.name.text);
                self.err(
                    m.name.span,
                    super::modules::undeclared(&m.name.text, &types.join(", "), &hint),
                );
                continue;
            };
            let candidates: Vec<Vec<Ty>> = match &self.alphabet.get(sym).sig {
                Signature::Fixed(t) => vec![t.clone()],
                Signature::Overloads(o) => o
                    .iter()
                    .map(|v| v.iter().map(|t| self.prec(*t)).collect())
                    .collect(),
            };
            let converts = |w: &Ty, t: &Ty| {
                w == t
                    || (w.is_numeric() && t.is_numeric())
                    || (w.is_vector() && w.dim() == t.dim())
            };
            let fits = |want: &[Ty]| {
                want.len() == args.len() && want.iter().zip(&args).all(|(w, (_, t))| converts(w, t))
            };
            let Some(want) = candidates.iter().find(|w| fits(w)).cloned() else {
                let same_arity = candidates.iter().find(|w| w.len() == args.len());
                match same_arity {
                    Some(want) => {
                        for ((_, t), (w, a)) in args.iter().zip(want.iter().zip(&m.args)) {
                            if !converts(w, t) {
                                self.err(
                                    a.span,
                                    format!(
                                        "type mismatch in argument of `{}`: expected {}, found {}",
                                        m.name.text,
                                        self.type_name(*w),
                                        self.type_name(*t)
                                    ),
                                );
                                break;
                            }
                        }
                    }
                    None => {
                        let counts: Vec<String> =
                            candidates.iter().map(|c| c.len().to_string()).collect();
                        self.err(
                            m.name.span,
                            format!(
                                "module `{}` takes {} parameter(s), but {} are given here",
                                m.name.text,
                                counts.join(" or "),
                                args.len()
                            ),
                        );
                    }
                }
                continue;
            };
            let args = args
                .into_iter()
                .zip(&want)
                .map(|((ex, t), w)| {
                    if t == *w {
                        ex
                    } else {
                        // To a `float` parameter: rounded, as lpfg stores it.
                        fold_unary(Ex::Convert(*w, Box::new(ex)))
                    }
                })
                .collect();
            out.push(Succ {
                sym,
                args,
                types: want,
                span: m.name.span,
            });
        }
        out
    }

    fn block_stmts(&mut self, stmts: &[ast::Stmt], scope: &mut Scope) -> Vec<St> {
        scope.push();
        let mut out = Vec::new();
        for s in stmts {
            self.stmt(s, scope, &mut out);
        }
        scope.pop();
        out
    }

    fn stmt(&mut self, s: &ast::Stmt, scope: &mut Scope, out: &mut Vec<St>) {
        match s {
            ast::Stmt::Expr(e) => {
                if let Some((ex, _)) = self.expr(e, scope) {
                    out.push(St::Expr(ex));
                }
            }
            ast::Stmt::Decl(d) => {
                let Some(base) = self.resolve_type(&d.ty) else {
                    return;
                };
                for v in &d.vars {
                    let Some(ty) = self.declarator_type(base, &d.ty, v) else {
                        continue;
                    };
                    if d.is_static {
                        self.static_local(d, v, ty, scope);
                        continue;
                    }
                    let chars = self.char_array(&d.ty, v.pointer, &v.name, &v.dims, &v.init);
                    let init = self.initializer(ty, &v.init, v.name.span, scope);
                    let init = self.fit_init(init, chars.as_ref(), &v.init);
                    let slot = self.local(scope, &v.name.text, ty, v.name.span);
                    scope.set_chars(chars);
                    if d.is_const {
                        scope.consts.insert(slot);
                    }
                    let value = init.unwrap_or_else(|| match ty {
                        Ty::Elem(k) => match (self.host.fresh)(k) {
                            Some(f) => Ex::Call(f, Vec::new(), v.name.span),
                            None => Ex::Const((self.host.zero)(k)),
                        },
                        _ => Ex::Const(self.zero(ty)),
                    });
                    out.push(St::Init(slot, value));
                }
            }
            ast::Stmt::Forall {
                var,
                set,
                body,
                span,
            } => {
                if let Some(st) = self.forall(var, set, body, *span, scope) {
                    out.push(st);
                }
            }
            ast::Stmt::SetEdit {
                op,
                elem,
                set,
                span,
            } => {
                if let Some(st) = self.set_edit(*op, elem, set, *span, scope) {
                    out.push(st);
                }
            }
            ast::Stmt::If { cond, then, els } => {
                let c = self.condition(cond, scope);
                let t = self.sub_stmt(then, scope);
                let e = els.as_ref().map(|e| Box::new(self.sub_stmt(e, scope)));
                if let Some(c) = c {
                    out.push(St::If(c, Box::new(t), e));
                }
            }
            ast::Stmt::While { cond, body, span } => {
                let c = self.condition(cond, scope);
                scope.loops += 1;
                let b = self.sub_stmt(body, scope);
                scope.loops -= 1;
                if let Some(c) = c {
                    out.push(St::Loop {
                        cond: Some(c),
                        body: Box::new(b),
                        step: None,
                        test_after: false,
                        span: *span,
                    });
                }
            }
            ast::Stmt::DoWhile { body, cond, span } => {
                scope.loops += 1;
                let b = self.sub_stmt(body, scope);
                scope.loops -= 1;
                if let Some(c) = self.condition(cond, scope) {
                    out.push(St::Loop {
                        cond: Some(c),
                        body: Box::new(b),
                        step: None,
                        test_after: true,
                        span: *span,
                    });
                }
            }
            ast::Stmt::For {
                init,
                cond,
                step,
                body,
                span,
            } => {
                scope.push();
                let mut stmts = Vec::new();
                if let Some(i) = init {
                    self.stmt(i, scope, &mut stmts);
                }
                let c = cond.as_ref().and_then(|c| self.condition(c, scope));
                let st = step
                    .as_ref()
                    .and_then(|e| self.expr(e, scope))
                    .map(|(e, _)| e);
                scope.loops += 1;
                let b = self.sub_stmt(body, scope);
                scope.loops -= 1;
                scope.pop();
                stmts.push(St::Loop {
                    cond: c,
                    body: Box::new(b),
                    step: st,
                    test_after: false,
                    span: *span,
                });
                out.push(St::Block(stmts));
            }
            ast::Stmt::Block(b) => out.push(St::Block(self.block_stmts(&b.stmts, scope))),
            ast::Stmt::Produce {
                modules,
                last,
                span,
            } => {
                if !scope.in_rule {
                    let kw = if *last { "produce" } else { "nproduce" };
                    self.err(
                        *span,
                        format!("`{kw}` is only allowed in the body of a production or rule"),
                    );
                    return;
                }
                let modules = self.successors(modules, scope);
                out.push(St::Produce {
                    modules,
                    last: *last,
                });
            }
            ast::Stmt::Return(value, span) => self.return_stmt(value.as_ref(), *span, scope, out),
            ast::Stmt::Switch { value, body, span } => self.switch(value, body, *span, scope, out),
            ast::Stmt::Break(_)
            | ast::Stmt::Continue(_)
            | ast::Stmt::Case(..)
            | ast::Stmt::Default(_) => self.jump(s, scope, out),
            ast::Stmt::Empty => {}
        }
    }

    /// `break`, `continue`, and a `case` or `default` label found outside
    /// a `switch`'s body. (Out of `stmt`, so that the frame of that
    /// recursive function stays small.)
    #[inline(never)]
    fn jump(&mut self, s: &ast::Stmt, scope: &Scope, out: &mut Vec<St>) {
        match s {
            ast::Stmt::Break(span) if scope.loops == 0 && scope.switches == 0 => {
                self.err(*span, "`break` is only allowed inside a loop or a `switch`")
            }
            ast::Stmt::Break(_) => out.push(St::Break),
            ast::Stmt::Continue(span) if scope.loops == 0 => {
                self.err(*span, "`continue` is only allowed inside a loop")
            }
            ast::Stmt::Continue(_) => out.push(St::Continue),
            ast::Stmt::Case(_, span) => self.err(
                *span,
                "a `case` label belongs directly in the body of a `switch`",
            ),
            ast::Stmt::Default(span) => self.err(
                *span,
                "a `default` label belongs directly in the body of a `switch`",
            ),
            _ => {}
        }
    }

    /// `switch (value) { case 1: ... default: ... }`: C's semantics. The
    /// labels are integer constants, each value once; control enters at
    /// the matching label and falls through the labels after it until a
    /// `break`. A label may not jump past a declaration of the body.
    #[inline(never)]
    fn switch(
        &mut self,
        value: &ast::Expr,
        body: &[ast::Stmt],
        span: Span,
        scope: &mut Scope,
        out: &mut Vec<St>,
    ) {
        let checked = self.expr(value, scope).and_then(|(ex, ty)| {
            if matches!(ty, Ty::Int | Ty::Bool) {
                Some(ex)
            } else {
                let found = self.type_name(ty);
                self.err(
                    value.span,
                    format!(
                        "the value of `switch` must be an integer (an int, a char, a bool or an enumerator), found {found}"
                    ),
                );
                None
            }
        });
        scope.push();
        scope.switches += 1;
        let mut stmts: Vec<St> = Vec::new();
        let mut cases: Vec<(i64, u32, Span)> = Vec::new();
        let mut default: Option<(u32, Span)> = None;
        let mut declared: Option<&ast::Name> = None;
        for s in body {
            let at = stmts.len() as u32;
            match s {
                ast::Stmt::Case(e, label) => {
                    let value = self
                        .expr(e, scope)
                        .map(|(ex, _)| match self.const_value(&ex, 0) {
                            Some(Value::Bool(b)) => Some(Value::Int(b as i64)),
                            v => v,
                        });
                    match value {
                        None => {}
                        Some(Some(Value::Int(v))) if cases.iter().any(|c| c.0 == v) => {
                            self.err(
                                e.span,
                                format!("this `case` is {v}, which is already a label of this `switch`"),
                            );
                        }
                        Some(Some(Value::Int(v))) => cases.push((v, at, *label)),
                        Some(_) => self.err(
                            e.span,
                            "a `case` label must be an integer constant: a number, a character, an enumerator or a `const int` global",
                        ),
                    }
                }
                ast::Stmt::Default(label) => {
                    if default.is_some() {
                        self.err(*label, "this `switch` already has a `default` label");
                    } else {
                        default = Some((at, *label));
                    }
                }
                _ => {
                    if let ast::Stmt::Decl(d) = s {
                        declared = declared.or(d.vars.first().map(|v| &v.name));
                    }
                    self.stmt(s, scope, &mut stmts);
                    continue;
                }
            }
            if let Some(name) = declared {
                let label = match s {
                    ast::Stmt::Case(_, l) | ast::Stmt::Default(l) => *l,
                    _ => span,
                };
                self.err(
                    label,
                    format!(
                        "this label jumps past the declaration of `{}`; put the statements of the case in braces `{{ }}`",
                        name.text
                    ),
                );
            }
        }
        scope.switches -= 1;
        scope.pop();
        if let Some(value) = checked {
            let mut cases: Vec<(i64, u32)> = cases.into_iter().map(|c| (c.0, c.1)).collect();
            cases.sort_unstable();
            out.push(St::Switch {
                value,
                cases,
                default: default.map(|d| d.0),
                body: stmts,
            });
        }
    }

    fn sub_stmt(&mut self, s: &ast::Stmt, scope: &mut Scope) -> St {
        scope.push();
        let mut v = Vec::new();
        self.stmt(s, scope, &mut v);
        scope.pop();
        if v.len() == 1 {
            v.pop().expect("one")
        } else {
            St::Block(v)
        }
    }

    /// A new local variable, or the error that there are too many, at
    /// `span`.
    fn local(&mut self, scope: &mut Scope, name: &str, ty: Ty, span: Span) -> u16 {
        let slot = scope.declare(name, ty);
        if scope.full {
            self.too_many_locals(scope, span);
        }
        let width = match ty {
            Ty::Struct(i) => self.struct_shapes[i as usize].0,
            _ => 1,
        };
        let before = scope.values;
        scope.values = scope.values.saturating_add(width);
        if before <= MAX_BODY_VALUES && scope.values > MAX_BODY_VALUES {
            self.err(
                span,
                format!(
                    "the local variables of this body hold more than {MAX_BODY_VALUES} \
                     values (an array counts its elements), the limit"
                ),
            );
        }
        slot
    }

    fn too_many_locals(&mut self, scope: &mut Scope, span: Span) {
        if scope.full && !std::mem::replace(&mut scope.full_reported, true) {
            self.err(
                span,
                format!(
                    "more than {MAX_LOCALS} local variables in one body (parameters, \
                     declarations and inlined functions' arguments); split it into several rules"
                ),
            );
        }
    }

    fn condition(&mut self, e: &ast::Expr, scope: &mut Scope) -> Option<Ex> {
        let (ex, ty) = self.expr(e, scope)?;
        self.condition_of(ex, ty, e.span)
    }

    fn place(&mut self, e: &ast::Expr, scope: &mut Scope) -> Option<Place> {
        self.place_of(e, scope, true)
    }

    /// The place `e` names; `write` when it is to be assigned (a `const`
    /// is refused).
    fn place_of(&mut self, e: &ast::Expr, scope: &mut Scope, write: bool) -> Option<Place> {
        match &e.kind {
            ExprKind::Ident(n) => {
                if let Some((ty, slot, true)) = scope.lookup_var(n) {
                    if self.globals[slot as usize].is_const && write {
                        self.err(
                            e.span,
                            format!("cannot assign to `{n}`: it is declared const"),
                        );
                        return None;
                    }
                    return Some(Place {
                        global: true,
                        slot,
                        path: Vec::new(),
                        ty,
                        chars: self.global_chars.get(&slot).cloned().map(Box::new),
                    });
                }
                if let Some((ty, slot)) = scope.lookup(n) {
                    if write && scope.consts.contains(&slot) {
                        self.err(
                            e.span,
                            format!("cannot assign to `{n}`: it is declared const"),
                        );
                        return None;
                    }
                    return Some(Place {
                        global: false,
                        slot,
                        path: Vec::new(),
                        ty,
                        chars: scope.chars_of(n).cloned().map(Box::new),
                    });
                }
                if let Some(&g) = self.global_names.get(n) {
                    let gv = &self.globals[g as usize];
                    if write && gv.is_const {
                        self.err(
                            e.span,
                            format!("cannot assign to `{n}`: it is declared const"),
                        );
                        return None;
                    }
                    return Some(Place {
                        global: true,
                        slot: g,
                        path: Vec::new(),
                        ty: gv.ty,
                        chars: self.global_chars.get(&g).cloned().map(Box::new),
                    });
                }
                let hint = self.value_hint(n, scope);
                self.err(e.span, format!("unknown identifier `{n}`{hint}"));
                None
            }
            ExprKind::Field(base, f) => {
                let mut p = self.place_of(base, scope, write)?;
                let (idx, ty) = self.field_of(p.ty, f)?;
                // A field declared as a `char` array, or none.
                p.chars = match p.ty {
                    Ty::Struct(s) => self.field_chars.get(&(s, idx)).map(|c| {
                        Box::new(CharArray {
                            name: written_place(e),
                            ..c.clone()
                        })
                    }),
                    _ => None,
                };
                p.path.push(Step::Field(idx));
                p.ty = ty;
                Some(p)
            }
            ExprKind::Index(base, index) => {
                let p = self.place_of(base, scope, write);
                let i = self.index(index, scope);
                let (mut p, i) = (p?, i?);
                let elem = self.elem_of(p.ty, e.span)?;
                // An element of an array of `char` arrays is one of them;
                // a string's character is none.
                if p.ty == Ty::Str {
                    p.chars = None;
                } else if let Some(c) = &mut p.chars {
                    c.name = written_place(e);
                }
                p.path.push(Step::Index(Box::new(i), e.span));
                p.ty = elem;
                Some(p)
            }
            _ => {
                self.err(e.span, "expected a variable or a field to assign to");
                None
            }
        }
    }

    fn field_of(&mut self, ty: Ty, f: &ast::Name) -> Option<(u16, Ty)> {
        let found = match ty {
            t if t.is_vector() => ["x", "y", "z"][..t.dim()]
                .iter()
                .position(|c| *c == f.text)
                .map(|i| (i as u16, t.scalar())),
            Ty::Struct(s) => self.struct_fields[s as usize]
                .get(&f.text)
                .map(|&i| (i, self.structs[s as usize].fields[i as usize].1)),
            _ => None,
        };
        if found.is_none() {
            self.err(
                f.span,
                format!("{} has no field `{}`", self.type_name(ty), f.text),
            );
        }
        found
    }

    /// Compiles an expression. The parser bounds the nesting of what is
    /// written; inlined functions nest their bodies inside their calls, so
    /// the same bound is kept here (and so on the interpreter's recursion).
    fn expr(&mut self, e: &ast::Expr, scope: &mut Scope) -> Typed {
        self.nested(1, e.span, |c| c.expr_inner(e, scope))
    }

    /// Runs `f` `levels` deeper, or refuses with the nesting limit's
    /// message at `span`.
    fn nested(&mut self, levels: usize, span: Span, f: impl FnOnce(&mut Self) -> Typed) -> Typed {
        if self.depth + levels > MAX_NESTING {
            self.err(
                span,
                format!(
                    "this is nested more than {MAX_NESTING} levels deep once the functions it \
                     calls are inlined; split it into simpler parts"
                ),
            );
            return None;
        }
        self.depth += levels;
        let r = f(self);
        self.depth -= levels;
        r
    }

    fn expr_inner(&mut self, e: &ast::Expr, scope: &mut Scope) -> Typed {
        let span = e.span;
        match &e.kind {
            ExprKind::Int(i) => Some((Ex::Const(Value::Int(*i)), Ty::Int)),
            // A literal without a suffix is a `double`, as in C.
            // A literal with an `f` suffix is a `float` (its value is
            // already the nearest single-precision one).
            ExprKind::Float(f, true) => Some((Ex::Const(Value::Float(*f)), self.prec(Ty::Float))),
            ExprKind::Float(f, false) => Some((Ex::Const(Value::Float(*f)), Ty::Double)),
            ExprKind::Str(s) => Some((
                Ex::Const(Value::Str(super::stdio::unescape(s).into())),
                Ty::Str,
            )),
            ExprKind::Ident(n) => {
                if let Some((ty, slot, global)) = scope.lookup_var(n) {
                    return Some((
                        if global {
                            Ex::Global(slot)
                        } else {
                            Ex::Local(slot)
                        },
                        ty,
                    ));
                }
                if let Some(&g) = self.global_names.get(n) {
                    return Some((Ex::Global(g), self.globals[g as usize].ty));
                }
                if let Some(&v) = self.enum_consts.get(n) {
                    return Some((Ex::Const(Value::Int(v)), Ty::Int));
                }
                if self.ambiguous_enums.contains(n) {
                    return self.ambiguous_enumerator(n, span);
                }
                let handle = match n.as_str() {
                    "NULL" => Some(0),
                    "stdout" => Some(super::stdio::STDOUT),
                    "stderr" => Some(super::stdio::STDERR),
                    _ => None,
                };
                if let Some(h) = handle {
                    return Some((Ex::Const(Value::Int(h)), Ty::Int));
                }
                if let Some((f, ty)) = self.host.value(n) {
                    return Some((Ex::Call(f, Vec::new(), span), self.prec(ty)));
                }
                let c = match n.as_str() {
                    "true" => Value::Bool(true),
                    "false" => Value::Bool(false),
                    "M_PI" | "PI" => Value::Float(std::f64::consts::PI),
                    "M_PI_2" => Value::Float(std::f64::consts::FRAC_PI_2),
                    "M_E" => Value::Float(std::f64::consts::E),
                    "M_SQRT2" => Value::Float(std::f64::consts::SQRT_2),
                    "RAND_MAX" => Value::Int(super::random::RAND_MAX),
                    _ => {
                        let hint = if self.alphabet.lookup(n).is_some() {
                            format!(": `{n}` is a module, not a value")
                        } else {
                            self.value_hint(n, scope)
                        };
                        self.err(span, format!("unknown identifier `{n}`{hint}"));
                        return None;
                    }
                };
                let ty = match c {
                    Value::Bool(_) => Ty::Bool,
                    Value::Int(_) => Ty::Int,
                    _ => Ty::Double,
                };
                Some((Ex::Const(c), ty))
            }
            ExprKind::Unary(op, a) => {
                let (x, t) = self.expr(a, scope)?;
                let (x, t) = self.arith(x, t, a.span);
                match op {
                    UnOp::Plus if t.is_numeric() || t.is_vector() => Some((x, t)),
                    UnOp::Neg if t.is_numeric() || t.is_vector() => {
                        let t = if t == Ty::Bool { Ty::Int } else { t };
                        Some((fold_unary(Ex::Neg(Box::new(x))), t))
                    }
                    UnOp::Not if t.is_numeric() => Some((Ex::Not(Box::new(x)), Ty::Bool)),
                    _ => {
                        let sym = match op {
                            UnOp::Neg => "-",
                            UnOp::Plus => "+",
                            UnOp::Not => "!",
                        };
                        self.err(
                            span,
                            format!(
                                "type error: cannot apply unary `{sym}` to {}",
                                self.type_name(t)
                            ),
                        );
                        None
                    }
                }
            }
            ExprKind::Binary(op, a, b) => {
                let l = self.expr(a, scope);
                let r = self.expr(b, scope);
                let ((lx, lt), (rx, rt)) = (l?, r?);
                let (lx, lt) = self.arith(lx, lt, a.span);
                let (rx, rt) = self.arith(rx, rt, b.span);
                let Some(ty) = binary_type(*op, lt, rt) else {
                    self.err(
                        span,
                        format!(
                            "type error: cannot apply `{}` to {} and {}",
                            op.symbol(),
                            self.type_name(lt),
                            self.type_name(rt)
                        ),
                    );
                    return None;
                };
                if *op == BinOp::Div && !lt.is_floating() && !rt.is_floating() && ty == Ty::Int {
                    self.int_divisions.push(span);
                }
                // A float result, or a float on either side (a comparison):
                // the integers are read as floats.
                if !matches!(ty, Ty::Int | Ty::Bool) || lt.is_floating() || rt.is_floating() {
                    self.check_truncation(&lx);
                    self.check_truncation(&rx);
                }
                // Single-precision arithmetic: C converts a scalar operand
                // to `float` first (lpfg's `V2f * s` takes a float), then
                // rounds the result.
                let arithmetic = matches!(
                    op,
                    BinOp::Add | BinOp::Sub | BinOp::Mul | BinOp::Div | BinOp::Rem
                );
                let (lx, rx) = if arithmetic && ty.is_single() {
                    let to_float = |x: Ex, t: Ty| {
                        if t.is_numeric() && t != Ty::Float {
                            fold_unary(Ex::Convert(Ty::Float, Box::new(x)))
                        } else {
                            x
                        }
                    };
                    (to_float(lx, lt), to_float(rx, rt))
                } else {
                    (lx, rx)
                };
                if let Some(c) = fold_constants(*op, &lx, &rx) {
                    return Some((Ex::Convert(ty, Box::new(c)), ty))
                        .map(|(x, t)| (fold_unary(x), t));
                }
                let ex = match op {
                    BinOp::And => Ex::Logic(true, Box::new(lx), Box::new(rx)),
                    BinOp::Or => Ex::Logic(false, Box::new(lx), Box::new(rx)),
                    _ => Ex::Bin(*op, Box::new(lx), Box::new(rx), span),
                };
                let ex = if arithmetic { self.round(ex, ty) } else { ex };
                Some((ex, ty))
            }
            ExprKind::Assign(op, lhs, rhs) if matches!(lhs.kind, ExprKind::Prop(..)) => {
                self.assign_property(*op, lhs, rhs, span, scope)
            }
            ExprKind::IncDec {
                target,
                delta,
                prefix,
            } if matches!(target.kind, ExprKind::Prop(..)) => {
                let one = ast::Expr {
                    kind: ExprKind::Int(1),
                    span,
                };
                let op = if *delta > 0 { BinOp::Add } else { BinOp::Sub };
                let (x, ty) = self.assign_property(Some(op), target, &one, span, scope)?;
                if *prefix {
                    return Some((x, ty));
                }
                if ty != Ty::Int {
                    self.err(
                        span,
                        "a property's `++`/`--` after it gives its old value only for an int; write `v$x += 1`",
                    );
                    return None;
                }
                let back = if *delta > 0 { BinOp::Sub } else { BinOp::Add };
                Some((
                    Ex::Bin(back, Box::new(x), Box::new(Ex::Const(Value::Int(1))), span),
                    ty,
                ))
            }
            ExprKind::Assign(op, lhs, rhs) => {
                let place = self.place(lhs, scope);
                let (rx, rhs_ty) = self.expr(rhs, scope)?;
                let place = place?;
                let rt = match op {
                    None => rhs_ty,
                    Some(o) => match binary_type(*o, place.ty, rhs_ty) {
                        Some(t) => t,
                        None => {
                            self.err(
                                span,
                                format!(
                                    "type error: cannot apply `{}=` to {} and {}",
                                    o.symbol(),
                                    self.type_name(place.ty),
                                    self.type_name(rhs_ty)
                                ),
                            );
                            return None;
                        }
                    },
                };
                let vectors = rt.is_vector() && rt.dim() == place.ty.dim();
                if !(rt == place.ty || (rt.is_numeric() && place.ty.is_numeric()) || vectors) {
                    self.err(
                        span,
                        format!(
                            "type mismatch in assignment: expected {}, found {}",
                            self.type_name(place.ty),
                            self.type_name(rt)
                        ),
                    );
                    return None;
                }
                let ty = place.ty;
                // `v *= s` on a `V2f` takes a float `s`, as lpfg's operator
                // does; the store rounds the result (`Value::convert`).
                let rx = if op.is_some() && ty.is_vector() && ty.is_single() && rhs_ty.is_numeric()
                {
                    fold_unary(Ex::Convert(Ty::Float, Box::new(rx)))
                } else {
                    rx
                };
                // A string assigned to a declared `char` array must fit.
                let rx = match &place.chars {
                    Some(c) => self.fit(rx, c, "the assignment", span)?,
                    None => rx,
                };
                Some((Ex::Assign(place, *op, Box::new(rx), ty), ty))
            }
            ExprKind::IncDec {
                target,
                delta,
                prefix,
            } => {
                let place = self.place(target, scope)?;
                if !place.ty.is_numeric() {
                    self.err(
                        span,
                        format!(
                            "type error: `++`/`--` need a number, found {}",
                            self.type_name(place.ty)
                        ),
                    );
                    return None;
                }
                let ty = place.ty;
                Some((Ex::IncDec(place, *delta, *prefix), ty))
            }
            ExprKind::Cond(c, a, b) => {
                let c = self.condition(c, scope);
                let l = self.expr(a, scope);
                let r = self.expr(b, scope);
                let (c, (lx, lt), (rx, rt)) = (c?, l?, r?);
                let ((lx, lt), (rx, rt)) = if lt == rt {
                    ((lx, lt), (rx, rt))
                } else {
                    (self.arith(lx, lt, a.span), self.arith(rx, rt, b.span))
                };
                let ty = if lt == rt {
                    lt
                } else if lt.is_numeric() && rt.is_numeric() {
                    lt.wider(rt).wider(Ty::Int)
                } else if lt.is_vector() && lt.dim() == rt.dim() {
                    lt.wider(rt)
                } else {
                    self.err(
                        span,
                        format!(
                            "type error: the branches of `?:` have different types, {} and {}",
                            self.type_name(lt),
                            self.type_name(rt)
                        ),
                    );
                    return None;
                };
                if ty.is_floating() {
                    self.check_truncation(&lx);
                    self.check_truncation(&rx);
                }
                let lx = if lt == ty {
                    lx
                } else {
                    fold_unary(Ex::Convert(ty, Box::new(lx)))
                };
                let rx = if rt == ty {
                    rx
                } else {
                    fold_unary(Ex::Convert(ty, Box::new(rx)))
                };
                Some((Ex::Cond(Box::new(c), Box::new(lx), Box::new(rx)), ty))
            }
            ExprKind::Cast(t, a) => {
                let ty = self.resolve_type(t);
                let (x, xt) = self.expr(a, scope)?;
                let ty = ty?;
                if xt == ty {
                    return Some((x, ty));
                }
                let vectors = xt.is_vector() && xt.dim() == ty.dim();
                if !(xt.is_numeric() && ty.is_numeric() || vectors) {
                    self.err(
                        span,
                        format!(
                            "cannot cast {} to {}",
                            self.type_name(xt),
                            self.type_name(ty)
                        ),
                    );
                    return None;
                }
                Some((fold_unary(Ex::Convert(ty, Box::new(x))), ty))
            }
            ExprKind::Field(..) | ExprKind::Index(..) | ExprKind::List(_) => self.access(e, scope),
            ExprKind::Method(recv, name, args) => self.method(recv, name, args, span, scope),
            ExprKind::Gather { op, var, set, cond } => {
                self.gather(op, Some(var), set, cond.as_deref(), scope)
            }
            ExprKind::Call(name, args) => self.call(name, args, span, scope),
            ExprKind::Prop(target, name) => {
                let (tx, tt) = self.expr(target, scope)?;
                let (_, index, ty) = self.property(tt, name, span)?;
                let get = self.host.properties?.get;
                Some((
                    Ex::Call(
                        Func::Host(get),
                        vec![tx, Ex::Const(Value::Int(index as i64))],
                        span,
                    ),
                    ty,
                ))
            }
            ExprKind::InContext(kind, pats) => {
                if !scope.in_rule {
                    self.err(
                        span,
                        "context tests are only allowed in the body of a production",
                    );
                    return None;
                }
                let mut out = Vec::new();
                let mut all_places = Vec::new();
                for p in pats {
                    let (sym, tys, width) = self.module_params(&p.name, p.params.len())?;
                    for (n, t) in p.params.iter().zip(tys.iter().copied()) {
                        let ident = ast::Expr {
                            kind: ExprKind::Ident(n.text.clone()),
                            span: n.span,
                        };
                        let place = self.place(&ident, scope)?;
                        let vectors = t.is_vector() && place.ty.dim() == t.dim();
                        if !(place.ty == t || (place.ty.is_numeric() && t.is_numeric()) || vectors)
                        {
                            self.err(
                                n.span,
                                format!(
                                    "`{}` has type {} but this parameter of `{}` is {}",
                                    n.text,
                                    self.type_name(place.ty),
                                    p.name.text,
                                    self.type_name(t)
                                ),
                            );
                            return None;
                        }
                        all_places.push(place);
                    }
                    out.push(Pattern {
                        sym,
                        slots: Vec::new(),
                        types: tys,
                        width,
                    });
                }
                Some((Ex::InContext(*kind, out, all_places), Ty::Bool))
            }
        }
    }

    /// A field, an element of an array, or a misplaced `{...}`; out of
    /// `expr_inner`, so that its frame stays small for deep nesting.
    #[inline(never)]
    fn access(&mut self, e: &ast::Expr, scope: &mut Scope) -> Typed {
        let span = e.span;
        match &e.kind {
            ExprKind::Field(base, f) => {
                if self.indexes_a_variable(e, scope) {
                    let p = self.place_of(e, scope, false)?;
                    let ty = p.ty;
                    return Some((Ex::Load(p), ty));
                }
                let (x, t) = self.expr(base, scope)?;
                let (idx, ft) = self.field_of(t, f)?;
                Some((Ex::Field(Box::new(x), idx), ft))
            }
            ExprKind::Index(base, index) => {
                if self.indexes_a_variable(e, scope) {
                    let p = self.place_of(e, scope, false)?;
                    let ty = p.ty;
                    return Some((Ex::Load(p), ty));
                }
                let b = self.expr(base, scope);
                let i = self.index(index, scope);
                let ((bx, bt), i) = (b?, i?);
                let elem = self.elem_of(bt, span)?;
                Some((Ex::Index(Box::new(bx), Box::new(i), span), elem))
            }
            _ => {
                self.err(
                    span,
                    "a `{...}` list is an initializer: it may only follow `=` in a declaration",
                );
                None
            }
        }
    }

    fn method(
        &mut self,
        recv: &ast::Expr,
        name: &ast::Name,
        args: &[ast::Expr],
        span: Span,
        scope: &mut Scope,
    ) -> Typed {
        let (x, t) = self.expr(recv, scope)?;
        if let (Ty::Struct(si), false) = (t, self.methods.is_empty()) {
            return self.struct_method(si, recv, name, args, span, scope);
        }
        if !t.is_vector() || !args.is_empty() {
            self.err(
                name.span,
                format!(
                    "{} has no method `{}` taking {} argument(s)",
                    self.type_name(t),
                    name.text,
                    args.len()
                ),
            );
            return None;
        }
        match name.text.as_str() {
            "Length" => Some((
                self.round(Ex::Call(Func::Length, vec![x], span), t.scalar()),
                t.scalar(),
            )),
            "Normalized" => Some((self.round(Ex::Call(Func::Normalized, vec![x], span), t), t)),
            "Normalize" => {
                let place = self.place(recv, scope)?;
                Some((
                    Ex::Assign(
                        place,
                        None,
                        Box::new(Ex::Call(Func::Normalized, vec![x], span)),
                        t,
                    ),
                    t,
                ))
            }
            _ => {
                self.err(
                    name.span,
                    format!(
                        "unknown method `{}`: vectors have Length(), Normalize() and Normalized()",
                        name.text
                    ),
                );
                None
            }
        }
    }

    fn call(
        &mut self,
        name: &ast::Name,
        args: &[ast::Expr],
        span: Span,
        scope: &mut Scope,
    ) -> Typed {
        let n = name.text.as_str();
        if let Some(&f) = self.function_names.get(n) {
            return self.inline(f, args, span, scope);
        }
        if let Some(&id) = self.user_fn_names.get(n) {
            return self.user_call(id, name, args, span, scope);
        }
        if let Some(r) = self.ctor_or_stdio_call(name, args, span, scope) {
            return r;
        }
        // A functional cast: `float(x)`, `int(x)`.
        if let ("int" | "float" | "double" | "bool" | "long" | "short" | "unsigned" | "char", [a]) =
            (n, args)
        {
            return self.functional_cast(name, a, span, scope);
        }
        let mut typed = Vec::new();
        let mut ok = true;
        for a in args {
            match self.expr(a, scope) {
                Some(t) => typed.push(t),
                None => ok = false,
            }
        }
        if !ok {
            return None;
        }
        if matches!(n, "V2f" | "V2d" | "V3f" | "V3d") {
            let ty = match n {
                "V2f" => self.prec(Ty::V2),
                "V3f" => self.prec(Ty::V3),
                "V2d" => Ty::V2d,
                _ => Ty::V3d,
            };
            let ex = self.construct(ty, typed, args, span)?;
            return Some((ex, ty));
        }
        // `avg(ring(v))`: an aggregate over a whole set.
        if let ("sum" | "avg" | "count", [(_, Ty::Elem(k))]) = (n, typed.as_slice()) {
            if (self.host.members)(*k).is_some() {
                let (set, ty) = typed.pop()?;
                return self.fold(name, set, ty, args[0].span, None, None, scope);
            }
        }
        // With `float` computed in double (`--double`), C's float
        // functions are their double twins: `expf` is `exp`.
        let float_function = builtins::is_float_function(n);
        let n = match (float_function, self.single) {
            (true, false) => &n[..n.len() - 1],
            _ => n,
        };
        let Some(b) = builtins::lookup(n, self.host) else {
            let hint = if self.alphabet.lookup(n).is_some() {
                format!(": `{n}` is a module; modules go after `produce`, not in expressions")
            } else if self.hint_allowed() {
                let names = self.function_names();
                super::suggest::hint(n, names.iter().map(String::as_str))
            } else {
                String::new()
            };
            self.err(name.span, format!("unknown function `{n}`{hint}"));
            return None;
        };
        let library = LIBRARY.iter().any(|l| l.name == n);
        if library {
            // The library takes numbers and vectors: elements read as
            // their values.
            typed = typed
                .into_iter()
                .zip(args)
                .map(|((x, t), a)| self.arith(x, t, a.span))
                .collect();
        }
        let tys: Vec<Ty> = typed.iter().map(|(_, t)| *t).collect();
        match (b.resolve)(&tys) {
            Ok((f, ty)) => {
                if matches!(f, Func::Math1(_) | Func::Math2(_)) {
                    for (x, _) in &typed {
                        self.check_truncation(x);
                    }
                }
                // lpfg's programs call C's maths functions of <math.h>,
                // not C++'s overloads: `sqrt` of a `float` is a `double`
                // (lpfg 9bf820d: `sqrt(x) * sqrt(x) - 2` with a float
                // `x = 2` is 4.4e-16, not the float -1.2e-7). A vector's
                // length or dot product has its components' precision.
                // What the library declares `float` (lpfg's `ran`,
                // `func`) is a single-precision result.
                let ty = match f {
                    // `expf`, `sqrtf`, …: a float whatever the argument.
                    Func::Math1(_) | Func::Math2(_) if float_function => self.prec(Ty::Float),
                    Func::Math1(_) | Func::Math2(_) => Ty::Double,
                    Func::Length | Func::Dot => tys.first().map_or(ty, |t| t.scalar()),
                    Func::Normalized | Func::Cross => tys.first().map_or(ty, |t| *t),
                    _ => self.prec(ty),
                };
                let exs = typed.into_iter().map(|(e, _)| e).collect();
                Some((self.round(fold_unary(Ex::Call(f, exs, span)), ty), ty))
            }
            Err(SigError::Arity(want)) => {
                self.err(
                    span,
                    format!(
                        "`{n}` takes {want} argument(s), but {} were given",
                        typed.len()
                    ),
                );
                None
            }
            Err(SigError::NotNumber(i)) => {
                let found = self.type_name(tys[i]);
                self.err(
                    args[i].span,
                    format!("type error: `{n}` expects a number, found {found}"),
                );
                None
            }
            Err(SigError::Message(m)) => {
                self.err(span, m);
                None
            }
        }
    }

    /// `sum(w in SET where COND)`: the variable is a local while the
    /// condition is checked.
    /// `e$name = rhs` and `e$name op= rhs`: the topology's property
    /// setter, which gives the value stored.
    fn assign_property(
        &mut self,
        op: Option<BinOp>,
        lhs: &ast::Expr,
        rhs: &ast::Expr,
        span: Span,
        scope: &mut Scope,
    ) -> Typed {
        let ExprKind::Prop(target, name) = &lhs.kind else {
            return None;
        };
        let (tx, tt) = self.expr(target, scope)?;
        let (_, index, ty) = self.property(tt, name, lhs.span)?;
        let props = self.host.properties?;
        let value = match op {
            None => rhs.clone(),
            Some(o) => ast::Expr {
                kind: ExprKind::Binary(o, Box::new(lhs.clone()), Box::new(rhs.clone())),
                span,
            },
        };
        let (vx, vt) = self.expr(&value, scope)?;
        let vx = self.coerce(vx, vt, ty, rhs.span)?;
        Some((
            Ex::Call(
                Func::Host(props.set),
                vec![tx, Ex::Const(Value::Int(index as i64)), vx],
                span,
            ),
            ty,
        ))
    }

    /// `forall x in S body`: `x` takes each member of a set, or each
    /// neighbour of a vertex (its members as the topology lists them).
    fn forall(
        &mut self,
        var: &ast::Name,
        set: &ast::Expr,
        body: &ast::Stmt,
        span: Span,
        scope: &mut Scope,
    ) -> Option<St> {
        let (sx, st) = self.expr(set, scope)?;
        let member = match st {
            Ty::Elem(k) => (self.host.members)(k),
            _ => None,
        };
        let Some(member) = member else {
            self.err(
                set.span,
                format!(
                    "`forall` goes over a set or a vertex's neighbours; this is {}",
                    self.type_name(st)
                ),
            );
            return None;
        };
        // A topology may check what a loop goes over (vv: a vertex that
        // has a neighbourhood to list) through its built-in `$forall`,
        // which gives it back; a host's `members` lists nothing otherwise.
        let sx = match self.host.function("$forall").map(|b| (b.resolve)(&[st])) {
            Some(Ok((f, _))) => Ex::Call(f, vec![sx], set.span),
            _ => sx,
        };
        scope.push();
        let slot = self.local(scope, &var.text, Ty::Elem(member), var.span);
        scope.loops += 1;
        let b = self.sub_stmt(body, scope);
        scope.loops -= 1;
        scope.pop();
        Some(St::ForAll {
            slot,
            set: sx,
            body: Box::new(b),
            span,
        })
    }

    /// `add v to S`, `remove v from S`, `merge S with T`: `S` must be a
    /// variable (or a field or element of one) holding a set.
    fn set_edit(
        &mut self,
        op: ast::SetEditOp,
        elem: &ast::Expr,
        set: &ast::Expr,
        span: Span,
        scope: &mut Scope,
    ) -> Option<St> {
        let place = self.place(set, scope);
        let ex = self.expr(elem, scope);
        let (place, (ex, et)) = (place?, ex?);
        let member = match place.ty {
            Ty::Elem(k) => (self.host.members)(k),
            _ => None,
        };
        let word = match op {
            ast::SetEditOp::Add => "add",
            ast::SetEditOp::Remove => "remove",
            ast::SetEditOp::Merge => "merge",
        };
        // A set's members are of another kind than the set; a vertex's
        // members are its neighbours, and a vertex is not a set to edit.
        let is_set = matches!(place.ty, Ty::Elem(k) if member != Some(k));
        let Some(member) = member.filter(|_| is_set) else {
            self.err(
                set.span,
                format!(
                    "`{word}` changes a set (a `mesh` variable); this is {}",
                    self.type_name(place.ty)
                ),
            );
            return None;
        };
        let want = match op {
            ast::SetEditOp::Merge => place.ty,
            _ => Ty::Elem(member),
        };
        if et != want {
            self.err(
                elem.span,
                format!(
                    "`{word}` takes {} here; this is {}",
                    self.type_name(want),
                    self.type_name(et)
                ),
            );
            return None;
        }
        let _ = span;
        // A topology may refuse what joins a set (vv: the null vertex)
        // through its built-in `$member`, which gives the element back.
        let ex = match (op, self.host.function("$member")) {
            (ast::SetEditOp::Add, Some(b)) => match (b.resolve)(&[et]) {
                Ok((f, _)) => Ex::Call(f, vec![ex], elem.span),
                Err(_) => ex,
            },
            _ => ex,
        };
        Some(St::SetEdit {
            place,
            op,
            elem: ex,
        })
    }

    fn gather(
        &mut self,
        op: &ast::Name,
        var: Option<&ast::Name>,
        set: &ast::Expr,
        cond: Option<&ast::Expr>,
        scope: &mut Scope,
    ) -> Typed {
        let (sx, st) = self.expr(set, scope)?;
        self.fold(op, sx, st, set.span, var, cond, scope)
    }

    #[allow(clippy::too_many_arguments)]
    fn fold(
        &mut self,
        op: &ast::Name,
        set: Ex,
        set_ty: Ty,
        set_span: Span,
        var: Option<&ast::Name>,
        cond: Option<&ast::Expr>,
        scope: &mut Scope,
    ) -> Typed {
        let fold_op = match op.text.as_str() {
            "sum" => FoldOp::Sum,
            "avg" => FoldOp::Avg,
            "count" => FoldOp::Count,
            other => {
                self.err(
                    op.span,
                    format!("unknown aggregate `{other}`: expected sum, avg or count"),
                );
                return None;
            }
        };
        let member = match set_ty {
            Ty::Elem(k) => (self.host.members)(k),
            _ => None,
        };
        let Some(member) = member else {
            let what = if self.host.elements.is_empty() {
                format!("a {} has no sets to sum over", self.host.name)
            } else {
                format!(
                    "`{}` sums over a set, such as `ring(v)`; this is {}",
                    op.text,
                    self.type_name(set_ty)
                )
            };
            self.err(set_span, what);
            return None;
        };
        if scope.next == u16::MAX {
            self.err(set_span, "this expression needs too many variables");
            return None;
        }
        // As for `forall`: the topology may check what is folded over.
        let set = match self
            .host
            .function("$forall")
            .map(|b| (b.resolve)(&[set_ty]))
        {
            Some(Ok((f, _))) => Ex::Call(f, vec![set], set_span),
            _ => set,
        };
        let mark = (scope.vars.len(), scope.next);
        let name = var.map_or("", |v| v.text.as_str());
        let slot = self.local(scope, name, Ty::Elem(member), op.span);
        let cond = match cond {
            Some(c) => self.condition(c, scope).map(|x| Some(Box::new(x))),
            None => Some(None),
        };
        let value = match fold_op {
            FoldOp::Count => Some(None),
            _ => {
                let (x, t) = self.arith(Ex::Local(slot), Ty::Elem(member), op.span);
                if t.is_numeric() || t.is_vector() {
                    Some(Some((Box::new(x), t)))
                } else {
                    self.err(
                        op.span,
                        format!(
                            "`{}` adds up values, but {} has no value to add",
                            op.text,
                            self.type_name(Ty::Elem(member))
                        ),
                    );
                    None
                }
            }
        };
        scope.truncate(mark.0);
        scope.next = mark.1;
        let (cond, value) = (cond?, value?);
        let ty = match (&value, fold_op) {
            (Some((_, t)), FoldOp::Sum) => *t,
            (Some((_, t)), FoldOp::Avg) if t.is_vector() => *t,
            (Some(_), FoldOp::Avg) => self.prec(Ty::Float),
            _ => Ty::Int,
        };
        Some((
            Ex::Fold {
                op: fold_op,
                slot,
                set: Box::new(set),
                cond,
                value,
            },
            ty,
        ))
    }

    // ----- C: arrays, enums, statics, functions, standard I/O ----------

    fn is_array(&self, ty: Ty) -> bool {
        matches!(ty, Ty::Struct(i) if self.structs[i as usize].elem.is_some())
    }

    /// The number of fields (or elements) of a struct type; 0 otherwise.
    fn fields_of(&self, ty: Ty) -> usize {
        match ty {
            Ty::Struct(i) => self.structs[i as usize].fields.len(),
            _ => 0,
        }
    }

    /// The element type of an array (a string's elements are `char`s,
    /// ints), or the error that `ty` has none.
    fn elem_of(&mut self, ty: Ty, span: Span) -> Option<Ty> {
        match ty {
            Ty::Struct(i) if self.structs[i as usize].elem.is_some() => {
                self.structs[i as usize].elem
            }
            Ty::Str => Some(Ty::Int),
            _ => {
                self.err(
                    span,
                    format!(
                        "{} is not an array: it cannot be indexed",
                        self.type_name(ty)
                    ),
                );
                None
            }
        }
    }

    /// An array index: an integer.
    #[inline(never)]
    fn index(&mut self, e: &ast::Expr, scope: &mut Scope) -> Option<Ex> {
        let (x, t) = self.expr(e, scope)?;
        if !matches!(t, Ty::Int | Ty::Bool) {
            self.err(
                e.span,
                format!(
                    "an array index must be an integer, found {}",
                    self.type_name(t)
                ),
            );
            return None;
        }
        Some(x)
    }

    /// True when `e` is a chain of fields and indices with at least one
    /// index, on a variable: read through a place, without copying the
    /// whole variable.
    #[inline(never)]
    fn indexes_a_variable(&self, e: &ast::Expr, scope: &Scope) -> bool {
        let mut indexed = false;
        let mut e = e;
        loop {
            match &e.kind {
                ExprKind::Index(b, _) => {
                    indexed = true;
                    e = b;
                }
                ExprKind::Field(b, _) => e = b,
                ExprKind::Ident(n) => {
                    return indexed
                        && (scope.lookup_var(n).is_some() || self.global_names.contains_key(n))
                }
                _ => return false,
            }
        }
    }

    /// The array type of `len` elements of `elem` (`None`: any length, a
    /// parameter's `float a[]`), made once.
    fn array_type(&mut self, elem: Ty, len: Option<usize>, span: Span) -> Option<Ty> {
        if let Some(&id) = self.array_types.get(&(elem, len)) {
            return Some(Ty::Struct(id));
        }
        let (values, depth) = match elem {
            Ty::Struct(i) => self.struct_shapes[i as usize],
            _ => (1, 0),
        };
        let total = values.saturating_mul(len.unwrap_or(0)).saturating_add(1);
        if total > MAX_ARRAY_VALUES {
            self.err(
                span,
                format!("this array holds more than {MAX_ARRAY_VALUES} values, the limit"),
            );
            return None;
        }
        if depth + 1 > MAX_NESTING {
            self.err(
                span,
                format!("arrays nest more than {MAX_NESTING} levels deep"),
            );
            return None;
        }
        if self.structs.len() >= MAX_DECLARED {
            self.too_many(MAX_DECLARED, "structs and array types", span);
            return None;
        }
        let elem_name = self.type_name(elem);
        let (head, tail) = match elem_name.find('[') {
            Some(k) if self.is_array(elem) => (&elem_name[..k], &elem_name[k..]),
            _ => (elem_name.as_str(), ""),
        };
        let dim = len.map(|n| n.to_string()).unwrap_or_default();
        let name = format!("{head}[{dim}]{tail}");
        let id = self.structs.len() as u16;
        self.array_types.insert((elem, len), id);
        self.struct_names.insert(name.clone(), id);
        self.struct_fields.push(HashMap::new());
        self.struct_shapes.push((total, depth + 1));
        self.structs.push(StructDef {
            name,
            fields: vec![(String::new(), elem); len.unwrap_or(0)],
            elem: Some(elem),
        });
        Some(Ty::Struct(id))
    }

    /// `ty` with the dimensions written after a name (`float a[3][2]`: 3
    /// arrays of 2 floats); a `char` array is a string. A first `[]` takes
    /// its length from `init_len` (the initializer's), or stays open (a
    /// parameter's).
    #[inline(never)]
    fn with_dims(
        &mut self,
        mut ty: Ty,
        base: &ast::TypeRef,
        dims: &[Option<ast::Expr>],
        init_len: Option<usize>,
        span: Span,
    ) -> Option<Ty> {
        let mut dims = dims;
        if base.name == "char" && !base.pointer && !dims.is_empty() {
            ty = Ty::Str;
            dims = &dims[..dims.len() - 1];
        }
        let mut lens = Vec::with_capacity(dims.len());
        for (k, d) in dims.iter().enumerate() {
            lens.push(match d {
                Some(e) => {
                    let n = self.const_int(e, "an array size")?;
                    if n <= 0 {
                        self.err(e.span, format!("an array size must be positive, found {n}"));
                        return None;
                    }
                    Some(n as usize)
                }
                None if k == 0 => init_len,
                None => {
                    self.err(
                        span,
                        "only an array's first dimension may be left empty (`[]`)",
                    );
                    return None;
                }
            });
        }
        for len in lens.into_iter().rev() {
            ty = self.array_type(ty, len, span)?;
        }
        Some(ty)
    }

    /// The type a declarator gives its variable: `char *s` is a string,
    /// `FILE *f` a handle, `float a[3]` an array.
    #[inline(never)]
    fn declarator_type(
        &mut self,
        base: Ty,
        tref: &ast::TypeRef,
        d: &ast::Declarator,
    ) -> Option<Ty> {
        let mut base = base;
        if d.pointer || tref.pointer {
            base = match tref.name.as_str() {
                "char" => Ty::Str,
                "FILE" => Ty::Int,
                _ => {
                    self.err(
                        d.name.span,
                        format!(
                            "pointers are not supported (`{} *{}`); use an array, or a reference parameter",
                            tref.name, d.name.text
                        ),
                    );
                    return None;
                }
            };
        }
        if base == Ty::Void {
            self.err(d.name.span, "a variable cannot have type void");
            return None;
        }
        let init_len = match &d.init {
            Init::List(items, _) => Some(items.len()),
            Init::Expr(ast::Expr {
                kind: ExprKind::Str(s),
                ..
            }) => Some(s.len() + 1),
            _ => None,
        };
        if d.dims.first().is_some_and(|d| d.is_none()) && init_len.is_none() {
            self.err(
                d.name.span,
                format!("`{}[]` needs a size or an initializer list", d.name.text),
            );
            return None;
        }
        let char_tref;
        let tref = if d.pointer && tref.name == "char" {
            char_tref = ast::TypeRef {
                pointer: true,
                ..tref.clone()
            };
            &char_tref
        } else {
            tref
        };
        self.with_dims(base, tref, &d.dims, init_len, d.name.span)
    }

    /// `{1, 2, 3}` for an array or a struct, nested lists for their
    /// elements; missing elements are zero, as in C.
    #[inline(never)]
    fn list_init(
        &mut self,
        ty: Ty,
        items: &[ast::Expr],
        span: Span,
        scope: &mut Scope,
    ) -> Option<Ex> {
        let want = self.parts_of(ty);
        if items.len() > want.len() || (!matches!(ty, Ty::Struct(_)) && items.len() != want.len()) {
            self.err(
                span,
                format!(
                    "{} takes {} value(s) here, but {} were given",
                    self.type_name(ty),
                    want.len(),
                    items.len()
                ),
            );
            return None;
        }
        let mut parts = Vec::with_capacity(want.len());
        let mut ok = true;
        for (k, w) in want.iter().enumerate() {
            let part = match items.get(k) {
                None => Some(Ex::Const(Value::zero(*w, &self.structs))),
                Some(ast::Expr {
                    kind: ExprKind::List(inner),
                    span,
                }) => self
                    .list_init(*w, inner, *span, scope)
                    .and_then(|x| self.fit_field(ty, k, x, *span)),
                Some(e) => self
                    .expr(e, scope)
                    .and_then(|(x, t)| self.coerce(x, t, *w, e.span))
                    .and_then(|x| self.fit_field(ty, k, x, e.span)),
            };
            match part {
                Some(p) => parts.push(p),
                None => ok = false,
            }
        }
        if !ok {
            return None;
        }
        assemble(ty, parts)
    }

    /// An integer constant: a literal, an enumerator, a `const` global
    /// with a constant initializer, or arithmetic of those.
    #[inline(never)]
    fn const_int(&mut self, e: &ast::Expr, what: &str) -> Option<i64> {
        let mut scope = Scope::default();
        let (ex, _) = self.expr(e, &mut scope)?;
        match self.const_value(&ex, 0) {
            Some(Value::Int(i)) => Some(i),
            Some(Value::Bool(b)) => Some(b as i64),
            _ => {
                self.err(e.span, format!("{what} must be an integer constant"));
                None
            }
        }
    }

    /// `e`'s value when it is an integer constant; `None`, and nothing
    /// reported, otherwise.
    fn quiet_const_int(&mut self, e: &ast::Expr) -> Option<i64> {
        let (diags, warnings) = (self.diags.len(), self.warnings.len());
        let mut scope = Scope::default();
        let v = self
            .expr(e, &mut scope)
            .and_then(|(ex, _)| self.const_value(&ex, 0));
        self.diags.truncate(diags);
        self.warnings.truncate(warnings);
        match v {
            Some(Value::Int(i)) => Some(i),
            Some(Value::Bool(b)) => Some(b as i64),
            _ => None,
        }
    }

    /// The `char` array that a declarator declares (`char b[4]`,
    /// `char names[3][16]`, `char s[] = "abc"`): its size is the last
    /// dimension, or the length of the literal that initialises it and its
    /// NUL. `None` for any other declarator, for a `char *`, and for a
    /// size that is not a constant (C's variable-length array: its strings
    /// are not checked); a size of 0 or less is an error.
    #[inline(never)]
    fn char_array(
        &mut self,
        tref: &ast::TypeRef,
        pointer: bool,
        name: &ast::Name,
        dims: &[Option<ast::Expr>],
        init: &Init,
    ) -> Option<CharArray> {
        if tref.name != "char" || tref.pointer || pointer {
            return None;
        }
        let (last, outer) = dims.split_last()?;
        let size = match last {
            Some(e) => {
                let n = self.quiet_const_int(e)?;
                if n <= 0 {
                    self.err(e.span, format!("an array size must be positive, found {n}"));
                    return None;
                }
                usize::try_from(n).ok()?
            }
            None if outer.is_empty() => match init {
                Init::Expr(ast::Expr {
                    kind: ExprKind::Str(s),
                    ..
                }) => super::stdio::unescape(s).len() + 1,
                _ => return None,
            },
            None => return None,
        };
        let mut decl = format!("char {}", name.text);
        for (k, d) in outer.iter().enumerate() {
            let n = match d {
                Some(e) => self.quiet_const_int(e).map(|n| n.to_string()),
                None if k == 0 => match init {
                    Init::List(items, _) => Some(items.len().to_string()),
                    _ => None,
                },
                None => None,
            };
            decl.push_str(&format!("[{}]", n.unwrap_or_default()));
        }
        decl.push_str(&format!("[{size}]"));
        Some(CharArray {
            size,
            name: name.text.clone(),
            decl,
        })
    }

    /// A declared `char` array's initializer, checked to fit ([`Self::fit`]).
    fn fit_init(
        &mut self,
        init: Option<Ex>,
        chars: Option<&CharArray>,
        written: &Init,
    ) -> Option<Ex> {
        match (init, chars, written) {
            (Some(ex), Some(c), Init::Expr(e)) => self.fit(ex, c, "the initializer", e.span),
            (Some(ex), Some(c), Init::List(_, span)) => self.fit(ex, c, "the initializer", *span),
            (init, ..) => init,
        }
    }

    /// `part`, the value that initialises field `k` of a struct `ty`,
    /// checked to fit when the field is a `char` array ([`Self::fit`]).
    fn fit_field(&mut self, ty: Ty, k: usize, part: Ex, span: Span) -> Option<Ex> {
        let Ty::Struct(s) = ty else {
            return Some(part);
        };
        match u16::try_from(k)
            .ok()
            .and_then(|k| self.field_chars.get(&(s, k)))
            .cloned()
        {
            Some(c) => self.fit(part, &c, "the initializer", span),
            None => Some(part),
        }
    }

    /// `value`, the string (or array of strings) that `what` writes into
    /// the declared `char` array `c`, checked to fit there with its
    /// terminating NUL: now when `value` is a constant (a string that does
    /// not fit is reported at `span`, and gives `None`), else when it
    /// runs, an error located at `span`.
    fn fit(&mut self, value: Ex, c: &CharArray, what: &str, span: Span) -> Option<Ex> {
        if let Some(v) = self.const_written(&value) {
            if let Some(m) = c.overflow(what, &v) {
                self.err(span, m);
                return None;
            }
            return Some(value);
        }
        let text = |s: &str| Ex::Const(Value::Str(s.into()));
        Some(Ex::Call(
            Func::Io(super::stdio::IoFunc::Fit),
            vec![
                value,
                Ex::Const(Value::Int(c.size as i64)),
                text(what),
                text(&c.name),
                text(&c.decl),
            ],
            span,
        ))
    }

    /// The value `ex` makes when it is known before the program runs: a
    /// constant, a string function (`sprintf`'s formatting) of constants,
    /// or an array or struct of those.
    fn const_written(&self, ex: &Ex) -> Option<Value> {
        use super::stdio::IoFunc;
        Some(match ex {
            Ex::Call(
                Func::Io(
                    f @ (IoFunc::Format | IoFunc::Concat | IoFunc::Strncat | IoFunc::Snprintf),
                ),
                args,
                _,
            ) => {
                let vals = args
                    .iter()
                    .map(|a| self.const_value(a, 0))
                    .collect::<Option<Vec<_>>>()?;
                super::stdio::call(*f, &vals, &super::stdio::ProgramOutput::default()).ok()?
            }
            Ex::MakeStruct(parts) => Value::Struct(
                parts
                    .iter()
                    .map(|p| self.const_written(p))
                    .collect::<Option<Vec<_>>>()?
                    .into(),
            ),
            _ => self.const_value(ex, 0)?,
        })
    }

    fn const_value(&self, ex: &Ex, depth: usize) -> Option<Value> {
        if depth > MAX_NESTING {
            return None;
        }
        match ex {
            Ex::Const(v) => Some(v.clone()),
            Ex::Global(g) => {
                let gv = self.globals.get(*g as usize)?;
                if gv.is_const {
                    Some(
                        self.const_value(gv.init.as_ref()?, depth + 1)?
                            .convert(gv.ty),
                    )
                } else {
                    None
                }
            }
            Ex::Neg(a) => {
                super::eval::binary(BinOp::Sub, Value::Int(0), self.const_value(a, depth + 1)?).ok()
            }
            Ex::Convert(t, a) => Some(self.const_value(a, depth + 1)?.convert(*t)),
            Ex::Bin(op, a, b, _) => super::eval::binary(
                *op,
                self.const_value(a, depth + 1)?,
                self.const_value(b, depth + 1)?,
            )
            .ok(),
            _ => None,
        }
    }

    /// `enum Kind { A, B = 5, C };`: int constants, and `Kind` an int type.
    /// Declared in struct `S` (`scope`), they are also `S::A` and `S::Kind`,
    /// and `A` alone names them unless another struct declares an `A` too.
    fn enum_decl(
        &mut self,
        name: Option<&ast::Name>,
        variants: &[(ast::Name, Option<ast::Expr>)],
        scope: Option<&str>,
    ) {
        if let Some(n) = name {
            self.typedefs.insert(n.text.clone(), Ty::Int);
            if let Some(s) = scope {
                self.typedefs.insert(format!("{s}::{}", n.text), Ty::Int);
            }
        }
        let mut next = 0i64;
        for (v, value) in variants {
            if let Some(e) = value {
                match self.const_int(e, "an enumerator's value") {
                    Some(x) => next = x,
                    None => continue,
                }
            }
            if let Some(s) = scope {
                let scoped = format!("{s}::{}", v.text);
                if self.enum_consts.contains_key(&scoped) {
                    self.err(v.span, format!("`{scoped}` is already declared"));
                    continue;
                }
                self.enum_consts.insert(scoped, next);
                if self.struct_enums.remove(&v.text) {
                    self.enum_consts.remove(&v.text);
                    self.ambiguous_enums.insert(v.text.clone());
                } else if !self.enum_consts.contains_key(&v.text)
                    && !self.ambiguous_enums.contains(&v.text)
                {
                    self.enum_consts.insert(v.text.clone(), next);
                    self.struct_enums.insert(v.text.clone());
                }
                next = next.wrapping_add(1);
                continue;
            }
            // An enumerator outside structs hides those of structs.
            if self.struct_enums.remove(&v.text) {
                self.enum_consts.remove(&v.text);
            }
            self.ambiguous_enums.remove(&v.text);
            if self.enum_consts.contains_key(&v.text) || self.global_names.contains_key(&v.text) {
                self.err(v.span, format!("`{}` is already declared", v.text));
                continue;
            }
            self.enum_consts.insert(v.text.clone(), next);
            next = next.wrapping_add(1);
        }
    }

    /// Adds a global's (or a `static` local's) values to the program's
    /// total, which is limited as one body's locals are.
    fn count_global_values(&mut self, ty: Ty, span: Span) {
        let width = match ty {
            Ty::Struct(i) => self.struct_shapes[i as usize].0,
            _ => 1,
        };
        let before = self.global_values;
        self.global_values = before.saturating_add(width);
        if before <= MAX_BODY_VALUES && self.global_values > MAX_BODY_VALUES {
            self.err(
                span,
                format!(
                    "the global (and static) variables hold more than {MAX_BODY_VALUES} \
                     values (an array counts its elements), the limit"
                ),
            );
        }
    }

    /// `static int n = 0;` in a body: a global that only this body names,
    /// initialised once before the run.
    #[inline(never)]
    fn static_local(&mut self, d: &ast::VarDecl, v: &ast::Declarator, ty: Ty, scope: &mut Scope) {
        let chars = self.char_array(&d.ty, v.pointer, &v.name, &v.dims, &v.init);
        let mut init_scope = Scope::default();
        let init = self.initializer(ty, &v.init, v.name.span, &mut init_scope);
        let init = self.fit_init(init, chars.as_ref(), &v.init);
        if init_scope.max > 0 {
            self.err(
                v.name.span,
                "a static variable's initializer cannot declare variables",
            );
        }
        if self.globals.len() >= MAX_DECLARED {
            self.too_many(MAX_DECLARED, "global variables", v.name.span);
            return;
        }
        self.count_global_values(ty, v.name.span);
        let owner = scope.ret.as_ref().map_or("a body", |(_, n)| n.as_str());
        let slot = self.globals.len() as u16;
        if let Some(c) = chars {
            self.global_chars.insert(slot, c);
        }
        self.globals.push(GlobalVar {
            name: format!("{}::{}", owner, v.name.text),
            ty,
            is_const: d.is_const,
            init,
        });
        scope.bind_static(&v.name.text, ty, slot);
    }

    #[inline(never)]
    fn return_stmt(
        &mut self,
        value: Option<&ast::Expr>,
        span: Span,
        scope: &mut Scope,
        out: &mut Vec<St>,
    ) {
        match (scope.ret.clone(), value) {
            (None, None) | (Some((Ty::Void, _)), None) => out.push(St::Return),
            (None, Some(v)) => self.err(
                v.span,
                "only a function returns a value; a production or a control block ends with a plain `return;`",
            ),
            (Some((Ty::Void, name)), Some(v)) => self.err(
                v.span,
                format!("`{name}` returns void: its `return` takes no value"),
            ),
            (Some((t, name)), None) => {
                let t = self.type_name(t);
                self.err(span, format!("`{name}` returns {t}: `return` needs a value"));
            }
            (Some((t, _)), Some(v)) => {
                if let Some((x, xt)) = self.expr(v, scope) {
                    if let Some(x) = self.coerce(x, xt, t, v.span) {
                        out.push(St::ReturnValue(x));
                    }
                }
            }
        }
    }

    /// A function's parameter types as its callers see them.
    fn param_types(&mut self, def: &ast::FunctionDef) -> Option<Vec<(Ty, bool)>> {
        let mut out = Vec::with_capacity(def.params.len());
        let mut ok = true;
        for p in &def.params {
            let at = p.name.as_ref().map_or(p.ty.span, |n| n.span);
            let Some(mut ty) = self.resolve_type(&p.ty) else {
                ok = false;
                continue;
            };
            let mut by_ref = p.ty.reference;
            if p.ty.pointer {
                match p.ty.name.as_str() {
                    "char" => ty = Ty::Str,
                    "FILE" => ty = Ty::Int,
                    // `float *a`: an array of any length.
                    _ => {
                        ty = match self.array_type(ty, None, at) {
                            Some(t) => t,
                            None => {
                                ok = false;
                                continue;
                            }
                        };
                    }
                }
            }
            if ty == Ty::Void {
                self.err(at, "a parameter cannot have type void");
                ok = false;
                continue;
            }
            match self.with_dims(ty, &p.ty, &p.dims, None, at) {
                Some(t) => ty = t,
                None => {
                    ok = false;
                    continue;
                }
            }
            // C passes arrays as pointers: the callee's writes are the
            // caller's. So are a `char *s` or `char s[]` parameter's
            // (`sprintf(s, ...)` fills the caller's buffer) when the
            // argument is a variable; a `const` one is not written.
            by_ref |= self.is_array(ty) || (ty == Ty::Str && !p.is_const);
            out.push((ty, by_ref));
        }
        ok.then_some(out)
    }

    /// A constructor of struct `s`: a user function returning the struct.
    /// Constructors of one struct are told apart by their number of
    /// parameters.
    #[inline(never)]
    fn ctor_sig(&mut self, s: &ast::Name, c: &ast::Ctor) {
        let Some(&si) = self.struct_names.get(&s.text) else {
            return;
        };
        let def = ast::FunctionDef {
            ret: ast::TypeRef {
                name: s.text.clone(),
                span: s.span,
                pointer: false,
                reference: false,
            },
            name: c.name.clone(),
            params: c.params.clone(),
            body: None,
        };
        let Some(params) = self.param_types(&def) else {
            return;
        };
        let ids = self.ctors.get(&s.text).cloned().unwrap_or_default();
        if ids
            .iter()
            .any(|&id| self.user_fns[id as usize].params.len() == params.len())
        {
            self.err(
                c.name.span,
                format!(
                    "`{}` already has a constructor with {} parameter(s); constructors are told apart only by their number of parameters",
                    s.text,
                    params.len()
                ),
            );
            return;
        }
        if self.user_fns.len() >= MAX_USER_FUNCTIONS {
            self.too_many(MAX_USER_FUNCTIONS, "functions", c.name.span);
            return;
        }
        self.ctors
            .entry(s.text.clone())
            .or_default()
            .push(self.user_fns.len() as u16);
        self.user_fns.push(UserSig {
            name: s.text.clone(),
            params,
            ret: Ty::Struct(si),
            span: c.name.span,
            defined: true,
        });
    }

    /// A constructor's body: the fields are locals, zero (or built by
    /// their own default constructor), that the parameters hide; the
    /// initialiser list sets them in the order they are declared, then the
    /// body runs, and the struct is made of them.
    #[inline(never)]
    fn ctor_body(&mut self, s: &ast::Name, c: &ast::Ctor, id: u16) -> Option<Function> {
        let sig = self.user_fns[id as usize].clone();
        let Ty::Struct(si) = sig.ret else {
            return None;
        };
        let fields = self.structs[si as usize].fields.clone();
        let mut scope = Scope {
            ret: Some((Ty::Void, sig.name.clone())),
            ..Scope::default()
        };
        scope.reserve(sig.params.len());
        let mut stmts = Vec::new();
        let mut slots = Vec::with_capacity(fields.len());
        for (name, ty) in &fields {
            let slot = self.local(&mut scope, name, *ty, c.name.span);
            let zero = self.default_value(*ty, c.name.span);
            stmts.push(St::Init(slot, zero));
            slots.push(slot);
        }
        scope.push();
        self.bind_params(&mut scope, &c.params, &sig.params, 0, fields.len());
        let mut inits: Vec<(usize, &ast::Name, &Vec<ast::Expr>, Span)> = Vec::new();
        for (f, args, span) in &c.inits {
            let Some(k) = fields.iter().position(|(n, _)| *n == f.text) else {
                self.err(
                    f.span,
                    format!(
                        "struct `{}` has no field `{}` to initialise",
                        s.text, f.text
                    ),
                );
                continue;
            };
            if inits.iter().any(|i| i.0 == k) {
                self.err(
                    f.span,
                    format!("the field `{}` is initialised twice", f.text),
                );
                continue;
            }
            inits.push((k, f, args, *span));
        }
        // C++ initialises the fields in the order they are declared.
        inits.sort_by_key(|i| i.0);
        for (k, _, args, span) in inits {
            let ty = fields[k].1;
            let value = if args.is_empty() {
                Some(self.default_value(ty, span))
            } else {
                self.initializer(ty, &Init::Ctor(args.clone(), span), span, &mut scope)
            };
            if let Some(v) = value {
                stmts.push(St::Init(slots[k], v));
            }
        }
        stmts.extend(self.block_stmts(&c.body.stmts, &mut scope));
        let end = c.body.span.end as usize;
        Some(Function {
            name: sig.name.clone(),
            params: sig.params.iter().map(|p| p.0).collect(),
            ret: sig.ret,
            body: stmts,
            frame_size: (scope.max as usize).max(sig.params.len()),
            frame_values: scope.values,
            end: Span::new(c.body.span.file, end.saturating_sub(1), end),
            result: Some(Ex::MakeStruct(slots.into_iter().map(Ex::Local).collect())),
            this_back: None,
        })
    }

    /// A method of struct `s`: a user function `S::name` whose first
    /// parameter is the struct, by reference; no overloads.
    #[inline(never)]
    fn method_sig(&mut self, s: &ast::Name, m: &ast::FunctionDef) {
        let Some(&si) = self.struct_names.get(&s.text) else {
            return;
        };
        let ret = match self.resolve_type(&m.ret) {
            Some(_) if m.ret.pointer && m.ret.name == "char" => Ty::Str,
            Some(_) if m.ret.pointer => {
                self.err(m.ret.span, "a method cannot return a pointer here");
                return;
            }
            Some(t) => t,
            None => return,
        };
        let this = ast::Param {
            ty: ast::TypeRef {
                name: s.text.clone(),
                span: s.span,
                pointer: false,
                reference: true,
            },
            name: None,
            dims: Vec::new(),
            is_const: false,
        };
        let def = ast::FunctionDef {
            params: std::iter::once(this)
                .chain(m.params.iter().cloned())
                .collect(),
            ..m.clone()
        };
        let Some(params) = self.param_types(&def) else {
            return;
        };
        let key = (si, m.name.text.clone());
        if self.methods.contains_key(&key)
            || self.struct_fields[si as usize].contains_key(&m.name.text)
        {
            self.err(
                m.name.span,
                format!(
                    "struct `{}` already has a member `{}`; methods cannot be overloaded",
                    s.text, m.name.text
                ),
            );
            return;
        }
        if self.user_fns.len() >= MAX_USER_FUNCTIONS {
            self.too_many(MAX_USER_FUNCTIONS, "functions", m.name.span);
            return;
        }
        self.methods.insert(key, self.user_fns.len() as u16);
        self.user_fns.push(UserSig {
            name: format!("{}::{}", s.text, m.name.text),
            params,
            ret,
            span: m.name.span,
            defined: true,
        });
    }

    /// A method's body: the struct is slot 0, the parameters follow; the
    /// fields are locals, read from it first and written back to it when
    /// the body ends, which the caller's variable then receives.
    #[inline(never)]
    fn method_body(&mut self, m: &ast::FunctionDef, id: u16) -> Option<Function> {
        let sig = self.user_fns[id as usize].clone();
        let Ty::Struct(si) = sig.params.first()?.0 else {
            return None;
        };
        let body = m.body.as_ref()?;
        let fields = self.structs[si as usize].fields.clone();
        let mut scope = Scope {
            ret: Some((sig.ret, sig.name.clone())),
            ..Scope::default()
        };
        scope.reserve(sig.params.len());
        let mut stmts = Vec::new();
        let mut slots = Vec::with_capacity(fields.len());
        for (k, (name, ty)) in fields.iter().enumerate() {
            let slot = self.local(&mut scope, name, *ty, m.name.span);
            scope.set_chars(self.field_chars.get(&(si, k as u16)).cloned());
            stmts.push(St::Init(slot, Ex::Field(Box::new(Ex::Local(0)), k as u16)));
            slots.push(slot);
        }
        scope.push();
        self.bind_params(&mut scope, &m.params, &sig.params, 1, fields.len());
        stmts.extend(self.block_stmts(&body.stmts, &mut scope));
        let end = body.span.end as usize;
        Some(Function {
            name: sig.name.clone(),
            params: sig.params.iter().map(|p| p.0).collect(),
            ret: sig.ret,
            body: stmts,
            frame_size: (scope.max as usize).max(sig.params.len()),
            frame_values: scope.values,
            end: Span::new(body.span.file, end.saturating_sub(1), end),
            result: None,
            this_back: Some(Ex::MakeStruct(slots.into_iter().map(Ex::Local).collect())),
        })
    }

    /// `v.name(args)` on a struct `v`: its method `name`, `v` passed by
    /// reference.
    #[inline(never)]
    fn struct_method(
        &mut self,
        si: u16,
        recv: &ast::Expr,
        name: &ast::Name,
        args: &[ast::Expr],
        span: Span,
        scope: &mut Scope,
    ) -> Typed {
        let sname = self.structs[si as usize].name.clone();
        let Some(&id) = self.methods.get(&(si, name.text.clone())) else {
            self.err(
                name.span,
                format!("struct `{sname}` has no method `{}`", name.text),
            );
            return None;
        };
        let want = self.user_fns[id as usize].params.len() - 1;
        if args.len() != want {
            self.err(
                span,
                format!(
                    "`{sname}::{}` takes {want} argument(s), but {} were given",
                    name.text,
                    args.len()
                ),
            );
            return None;
        }
        if !matches!(
            recv.kind,
            ExprKind::Ident(_) | ExprKind::Field(..) | ExprKind::Index(..)
        ) {
            self.err(
                recv.span,
                "methods are called on a variable here (`leaf.area()`), not on a value made by an expression",
            );
            return None;
        }
        let all: Vec<ast::Expr> = std::iter::once(recv.clone())
            .chain(args.iter().cloned())
            .collect();
        self.user_call(id, name, &all, span, scope)
    }

    /// Zero of type `ty`, with the topology's own zero for its elements
    /// (vv: the null vertex, an empty set) inside structs and arrays too;
    /// [`Value::zero`] knows no topology and leaves them void, which a
    /// set edit ignored (`add v to sets[1]` did nothing).
    fn zero(&self, ty: Ty) -> Value {
        match ty {
            Ty::Elem(k) => (self.host.zero)(k),
            Ty::Struct(id) if self.holds_elements(ty) => Value::Struct(
                self.structs[id as usize]
                    .fields
                    .iter()
                    .map(|(_, t)| self.zero(*t))
                    .collect(),
            ),
            _ => Value::zero(ty, &self.structs),
        }
    }

    /// Whether a value of type `ty` holds elements of the topology.
    fn holds_elements(&self, ty: Ty) -> bool {
        match ty {
            Ty::Elem(_) => true,
            Ty::Struct(id) => {
                let def = &self.structs[id as usize];
                match def.elem {
                    Some(t) => self.holds_elements(t),
                    None => def.fields.iter().any(|(_, t)| self.holds_elements(*t)),
                }
            }
            _ => false,
        }
    }

    /// The value a variable of type `ty` starts with when nothing
    /// initialises it, as C++ makes it: for a struct with a constructor
    /// without parameters, what that constructor makes; for another struct
    /// or an array, its fields or elements made so; otherwise zero (a
    /// constant).
    fn default_value(&mut self, ty: Ty, span: Span) -> Ex {
        let Ty::Struct(si) = ty else {
            return Ex::Const(self.zero(ty));
        };
        let zero = |c: &Compiler| Ex::Const(c.zero(ty));
        if self.ctors.is_empty() {
            return zero(self);
        }
        let def = &self.structs[si as usize];
        let id = self.ctors.get(&def.name).and_then(|ids| {
            ids.iter()
                .copied()
                .find(|&id| self.user_fns[id as usize].params.is_empty())
        });
        if let Some(id) = id {
            return Ex::CallUser {
                id,
                args: Vec::new(),
                back: Vec::new(),
                span,
            };
        }
        let fields: Vec<Ty> = def.fields.iter().map(|f| f.1).collect();
        if fields.len() > MAX_BUILT_ELEMENTS {
            // Only the first field tells whether the elements of a long
            // array are built: they all have its type.
            if matches!(
                fields.first().map(|&t| self.default_value(t, span)),
                Some(Ex::Const(_)) | None
            ) {
                return zero(self);
            }
            self.err(
                span,
                format!(
                    "an array of more than {MAX_BUILT_ELEMENTS} structs with constructors is not supported"
                ),
            );
            return zero(self);
        }
        let parts: Vec<Ex> = fields
            .iter()
            .map(|&t| self.default_value(t, span))
            .collect();
        if parts.iter().all(|p| matches!(p, Ex::Const(_))) {
            return zero(self);
        }
        Ex::MakeStruct(parts)
    }

    /// `A` that several structs declare: only `S::A` names it. (Out of
    /// `expr_inner`, so that the frame of that recursive function stays
    /// small.)
    #[cold]
    #[inline(never)]
    fn ambiguous_enumerator(&mut self, n: &str, span: Span) -> Typed {
        self.err(
            span,
            format!("more than one struct declares an enumerator `{n}`: write `Struct::{n}`"),
        );
        None
    }

    /// The struct type that `name` names (not an array's typedef).
    fn struct_named(&self, name: &str) -> Option<Ty> {
        match self.struct_names.get(name) {
            Some(&si) => Some(Ty::Struct(si)),
            None => match self.typedefs.get(name) {
                Some(t @ Ty::Struct(si)) if self.structs[*si as usize].elem.is_none() => Some(*t),
                _ => None,
            },
        }
    }

    /// `S(args)` in an expression, `S` naming struct type `ty`: the
    /// constructor of `S` that takes as many arguments; without
    /// constructors, `S()` is zero and `S(a, b)` sets the fields in order.
    #[inline(never)]
    fn ctor_call(
        &mut self,
        ty: Ty,
        name: &ast::Name,
        args: &[ast::Expr],
        span: Span,
        scope: &mut Scope,
    ) -> Typed {
        let sname = self.structs[pt_index(ty)].name.clone();
        let Some(ids) = self.ctors.get(&sname).cloned() else {
            if args.is_empty() {
                return Some((self.default_value(ty, span), ty));
            }
            let mut exs = Vec::new();
            for a in args {
                exs.push(self.expr(a, scope)?);
            }
            return self.construct(ty, exs, args, span).map(|ex| (ex, ty));
        };
        match ids
            .iter()
            .copied()
            .find(|&id| self.user_fns[id as usize].params.len() == args.len())
        {
            Some(id) => self.user_call(id, name, args, span, scope),
            None => {
                let mut counts: Vec<usize> = ids
                    .iter()
                    .map(|&id| self.user_fns[id as usize].params.len())
                    .collect();
                counts.sort_unstable();
                let counts: Vec<String> = counts.iter().map(|c| c.to_string()).collect();
                self.err(
                    span,
                    format!(
                        "`{sname}` has no constructor that takes {} argument(s); its constructors take {}",
                        args.len(),
                        counts.join(" or ")
                    ),
                );
                None
            }
        }
    }

    /// First pass: a function's signature, so that calls may come before
    /// its definition.
    fn function_sig(&mut self, def: &ast::FunctionDef) {
        let ret = match self.resolve_type(&def.ret) {
            Some(_) if def.ret.pointer && def.ret.name == "char" => Ty::Str,
            Some(_) if def.ret.pointer && def.ret.name != "FILE" => {
                self.err(def.ret.span, "a function cannot return a pointer here");
                return;
            }
            Some(t) => t,
            None => return,
        };
        let Some(params) = self.param_types(def) else {
            return;
        };
        let name = &def.name;
        if let Some(&id) = self.user_fn_names.get(&name.text) {
            let sig = &self.user_fns[id as usize];
            if sig.params != params || sig.ret != ret {
                self.err(
                    name.span,
                    format!(
                        "`{}` is declared again with other types; functions cannot be overloaded",
                        name.text
                    ),
                );
                return;
            }
            if sig.defined && def.body.is_some() {
                self.err(
                    name.span,
                    format!("function `{}` is defined twice", name.text),
                );
                return;
            }
            if def.body.is_some() {
                let sig = &mut self.user_fns[id as usize];
                sig.defined = true;
                sig.span = name.span;
            }
            return;
        }
        if self.user_fns.len() >= MAX_USER_FUNCTIONS {
            self.too_many(MAX_USER_FUNCTIONS, "functions", name.span);
            return;
        }
        self.user_fn_names
            .insert(name.text.clone(), self.user_fns.len() as u16);
        self.user_fns.push(UserSig {
            name: name.text.clone(),
            params,
            ret,
            span: name.span,
            defined: def.body.is_some(),
        });
    }

    /// Last pass: the functions' bodies, checked with every signature,
    /// global and struct known.
    fn function_bodies(&mut self, file: &ast::File) -> Vec<Function> {
        let mut out: Vec<Function> = self
            .user_fns
            .iter()
            .map(|s| Function {
                name: s.name.clone(),
                params: s.params.iter().map(|p| p.0).collect(),
                ret: s.ret,
                body: Vec::new(),
                frame_size: s.params.len(),
                frame_values: 0,
                end: s.span,
                result: None,
                this_back: None,
            })
            .collect();
        for item in &file.items {
            if let Item::Struct { name, body } = item {
                for c in &body.ctors {
                    let id = self.ctors.get(&name.text).and_then(|ids| {
                        ids.iter()
                            .copied()
                            .find(|&id| self.user_fns[id as usize].span == c.name.span)
                    });
                    if let Some(f) = id.and_then(|id| self.ctor_body(name, c, id).map(|f| (id, f)))
                    {
                        out[f.0 as usize] = f.1;
                    }
                }
                for m in &body.methods {
                    let id = self.struct_names.get(&name.text).and_then(|&si| {
                        self.methods
                            .get(&(si, m.name.text.clone()))
                            .copied()
                            .filter(|&id| self.user_fns[id as usize].span == m.name.span)
                    });
                    if let Some(f) = id.and_then(|id| self.method_body(m, id).map(|f| (id, f))) {
                        out[f.0 as usize] = f.1;
                    }
                }
            }
            let Item::Function(def) = item else { continue };
            let Some(body) = &def.body else { continue };
            let Some(&id) = self.user_fn_names.get(&def.name.text) else {
                continue;
            };
            let sig = self.user_fns[id as usize].clone();
            if sig.span != def.name.span {
                continue; // refused as a second definition
            }
            let mut scope = Scope {
                ret: Some((sig.ret, sig.name.clone())),
                ..Scope::default()
            };
            for (p, (t, _)) in def.params.iter().zip(&sig.params) {
                match &p.name {
                    Some(n) => {
                        if scope.lookup(&n.text).is_some() {
                            self.err(
                                n.span,
                                format!("the parameter name `{}` is used twice", n.text),
                            );
                        }
                        self.local(&mut scope, &n.text, *t, n.span);
                    }
                    None => {
                        scope.reserve(1);
                    }
                }
            }
            let stmts = self.block_stmts(&body.stmts, &mut scope);
            let end = body.span.end as usize;
            out[id as usize] = Function {
                name: sig.name.clone(),
                params: sig.params.iter().map(|p| p.0).collect(),
                ret: sig.ret,
                body: stmts,
                frame_size: (scope.max as usize).max(sig.params.len()),
                frame_values: scope.values,
                end: Span::new(body.span.file, end.saturating_sub(1), end),
                result: None,
                this_back: None,
            };
        }
        out
    }

    /// Binds the named parameters of a constructor or a method, which
    /// follow its struct's `fields` field locals in `scope`: parameter `k`
    /// lives in slot `first + k` with the type `types[first + k]`; a name
    /// given twice is an error.
    fn bind_params(
        &mut self,
        scope: &mut Scope,
        params: &[ast::Param],
        types: &[(Ty, bool)],
        first: usize,
        fields: usize,
    ) {
        for (k, p) in params.iter().enumerate() {
            if let Some(n) = &p.name {
                if scope.vars[fields..].iter().any(|v| v.0 == n.text) {
                    self.err(
                        n.span,
                        format!("the parameter name `{}` is used twice", n.text),
                    );
                }
                scope.bind(&n.text, types[first + k].0, (first + k) as u16);
            }
        }
    }

    /// Whether assigning to `p` is refused (a `const` variable).
    fn is_const_place(&self, p: &Place, scope: &Scope) -> bool {
        if p.global {
            self.globals[p.slot as usize].is_const
        } else {
            scope.consts.contains(&p.slot)
        }
    }

    /// A call of a user-defined function: arguments checked against the
    /// parameters, arrays and references passed as places.
    #[inline(never)]
    fn user_call(
        &mut self,
        id: u16,
        name: &ast::Name,
        args: &[ast::Expr],
        span: Span,
        scope: &mut Scope,
    ) -> Typed {
        let sig = self.user_fns[id as usize].clone();
        if args.len() != sig.params.len() {
            let types: Vec<String> = sig.params.iter().map(|p| self.type_name(p.0)).collect();
            self.err(
                span,
                format!(
                    "`{}` takes {} argument(s) ({}), but {} were given",
                    sig.name,
                    sig.params.len(),
                    types.join(", "),
                    args.len()
                ),
            );
            return None;
        }
        if !sig.defined {
            self.err(
                name.span,
                format!(
                    "`{}` is declared but never defined: its body is missing",
                    sig.name
                ),
            );
            return None;
        }
        let mut exs = Vec::with_capacity(args.len());
        let mut back = Vec::new();
        let mut ok = true;
        for (k, (a, &(pt, by_ref))) in args.iter().zip(&sig.params).enumerate() {
            let mismatch = |c: &mut Compiler, found: Ty| {
                let (w, f) = (c.type_name(pt), c.type_name(found));
                c.err(
                    a.span,
                    format!(
                        "type mismatch in argument {} of `{}`: expected {w}, found {f}",
                        k + 1,
                        sig.name
                    ),
                );
            };
            let is_place = matches!(
                a.kind,
                ExprKind::Ident(_) | ExprKind::Field(..) | ExprKind::Index(..)
            );
            // A string argument that is not a variable (a literal, a
            // call) is passed as a value.
            if by_ref && (pt != Ty::Str || is_place) {
                if !is_place {
                    self.err(
                        a.span,
                        format!(
                            "argument {} of `{}` is passed by reference: it must be a variable",
                            k + 1,
                            sig.name
                        ),
                    );
                    ok = false;
                    continue;
                }
                let Some(p) = self.place_of(a, scope, false) else {
                    ok = false;
                    continue;
                };
                let open_array = matches!(pt, Ty::Struct(i) if self.structs[i as usize].elem.is_some()
                    && self.structs[i as usize].fields.is_empty());
                let fits = p.ty == pt
                    || (open_array
                        && matches!(p.ty, Ty::Struct(j)
                            if self.structs[j as usize].elem == self.structs[pt_index(pt)].elem));
                if !fits {
                    mismatch(self, p.ty);
                    ok = false;
                    continue;
                }
                if !self.is_const_place(&p, scope) {
                    back.push((k as u16, p.clone()));
                }
                exs.push(Ex::Load(p));
            } else {
                let Some((x, t)) = self.expr(a, scope) else {
                    ok = false;
                    continue;
                };
                let (x, t) = self.arith(x, t, a.span);
                if !(t == pt || (t.is_numeric() && pt.is_numeric())) {
                    mismatch(self, t);
                    ok = false;
                    continue;
                }
                match self.coerce(x, t, pt, a.span) {
                    Some(x) => exs.push(x),
                    None => ok = false,
                }
            }
        }
        if !ok {
            return None;
        }
        Some((
            Ex::CallUser {
                id,
                args: exs,
                back,
                span,
            },
            sig.ret,
        ))
    }

    /// `float(x)`: the cast `(float) x`.
    #[inline(never)]
    fn functional_cast(
        &mut self,
        name: &ast::Name,
        a: &ast::Expr,
        span: Span,
        scope: &mut Scope,
    ) -> Typed {
        let t = ast::TypeRef {
            name: name.text.clone(),
            span: name.span,
            pointer: false,
            reference: false,
        };
        let cast = ast::Expr {
            kind: ExprKind::Cast(t, Box::new(a.clone())),
            span,
        };
        self.expr_inner(&cast, scope)
    }

    /// A struct's construction (`S(args)`) or one of C's standard I/O and
    /// string functions; `None` for another name. (One call in `call`, so
    /// that the frame of that recursive function stays small.)
    #[inline(never)]
    fn ctor_or_stdio_call(
        &mut self,
        name: &ast::Name,
        args: &[ast::Expr],
        span: Span,
        scope: &mut Scope,
    ) -> Option<Typed> {
        if let Some(ty) = self.struct_named(&name.text) {
            return Some(self.ctor_call(ty, name, args, span, scope));
        }
        self.stdio_call(name, args, span, scope)
    }

    /// C's standard I/O and string functions; `None` for another name.
    #[inline(never)]
    fn stdio_call(
        &mut self,
        name: &ast::Name,
        args: &[ast::Expr],
        span: Span,
        scope: &mut Scope,
    ) -> Option<Typed> {
        use super::stdio::IoFunc;
        let n = name.text.as_str();
        // (function, fixed leading argument types, whether more follow, result)
        let (f, fixed, varargs, ret): (IoFunc, &[Ty], bool, Ty) = match n {
            "printf" | "Printf" => (IoFunc::Printf, &[Ty::Str], true, Ty::Int),
            "fprintf" => (IoFunc::Fprintf, &[Ty::Int, Ty::Str], true, Ty::Int),
            "sprintf" => (IoFunc::Format, &[Ty::Str, Ty::Str], true, Ty::Str),
            "puts" => (IoFunc::Puts, &[Ty::Str], false, Ty::Int),
            "fputs" => (IoFunc::Fputs, &[Ty::Str, Ty::Int], false, Ty::Int),
            "fopen" => (IoFunc::Fopen, &[Ty::Str, Ty::Str], false, Ty::Int),
            "fclose" => (IoFunc::Fclose, &[Ty::Int], false, Ty::Int),
            "fflush" => (IoFunc::Fflush, &[Ty::Int], false, Ty::Int),
            "strlen" => (IoFunc::Strlen, &[Ty::Str], false, Ty::Int),
            "strcmp" => (IoFunc::Strcmp, &[Ty::Str, Ty::Str], false, Ty::Int),
            "strcpy" => (IoFunc::Concat, &[Ty::Str, Ty::Str], false, Ty::Str),
            "strcat" => (IoFunc::Concat, &[Ty::Str, Ty::Str], false, Ty::Str),
            "strncpy" => (
                IoFunc::Strncpy,
                &[Ty::Str, Ty::Str, Ty::Int],
                false,
                Ty::Str,
            ),
            "strncat" => (
                IoFunc::Strncat,
                &[Ty::Str, Ty::Str, Ty::Int],
                false,
                Ty::Str,
            ),
            "snprintf" => (
                IoFunc::Snprintf,
                &[Ty::Str, Ty::Int, Ty::Str],
                true,
                Ty::Str,
            ),
            "scanf" | "fscanf" | "sscanf" | "fgets" | "fgetc" | "getc" | "fread" | "gets"
            | "getchar" => {
                self.err(
                    name.span,
                    format!("`{n}` reads input, which a program may not do here"),
                );
                return Some(None);
            }
            _ => return None,
        };
        let count_ok = if varargs {
            args.len() >= fixed.len()
        } else {
            args.len() == fixed.len()
        };
        if !count_ok {
            let more = if varargs { " or more" } else { "" };
            self.err(
                span,
                format!(
                    "`{n}` takes {}{more} argument(s), but {} were given",
                    fixed.len(),
                    args.len()
                ),
            );
            return Some(None);
        }
        // `sprintf`, `strcpy`, `strcat` and their `n` forms write their
        // first argument.
        let target = if matches!(
            n,
            "sprintf" | "strcpy" | "strcat" | "snprintf" | "strncpy" | "strncat"
        ) {
            let p = self.place(&args[0], scope);
            match p {
                Some(p) if p.ty == Ty::Str => Some(p),
                Some(p) => {
                    let t = self.type_name(p.ty);
                    self.err(
                        args[0].span,
                        format!("`{n}` writes a string (a `char` array), found {t}"),
                    );
                    return Some(None);
                }
                None => return Some(None),
            }
        } else {
            None
        };
        let mut exs = Vec::with_capacity(args.len());
        let mut ok = true;
        // The functions that append, and `snprintf` (which may write
        // nothing), read it too.
        let skip = usize::from(matches!(n, "sprintf" | "strcpy" | "strncpy"));
        for (k, a) in args.iter().enumerate().skip(skip) {
            let Some((x, t)) = self.expr(a, scope) else {
                ok = false;
                continue;
            };
            let want = fixed.get(k).copied();
            let fits = match want {
                Some(Ty::Str) => t == Ty::Str,
                Some(w) => t.is_numeric() && w.is_numeric(),
                None => t.is_numeric() || t == Ty::Str,
            };
            if !fits {
                let found = self.type_name(t);
                let m = match want {
                    Some(w) => format!(
                        "type mismatch in argument {} of `{n}`: expected {}, found {found}",
                        k + 1,
                        if w == Ty::Str {
                            "a string".to_string()
                        } else {
                            self.type_name(w)
                        }
                    ),
                    // Vectors and structs have fields to print; a
                    // topology's element (a vv vertex, a set) has none.
                    None if matches!(t, Ty::Elem(_)) => {
                        format!("`{n}` prints numbers and strings, not {found}")
                    }
                    None => format!(
                        "`{n}` prints numbers and strings, not {found}; print its fields (`v.x`)"
                    ),
                };
                self.err(a.span, m);
                ok = false;
                continue;
            }
            exs.push(x);
        }
        if !ok {
            return Some(None);
        }
        // A declared `char` array takes only what fits in it.
        let chars = target.as_ref().and_then(|p| p.chars.as_deref()).cloned();
        let call = match (n, &chars) {
            ("strcpy", _) => exs.pop()?,
            // `strncpy` writes its count of bytes, however short the
            // string: the count must fit.
            ("strncpy", Some(c)) => {
                if let Some(Value::Int(k)) = self.const_value(&exs[1], 0) {
                    if k > c.size as i64 {
                        self.err(
                            span,
                            format!(
                                "strncpy writes {k} bytes into `{}` (it always writes its count, \
                                 padding with NULs), declared `{}` (room for {} bytes)",
                                c.name, c.decl, c.size
                            ),
                        );
                        return Some(None);
                    }
                }
                exs.push(Ex::Const(Value::Int(c.size as i64)));
                exs.push(Ex::Const(Value::Str(c.name.as_str().into())));
                exs.push(Ex::Const(Value::Str(c.decl.as_str().into())));
                Ex::Call(Func::Io(f), exs, span)
            }
            _ => Ex::Call(Func::Io(f), exs, span),
        };
        let call = match &chars {
            Some(c) if n != "strncpy" => match self.fit(call, c, n, span) {
                Some(x) => x,
                None => return Some(None),
            },
            _ => call,
        };
        Some(Some(match target {
            Some(p) => (Ex::Assign(p, None, Box::new(call), Ty::Str), Ty::Str),
            None => (call, ret),
        }))
    }

    /// A call of a `define` function: the arguments bind fresh locals,
    /// reserved before the arguments are compiled so that no argument's
    /// own locals overwrite a parameter already set; then the body sees
    /// only its parameters. The locals are free again after the call.
    fn inline(&mut self, f: usize, args: &[ast::Expr], span: Span, scope: &mut Scope) -> Typed {
        let functions = Rc::clone(&self.functions);
        let def = &functions[f];
        if def.params.len() != args.len() {
            self.err(
                span,
                format!(
                    "`{}` takes {} argument(s), but {} were given",
                    def.name,
                    def.params.len(),
                    args.len()
                ),
            );
            return None;
        }
        if self.inlining.contains(&f) {
            self.err(
                span,
                format!("`{}` calls itself; functions may not recurse", def.name),
            );
            return None;
        }
        if self.inlining.len() >= MAX_INLINE_DEPTH {
            self.err(
                span,
                format!(
                    "`{}` is called more than {MAX_INLINE_DEPTH} function calls deep; \
                     functions may not nest deeper",
                    def.name
                ),
            );
            return None;
        }
        self.inlined += 1;
        if self.inlined > MAX_INLINED_CALLS {
            self.err(
                span,
                format!(
                    "the functions called here expand to more than {MAX_INLINED_CALLS} calls; \
                     name a shared value with a parameter instead of calling a function twice"
                ),
            );
            return None;
        }
        // Each argument binds a local around the body: `Let`s nest.
        self.nested(args.len(), span, |c| {
            c.inline_body(f, def, args, span, scope)
        })
    }

    fn inline_body(
        &mut self,
        f: usize,
        def: &ast::Define,
        args: &[ast::Expr],
        span: Span,
        scope: &mut Scope,
    ) -> Typed {
        let mark = (scope.vars.len(), scope.next);
        let Some(first) = scope.reserve(args.len()) else {
            self.too_many_locals(scope, span);
            return None;
        };
        let mut lets = Vec::with_capacity(args.len());
        let mut ok = true;
        for a in args {
            match self.expr(a, scope) {
                Some(t) => lets.push(t),
                None => ok = false,
            }
        }
        if !ok {
            scope.truncate(mark.0);
            scope.next = mark.1;
            return None;
        }
        let barrier = scope.barrier;
        scope.barrier = scope.vars.len();
        for (i, (p, (_, t))) in def.params.iter().zip(&lets).enumerate() {
            scope.bind(p, *t, first + i as u16);
        }
        let marked = self.truncating.len();
        for (i, (a, _)) in lets.iter().enumerate() {
            if let Some(d) = self.truncated_division(a) {
                self.truncating.push((first + i as u16, d));
            }
        }
        self.inlining.push(f);
        let errors = self.diags.len();
        let body = self.expr(&def.body, scope);
        self.inlining.pop();
        self.truncating.truncate(marked);
        // The caret points into the body; name the function once, at the
        // innermost call.
        for d in &mut self.diags[errors..] {
            if !d.message.contains(" (in `") {
                d.message = format!("{} (in `{}`)", d.message, def.name);
            }
        }
        scope.barrier = barrier;
        scope.truncate(mark.0);
        scope.next = mark.1;
        let (mut x, t) = body?;
        for (i, (a, _)) in lets.into_iter().enumerate().rev() {
            x = Ex::Let(first + i as u16, Box::new(a), Box::new(x));
        }
        Some((x, t))
    }
}

/// The index in `Program::structs` of a struct or array type.
/// A destination as the program writes it (`b`, `s.name`, `names[i]`),
/// for the error that a string does not fit there; an index other than a
/// name or a number is `…`.
fn written_place(e: &ast::Expr) -> String {
    match &e.kind {
        ExprKind::Ident(n) => n.clone(),
        ExprKind::Field(b, f) => format!("{}.{}", written_place(b), f.text),
        ExprKind::Index(b, i) => {
            let i = match &i.kind {
                ExprKind::Ident(n) => n.clone(),
                ExprKind::Int(k) => k.to_string(),
                _ => "…".to_string(),
            };
            format!("{}[{i}]", written_place(b))
        }
        _ => "…".to_string(),
    }
}

fn pt_index(t: Ty) -> usize {
    match t {
        Ty::Struct(i) => i as usize,
        _ => 0,
    }
}

/// The most values an array may hold (counting those of its elements).
const MAX_ARRAY_VALUES: usize = 1 << 22;

/// The local variables of one body (a rule or a function) may hold this
/// many values in all.
const MAX_BODY_VALUES: usize = 1 << 22;

/// `a op b` of two constants, computed once at compile time. Divisions of
/// integers are left alone: `check` warns about those that truncate, and
/// division by zero is an error where the program runs.
fn fold_constants(op: BinOp, a: &Ex, b: &Ex) -> Option<Ex> {
    let (Ex::Const(x), Ex::Const(y)) = (a, b) else {
        return None;
    };
    let int = |v: &Value| matches!(v, Value::Int(_) | Value::Bool(_));
    if matches!(op, BinOp::Div | BinOp::Rem) && int(x) && int(y) {
        return None;
    }
    if matches!(op, BinOp::And | BinOp::Or) {
        return None;
    }
    super::eval::binary(op, x.clone(), y.clone())
        .ok()
        .map(Ex::Const)
}

/// A negation, conversion or maths function of constants, computed once.
fn fold_unary(e: Ex) -> Ex {
    match e {
        Ex::Neg(a) => match *a {
            Ex::Const(Value::Int(i)) => Ex::Const(Value::Int(i.wrapping_neg())),
            Ex::Const(Value::Float(f)) => Ex::Const(Value::Float(-f)),
            a => Ex::Neg(Box::new(a)),
        },
        Ex::Convert(t, a) => match *a {
            Ex::Const(v) => Ex::Const(v.convert(t)),
            a => Ex::Convert(t, Box::new(a)),
        },
        Ex::Call(Func::Math1(f), args, span) => match args.as_slice() {
            [Ex::Const(a)] => Ex::Const(Value::Float(f(a.as_f64()))),
            _ => Ex::Call(Func::Math1(f), args, span),
        },
        Ex::Call(Func::Math2(f), args, span) => match args.as_slice() {
            [Ex::Const(a), Ex::Const(b)] => Ex::Const(Value::Float(f(a.as_f64(), b.as_f64()))),
            _ => Ex::Call(Func::Math2(f), args, span),
        },
        e => e,
    }
}

/// A value of type `ty` built from its parts (see `Compiler::parts_of`),
/// already converted to their types.
fn assemble(ty: Ty, parts: Vec<Ex>) -> Option<Ex> {
    let mut it = parts.into_iter();
    Some(match ty {
        Ty::V2 | Ty::V2d => Ex::MakeV2(Box::new(it.next()?), Box::new(it.next()?)),
        Ty::V3 | Ty::V3d => Ex::MakeV3(
            Box::new(it.next()?),
            Box::new(it.next()?),
            Box::new(it.next()?),
        ),
        Ty::Struct(_) => Ex::MakeStruct(it.collect()),
        _ => it.last()?,
    })
}

/// The result type of `a op b`, or `None` for a type error. Numbers
/// follow C's usual arithmetic conversions (`double` over `float` over
/// `int`); vectors of one size but two precisions give the double one.
pub fn binary_type(op: BinOp, a: Ty, b: Ty) -> Option<Ty> {
    if let (Ty::Elem(x), Ty::Elem(y)) = (a, b) {
        // Elements compare by identity, and in the order of their ids
        // (vv's universe order, `p < q`).
        use BinOp::*;
        return (x == y && matches!(op, Eq | Ne | Lt | Le | Gt | Ge)).then_some(Ty::Bool);
    }
    let num = a.is_numeric() && b.is_numeric();
    let promote = || a.wider(b).wider(Ty::Int);
    let vectors = a.is_vector() && a.dim() == b.dim();
    use BinOp::*;
    match op {
        Add | Sub => {
            if num {
                Some(promote())
            } else if vectors {
                Some(a.wider(b))
            } else {
                None
            }
        }
        Mul => {
            if num {
                Some(promote())
            } else if a.is_numeric() && b.is_vector() {
                Some(b)
            } else if a.is_vector() && b.is_numeric() {
                Some(a)
            } else if vectors {
                // The dot product.
                Some(a.wider(b).scalar())
            } else {
                None
            }
        }
        Div => {
            if num {
                Some(promote())
            } else if a.is_vector() && b.is_numeric() {
                Some(a)
            } else {
                None
            }
        }
        Rem => {
            if num {
                Some(promote())
            } else if vectors && a.dim() == 3 {
                // The cross product.
                Some(a.wider(b))
            } else {
                None
            }
        }
        Lt | Le | Gt | Ge => num.then_some(Ty::Bool),
        Eq | Ne => (num || vectors).then_some(Ty::Bool),
        And | Or => num.then_some(Ty::Bool),
        BitAnd | BitOr | BitXor | Shl | Shr => {
            (num && !a.is_floating() && !b.is_floating()).then_some(Ty::Int)
        }
    }
}

fn pattern_label(p: &ast::Production) -> String {
    let list = |ms: &[ast::PatModule]| -> String {
        ms.iter()
            .map(|m| {
                if m.name.text == "#" {
                    "#".to_string()
                } else {
                    let ps: Vec<&str> = m.params.iter().map(|n| n.text.as_str()).collect();
                    format!("{}({})", m.name.text, ps.join(","))
                }
            })
            .collect::<Vec<_>>()
            .join(" ")
    };
    let mut s = String::new();
    if !p.new_left.is_empty() {
        s += &format!("{} << ", list(&p.new_left));
    }
    if !p.left.is_empty() {
        s += &format!("{} < ", list(&p.left));
    }
    s += &list(&p.strict);
    if !p.right.is_empty() {
        s += &format!(" > {}", list(&p.right));
    }
    if !p.new_right.is_empty() {
        s += &format!(" >> {}", list(&p.new_right));
    }
    s
}
