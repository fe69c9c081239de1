//! The precomputation at any scale in range: a mesh far from unit size is computed as an
//! exact power-of-two rescaling of itself, and its embedding scaled back. Squared lengths,
//! areas and the eigen-solver's tolerances then stay where double precision serves them
//! (a torus of size 1e-45 otherwise sent the MDS eigen-solver into an endless loop, and
//! below 1e-43 the embedding came out distorted), and the embedding is usable by the
//! projector or refused here, never written and refused later.

use wavg_mesh::{MAX_COORDINATE, MIN_EXTENT, TriMesh, ValidMesh};

use crate::embedding::Embedding;
use crate::error::{EmbedError, Monotone, Progress};
use crate::file::MAX_DIM;
use crate::pipeline::{PrecomputeOptions, precompute_unscaled};
use crate::report::Report;

/// Meshes whose bounding box's longest side lies within `2^-SCALE_FREE ..= 2^SCALE_FREE`
/// are computed as they are (the results of all everyday meshes are unchanged by the
/// rescaling's existence); others are rescaled to a longest side in `[0.5, 1)`.
const SCALE_FREE: i32 = 20;

/// Computes the 8-D embedding of `mesh` (paper Section 3.5).
///
/// The mesh must be connected (one component; any genus, boundaries allowed) and within
/// [`wavg_mesh::coordinates_out_of_range`]'s range. Progress is reported per
/// [`crate::Stage`]; when `progress.cancelled()` turns true the computation stops at the
/// next check and returns [`EmbedError::Cancelled`]. A mesh far from unit size gives the
/// embedding of its power-of-two rescaling, scaled back: the same numbers, up to the
/// exponent, whatever its scale.
///
/// ```
/// use wavg_embed::{PrecomputeOptions, precompute};
/// use wavg_embed::NoProgress;
/// use wavg_mesh::{ValidMesh, procedural};
/// let mesh = ValidMesh::new(procedural::torus(48, 24, 1.0, 0.4)).unwrap();
/// let opts = PrecomputeOptions { landmarks: 100, ..Default::default() };
/// let (emb, report) = precompute(&mesh, &opts, &NoProgress).unwrap();
/// assert_eq!(emb.coords.len(), mesh.n_vertices());
/// assert_eq!(report.landmarks, 100);
/// assert!(report.geodesic_rel_err_p50 < 0.1);
/// ```
pub fn precompute(
    mesh: &ValidMesh,
    opts: &PrecomputeOptions,
    progress: &dyn Progress,
) -> Result<(Embedding, Report), EmbedError> {
    if let Some(why) = wavg_mesh::coordinates_out_of_range(mesh) {
        return Err(EmbedError::InvalidArgument(why));
    }
    // Later rounds run stages again: their bars hold where the first round left them.
    let progress = &Monotone::new(progress);
    let k = scale_exponent(mesh);
    let (embedding, report) = if k == 0 {
        precompute_unscaled(mesh, opts, progress, true)?
    } else {
        let down = 2f64.powi(-k);
        let m = mesh.mesh();
        let positions = m.positions.iter().map(|p| p * down).collect();
        // An exact rescaling of a valid mesh is valid (faces are judged by their shape).
        let scaled = ValidMesh::new(TriMesh::new(positions, m.triangles.clone()))
            .map_err(|e| EmbedError::Numerical(format!("the rescaled mesh: {e}")))?;
        let (mut e, r) = precompute_unscaled(&scaled, opts, progress, true)?;
        let up = 2f64.powi(k);
        for c in &mut e.coords {
            for x in c.iter_mut() {
                *x *= up;
            }
        }
        (e, r)
    };
    check_range(&embedding)?;
    Ok((embedding, report))
}

/// `k` such that the mesh's longest bounding-box side times `2^-k` lies in `[0.5, 1)`, or 0
/// when that side is within `2^±SCALE_FREE` (or not positive).
fn scale_exponent(mesh: &ValidMesh) -> i32 {
    let Some((lo, hi)) = mesh.mesh().bounding_box() else {
        return 0;
    };
    let extent = (hi - lo).amax();
    if !(extent > 0.0 && extent.is_finite()) {
        return 0;
    }
    let k = extent.log2().floor() as i32 + 1;
    if k.abs() <= SCALE_FREE { 0 } else { k }
}

/// The projector's range for the embedding ([`MAX_COORDINATE`], [`MIN_EXTENT`]): an
/// embedding outside it (its geodesic distances can exceed the mesh's coordinates) is an
/// error naming the remedy rather than a file every solver would refuse.
fn check_range(e: &Embedding) -> Result<(), EmbedError> {
    let largest = e
        .coords
        .iter()
        .flatten()
        .fold(0.0f64, |m, x| m.max(x.abs()));
    if largest > MAX_COORDINATE {
        return Err(EmbedError::InvalidArgument(format!(
            "the embedding's coordinates reach {largest:e}, beyond the supported magnitude of \
             {MAX_COORDINATE:e} (the mesh's geodesic distances exceed its coordinates): scale \
             the mesh down"
        )));
    }
    let (lo, hi) = e.coords.iter().fold(
        ([f64::INFINITY; MAX_DIM], [f64::NEG_INFINITY; MAX_DIM]),
        |(l, h), c| {
            (
                std::array::from_fn(|k| l[k].min(c[k])),
                std::array::from_fn(|k| h[k].max(c[k])),
            )
        },
    );
    let extent = (0..MAX_DIM).map(|k| hi[k] - lo[k]).fold(0.0f64, f64::max);
    if extent > 0.0 && extent < MIN_EXTENT {
        return Err(EmbedError::InvalidArgument(format!(
            "the embedding spans only {extent:e}, below the supported size of {MIN_EXTENT:e}: \
             scale the mesh up"
        )));
    }
    Ok(())
}
