//! Compiling a parsed grammar file: each rule's condition and assignment
//! checked by the language's one checker, specialised, and read for what
//! they need (blocks, `refined`, which positions their points read).

use crate::lang::compile::RuleCompiler;
use crate::lang::eval::{Env, Interp};
use crate::lang::ir::{Ex, Func};
use crate::lang::value::{Ty, Value};
use crate::mesh::{BlockSplit, Creasing, Mesh};
use crate::surface::grammar::{GrammarFile, Op};
use crate::surface::host::{self, id, MeshHost};
use crate::syntax::span::{Diagnostic, SourceMap, Span};

use super::{Grammar, GrammarRun, Rule, MAX_FACES, MAX_VALENCE};

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
                    creasing: Creasing::Uniform,
                };
                let got = Interp::new(&[]).eval(
                    &x,
                    &mut vec![Value::Void; c.frame_size().max(1)],
                    &mut Env::with_model(Vec::new(), crate::model::default_ref()),
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
        creasing: file.creasing.map_or(Creasing::Uniform, |(c, _)| c),
        match_blocks_at: file.match_blocks,
        max_faces: MAX_FACES,
        max_valence: MAX_VALENCE,
        warnings,
    })
}

/// True when `e`, a split rule's assignment, reads positions only through
/// `pos` or `avg` of the matched element in slot `elem`: the split face's
/// or edge's own corners, which are there before the rule and keep their
/// positions until the step ends. Everything else it may read is a
/// number that no position changes (levels, valences, `c`, the step) or
/// arithmetic. Conservative: anything else says no.
pub(super) fn reads_only_matched_positions(e: &Ex, elem: u16) -> bool {
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
pub(super) fn reads_counts(e: &Ex) -> bool {
    let mut found = false;
    e.walk(&mut |x| {
        found |= matches!(x, Ex::Call(Func::Host(id::VALENCE | id::CREASES), ..));
    });
    found
}
