//! `subgram analyze` against published values. Every expected number is
//! computed here from a published formula or a matrix built here from the
//! scheme's masks, never taken from subgram's output.

use std::f64::consts::{PI, TAU};

use nalgebra::DMatrix;
use subgram::analyze::{analyze, analyze_at, CurveReport, Scheme, SurfaceReport};

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

/// A surface grammar's report at the valences `ns` only.
fn surface_at(file: &str, ns: &[usize]) -> SurfaceReport {
    match analyze_at(&lsys(file), &[], ns)
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
    let ns = valences(&(3..=12).collect::<Vec<_>>(), &[3, 4, 7]);
    let s = surface_at("surfaces/loop.lsys", &ns);
    assert_eq!(s.faces, "triangles");
    let got: Vec<usize> = s.valences.iter().map(|v| v.n).collect();
    assert_eq!(got, ns);
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
            let want = if (w.i, w.j) == (0.0, 0.0) {
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
            let centre = t.iter().find(|w| (w.i, w.j) == (0.0, 0.0)).unwrap().weight;
            let ring: f64 = t
                .iter()
                .filter(|w| (w.i, w.j) != (0.0, 0.0))
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
    let s = surface_at(
        "surfaces/catmull-clark.lsys",
        &valences(&[3, 4, 5, 7, 12], &[3, 4]),
    );
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
            let want = match (w.i as usize, w.j as usize) {
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
/// every curve scheme that refines is affine-invariant, and so is every
/// surface grammar (but the adaptive one, not measured) at valences 3, 4
/// and 12 (in a debug build at 4 alone; the command covers 3..12).
#[test]
fn every_scheme_in_lsystems_is_analysed() {
    let ns = valences(&[3, 4, 12], &[4]);
    for dir in ["curves", "surfaces"] {
        let mut files: Vec<_> = std::fs::read_dir(lsys(dir))
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "lsys"))
            .collect();
        files.sort();
        assert!(!files.is_empty());
        for f in files {
            let r = analyze_at(&f, &[], &ns).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
            assert!(!r.text().is_empty());
            let json: serde_json::Value = serde_json::from_str(&r.json()).unwrap();
            assert_eq!(
                json["kind"],
                if dir == "curves" { "curve" } else { "surface" }
            );
            match &r.scheme {
                Scheme::Curve(c) => assert!(c.affine, "{}", f.display()),
                // Every surface grammar but the adaptive one is measured at
                // every valence, and is affine-invariant there; the JSON
                // carries the local matrix.
                Scheme::Surface(s) if !f.ends_with("four-eight-adaptive.lsys") => {
                    assert_eq!(s.valences.len(), ns.len(), "{}", f.display());
                    let dual = ["doo-sabin.lsys", "peters.lsys"]
                        .iter()
                        .any(|d| f.ends_with(d));
                    assert_eq!(json["around"], if dual { "face" } else { "vertex" });
                    for (k, v) in s.valences.iter().enumerate() {
                        assert!(v.skipped.is_none() && v.affine, "{} {}", f.display(), v.n);
                        assert_eq!(
                            json["valences"][k]["matrix"].as_array().unwrap().len(),
                            v.size
                        );
                        assert_eq!(
                            json["valences"][k]["places"].as_array().unwrap().len(),
                            v.size
                        );
                    }
                }
                Scheme::Surface(_) => {}
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
    let tmp = scratch("analyze");
    let dir = tmp.path();
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

/// The measured local matrix, and the index of each of its places.
fn local_matrix(v: &subgram::analyze::surface::Valence) -> (DMatrix<f64>, Vec<(usize, f64, f64)>) {
    let m = DMatrix::from_fn(v.size, v.size, |r, c| v.matrix[r][c]);
    let places = v.places.iter().map(|p| (p.sector, p.i, p.j)).collect();
    (m, places)
}

/// `got` equals `want` entry by entry, where `index` says which row and
/// column of `want` each place of `got` is.
fn assert_same_matrix(
    what: &str,
    got: &DMatrix<f64>,
    want: &DMatrix<f64>,
    index: impl Fn(usize) -> usize,
) {
    assert_eq!(got.nrows(), want.nrows(), "{what}: size");
    for r in 0..got.nrows() {
        for c in 0..got.ncols() {
            let (g, w) = (got[(r, c)], want[(index(r), index(c))]);
            assert!(
                (g - w).abs() < 1e-12,
                "{what}: entry ({r}, {c}) is {g}, the masks give {w}"
            );
        }
    }
}

fn sorted_moduli(values: impl Iterator<Item = f64>) -> Vec<f64> {
    let mut e: Vec<f64> = values.collect();
    e.sort_by(|a, b| b.total_cmp(a));
    e
}

/// 4-8 subdivision with paper 004's smoothing (four-eight.lsys) and the
/// C4 box spline on any mesh (c4.lsys) around a vertex of k quads (valence
/// 2k in the triangles), k = 3..12: two bisections come back to the
/// lattice at half the spacing, and the local matrix on the 2-ring is the
/// one built in tests/it/surface_c4.rs from paper 004's masks (the face
/// mask, the factorised vertex mask with the old neighbours' average),
/// entry by entry, so its spectrum is too. At k = 4 the spectrum is the
/// four-directional box spline's: 1, 1/2, 1/2, 1/4, 1/4, 1/4 (paper 004:
/// the two-scale symbol (1+z1)(1+z2)(1+z1 z2)(1+z1/z2) reproduces
/// polynomials of degree 0 and 1, and the quadratic ones give 1/4).
#[test]
fn four_eight_and_c4_at_every_valence() {
    use crate::surface_c4;
    for file in ["surfaces/c4.lsys", "surfaces/four-eight.lsys"] {
        let ns = valences(&[3, 4, 5, 7, 12], &[3, 4]);
        let s = surface_at(file, &ns);
        assert_eq!((s.faces.as_str(), s.around.as_str()), ("quads", "vertex"));
        let got: Vec<usize> = s.valences.iter().map(|v| v.n).collect();
        assert_eq!(got, ns, "{file}");
        for v in &s.valences {
            let k = v.n;
            assert!(v.skipped.is_none(), "{file} {k}: {:?}", v.skipped);
            assert_eq!((v.steps, v.scale, v.rings), (2, 2, 2), "{file} {k}");
            assert_eq!(v.size, 6 * k + 1, "{file} {k}: the 2-ring of quads");
            let (m, places) = local_matrix(v);
            let f = surface_c4::fan(k, 4);
            let ls = surface_c4::labels(k, 2);
            let want = surface_c4::mask_matrix(&f, 2);
            let index = |a: usize| {
                let (t, i, j) = places[a];
                ls.iter()
                    .position(|&l| l == (t, i as usize, j as usize))
                    .unwrap_or_else(|| panic!("{file} {k}: place {:?}", places[a]))
            };
            assert_same_matrix(&format!("{file} {k}"), &m, &want, index);
            assert!(v.affine && v.reif, "{file} {k}");
            let built = sorted_moduli(surface_c4::spectrum(&want).iter().map(|z| z.norm()));
            for (e, w) in v.eigenvalues.iter().zip(&built).take(4) {
                assert!(
                    (e.modulus - w).abs() < 1e-9,
                    "{file} {k}: {e:?} against {w}"
                );
            }
        }
        let regular = &s.valences[1];
        assert_eq!(regular.n, 4);
        for (e, w) in regular
            .eigenvalues
            .iter()
            .zip([1.0, 0.5, 0.5, 0.25, 0.25, 0.25])
        {
            assert!(
                (e.re - w).abs() < 1e-9 && e.im.abs() < 1e-9,
                "{file}: {e:?} against {w}"
            );
        }
    }
}

/// Kobbelt's √3 subdivision ("√3-subdivision", SIGGRAPH 2000) on the
/// 1-ring (centre p, ring p_0 .. p_(n-1)), built here from its rules: a
/// step puts a new vertex at each triangle's centroid, q_t = (p + p_t +
/// p_(t+1)) / 3, and moves p to (1 - α_n) p + α_n / n Σ p_t with α_n =
/// (4 - 2 cos(2π/n)) / 9; after the flips p's new ring is q_0 .. q_(n-1),
/// so the second step reads the same 1-ring, and its new vertex between
/// q_(t-1) and q_t lies a third of the way along the old edge to p_t.
fn sqrt3_two_steps(n: usize) -> DMatrix<f64> {
    let alpha = (4.0 - 2.0 * (TAU / n as f64).cos()) / 9.0;
    let step = |shift: usize| {
        // Row t + 1: the centroid of p, ring vertex t + shift - 1 and
        // t + shift (shift 1: q_t between p_t and p_(t+1); shift 0: the
        // second step's vertex between q_(t-1) and q_t).
        let mut m = DMatrix::zeros(n + 1, n + 1);
        m[(0, 0)] = 1.0 - alpha;
        for t in 0..n {
            m[(0, t + 1)] = alpha / n as f64;
            m[(t + 1, 0)] = 1.0 / 3.0;
            m[(t + 1, (t + shift + n - 1) % n + 1)] += 1.0 / 3.0;
            m[(t + 1, (t + shift) % n + 1)] += 1.0 / 3.0;
        }
        m
    };
    step(0) * step(1)
}

/// √3 (sqrt3.lsys and sqrt3-printed.lsys): two steps make the triadic
/// lattice (new vertices at a third of the spacing, the lattice turned
/// back), and their local matrix on the 1-ring is the one built here from
/// Kobbelt's rules, entry by entry, at every valence 3..12. Its
/// eigenvalues, derived here from the built matrix's Fourier blocks: the
/// ring's k-th mode is multiplied by (1 + ω^k)/3 a step and turned back
/// by ω^-k, so two steps give |1 + ω^k|^2 / 9 = (2 + 2 cos(2πk/n)) / 9;
/// the symmetric block gives 1 and (2/3 - α_n)^2. With Kobbelt's α_n,
/// 2/3 - α_n is exactly (2 + 2 cos(2π/n)) / 9: the symmetric eigenvalue
/// is the square of the subdominant one.
#[test]
fn sqrt3_two_steps_are_kobbelts() {
    for file in ["surfaces/sqrt3.lsys", "surfaces/sqrt3-printed.lsys"] {
        let s = surface_at(file, &[3, 4, 5, 6, 7, 12]);
        assert_eq!(
            (s.faces.as_str(), s.around.as_str()),
            ("triangles", "vertex")
        );
        assert_eq!(s.valences.len(), 6, "{file}");
        for v in &s.valences {
            let n = v.n;
            assert!(v.skipped.is_none(), "{file} {n}: {:?}", v.skipped);
            assert_eq!(
                (v.steps, v.scale, v.rings, v.size),
                (2, 3, 1, n + 1),
                "{file} {n}"
            );
            let (m, places) = local_matrix(v);
            let index = |a: usize| match places[a] {
                (_, i, j) if (i, j) == (0.0, 0.0) => 0,
                (t, i, j) if (i, j) == (1.0, 0.0) => t + 1,
                p => panic!("{file} {n}: place {p:?} outside the 1-ring"),
            };
            let want = sqrt3_two_steps(n);
            assert_same_matrix(&format!("{file} {n}"), &m, &want, index);
            let built = sorted_moduli(want.complex_eigenvalues().iter().map(|z| z.norm()));
            let l1 = (2.0 + 2.0 * (TAU / n as f64).cos()) / 9.0;
            let alpha = (4.0 - 2.0 * (TAU / n as f64).cos()) / 9.0;
            assert!((built[1] - l1).abs() < 1e-12 && (2.0 / 3.0 - alpha - l1).abs() < 1e-12);
            assert!(v.affine && v.reif, "{file} {n}");
            for k in [1, 2] {
                assert!((v.eigenvalues[k].re - l1).abs() < 1e-9, "{file} {n}");
            }
            for (e, w) in v.eigenvalues.iter().zip(&built) {
                assert!(
                    (e.modulus - w).abs() < 1e-9,
                    "{file} {n}: {e:?} against {w}"
                );
            }
            // The symmetric block's (2/3 - α_n)^2 = λ1^2 is in the
            // spectrum of the built matrix, and so of the measured one.
            assert!(built.iter().any(|e| (e - l1 * l1).abs() < 1e-9), "{n}");
        }
    }
}

/// The moduli of a symmetric matrix's eigenvalues (the circulants here
/// are symmetric; nalgebra's general Schur iteration has no bound and
/// stalls on their many equal eigenvalues).
fn symmetric_moduli(m: &DMatrix<f64>) -> impl Iterator<Item = f64> {
    assert!((m - m.transpose()).abs().max() < 1e-15);
    m.clone()
        .symmetric_eigen()
        .eigenvalues
        .iter()
        .map(|x| x.abs())
        .collect::<Vec<_>>()
        .into_iter()
}

/// The central n-gon's corners after a dual step, from the old corners:
/// row t (new corner t) has `weight(d)` on old corner t + d.
fn circulant(n: usize, weight: impl Fn(usize) -> f64) -> DMatrix<f64> {
    DMatrix::from_fn(n, n, |r, c| weight((c + n - r) % n))
}

/// Doo-Sabin (doo-sabin.lsys) around an n-sided face: the new corner of
/// corner t is the average of corner t, the midpoints of the two edges at
/// it and the face's centroid (the file's averaging form), a circulant
/// built here, entry by entry, n = 3..12. At n = 4 it is Doo and Sabin's
/// mask 9/16, 3/16, 1/16, 3/16, and their weights α_0 = 1/4 + 5/(4n),
/// α_i = (3 + 2 cos(2πi/n))/(4n) (Doo and Sabin, "Behaviour of recursive
/// division surfaces near extraordinary points", CAD 10, 1978), whose
/// eigenvalues are 1, 1/2, 1/2, 1/4, ...; at other n the file's
/// averaging form is not α's (its comment says so): its eigenvalues are
/// (2 + cos(2πk/n))/4, derived here from the circulant.
#[test]
fn doo_sabin_around_a_face() {
    let ns = valences(&[3, 4, 5, 6, 12], &[3, 4, 5]);
    let s = surface_at("surfaces/doo-sabin.lsys", &ns);
    assert_eq!((s.faces.as_str(), s.around.as_str()), ("quads", "face"));
    assert_eq!(s.valences.len(), ns.len());
    for v in &s.valences {
        let n = v.n;
        let nf = n as f64;
        assert!(v.skipped.is_none(), "{n}: {:?}", v.skipped);
        assert_eq!((v.steps, v.scale, v.rings, v.size), (1, 2, 1, n), "{n}");
        let (m, places) = local_matrix(v);
        let index = |a: usize| {
            let (t, i, j) = places[a];
            assert_eq!((i, j), (0.25, 0.25), "{n}: a corner of the central n-gon");
            t
        };
        let averaging = circulant(n, |d| {
            let near = if d == 1 || d == n - 1 { 1.0 / 8.0 } else { 0.0 };
            let own = if d == 0 { 0.5 } else { 0.0 };
            own + near + 1.0 / (4.0 * nf)
        });
        assert_same_matrix(&format!("doo-sabin {n}"), &m, &averaging, index);
        let alpha = circulant(n, |d| {
            let a = (3.0 + 2.0 * (TAU * d as f64 / nf).cos()) / (4.0 * nf);
            if d == 0 {
                0.25 + 5.0 / (4.0 * nf)
            } else {
                a
            }
        });
        let l1 = (2.0 + (TAU / nf).cos()) / 4.0;
        let built = sorted_moduli(symmetric_moduli(&averaging));
        assert!((built[1] - l1).abs() < 1e-12);
        assert!(v.affine && v.reif, "{n}");
        for (e, w) in v.eigenvalues.iter().zip(&built) {
            assert!((e.modulus - w).abs() < 1e-9, "{n}: {e:?} against {w}");
        }
        let published = sorted_moduli(symmetric_moduli(&alpha));
        assert!((published[1] - 0.5).abs() < 1e-12 && (published[2] - 0.5).abs() < 1e-12);
        if n == 4 {
            assert!((&alpha - &averaging).abs().max() < 1e-15);
            for (e, w) in v.eigenvalues.iter().zip([1.0, 0.5, 0.5, 0.25]) {
                assert!((e.re - w).abs() < 1e-9, "{e:?} against {w}");
            }
        } else {
            assert!((v.eigenvalues[1].re - 0.5).abs() > 1e-3, "{n}");
        }
        // The next ring of corners adds nothing above λ1.
        let w = v.wider.as_ref().expect("a wider invariant neighbourhood");
        assert_eq!(w.size, 4 * n);
        assert!(w.reif, "{n}");
        assert!((w.eigenvalues[1].re - l1).abs() < 1e-9, "{n}");
    }
}

/// Peters and Reif's scheme (peters.lsys, one step = two mid-edge steps)
/// around an n-sided face: the new corner of corner b is (a + 2b + c)/4,
/// a and c b's neighbours in the face (the file's rule), a circulant built
/// here, entry by entry; its eigenvalues are (1 + cos(2πk/n))/2. Reif's
/// check holds on the face, and on the face with the next ring of corners
/// except at n = 3, where the face's λ1 = 1/4 is not above what the ring
/// adds (1/4 again at every n here): the simple check does not show the
/// surface C1 around a triangle (the file's comment and the README say
/// so).
#[test]
fn peters_reif_around_a_face() {
    let ns = valences(&[3, 4, 5, 6, 12], &[3, 4, 5]);
    let s = surface_at("surfaces/peters.lsys", &ns);
    assert_eq!(s.around, "face");
    assert_eq!(s.valences.len(), ns.len());
    for v in &s.valences {
        let n = v.n;
        assert!(v.skipped.is_none(), "{n}: {:?}", v.skipped);
        assert_eq!((v.steps, v.scale, v.rings, v.size), (1, 2, 1, n), "{n}");
        let (m, places) = local_matrix(v);
        let index = |a: usize| places[a].0;
        let built = circulant(n, |d| match d {
            0 => 0.5,
            d if d == 1 || d == n - 1 => 0.25,
            _ => 0.0,
        });
        assert_same_matrix(&format!("peters {n}"), &m, &built, index);
        let l1 = (1.0 + (TAU / n as f64).cos()) / 2.0;
        let moduli = sorted_moduli(symmetric_moduli(&built));
        assert!((moduli[1] - l1).abs() < 1e-12);
        assert!(v.affine && v.reif, "{n}");
        assert!((v.eigenvalues[1].re - l1).abs() < 1e-9, "{n}");
        let w = v.wider.as_ref().expect("a wider invariant neighbourhood");
        assert_eq!(w.size, 4 * n);
        assert_eq!(w.reif, n != 3, "{n}: {:?}", w.eigenvalues);
        if n == 3 {
            assert!((w.eigenvalues[3].modulus - l1).abs() < 1e-9);
        }
    }
    assert!(
        s.notes.iter().any(|t| t.contains("valence 3")),
        "{:?}",
        s.notes
    );
}

/// Adaptive 4-8 (four-eight-adaptive.lsys): which blocks split depends on
/// the positions, so there is no subdivision matrix; analyze says so in a
/// note and measures nothing.
#[test]
fn adaptive_grammar_is_not_a_linear_scheme() {
    let s = surface("surfaces/four-eight-adaptive.lsys");
    assert!(s.valences.is_empty());
    assert!(
        s.notes
            .iter()
            .any(|t| t.contains("adaptive") && t.contains("not one linear map")),
        "{:?}",
        s.notes
    );
    let r = analyze(&lsys("surfaces/four-eight-adaptive.lsys"), &[]).unwrap();
    assert!(r.text().contains("not one linear map"));
}

/// The characteristic map's net: λ1's eigenspace is the first rotational
/// Fourier mode, so (in any basis, made round) the centre of Loop's fan
/// is at the origin and its first ring, like the corners of Doo-Sabin's
/// central n-gon, is a regular n-gon turning once around it, 2π/n a
/// corner, all the same way.
#[test]
fn characteristic_nets_turn_once_around_the_centre() {
    for (file, inner) in [
        ("surfaces/loop.lsys", (1.0, 0.0)),
        ("surfaces/doo-sabin.lsys", (0.25, 0.25)),
    ] {
        let s = surface_at(file, &[3, 5, 7]);
        for v in &s.valences {
            let n = v.n;
            let c = v.characteristic.as_ref().expect("a characteristic net");
            assert_eq!(c.places.len(), c.points.len());
            assert!(!c.edges.is_empty());
            let mut ring: Vec<(usize, [f64; 2])> = Vec::new();
            for (p, q) in c.places.iter().zip(&c.points) {
                if (p.i, p.j) == (0.0, 0.0) {
                    assert!(
                        q[0].abs() < 1e-9 && q[1].abs() < 1e-9,
                        "{file} {n}: centre {q:?}"
                    );
                } else if (p.i, p.j) == inner {
                    ring.push((p.sector, *q));
                }
            }
            ring.sort_by_key(|r| r.0);
            assert_eq!(ring.len(), n, "{file} {n}");
            let r0 = (ring[0].1[0].powi(2) + ring[0].1[1].powi(2)).sqrt();
            let mut turns = Vec::new();
            for t in 0..n {
                let (a, b) = (ring[t].1, ring[(t + 1) % n].1);
                let r = (a[0].powi(2) + a[1].powi(2)).sqrt();
                assert!(
                    (r - r0).abs() < 1e-9 * r0.max(1.0),
                    "{file} {n}: radius {r} and {r0}"
                );
                let turn = (a[0] * b[1] - a[1] * b[0]).atan2(a[0] * b[0] + a[1] * b[1]);
                turns.push(turn);
            }
            let step = TAU / n as f64;
            assert!(
                turns.iter().all(|t| (t - step).abs() < 1e-9)
                    || turns.iter().all(|t| (t + step).abs() < 1e-9),
                "{file} {n}: {turns:?}"
            );
        }
    }
}
