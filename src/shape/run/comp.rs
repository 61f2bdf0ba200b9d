//! Component splits: a shape's faces, edges or vertices as new shapes.

use std::sync::Arc;

use glam::DVec3;

use crate::lang::value::Value;
use crate::shape::geom::{self, Geometry, Scope, Selector};
use crate::shape::grammar::CompKind;
use crate::shape::COp;
use crate::syntax::span::Span;

use super::{Cur, Deriver, ShapeError, R};

impl<'g> Deriver<'g> {
    #[allow(clippy::too_many_arguments)]
    pub(super) fn comp(
        &mut self,
        n: u32,
        cur: &Cur,
        frame: &mut [Value],
        attr_base: usize,
        kind: CompKind,
        parts: &'g [(Selector, Span, Vec<COp>)],
        span: Span,
    ) -> R<()> {
        let comps: Vec<(Geometry, Scope)> = match kind {
            CompKind::Faces => {
                if cur.geom.dim < 2 {
                    return Err(ShapeError::at(
                        span,
                        format!(
                            "`comp(f)` takes a shape with faces; this one is {}D",
                            cur.geom.dim
                        ),
                    ));
                }
                geom::comp_faces(&self.points, &cur.geom, &cur.scope, Selector::All)
            }
            CompKind::Edges => {
                if cur.geom.dim < 1 {
                    return Err(ShapeError::at(
                        span,
                        "`comp(e)` takes a shape with edges; this one is a point",
                    ));
                }
                geom::comp_edges(&self.points, &cur.geom, &cur.scope)
            }
            CompKind::Vertices => geom::comp_vertices(&self.points, &cur.geom, &cur.scope),
        };
        // Each component's class: a face's by its normal in the scope.
        let classes: Vec<Selector> = comps
            .iter()
            .map(|(_, s)| {
                if kind == CompKind::Faces {
                    let z = s.axes[2];
                    let local = DVec3::new(
                        z.dot(cur.scope.axes[0]),
                        z.dot(cur.scope.axes[1]),
                        z.dot(cur.scope.axes[2]),
                    );
                    Selector::classify(local)
                } else {
                    Selector::All
                }
            })
            .collect();
        // Each component goes to the first part whose selector takes it.
        let mut to: Vec<Vec<usize>> = vec![Vec::new(); parts.len()];
        for (k, &class) in classes.iter().enumerate() {
            if let Some(p) = parts.iter().position(|(sel, _, _)| sel.takes(class)) {
                to[p].push(k);
            }
        }
        // A selector that takes nothing because an earlier part took its
        // components is fine; one the shape has no component for is an
        // error.
        for (p, (sel, at, _)) in parts.iter().enumerate() {
            if to[p].is_empty() && !classes.iter().any(|&c| sel.takes(c)) {
                let what = match kind {
                    CompKind::Faces => "face",
                    CompKind::Edges => "edge",
                    CompKind::Vertices => "vertex",
                };
                let sym = if n == u32::MAX {
                    "the axiom".to_string()
                } else {
                    format!(
                        "`{}`",
                        self.g.symbols[self.nodes[n as usize].symbol as usize]
                    )
                };
                return Err(ShapeError::at(
                    *at,
                    format!(
                        "shape {sym} has no {} {what} left for this selector ({} {what}s in all)",
                        selector_name(*sel),
                        comps.len()
                    ),
                ));
            }
        }
        let mut comps: Vec<Option<(Geometry, Scope)>> = comps.into_iter().map(Some).collect();
        for (p, ks) in to.iter().enumerate() {
            let total = ks.len() as i64;
            for (i, &k) in ks.iter().enumerate() {
                let Some((g, s)) = comps[k].take() else {
                    continue;
                };
                let mut c = Cur {
                    scope: s,
                    geom: Arc::new(g),
                    group: cur.group.clone(),
                    colour: cur.colour,
                    split: cur.split,
                    comp: (i as i64, total),
                };
                let mut f = frame.to_vec();
                self.exec(n, &parts[p].2, &mut c, &mut f, attr_base)?;
            }
        }
        Ok(())
    }
}

pub(crate) fn selector_name(s: Selector) -> &'static str {
    use Selector::*;
    match s {
        Front => "front",
        Back => "back",
        Left => "left",
        Right => "right",
        Top => "top",
        Bottom => "bottom",
        Side => "side",
        Horizontal => "horizontal",
        Vertical => "vertical",
        All => "all",
    }
}
