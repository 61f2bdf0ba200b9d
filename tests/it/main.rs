//! The integration tests: one binary, one module per area.

mod cli;
mod corpus;
mod curves;
mod errors;
mod mesh;
mod mesh_draw;
mod mesh_io;
mod render;
mod reverse;
mod semantics;
mod support;
mod surface;
mod surface_quad;
