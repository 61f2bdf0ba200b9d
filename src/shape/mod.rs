pub(crate) mod smooth;
