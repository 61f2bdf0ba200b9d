//! `subgram serve`: a live preview page on 127.0.0.1.
//!
//! The page (`page.html`, `app.js`, `view3d.js`, `app.css`, built into
//! the binary) edits the program's text; each edit is posted to
//! `/api/render`, which derives it as [`command::sight_edited`] does, in
//! memory, under the derivation limits of [`Limits`], and answers a 2D
//! drawing's SVG, or 3D geometry (a plant the view file draws in 3D, a
//! grammar's, vv program's or shape grammar's mesh) kept as the GLB that
//! `render -o model.glb` writes, which the page fetches from
//! `/api/blob/ID` and draws itself with WebGL (`view3d.js`: orbit, pan,
//! zoom, reset, wireframe, flat); or the diagnostics with their lines and
//! columns. Geometry larger than [`Limits::max_scene_bytes`] comes as the
//! server's z-buffer picture of it, with a message. `/api/play` derives
//! every step once on a thread of its own (`play.rs`: the frames of
//! `render -o growth.gif`, one camera) and answers its progress at
//! `/api/play/ID`, then each frame's file for the page to keep and play.
//! The server reads the program and the files a run reads (a model's
//! files, a base mesh) and serves nothing from the disk: its only routes
//! are the page's four assets and the API; what renders made is kept in
//! memory within [`Limits::max_kept_bytes`]. It never writes a file,
//! except the program itself on `/api/save` when started with `--save`
//! (atomically). Malformed requests get an error status and a message.
//!
//! Each connection brings one request (the server's small HTTP/1.1 is in
//! `http.rs`), answered on a thread of its own, at most [`MAX_IN_FLIGHT`]
//! at a time (past that a connection gets 503 at once, not a place in a
//! queue); a client has [`REQUEST_TIMEOUT`] to send its request (408
//! after). So a render that blocks (a FIFO named as a mesh) or a client
//! that never sends its body holds one thread, not the server.
//!
//! What a request must show before it is answered ([`App::answer`], which
//! decides without a socket, so that a fuzz target can drive it):
//!
//! - `Host` names the address the server listens on, `127.0.0.1:PORT` or
//!   `localhost:PORT`: a name of the attacker's that resolves to 127.0.0.1
//!   (DNS rebinding) gets 403, on every route, the page included;
//! - an `Origin`, when there is one, is the page's own
//!   (`http://127.0.0.1:PORT` or `http://localhost:PORT`), and
//!   `Sec-Fetch-Site`, when there is one, is not another site's: 403;
//! - the API (`/api/source`, `/api/render`, `/api/save`, `/api/blob/ID`,
//!   `/api/play`, `/api/play/ID`) needs the run's
//!   token in [`TOKEN_HEADER`]: 32 random bytes drawn at start, written
//!   into the page (`<meta name="subgram-token">`), which another origin
//!   cannot read; missing or wrong, 403 (compared in constant time);
//! - a POST's `Content-Type` is `application/json` (415 otherwise), a type
//!   that a page of another origin cannot send without the browser asking
//!   the server first (a CORS preflight, which gets 403).
//!
//! All of that keeps other web pages in the user's browser out. It does not
//! keep out another process on the machine, which can read the page and
//! its token as the browser does.
//!
//! **Layer.** It uses `command`, `deadline`, `error`, `files`, `load`; nothing
//! in the library uses it. Nothing here names a layer above (see
//! ARCHITECTURE.md, "Layers").

use std::io::{Read, Write};
use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};

use crate::command::{self, RenderArgs, Sight, Solid};
use crate::error::Error;
use crate::render::Rgba;

mod http;
mod play;

pub use http::{MAX_HEAD, REQUEST_TIMEOUT};

const PAGE: &str = include_str!("page.html");
const SCRIPT: &str = include_str!("app.js");
const VIEWER: &str = include_str!("view3d.js");
const STYLE: &str = include_str!("app.css");

/// The place in `page.html` where the run's token goes.
const TOKEN_SLOT: &str = "{{subgram-token}}";

/// The largest request body read (a program's text with its fields).
pub const MAX_BODY: usize = 4 << 20;

/// The most requests answered at once; one more gets 503 at once.
pub const MAX_IN_FLIGHT: usize = 8;

/// The most 503 replies being written at once; past that a connection is
/// closed unanswered.
const MAX_REFUSING: usize = 4 * MAX_IN_FLIGHT;

/// The header in which the page sends the run's token with each API call.
pub const TOKEN_HEADER: &str = "X-Subgram-Token";

/// The page's Content-Security-Policy: its own script and style, pictures
/// from `data:` URLs (the SVG) and `blob:` URLs (a server's PNG of a
/// scene too large to send), requests to its own origin only, in no
/// frame.
const PAGE_POLICY: &str = "default-src 'none'; script-src 'self'; style-src 'self'; \
     img-src data: blob:; connect-src 'self'; base-uri 'none'; form-action 'none'; \
     frame-ancestors 'none'";

/// What one render may use: the page's edits run under these, so that a
/// runaway rule stops with a message instead of holding the server.
#[derive(Clone, Debug)]
pub struct Limits {
    pub max_modules: usize,
    pub max_steps: u64,
    pub timeout: Duration,
    /// The largest 3D geometry sent to the page (a GLB file's bytes); a
    /// larger one is drawn by the server's z-buffer and sent as a PNG,
    /// with a message.
    pub max_scene_bytes: usize,
    /// The most bytes of geometry and pictures the server keeps for the
    /// page to fetch (the oldest are dropped first).
    pub max_kept_bytes: usize,
    /// The time a growth's playback may take to derive and draw all its
    /// frames.
    pub play_timeout: Duration,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_modules: 2_000_000,
            max_steps: 1_000,
            timeout: Duration::from_secs(10),
            max_scene_bytes: 256 << 20,
            max_kept_bytes: 1 << 30,
            play_timeout: Duration::from_secs(60),
        }
    }
}

/// How the server is started.
#[derive(Clone, Debug)]
pub struct ServeOptions {
    /// The program, or an lpfg model folder.
    pub path: PathBuf,
    /// 0: a free port.
    pub port: u16,
    /// `/api/save` writes the program file.
    pub save: bool,
    pub limits: Limits,
    /// `-D` values given on the command line, before the page's.
    pub defines: Vec<String>,
    /// Curves in double precision.
    pub double: bool,
}

/// A running server, bound to 127.0.0.1.
pub struct Server {
    listener: TcpListener,
    app: Arc<App>,
    /// Requests being answered.
    in_flight: Arc<AtomicUsize>,
    /// Connections being told that the server is busy.
    refusing: Arc<AtomicUsize>,
}

/// What the server answers, without its socket: the program, the options,
/// the port that `Host` and `Origin` must name, and the run's token.
pub struct App {
    opts: ServeOptions,
    /// The program file (a model folder's L-system).
    program: PathBuf,
    port: u16,
    token: String,
    /// `page.html` with the token in it.
    page: String,
    /// What renders made for the page to fetch (`/api/blob/ID`).
    blobs: Arc<std::sync::Mutex<Blobs>>,
    /// Growth playbacks (`/api/play`).
    jobs: Arc<std::sync::Mutex<play::Jobs>>,
}

/// `m` locked; a lock a panicking thread left is taken as it is (the
/// kept files and the jobs' states stay readable).
fn lock<T>(m: &std::sync::Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|p| p.into_inner())
}

/// Files kept for the page: the newest first to stay, within
/// [`Limits::max_kept_bytes`].
#[derive(Default)]
struct Blobs {
    next: u64,
    bytes: usize,
    items: std::collections::VecDeque<(u64, &'static str, Arc<Vec<u8>>)>,
}

impl Blobs {
    /// Keeps `bytes` of type `kind`; drops the oldest past `most` bytes.
    fn keep(&mut self, kind: &'static str, bytes: Vec<u8>, most: usize) -> u64 {
        self.next += 1;
        self.bytes += bytes.len();
        self.items.push_back((self.next, kind, Arc::new(bytes)));
        while self.bytes > most && self.items.len() > 1 {
            if let Some((_, _, b)) = self.items.pop_front() {
                self.bytes -= b.len();
            }
        }
        self.next
    }

    fn get(&self, id: u64) -> Option<(&'static str, Arc<Vec<u8>>)> {
        self.items
            .iter()
            .find(|(i, _, _)| *i == id)
            .map(|(_, k, b)| (*k, Arc::clone(b)))
    }
}

/// A request as [`App::answer`] sees it: the method, the target as sent
/// (path and query) and the headers, in order, names as sent.
#[derive(Clone, Debug, Default)]
pub struct Head {
    pub method: String,
    pub url: String,
    pub headers: Vec<(String, String)>,
}

/// An answer: its status, its headers and its body.
#[derive(Clone, Debug)]
pub struct Reply {
    pub status: u16,
    pub headers: Vec<(&'static str, String)>,
    pub body: Vec<u8>,
}

#[derive(Deserialize)]
struct RenderRequest {
    text: String,
    #[serde(default)]
    steps: Option<u64>,
    #[serde(default)]
    defines: Vec<String>,
}

#[derive(Deserialize)]
struct SaveRequest {
    text: String,
}

/// A diagnostic as the page shows it: `program` when it lies in the text
/// being edited (the page marks it there).
#[derive(Serialize, Clone, Debug, PartialEq)]
pub struct Message {
    pub severity: &'static str,
    pub file: String,
    pub program: bool,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub line: Option<usize>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub col: Option<usize>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub end_line: Option<usize>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub end_col: Option<usize>,
    pub message: String,
}

#[derive(Serialize)]
struct RenderReply {
    ok: bool,
    #[serde(skip_serializing_if = "Option::is_none")]
    svg: Option<String>,
    /// 3D geometry, fetched from `/api/blob/ID`.
    #[serde(skip_serializing_if = "Option::is_none")]
    scene: Option<SceneReply>,
    seconds: f64,
    messages: Vec<Message>,
    /// The limit that stopped the run, when one did.
    #[serde(skip_serializing_if = "Option::is_none")]
    limit: Option<&'static str>,
}

/// 3D geometry for the page: a GLB (`kind` "glb") to draw with its
/// camera, or, when it is larger than [`Limits::max_scene_bytes`], the
/// server's picture of it (`kind` "png") and why.
#[derive(Serialize, Clone, Debug)]
pub struct SceneReply {
    pub blob: u64,
    pub kind: &'static str,
    pub bytes: usize,
    pub triangles: usize,
    pub vertices: usize,
    /// The lowest and highest corners of the geometry.
    pub bounds: [[f32; 3]; 2],
    /// The command line's camera: eye, orthonormal right, up and viewing
    /// direction, "parallel" or "perspective", and half the visible
    /// height (parallel) or the tangent of half the field of view.
    pub eye: [f32; 3],
    pub right: [f32; 3],
    pub up: [f32; 3],
    pub dir: [f32; 3],
    pub projection: &'static str,
    pub half_height: f32,
    /// The axis the view turns about.
    pub turn_axis: [f32; 3],
    pub lit: bool,
    /// Polygon edges come with the geometry (meshes); a plant's wireframe
    /// is its triangles'.
    pub edges: bool,
    /// Shade smooth (normals given or averaged), else flat.
    pub smooth: bool,
    pub background: [u8; 3],
    #[serde(skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

/// The routes.
#[derive(Clone, Copy, PartialEq, Debug)]
enum Route {
    Page,
    Script,
    Viewer,
    Blob(u64),
    Play,
    Job(u64),
    Style,
    Source,
    Render,
    Save,
}

impl Route {
    /// The API: the routes that need the token.
    fn api(self) -> bool {
        matches!(
            self,
            Route::Source
                | Route::Render
                | Route::Save
                | Route::Blob(_)
                | Route::Play
                | Route::Job(_)
        )
    }
}

impl Server {
    /// Binds 127.0.0.1:`port` and reads the program once, so that a
    /// missing file is an error now rather than on the page.
    pub fn bind(opts: ServeOptions) -> Result<Server, Error> {
        let port = opts.port;
        let mut app = App::new(opts, port)?;
        let listener = TcpListener::bind(("127.0.0.1", port)).map_err(|e| {
            Error::Usage(format!(
                "cannot listen on 127.0.0.1:{port}: {e}; choose another --port"
            ))
        })?;
        app.port = listener
            .local_addr()
            .map_err(|e| Error::Failed(format!("the server has no address: {e}")))?
            .port();
        Ok(Server {
            listener,
            app: Arc::new(app),
            in_flight: Arc::new(AtomicUsize::new(0)),
            refusing: Arc::new(AtomicUsize::new(0)),
        })
    }

    /// The page's address.
    pub fn url(&self) -> String {
        format!("http://127.0.0.1:{}/", self.app.port)
    }

    /// The run's token, which the API asks for (the page has it).
    pub fn token(&self) -> &str {
        self.app.token()
    }

    /// Answers connections until the process stops, one request each, on
    /// a thread of its own, at most [`MAX_IN_FLIGHT`] at a time: one more
    /// gets 503 at once (on a thread of its own too, at most
    /// `4 × MAX_IN_FLIGHT` of those; past that it is closed unanswered).
    /// This loop only accepts, counts and hands on: nothing it does waits
    /// on a client.
    pub fn run(&self) {
        for stream in self.listener.incoming() {
            let stream = match stream {
                Ok(s) => s,
                Err(_) => {
                    // Out of file descriptors, say: a moment for some to
                    // close.
                    std::thread::sleep(Duration::from_millis(20));
                    continue;
                }
            };
            let work: Box<dyn FnOnce() + Send> =
                if let Some(slot) = Slot::take(&self.in_flight, MAX_IN_FLIGHT) {
                    let app = Arc::clone(&self.app);
                    Box::new(move || {
                        let _slot = slot;
                        app.connection(&stream);
                    })
                } else if let Some(slot) = Slot::take(&self.refusing, MAX_REFUSING) {
                    Box::new(move || {
                        let _slot = slot;
                        busy(&stream);
                    })
                } else {
                    continue;
                };
            // When no thread can be made, the connection is closed.
            // The stack the command line's thread has: a deep program
            // recurses in the checker as it does there.
            let _ = std::thread::Builder::new()
                .name("subgram serve".into())
                .stack_size(256 << 20)
                .spawn(work);
        }
    }
}

/// Tells a connection that the server is busy, without reading it.
fn busy(stream: &TcpStream) {
    http::prepare(stream);
    let mut reply = guarded(failure(
        503,
        &format!("the server is busy: {MAX_IN_FLIGHT} requests are being answered; try again"),
    ));
    reply.headers.push(("Retry-After", "1".to_string()));
    let _ = http::write_reply(&mut &*stream, &reply, false);
    http::close(stream);
}

/// One of a bounded number of places, given back on drop.
struct Slot(Arc<AtomicUsize>);

impl Slot {
    fn take(count: &Arc<AtomicUsize>, most: usize) -> Option<Slot> {
        count
            .fetch_update(Ordering::AcqRel, Ordering::Acquire, |n| {
                (n < most).then_some(n + 1)
            })
            .ok()
            .map(|_| Slot(Arc::clone(count)))
    }
}

impl Drop for Slot {
    fn drop(&mut self) {
        self.0.fetch_sub(1, Ordering::AcqRel);
    }
}

impl App {
    /// The answers for `opts`, as a server on `port` gives them: reads the
    /// program once (a missing file is an error now) and draws the token.
    pub fn new(opts: ServeOptions, port: u16) -> Result<App, Error> {
        let program = crate::load::program_file(&opts.path)?;
        // Read as every input is: without blocking (a pipe in its place
        // waits no longer than a render may), and no more than a program
        // may hold.
        crate::deadline::within(Some(opts.limits.timeout), || crate::load::read(&program))?;
        let token = new_token()?;
        let page = PAGE.replace(TOKEN_SLOT, &token);
        Ok(App {
            opts,
            program,
            port,
            token,
            page,
            blobs: Default::default(),
            jobs: Default::default(),
        })
    }

    /// The run's token.
    pub fn token(&self) -> &str {
        &self.token
    }

    /// A connection: one request, read before [`REQUEST_TIMEOUT`], its
    /// answer, and the end.
    fn connection(&self, stream: &TcpStream) {
        http::prepare(stream);
        let mut input = http::Timed {
            stream,
            deadline: Instant::now() + REQUEST_TIMEOUT,
        };
        self.exchange(&mut input, &mut &*stream);
        http::close(stream);
    }

    /// Reads one request from `input` (HTTP/1.1, as a connection brings
    /// it) and writes the answer to `output`: the request's head (none
    /// when it could not be read) and the reply. A protocol error (a
    /// malformed head 400, a late one 408, a POST without a length 411, a
    /// head too long 431, a chunked body 501) is answered before the
    /// checks of [`App::answer`].
    pub fn exchange(&self, input: &mut dyn Read, output: &mut dyn Write) -> (Option<Head>, Reply) {
        let (head, reply) = match http::read_head(input) {
            Err(r) => (None, guarded(r)),
            Ok((head, rest)) => {
                let reply = match body_length(&head) {
                    Err(r) => guarded(r),
                    Ok(length) => {
                        let continues = single(&head, "Expect")
                            .ok()
                            .flatten()
                            .is_some_and(|e| e.eq_ignore_ascii_case("100-continue"));
                        let mut body = Body {
                            rest: std::io::Cursor::new(rest),
                            input,
                            output: &mut *output,
                            left: length,
                            continues,
                        };
                        self.answer(&head, &mut body)
                    }
                };
                (Some(head), reply)
            }
        };
        let head_only = head.as_ref().is_some_and(|h| h.method == "HEAD");
        let _ = http::write_reply(output, &reply, head_only);
        (head, reply)
    }

    /// The answer to a request: the checks of the module's documentation
    /// (`Host`, then `Origin`, then the route: 404 or 405, then
    /// `Sec-Fetch-Site`, the token and the content type), then the route's
    /// work. The body is read (at most [`MAX_BODY`] bytes) only when a POST
    /// has passed them all.
    pub fn answer(&self, head: &Head, body: &mut dyn Read) -> Reply {
        guarded(self.decide(head, body))
    }

    fn decide(&self, head: &Head, body: &mut dyn Read) -> Reply {
        if let Err(r) = self.check_host(head) {
            return r;
        }
        if let Err(r) = self.check_origin(head) {
            return r;
        }
        let path = head.url.split('?').next().unwrap_or("");
        let route = match (head.method.as_str(), path) {
            ("GET", "/") => Route::Page,
            ("GET", "/app.js") => Route::Script,
            ("GET", "/view3d.js") => Route::Viewer,
            ("GET", "/app.css") => Route::Style,
            ("GET", "/api/source") => Route::Source,
            ("POST", "/api/render") => Route::Render,
            ("POST", "/api/save") => Route::Save,
            ("POST", "/api/play") => Route::Play,
            ("GET", job) if job.starts_with("/api/play/") => {
                match job["/api/play/".len()..].parse::<u64>() {
                    Ok(id) => Route::Job(id),
                    Err(_) => return failure(404, "no such playback: its name is its number"),
                }
            }
            ("GET", blob) if blob.starts_with("/api/blob/") => {
                match blob["/api/blob/".len()..].parse::<u64>() {
                    Ok(id) => Route::Blob(id),
                    Err(_) => return failure(404, "no such file: a blob's name is its number"),
                }
            }
            (
                _,
                "/" | "/app.js" | "/view3d.js" | "/app.css" | "/api/source" | "/api/render"
                | "/api/save" | "/api/play",
            ) => {
                return failure(
                    405,
                    &format!("{} is not allowed on {path}", clip(&head.method)),
                )
            }
            _ => {
                return failure(
                    404,
                    "no such page: the server serves the editor and its API only",
                )
            }
        };
        if let Err(r) = check_fetch_site(head, route) {
            return r;
        }
        if route.api() {
            if let Err(r) = self.check_token(head) {
                return r;
            }
        }
        match route {
            Route::Page => {
                let mut r = asset(self.page.as_bytes(), "text/html; charset=utf-8");
                r.headers.extend([
                    ("Content-Security-Policy", PAGE_POLICY.to_string()),
                    ("X-Frame-Options", "DENY".to_string()),
                    ("Cross-Origin-Opener-Policy", "same-origin".to_string()),
                ]);
                r
            }
            Route::Script => asset(SCRIPT.as_bytes(), "application/javascript; charset=utf-8"),
            Route::Viewer => asset(VIEWER.as_bytes(), "application/javascript; charset=utf-8"),
            Route::Blob(id) => self.blob(id),
            Route::Job(id) => self.job(id),
            Route::Style => asset(STYLE.as_bytes(), "text/css; charset=utf-8"),
            Route::Source => self.source(),
            Route::Render | Route::Save | Route::Play => {
                let bytes = match check_json(head).and_then(|()| read_body(head, body)) {
                    Ok(b) => b,
                    Err(r) => return r,
                };
                match route {
                    Route::Render => self.render(&bytes),
                    Route::Play => self.play(&bytes),
                    _ => self.save(&bytes),
                }
            }
        }
    }

    /// `Host` names this server: `127.0.0.1:PORT` or `localhost:PORT` (the
    /// port may be left out only when it is 80).
    fn check_host(&self, head: &Head) -> Result<(), Reply> {
        let host = match single(head, "Host") {
            Ok(Some(h)) => h.trim(),
            Ok(None) => {
                return Err(failure(
                    403,
                    "refused: the request has no Host header; the server answers requests \
                     for its own address only",
                ))
            }
            Err(r) => return Err(r),
        };
        let port = self.port.to_string();
        let ours = ["127.0.0.1", "localhost"].iter().any(|name| {
            let Some(rest) = host
                .get(..name.len())
                .filter(|h| h.eq_ignore_ascii_case(name))
                .map(|_| &host[name.len()..])
            else {
                return false;
            };
            rest.strip_prefix(':') == Some(port.as_str()) || (rest.is_empty() && self.port == 80)
        });
        if ours {
            Ok(())
        } else {
            Err(failure(
                403,
                &format!(
                    "refused: the Host header `{}` is not this server's address \
                     (127.0.0.1:{p} or localhost:{p}); the server answers requests for its own \
                     address only, against DNS rebinding",
                    clip(host),
                    p = self.port
                ),
            ))
        }
    }

    /// An `Origin`, when there is one, is the page's own.
    fn check_origin(&self, head: &Head) -> Result<(), Reply> {
        let origin = match single(head, "Origin") {
            Ok(Some(o)) => o.trim(),
            Ok(None) => return Ok(()),
            Err(r) => return Err(r),
        };
        let ours = ["127.0.0.1", "localhost"]
            .iter()
            .any(|name| origin.eq_ignore_ascii_case(&format!("http://{name}:{}", self.port)));
        if ours {
            Ok(())
        } else {
            Err(failure(
                403,
                &format!(
                    "refused: a request from `{}`, not from the page's own origin \
                     (http://127.0.0.1:{})",
                    clip(origin),
                    self.port
                ),
            ))
        }
    }

    /// The token, once, compared in constant time.
    fn check_token(&self, head: &Head) -> Result<(), Reply> {
        match single(head, TOKEN_HEADER)? {
            Some(t) if same(t.trim().as_bytes(), self.token.as_bytes()) => Ok(()),
            Some(_) => Err(failure(
                403,
                &format!("refused: the {TOKEN_HEADER} header is not this run's token"),
            )),
            None => Err(failure(
                403,
                &format!(
                    "refused: the API needs this run's token in the {TOKEN_HEADER} header, \
                     as the page sends it"
                ),
            )),
        }
    }

    fn source(&self) -> Reply {
        let limit = Some(self.opts.limits.timeout);
        match crate::deadline::within(limit, || crate::load::read(&self.program)) {
            Ok(text) => json_reply(
                200,
                &serde_json::json!({
                    "name": self.program.file_name().map(|n| n.to_string_lossy()).unwrap_or_default(),
                    "text": text,
                    "save": self.opts.save,
                }),
            ),
            Err(e) => failure(500, &format!("cannot read the program: {e}")),
        }
    }

    fn render(&self, body: &[u8]) -> Reply {
        let req: RenderRequest = match serde_json::from_slice(body) {
            Ok(r) => r,
            Err(e) => return failure(400, &format!("the request is not a render request: {e}")),
        };
        let t = Instant::now();
        let (result, limit) = render_text(&self.opts, &self.program, &req);
        let reply = match result {
            Ok((Sight::Flat(svg), warnings)) => RenderReply {
                ok: true,
                svg: Some(svg),
                scene: None,
                seconds: t.elapsed().as_secs_f64(),
                messages: warnings,
                limit: None,
            },
            Ok((Sight::Solid(solid), mut warnings)) => match self.keep_solid(&solid) {
                Ok(scene) => RenderReply {
                    ok: true,
                    svg: None,
                    scene: Some(scene),
                    seconds: t.elapsed().as_secs_f64(),
                    messages: warnings,
                    limit: None,
                },
                Err(e) => {
                    warnings.extend(messages(&e, &self.program));
                    RenderReply {
                        ok: false,
                        svg: None,
                        scene: None,
                        seconds: t.elapsed().as_secs_f64(),
                        messages: warnings,
                        limit: which_limit(&e),
                    }
                }
            },
            Err(messages) => RenderReply {
                ok: false,
                svg: None,
                scene: None,
                seconds: t.elapsed().as_secs_f64(),
                messages,
                limit,
            },
        };
        json_reply(200, &reply)
    }

    /// Keeps a render's 3D geometry for the page: its GLB (with the
    /// meshes' polygon edges), or the server's PNG of it when the GLB is
    /// larger than the page's limit.
    fn keep_solid(&self, solid: &Solid) -> Result<SceneReply, Error> {
        let limits = &self.opts.limits;
        let glb = crate::export::glb_bytes_with_edges(&solid.scene, &solid.edges)?;
        let (kind, bytes, note) = if glb.len() <= limits.max_scene_bytes {
            ("glb", glb, None)
        } else {
            let mut ropts = crate::render::raster::RasterOptions::new(solid.camera);
            ropts.background = solid.background;
            ropts.shading = if solid.lit {
                crate::render::raster::Shading::Lit
            } else {
                crate::render::raster::Shading::Unlit
            };
            let png = crate::render::raster::render_png(&solid.scene, &ropts)?;
            let note = format!(
                "the geometry ({} triangles, {:.0} MB) is larger than the {:.0} MB the page takes \
                 whole: this is the server's picture of it, which does not turn; lower the steps \
                 to turn it, or export it with `subgram render FILE -o model.glb`",
                solid.scene.triangle_count(),
                glb.len() as f64 / 1e6,
                limits.max_scene_bytes as f64 / 1e6
            );
            ("png", png, Some(note))
        };
        let size = bytes.len();
        let content = if kind == "glb" {
            "model/gltf-binary"
        } else {
            "image/png"
        };
        let blob = self.keep(content, bytes);
        Ok(scene_reply(solid, blob, kind, size, note))
    }

    /// Keeps a file for the page to fetch; its number.
    fn keep(&self, content: &'static str, bytes: Vec<u8>) -> u64 {
        lock(&self.blobs).keep(content, bytes, self.opts.limits.max_kept_bytes)
    }

    /// A file a render kept: `/api/blob/ID`.
    fn blob(&self, id: u64) -> Reply {
        let found = lock(&self.blobs).get(id);
        match found {
            Some((kind, bytes)) => asset(&bytes, kind),
            None => failure(
                404,
                "no such file: it was dropped to keep the server's memory within its limit; render again",
            ),
        }
    }

    fn save(&self, body: &[u8]) -> Reply {
        if !self.opts.save {
            return failure(
                403,
                "saving is off: start the server with --save to allow it",
            );
        }
        let req: SaveRequest = match serde_json::from_slice(body) {
            Ok(r) => r,
            Err(e) => return failure(400, &format!("the request is not a save request: {e}")),
        };
        match crate::files::atomic::write_atomic(&self.program, req.text.as_bytes()) {
            Ok(()) => json_reply(200, &serde_json::json!({ "ok": true })),
            Err(e) => failure(
                500,
                &format!("cannot write {}: {e}", self.program.display()),
            ),
        }
    }
}

/// What the page is told of 3D geometry kept as `blob` (`bytes` long, of
/// `kind` "glb" or "png").
fn scene_reply(
    solid: &Solid,
    blob: u64,
    kind: &'static str,
    bytes: usize,
    note: Option<String>,
) -> SceneReply {
    let c = &solid.camera;
    let (lo, hi) = solid.scene.bounds().unwrap_or_default();
    let Rgba(r, g, b, _) = solid.background;
    SceneReply {
        blob,
        kind,
        bytes,
        triangles: solid.scene.triangle_count(),
        vertices: solid.scene.vertex_count(),
        bounds: [lo.to_array(), hi.to_array()],
        eye: c.eye.to_array(),
        right: c.right.to_array(),
        up: c.up.to_array(),
        dir: c.dir.to_array(),
        projection: match c.projection {
            crate::render::raster::Projection::Parallel => "parallel",
            crate::render::raster::Projection::Perspective => "perspective",
        },
        half_height: c.half_height,
        turn_axis: solid.up,
        lit: solid.lit,
        edges: solid.edges.iter().any(|e| !e.is_empty()),
        smooth: solid.smooth,
        background: [r, g, b],
        note,
    }
}

/// 32 bytes from the system's random source, in hex.
fn new_token() -> Result<String, Error> {
    let mut bytes = [0u8; 32];
    getrandom::fill(&mut bytes)
        .map_err(|e| Error::Failed(format!("cannot draw the page's token: {e}")))?;
    Ok(bytes.iter().map(|b| format!("{b:02x}")).collect())
}

/// Equal, in a time that depends on the lengths only.
fn same(a: &[u8], b: &[u8]) -> bool {
    if a.len() != b.len() {
        return false;
    }
    let diff = a.iter().zip(b).fold(0u8, |d, (x, y)| d | (x ^ y));
    std::hint::black_box(diff) == 0
}

/// The value of the header `name` (any case), when it is there once; a
/// header that comes twice is refused, since the two may be read
/// differently on the way.
fn single<'a>(head: &'a Head, name: &str) -> Result<Option<&'a str>, Reply> {
    let mut found = head
        .headers
        .iter()
        .filter(|(n, _)| n.trim().eq_ignore_ascii_case(name))
        .map(|(_, v)| v.as_str());
    let first = found.next();
    if found.next().is_some() {
        return Err(failure(
            400,
            &format!("the request has more than one {name} header"),
        ));
    }
    Ok(first)
}

/// `Sec-Fetch-Site`, which browsers send: the API answers the page's own
/// origin only (`same-origin`), the page and its files also a navigation
/// the user made (`none`); another site, or another port of this host
/// (`same-site`), gets 403.
fn check_fetch_site(head: &Head, route: Route) -> Result<(), Reply> {
    let Some(site) = single(head, "Sec-Fetch-Site")? else {
        return Ok(());
    };
    let site = site.trim().to_ascii_lowercase();
    let allowed = site == "same-origin" || (site == "none" && !route.api());
    if allowed {
        Ok(())
    } else {
        Err(failure(
            403,
            &format!(
                "refused: a request from another site (Sec-Fetch-Site: {})",
                clip(&site)
            ),
        ))
    }
}

/// A POST's body is JSON: `application/json`, with parameters or not.
fn check_json(head: &Head) -> Result<(), Reply> {
    let kind = single(head, "Content-Type")?.unwrap_or("");
    let media = kind.split(';').next().unwrap_or("").trim();
    if media.eq_ignore_ascii_case("application/json") {
        Ok(())
    } else {
        Err(failure(
            415,
            &format!(
                "the API takes application/json, not `{}`",
                clip(if kind.is_empty() { "(none)" } else { kind })
            ),
        ))
    }
}

/// The headers every reply has: not to be sniffed as another type, nor
/// cached, nor read by another origin through a no-cors request.
fn guarded(mut reply: Reply) -> Reply {
    reply.headers.extend([
        ("X-Content-Type-Options", "nosniff".to_string()),
        ("Cache-Control", "no-store".to_string()),
        ("Referrer-Policy", "no-referrer".to_string()),
        ("Cross-Origin-Resource-Policy", "same-origin".to_string()),
    ]);
    reply
}

/// At most 100 characters of a value the client sent, for a message.
fn clip(s: &str) -> String {
    s.chars().take(100).collect()
}
/// What the page shows and the warnings, or the messages and the limit
/// that stopped the run.
type Rendered = (
    Result<(Sight, Vec<Message>), Vec<Message>>,
    Option<&'static str>,
);

/// Renders the page's text under the limits: the SVG and the warnings, or
/// the messages and the limit that stopped it.
fn render_text(opts: &ServeOptions, program: &Path, req: &RenderRequest) -> Rendered {
    let l = &opts.limits;
    if let Some(n) = req.steps.filter(|&n| n > l.max_steps) {
        let m = format!("{n} steps are more than the {} a page may ask", l.max_steps);
        return (Err(vec![plain(m)]), Some("steps"));
    }
    let mut a = RenderArgs::new(opts.path.to_string_lossy(), "page.svg");
    a.steps = req.steps;
    a.defines = opts.defines.iter().chain(&req.defines).cloned().collect();
    a.double = opts.double;
    a.max_modules = l.max_modules;
    a.timeout = Some(l.timeout);
    match command::sight_edited(&a, &req.text) {
        Ok(seen) => {
            let warnings = seen.warnings.iter().map(|w| warning(w, program)).collect();
            (Ok((seen.sight, warnings)), None)
        }
        Err(e) => {
            let limit = which_limit(&e);
            (Err(messages(&e, program)), limit)
        }
    }
}

/// The limit an error reports, by its message.
fn which_limit(e: &Error) -> Option<&'static str> {
    let text = e.to_string();
    if text.contains("time limit") || text.contains("--timeout") {
        Some("time")
    } else if text.contains("--max-modules") || text.contains("modules, more than") {
        Some("modules")
    } else if text.contains("iterations in one body") {
        Some("loop")
    } else if text.contains("faces") && text.contains("limit") {
        Some("size")
    } else {
        None
    }
}

fn plain(message: String) -> Message {
    Message {
        severity: "error",
        file: String::new(),
        program: false,
        line: None,
        col: None,
        end_line: None,
        end_col: None,
        message,
    }
}

/// An error's diagnostics with their places.
pub fn messages(e: &Error, program: &Path) -> Vec<Message> {
    let program_name = program.display().to_string();
    match e {
        Error::Program {
            sources,
            diagnostics,
        } => diagnostics
            .iter()
            .map(|d| {
                let f = sources.get(d.span.file);
                let (line, col) = f.line_col(d.span.start as usize);
                let (end_line, end_col) = f.line_col(d.span.end as usize);
                Message {
                    severity: "error",
                    file: f.name.clone(),
                    program: f.name == program_name,
                    line: Some(line),
                    col: Some(col),
                    end_line: Some(end_line),
                    end_col: Some(end_col),
                    message: d.message.clone(),
                }
            })
            .collect(),
        Error::FileAt {
            path,
            line,
            text,
            start,
            message,
            ..
        } => vec![Message {
            severity: "error",
            file: path.clone(),
            // A mesh file being edited is the program.
            program: *path == program_name,
            line: Some(*line),
            col: Some(text.get(..*start).map_or(1, |t| t.chars().count() + 1)),
            end_line: None,
            end_col: None,
            message: message.clone(),
        }],
        Error::File {
            path,
            line,
            message,
        } => vec![Message {
            severity: "error",
            file: path.clone(),
            program: false,
            line: *line,
            col: line.map(|_| 1),
            end_line: None,
            end_col: None,
            message: message.clone(),
        }],
        other => vec![plain(other.to_string())],
    }
}

/// A rendered warning (`file:line:col: warning: message`, the line, a
/// caret) as a message with its place.
fn warning(text: &str, program: &Path) -> Message {
    let first = text.lines().next().unwrap_or("");
    let mut m = plain(first.to_string());
    m.severity = "warning";
    if let Some((head, message)) = first.split_once(": warning: ") {
        let mut parts = head.rsplitn(3, ':');
        let col = parts.next().and_then(|c| c.parse().ok());
        let line = parts.next().and_then(|l| l.parse().ok());
        let file = parts.next().unwrap_or("").to_string();
        if let (Some(line), Some(col)) = (line, col) {
            m.program = file == program.display().to_string();
            m.file = file;
            m.line = Some(line);
            m.col = Some(col);
            m.message = message.to_string();
        }
    }
    m
}

impl Reply {
    /// The first header called `name` (any case).
    pub fn header(&self, name: &str) -> Option<&str> {
        self.headers
            .iter()
            .find(|(n, _)| n.eq_ignore_ascii_case(name))
            .map(|(_, v)| v.as_str())
    }
}

/// The length of a request's body: a `Content-Length`, once, or none (0)
/// on a request other than POST; no chunked bodies.
fn body_length(head: &Head) -> Result<u64, Reply> {
    if single(head, "Transfer-Encoding")?.is_some() {
        return Err(failure(
            501,
            "the server takes a body with a Content-Length only, not chunked",
        ));
    }
    match single(head, "Content-Length")? {
        Some(n) if !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()) => n
            .parse()
            .map_err(|_| failure(413, "the Content-Length is too large")),
        Some(_) => Err(failure(400, "the Content-Length is not a number")),
        None if head.method == "POST" => Err(failure(411, "a POST needs a Content-Length")),
        None => Ok(0),
    }
}

/// A request's body: the bytes read with its head, then the connection,
/// `left` bytes in all; `100 Continue` is sent before the first read when
/// the client asked for it.
struct Body<'a> {
    rest: std::io::Cursor<Vec<u8>>,
    input: &'a mut dyn Read,
    output: &'a mut dyn Write,
    left: u64,
    continues: bool,
}

impl Read for Body<'_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        if self.left == 0 || buf.is_empty() {
            return Ok(0);
        }
        if std::mem::take(&mut self.continues) {
            self.output.write_all(b"HTTP/1.1 100 Continue\r\n\r\n")?;
            self.output.flush()?;
        }
        let most = buf
            .len()
            .min(usize::try_from(self.left).unwrap_or(usize::MAX));
        let n = match self.rest.read(&mut buf[..most])? {
            0 => self.input.read(&mut buf[..most])?,
            n => n,
        };
        if n == 0 {
            return Err(std::io::Error::new(
                std::io::ErrorKind::UnexpectedEof,
                "the request ended before its body did",
            ));
        }
        self.left -= n as u64;
        Ok(n)
    }
}

fn asset(bytes: &[u8], kind: &str) -> Reply {
    Reply {
        status: 200,
        headers: vec![("Content-Type", kind.to_string())],
        body: bytes.to_vec(),
    }
}

fn json_reply(status: u16, value: &impl Serialize) -> Reply {
    let body = serde_json::to_vec(value).unwrap_or_else(|e| {
        format!("{{\"ok\":false,\"message\":\"cannot write the reply: {e}\"}}").into_bytes()
    });
    Reply {
        status,
        headers: vec![("Content-Type", "application/json".to_string())],
        body,
    }
}

fn failure(status: u16, message: &str) -> Reply {
    json_reply(
        status,
        &serde_json::json!({ "ok": false, "message": message }),
    )
}

/// The request's body, at most [`MAX_BODY`] bytes: one announced larger is
/// refused before it is read.
fn read_body(head: &Head, body: &mut dyn Read) -> Result<Vec<u8>, Reply> {
    let too_large = || {
        failure(
            413,
            &format!("the request is larger than {} MiB", MAX_BODY >> 20),
        )
    };
    if let Some(n) = single(head, "Content-Length")? {
        match n.trim().parse::<u64>() {
            Ok(n) if n > MAX_BODY as u64 => return Err(too_large()),
            Ok(_) => {}
            Err(_) => return Err(failure(400, "the Content-Length is not a number")),
        }
    }
    let mut bytes = Vec::new();
    match body.take(MAX_BODY as u64 + 1).read_to_end(&mut bytes) {
        Err(e) if e.kind() == std::io::ErrorKind::TimedOut => Err(failure(408, &e.to_string())),
        Err(e) => Err(failure(400, &format!("cannot read the request: {e}"))),
        Ok(_) if bytes.len() > MAX_BODY => Err(too_large()),
        Ok(_) => Ok(bytes),
    }
}
