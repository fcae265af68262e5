//! The layers' QGIS styles, stored in the GeoPackage's `layer_styles` table (the table QGIS
//! itself writes, and applies when it opens a layer), so `plan.gpkg` looks like `plan.png`:
//! lots by machiya type, footprints grey, other uses pale green, skipped records red, refused
//! kura hatched. Each style is QML: a categorized renderer on an attribute or expression, or
//! one symbol.

use std::fmt::Write;

/// The geometry a symbol draws.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shape {
    /// Polygons: a fill.
    Fill,
    /// Lines.
    Line,
    /// Points: a circle.
    Marker,
}

/// How one symbol looks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Look {
    /// Fill (or line, or marker) colour.
    pub rgb: [u8; 3],
    /// Hatched instead of filled (polygons).
    pub hatched: bool,
    /// Only the outline, in the colour (polygons).
    pub outline: bool,
    /// Opacity, 0 to 1.
    pub alpha: f64,
    /// Line width or marker size, millimetres on the screen.
    pub size: f64,
}

impl Look {
    /// A plain symbol of a colour.
    pub const fn of(rgb: [u8; 3]) -> Look {
        Look {
            rgb,
            hatched: false,
            outline: false,
            alpha: 1.0,
            size: 0.0,
        }
    }
    /// The same, hatched.
    pub const fn hatched(self) -> Look {
        Look {
            hatched: true,
            ..self
        }
    }
    /// Only its outline, in its colour.
    pub const fn outline(self) -> Look {
        Look {
            outline: true,
            ..self
        }
    }
    /// The same, half seen through (a layer drawn under another of the same colours).
    pub const fn faded(self) -> Look {
        Look {
            alpha: 0.45,
            ..self
        }
    }
    /// The same, with a line width or marker size.
    pub const fn sized(self, size: f64) -> Look {
        Look { size, ..self }
    }
}

/// A style of one symbol for every feature.
pub fn single(shape: Shape, look: Look) -> String {
    let mut symbols = String::new();
    symbol(&mut symbols, "0", shape, look);
    wrap(&format!(
        "<renderer-v2 type=\"singleSymbol\" symbollevels=\"0\" forceraster=\"0\" \
         enableorderby=\"0\">\n<symbols>\n{symbols}</symbols>\n</renderer-v2>"
    ))
}

/// A style by category: `attr` (a column or a QGIS expression) against each value; features
/// of no listed value get `other`.
pub fn categorized(
    shape: Shape,
    attr: &str,
    categories: &[(String, Look)],
    other: Option<Look>,
) -> String {
    let (mut cats, mut symbols) = (String::new(), String::new());
    for (i, (value, look)) in categories.iter().enumerate() {
        let _ = writeln!(
            cats,
            "<category render=\"true\" symbol=\"{i}\" value=\"{v}\" label=\"{v}\"/>",
            v = escape(value)
        );
        symbol(&mut symbols, &i.to_string(), shape, *look);
    }
    if let Some(look) = other {
        let i = categories.len();
        let _ = writeln!(
            cats,
            "<category render=\"true\" symbol=\"{i}\" value=\"\" label=\"other\"/>"
        );
        symbol(&mut symbols, &i.to_string(), shape, look);
    }
    wrap(&format!(
        "<renderer-v2 type=\"categorizedSymbol\" attr=\"{}\" symbollevels=\"0\" \
         forceraster=\"0\" enableorderby=\"0\">\n<categories>\n{cats}</categories>\n\
         <symbols>\n{symbols}</symbols>\n</renderer-v2>",
        escape(attr)
    ))
}

fn wrap(renderer: &str) -> String {
    format!(
        "<!DOCTYPE qgis PUBLIC 'http://mrcc.com/qgis.dtd' 'SYSTEM'>\n\
         <qgis version=\"3.22.0\" styleCategories=\"Symbology\">\n{renderer}\n</qgis>\n"
    )
}

fn option(out: &mut String, name: &str, value: &str) {
    let _ = writeln!(
        out,
        "<Option type=\"QString\" name=\"{name}\" value=\"{}\"/>",
        escape(value)
    );
}

fn symbol(out: &mut String, name: &str, shape: Shape, look: Look) {
    let [r, g, b] = look.rgb;
    let colour = format!("{r},{g},{b},255");
    let outline = "60,60,60,255";
    let (kind, class) = match shape {
        Shape::Fill => ("fill", "SimpleFill"),
        Shape::Line => ("line", "SimpleLine"),
        Shape::Marker => ("marker", "SimpleMarker"),
    };
    let _ = writeln!(
        out,
        "<symbol type=\"{kind}\" name=\"{name}\" alpha=\"{}\" clip_to_extent=\"1\" \
         force_rhr=\"0\">\n<layer class=\"{class}\" enabled=\"1\" locked=\"0\" pass=\"0\">\n\
         <Option type=\"Map\">",
        look.alpha
    );
    match shape {
        Shape::Fill => {
            let style = match (look.outline, look.hatched) {
                (true, _) => "no",
                (false, true) => "b_diagonal",
                (false, false) => "solid",
            };
            let plain = !look.hatched && !look.outline;
            option(out, "color", &colour);
            option(out, "style", style);
            option(out, "outline_color", if plain { outline } else { &colour });
            option(out, "outline_style", "solid");
            let width = match plain {
                true => "0.1".to_string(),
                false => fmt_size(look.size, 0.4),
            };
            option(out, "outline_width", &width);
            option(out, "outline_width_unit", "MM");
        }
        Shape::Line => {
            option(out, "line_color", &colour);
            option(out, "line_style", "solid");
            option(out, "line_width", &fmt_size(look.size, 0.5));
            option(out, "line_width_unit", "MM");
            option(out, "capstyle", "round");
        }
        Shape::Marker => {
            option(out, "color", &colour);
            option(out, "name", "circle");
            option(out, "size", &fmt_size(look.size, 1.2));
            option(out, "size_unit", "MM");
            option(out, "outline_color", outline);
            option(out, "outline_width", "0");
        }
    }
    out.push_str("</Option>\n</layer>\n</symbol>\n");
}

fn fmt_size(size: f64, default: f64) -> String {
    let s = if size > 0.0 { size } else { default };
    format!("{s}")
}

/// Text for an XML attribute.
fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
        .replace('\'', "&apos;")
}

/// Creates `layer_styles` as QGIS does and stores each layer's style as its default.
pub fn write(conn: &rusqlite::Connection, styles: &[(String, String)]) -> rusqlite::Result<()> {
    if styles.is_empty() {
        return Ok(());
    }
    conn.execute_batch(
        "CREATE TABLE layer_styles (
           id INTEGER PRIMARY KEY AUTOINCREMENT, f_table_catalog TEXT(256),
           f_table_schema TEXT(256), f_table_name TEXT(256), f_geometry_column TEXT(256),
           styleName TEXT(30), styleQML TEXT, styleSLD TEXT, useAsDefault BOOLEAN,
           description TEXT, owner TEXT(30), ui TEXT(30), update_time DATETIME);",
    )?;
    conn.execute(
        "INSERT INTO gpkg_contents (table_name, data_type, identifier, description, \
         last_change) VALUES ('layer_styles', 'attributes', 'layer_styles', \
         'QGIS styles of the layers', ?1)",
        [super::FIXED_DATE],
    )?;
    let mut insert = conn.prepare(
        "INSERT INTO layer_styles (f_table_catalog, f_table_schema, f_table_name, \
         f_geometry_column, styleName, styleQML, styleSLD, useAsDefault, description, owner, \
         ui, update_time) VALUES ('', '', ?1, 'geom', ?1, ?2, '', 1, 'edo-city', '', NULL, ?3)",
    )?;
    for (table, qml) in styles {
        insert.execute(rusqlite::params![table, qml, super::FIXED_DATE])?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_categorized_style_lists_its_values_and_escapes_them() {
        let q = categorized(
            Shape::Fill,
            "\"status\"",
            &[("a<b".into(), Look::of([1, 2, 3]).hatched())],
            Some(Look::of([9, 9, 9])),
        );
        assert!(q.contains("attr=\"&quot;status&quot;\""), "{q}");
        assert!(q.contains("value=\"a&lt;b\""), "{q}");
        assert!(q.contains("value=\"b_diagonal\""), "{q}");
        assert!(q.contains("value=\"9,9,9,255\""), "{q}");
        assert_eq!(q.matches("<symbol ").count(), 2);
    }
}
