//! Reverse subdivision of a 100,032-point closed contour by 6 steps
//! (100,032 = 1,563 x 64, so no level is odd and the loop below compares).
//! `cargo run --release --example bench_reverse`
//!
//! Timed in the same run: the engine running `lsystems/reverse/chaikin.lsys`
//! with a fixed phase and with `--phase auto` (which also reconstructs both
//! candidates at every step), the report's error measurement, and a
//! hand-written loop applying production (38) directly, as the reference.

mod common;

use std::time::Duration;

use common::best_of;
use glam::DVec2;
use subgram::reverse::{self, Contour, Phase, ReverseOptions, Scheme};

fn reverse_loop(pts: &[DVec2], steps: usize) -> Vec<DVec2> {
    let mut cur = pts.to_vec();
    for _ in 0..steps {
        let n = cur.len();
        cur = (0..n / 2)
            .map(|j| {
                let (a, b) = (cur[2 * j], cur[2 * j + 1]);
                let l = cur[(2 * j + n - 1) % n];
                let r = cur[(2 * j + 2) % n];
                -0.25 * l + 0.75 * a + 0.75 * b - 0.25 * r
            })
            .collect();
    }
    cur
}

fn main() {
    let n = 100_032;
    let points: Vec<DVec2> = (0..n)
        .map(|i| {
            let t = i as f64 / n as f64 * std::f64::consts::TAU;
            let r = 100.0 * (1.0 + 0.1 * (37.0 * t).sin() + 0.03 * (301.0 * t).cos());
            DVec2::new(r * t.cos(), r * t.sin())
        })
        .collect();
    let input = Contour {
        points,
        closed: true,
        source: "synthetic".into(),
    };
    let scheme = Scheme::builtin(true);
    let runs = 3;
    let opts = |phase| ReverseOptions {
        steps: 6,
        phase,
        details: false,
    };
    let (t_loop, reference) = best_of(runs, || reverse_loop(&input.points, 6));
    let (t_fixed, r) = best_of(runs, || {
        reverse::reverse(&scheme, &input, &opts(Phase::Fixed(0))).unwrap()
    });
    assert_eq!(r.coarse.len(), reference.len());
    let worst = r
        .coarse
        .iter()
        .zip(&reference)
        .map(|(a, b)| a.distance(*b))
        .fold(0.0, f64::max);
    let (t_auto, _) = best_of(runs, || {
        reverse::reverse(&scheme, &input, &opts(Phase::Auto)).unwrap()
    });
    let (t_details, _) = best_of(runs, || {
        reverse::reverse(
            &scheme,
            &input,
            &ReverseOptions {
                details: true,
                ..opts(Phase::Fixed(0))
            },
        )
        .unwrap()
    });
    let (t_report, rep) = best_of(runs, || reverse::report(&scheme, &input, &r).unwrap());
    let ms = |d: Duration| d.as_secs_f64() * 1e3;
    println!(
        "100,032 points, 6 reverse steps -> {} points, best of {runs}",
        r.coarse.len()
    );
    println!("  hand-written loop (38)     {:>8.2} ms", ms(t_loop));
    println!(
        "  engine, fixed phase        {:>8.2} ms  ({:.1}x the loop; max difference {worst:e})",
        ms(t_fixed),
        ms(t_fixed) / ms(t_loop)
    );
    println!("  engine, --phase auto       {:>8.2} ms", ms(t_auto));
    println!("  engine, fixed, --details   {:>8.2} ms", ms(t_details));
    println!(
        "  report (reconstruct + errors, reverse and decimation) {:>8.2} ms",
        ms(t_report)
    );
    println!(
        "  rms error: reverse {:.4}, decimation {:.4}",
        rep.reverse.rms, rep.decimation.rms
    );
}
