//! The benchmark protocols behind `wavg bench`, in one place outside the library.
//!
//! Each protocol samples its queries (seeded), runs the timing loop and returns a report
//! that serialises (`serde::Serialize`) to the keys of the matching `wavg bench ... --json`
//! (the CLI adds the mesh argument and, for the spline, the load average); fields marked
//! "not serialised" are extra figures of the text output.
//!
//! * [`projection_bench`]: Phong projection speed and accuracy (`wavg bench project`).
//! * [`round_trip`] / [`round_trip_at`]: the paper's Table 1 round-trip protocol
//!   (`wavg bench roundtrip`, and the round trips of `wavg demo`).
//! * [`spline_bench`]: time per sample of a curve on the surface, checked against the
//!   closest valid projections (`wavg bench spline`).
//! * [`load_bench`]: reading, parsing and validating a mesh file (`wavg bench load`).
//! * [`drag_remesh`]: recomputing a remeshing while a base vertex is dragged (`wavg remesh
//!   --frames`).
//!
//! The library (the `wavg` facade and its inner crates) exports no benchmark: the round
//! trip and projection protocols were `wavg::round_trip`, `wavg::projection_bench` and
//! their option and report types, and are here under the same names. The crate uses the
//! facade alone, is not published, and its clocks are the caller's: CPU-time clocks are
//! plain function pointers ([`CpuClock`]), since the standard library has none.
//!
//! ```
//! use wavg::{Anchor, EmbeddedMesh, Projector, Solver, ValidMesh, mesh::procedural};
//! use wavg::sampling::{FpsMetric, farthest_point_vertices};
//! use wavg_bench::{RoundTripOptions, round_trip};
//! use std::sync::Arc;
//!
//! let mesh = Arc::new(ValidMesh::new(procedural::icosphere(2)).unwrap());
//! let proj = Arc::new(Projector::new(Arc::new(EmbeddedMesh::from_positions(mesh.clone()))).unwrap());
//! let anchors = farthest_point_vertices(&mesh, 12, 0, FpsMetric::EdgeGraph).unwrap();
//! let solver = Solver::new(proj, anchors.into_iter().map(Anchor::Vertex)).unwrap();
//! let report = round_trip(&solver, &RoundTripOptions { queries: 50, repeat: 1, ..Default::default() }).unwrap();
//! assert!(report.roundtrip_ok_fraction > 0.9);
//! ```

#![deny(unreachable_pub)]
#![forbid(unsafe_code)]

pub mod drag;
pub mod load;
pub mod projection;
pub mod roundtrip;
pub mod spline;
mod timing;

pub use drag::{DragError, DragOptions, DragReport, drag_remesh};
pub use load::{LoadBenchReport, load_bench};
pub use projection::{ProjectionBenchOptions, ProjectionBenchReport, projection_bench};
pub use roundtrip::{
    RoundTripOptions, RoundTripReport, VerifiedRoundTripReport, round_trip, round_trip_at,
};
pub use spline::{SplineBenchOptions, SplineBenchReport, spline_bench};
pub use timing::{CpuClock, load_average};
