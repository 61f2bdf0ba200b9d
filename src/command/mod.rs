//! The commands of the `subgram` binary, one function each, with their
//! arguments as plain structs. A command returns the text it prints on
//! standard output, if any; it writes its output files whole or not at all,
//! and never over one of its inputs.
//!
//! - `check.rs`: `check`.
//! - `derive.rs`: `derive`, `derive_to` and `DeriveArgs`: the word, streamed.
//! - `render.rs`: `render`, `render_edited` (for `serve`), `RenderArgs`,
//!   `Solidity`; an L-system drawn in 2D or 3D, or exported.
//! - `sight.rs`: `sight_edited`, what the live page shows: an SVG, or 3D
//!   geometry with its first camera.
//! - `animate.rs`: `render -o growth.gif`, `.apng`, or one still a frame
//!   (`{n}`): the frames encoded.
//! - `frames.rs`: `frames`, `FrameOptions`, `Frames`: a system run once,
//!   one picture per step with one camera (animations, the page's
//!   playback).
//! - `watch.rs`: `watch`, `WatchOptions`, `WatchEvent`.
//! - `infer.rs`: `infer` and `InferArgs`.
//! - `subdivide.rs`: `subdivide` and `SubdivideArgs`; a shape grammar's
//!   outputs.
//! - `mesh.rs`: `mesh_info`, `mesh_convert`, and `write_mesh`.
//! - `reverse.rs`: `reverse`, `reconstruct` and their arguments.
//! - `analyze.rs`: `analyze`, `analyze_reporting` and `AnalyzeArgs`.
//! - `picture.rs`: `Picture`, `write_picture`; how a mesh is drawn
//!   (`MeshLooks`), a curve's views, and where pictures go (`Out`).
//! - `common.rs`: what several commands share: `in_run`, load options, the
//!   steps' limit, JSON, `refuse_overwrite`, writing all or none, and the
//!   files a program wrote.
//!
//! `command` uses every layer below it: load and system, curve, surface,
//! shape and vv, render, draw, export, mesh, model, reverse, infer,
//! analyze, files and deadline; only `main` (the binary) and `serve` use it.
//! Its children are private; what is public is re-exported here.

mod analyze;
mod animate;
mod check;
mod common;
mod derive;
mod frames;
mod infer;
mod mesh;
mod picture;
mod render;
mod reverse;
mod sight;
mod subdivide;
mod watch;

pub use analyze::{analyze, analyze_reporting, AnalyzeArgs};
pub use check::check;
pub use derive::{derive, derive_to, DeriveArgs, Printed};
pub use frames::{
    frames, Frame, FrameGeometry, FrameOptions, FrameSelection, Frames, SolidFrame, MAX_FRAMES,
    MAX_FRAME_PIXELS,
};
pub use infer::{infer, InferArgs};
pub use mesh::{mesh_convert, mesh_info};
pub use picture::{write_picture, Picture};
pub use render::{render, render_edited, Drawn, RenderArgs, Solidity, DEFAULT_FPS};
pub use reverse::{reconstruct, reverse, ReconstructArgs, ReverseArgs};
pub use sight::{frames_edited, sight_edited, Seen, SeenFrames, Sight, Solid};
pub use subdivide::{subdivide, SubdivideArgs};
pub use watch::{watch, WatchEvent, WatchOptions};
