//! What a rule matches when it starts: the matched elements, tested in
//! parallel by ranges of ids, and the values elements take as a rule's
//! predecessor.

use rayon::prelude::*;

use crate::lang::eval::RuntimeError;
use crate::lang::value::Elem;
use crate::mesh::{EdgeId, Mesh, VertexId};
use crate::surface::grammar::{Op, VertexContext};
use crate::surface::host;

use super::evaluator::Evaluator;
use super::{Grammar, Protected, Rule, RunState, CHUNK};

/// The elements a rule matched when it started.
pub(super) struct Matches {
    pub(super) current: u32,
    /// The matched elements as values, in order, in parts (one for each
    /// range of ids tested), so that a split rule can let each part go
    /// once it is applied; none for a flip rule, which needs only their
    /// ids; an edge's value holds its id.
    pub(super) parts: Vec<Vec<Elem>>,
    /// A flip rule's matched edges (empty for other rules).
    pub(super) edge_ids: Vec<crate::mesh::EdgeId>,
}

impl Matches {
    /// The number of matched elements.
    pub(super) fn len(&self) -> usize {
        self.parts.iter().map(Vec::len).sum()
    }

    /// The matched elements, in order.
    pub(super) fn vals(&self) -> impl Iterator<Item = &Elem> + '_ {
        self.parts.iter().flatten()
    }
}

impl Grammar {
    /// What `rule` applies to, fixed when it starts: the matched elements
    /// and, for edge rules, their ids. Edges keep their ids through the
    /// splits and flips of other edges, so the ids stay valid while the
    /// rule runs.
    pub(super) fn find_matches(
        &self,
        rule: &Rule,
        mesh: &Mesh,
        state: &RunState,
    ) -> Result<Matches, RuntimeError> {
        self.find_matches_with(rule, None, mesh, state)
            .map(|m| m.0)
            .map_err(|(_, e)| e)
    }

    /// What `rule` applies to, and `other`, an edge rule for the other
    /// context (boundary or interior), tested in the same pass over the
    /// edges: both fixed when the first starts. An error says whether it
    /// came from `other`'s condition.
    pub(super) fn find_matches_with(
        &self,
        rule: &Rule,
        other: Option<&Rule>,
        mesh: &Mesh,
        state: &RunState,
    ) -> Result<(Matches, Matches), (bool, RuntimeError)> {
        // `c`, kept up to date by `apply_all` as rules make vertices.
        let current = state.current_level;
        // A crease rule on a mesh without creases matches nothing.
        if other.is_none()
            && !mesh.has_sharpness_flag()
            && rule
                .guard
                .as_ref()
                .is_some_and(|g| g.never_without_creases())
        {
            let none = || Matches {
                current,
                parts: Vec::new(),
                edge_ids: Vec::new(),
            };
            return Ok((none(), none()));
        }
        let step = state.step;
        // The ids to test: every slot, or a work list where the run knows
        // that nothing else can match.
        let list = state.work_list(rule, mesh);
        let slots = match (&list, rule.op) {
            (Some(l), _) => l.len(),
            (None, Op::FaceSplit) => mesh.f_alive.len(),
            (None, Op::EdgeSplit | Op::BoundarySplit | Op::Flip) => mesh.e_alive.len(),
            (None, Op::Vertex) => mesh.v_alive.len(),
        };
        let id_at = |i: u32| list.as_ref().map_or(i, |l| l[i as usize]);
        let frame_len = rule.frame.max(other.map_or(0, |o| o.frame));
        // What a protection leaves out is never tested, so the guards and
        // every specialised path see the same elements.
        let protect = state.protect.as_ref();
        type Part = (Vec<Elem>, Vec<crate::mesh::EdgeId>);
        // Conditions are pure, so ranges of ids are tested in parallel,
        // each by a plain loop, and the matches joined in id order.
        let ranges: Vec<(u32, u32)> = (0..slots.div_ceil(CHUNK))
            .map(|k| ((k * CHUNK) as u32, (((k + 1) * CHUNK).min(slots)) as u32))
            .collect();
        let parts: Vec<Result<(Part, Part), (bool, RuntimeError)>> = ranges
            .into_par_iter()
            .map(|(lo, hi)| {
                let mut ev = Evaluator::new(mesh, current, step, frame_len, self.creasing);
                let (mut a, mut b): (Part, Part) = Default::default();
                match rule.op {
                    Op::FaceSplit => {
                        for f in (lo..hi).map(|i| crate::mesh::FaceId(id_at(i))) {
                            // A polygon's fan is matched once, by its first
                            // triangle: its split takes the polygon whole.
                            if mesh.is_face(f)
                                && protect.is_none_or(|p| p.face_free(mesh, f))
                                && mesh.fan_at(f).is_none_or(|(_, first)| first)
                            {
                                let hs = mesh.face_halfedges(f);
                                let val = host::face(
                                    hs.map(|h| mesh.from(h)),
                                    mesh.face_level(f),
                                    hs.iter().any(|h| mesh.face(h.twin()).is_none()),
                                    hs.iter().any(|h| mesh.is_block_edge(h.edge())),
                                );
                                if ev.test(rule, &val).map_err(|e| (false, e))? {
                                    a.0.push(val);
                                }
                            }
                        }
                    }
                    Op::EdgeSplit | Op::BoundarySplit | Op::Flip => {
                        let want_boundary = rule.op == Op::BoundarySplit;
                        for e in (lo..hi).map(|i| crate::mesh::EdgeId(id_at(i))) {
                            if !mesh.is_edge(e) || protect.is_some_and(|p| !p.edge_free(mesh, e)) {
                                continue;
                            }
                            let on_boundary = mesh.is_boundary_edge(e);
                            let (r, out) = if on_boundary == want_boundary {
                                (rule, &mut a)
                            } else if let Some(o) = other {
                                (o, &mut b)
                            } else {
                                continue;
                            };
                            // An adaptive split rule sees the diagonals of
                            // diamonds, complete or not, as blocks' internal
                            // edges, and nothing else.
                            let block = if state.adaptive && r.op != Op::Flip {
                                if !mesh.is_refinement_edge(e) {
                                    continue;
                                }
                                true
                            } else {
                                mesh.is_block_edge(e)
                            };
                            let val = edge_value(mesh, e, block);
                            if ev.test(r, &val).map_err(|e| (!std::ptr::eq(r, rule), e))? {
                                // A flip needs the edge alone; a split's
                                // value holds the id.
                                if r.op == Op::Flip {
                                    out.1.push(e);
                                } else {
                                    out.0.push(val);
                                }
                            }
                        }
                    }
                    Op::Vertex => {
                        for v in (lo..hi).map(|i| VertexId(id_at(i))) {
                            let Some(ok) = vertex_candidate(mesh, v, protect, rule) else {
                                continue;
                            };
                            let val = host::vertex(v);
                            if ok && ev.test(rule, &val).map_err(|e| (false, e))? {
                                a.0.push(val);
                            }
                        }
                    }
                }
                Ok((a, b))
            })
            .collect();
        let parts = parts.into_iter().collect::<Result<Vec<_>, _>>()?;
        let (mut a, mut b) = (Vec::new(), Vec::new());
        let (mut a_ids, mut b_ids) = (Vec::new(), Vec::new());
        for ((av, ai), (bv, bi)) in parts {
            a.push(av);
            b.push(bv);
            a_ids.push(ai);
            b_ids.push(bi);
        }
        let join = |parts: Vec<Vec<Elem>>, ids: Vec<Vec<EdgeId>>| Matches {
            current,
            parts: parts.into_iter().filter(|p| !p.is_empty()).collect(),
            edge_ids: ids.concat(),
        };
        Ok((join(a, a_ids), join(b, b_ids)))
    }
}

/// The id of a matched edge's value.
/// Whether vertex `v` is one a vertex rule looks at (alive, on an edge,
/// not protected): `None` when it is not, else whether the rule's context
/// (`| boundary`, `| interior`) holds there; the guard is tested after.
pub(super) fn vertex_candidate(
    mesh: &Mesh,
    v: VertexId,
    protect: Option<&Protected>,
    rule: &Rule,
) -> Option<bool> {
    if !mesh.is_vertex(v)
        || mesh.outgoing(v).is_none()
        || protect.is_some_and(|p| !p.vertex_free(v))
    {
        return None;
    }
    Some(match rule.context {
        VertexContext::Any => true,
        VertexContext::Boundary => mesh.is_boundary_vertex(v),
        VertexContext::Interior => !mesh.is_boundary_vertex(v),
    })
}

pub(super) fn edge_id(val: &Elem) -> EdgeId {
    host::edge_id(val).expect("an edge value")
}

/// An edge as a rule's value: its ends (a boundary edge runs the way its
/// face does), level and marks, `block` the block mark it shows.
pub(super) fn edge_value(mesh: &Mesh, e: EdgeId, block: bool) -> Elem {
    let h = e.halfedge();
    let h = if mesh.face(h).is_none() { h.twin() } else { h };
    host::edge(
        mesh.from(h),
        mesh.to(h),
        mesh.edge_level(e),
        mesh.is_boundary_edge(e),
        block,
        mesh.is_transversal_edge(e),
        mesh.is_sharp_edge(e),
        e,
    )
}
