//! Anchor sets judged by their largest gap: farthest-point spreading in an embedding until
//! the gap is small enough, the gap itself, the count that should close it, and a short
//! closed tour through chosen points (the order of a closed spline's control points).

use wavg_mesh::{ValidMesh, VertexId};

use crate::Vec8;
use crate::error::SolveError;
use crate::sampling::{FpsMetric, farthest_point_vertices_until};

/// The largest gap (a fraction of the bounding-box diagonal) at or below which round
/// trips are reliable: about 90% of them lead back on real meshes.
pub const GOOD_GAP: f64 = 0.08;

/// Farthest-point sampling in the embedding `coords` (one point per vertex; the same
/// order as [`crate::sampling::farthest_point_vertices`] with [`FpsMetric::Embedding`]
/// and this `seed`) until the largest gap is at most `target` of the mesh's bounding-box
/// diagonal, with `min` to `max` anchors (`max` capped at the vertex count). Returns the
/// anchors and the gap reached, as a fraction of the diagonal.
///
/// ```
/// use wavg_mesh::{ValidMesh, procedural};
/// use wavg_solve::Vec8;
/// use wavg_solve::spread::{GOOD_GAP, largest_gap, spread_to_gap};
/// let m = ValidMesh::new(procedural::icosphere(3)).unwrap();
/// let c: Vec<Vec8> = m.positions.iter().map(|p| Vec8::from_fn(|k, _| if k < 3 { p[k] } else { 0.0 })).collect();
/// let (a, gap) = spread_to_gap(&m, &c, 0, 4, 500, GOOD_GAP)?;
/// assert!(gap <= GOOD_GAP && a.len() >= 4);
/// assert_eq!(gap, largest_gap(&c, &a) / m.bounding_box_diagonal());
/// # Ok::<(), wavg_solve::SolveError>(())
/// ```
pub fn spread_to_gap(
    mesh: &ValidMesh,
    coords: &[Vec8],
    seed: u64,
    min: usize,
    max: usize,
    target: f64,
) -> Result<(Vec<VertexId>, f64), SolveError> {
    let diagonal = mesh.bounding_box_diagonal().max(f64::MIN_POSITIVE);
    let (out, gap) =
        farthest_point_vertices_until(mesh, seed, FpsMetric::Embedding(coords), max, |n, gap| {
            n >= min && gap / diagonal <= target
        })?;
    Ok((out, gap / diagonal))
}

/// The largest distance from a vertex to its nearest anchor, in the embedding `coords`
/// (one point per vertex): the covering radius of the anchors. Anchors out of range are
/// skipped; with none, the gap is infinite.
///
/// ```
/// use wavg_solve::Vec8;
/// let c: Vec<Vec8> = (0..5).map(|i| Vec8::from_fn(|k, _| if k == 0 { i as f64 } else { 0.0 })).collect();
/// assert_eq!(wavg_solve::spread::largest_gap(&c, &[0, 4]), 2.0);
/// ```
pub fn largest_gap(coords: &[Vec8], anchors: &[VertexId]) -> f64 {
    let mut dist = vec![f64::INFINITY; coords.len()];
    for &a in anchors {
        let Some(&y) = coords.get(a as usize) else {
            continue;
        };
        for (d, x) in dist.iter_mut().zip(coords) {
            *d = d.min((x - y).norm());
        }
    }
    dist.into_iter().fold(0.0, f64::max)
}

/// A count that should bring a `gap` found with `count` anchors to [`GOOD_GAP`] (always
/// more than `count`): on a surface the gap shrinks like one over the square root of the
/// count.
///
/// ```
/// assert_eq!(wavg_solve::spread::suggested_count(8, 0.16), 32);
/// ```
pub fn suggested_count(count: usize, gap: f64) -> usize {
    let ratio = gap / GOOD_GAP;
    ((count as f64 * ratio * ratio).ceil() as usize).max(count + 1)
}

/// An order of `points` as a short closed tour (nearest neighbour from the first point,
/// then 2-opt until no swap shortens it): control points of a closed spline in that order
/// make a loop without crossings, whichever way the mesh is oriented.
///
/// ```
/// use wavg_solve::Vec8;
/// let p: Vec<Vec8> = [0.0, 2.0, 1.0].iter().map(|&x| Vec8::from_fn(|k, _| if k == 0 { x } else { 0.0 })).collect();
/// assert_eq!(wavg_solve::spread::closed_tour(&p), vec![0, 2, 1]);
/// ```
pub fn closed_tour(points: &[Vec8]) -> Vec<usize> {
    let n = points.len();
    if n == 0 {
        return Vec::new();
    }
    let d = |a: usize, b: usize| (points[a] - points[b]).norm();
    let mut tour = vec![0usize];
    let mut left: Vec<usize> = (1..n).collect();
    let mut last = 0;
    while let Some((i, _)) = left
        .iter()
        .enumerate()
        .min_by(|a, b| d(last, *a.1).total_cmp(&d(last, *b.1)))
    {
        last = left.swap_remove(i);
        tour.push(last);
    }
    let mut improved = n > 3;
    while improved {
        improved = false;
        for i in 0..n - 1 {
            for j in i + 2..n {
                let (a, b, c, e) = (tour[i], tour[i + 1], tour[j], tour[(j + 1) % n]);
                if a != e && d(a, c) + d(b, e) < d(a, b) + d(c, e) - 1e-12 {
                    tour[i + 1..=j].reverse();
                    improved = true;
                }
            }
        }
    }
    tour
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::farthest_point_vertices;
    use wavg_mesh::procedural;

    #[test]
    fn tour_of_a_scrambled_circle_goes_round_it() {
        let angles = [0.0, 3.0, 1.0, 5.0, 2.0, 4.0, 6.0, 7.0];
        let pts: Vec<Vec8> = angles
            .iter()
            .map(|&k: &f64| {
                let t = k * std::f64::consts::TAU / 8.0;
                let mut v = Vec8::zeros();
                (v[1], v[2]) = (t.cos(), t.sin()); // a y-up circle
                v
            })
            .collect();
        let tour = closed_tour(&pts);
        let steps: Vec<f64> = (0..8)
            .map(|i| (pts[tour[i]] - pts[tour[(i + 1) % 8]]).norm())
            .collect();
        let side = 2.0 * (std::f64::consts::PI / 8.0).sin();
        assert!(steps.iter().all(|s| (s - side).abs() < 1e-9), "{steps:?}");
        assert!(closed_tour(&[]).is_empty());
        assert_eq!(closed_tour(&pts[..1]), vec![0]);
    }

    #[test]
    fn gap_is_the_covering_radius() {
        let c: Vec<Vec8> = (0..5)
            .map(|i| {
                let mut v = Vec8::zeros();
                v[0] = i as f64;
                v
            })
            .collect();
        assert_eq!(largest_gap(&c, &[0]), 4.0);
        assert_eq!(largest_gap(&c, &[0, 4]), 2.0);
        assert_eq!(largest_gap(&c, &[0, 2, 4]), 1.0);
        assert_eq!(largest_gap(&c, &[]), f64::INFINITY);
        assert_eq!(suggested_count(8, 0.16), 32);
        assert_eq!(suggested_count(8, 0.08), 9);
    }

    fn padded(m: &ValidMesh) -> Vec<Vec8> {
        m.positions
            .iter()
            .map(|p| Vec8::from_fn(|k, _| if k < 3 { p[k] } else { 0.0 }))
            .collect()
    }

    #[test]
    fn gap_spread_is_a_prefix_of_the_fixed_count_spread() {
        let m = ValidMesh::new(procedural::torus(40, 16, 1.0, 0.35)).unwrap();
        let c = padded(&m);
        let diag = m.bounding_box_diagonal();
        let (a, gap) = spread_to_gap(&m, &c, 9, 8, 400, GOOD_GAP).unwrap();
        assert!(a.len() > 8 && a.len() < 400, "{}", a.len());
        assert!(gap <= GOOD_GAP);
        // One loop: the same vertices as the fixed-count spread, the same gap as measured.
        let fixed = farthest_point_vertices(&m, a.len(), 9, FpsMetric::Embedding(&c)).unwrap();
        assert_eq!(a, fixed);
        assert_eq!(gap, largest_gap(&c, &a) / diag);
        // One fewer anchor leaves a gap above the target.
        assert!(largest_gap(&c, &a[..a.len() - 1]) / diag > GOOD_GAP);
        // `min` and `max` bound the count.
        let (a, _) = spread_to_gap(&m, &c, 9, 30, 400, GOOD_GAP).unwrap();
        assert!(a.len() >= 30);
        let (a, gap) = spread_to_gap(&m, &c, 9, 1, 5, GOOD_GAP).unwrap();
        assert_eq!(a.len(), 5);
        assert!(gap > GOOD_GAP);
        assert!(spread_to_gap(&m, &c[1..], 9, 1, 5, GOOD_GAP).is_err());
    }
}
