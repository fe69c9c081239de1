//! The local validity test of a correspondence (see [`crate::correspond`]'s module docs):
//! a vertex is rejected when the map stretches or folds its neighbourhood, a disc of a
//! fixed share of the diagonal ([`NEIGHBOURHOOD`]) rather than its one-ring, so the test
//! judges a map at one scale whatever the mesh's resolution.

use std::cell::RefCell;

use nalgebra::Vector3;
use rayon::prelude::*;
use wavg_mesh::ValidMesh;

use crate::metrics::flipped_faces;

/// The radius of a vertex's neighbourhood in the local test, as a fraction of the source's
/// bounding-box diagonal: half the 1% error that counts as a right image, so an image
/// that far off cannot stretch the segments to the neighbourhood's edge by much. Larger
/// radii keep more right images but also more wrong ones (see BENCHMARKS.md).
pub const NEIGHBOURHOOD: f64 = 0.005;

/// Vertices a neighbourhood holds at most: on parts much finer than [`NEIGHBOURHOOD`]
/// (the fingers of a subdivided body) the growth stops there, which bounds the test's
/// cost per vertex (the judged scale shrinks to about 9 edges there).
pub const NEIGHBOURHOOD_VERTICES: usize = 256;

/// The local test rejects a vertex when at least this fraction (numerator, denominator)
/// of its neighbourhood's faces land flipped.
const FOLDED: (usize, usize) = (2, 3);

/// The local test (see the module docs): per vertex, whether most of the segments from it
/// to the edge of its neighbourhood map stretched beyond `max_stretch` times the map's
/// median edge stretch (image length over source length), or two thirds of the faces
/// around its neighbourhood's vertices land flipped against `normals` (per face; `None`:
/// not judged; a face counts once per corner inside), with `answered[v]` the image of
/// vertex `v` (unanswered vertices do not count).
///
/// A vertex's neighbourhood is the vertex and the vertices within [`NEIGHBOURHOOD`] of
/// the source's diagonal reached from it through such vertices (at most
/// [`NEIGHBOURHOOD_VERTICES`]); its edge is the vertices adjacent to those and not among
/// them, so on a coarse mesh it is the one-ring. An image a fraction of an edge off flips
/// and stretches the edges of a fine mesh although it lands close to the truth: judged
/// over a neighbourhood of fixed size, a mesh and its subdivision keep about the same
/// vertices, and a wrong patch of several vertices is rejected whole when it is smaller
/// than the neighbourhood.
pub fn inconsistent_vertices(
    mesh: &ValidMesh,
    answered: &[Option<Vector3<f64>>],
    normals: &[Option<Vector3<f64>>],
    max_stretch: f64,
) -> Vec<bool> {
    let topo = mesh.topology();
    let n = mesh.n_vertices();
    let flipped = flipped_faces(&mesh.positions, &mesh.triangles, answered, normals);
    let ratio = |a: u32, b: u32| -> Option<f64> {
        let (pa, pb) = (
            answered.get(a as usize)?.as_ref()?,
            answered.get(b as usize)?.as_ref()?,
        );
        let len = (mesh.positions[a as usize] - mesh.positions[b as usize]).norm();
        let r = (pa - pb).norm() / len;
        r.is_finite().then_some(r)
    };
    let mut ratios: Vec<f64> = (0..n as u32)
        .into_par_iter()
        .flat_map_iter(|v| {
            topo.ring(v)
                .iter()
                .filter(move |&&u| u > v)
                .filter_map(move |&u| ratio(v, u))
        })
        .collect();
    if ratios.is_empty() {
        return vec![false; n];
    }
    let mid = ratios.len() / 2;
    let median = *ratios.select_nth_unstable_by(mid, f64::total_cmp).1;
    let limit = max_stretch * median;
    let radius = NEIGHBOURHOOD * mesh.bounding_box_diagonal();
    // Per vertex: its faces and how many land flipped, summed over a neighbourhood.
    let ring_folds: Vec<(u32, u32)> = (0..n as u32)
        .into_par_iter()
        .map(|v| {
            let faces = topo.ring_faces(v);
            let folded = faces.iter().filter(|&&f| flipped[f as usize]).count();
            (faces.len() as u32, folded as u32)
        })
        .collect();
    (0..n as u32)
        .into_par_iter()
        .map(|v| {
            // `ratio(v, u)` with `v`'s image and position read once.
            let image = answered.get(v as usize).copied().flatten();
            let centre = mesh.positions[v as usize];
            SCRATCH.with_borrow_mut(|nb| {
                let (mut measured, mut bad, mut faces, mut folded) =
                    (0usize, 0usize, 0usize, 0usize);
                nb.grow(
                    mesh,
                    v,
                    radius,
                    |x| {
                        let (f, k) = ring_folds[x as usize];
                        faces += f as usize;
                        folded += k as usize;
                    },
                    |u| {
                        let (Some(pv), Some(Some(pu))) = (image, answered.get(u as usize)) else {
                            return;
                        };
                        let r = (pv - pu).norm() / (centre - mesh.positions[u as usize]).norm();
                        if r.is_finite() {
                            measured += 1;
                            bad += usize::from(r > limit);
                        }
                    },
                );
                2 * bad > measured || FOLDED.1 * folded >= FOLDED.0 * faces
            })
        })
        .collect()
}

thread_local! {
    /// Each thread's neighbourhood, reused from vertex to vertex and from call to call
    /// (its stamps need no clearing: generations only grow).
    static SCRATCH: RefCell<Neighbourhood> = const {
        RefCell::new(Neighbourhood {
            inside: Vec::new(),
            stamp: Vec::new(),
            generation: 0,
        })
    };
}

/// A vertex's neighbourhood in the local test: the vertices inside (the vertex, and those
/// within the radius reached through them), with one thread's marks of the vertices the
/// growth met (inside or at the edge: outside, adjacent to one inside).
struct Neighbourhood {
    inside: Vec<u32>,
    /// Per vertex: `2 g` inside, `2 g + 1` at the edge in generation `g` (one per
    /// growth); older values: not met.
    stamp: Vec<u32>,
    generation: u32,
}

impl Neighbourhood {
    /// Grows the neighbourhood of `v` on `mesh` (breadth first from `v`), calling
    /// `on_inside` once for each vertex inside (`v` first) and `on_edge` once for each
    /// vertex at the edge, as the growth meets them: the test's sums need no second pass
    /// and the edge no list.
    fn grow(
        &mut self,
        mesh: &ValidMesh,
        v: u32,
        radius: f64,
        mut on_inside: impl FnMut(u32),
        mut on_edge: impl FnMut(u32),
    ) {
        let n = mesh.n_vertices();
        if self.stamp.len() < n {
            self.stamp.resize(n, 0);
        }
        if self.generation >= u32::MAX / 2 - 1 {
            self.stamp.fill(0);
            self.generation = 0;
        }
        self.generation += 1;
        let (inside, edge) = (2 * self.generation, 2 * self.generation + 1);
        let topo = mesh.topology();
        let positions = &mesh.positions[..n];
        let stamp = &mut self.stamp[..n];
        let centre = positions[v as usize];
        let r2 = radius * radius;
        self.inside.clear();
        self.inside.reserve(NEIGHBOURHOOD_VERTICES);
        self.inside.push(v);
        stamp[v as usize] = inside;
        on_inside(v);
        let mut next = 0;
        while let Some(&x) = self.inside.get(next) {
            next += 1;
            for &u in topo.ring(x) {
                let Some(mark) = stamp.get_mut(u as usize) else {
                    continue;
                };
                if *mark >= inside {
                    continue;
                }
                // A vertex first met outside the radius (or past the cap) stays at the
                // edge even if a later path reaches it: the neighbourhood is what the
                // growth reached, in order.
                // Past the cap the distance is not needed.
                if self.inside.len() < NEIGHBOURHOOD_VERTICES
                    && (positions[u as usize] - centre).norm_squared() <= r2
                {
                    *mark = inside;
                    self.inside.push(u);
                    on_inside(u);
                } else {
                    *mark = edge;
                    on_edge(u);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::{Rotation3, Unit, Vector3};
    use wavg_mesh::{ValidMesh, procedural};

    use super::*;

    /// Per face of a unit sphere's map `answered`: the sphere's normal where its corners
    /// land (the sum of the images), as the correspondence judges flips.
    fn sphere_normals(
        mesh: &ValidMesh,
        answered: &[Option<Vector3<f64>>],
    ) -> Vec<Option<Vector3<f64>>> {
        mesh.triangles
            .iter()
            .map(|t| t.iter().map(|&v| answered[v as usize]).sum())
            .collect()
    }

    /// Below the cap, the disc is the part of the ball around the vertex reached through
    /// the ball (each vertex reported once), its edge the other vertices next to it; with
    /// a radius past the whole mesh, exactly the cap's count are inside, and the growth
    /// still reports every vertex next to them at the edge.
    #[test]
    fn the_disc_is_the_ball_reached_from_the_vertex_and_its_edge_the_vertices_next_to_it() {
        use std::collections::BTreeSet;
        let mesh = ValidMesh::new(procedural::icosphere(6)).unwrap();
        let topo = mesh.topology();
        let edge_len = (mesh.positions[0] - mesh.positions[topo.ring(0)[0] as usize]).norm();
        let mut nb = Neighbourhood {
            inside: Vec::new(),
            stamp: Vec::new(),
            generation: 0,
        };
        let mut grown = |v: u32, radius: f64| {
            let (mut inside, mut edge) = (Vec::new(), Vec::new());
            nb.grow(&mesh, v, radius, |x| inside.push(x), |u| edge.push(u));
            let (a, b) = (inside.len(), edge.len());
            let (inside, edge): (BTreeSet<u32>, BTreeSet<u32>) =
                (inside.into_iter().collect(), edge.into_iter().collect());
            assert_eq!(
                (inside.len(), edge.len()),
                (a, b),
                "a vertex reported twice"
            );
            (inside, edge)
        };
        for v in [0u32, 17, 4000, 40000] {
            let radius = 3.5 * edge_len;
            let (inside, edge) = grown(v, radius);
            let centre = mesh.positions[v as usize];
            let within = |u: u32| (mesh.positions[u as usize] - centre).norm() <= radius;
            let mut want = BTreeSet::from([v]);
            let mut todo = vec![v];
            while let Some(x) = todo.pop() {
                for &u in topo.ring(x) {
                    if within(u) && want.insert(u) {
                        todo.push(u);
                    }
                }
            }
            assert!(want.len() > 20 && want.len() < NEIGHBOURHOOD_VERTICES);
            assert_eq!(inside, want);
            let next: BTreeSet<u32> = want
                .iter()
                .flat_map(|&x| topo.ring(x).iter().copied())
                .filter(|u| !want.contains(u))
                .collect();
            assert_eq!(edge, next);
        }
        let (inside, edge) = grown(5, 10.0);
        assert_eq!(inside.len(), NEIGHBOURHOOD_VERTICES);
        assert!(inside.contains(&5));
        assert!(edge.is_disjoint(&inside));
        for &u in &edge {
            assert!(topo.ring(u).iter().any(|x| inside.contains(x)));
        }
        for &x in &inside {
            assert!(
                topo.ring(x)
                    .iter()
                    .all(|u| inside.contains(u) || edge.contains(u))
            );
        }
    }

    /// A fine sphere (an edge shorter than the neighbourhood's radius) mapped onto itself,
    /// then a patch of seven vertices (a vertex and its one-ring) sent rigidly elsewhere:
    /// inside the patch no edge stretches and no face flips, so only a neighbourhood wider
    /// than one ring sees that the patch left its surroundings. Every patch vertex is
    /// rejected, and the rejection stays near the patch.
    #[test]
    fn a_wrong_patch_is_rejected_whole() {
        let mesh = ValidMesh::new(procedural::icosphere(7)).unwrap();
        let edge = (mesh.positions[0] - mesh.positions[mesh.topology().ring(0)[0] as usize]).norm();
        let radius = NEIGHBOURHOOD * mesh.bounding_box_diagonal();
        assert!(edge < radius, "edge {edge}, radius {radius}");
        let mut answered: Vec<_> = mesh.positions.iter().map(|&p| Some(p)).collect();
        let normals = sphere_normals(&mesh, &answered);
        assert!(
            inconsistent_vertices(&mesh, &answered, &normals, 4.0)
                .iter()
                .all(|b| !b)
        );
        let v = 5000u32;
        let mut patch = vec![v];
        patch.extend_from_slice(mesh.topology().ring(v));
        // A turn of 1 radian about an axis perpendicular to the patch's centre.
        let centre = mesh.positions[v as usize];
        let axis = Unit::new_normalize(centre.cross(&Vector3::new(0.3, -0.5, 0.7)));
        let turn = Rotation3::from_axis_angle(&axis, 1.0);
        for &u in &patch {
            answered[u as usize] = Some(turn * mesh.positions[u as usize]);
        }
        let normals = sphere_normals(&mesh, &answered);
        let after = inconsistent_vertices(&mesh, &answered, &normals, 4.0);
        for &u in &patch {
            assert!(after[u as usize], "patch vertex {u} kept");
        }
        for (u, &bad) in after.iter().enumerate() {
            if bad {
                let d = (mesh.positions[u] - centre).norm();
                assert!(d < 2.0 * edge + radius, "vertex {u} rejected {d} away");
            }
        }
    }
}
