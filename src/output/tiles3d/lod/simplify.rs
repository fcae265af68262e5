//! A level's surfaces simplified by meshoptimizer, in time linear in what a model holds.
//!
//! meshoptimizer's edge-collapse simplifier classifies each vertex by walking its edges
//! against its neighbours' lists: time grows with the square of a vertex's valence. A
//! landmark model of 600,000 copies of one triangle (a small file, issue 57's class of
//! numbers that inputs allow) held one level's simplification for 390 s. Repeated and
//! degenerate triangles are dropped first (they carry no surface), and a part whose busiest
//! vertex still touches more than [`MAX_VALENCE`] triangles is simplified by clustering
//! instead (`simplify_sloppy`: no adjacency), with the error measured the same way.

use super::Part;

/// The most triangles at one vertex for which the edge-collapse simplifier is used: a
/// template's or a tree's busiest vertex touches a few dozen.
pub const MAX_VALENCE: usize = 1024;

/// `part` welded (equal position, colour and row) and simplified by meshoptimizer to
/// `target` metres, small disconnected parts pruned; with the error meshoptimizer measured.
pub fn simplify(part: Part, target: f64) -> (Part, f64) {
    if part.indices.is_empty() {
        return (part, 0.0);
    }
    let centre = part.positions[0];
    let mut welded = Part::default();
    // Looked up, never iterated: a fast fixed hash (SipHash was most of the welding).
    let mut index: std::collections::HashMap<
        ([i64; 3], [u8; 4], u32),
        u32,
        foldhash::fast::FixedState,
    > = Default::default();
    let remap: Vec<u32> = (0..part.positions.len())
        .map(|v| {
            let p = part.positions[v];
            let key = (
                p.map(|x| (x * 1000.0).round() as i64),
                part.colours[v],
                part.ids[v],
            );
            *index.entry(key).or_insert_with(|| {
                welded.positions.push(p);
                welded.colours.push(part.colours[v]);
                welded.ids.push(part.ids[v]);
                (welded.positions.len() - 1) as u32
            })
        })
        .collect();
    let welded_indices: Vec<u32> = part.indices.iter().map(|&i| remap[i as usize]).collect();
    let indices = distinct_triangles(&welded_indices);
    let local: Vec<f32> = welded
        .positions
        .iter()
        .flat_map(|p| [0, 1, 2].map(|k| (p[k] - centre[k]) as f32))
        .collect();
    let bytes = meshopt::utilities::typed_to_bytes(&local);
    let adapter =
        meshopt::VertexDataAdapter::new(bytes, 12, 0).expect("a whole number of vertices");
    let mut error = 0.0f32;
    let kept = if max_valence(&indices, welded.positions.len()) <= MAX_VALENCE {
        meshopt::simplify(
            &indices,
            &adapter,
            0,
            target as f32,
            meshopt::SimplifyOptions::ErrorAbsolute | meshopt::SimplifyOptions::Prune,
            Some(&mut error),
        )
    } else {
        // Sloppy simplification clusters vertices on a grid: no adjacency, linear time. Its
        // error is relative to the part's extent.
        let scale = meshopt::simplify_scale(&adapter).max(f32::MIN_POSITIVE);
        let kept = meshopt::simplify_sloppy(
            &indices,
            &adapter,
            0,
            target as f32 / scale,
            Some(&mut error),
        );
        error *= scale;
        kept
    };
    // Only the vertices still used.
    let mut out = Part::default();
    let mut seen = vec![u32::MAX; welded.positions.len()];
    for &v in &kept {
        out.keep(&welded, v, &mut seen);
    }
    (out, error as f64)
}

/// The triangles of `indices` with three distinct corners, each once whatever corner it
/// starts at (its winding kept), in their first order.
pub fn distinct_triangles(indices: &[u32]) -> Vec<u32> {
    let mut seen = std::collections::HashSet::with_capacity(indices.len() / 3);
    let mut out = Vec::with_capacity(indices.len());
    for t in indices.chunks_exact(3) {
        let (a, b, c) = (t[0], t[1], t[2]);
        if a == b || b == c || a == c {
            continue;
        }
        // The rotation that starts at the least corner: the same triangle, the same key.
        let key = match (a < b && a < c, b < c) {
            (true, _) => [a, b, c],
            (false, true) => [b, c, a],
            (false, false) => [c, a, b],
        };
        if seen.insert(key) {
            out.extend_from_slice(t);
        }
    }
    out
}

/// The most triangles that share one of `n` vertices.
pub fn max_valence(indices: &[u32], n: usize) -> usize {
    let mut count = vec![0usize; n];
    for &i in indices {
        if let Some(c) = count.get_mut(i as usize) {
            *c += 1;
        }
    }
    count.into_iter().max().unwrap_or(0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn repeated_and_degenerate_triangles_are_dropped_turned_ones_too() {
        let tris = [0, 1, 2, 1, 2, 0, 2, 0, 1, 0, 2, 1, 3, 3, 4, 0, 1, 2];
        // (1,2,0) and (2,0,1) are (0,1,2) turned; (0,2,1) is the other side; (3,3,4) is a line.
        assert_eq!(distinct_triangles(&tris), vec![0, 1, 2, 0, 2, 1]);
        assert_eq!(max_valence(&[0, 1, 2, 0, 2, 3], 4), 2);
    }

    #[test]
    fn a_fan_past_the_valence_is_simplified_by_clustering_in_linear_time() {
        // A disc of 20,000 slices around one centre: the centre's valence is 20,000.
        let n = 20_000u32;
        let mut part = Part::default();
        part.positions.push([0.0, 0.0, 0.0]);
        for k in 0..n {
            let a = k as f64 / n as f64 * std::f64::consts::TAU;
            part.positions.push([10.0 * a.cos(), 0.0, 10.0 * a.sin()]);
        }
        part.colours = vec![[200, 200, 200, 255]; part.positions.len()];
        part.ids = vec![0; part.positions.len()];
        for k in 0..n {
            part.indices.extend_from_slice(&[0, 1 + (k + 1) % n, 1 + k]);
        }
        assert!(max_valence(&part.indices, part.positions.len()) > MAX_VALENCE);
        let (out, error) = simplify(part, 1.0);
        assert!(out.indices.len() / 3 < 2_000, "{}", out.indices.len() / 3);
        assert!(error.is_finite() && error <= 1.5, "{error}");
    }
}
