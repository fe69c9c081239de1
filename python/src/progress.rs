//! Long computations that Python can watch and stop: the work runs on a worker thread
//! without the GIL while the calling thread checks for signals (Ctrl-C) and calls the
//! progress callable at the start, at every change of stage and about ten times a second in
//! between, so every stage is seen however short. Python code is only ever called from the
//! calling thread. A cancelled call returns at once: the worker owns its inputs and stops at
//! its next checkpoint in the background (a long sparse factorization has none), its result
//! dropped.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::{Duration, Instant};

use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use wavg::{Progress, Stage};

/// How often the calling thread looks at signals and progress.
const POLL: Duration = Duration::from_millis(100);

/// The stages, in the order of their codes.
const STAGES: [Stage; 5] = Stage::ALL;

/// Steps of a stage reported to Python (`done` out of this `total`).
pub(crate) const TOTAL: u64 = 1000;

/// Each stage's latest fraction (as `f64` bits) and the stop flag, shared with the worker.
/// Some stages run alongside others (the quality check's fast marching with the
/// decimation, the least-squares factorization with the geodesics), so the stage shown is
/// the first one in pipeline order that has not finished.
#[derive(Default)]
pub(crate) struct Shared {
    fractions: [AtomicU64; 5],
    cancel: AtomicBool,
}

impl Progress for Shared {
    fn report(&self, stage: Stage, fraction: f64) {
        let code = STAGES.iter().position(|s| *s == stage).unwrap_or(0);
        self.fractions[code].store(fraction.clamp(0.0, 1.0).to_bits(), Ordering::Relaxed);
    }

    fn cancelled(&self) -> bool {
        self.cancel.load(Ordering::Relaxed)
    }
}

impl Shared {
    /// The stage shown now (an index into [`STAGES`], 5 when all have finished) and its
    /// fraction.
    fn current(&self) -> (usize, f64) {
        (0..STAGES.len())
            .map(|i| (i, f64::from_bits(self.fractions[i].load(Ordering::Relaxed))))
            .find(|&(_, f)| f < 1.0)
            .unwrap_or((STAGES.len(), 1.0))
    }

    /// The calls owed to the callable: `(stage, total, total)` for each stage finished since
    /// the last calls (`shown` counts the stages already shown as finished), then the current
    /// `(stage, done, total)`. `finished`: the work has succeeded, so every stage has finished.
    fn calls(&self, shown: &mut usize, finished: bool) -> Vec<(&'static str, u64, u64)> {
        let (current, f) = if finished {
            (STAGES.len(), 1.0)
        } else {
            self.current()
        };
        let mut calls: Vec<_> = (*shown..current)
            .map(|i| (STAGES[i].name(), TOTAL, TOTAL))
            .collect();
        *shown = current.max(*shown);
        if let Some(stage) = STAGES.get(current) {
            calls.push((stage.name(), (f * TOTAL as f64).round() as u64, TOTAL));
        }
        calls
    }
}

/// Calls `callback` with each of `calls`; `Ok(false)` when one answered a false value
/// other than `None` (`False`, NumPy's `False_` from a comparison, 0; the later calls are
/// not made), the callable's exception (or its answer's, judged as a bool) as the error. A
/// callable that returns nothing goes on.
fn tell(callback: &Bound<'_, PyAny>, calls: Vec<(&'static str, u64, u64)>) -> PyResult<bool> {
    for args in calls {
        let answer = callback.call1(args)?;
        if !answer.is_none() && !answer.is_truthy()? {
            return Ok(false);
        }
    }
    Ok(true)
}

/// Runs `work` on a worker thread; meanwhile checks for signals and calls
/// `callback(stage, done, total)` at once, at every new stage (each stage is shown, however
/// short) and at every poll. A `False` answer (`CancelledError`) or a raised exception
/// (`KeyboardInterrupt` from Ctrl-C, or the callable's) cancels the work and is raised at
/// once; the worker is left to stop at its next checkpoint. `succeeded` tells whether the
/// result means every stage ran (the last call then shows them all finished).
pub(crate) fn watch<T: Send + 'static>(
    py: Python<'_>,
    callback: Option<&Bound<'_, PyAny>>,
    work: impl FnOnce(&Shared) -> T + Send + 'static,
    succeeded: impl FnOnce(&T) -> bool,
) -> PyResult<T> {
    let shared = Arc::new(Shared::default());
    let s = Arc::clone(&shared);
    let handle = std::thread::Builder::new()
        .name("wavg-watched".into())
        .spawn(move || crate::pool::run(|| work(&s)))
        .map_err(|e| PyRuntimeError::new_err(format!("wavg: cannot start a thread: {e}")))?;
    let mut shown = 0;
    let mut first = true;
    loop {
        let finished = !first
            && py.detach(|| {
                let t = Instant::now();
                let stage = shared.current().0;
                while !handle.is_finished() && t.elapsed() < POLL && shared.current().0 == stage {
                    std::thread::sleep(Duration::from_millis(5));
                }
                handle.is_finished()
            });
        first = false;
        if finished {
            break;
        }
        let stop = py.check_signals().err().or_else(|| {
            match tell(callback?, shared.calls(&mut shown, false)) {
                Ok(true) => None,
                Ok(false) => Some(crate::errors::cancelled(py)),
                Err(e) => Some(e),
            }
        });
        if let Some(e) = stop {
            shared.cancel.store(true, Ordering::Relaxed);
            return Err(e);
        }
    }
    let result = handle
        .join()
        .map_err(|_| PyRuntimeError::new_err("wavg: internal error (a worker thread panicked)"))?;
    if let Some(cb) = callback {
        // The work has ended (every stage has when it succeeded): a false answer now cancels
        // nothing.
        tell(cb, shared.calls(&mut shown, succeeded(&result)))?;
    }
    Ok(result)
}
