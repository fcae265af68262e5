use std::io::{Read, Write};
use std::net::TcpStream;

use super::*;

/// A server on a free port answering `/file` with `path` (as `.mtl` text), `/` with "hello"
/// and anything else with 404; its port.
fn start(limits: Limits, path: PathBuf) -> u16 {
    let listener = std::net::TcpListener::bind(("127.0.0.1", 0)).unwrap();
    let port = listener.local_addr().unwrap().port();
    let handler: Handler = Arc::new(move |call: &Call| match call.target.as_str() {
        "/echo" if call.post => Answer::Bytes {
            status: 200,
            content_type: "text/plain; charset=utf-8",
            body: call.body.clone(),
        },
        _ if call.post => Answer::NotAllowed { allow: "GET, HEAD" },
        "/file" => Answer::File {
            path: path.clone(),
            content_type: "text/plain; charset=utf-8",
        },
        "/" => Answer::text(200, "hello".into()),
        other => Answer::text(404, format!("not found: {other}")),
    });
    std::thread::spawn(move || serve(listener, handler, limits));
    port
}

fn connect(port: u16) -> TcpStream {
    let s = TcpStream::connect(("127.0.0.1", port)).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(60))).unwrap();
    s
}

/// Sends `head` (one request, the connection closed after it) and reads the whole answer.
fn ask(port: u16, head: &str) -> String {
    let mut s = connect(port);
    s.write_all(head.as_bytes()).unwrap();
    let mut text = Vec::new();
    s.read_to_end(&mut text).unwrap();
    String::from_utf8_lossy(&text).into_owned()
}

/// Whether the server closed `s` (a read gives end of file or a reset, not a timeout).
fn closed(s: &mut TcpStream) -> bool {
    let mut buf = [0u8; 64 * 1024];
    loop {
        match s.read(&mut buf) {
            Ok(0) => return true,
            Ok(_) => continue,
            Err(e) => {
                return !matches!(
                    e.kind(),
                    io::ErrorKind::WouldBlock | io::ErrorKind::TimedOut
                )
            }
        }
    }
}

fn file_of(bytes: usize) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("a.mtl");
    std::fs::write(&path, vec![b'x'; bytes]).unwrap();
    (dir, path)
}

#[test]
fn files_keep_our_types_and_tower_http_answers_head_and_ranges() {
    let (_dir, path) = file_of(1000);
    let port = start(Limits::default(), path);
    let get = ask(
        port,
        "GET /file HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n",
    );
    assert!(get.starts_with("HTTP/1.1 200 OK"), "{get}");
    let lower = get.to_ascii_lowercase();
    assert!(
        lower.contains("content-type: text/plain; charset=utf-8"),
        "{get}"
    );
    assert!(lower.contains("cache-control: no-cache"), "{get}");
    assert!(lower.contains("content-length: 1000"), "{get}");
    assert!(get.ends_with(&"x".repeat(1000)));
    let head = ask(
        port,
        "HEAD /file HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n",
    );
    assert!(
        head.to_ascii_lowercase().contains("content-length: 1000"),
        "{head}"
    );
    assert!(head.ends_with("\r\n\r\n"), "no body: {head}");
    let range = ask(
        port,
        "GET /file HTTP/1.1\r\nHost: x\r\nRange: bytes=10-19\r\nConnection: close\r\n\r\n",
    );
    assert!(range.starts_with("HTTP/1.1 206"), "{range}");
    assert!(range.ends_with("\r\n\r\nxxxxxxxxxx"), "{range}");
    let post = ask(
        port,
        "POST / HTTP/1.1\r\nHost: x\r\nContent-Length: 0\r\nConnection: close\r\n\r\n",
    );
    assert!(post.starts_with("HTTP/1.1 405"), "{post}");
    assert!(
        post.to_ascii_lowercase().contains("allow: get, head"),
        "{post}"
    );
    let put = ask(
        port,
        "PUT / HTTP/1.1\r\nHost: x\r\nContent-Length: 0\r\nConnection: close\r\n\r\n",
    );
    assert!(put.starts_with("HTTP/1.1 405"), "{put}");
    let echo = ask(
        port,
        "POST /echo HTTP/1.1\r\nHost: x\r\nContent-Length: 5\r\nConnection: close\r\n\r\nhello",
    );
    assert!(
        echo.starts_with("HTTP/1.1 200") && echo.ends_with("\r\n\r\nhello"),
        "{echo}"
    );
    let big = MAX_BODY + 1;
    let head = format!(
        "POST /echo HTTP/1.1\r\nHost: x\r\nContent-Length: {big}\r\nConnection: close\r\n\r\n{}",
        "x".repeat(big)
    );
    let too_big = ask(port, &head);
    assert!(too_big.starts_with("HTTP/1.1 413"), "{too_big}");
    let missing = ask(
        port,
        "GET /nothing HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n",
    );
    assert!(missing.starts_with("HTTP/1.1 404"), "{missing}");
    assert!(missing.ends_with("not found: /nothing"), "{missing}");
    let long = format!(
        "GET / HTTP/1.1\r\nHost: x\r\nX: {}\r\n\r\n",
        "a".repeat(2 * MAX_HEAD)
    );
    let refused = ask(port, &long);
    assert!(refused.starts_with("HTTP/1.1 431"), "{refused}");
    let junk = ask(port, "hello\r\n\r\n");
    assert!(junk.starts_with("HTTP/1.1 400"), "{junk}");
}

/// Keep-alive: several requests on one connection, each answered.
#[test]
fn one_connection_carries_many_requests() {
    let (_dir, path) = file_of(10);
    let port = start(Limits::default(), path);
    let mut s = connect(port);
    for _ in 0..3 {
        s.write_all(b"GET / HTTP/1.1\r\nHost: x\r\n\r\n").unwrap();
    }
    s.write_all(b"GET /file HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n")
        .unwrap();
    let mut text = String::new();
    s.read_to_string(&mut text).unwrap();
    assert_eq!(text.matches("HTTP/1.1 200 OK").count(), 4, "{text}");
}

/// More idle connections than the server holds: the ones idle longest are closed to make
/// room, and a real request is answered at once.
#[test]
fn idle_connections_never_keep_a_request_out() {
    let (_dir, path) = file_of(10);
    let limits = Limits {
        max_connections: 32,
        ..Limits::default()
    };
    let port = start(limits, path);
    let mut idle: Vec<TcpStream> = (0..200).map(|_| connect(port)).collect();
    let answer = ask(
        port,
        "GET / HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n",
    );
    assert!(answer.ends_with("hello"), "{answer}");
    // All but the newest 32 (at most) were let go; reading the first ones sees it.
    let short = Some(Duration::from_millis(50));
    let mut let_go = 0;
    for s in &mut idle {
        s.set_read_timeout(short).unwrap();
        let_go += closed(s) as usize;
    }
    assert!(
        let_go >= 200 - 32,
        "{let_go} of 200 idle connections closed"
    );
}

/// A client trickling its request head a byte at a time is let go when the head's time is
/// up, and one that stops reading an answer when no byte has moved for `stall`.
#[test]
fn slow_clients_are_let_go() {
    let (_dir, path) = file_of(64 << 20);
    let limits = Limits {
        head: Duration::from_millis(500),
        stall: Duration::from_millis(500),
        idle: Duration::from_secs(30),
        ..Limits::default()
    };
    let port = start(limits, path);
    let mut slow = connect(port);
    let mut sent = 0;
    let gone = loop {
        if slow.write_all(b"G").is_err() || sent > 100 {
            break true;
        }
        sent += 1;
        std::thread::sleep(Duration::from_millis(100));
        slow.set_read_timeout(Some(Duration::from_millis(1)))
            .unwrap();
        let mut b = [0u8; 256];
        match slow.read(&mut b) {
            Ok(0) => break true,
            Ok(_) => break true,
            Err(e)
                if matches!(
                    e.kind(),
                    io::ErrorKind::WouldBlock | io::ErrorKind::TimedOut
                ) => {}
            Err(_) => break true,
        }
    };
    assert!(gone && sent <= 100, "held after {sent} bytes");

    // 64 MiB asked for and never read: the socket buffers fill, then nothing moves.
    let mut reader = connect(port);
    reader
        .write_all(b"GET /file HTTP/1.1\r\nHost: x\r\n\r\n")
        .unwrap();
    std::thread::sleep(Duration::from_secs(3));
    let mut got = 0usize;
    let mut buf = vec![0u8; 1 << 20];
    loop {
        match reader.read(&mut buf) {
            Ok(0) | Err(_) => break,
            Ok(n) => got += n,
        }
    }
    assert!(
        got < 64 << 20,
        "the whole file came: the stalled answer was not closed"
    );
    // And the server still answers.
    let answer = ask(
        port,
        "GET / HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n",
    );
    assert!(answer.ends_with("hello"), "{answer}");
}

/// Clients trickling POST bodies a byte at a time (issue 57: 40 of them kept every slot of
/// 32 for minutes): a body has its own deadline, and a connection waiting for one is idle,
/// closable to make room, so a real request is answered.
#[test]
fn slow_bodies_never_keep_a_request_out() {
    let (_dir, path) = file_of(10);
    let limits = Limits {
        max_connections: 32,
        body: Duration::from_millis(500),
        ..Limits::default()
    };
    let port = start(limits, path);
    let mut slow: Vec<TcpStream> = (0..40)
        .map(|_| {
            let mut s = connect(port);
            s.write_all(b"POST /echo HTTP/1.1\r\nHost: x\r\nContent-Length: 100\r\n\r\nx")
                .unwrap();
            s
        })
        .collect();
    // A byte more each, as a trickle would.
    for s in &mut slow {
        let _ = s.write_all(b"y");
    }
    let answer = ask(
        port,
        "GET / HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n",
    );
    assert!(answer.ends_with("hello"), "{answer}");
    // A trickler still open past its body's deadline gets 408 and is closed.
    std::thread::sleep(Duration::from_secs(1));
    let last = slow.last_mut().unwrap();
    let mut got = String::new();
    let _ = last.read_to_string(&mut got);
    assert!(got.is_empty() || got.starts_with("HTTP/1.1 408"), "{got}");
}
