//! Tiles (the paper's fixed-size squares of the city): their ids and the ground they cover.
//!
//! Tile `c_r` covers `x0 + c*size <= x < x0 + (c+1)*size` (and the same for `r` in y), with
//! `tile_origin = [x0, y0]` fixed so ids never change when the data grows.

use geo_types::Coord;

/// A tile's id: `<col>_<row>` on the grid, or a name given in the data.
pub type TileId = String;

/// The id `<col>_<row>` of the tile holding `p`.
///
/// ```
/// use edo_city::model::tile::tile_id;
/// use geo_types::Coord;
/// assert_eq!(tile_id(Coord { x: 260.0, y: -10.0 }, 250.0, [0.0, 0.0]), "1_-1");
/// ```
pub fn tile_id(p: Coord<f64>, size: f64, origin: [f64; 2]) -> TileId {
    let col = ((p.x - origin[0]) / size).floor() as i64;
    let row = ((p.y - origin[1]) / size).floor() as i64;
    format!("{col}_{row}")
}

/// A tile id given in the data becomes a file name: it must not escape the tiles directory
/// or be mistaken for a flag.
///
/// ```
/// use edo_city::model::tile::is_valid_tile_name;
/// assert!(is_valid_tile_name("12_7"));
/// assert!(is_valid_tile_name("sanjo.east"));
/// assert!(!is_valid_tile_name("../12_7"));
/// assert!(!is_valid_tile_name("-3_4"));
/// ```
pub fn is_valid_tile_name(name: &str) -> bool {
    !name.is_empty()
        && name.len() <= 64
        && !name.starts_with(['-', '.'])
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.'))
}

/// Parses a tile id back to its column and row.
pub fn parse_tile_id(id: &str) -> Option<(i64, i64)> {
    let (c, r) = id.split_once('_')?;
    Some((c.parse().ok()?, r.parse().ok()?))
}

/// The rectangle `[xmin, ymin, xmax, ymax]` a tile id covers.
pub fn tile_bounds(id: &str, size: f64, origin: [f64; 2]) -> Option<[f64; 4]> {
    let (c, r) = parse_tile_id(id)?;
    let (x, y) = (origin[0] + c as f64 * size, origin[1] + r as f64 * size);
    Some([x, y, x + size, y + size])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ids_round_trip_and_stay_fixed() {
        let id = tile_id(
            Coord {
                x: -20_001.0,
                y: -108_999.0,
            },
            250.0,
            [0.0, 0.0],
        );
        assert_eq!(id, "-81_-436");
        assert_eq!(parse_tile_id(&id), Some((-81, -436)));
        assert_eq!(parse_tile_id("x_1"), None);
    }
}
