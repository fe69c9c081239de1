//! Reading and writing mesh files: OBJ, OFF and PLY (ASCII and binary), each optionally
//! gzip-compressed (`.gz` suffix), and glTF 2.0 (`.gltf`, `.glb`; [`gltf`]).
//!
//! Readers produce a raw [`TriMesh`] that keeps the file's vertex indexing exactly
//! (unreferenced vertices stay, out-of-range indices stay so that validation can name
//! them); polygons are fan-triangulated. Whatever the bytes, a reader returns a mesh or a
//! typed [`MeshError`], never panics. Malformed text gives [`MeshError::Parse`] with the
//! path and the 1-based line.
//!
//! ```
//! use wavg_mesh::{io, procedural};
//! let dir = tempfile::tempdir().unwrap();
//! let path = dir.path().join("sphere.off");
//! let mesh = procedural::icosphere(1);
//! io::save(&path, &mesh).unwrap();
//! let back = io::load(&path).unwrap();
//! assert_eq!(back.triangles, mesh.triangles);
//! assert_eq!(back.positions, mesh.positions); // shortest round-trip float text: bit-exact
//! ```

mod atomic;
pub(crate) mod format;
pub mod gltf;
mod obj;
mod off;
mod ply;
mod source;
mod text;

use std::io::{Read, Write};
use std::path::Path;

pub use atomic::{TEMP_PREFIX, is_special_destination, remove_stale_temporaries, write_atomic};
use format::{Format, LoadNotes};

use crate::error::MeshError;
use crate::mesh::TriMesh;

/// Reads a mesh file, choosing the format from the extension (`.obj`, `.off`, `.ply`,
/// each optionally followed by `.gz`; `.gltf`, `.glb`, optionally followed by `#MeshName`
/// to read one mesh of the file: [`gltf::split_mesh_name`]).
pub fn load(path: &Path) -> Result<TriMesh, MeshError> {
    load_with_notes(path).map(|(m, _)| m)
}

/// Like [`load`], also returning what the file held beyond the triangle mesh.
///
/// The file is parsed as it is read (and decompressed), a block at a time: the whole
/// file is never in memory beside the mesh.
pub fn load_with_notes(path: &Path) -> Result<(TriMesh, LoadNotes), MeshError> {
    let (format, gz) = Format::from_path(path)?;
    if matches!(format, Format::Gltf | Format::Glb) {
        // glTF is read whole: its JSON says where in the bytes each array is.
        let (_, bytes) = read_file(path)?;
        return parse_bytes(&bytes, format, path);
    }
    let file = std::fs::File::open(path).map_err(|e| io_err(path, e))?;
    let size = file.metadata().map_err(|e| io_err(path, e))?.len();
    if gz {
        let limit = gzip_limit(size);
        let hint = limit.min(size.saturating_mul(8));
        let reader = Gunzip {
            inner: flate2::read::MultiGzDecoder::new(file),
            left: limit,
            limit,
        };
        parse_from(reader, format, path, hint as usize)
    } else {
        parse_from(file, format, path, size as usize)
    }
}

/// The (decompressed) bytes of a mesh file and its format: the I/O half of [`load`],
/// for callers that time reading and parsing separately.
pub fn read_file(path: &Path) -> Result<(Format, Vec<u8>), MeshError> {
    let (format, gz) = Format::from_path(path)?;
    let (file, _) = gltf::split_mesh_name(path);
    Ok((format, read_bytes(&file, gz)?))
}

/// Parses an in-memory (uncompressed) file of the given format; `path` is used in error
/// messages and, for glTF, to find the buffers and images beside the file and the mesh
/// name after `#`.
pub fn parse_bytes(
    bytes: &[u8],
    format: Format,
    path: &Path,
) -> Result<(TriMesh, LoadNotes), MeshError> {
    if matches!(format, Format::Gltf | Format::Glb) {
        let (mesh, mut notes) = gltf::parse(bytes, path).map_err(|message| MeshError::Parse {
            path: gltf::split_mesh_name(path).0,
            line: 0,
            message,
        })?;
        notes.format = Some(format);
        return Ok((mesh, notes));
    }
    parse_from(bytes, format, path, bytes.len())
}

/// Parses what `reader` yields; `hint` is about its size in bytes (for capacities only).
fn parse_from(
    reader: impl Read,
    format: Format,
    path: &Path,
    hint: usize,
) -> Result<(TriMesh, LoadNotes), MeshError> {
    let located = |e: text::ParseError| match e.io {
        // Corrupt compressed data is the file's fault, said without a line.
        Some(source) if source.kind() != std::io::ErrorKind::InvalidData => MeshError::Io {
            path: path.to_path_buf(),
            source,
        },
        io => MeshError::Parse {
            path: path.to_path_buf(),
            line: if io.is_some() { 0 } else { e.line },
            message: e.message,
        },
    };
    let mut src = source::Source::new(reader);
    let (mesh, mut notes) = match format {
        Format::Obj => obj::parse(&mut text::TextLines::new(&mut src)),
        Format::Off => off::parse(&mut text::TextLines::new(&mut src), hint),
        Format::Ply => ply::parse(&mut src, hint),
        // Read whole by `parse_bytes`, never streamed.
        Format::Gltf | Format::Glb => Err(text::ParseError::new(0, "glTF is read whole")),
    }
    .map_err(located)?;
    notes.format = Some(format);
    if notes.non_triangles == 0 {
        notes.polygon_of = Vec::new();
    }
    Ok((mesh, notes))
}

fn io_err(path: &Path, source: std::io::Error) -> MeshError {
    MeshError::Io {
        path: path.to_path_buf(),
        source,
    }
}

pub(crate) fn write_err(path: &Path, source: std::io::Error) -> MeshError {
    MeshError::Write {
        path: path.to_path_buf(),
        source,
    }
}

/// Largest accepted expansion of a gzip-compressed mesh file: real meshes expand 2-5x, so
/// anything beyond this many times the compressed size (and beyond
/// [`GZIP_MIN_LIMIT`]) is refused as a decompression bomb instead of filling memory.
pub const GZIP_MAX_RATIO: u64 = 100;
/// Decompressed bytes always accepted, whatever the compressed size.
pub const GZIP_MIN_LIMIT: u64 = 64 << 20;

fn read_bytes(path: &Path, gz: bool) -> Result<Vec<u8>, MeshError> {
    let raw = std::fs::read(path).map_err(|e| io_err(path, e))?;
    if !gz {
        return Ok(raw);
    }
    gunzip_bounded(&raw).map_err(|message| MeshError::Parse {
        path: path.to_path_buf(),
        line: 0,
        message,
    })
}

/// The most bytes a gzip stream of `compressed` bytes may expand to:
/// `max(GZIP_MIN_LIMIT, GZIP_MAX_RATIO x compressed size)`, so memory and time stay
/// proportional to the bytes in the file.
fn gzip_limit(compressed: u64) -> u64 {
    GZIP_MIN_LIMIT.max(GZIP_MAX_RATIO.saturating_mul(compressed))
}

fn bomb(limit: u64) -> String {
    format!(
        "gzip: the data expands to more than {limit} bytes ({GZIP_MAX_RATIO}x the \
         compressed size): refused as a decompression bomb"
    )
}

/// A gzip stream that refuses to expand beyond `limit` bytes; its errors are
/// `InvalidData` (the file's fault) and say "gzip".
struct Gunzip<R: Read> {
    inner: flate2::read::MultiGzDecoder<R>,
    left: u64,
    limit: u64,
}

impl<R: Read> Read for Gunzip<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let invalid = |m: String| std::io::Error::new(std::io::ErrorKind::InvalidData, m);
        let n = (self.inner.read(buf)).map_err(|e| invalid(format!("gzip: {e}")))?;
        self.left = (self.left.checked_sub(n as u64)).ok_or_else(|| invalid(bomb(self.limit)))?;
        Ok(n)
    }
}

/// Decompresses `raw`, refusing output beyond [`gzip_limit`].
fn gunzip_bounded(raw: &[u8]) -> Result<Vec<u8>, String> {
    let limit = gzip_limit(raw.len() as u64);
    let mut out = Vec::with_capacity(raw.len().saturating_mul(4));
    flate2::read::MultiGzDecoder::new(raw)
        .take(limit.saturating_add(1))
        .read_to_end(&mut out)
        .map_err(|e| format!("gzip: {e}"))?;
    if out.len() as u64 > limit {
        return Err(bomb(limit));
    }
    Ok(out)
}

/// Writes a mesh, choosing the format from the extension: OBJ (with `vt` when the mesh has
/// texture coordinates), OFF (positions and triangles only) or binary little-endian PLY
/// (double positions; texture coordinates as a per-face `texcoord` list). A trailing `.gz`
/// compresses. Positions are written exactly (shortest round-trip decimal, or raw doubles).
/// The file is written atomically ([`write_atomic`]). A `.glb` or `.gltf` path writes glTF
/// ([`gltf::GltfScene`]: 32-bit float positions, texture coordinates split at seams).
pub fn save(path: &Path, mesh: &TriMesh) -> Result<(), MeshError> {
    check_output_name(path)?;
    if gltf::is_gltf_path(path) {
        return gltf::GltfScene::from_mesh(mesh).save(path);
    }
    let (format, gz) = Format::from_path(path)?;
    let bytes = to_bytes(mesh, format).map_err(|e| write_err(path, e))?;
    write_atomic(path, |w| {
        if gz {
            let mut enc = flate2::write::GzEncoder::new(w, flate2::Compression::default());
            enc.write_all(&bytes)?;
            enc.finish().map(drop)
        } else {
            w.write_all(&bytes)
        }
    })
    .map_err(|e| write_err(path, e))
}

/// Checks that [`save`] writes the format `path`'s extension names (OBJ, OFF, PLY,
/// optionally `.gz`, or glTF `.glb`/`.gltf`) and that the name is one to write
/// ([`check_output_name`]), before any work is done. The error names the extension and
/// lists those written.
///
/// ```
/// use std::path::Path;
/// use wavg_mesh::io::check_save_path;
/// assert!(check_save_path(Path::new("a.glb")).is_ok());
/// assert!(check_save_path(Path::new("a.ply.gz")).is_ok());
/// assert!(check_save_path(Path::new("a.stl")).is_err());
/// assert!(check_save_path(Path::new("a.gltf.gz")).is_err());
/// ```
pub fn check_save_path(path: &Path) -> Result<(), MeshError> {
    check_output_name(path)?;
    if gltf::is_gltf_path(path) {
        return Ok(());
    }
    Format::from_path(path).map(drop)
}

/// The extensions [`save`] writes, for messages.
const WRITTEN: &str = ".obj, .off or .ply (each optionally .gz), .glb or .gltf";

/// Refuses an output file name that the readers would take for another file or that no
/// writer makes, whatever the output holds: a `#NAME` after `.glb` or `.gltf` (it selects
/// one mesh when reading, [`gltf::split_mesh_name`], so the file written could not be
/// read under that name), and gzip-compressed glTF (`.glb.gz`, `.gltf.gz`: glTF files
/// are written uncompressed). Every command checks its outputs with it before any work.
///
/// ```
/// use std::path::Path;
/// use wavg_mesh::io::check_output_name;
/// assert!(check_output_name(Path::new("a.glb")).is_ok());
/// assert!(check_output_name(Path::new("frames")).is_ok());
/// assert!(check_output_name(Path::new("m#1.obj")).is_ok());
/// assert!(check_output_name(Path::new("a.glb#Body")).is_err());
/// assert!(check_output_name(Path::new("a.gltf.gz")).is_err());
/// ```
pub fn check_output_name(path: &Path) -> Result<(), MeshError> {
    let (file, name) = gltf::split_mesh_name(path);
    if let Some(name) = name {
        return Err(MeshError::InvalidArgument(format!(
            "{}: #{name} selects a mesh when a glTF file is read and is not part of an \
             output file's name: write {}",
            path.display(),
            file.display()
        )));
    }
    if let Ok((f @ (Format::Gltf | Format::Glb), true)) = Format::from_path(path) {
        let ext = if f == Format::Glb {
            ".glb.gz"
        } else {
            ".gltf.gz"
        };
        return Err(MeshError::Unsupported {
            path: path.to_path_buf(),
            message: format!(
                "{ext} is not written (glTF is written uncompressed); write {WRITTEN}"
            ),
        });
    }
    Ok(())
}

/// Serialises a mesh in memory (uncompressed; `.glb` as one binary glTF file).
pub fn to_bytes(mesh: &TriMesh, format: Format) -> std::io::Result<Vec<u8>> {
    match format {
        Format::Obj => Ok(obj::write(mesh)),
        Format::Off => Ok(off::write(mesh)),
        Format::Ply => ply::write(mesh),
        Format::Glb => gltf::GltfScene::from_mesh(mesh)
            .to_glb()
            .map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidInput, e.to_string())),
        Format::Gltf => Err(std::io::Error::new(
            std::io::ErrorKind::Unsupported,
            "a .gltf file is two files (JSON and .bin): write it with `save`",
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gzip(data: &[u8]) -> Vec<u8> {
        let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::best());
        enc.write_all(data).unwrap();
        enc.finish().unwrap()
    }

    #[test]
    fn gzip_within_the_limit_round_trips() {
        let text = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n".repeat(1000);
        assert_eq!(gunzip_bounded(&gzip(&text)).unwrap(), text);
    }

    #[test]
    fn gzip_bomb_is_refused_in_bounded_memory() {
        // 200 MB of zeros compress to about 200 KB: far beyond 100x.
        let zeros = vec![0u8; 200 << 20];
        let bomb = gzip(&zeros);
        drop(zeros);
        assert!(bomb.len() < 1 << 20);
        let e = gunzip_bounded(&bomb).unwrap_err();
        assert!(e.contains("decompression bomb"), "{e}");
    }
}
