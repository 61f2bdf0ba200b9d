//! The rules of a step applied in order (an interior and a boundary edge
//! split written next to each other matched together), and run errors
//! located at a rule.

use crate::lang::eval::RuntimeError;
use crate::mesh::Mesh;
use crate::surface::grammar::Op;

use super::{Grammar, Rule, RunError, RunState};

impl Grammar {
    /// Applies `rules` in order. An interior and a boundary edge-split rule
    /// written next to each other are the two contexts of one edge split:
    /// both match when the first starts, so that what one splits (or marks
    /// as a block's internal edge) cannot feed the other in the same step.
    pub(super) fn apply_all(
        &self,
        rules: &[&Rule],
        mesh: &mut Mesh,
        state: &mut RunState,
    ) -> Result<(), RunError> {
        let step = state.step as usize;
        let splits = |r: &Rule| matches!(r.op, Op::EdgeSplit | Op::BoundarySplit);
        // c: the highest vertex level, raised below by the vertices that
        // splits make (rules never remove vertices).
        state.current_level = mesh
            .vertices()
            .map(|v| mesh.vertex_level(v))
            .max()
            .unwrap_or(0);
        let mut i = 0;
        while i < rules.len() {
            let rule = rules[i];
            if let Err(m) = crate::deadline::check(state.deadline) {
                return Err(RunError {
                    span: Some(rule.span),
                    message: format!("at step {step}, before rule `{}`: {m}", rule.text),
                });
            }
            let pair = rules.get(i + 1).filter(|next| {
                matches!(
                    (rule.op, next.op),
                    (Op::EdgeSplit, Op::BoundarySplit) | (Op::BoundarySplit, Op::EdgeSplit)
                )
            });
            match pair {
                _ if state.adaptive && splits(rule) => {
                    let (a, b) = self
                        .find_matches_with(rule, pair.copied(), mesh, state)
                        .map_err(|(in_next, e)| {
                            self.runtime_error(
                                match pair {
                                    Some(next) if in_next => next,
                                    _ => rule,
                                },
                                step,
                                e,
                            )
                        })?;
                    self.apply_adaptive(rule, pair.copied(), mesh, state, a, b)?;
                    i += 1 + pair.is_some() as usize;
                }
                Some(next) => {
                    let (a, b) = self
                        .find_matches_with(rule, Some(next), mesh, state)
                        .map_err(|(in_next, e)| {
                            self.runtime_error(if in_next { next } else { rule }, step, e)
                        })?;
                    self.apply_matched(rule, mesh, state, a)?;
                    self.apply_matched(next, mesh, state, b)?;
                    i += 2;
                }
                None if rule.op == Op::Vertex => {
                    self.apply_vertex_rule(rule, mesh, state)?;
                    i += 1;
                }
                None => {
                    let m = self
                        .find_matches(rule, mesh, state)
                        .map_err(|e| self.runtime_error(rule, step, e))?;
                    self.apply_matched(rule, mesh, state, m)?;
                    i += 1;
                }
            }
        }
        Ok(())
    }

    /// A run-time error in a rule's expressions, located and with the step.
    pub(super) fn runtime_error(&self, rule: &Rule, step: usize, e: RuntimeError) -> RunError {
        let at = if step == 0 {
            format!("at initialization, rule `{}`", rule.text)
        } else {
            format!("at step {step}, rule `{}`", rule.text)
        };
        RunError {
            span: Some(e.span.unwrap_or(rule.span)),
            message: format!("{at}: {}", e.message),
        }
    }
}

/// An error of `rule` at `step` (0: the `init:` rules).
pub(super) fn rule_error(rule: &Rule, step: usize, m: String) -> RunError {
    RunError {
        span: Some(rule.span),
        message: if step == 0 {
            format!("at initialization, rule `{}`: {m}", rule.text)
        } else {
            format!("at step {step}, rule `{}`: {m}", rule.text)
        },
    }
}
