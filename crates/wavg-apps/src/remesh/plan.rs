//! The connectivity of semiregular remeshing, which depends only on the base's faces: for
//! every level the stencils of the new vertices (which old vertices each one averages with
//! equal weights), the faces of the finest mesh, and its smoothing stencils.

use std::collections::HashMap;

use super::base::{boundary_vertices, polygon_edges};

/// Uniform stencils in compressed rows: vertex `i` averages `idx[off[i]..off[i+1]]`
/// with equal weights.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct Stencils {
    pub(crate) off: Vec<u32>,
    pub(crate) idx: Vec<u32>,
}

impl Stencils {
    fn new() -> Self {
        Self {
            off: vec![0],
            idx: Vec::new(),
        }
    }

    fn push(&mut self, corners: &[u32]) {
        self.idx.extend_from_slice(corners);
        self.off.push(self.idx.len() as u32);
    }

    /// Number of stencils.
    pub(crate) fn len(&self) -> usize {
        self.off.len() - 1
    }

    /// Stencil `i` (empty: the vertex stays).
    pub(crate) fn get(&self, i: usize) -> &[u32] {
        &self.idx[self.off[i] as usize..self.off[i + 1] as usize]
    }
}

/// One level of splitting: the vertices of the coarser mesh keep their indices
/// (`0..n_old`) and the new ones follow: first one point per edge (the midpoint stencil of
/// its two ends, in order of first appearance), then one point per polygon with four or
/// more corners (the average of all its corners).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Level {
    pub(crate) n_old: usize,
    pub(crate) new: Stencils,
}

/// The whole refinement: levels, the finest faces and the smoothing stencils.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Plan {
    pub(crate) levels: Vec<Level>,
    pub(crate) faces: Vec<Vec<u32>>,
    /// Per finest vertex: its neighbours along edges, or nothing for boundary vertices
    /// (which stay where subdivision put them).
    pub(crate) smooth: Stencils,
}

/// Splits every face once. A triangle `(a, b, c)` with edge points `ab, bc, ca` becomes
/// `(a, ab, ca)`, `(b, bc, ab)`, `(c, ca, bc)`, `(ab, bc, ca)`; a polygon with `n >= 4`
/// corners and face point `m` becomes the `n` quads `(v_i, e_i, m, e_{i-1})` where `e_i`
/// is the point of edge `(v_i, v_{i+1})`, so a quad splits into four quads.
pub(crate) fn split(n_old: usize, faces: &[Vec<u32>]) -> (Level, Vec<Vec<u32>>) {
    let mut new = Stencils::new();
    let mut edge: HashMap<(u32, u32), u32> = HashMap::new();
    let mut next = n_old as u32;
    for f in faces {
        for (a, b) in polygon_edges(f) {
            edge.entry((a.min(b), a.max(b))).or_insert_with(|| {
                new.push(&[a, b]);
                next += 1;
                next - 1
            });
        }
    }
    let mut out = Vec::with_capacity(faces.len() * 4);
    for f in faces {
        let n = f.len();
        let e: Vec<u32> = polygon_edges(f)
            .map(|(a, b)| edge[&(a.min(b), a.max(b))])
            .collect();
        if n == 3 {
            out.push(vec![f[0], e[0], e[2]]);
            out.push(vec![f[1], e[1], e[0]]);
            out.push(vec![f[2], e[2], e[1]]);
            out.push(vec![e[0], e[1], e[2]]);
        } else {
            new.push(f);
            let m = next;
            next += 1;
            for i in 0..n {
                out.push(vec![f[i], e[i], m, e[(i + n - 1) % n]]);
            }
        }
    }
    (Level { n_old, new }, out)
}

/// The neighbours of every vertex along the faces' edges (sorted), empty for boundary
/// vertices.
pub(crate) fn smoothing_stencils(n: usize, faces: &[Vec<u32>]) -> Stencils {
    let mut nb: Vec<Vec<u32>> = vec![Vec::new(); n];
    for f in faces {
        for (a, b) in polygon_edges(f) {
            nb[a as usize].push(b);
            nb[b as usize].push(a);
        }
    }
    let boundary = boundary_vertices(n, faces);
    let mut s = Stencils::new();
    for (v, mut list) in nb.into_iter().enumerate() {
        if boundary[v] {
            list.clear();
        }
        list.sort_unstable();
        list.dedup();
        s.push(&list);
    }
    s
}

/// The plan for `levels` splits of a base with `n_base` vertices and these faces.
pub(crate) fn plan(n_base: usize, faces: &[Vec<u32>], levels: usize) -> Plan {
    let mut n = n_base;
    let mut cur = faces.to_vec();
    let mut out = Vec::with_capacity(levels);
    for _ in 0..levels {
        let (level, next) = split(n, &cur);
        n = level.n_old + level.new.len();
        out.push(level);
        cur = next;
    }
    let smooth = smoothing_stencils(n, &cur);
    Plan {
        levels: out,
        faces: cur,
        smooth,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Undirected edges of a face list.
    fn n_edges(faces: &[Vec<u32>]) -> usize {
        let mut e: Vec<(u32, u32)> = faces
            .iter()
            .flat_map(|f| polygon_edges(f).map(|(a, b)| (a.min(b), a.max(b))))
            .collect();
        e.sort_unstable();
        e.dedup();
        e.len()
    }

    #[test]
    fn counts_follow_the_closed_forms_on_a_mixed_cube() {
        // A cube with one face cut into two triangles and one face a pentagon's worth of
        // corners is not needed: quads + 2 triangles + 1 quad remain closed.
        let faces: Vec<Vec<u32>> = vec![
            vec![0, 3, 2, 1],
            vec![4, 5, 6, 7],
            vec![0, 1, 5, 4],
            vec![1, 2, 6, 5],
            vec![2, 3, 7],
            vec![2, 7, 6],
            vec![3, 0, 4, 7],
        ];
        let mut v = 8;
        let mut f = faces.clone();
        for _ in 0..3 {
            let e = n_edges(&f);
            let tris = f.iter().filter(|p| p.len() == 3).count();
            let polys: usize = f.iter().filter(|p| p.len() > 3).map(Vec::len).sum();
            let big = f.iter().filter(|p| p.len() > 3).count();
            let (level, next) = split(v, &f);
            assert_eq!(level.n_old + level.new.len(), v + e + big);
            assert_eq!(next.len(), 4 * tris + polys);
            assert_eq!(n_edges(&next), 2 * e + 3 * tris + polys);
            // Closed surface: Euler characteristic 2 at every level.
            let v2 = level.n_old + level.new.len();
            assert_eq!(v2 as i64 - n_edges(&next) as i64 + next.len() as i64, 2);
            v = v2;
            f = next;
        }
        // Quads stay quads, triangles stay triangles.
        assert!(f.iter().all(|p| p.len() == 3 || p.len() == 4));
        let p = plan(8, &faces, 3);
        assert_eq!(p.faces, f);
        assert_eq!(p.smooth.len(), v);
        assert!((0..v).all(|i| p.smooth.get(i).len() >= 3));
    }

    #[test]
    fn boundary_vertices_do_not_smooth() {
        // One quad split once: 9 vertices, only the centre is interior.
        let p = plan(4, &[vec![0, 1, 2, 3]], 1);
        assert_eq!(p.faces.len(), 4);
        let moving: Vec<usize> = (0..9).filter(|&i| !p.smooth.get(i).is_empty()).collect();
        assert_eq!(moving, vec![8]);
        assert_eq!(p.smooth.get(8), &[4, 5, 6, 7]);
        assert_eq!(p.levels[0].new.get(0), &[0, 1]);
        assert_eq!(p.levels[0].new.get(4), &[0, 1, 2, 3]);
    }
}
