//! Talking to `edo-city serve`'s garden designer as the viewer does: a page token, then JSON
//! POSTs that carry it.

use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::Value;

/// `edo-city serve` of `out` with a stand-in viewer in `dir/viewer`, with `--designs` when
/// given; the server and its port.
pub fn serve(dir: &Path, out: &Path, designs: Option<&Path>) -> (super::Server, u16) {
    let more: Vec<&std::ffi::OsStr> = match designs {
        Some(d) => vec!["--designs".as_ref(), d.as_os_str()],
        None => Vec::new(),
    };
    serve_with(dir, &[out], &more)
}

/// `edo-city serve` of `outs` with `more` arguments and a stand-in viewer in `dir/viewer`;
/// the server and its port.
pub fn serve_with(dir: &Path, outs: &[&Path], more: &[&std::ffi::OsStr]) -> (super::Server, u16) {
    let viewer = dir.join("viewer");
    std::fs::create_dir_all(viewer.join("node_modules/three")).unwrap();
    std::fs::write(viewer.join("index.html"), "<!doctype html>").unwrap();
    let mut cmd = Command::new(assert_cmd::cargo::cargo_bin("edo-city"));
    cmd.args(["serve", "--port", "0", "--viewer"])
        .arg(&viewer)
        .args(outs)
        .args(more);
    let (server, url) = super::start_server(cmd);
    let port = url
        .trim_start_matches("http://127.0.0.1:")
        .trim_end_matches('/')
        .parse()
        .unwrap();
    (server, port)
}

/// One request on a connection of its own: the status and the body as JSON.
pub fn ask(port: u16, method: &str, target: &str, body: &str) -> (u16, Value) {
    ask_with(port, &[], method, target, body)
}

/// [`ask`] with more headers.
pub fn ask_with(
    port: u16,
    headers: &[(&str, &str)],
    method: &str,
    target: &str,
    body: &str,
) -> (u16, Value) {
    let (status, text) = super::http_with(port, method, target, headers, body);
    let body = text.split_once("\r\n\r\n").map_or("", |(_, b)| b);
    (status, serde_json::from_str(body).unwrap_or(Value::Null))
}

/// A page of the viewer: its token for writes.
pub fn page(port: u16) -> String {
    let (status, t) = ask(port, "GET", "/api/token", "");
    assert_eq!(status, 200, "{t}");
    t["token"].as_str().unwrap().to_string()
}

/// A POST of the page holding `token`, as the viewer sends it.
pub fn post(port: u16, token: &str, route: &str, body: Value) -> (u16, Value) {
    ask_with(
        port,
        &[("X-Edo-City-Token", token)],
        "POST",
        &format!("/api/gardens/{route}"),
        &body.to_string(),
    )
}

/// A POST to `route` (the whole path) of the page holding `token`, as the viewer sends it.
#[allow(dead_code)]
pub fn post_to(port: u16, token: &str, route: &str, body: Value) -> (u16, Value) {
    ask_with(
        port,
        &[("X-Edo-City-Token", token)],
        "POST",
        route,
        &body.to_string(),
    )
}

/// `edo-city serve OUTS --edit PARAMS --input fixtures/kyoto-small` with a stand-in viewer in
/// `dir/viewer`: the server and its port.
#[allow(dead_code)]
pub fn serve_edit(dir: &Path, outs: &[&Path], params: &Path) -> (super::Server, u16) {
    let input = super::fixture("kyoto-small");
    let more = [
        "--edit".as_ref(),
        params.as_os_str(),
        "--input".as_ref(),
        input.as_os_str(),
    ];
    serve_with(dir, outs, &more)
}

/// The status and `error` text of an answer.
pub fn error((status, v): (u16, Value)) -> (u16, String) {
    (status, v["error"].as_str().unwrap_or("").to_string())
}

/// Temple and estate lots both get gardens: the fixture then has two (lots 138 and 343).
pub const USES: &str = "[garden]\nuses = [\"jisha\", \"buke\", \"kuge\"]\n";

/// The fixture built with two gardens into `dir/out` (`more` added to its parameters), and
/// the parameter file it used.
pub fn built(dir: &Path) -> (PathBuf, PathBuf) {
    built_with(dir, "")
}

/// [`built`] with `more` parameters of `[garden]`.
pub fn built_with(dir: &Path, more: &str) -> (PathBuf, PathBuf) {
    let params = dir.join("params.toml");
    std::fs::write(&params, format!("{USES}{more}")).unwrap();
    let out = dir.join("out");
    super::build_ok(
        &super::fixture("kyoto-small"),
        &out,
        &["--quiet", "--no-plan", "--params", params.to_str().unwrap()],
    );
    (out, params)
}
