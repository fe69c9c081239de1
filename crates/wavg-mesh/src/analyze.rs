//! One pass over a raw mesh: every validation defect, the statistics `wavg info` prints,
//! and (when the mesh is valid) its topology.

use rayon::prelude::*;

use crate::defect::{Defect, ValidationReport};
use crate::mesh::TriMesh;
use crate::topology::{self, Topology};

/// Faces whose doubled area is below this fraction of their longest squared edge are
/// degenerate. Scale-relative: a needle of area 5e-13 on a unit mesh is caught, a
/// well-shaped face of a mesh scaled by 1e-6 is not.
pub const ZERO_AREA_RELATIVE_TOLERANCE: f64 = 1e-10;

/// Counts that describe any parseable mesh, valid or not.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshStats {
    /// Number of vertices.
    pub vertices: usize,
    /// Number of triangles.
    pub faces: usize,
    /// Number of undirected edges (over faces with valid, distinct indices).
    pub edges: usize,
    /// Connected components of the faces (sharing a vertex connects).
    pub components: usize,
    /// Connected components of the graph of edges with exactly one incident face.
    pub boundary_loops: usize,
    /// Edges with at most two faces and vertices with a single fan.
    pub manifold: bool,
    /// Manifold with consistent orientation.
    pub oriented: bool,
    /// Manifold without boundary edges.
    pub watertight: bool,
    /// V - E + F over referenced vertices.
    pub euler_characteristic: i64,
    /// Sum over components of (2 - chi - b) / 2; `None` unless a non-empty oriented manifold.
    pub genus: Option<i64>,
}

/// Result of [`analyze`].
#[derive(Clone, Debug)]
pub struct Analysis {
    /// Counts.
    pub stats: MeshStats,
    /// Every defect found.
    pub report: ValidationReport,
    /// The topology, present exactly when the report is valid.
    pub topology: Option<Topology>,
}

/// Checks a raw mesh for every defect in [`Defect`] and computes its statistics.
/// Never panics, whatever the input.
///
/// ```
/// use wavg_mesh::{analyze, procedural};
/// let a = analyze(&procedural::torus(24, 12, 1.0, 0.3));
/// assert_eq!(a.stats.genus, Some(1));
/// assert!(a.report.is_valid() && a.topology.is_some());
/// ```
pub fn analyze(mesh: &TriMesh) -> Analysis {
    let nv = mesh.n_vertices();
    let nf = mesh.n_faces();
    let mut defects = Vec::new();
    if nv == 0 || nf == 0 {
        defects.push(Defect::Empty {
            vertices: nv,
            faces: nf,
        });
    }
    defects.extend(
        (mesh.positions.par_iter().enumerate())
            .filter(|(_, p)| !p.iter().all(|c| c.is_finite()))
            .map(|(v, _)| Defect::NonFiniteCoordinate { vertex: v as u32 })
            .collect::<Vec<_>>(),
    );
    // Faces usable for combinatorics: indices in range and distinct. Each face is judged
    // once, in parallel; the defects are listed kind by kind, each in face order.
    let verdicts: Vec<FaceVerdict> = (mesh.triangles.par_iter().enumerate())
        .map(|(f, t)| face_verdict(mesh, f, t))
        .collect();
    let usable: Vec<bool> = (verdicts.par_iter())
        .map(|v| matches!(v, FaceVerdict::Usable | FaceVerdict::ZeroArea))
        .collect();
    for kind in 0..3 {
        defects.extend(verdicts.iter().enumerate().filter_map(|(f, v)| {
            let face = f as u32;
            match (kind, *v) {
                (0, FaceVerdict::OutOfRange(index)) => Some(Defect::IndexOutOfRange {
                    face,
                    index,
                    vertex_count: nv,
                }),
                (1, FaceVerdict::RepeatedIndex) => Some(Defect::RepeatedIndex { face }),
                (2, FaceVerdict::ZeroArea) => Some(Defect::ZeroAreaFace { face }),
                _ => None,
            }
        }));
    }
    drop(verdicts);
    // The independent passes side by side: duplicate faces; the edge table with its
    // orientation and manifold checks and the face adjacency; the vertex-to-face incidence;
    // the components.
    let ((duplicates, (edges, edge_problems, adj)), (incidence, comps)) = rayon::join(
        || {
            rayon::join(
                || duplicate_faces(mesh, &usable),
                || {
                    let edges = topology::EdgeTable::build(&mesh.triangles, &usable);
                    let defects = edge_defects(mesh, &edges);
                    let adj = edges.manifold_adjacency(nf);
                    (edges, defects, adj)
                },
            )
        },
        || {
            rayon::join(
                || topology::VertexFaces::build(nv, &mesh.triangles, &usable),
                || topology::face_components(nv, &mesh.triangles, &usable),
            )
        },
    );
    defects.extend(duplicates);
    let (oriented, edge_manifold) = (
        !(edge_problems.iter()).any(|d| matches!(d, Defect::InconsistentOrientation { .. })),
        !(edge_problems.iter()).any(|d| matches!(d, Defect::NonManifoldEdge { .. })),
    );
    defects.extend(edge_problems);
    let mut vertex_manifold = true;
    // Fans per vertex (0 for an unreferenced vertex), in parallel; the defects are then
    // listed in vertex order.
    let fans: Vec<usize> = (0..nv)
        .into_par_iter()
        .map_init(
            || (Vec::new(), Vec::new()),
            |(seen, stack), v| {
                topology::count_fans(
                    v as u32,
                    incidence.faces(v),
                    &mesh.triangles,
                    &adj,
                    seen,
                    stack,
                )
            },
        )
        .collect();
    let mut referenced = 0usize;
    for (v, &fans) in fans.iter().enumerate() {
        if fans == 0 {
            defects.push(Defect::UnreferencedVertex { vertex: v as u32 });
            continue;
        }
        referenced += 1;
        if fans > 1 {
            vertex_manifold = false;
            defects.push(Defect::NonManifoldVertex {
                vertex: v as u32,
                fans,
            });
        }
    }
    if let Some(uv) = &mesh.uv {
        check_uv(mesh, uv, &mut defects);
    }
    defects.sort_by_key(|p| p.kind());

    let manifold = edge_manifold
        && vertex_manifold
        && !defects.iter().any(|p| {
            matches!(
                p,
                Defect::IndexOutOfRange { .. } | Defect::RepeatedIndex { .. }
            )
        });
    let n_edges = edges.groups().count();
    let boundary = edges.boundary_loop_count(nv, &mesh.triangles);
    let n_usable = usable.par_iter().filter(|&&u| u).count();
    let chi = referenced as i64 - n_edges as i64 + n_usable as i64;
    // Undefined for a mesh without any usable face (nothing to take the genus of).
    let genus = (manifold && oriented && n_usable > 0)
        .then(|| topology::genus_per_component(&comps, &edges, &mesh.triangles, &usable));
    let stats = MeshStats {
        vertices: nv,
        faces: nf,
        edges: n_edges,
        components: comps.count,
        boundary_loops: boundary,
        manifold,
        oriented: manifold && oriented,
        watertight: manifold && edges.groups().all(|g| g.len() == 2),
        euler_characteristic: chi,
        genus,
    };
    let report = ValidationReport { problems: defects };
    let topology = report
        .is_valid()
        .then(|| Topology::from_parts(mesh, adj, incidence, comps, genus.unwrap_or(0), chi));
    Analysis {
        stats,
        report,
        topology,
    }
}

/// What the face checks found about one face.
#[derive(Clone, Copy)]
enum FaceVerdict {
    /// Usable, with a positive area.
    Usable,
    /// An index beyond the vertices (the first such).
    OutOfRange(u32),
    /// A vertex twice.
    RepeatedIndex,
    /// Usable for combinatorics, but of zero area.
    ZeroArea,
}

/// The checks of face `f` (`t`) on its own.
fn face_verdict(mesh: &TriMesh, f: usize, t: &[u32; 3]) -> FaceVerdict {
    if let Some(&bad) = t.iter().find(|&&i| i as usize >= mesh.n_vertices()) {
        return FaceVerdict::OutOfRange(bad);
    }
    if t[0] == t[1] || t[1] == t[2] || t[2] == t[0] {
        return FaceVerdict::RepeatedIndex;
    }
    let [a, b, c] = mesh.corners(f);
    if [a, b, c].iter().all(|p| p.iter().all(|x| x.is_finite())) && is_degenerate(a, b, c) {
        FaceVerdict::ZeroArea
    } else {
        FaceVerdict::Usable
    }
}

/// Faces with the vertex set of an earlier one, in the order of their vertex sets.
fn duplicate_faces(mesh: &TriMesh, usable: &[bool]) -> Vec<Defect> {
    let mut defects = Vec::new();
    // Sorted by (smallest vertex, middle, largest, face): equal vertex sets are adjacent.
    let by_vertices =
        topology::bucket_sorted((0..mesh.n_faces()).filter(|&f| usable[f]).map(|f| {
            let mut t = mesh.triangles[f];
            t.sort_unstable();
            ((t[0] as u64) << 32 | t[1] as u64, f as u32)
        }));
    let mut i = 0;
    while i < by_vertices.len() {
        // Within a run of equal (smallest, middle), group by the largest vertex.
        let mut j = i + 1;
        while j < by_vertices.len() && by_vertices[j].0 == by_vertices[i].0 {
            j += 1;
        }
        if j - i > 1 {
            let mut run: Vec<(u32, u32)> = by_vertices[i..j]
                .iter()
                .map(|&(_, f)| (mesh.triangles[f as usize].into_iter().max().unwrap_or(0), f))
                .collect();
            run.sort_unstable();
            for w in run.windows(2) {
                if w[0].0 == w[1].0 {
                    defects.push(Defect::DuplicateFace {
                        face: w[1].1,
                        first: w[0].1,
                    });
                }
            }
        }
        i = j;
    }
    defects
}

/// Edges with more than two faces, and pairs of faces that run along their shared edge in
/// the same direction, in edge order.
fn edge_defects(mesh: &TriMesh, edges: &topology::EdgeTable) -> Vec<Defect> {
    let mut defects = Vec::new();
    for g in edges.groups() {
        let hs = &edges.halfedges[g.clone()];
        let (a, b) = edges.key_vertices(g.start);
        if hs.len() > 2 {
            defects.push(Defect::NonManifoldEdge {
                a,
                b,
                faces: hs.len(),
            });
        } else if hs.len() == 2 {
            let dir = |h: u32| mesh.triangles[(h / 3) as usize][(h % 3) as usize];
            if dir(hs[0]) == dir(hs[1]) {
                defects.push(Defect::InconsistentOrientation {
                    face_a: hs[0] / 3,
                    face_b: hs[1] / 3,
                    a,
                    b,
                });
            }
        }
    }
    defects
}

/// Doubled area small against the longest squared edge (collinear or coincident corners),
/// whatever the scale: the edges are scaled to a largest component of 1 first, so faces
/// of meshes too large or too small to square are judged by their shape (the
/// computations refuse such meshes, see [`crate::coordinates_out_of_range`]).
pub(crate) fn is_degenerate(
    a: nalgebra::Vector3<f64>,
    b: nalgebra::Vector3<f64>,
    c: nalgebra::Vector3<f64>,
) -> bool {
    let (mut e0, mut e1, mut e2) = (b - a, c - b, a - c);
    let mut m = e0.amax().max(e1.amax()).max(e2.amax());
    if !(m.is_finite() && m > 0.0) {
        return true;
    }
    if m < 1e-290 {
        // 1 / m would overflow: scale up by 2^600 first (exact).
        let up = 2f64.powi(600);
        (e0, e1, e2, m) = (e0 * up, e1 * up, e2 * up, m * up);
    }
    let (e0, e1, e2) = (e0 / m, e1 / m, e2 / m);
    let longest = e0
        .norm_squared()
        .max(e1.norm_squared())
        .max(e2.norm_squared());
    let twice_area = e0.cross(&(-e2)).norm();
    // Written so that NaN counts as degenerate.
    let well_shaped = twice_area > ZERO_AREA_RELATIVE_TOLERANCE * longest && longest > 0.0;
    !well_shaped
}

fn check_uv(mesh: &TriMesh, uv: &crate::mesh::TexCoords, defects: &mut Vec<Defect>) {
    if uv.faces.len() != mesh.triangles.len() {
        defects.push(Defect::InvalidTexCoords {
            face: uv.faces.len().min(mesh.triangles.len()) as u32,
            reason: format!(
                "{} texture faces for {} triangles",
                uv.faces.len(),
                mesh.triangles.len()
            ),
        });
        return;
    }
    for (f, t) in uv.faces.iter().enumerate() {
        if let Some(&i) = t.iter().find(|&&i| i as usize >= uv.coords.len()) {
            defects.push(Defect::InvalidTexCoords {
                face: f as u32,
                reason: format!("uv index {i} out of range ({} uvs)", uv.coords.len()),
            });
        } else if t
            .iter()
            .any(|&i| !uv.coords[i as usize].iter().all(|c| c.is_finite()))
        {
            defects.push(Defect::InvalidTexCoords {
                face: f as u32,
                reason: "non-finite uv".into(),
            });
        }
    }
}
