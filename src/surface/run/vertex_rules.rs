//! Vertex rules, matched and evaluated in one pass, their points written
//! to the next-position buffer.

use glam::DVec3;
use rayon::prelude::*;

use crate::lang::eval::RuntimeError;
use crate::lang::value::Value;
use crate::mesh::{Mesh, VertexId};
use crate::surface::host;

use super::apply::rule_error;
use super::evaluator::Evaluator;
use super::matching::vertex_candidate;
use super::{Grammar, Rule, RunError, RunState, CHUNK};

impl Grammar {
    /// A vertex rule, matched and evaluated in one pass: the vertices (or
    /// the work list) in chunks on rayon's threads, each chunk testing the
    /// condition and evaluating the assignment of its vertices and writing
    /// their points to the next-position buffer at their slots. The same
    /// as matching every vertex first and evaluating the matches after:
    /// a vertex rule changes neither the topology nor the current
    /// positions, so every match and every point reads what it read when
    /// the rule started. The errors are those of the two passes: the
    /// first condition that fails to evaluate, in id order; else the
    /// first match, in id order, whose point is not a finite point.
    pub(super) fn apply_vertex_rule(
        &self,
        rule: &Rule,
        mesh: &Mesh,
        state: &mut RunState,
    ) -> Result<(), RunError> {
        let step = state.step as usize;
        let current = state.current_level;
        // A crease rule on a mesh without creases matches nothing.
        if !mesh.has_sharpness_flag()
            && rule
                .guard
                .as_ref()
                .is_some_and(|g| g.never_without_creases())
        {
            return Ok(());
        }
        let list = state.work_list(rule, mesh);
        let slots = list.as_ref().map_or(mesh.v_alive.len(), |l| l.len());
        let id_at = |i: usize| VertexId(list.as_ref().map_or(i as u32, |l| l[i]));
        let protect = state.protect.as_ref();
        let assign = rule.assign.as_ref();
        let slot = rule.elem_slot as usize;
        // Tests and evaluates the ids at places `lo..hi`, handing each
        // point to `emit` with its place.
        let task = |lo: usize, hi: usize, emit: &mut dyn FnMut(usize, VertexId, DVec3)| {
            let mut ev = Evaluator::new(mesh, current, state.step, rule.frame, self.creasing);
            let mut end = VertexTask::default();
            for i in lo..hi {
                let v = id_at(i);
                let Some(ok) = vertex_candidate(mesh, v, protect, rule) else {
                    continue;
                };
                let val = host::vertex(v);
                match ok.then(|| ev.test(rule, &val)) {
                    Some(Err(e)) => {
                        end.error = Some(e);
                        return end;
                    }
                    Some(Ok(true)) => {}
                    _ => continue,
                }
                // After a bad point only the conditions matter: one that
                // fails later in the chunk is the error to report.
                let Some(assign) = assign.filter(|_| end.bad.is_none()) else {
                    continue;
                };
                ev.frame[slot] = Value::Elem(val);
                match ev.assign(rule, assign) {
                    Ok(Value::V3(p)) if p.is_finite() => emit(i, v, p),
                    _ => end.bad = Some(i),
                }
            }
            end
        };
        let ranges =
            |n: usize| (0..n.div_ceil(CHUNK)).map(move |k| (k * CHUNK, ((k + 1) * CHUNK).min(n)));
        let ends: Vec<VertexTask> = match (&list, assign) {
            // Every slot: each chunk writes its own block of the buffer.
            (None, Some(_)) => {
                state.next.cover(mesh);
                let pos = &mesh.pos;
                state
                    .next
                    .blocks
                    .par_iter_mut()
                    .take(slots.div_ceil(CHUNK))
                    .enumerate()
                    .map(|(k, block)| {
                        let lo = k * CHUNK;
                        let mut out = Vec::with_capacity(block.len);
                        let end = task(lo, lo + block.len, &mut |i, _, p| {
                            out.push(((i - lo) as u32, p))
                        });
                        block.write(&pos[lo..lo + block.len], &out);
                        end
                    })
                    .collect()
            }
            // A work list: each chunk's points, then written in order.
            (Some(_), Some(_)) => {
                let parts: Vec<(VertexTask, Vec<(VertexId, DVec3)>)> = ranges(slots)
                    .collect::<Vec<_>>()
                    .into_par_iter()
                    .map(|(lo, hi)| {
                        let mut out = Vec::new();
                        let end = task(lo, hi, &mut |_, v, p| out.push((v, p)));
                        (end, out)
                    })
                    .collect();
                state.next.cover(mesh);
                parts
                    .into_iter()
                    .map(|(end, out)| {
                        state.next.write(&mesh.pos, &out);
                        end
                    })
                    .collect()
            }
            // No assignment: the conditions are still tested.
            (_, None) => ranges(slots)
                .collect::<Vec<_>>()
                .into_par_iter()
                .map(|(lo, hi)| task(lo, hi, &mut |_, _, _| {}))
                .collect(),
        };
        let mut bad = None;
        for end in ends {
            if let Some(e) = end.error {
                return Err(self.runtime_error(rule, step, e));
            }
            bad = bad.or(end.bad);
        }
        let (Some(i), Some(assign)) = (bad, assign) else {
            return Ok(());
        };
        // Evaluate the first bad one again, to say what it gave.
        let v = id_at(i);
        let mut ev = Evaluator::new(mesh, current, state.step, rule.frame, self.creasing);
        ev.frame[slot] = Value::Elem(host::vertex(v));
        Err(match ev.assign(rule, assign) {
            Ok(Value::V3(p)) => rule_error(
                rule,
                step,
                format!("vertex {v} would move to {p}, which is not finite"),
            ),
            Ok(_) => rule_error(rule, step, "the assignment did not give a point".into()),
            Err(e) => self.runtime_error(rule, step, e),
        })
    }
}

/// How one task of a vertex rule ended (see `Grammar::apply_vertex_rule`).
#[derive(Default)]
struct VertexTask {
    /// The first condition that failed to evaluate, which stopped it.
    error: Option<RuntimeError>,
    /// The first matched vertex, by its place among the ids tested, whose
    /// point was not finite or not a point.
    bad: Option<usize>,
}
