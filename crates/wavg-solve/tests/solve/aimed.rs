//! The aimed warm start (`Solver::forward_aimed`): only the route of the search changes.

use crate::common;

use common::solver_on;

use wavg_mesh::{SurfacePoint, procedural};
use wavg_solve::sampling::uniform_surface_points;
use wavg_solve::{ForwardOptions, Normalization, SearchMode, Vec8};

/// An aim changes only the route of the warm start: with any aim the answer is a root of
/// Newton's method on its face (a valid projection of the average), a non-finite aim
/// gives the same answer as none, and aiming at the closest projection from a warm start
/// two faces away finds it.
#[test]
fn aimed_forward_problems_return_valid_projections() {
    let s = solver_on(procedural::bump_sphere(3, 0.3), 12, 3);
    let pts = uniform_surface_points(s.mesh(), 200, 5).unwrap();
    let (emb, topo) = (s.projector().embedded().clone(), s.mesh().topology());
    let closest = ForwardOptions {
        mode: SearchMode::Certified,
        ..ForwardOptions::default()
    };
    let mut found = 0;
    for (i, p) in pts.iter().enumerate() {
        let w = s.inverse(p).unwrap();
        let ybar = s.average(&w, Normalization::Reject).unwrap();
        let want = s.forward(&w, &closest).unwrap();
        let mut g = want.point.face;
        for _ in 0..2 {
            g = topo
                .face_neighbors(g)
                .into_iter()
                .find(|&x| x != u32::MAX)
                .unwrap();
        }
        let o = ForwardOptions::default().warm(SurfacePoint::new(g, [1.0 / 3.0; 3]));
        let at = emb.point(&want.point);
        let elsewhere = emb.point(&pts[(i + 100) % pts.len()]);
        let nan = Vec8::repeat(f64::NAN);
        for aim in [Some(&at), Some(&elsewhere), Some(&nan), None] {
            let r = s.forward_aimed(&w, &o, aim).unwrap();
            let (xi, d) = s
                .projector()
                .project_onto_face_or_exit(&ybar, r.point.face)
                .unwrap();
            assert_eq!((xi, d), (r.point.bary, r.distance), "query {i}");
        }
        assert_eq!(
            s.forward_aimed(&w, &o, Some(&nan)),
            s.forward_aimed(&w, &o, None)
        );
        let r = s.forward_aimed(&w, &o, Some(&at)).unwrap();
        found += usize::from(r.point.face == want.point.face);
    }
    assert!(found >= 190, "{found} of 200");
}
