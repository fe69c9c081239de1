//! The two-level least-squares mesh's prolongation: the coarse level's solution carried to
//! every vertex of the full mesh, as the conjugate gradients' start.
//!
//! Each vertex takes the linear interpolation of the coarse values on the coarse triangle
//! closest to it in space, found from the triangles around its nearest coarse vertex
//! (nearest by breadth-first layers over the full mesh's edges) by a short walk. Linear interpolation
//! keeps the solution's slope between coarse vertices; a piecewise-constant start (each
//! vertex the value of its nearest coarse vertex, or means of those) leaves plateaus
//! several rings wide that a few Jacobi-preconditioned iterations of the fourth-order
//! system barely move, and the forward walk crawls across plateaus of the embedding.

use nalgebra::Vector3;
use rayon::prelude::*;
use wavg_mesh::{NONE, ValidMesh, closest_point_barycentric};

use super::locality::VertexOrder;
use super::stiffness::Stiffness;
use crate::error::{EmbedError, Progress, check_cancel};
use crate::file::MAX_DIM;

type Row = [f64; MAX_DIM];

/// Marks a vertex no coarse vertex reached (a component without coarse vertices).
const UNREACHED: u32 = u32::MAX;

/// Steps at most from the nearest coarse vertex's triangles to closer neighbouring ones.
const WALK_STEPS: usize = 16;

/// The full level's side of the prolongation.
pub(super) struct FullLevel<'a> {
    /// The full mesh's positions, in its own vertex order.
    pub positions: &'a [Vector3<f64>],
    /// The system's vertex order.
    pub order: &'a VertexOrder,
    /// The full mesh's stiffness (its pattern gives each vertex's neighbours), in the
    /// system's order.
    pub stiffness: &'a Stiffness,
}

/// `coarse` values (one per vertex of `coarse_mesh`, whose vertex `i` is original vertex
/// `coarse_ids[i]`) carried to every vertex of the full level, in the system's order.
/// Looks at `progress`'s cancellation after each breadth-first layer.
pub(super) fn prolongate(
    full: &FullLevel<'_>,
    coarse_mesh: &ValidMesh,
    coarse_ids: &[u32],
    coarse: &[Row],
    progress: &dyn Progress,
) -> Result<Vec<Row>, EmbedError> {
    let nearest = nearest_coarse(full, coarse_ids, progress)?;
    let topo = coarse_mesh.topology();
    let cp = &coarse_mesh.positions;
    let x = (0..nearest.len())
        .into_par_iter()
        .with_min_len(4096)
        .map(|v| {
            let c = nearest[v];
            let p = full.positions[full.order.old_of_new[v] as usize];
            let on = |f: u32| {
                let t = coarse_mesh.triangles[f as usize];
                let (a, b, d) = (&cp[t[0] as usize], &cp[t[1] as usize], &cp[t[2] as usize]);
                let w = closest_point_barycentric(&p, a, b, d);
                let q = a * w[0] + b * w[1] + d * w[2];
                ((q - p).norm_squared(), f, t, w)
            };
            let mut best = (topo.ring_faces(c).iter())
                .map(|&f| on(f))
                .min_by(|x, y| x.0.total_cmp(&y.0))
                .unwrap_or((f64::INFINITY, NONE, [c, c, c], [1.0, 0.0, 0.0]));
            // Where the nearest coarse vertex's triangles do not hold the vertex (long
            // coarse triangles), walk to closer neighbouring ones.
            for _ in 0..WALK_STEPS {
                if best.1 == NONE {
                    break;
                }
                let step = (topo.face_neighbors(best.1).into_iter())
                    .filter(|&f| f != NONE)
                    .map(on)
                    .min_by(|x, y| x.0.total_cmp(&y.0));
                match step {
                    Some(s) if s.0 < best.0 => best = s,
                    _ => break,
                }
            }
            let (_, _, t, w) = best;
            let mut row = [0.0; MAX_DIM];
            for (corner, wk) in t.iter().zip(w) {
                for (r, c) in row.iter_mut().zip(&coarse[*corner as usize]) {
                    *r += wk * c;
                }
            }
            row
        })
        .collect();
    Ok(x)
}

/// For each vertex in the system's order, the coarse vertex (its index in the coarse
/// mesh) that breadth-first layers from all coarse vertices reach it from first; layers are
/// gathered in parallel in the frontier's order, so the result does not depend on the
/// thread count. A vertex no coarse vertex reaches is an error (a decimation keeps every
/// component, so only a mismatched coarse mesh has one).
fn nearest_coarse(
    full: &FullLevel<'_>,
    coarse_ids: &[u32],
    progress: &dyn Progress,
) -> Result<Vec<u32>, EmbedError> {
    let n = full.order.old_of_new.len();
    let mut nearest = vec![UNREACHED; n];
    let mut frontier: Vec<usize> = Vec::with_capacity(coarse_ids.len());
    for (i, &v) in coarse_ids.iter().enumerate() {
        let v = full.order.new_of_old[v as usize] as usize;
        nearest[v] = i as u32;
        frontier.push(v);
    }
    while !frontier.is_empty() {
        let seen: Vec<(usize, u32)> = (frontier.par_iter())
            .with_min_len(1024)
            .flat_map_iter(|&v| {
                let from = nearest[v];
                let nearest = &nearest;
                (full.stiffness.col_rows(v).iter())
                    .map(|&u| u as usize)
                    .filter(move |&u| nearest[u] == UNREACHED)
                    .map(move |u| (u, from))
            })
            .collect();
        let mut next = Vec::with_capacity(seen.len());
        for (u, from) in seen {
            if nearest[u] == UNREACHED {
                nearest[u] = from;
                next.push(u);
            }
        }
        frontier = next;
        check_cancel(progress)?;
    }
    if let Some(v) = nearest.iter().position(|&c| c == UNREACHED) {
        return Err(EmbedError::InvalidArgument(format!(
            "vertex {} is in a part of the mesh without coarse vertices",
            full.order.old_of_new[v]
        )));
    }
    Ok(nearest)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::NoProgress;
    use crate::decimate::{DecimateOptions, decimate};
    use wavg_mesh::procedural;

    /// A linear function of position is carried exactly at the vertices the coarse mesh
    /// covers, and elsewhere (where decimation cut a corner of the boundary) within its
    /// slope times the distance to the coarse mesh: every vertex gets the value of its
    /// closest point on the coarse mesh (brute force over all coarse triangles).
    #[test]
    fn linear_functions_of_position_are_carried_from_the_closest_coarse_point() {
        let mesh = ValidMesh::new(procedural::grid(60, 60, 1.0, 1.0)).unwrap();
        let d = decimate(
            &mesh,
            &DecimateOptions {
                target: 200,
                ..Default::default()
            },
            &NoProgress,
        )
        .unwrap();
        let coarse_mesh = ValidMesh::new(d.mesh.clone()).unwrap();
        let order = VertexOrder::morton(&mesh);
        let (stiffness, _) = Stiffness::cotan(&mesh, Some(&order), &NoProgress).unwrap();
        // Slope sqrt(5) in the first entry, 1 in the second.
        let f = |p: &Vector3<f64>| {
            let mut r = [0.0; MAX_DIM];
            r[0] = 2.0 * p.x - p.y + 0.5;
            r[1] = p.y;
            r
        };
        let coarse: Vec<Row> = coarse_mesh.positions.iter().map(f).collect();
        let full = FullLevel {
            positions: &mesh.positions,
            order: &order,
            stiffness: &stiffness,
        };
        let x = prolongate(&full, &coarse_mesh, &d.landmarks, &coarse, &NoProgress).unwrap();
        let cp = &coarse_mesh.positions;
        let mut covered = 0;
        for (v, p) in mesh.positions.iter().enumerate() {
            let off = (coarse_mesh.triangles.iter())
                .map(|t| {
                    let (a, b, c) = (&cp[t[0] as usize], &cp[t[1] as usize], &cp[t[2] as usize]);
                    let w = closest_point_barycentric(p, a, b, c);
                    (a * w[0] + b * w[1] + c * w[2] - p).norm()
                })
                .fold(f64::INFINITY, f64::min);
            covered += usize::from(off < 1e-12);
            let got = x[order.new_of_old[v] as usize];
            let want = f(p);
            let tolerance = 2.25 * off + 1e-9;
            assert!(
                (got[0] - want[0]).abs() <= tolerance && (got[1] - want[1]).abs() <= tolerance,
                "vertex {v}, {off:.2e} off the coarse mesh: {got:?} vs {want:?}"
            );
        }
        assert!(covered * 10 >= mesh.n_vertices() * 9, "{covered} covered");
    }
}
