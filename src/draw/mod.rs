//! Interpretation of a word as drawing: the turtle walks the modules and
//! emits renderer-neutral [`Event`]s in 3D. PNG and SVG both draw these
//! events, so the two always agree.
//!
//! **Layer.** It uses `colour`, `lang`, `model`, `rewrite`, `scene3`,
//! `syntax`; it is used by `command`, `curve`, `error`, `load`, `render`,
//! `reverse`. Nothing here names a layer above (see ARCHITECTURE.md,
//! "Layers").
//!
//! The folder holds one concept per file:
//!
//! - this file: the entry points ([`draw`], [`draw_with_queries`]), their
//!   settings ([`DrawOptions`], [`TurtleView`]), [`DrawError`], and the
//!   `Sink` that the walk draws into;
//! - `turtle`: the turtle: its frame, pen and coordinate system, and how
//!   it turns;
//! - `commands`: what each predefined module does to the turtle
//!   ([`acts_on`]), the circles and spheres, the modules that shape 3D
//!   geometry;
//! - `walk`: the turtle's walk over a word (the fast and the full loop, a
//!   word walked in pieces) and its errors at infinite coordinates;
//! - `events`: the renderer-neutral [`Event`]s and the 2D sink that makes
//!   them;
//! - `bounds`: the box around the turtle's lines ([`line_bounds`]);
//! - `surfaces`: where a model's surface lies at the turtle, and its
//!   patches' outlines as events;
//! - [`solid`]: the turtle's 3D geometry (tubes, generalized cylinders,
//!   surfaces, spheres, polygons);
//! - [`tropism`]: the view file's tropisms and the simple tropism;
//! - `queries`: the turtle's answers to query modules ([`QueryTurtle`]);
//! - `coverage`: warnings about modules the turtle does not act on.

mod bounds;
mod commands;
pub(crate) mod coverage;
mod events;
mod queries;
pub mod solid;
mod surfaces;
pub mod tropism;
mod turtle;
mod walk;

pub use crate::rewrite::is_query;
pub use bounds::line_bounds;
pub use commands::acts_on;
pub(crate) use commands::{Round, Shaping};
pub use events::{Event, Pen};
pub(crate) use events::{EventSink, Events};
pub use queries::QueryTurtle;
pub(crate) use surfaces::placement;
pub(crate) use turtle::Turtle;
use turtle::EPSILON;
pub(crate) use walk::{walk, Walk};

use glam::DVec3;

use crate::lang::value::StructDef;
use crate::lang::Alphabet;
use crate::rewrite::{TurtleAnswers, Word};

/// Settings of interpretation.
#[derive(Clone, Debug)]
pub struct DrawOptions {
    /// The angle of `+ - & ^ / \` and of `Left()` without an argument.
    pub angle: f64,
    /// Length of `F` without an argument.
    pub step: f64,
    /// The model the word came with: its surfaces for `Surface`.
    pub model: std::sync::Arc<crate::model::Model>,
    /// What the view file sets for the turtle.
    pub view: TurtleView,
}

impl Default for DrawOptions {
    fn default() -> Self {
        DrawOptions {
            angle: 90.0,
            step: 1.0,
            model: Default::default(),
            view: TurtleView::default(),
        }
    }
}

/// The view file's settings of the turtle (manual 8.1.3, 8.1.4).
#[derive(Clone, Debug, PartialEq)]
pub struct TurtleView {
    /// `corrected rotation:` (default on). Off, `Up`, `Down`, `RollL` and
    /// `RollR` turn the other way, as lpfg's old versions did.
    pub corrected_rotation: bool,
    /// `tropism:`, `torque:` and `stropism:`.
    pub tropisms: tropism::Tropisms,
}

impl Default for TurtleView {
    fn default() -> Self {
        TurtleView {
            corrected_rotation: true,
            tropisms: tropism::Tropisms::default(),
        }
    }
}

/// A problem with a word that cannot be drawn.
#[derive(Clone, Debug, PartialEq)]
pub struct DrawError {
    pub message: String,
    /// The module at fault (counted from 0), when one is.
    pub module: Option<usize>,
}

impl std::fmt::Display for DrawError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for DrawError {}

/// What the turtle's walk hands its drawing to: the 2D events of
/// [`draw`], or the 3D geometry of [`solid::solid`]. The walk moves and
/// turns the turtle; a sink only makes what the turtle draws, from the
/// turtle as it stands. An `Err` is a message about the module at hand.
pub(crate) trait Sink {
    /// Whether [`Sink::line`] reads the turtle's position and frame (it
    /// reads its pen in any case): the walk keeps them in registers and
    /// writes them to the turtle only for sinks that read them.
    const LINE_READS_FRAME: bool = true;
    /// A drawn line from `a` to `b` (`F`, `G`, `LineTo`, ...); the turtle
    /// is already at `b`, turned as it is after the module.
    fn line(&mut self, t: &Turtle, a: DVec3, b: DVec3) -> Result<(), String>;
    /// A circle or sphere of radius `r` (the pen's width for the `0`
    /// kinds) at the turtle.
    fn round(&mut self, t: &Turtle, kind: Round, r: f64) -> Result<(), String>;
    /// A filled polygon of three or more points (`SP ... EP`, `Rhombus`,
    /// `Triangle`), drawn by the turtle `t` where it ends.
    fn polygon(&mut self, t: &Turtle, points: Vec<DVec3>) -> Result<(), String>;
    /// Surface `s` of the model at the turtle, scaled by `scale`.
    fn surface(
        &mut self,
        t: &Turtle,
        s: &crate::model::Surface,
        scale: DVec3,
    ) -> Result<(), String>;
    /// `SB`: the turtle was pushed.
    fn push(&mut self) {}
    /// `EB`: the turtle was popped (only when the stack held one).
    fn pop(&mut self) -> Result<(), String> {
        Ok(())
    }
    /// `SetWidth` (after the pen took it) and the modules of
    /// [`Cmd::Shape`], with the module's parameters as numbers (missing
    /// ones 0).
    ///
    /// [`Cmd::Shape`]: commands::Cmd::Shape
    fn shape(&mut self, _t: &Turtle, _cmd: Option<Shaping>, _d: &[f64]) -> Result<(), String> {
        Ok(())
    }
}

/// Interprets `word` with the turtle and returns the drawing events.
pub fn draw(
    word: &Word,
    alphabet: &Alphabet,
    structs: &[StructDef],
    opts: &DrawOptions,
) -> Result<Vec<Event>, DrawError> {
    draw_with_queries(word, alphabet, structs, opts, None)
}

/// Like [`draw`]; also records, for every query module met, its index in
/// `word` and the vector it asks for (`GetPos`: position,
/// `GetHead`/`GetLeft`/`GetUp`: the frame).
pub fn draw_with_queries(
    word: &Word,
    alphabet: &Alphabet,
    structs: &[StructDef],
    opts: &DrawOptions,
    queries: Option<&mut TurtleAnswers>,
) -> Result<Vec<Event>, DrawError> {
    let mut events = Events::new(Vec::new());
    walk(word, alphabet, structs, opts, queries, &mut events)?;
    Ok(events.into_inner())
}
