//! The texture a mesh file carries: a glTF material's base colour texture (PNG or JPEG,
//! embedded or in a file beside the `.gltf`), which `transfer-texture` and `render` use
//! when no texture file is given.

use wavg_apps::Image;
use wavg_mesh::LoadNotes;
use wavg_mesh::io::gltf::TextureSource;

use crate::Result;

/// The decoded base colour texture the notes of a loaded file point to
/// ([`LoadNotes::texture`]), or `None` when the file has none. A texture file beside the
/// mesh is read now; an unreadable or undecodable image is an error naming it.
///
/// ```
/// let notes = wavg::LoadNotes::default(); // OBJ, OFF and PLY carry no texture
/// assert!(wavg::mesh_texture(&notes).unwrap().is_none());
/// ```
pub fn mesh_texture(notes: &LoadNotes) -> Result<Option<Image>> {
    Ok(match &notes.texture {
        None => None,
        Some(TextureSource::File(path)) => Some(Image::read(path)?),
        Some(TextureSource::Embedded { bytes, .. }) => {
            Some(Image::decode(bytes).map_err(|e| match e {
                wavg_apps::AppError::Image(m) => {
                    wavg_apps::AppError::Image(format!("the mesh file's embedded texture: {m}"))
                }
                other => other,
            })?)
        }
    })
}
