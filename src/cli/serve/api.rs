//! `serve`'s JSON API for designing rock gardens in the browser (issue 42), over the
//! designer's sessions (`designer.rs`):
//!
//! - `GET /api/token`: a page token (`{token}`), which every POST carries in
//!   `X-Edo-City-Token` with `Content-Type: application/json` (`guard.rs` says why).
//! - `GET /api/gardens?h=K`: the gardens build K (default 0) can design, with their lot ids,
//!   places (metres from the build's origin), sizes and stones as built.
//! - `POST /api/gardens/open` `{lot, h?, population?}`: a new session on a garden (by its key
//!   or its lot id): its first generation.
//! - `POST /api/gardens/next` `{session, generation, picks}`: the next generation, bred from
//!   the picked candidates (places among those shown), or by the GA when `picks` is empty.
//! - `POST /api/gardens/undo` `{session, generation}`: back one generation.
//! - `POST /api/gardens/keep` `{session, generation, candidate}`: writes the candidate as
//!   the garden's design into the `--designs` file (read-only without it: 403).
//!
//! Sessions are named by random ids and answer only the page (token) that opened them.
//! Errors are JSON `{error}` with 400 (a bad request), 403 (another origin, no token, a
//! read-only server), 404 (no such garden or session), 409 (a stale generation, a
//! conflicting design, the designs file held by another program), 413 (a designs file that
//! would pass its bound), 415 (not JSON) or 422 (a designs file that is not one, a garden
//! that cannot be designed); nothing is written on any of them.
//!
//! A keep reads, checks and writes the designs file while holding a lock on the directory
//! that holds it (the operating system's `flock`, which two servers on one file share), and
//! never while holding the sessions: a slow disk delays only the keep.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use anyhow::{bail, Context, Result};
use serde::Deserialize;
use serde_json::json;

use super::designer::{refuse, Refusal, Session, MAX_POPULATION};
use super::guard::{random_id, Guard};
use super::http::{Answer, Call};
use edo_city::model::design::Designs;
use edo_city::model::GardenStat;

/// Sessions held at once; past it the one unused longest is closed. With
/// `designer::MAX_KEPT_LAYOUTS` each, the sessions hold at most about 250 MB.
const MAX_SESSIONS: usize = 32;
/// The largest `manifest.json` or `report.json` of a served build read (a million lots' report
/// is about 300 MB).
const MAX_BUILD_JSON_BYTES: u64 = 2 << 30;
/// How long a keep waits for another program holding the designs file's directory.
const LOCK_WAIT: std::time::Duration = std::time::Duration::from_secs(5);

/// The gardens of one build being served.
#[derive(Default)]
pub struct BuildGardens {
    seed: u64,
    population: usize,
    origin: [f64; 2],
    gardens: Vec<GardenStat>,
}

impl BuildGardens {
    /// Reads a build's placed gardens (`report.json`) and seed and GA size (`manifest.json`).
    pub fn read(dir: &Path) -> Result<BuildGardens> {
        let json = |name: &str| -> Result<serde_json::Value> {
            let path = dir.join(name);
            let bytes = edo_city::bounded::read(&path, MAX_BUILD_JSON_BYTES)
                .with_context(|| format!("cannot read {}", path.display()))?;
            serde_json::from_slice(&bytes).with_context(|| format!("{}: not JSON", path.display()))
        };
        let m = json("manifest.json")?;
        let gardens = match dir.join("report.json").is_file() {
            true => {
                serde_json::from_value(json("report.json")?["gardens"].clone()).unwrap_or_default()
            }
            false => Vec::new(),
        };
        let gardens: Vec<GardenStat> = gardens
            .into_iter()
            .filter(|g: &GardenStat| g.placed && !g.key.is_empty() && !g.layout.is_empty())
            .collect();
        let p = &m["params"];
        Ok(BuildGardens {
            seed: p["seed"].as_u64().unwrap_or(1),
            population: p["garden"]["population"].as_u64().unwrap_or(30) as usize,
            origin: [
                m["origin"][0].as_f64().unwrap_or(0.0),
                m["origin"][1].as_f64().unwrap_or(0.0),
            ],
            gardens,
        })
    }

    fn find(&self, lot: &str) -> Option<&GardenStat> {
        let by_key = self.gardens.iter().find(|g| g.key == lot);
        by_key.or_else(|| self.gardens.iter().find(|g| g.lot == lot))
    }
}

/// A build's gardens as last read, and the manifest they were read with: a build rebuilt
/// while `serve` runs is read again (a visitor rebuilds with a kept design and reloads).
struct Served {
    dir: PathBuf,
    stamp: Option<(std::time::SystemTime, u64)>,
    gardens: Arc<BuildGardens>,
}

/// The manifest's time and length: written last by every build.
fn stamp(dir: &Path) -> Option<(std::time::SystemTime, u64)> {
    let m = std::fs::metadata(dir.join("manifest.json")).ok()?;
    Some((m.modified().ok()?, m.len()))
}

/// The designer's state: the builds' gardens, the sessions, the designs file.
pub struct Api {
    builds: Vec<Mutex<Served>>,
    designs: Option<PathBuf>,
    sessions: Mutex<Sessions>,
    /// Held while the designs file is read and written: one keep of this server at a time
    /// (the directory's lock keeps other servers out).
    file: Mutex<()>,
}

#[derive(Default)]
struct Sessions {
    clock: u64,
    open: BTreeMap<String, Held>,
}

/// An open session: when it was last used, the page that opened it, the session.
struct Held {
    used: u64,
    page: String,
    session: Session,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Open {
    lot: String,
    #[serde(default)]
    h: usize,
    population: Option<usize>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Step {
    session: String,
    generation: usize,
    #[serde(default)]
    picks: Vec<usize>,
    #[serde(default)]
    candidate: usize,
}

impl Api {
    /// The API over `builds`, writing designs to `designs` when given (checked now: a file
    /// that exists must be a designs file, and its directory must exist).
    pub fn new(dirs: &[PathBuf], designs: Option<PathBuf>) -> Result<Api> {
        let mut builds = Vec::new();
        for dir in dirs {
            builds.push(Mutex::new(Served {
                dir: dir.clone(),
                stamp: stamp(dir),
                gardens: Arc::new(BuildGardens::read(dir)?),
            }));
        }
        if let Some(path) = &designs {
            if std::fs::symlink_metadata(path).is_ok() {
                read_designs(path).map_err(|r| anyhow::anyhow!(r.message))?;
            } else if !path
                .parent()
                .is_none_or(|p| p.as_os_str().is_empty() || p.is_dir())
            {
                bail!("--designs {}: its directory does not exist", path.display());
            }
        }
        Ok(Api {
            builds,
            designs,
            sessions: Mutex::new(Sessions::default()),
            file: Mutex::new(()),
        })
    }

    /// The answer to an `/api/` request, or `None` for another route. `guard` has checked
    /// the request's host; a POST is checked here as a write before anything else.
    pub fn answer(&self, call: &Call, guard: &Guard) -> Option<Answer> {
        let (path, query) = call.target.split_once('?').unwrap_or((&call.target, ""));
        let route = path.strip_prefix("/api/")?;
        let known = matches!(
            route,
            "token" | "gardens" | "gardens/open" | "gardens/next" | "gardens/undo" | "gardens/keep"
        );
        let reads = matches!(route, "token" | "gardens");
        if known && call.post == reads {
            return Some(Answer::NotAllowed {
                allow: if reads { "GET, HEAD" } else { "POST" },
            });
        }
        let page = match call.post {
            true => match guard.write(&call.headers) {
                Ok(page) => page,
                Err(r) => return Some(refused(r)),
            },
            false => String::new(),
        };
        let body = &call.body[..];
        // A bug must still answer as the API promises: JSON, and nothing written.
        let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| match route {
            "token" => guard
                .page(&call.headers)
                .map(|()| json!({ "token": guard.issue() })),
            "gardens" => self.list(query),
            "gardens/open" => parse(body).and_then(|o| self.open(o, &page)),
            "gardens/next" => parse(body).and_then(|s: Step| {
                self.with(&s, &page, |session| session.next(&s.picks).map(|()| None))
            }),
            "gardens/undo" => parse(body)
                .and_then(|s: Step| self.with(&s, &page, |session| session.undo().map(|()| None))),
            "gardens/keep" => parse(body).and_then(|s: Step| self.keep(&s, &page)),
            _ => Err(refuse(404, format!("no such API route: {path}"))),
        }))
        .unwrap_or_else(|_| {
            Err(refuse(
                500,
                "internal error: the server met a bug (please report it); nothing was written"
                    .into(),
            ))
        });
        Some(match result {
            Ok(v) => json_answer(200, &v),
            Err(r) => refused(r),
        })
    }

    fn build(&self, h: usize) -> Result<Arc<BuildGardens>, Refusal> {
        let served = self.builds.get(h).ok_or_else(|| {
            refuse(
                404,
                format!("no build {h}: serve has {} build(s)", self.builds.len()),
            )
        })?;
        let mut s = served.lock().unwrap_or_else(|e| e.into_inner());
        let now = stamp(&s.dir);
        if now != s.stamp {
            // Half-way through a rebuild the old list stands until the new manifest is read.
            if let Ok(g) = BuildGardens::read(&s.dir) {
                s.gardens = Arc::new(g);
                s.stamp = now;
            }
        }
        Ok(s.gardens.clone())
    }

    fn list(&self, query: &str) -> Result<serde_json::Value, Refusal> {
        let h = query
            .split('&')
            .find_map(|kv| kv.strip_prefix("h="))
            .map_or(Ok(0), |v| v.parse::<usize>())
            .map_err(|_| refuse(400, format!("`h` must be a build's number, got `{query}`")))?;
        let b = self.build(h)?;
        let kept = self.designs.as_deref().and_then(|p| read_designs(p).ok());
        let gardens: Vec<serde_json::Value> = b
            .gardens
            .iter()
            .map(|g| {
                json!({
                    "lot": g.key,
                    "lot_id": g.lot,
                    "area": g.area,
                    "size": g.size,
                    "corner": [g.corner[0] - b.origin[0], g.corner[1] - b.origin[1]],
                    "angle": g.angle,
                    "ground": g.ground,
                    "fitness": g.fitness,
                    "scores": g.scores,
                    "stones": g.layout,
                    "built_from_design": g.kept,
                    "designed": kept.as_ref().is_some_and(|d| d.get(&g.key).is_some()),
                })
            })
            .collect();
        Ok(json!({
            "build": h,
            "seed": b.seed,
            "population": b.population.min(MAX_POPULATION),
            "writable": self.designs.is_some(),
            "gardens": gardens,
        }))
    }

    fn open(&self, o: Open, page: &str) -> Result<serde_json::Value, Refusal> {
        let b = self.build(o.h)?;
        let Some(garden) = b.find(&o.lot) else {
            return Err(refuse(
                404,
                format!(
                    "build {} has no garden `{}` to design (GET /api/gardens lists them)",
                    o.h, o.lot
                ),
            ));
        };
        // A build may have bred more layouts a generation than a visitor may ask for: the
        // designer then breeds as many as it may.
        let population = o.population.unwrap_or(b.population.min(MAX_POPULATION));
        if !(2..=MAX_POPULATION).contains(&population) {
            return Err(refuse(
                400,
                format!("`population` must be from 2 to {MAX_POPULATION}, got {population}"),
            ));
        }
        let base = match &self.designs {
            Some(p) if std::fs::symlink_metadata(p).is_ok() => {
                read_designs(p)?.get(&garden.key).cloned()
            }
            _ => None,
        };
        let session = Session::open(garden, o.h, b.seed, population, base)?;
        drop(b);
        let id = random_id();
        let state = session.state(&id);
        let mut s = self.lock();
        s.clock += 1;
        let used = s.clock;
        if s.open.len() >= MAX_SESSIONS {
            let oldest = (s.open.iter().min_by_key(|(_, h)| h.used)).map(|(k, _)| k.clone());
            if let Some(k) = oldest {
                s.open.remove(&k);
            }
        }
        let page = page.to_string();
        s.open.insert(
            id,
            Held {
                used,
                page,
                session,
            },
        );
        Ok(state)
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Sessions> {
        self.sessions.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Runs `f` on the session `s` names, opened by this page, at the generation it names;
    /// its new state, or what `f` returns instead.
    fn with(
        &self,
        s: &Step,
        page: &str,
        f: impl FnOnce(&mut Session) -> Result<Option<serde_json::Value>, Refusal>,
    ) -> Result<serde_json::Value, Refusal> {
        let mut all = self.lock();
        all.clock += 1;
        let now = all.clock;
        let held = all.open.get_mut(&s.session).filter(|h| h.page == page);
        let Some(held) = held else {
            return Err(refuse(
                404,
                format!(
                    "no session `{}` of this page: it was closed; open the garden again",
                    excerpt(&s.session)
                ),
            ));
        };
        held.used = now;
        held.session.at(s.generation)?;
        Ok(match f(&mut held.session)? {
            Some(v) => v,
            None => held.session.state(&s.session),
        })
    }

    fn keep(&self, s: &Step, page: &str) -> Result<serde_json::Value, Refusal> {
        let Some(path) = self.designs.clone() else {
            return Err(refuse(
                403,
                "this server is read-only: start it with `--designs FILE` to keep designs".into(),
            ));
        };
        // The design and what the session started from, taken under the sessions' lock; the
        // file is read and written without it.
        let (design, base, key) = {
            let mut taken = None;
            self.with(s, page, |session| {
                let design = session.design(s.candidate)?;
                taken = Some((design, session.base.clone(), session.key.clone()));
                Ok(Some(serde_json::Value::Null))
            })?;
            taken.expect("set by a session that answered")
        };
        let all = {
            let _one = self.file.lock().unwrap_or_else(|e| e.into_inner());
            let _dir = DirLock::take(&path)?;
            let mut all = match std::fs::symlink_metadata(&path).is_ok() {
                true => read_designs(&path)?,
                false => Designs::default(),
            };
            if all.get(&key) != base.as_ref() {
                return Err(refuse(
                    409,
                    format!(
                        "someone kept another design for garden `{key}` in {} since this \
                         session opened: open the garden again to start from theirs (nothing \
                         was written)",
                        path.display()
                    ),
                ));
            }
            all.put(design.clone());
            let text = all.to_text();
            let limit = edo_city::model::design::MAX_DESIGNS_BYTES;
            if text.len() as u64 > limit {
                return Err(refuse(
                    413,
                    format!(
                        "keeping this design would make {} larger than the {limit} bytes a \
                         build reads: move some designs to another file (nothing was written)",
                        path.display()
                    ),
                ));
            }
            edo_city::output::atomic::write_atomic(&path, text.as_bytes()).map_err(|e| {
                refuse(
                    500,
                    format!("cannot write {}: {e} (nothing was written)", path.display()),
                )
            })?;
            all
        };
        // This session's later keeps write over its own design (if it is still open).
        if let Some(held) = self.lock().open.get_mut(&s.session) {
            held.session.base = Some(design.clone());
        }
        Ok(json!({
            "kept": design,
            "file": path.display().to_string(),
            "designs": all.designs.len(),
        }))
    }
}

/// The operating system's lock on the directory of a designs file, held while it is read,
/// checked and replaced: a second server keeping into the same file waits for it (a keep
/// replaces the file by a rename, so a lock on the file itself would guard the old one).
struct DirLock(std::fs::File);

impl DirLock {
    fn take(designs: &Path) -> Result<DirLock, Refusal> {
        let dir = match designs.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
        let busy = |why: String| {
            refuse(
                409,
                format!(
                    "cannot lock {} to keep a design ({why}): try again (nothing was written)",
                    dir.display()
                ),
            )
        };
        let file = std::fs::File::open(dir).map_err(|e| busy(e.to_string()))?;
        let start = std::time::Instant::now();
        loop {
            match file.try_lock() {
                Ok(()) => return Ok(DirLock(file)),
                Err(std::fs::TryLockError::WouldBlock) if start.elapsed() < LOCK_WAIT => {
                    std::thread::sleep(std::time::Duration::from_millis(20));
                }
                Err(std::fs::TryLockError::WouldBlock) => {
                    return Err(busy("another program holds it".into()))
                }
                Err(std::fs::TryLockError::Error(e)) => return Err(busy(e.to_string())),
            }
        }
    }
}

impl Drop for DirLock {
    fn drop(&mut self) {
        let _ = self.0.unlock();
    }
}

/// At most 40 characters of a value a request sent, for a message.
fn excerpt(s: &str) -> String {
    match s.char_indices().nth(40) {
        Some((i, _)) => format!("{}...", &s[..i]),
        None => s.to_string(),
    }
}

/// A designs file, or a 422 naming it and what is wrong. Read through
/// `bounded::read_text`: a FIFO or device swapped in for it is refused, never waited on.
fn read_designs(path: &Path) -> Result<Designs, Refusal> {
    let bad = |m: String| {
        refuse(
            422,
            format!(
                "designs file {}: {m}; fix or move it (nothing was written)",
                path.display()
            ),
        )
    };
    let limit = edo_city::model::design::MAX_DESIGNS_BYTES;
    let text = edo_city::bounded::read_text(path, limit).map_err(|e| bad(format!("it {e}")))?;
    Designs::parse(&text).map_err(bad)
}

pub(super) fn parse<T: for<'de> Deserialize<'de>>(body: &[u8]) -> Result<T, Refusal> {
    serde_json::from_slice(body).map_err(|e| {
        refuse(
            400,
            format!("the request's body is not what this route takes: {e}"),
        )
    })
}

/// An error as the API promises it: JSON `{error}`, whatever the client accepts.
pub(super) fn refused(r: Refusal) -> Answer {
    json_answer(r.status, &json!({ "error": r.message }))
}

pub(super) fn json_answer(status: u16, v: &serde_json::Value) -> Answer {
    Answer::Bytes {
        status,
        content_type: "application/json",
        body: serde_json::to_vec(v).unwrap_or_default(),
    }
}
