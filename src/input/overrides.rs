//! The per-lot overrides `[input] overrides` names (issue 61): a CSV table `lot,field,value`
//! that the browser's workbench writes one edit a row, so that "what if this lot was a
//! sangai?" needs no edited DBF. Later rows win over earlier ones for the same lot and field.
//!
//! A row naming a lot the layer does not have, a field that is no field, or a use that is no
//! use stops the build with the file, the row and what to do: an override is a person's
//! deliberate edit, and building past it would show a city they did not ask for. The table
//! is listed in the report as a table joined to the lots (its rows, the lots it matched).

use std::collections::HashMap;
use std::path::Path;

use super::InputError;
pub use crate::model::overrides::Override;
use crate::model::{Lot, LotUse, TableJoin};

/// The largest overrides file read: a million edits of a few dozen bytes.
pub const MAX_OVERRIDES_BYTES: u64 = 64 << 20;
/// The most rows an overrides file may hold.
pub const MAX_ROWS: usize = 1_000_000;
/// The longest field name and value.
const MAX_TEXT: usize = 1000;
/// The lot fields edo-city itself decides from: set on the lot after the value maps.
pub const ROLES: [&str; 3] = ["use", "mtype", "district"];
/// The header an overrides file begins with.
pub const HEADER: [&str; 3] = ["lot", "field", "value"];

/// The rows of an overrides file's text, checked; `file` names it in errors.
pub fn parse(text: &str, file: &str) -> Result<Vec<Override>, InputError> {
    let bad = |row: usize, message: String| InputError::Table {
        file: file.to_string(),
        message: format!("row {row}: {message}"),
    };
    let text = text.trim_start_matches('\u{feff}');
    let mut reader = csv::ReaderBuilder::new()
        .flexible(false)
        .from_reader(text.as_bytes());
    let headers: Vec<String> = reader
        .headers()
        .map_err(|e| bad(1, format!("cannot read the header: {e}")))?
        .iter()
        .map(|h| h.trim().to_lowercase())
        .collect();
    if headers != HEADER {
        return Err(bad(
            1,
            format!(
                "the header must be `lot,field,value`, got `{}`",
                headers.join(",")
            ),
        ));
    }
    let mut rows = Vec::new();
    for (n, record) in reader.records().enumerate() {
        let row = n + 2;
        let record = record.map_err(|e| bad(row, e.to_string()))?;
        if rows.len() >= MAX_ROWS {
            return Err(bad(
                row,
                format!("more than {MAX_ROWS} overrides: fold them into the lots' table"),
            ));
        }
        let cell = |i: usize| unguard(record.get(i).unwrap_or("").trim()).to_string();
        let o = Override {
            lot: cell(0),
            field: cell(1),
            value: cell(2),
            row,
        };
        check(&o).map_err(|m| bad(row, m))?;
        rows.push(o);
    }
    Ok(rows)
}

/// What is wrong with one row on its own, if anything (the lot's existence is the build's
/// to check: only the input knows its lots).
pub fn check(o: &Override) -> Result<(), String> {
    if o.lot.is_empty() {
        return Err("no lot id".into());
    }
    if o.field.is_empty() || o.field.len() > 64 || o.field.chars().any(char::is_control) {
        return Err(format!(
            "`{}` is not a field name (up to 64 characters, no control characters)",
            o.field
        ));
    }
    if o.value.len() > MAX_TEXT || o.lot.len() > MAX_TEXT {
        return Err(format!("a value longer than {MAX_TEXT} bytes"));
    }
    if o.field == "use" {
        use_of(&o.value)?;
    }
    Ok(())
}

/// A use an override may give: one edo-city knows, or `other`.
pub fn use_of(value: &str) -> Result<LotUse, String> {
    match LotUse::parse(value) {
        LotUse::Other(v) if !v.eq_ignore_ascii_case("other") => Err(format!(
            "`{value}` is not a lot use: give machiya, buke, kuge, jisha or other"
        )),
        u => Ok(u),
    }
}

/// The overrides as a CSV table, header first, one row an edit, as [`parse`] reads it.
/// A cell a spreadsheet would take for a formula is guarded ([`guard`]).
pub fn to_csv(rows: &[Override]) -> String {
    let mut w = csv::Writer::from_writer(Vec::new());
    let _ = w.write_record(HEADER);
    for o in rows {
        let cells = [guard(&o.lot), guard(&o.field), guard(&o.value)];
        let _ = w.write_record(cells.iter().map(|c| c.as_bytes()));
    }
    let bytes = w.into_inner().unwrap_or_default();
    String::from_utf8(bytes).unwrap_or_default()
}

/// The first characters that make a spreadsheet read a cell as a formula (CWE-1236).
const FORMULA: [char; 4] = ['=', '+', '-', '@'];

/// Whether `cell` is a formula's start behind any number of `'`: the cells [`guard`] guards.
fn guarded(cell: &str) -> bool {
    cell.trim_start_matches('\'').starts_with(FORMULA)
}

/// A cell as written to the overrides table: one that a spreadsheet opening the table would
/// run as a formula (`=`, `+`, `-`, `@` first, as OWASP's CSV injection page lists them) gets
/// a `'` in front, which spreadsheets show as text; [`unguard`] takes it off again, so
/// every value comes back as it went in (a value that already begins with `'` and then a
/// formula's start gets one more, and loses just that one).
pub fn guard(cell: &str) -> std::borrow::Cow<'_, str> {
    match guarded(cell) {
        true => format!("'{cell}").into(),
        false => cell.into(),
    }
}

/// A cell as [`guard`] wrote it, back as it was.
pub fn unguard(cell: &str) -> &str {
    match cell.strip_prefix('\'') {
        Some(rest) if guarded(rest) => rest,
        _ => cell,
    }
}

/// Reads the file `[input] overrides` names, if any (or takes the rows given in memory):
/// its label for the report and its rows.
pub(super) fn read(
    input: &crate::params::InputParams,
) -> Result<Option<(String, Vec<Override>)>, InputError> {
    let name = input.overrides.as_str();
    if let Some(rows) = &input.rows {
        return Ok(Some((label_of(name), rows.as_ref().clone())));
    }
    if name.is_empty() {
        return Ok(None);
    }
    if name.to_lowercase().ends_with(".gpkg") {
        let label = label_of(name);
        return from_geopackage(Path::new(name), &input.overrides_layer, &label)
            .map(|rows| Some((label, rows)));
    }
    let text = crate::bounded::read_text(Path::new(name), MAX_OVERRIDES_BYTES).map_err(|e| {
        InputError::Table {
            file: name.to_string(),
            message: format!(
                "the overrides file {e}: `input.overrides` names it, relative to the parameter \
                 file (`edo-city serve OUT --edit PARAMS.toml` writes one)"
            ),
        }
    })?;
    let label = label_of(name);
    Ok(Some((label.clone(), parse(&text, &label)?)))
}

/// The columns of a GeoPackage layer read as overrides, and the field each gives: a
/// build's plan.gpkg names a lot's machiya type `type`, a person's own layer may say `mtype`.
const GPKG_FIELDS: [(&str, &str); 5] = [
    ("type", "mtype"),
    ("mtype", "mtype"),
    ("use", "use"),
    ("district", "district"),
    ("storeys", "storeys"),
];

/// The overrides a GeoPackage layer gives (a build's plan.gpkg edited in QGIS, issue 77):
/// for each row, its lot (`id`) and each of [`GPKG_FIELDS`] it fills, one override each,
/// checked as a CSV row is. A lot given the values the build decided builds as it did, so
/// only the lots changed in QGIS change.
fn from_geopackage(path: &Path, layer: &str, label: &str) -> Result<Vec<Override>, InputError> {
    let layer = match layer.trim() {
        "" => "lots",
        l => l,
    };
    let (headers, rows) = super::gpkg::attribute_rows(path, layer)?;
    let bad = |row: usize, message: String| InputError::Table {
        file: label.to_string(),
        message: format!("layer `{layer}` row {row}: {message}"),
    };
    let id = ["id", "lot"]
        .iter()
        .find_map(|c| headers.iter().position(|h| h == c))
        .ok_or_else(|| {
            bad(
                1,
                format!("no `id` column (columns: {})", headers.join(", ")),
            )
        })?;
    let columns: Vec<(usize, &str)> = (headers.iter().enumerate())
        .filter_map(|(i, h)| {
            (GPKG_FIELDS.iter())
                .find(|(c, _)| c == h)
                .map(|(_, field)| (i, *field))
        })
        .collect();
    let mut out = Vec::new();
    for (row, values) in rows {
        let lot = values.get(id).map_or("", |v| v.trim());
        for &(i, field) in &columns {
            let value = values.get(i).map_or("", |v| v.trim());
            if value.is_empty() || lot.is_empty() {
                continue;
            }
            if out.len() >= MAX_ROWS {
                return Err(bad(row, format!("more than {MAX_ROWS} overrides")));
            }
            let o = Override {
                lot: lot.to_string(),
                field: field.to_string(),
                value: value.to_string(),
                row,
            };
            check(&o).map_err(|m| bad(row, m))?;
            out.push(o);
        }
    }
    Ok(out)
}

/// The overrides file by its name alone: it may lie outside the input, and a build publishes
/// no one's directories.
fn label_of(name: &str) -> String {
    match Path::new(name).file_name() {
        Some(n) => n.to_string_lossy().into_owned(),
        None if name.is_empty() => "overrides".into(),
        None => name.to_string(),
    }
}

/// Where each override lands: the lots by id (a record id reaches each of its parts); an
/// error names the first row whose lot the layer does not have.
fn targets(
    lots: &[Lot],
    base_ids: &[String],
    rows: &[Override],
    file: &str,
) -> Result<Vec<Vec<usize>>, InputError> {
    let mut index: HashMap<&str, Vec<usize>> = HashMap::new();
    for (i, (lot, base)) in lots.iter().zip(base_ids).enumerate() {
        index.entry(base.as_str()).or_default().push(i);
        if lot.id != *base {
            index.entry(lot.id.as_str()).or_default().push(i);
        }
    }
    rows.iter()
        .map(|o| {
            index
                .get(o.lot.as_str())
                .cloned()
                .ok_or_else(|| InputError::Table {
                    file: file.to_string(),
                    message: format!(
                    "row {}: no lot has the id `{}`: remove the row, or give an id of the lots \
                     layer",
                    o.row, o.lot
                ),
                })
        })
        .collect()
}

/// The attribute rows applied to the lots (before the lots' fields are read from their
/// attributes, so a template's attribute and a mapped field see them); the table's entry
/// for the report.
pub(super) fn apply_attributes(
    lots: &mut [Lot],
    base_ids: &[String],
    rows: &[Override],
    file: &str,
) -> Result<TableJoin, InputError> {
    let at = targets(lots, base_ids, rows, file)?;
    let mut names = crate::model::FieldNames::default();
    let mut matched = vec![false; lots.len()];
    for (o, at) in rows.iter().zip(&at) {
        for &i in at {
            matched[i] = true;
            if !ROLES.contains(&o.field.as_str()) {
                lots[i]
                    .attrs
                    .insert(names.intern(&o.field), o.value.as_str());
            }
        }
    }
    Ok(TableJoin {
        layer: "lots".into(),
        file: file.to_string(),
        rows: rows.len(),
        matched: rows.len(),
        rows_without_feature: 0,
        rows_without_feature_ids: Vec::new(),
        features_without_row: matched.iter().filter(|m| !**m).count(),
    })
}

/// The role rows (use, type, district) applied to the lots, after their fields were read:
/// an override gives edo-city's own value, not the data's raw one a value map would turn.
pub(super) fn apply_roles(
    lots: &mut [Lot],
    base_ids: &[String],
    rows: &[Override],
    file: &str,
) -> Result<(), InputError> {
    let at = targets(lots, base_ids, rows, file)?;
    let some = |v: &str| (!v.is_empty()).then(|| v.to_string());
    for (o, at) in rows.iter().zip(&at) {
        for &i in at {
            let lot = &mut lots[i];
            match o.field.as_str() {
                "use" => lot.lot_use = use_of(&o.value).unwrap_or(LotUse::Machiya),
                "mtype" => lot.mtype = some(&o.value),
                "district" => lot.district = some(&o.value),
                _ => {}
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_read_back_as_written() {
        let rows = vec![
            Override {
                lot: "12_3".into(),
                field: "mtype".into(),
                value: "sangai".into(),
                row: 2,
            },
            Override {
                lot: "a,b \"c\"".into(),
                field: "storeys".into(),
                value: "3".into(),
                row: 3,
            },
        ];
        let text = to_csv(&rows);
        assert!(text.starts_with("lot,field,value\n"), "{text}");
        assert_eq!(parse(&text, "o.csv").unwrap(), rows);
        assert!(parse("lot,field,value\n", "o.csv").unwrap().is_empty());
    }

    #[test]
    fn no_cell_is_written_as_a_spreadsheet_formula_and_each_reads_back() {
        let values = [
            "=1+2",
            "@SUM(A1)",
            "-3",
            "+x",
            "'=x",
            "''@y",
            "'plain",
            "=a,b \"c\"",
        ];
        let rows: Vec<Override> = (values.iter().enumerate())
            .map(|(i, v)| Override {
                lot: v.to_string(),
                field: "district".into(),
                value: v.to_string(),
                row: i + 2,
            })
            .collect();
        let text = to_csv(&rows);
        let mut reader = csv::Reader::from_reader(text.as_bytes());
        for record in reader.records() {
            for cell in record.unwrap().iter() {
                assert!(!cell.starts_with(FORMULA), "{cell} in {text}");
            }
        }
        assert_eq!(parse(&text, "o.csv").unwrap(), rows);
        assert_eq!(unguard("'plain"), "'plain");
        assert_eq!(guard("sangai"), "sangai");
    }

    #[test]
    fn bad_rows_are_named_with_what_to_do() {
        let err = |t: &str| parse(t, "o.csv").unwrap_err().to_string();
        assert!(err("id,f,v\n").contains("row 1: the header must be"));
        let e = err("lot,field,value\n1,use,castle\n");
        assert!(
            e.contains("o.csv") && e.contains("row 2") && e.contains("`castle`"),
            "{e}"
        );
        assert!(err("lot,field,value\n,use,buke\n").contains("no lot id"));
        assert!(err("lot,field,value\n1,,buke\n").contains("not a field name"));
        assert!(err("lot,field,value\n1,use\n").contains("row 2"));
        assert!(use_of("武家地").is_ok() && use_of("Other").is_ok());
    }
}
