//! The projector's memory layout: the records random queries read (a vertex for the walk,
//! a vertex and a face for the tangent equations), each a few aligned cache lines, and
//! their construction.

use super::*;

/// Neighbours (and faces) stored in a vertex's walk record; larger rings come from the
/// topology.
pub(super) const WALK_RING: usize = 12;

/// A vertex as the walk sees it, in two cache lines. The first holds its coordinates as
/// 16-bit integers on a uniform grid over the bounding box (65535 steps along its longest
/// side) and its one-ring: reading a neighbour's distance brings in its ring too, so a
/// walk step waits for one round of (parallel) memory accesses. The second holds the
/// faces around it, so the walk's end leads straight to the candidate faces without two
/// more dependent reads of the topology. Only the greedy walk and the ordering of
/// candidate faces use the coordinates (heuristics; every answer is computed and
/// certified in f64).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(super) struct WalkPoint {
    pub(super) c: [u16; 8],
    pub(super) ring: [u32; WALK_RING],
    pub(super) faces: [u32; WALK_RING],
    /// Ring length, or `u32::MAX` if it does not fit.
    pub(super) n: u32,
    /// Number of faces around the vertex (ring length, one less on a boundary).
    pub(super) nf: u32,
}

impl WalkPoint {
    #[inline(always)]
    pub(super) fn unpack(&self) -> [f32; 8] {
        std::array::from_fn(|k| self.c[k] as f32)
    }

    /// Squared distance from these coordinates to `y` (walk units): [`wdist2`] of
    /// [`WalkPoint::unpack`], bit for bit, with the conversion done four lanes at a time.
    #[inline(always)]
    pub(super) fn dist2(&self, y: &[f32; 8]) -> f32 {
        dist2_packed(&self.c, y)
    }

    #[inline(always)]
    pub(super) fn ring<'a>(&'a self, topo: &'a wavg_mesh::Topology, v: VertexId) -> &'a [u32] {
        if (self.n as usize) <= WALK_RING {
            &self.ring[..self.n as usize]
        } else {
            topo.ring(v)
        }
    }

    #[inline(always)]
    pub(super) fn faces<'a>(&'a self, topo: &'a wavg_mesh::Topology, v: VertexId) -> &'a [u32] {
        if (self.n as usize) <= WALK_RING {
            &self.faces[..self.nf as usize]
        } else {
            topo.ring_faces(v)
        }
    }
}

/// [`wdist2`] from packed 16-bit walk coordinates `c` to `y`, bit for bit, with the
/// conversion done four lanes at a time where the target allows.
#[inline(always)]
pub(super) fn dist2_packed(c: &[u16; 8], y: &[f32; 8]) -> f32 {
    #[cfg(target_arch = "x86_64")]
    return crate::arch::dist2_u16(c, y);
    #[cfg(not(target_arch = "x86_64"))]
    wdist2(&c.map(f32::from), y)
}

#[cfg_attr(target_arch = "x86_64", allow(dead_code))] // the reference for `dist2`
/// Squared distance of walk coordinates, summed as two 4-lane halves and a fixed tree so
/// the compiler can keep it in SIMD registers (a sequential sum cannot be reordered).
#[inline(always)]
pub(super) fn wdist2(a: &[f32; 8], b: &[f32; 8]) -> f32 {
    let mut s = [0.0f32; 4];
    for k in 0..4 {
        let d0 = a[k] - b[k];
        let d1 = a[k + 4] - b[k + 4];
        s[k] = d0 * d0 + d1 * d1;
    }
    (s[0] + s[2]) + (s[1] + s[3])
}

/// Dot product of walk-coordinate vectors, summed in [`wdist2`]'s fixed tree (so it stays
/// in SIMD registers).
#[inline(always)]
pub(super) fn wdot(a: &[f32; 8], b: &[f32; 8]) -> f32 {
    let mut s = [0.0f32; 4];
    for k in 0..4 {
        s[k] = a[k] * b[k] + a[k + 4] * b[k + 4];
    }
    (s[0] + s[2]) + (s[1] + s[3])
}

/// What a query reads of a vertex, in two adjacent cache lines: its embedded point (f64,
/// for the tangent equations) and its frame (f32).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(super) struct VertexRec {
    pub(super) x: Vec8,
    pub(super) t: Frame32,
}

impl VertexRec {
    /// The frame's two tangent vectors (orthonormal in R^8, so also in walk units up to
    /// the walk's uniform scale).
    #[inline(always)]
    pub(super) fn tangents(&self) -> (&[f32; 8], &[f32; 8]) {
        let (t0, t1) = self.t.split_at(8);
        (t0.try_into().unwrap(), t1.try_into().unwrap())
    }
}

/// What a query reads of a face, in two cache lines: its blend matrices and corners.
#[derive(Clone, Copy, Debug, Default)]
#[repr(C, align(64))]
pub(super) struct Face {
    pub(super) d: TriData,
    pub(super) v: [u32; 3],
}

impl Projector {
    /// Computes the vertex frames, the per-triangle data, the bounding volume hierarchy,
    /// the walk records and the start grid, each in parallel chunks written in place (the
    /// result does not depend on the number of threads).
    pub fn new(emb: Arc<EmbeddedMesh>) -> Result<Self, ProjectError> {
        let mesh = emb.mesh();
        if mesh.n_faces() == 0 {
            return Err(ProjectError::EmptyMesh);
        }
        let coords = emb.coords();
        let big = |c: &Vec8| c.amax() > wavg_mesh::MAX_COORDINATE;
        if let Some(v) = coords.iter().position(big) {
            return Err(ProjectError::OutOfRange {
                vertex: v as u32,
                value: coords[v].amax(),
            });
        }
        let topo = mesh.topology();
        let chunk = 4096;
        let mut verts = crate::hugepage::filled(
            mesh.n_vertices(),
            VertexRec {
                x: Vec8::zeros(),
                t: [0.0; 16],
            },
        );
        let frame_kinds = verts
            .par_chunks_mut(chunk)
            .enumerate()
            .map(|(c, out)| {
                let mut counts = [0usize; 4];
                for (i, o) in out.iter_mut().enumerate() {
                    let v = c * chunk + i;
                    let (t, k) = crate::frames::vertex_frame(mesh, coords, v as u32);
                    *o = VertexRec {
                        x: coords[v],
                        t: frame_to_f32(&t),
                    };
                    counts[k as usize] += 1;
                }
                counts
            })
            .reduce(|| [0; 4], |a, b| std::array::from_fn(|k| a[k] + b[k]));
        const BATCH: usize = 4;
        let mut faces = crate::hugepage::filled(mesh.n_faces(), Face::default());
        faces
            .par_chunks_mut(BATCH)
            .zip(mesh.triangles.par_chunks(BATCH))
            .with_min_len(chunk / BATCH)
            .for_each(|(out, ts)| {
                let fr = |t: &[u32; 3]| t.map(|v| &verts[v as usize].t);
                if ts.len() == BATCH {
                    let d = TriData::new_batch([fr(&ts[0]), fr(&ts[1]), fr(&ts[2]), fr(&ts[3])]);
                    for i in 0..BATCH {
                        out[i] = Face { d: d[i], v: ts[i] };
                    }
                } else {
                    for (o, t) in out.iter_mut().zip(ts) {
                        *o = Face {
                            d: TriData::new(fr(t)),
                            v: *t,
                        };
                    }
                }
            });
        let bvh = Bvh::new(&mesh.triangles, coords);
        let (lo, hi) = coords
            .par_iter()
            .with_min_len(chunk)
            .fold(
                || (Vec8::repeat(f64::INFINITY), Vec8::repeat(f64::NEG_INFINITY)),
                |(l, h), c| (l.inf(c), h.sup(c)),
            )
            .reduce(
                || (Vec8::repeat(f64::INFINITY), Vec8::repeat(f64::NEG_INFINITY)),
                |(l0, h0), (l1, h1)| (l0.inf(&l1), h0.sup(&h1)),
            );
        let walk_origin = lo;
        let extent = (hi - lo).max();
        // (A collapsed embedding, every vertex at one point, is a degenerate case the
        // frames and searches handle; a tiny one is a mesh to scale.)
        if extent > 0.0 && extent < wavg_mesh::MIN_EXTENT {
            return Err(ProjectError::TooSmall { extent });
        }
        let walk_inv_step = if extent > 0.0 && extent.is_finite() {
            65535.0 / extent
        } else {
            1.0
        };
        let mut walk_coords = crate::hugepage::vec_with_capacity(coords.len());
        walk_coords.par_extend(
            coords
                .par_iter()
                .enumerate()
                .with_min_len(chunk)
                .map(|(v, c)| {
                    let r = topo.ring(v as u32);
                    let rf = topo.ring_faces(v as u32);
                    let mut ring = [0u32; WALK_RING];
                    let mut faces = [0u32; WALK_RING];
                    let n = if r.len() <= WALK_RING {
                        ring[..r.len()].copy_from_slice(r);
                        faces[..rf.len()].copy_from_slice(rf);
                        r.len() as u32
                    } else {
                        u32::MAX
                    };
                    WalkPoint {
                        c: std::array::from_fn(|k| {
                            ((c[k] - walk_origin[k]) * walk_inv_step)
                                .round()
                                .clamp(0.0, 65535.0) as u16
                        }),
                        ring,
                        faces,
                        n,
                        nf: rf.len() as u32,
                    }
                }),
        );
        let starts = StartGrid::new(&walk_coords);
        let reach = super::reach::Reach::new(mesh.n_vertices());
        Ok(Self {
            emb,
            verts,
            frame_kinds,
            faces,
            bvh,
            cones: std::sync::OnceLock::new(),
            unfiltered: std::sync::atomic::AtomicUsize::new(0),
            mesh_mean_edge: std::sync::OnceLock::new(),
            reach,
            walk_origin,
            walk_inv_step,
            walk_coords,
            starts,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use wavg_mesh::{ValidMesh, procedural};

    /// The set-up runs in parallel chunks; its result is the same on any number of
    /// threads (the hierarchy is large enough for its subtrees to be built in parallel).
    #[test]
    fn set_up_does_not_depend_on_the_thread_count() {
        let m = Arc::new(ValidMesh::new(procedural::icosphere(5)).unwrap());
        let emb = Arc::new(EmbeddedMesh::from_positions(m));
        let build = |threads| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| Projector::new(emb.clone()).unwrap())
        };
        let one = build(1);
        for threads in [2, 5] {
            let p = build(threads);
            assert_eq!(format!("{:?}", p.bvh), format!("{:?}", one.bvh));
            assert_eq!(p.frame_kinds, one.frame_kinds);
            for (a, b) in p.verts.iter().zip(&one.verts) {
                assert_eq!((a.x, a.t), (b.x, b.t));
            }
            for (a, b) in p.faces.iter().zip(&one.faces) {
                assert_eq!(format!("{a:?}"), format!("{b:?}"));
            }
            for (a, b) in p.walk_coords.iter().zip(&one.walk_coords) {
                assert_eq!(
                    (a.c, a.ring, a.faces, a.n, a.nf),
                    (b.c, b.ring, b.faces, b.n, b.nf)
                );
            }
            assert_eq!(p.starts.bytes(), one.starts.bytes());
        }
    }
}
