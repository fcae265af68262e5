//! `crowds/<tile>.csv`: every walker's clip (`people.motion = "boids"`) for tools that do not
//! read glTF animation: one row per walker per key, `t, id, x, y, z, heading, group`.
//!
//! `t` is seconds into the clip (0 to `crowd.duration`; the last key repeats the first, as
//! the clip loops), `x` and `y` are map metres in the layers' CRS (east, north: QGIS loads
//! the file as points, PedPy as trajectories), `z` the ground's height there, `heading` the
//! way the walker faces in degrees counter-clockwise from east, `group` the id of the first
//! person of its group. The OBJ tiles show the same people where they stand at `t = 0`.

use std::fmt::Write as _;

use super::species::quote;
use crate::model::Walk;

/// The directory of the files, relative to the output directory.
pub const DIR: &str = "crowds";

/// The file of tile `id`, relative to the output directory.
pub fn path(id: &str) -> String {
    format!("{DIR}/{id}.csv")
}

/// The CSV text of a tile's walkers.
pub fn csv(walks: &[Walk]) -> String {
    let rows: usize = walks.iter().map(|w| w.keys.len()).sum();
    let mut out = String::with_capacity(64 * rows + 40);
    out.push_str("t,id,x,y,z,heading,group\n");
    for w in walks {
        let (id, group) = (quote(&w.id), quote(&w.group));
        for (k, key) in w.keys.iter().enumerate() {
            let _ = writeln!(
                out,
                "{:.2},{id},{:.3},{:.3},{:.3},{:.1},{group}",
                k as f64 * w.dt,
                key.at[0],
                key.at[1],
                key.at[2],
                key.heading.to_degrees(),
            );
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::WalkKey;

    #[test]
    fn a_row_per_key_with_quoted_ids() {
        let w = Walk {
            id: "a,1".into(),
            group: "g".into(),
            street: "s/1".into(),
            dt: 0.5,
            keys: vec![
                WalkKey {
                    at: [100.0, 200.0, 3.0],
                    heading: std::f64::consts::FRAC_PI_2,
                },
                WalkKey {
                    at: [100.5, 200.0, 3.0],
                    heading: 0.0,
                },
            ],
        };
        assert_eq!(
            csv(&[w]),
            "t,id,x,y,z,heading,group\n\
             0.00,\"a,1\",100.000,200.000,3.000,90.0,g\n\
             0.50,\"a,1\",100.500,200.000,3.000,0.0,g\n"
        );
    }
}
