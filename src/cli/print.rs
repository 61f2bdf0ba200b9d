//! Printing: the progress bar, what a program printed, warnings, and
//! standard output (a closed pipe is no error).

use subgram::{Error, Progress};

/// Runs `f` with a progress bar on standard error (see [`progress_to`]).
pub(super) fn with_progress<T>(f: impl FnOnce(&mut dyn FnMut(Progress)) -> T) -> T {
    let bar = std::cell::RefCell::new(None);
    let result = f(&mut |p: Progress| progress_to(&bar, p));
    if let Some(b) = bar.into_inner() {
        b.finish_and_clear();
    }
    result
}

/// How long a run goes on before its progress is shown: a quick run
/// prints nothing but its result.
const QUIET_FOR: std::time::Duration = std::time::Duration::from_secs(1);

/// Shows `p` on the progress bar in `bar`, made once the run has gone on
/// for [`QUIET_FOR`] since its first report: the step, and the word's
/// modules (curves) or the mesh's counts (surfaces, vv programs); for
/// `analyze`, the valences measured.
/// indicatif draws nothing when standard error is not a terminal.
pub(super) fn progress_to(bar: &std::cell::RefCell<Option<indicatif::ProgressBar>>, p: Progress) {
    static FIRST: std::sync::OnceLock<std::time::Instant> = std::sync::OnceLock::new();
    let first = *FIRST.get_or_init(std::time::Instant::now);
    let mut bar = bar.borrow_mut();
    if bar.is_none() && first.elapsed() < QUIET_FOR {
        return;
    }
    let b = bar.get_or_insert_with(|| {
        let b = indicatif::ProgressBar::new(p.steps as u64);
        let template = if p.valences {
            "{spinner} valence {pos}/{len} measured [{elapsed}]"
        } else {
            "{spinner} step {pos}/{len} {msg} [{elapsed}]"
        };
        b.set_style(
            indicatif::ProgressStyle::with_template(template)
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        b
    });
    b.set_position(p.step as u64);
    if p.valences {
        // The template says it all.
    } else if p.modules > 0 {
        b.set_message(format!("{} modules", p.modules));
    } else {
        b.set_message(format!(
            "{} vertices, {} edges, {} faces",
            p.vertices, p.edges, p.faces
        ));
    }
}

/// Writes what an L+C program printed (`printf`, `fprintf(stderr, …)`):
/// its standard output to ours (or to standard error with `to_stderr`),
/// its standard error to ours.
pub(super) fn print_program_output(
    output: &subgram::ProgramOutput,
    to_stderr: bool,
) -> Result<(), Error> {
    use std::io::Write;
    for (stream, text) in output.take_text() {
        let r = if stream == subgram::Stream::Stderr || to_stderr {
            let mut e = std::io::stderr().lock();
            e.write_all(text.as_bytes()).and_then(|_| e.flush())
        } else {
            let mut o = std::io::stdout().lock();
            o.write_all(text.as_bytes()).and_then(|_| o.flush())
        };
        match r {
            Ok(()) => {}
            Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => return Ok(()),
            Err(e) => {
                return Err(Error::Failed(format!(
                    "cannot write the program's output: {e}"
                )))
            }
        }
    }
    Ok(())
}

/// Writes a program's warnings to stderr, each followed by a blank line.
pub(super) fn print_warnings(warnings: &[String]) {
    for w in warnings {
        eprintln!("{w}\n");
    }
}

/// Standard output written straight to its file descriptor: the word
/// comes in chunks of 64 KiB, which `Stdout`'s line buffer would search
/// for line breaks (4% of writing a JSON word of 119 MB). Whatever went
/// through `Stdout` before (what the program printed) is flushed first.
pub(super) struct Unbuffered {
    #[cfg(unix)]
    file: Option<std::fs::File>,
    flushed: bool,
}

impl Unbuffered {
    pub(super) fn stdout() -> Unbuffered {
        #[cfg(unix)]
        let file = {
            use std::os::fd::AsFd;
            std::io::stdout()
                .as_fd()
                .try_clone_to_owned()
                .ok()
                .map(std::fs::File::from)
        };
        Unbuffered {
            #[cfg(unix)]
            file,
            flushed: false,
        }
    }
}

impl std::io::Write for Unbuffered {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        if !self.flushed {
            std::io::stdout().flush()?;
            self.flushed = true;
        }
        #[cfg(unix)]
        if let Some(f) = &mut self.file {
            return f.write(buf);
        }
        std::io::stdout().write(buf)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        std::io::stdout().flush()
    }
}

/// Writes a line to stdout; a closed pipe (`subgram derive f | head`) is not an error.
pub(super) fn print_out(text: &str) -> Result<(), Error> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    match writeln!(out, "{text}").and_then(|_| out.flush()) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        Err(e) => Err(Error::Failed(format!("cannot write the output: {e}"))),
    }
}
