//! The revision log `<params>.history.jsonl`: one line a change a save writes, `{time, key,
//! old, new}` (and `lot` for a lot's field), appended: the log is never read back or written
//! whole (at 20 MB, a save that rewrote it cost 20 MB of writes, and a killed save left its
//! whole temporary behind: issue 74).

use std::collections::BTreeMap;

use serde_json::{json, Value};

use super::Hypothesis;

/// One log line per key whose value differs between the two texts, and per lot field whose
/// override differs; `time` is the save's, in UTC.
pub fn changes(before: &Hypothesis, after: &Hypothesis) -> Vec<Value> {
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
    fn seconds_read_as_dates() {
        assert_eq!(utc(0), "1970-01-01T00:00:00Z");
        assert_eq!(utc(951_782_400), "2000-02-29T00:00:00Z");
        assert_eq!(utc(1_796_083_199), "2026-11-30T23:59:59Z");
    }

    #[test]
    fn each_changed_key_and_lot_field_is_one_line() {
        let before = Hypothesis {
            text: "seed = 1\n[kura]\ngap = 2.0\n".into(),
            rows: Vec::new(),
        };
        let mut after = before.clone();
        after.text = "seed = 1\n[kura]\ngap = 3.0\n".into();
        after.rows.push(edo_city::input::overrides::Override {
            lot: "7".into(),
            field: "use".into(),
            value: "buke".into(),
            row: 2,
        });
        let lines = changes(&before, &after);
        assert_eq!(lines.len(), 2);
        assert_eq!(
            (lines[0]["key"].as_str(), &lines[0]["new"]),
            (Some("kura.gap"), &json!(3.0))
        );
        assert_eq!(lines[1]["lot"], "7");
        assert!(changes(&before, &before).is_empty());
    }
}
