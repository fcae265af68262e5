//! The HTTP side of `edo-city serve`: hyper's HTTP/1.1 on a tokio runtime, files sent by
//! tower-http's `ServeFile` (HEAD, ranges, conditional requests), with a bound on the
//! connections held and a time limit on every way a client can hold one.
//!
//! The server before this one gave each connection a thread and two file descriptors with no
//! limit: with `ulimit -n 1024`, about 680 idle local connections made a real request time
//! out while the accept loop spun on "too many open files", and a client sending a byte every
//! 20 s was held forever. Here a connection costs a task and one descriptor, and:
//! - at most [`Limits::max_connections`] are held (by default half the process's descriptor
//!   limit); a new one past it closes the connection that has been idle longest, so idle
//!   connections can never keep a request out; when every one is answering, the new one is
//!   closed (the browser retries);
//! - a request head must arrive whole within [`Limits::head`] of the connection's opening or
//!   its last answer, however slowly it trickles (hyper's header timer: an idle keep-alive
//!   connection goes then too);
//! - a POST's body must arrive whole within [`Limits::body`] of its head, and the connection
//!   counts as idle (closable to make room) until it has: 40 clients trickling a body a
//!   byte at a time kept every slot for minutes before;
//! - a connection with no request in flight and no byte either way for [`Limits::idle`] (a
//!   backstop to hyper's timer), or answering one with no byte moved for [`Limits::stall`]
//!   (a client that stopped reading), is closed;
//! - an accept error (out of descriptors) closes the longest-idle connection and waits a
//!   moment instead of spinning.

use std::collections::BTreeMap;
use std::convert::Infallible;
use std::io;
use std::path::PathBuf;
use std::pin::Pin;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::task::{Context, Poll};
use std::time::{Duration, Instant};

use http::header::{HeaderValue, ALLOW, CACHE_CONTROL, CONTENT_TYPE};
use http::{Method, Request, Response, StatusCode};
use http_body_util::combinators::UnsyncBoxBody;
use http_body_util::{BodyExt, Full};
use hyper::body::{Bytes, Incoming};
use hyper_util::rt::{TokioIo, TokioTimer};
use tokio::io::{AsyncRead, AsyncWrite, ReadBuf};
use tokio::net::{TcpListener, TcpStream};
use tokio::sync::Notify;
use tower::ServiceExt;
use tower_http::services::ServeFile;

/// What `serve` answers a GET or HEAD of a URL with.
pub enum Answer {
    /// Bytes made in memory (`/hypotheses.json`, a 404's text).
    Bytes {
        status: u16,
        content_type: &'static str,
        body: Vec<u8>,
    },
    /// A file, already checked to lie inside a served directory, with its MIME type.
    File {
        path: PathBuf,
        content_type: &'static str,
    },
    /// 405: the route takes only these methods (`GET, HEAD`).
    NotAllowed { allow: &'static str },
    /// An error with its status: sent as `{"error": message}` to a client that speaks JSON,
    /// else as text.
    Refused { status: u16, message: String },
}

impl Answer {
    /// A plain-text answer with a status.
    pub fn text(status: u16, text: String) -> Answer {
        Answer::Bytes {
            status,
            content_type: "text/plain; charset=utf-8",
            body: text.into_bytes(),
        }
    }
}

/// One request as the handler sees it.
pub struct Call {
    /// A POST (else a GET or HEAD).
    pub post: bool,
    /// The request target as sent (`/h/0/tileset.json?x=1`).
    pub target: String,
    /// Its headers (`Host`, `Origin`, `Content-Type`: what the handler checks a write by).
    pub headers: http::HeaderMap,
    /// A POST's body (at most [`MAX_BODY`] bytes); empty otherwise.
    pub body: Vec<u8>,
}

/// The handler `serve` calls for every GET, HEAD and POST.
pub type Handler = Arc<dyn Fn(&Call) -> Answer + Send + Sync>;

/// The longest POST body read; longer is refused with 413.
pub const MAX_BODY: usize = 64 * 1024;

/// The bounds of the server.
#[derive(Debug, Clone, Copy)]
pub struct Limits {
    /// Connections held at once.
    pub max_connections: usize,
    /// Time for a whole request head.
    pub head: Duration,
    /// Time for a whole POST body, from its head.
    pub body: Duration,
    /// Time a connection may stay silent with no request in flight.
    pub idle: Duration,
    /// Time an answer may go without a byte moved.
    pub stall: Duration,
}

/// The longest request head (request line and headers); longer is refused with 431.
const MAX_HEAD: usize = 64 * 1024;

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_connections: (open_files_limit() / 2).clamp(16, 10_000),
            head: Duration::from_secs(10),
            body: Duration::from_secs(10),
            idle: Duration::from_secs(30),
            stall: Duration::from_secs(60),
        }
    }
}

/// The process's soft limit of open files (1024 when it has none or cannot be read).
fn open_files_limit() -> usize {
    let limit = rustix::process::getrlimit(rustix::process::Resource::Nofile);
    limit
        .current
        .map_or(1024, |n| usize::try_from(n).unwrap_or(usize::MAX))
}

/// Answers every connection of `listener` until the process ends.
pub fn serve(listener: std::net::TcpListener, handler: Handler, limits: Limits) -> io::Result<()> {
    listener.set_nonblocking(true)?;
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()?;
    runtime.block_on(async move {
        let listener = TcpListener::from_std(listener)?;
        let held = Arc::new(Held::default());
        tokio::spawn(sweep(held.clone(), limits));
        loop {
            let stream = match listener.accept().await {
                Ok((stream, _)) => stream,
                Err(_) => {
                    // Out of descriptors, most likely: free one, and do not spin.
                    held.close_longest_idle();
                    tokio::time::sleep(Duration::from_millis(10)).await;
                    continue;
                }
            };
            if held.len() >= limits.max_connections && !held.close_longest_idle() {
                drop(stream);
                continue;
            }
            let _ = stream.set_nodelay(true);
            let (id, conn) = held.add();
            let (handler, held) = (handler.clone(), held.clone());
            tokio::spawn(async move {
                connection(stream, conn, handler, limits).await;
                held.remove(id);
            });
        }
    })
}

/// One connection's requests, until the client closes, a limit is passed, or it is closed
/// to make room.
async fn connection(stream: TcpStream, conn: Arc<Conn>, handler: Handler, limits: Limits) {
    let io = TokioIo::new(Watched {
        inner: stream,
        conn: conn.clone(),
    });
    let service = hyper::service::service_fn({
        let conn = conn.clone();
        move |req| respond(req, handler.clone(), conn.clone(), limits)
    });
    let mut builder = hyper::server::conn::http1::Builder::new();
    builder
        .timer(TokioTimer::new())
        .header_read_timeout(limits.head)
        .max_buf_size(MAX_HEAD);
    let served = builder.serve_connection(io, service);
    tokio::select! {
        _ = served => {}
        _ = conn.close.notified() => {}
    }
}

type Body = UnsyncBoxBody<Bytes, io::Error>;

/// The response to one request; the connection counts as answering from when its head and
/// body are in until its answer is sent (or dropped).
async fn respond(
    req: Request<Incoming>,
    handler: Handler,
    conn: Arc<Conn>,
    limits: Limits,
) -> Result<Response<Body>, Infallible> {
    let post = req.method() == Method::POST;
    let json = wants_json(req.headers());
    if req.method() != Method::GET && req.method() != Method::HEAD && !post {
        let busy = Busy::new(conn);
        return Ok(not_allowed("GET, HEAD, POST").map(|b| busy.keep(b)));
    }
    let target = req
        .uri()
        .path_and_query()
        .map_or("/", |p| p.as_str())
        .to_string();
    let (req, body) = if post {
        let (parts, incoming) = req.into_parts();
        let collect = http_body_util::Limited::new(incoming, MAX_BODY).collect();
        match tokio::time::timeout(limits.body, collect).await {
            Ok(Ok(b)) => (Request::from_parts(parts, None), b.to_bytes().to_vec()),
            Ok(Err(_)) => {
                let r = refusal(
                    413,
                    &format!("a request body is at most {MAX_BODY} bytes"),
                    json,
                );
                return Ok(r.map(|b| Busy::new(conn).keep(b)));
            }
            Err(_) => {
                let text = format!(
                    "the request body did not arrive within {} s",
                    limits.body.as_secs_f64()
                );
                let mut r = refusal(408, &text, json);
                r.headers_mut()
                    .insert(http::header::CONNECTION, HeaderValue::from_static("close"));
                return Ok(r.map(|b| Busy::new(conn).keep(b)));
            }
        }
    } else {
        let (parts, incoming) = req.into_parts();
        (Request::from_parts(parts, Some(incoming)), Vec::new())
    };
    let busy = Busy::new(conn);
    let headers = req.headers().clone();
    let call = Call {
        post,
        target,
        headers,
        body,
    };
    // The handler looks at the file system (links resolved): off the runtime's thread.
    let answer = tokio::task::spawn_blocking(move || handler(&call))
        .await
        .unwrap_or_else(|_| Answer::Refused {
            status: 500,
            message: "internal error: the server met a bug (please report it); nothing \
                      was written"
                .into(),
        });
    let response = match answer {
        Answer::Bytes {
            status,
            content_type,
            body,
        } => bytes(status, content_type, body),
        Answer::Refused { status, message } => refusal(status, &message, json),
        Answer::NotAllowed { allow } => not_allowed(allow),
        Answer::File { path, content_type } => match req.into_parts() {
            (parts, Some(incoming)) => {
                file(Request::from_parts(parts, incoming), path, content_type).await
            }
            // A file is never the answer to a POST.
            (_, None) => not_allowed("GET, HEAD"),
        },
    };
    Ok(response.map(|b| busy.keep(b)))
}

/// Whether the client speaks JSON (it sent JSON, or asks for it): its errors are then
/// `{"error": ...}`, else plain text.
fn wants_json(headers: &http::HeaderMap) -> bool {
    let has = |name: http::header::HeaderName| {
        headers
            .get(name)
            .and_then(|v| v.to_str().ok())
            .is_some_and(|v| v.to_ascii_lowercase().contains("application/json"))
    };
    has(CONTENT_TYPE) || has(http::header::ACCEPT)
}

/// An error answer: `{"error": message}` to a client that speaks JSON, else the text.
fn refusal(status: u16, message: &str, json: bool) -> Response<Body> {
    match json {
        true => bytes(
            status,
            "application/json",
            serde_json::to_vec(&serde_json::json!({ "error": message })).unwrap_or_default(),
        ),
        false => bytes(
            status,
            "text/plain; charset=utf-8",
            format!("{message}\n").into_bytes(),
        ),
    }
}

/// 405 with the methods the route takes.
fn not_allowed(allow: &'static str) -> Response<Body> {
    let text = format!("only {allow} here\n");
    let mut r = bytes(405, "text/plain; charset=utf-8", text.into_bytes());
    r.headers_mut()
        .insert(ALLOW, HeaderValue::from_static(allow));
    r
}

/// A response of bytes in memory.
fn bytes(status: u16, content_type: &'static str, body: Vec<u8>) -> Response<Body> {
    let mut r = Response::new(
        Full::new(Bytes::from(body))
            .map_err(|never| match never {})
            .boxed_unsync(),
    );
    *r.status_mut() = StatusCode::from_u16(status).unwrap_or(StatusCode::INTERNAL_SERVER_ERROR);
    let h = r.headers_mut();
    h.insert(CONTENT_TYPE, HeaderValue::from_static(content_type));
    h.insert(CACHE_CONTROL, HeaderValue::from_static("no-cache"));
    r
}

/// A file by tower-http, with our MIME type (tower-http guesses by extension, and has none
/// for `.mtl`) and no caching without asking (a rebuilt city shows at once).
async fn file(req: Request<Incoming>, path: PathBuf, content_type: &'static str) -> Response<Body> {
    match ServeFile::new(path).oneshot(req).await {
        Ok(r) => {
            let ok = r.status().is_success();
            let mut r = r.map(|b| b.boxed_unsync());
            let h = r.headers_mut();
            if ok {
                h.insert(CONTENT_TYPE, HeaderValue::from_static(content_type));
            }
            h.insert(CACHE_CONTROL, HeaderValue::from_static("no-cache"));
            r
        }
        Err(never) => match never {},
    }
}

/// One connection as the server holds it.
struct Conn {
    /// Requests being answered (their bodies not yet sent).
    busy: AtomicUsize,
    /// Milliseconds since `Held::start` of the last byte read or written.
    last: AtomicU64,
    /// Closes the connection (its task stops serving it and drops the socket).
    close: Notify,
    start: Instant,
}

impl Conn {
    fn touch(&self) {
        self.last
            .store(self.start.elapsed().as_millis() as u64, Ordering::Relaxed);
    }
}

/// Marks its connection as answering while it lives: it travels inside the response body.
struct Busy(Arc<Conn>);

impl Busy {
    fn new(conn: Arc<Conn>) -> Busy {
        conn.busy.fetch_add(1, Ordering::Relaxed);
        conn.touch();
        Busy(conn)
    }

    /// `body`, carrying this mark until it is sent or dropped.
    fn keep(self, body: Body) -> Body {
        Kept { body, _busy: self }.boxed_unsync()
    }
}

/// A body with its connection's [`Busy`] mark; its length still known (a `Content-Length`,
/// not chunks).
struct Kept {
    body: Body,
    _busy: Busy,
}

impl hyper::body::Body for Kept {
    type Data = Bytes;
    type Error = io::Error;

    fn poll_frame(
        mut self: Pin<&mut Self>,
        cx: &mut Context<'_>,
    ) -> Poll<Option<Result<hyper::body::Frame<Bytes>, io::Error>>> {
        Pin::new(&mut self.body).poll_frame(cx)
    }

    fn is_end_stream(&self) -> bool {
        self.body.is_end_stream()
    }

    fn size_hint(&self) -> hyper::body::SizeHint {
        self.body.size_hint()
    }
}

impl Drop for Busy {
    fn drop(&mut self) {
        self.0.busy.fetch_sub(1, Ordering::Relaxed);
        self.0.touch();
    }
}

/// The connections held.
struct Held {
    start: Instant,
    next: AtomicU64,
    conns: Mutex<BTreeMap<u64, Arc<Conn>>>,
}

impl Default for Held {
    fn default() -> Self {
        Held {
            start: Instant::now(),
            next: AtomicU64::new(0),
            conns: Mutex::new(BTreeMap::new()),
        }
    }
}

impl Held {
    fn conns(&self) -> std::sync::MutexGuard<'_, BTreeMap<u64, Arc<Conn>>> {
        // A panic while holding the lock leaves the map as it was: still usable.
        self.conns.lock().unwrap_or_else(|e| e.into_inner())
    }

    fn len(&self) -> usize {
        self.conns().len()
    }

    fn add(&self) -> (u64, Arc<Conn>) {
        let id = self.next.fetch_add(1, Ordering::Relaxed);
        let conn = Arc::new(Conn {
            busy: AtomicUsize::new(0),
            last: AtomicU64::new(0),
            close: Notify::new(),
            start: self.start,
        });
        conn.touch();
        self.conns().insert(id, conn.clone());
        (id, conn)
    }

    fn remove(&self, id: u64) {
        self.conns().remove(&id);
    }

    /// Closes the connection idle longest (none answering a request); whether there was one.
    fn close_longest_idle(&self) -> bool {
        let mut conns = self.conns();
        let idle = conns
            .iter()
            .filter(|(_, c)| c.busy.load(Ordering::Relaxed) == 0)
            .min_by_key(|(id, c)| (c.last.load(Ordering::Relaxed), **id))
            .map(|(id, _)| *id);
        match idle.and_then(|id| conns.remove(&id)) {
            Some(c) => {
                c.close.notify_one();
                true
            }
            None => false,
        }
    }
}

/// Closes, every quarter of the shortest limit, the connections past theirs.
async fn sweep(held: Arc<Held>, limits: Limits) {
    let every = (limits.idle.min(limits.stall) / 4).max(Duration::from_millis(50));
    loop {
        tokio::time::sleep(every).await;
        let now = held.start.elapsed().as_millis() as u64;
        let mut conns = held.conns();
        conns.retain(|_, c| {
            let quiet = Duration::from_millis(now.saturating_sub(c.last.load(Ordering::Relaxed)));
            let limit = match c.busy.load(Ordering::Relaxed) {
                0 => limits.idle,
                _ => limits.stall,
            };
            let keep = quiet <= limit;
            if !keep {
                c.close.notify_one();
            }
            keep
        });
    }
}

/// A socket that notes in its connection when a byte last moved.
struct Watched {
    inner: TcpStream,
    conn: Arc<Conn>,
}

impl AsyncRead for Watched {
    fn poll_read(
        mut self: Pin<&mut Self>,
        cx: &mut Context<'_>,
        buf: &mut ReadBuf<'_>,
    ) -> Poll<io::Result<()>> {
        let before = buf.filled().len();
        let r = Pin::new(&mut self.inner).poll_read(cx, buf);
        if buf.filled().len() > before {
            self.conn.touch();
        }
        r
    }
}

impl AsyncWrite for Watched {
    fn poll_write(
        mut self: Pin<&mut Self>,
        cx: &mut Context<'_>,
        buf: &[u8],
    ) -> Poll<io::Result<usize>> {
        let r = Pin::new(&mut self.inner).poll_write(cx, buf);
        if matches!(r, Poll::Ready(Ok(n)) if n > 0) {
            self.conn.touch();
        }
        r
    }

    fn poll_write_vectored(
        mut self: Pin<&mut Self>,
        cx: &mut Context<'_>,
        bufs: &[io::IoSlice<'_>],
    ) -> Poll<io::Result<usize>> {
        let r = Pin::new(&mut self.inner).poll_write_vectored(cx, bufs);
        if matches!(r, Poll::Ready(Ok(n)) if n > 0) {
            self.conn.touch();
        }
        r
    }

    fn is_write_vectored(&self) -> bool {
        self.inner.is_write_vectored()
    }

    fn poll_flush(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        Pin::new(&mut self.inner).poll_flush(cx)
    }

    fn poll_shutdown(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<io::Result<()>> {
        Pin::new(&mut self.inner).poll_shutdown(cx)
    }
}

#[cfg(test)]
mod tests;
