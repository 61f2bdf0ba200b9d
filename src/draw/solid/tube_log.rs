//! The tubes of a walk for a picture whose scale the walk finds
//! (`SolidOptions::fit_pixels`): logged as the turtle goes, each thinner
//! than a pixel at the scale so far made as its line on the spot, and the
//! others made once the scale is known.

use glam::DVec3;

use super::tubes::Pending;
use super::{fits, pixel_of, too_short, Builder, THIN};
use crate::scene3::Line;

/// A tube segment as [`Builder::tube`] reads it from the turtle and the
/// branch.
#[derive(Clone, Copy, Debug)]
pub(super) struct Seg {
    pub(super) a: DVec3,
    pub(super) b: DVec3,
    pub(super) left: DVec3,
    pub(super) up: DVec3,
    pub(super) color: i64,
    pub(super) scale: (f64, f64),
    pub(super) sides: Option<u32>,
    /// The lines its mesh had when it was logged: where its line goes if
    /// it turns out thin at the final scale.
    pub(super) lines: usize,
}

/// What a walk for a picture of unknown scale logs of its tubes, in order
/// ([`SolidOptions::fit_pixels`]): each tube, and each branch and each end
/// of a branch's tube, since they decide which tubes join.
///
/// [`SolidOptions::fit_pixels`]: super::SolidOptions::fit_pixels
pub(super) struct Log {
    fit: f64,
    /// The box around the lines so far.
    pub(super) lo: DVec3,
    pub(super) hi: DVec3,
    /// The largest scale a tube was found thin at: the final scale must
    /// be at least this (it is, as the box only grows).
    px_used: f64,
    pub(super) ops: Vec<Op>,
    segs: Vec<Seg>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Op {
    Tube,
    Push,
    Pop,
    End,
}

impl Log {
    pub(super) fn new(fit: f64) -> Log {
        Log {
            fit,
            lo: DVec3::splat(f64::INFINITY),
            hi: DVec3::splat(f64::NEG_INFINITY),
            px_used: 0.0,
            ops: Vec::new(),
            segs: Vec::new(),
        }
    }

    /// The scale so far: at most the final one, 0 while the lines span
    /// nothing.
    fn pixel_so_far(&self) -> f64 {
        let extent = (self.hi - self.lo).max_element();
        if extent.is_finite() && extent > 0.0 {
            extent / self.fit
        } else {
            0.0
        }
    }
}

impl<'m> Builder<'m> {
    /// Makes the logged tubes at the scale of the whole walk's lines, on
    /// a branch state of their own (the walk's holds no tube), as the
    /// walk would have made them knowing the scale.
    pub(super) fn replay(&mut self) -> Result<(), String> {
        let Some(log) = self.log.take() else {
            return Ok(());
        };
        let px = pixel_of((log.hi - log.lo).max_element(), log.fit);
        if px < log.px_used {
            return Err("the scale shrank".into());
        }
        self.picture_pixel = Some(px);
        self.stack.clear();
        self.cur.tube = None;
        self.cur.gc = None;
        // Thin tubes went into the meshes as lines on the walk; the ops
        // only say where the logged tubes join.
        if log.segs.is_empty() {
            return self.finish();
        }
        // Of a branch's state, making the tubes reads only its pending
        // tube: the branches keep that alone, where the walk kept all
        // (`push`, `pop`, `finish`, a tube at a time).
        let mut segs = log.segs.iter();
        let mut waiting: Vec<Pending> = Vec::new();
        let mut had: Vec<bool> = Vec::new();
        for op in &log.ops {
            match op {
                Op::Tube => {
                    let seg = segs.next().ok_or("a short log")?;
                    self.replaying = Some(seg.lines);
                    let made = self.tube_at(seg);
                    self.replaying = None;
                    made?
                }
                Op::Push => had.push(match self.cur.tube.take() {
                    Some(p) => {
                        waiting.push(p);
                        true
                    }
                    None => false,
                }),
                Op::Pop => {
                    self.end_tube()?;
                    if had.pop() == Some(true) {
                        self.cur.tube = waiting.pop();
                    }
                }
                Op::End => self.end_tube()?,
            }
        }
        self.end_tube()?;
        while let Some(h) = had.pop() {
            if h {
                self.cur.tube = waiting.pop();
                self.end_tube()?;
            }
        }
        self.place_late_lines();
        Ok(())
    }

    /// Puts the lines of logged tubes found thin at the final scale among
    /// the lines the walk made, each where a walk knowing the scale would
    /// have made it.
    fn place_late_lines(&mut self) {
        let late = std::mem::take(&mut self.late);
        for (k, mesh) in self.scene.meshes.iter_mut().enumerate() {
            let mine: Vec<(usize, Line)> = (late.iter())
                .filter(|(m, _, _)| *m as usize == k)
                .map(|&(_, at, line)| (at, line))
                .collect();
            let Some(&(_, filler)) = mine.first() else {
                continue;
            };
            // In place, from the back: the walk's lines from each place on
            // move up by the late lines at or before it.
            let lines = &mut mesh.lines;
            let mut end = lines.len();
            lines.resize(end + mine.len(), filler);
            for (j, &(at, line)) in mine.iter().enumerate().rev() {
                // Places only grow along the log; clamped all the same.
                let at = at.min(end);
                lines.copy_within(at..end, at + j + 1);
                lines[at + j] = line;
                end = at;
            }
        }
    }

    /// Logs a tube segment: as a line when it is thinner than a pixel at
    /// the scale so far (the final scale is at least that), else whole.
    #[inline]
    pub(super) fn log_tube(&mut self, seg: Seg) -> Result<(), String> {
        let (a, b) = (seg.a, seg.b);
        if self.log.is_none() || too_short(a, b) {
            return Ok(());
        }
        // The tube's mesh is made now, where a walk that made the tube
        // would make it, so that the meshes come in the same order.
        let mesh = self.mesh(seg.color);
        let Some(log) = &mut self.log else {
            return Ok(());
        };
        let width = seg.scale.0.abs().max(seg.scale.1.abs());
        let px = log.pixel_so_far();
        if px > 0.0 && width / px < THIN && fits(a, 0.0) && fits(b, 0.0) {
            log.px_used = log.px_used.max(px);
            // A line at any scale from here on: made now, in the order a
            // walk knowing the scale makes the lines, and the tube it
            // follows ends here (logged).
            log.ops.push(Op::End);
            let line = Line {
                a: a.as_vec3(),
                b: b.as_vec3(),
                width: width as f32,
            };
            // A line counts as a triangle against the limit.
            self.room(mesh, 0, 1)?.lines.push(line);
        } else {
            log.ops.push(Op::Tube);
            let lines = self.scene.meshes[mesh as usize].lines.len();
            log.segs.push(Seg { lines, ..seg });
        }
        Ok(())
    }
}
