//! The `.wavg` file: an embedding together with a fingerprint of the mesh it belongs to.
//! [`load`] checks everything a reader must check; [`save`] writes atomically.
//!
#![doc = include_str!("../FORMAT.md")]

use std::io::{Read, Write};
use std::path::Path;

use wavg_mesh::TriMesh;

pub use crate::checksum::{FNV_OFFSET, WordHash, fnv1a64, mesh_fingerprint, mesh_hash};
use crate::error::EmbedError;
use crate::{Embedding, EmbeddingParams};

/// The magic bytes that start every `.wavg` file.
pub const MAGIC: [u8; 8] = *b"WAVGEMB\0";
/// The format version this build writes and the highest it reads (it reads every version
/// from 1 up).
pub const FORMAT_VERSION: u32 = 2;
/// Maximum embedding dimension (coordinates are stored in `[f64; MAX_DIM]` in memory).
pub const MAX_DIM: usize = 8;
/// Size of the fixed header in bytes.
pub const HEADER_LEN: usize = 128;

/// Exact file length for the given counts, or `None` on overflow.
fn file_len(n_vertices: u64, dim: u64, n_landmarks: u64) -> Option<u64> {
    let coords = n_vertices.checked_mul(dim)?.checked_mul(8)?;
    let ids = n_landmarks.checked_mul(4)?;
    let pad = if n_landmarks % 2 == 1 { 4 } else { 0 };
    (HEADER_LEN as u64)
        .checked_add(coords)?
        .checked_add(ids)?
        .checked_add(pad)?
        .checked_add(8)
}

/// Rows of coordinates converted and checksummed per block when writing or reading (1 MiB
/// at 8 dimensions): the file is streamed, never held in memory beside the embedding.
const BLOCK_ROWS: usize = 1 << 14;

/// Checks `emb` against `mesh` and returns the exact file length.
fn checked_len(emb: &Embedding, mesh: &TriMesh) -> Result<usize, EmbedError> {
    emb.validate(mesh.n_vertices())
        .map_err(|m| EmbedError::InvalidArgument(format!("cannot save embedding: {m}")))?;
    file_len(
        mesh.n_vertices() as u64,
        emb.dim as u64,
        emb.landmarks.len() as u64,
    )
    .and_then(|l| usize::try_from(l).ok())
    .ok_or_else(|| EmbedError::InvalidArgument("embedding too large".into()))
}

/// The fixed header of `emb` for `mesh` (version 2: the fingerprint is
/// [`mesh_fingerprint`]).
fn header(emb: &Embedding, mesh: &TriMesh) -> Vec<u8> {
    let mut b = Vec::with_capacity(HEADER_LEN);
    b.extend_from_slice(&MAGIC);
    b.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    b.extend_from_slice(&(emb.dim as u32).to_le_bytes());
    b.extend_from_slice(&(mesh.n_vertices() as u64).to_le_bytes());
    b.extend_from_slice(&(mesh.n_faces() as u64).to_le_bytes());
    b.extend_from_slice(&mesh_fingerprint(mesh).to_le_bytes());
    b.extend_from_slice(&(emb.landmarks.len() as u64).to_le_bytes());
    let p = &emb.params;
    b.extend_from_slice(&p.landmarks_requested.to_le_bytes());
    b.extend_from_slice(&p.seed.to_le_bytes());
    b.extend_from_slice(&p.mds_max_iterations.to_le_bytes());
    b.extend_from_slice(&p.mds_tolerance.to_le_bytes());
    b.extend_from_slice(&p.geodesic_mesh_vertices.to_le_bytes());
    b.extend_from_slice(&emb.stress.to_le_bytes());
    b.extend_from_slice(&emb.geodesic_rel_err_p50.to_le_bytes());
    b.extend_from_slice(&emb.geodesic_rel_err_p90.to_le_bytes());
    b.extend_from_slice(&[0u8; 16]);
    debug_assert_eq!(b.len(), HEADER_LEN);
    b
}

/// Writes the version-2 bytes of `emb` (already checked by [`checked_len`]) to `w`, a
/// block at a time, with the running checksum.
fn write_embedding(emb: &Embedding, mesh: &TriMesh, w: &mut dyn Write) -> std::io::Result<()> {
    let head = header(emb, mesh);
    let mut sum = WordHash::new();
    sum.bytes(&head);
    w.write_all(&head)?;
    let mut buf = Vec::with_capacity(BLOCK_ROWS * emb.dim * 8);
    for block in emb.coords.chunks(BLOCK_ROWS) {
        buf.clear();
        for c in block {
            for x in &c[..emb.dim] {
                let bits = x.to_bits();
                sum.word(bits);
                buf.extend_from_slice(&bits.to_le_bytes());
            }
        }
        w.write_all(&buf)?;
    }
    buf.clear();
    buf.extend(emb.landmarks.iter().flat_map(|l| l.to_le_bytes()));
    if emb.landmarks.len() % 2 == 1 {
        buf.extend_from_slice(&[0u8; 4]);
    }
    sum.bytes(&buf);
    w.write_all(&buf)?;
    w.write_all(&sum.finish().to_le_bytes())
}

/// Serialises `emb` for `mesh` into the version-2 byte layout.
///
/// Errors if the embedding does not satisfy [`Embedding::validate`] for this mesh.
pub fn encode(emb: &Embedding, mesh: &TriMesh) -> Result<Vec<u8>, EmbedError> {
    let len = checked_len(emb, mesh)?;
    let mut b = Vec::with_capacity(len);
    write_embedding(emb, mesh, &mut b).map_err(|e| EmbedError::Numerical(e.to_string()))?;
    debug_assert_eq!(b.len(), len);
    Ok(b)
}

/// Why a byte buffer is not an acceptable `.wavg` for a mesh (before the path is attached).
#[derive(Debug)]
enum Fault {
    Bad(String),
    Version(u32),
    Mesh(String),
}

impl Fault {
    fn at(self, path: &Path) -> EmbedError {
        let path = path.to_path_buf();
        match self {
            Fault::Bad(message) => EmbedError::BadFile { path, message },
            Fault::Version(found) => EmbedError::UnsupportedVersion {
                path,
                found,
                supported: FORMAT_VERSION,
            },
            Fault::Mesh(message) => EmbedError::MeshMismatch { path, message },
        }
    }
}

/// Little-endian cursor over a byte slice whose length was checked beforehand.
struct Reader<'a> {
    b: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn take<const N: usize>(&mut self) -> [u8; N] {
        let mut a = [0u8; N];
        a.copy_from_slice(&self.b[self.at..self.at + N]);
        self.at += N;
        a
    }
    fn u32(&mut self) -> u32 {
        u32::from_le_bytes(self.take())
    }
    fn u64(&mut self) -> u64 {
        u64::from_le_bytes(self.take())
    }
    fn f64(&mut self) -> f64 {
        f64::from_le_bytes(self.take())
    }
}

/// Parsed fixed header.
struct Header {
    version: u32,
    dim: u32,
    n_vertices: u64,
    n_faces: u64,
    hash: u64,
    n_landmarks: u64,
}

/// Checks magic and version and reads the counts; `head` holds the first bytes of the file
/// (up to [`HEADER_LEN`]) and `total` is the file length.
fn parse_header(head: &[u8], total: u64) -> Result<Header, Fault> {
    if head.len() < MAGIC.len() || head[..MAGIC.len()] != MAGIC {
        return Err(Fault::Bad("not a .wavg file (bad magic bytes)".into()));
    }
    if head.len() < 12 {
        return Err(Fault::Bad(format!(
            "truncated: {total} bytes, shorter than the header"
        )));
    }
    let mut r = Reader { b: head, at: 8 };
    let version = r.u32();
    if version > FORMAT_VERSION {
        return Err(Fault::Version(version));
    }
    if version == 0 {
        return Err(Fault::Bad("corrupt: format version 0".into()));
    }
    if head.len() < HEADER_LEN {
        return Err(Fault::Bad(format!(
            "truncated: {total} bytes, shorter than the {HEADER_LEN}-byte header"
        )));
    }
    let dim = r.u32();
    let n_vertices = r.u64();
    let n_faces = r.u64();
    let hash = r.u64();
    let n_landmarks = r.u64();
    if dim == 0 || dim as usize > MAX_DIM {
        return Err(Fault::Bad(format!(
            "corrupt: dimension {dim} not in 1..={MAX_DIM}"
        )));
    }
    if n_landmarks > n_vertices {
        return Err(Fault::Bad(format!(
            "corrupt: {n_landmarks} landmarks for {n_vertices} vertices"
        )));
    }
    let expected = file_len(n_vertices, u64::from(dim), n_landmarks)
        .ok_or_else(|| Fault::Bad("corrupt: counts overflow".into()))?;
    if total < expected {
        return Err(Fault::Bad(format!(
            "truncated: {total} bytes, the header announces {expected}"
        )));
    }
    if total > expected {
        return Err(Fault::Bad(format!(
            "corrupt: {total} bytes, the header announces {expected}"
        )));
    }
    Ok(Header {
        version,
        dim,
        n_vertices,
        n_faces,
        hash,
        n_landmarks,
    })
}

/// Why reading a `.wavg` stream failed: its content, or the reading itself.
enum ReadFault {
    Fault(Fault),
    Io(std::io::Error),
}

impl From<Fault> for ReadFault {
    fn from(f: Fault) -> Self {
        Self::Fault(f)
    }
}

impl From<std::io::Error> for ReadFault {
    fn from(e: std::io::Error) -> Self {
        Self::Io(e)
    }
}

/// Reads into `buf` until it is full or the stream ends; the bytes read.
fn read_up_to(r: &mut dyn Read, buf: &mut [u8]) -> std::io::Result<usize> {
    let mut got = 0;
    while got < buf.len() {
        match r.read(&mut buf[got..]) {
            Ok(0) => break,
            Ok(k) => got += k,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(got)
}

/// The body of a `.wavg` stream after its header: checksum over everything before the
/// stored one, that stored checksum, the coordinates (only when the vertex count is the
/// mesh's; otherwise the file is refused anyway) and the landmark bytes with padding.
struct Body {
    sum: u64,
    stored: u64,
    coords: Vec<[f64; MAX_DIM]>,
    tail: Vec<u8>,
}

/// A running checksum of either format version.
enum Running {
    /// Version 1: FNV-1a 64, a byte at a time.
    Fnv(u64),
    /// Version 2 and later: [`WordHash`].
    Words(WordHash),
}

impl Running {
    fn new(version: u32) -> Self {
        if version == 1 {
            Self::Fnv(FNV_OFFSET)
        } else {
            Self::Words(WordHash::new())
        }
    }
    fn bytes(&mut self, b: &[u8]) {
        match self {
            Self::Fnv(h) => *h = fnv1a64(*h, b),
            Self::Words(h) => h.bytes(b),
        }
    }
    fn finish(&self) -> u64 {
        match self {
            Self::Fnv(h) => *h,
            Self::Words(h) => h.finish(),
        }
    }
}

/// The mesh fingerprint a file of `version` stores.
fn fingerprint(version: u32, mesh: &TriMesh) -> u64 {
    if version == 1 {
        mesh_hash(mesh)
    } else {
        mesh_fingerprint(mesh)
    }
}

/// Appends the rows of `block` (`dim` little-endian `f64` each) to `coords`, feeding each
/// word to the version-2 checksum `sum` on the way (one pass over the bytes).
fn convert_block(
    block: &[u8],
    dim: usize,
    mut sum: Option<&mut WordHash>,
    coords: &mut Vec<[f64; MAX_DIM]>,
) {
    for row in block.chunks_exact(dim * 8) {
        let mut c = [0.0; MAX_DIM];
        for (x, b) in c.iter_mut().zip(row.chunks_exact(8)) {
            let mut a = [0u8; 8];
            a.copy_from_slice(b);
            let w = u64::from_le_bytes(a);
            if let Some(h) = sum.as_deref_mut() {
                h.word(w);
            }
            *x = f64::from_bits(w);
        }
        coords.push(c);
    }
}

/// Reads the body announced by `h` a block at a time, checksumming as it goes.
fn read_body(
    r: &mut (dyn Read + Send),
    head: &[u8],
    h: &Header,
    keep: bool,
) -> std::io::Result<Body> {
    let dim = h.dim as usize;
    let mut sum = Running::new(h.version);
    sum.bytes(head);
    let mut coords = Vec::new();
    if keep {
        coords.reserve_exact(h.n_vertices as usize);
    }
    let mut buf = vec![0u8; BLOCK_ROWS * dim * 8];
    let mut left = h.n_vertices;
    while left > 0 {
        let rows = left.min(BLOCK_ROWS as u64) as usize;
        let block = &mut buf[..rows * dim * 8];
        r.read_exact(block)?;
        match (&mut sum, keep) {
            (Running::Words(w), true) => convert_block(block, dim, Some(w), &mut coords),
            (_, true) => {
                sum.bytes(block);
                convert_block(block, dim, None, &mut coords);
            }
            (_, false) => sum.bytes(block),
        }
        left -= rows as u64;
    }
    let k = h.n_landmarks as usize;
    let mut tail = vec![0u8; k * 4 + if k % 2 == 1 { 4 } else { 0 }];
    r.read_exact(&mut tail)?;
    sum.bytes(&tail);
    let mut stored = [0u8; 8];
    r.read_exact(&mut stored)?;
    Ok(Body {
        sum: sum.finish(),
        stored: u64::from_le_bytes(stored),
        coords,
        tail,
    })
}

/// Reads and fully checks a `.wavg` stream of `total` bytes against `mesh`. The mesh's
/// fingerprint is computed beside the reading (both are serial checksums).
fn read_embedding(
    r: &mut (dyn Read + Send),
    total: u64,
    mesh: &TriMesh,
) -> Result<Embedding, ReadFault> {
    let mut head = [0u8; HEADER_LEN];
    let got = read_up_to(r, &mut head)?;
    let head = &head[..got];
    let h = parse_header(head, total)?;
    let keep = h.n_vertices == mesh.n_vertices() as u64;
    let (fingerprint, body) = rayon::join(
        || fingerprint(h.version, mesh),
        || read_body(r, head, &h, keep),
    );
    let body = body?;
    if body.sum != body.stored {
        return Err(Fault::Bad("corrupt: checksum mismatch".into()).into());
    }
    if !keep || h.n_faces != mesh.n_faces() as u64 {
        return Err(Fault::Mesh(format!(
            "file is for {} vertices / {} faces, mesh has {} / {}",
            h.n_vertices,
            h.n_faces,
            mesh.n_vertices(),
            mesh.n_faces()
        ))
        .into());
    }
    if h.hash != fingerprint {
        return Err(Fault::Mesh(
            "same counts but different positions or faces (fingerprint mismatch)".into(),
        )
        .into());
    }
    let mut r = Reader { b: head, at: 48 };
    let params = EmbeddingParams {
        landmarks_requested: r.u64(),
        seed: r.u64(),
        mds_max_iterations: r.u64(),
        mds_tolerance: r.f64(),
        geodesic_mesh_vertices: r.u64(),
    };
    let stress = r.f64();
    let p50 = r.f64();
    let p90 = r.f64();
    if head[112..HEADER_LEN].iter().any(|&x| x != 0) {
        return Err(Fault::Bad("corrupt: reserved header bytes are not zero".into()).into());
    }
    let k = h.n_landmarks as usize;
    let landmarks: Vec<u32> = (body.tail[..k * 4].chunks_exact(4))
        .map(|b| u32::from_le_bytes(b.try_into().unwrap_or_default()))
        .collect();
    if body.tail[k * 4..].iter().any(|&x| x != 0) {
        return Err(Fault::Bad("corrupt: padding bytes are not zero".into()).into());
    }
    let emb = Embedding {
        dim: h.dim as usize,
        coords: body.coords,
        landmarks,
        params,
        stress,
        geodesic_rel_err_p50: p50,
        geodesic_rel_err_p90: p90,
    };
    emb.validate(mesh.n_vertices())
        .map_err(|m| Fault::Bad(format!("corrupt: {m}")))?;
    Ok(emb)
}

/// Parses a `.wavg` image held in memory; `path` only labels errors.
pub fn decode(bytes: &[u8], mesh: &TriMesh, path: &Path) -> Result<Embedding, EmbedError> {
    read_embedding(&mut &bytes[..], bytes.len() as u64, mesh).map_err(|f| match f {
        ReadFault::Fault(f) => f.at(path),
        // The header was checked against the slice's length: reading cannot fail.
        ReadFault::Io(e) => Fault::Bad(format!("unreadable: {e}")).at(path),
    })
}

/// Writes `emb` (computed for `mesh`) to `path` atomically.
///
/// The bytes go to a temporary file in the same directory, which is flushed to disk and
/// then renamed over `path`.
///
/// ```
/// use wavg_embed::file::{load, save};
/// use wavg_embed::{Embedding, EmbeddingParams};
/// let mesh = wavg_mesh::procedural::icosphere(1);
/// let emb = Embedding {
///     dim: 8,
///     coords: mesh.positions.iter().map(|p| [p.x, p.y, p.z, 0.0, 0.0, 0.0, 0.0, 0.0]).collect(),
///     landmarks: vec![0, 5, 7],
///     params: EmbeddingParams::default(),
///     stress: 0.0,
///     geodesic_rel_err_p50: f64::NAN,
///     geodesic_rel_err_p90: f64::NAN,
/// };
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("sphere.wavg");
/// save(&path, &emb, &mesh).unwrap();
/// assert_eq!(load(&path, &mesh).unwrap().coords, emb.coords);
/// ```
pub fn save(path: &Path, emb: &Embedding, mesh: &TriMesh) -> Result<(), EmbedError> {
    checked_len(emb, mesh)?;
    wavg_mesh::io::write_atomic(path, |w| write_embedding(emb, mesh, w)).map_err(|source| {
        EmbedError::Write {
            path: path.to_path_buf(),
            source,
        }
    })?;
    crate::memtrace::mark(".wavg written");
    Ok(())
}

/// Reads and checks a `.wavg` file for `mesh`.
///
/// Refuses (with [`EmbedError::BadFile`]) anything that is not a complete, uncorrupted
/// file of version 1 or 2; with [`EmbedError::UnsupportedVersion`] a file from a newer format; with
/// [`EmbedError::MeshMismatch`] a file computed for another mesh. The header is checked
/// against the real file length before the body is read, so a corrupt header never causes
/// a large allocation. The file is streamed a block at a time into the embedding.
pub fn load(path: &Path, mesh: &TriMesh) -> Result<Embedding, EmbedError> {
    let io = |source| EmbedError::Io {
        path: path.to_path_buf(),
        source,
    };
    let f = std::fs::File::open(path).map_err(io)?;
    let total = f.metadata().map_err(io)?.len();
    let mut r = std::io::BufReader::with_capacity(1 << 16, f);
    read_embedding(&mut r, total, mesh).map_err(|e| match e {
        ReadFault::Fault(f) => f.at(path),
        ReadFault::Io(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => {
            Fault::Bad("file changed size while being read".into()).at(path)
        }
        ReadFault::Io(e) => io(e),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use rand::{Rng, SeedableRng};
    use wavg_mesh::procedural;

    fn sample(mesh: &TriMesh, dim: usize, n_landmarks: usize, seed: u64) -> Embedding {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let coords = (0..mesh.n_vertices())
            .map(|_| {
                let mut c = [0.0; MAX_DIM];
                for x in &mut c[..dim] {
                    *x = rng.random_range(-10.0..10.0);
                }
                c
            })
            .collect();
        Embedding {
            dim,
            coords,
            landmarks: (0..n_landmarks as u32)
                .map(|i| i * 5 % mesh.n_vertices() as u32)
                .collect(),
            params: EmbeddingParams {
                landmarks_requested: n_landmarks as u64,
                seed,
                mds_max_iterations: 123,
                mds_tolerance: 1e-7,
                geodesic_mesh_vertices: 0,
            },
            stress: 0.0123,
            geodesic_rel_err_p50: 0.01,
            geodesic_rel_err_p90: f64::NAN,
        }
    }

    fn bits(e: &Embedding) -> Vec<u64> {
        let mut v: Vec<u64> = e.coords.iter().flatten().map(|x| x.to_bits()).collect();
        v.extend(e.landmarks.iter().map(|&l| u64::from(l)));
        let p = &e.params;
        v.extend([
            e.dim as u64,
            e.stress.to_bits(),
            e.geodesic_rel_err_p50.to_bits(),
            e.geodesic_rel_err_p90.to_bits(),
            p.landmarks_requested,
            p.seed,
            p.mds_max_iterations,
            p.mds_tolerance.to_bits(),
            p.geodesic_mesh_vertices,
        ]);
        v
    }

    fn p() -> &'static Path {
        Path::new("test.wavg")
    }

    /// A version-1 file as the version-1 writer made it: the same layout, version 1, the
    /// FNV-1a 64 fingerprint ([`mesh_hash`]) and FNV-1a 64 checksum.
    fn encode_v1(emb: &Embedding, mesh: &TriMesh) -> Vec<u8> {
        let mut b = encode(emb, mesh).unwrap();
        b[8..12].copy_from_slice(&1u32.to_le_bytes());
        b[32..40].copy_from_slice(&mesh_hash(mesh).to_le_bytes());
        reseal(&mut b);
        b
    }

    /// Version-1 files still open, bit-exact, through memory and the file system, and
    /// refuse every truncation, single-byte change and other mesh as before.
    #[test]
    fn version_1_files_still_open_and_are_checked() {
        let mesh = procedural::torus(12, 8, 1.0, 0.3);
        let emb = sample(&mesh, 8, 7, 9);
        let v1 = encode_v1(&emb, &mesh);
        assert_eq!(bits(&decode(&v1, &mesh, p()).unwrap()), bits(&emb));
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("v1.wavg");
        std::fs::write(&path, &v1).unwrap();
        assert_eq!(bits(&load(&path, &mesh).unwrap()), bits(&emb));
        // A version-2 checksum or fingerprint in a version-1 file is refused.
        let mut v2 = encode(&emb, &mesh).unwrap();
        v2[8..12].copy_from_slice(&1u32.to_le_bytes());
        assert!(matches!(
            decode(&v2, &mesh, p()),
            Err(EmbedError::BadFile { .. })
        ));
        reseal(&mut v2);
        assert!(matches!(
            decode(&v2, &mesh, p()),
            Err(EmbedError::MeshMismatch { .. })
        ));
        let small = procedural::icosphere(0);
        let v1 = encode_v1(&sample(&small, 8, 5, 3), &small);
        for cut in 0..v1.len() {
            assert!(decode(&v1[..cut], &small, p()).is_err(), "cut {cut}");
        }
        for at in 0..v1.len() {
            for x in [0x01u8, 0x80, 0xff] {
                let mut c = v1.clone();
                c[at] ^= x;
                assert!(decode(&c, &small, p()).is_err(), "flip {x:#x} at {at}");
            }
        }
        let mut moved = small.clone();
        moved.positions[7].x = f64::from_bits(moved.positions[7].x.to_bits() + 1);
        assert!(matches!(
            decode(&v1, &moved, p()),
            Err(EmbedError::MeshMismatch { .. })
        ));
    }

    /// Every bit flipped anywhere in a version-2 file is refused.
    #[test]
    fn every_single_bit_flip_is_refused() {
        let mesh = procedural::icosphere(0);
        let b = encode(&sample(&mesh, 3, 3, 4), &mesh).unwrap();
        for at in 0..b.len() {
            for bit in 0..8 {
                let mut c = b.clone();
                c[at] ^= 1 << bit;
                assert!(decode(&c, &mesh, p()).is_err(), "bit {bit} of byte {at}");
            }
        }
    }

    #[test]
    fn round_trip_is_bit_exact_through_a_file() {
        let mesh = procedural::torus(12, 8, 1.0, 0.3);
        for (dim, k) in [(8, 7), (8, 8), (3, 0), (1, 1)] {
            let emb = sample(&mesh, dim, k, 42 + k as u64);
            let dir = tempfile::tempdir().unwrap();
            let path = dir.path().join("t.wavg");
            save(&path, &emb, &mesh).unwrap();
            let back = load(&path, &mesh).unwrap();
            assert_eq!(bits(&back), bits(&emb));
            let len = std::fs::metadata(&path).unwrap().len();
            assert_eq!(
                Some(len),
                file_len(mesh.n_vertices() as u64, dim as u64, k as u64)
            );
            // Only the final file is left in the directory.
            assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
        }
    }

    #[test]
    fn header_layout_matches_the_documentation() {
        let mesh = procedural::icosphere(0);
        let emb = sample(&mesh, 8, 3, 1);
        let b = encode(&emb, &mesh).unwrap();
        assert_eq!(&b[..8], b"WAVGEMB\0");
        assert_eq!(u32::from_le_bytes(b[8..12].try_into().unwrap()), 2);
        assert_eq!(u32::from_le_bytes(b[12..16].try_into().unwrap()), 8);
        assert_eq!(u64::from_le_bytes(b[16..24].try_into().unwrap()), 12);
        assert_eq!(u64::from_le_bytes(b[24..32].try_into().unwrap()), 20);
        assert_eq!(
            u64::from_le_bytes(b[32..40].try_into().unwrap()),
            mesh_fingerprint(&mesh)
        );
        assert_eq!(u64::from_le_bytes(b[40..48].try_into().unwrap()), 3);
        assert_eq!(
            f64::from_le_bytes(b[88..96].try_into().unwrap()),
            emb.stress
        );
        let c0 = f64::from_le_bytes(b[128..136].try_into().unwrap());
        assert_eq!(c0, emb.coords[0][0]);
        let ids = 128 + 12 * 8 * 8;
        assert_eq!(
            u32::from_le_bytes(b[ids + 4..ids + 8].try_into().unwrap()),
            emb.landmarks[1]
        );
        let body = b.len() - 8;
        assert_eq!(body % 8, 0);
        let sum = u64::from_le_bytes(b[body..].try_into().unwrap());
        let mut h = WordHash::new();
        h.bytes(&b[..body]);
        assert_eq!(sum, h.finish());
        // Version 1 has the same layout, with FNV-1a 64 for the fingerprint and checksum.
        let v1 = encode_v1(&emb, &mesh);
        assert_eq!(u32::from_le_bytes(v1[8..12].try_into().unwrap()), 1);
        assert_eq!(
            u64::from_le_bytes(v1[32..40].try_into().unwrap()),
            mesh_hash(&mesh)
        );
        let sum = u64::from_le_bytes(v1[body..].try_into().unwrap());
        assert_eq!(sum, fnv1a64(FNV_OFFSET, &v1[..body]));
        assert_eq!(v1[40..body], b[40..body]);
    }

    #[test]
    fn every_truncation_is_refused() {
        let mesh = procedural::icosphere(0);
        let b = encode(&sample(&mesh, 8, 5, 3), &mesh).unwrap();
        for cut in 0..b.len() {
            let e = decode(&b[..cut], &mesh, p()).unwrap_err();
            assert!(matches!(e, EmbedError::BadFile { .. }), "cut {cut}: {e}");
        }
        // And through the file system, at a few offsets including inside the header.
        let dir = tempfile::tempdir().unwrap();
        for cut in [0, 7, 8, 11, 60, 127, 128, b.len() - 1] {
            let path = dir.path().join(format!("cut{cut}.wavg"));
            std::fs::write(&path, &b[..cut]).unwrap();
            assert!(matches!(
                load(&path, &mesh),
                Err(EmbedError::BadFile { .. })
            ));
        }
        assert!(decode(&b, &mesh, p()).is_ok());
    }

    #[test]
    fn every_single_byte_change_is_refused() {
        let mesh = procedural::icosphere(0);
        let b = encode(&sample(&mesh, 8, 5, 3), &mesh).unwrap();
        for at in 0..b.len() {
            for x in [0x01u8, 0x80, 0xff] {
                let mut c = b.clone();
                c[at] ^= x;
                assert!(
                    decode(&c, &mesh, p()).is_err(),
                    "flip {x:#x} at {at} accepted"
                );
            }
        }
    }

    #[test]
    fn appended_bytes_are_refused() {
        let mesh = procedural::icosphere(0);
        let mut b = encode(&sample(&mesh, 8, 2, 3), &mesh).unwrap();
        b.push(0);
        assert!(matches!(
            decode(&b, &mesh, p()),
            Err(EmbedError::BadFile { .. })
        ));
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(200))]
        #[test]
        fn random_multi_byte_corruption_is_refused(
            flips in proptest::collection::vec((any::<prop::sample::Index>(), 1u8..=255), 1..6)
        ) {
            let mesh = procedural::icosphere(1);
            let b = encode(&sample(&mesh, 8, 9, 5), &mesh).unwrap();
            let mut c = b.clone();
            for (i, x) in &flips {
                let at = i.index(c.len());
                c[at] ^= x;
            }
            prop_assume!(c != b);
            prop_assert!(decode(&c, &mesh, p()).is_err());
        }
    }

    #[test]
    fn another_mesh_is_refused() {
        let mesh = procedural::icosphere(1);
        let b = encode(&sample(&mesh, 8, 4, 3), &mesh).unwrap();
        // Different counts.
        let other = procedural::icosphere(2);
        assert!(matches!(
            decode(&b, &other, p()),
            Err(EmbedError::MeshMismatch { .. })
        ));
        // Same counts, one coordinate moved by one ulp.
        let mut moved = mesh.clone();
        moved.positions[17].y = f64::from_bits(moved.positions[17].y.to_bits() + 1);
        assert!(matches!(
            decode(&b, &moved, p()),
            Err(EmbedError::MeshMismatch { .. })
        ));
        // Same positions, faces relabelled (rotated corners).
        let mut rotated = mesh.clone();
        let t = rotated.triangles[3];
        rotated.triangles[3] = [t[1], t[2], t[0]];
        assert!(matches!(
            decode(&b, &rotated, p()),
            Err(EmbedError::MeshMismatch { .. })
        ));
    }

    /// Rewrites the checksum after an edit, so the check under test is not the checksum
    /// (FNV-1a 64 for a version-1 file, else the word hash).
    fn reseal(b: &mut [u8]) {
        let body = b.len() - 8;
        let s = if b[8..12] == 1u32.to_le_bytes() {
            fnv1a64(FNV_OFFSET, &b[..body])
        } else {
            let mut h = WordHash::new();
            h.bytes(&b[..body]);
            h.finish()
        };
        b[body..].copy_from_slice(&s.to_le_bytes());
    }

    #[test]
    fn future_version_is_refused_with_a_typed_error() {
        let mesh = procedural::icosphere(0);
        let mut b = encode(&sample(&mesh, 8, 2, 3), &mesh).unwrap();
        b[8..12].copy_from_slice(&3u32.to_le_bytes());
        reseal(&mut b);
        match decode(&b, &mesh, p()) {
            Err(EmbedError::UnsupportedVersion {
                found: 3,
                supported: 2,
                ..
            }) => {}
            other => panic!("expected UnsupportedVersion, got {other:?}"),
        }
        // Even a future file with a different (unknown) layout length is reported as such.
        assert!(matches!(
            decode(&b[..40], &mesh, p()),
            Err(EmbedError::UnsupportedVersion { .. })
        ));
    }

    #[test]
    fn resealed_invalid_values_are_refused() {
        let mesh = procedural::icosphere(0);
        let good = encode(&sample(&mesh, 8, 2, 3), &mesh).unwrap();
        let ids = 128 + 12 * 8 * 8;
        let edits: Vec<(usize, Vec<u8>)> = vec![
            (128, f64::NAN.to_le_bytes().to_vec()), // non-finite coordinate
            (128 + 8, f64::INFINITY.to_le_bytes().to_vec()), // non-finite coordinate
            (ids, 12u32.to_le_bytes().to_vec()),    // landmark out of range
            (ids + 4, 0u32.to_le_bytes().to_vec()), // duplicate landmark (ids 0, 0)
            (112, vec![1]),                         // reserved byte
            (88, (-1.0f64).to_le_bytes().to_vec()), // negative stress
            (12, 9u32.to_le_bytes().to_vec()),      // dimension 9
            (40, u64::MAX.to_le_bytes().to_vec()),  // absurd landmark count
            (16, (u64::MAX / 4).to_le_bytes().to_vec()), // absurd vertex count
        ];
        for (at, bytes) in edits {
            let mut b = good.clone();
            b[at..at + bytes.len()].copy_from_slice(&bytes);
            reseal(&mut b);
            assert!(
                matches!(decode(&b, &mesh, p()), Err(EmbedError::BadFile { .. })),
                "edit at {at} accepted"
            );
        }
    }

    #[test]
    fn save_rejects_inconsistent_embeddings_and_keeps_old_file() {
        let mesh = procedural::icosphere(0);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("e.wavg");
        let good = sample(&mesh, 8, 2, 3);
        save(&path, &good, &mesh).unwrap();
        let mut bad = good.clone();
        bad.coords[3][2] = f64::NAN;
        assert!(matches!(
            save(&path, &bad, &mesh),
            Err(EmbedError::InvalidArgument(_))
        ));
        let mut bad = sample(&mesh, 3, 2, 3);
        bad.coords[0][5] = 1.0;
        assert!(save(&path, &bad, &mesh).is_err());
        let mut bad = good.clone();
        bad.coords.pop();
        assert!(save(&path, &bad, &mesh).is_err());
        assert_eq!(bits(&load(&path, &mesh).unwrap()), bits(&good));
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[cfg(unix)]
    #[test]
    fn saved_file_gets_the_permissions_of_a_new_file() {
        use std::os::unix::fs::PermissionsExt;
        let mesh = procedural::icosphere(0);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.wavg");
        save(&path, &sample(&mesh, 8, 2, 3), &mesh).unwrap();
        let plain = dir.path().join("plain");
        std::fs::File::create(&plain).unwrap();
        let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode(&path), mode(&plain));
    }

    #[test]
    fn missing_file_and_garbage_are_refused() {
        let mesh = procedural::icosphere(0);
        let dir = tempfile::tempdir().unwrap();
        assert!(matches!(
            load(&dir.path().join("none.wavg"), &mesh),
            Err(EmbedError::Io { .. })
        ));
        let path = dir.path().join("g.wavg");
        std::fs::write(&path, b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n").unwrap();
        assert!(matches!(
            load(&path, &mesh),
            Err(EmbedError::BadFile { .. })
        ));
    }
}
