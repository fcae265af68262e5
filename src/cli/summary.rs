//! What the command line prints: the summary after a build, the table of `check`, Table 2
//! and the people-and-trees counts. Everything goes through `say!`, so a reader that goes
//! away ends the printing instead of panicking.

use edo_city::build::{BuildOptions, BuildOutcome};

/// A proj string cut to what tells CRSs apart in a table: `tmerc lat_0=36 lon_0=136`.
fn short_crs(def: &str) -> String {
    let keep = [
        "+proj=", "+zone=", "+south", "+lat_0=", "+lon_0=", "+datum=",
    ];
    let parts: Vec<&str> = def
        .split_whitespace()
        .filter(|t| keep.iter().any(|k| t.starts_with(k)))
        .map(|t| t.trim_start_matches("+proj=").trim_start_matches('+'))
        .collect();
    if parts.is_empty() {
        def.to_string()
    } else {
        parts.join(" ")
    }
}

/// The table `edo-city check` prints.
pub fn print_check(r: &edo_city::output::report::Report) -> std::io::Result<()> {
    say!("input {}", r.input);
    say!(
        "CRS   {}",
        if r.crs.is_empty() {
            "unknown (no .prj)"
        } else {
            &r.crs
        }
    );
    say!(
        "\n{:<12} {:>9} {:>7} {:>7}  {:<30} {:<28} {:<7} file",
        "layer",
        "records",
        "built",
        "skipped",
        "text encoding",
        "CRS",
        "reproj."
    );
    for l in &r.layers {
        // The layer's ledger: every record built or skipped (see report.json `accounting`).
        let a = r.accounting.iter().find(|a| a.file == l.file);
        let n = |f: fn(&edo_city::output::accounting::Account) -> usize| {
            a.map_or("-".to_string(), |a| f(a).to_string())
        };
        say!(
            "{:<12} {:>9} {:>7} {:>7}  {:<30} {:<28} {:<7} {}",
            l.role,
            l.features,
            n(|a| a.built),
            n(|a| a.skipped),
            l.encoding,
            short_crs(&l.crs),
            if l.reprojected { "yes" } else { "no" },
            l.file
        );
    }
    for a in r.accounting.iter().filter(|a| a.partly > 0) {
        say!(
            "{}: {} record(s) built in part (some parts built, others skipped: counted in \
             both; report.json `skipped` says which)",
            a.file,
            a.partly
        );
    }
    let c = &r.counts;
    say!(
        "\nlots {} ({}), machiya {}, footprints {} of {}, tiles {}, frontage fallback {}",
        c.lots,
        c.lots_by_use
            .iter()
            .map(|(k, v)| format!("{k} {v}"))
            .collect::<Vec<_>>()
            .join(", "),
        c.machiya,
        c.footprints,
        c.footprints_read,
        c.tiles,
        c.frontage_fallback
    );
    if c.people + c.trees > 0 {
        say!("people {}, trees {}", c.people, c.trees);
    }
    for t in &r.tables {
        say!(
            "table {}: {} rows, {} matched, {} without a lot ({}), {} lots without a row",
            t.file,
            t.rows,
            t.matched,
            t.rows_without_feature,
            t.rows_without_feature_ids.join(", "),
            t.features_without_row
        );
    }
    if r.skipped.is_empty() && r.warnings.is_empty() {
        say!("\nno problems: every feature would be built");
        return Ok(());
    }
    say!("\nproblems:");
    for w in &r.warnings {
        say!("  warning: {w}");
    }
    for s in r.skipped.iter().take(50) {
        say!("  skip {} {} ({}): {}", s.layer, s.id, s.file, s.reason);
    }
    if r.skipped.len() > 50 {
        say!(
            "  ... {} more skipped features (--json lists all)",
            r.skipped.len() - 50
        );
    }
    Ok(())
}

pub fn print_summary(opts: &BuildOptions, o: &BuildOutcome) -> std::io::Result<()> {
    let r = &o.report;
    let c = &r.counts;
    say!(
        "edo-city: built {} into {}",
        opts.input.display(),
        opts.out.display()
    );
    say!(
        "  lots       {:>7}  ({})",
        c.lots,
        c.lots_by_use
            .iter()
            .map(|(k, v)| format!("{k} {v}"))
            .collect::<Vec<_>>()
            .join(", ")
    );
    say!(
        "  machiya    {:>7}  (type from data {}, drawn from type_mix {})",
        c.machiya,
        c.type_given,
        c.type_drawn
    );
    for (t, n) in &c.by_type {
        let share = 100.0 * *n as f64 / c.machiya.max(1) as f64;
        say!("    {t:<18} {n:>7}  {share:5.1} %");
    }
    if c.footprints_read > 0 {
        say!(
            "  footprints {:>7}  of {} read ({})",
            c.footprints,
            c.footprints_read,
            c.footprints_by_type
                .iter()
                .map(|(k, v)| format!("{k} {v}"))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    say!(
        "  frontage fallback {:>3}  (no vertex pair passed the Fig.4 test)",
        c.frontage_fallback
    );
    print_table2(r, opts.params.kura.enabled, opts.params.kura.collision)?;
    if c.fence_segments + c.gates > 0 {
        say!(
            "  fences     {:>7}  segments, {} gates; walls: {}",
            c.fence_segments,
            c.gates,
            c.wall_metres
                .iter()
                .map(|(t, m)| format!("{t} {m:.0} m"))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    print_billboards(r)?;
    print_halls(r)?;
    print_landmarks(r)?;
    say!(
        "  tiles      {:>7}  ({} written now, {:.1} MB)",
        c.tiles,
        o.tiles_written,
        o.bytes_written as f64 / 1e6
    );
    for t in &r.tables {
        say!(
            "  table {}: {} rows, {} matched, {} rows without a lot, {} lots without a row",
            t.file,
            t.rows,
            t.matched,
            t.rows_without_feature,
            t.features_without_row
        );
    }
    if c.skipped > 0 {
        say!("  skipped    {:>7}  (details in report.json):", c.skipped);
        for (reason, n) in &r.skipped_by_reason {
            say!("    {n:>5}  {reason}");
        }
    }
    for w in r.warnings.iter().take(10) {
        say!("  warning: {w}");
    }
    if r.warnings.len() > 10 {
        say!(
            "  ... {} more warnings in report.json",
            r.warnings.len() - 10
        );
    }
    if o.cache == edo_city::build::cache::CacheUse::Reused {
        say!(
            "  analysis   reused: this input, these parameters and this program were read and \
             analysed by the last full build into this directory (EDO_CITY_CACHE=off does both \
             again)"
        );
    }
    say!("  in {:.2} s", o.timings.total.as_secs_f64());
    if opts.out.join("tileset.json").is_file() && opts.selection == edo_city::build::Selection::All
    {
        say!("  in a browser: edo-city serve {}", opts.out.display());
    }
    let gpkg = opts.out.join(edo_city::output::PLAN_GPKG);
    if gpkg.is_file() && opts.selection == edo_city::build::Selection::All {
        say!("  in QGIS: {} (docs/gpkg.md)", gpkg.display());
    }
    let model = opts.out.join(edo_city::output::cityjson::FILE);
    if model.is_file() && opts.selection == edo_city::build::Selection::All {
        say!(
            "  in 3D GIS: {} (CityJSON 2.0, docs/cityjson.md)",
            model.display()
        );
    }
    Ok(())
}

/// Halls: how many of each template were placed, and how many found no room (report.json's
/// `halls` says which and why).
fn print_halls(r: &edo_city::output::report::Report) -> std::io::Result<()> {
    if r.halls.is_empty() {
        return Ok(());
    }
    let mut placed: std::collections::BTreeMap<&str, usize> = Default::default();
    for h in r.halls.iter().filter(|h| h.placed) {
        *placed.entry(h.template.as_str()).or_default() += 1;
    }
    let without = r.halls.iter().filter(|h| !h.placed).count();
    say!(
        "  halls      {:>7}  ({}{})",
        placed.values().sum::<usize>(),
        placed
            .iter()
            .map(|(t, n)| format!("{t} {n}"))
            .collect::<Vec<_>>()
            .join(", "),
        if without > 0 {
            format!("; {without} without room, see report.json halls")
        } else {
            String::new()
        }
    );
    Ok(())
}

/// Landmarks: how many placed from which model, what they displaced, how many were skipped.
fn print_landmarks(r: &edo_city::output::report::Report) -> std::io::Result<()> {
    let l = &r.landmarks;
    if l.placed.is_empty() && l.skipped.is_empty() {
        return Ok(());
    }
    let mut by_model: std::collections::BTreeMap<&str, usize> = Default::default();
    for p in &l.placed {
        *by_model.entry(p.model.as_str()).or_default() += 1;
    }
    say!(
        "  landmarks  {:>7}  ({}); {} generated features displaced, {} landmarks skipped",
        l.placed.len(),
        by_model
            .iter()
            .map(|(m, n)| format!("{m} {n}"))
            .collect::<Vec<_>>()
            .join(", "),
        l.displaced.len(),
        l.skipped.len()
    );
    Ok(())
}

/// People and trees: how many, from where, and per district when there are districts; the
/// street crowds' order parameters when the people walked.
fn print_billboards(r: &edo_city::output::report::Report) -> std::io::Result<()> {
    let c = &r.counts;
    for (name, n, by_district, drawn) in [
        ("people", c.people, &c.people_by_district, "people.per_100m"),
        ("trees", c.trees, &c.trees_by_district, "trees.per_ha"),
    ] {
        if n == 0 {
            continue;
        }
        let source = match r.layers.iter().find(|l| l.role == name) {
            Some(l) => format!("points of {}", l.file),
            None => format!("drawn at {drawn}"),
        };
        let districts = if by_district.keys().any(|d| !d.is_empty()) {
            let list: Vec<String> = by_district
                .iter()
                .map(|(d, n)| format!("{} {n}", if d.is_empty() { "(none)" } else { d }))
                .collect();
            format!("; by district: {}", list.join(", "))
        } else {
            String::new()
        };
        say!("  {name:<10} {n:>7}  ({source}{districts})");
    }
    let crowds = &r.crowds;
    if !crowds.streets.is_empty() {
        let walkers: usize = crowds.streets.iter().map(|s| s.agents).sum();
        let list: Vec<String> = crowds
            .by_district
            .iter()
            .map(|(d, c)| {
                format!(
                    "{} lambda1 {:.3} lambda2 {:.3} lambda3 {:.3}",
                    if d.is_empty() { "(none)" } else { d },
                    c.mean.lambda1,
                    c.mean.lambda2,
                    c.mean.lambda3
                )
            })
            .collect();
        say!(
            "  crowds     {walkers:>7}  walked on {} street stretches (means over the clip: {})",
            crowds.streets.len(),
            list.join("; ")
        );
    }
    Ok(())
}

/// The paper's Table 2 beside this build's figures.
fn print_table2(
    r: &edo_city::output::report::Report,
    enabled: bool,
    avoid: bool,
) -> std::io::Result<()> {
    let (t, p) = (&r.table2.all, &r.table2.paper);
    if !enabled {
        say!("  kura             0  (kura.enabled = false)");
        return Ok(());
    }
    say!(
        "  kura       {:>7}  built ({} avoidance); Table 2:",
        r.counts.kura,
        if avoid { "with" } else { "without" }
    );
    say!("                          this build          paper (all Kyoto)");
    say!(
        "    machiya              {:>7}             {:>7}",
        t.machiya,
        p.machiya
    );
    say!(
        "    kura candidates      {:>7}  {:5.1} %",
        t.kura_candidates,
        100.0 * t.kura_candidates as f64 / t.machiya.max(1) as f64
    );
    say!(
        "    without avoidance    {:>7}  {:5.1} %    {:>7}  {:5.1} %",
        t.kura_without_avoidance,
        100.0 * t.ratio_without,
        p.kura_without_avoidance,
        100.0 * p.ratio_without
    );
    say!(
        "    with avoidance       {:>7}  {:5.1} %    {:>7}  {:5.1} %   (painting: {} / {} = {:.1} %)",
        t.kura_with_avoidance,
        100.0 * t.ratio_with,
        p.kura_with_avoidance,
        100.0 * p.ratio_with,
        p.painting_kura,
        p.painting_machiya,
        100.0 * p.painting_ratio
    );
    Ok(())
}
