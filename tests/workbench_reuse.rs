//! A build that keeps the tiles which would come out the same (`BuildOptions::reuse`, the
//! workbench's rebuilds, issue 61) gives, file for file, what a full build of the same
//! parameters and overrides gives: random sequences of edits of a lot (its type, use,
//! district, an attribute a template reads) and of parameters (analysis-only ones, which
//! remake only the tiles whose plan they change, and city-wide ones, which remake all).

mod common;

use std::path::Path;
use std::sync::Arc;

use common::*;
use edo_city::build::{build, reuse::Fingerprints, BuildOptions, NoProgress, Selection};
use edo_city::params::Params;
use proptest::prelude::*;

/// One edit of the hypothesis.
#[derive(Debug, Clone)]
enum Edit {
    /// An override row: the `nth` lot's field.
    Lot {
        nth: usize,
        field: usize,
        value: usize,
    },
    /// A parameter line.
    Param { line: usize },
}

const FIELDS: [(&str, &[&str]); 4] = [
    ("mtype", &["sangai", "hiraya", "sou-nikai", ""]),
    ("use", &["buke", "machiya", "jisha"]),
    ("district", &["kamigyo", "shimogyo", ""]),
    ("storeys", &["1", "3"]),
];

/// Parameter lines an edit may set (a later one of the same key wins).
const LINES: [&str; 8] = [
    "type_mix = { sangai = 1.0, hiraya = 2.0 }",
    "kura.gap = 2.5",
    "trees.per_ha = 10.0",
    "people.per_100m = 2.0",
    "seed = 7",
    "kura.collision = false",
    "frontage.min_length = 2.0",
    "trees.species.default = { matsu = 1.0 }",
];

fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        3 => (0usize..400, 0usize..4, 0usize..4).prop_map(|(nth, field, value)| Edit::Lot {
            nth,
            field,
            value
        }),
        1 => (0usize..LINES.len()).prop_map(|line| Edit::Param { line }),
    ]
}

/// The parameter file and its overrides for the edits so far.
fn write_hypothesis(dir: &Path, lots: &[String], edits: &[Edit]) -> Params {
    let mut rows = String::from("lot,field,value\n");
    let mut keys = std::collections::BTreeMap::new();
    for e in edits {
        match e {
            Edit::Lot { nth, field, value } => {
                let (name, values) = FIELDS[*field];
                let v = values[value % values.len()];
                rows += &format!("{},{name},{v}\n", lots[nth % lots.len()]);
            }
            Edit::Param { line } => {
                let l = LINES[*line];
                keys.insert(l.split(" = ").next().unwrap().to_string(), l);
            }
        }
    }
    std::fs::write(dir.join("p.overrides.csv"), rows).unwrap();
    // Dotted keys as their tables, so each key is set once.
    // Tiles of 50 m: 45 of them in two levels of detail, so an edit keeps some parents.
    let mut text = String::from("tile_size = 50.0\n");
    let mut tables: std::collections::BTreeMap<&str, Vec<String>> = Default::default();
    for (key, line) in &keys {
        match key.split_once('.') {
            Some((t, _)) if !key.starts_with("trees.species") => {
                let rest = line.split_once('.').unwrap().1;
                tables.entry(t).or_default().push(rest.to_string());
            }
            Some(_) => tables
                .entry("trees.species")
                .or_default()
                .push(line.trim_start_matches("trees.species.").to_string()),
            None => text += &format!("{line}\n"),
        }
    }
    text += "[input]\noverrides = \"p.overrides.csv\"\n";
    for (t, lines) in tables {
        text += &format!("[{t}]\n{}\n", lines.join("\n"));
    }
    let path = dir.join("p.toml");
    std::fs::write(&path, text).unwrap();
    Params::from_path(&path).expect("the hypothesis's parameters read")
}

fn options(input: &Path, out: &Path, params: Params) -> BuildOptions {
    BuildOptions {
        input: input.to_path_buf(),
        out: out.to_path_buf(),
        params,
        templates: None,
        threads: 2,
        plan_image: true,
        selection: Selection::All,
        force: true,
        cache: None,
        reuse: None,
    }
}

/// The lot ids of the town, in record order.
fn lot_ids(input: &Path) -> Vec<String> {
    let mut ids: Vec<String> = read_lots(&input.join("lots.shp")).into_keys().collect();
    ids.sort();
    ids
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 3, ..ProptestConfig::default() })]

    #[test]
    fn keeping_tiles_gives_what_a_full_build_gives(
        edits in proptest::collection::vec(edit(), 1..4),
    ) {
        let dir = tempfile::tempdir().unwrap();
        let input = dir.path().join("town");
        edo_city::synth::write_town(&input, 300, 3, edo_city::synth::Profile::Kyoto, true)
            .unwrap();
        let lots = lot_ids(&input);
        let hyp = dir.path().join("hyp");
        std::fs::create_dir(&hyp).unwrap();
        let live = dir.path().join("live");
        let params = write_hypothesis(&hyp, &lots, &[]);
        let mut opts = options(&input, &live, params);
        opts.reuse = Some(Arc::new(Fingerprints::default()));
        let first = build(&opts, &NoProgress).expect("first build");
        let (mut marks, made) = first.fingerprints.expect("fingerprints kept");
        prop_assert_eq!(made.len(), marks.len(), "a first build makes every tile");
        let mut kept_some = false;
        let mut kept_parents = false;
        let mut kept_strips = false;
        for n in 1..=edits.len() {
            let params = write_hypothesis(&hyp, &lots, &edits[..n]);
            let mut opts = options(&input, &live, params.clone());
            opts.reuse = Some(Arc::new(marks));
            let again = build(&opts, &NoProgress).expect("rebuild");
            let (next, made) = again.fingerprints.expect("fingerprints kept");
            kept_some |= made.len() < next.len();
            kept_parents |= next.levels_of_detail().kept() > 0;
            kept_strips |= next.plan_image().strips_kept() > 0;
            marks = next;
            let full = dir.path().join(format!("full{n}"));
            build(&options(&input, &full, params), &NoProgress).expect("full build");
            assert_same_tree(&live, &full);
        }
        // A lot's edit on its own keeps the tiles far from it.
        if edits.iter().all(|e| matches!(e, Edit::Lot { .. })) {
            prop_assert!(kept_some, "some tile kept");
            prop_assert!(kept_parents, "some parent of the levels of detail kept");
            prop_assert!(kept_strips, "some strip of plan.png kept");
        }
    }
}
