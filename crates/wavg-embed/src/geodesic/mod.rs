//! Geodesic distances by fast marching (Kimmel & Sethian 1998) on a triangle mesh.
//!
//! # Method
//!
//! The classic first-order scheme: vertices are frozen in order of increasing distance
//! (an indexed binary heap with decrease-key); when a vertex `v` freezes, every unfrozen
//! neighbour `x` is updated
//! * along each edge: `u(x) <= u(v) + |xv|` (Dijkstra), and
//! * across each *update stencil* `(x; v, w)` whose other vertex `w` is frozen: the planar
//!   wavefront through `(v, u(v))`, `(w, u(w))` with unit gradient gives `t`; it is used only
//!   if its characteristic (the direction `-grad u`) lies inside the stencil's angle at `x`
//!   (upwind condition). Otherwise only the edge updates apply (the standard fallback).
//!
//! With the stencil's edge vectors `a = v - x`, `b = w - x`, Gram matrix `G` and `Q = G^-1`,
//! `grad u = [a b] Q (U - t 1)` where `U = (u(v), u(w))`; `|grad u| = 1` is a quadratic in `t`
//! (its larger root), and upwind means both components of `Q (U - t 1)` are `<= 0`.
//!
//! **Obtuse triangles** are handled as Kimmel & Sethian propose: a corner `x` with an angle
//! above 90 degrees is split by a *virtual edge* to a vertex `W` found by unfolding the
//! triangles beyond the opposite edge into the triangle's plane (up to
//! [`MAX_UNFOLD_STEPS`] triangles) until `W` falls inside the section of directions making
//! at most 90 degrees with both edges at `x`. The corner then gets two acute stencils
//! `(x; v, W)` and `(x; W, w)` with the unfolded geometry, and `u(W) + |xW|` (unfolded
//! length) is used as an extra edge update. If the unfolding runs into a boundary or does
//! not find such a vertex, the obtuse stencil is kept as it is (its update is still applied
//! only when upwind). Since every edge update is applied too, the result never exceeds
//! the edge-graph (Dijkstra) distance; a property test checks that, and that it stays
//! above the straight-line distance.
//!
//! # Cost, and geodesics on a coarser mesh
//!
//! One run costs time linear in the vertex count (times a logarithm for the heap), and
//! the precomputation needs one run per landmark. For large meshes, compute the landmark
//! distances on an intermediate decimation of about [`DEFAULT_GEODESIC_VERTICES`]
//! vertices that contains every landmark: either decimate again with the landmarks locked
//! ([`GeodesicOptions::coarse_vertices`]), or, cheaper, pass a snapshot of the landmark
//! decimation itself ([`crate::decimate::decimate_with_snapshots`],
//! [`GeodesicOptions::coarse_mesh`]). Both use the coarse mesh for every pair and then
//! recompute the pairs closer than
//! [`NEAR_PAIR_RADIUS_EDGES`](landmarks::NEAR_PAIR_RADIUS_EDGES) coarse edges on the fine
//! mesh (or on a finer decimation, [`GeodesicOptions::refine_on`]) with radius-limited runs
//! ([`FastMarching::run_within`]), because on the coarse
//! mesh alone those close pairs are the least accurate. The measured differences from
//! full-resolution fast marching are in `BENCHMARKS.md`.
//!
//! **Near the source** the front is strongly curved and a plane wave fits it worst, so each
//! run starts with exact polyhedral distances within [`near_field::NEAR_FIELD_EDGES`]
//! mean edge lengths of the source (windows of Chen & Han with pseudo-sources at saddle
//! vertices and Xin & Wang's pruning, [`near_field`]; the radius is a parameter,
//! [`FastMarching::with_near_field_edges`]). It makes close pairs nearly exact and the
//! landmark matrix far more symmetric for a little more time per run; the figures are in
//! `BENCHMARKS.md`.
//!
//! All geometry is precomputed once per mesh in [`FastMarching`] (a flat list of
//! update entries per freezing vertex, single precision), so one run only touches the
//! distance array, the heap and that list. [`Workspace`] holds the per-run buffers so that
//! repeated runs do not allocate.

use nalgebra::Vector2;
use rayon::prelude::*;
use wavg_mesh::{NONE, ValidMesh};

use crate::decimate::{DecimateOptions, Decimated, decimate};
use crate::error::{EmbedError, Progress, Stage, check_cancel};

mod fast_marching;
mod heap;
mod landmarks;
pub(crate) mod near_field;
mod unfold;

use fast_marching::*;
use near_field::{NearField, NearScratch};
use unfold::*;

pub(crate) use fast_marching::{DEFAULT_GEODESIC_VERTICES, MAX_UNFOLD_STEPS};
pub use fast_marching::{FastMarching, Workspace};
pub use landmarks::{GeodesicOptions, distances_from, landmark_distances};
pub(crate) use landmarks::{KeptRows, landmark_distances_kept};

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::NoProgress;
    use nalgebra::Vector3;
    use proptest::prelude::*;
    use std::cmp::Reverse;
    use std::collections::BinaryHeap;
    use wavg_mesh::{TriMesh, procedural};

    fn valid(m: TriMesh) -> ValidMesh {
        ValidMesh::new(m).unwrap()
    }

    /// Mean and max relative error of `d` against `exact` over vertices with exact > `min`.
    fn rel_err(d: &[f64], exact: &[f64], min: f64) -> (f64, f64) {
        let (mut sum, mut max, mut k) = (0.0, 0.0f64, 0);
        for (a, e) in d.iter().zip(exact) {
            if *e > min {
                let r = (a - e).abs() / e;
                sum += r;
                max = max.max(r);
                k += 1;
            }
        }
        (sum / k as f64, max)
    }

    /// Plain Dijkstra on the edge graph (reference upper bound).
    fn dijkstra(mesh: &ValidMesh, s: u32) -> Vec<f64> {
        let mut d = vec![f64::INFINITY; mesh.n_vertices()];
        let mut h = BinaryHeap::new();
        d[s as usize] = 0.0;
        h.push(Reverse((0u64, s)));
        while let Some(Reverse((k, v))) = h.pop() {
            if k != d[v as usize].to_bits() {
                continue;
            }
            for &w in mesh.topology().ring(v) {
                let c = d[v as usize]
                    + (mesh.positions[v as usize] - mesh.positions[w as usize]).norm();
                if c < d[w as usize] {
                    d[w as usize] = c;
                    h.push(Reverse((c.to_bits(), w)));
                }
            }
        }
        d
    }

    #[test]
    fn icosphere_matches_great_circle_distance() {
        let mesh = valid(procedural::icosphere(6));
        assert_eq!(mesh.n_vertices(), 40962);
        let fm = FastMarching::new(&mesh);
        let mut ws = fm.workspace();
        let (mut worst_mean, mut worst_max) = (0.0f64, 0.0f64);
        for s in [0u32, 12345, 40000] {
            let d = fm.run(&mut ws, &[s]);
            let ps = mesh.positions[s as usize];
            let exact: Vec<f64> = mesh
                .positions
                .iter()
                .map(|p| p.dot(&ps).clamp(-1.0, 1.0).acos())
                .collect();
            let (mean, max) = rel_err(d, &exact, 1e-9);
            let (mean_far, _) = rel_err(d, &exact, 0.2);
            eprintln!(
                "icosphere(6) 40962 v, source {s}: mean rel err {:.4}%, beyond 0.2 rad {:.4}%, max {:.2}%",
                mean * 100.0,
                mean_far * 100.0,
                max * 100.0
            );
            worst_mean = worst_mean.max(mean);
            worst_max = worst_max.max(max);
        }
        // Measured 0.21-0.26% mean, 0.7-0.9% max with the exact near field (0.40-0.52%
        // and 3.9-4.5% without).
        assert!(worst_mean < 0.005, "mean relative error {worst_mean}");
        assert!(worst_max < 0.02, "max relative error {worst_max}");
    }

    /// Mean relative error against the Euclidean distance over all vertices and over those
    /// farther than 10 mean edge lengths, worst over `sources`.
    fn plane_errors(
        mesh: &ValidMesh,
        fm: &FastMarching,
        sources: &[u32],
        label: &str,
    ) -> (f64, f64) {
        let mut ws = fm.workspace();
        let h = wavg_mesh::geometry::mean_edge_length(mesh);
        let (mut worst, mut worst_far) = (0.0f64, 0.0f64);
        for &s in sources {
            let d = fm.run(&mut ws, &[s]);
            let ps = mesh.positions[s as usize];
            let exact: Vec<f64> = mesh.positions.iter().map(|p| (p - ps).norm()).collect();
            let (mean, max) = rel_err(d, &exact, 1e-12);
            let (mean_far, _) = rel_err(d, &exact, 10.0 * h);
            // In the plane the geodesic is the straight line; first-order fast marching may
            // undershoot it only slightly.
            for (a, e) in d.iter().zip(&exact) {
                assert!(*a >= e * (1.0 - 1e-2), "{label}: {a} < euclidean {e}");
            }
            eprintln!(
                "{label} ({} v, obtuse corners / split {:?}), source {s}: mean rel err {:.3}%, beyond 10 h {:.3}%, max {:.1}%",
                mesh.n_vertices(),
                fm.obtuse_corners(),
                mean * 100.0,
                mean_far * 100.0,
                max * 100.0
            );
            worst = worst.max(mean);
            worst_far = worst_far.max(mean_far);
        }
        (worst, worst_far)
    }

    #[test]
    fn flat_grid_matches_euclidean_distance() {
        let mesh = valid(procedural::grid(120, 80, 3.0, 2.0));
        let center = 40 * 121 + 60;
        let fm = FastMarching::new(&mesh);
        let (worst, _) = plane_errors(&mesh, &fm, &[0, center, 121 * 81 - 1], "grid 120x80");
        assert!(worst < 0.01, "{worst}");
    }

    fn sheared(shear: f64, squash: f64) -> ValidMesh {
        valid(
            procedural::grid(120, 80, 1.0, 1.0)
                .map_positions(|p| Vector3::new(p.x + shear * p.y, squash * p.y, 0.0)),
        )
    }

    #[test]
    fn sheared_grids_with_obtuse_triangles_match_euclidean_distance() {
        let sources = [0, 40 * 121 + 60, 121 * 81 - 1];
        // Half of the triangles have a 130 degree corner.
        let mesh = sheared(0.5, 0.6);
        let fm = FastMarching::new(&mesh);
        let (obtuse, split) = fm.obtuse_corners();
        assert!(obtuse == 9600 && split == obtuse, "{obtuse} {split}");
        let (mean, _) = plane_errors(&mesh, &fm, &sources, "grid sheared to 130 deg");
        let plain = FastMarching::build(&mesh, false, &NoProgress).unwrap();
        let (mean_plain, _) = plane_errors(&mesh, &plain, &sources, "  same without unfolding");
        assert!(mean < 0.01, "{mean}");
        assert!(
            mean < mean_plain,
            "unfolding should help: {mean} vs {mean_plain}"
        );
        // Extreme: 167 degree corners. Near the source the error is large (vertices closer
        // than the shortest edge are not neighbours), farther away it is small.
        let mesh = sheared(1.5, 0.35);
        let fm = FastMarching::new(&mesh);
        let (_, far) = plane_errors(&mesh, &fm, &sources, "grid sheared to 167 deg");
        let plain = FastMarching::build(&mesh, false, &NoProgress).unwrap();
        let (_, far_plain) = plane_errors(&mesh, &plain, &sources, "  same without unfolding");
        assert!(far < 0.01, "{far}");
        assert!(
            far < far_plain,
            "unfolding should help: {far} vs {far_plain}"
        );
    }

    #[test]
    fn noisy_anisotropic_triangulation_in_the_plane() {
        // 4:1 cells, vertices jittered in the plane: acute and obtuse triangles of all shapes.
        let (nx, ny) = (160u32, 40u32);
        let base = procedural::grid(nx, ny, 1.0, 1.0);
        let noisy = procedural::with_noise(base.clone(), 0.25, 3);
        let w = nx as usize + 1;
        let pos = noisy
            .positions
            .iter()
            .zip(&base.positions)
            .enumerate()
            .map(|(i, (n, b))| {
                // Keep the boundary straight so that the domain stays convex.
                let (ix, iy) = (i % w, i / w);
                let on_b = ix == 0 || ix == nx as usize || iy == 0 || iy == ny as usize;
                if on_b {
                    *b
                } else {
                    Vector3::new(n.x, n.y, 0.0)
                }
            })
            .collect();
        let mesh = valid(TriMesh::new(pos, base.triangles.clone()));
        let fm = FastMarching::new(&mesh);
        let sources = [0, 20 * w as u32 + 80, 7 * w as u32 + 150];
        let (worst, _) = plane_errors(&mesh, &fm, &sources, "jittered 4:1 grid");
        let plain = FastMarching::build(&mesh, false, &NoProgress).unwrap();
        let (worst_plain, _) = plane_errors(&mesh, &plain, &sources, "  same without unfolding");
        // Heavy jitter (40% of the short edges): first-order fast marching loses accuracy.
        assert!(
            worst < 0.025 && worst < worst_plain,
            "{worst} {worst_plain}"
        );
    }

    #[test]
    fn radius_limited_runs_match_full_runs_and_leave_the_workspace_clean() {
        let mesh = valid(procedural::with_noise(procedural::icosphere(4), 0.3, 3));
        let fm = FastMarching::new(&mesh);
        let mut ws = fm.workspace();
        let full = fm.run(&mut ws, &[17]).to_vec();
        for (src, r) in [(17u32, 0.3), (100, 0.05), (2000, 10.0), (5, 0.0)] {
            let reference = fm.run(&mut fm.workspace(), &[src]).to_vec();
            let local = fm.run_within(&mut ws, &[src], r).to_vec();
            let inside = reference.iter().filter(|&&d| d <= r).count();
            assert_eq!(local.len(), inside, "radius {r}");
            for &(v, d) in &local {
                assert_eq!(d, reference[v as usize]);
            }
            assert!(local.windows(2).all(|w| w[0].1 <= w[1].1));
        }
        // The workspace is clean again: a full run gives the same as before.
        assert_eq!(fm.run(&mut ws, &[17]), &full[..]);
        let again = fm.run_within(&mut ws, &[17], 0.3).to_vec();
        assert!(again.iter().all(|&(v, d)| d == full[v as usize]));
    }

    #[test]
    fn disconnected_components_are_unreachable() {
        let a = procedural::icosphere(2);
        let mut b = procedural::icosphere(2).map_positions(|p| p + Vector3::new(5.0, 0.0, 0.0));
        let off = a.n_vertices() as u32;
        for t in &mut b.triangles {
            *t = t.map(|v| v + off);
        }
        let mut m = a.clone();
        m.positions.extend(b.positions);
        m.triangles.extend(b.triangles);
        let mesh = valid(m);
        let d = distances_from(&mesh, &[0]);
        assert!(d[..off as usize].iter().all(|x| x.is_finite()));
        assert!(d[off as usize..].iter().all(|x| *x == f64::INFINITY));
        let e = landmark_distances(&mesh, &[0, off + 3], &GeodesicOptions::new(), &NoProgress)
            .unwrap_err();
        assert!(matches!(e, EmbedError::InvalidArgument(_)), "{e}");
    }

    #[test]
    fn no_valid_source_gives_infinity_everywhere() {
        let mesh = valid(procedural::icosphere(1));
        let d = distances_from(&mesh, &[1000]);
        assert!(d.iter().all(|x| x.is_infinite()));
        let d = distances_from(&mesh, &[]);
        assert!(d.iter().all(|x| x.is_infinite()));
    }

    #[test]
    fn multi_source_is_the_minimum_of_single_sources() {
        let mesh = valid(procedural::with_noise(procedural::icosphere(4), 0.3, 9));
        let fm = FastMarching::new(&mesh);
        let mut ws = fm.workspace();
        let srcs = [3u32, 700, 1500];
        let singles: Vec<Vec<f64>> = srcs
            .iter()
            .map(|&s| fm.run(&mut ws, &[s]).to_vec())
            .collect();
        let multi = fm.run(&mut ws, &srcs).to_vec();
        let h = wavg_mesh::geometry::mean_edge_length(&mesh);
        for v in 0..mesh.n_vertices() {
            let m = singles.iter().map(|d| d[v]).fold(f64::INFINITY, f64::min);
            // Fronts meeting may interact through a triangle update (slightly lower value).
            assert!(
                multi[v] <= m + 1e-12 && multi[v] >= m - 0.2 * h,
                "{v}: {} vs {m}",
                multi[v]
            );
        }
        for &s in &srcs {
            assert_eq!(multi[s as usize], 0.0);
        }
    }

    #[test]
    fn landmark_matrix_is_nearly_symmetric_and_symmetrised() {
        // First-order fast marching is not exactly symmetric; the worst pairs are the
        // closest ones (about 10-20 edge lengths apart).
        asymmetry(0.1, 0.02);
        asymmetry(0.3, 0.02);
    }

    fn asymmetry(noise: f64, bound: f64) {
        let mesh = valid(procedural::with_noise(
            procedural::torus(200, 80, 1.0, 0.35),
            noise,
            4,
        ));
        let lm: Vec<u32> = (0..60).map(|i| i * 263 + 5).collect();
        let fm = FastMarching::new(&mesh);
        let mut ws = fm.workspace();
        let n = lm.len();
        let d: Vec<Vec<f64>> = lm
            .iter()
            .map(|&s| {
                let r = fm.run(&mut ws, &[s]);
                lm.iter().map(|&l| r[l as usize]).collect()
            })
            .collect();
        let h = wavg_mesh::geometry::mean_edge_length(&mesh);
        let (mut worst, mut worst_far, mut sum) = (0.0f64, 0.0f64, 0.0);
        #[allow(clippy::needless_range_loop)]
        for i in 0..n {
            for j in 0..i {
                let q = 0.5 * (d[i][j] + d[j][i]);
                let a = (d[i][j] - d[j][i]).abs() / q;
                worst = worst.max(a);
                sum += a;
                if q > 10.0 * h {
                    worst_far = worst_far.max(a);
                }
            }
        }
        let mean = sum / (n * (n - 1) / 2) as f64;
        eprintln!(
            "torus 16k v, noise {noise}, 60 landmarks: asymmetry |D_ij - D_ji| / Q_ij mean {:.3}%, max {:.3}%, max beyond 10 edge lengths {:.3}%",
            mean * 100.0,
            worst * 100.0,
            worst_far * 100.0
        );
        assert!(worst_far < bound && mean < 0.005, "{worst_far} {mean}");
        let q = landmark_distances(&mesh, &lm, &GeodesicOptions::new(), &NoProgress).unwrap();
        for i in 0..n {
            assert_eq!(q[i * n + i], 0.0);
            for j in 0..n {
                assert_eq!(q[i * n + j], q[j * n + i]);
                if i != j {
                    let want = 0.5 * (d[i][j] + d[j][i]);
                    assert!((q[i * n + j] - want).abs() <= 1e-12 * want, "{i} {j}");
                }
            }
        }
    }

    /// Asymmetry `|d_ij - d_ji| / mean` of the full landmark matrix: mean, max, and the
    /// share of pairs above 2%.
    fn matrix_asymmetry(fm: &FastMarching, lm: &[u32]) -> (f64, f64, f64) {
        let rows = fm.landmark_rows(lm, &NoProgress).unwrap();
        let a: Vec<f64> = rows
            .iter()
            .enumerate()
            .flat_map(|(i, ri)| {
                let rows = &rows;
                ri.iter().take(i).enumerate().map(move |(j, &dij)| {
                    let dji = rows[j][i];
                    (dij - dji).abs() / (0.5 * (dij + dji))
                })
            })
            .collect();
        let n = a.len() as f64;
        (
            a.iter().sum::<f64>() / n,
            a.iter().copied().fold(0.0, f64::max),
            a.iter().filter(|&&x| x > 0.02).count() as f64 / n,
        )
    }

    /// Symmetry of the landmark distance matrix on real meshes. First-order fast marching
    /// is not symmetric; the exact near field (with pseudo-sources at saddles) makes close
    /// pairs exact. At the default 8 edge lengths a few pairs a little farther apart stay
    /// above 2% (at most 0.025% of pairs here); with the near field at 16 edge lengths
    /// every pair is within 2% (3-5x the time of a plain run).
    #[test]
    fn real_mesh_landmark_matrix_symmetry() {
        for file in [
            "meshes/pig.off",
            "meshes/camelhead.off",
            "meshes/fertility.off",
        ] {
            let Some(path) = wavg_testdata::require_data_file("geodesic::real_mesh_symmetry", file)
            else {
                return;
            };
            let mesh = valid(wavg_mesh::io::load(&path).unwrap());
            let opts = DecimateOptions {
                target: 300,
                ..Default::default()
            };
            let lm = crate::decimate::select_landmarks(&mesh, &opts, &NoProgress).unwrap();
            let fm = FastMarching::new(&mesh);
            let (mean, max, over) = matrix_asymmetry(&fm, &lm);
            eprintln!(
                "{file}: 300 landmarks, asymmetry mean {:.3}%, max {:.2}%, pairs above 2%: {:.3}%",
                100.0 * mean,
                100.0 * max,
                100.0 * over
            );
            assert!(mean < 0.003 && over < 0.0005, "{file}");
            let wide = fm.with_near_field_edges(16.0);
            let (mean, max, _) = matrix_asymmetry(&wide, &lm);
            eprintln!(
                "{file}: near field 16 edge lengths: asymmetry mean {:.3}%, max {:.2}%",
                100.0 * mean,
                100.0 * max
            );
            assert!(max < 0.02, "{file}: max asymmetry {max}");
        }
    }

    /// A matrix from kept runs (landmarks kept from the set before, in another order,
    /// and new ones) is the fresh matrix to the bit, on the full mesh and on a coarse one;
    /// a kept run that stopped before a new landmark froze runs again.
    #[test]
    fn kept_runs_give_the_fresh_matrix_bit_for_bit() {
        let mesh = valid(procedural::grid(120, 20, 6.0, 1.0));
        let n = mesh.n_vertices() as u32;
        // Landmarks in the left quarter (x < 1.5, y <= 0.5), then most of them and new
        // ones: one among them, one beyond (x = 2.25) that only some of their runs froze.
        let before: Vec<u32> = (0..30)
            .map(|i| (i * 97) % (n / 2) / 121 * 121 + i)
            .collect();
        let mut after: Vec<u32> = before[5..].iter().rev().copied().collect();
        after.extend([15 * 121 + 10, 5 * 121 + 45]);
        let bits = |q: &[f64]| q.iter().map(|d| d.to_bits()).collect::<Vec<u64>>();
        let coarse = crate::decimate::decimate(
            &mesh,
            &DecimateOptions {
                target: 900,
                locked: before.iter().chain(&after).copied().collect(),
                ..DecimateOptions::default()
            },
            &NoProgress,
        )
        .unwrap();
        let full = GeodesicOptions::new();
        let on_coarse = GeodesicOptions::new().coarse_mesh(&coarse);
        for opts in [full, on_coarse] {
            let mut kept = KeptRows::new(usize::MAX);
            let first =
                landmark_distances_kept(&mesh, &before, &opts, Some(&mut kept), &NoProgress);
            assert_eq!(
                bits(&first.unwrap()),
                bits(&landmark_distances(&mesh, &before, &opts, &NoProgress).unwrap())
            );
            assert_eq!(kept.reused, 0);
            let again = landmark_distances_kept(&mesh, &after, &opts, Some(&mut kept), &NoProgress);
            let fresh = landmark_distances(&mesh, &after, &opts, &NoProgress).unwrap();
            assert_eq!(bits(&again.unwrap()), bits(&fresh));
            // Runs from the left stopped before the far right froze: only some are kept.
            assert!(
                (1..25).contains(&kept.reused),
                "{} rows reused",
                kept.reused
            );
            // The same set once more: every run is kept now.
            let third = landmark_distances_kept(&mesh, &after, &opts, Some(&mut kept), &NoProgress);
            assert_eq!(bits(&third.unwrap()), bits(&fresh));
            assert_eq!(kept.reused, after.len());
        }
        // Over the budget, nothing is kept.
        let mut kept = KeptRows::new(8 * mesh.n_vertices());
        landmark_distances_kept(&mesh, &before, &full, Some(&mut kept), &NoProgress).unwrap();
        landmark_distances_kept(&mesh, &before, &full, Some(&mut kept), &NoProgress).unwrap();
        assert_eq!(kept.reused, 0);
    }

    #[test]
    fn landmark_distances_rejects_bad_ids_and_honours_cancellation() {
        let mesh = valid(procedural::icosphere(2));
        let n = mesh.n_vertices() as u32;
        assert!(matches!(
            landmark_distances(&mesh, &[0, n], &GeodesicOptions::new(), &NoProgress),
            Err(EmbedError::InvalidArgument(_))
        ));
        assert!(matches!(
            landmark_distances(&mesh, &[4, 4], &GeodesicOptions::new(), &NoProgress),
            Err(EmbedError::InvalidArgument(_))
        ));
        assert!(
            landmark_distances(&mesh, &[], &GeodesicOptions::new(), &NoProgress)
                .unwrap()
                .is_empty()
        );
        struct Stop;
        impl Progress for Stop {
            fn report(&self, _: Stage, _: f64) {}
            fn cancelled(&self) -> bool {
                true
            }
        }
        assert!(matches!(
            landmark_distances(&mesh, &[0, 1, 2], &GeodesicOptions::new(), &Stop),
            Err(EmbedError::Cancelled)
        ));
        // Progress reaches 1.
        struct Last(std::sync::Mutex<f64>);
        impl Progress for Last {
            fn report(&self, s: Stage, f: f64) {
                assert_eq!(s, Stage::Geodesics);
                let mut l = self.0.lock().unwrap();
                *l = l.max(f);
            }
        }
        let p = Last(std::sync::Mutex::new(0.0));
        landmark_distances(&mesh, &[0, 10, 20, 30], &GeodesicOptions::new(), &p).unwrap();
        assert_eq!(*p.0.lock().unwrap(), 1.0);
    }

    #[test]
    fn coarse_landmark_distances_stay_close_to_the_truth() {
        let mesh = valid(procedural::icosphere(5));
        let n_v = mesh.n_vertices() as u32;
        let lm: Vec<u32> = (0..60).map(|i| i * (n_v / 60) + 3).collect();
        let n = lm.len();
        let full = landmark_distances(&mesh, &lm, &GeodesicOptions::new(), &NoProgress).unwrap();
        // Not coarser than the mesh: identical.
        let same = landmark_distances(
            &mesh,
            &lm,
            &GeodesicOptions::new().coarse_vertices(n_v as usize),
            &NoProgress,
        )
        .unwrap();
        assert_eq!(same, full);
        let coarse = landmark_distances(
            &mesh,
            &lm,
            &GeodesicOptions::new().coarse_vertices(2000),
            &NoProgress,
        )
        .unwrap();
        let (mut e_full, mut e_coarse, mut diff) = (0.0, 0.0, 0.0);
        for i in 0..n {
            for j in 0..n {
                if i == j {
                    continue;
                }
                let (a, b) = (
                    mesh.positions[lm[i] as usize],
                    mesh.positions[lm[j] as usize],
                );
                let exact = a.dot(&b).clamp(-1.0, 1.0).acos();
                let k = i * n + j;
                e_full += (full[k] - exact).abs() / exact;
                e_coarse += (coarse[k] - exact).abs() / exact;
                diff += (coarse[k] - full[k]).abs() / full[k];
            }
        }
        let m = (n * (n - 1)) as f64;
        eprintln!(
            "icosphere(5) {n_v} v, 60 landmarks: mean rel err full {:.3}%, on 2000 v {:.3}%, coarse vs full {:.3}%",
            100.0 * e_full / m,
            100.0 * e_coarse / m,
            100.0 * diff / m
        );
        assert!(e_full / m < 0.01 && e_coarse / m < 0.02 && diff / m < 0.02);
    }

    #[test]
    fn distances_on_a_snapshot_of_the_landmark_decimation() {
        use crate::decimate::decimate_with_snapshots;
        let mesh = valid(procedural::with_noise(
            procedural::torus(80, 30, 1.0, 0.35),
            0.2,
            2,
        ));
        let opts = DecimateOptions {
            target: 40,
            ..Default::default()
        };
        let (fin, snaps) =
            decimate_with_snapshots(&mesh, &opts, &[800, 1600], &NoProgress).unwrap();
        let full = landmark_distances(&mesh, &fin.landmarks, &GeodesicOptions::new(), &NoProgress)
            .unwrap();
        let fm = FastMarching::new(&mesh);
        let stats = |q: &[f64]| {
            let (mut sum, mut max) = (0.0, 0.0f64);
            for k in 0..q.len() {
                if full[k] > 0.0 {
                    let r = (q[k] - full[k]).abs() / full[k];
                    sum += r;
                    max = max.max(r);
                }
            }
            (sum / (40.0 * 39.0), max)
        };
        let coarse_only = landmark_distances(
            &mesh,
            &fin.landmarks,
            &GeodesicOptions::new()
                .coarse_mesh(&snaps[0])
                .refine_near_pairs(false),
            &NoProgress,
        )
        .unwrap();
        let two = landmark_distances(
            &mesh,
            &fin.landmarks,
            &GeodesicOptions::new()
                .fast_marching(&fm)
                .coarse_mesh(&snaps[0]),
            &NoProgress,
        )
        .unwrap();
        // Close pairs corrected on the finer snapshot instead of the full mesh.
        let mid = landmark_distances(
            &mesh,
            &fin.landmarks,
            &GeodesicOptions::new()
                .coarse_mesh(&snaps[0])
                .refine_on(&snaps[1]),
            &NoProgress,
        )
        .unwrap();
        let (m1, x1) = stats(&coarse_only);
        let (m2, x2) = stats(&two);
        let (m3, x3) = stats(&mid);
        eprintln!(
            "torus 2400 v -> snapshot 800 v, 40 landmarks, rel. diff to full: coarse only mean {:.3}% max {:.2}%, two-level mean {:.3}% max {:.2}%, near pairs on 1600 v mean {:.3}% max {:.2}%",
            100.0 * m1,
            100.0 * x1,
            100.0 * m2,
            100.0 * x2,
            100.0 * m3,
            100.0 * x3
        );
        assert!(m1 < 0.03 && m2 <= m1 && x2 <= x1, "{m1} {m2} {x1} {x2}");
        assert!(m3 < m1 && x3 < x1, "{m1} {m3} {x1} {x3}");
        assert_ne!(mid, coarse_only, "some pairs were corrected");
        for q in [&two, &mid] {
            for k in 0..q.len() {
                assert_eq!(q[k], q[(k % 40) * 40 + k / 40], "symmetric");
            }
        }
        // A landmark that is not in the coarse mesh is refused.
        let missing = (0..mesh.n_vertices() as u32)
            .find(|&v| snaps[0].coarse_index(v).is_none())
            .unwrap();
        assert!(matches!(
            landmark_distances(
                &mesh,
                &[fin.landmarks[0], missing],
                &GeodesicOptions::new().coarse_mesh(&snaps[0]),
                &NoProgress
            ),
            Err(EmbedError::InvalidArgument(_))
        ));
    }

    /// Cancels from its `after`-th look on (counting every look).
    struct CancelAfter {
        looks: std::sync::atomic::AtomicUsize,
        after: usize,
    }

    impl CancelAfter {
        fn new(after: usize) -> Self {
            Self {
                looks: 0.into(),
                after,
            }
        }
        fn looks(&self) -> usize {
            self.looks.load(std::sync::atomic::Ordering::Relaxed)
        }
    }

    impl Progress for CancelAfter {
        fn report(&self, _: Stage, _: f64) {}
        fn cancelled(&self) -> bool {
            self.looks
                .fetch_add(1, std::sync::atomic::Ordering::Relaxed)
                .saturating_add(1)
                > self.after
        }
    }

    /// The build looks at the cancellation throughout (faces, stencils, entries, near
    /// field), and a cancellation at its last look still stops it.
    #[test]
    fn a_fast_marching_build_stops_when_cancelled() {
        let mesh = valid(procedural::torus(300, 120, 1.0, 0.35));
        let (n, f) = (mesh.n_vertices(), mesh.n_faces());
        let never = CancelAfter::new(usize::MAX);
        let fm = FastMarching::new_cancellable(&mesh, &never).unwrap();
        let looks = never.looks();
        // Faces, stencils (three a face at least), sorted entries and near-field vertices.
        let least = f.div_ceil(CANCEL_EVERY)
            + (3 * f).div_ceil(CANCEL_EVERY)
            + 2 * n.div_ceil(CANCEL_EVERY);
        assert!(looks >= least, "{looks} looks, expected at least {least}");
        let mut ws = fm.workspace();
        assert_eq!(
            fm.run(&mut ws, &[7]),
            FastMarching::new(&mesh).run(&mut fm.workspace(), &[7])
        );
        for after in [0, looks / 2, looks - 1] {
            assert!(
                matches!(
                    FastMarching::new_cancellable(&mesh, &CancelAfter::new(after)),
                    Err(EmbedError::Cancelled)
                ),
                "cancelled at look {after} of {looks}"
            );
        }
    }

    /// A run to targets stops when cancelled, and the workspace it leaves gives the same
    /// distances as a fresh one on the next run.
    #[test]
    fn a_run_to_targets_stops_when_cancelled() {
        let mesh = valid(procedural::torus(400, 200, 1.0, 0.35));
        let n = mesh.n_vertices();
        assert!(n > CANCEL_EVERY);
        let fm = FastMarching::new(&mesh);
        let mut ws = fm.workspace();
        // The farthest vertex from 0 freezes last.
        let d = fm.run(&mut ws, &[0]);
        let far = (0..n).max_by(|&a, &b| d[a].total_cmp(&d[b])).unwrap();
        let mut targets = vec![false; n];
        targets[far] = true;
        let cancel = CancelAfter::new(0);
        let r = fm.run_until_targets_cancellable(&mut ws, &[0], &targets, 1, &cancel);
        assert!(matches!(r, Err(EmbedError::Cancelled)));
        assert_eq!(cancel.looks(), 1, "stopped at its first look");
        let again = fm.run_until_targets_cancellable(&mut ws, &[0], &targets, 1, &NoProgress);
        let again = again.unwrap()[far];
        let fresh = fm.run_until_targets(&mut fm.workspace(), &[0], &targets, 1)[far];
        assert_eq!(again, fresh);
        // A run shorter than one look's worth of vertices never looks.
        let near: Vec<bool> = (0..n).map(|v| v == 1).collect();
        let quiet = CancelAfter::new(0);
        assert!(
            fm.run_until_targets_cancellable(&mut ws, &[0], &near, 1, &quiet)
                .is_ok()
        );
        assert_eq!(quiet.looks(), 0);
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]
        /// Between the straight-line (chord) lower bound and the edge-graph (Dijkstra) upper bound.
        #[test]
        fn bounded_by_chord_and_dijkstra(seed in 0u64..1000, amp in 0.0f64..0.6, src in 0u32..642) {
            let mesh = valid(procedural::with_noise(procedural::icosphere(3), amp, seed));
            let d = distances_from(&mesh, &[src]);
            let dj = dijkstra(&mesh, src);
            let ps = mesh.positions[src as usize];
            for v in 0..mesh.n_vertices() {
                let chord = (mesh.positions[v] - ps).norm();
                prop_assert!(d[v] <= dj[v] * (1.0 + 1e-6), "{} > dijkstra {}", d[v], dj[v]);
                prop_assert!(d[v] >= chord * (1.0 - 1e-3), "{} < chord {}", d[v], chord);
            }
        }
    }
}
