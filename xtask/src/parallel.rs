//! Independent jobs of one step, a few at a time: the installed-artifact checks spend most
//! of their wall time in one single-threaded process each (pip unpacking, a Python test
//! run, Blender starting), so on the 2-core machine two side by side take about half the
//! wall time of one after the other.

use std::sync::Mutex;

/// Runs `job` on every item, at most `width` at once, in the items' order; once a job has
/// failed no further one starts. Returns the error of the first failed item (in the items'
/// order), else `Ok`.
pub fn run<T: Sync>(
    items: &[T],
    width: usize,
    job: impl Fn(&T) -> Result<(), String> + Sync,
) -> Result<(), String> {
    let next = Mutex::new(0usize);
    let errors: Mutex<Vec<(usize, String)>> = Mutex::new(Vec::new());
    let take = || {
        let failed = !lock(&errors).is_empty();
        let mut n = lock(&next);
        (!failed && *n < items.len()).then(|| {
            *n += 1;
            *n - 1
        })
    };
    std::thread::scope(|scope| {
        for _ in 0..width.clamp(1, items.len().max(1)) {
            scope.spawn(|| {
                while let Some(i) = take() {
                    if let Err(e) = job(&items[i]) {
                        lock(&errors).push((i, e));
                    }
                }
            });
        }
    });
    let mut errors = errors.into_inner().unwrap_or_else(|e| e.into_inner());
    errors.sort_by_key(|(i, _)| *i);
    match errors.into_iter().next() {
        Some((_, e)) => Err(e),
        None => Ok(()),
    }
}

/// The guarded value, also after a job panicked while holding it.
fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::time::{Duration, Instant};

    #[test]
    fn jobs_run_side_by_side_but_never_more_than_the_width() {
        let (running, most, done) = (
            AtomicUsize::new(0),
            AtomicUsize::new(0),
            AtomicUsize::new(0),
        );
        let t = Instant::now();
        let items = [1, 2, 3, 4, 5, 6];
        run(&items, 2, |_| {
            let now = running.fetch_add(1, Ordering::SeqCst) + 1;
            most.fetch_max(now, Ordering::SeqCst);
            std::thread::sleep(Duration::from_millis(150));
            running.fetch_sub(1, Ordering::SeqCst);
            done.fetch_add(1, Ordering::SeqCst);
            Ok(())
        })
        .unwrap();
        assert_eq!(done.load(Ordering::SeqCst), 6);
        assert_eq!(most.load(Ordering::SeqCst), 2);
        let wall = t.elapsed();
        assert!(wall >= Duration::from_millis(440), "{wall:?}");
        assert!(
            wall < Duration::from_millis(880),
            "not side by side: {wall:?}"
        );
    }

    #[test]
    fn the_first_failure_in_order_is_returned_and_stops_what_has_not_started() {
        let started = AtomicUsize::new(0);
        let items: Vec<usize> = (0..20).collect();
        let result = run(&items, 2, |&i| {
            started.fetch_add(1, Ordering::SeqCst);
            std::thread::sleep(Duration::from_millis(if i == 1 { 10 } else { 60 }));
            match i {
                0 | 1 => Err(format!("job {i}")),
                _ => Ok(()),
            }
        });
        assert_eq!(result, Err("job 0".to_string()));
        assert!(started.load(Ordering::SeqCst) <= 3, "{started:?}");
        // One job, or none, runs alone.
        assert_eq!(run(&[7], 4, |_| Ok(())), Ok(()));
        assert_eq!(run(&[] as &[u8], 2, |_| Err("never".into())), Ok(()));
    }
}
