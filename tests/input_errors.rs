//! Bad input: clear messages naming the file and the fix, exit code 2, or a warning and the
//! rest built.

mod common;

use common::*;
use predicates::prelude::*;

#[test]
fn unknown_parameter_key_names_key_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let params = dir.path().join("p.toml");
    std::fs::write(&params, "seed = 3\n[machiya]\ndepht = 10.0\n").unwrap();
    build_cmd(
        &fixture("kyoto-small"),
        &dir.path().join("out"),
        &["--params", params.to_str().unwrap()],
    )
    .assert()
    .code(2)
    .stderr(predicate::str::contains("depht").and(predicate::str::contains("line 3")));
    assert!(!dir.path().join("out").exists(), "nothing written");
}

#[test]
fn missing_lots_layer_says_which_file_and_key() {
    let dir = tempfile::tempdir().unwrap();
    build_cmd(dir.path(), &dir.path().join("out"), &[])
        .assert()
        .code(2)
        .stderr(
            predicate::str::contains("lots.shp").and(predicate::str::contains("layers.lots.file")),
        );
}

#[test]
fn missing_dbf_is_named() {
    let dir = tempfile::tempdir().unwrap();
    copy_fixture("kyoto-small", dir.path());
    std::fs::remove_file(dir.path().join("lots.dbf")).unwrap();
    build_cmd(dir.path(), &dir.path().join("out"), &[])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("lots.dbf").and(predicate::str::contains("missing")));
}

#[test]
fn type_mix_naming_an_unknown_type_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let params = dir.path().join("p.toml");
    std::fs::write(&params, "[type_mix]\nhiraya = 1.0\npagoda = 2.0\n").unwrap();
    build_cmd(
        &fixture("kyoto-small"),
        &dir.path().join("out"),
        &["--params", params.to_str().unwrap()],
    )
    .assert()
    .code(2)
    .stderr(predicate::str::contains("pagoda"));
}

#[test]
fn shift_jis_dbf_without_cpg_or_code_page_warns_and_names_the_file() {
    let dir = tempfile::tempdir().unwrap();
    copy_fixture("kyoto-small", dir.path());
    std::fs::remove_file(dir.path().join("lots.cpg")).unwrap();
    // Byte 29 of a DBF header is its code page; 0 = not stated, as in much older data.
    let dbf = dir.path().join("lots.dbf");
    let mut bytes = std::fs::read(&dbf).unwrap();
    bytes[29] = 0;
    std::fs::write(&dbf, bytes).unwrap();
    let report = build_ok(dir.path(), &dir.path().join("out"), &["--quiet"]);
    let warnings = report["warnings"].to_string();
    assert!(
        warnings.contains("lots.shp") && warnings.contains("shift_jis"),
        "{warnings}"
    );

    // The fix the warning names works: the same data with the encoding set decodes.
    let params = dir.path().join("p.toml");
    std::fs::write(&params, "[layers.lots]\nencoding = \"shift_jis\"\n").unwrap();
    let fixed = build_ok(
        dir.path(),
        &dir.path().join("out2"),
        &["--quiet", "--params", params.to_str().unwrap()],
    );
    assert!(!fixed["warnings"].to_string().contains("did not decode"));
    let original = build_ok(
        &fixture("kyoto-small"),
        &dir.path().join("out3"),
        &["--quiet"],
    );
    assert_eq!(fixed["counts"]["by_type"], original["counts"]["by_type"]);
}

#[test]
fn xlsx_table_joins_from_the_named_sheet() {
    let dir = tempfile::tempdir().unwrap();
    copy_fixture("kyoto-small", dir.path());
    std::fs::remove_file(dir.path().join("lots.csv")).unwrap();
    let mut book = rust_xlsxwriter::Workbook::new();
    book.add_worksheet().set_name("notes").unwrap();
    let sheet = book.add_worksheet().set_name("types").unwrap();
    sheet.write(0, 0, "id").unwrap();
    sheet.write(0, 1, "mtype").unwrap();
    sheet.write(1, 0, 7).unwrap();
    sheet.write(1, 1, "看板建").unwrap();
    sheet.write(2, 0, 123456).unwrap();
    sheet.write(2, 1, "平屋").unwrap();
    book.save(dir.path().join("lots.xlsx")).unwrap();

    let params = dir.path().join("p.toml");
    std::fs::write(&params, "[layers.lots]\nsheet = \"types\"\n").unwrap();
    let report = build_ok(
        dir.path(),
        &dir.path().join("out"),
        &["--quiet", "--params", params.to_str().unwrap()],
    );
    let join = &report["tables"][0];
    assert_eq!(join["rows"], 2);
    assert_eq!(join["matched"], 1);
    assert_eq!(join["rows_without_feature_ids"][0], "123456");
    let obj_text: String = std::fs::read_dir(dir.path().join("out/tiles"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "obj"))
        .map(|p| std::fs::read_to_string(p).unwrap())
        .collect();
    let start = obj_text.find("o machiya_7\n").expect("lot 7 built");
    let rest = &obj_text[start + 4..];
    let end = rest.find("\no ").unwrap_or(rest.len());
    assert!(
        rest[..end].contains("usemtl facade_kanban"),
        "lot 7 is a kanban-gatera"
    );

    // A sheet that is not there is an error that lists the sheets.
    std::fs::write(&params, "[layers.lots]\nsheet = \"lots\"\n").unwrap();
    build_cmd(
        dir.path(),
        &dir.path().join("out2"),
        &["--params", params.to_str().unwrap()],
    )
    .assert()
    .code(2)
    .stderr(predicate::str::contains("notes, types"));
}

#[test]
fn points_as_lots_are_refused_with_the_record() {
    let dir = tempfile::tempdir().unwrap();
    copy_fixture("kyoto-small", dir.path());
    let table = dbase::TableWriterBuilder::new()
        .add_character_field(dbase::FieldName::try_from("id").unwrap(), 10);
    let mut w = shapefile::Writer::from_path(dir.path().join("lots.shp"), table).unwrap();
    let mut rec = dbase::Record::default();
    rec.insert("id".into(), dbase::FieldValue::Character(Some("1".into())));
    w.write_shape_and_record(&shapefile::Point::new(0.0, 0.0), &rec)
        .unwrap();
    drop(w);
    build_cmd(dir.path(), &dir.path().join("out"), &[])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("lots.shp").and(predicate::str::contains("point")));
}

#[test]
fn check_reports_without_writing_and_says_by_its_exit_code() {
    // Clean input (the fixture without its table row that matches no lot): exit 0.
    let clean = tempfile::tempdir().unwrap();
    copy_fixture("kyoto-small", clean.path());
    std::fs::write(clean.path().join("lots.csv"), "id,mtype\n5,sangai\n").unwrap();
    edo_city()
        .arg("check")
        .arg(clean.path())
        .assert()
        .code(0)
        .stdout(predicate::str::contains("no problems").and(predicate::str::contains("Shift_JIS")));
    // The fixture as shipped: its row 9999 is a problem (exit 1) naming the table.
    edo_city()
        .arg("check")
        .arg(fixture("kyoto-small"))
        .assert()
        .code(1)
        .stdout(
            predicate::str::contains("lots table 9999")
                .and(predicate::str::contains("no lot has this id")),
        );
    // A type nobody knows: a warning, exit 1, and the lot named.
    let dir = tempfile::tempdir().unwrap();
    copy_fixture("kyoto-small", dir.path());
    std::fs::write(dir.path().join("lots.csv"), "id,mtype\n12,castle\n").unwrap();
    edo_city()
        .arg("check")
        .arg(dir.path())
        .assert()
        .code(1)
        .stdout(predicate::str::contains(
            "lot 12: unknown machiya type `castle`",
        ));
    assert!(!dir.path().join("out").exists(), "check writes nothing");
    // No lots layer: an error, exit 2.
    let empty = tempfile::tempdir().unwrap();
    edo_city().arg("check").arg(empty.path()).assert().code(2);
}
