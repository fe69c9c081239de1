//! Seeded sampling for benchmarks and tests: surface points uniform by area, and anchor
//! vertices by farthest-point sampling.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use rand::distr::Distribution;
use rand::distr::weighted::WeightedIndex;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use wavg_mesh::geometry::face_areas;
use wavg_mesh::{SurfacePoint, TriMesh, ValidMesh, VertexId};

use crate::Vec8;
use crate::error::SolveError;

/// `n` surface points distributed uniformly by area (face chosen with probability
/// proportional to its area, then a uniform point in it), reproducible from `seed`.
///
/// ```
/// use wavg_mesh::procedural;
/// let m = procedural::icosphere(2);
/// let pts = wavg_solve::sampling::uniform_surface_points(&m, 100, 7).unwrap();
/// assert_eq!(pts, wavg_solve::sampling::uniform_surface_points(&m, 100, 7).unwrap());
/// assert!(pts.iter().all(|p| (p.bary.iter().sum::<f64>() - 1.0).abs() < 1e-12));
/// ```
pub fn uniform_surface_points(
    mesh: &TriMesh,
    n: usize,
    seed: u64,
) -> Result<Vec<SurfacePoint>, SolveError> {
    let areas = face_areas(mesh);
    let pick = WeightedIndex::new(&areas)
        .map_err(|e| SolveError::InvalidParameter(format!("cannot sample by area: {e}")))?;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    Ok((0..n)
        .map(|_| {
            let f = pick.sample(&mut rng) as u32;
            let r1: f64 = rng.random();
            let r2: f64 = rng.random();
            let s = r1.sqrt();
            let b1 = s * (1.0 - r2);
            let b2 = s * r2;
            SurfacePoint::new(f, [1.0 - b1 - b2, b1, b2])
        })
        .collect())
}

/// An ordering of `points` along a Morton (Z-order) curve over their bounding box, so that
/// consecutive points are usually close: the order for warm-started query sequences.
///
/// ```
/// use nalgebra::Vector3;
/// let p = [Vector3::new(1.0, 1.0, 0.0), Vector3::new(0.0, 0.0, 0.0), Vector3::new(0.9, 1.0, 0.0)];
/// assert_eq!(wavg_solve::sampling::spatial_order(&p), vec![1, 2, 0]);
/// ```
pub fn spatial_order(points: &[nalgebra::Vector3<f64>]) -> Vec<usize> {
    let mut lo = nalgebra::Vector3::repeat(f64::INFINITY);
    let mut hi = nalgebra::Vector3::repeat(f64::NEG_INFINITY);
    for p in points {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    let ext = (hi - lo).max().max(f64::MIN_POSITIVE);
    let key = |p: &nalgebra::Vector3<f64>| -> u64 {
        let mut k = 0u64;
        let q = (p - lo).map(|x| ((x / ext) * 2097151.0).clamp(0.0, 2097151.0) as u64);
        for bit in (0..21).rev() {
            for c in 0..3 {
                k = (k << 1) | ((q[c] >> bit) & 1);
            }
        }
        k
    };
    let mut idx: Vec<(u64, usize)> = points
        .iter()
        .enumerate()
        .map(|(i, p)| (key(p), i))
        .collect();
    idx.sort_unstable();
    idx.into_iter().map(|(_, i)| i).collect()
}

/// Which distance farthest-point sampling maximises.
#[derive(Clone, Copy, Debug)]
pub enum FpsMetric<'a> {
    /// Shortest paths along mesh edges (3-D edge lengths): an upper bound of the geodesic
    /// distance that does not depend on any embedding, so anchor sets are the same with or
    /// without one. The default.
    EdgeGraph,
    /// Straight-line distance between the vertices' coordinates in R^8 (one per vertex).
    Embedding(&'a [Vec8]),
}

/// `k` distinct vertices by farthest-point sampling: the first is drawn at random from
/// `seed`, each next one is the vertex farthest (in `metric`) from those already chosen
/// (ties to the lowest index). Vertices of other connected components are infinitely far
/// in [`FpsMetric::EdgeGraph`], so every component gets an anchor before any gets a
/// second one.
///
/// ```
/// use wavg_mesh::{ValidMesh, procedural};
/// use wavg_solve::sampling::{FpsMetric, farthest_point_vertices};
/// let m = ValidMesh::new(procedural::icosphere(2)).unwrap();
/// let a = farthest_point_vertices(&m, 10, 1, FpsMetric::EdgeGraph).unwrap();
/// assert_eq!(a.len(), 10);
/// ```
pub fn farthest_point_vertices(
    mesh: &ValidMesh,
    k: usize,
    seed: u64,
    metric: FpsMetric<'_>,
) -> Result<Vec<VertexId>, SolveError> {
    let nv = mesh.n_vertices();
    if k > nv {
        return Err(SolveError::InvalidParameter(format!(
            "cannot choose {k} anchors among {nv} vertices"
        )));
    }
    if k == 0 {
        check_metric(nv, metric)?;
        return Ok(Vec::new());
    }
    Ok(farthest_point_vertices_until(mesh, seed, metric, k, |_, _| false)?.0)
}

/// Farthest-point sampling (the order of [`farthest_point_vertices`] with this `seed`)
/// until `stop(count, gap)` holds or `max` vertices (at least 1, at most the vertex count)
/// are chosen, where `gap` is the largest distance in `metric` from a vertex to its
/// nearest chosen one. Returns the vertices and that gap: the one loop behind the
/// fixed-count spread and the gap-bounded one ([`crate::spread::spread_to_gap`]).
///
/// ```
/// use wavg_mesh::{ValidMesh, procedural};
/// use wavg_solve::sampling::{FpsMetric, farthest_point_vertices, farthest_point_vertices_until};
/// let m = ValidMesh::new(procedural::icosphere(2)).unwrap();
/// let (a, gap) = farthest_point_vertices_until(&m, 1, FpsMetric::EdgeGraph, 100, |_, g| g < 0.5)?;
/// assert!(gap < 0.5);
/// assert_eq!(a, farthest_point_vertices(&m, a.len(), 1, FpsMetric::EdgeGraph)?);
/// # Ok::<(), wavg_solve::SolveError>(())
/// ```
pub fn farthest_point_vertices_until(
    mesh: &ValidMesh,
    seed: u64,
    metric: FpsMetric<'_>,
    max: usize,
    mut stop: impl FnMut(usize, f64) -> bool,
) -> Result<(Vec<VertexId>, f64), SolveError> {
    let nv = mesh.n_vertices();
    check_metric(nv, metric)?;
    if nv == 0 {
        return Err(SolveError::InvalidParameter(
            "cannot choose anchors on a mesh without vertices".into(),
        ));
    }
    let max = max.clamp(1, nv);
    let mut out = Vec::with_capacity(max);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut dist = vec![f64::INFINITY; nv];
    let mut next = rng.random_range(0..nv) as VertexId;
    let mut heap = BinaryHeap::new();
    loop {
        out.push(next);
        match metric {
            FpsMetric::EdgeGraph => relax_from(mesh, next, &mut dist, &mut heap),
            FpsMetric::Embedding(c) => {
                let y = c[next as usize];
                for (d, x) in dist.iter_mut().zip(c) {
                    *d = d.min((x - y).norm());
                }
            }
        }
        let mut best = 0usize;
        for (v, &d) in dist.iter().enumerate() {
            if d > dist[best] {
                best = v;
            }
        }
        if out.len() >= max || stop(out.len(), dist[best]) {
            return Ok((out, dist[best]));
        }
        next = best as VertexId;
    }
}

/// Refuses embedded coordinates that are not one per vertex.
fn check_metric(nv: usize, metric: FpsMetric<'_>) -> Result<(), SolveError> {
    match metric {
        FpsMetric::Embedding(c) if c.len() != nv => Err(SolveError::InvalidParameter(format!(
            "{} embedded coordinates for {nv} vertices",
            c.len()
        ))),
        _ => Ok(()),
    }
}

/// `k` distinct vertices of `n_vertices` drawn uniformly at random from `seed` (in the
/// order drawn): `wavg anchors --method random`.
///
/// ```
/// let a = wavg_solve::sampling::random_vertices(100, 5, 7).unwrap();
/// assert_eq!(a, wavg_solve::sampling::random_vertices(100, 5, 7).unwrap());
/// assert!(wavg_solve::sampling::random_vertices(4, 5, 7).is_err());
/// ```
pub fn random_vertices(
    n_vertices: usize,
    k: usize,
    seed: u64,
) -> Result<Vec<VertexId>, SolveError> {
    if k > n_vertices {
        return Err(SolveError::InvalidParameter(format!(
            "cannot choose {k} anchors among {n_vertices} vertices"
        )));
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    Ok(rand::seq::index::sample(&mut rng, n_vertices, k)
        .into_iter()
        .map(|v| v as VertexId)
        .collect())
}

/// Min-heap entry for Dijkstra.
#[derive(PartialEq)]
struct Entry(f64, VertexId);
impl Eq for Entry {}
impl Ord for Entry {
    fn cmp(&self, o: &Self) -> Ordering {
        o.0.total_cmp(&self.0).then(o.1.cmp(&self.1))
    }
}
impl PartialOrd for Entry {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}

/// Lowers `dist` to the edge-graph distance from `source` where that is shorter; only the
/// region that improves is visited, so the whole sampling costs about one full Dijkstra.
fn relax_from(mesh: &ValidMesh, source: VertexId, dist: &mut [f64], heap: &mut BinaryHeap<Entry>) {
    let topo = mesh.topology();
    let pos = &mesh.positions;
    heap.clear();
    dist[source as usize] = 0.0;
    heap.push(Entry(0.0, source));
    while let Some(Entry(d, u)) = heap.pop() {
        if d > dist[u as usize] {
            continue;
        }
        for &v in topo.ring(u) {
            let nd = d + (pos[u as usize] - pos[v as usize]).norm();
            if nd < dist[v as usize] {
                dist[v as usize] = nd;
                heap.push(Entry(nd, v));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use wavg_mesh::procedural;

    #[test]
    fn fps_is_distinct_seeded_and_spread() {
        let m = ValidMesh::new(procedural::icosphere(3)).unwrap();
        let a = farthest_point_vertices(&m, 20, 5, FpsMetric::EdgeGraph).unwrap();
        let mut s = a.clone();
        s.sort();
        s.dedup();
        assert_eq!(s.len(), 20);
        assert_eq!(
            a,
            farthest_point_vertices(&m, 20, 5, FpsMetric::EdgeGraph).unwrap()
        );
        // The second anchor is (nearly) antipodal to the first on the unit sphere.
        let p = |v: VertexId| m.positions[v as usize];
        assert!((p(a[0]) + p(a[1])).norm() < 0.2);
        let coords: Vec<Vec8> = m
            .positions
            .iter()
            .map(|p| Vec8::from_fn(|k, _| if k < 3 { p[k] } else { 0.0 }))
            .collect();
        let b = farthest_point_vertices(&m, 20, 5, FpsMetric::Embedding(&coords)).unwrap();
        assert_eq!(b[0], a[0]);
        assert!((p(b[0]) + p(b[1])).norm() < 1e-9);
        assert!(farthest_point_vertices(&m, 643, 5, FpsMetric::EdgeGraph).is_err());
        assert!(farthest_point_vertices(&m, 3, 5, FpsMetric::Embedding(&coords[1..])).is_err());
    }

    #[test]
    fn area_sampling_follows_area() {
        // Two faces of very different areas: counts follow the area ratio.
        let m = procedural::grid(2, 1, 3.0, 1.0).map_positions(|p| {
            if p.x > 1.6 {
                nalgebra::Vector3::new(p.x * 3.0, p.y, p.z)
            } else {
                p
            }
        });
        let areas = face_areas(&m);
        let pts = uniform_surface_points(&m, 20000, 3).unwrap();
        let total: f64 = areas.iter().sum();
        for (f, a) in areas.iter().enumerate() {
            let c = pts.iter().filter(|p| p.face as usize == f).count() as f64 / 20000.0;
            assert!(
                (c - a / total).abs() < 0.02,
                "face {f}: {c} vs {}",
                a / total
            );
        }
        assert!(
            pts.iter()
                .all(|p| p.bary.iter().all(|&b| (0.0..=1.0).contains(&b)))
        );
    }
}
