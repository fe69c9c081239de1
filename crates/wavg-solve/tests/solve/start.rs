//! Where the forward problem starts its walk.

use crate::common;

use common::solver_on;
use wavg_mesh::procedural;
use wavg_solve::sampling::uniform_surface_points;
use wavg_solve::{ForwardOptions, Normalization, SearchMode, Start};

/// The forward problem may start from a vertex near the average instead of the
/// highest-weight anchor's start vertex: with the certified search that changes only the
/// work, never the answer, which is the exhaustive search's.
#[test]
fn located_start_does_not_change_certified_answers() {
    let s = solver_on(procedural::icosphere(5), 8, 3);
    let certified = ForwardOptions {
        mode: SearchMode::Certified,
        ..Default::default()
    };
    let exact = ForwardOptions {
        mode: SearchMode::Exact,
        ..Default::default()
    };
    let mut located = 0;
    for p in uniform_surface_points(s.mesh(), 300, 11).unwrap() {
        let w = s.inverse(&p).unwrap();
        let r = s.forward(&w, &certified).unwrap();
        let (anchor, from) = match r.start {
            Start::Located { anchor, vertex } => {
                located += 1;
                assert_ne!(vertex, s.anchors().start_vertex(anchor).unwrap());
                (anchor, vertex)
            }
            Start::HighestWeight { anchor, vertex } => (anchor, vertex),
            other => panic!("unexpected start {other:?}"),
        };
        assert!(w.iter().all(|&x| x <= w[anchor]));
        // From the anchor's own start vertex: the same projection.
        let ybar = s.average(&w, Normalization::Reject).unwrap();
        let anchor_start = s.anchors().start_vertex(anchor).unwrap();
        let own = s.projector().project(&ybar, anchor_start).unwrap();
        assert_eq!(own.point, r.point, "from {from} and from {anchor_start}");
        let e = s.forward(&w, &exact).unwrap();
        assert_eq!(e.point.face, r.point.face);
        for k in 0..3 {
            assert!((e.point.bary[k] - r.point.bary[k]).abs() < 1e-9);
        }
    }
    assert!(
        located > 100,
        "{located} of 300 started from a located vertex"
    );
}
