//! Reads one shapefile layer: geometry from `.shp`/`.shx`, attributes from `.dbf`, text
//! decoded by the `.cpg` code page.
//!
//! The dangerous case in Japanese data is a Shift_JIS DBF with no `.cpg` and no code page in
//! its header: it decodes as UTF-8 into replacement characters without any error. We decode,
//! then look for U+FFFD and warn, naming the file and the option that fixes it.

use std::fs::File;
use std::io::BufReader;
use std::path::{Path, PathBuf};

use shapefile::Shape;

use super::InputError;

/// One feature: its shape and its attributes as text.
pub struct Feature {
    /// Record number in the file, 0-based.
    pub record: usize,
    /// The shape as read.
    pub shape: Shape,
    /// Every DBF field as text, by field name.
    pub attrs: crate::model::Attrs,
}

/// A layer as read, before any interpretation.
pub struct Layer {
    /// The `.shp` file.
    pub path: PathBuf,
    /// The features in record order, deleted records left out.
    pub features: Vec<Feature>,
    /// The encoding used for the DBF text, for the report.
    pub encoding: String,
    /// The encoding itself when known (for matching truncated field names).
    pub text_encoding: Option<&'static encoding_rs::Encoding>,
    /// Field names in DBF order.
    pub fields: Vec<String>,
    /// The `.prj` text, if present.
    pub prj: Option<String>,
    /// What reading noticed (encodings, repeated fields, sidecars).
    pub warnings: Vec<crate::model::Warning>,
    /// Records in the file, deleted ones included (the FIDs run 0..records).
    pub records: usize,
    /// Records the DBF marks as deleted: they have no feature and are reported skipped.
    pub deleted: Vec<usize>,
}

/// The largest sidecar read (a `.prj` is a few hundred bytes).
const SIDECAR_BYTES: u64 = 1 << 20;

/// The text of a sidecar file (`.cpg`, `.prj`): `None` when there is none, `Err` saying what
/// is wrong when it is there but cannot be read (a directory, no permission, not text).
fn sidecar(path: &Path) -> Result<Option<String>, String> {
    use crate::bounded::Refusal;
    match crate::bounded::read(path, SIDECAR_BYTES) {
        Ok(bytes) => match String::from_utf8(bytes) {
            Ok(text) => Ok(Some(text)),
            Err(e) => match e
                .as_bytes()
                .iter()
                .any(|b| *b == 0 || *b > 0x7e && *b < 0xa0)
            {
                true => Err(format!("{} is not a text file", path.display())),
                // A Latin-1 WKT (a degree sign in a name, say) is still WKT.
                false => Ok(Some(
                    encoding_rs::WINDOWS_1252
                        .decode(e.as_bytes())
                        .0
                        .into_owned(),
                )),
            },
        },
        Err(Refusal::Io(e)) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
        Err(_) if path.is_dir() => Err(format!("{} is a directory, not a file", path.display())),
        Err(Refusal::Io(e)) => Err(format!("cannot read {}: {e}", path.display())),
        Err(e) => Err(format!(
            "{} {e}: name a file of a few lines",
            path.display()
        )),
    }
}

/// The deletion flag of every record of a DBF, read from the file itself (byte 0 of each
/// record is `*` for deleted, ` ` for live), streamed a record at a time: a million-record
/// DBF is not held in memory a second time.
fn deletion_flags(path: &Path) -> std::io::Result<Vec<bool>> {
    use std::io::{Read, Seek, SeekFrom};
    let mut f = BufReader::new(crate::bounded::file(path)?);
    let mut head = [0u8; 12];
    if f.read_exact(&mut head).is_err() {
        return Ok(Vec::new());
    }
    let n = u32::from_le_bytes([head[4], head[5], head[6], head[7]]) as usize;
    let header = u16::from_le_bytes([head[8], head[9]]) as u64;
    let len = u16::from_le_bytes([head[10], head[11]]) as usize;
    if len == 0 {
        return Ok(Vec::new());
    }
    f.seek(SeekFrom::Start(header))?;
    let mut record = vec![0u8; len];
    let mut flags = Vec::with_capacity(n.min(1 << 24));
    while flags.len() < n && f.read_exact(&mut record).is_ok() {
        flags.push(record[0] == b'*');
    }
    Ok(flags)
}

/// Maps a code page name (from a `.cpg` or the parameter file) to an encoding.
///
/// Accepts the names Japanese GIS software writes, including `MS932` and `Windows-31J`, which
/// the dbase crate's own table does not know.
pub fn encoding_for(name: &str) -> Option<&'static encoding_rs::Encoding> {
    let n = name
        .trim()
        .trim_start_matches('\u{feff}')
        .to_ascii_lowercase()
        .replace(['-', '_', ' '], "");
    match n.as_str() {
        "utf8" | "65001" | "unicode" => Some(encoding_rs::UTF_8),
        "shiftjis" | "sjis" | "cp932" | "932" | "ms932" | "windows31j" | "mskanji"
        | "windows932" => Some(encoding_rs::SHIFT_JIS),
        "eucjp" | "20932" | "51932" => Some(encoding_rs::EUC_JP),
        "latin1" | "iso88591" | "cp1252" | "1252" | "windows1252" => {
            Some(encoding_rs::WINDOWS_1252)
        }
        "gbk" | "cp936" | "936" => Some(encoding_rs::GBK),
        "big5" | "950" | "cp950" => Some(encoding_rs::BIG5),
        "euckr" | "949" | "cp949" => Some(encoding_rs::EUC_KR),
        _ => encoding_rs::Encoding::for_label(name.trim().as_bytes()),
    }
}

/// What to do about a file a reader cannot make sense of.
const DAMAGED: &str = "the file is damaged or cut short (an interrupted copy or download?): \
                       copy or export the layer again";

/// A layer's attribute table, read.
struct Table {
    dbf_path: PathBuf,
    /// Each record's fields as text, read one record at a time (a `dbase::Record` is a map
    /// with its own copy of every field name: holding a million of them took gigabytes).
    records: Vec<crate::model::Attrs>,
    /// Text values that did not decode (they hold U+FFFD).
    garbled: usize,
    fields: Vec<String>,
    encoding: Option<&'static encoding_rs::Encoding>,
    encoding_name: String,
    warnings: Vec<crate::model::Warning>,
}

/// The `.dbf` beside `path`, decoded by the encoding forced, else its `.cpg`, else its header.
fn read_table(path: &Path, forced: &str) -> Result<Table, InputError> {
    let file = path.display().to_string();
    let io = |what: &str, e: std::io::Error| InputError::Layer {
        file: file.clone(),
        message: format!("{what}: {e}"),
    };
    let mut warnings = Vec::new();
    let dbf_path = path.with_extension("dbf");
    let dbf = crate::bounded::file(&dbf_path).map_err(|e| match e.kind() {
        std::io::ErrorKind::NotFound => InputError::Layer {
            file: file.clone(),
            message: format!(
                "the attribute file {} is missing; a shapefile needs its .shp, .shx and .dbf",
                dbf_path.display()
            ),
        },
        _ => io("cannot open the .dbf", e),
    })?;

    let cpg = sidecar(&path.with_extension("cpg")).unwrap_or_else(|why| {
        warnings.push(
            crate::model::Warning::new(
                crate::model::WarningClass::Layer,
                format!("{why}; reading the DBF by its header"),
            )
            .in_file(&file),
        );
        None
    });
    let (encoding, encoding_name) = if !forced.trim().is_empty() {
        let enc = encoding_for(forced).ok_or_else(|| InputError::Layer {
            file: file.clone(),
            message: format!("unknown encoding `{forced}` in the parameter file"),
        })?;
        (Some(enc), format!("{} (parameter file)", enc.name()))
    } else if let Some(label) = cpg.as_deref().filter(|s| !s.trim().is_empty()) {
        match encoding_for(label) {
            Some(enc) => (Some(enc), format!("{} (.cpg)", enc.name())),
            None => {
                warnings.push(crate::model::Warning::new(crate::model::WarningClass::Layer, format!(
                    "{file}: the .cpg names an unknown code page `{}`; reading the DBF by its header",
                    label.trim()
                )).in_file(&file));
                (None, "DBF header".to_string())
            }
        }
    } else {
        (None, "DBF header or UTF-8 (no .cpg)".to_string())
    };
    let builder = dbase::ReaderBuilder::new();
    let builder = match encoding {
        Some(enc) => builder.with_encoding(dbase::encoding::EncodingRs::from(enc)),
        None => builder,
    };
    let mut dbf = builder
        .build(BufReader::new(dbf))
        .map_err(|e| InputError::Layer {
            file: dbf_path.display().to_string(),
            message: format!("cannot read the DBF ({e}); {DAMAGED}"),
        })?;
    let fields: Vec<String> = dbf.fields().iter().map(|f| f.name().to_string()).collect();
    for (i, name) in fields.iter().enumerate() {
        if let Some(j) = fields[i + 1..].iter().position(|n| n == name) {
            warnings.push(
                crate::model::Warning::new(
                    crate::model::WarningClass::Layer,
                    format!(
                "{}: two fields are named `{name}` (fields {} and {}); only the later one's \
                 values are read: rename one of them in the GIS",
                dbf_path.display(),
                i + 1,
                i + j + 2
            ),
                )
                .in_file(&dbf_path.display().to_string()),
            );
        }
    }
    let mut names = crate::model::FieldNames::default();
    let mut garbled = 0usize;
    let mut records = Vec::new();
    for rec in dbf.iter_records() {
        let rec = rec.map_err(|e| InputError::Layer {
            file: dbf_path.display().to_string(),
            message: format!("cannot read the DBF records ({e}); {DAMAGED}"),
        })?;
        let attrs = rec
            .into_iter()
            .map(|(name, value)| {
                let text = field_text(&value);
                garbled += usize::from(text.contains('\u{fffd}'));
                (names.intern(&name), text.into_boxed_str())
            })
            .collect();
        records.push(attrs);
    }
    Ok(Table {
        dbf_path,
        records,
        garbled,
        fields,
        encoding,
        encoding_name,
        warnings,
    })
}

/// The `.shp` and, when there is one, its `.shx`, each opened by [`crate::bounded::file`] (a
/// FIFO or device in their place is refused, never waited on or read for ever).
fn open_shapes(path: &Path) -> Result<shapefile::ShapeReader<BufReader<File>>, shapefile::Error> {
    let source = BufReader::new(crate::bounded::file(path)?);
    let shx = path.with_extension("shx");
    match std::fs::symlink_metadata(&shx).is_ok() {
        true => {
            let index = BufReader::new(crate::bounded::file(&shx)?);
            shapefile::ShapeReader::with_shx(source, index)
        }
        false => shapefile::ShapeReader::new(source),
    }
}

/// Reads a whole layer. `forced` is the encoding from the parameter file, empty for none.
///
/// The shapes and the attribute table are read at the same time (two files, two threads: at
/// a million lots each takes seconds); a broken `.shp` is still the error reported first.
pub fn read_layer(path: &Path, forced: &str) -> Result<Layer, InputError> {
    let file = path.display().to_string();
    let (shapes, table) = rayon::join(
        || {
            open_shapes(path)
                .and_then(|r| r.read())
                .map_err(|e| InputError::Layer {
                    file: file.clone(),
                    message: format!("cannot read the shapes ({e}); {DAMAGED}"),
                })
        },
        || read_table(path, forced),
    );
    let shapes = shapes?;
    let Table {
        dbf_path,
        records,
        garbled,
        fields,
        encoding,
        encoding_name,
        mut warnings,
    } = table?;
    // dBASE marks a deleted record with '*' and keeps it until the table is packed; the
    // dbase crate leaves such records out, so they are paired with their shapes here.
    let flags = deletion_flags(&dbf_path).unwrap_or_default();
    let deleted: Vec<usize> = flags
        .iter()
        .enumerate()
        .filter(|(_, d)| **d)
        .map(|(i, _)| i)
        .collect();
    let deleted = match flags.len() == shapes.len() && records.len() + deleted.len() == shapes.len()
    {
        true => deleted,
        false => Vec::new(),
    };
    if records.len() + deleted.len() != shapes.len() {
        return Err(InputError::Layer {
            file: file.clone(),
            message: format!(
                "the .shp and its .shx index give {} shape(s) but the .dbf has {} record(s); the files do not belong together, or one was cut short",
                shapes.len(),
                records.len()
            ),
        });
    }

    let mut features = Vec::with_capacity(shapes.len());
    let is_deleted: std::collections::HashSet<usize> = deleted.iter().copied().collect();
    let kept = shapes
        .into_iter()
        .enumerate()
        .filter(|(i, _)| !is_deleted.contains(i));
    for ((record, shape), attrs) in kept.zip(records) {
        features.push(Feature {
            record,
            shape,
            attrs,
        });
    }
    if garbled > 0 {
        warnings.push(crate::model::Warning::new(crate::model::WarningClass::Layer, format!(
            "{file}: {garbled} text value(s) did not decode as {encoding_name} and contain \u{fffd}; \
             if the data is Japanese, add a .cpg file containing SHIFT_JIS or set \
             `encoding = \"shift_jis\"` for this layer in the parameter file"
        )).in_file(&file));
    }
    let prj = sidecar(&path.with_extension("prj")).map_err(|why| InputError::Layer {
        file: file.clone(),
        message: format!(
            "{why}: the .prj says which coordinate system the layer is in; replace it with \
             the layer's own .prj, or remove it and set `crs`"
        ),
    })?;
    Ok(Layer {
        records: features.len() + deleted.len(),
        deleted,
        path: path.to_path_buf(),
        features,
        encoding: encoding_name,
        text_encoding: encoding,
        fields,
        prj,
        warnings,
    })
}

/// Renders a DBF value as the text a user would see in a GIS attribute table.
fn field_text(value: &dbase::FieldValue) -> String {
    use dbase::FieldValue as V;
    match value {
        V::Character(s) => s.as_deref().unwrap_or("").trim().to_string(),
        V::Memo(s) => s.trim().to_string(),
        V::Numeric(n) => n.map(fmt_number).unwrap_or_default(),
        V::Float(n) => n.map(|v| fmt_number(f64::from(v))).unwrap_or_default(),
        V::Double(n) => fmt_number(*n),
        V::Integer(n) => n.to_string(),
        V::Currency(n) => fmt_number(*n),
        V::Logical(b) => b.map(|b| b.to_string()).unwrap_or_default(),
        V::Date(d) => d
            .map(|d| format!("{:04}-{:02}-{:02}", d.year(), d.month(), d.day()))
            .unwrap_or_default(),
        V::DateTime(dt) => {
            let d = dt.date();
            format!("{:04}-{:02}-{:02}", d.year(), d.month(), d.day())
        }
    }
}

/// Whole numbers print without a fraction so that numeric ids read as `12`, not `12.0`.
pub(super) fn fmt_number(v: f64) -> String {
    if v.fract() == 0.0 && v.abs() < 1e15 {
        format!("{}", v as i64)
    } else {
        format!("{v}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn japanese_code_page_names_are_known() {
        for name in [
            "SHIFT_JIS",
            "Shift_JIS\n",
            "CP932",
            "932",
            "MS932",
            "Windows-31J",
            "sjis",
        ] {
            assert_eq!(encoding_for(name), Some(encoding_rs::SHIFT_JIS), "{name}");
        }
        assert_eq!(encoding_for("UTF-8"), Some(encoding_rs::UTF_8));
        assert_eq!(encoding_for("no-such-code-page"), None);
    }

    #[test]
    fn numeric_ids_print_as_integers() {
        assert_eq!(fmt_number(12.0), "12");
        assert_eq!(fmt_number(2.5), "2.5");
    }
}
