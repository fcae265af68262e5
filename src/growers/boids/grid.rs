//! A uniform grid over the agents, for the neighbour queries of a step: cells of the
//! largest zone's size, so an agent's neighbours are in its cell and the eight around it.

use std::collections::HashMap;

// Looked up, never iterated: a fast fixed hash (SipHash was a tenth of the crowds' step).
use foldhash::fast::FixedState;

use super::Boid;

/// The agents by cell.
pub(super) struct Grid {
    cell: f64,
    cells: HashMap<(i64, i64), Vec<usize>, FixedState>,
}

impl Grid {
    /// The grid of `boids` with cells of `cell` (> 0).
    pub(super) fn new(boids: &[Boid], cell: f64) -> Grid {
        let mut cells: HashMap<(i64, i64), Vec<usize>, FixedState> = HashMap::default();
        for (i, b) in boids.iter().enumerate() {
            cells.entry(key(b.pos, cell)).or_default().push(i);
        }
        Grid { cell, cells }
    }

    /// Calls `f` with every agent in the cells around `p`, cells in a fixed order and each
    /// cell's agents in index order (the caller's sums then do not depend on hashing).
    pub(super) fn near(&self, p: [f64; 2], mut f: impl FnMut(usize)) {
        let (cx, cy) = key(p, self.cell);
        for dy in -1..=1 {
            for dx in -1..=1 {
                if let Some(v) = self.cells.get(&(cx + dx, cy + dy)) {
                    v.iter().for_each(|&i| f(i));
                }
            }
        }
    }
}

fn key(p: [f64; 2], cell: f64) -> (i64, i64) {
    ((p[0] / cell).floor() as i64, (p[1] / cell).floor() as i64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_grid_finds_every_agent_within_a_cell_and_no_far_one() {
        let at = |x: f64, y: f64| Boid {
            pos: [x, y],
            heading: [1.0, 0.0],
            speed: 1.0,
        };
        let boids = vec![at(5.0, 5.0), at(14.0, 5.0), at(35.0, 5.0), at(5.0, -4.0)];
        let g = Grid::new(&boids, 10.0);
        let mut seen = Vec::new();
        g.near([5.0, 5.0], |i| seen.push(i));
        seen.sort();
        assert_eq!(seen, vec![0, 1, 3]);
    }
}
