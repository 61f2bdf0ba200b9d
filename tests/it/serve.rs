//! `subgram serve` over HTTP (issue 18): the page's API derives and draws
//! an edited text, reports errors at their lines, stops runaway rules at
//! its limits, serves nothing from the disk, writes nothing unless saving
//! is on, and answers malformed requests with an error. It answers only
//! its own Host, refuses other origins, and its API needs the run's token
//! and JSON; a blocked request does not stop the others. The browser test
//! of the page itself is tests/browser/serve.py (run by .ci/run).

use std::io::{Read, Write};
use std::net::TcpStream;
use std::path::Path;
use std::time::{Duration, Instant};

use subgram::serve::{Limits, ServeOptions, Server, MAX_IN_FLIGHT};
use tempfile::TempDir;

use crate::support::scratch;

/// A server on a free port in a thread of its own, serving a copy of
/// `program` in a fresh folder (removed when the `Live` is dropped).
struct Live {
    /// `127.0.0.1:PORT`
    addr: String,
    port: u16,
    /// The run's token, as the page has it.
    token: String,
    dir: TempDir,
}

impl Live {
    fn program(&self) -> Vec<u8> {
        std::fs::read(self.dir.path().join("prog.lsys")).unwrap()
    }
}

fn start(name: &str, program: &str, save: bool, limits: Limits) -> Live {
    let dir = scratch(&format!("serve-{name}"));
    let file = dir.path().join("prog.lsys");
    std::fs::write(&file, program).unwrap();
    start_at(dir, file, save, limits)
}

/// The server of `path` (a file or model folder inside `dir`).
fn start_at(dir: tempfile::TempDir, path: std::path::PathBuf, save: bool, limits: Limits) -> Live {
    let server = Server::bind(ServeOptions {
        path,
        port: 0,
        save,
        limits,
        defines: Vec::new(),
        double: false,
    })
    .unwrap();
    let url = server.url();
    let token = server.token().to_string();
    std::thread::spawn(move || server.run());
    let addr = url
        .trim_start_matches("http://")
        .trim_end_matches('/')
        .to_string();
    let port = addr.rsplit(':').next().unwrap().parse().unwrap();
    // The token as a browser finds it: in the page.
    let (status, page) = send(&addr, "GET", "/", &[format!("Host: {addr}")], "");
    assert_eq!(status, 200, "{page}");
    let meta = "<meta name=\"subgram-token\" content=\"";
    let at = page.find(meta).expect("the page carries the token") + meta.len();
    let in_page = &page[at..at + page[at..].find('"').unwrap()];
    assert_eq!(in_page, token);
    assert_eq!(token.len(), 64, "32 random bytes in hex: {token}");
    Live {
        addr,
        port,
        token,
        dir,
    }
}

/// Sends raw bytes, returns the whole reply (head and body).
fn exchange(addr: &str, request: &[u8]) -> String {
    let mut s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(30))).unwrap();
    s.write_all(request).unwrap();
    let mut reply = Vec::new();
    let _ = s.read_to_end(&mut reply);
    String::from_utf8_lossy(&reply).into_owned()
}

/// The status code and the body of a reply.
fn split(reply: &str) -> (u16, String) {
    let status = reply
        .split_whitespace()
        .nth(1)
        .and_then(|c| c.parse().ok())
        .unwrap_or(0);
    let body = reply
        .split_once("\r\n\r\n")
        .map(|(_, b)| b.to_string())
        .unwrap_or_default();
    (status, body)
}

/// Sends raw bytes, returns the status code and the body.
fn raw(addr: &str, request: &[u8]) -> (u16, String) {
    split(&exchange(addr, request))
}

/// The text of a request with exactly these headers, and the length of its
/// body.
fn compose(method: &str, path: &str, headers: &[String], body: &str) -> String {
    let mut r = format!("{method} {path} HTTP/1.1\r\n");
    for h in headers {
        r += h;
        r += "\r\n";
    }
    r += &format!(
        "Connection: close\r\nContent-Length: {}\r\n\r\n{body}",
        body.len()
    );
    r
}

/// A request with exactly these headers.
fn send(addr: &str, method: &str, path: &str, headers: &[String], body: &str) -> (u16, String) {
    raw(addr, compose(method, path, headers, body).as_bytes())
}

/// The headers the page sends: its Host, the token, and JSON for a POST.
fn page_headers(live: &Live, method: &str) -> Vec<String> {
    let mut h = vec![
        format!("Host: {}", live.addr),
        format!("X-Subgram-Token: {}", live.token),
    ];
    if method == "POST" {
        h.push("Content-Type: application/json".into());
    }
    h
}

/// A request as the page makes it.
fn request(live: &Live, method: &str, path: &str, body: &str) -> (u16, String) {
    send(&live.addr, method, path, &page_headers(live, method), body)
}

fn render_body(text: &str, extra: &str) -> String {
    format!(
        "{{\"text\": {}{extra}}}",
        serde_json::to_string(text).unwrap()
    )
}

fn render(live: &Live, text: &str, extra: &str) -> serde_json::Value {
    let (status, reply) = request(live, "POST", "/api/render", &render_body(text, extra));
    assert_eq!(status, 200, "{reply}");
    serde_json::from_str(&reply).unwrap()
}

/// A file a render kept (`/api/blob/ID`), fetched as the page fetches it:
/// its status, content type and bytes.
fn blob(live: &Live, id: &serde_json::Value) -> (u16, String, Vec<u8>) {
    let path = format!("/api/blob/{}", id.as_u64().expect("a blob number"));
    let request = compose("GET", &path, &page_headers(live, "GET"), "");
    let mut s = TcpStream::connect(&live.addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(30))).unwrap();
    s.write_all(request.as_bytes()).unwrap();
    let mut reply = Vec::new();
    let _ = s.read_to_end(&mut reply);
    let at = reply
        .windows(4)
        .position(|w| w == b"\r\n\r\n")
        .expect("a reply head");
    let head = String::from_utf8_lossy(&reply[..at]).into_owned();
    let status = head.split_whitespace().nth(1).unwrap().parse().unwrap();
    let kind = head
        .lines()
        .find_map(|l| l.strip_prefix("Content-Type: "))
        .unwrap_or("")
        .to_string();
    (status, kind, reply[at + 4..].to_vec())
}

/// A GLB's JSON chunk and its BIN chunk, read by the container's layout
/// (glTF 2.0, section 4.4).
fn glb(bytes: &[u8]) -> (serde_json::Value, &[u8]) {
    let word = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
    assert_eq!(&bytes[..4], b"glTF");
    assert_eq!(word(4), 2);
    assert_eq!(word(8), bytes.len());
    let json_len = word(12);
    assert_eq!(&bytes[16..20], b"JSON");
    let doc = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
    let bin_at = 20 + json_len;
    assert_eq!(&bytes[bin_at + 4..bin_at + 8], b"BIN\0");
    (doc, &bytes[bin_at + 8..bin_at + 8 + word(bin_at)])
}

const KOCH: &str = "angle: 60;\nderivation length: 3;\nAxiom: F--F--F;\nF -> F+F--F+F\n";

fn files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut v: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            (
                e.file_name().to_string_lossy().into_owned(),
                std::fs::read(e.path()).unwrap(),
            )
        })
        .collect();
    v.sort();
    v
}

#[test]
fn the_page_and_the_api_draw_an_edited_text_and_place_its_errors() {
    let live = start("draw", KOCH, false, Limits::default());
    let addr = &live;
    let dir = live.dir.path();
    let before = files(dir);
    let (status, page) = request(addr, "GET", "/", "");
    assert_eq!(status, 200);
    assert!(page.contains("/app.js") && page.contains("<textarea"));
    for asset in ["/app.js", "/app.css"] {
        assert_eq!(request(addr, "GET", asset, "").0, 200, "{asset}");
    }
    let (status, source) = request(addr, "GET", "/api/source", "");
    assert_eq!(status, 200);
    let source: serde_json::Value = serde_json::from_str(&source).unwrap();
    assert_eq!(source["text"], KOCH);
    assert_eq!(source["save"], false);

    // The text as it stands, then an edit: another picture. 3 steps of
    // the snowflake are 3 · 4³ segments, 2 steps 3 · 4².
    let three = render(addr, KOCH, "");
    assert_eq!(three["ok"], true, "{three}");
    let svg3 = three["svg"].as_str().unwrap();
    assert!(svg3.starts_with("<svg"));
    let two = render(addr, KOCH, ", \"steps\": 2");
    let svg2 = two["svg"].as_str().unwrap();
    assert_ne!(svg2, svg3);
    let segments = |svg: &str| svg.matches('L').count();
    assert_eq!(segments(svg3), 3 * 64);
    assert_eq!(segments(svg2), 3 * 16);
    // A -D value from the page's fields.
    let defined =
        "#define N 2\nangle: 60;\nderivation length: N;\nAxiom: F--F--F;\nF -> F+F--F+F\n";
    let r = render(addr, defined, ", \"defines\": [\"N=1\"]");
    assert_eq!(segments(r["svg"].as_str().unwrap()), 3 * 4);

    // An error: its line and column in the edited text.
    let bad = KOCH.replace("F -> F+F", "F -> F+F @");
    let r = render(addr, &bad, "");
    assert_eq!(r["ok"], false);
    let m = &r["messages"][0];
    let col = bad.lines().nth(3).unwrap().find('@').unwrap() as u64 + 1;
    assert_eq!(
        (m["line"].as_u64(), m["col"].as_u64()),
        (Some(4), Some(col)),
        "{r}"
    );
    assert_eq!(m["program"], true);
    assert!(m["message"].as_str().unwrap().contains("`@`"), "{r}");
    // Nothing written, the program untouched.
    assert_eq!(files(dir), before);
}

#[test]
fn runaway_rules_stop_at_the_page_limits_and_the_server_goes_on() {
    let limits = Limits {
        max_modules: 10_000,
        max_steps: 50,
        timeout: Duration::from_secs(2),
        ..Limits::default()
    };
    let live = start("limits", KOCH, false, limits);
    let addr = &live;
    let t = std::time::Instant::now();
    let r = render(
        addr,
        "module A;\nderivation length: 60;\nAxiom: A;\nA -> A A\n",
        "",
    );
    assert_eq!(
        (r["ok"].as_bool(), r["limit"].as_str()),
        (Some(false), Some("modules")),
        "{r}"
    );
    let r = render(
        addr,
        "module A;\nderivation length: 2;\nAxiom: A;\nA : { int i = 0; while (1) { i = i + 1; } produce A; }\n",
        "",
    );
    assert_eq!(r["ok"], false, "{r}");
    assert!(matches!(r["limit"].as_str(), Some("time" | "loop")), "{r}");
    let r = render(addr, KOCH, ", \"steps\": 51");
    assert_eq!(r["limit"], "steps", "{r}");
    assert!(t.elapsed() < Duration::from_secs(20));
    // Still there.
    assert_eq!(render(addr, KOCH, "")["ok"], true);
}

#[test]
fn malformed_requests_get_errors_and_nothing_from_the_disk_is_served() {
    let live = start("bad", KOCH, false, Limits::default());
    let addr = &live;
    let dir = live.dir.path();
    std::fs::write(dir.join("secret.txt"), "not for the page").unwrap();
    for path in [
        "/secret.txt",
        "/../secret.txt",
        "/prog.lsys",
        "/%2e%2e/Cargo.toml",
        "/api/../secret.txt",
        "/etc/passwd",
    ] {
        let (status, body) = request(addr, "GET", path, "");
        assert_eq!(status, 404, "{path}: {body}");
        assert!(
            !body.contains("not for the page") && !body.contains("F--F"),
            "{path}"
        );
    }
    assert_eq!(request(addr, "PUT", "/", "").0, 405);
    assert_eq!(request(addr, "GET", "/api/render", "").0, 405);
    let (status, body) = request(addr, "POST", "/api/render", "{not json");
    assert_eq!(status, 400, "{body}");
    let (status, _) = request(addr, "POST", "/api/render", "{\"steps\": 2}");
    assert_eq!(status, 400);
    // A body announced larger than the limit is refused before it is read.
    let mut big = String::from("POST /api/render HTTP/1.1\r\n");
    for h in page_headers(&live, "POST") {
        big += &format!("{h}\r\n");
    }
    big += &format!(
        "Connection: close\r\nContent-Length: {}\r\n\r\n{{}}",
        subgram::serve::MAX_BODY + 1
    );
    assert_eq!(raw(&live.addr, big.as_bytes()).0, 413);
    // Not HTTP at all.
    let (status, _) = raw(&live.addr, b"\x00\x01garbage\r\n\r\n");
    assert!(status == 400 || status == 0, "{status}");
    // Saving is off.
    let (status, body) = request(addr, "POST", "/api/save", "{\"text\": \"x\"}");
    assert_eq!(status, 403, "{body}");
    assert_eq!(
        std::fs::read_to_string(dir.join("prog.lsys")).unwrap(),
        KOCH
    );
    // And the server still answers.
    assert_eq!(render(addr, KOCH, "")["ok"], true);
}

#[test]
fn with_save_the_page_writes_the_program_back_and_nothing_else() {
    let live = start("save", KOCH, true, Limits::default());
    let addr = &live;
    let dir = live.dir.path();
    let edited = KOCH.replace("derivation length: 3", "derivation length: 2");
    let body = format!("{{\"text\": {}}}", serde_json::to_string(&edited).unwrap());
    let (status, reply) = request(addr, "POST", "/api/save", &body);
    assert_eq!(status, 200, "{reply}");
    assert_eq!(
        std::fs::read_to_string(dir.join("prog.lsys")).unwrap(),
        edited
    );
    let names: Vec<String> = files(dir).into_iter().map(|(n, _)| n).collect();
    assert_eq!(names, ["prog.lsys"], "no temporary file left");
    let (_, source) = request(addr, "GET", "/api/source", "");
    assert!(source.contains("derivation length: 2"));
}

/// A surface grammar on the page: its mesh for the page's 3D view, a GLB
/// of the subdivided octahedron (8 · 4² triangles after two Loop steps)
/// with its polygon edges as lines (a closed triangle mesh has 3F/2 edges,
/// and V = E - F + 2 vertices), its base mesh read from the disk as the
/// grammar names it; the camera is the command line's, orthonormal.
#[test]
fn a_surface_grammar_shows_its_shaded_mesh() {
    let mesh = crate::support::root().join("lsystems/meshes/octahedron.obj");
    let grammar = std::fs::read_to_string(crate::support::lsys("surfaces/loop.lsys"))
        .unwrap()
        .replace(
            "mesh: \"../meshes/octahedron.obj\";",
            &format!("mesh: {:?};", mesh.to_str().unwrap()),
        );
    assert!(grammar.contains(mesh.to_str().unwrap()));
    let live = start("surface", &grammar, false, Limits::default());
    let addr = &live;
    let r = render(addr, &grammar, ", \"steps\": 2");
    assert_eq!(r["ok"], true, "{r}");
    let scene = &r["scene"];
    assert_eq!(scene["kind"], "glb", "{r}");
    let (faces, edges) = (8 * 16, 8 * 16 * 3 / 2);
    assert_eq!(scene["triangles"], faces);
    assert_eq!(scene["edges"], true);
    let (status, kind, bytes) = blob(addr, &scene["blob"]);
    assert_eq!((status, kind.as_str()), (200, "model/gltf-binary"));
    assert_eq!(scene["bytes"], bytes.len());
    let (doc, bin) = glb(&bytes);
    let prims = doc["meshes"][0]["primitives"].as_array().unwrap();
    let count = |mode: u64| -> u64 {
        prims
            .iter()
            .filter(|p| p["mode"] == mode)
            .map(|p| {
                doc["accessors"][p["indices"].as_u64().unwrap() as usize]["count"]
                    .as_u64()
                    .unwrap()
            })
            .sum()
    };
    assert_eq!(count(4), 3 * faces as u64);
    assert_eq!(count(1), 2 * edges as u64);
    let positions = doc["accessors"][prims[0]["attributes"]["POSITION"].as_u64().unwrap() as usize]
        ["count"]
        .as_u64()
        .unwrap();
    assert_eq!(positions, (edges - faces + 2) as u64);
    assert_eq!(doc["buffers"][0]["byteLength"], bin.len());
    // The camera's frame is orthonormal, and it looks at the mesh.
    let v = |k: &str| -> [f64; 3] {
        let a = scene[k].as_array().unwrap();
        [0, 1, 2].map(|i| a[i].as_f64().unwrap())
    };
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    for (a, b, want) in [
        ("right", "right", 1.0),
        ("up", "up", 1.0),
        ("dir", "dir", 1.0),
        ("right", "up", 0.0),
        ("up", "dir", 0.0),
        ("right", "dir", 0.0),
    ] {
        assert!((dot(v(a), v(b)) - want).abs() < 1e-5, "{a}·{b}: {r}");
    }
    assert_eq!(scene["projection"], "parallel");
    // The octahedron's subdivided mesh lies within its base's box, ±1.
    let [lo, hi] = [0, 1].map(|k| scene["bounds"][k].as_array().unwrap().clone());
    for i in 0..3 {
        assert!(
            lo[i].as_f64().unwrap() >= -1.0 && hi[i].as_f64().unwrap() <= 1.0,
            "{r}"
        );
    }
}

/// A plant drawn in 3D (its view file asks for cylinders) comes to the
/// page as the GLB that `render -o plant.glb` writes, byte for byte; a
/// mesh too large for the page's limit comes as the server's PNG of it,
/// with a message that says why.
#[test]
fn a_3d_plant_comes_as_the_exported_glb_and_a_large_one_as_a_picture() {
    let dir = scratch("serve-plant");
    let model = crate::support::lsys("open/collide-3d");
    for e in std::fs::read_dir(&model).unwrap() {
        let p = e.unwrap().path();
        std::fs::copy(&p, dir.path().join(p.file_name().unwrap())).unwrap();
    }
    let export = scratch("serve-plant-export");
    let glb_path = export.path().join("plant.glb");
    let mut a =
        subgram::command::RenderArgs::new(dir.path().to_string_lossy(), glb_path.to_string_lossy());
    a.steps = Some(4);
    subgram::command::render(&a, |_| {}).unwrap();
    let exported = std::fs::read(&glb_path).unwrap();
    let folder = dir.path().to_path_buf();
    let text = std::fs::read_to_string(model.join("lsystem.l")).unwrap();
    let live = start_at(dir, folder, false, Limits::default());
    let r = render(&live, &text, ", \"steps\": 4");
    assert_eq!(r["ok"], true, "{r}");
    assert_eq!(r["scene"]["kind"], "glb");
    assert_eq!(r["scene"]["edges"], false);
    let (_, _, bytes) = blob(&live, &r["scene"]["blob"]);
    assert!(bytes == exported, "the page's GLB is the exported file");
    // Past the page's limit: the server's picture, and why.
    let folder = live.dir.path().to_path_buf();
    let small = Limits {
        max_scene_bytes: exported.len() - 1,
        ..Limits::default()
    };
    let tight = start_at(scratch("serve-plant-tight"), folder, false, small);
    let r = render(&tight, &text, ", \"steps\": 4");
    assert_eq!(r["ok"], true, "{r}");
    assert_eq!(r["scene"]["kind"], "png");
    let note = r["scene"]["note"].as_str().unwrap();
    assert!(
        note.contains("larger than") && note.contains("-o model.glb"),
        "{note}"
    );
    let (status, kind, png) = blob(&tight, &r["scene"]["blob"]);
    assert_eq!((status, kind.as_str()), (200, "image/png"));
    assert_eq!(&png[1..4], b"PNG");
    // A blob that is not there.
    let (status, _, _) = blob(&tight, &serde_json::json!(999_999));
    assert_eq!(status, 404);
}

/// An open L-system (a model folder with a `.e` file) is drawn with its
/// environment, started afresh for every run: two runs draw the same
/// picture, a run that turns the environment off draws another (its
/// tentacles never grow), and the folder gains no file.
#[test]
fn an_open_model_runs_with_its_environment_each_time() {
    let dir = scratch("serve-open");
    let model = crate::support::lsys("open/collide-3d");
    for e in std::fs::read_dir(&model).unwrap() {
        let p = e.unwrap().path();
        std::fs::copy(&p, dir.path().join(p.file_name().unwrap())).unwrap();
    }
    let before = files(dir.path());
    let folder = dir.path().to_path_buf();
    let live = start_at(dir, folder, false, Limits::default());
    let text = std::fs::read_to_string(model.join("lsystem.l")).unwrap();
    let geometry = |r: &serde_json::Value| blob(&live, &r["scene"]["blob"]).2;
    let first = render(&live, &text, ", \"steps\": 4");
    assert_eq!(first["ok"], true, "{first}");
    let again = render(&live, &text, ", \"steps\": 4");
    assert_eq!(geometry(&first), geometry(&again));
    let closed = text.replace("Axiom:", "Start: { NoEnvironment(); }\nAxiom:");
    let off = render(&live, &closed, ", \"steps\": 4");
    assert_eq!(off["ok"], true, "{off}");
    assert_ne!(geometry(&first), geometry(&off));
    assert_eq!(files(live.dir.path()), before);
}

/// The checks against other web pages: a page of another
/// origin, or a name of an attacker's that resolves to 127.0.0.1 (DNS
/// rebinding), can neither write the program (with `--save` on) nor read
/// it, nor read the page with its token; a request without the run's
/// token, or with a body that is not JSON, is refused. The program stays
/// byte for byte as it was.
#[test]
fn other_origins_and_hosts_cannot_save_read_or_see_the_token() {
    let live = start("origins", KOCH, true, Limits::default());
    let addr = &live.addr;
    let before = live.program();
    let host = format!("Host: {addr}");
    let token = format!("X-Subgram-Token: {}", live.token);
    let json = "Content-Type: application/json".to_string();
    let evil = "Origin: http://evil.example".to_string();
    let save = "{\"text\": \"Axiom: F;\\n\"}";
    let h = |v: &[&String]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    let refused = |what: &str, status: u16, headers: Vec<String>, method: &str, path: &str| {
        let (got, body) = send(addr, method, path, &headers, save);
        assert_eq!(got, status, "{what}: {body}");
        let reply: serde_json::Value = serde_json::from_str(&body)
            .unwrap_or_else(|e| panic!("{what}: not JSON ({e}): {body}"));
        assert_eq!(reply["ok"], false, "{what}: {body}");
        assert!(reply["message"].is_string(), "{what}: {body}");
        assert!(!body.contains(&live.token), "{what}: the token leaked");
        assert!(!body.contains("F--F"), "{what}: the program leaked");
        assert_eq!(live.program(), before, "{what}: the program was written");
    };
    let text_plain = "Content-Type: text/plain".to_string();
    // A form or a no-cors fetch of another page: text/plain, no token.
    refused(
        "cross-origin text/plain save",
        403,
        h(&[&host, &evil, &text_plain]),
        "POST",
        "/api/save",
    );
    // Even with the token and JSON, another origin is refused.
    refused(
        "cross-origin save with the token",
        403,
        h(&[&host, &evil, &token, &json]),
        "POST",
        "/api/save",
    );
    for origin in [
        "null",
        "http://127.0.0.1",
        "http://localhost:1",
        "https://127.0.0.1",
    ] {
        let o = format!("Origin: {origin}");
        refused(
            origin,
            403,
            h(&[&host, &o, &token, &json]),
            "POST",
            "/api/save",
        );
    }
    // JSON without the token, or with another one.
    refused("no token", 403, h(&[&host, &json]), "POST", "/api/save");
    let wrong = format!("X-Subgram-Token: {}", "0".repeat(64));
    refused(
        "a wrong token",
        403,
        h(&[&host, &json, &wrong]),
        "POST",
        "/api/save",
    );
    let short = format!("X-Subgram-Token: {}", &live.token[..63]);
    refused(
        "a token cut short",
        403,
        h(&[&host, &json, &short]),
        "POST",
        "/api/save",
    );
    // The token twice (one of them right): ambiguous, refused.
    refused(
        "two tokens",
        400,
        h(&[&host, &json, &wrong, &token]),
        "POST",
        "/api/save",
    );
    // The token, but not JSON: 415, on both POST routes.
    refused(
        "text/plain",
        415,
        h(&[&host, &token, &text_plain]),
        "POST",
        "/api/save",
    );
    refused(
        "no content type",
        415,
        h(&[&host, &token]),
        "POST",
        "/api/save",
    );
    let form = "Content-Type: application/x-www-form-urlencoded".to_string();
    refused(
        "a form",
        415,
        h(&[&host, &token, &form]),
        "POST",
        "/api/render",
    );
    let jsonish = "Content-Type: application/jsonp".to_string();
    refused(
        "application/jsonp",
        415,
        h(&[&host, &token, &jsonish]),
        "POST",
        "/api/save",
    );
    // DNS rebinding: the attacker's name, on the page and on the API.
    let rebound = "Host: evil.example".to_string();
    let rebound_port = format!("Host: evil.example:{}", live.port);
    for (what, headers, method, path) in [
        ("rebound page", h(&[&rebound]), "GET", "/"),
        (
            "rebound page with the port",
            h(&[&rebound_port]),
            "GET",
            "/",
        ),
        ("rebound script", h(&[&rebound_port]), "GET", "/app.js"),
        (
            "rebound source",
            h(&[&rebound_port, &token]),
            "GET",
            "/api/source",
        ),
        (
            "rebound save",
            h(&[&rebound_port, &token, &json]),
            "POST",
            "/api/save",
        ),
        (
            "rebound render",
            h(&[&rebound_port, &token, &json]),
            "POST",
            "/api/render",
        ),
    ] {
        refused(what, 403, headers, method, path);
    }
    // Another port, no port, no Host at all, two Hosts.
    let other_port = format!("Host: 127.0.0.1:{}", live.port.wrapping_add(1));
    refused("another port", 403, h(&[&other_port]), "GET", "/");
    refused(
        "no port",
        403,
        h(&[&"Host: 127.0.0.1".to_string()]),
        "GET",
        "/",
    );
    refused("no Host", 403, Vec::new(), "GET", "/");
    let (status, body) = raw(addr, b"GET / HTTP/1.0\r\n\r\n");
    assert_eq!(status, 403, "HTTP/1.0 without a Host: {body}");
    refused("two Hosts", 400, h(&[&host, &rebound]), "GET", "/");
    // Browsers' Sec-Fetch-Site: another site, or another port of this host.
    let cross = "Sec-Fetch-Site: cross-site".to_string();
    let same_site = "Sec-Fetch-Site: same-site".to_string();
    let none = "Sec-Fetch-Site: none".to_string();
    refused("cross-site page", 403, h(&[&host, &cross]), "GET", "/");
    refused(
        "cross-site save",
        403,
        h(&[&host, &cross, &token, &json]),
        "POST",
        "/api/save",
    );
    refused(
        "same-site source",
        403,
        h(&[&host, &same_site, &token]),
        "GET",
        "/api/source",
    );
    refused(
        "a navigation to the API",
        403,
        h(&[&host, &none, &token]),
        "GET",
        "/api/source",
    );
    // The program's text needs the token too.
    refused(
        "source without the token",
        403,
        h(&[&host]),
        "GET",
        "/api/source",
    );
    // A navigation the user made (typing the address) gets the page.
    let (status, _) = send(addr, "GET", "/", &h(&[&host, &none]), "");
    assert_eq!(status, 200);
    // The page's headers: no sniffing, its own script and style only, in
    // no frame, never cached.
    let reply = exchange(addr, compose("GET", "/", &h(&[&host]), "").as_bytes());
    let head = reply.split("\r\n\r\n").next().unwrap().to_ascii_lowercase();
    for want in [
        "x-content-type-options: nosniff",
        "content-security-policy: default-src 'none'; script-src 'self'; style-src 'self'",
        "frame-ancestors 'none'",
        "x-frame-options: deny",
        "cache-control: no-store",
        "content-type: text/html",
    ] {
        assert!(head.contains(want), "no `{want}` in\n{head}");
    }
    let reply = exchange(
        addr,
        compose("GET", "/api/source", &h(&[&host]), "").as_bytes(),
    );
    assert!(reply
        .to_ascii_lowercase()
        .contains("x-content-type-options: nosniff"));
    assert_eq!(live.program(), before);
}

/// The page's own requests: from its origin (either name of the loopback
/// address), with the token and JSON (with a charset), as a browser sends
/// them, are answered, and Save writes the program.
#[test]
fn the_page_s_own_origin_with_the_token_and_json_is_answered() {
    let live = start("own", KOCH, true, Limits::default());
    let edited = KOCH.replace("derivation length: 3", "derivation length: 1");
    let body = format!("{{\"text\": {}}}", serde_json::to_string(&edited).unwrap());
    for (host, origin) in [
        (live.addr.clone(), live.addr.clone()),
        (
            format!("localhost:{}", live.port),
            format!("localhost:{}", live.port),
        ),
        (
            format!("LocalHost:{}", live.port),
            format!("localhost:{}", live.port),
        ),
    ] {
        let headers = vec![
            format!("Host: {host}"),
            format!("Origin: http://{origin}"),
            "Sec-Fetch-Site: same-origin".to_string(),
            format!("X-Subgram-Token: {}", live.token),
            "Content-Type: application/json; charset=utf-8".to_string(),
        ];
        let (status, reply) = send(
            &live.addr,
            "POST",
            "/api/render",
            &headers,
            &render_body(KOCH, ""),
        );
        assert_eq!(status, 200, "{host}: {reply}");
        assert!(reply.contains("\"ok\":true"), "{host}: {reply}");
        let (status, source) = send(&live.addr, "GET", "/api/source", &headers[..4], "");
        assert_eq!(status, 200, "{host}: {source}");
        std::fs::write(live.dir.path().join("prog.lsys"), KOCH).unwrap();
        let (status, reply) = send(&live.addr, "POST", "/api/save", &headers, &body);
        assert_eq!(status, 200, "{host}: {reply}");
        assert_eq!(live.program(), edited.as_bytes(), "{host}");
    }
}

/// A request that does not finish, opened and left as it is: the headers
/// and a part of the announced body. The server's thread for it waits for
/// the rest (until `REQUEST_TIMEOUT`, far longer than this test).
fn hanging(live: &Live) -> TcpStream {
    let mut s = TcpStream::connect(&live.addr).unwrap();
    let mut r = "POST /api/render HTTP/1.1\r\n".to_string();
    for h in page_headers(live, "POST") {
        r += &h;
        r += "\r\n";
    }
    r += "Content-Length: 100000\r\n\r\n{\"text\": \"";
    s.write_all(r.as_bytes()).unwrap();
    s
}

/// Until `f` is true, for at most `secs` seconds.
fn within(secs: u64, what: &str, mut f: impl FnMut() -> bool) {
    let t = Instant::now();
    while !f() {
        assert!(
            t.elapsed() < Duration::from_secs(secs),
            "{what}: not within {secs} s"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
}

/// One request that blocks (a client that never sends its body; a render
/// of a grammar whose mesh is a FIFO nobody writes) stops neither the page
/// nor other renders; past [`MAX_IN_FLIGHT`] requests at once the server
/// answers 503 at once, and when they go it answers again.
#[test]
fn a_blocked_request_does_not_stop_the_others() {
    let live = start("blocked", KOCH, false, Limits::default());
    let mut held = vec![hanging(&live)];

    // A FIFO as the base mesh: reading it blocks until someone writes, or
    // is refused at once where FIFOs are refused; both are fine here.
    #[cfg(unix)]
    let fifo = {
        let fifo = live.dir.path().join("mesh.obj");
        let made = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap();
        assert!(made.success());
        let grammar = std::fs::read_to_string(crate::support::lsys("surfaces/loop.lsys"))
            .unwrap()
            .replace(
                "mesh: \"../meshes/octahedron.obj\";",
                &format!("mesh: {:?};", fifo.to_str().unwrap()),
            );
        assert!(grammar.contains(fifo.to_str().unwrap()));
        let r = compose(
            "POST",
            "/api/render",
            &page_headers(&live, "POST"),
            &render_body(&grammar, ", \"steps\": 1"),
        );
        let addr = live.addr.clone();
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || tx.send(raw(&addr, r.as_bytes())));
        (fifo, rx)
    };

    // The others are answered, and quickly.
    let t = Instant::now();
    let (status, page) = request(&live, "GET", "/", "");
    assert_eq!(status, 200);
    assert!(page.contains("<textarea"));
    assert_eq!(render(&live, KOCH, "")["ok"], true);
    assert!(t.elapsed() < Duration::from_secs(5), "{:?}", t.elapsed());

    #[cfg(unix)]
    {
        let (fifo, rx) = fifo;
        // Let a blocked reader go: a writer that opens and closes gives
        // it the end of the file. Opening without blocking fails while no
        // reader has the FIFO open.
        let mut reply = None;
        within(30, "the FIFO render", || {
            if let Ok(r) = rx.try_recv() {
                reply = Some(r);
                return true;
            }
            #[cfg(target_os = "linux")]
            {
                use std::os::unix::fs::OpenOptionsExt;
                let _ = std::fs::OpenOptions::new()
                    .write(true)
                    .custom_flags(libc::O_NONBLOCK)
                    .open(&fifo);
            }
            false
        });
        let (status, body) = reply.unwrap();
        assert_eq!(status, 200, "{body}");
        assert!(
            body.contains("\"ok\":false"),
            "an empty mesh draws nothing: {body}"
        );
    }

    // The bound: with MAX_IN_FLIGHT requests hanging, one more gets 503 at
    // once, not a place in a queue. (A hanging request that came while an
    // earlier one still held its place got 503 itself: another is opened
    // until the places are full.)
    while held.len() < MAX_IN_FLIGHT {
        held.push(hanging(&live));
    }
    within(10, "503 with every place taken", || {
        let t = Instant::now();
        let (status, body) = request(&live, "GET", "/", "");
        assert!(t.elapsed() < Duration::from_secs(5), "{:?}", t.elapsed());
        match status {
            503 => assert!(body.contains("busy"), "{body}"),
            200 => held.push(hanging(&live)),
            _ => panic!("{status}: {body}"),
        }
        status == 503
    });
    assert!(
        held.len() < 2 * MAX_IN_FLIGHT,
        "{} requests held",
        held.len()
    );
    // The clients go: their requests end, and the server answers again.
    drop(held);
    within(10, "answers again", || {
        request(&live, "GET", "/", "").0 == 200
    });
    assert_eq!(render(&live, KOCH, "")["ok"], true);
}

/// `subgram view`: the server started as `serve` starts it, and its page
/// opened with the browser `$BROWSER` names (here a script that writes
/// down the address it was given): the address printed, the page there.
#[cfg(unix)]
#[test]
fn view_opens_the_page_in_the_browser() {
    use std::io::BufRead;
    use std::os::unix::fs::PermissionsExt;
    let dir = scratch("serve-view");
    let program = dir.path().join("koch.lsys");
    std::fs::write(&program, KOCH).unwrap();
    let opened = dir.path().join("opened");
    let browser = dir.path().join("browser.sh");
    std::fs::write(
        &browser,
        format!(
            "#!/bin/sh\nprintf '%s' \"$1\" > '{}.part' && mv '{0}.part' '{0}'\n",
            opened.display()
        ),
    )
    .unwrap();
    std::fs::set_permissions(&browser, std::fs::Permissions::from_mode(0o755)).unwrap();
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_subgram"))
        .args(["view", program.to_str().unwrap(), "--port", "0"])
        .env("BROWSER", &browser)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let mut line = String::new();
    std::io::BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    let url = line
        .split_whitespace()
        .find(|w| w.starts_with("http://127.0.0.1:"))
        .unwrap_or_else(|| panic!("no address printed: {line:?}"))
        .to_string();
    let t = Instant::now();
    while !opened.exists() && t.elapsed() < Duration::from_secs(20) {
        std::thread::sleep(Duration::from_millis(20));
    }
    let given = std::fs::read_to_string(&opened);
    let addr = url
        .trim_start_matches("http://")
        .trim_end_matches('/')
        .to_string();
    let (status, page) = send(&addr, "GET", "/", &[format!("Host: {addr}")], "");
    let _ = child.kill();
    let _ = child.wait();
    assert_eq!(given.expect("the browser was not opened"), url);
    assert_eq!(status, 200);
    assert!(page.contains("subgram-token"), "{page}");
}

/// A playback's job to its end, polled as the page polls it.
fn play(live: &Live, text: &str, extra: &str) -> serde_json::Value {
    let (status, reply) = request(live, "POST", "/api/play", &render_body(text, extra));
    assert_eq!(status, 200, "{reply}");
    let job: serde_json::Value = serde_json::from_str(&reply).unwrap();
    let id = job["job"].as_u64().expect("a job number");
    let t = Instant::now();
    loop {
        let (status, reply) = request(live, "GET", &format!("/api/play/{id}"), "");
        assert_eq!(status, 200, "{reply}");
        let state: serde_json::Value = serde_json::from_str(&reply).unwrap();
        assert_eq!(state["id"], id);
        if state["phase"] == "done" || state["phase"] == "failed" {
            return state;
        }
        assert!(
            t.elapsed() < Duration::from_secs(60),
            "the job did not end: {state}"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Growth playback over HTTP: one SVG frame per step of a curve (steps 0
/// to 3, each another drawing, all in one box: the same `viewBox`), one
/// GLB frame per level of a surface grammar with one camera for all; a
/// runaway growth stops at the module limit with a message; an unknown
/// job is 404 and the route needs the token.
#[test]
fn playback_derives_every_step_once_and_keeps_each_frame() {
    let live = start("play", KOCH, false, Limits::default());
    let done = play(&live, KOCH, "");
    assert_eq!(done["phase"], "done", "{done}");
    let frames = done["frames"].as_array().unwrap();
    let steps: Vec<u64> = frames.iter().map(|f| f["step"].as_u64().unwrap()).collect();
    assert_eq!(steps, [0, 1, 2, 3]);
    let svgs: Vec<String> = frames
        .iter()
        .map(|f| {
            assert_eq!(f["kind"], "svg");
            let (status, kind, bytes) = blob(&live, &f["blob"]);
            assert_eq!((status, kind.as_str()), (200, "image/svg+xml"));
            String::from_utf8(bytes).unwrap()
        })
        .collect();
    for w in svgs.windows(2) {
        assert_ne!(w[0], w[1]);
    }
    let view_box = |svg: &str| {
        let at = svg.find("viewBox=\"").unwrap() + 9;
        svg[at..at + svg[at..].find('"').unwrap()].to_string()
    };
    assert!(svgs.iter().all(|s| view_box(s) == view_box(&svgs[0])));

    // A surface grammar: a GLB per level, one camera.
    let mesh = crate::support::root().join("lsystems/meshes/octahedron.obj");
    let grammar = std::fs::read_to_string(crate::support::lsys("surfaces/loop.lsys"))
        .unwrap()
        .replace(
            "mesh: \"../meshes/octahedron.obj\";",
            &format!("mesh: {:?};", mesh.to_str().unwrap()),
        );
    let done = play(&live, &grammar, ", \"steps\": 2");
    assert_eq!(done["phase"], "done", "{done}");
    let frames = done["frames"].as_array().unwrap();
    assert_eq!(frames.len(), 3);
    for (k, f) in frames.iter().enumerate() {
        assert_eq!(f["kind"], "glb");
        assert_eq!(f["scene"]["triangles"], 8 * 4usize.pow(k as u32), "{f}");
        for key in ["eye", "dir", "up", "half_height"] {
            assert_eq!(f["scene"][key], frames[0]["scene"][key], "{key}");
        }
        let (status, _, bytes) = blob(&live, &f["blob"]);
        assert_eq!(status, 200);
        let (doc, _) = glb(&bytes);
        assert_eq!(doc["asset"]["version"], "2.0");
    }

    // A runaway growth stops at the page's module limit.
    let limits = Limits {
        max_modules: 10_000,
        ..Limits::default()
    };
    let tight = start("play-tight", KOCH, false, limits);
    let runaway = "angle: 90;\nderivation length: 40;\nAxiom: F;\nF -> FF\n";
    let failed = play(&tight, runaway, "");
    assert_eq!(failed["phase"], "failed", "{failed}");
    assert_eq!(failed["limit"], "modules", "{failed}");
    assert!(!failed["messages"].as_array().unwrap().is_empty());

    let (status, _) = request(&live, "GET", "/api/play/999999", "");
    assert_eq!(status, 404);
    let addr = &live.addr;
    let (status, _) = send(addr, "GET", "/api/play/1", &[format!("Host: {addr}")], "");
    assert_eq!(status, 403);
}

/// A mesh file on the page: the edited text read as the mesh (a cube's six
/// quads: 12 triangles, 12 polygon edges, 8 corners each with the three
/// normals of its faces, so 24 vertices); a bad line is an error at its
/// place in the text; it has no growth to play.
#[test]
fn a_mesh_file_is_shown_from_its_edited_text() {
    let cube =
        std::fs::read_to_string(crate::support::root().join("lsystems/meshes/cube.obj")).unwrap();
    let dir = scratch("serve-mesh");
    let file = dir.path().join("cube.obj");
    std::fs::write(&file, &cube).unwrap();
    let live = start_at(dir, file, false, Limits::default());
    let r = render(&live, &cube, "");
    assert_eq!(r["ok"], true, "{r}");
    assert_eq!(r["scene"]["triangles"], 12, "{r}");
    let (_, _, bytes) = blob(&live, &r["scene"]["blob"]);
    let (doc, _) = glb(&bytes);
    let prims = doc["meshes"][0]["primitives"].as_array().unwrap();
    let lines: u64 = prims
        .iter()
        .filter(|p| p["mode"] == 1)
        .map(|p| {
            doc["accessors"][p["indices"].as_u64().unwrap() as usize]["count"]
                .as_u64()
                .unwrap()
        })
        .sum();
    assert_eq!(lines, 2 * 12);
    assert_eq!(r["scene"]["vertices"], 24, "{r}");
    let broken = cube.replacen("v ", "v x", 1);
    let r = render(&live, &broken, "");
    assert_eq!(r["ok"], false, "{r}");
    let m = &r["messages"][0];
    assert_eq!(m["program"], true, "{r}");
    let line = cube.lines().position(|l| l.starts_with("v ")).unwrap() + 1;
    assert_eq!(m["line"], line, "{r}");
    let failed = play(&live, &cube, "");
    assert_eq!(failed["phase"], "failed");
    assert!(failed["messages"][0]["message"]
        .as_str()
        .unwrap()
        .contains("no steps to play"));
}
