//! Surface grammars: the local subdivision matrix around one vertex of
//! valence n, measured by impulses through the grammar on a fan of faces
//! built here, its leading eigenvalues, Reif's check and the limit and
//! tangent stencils from its left eigenvectors.
//!
//! The fan: n sectors of a regular lattice (triangles or quads) around the
//! centre, [`FAN_RINGS`] rings deep, laid out in the plane; an impulse is
//! a height. A new vertex is named by the old vertices that carry its
//! largest weight: their centroid on the layout, doubled, is the old
//! lattice point it stands for (an old vertex stays itself, an edge point
//! its edge's midpoint, a face point its face's centre). The local matrix
//! maps the old vertices within r rings of the centre to the new vertices
//! of the same names; r is the smallest ring count whose new vertices
//! depend on no old vertex outside (an invariant neighbourhood).

use std::collections::HashMap;
use std::f64::consts::TAU;

use glam::{DVec2, DVec3};
use nalgebra::DMatrix;
use serde::Serialize;

use super::num::{eigenvalues, fraction};
use crate::mesh::{Mesh, PolygonSoup};
use crate::surface::Grammar;
use crate::{Deadline, Error};

/// The valences looked at.
pub const VALENCES: std::ops::RangeInclusive<usize> = 3..=12;
/// Rings of faces around the centre of a probe fan.
pub const FAN_RINGS: usize = 4;
/// The largest neighbourhood (rings) tried for invariance.
pub const MAX_RINGS: usize = 2;
/// Eigenvalues listed per valence.
pub const LISTED: usize = 6;
const TOL: f64 = 1e-9;
/// The time the valences of one grammar may take together; valences not
/// reached in it are skipped with a note.
pub const BUDGET: std::time::Duration = std::time::Duration::from_secs(20);

/// What `analyze` says about a surface grammar.
#[derive(Clone, Debug, Serialize)]
pub struct SurfaceReport {
    /// "triangles" or "quads": the faces of the probe fans.
    pub faces: String,
    pub valences: Vec<Valence>,
    pub notes: Vec<String>,
}

/// The analysis at one valence.
#[derive(Clone, Debug, Serialize)]
pub struct Valence {
    pub n: usize,
    /// Why there is no matrix, when there is none.
    pub skipped: Option<String>,
    /// Steps of the grammar in the measured matrix (1, or 2 for schemes
    /// whose vertices come back to the lattice every second step).
    pub steps: usize,
    /// Rings of the invariant neighbourhood, and the matrix's size.
    pub rings: usize,
    pub size: usize,
    /// Every row sums to one.
    pub affine: bool,
    /// The leading eigenvalues, largest modulus first.
    pub eigenvalues: Vec<Eigenvalue>,
    /// 1 = λ0 > λ1 = λ2 > |λ3|, λ1 real (Reif).
    pub reif: bool,
    /// The limit position as weights on the neighbourhood (left
    /// eigenvector of 1, summing to one).
    pub limit: Vec<LabelWeight>,
    /// Two tangent stencils (left eigenvectors of λ1 = λ2), when λ1 is
    /// real and double.
    pub tangents: Vec<Vec<LabelWeight>>,
}

/// A complex eigenvalue.
#[derive(Clone, Debug, Serialize)]
pub struct Eigenvalue {
    pub re: f64,
    pub im: f64,
    pub modulus: f64,
}

/// A weight on the old vertex `(sector, i, j)` of the fan: `i` steps along
/// the sector's first edge, `j` along the next sector's; the centre is
/// (0, 0, 0).
#[derive(Clone, Debug, Serialize)]
pub struct LabelWeight {
    pub sector: usize,
    pub i: usize,
    pub j: usize,
    pub weight: f64,
    pub fraction: String,
}

/// A fan of `n` sectors around one vertex.
struct Fan {
    soup: PolygonSoup,
    labels: Vec<(usize, usize, usize)>,
}

fn fan(n: usize, quads: bool, rings: usize) -> Fan {
    let u = |t: usize| {
        let a = TAU * (t % n) as f64 / n as f64;
        DVec2::new(a.cos(), a.sin())
    };
    let mut ids: HashMap<(usize, usize, usize), u32> = HashMap::new();
    let mut f = Fan {
        soup: PolygonSoup::default(),
        labels: Vec::new(),
    };
    let mut id = |f: &mut Fan, t: usize, i: usize, j: usize| -> u32 {
        let key = match (i, j) {
            (0, 0) => (0, 0, 0),
            (0, _) => ((t + 1) % n, j, 0),
            _ => (t % n, i, j),
        };
        *ids.entry(key).or_insert_with(|| {
            let p = i as f64 * u(t) + j as f64 * u(t + 1);
            f.soup.positions.push(DVec3::new(p.x, p.y, 0.0));
            f.labels.push(key);
            f.labels.len() as u32 - 1
        })
    };
    for t in 0..n {
        for i in 0..rings {
            for j in 0..rings {
                if quads {
                    let q = [
                        id(&mut f, t, i, j),
                        id(&mut f, t, i + 1, j),
                        id(&mut f, t, i + 1, j + 1),
                        id(&mut f, t, i, j + 1),
                    ];
                    f.soup.faces.push(q);
                } else if i + j < rings {
                    let a = [
                        id(&mut f, t, i, j),
                        id(&mut f, t, i + 1, j),
                        id(&mut f, t, i, j + 1),
                    ];
                    f.soup.faces.push(a);
                    if i + j + 1 < rings {
                        let b = [
                            id(&mut f, t, i + 1, j),
                            id(&mut f, t, i + 1, j + 1),
                            id(&mut f, t, i, j + 1),
                        ];
                        f.soup.faces.push(b);
                    }
                }
            }
        }
    }
    f
}

fn snap(p: DVec2) -> (i64, i64) {
    ((p.x * 1e6).round() as i64, (p.y * 1e6).round() as i64)
}

/// The full matrix of `steps` steps on the fan: rows the new vertices (in
/// id order), columns the old ones.
fn full_matrix(
    g: &Grammar,
    f: &Fan,
    steps: usize,
    deadline: Deadline,
) -> Result<DMatrix<f64>, String> {
    let run = |soup: &PolygonSoup| -> Result<Vec<DVec3>, String> {
        let mut m = Mesh::from_soup(soup).map_err(|e| e.to_string())?;
        g.run_until(&mut m, steps, Some(deadline), |_| {})
            .map_err(|e| e.message)?;
        Ok(m.vertices().map(|v| m.position(v)).collect())
    };
    let base = run(&f.soup)?;
    let cols = f.soup.positions.len();
    let mut s = DMatrix::zeros(base.len(), cols);
    for c in 0..cols {
        deadline.check()?;
        let mut soup = f.soup.clone();
        soup.positions[c].z = 1.0;
        let out = run(&soup)?;
        if out.len() != base.len() {
            return Err("the number of vertices depends on the positions".into());
        }
        for (r, p) in out.iter().enumerate() {
            if (p.truncate() - base[r].truncate()).length() > TOL {
                return Err("a height moves vertices sideways: not linear".into());
            }
            s[(r, c)] = p.z - base[r].z;
        }
    }
    if base.iter().any(|p| p.z.abs() > TOL) {
        return Err("a flat mesh does not stay flat: not linear".into());
    }
    Ok(s)
}

/// The local matrix in the smallest invariant neighbourhood, with its
/// labels and ring count.
fn local(f: &Fan, full: &DMatrix<f64>, quads: bool) -> Option<(DMatrix<f64>, Vec<usize>, usize)> {
    let layout: Vec<DVec2> = f.soup.positions.iter().map(|p| p.truncate()).collect();
    let mut new_at: HashMap<(i64, i64), usize> = HashMap::new();
    for r in 0..full.nrows() {
        let row = full.row(r);
        let top = row.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        let dom: Vec<usize> = (0..row.len())
            .filter(|&c| (row[c] - top).abs() <= TOL)
            .collect();
        if top <= TOL {
            continue;
        }
        let centre = dom.iter().map(|&c| layout[c]).sum::<DVec2>() / dom.len() as f64;
        if new_at.insert(snap(2.0 * centre), r).is_some() {
            // Two new vertices claim one name: keep none.
            new_at.insert(snap(2.0 * centre), usize::MAX);
        }
    }
    for rings in 1..=MAX_RINGS {
        let set: Vec<usize> = (0..layout.len())
            .filter(|&c| {
                let (_, i, j) = f.labels[c];
                if quads {
                    i.max(j) <= rings
                } else {
                    i + j <= rings
                }
            })
            .collect();
        let rows: Option<Vec<usize>> = set
            .iter()
            .map(|&c| {
                new_at
                    .get(&snap(layout[c]))
                    .copied()
                    .filter(|&r| r != usize::MAX)
            })
            .collect();
        let Some(rows) = rows else { continue };
        let inside: Vec<bool> = (0..layout.len()).map(|c| set.contains(&c)).collect();
        let invariant = rows.iter().all(|&r| {
            (0..layout.len())
                .filter(|&c| !inside[c])
                .all(|c| full[(r, c)].abs() <= TOL)
        });
        if invariant {
            let s = DMatrix::from_fn(set.len(), set.len(), |a, b| full[(rows[a], set[b])]);
            return Some((s, set, rings));
        }
    }
    None
}

/// The left null vectors of `s - λ I` (as many as `count`), from the SVD.
fn left_null(s: &DMatrix<f64>, lambda: f64, count: usize) -> Vec<Vec<f64>> {
    let n = s.nrows();
    let a = s.transpose() - DMatrix::identity(n, n) * lambda;
    let svd = a.svd(false, true);
    let Some(v_t) = svd.v_t else {
        return Vec::new();
    };
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&x, &y| svd.singular_values[x].total_cmp(&svd.singular_values[y]));
    order
        .iter()
        .take(count)
        .map(|&k| v_t.row(k).iter().cloned().collect())
        .collect()
}

fn label_weights(f: &Fan, set: &[usize], v: &[f64]) -> Vec<LabelWeight> {
    set.iter()
        .zip(v)
        .map(|(&c, &w)| {
            let (sector, i, j) = f.labels[c];
            LabelWeight {
                sector,
                i,
                j,
                weight: w,
                fraction: fraction(w),
            }
        })
        .collect()
}

fn valence(
    g: &Grammar,
    n: usize,
    quads: bool,
    deadline: Deadline,
    budget: Deadline,
) -> Result<Valence, Error> {
    let f = fan(n, quads, FAN_RINGS);
    let mut v = Valence {
        n,
        skipped: None,
        steps: 0,
        rings: 0,
        size: 0,
        affine: false,
        eigenvalues: Vec::new(),
        reif: false,
        limit: Vec::new(),
        tangents: Vec::new(),
    };
    let mut why = String::new();
    let mut found = None;
    for steps in 1..=2 {
        let limit = if budget.limit() < deadline.limit() {
            budget
        } else {
            deadline
        };
        match full_matrix(g, &f, steps, limit) {
            Ok(full) => {
                if let Some(l) = local(&f, &full, quads) {
                    found = Some((steps, l));
                    break;
                }
                why = format!(
                    "no invariant neighbourhood of at most {MAX_RINGS} rings whose new vertices \
                     stand at half the spacing after one or two steps (a √3 or dual scheme?)"
                );
            }
            Err(e) => {
                if deadline.passed() {
                    return Err(Error::Failed(deadline.message()));
                }
                if budget.passed() {
                    why = format!("not measured within the budget of {} s", BUDGET.as_secs());
                    break;
                }
                why = format!("the grammar does not run on this fan: {e}");
                break;
            }
        }
    }
    let Some((steps, (s, set, rings))) = found else {
        v.skipped = Some(why);
        return Ok(v);
    };
    v.steps = steps;
    v.rings = rings;
    v.size = set.len();
    v.affine = (0..s.nrows()).all(|r| (s.row(r).sum() - 1.0).abs() <= TOL);
    let Some(values) = eigenvalues(&s) else {
        v.skipped = Some(format!(
            "the eigenvalues of the {0}×{0} matrix did not converge",
            s.nrows()
        ));
        return Ok(v);
    };
    let mut eig: Vec<Eigenvalue> = values
        .iter()
        .map(|c| Eigenvalue {
            re: c.re,
            im: c.im,
            modulus: c.norm(),
        })
        .collect();
    eig.sort_by(|a, b| b.modulus.total_cmp(&a.modulus).then(b.re.total_cmp(&a.re)));
    let e = |k: usize| eig.get(k).cloned();
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-7;
    if let (Some(l0), Some(l1), Some(l2)) = (e(0), e(1), e(2)) {
        let l3 = e(3).map_or(0.0, |x| x.modulus);
        v.reif = close(l0.re, 1.0)
            && close(l0.im, 0.0)
            && close(l1.im, 0.0)
            && close(l2.im, 0.0)
            && close(l1.re, l2.re)
            && l1.re < 1.0 - 1e-7
            && l1.re > 0.0
            && l3 < l1.re - 1e-7;
        if close(l0.re, 1.0) && close(l0.im, 0.0) {
            if let Some(w) = left_null(&s, 1.0, 1).pop() {
                let sum: f64 = w.iter().sum();
                if sum.abs() > TOL {
                    let w: Vec<f64> = w.iter().map(|x| x / sum).collect();
                    v.limit = label_weights(&f, &set, &w);
                }
            }
        }
        if close(l1.im, 0.0) && close(l2.im, 0.0) && close(l1.re, l2.re) {
            v.tangents = left_null(&s, l1.re, 2)
                .iter()
                .map(|w| label_weights(&f, &set, w))
                .collect();
        }
    }
    eig.truncate(LISTED);
    v.eigenvalues = eig;
    Ok(v)
}

/// Analyses the surface grammar `g` (its file `path`, for messages).
pub fn analyze(g: &Grammar, path: &str, deadline: Deadline) -> Result<SurfaceReport, Error> {
    let _ = path;
    let mut notes = Vec::new();
    let quads = g.block_used_at.is_some();
    if g.dual_at.is_some() {
        notes.push(
            "a dual scheme: its new vertices are not the old ones, so there is no vertex \
             neighbourhood to measure around a vertex of valence n"
                .to_string(),
        );
        return Ok(SurfaceReport {
            faces: if quads { "quads" } else { "triangles" }.into(),
            valences: Vec::new(),
            notes,
        });
    }
    let mut valences = Vec::new();
    let budget = Deadline::after(BUDGET);
    for n in VALENCES {
        valences.push(valence(g, n, quads, deadline, budget)?);
    }
    if let Some(bad) = valences.iter().find(|v| v.skipped.is_none() && !v.reif) {
        notes.push(format!(
            "Reif's check fails at valence {}: the scheme is not shown C1 there",
            bad.n
        ));
    }
    Ok(SurfaceReport {
        faces: if quads { "quads" } else { "triangles" }.into(),
        valences,
        notes,
    })
}
