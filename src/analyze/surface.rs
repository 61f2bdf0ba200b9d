//! Surface grammars: the local subdivision matrix around one vertex of
//! valence n (primal schemes) or one n-sided face (dual schemes), measured
//! by impulses through the grammar on a fan of faces built here, its
//! leading eigenvalues, Reif's check and the limit and tangent stencils
//! from its left eigenvectors.
//!
//! The fan: n sectors of a regular lattice (triangles or quads) around the
//! centre, [`FAN_RINGS`] rings deep, laid out in the plane; an impulse is
//! a height. Every vertex gets a name, a place `(sector, x, y)` on the
//! lattice, `x` along the sector's first edge and `y` along the next
//! sector's, from the mesh's structure alone: a vertex of the fan is where
//! the fan put it; a vertex made later stands at the average of the places
//! of its neighbours made before it (an edge point at its edge's middle, a
//! face point at its face's centre, a √3 centroid at its triangle's), and
//! one with no such neighbour (a Catmull-Clark face point, the centre of a
//! dual scheme's edge block) at the average of its named neighbours. The
//! places are averaged in the unfolded chart of one sector, where the
//! lattice around a sector is regular, so names do not depend on the
//! valence.
//!
//! The local matrix maps the old vertices within r rings of the centre to
//! the new vertices named at the same places shrunk by the scheme's
//! scale (2 for a halving of the lattice, 3 for the triadic lattice of two
//! √3 steps); r is the smallest ring count whose new vertices depend on no
//! old vertex outside (an invariant neighbourhood).
//!
//! Dual schemes (`blocks: dual`) have no vertex that stays: they are
//! measured around the n-gon that one step makes around a vertex of
//! valence n, from the polygons' corners after that step to the corners
//! after the next (the probe is closed, two fans glued at their rims, for
//! dual grammars refuse open meshes).

use std::collections::HashMap;
use std::f64::consts::TAU;

use glam::{DVec2, DVec3};
use nalgebra::DMatrix;
use rayon::prelude::*;
use serde::Serialize;

use super::num::{eigenvalues, fraction};
use crate::mesh::{Mesh, PolygonSoup, VertexId};
use crate::surface::Grammar;
use crate::{Deadline, Error};

/// The valences looked at.
pub const VALENCES: std::ops::RangeInclusive<usize> = 3..=12;
/// Rings of faces around the centre of a probe fan (primal schemes; a
/// dual scheme's closed fan has one ring less, enough for the corners it
/// measures).
pub const FAN_RINGS: usize = 3;
/// The largest neighbourhood (rings) tried for invariance.
pub const MAX_RINGS: usize = 2;
/// Eigenvalues listed per valence.
pub const LISTED: usize = 6;
pub(super) const TOL: f64 = 1e-9;
/// The time the valences of one grammar may take together; valences not
/// reached in it are skipped with a note.
pub const BUDGET: std::time::Duration = std::time::Duration::from_secs(60);

/// What `analyze` says about a surface grammar.
#[derive(Clone, Debug, Serialize)]
pub struct SurfaceReport {
    /// "triangles" or "quads": the faces of the probe fans.
    pub faces: String,
    /// "vertex": the matrices are around a vertex of valence n; "face":
    /// around an n-sided face (a dual scheme).
    pub around: String,
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
    /// How much finer the new lattice is than the old: 2, or 3 for two
    /// √3 steps.
    pub scale: usize,
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
    /// The places of the neighbourhood's old vertices (the matrix's
    /// columns; its rows are the new vertices at the same places over
    /// `scale`), and the local matrix itself, row by row.
    pub places: Vec<Place>,
    pub matrix: Vec<Vec<f64>>,
    /// The next invariant neighbourhood (one ring more), when there is
    /// one within [`MAX_RINGS`]: its spectrum holds the smallest's and
    /// what the outer ring adds, and Reif's check on it.
    pub wider: Option<Wider>,
    /// The characteristic map's control net on the widest invariant
    /// neighbourhood, when λ1 = λ2 is real.
    pub characteristic: Option<CharacteristicNet>,
}

/// The control net of the characteristic map: every place of the
/// neighbourhood at its weights in two right eigenvectors of λ1 = λ2
/// (a basis of that eigenspace, turned and scaled so that the points'
/// second moment is the identity: a linear image of the map, which keeps
/// its folds and windings), and the old mesh's edges between the places.
#[derive(Clone, Debug, Serialize)]
pub struct CharacteristicNet {
    pub places: Vec<Place>,
    pub points: Vec<[f64; 2]>,
    pub edges: Vec<[usize; 2]>,
}

/// A place `(sector, i, j)` on the fan (see [`LabelWeight`]).
#[derive(Clone, Debug, Serialize)]
pub struct Place {
    pub sector: usize,
    pub i: f64,
    pub j: f64,
}

/// The matrix on a wider invariant neighbourhood.
#[derive(Clone, Debug, Serialize)]
pub struct Wider {
    pub rings: usize,
    pub size: usize,
    pub eigenvalues: Vec<Eigenvalue>,
    pub reif: bool,
}

/// A complex eigenvalue.
#[derive(Clone, Debug, Serialize)]
pub struct Eigenvalue {
    pub re: f64,
    pub im: f64,
    pub modulus: f64,
}

/// A weight on the old vertex at `(sector, i, j)` of the fan: `i` steps
/// along the sector's first edge, `j` along the next sector's; the centre
/// is (0, 0, 0). Around a face (dual schemes) the corners stand at
/// quarters: (s, 1/4, 1/4) is the central n-gon's corner in sector s.
#[derive(Clone, Debug, Serialize)]
pub struct LabelWeight {
    pub sector: usize,
    pub i: f64,
    pub j: f64,
    pub weight: f64,
    pub fraction: String,
}

/// A place on the fan: `x` along sector `t`'s first edge, `y` along the
/// next sector's. The centre is (0, 0, 0); a place on the edge between
/// sectors t - 1 and t is `(t, x, 0)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Label {
    pub(super) t: usize,
    pub(super) x: f64,
    pub(super) y: f64,
}

const CENTRE: Label = Label {
    t: 0,
    x: 0.0,
    y: 0.0,
};

impl Label {
    fn is_centre(self) -> bool {
        self.x.abs() <= TOL && self.y.abs() <= TOL
    }

    /// The label as a hashable key, its coordinates times `scale`.
    fn key(self, scale: f64) -> (usize, i64, i64) {
        let r = |v: f64| (v * scale * 1e6).round() as i64;
        (self.t, r(self.x), r(self.y))
    }
}

/// The lattice of a fan of `k` sectors: which sectors unfold next to
/// which, and how.
#[derive(Clone, Copy)]
struct Lattice {
    k: usize,
    quads: bool,
}

impl Lattice {
    /// The point (x, y) of sector `t`'s chart as a label: a point outside
    /// the sector (a negative coordinate) moves to the neighbouring
    /// sector's chart, as the regular lattice unfolds around sector t.
    fn canon(self, t: usize, mut x: f64, mut y: f64) -> Option<Label> {
        let k = self.k;
        let mut t = t % k;
        for _ in 0..2 * k {
            if x.abs() <= TOL && y.abs() <= TOL {
                return Some(CENTRE);
            }
            if y < -TOL {
                // Sector t - 1's (a, b) is (b, -a) here (quads), or
                // (a + b, -a) (triangles).
                (x, y) = if self.quads { (-y, x) } else { (-y, x + y) };
                t = (t + k - 1) % k;
                continue;
            }
            if x < -TOL {
                // Sector t + 1's (a, b) is (-b, a) here, or (-b, a + b).
                (x, y) = if self.quads { (y, -x) } else { (x + y, -x) };
                t = (t + 1) % k;
                continue;
            }
            if x.abs() <= TOL {
                return Some(Label {
                    t: (t + 1) % k,
                    x: y,
                    y: 0.0,
                });
            }
            let y = if y.abs() <= TOL { 0.0 } else { y };
            return Some(Label { t, x, y });
        }
        None
    }

    /// `l` in the chart of sector `c`, when l is in sector c or a
    /// neighbouring one.
    fn in_chart(self, l: Label, c: usize) -> Option<DVec2> {
        if l.is_centre() {
            return Some(DVec2::ZERO);
        }
        let (a, b) = (l.x, l.y);
        if l.t == c {
            Some(DVec2::new(a, b))
        } else if l.t == (c + 1) % self.k {
            Some(if self.quads {
                DVec2::new(-b, a)
            } else {
                DVec2::new(-b, a + b)
            })
        } else if (l.t + 1) % self.k == c {
            Some(if self.quads {
                DVec2::new(b, -a)
            } else {
                DVec2::new(a + b, -a)
            })
        } else {
            None
        }
    }

    /// The average of places next to each other, in the chart of the
    /// sector that holds most of them.
    fn average(self, ls: &[Label]) -> Option<Label> {
        if ls.is_empty() {
            return None;
        }
        let mut best: Option<(usize, usize, DVec2)> = None;
        for c in ls.iter().filter(|l| !l.is_centre()).map(|l| l.t) {
            let Some(ps) = ls
                .iter()
                .map(|&l| self.in_chart(l, c))
                .collect::<Option<Vec<DVec2>>>()
            else {
                continue;
            };
            let inside = ps.iter().filter(|p| p.x >= -TOL && p.y >= -TOL).count();
            if best.is_none_or(|(_, b, _)| inside > b) {
                let mean = ps.iter().sum::<DVec2>() / ps.len() as f64;
                best = Some((c, inside, mean));
            }
        }
        match best {
            Some((c, _, p)) => self.canon(c, p.x, p.y),
            // Every place is the centre.
            None => Some(CENTRE),
        }
    }

    /// Rings of a place: the lattice's ring for a vertex (`max(x, y)` on
    /// quads, `x + y` on triangles); for a dual scheme's corner at
    /// quarters, the ring of corners (1 for the central polygon's).
    fn ring(self, l: Label, dual: bool) -> usize {
        let r = if self.quads || dual {
            l.x.max(l.y)
        } else {
            l.x + l.y
        };
        if dual {
            (2.0 * r + 0.5).round() as usize
        } else {
            r.round() as usize
        }
    }
}

/// A fan of `n` sectors around one vertex, and for dual schemes its
/// mirror glued along the rim (whose vertices have no label); or the fan
/// of a [`Star`]: open (a boundary vertex) or with sharp edges.
pub(super) struct Fan {
    pub(super) soup: PolygonSoup,
    labels: Vec<Option<Label>>,
    lattice: Lattice,
    /// Edges made sharp for ever (soup vertices), and whether the centre
    /// is a sharp vertex.
    sharp: Vec<(u32, u32)>,
    sharp_centre: bool,
}

impl Fan {
    /// The mesh of `soup` (the fan's, or the fan's with other positions)
    /// with the fan's sharpness.
    fn mesh(&self, soup: &PolygonSoup) -> Result<Mesh, String> {
        let mut m = Mesh::from_soup(soup).map_err(|e| e.to_string())?;
        for &(a, b) in &self.sharp {
            let h = m
                .find_halfedge(VertexId(a), VertexId(b))
                .ok_or("a sharp edge of the fan is missing")?;
            m.set_edge_sharpness(h.edge(), f64::INFINITY)
                .map_err(|e| e.to_string())?;
        }
        if self.sharp_centre {
            m.set_vertex_sharpness(VertexId(0), f64::INFINITY)
                .map_err(|e| e.to_string())?;
        }
        Ok(m)
    }
}

/// The vertex a fan is built around for [`super::star::star_stencils`]: `n` faces
/// around it, the last one next to the first unless `open` (a boundary
/// vertex: edges 0 and n are boundary edges); its edges `sharp` (indices
/// 0..n, edge t between sectors t - 1 and t, sharp for ever), and whether
/// it is a sharp vertex (`corner`).
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Star {
    pub n: usize,
    pub open: bool,
    pub sharp: Vec<usize>,
    pub corner: bool,
}

impl Star {
    /// The edges that part the fan into sides: the boundary's and the
    /// sharp ones on an open fan; the sharp ones where there are two or
    /// more on a closed one; none else (one side all round).
    fn parting(&self) -> Vec<usize> {
        if self.open {
            let mut e = vec![0];
            e.extend(self.sharp.iter().copied().filter(|&t| t > 0 && t < self.n));
            e.push(self.n);
            e
        } else if self.sharp.len() >= 2 {
            self.sharp.clone()
        } else {
            Vec::new()
        }
    }

    /// True where the vertex stays (the grammars' corner rule): a sharp
    /// vertex, three or more sharp edges, or a sharp edge that meets the
    /// boundary.
    pub fn is_corner(&self) -> bool {
        self.corner
            || if self.open {
                self.sharp.iter().any(|&t| t > 0 && t < self.n)
            } else {
                self.sharp.len() >= 3
            }
    }

    /// The sides: (first sector, number of sectors), in order.
    pub fn sides(&self) -> Vec<(usize, usize)> {
        let e = self.parting();
        if e.is_empty() {
            return vec![(0, self.n)];
        }
        if self.open {
            return e.windows(2).map(|w| (w[0], w[1] - w[0])).collect();
        }
        (0..e.len())
            .map(|k| {
                let (a, b) = (e[k], e[(k + 1) % e.len()]);
                (a, (b + self.n - a - 1) % self.n + 1)
            })
            .collect()
    }
}

/// The fan of a smooth interior vertex of valence `n` (or, `closed`, the
/// closed probe of a dual scheme).
fn fan(n: usize, quads: bool, rings: usize, closed: bool) -> Fan {
    let star = Star {
        n,
        open: false,
        sharp: Vec::new(),
        corner: false,
    };
    star_fan(&star, quads, rings, closed)
}

/// The fan of `star`: on an open star the sectors span less than half a
/// turn, and the lattice's sectors do not wrap round (its `k` is larger
/// than the fan's).
pub(super) fn star_fan(star: &Star, quads: bool, rings: usize, closed: bool) -> Fan {
    let n = star.n;
    let (k, step) = if star.open {
        (n + 2, std::f64::consts::PI / (n + 1) as f64)
    } else {
        (n, TAU / n as f64)
    };
    let u = |t: usize| {
        let a = step * t as f64;
        DVec2::new(a.cos(), a.sin())
    };
    let lattice = Lattice { k, quads };
    let mut ids: HashMap<(usize, usize, usize), u32> = HashMap::new();
    let mut f = Fan {
        soup: PolygonSoup::default(),
        labels: Vec::new(),
        lattice,
        sharp: Vec::new(),
        sharp_centre: star.corner,
    };
    let mut rim = Vec::new();
    let mut id = |f: &mut Fan, t: usize, i: usize, j: usize| -> u32 {
        let key = match (i, j) {
            (0, 0) => (0, 0, 0),
            (0, _) => ((t + 1) % k, j, 0),
            _ => (t % k, i, j),
        };
        *ids.entry(key).or_insert_with(|| {
            let p = i as f64 * u(t) + j as f64 * u(t + 1);
            f.soup.positions.push(DVec3::new(p.x, p.y, 0.0));
            f.labels.push(Some(Label {
                t: key.0,
                x: key.1 as f64,
                y: key.2 as f64,
            }));
            let on_rim = if quads {
                i.max(j) == rings
            } else {
                i + j == rings
            };
            rim.push(on_rim);
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
    // Sharp edges all the way to the rim, so that the vertices on them
    // are crease vertices.
    for &e in &star.sharp {
        for j in 0..rings {
            let a = id(&mut f, e, j, 0);
            let b = id(&mut f, e, j + 1, 0);
            f.sharp.push((a, b));
        }
    }
    if closed {
        // The mirror: every vertex again, unnamed, every face turned over,
        // and a band of quads joining each rim edge to its mirror (so
        // that no two faces share two edges at the rim's corners).
        let front = f.soup.positions.len();
        for v in 0..front {
            // Wider, so that the band has area.
            let p = f.soup.positions[v];
            f.soup.positions.push(DVec3::new(1.5 * p.x, 1.5 * p.y, 0.0));
            f.labels.push(None);
        }
        let back = |v: u32| v + front as u32;
        let faces = f.soup.faces.to_vecs();
        let mut rim_edges = Vec::new();
        for face in &faces {
            let turned: Vec<u32> = face.iter().rev().map(|&v| back(v)).collect();
            f.soup.faces.push(turned);
            for a in 0..face.len() {
                let (p, q) = (face[a], face[(a + 1) % face.len()]);
                if rim[p as usize] && rim[q as usize] {
                    rim_edges.push((p, q));
                }
            }
        }
        for (p, q) in rim_edges {
            let band = [q, p, back(p), back(q)];
            if quads {
                f.soup.faces.push(band);
            } else {
                f.soup.faces.push([q, p, back(p)]);
                f.soup.faces.push([q, back(p), back(q)]);
            }
        }
    }
    f
}

/// Which step made each vertex: 0 for the fan's, 1 for the `init:`
/// rules', s + 1 for step s's.
fn generation(m: &Mesh, fan_vertices: usize, v: VertexId) -> usize {
    let s = m.vertex_step(v) as usize;
    if s == 0 && v.index() < fan_vertices {
        0
    } else {
        s + 1
    }
}

/// Names the vertices of generation `g` of `m` (see the module's text).
fn name_generation(
    m: &Mesh,
    fan_vertices: usize,
    lattice: Lattice,
    names: &mut Vec<Option<Label>>,
    g: usize,
) {
    let slots = m.vertices().map(|v| v.index() + 1).max().unwrap_or(0);
    if names.len() < slots {
        names.resize(slots, None);
    }
    let gen = |v: VertexId| generation(m, fan_vertices, v);
    let vs: Vec<VertexId> = m.vertices().filter(|&v| gen(v) == g).collect();
    let mut blocked = vec![false; slots];
    for &v in &vs {
        let older: Vec<VertexId> = m.one_ring(v).filter(|&w| gen(w) < g).collect();
        if older.is_empty() {
            continue;
        }
        let ls: Option<Vec<Label>> = older.iter().map(|w| names[w.index()]).collect();
        match ls.and_then(|ls| lattice.average(&ls)) {
            Some(l) => names[v.index()] = Some(l),
            None => blocked[v.index()] = true,
        }
    }
    loop {
        let mut changed = false;
        for &v in &vs {
            if names[v.index()].is_some() || blocked[v.index()] {
                continue;
            }
            let ls: Option<Vec<Label>> = m.one_ring(v).map(|w| names[w.index()]).collect();
            if let Some(l) = ls.and_then(|ls| lattice.average(&ls)) {
                names[v.index()] = Some(l);
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
}

/// A measured map: the old vertices (columns: their place), the new ones
/// (rows: their place) and the matrix between them.
pub(super) struct Measured {
    pub(super) cols: Vec<Label>,
    rows: Vec<Option<Label>>,
    full: DMatrix<f64>,
    /// The old mesh's edges between columns.
    edges: Vec<(usize, usize)>,
}

/// The edges between the old vertices `cols` (mesh or soup indices) that
/// `joined` lists, as pairs of positions in `cols`, each once.
fn edges_among(
    cols: &[usize],
    joined: impl Iterator<Item = (usize, usize)>,
) -> Vec<(usize, usize)> {
    let at: HashMap<usize, usize> = cols.iter().enumerate().map(|(k, &c)| (c, k)).collect();
    let mut out: Vec<(usize, usize)> = joined
        .filter_map(|(a, b)| {
            let (a, b) = (*at.get(&a)?, *at.get(&b)?);
            Some((a.min(b), a.max(b)))
        })
        .collect();
    out.sort_unstable();
    out.dedup();
    out
}

/// A run's error as the text of a skipped valence.
fn start_error(e: crate::surface::RunError) -> String {
    e.message
}

/// The positions of the vertices after `steps` steps of `g` on `soup`,
/// in id order.
fn run_primal(
    g: &Grammar,
    f: &Fan,
    soup: &PolygonSoup,
    steps: usize,
    deadline: Deadline,
) -> Result<Vec<DVec3>, String> {
    let mut m = f.mesh(soup)?;
    g.run_until(&mut m, steps, Some(deadline), |_| {})
        .map_err(start_error)?;
    Ok(m.vertices().map(|v| m.position(v)).collect())
}

/// The matrix of `steps` steps of a primal scheme on the fan: rows the
/// new vertices (in id order, with their names), columns the fan's
/// vertices within `MAX_RINGS + 1` rings (the rings an invariant
/// neighbourhood is checked against). The impulse runs must make the
/// mesh the naming run made: `fill_column` checks that every vertex stays
/// where it was in the plane.
fn measure_primal(
    g: &Grammar,
    f: &Fan,
    steps: usize,
    deadline: Deadline,
) -> Result<Measured, String> {
    let fan_vertices = f.soup.positions.len();
    // The names, step by step on one run.
    let mut m = f.mesh(&f.soup)?;
    let mut names: Vec<Option<Label>> = f.labels.clone();
    {
        let mut run = g.start(&mut m).map_err(start_error)?;
        run.set_deadline(Some(deadline));
        name_generation(run.mesh(), fan_vertices, f.lattice, &mut names, 1);
        for s in 1..=steps {
            run.steps(1, |_| {}).map_err(start_error)?;
            name_generation(run.mesh(), fan_vertices, f.lattice, &mut names, s + 1);
        }
    }
    let base: Vec<DVec3> = m.vertices().map(|v| m.position(v)).collect();
    let rows: Vec<Option<Label>> = m
        .vertices()
        .map(|v| names.get(v.index()).copied().flatten())
        .collect();
    if base.iter().any(|p| p.z.abs() > TOL) {
        return Err("a flat mesh does not stay flat: not linear".into());
    }
    // Impulses on the fan's vertices within one ring more than the
    // largest neighbourhood tried: what its invariance is checked against.
    let cols: Vec<usize> = (0..fan_vertices)
        .filter(|&c| f.labels[c].is_some_and(|l| f.lattice.ring(l, false) <= MAX_RINGS + 1))
        .collect();
    let outs: Vec<Vec<DVec3>> = cols
        .par_iter()
        .map(|&c| {
            deadline.check()?;
            let mut soup = f.soup.clone();
            soup.positions[c].z = 1.0;
            run_primal(g, f, &soup, steps, deadline)
        })
        .collect::<Result<_, String>>()?;
    let mut s = DMatrix::zeros(base.len(), cols.len());
    for (k, out) in outs.iter().enumerate() {
        fill_column(&mut s, k, &base, out)?;
    }
    let faces = f.soup.faces.to_vecs();
    let edges = edges_among(
        &cols,
        faces.iter().flat_map(|face| {
            (0..face.len()).map(|a| (face[a] as usize, face[(a + 1) % face.len()] as usize))
        }),
    );
    Ok(Measured {
        cols: cols
            .iter()
            .map(|&c| f.labels[c].unwrap_or(CENTRE))
            .collect(),
        rows,
        full: s,
        edges,
    })
}

fn fill_column(
    s: &mut DMatrix<f64>,
    c: usize,
    base: &[DVec3],
    out: &[DVec3],
) -> Result<(), String> {
    if out.len() != base.len() {
        return Err("the number of vertices depends on the positions".into());
    }
    for (r, p) in out.iter().enumerate() {
        if (p.truncate() - base[r].truncate()).length() > TOL {
            return Err("a height moves vertices sideways: not linear".into());
        }
        s[(r, c)] = p.z - base[r].z;
    }
    Ok(())
}

/// A dual scheme's step from the polygons' corners after one step on the
/// closed fan to the corners after the next: rows the new corners (with
/// their names), columns the old corners within `MAX_RINGS + 1` rings of
/// corners (the rings an invariant neighbourhood is checked against).
fn measure_dual(g: &Grammar, f: &Fan, deadline: Deadline) -> Result<Measured, String> {
    let fan_vertices = f.soup.positions.len();
    let mut names: Vec<Option<Label>> = f.labels.clone();
    // The corners after one step, and after two, with their names.
    let mut m = Mesh::from_soup(&f.soup).map_err(|e| e.to_string())?;
    let (old, new, base, vertex_count, edges) = {
        let mut run = g.start(&mut m).map_err(start_error)?;
        run.set_deadline(Some(deadline));
        name_generation(run.mesh(), fan_vertices, f.lattice, &mut names, 1);
        run.steps(1, |_| {}).map_err(start_error)?;
        name_generation(run.mesh(), fan_vertices, f.lattice, &mut names, 2);
        let m1 = run.mesh();
        let old: Vec<(VertexId, Label)> = m1
            .vertices()
            .filter(|&v| !m1.is_block_centre(v))
            .filter_map(|v| Some((v, names.get(v.index()).copied().flatten()?)))
            .filter(|&(_, l)| f.lattice.ring(l, true) <= MAX_RINGS + 1)
            .collect();
        let ids: Vec<usize> = old.iter().map(|(v, _)| v.index()).collect();
        let edges = edges_among(
            &ids,
            m1.edges().map(|e| {
                let (a, b) = m1.edge_vertices(e);
                (a.index(), b.index())
            }),
        );
        run.steps(1, |_| {}).map_err(start_error)?;
        name_generation(run.mesh(), fan_vertices, f.lattice, &mut names, 3);
        let m2 = run.mesh();
        let new: Vec<VertexId> = m2
            .vertices()
            .filter(|&v| generation(m2, fan_vertices, v) == 3 && !m2.is_block_centre(v))
            .collect();
        let base: Vec<DVec3> = new.iter().map(|&v| m2.position(v)).collect();
        (old, new, base, m2.vertex_count(), edges)
    };
    if base.iter().any(|p| p.z.abs() > TOL) {
        return Err("a flat mesh does not stay flat: not linear".into());
    }
    let outs: Vec<Vec<DVec3>> = old
        .par_iter()
        .map(|&(v, _)| impulse_dual(g, f, v, &new, vertex_count, deadline))
        .collect::<Result<_, String>>()?;
    let mut s = DMatrix::zeros(new.len(), old.len());
    for (c, out) in outs.iter().enumerate() {
        fill_column(&mut s, c, &base, out)?;
    }
    Ok(Measured {
        cols: old.iter().map(|&(_, l)| l).collect(),
        rows: new
            .iter()
            .map(|v| names.get(v.index()).copied().flatten())
            .collect(),
        full: s,
        edges,
    })
}

/// The corners `new` after a dual scheme's second step, with an impulse
/// on corner `v` after the first.
fn impulse_dual(
    g: &Grammar,
    f: &Fan,
    v: VertexId,
    new: &[VertexId],
    vertex_count: usize,
    deadline: Deadline,
) -> Result<Vec<DVec3>, String> {
    deadline.check()?;
    let mut m = Mesh::from_soup(&f.soup).map_err(|e| e.to_string())?;
    let mut run = g.start(&mut m).map_err(start_error)?;
    run.set_deadline(Some(deadline));
    run.steps(1, |_| {}).map_err(start_error)?;
    // The impulse on a corner, and on the centres of the blocks it is a
    // corner of, which stand at their polygons' centroids (as the files'
    // `init:` and `center(v)` rules put them).
    let m1 = run.mesh();
    let lift: Vec<(VertexId, f64)> = std::iter::once((v, 1.0))
        .chain(
            m1.one_ring(v)
                .filter(|&w| m1.is_block_centre(w))
                .map(|w| (w, 1.0 / m1.valence(w) as f64)),
        )
        .collect();
    for (w, z) in lift {
        let p = run.mesh().position(w);
        run.set_position(w, DVec3::new(p.x, p.y, p.z + z));
    }
    run.steps(1, |_| {}).map_err(start_error)?;
    let m2 = run.mesh();
    if m2.vertex_count() != vertex_count || new.iter().any(|&w| !m2.is_vertex(w)) {
        return Err("the number of vertices depends on the positions".into());
    }
    Ok(new.iter().map(|&w| m2.position(w)).collect())
}

/// A local matrix, its columns (indices into `Measured::cols`) and its
/// ring count.
pub(super) type Hood = (DMatrix<f64>, Vec<usize>, usize);

/// The local matrices in the invariant neighbourhoods of at most
/// [`MAX_RINGS`] rings, smallest first, with their columns and ring
/// counts: the old places within r rings, and the new vertices at the
/// same places over `scale`.
fn local(m: &Measured, lattice: Lattice, scale: usize, dual: bool) -> Option<Vec<Hood>> {
    let mut new_at: HashMap<(usize, i64, i64), usize> = HashMap::new();
    for (r, l) in m.rows.iter().enumerate() {
        let Some(l) = l else { continue };
        if new_at.insert(l.key(scale as f64), r).is_some() {
            // Two new vertices claim one name: keep none.
            new_at.insert(l.key(scale as f64), usize::MAX);
        }
    }
    let mut found = Vec::new();
    for rings in 1..=MAX_RINGS {
        let set: Vec<usize> = (0..m.cols.len())
            .filter(|&c| lattice.ring(m.cols[c], dual) <= rings)
            .collect();
        if set.is_empty() {
            continue;
        }
        let rows: Option<Vec<usize>> = set
            .iter()
            .map(|&c| {
                new_at
                    .get(&m.cols[c].key(1.0))
                    .copied()
                    .filter(|&r| r != usize::MAX)
            })
            .collect();
        let Some(rows) = rows else { continue };
        let inside: Vec<bool> = (0..m.cols.len()).map(|c| set.contains(&c)).collect();
        let invariant = rows.iter().all(|&r| {
            (0..m.cols.len())
                .filter(|&c| !inside[c])
                .all(|c| m.full[(r, c)].abs() <= TOL)
        });
        if invariant {
            let s = DMatrix::from_fn(set.len(), set.len(), |a, b| m.full[(rows[a], set[b])]);
            found.push((s, set, rings));
        }
    }
    (!found.is_empty()).then_some(found)
}

/// The eigenvalues of `s`, largest modulus first.
pub(super) fn spectrum(s: &DMatrix<f64>) -> Option<Vec<Eigenvalue>> {
    let mut eig: Vec<Eigenvalue> = eigenvalues(s)?
        .iter()
        .map(|c| Eigenvalue {
            re: c.re,
            im: c.im,
            modulus: c.norm(),
        })
        .collect();
    eig.sort_by(|a, b| b.modulus.total_cmp(&a.modulus).then(b.re.total_cmp(&a.re)));
    Some(eig)
}

pub(super) fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-7
}

/// 1 = λ0 > λ1 = λ2 > |λ3|, λ1 real and positive.
fn reif(eig: &[Eigenvalue]) -> bool {
    let (Some(l0), Some(l1), Some(l2)) = (eig.first(), eig.get(1), eig.get(2)) else {
        return false;
    };
    let l3 = eig.get(3).map_or(0.0, |x| x.modulus);
    close(l0.re, 1.0)
        && close(l0.im, 0.0)
        && close(l1.im, 0.0)
        && close(l2.im, 0.0)
        && close(l1.re, l2.re)
        && l1.re < 1.0 - 1e-7
        && l1.re > 0.0
        && l3 < l1.re - 1e-7
}

/// The characteristic net of the local matrix `s` on the columns `set`
/// of `m` (see [`CharacteristicNet`]), when its λ1 = λ2 is real.
fn characteristic(s: &DMatrix<f64>, set: &[usize], m: &Measured) -> Option<CharacteristicNet> {
    let eig = spectrum(s)?;
    let (l1, l2) = (eig.get(1)?, eig.get(2)?);
    if !(close(l1.im, 0.0) && close(l2.im, 0.0) && close(l1.re, l2.re)) {
        return None;
    }
    let n = s.nrows();
    let svd = (s - DMatrix::identity(n, n) * l1.re).svd(false, true);
    let v_t = svd.v_t?;
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&x, &y| svd.singular_values[x].total_cmp(&svd.singular_values[y]));
    let (a, b) = (v_t.row(order[0]), v_t.row(order[1]));
    // Round: the inverse square root of the points' second moment.
    let mut moment = nalgebra::Matrix2::<f64>::zeros();
    for k in 0..n {
        let p = nalgebra::Vector2::new(a[k], b[k]);
        moment += p * p.transpose();
    }
    let e = moment.symmetric_eigen();
    if e.eigenvalues.min() <= 1e-12 {
        return None;
    }
    let inv = e.eigenvectors
        * nalgebra::Matrix2::from_diagonal(&e.eigenvalues.map(|x| 1.0 / x.sqrt()))
        * e.eigenvectors.transpose();
    let points = (0..n)
        .map(|k| {
            let p = inv * nalgebra::Vector2::new(a[k], b[k]);
            [p.x, p.y]
        })
        .collect();
    let at: HashMap<usize, usize> = set.iter().enumerate().map(|(k, &c)| (c, k)).collect();
    let edges = m
        .edges
        .iter()
        .filter_map(|&(a, b)| Some([*at.get(&a)?, *at.get(&b)?]))
        .collect();
    let places = set
        .iter()
        .map(|&c| Place {
            sector: m.cols[c].t,
            i: m.cols[c].x,
            j: m.cols[c].y,
        })
        .collect();
    Some(CharacteristicNet {
        places,
        points,
        edges,
    })
}

/// The left null vectors of `s - λ I` (as many as `count`), from the SVD.
pub(super) fn left_null(s: &DMatrix<f64>, lambda: f64, count: usize) -> Vec<Vec<f64>> {
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

pub(super) fn label_weights(cols: &[Label], set: &[usize], v: &[f64]) -> Vec<LabelWeight> {
    set.iter()
        .zip(v)
        .map(|(&c, &w)| {
            let l = cols[c];
            LabelWeight {
                sector: l.t,
                i: l.x,
                j: l.y,
                weight: w,
                fraction: fraction(w),
            }
        })
        .collect()
}

/// What [`measure`] finds: the steps and the scale of the measured map,
/// its invariant neighbourhoods (smallest first) and the map itself.
pub(super) type Found = (usize, usize, Vec<Hood>, Measured);

/// One or two steps of `g` measured on the fan `f` by impulses, and the
/// invariant neighbourhoods in it; `Ok(Err(why))` where there is none.
pub(super) fn measure(
    g: &Grammar,
    f: &Fan,
    dual: bool,
    deadline: Deadline,
    budget: Deadline,
) -> Result<Result<Found, String>, Error> {
    let mut why = String::new();
    let limit = if budget.limit() < deadline.limit() {
        budget
    } else {
        deadline
    };
    let tries: &[usize] = if dual { &[1] } else { &[1, 2] };
    for &steps in tries {
        let measured = if dual {
            measure_dual(g, f, limit)
        } else {
            measure_primal(g, f, steps, limit)
        };
        match measured {
            Ok(m) => {
                if let Some((scale, hoods)) = [2, 3]
                    .iter()
                    .find_map(|&scale| Some((scale, local(&m, f.lattice, scale, dual)?)))
                {
                    return Ok(Ok((steps, scale, hoods, m)));
                }
                why = format!(
                    "no invariant neighbourhood of at most {MAX_RINGS} rings whose new vertices \
                     stand at a half or a third of the spacing after {}",
                    if dual { "one step" } else { "one or two steps" }
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
    Ok(Err(why))
}

fn valence(
    g: &Grammar,
    n: usize,
    quads: bool,
    dual: bool,
    deadline: Deadline,
    budget: Deadline,
) -> Result<Valence, Error> {
    let f = fan(n, quads, FAN_RINGS, dual);
    let mut v = Valence {
        n,
        skipped: None,
        steps: 0,
        scale: 0,
        rings: 0,
        size: 0,
        affine: false,
        eigenvalues: Vec::new(),
        reif: false,
        limit: Vec::new(),
        tangents: Vec::new(),
        places: Vec::new(),
        matrix: Vec::new(),
        wider: None,
        characteristic: None,
    };
    let (steps, scale, mut hoods, measured) = match measure(g, &f, dual, deadline, budget)? {
        Ok(found) => found,
        Err(why) => {
            v.skipped = Some(why);
            return Ok(v);
        }
    };
    let wider = (hoods.len() > 1).then(|| hoods.remove(1));
    let (s, set, rings) = hoods.swap_remove(0);
    v.characteristic = match &wider {
        Some((w, wset, _)) => characteristic(w, wset, &measured),
        None => characteristic(&s, &set, &measured),
    };
    let cols = &measured.cols;
    v.steps = steps;
    v.scale = scale;
    v.rings = rings;
    v.size = set.len();
    v.affine = (0..s.nrows()).all(|r| (s.row(r).sum() - 1.0).abs() <= TOL);
    v.places = set
        .iter()
        .map(|&c| Place {
            sector: cols[c].t,
            i: cols[c].x,
            j: cols[c].y,
        })
        .collect();
    v.matrix = s.row_iter().map(|r| r.iter().copied().collect()).collect();
    let Some(mut eig) = spectrum(&s) else {
        v.skipped = Some(format!(
            "the eigenvalues of the {0}×{0} matrix did not converge",
            s.nrows()
        ));
        return Ok(v);
    };
    v.reif = reif(&eig);
    if let (Some(l0), Some(l1), Some(l2)) = (eig.first(), eig.get(1), eig.get(2)) {
        if close(l0.re, 1.0) && close(l0.im, 0.0) {
            if let Some(w) = left_null(&s, 1.0, 1).pop() {
                let sum: f64 = w.iter().sum();
                if sum.abs() > TOL {
                    let w: Vec<f64> = w.iter().map(|x| x / sum).collect();
                    v.limit = label_weights(cols, &set, &w);
                }
            }
        }
        if close(l1.im, 0.0) && close(l2.im, 0.0) && close(l1.re, l2.re) {
            v.tangents = left_null(&s, l1.re, 2)
                .iter()
                .map(|w| label_weights(cols, &set, w))
                .collect();
        }
    }
    if let Some((w, _, rings)) = wider {
        if let Some(mut e) = spectrum(&w) {
            let reif = reif(&e);
            e.truncate(LISTED);
            v.wider = Some(Wider {
                rings,
                size: w.nrows(),
                eigenvalues: e,
                reif,
            });
        }
    }
    eig.truncate(LISTED);
    v.eigenvalues = eig;
    Ok(v)
}

/// Analyses the surface grammar `g` (its file `path`, for messages) at
/// the valences [`VALENCES`].
pub fn analyze(g: &Grammar, path: &str, deadline: Deadline) -> Result<SurfaceReport, Error> {
    let all: Vec<usize> = VALENCES.collect();
    analyze_at(g, path, deadline, &all, &mut |_, _| {})
}

/// [`analyze`] at the valences `ns` only (each at least 3).
pub fn analyze_at(
    g: &Grammar,
    path: &str,
    deadline: Deadline,
    ns: &[usize],
    on_valence: &mut dyn FnMut(usize, usize),
) -> Result<SurfaceReport, Error> {
    let _ = path;
    let mut notes = Vec::new();
    let quads = g.block_used_at.is_some();
    let dual = g.dual_at.is_some();
    let faces = if quads { "quads" } else { "triangles" }.to_string();
    let around = if dual { "face" } else { "vertex" }.to_string();
    if g.adaptive.is_some() {
        notes.push(
            "an adaptive grammar (`adaptive;`): which blocks split depends on the positions \
             (its guards), so a step is not one linear map of the points and there is no \
             subdivision matrix to measure; where every block is selected it is the \
             uniform scheme of its rules"
                .to_string(),
        );
        return Ok(SurfaceReport {
            faces,
            around,
            valences: Vec::new(),
            notes,
        });
    }
    if dual {
        notes.push(
            "a dual scheme: measured around the n-gon that one step makes around a vertex of \
             valence n, from its corners (and the rings of corners around it) to the corners \
             of the next step's n-gon; places (s, i, j) of corners stand at quarters of the \
             coarse fan's spacing"
                .to_string(),
        );
    }
    let mut valences = Vec::new();
    let budget = Deadline::after(BUDGET);
    for &n in ns {
        if n < 3 {
            return Err(Error::Failed(format!(
                "valence {n}: a fan needs at least 3 sectors"
            )));
        }
        valences.push(valence(g, n, quads, dual, deadline, budget)?);
        on_valence(valences.len(), ns.len());
    }
    for v in valences.iter().filter(|v| v.skipped.is_none()) {
        if !v.reif {
            notes.push(format!(
                "Reif's check fails at valence {}: the scheme is not shown C1 there",
                v.n
            ));
        } else if let Some(w) = v.wider.as_ref().filter(|w| !w.reif) {
            notes.push(format!(
                "Reif's check fails at valence {} on the neighbourhood of {} rings: what the \
                 outer ring adds has a modulus not below λ1 ({:.6} against {:.6}), so this \
                 check does not show the scheme C1 there",
                v.n,
                w.rings,
                w.eigenvalues.get(3).map_or(0.0, |e| e.modulus),
                w.eigenvalues.get(1).map_or(0.0, |e| e.re),
            ));
        }
    }
    Ok(SurfaceReport {
        faces,
        around,
        valences,
        notes,
    })
}
