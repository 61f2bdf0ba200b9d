//! Fused built-ins: the two forms every scheme evaluates for every
//! element (`l(x) OP c`, and a fold over a one-ring with no condition or
//! a simple one) rewritten into one built-in each after checking.

use crate::lang::ir::{Ex, FoldOp, Func};
use crate::lang::value::Value;

use super::id;
use super::mesh_host::op_code;

/// Rewrites the two forms every scheme evaluates for every element into
/// fused built-ins: `l(x) OP c` and a fold over `ring(v)` whose value is
/// the member's position and whose condition is absent, `l(w) OP c`,
/// `new(w)` or `!new(w)`. Everything else is left to the interpreter.
pub fn specialise(e: &mut Ex) {
    // Children first, so that a fused condition inside a fold is seen.
    e.walk_mut(&mut |x| {
        if let Some(fused) = fused(x) {
            *x = fused;
        }
    });
}

fn host_call(e: &Ex, f: u16) -> Option<&[Ex]> {
    match e {
        Ex::Call(Func::Host(g), args, _) if *g == f => Some(args),
        _ => None,
    }
}

fn is_local(e: &Ex, slot: u16) -> bool {
    matches!(e, Ex::Local(s) if *s == slot)
}

fn int(i: i64) -> Ex {
    Ex::Const(Value::Int(i))
}

fn fused(e: &Ex) -> Option<Ex> {
    match e {
        // l(x) OP c
        Ex::Bin(op, a, b, span) => {
            let code = op_code(*op)?;
            let x = host_call(a, id::LEVEL)?;
            host_call(b, id::CURRENT)?;
            Some(Ex::Call(
                Func::Host(id::LEVEL_VS_CURRENT),
                vec![x[0].clone(), int(code)],
                *span,
            ))
        }
        Ex::Fold {
            op,
            slot,
            set,
            cond,
            value,
        } => {
            let ring = host_call(set, id::RING)?;
            if let Some((v, _)) = value {
                let p = host_call(v, id::POS)?;
                if !is_local(&p[0], *slot) {
                    return None;
                }
            }
            let filter = match cond.as_deref() {
                None => 0,
                Some(c) => {
                    if let Some(a) = host_call(c, id::NEW) {
                        if !is_local(&a[0], *slot) {
                            return None;
                        }
                        1
                    } else if let Ex::Not(n) = c {
                        let a = host_call(n, id::NEW)?;
                        if !is_local(&a[0], *slot) {
                            return None;
                        }
                        2
                    } else {
                        let a = host_call(c, id::LEVEL_VS_CURRENT)?;
                        if !is_local(&a[0], *slot) {
                            return None;
                        }
                        let Ex::Const(Value::Int(code)) = a[1] else {
                            return None;
                        };
                        10 + code
                    }
                }
            };
            let fold = match op {
                FoldOp::Sum => 0,
                FoldOp::Avg => 1,
                FoldOp::Count => 2,
            };
            Some(Ex::Call(
                Func::Host(id::RING_FOLD),
                vec![ring[0].clone(), int(fold), int(filter)],
                crate::syntax::span::Span::default(),
            ))
        }
        _ => None,
    }
}
