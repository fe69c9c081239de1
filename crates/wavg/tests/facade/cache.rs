//! The embedding cache and the default options: keys follow the mesh and the options, an
//! entry gives back the very embedding that was stored, a damaged entry is computed again,
//! listing and clearing, and the default options are what every door uses.

use wavg::cache::{Cache, EntryInfo};
use wavg::{NoProgress, PrecomputeOptions, Provenance, Surface, ValidMesh};

fn torus() -> ValidMesh {
    ValidMesh::new(wavg::mesh::procedural::torus(24, 10, 1.0, 0.4)).unwrap()
}

fn small() -> PrecomputeOptions {
    PrecomputeOptions {
        landmarks: 40,
        quality_pairs: 0,
        ..Default::default()
    }
}

#[test]
fn key_follows_the_mesh_and_the_options() {
    let a = ValidMesh::new(wavg::mesh::procedural::icosphere(1)).unwrap();
    let mut moved = wavg::mesh::procedural::icosphere(1);
    moved.positions[3].x += 1e-9;
    let b = ValidMesh::new(moved).unwrap();
    let o = wavg::default_precompute_options(&a);
    let other = PrecomputeOptions {
        seed: 7,
        ..o.clone()
    };
    assert_eq!(Cache::key(&a, &o), Cache::key(&a, &o.clone()));
    assert_ne!(Cache::key(&a, &o), Cache::key(&b, &o));
    assert_ne!(Cache::key(&a, &o), Cache::key(&a, &other));
    assert_eq!(Cache::key(&a, &o).len(), 33);
}

#[test]
fn an_entry_gives_back_the_stored_embedding_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let cache = Cache::new(dir.path().join("c"));
    let mesh = torus();
    let info = EntryInfo::new("torus 24x10", "test");
    let (computed, first) =
        wavg::embedding_cached(&mesh, &small(), Some(&cache), &info, &NoProgress).unwrap();
    let Provenance::Computed { stored, .. } = &first.provenance else {
        panic!("an empty cache computes: {first:?}");
    };
    let stored = stored.as_ref().unwrap().as_ref().unwrap().clone();
    assert!(stored.starts_with(cache.dir()));
    let (read, second) =
        wavg::embedding_cached(&mesh, &small(), Some(&cache), &info, &NoProgress).unwrap();
    assert!(matches!(&second.provenance, Provenance::Cached(p) if *p == stored));
    assert_eq!(read.coords, computed.coords);
    assert_eq!(read.landmarks, computed.landmarks);
    // The same as the plain precomputation.
    let (plain, _) = wavg::precompute(&mesh, &small(), &NoProgress).unwrap();
    assert_eq!(plain.coords, computed.coords);

    let list = cache.entries().unwrap();
    assert_eq!(list.len(), 1);
    let meta = list[0].meta.as_ref().unwrap();
    assert_eq!(
        (meta.mesh.as_str(), meta.writer.as_str()),
        ("torus 24x10", "test")
    );
    assert_eq!((meta.vertices, meta.faces, meta.landmarks), (240, 480, 40));
    assert_eq!(list[0].path, stored);
    assert_eq!(list[0].bytes, std::fs::metadata(&stored).unwrap().len());
    // No temporary files are left beside the entry.
    let names: Vec<_> = std::fs::read_dir(cache.dir())
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    assert_eq!(names.len(), 2, "{names:?}");
}

#[test]
fn a_damaged_entry_is_computed_again_and_replaced() {
    let dir = tempfile::tempdir().unwrap();
    let cache = Cache::new(dir.path());
    let mesh = torus();
    let info = EntryInfo::new("t", "test");
    let (good, _) =
        wavg::embedding_cached(&mesh, &small(), Some(&cache), &info, &NoProgress).unwrap();
    let path = cache.path_of(&Cache::key(&mesh, &small()));
    let bytes = std::fs::read(&path).unwrap();
    std::fs::write(&path, &bytes[..bytes.len() / 2]).unwrap();
    assert!(cache.load(&mesh, &small()).unwrap().is_err());
    let (again, outcome) =
        wavg::embedding_cached(&mesh, &small(), Some(&cache), &info, &NoProgress).unwrap();
    assert!(outcome.unusable_entry.is_some());
    assert!(matches!(outcome.provenance, Provenance::Computed { .. }));
    assert_eq!(again.coords, good.coords);
    assert_eq!(std::fs::read(&path).unwrap(), bytes);
}

#[test]
fn clear_removes_every_entry_and_an_absent_folder_is_empty() {
    let dir = tempfile::tempdir().unwrap();
    let cache = Cache::new(dir.path().join("never-made"));
    assert!(cache.entries().unwrap().is_empty());
    let mesh = torus();
    let info = EntryInfo::new("t", "test");
    for seed in [1, 2] {
        let o = PrecomputeOptions { seed, ..small() };
        wavg::embedding_cached(&mesh, &o, Some(&cache), &info, &NoProgress).unwrap();
    }
    // A user's own `.wavg` files in the folder are neither listed nor removed.
    let mine = [
        dir.path().join("never-made").join("mine.wavg"),
        dir.path()
            .join("never-made")
            .join(format!("{}.wavg", "0".repeat(33))),
    ];
    for m in &mine {
        std::fs::write(m, b"mine").unwrap();
    }
    assert_eq!(cache.entries().unwrap().len(), 2);
    assert_eq!(cache.others().unwrap().len(), 2);
    let (n, bytes) = cache.clear().unwrap();
    assert_eq!(n, 2);
    assert!(bytes > 0);
    assert!(cache.entries().unwrap().is_empty());
    assert!(mine.iter().all(|m| m.exists()));
    assert_eq!(cache.others().unwrap(), {
        let mut m = mine.to_vec();
        m.sort();
        m
    });
}

#[test]
fn without_a_cache_nothing_is_written() {
    let mesh = torus();
    let (_, outcome) = wavg::embedding_cached(
        &mesh,
        &small(),
        None,
        &EntryInfo::new("t", "test"),
        &NoProgress,
    )
    .unwrap();
    assert!(matches!(
        outcome.provenance,
        Provenance::Computed { stored: None, .. }
    ));
}

#[test]
fn landmarks_zero_means_the_default_choice() {
    let mesh = torus();
    let zero = PrecomputeOptions {
        landmarks: 0,
        ..wavg::default_precompute_options(&mesh)
    };
    let resolved = wavg::resolve_landmarks(&zero, &mesh);
    assert_eq!(resolved, wavg::default_precompute_options(&mesh));
    assert_eq!(resolved.landmarks, wavg::DEFAULT_LANDMARKS);
    // Explicit counts are kept.
    assert_eq!(wavg::resolve_landmarks(&small(), &mesh).landmarks, 40);
}

#[test]
fn the_surface_and_the_free_function_refuse_the_same_meshes() {
    // Two disjoint tetrahedra: a valid mesh, but two components.
    let mut two = wavg::mesh::procedural::icosphere(0);
    let one = two.clone();
    let n = two.positions.len() as u32;
    two.positions.extend(
        one.positions
            .iter()
            .map(|p| p + wavg::Vector3::new(5.0, 0.0, 0.0)),
    );
    two.triangles
        .extend(one.triangles.iter().map(|t| [t[0] + n, t[1] + n, t[2] + n]));
    let mesh = ValidMesh::new(two).unwrap();
    let free = wavg::precompute(&mesh, &small(), &NoProgress).unwrap_err();
    let mut s = Surface::from_valid(mesh).unwrap();
    let method = s.precompute(&small(), &NoProgress).unwrap_err();
    assert_eq!(free.to_string(), method.to_string());
    assert!(
        free.to_string().contains("2 connected components"),
        "{free}"
    );
    assert_eq!(free.kind(), wavg::ErrorKind::InvalidMesh);
}

#[test]
fn precompute_cached_sets_the_surface_embedding() {
    let dir = tempfile::tempdir().unwrap();
    let cache = Cache::new(dir.path());
    let mut s = Surface::from_valid(torus()).unwrap();
    let info = EntryInfo::new("t", "test");
    s.precompute_cached(&small(), Some(&cache), &info, &NoProgress)
        .unwrap();
    let mut t = Surface::from_valid(torus()).unwrap();
    let outcome = t
        .precompute_cached(&small(), Some(&cache), &info, &NoProgress)
        .unwrap();
    assert!(matches!(outcome.provenance, Provenance::Cached(_)));
    assert_eq!(s.embedded_coords(), t.embedded_coords());
    assert_eq!(s.landmarks(), t.landmarks());
}
