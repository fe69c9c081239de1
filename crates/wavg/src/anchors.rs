//! Anchors: the anchors file (read, resolved against a mesh, written) and the anchor sets
//! every front end spreads the same way (`wavg anchors`, Python's `S.spread_anchors`, the
//! C ABI's `wavg_surface_spread_anchors`).
//!
//! An anchors file has one anchor per line, `v VERTEX` or `f FACE B0 B1 B2` (0-based
//! indices, barycentric coordinates of the face's corners); `#` starts a comment, blank
//! lines are skipped (the point format of [`crate::text`]).
//!
//! Spreading is farthest-point sampling in the embedding: the first vertex drawn from the
//! seed, each next one the vertex farthest (straight-line distance in R^8) from those
//! already chosen. Its quality is the largest gap, the largest distance from a vertex to
//! its nearest anchor, as a fraction of the bounding-box diagonal: [`GOOD_GAP`] or less
//! keeps about 90% of round trips on real meshes.
//!
//! ```
//! use wavg::{Anchor, Surface};
//! let surface = Surface::from_mesh(wavg::mesh::procedural::icosphere(3))?;
//! let anchors = surface.spread_anchors(20, 0)?;
//! let path = std::env::temp_dir().join(format!("wavg-anchors-doc-{}.txt", std::process::id()));
//! wavg::anchors::write(&path, &anchors)?;
//! assert_eq!(wavg::anchors::read(&path, surface.mesh())?, anchors);
//! # std::fs::remove_file(&path).ok();
//! # Ok::<(), wavg::Error>(())
//! ```

use std::path::Path;

use wavg_io::text::PointSpec;
use wavg_mesh::{MeshError, SurfacePoint, ValidMesh, VertexId};
use wavg_solve::{Anchor, SolveError, Vec8};

use crate::error::{Error, Result};
use crate::surface::Surface;

pub use wavg_solve::spread::{GOOD_GAP, closed_tour, suggested_count};

/// Reads an anchors file and checks every anchor against `mesh` (a UTF-8 byte order mark
/// opening the file is skipped; a `#` comment may hold any bytes, the rest must be UTF-8:
/// [`wavg_io::text::decode`]). Errors name the file and the line: a malformed line, a
/// vertex or face out of range, bad barycentric coordinates, or a file without anchors
/// ([`Error::Input`]); an unreadable file is an I/O error. The anchors come back as
/// written (tiny negative barycentrics are clamped when a solver resolves them).
pub fn read(path: impl AsRef<Path>, mesh: &ValidMesh) -> Result<Vec<Anchor>> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|source| MeshError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let text = wavg_io::text::decode(bytes, 1).map_err(|e| Error::Input {
        path: path.to_path_buf(),
        line: e.line,
        message: e.message,
    })?;
    parse(&text, path, mesh)
}

/// Parses the text of an anchors file (see [`read`]); `file` names it in errors.
pub fn parse(text: &str, file: &Path, mesh: &ValidMesh) -> Result<Vec<Anchor>> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let at = |line: usize, message: &dyn std::fmt::Display| Error::Input {
        path: file.to_path_buf(),
        line,
        message: message.to_string().replace('\n', " "),
    };
    let specs = wavg_io::text::parse_points(text, 1).map_err(|e| at(e.line, &e.message))?;
    if specs.is_empty() {
        return Err(at(0, &"no anchors"));
    }
    specs
        .into_iter()
        .map(|(line, spec)| {
            let a = spec_anchor(spec).map_err(|m| at(line, &m))?;
            wavg_solve::resolve_anchor(mesh, &a).map_err(|e| at(line, &e))?;
            Ok(a)
        })
        .collect()
}

/// A point as written in a file, as an [`Anchor`] (indices must fit in 32 bits); the error
/// says which index is out of range.
pub fn spec_anchor(spec: PointSpec) -> std::result::Result<Anchor, String> {
    let idx =
        |i: u64, what: &str| u32::try_from(i).map_err(|_| format!("{what} {i} is out of range"));
    Ok(match spec {
        PointSpec::Vertex(v) => Anchor::Vertex(idx(v, "vertex")?),
        PointSpec::Face { face, bary } => {
            Anchor::Point(SurfacePoint::new(idx(face, "face")?, bary))
        }
    })
}

/// The anchors file's text: `v VERTEX` or `f FACE B0 B1 B2` lines (numbers in their
/// shortest round-trip form).
pub fn format(anchors: &[Anchor]) -> String {
    let mut out = Vec::new();
    for a in anchors {
        match a {
            Anchor::Vertex(v) => out.extend_from_slice(format!("v {v}").as_bytes()),
            Anchor::Point(p) => {
                out.extend_from_slice(format!("f {} ", p.face).as_bytes());
                wavg_io::text::push_numbers(&mut out, p.bary);
            }
        }
        out.push(b'\n');
    }
    String::from_utf8(out).unwrap_or_default()
}

/// Writes an anchors file ([`format()`]) atomically: a temporary file beside it, renamed
/// into place, so a failure leaves nothing at `path`. Only what [`read`] takes back is
/// written: no anchors, or barycentric coordinates that are not finite, clearly negative
/// or do not sum to 1, are an error ([`ErrorKind::InvalidArgument`](crate::ErrorKind))
/// and nothing is written.
pub fn write(path: impl AsRef<Path>, anchors: &[Anchor]) -> Result<()> {
    let path = path.as_ref();
    if anchors.is_empty() {
        return Err(SolveError::NoAnchors.into());
    }
    for a in anchors {
        if let Anchor::Point(p) = a {
            wavg_solve::check_barycentrics(p)?;
        }
    }
    let text = format(anchors);
    wavg_mesh::io::write_atomic(path, |w| w.write_all(text.as_bytes())).map_err(|source| {
        MeshError::Io {
            path: path.to_path_buf(),
            source,
        }
    })?;
    Ok(())
}

/// `k` vertices spread by farthest-point sampling in the embedding `coords` (one point
/// per vertex), the first drawn from `seed`: `wavg anchors --count k --seed seed`.
pub fn spread(mesh: &ValidMesh, coords: &[Vec8], k: usize, seed: u64) -> Result<Vec<VertexId>> {
    use wavg_solve::sampling::{FpsMetric, farthest_point_vertices};
    Ok(farthest_point_vertices(
        mesh,
        k,
        seed,
        FpsMetric::Embedding(coords),
    )?)
}

/// Spreads as [`spread`] does (the same order) until the largest gap is at most `target`
/// of the diagonal, with `min` to `max` anchors. Returns them and the gap reached.
pub fn spread_to_gap(
    mesh: &ValidMesh,
    coords: &[Vec8],
    seed: u64,
    min: usize,
    max: usize,
    target: f64,
) -> Result<(Vec<VertexId>, f64)> {
    Ok(wavg_solve::spread::spread_to_gap(
        mesh, coords, seed, min, max, target,
    )?)
}

/// The largest distance in the embedding `coords` from a vertex to its nearest anchor
/// among `anchors`, as a fraction of `mesh`'s bounding-box diagonal.
pub fn largest_gap(mesh: &ValidMesh, coords: &[Vec8], anchors: &[VertexId]) -> f64 {
    wavg_solve::spread::largest_gap(coords, anchors)
        / mesh.bounding_box_diagonal().max(f64::MIN_POSITIVE)
}

/// `k` distinct vertices of `mesh` drawn uniformly at random from `seed`: `wavg anchors
/// --method random`.
pub fn random(mesh: &ValidMesh, k: usize, seed: u64) -> Result<Vec<VertexId>> {
    Ok(wavg_solve::sampling::random_vertices(
        mesh.n_vertices(),
        k,
        seed,
    )?)
}

impl Surface {
    /// `k` vertices spread over the surface by farthest-point sampling in its embedding
    /// (the 3-D positions padded with zeros when it has none), the first drawn from
    /// `seed`: what `wavg anchors --count k --seed seed` writes for this embedding. A good
    /// default anchor set.
    ///
    /// ```
    /// let s = wavg::Surface::from_mesh(wavg::mesh::procedural::icosphere(2))?;
    /// let a = s.spread_anchors(8, 0)?;
    /// assert_eq!(a.len(), 8);
    /// assert_eq!(a, s.spread_anchors(8, 0)?);
    /// # Ok::<(), wavg::Error>(())
    /// ```
    pub fn spread_anchors(&self, k: usize, seed: u64) -> Result<Vec<Anchor>> {
        let v = spread(self.mesh(), self.embedded_coords(), k, seed)?;
        Ok(v.into_iter().map(Anchor::Vertex).collect())
    }

    /// Spreads anchors as [`Surface::spread_anchors`] does (the same order) until the
    /// largest gap is at most `target` of the diagonal ([`GOOD_GAP`] is a good target),
    /// with `min` to `max` of them. Returns the anchors and the gap reached.
    ///
    /// ```
    /// let s = wavg::Surface::from_mesh(wavg::mesh::procedural::icosphere(3))?;
    /// let (a, gap) = s.spread_anchors_to_gap(wavg::anchors::GOOD_GAP, 4, 500, 0)?;
    /// assert!(gap <= wavg::anchors::GOOD_GAP);
    /// assert_eq!(a, s.spread_anchors(a.len(), 0)?);
    /// # Ok::<(), wavg::Error>(())
    /// ```
    pub fn spread_anchors_to_gap(
        &self,
        target: f64,
        min: usize,
        max: usize,
        seed: u64,
    ) -> Result<(Vec<Anchor>, f64)> {
        let (v, gap) = spread_to_gap(self.mesh(), self.embedded_coords(), seed, min, max, target)?;
        Ok((v.into_iter().map(Anchor::Vertex).collect(), gap))
    }

    /// The largest distance in the embedding from a vertex to its nearest vertex among
    /// `anchors`, as a fraction of the bounding-box diagonal.
    pub fn largest_gap(&self, anchors: &[VertexId]) -> f64 {
        largest_gap(self.mesh(), self.embedded_coords(), anchors)
    }
}
