//! lpfg's semantics of `Cut`, of query modules and of the turtle's frame
//! modules, on small programs. The expected words come from the manual's
//! definitions (cited in each test) and were confirmed by lpfg itself
//! (vlab commit 9bf820d, built headless with ../shared/tools/lpfg, run with
//! `run_lpfg.sh`): each test quotes lpfg's final string.

use subgram::{DeriveOptions, Value};

use crate::support::*;

fn run(src: &str) -> String {
    let l = load_text(src);
    let d = derive(&l, DeriveOptions::default());
    text(&l, &d)
}

// Manual 5.4: "Cut() Cut the remainder of the current branch, if the
// derivation direction is Forward. This module and all following modules
// are ignored up to the closest unmatched EB module, or the end of the
// string if no EB module is found." lpfg performs the cut as part of a
// production step: the Cut module and the rest of its branch are neither
// rewritten nor copied into the new word, and the closing EB is kept.

#[test]
fn cut_at_top_level_removes_the_rest_of_the_word() {
    // lpfg 9bf820d gives `A(11) B(12)`.
    let src = "module A(int); module B(int);\nderivation length: 1;\n\
               Axiom: A(1) B(2) Cut() A(3) B(4) SB() A(5) EB() B(6);\n\
               A(x) : { produce A(x+10); }\nB(x) : { produce B(x+10); }\n";
    assert_eq!(run(src), "A(11) B(12)");
}

#[test]
fn cut_in_a_branch_removes_up_to_its_closing_bracket() {
    // The nested branch after the Cut goes with it; the EB that closes the
    // Cut's branch stays. lpfg 9bf820d gives
    // `A(11) SB() B(12) EB() B(16) SB() A(17) EB()`.
    let src = "module A(int); module B(int);\nderivation length: 1;\n\
               Axiom: A(1) SB() B(2) Cut() A(3) SB() B(4) EB() A(5) EB() B(6) SB() A(7) EB();\n\
               A(x) : { produce A(x+10); }\nB(x) : { produce B(x+10); }\n";
    assert_eq!(run(src), "A(11) SB B(12) EB B(16) SB A(17) EB");
}

#[test]
fn cut_in_nested_branches_removes_only_its_own_branch() {
    // lpfg 9bf820d gives `A(11) SB() A(12) SB() A(13) EB() A(17) EB() A(18)`.
    let src = "module A(int);\nderivation length: 1;\n\
               Axiom: A(1) SB() A(2) SB() A(3) Cut() A(4) SB() A(5) EB() A(6) EB() A(7) EB() A(8);\n\
               A(x) : { produce A(x+10); }\n";
    assert_eq!(run(src), "A(11) SB A(12) SB A(13) EB A(17) EB A(18)");
}

#[test]
fn a_produced_cut_takes_effect_in_the_next_step() {
    // Step 1 produces `A(13) Cut() B(3)` in a branch; step 2 removes the
    // Cut and B(3), which a production would otherwise have rewritten to
    // B(13). lpfg 9bf820d gives `A(21) SB() B(22) A(23) EB() B(24)`.
    let src = "module A(int); module B(int);\nderivation length: 2;\n\
               Axiom: A(1) SB() B(2) A(3) EB() B(4);\n\
               A(x) : { if (x == 3) produce A(x+10) Cut() B(x); produce A(x+10); }\n\
               B(x) : { produce B(x+10); }\n";
    let l = load_text(src);
    let one = derive(&l, DeriveOptions::default().with_steps(1));
    assert_eq!(text(&l, &one), "A(11) SB B(12) A(13) Cut B(3) EB B(14)");
    assert_eq!(run(src), "A(21) SB B(22) A(23) EB B(24)");
}

#[test]
fn contexts_see_the_old_word_across_a_cut() {
    // A(1)'s right context skips the branch `[Cut B(2)]` and finds B(3);
    // B(3)'s right context is A(4). The cut modules are gone from the new
    // word, but matching read the old one. lpfg 9bf820d gives
    // `A(301) SB() EB() B(403) A(4)`.
    let src = "module A(int); module B(int);\nderivation length: 1;\n\
               Axiom: A(1) SB() Cut() B(2) EB() B(3) A(4) Cut() B(5);\n\
               A(x) > B(y) : { produce A(x+100*y); }\n\
               B(x) > A(y) : { produce B(x+100*y); }\n";
    assert_eq!(run(src), "A(301) SB EB B(403) A(4)");
}

#[test]
fn cut_in_a_ring_removes_to_the_end_of_the_word() {
    // A(1) sees A(4) on its left around the ring, and A(2) on its right;
    // A(2) is copied (its right neighbour is the Cut), and the Cut with
    // A(3) A(4) is removed. lpfg 9bf820d gives `A(412) A(2)`.
    let src = "module A(int);\nderivation length: 1;\nring L-system: 1;\n\
               Axiom: A(1) A(2) Cut() A(3) A(4);\n\
               A(l) < A(x) > A(r) : { produce A(100*l+10*x+r); }\n";
    assert_eq!(run(src), "A(412) A(2)");
}

#[test]
fn cut_on_a_ring_does_not_go_round_from_a_phase() {
    // lpfg has no phase; subgram's `--phase` starts the scan elsewhere on
    // a ring. A scan that starts at the Cut removes it with A(4) A(5), to
    // the end of the word, and then rewrites A(1) A(2) A(3): the word of
    // phase 0, which lpfg 9bf820d gives as `A(11) A(12) A(13)`.
    let src = "module A(int);\nderivation length: 1;\nring L-system: 1;\n\
               Axiom: A(1) A(2) A(3) Cut() A(4) A(5);\nA(x) : { produce A(x+10); }\n";
    let l = load_text(src);
    for phase in [0, 1, 3] {
        let d = derive(&l, DeriveOptions::default().with_phase(phase));
        assert_eq!(text(&l, &d), "A(11) A(12) A(13)", "phase {phase}");
    }
}

#[test]
fn cut_stays_when_deriving_backward() {
    // Manual 5.4: Cut "has no effect if the derivation direction is
    // Backward". lpfg 9bf820d gives `A(11) Cut() A(12)` (and says "Cut
    // module found while deriving backwards. Ignored.").
    let src = "module A(int);\nderivation length: 1;\nStart: { Backward(); }\n\
               Axiom: A(1) Cut() A(2);\nA(x) : { produce A(x+10); }\n";
    assert_eq!(run(src), "A(11) Cut A(12)");
}

#[test]
fn decomposition_does_not_cut() {
    // Only production steps cut (lpfg's decomposition has no Cut case):
    // the decomposed axiom keeps its Cut, and the first step removes it.
    // lpfg 9bf820d gives `A(1) Cut() A(2)` and, with one step, `A(1)`.
    let src = "module A(int); module D;\nderivation length: 0;\n\
               Axiom: A(1) D A(2);\ndecomposition:\nD : { produce Cut(); }\n";
    assert_eq!(run(src), "A(1) Cut A(2)");
    assert_eq!(run(&src.replace("length: 0", "length: 1")), "A(1)");
}

#[test]
fn the_turtle_draws_past_a_cut_left_in_the_word() {
    // A Cut in the axiom with derivation length 0 is still in the word.
    // lpfg's turtle has no action for Cut: its -dtf dump of this axiom
    // lists all five F(1), and so five lines are drawn here.
    let src = "derivation length: 0;\n\
               Axiom: F(1) SB() Left(90) F(1) Cut() F(1) EB() F(1) Cut() Right(90) F(1);\n";
    let l = load_text(src);
    let mut run = l.run(DeriveOptions::default()).unwrap();
    let lines = run.polylines().unwrap();
    let segments: usize = lines.iter().map(|p| p.len() - 1).sum();
    assert_eq!(segments, 5);
}

// Manual 5.12: with a query module in a predecessor, an interpretation
// step moves the turtle and fills the query modules. lpfg does it at the
// start of each derivation step (before StartEach), writing into the
// word's own query modules as the turtle meets them.

#[test]
fn query_modules_after_a_cut_are_answered() {
    // The program: a GetPos after a Cut and no interpretation rule
    // used to fail with "the word has 2 query modules but its
    // interpretation has 1". The first step's interpretation (of the
    // axiom) answers both; the step then removes the Cut and the rest.
    // lpfg 9bf820d gives `F(1) GetPos(0,1,0)`.
    let src = "derivation length: 1;\n\
               Axiom: F(1) GetPos(0,0,0) Cut() F(1) GetPos(0,0,0);\n\
               GetPos(x,y,z) : { produce GetPos(x,y,z); }\n";
    assert_eq!(run(src), "F(1) GetPos(0, 1, 0)");
}

#[test]
fn queries_are_answered_only_where_the_turtle_meets_the_words_own_module() {
    // The interpretation rule rewrites GetPos(-1,0,0), so that module is
    // not met and keeps its parameters, but its F(7) moves the turtle: the
    // next GetPos reads 7 + 2 = 9. The GetPos(5,5,5) produced in the last
    // step is not answered: no interpretation for queries follows the
    // last step. lpfg 9bf820d gives
    // `GetPos(-1,0,0) F(2) GetPos(0,9,0) SB() EB() F(1) GetPos(5,5,5) A(2)`.
    let src = "module A(int);\nderivation length: 1;\n\
               Axiom: GetPos(-1,0,0) F(2) GetPos(0,0,0) SB() Cut() F(1) GetPos(0,0,0) EB() A(1);\n\
               GetPos(x,y,z) : { produce GetPos(x,y,z); }\n\
               A(x) : { produce F(1) GetPos(5,5,5) A(x+1); }\n\
               interpretation:\n\
               GetPos(x,y,z) : { if (x < 0) produce F(7) GetPos(x,y,z); }\n";
    assert_eq!(
        run(src),
        "GetPos(-1, 0, 0) F(2) GetPos(0, 9, 0) SB EB F(1) GetPos(5, 5, 5) A(2)"
    );
}

/// The parameters of the query modules of the derived word, in order.
fn queries(src: &str) -> Vec<[f64; 3]> {
    let l = load_text(src);
    let d = derive(&l, DeriveOptions::default());
    d.word
        .modules(&l.program.alphabet, &l.program.structs)
        .filter(|(s, _)| l.program.alphabet.name(*s).starts_with("Get"))
        .map(|(_, ps)| {
            let f: Vec<f64> = ps.iter().map(Value::as_f64).collect();
            [f[0], f[1], f[2]]
        })
        .collect()
}

#[test]
// lpfg's numbers as it printed them, some close to 1/sqrt(2).
#[allow(clippy::approx_constant)]
fn frame_modules_turn_the_turtle_as_lpfg_does() {
    // Manual 5.1 and 5.2 define SetHead, RollToVert, RotateXYZ, RotateHLU,
    // SetHead3f and SetCoordinateSystem; the expected vectors are lpfg's
    // (single precision, so compared to 1e-5): lpfg 9bf820d gives
    // GetHead(0.70710677,0.70710677,0) GetLeft(-0.70710677,0.70710677,0)
    // GetUp(0,-0,0.99999994) ... as listed below.
    let src = "derivation length: 1;\n\
        Axiom: SetHead(1,1,0, 0,0,1) GetHead(0,0,0) GetLeft(0,0,0) GetUp(0,0,0) \
        RollToVert() GetLeft(0,0,0) GetUp(0,0,0) \
        RotateXYZ(V3f(0,0,1), 30) GetHead(0,0,0) GetLeft(0,0,0) \
        RotateHLU(V3f(0,1,0), 40) GetHead(0,0,0) GetUp(0,0,0) F(1) \
        SetCoordinateSystem(2) MoveTo(1,2,3) GetPos(0,0,0) MoveRel3f(V3f(1,0,0)) GetPos(0,0,0) \
        SetHead3f(V3f(0,0,1)) GetHead(0,0,0) GetLeft(0,0,0) GetUp(0,0,0) \
        Line3f(V3f(0,0,0), V3f(1,1,1)) GetPos(0,0,0) LineRel3f(V3f(0,1,0)) GetPos(0,0,0);\n\
        GetHead(x,y,z) : { produce GetHead(x,y,z); }\n";
    let lpfg = [
        [0.70710677, 0.70710677, 0.0],
        [-0.70710677, 0.70710677, 0.0],
        [0.0, -0.0, 0.99999994],
        [0.0, 0.0, -0.99999994],
        [-0.7071067, 0.7071067, 0.0],
        [0.25881907, 0.96592593, 0.0],
        [0.0, 0.0, -1.0],
        [0.81915224, 0.57357657, 0.0],
        [-0.5735765, 0.81915206, 0.0],
        [0.654302, 7.782795, 2.0000002],
        [1.4734542, 8.356372, 4.0000005],
        [-0.57357657, 0.81915236, 0.0],
        [0.0, 0.0, -1.0000001],
        [-0.81915206, -0.5735765, 0.0],
        [1.3103037, 3.359034, 2.0000002],
        [3.7677603, 5.079764, 2.0000002],
    ];
    assert_close(&queries(src), &lpfg);
}

/// Each query's vector within 1e-5 (relative above 1) of lpfg's single
/// precision one.
fn assert_close(got: &[[f64; 3]], lpfg: &[[f64; 3]]) {
    assert_eq!(got.len(), lpfg.len());
    for (k, (g, w)) in got.iter().zip(lpfg).enumerate() {
        for c in 0..3 {
            assert!(
                (g[c] - w[c]).abs() <= 1e-5 * w[c].abs().max(1.0),
                "query {k}: {g:?}, lpfg {w:?}"
            );
        }
    }
}

#[test]
fn rotations_turn_the_turtle_as_lpfg_does() {
    // Manual 5.2's rotations, in lpfg's default (uncorrected) sense.
    // lpfg 9bf820d gives GetHead(0,0.8660254,0.5) GetUp(0,-0.5,0.8660254)
    // ... as listed below.
    let src = "derivation length: 1;
        Axiom: Up(30) GetHead(0,0,0) GetUp(0,0,0) Down(50) GetHead(0,0,0)         RollL(40) GetLeft(0,0,0) GetUp(0,0,0) RollR(15) GetLeft(0,0,0)         Left(20) GetHead(0,0,0) Right(70) GetHead(0,0,0)         TurnAround() GetHead(0,0,0) GetLeft(0,0,0);
        GetHead(x,y,z) : { produce GetHead(x,y,z); }
";
    let lpfg = [
        [0.0, 0.8660254, 0.5],
        [0.0, -0.5, 0.8660254],
        [0.0, 0.9396926, -0.34202012],
        [-0.76604444, -0.2198463, -0.60402274],
        [-0.6427876, 0.26200262, 0.7198463],
        [-0.90630776, -0.14454395, -0.3971312],
        [-0.3099755, 0.83358526, -0.45722067],
        [0.694272, 0.7147498, 0.08437383],
        [-0.6942719, -0.7147499, -0.08437379],
        [0.58256346, -0.6269352, 0.5172736],
    ];
    assert_close(&queries(src), &lpfg);
}

#[test]
fn a_batch_run_has_no_mouse_and_no_menu_choice() {
    // The manual's SimpleDraw model (7.4): lines are drawn only while the
    // left button is down. Without a window no button is ever pushed or
    // down, so the cursor is copied and nothing is drawn. lpfg's batch mode
    // cannot run it (GetMouseStatus needs a view); the values are those of
    // lpfg's source when no view was clicked: viewNum -1, buttons false,
    // and UserMenuChoice -1 when no item was chosen.
    let simple_draw = "derivation length: 1;\nmodule Cursor();\nMouseStatus ms;\n\
        StartEach: { ms = GetMouseStatus(); }\n\
        Axiom: SetColor(2) SetWidth(0.3) Cursor();\n\
        Cursor() : {\n  if(ms.lbPushed) produce MoveTo3d(ms.atMiddle) Cursor();\n\
        if(ms.lbDown) produce LineTo3d(ms.atMiddle) Cursor();\n}\n";
    assert_eq!(run(simple_draw), "SetColor(2) SetWidth(0.3) Cursor");
    let menu = "derivation length: 1;\nmodule C(int, int, int);\nint choice;\nMouseStatus ms;\n\
        Start: { UserMenuItem(\"First menu item\", 1); UserMenuItem(\"Second\", 2); }\n\
        StartEach: { choice = UserMenuChoice(); ms = GetMouseStatus(); }\n\
        Axiom: C(0, 0, 0);\n\
        C(a, b, c) : { produce C(choice, ms.viewNum, ms.lbReleased); }\n";
    assert_eq!(run(menu), "C(-1, -1, 0)");
}

#[test]
fn no_environment_stops_the_answers_to_queries() {
    // Manual 6.1.3: NoEnvironment() turns the interpretation for the
    // environment off, and query modules are answered by that
    // interpretation. lpfg 9bf820d gives `F(1) GetPos(0,0,0)`; without the
    // call, GetPos(0,1,0).
    let src = "derivation length: 2;\nStart: { NoEnvironment(); }\n\
               Axiom: F(1) GetPos(0,0,0);\nGetPos(x,y,z) : { produce GetPos(x,y,z); }\n";
    assert_eq!(run(src), "F(1) GetPos(0, 0, 0)");
    assert_eq!(
        run(&src.replace("Start: { NoEnvironment(); }\n", "")),
        "F(1) GetPos(0, 1, 0)"
    );
}

#[test]
fn line_modules_record_polygon_vertices_as_f_does() {
    // lpfg draws LineTo and LineRel as a turn and an F, so inside SP() ...
    // EP() each end is a vertex; a LineTo to where the turtle stands
    // (shorter than epsilon, manual 5.1) is ignored. lpfg 9bf820d draws
    // the two triangles (1,0) (1,1) (0,1) and (5,5) (6,5) (6,6) for this
    // axiom (its picture, read by eye).
    let src = "derivation length: 0;\n\
        Axiom: SP() LineTo(1,0,0) LineTo(1,1,0) LineTo(0,1,0) EP() \
        SP() MoveTo(5,5,0) LineTo(5,5,0) PP() LineRel3f(V3f(1,0,0)) LineRel3f(V3f(0,1,0)) EP();\n";
    let l = load_text(src);
    let mut run = l.run(DeriveOptions::default()).unwrap();
    let polygons: Vec<Vec<[f64; 2]>> = run
        .events()
        .unwrap()
        .into_iter()
        .filter_map(|e| match e {
            subgram::draw::Event::Polygon { points, .. } => {
                Some(points.iter().map(|p| [p.x, p.y]).collect())
            }
            _ => None,
        })
        .collect();
    assert_eq!(
        polygons,
        [
            vec![[1.0, 0.0], [1.0, 1.0], [0.0, 1.0]],
            vec![[5.0, 5.0], [6.0, 5.0], [6.0, 6.0]]
        ]
    );
}

#[test]
fn rhombus_and_triangle_are_polygons_in_the_hl_plane() {
    // Manual 5.6: the turtle at the middle of the bottom edge, in the
    // plane of heading and left. lpfg's OpenGL turtle draws
    // Rhombus(length a, width b) through P, P + aH/2 + bL/2, P + aH,
    // P + aH/2 - bL/2, and Triangle(width a, height b) through P + aL/2,
    // P + bH, P - aL/2. lpfg 9bf820d's picture of these two (moved apart
    // by MoveTo(3,0,0)) shows an upright rhombus 1 wide and 2 long and a
    // triangle of base 4 and height 3. With H = +y and L = -x at the
    // origin:
    let src = "derivation length: 0;\nAxiom: Rhombus(2, 1) Triangle(4, 3);\n";
    let l = load_text(src);
    let mut run = l.run(DeriveOptions::default()).unwrap();
    let polygons: Vec<Vec<[f64; 2]>> = run
        .events()
        .unwrap()
        .into_iter()
        .filter_map(|e| match e {
            subgram::draw::Event::Polygon { points, .. } => {
                Some(points.iter().map(|p| [p.x, p.y]).collect())
            }
            _ => None,
        })
        .collect();
    assert_eq!(
        polygons,
        [
            vec![[0.0, 0.0], [-0.5, 1.0], [0.0, 2.0], [0.5, 1.0]],
            vec![[-2.0, 0.0], [0.0, 3.0], [2.0, 0.0]]
        ]
    );
}

/// The query vectors of `program` derived beside a view file `view`.
fn queries_with_view(name: &str, view: &str, program: &str) -> Vec<[f64; 3]> {
    let tmp = scratch(&format!("lpfg-{name}"));
    let dir = tmp.path();
    std::fs::write(dir.join("view.v"), view).unwrap();
    let file = dir.join("lsystem.l");
    std::fs::write(&file, program).unwrap();
    let l = load(&file);
    // The curve's own derive: it brings the view file's settings.
    let d = l.derive(DeriveOptions::default()).unwrap();
    d.word
        .modules(&l.program.alphabet, &l.program.structs)
        .filter(|(s, _)| l.program.alphabet.name(*s).starts_with("Get"))
        .map(|(_, ps)| {
            let f: Vec<f64> = ps.iter().map(Value::as_f64).collect();
            [f[0], f[1], f[2]]
        })
        .collect()
}

#[test]
fn tropisms_of_the_view_file_bend_the_turtle_as_lpfg_does() {
    // Manual 5.11 and 8.1.4: two tropisms (the second with an angle, an
    // intensity and a step), changed by SetElasticity inside a branch
    // (undone at its end) and by IncElasticity and DecElasticity. lpfg
    // 9bf820d gives GetPos(-0.41180086,0.7883673,0.45705268) ... as listed
    // below.
    let view = "tropism: T: 0 -1 0 E: 0.3\ntropism: T: 1 0 0 A: 45 I: 2 E: 0.1 S: 0.05\n";
    let program = "derivation length: 1;\n\
        Axiom: Left(30) Up(20) F(1) GetPos(0,0,0) GetHead(0,0,0) GetUp(0,0,0) \
        SB() SetElasticity(0, 0.6) F(1) GetHead(0,0,0) IncElasticity(1) F(1) GetHead(0,0,0) EB() \
        F(1) GetPos(0,0,0) GetHead(0,0,0) DecElasticity(1) f(2) GetPos(0,0,0) GetLeft(0,0,0);\n\
        GetHead(x,y,z) : { produce GetHead(x,y,z); }\n";
    let lpfg = [
        [-0.41180086, 0.7883673, 0.45705268],
        [-0.41180086, 0.7883673, 0.45705268],
        [0.22659694, -0.39721283, 0.88931197],
        [-0.41706395, 0.59466606, 0.6873355],
        [-0.26911467, 0.23072453, 0.93506336],
        [-0.7448687, 1.5186445, 1.05351],
        [-0.33306783, 0.7302772, 0.5964573],
        [-1.3749291, 2.720795, 2.5224752],
        [-0.8827991, -0.4697159, 0.005754024],
    ];
    assert_close(&queries_with_view("tropism", view, program), &lpfg);
}

#[test]
fn torque_simple_tropism_and_old_rotations_as_lpfg_does() {
    // A torque, a simple tropism (stropism, then Elasticity and
    // SetTropismDirection3f in a branch) and `corrected rotation: off`,
    // under which Up and RollL turn the other way. lpfg 9bf820d gives
    // GetPos(-0.4698463,0.81379765,-0.34202012) ... as listed below.
    let view = "torque: T: 0 0 1 E: 0.4\nstropism: 0 -1 0, 0.2\ncorrected rotation: off\n";
    let program = "derivation length: 1;\n\
        Axiom: Left(30) Up(20) RollL(10) F(1) GetPos(0,0,0) GetHead(0,0,0) GetUp(0,0,0) \
        SB() Elasticity(0.5) F(1) GetHead(0,0,0) SetTropismDirection3f(V3f(1,0,0)) G(1) \
        GetHead(0,0,0) EB() F(1) GetPos(0,0,0) GetHead(0,0,0) GetLeft(0,0,0);\n\
        GetHead(x,y,z) : { produce GetHead(x,y,z); }\n";
    let lpfg = [
        [-0.4698463, 0.81379765, -0.34202012],
        [-0.5431325, 0.7408682, -0.39512172],
        [0.00476411, 0.47329235, 0.88089263],
        [-0.71307385, 0.47653702, -0.5142354],
        [-0.4225716, 0.61358297, -0.66704506],
        [-1.0129788, 1.5546658, -0.73714185],
        [-0.61867213, 0.6441538, -0.44978946],
        [-0.78450924, -0.47568265, 0.39783323],
    ];
    assert_close(&queries_with_view("torque", view, program), &lpfg);
}
