//! The geometry kernel of shape grammars (paper 003): points shared by every
//! shape of a derivation, a shape's geometry (faces, edges or points), its
//! scope, plane cuts and splits with caps, primitives, extrusion, component
//! selection and the welding of a smoothing group into one polygon soup.
//!
//! Shapes hold [`PointId`]s into one [`Points`]; two shapes that hold the
//! same id share that vertex. Cuts are made once per edge and plane, so the
//! shapes on both sides of a cut, and siblings cut by the same plane, share
//! the cut points; [`Points::resolve`] inserts the cut points that lie on a
//! polygon's edges so that neighbours meet without T-junctions.
//!
//! Nothing here panics on bad input: degenerate geometry gives an empty
//! result or an `Err` with a message.
#![allow(dead_code)]

use std::collections::{HashMap, HashSet};

use glam::{DAffine3, DMat3, DVec3};

use crate::mesh::PolygonSoup;

/// The index of a point in [`Points`].
pub(crate) type PointId = u32;

/// The most points one derivation may hold.
pub(crate) const MAX_POINTS: usize = 50_000_000;

/// A number for a message: plain, or in scientific notation when it is
/// very large or very small (1e308 is not 309 digits).
pub(crate) fn show(x: f64) -> String {
    if x != 0.0 && x.is_finite() && !(1e-4..1e9).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// The largest coordinate a point may have: far beyond any model (in
/// metres, the orbit of Neptune is 4.5e12), near enough to zero that areas,
/// volumes and normals of shapes stay finite and precise.
pub(crate) const MAX_COORD: f64 = 1e15;

/// The cell size of the index of cut points by position: two cut points
/// closer than this (and than 1e-10 of their magnitude) are one point.
const GRID: f64 = 1e-6;

/// The most segments (or slices, stacks) a round primitive may have.
pub(crate) const MAX_SEGMENTS: usize = 1 << 16;

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

    fn check(&self, id: PointId) -> Result<(), String> {
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

/// A polygon of a shape.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Face {
    /// Counter-clockwise seen from outside (3D) or from the side the
    /// normal points to (2D).
    pub pts: Vec<PointId>,
    /// 0: the shape's own surface. 2k: the cap cut k made on its lower
    /// side, 2k + 1: the same cap on its upper side (the same ids,
    /// reversed).
    pub seam: u32,
}

/// A shape's geometry: a polyhedron (dim 3) or faces (dim 2), edges (dim 1)
/// or points (dim 0).
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Geometry {
    pub dim: u8,
    pub faces: Vec<Face>,
    pub edges: Vec<[PointId; 2]>,
    pub verts: Vec<PointId>,
}

impl Geometry {
    pub fn empty(dim: u8) -> Geometry {
        Geometry {
            dim,
            faces: Vec::new(),
            edges: Vec::new(),
            verts: Vec::new(),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.faces.is_empty() && self.edges.is_empty() && self.verts.is_empty()
    }

    /// Every point id the geometry uses, once per use (faces, then edges,
    /// then points).
    pub fn point_ids(&self) -> impl Iterator<Item = PointId> + '_ {
        self.faces
            .iter()
            .flat_map(|f| f.pts.iter().copied())
            .chain(self.edges.iter().flat_map(|e| e.iter().copied()))
            .chain(self.verts.iter().copied())
    }

    /// Every point id the geometry uses, once, in first-use order.
    pub fn unique_points(&self) -> Vec<PointId> {
        let mut seen = HashSet::new();
        self.point_ids().filter(|&p| seen.insert(p)).collect()
    }

    pub fn face_count(&self) -> usize {
        self.faces.len()
    }

    /// Its elements: faces, edges and points, what a shape holds.
    pub fn elements(&self) -> usize {
        self.faces.len() + self.edges.len() + self.verts.len()
    }
}

/// A shape's frame: origin, orthonormal right-handed axes x, y, z and the
/// size along them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Scope {
    pub origin: DVec3,
    pub axes: [DVec3; 3],
    pub size: DVec3,
}

impl Scope {
    /// The world frame at the origin, of size 0.
    pub fn world() -> Scope {
        Scope {
            origin: DVec3::ZERO,
            axes: [DVec3::X, DVec3::Y, DVec3::Z],
            size: DVec3::ZERO,
        }
    }

    /// The coordinates of world point `p` in the scope's frame.
    pub fn local(&self, p: DVec3) -> DVec3 {
        let v = p - self.origin;
        DVec3::new(
            v.dot(self.axes[0]),
            v.dot(self.axes[1]),
            v.dot(self.axes[2]),
        )
    }

    /// The world point at coordinates `l` in the scope's frame (named
    /// `to_world` because `world()` makes the world scope).
    pub fn to_world(self, l: DVec3) -> DVec3 {
        self.origin + l.x * self.axes[0] + l.y * self.axes[1] + l.z * self.axes[2]
    }

    fn is_right_handed(&self) -> bool {
        self.axes[0].cross(self.axes[1]).dot(self.axes[2]) >= 0.0
    }
}

/// The polygon's normal by Newell's method (its length is twice the area).
pub(crate) fn newell(points: &Points, poly: &[PointId]) -> DVec3 {
    let m = poly.len();
    let mut n = DVec3::ZERO;
    for i in 0..m {
        let a = points.get(poly[i]);
        let b = points.get(poly[(i + 1) % m]);
        n += DVec3::new(
            (a.y - b.y) * (a.z + b.z),
            (a.z - b.z) * (a.x + b.x),
            (a.x - b.x) * (a.y + b.y),
        );
    }
    n
}

fn check_plane(n: DVec3, d: f64, eps: f64) -> Result<(), String> {
    if !n.is_finite() || n.length_squared() == 0.0 || !d.is_finite() || !eps.is_finite() {
        return Err(format!(
            "a cut plane needs a finite non-zero normal and offset (got normal ({}, {}, {}), offset {d})",
            n.x, n.y, n.z
        ));
    }
    Ok(())
}

fn seam_pair(cut: u32) -> Result<(u32, u32), String> {
    if cut == 0 || cut > (u32::MAX - 1) / 2 {
        return Err(format!("cut number {cut} is out of range"));
    }
    Ok((2 * cut, 2 * cut + 1))
}

/// One node of a face's ring while it is split: a vertex, or the point
/// where an edge crosses the plane.
#[derive(Clone, Copy)]
struct Node {
    id: PointId,
    /// For a vertex: -1 below, 0 on, 1 above. Unused for a crossing.
    side: i8,
    /// For a crossing: Some(true) from above to below, Some(false) from
    /// below to above.
    down: Option<bool>,
    /// Where a crossing lies along the cut line, and the tie-break for two
    /// crossings at one on-plane vertex.
    key: (f64, f64),
}

/// Splits one polygon (any shape) by the plane: every piece on each side.
/// On-plane vertices count as infinitesimally below for the topology (so
/// every crossing is proper) and stand for their own crossing points.
fn split_polygon(
    points: &mut Points,
    face: &Face,
    (n, d): (DVec3, f64),
    s: &[f64],
    side: &[i8],
    below: &mut Vec<Face>,
    above: &mut Vec<Face>,
) -> Result<(), String> {
    let pts = &face.pts;
    let m = pts.len();
    let dir = n.cross(newell(points, pts));
    let mut ring: Vec<Node> = Vec::with_capacity(m * 2);
    for i in 0..m {
        let j = (i + 1) % m;
        ring.push(Node {
            id: pts[i],
            side: side[i],
            down: None,
            key: (0.0, 0.0),
        });
        let (bi, bj) = (side[i] <= 0, side[j] <= 0);
        if bi == bj {
            continue;
        }
        let (lo, hi) = if bi { (i, j) } else { (j, i) };
        let (id, tie) = if side[lo] == 0 {
            let v = points.get(pts[lo]);
            (pts[lo], dir.dot(points.get(pts[hi]) - v) / s[hi])
        } else {
            (points.cut(pts[i], pts[j], n, d)?, 0.0)
        };
        ring.push(Node {
            id,
            side: 0,
            down: Some(!bi),
            key: (dir.dot(points.get(id)), tie),
        });
    }
    let mut crossings: Vec<usize> = (0..ring.len())
        .filter(|&i| ring[i].down.is_some())
        .collect();
    if !crossings.len().is_multiple_of(2) {
        return Err("a face crosses a cut plane an odd number of times".into());
    }
    crossings.sort_by(|&a, &b| {
        let (ka, kb) = (ring[a].key, ring[b].key);
        ka.0.total_cmp(&kb.0).then(ka.1.total_cmp(&kb.1))
    });
    let mut partner = vec![usize::MAX; ring.len()];
    for pair in crossings.chunks(2) {
        partner[pair[0]] = pair[1];
        partner[pair[1]] = pair[0];
    }
    let len = ring.len();
    for (entering_down, side_sign, out) in [(true, -1i8, &mut *below), (false, 1i8, &mut *above)] {
        let mut visited = vec![false; len];
        for start in 0..len {
            if ring[start].down != Some(entering_down) || visited[start] {
                continue;
            }
            let mut piece: Vec<PointId> = Vec::new();
            let mut strict = false;
            let mut i = start;
            let mut steps = 0usize;
            loop {
                visited[i] = true;
                piece.push(ring[i].id);
                i = (i + 1) % len;
                while ring[i].down != Some(!entering_down) {
                    if ring[i].down.is_none() {
                        piece.push(ring[i].id);
                        strict |= ring[i].side == side_sign;
                    }
                    i = (i + 1) % len;
                    steps += 1;
                    if steps > 4 * len {
                        return Err("a face could not be split by a cut plane".into());
                    }
                }
                visited[i] = true;
                piece.push(ring[i].id);
                let j = partner[i];
                if j >= len || ring[j].down != Some(entering_down) {
                    return Err(
                        "a face could not be split by a cut plane (is it self-intersecting?)"
                            .into(),
                    );
                }
                if j == start {
                    break;
                }
                if visited[j] {
                    return Err(
                        "a face could not be split by a cut plane (is it self-intersecting?)"
                            .into(),
                    );
                }
                i = j;
                steps += 1;
                if steps > 4 * len {
                    return Err("a face could not be split by a cut plane".into());
                }
            }
            dedup_ring(&mut piece);
            if strict && piece.len() >= 3 {
                out.push(Face {
                    pts: piece,
                    seam: face.seam,
                });
            }
        }
    }
    Ok(())
}

/// Removes consecutive repeats, around the end too.
fn dedup_ring(poly: &mut Vec<PointId>) {
    poly.dedup();
    while poly.len() > 1 && poly.first() == poly.last() {
        poly.pop();
    }
}

/// Cuts `geom` by the plane {x : n·x = d}: (below = {n·x <= d}, above).
///
/// Vertices within `eps` of the plane are on it and belong to both sides
/// without a cut. Faces of any shape are split into all their pieces. A
/// polyhedron (dim 3) is closed again with caps: the loops of its cut
/// outline, seam `2 cut` with normal +n below and the same ids reversed,
/// seam `2 cut + 1`, above. A cap with a hole is refused; an outline that
/// does not close (an open input mesh) gets no cap. Faces (dim 2) share
/// the cut points and get no caps; edges (dim 1) are split; points (dim 0)
/// go by side, on-plane ones below.
pub(crate) fn plane_cut(
    points: &mut Points,
    geom: &Geometry,
    n: DVec3,
    d: f64,
    cut: u32,
    eps: f64,
) -> Result<(Geometry, Geometry), String> {
    check_plane(n, d, eps)?;
    let (seam_below, seam_above) = seam_pair(cut)?;
    let eps = eps.abs();
    let mut below = Geometry::empty(geom.dim);
    let mut above = Geometry::empty(geom.dim);
    let sd = |points: &Points, p: PointId| n.dot(points.get(p)) - d;
    let side_of = |s: f64| -> i8 {
        if s > eps {
            1
        } else if s < -eps {
            -1
        } else {
            0
        }
    };
    for &v in &geom.verts {
        points.check(v)?;
        if side_of(sd(points, v)) <= 0 {
            below.verts.push(v);
        } else {
            above.verts.push(v);
        }
    }
    for &[a, b] in &geom.edges {
        points.check(a)?;
        points.check(b)?;
        let (sa, sb) = (side_of(sd(points, a)), side_of(sd(points, b)));
        if sa * sb < 0 {
            let c = points.cut(a, b, n, d)?;
            if sa < 0 {
                below.edges.push([a, c]);
                above.edges.push([c, b]);
            } else {
                above.edges.push([a, c]);
                below.edges.push([c, b]);
            }
        } else if sa > 0 || sb > 0 {
            above.edges.push([a, b]);
        } else {
            below.edges.push([a, b]);
        }
    }
    // A solid with no vertex strictly on one side is not cut: it lies on
    // the other side whole (a piece thinner than `eps`, all of its
    // vertices on the plane, goes below), with no caps.
    if geom.dim >= 3 {
        let mut strictly = [false; 2];
        for f in &geom.faces {
            for &p in &f.pts {
                points.check(p)?;
                match side_of(sd(points, p)) {
                    -1 => strictly[0] = true,
                    1 => strictly[1] = true,
                    _ => {}
                }
            }
        }
        if !strictly[0] || !strictly[1] {
            let whole = if strictly[1] { &mut above } else { &mut below };
            whole.faces = geom
                .faces
                .iter()
                .filter(|f| f.pts.len() >= 3)
                .cloned()
                .collect();
            return Ok((below, above));
        }
    }
    for face in &geom.faces {
        for &p in &face.pts {
            points.check(p)?;
        }
        if face.pts.len() < 3 {
            continue;
        }
        let s: Vec<f64> = face.pts.iter().map(|&p| sd(points, p)).collect();
        let side: Vec<i8> = s.iter().map(|&x| side_of(x)).collect();
        let has_below = side.contains(&-1);
        let has_above = side.contains(&1);
        if !has_below && !has_above {
            // In the plane: a solid's face goes to the side it bounds.
            if geom.dim >= 3 && newell(points, &face.pts).dot(n) < 0.0 {
                above.faces.push(face.clone());
            } else {
                below.faces.push(face.clone());
            }
        } else if !has_above {
            below.faces.push(face.clone());
        } else if !has_below {
            above.faces.push(face.clone());
        } else {
            split_polygon(
                points,
                face,
                (n, d),
                &s,
                &side,
                &mut below.faces,
                &mut above.faces,
            )?;
        }
    }
    if geom.dim >= 3 && !below.faces.is_empty() && !above.faces.is_empty() {
        // On the plane: within eps, or a cut point (off by rounding only).
        let on = |p: PointId| {
            let slack = eps.max(1e-12 * (1.0 + d.abs() + points.get(p).abs().max_element()));
            sd(points, p).abs() <= slack
        };
        let caps = cap_loops(points, &below.faces, n, on);
        for lp in caps {
            let o = newell(points, &lp).dot(n);
            if o < 0.0 {
                return Err(format!(
                    "cut {cut} would leave a cap with a hole (the plane crosses the shape around \
                     an opening); caps with holes are not supported"
                ));
            }
            if o == 0.0 {
                continue;
            }
            let mut rev = lp.clone();
            rev.reverse();
            below.faces.push(Face {
                pts: lp,
                seam: seam_below,
            });
            above.faces.push(Face {
                pts: rev,
                seam: seam_above,
            });
        }
    }
    Ok((below, above))
}

/// The loops that close `faces` (a solid's part on one side) in the cut
/// plane of normal `n`: the in-plane edges no other face uses the other
/// way, reversed and chained. Where outlines meet at a point, each loop
/// turns as far left as it can, so that the loops stay apart. Chains that
/// do not close are left out.
fn cap_loops(
    points: &Points,
    faces: &[Face],
    n: DVec3,
    on: impl Fn(PointId) -> bool,
) -> Vec<Vec<PointId>> {
    let mut directed = HashSet::new();
    for f in faces {
        let m = f.pts.len();
        for i in 0..m {
            directed.insert((f.pts[i], f.pts[(i + 1) % m]));
        }
    }
    let mut edges: Vec<(PointId, PointId)> = Vec::new();
    let mut out: HashMap<PointId, Vec<usize>> = HashMap::new();
    for f in faces {
        let m = f.pts.len();
        for i in 0..m {
            let (u, v) = (f.pts[i], f.pts[(i + 1) % m]);
            if u != v && on(u) && on(v) && !directed.contains(&(v, u)) {
                out.entry(v).or_default().push(edges.len());
                edges.push((v, u));
            }
        }
    }
    let mut used = vec![false; edges.len()];
    let mut loops = Vec::new();
    for e in 0..edges.len() {
        if used[e] {
            continue;
        }
        let start = edges[e].0;
        let mut lp = vec![start];
        let mut cur = e;
        let mut closed = false;
        for _ in 0..=edges.len() {
            used[cur] = true;
            let (from, to) = edges[cur];
            if to == start {
                closed = true;
                break;
            }
            lp.push(to);
            let din = points.get(to) - points.get(from);
            let turn = |k: usize| {
                let dout = points.get(edges[k].1) - points.get(to);
                n.dot(din.cross(dout)).atan2(din.dot(dout))
            };
            let candidates = out.get(&to).map(Vec::as_slice).unwrap_or(&[]);
            let best = candidates
                .iter()
                .copied()
                .filter(|&k| !used[k])
                .max_by(|&a, &b| turn(a).total_cmp(&turn(b)));
            match best {
                Some(k) => cur = k,
                None => break,
            }
        }
        if closed && lp.len() >= 3 {
            loops.push(lp);
        }
    }
    loops
}

/// The plane {x : n·x = d} of a split at distance `c` from `origin` along
/// `axis`: the normal is `axis` normalised. [`split`] cuts with exactly
/// these planes, so a caller that records them (for [`weld`]'s seam
/// refinement) gets the same bits.
pub(crate) fn plane_of(origin: DVec3, axis: DVec3, c: f64) -> (DVec3, f64) {
    let n = axis.normalize_or_zero();
    (n, n.dot(origin) + c)
}

/// The distance within which a split's plane at offset `d` takes vertices
/// as on it.
fn split_eps(d: f64) -> f64 {
    1e-9 * (1.0 + d.abs())
}

/// Splits `geom` across planes normal to `axis` (unit) at distances `cuts`
/// (increasing) from `origin`: `cuts.len() + 1` pieces, lowest first, made
/// sequentially (the whole at the first plane, the part above it at the
/// next, ...). Piece i and piece i + 1 share cut `first_cut + i`. Pieces may
/// be empty.
pub(crate) fn split(
    points: &mut Points,
    geom: &Geometry,
    origin: DVec3,
    axis: DVec3,
    cuts: &[f64],
    first_cut: u32,
) -> Result<Vec<Geometry>, String> {
    if !origin.is_finite() || !axis.is_finite() || axis.length_squared() == 0.0 {
        return Err("a split needs a finite origin and a non-zero axis".into());
    }
    for w in cuts.windows(2) {
        if w[0] > w[1] {
            return Err(format!(
                "split positions must increase ({} comes before {})",
                w[0], w[1]
            ));
        }
    }
    if let Some(c) = cuts.iter().find(|c| !c.is_finite()) {
        return Err(format!("split position {c} is not finite"));
    }
    let mut pieces = Vec::with_capacity(cuts.len() + 1);
    let mut rest = geom.clone();
    for (i, &c) in cuts.iter().enumerate() {
        let cut = u32::try_from(i)
            .ok()
            .and_then(|i| first_cut.checked_add(i))
            .ok_or_else(|| "too many cuts".to_string())?;
        let (n, d) = plane_of(origin, axis, c);
        let (lo, hi) = plane_cut(points, &rest, n, d, cut, split_eps(d))?;
        pieces.push(lo);
        rest = hi;
    }
    pieces.push(rest);
    Ok(pieces)
}

fn check_scope(scope: &Scope) -> bool {
    scope.origin.is_finite()
        && scope.axes.iter().all(|a| a.is_finite())
        && scope.size.is_finite()
        && scope.size.min_element() > 0.0
}

fn quad(a: PointId, b: PointId, c: PointId, e: PointId) -> Face {
    Face {
        pts: vec![a, b, c, e],
        seam: 0,
    }
}

fn solid(faces: Vec<Face>, scope: &Scope) -> Geometry {
    let mut g = Geometry::empty(3);
    g.faces = faces;
    if !scope.is_right_handed() {
        for f in &mut g.faces {
            f.pts.reverse();
        }
    }
    g
}

/// A box filling the scope: 6 quads, counter-clockwise from outside, each
/// side face starting at its bottom edge (so that its `comp` scope has y up).
/// A scope with a zero (or non-finite) size gives an empty geometry.
pub(crate) fn box_in(points: &mut Points, scope: &Scope) -> Result<Geometry, String> {
    if !check_scope(scope) {
        return Ok(Geometry::empty(3));
    }
    let mut c = [0; 8];
    for (k, slot) in c.iter_mut().enumerate() {
        let l = DVec3::new(
            (k & 1) as f64 * scope.size.x,
            ((k >> 1) & 1) as f64 * scope.size.y,
            ((k >> 2) & 1) as f64 * scope.size.z,
        );
        *slot = points.add(scope.to_world(l))?;
    }
    let faces = vec![
        quad(c[4], c[5], c[7], c[6]), // front +z
        quad(c[1], c[0], c[2], c[3]), // back -z
        quad(c[5], c[1], c[3], c[7]), // right +x
        quad(c[0], c[4], c[6], c[2]), // left -x
        quad(c[6], c[7], c[3], c[2]), // top +y
        quad(c[0], c[1], c[5], c[4]), // bottom -y
    ];
    Ok(solid(faces, scope))
}

fn check_segments(what: &str, k: usize, min: usize) -> Result<(), String> {
    if k < min || k > MAX_SEGMENTS {
        return Err(format!(
            "{what} must be between {min} and {MAX_SEGMENTS} (got {k})"
        ));
    }
    Ok(())
}

/// A cylinder in the scope: its axis along the scope's y, its base the
/// ellipse inscribed in the scope's x-z rectangle, `segments` sides; n-gon
/// caps and quads around.
pub(crate) fn cylinder_in(
    points: &mut Points,
    scope: &Scope,
    segments: usize,
) -> Result<Geometry, String> {
    check_segments("a cylinder's segments", segments, 3)?;
    if !check_scope(scope) {
        return Ok(Geometry::empty(3));
    }
    let (rx, rz, h) = (scope.size.x / 2.0, scope.size.z / 2.0, scope.size.y);
    let mut bottom = Vec::with_capacity(segments);
    let mut top = Vec::with_capacity(segments);
    for i in 0..segments {
        let a = std::f64::consts::TAU * i as f64 / segments as f64;
        // Counter-clockwise seen from +y: x = cos, z = -sin.
        let (x, z) = (rx + rx * a.cos(), rz - rz * a.sin());
        bottom.push(points.add(scope.to_world(DVec3::new(x, 0.0, z)))?);
        top.push(points.add(scope.to_world(DVec3::new(x, h, z)))?);
    }
    let mut faces = Vec::with_capacity(segments + 2);
    for i in 0..segments {
        let j = (i + 1) % segments;
        faces.push(quad(bottom[i], bottom[j], top[j], top[i]));
    }
    let mut b = bottom.clone();
    b.reverse();
    faces.push(Face { pts: top, seam: 0 });
    faces.push(Face { pts: b, seam: 0 });
    Ok(solid(faces, scope))
}

/// A UV sphere (an ellipsoid) inscribed in the scope: `slices` around the
/// scope's y, `stacks` from pole to pole; triangles at the poles, quads
/// elsewhere.
pub(crate) fn sphere_in(
    points: &mut Points,
    scope: &Scope,
    slices: usize,
    stacks: usize,
) -> Result<Geometry, String> {
    check_segments("a sphere's slices", slices, 3)?;
    check_segments("a sphere's stacks", stacks, 2)?;
    if !check_scope(scope) {
        return Ok(Geometry::empty(3));
    }
    let r = scope.size / 2.0;
    let at = |polar: f64, az: f64| {
        let (sp, cp) = polar.sin_cos();
        r + DVec3::new(r.x * sp * az.cos(), r.y * cp, -r.z * sp * az.sin())
    };
    let north = points.add(scope.to_world(r + DVec3::new(0.0, r.y, 0.0)))?;
    let south = points.add(scope.to_world(r - DVec3::new(0.0, r.y, 0.0)))?;
    let mut rings = Vec::with_capacity(stacks - 1);
    for k in 1..stacks {
        let polar = std::f64::consts::PI * k as f64 / stacks as f64;
        let mut ring = Vec::with_capacity(slices);
        for i in 0..slices {
            let az = std::f64::consts::TAU * i as f64 / slices as f64;
            ring.push(points.add(scope.to_world(at(polar, az)))?);
        }
        rings.push(ring);
    }
    let mut faces = Vec::new();
    // Azimuth grows counter-clockwise seen from +y; polar grows downwards.
    for i in 0..slices {
        let j = (i + 1) % slices;
        faces.push(Face {
            pts: vec![north, rings[0][i], rings[0][j]],
            seam: 0,
        });
        for k in 0..rings.len() - 1 {
            let (u, l) = (&rings[k], &rings[k + 1]);
            faces.push(quad(u[i], l[i], l[j], u[j]));
        }
        let last = &rings[rings.len() - 1];
        faces.push(Face {
            pts: vec![south, last[j], last[i]],
            seam: 0,
        });
    }
    Ok(solid(faces, scope))
}

/// A polygon soup fitted into the scope: its bounding box mapped onto the
/// scope's box (a zero extent maps to the scope's origin plane), on new
/// points.
pub(crate) fn mesh_in(
    points: &mut Points,
    scope: &Scope,
    soup: &PolygonSoup,
) -> Result<Geometry, String> {
    if soup.positions.is_empty() || !check_scope_finite(scope) {
        return Ok(Geometry::empty(3));
    }
    if soup.positions.iter().any(|p| !p.is_finite()) {
        return Err("the mesh has a vertex that is not finite".into());
    }
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for &p in &soup.positions {
        lo = lo.min(p);
        hi = hi.max(p);
    }
    let ext = hi - lo;
    let scale = |e: f64, s: f64| if e > 0.0 { s / e } else { 0.0 };
    let k = DVec3::new(
        scale(ext.x, scope.size.x),
        scale(ext.y, scope.size.y),
        scale(ext.z, scope.size.z),
    );
    let mut ids = Vec::with_capacity(soup.positions.len());
    for &p in &soup.positions {
        ids.push(points.add(scope.to_world((p - lo) * k))?);
    }
    let mut g = Geometry::empty(3);
    for (f, face) in soup.faces.iter().enumerate() {
        let mut pts = Vec::with_capacity(face.len());
        for &i in face {
            let id = ids.get(i as usize).ok_or_else(|| {
                format!(
                    "face {} of the mesh uses vertex {i}, which does not exist",
                    f + 1
                )
            })?;
            pts.push(*id);
        }
        if pts.len() >= 3 {
            g.faces.push(Face { pts, seam: 0 });
        }
    }
    if !scope.is_right_handed() {
        for f in &mut g.faces {
            f.pts.reverse();
        }
    }
    Ok(g)
}

fn check_scope_finite(scope: &Scope) -> bool {
    scope.origin.is_finite()
        && scope.axes.iter().all(|a| a.is_finite())
        && scope.size.is_finite()
        && scope.size.min_element() >= 0.0
}

/// One planar polygon (dim 2) on new points at world positions `corners`.
pub(crate) fn polygon(points: &mut Points, corners: &[DVec3]) -> Result<Geometry, String> {
    if corners.len() < 3 {
        return Err(format!(
            "a polygon needs at least 3 corners (got {})",
            corners.len()
        ));
    }
    let mut pts = Vec::with_capacity(corners.len());
    for &c in corners {
        pts.push(points.add(c)?);
    }
    let mut g = Geometry::empty(2);
    g.faces.push(Face { pts, seam: 0 });
    Ok(g)
}

/// One planar polygon (dim 2) with corners given in the scope's frame.
pub(crate) fn polygon_in(
    points: &mut Points,
    scope: &Scope,
    corners: &[DVec3],
) -> Result<Geometry, String> {
    let world: Vec<DVec3> = corners.iter().map(|&c| scope.to_world(c)).collect();
    polygon(points, &world)
}

/// Extrudes faces (dim 2) by `h` along unit `dir` into a polyhedron: the
/// base faces reversed on the original ids, the top faces on new points
/// moved by h·dir, a quad on every boundary edge (an edge of one face).
/// The faces point outwards for either sign of `h`.
pub(crate) fn extrude(
    points: &mut Points,
    geom: &Geometry,
    dir: DVec3,
    h: f64,
) -> Result<Geometry, String> {
    if geom.dim != 2 {
        return Err(format!(
            "only faces can be extruded (this shape has dimension {})",
            geom.dim
        ));
    }
    if !h.is_finite() || !dir.is_finite() || h == 0.0 || dir.length_squared() == 0.0 {
        return Err(format!(
            "an extrusion needs a finite non-zero height and direction (got {h})"
        ));
    }
    let offset = dir * h;
    let mut total = DVec3::ZERO;
    for f in &geom.faces {
        for &p in &f.pts {
            points.check(p)?;
        }
        total += newell(points, &f.pts);
    }
    let orient = total.dot(offset);
    if geom.faces.is_empty() {
        return Ok(Geometry::empty(3));
    }
    if !orient.is_finite() {
        return Err(format!(
            "an extrusion of {} makes a solid too large to measure",
            show(h)
        ));
    }
    if orient == 0.0 {
        return Err("the extrusion direction lies in the plane of the faces".into());
    }
    let up = orient > 0.0;
    let mut top_of: HashMap<PointId, PointId> = HashMap::new();
    let mut count: HashMap<(PointId, PointId), u32> = HashMap::new();
    for f in &geom.faces {
        let m = f.pts.len();
        for i in 0..m {
            let (a, b) = (f.pts[i], f.pts[(i + 1) % m]);
            *count.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    let mut out = Geometry::empty(3);
    let mut sides = Vec::new();
    let mut tops = Vec::new();
    for f in &geom.faces {
        let mut top = Vec::with_capacity(f.pts.len());
        for &p in &f.pts {
            let t = match top_of.get(&p) {
                Some(&t) => t,
                None => {
                    let t = points.add(points.get(p) + offset)?;
                    top_of.insert(p, t);
                    t
                }
            };
            top.push(t);
        }
        let m = f.pts.len();
        for i in 0..m {
            let (a, b) = (f.pts[i], f.pts[(i + 1) % m]);
            if count.get(&(a.min(b), a.max(b))) != Some(&1) {
                continue;
            }
            let (ta, tb) = (top[i], top[(i + 1) % m]);
            sides.push(if up {
                quad(a, b, tb, ta)
            } else {
                quad(b, a, ta, tb)
            });
        }
        let mut base = f.pts.clone();
        if up {
            base.reverse();
        } else {
            top.reverse();
        }
        out.faces.push(Face {
            pts: base,
            seam: f.seam,
        });
        tops.push(Face {
            pts: top,
            seam: f.seam,
        });
    }
    out.faces.extend(tops);
    out.faces.extend(sides);
    Ok(out)
}

/// Which faces a component split takes, by the direction of their normal in
/// the shape's scope.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum Selector {
    Front,
    Back,
    Left,
    Right,
    Top,
    Bottom,
    /// Front, back, left and right.
    Side,
    /// Top and bottom.
    Horizontal,
    /// The same as `Side`.
    Vertical,
    All,
}

impl Selector {
    pub fn parse(s: &str) -> Option<Selector> {
        Some(match s {
            "front" => Selector::Front,
            "back" => Selector::Back,
            "left" => Selector::Left,
            "right" => Selector::Right,
            "top" => Selector::Top,
            "bottom" => Selector::Bottom,
            "side" => Selector::Side,
            "horizontal" => Selector::Horizontal,
            "vertical" => Selector::Vertical,
            "all" => Selector::All,
            _ => return None,
        })
    }

    /// The direction a normal (in the scope's frame) faces, by its dominant
    /// component: +z front, -z back, -x left, +x right, +y top, -y bottom;
    /// on ties y wins, then z, then x.
    pub fn classify(n: DVec3) -> Selector {
        let a = n.abs();
        if a.y >= a.z && a.y >= a.x {
            if n.y >= 0.0 {
                Selector::Top
            } else {
                Selector::Bottom
            }
        } else if a.z >= a.x {
            if n.z >= 0.0 {
                Selector::Front
            } else {
                Selector::Back
            }
        } else if n.x >= 0.0 {
            Selector::Right
        } else {
            Selector::Left
        }
    }

    /// Whether a face classified as `c` is selected.
    pub fn takes(self, c: Selector) -> bool {
        match self {
            Selector::All => true,
            Selector::Side | Selector::Vertical => matches!(
                c,
                Selector::Front | Selector::Back | Selector::Left | Selector::Right
            ),
            Selector::Horizontal => matches!(c, Selector::Top | Selector::Bottom),
            s => s == c,
        }
    }
}

/// A frame with x along `x` and z along `z` (made orthogonal), y = z × x,
/// fitted around `pts`: origin at the minimum corner, size the extent.
fn frame_around(points: &Points, pts: &[PointId], x: DVec3, z: DVec3) -> Option<Scope> {
    let z = z.try_normalize()?;
    let x = (x - x.dot(z) * z).try_normalize()?;
    let y = z.cross(x);
    Some(fit(points, pts.iter().copied(), [x, y, z]))
}

fn fit(points: &Points, pts: impl Iterator<Item = PointId>, axes: [DVec3; 3]) -> Scope {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for p in pts {
        let q = points.get(p);
        let l = DVec3::new(q.dot(axes[0]), q.dot(axes[1]), q.dot(axes[2]));
        lo = lo.min(l);
        hi = hi.max(l);
    }
    if !lo.is_finite() || !hi.is_finite() {
        return Scope {
            origin: DVec3::ZERO,
            axes,
            size: DVec3::ZERO,
        };
    }
    Scope {
        origin: lo.x * axes[0] + lo.y * axes[1] + lo.z * axes[2],
        axes,
        size: hi - lo,
    }
}

/// The scope of a lot (faces, dim 2, made by the axiom): x along the first
/// face's first edge, y the faces' normal (Newell, summed), z = x × y,
/// fitted around the faces (size.y = 0). None for faces without area.
pub(crate) fn lot_scope(points: &Points, geom: &Geometry) -> Option<Scope> {
    let f = geom.faces.first()?;
    let y = geom
        .faces
        .iter()
        .map(|f| newell(points, &f.pts))
        .sum::<DVec3>()
        .try_normalize()?;
    let m = f.pts.len();
    let edge = (0..m)
        .map(|i| points.get(f.pts[(i + 1) % m]) - points.get(f.pts[i]))
        .find(|e| e.length_squared() > 0.0)?;
    let x = (edge - edge.dot(y) * y).try_normalize()?;
    let mut s = fit(points, geom.point_ids(), [x, y, x.cross(y)]);
    s.size.y = 0.0;
    Some(s)
}

/// The faces of `geom` that `sel` takes, each as a one-face geometry (dim
/// 2, the same point ids) with its scope: x along the face's first edge,
/// z its normal (Newell), y = z × x, fitted around the face (size.z = 0).
/// Degenerate faces (no area) are left out.
pub(crate) fn comp_faces(
    points: &Points,
    geom: &Geometry,
    scope: &Scope,
    sel: Selector,
) -> Vec<(Geometry, Scope)> {
    let mut out = Vec::new();
    for f in &geom.faces {
        let n = newell(points, &f.pts);
        if !n.is_finite() || n.length_squared() == 0.0 {
            continue;
        }
        let local = DVec3::new(
            n.dot(scope.axes[0]),
            n.dot(scope.axes[1]),
            n.dot(scope.axes[2]),
        );
        if !sel.takes(Selector::classify(local)) {
            continue;
        }
        let m = f.pts.len();
        let edge = (0..m)
            .map(|i| points.get(f.pts[(i + 1) % m]) - points.get(f.pts[i]))
            .find(|e| e.length_squared() > 0.0);
        let Some(edge) = edge else { continue };
        let Some(mut s) = frame_around(points, &f.pts, edge, n) else {
            continue;
        };
        s.size.z = 0.0;
        let mut g = Geometry::empty(2);
        g.faces.push(f.clone());
        out.push((g, s));
    }
    out
}

/// The unique undirected edges of `geom` (of its faces, or its edges), in
/// first-seen order, each a one-edge geometry (dim 1) with a scope whose x
/// runs along the edge (y the parent's y made orthogonal where it can be).
pub(crate) fn comp_edges(
    points: &Points,
    geom: &Geometry,
    scope: &Scope,
) -> Vec<(Geometry, Scope)> {
    let mut seen = HashSet::new();
    let mut list = Vec::new();
    for f in &geom.faces {
        let m = f.pts.len();
        for i in 0..m {
            list.push([f.pts[i], f.pts[(i + 1) % m]]);
        }
    }
    list.extend(geom.edges.iter().copied());
    let mut out = Vec::new();
    for [a, b] in list {
        if a == b || !seen.insert((a.min(b), a.max(b))) {
            continue;
        }
        let (pa, pb) = (points.get(a), points.get(b));
        let Some(x) = (pb - pa).try_normalize() else {
            continue;
        };
        let y = [
            scope.axes[1],
            scope.axes[2],
            scope.axes[0],
            DVec3::Y,
            DVec3::Z,
        ]
        .into_iter()
        .find_map(|c| (c - c.dot(x) * x).try_normalize())
        .unwrap_or(DVec3::Y);
        let z = x.cross(y);
        let mut g = Geometry::empty(1);
        g.edges.push([a, b]);
        out.push((
            g,
            Scope {
                origin: pa,
                axes: [x, y, z],
                size: DVec3::new((pb - pa).length(), 0.0, 0.0),
            },
        ));
    }
    out
}

/// Every point of `geom` once (first-use order), each a one-point geometry
/// (dim 0) with the parent's axes, at the point, of size 0.
pub(crate) fn comp_vertices(
    points: &Points,
    geom: &Geometry,
    scope: &Scope,
) -> Vec<(Geometry, Scope)> {
    geom.unique_points()
        .into_iter()
        .map(|p| {
            let mut g = Geometry::empty(0);
            g.verts.push(p);
            (
                g,
                Scope {
                    origin: points.get(p),
                    axes: scope.axes,
                    size: DVec3::ZERO,
                },
            )
        })
        .collect()
}

/// The box on `axes` around `geom` (origin at its minimum corner); an empty
/// geometry gives a scope at the world origin of size 0.
pub(crate) fn bounding_scope(points: &Points, geom: &Geometry, axes: [DVec3; 3]) -> Scope {
    fit(points, geom.point_ids(), axes)
}

/// A copy of `geom` moved by `m`, on new points (a moved shape no longer
/// shares vertices). A mirroring transform reverses the faces so that they
/// still face outwards.
pub(crate) fn transform(
    points: &mut Points,
    geom: &Geometry,
    m: &DAffine3,
) -> Result<Geometry, String> {
    let mat: DMat3 = m.matrix3;
    if !mat.is_finite() || !m.translation.is_finite() {
        return Err("a transformation with a non-finite entry".into());
    }
    let mut map: HashMap<PointId, PointId> = HashMap::new();
    let mut moved = |points: &mut Points, p: PointId| -> Result<PointId, String> {
        if let Some(&q) = map.get(&p) {
            return Ok(q);
        }
        points.check(p)?;
        let q = points.add(m.transform_point3(points.get(p)))?;
        map.insert(p, q);
        Ok(q)
    };
    let flip = mat.determinant() < 0.0;
    let mut out = Geometry::empty(geom.dim);
    for f in &geom.faces {
        let mut pts = Vec::with_capacity(f.pts.len());
        for &p in &f.pts {
            pts.push(moved(points, p)?);
        }
        if flip {
            pts.reverse();
        }
        out.faces.push(Face { pts, seam: f.seam });
    }
    for &[a, b] in &geom.edges {
        out.edges.push([moved(points, a)?, moved(points, b)?]);
    }
    for &v in &geom.verts {
        out.verts.push(moved(points, v)?);
    }
    Ok(out)
}

/// A smoothing group's faces gathered into one polygon soup.
#[derive(Clone, Debug, Default)]
pub(crate) struct Welded {
    /// Positions of the used points, faces (polygons, counter-clockwise).
    pub soup: PolygonSoup,
    /// Soup vertex -> its point.
    pub point_of: Vec<PointId>,
    /// Soup face -> the index of its member shape in the group.
    pub tags: Vec<u32>,
    /// Soup vertex: shared with a shape outside the group.
    pub protected_vertex: Vec<bool>,
    /// Soup face: all its vertices protected.
    pub protected_face: Vec<bool>,
}

/// The cut ids of a geometry's seam faces (its caps), each once, in
/// increasing order.
pub(crate) fn seams_of(geom: &Geometry) -> impl Iterator<Item = u32> {
    let ks: std::collections::BTreeSet<u32> = geom
        .faces
        .iter()
        .filter(|f| f.seam >= 2)
        .map(|f| f.seam / 2)
        .collect();
    ks.into_iter()
}

/// `faces` with every face of a cut k that has planes in `seam_planes`
/// cut by those planes in order, both pieces kept: the two sides of a wall
/// cut later on one side only get the same pieces with the same ids.
fn refine(
    points: &mut Points,
    faces: &[Face],
    seam_planes: &HashMap<u32, Vec<(DVec3, f64)>>,
) -> Result<Vec<Face>, String> {
    let mut out = Vec::with_capacity(faces.len());
    for f in faces {
        for &p in &f.pts {
            points.check(p)?;
        }
        let planes = match seam_planes.get(&(f.seam / 2)) {
            Some(pl) if f.seam >= 2 && !pl.is_empty() => pl,
            _ => {
                out.push(f.clone());
                continue;
            }
        };
        let mut pieces = vec![f.clone()];
        for &(n, d) in planes {
            let eps = split_eps(d);
            check_plane(n, d, eps)?;
            let mut next = Vec::with_capacity(pieces.len() + 1);
            for piece in pieces {
                if piece.pts.len() < 3 {
                    continue;
                }
                let s: Vec<f64> = piece
                    .pts
                    .iter()
                    .map(|&p| n.dot(points.get(p)) - d)
                    .collect();
                let side: Vec<i8> = s
                    .iter()
                    .map(|&x| {
                        if x > eps {
                            1
                        } else if x < -eps {
                            -1
                        } else {
                            0
                        }
                    })
                    .collect();
                if side.contains(&-1) && side.contains(&1) {
                    let mut below = Vec::new();
                    split_polygon(points, &piece, (n, d), &s, &side, &mut below, &mut next)?;
                    next.extend(below);
                } else {
                    next.push(piece);
                }
            }
            pieces = next;
        }
        out.extend(pieces);
    }
    Ok(out)
}

/// A polygon's cycle written from its smallest id, for comparing cycles
/// whatever vertex they start at.
fn cycle_key(poly: &[PointId]) -> Vec<PointId> {
    let Some(start) = (0..poly.len()).min_by_key(|&i| poly[i]) else {
        return Vec::new();
    };
    poly[start..]
        .iter()
        .chain(&poly[..start])
        .copied()
        .collect()
}

/// The members' faces as one soup.
///
/// First every face of a cut k (members' and `others'`) is refined by the
/// planes `seam_planes` records for k (the later splits that crossed a
/// shape holding a part of k's wall), in order, so that both sides of the
/// wall have the same pieces; every face is resolved (no T-junctions).
/// Then a member's face of cut k is dropped when another member holds the
/// same cycle reversed (an internal wall of the group) and k is not loose;
/// every other face is kept (a wall towards a shape outside the group or
/// removed, or a part of a wall the other side does not cover). For a
/// loose cut both faces of each mirrored pair stay, and the members on
/// the upper side (seam 2k + 1) get their own copies of those faces'
/// points that no member without cut-k faces holds (a zero-width slit,
/// attached where another member holds the points). Points used by
/// `others` are protected.
pub(crate) fn weld(
    points: &mut Points,
    members: &[&Geometry],
    others: &[&Geometry],
    loose: &HashSet<u32>,
    seam_planes: &HashMap<u32, Vec<(DVec3, f64)>>,
) -> Result<Welded, String> {
    if members.len() > u32::MAX as usize {
        return Err("too many shapes in a smoothing group".into());
    }
    // The points of the shapes outside the group, their walls refined.
    let mut other_points = HashSet::new();
    for g in others {
        if g.faces
            .iter()
            .any(|f| f.seam >= 2 && seam_planes.contains_key(&(f.seam / 2)))
        {
            let faces = refine(points, &g.faces, seam_planes)?;
            other_points.extend(faces.iter().flat_map(|f| f.pts.iter().copied()));
        } else {
            other_points.extend(g.faces.iter().flat_map(|f| f.pts.iter().copied()));
        }
        other_points.extend(g.edges.iter().flat_map(|e| e.iter().copied()));
        other_points.extend(g.verts.iter().copied());
    }
    // The members' faces, refined and resolved.
    let mut kept: Vec<Vec<Face>> = Vec::with_capacity(members.len());
    let mut buf = Vec::new();
    for g in members {
        let mut fs = Vec::new();
        for f in refine(points, &g.faces, seam_planes)? {
            points.resolve(&f.pts, &mut buf);
            dedup_ring(&mut buf);
            if buf.len() >= 3 {
                fs.push(Face {
                    pts: buf.clone(),
                    seam: f.seam,
                });
            }
        }
        kept.push(fs);
    }
    // Mirrored pairs: a cut-k face of one member whose reversed cycle
    // another member holds as a cut-k face.
    let mut cycles: HashMap<(u32, Vec<PointId>), Vec<usize>> = HashMap::new();
    for (i, fs) in kept.iter().enumerate() {
        for f in fs.iter().filter(|f| f.seam >= 2) {
            cycles
                .entry((f.seam / 2, cycle_key(&f.pts)))
                .or_default()
                .push(i);
        }
    }
    let mut mirrored: Vec<Vec<bool>> = Vec::with_capacity(kept.len());
    for (i, fs) in kept.iter().enumerate() {
        let mut m = Vec::with_capacity(fs.len());
        for f in fs {
            let hit = f.seam >= 2 && {
                let mut rev = f.pts.clone();
                rev.reverse();
                cycles
                    .get(&(f.seam / 2, cycle_key(&rev)))
                    .is_some_and(|who| who.iter().any(|&j| j != i))
            };
            m.push(hit);
        }
        mirrored.push(m);
    }
    // Loose cuts with mirrored pairs: the upper side gets its own copies of
    // the pairs' points.
    let mut loose_cuts: Vec<u32> = Vec::new();
    for (fs, m) in kept.iter().zip(&mirrored) {
        for (f, &hit) in fs.iter().zip(m) {
            if hit && loose.contains(&(f.seam / 2)) && !loose_cuts.contains(&(f.seam / 2)) {
                loose_cuts.push(f.seam / 2);
            }
        }
    }
    loose_cuts.sort_unstable();
    for k in loose_cuts {
        let with_cut: Vec<bool> = kept
            .iter()
            .map(|fs| fs.iter().any(|f| f.seam / 2 == k && f.seam >= 2))
            .collect();
        let mut held = HashSet::new();
        for (i, fs) in kept.iter().enumerate() {
            if !with_cut[i] {
                for f in fs {
                    held.extend(f.pts.iter().copied());
                }
            }
        }
        let mut upper = Vec::new();
        let mut dup: HashMap<PointId, PointId> = HashMap::new();
        for (i, fs) in kept.iter().enumerate() {
            let mut any = false;
            for (f, &hit) in fs.iter().zip(&mirrored[i]) {
                if !hit || f.seam != 2 * k + 1 {
                    continue;
                }
                any = true;
                for &p in &f.pts {
                    if !held.contains(&p) && !dup.contains_key(&p) {
                        let q = points.add(points.get(p))?;
                        dup.insert(p, q);
                    }
                }
            }
            if any {
                upper.push(i);
            }
        }
        for i in upper {
            for f in &mut kept[i] {
                for p in &mut f.pts {
                    if let Some(&q) = dup.get(p) {
                        *p = q;
                    }
                }
            }
        }
    }
    let mut w = Welded::default();
    let mut index: HashMap<PointId, u32> = HashMap::new();
    for (i, (fs, m)) in kept.into_iter().zip(mirrored).enumerate() {
        for (f, hit) in fs.into_iter().zip(m) {
            if hit && !loose.contains(&(f.seam / 2)) {
                continue;
            }
            let mut face = Vec::with_capacity(f.pts.len());
            for p in f.pts {
                let v = match index.get(&p) {
                    Some(&v) => v,
                    None => {
                        let v = w.point_of.len() as u32;
                        index.insert(p, v);
                        w.point_of.push(p);
                        w.soup.positions.push(points.get(p));
                        w.protected_vertex.push(other_points.contains(&p));
                        v
                    }
                };
                face.push(v);
            }
            w.protected_face
                .push(face.iter().all(|&v| w.protected_vertex[v as usize]));
            w.soup.faces.push(face);
            w.tags.push(i as u32);
        }
    }
    w.soup.face_lines = vec![0; w.soup.faces.len()];
    w.soup.vertex_lines = vec![0; w.soup.positions.len()];
    Ok(w)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The signed volume by the divergence theorem: the sum over faces
    /// (fanned) of p0 · (pi × pi+1) / 6, positions taken relative to the
    /// first point (a closed surface's volume does not depend on it).
    fn volume(points: &Points, g: &Geometry) -> f64 {
        let Some(o) = g.point_ids().next().map(|p| points.get(p)) else {
            return 0.0;
        };
        let at = |p: PointId| points.get(p) - o;
        let mut v = 0.0;
        for f in &g.faces {
            let p0 = at(f.pts[0]);
            for i in 1..f.pts.len() - 1 {
                v += p0.dot(at(f.pts[i]).cross(at(f.pts[i + 1])));
            }
        }
        v / 6.0
    }

    /// Every undirected edge in exactly two faces, once each way (a closed,
    /// consistently oriented 2-manifold surface).
    fn assert_closed(faces: &[Vec<u32>]) {
        let mut directed: HashMap<(u32, u32), usize> = HashMap::new();
        for f in faces {
            for i in 0..f.len() {
                *directed.entry((f[i], f[(i + 1) % f.len()])).or_default() += 1;
            }
        }
        for (&(a, b), &k) in &directed {
            assert_eq!(k, 1, "edge {a}->{b} used {k} times");
            assert_eq!(directed.get(&(b, a)), Some(&1), "edge {a}-{b} has one face");
        }
    }

    fn face_lists(g: &Geometry) -> Vec<Vec<u32>> {
        g.faces.iter().map(|f| f.pts.clone()).collect()
    }

    fn sized(origin: DVec3, size: DVec3) -> Scope {
        Scope {
            origin,
            size,
            ..Scope::world()
        }
    }

    fn unit_box(points: &mut Points) -> Geometry {
        box_in(points, &sized(DVec3::ZERO, DVec3::ONE)).unwrap()
    }

    /// Splits the unit box at x = 0.3 and x = 0.7 (cuts 1 and 2).
    fn three_pieces(points: &mut Points) -> Vec<Geometry> {
        let b = unit_box(points);
        split(points, &b, DVec3::ZERO, DVec3::X, &[0.3, 0.7], 1).unwrap()
    }

    fn cap(g: &Geometry, seam: u32) -> Vec<PointId> {
        let caps: Vec<&Face> = g.faces.iter().filter(|f| f.seam == seam).collect();
        assert_eq!(caps.len(), 1, "one cap with seam {seam}");
        caps[0].pts.clone()
    }

    #[test]
    fn split_box_gives_pieces_of_the_right_volumes_with_mirrored_caps() {
        let mut points = Points::new();
        let pieces = three_pieces(&mut points);
        assert_eq!(pieces.len(), 3);
        // Slabs of the unit box: 1 x 1 x width.
        for (g, w) in pieces.iter().zip([0.3, 0.4, 0.3]) {
            assert!((volume(&points, g) - w).abs() < 1e-12);
            assert_closed(&face_lists(g));
        }
        for k in 1..=2u32 {
            let lower = cap(&pieces[k as usize - 1], 2 * k);
            let mut upper = cap(&pieces[k as usize], 2 * k + 1);
            upper.reverse();
            assert_eq!(lower, upper, "cut {k}'s caps are mirrored id for id");
            assert_eq!(lower.len(), 4);
            let x = [0.3, 0.7][k as usize - 1];
            for &p in &lower {
                assert!((points.get(p).x - x).abs() < 1e-15);
            }
            // The lower side's cap faces +x.
            assert!(newell(&points, &lower).x > 0.0);
        }
        // 8 corners and 4 points per cut.
        assert_eq!(points.len(), 16);
    }

    #[test]
    fn welding_every_piece_closes_the_box_again() {
        let mut points = Points::new();
        let pieces = three_pieces(&mut points);
        let members: Vec<&Geometry> = pieces.iter().collect();
        let w = weld(&mut points, &members, &[], &HashSet::new(), &HashMap::new()).unwrap();
        assert_closed(&w.soup.faces.to_vecs());
        // 8 corners + 2 cuts x 4 points; the 4 faces across x in 3 pieces
        // each and the 2 ends: 14 faces, none of them a cap.
        assert_eq!(w.soup.positions.len(), 16);
        assert_eq!(w.soup.faces.len(), 14);
        assert!(w.protected_vertex.iter().all(|&p| !p));
        assert_eq!(w.tags.iter().filter(|&&t| t == 1).count(), 4);
        let mut g = Geometry::empty(3);
        for f in &w.soup.faces {
            g.faces.push(Face {
                pts: f.iter().map(|&v| w.point_of[v as usize]).collect(),
                seam: 0,
            });
        }
        assert!((volume(&points, &g) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn a_loose_cut_leaves_a_slit() {
        let mut points = Points::new();
        let pieces = three_pieces(&mut points);
        let members: Vec<&Geometry> = pieces.iter().collect();
        let loose: HashSet<u32> = [2].into_iter().collect();
        let w = weld(&mut points, &members, &[], &loose, &HashMap::new()).unwrap();
        assert_closed(&w.soup.faces.to_vecs());
        // 16 points and the 4 points of cut 2 copied for the upper side;
        // 14 faces and both caps of cut 2.
        assert_eq!(w.soup.positions.len(), 20);
        assert_eq!(w.soup.faces.len(), 16);
        // The copies sit where the originals are.
        let mut at: HashMap<[u64; 3], usize> = HashMap::new();
        for p in &w.soup.positions {
            *at.entry([p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
                .or_default() += 1;
        }
        assert_eq!(at.values().filter(|&&k| k == 2).count(), 4);
        assert!(w
            .soup
            .positions
            .iter()
            .all(|p| p.x == 0.7 || at[&[p.x.to_bits(), p.y.to_bits(), p.z.to_bits()]] == 1));
    }

    /// The welded soup as one geometry on point ids (for `volume`).
    fn soup_geometry(w: &Welded) -> Geometry {
        let mut g = Geometry::empty(3);
        for f in &w.soup.faces {
            g.faces.push(Face {
                pts: f.iter().map(|&v| w.point_of[v as usize]).collect(),
                seam: 0,
            });
        }
        g
    }

    #[test]
    fn a_wall_shared_with_a_shape_outside_the_group_keeps_its_uncovered_part() {
        let mut points = Points::new();
        let pieces = three_pieces(&mut points);
        // Piece 1 split along z (cut 3): its halves both hold a part of
        // cut 2's wall; the plane crossed a shape with cut-2 faces.
        let halves = split(&mut points, &pieces[1], DVec3::ZERO, DVec3::Z, &[0.5], 3).unwrap();
        let seam_planes: HashMap<u32, Vec<(DVec3, f64)>> =
            [(2, vec![plane_of(DVec3::ZERO, DVec3::Z, 0.5)])]
                .into_iter()
                .collect();
        let w = weld(
            &mut points,
            &[&halves[0], &pieces[2]],
            &[&halves[1]],
            &HashSet::new(),
            &seam_planes,
        )
        .unwrap();
        // Piece 2's wall is cut in two: the half against halves[0] goes
        // with its mirror, the half against halves[1] stays.
        assert_closed(&w.soup.faces.to_vecs());
        // [0.3, 1] x [0, 1] x [0, 0.5] and [0.7, 1] x [0, 1] x [0.5, 1].
        let v = 0.7 * 0.5 + 0.3 * 0.5;
        assert!((volume(&points, &soup_geometry(&w)) - v).abs() < 1e-12);
        // Protected faces: halves[0]'s cut-3 cap and piece 2's kept wall
        // half, both on points of halves[1].
        assert_eq!(w.protected_face.iter().filter(|&&p| p).count(), 2);
    }

    #[test]
    fn welding_resolves_t_junctions() {
        let mut points = Points::new();
        let pieces = three_pieces(&mut points);
        let halves = split(&mut points, &pieces[1], DVec3::ZERO, DVec3::Y, &[0.5], 3).unwrap();
        assert_eq!(halves.len(), 2);
        let members = [&pieces[0], &halves[0], &halves[1], &pieces[2]];
        // The y cut crossed a shape holding walls of cuts 1 and 2.
        let y = plane_of(DVec3::ZERO, DVec3::Y, 0.5);
        let seam_planes: HashMap<u32, Vec<(DVec3, f64)>> =
            [(1, vec![y]), (2, vec![y])].into_iter().collect();
        let w = weld(&mut points, &members, &[], &HashSet::new(), &seam_planes).unwrap();
        assert_closed(&w.soup.faces.to_vecs());
        // The y cut put 4 points on the middle slab's edges at x = 0.3 and
        // 0.7 (front and back), all used.
        assert_eq!(w.soup.positions.len(), 20);
    }

    #[test]
    fn a_shape_outside_the_group_protects_the_shared_wall() {
        let mut points = Points::new();
        let pieces = three_pieces(&mut points);
        let w = weld(
            &mut points,
            &[&pieces[0]],
            &[&pieces[1]],
            &HashSet::new(),
            &HashMap::new(),
        )
        .unwrap();
        assert_closed(&w.soup.faces.to_vecs());
        let protected: Vec<DVec3> = (0..w.soup.positions.len())
            .filter(|&v| w.protected_vertex[v])
            .map(|v| w.soup.positions[v])
            .collect();
        assert_eq!(protected.len(), 4);
        assert!(protected.iter().all(|p| (p.x - 0.3).abs() < 1e-15));
        let faces: Vec<usize> = (0..w.soup.faces.len())
            .filter(|&f| w.protected_face[f])
            .collect();
        assert_eq!(faces.len(), 1);
        let n = {
            let f = &w.soup.faces[faces[0]];
            let ids: Vec<PointId> = f.iter().map(|&v| w.point_of[v as usize]).collect();
            newell(&points, &ids)
        };
        assert!(n.x > 0.0 && n.y.abs() < 1e-12 && n.z.abs() < 1e-12);
    }

    /// An L: [0,2]x[0,1] and [0,1]x[0,2] in the ground plane (x, z), facing up.
    fn l_shape(points: &mut Points) -> Geometry {
        let mut c = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(2.0, 0.0, 1.0),
            DVec3::new(1.0, 0.0, 1.0),
            DVec3::new(1.0, 0.0, 2.0),
            DVec3::new(0.0, 0.0, 2.0),
        ];
        // Face +y: counter-clockwise seen from above.
        let mut n = DVec3::ZERO;
        for i in 0..c.len() {
            n += c[i].cross(c[(i + 1) % c.len()]);
        }
        if n.y < 0.0 {
            c.reverse();
        }
        polygon(points, &c).unwrap()
    }

    fn components(g: &Geometry) -> usize {
        let faces = &g.faces;
        let mut parent: Vec<usize> = (0..faces.len()).collect();
        fn find(p: &mut [usize], i: usize) -> usize {
            let mut i = i;
            while p[i] != i {
                p[i] = p[p[i]];
                i = p[i];
            }
            i
        }
        let mut owner: HashMap<PointId, usize> = HashMap::new();
        for (f, face) in faces.iter().enumerate() {
            for &p in &face.pts {
                if let Some(&o) = owner.get(&p) {
                    let (a, b) = (find(&mut parent, o), find(&mut parent, f));
                    parent[a] = b;
                } else {
                    owner.insert(p, f);
                }
            }
        }
        (0..faces.len())
            .filter(|&f| find(&mut parent, f) == f)
            .count()
    }

    #[test]
    fn a_non_convex_solid_cut_through_its_notch_gives_two_parts_on_one_side() {
        let mut points = Points::new();
        let lot = l_shape(&mut points);
        let solid = extrude(&mut points, &lot, DVec3::Y, 1.0).unwrap();
        assert!((volume(&points, &solid) - 3.0).abs() < 1e-12);
        // The plane x + z = 2.5 crosses both arms: the tip of each arm is
        // the triangle (1.5, 1), (2, 1), (2, 0.5) (or its mirror), area
        // 0.125, so 0.25 above and 3 - 0.25 below (height 1).
        let n = DVec3::new(1.0, 0.0, 1.0).normalize();
        let d = 2.5 / 2f64.sqrt();
        let (below, above) = plane_cut(&mut points, &solid, n, d, 1, 1e-9).unwrap();
        assert!((volume(&points, &above) - 0.25).abs() < 1e-12);
        assert!((volume(&points, &below) - 2.75).abs() < 1e-12);
        assert_closed(&face_lists(&above));
        assert_closed(&face_lists(&below));
        assert_eq!(components(&above), 2);
        assert_eq!(components(&below), 1);
        assert_eq!(above.faces.iter().filter(|f| f.seam == 3).count(), 2);
        // The lot itself: two pieces above, one below sharing cut points.
        let (b2, a2) = plane_cut(&mut points, &lot, n, d, 2, 1e-9).unwrap();
        assert_eq!(a2.faces.len(), 2);
        assert_eq!(b2.faces.len(), 1);
        let below_pts: HashSet<PointId> = b2.point_ids().collect();
        assert_eq!(a2.point_ids().filter(|p| below_pts.contains(p)).count(), 4);
    }

    #[test]
    fn on_plane_vertices_belong_to_both_sides_without_cuts() {
        let mut points = Points::new();
        let b = unit_box(&mut points);
        // A plane through the diagonal edge pair x = z: no edge is crossed
        // between its ends except across the faces; the two halves are
        // prisms of volume 1/2.
        let n = DVec3::new(1.0, 0.0, -1.0).normalize();
        let (lo, hi) = plane_cut(&mut points, &b, n, 0.0, 1, 1e-9).unwrap();
        assert_eq!(
            points.len(),
            8,
            "no new point: the plane passes through vertices"
        );
        assert!((volume(&points, &lo) - 0.5).abs() < 1e-12);
        assert!((volume(&points, &hi) - 0.5).abs() < 1e-12);
        assert_closed(&face_lists(&lo));
        assert_closed(&face_lists(&hi));
        // A plane along a face keeps the whole on one side, without caps.
        let (lo, hi) = plane_cut(&mut points, &b, DVec3::X, 1.0, 2, 1e-9).unwrap();
        assert_eq!((lo.faces.len(), hi.faces.len()), (6, 0));
        let (lo, hi) = plane_cut(&mut points, &b, DVec3::X, 0.0, 3, 1e-9).unwrap();
        assert_eq!((lo.faces.len(), hi.faces.len()), (0, 6));
    }

    #[test]
    fn siblings_cut_by_one_plane_share_the_points_on_their_wall() {
        let mut points = Points::new();
        let b = unit_box(&mut points);
        let halves = split(&mut points, &b, DVec3::ZERO, DVec3::X, &[0.5], 1).unwrap();
        let lo = split(&mut points, &halves[0], DVec3::ZERO, DVec3::Y, &[0.5], 2).unwrap();
        let hi = split(&mut points, &halves[1], DVec3::ZERO, DVec3::Y, &[0.5], 3).unwrap();
        // 8 corners, 4 points of cut 1, and the y cuts cross the 4 vertical
        // edges of each half, 2 of them (at x = 0.5) shared: 6.
        assert_eq!(points.len(), 18);
        let members = [&lo[0], &lo[1], &hi[0], &hi[1]];
        for g in members {
            assert!((volume(&points, g) - 0.25).abs() < 1e-12);
        }
        let w = weld(&mut points, &members, &[], &HashSet::new(), &HashMap::new()).unwrap();
        assert_closed(&w.soup.faces.to_vecs());
        assert_eq!(w.soup.positions.len(), 18);
    }

    #[test]
    fn cuts_through_a_reflex_vertex() {
        let mut points = Points::new();
        let lot = l_shape(&mut points);
        let area = |points: &Points, g: &Geometry| -> f64 {
            g.faces.iter().map(|f| newell(points, &f.pts).y / 2.0).sum()
        };
        // x = 1 runs along the inner wall from the reflex corner (1, 1):
        // [0,1]x[0,2] (area 2) below, [1,2]x[0,1] (area 1) above.
        let (lo, hi) = plane_cut(&mut points, &lot, DVec3::X, 1.0, 1, 1e-9).unwrap();
        assert_eq!((lo.faces.len(), hi.faces.len()), (1, 1));
        assert!((area(&points, &lo) - 2.0).abs() < 1e-12);
        assert!((area(&points, &hi) - 1.0).abs() < 1e-12);
        let solid = extrude(&mut points, &lot, DVec3::Y, 1.0).unwrap();
        for (n, d, vlo, vhi) in [(DVec3::Z, 1.0, 2.0, 1.0), (DVec3::X, 1.0, 2.0, 1.0)] {
            let (lo, hi) = plane_cut(&mut points, &solid, n, d, 2, 1e-9).unwrap();
            assert!((volume(&points, &lo) - vlo).abs() < 1e-12);
            assert!((volume(&points, &hi) - vhi).abs() < 1e-12);
            assert_closed(&face_lists(&lo));
            assert_closed(&face_lists(&hi));
        }
    }

    #[test]
    fn tilted_cuts_of_round_solids_conserve_volume() {
        let mut points = Points::new();
        let far = DVec3::new(1e6, -2e5, 3e5);
        let c = cylinder_in(&mut points, &sized(far, DVec3::new(2.0, 3.0, 1.0)), 24).unwrap();
        let sp = sphere_in(&mut points, &sized(far, DVec3::splat(2.0)), 16, 9).unwrap();
        let mut cut = 1;
        for g in [&c, &sp] {
            let whole = volume(&points, g);
            for n in [
                DVec3::new(1.0, 2.0, 0.5),
                DVec3::new(-0.3, 0.1, 1.0),
                DVec3::X,
            ] {
                let n = n.normalize();
                let d = n.dot(far + DVec3::new(0.9, 1.1, 0.5));
                let (lo, hi) = plane_cut(&mut points, g, n, d, cut, 0.0).unwrap();
                cut += 1;
                assert_closed(&face_lists(&lo));
                assert_closed(&face_lists(&hi));
                let (vl, vh) = (volume(&points, &lo), volume(&points, &hi));
                assert!(vl > 0.0 && vh > 0.0);
                // Both parts make up the whole (additivity of volume).
                assert!(
                    (vl + vh - whole).abs() < 1e-6 * whole.abs().max(1.0),
                    "{vl} + {vh} vs {whole}"
                );
            }
        }
    }

    /// A small deterministic generator (an LCG) for the randomised tests.
    struct Lcg(u64);

    impl Lcg {
        /// Uniform in [0, 1).
        fn next(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// A star-shaped simple polygon in the ground plane, facing up: corner
    /// k at angle 2 pi k / m and a random radius.
    fn star(points: &mut Points, rng: &mut Lcg, m: usize) -> Geometry {
        let corners: Vec<DVec3> = (0..m)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / m as f64;
                let r = 0.3 + rng.next();
                // Counter-clockwise seen from +y: x = cos, z = -sin.
                DVec3::new(r * a.cos(), 0.0, -r * a.sin())
            })
            .collect();
        polygon(points, &corners).unwrap()
    }

    fn area_up(points: &Points, g: &Geometry) -> f64 {
        g.faces.iter().map(|f| newell(points, &f.pts).y / 2.0).sum()
    }

    #[test]
    fn random_cuts_of_non_convex_polygons_and_prisms_conserve_area_and_volume() {
        let mut rng = Lcg(14);
        let mut cut = 1;
        for round in 0..200 {
            let mut points = Points::new();
            let m = 3 + (rng.next() * 12.0) as usize;
            let lot = star(&mut points, &mut rng, m);
            let whole = area_up(&points, &lot);
            let a = rng.next() * std::f64::consts::TAU;
            let n = DVec3::new(a.cos(), 0.0, a.sin());
            // Every other plane passes exactly through a corner.
            let d = if round % 2 == 0 {
                n.dot(points.get(lot.faces[0].pts[(rng.next() * m as f64) as usize]))
            } else {
                (rng.next() - 0.5) * 1.5
            };
            let (lo, hi) = plane_cut(&mut points, &lot, n, d, cut, 1e-9).unwrap();
            cut += 1;
            // Additivity of area; every piece faces up and lies on its side.
            let (al, ah) = (area_up(&points, &lo), area_up(&points, &hi));
            assert!(
                (al + ah - whole).abs() < 1e-9,
                "round {round}: {al} + {ah} vs {whole}"
            );
            for f in &lo.faces {
                assert!(newell(&points, &f.pts).y > 0.0);
                assert!(f.pts.iter().all(|&p| n.dot(points.get(p)) - d <= 1e-9));
            }
            for f in &hi.faces {
                assert!(newell(&points, &f.pts).y > 0.0);
                assert!(f.pts.iter().all(|&p| n.dot(points.get(p)) - d >= -1e-9));
            }
            // The prism over the lot, cut by a plane off the corners: the
            // two closed parts make up its volume.
            if round % 2 == 1 {
                let solid = extrude(&mut points, &lot, DVec3::Y, 1.0).unwrap();
                let tilt = DVec3::new(n.x, 0.4 * (rng.next() - 0.5), n.z).normalize();
                let d = tilt.dot(DVec3::new(0.0, 0.5, 0.0)) + (rng.next() - 0.5);
                let (lo, hi) = plane_cut(&mut points, &solid, tilt, d, cut, 1e-9).unwrap();
                cut += 1;
                assert_closed(&face_lists(&lo));
                assert_closed(&face_lists(&hi));
                let (vl, vh) = (volume(&points, &lo), volume(&points, &hi));
                assert!(
                    (vl + vh - whole).abs() < 1e-9,
                    "round {round}: {vl} + {vh} vs {whole}"
                );
            }
        }
    }

    #[test]
    fn outlines_meeting_at_a_point_give_separate_caps() {
        let mut points = Points::new();
        // Two unit squares facing up that share one corner (1, 0, 1).
        let mut id = |x: f64, z: f64| points.add(DVec3::new(x, 0.0, z)).unwrap();
        let (a0, a1, p, a3) = (id(0.0, 0.0), id(0.0, 1.0), id(1.0, 1.0), id(1.0, 0.0));
        let (b1, b2, b3) = (id(1.0, 2.0), id(2.0, 2.0), id(2.0, 1.0));
        let mut bowtie = Geometry::empty(2);
        bowtie.faces.push(quad(a0, a1, p, a3));
        bowtie.faces.push(quad(p, b1, b2, b3));
        let solid = extrude(&mut points, &bowtie, DVec3::Y, 1.0).unwrap();
        let (lo, hi) = plane_cut(&mut points, &solid, DVec3::Y, 0.5, 1, 1e-9).unwrap();
        // Each square's section is a square cap; both pass through the
        // point cut on the shared vertical edge.
        let caps: Vec<&Face> = lo.faces.iter().filter(|f| f.seam == 2).collect();
        assert_eq!(caps.len(), 2);
        assert!(caps.iter().all(|f| f.pts.len() == 4));
        let shared: Vec<PointId> = caps[0]
            .pts
            .iter()
            .copied()
            .filter(|q| caps[1].pts.contains(q))
            .collect();
        assert_eq!(shared.len(), 1);
        assert_eq!(points.get(shared[0]), DVec3::new(1.0, 0.5, 1.0));
        // Two unit squares by half the height on each side.
        assert!((volume(&points, &lo) - 1.0).abs() < 1e-12);
        assert!((volume(&points, &hi) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn a_cap_with_a_hole_is_refused() {
        let mut points = Points::new();
        // A square frame: outer [0,3]^2, inner [1,2]^2 in (x, z), as 4
        // quads facing +y, extruded up: a solid with a hole through it.
        let corner = |x: f64, z: f64| DVec3::new(x, 0.0, z);
        let o = [
            corner(0.0, 0.0),
            corner(0.0, 3.0),
            corner(3.0, 3.0),
            corner(3.0, 0.0),
        ];
        let i = [
            corner(1.0, 1.0),
            corner(1.0, 2.0),
            corner(2.0, 2.0),
            corner(2.0, 1.0),
        ];
        let oid: Vec<PointId> = o.iter().map(|&p| points.add(p).unwrap()).collect();
        let iid: Vec<PointId> = i.iter().map(|&p| points.add(p).unwrap()).collect();
        let mut frame = Geometry::empty(2);
        for k in 0..4 {
            let j = (k + 1) % 4;
            frame.faces.push(quad(oid[k], oid[j], iid[j], iid[k]));
        }
        assert!(newell(&points, &frame.faces[0].pts).y > 0.0);
        let solid = extrude(&mut points, &frame, DVec3::Y, 1.0).unwrap();
        assert_closed(&face_lists(&solid));
        // Outer 9 - inner 1, height 1.
        assert!((volume(&points, &solid) - 8.0).abs() < 1e-12);
        let e = plane_cut(&mut points, &solid, DVec3::Y, 0.5, 1, 1e-9);
        assert!(e.unwrap_err().contains("hole"));
        // Across the hole's axis there is no hole in the caps.
        let (lo, hi) = plane_cut(&mut points, &solid, DVec3::X, 1.5, 2, 1e-9).unwrap();
        assert!((volume(&points, &lo) - 4.0).abs() < 1e-12);
        assert!((volume(&points, &hi) - 4.0).abs() < 1e-12);
        assert_eq!(lo.faces.iter().filter(|f| f.seam == 4).count(), 2);
    }

    #[test]
    fn primitives_are_closed_with_outward_faces() {
        let mut points = Points::new();
        let s = sized(DVec3::new(1.0, 2.0, 3.0), DVec3::new(2.0, 3.0, 4.0));
        let b = box_in(&mut points, &s).unwrap();
        assert_closed(&face_lists(&b));
        assert!((volume(&points, &b) - 24.0).abs() < 1e-12);

        // A regular n-gon of circumradius r has area (n / 2) r^2 sin(2 pi / n).
        let n = 64;
        let c = cylinder_in(
            &mut points,
            &sized(DVec3::ZERO, DVec3::new(2.0, 5.0, 2.0)),
            n,
        )
        .unwrap();
        assert_closed(&face_lists(&c));
        let ngon = n as f64 / 2.0 * (std::f64::consts::TAU / n as f64).sin();
        assert!((volume(&points, &c) - 5.0 * ngon).abs() < 1e-9);
        assert!((volume(&points, &c) / (5.0 * std::f64::consts::PI) - 1.0).abs() < 0.01);

        let sp = sphere_in(&mut points, &sized(DVec3::ZERO, DVec3::splat(2.0)), 32, 16).unwrap();
        assert_closed(&face_lists(&sp));
        for f in &sp.faces {
            assert!(
                newell(&points, &f.pts).length() > 1e-6,
                "no degenerate face"
            );
        }
        let v = volume(&points, &sp);
        let ball = 4.0 / 3.0 * std::f64::consts::PI;
        assert!(v < ball && v > 0.95 * ball, "{v} vs {ball}");
        // 32 triangles at each pole, 32 x 14 quads.
        assert_eq!(sp.faces.len(), 64 + 32 * 14);

        // A zero-size scope gives nothing.
        let flat = sized(DVec3::ZERO, DVec3::new(1.0, 0.0, 1.0));
        assert!(box_in(&mut points, &flat).unwrap().is_empty());
        assert!(sphere_in(&mut points, &flat, 8, 4).unwrap().is_empty());
        assert!(cylinder_in(&mut points, &flat, 2).is_err());
    }

    #[test]
    fn a_mesh_fills_its_scope() {
        let mut points = Points::new();
        // A tetrahedron with outward faces, volume 1/6, in [0,1]^3.
        let soup = PolygonSoup {
            positions: vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z],
            faces: vec![vec![0, 2, 1], vec![0, 1, 3], vec![0, 3, 2], vec![1, 2, 3]].into(),
            ..PolygonSoup::default()
        };
        let s = sized(DVec3::new(5.0, 0.0, 0.0), DVec3::new(2.0, 3.0, 4.0));
        let g = mesh_in(&mut points, &s, &soup).unwrap();
        assert_closed(&face_lists(&g));
        // Scaled by 2, 3, 4.
        assert!((volume(&points, &g) - 24.0 / 6.0).abs() < 1e-12);
        let bs = bounding_scope(&points, &g, s.axes);
        assert_eq!(bs.origin, s.origin);
        assert_eq!(bs.size, s.size);
        // A flat soup lands on the scope's origin plane.
        let flat = PolygonSoup {
            positions: vec![DVec3::ZERO, DVec3::X, DVec3::Y],
            faces: vec![vec![0, 1, 2]].into(),
            ..PolygonSoup::default()
        };
        let g = mesh_in(&mut points, &s, &flat).unwrap();
        assert!(g.point_ids().all(|p| points.get(p).z == 0.0));
        let bad = PolygonSoup {
            faces: vec![vec![0, 1, 7]].into(),
            ..flat
        };
        assert!(mesh_in(&mut points, &s, &bad).is_err());
    }

    #[test]
    fn extruding_a_lot_gives_height_times_area() {
        let mut points = Points::new();
        let lot = polygon_in(
            &mut points,
            &Scope::world(),
            &[
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(0.0, 0.0, 2.0),
                DVec3::new(2.0, 0.0, 2.0),
                DVec3::new(2.0, 0.0, 0.0),
            ],
        )
        .unwrap();
        assert!(newell(&points, &lot.faces[0].pts).y > 0.0);
        let area = 4.0;
        for (dir, h) in [(DVec3::Y, 3.0), (DVec3::Y, -3.0), (DVec3::NEG_Y, 3.0)] {
            let g = extrude(&mut points, &lot, dir, h).unwrap();
            assert_closed(&face_lists(&g));
            assert!((volume(&points, &g) - 3.0 * area).abs() < 1e-12);
            // The base keeps the lot's ids.
            assert!(g.faces[0].pts.iter().all(|p| lot.faces[0].pts.contains(p)));
        }
        // The lot's own scope: x along its first edge (+z here), y up.
        let s = lot_scope(&points, &lot).unwrap();
        assert!((s.axes[0] - DVec3::Z).length() < 1e-12);
        assert!((s.axes[1] - DVec3::Y).length() < 1e-12);
        assert!((s.axes[2] + DVec3::X).length() < 1e-12);
        assert!((s.size - DVec3::new(2.0, 0.0, 2.0)).length() < 1e-12);
        assert!((s.origin - DVec3::new(2.0, 0.0, 0.0)).length() < 1e-12);
        assert!(extrude(&mut points, &lot, DVec3::X, 3.0).is_err());
        assert!(extrude(&mut points, &lot, DVec3::Y, f64::NAN).is_err());
    }

    #[test]
    fn comp_of_a_box_gives_each_side_once_with_up_facades() {
        let mut points = Points::new();
        let s = sized(DVec3::ZERO, DVec3::new(2.0, 3.0, 4.0));
        let b = box_in(&mut points, &s).unwrap();
        for name in ["front", "back", "left", "right", "top", "bottom"] {
            let sel = Selector::parse(name).unwrap();
            let faces = comp_faces(&points, &b, &s, sel);
            assert_eq!(faces.len(), 1, "{name}");
            let (g, fs) = &faces[0];
            assert_eq!(g.dim, 2);
            assert_eq!(
                g.faces[0],
                *b.faces.iter().find(|f| f.pts == g.faces[0].pts).unwrap()
            );
            assert_eq!(fs.size.z, 0.0);
        }
        let sides = comp_faces(&points, &b, &s, Selector::Side);
        assert_eq!(sides.len(), 4);
        for (_, fs) in &sides {
            assert!((fs.axes[1] - DVec3::Y).length() < 1e-12);
            assert!(fs.axes[2].y.abs() < 1e-12);
            assert!((fs.size.y - 3.0).abs() < 1e-12);
        }
        let (_, front) = &comp_faces(&points, &b, &s, Selector::Front)[0];
        assert!((front.size - DVec3::new(2.0, 3.0, 0.0)).length() < 1e-12);
        assert!((front.origin - DVec3::new(0.0, 0.0, 4.0)).length() < 1e-12);
        assert_eq!(comp_faces(&points, &b, &s, Selector::Horizontal).len(), 2);
        assert_eq!(comp_faces(&points, &b, &s, Selector::All).len(), 6);
        // 12 edges and 8 vertices.
        let edges = comp_edges(&points, &b, &s);
        assert_eq!(edges.len(), 12);
        for (g, es) in &edges {
            let [a, c] = g.edges[0];
            let e = points.get(c) - points.get(a);
            assert!((es.axes[0] * es.size.x - e).length() < 1e-12);
        }
        assert_eq!(comp_vertices(&points, &b, &s).len(), 8);
        assert_eq!(Selector::parse("sideways"), None);
    }

    #[test]
    fn classify_by_the_dominant_component_with_y_then_z_winning_ties() {
        assert_eq!(Selector::classify(DVec3::ONE), Selector::Top);
        assert_eq!(
            Selector::classify(DVec3::new(1.0, -1.0, 0.0)),
            Selector::Bottom
        );
        assert_eq!(
            Selector::classify(DVec3::new(1.0, 0.0, -1.0)),
            Selector::Back
        );
        assert_eq!(
            Selector::classify(DVec3::new(-2.0, 1.0, 1.0)),
            Selector::Left
        );
        assert_eq!(
            Selector::classify(DVec3::new(0.0, 0.2, 0.3)),
            Selector::Front
        );
        assert_eq!(
            Selector::classify(DVec3::new(0.5, 0.2, 0.3)),
            Selector::Right
        );
    }

    #[test]
    fn cuts_are_shared_and_resolved_in_chains() {
        let mut points = Points::new();
        let a = points.add(DVec3::ZERO).unwrap();
        let b = points.add(DVec3::new(1.0, 0.0, 0.0)).unwrap();
        let c = points.add(DVec3::new(0.0, 1.0, 0.0)).unwrap();
        let m = points.cut(a, b, DVec3::X, 0.5).unwrap();
        assert_eq!(points.cut(b, a, DVec3::X, 0.5).unwrap(), m);
        assert_eq!(points.get(m), DVec3::new(0.5, 0.0, 0.0));
        // A cut on a cut, and a sibling's cut of the whole edge by the
        // same plane: one point each.
        let q = points.cut(a, m, DVec3::X, 0.25).unwrap();
        assert_eq!(points.cut(a, b, DVec3::X, 0.25).unwrap(), q);
        let r = points.cut(m, b, DVec3::X, 0.75).unwrap();
        let mut out = Vec::new();
        points.resolve(&[a, b, c], &mut out);
        assert_eq!(out, vec![a, q, m, r, b, c]);
        points.resolve(&[c, b, a], &mut out);
        assert_eq!(out, vec![c, b, r, m, q, a]);
        points.resolve(&[q, r, c], &mut out);
        assert_eq!(out, vec![q, m, r, c]);
        assert_eq!(points.len(), 6);
    }

    #[test]
    fn bad_input_gives_errors_not_panics() {
        let mut points = Points::new();
        assert!(points.add(DVec3::new(f64::NAN, 0.0, 0.0)).is_err());
        let b = unit_box(&mut points);
        assert!(plane_cut(&mut points, &b, DVec3::ZERO, 0.5, 1, 1e-9).is_err());
        assert!(plane_cut(&mut points, &b, DVec3::X, f64::NAN, 1, 1e-9).is_err());
        assert!(plane_cut(&mut points, &b, DVec3::X, 0.5, 0, 1e-9).is_err());
        assert!(split(&mut points, &b, DVec3::ZERO, DVec3::X, &[0.7, 0.3], 1).is_err());
        let e = Geometry::empty(3);
        let pieces = split(&mut points, &e, DVec3::ZERO, DVec3::X, &[0.5], 1).unwrap();
        assert!(pieces.iter().all(Geometry::is_empty));
        // Cuts outside the shape give empty pieces.
        let pieces = split(&mut points, &b, DVec3::ZERO, DVec3::X, &[-1.0, 2.0], 1).unwrap();
        assert!(pieces[0].is_empty() && pieces[2].is_empty());
        assert_eq!(pieces[1].faces.len(), 6);
        let ghost = Geometry {
            verts: vec![999],
            ..Geometry::empty(0)
        };
        assert!(plane_cut(&mut points, &ghost, DVec3::X, 0.5, 1, 1e-9).is_err());
        let bs = bounding_scope(&points, &e, Scope::world().axes);
        assert_eq!(bs.size, DVec3::ZERO);
        let nan = DAffine3::from_translation(DVec3::NAN);
        assert!(transform(&mut points, &b, &nan).is_err());
    }

    #[test]
    fn transform_copies_onto_new_points_and_keeps_faces_outward() {
        let mut points = Points::new();
        let b = unit_box(&mut points);
        let mirror = DAffine3::from_scale(DVec3::new(-2.0, 1.0, 1.0));
        let t = transform(&mut points, &b, &mirror).unwrap();
        let old: HashSet<PointId> = b.point_ids().collect();
        assert!(t.point_ids().all(|p| !old.contains(&p)));
        assert_eq!(t.unique_points().len(), 8);
        assert_closed(&face_lists(&t));
        assert!((volume(&points, &t) - 2.0).abs() < 1e-12);
    }

    #[test]
    fn lower_dimensions_split_too() {
        let mut points = Points::new();
        let a = points.add(DVec3::ZERO).unwrap();
        let b = points.add(DVec3::new(2.0, 0.0, 0.0)).unwrap();
        let edge = Geometry {
            edges: vec![[a, b]],
            ..Geometry::empty(1)
        };
        let (lo, hi) = plane_cut(&mut points, &edge, DVec3::X, 0.5, 1, 1e-9).unwrap();
        let m = lo.edges[0][1];
        assert_eq!(lo.edges, vec![[a, m]]);
        assert_eq!(hi.edges, vec![[m, b]]);
        assert_eq!(points.get(m).x, 0.5);
        let pts = Geometry {
            verts: vec![a, b, m],
            ..Geometry::empty(0)
        };
        let (lo, hi) = plane_cut(&mut points, &pts, DVec3::X, 0.5, 2, 1e-9).unwrap();
        assert_eq!(lo.verts, vec![a, m]);
        assert_eq!(hi.verts, vec![b]);
    }

    /// The S0/S1 case: a 2 x 4 x 2 box split at x = 1 (cut 1); the left
    /// part split at y = 1 (cut 2), the right part at y = 2 (cut 3), in
    /// the order asked; both lower parts welded, cut 1's wall refined by
    /// the planes of the splits that crossed it, in the order they ran.
    fn s0_s1(right_first: bool, loose: &[u32]) -> (Points, Welded) {
        let mut points = Points::new();
        let b = box_in(&mut points, &sized(DVec3::ZERO, DVec3::new(2.0, 4.0, 2.0))).unwrap();
        let halves = split(&mut points, &b, DVec3::ZERO, DVec3::X, &[1.0], 1).unwrap();
        let right_origin = DVec3::new(1.0, 0.0, 0.0);
        let mut planes = Vec::new();
        let mut left = None;
        let mut right = None;
        for step in 0..2 {
            if (step == 0) != right_first {
                left =
                    Some(split(&mut points, &halves[0], DVec3::ZERO, DVec3::Y, &[1.0], 2).unwrap());
                planes.push(plane_of(DVec3::ZERO, DVec3::Y, 1.0));
            } else {
                right = Some(
                    split(&mut points, &halves[1], right_origin, DVec3::Y, &[2.0], 3).unwrap(),
                );
                planes.push(plane_of(right_origin, DVec3::Y, 2.0));
            }
        }
        let (left, right) = (left.unwrap(), right.unwrap());
        assert!((volume(&points, &left[0]) - 2.0).abs() < 1e-12);
        assert!((volume(&points, &right[0]) - 4.0).abs() < 1e-12);
        // The lower left part holds caps of cuts 1 and 2, the right one of
        // cuts 1 and 3.
        assert_eq!(seams_of(&left[0]).collect::<Vec<_>>(), vec![1, 2]);
        assert_eq!(seams_of(&right[0]).collect::<Vec<_>>(), vec![1, 3]);
        let seam_planes: HashMap<u32, Vec<(DVec3, f64)>> = [(1, planes)].into_iter().collect();
        let w = weld(
            &mut points,
            &[&left[0], &right[0]],
            &[],
            &loose.iter().copied().collect(),
            &seam_planes,
        )
        .unwrap();
        (points, w)
    }

    #[test]
    fn a_wall_cut_later_on_one_side_only_is_refined_on_both() {
        let (points, w) = s0_s1(false, &[]);
        // Every edge in two faces: closed, and no T-junction (a vertex in
        // the middle of another face's edge would leave that edge in one).
        assert_closed(&w.soup.faces.to_vecs());
        // [0, 1] x [0, 1] x [0, 2] and [1, 2] x [0, 2] x [0, 2].
        let v = 1.0 * 1.0 * 2.0 + 1.0 * 2.0 * 2.0;
        assert!((volume(&points, &soup_geometry(&w)) - v).abs() < 1e-12);
        // The wall's part against the left piece went; its part above
        // y = 1 stayed, facing -x.
        let walls: Vec<DVec3> = w
            .soup
            .faces
            .iter()
            .filter(|f| f.iter().all(|&v| w.soup.positions[v as usize].x == 1.0))
            .map(|f| {
                let ids: Vec<PointId> = f.iter().map(|&v| w.point_of[v as usize]).collect();
                newell(&points, &ids)
            })
            .collect();
        assert_eq!(walls.len(), 1);
        assert!(walls[0].x < 0.0);
    }

    #[test]
    fn the_order_of_splits_does_not_change_positions() {
        let sorted = |points: &Points, w: &Welded| {
            let mut v: Vec<[u64; 3]> = w
                .point_of
                .iter()
                .map(|&p| {
                    let q = points.get(p);
                    [q.x.to_bits(), q.y.to_bits(), q.z.to_bits()]
                })
                .collect();
            v.sort_unstable();
            v
        };
        let (pa, wa) = s0_s1(false, &[]);
        let (pb, wb) = s0_s1(true, &[]);
        assert_closed(&wb.soup.faces.to_vecs());
        assert_eq!(sorted(&pa, &wa), sorted(&pb, &wb));
        assert_eq!(wa.soup.faces.len(), wb.soup.faces.len());
        // Every point of the derivation too (the right piece's removed
        // upper part included).
        let all = |p: &Points| {
            let mut v: Vec<[u64; 3]> = p
                .pos
                .iter()
                .map(|q| [q.x.to_bits(), q.y.to_bits(), q.z.to_bits()])
                .collect();
            v.sort_unstable();
            v
        };
        assert_eq!(all(&pa), all(&pb));
    }

    #[test]
    fn a_cut_on_a_root_is_found_from_any_piece_and_placed_from_its_canonical_end() {
        let mut points = Points::new();
        // Made in the order b, a: a (the smaller x) is the canonical end.
        let b = points.add(DVec3::new(3.0, 0.0, 0.0)).unwrap();
        let a = points.add(DVec3::new(0.0, 0.0, 0.0)).unwrap();
        let m = points.cut(b, a, DVec3::X, 2.0).unwrap();
        let q = points.cut(a, b, DVec3::X, 1.0).unwrap();
        // The plane x = 2 asked again from the piece (q, b): the same point.
        assert_eq!(points.cut(q, b, DVec3::X, 2.0).unwrap(), m);
        assert_eq!(points.cut(b, q, DVec3::X, 2.0).unwrap(), m);
        // t = 2/3 and 1/3 along a -> b.
        assert_eq!(
            points.get(m),
            DVec3::new(0.0 + (2.0f64 / 3.0) * 3.0, 0.0, 0.0)
        );
        assert_eq!(
            points.get(q),
            DVec3::new(0.0 + (1.0f64 / 3.0) * 3.0, 0.0, 0.0)
        );
        // Two planes on one root: both points, in order, on every piece.
        let c = points.add(DVec3::new(0.0, 1.0, 0.0)).unwrap();
        let mut out = Vec::new();
        points.resolve(&[b, a, c], &mut out);
        assert_eq!(out, vec![b, m, q, a, c]);
        points.resolve(&[q, b, c], &mut out);
        assert_eq!(out, vec![q, m, b, c]);
        assert_eq!(points.len(), 5);
    }

    /// Splits `g` (its scope `s`) in half along x, pieces with their scopes
    /// (the origin moved as a split moves it).
    fn halve(
        points: &mut Points,
        g: &Geometry,
        s: Scope,
        cut: u32,
    ) -> Result<Vec<(Geometry, Scope)>, String> {
        let half = s.size.x / 2.0;
        let pieces = split(points, g, s.origin, s.axes[0], &[half], cut)?;
        let mut off = 0.0;
        let mut out = Vec::new();
        for p in pieces {
            let mut sc = s;
            sc.origin += s.axes[0] * off;
            sc.size.x = half;
            off += half;
            out.push((p, sc));
        }
        Ok(out)
    }

    #[test]
    fn repeated_halving_gives_closed_pieces_of_the_right_volumes() {
        let mut points = Points::new();
        let s = sized(DVec3::ZERO, DVec3::new(8.0, 1.0, 1.0));
        let b = box_in(&mut points, &s).unwrap();
        let mut work = vec![(b, s)];
        let mut cut = 1;
        for _ in 0..9 {
            let mut next = Vec::new();
            for (g, s) in &work {
                next.extend(halve(&mut points, g, *s, cut).unwrap());
                cut += 1;
            }
            work = next;
        }
        // 2^9 = 512 pieces of 8/512 x 1 x 1.
        assert_eq!(work.len(), 512);
        for (g, _) in &work {
            assert_closed(&face_lists(g));
            assert!((volume(&points, g) - 8.0 / 512.0).abs() < 1e-12);
        }
        let members: Vec<&Geometry> = work.iter().map(|(g, _)| g).collect();
        let w = weld(&mut points, &members, &[], &HashSet::new(), &HashMap::new()).unwrap();
        assert_closed(&w.soup.faces.to_vecs());
        assert!((volume(&points, &soup_geometry(&w)) - 8.0).abs() < 1e-9);
        // 8 corners and 4 points on each of the 511 walls.
        assert_eq!(w.soup.positions.len(), 8 + 4 * 511);
    }

    #[test]
    fn halving_past_the_precision_of_the_numbers_does_not_fail() {
        // The last piece halved again and again (a runaway grammar): past
        // the cut tolerance a piece stops being cut (it goes whole below),
        // and nothing fails.
        let mut points = Points::new();
        let s = sized(DVec3::ZERO, DVec3::new(8.0, 1.0, 1.0));
        let b = box_in(&mut points, &s).unwrap();
        let mut cur = (b, s);
        let mut kept = Vec::new();
        for cut in 1..=80 {
            let mut two = halve(&mut points, &cur.0, cur.1, cut).unwrap();
            cur = two.pop().unwrap();
            kept.push(two.pop().unwrap().0);
        }
        kept.push(cur.0);
        let mut total = 0.0;
        for (i, g) in kept.iter().enumerate() {
            if g.is_empty() {
                continue;
            }
            assert_closed(&face_lists(g));
            let v = volume(&points, g);
            assert!(v > 0.0);
            // While a half is well above the tolerance it is exact.
            if i < 20 {
                assert!((v - 8.0 / 2f64.powi(i as i32 + 1)).abs() < 1e-12);
            }
            total += v;
        }
        assert!((total - 8.0).abs() < 1e-12);
    }

    #[test]
    fn cut_positions_do_not_depend_on_the_order_of_cuts_or_ids() {
        // Two planes cross a segment; run A makes its ends in one order and
        // cuts at plane 1 then plane 2 (on the piece left over), run B
        // makes the ends the other way round and cuts at plane 2 first.
        // The same geometric points must come out bit for bit.
        let mut rng = Lcg(7);
        let mut r = |s: f64| (rng.next() - 0.5) * s;
        for _ in 0..500 {
            let a = DVec3::new(r(10.0), r(10.0), r(10.0));
            let b = DVec3::new(r(10.0), r(10.0), r(10.0));
            let n = DVec3::new(r(2.0), r(2.0), r(2.0)) + (b - a).normalize();
            let (t1, t2) = (0.1 + 0.35 * (r(1.0) + 0.5), 0.55 + 0.35 * (r(1.0) + 0.5));
            let d1 = n.dot(a + t1 * (b - a));
            let d2 = n.dot(a + t2 * (b - a));
            let mut pa = Points::new();
            let (ia, ib) = (pa.add(a).unwrap(), pa.add(b).unwrap());
            let m = pa.cut(ia, ib, n, d1).unwrap();
            let q = pa.cut(m, ib, n, d2).unwrap();
            let mut pb = Points::new();
            let (jb, ja) = (pb.add(b).unwrap(), pb.add(a).unwrap());
            let q2 = pb.cut(jb, ja, n, d2).unwrap();
            let m2 = pb.cut(ja, q2, n, d1).unwrap();
            assert_eq!(pa.get(m), pb.get(m2));
            assert_eq!(pa.get(q), pb.get(q2));
        }
    }

    #[test]
    fn walls_refined_by_crossing_planes_from_both_sides_still_match() {
        // A 2 x 4 x 2 box split at x = 1 (cut 1); the left part split at
        // y = 1 (cut 2), the right part at z = 1 (cut 3): the wall's
        // refinement puts a point where the two lines cross, reached along
        // the y = 1 line on one side and along the z = 1 line on the other.
        for right_first in [false, true] {
            let mut points = Points::new();
            let b = box_in(&mut points, &sized(DVec3::ZERO, DVec3::new(2.0, 4.0, 2.0))).unwrap();
            let halves = split(&mut points, &b, DVec3::ZERO, DVec3::X, &[1.0], 1).unwrap();
            let ro = DVec3::new(1.0, 0.0, 0.0);
            let (mut left, mut right, mut planes) = (None, None, Vec::new());
            for step in 0..2 {
                if (step == 0) != right_first {
                    left = Some(
                        split(&mut points, &halves[0], DVec3::ZERO, DVec3::Y, &[1.0], 2).unwrap(),
                    );
                    planes.push(plane_of(DVec3::ZERO, DVec3::Y, 1.0));
                } else {
                    right = Some(split(&mut points, &halves[1], ro, DVec3::Z, &[1.0], 3).unwrap());
                    planes.push(plane_of(ro, DVec3::Z, 1.0));
                }
            }
            let (left, right) = (left.unwrap(), right.unwrap());
            let seam_planes: HashMap<u32, Vec<(DVec3, f64)>> = [(1, planes)].into_iter().collect();
            let w = weld(
                &mut points,
                &[&left[0], &right[0]],
                &[],
                &HashSet::new(),
                &seam_planes,
            )
            .unwrap();
            assert_closed(&w.soup.faces.to_vecs());
            // [0, 1] x [0, 1] x [0, 2] and [1, 2] x [0, 4] x [0, 1].
            let v = 1.0 * 1.0 * 2.0 + 1.0 * 4.0 * 1.0;
            assert!((volume(&points, &soup_geometry(&w)) - v).abs() < 1e-12);
        }
    }

    #[test]
    fn a_loose_wall_cut_on_one_side_only_opens_where_both_sides_meet() {
        let (points, w) = s0_s1(false, &[1]);
        // Both parts closed on their own: the pair of wall pieces that
        // mirror each other stays, the right part on copies of its points.
        assert_closed(&w.soup.faces.to_vecs());
        assert!((volume(&points, &soup_geometry(&w)) - 6.0).abs() < 1e-12);
        // The left part's 8 corners, the right part's 8 corners (2 of them
        // copies) and its 2 copied points at y = 1 on the wall: 18, and
        // the 4 corners of the mirrored piece twice.
        assert_eq!(w.soup.positions.len(), 18);
        let mut at: HashMap<[u64; 3], usize> = HashMap::new();
        for p in &w.soup.positions {
            *at.entry([p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
                .or_default() += 1;
        }
        assert_eq!(at.values().filter(|&&k| k == 2).count(), 4);
        // Left: 6 faces; right: 5 outer faces and its wall in 2 pieces.
        assert_eq!(w.soup.faces.len(), 13);
    }
}
