//! Who may ask `serve` for what (issue 57). The server listens on 127.0.0.1 only, but a page
//! of any other origin open in the same browser can still send it requests: plain `no-cors`
//! POSTs, which the browser sends without asking, and, by DNS rebinding, requests whose
//! `Host` is the attacker's name resolved to 127.0.0.1. So:
//!
//! - every request must name this server in `Host` (127.0.0.1, localhost or [::1], with the
//!   served port when a port is given); a rebound name is refused, for reads too;
//! - a write (any POST) must come from the served origin when the browser says where it
//!   comes from (`Origin`, `Sec-Fetch-Site`), be `application/json` (a cross-origin page can
//!   then only send it after a CORS preflight, which this server never grants), and carry a
//!   page token in [`TOKEN_HEADER`]: one `GET /api/token` hands out per page load, which
//!   another origin cannot read (no CORS headers) and cannot guess (128 random bits).
//!
//! The designer's sessions are named by random ids of the same size and answer only the
//! page that opened them.

use std::collections::VecDeque;
use std::sync::Mutex;

use http::header::{CONTENT_TYPE, HOST, ORIGIN};
use http::HeaderMap;

use super::designer::{refuse, Refusal};

/// The header a write carries its page token in.
pub const TOKEN_HEADER: &str = "x-edo-city-token";
/// Page tokens held at once; a page older than this many later loads reloads for a new one.
const MAX_PAGES: usize = 256;
/// The host names this server answers to (it listens on 127.0.0.1; browsers may say any).
const LOOPBACK: [&str; 3] = ["127.0.0.1", "localhost", "[::1]"];

/// The checks, and the page tokens handed out.
pub struct Guard {
    port: u16,
    pages: Mutex<VecDeque<String>>,
}

impl Guard {
    /// The guard of a server on 127.0.0.1:`port`.
    pub fn new(port: u16) -> Guard {
        Guard {
            port,
            pages: Mutex::new(VecDeque::new()),
        }
    }

    /// Refuses a request whose `Host` is not this server (DNS rebinding).
    pub fn host(&self, headers: &HeaderMap) -> Result<(), Refusal> {
        let host = headers
            .get(HOST)
            .and_then(|h| h.to_str().ok())
            .unwrap_or("");
        match self.is_ours(host, false) {
            true => Ok(()),
            false => Err(refuse(
                403,
                format!(
                    "this server answers only to 127.0.0.1:{port} or localhost:{port}, not to \
                     `{}`: open http://127.0.0.1:{port}/",
                    excerpt(host),
                    port = self.port
                ),
            )),
        }
    }

    /// Whether `host` (a `Host` header, or an origin without its scheme) names this server;
    /// with `exact`, by its port too (an origin names it unless it is 80).
    fn is_ours(&self, host: &str, exact: bool) -> bool {
        let (name, port) = match host.rsplit_once(':') {
            // `[::1]` alone has colons but no port.
            Some((n, p)) if !p.contains(']') => (n, Some(p)),
            _ => (host, None),
        };
        let name_ok = LOOPBACK.iter().any(|l| l.eq_ignore_ascii_case(name));
        let port_ok = match port {
            Some(p) => p.parse::<u16>() == Ok(self.port),
            None => !exact || self.port == 80,
        };
        name_ok && port_ok
    }

    /// A new page token.
    pub fn issue(&self) -> String {
        let token = random_id();
        let mut pages = self.pages.lock().unwrap_or_else(|e| e.into_inner());
        if pages.len() >= MAX_PAGES {
            pages.pop_front();
        }
        pages.push_back(token.clone());
        token
    }

    /// Checks a write request; the page token it carries.
    pub fn write(&self, headers: &HeaderMap) -> Result<String, Refusal> {
        let get = |name: &str| headers.get(name).and_then(|v| v.to_str().ok());
        if let Some(origin) = headers.get(ORIGIN) {
            let origin = origin.to_str().unwrap_or("");
            let ours = origin
                .strip_prefix("http://")
                .is_some_and(|h| self.is_ours(h, true));
            if !ours {
                return Err(refuse(
                    403,
                    format!(
                        "a write from the origin `{}` is refused: only pages of \
                         http://127.0.0.1:{} may change files",
                        excerpt(origin),
                        self.port
                    ),
                ));
            }
        }
        if let Some(site) = get("sec-fetch-site") {
            if site != "same-origin" && site != "none" {
                return Err(refuse(
                    403,
                    format!("a write from another site (`{}`) is refused", excerpt(site)),
                ));
            }
        }
        let json = headers
            .get(CONTENT_TYPE)
            .and_then(|v| v.to_str().ok())
            .and_then(|v| v.split(';').next())
            .is_some_and(|v| v.trim().eq_ignore_ascii_case("application/json"));
        if !json {
            return Err(refuse(
                415,
                "a write's body must be sent as `Content-Type: application/json`".into(),
            ));
        }
        let token = get(TOKEN_HEADER).unwrap_or("");
        let pages = self.pages.lock().unwrap_or_else(|e| e.into_inner());
        match !token.is_empty() && pages.iter().any(|t| t == token) {
            true => Ok(token.to_string()),
            false => Err(refuse(
                403,
                format!(
                    "a write needs this page's token in `{TOKEN_HEADER}` (GET /api/token gives \
                     one): reload the page"
                ),
            )),
        }
    }
}

/// 128 random bits from the operating system's generator, as hex: a token or a session id
/// nobody can guess. (Not the build's `rng`: nothing the server writes depends on it.)
pub fn random_id() -> String {
    use rand::RngExt as _;
    let bits: u128 = rand::rng().random();
    format!("{bits:032x}")
}

/// At most 60 characters of a header, for a message.
fn excerpt(s: &str) -> String {
    match s.char_indices().nth(60) {
        Some((i, _)) => format!("{}...", &s[..i]),
        None => s.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn headers(pairs: &[(&'static str, &str)]) -> HeaderMap {
        let mut h = HeaderMap::new();
        for (k, v) in pairs {
            h.insert(*k, v.parse().unwrap());
        }
        h
    }

    #[test]
    fn only_this_server_by_its_names_and_port() {
        let g = Guard::new(8080);
        for ok in [
            "127.0.0.1:8080",
            "localhost:8080",
            "LOCALHOST",
            "[::1]:8080",
            "[::1]",
        ] {
            assert!(g.host(&headers(&[("host", ok)])).is_ok(), "{ok}");
        }
        for bad in [
            "evil.example",
            "evil.example:8080",
            "127.0.0.1:9090",
            "127.0.0.1.evil",
        ] {
            assert_eq!(g.host(&headers(&[("host", bad)])).unwrap_err().status, 403);
        }
        assert!(g.host(&HeaderMap::new()).is_err(), "no Host");
    }

    #[test]
    fn a_write_needs_our_origin_json_and_a_page_token() {
        let g = Guard::new(8080);
        let token = g.issue();
        assert_eq!(token.len(), 32);
        assert_ne!(token, g.issue(), "each page its own");
        let json = ("content-type", "application/json; charset=utf-8");
        let ok = headers(&[
            json,
            (TOKEN_HEADER, &token),
            ("origin", "http://127.0.0.1:8080"),
        ]);
        assert_eq!(g.write(&ok).unwrap(), token);
        // A script or curl sends no Origin: the token is what counts.
        assert!(g.write(&headers(&[json, (TOKEN_HEADER, &token)])).is_ok());
        let status = |h: &[(&'static str, &str)]| g.write(&headers(h)).unwrap_err().status;
        assert_eq!(
            status(&[
                json,
                (TOKEN_HEADER, &token),
                ("origin", "http://evil.example")
            ]),
            403
        );
        assert_eq!(
            status(&[json, (TOKEN_HEADER, &token), ("origin", "null")]),
            403
        );
        assert_eq!(
            status(&[
                json,
                (TOKEN_HEADER, &token),
                ("origin", "http://127.0.0.1:9")
            ]),
            403
        );
        let cross = ("sec-fetch-site", "cross-site");
        assert_eq!(status(&[json, (TOKEN_HEADER, &token), cross]), 403);
        assert_eq!(
            status(&[("content-type", "text/plain"), (TOKEN_HEADER, &token)]),
            415
        );
        assert_eq!(status(&[(TOKEN_HEADER, &token)]), 415);
        assert_eq!(status(&[json]), 403);
        assert_eq!(status(&[json, (TOKEN_HEADER, "0123")]), 403);
        // Old pages give way to new ones, within a bound.
        for _ in 0..MAX_PAGES {
            g.issue();
        }
        assert_eq!(status(&[json, (TOKEN_HEADER, &token)]), 403);
    }
}
