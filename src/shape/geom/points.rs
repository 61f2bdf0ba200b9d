//! All points of a derivation: [`Points`], with the cut points that the
//! shapes on both sides of a cut share.

use std::collections::HashMap;

use glam::DVec3;

use super::{show, PointId, MAX_COORD};

/// The most points one derivation may hold.
pub(crate) const MAX_POINTS: usize = 50_000_000;

/// The cell size of the index of cut points by position: two cut points
/// closer than this (and than 1e-10 of their magnitude) are one point.
const GRID: f64 = 1e-6;

/// A root edge: the segment that cut points lie on, its canonical end
/// first (the end with the lexicographically smaller position, ties by id).
type Root = (PointId, PointId);

/// All points of one derivation.
///
/// A shape's vertices shared with its parent, children and siblings are the
/// ids they have in common: that is the paper's connectivity map.
///
/// Every cut point records its root edge (an edge whose ends are not cut
/// points of one common edge) and its parameter along it from the
/// canonical end. A cut of any piece of a root by a plane is looked up by
/// (root, plane), so the same geometric point gets the same id whichever
/// piece, face or shape asks, and its position, computed on the root from
/// the canonical end, does not depend on the order shapes were cut in.
#[derive(Clone, Debug, Default)]
pub(crate) struct Points {
    pub pos: Vec<DVec3>,
    /// A root edge -> the cut points on it, sorted by their parameter.
    cuts: HashMap<Root, Vec<(f64, PointId)>>,
    /// A cut point -> its root edges and its parameters along them: the
    /// root it was made on, then any root crossing it that a later cut
    /// reached it along (where two lines of cuts cross in a face).
    root: HashMap<PointId, Vec<(Root, f64)>>,
    /// The cut points by position (cells of [`GRID`]), to find the point
    /// where two lines of cuts cross whichever line reaches it.
    grid: HashMap<[i64; 3], Vec<PointId>>,
    /// (root, the exact bits of the plane's normal and offset) -> the cut
    /// point that plane put on that root.
    planes: HashMap<(Root, [u64; 4]), PointId>,
}

impl Points {
    pub fn new() -> Points {
        Points::default()
    }

    /// How many points there are.
    pub fn len(&self) -> usize {
        self.pos.len()
    }

    pub fn is_empty(&self) -> bool {
        self.pos.is_empty()
    }

    /// The position of `id` (NaN for an id that is not a point).
    pub fn get(&self, id: PointId) -> DVec3 {
        self.pos.get(id as usize).copied().unwrap_or(DVec3::NAN)
    }

    /// A new point. Refused past [`MAX_POINTS`] and for a position that is
    /// not finite or has a coordinate beyond [`MAX_COORD`].
    pub fn add(&mut self, p: DVec3) -> Result<PointId, String> {
        if !p.is_finite() {
            return Err(format!(
                "a point at ({}, {}, {}) is not finite",
                p.x, p.y, p.z
            ));
        }
        if p.abs().max_element() > MAX_COORD {
            return Err(format!(
                "a point at ({}, {}, {}) is farther than {MAX_COORD:e} from the origin along an \
                 axis; shapes stay within that",
                show(p.x),
                show(p.y),
                show(p.z)
            ));
        }
        if self.pos.len() >= MAX_POINTS {
            return Err(format!(
                "the shapes have more than {MAX_POINTS} points; the grammar makes too much geometry"
            ));
        }
        self.pos.push(p);
        Ok((self.pos.len() - 1) as PointId)
    }

    pub(super) fn check(&self, id: PointId) -> Result<(), String> {
        if (id as usize) < self.pos.len() {
            Ok(())
        } else {
            Err(format!("point {id} does not exist"))
        }
    }

    /// Edge (a, b) with its canonical end first: the lexicographically
    /// smaller position (x, then y, then z), ties by id. By geometry, so
    /// that it does not depend on the order points were made in.
    fn canonical(&self, a: PointId, b: PointId) -> Root {
        let (pa, pb) = (self.get(a), self.get(b));
        let ord = |x: f64, y: f64| x.partial_cmp(&y).unwrap_or(std::cmp::Ordering::Equal);
        let o = ord(pa.x, pb.x)
            .then(ord(pa.y, pb.y))
            .then(ord(pa.z, pb.z))
            .then(a.cmp(&b));
        if o == std::cmp::Ordering::Greater {
            (b, a)
        } else {
            (a, b)
        }
    }

    /// Whether cut point `p` lies on root `r` (was made or found on it).
    fn on_root(&self, p: PointId, r: Root) -> bool {
        self.root
            .get(&p)
            .is_some_and(|rs| rs.iter().any(|e| e.0 == r))
    }

    /// The root edge that edge (a, b) lies on: a root of a or b when the
    /// other is an end or a cut point of that same root, else (a, b)
    /// itself (canonically ordered).
    fn line_of(&self, a: PointId, b: PointId) -> Root {
        for (x, y) in [(a, b), (b, a)] {
            if let Some(rs) = self.root.get(&y) {
                for &(r, _) in rs {
                    if x == r.0 || x == r.1 || self.on_root(x, r) {
                        return r;
                    }
                }
            }
        }
        self.canonical(a, b)
    }

    fn cell(p: DVec3) -> [i64; 3] {
        let c = (p / GRID).floor();
        [c.x as i64, c.y as i64, c.z as i64]
    }

    /// A cut point within `tol` of `p`, if any.
    fn near(&self, p: DVec3, tol: f64) -> Option<PointId> {
        let c = Self::cell(p);
        let mut best: Option<(f64, PointId)> = None;
        for dx in -1..=1i64 {
            for dy in -1..=1i64 {
                for dz in -1..=1i64 {
                    let k = [
                        c[0].saturating_add(dx),
                        c[1].saturating_add(dy),
                        c[2].saturating_add(dz),
                    ];
                    for &q in self.grid.get(&k).map(Vec::as_slice).unwrap_or(&[]) {
                        let e = (self.get(q) - p).abs().max_element();
                        if e <= tol && best.is_none_or(|(b, _)| e < b) {
                            best = Some((e, q));
                        }
                    }
                }
            }
        }
        best.map(|(_, q)| q)
    }

    /// The parameter of `p` along root edge `r` (0 at r.0, 1 at r.1).
    fn param(&self, r: Root, p: PointId) -> f64 {
        if p == r.0 {
            return 0.0;
        }
        if p == r.1 {
            return 1.0;
        }
        match self
            .root
            .get(&p)
            .and_then(|rs| rs.iter().find(|e| e.0 == r))
        {
            Some(&(_, t)) => t,
            None => {
                let (a, b) = (self.get(r.0), self.get(r.1));
                let l2 = (b - a).length_squared();
                if l2 > 0.0 {
                    (self.get(p) - a).dot(b - a) / l2
                } else {
                    0.0
                }
            }
        }
    }

    /// The point where the plane {x : n·x = d} crosses edge (a, b), made
    /// once per root edge and plane: the same id whichever piece of the
    /// root, face or shape asks, at a position computed on the root from
    /// its canonical end (bit-identical whatever the direction or the
    /// order asked). A point of another plane within rounding of it on
    /// the same root is taken as the same point.
    pub fn cut(&mut self, a: PointId, b: PointId, n: DVec3, d: f64) -> Result<PointId, String> {
        self.check(a)?;
        self.check(b)?;
        if a == b {
            return Ok(a);
        }
        let r = self.line_of(a, b);
        let key = (
            r,
            [n.x.to_bits(), n.y.to_bits(), n.z.to_bits(), d.to_bits()],
        );
        if let Some(&q) = self.planes.get(&key) {
            return Ok(q);
        }
        let (ta, tb) = (self.param(r, a), self.param(r, b));
        let (tmin, tmax) = (ta.min(tb), ta.max(tb));
        let (pa, pb) = (self.get(r.0), self.get(r.1));
        let (da, db) = (n.dot(pa) - d, n.dot(pb) - d);
        let mut t = da / (da - db);
        if !t.is_finite() {
            t = 0.5 * (ta + tb);
        }
        let t = t.clamp(0.0, 1.0);
        let p = pa + t * (pb - pa);
        // The same point reached along another line (two lines of cuts
        // crossing), or made by another plane within rounding.
        let tol = (1e-10 * (1.0 + p.abs().max_element())).min(GRID);
        if let Some(q) = self.near(p, tol) {
            let tq = self.param(r, q);
            if tq > tmin && tq < tmax {
                if !self.on_root(q, r) {
                    let list = self.cuts.entry(r).or_default();
                    let at = list.partition_point(|&(u, _)| u < tq);
                    list.insert(at, (tq, q));
                    self.root.entry(q).or_default().push((r, tq));
                }
                self.planes.insert(key, q);
                return Ok(q);
            }
        }
        let id = self.add(p)?;
        let list = self.cuts.entry(r).or_default();
        let at = list.partition_point(|&(u, _)| u < t);
        list.insert(at, (t, id));
        self.root.insert(id, vec![(r, t)]);
        self.grid.entry(Self::cell(p)).or_default().push(id);
        self.planes.insert(key, id);
        Ok(id)
    }

    /// `poly` with every point that cuts put on its edges inserted in
    /// order, cuts on cuts included: faces of neighbouring shapes then meet
    /// without T-junctions. `out` is cleared first.
    pub fn resolve(&self, poly: &[PointId], out: &mut Vec<PointId>) {
        out.clear();
        let m = poly.len();
        for i in 0..m {
            let (a, b) = (poly[i], poly[(i + 1) % m]);
            out.push(a);
            if a == b {
                continue;
            }
            let r = self.line_of(a, b);
            let Some(list) = self.cuts.get(&r) else {
                continue;
            };
            let (ta, tb) = (self.param(r, a), self.param(r, b));
            let (tmin, tmax) = (ta.min(tb), ta.max(tb));
            let lo = list.partition_point(|&(t, _)| t <= tmin);
            let hi = list.partition_point(|&(t, _)| t < tmax);
            if lo >= hi {
                continue;
            }
            let inner = list[lo..hi]
                .iter()
                .map(|&(_, q)| q)
                .filter(|&q| q != a && q != b);
            if ta <= tb {
                out.extend(inner);
            } else {
                let v: Vec<PointId> = inner.collect();
                out.extend(v.into_iter().rev());
            }
        }
    }
}
