//! The walk's two loops compared in 3D.

use super::super::walk::walk_loops;
use super::super::{tropism, DrawOptions, Events, TurtleView};
use super::{Builder, SolidOptions};
use crate::model::view::LineStyle;
use glam::DVec3;

/// The two loops against the full loop alone where the project's
/// `draw::walk::tests` do not reach: long runs of common modules (the full
/// loop's hand-back), the 3D sink (whose `line` reads the turtle's frame),
/// tropisms and the simple tropism (`bends`), and queries.
#[test]
fn the_two_loops_agree_in_3d_with_tropisms_queries_and_hand_backs() {
    let common = [
        "F(1)",
        "f(2)",
        "G(1)",
        "F",
        "Left(30)",
        "Right(45)",
        "Down(20)",
        "RollR(70)",
        "TurnAround",
        "SB",
        "EB",
        "SetColor(3)",
        "IncColor",
        "SetWidth(0.5)",
    ];
    let other = [
        "Circle(1)",
        "Sphere(0.5)",
        "MoveTo(1, 2, 0)",
        "LineRel3f(V3f(0.5, 0.25, 1))",
        "SP",
        "PP",
        "EP",
        "RotateHLU(V3f(0, 0, 1), 33)",
        "SetHead3f(V3f(0, 1, 1))",
        "Elasticity(0.2)",
        "Elasticity(0)",
        "SetTropismDirection3f(V3f(0, -1, 0))",
        "IncElasticity(0)",
        "GetPos(0, 0, 0)",
        "GetHead(0, 0, 0)",
        "SetCoordinateSystem(2)",
        "StartGC",
        "PointGC",
        "EndGC",
    ];
    let opts = DrawOptions {
        view: TurtleView {
            corrected_rotation: false,
            tropisms: tropism::Tropisms {
                list: vec![
                    tropism::Tropism {
                        torque: false,
                        direction: DVec3::new(0.0, -1.0, 0.2),
                        angle: 0.5,
                        elasticity: 0.1,
                        step: 0.05,
                    },
                    tropism::Tropism {
                        torque: true,
                        direction: DVec3::X,
                        angle: 0.0,
                        elasticity: 0.2,
                        step: 0.1,
                    },
                ],
                simple: tropism::SimpleTropism {
                    direction: DVec3::new(0.3, -1.0, 0.0),
                    elasticity: 0.15,
                },
            },
        },
        ..Default::default()
    };
    let mut next = crate::testing::xorshift(0xfeed_5eed);
    for round in 0..30 {
        // One module in 40 not common: runs of 32 and more are many.
        let word: Vec<&str> = (0..600)
            .map(|_| match next() % 40 {
                0 => other[(next() % other.len() as u64) as usize],
                _ => common[(next() % common.len() as u64) as usize],
            })
            .collect();
        let src = format!("derivation length: 0;\nAxiom: {};\n", word.join(" "));
        let loaded =
            crate::load_str_with("walk.lsys", &src, &[], crate::Precision::Double).expect("loads");
        let p = &loaded.program;
        let w = crate::derive(p, Default::default()).expect("derives").word;
        let style = [LineStyle::Cylinder, LineStyle::Polygon][round % 2];
        let sopts = SolidOptions {
            line_style: Some(style),
            ..Default::default()
        };
        let [fast, full] = [true, false].map(|fast| {
            let mut queries = crate::rewrite::TurtleAnswers::default();
            let mut events = Events::new(Vec::new());
            let drawn = walk_loops(
                &w,
                &p.alphabet,
                &p.structs,
                &opts,
                Some(&mut queries),
                &mut events,
                fast,
            );
            let mut b = Builder::new(&opts.model, &sopts);
            let built = walk_loops(&w, &p.alphabet, &p.structs, &opts, None, &mut b, fast);
            let finished = b.finish();
            format!(
                "{drawn:?} {:?} {queries:?} {built:?} {finished:?} {:?}",
                events.into_inner(),
                b.scene
            )
        });
        assert!(fast == full, "{src}");
    }
}
