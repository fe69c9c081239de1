//! The types of the repairs: their options and their result with its index maps.

use crate::mesh::{FaceId, NONE, TriMesh, VertexId};

/// A repaired mesh and how its indices relate to the input's.
#[derive(Clone, Debug, PartialEq)]
pub struct Repaired {
    /// The repaired mesh.
    pub mesh: TriMesh,
    /// For each new vertex, the original vertex it comes from (for welded vertices: the
    /// lowest original index of the group).
    pub vertex_map: Vec<VertexId>,
    /// For each original vertex, its new index, or [`NONE`] when it was dropped.
    pub original_to_new: Vec<VertexId>,
    /// For each new face, the original face it comes from.
    pub face_map: Vec<FaceId>,
}

impl Repaired {
    /// The new index of original vertex `v`, if it survived.
    pub fn new_vertex(&self, v: VertexId) -> Option<VertexId> {
        self.original_to_new
            .get(v as usize)
            .copied()
            .filter(|&n| n != NONE)
    }

    /// Number of original vertices that were merged into others or dropped.
    pub fn removed_vertices(&self) -> usize {
        self.original_to_new.len() - self.kept_vertices()
    }

    /// Number of new vertices that are copies of a kept vertex (made by splitting a
    /// non-manifold vertex).
    pub fn added_vertices(&self) -> usize {
        self.vertex_map.len() - self.kept_vertices()
    }

    /// Original vertices that survive as themselves (not dropped, not merged away).
    fn kept_vertices(&self) -> usize {
        (self.original_to_new.iter().enumerate())
            .filter(|&(v, &n)| self.vertex_map.get(n as usize) == Some(&(v as u32)))
            .count()
    }

    /// Number of original faces that were dropped.
    pub fn removed_faces(&self, original_faces: usize) -> usize {
        original_faces - self.face_map.len()
    }

    /// A repair that keeps every face, in order.
    pub(super) fn faces_kept(
        mesh: TriMesh,
        vertex_map: Vec<VertexId>,
        original_to_new: Vec<VertexId>,
    ) -> Self {
        let face_map = (0..mesh.n_faces() as u32).collect();
        Self {
            mesh,
            vertex_map,
            original_to_new,
            face_map,
        }
    }

    /// The identity repair of `mesh`.
    pub(super) fn identity(mesh: &TriMesh) -> Self {
        let nv = mesh.n_vertices() as u32;
        Self {
            mesh: mesh.clone(),
            vertex_map: (0..nv).collect(),
            original_to_new: (0..nv).collect(),
            face_map: (0..mesh.n_faces() as u32).collect(),
        }
    }

    /// Applies `next` (a repair of `self.mesh`) on top of `self`: maps compose so that
    /// they still refer to the original input.
    pub(super) fn then(self, next: Repaired) -> Repaired {
        let vertex_map = next
            .vertex_map
            .iter()
            .map(|&v| self.vertex_map[v as usize])
            .collect();
        let original_to_new = self
            .original_to_new
            .iter()
            .map(|&v| {
                if v == NONE {
                    NONE
                } else {
                    next.original_to_new[v as usize]
                }
            })
            .collect();
        let face_map = next
            .face_map
            .iter()
            .map(|&f| self.face_map[f as usize])
            .collect();
        Repaired {
            mesh: next.mesh,
            vertex_map,
            original_to_new,
            face_map,
        }
    }
}

/// Which repairs [`repair_all`](super::repair_all) applies, in this order: weld, drop
/// degenerate faces, drop duplicate faces, make manifold, orient, keep the largest
/// component, drop unreferenced vertices.
#[derive(Clone, Debug, PartialEq)]
pub struct RepairOptions {
    /// Weld vertices closer than this distance (`Some(0.0)`: identical positions only).
    pub weld: Option<f64>,
    /// Drop out-of-range, repeated-index, non-finite and zero-area faces.
    pub drop_degenerate_faces: bool,
    /// Drop faces repeating an earlier face's vertices.
    pub drop_duplicate_faces: bool,
    /// Split vertices and edges shared by separate sheets of surface
    /// ([`make_manifold`](super::make_manifold)).
    pub make_manifold: bool,
    /// Flip faces to a consistent orientation per component
    /// ([`orient_faces`](super::orient_faces)).
    pub orient: bool,
    /// Keep only the largest connected component.
    pub keep_largest_component: bool,
    /// Drop vertices no face uses.
    pub drop_unreferenced_vertices: bool,
}

impl Default for RepairOptions {
    /// Everything that cannot lose surface: exact weld, drop degenerate and duplicate
    /// faces, make manifold, orient, drop unreferenced vertices; components are kept.
    fn default() -> Self {
        Self {
            weld: Some(0.0),
            drop_degenerate_faces: true,
            drop_duplicate_faces: true,
            make_manifold: true,
            orient: true,
            keep_largest_component: false,
            drop_unreferenced_vertices: true,
        }
    }
}
