//! `serve`'s JSON API for designing rock gardens in the browser (issue 42), over the
//! designer's sessions (`designer.rs`):
//!
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
//! Errors are JSON `{error}` with 400 (a bad request), 403, 404 (no such garden or
//! session), 409 (a stale generation, a conflicting design) or 422 (a designs file that is
//! not one); nothing is written on any of them.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use anyhow::{bail, Context, Result};
use serde::Deserialize;
use serde_json::json;

use super::designer::{refuse, Refusal, Session, MAX_POPULATION};
use super::http::Answer;
use edo_city::model::design::Designs;
use edo_city::model::GardenStat;

/// Sessions held at once; past it the one unused longest is closed. With
/// `designer::MAX_KEPT_LAYOUTS` each, the sessions hold at most about 250 MB.
const MAX_SESSIONS: usize = 32;

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
            let text = std::fs::read_to_string(&path)
                .with_context(|| format!("cannot read {}", path.display()))?;
            serde_json::from_str(&text).with_context(|| format!("{}: not JSON", path.display()))
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
    /// Held while the designs file is read and written: one keep at a time.
    file: Mutex<()>,
}

#[derive(Default)]
struct Sessions {
    next_id: u64,
    clock: u64,
    open: BTreeMap<u64, (u64, Session)>,
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
    session: u64,
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
            if path.exists() {
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

    /// The answer to an `/api/` request, or `None` for another route.
    pub fn answer(&self, post: bool, target: &str, body: &[u8]) -> Option<Answer> {
        let (path, query) = target.split_once('?').unwrap_or((target, ""));
        let route = path.strip_prefix("/api/")?;
        let result = match (post, route) {
            (false, "gardens") => self.list(query),
            (true, "gardens/open") => parse(body).and_then(|o| self.open(o)),
            (true, "gardens/next") => parse(body)
                .and_then(|s: Step| self.with(&s, |session| session.next(&s.picks).map(|()| None))),
            (true, "gardens/undo") => parse(body)
                .and_then(|s: Step| self.with(&s, |session| session.undo().map(|()| None))),
            (true, "gardens/keep") => parse(body).and_then(|s: Step| self.keep(&s)),
            (_, "gardens" | "gardens/open" | "gardens/next" | "gardens/undo" | "gardens/keep") => {
                return Some(Answer::NotAllowed {
                    allow: if post { "GET, HEAD" } else { "POST" },
                })
            }
            _ => Err(refuse(404, format!("no such API route: {path}"))),
        };
        Some(match result {
            Ok(v) => json_answer(200, &v),
            Err(r) => json_answer(r.status, &json!({ "error": r.message })),
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
            "population": b.population,
            "writable": self.designs.is_some(),
            "gardens": gardens,
        }))
    }

    fn open(&self, o: Open) -> Result<serde_json::Value, Refusal> {
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
        let population = o.population.unwrap_or(b.population);
        if !(2..=MAX_POPULATION).contains(&population) {
            return Err(refuse(
                400,
                format!("`population` must be from 2 to {MAX_POPULATION}, got {population}"),
            ));
        }
        let base = match &self.designs {
            Some(p) if p.exists() => read_designs(p)?.get(&garden.key).cloned(),
            _ => None,
        };
        let session = Session::open(garden, o.h, b.seed, population, base);
        drop(b);
        let mut s = self.lock();
        s.next_id += 1;
        s.clock += 1;
        let (id, now) = (s.next_id, s.clock);
        let state = session.state(id);
        if s.open.len() >= MAX_SESSIONS {
            let oldest = s.open.iter().min_by_key(|(_, (t, _))| *t).map(|(k, _)| *k);
            if let Some(k) = oldest {
                s.open.remove(&k);
            }
        }
        s.open.insert(id, (now, session));
        Ok(state)
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Sessions> {
        self.sessions.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Runs `f` on the session `s` names at the generation it names; its new state, or what
    /// `f` returns instead.
    fn with(
        &self,
        s: &Step,
        f: impl FnOnce(&mut Session) -> Result<Option<serde_json::Value>, Refusal>,
    ) -> Result<serde_json::Value, Refusal> {
        let mut all = self.lock();
        all.clock += 1;
        let now = all.clock;
        let Some((used, session)) = all.open.get_mut(&s.session) else {
            return Err(refuse(
                404,
                format!(
                    "no session {}: it was closed; open the garden again",
                    s.session
                ),
            ));
        };
        *used = now;
        session.at(s.generation)?;
        Ok(match f(session)? {
            Some(v) => v,
            None => session.state(s.session),
        })
    }

    fn keep(&self, s: &Step) -> Result<serde_json::Value, Refusal> {
        let Some(path) = self.designs.clone() else {
            return Err(refuse(
                403,
                "this server is read-only: start it with `--designs FILE` to keep designs".into(),
            ));
        };
        self.with(s, |session| {
            let design = session.design(s.candidate)?;
            let _file = self.file.lock().unwrap_or_else(|e| e.into_inner());
            let mut all = match path.exists() {
                true => read_designs(&path)?,
                false => Designs::default(),
            };
            if all.get(&session.key) != session.base.as_ref() {
                return Err(refuse(
                    409,
                    format!(
                        "someone kept another design for garden `{}` in {} since this session \
                         opened: open the garden again to start from theirs (nothing was written)",
                        session.key,
                        path.display()
                    ),
                ));
            }
            all.put(design.clone());
            edo_city::output::atomic::write_atomic(&path, all.to_text().as_bytes()).map_err(
                |e| {
                    refuse(
                        500,
                        format!("cannot write {}: {e} (nothing was written)", path.display()),
                    )
                },
            )?;
            // This session's later keeps write over its own design.
            session.base = Some(design.clone());
            Ok(Some(json!({
                "kept": design,
                "file": path.display().to_string(),
                "designs": all.designs.len(),
            })))
        })
    }
}

/// A designs file, or a 422 naming it and what is wrong.
fn read_designs(path: &Path) -> Result<Designs, Refusal> {
    use std::io::Read as _;
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
    let file = std::fs::File::open(path).map_err(|e| bad(e.to_string()))?;
    let mut text = String::new();
    file.take(limit + 1)
        .read_to_string(&mut text)
        .map_err(|e| bad(format!("not UTF-8 text ({e})")))?;
    if text.len() as u64 > limit {
        return Err(bad(format!("larger than {limit} bytes")));
    }
    Designs::parse(&text).map_err(bad)
}

fn parse<T: for<'de> Deserialize<'de>>(body: &[u8]) -> Result<T, Refusal> {
    serde_json::from_slice(body).map_err(|e| {
        refuse(
            400,
            format!("the request's body is not what this route takes: {e}"),
        )
    })
}

fn json_answer(status: u16, v: &serde_json::Value) -> Answer {
    Answer::Bytes {
        status,
        content_type: "application/json",
        body: serde_json::to_vec(v).unwrap_or_default(),
    }
}
