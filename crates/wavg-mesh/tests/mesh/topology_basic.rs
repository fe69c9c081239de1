//! Topology of procedural meshes: counts, rings, loops.

use wavg_mesh::{ValidMesh, analyze, procedural};

#[test]
fn icosphere_counts_and_rings() {
    let m = ValidMesh::new(procedural::icosphere(3)).unwrap();
    let t = m.topology();
    assert_eq!(t.euler_characteristic(), 2);
    assert_eq!(t.genus(), 0);
    assert_eq!(t.n_components(), 1);
    assert!(t.boundary_loops().is_empty());
    for v in 0..m.n_vertices() as u32 {
        let ring = t.ring(v);
        let faces = t.ring_faces(v);
        assert_eq!(ring.len(), faces.len());
        assert!(ring.len() == 5 || ring.len() == 6);
        // face j contains v, ring[j] and ring[j+1] in ccw order.
        for j in 0..faces.len() {
            let tri = m.triangles[faces[j] as usize];
            let a = ring[j];
            let b = ring[(j + 1) % ring.len()];
            let rot = [tri, [tri[1], tri[2], tri[0]], [tri[2], tri[0], tri[1]]];
            assert!(rot.contains(&[v, a, b]), "v{v} face {:?} ring {a} {b}", tri);
        }
    }
}

#[test]
fn grid_boundary_and_torus_genus() {
    let g = ValidMesh::new(procedural::grid(5, 4, 1.0, 1.0)).unwrap();
    let t = g.topology();
    assert_eq!(t.boundary_loops().len(), 1);
    assert_eq!(t.boundary_loops()[0].len(), 18);
    assert_eq!(t.genus(), 0);
    for v in 0..g.n_vertices() as u32 {
        let ring = t.ring(v);
        let faces = t.ring_faces(v);
        if t.is_boundary_vertex(v) {
            assert_eq!(ring.len(), faces.len() + 1);
        } else {
            assert_eq!(ring.len(), faces.len());
        }
        for j in 0..faces.len() {
            let tri = g.triangles[faces[j] as usize];
            let (a, b) = (ring[j], ring[(j + 1) % ring.len()]);
            let rot = [tri, [tri[1], tri[2], tri[0]], [tri[2], tri[0], tri[1]]];
            assert!(rot.contains(&[v, a, b]));
        }
    }
    let tor = analyze(&procedural::torus(20, 10, 1.0, 0.3));
    assert_eq!(tor.stats.genus, Some(1));
    assert_eq!(tor.stats.euler_characteristic, 0);
    assert!(tor.stats.watertight);
}

#[test]
fn builtins_are_valid() {
    for (name, _) in procedural::BUILTINS {
        let m = procedural::builtin(name).unwrap();
        let a = analyze(&m);
        assert!(a.report.is_valid(), "{name}: {}", a.report);
    }
}

/// The benchmark plates have the genus and vertex count their descriptions give.
#[test]
fn benchmark_plates_have_their_genus_and_size() {
    for (name, genus, n) in [
        ("genus2", 2, 51_390),
        ("genus12", 12, 7_146),
        ("ladder8", 8, 1_650),
    ] {
        let m = procedural::builtin(name).unwrap();
        let st = analyze(&m).stats;
        assert_eq!(st.genus, Some(genus), "{name}");
        assert_eq!(m.n_vertices(), n, "{name}");
        let desc = procedural::BUILTINS.iter().find(|b| b.0 == name).unwrap().1;
        let count = n.to_string();
        let shown = format!(
            "{},{}",
            &count[..count.len() - 3],
            &count[count.len() - 3..]
        );
        assert!(desc.contains(&shown), "{name}: {desc}");
    }
}
