//! The workbench's builder: one build at a time into OUT, of the newest edit, keeping the
//! tiles its fingerprints say would come out the same; the lots it changed found after it.
//!
//! What the fingerprints say of OUT holds only while the workbench is the one building it.
//! A `build --force` into OUT between two edits (OUT's lock keeps it out only while a build
//! runs) left the workbench keeping three tiles of another seed beside the one it made
//! (issue 74). So the builder keeps a sha256 of OUT's manifest as its own last build left
//! it, and a rebuild over a manifest that differs keeps nothing: every tile is made again.

use std::sync::Arc;
use std::time::{Duration, Instant};

use edo_city::build::reuse::Fingerprints;
use edo_city::build::{BuildOptions, NoProgress, Selection, Timings};
use edo_city::output::gpkg::{lot_differences, plan_lots, LotDiff};
use sha2::{Digest, Sha256};

use super::super::designer::{refuse, Refusal};
use super::{resolve, Failure, Hypothesis, State, Workbench, MAX_FAILURES};

impl Workbench {
    /// The builder's loop: the newest edit not tried yet, built; forever.
    pub(super) fn builds(&self) {
        loop {
            let (rev, hyp, before, lots, manifest) = {
                let mut s = self.lock();
                while s.tried == s.requested {
                    s = self.bell.wait(s).unwrap_or_else(|e| e.into_inner());
                }
                s.busy = true;
                (
                    s.requested,
                    s.now.clone(),
                    s.fingerprints.clone(),
                    s.lots.clone(),
                    s.manifest,
                )
            };
            let t = Instant::now();
            let outside = manifest.is_some() && manifest != self.manifest();
            let before = match outside {
                true => Arc::new(Fingerprints::default()),
                false => before,
            };
            let result = self.build(&hyp, before);
            // What changed, lot by lot, off the lock: the pages' polls go on meanwhile.
            // OUT's manifest read once: its fingerprint, and the origin the outlines need.
            let after = self.manifest_bytes();
            let manifest = after.as_deref().map(fingerprint);
            let t_lots = Instant::now();
            let new_lots = result
                .as_ref()
                .ok()
                .map(|_| plan_lots(&self.place.out).unwrap_or_default());
            let changed_lots = match &new_lots {
                Some(new) => outlines(lot_differences(&lots, new), origin(after.as_deref())),
                None => Vec::new(),
            };
            if let Ok((_, made, timings)) = &result {
                log_rebuild(rev, made.len(), t.elapsed(), timings, t_lots.elapsed());
            }
            let result = result.map(|(marks, made, _)| (marks, made));
            let mut s = self.lock();
            s.busy = false;
            s.tried = rev;
            if outside {
                let note = format!(
                    "{} was built by another run since revision {}: revision {rev} made every \
                     tile again",
                    self.place.out.display(),
                    s.built
                );
                eprintln!("{note}");
                s.notice = Some(note);
            } else if result.is_ok() {
                s.notice = None;
            }
            match result {
                Ok((marks, made)) => {
                    s.built = rev;
                    s.good = Some(hyp);
                    s.changed_tiles = made;
                    s.changed_lots = changed_lots;
                    s.lots = Arc::new(new_lots.unwrap_or_default());
                    s.last_ms = t.elapsed().as_millis() as u64;
                    s.fingerprints = Arc::new(marks);
                    s.manifest = manifest;
                }
                Err(message) => failed(&mut s, rev, message),
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

    /// OUT's manifest as it is now (`None`: none, or unreadable).
    fn manifest_bytes(&self) -> Option<Vec<u8>> {
        edo_city::bounded::read(&self.place.out.join("manifest.json"), 2 << 30).ok()
    }

    /// The sha256 of OUT's manifest as it is now.
    fn manifest(&self) -> Option<[u8; 32]> {
        self.manifest_bytes().as_deref().map(fingerprint)
    }

    /// Whether OUT's manifest is no longer the one the workbench's last build wrote.
    pub(super) fn out_changed(&self, s: &State) -> bool {
        s.manifest.is_some() && s.manifest != self.manifest()
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
        let origin = origin(self.manifest_bytes().as_deref());
        Ok(outlines(lot_differences(&other, &now), origin))
    }
}

/// A manifest's fingerprint: the sha256 of its bytes.
fn fingerprint(bytes: &[u8]) -> [u8; 32] {
    Sha256::digest(bytes).into()
}

/// The output origin a manifest gives (0, 0 without one).
fn origin(manifest: Option<&[u8]>) -> [f64; 2] {
    manifest
        .and_then(|b| serde_json::from_slice::<serde_json::Value>(b).ok())
        .map_or([0.0, 0.0], |m| {
            [
                m["origin"][0].as_f64().unwrap_or(0.0),
                m["origin"][1].as_f64().unwrap_or(0.0),
            ]
        })
}

/// The lots' rings moved to metres from the build's `origin` (the viewer's frame).
fn outlines(mut lots: Vec<LotDiff>, origin: [f64; 2]) -> Vec<LotDiff> {
    for l in &mut lots {
        for p in &mut l.ring {
            *p = [p[0] - origin[0], p[1] - origin[1]];
        }
    }
    lots
}

/// The build of revision `rev` failed with `message`: the hypothesis goes back to the last
/// one built, or, before any was, to the one on disk (the person's file as they wrote it,
/// never the defaults); the edits made on top of it go with it, and every request waiting
/// on any of them is answered.
fn failed(s: &mut State, rev: u64, message: String) {
    let f = Failure {
        after: s.built,
        rev,
        upto: s.requested,
        message,
    };
    s.failures.push_back(f);
    if s.failures.len() > MAX_FAILURES {
        s.failures.pop_front();
    }
    let back = s.good.clone().unwrap_or_else(|| s.saved.clone());
    while let Some(top) = s.undo.pop() {
        if top == back {
            break;
        }
    }
    s.now = back;
    s.tried = s.requested;
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

#[cfg(test)]
mod tests {
    use super::*;

    fn hyp(seed: u64) -> Hypothesis {
        Hypothesis {
            text: format!("seed = {seed}\n"),
            rows: Vec::new(),
        }
    }

    /// Revision `rev`'s edit, as `Workbench::edit` makes it.
    fn edit(s: &mut State, to: Hypothesis) -> u64 {
        let now = std::mem::replace(&mut s.now, to);
        s.undo.push(now);
        s.requested += 1;
        s.requested
    }

    #[test]
    fn a_failed_first_build_keeps_the_file_as_the_person_wrote_it() {
        let mut s = State::new(hyp(7), Default::default(), Default::default());
        failed(&mut s, 1, "no lot has the id `x`".into());
        assert_eq!(s.now, hyp(7), "not the defaults");
        assert_eq!((s.tried, s.requested), (1, 1));
    }

    #[test]
    fn the_edits_made_on_a_failing_build_are_taken_back_and_answered() {
        let mut s = State::new(hyp(1), Default::default(), Default::default());
        s.built = 1;
        s.tried = 1;
        s.good = Some(hyp(1));
        let failing = edit(&mut s, hyp(2));
        // Made while revision 2 builds, on top of it.
        let on_top = edit(&mut s, hyp(3));
        let and_another = edit(&mut s, hyp(4));
        failed(&mut s, failing, "no lot has the id `x`".into());
        assert_eq!(s.now, hyp(1));
        assert_eq!(s.undo.len(), 0);
        assert_eq!(s.tried, s.requested, "no build is left waiting for");
        let f = s.failures.back().unwrap().clone();
        for rev in [failing, on_top, and_another] {
            assert!(f.after < rev && rev <= f.upto, "{rev} is answered");
        }
        assert!(f.message_for(on_top).contains("on top of revision 2"));
        // The next edit builds on what OUT holds.
        assert_eq!(
            s.error().map(|e| e.rev),
            Some(failing),
            "the status shows it"
        );
        let next = edit(&mut s, hyp(5));
        assert!(next > f.upto);
        // Its build succeeds: no error shows.
        s.built = next;
        assert!(s.error().is_none());
        assert_eq!(s.undo.pop(), Some(hyp(1)));
    }
}
