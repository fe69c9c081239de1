//! The dragged-remesh protocol (`wavg remesh --frames`): how long recomputing a
//! semiregular remeshing takes while one base vertex moves, as in an interactive editor.
//! The vertex goes once around a small circle (radius 2% of the surface's bounding-box
//! diagonal, in the x-y plane, starting at its base position), each frame's position put
//! on the surface first (not timed); each frame is one warm-started [`Remesher::remesh`].
//!
//! ```
//! use std::sync::Arc;
//! use wavg::apps::{BaseMesh, Remesher};
//! use wavg::{EmbeddedMesh, Projector, ValidMesh, mesh::procedural};
//! use wavg_bench::{DragOptions, drag_remesh};
//!
//! let mesh = Arc::new(ValidMesh::new(procedural::icosphere(3)).unwrap());
//! let proj = Arc::new(Projector::new(Arc::new(EmbeddedMesh::from_positions(mesh))).unwrap());
//! let base = BaseMesh::from_obj_str(
//!     "v 1 0 0\nv 0 1 0\nv -1 0 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n\
//!      f 1 2 5\nf 2 3 5\nf 3 4 5\nf 4 1 5\nf 2 1 6\nf 3 2 6\nf 4 3 6\nf 1 4 6\n",
//! ).unwrap();
//! let mut r = Remesher::new(proj, &base).unwrap();
//! let opts = DragOptions { vertex: 4, frames: 3, levels: 1, smooth: 1, cpu_clock: None };
//! let d = drag_remesh(&mut r, &base, &opts).unwrap();
//! assert!(d.median_s.unwrap() <= d.max_s.unwrap());
//! assert_eq!(d.cpu_s, None);
//! ```

use std::time::Instant;

use wavg::Vector3;
use wavg::apps::{BaseMesh, RemeshError, Remesher};

use crate::timing::{CpuClock, with_cpu};

/// Options of [`drag_remesh`].
#[derive(Clone, Copy, Debug)]
pub struct DragOptions {
    /// The base vertex dragged (an index into the base mesh's vertices).
    pub vertex: usize,
    /// Frames, each one recomputation; 0 measures nothing.
    pub frames: usize,
    /// Levels of splitting of each recomputation.
    pub levels: usize,
    /// Smoothing steps of each recomputation.
    pub smooth: usize,
    /// A process CPU-time clock; when given, [`DragReport::cpu_s`] is filled in.
    pub cpu_clock: Option<CpuClock>,
}

/// Times of the dragged frames, in seconds; all `None` without frames.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DragReport {
    /// Median wall time of a frame.
    pub median_s: Option<f64>,
    /// Largest wall time of a frame.
    pub max_s: Option<f64>,
    /// Mean CPU time of the whole process (all threads) per frame; `None` without a clock.
    pub cpu_s: Option<f64>,
}

/// A frame that failed: its number (counted from 1) and the remesher's error.
#[derive(Debug)]
pub struct DragError {
    /// The frame, counted from 1.
    pub frame: usize,
    /// What the remesher reported.
    pub error: RemeshError,
}

/// Drags base vertex `opts.vertex` of `base` (the base mesh `r` was built from) over
/// `opts.frames` frames, recomputing warm each time. Leaves `r` at the last frame.
/// Errors when a frame cannot be recomputed (an out-of-range vertex included).
pub fn drag_remesh(
    r: &mut Remesher,
    base: &BaseMesh,
    opts: &DragOptions,
) -> Result<DragReport, DragError> {
    if opts.frames == 0 {
        return Ok(DragReport::default());
    }
    let fail = |frame, error| DragError { frame, error };
    let start = *base.positions.get(opts.vertex).ok_or_else(|| {
        let count = base.positions.len();
        fail(
            1,
            RemeshError::VertexOutOfRange {
                vertex: opts.vertex,
                count,
            },
        )
    })?;
    let radius = 0.02 * r.diagonal();
    let mut times = Vec::with_capacity(opts.frames);
    let mut cpu = Some(0.0);
    for k in 0..opts.frames {
        let a = std::f64::consts::TAU * (k + 1) as f64 / opts.frames as f64;
        let target = start + radius * Vector3::new(a.cos() - 1.0, a.sin(), 0.0);
        let (p, _) = r.closest_point(&target);
        let t = Instant::now();
        let (done, c) = with_cpu(opts.cpu_clock, || {
            r.move_base_vertex(opts.vertex, p)
                .and_then(|()| r.remesh(opts.levels, opts.smooth))
        });
        done.map_err(|e| fail(k + 1, e))?;
        times.push(t.elapsed().as_secs_f64());
        cpu = cpu.zip(c).map(|(sum, c)| sum + c);
    }
    let max = times.iter().copied().fold(0.0, f64::max);
    times.sort_by(f64::total_cmp);
    Ok(DragReport {
        median_s: Some(times[times.len() / 2]),
        max_s: Some(max),
        cpu_s: cpu.map(|c| c / opts.frames as f64),
    })
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use wavg::{EmbeddedMesh, Projector, ValidMesh, mesh::procedural};

    use super::*;

    fn octahedron_on_sphere() -> (Remesher, BaseMesh) {
        let mesh = Arc::new(ValidMesh::new(procedural::icosphere(3)).unwrap());
        let proj = Arc::new(Projector::new(Arc::new(EmbeddedMesh::from_positions(mesh))).unwrap());
        let base = BaseMesh::from_obj_str(
            "v 1 0 0\nv 0 1 0\nv -1 0 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n\
             f 1 2 5\nf 2 3 5\nf 3 4 5\nf 4 1 5\nf 2 1 6\nf 3 2 6\nf 4 3 6\nf 1 4 6\n",
        )
        .unwrap();
        (Remesher::new(proj, &base).unwrap(), base)
    }

    #[test]
    fn no_frames_measure_nothing_and_a_missing_vertex_fails_frame_one() {
        let (mut r, base) = octahedron_on_sphere();
        let opts = DragOptions {
            vertex: 6,
            frames: 0,
            levels: 1,
            smooth: 0,
            cpu_clock: None,
        };
        assert_eq!(
            drag_remesh(&mut r, &base, &opts).unwrap(),
            DragReport::default()
        );
        let e = drag_remesh(&mut r, &base, &DragOptions { frames: 2, ..opts }).unwrap_err();
        assert_eq!(e.frame, 1);
        assert!(matches!(
            e.error,
            RemeshError::VertexOutOfRange {
                vertex: 6,
                count: 6
            }
        ));
    }

    #[test]
    fn a_clock_gives_the_cpu_time_per_frame() {
        let (mut r, base) = octahedron_on_sphere();
        let opts = DragOptions {
            vertex: 0,
            frames: 4,
            levels: 2,
            smooth: 1,
            cpu_clock: Some(|| Some(1.0)),
        };
        let d = drag_remesh(&mut r, &base, &opts).unwrap();
        assert_eq!(d.cpu_s, Some(0.0), "a clock that stands still");
        assert!(d.median_s.unwrap() > 0.0 && d.median_s <= d.max_s);
    }
}
