//! Every class of mistake gets `file:line:col`, the line, a caret and a
//! message that says what was expected or what is wrong.
//!
//! The bad inputs are files, `tests/data/err/NAME.lsys`; the first line of
//! each says how to run it (`// run: subgram check` or `// run: subgram
//! derive [OPTIONS]`), and `NAME.expected` holds what the command line
//! prints on stderr for it, run from that folder. The exit code must be 1
//! (a problem with the input) and nothing may panic. See the folder's
//! README for where the expected texts come from.

use std::path::Path;
use std::process::Command;

use subgram::DeriveOptions;

use crate::golden::{self, Kind};
use crate::support::root;

/// Runs `tests/data/err/NAME.lsys` as its first line says; the stderr, or
/// why the run is wrong.
fn diagnostic(dir: &Path, name: &str) -> Result<Vec<u8>, String> {
    // Read as bytes: some bad inputs are not UTF-8.
    let text = std::fs::read(dir.join(name)).map_err(|e| format!("{name}: {e}"))?;
    let text = String::from_utf8_lossy(&text);
    let run = text
        .lines()
        .next()
        .and_then(|l| l.strip_prefix("// run: subgram "))
        .ok_or_else(|| format!("{name}: the first line must be `// run: subgram COMMAND ...`"))?;
    let mut args: Vec<&str> = run.split_whitespace().collect();
    args.push(name);
    let o = Command::new(env!("CARGO_BIN_EXE_subgram"))
        .current_dir(dir)
        .args(&args)
        .output()
        .map_err(|e| format!("the binary does not run: {e}"))?;
    let stderr = String::from_utf8_lossy(&o.stderr);
    if o.status.code() != Some(1) || stderr.contains("panicked") {
        return Err(format!(
            "{name}: `subgram {}` gave {}, expected exit code 1:\n{stderr}",
            args.join(" "),
            o.status
        ));
    }
    Ok(o.stderr)
}

#[test]
fn every_bad_input_gives_its_diagnostic() {
    let dir = root().join("tests/data/err");
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    names.sort();
    let mut failures = Vec::new();
    let mut cases = 0;
    for name in &names {
        if let Some(stem) = name.strip_suffix(".lsys") {
            cases += 1;
            let expected = format!("tests/data/err/{stem}.expected");
            match diagnostic(&dir, name) {
                Ok(got) => failures.extend(golden::compare(&expected, &got, Kind::Exact).err()),
                Err(e) => failures.push(e),
            }
        } else if let Some(stem) = name.strip_suffix(".expected") {
            if !names.contains(&format!("{stem}.lsys")) {
                failures.push(format!("{name}: no {stem}.lsys beside it"));
            }
        }
    }
    assert!(cases >= 29, "only {cases} bad inputs in {}", dir.display());
    golden::assert_all(failures);
}

/// The other side of `nesting-of-parentheses.lsys`: just below the limit,
/// checking and deriving work, on a test thread's ordinary stack. Each step
/// adds x 95 times: 1, 95, 95^2.
#[test]
fn nesting_just_below_the_limit_works() {
    let ok = format!(
        "module A(float);\nderivation length: 2;\nAxiom: A({}1{});\nA(x) -> A({})\n",
        "(".repeat(95),
        ")".repeat(95),
        vec!["x"; 95].join("+")
    );
    let l = subgram::load_str("ok.lsys", &ok, &[]).unwrap();
    let d = subgram::derive(&l.program, DeriveOptions::default()).unwrap();
    assert_eq!(
        subgram::output::word_text(&d.word, &l.program.alphabet, &l.program.structs),
        "A(9025)"
    );
}
