//! Landmark drivers: all-pairs distances between landmarks, on the full mesh or on a
//! coarser one with the near pairs recomputed on the full mesh.

use super::*;

/// Fast-marching distances from the nearest of `sources` to every vertex of `mesh`
/// (`f64::INFINITY` for vertices in other components). Out-of-range source ids are ignored;
/// with no valid source every distance is infinite.
///
/// For many runs on one mesh, build a [`FastMarching`] once instead.
///
/// ```
/// use wavg_embed::distances_from;
/// use wavg_mesh::{ValidMesh, procedural};
/// let sphere = ValidMesh::new(procedural::icosphere(4)).unwrap();
/// let d = distances_from(&sphere, &[0]);
/// let p0 = sphere.positions[0];
/// // Antipode of vertex 0: half the great circle, pi.
/// let far = (0..d.len()).min_by(|&a, &b| sphere.positions[a].dot(&p0).total_cmp(&sphere.positions[b].dot(&p0))).unwrap();
/// assert!((d[far] - std::f64::consts::PI).abs() < 0.03);
/// ```
pub fn distances_from(mesh: &ValidMesh, sources: &[u32]) -> Vec<f64> {
    let fm = FastMarching::new(mesh);
    let mut ws = fm.workspace();
    fm.run(&mut ws, sources);
    ws.dist
}

/// Where [`landmark_distances`] runs fast marching.
#[derive(Clone, Copy, Debug, Default)]
enum Resolution<'a> {
    /// Every run on the full mesh.
    #[default]
    Full,
    /// On a decimation of the mesh down to this many vertices, landmarks locked.
    Decimate(usize),
    /// On this decimation of the mesh (it must contain every landmark).
    Coarse(&'a Decimated),
}

/// How [`landmark_distances`] computes the landmark matrix: on the full mesh (the default)
/// or on a coarser mesh, optionally correcting close pairs on the full mesh, and with an
/// optional prebuilt [`FastMarching`] of the full mesh to reuse.
///
/// ```
/// use wavg_embed::{GeodesicOptions, NoProgress, landmark_distances};
/// use wavg_mesh::{ValidMesh, procedural};
/// let mesh = ValidMesh::new(procedural::icosphere(4)).unwrap();
/// let lm = [0, 700, 1500, 2300];
/// let full = landmark_distances(&mesh, &lm, &GeodesicOptions::new(), &NoProgress).unwrap();
/// let opts = GeodesicOptions::new().coarse_vertices(800);
/// let coarse = landmark_distances(&mesh, &lm, &opts, &NoProgress).unwrap();
/// assert!((coarse[1] - full[1]).abs() < 0.05 * full[1]);
/// ```
#[derive(Clone, Copy, Debug)]
pub struct GeodesicOptions<'a> {
    resolution: Resolution<'a>,
    fine: Option<&'a FastMarching>,
    refine_near_pairs: bool,
    refine_on: Option<&'a Decimated>,
}

impl Default for GeodesicOptions<'_> {
    fn default() -> Self {
        GeodesicOptions {
            resolution: Resolution::Full,
            fine: None,
            refine_near_pairs: true,
            refine_on: None,
        }
    }
}

impl<'a> GeodesicOptions<'a> {
    /// Every pair on the full mesh, with a [`FastMarching`] built for the call.
    pub fn new() -> Self {
        Self::default()
    }

    /// Reuses `fm`, a [`FastMarching`] of the same mesh, for the full-mesh runs (its
    /// near-field radius applies).
    pub fn fast_marching(mut self, fm: &'a FastMarching) -> Self {
        self.fine = Some(fm);
        self
    }

    /// Computes every pair on a decimation of the mesh down to `vertices` vertices (the
    /// landmarks locked, so they all survive), to save time on large meshes. With
    /// `vertices >=` the vertex count this is the full-mesh computation.
    pub fn coarse_vertices(mut self, vertices: usize) -> Self {
        self.resolution = Resolution::Decimate(vertices);
        self
    }

    /// Computes every pair on `coarse`, a decimation of the mesh containing every landmark
    /// (for example a snapshot of the landmark decimation,
    /// [`decimate_with_snapshots`](crate::internal::decimate_with_snapshots)).
    pub fn coarse_mesh(mut self, coarse: &'a Decimated) -> Self {
        self.resolution = Resolution::Coarse(coarse);
        self
    }

    /// Whether pairs computed on a coarse mesh that lie closer than a few coarse edge
    /// lengths are recomputed on the full mesh with short radius-limited runs (default
    /// `true`): the coarse mesh's few large triangles between close landmarks are least
    /// accurate there, and MDS weights close pairs most. The fine runs cost little, each
    /// covering only a small disc. No effect on the full mesh.
    pub fn refine_near_pairs(mut self, refine: bool) -> Self {
        self.refine_near_pairs = refine;
        self
    }

    /// Runs the close-pair correction ([`Self::refine_near_pairs`]) on `mesh`, a
    /// decimation of the mesh that contains every landmark and is finer than the coarse
    /// mesh, instead of the full mesh. Each correction run covers a disc of fixed radius,
    /// so on the full mesh its cost grows with the vertex count; a decimation of a few
    /// hundred thousand vertices resolves those discs almost as well.
    pub fn refine_on(mut self, mesh: &'a Decimated) -> Self {
        self.refine_on = Some(mesh);
        self
    }
}

/// Geodesic distances between all pairs of `landmarks`, symmetrised: the `n x n` matrix
/// `Q = (D + D^T) / 2` row-major (`n = landmarks.len()`), where row `i` of `D` is one fast
/// marching run from landmark `i` (see [`FastMarching::landmark_rows`]). Runs go in
/// parallel (rayon), each stopping once all landmarks are frozen; progress is reported as
/// [`Stage::Geodesics`] and cancellation is checked between runs. `opts` chooses the mesh
/// the runs go on.
///
/// Errors: a landmark id out of range or repeated, a pair of landmarks in different
/// components (infinite distance), a landmark missing from the coarse mesh, a prebuilt
/// [`FastMarching`] of another mesh, or cancellation.
pub fn landmark_distances(
    mesh: &ValidMesh,
    landmarks: &[u32],
    opts: &GeodesicOptions<'_>,
    progress: &dyn Progress,
) -> Result<Vec<f64>, EmbedError> {
    landmark_distances_kept(mesh, landmarks, opts, None, progress)
}

/// [`landmark_distances`], reusing the runs `kept` holds from an earlier call on the same
/// mesh (the same runs give the same numbers) and keeping this call's runs in it.
pub(crate) fn landmark_distances_kept(
    mesh: &ValidMesh,
    landmarks: &[u32],
    opts: &GeodesicOptions<'_>,
    kept: Option<&mut KeptRows>,
    progress: &dyn Progress,
) -> Result<Vec<f64>, EmbedError> {
    if let Some(fm) = opts.fine
        && fm.n != mesh.n_vertices()
    {
        return Err(EmbedError::InvalidArgument(format!(
            "the fast marching has {} vertices, the mesh {}",
            fm.n,
            mesh.n_vertices()
        )));
    }
    let built = std::cell::OnceCell::new();
    let fine = || -> Result<&FastMarching, EmbedError> {
        if let Some(fm) = opts.fine.or(built.get()) {
            return Ok(fm);
        }
        let fm = FastMarching::new_cancellable(mesh, progress)?;
        Ok(built.get_or_init(|| fm))
    };
    let decimated;
    let coarse = match opts.resolution {
        Resolution::Full => {
            let key = MeshKey::new(mesh, None);
            return full_matrix_kept(&fine, &key, landmarks, kept, progress);
        }
        Resolution::Decimate(target) if target >= mesh.n_vertices() => {
            return full_matrix(fine()?, landmarks, progress);
        }
        Resolution::Decimate(target) => {
            let d = DecimateOptions {
                target: target.max(landmarks.len()),
                locked: landmarks.to_vec(),
                ..DecimateOptions::default()
            };
            decimated = decimate(mesh, &d, &CancelOnly(progress))?;
            &decimated
        }
        Resolution::Coarse(c) => c,
    };
    let mut q = landmark_distances_decimated(coarse, landmarks, kept, progress)?;
    if opts.refine_near_pairs {
        let radius = NEAR_PAIR_RADIUS_EDGES * wavg_mesh::geometry::mean_edge_length(&coarse.mesh);
        match opts.refine_on {
            None => {
                refine_near_pairs(fine()?, landmarks, radius, &mut q, progress)?;
            }
            Some(mid) => {
                let ids = decimated_ids(mid, landmarks)?;
                let mid_mesh = ValidMesh::new(mid.mesh.clone()).map_err(|e| {
                    EmbedError::Numerical(format!("the decimated mesh is not valid: {e}"))
                })?;
                let fm = FastMarching::new_cancellable(&mid_mesh, progress)?;
                refine_near_pairs(&fm, &ids, radius, &mut q, progress)?;
            }
        }
    }
    Ok(q)
}

/// The symmetrised landmark matrix from full-mesh runs of `fm`.
fn full_matrix(
    fm: &FastMarching,
    landmarks: &[u32],
    progress: &dyn Progress,
) -> Result<Vec<f64>, EmbedError> {
    let rows = fm.landmark_rows(landmarks, progress)?;
    symmetrised(rows, landmarks)
}

/// [`full_matrix`] on the mesh `key` names, its runs from `kept` where it holds them (the
/// fast marching, from `fm`, is built only when a run is missing).
fn full_matrix_kept<'f>(
    fm: &dyn Fn() -> Result<&'f FastMarching, EmbedError>,
    key: &MeshKey,
    landmarks: &[u32],
    kept: Option<&mut KeptRows>,
    progress: &dyn Progress,
) -> Result<Vec<f64>, EmbedError> {
    let rows = match kept {
        Some(kept) => kept.rows(fm, key, landmarks, progress)?,
        None => fm()?.landmark_rows(landmarks, progress)?,
    };
    symmetrised(rows, landmarks)
}

/// `Q = (D + D^T) / 2` from the rows of `D`, with a zero diagonal; an error where two
/// landmarks do not reach each other.
fn symmetrised(rows: Vec<Vec<f64>>, landmarks: &[u32]) -> Result<Vec<f64>, EmbedError> {
    let n = landmarks.len();
    let mut q = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..n {
            q[i * n + j] = 0.5 * (rows[i][j] + rows[j][i]);
        }
        q[i * n + i] = 0.0;
    }
    if let Some(k) = q.iter().position(|d| !d.is_finite()) {
        return Err(EmbedError::InvalidArgument(format!(
            "landmarks {} and {} are in different components (no geodesic between them); \
             keep only one component (`--largest-component`)",
            landmarks[k / n],
            landmarks[k % n]
        )));
    }
    Ok(q)
}

impl FastMarching {
    /// The raw rows behind [`landmark_distances`]: row `i` holds the fast-marching
    /// distances from `landmarks[i]` to every landmark, not symmetrised (`rows[i][j]` and
    /// `rows[j][i]` differ by the method's error). Runs in parallel, each stopping once
    /// every landmark is reached; progress is reported as [`Stage::Geodesics`].
    ///
    /// Errors: a landmark id out of range or repeated, or cancellation.
    ///
    /// ```
    /// use wavg_embed::{FastMarching, NoProgress};
    /// use wavg_mesh::{ValidMesh, procedural};
    /// let mesh = ValidMesh::new(procedural::icosphere(3)).unwrap();
    /// let rows = FastMarching::new(&mesh).landmark_rows(&[0, 5, 100], &NoProgress).unwrap();
    /// assert_eq!(rows[1][1], 0.0);
    /// assert!((rows[0][2] - rows[2][0]).abs() < 0.02 * rows[0][2]);
    /// ```
    pub fn landmark_rows(
        &self,
        landmarks: &[u32],
        progress: &dyn Progress,
    ) -> Result<Vec<Vec<f64>>, EmbedError> {
        let is_target = targets(self.n, landmarks)?;
        let all: Vec<usize> = (0..landmarks.len()).collect();
        let runs = self.runs(landmarks, &is_target, &all, false, 0, progress)?;
        Ok(runs.into_iter().map(|(row, _)| row).collect())
    }

    /// The runs from `landmarks[i]` for each `i` in `which` (in parallel): each one's row
    /// and, with `keep_fields`, its field ([`KeptRows`]); progress counts `done_before`
    /// rows as done already.
    fn runs(
        &self,
        landmarks: &[u32],
        is_target: &[bool],
        which: &[usize],
        keep_fields: bool,
        done_before: usize,
        progress: &dyn Progress,
    ) -> Result<Vec<RowAndField>, EmbedError> {
        let fm = self;
        let n = landmarks.len();
        check_cancel(progress)?;
        let done = std::sync::atomic::AtomicUsize::new(done_before);
        which
            .par_iter()
            .map_init(
                || fm.workspace(),
                |ws, &i| {
                    check_cancel(progress)?;
                    fm.run_until_targets(ws, &landmarks[i..i + 1], is_target, n);
                    let row: Vec<f64> = landmarks.iter().map(|&l| ws.dist[l as usize]).collect();
                    let field = keep_fields.then(|| frozen_field(ws));
                    let k = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                    progress.report(Stage::Geodesics, k as f64 / n as f64);
                    Ok((row, field))
                },
            )
            .collect()
    }
}

/// One run's row (its distances to the landmarks) and, if kept, its [`frozen_field`].
type RowAndField = (Vec<f64>, Option<Vec<f64>>);

/// Flags of `landmarks` among `n` vertices; an error for an id out of range or repeated.
fn targets(n: usize, landmarks: &[u32]) -> Result<Vec<bool>, EmbedError> {
    let mut is_target = vec![false; n];
    for &l in landmarks {
        let slot = is_target.get_mut(l as usize).ok_or_else(|| {
            EmbedError::InvalidArgument(format!(
                "landmark {l} out of range (mesh has {n} vertices)"
            ))
        })?;
        if std::mem::replace(slot, true) {
            return Err(EmbedError::InvalidArgument(format!(
                "landmark {l} appears twice"
            )));
        }
    }
    Ok(is_target)
}

/// A stopped run's distances, NaN where a vertex was not frozen yet (those are upper
/// bounds that a longer run may lower; a frozen vertex's distance is final).
fn frozen_field(ws: &Workspace) -> Vec<f64> {
    (ws.dist.iter().zip(&ws.state))
        .map(|(&d, &s)| if s == FROZEN { d } else { f64::NAN })
        .collect()
}

/// Which mesh a landmark matrix ran on: its triangles and, for a decimation, the original
/// ids of its vertices (a decimation's vertices keep their positions).
#[derive(Clone, Debug, PartialEq)]
struct MeshKey {
    vertices: usize,
    triangles: Vec<[u32; 3]>,
    ids: Option<Vec<u32>>,
}

impl MeshKey {
    fn new(mesh: &ValidMesh, ids: Option<&[u32]>) -> Self {
        MeshKey {
            vertices: mesh.n_vertices(),
            triangles: mesh.triangles.clone(),
            ids: ids.map(<[u32]>::to_vec),
        }
    }
}

/// The fast-marching runs of one landmark matrix, kept for the next matrix on the same
/// mesh: a run stops once every landmark is frozen, and frozen distances do not depend on
/// when it stops, so a landmark kept from one set to the next gets the same row, to the
/// bit, wherever the new landmarks were frozen in its run (else it runs again). Each
/// run's field costs 8 bytes a vertex of the geodesic mesh; fields are kept only while
/// the whole set fits in `budget` bytes.
#[derive(Debug)]
pub(crate) struct KeptRows {
    key: Option<MeshKey>,
    /// Per source vertex (of the geodesic mesh), its run's [`frozen_field`].
    fields: std::collections::HashMap<u32, Vec<f64>>,
    budget: usize,
    /// Whether this call's runs are kept for a next one (off for the last).
    pub(crate) keep: bool,
    /// Rows the last call took from kept runs.
    pub(crate) reused: usize,
}

impl KeptRows {
    /// Nothing kept yet; at most `budget` bytes of fields.
    pub(crate) fn new(budget: usize) -> Self {
        KeptRows {
            key: None,
            fields: Default::default(),
            budget,
            keep: true,
            reused: 0,
        }
    }

    /// Runs reused (kept fields that reach every landmark) and run again in the last call.
    fn rows<'f>(
        &mut self,
        fm: &dyn Fn() -> Result<&'f FastMarching, EmbedError>,
        key: &MeshKey,
        landmarks: &[u32],
        progress: &dyn Progress,
    ) -> Result<Vec<Vec<f64>>, EmbedError> {
        let n_vertices = key.vertices;
        let is_target = targets(n_vertices, landmarks)?;
        if self.key.as_ref() != Some(key) {
            self.fields.clear();
        }
        let reached = |f: &Vec<f64>| landmarks.iter().all(|&l| !f[l as usize].is_nan());
        let kept: Vec<Option<&Vec<f64>>> = (landmarks.iter())
            .map(|l| self.fields.get(l).filter(|f| reached(f)))
            .collect();
        let missing: Vec<usize> = (0..landmarks.len())
            .filter(|&i| kept[i].is_none())
            .collect();
        self.reused = landmarks.len() - missing.len();
        let keep = self.keep && landmarks.len().saturating_mul(n_vertices) <= self.budget / 8;
        let mut runs = if missing.is_empty() {
            check_cancel(progress)?;
            Vec::new()
        } else {
            let done = landmarks.len() - missing.len();
            fm()?.runs(landmarks, &is_target, &missing, keep, done, progress)?
        };
        let mut rows: Vec<Option<Vec<f64>>> = (kept.iter())
            .map(|f| f.map(|f| landmarks.iter().map(|&l| f[l as usize]).collect()))
            .collect();
        for (&i, (row, _)) in missing.iter().zip(&mut runs) {
            rows[i] = Some(std::mem::take(row));
        }
        if keep {
            let mut fields: std::collections::HashMap<u32, Vec<f64>> = Default::default();
            for (&i, (_, field)) in missing.iter().zip(runs) {
                fields.extend(field.map(|f| (landmarks[i], f)));
            }
            for l in landmarks {
                if let Some(f) = self.fields.remove(l) {
                    fields.entry(*l).or_insert(f);
                }
            }
            self.fields = fields;
            self.key = Some(key.clone());
        } else {
            self.fields.clear();
            self.key = None;
        }
        Ok(rows.into_iter().map(|r| r.unwrap_or_default()).collect())
    }
}

/// Landmark pairs closer than this many mean edge lengths of the coarse mesh get their
/// distance from the fine mesh (see [`GeodesicOptions::refine_near_pairs`]).
pub(crate) const NEAR_PAIR_RADIUS_EDGES: f64 = 8.0;

/// Overwrites the entries of the symmetric `n x n` matrix `q` for landmark pairs within
/// `radius` of each other on `fine` with fine-mesh fast-marching distances (averaged over
/// both directions when both runs reach the other landmark). Returns the number of pairs
/// replaced.
fn refine_near_pairs(
    fine: &FastMarching,
    landmarks: &[u32],
    radius: f64,
    q: &mut [f64],
    progress: &dyn Progress,
) -> Result<usize, EmbedError> {
    let n = landmarks.len();
    if q.len() != n * n {
        return Err(EmbedError::InvalidArgument(format!(
            "distance matrix has {} entries, expected {n} x {n}",
            q.len()
        )));
    }
    let mut index = vec![NONE; fine.n];
    for (i, &l) in landmarks.iter().enumerate() {
        let slot = index
            .get_mut(l as usize)
            .ok_or_else(|| EmbedError::InvalidArgument(format!("landmark {l} out of range")))?;
        *slot = i as u32;
    }
    let rows: Vec<Vec<(u32, f64)>> = (0..n)
        .into_par_iter()
        .map_init(
            || fine.workspace(),
            |ws, i| {
                check_cancel(progress)?;
                let local = fine.run_within(ws, &landmarks[i..i + 1], radius);
                Ok(local
                    .iter()
                    .filter(|&&(v, _)| index[v as usize] != NONE && index[v as usize] != i as u32)
                    .map(|&(v, d)| (index[v as usize], d))
                    .collect())
            },
        )
        .collect::<Result<_, EmbedError>>()?;
    // Pair (i, j) -> sum of the fine distances found and how many.
    let mut acc: std::collections::HashMap<(u32, u32), (f64, u32)> = Default::default();
    for (i, row) in rows.iter().enumerate() {
        for &(j, d) in row {
            let key = ((i as u32).min(j), (i as u32).max(j));
            let e = acc.entry(key).or_insert((0.0, 0));
            e.0 += d;
            e.1 += 1;
        }
    }
    for (&(i, j), &(sum, k)) in &acc {
        let d = sum / f64::from(k);
        q[i as usize * n + j as usize] = d;
        q[j as usize * n + i as usize] = d;
    }
    Ok(acc.len())
}

/// The landmark matrix on an already decimated mesh only (no fine-mesh correction of
/// close pairs); `landmarks` are original vertex ids and must all be vertices of `coarse`.
fn landmark_distances_decimated(
    coarse: &Decimated,
    landmarks: &[u32],
    kept: Option<&mut KeptRows>,
    progress: &dyn Progress,
) -> Result<Vec<f64>, EmbedError> {
    let ids = decimated_ids(coarse, landmarks)?;
    let mesh = ValidMesh::new(coarse.mesh.clone())
        .map_err(|e| EmbedError::Numerical(format!("the decimated mesh is not valid: {e}")))?;
    let built = std::cell::OnceCell::new();
    let fm = || -> Result<&FastMarching, EmbedError> {
        if let Some(fm) = built.get() {
            return Ok(fm);
        }
        let fm = FastMarching::new_cancellable(&mesh, progress)?;
        Ok(built.get_or_init(|| fm))
    };
    let key = MeshKey::new(&mesh, Some(&coarse.landmarks));
    full_matrix_kept(&fm, &key, &ids, kept, progress)
}

/// The indices in `coarse` of the original vertices `landmarks` (an error if one is not
/// a vertex of `coarse`).
fn decimated_ids(coarse: &Decimated, landmarks: &[u32]) -> Result<Vec<u32>, EmbedError> {
    landmarks
        .iter()
        .map(|&l| {
            coarse.coarse_index(l).ok_or_else(|| {
                EmbedError::InvalidArgument(format!(
                    "landmark {l} is not a vertex of the decimated mesh"
                ))
            })
        })
        .collect()
}

/// Forwards cancellation but not progress (for a sub-step reported as part of another stage).
pub(super) struct CancelOnly<'a>(&'a dyn Progress);

impl Progress for CancelOnly<'_> {
    fn report(&self, _stage: Stage, _fraction: f64) {}
    fn cancelled(&self) -> bool {
        self.0.cancelled()
    }
}
