//! Texture transfer between two surfaces with corresponding anchors (paper Section 4):
//! every texel of the target's atlas that a triangle covers (in the target's UV layout) is
//! a point on the target; its weights with respect to the target's anchors (the inverse
//! problem, verified by default so that the weights lead back to the point) are averaged
//! over the source's anchors (the forward problem), which gives the corresponding point on
//! the source, where the source texture is sampled bilinearly at the source's UVs.
//! Uncovered and failed texels stay transparent; a few rings of dilation then fill the
//! texels just outside the charts, so that bilinear sampling at seams sees no background.

use nalgebra::Vector2;
use rayon::prelude::*;
use wavg_mesh::{SurfacePoint, TexCoords, TriMesh};
use wavg_solve::{BatchWeights, ForwardOptions, Par, RoundTrip, Solver};

use crate::{AppError, Image};

/// Size of the produced texture and how the correspondence is computed.
#[derive(Clone, Copy, Debug)]
pub struct TransferOptions {
    /// Width of the target texture in texels.
    pub width: u32,
    /// Height of the target texture in texels.
    pub height: u32,
    /// Use the verified inverse (weights that round-trip to the point) instead of the
    /// paper's weights alone.
    pub verified: bool,
    /// Round-trip tolerance of the verified inverse, in mean edge lengths of the target.
    pub tolerance: f64,
    /// Rings of texels filled around the covered ones (seam dilation).
    pub dilation: u32,
    /// Texels solved per batch (bounds the memory of the weights).
    pub batch: usize,
    /// Lattice step: texels on every `stride`-th row and column are solved exactly, and
    /// the texels between four such texels whose source UVs lie close together (one
    /// chart, no seam) interpolate them bilinearly; all others are solved exactly.
    /// 1 solves every texel.
    pub stride: u32,
}

/// The largest [`TransferOptions::stride`] the front ends accept (1 is the smallest).
pub const MAX_STRIDE: u32 = 64;

impl Default for TransferOptions {
    fn default() -> Self {
        Self {
            width: 1024,
            height: 1024,
            verified: true,
            tolerance: wavg_solve::DEFAULT_TOLERANCE,
            dilation: 4,
            batch: 1 << 16,
            stride: 4,
        }
    }
}

/// The transferred texture and what happened to its texels. With the `serde` feature the
/// counts (not the image) serialise to the keys of `wavg transfer-texture --json`.
#[derive(Clone, Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct TextureTransfer {
    /// The target texture (RGBA; alpha 0 where nothing was transferred).
    #[cfg_attr(feature = "serde", serde(skip))]
    pub image: Image,
    /// Texels covered by a target triangle (each one an inverse and a forward problem).
    #[cfg_attr(feature = "serde", serde(rename = "texels"))]
    pub covered: usize,
    /// Covered texels with a point on the source (the others are transparent).
    #[cfg_attr(feature = "serde", serde(rename = "valid_texels"))]
    pub valid: usize,
    /// Covered texels whose verified weights did not lead back to the target point (the
    /// paper's weights are used for them).
    pub not_reached: usize,
    /// Texels filled by the seam dilation.
    #[cfg_attr(feature = "serde", serde(rename = "dilated_texels"))]
    pub dilated: usize,
    /// Covered texels whose source UV was interpolated between exactly solved lattice
    /// texels (see [`TransferOptions::stride`]) rather than solved themselves.
    #[cfg_attr(feature = "serde", serde(rename = "interpolated_texels"))]
    pub interpolated: usize,
}

/// Checks that a mesh's texture coordinates are present and consistent.
pub fn check_uv<'a>(mesh: &'a TriMesh, what: &str) -> Result<&'a TexCoords, AppError> {
    let uv = mesh.uv.as_ref().ok_or_else(|| {
        AppError::Input(format!(
            "the {what} mesh has no texture coordinates (they need a `vt` on every face's \
             corners: `wavg info MESH` tells whether some faces lacked them)"
        ))
    })?;
    check_layout(uv, mesh.triangles.len(), what)?;
    Ok(uv)
}

/// Checks that texture coordinates have one UV triple per face, in range and finite.
fn check_layout(uv: &TexCoords, n_faces: usize, what: &str) -> Result<(), AppError> {
    if uv.faces.len() != n_faces
        || uv
            .faces
            .iter()
            .flatten()
            .any(|&i| i as usize >= uv.coords.len())
        || !uv.coords.iter().flatten().all(|c| c.is_finite())
    {
        return Err(AppError::Input(format!(
            "the {what} texture coordinates are inconsistent ({} UV triangles for {n_faces} \
             faces, {} UVs; indices must be in range and UVs finite)",
            uv.faces.len(),
            uv.coords.len()
        )));
    }
    Ok(())
}

/// The texels whose centres lie in a target triangle in UV space, as (texel index, point
/// on the target), triangle by triangle (so that consecutive texels are neighbours on the
/// surface); where charts overlap, the first triangle keeps the texel.
pub fn rasterize_uv(uv: &TexCoords, width: u32, height: u32) -> Vec<(u32, SurfacePoint)> {
    let (w, h) = (width as f64, height as f64);
    let mut owner = vec![false; width as usize * height as usize];
    let mut out = Vec::new();
    for (f, t) in uv.faces.iter().enumerate() {
        let p = t.map(|i| {
            let c = uv.coords[i as usize];
            [c.x * w, (1.0 - c.y) * h]
        });
        let area = cross(p[0], p[1], p[2]);
        if area == 0.0 || !area.is_finite() {
            continue;
        }
        let lo = |k: usize| p.iter().map(|q| q[k]).fold(f64::INFINITY, f64::min);
        let hi = |k: usize| p.iter().map(|q| q[k]).fold(f64::NEG_INFINITY, f64::max);
        let x0 = (lo(0) - 0.5).ceil().max(0.0) as usize;
        let y0 = (lo(1) - 0.5).ceil().max(0.0) as usize;
        let x1 = (hi(0) - 0.5).floor().min(w - 1.0);
        let y1 = (hi(1) - 0.5).floor().min(h - 1.0);
        if x1 < 0.0 || y1 < 0.0 {
            continue;
        }
        for y in y0..=y1 as usize {
            for x in x0..=x1 as usize {
                let q = [x as f64 + 0.5, y as f64 + 0.5];
                let b = [
                    cross(p[1], p[2], q) / area,
                    cross(p[2], p[0], q) / area,
                    cross(p[0], p[1], q) / area,
                ];
                let i = y * width as usize + x;
                if b.iter().all(|&v| v >= 0.0) && !owner[i] {
                    owner[i] = true;
                    out.push((i as u32, SurfacePoint::new(f as u32, b)));
                }
            }
        }
    }
    out
}

/// Twice the signed area of (a, b, c).
fn cross(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

/// Transfers `source_texture` (on the source mesh's UVs) onto the target's UV layout.
/// The two solvers must have the same number of anchors, anchor `i` of one corresponding
/// to anchor `i` of the other; both meshes need texture coordinates. `progress` is called
/// with (texels done, texels covered) after every batch.
pub fn transfer_texture(
    source: &Solver,
    source_texture: &Image,
    target: &Solver,
    opts: &TransferOptions,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<TextureTransfer, AppError> {
    let suv = check_uv(source.mesh().mesh(), "source")?;
    let tuv = check_uv(target.mesh().mesh(), "target")?;
    transfer_texture_with_uv(source, suv, source_texture, target, tuv, opts, progress)
}

/// [`transfer_texture`] with the texture coordinates given apart from the meshes (one UV
/// triple per triangle of each solver's mesh), e.g. for callers whose meshes carry none.
pub fn transfer_texture_with_uv(
    source: &Solver,
    suv: &TexCoords,
    source_texture: &Image,
    target: &Solver,
    tuv: &TexCoords,
    opts: &TransferOptions,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<TextureTransfer, AppError> {
    check_layout(suv, source.mesh().n_faces(), "source")?;
    check_layout(tuv, target.mesh().n_faces(), "target")?;
    if source.n_anchors() != target.n_anchors() {
        return Err(AppError::Input(format!(
            "the source has {} anchors and the target {}: they must correspond one to one",
            source.n_anchors(),
            target.n_anchors()
        )));
    }
    let mut image = Image::new(opts.width, opts.height, [0, 0, 0, 0])?;
    if !(opts.tolerance.is_finite() && opts.tolerance > 0.0) {
        return Err(AppError::Input(format!(
            "the round-trip tolerance must be finite and positive, got {}",
            opts.tolerance
        )));
    }
    let texels = rasterize_uv(tuv, opts.width, opts.height);
    let width = opts.width as usize;
    let step = opts.stride.max(1) as usize;
    let mut solver = Solve {
        source,
        target,
        suv,
        opts,
        not_reached: 0,
        done: 0,
        total: texels.len(),
        progress,
    };
    // Pass 1: the lattice texels (every `step`-th column and row), solved exactly.
    let (gw, gh) = (width / step + 2, opts.height as usize / step + 2);
    let mut lattice: Vec<Option<Vector2<f64>>> = vec![None; gw * gh];
    let on_lattice = |i: u32| {
        let (x, y) = (i as usize % width, i as usize / width);
        x % step == 0 && y % step == 0
    };
    let keys: Vec<(u32, SurfacePoint)> =
        texels.iter().copied().filter(|t| on_lattice(t.0)).collect();
    let mut uvs: Vec<Option<Vector2<f64>>> = vec![None; width * opts.height as usize];
    for ((i, _), uv) in keys.iter().zip(solver.source_uvs(&keys)) {
        let (x, y) = (*i as usize % width, *i as usize / width);
        lattice[(y / step) * gw + x / step] = uv;
        uvs[*i as usize] = uv;
    }
    // Pass 2: texels inside a lattice cell whose four corners landed close together in the
    // source's UV layout (one chart, no seam between them) interpolate the corners' source
    // UVs bilinearly (the correspondence is smooth there); the others are solved exactly.
    let reach = 8.0 * step as f64 / opts.width.min(opts.height) as f64;
    let mut exact = Vec::new();
    for &(i, p) in &texels {
        if step == 1 || on_lattice(i) {
            continue;
        }
        let (x, y) = (i as usize % width, i as usize / width);
        let (cx, cy) = (x / step, y / step);
        let c = [
            lattice[cy * gw + cx],
            lattice[cy * gw + cx + 1],
            lattice[(cy + 1) * gw + cx],
            lattice[(cy + 1) * gw + cx + 1],
        ];
        let close = c.iter().all(|a| {
            a.is_some_and(|a| c.iter().all(|b| b.is_some_and(|b| (a - b).norm() <= reach)))
        });
        if close {
            let c = c.map(|a| a.expect("checked"));
            let (fx, fy) = (
                (x % step) as f64 / step as f64,
                (y % step) as f64 / step as f64,
            );
            let top = c[0] * (1.0 - fx) + c[1] * fx;
            let bottom = c[2] * (1.0 - fx) + c[3] * fx;
            uvs[i as usize] = Some(top * (1.0 - fy) + bottom * fy);
            solver.done += 1;
        } else {
            exact.push((i, p));
        }
    }
    let interpolated = texels.len() - keys.len() - exact.len();
    for ((i, _), uv) in exact.iter().zip(solver.source_uvs(&exact)) {
        uvs[*i as usize] = uv;
    }
    let not_reached = solver.not_reached;
    let valid = uvs.iter().filter(|u| u.is_some()).count();
    image
        .pixels
        .par_iter_mut()
        .zip(uvs.par_iter())
        .with_min_len(4096)
        .for_each(|(px, uv)| {
            if let Some(q) = uv {
                let s = source_texture.sample_bilinear(q.x, q.y);
                *px = s.map(|v| v.round().clamp(0.0, 255.0) as u8);
            }
        });
    let points = texels;
    let dilated = dilate(&mut image, opts.dilation);
    Ok(TextureTransfer {
        image,
        covered: points.len(),
        valid,
        not_reached,
        dilated,
        interpolated,
    })
}

/// The exact correspondence of batches of target points, with progress reporting.
struct Solve<'a> {
    source: &'a Solver,
    target: &'a Solver,
    suv: &'a TexCoords,
    opts: &'a TransferOptions,
    not_reached: usize,
    done: usize,
    total: usize,
    progress: &'a (dyn Fn(usize, usize) + Sync),
}

impl Solve<'_> {
    /// The source UV of each target point (inverse on the target, forward on the source),
    /// `None` where a problem failed.
    fn source_uvs(&mut self, texels: &[(u32, SurfacePoint)]) -> Vec<Option<Vector2<f64>>> {
        let points: Vec<SurfacePoint> = texels.iter().map(|t| t.1).collect();
        let mut weights = BatchWeights::default();
        let mut trips = Vec::new();
        let fwd = ForwardOptions::default();
        let mut out = Vec::with_capacity(points.len());
        for chunk in points.chunks(self.opts.batch.max(1)) {
            if self.opts.verified {
                let tol = self.opts.tolerance;
                // `Par::Rayon` always starts.
                let _ = self.target.inverse_verified_batch_into(
                    chunk,
                    tol,
                    &mut weights,
                    &mut trips,
                    Par::Rayon,
                );
                self.not_reached += trips
                    .iter()
                    .filter(|t| matches!(t, Ok(RoundTrip::NotReached)))
                    .count();
            } else {
                // `Par::Rayon` always starts.
                let _ = self
                    .target
                    .inverse_batch_into(chunk, &mut weights, Par::Rayon);
            }
            let rows: Vec<&[f64]> = weights.iter().map(|r| r.unwrap_or(&[])).collect();
            let found = self.source.forward_batch(&rows, &fwd);
            let suv = self.suv;
            out.extend(found.iter().map(|r| {
                let p = r.as_ref().ok()?.point;
                let c = suv.faces[p.face as usize].map(|i| suv.coords[i as usize]);
                Some(c[0] * p.bary[0] + c[1] * p.bary[1] + c[2] * p.bary[2])
            }));
            self.done += chunk.len();
            (self.progress)(self.done.min(self.total), self.total);
        }
        out
    }
}

/// Fills transparent texels next to opaque ones with the mean of their opaque
/// 8-neighbours, `rings` times; returns how many were filled.
pub fn dilate(img: &mut Image, rings: u32) -> usize {
    let (w, h) = (img.width as usize, img.height as usize);
    let mut filled = 0;
    for _ in 0..rings {
        let before = img.pixels.clone();
        let ring: usize = img
            .pixels
            .par_chunks_mut(w)
            .enumerate()
            .map(|(y, row)| {
                let mut n_filled = 0;
                for (x, px) in row.iter_mut().enumerate() {
                    if px[3] != 0 {
                        continue;
                    }
                    let (mut acc, mut n) = ([0u32; 3], 0u32);
                    for ny in y.saturating_sub(1)..(y + 2).min(h) {
                        for nx in x.saturating_sub(1)..(x + 2).min(w) {
                            let p = before[ny * w + nx];
                            if p[3] != 0 {
                                for k in 0..3 {
                                    acc[k] += p[k] as u32;
                                }
                                n += 1;
                            }
                        }
                    }
                    if n > 0 {
                        let c = acc.map(|a| ((a + n / 2) / n) as u8);
                        *px = [c[0], c[1], c[2], 255];
                        n_filled += 1;
                    }
                }
                n_filled
            })
            .sum();
        filled += ring;
        if ring == 0 {
            break;
        }
    }
    filled
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    #[test]
    fn rasterized_texels_cover_the_uv_triangles_once() {
        // Two triangles making the unit square: every texel, once.
        let uv = TexCoords {
            coords: vec![
                Vector2::new(0.0, 0.0),
                Vector2::new(1.0, 0.0),
                Vector2::new(1.0, 1.0),
                Vector2::new(0.0, 1.0),
            ],
            faces: vec![[0, 1, 2], [0, 2, 3]],
        };
        let t = rasterize_uv(&uv, 16, 8);
        assert_eq!(t.len(), 128);
        let mut seen = [false; 128];
        for (i, p) in &t {
            assert!(!seen[*i as usize]);
            seen[*i as usize] = true;
            assert!((p.bary.iter().sum::<f64>() - 1.0).abs() < 1e-12);
            // The point's UV is the texel centre.
            let q = p.bary[0] * uv.coords[uv.faces[p.face as usize][0] as usize]
                + p.bary[1] * uv.coords[uv.faces[p.face as usize][1] as usize]
                + p.bary[2] * uv.coords[uv.faces[p.face as usize][2] as usize];
            let (x, y) = (*i % 16, *i / 16);
            assert!((q.x - (x as f64 + 0.5) / 16.0).abs() < 1e-12);
            assert!((q.y - (1.0 - (y as f64 + 0.5) / 8.0)).abs() < 1e-12);
        }
    }

    #[test]
    fn dilation_grows_by_one_ring_per_pass() {
        let mut img = Image::new(9, 9, [0; 4]).unwrap();
        img.set(4, 4, [90, 60, 30, 255]);
        assert_eq!(dilate(&mut img, 2), 24);
        assert_eq!(img.get(2, 2), [90, 60, 30, 255]);
        assert_eq!(img.get(1, 4)[3], 0);
    }
}
