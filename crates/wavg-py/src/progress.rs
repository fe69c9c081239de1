//! Long computations that Python can watch and stop: the work runs on a worker thread
//! without the GIL while the calling thread checks for signals (Ctrl-C) and calls the
//! progress callable, about ten times a second. Python code is only ever called from the
//! calling thread. A cancelled call returns at once: the worker owns its inputs and stops at
//! its next checkpoint in the background (a long sparse factorization has none), its result
//! dropped.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU8, AtomicU64, Ordering};
use std::time::{Duration, Instant};

use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use wavg::{Progress, Stage};

/// How often the calling thread looks at signals and progress.
const POLL: Duration = Duration::from_millis(100);

/// The stages, in the order of their codes.
const STAGES: [Stage; 5] = [
    Stage::Decimate,
    Stage::Geodesics,
    Stage::Mds,
    Stage::LsMesh,
    Stage::Quality,
];

/// Steps of a stage reported to Python (`done` out of this `total`).
pub(crate) const TOTAL: u64 = 1000;

/// The latest progress and the stop flag, shared with the worker.
#[derive(Default)]
pub(crate) struct Shared {
    stage: AtomicU8,
    fraction: AtomicU64,
    cancel: AtomicBool,
}

impl Progress for Shared {
    fn report(&self, stage: Stage, fraction: f64) {
        let code = STAGES.iter().position(|s| *s == stage).unwrap_or(0) as u8;
        self.stage.store(code, Ordering::Relaxed);
        self.fraction
            .store(fraction.clamp(0.0, 1.0).to_bits(), Ordering::Relaxed);
    }

    fn cancelled(&self) -> bool {
        self.cancel.load(Ordering::Relaxed)
    }
}

impl Shared {
    /// `(stage name, done, total)` now.
    fn state(&self) -> (&'static str, u64, u64) {
        let stage = STAGES[usize::from(self.stage.load(Ordering::Relaxed)).min(4)];
        let f = f64::from_bits(self.fraction.load(Ordering::Relaxed));
        (stage.name(), (f * TOTAL as f64).round() as u64, TOTAL)
    }
}

/// Runs `work` on a worker thread; meanwhile calls `callback(stage, done, total)` at every
/// poll (a `False` return cancels: `CancelledError`) and checks for signals. A raised
/// exception (`KeyboardInterrupt` from Ctrl-C, or the callback's) cancels the work and is
/// raised at once; the worker is left to stop at its next checkpoint.
pub(crate) fn watch<T: Send + 'static>(
    py: Python<'_>,
    callback: Option<&Bound<'_, PyAny>>,
    work: impl FnOnce(&Shared) -> T + Send + 'static,
) -> PyResult<T> {
    let shared = Arc::new(Shared::default());
    let s = Arc::clone(&shared);
    let handle = std::thread::Builder::new()
        .name("wavg-watched".into())
        .spawn(move || crate::args::run(|| work(&s)))
        .map_err(|e| PyRuntimeError::new_err(format!("wavg: cannot start a thread: {e}")))?;
    loop {
        let finished = py.detach(|| {
            let t = Instant::now();
            while !handle.is_finished() && t.elapsed() < POLL {
                std::thread::sleep(Duration::from_millis(5));
            }
            handle.is_finished()
        });
        if finished {
            break;
        }
        let stop = py.check_signals().err().or_else(|| {
            let cb = callback?;
            match cb.call1(shared.state()) {
                Ok(r) if r.is(&*pyo3::types::PyBool::new(py, false)) => {
                    Some(crate::errors::cancelled(py))
                }
                Ok(_) => None,
                Err(e) => Some(e),
            }
        });
        if let Some(e) = stop {
            shared.cancel.store(true, Ordering::Relaxed);
            return Err(e);
        }
    }
    if let Some(cb) = callback {
        cb.call1(shared.state())?;
    }
    handle
        .join()
        .map_err(|_| PyRuntimeError::new_err("wavg: internal error (a worker thread panicked)"))
}
