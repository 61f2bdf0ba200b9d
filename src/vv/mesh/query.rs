//! The queries and selections of Table 2: `valence`, `is x in v`, `v*`,
//! whether a neighbourhood is open, `any`, `nextto` and `prevto`.

use super::{find, Rotation, ANY, BOUNDARY, IS_IN, NEIGHBOURS, NEXTTO, NULL, PREVTO, VALENCE};

impl Rotation {
    // ----- queries -----------------------------------------------------

    /// `valence v`: the number of `v`'s neighbours.
    #[inline]
    pub fn valence(&self, v: u32, old: bool) -> Result<usize, String> {
        let i = self.slot(v, old, VALENCE)?;
        Ok(self.state(i, old).0.len())
    }

    /// `is x in v`: whether `x` is a neighbour of `v` (false for [`NULL`]).
    #[inline]
    pub fn is_in(&self, x: u32, v: u32, old: bool) -> Result<bool, String> {
        let i = self.slot(v, old, IS_IN)?;
        Ok(find(self.state(i, old).0, x).is_some())
    }

    /// `v*`: `v`'s neighbours counter-clockwise; an open neighbourhood from
    /// its first to its last.
    #[inline]
    pub fn neighbours(&self, v: u32, old: bool) -> Result<&[u32], String> {
        let i = self.slot(v, old, NEIGHBOURS)?;
        Ok(self.state(i, old).0)
    }

    /// Whether `v`'s neighbourhood is open (`v` lies on the boundary).
    #[inline]
    pub fn is_open(&self, v: u32, old: bool) -> Result<bool, String> {
        let i = self.slot(v, old, BOUNDARY)?;
        Ok(self.state(i, old).1)
    }

    // ----- selection ---------------------------------------------------

    /// `any in v`: a neighbour of `v` (the first of an open
    /// neighbourhood); [`NULL`] if `v` has none (note 1).
    #[inline]
    pub fn any(&self, v: u32, old: bool) -> Result<u32, String> {
        let i = self.slot(v, old, ANY)?;
        Ok(self.state(i, old).0.first().copied().unwrap_or(NULL))
    }

    /// `nextto x in v`: the neighbour that follows `x` counter-clockwise;
    /// [`NULL`] if `x` is not a neighbour (note 2) or is the last of an
    /// open neighbourhood (the gap follows it).
    #[inline]
    pub fn nextto(&self, x: u32, v: u32, old: bool) -> Result<u32, String> {
        let i = self.slot(v, old, NEXTTO)?;
        let (list, open) = self.state(i, old);
        Ok(match find(list, x) {
            None => NULL,
            Some(k) if k + 1 < list.len() => list[k + 1],
            Some(_) if open => NULL,
            Some(_) => list[0],
        })
    }

    /// `prevto x in v`: the neighbour that precedes `x` counter-clockwise;
    /// [`NULL`] if `x` is not a neighbour (note 2) or is the first of an
    /// open neighbourhood (the gap precedes it).
    #[inline]
    pub fn prevto(&self, x: u32, v: u32, old: bool) -> Result<u32, String> {
        let i = self.slot(v, old, PREVTO)?;
        let (list, open) = self.state(i, old);
        Ok(match find(list, x) {
            None => NULL,
            Some(k) if k > 0 => list[k - 1],
            Some(_) if open => NULL,
            Some(_) => list[list.len() - 1],
        })
    }
}
