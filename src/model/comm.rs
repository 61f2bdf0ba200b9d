//! The communication file (`.e`) of an open L-system: which environmental
//! program to start and what the turtle sends it (vlab's Environmental
//! Programs manual; read by lpfg as described in
//! `../shared/tools/lpfg/README.md`, "Open L-systems").
//!
//! ```text
//! executable: honda81 -e commfile.e density.spec
//! communication type: files
//! turtle position: P: %f %f %f
//! following module: off
//! ```
//!
//! lpfg's defaults: the position is sent as `%f %f %f`, the heading, left
//! and up vectors are not sent, no following module. When the
//! `executable:` line has no `-e FILE`, lpfg adds `-e` and the `.e` file's
//! name after the program's name; so does [`CommSpec::read`].

use std::path::{Path, PathBuf};

use super::error::ModelError;

/// What a `.e` file says.
#[derive(Clone, Debug, PartialEq)]
pub struct CommSpec {
    /// The `.e` file.
    pub path: PathBuf,
    /// The `executable:` line split at white space (as lpfg splits it
    /// before `execvp`): the program and its arguments, `-e FILE`
    /// included.
    pub command: Vec<String>,
    /// The line of the `.e` file that names the program (1-based) and its
    /// text, for messages about it.
    pub command_line: (usize, String),
    /// The `printf` formats of the turtle's position, heading, left and up
    /// vectors (three numbers each), or `None` where they are not sent.
    pub position: Option<String>,
    pub heading: Option<String>,
    pub left: Option<String>,
    pub up: Option<String>,
    /// `following module: on`: each query also carries the module after
    /// it.
    pub following: bool,
    /// `verbose: on`.
    pub verbose: bool,
    /// The `communication type:` line (1-based) and its value, where there
    /// is one.
    pub communication: Option<(usize, String)>,
}

impl CommSpec {
    /// What to say about the file's `communication type:` line: lpfg talks
    /// through files whatever it says, but vlab's programs read it too and
    /// talk through files only when it says `files` (they wait on their
    /// standard input otherwise, and lpfg's run hangs).
    pub fn communication_note(&self) -> Option<String> {
        match &self.communication {
            Some((_, v)) if v == "files" => None,
            Some((_, v)) => Some(format!(
                "`communication type: {v}`: lpfg talks to the program through files, and vlab's \
                 programs do the same only when this line says `files`"
            )),
            None => Some(
                "no `communication type: files` line: lpfg talks to the program through files, \
                 and vlab's programs do the same only when this file says so (subgram's built-in \
                 honda81 and shadowpyramid do not need it)"
                    .into(),
            ),
        }
    }

    /// The program's name as the `.e` file gives it (`honda81`).
    pub fn program(&self) -> &str {
        &self.command[0]
    }

    /// The arguments after `-e FILE` that name files (the program's
    /// specification files), in order: for `honda81 -e commfile.e
    /// density.spec`, `density.spec`.
    pub fn spec_files(&self) -> Vec<&str> {
        let mut out = Vec::new();
        let mut i = 1;
        while i < self.command.len() {
            let a = self.command[i].as_str();
            if matches!(a, "-e" | "-k" | "-ext" | "-h") {
                i += 2;
                continue;
            }
            out.push(a);
            i += 1;
        }
        out
    }

    /// Reads the `.e` file at `path` (whose text is `text`).
    pub fn read(path: &Path, text: &str) -> Result<CommSpec, ModelError> {
        let shown = path.display().to_string();
        let mut spec = CommSpec {
            path: path.to_path_buf(),
            command: Vec::new(),
            command_line: (0, String::new()),
            position: Some("%f %f %f".to_string()),
            heading: None,
            left: None,
            up: None,
            following: false,
            verbose: false,
            communication: None,
        };
        let at = |line: usize, text: &str, start: usize, end: usize, message: String| {
            ModelError::FileAt {
                path: shown.clone(),
                line,
                text: text.to_string(),
                start,
                end: end.max(start + 1).min(text.len().max(start + 1)),
                message,
            }
        };
        for (n, raw) in text.lines().enumerate() {
            let line = n + 1;
            let l = raw.trim_end_matches('\r');
            if l.trim().is_empty() {
                continue;
            }
            let Some(colon) = l.find(':') else {
                let s = l.len() - l.trim_start().len();
                return Err(at(
                    line,
                    l,
                    s,
                    l.len(),
                    "expected `label: value` (`executable:`, `turtle position:`, …)".into(),
                ));
            };
            let label = l[..colon].trim().to_ascii_lowercase();
            let value = &l[colon + 1..];
            let vstart = colon + 1 + (value.len() - value.trim_start().len());
            match label.as_str() {
                "executable" => {
                    let words: Vec<String> = value.split_whitespace().map(String::from).collect();
                    if words.is_empty() {
                        return Err(at(
                            line,
                            l,
                            colon,
                            colon + 1,
                            "expected the environmental program's command line after `executable:`"
                                .into(),
                        ));
                    }
                    spec.command = words;
                    spec.command_line = (line, l.to_string());
                }
                "communication type" => {
                    let v = value.trim();
                    if !matches!(v, "files" | "pipes" | "sockets" | "memory" | "") {
                        return Err(at(
                            line,
                            l,
                            vstart,
                            l.len(),
                            format!(
                                "unknown communication type `{v}`: expected `files` (lpfg talks \
                                 to every program through files, whatever this line says)"
                            ),
                        ));
                    }
                    spec.communication = Some((line, v.to_string()));
                }
                "turtle position" | "turtle heading" | "turtle left" | "turtle up" => {
                    let fmt = value.to_string();
                    if let Err((i, why)) = check_format(&fmt) {
                        let s = colon + 1 + i;
                        return Err(at(line, l, s, s + 1, why));
                    }
                    let slot = match label.as_str() {
                        "turtle position" => &mut spec.position,
                        "turtle heading" => &mut spec.heading,
                        "turtle left" => &mut spec.left,
                        _ => &mut spec.up,
                    };
                    *slot = Some(fmt);
                }
                "turtle line width" | "turtle scale factor" | "interpreted modules" => {
                    // lpfg reads these and sends nothing for them.
                }
                "verbose" | "following module" => {
                    let on = match value.trim() {
                        "on" => true,
                        "off" => false,
                        v => {
                            return Err(at(
                                line,
                                l,
                                vstart,
                                l.len(),
                                format!("expected `on` or `off`, found `{v}`"),
                            ))
                        }
                    };
                    if label == "verbose" {
                        spec.verbose = on;
                    } else {
                        spec.following = on;
                    }
                }
                // The environmental program's own settings may sit in the
                // same file (honda81's `radius:` in a one-file setup); the
                // program reads them, lpfg passes over them.
                _ => {}
            }
        }
        if spec.command.is_empty() {
            return Err(ModelError::File {
                path: shown,
                line: None,
                message: "no `executable:` line names the environmental program \
                          (`executable: honda81 -e commfile.e density.spec`)"
                    .into(),
            });
        }
        if !spec.command.iter().any(|w| w == "-e") {
            let name = path
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default();
            spec.command.insert(1, "-e".into());
            spec.command.insert(2, name);
        }
        Ok(spec)
    }
}

/// Checks a turtle format: text with exactly three conversions, each
/// `%f`, `%g` or `%e` (with flags, width, precision or `l`, as `printf`
/// takes them); `%%` is a percent sign. The error is the byte where it
/// goes wrong and why. The line is printed by `lang::cfmt::format`.
pub fn check_format(fmt: &str) -> Result<(), (usize, String)> {
    let b = fmt.as_bytes();
    let (mut n, mut i) = (0, 0);
    while i < b.len() {
        if b[i] != b'%' {
            i += 1;
            continue;
        }
        if b.get(i + 1) == Some(&b'%') {
            i += 2;
            continue;
        }
        let at = i;
        i += 1;
        while b.get(i).is_some_and(|c| b"-+ #0123456789.l".contains(c)) {
            i += 1;
        }
        match b.get(i) {
            Some(b'f' | b'F' | b'e' | b'E' | b'g' | b'G') => n += 1,
            Some(_) => {
                let c = fmt[i..].chars().next().unwrap_or('?');
                return Err((
                    at,
                    format!("`%{c}` cannot print a coordinate: expected `%f`, `%g` or `%e`"),
                ));
            }
            None => {
                return Err((
                    at,
                    "the format ends inside a conversion: expected `%f`".into(),
                ))
            }
        }
        i += 1;
    }
    if n != 3 {
        return Err((
            0,
            format!("expected three numbers in the format (`%f %f %f`), found {n}"),
        ));
    }
    Ok(())
}
