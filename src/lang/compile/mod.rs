//! Name resolution and type checking: [`ast::File`] to [`Program`].
//!
//! Every problem found is reported; compilation goes on after an error so
//! that `subgram check` can list all of them at once.
//!
//! This file holds the entry points ([`compile_with`], [`compile_on`],
//! [`RuleCompiler`]), the checker's state (`Compiler`), a body's local
//! variables (`Scope`) and the limits that several parts share. The rest
//! is `Compiler`'s methods, one part of the language a file:
//!
//! - [`program`]: the passes over the items: declarations, globals,
//!   directives, the axiom, groups and productions, which make the program
//! - [`rules`]: productions: predecessor patterns, successors, brackets
//! - [`statements`]: blocks, locals, loops, `switch`, `return`, conditions
//! - [`expressions`]: operators, names, assignments, casts, context tests
//! - [`places`]: the variables, fields and elements assigned or read in place
//! - [`calls`]: calls by name, and the inlining of `define` functions
//! - [`functions`]: user-defined C functions: signatures, bodies, calls
//! - [`structs`]: structs' constructors and methods
//! - [`arrays`]: array types, declarators' dimensions, indexing
//! - [`initializers`]: initializers, `{...}` lists, default values
//! - [`strings`]: `char` arrays checked to fit, C's stdio and string functions
//! - [`topology`]: properties, `forall`, set edits and aggregates over a
//!   topology's elements
//! - [`types`]: type names, `float`'s precision, conversions, operators' types
//! - [`constants`]: constant folding, integer constants, values known early
//! - [`diagnostics`]: errors, truncation warnings, "did you mean" hints
//!
//! It uses `syntax` and the rest of `lang`; nothing above.

mod arrays;
mod calls;
mod constants;
mod diagnostics;
mod expressions;
mod functions;
mod initializers;
mod places;
mod program;
mod rules;
mod statements;
mod strings;
mod structs;
mod topology;
mod types;

use std::collections::{HashMap, HashSet};
use std::rc::Rc;

use crate::syntax::ast;
use crate::syntax::span::{Diagnostic, Span};

use super::builtins::{HostTable, WORD_HOST};
use super::ir::*;
use super::modules::Alphabet;
use super::value::{StructDef, Ty};

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

/// The most user-defined functions a program may declare (each is
/// numbered with a `u16`).
const MAX_USER_FUNCTIONS: usize = u16::MAX as usize;

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

/// The local variables of one body (a rule or a function) may hold this
/// many values in all.
const MAX_BODY_VALUES: usize = 1 << 22;

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
}

/// The index in `Program::structs` of a struct or array type.
fn pt_index(t: Ty) -> usize {
    match t {
        Ty::Struct(i) => i as usize,
        _ => 0,
    }
}
