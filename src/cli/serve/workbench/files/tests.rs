use super::*;
use serde_json::{json, Value};

fn lot(lot: &str, value: &str, row: usize) -> overrides::Override {
    overrides::Override {
        lot: lot.into(),
        field: "mtype".into(),
        value: value.into(),
        row,
    }
}

#[test]
fn a_save_logs_each_change_and_keeps_the_persons_text() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("hyp.toml");
    std::fs::write(&p, "# mine\nseed = 2\n").unwrap();
    let files = Files::of(&p).unwrap();
    assert_eq!(files.overrides, dir.path().join("hyp.overrides.csv"));
    let (saved, disk) = files.read().unwrap();
    let mut now = saved.clone();
    now.text = edit::set_key(&now.text, "kura.gap", &json!(2.5)).unwrap();
    now.rows.push(lot("7", "sangai", 2));
    let (n, disk) = files.save(&disk, &saved, &now).unwrap();
    assert_eq!(n, 2);
    assert_eq!(
        std::fs::read_to_string(&p).unwrap(),
        "# mine\nseed = 2\n\n[kura]\ngap = 2.5\n"
    );
    assert_eq!(files.read().unwrap().0.rows, now.rows);
    assert_eq!(
        files.read().unwrap().1,
        disk,
        "what is on disk is what was written"
    );
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
    // A second save appends to the log; the first lines stay as they were.
    let mut next = now.clone();
    next.rows.push(lot("8", "hiraya", 3));
    let (_, disk) = files.save(&disk, &now, &next).unwrap();
    let again = std::fs::read_to_string(&files.history).unwrap();
    assert!(
        again.starts_with(&log) && again.lines().count() == 3,
        "{again}"
    );
    // Another editor's change on disk is never overwritten.
    std::fs::write(&p, "seed = 9\n").unwrap();
    assert_eq!(files.save(&disk, &next, &now).unwrap_err().status, 409);
    assert_eq!(std::fs::read_to_string(&p).unwrap(), "seed = 9\n");
}

#[test]
fn a_row_added_by_hand_or_by_another_server_is_never_dropped() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("hyp.toml");
    std::fs::write(&p, "seed = 2\n").unwrap();
    let files = Files::of(&p).unwrap();
    let (saved, disk) = files.read().unwrap();
    let mut now = saved.clone();
    now.rows.push(lot("7", "sangai", 2));
    let (_, disk) = files.save(&disk, &saved, &now).unwrap();
    let by_hand = "lot,field,value\n7,mtype,sangai\n9,use,buke\n";
    std::fs::write(&files.overrides, by_hand).unwrap();
    let mut next = now.clone();
    next.rows.push(lot("8", "hiraya", 3));
    let e = files.save(&disk, &now, &next).unwrap_err();
    assert_eq!(e.status, 409);
    assert!(
        e.message.contains("hyp.overrides.csv changed on disk"),
        "{}",
        e.message
    );
    assert_eq!(std::fs::read_to_string(&files.overrides).unwrap(), by_hand);
    // The table removed by hand is a change too.
    std::fs::remove_file(&files.overrides).unwrap();
    assert_eq!(files.save(&disk, &now, &next).unwrap_err().status, 409);
}

#[test]
fn a_save_that_fails_at_any_file_writes_none_and_the_next_one_saves() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("hyp.toml");
    let before = "# mine\nseed = 2\n";
    std::fs::write(&p, before).unwrap();
    let files = Files::of(&p).unwrap();
    let (saved, disk) = files.read().unwrap();
    let mut now = saved.clone();
    now.text = edit::set_key(&now.text, "seed", &json!(3)).unwrap();
    now.rows.push(lot("7", "sangai", 2));
    // The log's name taken by a directory: the last file of the save fails.
    std::fs::create_dir(&files.history).unwrap();
    let e = files.save(&disk, &saved, &now).unwrap_err();
    assert_eq!(e.status, 500);
    assert!(e.message.ends_with("nothing was saved"), "{}", e.message);
    assert!(e.message.contains("hyp.history.jsonl"), "{}", e.message);
    assert_eq!(std::fs::read_to_string(&p).unwrap(), before);
    assert!(!files.overrides.exists());
    let names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(names.iter().all(|n| !n.contains(".tmp-")), "{names:?}");
    // Once the cause is gone, the same save goes through: "on disk" is what is on disk.
    std::fs::remove_dir(&files.history).unwrap();
    let (n, _) = files.save(&disk, &saved, &now).unwrap();
    assert_eq!(n, 2);
    assert!(std::fs::read_to_string(&p).unwrap().contains("seed = 3"));
    assert_eq!(files.read().unwrap().0.rows, now.rows);
}

#[test]
fn a_rename_that_fails_sets_back_the_files_renamed_before_it() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("hyp.toml");
    std::fs::write(&p, "seed = 2\n").unwrap();
    let files = Files::of(&p).unwrap();
    std::fs::write(&files.overrides, "lot,field,value\n1,mtype,hiraya\n").unwrap();
    std::fs::write(&files.history, "{\"old\":1}\n").unwrap();
    let (saved, disk) = files.read().unwrap();
    let mut now = saved.clone();
    now.text = "seed = 3\n".into();
    now.rows.push(lot("7", "sangai", 3));
    let mut t = Transaction::default();
    t.stage(
        &files.overrides,
        b"lot,field,value\n",
        Some(b"lot,field,value\n1,mtype,hiraya\n".to_vec()),
    )
    .unwrap();
    // The parameter file's temporary gone before its rename: the second rename fails.
    t.stage(&files.params, b"seed = 3\n", Some(b"seed = 2\n".to_vec()))
        .unwrap();
    t.append(&files.history, &[json!({"new": 3})]).unwrap();
    std::fs::remove_file(&t.staged[1].1).unwrap();
    let e = t.commit().unwrap_err();
    let message = t.undo(e);
    assert!(message.ends_with("nothing was saved"), "{message}");
    assert_eq!(
        std::fs::read_to_string(&files.overrides).unwrap(),
        "lot,field,value\n1,mtype,hiraya\n"
    );
    assert_eq!(std::fs::read_to_string(&p).unwrap(), "seed = 2\n");
    assert_eq!(
        std::fs::read_to_string(&files.history).unwrap(),
        "{\"old\":1}\n"
    );
    assert_eq!(files.read().unwrap().1, disk);
}

#[test]
fn a_killed_saves_temporaries_are_swept_and_nothing_else() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("hyp.toml");
    let files = Files::of(&p).unwrap();
    // No process has pid 4194305 (above Linux's largest).
    for name in [
        ".hyp.history.jsonl.tmp-4194305-12",
        ".hyp.toml.tmp-4194305-7",
        ".hyp.overrides.csv.tmp-4194305-1",
    ] {
        std::fs::write(dir.path().join(name), "half").unwrap();
    }
    let live = format!(".hyp.toml.tmp-{}-5", std::process::id());
    for keep in [
        ".other.toml.tmp-4194305-1",
        ".hyp.toml.tmp-x",
        live.as_str(),
        "hyp.toml",
    ] {
        std::fs::write(dir.path().join(keep), "keep").unwrap();
    }
    assert_eq!(files.sweep(), 3);
    let mut left: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    left.sort();
    assert_eq!(left.len(), 4, "{left:?}");
}

#[test]
fn overrides_in_a_geopackage_are_not_the_workbenchs_to_write() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("hyp.toml");
    std::fs::write(&p, "[input]\noverrides = \"corrections.gpkg\"\n").unwrap();
    let e = Files::of(&p).err().unwrap().to_string();
    assert!(e.contains("its overrides are a GeoPackage"), "{e}");
}

#[test]
fn a_file_that_is_not_text_is_named_for_what_it_is() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("lots.shp");
    std::fs::write(&p, [0u8, 0, 0x27, 0x0a, 0xff, 0xfe]).unwrap();
    let e = Files::of(&p).err().unwrap().to_string();
    assert!(
        e.contains("is not a text file") && e.contains("lots.shp"),
        "{e}"
    );
}
