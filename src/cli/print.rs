//! Printing: the progress bar, what a program printed, warnings, and
//! standard output (a closed pipe is no error).

use subgram::{Error, Progress};

/// Runs `f` with a progress bar on standard error for surface grammars'
/// steps (shown only on a terminal).
pub(super) fn with_progress<T>(f: impl FnOnce(&mut dyn FnMut(Progress)) -> T) -> T {
    let bar = std::cell::RefCell::new(None);
    let result = f(&mut |p: Progress| progress_to(&bar, p));
    if let Some(b) = bar.into_inner() {
        b.finish_and_clear();
    }
    result
}

/// Shows `p` on the progress bar in `bar`, made on the first report.
pub(super) fn progress_to(bar: &std::cell::RefCell<Option<indicatif::ProgressBar>>, p: Progress) {
    let mut bar = bar.borrow_mut();
    let b = bar.get_or_insert_with(|| {
        let b = indicatif::ProgressBar::new(p.steps as u64);
        b.set_style(
            indicatif::ProgressStyle::with_template("{spinner} step {pos}/{len} {msg} [{elapsed}]")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        b
    });
    b.set_position(p.step as u64);
    b.set_message(format!(
        "{} vertices, {} edges, {} faces",
        p.vertices, p.edges, p.faces
    ));
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
