//! Rules that change the topology: face splits, edge splits and flips,
//! applied to what they matched, and the points of the vertices the
//! splits make.

use glam::DVec3;
use rayon::prelude::*;

use crate::lang::eval::RuntimeError;
use crate::lang::ir::Ex;
use crate::lang::value::{Elem, Value};
use crate::mesh::{Mesh, VertexId};
use crate::surface::grammar::Op;
use crate::surface::host;

use super::apply::rule_error;
use super::evaluator::Evaluator;
use super::matching::{edge_id, Matches};
use super::{Grammar, Rule, RunError, RunState, CHUNK};

/// The points of a split rule whose points read no other new vertex
/// (`Rule::points_in_place`) are computed and written this many at a
/// time.
const POINT_BATCH: usize = 16 * CHUNK;

/// The points of a split rule that are computed between its splits
/// (`Rule::points_between_splits`) are computed this many at a time (at
/// least: whole parts of the matches).
const BETWEEN_SPLITS_BATCH: usize = 4 * CHUNK;

impl Grammar {
    /// Evaluates `assign` for elements `range` in parallel, `bind` setting
    /// each one's frame slots, giving the points in order; or the first
    /// element whose point is not finite, with what it gave: a point, a
    /// value that is not one, or an error.
    #[allow(clippy::too_many_arguments)] // the host's `c` and step beside the rule's inputs
    fn eval_points(
        &self,
        rule: &Rule,
        mesh: &Mesh,
        current: u32,
        step: u32,
        assign: &Ex,
        range: std::ops::Range<usize>,
        bind: impl Fn(&mut [Value], usize) + Sync,
    ) -> Result<Vec<DVec3>, (usize, Result<Value, RuntimeError>)> {
        let lo = range.start;
        let one = |ev: &mut Evaluator, k: usize| {
            bind(&mut ev.frame, k);
            ev.assign(rule, assign)
        };
        let points: Vec<DVec3> = range
            .into_par_iter()
            .with_min_len(CHUNK)
            .map_init(
                || Evaluator::new(mesh, current, step, rule.frame, self.creasing),
                |ev, k| match one(ev, k) {
                    Ok(Value::V3(p)) => p,
                    _ => DVec3::NAN,
                },
            )
            .collect();
        match points.iter().position(|p| !p.is_finite()) {
            None => Ok(points),
            // Evaluate the first bad one again, to say what it gave.
            Some(k) => Err((
                lo + k,
                one(
                    &mut Evaluator::new(mesh, current, step, rule.frame, self.creasing),
                    lo + k,
                ),
            )),
        }
    }

    pub(super) fn apply_matched(
        &self,
        rule: &Rule,
        mesh: &mut Mesh,
        state: &mut RunState,
        m: Matches,
    ) -> Result<(), RunError> {
        let step = state.step as usize;
        let count = m.len();
        let Matches {
            current,
            parts,
            edge_ids,
        } = m;
        debug_assert!(rule.op == Op::Flip || edge_ids.is_empty());
        let fail = |m: String| rule_error(rule, step, m);

        match rule.op {
            Op::Vertex => unreachable!("vertex rules run in apply_vertex_rule"),
            Op::Flip => {
                for &e in &edge_ids {
                    mesh.edge_flip(e).map_err(|e| fail(e.message))?;
                }
                state.check_valence(mesh).map_err(fail)
            }
            Op::FaceSplit | Op::EdgeSplit | Op::BoundarySplit => {
                let per = if rule.op == Op::BoundarySplit { 1 } else { 2 };
                let after = mesh.face_count() + per * count;
                if after > self.max_faces {
                    return Err(fail(format!(
                        "this rule would make {after} faces, past the limit of {}; \
                         run fewer steps",
                        self.max_faces
                    )));
                }
                let split = state.split();
                mesh.reserve(count, 3 * count, 2 * count);
                // Splits the elements of `part`, in order, adding the
                // vertex made from each to `made`.
                let split_all = |mesh: &mut Mesh,
                                 state: &mut RunState,
                                 part: &[Elem],
                                 made: &mut Vec<VertexId>|
                 -> Result<(), RunError> {
                    let first = made.len();
                    for val in part {
                        let v = if let Some(vs) = host::face_vertices(val) {
                            let Some(f) = face_of(mesh, vs) else {
                                return Err(fail("a face to split is gone".into()));
                            };
                            if let Some((k, _)) = mesh.fan_at(f) {
                                // A polygon of five or more sides: its centre
                                // joined to every corner.
                                let p = mesh.fan_centroid(k);
                                mesh.polygon_split_with(k, p, &split)
                                    .map_err(|e| fail(e.message))?
                            } else {
                                let p = vs.iter().map(|v| mesh.position(*v)).sum::<DVec3>() / 3.0;
                                mesh.face_split_with(f, p, &split)
                                    .map_err(|e| fail(e.message))?
                            }
                        } else if let Some((p, q)) = host::edge_vertices(val) {
                            let e = edge_id(val);
                            debug_assert!({
                                let (a, b) = mesh.edge_vertices(e);
                                (a, b) == (p, q) || (a, b) == (q, p)
                            });
                            let at = (mesh.position(p) + mesh.position(q)) * 0.5;
                            mesh.edge_split_with(e, at, &split)
                                .map_err(|e| fail(e.message))?
                        } else {
                            unreachable!("a split rule matches faces and edges")
                        };
                        made.push(v);
                    }
                    if state.adaptive {
                        state.made_now.extend(&made[first..]);
                    }
                    state.current_level = made[first..]
                        .iter()
                        .map(|v| mesh.vertex_level(*v))
                        .fold(state.current_level, u32::max);
                    Ok(())
                };
                let run_step = state.step;
                let slot = rule.elem_slot as usize;
                // Evaluates the points of `matched`, whose new vertices
                // are `made`, `batch` at a time, writing each batch before
                // the next is computed; the error of the first bad one.
                let points = |mesh: &mut Mesh,
                              assign: &Ex,
                              matched: &[Elem],
                              made: &[VertexId],
                              batch: usize|
                 -> Result<(), RunError> {
                    let vslot = rule.vertex_slot.expect("an assignment names its vertex") as usize;
                    let bind = |frame: &mut [Value], k: usize| {
                        frame[slot] = Value::Elem(matched[k]);
                        frame[vslot] = Value::Elem(host::vertex(made[k]));
                    };
                    let bad = |(k, p): (usize, Result<Value, RuntimeError>)| match p {
                        Ok(Value::V3(p)) => fail(format!(
                            "new vertex {} would be at {p}, which is not finite",
                            made[k]
                        )),
                        Ok(_) => fail("the assignment did not give a point".into()),
                        Err(e) => self.runtime_error(rule, step, e),
                    };
                    for lo in (0..made.len()).step_by(batch.max(1)) {
                        let range = lo..(lo + batch).min(made.len());
                        let out = self
                            .eval_points(rule, mesh, current, run_step, assign, range, bind)
                            .map_err(bad)?;
                        for (v, p) in made[lo..].iter().zip(out) {
                            mesh.set_position(*v, p);
                        }
                    }
                    Ok(())
                };
                match &rule.assign {
                    // Each part's points right after its splits (they read
                    // nothing the later splits change), a batch at a
                    // time, and the part let go: the matches are never
                    // held whole while the mesh grows. The errors are
                    // those of splitting everything first: a bad point
                    // waits until the other splits and the valence check
                    // have passed.
                    Some(assign) if rule.points_between_splits => {
                        let mut bad = None;
                        let (mut matched, mut made) = (Vec::new(), Vec::new());
                        let mut parts = parts.into_iter().peekable();
                        while let Some(part) = parts.next() {
                            split_all(mesh, state, &part, &mut made)?;
                            matched.extend_from_slice(&part);
                            drop(part);
                            if matched.len() >= BETWEEN_SPLITS_BATCH || parts.peek().is_none() {
                                if bad.is_none() {
                                    bad =
                                        points(mesh, assign, &matched, &made, matched.len()).err();
                                }
                                matched.clear();
                                made.clear();
                            }
                        }
                        state.check_valence(mesh).map_err(fail)?;
                        bad.map_or(Ok(()), Err)
                    }
                    assign => {
                        let matched = parts.concat();
                        drop(parts);
                        // The vertex made from each matched element, in
                        // order.
                        let mut made: Vec<VertexId> = Vec::with_capacity(matched.len());
                        split_all(mesh, state, &matched, &mut made)?;
                        state.check_valence(mesh).map_err(fail)?;
                        let Some(assign) = assign else {
                            return Ok(());
                        };
                        // Where no point reads another, a batch's points
                        // are written before the next batch is computed,
                        // and only a batch is held; else all are computed
                        // first. A bad point stops the rule before its
                        // batch is written.
                        let batch = if rule.points_in_place {
                            POINT_BATCH
                        } else {
                            made.len()
                        };
                        points(mesh, assign, &matched, &made, batch)
                    }
                }
            }
        }
    }
}

fn face_of(mesh: &Mesh, vs: [VertexId; 3]) -> Option<crate::mesh::FaceId> {
    mesh.find_face(vs)
}
