//! Environmental programs of open L-systems: what answers the
//! communication modules (`E1`, `E2`, `EA20`) of a model whose folder has
//! a `.e` file (the exchange: [`EnvironmentStarter`], [`Environment`], re-exported here).
//!
//! * [`honda81`] and [`shadowpyramid`]: vlab's programs of those names,
//!   built in (no process, nothing to install), chosen when the `.e`
//!   file's `executable:` names one of them.
//! * [`external`]: any other program, started as lpfg starts it and spoken
//!   to with lpfg's protocol ([`protocol`]: the `.to_field`/`.from_field`
//!   files and a pair of SysV semaphores), so that vlab's programs and a
//!   user's own work unchanged.
//!
//! [`starter`] makes the one that a model's `.e` file asks for.
//!
//! **Layer.** It uses `deadline`, `lang` (the `printf` formatting),
//! `model` (the `.e` file) and `rewrite` (the traits it implements); it is
//! used by `load`. Nothing here names a layer above (see ARCHITECTURE.md,
//! "Layers").

pub mod external;
pub mod honda81;
pub mod protocol;
pub mod shadowpyramid;
mod spec_file;

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Duration;

use crate::model::comm::CommSpec;
use crate::model::text::read_text;
use crate::model::ModelError;
pub use crate::rewrite::environment::{
    Answer, Environment, EnvironmentStarter, Following, Frame, Query,
};

/// How environmental programs are run.
#[derive(Clone, Debug)]
pub struct Options {
    /// Run the program named by the `.e` file as a process even where a
    /// built-in one exists (`honda81`).
    pub external: bool,
    /// How long an external program may take to answer one step before it
    /// is stopped (default 30 s).
    pub answer_timeout: Duration,
    /// lpfg's `-cleanEA20`: an `EA20` answered with fewer than twenty
    /// values has the rest zeroed.
    pub clean_ea20: bool,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            external: false,
            answer_timeout: Duration::from_secs(30),
            clean_ea20: false,
        }
    }
}

/// The built-in programs, by the name an `.e` file gives them.
pub const BUILT_IN: &[&str] = &["honda81", "shadowpyramid"];

/// What starts the environment that `spec` asks for: the built-in program
/// of its name (reading its parameter file now, so that a bad one is
/// reported before the run), or the named program as a process.
pub fn starter(spec: &CommSpec, opts: &Options) -> Result<Arc<dyn EnvironmentStarter>, ModelError> {
    let inner = program(spec, opts)?;
    Ok(match opts.clean_ea20 {
        true => Arc::new(Cleaning(inner)),
        false => inner,
    })
}

/// An environment whose runs zero what an `EA20` answer leaves
/// (`-cleanEA20`).
#[derive(Debug)]
struct Cleaning(Arc<dyn EnvironmentStarter>);

impl EnvironmentStarter for Cleaning {
    fn start(
        &self,
        deadline: Option<crate::deadline::Deadline>,
    ) -> Result<Box<dyn crate::rewrite::environment::Environment>, String> {
        self.0.start(deadline)
    }

    fn following_module(&self) -> bool {
        self.0.following_module()
    }

    fn clean_ea20(&self) -> bool {
        true
    }
}

/// The program itself: built in, or a process.
fn program(spec: &CommSpec, opts: &Options) -> Result<Arc<dyn EnvironmentStarter>, ModelError> {
    let folder = folder_of(spec);
    let name = Path::new(spec.program())
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    if !opts.external && BUILT_IN.contains(&name.as_str()) {
        let files = spec.spec_files();
        let Some(file) = files.first() else {
            return Err(ModelError::FileAt {
                path: spec.path.display().to_string(),
                line: spec.command_line.0,
                text: spec.command_line.1.clone(),
                start: 0,
                end: spec.command_line.1.len(),
                message: format!(
                    "{name} needs its parameter file after `-e FILE` \
                     (`executable: {name} -e commfile.e {name}.spec`)"
                ),
            });
        };
        let path = folder.join(file);
        let text = read_text(&path)?;
        if name == "shadowpyramid" {
            let settings = shadowpyramid::Settings::read(&path, &text)?;
            return Ok(Arc::new(shadowpyramid::Starter {
                settings,
                spec: spec.clone(),
                file: path,
            }));
        }
        let settings = honda81::Settings::read(&path, &text)?;
        return Ok(Arc::new(honda81::Starter {
            settings,
            spec: spec.clone(),
            file: path,
        }));
    }
    Ok(Arc::new(external::Starter::new(
        spec.clone(),
        folder,
        opts.answer_timeout,
    )))
}

/// The folder the program runs in: the `.e` file's (the model folder).
pub fn folder_of(spec: &CommSpec) -> PathBuf {
    match spec.path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}
