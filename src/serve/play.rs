//! Growth playback for the page: a program's frames (one per step, or per
//! frame of its `.a` file, all with one camera: [`command::frames_edited`],
//! what `render -o growth.gif` draws) derived once on a thread of their
//! own, under the page's limits, while the page asks how far it has come.
//!
//! `POST /api/play` starts a job and answers its number at once; `GET
//! /api/play/ID` answers its state: the step derived so far (the page shows
//! it as progress), and once it is done, every frame's kept file (an SVG,
//! or a GLB with its camera) for the page to fetch and keep, so that
//! scrubbing back needs no request. At most [`MAX_RUNNING`] jobs run at
//! once; the server remembers the last [`MAX_JOBS`].

use std::collections::VecDeque;
use std::path::Path;
use std::sync::{Arc, Mutex};
use std::time::Instant;

use serde::{Deserialize, Serialize};

use super::{lock, scene_reply, App, Blobs, Message, SceneReply, ServeOptions};
use crate::command::{self, FrameGeometry, RenderArgs, Solid};
use crate::render::raster::Shading;

/// The most playback jobs deriving at once (each holds a thread and its
/// frames).
pub const MAX_RUNNING: usize = 2;

/// The jobs whose state the server keeps.
const MAX_JOBS: usize = 8;

#[derive(Deserialize)]
pub(super) struct PlayRequest {
    text: String,
    #[serde(default)]
    steps: Option<u64>,
    #[serde(default)]
    defines: Vec<String>,
}

/// One frame as the page fetches it.
#[derive(Serialize, Clone, Debug)]
struct FrameReply {
    step: u64,
    /// `/api/blob/ID`.
    blob: u64,
    /// "svg" or "glb".
    kind: &'static str,
    /// A GLB's camera and counts.
    #[serde(skip_serializing_if = "Option::is_none")]
    scene: Option<SceneReply>,
}

/// A job's state, as `/api/play/ID` answers it.
#[derive(Serialize, Clone, Debug, Default)]
struct JobState {
    id: u64,
    /// "deriving", "drawing", "done" or "failed".
    phase: &'static str,
    /// The last step derived, and the derivation's length.
    step: usize,
    steps: usize,
    modules: usize,
    frames: Vec<FrameReply>,
    /// The time between frames the model's `.a` file asks for.
    #[serde(skip_serializing_if = "Option::is_none")]
    interval_ms: Option<u64>,
    messages: Vec<Message>,
    #[serde(skip_serializing_if = "Option::is_none")]
    limit: Option<&'static str>,
    seconds: f64,
}

/// The jobs the server remembers.
#[derive(Default)]
pub(super) struct Jobs {
    next: u64,
    running: usize,
    jobs: VecDeque<Arc<Mutex<JobState>>>,
}

/// What a job's thread needs of the server.
struct Player {
    opts: ServeOptions,
    program: std::path::PathBuf,
    blobs: Arc<Mutex<Blobs>>,
}

impl App {
    /// `POST /api/play`: a job started, or 503 when [`MAX_RUNNING`] are.
    pub(super) fn play(&self, body: &[u8]) -> super::Reply {
        let req: PlayRequest = match serde_json::from_slice(body) {
            Ok(r) => r,
            Err(e) => {
                return super::failure(400, &format!("the request is not a play request: {e}"))
            }
        };
        let limits = &self.opts.limits;
        if let Some(n) = req.steps.filter(|&n| n > limits.max_steps) {
            return super::failure(
                400,
                &format!(
                    "{n} steps are more than the {} a page may ask",
                    limits.max_steps
                ),
            );
        }
        let job = {
            let mut jobs = lock(&self.jobs);
            if jobs.running >= MAX_RUNNING {
                return super::failure(
                    503,
                    "the server is deriving other growths; try again when one has finished",
                );
            }
            jobs.running += 1;
            jobs.next += 1;
            let job = Arc::new(Mutex::new(JobState {
                id: jobs.next,
                phase: "deriving",
                ..JobState::default()
            }));
            jobs.jobs.push_back(Arc::clone(&job));
            while jobs.jobs.len() > MAX_JOBS {
                jobs.jobs.pop_front();
            }
            job
        };
        let id = lock(&job).id;
        let player = Player {
            opts: self.opts.clone(),
            program: self.program.clone(),
            blobs: Arc::clone(&self.blobs),
        };
        let jobs = Arc::clone(&self.jobs);
        let spawned = std::thread::Builder::new()
            .name("subgram play".into())
            .stack_size(256 << 20)
            .spawn(move || {
                player.run_job(&job, &req);
                lock(&jobs).running -= 1;
            });
        if spawned.is_err() {
            lock(&self.jobs).running -= 1;
            return super::failure(503, "the server cannot start another thread now");
        }
        super::json_reply(200, &serde_json::json!({ "ok": true, "job": id }))
    }

    /// `GET /api/play/ID`.
    pub(super) fn job(&self, id: u64) -> super::Reply {
        let jobs = lock(&self.jobs);
        let found = jobs.jobs.iter().find(|j| lock(j).id == id);
        match found {
            Some(j) => {
                let state = lock(j).clone();
                super::json_reply(200, &state)
            }
            None => super::failure(404, "no such playback: the server remembers the last 8"),
        }
    }
}

impl Player {
    fn keep(&self, content: &'static str, bytes: Vec<u8>) -> u64 {
        lock(&self.blobs).keep(content, bytes, self.opts.limits.max_kept_bytes)
    }

    /// Derives the frames and keeps each as a file for the page.
    fn run_job(&self, job: &Mutex<JobState>, req: &PlayRequest) {
        let t = Instant::now();
        let l = &self.opts.limits;
        let mut a = RenderArgs::new(self.opts.path.to_string_lossy(), "page.svg");
        a.steps = req.steps;
        a.defines = self
            .opts
            .defines
            .iter()
            .chain(&req.defines)
            .cloned()
            .collect();
        a.double = self.opts.double;
        a.max_modules = l.max_modules;
        a.timeout = Some(l.play_timeout);
        let set = |f: &mut dyn FnMut(&mut JobState)| f(&mut lock(job));
        let result = command::frames_edited(&a, &req.text, |p| {
            set(&mut |s| {
                s.step = p.step;
                s.steps = p.steps;
                s.modules = p.modules;
            })
        })
        .and_then(|seen| {
            set(&mut |s| s.phase = "drawing");
            let frames = self.keep_frames(&seen)?;
            Ok((seen, frames))
        });
        let program = Path::new(&self.program);
        set(&mut |s| {
            s.seconds = t.elapsed().as_secs_f64();
            match &result {
                Ok((seen, frames)) => {
                    s.phase = "done";
                    s.frames = frames.clone();
                    s.interval_ms = seen.frames.interval.map(|d| d.as_millis() as u64);
                    s.messages = seen
                        .warnings
                        .iter()
                        .map(|w| super::warning(w, program))
                        .collect();
                }
                Err(e) => {
                    s.phase = "failed";
                    s.messages = super::messages(e, program);
                    s.limit = super::which_limit(e);
                }
            }
        });
    }

    /// Each frame as a file the page fetches: an SVG, or a GLB with its
    /// camera. Refused, keeping nothing, when one frame's geometry is
    /// larger than the page takes or all of them more than half of what
    /// the server keeps.
    fn keep_frames(&self, seen: &command::SeenFrames) -> Result<Vec<FrameReply>, crate::Error> {
        let l = &self.opts.limits;
        let mut files = Vec::with_capacity(seen.frames.frames.len());
        let mut total = 0usize;
        for f in &seen.frames.frames {
            crate::deadline::check(crate::deadline::current()).map_err(crate::Error::Failed)?;
            let (kind, bytes, solid) = match &f.geometry {
                FrameGeometry::Flat(_) => ("svg", f.picture(command::Picture::Svg)?, None),
                FrameGeometry::Solid(s) => {
                    let edges = s
                        .raster
                        .wireframe
                        .as_ref()
                        .map(|w| polygon_edges(&s.scene, &w.polygons))
                        .unwrap_or_default();
                    let solid = Solid {
                        scene: s.scene.clone(),
                        edges,
                        camera: s.raster.camera,
                        lit: s.raster.shading == Shading::Lit,
                        background: s.raster.background,
                        up: seen.up,
                        smooth: true,
                    };
                    let glb = if solid.scene.triangle_count() == 0 {
                        Vec::new()
                    } else {
                        crate::export::glb_bytes_with_edges(&solid.scene, &solid.edges)?
                    };
                    ("glb", glb, Some(solid))
                }
            };
            if bytes.len() > l.max_scene_bytes {
                return Err(crate::Error::Failed(format!(
                    "step {}'s geometry takes {:.0} MB, more than the {:.0} MB the page takes whole: \
                     play fewer steps, or render the growth with `subgram render FILE -o growth.gif`",
                    f.step,
                    bytes.len() as f64 / 1e6,
                    l.max_scene_bytes as f64 / 1e6
                )));
            }
            total += bytes.len();
            if total > l.max_kept_bytes / 2 {
                return Err(crate::Error::Failed(format!(
                    "the frames up to step {} take more than the {:.0} MB the page keeps for a \
                     growth: play fewer steps, or render it with `subgram render FILE -o growth.gif`",
                    f.step,
                    l.max_kept_bytes as f64 / 2e6
                )));
            }
            files.push((f.step, kind, bytes, solid));
        }
        Ok(files
            .into_iter()
            .map(|(step, kind, bytes, solid)| {
                let size = bytes.len();
                let content = if kind == "svg" {
                    "image/svg+xml"
                } else {
                    "model/gltf-binary"
                };
                let blob = self.keep(content, bytes);
                FrameReply {
                    step,
                    blob,
                    kind,
                    scene: solid.map(|s| scene_reply(&s, blob, "glb", size, None)),
                }
            })
            .collect())
    }
}

/// The polygons' edges of a scene whose triangles are numbered by polygon
/// (`polygons`, over the meshes in order): each triangle edge that no
/// other triangle of the same polygon has, in its mesh's numbering.
fn polygon_edges(scene: &crate::scene3::Scene3, polygons: &[u32]) -> Vec<Vec<[u32; 2]>> {
    use std::collections::HashMap;
    let mut at = 0usize;
    scene
        .meshes
        .iter()
        .map(|m| {
            let mut seen: HashMap<(u32, u32, u32), u32> = HashMap::new();
            for t in &m.triangles {
                let p = polygons.get(at).copied().unwrap_or(u32::MAX);
                at += 1;
                for k in 0..3 {
                    let (a, b) = (t[k], t[(k + 1) % 3]);
                    *seen.entry((p, a.min(b), a.max(b))).or_default() += 1;
                }
            }
            let mut edges: Vec<[u32; 2]> = seen
                .into_iter()
                .filter(|(_, n)| *n == 1)
                .map(|((_, a, b), _)| [a, b])
                .collect();
            edges.sort_unstable();
            edges.dedup();
            edges
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene3::{Look, Scene3, TriMesh};
    use glam::Vec3;

    /// A quad fanned into two triangles and a lone triangle: the quad's
    /// four sides and the triangle's three, not the quad's diagonal.
    #[test]
    fn polygon_edges_leave_out_the_diagonals() {
        let mut scene = Scene3::default();
        scene.looks.push(Look::colour("a", 0, [1, 2, 3]));
        scene.meshes.push(TriMesh {
            positions: vec![Vec3::ZERO; 7],
            triangles: vec![[0, 1, 2], [0, 2, 3], [4, 5, 6]],
            ..TriMesh::default()
        });
        let edges = polygon_edges(&scene, &[0, 0, 1]);
        assert_eq!(
            edges,
            vec![vec![[0, 1], [0, 3], [1, 2], [2, 3], [4, 5], [4, 6], [5, 6]]]
        );
    }
}
