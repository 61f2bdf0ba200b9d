//! Conversion from and to polygon soups.

use crate::mesh::PolygonSoup;

use super::{Rotation, NULL};

impl Rotation {
    // ----- polygon soups -------------------------------------------------

    /// The system built from the counter-clockwise polygons of `soup`
    /// (any size from 3): vertex `i` of the soup is vertex `i` here, at
    /// its position; the second value lists the vertices in id order.
    ///
    /// At a corner `(…, a, v, b, …)` of a polygon, `a` immediately follows
    /// `b` in `v`'s counter-clockwise list; each vertex's corners link into
    /// one fan, open (a boundary vertex, its first the fan's start) or
    /// closed. Refused: polygons of fewer than 3 vertices, a vertex twice
    /// in a polygon, an index out of range, a directed edge used by two
    /// polygons (orientations that disagree, or more than two polygons at
    /// an edge) and a vertex whose polygons form more than one fan. A
    /// vertex in no polygon has no neighbours.
    pub fn from_soup(soup: &PolygonSoup) -> Result<(Rotation, Vec<u32>), String> {
        let n = soup.positions.len();
        if n >= NULL as usize {
            return Err(format!("the mesh has {n} vertices, too many"));
        }
        let face = |f: usize| match soup.face_line(f) {
            Some(l) => format!("face {} (line {l})", f + 1),
            None => format!("face {}", f + 1),
        };
        // Corners sorted by vertex: `start[v]..start[v + 1]`.
        let mut start = vec![0usize; n + 1];
        for (fi, f) in soup.faces.iter().enumerate() {
            if f.len() < 3 {
                return Err(format!(
                    "{} has {} vertices; a face needs at least 3",
                    face(fi),
                    f.len()
                ));
            }
            if let Some(&v) = f.iter().find(|&&v| v as usize >= n) {
                return Err(format!(
                    "{} refers to vertex {}, but there are only {n} vertices",
                    face(fi),
                    v as usize + 1
                ));
            }
            if let Some(k) = crate::mesh::soup::first_repeat(f) {
                return Err(format!(
                    "{} uses vertex {} twice",
                    face(fi),
                    f[k] as usize + 1
                ));
            }
            for &v in f {
                start[v as usize + 1] += 1;
            }
        }
        for v in 0..n {
            start[v + 1] += start[v];
        }
        /// A corner at a vertex: `a` follows `b` there; from polygon `face`.
        #[derive(Clone, Copy)]
        struct Corner {
            b: u32,
            a: u32,
            face: usize,
        }
        let mut fill = start.clone();
        let mut corners = vec![
            Corner {
                b: 0,
                a: 0,
                face: 0
            };
            start[n]
        ];
        for (fi, f) in soup.faces.iter().enumerate() {
            let k = f.len();
            for j in 0..k {
                let v = f[j] as usize;
                corners[fill[v]] = Corner {
                    b: f[(j + 1) % k],
                    a: f[(j + k - 1) % k],
                    face: fi,
                };
                fill[v] += 1;
            }
        }
        // Each directed edge (v, b) once.
        for v in 0..n {
            let cs = &mut corners[start[v]..start[v + 1]];
            cs.sort_unstable_by_key(|c| (c.b, c.face));
            if let Some(w) = cs.windows(2).find(|w| w[0].b == w[1].b) {
                return Err(format!(
                    "{} and {} both run from vertex {} to vertex {}: their orientations \
                     disagree, or more than two faces meet at that edge",
                    face(w[0].face),
                    face(w[1].face),
                    v + 1,
                    w[0].b as usize + 1
                ));
            }
        }
        // One fan per vertex.
        let mut rot = Rotation::new();
        let mut has_pred = vec![false; start[n]];
        for v in 0..n {
            let id = rot.new_vertex();
            rot.pos[id as usize] = soup.positions[v];
            let (s, e) = (start[v], start[v + 1]);
            let cs = &corners[s..e];
            let next = |x: u32| cs.binary_search_by_key(&x, |c| c.b).ok();
            for c in cs {
                if let Some(k) = next(c.a) {
                    has_pred[s + k] = true;
                }
            }
            let mut starts = (0..cs.len()).filter(|&k| !has_pred[s + k]);
            let first = starts.next();
            let open = first.is_some();
            let bow_tie = || {
                format!(
                    "vertex {} is a bow-tie: its faces form more than one fan, so the mesh is \
                     not a 2-manifold there",
                    v + 1
                )
            };
            if starts.next().is_some() {
                return Err(bow_tie());
            }
            if cs.is_empty() {
                continue;
            }
            let k0 = first.unwrap_or(0);
            let list = &mut rot.nbs[v];
            list.push(cs[k0].b);
            let mut k = k0;
            let mut walked = 1;
            loop {
                let a = cs[k].a;
                if a == cs[k0].b {
                    break; // closed, back at the start
                }
                list.push(a);
                match next(a) {
                    Some(j) if walked < cs.len() => {
                        k = j;
                        walked += 1;
                    }
                    _ => break, // open: `a` is the last
                }
            }
            if walked != cs.len() {
                return Err(bow_tie());
            }
            rot.open[v] = open;
        }
        let members = (0..n as u32).collect();
        Ok((rot, members))
    }

    /// `set` as a polygon soup: the positions in `set`'s order and the
    /// faces of [`Rotation::faces`] by position in `set`.
    pub fn to_soup(&self, set: &[u32]) -> Result<PolygonSoup, String> {
        self.to_soup_and_holes(set).map(|(soup, _)| soup)
    }

    /// [`Rotation::to_soup`], and the number of holes, from one walk.
    pub fn to_soup_and_holes(&self, set: &[u32]) -> Result<(PolygonSoup, usize), String> {
        let mut index = vec![0u32; self.alive.len()];
        for (k, &v) in set.iter().enumerate() {
            if let Some(i) = index.get_mut(v as usize) {
                *i = k as u32;
            }
        }
        let mut faces = crate::mesh::Faces::new();
        let mut holes = 0;
        self.trace(set, true, |hole, vs| {
            if hole {
                holes += 1;
            } else {
                faces.push(vs.iter().map(|&v| index[v as usize]).collect::<Vec<u32>>());
            }
        })?;
        let soup = PolygonSoup {
            positions: set.iter().map(|&v| self.pos[v as usize]).collect(),
            faces,
            ..Default::default()
        };
        Ok((soup, holes))
    }
}
