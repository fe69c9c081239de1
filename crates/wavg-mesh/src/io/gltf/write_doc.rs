//! The low-level half of the glTF writer: one binary buffer with its views and accessors,
//! and the two containers (`.glb`: JSON and buffer in one file; `.gltf`: JSON naming a
//! `.bin` beside it).

use gltf_json as json;
use json::accessor::{ComponentType, GenericComponentType, Type};
use json::buffer::Target;
use json::validation::{Checked::Valid, USize64};

/// A glTF document being built: the JSON root and the bytes of its one buffer.
pub(super) struct Doc {
    pub(super) root: json::Root,
    pub(super) bin: Vec<u8>,
}

/// Pads `bytes` with `fill` to a multiple of four (glTF aligns views and GLB chunks so).
fn pad4(bytes: &mut Vec<u8>, fill: u8) {
    while bytes.len() % 4 != 0 {
        bytes.push(fill);
    }
}

impl Doc {
    pub(super) fn new() -> Self {
        let root = json::Root {
            asset: json::Asset {
                generator: Some(format!("wavg {}", env!("CARGO_PKG_VERSION"))),
                version: "2.0".into(),
                ..Default::default()
            },
            ..Default::default()
        };
        Self {
            root,
            bin: Vec::new(),
        }
    }

    /// Appends `bytes` as a buffer view (4-byte aligned) of the one buffer.
    pub(super) fn view(
        &mut self,
        bytes: &[u8],
        target: Option<Target>,
    ) -> json::Index<json::buffer::View> {
        pad4(&mut self.bin, 0);
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        self.root.push(json::buffer::View {
            buffer: json::Index::new(0),
            byte_length: USize64::from(bytes.len()),
            byte_offset: Some(USize64::from(offset)),
            byte_stride: None,
            name: None,
            target: target.map(Valid),
            extensions: None,
            extras: Default::default(),
        })
    }

    /// A float accessor of `n`-component elements (`values.len()` a multiple of `n`);
    /// with `bounds`, its per-component min and max (required for positions).
    pub(super) fn floats(
        &mut self,
        values: &[f32],
        type_: Type,
        bounds: bool,
    ) -> json::Index<json::Accessor> {
        let n = type_.multiplicity();
        let bytes: Vec<u8> = values.iter().flat_map(|x| x.to_le_bytes()).collect();
        let view = self.view(&bytes, Some(Target::ArrayBuffer));
        let (min, max) = if bounds {
            let mut lo = vec![f32::INFINITY; n];
            let mut hi = vec![f32::NEG_INFINITY; n];
            for e in values.chunks_exact(n) {
                for (k, &x) in e.iter().enumerate() {
                    lo[k] = lo[k].min(x);
                    hi[k] = hi[k].max(x);
                }
            }
            (Some(json::Value::from(lo)), Some(json::Value::from(hi)))
        } else {
            (None, None)
        };
        self.accessor(view, values.len() / n, ComponentType::F32, type_, min, max)
    }

    /// A scalar `u32` index accessor.
    pub(super) fn indices(&mut self, values: &[u32]) -> json::Index<json::Accessor> {
        let bytes: Vec<u8> = values.iter().flat_map(|x| x.to_le_bytes()).collect();
        let view = self.view(&bytes, Some(Target::ElementArrayBuffer));
        self.accessor(
            view,
            values.len(),
            ComponentType::U32,
            Type::Scalar,
            None,
            None,
        )
    }

    fn accessor(
        &mut self,
        view: json::Index<json::buffer::View>,
        count: usize,
        component: ComponentType,
        type_: Type,
        min: Option<json::Value>,
        max: Option<json::Value>,
    ) -> json::Index<json::Accessor> {
        self.root.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: USize64::from(count),
            component_type: Valid(GenericComponentType(component)),
            extensions: None,
            extras: Default::default(),
            type_: Valid(type_),
            min,
            max,
            name: None,
            normalized: false,
            sparse: None,
        })
    }

    /// Finishes the buffer: `uri` names the `.bin` file (`None` in a `.glb`).
    fn close(&mut self, uri: Option<String>) {
        pad4(&mut self.bin, 0);
        if self.bin.is_empty() {
            return;
        }
        self.root.buffers = vec![json::Buffer {
            byte_length: USize64::from(self.bin.len()),
            name: None,
            uri,
            extensions: None,
            extras: Default::default(),
        }];
    }

    /// The document as one `.glb` file.
    pub(super) fn into_glb(mut self) -> std::io::Result<Vec<u8>> {
        self.close(None);
        let mut text = json::serialize::to_vec(&self.root).map_err(std::io::Error::other)?;
        pad4(&mut text, b' ');
        let chunks = 8
            + text.len()
            + if self.bin.is_empty() {
                0
            } else {
                8 + self.bin.len()
            };
        let total = u32::try_from(12 + chunks)
            .map_err(|_| std::io::Error::other("the file would pass the 4 GiB limit of .glb"))?;
        let mut out = Vec::with_capacity(total as usize);
        out.extend_from_slice(b"glTF");
        out.extend_from_slice(&2u32.to_le_bytes());
        out.extend_from_slice(&total.to_le_bytes());
        for (kind, data) in [(b"JSON", &text), (b"BIN\0", &self.bin)] {
            if data.is_empty() {
                continue;
            }
            out.extend_from_slice(&(data.len() as u32).to_le_bytes());
            out.extend_from_slice(kind);
            out.extend_from_slice(data);
        }
        Ok(out)
    }

    /// The document as a `.gltf` JSON text naming its buffer `bin_uri`, and the buffer's
    /// bytes (empty when there are none).
    pub(super) fn into_gltf(mut self, bin_uri: &str) -> std::io::Result<(Vec<u8>, Vec<u8>)> {
        self.close(Some(uri_escape(bin_uri)));
        let text = json::serialize::to_vec_pretty(&self.root).map_err(std::io::Error::other)?;
        Ok((text, self.bin))
    }
}

/// A relative URI reference for a file name: bytes outside RFC 3986's unreserved set are
/// percent-encoded (a space becomes `%20`).
fn uri_escape(name: &str) -> String {
    let mut out = String::with_capacity(name.len());
    for b in name.bytes() {
        if b.is_ascii_alphanumeric() || b"-._~".contains(&b) {
            out.push(b as char);
        } else {
            out.push_str(&format!("%{b:02X}"));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uri_escape_keeps_plain_names_and_encodes_the_rest() {
        assert_eq!(uri_escape("mesh_1.bin"), "mesh_1.bin");
        assert_eq!(uri_escape("my mesh#1.bin"), "my%20mesh%231.bin");
        assert_eq!(uri_escape("é.bin"), "%C3%A9.bin");
    }

    #[test]
    fn glb_chunks_are_aligned_and_sized() {
        let mut d = Doc::new();
        d.floats(&[0.0, 1.0, 2.0], Type::Vec3, true);
        let glb = d.into_glb().unwrap();
        assert_eq!(&glb[..4], b"glTF");
        assert_eq!(
            u32::from_le_bytes(glb[8..12].try_into().unwrap()) as usize,
            glb.len()
        );
        let json_len = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
        assert_eq!(json_len % 4, 0);
        assert_eq!(&glb[20 + json_len + 4..20 + json_len + 8], b"BIN\0");
        assert_eq!(glb.len() % 4, 0);
    }
}
