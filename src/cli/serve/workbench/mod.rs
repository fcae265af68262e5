//! The workbench of `edo-city serve OUT --edit PARAMS.toml` (issue 61): a hypothesis edited
//! in the browser (a parameter, a lot), rebuilt into OUT keeping every tile that would come
//! out the same (`build::reuse`), undone and redone, and saved as the person's own
//! parameter file, its overrides table and a revision log beside it.
//!
//! It never loses a person's work (issue 74):
//! - the edits live in memory until `save`, which writes the files as one transaction
//!   (`files.rs`), only a hypothesis that built (it waits for the builds asked for), and
//!   only over files that are still what the workbench last read or wrote;
//! - one build runs at a time, on a thread of its own (`builds.rs`), always of the newest
//!   edit: edits that arrive while it runs are built together next. A build that fails
//!   takes the hypothesis back to the last one built, or, before any was, to the file as
//!   the person wrote it; every edit waiting on it, and every edit made on top of it, gets
//!   the build's own message;
//! - a key is looked up in the catalogue before anything is built from it; the files the
//!   workbench owns are no parameters a page may set, and a path a page sets lies inside the
//!   input or beside the parameter file (`keys.rs`);
//! - the undo steps are bounded by their bytes as well as their count (`steps.rs`);
//! - a build of OUT by another run is noticed by the manifest's fingerprint, and the next
//!   rebuild then trusts nothing it kept of OUT.

mod builds;
mod files;
mod keys;
mod log;
pub mod routes;
mod steps;
mod toml;

use std::collections::VecDeque;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::time::{Duration, Instant};

use edo_city::build::reuse::Fingerprints;
use edo_city::input::overrides::{self, Override, MAX_OVERRIDES_BYTES, MAX_ROWS};
use edo_city::output::gpkg::{plan_lots, LotDiff, PlanLots};
use edo_city::params::{Params, MAX_PARAMS_BYTES};

use super::designer::{refuse, Refusal};
use files::Disk;
pub use files::Files;
use steps::Steps;

/// How long a request waits for its build before answering that it is still building (the
/// page then follows `status`): well inside the server's 60 s limit on an answer that moves
/// no byte (`http::Limits::stall`), which closed a request waiting two minutes unanswered.
const WAIT: Duration = Duration::from_secs(45);
/// Failures remembered for the edits still waiting on them.
const MAX_FAILURES: usize = 64;

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
    /// The hypothesis OUT holds (the last one built); `None` until a build succeeded.
    good: Option<Hypothesis>,
    /// The hypothesis on disk, and what was last read or written of each file.
    saved: Hypothesis,
    disk: Disk,
    undo: Steps,
    redo: Steps,
    /// The newest edit's revision; the one OUT shows; the last one a build was tried for.
    requested: u64,
    built: u64,
    tried: u64,
    /// The latest failures, newest last, for the requests still waiting on them.
    failures: VecDeque<Failure>,
    busy: bool,
    changed_tiles: Vec<String>,
    /// The lots whose type, kura, house or trees the last build changed (as `compare
    /// --gpkg` finds them), their rings in metres from the build's origin.
    changed_lots: Vec<LotDiff>,
    /// The lots of what OUT holds, to find the next build's changes against.
    lots: Arc<PlanLots>,
    last_ms: u64,
    fingerprints: Arc<Fingerprints>,
    /// The sha256 of OUT's manifest as the workbench's last build left it.
    manifest: Option<[u8; 32]>,
    /// What the pages should know that is no error (OUT built by another run meanwhile).
    notice: Option<String>,
}

impl State {
    /// The last build's failure, while no build has succeeded since (a success builds a
    /// revision past every one a failure took back).
    fn error(&self) -> Option<&Failure> {
        self.failures.back().filter(|f| f.upto > self.built)
    }

    /// Before the first build: the hypothesis on disk, nothing built yet.
    fn new(saved: Hypothesis, disk: Disk, lots: Arc<PlanLots>) -> State {
        State {
            now: saved.clone(),
            good: None,
            saved,
            disk,
            undo: Steps::default(),
            redo: Steps::default(),
            requested: 1,
            built: 0,
            tried: 0,
            failures: VecDeque::new(),
            busy: false,
            changed_tiles: Vec::new(),
            changed_lots: Vec::new(),
            lots,
            last_ms: 0,
            fingerprints: Arc::new(Fingerprints::default()),
            manifest: None,
            notice: None,
        }
    }
}

/// A build that failed: the revisions after `after` up to `upto` did not build.
#[derive(Debug, Clone)]
struct Failure {
    /// The revision built when it failed.
    after: u64,
    /// The revision the build was for.
    rev: u64,
    /// The newest revision asked for when it failed: the edits made on top of it.
    upto: u64,
    message: String,
}

impl Failure {
    /// The answer to the edit of revision `rev`, one of those it took back.
    fn message_for(&self, rev: u64) -> String {
        match rev > self.rev {
            false => self.message.clone(),
            true => format!(
                "{} (this edit was made on top of revision {}, which did not build: both were \
                 taken back; make it again)",
                self.message, self.rev
            ),
        }
    }
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
        let swept = files.sweep();
        if swept > 0 {
            eprintln!(
                "removed {swept} temporary file(s) a killed save left beside the parameter file"
            );
        }
        let (saved, disk) = files.read()?;
        // The hypothesis must read as a build would read it, before anything is served.
        resolve(&files, &saved).map_err(|m| anyhow::anyhow!("{m}"))?;
        let lots = Arc::new(plan_lots(&place.out).unwrap_or_default());
        let wb = Arc::new(Workbench {
            files,
            place,
            state: Mutex::new(State::new(saved, disk, lots)),
            bell: Condvar::new(),
        });
        let builder = wb.clone();
        std::thread::Builder::new()
            .name("workbench builds".into())
            .spawn(move || builder.builds())?;
        Ok(wb)
    }

    fn lock(&self) -> MutexGuard<'_, State> {
        self.state.lock().unwrap_or_else(|e| e.into_inner())
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
            within_bounds(&next)?;
            resolve(&self.files, &next).map_err(|m| refuse(422, m))?;
            let now = std::mem::replace(&mut s.now, next);
            s.undo.push(now);
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
            let failed = s
                .failures
                .iter()
                .rev()
                .find(|f| f.after < rev && rev <= f.upto);
            if let Some(f) = failed {
                return Err(refuse(422, f.message_for(rev)));
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
            s = self.sleep(s, left);
        }
    }

    /// Waits for the bell, at most `left`.
    fn sleep<'a>(&self, s: MutexGuard<'a, State>, left: Duration) -> MutexGuard<'a, State> {
        self.bell
            .wait_timeout(s, left)
            .map_or_else(|e| e.into_inner().0, |r| r.0)
    }

    /// Waits until every build asked for has ended (or [`WAIT`] has passed: 503).
    fn idle<'a>(&self, mut s: MutexGuard<'a, State>) -> Result<MutexGuard<'a, State>, Refusal> {
        let deadline = Instant::now() + WAIT;
        while s.busy || s.tried < s.requested {
            let left = deadline.saturating_duration_since(Instant::now());
            if left.is_zero() {
                return Err(refuse(
                    503,
                    format!(
                        "revision {} is still building: nothing was saved; save again once it \
                         is built (the status shows it)",
                        s.requested
                    ),
                ));
            }
            s = self.sleep(s, left);
        }
        Ok(s)
    }

    /// Sets parameter `key` to `value` (null: back to the default).
    pub fn set(
        &self,
        base: Option<u64>,
        key: &str,
        value: &serde_json::Value,
    ) -> Result<Done, Refusal> {
        keys::check(self, key, value)?;
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
        overrides::check(&one)
            .map_err(|m| refuse(422, format!("lot `{}`: {m}", keys::excerpt(lot))))?;
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

    /// A new draw of everything random: the next `seed` (after the largest seed a parameter
    /// file can hold, TOML's largest integer, comes 0).
    pub fn reroll(&self, base: Option<u64>) -> Result<Done, Refusal> {
        let seed = {
            let s = self.lock();
            resolve(&self.files, &s.now).map_or(1, |p| p.seed)
        };
        self.set(base, "seed", &serde_json::json!(next_seed(seed)))
    }

    /// Keeps `section`'s draw (its own seed, `[seeds]`, set to the one it draws from now) or
    /// lets it follow `seed` again.
    pub fn keep_draw(&self, base: Option<u64>, section: &str, keep: bool) -> Result<Done, Refusal> {
        if !edo_city::params::SEED_SECTIONS.contains(&section) {
            return Err(refuse(
                400,
                format!(
                    "`{}` draws from no seed of its own: give one of {}",
                    keys::excerpt(section),
                    edo_city::params::SEED_SECTIONS.join(", ")
                ),
            ));
        }
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

    /// Writes the hypothesis as it built: the parameter file, its overrides, the log, as one
    /// transaction. The builds asked for end first (a save during a failing edit writes what
    /// the build took back to, never what it refused); a build of OUT by another run since
    /// is made again first, so that OUT holds what is saved.
    pub fn save(&self) -> Result<serde_json::Value, Refusal> {
        let mut s = self.idle(self.lock())?;
        if s.good.is_some() && self.out_changed(&s) {
            s.requested += 1;
            self.bell.notify_all();
            s = self.idle(s)?;
        }
        let target = s.good.clone().unwrap_or_else(|| s.saved.clone());
        if target != s.now {
            return Err(refuse(
                409,
                "the hypothesis did not build as it stands: nothing was saved; see the error, \
                 undo or make the edit again"
                    .into(),
            ));
        }
        let (lines, disk) = self.files.save(&s.disk, &s.saved, &target)?;
        s.disk = disk;
        s.saved = target;
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
            "error": s.error().map(|f| f.message.clone()),
            "notice": s.notice,
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

    /// The input directory the builds read.
    pub fn input(&self) -> &Path {
        &self.place.input
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

/// Refuses a hypothesis that `build --params` would not read once saved: a parameter file
/// over the build's bound, or more overrides than a build reads.
fn within_bounds(h: &Hypothesis) -> Result<(), Refusal> {
    if h.text.len() as u64 > MAX_PARAMS_BYTES {
        return Err(refuse(
            413,
            format!(
                "the parameter file would be {} bytes, more than the {MAX_PARAMS_BYTES} a build \
                 reads",
                h.text.len()
            ),
        ));
    }
    // Each row's CSV is at most its text twice (every quote doubled) and its separators.
    let most: usize = (h.rows.iter())
        .map(|o| 2 * (o.lot.len() + o.field.len() + o.value.len()) + 9)
        .sum();
    let over = h.rows.len() > MAX_ROWS
        || (most as u64 > MAX_OVERRIDES_BYTES
            && overrides::to_csv(&h.rows).len() as u64 > MAX_OVERRIDES_BYTES);
    match over {
        true => Err(refuse(
            413,
            format!(
                "the overrides would be more than a build reads ({MAX_ROWS} rows, \
                 {MAX_OVERRIDES_BYTES} bytes): fold them into the lots' table"
            ),
        )),
        false => Ok(()),
    }
}

/// The seed after `seed`: the largest a TOML integer holds is followed by 0 (a seed past it
/// would be written as a float, which no build reads).
fn next_seed(seed: u64) -> u64 {
    match seed >= i64::MAX as u64 {
        true => 0,
        false => seed + 1,
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_seed_after_the_largest_is_one_toml_holds() {
        assert_eq!(next_seed(1), 2);
        assert_eq!(next_seed(i64::MAX as u64 - 1), i64::MAX as u64);
        assert_eq!(next_seed(i64::MAX as u64), 0);
        assert_eq!(next_seed(u64::MAX), 0);
    }

    #[test]
    fn an_edit_taken_back_with_the_one_below_it_says_so() {
        let f = Failure {
            after: 1,
            rev: 2,
            upto: 3,
            message: "no lot has the id `x`".into(),
        };
        assert_eq!(f.message_for(2), "no lot has the id `x`");
        assert!(f.message_for(3).contains("made on top of revision 2"));
    }

    #[test]
    fn a_hypothesis_past_what_a_build_reads_is_refused() {
        let mut h = Hypothesis {
            text: "x".repeat(MAX_PARAMS_BYTES as usize + 1),
            rows: Vec::new(),
        };
        assert_eq!(within_bounds(&h).unwrap_err().status, 413);
        h.text = "seed = 1\n".into();
        assert!(within_bounds(&h).is_ok());
        h.rows = vec![
            Override {
                lot: "1".into(),
                field: "mtype".into(),
                value: "x".repeat(1000),
                row: 2,
            };
            70_000
        ];
        assert_eq!(within_bounds(&h).unwrap_err().status, 413);
    }
}
