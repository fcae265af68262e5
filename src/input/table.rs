//! Attribute tables (CSV or XLSX) joined to a layer on its id field.
//!
//! Historians keep attributes in spreadsheets; the paper's tool read any table Excel could
//! open. Values in the table win over the DBF's, since the table is what the user edits.

use std::collections::BTreeMap;
use std::path::Path;

use calamine::{Data, Reader};

use super::InputError;

/// A table as rows keyed by id; each row maps column name to text.
#[derive(Debug, Clone, Default)]
pub struct Table {
    /// The table's file.
    pub file: String,
    /// Rows in file order: (id, values), each id once.
    pub rows: Vec<(String, BTreeMap<String, String>)>,
    /// Rows not used, as the spreadsheet numbers them (the header is row 1), with the id
    /// and why: a repeated id (the first row with it is used), an id that is a date, no id.
    pub unusable: Vec<(usize, String, String)>,
    /// What the reader noticed and the user should know (ignored files, unnamed columns,
    /// formulas without values).
    pub warnings: Vec<crate::model::Warning>,
}

impl Table {
    /// A table from its header and rows (row numbers as the spreadsheet shows them): drops
    /// blank rows, lists rows with values but no id as unusable, keeps the first row of each id, and warns about columns without a
    /// name that hold values.
    fn assemble(
        path: &Path,
        headers: &[String],
        id_col: usize,
        rows: Vec<(usize, Vec<String>)>,
    ) -> Result<Table, InputError> {
        for (i, h) in headers.iter().enumerate() {
            if h.is_empty() {
                continue;
            }
            if let Some(j) = headers[i + 1..].iter().position(|x| x == h) {
                return Err(table_error(
                    path,
                    format!(
                        "columns {} and {} are both named `{h}`, so it is not clear which to \
                         use: rename one of them",
                        column_name(i),
                        column_name(i + j + 1)
                    ),
                ));
            }
        }
        let mut t = Table {
            file: path.display().to_string(),
            ..Table::default()
        };
        let unnamed: Vec<String> = (0..headers.len())
            .filter(|&i| headers[i].is_empty())
            .filter(|&i| {
                rows.iter()
                    .any(|(_, v)| v.get(i).is_some_and(|x| !x.is_empty()))
            })
            .map(column_name)
            .collect();
        if !unnamed.is_empty() {
            t.warnings.push(
                crate::model::Warning::new(
                    crate::model::WarningClass::Table,
                    format!(
                "{}: column(s) {} hold values but have no name in the header row (a merged \
                 header cell?); their values are not used: give each column a name of its own",
                t.file,
                unnamed.join(", ")
            ),
                )
                .in_file(&t.file),
            );
        }
        let mut first: std::collections::HashMap<String, usize> = Default::default();
        for (n, values) in rows {
            let (id, map) = make_row(headers, values, id_col);
            if id.is_empty() {
                // A blank row is no record; a row with values and no id is one, not used.
                if !map.is_empty() {
                    t.unusable.push((
                        n,
                        String::new(),
                        format!(
                            "the row has values but no `{}`: give it an id",
                            headers[id_col]
                        ),
                    ));
                }
                continue;
            }
            match first.get(&id) {
                Some(&row) => t.unusable.push((
                    n,
                    id,
                    format!(
                        "row {row} has the same id and was used; this row was not: merge the \
                         two rows or correct the id"
                    ),
                )),
                None => {
                    first.insert(id.clone(), n);
                    t.rows.push((id, map));
                }
            }
        }
        Ok(t)
    }
}

/// A spreadsheet's name for column `i` (from 0): A, B, ..., Z, AA, ...
fn column_name(i: usize) -> String {
    let mut n = i + 1;
    let mut out = Vec::new();
    while n > 0 {
        n -= 1;
        out.push(b'A' + (n % 26) as u8);
        n /= 26;
    }
    out.reverse();
    String::from_utf8(out).unwrap_or_default()
}

/// Finds `<base>.csv` or `<base>.xlsx` in `dir`; `Ok(None)` when neither exists.
pub fn find_and_read(
    dir: &Path,
    base: &str,
    sheet: &str,
    id_field: &str,
) -> Result<Option<Table>, InputError> {
    if base.trim().is_empty() {
        return Ok(None);
    }
    // A GeoPackage's attributes table (`sheet` names it, as it names a workbook's sheet).
    if base.trim().to_lowercase().ends_with(".gpkg") {
        let path = dir.join(base.trim());
        if !path.exists() {
            return Ok(None);
        }
        return read_gpkg(&path, sheet, id_field).map(Some);
    }
    let csv = dir.join(format!("{base}.csv"));
    let xlsx = dir.join(format!("{base}.xlsx"));
    if csv.exists() {
        let mut t = read_csv(&csv, id_field)?;
        if xlsx.exists() {
            t.warnings.push(
                crate::model::Warning::new(
                    crate::model::WarningClass::Table,
                    format!(
                "both {} and {} are there; the CSV was joined and the workbook ignored: remove \
                 or rename the one that is not current",
                csv.display(),
                xlsx.display()
            ),
                )
                .in_file(&t.file),
            );
        }
        Ok(Some(t))
    } else if xlsx.exists() {
        read_xlsx(&xlsx, sheet, id_field).map(Some)
    } else {
        Ok(None)
    }
}

/// Reads a GeoPackage's attributes table, as a workbook's sheet is read.
fn read_gpkg(path: &Path, table: &str, id_field: &str) -> Result<Table, InputError> {
    let (headers, rows) = super::gpkg::attribute_rows(path, table)?;
    let id_col = headers.iter().position(|h| h == id_field).ok_or_else(|| {
        table_error(
            path,
            format!(
                "no id column `{id_field}` (columns: {}); set `layers.lots.fields.id`",
                headers.join(", ")
            ),
        )
    })?;
    Table::assemble(path, &headers, id_col, rows)
}

/// The largest CSV table read (a million lots' attributes are about 100 MB).
const MAX_TABLE_BYTES: u64 = 4 << 30;

fn table_error(path: &Path, message: String) -> InputError {
    InputError::Table {
        file: path.display().to_string(),
        message,
    }
}

/// Reads a CSV table with a header row. A UTF-8 byte-order mark (Excel's export) is ignored.
pub fn read_csv(path: &Path, id_field: &str) -> Result<Table, InputError> {
    let bytes = crate::bounded::read(path, MAX_TABLE_BYTES)
        .map_err(|e| table_error(path, format!("the table {e}")))?;
    let text = match std::str::from_utf8(&bytes) {
        Ok(t) => t.trim_start_matches('\u{feff}').to_string(),
        // Excel on Japanese Windows saves CSV as Shift_JIS.
        Err(_) => encoding_rs::SHIFT_JIS.decode(&bytes).0.into_owned(),
    };
    let mut reader = csv::ReaderBuilder::new()
        .flexible(false)
        .from_reader(text.as_bytes());
    let headers: Vec<String> = reader
        .headers()
        .map_err(|e| table_error(path, format!("cannot read the header row: {e}")))?
        .iter()
        .map(|h| h.trim().to_string())
        .collect();
    let id_col = column(&headers, id_field, path)?;
    let mut rows = Vec::new();
    for (n, record) in reader.records().enumerate() {
        let record = record.map_err(|e| table_error(path, format!("row {}: {e}", n + 2)))?;
        rows.push((n + 2, record.iter().map(|v| v.trim().to_string()).collect()));
    }
    Table::assemble(path, &headers, id_col, rows)
}

/// Reads the named sheet (or the first) of an XLSX workbook, first row as header.
pub fn read_xlsx(path: &Path, sheet: &str, id_field: &str) -> Result<Table, InputError> {
    let file = crate::bounded::file(path)
        .map_err(|e| table_error(path, format!("cannot open the workbook: {e}")))?;
    let mut book: calamine::Xlsx<_> =
        calamine::open_workbook_from_rs(std::io::BufReader::new(file))
            .map_err(|e| table_error(path, format!("cannot open the workbook: {e}")))?;
    let names = book.sheet_names().to_vec();
    let name = if sheet.trim().is_empty() {
        names
            .first()
            .cloned()
            .ok_or_else(|| table_error(path, "the workbook has no sheet".into()))?
    } else if names.iter().any(|n| n == sheet) {
        sheet.to_string()
    } else {
        return Err(table_error(
            path,
            format!(
                "no sheet named `{sheet}` (the workbook has: {}); fix `sheet` in the parameter file",
                names.join(", ")
            ),
        ));
    };
    let range = book
        .worksheet_range(&name)
        .map_err(|e| table_error(path, format!("sheet `{name}`: {e}")))?;
    // Row numbers as the spreadsheet shows them: the range may start below row 1.
    let top = range.start().map_or(0, |(r, _)| r as usize);
    let left = range.start().map_or(0, |(_, c)| c as usize);
    let mut it = range.rows();
    let Some(header) = it.next() else {
        return Err(table_error(
            path,
            format!(
                "sheet `{name}` is empty (the workbook has: {}); put the table on the first \
                 sheet or name its sheet in `sheet`",
                names.join(", ")
            ),
        ));
    };
    // Columns left of the range are empty in the spreadsheet; keep the letters right.
    let headers: Vec<String> = std::iter::repeat_n(String::new(), left)
        .chain(header.iter().map(|c| cell_text(c).trim().to_string()))
        .collect();
    let id_col = column(&headers, id_field, path)?;
    let mut rows = Vec::new();
    let mut dates = Vec::new();
    for (k, r) in it.enumerate() {
        let n = top + k + 2;
        let values: Vec<String> = std::iter::repeat_n(String::new(), left)
            .chain(r.iter().map(|c| cell_text(c).trim().to_string()))
            .collect();
        if let Some(cell) = r.get(id_col.wrapping_sub(left)) {
            if matches!(cell, Data::DateTime(_) | Data::DateTimeIso(_)) {
                dates.push((n, values.get(id_col).cloned().unwrap_or_default()));
                continue;
            }
        }
        rows.push((n, values));
    }
    let mut t = Table::assemble(path, &headers, id_col, rows)?;
    for (n, id) in dates {
        t.unusable.push((
            n,
            id,
            format!(
                "the id is a date, not text (a spreadsheet reads ids such as 1-2 as dates): \
                 format the `{id_field}` column as text and type the ids again"
            ),
        ));
    }
    // A formula saved without its value (written by a script, never opened in a
    // spreadsheet program) reads as an empty cell.
    if let Ok(formulas) = book.worksheet_formula(&name) {
        let lost = formulas
            .cells()
            .filter(|(_, _, f)| !f.is_empty())
            .filter(|(r, c, _)| {
                let (r, c) = (
                    formulas.start().map_or(0, |s| s.0) + *r as u32,
                    formulas.start().map_or(0, |s| s.1) + *c as u32,
                );
                matches!(range.get_value((r, c)), None | Some(Data::Empty))
            })
            .count();
        if lost > 0 {
            t.warnings.push(
                crate::model::Warning::new(
                    crate::model::WarningClass::Table,
                    format!(
                "{}: {lost} formula cell(s) of sheet `{name}` have no saved value and read as \
                 empty: open the workbook in Excel or LibreOffice and save it, so the values \
                 are stored",
                t.file
            ),
                )
                .in_file(&t.file),
            );
        }
    }
    Ok(t)
}

fn column(headers: &[String], id_field: &str, path: &Path) -> Result<usize, InputError> {
    headers.iter().position(|h| h == id_field).ok_or_else(|| {
        table_error(
            path,
            format!(
                "no `{id_field}` column to join on (columns: {})",
                headers.join(", ")
            ),
        )
    })
}

fn make_row(
    headers: &[String],
    values: Vec<String>,
    id_col: usize,
) -> (String, BTreeMap<String, String>) {
    let id = values.get(id_col).cloned().unwrap_or_default();
    let map = headers
        .iter()
        .zip(values)
        .enumerate()
        .filter(|(i, (h, v))| *i != id_col && !h.is_empty() && !v.is_empty())
        .map(|(_, (h, v))| (h.clone(), v))
        .collect();
    (id, map)
}

/// Spreadsheet cells as text; whole numbers without a fraction so ids match DBF ids.
fn cell_text(cell: &Data) -> String {
    match cell {
        Data::Float(f) if f.fract() == 0.0 && f.abs() < 1e15 => format!("{}", *f as i64),
        Data::Empty => String::new(),
        other => other.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_rows_join_on_id_and_drop_empty_cells() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("lots.csv");
        std::fs::write(&p, "\u{feff}id,mtype,district\n1,総二階,\n2,,北\n").unwrap();
        let t = read_csv(&p, "id").unwrap();
        assert_eq!(t.rows.len(), 2);
        assert_eq!(t.rows[0].0, "1");
        assert_eq!(t.rows[0].1.get("mtype").map(String::as_str), Some("総二階"));
        assert!(!t.rows[0].1.contains_key("district"));
        assert_eq!(t.rows[1].1.get("district").map(String::as_str), Some("北"));
    }

    #[test]
    fn rows_without_an_id_are_listed_and_blank_rows_are_not() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("landmarks.csv");
        std::fs::write(&p, "id,model\na,a.obj\n,b.obj\n,\n c ,c.obj\n").unwrap();
        let t = read_csv(&p, "id").unwrap();
        assert_eq!(t.rows.len(), 2);
        assert_eq!(t.unusable.len(), 1, "{:?}", t.unusable);
        let (row, id, why) = &t.unusable[0];
        assert_eq!((*row, id.as_str()), (3, ""));
        assert!(why.contains("no `id`"), "{why}");
    }

    #[test]
    fn csv_without_id_column_is_an_error_naming_the_columns() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("lots.csv");
        std::fs::write(&p, "lot,mtype\n1,hiraya\n").unwrap();
        let err = read_csv(&p, "id").unwrap_err().to_string();
        assert!(
            err.contains("lots.csv") && err.contains("lot, mtype"),
            "{err}"
        );
    }

    #[test]
    fn shift_jis_csv_from_excel_decodes() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("lots.csv");
        let (bytes, _, _) = encoding_rs::SHIFT_JIS.encode("id,mtype\n7,平屋\n");
        std::fs::write(&p, &bytes).unwrap();
        let t = read_csv(&p, "id").unwrap();
        assert_eq!(t.rows[0].1.get("mtype").map(String::as_str), Some("平屋"));
    }
}
