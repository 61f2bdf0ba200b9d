//! Starting a run ([`Grammar::run`], [`Grammar::start`] and the checks
//! they make of the mesh) and the run itself, a [`GrammarRun`], whose steps
//! the production schedule drives.

use glam::DVec3;

use crate::mesh::{Mesh, VertexId};
use crate::surface::grammar::Op;
use crate::surface::host::SURFACE_HOST;

use super::adaptive::check_adaptive_start;
use super::{
    Grammar, Protected, Protection, Rule, RunError, RunState, StepCounts, MAX_VALENCE_VAR,
};

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
        // Pairing takes the triangles of a fanned polygon like any other,
        // and a face split takes the polygon whole (Mesh::polygon_split_with).
        let face_split = self.rules.iter().any(|r| r.op == Op::FaceSplit);
        let fanned = mesh
            .fanned_polygon()
            .filter(|_| self.match_blocks_at.is_none() && !face_split);
        if let (Some(span), Some(fan)) = (self.block_used_at, fanned) {
            let line = fan.line.map_or(String::new(), |l| format!(" (line {l})"));
            return Err(RunError {
                span: Some(span),
                message: format!(
                    "this grammar reads quads as basic blocks, but face {}{line} has {} sides, \
                     and only a grammar with a face split (F -> V || E^3 F^3) takes a polygon \
                     of more than four sides whole; split it into quads and triangles first",
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
                         vertex {v} is on a boundary (lsystems/vv/doo-sabin.lsys and \
                         peters-reif.lsys, vv programs of the same schemes, have boundary rules)"
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
        // corners soften (OpenSubdiv's uniform rule, or its Chaikin rule
        // at each edge's end that was there before the step). The rules
        // of the step read the sharpness it started with.
        if self.state.creased {
            let (mesh, step) = (&mut *self.mesh, self.state.step);
            let old: Vec<bool> = (0..mesh.v_alive.len() as u32)
                .map(|v| mesh.vertex_step(crate::mesh::VertexId(v)) < step)
                .collect();
            mesh.soften_sharpness(self.grammar.creasing, |v| old[v.index()]);
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

    /// Makes the mesh sharp everywhere before the next step (see
    /// [`Mesh::sharpen_everything`]): how face-varying data is
    /// interpolated linearly by a crease-aware grammar.
    pub fn sharpen_everything(&mut self) {
        self.mesh.sharpen_everything();
        self.state.creased = true;
    }

    /// Stops the run with an error once `deadline` passes: it is looked
    /// at before every rule.
    pub fn set_deadline(&mut self, deadline: Option<crate::Deadline>) {
        self.state.deadline = deadline;
    }
}

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
