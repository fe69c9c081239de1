//! Long computations that Python can watch and stop: the work runs on a worker thread
//! without the GIL while the calling thread checks for signals (Ctrl-C) and feeds the
//! progress callable, about ten times a second. Python code is only ever called from the
//! calling thread.

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

/// Runs `work` on a worker thread; meanwhile calls `callback(stage, done, total)` when the
/// progress changes (a `False` return cancels) and checks for signals. A raised
/// exception (`KeyboardInterrupt` from Ctrl-C, or the callback's) cancels the work and is
/// raised once the worker has stopped.
pub(crate) fn watch<T: Send>(
    py: Python<'_>,
    callback: Option<&Bound<'_, PyAny>>,
    work: impl FnOnce(&Shared) -> T + Send,
) -> PyResult<T> {
    let shared = Shared::default();
    let mut raised: Option<PyErr> = None;
    let mut last = None;
    let out = std::thread::scope(|scope| {
        let s = &shared;
        let handle = scope.spawn(move || work(s));
        loop {
            let finished = py.detach(|| {
                let t = Instant::now();
                while !handle.is_finished() && t.elapsed() < POLL {
                    std::thread::sleep(Duration::from_millis(5));
                }
                handle.is_finished()
            });
            if raised.is_none() {
                if let Err(e) = py.check_signals() {
                    shared.cancel.store(true, Ordering::Relaxed);
                    raised = Some(e);
                }
            }
            if let (None, Some(cb)) = (&raised, callback) {
                let now = shared.state();
                if last != Some(now) {
                    last = Some(now);
                    match cb.call1(now) {
                        Ok(r) if r.is(&*pyo3::types::PyBool::new(py, false)) => {
                            shared.cancel.store(true, Ordering::Relaxed);
                        }
                        Ok(_) => {}
                        Err(e) => {
                            shared.cancel.store(true, Ordering::Relaxed);
                            raised = Some(e);
                        }
                    }
                }
            }
            if finished {
                break;
            }
        }
        handle.join()
    });
    if let Some(e) = raised {
        return Err(e);
    }
    out.map_err(|_| PyRuntimeError::new_err("wavg: internal error (a worker thread panicked)"))
}
