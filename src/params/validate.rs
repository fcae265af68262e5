//! A parameter file's values checked once they are read: every number a user sets within a
//! range that keeps a typo from sizing anything (issue 39), every mapping and mix usable,
//! each section by its own `validate`. An error names the key and what it must be.

use std::collections::BTreeMap;

use super::{allowed, billboards, output, Params, ParamsError};

impl Params {
    /// Checks the values, naming the file `path` and the first key that is wrong.
    pub(super) fn validate(&self, path: &str) -> Result<(), ParamsError> {
        let bad = |message: String| ParamsError::Invalid {
            path: path.to_string(),
            message,
        };
        self.sizes().map_err(bad)?;
        if let Some(s) = self
            .seeds
            .keys()
            .find(|s| !super::SEED_SECTIONS.contains(&s.as_str()))
        {
            return Err(bad(format!(
                "`seeds.{s}`: only {} draw from a seed of their own",
                super::SEED_SECTIONS.join(", ")
            )));
        }
        self.places().map_err(bad)?;
        self.lot_mappings().map_err(bad)?;
        check_mix("type_mix", &self.type_mix).map_err(bad)?;
        self.districts().map_err(bad)?;
        self.people.validate().map_err(bad)?;
        self.trees.validate().map_err(bad)?;
        self.crowd.validate().map_err(bad)?;
        self.garden.validate().map_err(bad)?;
        self.halls.validate().map_err(bad)?;
        self.ground.validate().map_err(bad)?;
        self.landmarks.validate().map_err(bad)?;
        self.output.validate().map_err(bad)?;
        if let Some(o) = &self.origin_lonlat {
            output::check_origin_lonlat(o).map_err(bad)?;
        }
        Ok(())
    }

    /// Every size and distance a user sets, with the range it must lie in: low exclusive
    /// where 0 itself is meaningless (a size), inclusive where 0 switches a thing off. The
    /// upper bounds are far past any city and keep a typo (1e9 for 1.9) from allocating the
    /// machine away.
    fn sizes(&self) -> Result<(), String> {
        let k = &self.kura;
        let fp = &self.layers.footprints;
        for (key, value) in [
            ("tile_size", self.tile_size),
            ("fence.gate_width", self.fence.gate_width),
            ("kura.width", k.width),
            ("kura.depth", k.depth),
            ("kura.min_width", k.min_width),
            ("kura.min_depth", k.min_depth),
            ("frontage.min_length", self.frontage.min_length),
            ("machiya.depth", self.machiya.depth),
            (
                "layers.streets.default_width",
                self.layers.streets.default_width,
            ),
            ("layers.footprints.storey_height", fp.storey_height),
            ("layers.footprints.default_height", fp.default_height),
            (
                "layers.street_widths.max_distance",
                self.layers.street_widths.max_distance,
            ),
            ("kura.min_frontage", k.min_frontage),
            ("kura.depth_ratio", k.depth_ratio),
            ("kura.gap", k.gap),
            ("kura.back_margin", k.back_margin),
            ("kura.side_margin", k.side_margin),
            ("kura.overlap_tolerance", k.overlap_tolerance),
            ("simplify.tolerance", self.simplify.tolerance),
            ("machiya.min_depth", self.machiya.min_depth),
            ("simplify.max_vertices", self.simplify.max_vertices as f64),
            ("frontage.max_angle_deg", self.frontage.max_angle_deg),
        ] {
            allowed::check_number(key, value)?;
        }
        if k.min_width > k.width || k.min_depth > k.depth {
            return Err(
                "`kura.min_width` / `kura.min_depth` must not exceed `kura.width` / `kura.depth`"
                    .into(),
            );
        }
        Ok(())
    }

    /// Points of the plane: finite, and nearer the CRS's origin than damaged data lies.
    fn places(&self) -> Result<(), String> {
        let far = crate::model::FAR;
        for (key, point) in [
            ("tile_origin", Some(self.tile_origin)),
            ("origin", self.origin),
        ] {
            if let Some([x, y]) = point {
                if !(x.is_finite() && y.is_finite() && x.abs() < far && y.abs() < far) {
                    return Err(format!(
                        "`{key}` must be two finite numbers within {far:e} m of the CRS's \
                         origin, got [{x}, {y}]"
                    ));
                }
            }
        }
        Ok(())
    }

    /// The lot fields a value map or a constant may set: use, mtype and district.
    fn lot_mappings(&self) -> Result<(), String> {
        let lots = &self.layers.lots;
        for key in lots.values.keys().chain(lots.constants.keys()) {
            if !["use", "mtype", "district"].contains(&key.as_str()) {
                return Err(format!(
                    "`layers.lots.values.{key}` / `constants.{key}`: only use, mtype and district can be mapped"
                ));
            }
        }
        Ok(())
    }

    /// Each district's own mix, densities, motion and trees.
    fn districts(&self) -> Result<(), String> {
        for (id, d) in &self.district {
            if let Some(mix) = &d.type_mix {
                check_mix(&format!("district.{id}.type_mix"), mix)?;
            }
            for (key, v, high) in [
                (
                    "people_per_100m",
                    d.people_per_100m,
                    billboards::MAX_PER_100M,
                ),
                ("trees_per_ha", d.trees_per_ha, billboards::MAX_PER_HA),
                (
                    "trees_per_ha_machiya",
                    d.trees_per_ha_machiya,
                    billboards::MAX_PER_HA,
                ),
            ] {
                if let Some(v) = v.filter(|v| !(v.is_finite() && (0.0..=high).contains(v))) {
                    return Err(format!(
                        "`district.{id}.{key}` must be from 0 to {high}, got {}",
                        crate::model::number::Num(v)
                    ));
                }
            }
            if let Some(m) =
                (d.people_motion.as_deref()).filter(|m| !["scatter", "boids"].contains(m))
            {
                return Err(format!(
                    "`district.{id}.people_motion` must be \"scatter\" or \"boids\", got \"{m}\""
                ));
            }
            if let Some(style) = &d.trees_style {
                billboards::check_style(&format!("district.{id}.trees_style"), style)?;
            }
            if let Some(table) = &d.tree_species {
                billboards::check_species(&format!("district.{id}.tree_species"), table)?;
            }
        }
        Ok(())
    }
}

/// A machiya type mix: some type, every weight from 0 to 1e9 (so their sum stays finite),
/// not all 0.
fn check_mix(key: &str, mix: &BTreeMap<String, f64>) -> Result<(), String> {
    if mix.is_empty() {
        return Err(format!("`{key}` lists no machiya type"));
    }
    for (name, w) in mix {
        if !(w.is_finite() && (0.0..=1e9).contains(w)) {
            return Err(format!(
                "`{key}.{name}` must be a weight from 0 to 1e9, got {w}"
            ));
        }
    }
    if mix.values().sum::<f64>() <= 0.0 {
        return Err(format!("`{key}` weights add up to 0"));
    }
    Ok(())
}
