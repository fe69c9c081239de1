//! How a batch runs: one choice of parallelism shared by every batch of the workspace (the
//! projector's and the solver's), after faer's `Par`.

use std::cell::RefCell;
use std::num::NonZeroUsize;
use std::sync::Arc;

use rayon::prelude::*;

use crate::ProjectError;

/// The parallelism of a batch. Batches are independent per query, so the choice changes
/// only the speed, never a result.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Par {
    /// On the calling thread only.
    Seq,
    /// On the current rayon pool: the global one, or the pool the caller runs in.
    #[default]
    Rayon,
    /// On a pool of this many threads. The pool is built on first use and kept, per
    /// calling thread, for the next call with the same count.
    Threads(NonZeroUsize),
}

impl Par {
    /// From an optional thread count, as a command line takes it: `None` is
    /// [`Par::Rayon`], `Some(1)` is [`Par::Seq`], `Some(n)` is [`Par::Threads`]; zero is
    /// [`ProjectError::InvalidThreads`].
    ///
    /// ```
    /// use wavg_project::Par;
    /// assert_eq!(Par::from_threads(None), Ok(Par::Rayon));
    /// assert_eq!(Par::from_threads(Some(1)), Ok(Par::Seq));
    /// assert!(Par::from_threads(Some(0)).is_err());
    /// assert_eq!(Par::from_threads(Some(3)).unwrap().install(rayon::current_num_threads), Ok(3));
    /// ```
    pub fn from_threads(threads: Option<usize>) -> Result<Self, ProjectError> {
        match threads {
            None => Ok(Par::Rayon),
            Some(0) => Err(ProjectError::InvalidThreads),
            Some(1) => Ok(Par::Seq),
            Some(n) => Ok(NonZeroUsize::new(n).map_or(Par::Seq, Par::Threads)),
        }
    }

    /// The most threads worth asking for: 4 per CPU this process may use, and at least 64.
    /// Far more threads than cores only add overhead (thousands of them take seconds to
    /// start and to hand work to); the command line and Python refuse more.
    ///
    /// ```
    /// assert!(wavg_project::Par::max_threads() >= 64);
    /// ```
    pub fn max_threads() -> usize {
        let cpus = std::thread::available_parallelism().map_or(1, |n| n.get());
        (4 * cpus).max(64)
    }

    /// Runs `f` with this parallelism: rayon's parallel iterators inside `f` use one
    /// thread ([`Par::Seq`]), the current pool ([`Par::Rayon`]) or `n` threads
    /// ([`Par::Threads`]). [`ProjectError::ThreadPool`] when the threads cannot start.
    pub fn install<T: Send>(self, f: impl FnOnce() -> T + Send) -> Result<T, ProjectError> {
        let n = match self {
            Par::Rayon => return Ok(f()),
            Par::Seq => 1,
            Par::Threads(n) => n.get(),
        };
        if rayon::current_thread_index().is_some() && rayon::current_num_threads() == n {
            return Ok(f());
        }
        Ok(pool(n)?.install(f))
    }

    /// Sorts `v` (unstable; ties keep no order, so give the items distinct keys), in
    /// parallel unless [`Par::Seq`].
    pub fn sort<T: Ord + Send>(self, v: &mut [T]) -> Result<(), ProjectError> {
        match self {
            Par::Seq => {
                v.sort_unstable();
                Ok(())
            }
            _ => self.install(|| v.par_sort_unstable()),
        }
    }

    /// Appends `f(chunk)` for every chunk of `chunk` items of `items` to `out`, in order:
    /// the chunks run in parallel unless [`Par::Seq`], which runs them on the calling
    /// thread. The one way batches of this workspace spread work over threads.
    pub fn map_chunks<I: Sync, T: Send>(
        self,
        items: &[I],
        chunk: usize,
        out: &mut Vec<T>,
        f: impl Fn(&[I]) -> Vec<T> + Sync + Send,
    ) -> Result<(), ProjectError> {
        let chunk = chunk.max(1);
        match self {
            Par::Seq => {
                out.extend(items.chunks(chunk).flat_map(f));
                Ok(())
            }
            _ => self.install(|| out.par_extend(items.par_chunks(chunk).flat_map_iter(f))),
        }
    }

    /// `out` becomes `[f(0), f(1), .., f(n - 1)]`, computed in parallel (runs of at least
    /// `min_len` indices per task) unless [`Par::Seq`]. Written in place, no intermediate
    /// lists.
    pub fn map_range<T: Send>(
        self,
        n: usize,
        min_len: usize,
        out: &mut Vec<T>,
        f: impl Fn(usize) -> T + Sync + Send,
    ) -> Result<(), ProjectError> {
        match self {
            Par::Seq => {
                out.clear();
                out.extend((0..n).map(f));
                Ok(())
            }
            _ => self.install(|| {
                (0..n)
                    .into_par_iter()
                    .with_min_len(min_len.max(1))
                    .map(f)
                    .collect_into_vec(out)
            }),
        }
    }

    /// [`Par::map_chunks`] over `items` and, in step, the chunks of `chunk_a` items of
    /// `a` that `f` may write (the rows a chunk of queries fills in place).
    pub fn zip_chunks_mut<A: Send, I: Sync, T: Send>(
        self,
        a: &mut [A],
        chunk_a: usize,
        items: &[I],
        chunk: usize,
        out: &mut Vec<T>,
        f: impl Fn(&mut [A], &[I]) -> Vec<T> + Sync + Send,
    ) -> Result<(), ProjectError> {
        let (chunk_a, chunk) = (chunk_a.max(1), chunk.max(1));
        match self {
            Par::Seq => {
                let pairs = a.chunks_mut(chunk_a).zip(items.chunks(chunk));
                out.extend(pairs.flat_map(|(a, i)| f(a, i)));
                Ok(())
            }
            _ => self.install(|| {
                let pairs = a.par_chunks_mut(chunk_a).zip(items.par_chunks(chunk));
                out.par_extend(pairs.flat_map_iter(|(a, i)| f(a, i)))
            }),
        }
    }
}

thread_local! {
    /// The last pool built on this thread, with its size.
    static POOL: RefCell<Option<(usize, Arc<rayon::ThreadPool>)>> = const { RefCell::new(None) };
}

/// A pool of `n` threads, reused when this thread asked for the same size last time.
fn pool(n: usize) -> Result<Arc<rayon::ThreadPool>, ProjectError> {
    POOL.with(|cell| {
        let mut cell = cell.borrow_mut();
        if let Some((m, p)) = cell.as_ref()
            && *m == n
        {
            return Ok(p.clone());
        }
        let p = rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .map_err(|e| ProjectError::ThreadPool(format!("cannot start {n} threads: {e}")))?;
        let p = Arc::new(p);
        *cell = Some((n, p.clone()));
        Ok(p)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn install_runs_on_the_requested_number_of_threads() {
        assert_eq!(Par::Seq.install(rayon::current_num_threads), Ok(1));
        let two = Par::Threads(NonZeroUsize::new(2).unwrap());
        assert_eq!(two.install(rayon::current_num_threads), Ok(2));
        // Nested: the same size runs in place.
        assert_eq!(
            two.install(|| two.install(rayon::current_num_threads)),
            Ok(Ok(2))
        );
        assert_eq!(
            Par::Rayon.install(rayon::current_num_threads),
            Ok(rayon::current_num_threads())
        );
    }

    #[test]
    fn chunks_and_sorts_agree_for_every_parallelism() {
        let items: Vec<u32> = (0..1000).map(|i| (i * 7919) % 1009).collect();
        let three = Par::Threads(NonZeroUsize::new(3).unwrap());
        let mut want = None;
        for par in [Par::Seq, Par::Rayon, three] {
            let mut out = vec![u64::MAX];
            par.map_chunks(&items, 37, &mut out, |c| {
                c.iter().map(|&x| u64::from(x) * 2).collect()
            })
            .unwrap();
            let mut sorted = items.clone();
            par.sort(&mut sorted).unwrap();
            let mut squares = vec![7];
            par.map_range(1000, 16, &mut squares, |i| i * i).unwrap();
            assert!(squares.iter().enumerate().all(|(i, &x)| x == i * i) && squares.len() == 1000);
            let got = (out, sorted);
            assert_eq!(got.0.len(), 1001);
            assert_eq!(*want.get_or_insert_with(|| got.clone()), got);
        }
    }
}
