//! Random bytes at every reader of user files: shapefile (.shp, .shx, .dbf), CSV and XLSX
//! (the zip, and the XML inside it re-zipped so that damage gets past the zip's checksums).
//! Each reader either reads or returns an error naming the file; none panics. Seeded, so a
//! failure is repeatable; `EDO_CITY_FUZZ_CASES` runs more cases than the default.

mod common;

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;

use common::{fixture, rezip};
use edo_city::input::table::{read_csv, read_xlsx};
use rand::{Rng, RngExt, SeedableRng};
use rand_pcg::Pcg64;

fn cases() -> usize {
    std::env::var("EDO_CITY_FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(150)
}

/// One random kind of damage: a cut, overwritten bytes, inserted bytes, a repeated chunk, or
/// nothing but noise.
fn damage(rng: &mut Pcg64, good: &[u8]) -> Vec<u8> {
    let mut b = good.to_vec();
    let len = b.len().max(1);
    match rng.random_range(0..5) {
        0 => b.truncate(rng.random_range(0..len)),
        1 => {
            for _ in 0..rng.random_range(1..6) {
                let at = rng.random_range(0..len);
                let n = rng.random_range(1..32);
                for byte in b.iter_mut().skip(at).take(n) {
                    *byte = rng.random();
                }
            }
        }
        2 => {
            let at = rng.random_range(0..len);
            let noise: Vec<u8> = (0..rng.random_range(1..64)).map(|_| rng.random()).collect();
            b.splice(at.min(b.len())..at.min(b.len()), noise);
        }
        3 => {
            let (at, n) = (rng.random_range(0..len), rng.random_range(1..200));
            let chunk: Vec<u8> = b.iter().skip(at).take(n).cloned().collect();
            let to = rng.random_range(0..len).min(b.len());
            b.splice(to..to, chunk);
        }
        _ => {
            b = (0..rng.random_range(0..2 * len))
                .map(|_| rng.random())
                .collect();
        }
    }
    b
}

/// Runs `read` and checks it did not panic and, when it failed, named `name`.
fn must_not_panic<T, E: std::fmt::Display>(
    what: &str,
    name: &str,
    read: impl FnOnce() -> Result<T, E>,
) -> bool {
    match catch_unwind(AssertUnwindSafe(read)) {
        Err(_) => panic!("{what}: the reader panicked"),
        Ok(Ok(_)) => true,
        Ok(Err(e)) => {
            let message = e.to_string();
            assert!(
                message.contains(name),
                "{what}: `{message}` does not name {name}"
            );
            false
        }
    }
}

#[test]
fn random_bytes_at_the_shapefile_readers_never_panic() {
    let mut rng = Pcg64::seed_from_u64(20261123);
    let src = fixture("kyoto-small");
    let (mut read, mut refused) = (0, 0);
    for part in ["shp", "shx", "dbf"] {
        let good = std::fs::read(src.join(format!("lots.{part}"))).unwrap();
        for case in 0..cases() {
            let dir = tempfile::tempdir().unwrap();
            for ext in ["shp", "shx", "dbf", "cpg", "prj"] {
                std::fs::copy(
                    src.join(format!("lots.{ext}")),
                    dir.path().join(format!("lots.{ext}")),
                )
                .unwrap();
            }
            std::fs::write(
                dir.path().join(format!("lots.{part}")),
                damage(&mut rng, &good),
            )
            .unwrap();
            let path = dir.path().join("lots.shp");
            let what = format!("lots.{part} case {case}");
            if must_not_panic(&what, "lots", || {
                edo_city::input::shp::read_layer(&path, "")
            }) {
                read += 1;
            } else {
                refused += 1;
            }
        }
    }
    // Damage that leaves a readable layer reads (broken records are the next stage's to
    // skip); the rest is refused with the file named.
    assert!(read > 10 && refused > 100, "read {read}, refused {refused}");
}

#[test]
fn random_bytes_at_the_csv_reader_never_panic() {
    let mut rng = Pcg64::seed_from_u64(7);
    let good = std::fs::read(fixture("kyoto-small").join("lots.csv")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("lots.csv");
    let (mut read, mut refused) = (0, 0);
    for case in 0..cases() * 2 {
        std::fs::write(&path, damage(&mut rng, &good)).unwrap();
        if must_not_panic(&format!("lots.csv case {case}"), "lots.csv", || {
            read_csv(&path, "id")
        }) {
            read += 1;
        } else {
            refused += 1;
        }
    }
    assert!(read > 10 && refused > 10, "read {read}, refused {refused}");
}

/// A small workbook: a sheet `types` of ids and machiya types, with shared strings.
fn workbook(path: &Path) {
    let mut book = rust_xlsxwriter::Workbook::new();
    let sheet = book.add_worksheet().set_name("types").unwrap();
    sheet.write(0, 0, "id").unwrap();
    sheet.write(0, 1, "mtype").unwrap();
    sheet.write(0, 2, "height").unwrap();
    for r in 1..20u32 {
        sheet.write(r, 0, r).unwrap();
        sheet
            .write(r, 1, ["平屋", "看板建", "厨子二階"][r as usize % 3])
            .unwrap();
        sheet.write(r, 2, 6.5 + r as f64 / 10.0).unwrap();
    }
    book.save(path).unwrap();
}

#[test]
fn random_bytes_in_a_workbook_and_its_xml_never_panic() {
    let mut rng = Pcg64::seed_from_u64(11);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("lots.xlsx");
    workbook(&path);
    let good = std::fs::read(&path).unwrap();
    let names: Vec<String> = zip::ZipArchive::new(std::io::Cursor::new(&good[..]))
        .unwrap()
        .file_names()
        .map(|n| n.unwrap().to_string())
        .collect();
    assert!(
        names.iter().any(|n| n == "xl/worksheets/sheet1.xml"),
        "{names:?}"
    );
    let (mut read, mut refused) = (0, 0);
    for case in 0..cases() * 2 {
        let bytes = if case % 3 == 0 {
            damage(&mut rng, &good)
        } else {
            // Mostly the sheet and its strings, where the data is; sometimes any part.
            let entry = match rng.random_range(0..4) {
                0 | 1 => "xl/worksheets/sheet1.xml".to_string(),
                2 => "xl/sharedStrings.xml".to_string(),
                _ => names[rng.random_range(0..names.len())].clone(),
            };
            let seed = rng.next_u64();
            rezip(&good, &entry, |b| {
                damage(&mut Pcg64::seed_from_u64(seed), b)
            })
        };
        std::fs::write(&path, bytes).unwrap();
        let what = format!("lots.xlsx case {case}");
        if must_not_panic(&what, "lots.xlsx", || read_xlsx(&path, "types", "id")) {
            read += 1;
        } else {
            refused += 1;
        }
    }
    assert!(read > 10 && refused > 10, "read {read}, refused {refused}");
}
