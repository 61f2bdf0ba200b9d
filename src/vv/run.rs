//! Running a vv program: the base mesh into the rotation system, `Start`,
//! then each step `StartEach`, `Step`, `EndEach`, the consistency check of
//! the mesh and the release of vertices nothing holds; `End` after the
//! last step.

use std::path::PathBuf;

use crate::deadline::Deadline;
use crate::lang::eval::{Env, Interp, RuntimeError};
use crate::lang::ir::{Program, St};
use crate::lang::value::Value;
use crate::mesh::PolygonSoup;
use crate::production::Topology;
use crate::syntax::ast::ControlKind;
use crate::syntax::{Diagnostic, SourceMap, Span};

use super::host::{self, Layout, Layouts, VvHost, VV_HOST};
use super::mesh::Rotation;

/// The most steps a vv program may run.
pub const MAX_VV_STEPS: u64 = 1000;

/// The most vertices a vv mesh may hold, by default: about 500 MB of
/// neighbour lists, positions and their synchronized copies (Loop makes
/// 655,362 from an 81,920-triangle sphere in two steps, 2.6 million in
/// three). `SUBGRAM_MAX_VERTICES=N` in the environment sets another bound.
pub const MAX_VV_VERTICES: usize = 2_000_000;

/// The environment variable that sets the vertex limit.
const MAX_VERTICES_VAR: &str = "SUBGRAM_MAX_VERTICES";

/// The vertex limit of a run: the environment's, else `default`.
fn vertex_limit(default: usize) -> Result<usize, String> {
    crate::limits::from_env(MAX_VERTICES_VAR, default as u64, "a whole number").map(|n| n as usize)
}

/// The environment variable that sets the valence limit, as for surface
/// grammars: `SUBGRAM_MAX_VALENCE=5000`.
use crate::surface::run::MAX_VALENCE_VAR;

/// The valence limit: [`MAX_VALENCE_VAR`] where it is set, else the
/// surface grammars' default (1000); raised to twice the base mesh's
/// highest valence.
fn valence_limit(mesh: &Rotation, members: &[u32]) -> Result<usize, String> {
    let configured = crate::limits::from_env(
        MAX_VALENCE_VAR,
        crate::surface::run::MAX_VALENCE as u64,
        "a whole number",
    )? as usize;
    let highest = members
        .iter()
        .map(|&v| mesh.valence(v, false).unwrap_or(0))
        .max()
        .unwrap_or(0);
    Ok(configured.max(2 * highest))
}

/// A checked vv program.
#[derive(Debug)]
pub struct VvProgram {
    pub program: Program,
    pub sources: SourceMap,
    pub warnings: Vec<Diagnostic>,
    /// The global `mesh` that is the structure: drawn, written, checked.
    pub structure: u16,
    /// Its name and where it is declared.
    pub structure_name: (String, Span),
    /// The base mesh file its declaration names (`mesh S = "cube.obj";`),
    /// as written, with the span of the string.
    pub base: Option<(String, Span)>,
    /// Creating a vertex beyond this many is an error
    /// (`MAX_VV_VERTICES` unless changed).
    pub max_vertices: usize,
}

/// Why a run stopped: a message, located in the program when a statement
/// is to blame.
#[derive(Clone, Debug, PartialEq)]
pub struct VvError {
    pub span: Option<Span>,
    pub message: String,
}

impl From<RuntimeError> for VvError {
    fn from(e: RuntimeError) -> VvError {
        VvError {
            span: e.span,
            message: e.message,
        }
    }
}

/// A vv program running on its mesh.
pub struct VvRun<'p> {
    vv: &'p VvProgram,
    pub mesh: Rotation,
    pub env: Env,
    layouts: Layouts,
    interp: Interp<'p>,
    /// The valence limit of this run (see `valence_limit`).
    max_valence: usize,
    /// The most vertices the run may make (see [`MAX_VV_VERTICES`]).
    max_vertices: usize,
    steps: u64,
    length: u64,
}

impl VvProgram {
    /// Starts a run on `base` (the base mesh's polygons, if any): the
    /// properties declared, the globals initialised, `Start` run; the
    /// steps to make are `steps`, else the derivation length, else 1.
    /// `seed` seeds every random number generator (`--seed`), as for
    /// curves; without it they start as lpfg's do.
    pub fn start(
        &self,
        base: Option<&PolygonSoup>,
        steps: Option<u64>,
        deadline: Option<Deadline>,
        output: crate::lang::ProgramOutput,
        seed: Option<u32>,
    ) -> Result<VvRun<'_>, VvError> {
        let program = &self.program;
        let mut interp = Interp::for_program(program, deadline);
        let mut env = Env::for_program(program, &mut interp, output, seed)?;
        let (mut mesh, members) = match base {
            Some(soup) => Rotation::from_soup(soup).map_err(|m| VvError {
                span: self.base.as_ref().map(|b| b.1),
                message: format!("the base mesh: {m}"),
            })?,
            None => (Rotation::new(), Vec::new()),
        };
        let max_valence = valence_limit(&mesh, &members).map_err(|message| VvError {
            span: None,
            message,
        })?;
        let max_vertices = vertex_limit(self.max_vertices).map_err(|message| VvError {
            span: None,
            message,
        })?;
        env.globals[self.structure as usize] = host::set_value(members);
        let mut layouts = Layouts::default();
        for p in &program.properties {
            let value = interp.eval_global(&p.init, &mut env)?.convert(p.ty);
            host::storable(&value).map_err(|message| VvError {
                span: Some(p.span),
                message,
            })?;
            let mut slots = vec![0.0; host::width(p.ty)];
            host::encode(&value, &mut slots);
            let index = match p.owner {
                0 => mesh.add_vertex_property(slots.len(), &slots),
                1 => mesh.add_edge_property(slots.len(), &slots),
                _ => mesh.add_mesh_property(slots.len(), &slots),
            };
            let l = Layout { ty: p.ty, index };
            match p.owner {
                0 => layouts.vertex.push(l),
                1 => layouts.edge.push(l),
                _ => layouts.mesh.push(l),
            }
        }
        // A step walks the whole mesh, some dozen iterations a vertex.
        interp.loop_limit = crate::lang::eval::LOOP_LIMIT.max(64 * max_vertices as u64);
        let mut run = VvRun {
            vv: self,
            mesh,
            env,
            layouts,
            interp,
            max_valence,
            max_vertices,
            steps: 0,
            length: 0,
        };
        let edits = run.mesh.topology_edits();
        run.control(ControlKind::Start)?;
        let stated = match &program.derivation_length {
            Some((e, span)) => {
                let v = run.interp.eval_global(e, &mut run.env)?.as_f64();
                if !(0.0..=MAX_VV_STEPS as f64).contains(&v) || v.fract() != 0.0 {
                    return Err(VvError {
                        span: Some(*span),
                        message: format!(
                            "the derivation length must be a whole number of steps from 0 to {MAX_VV_STEPS}"
                        ),
                    });
                }
                Some(v as u64)
            }
            None => None,
        };
        run.length = steps.or(stated).unwrap_or(1);
        if run.length > MAX_VV_STEPS {
            return Err(VvError {
                span: None,
                message: format!(
                    "{} steps are more than a vv program may run ({MAX_VV_STEPS})",
                    run.length
                ),
            });
        }
        // A mesh read from a file is consistent, and holds nothing to
        // release; one that `Start` built or changed is checked.
        if base.is_none() || run.mesh.topology_edits() != edits {
            run.end_of_step("`Start`", true)?;
        }
        Ok(run)
    }
}

impl<'p> VvRun<'p> {
    fn control(&mut self, kind: ControlKind) -> Result<(), VvError> {
        for (k, body, frame) in &self.vv.program.control {
            if *k == kind {
                let mut host = VvHost {
                    mesh: &mut self.mesh,
                    layouts: &self.layouts,
                    max_vertices: self.max_vertices,
                    list: Vec::new(),
                    max_valence: self.max_valence,
                };
                run_body(&mut self.interp, body, *frame, &mut self.env, &mut host)?;
            }
        }
        Ok(())
    }

    /// The structure's vertices.
    pub fn members(&self) -> &[u32] {
        host::set_ids(&self.env.globals[self.vv.structure as usize])
    }

    /// The consistency check of the structure, then, with `release`, the
    /// release of every vertex that the program can no longer reach (not
    /// needed when nothing runs after).
    fn end_of_step(&mut self, after: &str, release: bool) -> Result<(), VvError> {
        let members = host::set_ids(&self.env.globals[self.vv.structure as usize]);
        // A vertex of the mesh lies on a face: one with no neighbours is
        // not part of a 2-manifold.
        let lone = members
            .iter()
            .find(|&&v| self.mesh.valence(v, false).is_ok_and(|n| n == 0));
        let checked = match lone {
            Some(v) => Err(format!(
                "vertex {v} has no neighbours: every vertex of a mesh lies on a face"
            )),
            None => self.mesh.check(members),
        };
        if let Err(m) = checked {
            return Err(VvError {
                span: Some(self.vv.structure_name.1),
                message: format!(
                    "after {after}, `{}` is not a consistent mesh: {m}",
                    self.vv.structure_name.0
                ),
            });
        }
        if !release {
            return Ok(());
        }
        let mut roots: Vec<u32> = Vec::new();
        for g in &self.env.globals {
            collect_vertices(g, &mut roots);
        }
        reachable(&self.mesh, &mut roots);
        self.mesh.retain(&roots);
        Ok(())
    }

    /// The structure's polygons (Edmonds' faces) and positions, and its
    /// number of holes (boundary loops).
    pub fn soup(&self) -> Result<(PolygonSoup, usize), VvError> {
        self.mesh
            .to_soup_and_holes(self.members())
            .map_err(|message| VvError {
                span: None,
                message,
            })
    }

    /// True when the program has a control block of `kind`.
    fn has(&self, kind: ControlKind) -> bool {
        self.vv.program.control.iter().any(|(k, _, _)| *k == kind)
    }

    /// Runs the steps that remain, then `End`.
    pub fn finish(&mut self, mut progress: impl FnMut(&Self)) -> Result<(), VvError> {
        crate::production::run(self, &mut progress)?;
        if self.has(ControlKind::End) {
            self.control(ControlKind::End)?;
            self.end_of_step("`End`", false)?;
        }
        Ok(())
    }

    /// The number of steps the run makes.
    pub fn length(&self) -> u64 {
        self.length
    }
}

/// Appends the vertices a global holds (a vertex, a set, inside structs).
fn collect_vertices(v: &Value, out: &mut Vec<u32>) {
    match v {
        Value::Elem(e) if e.kind == host::VERTEX && e.ids[0] != super::mesh::NULL => {
            out.push(e.ids[0])
        }
        Value::Set(s) => out.extend_from_slice(s.ids()),
        Value::Struct(fs) => fs.iter().for_each(|f| collect_vertices(f, out)),
        _ => {}
    }
}

/// Extends `roots` (vertices the globals hold) with every vertex reachable
/// from them through current and old (`'v`) neighbourhoods: a program
/// reaches those with `forall x in v` and `forall x in 'v`, so freeing one
/// and reusing its slot would make a stale id name a new vertex.
fn reachable(mesh: &Rotation, roots: &mut Vec<u32>) {
    let mut seen = vec![false; mesh.slots()];
    roots.retain(|&v| {
        let fresh = mesh.is_alive(v) && !seen[v as usize];
        if fresh {
            seen[v as usize] = true;
        }
        fresh
    });
    let mut k = 0;
    while k < roots.len() {
        let v = roots[k];
        k += 1;
        // No error strings made for vertices without an old state.
        let old = if mesh.has_old(v) {
            mesh.neighbours(v, true).unwrap_or(&[])
        } else {
            &[]
        };
        let cur = mesh.neighbours(v, false).unwrap_or(&[]);
        for &x in cur.iter().chain(old) {
            if mesh.is_alive(x) && !seen[x as usize] {
                seen[x as usize] = true;
                roots.push(x);
            }
        }
    }
}

fn run_body(
    interp: &mut Interp,
    body: &[St],
    frame: usize,
    env: &mut Env,
    host: &mut VvHost,
) -> Result<(), VvError> {
    let mut frame = vec![Value::Void; frame];
    let mut sink: Vec<(crate::lang::modules::Sym, Vec<Value>)> = Vec::new();
    interp.run(body, &mut frame, env, host, &mut sink)?;
    Ok(())
}

impl Topology for VvRun<'_> {
    type Structure = Rotation;
    type Error = VvError;

    fn host_table() -> &'static crate::lang::builtins::HostTable {
        &VV_HOST
    }

    fn structure(&self) -> &Rotation {
        &self.mesh
    }

    fn steps_done(&self) -> u64 {
        self.steps
    }

    fn has_next(&self) -> bool {
        self.steps < self.length && !self.env.stop
    }

    fn step(&mut self) -> Result<(), VvError> {
        if let Err(m) = crate::deadline::check(self.interp.deadline) {
            return Err(VvError {
                span: None,
                message: m,
            });
        }
        self.env.step = self.steps as i64;
        self.control(ControlKind::StartEach)?;
        self.control(ControlKind::Step)?;
        self.control(ControlKind::EndEach)?;
        self.steps += 1;
        self.env.step = self.steps as i64;
        let after = format!("step {}", self.steps);
        // Nothing runs after the last step but `End`: what it would
        // release goes with the run.
        let release = self.steps < self.length || self.has(ControlKind::End);
        self.end_of_step(&after, release)
    }
}

/// The base mesh path of a program read from `file`: relative to its
/// folder when that file exists, else as written.
pub fn base_path(vv: &VvProgram, dir: Option<&std::path::Path>) -> Option<PathBuf> {
    let (p, _) = vv.base.as_ref()?;
    let rel = dir.unwrap_or(std::path::Path::new(".")).join(p);
    Some(if rel.exists() { rel } else { PathBuf::from(p) })
}
