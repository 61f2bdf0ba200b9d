//! Progress reports (issue 40, item 8): a curve's derivation tells its
//! caller after every step where it stands, for the binary's progress bar.

use subgram::{DeriveOptions, FigureOptions, Progress};

use crate::support::load_text;

/// The word's length after each step, by rewriting the text of the
/// program's one production here (F -> F+F--F+F, every other symbol
/// kept): the expected counts do not come from the engine.
fn koch_lengths(steps: usize) -> Vec<usize> {
    let mut word = String::from("F");
    let mut out = Vec::new();
    for _ in 0..steps {
        word = word
            .chars()
            .map(|c| {
                if c == 'F' {
                    "F+F--F+F".to_string()
                } else {
                    c.to_string()
                }
            })
            .collect();
        out.push(word.len());
    }
    out
}

const KOCH: &str = "angle: 60;\nderivation length: 4;\nAxiom: F;\nF -> F+F--F+F\n";

#[test]
fn a_curve_run_reports_each_step_and_its_modules() {
    let c = load_text(KOCH);
    let mut seen: Vec<Progress> = Vec::new();
    let run = c
        .run_reporting(DeriveOptions::default(), |d| {
            seen.push(Progress::of_derivation(d))
        })
        .unwrap();
    let want = koch_lengths(4);
    assert_eq!(seen.len(), 4);
    for (k, p) in seen.iter().enumerate() {
        assert_eq!((p.step, p.steps), (k + 1, 4));
        assert_eq!(p.modules, want[k], "after step {}", k + 1);
        assert_eq!((p.vertices, p.edges, p.faces), (0, 0, 0));
    }
    assert_eq!(run.word().len(), want[3]);
}

/// The pictures' derivation reports the same steps, PNG and SVG alike.
#[test]
fn figures_report_each_step() {
    let c = load_text(KOCH);
    let want = koch_lengths(4);
    let opts = FigureOptions::default();
    for png in [false, true] {
        let mut seen = Vec::new();
        let mut on_step = |d: &subgram::Derivation| seen.push(Progress::of_derivation(d));
        if png {
            c.png_figures_reporting(&opts, &mut on_step).unwrap();
        } else {
            c.figures_reporting(&opts, &mut on_step).unwrap();
        }
        let modules: Vec<usize> = seen.iter().map(|p| p.modules).collect();
        assert_eq!(modules, want, "png: {png}");
    }
}

/// `analyze` tells how many valences of how many it has measured.
#[test]
fn analyze_reports_each_valence() {
    let args = subgram::command::AnalyzeArgs {
        file: crate::support::lsys("surfaces/loop.lsys")
            .to_string_lossy()
            .into_owned(),
        valences: Some(vec![3, 4]),
        ..Default::default()
    };
    let mut seen = Vec::new();
    subgram::command::analyze_reporting(&args, |p| seen.push(p)).unwrap();
    let steps: Vec<(bool, usize, usize)> =
        seen.iter().map(|p| (p.valences, p.step, p.steps)).collect();
    assert_eq!(steps, [(true, 1, 2), (true, 2, 2)]);
}
