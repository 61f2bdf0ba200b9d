//! Phase 1 for one shape: a rule chosen and its successor run; the
//! expressions evaluated for a shape, the new shapes and the limits on
//! shapes and held faces.

use crate::lang::random::Rand48;
use crate::lang::value::Value;
use crate::shape::host::ShapeHost;
use crate::shape::X;
use crate::syntax::span::Span;

use super::exec::Made;
use super::tree::{Node, State};
use super::{mix, random_of, Cur, Deriver, ShapeError, MAX_SHAPES_VAR, R};

impl<'g> Deriver<'g> {
    /// A shape's geometry of `old` elements becomes one of `new`: refused
    /// past the face limit.
    pub(super) fn hold(&mut self, old: usize, new: usize, span: Span) -> R<()> {
        self.held = self.held.saturating_sub(old).saturating_add(new);
        if self.held > self.opts.max_faces {
            return Err(ShapeError::at(
                span,
                format!(
                    "the shapes hold {} faces, edges and points, past the limit of {}: each \
                     shape keeps its own copy of its geometry, so many children of a large \
                     mesh, or too many shapes, hold too much",
                    self.held, self.opts.max_faces
                ),
            ));
        }
        Ok(())
    }

    fn tick(&mut self, span: Span) -> R<()> {
        self.ticks = self.ticks.wrapping_add(1);
        if self.ticks.is_multiple_of(1024) {
            self.deadline.check().map_err(|m| ShapeError::at(span, m))?;
        }
        Ok(())
    }

    pub(super) fn eval(&mut self, e: &X, frame: &mut [Value], cur: &Cur, depth: u32) -> R<Value> {
        let mut host = ShapeHost::of(&cur.scope);
        host.split = cur.split;
        host.comp = cur.comp;
        host.depth = depth as i64;
        host.faces = cur.geom.face_count() as i64;
        self.interp
            .eval(&e.ex, frame, &mut self.env, &mut host)
            .map_err(|err| ShapeError::at(err.span.unwrap_or(e.span), err.message))
    }

    pub(super) fn num(&mut self, e: &X, frame: &mut [Value], cur: &Cur, depth: u32) -> R<f64> {
        let v = self.eval(e, frame, cur, depth)?.as_f64();
        if !v.is_finite() {
            return Err(ShapeError::at(
                e.span,
                format!("this is {v}, not a finite number"),
            ));
        }
        Ok(v)
    }

    pub(super) fn new_node(
        &mut self,
        parent: u32,
        symbol: u32,
        params: Vec<f64>,
        attrs: Vec<Value>,
        cur: &Cur,
        span: Span,
    ) -> R<u32> {
        if self.nodes.len() >= self.opts.max_shapes {
            return Err(ShapeError::at(
                span,
                format!(
                    "the derivation made {} shapes, the limit: does a rule never reach a \
                     terminal shape? (raise it with --max-shapes or {MAX_SHAPES_VAR})",
                    self.opts.max_shapes
                ),
            ));
        }
        let id = self.nodes.len() as u32;
        let (pkey, depth, index) = if parent == u32::MAX {
            (self.opts.seed as u64, 0, self.roots.len())
        } else {
            let p = &self.nodes[parent as usize];
            (p.key, p.depth + 1, p.children.len())
        };
        let key = mix(pkey, index as u64 + 1);
        self.hold(0, cur.geom.elements(), span)?;
        self.nodes.push(Node {
            symbol,
            params,
            attrs,
            group: cur.group.clone(),
            colour: cur.colour,
            scope: cur.scope,
            geom: cur.geom.clone(),
            parent,
            children: Vec::new(),
            key,
            depth,
            split: cur.split,
            comp: cur.comp,
            state: State::Pending,
        });
        if parent == u32::MAX {
            self.roots.push(id);
        } else {
            self.nodes[parent as usize].children.push(id);
        }
        self.pending.push_back(id);
        Ok(id)
    }

    /// Algorithm 1, steps 2 and 3, for one shape.
    pub(super) fn rewrite(&mut self, n: u32) -> R<()> {
        let g = self.g;
        let sym = self.nodes[n as usize].symbol as usize;
        let rules = &g.by_symbol[sym];
        if rules.is_empty() {
            self.nodes[n as usize].state = State::Leaf;
            return Ok(());
        }
        self.tick(g.rules[rules[0]].span)?;
        let node = &self.nodes[n as usize];
        // The shape's own random numbers.
        let key = node.key;
        self.env.random = random_of(key);
        let mut choose = Rand48::from_state(key & 0xFFFF_FFFF_FFFF);
        let cur = Cur::of(node);
        let depth = node.depth;
        let params: Vec<Value> = node.params.iter().map(|&x| Value::Float(x)).collect();
        let attrs = node.attrs.clone();
        // The applicable rules, in file order, with their probabilities.
        let mut applicable: Vec<(usize, Vec<Value>, Option<f64>)> = Vec::new();
        for &ri in rules {
            let r = &g.rules[ri];
            if r.params != params.len() {
                continue;
            }
            let mut frame = params.clone();
            frame.extend(attrs.iter().cloned());
            frame.resize(r.frame.max(frame.len()), Value::Void);
            if let Some(c) = &r.cond {
                if !self.eval(c, &mut frame, &cur, depth)?.truthy() {
                    continue;
                }
            }
            let p = match &r.prob {
                Some(e) => {
                    let p = self.num(e, &mut frame, &cur, depth)?;
                    if !(0.0..=1.0).contains(&p) {
                        return Err(ShapeError::at(
                            e.span,
                            format!("a rule's probability is between 0 and 1; this is {p}"),
                        ));
                    }
                    Some(p)
                }
                None => None,
            };
            applicable.push((ri, frame, p));
        }
        if applicable.is_empty() {
            self.nodes[n as usize].state = State::Leaf;
            return Ok(());
        }
        let chosen = if applicable.iter().all(|a| a.2.is_none()) {
            0
        } else {
            let sum: f64 = applicable.iter().map(|a| a.2.unwrap_or(0.0)).sum();
            if let Some(a) = applicable.iter().find(|a| a.2.is_none()) {
                let r = &g.rules[a.0];
                return Err(ShapeError::at(
                    r.span,
                    format!(
                        "this rule for `{}` has no probability, but another rule that applies \
                         has one: give every applicable rule a probability",
                        g.symbols[sym]
                    ),
                ));
            }
            if (sum - 1.0).abs() > 1e-9 {
                let r = &g.rules[applicable[0].0];
                return Err(ShapeError::at(
                    r.span,
                    format!(
                        "the probabilities of the {} rules that apply to `{}` sum to {sum}, not 1",
                        applicable.len(),
                        g.symbols[sym]
                    ),
                ));
            }
            let x = choose.next_f64();
            let mut acc = 0.0;
            let mut k = applicable.len() - 1;
            for (i, a) in applicable.iter().enumerate() {
                acc += a.2.unwrap_or(0.0);
                if x < acc {
                    k = i;
                    break;
                }
            }
            k
        };
        let (ri, mut frame, _) = applicable.swap_remove(chosen);
        let r = &g.rules[ri];
        let mut cur = cur;
        let base = params.len();
        self.nodes[n as usize].state = State::Expanded;
        let made = self.exec(n, &r.body, &mut cur, &mut frame, base)?;
        self.finish(n, made, cur, r.span)
    }

    /// After a successor: a shape that made no child and was neither
    /// removed nor left waiting is terminal, with the state the operations
    /// left it in.
    pub(super) fn finish(&mut self, n: u32, made: Made, cur: Cur, span: Span) -> R<()> {
        if made == Made::Nothing {
            let old = self.nodes[n as usize].geom.elements();
            self.hold(old, cur.geom.elements(), span)?;
        }
        let node = &mut self.nodes[n as usize];
        match made {
            Made::Children => node.state = State::Expanded,
            Made::Removed => node.state = State::Removed,
            Made::Waiting => node.state = State::Waiting,
            Made::Nothing => {
                node.state = State::Leaf;
                node.scope = cur.scope;
                node.geom = cur.geom;
                node.group = cur.group;
                node.colour = cur.colour;
            }
        }
        Ok(())
    }
}
