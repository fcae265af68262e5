//! The garden designer of `edo-city serve --designs` against what another origin, a careless
//! script or a second server sends (issue 57): writes need the served host and origin, JSON
//! and a page token; sessions answer only their page; picks, sizes and the designs file are
//! bounded; a FIFO swapped in for the designs file is refused while the server goes on; two
//! servers keeping into one file lose nothing. Every refusal is JSON `{error}` and writes
//! nothing.

mod common;

use std::path::Path;

use common::designer::{ask, ask_with, built, built_with, error, page, post, serve};
use common::read_json;
use serde_json::{json, Value};

/// A raw POST of `body` to `route` with exactly `headers` (and the JSON type unless given).
fn raw(port: u16, headers: &[(&str, &str)], route: &str, body: &Value) -> (u16, String) {
    error(ask_with(
        port,
        headers,
        "POST",
        &format!("/api/gardens/{route}"),
        &body.to_string(),
    ))
}

#[test]
fn writes_need_this_servers_host_and_origin_json_and_the_pages_token() {
    let dir = tempfile::tempdir().unwrap();
    let (out, _) = built(dir.path());
    let designs = dir.path().join("designs.json");
    let (server, port) = serve(dir.path(), &out, Some(&designs));
    let tok = page(port);
    let open = json!({"lot": "343"});
    let with = |extra: &[(&'static str, &'static str)]| -> Vec<(&str, String)> {
        let mut h: Vec<(&str, String)> = vec![("X-Edo-City-Token", tok.clone())];
        h.extend(extra.iter().map(|(k, v)| (*k, v.to_string())));
        h
    };
    let send = |h: Vec<(&str, String)>| {
        let h: Vec<(&str, &str)> = h.iter().map(|(k, v)| (*k, v.as_str())).collect();
        raw(port, &h, "open", &open)
    };
    // DNS rebinding: the attacker's name resolved to 127.0.0.1.
    let (status, e) = send(with(&[
        ("Host", "evil.example"),
        ("Origin", "http://evil.example"),
    ]));
    assert_eq!(status, 403, "{e}");
    assert!(e.contains("answers only to 127.0.0.1"), "{e}");
    // Reads too.
    let (status, _) = ask_with(
        port,
        &[("Host", "evil.example:80")],
        "GET",
        "/api/token",
        "",
    );
    assert_eq!(status, 403);
    let (status, e) = send(with(&[("Origin", "http://evil.example")]));
    assert_eq!(status, 403, "{e}");
    assert!(e.contains("origin `http://evil.example` is refused"), "{e}");
    let (status, e) = send(with(&[("Sec-Fetch-Site", "cross-site")]));
    assert_eq!(status, 403, "{e}");
    let (status, e) = send(with(&[("Content-Type", "text/plain")]));
    assert_eq!(status, 415, "{e}");
    let (status, e) = raw(port, &[], "open", &open);
    assert_eq!(status, 403, "{e}");
    assert!(e.contains("page's token"), "{e}");
    let (status, _) = raw(port, &[("X-Edo-City-Token", "0123")], "open", &open);
    assert_eq!(status, 403);

    // The page's own origin opens a session named by 128 random bits.
    let origin = format!("http://127.0.0.1:{port}");
    let h = [
        ("X-Edo-City-Token", tok.as_str()),
        ("Origin", origin.as_str()),
    ];
    let (status, s) = ask_with(port, &h, "POST", "/api/gardens/open", &open.to_string());
    assert_eq!(status, 200, "{s}");
    let id = s["session"].as_str().unwrap().to_string();
    assert_eq!(id.len(), 32);
    assert!(id.chars().all(|c| c.is_ascii_hexdigit()));
    // Another page cannot drive it, nor keep its candidates.
    let other = page(port);
    assert_ne!(other, tok);
    let keep = json!({"session": id, "generation": 0, "candidate": 0});
    let (status, e) = error(post(port, &other, "keep", keep.clone()));
    assert_eq!(status, 404, "{e}");
    assert!(!designs.exists(), "nothing written by any of them");
    let (status, _) = post(port, &tok, "keep", keep);
    assert_eq!(status, 200);
    assert!(designs.is_file());
    drop(server);
}

#[test]
fn what_a_visitor_sends_is_bounded_and_answered_in_json() {
    let dir = tempfile::tempdir().unwrap();
    let (out, _) = built(dir.path());
    let designs = dir.path().join("designs.json");
    let (server, port) = serve(dir.path(), &out, Some(&designs));
    let tok = page(port);
    let (_, s) = post(port, &tok, "open", json!({"lot": "343"}));
    let id = s["session"].as_str().unwrap().to_string();
    let (status, e) = error(post(
        port,
        &tok,
        "next",
        json!({"session": id, "generation": 0, "picks": [1, 1]}),
    ));
    assert_eq!(status, 400);
    assert!(e.contains("picked twice"), "{e}");
    // 32,000 zeros: refused, not kept in the history.
    let zeros = vec![0; 32_000];
    let (status, _) = post(
        port,
        &tok,
        "next",
        json!({"session": id, "generation": 0, "picks": zeros}),
    );
    assert_eq!(status, 400);
    // A long session of real picks keeps a small design.
    for g in 0..180 {
        let (status, v) = post(
            port,
            &tok,
            "next",
            json!({"session": id, "generation": g, "picks": [0, 1, 2, 3, 4, 5]}),
        );
        assert_eq!(status, 200, "{v}");
    }
    let (status, _) = post(
        port,
        &tok,
        "keep",
        json!({"session": id, "generation": 180, "candidate": 0}),
    );
    assert_eq!(status, 200);
    let size = std::fs::metadata(&designs).unwrap().len();
    assert!(
        size < 200_000,
        "{size} bytes for one design of 180 generations"
    );
    // A body past the bound: JSON too.
    let big = format!("{{\"lot\": \"{}\"}}", "x".repeat(70_000));
    let (status, v) = ask_with(
        port,
        &[("X-Edo-City-Token", &tok)],
        "POST",
        "/api/gardens/open",
        &big,
    );
    assert_eq!(status, 413);
    assert!(v["error"].as_str().unwrap().contains("at most"), "{v}");
    drop(server);

    // A garden of 5 mm in the report (edited, or damaged): a 422 in JSON, not a panic.
    let mut report = read_json(&out.join("report.json"));
    for g in report["gardens"].as_array_mut().unwrap() {
        g["size"] = json!([0.005, 0.005]);
    }
    std::fs::write(out.join("report.json"), report.to_string()).unwrap();
    let (server, port) = serve(dir.path(), &out, Some(&designs));
    let tok = page(port);
    let (status, e) = error(post(port, &tok, "open", json!({"lot": "343"})));
    assert_eq!(status, 422, "{e}");
    assert!(e.contains("cannot be designed"), "{e}");
    drop(server);
}

#[test]
fn a_city_bred_with_more_layouts_than_a_visitor_may_ask_opens_with_the_most_allowed() {
    let dir = tempfile::tempdir().unwrap();
    let (out, _) = built_with(dir.path(), "population = 2000\ngenerations = 1\n");
    let (server, port) = serve(dir.path(), &out, None);
    let tok = page(port);
    let (status, s) = post(port, &tok, "open", json!({"lot": "343"}));
    assert_eq!(status, 200, "{s}");
    assert_eq!(s["population"], 1000);
    let (_, list) = ask(port, "GET", "/api/gardens", "");
    assert_eq!(list["population"], 1000);
    drop(server);
}

/// Replaces `path` with a FIFO.
fn fifo(path: &Path) {
    let _ = std::fs::remove_file(path);
    assert!(std::process::Command::new("mkfifo")
        .arg(path)
        .status()
        .unwrap()
        .success());
}

#[test]
fn a_fifo_for_the_designs_file_is_refused_at_start_and_while_serving() {
    let dir = tempfile::tempdir().unwrap();
    let (out, _) = built(dir.path());
    let designs = dir.path().join("designs.json");
    fifo(&designs);
    let viewer = dir.path().join("viewer");
    std::fs::create_dir_all(viewer.join("node_modules/three")).unwrap();
    std::fs::write(viewer.join("index.html"), "<!doctype html>").unwrap();
    let o = common::edo_city()
        .args(["serve", "--port", "0", "--viewer"])
        .arg(dir.path().join("viewer"))
        .arg(&out)
        .arg("--designs")
        .arg(&designs)
        .output()
        .unwrap();
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("not a regular file"), "{err}");

    std::fs::remove_file(&designs).unwrap();
    let (server, port) = serve(dir.path(), &out, Some(&designs));
    let tok = page(port);
    let (_, s) = post(port, &tok, "open", json!({"lot": "343"}));
    let id = s["session"].as_str().unwrap().to_string();
    fifo(&designs);
    let (status, e) = error(post(
        port,
        &tok,
        "keep",
        json!({"session": id, "generation": 0, "candidate": 0}),
    ));
    assert_eq!(status, 422, "{e}");
    assert!(e.contains("not a regular file"), "{e}");
    // Everyone else is still answered.
    let (status, _) = ask(port, "GET", "/api/gardens", "");
    assert_eq!(status, 200);
    let (status, _) = post(port, &tok, "open", json!({"lot": "138"}));
    assert_eq!(status, 422, "the designs file is read to open a garden too");
    drop(server);
}

#[test]
fn two_servers_keeping_into_one_designs_file_lose_no_design() {
    let dir = tempfile::tempdir().unwrap();
    let (out, _) = built(dir.path());
    let designs = dir.path().join("designs.json");
    let (one, p1) = serve(dir.path(), &out, Some(&designs));
    let (two, p2) = serve(dir.path(), &out, Some(&designs));
    let session = |port: u16, lot: &str| {
        let tok = page(port);
        let (_, s) = post(port, &tok, "open", json!({"lot": lot}));
        (tok, s["session"].as_str().unwrap().to_string())
    };
    let (t1, s1) = session(p1, "138");
    let (t2, s2) = session(p2, "343");
    for round in 0..15 {
        let keep = |port: u16, tok: String, id: String| {
            std::thread::spawn(move || {
                post(
                    port,
                    &tok,
                    "keep",
                    json!({"session": id, "generation": 0, "candidate": round % 3}),
                )
            })
        };
        let a = keep(p1, t1.clone(), s1.clone());
        let b = keep(p2, t2.clone(), s2.clone());
        let (a, b) = (a.join().unwrap(), b.join().unwrap());
        assert_eq!((a.0, b.0), (200, 200), "round {round}: {} {}", a.1, b.1);
        let file = read_json(&designs);
        let lots: Vec<&str> = (file["designs"].as_array().unwrap().iter())
            .map(|d| d["lot"].as_str().unwrap())
            .collect();
        assert!(
            lots.contains(&"138") && lots.contains(&"343"),
            "round {round}: {lots:?}"
        );
    }
    drop((one, two));
}
