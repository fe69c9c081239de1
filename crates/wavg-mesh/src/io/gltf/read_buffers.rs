//! The bytes behind a glTF file: the GLB container's chunks, and each buffer from the
//! binary chunk, a `data:` URI or a file beside the `.gltf`.

use std::borrow::Cow;
use std::path::{Path, PathBuf};

/// The JSON and binary chunks of a `.glb`, or the whole input as JSON.
#[derive(Debug)]
pub(crate) struct Container<'a> {
    /// The JSON text.
    pub json: &'a [u8],
    /// The binary chunk (GLB only).
    pub bin: Option<&'a [u8]>,
}

const GLB_MAGIC: &[u8; 4] = b"glTF";
const CHUNK_JSON: u32 = 0x4E4F_534A;
const CHUNK_BIN: u32 = 0x004E_4942;

fn u32_at(b: &[u8], at: usize) -> Option<u32> {
    let s = b.get(at..at.checked_add(4)?)?;
    Some(u32::from_le_bytes([s[0], s[1], s[2], s[3]]))
}

/// Splits a `.glb` into its chunks (header `glTF`, version 2, length; then a JSON chunk
/// and an optional BIN chunk), each length checked against the bytes present; input that
/// does not start with the magic is taken as JSON.
pub(crate) fn container(bytes: &[u8]) -> Result<Container<'_>, String> {
    if !bytes.starts_with(GLB_MAGIC) {
        return Ok(Container {
            json: bytes,
            bin: None,
        });
    }
    let short = || "GLB: the file ends inside its header".to_string();
    let version = u32_at(bytes, 4).ok_or_else(short)?;
    if version != 2 {
        return Err(format!("GLB version {version} (only glTF 2.0 is read)"));
    }
    let declared = u32_at(bytes, 8).ok_or_else(short)? as usize;
    if declared > bytes.len() || declared < 12 {
        return Err(format!(
            "GLB header declares {declared} bytes, the file has {}",
            bytes.len()
        ));
    }
    let body = &bytes[..declared];
    let mut at = 12;
    let mut json = None;
    let mut bin = None;
    while at < body.len() {
        let len = u32_at(body, at).ok_or("GLB: the file ends inside a chunk header")? as usize;
        let kind = u32_at(body, at + 4).ok_or("GLB: the file ends inside a chunk header")?;
        let start = at + 8;
        let data = start
            .checked_add(len)
            .and_then(|end| body.get(start..end))
            .ok_or_else(|| {
                format!("GLB chunk at byte {at} declares {len} bytes past the end of the file")
            })?;
        match kind {
            CHUNK_JSON if json.is_none() && at == 12 => json = Some(data),
            CHUNK_BIN if bin.is_none() && json.is_some() => bin = Some(data),
            CHUNK_JSON | CHUNK_BIN => {
                return Err(format!("GLB: unexpected chunk at byte {at}"));
            }
            _ => {} // Unknown chunk types are skipped, as the specification asks.
        }
        at = start + len;
    }
    let json = json.ok_or("GLB without a JSON chunk")?;
    Ok(Container { json, bin })
}

/// Where buffers and images named by relative URIs are looked for: the folder of the
/// `.gltf` file or a folder below it. A URI that leaves it (a `..` step, an absolute path,
/// once percent-decoded) is refused, as browsers and most viewers refuse it, so a file
/// from elsewhere cannot make the reader open any file it likes.
pub(crate) fn beside(path: &Path, uri: &str) -> Result<PathBuf, String> {
    let first = uri.split(['/', '\\']).next().unwrap_or("");
    if first.contains(':') {
        return Err(format!(
            "URI {uri:?}: only data: URIs and relative file names are read"
        ));
    }
    let decoded = percent_decode(uri)?;
    let outside = decoded.starts_with(['/', '\\'])
        || decoded.split(['/', '\\']).any(|step| step == "..")
        || decoded
            .split(['/', '\\'])
            .next()
            .is_some_and(|s| s.contains(':'));
    if outside {
        return Err(format!(
            "URI {uri:?} names a file outside the glTF file's folder; only files in that \
             folder or below it are read: move the file there (and the URI with it), or \
             use a .glb"
        ));
    }
    let dir = path.parent().unwrap_or(Path::new(""));
    Ok(dir.join(decoded))
}

fn percent_decode(s: &str) -> Result<String, String> {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' {
            let hex = b
                .get(i + 1..i + 3)
                .and_then(|h| std::str::from_utf8(h).ok())
                .and_then(|h| u8::from_str_radix(h, 16).ok())
                .ok_or_else(|| format!("URI {s:?}: bad percent escape"))?;
            out.push(hex);
            i += 3;
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    String::from_utf8(out).map_err(|_| format!("URI {s:?} is not UTF-8 once decoded"))
}

/// The bytes of a `data:` URI (base64 or percent-encoded) and its media type, or `None`
/// when `uri` is not a data URI.
pub(crate) fn data_uri(uri: &str) -> Option<Result<(String, Vec<u8>), String>> {
    let rest = uri.strip_prefix("data:")?;
    let Some((head, payload)) = rest.split_once(',') else {
        return Some(Err("data: URI without a comma".into()));
    };
    let (mime, base64) = match head.strip_suffix(";base64") {
        Some(m) => (m, true),
        None => (head, false),
    };
    let bytes = if base64 {
        base64_decode(payload)
    } else {
        percent_decode(payload).map(String::into_bytes)
    };
    Some(bytes.map(|b| (mime.to_string(), b)))
}

/// Standard base64 (padding optional, whitespace refused).
fn base64_decode(s: &str) -> Result<Vec<u8>, String> {
    fn value(c: u8) -> Option<u32> {
        Some(match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' => 62,
            b'/' => 63,
            _ => return None,
        } as u32)
    }
    let s = s.trim_end_matches('=').as_bytes();
    let mut out = Vec::with_capacity(s.len() / 4 * 3 + 3);
    for chunk in s.chunks(4) {
        let mut acc = 0u32;
        for (k, &c) in chunk.iter().enumerate() {
            let v = value(c).ok_or("data: URI: invalid base64")?;
            acc |= v << (18 - 6 * k);
        }
        let n = match chunk.len() {
            4 => 3,
            3 => 2,
            2 => 1,
            _ => return Err("data: URI: truncated base64".into()),
        };
        out.extend_from_slice(&acc.to_be_bytes()[1..1 + n]);
    }
    Ok(out)
}

/// Every buffer of the document, in order: at least as many bytes as declared (extra
/// bytes are ignored, as the GLB binary chunk's padding).
pub(crate) fn load<'a>(
    doc: &gltf::Document,
    bin: Option<&'a [u8]>,
    path: &Path,
) -> Result<Vec<Cow<'a, [u8]>>, String> {
    let mut out = Vec::with_capacity(doc.buffers().len());
    for b in doc.buffers() {
        let what = format!("buffer {}", b.index());
        let data: Cow<'a, [u8]> = match b.source() {
            gltf::buffer::Source::Bin => Cow::Borrowed(
                bin.ok_or_else(|| format!("{what} is the GLB binary chunk, which is missing"))?,
            ),
            gltf::buffer::Source::Uri(uri) => match data_uri(uri) {
                Some(r) => Cow::Owned(r.map_err(|e| format!("{what}: {e}"))?.1),
                None => {
                    let file = beside(path, uri).map_err(|e| format!("{what}: {e}"))?;
                    Cow::Owned(read_at_most(&file, b.length()).map_err(|e| format!("{what}: {e}"))?)
                }
            },
        };
        if data.len() < b.length() {
            return Err(format!(
                "{what} declares {} bytes but holds {}",
                b.length(),
                data.len()
            ));
        }
        out.push(data);
    }
    Ok(out)
}

/// The first `limit` bytes of a file (a declared buffer length never makes the reader
/// allocate more than the file holds).
fn read_at_most(file: &Path, limit: usize) -> Result<Vec<u8>, String> {
    use std::io::Read;
    let f = std::fs::File::open(file).map_err(|e| format!("{}: {e}", file.display()))?;
    let mut out = Vec::new();
    f.take(limit as u64)
        .read_to_end(&mut out)
        .map_err(|e| format!("{}: {e}", file.display()))?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_decodes_with_and_without_padding() {
        assert_eq!(base64_decode("aGVsbG8=").unwrap(), b"hello");
        assert_eq!(base64_decode("aGVsbG8").unwrap(), b"hello");
        assert_eq!(base64_decode("AAEC/w==").unwrap(), [0, 1, 2, 255]);
        assert!(base64_decode("a").is_err());
        assert!(base64_decode("a*bc").is_err());
        let (mime, b) = data_uri("data:application/octet-stream;base64,AAEC")
            .unwrap()
            .unwrap();
        assert_eq!(
            (mime.as_str(), b),
            ("application/octet-stream", vec![0, 1, 2])
        );
        assert!(data_uri("file.bin").is_none());
    }

    #[test]
    fn uris_resolve_beside_the_file_and_nowhere_else() {
        let p = beside(Path::new("d/m.gltf"), "my%20mesh.bin").unwrap();
        assert_eq!(p, Path::new("d/my mesh.bin"));
        let p = beside(Path::new("d/m.gltf"), "./tex/a..b.png").unwrap();
        assert_eq!(p, Path::new("d/./tex/a..b.png"));
        assert!(beside(Path::new("m.gltf"), "https://x/y.bin").is_err());
        assert!(beside(Path::new("m.gltf"), "file:/etc/passwd").is_err());
        assert!(beside(Path::new("m.gltf"), "%zz").is_err());
        for uri in [
            "/etc/passwd",
            "\\\\server\\x.bin",
            "../x.bin",
            "tex/../../x.bin",
            "tex\\..\\..\\x.bin",
            "%2E%2E/x.bin",
            "%2Fetc%2Fpasswd",
            "C%3A%5Cx.bin",
        ] {
            let e = beside(Path::new("d/m.gltf"), uri).unwrap_err();
            assert!(e.contains(&format!("{uri:?}")), "{e}");
        }
    }

    #[test]
    fn glb_chunks_are_checked_against_the_bytes() {
        let mut glb = b"glTF".to_vec();
        glb.extend(2u32.to_le_bytes());
        glb.extend(24u32.to_le_bytes());
        glb.extend(4u32.to_le_bytes());
        glb.extend(CHUNK_JSON.to_le_bytes());
        glb.extend(b"{}  ");
        let c = container(&glb).unwrap();
        assert_eq!((c.json, c.bin), (&b"{}  "[..], None));
        let mut long = glb.clone();
        long[12] = 200; // the JSON chunk claims 200 bytes
        assert!(container(&long).is_err());
        let mut short_header = glb.clone();
        short_header[8] = 4; // total length below the header's own 12 bytes
        assert!(container(&short_header).is_err());
        assert!(container(&glb[..10]).is_err());
        let mut v1 = glb;
        v1[4] = 1;
        assert!(container(&v1).unwrap_err().contains("version 1"));
    }
}
