//! `analyze` against brute-force definitions on random small (often broken) meshes.

use std::collections::{BTreeMap, BTreeSet};

use nalgebra::Vector3;
use proptest::prelude::*;
use wavg_mesh::{Defect, DefectKind, TriMesh, ValidMesh, analyze};

fn find(p: &mut Vec<usize>, x: usize) -> usize {
    if p[x] != x {
        let r = find(p, p[x]);
        p[x] = r;
    }
    p[x]
}

fn components(n: usize, pairs: impl Iterator<Item = (usize, usize)>, members: &[usize]) -> usize {
    let mut p: Vec<usize> = (0..n).collect();
    for (a, b) in pairs {
        let (ra, rb) = (find(&mut p, a), find(&mut p, b));
        p[ra] = rb;
    }
    members
        .iter()
        .map(|&m| find(&mut p, m))
        .collect::<BTreeSet<_>>()
        .len()
}

fn random_mesh(nv: usize, faces: Vec<[u32; 3]>, seed: u64) -> TriMesh {
    // Random positions in general position, so no face is degenerate by accident.
    let positions = (0..nv)
        .map(|i| {
            let x = (i as f64 + 1.0) * 0.7 + seed as f64 * 1e-3;
            Vector3::new(
                x.sin(),
                (2.3 * x).cos(),
                (1.7 * x).sin() * 0.5 + i as f64 * 0.1,
            )
        })
        .collect();
    TriMesh::new(positions, faces)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]
    #[test]
    fn analysis_matches_brute_force(
        nv in 1usize..10,
        raw in proptest::collection::vec((0u32..11, 0u32..11, 0u32..11), 0..24),
        seed in 0u64..100,
    ) {
        let faces: Vec<[u32; 3]> = raw.iter().map(|&(a, b, c)| [a, b, c]).collect();
        let m = random_mesh(nv, faces.clone(), seed);
        let a = analyze(&m);
        let usable: Vec<usize> = (0..faces.len())
            .filter(|&f| {
                let t = faces[f];
                t.iter().all(|&i| (i as usize) < nv) && t[0] != t[1] && t[1] != t[2] && t[0] != t[2]
            })
            .collect();
        // Duplicate faces: (later, previous with the same vertex set).
        let mut dups = Vec::new();
        for (k, &f) in usable.iter().enumerate() {
            let key: BTreeSet<u32> = faces[f].into_iter().collect();
            if let Some(&g) = usable[..k].iter().rev().find(|&&g| faces[g].into_iter().collect::<BTreeSet<_>>() == key) {
                dups.push((f as u32, g as u32));
            }
        }
        let mut got: Vec<(u32, u32)> = a.report.problems.iter().filter_map(|p| match p {
            Defect::DuplicateFace { face, first } => Some((*face, *first)),
            _ => None,
        }).collect();
        got.sort();
        dups.sort();
        prop_assert_eq!(got, dups);
        // Edges and their directed uses.
        let mut edges: BTreeMap<(u32, u32), Vec<(u32, u32)>> = BTreeMap::new();
        for &f in &usable {
            let t = faces[f];
            for c in 0..3 {
                let (x, y) = (t[c], t[(c + 1) % 3]);
                edges.entry((x.min(y), x.max(y))).or_default().push((x, y));
            }
        }
        prop_assert_eq!(a.stats.edges, edges.len());
        let nm = edges.values().filter(|h| h.len() > 2).count();
        prop_assert_eq!(a.report.count(DefectKind::NonManifoldEdge), nm);
        let flips = edges.values().filter(|h| h.len() == 2 && h[0] == h[1]).count();
        prop_assert_eq!(a.report.count(DefectKind::InconsistentOrientation), flips);
        // Referenced vertices, Euler characteristic, components.
        let referenced: BTreeSet<usize> = usable.iter().flat_map(|&f| faces[f].map(|i| i as usize)).collect();
        prop_assert_eq!(a.report.count(DefectKind::UnreferencedVertex), nv - referenced.len());
        prop_assert_eq!(
            a.stats.euler_characteristic,
            referenced.len() as i64 - edges.len() as i64 + usable.len() as i64
        );
        let refs: Vec<usize> = referenced.iter().copied().collect();
        let comps = components(
            nv,
            usable.iter().flat_map(|&f| {
                let t = faces[f];
                [(t[0] as usize, t[1] as usize), (t[1] as usize, t[2] as usize)]
            }),
            &refs,
        );
        prop_assert_eq!(a.stats.components, comps);
        // Boundary loops: components of the graph of single-face edges.
        let bnd: Vec<(usize, usize)> = edges
            .iter()
            .filter(|(_, h)| h.len() == 1)
            .map(|(&(x, y), _)| (x as usize, y as usize))
            .collect();
        let bverts: Vec<usize> = bnd.iter().flat_map(|&(x, y)| [x, y]).collect::<BTreeSet<_>>().into_iter().collect();
        prop_assert_eq!(a.stats.boundary_loops, components(nv, bnd.iter().copied(), &bverts));
        // Fans: faces around v joined across edges (v, w) that have exactly two faces.
        let mut pinched = 0;
        for v in 0..nv as u32 {
            let around: Vec<usize> = usable.iter().copied().filter(|&f| faces[f].contains(&v)).collect();
            if around.len() < 2 {
                continue;
            }
            let mut pairs = Vec::new();
            for i in 0..around.len() {
                for j in i + 1..around.len() {
                    let (f, g) = (faces[around[i]], faces[around[j]]);
                    for &w in &f {
                        if w != v && g.contains(&w) && edges[&(v.min(w), v.max(w))].len() == 2 {
                            pairs.push((i, j));
                        }
                    }
                }
            }
            let all: Vec<usize> = (0..around.len()).collect();
            if components(around.len(), pairs.into_iter(), &all) > 1 {
                pinched += 1;
            }
        }
        prop_assert_eq!(a.report.count(DefectKind::NonManifoldVertex), pinched);
        // Valid exactly when no problem; then the topology agrees with the counts.
        prop_assert_eq!(a.topology.is_some(), a.report.is_valid());
        if a.report.is_valid() {
            let v = ValidMesh::new(m).unwrap();
            let t = v.topology();
            prop_assert_eq!(t.n_components(), comps);
            prop_assert_eq!(t.boundary_loops().len(), a.stats.boundary_loops);
            let ring_total: usize = (0..nv as u32).map(|x| t.ring_faces(x).len()).sum();
            prop_assert_eq!(ring_total, 3 * usable.len());
        }
    }
}

/// A closed double cone whose two apexes have 200k faces each: fan counting must not be
/// quadratic in the valence (it was: minutes instead of a fraction of a second).
#[test]
fn huge_valence_vertex_does_not_hang() {
    let k = 200_000u32;
    let mut positions = vec![Vector3::new(0.0, 0.0, 1.0), Vector3::new(0.0, 0.0, 0.0)];
    for i in 0..k {
        let a = i as f64 / k as f64 * std::f64::consts::TAU;
        positions.push(Vector3::new(a.cos(), a.sin(), 0.0));
    }
    let mut faces = Vec::new();
    for i in 0..k {
        let (p, q) = (2 + i, 2 + (i + 1) % k);
        faces.push([0, p, q]);
        faces.push([1, q, p]);
    }
    let v = ValidMesh::new(TriMesh::new(positions, faces)).unwrap();
    assert_eq!(v.topology().genus(), 0);
    assert_eq!(v.topology().ring(0).len(), k as usize);
}
