//! Shape grammars (paper 003): the shape tree over the geometry kernel.
pub(crate) mod geom;
pub(crate) mod smooth;
