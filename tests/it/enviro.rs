//! Open L-systems (issue 36): the built-in environmental programs on
//! hand-made queries whose answers are worked out here, the exchange's
//! timing and rules in small models, the files that set it up and their
//! mistakes, and the open models of `lsystems/open/` against lpfg's own
//! words (made by lpfg 9bf820d with vlab's honda81 and shadowpyramid, see
//! `tests/data/open/README.md`).

use std::path::Path;

use subgram::enviro::{honda81, shadowpyramid};
use subgram::enviro::{Answer, EnvironmentStarter, Frame, Query};
use subgram::model::comm::CommSpec;
use subgram::{DeriveOptions, LoadOptions, System};

use crate::support::{root, scratch};

fn spec() -> CommSpec {
    CommSpec::read(Path::new("c.e"), "executable: prog -e c.e p.spec\n").unwrap()
}

fn query(id: u64, values: &[f64], at: [f64; 3]) -> Query {
    Query {
        id,
        values: values.to_vec(),
        following: None,
        frame: Frame {
            position: at,
            ..Frame::default()
        },
    }
}

fn answers(a: &[Answer]) -> Vec<(u64, Vec<f64>)> {
    a.iter().map(|a| (a.id, a.values.clone())).collect()
}

fn honda(radius: f32, three_d: bool, qs: &[Query]) -> Vec<(u64, Vec<f64>)> {
    answers(&honda81::answer(
        &honda81::Settings::new(radius, three_d),
        &spec(),
        qs,
    ))
}

#[test]
fn honda81_stops_a_query_near_another_of_equal_or_higher_vigour() {
    // Three queries in 3D, radius 1: 0 and 1 are 0.5 apart with equal
    // vigours (each stops the other), 2 is 5 away (free).
    let qs = [
        query(10, &[0.5], [0.0, 0.0, 0.0]),
        query(11, &[0.5], [0.0, 0.5, 0.0]),
        query(12, &[0.5], [5.0, 0.0, 0.0]),
    ];
    assert_eq!(
        honda(1.0, true, &qs),
        [(10, vec![0.0]), (11, vec![0.0]), (12, vec![1.0])]
    );
    // A higher vigour is not stopped by a lower one, but stops it.
    let qs = [
        query(1, &[0.9], [0.0, 0.0, 0.0]),
        query(2, &[0.5], [0.0, 0.5, 0.0]),
    ];
    assert_eq!(honda(1.0, true, &qs), [(1, vec![1.0]), (2, vec![0.0])]);
}

#[test]
fn honda81_in_2d_measures_in_x_and_z() {
    // 10 apart in y, 0.6 apart in z: a collision in the 2D case (y is not
    // looked at), none in 3D.
    let qs = [
        query(1, &[0.5], [0.0, 0.0, 0.0]),
        query(2, &[0.5], [0.0, 10.0, 0.6]),
    ];
    assert_eq!(honda(1.0, false, &qs), [(1, vec![0.0]), (2, vec![0.0])]);
    assert_eq!(honda(1.0, true, &qs), [(1, vec![1.0]), (2, vec![1.0])]);
}

#[test]
fn honda81_compares_only_queries_of_the_same_index() {
    // The second value is the index (cut to an integer): 1.7 and 1.2 are
    // both index 1; a query without one is index 0.
    let qs = [
        query(1, &[0.5], [0.0, 0.0, 0.0]),
        query(2, &[0.5, 1.7], [0.0, 0.1, 0.0]),
        query(3, &[0.5, 1.2], [0.1, 0.0, 0.0]),
    ];
    assert_eq!(
        honda(1.0, true, &qs),
        [(1, vec![1.0]), (2, vec![0.0]), (3, vec![0.0])]
    );
}

#[test]
fn honda81_counts_the_radius_itself_as_a_collision() {
    // Exactly 0.5 apart (the squared distance 0.25 equals the squared
    // radius): stopped, as `<=` in vlab's program.
    let qs = [
        query(1, &[0.5], [0.0, 0.0, 0.0]),
        query(2, &[0.5], [0.5, 0.0, 0.0]),
    ];
    assert_eq!(honda(0.5, true, &qs), [(1, vec![0.0]), (2, vec![0.0])]);
    assert_eq!(honda(0.49, true, &qs), [(1, vec![1.0]), (2, vec![1.0])]);
}

#[test]
fn honda81_answers_many_queries_as_the_double_loop_does() {
    // 3,000 queries (past the size where cells are used) on a lattice with
    // jitter, some vigours equal: every answer is the plain double loop's,
    // computed here in `float` as vlab's program does.
    let mut s = 12345u64;
    let mut next = || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((s >> 33) as f64) / (1u64 << 31) as f64
    };
    let qs: Vec<Query> = (0..3000)
        .map(|i| {
            let at = [next() * 30.0, next() * 30.0, next() * 30.0];
            let vigour = (next() * 4.0).floor() / 4.0;
            query(i, &[vigour, (i % 3) as f64], at)
        })
        .collect();
    let r = 1.3f32;
    let got = honda(r, true, &qs);
    // The positions as the program reads them: printed with `%f`, read
    // back as `float`s.
    let ps: Vec<[f32; 3]> = qs
        .iter()
        .map(|q| {
            q.frame
                .position
                .map(|x| format!("{:.6}", x as f32).parse::<f32>().unwrap())
        })
        .collect();
    let mut zeros = 0;
    for (i, a) in qs.iter().enumerate() {
        let blocked = qs.iter().enumerate().any(|(j, b)| {
            let (pa, pb) = (ps[i], ps[j]);
            let d2: f32 = (0..3).map(|k| (pa[k] - pb[k]) * (pa[k] - pb[k])).sum();
            i != j
                && (a.values[1] as i32) == (b.values[1] as i32)
                && a.values[0] as f32 <= b.values[0] as f32
                && d2 <= r * r
        });
        zeros += blocked as usize;
        assert_eq!(
            got[i],
            (i as u64, vec![if blocked { 0.0 } else { 1.0 }]),
            "{i}"
        );
    }
    // Both answers occur.
    assert!(zeros > 100 && zeros < 2900, "{zeros}");
}

fn pyramid(settings: &str, qs: &[Query]) -> Vec<(u64, Vec<f64>)> {
    let s = shadowpyramid::Settings::read(Path::new("light.spec"), settings).unwrap();
    let starter = shadowpyramid::Starter {
        settings: s,
        spec: spec(),
        file: "light.spec".into(),
    };
    let mut env = starter.start(None).unwrap();
    answers(&env.exchange(qs).unwrap())
}

#[test]
fn shadowpyramid_shades_the_tiers_below_a_leaf() {
    // 21 voxels a side over [-10, 10] × [0, 20] × [-10, 10]: one voxel a
    // unit, voxel x = floor(x + 10.5). A leaf at (0.5, 10.5, 0.5) sits in
    // voxel (11, 10, 11) and shades it by 1 − 0.5·2⁻⁰ = 0.5; tier 1 below,
    // voxel (11, 9, 11) at distance 1, by 1 − 0.5·2⁻¹ = 0.75; tier 2,
    // (11, 8, 11) at distance 2, by 0.875; (12, 9, 11) at distance √2.
    let spec = "grid size: 21\ngrid span: 10\nshadow spread: 1\nshadow depth: 3\n\
                shadow weight: 0.5\nshadow dissipation: 2\nsample radius: 1\n";
    let qs = [
        query(1, &[1.0], [0.5, 10.5, 0.5]),
        // A bud on the voxel corner (1, 9, 1): the light of voxel
        // (11, 9, 11) alone.
        query(2, &[0.0], [1.0, 9.0, 1.0]),
        // The same place asking for the gradient (EA20: 20 values): light
        // (12,9,11) − (10,9,11) = 0 across x and z, (11,10,11) − (11,8,11)
        // = 0.5 − 0.875 up.
        query(3, &[0.0; 20], [1.0, 9.0, 1.0]),
        // E2 gets the light and 0.
        query(4, &[0.0, 5.0], [1.0, 9.0, 1.0]),
    ];
    let got = pyramid(spec, &qs);
    // The leaf itself: the mean of the 8 voxels around it, one of them at
    // 0.5: (7 + 0.5) / 8.
    assert_eq!(got[0], (1, vec![0.9375]));
    assert_eq!(got[1], (2, vec![0.75]));
    let mut grad = vec![0.0; 20];
    grad[0] = 0.75;
    grad[2] = -0.375;
    assert_eq!(got[2], (3, grad));
    assert_eq!(got[3], (4, vec![0.75, 0.0]));
    // Without the leaf, full light everywhere.
    let got = pyramid(spec, &qs[1..2]);
    assert_eq!(got, [(2, vec![1.0])]);
}

#[test]
fn spec_files_with_mistakes_are_located() {
    let e = honda81::Settings::read(Path::new("density.spec"), "radius: 1\nradious: 2\n")
        .unwrap_err()
        .to_string();
    assert!(e.contains("density.spec:2:"), "{e}");
    assert!(e.contains("did you mean `radius:`?"), "{e}");
    let e = honda81::Settings::read(Path::new("density.spec"), "radius: wide\n")
        .unwrap_err()
        .to_string();
    assert!(e.contains("density.spec:1:9"), "{e}");
    assert!(e.contains("expected a number after `radius:`"), "{e}");
    let e = shadowpyramid::Settings::read(Path::new("light.spec"), "grid size: 2000\n")
        .unwrap_err()
        .to_string();
    assert!(e.contains("light.spec:1:12"), "{e}");
    assert!(e.contains("whole number from 2 to 750"), "{e}");
    let e = CommSpec::read(
        Path::new("c.e"),
        "executable: x\nturtle position: P: %f %d %f\n",
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("c.e:2:"), "{e}");
    assert!(e.contains("`%d` cannot print a coordinate"), "{e}");
    let e = CommSpec::read(Path::new("c.e"), "turtle position: %f %f %f\n")
        .unwrap_err()
        .to_string();
    assert!(e.contains("no `executable:` line"), "{e}");
    let e = CommSpec::read(Path::new("c.e"), "executable: x\nfollowing module: yes\n")
        .unwrap_err()
        .to_string();
    assert!(e.contains("c.e:2:19"), "{e}");
}

#[test]
fn the_e_file_gets_lpfgs_defaults() {
    let s = CommSpec::read(
        Path::new("dir/comm.e"),
        "executable: honda81 density.spec\n",
    )
    .unwrap();
    // lpfg adds `-e` and the file's name after the program.
    assert_eq!(s.command, ["honda81", "-e", "comm.e", "density.spec"]);
    assert_eq!(s.spec_files(), ["density.spec"]);
    assert_eq!(s.position.as_deref(), Some("%f %f %f"));
    assert_eq!(s.heading, None);
    assert!(!s.following);
}

/// A model folder with `lsystem.l` and honda81 set up (3D, `radius`).
fn open_model(name: &str, program: &str, radius: &str) -> tempfile::TempDir {
    let dir = scratch(name);
    std::fs::write(dir.path().join("lsystem.l"), program).unwrap();
    std::fs::write(
        dir.path().join("commfile.e"),
        "executable: honda81 -e commfile.e density.spec\nturtle position: P: %f %f %f\n",
    )
    .unwrap();
    std::fs::write(
        dir.path().join("density.spec"),
        format!("radius: {radius}\n3d case: on\n"),
    )
    .unwrap();
    dir
}

fn derive_folder(dir: &Path, opts: DeriveOptions) -> String {
    let System::Curve(c) = subgram::load(dir, &LoadOptions::default()).unwrap() else {
        panic!("a curve")
    };
    let d = c.derive(opts).unwrap_or_else(|e| panic!("{e}"));
    c.word_text(&d.word)
}

#[test]
fn sensors_in_branches_are_answered_before_each_step() {
    // Two sensors at (0, 1, 0), one in each branch (equal vigours: both
    // stopped), one at (0, 3, 0) (free). One step: the answers are written
    // before it, and no rule rewrites E1.
    let dir = open_model(
        "branches",
        "#include <lpfgall.h>\nderivation length: 1;\n\
         Axiom: SB() F(1) E1(0.5) EB() SB() F(1) E1(0.5) EB() F(3) E1(0.5);\n",
        "0.5",
    );
    assert_eq!(
        derive_folder(dir.path(), DeriveOptions::default()),
        "SB F(1) E1(0) EB SB F(1) E1(0) EB F(3) E1(1)"
    );
    // With no steps, no exchange.
    assert_eq!(
        derive_folder(dir.path(), DeriveOptions::default().with_steps(0)),
        "SB F(1) E1(0.5) EB SB F(1) E1(0.5) EB F(3) E1(0.5)"
    );
}

#[test]
fn no_environment_in_start_each_skips_the_next_exchange() {
    // E1(x) --> E1(x + 10), a lone sensor (honda81 answers 1). With an
    // exchange before every step: 1 + 10 after each, 11. StartEach of step 2
    // calls NoEnvironment(): lpfg's manual says the exchange after that
    // step (before step 3) is skipped, so step 3 adds 10 to 11: 21. The
    // count of exchanges the rules saw is kept in a global: a rule of step
    // k reads the value answered before it.
    let program = |skip: &str| {
        format!(
            "#include <lpfgall.h>\nderivation length: 3;\nint ones;\n\
             Start: {{ ones = 0; }}\nStartEach: {{ {skip} }}\n\
             Axiom: E1(0.5);\nE1(x) : {{ if (x == 1) ones = ones + 1; produce E1(x + 10); }}\n\
             End: {{ printf(\"%d\\n\", ones); }}\n"
        )
    };
    let dir = open_model("noenv", &program(""), "0.5");
    assert_eq!(
        derive_folder(dir.path(), DeriveOptions::default()),
        "E1(11)"
    );
    let dir = open_model(
        "noenv2",
        &program("if (StepNo() == 2) NoEnvironment();"),
        "0.5",
    );
    assert_eq!(
        derive_folder(dir.path(), DeriveOptions::default()),
        "E1(21)"
    );
}

#[test]
fn ea20_keeps_or_zeroes_what_the_answer_leaves() {
    // honda81 answers one value; an EA20 takes up to twenty: the first is
    // replaced, the rest kept (or zeroed with lpfg's -cleanEA20).
    let program = "#include <lpfgall.h>\nderivation length: 1;\nEA20Array a;\n\
                   Start: { a[0] = 0.5; a[2] = 7; }\nAxiom: EA20(a);\n";
    let dir = open_model("ea20", program, "0.5");
    let kept = derive_folder(dir.path(), DeriveOptions::default());
    assert!(kept.starts_with("EA20({1, 0, 7, 0"), "{kept}");
    let clean = derive_folder(
        dir.path(),
        DeriveOptions {
            clean_ea20: true,
            ..Default::default()
        },
    );
    assert!(clean.starts_with("EA20({1, 0, 0, 0"), "{clean}");
}

#[test]
fn e2_answered_with_one_value_keeps_its_values_and_says_so() {
    // honda81 answers every query with one value; lpfg passes over such an
    // answer to an E2 (which takes two), with a message, and so does
    // subgram.
    let dir = open_model(
        "e2",
        "#include <lpfgall.h>\nderivation length: 1;\nAxiom: F(1) E2(0.5, 3);\n",
        "0.5",
    );
    let out = subgram::ProgramOutput::new();
    let w = derive_folder(
        dir.path(),
        DeriveOptions::default().with_output(out.clone()),
    );
    assert_eq!(w, "F(1) E2(0.5, 3)");
    let said: String = out.take_text().into_iter().map(|(_, t)| t).collect();
    assert!(
        said.contains("answered module 1 (`E2`, which takes 2) with 1 value"),
        "{said}"
    );
}

#[test]
fn a_missing_parameter_file_is_named() {
    let dir = open_model("nospec", "#include <lpfgall.h>\nAxiom: E1(0);\n", "1");
    std::fs::remove_file(dir.path().join("density.spec")).unwrap();
    let e = subgram::load(dir.path(), &LoadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("density.spec"), "{e}");
}

/// A word as (name, parameters), parameters as numbers (structs' fields
/// in order).
fn modules(text: &str) -> Vec<(String, Vec<f64>)> {
    let text = text.replace(", ", ",");
    text.split_whitespace()
        .map(|t| {
            let (name, rest) = t.split_once('(').unwrap_or((t, ""));
            let nums = rest
                .trim_end_matches(')')
                .split([',', '{', '}'])
                .filter(|s| !s.is_empty())
                .map(|s| s.parse::<f64>().unwrap_or_else(|_| panic!("{t}")))
                .collect();
            (name.to_string(), nums)
        })
        .collect()
}

/// lpfg's word for `lsystems/open/NAME` (gzip).
fn lpfg_word(name: &str) -> String {
    use std::io::Read;
    let path = root().join(format!("tests/data/open/{name}.lpfg.txt.gz"));
    let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut s = String::new();
    flate2::read::GzDecoder::new(&bytes[..])
        .read_to_string(&mut s)
        .unwrap();
    s
}

fn same_as_lpfg(name: &str, defines: &[&str], tolerance: f64) {
    let opts = LoadOptions {
        defines: defines.iter().map(|d| d.to_string()).collect(),
        ..Default::default()
    };
    let System::Curve(c) = subgram::load(root().join("lsystems/open").join(name), &opts).unwrap()
    else {
        panic!("a curve")
    };
    let d = c.derive(DeriveOptions::default()).unwrap();
    let ours = modules(&c.word_text(&d.word));
    let theirs = modules(&lpfg_word(name));
    assert_eq!(ours.len(), theirs.len(), "{name}: module counts");
    for (i, (a, b)) in ours.iter().zip(&theirs).enumerate() {
        assert_eq!(a.0, b.0, "{name}: module {i}");
        assert_eq!(a.1.len(), b.1.len(), "{name}: module {i} ({})", a.0);
        for (x, y) in a.1.iter().zip(&b.1) {
            assert!(
                (x - y).abs() <= tolerance * x.abs().max(y.abs()).max(1.0),
                "{name}: module {i} ({}): {x} and lpfg's {y}",
                a.0
            );
        }
    }
}

#[test]
fn collide_3d_gives_lpfgs_word() {
    same_as_lpfg("collide-3d", &[], 1e-5);
}

#[test]
fn leaf_shedding_gives_lpfgs_word() {
    same_as_lpfg("leaf-shedding", &["STEPS=8"], 1e-5);
}

#[test]
fn shade_tree_gives_lpfgs_word() {
    // Light values agree within 2e-5: lpfg's turtle moves in `float`, and
    // a bud's place, a few millionths off, shifts its interpolation.
    same_as_lpfg("shade-tree", &["STEPS=8"], 2e-5);
}
