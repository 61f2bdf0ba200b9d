//! `subgram analyze` against published values. Every expected number is
//! computed here from a published formula or a matrix built here from the
//! scheme's masks, never taken from subgram's output.

use std::f64::consts::{PI, TAU};

use nalgebra::DMatrix;
use subgram::analyze::{analyze, CurveReport, Scheme, SurfaceReport};

use crate::support::*;

fn curve(file: &str) -> CurveReport {
    match analyze(&lsys(file), &[])
        .unwrap_or_else(|e| panic!("{e}"))
        .scheme
    {
        Scheme::Curve(c) => *c,
        Scheme::Surface(_) => panic!("{file} is a curve"),
    }
}

fn surface(file: &str) -> SurfaceReport {
    match analyze(&lsys(file), &[])
        .unwrap_or_else(|e| panic!("{e}"))
        .scheme
    {
        Scheme::Surface(s) => s,
        Scheme::Curve(_) => panic!("{file} is a surface grammar"),
    }
}

fn stencil_values(c: &CurveReport) -> Vec<Vec<f64>> {
    c.stencils
        .iter()
        .map(|s| s.weights.iter().map(|w| w.value).collect())
        .collect()
}

/// Chaikin's scheme is the quadratic B-spline: mask (1+z)^3 / 4, so it
/// generates quadratics; the quadratic B-spline is C^1 with a Lipschitz
/// derivative, Hölder exponent 2 (de Boor, A Practical Guide to Splines;
/// Dyn, "Subdivision schemes in CAGD", 1992, the B-spline of degree d has
/// Hölder exponent d).
#[test]
fn chaikin_is_the_quadratic_b_spline() {
    for f in ["chaikin-13", "chaikin-17", "chaikin-18", "chaikin-20"] {
        let c = curve(&format!("curves/{f}.lsys"));
        assert_eq!(c.arity, Some(2), "{f}");
        let mut st = stencil_values(&c);
        st.sort_by(|a, b| a[0].total_cmp(&b[0]));
        assert_eq!(st, vec![vec![0.25, 0.75], vec![0.75, 0.25]], "{f}");
        assert!(c.stencils.iter().all(|s| (s.sum - 1.0).abs() < 1e-12));
        assert!(c.affine && !c.interpolating);
        let m = c.mask.as_ref().unwrap();
        assert_eq!(m.coefficients, vec![0.25, 0.75, 0.75, 0.25], "{f}");
        assert_eq!(m.factor_power, 3);
        assert_eq!(c.generation_degree, Some(2));
        assert_eq!(c.reproduction_degree, Some(1));
        let h = c.smoothness.as_ref().unwrap();
        assert!((h.lower - 2.0).abs() < 1e-9, "{f}: {}", h.lower);
        assert!((h.upper.unwrap() - 2.0).abs() < 1e-9);
        assert_eq!(h.continuity, Some(1));
    }
}

/// The cubic B-spline: mask (1+z)^4 / 8, generates cubics, C^2 with
/// Hölder exponent 3 (de Boor; Dyn 1992).
#[test]
fn cubic_is_the_cubic_b_spline() {
    for f in ["cubic-22", "cubic-23"] {
        let c = curve(&format!("curves/{f}.lsys"));
        let m = c.mask.as_ref().unwrap();
        // (1+z)^4 / 8 = 1/8 (1, 4, 6, 4, 1)
        assert_eq!(m.coefficients, vec![0.125, 0.5, 0.75, 0.5, 0.125], "{f}");
        assert_eq!(m.factor_power, 4);
        assert!(c.affine && !c.interpolating);
        assert_eq!(c.support, 5);
        assert_eq!(c.generation_degree, Some(3));
        let h = c.smoothness.as_ref().unwrap();
        assert!((h.lower - 3.0).abs() < 1e-9 && (h.upper.unwrap() - 3.0).abs() < 1e-9);
        assert_eq!(h.continuity, Some(2));
    }
}

/// The Dyn-Levin-Gregory four-point scheme with w = 1/16 (Dyn, Gregory,
/// Levin, "A 4-point interpolatory subdivision scheme for curve design",
/// CAGD 4, 1987: interpolating, C^1 for 0 < w < 1/8, reproduces cubics).
/// Its Hölder exponent is 2: C^1, not C^2, the derivative Hölder of every
/// exponent below 1 (Daubechies and Lagarias, "Two-scale difference
/// equations II", SIAM J. Math. Anal. 23, 1992). The mask is
/// (1+z)^4 (-1 + 4z - z^2) / 16, up to a power of z.
#[test]
fn four_point_interpolates_and_is_c1() {
    for f in ["fourpoint-25", "fourpoint-26"] {
        let c = curve(&format!("curves/{f}.lsys"));
        assert!(c.interpolating && c.affine, "{f}");
        assert!(c.stencils.iter().all(|s| (s.sum - 1.0).abs() < 1e-12));
        let m = c.mask.as_ref().unwrap();
        let want = [-1.0, 0.0, 9.0, 16.0, 9.0, 0.0, -1.0].map(|x| x / 16.0);
        assert_eq!(m.coefficients, want, "{f}");
        assert_eq!(m.factor_power, 4);
        let q: Vec<f64> = m.quotient.iter().map(|x| x * 16.0).collect();
        assert!(q
            .iter()
            .zip([-1.0, 4.0, -1.0])
            .all(|(a, b)| (a - b).abs() < 1e-12));
        assert_eq!(c.reproduction_degree, Some(3));
        let h = c.smoothness.as_ref().unwrap();
        assert!(
            h.lower <= 2.0 + 1e-9 && h.upper.unwrap() >= 2.0 - 1e-9,
            "{f}"
        );
        // Within rounding of 2, so above 1: C^1.
        assert!(h.lower > 2.0 - 1e-6);
        assert_eq!(h.continuity, Some(1));
    }
}

/// Open Chaikin (paper 002, matrix (27)): interior stencils of Chaikin,
/// the ends kept and the midpoints next to them.
#[test]
fn open_chaikin_reports_its_boundary_rows() {
    for f in ["open-chaikin-full", "open-chaikin-short"] {
        let c = curve(&format!("curves/{f}.lsys"));
        assert!(!c.closed && c.affine);
        assert_eq!(c.mask.as_ref().unwrap().factor_power, 3);
        type Row = (String, i64, Vec<(i64, f64)>);
        let rows: Vec<Row> = c
            .boundary
            .iter()
            .map(|b| {
                let w = b.weights.iter().map(|w| (w.offset, w.value)).collect();
                (b.end.clone(), b.row, w)
            })
            .collect();
        assert_eq!(
            rows,
            vec![
                ("left".into(), 0, vec![(0, 1.0)]),
                ("left".into(), 1, vec![(0, 0.5), (1, 0.5)]),
                ("right".into(), -2, vec![(-2, 0.5), (-1, 0.5)]),
                ("right".into(), -1, vec![(-1, 1.0)]),
            ],
            "{f}"
        );
    }
}

/// Reverse Chaikin (38): one point from two, weights -1/4 3/4 3/4 -1/4.
#[test]
fn reverse_chaikin_is_a_reduction() {
    let c = curve("curves/reverse-chaikin-38.lsys");
    assert_eq!(c.reduction, Some(2));
    assert_eq!(stencil_values(&c), vec![vec![-0.25, 0.75, 0.75, -0.25]]);
    assert!(c.affine && c.mask.is_none());
}

/// Loop's β (his thesis, 1987): β(n) = (5/8 - (3/8 + 1/4 cos(2π/n))^2) / n.
fn loop_beta(n: usize) -> f64 {
    let c = 3.0 / 8.0 + 0.25 * (TAU / n as f64).cos();
    (5.0 / 8.0 - c * c) / n as f64
}

/// The 1-ring matrix of Loop's masks, built here: the centre is
/// (1 - nβ) c + β Σ v_i, the edge point on (c, v_i) is 3/8 (c + v_i) +
/// 1/8 (v_(i-1) + v_(i+1)).
fn loop_matrix(n: usize) -> DMatrix<f64> {
    let b = loop_beta(n);
    let mut s = DMatrix::zeros(n + 1, n + 1);
    s[(0, 0)] = 1.0 - n as f64 * b;
    for i in 0..n {
        s[(0, i + 1)] = b;
        s[(i + 1, 0)] = 3.0 / 8.0;
        s[(i + 1, i + 1)] = 3.0 / 8.0;
        s[(i + 1, (i + n - 1) % n + 1)] += 1.0 / 8.0;
        s[(i + 1, (i + 1) % n + 1)] += 1.0 / 8.0;
    }
    s
}

fn moduli(m: &DMatrix<f64>) -> Vec<f64> {
    let mut e: Vec<f64> = m.complex_eigenvalues().iter().map(|c| c.norm()).collect();
    e.sort_by(|a, b| b.total_cmp(a));
    e
}

/// Loop: the subdominant eigenvalue of the 1-ring matrix is
/// 3/8 + 1/4 cos(2π/n) (Loop's thesis, 1987), at every valence 3..12, the
/// same as the matrix built here from the masks; Reif's check holds; the
/// limit position is (1 - nχ) c + χ Σ v_i, χ = 1 / (3 / (8β) + n) (Loop's
/// thesis; Hoppe et al., "Piecewise smooth surface reconstruction", 1994).
#[test]
fn loop_eigenvalues_and_limit_stencil() {
    let s = surface("surfaces/loop.lsys");
    assert_eq!(s.faces, "triangles");
    let got: Vec<usize> = s.valences.iter().map(|v| v.n).collect();
    assert_eq!(got, (3..=12).collect::<Vec<_>>());
    for v in &s.valences {
        let n = v.n;
        assert!(v.skipped.is_none(), "{n}: {:?}", v.skipped);
        let formula = 3.0 / 8.0 + 0.25 * (TAU / n as f64).cos();
        let built = moduli(&loop_matrix(n));
        assert!((built[1] - formula).abs() < 1e-12 && (built[2] - formula).abs() < 1e-12);
        assert_eq!(v.size, n + 1, "{n}: the 1-ring");
        assert!(v.affine && v.reif, "{n}");
        assert!((v.eigenvalues[0].re - 1.0).abs() < 1e-9);
        for k in [1, 2] {
            assert!((v.eigenvalues[k].re - formula).abs() < 1e-9, "{n}");
            assert!(v.eigenvalues[k].im.abs() < 1e-9);
        }
        assert!((v.eigenvalues[3].modulus - built[3]).abs() < 1e-9, "{n}");
        let chi = 1.0 / (3.0 / (8.0 * loop_beta(n)) + n as f64);
        for w in &v.limit {
            let want = if (w.i, w.j) == (0, 0) {
                1.0 - n as f64 * chi
            } else {
                chi
            };
            assert!((w.weight - want).abs() < 1e-9, "{n}: {w:?} against {want}");
        }
        // The tangents span the cosine and sine of the ring (Loop's
        // tangent masks): both are orthogonal to the centre and to the
        // constant on the ring.
        assert_eq!(v.tangents.len(), 2);
        for t in &v.tangents {
            let centre = t.iter().find(|w| (w.i, w.j) == (0, 0)).unwrap().weight;
            let ring: f64 = t
                .iter()
                .filter(|w| (w.i, w.j) != (0, 0))
                .map(|w| w.weight)
                .sum();
            assert!(centre.abs() < 1e-9 && ring.abs() < 1e-9, "{n}");
        }
    }
}

/// Catmull-Clark: at valence 4 the subdivision matrix of the uniform
/// bicubic B-spline has 1, 1/2, 1/2, 1/4 (Catmull and Clark, 1978); at
/// valence n the subdominant eigenvalue is
/// (5 + cos(2π/n) + cos(π/n) sqrt(2 (9 + cos(2π/n)))) / 16 (Halstead,
/// Kass and DeRose, "Efficient, fair interpolation using Catmull-Clark
/// surfaces", SIGGRAPH 1993; Stam, "Exact evaluation of Catmull-Clark
/// subdivision surfaces at arbitrary parameter values", SIGGRAPH 1998).
/// The limit position is n/(n+5) of the vertex, 4/(n(n+5)) of each edge
/// neighbour and 1/(n(n+5)) of each face neighbour (Halstead et al.).
#[test]
fn catmull_clark_eigenvalues_and_limit_stencil() {
    let s = surface("surfaces/catmull-clark.lsys");
    assert_eq!(s.faces, "quads");
    for v in &s.valences {
        let n = v.n as f64;
        assert!(v.skipped.is_none(), "{n}: {:?}", v.skipped);
        assert!(v.affine && v.reif, "{n}");
        assert_eq!(v.size, 2 * v.n + 1);
        let c = (TAU / n).cos();
        let l1 = (5.0 + c + (PI / n).cos() * (2.0 * (9.0 + c)).sqrt()) / 16.0;
        assert!((v.eigenvalues[1].re - l1).abs() < 1e-9, "{n}: {l1}");
        assert!((v.eigenvalues[2].re - l1).abs() < 1e-9, "{n}");
        for w in &v.limit {
            let want = match (w.i, w.j) {
                (0, 0) => n / (n + 5.0),
                (1, 0) => 4.0 / (n * (n + 5.0)),
                _ => 1.0 / (n * (n + 5.0)),
            };
            assert!((w.weight - want).abs() < 1e-9, "{n}: {w:?}");
        }
    }
    let regular = &s.valences[1];
    assert_eq!(regular.n, 4);
    let e: Vec<f64> = regular.eigenvalues.iter().map(|e| e.re).collect();
    for (k, want) in [1.0, 0.5, 0.5, 0.25].iter().enumerate() {
        assert!((e[k] - want).abs() < 1e-9, "λ{k} = {}", e[k]);
    }
}

/// Every curve and surface file of `lsystems/` is analysed without error;
/// every curve scheme that refines is affine-invariant.
#[test]
fn every_scheme_in_lsystems_is_analysed() {
    for dir in ["curves", "surfaces"] {
        let mut files: Vec<_> = std::fs::read_dir(lsys(dir))
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "lsys"))
            .collect();
        files.sort();
        assert!(!files.is_empty());
        for f in files {
            let r = analyze(&f, &[]).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
            assert!(!r.text().is_empty());
            let json: serde_json::Value = serde_json::from_str(&r.json()).unwrap();
            assert_eq!(
                json["kind"],
                if dir == "curves" { "curve" } else { "surface" }
            );
            if let Scheme::Curve(c) = &r.scheme {
                assert!(c.affine, "{}", f.display());
            }
        }
    }
}

/// The JSON report carries the same content as the text.
#[test]
fn json_has_the_stencils() {
    let r = analyze(&lsys("curves/cubic-22.lsys"), &[]).unwrap();
    let j: serde_json::Value = serde_json::from_str(&r.json()).unwrap();
    assert_eq!(j["kind"], "curve");
    assert_eq!(j["mask"]["factor_power"], 4);
    assert_eq!(j["stencils"][0]["weights"][0]["fraction"], "1/8");
    assert_eq!(j["smoothness"]["continuity"], 2);
}

fn refused(text: &str) -> String {
    let dir = std::env::temp_dir().join(format!("subgram-analyze-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let f = dir.join(format!("t{}.lsys", text.len()));
    std::fs::write(&f, text).unwrap();
    let e = analyze(&f, &[]).expect_err("must be refused").to_string();
    let _ = std::fs::remove_file(&f);
    e
}

/// What is not a linear, uniform scheme of points is refused with a
/// message that says what analyze needs.
#[test]
fn non_schemes_are_refused() {
    let head = "module P(V2f);\nmodule Q(V2f);\nring L-system: 1;\nderivation length: 1;\n";
    let e = refused(&format!(
        "{head}Axiom: P(V2f(0,0)) P(V2f(1,0)) P(V2f(1,1));\nP(v) -> P(v + V2f(1, 0))\n"
    ));
    assert!(
        e.contains("not linear") && e.contains("analyze needs"),
        "{e}"
    );
    let e = refused(&format!(
        "{head}Axiom: P(V2f(0,0)) Q(V2f(1,0)) P(V2f(1,1));\nP(v) -> P(v)\n"
    ));
    assert!(e.contains("two modules"), "{e}");
    let e = refused(&format!(
        "{head}Axiom: P(V2f(0,0)) P(V2f(1,0)) P(V2f(1,1));\nP(v) -> P(v) Q(v)\n"
    ));
    assert!(e.contains("beside the points"), "{e}");
    let e = refused(&format!(
        "{head}Axiom: P(V2f(0,0)) P(V2f(1,0)) P(V2f(1,1));\n\
         P(v) : {{ if (v.x > 0.5) produce P(v) P(v); else produce P(v); }}\n"
    ));
    assert!(e.contains("analyze needs"), "{e}");
}
