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

/// Geodesic distances between all pairs of `landmarks`, symmetrised: the `n x n` matrix
/// `Q = (D + D^T) / 2` row-major (`n = landmarks.len()`), where row `i` of `D` is one fast
/// marching run from landmark `i`. Runs go in parallel (rayon), each stopping once all
/// landmarks are frozen; progress is reported as [`Stage::Geodesics`] and cancellation is
/// checked between runs.
///
/// Errors: a landmark id out of range or repeated, or a pair of landmarks in different
/// components (infinite distance).
pub fn landmark_distances(
    mesh: &ValidMesh,
    landmarks: &[u32],
    progress: &dyn Progress,
) -> Result<Vec<f64>, EmbedError> {
    let fm = FastMarching::new(mesh);
    landmark_distances_with(&fm, landmarks, progress)
}

/// [`landmark_distances`] with a prebuilt [`FastMarching`] (of the same mesh).
pub fn landmark_distances_with(
    fm: &FastMarching,
    landmarks: &[u32],
    progress: &dyn Progress,
) -> Result<Vec<f64>, EmbedError> {
    let rows = landmark_rows(fm, landmarks, progress)?;
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

/// The raw rows behind [`landmark_distances_with`]: row `i` holds the fast-marching
/// distances from `landmarks[i]` to every landmark, not symmetrised (`rows[i][j]` and
/// `rows[j][i]` differ by the method's error). Runs in parallel, each stopping once every
/// landmark is reached; progress is reported as [`Stage::Geodesics`].
///
/// Errors: a landmark id out of range or repeated, or cancellation.
///
/// ```
/// use wavg_embed::NoProgress;
/// use wavg_embed::{FastMarching, internal::landmark_rows};
/// use wavg_mesh::{ValidMesh, procedural};
/// let mesh = ValidMesh::new(procedural::icosphere(3)).unwrap();
/// let rows = landmark_rows(&FastMarching::new(&mesh), &[0, 5, 100], &NoProgress).unwrap();
/// assert_eq!(rows[1][1], 0.0);
/// assert!((rows[0][2] - rows[2][0]).abs() < 0.02 * rows[0][2]);
/// ```
pub fn landmark_rows(
    fm: &FastMarching,
    landmarks: &[u32],
    progress: &dyn Progress,
) -> Result<Vec<Vec<f64>>, EmbedError> {
    let n = landmarks.len();
    let mut is_target = vec![false; fm.n];
    for &l in landmarks {
        let slot = is_target.get_mut(l as usize).ok_or_else(|| {
            EmbedError::InvalidArgument(format!(
                "landmark {l} out of range (mesh has {} vertices)",
                fm.n
            ))
        })?;
        if std::mem::replace(slot, true) {
            return Err(EmbedError::InvalidArgument(format!(
                "landmark {l} appears twice"
            )));
        }
    }
    check_cancel(progress)?;
    let done = std::sync::atomic::AtomicUsize::new(0);
    let rows: Vec<Vec<f64>> = (0..n)
        .into_par_iter()
        .map_init(
            || fm.workspace(),
            |ws, i| {
                check_cancel(progress)?;
                let d = fm.run_until_targets(ws, &landmarks[i..i + 1], &is_target, n);
                let row: Vec<f64> = landmarks.iter().map(|&l| d[l as usize]).collect();
                let k = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                progress.report(Stage::Geodesics, k as f64 / n as f64);
                Ok(row)
            },
        )
        .collect::<Result<_, EmbedError>>()?;
    Ok(rows)
}

/// Landmark pairs closer than this many mean edge lengths of the coarse mesh get their
/// distance from the fine mesh in [`landmark_distances_two_level`].
pub(crate) const NEAR_PAIR_RADIUS_EDGES: f64 = 8.0;

/// [`landmark_distances`] computed on a coarser mesh, to save time on large meshes: the
/// mesh is first decimated (with the landmarks locked, so they all survive) down to
/// `intermediate_vertices`, and the distances come from
/// [`landmark_distances_two_level`]. With `intermediate_vertices >=` the vertex count this
/// is exactly [`landmark_distances`].
pub fn landmark_distances_coarse(
    mesh: &ValidMesh,
    landmarks: &[u32],
    intermediate_vertices: usize,
    progress: &dyn Progress,
) -> Result<Vec<f64>, EmbedError> {
    if intermediate_vertices >= mesh.n_vertices() {
        return landmark_distances(mesh, landmarks, progress);
    }
    let opts = DecimateOptions {
        target: intermediate_vertices.max(landmarks.len()),
        locked: landmarks.to_vec(),
        ..DecimateOptions::default()
    };
    let coarse = decimate(mesh, &opts, &CancelOnly(progress))?;
    landmark_distances_two_level(&FastMarching::new(mesh), &coarse, landmarks, progress)
}

/// Landmark distances from two resolutions: every pair from fast marching on `coarse` (a
/// decimation of the fine mesh containing all landmarks, for example a snapshot of the
/// landmark decimation, [`crate::decimate::decimate_with_snapshots`]), then pairs closer
/// than `NEAR_PAIR_RADIUS_EDGES` (8) coarse edge lengths replaced by fine-mesh values from
/// short radius-limited runs on `fine` (the coarse mesh's few large triangles between
/// close landmarks give errors of 20-80% there, and MDS weights close pairs most). The
/// fine runs cost little: each covers only a small disc.
pub fn landmark_distances_two_level(
    fine: &FastMarching,
    coarse: &Decimated,
    landmarks: &[u32],
    progress: &dyn Progress,
) -> Result<Vec<f64>, EmbedError> {
    let mut q = landmark_distances_decimated(coarse, landmarks, progress)?;
    let radius = NEAR_PAIR_RADIUS_EDGES * wavg_mesh::geometry::mean_edge_length(&coarse.mesh);
    refine_near_pairs(fine, landmarks, radius, &mut q, progress)?;
    Ok(q)
}

/// Overwrites the entries of the symmetric `n x n` matrix `q` for landmark pairs within
/// `radius` of each other on `fine` with fine-mesh fast-marching distances (averaged over
/// both directions when both runs reach the other landmark). Returns the number of pairs
/// replaced.
pub(crate) fn refine_near_pairs(
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

/// [`landmark_distances`] on an already decimated mesh only (no fine-mesh correction of
/// close pairs, see [`landmark_distances_two_level`]); `landmarks` are original vertex ids
/// and must all be vertices of `coarse`.
pub(crate) fn landmark_distances_decimated(
    coarse: &Decimated,
    landmarks: &[u32],
    progress: &dyn Progress,
) -> Result<Vec<f64>, EmbedError> {
    let ids = landmarks
        .iter()
        .map(|&l| {
            coarse.coarse_index(l).ok_or_else(|| {
                EmbedError::InvalidArgument(format!(
                    "landmark {l} is not a vertex of the decimated mesh"
                ))
            })
        })
        .collect::<Result<Vec<u32>, _>>()?;
    let mesh = ValidMesh::new(coarse.mesh.clone())
        .map_err(|e| EmbedError::Numerical(format!("the decimated mesh is not valid: {e}")))?;
    landmark_distances(&mesh, &ids, progress)
}

/// Forwards cancellation but not progress (for a sub-step reported as part of another stage).
pub(super) struct CancelOnly<'a>(&'a dyn Progress);

impl Progress for CancelOnly<'_> {
    fn report(&self, _stage: Stage, _fraction: f64) {}
    fn cancelled(&self) -> bool {
        self.0.cancelled()
    }
}
