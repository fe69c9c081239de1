//! Forward and inverse problems on procedural and real meshes.

use crate::common;

use common::solver_on;

use std::sync::Arc;

use wavg_mesh::geometry::mean_edge_length;
use wavg_mesh::{SurfacePoint, ValidMesh, procedural};
use wavg_solve::sampling::{FpsMetric, farthest_point_vertices, uniform_surface_points};
use wavg_solve::{
    Anchor, BatchWeights, CurveAim, EmbeddedMesh, ForwardOptions, ForwardScratch, Normalization,
    Par, ProjectionPath, Projector, SearchGoal, SearchMode, SolveError, Solver, Start,
};

/// Inverse then forward on `n` random points; returns the fraction back within 1e-3 mean
/// edge lengths, after checking partition of unity on every query and, for the certified
/// searches, that a point that does not come back was replaced by a closer valid projection
/// (they return the closest Phong projection; the original point is a valid one by
/// construction). The paper's local search (`Fast`) is not certified.
fn round_trip_fraction(s: &Solver, n: usize, seed: u64, mode: SearchMode) -> f64 {
    let mel = mean_edge_length(s.mesh());
    let pts = uniform_surface_points(s.mesh(), n, seed).unwrap();
    let mut ok = 0;
    for p in &pts {
        let w = s.inverse(p).unwrap();
        assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        let opts = ForwardOptions {
            mode,
            ..Default::default()
        };
        let r = s.forward(&w, &opts).unwrap();
        if (r.position - p.position(s.mesh())).norm() < 1e-3 * mel {
            ok += 1;
        } else if mode != SearchMode::Fast {
            let ybar = s.average(&w, Normalization::Reject).unwrap();
            let own = (ybar - s.projector().embedded().point(p)).norm();
            assert!(
                r.distance <= own * (1.0 + 1e-6),
                "found {} but the point is at {own}",
                r.distance
            );
        }
    }
    ok as f64 / n as f64
}

#[test]
fn round_trips_on_procedural_meshes() {
    for (name, mesh, k) in [
        ("icosphere", procedural::icosphere(3), 20),
        ("bump sphere", procedural::bump_sphere(3, 0.4), 30),
        ("torus", procedural::torus(48, 24, 1.0, 0.35), 40),
        (
            "noisy sphere",
            procedural::with_noise(procedural::icosphere(3), 0.01, 3),
            25,
        ),
    ] {
        let s = solver_on(mesh, k, 1);
        let f = round_trip_fraction(&s, 400, 2, SearchMode::Fast);
        assert!(f >= 0.99, "{name}: round trip fraction {f}");
        let f = round_trip_fraction(&s, 50, 3, SearchMode::Exact);
        assert!(f >= 0.98, "{name} (exact): round trip fraction {f}");
        let f = round_trip_fraction(&s, 100, 4, SearchMode::Certified);
        assert!(f >= 0.98, "{name} (certified): round trip fraction {f}");
    }
}

#[test]
fn round_trips_on_a_real_mesh() {
    let Some(path) =
        wavg_testdata::require_data_file("round_trips_on_a_real_mesh", "meshes/pig.off")
    else {
        return;
    };
    let mesh = wavg_mesh::io::load(&path).unwrap();
    // With the 3-D positions as the embedding (no geodesic embedding in unit tests), about
    // 7% of the averages are closer to another part of the pig than to the original point.
    let s = solver_on(mesh, 27, 0);
    let f = round_trip_fraction(&s, 1000, 4, SearchMode::Fast);
    assert!(f >= 0.9, "pig: round trip fraction {f}");
    let f = round_trip_fraction(&s, 300, 5, SearchMode::Certified);
    assert!(f >= 0.9, "pig (certified): round trip fraction {f}");
}

#[test]
fn interpolates_at_anchors_and_one_hot_forward_returns_the_anchor() {
    let mesh = Arc::new(ValidMesh::new(procedural::bump_sphere(3, 0.3)).unwrap());
    let proj =
        Arc::new(Projector::new(Arc::new(EmbeddedMesh::from_positions(mesh.clone()))).unwrap());
    let mut anchors: Vec<Anchor> = farthest_point_vertices(&mesh, 12, 9, FpsMetric::EdgeGraph)
        .unwrap()
        .into_iter()
        .map(Anchor::Vertex)
        .collect();
    anchors.push(Anchor::Point(SurfacePoint::new(100, [0.2, 0.5, 0.3])));
    anchors.push(Anchor::Point(SurfacePoint::new(900, [0.6, 0.1, 0.3])));
    let s = Solver::new(proj, anchors.clone()).unwrap();
    let n = anchors.len();
    for i in 0..n {
        let p = s.anchors().point(i).unwrap();
        let w = s.inverse(&p).unwrap();
        for (j, wj) in w.iter().enumerate() {
            let expect = if i == j { 1.0 } else { 0.0 };
            assert!((wj - expect).abs() < 1e-9, "anchor {i}: w[{j}] = {wj}");
        }
        let mut onehot = vec![0.0; n];
        onehot[i] = 1.0;
        let r = s.forward(&onehot, &ForwardOptions::default()).unwrap();
        assert!((r.position - p.position(&mesh)).norm() < 1e-9, "anchor {i}");
        assert!(matches!(r.start, Start::HighestWeight { anchor, .. } if anchor == i));
        let r = s
            .forward(
                &onehot,
                &ForwardOptions {
                    mode: SearchMode::Exact,
                    ..Default::default()
                },
            )
            .unwrap();
        assert!(
            (r.position - p.position(&mesh)).norm() < 1e-9,
            "anchor {i} (exact)"
        );
    }
}

#[test]
fn locality_far_anchors_get_small_weights() {
    let s = solver_on(procedural::icosphere(4), 60, 5);
    let pts = uniform_surface_points(s.mesh(), 100, 6).unwrap();
    let mut far_max = 0.0f64;
    for p in &pts {
        let w = s.inverse(p).unwrap();
        let x = p.position(s.mesh());
        for (i, wi) in w.iter().enumerate() {
            let a = s.anchors().point(i).unwrap().position(s.mesh());
            // Anchors are ~0.45 apart; "far" is more than a quarter of the sphere away.
            if (a - x).norm() > 1.0 {
                far_max = far_max.max(wi.abs());
            }
        }
        let top = w.iter().copied().fold(0.0, f64::max);
        assert!(top > 0.2, "no dominant nearby anchor: {top}");
    }
    // Weights fall off like 1/d^2 with d a squared distance: anchors 2-5x farther than the
    // nearest ones get weights in the 1e-3 range, never a share comparable to 1/60.
    assert!(far_max < 5e-3, "a far anchor got weight {far_max}");
}

#[test]
fn weights_are_continuous_across_edges() {
    let s = solver_on(procedural::bump_sphere(3, 0.4), 25, 7);
    let mesh = s.mesh().clone();
    let topo = mesh.topology();
    for f in (0..mesh.n_faces() as u32).step_by(37) {
        let g = topo.face_neighbors(f)[0];
        // Edge 0 of f runs from corner 0 to corner 1; find the same vertices in g.
        let t = mesh.triangles[f as usize];
        let tg = mesh.triangles[g as usize];
        let ia = tg.iter().position(|&v| v == t[0]).unwrap();
        let ib = tg.iter().position(|&v| v == t[1]).unwrap();
        let ic = 3 - ia - ib;
        for u in [0.0, 0.3, 0.5, 0.9] {
            let on_f = SurfacePoint::new(f, [1.0 - u, u, 0.0]);
            let mut b = [0.0; 3];
            b[ia] = 1.0 - u;
            b[ib] = u;
            let on_g = SurfacePoint::new(g, b);
            let wf = s.inverse(&on_f).unwrap();
            let wg = s.inverse(&on_g).unwrap();
            let diff = wf
                .iter()
                .zip(&wg)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(diff < 1e-5, "face {f}/{g} u={u}: weights differ by {diff}");
            // Stepping eps into either face changes the weights by O(eps).
            let eps = 1e-6;
            let mut bf = [1.0 - u - eps / 2.0, u - eps / 2.0, eps];
            bf.iter_mut().for_each(|x| *x = x.max(0.0));
            let s_f: f64 = bf.iter().sum();
            let into_f = SurfacePoint::new(f, bf.map(|x| x / s_f));
            let mut bg = b;
            bg[ic] = eps;
            bg[ia] -= eps / 2.0;
            bg[ib] -= eps / 2.0;
            bg.iter_mut().for_each(|x| *x = x.max(0.0));
            let s_g: f64 = bg.iter().sum();
            let into_g = SurfacePoint::new(g, bg.map(|x| x / s_g));
            let w1 = s.inverse(&into_f).unwrap();
            let w2 = s.inverse(&into_g).unwrap();
            let diff = w1
                .iter()
                .zip(&w2)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(
                diff < 1e-4,
                "face {f}/{g} u={u}: step across the edge changes weights by {diff}"
            );
        }
    }
}

/// Rotation by 180 degrees about z maps the icosphere onto itself; with the 12 icosahedron
/// vertices as anchors, weights of the rotated point are the rotated weights, and forward
/// with permuted weights gives the rotated point.
#[test]
fn symmetric_inputs_give_symmetric_answers() {
    let mesh = Arc::new(ValidMesh::new(procedural::icosphere(3)).unwrap());
    let rot = |p: nalgebra::Vector3<f64>| nalgebra::Vector3::new(-p.x, -p.y, p.z);
    let find = |q: nalgebra::Vector3<f64>| {
        mesh.positions
            .iter()
            .position(|p| (p - q).norm() < 1e-9)
            .unwrap() as u32
    };
    let vmap: Vec<u32> = mesh.positions.iter().map(|&p| find(rot(p))).collect();
    let proj =
        Arc::new(Projector::new(Arc::new(EmbeddedMesh::from_positions(mesh.clone()))).unwrap());
    let s = Solver::new(proj, (0..12).map(Anchor::Vertex)).unwrap();
    let sigma: Vec<usize> = (0..12).map(|i| vmap[i] as usize).collect();
    assert!(sigma.iter().all(|&j| j < 12));
    let pts = uniform_surface_points(&mesh, 60, 11).unwrap();
    for p in &pts {
        let t = mesh.triangles[p.face as usize];
        let rt = t.map(|v| vmap[v as usize]);
        let g = mesh
            .triangles
            .iter()
            .position(|tg| rt.iter().all(|v| tg.contains(v)))
            .unwrap();
        let tg = mesh.triangles[g];
        let mut b = [0.0; 3];
        for (i, v) in rt.iter().enumerate() {
            b[tg.iter().position(|x| x == v).unwrap()] = p.bary[i];
        }
        let q = SurfacePoint::new(g as u32, b);
        assert!((q.position(&mesh) - rot(p.position(&mesh))).norm() < 1e-12);
        let wp = s.inverse(p).unwrap();
        let wq = s.inverse(&q).unwrap();
        for i in 0..12 {
            assert!(
                (wp[i] - wq[sigma[i]]).abs() < 1e-5,
                "w[{i}] {} vs {}",
                wp[i],
                wq[sigma[i]]
            );
        }
        let mut permuted = vec![0.0; 12];
        for i in 0..12 {
            permuted[sigma[i]] = wp[i];
        }
        let a = s.forward(&wp, &ForwardOptions::default()).unwrap();
        let b = s.forward(&permuted, &ForwardOptions::default()).unwrap();
        assert!((rot(a.position) - b.position).norm() < 1e-6);
    }
}

#[test]
fn batches_equal_sequential_for_any_thread_count() {
    let s = solver_on(procedural::bump_sphere(3, 0.3), 20, 1);
    let pts = uniform_surface_points(s.mesh(), 500, 8).unwrap();
    let seq_w: Vec<_> = pts.iter().map(|p| s.inverse(p)).collect();
    let mut weights: Vec<Vec<f64>> = seq_w.iter().map(|w| w.clone().unwrap()).collect();
    // Malformed rows among them: each batch reports the same typed error in its place.
    weights[3] = vec![0.5; 3];
    weights[100][0] = f64::INFINITY; // (not NaN: NaN != NaN in the comparison)
    weights[200][1] += 0.5;
    let opts = ForwardOptions::default();
    let seq_f: Vec<_> = weights.iter().map(|w| s.forward(w, &opts)).collect();
    let mut seq_warm = Vec::new();
    for c in weights.chunks(50) {
        let mut o = opts;
        let mut aim = CurveAim::default();
        for w in c {
            let r = s.forward_aimed(w, &o, aim.aim().as_ref());
            if let Ok(r) = &r {
                o.warm_start = Some(r.point);
                aim.record(&s, &r.point);
            }
            seq_warm.push(r);
        }
    }
    for threads in [1, 2, 4] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let bw = s.inverse_batch(&pts);
            assert_eq!(bw.len(), pts.len());
            for (i, w) in seq_w.iter().enumerate() {
                assert_eq!(
                    bw.get(i).unwrap(),
                    &w.as_ref().unwrap()[..],
                    "{threads} threads, inverse {i}"
                );
            }
            let fb = s.forward_batch(&weights, &opts);
            for (i, (a, b)) in fb.iter().zip(&seq_f).enumerate() {
                assert_eq!(a, b, "{threads} threads, forward {i}");
            }
            assert_eq!(fb.len(), seq_f.len());
            assert_eq!(
                s.forward_batch_warm(&weights, &opts, 50),
                seq_warm,
                "{threads} threads, warm"
            );
        });
    }
    // Every search mode, and a warm start shared by the whole batch.
    let warm = ForwardOptions::default().warm(pts[0]);
    for o in [SearchMode::Certified, SearchMode::Exact]
        .map(|mode| ForwardOptions { mode, ..opts })
        .into_iter()
        .chain([warm])
    {
        let seq: Vec<_> = weights.iter().map(|w| s.forward(w, &o)).collect();
        assert_eq!(s.forward_batch(&weights, &o), seq, "{o:?}");
    }
    // The explicit layer: every parallelism, buffers reused from one call to the next.
    let mut scratch = ForwardScratch::default();
    let (mut fb, mut warm, mut bw) = (Vec::new(), Vec::new(), BatchWeights::default());
    let two = Par::Threads(std::num::NonZeroUsize::new(2).unwrap());
    let three = Par::Threads(std::num::NonZeroUsize::new(3).unwrap());
    for par in [Par::Seq, Par::Rayon, two, three, Par::Seq] {
        s.forward_batch_into(&weights, &opts, &mut scratch, &mut fb, par)
            .unwrap();
        assert_eq!(fb, seq_f, "{par:?}");
        s.forward_batch_warm_into(&weights, &opts, 50, &mut warm, par)
            .unwrap();
        assert_eq!(warm, seq_warm, "{par:?}");
        s.inverse_batch_into(&pts, &mut bw, par).unwrap();
        assert_eq!(bw.len(), pts.len());
        for (i, w) in seq_w.iter().enumerate() {
            assert_eq!(bw.get(i).unwrap(), &w.as_ref().unwrap()[..], "{par:?}");
        }
    }
}

#[test]
fn warm_start_is_used_and_agrees() {
    let s = solver_on(procedural::torus(48, 24, 1.0, 0.35), 40, 2);
    let pts = uniform_surface_points(s.mesh(), 100, 12).unwrap();
    for p in &pts {
        let w = s.inverse(p).unwrap();
        let cold = s.forward(&w, &ForwardOptions::default()).unwrap();
        let warm = s.forward(&w, &ForwardOptions::default().warm(*p)).unwrap();
        assert!(matches!(warm.start, Start::Warm(_)));
        assert!((cold.position - warm.position).norm() < 1e-9);
    }
}

#[test]
fn malformed_inputs_are_typed_errors() {
    let mut s = solver_on(procedural::icosphere(2), 6, 1);
    let o = ForwardOptions::default();
    let nv = s.mesh().n_vertices() as u32;
    let nf = s.mesh().n_faces() as u32;
    assert!(matches!(
        s.forward(&[0.5, 0.5], &o),
        Err(SolveError::WeightCount {
            expected: 6,
            got: 2
        })
    ));
    let mut w = vec![1.0 / 6.0; 6];
    w[2] = f64::NAN;
    assert!(matches!(
        s.forward(&w, &o),
        Err(SolveError::NonFiniteWeight { index: 2, .. })
    ));
    let w = vec![0.2; 6];
    assert!(matches!(
        s.forward(&w, &o),
        Err(SolveError::WeightSum { .. })
    ));
    let norm = ForwardOptions {
        normalization: Normalization::Normalize,
        ..o
    };
    assert!(s.forward(&w, &norm).is_ok());
    let w1 = vec![1.0 / 6.0; 6];
    let bad_warm = o.warm(SurfacePoint::new(nf, [1.0, 0.0, 0.0]));
    assert!(matches!(
        s.forward(&w1, &bad_warm),
        Err(SolveError::FaceOutOfRange { .. })
    ));
    assert!(matches!(
        s.inverse(&SurfacePoint::new(nf + 5, [1.0, 0.0, 0.0])),
        Err(SolveError::FaceOutOfRange { .. })
    ));
    for b in [[0.5, 0.5, 0.5], [f64::NAN, 0.5, 0.5], [1.5, -0.5, 0.0]] {
        assert!(matches!(
            s.inverse(&SurfacePoint::new(0, b)),
            Err(SolveError::BadBarycentrics { .. })
        ));
    }
    let a = s.anchors_mut();
    assert!(matches!(
        a.push(Anchor::Vertex(nv)),
        Err(SolveError::VertexOutOfRange { .. })
    ));
    assert!(matches!(
        a.set(6, Anchor::Vertex(0)),
        Err(SolveError::AnchorOutOfRange { index: 6, count: 6 })
    ));
    assert!(matches!(
        a.remove(17),
        Err(SolveError::AnchorOutOfRange { .. })
    ));
    assert!(matches!(
        a.push(Anchor::Point(SurfacePoint::new(0, [0.2, 0.2, 0.2]))),
        Err(SolveError::BadBarycentrics { .. })
    ));
    assert_eq!(a.len(), 6);
    assert!(
        s.set_gamma(f64::NAN).is_err() && s.set_gamma(-1.0).is_err() && s.set_gamma(5.0).is_ok()
    );
    // No anchors at all.
    while !s.anchors().is_empty() {
        s.anchors_mut().remove(0).unwrap();
    }
    assert!(matches!(s.forward(&[], &o), Err(SolveError::NoAnchors)));
    assert!(matches!(
        s.inverse(&SurfacePoint::new(0, [1.0, 0.0, 0.0])),
        Err(SolveError::NoAnchors)
    ));
}

#[test]
fn editing_anchors_changes_the_answers_consistently() {
    let mut s = solver_on(procedural::icosphere(3), 10, 3);
    let fresh = |s: &Solver| {
        Solver::new(s.projector().clone(), s.anchors().anchors().iter().copied()).unwrap()
    };
    let p = SurfacePoint::new(77, [0.3, 0.3, 0.4]);
    s.anchors_mut()
        .set(4, Anchor::Point(SurfacePoint::new(500, [0.1, 0.1, 0.8])))
        .unwrap();
    s.anchors_mut().remove(1).unwrap();
    s.anchors_mut().push(Anchor::Vertex(321)).unwrap();
    assert_eq!(s.inverse(&p).unwrap(), fresh(&s).inverse(&p).unwrap());
    assert_eq!(s.anchors().len(), 10);
}

#[test]
fn no_weighted_average_is_a_typed_outcome() {
    // A flat square with anchors at its corners: extrapolating weights put the average
    // outside the square, where nothing projects.
    let mesh = Arc::new(ValidMesh::new(procedural::grid(6, 6, 1.0, 1.0)).unwrap());
    let proj = Arc::new(Projector::new(Arc::new(EmbeddedMesh::from_positions(mesh))).unwrap());
    let s = Solver::new(proj, [0u32, 6, 48, 42].map(Anchor::Vertex)).unwrap();
    let w = [2.0, -1.0, 0.0, 0.0];
    assert_eq!(
        s.forward(&w, &ForwardOptions::default()),
        Err(SolveError::NoWeightedAverage)
    );
    let exact = ForwardOptions {
        mode: SearchMode::Exact,
        ..Default::default()
    };
    assert_eq!(s.forward(&w, &exact), Err(SolveError::NoWeightedAverage));
    // Inside, it works and matches bilinear intuition: the centre.
    let r = s.forward(&[0.25; 4], &ForwardOptions::default()).unwrap();
    assert!((r.position - nalgebra::Vector3::new(0.5, 0.5, 0.0)).norm() < 1e-9);
}

/// The local search returns any point of the surface itself, from any start vertex.
#[test]
fn local_search_finds_points_on_the_surface_from_anywhere() {
    let s = solver_on(procedural::bump_sphere(3, 0.4), 4, 1);
    let proj = s.projector();
    let pts = uniform_surface_points(s.mesh(), 200, 9).unwrap();
    let mut n_near = 0;
    for (i, p) in pts.iter().enumerate() {
        let y = proj.embedded().point(p);
        let start = (i * 37 % s.mesh().n_vertices()) as u32;
        let v = proj.walk(&y, start);
        let near = s.mesh().triangles[p.face as usize].contains(&v);
        let hit = proj.project_with(&y, start, None, SearchGoal::FirstHit);
        // On a convex-ish sphere the walk reaches a corner of the face (or a neighbour).
        if near {
            n_near += 1;
            let h = hit.expect("a point on the surface has a projection next to it");
            assert_eq!(h.path, ProjectionPath::Local);
            assert!(h.distance < 1e-6, "{}", h.distance);
            assert!((h.point.position(s.mesh()) - p.position(s.mesh())).norm() < 1e-6);
        }
    }
    assert!(
        n_near >= 180,
        "the walk ended next to the point only {n_near} times of 200"
    );
}

/// With a real geodesic embedding (the precomputation pipeline) instead of 3-D positions.
#[test]
fn round_trips_with_a_geodesic_embedding() {
    for (name, mesh, k) in [
        ("bump sphere", procedural::bump_sphere(4, 0.5), 40),
        ("torus", procedural::torus(64, 24, 1.0, 0.35), 60),
    ] {
        let mesh = Arc::new(ValidMesh::new(mesh).unwrap());
        let opts = wavg_embed::PrecomputeOptions {
            landmarks: 300,
            ..Default::default()
        };
        let (e, _) = wavg_embed::precompute(&mesh, &opts, &wavg_embed::NoProgress).unwrap();
        let coords = e
            .coords
            .iter()
            .map(|c| wavg_solve::Vec8::from(*c))
            .collect();
        let emb = Arc::new(EmbeddedMesh::new(mesh.clone(), coords).unwrap());
        let proj = Arc::new(Projector::new(emb).unwrap());
        let a = farthest_point_vertices(&mesh, k, 1, FpsMetric::EdgeGraph).unwrap();
        let s = Solver::new(proj, a.into_iter().map(Anchor::Vertex)).unwrap();
        let f = round_trip_fraction(&s, 500, 2, SearchMode::Fast);
        assert!(f >= 0.99, "{name}: round trip fraction {f}");
        let f = round_trip_fraction(&s, 100, 3, SearchMode::Certified);
        assert!(f >= 0.99, "{name} (certified): round trip fraction {f}");
    }
}

/// The second chance of the fast search: the nearest vertex (branch and bound) is the
/// brute-force one, near and far off the surface, and the search from it finds points on
/// the surface.
#[test]
fn nearest_vertex_second_chance() {
    let s = solver_on(procedural::torus(48, 24, 1.0, 0.35), 4, 1);
    let proj = s.projector();
    let c = proj.embedded().coords();
    for (i, p) in uniform_surface_points(s.mesh(), 100, 3)
        .unwrap()
        .iter()
        .enumerate()
    {
        for scale in [0.01, 0.3, 3.0] {
            let y = proj.embedded().point(p)
                + wavg_solve::Vec8::from_fn(|k, _| ((i + k) % 3) as f64 * scale);
            let brute = (0..c.len())
                .min_by(|&a, &b| {
                    (c[a] - y)
                        .norm_squared()
                        .total_cmp(&(c[b] - y).norm_squared())
                })
                .unwrap();
            assert_eq!(proj.nearest_vertex(&y) as usize, brute, "{i} {scale}");
        }
        let yhat = proj.embedded().point(p);
        let h = proj
            .project_with(
                &yhat,
                proj.nearest_vertex(&yhat),
                None,
                SearchGoal::FirstHit,
            )
            .unwrap();
        assert!(h.distance < 1e-6 && h.path == ProjectionPath::Local);
    }
}
