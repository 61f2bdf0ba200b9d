//! An environmental program run as a process, spoken to with lpfg's
//! protocol. (Being written: see the brief.)

use std::path::PathBuf;
use std::time::Duration;

use crate::deadline::Deadline;
use crate::model::comm::CommSpec;
use crate::rewrite::environment::{Environment, EnvironmentStarter};

/// Starts the `.e` file's program as a process for each run.
#[derive(Clone, Debug)]
pub struct Starter {
    pub spec: CommSpec,
    pub folder: PathBuf,
    pub timeout: Duration,
}

impl Starter {
    pub fn new(spec: CommSpec, folder: PathBuf, timeout: Duration) -> Starter {
        Starter {
            spec,
            folder,
            timeout,
        }
    }
}

impl EnvironmentStarter for Starter {
    fn start(&self, _deadline: Option<Deadline>) -> Result<Box<dyn Environment>, String> {
        Err(format!(
            "{}: external environmental programs are not run yet",
            self.spec.program()
        ))
    }

    fn following_module(&self) -> bool {
        self.spec.following
    }
}
