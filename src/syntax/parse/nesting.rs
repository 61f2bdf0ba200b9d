//! How deeply expressions and statements nest: the limit ([`MAX_NESTING`])
//! and the depth and peak that the parser keeps under it.

use crate::syntax::span::{Diagnostic, Span};

use super::{PResult, Parser};

/// How deeply expressions and statements may nest: the height of the
/// syntax tree, counting every level that the checker and the interpreter
/// recurse through (an operator, a call, a field, a cast, a parenthesis, a
/// statement, a block). Deeper programs are refused with a message rather
/// than overflowing the stack later; a chain that the grammar nests
/// (`a = b = c`, `x ? y : x ? y : z`, `a + b + c`, `v.x.y`) counts one
/// level per link.
pub const MAX_NESTING: usize = 100;

impl<'t> Parser<'t> {
    fn too_deep<T>(&self, at: Span) -> PResult<T> {
        Err(Diagnostic::new(
            at,
            format!(
                "this is nested more than {MAX_NESTING} levels deep; split it into simpler parts"
            ),
        ))
    }

    /// Goes one level deeper, to parse the children of a node; [`ascend`]
    /// comes back. (Plain calls rather than a closure: every stack frame
    /// counts on a deep parse in a debug build.)
    ///
    /// [`ascend`]: Parser::ascend
    pub(crate) fn descend(&mut self) -> PResult<()> {
        if self.depth + 1 > MAX_NESTING {
            return self.too_deep(self.span_here());
        }
        self.depth += 1;
        self.peak = self.peak.max(self.depth);
        Ok(())
    }

    pub(crate) fn ascend(&mut self) {
        self.depth -= 1;
    }

    /// Starts measuring the deepest level that the parse which follows
    /// reaches; [`reached`] ends it with the level, given what this
    /// returned.
    ///
    /// [`reached`]: Parser::reached
    pub(super) fn measure(&mut self) -> usize {
        std::mem::replace(&mut self.peak, self.depth)
    }

    pub(super) fn reached(&mut self, outer: usize) -> usize {
        let reached = self.peak;
        self.peak = outer.max(reached);
        reached
    }

    /// A node is built around an operand whose deepest level was
    /// `reached`: everything in it moves one level down. The error points
    /// at `at`, the operator that makes the node.
    pub(super) fn wrap(&mut self, reached: usize, at: Span) -> PResult<usize> {
        if reached + 1 > MAX_NESTING {
            return self.too_deep(at);
        }
        self.peak = self.peak.max(reached + 1);
        Ok(reached + 1)
    }
}
