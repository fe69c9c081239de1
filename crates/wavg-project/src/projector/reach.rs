//! Per-vertex reach: how close to a vertex's embedded position any triangle *not* around
//! the vertex comes. A certified search whose local search tried every face around its
//! walk's end `v` is done without the global search when its answer's distance `r` and the
//! query `y` satisfy `|y - x_v| + r <= reach(v)`: every other triangle's convex hull, which
//! holds its Phong points, is then at least `r` from `y`. A reach costs about as much as
//! one global search, so it is computed the second time a search asks for it (queries
//! that come back to a region pay it once; one-off queries never do); workloads that never
//! certify pay nothing.

use std::sync::atomic::{AtomicU32, Ordering};

use super::search::FaceSet;
use super::*;

/// Bits of a reach nobody asked for yet, and of one asked for once (NaNs: never valid
/// reaches).
const UNSET: u32 = u32::MAX;
const ASKED: u32 = u32::MAX - 1;

/// The reach of every vertex, as `f32` bits, filled on first use.
pub(super) struct Reach(Vec<AtomicU32>);

impl Reach {
    /// Nothing computed, for `n` vertices.
    pub(super) fn new(n: usize) -> Self {
        Self((0..n).map(|_| AtomicU32::new(UNSET)).collect())
    }

    /// Heap bytes used.
    pub(super) fn bytes(&self) -> usize {
        self.0.len() * std::mem::size_of::<AtomicU32>()
    }
}

impl Projector {
    /// A lower bound of the distance from vertex `v`'s embedded position to the convex hull
    /// of every triangle that does not have `v` as a corner (infinite when there is none),
    /// computed now if needed. Racing threads compute the same value.
    fn reach(&self, v: VertexId) -> f64 {
        let slot = &self.reach.0[v as usize];
        let bits = slot.load(Ordering::Relaxed);
        if bits != UNSET && bits != ASKED {
            return f32::from_bits(bits) as f64;
        }
        let r = self.compute_reach(v);
        slot.store(r.to_bits(), Ordering::Relaxed);
        r as f64
    }

    /// `v`'s reach if a search asked for it before (computed now if needed); `None` the
    /// first time, which is recorded.
    fn reach_if_asked_before(&self, v: VertexId) -> Option<f64> {
        let slot = &self.reach.0[v as usize];
        if slot.load(Ordering::Relaxed) == UNSET {
            slot.store(ASKED, Ordering::Relaxed);
            return None;
        }
        Some(self.reach(v))
    }

    fn compute_reach(&self, v: VertexId) -> f32 {
        let x = self.verts[v as usize].x;
        let mut bound = f64::INFINITY;
        self.bvh.search(&x, &mut bound, |f, bound| {
            if self.faces[f as usize].v.contains(&v) {
                return;
            }
            let [a, b, c] = self.corners(f);
            let w = closest_point_barycentric(&x, &a, &b, &c);
            let d2 = (a * w[0] + b * w[1] + c * w[2] - x).norm_squared();
            if d2 < *bound {
                *bound = d2;
            }
        });
        // A margin far above the closest point's rounding; then down to an f32 below it.
        let r = bound.sqrt() * (1.0 - 1e-6);
        let f = r as f32;
        if f as f64 > r {
            f32::from_bits(f.to_bits() - 1)
        } else {
            f
        }
    }

    /// Whether the answer `local` (distance `sqrt(local.d2)` from `y`) is the closest
    /// projection because the local search tried every face around `v` and `y`'s ball of
    /// that radius lies within `v`'s reach.
    pub(super) fn certified_by_reach(
        &self,
        y: &Vec8,
        local: &Best,
        v: VertexId,
        tried: &FaceSet,
    ) -> bool {
        let topo = self.emb.mesh().topology();
        let around = self.walk_coords[v as usize].faces(topo, v);
        if !around.iter().all(|&f| tried.contains(f)) {
            return false;
        }
        let need = (y - self.verts[v as usize].x).norm() + local.d2.sqrt();
        self.reach_if_asked_before(v).is_some_and(|r| need <= r)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use wavg_mesh::{ValidMesh, procedural};

    /// The reach is a lower bound of the distance to every triangle not around the vertex,
    /// and a tight one (the brute force over all triangles).
    #[test]
    fn reach_bounds_the_distance_to_every_triangle_not_around_the_vertex() {
        for mesh in [
            procedural::icosphere(2),
            procedural::with_noise(procedural::torus(24, 12, 1.0, 0.3), 0.02, 5),
        ] {
            let mesh = Arc::new(ValidMesh::new(mesh).unwrap());
            let emb = Arc::new(EmbeddedMesh::from_positions(mesh.clone()));
            let p = Projector::new(emb).unwrap();
            for v in 0..mesh.n_vertices() as VertexId {
                let x = p.verts[v as usize].x;
                let mut brute = f64::INFINITY;
                for f in 0..mesh.n_faces() as FaceId {
                    if p.faces[f as usize].v.contains(&v) {
                        continue;
                    }
                    let [a, b, c] = p.corners(f);
                    let w = closest_point_barycentric(&x, &a, &b, &c);
                    brute = brute.min((a * w[0] + b * w[1] + c * w[2] - x).norm());
                }
                // Asked once: not computed, and recorded.
                assert_eq!(p.reach_if_asked_before(v), None);
                let r = p.reach_if_asked_before(v).unwrap();
                assert!(
                    r <= brute && r >= brute * (1.0 - 1e-5),
                    "{v}: {r} vs {brute}"
                );
                // Asked again: the stored value.
                assert_eq!(p.reach(v), r);
            }
        }
    }

    /// Answers of `queries` projections from the given start vertices, each asked twice
    /// (the second time certified by reach where it can be), against the brute force;
    /// returns how many reaches were computed.
    fn check_against_brute_force(p: &Projector, queries: &[(Vec8, VertexId)]) -> usize {
        let h = p.embedded().mean_edge_length();
        for (y, start) in queries {
            let brute = p.project_brute_force(y).unwrap();
            for _ in 0..2 {
                let got = p.project(y, *start).unwrap();
                let at = |q: &SurfacePoint| p.embedded().point(q);
                let same = (at(&got.point) - at(&brute.point)).norm() <= 1e-9 * h;
                let tie = (got.distance - brute.distance).abs() <= 1e-12 * h;
                assert!(same || tie, "{got:?} vs brute force {brute:?}");
            }
        }
        (p.reach.0.iter())
            .filter(|b| !matches!(b.load(Ordering::Relaxed), UNSET | ASKED))
            .count()
    }

    /// Near and a little off a noisy torus, and between two parallel sheets (where the
    /// other sheet is often the closer one): the brute force's answers, with the reach
    /// path taken.
    #[test]
    fn answers_certified_by_reach_are_the_brute_forces() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let torus = procedural::with_noise(procedural::torus(24, 12, 1.0, 0.3), 0.02, 5);
        // Two 10 x 10 grids of cell 0.1, at z = 0 and z = 0.15.
        let mut sheets = procedural::grid(10, 10, 1.0, 1.0);
        let n = sheets.positions.len() as u32;
        let lifted: Vec<_> = (sheets.positions.iter())
            .map(|q| nalgebra::Vector3::new(q.x, q.y, 0.15))
            .collect();
        sheets.positions.iter_mut().for_each(|q| q.z = 0.0);
        sheets.positions.extend(lifted);
        let tris = sheets.triangles.clone();
        (sheets.triangles).extend(tris.iter().map(|t| t.map(|v| v + n)));
        for (mesh, gap) in [(torus, None), (sheets, Some(0.15))] {
            let mesh = Arc::new(ValidMesh::new(mesh).unwrap());
            let emb = Arc::new(EmbeddedMesh::from_positions(mesh.clone()));
            let p = Projector::new(emb.clone()).unwrap();
            let h = emb.mean_edge_length();
            let queries: Vec<(Vec8, VertexId)> = (0..1500)
                .map(|_| {
                    let faces = match gap {
                        Some(_) => mesh.n_faces() as FaceId / 2,
                        None => mesh.n_faces() as FaceId,
                    };
                    let f = rng.random_range(0..faces);
                    let (a, b) = (rng.random::<f64>(), rng.random::<f64>());
                    let (a, b) = if a + b > 1.0 {
                        (1.0 - a, 1.0 - b)
                    } else {
                        (a, b)
                    };
                    let mut y = emb.point(&SurfacePoint::new(f, [1.0 - a - b, a, b]));
                    match gap {
                        Some(g) => y[2] += g * rng.random_range(0.3..0.7),
                        None => {
                            let dir = Vec8::from_fn(|_, _| rng.random::<f64>() - 0.5);
                            y += dir.normalize() * (h * rng.random_range(0.01..0.5));
                        }
                    }
                    (y, mesh.triangles[f as usize][0])
                })
                .collect();
            let computed = check_against_brute_force(&p, &queries);
            assert!(computed > 50, "only {computed} reaches computed");
        }
    }
}
