//! Shape grammars (paper 003): splits, repeats and components against
//! sizes computed here, reproducible stochastic rules, paper 003's rule
//! notation, and `Subdivide`'s smoothing groups: protected walls left
//! exactly as they were, and slices handed back to their shapes by count.

use std::collections::{HashMap, HashSet};

use subgram::{LoadOptions, RunOptions, ShapeRun, Shapes, System};

use crate::support::scratch;

fn load(text: &str) -> Shapes {
    match subgram::load_text("t.lsys", text, &LoadOptions::default()) {
        Ok(System::Shapes(s)) => s,
        Ok(_) => panic!("not a shape grammar"),
        Err(e) => panic!("{e}"),
    }
}

fn file(name: &str) -> Shapes {
    let path = format!("{}/lsystems/shapes/{name}", env!("CARGO_MANIFEST_DIR"));
    match subgram::load(&path, &LoadOptions::default()) {
        Ok(System::Shapes(s)) => s,
        Ok(_) => panic!("not a shape grammar"),
        Err(e) => panic!("{e}"),
    }
}

fn derive(s: &Shapes, seed: Option<u32>) -> ShapeRun {
    let opts = RunOptions {
        seed,
        ..RunOptions::default()
    };
    s.derive(&opts).unwrap_or_else(|e| panic!("{e}"))
}

/// The children of the first root, as (symbol, origin, size).
fn children(s: &Shapes, run: &ShapeRun) -> Vec<(String, [f64; 3], [f64; 3])> {
    let tree: serde_json::Value = serde_json::from_str(&s.tree_json(run)).unwrap();
    let three = |v: &serde_json::Value| -> [f64; 3] {
        let a = v.as_array().unwrap();
        [
            a[0].as_f64().unwrap(),
            a[1].as_f64().unwrap(),
            a[2].as_f64().unwrap(),
        ]
    };
    tree[0]["children"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| {
            (
                c["symbol"].as_str().unwrap().to_string(),
                three(&c["scope"]["origin"]),
                three(&c["scope"]["size"]),
            )
        })
        .collect()
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * b.abs().max(1.0)
}

/// `(symbol, x origin, x size)` of every child along x.
fn along_x(s: &Shapes, run: &ShapeRun) -> Vec<(String, f64, f64)> {
    children(s, run)
        .into_iter()
        .map(|(n, o, z)| (n, o[0], z[0]))
        .collect()
}

fn assert_parts(got: &[(String, f64, f64)], want: &[(&str, f64, f64)]) {
    assert_eq!(got.len(), want.len(), "{got:?}");
    for (g, w) in got.iter().zip(want) {
        assert_eq!(g.0, w.0, "{got:?}");
        assert!(close(g.1, w.1) && close(g.2, w.2), "{g:?} should be {w:?}");
    }
}

#[test]
fn split_sizes_absolute_relative_and_floating() {
    // A scope of 10: B is 2, E is a tenth (1); the floating parts share the
    // 7 left in the ratio 1 : 3.
    let s = load(
        "axiom: s(10, 1, 1) i(\"box\") A\n\
         A --> split(x) { 2 : B | ~1 : C | ~3 : D | '0.1 : E }\n",
    );
    let run = derive(&s, None);
    let (c, d) = (7.0 * 1.0 / 4.0, 7.0 * 3.0 / 4.0);
    assert_parts(
        &along_x(&s, &run),
        &[
            ("B", 0.0, 2.0),
            ("C", 2.0, c),
            ("D", 2.0 + c, d),
            ("E", 2.0 + c + d, 1.0),
        ],
    );
    // Each part is a closed box of its size: volume from its faces.
    let vols = volumes(&s, &run);
    for (name, v) in [("B", 2.0), ("C", c), ("D", d), ("E", 1.0)] {
        assert!(close(vols[&format!("{name}_1")], v), "{name}: {vols:?}");
    }
}

#[test]
fn repeats_fit_their_pattern() {
    // round(7 / 2) = 4 tiles of about 2, stretched to 7/4 each.
    let s = load("axiom: s(7, 1, 1) i(\"box\") A\nA --> split(x) { ~2 : T }*\n");
    let run = derive(&s, None);
    let q = 7.0 / 4.0;
    assert_parts(
        &along_x(&s, &run),
        &[
            ("T", 0.0, q),
            ("T", q, q),
            ("T", 2.0 * q, q),
            ("T", 3.0 * q, q),
        ],
    );
    // Without a floating part: floor(7 / 2) = 3 tiles of 2, the last 1 cut off.
    let s = load("axiom: s(7, 1, 1) i(\"box\") A\nA --> split(x) { 2 : T }*\n");
    let run = derive(&s, None);
    assert_parts(
        &along_x(&s, &run),
        &[("T", 0.0, 2.0), ("T", 2.0, 2.0), ("T", 4.0, 2.0)],
    );
    // A pattern of a fixed 1 and a floating 2 in 10: round(10 / 3) = 3
    // repetitions; the floating parts share 10 - 3 = 7.
    let s = load("axiom: s(10, 1, 1) i(\"box\") A\nA --> split(x) { 1 : W | ~2 : G }*\n");
    let run = derive(&s, None);
    let g = 7.0 / 3.0;
    let mut want = Vec::new();
    for k in 0..3 {
        let at = k as f64 * (1.0 + g);
        want.push(("W", at, 1.0));
        want.push(("G", at + 1.0, g));
    }
    assert_parts(&along_x(&s, &run), &want);
    // Paper 003's Repeat(X, 2){B} is the first form.
    let s = load("axiom: s(7, 1, 1) i(\"box\") A\nA --> Repeat(X, 2) { T }\n");
    let run = derive(&s, None);
    assert_eq!(along_x(&s, &run).len(), 4);
}

#[test]
fn comp_selects_faces_by_direction() {
    let s = load(
        "axiom: s(2, 3, 4) i(\"box\") M\n\
         M --> comp(f) { top : T | bottom : B | side : S }\n",
    );
    let run = derive(&s, None);
    let mut count: HashMap<String, usize> = HashMap::new();
    for (n, _, size) in children(&s, &run) {
        *count.entry(n.clone()).or_default() += 1;
        // A face's scope is flat along its own z.
        assert_eq!(size[2], 0.0, "{n}");
    }
    assert_eq!(count["T"], 1);
    assert_eq!(count["B"], 1);
    assert_eq!(count["S"], 4);
    // A side face's y is up: its height is the box's 3.
    for (n, _, size) in children(&s, &run) {
        if n == "S" {
            assert!(close(size[1], 3.0), "{size:?}");
        }
    }
}

#[test]
fn extrude_makes_a_closed_mass() {
    let s = load("axiom: lot(4, 3) L\nL --> extrude(2) M\n");
    let run = derive(&s, None);
    let vols = volumes(&s, &run);
    assert!(close(vols["M_1"], 24.0), "{vols:?}");
}

#[test]
fn a_seed_makes_the_same_model() {
    let s = file("building.lsys");
    let a = s.obj(&derive(&s, Some(7)), "b.mtl");
    let b = s.obj(&derive(&s, Some(7)), "b.mtl");
    assert_eq!(a, b);
    // Another seed lights other windows.
    let c = s.obj(&derive(&s, Some(8)), "b.mtl");
    assert_ne!(a.0, c.0);
    // The 0.75 / 0.25 rules: of the windows of 20 seeds, a quarter are
    // lit, within 3 standard deviations of a binomial's share.
    let (mut lit, mut all) = (0, 0);
    for seed in 1..=20 {
        let (obj, _) = s.obj(&derive(&s, Some(seed)), "b.mtl");
        let l = obj.matches("g Lit_").count();
        lit += l;
        all += l + obj.matches("g Glass_").count();
    }
    let share = lit as f64 / all as f64;
    let sd = (0.25 * 0.75 / all as f64).sqrt();
    assert!((share - 0.25).abs() < 3.0 * sd, "{lit} lit of {all}");
}

#[test]
fn paper_notation_runs_as_printed() {
    let s = file("paper-notation.lsys");
    let mut seen = HashSet::new();
    for seed in 1..40 {
        let run = derive(&s, Some(seed));
        let kids: Vec<(String, Vec<f64>)> = {
            let tree: serde_json::Value = serde_json::from_str(&s.tree_json(&run)).unwrap();
            tree[0]["children"]
                .as_array()
                .unwrap()
                .iter()
                .map(|c| {
                    let p = c["params"].as_array().unwrap();
                    (
                        c["symbol"].as_str().unwrap().to_string(),
                        p.iter().map(|x| x.as_f64().unwrap()).collect(),
                    )
                })
                .collect()
        };
        // h = 9: wall(3) window(3) wall(3), or wall(9).
        let three = vec![
            ("wall".to_string(), vec![3.0]),
            ("window".to_string(), vec![3.0]),
            ("wall".to_string(), vec![3.0]),
        ];
        let one = vec![("wall".to_string(), vec![9.0])];
        assert!(kids == three || kids == one, "{kids:?}");
        seen.insert(kids.len());
    }
    // Both rules fire over 39 seeds (each has probability at least 0.2).
    assert_eq!(seen.len(), 2);
}

/// The enclosed volume of each terminal shape's faces (divergence
/// theorem over a fan of each polygon), by OBJ group name.
fn volumes(s: &Shapes, run: &ShapeRun) -> HashMap<String, f64> {
    let (obj, _) = s.obj(run, "t.mtl");
    let mut pos: Vec<[f64; 3]> = Vec::new();
    let mut vol: HashMap<String, f64> = HashMap::new();
    let mut group = String::new();
    for line in obj.lines() {
        let mut w = line.split_whitespace();
        match w.next() {
            Some("v") => {
                let v: Vec<f64> = w.map(|x| x.parse().unwrap()).collect();
                pos.push([v[0], v[1], v[2]]);
            }
            Some("g") => group = w.next().unwrap().to_string(),
            Some("f") => {
                let idx: Vec<usize> = w.map(|x| x.parse::<usize>().unwrap() - 1).collect();
                let p0 = pos[idx[0]];
                let mut v = 0.0;
                for k in 1..idx.len() - 1 {
                    let (a, b) = (pos[idx[k]], pos[idx[k + 1]]);
                    // p0 · (a × b) / 6
                    v += (p0[0] * (a[1] * b[2] - a[2] * b[1])
                        + p0[1] * (a[2] * b[0] - a[0] * b[2])
                        + p0[2] * (a[0] * b[1] - a[1] * b[0]))
                        / 6.0;
                }
                *vol.entry(group.clone()).or_default() += v;
            }
            _ => {}
        }
    }
    vol
}

/// The faces of each OBJ group, as lists of positions.
fn groups(s: &Shapes, run: &ShapeRun) -> Vec<(String, Vec<Vec<[f64; 3]>>)> {
    let (obj, _) = s.obj(run, "t.mtl");
    let mut pos: Vec<[f64; 3]> = Vec::new();
    let mut out: Vec<(String, Vec<Vec<[f64; 3]>>)> = Vec::new();
    for line in obj.lines() {
        let mut w = line.split_whitespace();
        match w.next() {
            Some("v") => {
                let v: Vec<f64> = w.map(|x| x.parse().unwrap()).collect();
                pos.push([v[0], v[1], v[2]]);
            }
            Some("g") => out.push((w.next().unwrap().to_string(), Vec::new())),
            Some("f") => {
                let f = w.map(|x| pos[x.parse::<usize>().unwrap() - 1]).collect();
                out.last_mut().unwrap().1.push(f);
            }
            _ => {}
        }
    }
    out
}

/// Paper 003, Fig. 10b and Algorithm 3: two parts of a split are smoothed,
/// the third is not. The wall between the group and the unsmoothed part is
/// protected: after subdivision the group still covers it with faces made
/// of the unsmoothed part's own corners, bit for bit, so the two stay
/// attached; the far end of the group was smoothed.
#[test]
fn the_wall_towards_an_unsmoothed_shape_is_protected() {
    let text = "axiom: s(6, 2, 2) i(\"box\") A\n\
         A --> split(x) { ~1 : P | ~1 : P | ~1 : Plain }\n\
         P --> Subdivide(STEPS) { Done }\n";
    for steps in 1..=3 {
        let s = load(&text.replace("STEPS", &steps.to_string()));
        let run = derive(&s, None);
        let g = groups(&s, &run);
        let plain = &g.iter().find(|(n, _)| n == "Plain_1").unwrap().1;
        // Plain's wall towards the group is its face at x = 4.
        let wall: Vec<[f64; 3]> = plain
            .iter()
            .find(|f| f.iter().all(|p| p[0] == 4.0))
            .expect("Plain has its wall at x = 4")
            .clone();
        let done: Vec<&Vec<[f64; 3]>> = g
            .iter()
            .filter(|(n, _)| n.starts_with("Done_"))
            .flat_map(|(_, f)| f)
            .collect();
        // The group still has the wall, as faces made of the wall's own
        // corners only (the quad may come back as its two triangles) that
        // cover its area, 2 x 2.
        let on_wall: Vec<&&Vec<[f64; 3]>> = done
            .iter()
            .filter(|f| f.iter().all(|p| wall.contains(p)))
            .collect();
        let area: f64 = on_wall
            .iter()
            .map(|f| {
                (1..f.len() - 1)
                    .map(|k| {
                        let (a, b, c) = (f[0], f[k], f[k + 1]);
                        let u = [b[1] - a[1], b[2] - a[2]];
                        let v = [c[1] - a[1], c[2] - a[2]];
                        (u[0] * v[1] - u[1] * v[0]).abs() / 2.0
                    })
                    .sum::<f64>()
            })
            .sum();
        assert_eq!(
            area, 4.0,
            "after {steps} steps the wall {wall:?} is not whole: {on_wall:?}"
        );
        // No vertex of the group lies inside the wall or moved off it.
        assert!(done
            .iter()
            .flat_map(|f| f.iter())
            .filter(|p| p[0] == 4.0)
            .all(|p| wall.contains(p)));
        // The rest of the group was smoothed: no other vertex of the group
        // is a corner of the original box at x = 0.
        let corners = done
            .iter()
            .flat_map(|f| f.iter())
            .filter(|p| p[0] == 0.0 && (p[1] == 0.0 || p[1] == 2.0))
            .count();
        assert_eq!(corners, 0, "the far end was not smoothed");
    }
}

/// Paper 003, Fig. 12: each shape gets exactly the faces that came from its
/// own. On a closed group with nothing protected, sqrt(3) turns every
/// triangle into 3 per step whose tag is the triangle's (a face split makes
/// 3 of the same tag, a flip keeps both slots' tags), so a shape's slice
/// after n steps has 3^n times the triangles it brought: its quads count 2.
#[test]
fn slices_go_back_to_their_shapes() {
    let before = file("fig12-slices.lsys");
    let text_before = std::fs::read_to_string(format!(
        "{}/lsystems/shapes/fig12-slices.lsys",
        env!("CARGO_MANIFEST_DIR")
    ))
    .unwrap();
    let unsmoothed = load(&text_before.replace("Subdivide(3)", "Subdivide(0)"));
    let run0 = derive(&unsmoothed, None);
    let run3 = derive(&before, None);
    // Each shape's triangles before: the faces of its part of the welded
    // group (after Subdivide(0), which welds and hands back).
    let tri = |faces: &Vec<Vec<[f64; 3]>>| faces.iter().map(|f| f.len() - 2).sum::<usize>();
    let g0 = groups(&unsmoothed, &run0);
    let g3 = groups(&before, &run3);
    assert_eq!(g0.len(), 4);
    assert_eq!(g3.len(), 4);
    let mut total = 0;
    for ((n0, f0), (n3, f3)) in g0.iter().zip(&g3) {
        assert_eq!(n0, n3);
        assert_eq!(f3.len(), tri(f0) * 27, "{n3}");
        total += f3.len();
    }
    // The union of the slices is the whole subdivided mesh.
    assert_eq!(total, run3.soup.faces.len());
    assert_eq!(run3.counts().faces, total);
}

/// `Subdivide` takes the project's Loop and Catmull-Clark grammars too: a
/// box of 6 quads is 12 triangles, which one Loop step makes 4 x 12 = 48;
/// one Catmull-Clark step makes 4 quads of each quad, 24.
#[test]
fn subdivide_with_loop_and_catmull_clark() {
    for (scheme, faces, sides) in [("loop", 48, 3), ("catmull-clark", 24, 4)] {
        let s = load(&format!(
            "axiom: s(2, 2, 2) i(\"box\") A\nA --> Subdivide(1, \"{scheme}\") {{ Done }}\n"
        ));
        let run = derive(&s, None);
        assert_eq!(run.soup.faces.len(), faces, "{scheme}");
        assert!(run.soup.faces.iter().all(|f| f.len() == sides), "{scheme}");
    }
}

/// Paper 003, section 4.3.1 and Algorithm 4: a group named by the
/// `smoothingGroup` attribute is subdivided once every member is waiting
/// or terminal, terminal members included. Here R never subdivides but is
/// in the group, so it is smoothed with L: both halves of the box come back
/// as 3 times the triangles they brought (one step of sqrt(3) on a closed
/// mesh), and there is one group.
#[test]
fn a_named_group_waits_for_its_members_and_takes_terminal_ones() {
    let s = load(
        "axiom: s(4, 2, 2) i(\"box\") A\n\
         A --> set(smoothingGroup, \"g\") split(x) { ~1 : L | ~1 : R }\n\
         L --> Subdivide(1) { Done }\n",
    );
    let run = derive(&s, None);
    assert_eq!(run.counts().smoothing_groups, 1);
    let g = groups(&s, &run);
    // Each half brings 5 quads (its wall towards the other is dropped):
    // 10 triangles, 30 after one step.
    for name in ["Done_1", "R_1"] {
        let faces = &g.iter().find(|(n, _)| n == name).unwrap().1;
        assert_eq!(faces.len(), 30, "{name}");
    }
    // Without the name, R is not waiting and not in a group: it keeps its
    // box faces and protects the wall it shares with L.
    let s = load(
        "axiom: s(4, 2, 2) i(\"box\") A\n\
         A --> split(x) { ~1 : L | ~1 : R }\n\
         L --> Subdivide(1) { Done }\n",
    );
    let run = derive(&s, None);
    let g = groups(&s, &run);
    assert_eq!(g.iter().find(|(n, _)| n == "R_1").unwrap().1.len(), 6);
}

/// A derivation that fails writes nothing: no OBJ, no MTL.
#[test]
fn a_failed_derivation_writes_no_file() {
    let tmp = scratch("shapes-nowrite");
    let dir = tmp.path();
    let grammar = dir.join("bad.lsys");
    std::fs::write(
        &grammar,
        "axiom: s(10, 1, 1) i(\"box\") A\nA --> split(x) { 6 : B | 6 : C }\n",
    )
    .unwrap();
    let out = dir.join("out.obj");
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_subgram"))
        .args(["subdivide", "--grammar"])
        .arg(&grammar)
        .arg("-o")
        .arg(&out)
        .stderr(std::process::Stdio::null())
        .status()
        .unwrap();
    assert_eq!(status.code(), Some(1));
    assert!(!out.exists() && !dir.join("out.mtl").exists());
}

/// CityEngine's relative coordinates in `s` and `t`: `'0.5` is half the
/// scope's size along that axis.
#[test]
fn relative_scale_and_translate() {
    let s = load(
        "axiom: s(4, 2, 6) i(\"box\") A\n\
         A --> s('0.5, '1, 2) t('0.5, 0, '0.25) B\n",
    );
    let run = derive(&s, None);
    let c = children(&s, &run);
    assert_eq!(c.len(), 1);
    // Size (2, 2, 2); moved by half the new x size (1) and a quarter of z (0.5).
    assert_eq!(c[0].2, [2.0, 2.0, 2.0]);
    assert_eq!(c[0].1, [1.0, 0.0, 0.5]);
    let vols = volumes(&s, &run);
    assert!(close(vols["B_1"], 8.0), "{vols:?}");
}

/// A selector whose faces an earlier part took selects nothing, silently;
/// only a selector the shape has no face for at all is an error.
#[test]
fn a_selector_after_all_takes_nothing() {
    let s = load(
        "axiom: s(1, 1, 1) i(\"box\") M\n\
         M --> comp(f) { all : F | top : T }\n",
    );
    let run = derive(&s, None);
    let names: Vec<String> = children(&s, &run).into_iter().map(|c| c.0).collect();
    assert_eq!(names, vec!["F"; 6]);
}

// Adversarial inputs (issue 14's adversarial pass): what once misread,
// panicked or ran without end.

/// C's `k-->0` is `k-- > 0`: inside a block it does not make an L+C
/// program a shape grammar, where a rule's arrow stands at the top level.
#[test]
fn cs_goes_to_operator_stays_lplusc() {
    let text = "derivation length: 2;\nmodule A(int);\nAxiom: A(3);\n\
                A(n) : { int k = n; while (k-->0) { } produce A(k) F(1); }\n";
    match subgram::load_text("t.lsys", text, &LoadOptions::default()) {
        Ok(System::Curve(_)) => {}
        Ok(_) => panic!("an L+C program read as another kind"),
        Err(e) => panic!("{e}"),
    }
    // A rule's arrow at the top level, after a parenthesised condition.
    load("axiom: s(1, 1, 1) i(\"box\") A(1)\nA(k) : (k > 0) --> B\n");
}

/// Probabilities that are expressions, or rules with conditions, are
/// checked when the rules apply, not summed at load: 0.25 * 2 + 0.5 is 1
/// (by hand), so both successors occur over a few seeds.
#[test]
fn computed_probabilities_are_checked_when_they_apply() {
    let s = load(
        "axiom: s(1, 1, 1) i(\"box\") A\n\
         1 : A ~> B : 0.25 * 2\n\
         2 : A ~> C : 0.5\n",
    );
    let mut seen = HashSet::new();
    for seed in 1..20 {
        let run = derive(&s, Some(seed));
        let tree: serde_json::Value = serde_json::from_str(&s.tree_json(&run)).unwrap();
        seen.insert(
            tree[0]["children"][0]["symbol"]
                .as_str()
                .unwrap()
                .to_string(),
        );
    }
    assert_eq!(seen, HashSet::from(["B".to_string(), "C".to_string()]));
    // A condition that always holds: 0.5 + 0.5 among the rules that apply.
    let s = load(
        "axiom: s(1, 1, 1) i(\"box\") A\n\
         1 : A : scope.sx > 0 ~> B : 0.5\n\
         2 : A ~> C : 0.5\n",
    );
    derive(&s, Some(1));
}

/// A chain of shapes 1,201 levels deep: the text tree indents at most 32
/// levels (the level is written in brackets beyond), so its lines stay
/// short; the JSON tree, one nested object per level, is refused with a
/// message past 256 levels, and written below that on a test thread's
/// small stack. (Indenting 2 × 40,000 columns panicked; a JSON tree of
/// 20,000 levels ran for minutes.)
#[test]
fn deep_trees_are_written_in_bounded_lines() {
    let s = load("axiom: s(1, 1, 1) i(\"box\") A(0)\nA(k) : k < 1200 --> A(k + 1)\n");
    let run = derive(&s, None);
    let text = s.tree_text(&run);
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 1201);
    assert!(lines.iter().all(|l| l.len() < 200), "a line is long");
    assert!(lines[1200].starts_with(&format!("{}[1200] A(1200)", " ".repeat(64))));
    assert!(lines[32].starts_with(&format!("{}A(32)", " ".repeat(64))));
    // The JSON is one shape per line at any depth, its closing brackets
    // broken into short lines, balanced: 1201 objects opened and closed.
    let json = s.tree_json(&run);
    assert!(json.lines().all(|l| l.len() < 400), "a line is long");
    assert_eq!(json.matches('{').count(), json.matches('}').count());
    assert_eq!(json.matches('[').count(), json.matches(']').count());
    assert_eq!(json.matches("\"children\": [").count(), 1201);
    // A shallower tree parses back (serde_json refuses nesting beyond 128).
    let s = load("axiom: s(1, 1, 1) i(\"box\") A(0)\nA(k) : k < 40 --> A(k + 1)\n");
    let run = derive(&s, None);
    let v: serde_json::Value = serde_json::from_str(&s.tree_json(&run)).unwrap();
    assert_eq!(v[0]["symbol"], "A");
}

/// Inserting what is not a regular file (a directory named like a mesh, a
/// named pipe, which would wait for a writer forever) is refused at the
/// string.
#[test]
fn inserting_a_non_file_is_refused() {
    let tmp = scratch("adv14");
    let dir = tmp.path();
    std::fs::create_dir_all(dir.join("folder.obj")).unwrap();
    let fifo = dir.join("pipe.obj");
    let made_fifo = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .is_ok_and(|s| s.success());
    let mut names = vec!["folder.obj"];
    if made_fifo {
        names.push("pipe.obj");
    }
    for name in names {
        let path = dir.join(name);
        let text = format!("axiom: s(1, 1, 1) i(\"{}\") A\nA --> B\n", path.display());
        let e = match subgram::load_text("t.lsys", &text, &LoadOptions::default()) {
            Err(e) => e.to_string(),
            Ok(_) => panic!("{name} was inserted"),
        };
        assert!(e.contains("is not a regular file"), "{e}");
        assert!(e.contains("t.lsys:1:21"), "{e}");
    }
}

/// `set` converts to the attribute's type as C's assignment does: 2.5 in
/// a truth value is true (1), 2.7 in an int is 2. (A truth value held
/// 2.5.)
#[test]
fn set_converts_to_the_attributes_type() {
    let s = load(
        "attr b = true;\nattr n = 1;\naxiom: s(1, 1, 1) i(\"box\") A\n\
         A --> set(b, 2.5) set(n, 2.7) B(b, n)\n",
    );
    let run = derive(&s, None);
    let tree: serde_json::Value = serde_json::from_str(&s.tree_json(&run)).unwrap();
    let p = &tree[0]["children"][0]["params"];
    assert_eq!(p, &serde_json::json!([1.0, 2.0]));
}

/// A mesh inserted by several operations is read once, and it and the
/// scheme files are the grammar's inputs, which `subdivide` never
/// overwrites.
#[test]
fn inserted_meshes_are_read_once_and_are_inputs() {
    let cube = format!("{}/lsystems/meshes/cube.obj", env!("CARGO_MANIFEST_DIR"));
    let s = load(&format!(
        "axiom: s(1, 1, 1) i(\"{cube}\") A\nA --> i(\"{cube}\") B\nB --> [ i(\"{cube}\") C ]\n"
    ));
    assert_eq!(s.inputs(), vec![std::path::PathBuf::from(&cube)]);
    let run = derive(&s, None);
    assert_eq!(run.soup.faces.len(), 6);
}
