//! `subgram serve` over HTTP (issue 18): the page's API derives and draws
//! an edited text, reports errors at their lines, stops runaway rules at
//! its limits, serves nothing from the disk, writes nothing unless saving
//! is on, and answers malformed requests with an error. The browser test
//! of the page itself is tests/browser/serve.py (run by .ci/run).

use std::io::{Read, Write};
use std::net::TcpStream;
use std::path::Path;
use std::time::Duration;

use subgram::serve::{Limits, ServeOptions, Server};
use tempfile::TempDir;

use crate::support::scratch;

/// A server on a free port in a thread of its own, serving a copy of
/// `program` in a fresh folder; its address and the folder, removed when
/// the caller drops it.
fn start(name: &str, program: &str, save: bool, limits: Limits) -> (String, TempDir) {
    let dir = scratch(&format!("serve-{name}"));
    let file = dir.path().join("prog.lsys");
    std::fs::write(&file, program).unwrap();
    let server = Server::bind(ServeOptions {
        path: file,
        port: 0,
        save,
        limits,
        defines: Vec::new(),
        double: false,
    })
    .unwrap();
    let url = server.url();
    std::thread::spawn(move || server.run());
    let addr = url
        .trim_start_matches("http://")
        .trim_end_matches('/')
        .to_string();
    (addr, dir)
}

/// Sends raw bytes, returns the status code and the body.
fn raw(addr: &str, request: &[u8]) -> (u16, String) {
    let mut s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(30))).unwrap();
    s.write_all(request).unwrap();
    let mut reply = Vec::new();
    let _ = s.read_to_end(&mut reply);
    let reply = String::from_utf8_lossy(&reply).into_owned();
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

fn request(addr: &str, method: &str, path: &str, body: &str) -> (u16, String) {
    let r = format!(
        "{method} {path} HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\nContent-Length: {}\r\n\r\n{body}",
        body.len()
    );
    raw(addr, r.as_bytes())
}

fn render(addr: &str, text: &str, extra: &str) -> serde_json::Value {
    let body = format!(
        "{{\"text\": {}{extra}}}",
        serde_json::to_string(text).unwrap()
    );
    let (status, reply) = request(addr, "POST", "/api/render", &body);
    assert_eq!(status, 200, "{reply}");
    serde_json::from_str(&reply).unwrap()
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
    let (addr, tmp) = start("draw", KOCH, false, Limits::default());
    let dir = tmp.path();
    let before = files(dir);
    let (status, page) = request(&addr, "GET", "/", "");
    assert_eq!(status, 200);
    assert!(page.contains("/app.js") && page.contains("<textarea"));
    for asset in ["/app.js", "/app.css"] {
        assert_eq!(request(&addr, "GET", asset, "").0, 200, "{asset}");
    }
    let (status, source) = request(&addr, "GET", "/api/source", "");
    assert_eq!(status, 200);
    let source: serde_json::Value = serde_json::from_str(&source).unwrap();
    assert_eq!(source["text"], KOCH);
    assert_eq!(source["save"], false);

    // The text as it stands, then an edit: another picture. 3 steps of
    // the snowflake are 3 · 4³ segments, 2 steps 3 · 4².
    let three = render(&addr, KOCH, "");
    assert_eq!(three["ok"], true, "{three}");
    let svg3 = three["svg"].as_str().unwrap();
    assert!(svg3.starts_with("<svg"));
    let two = render(&addr, KOCH, ", \"steps\": 2");
    let svg2 = two["svg"].as_str().unwrap();
    assert_ne!(svg2, svg3);
    let segments = |svg: &str| svg.matches('L').count();
    assert_eq!(segments(svg3), 3 * 64);
    assert_eq!(segments(svg2), 3 * 16);
    // A -D value from the page's fields.
    let defined =
        "#define N 2\nangle: 60;\nderivation length: N;\nAxiom: F--F--F;\nF -> F+F--F+F\n";
    let r = render(&addr, defined, ", \"defines\": [\"N=1\"]");
    assert_eq!(segments(r["svg"].as_str().unwrap()), 3 * 4);

    // An error: its line and column in the edited text.
    let bad = KOCH.replace("F -> F+F", "F -> F+F @");
    let r = render(&addr, &bad, "");
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
    };
    let (addr, _dir) = start("limits", KOCH, false, limits);
    let t = std::time::Instant::now();
    let r = render(
        &addr,
        "module A;\nderivation length: 60;\nAxiom: A;\nA -> A A\n",
        "",
    );
    assert_eq!(
        (r["ok"].as_bool(), r["limit"].as_str()),
        (Some(false), Some("modules")),
        "{r}"
    );
    let r = render(
        &addr,
        "module A;\nderivation length: 2;\nAxiom: A;\nA : { int i = 0; while (1) { i = i + 1; } produce A; }\n",
        "",
    );
    assert_eq!(r["ok"], false, "{r}");
    assert!(matches!(r["limit"].as_str(), Some("time" | "loop")), "{r}");
    let r = render(&addr, KOCH, ", \"steps\": 51");
    assert_eq!(r["limit"], "steps", "{r}");
    assert!(t.elapsed() < Duration::from_secs(20));
    // Still there.
    assert_eq!(render(&addr, KOCH, "")["ok"], true);
}

#[test]
fn malformed_requests_get_errors_and_nothing_from_the_disk_is_served() {
    let (addr, tmp) = start("bad", KOCH, false, Limits::default());
    let dir = tmp.path();
    std::fs::write(dir.join("secret.txt"), "not for the page").unwrap();
    for path in [
        "/secret.txt",
        "/../secret.txt",
        "/prog.lsys",
        "/%2e%2e/Cargo.toml",
        "/api/../secret.txt",
        "/etc/passwd",
    ] {
        let (status, body) = request(&addr, "GET", path, "");
        assert_eq!(status, 404, "{path}: {body}");
        assert!(
            !body.contains("not for the page") && !body.contains("F--F"),
            "{path}"
        );
    }
    assert_eq!(request(&addr, "PUT", "/", "").0, 405);
    assert_eq!(request(&addr, "GET", "/api/render", "").0, 405);
    let (status, body) = request(&addr, "POST", "/api/render", "{not json");
    assert_eq!(status, 400, "{body}");
    let (status, _) = request(&addr, "POST", "/api/render", "{\"steps\": 2}");
    assert_eq!(status, 400);
    // A body announced larger than the limit is refused before it is read.
    let big = format!(
        "POST /api/render HTTP/1.1\r\nHost: x\r\nConnection: close\r\nContent-Length: {}\r\n\r\n{{}}",
        subgram::serve::MAX_BODY + 1
    );
    assert_eq!(raw(&addr, big.as_bytes()).0, 413);
    // Not HTTP at all.
    let (status, _) = raw(&addr, b"\x00\x01garbage\r\n\r\n");
    assert!(status == 400 || status == 0, "{status}");
    // Saving is off.
    let (status, body) = request(&addr, "POST", "/api/save", "{\"text\": \"x\"}");
    assert_eq!(status, 403, "{body}");
    assert_eq!(
        std::fs::read_to_string(dir.join("prog.lsys")).unwrap(),
        KOCH
    );
    // And the server still answers.
    assert_eq!(render(&addr, KOCH, "")["ok"], true);
}

#[test]
fn with_save_the_page_writes_the_program_back_and_nothing_else() {
    let (addr, tmp) = start("save", KOCH, true, Limits::default());
    let dir = tmp.path();
    let edited = KOCH.replace("derivation length: 3", "derivation length: 2");
    let body = format!("{{\"text\": {}}}", serde_json::to_string(&edited).unwrap());
    let (status, reply) = request(&addr, "POST", "/api/save", &body);
    assert_eq!(status, 200, "{reply}");
    assert_eq!(
        std::fs::read_to_string(dir.join("prog.lsys")).unwrap(),
        edited
    );
    let names: Vec<String> = files(dir).into_iter().map(|(n, _)| n).collect();
    assert_eq!(names, ["prog.lsys"], "no temporary file left");
    let (_, source) = request(&addr, "GET", "/api/source", "");
    assert!(source.contains("derivation length: 2"));
}

/// A surface grammar on the page: the shaded mesh, one polygon per face
/// of the subdivided octahedron (8 · 4² after two Loop steps), its base
/// mesh read from the disk as the grammar names it.
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
    let (addr, _dir) = start("surface", &grammar, false, Limits::default());
    let r = render(&addr, &grammar, ", \"steps\": 2");
    assert_eq!(r["ok"], true, "{r}");
    assert_eq!(
        r["svg"].as_str().unwrap().matches("<polygon").count(),
        8 * 16
    );
}
