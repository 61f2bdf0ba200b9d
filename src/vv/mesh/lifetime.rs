//! The lifetime of vertices: making room for them, making and freeing
//! them, and `synchronize`, which copies their state to the old one.

use glam::DVec3;

use super::{Rotation, FREE, SYNC};

impl Rotation {
    /// Makes room for `additional` more vertices, so that creating them
    /// moves no arrays (free slots count).
    pub fn reserve(&mut self, additional: usize) {
        let extra = additional.saturating_sub(self.free.len());
        self.alive.reserve(extra);
        self.gen.reserve(extra);
        self.nbs.reserve(extra);
        self.open.reserve(extra);
        self.pos.reserve(extra);
        self.edges.reserve(extra);
        self.synced.reserve(extra);
        self.old_nbs.reserve(extra);
        self.old_open.reserve(extra);
        self.old_pos.reserve(extra);
        self.old_edges.reserve(extra);
        for c in &mut self.vprops {
            c.cur.reserve(extra * c.width);
            c.old.reserve(extra * c.width);
        }
    }

    /// `vertex v`: a new vertex with no neighbours, at the origin, its
    /// properties at their defaults and no old state. Reuses a freed slot
    /// (and its lists' capacity) when there is one.
    pub fn new_vertex(&mut self) -> u32 {
        self.edits += 1;
        self.live += 1;
        if let Some(v) = self.free.pop() {
            let i = v as usize;
            self.alive[i] = true;
            self.open[i] = false;
            self.pos[i] = DVec3::ZERO;
            self.synced[i] = false;
            for c in &mut self.vprops {
                c.cur[i * c.width..(i + 1) * c.width].copy_from_slice(&c.default);
            }
            return v;
        }
        let v = self.alive.len() as u32;
        self.alive.push(true);
        self.gen.push(0);
        self.nbs.push(Vec::new());
        self.open.push(false);
        self.pos.push(DVec3::ZERO);
        self.edges.push(Vec::new());
        self.synced.push(false);
        self.old_nbs.push(Vec::new());
        self.old_open.push(false);
        self.old_pos.push(DVec3::ZERO);
        self.old_edges.push(Vec::new());
        for c in &mut self.vprops {
            c.cur.extend_from_slice(&c.default);
            c.old.extend_from_slice(&c.default);
        }
        v
    }

    // ----- coordination and lifetime -------------------------------------

    /// `synchronize S`: copies the current state of every vertex of `set`
    /// (neighbours, openness, position, vertex and edge properties) to its
    /// old state, which the `old` readings return until the next
    /// synchronize that includes it. Refused, with nothing copied, if a
    /// member is the null or a dead vertex.
    pub fn synchronize(&mut self, set: &[u32]) -> Result<(), String> {
        for &v in set {
            self.slot(v, false, SYNC)?;
        }
        for &v in set {
            let i = v as usize;
            self.old_nbs[i].clear();
            self.old_nbs[i].extend_from_slice(&self.nbs[i]);
            self.old_open[i] = self.open[i];
            self.old_pos[i] = self.pos[i];
            self.old_edges[i].clear();
            self.old_edges[i].extend_from_slice(&self.edges[i]);
            for c in &mut self.vprops {
                let r = i * c.width..(i + 1) * c.width;
                c.old[r.clone()].copy_from_slice(&c.cur[r]);
            }
            self.synced[i] = true;
        }
        Ok(())
    }

    /// Frees `v`: its slot goes to the free list, its generation moves on,
    /// so handles to it are stale. Its neighbours' lists are not touched.
    pub fn free(&mut self, v: u32) -> Result<(), String> {
        self.edits += 1;
        let i = self.slot(v, false, FREE)?;
        self.alive[i] = false;
        self.gen[i] = self.gen[i].wrapping_add(1);
        self.nbs[i].clear();
        self.open[i] = false;
        self.edges[i].clear();
        self.synced[i] = false;
        self.old_nbs[i].clear();
        self.old_edges[i].clear();
        self.free.push(v);
        self.live -= 1;
        Ok(())
    }

    /// Frees every vertex alive that `live` does not hold, in id order
    /// (entries that are not alive are ignored).
    pub fn retain(&mut self, live: &[u32]) {
        self.marks.clear();
        self.marks.resize(self.alive.len(), false);
        for &v in live {
            if let Some(m) = self.marks.get_mut(v as usize) {
                *m = true;
            }
        }
        for i in 0..self.alive.len() {
            if self.alive[i] && !self.marks[i] {
                // Alive, so free cannot refuse.
                let _ = self.free(i as u32);
            }
        }
    }
}
