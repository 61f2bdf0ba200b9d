//! Adaptive 4-8 refinement (`adaptive;`): the 4-8 mesh a run starts on,
//! and the rounds of splits that split the coarser neighbours of a
//! selected block first.

use crate::lang::value::Elem;
use crate::mesh::{EdgeId, Mesh};
use crate::surface::grammar::Op;

use super::matching::{edge_id, edge_value, Matches};
use super::{Grammar, Rule, RunError, RunState};

impl Grammar {
    /// Adaptive 4-8 refinement: `rule` (and `other`, the split rule of the
    /// other context written next to it) matched `a` (and `b`) when it
    /// started. A selected edge whose diamond is incomplete, because the
    /// face across it is still half of a coarser block, waits until that
    /// block's internal edge is split, which may wait in turn (the forced
    /// splits of 4-8 and ROAM hierarchies). So the splits go in rounds:
    /// each splits every complete diamond that is selected or needed, in
    /// id order, interior edges by the interior rule and boundary edges by
    /// the boundary rule, as written; their new vertices get the rule's
    /// assignment before the next round, which may read them. Where every
    /// diamond is selected and complete (uniform refinement), there is one
    /// round, and it does what the rules do without `adaptive;`.
    pub(super) fn apply_adaptive(
        &self,
        rule: &Rule,
        other: Option<&Rule>,
        mesh: &mut Mesh,
        state: &mut RunState,
        a: Matches,
        b: Matches,
    ) -> Result<(), RunError> {
        let step = state.step as usize;
        let current = a.current;
        let fail = |r: &Rule, m: String| RunError {
            span: Some(r.span),
            message: format!("at step {step}, rule `{}`: {m}", r.text),
        };
        let rules: Vec<&Rule> = std::iter::once(rule).chain(other).collect();
        let rule_for = |boundary: bool| {
            let want = if boundary {
                Op::BoundarySplit
            } else {
                Op::EdgeSplit
            };
            rules.iter().position(|r| r.op == want)
        };
        // The values the selected edges had when the rule started.
        let mut selected: std::collections::HashMap<EdgeId, Elem> =
            a.vals().chain(b.vals()).map(|v| (edge_id(v), *v)).collect();
        let mut todo: Vec<EdgeId> = a.vals().chain(b.vals()).map(edge_id).collect();
        todo.sort_unstable();
        while !todo.is_empty() {
            if let Err(m) = crate::deadline::check(state.deadline) {
                return Err(fail(rule, m));
            }
            // The complete diamonds among the edges wanted, and the
            // blocking edges of the others, followed down to complete ones.
            let mut now: Vec<EdgeId> = Vec::new();
            let mut later: Vec<EdgeId> = Vec::new();
            let mut seen = std::collections::HashSet::new();
            let mut stack: Vec<EdgeId> = todo.iter().rev().copied().collect();
            while let Some(e) = stack.pop() {
                if !seen.insert(e) {
                    continue;
                }
                match mesh.bisection_blocker(e) {
                    None => now.push(e),
                    Some(d) => {
                        later.push(e);
                        stack.push(d);
                    }
                }
            }
            if now.is_empty() {
                let (p, q) = mesh.edge_vertices(todo[0]);
                return Err(fail(
                    rule,
                    format!(
                        "the edge between vertices {p} and {q} is selected, but no diamond it \
                         waits for can be split: the blocks are not those of a 4-8 mesh"
                    ),
                ));
            }
            now.sort_unstable();
            later.sort_unstable();
            let mut per_rule: Vec<Vec<EdgeId>> = vec![Vec::new(); rules.len()];
            for &e in &now {
                let boundary = mesh.is_boundary_edge(e);
                let Some(k) = rule_for(boundary) else {
                    let (p, q) = mesh.edge_vertices(e);
                    return Err(fail(
                        rule,
                        format!(
                            "a selected block needs the {} edge between vertices {p} and {q} \
                             split first, but no {} split rule is written next to this one",
                            if boundary { "boundary" } else { "interior" },
                            if boundary { "boundary" } else { "interior" },
                        ),
                    ));
                };
                if let Some(p) = state.protect.as_ref() {
                    if !p.edge_free(mesh, e) {
                        let (p, q) = mesh.edge_vertices(e);
                        return Err(fail(
                            rules[k],
                            format!(
                                "the edge between vertices {p} and {q} must be split, but it \
                                 is protected"
                            ),
                        ));
                    }
                }
                per_rule[k].push(e);
            }
            for (k, edges) in per_rule.into_iter().enumerate() {
                if edges.is_empty() {
                    continue;
                }
                let vals: Vec<Elem> = edges
                    .iter()
                    .map(|e| {
                        selected
                            .remove(e)
                            .unwrap_or_else(|| edge_value(mesh, *e, true))
                    })
                    .collect();
                self.apply_matched(
                    rules[k],
                    mesh,
                    state,
                    Matches {
                        current,
                        parts: vec![vals],
                        edge_ids: Vec::new(),
                    },
                )?;
            }
            todo = later;
        }
        Ok(())
    }
}

/// An adaptive run starts on a 4-8 mesh: every face has exactly one edge
/// that is a block's internal edge (so every face is half of a block,
/// or of a boundary half-block), and vertices are numbered in the order
/// they were made ([`Mesh::refinement_edge`] reads the newest vertex).
pub(super) fn check_adaptive_start(mesh: &Mesh) -> Result<(), String> {
    for f in mesh.faces() {
        let marked = mesh
            .face_edges(f)
            .iter()
            .filter(|&&e| mesh.is_block_edge(e))
            .count();
        if marked != 1 {
            let [a, b, c] = mesh.face_vertices(f).map(|v| v.index() + 1);
            return Err(format!(
                "adaptive 4-8 refinement needs every triangle to be half of exactly one basic \
                 block, but the triangle on vertices {a}, {b} and {c} has {marked} internal \
                 edges of blocks"
            ));
        }
    }
    if mesh.reuses_vertex_slots() {
        return Err(
            "adaptive 4-8 refinement needs vertices numbered in the order they \
                    were made, but this mesh has vertex slots freed for reuse"
                .into(),
        );
    }
    Ok(())
}
