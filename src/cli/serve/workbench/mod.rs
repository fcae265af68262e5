//! The workbench of `edo-city serve OUT --edit PARAMS.toml` (issue 61): a hypothesis edited
//! in the browser (a parameter, a lot), rebuilt into OUT keeping every tile that would come
//! out the same (`build::reuse`), undone and redone, and saved as the person's own
//! parameter file, its overrides table and a revision log beside it.
//!
//! The edits live in memory until `save`: the files on disk change only then, each written
//! whole (a temporary renamed over it), so a crash loses nothing saved. One build runs at a
//! time, on a thread of its own, always of the newest edit: edits that arrive while it runs
//! are built together next (a bounded queue of one). A build that fails (a lot the input
//! does not have, a value the build refuses) takes the hypothesis back to the last one
//! built, and every edit waiting on it gets the build's own message.

mod files;
pub mod routes;
mod toml;

use std::path::{Path, PathBuf};
use std::sync::{Arc, Condvar, Mutex};
use std::time::{Duration, Instant};

use edo_city::build::reuse::Fingerprints;
use edo_city::build::{BuildOptions, NoProgress, Selection, Timings};
use edo_city::input::overrides::{self, Override};
use edo_city::output::gpkg::{lot_differences, plan_lots, LotDiff, PlanLots};
use edo_city::params::Params;

use super::designer::{refuse, Refusal};
pub use files::Files;

/// Undo steps kept.
const MAX_UNDO: usize = 200;
/// How long an edit's request waits for its build before answering that it is still
/// building (the page then follows `status`).
const WAIT: Duration = Duration::from_secs(120);

/// A hypothesis as edited: the parameter file's text and the overrides' rows.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Hypothesis {
    pub text: String,
    pub rows: Vec<Override>,
}

/// Where the builds go and what they read.
pub struct Place {
    pub input: PathBuf,
    pub out: PathBuf,
    pub templates: Option<PathBuf>,
    pub threads: usize,
    /// Every build served, `out` first: the hypotheses the outlines may compare against.
    pub served: Vec<PathBuf>,
}

/// The workbench: its files, the builds' place, the state the pages share.
pub struct Workbench {
    files: Files,
    place: Place,
    state: Mutex<State>,
    /// Woken when an edit arrives (the builder) and when a build ends (the waiting edits).
    bell: Condvar,
}

/// What every page sees.
struct State {
    now: Hypothesis,
    /// The hypothesis OUT holds (the last one built).
    good: Hypothesis,
    /// The hypothesis on disk.
    saved: Hypothesis,
    undo: Vec<Hypothesis>,
    redo: Vec<Hypothesis>,
    /// The newest edit's revision; the one OUT shows; the last one a build was tried for.
    requested: u64,
    built: u64,
    tried: u64,
    /// The last build's failure: the revision it was for and the build's message.
    failed: Option<(u64, String)>,
    busy: bool,
    changed_tiles: Vec<String>,
    /// The lots whose type, kura, house or trees the last build changed (as `compare
    /// --gpkg` finds them), their rings in metres from the build's origin.
    changed_lots: Vec<LotDiff>,
    /// The lots of what OUT holds, to find the next build's changes against.
    lots: Arc<PlanLots>,
    last_ms: u64,
    fingerprints: Arc<Fingerprints>,
}

/// The outcome of an edit, once built.
pub struct Done {
    pub revision: u64,
    pub changed_tiles: Vec<String>,
    pub ms: u64,
    /// Still building after [`WAIT`]: follow `status`.
    pub pending: bool,
}

impl Workbench {
    /// The workbench of `files` building into `place`, starting from what is on disk; its
    /// first build (every tile, to know what each was made from) is started at once.
    pub fn start(files: Files, place: Place) -> anyhow::Result<Arc<Workbench>> {
        let saved = files.read()?;
        // The hypothesis must read as a build would read it, before anything is served.
        resolve(&files, &saved).map_err(|m| anyhow::anyhow!("{m}"))?;
        let lots = Arc::new(plan_lots(&place.out).unwrap_or_default());
        let wb = Arc::new(Workbench {
            files,
            place,
            state: Mutex::new(State {
                now: saved.clone(),
                good: Hypothesis::default(),
                saved,
                undo: Vec::new(),
                redo: Vec::new(),
                requested: 1,
                built: 0,
                tried: 0,
                failed: None,
                busy: false,
                changed_tiles: Vec::new(),
                changed_lots: Vec::new(),
                lots,
                last_ms: 0,
                fingerprints: Arc::new(Fingerprints::default()),
            }),
            bell: Condvar::new(),
        });
        let builder = wb.clone();
        std::thread::Builder::new()
            .name("workbench builds".into())
            .spawn(move || builder.builds())?;
        Ok(wb)
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, State> {
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The builder's loop: the newest edit not tried yet, built; forever.
    fn builds(&self) {
        loop {
            let (rev, hyp, before, lots) = {
                let mut s = self.lock();
                while s.tried == s.requested {
                    s = self.bell.wait(s).unwrap_or_else(|e| e.into_inner());
                }
                s.busy = true;
                let lots = s.lots.clone();
                (s.requested, s.now.clone(), s.fingerprints.clone(), lots)
            };
            let t = Instant::now();
            let result = self.build(&hyp, before);
            // What changed, lot by lot, off the lock: the pages' polls go on meanwhile.
            let t_lots = Instant::now();
            let new_lots = result
                .as_ref()
                .ok()
                .map(|_| plan_lots(&self.place.out).unwrap_or_default());
            let changed_lots = match &new_lots {
                Some(new) => self.outlines(lot_differences(&lots, new)),
                None => Vec::new(),
            };
            if let Ok((_, made, timings)) = &result {
                log_rebuild(rev, made.len(), t.elapsed(), timings, t_lots.elapsed());
            }
            let result = result.map(|(marks, made, _)| (marks, made));
            let mut s = self.lock();
            s.busy = false;
            s.tried = rev;
            match result {
                Ok((marks, made)) => {
                    s.built = rev;
                    s.good = hyp;
                    s.changed_tiles = made;
                    s.changed_lots = changed_lots;
                    s.lots = Arc::new(new_lots.unwrap_or_default());
                    s.last_ms = t.elapsed().as_millis() as u64;
                    s.fingerprints = Arc::new(marks);
                    s.failed = None;
                }
                Err(message) => {
                    s.failed = Some((rev, message));
                    // Back to what OUT holds, with the undo steps it had; edits made since
                    // the failed one was asked for go too (they were built on it).
                    let good = s.good.clone();
                    while let Some(top) = s.undo.pop() {
                        if top == good {
                            break;
                        }
                    }
                    s.now = good;
                    s.tried = s.requested;
                }
            }
            self.bell.notify_all();
        }
    }

    /// One build of `hyp` into OUT, keeping the tiles `before` says would come out the same.
    fn build(
        &self,
        hyp: &Hypothesis,
        before: Arc<Fingerprints>,
    ) -> Result<(Fingerprints, Vec<String>, Timings), String> {
        let params = resolve(&self.files, hyp)?;
        let opts = BuildOptions {
            input: self.place.input.clone(),
            out: self.place.out.clone(),
            params,
            templates: self.place.templates.clone(),
            threads: self.place.threads,
            plan_image: true,
            selection: Selection::All,
            force: false,
            cache: None,
            reuse: Some(before),
        };
        let outcome = edo_city::build::build(&opts, &NoProgress).map_err(|e| e.to_string())?;
        let (marks, made) =
            (outcome.fingerprints).ok_or_else(|| "the build kept no fingerprints".to_string())?;
        Ok((marks, made, outcome.timings))
    }

    /// The lots' rings moved to metres from the build's origin (the viewer's frame).
    fn outlines(&self, mut lots: Vec<LotDiff>) -> Vec<LotDiff> {
        let origin = edo_city::bounded::read(&self.place.out.join("manifest.json"), 2 << 30)
            .ok()
            .and_then(|b| serde_json::from_slice::<serde_json::Value>(&b).ok())
            .map_or([0.0, 0.0], |m| {
                [
                    m["origin"][0].as_f64().unwrap_or(0.0),
                    m["origin"][1].as_f64().unwrap_or(0.0),
                ]
            });
        for l in &mut lots {
            for p in &mut l.ring {
                *p = [p[0] - origin[0], p[1] - origin[1]];
            }
        }
        lots
    }

    /// The lots where served build `h` and the hypothesis as built disagree (type, kura,
    /// house, trees), as `compare --gpkg` finds them; rings in the viewer's frame.
    pub fn compare(&self, h: usize) -> Result<Vec<LotDiff>, Refusal> {
        let dir = self.place.served.get(h).ok_or_else(|| {
            refuse(
                404,
                format!(
                    "no build {h}: serve has {} build(s)",
                    self.place.served.len()
                ),
            )
        })?;
        let other = plan_lots(dir).map_err(|e| refuse(422, e.to_string()))?;
        let now = self.lock().lots.clone();
        Ok(self.outlines(lot_differences(&other, &now)))
    }

    /// Applies an edit made by `change` from the hypothesis as it stands (checked as the
    /// build will read it), when the page saw revision `base`; waits for its build.
    fn edit(
        &self,
        base: Option<u64>,
        change: impl FnOnce(&Hypothesis) -> Result<Hypothesis, Refusal>,
    ) -> Result<Done, Refusal> {
        let rev = {
            let mut s = self.lock();
            stale(&s, base)?;
            let next = change(&s.now)?;
            if next == s.now {
                return Ok(Done {
                    revision: s.built,
                    changed_tiles: Vec::new(),
                    ms: 0,
                    pending: false,
                });
            }
            resolve(&self.files, &next).map_err(|m| refuse(422, m))?;
            let now = std::mem::replace(&mut s.now, next);
            s.undo.push(now);
            if s.undo.len() > MAX_UNDO {
                s.undo.remove(0);
            }
            s.redo.clear();
            s.requested += 1;
            s.requested
        };
        self.bell.notify_all();
        self.wait(rev)
    }

    /// Waits until revision `rev` is built or has failed.
    fn wait(&self, rev: u64) -> Result<Done, Refusal> {
        let deadline = Instant::now() + WAIT;
        let mut s = self.lock();
        loop {
            if let Some((failed, message)) = &s.failed {
                if *failed >= rev {
                    return Err(refuse(422, message.clone()));
                }
            }
            if s.built >= rev {
                return Ok(Done {
                    revision: s.built,
                    changed_tiles: s.changed_tiles.clone(),
                    ms: s.last_ms,
                    pending: false,
                });
            }
            let left = deadline.saturating_duration_since(Instant::now());
            if left.is_zero() {
                return Ok(Done {
                    revision: rev,
                    changed_tiles: Vec::new(),
                    ms: 0,
                    pending: true,
                });
            }
            s = self
                .bell
                .wait_timeout(s, left)
                .map_or_else(|e| e.into_inner().0, |r| r.0);
        }
    }

    /// Sets parameter `key` to `value` (null: back to the default).
    pub fn set(
        &self,
        base: Option<u64>,
        key: &str,
        value: &serde_json::Value,
    ) -> Result<Done, Refusal> {
        self.edit(base, |h| {
            let text = toml::set_key(&h.text, key, value).map_err(|m| refuse(400, m))?;
            Ok(Hypothesis {
                text,
                rows: h.rows.clone(),
            })
        })
    }

    /// Gives lot `lot`'s `field` the value `value`: one more row of the overrides, which the
    /// parameter file names (added to it at the first).
    pub fn lot(
        &self,
        base: Option<u64>,
        lot: &str,
        field: &str,
        value: &str,
    ) -> Result<Done, Refusal> {
        let one = Override {
            lot: lot.trim().into(),
            field: field.trim().into(),
            value: value.trim().into(),
            row: 0,
        };
        overrides::check(&one).map_err(|m| refuse(422, format!("lot `{lot}`: {m}")))?;
        let name = self.files.overrides_name();
        self.edit(base, |h| {
            let mut next = h.clone();
            if toml::get_key(&h.text, "input.overrides").is_none() {
                next.text = toml::set_key(&h.text, "input.overrides", &name.into())
                    .map_err(|m| refuse(400, m))?;
            }
            next.rows.push(Override {
                row: next.rows.len() + 2,
                ..one
            });
            Ok(next)
        })
    }

    /// Back one edit.
    pub fn undo(&self, base: Option<u64>) -> Result<Done, Refusal> {
        self.step(base, true)
    }

    /// Forward one edit undone.
    pub fn redo(&self, base: Option<u64>) -> Result<Done, Refusal> {
        self.step(base, false)
    }

    fn step(&self, base: Option<u64>, back: bool) -> Result<Done, Refusal> {
        let rev = {
            let mut s = self.lock();
            stale(&s, base)?;
            let from = match back {
                true => s.undo.pop(),
                false => s.redo.pop(),
            };
            let Some(h) = from else {
                let what = if back { "undo" } else { "redo" };
                return Err(refuse(409, format!("nothing to {what}")));
            };
            let now = std::mem::replace(&mut s.now, h);
            match back {
                true => s.redo.push(now),
                false => s.undo.push(now),
            }
            s.requested += 1;
            s.requested
        };
        self.bell.notify_all();
        self.wait(rev)
    }

    /// A new draw of everything random: `seed` one more.
    pub fn reroll(&self, base: Option<u64>) -> Result<Done, Refusal> {
        let seed = {
            let s = self.lock();
            resolve(&self.files, &s.now).map_or(1, |p| p.seed)
        };
        self.set(base, "seed", &serde_json::json!(seed.wrapping_add(1)))
    }

    /// Keeps `section`'s draw (its own seed, `[seeds]`, set to the one it draws from now) or
    /// lets it follow `seed` again.
    pub fn keep_draw(&self, base: Option<u64>, section: &str, keep: bool) -> Result<Done, Refusal> {
        let key = format!("seeds.{section}");
        let value = match keep {
            true => {
                let s = self.lock();
                let p = resolve(&self.files, &s.now).map_err(|m| refuse(422, m))?;
                serde_json::json!(p.seed_for(section))
            }
            false => serde_json::Value::Null,
        };
        self.set(base, &key, &value)
    }

    /// Writes the hypothesis as it stands: the parameter file, its overrides, the log.
    pub fn save(&self) -> Result<serde_json::Value, Refusal> {
        let mut s = self.lock();
        let now = s.now.clone();
        let lines = self.files.save(&s.saved, &now)?;
        s.saved = now;
        Ok(serde_json::json!({ "saved": true, "changes": lines }))
    }

    /// The state every page polls.
    pub fn status(&self) -> serde_json::Value {
        let s = self.lock();
        serde_json::json!({
            "busy": s.busy || s.tried < s.requested,
            "revision": s.built,
            "requested": s.requested,
            "changedTiles": s.changed_tiles,
            "changedLots": s.changed_lots,
            "lastMs": s.last_ms,
            "error": s.failed.as_ref().map(|f| f.1.clone()),
            "saved": s.saved == s.now,
            "undo": s.undo.len(),
            "redo": s.redo.len(),
        })
    }

    /// The parameters as the hypothesis stands, and the text of its file.
    pub fn current(&self) -> (Option<Params>, String) {
        let s = self.lock();
        (resolve(&self.files, &s.now).ok(), s.now.text.clone())
    }

    /// The files, for messages.
    pub fn files(&self) -> &Files {
        &self.files
    }

    /// The builds' template directory, when they have one of their own.
    pub fn templates(&self) -> Option<&Path> {
        self.place.templates.as_deref()
    }
}

/// A write from a page that has not seen the newest edit: another tab got there first.
fn stale(s: &State, base: Option<u64>) -> Result<(), Refusal> {
    match base {
        Some(b) if b != s.requested => Err(refuse(
            409,
            format!(
                "another page changed the hypothesis (revision {} now, this page saw {b}): \
                 it shows the new one; make the edit again",
                s.requested
            ),
        )),
        _ => Ok(()),
    }
}

/// The parameters of `hyp` as `build --params` reads them once saved, the overrides given
/// in memory.
fn resolve(files: &Files, hyp: &Hypothesis) -> Result<Params, String> {
    let mut p = Params::from_text_at(&hyp.text, &files.params).map_err(|e| e.to_string())?;
    if !p.input.overrides.is_empty() {
        p.input.rows = Some(Arc::new(hyp.rows.clone()));
    }
    Ok(p)
}

/// `path` absolute, for a build that names files wherever it is started.
pub fn absolute(path: &Path) -> PathBuf {
    edo_city::build::absolute(path)
}

/// One line on the server's stderr per rebuild: what was made, in how long, stage by stage
/// (as `build --timings` names them), the plan files drawn beside the tiles, and the lots
/// compared after it.
fn log_rebuild(rev: u64, tiles: usize, took: Duration, timings: &Timings, compared: Duration) {
    let mut line = format!(
        "revision {rev}: {tiles} tile(s) made in {:.2} s (",
        took.as_secs_f64()
    );
    for st in &timings.stages {
        line += &format!("{} {:.2} s, ", st.name, st.wall.as_secs_f64());
    }
    line += &format!(
        "of which plan.png {:.2} s and plan.gpkg {:.2} s, ",
        timings.plan.as_secs_f64(),
        (timings.gpkg[0] + timings.gpkg[1]).as_secs_f64()
    );
    line += &format!("lots compared {:.2} s)", compared.as_secs_f64());
    eprintln!("{line}");
}
