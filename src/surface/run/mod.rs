//! Running a surface grammar on a mesh (paper 000, §7): rules in file
//! order; each applies, in parallel, to every element that matches its
//! type, context and condition when the rule starts; new vertices get their
//! assignment from the positions before the rule; vertex rules read the
//! current positions and write the next ones, which become current at the
//! end of each step.
//!
//! The current level `c` is the highest vertex level in the mesh when a
//! rule starts: the level of the newest vertices. (Paper 000 says that `c`
//! advances with each rule; read literally, its level rules and its
//! printed conditions disagree for Loop and Catmull-Clark. This definition
//! runs √3 exactly as printed; the grammar files note where they differ.)
//!
//! A run's state (its step, `c`, the positions written for the next step,
//! the block policy of its splits) lives in a [`GrammarRun`], not in the
//! mesh.
//!
//! The folder, one concept a file:
//! - [`compile`]: compiling a parsed grammar file into checked [`Rule`]s
//!   and a [`Grammar`], and what the rules' expressions read;
//! - [`grammar_run`]: starting a run ([`Grammar::run`], [`Grammar::start`]
//!   and their checks of the mesh) and the run, [`GrammarRun`], stepped by
//!   the production schedule;
//! - [`protection`]: the parts of a mesh a run leaves as they are
//!   ([`Protection`]);
//! - [`evaluator`]: what one thread needs to evaluate a rule's expressions;
//! - [`matching`]: what a rule matches when it starts, and the values of
//!   matched elements;
//! - [`apply`]: the rules of a step applied in order, and errors located
//!   at a rule;
//! - [`topology_rules`]: face splits, edge splits and flips applied to
//!   their matches, with the points of the new vertices;
//! - [`vertex_rules`]: vertex rules, matched and evaluated in one pass;
//! - [`adaptive`]: adaptive 4-8 refinement: the mesh it starts on and its
//!   rounds of forced splits;
//! - [`next_positions`]: the second position buffer, which vertex rules
//!   write and the end of a step makes current.
//!
//! Here: the compiled [`Rule`] and [`Grammar`], the limits of a run, its
//! errors and counts, and the state it carries between rules and steps.
//!
//! It uses `lang`, `mesh`, `syntax` and the surface's `grammar` and `host`;
//! nothing above.

use crate::lang::eval::RuntimeError;
use crate::lang::ir::Ex;
use crate::mesh::{BlockSplit, Mesh, Split, VertexId};
use crate::syntax::span::{Diagnostic, SourceMap, Span};

use super::grammar::{Op, VertexContext};
use super::host;

mod adaptive;
mod apply;
mod compile;
mod evaluator;
mod grammar_run;
mod matching;
mod next_positions;
mod protection;
mod topology_rules;
mod vertex_rules;

#[cfg(test)]
mod tests;

pub(crate) use compile::compile_with;
pub use grammar_run::GrammarRun;
use next_positions::NextPositions;
use protection::Protected;
pub use protection::Protection;

/// A compiled rule.
#[derive(Debug)]
pub struct Rule {
    pub op: Op,
    pub context: VertexContext,
    pub cond: Option<Ex>,
    pub assign: Option<Ex>,
    /// `cond` as a guard on the element alone, when it is one.
    guard: Option<host::Guard>,
    /// `assign` as an affine combination, when it is one.
    affine: Option<host::Affine>,
    /// Frame slots: the predecessor element and the new vertex.
    pub elem_slot: u16,
    pub vertex_slot: Option<u16>,
    pub frame: usize,
    pub span: Span,
    pub text: String,
    /// Runs once, before the first step.
    pub init: bool,
    /// A vertex rule whose condition is `refined(v) && ...`: only corners
    /// of faces with a vertex made in this step can match.
    needs_refined: bool,
    /// A split rule whose assignment reads positions only through `pos`
    /// and `avg` of the matched element ([`reads_only_matched_positions`](compile::reads_only_matched_positions)):
    /// its new vertices' points read none of theirs, so each can be
    /// written as soon as it is computed.
    points_in_place: bool,
    /// A split rule whose points read, besides the matched element's
    /// positions, no number that a split of another element changes (no
    /// valence, no count of creases; [`reads_counts`](compile::reads_counts)): each part of the
    /// matches gets its points right after its splits, and is let go.
    points_between_splits: bool,
}

/// A checked grammar, ready to run.
#[derive(Debug)]
pub struct Grammar {
    pub rules: Vec<Rule>,
    pub mesh: Option<(String, Span)>,
    pub length: Option<u64>,
    pub sources: SourceMap,
    /// Where the grammar first asks `block(e)`: such a grammar is for
    /// tri-quad meshes. Without it, quads are read as two triangles.
    pub block_used_at: Option<Span>,
    /// Where the grammar says it is a dual scheme (`blocks: dual;`, or
    /// its first `center(v)`): it needs a closed mesh.
    pub dual_at: Option<Span>,
    /// What splitting a block's internal edge does (`blocks:`).
    pub block_split: BlockSplit,
    /// Where the grammar says `adaptive;`: its split rules select blocks,
    /// and the closure keeps the mesh a 4-8 mesh (see [`GrammarRun`]).
    pub adaptive: Option<Span>,
    /// `adaptive: incremental;`: from the second step on, split rules test
    /// only the refinement edges of faces at vertices made in the step
    /// before or in this one; a diamond not selected when it appeared is
    /// not tested again.
    pub incremental: bool,
    /// `creasing:`: how semi-sharp creases soften after each step
    /// (uniform without the declaration).
    pub creasing: crate::mesh::Creasing,
    /// `init: match_blocks;`: triangles in no block are paired by a
    /// maximum matching before the `init:` rules.
    pub match_blocks_at: Option<Span>,
    /// A rule that would make more faces than this stops the run with an
    /// error instead of exhausting memory (about 70 bytes a face at the
    /// peak of a Loop step).
    pub max_faces: usize,
    /// A rule after which a vertex has a higher valence than this (or
    /// than twice the base mesh's highest, where that is more) stops the
    /// run with an error: work at a vertex grows with its valence, so a
    /// grammar whose valences keep growing (two face splits a step) would
    /// slow down without end. `SUBGRAM_MAX_VALENCE` in the environment, when
    /// set, takes its place.
    pub max_valence: usize,
    /// What `check` reports without refusing the grammar.
    pub warnings: Vec<Diagnostic>,
}

/// The default face limit: about 3.5 GB at the peak of a step.
pub const MAX_FACES: usize = 50_000_000;

/// The default valence limit ([`Grammar::max_valence`]): far above what
/// subdivision schemes make (they keep valences, or double them for a
/// rule), low enough that a grammar whose valences explode stops within
/// seconds.
pub const MAX_VALENCE: usize = 1000;

/// The environment variable that sets the valence limit:
/// `SUBGRAM_MAX_VALENCE=5000`.
pub const MAX_VALENCE_VAR: &str = "SUBGRAM_MAX_VALENCE";

/// A failed run: the rule, the step, and what went wrong.
#[derive(Clone, Debug)]
pub struct RunError {
    pub span: Option<Span>,
    pub message: String,
}

/// Counts after a step, for progress reports.
#[derive(Clone, Copy, Debug, Default)]
pub struct StepCounts {
    /// The step, counted from 1 in one call of [`GrammarRun::steps`].
    pub step: usize,
    pub vertices: usize,
    pub edges: usize,
    pub faces: usize,
}

impl From<RuntimeError> for RunError {
    fn from(e: RuntimeError) -> RunError {
        RunError {
            span: e.span,
            message: e.message,
        }
    }
}

/// The message alone; `Surface::error` adds the rule's line and
/// caret.
impl std::fmt::Display for RunError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for RunError {}

/// What a run carries between rules and steps.
#[derive(Debug, Default)]
struct RunState {
    /// `c`: the highest vertex level when a rule starts, raised as splits
    /// make vertices.
    current_level: u32,
    /// The step running (0 for `init:` rules); new vertices record it.
    step: u32,
    /// Positions written for the next step (the second buffer of paper
    /// 000, §7): they become current at the end of the step.
    next: NextPositions,
    /// What splitting a basic block's internal edge makes of the block.
    blocks: BlockSplit,
    /// Set for grammars that read blocks: a face split then makes blocks.
    lone_triangles_join_blocks: bool,
    /// An adaptive 4-8 run (`adaptive;`): split rules see refinement
    /// edges only, and the closure splits coarser neighbours first.
    adaptive: bool,
    /// `adaptive: incremental;`.
    incremental: bool,
    /// In adaptive runs: the vertices splits made in this step, and in
    /// the step before (the work lists of matching).
    made_now: Vec<VertexId>,
    made_before: Vec<VertexId>,
    /// The highest valence a rule may leave (see [`Grammar::max_valence`]).
    valence_limit: usize,
    /// At least the highest valence in the mesh (see `check_valence`).
    valence_bound: usize,
    /// The run stops once this passes.
    deadline: Option<crate::Deadline>,
    /// What no rule may match.
    protect: Option<Protected>,
    /// Some edge or vertex was sharp when the run started: the steps
    /// decrement sharpness (nothing else makes any).
    creased: bool,
}

impl RunState {
    /// The policy of the splits made now.
    fn split(&self) -> Split {
        Split {
            step: self.step,
            blocks: self.blocks,
            lone_triangles_join_blocks: self.lone_triangles_join_blocks,
            adaptive: self.adaptive,
        }
    }

    /// The ids `rule` may match, in increasing order, where an adaptive
    /// run knows that no other element can: for a vertex rule that
    /// requires `refined(v)`, the vertices made in this step and their
    /// neighbours (a corner of a face with a new vertex is one of them);
    /// for a split rule of an incremental run after its first step, the
    /// refinement edges of the faces at the vertices made in the step
    /// before or in this one. `None`: every slot.
    fn work_list(&self, rule: &Rule, mesh: &Mesh) -> Option<Vec<u32>> {
        if !self.adaptive {
            return None;
        }
        let mut ids: Vec<u32> = match rule.op {
            Op::Vertex if rule.needs_refined => self
                .made_now
                .iter()
                .flat_map(|&v| std::iter::once(v).chain(mesh.one_ring(v)))
                .map(|v| v.0)
                .collect(),
            Op::EdgeSplit | Op::BoundarySplit if self.incremental && self.step >= 2 => self
                .made_before
                .iter()
                .chain(&self.made_now)
                .flat_map(|&v| mesh.vertex_faces(v))
                .map(|f| mesh.refinement_edge(f).0)
                .collect(),
            _ => return None,
        };
        ids.sort_unstable();
        ids.dedup();
        Some(ids)
    }

    /// Refuses a mesh with a vertex of higher valence than the limit.
    /// Checks the valences after a split or flip rule. A split or a flip
    /// at most doubles a vertex's valence (each edge it adds at a vertex
    /// sits in a face or beside an edge that was already there), so the
    /// highest valence is bounded without looking: the mesh is walked only
    /// when that bound passes the limit, and the walk resets the bound.
    fn check_valence(&mut self, mesh: &Mesh) -> Result<(), String> {
        self.valence_bound = self.valence_bound.saturating_mul(2).max(4);
        if self.valence_bound <= self.valence_limit {
            return Ok(());
        }
        let highest = mesh.max_valence();
        self.valence_bound = highest.map_or(0, |(_, n)| n);
        match highest {
            Some((v, n)) if n > self.valence_limit => Err(format!(
                "vertex {v} has valence {n} after this rule, more than the limit of {}; \
                 a grammar whose valences keep growing slows down without end \
                 (set {MAX_VALENCE_VAR} to a larger number to allow more)",
                self.valence_limit
            )),
            _ => Ok(()),
        }
    }

    /// Makes the next positions current (paper 000, §7: the buffer is
    /// swapped after each step), in the order they were written.
    fn swap_positions(&mut self, mesh: &mut Mesh) {
        std::mem::take(&mut self.next).make_current(mesh);
    }
}

/// Elements per parallel task: small jobs stay on one thread. A multiple
/// of 64, so that a block's flags in [`NextPositions`] are whole words.
const CHUNK: usize = 16384;
