//! Editing a neighbourhood: `make`, `erase`, `replace` and `splice`, with
//! the refusals of notes 3–5.

use super::{find, Op, Rotation, AFTER, BEFORE, ERASE, FIRST_CAPACITY, MAKE, NULL, REPLACE};

impl Rotation {
    // ----- editing -----------------------------------------------------

    /// `make {…} nb_of v`: sets `v`'s neighbourhood to `list`, its edge
    /// properties to their defaults.
    ///
    /// [`NULL`] entries mark the gap of a boundary vertex: they must form
    /// one run, read cyclically; they are dropped, the neighbourhood is
    /// open and begins after the gap (`{p, NULL, q, r}` gives the open
    /// `[q, r, p]`). A list of nothing but null vertices leaves `v` with no
    /// neighbours. Refused (note 3) if `v` is in the list or a vertex is
    /// listed twice.
    pub fn make(&mut self, v: u32, list: &[u32]) -> Result<(), String> {
        self.edits += 1;
        let i = self.slot(v, false, MAKE)?;
        let n = list.len();
        let (mut runs, mut start, mut count) = (0, 0, 0);
        for (k, &x) in list.iter().enumerate() {
            if x == NULL {
                continue;
            }
            if x == v {
                return Err(format!(
                    "`{}`: v (vertex {v}) is listed in its own neighbourhood",
                    MAKE.name
                ));
            }
            if !self.is_alive(x) {
                return Err(self.listed_error(x));
            }
            count += 1;
            if list[(k + n - 1) % n] == NULL {
                runs += 1;
                start = k;
            }
        }
        if runs > 1 {
            return Err(format!(
                "`{}`: the list has more than one gap (its null vertices form {runs} runs); \
                 an open neighbourhood has one",
                MAKE.name
            ));
        }
        if let Some(x) = self.repeated(list) {
            return Err(format!("`{}`: vertex {x} is listed twice", MAKE.name));
        }
        let nb = &mut self.nbs[i];
        nb.clear();
        if nb.capacity() < count {
            nb.reserve_exact(count.max(FIRST_CAPACITY));
        }
        if count == n {
            nb.extend_from_slice(list);
        } else {
            nb.extend(
                list[start..]
                    .iter()
                    .chain(&list[..start])
                    .copied()
                    .filter(|&x| x != NULL),
            );
        }
        self.open[i] = count > 0 && count < n;
        let vals = &mut self.edges[i];
        vals.clear();
        for _ in 0..count {
            vals.extend_from_slice(&self.edge_default);
        }
        Ok(())
    }

    #[cold]
    fn listed_error(&self, x: u32) -> String {
        if x as usize >= self.alive.len() {
            format!(
                "`{}`: the list holds vertex {x}, which does not exist",
                MAKE.name
            )
        } else {
            format!(
                "`{}`: the list holds vertex {x}, which no longer exists",
                MAKE.name
            )
        }
    }

    /// A vertex other than [`NULL`] that `list` holds twice: the first
    /// repeat in list order for short lists, the smallest repeated id
    /// (found by sorting a copy) for long ones.
    fn repeated(&mut self, list: &[u32]) -> Option<u32> {
        if list.len() <= 32 {
            return list
                .iter()
                .enumerate()
                .find(|&(k, &x)| x != NULL && list[..k].contains(&x))
                .map(|(_, &x)| x);
        }
        self.scratch.clear();
        self.scratch
            .extend(list.iter().copied().filter(|&x| x != NULL));
        self.scratch.sort_unstable();
        self.scratch.windows(2).find(|w| w[0] == w[1]).map(|w| w[0])
    }

    /// `erase x from v`: removes `x` and the edge's properties from `v`'s
    /// neighbourhood; no effect if `x` is not there (note 4). A
    /// neighbourhood left empty is closed.
    #[inline]
    pub fn erase(&mut self, x: u32, v: u32) -> Result<(), String> {
        self.edits += 1;
        let i = self.slot(v, false, ERASE)?;
        if let Some(k) = find(&self.nbs[i], x) {
            self.nbs[i].remove(k);
            let w = self.edge_default.len();
            if w > 0 {
                self.edges[i].drain(k * w..(k + 1) * w);
            }
            if self.nbs[i].is_empty() {
                self.open[i] = false;
            }
        }
        Ok(())
    }

    /// `replace a with x in v`: `x` takes `a`'s place, with the edge
    /// properties' defaults; no effect if `a` is not a neighbour, refused
    /// if `x` is `v` or already a neighbour (note 5), or is the null or a
    /// dead vertex.
    #[inline]
    pub fn replace(&mut self, a: u32, x: u32, v: u32) -> Result<(), String> {
        self.edits += 1;
        let i = self.slot(v, false, REPLACE)?;
        self.storable(x, v, REPLACE)?;
        let Some(k) = find(&self.nbs[i], a) else {
            return Ok(());
        };
        if find(&self.nbs[i], x).is_some() {
            return Err(already(REPLACE, x, v));
        }
        self.nbs[i][k] = x;
        let w = self.edge_default.len();
        if w > 0 {
            self.edges[i][k * w..(k + 1) * w].copy_from_slice(&self.edge_default);
        }
        Ok(())
    }

    /// `splice x after a in v`: inserts `x` right after `a`,
    /// counter-clockwise, with the edge properties' defaults; after the
    /// last of an open neighbourhood, `x` becomes the last (the gap stays
    /// after it). No effect if `a` is not a neighbour, refused if `x` is
    /// `v` or already a neighbour (note 5), or is the null or a dead
    /// vertex.
    #[inline]
    pub fn splice_after(&mut self, x: u32, a: u32, v: u32) -> Result<(), String> {
        self.splice(x, a, v, 1, AFTER)
    }

    /// `splice x before a in v`: inserts `x` right before `a`; before the
    /// first of an open neighbourhood, `x` becomes the first. Otherwise as
    /// [`Rotation::splice_after`].
    #[inline]
    pub fn splice_before(&mut self, x: u32, a: u32, v: u32) -> Result<(), String> {
        self.splice(x, a, v, 0, BEFORE)
    }

    #[inline]
    fn splice(&mut self, x: u32, a: u32, v: u32, shift: usize, op: Op) -> Result<(), String> {
        self.edits += 1;
        let i = self.slot(v, false, op)?;
        self.storable(x, v, op)?;
        let Some(k) = find(&self.nbs[i], a) else {
            return Ok(());
        };
        if find(&self.nbs[i], x).is_some() {
            return Err(already(op, x, v));
        }
        let at = k + shift;
        if self.nbs[i].capacity() == 0 {
            self.nbs[i].reserve_exact(FIRST_CAPACITY);
        }
        self.nbs[i].insert(at, x);
        let w = self.edge_default.len();
        if w > 0 {
            let vals = &mut self.edges[i];
            let end = vals.len();
            vals.extend_from_slice(&self.edge_default);
            vals.copy_within(at * w..end, (at + 1) * w);
            vals[at * w..(at + 1) * w].copy_from_slice(&self.edge_default);
        }
        Ok(())
    }
}

#[cold]
fn already(op: Op, x: u32, v: u32) -> String {
    format!(
        "`{}`: vertex {x} is already a neighbour of vertex {v}",
        op.name
    )
}
