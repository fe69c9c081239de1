//! Triangle meshes for wavg: storage, connectivity, validation, repair, I/O and geometry.
//!
//! The flow is: load or generate a [`TriMesh`] (any file can be parsed into one, however
//! broken), [`analyze()`] it to see its defects and statistics, optionally [`repair`] it, then
//! make a [`ValidMesh`] (oriented manifold plus [`Topology`]), the only type later stages take.
//!
//! ```
//! use wavg_mesh::{ValidMesh, procedural};
//! let mesh = ValidMesh::new(procedural::torus(32, 16, 1.0, 0.3)).unwrap();
//! assert_eq!(mesh.topology().genus(), 1);
//! ```
//!
//! A file from a scanner, end to end ([`io::load`] reads OBJ/OFF/PLY, optionally `.gz`, and glTF):
//!
//! ```
//! use wavg_mesh::{RepairOptions, ValidMesh, analyze, io, repair};
//! # let dir = tempfile::tempdir().unwrap();
//! # let path = dir.path().join("scan.off");
//! # std::fs::write(&path, "OFF\n5 3 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n9 9 9\n\
//! #     3 0 1 2\n3 1 3 2\n3 2 1 3\n").unwrap();
//! let raw = io::load(&path)?;
//! let report = analyze(&raw).report;
//! if !report.is_valid() {
//!     eprintln!("{report}"); // duplicate face 2, unreferenced vertex 4
//! }
//! let fixed = repair::repair_all(&raw, &RepairOptions::default());
//! let mesh = ValidMesh::new(fixed.mesh)?;
//! assert_eq!((mesh.n_vertices(), mesh.n_faces()), (4, 2));
//! # Ok::<(), wavg_mesh::MeshError>(())
//! ```

#![deny(unreachable_pub)]
#![forbid(unsafe_code)]

mod analyze;
mod closest;
mod defect;
mod error;
pub mod geometry;
pub mod io;
mod mesh;
mod point;
pub mod procedural;
pub mod repair;
mod report;
mod rings;
pub mod subdivide;
mod topology;
mod valid;

// Meshes and their validation.
pub use closest::closest_point_barycentric;
pub use mesh::{FaceId, NONE, TexCoords, TriMesh, VertexId};
pub use rings::RingSearch;
pub use topology::Topology;
pub use valid::{Rejected, ValidMesh};

// Diagnostics.
pub use analyze::{Analysis, MeshStats, ZERO_AREA_RELATIVE_TOLERANCE, analyze};
pub use defect::{Defect, DefectKind, DefectSummary, ValidationReport};

/// Renamed to [`Defect`] ("problem" names the paper's forward and inverse problems).
#[deprecated(note = "renamed to `Defect`")]
pub type Problem = Defect;
/// Renamed to [`DefectKind`].
#[deprecated(note = "renamed to `DefectKind`")]
pub type ProblemKind = DefectKind;
/// Renamed to [`DefectSummary`].
#[deprecated(note = "renamed to `DefectSummary`")]
pub type ProblemSummary = DefectSummary;
/// Renamed to [`DefectGroup`].
#[deprecated(note = "renamed to `DefectGroup`")]
pub type ProblemGroup = DefectGroup;

// Reports for people and programs (with the `serde` feature, serialisable).
pub use report::{
    BoundingBox, DefectGroup, MeshInfo, RepairPreview, RepairReport, SubdivisionReport,
};

// Points on the surface.
pub use point::SurfacePoint;

// Files and repairs (the functions live in the `io` and `repair` modules).
pub use io::format::{Format, LoadNotes};
pub use repair::types::{RepairOptions, Repaired};

// Errors.
pub use error::MeshError;

/// The largest coordinate magnitude the embedding and the projector accept (their fast
/// marching and hierarchy store lengths in single precision, up to about 3.4e38, with room
/// for sums of a few of them). Larger meshes are refused with an error that says to scale
/// them down; valid meshes beyond it can still be inspected and repaired.
pub const MAX_COORDINATE: f64 = 1e37;

/// The smallest bounding-box side (the longest of the three) the embedding accepts: its
/// least-squares mesh weighs vertices by their areas, products of four lengths that must
/// stay normal double-precision numbers (a sphere of radius 1e-75 still round-trips every
/// query; at 1e-80 some fail, at 1e-90 the areas underflow). Smaller meshes are refused
/// with an error that says to scale them up.
pub const MIN_EXTENT: f64 = 1e-60;

/// Why `mesh` is beyond [`MAX_COORDINATE`] or smaller than [`MIN_EXTENT`] (a message that
/// names the remedy), or `None`.
///
/// ```
/// let mut m = wavg_mesh::procedural::icosphere(0);
/// assert!(wavg_mesh::coordinates_out_of_range(&m).is_none());
/// m.positions[3].x = -2e38;
/// assert!(wavg_mesh::coordinates_out_of_range(&m).unwrap().contains("scale the mesh down"));
/// let mut m = wavg_mesh::procedural::icosphere(0);
/// for p in &mut m.positions {
///     *p *= 1e-70;
/// }
/// assert!(wavg_mesh::coordinates_out_of_range(&m).unwrap().contains("scale the mesh up"));
/// for p in &mut m.positions {
///     *p = *p * 1e70 + nalgebra::Vector3::repeat(1e38);
/// }
/// let why = wavg_mesh::coordinates_out_of_range(&m).unwrap();
/// assert!(why.contains("move the mesh towards the origin"), "{why}");
/// ```
pub fn coordinates_out_of_range(mesh: &TriMesh) -> Option<String> {
    let largest = mesh.positions.iter().map(|p| p.amax()).fold(0.0, f64::max);
    let extent = mesh.bounding_box().map_or(0.0, |(lo, hi)| (hi - lo).amax());
    if largest > MAX_COORDINATE {
        // Far from the origin but of moderate size: moving it is the remedy.
        let remedy = if extent <= MAX_COORDINATE / 8.0 {
            "move the mesh towards the origin"
        } else {
            "scale the mesh down"
        };
        return Some(format!(
            "the mesh's coordinates reach {largest:e}, beyond the supported magnitude of \
             {MAX_COORDINATE:e}: {remedy}"
        ));
    }
    (extent < MIN_EXTENT).then(|| {
        format!(
            "the mesh spans only {extent:e}, below the supported size of {MIN_EXTENT:e}: \
             scale the mesh up"
        )
    })
}
