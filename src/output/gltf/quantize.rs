//! Positions as shorts (`KHR_mesh_quantization`, which every tile already requires for its
//! normals): a vertex's position is a whole number of `step`s from `centre`, and the node
//! drawing it is moved to `centre` and scaled by `step` (gltfpack's layout). Floats rounded
//! to 1/1024 m still vary in their exponent and high mantissa bits from vertex to vertex,
//! which meshopt's byte-wise vertex codec stores poorly; shorts are 8 bytes a vertex (x, y,
//! z and a pad) before compression instead of 12 and compress to about half of the floats.
//!
//! One grid per tile, shared by all its nodes: the same point in two nodes (a wall's foot on
//! the ground) lands on the same short, so no crack opens between them. The step is a power
//! of two, so a dequantized position is an exact float, and never finer than the 1/1024 m
//! the positions were rounded to: a tile under 64 m across keeps them exactly.

/// The positions' grid of a tile or a model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    /// Where the node is moved to (metres, y up): a whole number of steps.
    pub centre: [f32; 3],
    /// The node's scale: metres a unit.
    pub step: f32,
}

/// The finest step: the 1/1024 m the positions are rounded to.
const FINEST: f32 = 1.0 / 1024.0;

/// The largest short a coordinate takes (±, one left for rounding).
const REACH: f32 = 32_766.0;

impl Grid {
    /// The grid over `positions` (x, y, z floats in a row): the finest power-of-two step
    /// at which every position is within a short of the box's centre. An empty list gives
    /// the finest step at the origin.
    pub fn over(positions: impl IntoIterator<Item = f32>) -> Grid {
        let mut lo = [f32::INFINITY; 3];
        let mut hi = [f32::NEG_INFINITY; 3];
        for (i, v) in positions.into_iter().enumerate() {
            lo[i % 3] = lo[i % 3].min(v);
            hi[i % 3] = hi[i % 3].max(v);
        }
        if lo[0] > hi[0] {
            return Grid {
                centre: [0.0; 3],
                step: FINEST,
            };
        }
        let half = (0..3).map(|k| (hi[k] - lo[k]) / 2.0).fold(0.0, f32::max);
        let step = Self::step_for(half);
        let centre = [0, 1, 2].map(|k| (((lo[k] + hi[k]) / 2.0) / step).round() * step);
        Grid { centre, step }
    }

    /// The grid of a model placed by instances: centred on its origin (the trunk's foot), so
    /// that an instance's scale times the step is all it takes to place it.
    pub fn at_origin(positions: impl IntoIterator<Item = f32>) -> Grid {
        let reach = positions.into_iter().fold(0.0f32, |m, v| m.max(v.abs()));
        Grid {
            centre: [0.0; 3],
            step: Self::step_for(reach),
        }
    }

    /// The finest power-of-two step (not under [`FINEST`]) that reaches `half` in a short,
    /// with a step to spare for the centre's rounding.
    fn step_for(half: f32) -> f32 {
        let mut step = FINEST;
        while half / step + 1.0 > REACH {
            step *= 2.0;
        }
        step
    }

    /// `positions` (x, y, z floats in a row) as shorts on the grid.
    pub fn shorts(&self, positions: &[f32]) -> Vec<[i16; 3]> {
        positions
            .chunks_exact(3)
            .map(|p| {
                [0, 1, 2].map(|k| {
                    ((p[k] - self.centre[k]) / self.step)
                        .round()
                        .clamp(-REACH - 1.0, REACH + 1.0) as i16
                })
            })
            .collect()
    }

    /// The node's `translation` and `scale` that turn the shorts back into metres.
    pub fn node_transform(&self) -> serde_json::Value {
        let step = [self.step; 3];
        serde_json::json!({"translation": self.centre, "scale": step})
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Back to metres as a client does: centre + step * short.
    fn metres(g: &Grid, q: [i16; 3]) -> [f32; 3] {
        [0, 1, 2].map(|k| g.centre[k] + g.step * f32::from(q[k]))
    }

    #[test]
    fn a_small_tile_keeps_its_positions_exactly() {
        // Multiples of 1/1024 within 60 m: the finest step holds them all.
        let p: Vec<f32> = (0..300)
            .map(|i| ((i * 7919) % 61_440) as f32 / 1024.0 - 10.0)
            .collect();
        let g = Grid::over(p.iter().copied());
        assert_eq!(g.step, FINEST);
        for (q, v) in g.shorts(&p).into_iter().zip(p.chunks_exact(3)) {
            assert_eq!(metres(&g, q), [v[0], v[1], v[2]]);
        }
    }

    #[test]
    fn a_city_tile_is_within_half_a_step_of_its_positions() {
        // 250 m across and a building over the edge: 1/128 m.
        let p = [-131.5, 0.0, -125.0, 129.25, 14.0, 125.0, 3.0, 7.5, -2.0];
        let g = Grid::over(p);
        assert_eq!(g.step, 1.0 / 128.0);
        for (q, v) in g.shorts(&p).into_iter().zip(p.chunks_exact(3)) {
            let m = metres(&g, q);
            for k in 0..3 {
                assert!((m[k] - v[k]).abs() <= g.step / 2.0, "{m:?} {v:?}");
            }
        }
        // The centre is on the grid: the same point in another node is the same short.
        for c in g.centre {
            assert_eq!((c / g.step).fract(), 0.0);
        }
    }

    #[test]
    fn a_model_at_its_origin_reaches_its_farthest_point() {
        let p = [0.0, 0.0, 0.0, 4.0, 40.0, -3.0];
        let g = Grid::at_origin(p);
        assert_eq!(g.centre, [0.0; 3]);
        assert_eq!(g.step, 1.0 / 512.0, "40 m is past a short of 1/1024 m");
        let q = g.shorts(&p);
        assert_eq!(metres(&g, q[1]), [4.0, 40.0, -3.0]);
    }

    #[test]
    fn no_positions_is_the_finest_grid() {
        assert_eq!(Grid::over([]).step, FINEST);
    }
}
