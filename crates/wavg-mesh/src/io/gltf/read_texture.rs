//! The base colour texture of a glTF material: where its encoded image is.

use std::path::{Path, PathBuf};

use super::read_buffers;

/// Where the encoded image (PNG or JPEG) of a glTF file's base colour texture is: inside
/// the file (a buffer view or a `data:` URI), or in a file beside it. The image is not
/// decoded here; `media_type` is the file's declared type (`image/png`, `image/jpeg`),
/// when it gives one.
#[derive(Clone, Debug, PartialEq)]
pub enum TextureSource {
    /// The image's bytes, embedded in the file.
    Embedded {
        /// The declared media type, if any.
        media_type: Option<String>,
        /// The encoded image.
        bytes: Vec<u8>,
    },
    /// An image file beside the `.gltf`.
    File(PathBuf),
}

/// The base colour texture of `material` when it uses `TEXCOORD_0`.
pub(crate) fn base_colour(
    material: &gltf::Material,
    buffers: &[std::borrow::Cow<'_, [u8]>],
    path: &Path,
) -> Result<Option<TextureSource>, String> {
    let Some(info) = material.pbr_metallic_roughness().base_color_texture() else {
        return Ok(None);
    };
    if info.tex_coord() != 0 {
        return Ok(None);
    }
    let image = info.texture().source();
    let what = format!("image {}", image.index());
    Ok(Some(match image.source() {
        gltf::image::Source::View { view, mime_type } => {
            let bytes = view
                .offset()
                .checked_add(view.length())
                .and_then(|end| buffers[view.buffer().index()].get(view.offset()..end))
                .ok_or_else(|| {
                    format!("{what}: buffer view {} lies past its buffer", view.index())
                })?;
            TextureSource::Embedded {
                media_type: Some(mime_type.to_string()),
                bytes: bytes.to_vec(),
            }
        }
        gltf::image::Source::Uri { uri, mime_type } => match read_buffers::data_uri(uri) {
            Some(r) => {
                let (mime, bytes) = r.map_err(|e| format!("{what}: {e}"))?;
                TextureSource::Embedded {
                    media_type: mime_type.map(str::to_string).or(Some(mime)),
                    bytes,
                }
            }
            None => TextureSource::File(
                read_buffers::beside(path, uri).map_err(|e| format!("{what}: {e}"))?,
            ),
        },
    }))
}
