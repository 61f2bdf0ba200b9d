//! A whole derivation: globals, `Start`, the axiom, the steps with their
//! `StartEach`/`EndEach` blocks and groups, decomposition after the axiom
//! and after every step, `End`, and interpretation on request.

use crate::deadline::Deadline;
use crate::lang::eval::{Env, Interp, NoHost, RuntimeError};
use crate::lang::ir::{Program, St};
use crate::lang::{ProgramOutput, Sym, Value};
use crate::syntax::ast::{ControlKind, Section};
use crate::syntax::span::Span;

use super::step::{Rewriter, StepError, StepOptions, COPIED};
use super::word::Word;

/// Settings of a derivation. `Default` gives lpfg's behaviour.
#[derive(Clone, Debug)]
pub struct DeriveOptions {
    /// Overrides `derivation length:`.
    pub steps: Option<u64>,
    /// A step that makes a longer word fails. Default: 20 million.
    pub max_modules: usize,
    /// Where the partition into multi-module strict predecessors starts.
    pub phase: usize,
    /// The derivation, its decomposition and interpretation stop with an
    /// error once this passes. Default: none.
    pub deadline: Option<Deadline>,
    /// Seeds every random number generator before the globals and `Start`
    /// (see `lang::random`); without it they start as lpfg's do.
    pub seed: Option<u32>,
    /// Where what the program prints (`printf`) and the files it writes
    /// go; the caller reads them from its clone. Default: a new one,
    /// which refuses `fopen` for writing.
    pub output: ProgramOutput,
    /// What answers query modules before each step: the turtle's
    /// interpretation of the word. `Default` gives `draw`'s turtle with no
    /// view file's settings (see [`Queries`]).
    pub queries: std::sync::Arc<dyn Queries>,
    /// The environment of an open L-system (a model's `.e` file): started
    /// when the derivation starts, it answers the communication modules
    /// before every step (see `enviro`). Default: none, and
    /// those modules keep their parameters.
    pub environment: Option<std::sync::Arc<dyn super::environment::EnvironmentStarter>>,
    /// lpfg's `-cleanEA20`: an `EA20` answered with fewer than twenty
    /// values has the rest set to zero (else they keep their values).
    pub clean_ea20: bool,
}

/// What answers the query modules of a word (`GetPos`, `GetHead`, …;
/// [`is_query`]) before a step: the turtle, walking the word after
/// interpretation. The derivation knows only this trait; the drawing
/// layer implements it (`draw::QueryTurtle`), and the `Default` of
/// [`DeriveOptions`], which lives beside that turtle, uses it.
pub trait Queries: Send + Sync + std::fmt::Debug {
    /// Walks `shown` (a word of `program`'s, after interpretation) with
    /// the turtle turning by `angle` where the program set one, and gives
    /// each query module met: its index in `shown` and the vector it asks
    /// for. An error is the turtle's message.
    fn answer(
        &self,
        shown: &Word,
        program: &Program,
        angle: Option<f64>,
    ) -> Result<TurtleAnswers, String>;
}

/// What the turtle met walking an interpreted word for [`Queries`]: each
/// query module (its index and the vector it asks for), and each
/// communication module (`E1`, `E2`, `EA20`: its index and the turtle's
/// frame there).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TurtleAnswers {
    pub queries: Vec<(usize, [f64; 3])>,
    pub communication: Vec<(usize, super::environment::Frame)>,
}

/// True for lpfg's query modules, which the turtle fills in.
pub fn is_query(name: &str) -> bool {
    matches!(name, "GetPos" | "GetHead" | "GetLeft" | "GetUp")
}

impl DeriveOptions {
    /// lpfg's behaviour, with query modules answered by `queries`.
    pub fn answered_by(queries: std::sync::Arc<dyn Queries>) -> DeriveOptions {
        DeriveOptions {
            steps: None,
            max_modules: DEFAULT_MAX_MODULES,
            phase: 0,
            deadline: None,
            seed: None,
            output: ProgramOutput::default(),
            queries,
            environment: None,
            clean_ea20: false,
        }
    }
}

pub const DEFAULT_MAX_MODULES: usize = 20_000_000;
/// Derivation lengths beyond this are refused as runaway.
pub const MAX_STEPS: u64 = 1_000_000;
/// Decomposition and interpretation depths beyond this are refused.
pub const MAX_DEPTH: u64 = 10_000;

impl DeriveOptions {
    pub fn with_steps(mut self, n: u64) -> Self {
        self.steps = Some(n);
        self
    }

    pub fn with_phase(mut self, p: usize) -> Self {
        self.phase = p;
        self
    }

    pub fn with_max_modules(mut self, m: usize) -> Self {
        self.max_modules = m;
        self
    }

    pub fn with_deadline(mut self, d: Option<Deadline>) -> Self {
        self.deadline = d;
        self
    }

    pub fn with_seed(mut self, seed: u32) -> Self {
        self.seed = Some(seed);
        self
    }

    pub fn with_output(mut self, output: ProgramOutput) -> Self {
        self.output = output;
        self
    }
}

/// What a word that outgrew `limit` modules says after where it happened.
fn too_long(limit: usize) -> String {
    format!(
        "the word grew past {limit} modules; raise the limit with --max-modules or derive fewer steps"
    )
}

/// A failed derivation: the message, where in the program, and at which step.
#[derive(Clone, Debug, PartialEq)]
pub struct DeriveError {
    pub span: Option<Span>,
    pub message: String,
    pub step: u64,
}

/// The message alone; `Curve::error` adds the rule's line and
/// caret.
impl std::fmt::Display for DeriveError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for DeriveError {}

/// The result of a derivation.
#[derive(Clone, Debug)]
pub struct Derived {
    pub word: Word,
    pub ring: bool,
    /// The number of steps performed.
    pub step: u64,
    /// Global variables after `End`.
    pub env: Env,
}

/// What made a module of a traced derivation's word: a module of the
/// axiom, or a rule (indices into `Program::axiom` and `Program::rules`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Maker {
    Axiom(usize),
    Rule(usize),
}

/// "production", "decomposition rule" or "interpretation rule".
pub fn rule_kind(section: Section) -> &'static str {
    match section {
        Section::Productions => "production",
        Section::Decomposition => "decomposition rule",
        Section::Interpretation => "interpretation rule",
    }
}

/// The makers of a step's new word, from the old word's and the step's
/// origins; `None` when they do not fit the old word.
fn made_by(makers: &[Maker], origin: &[u32]) -> Option<Vec<Maker>> {
    origin
        .iter()
        .map(|&o| match o & COPIED {
            0 => Some(Maker::Rule(o as usize)),
            _ => makers.get((o & !COPIED) as usize).copied(),
        })
        .collect()
}

/// Runs a program and keeps the state between steps, so that callers can
/// look at every intermediate word (`--each`) or stop early.
pub struct Derivation<'p> {
    program: &'p Program,
    rewriter: Rewriter<'p>,
    pub env: Env,
    pub word: Word,
    spare: Word,
    pub ring: bool,
    pub length: u64,
    pub step: u64,
    opts: DeriveOptions,
    /// For a traced derivation, what made each module of the word.
    makers: Option<Vec<Maker>>,
    /// The view whose interpretation rules (`vgroup`) interpretation uses:
    /// 0, the main view, but while [`Derivation::interpret_view`] runs.
    view: i64,
    /// The running environment of an open L-system (dropping it ends it).
    running: Option<Box<dyn super::environment::Environment>>,
    /// The program's communication modules (`E1`, `E2`, `EA20`) among its
    /// symbols.
    communication: Vec<Sym>,
}

impl<'p> Derivation<'p> {
    /// Initialises globals, evaluates the directives, runs `Start`, sets the
    /// word to the axiom and decomposes it.
    pub fn new(program: &'p Program, opts: DeriveOptions) -> Result<Derivation<'p>, DeriveError> {
        Self::start(program, opts, false)
    }

    /// [`Derivation::new`] that also keeps what made each module (see
    /// [`Derivation::interpret_traced`]). Steps take the general path,
    /// whose results are those of the fast paths.
    pub(crate) fn traced(
        program: &'p Program,
        opts: DeriveOptions,
    ) -> Result<Derivation<'p>, DeriveError> {
        Self::start(program, opts, true)
    }

    fn start(
        program: &'p Program,
        opts: DeriveOptions,
        traced: bool,
    ) -> Result<Derivation<'p>, DeriveError> {
        let mut interp = Interp::for_program(program, opts.deadline);
        let env = Env::for_program(program, &mut interp, opts.output.clone(), opts.seed)
            .map_err(|e| runtime(e, None, 0))?;
        let mut d = Derivation {
            program,
            rewriter: Rewriter::new(program),
            env,
            word: Word::new(),
            spare: Word::new(),
            ring: false,
            length: 0,
            step: 0,
            opts,
            makers: None,
            view: 0,
            running: None,
            communication: ["E1", "E2", "EA20"]
                .iter()
                .filter_map(|n| program.alphabet.lookup(n))
                .collect(),
        };
        if let Some(starter) = d.opts.environment.clone() {
            if !d.communication.is_empty() {
                d.running =
                    Some(
                        starter
                            .start(d.opts.deadline)
                            .map_err(|message| DeriveError {
                                span: None,
                                message,
                                step: 0,
                            })?,
                    );
            }
        }
        // `Start` runs before the directives are read, as in lpfg, whose
        // `derivation length:` may read what `Start` computed
        // (`derivation length: (int)(simulation_ends/dt);`).
        d.control(ControlKind::Start)?;
        type Directive = Option<(crate::lang::ir::Ex, Span)>;
        let mut number =
            |e: &Directive, env: &mut Env| -> Result<Option<(f64, Span)>, DeriveError> {
                match e {
                    Some((e, span)) => {
                        let v = interp
                            .eval_global(e, env)
                            .map_err(|e| runtime(e, Some(*span), 0))?;
                        Ok(Some((v.as_f64(), *span)))
                    }
                    None => Ok(None),
                }
            };
        let stated = number(&program.derivation_length, &mut d.env)?;
        d.ring = number(&program.ring, &mut d.env)?.is_some_and(|(v, _)| v != 0.0);
        d.length = match (d.opts.steps, stated) {
            (Some(n), _) => n,
            (None, None) => 0,
            (None, Some((v, span))) => {
                if !(0.0..=MAX_STEPS as f64).contains(&v) || v.fract() != 0.0 {
                    return Err(DeriveError {
                        span: Some(span),
                        message: format!(
                            "the derivation length must be a whole number of steps from 0 to {MAX_STEPS}"
                        ),
                        step: 0,
                    });
                }
                v as u64
            }
        };
        if d.length > MAX_STEPS {
            return Err(DeriveError {
                span: None,
                message: format!(
                    "a derivation length of {} steps is beyond the limit of {MAX_STEPS}",
                    d.length
                ),
                step: 0,
            });
        }
        if let Some(m) = program.axiom.get(d.opts.max_modules) {
            return Err(DeriveError {
                span: Some(m.span),
                message: format!(
                    "the axiom has {} modules, more than the limit of {}; raise the limit with --max-modules",
                    program.axiom.len(),
                    d.opts.max_modules
                ),
                step: 0,
            });
        }
        let mut axiom = Word::new();
        interp
            .eval_modules(&program.axiom, &mut d.env, &mut axiom)
            .map_err(|e| runtime(e, None, 0))?;
        if traced {
            d.makers = Some((0..axiom.len()).map(Maker::Axiom).collect());
        }
        d.word = axiom;
        d.decompose()?;
        Ok(d)
    }

    /// lpfg's "interpretation for the environment", at the start of every
    /// derivation step, before `StartEach` (so on the axiom and on every
    /// word but the last), unless `NoEnvironment()` was called:
    ///
    /// * query modules (`GetPos`, `GetHead`, `GetLeft`, `GetUp`), when a
    ///   rule's predecessor mentions one: each that the turtle meets
    ///   receives the turtle's position (or heading, left, up vector) at
    ///   that point;
    /// * communication modules (`E1`, `E2`, `EA20`), when the run has an
    ///   environment ([`DeriveOptions::environment`]): each that the turtle
    ///   meets is sent with the turtle's frame, in the word's order, and
    ///   the environment's answers overwrite their parameters (E1 one
    ///   value, E2 two, EA20 up to twenty, the rest zeroed with
    ///   `clean_ea20`); a module it does not answer keeps its values.
    ///
    /// As in lpfg, the answers go into the word's own modules only: a
    /// module that an interpretation rule rewrites keeps its parameters,
    /// and one that an interpretation rule produces is answered in the
    /// interpreted word alone (it is still sent).
    fn answer_queries(&mut self) -> Result<(), DeriveError> {
        let p = self.program;
        if !self.env.environment {
            return Ok(());
        }
        let queries = self.queries_used();
        let communicating = self.running.is_some()
            && self
                .word
                .syms()
                .iter()
                .any(|s| self.communication.contains(s));
        if !queries && !communicating {
            return Ok(());
        }
        // Which module of the word each interpreted module copies: a
        // traced interpretation whose "axiom" is the word itself.
        let depth = self.depth(Section::Interpretation)?;
        let mut sources = Some((0..self.word.len()).map(Maker::Axiom).collect());
        let shown = self.rewrite_to_depth(
            Section::Interpretation,
            self.word.clone(),
            depth,
            &mut sources,
        )?;
        let angle = self.angle()?;
        let met = self
            .opts
            .queries
            .answer(&shown, p, angle)
            .map_err(|message| DeriveError {
                span: None,
                message: format!(
                    "at step {}, the interpretation step for query modules failed: {message}",
                    self.step
                ),
                step: self.step,
            })?;
        let sources = sources.unwrap_or_default();
        let source = |j: usize| match sources.get(j) {
            Some(Maker::Axiom(i)) => Some(*i),
            _ => None,
        };
        let mut answer: Vec<Option<Vec<f64>>> = vec![None; self.word.len()];
        for (j, v) in met.queries {
            if let Some(i) = source(j) {
                if self.word.data(i).len() == 3 {
                    answer[i] = Some(v.to_vec());
                }
            }
        }
        if communicating && !met.communication.is_empty() {
            self.exchange(&shown, &met.communication, &source, &mut answer)?;
        }
        if answer.iter().all(Option::is_none) {
            return Ok(());
        }
        let mut out = Word::new();
        out.reserve(self.word.len(), self.word.slot_count());
        for (i, a) in answer.iter().enumerate() {
            match a {
                Some(v) => {
                    // A `float` parameter holds the answer as lpfg's does.
                    let v: Vec<f64> = match p.single {
                        true => v.iter().map(|x| *x as f32 as f64).collect(),
                        false => v.clone(),
                    };
                    out.push_raw(self.word.sym(i), &v)
                }
                None => out.push_from(&self.word, i),
            }
        }
        self.word = out;
        Ok(())
    }

    /// Sends the communication modules the turtle met (`met`: index in
    /// `shown` and frame) to the running environment and puts its answers
    /// into `answer`, by the word's module each copies (`source`).
    fn exchange(
        &mut self,
        shown: &Word,
        met: &[(usize, super::environment::Frame)],
        source: &dyn Fn(usize) -> Option<usize>,
        answer: &mut [Option<Vec<f64>>],
    ) -> Result<(), DeriveError> {
        use super::environment::{Following, Query};
        let p = self.program;
        let following = self
            .opts
            .environment
            .as_ref()
            .is_some_and(|e| e.following_module());
        let clean_ea20 = self.opts.clean_ea20
            || self
                .opts
                .environment
                .as_ref()
                .is_some_and(|e| e.clean_ea20());
        let queries: Vec<Query> = met
            .iter()
            .map(|(j, frame)| Query {
                id: *j as u64,
                values: shown.data(*j).to_vec(),
                following: (following && j + 1 < shown.len()).then(|| Following {
                    name: p.alphabet.name(shown.sym(j + 1)).to_string(),
                    params: shown.data(j + 1).to_vec(),
                }),
                frame: *frame,
            })
            .collect();
        let step = self.step;
        let fail = |message: String| DeriveError {
            span: None,
            message: format!("before step {}, {message}", step + 1),
            step,
        };
        let running = self.running.as_mut().expect("an environment");
        let answers = running.exchange(&queries).map_err(&fail)?;
        // An answer lpfg cannot use (a module it did not send, the wrong
        // number of values) is reported and passed over, as lpfg does
        // ("Invalid response received from environment"): the module keeps
        // its values.
        let mut invalid: Vec<String> = Vec::new();
        // The turtle meets the modules in the word's order.
        debug_assert!(met.windows(2).all(|w| w[0].0 < w[1].0));
        for a in answers {
            let j = usize::try_from(a.id).unwrap_or(usize::MAX);
            if met.binary_search_by_key(&j, |(k, _)| *k).is_err() {
                invalid.push(format!("module {}, which it was not sent", a.id));
                continue;
            }
            let name = p.alphabet.name(shown.sym(j));
            let width = shown.data(j).len();
            let ok = match name {
                "EA20" => a.values.len() <= width,
                _ => a.values.len() == width,
            };
            if !ok {
                invalid.push(format!(
                    "module {} (`{name}`, which takes {}{width}) with {} value{}",
                    a.id,
                    if name == "EA20" { "at most " } else { "" },
                    a.values.len(),
                    if a.values.len() == 1 { "" } else { "s" },
                ));
                continue;
            }
            let Some(i) = source(j) else { continue };
            let mut v = answer[i]
                .take()
                .unwrap_or_else(|| self.word.data(i).to_vec());
            if v.len() != width {
                continue;
            }
            for (k, x) in a.values.iter().enumerate() {
                v[k] = *x as f32 as f64;
            }
            if name == "EA20" && clean_ea20 {
                for x in &mut v[a.values.len()..] {
                    *x = 0.0;
                }
            }
            answer[i] = Some(v);
        }
        if let Some(first) = invalid.first() {
            let more = match invalid.len() {
                1 => String::new(),
                n => format!(" (and {} more)", n - 1),
            };
            self.opts.output.message(&format!(
                "warning: before step {}, the environmental program answered {first}{more}; \
                 lpfg passes over such answers, and so does subgram: those modules keep their \
                 values\n",
                step + 1
            ));
        }
        Ok(())
    }

    /// True when a production, decomposition or interpretation rule of
    /// any group has a query module in its strict predecessor or its
    /// contexts (lpfg does not look at new contexts).
    fn queries_used(&self) -> bool {
        let p = self.program;
        p.rules.iter().any(|r| {
            r.left
                .iter()
                .chain(&r.strict)
                .chain(&r.right)
                .any(|pat| is_query(p.alphabet.name(pat.sym)))
        })
    }

    fn control(&mut self, kind: ControlKind) -> Result<(), DeriveError> {
        let mut interp = Interp::for_program(self.program, self.opts.deadline);
        for (k, body, frame) in &self.program.control {
            if *k == kind {
                let mut frame = vec![Value::Void; *frame];
                let mut sink: Vec<(Sym, Vec<Value>)> = Vec::new();
                run_block(&mut interp, body, &mut frame, &mut self.env, &mut sink)
                    .map_err(|e| runtime(e, None, self.step))?;
            }
        }
        Ok(())
    }

    /// The rules of `section` usable now: the current group's, then group
    /// 0's; for interpretation, only those of the view being drawn.
    fn candidates(&self, section: Section) -> Vec<usize> {
        let g = self.env.current_group;
        let view = self.view;
        let of = |group: i64| {
            self.program.rules_of(section).filter(move |(_, r)| {
                r.group == group && (section != Section::Interpretation || r.vgroup == view)
            })
        };
        let mut v: Vec<usize> = of(g).map(|(i, _)| i).collect();
        if g != 0 {
            v.extend(of(0).map(|(i, _)| i));
        }
        v
    }

    fn step_options(&self) -> StepOptions {
        StepOptions {
            ring: self.ring,
            forward: self.env.forward,
            phase: self.opts.phase,
            max_modules: self.opts.max_modules,
            deadline: self.opts.deadline,
            cut: false,
        }
    }

    /// The options the derivation runs with.
    pub fn options(&self) -> &DeriveOptions {
        &self.opts
    }

    /// True while steps remain and `Stop()` has not been called.
    pub fn has_next(&self) -> bool {
        self.step < self.length && !self.env.stop
    }

    /// Performs one derivation step with its control blocks.
    pub fn next_step(&mut self) -> Result<(), DeriveError> {
        self.step_read(None)
    }

    /// [`Derivation::next_step`], with `growth`'s reader reading the
    /// step's new word: as its parts are written, when the step writes it
    /// in parts, and then whole, before the step's decomposition and
    /// `EndEach`. When the step fails the reader may have read only some
    /// of it, or none; the caller then abandons the growth.
    pub(crate) fn next_step_read(
        &mut self,
        growth: &std::sync::Arc<super::growth::Growth>,
    ) -> Result<(), DeriveError> {
        self.step_read(Some(growth))
    }

    fn step_read(
        &mut self,
        growth: Option<&std::sync::Arc<super::growth::Growth>>,
    ) -> Result<(), DeriveError> {
        if let Err(m) = crate::deadline::check(self.opts.deadline) {
            return Err(self.step_error(StepError::Timeout(m), self.step + 1));
        }
        self.answer_queries()?;
        // `StepNo()` is the step under way from `StartEach` on, counted
        // from 1 (lpfg: 1 in the first `StartEach`, production and
        // `EndEach`; 0 in `Start`).
        self.env.step = self.step as i64 + 1;
        self.control(ControlKind::StartEach)?;
        self.env.current_group = self.env.next_group;
        let rules = self.candidates(Section::Productions);
        // Production steps cut branches; decomposition and interpretation
        // do not (lpfg).
        let opts = StepOptions {
            cut: true,
            ..self.step_options()
        };
        let mut dst = std::mem::take(&mut self.spare);
        let step = self.step + 1;
        let mut origin = Vec::new();
        let traced = self.makers.is_some();
        let gillespie = self
            .program
            .gillespie_groups
            .iter()
            .find(|(g, _)| *g == self.env.current_group);
        if let (Some((_, at)), false) = (gillespie, self.env.forward) {
            return Err(DeriveError {
                span: Some(*at),
                message: format!(
                    "at step {step}, group {} is a Gillespie group, which derives forward \
                     only: `Backward()` cannot be used with it",
                    self.env.current_group
                ),
                step,
            });
        }
        self.rewriter.reader = growth.cloned();
        let result = if gillespie.is_some() {
            self.gillespie_step(&mut dst, traced.then_some(&mut origin))
        } else {
            self.rewriter.step(
                &rules,
                &self.word,
                &mut dst,
                &mut self.env,
                &opts,
                None,
                traced.then_some(&mut origin),
            )
        };
        self.rewriter.reader = None;
        if let Err(e) = result {
            return Err(self.step_error(e, step));
        }
        if let Some(g) = growth {
            g.hand_over(&dst);
        }
        if let Some(m) = &self.makers {
            self.makers = made_by(m, &origin);
        }
        self.spare = std::mem::replace(&mut self.word, dst);
        self.env.step = step as i64;
        self.step = step;
        self.decompose()?;
        self.control(ControlKind::EndEach)?;
        if !self.has_next() {
            // The last step is done: the old word and the rewriter's
            // scratch words would only hold memory while the word is
            // drawn or written.
            self.spare = Word::new();
            self.rewriter.release();
        }
        Ok(())
    }

    /// A step of the current group, a Gillespie group: its productions
    /// only (no fall-back to group 0), one reaction in the whole word.
    fn gillespie_step(
        &mut self,
        dst: &mut Word,
        origin: Option<&mut Vec<u32>>,
    ) -> Result<usize, StepError> {
        let g = self.env.current_group;
        let rules: Vec<usize> = self
            .program
            .rules_of(Section::Productions)
            .filter(|(_, r)| r.group == g)
            .map(|(i, _)| i)
            .collect();
        let opts = self.step_options();
        super::gillespie::step(
            &mut self.rewriter,
            self.program,
            &rules,
            &self.word,
            dst,
            &mut self.env,
            &opts,
            origin,
        )
    }

    /// Runs `End`, as lpfg does after the final derivation step. A caller
    /// that drives the steps itself calls this once it has taken the last.
    pub fn end(&mut self) -> Result<(), DeriveError> {
        self.control(ControlKind::End)
    }

    /// Runs the remaining steps and `End`.
    pub fn run(mut self) -> Result<Derived, DeriveError> {
        while self.has_next() {
            self.next_step()?;
        }
        self.control(ControlKind::End)?;
        Ok(Derived {
            word: self.word,
            ring: self.ring,
            step: self.step,
            env: self.env,
        })
    }

    fn step_error(&self, e: StepError, step: u64) -> DeriveError {
        let at_rule = |rule: usize, span: Option<Span>, message: &str| {
            let r = &self.program.rules[rule];
            let what = rule_kind(r.section);
            DeriveError {
                span: span.or(Some(r.span)),
                message: format!("at step {step}, {what} `{}`: {message}", r.label),
                step,
            }
        };
        match e {
            StepError::Runtime { rule, error } => at_rule(rule, error.span, &error.message),
            StepError::TooLong {
                limit,
                rule: Some(rule),
            } => at_rule(rule, None, &too_long(limit)),
            StepError::TooLong { limit, rule: None } => DeriveError {
                span: None,
                message: format!("at step {step}, {}", too_long(limit)),
                step,
            },
            StepError::Timeout(m) => DeriveError {
                span: None,
                message: format!("at step {step}, {m}"),
                step,
            },
        }
    }

    /// Applies decomposition rules to the current word, to the maximum depth.
    fn decompose(&mut self) -> Result<(), DeriveError> {
        let depth = self.depth(Section::Decomposition)?;
        let word = std::mem::take(&mut self.word);
        let mut makers = self.makers.take();
        self.word = self.rewrite_to_depth(Section::Decomposition, word, depth, &mut makers)?;
        self.makers = makers;
        Ok(())
    }

    fn depth(&mut self, section: Section) -> Result<u64, DeriveError> {
        let e = match section {
            Section::Interpretation => &self.program.interpretation_depth,
            _ => &self.program.decomposition_depth,
        };
        let Some((e, span)) = e else { return Ok(1) };
        let mut interp = Interp::for_program(self.program, None);
        let v = interp
            .eval_global(e, &mut self.env)
            .map_err(|e| runtime(e, Some(*span), self.step))?
            .as_f64();
        if !(0.0..=MAX_DEPTH as f64).contains(&v) || v.fract() != 0.0 {
            return Err(DeriveError {
                span: Some(*span),
                message: format!(
                    "the maximum depth must be a whole number of levels from 0 to {MAX_DEPTH}"
                ),
                step: self.step,
            });
        }
        Ok(v as u64)
    }

    /// Rewrites `word` with the rules of `section` recursively: after the
    /// first pass only modules that a rule produced are rewritten again.
    /// `makers`, if any, follow the word's modules.
    fn rewrite_to_depth(
        &mut self,
        section: Section,
        mut word: Word,
        depth: u64,
        makers: &mut Option<Vec<Maker>>,
    ) -> Result<Word, DeriveError> {
        let rules = self.candidates(section);
        if rules.is_empty() {
            return Ok(word);
        }
        let opts = self.step_options();
        // After the first pass: which modules a rule produced.
        let mut eligible: Vec<bool> = Vec::new();
        let mut origin = Vec::new();
        let mut dst = Word::new();
        for pass in 0..depth {
            let n = self
                .rewriter
                .step(
                    &rules,
                    &word,
                    &mut dst,
                    &mut self.env,
                    &opts,
                    (pass > 0).then_some(&eligible[..]),
                    Some(&mut origin),
                )
                .map_err(|e| self.step_error(e, self.step))?;
            std::mem::swap(&mut word, &mut dst);
            if let Some(m) = makers {
                *makers = made_by(m, &origin);
            }
            if n == 0 {
                break;
            }
            eligible.clear();
            eligible.extend(origin.iter().map(|&o| o & COPIED == 0));
        }
        Ok(word)
    }

    /// The value of `angle:`, if the program sets it.
    pub fn angle(&mut self) -> Result<Option<f64>, DeriveError> {
        let Some((e, span)) = &self.program.angle else {
            return Ok(None);
        };
        let mut interp = Interp::for_program(self.program, None);
        let v = interp
            .eval_global(e, &mut self.env)
            .map_err(|e| runtime(e, Some(*span), self.step))?;
        Ok(Some(v.as_f64()))
    }

    /// The word after interpretation rules: what the turtle draws.
    pub fn interpret(&mut self) -> Result<Word, DeriveError> {
        Ok(self.interpret_traced()?.0)
    }

    /// The word after the interpretation rules of view `view` (those after
    /// `vgroup view:`; view 0 is the main view, [`Derivation::interpret`]).
    pub fn interpret_view(&mut self, view: i64) -> Result<Word, DeriveError> {
        self.interpreted_view(view)
            .map(std::borrow::Cow::into_owned)
    }

    /// [`Derivation::interpret_view`], borrowing the word when no
    /// interpretation rule of the view applies (a large word is not
    /// copied to be drawn): the rules, when some apply, rewrite a copy of
    /// it to the interpretation's depth.
    pub fn interpreted_view(
        &mut self,
        view: i64,
    ) -> Result<std::borrow::Cow<'_, Word>, DeriveError> {
        self.view = view;
        let rewritten = self.depth(Section::Interpretation).and_then(|depth| {
            if self.candidates(Section::Interpretation).is_empty() {
                return Ok(None);
            }
            let word = self.word.clone();
            self.rewrite_to_depth(Section::Interpretation, word, depth, &mut None)
                .map(Some)
        });
        self.view = 0;
        Ok(match rewritten? {
            Some(word) => std::borrow::Cow::Owned(word),
            None => std::borrow::Cow::Borrowed(&self.word),
        })
    }

    /// The views `UseView` activated so far, in order.
    pub fn views(&self) -> &[i64] {
        &self.env.views
    }

    /// [`Derivation::interpret`], with what made each module of the
    /// interpreted word when the derivation is traced
    /// ([`Derivation::traced`]) and the word was not replaced.
    pub(crate) fn interpret_traced(&mut self) -> Result<(Word, Option<Vec<Maker>>), DeriveError> {
        let depth = self.depth(Section::Interpretation)?;
        let word = self.word.clone();
        let mut makers = self.makers.clone().filter(|m| m.len() == self.word.len());
        let word = self.rewrite_to_depth(Section::Interpretation, word, depth, &mut makers)?;
        Ok((word, makers))
    }
}

fn run_block(
    interp: &mut Interp,
    body: &[St],
    frame: &mut [Value],
    env: &mut Env,
    sink: &mut Vec<(Sym, Vec<Value>)>,
) -> Result<(), RuntimeError> {
    interp.run(body, frame, env, &mut NoHost, sink)?;
    Ok(())
}

fn runtime(e: RuntimeError, span: Option<Span>, step: u64) -> DeriveError {
    DeriveError {
        span: e.span.or(span),
        message: e.message,
        step,
    }
}

/// Derives `program` to its derivation length (or `opts.steps`).
pub fn derive(program: &Program, opts: DeriveOptions) -> Result<Derived, DeriveError> {
    Derivation::new(program, opts)?.run()
}
