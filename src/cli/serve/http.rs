//! The HTTP/1.1 side of `edo-city serve`, on `std::net` alone: one thread per connection, one
//! request per connection (`Connection: close`), GET and HEAD.
//!
//! Why not a server crate: `tiny_http` 0.12 (used before) hands each connection to a pool
//! thread for the connection's whole life, and its pool can queue a new connection while every
//! thread sits on a keep-alive one (two connections accepted before the one idle thread wakes
//! both count on it). Chromium opens six connections at once for the viewer's modules, so now
//! and then a module never came and the page never loaded (a 120 s `page.goto` timeout in CI;
//! eight concurrent keep-alive clients left 1 request of 240 unanswered). A thread per
//! connection and no keep-alive cannot queue anything; on 127.0.0.1 the reconnects cost
//! nothing, and an async runtime for a static file server would be out of proportion.

use std::fs::File;
use std::io::{self, BufRead, BufReader, Read, Write};
use std::net::{Shutdown, TcpListener, TcpStream};
use std::sync::Arc;
use std::time::Duration;

/// The longest request head read (request line and headers); longer is refused with 431.
const MAX_HEAD: usize = 64 * 1024;

/// How long a connection may stay silent: a browser's speculative connection that never sends
/// a request frees its thread after this.
const IDLE: Duration = Duration::from_secs(30);

/// A request: what the handler needs of it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Request {
    /// `GET`, `HEAD`, ...
    pub method: String,
    /// The request target as sent (`/h/0/tileset.json?x=1`).
    pub url: String,
}

/// What a response carries.
pub enum Body {
    Bytes(Vec<u8>),
    File(File),
}

/// A response: status, extra headers (Content-Length and Connection are added), body.
pub struct Response {
    pub status: u16,
    pub headers: Vec<(&'static str, String)>,
    pub body: Body,
}

impl Response {
    /// A plain-text response with a status.
    pub fn text(status: u16, text: String) -> Response {
        Response {
            status,
            headers: vec![("Content-Type", "text/plain; charset=utf-8".into())],
            body: Body::Bytes(text.into_bytes()),
        }
    }
}

/// The handler `serve` calls for every request.
pub type Handler = Arc<dyn Fn(&Request) -> Response + Send + Sync>;

/// Answers every connection of `listener` until the process ends. A connection that cannot get
/// a thread is closed (the browser retries); an accept error is skipped.
pub fn serve(listener: TcpListener, handler: Handler) {
    for stream in listener.incoming() {
        let Ok(stream) = stream else { continue };
        let handler = handler.clone();
        // A failed spawn drops the connection: nothing else to do with it.
        let _ = std::thread::Builder::new()
            .name("edo-city-http".into())
            .spawn(move || {
                let _ = connection(stream, &*handler);
            });
    }
}

/// One connection: read a request, answer it, close.
fn connection(
    stream: TcpStream,
    handler: &(dyn Fn(&Request) -> Response + Send + Sync),
) -> io::Result<()> {
    stream.set_read_timeout(Some(IDLE))?;
    stream.set_write_timeout(Some(IDLE))?;
    let _ = stream.set_nodelay(true);
    let mut reader = BufReader::new(stream.try_clone()?);
    let (response, head_only) = match read_head(&mut reader)? {
        Head::Request(req) if req.method == "GET" || req.method == "HEAD" => {
            (handler(&req), req.method == "HEAD")
        }
        Head::Request(_) => (Response::text(405, "only GET and HEAD\n".into()), false),
        Head::TooLong => (Response::text(431, "request head too long\n".into()), false),
        Head::Malformed => (Response::text(400, "not an HTTP request\n".into()), false),
        Head::Closed => return Ok(()),
    };
    let mut out = io::BufWriter::new(&stream);
    write_response(&mut out, response, head_only)?;
    out.flush()?;
    drop(out);
    stream.shutdown(Shutdown::Write)
}

/// What the start of a connection held.
#[derive(Debug, PartialEq, Eq)]
enum Head {
    Request(Request),
    /// Over `MAX_HEAD` bytes without the blank line.
    TooLong,
    /// No request line of three words.
    Malformed,
    /// The client closed (or stayed silent past `IDLE`) before a request.
    Closed,
}

/// Reads the request line and skips the headers up to the blank line.
fn read_head(reader: &mut impl BufRead) -> io::Result<Head> {
    let mut line = Vec::new();
    let mut first: Option<Vec<u8>> = None;
    let mut read = 0usize;
    loop {
        line.clear();
        let n = match reader
            .by_ref()
            .take((MAX_HEAD - read + 1) as u64)
            .read_until(b'\n', &mut line)
        {
            Ok(n) => n,
            Err(e)
                if matches!(
                    e.kind(),
                    io::ErrorKind::WouldBlock | io::ErrorKind::TimedOut
                ) =>
            {
                return Ok(Head::Closed)
            }
            Err(e) => return Err(e),
        };
        if n == 0 {
            return Ok(if first.is_none() {
                Head::Closed
            } else {
                Head::Malformed
            });
        }
        read += n;
        if read > MAX_HEAD {
            return Ok(Head::TooLong);
        }
        let trimmed = line.strip_suffix(b"\n").unwrap_or(&line);
        let trimmed = trimmed.strip_suffix(b"\r").unwrap_or(trimmed);
        match &first {
            // Blank lines before the request line are allowed (RFC 9112 2.2).
            None if trimmed.is_empty() => {}
            None => first = Some(trimmed.to_vec()),
            Some(_) if trimmed.is_empty() => break,
            Some(_) => {}
        }
    }
    let first = String::from_utf8_lossy(first.as_deref().unwrap_or_default()).into_owned();
    let mut words = first.split(' ');
    match (words.next(), words.next(), words.next(), words.next()) {
        (Some(method), Some(url), Some(version), None)
            if !method.is_empty() && url.starts_with('/') && version.starts_with("HTTP/1.") =>
        {
            Ok(Head::Request(Request {
                method: method.to_string(),
                url: url.to_string(),
            }))
        }
        _ => Ok(Head::Malformed),
    }
}

/// The reason phrase of the statuses we send.
fn reason(status: u16) -> &'static str {
    match status {
        200 => "OK",
        400 => "Bad Request",
        404 => "Not Found",
        405 => "Method Not Allowed",
        431 => "Request Header Fields Too Large",
        _ => "Internal Server Error",
    }
}

/// Status line, headers, and the body unless `head_only`.
fn write_response(out: &mut impl Write, r: Response, head_only: bool) -> io::Result<()> {
    let (len, body): (u64, Box<dyn Read>) = match r.body {
        Body::Bytes(b) => (b.len() as u64, Box::new(io::Cursor::new(b))),
        Body::File(f) => (f.metadata()?.len(), Box::new(f)),
    };
    write!(out, "HTTP/1.1 {} {}\r\n", r.status, reason(r.status))?;
    for (k, v) in &r.headers {
        write!(out, "{k}: {v}\r\n")?;
    }
    if r.status == 405 {
        write!(out, "Allow: GET, HEAD\r\n")?;
    }
    write!(out, "Content-Length: {len}\r\nConnection: close\r\n\r\n")?;
    if !head_only {
        // Exactly the length announced, even if the file grew meanwhile.
        io::copy(&mut body.take(len), out)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn head(text: &str) -> Head {
        read_head(&mut io::Cursor::new(text.as_bytes().to_vec())).unwrap()
    }

    #[test]
    fn request_lines_are_read_and_bad_ones_named() {
        assert_eq!(
            head("GET /h/0/a.glb?x=1 HTTP/1.1\r\nHost: x\r\n\r\n"),
            Head::Request(Request {
                method: "GET".into(),
                url: "/h/0/a.glb?x=1".into()
            })
        );
        assert_eq!(
            head("\r\nHEAD / HTTP/1.0\n\n"),
            Head::Request(Request {
                method: "HEAD".into(),
                url: "/".into()
            })
        );
        assert_eq!(head(""), Head::Closed);
        assert_eq!(head("GET / HTTP/1.1\r\nHost: x\r\n"), Head::Malformed);
        assert_eq!(head("hello\r\n\r\n"), Head::Malformed);
        assert_eq!(head("GET x HTTP/1.1\r\n\r\n"), Head::Malformed);
        let long = format!("GET / HTTP/1.1\r\nX: {}\r\n\r\n", "a".repeat(MAX_HEAD));
        assert_eq!(head(&long), Head::TooLong);
    }

    #[test]
    fn responses_carry_their_length_and_close() {
        let mut out = Vec::new();
        write_response(
            &mut out,
            Response::text(404, "not found: /x\n".into()),
            false,
        )
        .unwrap();
        let text = String::from_utf8(out).unwrap();
        assert!(text.starts_with("HTTP/1.1 404 Not Found\r\n"), "{text}");
        assert!(text.contains("Content-Length: 14\r\nConnection: close\r\n\r\nnot found: /x\n"));
        let mut out = Vec::new();
        write_response(&mut out, Response::text(200, "abc".into()), true).unwrap();
        let text = String::from_utf8(out).unwrap();
        assert!(
            text.ends_with("Content-Length: 3\r\nConnection: close\r\n\r\n"),
            "{text}"
        );
    }

    /// Many clients at once, each holding its connection open until all are answered: with a
    /// pooled server some would wait on the others; here every one is answered.
    #[test]
    fn concurrent_connections_are_all_answered() {
        let listener = TcpListener::bind(("127.0.0.1", 0)).unwrap();
        let port = listener.local_addr().unwrap().port();
        let handler: Handler = Arc::new(|r: &Request| Response::text(200, r.url.clone()));
        std::thread::spawn(move || serve(listener, handler));
        for round in 0..5 {
            let mut socks: Vec<TcpStream> = (0..12)
                .map(|_| TcpStream::connect(("127.0.0.1", port)).unwrap())
                .collect();
            for (i, s) in socks.iter_mut().enumerate() {
                s.set_read_timeout(Some(Duration::from_secs(60))).unwrap();
                write!(
                    s,
                    "GET /{round}/{i} HTTP/1.1\r\nConnection: keep-alive\r\n\r\n"
                )
                .unwrap();
            }
            for (i, s) in socks.iter_mut().enumerate() {
                let mut text = String::new();
                s.read_to_string(&mut text).unwrap();
                assert!(text.starts_with("HTTP/1.1 200 OK"), "{text}");
                assert!(text.ends_with(&format!("\r\n\r\n/{round}/{i}")), "{text}");
            }
        }
    }
}
