//! Curve schemes: the matrix of one step measured by impulses through the
//! engine, then the stencils, the mask and its factors, polynomial
//! reproduction and generation, and a Hölder estimate from the difference
//! scheme (Rioul 1992).

use nalgebra::DMatrix;
use serde::Serialize;

use super::num::{divide, fraction, multiply, spectral_radius};
use crate::lang::Sym;
use crate::{Curve, Deadline, Derivation, DeriveOptions, Error, Value, Word};

/// Old points in a probe word.
pub const PROBE_POINTS: usize = 24;
/// Steps of the difference scheme whose norms bound the Hölder exponent
/// from below.
pub const MAX_NORM_STEPS: usize = 12;
/// Length of the products of transition matrices whose spectral radii
/// bound it from above.
pub const MAX_PRODUCT_STEPS: usize = 8;
/// The largest degree of polynomial reproduction looked for.
pub const MAX_DEGREE: usize = 10;
/// Weights closer than this are equal.
const TOL: f64 = 1e-9;

/// What `analyze` says about a curve scheme.
#[derive(Clone, Debug, Serialize)]
pub struct CurveReport {
    /// The point module's name.
    pub module: String,
    /// A ring (closed curve), or an open word (with endmarkers when the
    /// axiom has them).
    pub closed: bool,
    /// 2 or 3: the coordinates of a point.
    pub dimension: usize,
    /// Old points of the probe word, and the new points one step made.
    pub probe_points: usize,
    pub new_points: usize,
    /// New points per old point (2 for a binary scheme); `None` for a
    /// scheme that makes one point of several (`reduction` of them).
    pub arity: Option<usize>,
    pub reduction: Option<usize>,
    /// One stencil per coset: new point `arity·i + coset` from the old
    /// points `i + offset` (for a reduction, new point `i` from the old
    /// points `reduction·i + offset`).
    pub stencils: Vec<Stencil>,
    /// An open curve's rows that do not follow the interior stencils.
    pub boundary: Vec<BoundaryRow>,
    /// Every stencil's weights sum to one.
    pub affine: bool,
    /// The mask's width in new points (a reduction: the stencil's width in
    /// old points).
    pub support: usize,
    /// Some stencil keeps an old point as it is.
    pub interpolating: bool,
    pub mask: Option<Mask>,
    /// The largest degree d such that samples of every polynomial of
    /// degree at most d give samples of the same polynomial.
    pub reproduction_degree: Option<usize>,
    /// The largest degree d with (1+z)^(d+1) dividing the mask.
    pub generation_degree: Option<usize>,
    pub smoothness: Option<Smoothness>,
    pub notes: Vec<String>,
}

/// One coset's weights.
#[derive(Clone, Debug, Serialize)]
pub struct Stencil {
    pub coset: usize,
    pub weights: Vec<Weight>,
    pub sum: f64,
    pub sum_is_one: bool,
}

/// A weight on the old point at `offset`.
#[derive(Clone, Debug, Serialize)]
pub struct Weight {
    pub offset: i64,
    pub value: f64,
    pub fraction: String,
}

/// A boundary row of an open scheme: `row` counts from the start (0, 1,
/// …) at the left end and from the end (-1, -2, …) at the right; the
/// offsets are old points counted the same way.
#[derive(Clone, Debug, Serialize)]
pub struct BoundaryRow {
    pub end: String,
    pub row: i64,
    pub weights: Vec<Weight>,
    pub sum: f64,
}

/// The mask a(z) = sum of a_k z^k, k from `first`, and its factors.
#[derive(Clone, Debug, Serialize)]
pub struct Mask {
    pub first: i64,
    pub coefficients: Vec<f64>,
    pub fractions: Vec<String>,
    /// The largest k with (1 + z + … + z^(arity-1))^k dividing a(z).
    pub factor_power: usize,
    /// a(z) / (1 + … + z^(arity-1))^k / z^first, lowest power first.
    pub quotient: Vec<f64>,
    pub quotient_fractions: Vec<String>,
}

/// Rioul's estimate of the Hölder exponent α of the limit curves.
#[derive(Clone, Debug, Serialize)]
pub struct Smoothness {
    /// α ≥ lower: k - 1 - log2 of the best j-th root of the norm of j
    /// steps of the difference scheme, j ≤ `norm_steps`.
    pub lower: f64,
    pub norm_steps: usize,
    /// α ≤ upper: k - 1 - log2 of the largest j-th root of the spectral
    /// radius of a product of j transition matrices, j ≤ `product_steps`.
    pub upper: Option<f64>,
    pub product_steps: usize,
    /// The largest n with lower > n: the curves are C^n.
    pub continuity: Option<usize>,
}

struct Probe<'c> {
    curve: &'c Curve,
    path: String,
    point: Sym,
    ends: Option<Sym>,
    dimension: usize,
    closed: bool,
    deadline: Deadline,
}

fn refuse(path: &str, message: String) -> Error {
    Error::File {
        path: path.to_string(),
        line: None,
        message,
    }
}

const NEEDS: &str = "analyze needs a subdivision scheme: an axiom of points of one module \
                     with one V2f, V2d, V3f or V3d parameter (and `#` endmarkers for an open \
                     curve), and rules that make points of that module as fixed affine \
                     combinations of old points";

impl Probe<'_> {
    fn options(&self) -> DeriveOptions {
        DeriveOptions::default()
            .with_steps(1)
            .with_deadline(Some(self.deadline))
    }

    /// One step of the program on `points` (one coordinate array each).
    fn step(&self, points: &[Vec<f64>]) -> Result<Vec<Vec<f64>>, Error> {
        let p = &self.curve.program;
        let mut d = Derivation::new(p, self.options()).map_err(|e| self.curve.error(e))?;
        let mut w = Word::new();
        let ends = if self.closed { None } else { self.ends };
        if let Some(e) = ends {
            w.push_raw(e, &[]);
        }
        for x in points {
            w.push_raw(self.point, x);
        }
        if let Some(e) = ends {
            w.push_raw(e, &[]);
        }
        d.word = w;
        d.next_step().map_err(|e| self.curve.error(e))?;
        let mut out = Vec::new();
        for i in 0..d.word.len() {
            let s = d.word.sym(i);
            if s == self.point {
                out.push(d.word.data(i).to_vec());
            } else if Some(s) != self.ends {
                return Err(refuse(
                    &self.path,
                    format!(
                        "one step makes a `{}` module beside the points; {NEEDS}",
                        p.alphabet.name(s)
                    ),
                ));
            }
        }
        Ok(out)
    }
}

/// The matrix of one step: column j is the step applied to the impulse at
/// old point j (x coordinate), checked for linearity on other data.
fn measure(probe: &Probe, n: usize) -> Result<DMatrix<f64>, Error> {
    let dim = probe.dimension;
    let zero = vec![vec![0.0; dim]; n];
    let z = probe.step(&zero)?;
    if z.iter().flatten().any(|x| x.abs() > TOL) {
        return Err(refuse(
            &probe.path,
            format!("the step moves points at the origin: not linear. {NEEDS}"),
        ));
    }
    let rows = z.len();
    if rows == 0 {
        return Err(refuse(
            &probe.path,
            format!("the step leaves no points. {NEEDS}"),
        ));
    }
    let mut m = DMatrix::zeros(rows, n);
    for j in 0..n {
        let mut x = zero.clone();
        x[j][0] = 1.0;
        let out = probe.step(&x)?;
        if out.len() != rows {
            return Err(refuse(
                &probe.path,
                format!("the number of new points depends on the coordinates. {NEEDS}"),
            ));
        }
        for (r, p) in out.iter().enumerate() {
            if p[1..].iter().any(|y| y.abs() > TOL) {
                return Err(refuse(
                    &probe.path,
                    format!("an x coordinate moves a y coordinate. {NEEDS}"),
                ));
            }
            m[(r, j)] = p[0];
        }
    }
    // Linearity on other data: a fixed pseudo-random polygon.
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut next = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    let data: Vec<Vec<f64>> = (0..n).map(|_| (0..dim).map(|_| next()).collect()).collect();
    let out = probe.step(&data)?;
    for c in 0..dim {
        let x = nalgebra::DVector::from_iterator(n, data.iter().map(|p| p[c]));
        let want = &m * x;
        if out.len() != rows || (0..rows).any(|r| (out[r][c] - want[r]).abs() > 1e-7) {
            return Err(refuse(
                &probe.path,
                format!("the step is not linear in the points. {NEEDS}"),
            ));
        }
    }
    Ok(m)
}

fn weights(pairs: impl IntoIterator<Item = (i64, f64)>) -> Vec<Weight> {
    let mut w: Vec<Weight> = pairs
        .into_iter()
        .filter(|(_, v)| v.abs() > TOL)
        .map(|(offset, value)| Weight {
            offset,
            value,
            fraction: fraction(value),
        })
        .collect();
    w.sort_by_key(|w| w.offset);
    w
}

fn stencil(coset: usize, weights: Vec<Weight>) -> Stencil {
    let sum = weights.iter().map(|w| w.value).sum::<f64>();
    Stencil {
        coset,
        weights,
        sum,
        sum_is_one: (sum - 1.0).abs() <= TOL,
    }
}

/// Analyses the curve scheme `curve` (its file `path`, for messages).
pub fn analyze(curve: &Curve, path: &str, deadline: Deadline) -> Result<CurveReport, Error> {
    let p = &curve.program;
    let opts = DeriveOptions::default()
        .with_steps(1)
        .with_deadline(Some(deadline));
    let d = Derivation::new(p, opts).map_err(|e| curve.error(e))?;
    let mut point: Option<(Sym, usize)> = None;
    let mut ends = None;
    for i in 0..d.word.len() {
        let s = d.word.sym(i);
        let name = p.alphabet.name(s);
        if name == "#" {
            ends = Some(s);
            continue;
        }
        let dim = match d.word.values(i, &p.alphabet, &p.structs).as_slice() {
            [Value::V2(_)] => 2,
            [Value::V3(_)] => 3,
            _ => {
                return Err(refuse(
                    path,
                    format!("the axiom has a module `{name}` that is not a point. {NEEDS}"),
                ))
            }
        };
        match point {
            None => point = Some((s, dim)),
            Some((q, _)) if q == s => {}
            Some((q, _)) => {
                return Err(refuse(
                    path,
                    format!(
                        "the axiom has points of two modules, `{}` and `{name}`. {NEEDS}",
                        p.alphabet.name(q)
                    ),
                ))
            }
        }
    }
    let Some((point, dimension)) = point else {
        return Err(refuse(path, format!("the axiom has no points. {NEEDS}")));
    };
    let probe = Probe {
        curve,
        path: path.to_string(),
        point,
        ends,
        dimension,
        closed: d.ring,
        deadline,
    };
    let n = PROBE_POINTS;
    let m = measure(&probe, n)?;
    let mut notes = Vec::new();
    let module = p.alphabet.name(point).to_string();
    let rows = m.nrows();
    let base = |arity: Option<usize>, reduction: Option<usize>| CurveReport {
        module: module.clone(),
        closed: probe.closed,
        dimension,
        probe_points: n,
        new_points: rows,
        arity,
        reduction,
        stencils: Vec::new(),
        boundary: Vec::new(),
        affine: false,
        support: 0,
        interpolating: false,
        mask: None,
        reproduction_degree: None,
        generation_degree: None,
        smoothness: None,
        notes: Vec::new(),
    };
    let not_uniform = || {
        refuse(
            path,
            format!(
                "the step is not the same stencil at every point ({n} points gave {rows}). {NEEDS}"
            ),
        )
    };
    let near = |a: f64, b: f64| (a - b).abs() <= TOL;
    if probe.closed && rows < n {
        // A reduction: one new point from `red` old ones.
        if !n.is_multiple_of(rows) {
            return Err(not_uniform());
        }
        let red = n / rows;
        let wrap = |j: i64| {
            let k = j.rem_euclid(n as i64);
            if k > n as i64 / 2 {
                k - n as i64
            } else {
                k
            }
        };
        let s: Vec<(i64, f64)> = (0..n).map(|j| (wrap(j as i64), m[(0, j)])).collect();
        for i in 0..rows {
            for j in 0..n {
                let o = wrap(j as i64 - (red * i) as i64);
                let want = s.iter().find(|(k, _)| *k == o).map_or(0.0, |x| x.1);
                if !near(m[(i, j)], want) {
                    return Err(not_uniform());
                }
            }
        }
        let st = stencil(0, weights(s));
        let mut r = base(None, Some(red));
        r.affine = st.sum_is_one;
        r.support = match (st.weights.first(), st.weights.last()) {
            (Some(a), Some(b)) => (b.offset - a.offset + 1) as usize,
            _ => 0,
        };
        r.stencils = vec![st];
        r.notes.push(format!(
            "a reduction ({red} old points to 1 new): no mask, degrees or smoothness"
        ));
        return Ok(r);
    }
    // The mask a_k: new point k (relative to `arity`·j) from old point j.
    let (arity, mask, boundary) = if probe.closed {
        if !rows.is_multiple_of(n) {
            return Err(not_uniform());
        }
        let arity = rows / n;
        let wrap = |k: i64| {
            let k = k.rem_euclid(rows as i64);
            if k > rows as i64 / 2 {
                k - rows as i64
            } else {
                k
            }
        };
        let a: Vec<(i64, f64)> = (0..rows).map(|r| (wrap(r as i64), m[(r, 0)])).collect();
        let at = |k: i64| a.iter().find(|x| x.0 == k).map_or(0.0, |x| x.1);
        for j in 0..n {
            for r in 0..rows {
                if !near(m[(r, j)], at(wrap(r as i64 - (arity * j) as i64))) {
                    return Err(not_uniform());
                }
            }
        }
        if a.iter()
            .any(|(k, v)| v.abs() > TOL && k.unsigned_abs() as usize * 3 > rows)
        {
            return Err(refuse(
                path,
                format!("the stencils reach further than the probe of {n} points can tell"),
            ));
        }
        (arity, a, Vec::new())
    } else {
        // The interior: the middle column, and the next one `arity` rows on.
        let c = n / 2;
        let first_nz = |j: usize| (0..rows).find(|&r| m[(r, j)].abs() > TOL).map(|r| r as i64);
        let (Some(f0), Some(f1)) = (first_nz(c), first_nz(c + 1)) else {
            return Err(not_uniform());
        };
        if f1 <= f0 {
            return Err(not_uniform());
        }
        let arity = (f1 - f0) as usize;
        let a: Vec<(i64, f64)> = (0..rows)
            .map(|r| (r as i64 - (arity * c) as i64, m[(r, c)]))
            .collect();
        let at = |k: i64| a.iter().find(|x| x.0 == k).map_or(0.0, |x| x.1);
        let interior =
            |r: usize| (0..n).all(|j| near(m[(r, j)], at(r as i64 - (arity * j) as i64)));
        let mut boundary = Vec::new();
        for r in 0..rows {
            if interior(r) {
                continue;
            }
            let left = r < rows / 2;
            let pairs = (0..n).map(|j| {
                let o = if left { j as i64 } else { j as i64 - n as i64 };
                (o, m[(r, j)])
            });
            let w = weights(pairs);
            let sum = w.iter().map(|w| w.value).sum();
            boundary.push(BoundaryRow {
                end: if left { "left" } else { "right" }.into(),
                row: if left {
                    r as i64
                } else {
                    r as i64 - rows as i64
                },
                weights: w,
                sum,
            });
        }
        if boundary.len() * 2 > rows {
            return Err(not_uniform());
        }
        (arity, a, boundary)
    };
    let nz: Vec<&(i64, f64)> = mask.iter().filter(|x| x.1.abs() > TOL).collect();
    let (Some(first), Some(last)) = (nz.iter().map(|x| x.0).min(), nz.iter().map(|x| x.0).max())
    else {
        return Err(refuse(path, format!("the step makes only zeros. {NEEDS}")));
    };
    let at = |k: i64| mask.iter().find(|x| x.0 == k).map_or(0.0, |x| x.1);
    let coeffs: Vec<f64> = (first..=last).map(at).collect();
    let mut r = base(Some(arity), None);
    r.boundary = boundary;
    r.support = coeffs.len();
    // Coset c: new point arity·i + c = sum over l of a_(c + arity·l) p_(i - l).
    for c in 0..arity {
        let pairs = (first..=last)
            .filter(|k| (k - c as i64).rem_euclid(arity as i64) == 0)
            .map(|k| (-(k - c as i64) / arity as i64, at(k)));
        r.stencils.push(stencil(c, weights(pairs)));
    }
    r.affine = r.stencils.iter().all(|s| s.sum_is_one);
    r.interpolating = r
        .stencils
        .iter()
        .any(|s| s.weights.len() == 1 && near(s.weights[0].value, 1.0));
    if arity < 2 {
        r.notes
            .push("one new point per old point: not a refinement; no factors".into());
        return Ok(r);
    }
    let scale = coeffs.iter().fold(0.0f64, |x, y| x.max(y.abs()));
    let sigma = vec![1.0; arity];
    let mut quotient = coeffs.clone();
    let mut k = 0;
    while let Some(q) = divide(&quotient, &sigma, 1e-9 * scale.max(1.0)) {
        quotient = q;
        k += 1;
    }
    r.mask = Some(Mask {
        first,
        fractions: coeffs.iter().map(|&x| fraction(x)).collect(),
        coefficients: coeffs.clone(),
        factor_power: k,
        quotient_fractions: quotient.iter().map(|&x| fraction(x)).collect(),
        quotient: quotient.clone(),
    });
    if r.affine {
        r.generation_degree = k.checked_sub(1);
        r.reproduction_degree = reproduction(&coeffs, first, arity);
    } else {
        notes.push("not affine-invariant: no degrees or smoothness".to_string());
    }
    if r.affine && arity == 2 && k >= 1 {
        r.smoothness = Some(holder(&quotient, k));
    } else if r.affine && arity != 2 {
        notes.push("the smoothness estimate is made for binary schemes only".to_string());
    }
    r.notes.extend(notes);
    Ok(r)
}

/// The largest degree d such that the mask maps samples of x^e at the
/// integers to samples of the same polynomial at the new points, for
/// every e ≤ d; the new points' parameters come from the linear case.
pub fn reproduction(a: &[f64], first: i64, arity: usize) -> Option<usize> {
    let last = first + a.len() as i64 - 1;
    let m = arity as i64;
    let w = 4 * a.len() as i64 + 8;
    // New points n whose old points all lie in -w..=w.
    let lo = m * -w + last;
    let hi = m * w + first;
    let apply = |f: &dyn Fn(i64) -> f64, n: i64| -> f64 {
        (first..=last)
            .filter(|k| (n - k).rem_euclid(m) == 0)
            .map(|k| a[(k - first) as usize] * f((n - k) / m))
            .sum()
    };
    let scale = w as f64;
    // Degree 0.
    if (lo..=hi).any(|n| (apply(&|_| 1.0, n) - 1.0).abs() > 1e-9) {
        return None;
    }
    let lin: Vec<f64> = (lo..=hi)
        .map(|n| m as f64 * apply(&|j| j as f64, n) - n as f64)
        .collect();
    let shift = lin[0];
    if lin.iter().any(|s| (s - shift).abs() > 1e-9) {
        return Some(0);
    }
    let mut degree = 1;
    for d in 2..=MAX_DEGREE as i32 {
        let ok = (lo..=hi).all(|n| {
            let got = apply(&|j| (j as f64 / scale).powi(d), n);
            let want = ((n as f64 + shift) / (m as f64 * scale)).powi(d);
            (got - want).abs() <= 1e-9
        });
        if !ok {
            break;
        }
        degree = d as usize;
    }
    Some(degree)
}

/// Rioul's estimate for a binary scheme a(z) = (1+z)^k b(z):
/// q = 2^(k-1) b, α ≥ k - 1 - log2 ||S_q^j||^(1/j), and α ≤ k - 1 - log2 of
/// ρ(T_e1 … T_ej)^(1/j) over products of the transition matrices.
pub fn holder(b: &[f64], k: usize) -> Smoothness {
    let q: Vec<f64> = b.iter().map(|x| x * 2f64.powi(k as i32 - 1)).collect();
    let base = k as f64 - 1.0;
    let mut lower = f64::NEG_INFINITY;
    let mut qj = q.clone();
    let mut norm_steps = 0;
    for j in 1..=MAX_NORM_STEPS {
        if j > 1 {
            let step = 1usize << (j - 1);
            if qj.len() + (q.len() - 1) * step > 1 << 20 {
                break;
            }
            let mut up = vec![0.0; (q.len() - 1) * step + 1];
            for (i, x) in q.iter().enumerate() {
                up[i * step] = *x;
            }
            qj = multiply(&qj, &up);
        }
        let period = 1usize << j;
        let mut worst = 0.0f64;
        for r in 0..period.min(qj.len()) {
            let s: f64 = qj.iter().skip(r).step_by(period).map(|x| x.abs()).sum();
            worst = worst.max(s);
        }
        let rho = worst.powf(1.0 / j as f64);
        lower = lower.max(base - rho.log2());
        norm_steps = j;
    }
    // Transition matrices (T_e)_(i, l) = q_(2i - l + e), i, l < L.
    let len = q.len().saturating_sub(1).max(1);
    let upper = (len <= 32).then(|| {
        let qa = |i: i64| {
            if i < 0 || i as usize >= q.len() {
                0.0
            } else {
                q[i as usize]
            }
        };
        let t: Vec<DMatrix<f64>> = (0..2)
            .map(|e| DMatrix::from_fn(len, len, |i, l| qa(2 * i as i64 - l as i64 + e)))
            .collect();
        let mut best = 0.0f64;
        let mut products = vec![DMatrix::<f64>::identity(len, len)];
        for j in 1..=MAX_PRODUCT_STEPS {
            products = products
                .iter()
                .flat_map(|p| t.iter().map(move |te| p * te))
                .collect();
            for p in &products {
                // A product whose eigenvalues do not converge bounds nothing.
                if let Some(r) = spectral_radius(p) {
                    best = best.max(r.powf(1.0 / j as f64));
                }
            }
        }
        base - best.log2()
    });
    let continuity = (lower > 0.0).then(|| {
        let l = (lower * 1e9).round() / 1e9;
        l.ceil() as usize - 1
    });
    Smoothness {
        lower,
        norm_steps,
        upper,
        product_steps: MAX_PRODUCT_STEPS,
        continuity,
    }
}
