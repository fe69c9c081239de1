//! The crate's error type and progress reporting.

use std::path::PathBuf;

/// Everything that can go wrong computing, reading or writing an embedding.
#[derive(Debug, thiserror::Error)]
pub enum EmbedError {
    /// A parameter is out of range or the mesh is unsuitable (message says how to fix it).
    #[error("{0}")]
    InvalidArgument(String),
    /// The caller asked to stop.
    #[error("cancelled")]
    Cancelled,
    /// A numerical step failed (for example a factorisation).
    #[error("numerical failure: {0}")]
    Numerical(String),
    /// Reading a file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// Writing a file failed (a missing folder, no permission, a full disk).
    #[error("{path}: {source}")]
    Write {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// A `.wavg` file is not a `.wavg` file, truncated or corrupt.
    #[error("{path}: {message}")]
    BadFile {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A `.wavg` file written by a newer wavg (format version above the supported one).
    #[error(
        "{path}: .wavg format version {found} is newer than the supported version {supported}; \
         upgrade wavg or recompute the embedding"
    )]
    UnsupportedVersion {
        /// The file.
        path: PathBuf,
        /// Version found in the file.
        found: u32,
        /// Highest version this build reads.
        supported: u32,
    },
    /// A valid `.wavg` file that was computed for another mesh.
    #[error(
        "{path}: embedding belongs to another mesh ({message}); recompute it with `wavg precompute`"
    )]
    MeshMismatch {
        /// The file.
        path: PathBuf,
        /// Which part of the fingerprint differs.
        message: String,
    },
}

/// The stages of the precomputation, in order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Stage {
    /// Landmark selection by decimation.
    Decimate,
    /// Fast-marching geodesic distances between landmarks.
    Geodesics,
    /// Metric multidimensional scaling of the landmarks.
    Mds,
    /// Least-squares-mesh upsampling to all vertices.
    LsMesh,
    /// Quality check: embedding vs geodesic distance on random vertex pairs.
    Quality,
}

impl Stage {
    /// Every stage, in pipeline order.
    pub const ALL: [Stage; 5] = [
        Stage::Decimate,
        Stage::Geodesics,
        Stage::Mds,
        Stage::LsMesh,
        Stage::Quality,
    ];

    /// Lower-case name used in JSON and progress bars.
    pub fn name(self) -> &'static str {
        match self {
            Self::Decimate => "decimate",
            Self::Geodesics => "geodesics",
            Self::Mds => "mds",
            Self::LsMesh => "lsmesh",
            Self::Quality => "quality",
        }
    }
}

/// Receives progress and answers whether to stop. Must be cheap: it is called often and
/// from several threads.
pub trait Progress: Sync {
    /// `fraction` of `stage` is done (0..=1).
    fn report(&self, stage: Stage, fraction: f64);
    /// True when the caller wants the computation to stop (it then returns `Cancelled`).
    fn cancelled(&self) -> bool {
        false
    }
}

/// Progress sink that ignores everything and never cancels.
pub struct NoProgress;

impl Progress for NoProgress {
    fn report(&self, _stage: Stage, _fraction: f64) {}
}

/// Forwards to a sink only the reports that raise their stage's fraction, so that what
/// the sink sees never decreases within a stage: the rounds that add landmarks run the
/// geodesics, MDS and the least-squares mesh again, each from 0, and parallel runs report
/// out of order.
pub(crate) struct Monotone<'a> {
    inner: &'a dyn Progress,
    /// The highest fraction forwarded per stage (in [`Stage::ALL`]'s order), if any.
    highest: std::sync::Mutex<[Option<f64>; 5]>,
}

impl<'a> Monotone<'a> {
    pub(crate) fn new(inner: &'a dyn Progress) -> Self {
        Monotone {
            inner,
            highest: std::sync::Mutex::new([None; 5]),
        }
    }
}

impl Progress for Monotone<'_> {
    fn report(&self, stage: Stage, fraction: f64) {
        let i = Stage::ALL.iter().position(|&s| s == stage).unwrap_or(0);
        // A poisoned lock only means another report panicked: its values still hold.
        let mut highest = self.highest.lock().unwrap_or_else(|e| e.into_inner());
        if highest[i].is_none_or(|h| fraction > h) {
            highest[i] = Some(fraction);
            // Under the lock, so that two threads' reports reach the sink in order.
            self.inner.report(stage, fraction);
        }
    }
    fn cancelled(&self) -> bool {
        self.inner.cancelled()
    }
}

/// Returns `Err(Cancelled)` if the sink asks to stop.
pub(crate) fn check_cancel(p: &dyn Progress) -> Result<(), EmbedError> {
    if p.cancelled() {
        Err(EmbedError::Cancelled)
    } else {
        Ok(())
    }
}

/// Entries a large buffer gets between two looks at the cancellation in [`filled`].
pub(crate) const FILL_BLOCK: usize = 1 << 20;

/// `vec![value; len]`, filled [`FILL_BLOCK`] entries at a time with a look at the
/// cancellation before each block: first touches of fresh memory cost seconds for a buffer
/// of a gigabyte or more (the fast marching's update table at 10M vertices), and a
/// cancellation must not wait for them.
pub(crate) fn filled<T: Clone>(
    len: usize,
    value: T,
    p: &dyn Progress,
) -> Result<Vec<T>, EmbedError> {
    let mut v = Vec::with_capacity(len);
    while v.len() < len {
        check_cancel(p)?;
        let block = (len - v.len()).min(FILL_BLOCK);
        v.resize(v.len() + block, value.clone());
    }
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicUsize, Ordering};

    /// Cancels from its `after`-th look on, counting the looks.
    struct CancelAfter {
        after: usize,
        looks: AtomicUsize,
    }

    impl Progress for CancelAfter {
        fn report(&self, _: Stage, _: f64) {}
        fn cancelled(&self) -> bool {
            self.looks.fetch_add(1, Ordering::Relaxed) + 1 >= self.after
        }
    }

    #[test]
    fn a_large_buffer_is_filled_a_block_at_a_time_looking_at_the_cancellation() {
        let never = CancelAfter {
            after: usize::MAX,
            looks: AtomicUsize::new(0),
        };
        let len = 3 * FILL_BLOCK + 5;
        let v = filled(len, 7u8, &never).unwrap();
        assert_eq!(v.len(), len);
        assert!(v.iter().all(|&x| x == 7));
        assert_eq!(never.looks.load(Ordering::Relaxed), 4);

        let third = CancelAfter {
            after: 3,
            looks: AtomicUsize::new(0),
        };
        assert!(matches!(
            filled(len, 0u8, &third),
            Err(EmbedError::Cancelled)
        ));
        assert_eq!(third.looks.load(Ordering::Relaxed), 3);

        let empty = CancelAfter {
            after: 1,
            looks: AtomicUsize::new(0),
        };
        assert!(filled(0, 0u8, &empty).unwrap().is_empty());
    }
}
