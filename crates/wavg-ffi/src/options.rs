//! `wavg_precompute_options`: the precomputation settings a C caller can change, in a
//! struct that can grow without breaking programs compiled against an older header.

use crate::boundary::{Failure, guard_value};

/// Settings of `wavg_surface_precompute`. Always start from
/// `wavg_precompute_options_default()` and change the fields you need.
///
/// Forward compatibility: `struct_size` is `sizeof(wavg_precompute_options)` as the caller
/// compiled it (the default sets it). Later versions only append fields; the library reads
/// the fields that fit in `struct_size` and uses defaults for the rest, so a program built
/// against an older header keeps working with a newer library.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct wavg_precompute_options {
    /// `sizeof(wavg_precompute_options)` of the caller's header (set by the default).
    pub struct_size: usize,
    /// Number of landmark vertices (default 1000, the paper's): 0 lets the library choose
    /// for the mesh, as every front end does without explicit options; otherwise at least
    /// 4. A mesh with fewer vertices uses all of them.
    pub landmarks: usize,
    /// Seed of the random choices (the quality-check pairs); every other stage is
    /// deterministic. Default 0.
    pub seed: u64,
    /// Above this many mesh vertices, the landmark geodesics run on an intermediate
    /// decimated mesh of this size (0: always on the full mesh). Default 10000.
    pub geodesic_vertices: usize,
    /// Vertex pairs for the embedding quality check (0 skips it). Default 1024.
    pub quality_pairs: usize,
}

/// Size of the first published layout (every later layout starts with it).
const V1_SIZE: usize =
    std::mem::offset_of!(wavg_precompute_options, quality_pairs) + std::mem::size_of::<usize>();

impl wavg_precompute_options {
    fn defaults() -> Self {
        let d = wavg::PrecomputeOptions::default();
        Self {
            struct_size: std::mem::size_of::<Self>(),
            landmarks: wavg::DEFAULT_LANDMARKS,
            seed: d.seed,
            geodesic_vertices: d.geodesic_vertices,
            quality_pairs: d.quality_pairs,
        }
    }

    /// Reads the caller's options (NULL: defaults) as the library's settings.
    ///
    /// # Safety
    /// `ptr` must be NULL or point to at least `struct_size` readable bytes.
    pub(crate) unsafe fn read(ptr: *const Self) -> Result<wavg::PrecomputeOptions, Failure> {
        let mut o = Self::defaults();
        if !ptr.is_null() {
            // SAFETY: the first field is always present and readable.
            let size = unsafe { std::ptr::addr_of!((*ptr).struct_size).read_unaligned() };
            if size < V1_SIZE {
                return Err(Failure::arg(format!(
                    "wavg_precompute_options.struct_size is {size}, smaller than any published \
                     layout ({V1_SIZE}); start from wavg_precompute_options_default()"
                )));
            }
            // Only the fields this library knows; a newer caller's extra fields are ignored.
            let n = size.min(std::mem::size_of::<Self>());
            // SAFETY: the caller guarantees `size >= n` readable bytes; `o` has `n` bytes.
            unsafe {
                std::ptr::copy_nonoverlapping(ptr.cast::<u8>(), (&raw mut o).cast::<u8>(), n)
            };
        }
        if o.landmarks != 0 && o.landmarks < 4 {
            return Err(Failure::arg(format!(
                "{} landmarks requested; at least 4 are needed (0: the library's choice)",
                o.landmarks
            )));
        }
        Ok(wavg::PrecomputeOptions {
            landmarks: o.landmarks,
            seed: o.seed,
            geodesic_vertices: o.geodesic_vertices,
            quality_pairs: o.quality_pairs,
            ..Default::default()
        })
    }
}

/// The default precomputation settings (the paper's 1000 landmarks, the same as every
/// other front end's default), with `struct_size` set. Thread-safe; cannot fail.
#[unsafe(no_mangle)]
pub extern "C" fn wavg_precompute_options_default() -> wavg_precompute_options {
    guard_value(
        wavg_precompute_options::defaults(),
        wavg_precompute_options::defaults,
    )
}
