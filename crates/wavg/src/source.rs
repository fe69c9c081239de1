//! Where a mesh comes from: a mesh file, or `builtin:NAME`, a mesh generated in code.
//! Every way in takes either wherever it takes a mesh path (the commands, `Surface::open`,
//! Python's `read_mesh` and `Surface.open`, the C ABI's `wavg_surface_open`).

use std::path::Path;

use wavg_mesh::{LoadNotes, TriMesh, procedural};

use crate::error::Result;

/// The prefix that names a procedural mesh instead of a file: `builtin:torus`
/// ([`procedural::BUILTINS`] lists the names and says what each is).
pub const BUILTIN_PREFIX: &str = "builtin:";

/// The name after [`BUILTIN_PREFIX`] when `source` names a builtin mesh.
///
/// ```
/// use std::path::Path;
/// assert_eq!(wavg::builtin_name(Path::new("builtin:torus")), Some("torus"));
/// assert_eq!(wavg::builtin_name(Path::new("torus.obj")), None);
/// ```
pub fn builtin_name(source: &Path) -> Option<&str> {
    source.to_str()?.strip_prefix(BUILTIN_PREFIX)
}

/// The mesh `source` names: `builtin:NAME` ([`procedural::builtin`]; an unknown name is an
/// [`ErrorKind::InvalidArgument`](crate::ErrorKind) listing the names) or a mesh file
/// ([`wavg_mesh::io::load`]: `.obj`, `.off`, `.ply`, optionally `.gz`, `.gltf`, `.glb`,
/// `scene.glb#Name`). Not validated.
///
/// ```
/// let torus = wavg::load_mesh("builtin:torus")?;
/// assert_eq!(torus.n_vertices(), 1536);
/// assert!(wavg::load_mesh("builtin:teapot").is_err());
/// # Ok::<(), wavg::Error>(())
/// ```
pub fn load_mesh(source: impl AsRef<Path>) -> Result<TriMesh> {
    load_mesh_with_notes(source).map(|(mesh, _)| mesh)
}

/// Like [`load_mesh`], also returning what the file held beyond the triangle mesh (the
/// default [`LoadNotes`] for a builtin mesh).
pub fn load_mesh_with_notes(source: impl AsRef<Path>) -> Result<(TriMesh, LoadNotes)> {
    let source = source.as_ref();
    Ok(match builtin_name(source) {
        Some(name) => (procedural::builtin(name)?, LoadNotes::default()),
        None => wavg_mesh::io::load_with_notes(source)?,
    })
}
