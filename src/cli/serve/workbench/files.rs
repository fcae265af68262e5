//! The workbench's files beside the parameter file `--edit` names: the parameter file
//! itself, its overrides (`<params>.overrides.csv`, unless the file names another) and its
//! revision log (`<params>.history.jsonl`: one line a change, `{time, key, old, new}`, and
//! `lot` for a lot's field). Each is written whole, a temporary renamed over it; nothing
//! else is written.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::Context;
use edo_city::input::overrides::{self, MAX_OVERRIDES_BYTES};
use serde_json::{json, Value};

use super::super::designer::{refuse, Refusal};
use super::{toml as edit, Hypothesis};

/// The largest parameter file or revision log read.
const MAX_TEXT: u64 = 64 << 20;

/// The parameter file and the files beside it.
pub struct Files {
    /// The parameter file (absolute).
    pub params: PathBuf,
    /// Its overrides table.
    pub overrides: PathBuf,
    /// Its revision log.
    pub history: PathBuf,
}

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
            true => read(&params)?,
            false => String::new(),
        };
        // A file that already names its overrides keeps them where it says.
        let overrides = match edit::get_key(&text, "input.overrides") {
            Some(Value::String(f)) if !f.is_empty() => dir.join(f),
            _ => dir.join(format!("{stem}.overrides.csv")),
        };
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

    /// The hypothesis on disk.
    pub fn read(&self) -> anyhow::Result<Hypothesis> {
        let text = match self.params.is_file() {
            true => read(&self.params)?,
            false => String::new(),
        };
        let rows = match self.overrides.is_file() {
            true => {
                let t = edo_city::bounded::read_text(&self.overrides, MAX_OVERRIDES_BYTES)
                    .with_context(|| format!("cannot read {}", self.overrides.display()))?;
                overrides::parse(&t, &self.overrides.display().to_string())?
            }
            false => Vec::new(),
        };
        Ok(Hypothesis { text, rows })
    }

    /// Writes `now` over `saved`: the overrides, then the parameter file naming them, then
    /// the log of what changed; the number of changes logged. Refused when the parameter
    /// file changed on disk since it was read (another editor's work is never overwritten).
    pub fn save(&self, saved: &Hypothesis, now: &Hypothesis) -> Result<usize, Refusal> {
        let on_disk = match self.params.is_file() {
            true => read(&self.params).map_err(|e| refuse(409, format!("{e:#}")))?,
            false => String::new(),
        };
        if on_disk != saved.text {
            return Err(refuse(
                409,
                format!(
                    "{} changed on disk since the workbench read it: nothing was saved; \
                     restart `serve --edit` to edit the new file",
                    self.params.display()
                ),
            ));
        }
        let write = |path: &Path, bytes: &[u8]| {
            edo_city::output::atomic::write_atomic(path, bytes).map_err(|e| {
                refuse(
                    500,
                    format!(
                        "cannot write {}: {e}; nothing else was written",
                        path.display()
                    ),
                )
            })
        };
        if now.rows != saved.rows || (!now.rows.is_empty() && !self.overrides.exists()) {
            write(&self.overrides, overrides::to_csv(&now.rows).as_bytes())?;
        }
        if now.text != saved.text || !self.params.exists() {
            write(&self.params, now.text.as_bytes())?;
        }
        let lines = changes(saved, now);
        if !lines.is_empty() {
            let mut log = match self.history.is_file() {
                true => read(&self.history).map_err(|e| refuse(500, format!("{e:#}")))?,
                false => String::new(),
            };
            for l in &lines {
                log += &format!("{l}\n");
            }
            write(&self.history, log.as_bytes())?;
        }
        Ok(lines.len())
    }
}

fn read(path: &Path) -> anyhow::Result<String> {
    edo_city::bounded::read_text(path, MAX_TEXT)
        .with_context(|| format!("cannot read {}", path.display()))
}

/// One log line per key whose value differs between the two texts, and per lot field whose
/// override differs; `time` is the save's, in UTC.
fn changes(before: &Hypothesis, after: &Hypothesis) -> Vec<Value> {
    let time = now_utc();
    let mut out = Vec::new();
    let (a, b) = (leaves(&before.text), leaves(&after.text));
    let keys: std::collections::BTreeSet<&String> = a.keys().chain(b.keys()).collect();
    for k in keys {
        if a.get(k) != b.get(k) {
            out.push(json!({"time": time, "key": k, "old": a.get(k), "new": b.get(k)}));
        }
    }
    let fields = |h: &Hypothesis| -> BTreeMap<(String, String), String> {
        (h.rows.iter())
            .map(|o| ((o.lot.clone(), o.field.clone()), o.value.clone()))
            .collect()
    };
    let (a, b) = (fields(before), fields(after));
    let keys: std::collections::BTreeSet<&(String, String)> = a.keys().chain(b.keys()).collect();
    for k in keys {
        if a.get(k) != b.get(k) {
            out.push(json!({
                "time": time, "lot": k.0, "key": k.1, "old": a.get(k), "new": b.get(k)
            }));
        }
    }
    out
}

/// Every key a parameter text sets (a table given whole, `type_mix`, as one).
pub fn leaves(text: &str) -> BTreeMap<String, Value> {
    let mut out = BTreeMap::new();
    if let Ok(t) = text.parse::<::toml::Table>() {
        if let Ok(v) = serde_json::to_value(t) {
            flatten(&v, "", &mut out);
        }
    }
    out
}

fn flatten(v: &Value, at: &str, out: &mut BTreeMap<String, Value>) {
    let name = at.rsplit('.').next().unwrap_or(at);
    match v {
        Value::Object(map) if !edo_city::params::catalogue::WHOLE.contains(&name) => {
            for (k, v) in map {
                let key = if at.is_empty() {
                    k.clone()
                } else {
                    format!("{at}.{k}")
                };
                flatten(v, &key, out);
            }
        }
        _ => {
            out.insert(at.to_string(), v.clone());
        }
    }
}

/// The time now as `YYYY-MM-DDTHH:MM:SSZ`.
fn now_utc() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs() as i64);
    utc(secs)
}

/// Seconds since 1970 as `YYYY-MM-DDTHH:MM:SSZ` (civil from days, Howard Hinnant's
/// algorithm: std has no calendar, and a date is all the log needs of one).
fn utc(secs: i64) -> String {
    let (days, rem) = (secs.div_euclid(86_400), secs.rem_euclid(86_400));
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!(
        "{y:04}-{m:02}-{d:02}T{:02}:{:02}:{:02}Z",
        rem / 3600,
        rem % 3600 / 60,
        rem % 60
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_save_logs_each_change_and_keeps_the_persons_text() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("hyp.toml");
        std::fs::write(&p, "# mine\nseed = 2\n").unwrap();
        let files = Files::of(&p).unwrap();
        assert_eq!(files.overrides, dir.path().join("hyp.overrides.csv"));
        let saved = files.read().unwrap();
        let mut now = saved.clone();
        now.text = edit::set_key(&now.text, "kura.gap", &json!(2.5)).unwrap();
        now.rows.push(overrides::Override {
            lot: "7".into(),
            field: "mtype".into(),
            value: "sangai".into(),
            row: 2,
        });
        assert_eq!(files.save(&saved, &now).unwrap(), 2);
        assert_eq!(
            std::fs::read_to_string(&p).unwrap(),
            "# mine\nseed = 2\n\n[kura]\ngap = 2.5\n"
        );
        assert_eq!(files.read().unwrap().rows, now.rows);
        let log = std::fs::read_to_string(&files.history).unwrap();
        let lines: Vec<Value> = log
            .lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect();
        assert_eq!(lines[0]["key"], "kura.gap");
        assert_eq!(
            (lines[0]["old"].clone(), lines[0]["new"].clone()),
            (Value::Null, json!(2.5))
        );
        assert_eq!(
            (lines[1]["lot"].as_str(), lines[1]["new"].as_str()),
            (Some("7"), Some("sangai"))
        );
        assert_eq!(lines[1]["time"].as_str().unwrap().len(), 20);
        // Another editor's change on disk is never overwritten.
        std::fs::write(&p, "seed = 9\n").unwrap();
        assert_eq!(files.save(&now, &saved).unwrap_err().status, 409);
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "seed = 9\n");
    }

    #[test]
    fn seconds_read_as_dates() {
        assert_eq!(utc(0), "1970-01-01T00:00:00Z");
        assert_eq!(utc(951_782_400), "2000-02-29T00:00:00Z");
        assert_eq!(utc(1_796_083_199), "2026-11-30T23:59:59Z");
    }
}
