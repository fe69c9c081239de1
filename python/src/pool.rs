//! Where the library's work of a call runs. rayon's pools do not survive `fork()`: a child
//! forked after the import (`multiprocessing`'s fork start method, the default on Linux
//! before Python 3.14; `multiprocessing.Pool`, joblib's multiprocessing backend) inherits
//! their memory but none of their threads, so work handed to them there waits forever. In
//! the importing process a call's work runs on the calling thread, on the library's pools
//! as usual; in any other process on a pool made there (remembered with that process's
//! id), whose threads start with no pool cached, so every pool the work asks for is alive.
//! Every call reaches the library through [`run`] (most through [`DetachRun`]).

use std::sync::{Arc, Mutex, OnceLock, TryLockError};
use std::time::{Duration, Instant};

use pyo3::Python;

/// The process that imported the module.
static IMPORT_PID: OnceLock<u32> = OnceLock::new();

/// The pool of a process other than the importing one, with that process's id.
static CHILD_POOL: Mutex<Option<(u32, Arc<rayon::ThreadPool>)>> = Mutex::new(None);

/// How long [`run`] waits for another thread's hold on the pool's slot before it makes a
/// pool of its own for the call (the slot's lock may have been copied, held, by a fork).
const LOCK_WAIT: Duration = Duration::from_millis(100);

/// Records the importing process, once.
pub(crate) fn remember_pid() {
    IMPORT_PID.get_or_init(std::process::id);
}

/// Runs `f`, the library's work of one call, on live threads: on the calling thread in
/// the importing process, on this process's own pool in a forked child.
pub(crate) fn run<T: Send>(f: impl FnOnce() -> T + Send) -> T {
    let pid = std::process::id();
    if IMPORT_PID.get().is_none_or(|&p| p == pid) {
        return f();
    }
    match child_pool(pid) {
        Some(pool) => pool.install(f),
        // No thread could start: the calling thread is alive at least.
        None => f(),
    }
}

/// This process's pool, made on first use.
fn child_pool(pid: u32) -> Option<Arc<rayon::ThreadPool>> {
    let start = Instant::now();
    let mut slot = loop {
        match CHILD_POOL.try_lock() {
            Ok(slot) => break slot,
            Err(TryLockError::Poisoned(e)) => break e.into_inner(),
            Err(TryLockError::WouldBlock) if start.elapsed() < LOCK_WAIT => {
                std::thread::yield_now();
            }
            // Held by a thread of the process this one was forked from: a pool for this
            // call alone.
            Err(TryLockError::WouldBlock) => return new_pool().map(Arc::new),
        }
    };
    match slot.as_ref() {
        Some((p, pool)) if *p == pid => return Some(pool.clone()),
        // The pool of the process this one was forked from: its threads are not here, and
        // dropping it would signal them through locks they may hold. Leaked.
        Some(_) => std::mem::forget(slot.take()),
        None => {}
    }
    let pool = Arc::new(new_pool()?);
    *slot = Some((pid, pool.clone()));
    Some(pool)
}

/// A pool of as many threads as rayon's global one would have (`RAYON_NUM_THREADS`, else
/// one per CPU).
fn new_pool() -> Option<rayon::ThreadPool> {
    rayon::ThreadPoolBuilder::new()
        .thread_name(|i| format!("wavg-{i}"))
        .build()
        .ok()
}

/// [`Python::detach`] for the library's work: without the GIL, through [`run`].
pub(crate) trait DetachRun {
    /// Runs `f` without the GIL, on live threads.
    fn detach_run<T: Send>(self, f: impl FnOnce() -> T + Send) -> T;
}

impl DetachRun for Python<'_> {
    fn detach_run<T: Send>(self, f: impl FnOnce() -> T + Send) -> T {
        self.detach(|| run(f))
    }
}
