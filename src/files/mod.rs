//! What a run reads and writes.
//!
//! **Reading.** [`open`] opens an input without ever blocking: a named pipe
//! with no writer, a terminal or another device opens at once, and is
//! then read under the run's deadline ([`crate::deadline::current`], or
//! [`DEFAULT_TIMEOUT`](crate::DEFAULT_TIMEOUT) from the first read where
//! the run set none), so that a pipe nobody writes to ends the run with a
//! message instead of holding it. A socket or a folder is refused.
//!
//! **Writing.** A command begins a [`Run`]; while it lives, every output
//! that [`crate::files::atomic`] writes on this thread is staged (written whole to
//! a temporary file beside its target) instead of put in place, and the
//! regular files this thread opens with [`open`] are noted as the run's
//! inputs. [`Run::commit`] then checks that the deadline has not passed
//! and that no output is one of the inputs, however spelled (the same
//! device and inode), unless the command was told `--force`; and puts
//! every output in place, all or none: a file that a rename replaced is
//! put back from a hard link kept beside it when a later rename fails, a
//! file the run created is removed, and so is a folder it made. A run
//! dropped without a commit leaves nothing behind; a process killed in the
//! middle (Ctrl-C) leaves its hidden temporaries (`.NAME.tmp-PID-K`) and
//! the folders it made, never a half-written output under its own name.
//!
//! **Layer.** It uses `deadline`; it is used by `command`, `error`, `export`,
//! `load`, `mesh`, `model`, `render`, `reverse`, `serve`, `syntax`. Nothing
//! here names a layer above (see ARCHITECTURE.md, "Layers").

use std::cell::RefCell;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::time::Duration;

use crate::deadline::{self, Deadline};

pub(crate) mod atomic;

/// Why [`Run::commit`] put nothing in place. The crate's `Error`
/// wraps it: `Late` and `Refused` as the run's failure and a usage error,
/// `Write` as a write error of the file named.
#[derive(Debug)]
pub enum CommitError {
    /// The run's deadline passed before its outputs were put in place.
    Late(String),
    /// The outputs cannot be put in place as named: one would replace an
    /// input, or two are one file.
    Refused(String),
    /// Putting `path` in place failed.
    Write {
        path: PathBuf,
        error: std::io::Error,
    },
}

impl std::fmt::Display for CommitError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            CommitError::Late(m) | CommitError::Refused(m) => f.write_str(m),
            CommitError::Write { path, error } => {
                write!(f, "cannot write `{}`: {error}", path.display())
            }
        }
    }
}

impl std::error::Error for CommitError {}

/// An input opened by [`open`]: a regular file, read as it is, or a stream
/// (a pipe, a device) read under the run's deadline.
pub(crate) struct Input {
    file: std::fs::File,
    /// The size of a regular file; `None` for a stream.
    size: Option<u64>,
    /// For a stream: when waiting for it ends, fixed at the first read.
    deadline: Option<Deadline>,
    what: &'static str,
    /// Whether a stream has given any byte yet.
    began: bool,
}

impl Input {
    /// The size of a regular file; `None` for a pipe or a device.
    pub(crate) fn size(&self) -> Option<u64> {
        self.size
    }
}

/// Opens `path` for reading without blocking: a named pipe without a
/// writer opens at once (and is read under the deadline), a folder or a
/// socket is refused with a message that says what it is.
pub(crate) fn open(path: &Path) -> std::io::Result<Input> {
    // A socket cannot be opened at all (ENXIO, "no such device"): say
    // what it is instead.
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if std::fs::metadata(path).is_ok_and(|m| m.file_type().is_socket()) {
            return Err(refused("it is a socket, not a file"));
        }
    }
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NONBLOCK);
    }
    let file = options.open(path)?;
    let meta = file.metadata()?;
    let kind = meta.file_type();
    if kind.is_dir() {
        return Err(refused("it is a folder, not a file"));
    }
    if meta.is_file() {
        #[cfg(unix)]
        {
            note_input(&meta);
            set_blocking(&file)?;
        }
        return Ok(Input {
            file,
            size: Some(meta.len()),
            deadline: None,
            began: false,
            what: "file",
        });
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if kind.is_socket() {
            return Err(refused("it is a socket, not a file"));
        }
        let what = if kind.is_fifo() {
            "pipe"
        } else if kind.is_char_device() {
            "device"
        } else {
            "block device"
        };
        Ok(Input {
            file,
            size: None,
            deadline: None,
            began: false,
            what,
        })
    }
    #[cfg(not(unix))]
    Ok(Input {
        file,
        size: None,
        deadline: None,
        began: false,
        what: "stream",
    })
}

fn refused(why: &str) -> std::io::Error {
    std::io::Error::new(std::io::ErrorKind::InvalidInput, why.to_string())
}

#[cfg(unix)]
fn set_blocking(file: &std::fs::File) -> std::io::Result<()> {
    use std::os::unix::io::AsRawFd;
    let fd = file.as_raw_fd();
    // SAFETY: fcntl on a descriptor this function's caller owns, with
    // flags it read from that same descriptor.
    let flags = unsafe { libc::fcntl(fd, libc::F_GETFL) };
    if flags < 0 {
        return Err(std::io::Error::last_os_error());
    }
    // SAFETY: as above.
    if unsafe { libc::fcntl(fd, libc::F_SETFL, flags & !libc::O_NONBLOCK) } < 0 {
        return Err(std::io::Error::last_os_error());
    }
    Ok(())
}

impl Read for Input {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        if self.size.is_some() || buf.is_empty() {
            return self.file.read(buf);
        }
        self.read_stream(buf)
    }
}

impl Input {
    /// Waits until the stream has bytes, or its writer has gone, or the
    /// deadline passes; then reads what is there.
    #[cfg(unix)]
    fn read_stream(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        use std::os::unix::io::AsRawFd;
        let deadline = *self.deadline.get_or_insert_with(|| {
            deadline::current().unwrap_or_else(|| Deadline::after(crate::DEFAULT_TIMEOUT))
        });
        loop {
            let Some(left) = deadline.left() else {
                return Err(std::io::Error::new(
                    std::io::ErrorKind::TimedOut,
                    format!(
                        "nothing {}came from this {} before the run's time limit of {} s; \
                         raise it with --timeout SECONDS (0 for no limit)",
                        if self.began { "more " } else { "" },
                        self.what,
                        deadline.limit().as_secs_f64()
                    ),
                ));
            };
            // Wake at least every quarter second to look at the clock.
            let wait = left.min(Duration::from_millis(250)).as_millis().max(1) as libc::c_int;
            let mut fds = libc::pollfd {
                fd: self.file.as_raw_fd(),
                events: libc::POLLIN,
                revents: 0,
            };
            // SAFETY: one valid pollfd, for a descriptor this value owns.
            let ready = unsafe { libc::poll(&mut fds, 1, wait) };
            if ready < 0 {
                let e = std::io::Error::last_os_error();
                if e.kind() == std::io::ErrorKind::Interrupted {
                    continue;
                }
                return Err(e);
            }
            if ready == 0 {
                continue;
            }
            match self.file.read(buf) {
                Ok(n) => {
                    self.began |= n > 0;
                    return Ok(n);
                }
                Err(e)
                    if matches!(
                        e.kind(),
                        std::io::ErrorKind::WouldBlock | std::io::ErrorKind::Interrupted
                    ) =>
                {
                    continue
                }
                Err(e) => return Err(e),
            }
        }
    }

    #[cfg(not(unix))]
    fn read_stream(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        self.file.read(buf)
    }
}

// ---------------------------------------------------------------------------
// A run's ledger

/// An output written whole to `temp`, waiting to be renamed to `target`.
struct Staged {
    target: PathBuf,
    temp: PathBuf,
}

#[derive(Default)]
struct Ledger {
    /// (device, inode) of every regular file the run opened.
    inputs: Vec<(u64, u64)>,
    staged: Vec<Staged>,
    /// Folders the run made for its outputs, in the order made.
    made: Vec<PathBuf>,
    /// `Some(true)`: `--force`, outputs may replace inputs; `None`: the
    /// command has no `--force`.
    force: Option<bool>,
}

thread_local! {
    static LEDGER: RefCell<Option<Ledger>> = const { RefCell::new(None) };
}

#[cfg(unix)]
fn note_input(meta: &std::fs::Metadata) {
    use std::os::unix::fs::MetadataExt;
    LEDGER.with(|l| {
        if let Some(l) = l.borrow_mut().as_mut() {
            let id = (meta.dev(), meta.ino());
            if !l.inputs.contains(&id) {
                l.inputs.push(id);
            }
        }
    });
}

/// Runs `work` on this thread (one without a run of its own, such as a
/// thread with a larger stack that a command's work moved to) and gives
/// back the (device, inode) of each regular file it opened, for the
/// command's run ([`note_inputs`]).
pub(crate) fn noting_inputs<T>(work: impl FnOnce() -> T) -> (T, Vec<(u64, u64)>) {
    let fresh = LEDGER.with(|l| {
        let mut l = l.borrow_mut();
        if l.is_some() {
            return false;
        }
        *l = Some(Ledger::default());
        true
    });
    let value = work();
    let inputs = if fresh {
        LEDGER
            .with(|l| l.borrow_mut().take())
            .map(|l| {
                // Nothing is written on such a thread; were anything
                // staged, it is not left behind.
                discard(&l);
                l.inputs
            })
            .unwrap_or_default()
    } else {
        Vec::new()
    };
    (value, inputs)
}

/// Adds `inputs` to the current run's, if one is active on this thread.
pub(crate) fn note_inputs(inputs: Vec<(u64, u64)>) {
    LEDGER.with(|l| {
        if let Some(l) = l.borrow_mut().as_mut() {
            for id in inputs {
                if !l.inputs.contains(&id) {
                    l.inputs.push(id);
                }
            }
        }
    });
}

/// Hands the temporary file `temp`, written whole, to the current run to
/// be renamed to `target` at its commit; gives it back when no run is
/// active on this thread.
pub(crate) fn stage(target: &Path, temp: PathBuf) -> Option<PathBuf> {
    LEDGER.with(|l| match l.borrow_mut().as_mut() {
        Some(l) => {
            // The same target staged twice is refused at the commit.
            l.staged.push(Staged {
                target: target.to_path_buf(),
                temp,
            });
            None
        }
        None => Some(temp),
    })
}

/// True while a run is active on this thread.
pub(crate) fn in_run() -> bool {
    LEDGER.with(|l| l.borrow().is_some())
}

/// Makes the folder `dir` and those above it that are missing; the run,
/// if one is active, removes them again unless it commits.
pub(crate) fn make_folders(dir: &Path) -> std::io::Result<()> {
    let mut missing = Vec::new();
    let mut d = Some(dir);
    while let Some(p) = d.filter(|p| !p.as_os_str().is_empty()) {
        if std::fs::symlink_metadata(p).is_ok() {
            break;
        }
        missing.push(p.to_path_buf());
        d = p.parent();
    }
    for p in missing.iter().rev() {
        std::fs::create_dir(p)?;
        LEDGER.with(|l| {
            if let Some(l) = l.borrow_mut().as_mut() {
                l.made.push(p.clone());
            }
        });
    }
    Ok(())
}

/// A command's run: its deadline and its ledger; see the module's text.
#[must_use = "a run that is not committed writes nothing"]
pub struct Run {
    /// False for a run begun inside another: the outer one commits.
    owner: bool,
    _deadline: Option<deadline::Scope>,
}

impl Run {
    /// Begins a run on this thread with `deadline` (none: no limit) and,
    /// with `force` `Some(true)`, outputs allowed over inputs (`None`: the
    /// command has no `--force`, and its messages do not offer it). Inside
    /// another run, the new one joins it: the outer run's commit puts the
    /// files in place.
    pub fn begin(deadline: Option<Deadline>, force: Option<bool>) -> Run {
        let owner = LEDGER.with(|l| {
            let mut l = l.borrow_mut();
            if l.is_some() {
                return false;
            }
            *l = Some(Ledger {
                force,
                ..Ledger::default()
            });
            true
        });
        Run {
            owner,
            // Without a limit of its own, the run keeps the thread's.
            _deadline: (owner && deadline.is_some()).then(|| deadline::scope(deadline)),
        }
    }

    /// Puts every staged output in place, or none; see the module's text.
    pub fn commit(self) -> Result<(), CommitError> {
        if !self.owner {
            return Ok(());
        }
        let Some(ledger) = LEDGER.with(|l| l.borrow_mut().take()) else {
            return Ok(());
        };
        let result = commit(&ledger);
        if result.is_err() {
            discard(&ledger);
        }
        result
    }
}

impl Drop for Run {
    fn drop(&mut self) {
        if self.owner {
            if let Some(ledger) = LEDGER.with(|l| l.borrow_mut().take()) {
                discard(&ledger);
            }
        }
    }
}

/// Removes the staged temporaries and the folders the run made.
fn discard(ledger: &Ledger) {
    for s in &ledger.staged {
        let _ = std::fs::remove_file(&s.temp);
    }
    for d in ledger.made.iter().rev() {
        // Only while empty: a folder that holds anything else stays.
        let _ = std::fs::remove_dir(d);
    }
}

fn commit(ledger: &Ledger) -> Result<(), CommitError> {
    if let Some(d) = deadline::current() {
        d.check().map_err(CommitError::Late)?;
    }
    if ledger.force != Some(true) {
        for s in &ledger.staged {
            if let Some(id) = file_id(&s.target) {
                if ledger.inputs.contains(&id) {
                    let force = if ledger.force.is_some() {
                        ", or add --force to replace it"
                    } else {
                        ""
                    };
                    return Err(CommitError::Refused(format!(
                        "the output `{}` is a file this run read: writing it would replace an input; \
                         name another output{force}",
                        s.target.display()
                    )));
                }
            }
        }
    }
    // Two outputs of one run that are one file under two names (a program
    // file of `--allow-writes` and `-o`): refused, not one lost.
    let mut seen: Vec<(PathBuf, &Path)> = Vec::new();
    for s in &ledger.staged {
        let key = resolved(&s.target);
        if let Some((_, first)) = seen.iter().find(|(k, _)| *k == key) {
            return Err(CommitError::Refused(format!(
                "`{}` and `{}` are the same output file; name two different files",
                first.display(),
                s.target.display()
            )));
        }
        seen.push((key, &s.target));
    }
    let targets: Vec<(&Path, &Path)> = ledger
        .staged
        .iter()
        .map(|s| (s.target.as_path(), s.temp.as_path()))
        .collect();
    rename_all(&targets).map_err(|(path, error)| CommitError::Write { path, error })
}

/// `path` with its folder's links resolved (the folder exists: a staged
/// temporary lies in it).
fn resolved(path: &Path) -> PathBuf {
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    match (dir.canonicalize(), path.file_name()) {
        (Ok(d), Some(n)) => d.join(n),
        _ => path.to_path_buf(),
    }
}

/// The (device, inode) of the file `path` leads to, if it exists.
fn file_id(path: &Path) -> Option<(u64, u64)> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        std::fs::metadata(path).ok().map(|m| (m.dev(), m.ino()))
    }
    #[cfg(not(unix))]
    {
        let _ = path;
        None
    }
}

/// Renames each temporary onto its target, all or none: a target that
/// existed is first hard-linked (or, where the file system cannot, moved)
/// to a backup beside it, so that a failed later rename can put it back;
/// a target that did not exist is removed again. The temporaries of the
/// renames not made are left to the caller. The error names the target
/// that failed.
pub(crate) fn rename_all(files: &[(&Path, &Path)]) -> Result<(), (PathBuf, std::io::Error)> {
    // (target, its backup) for each rename made.
    let mut done: Vec<(&Path, Option<PathBuf>)> = Vec::with_capacity(files.len());
    let undo = |done: &[(&Path, Option<PathBuf>)]| {
        for (target, backup) in done.iter().rev() {
            match backup {
                Some(b) => {
                    let _ = std::fs::rename(b, target);
                }
                None => {
                    let _ = std::fs::remove_file(target);
                }
            }
        }
    };
    for (target, temp) in files {
        let backup = match std::fs::symlink_metadata(target) {
            Ok(m) if !m.is_dir() => match keep_aside(target) {
                Ok(b) => Some(b),
                Err(e) => {
                    undo(&done);
                    return Err((target.to_path_buf(), e));
                }
            },
            _ => None,
        };
        if let Err(e) = std::fs::rename(temp, target) {
            if let Some(b) = &backup {
                // A moved (not linked) target goes back; a link is dropped.
                if std::fs::symlink_metadata(target).is_err() {
                    let _ = std::fs::rename(b, target);
                } else {
                    let _ = std::fs::remove_file(b);
                }
            }
            undo(&done);
            return Err((target.to_path_buf(), e));
        }
        done.push((target, backup));
    }
    for (_, backup) in done {
        if let Some(b) = backup {
            let _ = std::fs::remove_file(b);
        }
    }
    Ok(())
}

/// Keeps the file `target` under a fresh hidden name beside it: a hard
/// link where the file system makes one, else the file moved there. No
/// existing file is removed or replaced to make room.
fn keep_aside(target: &Path) -> std::io::Result<PathBuf> {
    static COUNT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    loop {
        let k = COUNT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let b = sibling(target, &format!("bak-{k}"));
        if std::fs::symlink_metadata(&b).is_ok() {
            continue;
        }
        match std::fs::hard_link(target, &b) {
            Ok(()) => return Ok(b),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            Err(_) => {
                // No hard links here: moved (the name was free a moment
                // ago; rename would replace a file made since).
                if std::fs::symlink_metadata(&b).is_ok() {
                    continue;
                }
                std::fs::rename(target, &b)?;
                return Ok(b);
            }
        }
    }
}

/// A hidden name beside `path`: `.NAME.WHAT-PID`.
pub(crate) fn sibling(path: &Path, what: &str) -> PathBuf {
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".into());
    dir.join(format!(".{name}.{what}-{}", std::process::id()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch() -> tempfile::TempDir {
        tempfile::Builder::new()
            .prefix("subgram-files-")
            .tempdir()
            .unwrap()
    }

    fn names(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn a_later_failure_puts_replaced_files_back() {
        let tmp = scratch();
        let dir = tmp.path();
        let (a, b) = (dir.join("a.txt"), dir.join("b.txt"));
        std::fs::write(&a, "old a").unwrap();
        std::fs::create_dir(dir.join("taken")).unwrap();
        std::fs::write(dir.join("taken/x"), "x").unwrap();
        let run = Run::begin(None, Some(false));
        crate::files::atomic::write_atomic(&a, b"new a").unwrap();
        crate::files::atomic::write_atomic(&b, b"new b").unwrap();
        crate::files::atomic::write_atomic(&dir.join("taken"), b"t").unwrap();
        // Staged: nothing is in place yet.
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "old a");
        assert!(!b.exists());
        let e = run.commit().unwrap_err().to_string();
        assert!(e.contains("taken"), "{e}");
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "old a");
        assert_eq!(names(dir), ["a.txt", "taken"]);
    }

    #[test]
    fn an_input_is_never_an_output() {
        let tmp = scratch();
        let dir = tmp.path();
        let input = dir.join("in.txt");
        std::fs::write(&input, "keep").unwrap();
        std::os::unix::fs::symlink(&input, dir.join("link.txt")).unwrap();
        let run = Run::begin(None, Some(false));
        let mut text = String::new();
        open(&input).unwrap().read_to_string(&mut text).unwrap();
        crate::files::atomic::write_atomic(&dir.join("other.txt"), b"o").unwrap();
        crate::files::atomic::write_atomic(&dir.join("link.txt"), b"gone").unwrap();
        let e = run.commit().unwrap_err().to_string();
        assert!(e.contains("link.txt") && e.contains("--force"), "{e}");
        assert_eq!(std::fs::read_to_string(&input).unwrap(), "keep");
        assert_eq!(names(dir), ["in.txt", "link.txt"]);
        // With --force it is written.
        let run = Run::begin(None, Some(true));
        open(&input).unwrap();
        crate::files::atomic::write_atomic(&input, b"new").unwrap();
        run.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&input).unwrap(), "new");
    }

    #[test]
    fn a_passed_deadline_writes_nothing_and_a_dropped_run_leaves_nothing() {
        let tmp = scratch();
        let dir = tmp.path();
        let run = Run::begin(Some(Deadline::after(Duration::from_millis(1))), Some(false));
        make_folders(&dir.join("new/deeper")).unwrap();
        crate::files::atomic::write_atomic(&dir.join("new/deeper/x"), b"x").unwrap();
        std::thread::sleep(Duration::from_millis(5));
        let e = run.commit().unwrap_err().to_string();
        assert!(e.contains("time limit"), "{e}");
        assert!(names(dir).is_empty(), "{:?}", names(dir));
        let run = Run::begin(None, Some(false));
        crate::files::atomic::write_atomic(&dir.join("y"), b"y").unwrap();
        drop(run);
        assert!(names(dir).is_empty(), "{:?}", names(dir));
    }

    #[test]
    fn a_pipe_without_a_writer_waits_only_until_the_deadline() {
        let tmp = scratch();
        let fifo = tmp.path().join("p");
        let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
        // SAFETY: a valid NUL-terminated path.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        let _d = deadline::scope(Some(Deadline::after(Duration::from_millis(300))));
        let t = std::time::Instant::now();
        let mut f = open(&fifo).unwrap();
        assert_eq!(f.size(), None);
        let mut bytes = Vec::new();
        let e = f.read_to_end(&mut bytes).unwrap_err();
        assert_eq!(e.kind(), std::io::ErrorKind::TimedOut);
        assert!(e.to_string().contains("pipe"), "{e}");
        assert!(t.elapsed() < Duration::from_secs(2), "{:?}", t.elapsed());
        // A folder and a socket are refused.
        let e = open(tmp.path()).err().unwrap();
        assert!(e.to_string().contains("folder"), "{e}");
        let socket = tmp.path().join("s");
        let _listener = std::os::unix::net::UnixListener::bind(&socket).unwrap();
        let e = open(&socket).err().unwrap();
        assert!(e.to_string().contains("socket"), "{e}");
    }
}
