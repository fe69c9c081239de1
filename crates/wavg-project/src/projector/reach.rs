//! Per-vertex reach: how close to a vertex's embedded position any triangle *not* around
//! the vertex comes. A certified search whose local search tried every face around its
//! walk's end `v` is done without the global search when its answer's distance `r` and the
//! query `y` satisfy `|y - x_v| + r <= reach(v)`: every other triangle's convex hull, which
//! holds its Phong points, is then at least `r` from `y`. Computed for a vertex the first
//! time a search asks (one nearest-triangle search of the hierarchy), like the cone
//! bounds: workloads that never certify pay nothing.

use std::sync::atomic::{AtomicU32, Ordering};

use super::search::FaceSet;
use super::*;

/// Bits of a reach not computed yet (a NaN: never a valid reach).
const UNSET: u32 = u32::MAX;

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
    /// of every triangle that does not have `v` as a corner (infinite when there is none).
    /// Racing threads compute the same value.
    pub(super) fn reach(&self, v: VertexId) -> f64 {
        let slot = &self.reach.0[v as usize];
        let bits = slot.load(Ordering::Relaxed);
        if bits != UNSET {
            return f32::from_bits(bits) as f64;
        }
        let r = self.compute_reach(v);
        slot.store(r.to_bits(), Ordering::Relaxed);
        r as f64
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
        let x = &self.verts[v as usize].x;
        (y - x).norm() + local.d2.sqrt() <= self.reach(v)
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
                let r = p.reach(v);
                assert!(
                    r <= brute && r >= brute * (1.0 - 1e-5),
                    "{v}: {r} vs {brute}"
                );
                // Asked again: the stored value.
                assert_eq!(p.reach(v), r);
            }
        }
    }
}
