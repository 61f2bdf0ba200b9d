//! Atomic file writes, shared by every output (pictures, meshes, points).

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
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".into());
    let tmp = dir.join(format!(".{name}.tmp-{}", std::process::id()));
    let result = (|| {
        let mut f = std::io::BufWriter::with_capacity(1 << 16, std::fs::File::create(&tmp)?);
        fill(&mut f)?;
        f.into_inner().map_err(|e| e.into_error())?.sync_all()
    })();
    match result {
        Ok(()) => Ok(tmp),
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            Err(e)
        }
    }
}

/// Writes `bytes` to `path` through a temporary file in the same folder and
/// a rename, so that a failure never leaves a truncated file behind.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let tmp = write_temp(path, bytes)?;
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
    let result = std::fs::rename(&tmp, path);
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// Writes several files, all or none: every file is written to its
/// temporary first, and only when all of them are written are they renamed
/// into place. A failure removes the temporaries and the files this call
/// created; a file that existed before and was already replaced stays
/// replaced. The paths must be distinct files. The error names the file
/// that failed.
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
    let mut created: Vec<&Path> = Vec::new();
    for (k, ((path, _), tmp)) in files.iter().zip(&temps).enumerate() {
        let existed = std::fs::symlink_metadata(path).is_ok();
        if let Err(e) = std::fs::rename(tmp, path) {
            cleanup(&temps[k..]);
            for c in created {
                let _ = std::fs::remove_file(c);
            }
            return Err((path.to_path_buf(), e));
        }
        if !existed {
            created.push(path);
        }
    }
    Ok(())
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
        let left: Vec<_> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(left, vec![std::ffi::OsString::from("taken")]);
        write_all_atomic(&[(&a, b"a"), (&b, b"b")]).unwrap();
        assert_eq!(std::fs::read(&b).unwrap(), b"b");
    }
}
