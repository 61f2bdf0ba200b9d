//! Properties and positions: declaring vertex, edge and mesh properties,
//! and reading and setting them and `v$pos`.

use glam::DVec3;

use super::{find, Column, Field, Rotation, EPROP, POS, VPROP};

impl Rotation {
    // ----- declarations ------------------------------------------------

    /// Declares a vertex property of `width` values; every vertex, those
    /// alive now included, starts with `default`. Returns its index.
    ///
    /// # Panics
    /// If `default` does not hold `width` values (a caller's mistake).
    pub fn add_vertex_property(&mut self, width: usize, default: &[f64]) -> usize {
        assert_eq!(default.len(), width, "a property's default has its width");
        let slots = self.slots();
        let mut cur = Vec::with_capacity(slots * width);
        for _ in 0..slots {
            cur.extend_from_slice(default);
        }
        self.vprops.push(Column {
            width,
            default: default.to_vec(),
            old: cur.clone(),
            cur,
        });
        self.vprops.len() - 1
    }

    /// Declares a property of directed edges, `width` values each; every
    /// edge, those there now included, starts with `default`. Returns its
    /// index.
    ///
    /// # Panics
    /// If `default` does not hold `width` values (a caller's mistake).
    pub fn add_edge_property(&mut self, width: usize, default: &[f64]) -> usize {
        assert_eq!(default.len(), width, "a property's default has its width");
        let before = self.edge_default.len();
        let after = before + width;
        // Widen every edge's values: the new field goes at the end of each.
        for (lists, values) in [
            (&self.nbs, &mut self.edges),
            (&self.old_nbs, &mut self.old_edges),
        ] {
            for (list, vals) in lists.iter().zip(values.iter_mut()) {
                let mut wide = Vec::with_capacity(list.len() * after);
                for k in 0..list.len() {
                    wide.extend_from_slice(&vals[k * before..(k + 1) * before]);
                    wide.extend_from_slice(default);
                }
                *vals = wide;
            }
        }
        self.efields.push(Field {
            offset: before,
            width,
        });
        self.edge_default.extend_from_slice(default);
        self.efields.len() - 1
    }

    /// Declares a mesh property of `width` values, set to `default`.
    /// Returns its index.
    ///
    /// # Panics
    /// If `default` does not hold `width` values (a caller's mistake).
    pub fn add_mesh_property(&mut self, width: usize, default: &[f64]) -> usize {
        assert_eq!(default.len(), width, "a property's default has its width");
        self.mfields.push(Field {
            offset: self.mdata.len(),
            width,
        });
        self.mdata.extend_from_slice(default);
        self.mfields.len() - 1
    }

    // ----- positions and properties ------------------------------------

    /// `v$pos` (or `'v$pos` with `old`).
    #[inline]
    pub fn pos(&self, v: u32, old: bool) -> Result<DVec3, String> {
        let i = self.slot(v, old, POS)?;
        Ok(if old { self.old_pos[i] } else { self.pos[i] })
    }

    /// Sets `v$pos`.
    #[inline]
    pub fn set_pos(&mut self, v: u32, p: DVec3) -> Result<(), String> {
        let i = self.slot(v, false, POS)?;
        self.pos[i] = p;
        Ok(())
    }

    /// The values of vertex property `idx` of `v`.
    pub fn vertex_property(&self, v: u32, idx: usize, old: bool) -> Result<&[f64], String> {
        let i = self.slot(v, old, VPROP)?;
        let c = self
            .vprops
            .get(idx)
            .ok_or_else(|| format!("there is no vertex property {idx}"))?;
        let data = if old { &c.old } else { &c.cur };
        Ok(&data[i * c.width..(i + 1) * c.width])
    }

    /// Sets vertex property `idx` of `v`.
    pub fn set_vertex_property(&mut self, v: u32, idx: usize, vals: &[f64]) -> Result<(), String> {
        let i = self.slot(v, false, VPROP)?;
        let c = self
            .vprops
            .get_mut(idx)
            .ok_or_else(|| format!("there is no vertex property {idx}"))?;
        if vals.len() != c.width {
            return Err(width_error("vertex", idx, c.width, vals.len()));
        }
        c.cur[i * c.width..(i + 1) * c.width].copy_from_slice(vals);
        Ok(())
    }

    /// The values of edge property `idx` of the directed edge `(v, x)`;
    /// `None` if `x` is not a neighbour of `v`.
    pub fn edge_property(
        &self,
        v: u32,
        x: u32,
        idx: usize,
        old: bool,
    ) -> Result<Option<&[f64]>, String> {
        let i = self.slot(v, old, EPROP)?;
        let f = self.edge_field(idx)?;
        let (list, vals) = if old {
            (&self.old_nbs[i], &self.old_edges[i])
        } else {
            (&self.nbs[i], &self.edges[i])
        };
        let w = self.edge_default.len();
        Ok(find(list, x).map(|k| &vals[k * w + f.offset..k * w + f.offset + f.width]))
    }

    /// Sets edge property `idx` of the directed edge `(v, x)`; refused if
    /// `x` is not a neighbour of `v`.
    pub fn set_edge_property(
        &mut self,
        v: u32,
        x: u32,
        idx: usize,
        vals: &[f64],
    ) -> Result<(), String> {
        let i = self.slot(v, false, EPROP)?;
        let f = self.edge_field(idx)?;
        if vals.len() != f.width {
            return Err(width_error("edge", idx, f.width, vals.len()));
        }
        let Some(k) = find(&self.nbs[i], x) else {
            return Err(format!(
                "`{}`: vertex {x} is not a neighbour of vertex {v}, so there is no edge \
                 ({v}, {x})",
                EPROP.name
            ));
        };
        let at = k * self.edge_default.len() + f.offset;
        self.edges[i][at..at + f.width].copy_from_slice(vals);
        Ok(())
    }

    fn edge_field(&self, idx: usize) -> Result<Field, String> {
        self.efields
            .get(idx)
            .copied()
            .ok_or_else(|| format!("there is no edge property {idx}"))
    }

    /// The values of mesh property `idx`.
    pub fn mesh_property(&self, idx: usize) -> Result<&[f64], String> {
        let f = self.mesh_field(idx)?;
        Ok(&self.mdata[f.offset..f.offset + f.width])
    }

    /// Sets mesh property `idx`.
    pub fn set_mesh_property(&mut self, idx: usize, vals: &[f64]) -> Result<(), String> {
        let f = self.mesh_field(idx)?;
        if vals.len() != f.width {
            return Err(width_error("mesh", idx, f.width, vals.len()));
        }
        self.mdata[f.offset..f.offset + f.width].copy_from_slice(vals);
        Ok(())
    }

    fn mesh_field(&self, idx: usize) -> Result<Field, String> {
        self.mfields
            .get(idx)
            .copied()
            .ok_or_else(|| format!("there is no mesh property {idx}"))
    }
}

#[cold]
fn width_error(kind: &str, idx: usize, width: usize, got: usize) -> String {
    format!("{kind} property {idx} holds {width} values, not {got}")
}
