//! The workbench's HTTP routes (JSON):
//!
//! - `GET /api/params`: every parameter as `{key, section, type, default, value, allowed,
//!   doc, set}` (`params::catalogue` and `params::allowed`; `value` as the hypothesis
//!   stands, `set` whether its file sets the key). Served read-only without `--edit`.
//! - `GET /api/edit/status`: `{busy, revision, requested, changedTiles, lastMs, error,
//!   saved, undo, redo}`; `revision` is what OUT shows.
//! - `GET /api/edit/compare?h=K`: `{h, changedLots}`, the lots where served build K and
//!   the hypothesis as built disagree (as `compare --gpkg` finds them).
//! - `GET /api/edit/state`: the files edited and the machiya types, uses and fields a lot
//!   may be given; `{enabled: false}` from a server without `--edit`.
//! - `POST /api/edit/set {key, value, base?}`, `/lot {lot, field, value, base?}`, `/undo`,
//!   `/redo`, `/reroll` (`{base?}`): answer `{revision, changedTiles, ms, pending}` once
//!   built; `base` is the revision the page last saw (409 when another page edited since).
//! - `POST /api/edit/lock {section, keep, base?}`: keeps a section's draw (`[seeds]`) when
//!   the seed changes, or lets it follow `seed` again.
//! - `POST /api/edit/save {}`: writes the parameter file, its overrides and its log.
//!
//! A POST is a write: checked by `guard.rs` (this server's origin, JSON, the page's token)
//! before anything is read. Errors are `{error}` with 400 (a bad request), 403 (no `--edit`,
//! another origin), 409 (a stale page, nothing to undo, a file changed on disk), 422 (a
//! value the build refuses: its own message).

use serde::Deserialize;
use serde_json::{json, Value};

use super::super::api::{json_answer, parse, refused};
use super::super::designer::{refuse, Refusal};
use super::super::guard::Guard;
use super::super::http::{Answer, Call};
use super::{Done, Workbench};
use edo_city::params::{allowed, catalogue, Params};

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Set {
    key: String,
    value: Value,
    base: Option<u64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Lot {
    lot: String,
    field: String,
    value: String,
    base: Option<u64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Lock {
    section: String,
    keep: bool,
    base: Option<u64>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct Base {
    base: Option<u64>,
}

/// The answer to a workbench route, or `None` for another route.
pub fn answer(bench: Option<&Workbench>, call: &Call, guard: &Guard) -> Option<Answer> {
    let path = call.target.split('?').next().unwrap_or("");
    let route = match path {
        "/api/params" => "params",
        p => p.strip_prefix("/api/edit/")?,
    };
    let reads = matches!(route, "params" | "status" | "state" | "compare");
    let writes = matches!(
        route,
        "set" | "lot" | "lock" | "undo" | "redo" | "reroll" | "save"
    );
    if !reads && !writes {
        return Some(refused(refuse(404, format!("no such API route: {path}"))));
    }
    if call.post != writes {
        return Some(Answer::NotAllowed {
            allow: if reads { "GET, HEAD" } else { "POST" },
        });
    }
    if writes {
        if let Err(r) = guard.write(&call.headers) {
            return Some(refused(r));
        }
    }
    if route == "params" {
        return Some(json_answer(200, &params(bench)));
    }
    let Some(bench) = bench else {
        // The viewer asks on every load: a read-only server says so without an error.
        if route == "state" {
            return Some(json_answer(200, &json!({ "enabled": false })));
        }
        return Some(refused(refuse(
            403,
            "this server is read-only: start it with `edo-city serve OUT --edit PARAMS.toml` \
             to edit a hypothesis"
                .into(),
        )));
    };
    let body = &call.body[..];
    let base = || -> Result<Option<u64>, Refusal> {
        match body.is_empty() {
            true => Ok(None),
            false => parse::<Base>(body).map(|b| b.base),
        }
    };
    let result =
        match route {
            "status" => Ok(bench.status()),
            "state" => Ok(state(bench)),
            "compare" => compare(bench, &call.target),
            "set" => parse(body).and_then(|s: Set| bench.set(s.base, &s.key, &s.value).map(done)),
            "lot" => parse(body)
                .and_then(|l: Lot| bench.lot(l.base, &l.lot, &l.field, &l.value).map(done)),
            "lock" => parse(body)
                .and_then(|l: Lock| bench.keep_draw(l.base, &l.section, l.keep).map(done)),
            "undo" => base().and_then(|b| bench.undo(b).map(done)),
            "redo" => base().and_then(|b| bench.redo(b).map(done)),
            "reroll" => base().and_then(|b| bench.reroll(b).map(done)),
            _ => bench.save(),
        };
    Some(match result {
        Ok(v) => json_answer(200, &v),
        Err(r) => refused(r),
    })
}

fn done(d: Done) -> Value {
    json!({
        "revision": d.revision,
        "changedTiles": d.changed_tiles,
        "ms": d.ms,
        "pending": d.pending,
    })
}

/// Every parameter, with its value as the hypothesis stands.
fn params(bench: Option<&Workbench>) -> Value {
    let (current, text) = match bench {
        Some(b) => b.current(),
        None => (None, String::new()),
    };
    let values = serde_json::to_value(current.unwrap_or_else(Params::default)).unwrap_or_default();
    // The keys the person's file sets, read once (a table's key is set when any of its own is).
    let set = super::log::leaves(&text);
    let sets = |key: &str| {
        set.keys()
            .any(|k| k == key || k.strip_prefix(key).is_some_and(|r| r.starts_with('.')))
    };
    let list: Vec<Value> = catalogue::catalogue()
        .into_iter()
        .map(|p| {
            let value = p.key.split('.').fold(&values, |v, k| &v[k]).clone();
            let value = match value {
                // Left out of the parameters as published when unset.
                Value::Null => p.default.clone(),
                v => v,
            };
            json!({
                "key": p.key,
                "section": p.section,
                "type": p.kind,
                "default": p.default,
                "value": value,
                "allowed": allowed::allowed(&p.key).map(|a| a.to_json()),
                "doc": p.doc,
                "set": sets(&p.key),
            })
        })
        .collect();
    Value::Array(list)
}

/// `GET /api/edit/compare?h=K`: the lots where build K and the hypothesis disagree.
fn compare(bench: &Workbench, target: &str) -> Result<Value, Refusal> {
    let query = target.split_once('?').map_or("", |q| q.1);
    let h = query
        .split('&')
        .find_map(|kv| kv.strip_prefix("h="))
        .unwrap_or("0");
    let h: usize = h
        .parse()
        .map_err(|_| refuse(400, format!("`h` must be a build's number, got `{h}`")))?;
    Ok(json!({ "h": h, "changedLots": bench.compare(h)? }))
}

/// The files edited and what a lot may be given.
fn state(bench: &Workbench) -> Value {
    let f = bench.files();
    let (params, _) = bench.current();
    let types = params
        .as_ref()
        .and_then(|p| edo_city::build::load_catalog(p, bench.templates()).ok())
        .map(|c| {
            c.names_of(edo_city::templates::Kind::Machiya)
                .into_iter()
                .map(String::from)
                .collect::<Vec<_>>()
        })
        .unwrap_or_default();
    json!({
        "enabled": true,
        "params": f.params.display().to_string(),
        "overrides": f.overrides.display().to_string(),
        "history": f.history.display().to_string(),
        "types": types,
        "uses": ["machiya", "buke", "kuge", "jisha", "other"],
        "fields": ["mtype", "use", "district", "storeys"],
        "seedSections": edo_city::params::SEED_SECTIONS,
        "locks": params.as_ref().map(|p| p.seeds.keys().cloned().collect::<Vec<_>>()).unwrap_or_default(),
        "status": bench.status(),
    })
}
