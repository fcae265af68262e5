//! The workbench's files beside the parameter file `--edit` names: the parameter file
//! itself, its overrides (`<params>.overrides.csv`, unless the file names another) and its
//! revision log (`<params>.history.jsonl`, `log.rs`).
//!
//! A save is one transaction (issue 74): the new parameter file and overrides are written to
//! temporaries beside them, the log's lines appended, then the temporaries renamed over the
//! files; a failure at any step undoes the steps before it (the log cut back to its length,
//! an overrides file renamed already written back), so the files hold the whole save or
//! none of it. Before anything is written, both files are checked against what the
//! workbench last read or wrote of them (a sha256 of each): another editor's work, a second
//! server on the same file or a row added by hand, is never overwritten. Nothing else is
//! written.

use std::fs::{self, OpenOptions};
use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::Context;
use edo_city::input::overrides::{self, MAX_OVERRIDES_BYTES};
use edo_city::params::MAX_PARAMS_BYTES;
use sha2::{Digest, Sha256};

use super::super::designer::{refuse, Refusal};
use super::{log, toml as edit, Hypothesis};

/// The parameter file and the files beside it.
pub struct Files {
    /// The parameter file (absolute).
    pub params: PathBuf,
    /// Its overrides table.
    pub overrides: PathBuf,
    /// Its revision log.
    pub history: PathBuf,
}

/// What the workbench last read or wrote of its files: a sha256 of each, `None` when absent.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Disk {
    params: Option<[u8; 32]>,
    overrides: Option<[u8; 32]>,
}

/// A file as it is on disk now: its bytes, `None` when absent.
type Now = Option<Vec<u8>>;

impl Files {
    /// The files of the parameter file `params` (which need not exist yet: it is written at
    /// the first save). Its directory must exist.
    pub fn of(params: &Path) -> anyhow::Result<Files> {
        let params = super::absolute(params);
        let dir = params.parent().filter(|d| d.is_dir()).with_context(|| {
            format!("--edit {}: its directory does not exist", params.display())
        })?;
        if params.exists() && !params.is_file() {
            anyhow::bail!("--edit {}: not a file", params.display());
        }
        let stem = params
            .file_stem()
            .map_or_else(|| "params".into(), |s| s.to_string_lossy().into_owned());
        let text = match params.is_file() {
            true => read_params(&params)?,
            false => String::new(),
        };
        // A file that already names its overrides keeps them where it says.
        let overrides = match edit::get_key(&text, "input.overrides") {
            Some(serde_json::Value::String(f)) if !f.is_empty() => dir.join(f),
            _ => dir.join(format!("{stem}.overrides.csv")),
        };
        // A GeoPackage of overrides (a plan.gpkg edited in QGIS) is read by builds, but the
        // workbench writes its edits as CSV rows: it would write them over the package.
        if overrides
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("gpkg"))
        {
            anyhow::bail!(
                "--edit {}: its overrides are a GeoPackage ({}), which builds read but the \
                 workbench cannot write its lot edits to: start `serve --edit` on a parameter \
                 file whose `[input] overrides` names a CSV table (or nothing), or set the \
                 GeoPackage's changes in the page by lot",
                params.display(),
                overrides.display()
            );
        }
        Ok(Files {
            history: dir.join(format!("{stem}.history.jsonl")),
            overrides,
            params,
        })
    }

    /// The overrides' name as the parameter file gives it (beside it).
    pub fn overrides_name(&self) -> String {
        match (self.overrides.parent(), self.params.parent()) {
            (Some(a), Some(b)) if a == b => self
                .overrides
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default(),
            _ => self.overrides.display().to_string(),
        }
    }

    /// The hypothesis on disk, and what was read of each file.
    pub fn read(&self) -> anyhow::Result<(Hypothesis, Disk)> {
        let (params, over) = self.now().map_err(|m| anyhow::anyhow!("{m}"))?;
        let text = match &params {
            Some(b) => text_of(&self.params, b.clone())?,
            None => String::new(),
        };
        let rows = match &over {
            Some(b) => {
                let t = text_of(&self.overrides, b.clone())?;
                overrides::parse(&t, &self.overrides.display().to_string())?
            }
            None => Vec::new(),
        };
        let disk = Disk {
            params: params.as_deref().map(sha),
            overrides: over.as_deref().map(sha),
        };
        Ok((Hypothesis { text, rows }, disk))
    }

    /// The parameter file's and the overrides' bytes as they are now.
    fn now(&self) -> Result<(Now, Now), String> {
        let one = |path: &Path, cap: u64| -> Result<Now, String> {
            match fs::symlink_metadata(path) {
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
                _ => edo_city::bounded::read(path, cap)
                    .map(Some)
                    .map_err(|e| format!("cannot read {}: {e}", path.display())),
            }
        };
        Ok((
            one(&self.params, MAX_PARAMS_BYTES)?,
            one(&self.overrides, MAX_OVERRIDES_BYTES)?,
        ))
    }

    /// Removes the temporaries a killed save left beside the files (`.<file>.tmp-<pid>-<n>`
    /// of a process that is gone); their number.
    pub fn sweep(&self) -> usize {
        let mut swept = 0;
        for file in [&self.params, &self.overrides, &self.history] {
            let (Some(dir), Some(name)) = (file.parent(), file.file_name()) else {
                continue;
            };
            let prefix = format!(".{}.tmp-", name.to_string_lossy());
            let Ok(entries) = fs::read_dir(dir) else {
                continue;
            };
            for e in entries.flatten() {
                let name = e.file_name().to_string_lossy().into_owned();
                let Some(run) = name.strip_prefix(&prefix) else {
                    continue;
                };
                let pid = run.split('-').next().unwrap_or("");
                let ours = !pid.is_empty() && run.bytes().all(|b| b.is_ascii_digit() || b == b'-');
                let alive = Path::new("/proc").join(pid).exists();
                if ours && !alive && e.file_type().is_ok_and(|t| t.is_file()) {
                    swept += usize::from(fs::remove_file(e.path()).is_ok());
                }
            }
        }
        swept
    }

    /// Writes `now` over `saved`, all of it or nothing (see the module's doc), when the files
    /// are still what `disk` says; the number of changes logged and what is on disk after.
    pub fn save(
        &self,
        disk: &Disk,
        saved: &Hypothesis,
        now: &Hypothesis,
    ) -> Result<(usize, Disk), Refusal> {
        let (params_now, over_now) = self.now().map_err(|m| refuse(500, nothing(m)))?;
        for (path, was, is) in [
            (&self.params, disk.params, params_now.as_deref().map(sha)),
            (
                &self.overrides,
                disk.overrides,
                over_now.as_deref().map(sha),
            ),
        ] {
            if was != is {
                return Err(refuse(
                    409,
                    format!(
                        "{} changed on disk since the workbench read it (another editor, or a \
                         second `serve --edit` on the same file): nothing was saved; restart \
                         `serve --edit` to edit the file as it is now",
                        path.display()
                    ),
                ));
            }
        }
        let rows_bytes = (now.rows != saved.rows || (!now.rows.is_empty() && over_now.is_none()))
            .then(|| overrides::to_csv(&now.rows).into_bytes());
        let text_bytes =
            (now.text != saved.text || params_now.is_none()).then(|| now.text.clone().into_bytes());
        let lines = log::changes(saved, now);
        let mut t = Transaction::default();
        let result = (|| {
            if let Some(b) = &rows_bytes {
                t.stage(&self.overrides, b, over_now.clone())?;
            }
            if let Some(b) = &text_bytes {
                t.stage(&self.params, b, params_now.clone())?;
            }
            t.append(&self.history, &lines)?;
            t.commit()
        })();
        if let Err(message) = result {
            return Err(refuse(500, t.undo(message)));
        }
        let after = Disk {
            params: text_bytes.as_deref().or(params_now.as_deref()).map(sha),
            overrides: rows_bytes.as_deref().or(over_now.as_deref()).map(sha),
        };
        Ok((lines.len(), after))
    }
}

/// A save's writes so far, to be undone when a later one fails.
#[derive(Default)]
struct Transaction {
    /// Each file: its temporary, and its bytes before (`None`: it did not exist).
    staged: Vec<(PathBuf, PathBuf, Now)>,
    /// How many of them are renamed over their file.
    renamed: usize,
    /// The log and its length before the lines were appended.
    log: Option<(PathBuf, u64)>,
}

impl Transaction {
    /// Writes `bytes` to a temporary beside `path`, to its disk.
    fn stage(&mut self, path: &Path, bytes: &[u8], before: Now) -> Result<(), String> {
        let tmp = edo_city::output::atomic::temporary_for(path);
        let written = (|| {
            let mut f = fs::File::create(&tmp)?;
            f.write_all(bytes)?;
            f.sync_all()
        })();
        if let Err(e) = written {
            let _ = fs::remove_file(&tmp);
            return Err(format!("cannot write {}: {e}", path.display()));
        }
        self.staged.push((path.to_path_buf(), tmp, before));
        Ok(())
    }

    /// Appends `lines` to the log at `path` (a regular file, or none yet).
    fn append(&mut self, path: &Path, lines: &[serde_json::Value]) -> Result<(), String> {
        if lines.is_empty() {
            return Ok(());
        }
        let cannot = |e: &dyn std::fmt::Display| format!("cannot write {}: {e}", path.display());
        let len = match fs::symlink_metadata(path) {
            Ok(m) if m.is_file() => m.len(),
            Ok(_) => return Err(cannot(&"not a regular file")),
            Err(_) => 0,
        };
        let text: String = lines.iter().map(|l| format!("{l}\n")).collect();
        let mut f = OpenOptions::new()
            .append(true)
            .create(true)
            .open(path)
            .map_err(|e| cannot(&e))?;
        self.log = Some((path.to_path_buf(), len));
        f.write_all(text.as_bytes())
            .and_then(|()| f.sync_all())
            .map_err(|e| cannot(&e))
    }

    /// Renames every temporary over its file.
    fn commit(&mut self) -> Result<(), String> {
        for (path, tmp, _) in &self.staged[self.renamed..] {
            fs::rename(tmp, path).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
            self.renamed += 1;
        }
        Ok(())
    }

    /// Undoes what was done after `failure`; the message: nothing saved, or what could not
    /// be set back.
    fn undo(self, failure: String) -> String {
        let mut stuck = Vec::new();
        for (_, tmp, _) in &self.staged[self.renamed..] {
            let _ = fs::remove_file(tmp);
        }
        for (path, _, before) in &self.staged[..self.renamed] {
            let back = match before {
                Some(b) => edo_city::output::atomic::write_atomic(path, b),
                None => fs::remove_file(path),
            };
            if back.is_err() {
                stuck.push(path.display().to_string());
            }
        }
        if let Some((path, len)) = &self.log {
            let cut = OpenOptions::new()
                .write(true)
                .open(path)
                .and_then(|f| f.set_len(*len));
            if cut.is_err() {
                stuck.push(path.display().to_string());
            }
        }
        match stuck.is_empty() {
            true => nothing(failure),
            false => format!(
                "{failure}; {} could not be set back as it was (it holds this save's part): \
                 check it before saving again",
                stuck.join(" and ")
            ),
        }
    }
}

/// A failure's message, with nothing written.
fn nothing(failure: String) -> String {
    format!("{failure}; nothing was saved")
}

fn sha(bytes: &[u8]) -> [u8; 32] {
    Sha256::digest(bytes).into()
}

/// The parameter file's text, with the bound `build --params` reads it within.
fn read_params(path: &Path) -> anyhow::Result<String> {
    let bytes = edo_city::bounded::read(path, MAX_PARAMS_BYTES)
        .with_context(|| format!("cannot read {}", path.display()))?;
    text_of(path, bytes)
}

/// A file's bytes as text, or what it is instead.
fn text_of(path: &Path, bytes: Vec<u8>) -> anyhow::Result<String> {
    String::from_utf8(bytes).map_err(|_| {
        anyhow::anyhow!(
            "{} is not a text file (not UTF-8): --edit names a parameter file (.toml) of \
             your own, which the workbench reads and writes",
            path.display()
        )
    })
}

#[cfg(test)]
mod tests;
