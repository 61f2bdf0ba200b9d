//! The `subgram` binary: output formats, exit codes, and no panics.

use std::process::{Command, Output};

use crate::support::*;

fn subgram(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_subgram"))
        .args(args)
        .output()
        .expect("the binary runs")
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn derive_prints_the_final_word() {
    let f = lsys("curves/reverse-chaikin-38.lsys");
    let o = subgram(&["derive", f.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(stdout(&o).trim(), "P([0, 0]) P([0, 1]) P([1, 1]) P([1, 0])");
}

#[test]
fn derive_json_has_the_documented_shape() {
    let f = lsys("curves/reverse-chaikin-38.lsys");
    let o = subgram(&["derive", f.to_str().unwrap(), "--format", "json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(v["ring"], true);
    assert_eq!(v["step"], 1);
    assert_eq!(v["modules"].as_array().unwrap().len(), 4);
    assert_eq!(v["modules"][1]["symbol"], "P");
    assert_eq!(v["modules"][1]["params"], serde_json::json!([[0.0, 1.0]]));
}

#[test]
fn steps_and_defines_override_the_file() {
    let f = lsys("curves/chaikin-13.lsys");
    let o = subgram(&["derive", f.to_str().unwrap(), "-n", "2", "--format", "json"]);
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(v["modules"].as_array().unwrap().len(), 6 * 4);
    let o = subgram(&[
        "derive",
        f.to_str().unwrap(),
        "-D",
        "STEPS=1",
        "--format",
        "json",
    ]);
    let v: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(v["modules"].as_array().unwrap().len(), 6 * 2);
}

#[test]
fn check_reports_diagnostics_with_exit_code_1() {
    let dir = std::env::temp_dir().join(format!("subgram-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("bad.lsys");
    std::fs::write(
        &bad,
        "module P(V2f);\nAxiom: P(V2f(0,0)) Q;\nP(v) : { produce P(v + 1); }\n",
    )
    .unwrap();
    let o = subgram(&["check", bad.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1));
    let err = stderr(&o);
    assert!(
        err.contains("bad.lsys:2:20: error: undeclared module `Q`"),
        "{err}"
    );
    assert!(
        err.contains("bad.lsys:3:20: error: type error: cannot apply `+` to V2f and int"),
        "{err}"
    );
    assert!(!err.contains("panicked"));
    let good = lsys("curves/chaikin-13.lsys");
    let o = subgram(&["check", good.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

#[test]
fn usage_errors_exit_with_2() {
    assert_eq!(subgram(&["derive"]).status.code(), Some(2));
    assert_eq!(subgram(&["frobnicate"]).status.code(), Some(2));
    let f = lsys("curves/chaikin-13.lsys");
    let o = subgram(&["derive", f.to_str().unwrap(), "-D", "NOEQUALS"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("must have the form NAME=VALUE"));
    let o = subgram(&["derive", f.to_str().unwrap(), "-n", "many"]);
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn a_missing_file_is_an_input_error() {
    let o = subgram(&["derive", "no/such/file.lsys"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("cannot read `no/such/file.lsys`"));
}

#[test]
fn runaway_derivation_stops_with_a_message() {
    let dir = std::env::temp_dir().join(format!("subgram-cli-grow-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let f = dir.join("grow.lsys");
    std::fs::write(
        &f,
        "module A;\nderivation length: 100;\nAxiom: A;\nA() -> A A\n",
    )
    .unwrap();
    let o = subgram(&["derive", f.to_str().unwrap(), "--max-modules", "5000"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("the word grew past 5000 modules"),
        "{}",
        stderr(&o)
    );
}
