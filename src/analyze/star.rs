//! Limit and tangent stencils around any vertex of a primal scheme: a
//! smooth interior one, one on the boundary, on a crease, at a dart or at
//! a corner ([`Star`]), measured by impulses through the grammar on the
//! vertex's fan as [`super::surface`] measures interior vertices (the same
//! fan, naming and invariant neighbourhood; an open fan for a boundary
//! vertex, sharp edges made sharp for ever along whole lines of the fan).
//!
//! **Sides.** The boundary and the sharp edges part the fan into sides
//! (one side all round where fewer than two sharp edges meet an interior
//! vertex). The places of one side (its sectors, the curves that bound
//! it, the centre) are an invariant subspace of the local matrix when the
//! rules along a boundary or a crease read only the curve (the curve
//! rules of `catmull-clark.lsys` and `loop.lsys`); that is checked, and
//! each side is analysed on its own: its local matrix's spectrum is the
//! curve's (1, ½, ¼, … for the cubic B-spline) and what the side's
//! interior adds.
//!
//! **Which eigenvectors.** The limit position is the left eigenvector of
//! 1 (of the whole neighbourhood). A side's two tangents are the left
//! eigenvectors of its two largest eigenvalues below 1, λ1 ≥ λ2, which
//! must be real, positive and above the modulus of every other one (else
//! the tangent plane is not fixed by the eigen-analysis, and the side is
//! refused with that reason). Where λ1 = λ2 the two are a basis of the
//! double eigenvalue's left null space (a smooth vertex; a regular
//! boundary vertex: both ½, along the boundary and across it; a corner
//! sector between two curves: ½ on each). Where they differ, on an
//! irregular boundary or crease side, one is the curve's ½, whose left
//! eigenvector lies on the curve (the tangent along it), and the other,
//! the side's largest interior eigenvalue μ, gives the tangent across
//! (its left eigenvector reaches into the side); μ may be above or below
//! ½. Where μ is below the curve's ¼ (or equal to it), the two largest
//! are the curve's ½ and ¼ and the characteristic map (the curve's
//! parameter and its square) is not regular: the scheme is not C1 there
//! and the side is refused. [`Side::eigenvalues`] says which case holds.

use nalgebra::DMatrix;

use super::surface::{
    close, label_weights, left_null, measure, spectrum, star_fan, Label, LabelWeight, Star,
    FAN_RINGS, TOL,
};
use crate::surface::Grammar;
use crate::{Deadline, Error};

/// The stencils of one side of a star: sectors `first` to `first +
/// sectors - 1` (modulo the star's n when it is closed).
#[derive(Clone, Debug)]
pub struct Side {
    pub first: usize,
    pub sectors: usize,
    /// λ1 ≥ λ2: the eigenvalues of the two tangent stencils.
    pub eigenvalues: [f64; 2],
    /// The largest modulus among the side's other eigenvalues below 1.
    pub next: f64,
    /// The two tangent stencils (left eigenvectors of λ1 and λ2).
    pub tangents: [Vec<LabelWeight>; 2],
    /// Every other eigenvalue of the side has a smaller modulus than both
    /// λ1 and λ2 (the eigenvalue condition for C1; where it fails the
    /// tangents are still written, see the module's text).
    pub c1: bool,
}

/// The stencils of a star: its limit position, and a side's tangents for
/// each side.
#[derive(Clone, Debug)]
pub struct StarStencils {
    pub star: Star,
    pub limit: Vec<LabelWeight>,
    pub sides: Vec<Side>,
}

/// The limit and tangent stencils of `g` around the vertex `star`,
/// measured on its fan; `Ok(Err(why))` where the analysis gives none (the
/// grammar does not run on the fan, no invariant neighbourhood, no tangent
/// plane from the eigenvalues).
pub fn star_stencils(
    g: &Grammar,
    star: &Star,
    deadline: Deadline,
) -> Result<Result<StarStencils, String>, Error> {
    if g.dual_at.is_some() || g.adaptive.is_some() {
        return Ok(Err(
            "a dual or adaptive grammar has no stencils around a vertex".into(),
        ));
    }
    if star.is_corner() && star.sides().len() == 1 && !star.open {
        return Ok(Err(
            "a sharp vertex with fewer than two sharp edges is the tip of a cone: it has no \
             tangent plane"
                .into(),
        ));
    }
    let quads = g.block_used_at.is_some();
    let f = star_fan(star, quads, FAN_RINGS, false);
    let (_, _, hoods, measured) = match measure(g, &f, false, deadline, deadline)? {
        Ok(found) => found,
        Err(why) => return Ok(Err(why)),
    };
    let Some((s, set, _)) = hoods.into_iter().next() else {
        return Ok(Err("no invariant neighbourhood".into()));
    };
    let places: Vec<Label> = set.iter().map(|&c| measured.cols[c]).collect();
    let Some(eig) = spectrum(&s) else {
        return Ok(Err("the eigenvalues did not converge".into()));
    };
    let simple_one = eig
        .first()
        .is_some_and(|l| close(l.re, 1.0) && close(l.im, 0.0))
        && eig.get(1).is_none_or(|l| l.modulus < 1.0 - 1e-7);
    let limit = match left_null(&s, 1.0, 1).pop() {
        Some(w) if simple_one && w.iter().sum::<f64>().abs() > TOL => {
            let sum: f64 = w.iter().sum();
            let w: Vec<f64> = w.iter().map(|x| x / sum).collect();
            label_weights(&measured.cols, &set, &w)
        }
        _ => return Ok(Err("1 is not a simple eigenvalue: no limit stencil".into())),
    };
    let mut sides = Vec::new();
    for (first, sectors) in star.sides() {
        match side(star, &s, &places, &measured.cols, &set, first, sectors) {
            Ok(side) => sides.push(side),
            Err(why) => {
                return Ok(Err(format!(
                    "the side of sectors {first} to {}: {why}",
                    first + sectors - 1
                )))
            }
        }
    }
    Ok(Ok(StarStencils {
        star: star.clone(),
        limit,
        sides,
    }))
}

/// Where a place is in a side.
#[derive(Clone, Copy, PartialEq, Eq)]
enum At {
    Centre,
    /// On the curve (boundary or sharp edge) the side starts at, or ends at.
    Start,
    End,
    Inside,
}

/// Where the place `l` is in the side of `sectors` sectors from `first`,
/// `None` outside it. A side all round has no curves.
fn in_side(star: &Star, l: Label, first: usize, sectors: usize) -> Option<At> {
    if l.x.abs() <= TOL && l.y.abs() <= TOL {
        return Some(At::Centre);
    }
    if !star.open && sectors == star.n {
        return Some(At::Inside);
    }
    let r = if star.open {
        l.t.checked_sub(first)?
    } else {
        (l.t + star.n - first) % star.n
    };
    if l.y.abs() <= TOL {
        match r {
            0 => Some(At::Start),
            r if r == sectors => Some(At::End),
            r if r < sectors => Some(At::Inside),
            _ => None,
        }
    } else {
        (r < sectors).then_some(At::Inside)
    }
}

/// The submatrix of `s` on the rows and columns `rows`, `cols`.
fn sub(s: &DMatrix<f64>, rows: &[usize], cols: &[usize]) -> DMatrix<f64> {
    DMatrix::from_fn(rows.len(), cols.len(), |a, b| s[(rows[a], cols[b])])
}

/// The largest eigenvalue of `m` below 1 (after `skip` of modulus 1) and
/// its left eigenvector, when it is real, positive and simple, with the
/// next modulus.
fn dominant(m: &DMatrix<f64>, skip: usize, what: &str) -> Result<(f64, Vec<f64>, f64), String> {
    let eig = spectrum(m).ok_or("the eigenvalues did not converge")?;
    let l = eig
        .get(skip)
        .ok_or_else(|| format!("{what}: no eigenvalue"))?;
    let next = eig.get(skip + 1).map_or(0.0, |e| e.modulus);
    if !close(l.im, 0.0) || l.re <= 1e-7 || l.re > 1.0 - 1e-7 {
        return Err(format!(
            "{what}: the eigenvalue {:.6}{:+.6}i is not real, positive and below 1",
            l.re, l.im
        ));
    }
    if next > l.re - 1e-7 {
        return Err(format!(
            "{what}: the eigenvalue {:.6} is not simple (the next has modulus {next:.6}): the \
             eigen-analysis does not fix a tangent here",
            l.re
        ));
    }
    let v = left_null(m, l.re, 1)
        .pop()
        .ok_or_else(|| format!("{what}: no left eigenvector"))?;
    Ok((l.re, v, next))
}

fn side(
    star: &Star,
    s: &DMatrix<f64>,
    places: &[Label],
    cols: &[Label],
    set: &[usize],
    first: usize,
    sectors: usize,
) -> Result<Side, String> {
    let at: Vec<Option<At>> = places
        .iter()
        .map(|&l| in_side(star, l, first, sectors))
        .collect();
    let idx: Vec<usize> = (0..places.len()).filter(|&k| at[k].is_some()).collect();
    // The side's places must be invariant: their new positions read no
    // place of another side.
    for &r in &idx {
        if let Some(c) = (0..places.len()).find(|&c| at[c].is_none() && s[(r, c)].abs() > TOL) {
            let (a, b) = (places[r], places[c]);
            return Err(format!(
                "the new vertex at ({}, {}, {}) reads the old one at ({}, {}, {}), across a \
                 boundary or a crease: the sides are not separate",
                a.t, a.x, a.y, b.t, b.x, b.y
            ));
        }
    }
    let m = sub(s, &idx, &idx);
    let local =
        |p: At| -> Vec<usize> { (0..idx.len()).filter(|&a| at[idx[a]] == Some(p)).collect() };
    let (centre, start, end, inside) = (
        local(At::Centre),
        local(At::Start),
        local(At::End),
        local(At::Inside),
    );
    // A stencil on the places `on` of the side, spread to the whole side.
    let spread = |on: &[usize], w: &[f64]| -> Vec<f64> {
        let mut v = vec![0.0; idx.len()];
        for (&a, &x) in on.iter().zip(w) {
            v[a] = x;
        }
        v
    };
    let ([la, lb], [wa, wb], next, c1) = if start.is_empty() {
        // All round: the two largest eigenvalues below 1.
        let eig = spectrum(&m).ok_or("the eigenvalues did not converge")?;
        let (Some(l1), Some(l2)) = (eig.get(1), eig.get(2)) else {
            return Err("fewer than three eigenvalues".into());
        };
        let next = eig.get(3).map_or(0.0, |e| e.modulus);
        if !(close(l1.im, 0.0) && close(l2.im, 0.0) && l2.re > 1e-7 && l1.re < 1.0 - 1e-7) {
            return Err(format!(
                "the subdominant eigenvalues {:.6}{:+.6}i, {:.6}{:+.6}i are not real, positive \
                 and below 1",
                l1.re, l1.im, l2.re, l2.im
            ));
        }
        if next > l2.re - 1e-7 {
            return Err(format!(
                "the eigenvalues λ1 = {:.6}, λ2 = {:.6} are not above the next one ({next:.6}): \
                 the eigen-analysis does not fix a tangent plane here",
                l1.re, l2.re
            ));
        }
        let v = if close(l1.re, l2.re) {
            left_null(&m, l1.re, 2)
        } else {
            let mut v = left_null(&m, l1.re, 1);
            v.extend(left_null(&m, l2.re, 1));
            v
        };
        let [a, b]: [Vec<f64>; 2] = v.try_into().map_err(|_| "no left eigenvectors")?;
        ([l1.re, l2.re], [a, b], next, true)
    } else if star.is_corner() {
        // A corner: the tangents along the two curves that leave it, each
        // the dominant left eigenvector of its curve (which reads only
        // itself and the corner).
        let mut t = Vec::new();
        let mut lam = Vec::new();
        let mut next: f64 = 0.0;
        for (curve, name) in [(&start, "the first curve"), (&end, "the second curve")] {
            let on: Vec<usize> = centre.iter().chain(curve.iter()).copied().collect();
            let (l, w, nx) = dominant(&sub(&m, &on, &on), 1, name)?;
            t.push(spread(&on, &w));
            lam.push(l);
            next = next.max(nx);
        }
        let low = lam[0].min(lam[1]);
        let c1 = match dominant(&sub(&m, &inside, &inside), 0, "inside") {
            Ok((mu, _, _)) => mu < low - 1e-7,
            Err(_) => inside.is_empty(),
        } && next < low - 1e-7;
        let [a, b]: [Vec<f64>; 2] = t.try_into().map_err(|_| "no tangents")?;
        ([lam[0], lam[1]], [a, b], next, c1)
    } else {
        // A boundary or a crease through the vertex: along it, the curve's
        // dominant left eigenvector (on the curve only); across it, the
        // side's largest eigenvalue after that one (see the module's text).
        let curve: Vec<usize> = centre.iter().chain(&start).chain(&end).copied().collect();
        let b = sub(&m, &curve, &curve);
        let (la, wa, beta) = dominant(&b, 1, "along the curve")?;
        let interior = if inside.is_empty() {
            None
        } else {
            Some(dominant(&sub(&m, &inside, &inside), 0, "across the curve")?)
        };
        let (mu, w, next, c1) = match interior {
            Some((mu, wi, next_inside)) if mu >= beta - 1e-7 => {
                // l = (l_C, l_I): l_I the interior block's, l_C solving
                // l_C (B - μ) = -l_I X (least squares: where μ is the
                // curve's ½ too, fixed up to the tangent along).
                let x = sub(&m, &inside, &curve);
                let li = nalgebra::DVector::from_vec(wi);
                let rhs = -(x.transpose() * &li);
                let a = (b.clone() - DMatrix::identity(curve.len(), curve.len()) * mu).transpose();
                let lc = a
                    .clone()
                    .svd(true, true)
                    .solve(&rhs, 1e-10)
                    .map_err(|e| format!("across the curve: {e}"))?;
                let consistent = (&a * &lc - &rhs).norm() <= 1e-8 * (1.0 + rhs.norm());
                if consistent && close(mu, beta) {
                    return Err(format!(
                        "across the curve: μ = {mu:.6} is the curve's second eigenvalue too, \
                         with two left eigenvectors: the eigen-analysis does not fix a tangent \
                         here"
                    ));
                }
                if !consistent && !close(mu, beta) {
                    return Err(format!(
                        "across the curve: μ = {mu:.6} has no left eigenvector: the \
                         eigen-analysis does not fix a tangent here"
                    ));
                }
                if consistent {
                    let mut w = spread(&curve, lc.as_slice());
                    for (&k, &v) in inside.iter().zip(li.iter()) {
                        w[k] = v;
                    }
                    let next = next_inside.max(beta);
                    (mu, w, next, next < la.min(mu) - 1e-7)
                } else {
                    // A Jordan block: μ's only left eigenvector is the
                    // curve's, whose coefficient grows like m μ^m and leads.
                    let (_, wc, _) = dominant(&b, 2, "across the curve")?;
                    (mu, spread(&curve, &wc), next_inside, false)
                }
            }
            // Nothing inside reaches the curve's second eigenvalue: the
            // tangent plane is the curve's osculating plane.
            other => {
                let (_, wc, _) = dominant(&b, 2, "across the curve")?;
                let next = other.map_or(0.0, |(mu, _, _)| mu);
                (beta, spread(&curve, &wc), next, false)
            }
        };
        ([la, mu], [spread(&curve, &wa), w], next, c1)
    };
    let sub_set: Vec<usize> = idx.iter().map(|&k| set[k]).collect();
    Ok(Side {
        first,
        sectors,
        eigenvalues: [la, lb],
        next,
        tangents: [
            label_weights(cols, &sub_set, &wa),
            label_weights(cols, &sub_set, &wb),
        ],
        c1,
    })
}
