//! [`System`]: a loaded file, curve or surface, and how to run it.

use std::path::{Path, PathBuf};

use crate::curve::{Curve, CurveRun};
use crate::deadline::Deadline;
use crate::error::Error;
use crate::lang::ProgramOutput;
use crate::mesh::Mesh;
use crate::mesh::PolygonSoup;
use crate::rewrite::derive::DEFAULT_MAX_MODULES;
use crate::rewrite::{DeriveOptions, Word};
use crate::surface::{Grammar, StepCounts};
use crate::syntax::Diagnostic;
use crate::syntax::{FileId, SourceMap};
use crate::vv::{VvError, VvProgram};

/// A checked `.lsys` file: what the loader (`subgram::load`) returns.
#[derive(Debug)]
#[allow(clippy::large_enum_variant)] // one per loaded file: boxing saves nothing
pub enum System {
    /// An L-system whose word of modules is derived and drawn as a curve.
    Curve(Curve),
    /// A stellar subdivision grammar, run on a mesh.
    Surface(Surface),
    /// A vertex-vertex program (paper 001), run on a rotation system.
    Vv(Vv),
    /// A shape grammar (paper 003, CGA shape), derived into a tree of
    /// shapes.
    Shapes(Shapes),
}

impl System {
    /// The system of a program that a topology's entry checked
    /// ([`crate::production::Entry`]), read from `file` (relative file
    /// names are then found beside it) or from text.
    pub(crate) fn checked(checked: crate::production::Checked, file: Option<&Path>) -> System {
        let checked = match checked.downcast::<Grammar>() {
            Ok(g) => return System::Surface(Surface::new(*g, file)),
            Err(other) => other,
        };
        let checked = match checked.downcast::<VvProgram>() {
            Ok(p) => return System::Vv(Vv::new(*p, file)),
            Err(other) => other,
        };
        match checked.downcast::<crate::shape::ShapeGrammar>() {
            Ok(g) => System::Shapes(Shapes::new(*g)),
            Err(_) => unreachable!("every topology's entry checks into its own type, listed here"),
        }
    }
}

/// Settings of [`System::run`].
#[derive(Clone, Debug)]
pub struct RunOptions {
    /// The number of steps; by default the file's `derivation length:`
    /// (for a surface grammar without one, 1).
    pub steps: Option<u64>,
    /// Curves: a step that makes a longer word fails.
    pub max_modules: usize,
    /// Curves: where the partition into multi-module strict predecessors
    /// starts.
    pub phase: usize,
    /// Curves: seeds every random number generator as if `Start` began
    /// with `sran(N); srand(N); srand48(N); SeedGillespie(N);`. Without
    /// it the generators start as lpfg's do. Runs are reproducible either
    /// way.
    pub seed: Option<u32>,
    /// Surfaces: the base mesh file, instead of the grammar's `mesh:`.
    pub base_mesh: Option<PathBuf>,
    /// The run stops with an error once this passes. Default: none.
    pub deadline: Option<Deadline>,
    /// Curves: where the program's `printf`s and files go.
    pub output: ProgramOutput,
    /// Shape grammars: the most shapes a derivation may make (default
    /// `SUBGRAM_MAX_SHAPES` or 1,000,000).
    pub max_shapes: Option<usize>,
}

impl Default for RunOptions {
    fn default() -> Self {
        RunOptions {
            steps: None,
            max_modules: DEFAULT_MAX_MODULES,
            phase: 0,
            seed: None,
            base_mesh: None,
            deadline: None,
            output: ProgramOutput::default(),
            max_shapes: None,
        }
    }
}

impl RunOptions {
    /// Runs `n` steps instead of the file's derivation length.
    pub fn with_steps(mut self, n: u64) -> Self {
        self.steps = Some(n);
        self
    }

    /// The options of a curve's derivation.
    pub fn derive_options(&self) -> DeriveOptions {
        let mut d = DeriveOptions::default()
            .with_max_modules(self.max_modules)
            .with_phase(self.phase)
            .with_deadline(self.deadline)
            .with_output(self.output.clone());
        d.steps = self.steps;
        d.seed = self.seed;
        d
    }
}

/// The result of [`System::run`].
#[allow(clippy::large_enum_variant)] // one per run: boxing saves nothing
pub enum Run<'s> {
    Curve(CurveRun<'s>),
    Surface(SurfaceRun),
    Vv(VvResult),
    Shapes(ShapeRun),
}

impl Run<'_> {
    /// A curve's derived word.
    pub fn word(&self) -> Option<&Word> {
        match self {
            Run::Curve(c) => Some(c.word()),
            Run::Surface(_) | Run::Vv(_) | Run::Shapes(_) => None,
        }
    }

    /// A surface grammar's subdivided mesh.
    pub fn mesh(&self) -> Option<&Mesh> {
        match self {
            Run::Curve(_) | Run::Vv(_) | Run::Shapes(_) => None,
            Run::Surface(s) => Some(&s.mesh),
        }
    }

    /// A vv program's mesh, as polygons.
    pub fn polygons(&self) -> Option<&PolygonSoup> {
        match self {
            Run::Vv(v) => Some(&v.soup),
            Run::Shapes(s) => Some(&s.soup),
            _ => None,
        }
    }
}

impl System {
    /// Runs the system: derives a curve's word, or subdivides a surface
    /// grammar's base mesh.
    ///
    /// ```
    /// # fn main() -> Result<(), subgram::Error> {
    /// let root = env!("CARGO_MANIFEST_DIR");
    /// let opts = subgram::LoadOptions::default();
    /// let system = subgram::load(format!("{root}/lsystems/surfaces/loop.lsys"), &opts)?;
    /// let run = system.run(&subgram::RunOptions::default().with_steps(1))?;
    /// assert_eq!(run.mesh().unwrap().info().faces, 8 * 4); // an octahedron, each face split in 4
    /// # Ok(()) }
    /// ```
    pub fn run(&self, opts: &RunOptions) -> Result<Run<'_>, Error> {
        match self {
            System::Curve(c) => Ok(Run::Curve(c.run(opts.derive_options())?)),
            System::Surface(s) => Ok(Run::Surface(s.subdivide(opts, |_| {})?)),
            System::Vv(v) => Ok(Run::Vv(v.run(opts, |_| {})?)),
            System::Shapes(s) => Ok(Run::Shapes(s.derive(opts)?)),
        }
    }

    /// What the checker found questionable without refusing the program,
    /// each rendered with `file:line:col: warning:`, the line and a caret
    /// (a division of integer constants that truncates where a
    /// floating-point number is wanted).
    pub fn warnings(&self) -> Vec<String> {
        let (sources, warnings) = match self {
            System::Curve(c) => (&c.sources, &c.program.warnings),
            System::Surface(s) => (&s.grammar.sources, &s.grammar.warnings),
            System::Vv(v) => (&v.program.sources, &v.program.warnings),
            System::Shapes(s) => (&s.grammar.sources, &s.grammar.warnings),
        };
        warnings
            .iter()
            .map(|d| sources.render_warning(d.span, &d.message))
            .collect()
    }

    /// Every file a run of the system reads: its own text (and the texts
    /// it includes), a model's files (view, functions, contours, surfaces,
    /// colours), a base mesh, a shape grammar's meshes and schemes. `watch`
    /// re-renders when one of them changes.
    pub fn inputs(&self) -> Vec<PathBuf> {
        let mut files: Vec<PathBuf> = self
            .sources()
            .names()
            .map(PathBuf::from)
            .filter(|p| p.is_file())
            .collect();
        match self {
            System::Curve(c) => files.extend(crate::model::of(&c.program).files.iter().cloned()),
            System::Surface(s) => files.extend(s.base_mesh()),
            System::Vv(v) => files.extend(v.base_mesh()),
            System::Shapes(s) => files.extend(s.inputs()),
        }
        let mut seen = std::collections::HashSet::new();
        files.retain(|f| seen.insert(f.clone()));
        files
    }

    /// The texts the system was checked from: the file and its `-D` values.
    pub fn sources(&self) -> &SourceMap {
        match self {
            System::Curve(c) => &c.sources,
            System::Surface(s) => &s.grammar.sources,
            System::Vv(v) => &v.program.sources,
            System::Shapes(s) => &s.grammar.sources,
        }
    }
}

/// The most steps a surface grammar may run: each at least doubles the
/// faces.
pub const MAX_SURFACE_STEPS: u64 = 12;

/// A checked surface grammar and the folder its `mesh:` is relative to.
#[derive(Debug)]
pub struct Surface {
    pub grammar: Grammar,
    dir: Option<PathBuf>,
}

/// Where a run stands, for progress reports: after `step` of `steps` (0
/// before the first), the mesh's counts (surfaces, vv programs) or the
/// word's modules (curves; the mesh counts are then 0). `valences`: the
/// steps are the valences `analyze` has measured, not derivation steps.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Progress {
    pub valences: bool,
    pub step: usize,
    pub steps: usize,
    pub vertices: usize,
    pub edges: usize,
    pub faces: usize,
    pub modules: usize,
}

impl Progress {
    /// A curve's derivation after its step `d.step`.
    pub fn of_derivation(d: &crate::rewrite::Derivation) -> Progress {
        Progress {
            step: d.step as usize,
            steps: d.length as usize,
            modules: d.word.len(),
            ..Progress::default()
        }
    }
}

/// A subdivided mesh and the number of steps that made it.
#[derive(Clone, Debug)]
pub struct SurfaceRun {
    pub mesh: Mesh,
    pub steps: usize,
}

/// A run's mesh as a soup of polygons with what a file keeps of it: its
/// sharp edges and its corners' texture coordinates.
#[derive(Debug)]
pub struct TexturedSoup {
    pub soup: PolygonSoup,
    pub sharpness: crate::mesh::SoupSharpness,
    pub uvs: crate::mesh::FaceUvs,
}

impl Surface {
    /// `grammar`, read from `file` (its `mesh:` is relative to the file's
    /// folder) or from text (relative to the current folder).
    pub fn new(grammar: Grammar, file: Option<&Path>) -> Surface {
        let dir = file.map(|f| f.parent().unwrap_or(Path::new("")).to_path_buf());
        Surface { grammar, dir }
    }

    /// The base mesh the grammar names with `mesh:`: relative to the
    /// grammar's folder when that file exists, else as written.
    pub fn base_mesh(&self) -> Option<PathBuf> {
        let (p, _) = self.grammar.mesh.as_ref()?;
        let rel = self.dir.as_deref().unwrap_or(Path::new(".")).join(p);
        Some(if rel.exists() { rel } else { PathBuf::from(p) })
    }

    /// The steps a run makes: `requested`, else the grammar's derivation
    /// length, else 1; more than [`MAX_SURFACE_STEPS`] are refused.
    pub fn steps(&self, requested: Option<u64>) -> Result<usize, Error> {
        let n = requested.or(self.grammar.length).unwrap_or(1);
        if n > MAX_SURFACE_STEPS {
            return Err(Error::Usage(format!(
                "{n} steps would multiply the faces by at least 2^{n}; at most {MAX_SURFACE_STEPS} are allowed"
            )));
        }
        Ok(n as usize)
    }

    /// A run's error as an [`Error`], located at the rule when one is to
    /// blame, else at the grammar's file.
    pub fn error(&self, e: crate::surface::RunError) -> Error {
        match e.span {
            Some(span) => Error::at(
                &self.grammar.sources,
                crate::syntax::Diagnostic::new(span, e.message),
            ),
            None => Error::File {
                path: self.grammar.sources.get(FileId(0)).name.clone(),
                line: None,
                message: e.message,
            },
        }
    }

    /// Runs the `init:` rules, then `steps` steps on `mesh`, as a new run
    /// ([`Grammar::run_until`]), stopping once `deadline` passes.
    /// `progress` hears before the first step and after each.
    /// A run that fails in a rule leaves the mesh partly derived.
    pub fn run_on(
        &self,
        mesh: &mut Mesh,
        steps: usize,
        deadline: Option<Deadline>,
        mut progress: impl FnMut(Progress),
    ) -> Result<(), Error> {
        let at = |c: StepCounts| Progress {
            step: c.step,
            steps,
            vertices: c.vertices,
            edges: c.edges,
            faces: c.faces,
            ..Progress::default()
        };
        progress(at(StepCounts {
            step: 0,
            vertices: mesh.vertex_count(),
            edges: mesh.edge_count(),
            faces: mesh.face_count(),
        }));
        self.grammar
            .run_until(mesh, steps, deadline, |c| progress(at(c)))
            .map_err(|e| self.error(e))
    }

    /// Loads the base mesh (`opts.base_mesh`, else the grammar's `mesh:`) and
    /// runs `opts.steps` steps on it (see [`Surface::steps`]).
    pub fn subdivide(
        &self,
        opts: &RunOptions,
        progress: impl FnMut(Progress),
    ) -> Result<SurfaceRun, Error> {
        let mut mesh = self.base(opts)?;
        let steps = self.steps(opts.steps)?;
        self.run_on(&mut mesh, steps, opts.deadline, progress)?;
        Ok(SurfaceRun { mesh, steps })
    }

    /// [`Surface::subdivide`], handing `each` the mesh of every level as
    /// the run makes it: level 0 (the base mesh after the `init:` rules),
    /// then after each step. `progress` hears as `subdivide`'s does.
    pub fn subdivide_each(
        &self,
        opts: &RunOptions,
        mut progress: impl FnMut(Progress),
        mut each: impl FnMut(usize, &Mesh) -> Result<(), Error>,
    ) -> Result<SurfaceRun, Error> {
        let mut mesh = self.base(opts)?;
        let steps = self.steps(opts.steps)?;
        let at = |step: usize, m: &Mesh| Progress {
            step,
            steps,
            vertices: m.vertex_count(),
            edges: m.edge_count(),
            faces: m.face_count(),
            ..Progress::default()
        };
        progress(at(0, &mesh));
        {
            let mut run = {
                // The pairing of `init: match_blocks` reads the thread's
                // deadline.
                let _scope = opts.deadline.map(|d| crate::deadline::scope(Some(d)));
                self.grammar.start(&mut mesh).map_err(|e| self.error(e))?
            };
            run.set_deadline(opts.deadline);
            each(0, run.mesh())?;
            for step in 1..=steps {
                run.steps(1, |_| {}).map_err(|e| self.error(e))?;
                progress(at(step, run.mesh()));
                each(step, run.mesh())?;
            }
        }
        Ok(SurfaceRun { mesh, steps })
    }

    /// The base mesh a run starts from: `opts.base_mesh`, else the
    /// grammar's `mesh:` (an unreadable one shown at that line).
    fn base(&self, opts: &RunOptions) -> Result<Mesh, Error> {
        self.base_with(opts, load_mesh)
    }

    /// Loads the base mesh (see [`Surface::subdivide`]) and runs the steps
    /// on it and, where the file gives its corners texture coordinates, on
    /// its UV layout too (see [`crate::surface::uvs`]): the run, and the
    /// mesh it made as a soup with its sharpness and its corners'
    /// coordinates. Without coordinates in the file, the second part is
    /// `None` and the run is [`Surface::subdivide`]'s; the third is a
    /// warning where the file's coordinates are not whole and were
    /// dropped.
    pub fn subdivide_with_uvs(
        &self,
        opts: &RunOptions,
        mode: crate::surface::uvs::FvarLinear,
        progress: impl FnMut(Progress),
    ) -> Result<(SurfaceRun, Option<TexturedSoup>, Option<String>), Error> {
        use crate::surface::uvs;
        let (mut mesh, soup, read) =
            self.base_with(opts, |p| Ok(crate::mesh::io::read_with_uvs(p)?))?;
        let steps = self.steps(opts.steps)?;
        let Some(found) = read.uvs else {
            self.run_on(&mut mesh, steps, opts.deadline, progress)?;
            return Ok((SurfaceRun { mesh, steps }, None, read.warning));
        };
        let name = &self.grammar.sources.get(FileId(0)).name;
        let what = if self.grammar.dual_at.is_some() {
            Some("a dual scheme, which runs on closed meshes only")
        } else if self.grammar.adaptive.is_some() {
            Some("adaptive, so its splits depend on the shape of what it runs on")
        } else {
            None
        };
        if let Some(what) = what {
            return Err(Error::Usage(format!(
                "`{}` gives its corners texture coordinates, which run through a grammar as a \
                 layout of their own, with boundaries at the seams; `{name}` is {what}: \
                 subdivide with `--no-uvs`",
                self.base_name(opts)
            )));
        }
        if mode != uvs::FvarLinear::None && !uvs::reads_sharpness(&self.grammar) {
            return Err(Error::Usage(format!(
                "`--fvar-linear {}` keeps some texture coordinates linear through the grammar's \
                 crease rules, and `{name}` has none (it never reads `sharp`, `sharpness` or \
                 `creases`): use `--fvar-linear none`, or `--no-uvs`",
                mode.name()
            )));
        }
        let mut layout = uvs::UvLayout::new(&soup, &found, &mesh, mode)
            .map_err(|m| Error::Failed(format!("{}: {m}", self.base_name(opts))))?;
        drop(soup);
        mesh.track_origins(uvs::base_key);
        self.run_on(&mut mesh, steps, opts.deadline, progress)?;
        layout
            .run(&self.grammar, steps, opts.deadline)
            .map_err(|e| self.error(e))?;
        let (soup, sharpness, uvs) = uvs::carry(&mesh, &layout.mesh).map_err(Error::Failed)?;
        Ok((
            SurfaceRun { mesh, steps },
            Some(TexturedSoup {
                soup,
                sharpness,
                uvs,
            }),
            None,
        ))
    }

    /// The base mesh's path as given, for messages.
    fn base_name(&self, opts: &RunOptions) -> String {
        match (&opts.base_mesh, self.base_mesh()) {
            (Some(m), _) => m.display().to_string(),
            (None, Some(p)) => p.display().to_string(),
            (None, None) => "the base mesh".into(),
        }
    }

    /// Loads the base mesh with `load`: `opts.base_mesh`, else the
    /// grammar's `mesh:` (a problem reading it shown at that line).
    fn base_with<T>(
        &self,
        opts: &RunOptions,
        load: impl Fn(&Path) -> Result<T, Error>,
    ) -> Result<T, Error> {
        let path = match (&opts.base_mesh, self.base_mesh()) {
            (Some(m), _) => m.clone(),
            (None, Some(p)) => p,
            (None, None) => {
                // The grammar's own file comes first in its sources.
                let name = &self.grammar.sources.get(FileId(0)).name;
                return Err(Error::Usage(format!(
                    "give a base mesh: `subgram subdivide MESH --grammar {name} ...`, or `mesh: \"file.obj\";` in the grammar"
                )));
            }
        };
        let named_here = opts.base_mesh.is_none();
        load(&path).map_err(|e| match &self.grammar.mesh {
            // A mesh the grammar names but that cannot be read at all is
            // shown at its `mesh:` line; a problem inside the mesh file
            // keeps its own place.
            Some((_, span)) if named_here && !in_the_file(&e) => Error::at(
                &self.grammar.sources,
                Diagnostic::new(
                    *span,
                    match &e {
                        Error::File { path, message, .. } => {
                            format!("the base mesh `{path}`: {message}")
                        }
                        e => format!("the base mesh: {e}"),
                    },
                ),
            ),
            _ => e,
        })
    }
}

/// A checked vv program and the folder its base mesh is relative to.
#[derive(Debug)]
pub struct Vv {
    pub program: VvProgram,
    dir: Option<PathBuf>,
}

/// What a vv run made: the mesh's polygons (Edmonds' faces) and
/// positions, and the steps run.
#[derive(Clone, Debug)]
pub struct VvResult {
    pub soup: PolygonSoup,
    pub steps: u64,
    pub info: VvInfo,
}

/// A vv mesh's counts: vertices, edges, faces, boundary loops, the Euler
/// characteristic and the valences.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize)]
pub struct VvInfo {
    pub vertices: usize,
    pub edges: usize,
    pub faces: usize,
    pub boundary_loops: usize,
    pub euler_characteristic: i64,
    /// `(valence, number of vertices)`, by valence.
    pub valences: Vec<(usize, usize)>,
    /// `(sides, number of faces)`, by sides.
    pub face_sides: Vec<(usize, usize)>,
}

impl std::fmt::Display for VvInfo {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(f, "vertices: {}", self.vertices)?;
        writeln!(f, "edges: {}", self.edges)?;
        writeln!(f, "faces: {}", self.faces)?;
        writeln!(f, "boundary loops: {}", self.boundary_loops)?;
        writeln!(f, "Euler characteristic: {}", self.euler_characteristic)?;
        let list = |v: &[(usize, usize)]| {
            v.iter()
                .map(|(k, n)| format!("{k}:{n}"))
                .collect::<Vec<_>>()
                .join(" ")
        };
        writeln!(f, "valences: {}", list(&self.valences))?;
        writeln!(f, "face sides: {}", list(&self.face_sides))
    }
}

impl Vv {
    /// `program`, read from `file` (its base mesh is relative to the
    /// file's folder) or from text (relative to the current folder).
    pub fn new(program: VvProgram, file: Option<&Path>) -> Vv {
        let dir = file.map(|f| f.parent().unwrap_or(Path::new("")).to_path_buf());
        Vv { program, dir }
    }

    /// The base mesh file the program names (`mesh S = "cube.obj";`).
    pub fn base_mesh(&self) -> Option<PathBuf> {
        crate::vv::run::base_path(&self.program, self.dir.as_deref())
    }

    /// A run's error as an [`Error`], located in the program when a
    /// statement is to blame.
    pub fn error(&self, e: VvError) -> Error {
        match e.span {
            Some(span) => Error::at(
                &self.program.sources,
                crate::syntax::Diagnostic::new(span, e.message),
            ),
            None => Error::File {
                path: self.program.sources.get(FileId(0)).name.clone(),
                line: None,
                message: e.message,
            },
        }
    }

    /// Reads the base mesh (`opts.base_mesh`, else the program's own), runs
    /// `Start`, `opts.steps` steps (else the derivation length, else 1) and
    /// `End`; `progress` hears after `Start` and after each step.
    pub fn run(
        &self,
        opts: &RunOptions,
        progress: impl FnMut(Progress),
    ) -> Result<VvResult, Error> {
        self.run_each(opts, progress, |_| false, |_, _| {})
    }

    /// [`Vv::run`], handing `each` the mesh's polygons after `Start` (step
    /// 0) and after each step (before `End`: the result's soup is the last
    /// step's after `End`), for every step that `wanted` names.
    pub fn run_each(
        &self,
        opts: &RunOptions,
        progress: impl FnMut(Progress),
        wanted: impl Fn(u64) -> bool,
        each: impl FnMut(u64, PolygonSoup),
    ) -> Result<VvResult, Error> {
        let path = opts.base_mesh.clone().or_else(|| self.base_mesh());
        let soup = match &path {
            Some(p) => Some(crate::mesh::io::read(p).map_err(|e| {
                match (&self.program.base, opts.base_mesh.is_none(), e.line) {
                    (Some((_, span)), true, None) => Error::at(
                        &self.program.sources,
                        Diagnostic::new(
                            *span,
                            format!("the base mesh `{}`: {}", e.path, e.message),
                        ),
                    ),
                    _ => Error::from(e),
                }
            })?),
            None => None,
        };
        let r = self.run_from(soup.as_ref(), opts, progress, (wanted, each));
        match (r, &path, &self.program.base) {
            // A base mesh given on the command line is refused at its
            // file, not at the program's own `mesh S = "...";`.
            (
                Err(Error::Program {
                    ref diagnostics, ..
                }),
                Some(p),
                Some((_, span)),
            ) if opts.base_mesh.is_some()
                && diagnostics.len() == 1
                && diagnostics[0].span == *span =>
            {
                Err(Error::File {
                    path: p.display().to_string(),
                    line: None,
                    message: diagnostics[0].message.clone(),
                })
            }
            (r, _, _) => r,
        }
    }

    /// Runs the program on the polygons `base` (instead of a file), as
    /// [`Vv::run`] does.
    pub fn run_soup(&self, base: &PolygonSoup, opts: &RunOptions) -> Result<VvResult, Error> {
        self.run_from(Some(base), opts, |_| {}, (|_| false, |_, _| {}))
    }

    fn run_from(
        &self,
        soup: Option<&PolygonSoup>,
        opts: &RunOptions,
        mut progress: impl FnMut(Progress),
        (wanted, mut each): (impl Fn(u64) -> bool, impl FnMut(u64, PolygonSoup)),
    ) -> Result<VvResult, Error> {
        if let Some(n) = opts.steps.filter(|&n| n > crate::vv::run::MAX_VV_STEPS) {
            return Err(Error::Usage(format!(
                "{n} steps are more than a vv program may run ({})",
                crate::vv::run::MAX_VV_STEPS
            )));
        }
        let mut run = self
            .program
            .start(
                soup,
                opts.steps,
                opts.deadline,
                opts.output.clone(),
                opts.seed,
            )
            .map_err(|e| self.error(e))?;
        let steps = run.length() as usize;
        let at = |r: &crate::vv::VvRun| {
            let n = r.members().len();
            Progress {
                step: crate::production::Topology::steps_done(r) as usize,
                steps,
                vertices: n,
                edges: 0,
                ..Progress::default()
            }
        };
        // The polygons of a step the caller wants, or the first error
        // in making them.
        let mut failed = None;
        let mut hand = |r: &crate::vv::VvRun| {
            let step = crate::production::Topology::steps_done(r);
            if failed.is_none() && wanted(step) {
                match r.soup() {
                    Ok((soup, _)) => each(step, soup),
                    Err(e) => failed = Some(e),
                }
            }
        };
        progress(at(&run));
        hand(&run);
        run.finish(|r| {
            progress(at(r));
            hand(r);
        })
        .map_err(|e| self.error(e))?;
        if let Some(e) = failed {
            return Err(self.error(e));
        }
        let (soup, holes) = run.soup().map_err(|e| self.error(e))?;
        let info = vv_info(&run, &soup, holes);
        Ok(VvResult {
            soup,
            steps: crate::production::Topology::steps_done(&run),
            info,
        })
    }
}

/// The counts of a run's mesh.
fn vv_info(run: &crate::vv::VvRun, soup: &PolygonSoup, holes: usize) -> VvInfo {
    use std::collections::BTreeMap;
    let members = run.members();
    let mesh = &run.mesh;
    let faces = &soup.faces;
    let mut valences: BTreeMap<usize, usize> = BTreeMap::new();
    let mut degree_sum = 0;
    for &v in members {
        let k = mesh.valence(v, false).unwrap_or(0);
        degree_sum += k;
        *valences.entry(k).or_default() += 1;
    }
    let mut sides: BTreeMap<usize, usize> = BTreeMap::new();
    for f in faces {
        *sides.entry(f.len()).or_default() += 1;
    }
    let edges = degree_sum / 2;
    VvInfo {
        vertices: members.len(),
        edges,
        faces: faces.len(),
        boundary_loops: holes,
        euler_characteristic: members.len() as i64 - edges as i64 + faces.len() as i64,
        valences: valences.into_iter().collect(),
        face_sides: sides.into_iter().collect(),
    }
}

/// True when `e` points at a line of the file it is about.
fn in_the_file(e: &Error) -> bool {
    match e {
        Error::File { line, .. } => line.is_some(),
        Error::Program { .. } | Error::FileAt { .. } => true,
        _ => false,
    }
}

/// Reads a mesh file (`.obj`, `.off`, `.ply`) and builds the half-edge
/// mesh, with the file's name on every message.
pub fn load_mesh(path: &Path) -> Result<Mesh, Error> {
    Ok(crate::mesh::io::read_mesh(path)?)
}

/// A checked shape grammar (paper 003).
#[derive(Debug)]
pub struct Shapes {
    pub(crate) grammar: crate::shape::ShapeGrammar,
}

/// A shape derivation: the tree of shapes, and the terminal shapes' faces
/// with their colours.
#[derive(Debug)]
pub struct ShapeRun {
    pub(crate) grammar_symbols: usize,
    pub(crate) tree: crate::shape::ShapeTree,
    /// The terminal shapes' faces, in tree order.
    pub soup: PolygonSoup,
    /// The colour of each face of `soup`.
    pub colours: Vec<crate::render::Rgba>,
}

/// A shape derivation's counts.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize)]
pub struct ShapeCounts {
    /// Every shape the derivation made.
    pub shapes: usize,
    pub terminal_shapes: usize,
    /// The faces of the terminal shapes.
    pub faces: usize,
    /// The smoothing groups subdivided.
    pub smoothing_groups: usize,
}

impl Shapes {
    pub(crate) fn new(grammar: crate::shape::ShapeGrammar) -> Shapes {
        Shapes { grammar }
    }

    /// The number of rules.
    pub fn rules(&self) -> usize {
        self.grammar.rules.len()
    }

    /// Derives the grammar's shapes (`opts.seed` seeds its random choices;
    /// `opts.deadline` stops it).
    pub fn derive(&self, opts: &RunOptions) -> Result<ShapeRun, Error> {
        let never = Deadline::after(std::time::Duration::from_secs(u64::MAX / 4));
        let deadline = opts.deadline.as_ref().unwrap_or(&never);
        let mut o = crate::shape::ShapeOptions {
            seed: opts.seed.unwrap_or(1),
            ..Default::default()
        };
        o.max_shapes = match opts.max_shapes {
            Some(n) => n,
            None => crate::limits::from_env(
                crate::shape::run::MAX_SHAPES_VAR,
                crate::shape::run::MAX_SHAPES as u64,
                "a whole number",
            )
            .map_err(Error::Usage)? as usize,
        };
        let tree =
            crate::shape::run::derive(&self.grammar, &o, deadline).map_err(|e| self.error(e))?;
        let (soup, colours) = crate::shape::output::soup(&tree);
        Ok(ShapeRun {
            grammar_symbols: self.grammar.symbols.len(),
            tree,
            soup,
            colours,
        })
    }

    /// A derivation's error, located in the grammar.
    pub fn error(&self, e: crate::shape::ShapeError) -> Error {
        Error::at(&self.grammar.sources, Diagnostic::new(e.span, e.message))
    }

    /// The files the grammar reads besides itself: inserted meshes and
    /// `Subdivide` scheme files.
    pub fn inputs(&self) -> Vec<PathBuf> {
        self.grammar.inputs.clone()
    }

    /// The shape tree as indented text.
    pub fn tree_text(&self, run: &ShapeRun) -> String {
        crate::shape::output::tree_text(&self.grammar, &run.tree)
    }

    /// One line per smoothing group subdivided: its shapes, scheme and
    /// steps, faces before and after, protected faces and vertices.
    pub fn groups_text(&self, run: &ShapeRun) -> String {
        crate::shape::output::groups_text(&run.tree)
    }

    /// The shape tree as JSON.
    pub fn tree_json(&self, run: &ShapeRun) -> String {
        crate::shape::output::tree_json(&self.grammar, &run.tree)
    }

    /// The OBJ text (one group per terminal shape) and its MTL text;
    /// `mtl_name` is how the OBJ names the MTL file.
    pub fn obj(&self, run: &ShapeRun, mtl_name: &str) -> (String, String) {
        crate::shape::output::obj(&self.grammar, &run.tree, mtl_name)
    }
}

impl ShapeRun {
    pub fn counts(&self) -> ShapeCounts {
        let (shapes, terminal_shapes, faces) = crate::shape::output::counts(&self.tree);
        let _ = self.grammar_symbols;
        ShapeCounts {
            shapes,
            terminal_shapes,
            faces,
            smoothing_groups: self.tree.groups.len(),
        }
    }
}
