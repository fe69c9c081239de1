//! The paper's properties of Phong projection (Section 3.3) and the projector's
//! guarantees, on procedural meshes under three embeddings.

use crate::common;

use common::*;
use proptest::prelude::*;
use wavg_mesh::{NONE, SurfacePoint};
use wavg_project::{ProjectError, ProjectionPath, SearchGoal};

fn fixture() -> impl Strategy<Value = usize> {
    0..fixtures().len()
}

fn config() -> ProptestConfig {
    ProptestConfig {
        cases: 256,
        ..ProptestConfig::default()
    }
}

proptest! {
    #![proptest_config(config())]

    /// Property 1: a point on the mesh projects to itself (from any start vertex).
    #[test]
    fn on_surface_points_project_to_themselves(
        fx in fixture(), f in 0.0f64..1.0, a in 0.0f64..1.0, b in 0.0f64..1.0, s in 0.0f64..1.0,
    ) {
        let fx = &fixtures()[fx];
        let p = fx.point(f, a, b);
        let y = fx.emb.point(&p);
        let r = fx.proj.project(&y, fx.vertex(s)).unwrap();
        let scale = fx.face_scale(p.face);
        prop_assert!(r.distance <= 1e-9 * scale, "{}: distance {}", fx.name, r.distance);
        if r.point.face == p.face {
            for i in 0..3 {
                prop_assert!((r.point.bary[i] - p.bary[i]).abs() <= 1e-9, "{}: {:?} vs {:?}", fx.name, r.point, p);
            }
        } else {
            let (t, u) = (fx.mesh().triangles[p.face as usize], fx.mesh().triangles[r.point.face as usize]);
            prop_assert!(t.iter().any(|v| u.contains(v)), "{}: far face", fx.name);
        }
        let sum: f64 = r.point.bary.iter().sum();
        prop_assert!((sum - 1.0).abs() < 1e-12 && r.point.bary.iter().all(|&x| x >= 0.0));
    }

    /// Property 4: on a shared edge Psi spans the same plane from both faces, and a
    /// projection on the edge is a projection onto both triangles.
    #[test]
    fn shared_edges_agree(fx in fixture(), f in 0.0f64..1.0, e in 0usize..3, t in 0.02f64..0.98,
                          off in 0.0f64..0.3, seed in 0u64..1000) {
        let fx = &fixtures()[fx];
        let face = fx.point(f, 0.3, 0.3).face;
        let other = fx.mesh().topology().face_neighbors(face)[e];
        prop_assume!(other != NONE);
        let tri = fx.mesh().triangles[face as usize];
        let (va, vb) = (tri[e], tri[(e + 1) % 3]);
        let mut bary = [0.0; 3];
        bary[e] = 1.0 - t;
        bary[(e + 1) % 3] = t;
        let p = SurfacePoint::new(face, bary);
        let oth = fx.mesh().triangles[other as usize];
        let mut bo = [0.0; 3];
        for i in 0..3 {
            if oth[i] == va { bo[i] = 1.0 - t; }
            if oth[i] == vb { bo[i] = t; }
        }
        let q = SurfacePoint::new(other, bo);
        let (psi_p, psi_q) = (fx.proj.psi(&p), fx.proj.psi(&q));
        let angle = principal_angle(&psi_p, &psi_q);
        prop_assert!(angle < 1e-5, "{}: principal angle {angle}", fx.name);
        let ep = fx.emb.point(&p);
        prop_assert!((ep - fx.emb.point(&q)).norm() < 1e-12 * (1.0 + ep.norm()));
        let y = ep + normal_to(&psi_p, seed) * (off * fx.mean_edge);
        // Psi(p) (e(p) - y) = 0 from both sides.
        for (psi, s) in [(psi_p, "p"), (psi_q, "q")] {
            let r = psi * (ep - y);
            prop_assert!(r.norm() <= 1e-5 * fx.mean_edge, "{}: residual {s} {}", fx.name, r.norm());
        }
        let scale = fx.face_scale(face);
        for (g, sp) in [(face, p), (other, q)] {
            let xi = fx.proj.project_onto_face(&y, g);
            prop_assert!(xi.is_some(), "{}: no projection onto face {g}", fx.name);
            let got = fx.emb.point(&SurfacePoint::new(g, xi.unwrap()));
            prop_assert!((got - fx.emb.point(&sp)).norm() <= 1e-6 * scale, "{}: face {g} gives another point", fx.name);
        }
    }

    /// Property 5: the points of R^8 with a given Phong projection form an affine subspace
    /// (the normal space at that point): affine combinations of normal offsets project back.
    #[test]
    fn preimage_is_affine(fx in fixture(), f in 0.0f64..1.0, a in 0.05f64..0.9, b in 0.05f64..0.9,
                          s1 in 0u64..1000, s2 in 0u64..1000, al in -1.0f64..1.0, be in -1.0f64..1.0) {
        let fx = &fixtures()[fx];
        let p = fx.point(f, a, b);
        prop_assume!(p.bary.iter().all(|&x| x > 0.02));
        let psi = fx.proj.psi(&p);
        let ep = fx.emb.point(&p);
        let h = 0.2 * fx.mean_edge;
        let (n1, n2) = (normal_to(&psi, s1) * h, normal_to(&psi, s2 + 5000) * h);
        for (c1, c2) in [(1.0, 0.0), (0.0, 1.0), (al, be), (0.5 * al, -be)] {
            let y = ep + n1 * c1 + n2 * c2;
            let xi = fx.proj.project_onto_face(&y, p.face);
            prop_assert!(xi.is_some(), "{}: lost the projection", fx.name);
            let xi = xi.unwrap();
            for i in 0..3 {
                prop_assert!((xi[i] - p.bary[i]).abs() < 1e-6, "{}: {:?} vs {:?}", fx.name, xi, p.bary);
            }
        }
    }

    /// Property 3: if y projects onto a vertex's tangent plane at the vertex, the vertex is
    /// a Phong projection (of every incident triangle's tangent equations, and found).
    #[test]
    fn vertex_property(fx in fixture(), u in 0.0f64..1.0, off in 0.0f64..0.3, seed in 0u64..1000) {
        let fx = &fixtures()[fx];
        let v = fx.vertex(u);
        let ev = fx.emb.coords()[v as usize];
        let y = ev + normal_to(&fx.proj.frame(v), seed) * (off * fx.mean_edge);
        let topo = fx.mesh().topology();
        let mut found = false;
        for &f in topo.ring_faces(v) {
            let c = fx.mesh().triangles[f as usize].iter().position(|&w| w == v).unwrap();
            let corner = SurfacePoint::at_corner(f, c);
            let psi = fx.proj.psi(&corner);
            prop_assert!(principal_angle(&psi, &fx.proj.frame(v)) < 1e-6);
            prop_assert!((psi * (ev - y)).norm() <= 1e-6 * fx.mean_edge);
            if let Some(xi) = fx.proj.project_onto_face(&y, f) {
                found |= xi[c] > 1.0 - 1e-6;
            }
        }
        prop_assert!(found, "{}: no incident face finds vertex {v}", fx.name);
    }

    /// The fast path returns the same closest valid projection as the exhaustive search
    /// and the brute force, for points near the surface, from any start vertex.
    #[test]
    fn fast_path_agrees_with_exhaustive(fx in fixture(), f in 0.0f64..1.0, a in 0.0f64..1.0, b in 0.0f64..1.0,
                                       s in 0.0f64..1.0, off in 0.0f64..1.0, seed in 0u64..10000) {
        let fx = &fixtures()[fx];
        let p = fx.point(f, a, b);
        let dir = normal_to(&wavg_project::Mat2x8::zeros(), seed); // any direction
        let y = fx.emb.point(&p) + dir * (off * fx.mean_edge);
        let fast = fx.proj.project(&y, fx.vertex(s));
        let exh = fx.proj.project_exhaustive(&y);
        let brute = fx.proj.project_brute_force(&y);
        match (&fast, &exh, &brute) {
            (Ok(x), Ok(e), Ok(bf)) => {
                prop_assert!(x.path == ProjectionPath::Certified || x.path == ProjectionPath::Fallback);
                for other in [e, bf] {
                    let same = (fx.emb.point(&x.point) - fx.emb.point(&other.point)).norm() <= 1e-6 * fx.mean_edge;
                    let tie = (x.distance - other.distance).abs() <= 1e-9 * (other.distance + fx.mean_edge);
                    prop_assert!(same || tie, "{}: fast {:?} vs {:?}", fx.name, x, other);
                }
            }
            (Err(ProjectError::NoProjection), Err(ProjectError::NoProjection), Err(ProjectError::NoProjection)) => {}
            _ => prop_assert!(false, "{}: {:?} / {:?} / {:?}", fx.name, fast, exh, brute),
        }
    }

    /// The two goals of the one local search: the first hit (the forward problem's fast
    /// mode, with or without a warm-start face: the point's own, or one or two faces
    /// away, which the face walk steps over) is a valid Phong projection, never closer
    /// than the brute force's; the closest goal equals the brute force.
    #[test]
    fn first_hit_is_valid_and_closest_is_the_brute_force(
        fx in fixture(), f in 0.0f64..1.0, a in 0.0f64..1.0, b in 0.0f64..1.0,
        s in 0.0f64..1.0, off in 0.0f64..1.5, seed in 0u64..10000, warm in 0usize..4,
        side in 0usize..3,
    ) {
        let fx = &fixtures()[fx];
        let p = fx.point(f, a, b);
        let dir = normal_to(&wavg_project::Mat2x8::zeros(), seed);
        let y = fx.emb.point(&p) + dir * (off * fx.mean_edge);
        let topo = fx.emb.mesh().topology();
        let step = |f: u32, k: usize| Some(topo.face_neighbors(f)[k]).filter(|&g| g != NONE).unwrap_or(f);
        let hint = match warm {
            0 => None,
            1 => Some(p.face),
            2 => Some(step(p.face, side)),
            _ => Some(step(step(p.face, side), (side + 1) % 3)),
        };
        let first = fx.proj.project_with(&y, fx.vertex(s), hint, SearchGoal::FirstHit);
        let closest = fx.proj.project_with(&y, fx.vertex(s), None, SearchGoal::Closest);
        let brute = fx.proj.project_brute_force(&y);
        match (&first, &closest, &brute) {
            (Ok(x), Ok(c), Ok(bf)) => {
                prop_assert!(x.path == ProjectionPath::Local || x.path == ProjectionPath::Fallback);
                prop_assert!(c.path == ProjectionPath::Certified || c.path == ProjectionPath::Fallback);
                // Valid: barycentrics on the triangle, the residual normal to Psi there,
                // and Newton on that face alone finds the same point.
                let bary = x.point.bary;
                prop_assert!(bary.iter().all(|&t| t >= 0.0) && (bary.iter().sum::<f64>() - 1.0).abs() < 1e-12);
                // A root up to BARY_EPS outside the triangle is clamped onto its edge, which
                // leaves a residual of that order.
                let r = fx.proj.psi(&x.point) * (y - fx.emb.point(&x.point));
                let tol = if bary.contains(&0.0) { wavg_project::BARY_EPS } else { 1e-6 };
                prop_assert!(r.norm() <= tol * (x.distance + fx.mean_edge), "{}: residual {} at {:?}", fx.name, r.norm(), x.point);
                let again = fx.proj.project_onto_face_with_distance(&y, x.point.face);
                prop_assert!(again.is_some_and(|(_, d)| (d - x.distance).abs() <= 1e-9 * (d + fx.mean_edge)));
                prop_assert!(x.distance >= bf.distance - 1e-9 * (bf.distance + fx.mean_edge));
                let same = (fx.emb.point(&c.point) - fx.emb.point(&bf.point)).norm() <= 1e-6 * fx.mean_edge;
                let tie = (c.distance - bf.distance).abs() <= 1e-9 * (bf.distance + fx.mean_edge);
                prop_assert!(same || tie, "{}: closest {:?} vs brute force {:?}", fx.name, c, bf);
            }
            (Err(ProjectError::NoProjection), Err(ProjectError::NoProjection), Err(ProjectError::NoProjection)) => {}
            _ => prop_assert!(false, "{}: {:?} / {:?} / {:?}", fx.name, first, closest, brute),
        }
    }

    /// `dPsi/dxi` is the derivative of `Psi` (central differences along the triangle).
    #[test]
    fn psi_derivative_matches_finite_differences(fx in fixture(), f in 0.0f64..1.0, a in 0.05f64..0.9, b in 0.05f64..0.9) {
        let fx = &fixtures()[fx];
        let p = fx.point(f, a, b);
        prop_assume!(p.bary.iter().all(|&x| x > 0.03));
        let d = fx.proj.psi_derivatives(&p);
        let h = 1e-6;
        for (i, j) in [(0, 2), (1, 2), (0, 1)] {
            let mut bp = p.bary;
            let mut bm = p.bary;
            bp[i] += h; bp[j] -= h;
            bm[i] -= h; bm[j] += h;
            let fd = (fx.proj.psi(&SurfacePoint::new(p.face, bp)) - fx.proj.psi(&SurfacePoint::new(p.face, bm))) / (2.0 * h);
            let an = d[i] - d[j];
            prop_assert!((fd - an).norm() < 1e-4 * (1.0 + an.norm()), "{}: {} vs {}", fx.name, fd, an);
        }
    }

    /// Psi's rows are close to orthonormal on these smooth meshes.
    #[test]
    fn psi_rows_are_near_orthonormal(fx in fixture(), f in 0.0f64..1.0, a in 0.0f64..1.0, b in 0.0f64..1.0) {
        let fx = &fixtures()[fx];
        let p = fx.point(f, a, b);
        let psi = fx.proj.psi(&p);
        let g = psi * psi.transpose();
        prop_assert!((g - nalgebra::Matrix2::identity()).norm() < 0.2, "{}: {}", fx.name, g);
    }
}

/// Property 2: on a flat patch (any linear embedding of a planar grid) Phong projection
/// equals Euclidean projection, also at boundary vertices.
#[test]
fn flat_patch_phong_equals_euclidean() {
    for e in [
        Embedding::Padded,
        Embedding::Linear(3),
        Embedding::Linear(11),
    ] {
        let fx = Fixture::new("flat", wavg_mesh::procedural::grid(7, 5, 1.4, 1.0), e);
        let mut n = 0;
        for k in 0..400u64 {
            let x = (k as f64 * 0.6180339887).fract();
            let y = (k as f64 * 0.7548776662).fract();
            let p = fx.point(x, y, (k as f64 * 0.5698402910).fract());
            let psi = fx.proj.psi(&p);
            let ey =
                fx.emb.point(&p) + normal_to(&psi, k) * (2.0 * fx.mean_edge * (k % 5) as f64 / 4.0);
            let ph = fx.proj.project(&ey, fx.vertex(0.37)).unwrap();
            let eu = fx.proj.project_euclidean(&ey);
            assert_eq!(eu.path, ProjectionPath::Euclidean);
            let d = (fx.emb.point(&ph.point) - fx.emb.point(&eu.point)).norm();
            assert!(
                d < 1e-6 * fx.mean_edge,
                "{e:?}: phong {ph:?} euclidean {eu:?}"
            );
            assert!((fx.emb.point(&ph.point) - fx.emb.point(&p)).norm() < 1e-6 * fx.mean_edge);
            n += 1;
        }
        assert_eq!(n, 400);
    }
}

/// The paper's Figure 3: along a straight segment inside a coarse sphere, crossing the
/// bisector of two faces, Euclidean projection jumps while Phong projection moves
/// continuously.
#[test]
fn segment_projects_continuously_with_phong_but_jumps_with_euclidean() {
    let fx = Fixture::new(
        "ico1",
        wavg_mesh::procedural::icosphere(1),
        Embedding::Padded,
    );
    for (face, e) in [(0u32, 0usize), (17, 1), (40, 2)] {
        let other = fx.mesh().topology().face_neighbors(face)[e];
        let ca = fx.emb.point(&SurfacePoint::new(face, [1.0 / 3.0; 3]));
        let cb = fx.emb.point(&SurfacePoint::new(other, [1.0 / 3.0; 3]));
        let centre =
            fx.emb.coords().iter().sum::<wavg_project::Vec8>() / fx.emb.coords().len() as f64;
        let steps = 400;
        let mut prev: Option<(wavg_project::Vec8, wavg_project::Vec8)> = None;
        let (mut max_phong, mut max_eucl) = (0.0f64, 0.0f64);
        for k in 0..=steps {
            let t = k as f64 / steps as f64;
            let on_seg = ca * (1.0 - t) + cb * t;
            let y = centre + (on_seg - centre) * 0.6;
            let ph = fx.proj.project(&y, 0).unwrap();
            let eu = fx.proj.project_euclidean(&y);
            let (pp, pe) = (fx.emb.point(&ph.point), fx.emb.point(&eu.point));
            if let Some((a, b)) = prev {
                max_phong = max_phong.max((pp - a).norm());
                max_eucl = max_eucl.max((pe - b).norm());
            }
            prev = Some((pp, pe));
        }
        let step = 0.6 * (cb - ca).norm() / steps as f64;
        eprintln!("{e:?}: max Phong jump {max_phong}, max Euclidean jump {max_eucl}, step {step}");
        assert!(
            max_phong < 3.0 * step,
            "{e:?}: Phong jumps by {max_phong} (step {step})"
        );
        assert!(
            max_eucl > 30.0 * step,
            "{e:?}: Euclidean does not jump ({max_eucl}, step {step})"
        );
    }
}

/// Results do not depend on the mesh's scale or position: a similarity applied to the
/// embedding (and the queries) gives the same surface points.
#[test]
fn scale_and_translation_invariance() {
    let base =
        wavg_mesh::procedural::with_noise(wavg_mesh::procedural::torus(24, 12, 1.0, 0.4), 0.01, 9);
    for e in EMBEDDINGS {
        let reference = Fixture::new("torus", base.clone(), e);
        let shift =
            wavg_project::Vec8::from_fn(|i, _| [300.0, -200.0, 50.0, 7.0, -1.0, 0.5, 2.0, -9.0][i]);
        for (s, t) in [(1e-3, 0.0), (1e3, 0.0), (1.0, 1.0), (1e-3, 1.0), (1e3, 1e3)] {
            let coords = reference
                .emb
                .coords()
                .iter()
                .map(|c| c * s + shift * t)
                .collect();
            let emb = std::sync::Arc::new(
                wavg_project::EmbeddedMesh::new(reference.emb.mesh().clone(), coords).unwrap(),
            );
            let moved = wavg_project::Projector::new(emb).unwrap();
            let mut compared = 0;
            for k in 0..300u64 {
                let p = reference.point(
                    (k as f64 * 0.618034).fract(),
                    (k as f64 * 0.7548777).fract(),
                    (k as f64 * 0.569840).fract(),
                );
                let start = reference.vertex((k as f64 * 0.3819660).fract());
                let dir = normal_to(&wavg_project::Mat2x8::zeros(), k);
                let y =
                    reference.emb.point(&p) + dir * (0.3 * reference.mean_edge * (k % 3) as f64);
                let (a, b) = (
                    reference.proj.project(&y, start),
                    moved.project(&(y * s + shift * t), start),
                );
                match (a, b) {
                    (Ok(a), Ok(b)) => {
                        let d =
                            (reference.emb.point(&a.point) - reference.emb.point(&b.point)).norm();
                        assert!(
                            d < 1e-6 * reference.mean_edge,
                            "{e:?} s={s} t={t}: {a:?} vs {b:?}"
                        );
                        assert!(
                            (a.distance * s - b.distance).abs() <= 1e-6 * s * reference.mean_edge
                        );
                        compared += 1;
                    }
                    (Err(x), Err(y)) => assert_eq!(x, y),
                    (a, b) => panic!("{e:?} s={s} t={t}: {a:?} vs {b:?}"),
                }
            }
            assert!(compared > 250);
        }
    }
}
