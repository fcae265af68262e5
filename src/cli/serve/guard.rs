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
//! A token is 128 random bits and their HMAC-SHA256 under a key drawn when the server starts
//! (issue 74): the server checks a token by its MAC, so it keeps no list of them, and no
//! number of tokens asked for by anyone can push an open page's token out (a list of the
//! last 256 could be flushed by 256 cross-site `<img src>` GETs, which locked the page out).
//! The token route itself answers only this server's pages and scripts (`Sec-Fetch-Site`,
//! `Origin`), so another site's GETs are refused before anything is drawn.
//!
//! The designer's sessions are named by random ids of the same size and answer only the
//! page that opened them.

use hmac::{Hmac, Mac};
use http::header::{CONTENT_TYPE, HOST, ORIGIN};
use http::HeaderMap;
use sha2::Sha256;

use super::designer::{refuse, Refusal};

/// The header a write carries its page token in.
pub const TOKEN_HEADER: &str = "x-edo-city-token";
/// The host names this server answers to (it listens on 127.0.0.1; browsers may say any).
const LOOPBACK: [&str; 3] = ["127.0.0.1", "localhost", "[::1]"];

/// The checks, and the key the page tokens are signed with.
pub struct Guard {
    port: u16,
    key: [u8; 32],
}

impl Guard {
    /// The guard of a server on 127.0.0.1:`port`, with a token key of its own.
    pub fn new(port: u16) -> Guard {
        use rand::RngExt as _;
        Guard {
            port,
            key: rand::rng().random(),
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

    /// A new page token: 128 random bits and their MAC, as hex.
    pub fn issue(&self) -> String {
        let nonce = random_id();
        let tag = self.mac(&nonce);
        format!("{nonce}{tag}")
    }

    /// The MAC of a token's random part, as hex (its first 128 bits).
    fn mac(&self, nonce: &str) -> String {
        let mut m = <Hmac<Sha256> as Mac>::new_from_slice(&self.key).expect("any key length");
        m.update(nonce.as_bytes());
        let tag = m.finalize().into_bytes();
        tag[..16].iter().map(|b| format!("{b:02x}")).collect()
    }

    /// Whether `token` is one this server issued (its MAC checked in constant time).
    fn issued(&self, token: &str) -> bool {
        if token.len() != 64 || !token.is_ascii() {
            return false;
        }
        let (nonce, tag) = token.split_at(32);
        let mut m = <Hmac<Sha256> as Mac>::new_from_slice(&self.key).expect("any key length");
        m.update(nonce.as_bytes());
        let Some(tag) = unhex(tag) else {
            return false;
        };
        m.verify_truncated_left(&tag).is_ok()
    }

    /// Refuses a request for a page token that does not come from this server's own pages
    /// (or a script, which says nothing of where it comes from): another site cannot read
    /// the answer, and is not answered at all.
    pub fn page(&self, headers: &HeaderMap) -> Result<(), Refusal> {
        self.same_origin(headers, "a page token")
    }

    /// Refuses a request that says it comes from another origin or site.
    fn same_origin(&self, headers: &HeaderMap, what: &str) -> Result<(), Refusal> {
        if let Some(origin) = headers.get(ORIGIN) {
            let origin = origin.to_str().unwrap_or("");
            let ours = origin
                .strip_prefix("http://")
                .is_some_and(|h| self.is_ours(h, true));
            if !ours {
                return Err(refuse(
                    403,
                    format!(
                        "{what} from the origin `{}` is refused: only pages of \
                         http://127.0.0.1:{} may change files",
                        excerpt(origin),
                        self.port
                    ),
                ));
            }
        }
        if let Some(site) = headers.get("sec-fetch-site") {
            let site = site.to_str().unwrap_or("");
            if site != "same-origin" && site != "none" {
                return Err(refuse(
                    403,
                    format!("{what} from another site (`{}`) is refused", excerpt(site)),
                ));
            }
        }
        Ok(())
    }

    /// Checks a write request; the page token it carries.
    pub fn write(&self, headers: &HeaderMap) -> Result<String, Refusal> {
        let get = |name: &str| headers.get(name).and_then(|v| v.to_str().ok());
        self.same_origin(headers, "a write")?;
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
        match self.issued(token) {
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

/// The bytes of a hex string, if it is one.
fn unhex(s: &str) -> Option<Vec<u8>> {
    (0..s.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(s.get(i..i + 2)?, 16).ok())
        .collect()
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
        assert_eq!(token.len(), 64);
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
        // No number of tokens handed out since pushes an open page's out (issue 74).
        for _ in 0..10_000 {
            g.issue();
        }
        assert!(g.write(&ok).is_ok());
        // A token of this shape that the server did not sign, or signed by another server.
        let forged = format!("{}{}", &token[..32], "0".repeat(32));
        assert_eq!(status(&[json, (TOKEN_HEADER, &forged)]), 403);
        let other = Guard::new(8080).issue();
        assert_eq!(status(&[json, (TOKEN_HEADER, &other)]), 403);
        assert_eq!(status(&[json, (TOKEN_HEADER, &"zz".repeat(32))]), 403);
        assert_eq!(
            status(&[json, (TOKEN_HEADER, "é".repeat(32).as_str())]),
            403
        );
    }

    #[test]
    fn a_page_token_goes_only_to_this_servers_pages() {
        let g = Guard::new(8080);
        // The page's own fetch, and a script's (which says nothing of where it comes from).
        assert!(g
            .page(&headers(&[("sec-fetch-site", "same-origin")]))
            .is_ok());
        assert!(g.page(&HeaderMap::new()).is_ok());
        // Another site's `<img src>` or a top-level GET from another site's link.
        for cross in ["cross-site", "same-site"] {
            let h = headers(&[("sec-fetch-site", cross)]);
            assert_eq!(g.page(&h).unwrap_err().status, 403, "{cross}");
        }
        let h = headers(&[("origin", "http://evil.example")]);
        assert_eq!(g.page(&h).unwrap_err().status, 403);
    }
}
