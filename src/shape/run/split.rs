//! Split and repeat: the layout of a split's parts along the scope and
//! the cuts that make them.

use std::sync::Arc;

use glam::DVec3;

use crate::lang::value::Value;
use crate::shape::geom::{self, Geometry};
use crate::shape::grammar::{Axis, SizeKind};
use crate::shape::{CPart, X};
use crate::syntax::span::Span;

use super::{Cur, Deriver, ShapeError, MAX_SHAPES_VAR, MAX_SPLIT_WORK, R};

impl<'g> Deriver<'g> {
    #[allow(clippy::too_many_arguments)]
    pub(super) fn split(
        &mut self,
        n: u32,
        cur: &Cur,
        frame: &mut [Value],
        attr_base: usize,
        axis: Axis,
        parts: &'g [CPart],
        repeat: bool,
        parallel: Option<&'g [X]>,
        span: Span,
    ) -> R<()> {
        let depth = if n == u32::MAX {
            0
        } else {
            self.nodes[n as usize].depth
        };
        let a = axis.index();
        let total = cur.scope.size[a];
        let mut sizes = Vec::with_capacity(parts.len());
        for p in parts {
            let s = self.num(&p.size, frame, cur, depth)?;
            if s < 0.0 {
                return Err(ShapeError::at(
                    p.span,
                    format!("a part's size is not negative; this is {s}"),
                ));
            }
            sizes.push((p.kind, s));
        }
        let layout = lay_out(&sizes, total, repeat).map_err(|m| ShapeError::at(span, m))?;
        if layout.len() > self.opts.max_shapes {
            return Err(ShapeError::at(
                span,
                format!(
                "this split makes {} parts, more than the limit of {} shapes ({MAX_SHAPES_VAR})",
                layout.len(), self.opts.max_shapes
            ),
            ));
        }
        let work = cuts_of(&layout, total).saturating_mul(cur.geom.elements());
        if work > MAX_SPLIT_WORK {
            return Err(ShapeError::at(
                span,
                format!(
                    "this split cuts a shape of {} faces at {} planes, one after another: {work} \
                     face cuts, more than the limit of {MAX_SPLIT_WORK}; split a coarser shape, \
                     or into fewer parts",
                    cur.geom.elements(),
                    cuts_of(&layout, total)
                ),
            ));
        }
        let mut flags = Vec::new();
        if let Some(fl) = parallel {
            for f in fl {
                flags.push(self.eval(f, frame, cur, depth)?.truthy());
            }
        }
        // The cut planes: every part's end strictly inside the scope, once.
        // A part of no length gets no geometry; a remainder after the last
        // part is cut off.
        let axis_dir = cur.scope.axes[a];
        let tol = 1e-9 * total.abs().max(1.0);
        let mut cuts: Vec<f64> = Vec::with_capacity(layout.len());
        let mut at = 0.0;
        let mut spans = Vec::with_capacity(layout.len());
        for (_, len) in &layout {
            let (start, end) = (at, at + len);
            spans.push((start, end));
            at = end;
            if end > tol && end < total - tol && cuts.last().is_none_or(|&c| end > c + tol) {
                cuts.push(end);
            }
        }
        let first = self.next_cut;
        self.next_cut += cuts.len() as u32;
        if !cuts.is_empty() {
            let planes: Vec<(DVec3, f64)> = cuts
                .iter()
                .map(|&c| geom::plane_of(cur.scope.origin, axis_dir, c))
                .collect();
            for k in geom::seams_of(&cur.geom) {
                self.seam_planes
                    .entry(k)
                    .or_default()
                    .extend_from_slice(&planes);
            }
        }
        let pieces = geom::split(
            &mut self.points,
            &cur.geom,
            cur.scope.origin,
            axis_dir,
            &cuts,
            first,
        )
        .map_err(|m| ShapeError::at(span, m))?;
        // Piece k lies between cut k - 1 and cut k.
        let piece_of = |start: f64, end: f64| -> Option<usize> {
            if end - start <= tol {
                return None;
            }
            let mid = 0.5 * (start + end);
            Some(cuts.iter().take_while(|&&c| c < mid).count())
        };
        let mut taken: Vec<Option<Geometry>> = pieces.into_iter().map(Some).collect();
        let dim = cur.geom.dim;
        if parallel.is_some() {
            // Soft connectivity: flag i joins parts i and i + 1 (in a
            // repeat, the flags repeat with the pattern). A cut between
            // parts that are not soft-connected is loose.
            for i in 0..layout.len().saturating_sub(1) {
                let soft = if flags.is_empty() {
                    false
                } else {
                    flags[i % flags.len()]
                };
                let end = spans[i].1;
                if let Some(k) = cuts.iter().position(|&c| (c - end).abs() <= tol) {
                    if !soft {
                        self.loose.insert(first + k as u32);
                    }
                }
            }
        }
        let count = layout.len() as i64;
        let mut offset = 0.0;
        for (i, (pi, len)) in layout.iter().enumerate() {
            let (start, end) = spans[i];
            let g = match piece_of(start, end) {
                Some(k) => taken
                    .get_mut(k)
                    .and_then(Option::take)
                    .unwrap_or_else(|| Geometry::empty(dim)),
                None => Geometry::empty(dim),
            };
            let mut scope = cur.scope;
            scope.origin += axis_dir * offset;
            scope.size[a] = *len;
            offset += len;
            let mut c = Cur {
                scope,
                geom: Arc::new(g),
                group: cur.group.clone(),
                colour: cur.colour,
                split: (i as i64, count),
                comp: cur.comp,
            };
            let mut f = frame.to_vec();
            let made = self.exec(n, &parts[*pi].body, &mut c, &mut f, attr_base)?;
            let _ = made;
        }
        Ok(())
    }
}

/// The number of planes a split with this layout cuts at (at most): the
/// part ends strictly inside the scope.
fn cuts_of(layout: &[(usize, f64)], total: f64) -> usize {
    let mut at = 0.0;
    let mut n = 0usize;
    for (_, len) in layout {
        at += len;
        if at < total {
            n += 1;
        }
    }
    n
}

/// The sizes of a split's parts along a scope of length `total`: (part,
/// length) in order. Absolute sizes are kept, relative ones are fractions
/// of `total`, floating ones share what is left in proportion to their
/// sizes. A repeat lays its pattern as many times as fits: with floating
/// parts, round(total / pattern) times (at least once) stretched to fill;
/// without, floor(total / pattern) times, the rest cut off.
pub(crate) fn lay_out(
    sizes: &[(SizeKind, f64)],
    total: f64,
    repeat: bool,
) -> Result<Vec<(usize, f64)>, String> {
    let tol = 1e-9 * total.abs().max(1.0);
    let fixed = |s: &(SizeKind, f64)| match s.0 {
        SizeKind::Absolute => s.1,
        SizeKind::Relative => s.1 * total,
        SizeKind::Floating => 0.0,
    };
    let fixed_sum: f64 = sizes.iter().map(fixed).sum();
    let float_sum: f64 = sizes
        .iter()
        .filter(|s| s.0 == SizeKind::Floating)
        .map(|s| s.1)
        .sum();
    let has_float = sizes.iter().any(|s| s.0 == SizeKind::Floating);
    if !repeat {
        if fixed_sum > total + tol {
            return Err(format!(
                "the split's fixed sizes add up to {fixed_sum}, more than the scope's {total}"
            ));
        }
        let left = (total - fixed_sum).max(0.0);
        return Ok(sizes
            .iter()
            .enumerate()
            .map(|(i, s)| {
                let len = match s.0 {
                    SizeKind::Floating if float_sum > 0.0 => left * s.1 / float_sum,
                    SizeKind::Floating => {
                        left / sizes.iter().filter(|s| s.0 == SizeKind::Floating).count() as f64
                    }
                    _ => fixed(s),
                };
                (i, len)
            })
            .collect());
    }
    let pattern = fixed_sum + float_sum;
    if pattern <= 0.0 {
        return Err("a repeated pattern has a length above zero".into());
    }
    let times = if has_float {
        (total / pattern).round().max(1.0)
    } else {
        ((total + tol) / pattern).floor()
    };
    if times > 1e7 {
        return Err(format!(
            "this repeat would lay its pattern {} times (a pattern of {} in {}); at most 1e7",
            geom::show(times),
            geom::show(pattern),
            geom::show(total)
        ));
    }
    let times = times as usize;
    if has_float && fixed_sum * times as f64 > total + tol {
        return Err(format!(
            "the repeat's fixed sizes add up to {} in {times} repetitions, more than the scope's {total}",
            fixed_sum * times as f64
        ));
    }
    let left = (total - fixed_sum * times as f64).max(0.0) / times as f64;
    let mut out = Vec::with_capacity(times * sizes.len());
    for _ in 0..times {
        for (i, s) in sizes.iter().enumerate() {
            let len = match s.0 {
                SizeKind::Floating => left * s.1 / float_sum,
                _ => fixed(s),
            };
            out.push((i, len));
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layout_matches_hand_sums() {
        use SizeKind::*;
        // 10 = 2 + 1 (a tenth) + 7 shared 1 : 3.
        let l = lay_out(
            &[
                (Absolute, 2.0),
                (Floating, 1.0),
                (Floating, 3.0),
                (Relative, 0.1),
            ],
            10.0,
            false,
        )
        .unwrap();
        let lens: Vec<f64> = l.iter().map(|x| x.1).collect();
        assert_eq!(lens, vec![2.0, 1.75, 5.25, 1.0]);
        assert!(lay_out(&[(Absolute, 6.0), (Absolute, 6.0)], 10.0, false).is_err());
        // A repeat of about 2 in 7: round(3.5) = 4 parts of 1.75.
        let l = lay_out(&[(Floating, 2.0)], 7.0, true).unwrap();
        assert_eq!(l.iter().map(|x| x.1).collect::<Vec<_>>(), vec![1.75; 4]);
    }
}
