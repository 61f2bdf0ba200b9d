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

use glam::DVec3;
use rayon::prelude::*;

use crate::lang::compile::RuleCompiler;
use crate::lang::eval::{Env, Interp, RuntimeError};
use crate::lang::ir::{Ex, Func};
use crate::lang::value::{Elem, Ty, Value};
use crate::mesh::{BlockSplit, EdgeId, FaceId, Mesh, Split, VertexId};
use crate::syntax::span::{Diagnostic, SourceMap, Span};

use super::grammar::{GrammarFile, Op, VertexContext};
use super::host::{self, id, MeshHost, SURFACE_HOST};

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
    /// and `avg` of the matched element ([`reads_only_matched_positions`]):
    /// its new vertices' points read none of theirs, so each can be
    /// written as soon as it is computed.
    points_in_place: bool,
    /// A split rule whose points read, besides the matched element's
    /// positions, no number that a split of another element changes (no
    /// valence, no count of creases; [`reads_counts`]): each part of the
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

/// The valence limit of a run on `mesh`: `configured`, or
/// [`MAX_VALENCE_VAR`] where it is set, raised to twice the mesh's highest
/// valence.
/// Also gives the mesh's highest valence.
fn valence_limit(configured: usize, mesh: &Mesh) -> Result<(usize, usize), String> {
    let limit =
        crate::limits::from_env(MAX_VALENCE_VAR, configured as u64, "a whole number")? as usize;
    let highest = mesh.max_valence().map_or(0, |(_, n)| n);
    Ok((limit.max(2 * highest), highest))
}

/// Where the first call of host built-in `f` in `e` is, if there is one.
fn first_call(e: &Ex, f: u16) -> Option<Span> {
    let mut found: Option<Span> = None;
    e.walk(&mut |x| {
        if let Ex::Call(Func::Host(g), _, span) = x {
            if *g == f && found.is_none() {
                found = Some(*span);
            }
        }
    });
    found
}

/// True when `e` is `refined(x)` on the local `slot`, or a conjunction
/// with such a term: `e` can hold only where `refined` does.
fn requires_refined(e: &Ex, slot: u16) -> bool {
    match e {
        Ex::Logic(true, a, b) => requires_refined(a, slot) || requires_refined(b, slot),
        Ex::Call(Func::Host(id::REFINED), args, _) => {
            matches!(args.as_slice(), [Ex::Local(s)] if *s == slot)
        }
        _ => false,
    }
}

/// Compiles a parsed grammar file: its conditions and assignments are
/// checked by the language's one checker, with the stellar topology's
/// elements and built-ins.
///
/// With `specialise`, the IR is specialised after checking (fused
/// built-ins, guards, affine assignments); the tests run both and compare.
pub(crate) fn compile_with(
    file: &GrammarFile,
    sources: SourceMap,
    specialise: bool,
) -> Result<Grammar, (SourceMap, Vec<Diagnostic>)> {
    let mut rules = Vec::new();
    let mut diags = Vec::new();
    let mut warnings = Vec::new();
    let mut block_used_at = None;
    let mut centre_used_at = None;
    let mut lone_used = false;
    let mut c = RuleCompiler::new(
        <GrammarRun as crate::production::Topology>::host_table(),
        &file.functions,
    );
    for r in &file.rules {
        c.start_rule();
        let elem_t = Ty::Elem(match r.op {
            Op::FaceSplit => host::FACE,
            Op::EdgeSplit | Op::BoundarySplit | Op::Flip => host::EDGE,
            Op::Vertex => host::VERTEX,
        });
        let elem_slot = c.bind(&r.name, elem_t);
        let cond = r.cond.as_ref().map(|e| c.expr_as(e, Ty::Bool));
        let (vertex_slot, assign) = match &r.assign {
            Some((name, e)) => {
                // In a vertex rule the successor's name is the same vertex.
                let s = if r.op == Op::Vertex && *name == r.name {
                    elem_slot
                } else {
                    c.bind(name, Ty::Elem(host::VERTEX))
                };
                (Some(s), Some(c.expr_as(e, Ty::V3d)))
            }
            None => (None, None),
        };
        let (errors, warned) = c.take_diagnostics();
        warnings.extend(warned);
        if !errors.is_empty() {
            diags.extend(errors);
            continue;
        }
        let (Some(mut cond), Some(mut assign)) = (
            cond.map_or(Some(None), |x| x.map(Some)),
            assign.map_or(Some(None), |x| x.map(Some)),
        ) else {
            continue;
        };
        for x in cond.iter().chain(assign.iter()) {
            block_used_at = block_used_at
                .or(first_call(x, id::BLOCK))
                .or(first_call(x, id::CENTER));
            centre_used_at = centre_used_at.or(first_call(x, id::CENTER));
            lone_used |= first_call(x, id::LONE).is_some();
        }
        let (mut guard, mut affine) = (None, None);
        if specialise {
            cond.iter_mut()
                .chain(assign.iter_mut())
                .for_each(host::specialise);
            guard = cond.as_ref().and_then(|c| host::Guard::of(c, elem_slot));
            affine = assign.as_ref().and_then(host::Affine::of);
        }
        let needs_refined = cond
            .as_ref()
            .is_some_and(|c| requires_refined(c, elem_slot));
        let points_in_place = r.op != Op::Vertex
            && assign
                .as_ref()
                .is_some_and(|a| reads_only_matched_positions(a, elem_slot));
        let points_between_splits = points_in_place && !assign.as_ref().is_some_and(reads_counts);
        rules.push(Rule {
            guard,
            affine,
            op: r.op,
            context: r.vertex_context,
            cond,
            assign,
            elem_slot,
            vertex_slot,
            frame: c.frame_size().max(1),
            span: r.span,
            text: r.text.clone(),
            init: r.init,
            needs_refined,
            points_in_place,
            points_between_splits,
        });
    }
    let length = match &file.length {
        None => None,
        Some(e) => {
            c.start_rule();
            let x = c.expr(e).map(|(x, _)| x);
            let (errors, warned) = c.take_diagnostics();
            warnings.extend(warned);
            diags.extend(errors);
            x.and_then(|x| {
                let m = Mesh::default();
                let mut host = MeshHost {
                    mesh: &m,
                    current: 0,
                    step: 0,
                };
                let got = Interp::new(&[]).eval(
                    &x,
                    &mut vec![Value::Void; c.frame_size().max(1)],
                    &mut Env::new(Vec::new()),
                    &mut host,
                );
                match got {
                    Ok(Value::Int(n)) if (0..=64).contains(&n) => Some(n as u64),
                    Ok(Value::Float(n)) if n.fract() == 0.0 && (0.0..=64.0).contains(&n) => {
                        Some(n as u64)
                    }
                    Ok(_) => {
                        diags.push(Diagnostic::new(
                            e.span,
                            "the derivation length must be a whole number of steps from 0 to 64",
                        ));
                        None
                    }
                    Err(err) => {
                        diags.push(Diagnostic::new(err.span.unwrap_or(e.span), err.message));
                        None
                    }
                }
            })
        }
    };
    if let Some(at) = file.adaptive {
        if !matches!(file.block_split, Some((BlockSplit::Bisection, _))) {
            diags.push(Diagnostic::new(
                at,
                "`adaptive;` is for 4-8 grammars, which refine by bisection: it needs \
                 `blocks: bisection;`",
            ));
        }
        for r in file.rules.iter().filter(|r| !r.init) {
            if matches!(r.op, Op::FaceSplit | Op::Flip) {
                diags.push(Diagnostic::new(
                    r.span,
                    "an adaptive 4-8 grammar refines by splitting blocks' internal edges only; \
                     a face split or an edge flip would break its blocks (put it under `init:`, \
                     or drop `adaptive;`)",
                ));
            }
        }
    }
    // Pairs that nothing reads would not be idle: the splits of a grammar
    // with blocks keep them, which changes what its rules match (√3 gives
    // another mesh) and what it writes (quads).
    // (Only where every rule compiled: a rule with an error reads nothing.)
    if let Some(at) = file.match_blocks.filter(|_| diags.is_empty()) {
        let dual =
            matches!(file.block_split, Some((BlockSplit::Dual, _))) || centre_used_at.is_some();
        if dual {
            diags.push(Diagnostic::new(
                at,
                "`init: match_blocks;` pairs triangles into quads, the blocks of primal schemes; \
                 this grammar is a dual scheme (`blocks: dual;` or `center(v)`), whose blocks are \
                 fans around a centre, so leave it out",
            ));
        } else if block_used_at.is_none() && !lone_used && file.block_split.is_none() {
            diags.push(Diagnostic::new(
                at,
                "`init: match_blocks;` pairs the triangles into basic blocks, but this grammar \
                 reads none (no `block(x)` or `lone(x)` in its rules, no `blocks:` line), and \
                 pairs it does not read would still change what its rules match; leave it out \
                 for a scheme on triangles",
            ));
        }
    }
    if !diags.is_empty() {
        diags.sort_by_key(|d| (d.span.file.0, d.span.start));
        return Err((sources, diags));
    }
    warnings.sort_by_key(|d| (d.span.file.0, d.span.start));
    Ok(Grammar {
        rules,
        mesh: file.mesh.clone(),
        length,
        sources,
        block_used_at: block_used_at
            .or(file.block_split.map(|(_, s)| s))
            .or(file.match_blocks),
        dual_at: match file.block_split {
            Some((BlockSplit::Dual, at)) => Some(at),
            _ => centre_used_at,
        },
        block_split: file
            .block_split
            .map_or(BlockSplit::Quadrisection, |(b, _)| b),
        adaptive: file.adaptive,
        incremental: file.incremental,
        match_blocks_at: file.match_blocks,
        max_faces: MAX_FACES,
        max_valence: MAX_VALENCE,
        warnings,
    })
}

/// The parts of a mesh a run leaves as they are (paper 003, §4.2.2: the
/// faces and vertices a smoothing group shares with shapes outside it).
/// No rule matches a protected face, or a face whose three corners are
/// protected vertices (Algorithm 3 for the mesh's triangles); a vertex
/// that is protected or lies
/// on a protected face; an edge with a protected face on either side, or
/// whose two ends are protected. So no face point is put in a protected
/// face, none of its vertices moves, no edge is drawn in it or split on
/// its border, and no edge next to it flips (Algorithm 2 with the sets of
/// Algorithm 3). Protected elements are never rewritten, so their ids and
/// positions stay as they were through the run.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Protection {
    /// By [`FaceId`] index; faces past its end are not protected.
    pub faces: Vec<bool>,
    /// By [`VertexId`] index; vertices past its end are not protected.
    pub vertices: Vec<bool>,
}

/// A [`Protection`] as a run reads it.
#[derive(Debug, Default)]
struct Protected {
    face: Vec<bool>,
    vertex: Vec<bool>,
    /// Protected, or a corner of a protected face: never moved.
    fixed: Vec<bool>,
    /// The protected faces with their corners and the fixed vertices with
    /// their positions, as the run found them (for a debug check).
    faces: Vec<(FaceId, [VertexId; 3])>,
    positions: Vec<(VertexId, DVec3)>,
}

impl Protected {
    /// Checks `p` against `mesh`: every protected element must exist.
    fn new(p: Protection, mesh: &Mesh) -> Result<Protected, String> {
        if let Some(f) = p
            .faces
            .iter()
            .enumerate()
            .position(|(i, &on)| on && !mesh.is_face(FaceId(i as u32)))
        {
            return Err(format!(
                "face {} is protected but is not a face of the mesh",
                f + 1
            ));
        }
        if let Some(v) = p
            .vertices
            .iter()
            .enumerate()
            .position(|(i, &on)| on && !mesh.is_vertex(VertexId(i as u32)))
        {
            return Err(format!(
                "vertex {} is protected but is not a vertex of the mesh",
                v + 1
            ));
        }
        let mut fixed = p.vertices.clone();
        fixed.resize(mesh.v_alive.len(), false);
        let mut faces = Vec::new();
        for (i, &on) in p.faces.iter().enumerate() {
            if on {
                let f = FaceId(i as u32);
                let vs = mesh.face_vertices(f);
                for v in vs {
                    fixed[v.index()] = true;
                }
                faces.push((f, vs));
            }
        }
        let positions = (0..fixed.len())
            .filter(|&i| fixed[i])
            .map(|i| (VertexId(i as u32), mesh.position(VertexId(i as u32))))
            .collect();
        Ok(Protected {
            face: p.faces,
            vertex: p.vertices,
            fixed,
            faces,
            positions,
        })
    }

    #[inline]
    fn face(&self, f: FaceId) -> bool {
        self.face.get(f.index()).copied().unwrap_or(false)
    }

    /// A face rule may match `f`: it is not protected, and not all its
    /// corners are protected vertices. The second is Algorithm 3's rule
    /// (a face whose vertices are all protected is protected) for the
    /// triangles being subdivided, whatever polygons the protection was
    /// given for: a face point in such a triangle would join three
    /// spokes whose ends never move and whose edges never flip, and a
    /// later step that flips all three (√3 next to a protected boundary
    /// edge) would join two new vertices twice.
    #[inline]
    fn face_free(&self, mesh: &Mesh, f: FaceId) -> bool {
        let protected = |v: VertexId| self.vertex.get(v.index()).copied().unwrap_or(false);
        !self.face(f) && !mesh.face_vertices(f).into_iter().all(protected)
    }

    /// A vertex rule may match `v`.
    #[inline]
    fn vertex_free(&self, v: VertexId) -> bool {
        !self.fixed.get(v.index()).copied().unwrap_or(false)
    }

    /// An edge rule may match `e`.
    fn edge_free(&self, mesh: &Mesh, e: EdgeId) -> bool {
        let protected = |v: VertexId| self.vertex.get(v.index()).copied().unwrap_or(false);
        let (a, b) = mesh.edge_vertices(e);
        !(protected(a) && protected(b)
            || mesh.edge_faces(e).iter().flatten().any(|&f| self.face(f)))
    }

    /// True while every protected face has its corners and every fixed
    /// vertex its position, bit for bit.
    fn intact(&self, mesh: &Mesh) -> bool {
        self.faces.iter().all(|&(f, vs)| {
            mesh.is_face(f) && {
                let now = mesh.face_vertices(f);
                (0..3).any(|k| (0..3).all(|i| now[(k + i) % 3] == vs[i]))
            }
        }) && self.positions.iter().all(|&(v, p)| {
            mesh.is_vertex(v)
                && mesh.position(v).to_array().map(f64::to_bits) == p.to_array().map(f64::to_bits)
        })
    }
}

/// The elements a rule matched when it started.
struct Matches {
    current: u32,
    /// The matched elements as values, in order, in parts (one for each
    /// range of ids tested), so that a split rule can let each part go
    /// once it is applied; none for a flip rule, which needs only their
    /// ids; an edge's value holds its id.
    parts: Vec<Vec<Elem>>,
    /// A flip rule's matched edges (empty for other rules).
    edge_ids: Vec<crate::mesh::EdgeId>,
}

impl Matches {
    /// The number of matched elements.
    fn len(&self) -> usize {
        self.parts.iter().map(Vec::len).sum()
    }

    /// The matched elements, in order.
    fn vals(&self) -> impl Iterator<Item = &Elem> + '_ {
        self.parts.iter().flatten()
    }
}

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

/// What one thread needs to evaluate a rule's expressions.
struct Evaluator<'m> {
    interp: Interp<'static>,
    env: Env,
    host: MeshHost<'m>,
    frame: Vec<Value>,
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
    fn new(mesh: &'m Mesh, current: u32, step: u32, frame: usize) -> Evaluator<'m> {
        Evaluator {
            interp: Interp::new(&[]),
            env: Env::new(Vec::new()),
            host: MeshHost {
                mesh,
                current,
                step,
            },
            frame: vec![Value::Void; frame],
            memo: host::Memo::default(),
        }
    }

    /// Whether the element passes `rule`'s condition.
    fn test(&mut self, rule: &Rule, val: &Elem) -> Result<bool, RuntimeError> {
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
    fn assign(&mut self, rule: &Rule, assign: &Ex) -> Result<Value, RuntimeError> {
        if let Some(a) = &rule.affine {
            if let Some(v) = a.eval(self)? {
                return Ok(v);
            }
        }
        host::Evaluate::eval(self, assign)
    }
}

impl Grammar {
    /// Renders a run error with the rule's line and caret.
    pub fn render_error(&self, e: &RunError) -> String {
        match e.span {
            Some(s) => self.sources.render(s, &e.message),
            None => e.message.clone(),
        }
    }

    /// Runs the `init:` rules, then `steps` steps of the grammar on
    /// `mesh`, as a new run: the mesh is taken as a base mesh, whatever
    /// runs made it. `progress` hears after each step. Checks that can be
    /// made before the run (quads for block grammars, closed meshes for
    /// dual ones) leave the mesh untouched; an error during a rule leaves
    /// it partly derived, so callers that must keep it run on a copy. To
    /// continue a run, use [`Grammar::start`] and [`GrammarRun::steps`].
    pub fn run(
        &self,
        mesh: &mut Mesh,
        steps: usize,
        progress: impl FnMut(StepCounts),
    ) -> Result<(), RunError> {
        self.run_until(mesh, steps, None, progress)
    }

    /// [`Grammar::run`] that stops with an error once `deadline` passes:
    /// it is looked at before every rule.
    pub fn run_until(
        &self,
        mesh: &mut Mesh,
        steps: usize,
        deadline: Option<crate::Deadline>,
        progress: impl FnMut(StepCounts),
    ) -> Result<(), RunError> {
        let mut run = {
            // The pairing of `init: match_blocks` reads the thread's
            // deadline: this one, where the caller gave one.
            let _scope = deadline.map(|d| crate::deadline::scope(Some(d)));
            self.start(mesh)?
        };
        run.state.deadline = deadline;
        run.until = steps as u32;
        let mut progress = progress;
        crate::production::run(&mut run, |r| {
            use crate::production::Topology;
            let m = r.structure();
            progress(StepCounts {
                step: r.steps_done() as usize,
                vertices: m.vertex_count(),
                edges: m.edge_count(),
                faces: m.face_count(),
            })
        })
    }

    /// Starts a run on `mesh`: checks it (see [`Grammar::run`]; a refused
    /// mesh is left untouched), takes it as the run's base mesh (its
    /// vertices are made at step 0), and runs the `init:` rules. The run's
    /// [`GrammarRun::steps`] continue from one call to the next.
    pub fn start<'a>(&'a self, mesh: &'a mut Mesh) -> Result<GrammarRun<'a>, RunError> {
        self.start_with(mesh, None)
    }

    /// [`Grammar::start`] with the parts of `mesh` that the run must
    /// leave as they are: see [`Protection`]. An empty protection runs
    /// exactly as [`Grammar::start`]. A protected element that is not in
    /// the mesh is an error.
    pub fn start_protected<'a>(
        &'a self,
        mesh: &'a mut Mesh,
        protection: Protection,
    ) -> Result<GrammarRun<'a>, RunError> {
        self.start_with(mesh, Some(protection))
    }

    /// A grammar that reads blocks needs a mesh of blocks (quads, or
    /// triangles a face split makes into quads); one that reads none takes
    /// quads as two triangles.
    fn check_blocks(&self, mesh: &mut Mesh) -> Result<(), RunError> {
        // Pairing takes the triangles of a fanned polygon like any other.
        let fanned = mesh
            .fanned_polygon()
            .filter(|_| self.match_blocks_at.is_none());
        if let (Some(span), Some(fan)) = (self.block_used_at, fanned) {
            let line = fan.line.map_or(String::new(), |l| format!(" (line {l})"));
            return Err(RunError {
                span: Some(span),
                message: format!(
                    "this grammar reads quads as basic blocks, but face {}{line} has {} sides; \
                     polygons of more than four sides are not supported by such grammars yet \
                     (split them into quads and triangles first)",
                    fan.face + 1,
                    fan.sides
                ),
            });
        }
        match self.block_used_at {
            None => mesh.forget_blocks(),
            // A grammar with a face split (Catmull-Clark) takes lone
            // triangles too: it splits them at their centres.
            Some(_) if self.rules.iter().any(|r| r.op == Op::FaceSplit) => {}
            Some(span) => {
                if let Some(f) = mesh.face_outside_blocks() {
                    let [a, b, c] = mesh.face_vertices(f).map(|v| v.index() + 1);
                    if self.match_blocks_at.is_some() {
                        return Err(RunError {
                            span: self.match_blocks_at,
                            message: format!(
                                "the triangle on vertices {a}, {b} and {c} is on the boundary and \
                                 in no block after pairing; split its boundary edge in an `init:` \
                                 rule, e.g. `init: E(e; lone(e)) | F -> V(v = avg(e)) || E^3 F^2;`"
                            ),
                        });
                    }
                    return Err(RunError {
                        span: Some(span),
                        message: format!(
                            "this grammar reads basic blocks (here), so it needs a mesh of quads, but the \
                             triangle on vertices {a}, {b} and {c} is not half of a quad"
                        ),
                    });
                }
            }
        }
        Ok(())
    }

    fn start_with<'a>(
        &'a self,
        mesh: &'a mut Mesh,
        protection: Option<Protection>,
    ) -> Result<GrammarRun<'a>, RunError> {
        // With `init: match_blocks;` the checks on blocks wait until the
        // triangles are paired and the `init:` rules have run.
        if self.match_blocks_at.is_none() {
            self.check_blocks(mesh)?;
        }
        if let Some(span) = self.dual_at {
            if let Some(v) = mesh.vertices().find(|&v| mesh.is_boundary_vertex(v)) {
                return Err(RunError {
                    span: Some(span),
                    message: format!(
                        "this grammar is a dual scheme, which runs on closed meshes only; \
                         vertex {v} is on a boundary"
                    ),
                });
            }
        }
        // Nothing protected is no protection: the run is `start`'s.
        let protection = protection.filter(|p| p.faces.iter().chain(&p.vertices).any(|&on| on));
        let protect = match protection {
            None => None,
            Some(p) => Some(Protected::new(p, mesh).map_err(|message| RunError {
                span: None,
                message,
            })?),
        };
        // `new(v)` counts this run's steps only.
        mesh.reset_vertex_steps();
        let (valence_limit, highest) =
            valence_limit(self.max_valence, mesh).map_err(|message| RunError {
                span: None,
                message,
            })?;
        let mut state = RunState {
            valence_limit,
            valence_bound: highest,
            blocks: self.block_split,
            lone_triangles_join_blocks: self.block_used_at.is_some(),
            adaptive: self.adaptive.is_some(),
            incremental: self.incremental,
            protect,
            creased: mesh.has_sharpness(),
            ..RunState::default()
        };
        let init: Vec<&Rule> = self.rules.iter().filter(|r| r.init).collect();
        // The init rules prepare the blocks; the adaptive closure starts
        // with the first step.
        state.adaptive = false;
        if let Some(span) = self.match_blocks_at {
            // Paper 004's preprocess: the triangles paired into blocks; those
            // left on the boundary are for an `init:` boundary split. A mesh
            // refused after this is given back as it came.
            let budget = 1_000_000 + 400 * (mesh.face_count() as u64 + mesh.edge_count() as u64);
            let before = mesh.clone();
            let refuse = |mesh: &mut Mesh, message: String| {
                *mesh = before.clone();
                RunError {
                    span: Some(span),
                    message,
                }
            };
            if let Err(e) = mesh.match_blocks(budget) {
                return Err(refuse(mesh, e.message));
            }
            if let Err(e) = self.apply_all(&init, mesh, &mut state) {
                *mesh = before;
                return Err(e);
            }
            if let Err(e) = self.check_blocks(mesh) {
                return Err(refuse(mesh, e.message));
            }
        } else {
            self.apply_all(&init, mesh, &mut state)?;
        }
        state.adaptive = self.adaptive.is_some();
        // What init's vertex rules wrote is current before the first step.
        state.swap_positions(mesh);
        if let Some(span) = self.adaptive {
            check_adaptive_start(mesh).map_err(|message| RunError {
                span: Some(span),
                message,
            })?;
        }
        debug_assert!(state.protect.as_ref().is_none_or(|p| p.intact(mesh)));
        Ok(GrammarRun {
            grammar: self,
            mesh,
            state,
            until: 0,
        })
    }

    /// What `rule` applies to, fixed when it starts: the matched elements
    /// and, for edge rules, their ids. Edges keep their ids through the
    /// splits and flips of other edges, so the ids stay valid while the
    /// rule runs.
    fn find_matches(
        &self,
        rule: &Rule,
        mesh: &Mesh,
        state: &RunState,
    ) -> Result<Matches, RuntimeError> {
        self.find_matches_with(rule, None, mesh, state)
            .map(|m| m.0)
            .map_err(|(_, e)| e)
    }

    /// What `rule` applies to, and `other`, an edge rule for the other
    /// context (boundary or interior), tested in the same pass over the
    /// edges: both fixed when the first starts. An error says whether it
    /// came from `other`'s condition.
    fn find_matches_with(
        &self,
        rule: &Rule,
        other: Option<&Rule>,
        mesh: &Mesh,
        state: &RunState,
    ) -> Result<(Matches, Matches), (bool, RuntimeError)> {
        // `c`, kept up to date by `apply_all` as rules make vertices.
        let current = state.current_level;
        // A crease rule on a mesh without creases matches nothing.
        if other.is_none()
            && !mesh.has_sharpness_flag()
            && rule
                .guard
                .as_ref()
                .is_some_and(|g| g.never_without_creases())
        {
            let none = || Matches {
                current,
                parts: Vec::new(),
                edge_ids: Vec::new(),
            };
            return Ok((none(), none()));
        }
        let step = state.step;
        // The ids to test: every slot, or a work list where the run knows
        // that nothing else can match.
        let list = state.work_list(rule, mesh);
        let slots = match (&list, rule.op) {
            (Some(l), _) => l.len(),
            (None, Op::FaceSplit) => mesh.f_alive.len(),
            (None, Op::EdgeSplit | Op::BoundarySplit | Op::Flip) => mesh.e_alive.len(),
            (None, Op::Vertex) => mesh.v_alive.len(),
        };
        let id_at = |i: u32| list.as_ref().map_or(i, |l| l[i as usize]);
        let frame_len = rule.frame.max(other.map_or(0, |o| o.frame));
        // What a protection leaves out is never tested, so the guards and
        // every specialised path see the same elements.
        let protect = state.protect.as_ref();
        type Part = (Vec<Elem>, Vec<crate::mesh::EdgeId>);
        // Conditions are pure, so ranges of ids are tested in parallel,
        // each by a plain loop, and the matches joined in id order.
        let ranges: Vec<(u32, u32)> = (0..slots.div_ceil(CHUNK))
            .map(|k| ((k * CHUNK) as u32, (((k + 1) * CHUNK).min(slots)) as u32))
            .collect();
        let parts: Vec<Result<(Part, Part), (bool, RuntimeError)>> = ranges
            .into_par_iter()
            .map(|(lo, hi)| {
                let mut ev = Evaluator::new(mesh, current, step, frame_len);
                let (mut a, mut b): (Part, Part) = Default::default();
                match rule.op {
                    Op::FaceSplit => {
                        for f in (lo..hi).map(|i| crate::mesh::FaceId(id_at(i))) {
                            if mesh.is_face(f) && protect.is_none_or(|p| p.face_free(mesh, f)) {
                                let hs = mesh.face_halfedges(f);
                                let val = host::face(
                                    hs.map(|h| mesh.from(h)),
                                    mesh.face_level(f),
                                    hs.iter().any(|h| mesh.face(h.twin()).is_none()),
                                    hs.iter().any(|h| mesh.is_block_edge(h.edge())),
                                );
                                if ev.test(rule, &val).map_err(|e| (false, e))? {
                                    a.0.push(val);
                                }
                            }
                        }
                    }
                    Op::EdgeSplit | Op::BoundarySplit | Op::Flip => {
                        let want_boundary = rule.op == Op::BoundarySplit;
                        for e in (lo..hi).map(|i| crate::mesh::EdgeId(id_at(i))) {
                            if !mesh.is_edge(e) || protect.is_some_and(|p| !p.edge_free(mesh, e)) {
                                continue;
                            }
                            let on_boundary = mesh.is_boundary_edge(e);
                            let (r, out) = if on_boundary == want_boundary {
                                (rule, &mut a)
                            } else if let Some(o) = other {
                                (o, &mut b)
                            } else {
                                continue;
                            };
                            // An adaptive split rule sees the diagonals of
                            // diamonds, complete or not, as blocks' internal
                            // edges, and nothing else.
                            let block = if state.adaptive && r.op != Op::Flip {
                                if !mesh.is_refinement_edge(e) {
                                    continue;
                                }
                                true
                            } else {
                                mesh.is_block_edge(e)
                            };
                            let val = edge_value(mesh, e, block);
                            if ev.test(r, &val).map_err(|e| (!std::ptr::eq(r, rule), e))? {
                                // A flip needs the edge alone; a split's
                                // value holds the id.
                                if r.op == Op::Flip {
                                    out.1.push(e);
                                } else {
                                    out.0.push(val);
                                }
                            }
                        }
                    }
                    Op::Vertex => {
                        for v in (lo..hi).map(|i| VertexId(id_at(i))) {
                            let Some(ok) = vertex_candidate(mesh, v, protect, rule) else {
                                continue;
                            };
                            let val = host::vertex(v);
                            if ok && ev.test(rule, &val).map_err(|e| (false, e))? {
                                a.0.push(val);
                            }
                        }
                    }
                }
                Ok((a, b))
            })
            .collect();
        let parts = parts.into_iter().collect::<Result<Vec<_>, _>>()?;
        let (mut a, mut b) = (Vec::new(), Vec::new());
        let (mut a_ids, mut b_ids) = (Vec::new(), Vec::new());
        for ((av, ai), (bv, bi)) in parts {
            a.push(av);
            b.push(bv);
            a_ids.push(ai);
            b_ids.push(bi);
        }
        let join = |parts: Vec<Vec<Elem>>, ids: Vec<Vec<EdgeId>>| Matches {
            current,
            parts: parts.into_iter().filter(|p| !p.is_empty()).collect(),
            edge_ids: ids.concat(),
        };
        Ok((join(a, a_ids), join(b, b_ids)))
    }

    /// Evaluates `assign` for elements `range` in parallel, `bind` setting
    /// each one's frame slots, giving the points in order; or the first
    /// element whose point is not finite, with what it gave: a point, a
    /// value that is not one, or an error.
    #[allow(clippy::too_many_arguments)] // the host's `c` and step beside the rule's inputs
    fn eval_points(
        &self,
        rule: &Rule,
        mesh: &Mesh,
        current: u32,
        step: u32,
        assign: &Ex,
        range: std::ops::Range<usize>,
        bind: impl Fn(&mut [Value], usize) + Sync,
    ) -> Result<Vec<DVec3>, (usize, Result<Value, RuntimeError>)> {
        let lo = range.start;
        let one = |ev: &mut Evaluator, k: usize| {
            bind(&mut ev.frame, k);
            ev.assign(rule, assign)
        };
        let points: Vec<DVec3> = range
            .into_par_iter()
            .with_min_len(CHUNK)
            .map_init(
                || Evaluator::new(mesh, current, step, rule.frame),
                |ev, k| match one(ev, k) {
                    Ok(Value::V3(p)) => p,
                    _ => DVec3::NAN,
                },
            )
            .collect();
        match points.iter().position(|p| !p.is_finite()) {
            None => Ok(points),
            // Evaluate the first bad one again, to say what it gave.
            Some(k) => Err((
                lo + k,
                one(&mut Evaluator::new(mesh, current, step, rule.frame), lo + k),
            )),
        }
    }

    /// Applies `rules` in order. An interior and a boundary edge-split rule
    /// written next to each other are the two contexts of one edge split:
    /// both match when the first starts, so that what one splits (or marks
    /// as a block's internal edge) cannot feed the other in the same step.
    fn apply_all(
        &self,
        rules: &[&Rule],
        mesh: &mut Mesh,
        state: &mut RunState,
    ) -> Result<(), RunError> {
        let step = state.step as usize;
        let splits = |r: &Rule| matches!(r.op, Op::EdgeSplit | Op::BoundarySplit);
        // c: the highest vertex level, raised below by the vertices that
        // splits make (rules never remove vertices).
        state.current_level = mesh
            .vertices()
            .map(|v| mesh.vertex_level(v))
            .max()
            .unwrap_or(0);
        let mut i = 0;
        while i < rules.len() {
            let rule = rules[i];
            if let Err(m) = crate::deadline::check(state.deadline) {
                return Err(RunError {
                    span: Some(rule.span),
                    message: format!("at step {step}, before rule `{}`: {m}", rule.text),
                });
            }
            let pair = rules.get(i + 1).filter(|next| {
                matches!(
                    (rule.op, next.op),
                    (Op::EdgeSplit, Op::BoundarySplit) | (Op::BoundarySplit, Op::EdgeSplit)
                )
            });
            match pair {
                _ if state.adaptive && splits(rule) => {
                    let (a, b) = self
                        .find_matches_with(rule, pair.copied(), mesh, state)
                        .map_err(|(in_next, e)| {
                            self.runtime_error(
                                match pair {
                                    Some(next) if in_next => next,
                                    _ => rule,
                                },
                                step,
                                e,
                            )
                        })?;
                    self.apply_adaptive(rule, pair.copied(), mesh, state, a, b)?;
                    i += 1 + pair.is_some() as usize;
                }
                Some(next) => {
                    let (a, b) = self
                        .find_matches_with(rule, Some(next), mesh, state)
                        .map_err(|(in_next, e)| {
                            self.runtime_error(if in_next { next } else { rule }, step, e)
                        })?;
                    self.apply_matched(rule, mesh, state, a)?;
                    self.apply_matched(next, mesh, state, b)?;
                    i += 2;
                }
                None if rule.op == Op::Vertex => {
                    self.apply_vertex_rule(rule, mesh, state)?;
                    i += 1;
                }
                None => {
                    let m = self
                        .find_matches(rule, mesh, state)
                        .map_err(|e| self.runtime_error(rule, step, e))?;
                    self.apply_matched(rule, mesh, state, m)?;
                    i += 1;
                }
            }
        }
        Ok(())
    }

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
    fn apply_adaptive(
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

    /// A run-time error in a rule's expressions, located and with the step.
    fn runtime_error(&self, rule: &Rule, step: usize, e: RuntimeError) -> RunError {
        let at = if step == 0 {
            format!("at initialization, rule `{}`", rule.text)
        } else {
            format!("at step {step}, rule `{}`", rule.text)
        };
        RunError {
            span: Some(e.span.unwrap_or(rule.span)),
            message: format!("{at}: {}", e.message),
        }
    }

    /// A vertex rule, matched and evaluated in one pass: the vertices (or
    /// the work list) in chunks on rayon's threads, each chunk testing the
    /// condition and evaluating the assignment of its vertices and writing
    /// their points to the next-position buffer at their slots. The same
    /// as matching every vertex first and evaluating the matches after:
    /// a vertex rule changes neither the topology nor the current
    /// positions, so every match and every point reads what it read when
    /// the rule started. The errors are those of the two passes: the
    /// first condition that fails to evaluate, in id order; else the
    /// first match, in id order, whose point is not a finite point.
    fn apply_vertex_rule(
        &self,
        rule: &Rule,
        mesh: &Mesh,
        state: &mut RunState,
    ) -> Result<(), RunError> {
        let step = state.step as usize;
        let current = state.current_level;
        // A crease rule on a mesh without creases matches nothing.
        if !mesh.has_sharpness_flag()
            && rule
                .guard
                .as_ref()
                .is_some_and(|g| g.never_without_creases())
        {
            return Ok(());
        }
        let list = state.work_list(rule, mesh);
        let slots = list.as_ref().map_or(mesh.v_alive.len(), |l| l.len());
        let id_at = |i: usize| VertexId(list.as_ref().map_or(i as u32, |l| l[i]));
        let protect = state.protect.as_ref();
        let assign = rule.assign.as_ref();
        let slot = rule.elem_slot as usize;
        // Tests and evaluates the ids at places `lo..hi`, handing each
        // point to `emit` with its place.
        let task = |lo: usize, hi: usize, emit: &mut dyn FnMut(usize, VertexId, DVec3)| {
            let mut ev = Evaluator::new(mesh, current, state.step, rule.frame);
            let mut end = VertexTask::default();
            for i in lo..hi {
                let v = id_at(i);
                let Some(ok) = vertex_candidate(mesh, v, protect, rule) else {
                    continue;
                };
                let val = host::vertex(v);
                match ok.then(|| ev.test(rule, &val)) {
                    Some(Err(e)) => {
                        end.error = Some(e);
                        return end;
                    }
                    Some(Ok(true)) => {}
                    _ => continue,
                }
                // After a bad point only the conditions matter: one that
                // fails later in the chunk is the error to report.
                let Some(assign) = assign.filter(|_| end.bad.is_none()) else {
                    continue;
                };
                ev.frame[slot] = Value::Elem(val);
                match ev.assign(rule, assign) {
                    Ok(Value::V3(p)) if p.is_finite() => emit(i, v, p),
                    _ => end.bad = Some(i),
                }
            }
            end
        };
        let ranges =
            |n: usize| (0..n.div_ceil(CHUNK)).map(move |k| (k * CHUNK, ((k + 1) * CHUNK).min(n)));
        let ends: Vec<VertexTask> = match (&list, assign) {
            // Every slot: each chunk writes its own block of the buffer.
            (None, Some(_)) => {
                state.next.cover(mesh);
                let pos = &mesh.pos;
                state
                    .next
                    .blocks
                    .par_iter_mut()
                    .take(slots.div_ceil(CHUNK))
                    .enumerate()
                    .map(|(k, block)| {
                        let lo = k * CHUNK;
                        let mut out = Vec::with_capacity(block.len);
                        let end = task(lo, lo + block.len, &mut |i, _, p| {
                            out.push(((i - lo) as u32, p))
                        });
                        block.write(&pos[lo..lo + block.len], &out);
                        end
                    })
                    .collect()
            }
            // A work list: each chunk's points, then written in order.
            (Some(_), Some(_)) => {
                let parts: Vec<(VertexTask, Vec<(VertexId, DVec3)>)> = ranges(slots)
                    .collect::<Vec<_>>()
                    .into_par_iter()
                    .map(|(lo, hi)| {
                        let mut out = Vec::new();
                        let end = task(lo, hi, &mut |_, v, p| out.push((v, p)));
                        (end, out)
                    })
                    .collect();
                state.next.cover(mesh);
                parts
                    .into_iter()
                    .map(|(end, out)| {
                        state.next.write(&mesh.pos, &out);
                        end
                    })
                    .collect()
            }
            // No assignment: the conditions are still tested.
            (_, None) => ranges(slots)
                .collect::<Vec<_>>()
                .into_par_iter()
                .map(|(lo, hi)| task(lo, hi, &mut |_, _, _| {}))
                .collect(),
        };
        let mut bad = None;
        for end in ends {
            if let Some(e) = end.error {
                return Err(self.runtime_error(rule, step, e));
            }
            bad = bad.or(end.bad);
        }
        let (Some(i), Some(assign)) = (bad, assign) else {
            return Ok(());
        };
        // Evaluate the first bad one again, to say what it gave.
        let v = id_at(i);
        let mut ev = Evaluator::new(mesh, current, state.step, rule.frame);
        ev.frame[slot] = Value::Elem(host::vertex(v));
        Err(match ev.assign(rule, assign) {
            Ok(Value::V3(p)) => rule_error(
                rule,
                step,
                format!("vertex {v} would move to {p}, which is not finite"),
            ),
            Ok(_) => rule_error(rule, step, "the assignment did not give a point".into()),
            Err(e) => self.runtime_error(rule, step, e),
        })
    }

    fn apply_matched(
        &self,
        rule: &Rule,
        mesh: &mut Mesh,
        state: &mut RunState,
        m: Matches,
    ) -> Result<(), RunError> {
        let step = state.step as usize;
        let count = m.len();
        let Matches {
            current,
            parts,
            edge_ids,
        } = m;
        debug_assert!(rule.op == Op::Flip || edge_ids.is_empty());
        let fail = |m: String| rule_error(rule, step, m);

        match rule.op {
            Op::Vertex => unreachable!("vertex rules run in apply_vertex_rule"),
            Op::Flip => {
                for &e in &edge_ids {
                    mesh.edge_flip(e).map_err(|e| fail(e.message))?;
                }
                state.check_valence(mesh).map_err(fail)
            }
            Op::FaceSplit | Op::EdgeSplit | Op::BoundarySplit => {
                let per = if rule.op == Op::BoundarySplit { 1 } else { 2 };
                let after = mesh.face_count() + per * count;
                if after > self.max_faces {
                    return Err(fail(format!(
                        "this rule would make {after} faces, past the limit of {}; \
                         run fewer steps",
                        self.max_faces
                    )));
                }
                let split = state.split();
                mesh.reserve(count, 3 * count, 2 * count);
                // Splits the elements of `part`, in order, adding the
                // vertex made from each to `made`.
                let split_all = |mesh: &mut Mesh,
                                 state: &mut RunState,
                                 part: &[Elem],
                                 made: &mut Vec<VertexId>|
                 -> Result<(), RunError> {
                    let first = made.len();
                    for val in part {
                        let v = if let Some(vs) = host::face_vertices(val) {
                            let Some(f) = face_of(mesh, vs) else {
                                return Err(fail("a face to split is gone".into()));
                            };
                            let p = vs.iter().map(|v| mesh.position(*v)).sum::<DVec3>() / 3.0;
                            mesh.face_split_with(f, p, &split)
                                .map_err(|e| fail(e.message))?
                        } else if let Some((p, q)) = host::edge_vertices(val) {
                            let e = edge_id(val);
                            debug_assert!({
                                let (a, b) = mesh.edge_vertices(e);
                                (a, b) == (p, q) || (a, b) == (q, p)
                            });
                            let at = (mesh.position(p) + mesh.position(q)) * 0.5;
                            mesh.edge_split_with(e, at, &split)
                                .map_err(|e| fail(e.message))?
                        } else {
                            unreachable!("a split rule matches faces and edges")
                        };
                        made.push(v);
                    }
                    if state.adaptive {
                        state.made_now.extend(&made[first..]);
                    }
                    state.current_level = made[first..]
                        .iter()
                        .map(|v| mesh.vertex_level(*v))
                        .fold(state.current_level, u32::max);
                    Ok(())
                };
                let run_step = state.step;
                let slot = rule.elem_slot as usize;
                // Evaluates the points of `matched`, whose new vertices
                // are `made`, `batch` at a time, writing each batch before
                // the next is computed; the error of the first bad one.
                let points = |mesh: &mut Mesh,
                              assign: &Ex,
                              matched: &[Elem],
                              made: &[VertexId],
                              batch: usize|
                 -> Result<(), RunError> {
                    let vslot = rule.vertex_slot.expect("an assignment names its vertex") as usize;
                    let bind = |frame: &mut [Value], k: usize| {
                        frame[slot] = Value::Elem(matched[k]);
                        frame[vslot] = Value::Elem(host::vertex(made[k]));
                    };
                    let bad = |(k, p): (usize, Result<Value, RuntimeError>)| match p {
                        Ok(Value::V3(p)) => fail(format!(
                            "new vertex {} would be at {p}, which is not finite",
                            made[k]
                        )),
                        Ok(_) => fail("the assignment did not give a point".into()),
                        Err(e) => self.runtime_error(rule, step, e),
                    };
                    for lo in (0..made.len()).step_by(batch.max(1)) {
                        let range = lo..(lo + batch).min(made.len());
                        let out = self
                            .eval_points(rule, mesh, current, run_step, assign, range, bind)
                            .map_err(bad)?;
                        for (v, p) in made[lo..].iter().zip(out) {
                            mesh.set_position(*v, p);
                        }
                    }
                    Ok(())
                };
                match &rule.assign {
                    // Each part's points right after its splits (they read
                    // nothing the later splits change), a batch at a
                    // time, and the part let go: the matches are never
                    // held whole while the mesh grows. The errors are
                    // those of splitting everything first: a bad point
                    // waits until the other splits and the valence check
                    // have passed.
                    Some(assign) if rule.points_between_splits => {
                        let mut bad = None;
                        let (mut matched, mut made) = (Vec::new(), Vec::new());
                        let mut parts = parts.into_iter().peekable();
                        while let Some(part) = parts.next() {
                            split_all(mesh, state, &part, &mut made)?;
                            matched.extend_from_slice(&part);
                            drop(part);
                            if matched.len() >= BETWEEN_SPLITS_BATCH || parts.peek().is_none() {
                                if bad.is_none() {
                                    bad =
                                        points(mesh, assign, &matched, &made, matched.len()).err();
                                }
                                matched.clear();
                                made.clear();
                            }
                        }
                        state.check_valence(mesh).map_err(fail)?;
                        bad.map_or(Ok(()), Err)
                    }
                    assign => {
                        let matched = parts.concat();
                        drop(parts);
                        // The vertex made from each matched element, in
                        // order.
                        let mut made: Vec<VertexId> = Vec::with_capacity(matched.len());
                        split_all(mesh, state, &matched, &mut made)?;
                        state.check_valence(mesh).map_err(fail)?;
                        let Some(assign) = assign else {
                            return Ok(());
                        };
                        // Where no point reads another, a batch's points
                        // are written before the next batch is computed,
                        // and only a batch is held; else all are computed
                        // first. A bad point stops the rule before its
                        // batch is written.
                        let batch = if rule.points_in_place {
                            POINT_BATCH
                        } else {
                            made.len()
                        };
                        points(mesh, assign, &matched, &made, batch)
                    }
                }
            }
        }
    }
}

/// A grammar's run on a mesh, from [`Grammar::start`]: the mesh and what
/// the run carries from rule to rule and step to step. Each call of
/// [`GrammarRun::steps`] continues where the last one stopped. After an
/// error the mesh is partly derived, and the run should not be continued.
#[derive(Debug)]
pub struct GrammarRun<'a> {
    grammar: &'a Grammar,
    mesh: &'a mut Mesh,
    state: RunState,
    /// The step [`crate::production::run`] runs to.
    until: u32,
}

impl GrammarRun<'_> {
    /// Runs `n` more steps; `progress` hears after each, counted from 1 in
    /// this call.
    pub fn steps(
        &mut self,
        n: usize,
        mut progress: impl FnMut(StepCounts),
    ) -> Result<(), RunError> {
        for k in 1..=n {
            self.one_step()?;
            progress(StepCounts {
                step: k,
                vertices: self.mesh.vertex_count(),
                edges: self.mesh.edge_count(),
                faces: self.mesh.face_count(),
            });
        }
        Ok(())
    }

    /// The steps run so far (0 after the `init:` rules).
    pub fn step(&self) -> u32 {
        self.state.step
    }

    /// One step: the rules in file order, each applied to what matched when
    /// it started, then the second position buffer made current.
    fn one_step(&mut self) -> Result<(), RunError> {
        let each: Vec<&Rule> = self.grammar.rules.iter().filter(|r| !r.init).collect();
        // Vertices made from here on record this step (`new(v)`).
        self.state.step += 1;
        self.state.made_before = std::mem::take(&mut self.state.made_now);
        self.grammar.apply_all(&each, self.mesh, &mut self.state)?;
        self.state.swap_positions(self.mesh);
        // A step is one level of the scheme: semi-sharp creases and
        // corners soften by one (OpenSubdiv's uniform rule). The rules of
        // the step read the sharpness it started with.
        if self.state.creased {
            self.mesh.decrement_sharpness();
        }
        debug_assert!(
            self.state
                .protect
                .as_ref()
                .is_none_or(|p| p.intact(self.mesh)),
            "a rule rewrote a protected element"
        );
        Ok(())
    }

    /// The mesh as the run has made it.
    pub fn mesh(&self) -> &Mesh {
        self.mesh
    }

    /// Moves vertex `v` between steps (the next step reads `p`): how
    /// `subgram analyze` puts an impulse on a mesh the run has made.
    pub fn set_position(&mut self, v: VertexId, p: DVec3) {
        self.mesh.set_position(v, p);
    }

    /// Stops the run with an error once `deadline` passes: it is looked
    /// at before every rule.
    pub fn set_deadline(&mut self, deadline: Option<crate::Deadline>) {
        self.state.deadline = deadline;
    }
}

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

/// The points of a split rule whose points read no other new vertex
/// (`Rule::points_in_place`) are computed and written this many at a
/// time.
const POINT_BATCH: usize = 16 * CHUNK;

/// The points of a split rule that are computed between its splits
/// (`Rule::points_between_splits`) are computed this many at a time (at
/// least: whole parts of the matches).
const BETWEEN_SPLITS_BATCH: usize = 4 * CHUNK;

/// Elements per parallel task: small jobs stay on one thread. A multiple
/// of 64, so that a block's flags in [`NextPositions`] are whole words.
const CHUNK: usize = 16384;

/// The positions vertex rules write for the next step, by vertex slot,
/// in blocks of [`CHUNK`] slots, filled while the rules run and made
/// current when the step ends. A later rule's point for a vertex replaces
/// an earlier one's.
///
/// A block keeps each written point as its difference from the vertex's
/// current position: per coordinate, the new bits minus the current bits,
/// as integers (wrapping), which gives back the same bits whatever the
/// numbers. A vertex moves little against its coordinates (at three levels
/// of Loop on a sphere, almost every one by less than 2^39 units in the
/// last place), so the
/// differences fit in fewer bytes than a coordinate: each block stores
/// them in the width ([`Block::width`], 1 to 8 bytes) that makes it
/// smallest, and the points whose differences do not fit (a coordinate
/// near 0, which moves by many of its units in the last place) in a list
/// of their own. Vertex rules never move a vertex otherwise, and splits
/// place only the vertices they make, so a written slot's current
/// position is the same when it is written and when the step ends.
#[derive(Debug, Default)]
struct NextPositions {
    blocks: Vec<Block>,
}

/// The next positions of [`CHUNK`] vertex slots (fewer in the last
/// block): see [`NextPositions`].
#[derive(Debug, Default)]
struct Block {
    /// The slots of the block.
    len: usize,
    /// Bytes per coordinate's difference in `diffs`; 0 while nothing is
    /// written.
    width: usize,
    /// Three differences a slot, `width` bytes each, little-endian, and
    /// [`Block::PAD`] bytes after them.
    diffs: Vec<u8>,
    /// The slots written.
    written: Vec<u64>,
    /// The written slots whose last point is in `wide`.
    is_wide: Vec<u64>,
    /// Points whose differences do not fit `width` bytes, with their
    /// places in the block, in the order written: a later one for a slot
    /// replaces an earlier one.
    wide: Vec<(u32, DVec3)>,
}

/// The difference of `next`'s coordinates from `cur`'s, as integers: the
/// bits of `next` are `cur`'s plus it, wrapping.
#[inline]
fn bit_difference(cur: DVec3, next: DVec3) -> [i64; 3] {
    let d = |c: f64, n: f64| (n.to_bits() as i64).wrapping_sub(c.to_bits() as i64);
    [d(cur.x, next.x), d(cur.y, next.y), d(cur.z, next.z)]
}

/// `cur` moved by a [`bit_difference`].
#[inline]
fn add_bit_difference(cur: DVec3, d: [i64; 3]) -> DVec3 {
    let a = |c: f64, d: i64| f64::from_bits((c.to_bits() as i64).wrapping_add(d) as u64);
    DVec3::new(a(cur.x, d[0]), a(cur.y, d[1]), a(cur.z, d[2]))
}

/// The fewest bytes that hold each of `d` as a signed number (1 to 8).
#[inline]
fn bytes_needed(d: [i64; 3]) -> usize {
    // A number fits in b bytes when its bits above the lowest 8b - 1 are
    // copies of its sign.
    let bits = d
        .iter()
        .map(|&x| 64 - (x ^ (x >> 63)).leading_zeros() as usize + 1)
        .max()
        .unwrap_or(1);
    bits.div_ceil(8).max(1)
}

#[inline]
fn bit(words: &[u64], i: usize) -> bool {
    (words[i >> 6] >> (i & 63)) & 1 != 0
}

#[inline]
fn set_bit(words: &mut [u64], i: usize, value: bool) {
    if value {
        words[i >> 6] |= 1 << (i & 63);
    } else {
        words[i >> 6] &= !(1 << (i & 63));
    }
}

impl Block {
    /// Bytes a wide point takes in `wide`.
    const WIDE_BYTES: usize = std::mem::size_of::<(u32, DVec3)>();

    /// Bytes after the last difference, so that each is read and written
    /// as the 8 bytes from where it starts.
    const PAD: usize = 8;

    /// The 8 bytes of `diffs` from `at`, as a number.
    #[inline]
    fn word(&self, at: usize) -> u64 {
        let mut b = [0u8; 8];
        b.copy_from_slice(&self.diffs[at..at + 8]);
        u64::from_le_bytes(b)
    }

    /// Grows the block to `len` slots, none of the new ones written.
    fn grow(&mut self, len: usize) {
        if len <= self.len {
            return;
        }
        self.len = len;
        self.written.resize(len.div_ceil(64), 0);
        self.is_wide.resize(len.div_ceil(64), 0);
        if self.width > 0 {
            self.diffs.resize(3 * self.width * len + Self::PAD, 0);
        }
    }

    /// The difference stored for slot `i` (written, not wide).
    #[inline]
    fn stored(&self, i: usize) -> [i64; 3] {
        let w = self.width;
        let at = 3 * w * i;
        // The lowest `w` bytes, sign-extended.
        let shift = 64 - 8 * w as u32;
        std::array::from_fn(|k| ((self.word(at + k * w) << shift) as i64) >> shift)
    }

    /// Stores `d`, which fits `width` bytes, for slot `i`.
    #[inline]
    fn store(&mut self, i: usize, d: [i64; 3]) {
        let w = self.width;
        let at = 3 * w * i;
        // The lowest `w` bytes of each; the bytes after them are kept.
        let mask = u64::MAX >> (64 - 8 * w as u32);
        for (k, &x) in d.iter().enumerate() {
            let o = at + k * w;
            let word = (self.word(o) & !mask) | (x as u64 & mask);
            self.diffs[o..o + 8].copy_from_slice(&word.to_le_bytes());
        }
    }

    /// Records `p` for slot `i`, whose current position is `cur`.
    #[inline]
    fn put(&mut self, i: usize, cur: DVec3, p: DVec3) {
        let d = bit_difference(cur, p);
        set_bit(&mut self.written, i, true);
        let wide = bytes_needed(d) > self.width;
        set_bit(&mut self.is_wide, i, wide);
        if wide {
            self.wide.push((i as u32, p));
        } else {
            self.store(i, d);
        }
    }

    /// Records `points` (places in the block, in increasing order, and
    /// points) given the current positions `cur` of the block's slots,
    /// first widening the block where the points and those written
    /// before take less room that way.
    fn write(&mut self, cur: &[DVec3], points: &[(u32, DVec3)]) {
        debug_assert_eq!(cur.len(), self.len);
        if points.is_empty() {
            return;
        }
        // How many points need each width: the new ones and the last
        // of each slot before.
        let mut need = [0usize; 9];
        for &(i, p) in points {
            need[bytes_needed(bit_difference(cur[i as usize], p))] += 1;
        }
        if self.width > 0 {
            for i in 0..self.len {
                if bit(&self.written, i) && !bit(&self.is_wide, i) {
                    need[self.width] += 1;
                }
            }
            for &(i, p) in &self.wide {
                need[bytes_needed(bit_difference(cur[i as usize], p))] += 1;
            }
        }
        // The width that takes the least room from the current one up
        // (the widest that does, where several do).
        let cost =
            |w: usize| 3 * w * self.len + Self::WIDE_BYTES * need[w + 1..].iter().sum::<usize>();
        let best = (self.width.max(1)..=8)
            .rev()
            .min_by_key(|&w| cost(w))
            .unwrap_or(8);
        if best > self.width {
            self.widen(best, cur);
        }
        for &(i, p) in points {
            self.put(i as usize, cur[i as usize], p);
        }
    }

    /// Stores every difference in `width` bytes, more than now, and takes
    /// the wide points that then fit out of `wide`.
    fn widen(&mut self, width: usize, cur: &[DVec3]) {
        let fresh = Block {
            len: self.len,
            width,
            diffs: vec![0; 3 * width * self.len + Self::PAD],
            written: std::mem::take(&mut self.written),
            is_wide: std::mem::take(&mut self.is_wide),
            wide: Vec::new(),
        };
        let old = std::mem::replace(self, fresh);
        if old.width > 0 {
            for i in 0..self.len {
                if bit(&self.written, i) && !bit(&self.is_wide, i) {
                    self.store(i, old.stored(i));
                }
            }
        }
        // The last point of each wide slot, from the end.
        let mut seen = vec![0u64; self.len.div_ceil(64)];
        let mut still = Vec::new();
        for &(i, p) in old.wide.iter().rev() {
            let k = i as usize;
            if bit(&seen, k) || !bit(&self.is_wide, k) {
                continue;
            }
            set_bit(&mut seen, k, true);
            let d = bit_difference(cur[k], p);
            if bytes_needed(d) <= width {
                self.store(k, d);
                set_bit(&mut self.is_wide, k, false);
            } else {
                still.push((i, p));
            }
        }
        still.reverse();
        self.wide = still;
    }

    /// Gives the written slots their points; `pos` holds the block's
    /// current positions.
    fn make_current(&self, pos: &mut [DVec3]) {
        for (i, p) in pos.iter_mut().enumerate().take(self.len) {
            if bit(&self.written, i) && !bit(&self.is_wide, i) {
                *p = add_bit_difference(*p, self.stored(i));
            }
        }
        for &(i, p) in &self.wide {
            if bit(&self.is_wide, i as usize) {
                pos[i as usize] = p;
            }
        }
    }

    /// The bytes the block holds.
    #[cfg(test)]
    fn bytes(&self) -> usize {
        self.diffs.len()
            + 8 * (self.written.len() + self.is_wide.len())
            + Self::WIDE_BYTES * self.wide.len()
    }
}

impl NextPositions {
    /// Room for every vertex slot of `mesh`, none of the new ones written.
    fn cover(&mut self, mesh: &Mesh) {
        let n = mesh.v_alive.len();
        let blocks = n.div_ceil(CHUNK);
        let k = self.blocks.len().saturating_sub(1);
        if let Some(last) = self.blocks.last_mut() {
            last.grow((n - k * CHUNK).min(CHUNK));
        }
        while self.blocks.len() < blocks {
            let k = self.blocks.len();
            let mut b = Block::default();
            b.grow((n - k * CHUNK).min(CHUNK));
            self.blocks.push(b);
        }
    }

    /// Records `points` (vertices in increasing order of id, and their
    /// points) given the current positions `pos`.
    fn write(&mut self, pos: &[DVec3], points: &[(VertexId, DVec3)]) {
        let mut rest = points;
        while let Some(&(v, _)) = rest.first() {
            let k = v.index() / CHUNK;
            let n = rest
                .iter()
                .position(|(w, _)| w.index() / CHUNK != k)
                .unwrap_or(rest.len());
            let lo = k * CHUNK;
            let block: Vec<(u32, DVec3)> = rest[..n]
                .iter()
                .map(|&(w, p)| ((w.index() - lo) as u32, p))
                .collect();
            let b = &mut self.blocks[k];
            b.write(&pos[lo..lo + b.len], &block);
            rest = &rest[n..];
        }
    }

    /// Gives the written vertices their points.
    fn make_current(self, mesh: &mut Mesh) {
        self.blocks
            .par_iter()
            .zip(mesh.pos.par_chunks_mut(CHUNK))
            .for_each(|(b, pos)| b.make_current(pos));
    }
}

/// How one task of a vertex rule ended (see `Grammar::apply_vertex_rule`).
#[derive(Default)]
struct VertexTask {
    /// The first condition that failed to evaluate, which stopped it.
    error: Option<RuntimeError>,
    /// The first matched vertex, by its place among the ids tested, whose
    /// point was not finite or not a point.
    bad: Option<usize>,
}

/// An error of `rule` at `step` (0: the `init:` rules).
fn rule_error(rule: &Rule, step: usize, m: String) -> RunError {
    RunError {
        span: Some(rule.span),
        message: if step == 0 {
            format!("at initialization, rule `{}`: {m}", rule.text)
        } else {
            format!("at step {step}, rule `{}`: {m}", rule.text)
        },
    }
}

/// True when `e`, a split rule's assignment, reads positions only through
/// `pos` or `avg` of the matched element in slot `elem`: the split face's
/// or edge's own corners, which are there before the rule and keep their
/// positions until the step ends. Everything else it may read is a
/// number that no position changes (levels, valences, `c`, the step) or
/// arithmetic. Conservative: anything else says no.
fn reads_only_matched_positions(e: &Ex, elem: u16) -> bool {
    let mut ok = true;
    e.walk(&mut |x| match x {
        Ex::Call(Func::Host(id::POS | id::AVG_OF), args, _) => {
            ok &= matches!(args.as_slice(), [Ex::Local(s)] if *s == elem);
        }
        Ex::Call(
            Func::Host(id::VALENCE | id::LEVEL | id::CURRENT | id::STEP | id::CREASES),
            ..,
        ) => {}
        Ex::Let(s, ..) => ok &= *s != elem,
        Ex::Const(_)
        | Ex::Local(_)
        | Ex::Bin(..)
        | Ex::Neg(_)
        | Ex::Not(_)
        | Ex::Logic(..)
        | Ex::Cond(..)
        | Ex::Convert(..)
        | Ex::MakeV3(..) => {}
        _ => ok = false,
    });
    ok
}

/// True when `e` calls `valence` or `creases`, which the splits of other
/// elements may change while a split rule runs.
fn reads_counts(e: &Ex) -> bool {
    let mut found = false;
    e.walk(&mut |x| {
        found |= matches!(x, Ex::Call(Func::Host(id::VALENCE | id::CREASES), ..));
    });
    found
}

/// The id of a matched edge's value.
/// Whether vertex `v` is one a vertex rule looks at (alive, on an edge,
/// not protected): `None` when it is not, else whether the rule's context
/// (`| boundary`, `| interior`) holds there; the guard is tested after.
fn vertex_candidate(
    mesh: &Mesh,
    v: VertexId,
    protect: Option<&Protected>,
    rule: &Rule,
) -> Option<bool> {
    if !mesh.is_vertex(v)
        || mesh.outgoing(v).is_none()
        || protect.is_some_and(|p| !p.vertex_free(v))
    {
        return None;
    }
    Some(match rule.context {
        VertexContext::Any => true,
        VertexContext::Boundary => mesh.is_boundary_vertex(v),
        VertexContext::Interior => !mesh.is_boundary_vertex(v),
    })
}

fn edge_id(val: &Elem) -> EdgeId {
    host::edge_id(val).expect("an edge value")
}

/// An edge as a rule's value: its ends (a boundary edge runs the way its
/// face does), level and marks, `block` the block mark it shows.
fn edge_value(mesh: &Mesh, e: EdgeId, block: bool) -> Elem {
    let h = e.halfedge();
    let h = if mesh.face(h).is_none() { h.twin() } else { h };
    host::edge(
        mesh.from(h),
        mesh.to(h),
        mesh.edge_level(e),
        mesh.is_boundary_edge(e),
        block,
        mesh.is_transversal_edge(e),
        mesh.is_sharp_edge(e),
        e,
    )
}

/// An adaptive run starts on a 4-8 mesh: every face has exactly one edge
/// that is a block's internal edge (so every face is half of a block,
/// or of a boundary half-block), and vertices are numbered in the order
/// they were made ([`Mesh::refinement_edge`] reads the newest vertex).
fn check_adaptive_start(mesh: &Mesh) -> Result<(), String> {
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

fn face_of(mesh: &Mesh, vs: [VertexId; 3]) -> Option<crate::mesh::FaceId> {
    mesh.find_face(vs)
}

/// The message alone; [`crate::Surface::error`] adds the rule's line and
/// caret.
impl std::fmt::Display for RunError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for RunError {}

/// The stellar topology's schedule: rules in file order, each on what
/// matched when it started.
impl crate::production::Topology for GrammarRun<'_> {
    type Structure = Mesh;
    type Error = RunError;

    fn host_table() -> &'static crate::lang::builtins::HostTable {
        &SURFACE_HOST
    }

    fn structure(&self) -> &Mesh {
        self.mesh
    }

    fn steps_done(&self) -> u64 {
        self.state.step as u64
    }

    fn has_next(&self) -> bool {
        self.state.step < self.until
    }

    fn step(&mut self) -> Result<(), RunError> {
        self.one_step()
    }
}

#[cfg(test)]
mod tests {
    use std::path::PathBuf;

    use glam::DVec3;

    use super::{bytes_needed, Grammar, NextPositions, CHUNK};
    use crate::mesh::{io, shapes, Mesh, VertexId};

    use crate::testing::xorshift as rng;

    #[test]
    fn bytes_needed_is_the_narrowest_signed_width() {
        let mut next = rng(77);
        let mut xs = vec![
            0i64,
            1,
            -1,
            127,
            128,
            -128,
            -129,
            255,
            256,
            i64::MAX,
            i64::MIN,
        ];
        for b in 1..8 {
            let edge = 1i64 << (8 * b - 1);
            xs.extend([edge - 1, edge, -edge, -edge - 1]);
        }
        xs.extend((0..1000).map(|_| (next() as i64) >> (next() % 64)));
        for x in xs {
            // The smallest b with -2^(8b-1) <= x < 2^(8b-1), in i128.
            let want = (1..=8)
                .find(|&b| {
                    let half = 1i128 << (8 * b - 1);
                    (-half..half).contains(&(x as i128))
                })
                .expect("8 bytes hold any i64");
            assert_eq!(bytes_needed([x, 0, 0]), want, "{x}");
            assert_eq!(bytes_needed([0, x, -1]), want, "{x}");
        }
    }

    /// The next positions against a plain list of the last point written
    /// for each slot: rounds of writes (a round is a vertex rule: some
    /// slots, in id order), with small moves, none, sign changes, zeros
    /// of either sign, huge moves and subnormal numbers, on a mesh that
    /// grows between rounds; every coordinate must come back to the bit.
    #[test]
    fn next_positions_give_back_the_last_point_of_every_slot_to_the_bit() {
        let mut next = rng(0x51_7cc1_b727_220a);
        let mut unit = move || (next() >> 11) as f64 / (1u64 << 53) as f64;
        let mut m = Mesh::from_soup(&shapes::triangle_grid(150, 120)).expect("a grid");
        let n0 = m.v_alive.len();
        assert!(n0 > CHUNK, "more than one block");
        let magnitudes = [1e-300, 1e-9, 0.5, 3.0, 1e6, 1e300];
        for i in 0..n0 {
            let c = |u: f64, k: f64| (u - 0.5) * magnitudes[(k * 6.0) as usize % 6];
            let p = DVec3::new(c(unit(), unit()), c(unit(), unit()), c(unit(), unit()));
            m.set_position(VertexId(i as u32), p);
        }
        m.set_position(VertexId(3), DVec3::new(0.0, -0.0, f64::MIN_POSITIVE / 8.0));
        let mut buf = NextPositions::default();
        let mut plain: Vec<Option<DVec3>> = vec![None; n0];
        for round in 0..5 {
            if round == 2 {
                // New vertices between rules (a split rule's).
                for k in 0..CHUNK + 100 {
                    m.new_vertex(DVec3::splat(k as f64 * 0.25 - 7.0), 1, 1);
                }
                plain.resize(m.v_alive.len(), None);
            }
            buf.cover(&m);
            let share = [0.9, 0.8, 0.5, 0.05, 0.6][round];
            let mut points = Vec::new();
            for (i, last) in plain.iter_mut().enumerate() {
                if unit() >= share {
                    continue;
                }
                let cur = m.position(VertexId(i as u32));
                // The kinds of point: a tiny move, a move as a smoothing
                // step makes, none, a sign change, zeros, a huge move, a
                // subnormal point. The first rounds are mostly tiny
                // moves, then mostly larger ones, so that blocks widen
                // over points that were wide before.
                let weights: [f64; 7] = match round {
                    0 | 3 => [0.93, 0.03, 0.01, 0.01, 0.005, 0.01, 0.005],
                    1 => [0.02, 0.9, 0.02, 0.02, 0.01, 0.02, 0.01],
                    _ => [0.3, 0.3, 0.1, 0.1, 0.05, 0.1, 0.05],
                };
                let mut r = unit();
                let kind = weights
                    .iter()
                    .position(|&w| {
                        r -= w;
                        r < 0.0
                    })
                    .unwrap_or(6);
                let t = unit() - 0.5;
                let p = match kind {
                    0 => cur + cur * t * 1e-12,
                    1 => cur + cur * t * 1e-7,
                    2 => cur,
                    3 => -cur,
                    4 => DVec3::new(0.0, -0.0, cur.z),
                    5 => cur * 1e200 + DVec3::splat(t),
                    _ => DVec3::splat(f64::MIN_POSITIVE * t),
                };
                *last = Some(p);
                points.push((VertexId(i as u32), p));
            }
            buf.write(&m.pos, &points);
        }
        let before = m.pos.clone();
        // Small moves everywhere take fewer bytes than the points.
        buf.make_current(&mut m);
        for (i, (&got, (&was, want))) in m.pos.iter().zip(before.iter().zip(&plain)).enumerate() {
            let want = want.unwrap_or(was);
            assert_eq!(
                got.to_array().map(f64::to_bits),
                want.to_array().map(f64::to_bits),
                "slot {i}"
            );
        }
    }

    /// Writes that move every vertex a little take fewer bytes than the
    /// points would (24 a slot), and one far move among them goes to the
    /// block's list of wide points instead of widening the block.
    #[test]
    fn small_moves_take_fewer_bytes_than_points() {
        let mut m = Mesh::from_soup(&shapes::triangle_grid(150, 120)).expect("a grid");
        let n = m.v_alive.len();
        let mut next = rng(9);
        let mut points: Vec<(VertexId, DVec3)> = (0..n)
            .map(|i| {
                let v = VertexId(i as u32);
                let p = m.position(v) + DVec3::splat(1.0);
                m.set_position(v, p);
                let t = (next() >> 11) as f64 / (1u64 << 53) as f64;
                (v, p * (1.0 + 1e-10 * (t - 0.5)))
            })
            .collect();
        points[5].1 = DVec3::splat(-1e100);
        let mut buf = NextPositions::default();
        buf.cover(&m);
        buf.write(&m.pos, &points);
        let bytes: usize = buf.blocks.iter().map(|b| b.bytes()).sum();
        assert!(bytes < 12 * n, "{bytes} bytes for {n} slots");
        assert_eq!(buf.blocks[0].wide.len(), 1);
        buf.make_current(&mut m);
        for (v, p) in points {
            assert_eq!(
                m.position(v).to_array().map(f64::to_bits),
                p.to_array().map(f64::to_bits)
            );
        }
    }

    fn grammar(name: &str, text: &str) -> Grammar {
        let front = crate::load::front(name, text.to_string(), &[]).expect("reads");
        crate::surface::from_front_with(front, true).unwrap_or_else(|e| panic!("{e}"))
    }

    /// A mesh of `lsystems/meshes`.
    fn mesh_file(name: &str) -> Mesh {
        let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("lsystems/meshes");
        io::read_mesh(&dir.join(name)).expect("a mesh")
    }

    /// Runs `g` `steps` steps on `mesh`, with the points of split rules
    /// computed between their splits where `between` allows it, and after
    /// all of them otherwise.
    fn run_with(g: &mut Grammar, mesh: &Mesh, steps: usize, between: bool) -> Result<Mesh, String> {
        for r in &mut g.rules {
            r.points_between_splits &= between;
        }
        let mut m = mesh.clone();
        g.run(&mut m, steps, |_| {})
            .map(|()| m)
            .map_err(|e| g.render_error(&e))
    }

    fn same_bits(a: &Mesh, b: &Mesh) -> bool {
        a == b
            && a.pos
                .iter()
                .zip(&b.pos)
                .all(|(p, q)| p.to_array().map(f64::to_bits) == q.to_array().map(f64::to_bits))
    }

    /// A split rule's points computed right after each part of its splits
    /// give the mesh that computing them after all splits gives, to the
    /// bit: Loop, Catmull-Clark, √3, c4 and 4-8 (their `avg(e)` and
    /// `avg(f)` split rules compute points between splits) on their own
    /// meshes, the bunny and a sphere of two batches. A point that reads a
    /// valence, which later splits change, is computed after all of them,
    /// and a bad point gives the error it gives after all splits.
    #[test]
    fn points_between_splits_are_the_points_after_all_splits() {
        let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("lsystems/surfaces");
        let mut between = 0;
        let sphere = Mesh::from_soup(&shapes::icosphere(6)).expect("a sphere");
        for file in [
            "loop.lsys",
            "catmull-clark.lsys",
            "sqrt3.lsys",
            "c4.lsys",
            "four-eight.lsys",
        ] {
            let text = std::fs::read_to_string(dir.join(file)).expect("reads");
            let mut g = grammar(file, &text);
            between += g.rules.iter().filter(|r| r.points_between_splits).count();
            let own = g.mesh.clone().expect("names its mesh").0;
            let own = mesh_file(own.trim_start_matches("../meshes/"));
            // The icosphere's 122,880 edges are eight parts of matches and
            // two batches of points.
            for (mesh, steps) in [(&own, 3), (&mesh_file("bunny.obj"), 1), (&sphere, 1)] {
                let a = run_with(&mut grammar(file, &text), mesh, steps, true);
                let b = run_with(&mut g, mesh, steps, false);
                match (a, b) {
                    (Ok(a), Ok(b)) => assert!(same_bits(&a, &b), "{file}"),
                    (Err(a), Err(b)) => assert_eq!(a, b, "{file}"),
                    (a, b) => panic!("{file}: {:?} and {:?}", a.err(), b.err()),
                }
            }
        }
        assert!(
            between >= 3,
            "{between} rules compute points between splits"
        );
        // A point that reads the new vertex's valence: the splits of the
        // edges after its own raise it, so it waits for all of them (on
        // the sphere, whose edges make two batches).
        let valence = "mesh: \"../meshes/octahedron.obj\";\n\
            E(e) | F^2 -> V(v = avg(e) * (1 + 0.01 * valence(v))) || E^4 F^4;\n";
        let mut g = grammar("valence.lsys", valence);
        assert!(!g.rules[0].points_between_splits && g.rules[0].points_in_place);
        let after = run_with(&mut g, &sphere, 1, true).expect("runs");
        let mut wrong = grammar("valence.lsys", valence);
        wrong.rules[0].points_between_splits = true;
        let early = run_with(&mut wrong, &sphere, 1, true).expect("runs");
        assert!(
            !same_bits(&after, &early),
            "the valences differ between splits"
        );
        // A bad point is the error it is after all splits.
        let bad = "mesh: \"../meshes/bunny.obj\";\n\
            E(e) | F^2 -> V(v = avg(e) / (l(e) - l(e))) || E^4 F^4;\n\
            E(e) | F -> V(v = avg(e)) || E^3 F^2;\n";
        let bunny = mesh_file("bunny.obj");
        let a = run_with(&mut grammar("bad.lsys", bad), &bunny, 1, true);
        let b = run_with(&mut grammar("bad.lsys", bad), &bunny, 1, false);
        assert!(a.is_err());
        assert_eq!(a.err(), b.err());
    }
}
