//! Landmarks around thin parts. The least-squares mesh extends the landmarks' values by
//! minimising bending, so a part that is thinner than the landmark spacing (a finger
//! with a landmark at its tip and the next ones at its base) comes out as a line: its
//! cross-sections collapse, in the embedding as in space. The check extends the
//! landmarks' own 3D positions with the factored system (a three-column solve) and
//! measures, per face, how much the extension shrinks it; where faces collapse, more
//! landmarks go in, spread by farthest-point sampling over the collapsed region.
//! Meshes whose landmarks already cover every part add none and are unchanged.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use rayon::prelude::*;

use wavg_mesh::ValidMesh;

use crate::decimate::Decimated;
use crate::error::{EmbedError, Progress, check_cancel};
use crate::file::MAX_DIM;
use crate::lsmesh::two_level::LsMeshExtension;

/// A face is collapsed when the extension of the landmarks' positions shrinks it by
/// more than this factor in some direction (the smaller singular value of the face's
/// affine map), and so is a pair of vertices two edges apart whose distance it shrinks
/// by more. Smooth parts that the landmarks cover stay near 1; a part thinner than the
/// landmark spacing drops below 0.1.
pub(crate) const COLLAPSED_SCALE: f64 = 0.5;

/// Landmarks are added only to meshes where faces of [`COLLAPSE_TRIGGER_AREA`] and at
/// least [`COLLAPSE_TRIGGER_FACES`] shrink below this ([`COLLAPSED_SCALE`] then marks what to cover): a clear collapse of
/// a part, which the meshes of the test data never show (at most one sliver), while
/// their curved regions may dip below [`COLLAPSED_SCALE`] in a few faces, and pairs of
/// vertices two edges apart on scans, where such a pair may be far closer than its
/// edges, below the trigger too.
pub(crate) const COLLAPSE_TRIGGER_SCALE: f64 = 0.1;

/// Area of the faces below [`COLLAPSE_TRIGGER_SCALE`] that starts the additions, in
/// landmark spacings (the mesh's area over the landmark count): an area, not a face
/// count, so that a mesh and its subdivisions agree. Thin parts measure 4-9 spacings
/// (bodies' fingers and toes) to 45 (a tube 50 times thinner than its ring); smooth
/// scans 0.02-0.06 whatever their resolution (horse, and its Loop subdivisions).
pub(crate) const COLLAPSE_TRIGGER_AREA: f64 = 0.5;

/// And at least this many faces below [`COLLAPSE_TRIGGER_SCALE`]: on coarse meshes, where
/// a landmark spacing is a handful of faces, a single sliver is no thin part.
pub(crate) const COLLAPSE_TRIGGER_FACES: usize = 16;

/// The smaller singular value of the affine map taking triangle `p` onto triangle `q`
/// (any dimension): how much the map shrinks the triangle in its most shrunk direction.
/// NaN for a degenerate `p`.
fn min_stretch(p: [[f64; 3]; 3], q: [&[f64]; 3]) -> f64 {
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let (a, b) = (sub(p[1], p[0]), sub(p[2], p[0]));
    let la = dot(a, a).sqrt();
    if la == 0.0 {
        return f64::NAN;
    }
    // `p` in its own plane: corners 0, (la, 0), (bx, by).
    let bx = dot(b, a) / la;
    let by = (dot(b, b) - bx * bx).max(0.0).sqrt();
    if by <= 1e-12 * la {
        return f64::NAN;
    }
    // Columns of the map's matrix: J = [qa qb] [[la, bx], [0, by]]^-1.
    let (mut g00, mut g01, mut g11) = (0.0, 0.0, 0.0);
    for ((&q0, &q1), &q2) in q[0].iter().zip(q[1]).zip(q[2]) {
        let (qa, qb) = (q1 - q0, q2 - q0);
        let c0 = qa / la;
        let c1 = (qb - qa * bx / la) / by;
        g00 += c0 * c0;
        g01 += c0 * c1;
        g11 += c1 * c1;
    }
    let (half_trace, det) = ((g00 + g11) / 2.0, g00 * g11 - g01 * g01);
    let disc = (half_trace * half_trace - det).max(0.0).sqrt();
    (half_trace - disc).max(0.0).sqrt()
}

/// Vertices of faces and pairs that the least-squares extension of the landmarks' 3D
/// positions collapses ([`COLLAPSED_SCALE`]), landmarks excluded; none unless faces
/// covering [`COLLAPSE_TRIGGER_AREA`] landmark spacings (and [`COLLAPSE_TRIGGER_FACES`])
/// shrink below [`COLLAPSE_TRIGGER_SCALE`] or `triggered` (an earlier round added
/// landmarks).
///
/// The check runs where the extension is exact: on the full mesh with a direct
/// factorisation, on the coarse level of a two-level one (whose full-mesh solution stops
/// early and keeps small-scale ripples of its prolongation that shrink faces of no
/// part), marking coarse vertices only.
pub(crate) fn collapsed_vertices(
    mesh: &ValidMesh,
    landmarks: &[u32],
    solver: &LsMeshExtension,
    triggered: bool,
    progress: &dyn Progress,
) -> Result<Vec<bool>, EmbedError> {
    match solver {
        LsMeshExtension::Direct(s) => {
            collapsed_on(mesh, landmarks, triggered, |values| s.solve(values, 3))
        }
        LsMeshExtension::TwoLevel(t) => {
            let (coarse, ids, s) = t.coarse_level();
            let local = landmarks
                .iter()
                .map(|&l| {
                    ids.binary_search(&l).map(|i| i as u32).map_err(|_| {
                        EmbedError::InvalidArgument(format!("landmark {l} is not a coarse vertex"))
                    })
                })
                .collect::<Result<Vec<u32>, _>>()?;
            check_cancel(progress)?;
            let marks = collapsed_on(coarse, &local, triggered, |values| s.solve(values, 3))?;
            let mut out = vec![false; mesh.n_vertices()];
            for (&id, m) in ids.iter().zip(marks) {
                out[id as usize] = m;
            }
            Ok(out)
        }
    }
}

/// [`collapsed_vertices`] on `mesh`, whose exact extension of the landmarks' values is
/// `extend`.
fn collapsed_on(
    mesh: &ValidMesh,
    landmarks: &[u32],
    triggered: bool,
    extend: impl FnOnce(&[[f64; MAX_DIM]]) -> Result<Vec<[f64; MAX_DIM]>, EmbedError>,
) -> Result<Vec<bool>, EmbedError> {
    let pos = &mesh.positions;
    let values: Vec<[f64; MAX_DIM]> = landmarks
        .iter()
        .map(|&l| {
            let p = pos[l as usize];
            let mut v = [0.0; MAX_DIM];
            v[..3].copy_from_slice(&[p.x, p.y, p.z]);
            v
        })
        .collect();
    let x = extend(&values)?;
    let mut out = vec![false; mesh.n_vertices()];
    let (mut area, mut area_below_trigger, mut below_trigger) = (0.0, 0.0, 0);
    for t in &mesh.triangles {
        let p = t.map(|v| {
            let q = pos[v as usize];
            [q.x, q.y, q.z]
        });
        let s = min_stretch(p, t.map(|v| &x[v as usize][..3]));
        let [a, b, c] = t.map(|v| pos[v as usize]);
        let face_area = (b - a).cross(&(c - a)).norm() / 2.0;
        area += face_area;
        if s < COLLAPSE_TRIGGER_SCALE {
            area_below_trigger += face_area;
            below_trigger += 1;
        }
        if s < COLLAPSED_SCALE {
            for &v in t {
                out[v as usize] = true;
            }
        }
    }
    let spacings = area_below_trigger / (area / landmarks.len().max(1) as f64);
    let trigger = spacings >= COLLAPSE_TRIGGER_AREA && below_trigger >= COLLAPSE_TRIGGER_FACES;
    if !(triggered || trigger) {
        return Ok(vec![false; mesh.n_vertices()]);
    }
    // Folds that keep every face's shape but bring two sides of a part together show
    // in the distances of vertices two edges apart.
    let graph = PathDistances::new(mesh);
    let dist = |a: &[f64], b: &[f64]| {
        a.iter()
            .zip(b)
            .map(|(s, t)| (s - t) * (s - t))
            .sum::<f64>()
            .sqrt()
    };
    for u in 0..mesh.n_vertices() {
        for &(v, _) in graph.neighbours(u as u32) {
            for &(w, _) in graph.neighbours(v) {
                let w = w as usize;
                if w <= u {
                    continue;
                }
                let d = (pos[u] - pos[w]).norm();
                if dist(&x[u][..3], &x[w][..3]) < COLLAPSED_SCALE * d {
                    out[u] = true;
                    out[w] = true;
                }
            }
        }
    }
    for &l in landmarks {
        out[l as usize] = false;
    }
    Ok(out)
}

/// A vertex is squashed in the solved embedding when it lies closer to some landmark
/// than this times their straight-line distance. Embedded distances stand for geodesic
/// ones, which are never shorter than straight lines, so a well-embedded vertex stays
/// near 1 or above; a margin above the 0.5 of a collapsed pair, since a pair of squashed
/// vertices may come closer to each other than either comes to a landmark.
pub(crate) const SQUASHED_SCALE: f64 = 0.6;

/// Rounds at most in which landmarks go where the solved embedding squashes vertices
/// ([`squashed_vertices`]), each followed by the geodesics, MDS and solve again.
pub(crate) const SQUASHED_ROUNDS: usize = 2;

/// Vertices checked at most by [`squashed_vertices`] (every `stride`-th one above):
/// squashed regions span several vertices, and the check costs a distance per landmark.
const SQUASHED_CHECKED_VERTICES: usize = 200_000;

/// Vertices that the solved embedding `coords` brings closer to some landmark than
/// [`SQUASHED_SCALE`] times their straight-line distance, landmarks excluded.
///
/// The check on the landmarks' 3D positions ([`collapsed_vertices`]) stands in for the
/// embedding before it is computed; between landmarks whose own distances are kept, the
/// 8D extension may still squash a fingertip or an ear tip that the 3D extension leaves
/// whole. This check looks at the result itself.
pub(crate) fn squashed_vertices(
    mesh: &ValidMesh,
    landmarks: &[u32],
    coords: &[[f64; MAX_DIM]],
) -> Vec<bool> {
    let pos = &mesh.positions;
    let n = mesh.n_vertices();
    let anchors: Vec<([f64; 3], [f64; MAX_DIM])> = (landmarks.iter())
        .map(|&l| {
            let p = pos[l as usize];
            ([p.x, p.y, p.z], coords[l as usize])
        })
        .collect();
    let scale2 = SQUASHED_SCALE * SQUASHED_SCALE;
    let squashed = |v: usize| {
        let (p, e) = (pos[v], &coords[v]);
        anchors.iter().any(|(q, f)| {
            let d2 = (p.x - q[0]).powi(2) + (p.y - q[1]).powi(2) + (p.z - q[2]).powi(2);
            let e2: f64 = e.iter().zip(f).map(|(a, b)| (a - b) * (a - b)).sum();
            e2 < scale2 * d2
        })
    };
    let stride = n.div_ceil(SQUASHED_CHECKED_VERTICES).max(1);
    let found: Vec<usize> = (0..n)
        .into_par_iter()
        .step_by(stride)
        .filter(|&v| squashed(v))
        .collect();
    let mut out = vec![false; n];
    found.into_iter().for_each(|v| out[v] = true);
    for &l in landmarks {
        out[l as usize] = false;
    }
    out
}

/// Which of the `n` vertices of the full mesh the intermediate mesh `d` keeps: where a
/// later round's landmarks preferably go ([`landmarks_to_add`]'s `allowed`).
pub(crate) fn kept_by(d: &Decimated, n: usize) -> Vec<bool> {
    let mut out = vec![false; n];
    d.landmarks.iter().for_each(|&v| out[v as usize] = true);
    out
}

/// The aspect-ratio bound of the landmark decimation: the one asked for, but at least
/// twice the input's 90th-percentile ratio. Demanding rounder triangles than most of the
/// mesh's own would let the bound, not the shape, steer the decimation (a mesh of slivers
/// then loses every landmark of some regions).
pub(crate) fn landmark_aspect_bound(mesh: &ValidMesh, asked: Option<f64>) -> Option<f64> {
    let asked = asked?;
    let mut ratios: Vec<f64> = (mesh.triangles.par_iter())
        .map(|t| {
            let [a, b, c] = t.map(|v| mesh.positions[v as usize]);
            crate::decimate::aspect_ratio(a, b, c)
        })
        .collect();
    if ratios.is_empty() {
        return Some(asked);
    }
    let k = ratios.len() * 9 / 10;
    let (_, p90, _) = ratios.select_nth_unstable_by(k, f64::total_cmp);
    Some(asked.max(2.0 * *p90))
}

/// Landmarks to add where the solved embedding `coords` squashes vertices
/// ([`squashed_vertices`]), at most `limit`, preferably on `base` (the finest
/// intermediate mesh, which a later round restarts from): [`landmarks_to_add`].
pub(crate) fn landmarks_where_squashed(
    mesh: &ValidMesh,
    landmarks: &[u32],
    coords: &[[f64; MAX_DIM]],
    base: Option<&Decimated>,
    limit: usize,
) -> Vec<u32> {
    let n = mesh.n_vertices();
    let squashed = squashed_vertices(mesh, landmarks, coords);
    let on_base = base.map(|b| kept_by(b, n));
    let limit = limit.min(n - landmarks.len());
    landmarks_to_add(mesh, landmarks, &squashed, on_base.as_deref(), limit)
}

/// The landmarks with `more` added, sorted.
pub(crate) fn merged(landmarks: &[u32], more: &[u32]) -> Vec<u32> {
    let mut out = [landmarks, more].concat();
    out.sort_unstable();
    out
}

/// A heap entry of Dijkstra's algorithm (smallest distance first).
#[derive(PartialEq)]
struct Entry(f64, u32);

impl Eq for Entry {}

impl PartialOrd for Entry {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Entry {
    fn cmp(&self, other: &Self) -> Ordering {
        other.0.total_cmp(&self.0).then(other.1.cmp(&self.1))
    }
}

/// Edge-path distances from a set of sources, updated as sources are added.
struct PathDistances {
    /// Neighbours of vertex `v`: `adj[start[v]..start[v + 1]]`, with edge lengths.
    start: Vec<usize>,
    adj: Vec<(u32, f64)>,
    dist: Vec<f64>,
}

impl PathDistances {
    fn new(mesh: &ValidMesh) -> Self {
        let n = mesh.n_vertices();
        let mut degree = vec![0usize; n + 1];
        for t in &mesh.triangles {
            for &v in t {
                degree[v as usize + 1] += 2;
            }
        }
        for i in 0..n {
            degree[i + 1] += degree[i];
        }
        let start = degree;
        let mut fill = start.clone();
        let mut adj = vec![(0u32, 0.0); start[n]];
        for t in &mesh.triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let len = (mesh.positions[a as usize] - mesh.positions[b as usize]).norm();
                // Each edge of a closed manifold appears in two faces: once per direction
                // per face, so both directions are listed (duplicates are harmless).
                for (u, w) in [(a, b), (b, a)] {
                    adj[fill[u as usize]] = (w, len);
                    fill[u as usize] += 1;
                }
            }
        }
        Self {
            start,
            adj,
            dist: vec![f64::INFINITY; n],
        }
    }

    /// The neighbours of `v` with the edges' lengths (each listed once per face).
    fn neighbours(&self, v: u32) -> &[(u32, f64)] {
        &self.adj[self.start[v as usize]..self.start[v as usize + 1]]
    }

    /// Makes `sources` distance 0 and lowers every distance they shorten.
    fn add_sources(&mut self, sources: &[u32]) {
        let mut heap = BinaryHeap::new();
        for &s in sources {
            self.dist[s as usize] = 0.0;
            heap.push(Entry(0.0, s));
        }
        while let Some(Entry(d, v)) = heap.pop() {
            if d > self.dist[v as usize] {
                continue;
            }
            for &(w, len) in &self.adj[self.start[v as usize]..self.start[v as usize + 1]] {
                let nd = d + len;
                if nd < self.dist[w as usize] {
                    self.dist[w as usize] = nd;
                    heap.push(Entry(nd, w));
                }
            }
        }
    }
}

/// Landmarks to add where the extension collapses faces (`collapsed`, from
/// [`collapsed_vertices`]): farthest-point sampling, by edge-path distance to the
/// landmarks, until every collapsed vertex is within `reach`, half of the median
/// collapsed vertex's distance, at most `limit` of them. Sorted.
///
/// The samples are `allowed` vertices (those of the intermediate mesh a later round
/// restarts from) first; collapsed vertices that these leave farther than `reach` get
/// samples of their own (the next round then decimates the full mesh again). On a fine mesh the intermediate mesh may keep too few
/// vertices on a small thin part (toes of a subdivided body) to cover it: quadric errors
/// are small on small parts, so the decimation removes them first.
pub(crate) fn landmarks_to_add(
    mesh: &ValidMesh,
    landmarks: &[u32],
    collapsed: &[bool],
    allowed: Option<&[bool]>,
    limit: usize,
) -> Vec<u32> {
    let all: Vec<u32> = (0..mesh.n_vertices() as u32)
        .filter(|&v| collapsed[v as usize])
        .collect();
    if all.is_empty() || limit == 0 {
        return Vec::new();
    }
    let preferred: Vec<u32> = match allowed {
        Some(a) => all.iter().copied().filter(|&v| a[v as usize]).collect(),
        None => all.clone(),
    };
    let mut paths = PathDistances::new(mesh);
    paths.add_sources(landmarks);
    let mut reaches: Vec<f64> = all.iter().map(|&v| paths.dist[v as usize]).collect();
    let mid = reaches.len() / 2;
    let reach = *reaches.select_nth_unstable_by(mid, f64::total_cmp).1;
    let mut added = Vec::new();
    for (candidates, beyond) in [(&preferred, reach), (&all, reach)] {
        while added.len() < limit {
            let farthest = (candidates.iter().copied())
                .max_by(|&a, &b| {
                    (paths.dist[a as usize].total_cmp(&paths.dist[b as usize])).then(b.cmp(&a))
                })
                .map(|v| (v, paths.dist[v as usize]));
            match farthest {
                Some((v, d)) if d > beyond && d > 0.0 => {
                    added.push(v);
                    paths.add_sources(&[v]);
                }
                _ => break,
            }
        }
    }
    added.sort_unstable();
    added
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn min_stretch_measures_the_most_shrunk_direction() {
        let p = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        // The same triangle, moved into 4 dimensions: no shrinking.
        let q = [
            [5.0, 0.0, 0.0, 1.0],
            [6.0, 0.0, 0.0, 1.0],
            [5.0, 1.0, 0.0, 1.0],
        ];
        let s = min_stretch(p, [&q[0][..], &q[1][..], &q[2][..]]);
        assert!((s - 1.0).abs() < 1e-12, "{s}");
        // Squashed to a tenth across.
        let q = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.1, 0.0]];
        let s = min_stretch(p, [&q[0][..], &q[1][..], &q[2][..]]);
        assert!((s - 0.1).abs() < 1e-12, "{s}");
        // Collapsed onto a line.
        let q = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, 0.0, 0.0]];
        let s = min_stretch(p, [&q[0][..], &q[1][..], &q[2][..]]);
        assert!(s < 1e-9, "{s}");
        // A degenerate input triangle has no answer.
        let flat = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]];
        assert!(min_stretch(flat, [&q[0][..], &q[1][..], &q[2][..]]).is_nan());
    }
}
