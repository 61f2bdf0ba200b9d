//! The HTTP/1.1 of `subgram serve`, as little of it as the page needs: one
//! request a connection (`Connection: close` on every reply), its head at
//! most [`MAX_HEAD`] bytes, a body only with a `Content-Length`, and
//! deadlines for the client's reading and writing, so that no client holds
//! a thread for long by being slow. Anything else gets an error status.
//!
//! (tiny_http, which the server used before, answers every connection on a
//! thread of a pool of its own whose hand-over can leave a new connection
//! waiting behind busy ones, reads what is left of a body when a request
//! is dropped, and has no deadlines: a blocked request there could keep
//! others waiting.)

use std::io::{self, ErrorKind, Read, Write};
use std::net::{Shutdown, TcpStream};
use std::time::{Duration, Instant};

use super::{failure, Head, Reply};

/// The longest request head: the request line and the headers.
pub const MAX_HEAD: usize = 32 << 10;
/// The most header lines.
const MAX_HEADERS: usize = 100;
/// How long a client may take to send its whole request, head and body.
pub const REQUEST_TIMEOUT: Duration = Duration::from_secs(20);
/// How long writing a reply may take.
const WRITE_TIMEOUT: Duration = Duration::from_secs(10);
/// How long the server waits, after its reply, for the client to close.
const CLOSE_TIMEOUT: Duration = Duration::from_secs(2);

/// A connection's input with a deadline: each read waits at most until
/// then, and one after it fails with `TimedOut`.
pub struct Timed<'a> {
    pub stream: &'a TcpStream,
    pub deadline: Instant,
}

impl Read for Timed<'_> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let left = self.deadline.saturating_duration_since(Instant::now());
        if left.is_zero() {
            return Err(io::Error::new(
                ErrorKind::TimedOut,
                "the client took too long to send its request",
            ));
        }
        self.stream.set_read_timeout(Some(left))?;
        match (&*self.stream).read(buf) {
            Err(e) if e.kind() == ErrorKind::WouldBlock => Err(io::Error::new(
                ErrorKind::TimedOut,
                "the client took too long to send its request",
            )),
            r => r,
        }
    }
}

/// Reads a request's head: the head, and the bytes read past it (the
/// start of the body). The head is parsed by httparse (the parser of
/// hyper, strict by default: no folded lines, no control characters, no
/// space before a header's colon); the server asks more of it: a target
/// that is a path, HTTP/1.1 or 1.0, UTF-8 text.
pub fn read_head(input: &mut dyn Read) -> Result<(Head, Vec<u8>), Reply> {
    let mut buf = Vec::with_capacity(1024);
    let mut chunk = [0u8; 4096];
    loop {
        if let Some(parsed) = parse_head(&buf)? {
            return Ok(parsed);
        }
        if buf.len() > MAX_HEAD {
            return Err(too_long());
        }
        match input.read(&mut chunk) {
            Ok(0) => return Err(failure(400, "the request ended before its head did")),
            Ok(n) => buf.extend_from_slice(&chunk[..n]),
            Err(e) if e.kind() == ErrorKind::Interrupted => {}
            Err(e) if e.kind() == ErrorKind::TimedOut => return Err(failure(408, &e.to_string())),
            Err(e) => return Err(failure(400, &format!("cannot read the request: {e}"))),
        }
    }
}

fn too_long() -> Reply {
    failure(
        431,
        &format!("the request's head is longer than {} KiB", MAX_HEAD >> 10),
    )
}

/// The head at the start of `buf` and the bytes after it, or `None` when
/// `buf` does not hold the whole head yet.
fn parse_head(buf: &[u8]) -> Result<Option<(Head, Vec<u8>)>, Reply> {
    let bad = |what: &str| failure(400, &format!("a malformed request: {what}"));
    let mut headers = [httparse::EMPTY_HEADER; MAX_HEADERS];
    let mut req = httparse::Request::new(&mut headers);
    let end = match req.parse(buf) {
        Ok(httparse::Status::Partial) => return Ok(None),
        Ok(httparse::Status::Complete(end)) => end,
        Err(httparse::Error::TooManyHeaders) => {
            return Err(failure(
                431,
                &format!("the request has more than {MAX_HEADERS} headers"),
            ))
        }
        Err(httparse::Error::Version) => {
            // `METHOD /PATH HTTP/2.0`: a version this server does not
            // speak; anything else there is a malformed line.
            let line = buf.split(|&b| b == b'\n').next().unwrap_or(&[]);
            let parts: Vec<&[u8]> = line.trim_ascii_end().split(|&b| b == b' ').collect();
            return Err(match parts.as_slice() {
                [_, _, v] if v.starts_with(b"HTTP/") => {
                    failure(505, "the server speaks HTTP/1.1 and HTTP/1.0 only")
                }
                _ => bad("the request line is not `METHOD /PATH HTTP/1.1`"),
            });
        }
        Err(e) => return Err(bad(&e.to_string())),
    };
    if end > MAX_HEAD {
        return Err(too_long());
    }
    let (Some(method), Some(url)) = (req.method, req.path) else {
        return Err(bad("the request line is not `METHOD /PATH HTTP/1.1`"));
    };
    if !url.starts_with('/') {
        return Err(bad("the target is not a path"));
    }
    let mut list = Vec::with_capacity(req.headers.len());
    for h in req.headers.iter() {
        let value =
            std::str::from_utf8(h.value).map_err(|_| bad("a header's value is not UTF-8"))?;
        if value.chars().any(|c| c.is_control() && c != '\t') {
            return Err(bad("a control character in a header"));
        }
        list.push((
            h.name.to_string(),
            value.trim_matches([' ', '\t']).to_string(),
        ));
    }
    let head = Head {
        method: method.to_string(),
        url: url.to_string(),
        headers: list,
    };
    Ok(Some((head, buf[end..].to_vec())))
}

/// Writes a reply, with its length and `Connection: close`; the body is
/// left out for a HEAD request.
pub fn write_reply(out: &mut dyn Write, reply: &Reply, head_only: bool) -> io::Result<()> {
    let mut text = format!("HTTP/1.1 {} {}\r\n", reply.status, reason(reply.status));
    for (name, value) in &reply.headers {
        // The values are the server's own; one with a line break would
        // split the reply, so it is left out.
        if !value.chars().any(|c| c.is_control()) {
            text += &format!("{name}: {value}\r\n");
        }
    }
    text += &format!(
        "Content-Length: {}\r\nConnection: close\r\n\r\n",
        reply.body.len()
    );
    out.write_all(text.as_bytes())?;
    if !head_only {
        out.write_all(&reply.body)?;
    }
    out.flush()
}

fn reason(status: u16) -> &'static str {
    match status {
        200 => "OK",
        400 => "Bad Request",
        403 => "Forbidden",
        404 => "Not Found",
        405 => "Method Not Allowed",
        408 => "Request Timeout",
        411 => "Length Required",
        413 => "Content Too Large",
        415 => "Unsupported Media Type",
        431 => "Request Header Fields Too Large",
        500 => "Internal Server Error",
        501 => "Not Implemented",
        503 => "Service Unavailable",
        505 => "HTTP Version Not Supported",
        _ => "",
    }
}

/// Sets the connection's write deadline.
pub fn prepare(stream: &TcpStream) {
    let _ = stream.set_nodelay(true);
    let _ = stream.set_write_timeout(Some(WRITE_TIMEOUT));
}

/// Ends a connection after its reply: no more output, then what the
/// client still sends is read and dropped until it closes (at most
/// [`CLOSE_TIMEOUT`] and a few MiB), so that closing does not reset the
/// connection before the client has read the reply.
pub fn close(stream: &TcpStream) {
    let _ = stream.shutdown(Shutdown::Write);
    let mut rest = Timed {
        stream,
        deadline: Instant::now() + CLOSE_TIMEOUT,
    };
    let _ = io::copy(
        &mut (&mut rest).take(super::MAX_BODY as u64 + MAX_HEAD as u64),
        &mut io::sink(),
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    fn head(text: &str) -> Result<Head, u16> {
        let (h, rest) = read_head(&mut text.as_bytes()).map_err(|r| r.status)?;
        assert!(rest.is_empty() || text.contains("\r\n\r\nbody") || text.contains("\n\nbody"));
        Ok(h)
    }

    #[test]
    fn heads_are_read_strictly() {
        let h = head("GET /x?y HTTP/1.1\r\nHost: a:1\r\nX-A:  b c \t\r\n\r\n").unwrap();
        assert_eq!((h.method.as_str(), h.url.as_str()), ("GET", "/x?y"));
        assert_eq!(
            h.headers,
            [("Host".into(), "a:1".into()), ("X-A".into(), "b c".into())]
        );
        let (h, rest) = read_head(&mut &b"POST / HTTP/1.0\nA: b\n\nbody"[..]).unwrap();
        assert_eq!((h.method.as_str(), rest.as_slice()), ("POST", &b"body"[..]));
        for (text, status) in [
            ("GET / HTTP/1.1\r\n", 400),
            ("GET /  HTTP/1.1\r\n\r\n", 400),
            ("GET http://a/ HTTP/1.1\r\n\r\n", 400),
            ("GET / HTTP/2.0\r\n\r\n", 505),
            ("GET / HTTP/1.1 x\r\n\r\n", 400),
            ("G(T / HTTP/1.1\r\n\r\n", 400),
            ("GET / HTTP/1.1\r\nHost a\r\n\r\n", 400),
            ("GET / HTTP/1.1\r\nHost : a\r\n\r\n", 400),
            ("GET / HTTP/1.1\r\nA: b\r\n c\r\n\r\n", 400),
            ("GET / HTTP/1.1\r\nA: b\x01\r\n\r\n", 400),
            ("\r\n\r\n", 400),
        ] {
            assert_eq!(head(text).err(), Some(status), "{text:?}");
        }
        let long = format!("GET / HTTP/1.1\r\nA: {}\r\n\r\n", "b".repeat(MAX_HEAD));
        assert_eq!(head(&long).err(), Some(431));
        let many = format!(
            "GET / HTTP/1.1\r\n{}\r\n",
            "A: b\r\n".repeat(MAX_HEADERS + 1)
        );
        assert_eq!(head(&many).err(), Some(431));
    }

    #[test]
    fn replies_say_their_length_and_close() {
        let r = failure(404, "no");
        let mut out = Vec::new();
        write_reply(&mut out, &r, false).unwrap();
        let text = String::from_utf8(out).unwrap();
        assert!(text.starts_with("HTTP/1.1 404 Not Found\r\n"), "{text}");
        assert!(text.contains("Connection: close\r\n"));
        assert!(text.ends_with(&format!(
            "Content-Length: {}\r\nConnection: close\r\n\r\n{}",
            r.body.len(),
            String::from_utf8_lossy(&r.body)
        )));
        let mut out = Vec::new();
        write_reply(&mut out, &r, true).unwrap();
        assert!(String::from_utf8(out).unwrap().ends_with("\r\n\r\n"));
    }
}
