//! An environmental program run as a process and spoken to with lpfg's
//! protocol (the master's side; [`super::protocol`] has the text).
//!
//! For each run, [`Starter::start`]:
//!
//! 1. makes a SysV set of two semaphores under a fresh key `KEY` (created
//!    with `IPC_EXCL`, so that no other run, in this process or another,
//!    shares it; never a multiple of 4, so never the `getpid()*4` of an
//!    lpfg), both at 0;
//! 2. starts `PROGRAM -k KEY -ext KEY.0 REST…` (the `.e` file's
//!    `executable:` line with the two options after the program's name) in
//!    the model folder, the program found through `PATH` (a name with a `/`
//!    is relative to the model folder). Its standard error is ours; its
//!    standard output goes to our standard error too, so that what it
//!    prints cannot mix with a word that `subgram derive` writes to
//!    standard output; its standard input is empty.
//!
//! Each step ([`Environment::exchange`]) writes the queries to
//! `.to_fieldKEY.0` in the model folder, raises semaphore 0, and waits for
//! semaphore 1 (at most the answer timeout, and never past the run's
//! deadline; every 50 ms it looks whether the program has exited); then it
//! reads the chunk in `.from_fieldKEY.0` (and removes the file, so that a
//! signal without a new answer cannot read an old one), and while a chunk
//! is not the last, raises semaphore 0 again and waits for the next one. An error is
//! a one-line message that names the program: it could not be started, it
//! exited before answering, it gave no answer in time (then it is killed),
//! its answer file is missing or malformed. Answers that are well formed
//! and that lpfg cannot use (a module not sent, the wrong number of
//! values) go to the derivation, which passes over them with a warning,
//! as lpfg does.
//!
//! Dropping the environment (at the end of the run, after an error, or
//! while a panic unwinds) ends it: `Control: 9 0` to the program, a second
//! for it to exit, then `SIGKILL`; the process is reaped, both files are
//! removed and the semaphore set too. Nothing is left behind. (A `subgram`
//! that is itself killed cannot clean up; lpfg leaves the same behind.)

use std::path::{Path, PathBuf};
use std::time::Duration;

use crate::deadline::Deadline;
use crate::model::comm::CommSpec;
use crate::rewrite::environment::{Environment, EnvironmentStarter};

/// Starts the `.e` file's program as a process for each run.
#[derive(Clone, Debug)]
pub struct Starter {
    pub spec: CommSpec,
    /// The model folder: where the program runs and the files go.
    pub folder: PathBuf,
    /// How long the program may take to answer one step.
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

    /// How messages name the program: `the environmental program
    /// `NAME``, as the `.e` file names it.
    fn who(&self) -> String {
        format!("the environmental program `{}`", self.spec.program())
    }
}

impl EnvironmentStarter for Starter {
    fn start(&self, deadline: Option<Deadline>) -> Result<Box<dyn Environment>, String> {
        #[cfg(target_os = "linux")]
        {
            let deadline = deadline.or_else(crate::deadline::current);
            Ok(Box::new(linux::Running::start(self, deadline)?))
        }
        #[cfg(not(target_os = "linux"))]
        {
            let _ = deadline;
            Err(format!(
                "{} cannot be run: external environmental programs need SysV semaphores, \
                 which subgram uses on Linux only (the built-in ones: {})",
                self.who(),
                super::BUILT_IN.join(", ")
            ))
        }
    }

    fn following_module(&self) -> bool {
        self.spec.following
    }
}

/// The command line that starts the program for `key`: `command` (the
/// `.e` file's, `-e FILE` included) with `-k KEY -ext KEY.0` after the
/// program's name, as lpfg starts it.
pub fn command_line(command: &[String], key: i32) -> Vec<String> {
    let mut out = Vec::with_capacity(command.len() + 4);
    out.extend(command.first().cloned());
    out.push("-k".into());
    out.push(key.to_string());
    out.push("-ext".into());
    out.push(format!("{key}.0"));
    out.extend(command.iter().skip(1).cloned());
    out
}

/// What to run for the program named `program`: a name without a `/` as
/// it is (looked up in `PATH`), one with a `/` relative to the model
/// folder `folder` (where lpfg's `execvp` runs it).
pub fn program_path(program: &str, folder: &Path) -> PathBuf {
    let p = Path::new(program);
    if !program.contains('/') || p.is_absolute() {
        return p.to_path_buf();
    }
    let mut out = std::path::absolute(folder).unwrap_or_else(|_| folder.to_path_buf());
    out.extend(
        p.components()
            .filter(|c| *c != std::path::Component::CurDir),
    );
    out
}

/// The file the master writes for `key`, in the model folder.
pub fn to_field_name(key: i32) -> String {
    format!(".to_field{key}.0")
}

/// The file the program writes for `key`, in the model folder.
pub fn from_field_name(key: i32) -> String {
    format!(".from_field{key}.0")
}

/// The semaphore keys that runs in this process have used for programs
/// in `folder` (the model folder as the `.e` file's path gives it), oldest
/// first (of the last [`KEPT_KEYS`] runs): for tests, which look that none
/// of them is left.
pub fn keys_used_in(folder: &Path) -> Vec<i32> {
    let used = USED.lock().unwrap_or_else(|e| e.into_inner());
    used.iter()
        .filter(|(f, _)| f == folder)
        .map(|(_, k)| *k)
        .collect()
}

/// How many runs' keys [`keys_used_in`] remembers.
pub const KEPT_KEYS: usize = 4096;

static USED: std::sync::Mutex<Vec<(PathBuf, i32)>> = std::sync::Mutex::new(Vec::new());

#[cfg(target_os = "linux")]
mod linux {
    use std::io::ErrorKind;
    use std::os::fd::AsFd;
    use std::path::PathBuf;
    use std::process::{Child, Command, ExitStatus, Stdio};
    use std::sync::atomic::{AtomicU32, Ordering};
    use std::time::{Duration, Instant};

    use super::{command_line, from_field_name, program_path, to_field_name};
    use super::{Starter, KEPT_KEYS, USED};
    use crate::deadline::Deadline;
    use crate::enviro::protocol::{queries_text, read_chunk, EXIT};
    use crate::model::comm::CommSpec;
    use crate::rewrite::environment::{Answer, Environment, Query};

    // glibc and musl have it; the libc crate does not declare it.
    extern "C" {
        fn semtimedop(
            semid: libc::c_int,
            sops: *mut libc::sembuf,
            nsops: libc::size_t,
            timeout: *const libc::timespec,
        ) -> libc::c_int;
    }

    /// How often a wait for an answer looks whether the program exited.
    const SLICE: Duration = Duration::from_millis(50);
    /// How long the program has to exit after `Control: 9 0` (lpfg's).
    const EXIT_GRACE: Duration = Duration::from_secs(1);

    /// A SysV semaphore set of two, removed on drop.
    #[derive(Debug)]
    pub(super) struct SemSet {
        id: libc::c_int,
        key: libc::key_t,
    }

    static COUNTER: AtomicU32 = AtomicU32::new(0);

    impl SemSet {
        /// A new set under a key that no live set has, whose files do not
        /// exist in `folder`; both semaphores 0.
        pub(super) fn create(folder: &std::path::Path) -> Result<SemSet, String> {
            let pid = std::process::id();
            for _ in 0..10_000 {
                let n = COUNTER.fetch_add(1, Ordering::Relaxed);
                let h = pid.wrapping_mul(0x9E37_79B1) ^ n.wrapping_mul(0x85EB_CA77);
                // Positive, and never a multiple of 4 (lpfg's keys are
                // its pid times 4), so never 0 (IPC_PRIVATE).
                let key = ((h & 0x7FFF_FFFC) | 1) as libc::key_t;
                if folder.join(to_field_name(key)).exists()
                    || folder.join(from_field_name(key)).exists()
                {
                    continue;
                }
                // SAFETY: a plain system call with integer arguments.
                let id = unsafe { libc::semget(key, 2, libc::IPC_CREAT | libc::IPC_EXCL | 0o600) };
                if id < 0 {
                    let e = std::io::Error::last_os_error();
                    if e.raw_os_error() == Some(libc::EEXIST) {
                        continue;
                    }
                    return Err(format!("cannot make a SysV semaphore set: {e}"));
                }
                let set = SemSet { id, key };
                let mut zero: [libc::c_ushort; 2] = [0, 0];
                // SAFETY: SETALL reads two values (the set's size) through
                // the pointer, which is semun's `array`.
                if unsafe { libc::semctl(id, 0, libc::SETALL, zero.as_mut_ptr()) } < 0 {
                    return Err(format!(
                        "cannot set the SysV semaphores: {}",
                        std::io::Error::last_os_error()
                    ));
                }
                return Ok(set);
            }
            Err("cannot make a SysV semaphore set: every key tried is taken".into())
        }

        pub(super) fn key(&self) -> libc::key_t {
            self.key
        }

        /// Raises semaphore `n` by one.
        fn post(&self, n: u16) -> std::io::Result<()> {
            let mut op = libc::sembuf {
                sem_num: n,
                sem_op: 1,
                sem_flg: 0,
            };
            loop {
                // SAFETY: one valid sembuf for a set this value owns.
                if unsafe { libc::semop(self.id, &mut op, 1) } == 0 {
                    return Ok(());
                }
                let e = std::io::Error::last_os_error();
                if e.kind() != ErrorKind::Interrupted {
                    return Err(e);
                }
            }
        }

        /// Takes one from semaphore `n`, waiting at most `wait`: whether it
        /// did (false: the time passed, or a signal came).
        fn take(&self, n: u16, wait: Duration) -> std::io::Result<bool> {
            let mut op = libc::sembuf {
                sem_num: n,
                sem_op: -1,
                sem_flg: 0,
            };
            let t = libc::timespec {
                tv_sec: wait.as_secs() as libc::time_t,
                tv_nsec: wait.subsec_nanos() as libc::c_long,
            };
            // SAFETY: one valid sembuf and a valid timespec, for a set this
            // value owns.
            if unsafe { semtimedop(self.id, &mut op, 1, &t) } == 0 {
                return Ok(true);
            }
            let e = std::io::Error::last_os_error();
            match e.raw_os_error() {
                Some(libc::EAGAIN) | Some(libc::EINTR) => Ok(false),
                _ => Err(e),
            }
        }
    }

    impl Drop for SemSet {
        fn drop(&mut self) {
            // SAFETY: removes the set this value made; no pointer.
            unsafe { libc::semctl(self.id, 0, libc::IPC_RMID) };
        }
    }

    /// One running program.
    #[derive(Debug)]
    pub(super) struct Running {
        who: String,
        spec: CommSpec,
        to_field: PathBuf,
        from_field: PathBuf,
        /// `None` once it has been reaped.
        child: Option<Child>,
        timeout: Duration,
        deadline: Option<Deadline>,
        /// `None` once removed.
        sem: Option<SemSet>,
    }

    impl Running {
        pub(super) fn start(s: &Starter, deadline: Option<Deadline>) -> Result<Running, String> {
            let who = s.who();
            let sem = SemSet::create(&s.folder).map_err(|e| format!("{who}: {e}"))?;
            let key = sem.key();
            {
                let mut used = USED.lock().unwrap_or_else(|e| e.into_inner());
                if used.len() >= KEPT_KEYS {
                    used.remove(0);
                }
                used.push((s.folder.clone(), key));
            }
            let line = command_line(&s.spec.command, key);
            let program = program_path(&line[0], &s.folder);
            let mut cmd = Command::new(&program);
            cmd.args(&line[1..])
                .current_dir(&s.folder)
                .stdin(Stdio::null())
                .stderr(Stdio::inherit());
            match std::io::stderr().as_fd().try_clone_to_owned() {
                Ok(err) => cmd.stdout(Stdio::from(err)),
                Err(_) => cmd.stdout(Stdio::null()),
            };
            let child = cmd.spawn().map_err(|e| {
                let (n, text) = &s.spec.command_line;
                let why = match e.kind() {
                    ErrorKind::NotFound if !s.spec.program().contains('/') => {
                        "not found: is it installed, and is its folder in PATH?".to_string()
                    }
                    ErrorKind::NotFound => format!("{} does not exist", program.display()),
                    ErrorKind::PermissionDenied => {
                        format!("{} is not executable ({e})", program.display())
                    }
                    _ => e.to_string(),
                };
                format!(
                    "cannot start {who} ({}:{n}: `{}`): {why}",
                    s.spec.path.display(),
                    text.trim()
                )
            })?;
            interrupt::enter();
            Ok(Running {
                who,
                spec: s.spec.clone(),
                to_field: s.folder.join(to_field_name(key)),
                from_field: s.folder.join(from_field_name(key)),
                child: Some(child),
                timeout: s.timeout,
                deadline,
                sem: Some(sem),
            })
        }

        fn sem(&self) -> Result<&SemSet, String> {
            self.sem
                .as_ref()
                .ok_or_else(|| format!("{} was stopped after an earlier error", self.who))
        }

        /// Whether the program has exited, reaping it if so.
        fn exited(&mut self) -> Option<ExitStatus> {
            let status = self.child.as_mut()?.try_wait().ok()??;
            self.child = None;
            Some(status)
        }

        /// Kills the program now and reaps it.
        fn kill(&mut self) {
            if let Some(mut c) = self.child.take() {
                let _ = c.kill();
                let _ = c.wait();
            }
        }

        /// Waits for semaphore 1 (the program's chunk is ready) until
        /// `until` (the step's answer time limit) or the run's deadline.
        fn wait_answer(&mut self, until: Instant) -> Result<(), String> {
            loop {
                let own = until.checked_duration_since(Instant::now());
                let run = self.deadline.map(|d| d.left());
                let left = match (own, run) {
                    (_, Some(None)) => {
                        self.kill();
                        let d = self.deadline.map(|d| d.message()).unwrap_or_default();
                        return Err(format!(
                            "{} gave no answer before the run's time limit, and was stopped: {d}",
                            self.who
                        ));
                    }
                    (None, _) => {
                        self.kill();
                        return Err(format!(
                            "{} gave no answer within {} s, and was stopped (the answer time \
                             limit; raise it with --env-timeout SECONDS)",
                            self.who,
                            self.timeout.as_secs_f64()
                        ));
                    }
                    (Some(a), Some(Some(b))) => a.min(b),
                    (Some(a), None) => a,
                };
                let got = self
                    .sem()?
                    .take(1, left.min(SLICE))
                    .map_err(|e| format!("{}: waiting for its answer failed: {e}", self.who))?;
                if got {
                    return Ok(());
                }
                if interrupt::pending() {
                    self.kill();
                    return Err(format!("interrupted while waiting for {}", self.who));
                }
                if let Some(status) = self.exited() {
                    return Err(match status.code() {
                        Some(code) => {
                            format!("{} exited with status {code} before answering", self.who)
                        }
                        None => format!("{} ended before answering ({status})", self.who),
                    });
                }
            }
        }

        fn step(&mut self, queries: &[Query]) -> Result<Vec<Answer>, String> {
            let who = self.who.clone();
            if let Some(status) = self.exited() {
                return Err(format!("{who} is no longer running ({status})"));
            }
            if interrupt::pending() {
                return Err(format!("interrupted before {who} was asked"));
            }
            let until = Instant::now() + self.timeout;
            let text = queries_text(&self.spec, queries)
                .map_err(|e| format!("the queries for {who} cannot be written: {e}"))?;
            let file_error =
                |p: &PathBuf, e: std::io::Error| format!("{who}: {}: {e}", p.display());
            std::fs::write(&self.to_field, text).map_err(|e| file_error(&self.to_field, e))?;
            let post = |s: &Self| {
                s.sem()?
                    .post(0)
                    .map_err(|e| format!("{who}: cannot signal it: {e}"))
            };
            post(self)?;
            let mut answers = Vec::new();
            loop {
                self.wait_answer(until)?;
                let text = std::fs::read_to_string(&self.from_field).map_err(|e| {
                    format!(
                        "{who} signalled an answer, and its file cannot be read: {}: {e}",
                        self.from_field.display()
                    )
                })?;
                // Read once: a signal without a new file finds none.
                std::fs::remove_file(&self.from_field)
                    .map_err(|e| file_error(&self.from_field, e))?;
                let chunk = read_chunk(&text).map_err(|e| {
                    format!(
                        "{who} wrote a malformed answer: {}: {e}",
                        self.from_field.display()
                    )
                })?;
                answers.extend(chunk.answers);
                if chunk.last {
                    break;
                }
                post(self)?;
            }
            Ok(answers)
        }

        /// Ends the program (asked, then killed), reaps it, and removes the
        /// files and the semaphore set. Idempotent.
        fn stop(&mut self) {
            if self.child.is_some() && self.exited().is_none() {
                let asked = std::fs::write(&self.to_field, EXIT).is_ok()
                    && self.sem.as_ref().is_some_and(|s| s.post(0).is_ok());
                if asked {
                    let until = Instant::now() + EXIT_GRACE;
                    let mut nap = Duration::from_millis(1);
                    while Instant::now() < until && self.exited().is_none() {
                        std::thread::sleep(nap);
                        nap = (nap * 2).min(Duration::from_millis(20));
                    }
                }
                self.kill();
            }
            for f in [&self.to_field, &self.from_field] {
                let _ = std::fs::remove_file(f);
            }
            self.sem = None;
        }
    }

    impl Environment for Running {
        fn exchange(&mut self, queries: &[Query]) -> Result<Vec<Answer>, String> {
            self.step(queries)
        }
    }

    impl Drop for Running {
        fn drop(&mut self) {
            self.stop();
            interrupt::leave();
        }
    }

    /// Ctrl-C (SIGINT), SIGTERM and SIGHUP while an external program runs:
    /// instead of dying at once (and leaving the two files and the
    /// semaphore set behind), the process notes the signal; the wait for
    /// an answer sees it within its 50 ms slice and fails, the derivation
    /// stops, the environment is dropped and cleans up, and then the
    /// signal is raised again with its default action, so that the
    /// command ends as the user asked. With no external program running,
    /// the signals act as always.
    pub(super) mod interrupt {
        use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

        const SIGNALS: [libc::c_int; 3] = [libc::SIGINT, libc::SIGTERM, libc::SIGHUP];
        static ACTIVE: AtomicUsize = AtomicUsize::new(0);
        static CAUGHT: std::sync::atomic::AtomicI32 = std::sync::atomic::AtomicI32::new(0);
        static INSTALLED: std::sync::Once = std::sync::Once::new();
        static PENDING: AtomicBool = AtomicBool::new(false);

        extern "C" fn on_signal(sig: libc::c_int) {
            if ACTIVE.load(Ordering::SeqCst) == 0 {
                // SAFETY: signal and raise are async-signal-safe.
                unsafe {
                    libc::signal(sig, libc::SIG_DFL);
                    libc::raise(sig);
                }
                return;
            }
            CAUGHT.store(sig, Ordering::SeqCst);
            PENDING.store(true, Ordering::SeqCst);
        }

        /// An external program starts running.
        pub fn enter() {
            INSTALLED.call_once(|| {
                for sig in SIGNALS {
                    // SAFETY: installs a handler that only touches atomics
                    // and async-signal-safe calls.
                    unsafe {
                        let old = libc::signal(sig, on_signal as *const () as libc::sighandler_t);
                        // A signal the process ignores (nohup) stays ignored.
                        if old == libc::SIG_IGN {
                            libc::signal(sig, libc::SIG_IGN);
                        }
                    }
                }
            });
            ACTIVE.fetch_add(1, Ordering::SeqCst);
        }

        /// Whether a signal came while a program ran.
        pub fn pending() -> bool {
            PENDING.load(Ordering::SeqCst)
        }

        /// An external program has ended and been cleaned up: when a
        /// signal came meanwhile and no other program runs, it now takes
        /// its default action.
        pub fn leave() {
            if ACTIVE.fetch_sub(1, Ordering::SeqCst) == 1 && PENDING.load(Ordering::SeqCst) {
                let sig = CAUGHT.load(Ordering::SeqCst);
                // SAFETY: plain system calls with a signal number.
                unsafe {
                    libc::signal(sig, libc::SIG_DFL);
                    libc::raise(sig);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn words(s: &str) -> Vec<String> {
        s.split_whitespace().map(String::from).collect()
    }

    #[test]
    fn the_key_options_go_right_after_the_program_name() {
        assert_eq!(
            command_line(&words("prog -e commfile.e density.spec"), 4321),
            words("prog -k 4321 -ext 4321.0 -e commfile.e density.spec")
        );
        assert_eq!(
            command_line(&words("/opt/bin/prog"), 5),
            words("/opt/bin/prog -k 5 -ext 5.0")
        );
        assert_eq!(to_field_name(77), ".to_field77.0");
        assert_eq!(from_field_name(77), ".from_field77.0");
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn a_semaphore_set_has_a_key_of_its_own_and_goes_with_its_value() {
        let live = || -> Vec<i32> {
            let t = std::fs::read_to_string("/proc/sysvipc/sem").unwrap();
            t.lines()
                .skip(1)
                .filter_map(|l| l.split_whitespace().next()?.parse().ok())
                .collect()
        };
        let folder = std::env::temp_dir();
        let (a, b) = (
            linux::SemSet::create(&folder).unwrap(),
            linux::SemSet::create(&folder).unwrap(),
        );
        let (ka, kb) = (a.key(), b.key());
        assert_ne!(ka, kb);
        for k in [ka, kb] {
            // Positive, and never lpfg's getpid()*4.
            assert!(k > 0 && k % 4 != 0, "{k}");
            assert!(live().contains(&k));
        }
        drop(a);
        drop(b);
        assert!(!live().contains(&ka) && !live().contains(&kb));
    }

    #[test]
    fn a_program_with_a_slash_is_found_in_the_model_folder() {
        let folder = Path::new("/models/plant");
        assert_eq!(program_path("honda81", folder), Path::new("honda81"));
        assert_eq!(
            program_path("./field", folder),
            Path::new("/models/plant/field")
        );
        assert_eq!(
            program_path("bin/field", folder),
            Path::new("/models/plant/bin/field")
        );
        assert_eq!(program_path("/usr/bin/f", folder), Path::new("/usr/bin/f"));
        let rel = program_path("bin/field", Path::new("plant"));
        assert!(rel.is_absolute() && rel.ends_with("plant/bin/field"));
    }
}
