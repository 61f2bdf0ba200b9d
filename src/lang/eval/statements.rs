//! Statements: expressions, initialisations, `if`, loops, blocks,
//! `produce`, `return`, `switch`, `forall` and set edits.

use crate::syntax::ast::SetEditOp;
use crate::syntax::span::Span;

use super::super::ir::*;
use super::super::value::Value;
use super::{rt, Cx, Flow, Interp, DEADLINE_EVERY, R};

impl<'p> Interp<'p> {
    pub(super) fn stmt(&mut self, s: &St, cx: &mut Cx) -> R<Flow> {
        match s {
            St::Expr(e) => {
                self.expr(e, cx)?;
                Ok(Flow::Normal)
            }
            St::Init(slot, e) => {
                let v = self.expr(e, cx)?;
                cx.frame[*slot as usize] = v;
                Ok(Flow::Normal)
            }
            St::If(c, t, e) => {
                if self.expr(c, cx)?.truthy() {
                    self.stmt(t, cx)
                } else if let Some(e) = e {
                    self.stmt(e, cx)
                } else {
                    Ok(Flow::Normal)
                }
            }
            St::Loop {
                cond,
                body,
                step,
                test_after,
                span,
            } => {
                let mut first = true;
                loop {
                    if !(first && *test_after) {
                        if let Some(c) = cond {
                            if !self.expr(c, cx)?.truthy() {
                                break;
                            }
                        }
                    }
                    first = false;
                    if self.fuel == 0 {
                        return Err(rt(
                            Some(*span),
                            format!("a loop ran more than {} iterations in one body; is its condition ever false?", self.loop_limit),
                        ));
                    }
                    self.fuel -= 1;
                    self.ticks = self.ticks.wrapping_add(1);
                    if self.ticks.is_multiple_of(DEADLINE_EVERY) {
                        if let Err(m) = crate::deadline::check(self.deadline) {
                            return Err(rt(Some(*span), m));
                        }
                    }
                    match self.stmt(body, cx)? {
                        Flow::Break => break,
                        Flow::Normal | Flow::Continue => {}
                        f => return Ok(f),
                    }
                    if let Some(st) = step {
                        self.expr(st, cx)?;
                    }
                }
                Ok(Flow::Normal)
            }
            St::Block(b) => {
                for s in b {
                    match self.stmt(s, cx)? {
                        Flow::Normal => {}
                        f => return Ok(f),
                    }
                }
                Ok(Flow::Normal)
            }
            St::Produce { modules, last } => {
                self.produce(modules, cx)?;
                Ok(if *last { Flow::Produced } else { Flow::Normal })
            }
            St::Return => Ok(Flow::Return),
            St::ReturnValue(e) => {
                let v = self.expr(e, cx)?;
                self.ret = Some(v);
                Ok(Flow::Return)
            }
            St::Break => Ok(Flow::Break),
            St::Continue => Ok(Flow::Continue),
            St::Switch {
                value,
                cases,
                default,
                body,
            } => self.switch(value, cases, *default, body, cx),
            St::ForAll {
                slot,
                set,
                body,
                span,
            } => self.for_all(*slot, set, body, *span, cx),
            St::SetEdit { place, op, elem } => {
                let e = self.expr(elem, cx)?;
                self.set_edit(place, *op, e, cx)?;
                Ok(Flow::Normal)
            }
        }
    }

    /// `forall x in S`: the members the host lists when the loop starts,
    /// one at a time in local `slot`. Out of `stmt`, so that its frame
    /// stays small.
    #[inline(never)]
    fn for_all(&mut self, slot: u16, set: &Ex, body: &St, span: Span, cx: &mut Cx) -> R<Flow> {
        let s = self.expr(set, cx)?;
        let mut members = self.member_lists.pop().unwrap_or_default();
        members.clear();
        cx.host.members(&s, &mut members);
        let mut flow = Flow::Normal;
        for m in members.drain(..) {
            if self.fuel == 0 {
                return Err(rt(
                    Some(span),
                    format!(
                        "loops ran more than {} iterations in one body",
                        self.loop_limit
                    ),
                ));
            }
            self.fuel -= 1;
            self.ticks = self.ticks.wrapping_add(1);
            if self.ticks.is_multiple_of(DEADLINE_EVERY) {
                if let Err(m) = crate::deadline::check(self.deadline) {
                    return Err(rt(Some(span), m));
                }
            }
            cx.frame[slot as usize] = m;
            match self.stmt(body, cx)? {
                Flow::Break => break,
                Flow::Normal | Flow::Continue => {}
                f => {
                    flow = f;
                    break;
                }
            }
        }
        members.clear();
        self.member_lists.push(members);
        Ok(flow)
    }

    /// `add`, `remove`, `merge` on the set at `place`: in place when the
    /// place is a variable, so that a set held once is never copied.
    #[inline(never)]
    fn set_edit(&mut self, place: &Place, op: SetEditOp, elem: Value, cx: &mut Cx) -> R<()> {
        fn edit(set: &mut Value, op: SetEditOp, elem: &Value) {
            let Value::Set(s) = set else { return };
            let s = std::sync::Arc::make_mut(s);
            match (op, elem) {
                (SetEditOp::Add, Value::Elem(e)) => {
                    s.insert(e.ids[0]);
                }
                (SetEditOp::Remove, Value::Elem(e)) => {
                    s.remove(e.ids[0]);
                }
                (SetEditOp::Merge, Value::Set(t)) => s.merge(t),
                _ => {}
            }
        }
        if place.path.is_empty() {
            let root = if place.global {
                &mut cx.env.globals[place.slot as usize]
            } else {
                &mut cx.frame[place.slot as usize]
            };
            edit(root, op, &elem);
            return Ok(());
        }
        let mut v = self.load(place, cx)?;
        edit(&mut v, op, &elem);
        self.store(place, v, cx)
    }

    /// Runs a `switch`'s body from the label of its value's; a `break`
    /// ends it. Out of `stmt`, so that its frame stays small.
    #[inline(never)]
    fn switch(
        &mut self,
        value: &Ex,
        cases: &[(i64, u32)],
        default: Option<u32>,
        body: &[St],
        cx: &mut Cx,
    ) -> R<Flow> {
        let v = self.expr(value, cx)?.as_i64();
        let start = match cases.binary_search_by_key(&v, |c| c.0) {
            Ok(k) => Some(cases[k].1),
            Err(_) => default,
        };
        if let Some(start) = start {
            for s in &body[start as usize..] {
                match self.stmt(s, cx)? {
                    Flow::Normal => {}
                    Flow::Break => break,
                    f => return Ok(f),
                }
            }
        }
        Ok(Flow::Normal)
    }

    pub(super) fn produce(&mut self, modules: &[Succ], cx: &mut Cx) -> R<()> {
        for m in modules {
            let base = self.scratch.len();
            for (k, a) in m.args.iter().enumerate() {
                let v = self.expr(a, cx)?;
                if v.is_non_finite() {
                    self.scratch.truncate(base);
                    return Err(rt(
                        Some(m.span),
                        format!(
                            "parameter {} of this successor module is {v}; NaN and infinity are not allowed in a word",
                            k + 1
                        ),
                    ));
                }
                self.scratch.push(v);
            }
            cx.sink.emit(m.sym, &self.scratch[base..]);
            self.scratch.truncate(base);
        }
        if cx.sink.full() {
            return Err(rt(
                modules.first().map(|m| m.span),
                "this successor takes the word past its limit",
            ));
        }
        Ok(())
    }
}
