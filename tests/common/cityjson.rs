//! Reading a build's `city.city.jsonl` in tests: CityJSON's official validator (cjval) over
//! the header and every feature, and the city objects as JSON.

use std::io::BufRead;
use std::path::Path;

use serde_json::Value;

/// What cjval said of a CityJSONSeq: its features, and every error and warning with the
/// line it is on.
pub struct Validated {
    pub features: usize,
    pub errors: Vec<String>,
    pub warnings: Vec<String>,
}

/// Validates the CityJSONSeq at `path`, line by line.
pub fn validate(path: &Path) -> Validated {
    let file = std::io::BufReader::new(std::fs::File::open(path).unwrap());
    let mut lines = file.lines();
    let first = lines.next().expect("a header").unwrap();
    let mut v = cjval::CJValidator::from_str(&first);
    let mut out = Validated {
        features: 0,
        errors: Vec::new(),
        warnings: Vec::new(),
    };
    let check = |v: &cjval::CJValidator, line: usize, out: &mut Validated| {
        for (criterion, s) in v.validate() {
            if !s.has_errors() {
                continue;
            }
            let what = format!("line {line}: {criterion}: {:?}", s.get_errors());
            match s.is_warning() {
                true => out.warnings.push(what),
                false => out.errors.push(what),
            }
        }
    };
    check(&v, 1, &mut out);
    for (i, line) in lines.enumerate() {
        let line = line.unwrap();
        out.features += 1;
        if let Err(e) = v.from_str_cjfeature(&line) {
            out.errors.push(format!("line {}: {e}", i + 2));
            continue;
        }
        check(&v, i + 2, &mut out);
    }
    out
}

/// The header and the features of a CityJSONSeq, as JSON.
pub fn read(path: &Path) -> (Value, Vec<Value>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text
        .lines()
        .map(|l| serde_json::from_str::<Value>(l).unwrap());
    let header = lines.next().unwrap();
    (header, lines.collect())
}

/// Every city object of `features` by id, with its type.
pub fn objects(features: &[Value]) -> Vec<(String, Value)> {
    features
        .iter()
        .flat_map(|f| f["CityObjects"].as_object().unwrap().clone())
        .collect()
}
