//! The integration tests: one binary, one module per area. The checks
//! against the shared lpfg corpus are a separate target, tests/shared.

mod abop;
mod bad_inputs;
mod cli;
mod curves;
mod errors;
mod front_limits;
mod fuzz_replay;
mod gillespie;
mod golden;
mod golden_tests;
mod lang_features;
mod limits;
mod lpfg_agreement;
mod lpfg_semantics;
mod lsystems;
mod mesh;
mod mesh_bounds;
mod mesh_draw;
mod mesh_io;
mod model;
mod one_language;
mod precision;
mod preprocessor;
mod random;
mod render;
mod reverse;
mod semantics;
mod shapes;
mod support;
mod surface;
mod surface_adaptive;
mod surface_c4;
mod surface_quad;
mod vv;
mod vv_adversarial;
