//! Atomic file writes, shared by every output (pictures, meshes, points).
//!
//! Inside a command's [`super::Run`], each write is staged: the
//! file is written whole beside its target, and the run puts every output
//! in place at its commit, all or none. Outside a run each call puts its
//! own files in place at once.

use std::io::Write;
use std::path::{Path, PathBuf};

/// Writes `bytes` to a temporary file next to `path` and returns its name;
/// on failure nothing is left behind.
fn write_temp(path: &Path, bytes: &[u8]) -> std::io::Result<PathBuf> {
    write_temp_with(path, |w| w.write_all(bytes))
}

/// Writes what `fill` writes to a temporary file next to `path` (through
/// a buffer) and returns its name; on failure nothing is left behind.
fn write_temp_with(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> std::io::Result<PathBuf> {
    // Unique within the process too (two threads may write one target),
    // and made new: a file or a link already under the name (another
    // user's, in a shared folder) is never followed nor truncated.
    static COUNT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let (tmp, created) = loop {
        let k = COUNT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let tmp = super::sibling(path, &format!("tmp-{k}"));
        match std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&tmp)
        {
            Ok(f) => break (tmp, f),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(e),
        }
    };
    let result = (|| {
        let file = Timed {
            file: created,
            deadline: crate::deadline::current(),
            writes: 0,
        };
        let mut f = std::io::BufWriter::with_capacity(1 << 16, file);
        fill(&mut f)?;
        f.into_inner().map_err(|e| e.into_error())?.file.sync_all()
    })();
    match result {
        Ok(()) => Ok(tmp),
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            Err(e)
        }
    }
}

/// A file being written that stops with the deadline's message once the
/// run's deadline passes (looked at every 16 writes of the buffer, a
/// megabyte), so that a large output ends the run at its limit too.
struct Timed {
    file: std::fs::File,
    deadline: Option<crate::Deadline>,
    writes: u32,
}

impl Write for Timed {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.writes = self.writes.wrapping_add(1);
        if self.writes.is_multiple_of(16) {
            if let Some(d) = self.deadline.filter(|d| d.passed()) {
                return Err(std::io::Error::new(
                    std::io::ErrorKind::TimedOut,
                    d.message(),
                ));
            }
        }
        self.file.write(buf)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.file.flush()
    }
}

/// Writes `bytes` to `path` through a temporary file in the same folder and
/// a rename, so that a failure never leaves a truncated file behind.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let tmp = write_temp(path, bytes)?;
    let Some(tmp) = super::stage(path, tmp) else {
        return Ok(());
    };
    let result = std::fs::rename(&tmp, path);
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// [`write_atomic`] for a file written piece by piece: `fill` writes it
/// (buffered) to the temporary file, so that a large file never has to be
/// held in memory whole.
pub fn write_atomic_with(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> std::io::Result<()> {
    let tmp = write_temp_with(path, fill)?;
    let Some(tmp) = super::stage(path, tmp) else {
        return Ok(());
    };
    let result = std::fs::rename(&tmp, path);
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// Writes several files, all or none: every file is written to its
/// temporary first, and only when all of them are written are they renamed
/// into place (see [`super::rename_all`]: a file that a rename
/// replaced is put back when a later one fails). Inside a run they are
/// staged for the run's commit. The paths must be distinct files. The
/// error names the file that failed.
pub fn write_all_atomic(files: &[(&Path, &[u8])]) -> Result<(), (PathBuf, std::io::Error)> {
    let mut temps: Vec<PathBuf> = Vec::with_capacity(files.len());
    let cleanup = |temps: &[PathBuf]| {
        for t in temps {
            let _ = std::fs::remove_file(t);
        }
    };
    for (path, bytes) in files {
        match write_temp(path, bytes) {
            Ok(t) => temps.push(t),
            Err(e) => {
                cleanup(&temps);
                return Err((path.to_path_buf(), e));
            }
        }
    }
    if super::in_run() {
        for ((path, _), tmp) in files.iter().zip(temps) {
            super::stage(path, tmp);
        }
        return Ok(());
    }
    let pairs: Vec<(&Path, &Path)> = files
        .iter()
        .zip(&temps)
        .map(|((p, _), t)| (*p, t.as_path()))
        .collect();
    let result = super::rename_all(&pairs);
    if result.is_err() {
        cleanup(&temps);
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn all_or_none() {
        let tmp = tempfile::Builder::new()
            .prefix("subgram-atomic-")
            .tempdir()
            .unwrap();
        let dir = tmp.path();
        std::fs::create_dir(dir.join("taken")).unwrap();
        let (a, b) = (dir.join("a.txt"), dir.join("b.txt"));
        // The second cannot be written (its folder is missing): neither is.
        let missing = dir.join("no/such/c.txt");
        let e = write_all_atomic(&[(&a, b"a"), (&missing, b"c")]).unwrap_err();
        assert_eq!(e.0, missing);
        // The second is renamed onto a folder and fails: the first goes.
        let e = write_all_atomic(&[(&a, b"a"), (&dir.join("taken"), b"t")]).unwrap_err();
        assert_eq!(e.0, dir.join("taken"));
        // A first file that existed is put back as it was.
        std::fs::write(&a, "old").unwrap();
        let e = write_all_atomic(&[(&a, b"new"), (&dir.join("taken"), b"t")]).unwrap_err();
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "old");
        std::fs::remove_file(&a).unwrap();
        assert_eq!(e.0, dir.join("taken"));
        let left: Vec<_> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(left, vec![std::ffi::OsString::from("taken")]);
        write_all_atomic(&[(&a, b"a"), (&b, b"b")]).unwrap();
        assert_eq!(std::fs::read(&b).unwrap(), b"b");
    }
}
