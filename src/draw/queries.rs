//! [`QueryTurtle`]: the turtle as the derivation's answerer of query
//! modules ([`crate::rewrite::Queries`]), and the `Default` of
//! [`DeriveOptions`], which answers with it. (The derivation sits below
//! the drawing and cannot name the turtle; the default is given here.)

use std::sync::Arc;

use crate::lang::ir::Program;
use crate::rewrite::{DeriveOptions, Queries, TurtleAnswers, Word};

use super::{draw_with_queries, DrawOptions, TurtleView};

/// The turtle with a view file's settings (rotations, tropisms), walking
/// the interpreted word to answer its query modules.
#[derive(Clone, Debug, Default)]
pub struct QueryTurtle {
    pub view: TurtleView,
}

impl Queries for QueryTurtle {
    fn answer(
        &self,
        shown: &Word,
        program: &Program,
        angle: Option<f64>,
    ) -> Result<TurtleAnswers, String> {
        let mut draw_opts = DrawOptions {
            view: self.view.clone(),
            ..Default::default()
        };
        if let Some(a) = angle {
            draw_opts.angle = a;
        }
        let mut answers = TurtleAnswers::default();
        draw_with_queries(
            shown,
            &program.alphabet,
            &program.structs,
            &draw_opts,
            Some(&mut answers),
        )
        .map_err(|e| e.message)?;
        Ok(answers)
    }
}

impl Default for DeriveOptions {
    /// lpfg's behaviour: query modules answered by the turtle without a
    /// view file's settings.
    fn default() -> Self {
        DeriveOptions::answered_by(Arc::new(QueryTurtle::default()))
    }
}
