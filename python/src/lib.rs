//! `subgram._subgram`: the Python bindings of the `subgram` library.
//!
//! Everything here goes through the library's own entry points (the
//! loader, `Curve::derivation`, `subgram::command::*`, the mesh and
//! reverse modules), so that a result is the CLI's to the bit. The thin
//! Python layer (argument coercion, dicts, notebook hooks) is in
//! `python/subgram/__init__.py`.
//!
//! Long runs happen on a worker thread with a large stack (as the binary
//! runs its commands: deep programs recurse deeply), with the GIL released;
//! the calling thread wakes every few milliseconds to check for signals
//! (Ctrl-C), and a derivation stops at its next step when one came.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::time::Duration;

use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::exceptions::{PyException, PyIndexError, PyKeyError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyList, PyString, PyTuple};

use subgram::mesh::{Faces, Mesh, PolygonSoup};
use subgram::{DeriveOptions, LoadOptions, Precision, RunOptions, Value};

pyo3::create_exception!(
    _subgram,
    Error,
    PyException,
    "A subgram error: a program that does not check, a run that failed, a \
     file that cannot be read. `str(err)` is what the CLI prints; `.path`, \
     `.line` and `.column` locate it (None where unknown)."
);

/// The stack of the worker thread: the binary's (src/main.rs).
const STACK: usize = 256 << 20;

// ---------------------------------------------------------------------------
// Errors

/// Where an error points: the file, 1-based line and column.
fn locate(e: &subgram::Error) -> (Option<String>, Option<usize>, Option<usize>) {
    match e {
        subgram::Error::Program {
            sources,
            diagnostics,
        } => match diagnostics.first() {
            Some(d) => {
                let f = sources.get(d.span.file);
                let (line, col) = f.line_col(d.span.start as usize);
                (Some(f.name.clone()), Some(line), Some(col))
            }
            None => (None, None, None),
        },
        subgram::Error::File { path, line, .. } => (Some(path.clone()), *line, None),
        subgram::Error::FileAt {
            path,
            line,
            text,
            start,
            ..
        } => {
            let col = text
                .get(..*start)
                .map(|t| t.chars().count() + 1)
                .unwrap_or(*start + 1);
            (Some(path.clone()), Some(*line), Some(col))
        }
        subgram::Error::Io { path, .. } => (Some(path.display().to_string()), None, None),
        _ => (None, None, None),
    }
}

/// The message the binary prints for `e` (src/main.rs).
fn message(e: &subgram::Error) -> String {
    if e.has_location() {
        e.to_string()
    } else {
        format!("error: {e}")
    }
}

fn py_error(py: Python<'_>, e: subgram::Error) -> PyErr {
    let err = Error::new_err(message(&e));
    let (path, line, column) = locate(&e);
    let value = err.value(py);
    let _ = value.setattr("path", path);
    let _ = value.setattr("line", line);
    let _ = value.setattr("column", column);
    let usage = matches!(e, subgram::Error::Usage(_));
    let _ = value.setattr("usage", usage);
    err
}

// ---------------------------------------------------------------------------
// Running off the Python thread

/// Runs `work` on a worker thread with the binary's stack, the GIL
/// released; every 20 ms the calling thread takes the GIL back briefly and
/// checks for signals. When a handler raises (Ctrl-C: KeyboardInterrupt),
/// `stop` is set and every run's deadline counts as passed
/// (`Deadline::stop_all`), the worker is waited for (a derivation stops
/// at its next step, any other run at its next deadline check) and the
/// exception is returned.
fn run_off_thread<T: Send>(
    py: Python<'_>,
    work: impl FnOnce(&AtomicBool) -> T + Send,
) -> PyResult<T> {
    let stop = AtomicBool::new(false);
    py.detach(|| {
        std::thread::scope(|s| {
            let (tx, rx) = std::sync::mpsc::channel();
            let stop = &stop;
            let worker = std::thread::Builder::new()
                .stack_size(STACK)
                .spawn_scoped(s, move || {
                    let r = work(stop);
                    let _ = tx.send(());
                    r
                })
                .map_err(|e| PyException::new_err(format!("cannot start a thread: {e}")))?;
            loop {
                match rx.recv_timeout(Duration::from_millis(20)) {
                    Ok(()) | Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => break,
                    Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {
                        if let Err(e) = Python::attach(|py| py.check_signals()) {
                            stop.store(true, Ordering::SeqCst);
                            subgram::Deadline::stop_all(true);
                            let _ = worker.join();
                            subgram::Deadline::stop_all(false);
                            return Err(e);
                        }
                    }
                }
            }
            worker
                .join()
                .map_err(|_| PyException::new_err("internal failure (this is a bug in subgram)"))
        })
    })
}

/// A folder of its own under the system's temporary folder, removed on drop.
struct TempDir(PathBuf);

impl TempDir {
    fn new() -> PyResult<TempDir> {
        static COUNT: AtomicU64 = AtomicU64::new(0);
        let n = COUNT.fetch_add(1, Ordering::SeqCst);
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.subsec_nanos())
            .unwrap_or(0);
        let dir =
            std::env::temp_dir().join(format!("subgram-py-{}-{n}-{nanos}", std::process::id()));
        std::fs::create_dir_all(&dir)
            .map_err(|e| PyException::new_err(format!("cannot make {}: {e}", dir.display())))?;
        Ok(TempDir(dir))
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// The deadline of a run: `timeout` seconds, or none (0 or None) — a
/// deadline that never passes but is there, so that Ctrl-C
/// (`Deadline::stop_all`) reaches the run all the same.
fn deadline(timeout: Option<f64>) -> Option<subgram::Deadline> {
    timeout
        .and_then(subgram::Deadline::from_secs)
        .or(Some(subgram::Deadline::after(Duration::MAX)))
}

// ---------------------------------------------------------------------------
// System

/// A box's lowest and highest corners.
type Corners<'py> = (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>);

/// Where a system's program came from: `render` hands it to the CLI's
/// command.
#[derive(Clone, Debug)]
enum Source {
    Path(String),
    Text { name: String, text: String },
}

/// A loaded `.lsys` file, model folder or program text (`subgram.load`).
#[pyclass(module = "subgram._subgram", frozen)]
struct System {
    inner: Arc<subgram::System>,
    source: Source,
    defines: Vec<String>,
    double: bool,
    seed: Option<u32>,
}

fn load_options(defines: &[String], double: bool) -> LoadOptions {
    LoadOptions {
        defines: defines.to_vec(),
        precision: if double {
            Precision::Double
        } else {
            Precision::Single
        },
        ..LoadOptions::default()
    }
}

/// `defines` as `NAME=VALUE` strings: a dict's items, or a list of strings.
fn defines_of(defines: Option<&Bound<'_, PyAny>>) -> PyResult<Vec<String>> {
    let Some(d) = defines else {
        return Ok(Vec::new());
    };
    if d.is_none() {
        return Ok(Vec::new());
    }
    if let Ok(dict) = d.cast::<pyo3::types::PyDict>() {
        let mut out = Vec::new();
        for (k, v) in dict.iter() {
            let v = if let Ok(b) = v.extract::<bool>() {
                (b as i32).to_string()
            } else {
                v.str()?.to_string()
            };
            out.push(format!("{}={}", k.str()?, v));
        }
        return Ok(out);
    }
    d.extract::<Vec<String>>().map_err(|_| {
        PyTypeError::new_err("defines: a dict {NAME: VALUE} or a list of 'NAME=VALUE' strings")
    })
}

/// `load(path_or_text, *, defines=None, seed=None, double=False)`.
#[pyfunction]
#[pyo3(signature = (path_or_text, *, defines=None, seed=None, double=false, name=None))]
fn load(
    py: Python<'_>,
    path_or_text: &Bound<'_, PyAny>,
    defines: Option<&Bound<'_, PyAny>>,
    seed: Option<u32>,
    double: bool,
    name: Option<String>,
) -> PyResult<System> {
    let defines = defines_of(defines)?;
    let source = if let Ok(p) = path_or_text.cast::<PyString>() {
        let s: String = p.extract()?;
        // Program text has a `;` or a line break; a path has neither as a
        // rule, and names a file or folder that exists.
        if !s.contains('\n') && !s.contains(';') || Path::new(&s).exists() {
            Source::Path(s)
        } else {
            Source::Text {
                name: name.unwrap_or_else(|| "<text>.lsys".to_string()),
                text: s,
            }
        }
    } else {
        // An os.PathLike.
        let p: PathBuf = path_or_text.extract()?;
        Source::Path(p.display().to_string())
    };
    let opts = load_options(&defines, double);
    let src = source.clone();
    let loaded = run_off_thread(py, move |_| match &src {
        Source::Path(p) => subgram::load(p, &opts),
        Source::Text { name, text } => subgram::load_text(name, text, &opts),
    })?;
    let inner = loaded.map_err(|e| py_error(py, e))?;
    Ok(System {
        inner: Arc::new(inner),
        source,
        defines,
        double,
        seed,
    })
}

fn kind_name(s: &subgram::System) -> &'static str {
    match s {
        subgram::System::Curve(_) => "curve",
        subgram::System::Surface(_) => "surface",
        subgram::System::Vv(_) => "vv",
        subgram::System::Shapes(_) => "shapes",
        #[allow(unreachable_patterns)]
        _ => "other",
    }
}

impl System {
    fn curve(&self) -> PyResult<&subgram::Curve> {
        match &*self.inner {
            subgram::System::Curve(c) => Ok(c),
            other => Err(PyTypeError::new_err(format!(
                "this is a {} system, not a curve: use mesh() or render()",
                kind_name(other)
            ))),
        }
    }

    /// The CLI's run options for a curve (`subgram derive`'s).
    fn run_options(
        &self,
        steps: Option<u64>,
        seed: Option<u32>,
        timeout: Option<f64>,
    ) -> RunOptions {
        RunOptions {
            steps,
            seed: seed.or(self.seed),
            deadline: deadline(timeout),
            ..RunOptions::default()
        }
    }
}

#[pymethods]
impl System {
    /// "curve", "surface", "vv" or "shapes".
    #[getter]
    fn kind(&self) -> &'static str {
        kind_name(&self.inner)
    }

    /// The path the system was loaded from, or None for program text.
    #[getter]
    fn path(&self) -> Option<String> {
        match &self.source {
            Source::Path(p) => Some(p.clone()),
            Source::Text { .. } => None,
        }
    }

    /// The seed given to `load`, or None.
    #[getter]
    fn seed(&self) -> Option<u32> {
        self.seed
    }

    /// The defines given to `load`, as `NAME=VALUE` strings.
    #[getter]
    fn defines(&self) -> Vec<String> {
        self.defines.clone()
    }

    /// The checker's warnings, each as the CLI prints it.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.inner.warnings()
    }

    fn __repr__(&self) -> String {
        let from = match &self.source {
            Source::Path(p) => p.clone(),
            Source::Text { name, .. } => name.clone(),
        };
        format!("<subgram.System {} from {:?}>", self.kind(), from)
    }

    /// `derive(steps=None, *, seed=None, max_modules=None, timeout=None)`.
    #[pyo3(signature = (steps=None, *, seed=None, max_modules=None, timeout=None))]
    fn derive(
        &self,
        py: Python<'_>,
        steps: Option<u64>,
        seed: Option<u32>,
        max_modules: Option<usize>,
        timeout: Option<f64>,
    ) -> PyResult<Word> {
        let subgram::System::Curve(curve) = &*self.inner else {
            return Err(PyTypeError::new_err(format!(
                "derive() makes a word, and this is a {} system: use subdivide() or render()",
                self.kind()
            )));
        };
        let opts = RunOptions {
            steps,
            max_modules: max_modules.unwrap_or(subgram::DEFAULT_MAX_MODULES),
            seed: seed.or(self.seed),
            deadline: deadline(timeout),
            ..RunOptions::default()
        };
        let dopts: DeriveOptions = opts.derive_options();
        let derived = run_off_thread(py, |stop| -> Result<Option<_>, subgram::Error> {
            let mut d = curve.derivation(dopts)?;
            while d.has_next() {
                if stop.load(Ordering::SeqCst) {
                    return Ok(None);
                }
                d.next_step().map_err(|e| curve.error(e))?;
            }
            d.end().map_err(|e| curve.error(e))?;
            let word = std::mem::take(&mut d.word);
            Ok(Some((word, d.ring, d.step)))
        })?;
        match derived.map_err(|e| py_error(py, e))? {
            Some((word, ring, step)) => Ok(Word {
                system: self.inner.clone(),
                word,
                ring,
                step,
                names: Default::default(),
            }),
            // The signal's exception was raised already; a stop without
            // one cannot happen.
            None => Err(pyo3::exceptions::PyKeyboardInterrupt::new_err("")),
        }
    }

    /// `render(path=None, *, format="png", size=None, view=None, steps=None,
    /// seed=None, timeout=600)`: the CLI's `subgram render`.
    #[pyo3(signature = (path=None, *, format=None, size=None, view=None, steps=None, seed=None, solid=None, timeout=Some(600.0)))]
    #[allow(clippy::too_many_arguments)]
    fn render<'py>(
        &self,
        py: Python<'py>,
        path: Option<PathBuf>,
        format: Option<String>,
        size: Option<(u32, u32)>,
        view: Option<String>,
        steps: Option<u64>,
        seed: Option<u32>,
        solid: Option<bool>,
        timeout: Option<f64>,
    ) -> PyResult<Option<Bound<'py, PyBytes>>> {
        let dir = TempDir::new()?;
        let file = match &self.source {
            Source::Path(p) => p.clone(),
            Source::Text { name, text } => {
                let base = Path::new(name)
                    .file_name()
                    .map(|n| n.to_string_lossy().into_owned())
                    .filter(|n| n.ends_with(".lsys") || n.ends_with(".l"))
                    .unwrap_or_else(|| "program.lsys".into());
                let f = dir.0.join(base);
                std::fs::write(&f, text).map_err(|e| {
                    PyException::new_err(format!("cannot write {}: {e}", f.display()))
                })?;
                f.display().to_string()
            }
        };
        let format = match (&format, &path) {
            (Some(f), _) => f.to_ascii_lowercase(),
            (None, Some(p)) => p
                .extension()
                .map(|e| e.to_string_lossy().to_ascii_lowercase())
                .unwrap_or_else(|| "png".into()),
            (None, None) => "png".into(),
        };
        let output = match &path {
            Some(p) => p.clone(),
            None => dir.0.join(format!("picture.{format}")),
        };
        let mut a = subgram::command::RenderArgs::new(file, output.display().to_string());
        a.size = size;
        a.view = view;
        a.steps = steps;
        a.defines = self.defines.clone();
        a.double = self.double;
        a.seed = seed.or(self.seed);
        // No limit is a limit that never comes: Ctrl-C still reaches it.
        a.timeout = Some(
            timeout
                .filter(|t| *t > 0.0)
                .and_then(|t| Duration::try_from_secs_f64(t).ok())
                .unwrap_or(Duration::MAX),
        );
        // As the CLI without --force: never over one of the inputs.
        a.force = false;
        a.solid = match solid {
            None => subgram::command::Solidity::Auto,
            Some(true) => subgram::command::Solidity::Solid,
            Some(false) => subgram::command::Solidity::Lines,
        };
        let r = run_off_thread(py, |_| subgram::command::render(&a, |_| {}))?;
        r.map_err(|e| py_error(py, e))?;
        if path.is_some() {
            return Ok(None);
        }
        let bytes = std::fs::read(&output)
            .map_err(|e| PyException::new_err(format!("cannot read {}: {e}", output.display())))?;
        Ok(Some(PyBytes::new(py, &bytes)))
    }

    /// `lines(steps=None, *, seed=None, timeout=None)`: the turtle's
    /// polylines (the interpreted word drawn, as `render` draws it), each an
    /// n×3 float64 array.
    #[pyo3(signature = (steps=None, *, seed=None, timeout=None))]
    fn lines<'py>(
        &self,
        py: Python<'py>,
        steps: Option<u64>,
        seed: Option<u32>,
        timeout: Option<f64>,
    ) -> PyResult<Vec<Bound<'py, PyArray2<f64>>>> {
        let curve = self.curve()?;
        let dopts = self.run_options(steps, seed, timeout).derive_options();
        let r = run_off_thread(py, |_| curve.run(dopts)?.polylines())?;
        let lines = r.map_err(|e| py_error(py, e))?;
        Ok(lines
            .iter()
            .map(|l| {
                let flat: Vec<f64> = l.iter().flat_map(|p| [p.x, p.y, p.z]).collect();
                Array2::from_shape_vec((l.len(), 3), flat)
                    .expect("n × 3")
                    .into_pyarray(py)
            })
            .collect())
    }

    /// `bounds(steps=None, *, seed=None, timeout=None)`: the box around the
    /// turtle's lines, `(lo, hi)` as 3-element float64 arrays, or None when
    /// it draws none.
    #[pyo3(signature = (steps=None, *, seed=None, timeout=None))]
    fn bounds<'py>(
        &self,
        py: Python<'py>,
        steps: Option<u64>,
        seed: Option<u32>,
        timeout: Option<f64>,
    ) -> PyResult<Option<Corners<'py>>> {
        let curve = self.curve()?;
        let dopts = self.run_options(steps, seed, timeout).derive_options();
        let r = run_off_thread(py, |_| curve.run(dopts)?.line_bounds())?;
        let b = r.map_err(|e| py_error(py, e))?;
        Ok(b.map(|(lo, hi)| {
            (
                vec![lo.x, lo.y, lo.z].into_pyarray(py),
                vec![hi.x, hi.y, hi.z].into_pyarray(py),
            )
        }))
    }

    /// A surface grammar or vv program run on its own base mesh (its
    /// `mesh:`): `(vertices, faces)` as `subdivide` gives them.
    #[pyo3(signature = (steps=None, *, timeout=None))]
    fn _mesh<'py>(
        &self,
        py: Python<'py>,
        steps: Option<u64>,
        timeout: Option<f64>,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let opts = RunOptions {
            steps,
            deadline: deadline(timeout),
            seed: self.seed,
            ..RunOptions::default()
        };
        let inner = self.inner.clone();
        let r = run_off_thread(py, move |_| -> Result<PolygonSoup, subgram::Error> {
            match &*inner {
                subgram::System::Surface(s) => Ok(s.subdivide(&opts, |_| {})?.mesh.to_quad_soup()),
                subgram::System::Vv(v) => Ok(v.run(&opts, |_| {})?.soup),
                subgram::System::Shapes(s) => Ok(s.derive(&opts)?.soup),
                _ => Err(subgram::Error::Usage(
                    "a curve has no mesh: use derive() or render()".into(),
                )),
            }
        })?;
        let soup = r.map_err(|e| py_error(py, e))?;
        soup_out(py, &soup)
    }
}

// ---------------------------------------------------------------------------
// Word

/// A derived word of modules (`System.derive`).
#[pyclass(module = "subgram._subgram", frozen)]
struct Word {
    system: Arc<subgram::System>,
    word: subgram::Word,
    ring: bool,
    step: u64,
    names: std::sync::OnceLock<Vec<Py<PyString>>>,
}

impl Word {
    fn curve(&self) -> &subgram::Curve {
        match &*self.system {
            subgram::System::Curve(c) => c,
            _ => unreachable!("words come from curves"),
        }
    }

    /// The alphabet's names as Python strings, made once.
    fn names(&self, py: Python<'_>) -> &Vec<Py<PyString>> {
        self.names.get_or_init(|| {
            self.curve()
                .program
                .alphabet
                .kinds
                .iter()
                .map(|k| PyString::new(py, &k.name).unbind())
                .collect()
        })
    }

    fn index(&self, i: isize) -> PyResult<usize> {
        let n = self.word.len() as isize;
        let j = if i < 0 { i + n } else { i };
        if j < 0 || j >= n {
            return Err(PyIndexError::new_err("module index out of range"));
        }
        Ok(j as usize)
    }
}

fn value_to_py(py: Python<'_>, v: &Value) -> PyResult<Py<PyAny>> {
    Ok(match v {
        Value::Int(i) => i.into_pyobject(py)?.into_any().unbind(),
        Value::Float(f) => f.into_pyobject(py)?.into_any().unbind(),
        Value::Bool(b) => b.into_pyobject(py)?.to_owned().into_any().unbind(),
        Value::V2(p) => PyTuple::new(py, [p.x, p.y])?.into_any().unbind(),
        Value::V3(p) => PyTuple::new(py, [p.x, p.y, p.z])?.into_any().unbind(),
        Value::Struct(fields) => {
            let items = fields
                .iter()
                .map(|f| value_to_py(py, f))
                .collect::<PyResult<Vec<_>>>()?;
            PyTuple::new(py, items)?.into_any().unbind()
        }
        Value::Str(s) => PyString::new(py, s).into_any().unbind(),
        other => PyString::new(py, &format!("{other:?}")).into_any().unbind(),
    })
}

#[pymethods]
impl Word {
    fn __len__(&self) -> usize {
        self.word.len()
    }

    /// True for a ring L-system's word (`ring L-system: 1`).
    #[getter]
    fn ring(&self) -> bool {
        self.ring
    }

    /// The derivation steps taken.
    #[getter]
    fn step(&self) -> u64 {
        self.step
    }

    /// Each module's symbol, a list of str.
    #[getter]
    fn symbols<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let names = self.names(py);
        PyList::new(
            py,
            self.word
                .syms()
                .iter()
                .map(|s| names[s.0 as usize].bind(py)),
        )
    }

    /// The alphabet: the name of each symbol id (`symbol_ids` indexes it).
    #[getter]
    fn alphabet(&self) -> Vec<String> {
        self.curve()
            .program
            .alphabet
            .kinds
            .iter()
            .map(|k| k.name.clone())
            .collect()
    }

    /// Each module's symbol id (uint16), an index into `alphabet`.
    #[getter]
    fn symbol_ids<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u16>> {
        let ids: Vec<u16> = self.word.syms().iter().map(|s| s.0).collect();
        ids.into_pyarray(py)
    }

    /// All modules' parameter slots, one float64 array (vectors take 2 or 3
    /// slots, ints and bools are stored as floats).
    #[getter]
    fn slots<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, self.word.all_slots())
    }

    /// Where each module's slots start in `slots`, and the end: n + 1
    /// int64 offsets.
    #[getter]
    fn offsets<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        let n = self.word.len();
        let mut out = Vec::with_capacity(n + 1);
        let mut at = 0i64;
        out.push(0);
        for i in 0..n {
            at += self.word.data(i).len() as i64;
            out.push(at);
        }
        out.into_pyarray(py)
    }

    /// The parameters of every module with `symbol`: a float64 array, one
    /// row a module and one column a slot (NaN where a module has fewer
    /// slots than the widest).
    fn params<'py>(&self, py: Python<'py>, symbol: &str) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let alphabet = &self.curve().program.alphabet;
        let ids: Vec<u16> = alphabet
            .kinds
            .iter()
            .enumerate()
            .filter(|(_, k)| k.name == symbol)
            .map(|(i, _)| i as u16)
            .collect();
        if ids.is_empty() {
            return Err(PyKeyError::new_err(format!(
                "the program has no module `{symbol}`"
            )));
        }
        let word = &self.word;
        let array = py.detach(|| {
            let syms = word.syms();
            let wanted = |s: u16| ids.contains(&s);
            let (mut rows, mut width, mut uniform) = (0usize, None::<usize>, true);
            for (i, s) in syms.iter().enumerate() {
                if wanted(s.0) {
                    let w = word.data(i).len();
                    match width {
                        None => width = Some(w),
                        Some(x) if x != w => {
                            uniform = false;
                            width = Some(x.max(w));
                        }
                        _ => {}
                    }
                    rows += 1;
                }
            }
            let width = width.unwrap_or(0);
            let mut out = Vec::with_capacity(rows * width);
            for (i, s) in syms.iter().enumerate() {
                if wanted(s.0) {
                    let d = word.data(i);
                    out.extend_from_slice(d);
                    if !uniform {
                        out.extend(std::iter::repeat_n(f64::NAN, width - d.len()));
                    }
                }
            }
            Array2::from_shape_vec((rows, width), out).expect("rows × width slots")
        });
        Ok(array.into_pyarray(py))
    }

    /// The number of modules with each symbol, a dict.
    fn counts(&self) -> std::collections::BTreeMap<String, usize> {
        let alphabet = &self.curve().program.alphabet;
        let mut by_id = vec![0usize; alphabet.kinds.len()];
        for s in self.word.syms() {
            by_id[s.0 as usize] += 1;
        }
        let mut out = std::collections::BTreeMap::new();
        for (k, n) in alphabet.kinds.iter().zip(by_id) {
            if n > 0 {
                *out.entry(k.name.clone()).or_default() += n;
            }
        }
        out
    }

    /// `word[i]` → `(symbol, params)`, params a tuple (vectors as tuples).
    fn __getitem__<'py>(&self, py: Python<'py>, i: isize) -> PyResult<Bound<'py, PyTuple>> {
        let i = self.index(i)?;
        let c = self.curve();
        let sym = self.word.sym(i);
        let values = self
            .word
            .values(i, &c.program.alphabet, &c.program.structs)
            .iter()
            .map(|v| value_to_py(py, v))
            .collect::<PyResult<Vec<_>>>()?;
        let name = self.names(py)[sym.0 as usize].clone_ref(py);
        PyTuple::new(
            py,
            [
                name.into_any(),
                PyTuple::new(py, values)?.into_any().unbind(),
            ],
        )
    }

    /// The CLI's `subgram derive --format json` (without the final newline).
    fn to_json(&self, py: Python<'_>) -> String {
        py.detach(|| self.curve().word_json(&self.word, self.ring, self.step))
    }

    /// The CLI's `subgram derive` text (without the final newline).
    fn to_text(&self, py: Python<'_>) -> String {
        py.detach(|| self.curve().word_text(&self.word))
    }

    fn __repr__(&self) -> String {
        format!(
            "<subgram.Word of {} modules, step {}{}>",
            self.word.len(),
            self.step,
            if self.ring { ", ring" } else { "" }
        )
    }
}

// ---------------------------------------------------------------------------
// Meshes

/// `(vertices n×3 float64, indices int64, sizes int64)`.
fn soup_out<'py>(py: Python<'py>, soup: &PolygonSoup) -> PyResult<Bound<'py, PyTuple>> {
    let mut pos = Vec::with_capacity(3 * soup.positions.len());
    for p in &soup.positions {
        pos.extend_from_slice(&[p.x, p.y, p.z]);
    }
    let v = Array2::from_shape_vec((soup.positions.len(), 3), pos)
        .expect("n × 3")
        .into_pyarray(py);
    let indices: Vec<i64> = soup.faces.indices().iter().map(|&i| i as i64).collect();
    let sizes: Vec<i64> = soup.faces.iter().map(|f| f.len() as i64).collect();
    PyTuple::new(
        py,
        [
            v.into_any(),
            indices.into_pyarray(py).into_any(),
            sizes.into_pyarray(py).into_any(),
        ],
    )
}

fn soup_in(
    vertices: &PyReadonlyArray2<'_, f64>,
    indices: &PyReadonlyArray1<'_, i64>,
    sizes: &PyReadonlyArray1<'_, i64>,
) -> PyResult<PolygonSoup> {
    let v = vertices.as_array();
    if v.ncols() != 3 {
        return Err(PyValueError::new_err(format!(
            "vertices: an n×3 array, not n×{}",
            v.ncols()
        )));
    }
    let positions: Vec<glam::DVec3> = v
        .rows()
        .into_iter()
        .map(|r| glam::DVec3::new(r[0], r[1], r[2]))
        .collect();
    let idx = indices.as_slice()?;
    let sz = sizes.as_slice()?;
    let n = positions.len() as i64;
    let mut faces = Faces::with_capacity(sz.len(), idx.len());
    let mut at = 0usize;
    let mut face = Vec::new();
    for (k, &s) in sz.iter().enumerate() {
        if s < 3 {
            return Err(PyValueError::new_err(format!(
                "face {k} has {s} corners; a face has at least 3"
            )));
        }
        let end = at + s as usize;
        let Some(corners) = idx.get(at..end) else {
            return Err(PyValueError::new_err(
                "faces: fewer indices than the sizes say",
            ));
        };
        face.clear();
        for &i in corners {
            if i < 0 || i >= n {
                return Err(PyValueError::new_err(format!(
                    "face {k} names vertex {i}, and there are {n}"
                )));
            }
            face.push(i as u32);
        }
        faces.push(&face);
        at = end;
    }
    Ok(PolygonSoup {
        positions,
        faces,
        ..PolygonSoup::default()
    })
}

/// The surface grammars of lsystems/surfaces, by name (`subdivide`'s
/// built-in schemes): the very files, so that a run is the CLI's with
/// `--grammar lsystems/surfaces/NAME.lsys`.
const SCHEMES: &[(&str, &str)] = &[
    ("loop", include_str!("../../lsystems/surfaces/loop.lsys")),
    (
        "catmull-clark",
        include_str!("../../lsystems/surfaces/catmull-clark.lsys"),
    ),
    ("sqrt3", include_str!("../../lsystems/surfaces/sqrt3.lsys")),
    (
        "doo-sabin",
        include_str!("../../lsystems/surfaces/doo-sabin.lsys"),
    ),
    (
        "four-eight",
        include_str!("../../lsystems/surfaces/four-eight.lsys"),
    ),
    ("c4", include_str!("../../lsystems/surfaces/c4.lsys")),
    (
        "peters",
        include_str!("../../lsystems/surfaces/peters.lsys"),
    ),
];

/// The names `subdivide` takes as built-in schemes.
#[pyfunction]
fn schemes() -> Vec<&'static str> {
    SCHEMES.iter().map(|(n, _)| *n).collect()
}

/// `_subdivide(vertices, indices, sizes, grammar, steps, defines, timeout)`:
/// `(vertices, indices, sizes)` of the subdivided mesh.
#[pyfunction]
#[pyo3(signature = (vertices, indices, sizes, grammar, steps=None, defines=Vec::new(), timeout=None))]
#[allow(clippy::too_many_arguments)]
fn _subdivide<'py>(
    py: Python<'py>,
    vertices: PyReadonlyArray2<'py, f64>,
    indices: PyReadonlyArray1<'py, i64>,
    sizes: PyReadonlyArray1<'py, i64>,
    grammar: String,
    steps: Option<u64>,
    defines: Vec<String>,
    timeout: Option<f64>,
) -> PyResult<Bound<'py, PyTuple>> {
    let soup = soup_in(&vertices, &indices, &sizes)?;
    drop((vertices, indices, sizes));
    let builtin = SCHEMES.iter().find(|(n, _)| *n == grammar).map(|(_, t)| *t);
    let opts = load_options(&defines, false);
    let run = RunOptions {
        steps,
        deadline: deadline(timeout),
        ..RunOptions::default()
    };
    let r = run_off_thread(py, move |_| -> Result<PolygonSoup, subgram::Error> {
        let system = match builtin {
            Some(text) => subgram::load_text(&format!("{grammar}.lsys"), text, &opts)?,
            None => subgram::load(&grammar, &opts)?,
        };
        match system {
            subgram::System::Surface(s) => {
                let mut mesh = Mesh::from_soup(&soup)
                    .map_err(|e| subgram::Error::Failed(format!("the mesh: {}", e.message)))?;
                let n = s.steps(run.steps)?;
                s.run_on(&mut mesh, n, run.deadline, |_| {})?;
                // What `subgram subdivide` writes (mesh::io::write_mesh):
                // basic blocks merged into polygons where there are any.
                Ok(mesh.to_quad_soup())
            }
            subgram::System::Vv(v) => Ok(v.run_soup(&soup, &run)?.soup),
            other => Err(subgram::Error::Usage(format!(
                "`{grammar}` is a {} system, not a surface grammar or vv program",
                kind_name(&other)
            ))),
        }
    })?;
    let soup = r.map_err(|e| py_error(py, e))?;
    soup_out(py, &soup)
}

/// `_read_mesh(path)`: `(vertices, indices, sizes)` of a mesh file, read as
/// the CLI reads it.
#[pyfunction]
fn read_mesh<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyTuple>> {
    let r = run_off_thread(py, |_| subgram::mesh::io::read(&path))?;
    let soup = r.map_err(|e| py_error(py, subgram::Error::from(e)))?;
    soup_out(py, &soup)
}

/// `_write_mesh(path, vertices, indices, sizes)`: the mesh written as the
/// CLI writes it (.obj, .off, .ply by the extension).
#[pyfunction]
fn _write_mesh<'py>(
    py: Python<'py>,
    path: PathBuf,
    vertices: PyReadonlyArray2<'py, f64>,
    indices: PyReadonlyArray1<'py, i64>,
    sizes: PyReadonlyArray1<'py, i64>,
) -> PyResult<()> {
    let soup = soup_in(&vertices, &indices, &sizes)?;
    let r = run_off_thread(py, |_| subgram::mesh::io::write(&path, &soup))?;
    r.map_err(|e| py_error(py, subgram::Error::from(e)))
}

// ---------------------------------------------------------------------------
// Reverse subdivision, inference, analysis

/// `_reverse(points, steps, open, scheme, timeout)`: `(coarse, details
/// JSON)`.
#[pyfunction]
#[pyo3(signature = (points, steps, open=false, scheme=None, timeout=None))]
fn _reverse<'py>(
    py: Python<'py>,
    points: PyReadonlyArray2<'py, f64>,
    steps: usize,
    open: bool,
    scheme: Option<String>,
    timeout: Option<f64>,
) -> PyResult<Bound<'py, PyTuple>> {
    let p = points.as_array();
    if p.ncols() != 2 {
        return Err(PyValueError::new_err(format!(
            "points: an n×2 array, not n×{}",
            p.ncols()
        )));
    }
    let contour = subgram::reverse::input::Contour {
        points: p
            .rows()
            .into_iter()
            .map(|r| glam::DVec2::new(r[0], r[1]))
            .collect(),
        closed: !open,
        source: "points".into(),
    };
    drop(points);
    let r = run_off_thread(py, move |_| -> Result<_, subgram::Error> {
        let mut scheme = match &scheme {
            Some(s) => subgram::reverse::Scheme::from_file(Path::new(s), contour.closed)?,
            None => subgram::reverse::Scheme::builtin(contour.closed),
        };
        scheme.deadline = deadline(timeout);
        let opts = subgram::reverse::ReverseOptions {
            steps,
            phase: subgram::reverse::Phase::Auto,
            details: true,
        };
        let r = subgram::reverse::reverse(&scheme, &contour, &opts)?;
        let details = serde_json_string(&r.details)?;
        let report = subgram::reverse::report(&scheme, &contour, &r)?;
        let report = serde_json_string(&report)?;
        Ok((r.coarse, details, report))
    })?;
    let (coarse, details, report) = r.map_err(|e| py_error(py, e))?;
    let mut flat = Vec::with_capacity(2 * coarse.len());
    for q in &coarse {
        flat.extend_from_slice(&[q.x, q.y]);
    }
    let c = Array2::from_shape_vec((coarse.len(), 2), flat)
        .expect("n × 2")
        .into_pyarray(py);
    PyTuple::new(
        py,
        [
            c.into_any(),
            PyString::new(py, &details).into_any(),
            PyString::new(py, &report).into_any(),
        ],
    )
}

fn serde_json_string(v: &impl serde::Serialize) -> Result<String, subgram::Error> {
    serde_json::to_string(v).map_err(|e| subgram::Error::Failed(e.to_string()))
}

/// `_render_mesh_file(file, output, size, view, wireframe)`: `subgram
/// render FILE -o OUTPUT` for a mesh file, drawn as it is.
#[pyfunction]
#[pyo3(signature = (file, output, size=None, view=None, wireframe=true))]
fn _render_mesh_file(
    py: Python<'_>,
    file: String,
    output: String,
    size: Option<(u32, u32)>,
    view: Option<String>,
    wireframe: bool,
) -> PyResult<()> {
    let mut a = subgram::command::RenderArgs::new(file, output);
    a.size = size;
    a.view = view;
    a.wireframe = wireframe;
    a.force = false;
    let r = run_off_thread(py, |_| subgram::command::render(&a, |_| {}))?;
    r.map(|_| ()).map_err(|e| py_error(py, e))
}

/// `_infer(rows, rows_file, mask, arity, open, reverse, shift, list,
/// ordered)`: the program text `subgram infer` prints.
#[pyfunction]
#[pyo3(signature = (rows=None, rows_file=None, mask=None, arity=None, open=false, reverse=false, shift=None, list=false, ordered=false))]
#[allow(clippy::too_many_arguments)]
fn _infer(
    py: Python<'_>,
    rows: Option<String>,
    rows_file: Option<String>,
    mask: Option<String>,
    arity: Option<usize>,
    open: bool,
    reverse: bool,
    shift: Option<i64>,
    list: bool,
    ordered: bool,
) -> PyResult<String> {
    let a = subgram::command::InferArgs {
        rows,
        rows_file,
        mask,
        arity,
        open,
        reverse,
        shift,
        list,
        ordered,
        output: None,
    };
    let r = run_off_thread(py, |_| subgram::command::infer(&a))?;
    r.map_err(|e| py_error(py, e))
}

/// `_analyze(file, defines, valences)`: `subgram analyze --format json`.
#[pyfunction]
#[pyo3(signature = (file, defines=Vec::new(), valences=None))]
fn _analyze(
    py: Python<'_>,
    file: String,
    defines: Vec<String>,
    valences: Option<Vec<usize>>,
) -> PyResult<String> {
    let a = subgram::command::AnalyzeArgs {
        file,
        json: true,
        defines,
        picture: None,
        valences,
    };
    let r = run_off_thread(py, |_| subgram::command::analyze(&a))?;
    r.map_err(|e| py_error(py, e))
}

/// `check(path, defines=None, double=False)`: what `subgram check` prints
/// for a file that checks (an Error for one that does not).
#[pyfunction]
#[pyo3(signature = (path, *, defines=None, double=false))]
fn check(
    py: Python<'_>,
    path: String,
    defines: Option<&Bound<'_, PyAny>>,
    double: bool,
) -> PyResult<String> {
    let defines = defines_of(defines)?;
    let r = run_off_thread(py, |_| subgram::command::check(&path, &defines, double))?;
    r.map_err(|e| py_error(py, e))
}

#[pymodule]
fn _subgram(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    let error = py.get_type::<Error>();
    error.setattr("path", py.None())?;
    error.setattr("line", py.None())?;
    error.setattr("column", py.None())?;
    error.setattr("usage", false)?;
    m.add("Error", error)?;
    m.add_class::<System>()?;
    m.add_class::<Word>()?;
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(check, m)?)?;
    m.add_function(wrap_pyfunction!(schemes, m)?)?;
    m.add_function(wrap_pyfunction!(_subdivide, m)?)?;
    m.add_function(wrap_pyfunction!(read_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(_write_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(_reverse, m)?)?;
    m.add_function(wrap_pyfunction!(_infer, m)?)?;
    m.add_function(wrap_pyfunction!(_render_mesh_file, m)?)?;
    m.add_function(wrap_pyfunction!(_analyze, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
