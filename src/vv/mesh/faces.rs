//! The consistency check, and the faces and holes of a set by Edmonds'
//! technique (§2.1).

use super::{find, Rotation, NULL};

impl Rotation {
    // ----- structure -----------------------------------------------------

    /// The consistency check of the vertex-vertex system over `set`, with
    /// the first problem found (members in id order, neighbours in list
    /// order): every member alive and listed once; the set closed (every
    /// neighbour of a member a member); no vertex its own neighbour or
    /// listed twice; symmetry (`u ∈ v*` iff `v ∈ u*`); and a 2-manifold
    /// face structure: every orbit of Edmonds' technique is a face (no
    /// corner in a gap, at least 3 vertices, none twice) or a hole (every
    /// corner in a gap, at least 3 vertices).
    pub fn check(&self, set: &[u32]) -> Result<(), String> {
        // The order of the orbits does not matter to a check.
        self.trace(set, false, |_, _| {})
    }

    /// The faces of the polygonal interpretation of `set` (Edmonds'
    /// technique, §2.1), each counter-clockwise seen from the outside and
    /// starting at its smallest vertex, ordered by their first two
    /// vertices. Refused as [`Rotation::check`] refuses.
    pub fn faces(&self, set: &[u32]) -> Result<Vec<Vec<u32>>, String> {
        self.orbits(set, false)
    }

    /// The holes (boundary loops) of `set`, each as its orbit runs
    /// (clockwise seen from the outside), starting at its smallest vertex,
    /// ordered by their first two vertices. Refused as [`Rotation::check`]
    /// refuses.
    pub fn holes(&self, set: &[u32]) -> Result<Vec<Vec<u32>>, String> {
        self.orbits(set, true)
    }

    fn orbits(&self, set: &[u32], holes: bool) -> Result<Vec<Vec<u32>>, String> {
        let mut out = Vec::new();
        self.trace(set, true, |hole, vs| {
            if hole == holes {
                out.push(vs.to_vec());
            }
        })?;
        Ok(out)
    }

    /// Checks `set` and hands every orbit to `each` (whether it is a hole,
    /// its vertices from its smallest one), ordered by their first two
    /// vertices.
    ///
    /// The orbit of the directed edge `(u, v)` continues with `(v, w)`,
    /// `w` the vertex before `u` in `v`'s list read cyclically, which with
    /// counter-clockwise lists traces a face counter-clockwise. The corner
    /// `(u, v, w)` lies in `v`'s gap when `v` is open and `u` is its first.
    ///
    /// Members are taken in id order, so an orbit is met first at its
    /// smallest vertex, and from there along its edges in the order of
    /// their other ends. Each step checks the vertex it comes to (alive, in
    /// the set, listing the vertex it came from); every directed edge is
    /// walked once.
    ///
    /// With `ordered` false the orbits come in no particular order (the
    /// edges of a member in the order of its list), which is all a check
    /// needs.
    pub(super) fn trace(
        &self,
        set: &[u32],
        ordered: bool,
        mut each: impl FnMut(bool, &[u32]),
    ) -> Result<(), String> {
        const NONE: u32 = u32::MAX;
        let slots = self.alive.len();
        // Each member's first directed edge in `seen_edge`; NONE for the
        // vertices outside the set.
        let mut offset = vec![NONE; slots];
        for &v in set {
            if !self.is_alive(v) {
                let what = if v == NULL {
                    "the null vertex".to_string()
                } else if v as usize >= slots {
                    format!("vertex {v}, which does not exist")
                } else {
                    format!("vertex {v}, which no longer exists")
                };
                return Err(format!("`check`: the set holds {what}"));
            }
            if offset[v as usize] != NONE {
                return Err(format!("`check`: the set holds vertex {v} twice"));
            }
            offset[v as usize] = 0;
        }
        let sorted;
        let members = if !ordered || set.is_sorted() {
            set
        } else {
            sorted = {
                let mut m = set.to_vec();
                m.sort_unstable();
                m
            };
            &sorted[..]
        };
        let mut total = 0usize;
        for &u in members {
            let list = &self.nbs[u as usize];
            if total + list.len() >= NONE as usize {
                return Err("`check`: the set has too many edges".into());
            }
            offset[u as usize] = total as u32;
            total += list.len();
            if let Some(x) = self.loop_or_repeat(u, list) {
                return Err(if x == u {
                    format!("vertex {u} lists itself as a neighbour")
                } else {
                    format!("vertex {u} lists vertex {x} twice")
                });
            }
        }
        let mut stamp = vec![0u32; slots];
        let mut seen_edge = vec![false; total];
        let mut orbit = Vec::new();
        let mut order: Vec<(u32, usize)> = Vec::new();
        let mut count = 0u32;
        for &u in members {
            let start = &self.nbs[u as usize];
            order.clear();
            order.extend(start.iter().enumerate().map(|(p, &v)| (v, p)));
            if ordered {
                order.sort_unstable();
            }
            for &(v, p) in &order {
                if seen_edge[offset[u as usize] as usize + p] {
                    continue;
                }
                count = count.wrapping_add(1).max(1);
                orbit.clear();
                let (mut a, mut pa) = (u, p);
                let (mut gap_at, mut face_at, mut twice) = (NULL, NULL, NULL);
                loop {
                    seen_edge[offset[a as usize] as usize + pa] = true;
                    if stamp[a as usize] == count && twice == NULL {
                        twice = a;
                    }
                    stamp[a as usize] = count;
                    orbit.push(a);
                    let b = self.nbs[a as usize][pa];
                    if offset.get(b as usize).is_none_or(|&o| o == NONE) {
                        return Err(if self.is_alive(b) {
                            format!("vertex {a} lists vertex {b}, which is not in the set")
                        } else {
                            format!("vertex {a} lists vertex {b}, which no longer exists")
                        });
                    }
                    let list = &self.nbs[b as usize];
                    let Some(q) = find(list, a) else {
                        return Err(format!(
                            "vertex {a} lists {b} as a neighbour but {b} does not list {a}"
                        ));
                    };
                    if q == 0 && self.open[b as usize] {
                        gap_at = if gap_at == NULL { b } else { gap_at };
                    } else {
                        face_at = if face_at == NULL { b } else { face_at };
                    }
                    let pw = if q == 0 { list.len() - 1 } else { q - 1 };
                    (a, pa) = (b, pw);
                    if (a, pa) == (u, p) {
                        break;
                    }
                    if seen_edge[offset[a as usize] as usize + pa] || orbit.len() > total {
                        return Err(format!(
                            "the orbit of edge ({u}, {v}) does not close: the neighbourhoods \
                             are not a rotation system"
                        ));
                    }
                }
                if gap_at != NULL && face_at != NULL {
                    return Err(format!(
                        "the faces and the boundary disagree on the loop through edge ({u}, \
                         {v}): vertex {gap_at}'s neighbourhood is open there but vertex \
                         {face_at}'s is not"
                    ));
                }
                let hole = gap_at != NULL;
                if orbit.len() < 3 {
                    return Err(if hole {
                        format!("edge ({u}, {v}) borders no face: both its sides are boundary")
                    } else {
                        format!(
                            "the face through edge ({u}, {v}) has only 2 vertices: a face \
                             needs at least 3"
                        )
                    });
                }
                if twice != NULL {
                    return Err(format!(
                        "the {} through edge ({u}, {v}) passes vertex {twice} twice",
                        if hole { "boundary" } else { "face" }
                    ));
                }
                each(hole, &orbit);
            }
        }
        Ok(())
    }

    /// `u` itself or a vertex that `list`, `u`'s neighbours, holds twice:
    /// pairwise for the short lists of most meshes, by sorting a copy for
    /// long ones.
    fn loop_or_repeat(&self, u: u32, list: &[u32]) -> Option<u32> {
        if list.len() <= 16 {
            return list
                .iter()
                .enumerate()
                .find(|&(k, &x)| x == u || list[..k].contains(&x))
                .map(|(_, &x)| x);
        }
        if list.contains(&u) {
            return Some(u);
        }
        let mut copy = list.to_vec();
        copy.sort_unstable();
        copy.windows(2).find(|w| w[0] == w[1]).map(|w| w[0])
    }
}
