//! `subgram serve`: a live preview page on 127.0.0.1.
//!
//! The page (`page.html`, `app.js`, `app.css`, built into the binary) edits
//! the program's text; each edit is posted to `/api/render`, which derives
//! and draws it as [`command::render_edited`] does, in memory, under the
//! derivation limits of [`Limits`], and answers the SVG or the diagnostics
//! with their lines and columns. The server reads the program and the files
//! a run reads (a model's files, a base mesh) and serves nothing from the
//! disk: its only routes are the page's three assets and the API. It never
//! writes a file, except the program itself on `/api/save` when started
//! with `--save` (atomically). Malformed requests get an error status and a
//! message.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};

use crate::command::{self, RenderArgs};
use crate::error::Error;

const PAGE: &str = include_str!("page.html");
const SCRIPT: &str = include_str!("app.js");
const STYLE: &str = include_str!("app.css");

/// The largest request body read (a program's text with its fields).
pub const MAX_BODY: usize = 4 << 20;

/// What one render may use: the page's edits run under these, so that a
/// runaway rule stops with a message instead of holding the server.
#[derive(Clone, Debug)]
pub struct Limits {
    pub max_modules: usize,
    pub max_steps: u64,
    pub timeout: Duration,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_modules: 2_000_000,
            max_steps: 1_000,
            timeout: Duration::from_secs(10),
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
    http: tiny_http::Server,
    opts: ServeOptions,
    /// The program file (a model folder's L-system).
    program: PathBuf,
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
#[derive(Serialize, Debug, PartialEq)]
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
    seconds: f64,
    messages: Vec<Message>,
    /// The limit that stopped the run, when one did.
    #[serde(skip_serializing_if = "Option::is_none")]
    limit: Option<&'static str>,
}

impl Server {
    /// Binds 127.0.0.1:`port` and reads the program once, so that a
    /// missing file is an error now rather than on the page.
    pub fn bind(opts: ServeOptions) -> Result<Server, Error> {
        let program = crate::load::program_file(&opts.path)?;
        std::fs::read_to_string(&program).map_err(|e| Error::read(&program, e))?;
        let http = tiny_http::Server::http(("127.0.0.1", opts.port)).map_err(|e| {
            Error::Usage(format!(
                "cannot listen on 127.0.0.1:{}: {e}; choose another --port",
                opts.port
            ))
        })?;
        Ok(Server {
            http,
            opts,
            program,
        })
    }

    /// The page's address.
    pub fn url(&self) -> String {
        match self.http.server_addr().to_ip() {
            Some(a) => format!("http://{a}/"),
            None => "http://127.0.0.1/".into(),
        }
    }

    /// Answers requests, one at a time, until the process stops.
    pub fn run(&self) {
        for request in self.http.incoming_requests() {
            self.answer(request);
        }
    }

    fn answer(&self, mut request: tiny_http::Request) {
        let method = request.method().clone();
        let url = request.url().to_string();
        let path = url.split('?').next().unwrap_or("");
        let reply = match (&method, path) {
            (tiny_http::Method::Get, "/") => asset(PAGE, "text/html; charset=utf-8"),
            (tiny_http::Method::Get, "/app.js") => {
                asset(SCRIPT, "application/javascript; charset=utf-8")
            }
            (tiny_http::Method::Get, "/app.css") => asset(STYLE, "text/css; charset=utf-8"),
            (tiny_http::Method::Get, "/api/source") => self.source(),
            (tiny_http::Method::Post, "/api/render") => match body(&mut request) {
                Ok(b) => self.render(&b),
                Err(r) => r,
            },
            (tiny_http::Method::Post, "/api/save") => match body(&mut request) {
                Ok(b) => self.save(&b),
                Err(r) => r,
            },
            (_, "/" | "/app.js" | "/app.css" | "/api/source" | "/api/render" | "/api/save") => {
                failure(405, &format!("{method} is not allowed on {path}"))
            }
            _ => failure(
                404,
                "no such page: the server serves the editor and its API only",
            ),
        };
        // The client may have gone: nothing to do about it.
        let _ = request.respond(reply);
    }

    fn source(&self) -> Reply {
        match std::fs::read_to_string(&self.program) {
            Ok(text) => json_reply(
                200,
                &serde_json::json!({
                    "name": self.program.file_name().map(|n| n.to_string_lossy()).unwrap_or_default(),
                    "text": text,
                    "save": self.opts.save,
                }),
            ),
            Err(e) => failure(500, &format!("cannot read {}: {e}", self.program.display())),
        }
    }

    fn render(&self, body: &[u8]) -> Reply {
        let req: RenderRequest = match serde_json::from_slice(body) {
            Ok(r) => r,
            Err(e) => return failure(400, &format!("the request is not a render request: {e}")),
        };
        let t = Instant::now();
        let (result, limit) = render_text(&self.opts, &self.program, &req);
        let seconds = t.elapsed().as_secs_f64();
        let reply = match result {
            Ok((svg, warnings)) => RenderReply {
                ok: true,
                svg: Some(svg),
                seconds,
                messages: warnings,
                limit: None,
            },
            Err(messages) => RenderReply {
                ok: false,
                svg: None,
                seconds,
                messages,
                limit,
            },
        };
        json_reply(200, &reply)
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
        match crate::atomic::write_atomic(&self.program, req.text.as_bytes()) {
            Ok(()) => json_reply(200, &serde_json::json!({ "ok": true })),
            Err(e) => failure(
                500,
                &format!("cannot write {}: {e}", self.program.display()),
            ),
        }
    }
}

/// The SVG and the warnings, or the messages and the limit that stopped
/// the run.
type Rendered = (
    Result<(String, Vec<Message>), Vec<Message>>,
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
    match command::render_edited(&a, &req.text) {
        Ok(drawn) => {
            let svg = String::from_utf8_lossy(&drawn.picture).into_owned();
            let warnings = drawn.warnings.iter().map(|w| warning(w, program)).collect();
            (Ok((svg, warnings)), None)
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
            program: false,
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

type Reply = tiny_http::Response<std::io::Cursor<Vec<u8>>>;

fn header(name: &str, value: &str) -> tiny_http::Header {
    // Both are ASCII constants of this file or the content types above.
    tiny_http::Header::from_bytes(name.as_bytes(), value.as_bytes())
        .unwrap_or_else(|()| tiny_http::Header::from_bytes(&b"X-Bad"[..], &b"1"[..]).unwrap())
}

fn asset(text: &'static str, kind: &str) -> Reply {
    tiny_http::Response::from_data(text.as_bytes().to_vec())
        .with_header(header("Content-Type", kind))
        .with_header(header("Cache-Control", "no-store"))
}

fn json_reply(status: u16, value: &impl Serialize) -> Reply {
    let bytes = serde_json::to_vec(value).unwrap_or_else(|e| {
        format!("{{\"ok\":false,\"message\":\"cannot write the reply: {e}\"}}").into_bytes()
    });
    tiny_http::Response::from_data(bytes)
        .with_status_code(status)
        .with_header(header("Content-Type", "application/json"))
        .with_header(header("Cache-Control", "no-store"))
}

fn failure(status: u16, message: &str) -> Reply {
    json_reply(
        status,
        &serde_json::json!({ "ok": false, "message": message }),
    )
}

/// The request's body, at most [`MAX_BODY`] bytes.
fn body(request: &mut tiny_http::Request) -> Result<Vec<u8>, Reply> {
    if request.body_length().is_some_and(|n| n > MAX_BODY) {
        return Err(failure(
            413,
            &format!("the request is larger than {} MiB", MAX_BODY >> 20),
        ));
    }
    let mut bytes = Vec::new();
    let read = request
        .as_reader()
        .take(MAX_BODY as u64 + 1)
        .read_to_end(&mut bytes);
    match read {
        Err(e) => Err(failure(400, &format!("cannot read the request: {e}"))),
        Ok(_) if bytes.len() > MAX_BODY => Err(failure(
            413,
            &format!("the request is larger than {} MiB", MAX_BODY >> 20),
        )),
        Ok(_) => Ok(bytes),
    }
}
