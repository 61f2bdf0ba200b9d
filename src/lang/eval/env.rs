//! The global state shared by all bodies of one derivation.

use super::super::ir::Program;
use super::super::random::Random;
use super::super::stdio::ProgramOutput;
use super::super::value::Value;
use super::{Interp, RuntimeError};

/// Global state shared by all bodies of one derivation.
#[derive(Clone, Debug)]
pub struct Env {
    pub globals: Vec<Value>,
    pub step: i64,
    pub current_group: i64,
    pub next_group: i64,
    /// Direction requested for the next step (`Forward()` / `Backward()`).
    pub forward: bool,
    pub stop: bool,
    /// The run's random number generators (`ran`, `rand`, `drand48`,
    /// Gillespie steps).
    pub random: Random,
    /// The model folder's functions and contours, for `func` and its kin.
    pub model: super::super::model::ModelRef,
    /// What the program prints and the files it writes.
    pub output: ProgramOutput,
    /// The views `UseView` activated, in the order of their first call,
    /// each once (at most [`MAX_VIEWS`]).
    pub views: Vec<i64>,
    /// False after `NoEnvironment()`: query modules are not answered.
    pub environment: bool,
}

impl Env {
    /// The environment of a run of `program`: every global exists, zero,
    /// before the initialisers run (one may call a function that reads a
    /// global declared after it); then each initialiser, in order.
    pub fn for_program(
        program: &Program,
        interp: &mut Interp,
        output: ProgramOutput,
        seed: Option<u32>,
    ) -> Result<Env, RuntimeError> {
        let zeros = program
            .globals
            .iter()
            .map(|g| Value::zero(g.ty, &program.structs))
            .collect();
        let mut env = Env::new(zeros);
        env.output = output;
        env.random = Random::new(seed);
        env.model = program.model.clone();
        for (k, g) in program.globals.iter().enumerate() {
            if let Some(e) = &g.init {
                env.globals[k] = interp.eval_global(e, &mut env)?.convert(g.ty);
            }
        }
        Ok(env)
    }
}

/// More views than this are not recorded.
pub const MAX_VIEWS: usize = 64;

impl Env {
    /// An environment with `globals` whose model accessors ask `model`.
    pub fn with_model(globals: Vec<Value>, model: super::super::model::ModelRef) -> Env {
        Env {
            model,
            ..Env::new(globals)
        }
    }

    /// An environment with `globals` and no model ([`super::super::model::NoModel`]).
    pub fn new(globals: Vec<Value>) -> Env {
        Env {
            globals,
            step: 0,
            current_group: 0,
            next_group: 0,
            forward: true,
            stop: false,
            random: Random::default(),
            model: Default::default(),
            output: ProgramOutput::default(),
            views: Vec::new(),
            environment: true,
        }
    }
}
