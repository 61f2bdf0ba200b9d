//! The box around the turtle's lines, found by the walk without drawing.

use glam::DVec3;

use super::{walk, DrawError, DrawOptions, Round, Sink, Turtle};
use crate::lang::value::StructDef;
use crate::lang::Alphabet;
use crate::rewrite::Word;

/// The box of the turtle's lines: their end points' least and greatest
/// coordinates.
struct LineBounds(DVec3, DVec3);

impl Sink for LineBounds {
    const LINE_READS_FRAME: bool = false;

    #[inline]
    fn line(&mut self, _t: &Turtle, a: DVec3, b: DVec3) -> Result<(), String> {
        // The walk draws finite lines only.
        (self.0, self.1) = grown(grown((self.0, self.1), a), b);
        Ok(())
    }

    fn round(&mut self, _t: &Turtle, _kind: Round, _r: f64) -> Result<(), String> {
        Ok(())
    }

    fn polygon(&mut self, _t: &Turtle, _points: Vec<DVec3>) -> Result<(), String> {
        Ok(())
    }

    fn surface(
        &mut self,
        _t: &Turtle,
        _s: &crate::model::Surface,
        _scale: DVec3,
    ) -> Result<(), String> {
        Ok(())
    }
}

/// The box around the turtle's lines in `word` (lines only: discs,
/// polygons and surfaces are left out), `None` when it draws no line: what
/// [`draw`]'s paths span, found by the same walk without keeping them.
///
/// [`draw`]: super::draw
pub fn line_bounds(
    word: &Word,
    alphabet: &Alphabet,
    structs: &[StructDef],
    opts: &DrawOptions,
) -> Result<Option<(DVec3, DVec3)>, DrawError> {
    let mut b = LineBounds(DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    walk(word, alphabet, structs, opts, None, &mut b)?;
    Ok((b.0.x <= b.1.x).then_some((b.0, b.1)))
}

/// The box `lo..hi` grown to take in the point `p`, by plain comparisons
/// (glam's `select`): `f64::min` and `max` give the same for finite
/// numbers, but compile to a sequence that also handles a NaN operand (a
/// quarter of a box walk's instructions). A NaN coordinate leaves the box
/// as it is, as with them.
#[inline(always)]
fn grown((lo, hi): (DVec3, DVec3), p: DVec3) -> (DVec3, DVec3) {
    (
        DVec3::select(p.cmplt(lo), p, lo),
        DVec3::select(p.cmpgt(hi), p, hi),
    )
}
