//! Calls of user-defined functions: a frame of their own, parameters
//! passed by reference written back, limits on depth and frame size, and
//! a new stack segment when the stack runs low.

use crate::syntax::span::Span;

use super::super::ir::*;
use super::super::value::{Ty, Value};
use super::{
    rt, Cx, Env, Flow, Host, Interp, NoSink, DEADLINE_EVERY, MAX_CALL_DEPTH, MAX_FRAME_VALUES, R,
    SEGMENT_MARGIN, SEGMENT_STACK,
};

impl<'p> Interp<'p> {
    /// A call of a user-defined function: the arguments go into a new
    /// frame, the body runs, parameters passed by reference are written
    /// back.
    #[inline(never)]
    pub(super) fn call_user(
        &mut self,
        id: u16,
        args: &[Ex],
        back: &[(u16, Place)],
        span: Span,
        cx: &mut Cx,
    ) -> R<Value> {
        let funcs = self.funcs;
        let f = &funcs[id as usize];
        // Frames are reused: a call allocates only when it goes deeper
        // than any before it.
        let mut frame = self.frames.pop().unwrap_or_default();
        frame.clear();
        frame.resize(f.frame_size.max(args.len()), Value::Void);
        let r = self.call_in(f, args, back, span, cx, &mut frame);
        frame.clear();
        self.frames.push(frame);
        r
    }

    /// [`Interp::call_user`] on the frame it got.
    fn call_in(
        &mut self,
        f: &'p Function,
        args: &[Ex],
        back: &[(u16, Place)],
        span: Span,
        cx: &mut Cx,
        frame: &mut [Value],
    ) -> R<Value> {
        for (slot, a) in frame.iter_mut().zip(args) {
            *slot = self.expr(a, cx)?;
        }
        if self.calls >= MAX_CALL_DEPTH {
            return Err(rt(
                Some(span),
                format!(
                    "calls of functions nest more than {MAX_CALL_DEPTH} deep here (a recursion that does not end?), calling `{}`",
                    f.name
                ),
            ));
        }
        // A recursion without loops looks at the deadline too.
        self.ticks = self.ticks.wrapping_add(1);
        if self.ticks.is_multiple_of(DEADLINE_EVERY) {
            if let Err(m) = crate::deadline::check(self.deadline) {
                return Err(rt(Some(span), m));
            }
        }
        let values = frame[..args.len()]
            .iter()
            .fold(f.frame_values, |n, v| n.saturating_add(value_count(v)));
        if self.frame_values.saturating_add(values) > MAX_FRAME_VALUES {
            return Err(rt(
                Some(span),
                format!(
                    "the calls of functions in progress would hold more than {MAX_FRAME_VALUES} \
                     values (arguments and local arrays; an array passed is copied), calling `{}`",
                    f.name
                ),
            ));
        }
        self.calls += 1;
        self.frame_values += values;
        let r = self.invoke(f, frame, cx.env, &mut *cx.host, span);
        self.frame_values -= values;
        self.calls -= 1;
        let v = r?;
        for (k, place) in back {
            let value = std::mem::replace(&mut frame[*k as usize], Value::Void);
            // What the function wrote into a declared `char` array of the
            // caller's (through a `char *` parameter) must fit there.
            if let Some(m) = place
                .chars
                .as_ref()
                .and_then(|c| c.overflow(&format!("`{}`", f.name), &value))
            {
                return Err(rt(Some(span), m));
            }
            self.store(place, value, cx)?;
        }
        Ok(v)
    }

    /// Runs function `f`'s body on `frame`, on a new stack segment when
    /// this one is used up.
    #[inline(never)]
    fn invoke(
        &mut self,
        f: &'p Function,
        frame: &mut [Value],
        env: &mut Env,
        host: &mut (dyn Host + Send),
        span: Span,
    ) -> R<Value> {
        let here = stack_address();
        if self.stack_base == 0 {
            self.stack_base = here;
        }
        if self.stack_base.abs_diff(here) > self.stack_room {
            let saved = (self.stack_base, self.stack_room);
            let spawned = std::thread::scope(|s| {
                std::thread::Builder::new()
                    .name("subgram-calls".into())
                    .stack_size(SEGMENT_STACK)
                    .spawn_scoped(s, || {
                        self.stack_base = 0;
                        self.stack_room = SEGMENT_STACK - SEGMENT_MARGIN;
                        self.run_function(f, frame, env, host)
                    })
                    .map(|h| h.join())
            });
            (self.stack_base, self.stack_room) = saved;
            return match spawned {
                Ok(Ok(r)) => r,
                Ok(Err(panic)) => std::panic::resume_unwind(panic),
                Err(e) => Err(rt(
                    Some(span),
                    format!("no stack for deeper function calls: {e}"),
                )),
            };
        }
        self.run_function(f, frame, env, host)
    }

    #[inline(never)]
    fn run_function(
        &mut self,
        f: &'p Function,
        frame: &mut [Value],
        env: &mut Env,
        host: &mut (dyn Host + Send),
    ) -> R<Value> {
        let mut sink = NoSink;
        let mut cx = Cx {
            frame,
            env,
            host,
            sink: &mut sink,
        };
        self.ret = None;
        for s in &f.body {
            match self.stmt(s, &mut cx)? {
                Flow::Normal => {}
                _ => break,
            }
        }
        if let Some(this) = &f.this_back {
            cx.frame[0] = self.expr(this, &mut cx)?;
        }
        if let Some(r) = &f.result {
            return self.expr(r, &mut cx);
        }
        match self.ret.take() {
            Some(v) => Ok(v),
            None if f.ret == Ty::Void => Ok(Value::Void),
            None => Err(rt(
                Some(f.end),
                format!(
                    "`{}` reached its end without a `return`; it must return a value",
                    f.name
                ),
            )),
        }
    }
}

/// The address of a local variable: how deep the stack is here.
#[inline(never)]
fn stack_address() -> usize {
    let marker = 0u8;
    std::hint::black_box(&marker) as *const u8 as usize
}

/// How many numbers a value holds: an array or struct counts its
/// elements, all the way down.
fn value_count(v: &Value) -> usize {
    match v {
        Value::Struct(fs) => fs.iter().fold(1, |n, f| n.saturating_add(value_count(f))),
        _ => 1,
    }
}
