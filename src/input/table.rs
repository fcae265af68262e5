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
    pub file: String,
    /// Rows in file order: (id, values).
    pub rows: Vec<(String, BTreeMap<String, String>)>,
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
    let csv = dir.join(format!("{base}.csv"));
    let xlsx = dir.join(format!("{base}.xlsx"));
    if csv.exists() {
        read_csv(&csv, id_field).map(Some)
    } else if xlsx.exists() {
        read_xlsx(&xlsx, sheet, id_field).map(Some)
    } else {
        Ok(None)
    }
}

fn table_error(path: &Path, message: String) -> InputError {
    InputError::Table {
        file: path.display().to_string(),
        message,
    }
}

/// Reads a CSV table with a header row. A UTF-8 byte-order mark (Excel's export) is ignored.
pub fn read_csv(path: &Path, id_field: &str) -> Result<Table, InputError> {
    let bytes = std::fs::read(path).map_err(|e| table_error(path, e.to_string()))?;
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
        let values: Vec<String> = record.iter().map(|v| v.trim().to_string()).collect();
        rows.push(make_row(&headers, values, id_col));
    }
    Ok(Table {
        file: path.display().to_string(),
        rows,
    })
}

/// Reads the named sheet (or the first) of an XLSX workbook, first row as header.
pub fn read_xlsx(path: &Path, sheet: &str, id_field: &str) -> Result<Table, InputError> {
    let mut book = calamine::open_workbook_auto(path)
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
    let mut it = range.rows();
    let headers: Vec<String> = match it.next() {
        Some(h) => h.iter().map(|c| cell_text(c).trim().to_string()).collect(),
        None => {
            return Ok(Table {
                file: path.display().to_string(),
                rows: Vec::new(),
            })
        }
    };
    let id_col = column(&headers, id_field, path)?;
    let rows = it
        .map(|r| {
            let values = r.iter().map(|c| cell_text(c).trim().to_string()).collect();
            make_row(&headers, values, id_col)
        })
        .filter(|(id, _)| !id.is_empty())
        .collect();
    Ok(Table {
        file: path.display().to_string(),
        rows,
    })
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
