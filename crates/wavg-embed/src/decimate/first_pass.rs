//! The fast first pass of the landmark decimation on large meshes: meshoptimizer's
//! simplifier (edge collapses onto existing vertices, far cheaper per collapse than the
//! quadric decimator's legality checks) down to a few hundred thousand vertices, then a
//! cleanup that makes its output a valid oriented manifold with the input's topology, on
//! distinct original vertices. The quadric decimator then continues from that mesh.
//!
//! meshoptimizer does not check the link condition, so where thin parts collapse its
//! output can hold duplicate faces (a tube flattened to two back-to-back triangles), edges
//! with four faces and pinched vertices. The cleanup:
//!
//! 1. cancels duplicate faces: of the faces on one vertex triple, opposite orientations
//!    cancel in pairs and at most one face stays;
//! 2. drops degenerate faces, splits non-manifold vertices and edges into one vertex per
//!    fan ([`wavg_mesh::repair::make_manifold`]), orients, drops unreferenced vertices,
//!    and, when the input is connected, keeps the largest component (a piece pinched off
//!    where a thin part collapsed);
//! 3. gives each split copy of a vertex a fresh identity: the nearest original vertex
//!    the simplifier removed (within three rings of the original), on the copy's side, so
//!    every reduced vertex is a distinct original vertex and landmarks stay distinct;
//! 4. keeps the result only if it validates and has the input's genus, boundary loops and
//!    components (and every locked vertex); otherwise the caller decimates the full mesh.
//!
//! The simplifier cannot stop partway (about 15 s at 3M vertices), so it runs on a thread
//! of its own while the caller polls for cancellation every [`CANCEL_POLL`]: a cancelled
//! precomputation returns within that, and the abandoned simplification finishes in the
//! background and frees its memory (an exiting `wavg` ends it at once). The clean-up
//! (about 4 s at 3M vertices) looks at the cancellation between its steps.

use std::sync::mpsc;
use std::time::Duration;

use nalgebra::Vector3;
use wavg_mesh::{RepairOptions, TriMesh, ValidMesh, repair};

use crate::error::{EmbedError, Progress, check_cancel};

/// How often the caller looks for cancellation while the simplifier runs.
pub(super) const CANCEL_POLL: Duration = Duration::from_millis(50);

/// The result of the first pass: a valid mesh on original vertices.
pub(super) struct Reduced {
    /// The reduced mesh; its vertex `i` is original vertex `original[i]` (same position).
    pub mesh: ValidMesh,
    /// Original id of each reduced vertex, ascending.
    pub original: Vec<u32>,
}

/// Rings of the original mesh searched for a fresh identity of a split copy.
const FRESH_RINGS: usize = 3;

/// Simplifies `mesh` to about `keep` vertices with `locked` vertices kept, then cleans up;
/// `None` when the cleaned result is not a valid mesh of the input's topology, and
/// [`EmbedError::Cancelled`] within about [`CANCEL_POLL`] of `progress` asking.
pub(super) fn first_pass(
    mesh: &ValidMesh,
    keep: usize,
    locked: &[u32],
    progress: &dyn Progress,
) -> Result<Option<Reduced>, EmbedError> {
    let raw = simplify(mesh, keep, locked, progress)?;
    check_cancel(progress)?;
    let raw = cancel_duplicate_faces(raw);
    match clean(mesh, raw, locked, progress) {
        Ok(reduced) => Ok(Some(reduced)),
        Err(Failed::Cancelled) => Err(EmbedError::Cancelled),
        Err(Failed::Invalid(_)) => Ok(None),
    }
}

/// meshoptimizer's simplifier towards `keep` vertices (`2 keep` faces), borders and
/// `locked` vertices kept: the surviving faces, in original vertex ids. It runs on a
/// thread of its own, abandoned when `progress` cancels (module documentation).
fn simplify(
    mesh: &ValidMesh,
    keep: usize,
    locked: &[u32],
    progress: &dyn Progress,
) -> Result<Vec<[u32; 3]>, EmbedError> {
    let n = mesh.n_vertices();
    let bytes: Vec<u8> = (mesh.positions.iter())
        .flat_map(|p| [p.x as f32, p.y as f32, p.z as f32])
        .flat_map(f32::to_le_bytes)
        .collect();
    let indices: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
    let mut lock = vec![false; n];
    for &l in locked {
        lock[l as usize] = true;
    }
    // Faces of a closed mesh are about twice its vertices.
    let target = (2 * keep).min(mesh.n_faces()) * 3;
    let run = move || -> Option<Vec<u32>> {
        let adapter = meshopt::VertexDataAdapter::new(&bytes, 12, 0).ok()?;
        Some(meshopt::simplify_with_locks(
            &indices,
            &adapter,
            &lock,
            target,
            1.0,
            meshopt::SimplifyOptions::LockBorder,
            None,
        ))
    };
    let (tx, rx) = mpsc::channel();
    let spawned = std::thread::Builder::new()
        .name("wavg-simplify".into())
        .spawn(move || {
            // The receiver is gone when the caller was cancelled: nothing to deliver.
            let _ = tx.send(run());
        });
    let out = match spawned {
        Ok(_) => loop {
            match rx.recv_timeout(CANCEL_POLL) {
                Ok(out) => break out,
                Err(mpsc::RecvTimeoutError::Timeout) => check_cancel(progress)?,
                // The simplifier panicked: as if it had reduced nothing.
                Err(mpsc::RecvTimeoutError::Disconnected) => break None,
            }
        },
        // No thread to be had: nothing to simplify with.
        Err(_) => None,
    };
    Ok(match out {
        Some(out) => out.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect(),
        None => mesh.triangles.clone(),
    })
}

/// Of the faces on one vertex triple, faces of opposite orientation cancel in pairs and at
/// most one of the orientation left over stays (the first of its kind, in face order).
fn cancel_duplicate_faces(mut faces: Vec<[u32; 3]>) -> Vec<[u32; 3]> {
    // (sorted corners, whether the face is an even rotation of them, face index)
    let mut keys: Vec<([u32; 3], bool, u32)> = (faces.iter().enumerate())
        .map(|(f, t)| {
            let mut k = *t;
            k.sort_unstable();
            let even = [[t[0], t[1], t[2]], [t[1], t[2], t[0]], [t[2], t[0], t[1]]].contains(&k);
            (k, even, f as u32)
        })
        .collect();
    keys.sort_unstable();
    let mut drop = vec![false; faces.len()];
    for group in keys.chunk_by(|a, b| a.0 == b.0) {
        if group.len() < 2 {
            continue;
        }
        let even = group.iter().filter(|g| g.1).count() as i64;
        let net = 2 * even - group.len() as i64;
        let survivor = match net.cmp(&0) {
            std::cmp::Ordering::Equal => None,
            o => group.iter().find(|g| g.1 == o.is_gt()),
        };
        for g in group {
            drop[g.2 as usize] = survivor.is_none_or(|s| s.2 != g.2);
        }
    }
    let mut f = 0;
    faces.retain(|_| {
        f += 1;
        !drop[f - 1]
    });
    faces
}

/// Why the clean-up gave no mesh.
#[derive(Debug)]
enum Failed {
    /// `progress` asked to stop.
    Cancelled,
    /// The simplifier's output could not be made a valid mesh of the input's topology
    /// (why: the caller decimates the full mesh instead; the diagnosis test shows it).
    Invalid(
        #[cfg_attr(not(test), expect(dead_code, reason = "read by the diagnosis test"))] String,
    ),
}

impl From<String> for Failed {
    fn from(why: String) -> Self {
        Self::Invalid(why)
    }
}

/// [`check_cancel`] for the clean-up, between its steps (each under a second at 10M
/// vertices, most of them on the reduced mesh).
fn stop_if_cancelled(progress: &dyn Progress) -> Result<(), Failed> {
    check_cancel(progress).map_err(|_| Failed::Cancelled)
}

/// Repairs the simplifier's faces into a valid mesh on distinct original vertices with the
/// input's topology (module docs, steps 2 to 4); else what failed.
fn clean(
    mesh: &ValidMesh,
    faces: Vec<[u32; 3]>,
    locked: &[u32],
    progress: &dyn Progress,
) -> Result<Reduced, Failed> {
    let n = mesh.n_vertices();
    // The used original vertices, ascending, as a compact mesh.
    let mut new_id = vec![u32::MAX; n];
    for t in &faces {
        for &v in t {
            new_id[v as usize] = 0;
        }
    }
    let mut ids: Vec<u32> = (0..n as u32).filter(|&v| new_id[v as usize] == 0).collect();
    for (i, &v) in ids.iter().enumerate() {
        new_id[v as usize] = i as u32;
    }
    let compact = TriMesh::new(
        ids.iter().map(|&v| mesh.positions[v as usize]).collect(),
        faces
            .iter()
            .map(|t| t.map(|v| new_id[v as usize]))
            .collect(),
    );
    // Pieces the simplifier pinched off a connected mesh (a collapsed thin part) go.
    let opts = RepairOptions {
        weld: None,
        drop_duplicate_faces: false,
        keep_largest_component: mesh.topology().n_components() == 1,
        ..RepairOptions::default()
    };
    stop_if_cancelled(progress)?;
    let r = repair::repair_all(&compact, &opts);
    drop(compact);
    stop_if_cancelled(progress)?;
    // Original id of each repaired vertex; a split copy repeats its vertex's id.
    let mut orig: Vec<u32> = r.vertex_map.iter().map(|&v| ids[v as usize]).collect();
    ids.clear();
    let mut used = vec![false; n];
    let mut copies = Vec::new();
    for (i, &v) in orig.iter().enumerate() {
        if std::mem::replace(&mut used[v as usize], true) {
            copies.push(i);
        }
    }
    if !copies.is_empty() {
        let centroids = fan_centroids(&r.mesh, &copies);
        for (&c, centre) in copies.iter().zip(centroids) {
            let fresh = fresh_vertex(mesh, orig[c], centre, &used)
                .ok_or_else(|| format!("no fresh vertex near {}", orig[c]))?;
            used[fresh as usize] = true;
            orig[c] = fresh;
        }
    }
    stop_if_cancelled(progress)?;
    // Renumber by ascending original id.
    let mut order: Vec<u32> = (0..orig.len() as u32).collect();
    order.sort_unstable_by_key(|&i| orig[i as usize]);
    let mut rank = vec![0u32; orig.len()];
    for (k, &i) in order.iter().enumerate() {
        rank[i as usize] = k as u32;
    }
    let original: Vec<u32> = order.iter().map(|&i| orig[i as usize]).collect();
    let reduced = TriMesh::new(
        original
            .iter()
            .map(|&v| mesh.positions[v as usize])
            .collect(),
        (r.mesh.triangles.iter())
            .map(|t| t.map(|v| rank[v as usize]))
            .collect(),
    );
    stop_if_cancelled(progress)?;
    let reduced = ValidMesh::new(reduced).map_err(|e| e.to_string())?;
    stop_if_cancelled(progress)?;
    let (a, b) = (mesh.topology(), reduced.topology());
    let shape = |t: &wavg_mesh::Topology| (t.genus(), t.boundary_loops().len(), t.n_components());
    if shape(a) != shape(b) {
        return Err(Failed::Invalid(format!(
            "topology (genus, loops, components) {:?} became {:?}",
            shape(a),
            shape(b)
        )));
    }
    if !locked.iter().all(|l| original.binary_search(l).is_ok()) {
        return Err(Failed::Invalid("a locked vertex was lost".into()));
    }
    Ok(Reduced {
        mesh: reduced,
        original,
    })
}

/// For each vertex of `copies`, the centroid of the other corners of its faces.
fn fan_centroids(mesh: &TriMesh, copies: &[usize]) -> Vec<Vector3<f64>> {
    let mut slot = vec![u32::MAX; mesh.n_vertices()];
    for (k, &c) in copies.iter().enumerate() {
        slot[c] = k as u32;
    }
    let mut sum = vec![(Vector3::zeros(), 0usize); copies.len()];
    for t in &mesh.triangles {
        for c in 0..3 {
            let k = slot[t[c] as usize];
            if k != u32::MAX {
                let s = &mut sum[k as usize];
                s.0 += mesh.positions[t[(c + 1) % 3] as usize]
                    + mesh.positions[t[(c + 2) % 3] as usize];
                s.1 += 2;
            }
        }
    }
    sum.into_iter().map(|(s, k)| s / k.max(1) as f64).collect()
}

/// The unused original vertex within [`FRESH_RINGS`] rings of `v` nearest to `centre`.
fn fresh_vertex(mesh: &ValidMesh, v: u32, centre: Vector3<f64>, used: &[bool]) -> Option<u32> {
    let topo = mesh.topology();
    let mut seen = vec![v];
    let mut frontier = vec![v];
    for _ in 0..FRESH_RINGS {
        let mut next = Vec::new();
        for &u in &frontier {
            for &w in topo.ring(u) {
                if !seen.contains(&w) {
                    seen.push(w);
                    next.push(w);
                }
            }
        }
        frontier = next;
    }
    (seen.into_iter())
        .filter(|&w| !used[w as usize])
        .min_by(|&a, &b| {
            let d = |w: u32| (mesh.positions[w as usize] - centre).norm_squared();
            d(a).total_cmp(&d(b))
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::NoProgress;
    use wavg_mesh::procedural;

    fn valid(m: TriMesh) -> ValidMesh {
        ValidMesh::new(m).unwrap()
    }

    /// The first pass on `WAVG_FIRST_PASS_MESH`, with what the clean-up met.
    #[test]
    #[ignore = "a diagnosis on a large mesh named by WAVG_FIRST_PASS_MESH"]
    fn diagnose_a_large_mesh() {
        let path = std::env::var("WAVG_FIRST_PASS_MESH").unwrap();
        let mesh = valid(wavg_mesh::io::load(path.as_ref()).unwrap());
        let t = std::time::Instant::now();
        let raw = simplify(&mesh, FIRST_PASS_VERTICES_FOR_TEST, &[], &NoProgress).unwrap();
        let ts = t.elapsed().as_secs_f64();
        let n_raw = raw.len();
        let raw = cancel_duplicate_faces(raw);
        eprintln!(
            "simplified to {n_raw} faces in {ts:.2} s, {} after cancelling",
            raw.len()
        );
        let t = std::time::Instant::now();
        match clean(&mesh, raw, &[], &NoProgress) {
            Ok(r) => eprintln!(
                "clean: {} vertices, {} faces in {:.2} s",
                r.mesh.n_vertices(),
                r.mesh.n_faces(),
                t.elapsed().as_secs_f64()
            ),
            Err(Failed::Invalid(why)) => eprintln!("clean failed: {why}"),
            Err(Failed::Cancelled) => unreachable!("NoProgress never cancels"),
        }
    }

    /// A cancellation while the simplifier runs returns within a poll, without waiting
    /// for the simplification (about a second on this mesh) to end.
    #[test]
    fn the_simplifier_is_abandoned_when_cancelled() {
        struct Cancelled;
        impl Progress for Cancelled {
            fn report(&self, _: crate::Stage, _: f64) {}
            fn cancelled(&self) -> bool {
                true
            }
        }
        let mesh = valid(procedural::icosphere(7));
        let t = std::time::Instant::now();
        let r = simplify(&mesh, 1000, &[], &Cancelled);
        let latency = t.elapsed();
        eprintln!("cancelled after {latency:?}");
        assert!(matches!(r, Err(EmbedError::Cancelled)), "{r:?}");
        assert!(latency < 20 * CANCEL_POLL, "{latency:?}");
        assert!(matches!(
            first_pass(&mesh, 1000, &[], &Cancelled),
            Err(EmbedError::Cancelled)
        ));
    }

    /// The clean-up stops between its steps when cancelled: at its first look, and at
    /// its last (after the reduced mesh is validated).
    #[test]
    fn the_clean_up_stops_when_cancelled() {
        struct CancelAt(std::sync::atomic::AtomicUsize, usize);
        impl Progress for CancelAt {
            fn report(&self, _: crate::Stage, _: f64) {}
            fn cancelled(&self) -> bool {
                self.0.fetch_add(1, std::sync::atomic::Ordering::Relaxed) >= self.1
            }
        }
        let grid = valid(procedural::grid(80, 60, 2.0, 1.0));
        let count = CancelAt(0.into(), usize::MAX);
        assert!(clean(&grid, grid.triangles.clone(), &[], &count).is_ok());
        let looks = count.0.into_inner();
        assert!(looks >= 4, "{looks} looks");
        for at in [0, looks - 1] {
            let r = clean(&grid, grid.triangles.clone(), &[], &CancelAt(0.into(), at));
            assert!(
                matches!(r, Err(Failed::Cancelled)),
                "at look {at}: {:?}",
                r.err()
            );
        }
    }

    const FIRST_PASS_VERTICES_FOR_TEST: usize = super::super::FIRST_PASS_VERTICES;

    #[test]
    fn duplicate_faces_cancel_by_orientation() {
        let faces = vec![
            [0, 1, 2],
            [1, 0, 2], // opposite of the first: both go
            [3, 4, 5],
            [4, 5, 3], // same orientation as the one before: one stays
            [6, 7, 8],
        ];
        assert_eq!(cancel_duplicate_faces(faces), vec![[3, 4, 5], [6, 7, 8]]);
        let three = vec![[0, 1, 2], [2, 1, 0], [1, 2, 0]];
        assert_eq!(cancel_duplicate_faces(three), vec![[0, 1, 2]]);
    }

    /// The first pass leaves a valid mesh of the input's topology on distinct original
    /// vertices, ascending, each at its original position, with the locked vertices.
    #[test]
    fn reduced_meshes_are_valid_with_the_same_topology() {
        for (name, m, keep) in [
            (
                "noisy sphere",
                procedural::with_noise(procedural::icosphere(5), 0.3, 3),
                1000,
            ),
            (
                "torus",
                procedural::with_noise(procedural::torus(200, 60, 1.0, 0.3), 0.2, 1),
                1500,
            ),
            ("grid", procedural::grid(80, 60, 2.0, 1.0), 800),
            ("genus 2", procedural::builtin("genus2").unwrap(), 1000),
        ] {
            let mesh = valid(m);
            let locked = [3, 77, 500];
            let r = first_pass(&mesh, keep, &locked, &NoProgress)
                .unwrap()
                .unwrap_or_else(|| panic!("{name}"));
            let n = r.mesh.n_vertices();
            assert!(n < mesh.n_vertices() / 2 && n > keep / 2, "{name}: {n}");
            assert!(r.original.windows(2).all(|w| w[0] < w[1]), "{name}");
            for (i, &v) in r.original.iter().enumerate() {
                assert_eq!(r.mesh.positions[i], mesh.positions[v as usize]);
            }
            let (a, b) = (mesh.topology(), r.mesh.topology());
            assert_eq!(a.genus(), b.genus(), "{name}");
            assert_eq!(a.boundary_loops().len(), b.boundary_loops().len(), "{name}");
            assert!(locked.iter().all(|l| r.original.binary_search(l).is_ok()));
        }
    }

    /// A vertex collapsed onto one three rings away (the simplifier's pinch: two fans on
    /// one vertex) is split, and its copy takes the nearest unused
    /// original vertex, here the collapsed one itself: the input comes back.
    #[test]
    fn pinched_vertices_take_fresh_original_ids() {
        let mesh = valid(procedural::icosphere(3));
        // `a` three rings from `b`: the two fans share no vertex but `b`.
        let (b, topo) = (0u32, mesh.topology());
        let mut near: Vec<u32> = vec![b];
        for _ in 0..2 {
            let next: Vec<u32> = near.iter().flat_map(|&u| topo.ring(u).to_vec()).collect();
            near.extend(next);
        }
        let a = (near.iter())
            .flat_map(|&u| topo.ring(u).to_vec())
            .find(|w| !near.contains(w))
            .unwrap();
        let pinched: Vec<[u32; 3]> = (mesh.triangles.iter())
            .map(|t| t.map(|v| if v == a { b } else { v }))
            .collect();
        let broken = TriMesh::new(mesh.positions.clone(), pinched.clone());
        assert!(
            ValidMesh::new(broken).is_err(),
            "the pinch is not a valid mesh"
        );
        let r = clean(&mesh, pinched, &[], &NoProgress).unwrap();
        assert_eq!(
            r.original,
            (0..mesh.n_vertices() as u32).collect::<Vec<_>>()
        );
        assert_eq!(r.mesh.n_faces(), mesh.n_faces());
        assert_eq!(r.mesh.topology().genus(), 0);
        // A face set the simplifier left intact comes back unchanged.
        let grid = valid(procedural::grid(20, 20, 1.0, 1.0));
        let r = clean(&grid, grid.triangles.clone(), &[], &NoProgress).unwrap();
        assert_eq!(
            r.original,
            (0..grid.n_vertices() as u32).collect::<Vec<_>>()
        );
    }
}
