//! What one thread needs to evaluate a rule's expressions: the
//! interpreter on the mesh, the rule's frame, and the memo of the
//! specialised forms.

use crate::lang::eval::{Env, Interp, RuntimeError};
use crate::lang::ir::Ex;
use crate::lang::value::{Elem, Value};
use crate::mesh::Mesh;
use crate::surface::host::{self, MeshHost};

use super::Rule;

/// What one thread needs to evaluate a rule's expressions.
pub(super) struct Evaluator<'m> {
    interp: Interp<'static>,
    env: Env,
    host: MeshHost<'m>,
    pub(super) frame: Vec<Value>,
    memo: host::Memo,
}

impl<'m> host::Evaluate<'m> for Evaluator<'m> {
    fn eval(&mut self, e: &Ex) -> Result<Value, RuntimeError> {
        self.interp
            .eval(e, &mut self.frame, &mut self.env, &mut self.host)
    }

    fn host(&self) -> MeshHost<'m> {
        self.host
    }

    fn frame(&mut self) -> &mut [Value] {
        &mut self.frame
    }

    fn memo(&mut self) -> &mut host::Memo {
        &mut self.memo
    }
}

impl<'m> Evaluator<'m> {
    pub(super) fn new(
        mesh: &'m Mesh,
        current: u32,
        step: u32,
        frame: usize,
        creasing: crate::mesh::Creasing,
    ) -> Evaluator<'m> {
        Evaluator {
            interp: Interp::new(&[]),
            env: Env::with_model(Vec::new(), crate::model::default_ref()),
            host: MeshHost {
                mesh,
                current,
                step,
                creasing,
            },
            frame: vec![Value::Void; frame],
            memo: host::Memo::default(),
        }
    }

    /// Whether the element passes `rule`'s condition.
    pub(super) fn test(&mut self, rule: &Rule, val: &Elem) -> Result<bool, RuntimeError> {
        if let Some(g) = &rule.guard {
            return g.test(self, val);
        }
        self.frame[rule.elem_slot as usize] = Value::Elem(*val);
        match &rule.cond {
            Some(c) => host::Evaluate::eval(self, c).map(|v| v.truthy()),
            None => Ok(true),
        }
    }

    /// `rule`'s assignment, on the locals bound in the frame.
    pub(super) fn assign(&mut self, rule: &Rule, assign: &Ex) -> Result<Value, RuntimeError> {
        if let Some(a) = &rule.affine {
            if let Some(v) = a.eval(self)? {
                return Ok(v);
            }
        }
        host::Evaluate::eval(self, assign)
    }
}
