//! `subgram watch`: render, then render again when a file the program reads changes.

use std::path::{Path, PathBuf};
use std::time::Duration;

use super::common::load_options;
use super::render::{render, RenderArgs};
use crate::error::Error;
use crate::load::load;
use crate::mesh;

/// How `watch` watches.
#[derive(Clone, Debug)]
pub struct WatchOptions {
    /// How often the files are looked at.
    pub poll: Duration,
    /// Return after this many renders; `None`: until the process stops.
    pub max_renders: Option<usize>,
}

impl Default for WatchOptions {
    fn default() -> Self {
        WatchOptions {
            poll: Duration::from_millis(200),
            max_renders: None,
        }
    }
}

/// What `watch` reports as it goes.
#[derive(Debug)]
pub enum WatchEvent<'a> {
    /// The picture was written, with the program's warnings.
    Rendered {
        output: &'a str,
        seconds: f64,
        warnings: &'a [String],
    },
    /// The render failed; the last picture (if any) is left as it was.
    Failed { error: &'a Error },
    /// Waiting for one of these files to change.
    Watching { files: &'a [PathBuf] },
}

/// A file's identity and state as `watch` compares them: `None` when it
/// cannot be read (a change too: an editor replacing it, or deleting it).
type Stamp = Option<(std::time::SystemTime, u64, u64)>;

fn stamp(path: &Path) -> Stamp {
    let m = std::fs::metadata(path).ok()?;
    #[cfg(unix)]
    let inode = std::os::unix::fs::MetadataExt::ino(&m);
    #[cfg(not(unix))]
    let inode = 0;
    Some((m.modified().ok()?, m.len(), inode))
}

/// `subgram watch`: renders as `render` does, then again whenever the
/// file or one of the files it reads (`System::inputs`: a model's files, a
/// base mesh, included texts) changes. An error is reported and the last
/// picture kept: pictures are written atomically, so a failed render
/// leaves the last good one in place. A usage error (an unknown view, an
/// output format) ends the watch, as no edit of the files can mend it.
pub fn watch(
    a: &RenderArgs,
    w: &WatchOptions,
    mut report: impl FnMut(WatchEvent),
) -> Result<(), Error> {
    let file = PathBuf::from(&a.file);
    let mut files = vec![file.clone()];
    let mut renders = 0;
    loop {
        // What the program reads now; after an error that stops the
        // loading, the files of the last good load (and the file itself).
        if mesh::io::Format::from_path(&file).is_none() {
            // Under the render's time limit: a pipe among the files waits
            // no longer than the render would.
            let loaded = crate::deadline::within(a.timeout, || {
                load(&file, &load_options(&a.defines, a.double, &a.environment))
            });
            if let Ok(system) = loaded {
                files = system.inputs();
                if !files.contains(&file) {
                    files.insert(0, file.clone());
                }
            }
        }
        let before: Vec<Stamp> = files.iter().map(|f| stamp(f)).collect();
        let t = std::time::Instant::now();
        match render(a, |_| {}) {
            Ok(warnings) => report(WatchEvent::Rendered {
                output: &a.output,
                seconds: t.elapsed().as_secs_f64(),
                warnings: &warnings,
            }),
            Err(e @ Error::Usage(_)) => return Err(e),
            Err(error) => report(WatchEvent::Failed { error: &error }),
        }
        renders += 1;
        if w.max_renders.is_some_and(|m| renders >= m) {
            return Ok(());
        }
        report(WatchEvent::Watching { files: &files });
        // A change during the render counts: the stamps are from before it.
        loop {
            std::thread::sleep(w.poll);
            if files.iter().map(|f| stamp(f)).ne(before.iter().cloned()) {
                // Let an editor finish writing before the file is read.
                std::thread::sleep(w.poll.min(Duration::from_millis(50)));
                break;
            }
        }
    }
}
