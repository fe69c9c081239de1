//! Reports of what a mesh is and what was done to it. With the `serde` feature they
//! serialise to the keys of `wavg info --json` ([`MeshInfo`]), `wavg repair --json`
//! ([`RepairReport`]) and `wavg subdivide --json` ([`SubdivisionReport`]): the field names.

use crate::analyze::{Analysis, analyze};
use crate::defect::{DefectKind, DefectSummary};
use crate::io::format::LoadNotes;
use crate::mesh::TriMesh;
use crate::repair::repair_all;
use crate::repair::types::{RepairOptions, Repaired};

/// Counts, topology, bounding box and defects of a mesh, valid or not, and what the
/// default repairs would do to it.
///
/// ```
/// use wavg_mesh::{MeshInfo, analyze, procedural};
/// let mesh = procedural::torus(12, 6, 1.0, 0.3);
/// let info = MeshInfo::new(&mesh, None, &analyze(&mesh));
/// assert_eq!((info.vertices, info.genus, info.valid), (72, Some(1), true));
/// assert!(info.repair.is_none());
/// ```
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct MeshInfo {
    /// Vertices.
    pub vertices: usize,
    /// Triangles.
    pub faces: usize,
    /// Faces in the file before triangulation (the triangle count without load notes).
    pub polygons: usize,
    /// Faces of the file with fewer than three corners, skipped.
    pub skipped_faces: usize,
    /// Whether the file's texture coordinates were dropped (only some faces had them).
    pub uv_dropped: bool,
    /// Vertices the reader merged into others by welding exactly equal positions (glTF
    /// splits a vertex at every UV seam); 0 for OBJ, OFF and PLY.
    pub welded_vertices: usize,
    /// glTF primitives of points or lines, skipped.
    pub skipped_primitives: usize,
    /// Edges.
    pub edges: usize,
    /// Connected components.
    pub components: usize,
    /// Boundary loops.
    pub boundary_loops: usize,
    /// Euler characteristic.
    pub euler_characteristic: i64,
    /// Genus (`None` unless the mesh is valid: an invalid mesh's genus, even when its
    /// faces form an oriented manifold, says nothing about the surface its repair gives).
    pub genus: Option<i64>,
    /// Whether every edge and vertex is manifold.
    pub manifold: bool,
    /// Whether the faces are consistently oriented.
    pub oriented: bool,
    /// Whether there is no boundary.
    pub watertight: bool,
    /// Whether no defect was found (an oriented manifold wavg can use).
    pub valid: bool,
    /// Whether the mesh has texture coordinates.
    pub uv: bool,
    /// Bounding box (`None` without vertices).
    pub bounding_box: Option<BoundingBox>,
    /// One line per kind of defect ([`crate::ValidationReport::lines`]).
    pub problems: Vec<String>,
    /// The defects by kind.
    pub problem_summary: Vec<DefectGroup>,
    /// What the default repairs would do (`None` for a valid mesh).
    pub repair: Option<RepairPreview>,
    /// Why the embedding and the solvers would refuse the size of this valid mesh
    /// (coordinates beyond [`crate::MAX_COORDINATE`] or a span below
    /// [`crate::MIN_EXTENT`]: [`crate::coordinates_out_of_range`]); `None` within range,
    /// and for an invalid mesh (its repair may change what is in range: an unused far
    /// vertex goes).
    pub out_of_range: Option<String>,
}

impl MeshInfo {
    /// The report of `mesh` and its `analysis`, with the notes of loading it from a file
    /// (`None` for a mesh made in memory). For an invalid mesh this runs the default
    /// repairs ([`RepairPreview::of`]).
    pub fn new(mesh: &TriMesh, notes: Option<&LoadNotes>, analysis: &Analysis) -> Self {
        let s = &analysis.stats;
        let valid = analysis.report.is_valid();
        Self {
            vertices: s.vertices,
            faces: s.faces,
            polygons: notes.map_or(s.faces, |n| n.polygons),
            skipped_faces: notes.map_or(0, |n| n.skipped_faces),
            uv_dropped: notes.is_some_and(|n| n.uv_dropped),
            welded_vertices: notes.map_or(0, |n| n.welded_vertices),
            skipped_primitives: notes.map_or(0, |n| n.skipped_primitives),
            edges: s.edges,
            components: s.components,
            boundary_loops: s.boundary_loops,
            euler_characteristic: s.euler_characteristic,
            genus: s.genus.filter(|_| valid),
            manifold: s.manifold,
            oriented: s.oriented,
            watertight: s.watertight,
            valid,
            uv: mesh.uv.is_some(),
            bounding_box: mesh.bounding_box().map(|(lo, hi)| BoundingBox {
                min: [lo.x, lo.y, lo.z],
                max: [hi.x, hi.y, hi.z],
                // Scaled by the longest side first: no overflow or underflow on the way.
                diagonal: {
                    let d = hi - lo;
                    let m = d.amax();
                    if m > 0.0 && m.is_finite() {
                        m * (d / m).norm()
                    } else {
                        m
                    }
                },
            }),
            problems: analysis.report.lines(),
            problem_summary: analysis
                .report
                .summary()
                .iter()
                .map(DefectGroup::from)
                .collect(),
            repair: (!valid).then(|| RepairPreview::of(mesh)),
            out_of_range: valid
                .then(|| crate::coordinates_out_of_range(mesh))
                .flatten(),
        }
    }
}

/// An axis-aligned bounding box.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct BoundingBox {
    /// Smallest x, y, z.
    pub min: [f64; 3],
    /// Largest x, y, z.
    pub max: [f64; 3],
    /// Length of the diagonal.
    pub diagonal: f64,
}

/// One kind of defect: [`DefectSummary`] in words.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct DefectGroup {
    /// The kind (in JSON its snake_case name, e.g. `non_manifold_edge`).
    pub kind: DefectKind,
    /// [`DefectKind::describe`].
    pub description: &'static str,
    /// How many defects of this kind.
    pub count: usize,
    /// The first few, as sentences.
    pub examples: Vec<String>,
    /// [`DefectKind::remedy`].
    pub remedy: Option<&'static str>,
}

impl From<&DefectSummary> for DefectGroup {
    fn from(p: &DefectSummary) -> Self {
        Self {
            kind: p.kind,
            description: p.kind.describe(),
            count: p.count,
            examples: p.examples.iter().map(|e| e.to_string()).collect(),
            remedy: p.kind.remedy(),
        }
    }
}

/// What the default repairs ([`repair_all`] with [`RepairOptions::default`]) do to a mesh:
/// tried, not guessed (a duplicate face also makes non-manifold edges that disappear with
/// it).
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct RepairPreview {
    /// Whether the repaired mesh is valid.
    pub fixes_all: bool,
    /// Vertices removed ([`Repaired::removed_vertices`]).
    pub removed_vertices: usize,
    /// Copies made by splitting non-manifold vertices ([`Repaired::added_vertices`]).
    pub added_vertices: usize,
    /// Faces removed.
    pub removed_faces: usize,
    /// The defects left, one `"COUNT DESCRIPTION"` per kind (empty when `fixes_all`).
    pub remaining_problems: Vec<String>,
    /// Connected components after repair. Not serialised.
    #[cfg_attr(feature = "serde", serde(skip))]
    pub components: usize,
}

impl RepairPreview {
    /// Runs the default repairs on `mesh` and analyses the result.
    pub fn of(mesh: &TriMesh) -> Self {
        let r = repair_all(mesh, &RepairOptions::default());
        let after = analyze(&r.mesh);
        let remaining: Vec<String> = after
            .report
            .summary()
            .iter()
            .map(|s| format!("{} {}", s.count, s.kind.describe()))
            .collect();
        Self {
            fixes_all: remaining.is_empty(),
            removed_vertices: r.removed_vertices(),
            added_vertices: r.added_vertices(),
            removed_faces: r.removed_faces(mesh.n_faces()),
            remaining_problems: remaining,
            components: after.stats.components,
        }
    }
}

/// What a repair did: the counts before and after, and the defects left.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct RepairReport {
    /// Vertices of the input.
    pub vertices_before: usize,
    /// Faces of the input.
    pub faces_before: usize,
    /// Vertices of the output.
    pub vertices: usize,
    /// Faces of the output.
    pub faces: usize,
    /// Input vertices removed ([`Repaired::removed_vertices`]).
    pub removed_vertices: usize,
    /// Copies made by splitting non-manifold vertices ([`Repaired::added_vertices`]).
    pub added_vertices: usize,
    /// Input faces removed.
    pub removed_faces: usize,
    /// Connected components of the output.
    pub components: usize,
    /// Whether the output is valid.
    pub valid: bool,
    /// The defects left, one line per kind ([`crate::ValidationReport::lines`]).
    pub problems: Vec<String>,
}

impl RepairReport {
    /// The report of repairing `input` into `repaired`, whose analysis is `after`.
    pub fn new(input: &TriMesh, repaired: &Repaired, after: &Analysis) -> Self {
        Self {
            vertices_before: input.n_vertices(),
            faces_before: input.n_faces(),
            vertices: repaired.mesh.n_vertices(),
            faces: repaired.mesh.n_faces(),
            removed_vertices: repaired.removed_vertices(),
            added_vertices: repaired.added_vertices(),
            removed_faces: repaired.removed_faces(input.n_faces()),
            components: after.stats.components,
            valid: after.report.is_valid(),
            problems: after.report.lines(),
        }
    }
}

/// What a Loop subdivision ([`crate::subdivide::loop_subdivide`], level after level) did.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct SubdivisionReport {
    /// Vertices of the input.
    pub input_vertices: usize,
    /// Faces of the input.
    pub input_faces: usize,
    /// Vertices of the output.
    pub vertices: usize,
    /// Faces of the output.
    pub faces: usize,
    /// Levels applied.
    pub levels: u32,
    /// Wall-clock seconds of the subdivision.
    pub seconds: f64,
}
