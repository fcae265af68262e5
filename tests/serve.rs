//! `edo-city serve` as a visitor's browser and a hostile client meet it: its routes and MIME
//! types, twenty spellings of a way out of its directories refused, and under `ulimit -n
//! 1024` two thousand idle connections and a client trickling its request a byte at a time,
//! while a real request is still answered (issue 39).

mod common;

use std::io::{Read, Write};
use std::net::TcpStream;
use std::path::Path;
use std::process::Command;
use std::time::Duration;

use common::{build_ok, fixture};

/// `edo-city serve` of `out` with a viewer of a few files, under `ulimit -n 1024`; the
/// server and its port.
fn serve(dir: &Path, out: &Path) -> (common::Server, u16) {
    let viewer = dir.join("viewer");
    std::fs::create_dir_all(viewer.join("node_modules/three/build")).unwrap();
    std::fs::write(
        viewer.join("index.html"),
        "<!doctype html><title>edo</title>",
    )
    .unwrap();
    std::fs::write(viewer.join("main.js"), "export {};").unwrap();
    std::fs::write(
        viewer.join("node_modules/three/build/three.module.js"),
        "export const REVISION = '1';",
    )
    .unwrap();
    std::fs::write(dir.join("secret.txt"), "not to be served").unwrap();
    std::os::unix::fs::symlink(dir.join("secret.txt"), out.join("link.txt")).unwrap();
    let mut cmd = Command::new("sh");
    cmd.arg("-c")
        .arg("ulimit -n 1024 && exec \"$0\" serve --port 0 --viewer \"$1\" \"$2\"")
        .arg(assert_cmd::cargo::cargo_bin("edo-city"))
        .arg(&viewer)
        .arg(out);
    let (server, url) = common::start_server(cmd);
    let port = url
        .trim_start_matches("http://127.0.0.1:")
        .trim_end_matches('/')
        .parse()
        .unwrap_or_else(|_| panic!("no port in {url}"));
    (server, port)
}

fn connect(port: u16) -> TcpStream {
    let s = TcpStream::connect(("127.0.0.1", port)).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(60))).unwrap();
    s
}

/// A GET of `target` on a connection of its own: status and the response as text.
fn get(port: u16, target: &str) -> (u16, String) {
    common::http(port, "GET", target, "")
}

/// Whether the server closed `s`: end of file or a reset, not a read that timed out.
fn closed(s: &mut TcpStream) -> bool {
    s.set_read_timeout(Some(Duration::from_millis(20))).unwrap();
    let mut b = [0u8; 1024];
    match s.read(&mut b) {
        Ok(n) => n == 0 || !b.starts_with(b"HTTP/1.1 200"),
        Err(e) => !matches!(
            e.kind(),
            std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
        ),
    }
}

fn header<'a>(response: &'a str, name: &str) -> Option<&'a str> {
    response.lines().find_map(|l| {
        let (k, v) = l.split_once(':')?;
        k.eq_ignore_ascii_case(name).then(|| v.trim())
    })
}

/// Raises this process's open-files limit to what 2,000 connections need, if it may.
fn room_for(files: u64) -> u64 {
    use rustix::process::{getrlimit, setrlimit, Resource, Rlimit};
    let now = getrlimit(Resource::Nofile);
    let want = now.maximum.map_or(files, |max| files.min(max));
    if now.current.is_some_and(|c| c < want) {
        let _ = setrlimit(
            Resource::Nofile,
            Rlimit {
                current: Some(want),
                maximum: now.maximum,
            },
        );
    }
    getrlimit(Resource::Nofile).current.unwrap_or(u64::MAX)
}

#[test]
fn serve_keeps_its_routes_refuses_ways_out_and_outlasts_idle_and_slow_clients() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("edo");
    build_ok(&fixture("kyoto-small"), &out, &["--quiet", "--no-plan"]);
    let (_server, port) = serve(dir.path(), &out);

    // Routes and MIME types.
    let tile = std::fs::read_dir(out.join("tiles"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .find(|n| n.ends_with(".glb"))
        .unwrap();
    let expect = [
        ("/", "text/html; charset=utf-8"),
        ("/viewer/main.js", "text/javascript; charset=utf-8"),
        (
            "/node_modules/three/build/three.module.js",
            "text/javascript; charset=utf-8",
        ),
        ("/hypotheses.json", "application/json"),
        ("/h/0/tileset.json", "application/json"),
        (&format!("/h/0/tiles/{tile}"), "model/gltf-binary"),
    ];
    for (target, mime) in expect {
        let (status, text) = get(port, target);
        assert_eq!(status, 200, "{target}: {text}");
        assert_eq!(header(&text, "content-type"), Some(mime), "{target}");
    }
    let glb = std::fs::read(out.join("tiles").join(&tile)).unwrap();
    let (_, text) = get(port, &format!("/h/0/tiles/{tile}"));
    assert_eq!(
        header(&text, "content-length"),
        Some(glb.len().to_string().as_str())
    );

    // Twenty spellings of a way out: each 404 (or 400), never the file.
    let ways_out = [
        "/h/0/../../secret.txt",
        "/h/0/%2e%2e/%2e%2e/secret.txt",
        "/h/0/%2E%2E/%2E%2E/secret.txt",
        "/h/0/..%2f..%2fsecret.txt",
        "/h/0/..%2F..%2Fsecret.txt",
        "/h/0/%2e%2e%2f%2e%2e%2fsecret.txt",
        "/h/0/..%5c..%5csecret.txt",
        "/h/0/..\\..\\secret.txt",
        "/h/0/link.txt",
        "/h/0//etc/passwd",
        "/h/0/%2fetc%2fpasswd",
        "/viewer/../../secret.txt",
        "/viewer/%2e%2e/%2e%2e/secret.txt",
        "/node_modules/../../secret.txt",
        "/node_modules/%2e%2e/%2e%2e/secret.txt",
        "/h/1/tileset.json",
        "/h/-1/tileset.json",
        "/h/0/tiles/",
        "/h/0/%00secret.txt",
        "/../secret.txt",
    ];
    for target in ways_out {
        let (status, text) = get(port, target);
        assert!(matches!(status, 400 | 404), "{target}: {text}");
        assert!(!text.contains("not to be served"), "{target}: {text}");
        assert!(!text.contains("root:"), "{target}: {text}");
    }

    // Two thousand idle connections (the server may hold 1024 files): a real request is
    // still answered, and the connections idle longest were let go.
    let files = room_for(2_200);
    let n = 2_000.min(files.saturating_sub(200) as usize);
    assert!(n >= 1_500, "this process may open only {files} files");
    let mut idle: Vec<TcpStream> = (0..n).map(|_| connect(port)).collect();
    let (status, text) = get(port, "/hypotheses.json");
    assert_eq!(status, 200, "{text}");
    // The server holds at most half its 1024 files in connections: the oldest half of ours
    // were closed to make room.
    let let_go = idle[..n / 2].iter_mut().map(closed).filter(|c| *c).count();
    assert_eq!(let_go, n / 2, "of the {} oldest idle connections", n / 2);
    drop(idle);

    // A client trickling its request head a byte a second is let go (the head has 10 s),
    // and the server answers meanwhile.
    let mut slow = connect(port);
    let mut held = 0;
    for byte in b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Slow: "
        .iter()
        .cycle()
        .take(40)
    {
        if slow.write_all(&[*byte]).is_err() {
            break;
        }
        if closed(&mut slow) {
            break;
        }
        held += 1;
        std::thread::sleep(Duration::from_secs(1));
    }
    assert!(held < 40, "a client trickling its head was held {held} s");
    assert_eq!(get(port, "/").0, 200);
}
