//! The walls of a parent's massing that no one can see: a machiya's side wall against its
//! neighbour's (町家 stand wall to wall along a street, each drawn as its own box). Two
//! such walls lie in one plane facing each other, each inside the other's box; drawing
//! them was a third of a row house's triangles at every level above the leaves.
//!
//! A wall is left out when another mass's wall, facing it, covers it: the same line within
//! [`NEAR`] (the footprints' rectangles of two row houses meet within centimetres), its
//! ends within the other's, its foot no lower and its top no higher. Nothing seen from
//! outside changes but a slit of at most [`NEAR`] between the two boxes, far under any
//! level's error (metres).

use std::collections::HashMap;

use super::massing::Mass;

/// How far apart two walls may be and still hide each other, metres.
const NEAR: f64 = 0.25;

/// How nearly opposite two walls must face: the cosine of about 2.6 degrees.
const FACING: f64 = 0.999;

/// The side of the grid cells walls are found in, metres.
const CELL: f64 = 16.0;

/// One wall: its foot's ends (counter-clockwise around its mass, seen from above) and its
/// foot and top heights.
#[derive(Debug, Clone, Copy)]
struct Wall {
    from: [f64; 2],
    to: [f64; 2],
    base: f64,
    top: f64,
}

/// The four walls of `m`, up to its eaves (`flat`: up to its flat top).
fn walls(m: &Mass, flat: bool) -> [Wall; 4] {
    let top = if flat { m.flat } else { m.eave };
    std::array::from_fn(|k| Wall {
        from: m.rect[k],
        to: m.rect[(k + 1) % 4],
        base: m.base,
        top,
    })
}

/// Whether `b` hides `a`: facing it on the same line, over all of its length and height.
fn covers(b: &Wall, a: &Wall) -> bool {
    let (da, db) = (sub(a.to, a.from), sub(b.to, b.from));
    let (la, lb) = (len(da), len(db));
    if la < 1e-9 || lb < 1e-9 || dot(da, db) / (la * lb) > -FACING {
        return false;
    }
    if b.base > a.base + NEAR || b.top < a.top - NEAR {
        return false;
    }
    // `a`'s ends on `b`'s line, within its length.
    [a.from, a.to].iter().all(|&p| {
        let v = sub(p, b.from);
        let along = dot(v, db) / lb;
        let across = (v[0] * db[1] - v[1] * db[0]).abs() / lb;
        across <= NEAR && along >= -NEAR && along <= lb + NEAR
    })
}

/// For each of `masses`, which of its four walls (the rectangle's sides from corner k to
/// k + 1) another's wall hides. `flat`: the masses are drawn as flat boxes.
pub fn hidden_walls(masses: &[Mass], flat: bool) -> Vec<[bool; 4]> {
    let all: Vec<[Wall; 4]> = masses.iter().map(|m| walls(m, flat)).collect();
    // Each wall in the cells its box touches.
    // Looked up, never iterated: a fast fixed hash.
    let mut grid: HashMap<(i64, i64), Vec<(usize, usize)>, foldhash::fast::FixedState> =
        HashMap::default();
    for (i, ws) in all.iter().enumerate() {
        for (k, w) in ws.iter().enumerate() {
            for cell in cells(w) {
                grid.entry(cell).or_default().push((i, k));
            }
        }
    }
    all.iter()
        .enumerate()
        .map(|(i, ws)| {
            std::array::from_fn(|k| {
                let a = &ws[k];
                cells(a).any(|cell| {
                    grid.get(&cell).is_some_and(|near| {
                        near.iter().any(|&(j, v)| j != i && covers(&all[j][v], a))
                    })
                })
            })
        })
        .collect()
}

/// The grid cells the box of `w` (grown by [`NEAR`]) touches.
fn cells(w: &Wall) -> impl Iterator<Item = (i64, i64)> {
    let cell = |v: f64| (v / CELL).floor() as i64;
    let (x0, x1) = (w.from[0].min(w.to[0]) - NEAR, w.from[0].max(w.to[0]) + NEAR);
    let (y0, y1) = (w.from[1].min(w.to[1]) - NEAR, w.from[1].max(w.to[1]) + NEAR);
    let (y0, y1) = (cell(y0), cell(y1));
    (cell(x0)..=cell(x1)).flat_map(move |x| (y0..=y1).map(move |y| (x, y)))
}

fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

fn len(a: [f64; 2]) -> f64 {
    a[0].hypot(a[1])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A box of `w` x `d` metres at `x` (counter-clockwise from above), `h` metres tall.
    fn house(x: f64, w: f64, d: f64, h: f64) -> Mass {
        Mass {
            id: 0,
            rect: [[x, 0.0], [x + w, 0.0], [x + w, d], [x, d]],
            base: 0.0,
            eave: h,
            ridge: h + 2.0,
            flat: h + 1.0,
            wall: [0; 4],
            roof: [0; 4],
            gable_error: 0.0,
            flat_error: 0.0,
        }
    }

    #[test]
    fn row_houses_hide_the_walls_they_share_and_only_those() {
        // Three in a row, the middle one 5 cm off its neighbours; a lone one apart.
        let masses = [
            house(0.0, 6.0, 15.0, 6.0),
            house(6.05, 6.0, 15.0, 6.0),
            house(12.05, 6.0, 15.0, 6.0),
            house(40.0, 6.0, 15.0, 6.0),
        ];
        let hidden = hidden_walls(&masses, false);
        // Walls: 0 front (y = 0), 1 right (x = x + w), 2 back, 3 left.
        assert_eq!(hidden[0], [false, true, false, false]);
        assert_eq!(hidden[1], [false, true, false, true]);
        assert_eq!(hidden[2], [false, false, false, true]);
        assert_eq!(hidden[3], [false; 4]);
    }

    #[test]
    fn a_taller_or_deeper_wall_stays_where_it_shows() {
        // The right one is taller and deeper: its wall over the left one's shows above and
        // behind it; the left one's wall is hidden.
        let masses = [house(0.0, 6.0, 15.0, 6.0), house(6.0, 6.0, 20.0, 9.0)];
        let hidden = hidden_walls(&masses, false);
        assert_eq!(hidden[0], [false, true, false, false]);
        assert_eq!(hidden[1], [false; 4]);
        // As flat boxes the tops are what count: the same here.
        assert_eq!(hidden_walls(&masses, true)[1], [false; 4]);
    }

    #[test]
    fn walls_too_far_apart_or_askew_hide_nothing() {
        let apart = [house(0.0, 6.0, 15.0, 6.0), house(6.5, 6.0, 15.0, 6.0)];
        assert!(hidden_walls(&apart, false).iter().all(|h| h == &[false; 4]));
        let mut askew = house(6.0, 6.0, 15.0, 6.0);
        // Its left wall turned by 5 degrees about its foot.
        let a = 5f64.to_radians();
        askew.rect[0] = [6.0 + 15.0 * a.sin(), 15.0 - 15.0 * a.cos()];
        let h = hidden_walls(&[house(0.0, 6.0, 15.0, 6.0), askew], false);
        assert_eq!(h[0], [false; 4]);
    }
}
