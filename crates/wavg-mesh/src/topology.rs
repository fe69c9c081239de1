//! Connectivity of a valid mesh, built once: face adjacency across edges, ordered one-rings
//! with boundary flags, boundary loops, components, Euler characteristic and genus.

use std::ops::Range;

use rayon::prelude::*;

use crate::mesh::{FaceId, NONE, TriMesh, VertexId};

/// Undirected edges as sorted groups of halfedges (`face * 3 + corner`, the edge from
/// corner `c` to corner `c + 1`). Sorted rather than hashed: a sort of large arrays is
/// cache-friendly where hashing is not.
pub(crate) struct EdgeTable {
    keys: Vec<u64>,
    pub(crate) halfedges: Vec<u32>,
    starts: Vec<u32>,
}

impl EdgeTable {
    pub(crate) fn build(tris: &[[u32; 3]], usable: &[bool]) -> Self {
        let key = |a: u32, b: u32| ((a.min(b) as u64) << 32) | a.max(b) as u64;
        let pairs = bucket_sorted(
            tris.iter()
                .enumerate()
                .filter(|&(f, _)| usable[f])
                .flat_map(|(f, t)| {
                    (0..3).map(move |c| (key(t[c], t[(c + 1) % 3]), (f * 3 + c) as u32))
                }),
        );
        let mut starts = Vec::with_capacity(pairs.len() / 2 + 1);
        for i in 0..pairs.len() {
            if i == 0 || pairs[i].0 != pairs[i - 1].0 {
                starts.push(i as u32);
            }
        }
        starts.push(pairs.len() as u32);
        let (keys, halfedges) = pairs.into_iter().unzip();
        Self {
            keys,
            halfedges,
            starts,
        }
    }

    /// Ranges into `halfedges`, one per undirected edge.
    pub(crate) fn groups(&self) -> impl Iterator<Item = Range<usize>> + '_ {
        self.starts.windows(2).map(|w| w[0] as usize..w[1] as usize)
    }

    pub(crate) fn key_vertices(&self, i: usize) -> (u32, u32) {
        ((self.keys[i] >> 32) as u32, self.keys[i] as u32)
    }

    /// Opposite halfedge per halfedge across edges with exactly two faces, else NONE.
    pub(crate) fn manifold_adjacency(&self, n_faces: usize) -> Vec<u32> {
        let mut adj = vec![NONE; n_faces * 3];
        for g in self.groups() {
            if g.len() == 2 {
                let (h0, h1) = (self.halfedges[g.start], self.halfedges[g.start + 1]);
                adj[h0 as usize] = h1;
                adj[h1 as usize] = h0;
            }
        }
        adj
    }

    /// Components of the graph of edges with exactly one incident face.
    pub(crate) fn boundary_loop_count(&self, nv: usize, _tris: &[[u32; 3]]) -> usize {
        let mut uf = UnionFind::new(nv);
        let mut on_boundary = vec![false; nv];
        for g in self.groups() {
            if g.len() == 1 {
                let (a, b) = self.key_vertices(g.start);
                uf.union(a as usize, b as usize);
                on_boundary[a as usize] = true;
                on_boundary[b as usize] = true;
            }
        }
        (0..nv)
            .filter(|&v| on_boundary[v] && uf.find(v) == v)
            .count()
    }
}

/// `(key, payload)` pairs sorted by key then payload, where the key's high 32 bits are a
/// vertex index: a counting sort on the vertex, then a sort of each (small) bucket. Same
/// order as a full sort, in linear time for the first key (comparison sorts of the
/// halfedges would otherwise dominate validation).
pub(crate) fn bucket_sorted(items: impl Iterator<Item = (u64, u32)> + Clone) -> Vec<(u64, u32)> {
    let n_buckets = items
        .clone()
        .map(|(k, _)| (k >> 32) as usize + 1)
        .max()
        .unwrap_or(0);
    let mut offsets = vec![0u32; n_buckets + 1];
    let mut total = 0usize;
    for (k, _) in items.clone() {
        offsets[(k >> 32) as usize + 1] += 1;
        total += 1;
    }
    for i in 0..n_buckets {
        offsets[i + 1] += offsets[i];
    }
    let mut out = vec![(0u64, 0u32); total];
    let mut fill = offsets.clone();
    for item in items {
        let b = (item.0 >> 32) as usize;
        out[fill[b] as usize] = item;
        fill[b] += 1;
    }
    for w in offsets.windows(2) {
        let bucket = &mut out[w[0] as usize..w[1] as usize];
        if bucket.len() > 1 {
            bucket.sort_unstable();
        }
    }
    out
}

/// Vertex to incident faces (CSR), in ascending face order (binary-searchable).
pub(crate) struct VertexFaces {
    offsets: Vec<u32>,
    faces: Vec<u32>,
}

impl VertexFaces {
    pub(crate) fn build(nv: usize, tris: &[[u32; 3]], usable: &[bool]) -> Self {
        let mut offsets = vec![0u32; nv + 1];
        for (f, t) in tris.iter().enumerate() {
            if usable[f] {
                for &v in t {
                    offsets[v as usize + 1] += 1;
                }
            }
        }
        for i in 0..nv {
            offsets[i + 1] += offsets[i];
        }
        let mut fill = offsets.clone();
        let mut faces = vec![0u32; offsets[nv] as usize];
        for (f, t) in tris.iter().enumerate() {
            if usable[f] {
                for &v in t {
                    faces[fill[v as usize] as usize] = f as u32;
                    fill[v as usize] += 1;
                }
            }
        }
        Self { offsets, faces }
    }

    pub(crate) fn faces(&self, v: usize) -> &[u32] {
        &self.faces[self.offsets[v] as usize..self.offsets[v + 1] as usize]
    }
}

fn corner_of(t: &[u32; 3], v: u32) -> usize {
    if t[0] == v {
        0
    } else if t[1] == v {
        1
    } else {
        2
    }
}

/// Number of edge-connected fans among the faces around `v` (1 for a manifold vertex).
/// `seen` and `stack` are scratch buffers reused across vertices (no allocation per vertex).
pub(crate) fn count_fans(
    v: u32,
    faces: &[u32],
    tris: &[[u32; 3]],
    adj: &[u32],
    seen: &mut Vec<bool>,
    stack: &mut Vec<u32>,
) -> usize {
    if faces.len() <= 1 {
        return faces.len();
    }
    seen.clear();
    seen.resize(faces.len(), false);
    stack.clear();
    let mut fans = 0;
    for s in 0..faces.len() {
        if seen[s] {
            continue;
        }
        fans += 1;
        seen[s] = true;
        stack.push(faces[s]);
        while let Some(f) = stack.pop() {
            let c = corner_of(&tris[f as usize], v);
            for e in [c, (c + 2) % 3] {
                let h = adj[f as usize * 3 + e];
                if h != NONE {
                    let g = h / 3;
                    // `faces` is in ascending face order (see VertexFaces): O(log k) lookup
                    // keeps a vertex of huge valence (a cone apex) from taking O(k^2).
                    if let Ok(i) = faces.binary_search(&g) {
                        if !seen[i] {
                            seen[i] = true;
                            stack.push(g);
                        }
                    }
                }
            }
        }
    }
    fans
}

pub(crate) struct UnionFind {
    parent: Vec<u32>,
}

impl UnionFind {
    pub(crate) fn new(n: usize) -> Self {
        Self {
            parent: (0..n as u32).collect(),
        }
    }
    pub(crate) fn find(&mut self, mut x: usize) -> usize {
        while self.parent[x] as usize != x {
            let p = self.parent[x] as usize;
            self.parent[x] = self.parent[p];
            x = p;
        }
        x
    }
    pub(crate) fn union(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            let (lo, hi) = (ra.min(rb), ra.max(rb));
            self.parent[hi] = lo as u32;
        }
    }
}

/// Component id per face (NONE for unusable faces) and the component count.
pub(crate) struct Components {
    pub(crate) of_face: Vec<u32>,
    pub(crate) count: usize,
}

pub(crate) fn face_components(nv: usize, tris: &[[u32; 3]], usable: &[bool]) -> Components {
    let mut uf = UnionFind::new(nv);
    for (f, t) in tris.iter().enumerate() {
        if usable[f] {
            uf.union(t[0] as usize, t[1] as usize);
            uf.union(t[1] as usize, t[2] as usize);
        }
    }
    let mut id = vec![NONE; nv];
    let mut count = 0usize;
    let mut of_face = vec![NONE; tris.len()];
    for (f, t) in tris.iter().enumerate() {
        if usable[f] {
            let r = uf.find(t[0] as usize);
            if id[r] == NONE {
                id[r] = count as u32;
                count += 1;
            }
            of_face[f] = id[r];
        }
    }
    Components { of_face, count }
}

/// Sum over components of (2 - chi_c - b_c) / 2 (oriented manifold meshes only).
pub(crate) fn genus_per_component(
    comps: &Components,
    edges: &EdgeTable,
    tris: &[[u32; 3]],
    usable: &[bool],
) -> i64 {
    let k = comps.count;
    let mut chi = vec![0i64; k];
    let nv = tris
        .iter()
        .zip(usable)
        .filter(|(_, u)| **u)
        .map(|(t, _)| t[0].max(t[1]).max(t[2]) as usize + 1)
        .max()
        .unwrap_or(0);
    let mut verts_seen = vec![false; nv];
    for (f, t) in tris.iter().enumerate() {
        if !usable[f] {
            continue;
        }
        let c = comps.of_face[f] as usize;
        chi[c] += 1;
        for &v in t {
            if !std::mem::replace(&mut verts_seen[v as usize], true) {
                chi[c] += 1;
            }
        }
    }
    // Boundary loops per component: each boundary edge belongs to its face's component.
    // Oriented manifold: at most one boundary halfedge leaves each vertex (`bnd_start`
    // holds its index in `bnd`).
    let mut bnd_start = vec![usize::MAX; nv];
    let mut bnd: Vec<usize> = Vec::new();
    for g in edges.groups() {
        let h = edges.halfedges[g.start];
        let c = comps.of_face[(h / 3) as usize] as usize;
        chi[c] -= 1;
        if g.len() == 1 {
            let t = tris[(h / 3) as usize];
            let a = t[(h % 3) as usize];
            bnd_start[a as usize] = bnd.len();
            bnd.push(h as usize);
        }
    }
    // Join each boundary halfedge to the one leaving its end vertex.
    let mut uf = UnionFind::new(bnd.len());
    for (i, &h) in bnd.iter().enumerate() {
        let t = tris[h / 3];
        let end = t[(h % 3 + 1) % 3];
        let next = bnd_start[end as usize];
        if next != usize::MAX {
            uf.union(i, next);
        }
    }
    let mut loops = vec![0i64; k];
    for (i, &h) in bnd.iter().enumerate() {
        if uf.find(i) == i {
            loops[comps.of_face[h / 3] as usize] += 1;
        }
    }
    (0..k).map(|c| (2 - chi[c] - loops[c]) / 2).sum()
}

/// A vertex's fan of faces: its first face (clockwise), its face count and whether it is
/// open (a boundary vertex).
struct Fan {
    start: u32,
    faces: u32,
    boundary: bool,
}

impl Fan {
    /// The fan of `v`, whose faces (`faces[0]` among them) form one fan.
    fn of(v: u32, faces: &[u32], tris: &[[u32; 3]], adjacency: &[[u32; 3]]) -> Fan {
        // Walk clockwise to the fan's first face (or all the way round).
        let mut start = faces[0];
        let mut boundary = false;
        loop {
            let c = corner_of(&tris[start as usize], v);
            let prev = adjacency[start as usize][c];
            if prev == NONE {
                boundary = true;
                break;
            }
            start = prev;
            if start == faces[0] {
                break;
            }
        }
        let faces = Self::fill(v, start, tris, adjacency, &mut [], &mut []);
        Fan {
            start,
            faces,
            boundary,
        }
    }

    /// Walks the fan of `v` counter-clockwise from its first face `start`, writing its
    /// ring vertices into `ring` and its faces into `ring_faces` as far as they reach;
    /// returns the face count.
    fn fill(
        v: u32,
        start: u32,
        tris: &[[u32; 3]],
        adjacency: &[[u32; 3]],
        ring: &mut [u32],
        ring_faces: &mut [u32],
    ) -> u32 {
        let put = |slots: &mut [u32], i: usize, x: u32| {
            if let Some(s) = slots.get_mut(i) {
                *s = x;
            }
        };
        let mut f = start;
        let c0 = corner_of(&tris[f as usize], v);
        put(ring, 0, tris[f as usize][(c0 + 1) % 3]);
        let mut count = 0usize;
        loop {
            put(ring_faces, count, f);
            count += 1;
            let c = corner_of(&tris[f as usize], v);
            let next = adjacency[f as usize][(c + 2) % 3];
            // An interior fan's last face closes on ring vertex 0.
            if next != start {
                put(ring, count, tris[f as usize][(c + 2) % 3]);
            }
            if next == NONE || next == start {
                break;
            }
            f = next;
        }
        count as u32
    }
}

/// Connectivity of a valid (oriented, manifold, non-degenerate) mesh.
///
/// Conventions: halfedge `3 f + i` runs from corner `i` to corner `i + 1` of face `f`;
/// each vertex's one-ring is counter-clockwise around the outward normal; at a boundary
/// vertex the ring is the fan from the boundary neighbour that follows it on the
/// boundary loop to the one that precedes it.
///
/// ```
/// use wavg_mesh::{ValidMesh, procedural};
/// let m = ValidMesh::new(procedural::grid(4, 3, 1.0, 1.0)).unwrap();
/// let t = m.topology();
/// assert_eq!(t.boundary_loops().len(), 1);
/// assert!(t.is_boundary_vertex(0));
/// assert_eq!(t.ring(0).len(), t.ring_faces(0).len() + 1);
/// ```
#[derive(Clone, Debug)]
pub struct Topology {
    adjacency: Vec<[FaceId; 3]>,
    ring_offsets: Vec<u32>,
    ring: Vec<VertexId>,
    face_offsets: Vec<u32>,
    ring_faces: Vec<FaceId>,
    boundary: Vec<bool>,
    loops: Vec<Vec<VertexId>>,
    component_of_face: Vec<u32>,
    n_components: usize,
    euler: i64,
    genus: i64,
}

impl Topology {
    pub(crate) fn from_parts(
        mesh: &TriMesh,
        adj: Vec<u32>,
        incidence: VertexFaces,
        comps: Components,
        genus: i64,
        euler: i64,
    ) -> Self {
        let nv = mesh.n_vertices();
        let tris = &mesh.triangles;
        let adjacency: Vec<[u32; 3]> = adj
            .par_chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]].map(|h| if h == NONE { NONE } else { h / 3 }))
            .collect();
        drop(adj);
        // Each vertex's fan walked twice, in parallel: once for its sizes, once to fill
        // its slices of the rings.
        let fans: Vec<Fan> = (0..nv)
            .into_par_iter()
            .map(|v| Fan::of(v as u32, incidence.faces(v), tris, &adjacency))
            .collect();
        drop(incidence);
        let mut ring_offsets = Vec::with_capacity(nv + 1);
        let mut face_offsets = Vec::with_capacity(nv + 1);
        ring_offsets.push(0u32);
        face_offsets.push(0u32);
        let (mut r_end, mut f_end) = (0u32, 0u32);
        for fan in &fans {
            r_end += fan.faces + fan.boundary as u32;
            f_end += fan.faces;
            ring_offsets.push(r_end);
            face_offsets.push(f_end);
        }
        let mut ring = vec![0; r_end as usize];
        let mut ring_faces = vec![0; f_end as usize];
        let boundary: Vec<bool> = fans.par_iter().map(|f| f.boundary).collect();
        // Blocks of vertices with their slices of the rings, filled in parallel.
        const BLOCK: usize = 1 << 14;
        let mut blocks = Vec::with_capacity(nv.div_ceil(BLOCK));
        let (mut rest_ring, mut rest_faces) = (&mut ring[..], &mut ring_faces[..]);
        for first in (0..nv).step_by(BLOCK) {
            let last = (first + BLOCK).min(nv);
            let r = (ring_offsets[last] - ring_offsets[first]) as usize;
            let f = (face_offsets[last] - face_offsets[first]) as usize;
            let (r, rr) = std::mem::take(&mut rest_ring).split_at_mut(r);
            let (f, rf) = std::mem::take(&mut rest_faces).split_at_mut(f);
            (rest_ring, rest_faces) = (rr, rf);
            blocks.push((first..last, r, f));
        }
        blocks.into_par_iter().for_each(|(vs, mut r, mut f)| {
            for v in vs {
                let fan = &fans[v];
                let (rv, rr) =
                    std::mem::take(&mut r).split_at_mut((fan.faces + fan.boundary as u32) as usize);
                let (fv, rf) = std::mem::take(&mut f).split_at_mut(fan.faces as usize);
                (r, f) = (rr, rf);
                Fan::fill(v as u32, fan.start, tris, &adjacency, rv, fv);
            }
        });
        drop(fans);
        // Boundary loops: follow boundary halfedges a -> b.
        let mut next_on_boundary = vec![NONE; nv];
        for (f, a) in adjacency.iter().enumerate() {
            for i in 0..3 {
                if a[i] == NONE {
                    next_on_boundary[tris[f][i] as usize] = tris[f][(i + 1) % 3];
                }
            }
        }
        let mut visited = vec![false; nv];
        let mut loops = Vec::new();
        for v in 0..nv {
            if next_on_boundary[v] == NONE || visited[v] {
                continue;
            }
            let mut lp = Vec::new();
            let mut x = v;
            while !visited[x] {
                visited[x] = true;
                lp.push(x as u32);
                x = next_on_boundary[x] as usize;
            }
            loops.push(lp);
        }
        Self {
            adjacency,
            ring_offsets,
            ring,
            face_offsets,
            ring_faces,
            boundary,
            loops,
            component_of_face: comps.of_face,
            n_components: comps.count,
            euler,
            genus,
        }
    }

    /// Number of vertices.
    pub fn n_vertices(&self) -> usize {
        self.boundary.len()
    }

    /// Neighbouring face across edge `i` (from corner `i` to corner `i+1`) of `face`, or [`NONE`].
    #[inline]
    pub fn face_neighbors(&self, face: FaceId) -> [FaceId; 3] {
        self.adjacency[face as usize]
    }

    /// All face adjacencies (one `[FaceId; 3]` per face, [`NONE`] across boundary edges).
    pub fn adjacency(&self) -> &[[FaceId; 3]] {
        &self.adjacency
    }

    /// One-ring neighbours of `v`, counter-clockwise. For a boundary vertex the fan runs
    /// from one boundary neighbour to the other (one more vertex than faces).
    #[inline]
    pub fn ring(&self, v: VertexId) -> &[VertexId] {
        &self.ring
            [self.ring_offsets[v as usize] as usize..self.ring_offsets[v as usize + 1] as usize]
    }

    /// Faces around `v` in the same order: face `j` lies between `ring[j]` and `ring[j+1]`
    /// (cyclically for interior vertices).
    #[inline]
    pub fn ring_faces(&self, v: VertexId) -> &[FaceId] {
        &self.ring_faces
            [self.face_offsets[v as usize] as usize..self.face_offsets[v as usize + 1] as usize]
    }

    /// Whether `v` lies on a boundary loop.
    #[inline]
    pub fn is_boundary_vertex(&self, v: VertexId) -> bool {
        self.boundary[v as usize]
    }

    /// Boundary loops as vertex cycles, each following the boundary halfedges' direction.
    pub fn boundary_loops(&self) -> &[Vec<VertexId>] {
        &self.loops
    }

    /// Connected component of each face.
    pub fn component_of_face(&self, f: FaceId) -> u32 {
        self.component_of_face[f as usize]
    }

    /// Number of connected components.
    pub fn n_components(&self) -> usize {
        self.n_components
    }

    /// Euler characteristic V - E + F.
    pub fn euler_characteristic(&self) -> i64 {
        self.euler
    }

    /// Total genus (sum over components).
    pub fn genus(&self) -> i64 {
        self.genus
    }
}

#[cfg(test)]
mod tests {
    use crate::{ValidMesh, procedural};

    /// Rings built in parallel blocks (a mesh of several blocks, with a boundary) are the
    /// same whatever the thread count, and each is its vertex's fan: every incident face
    /// once, consecutive ring vertices spanning each face.
    #[test]
    fn rings_are_fans_whatever_the_thread_count() {
        let mesh = procedural::grid(300, 130, 2.0, 1.0);
        let build = |threads| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| ValidMesh::new(mesh.clone()).unwrap())
        };
        let (one, two) = (build(1), build(2));
        assert!(mesh.n_vertices() > 2 * (1 << 14));
        let mut incident = vec![Vec::new(); mesh.n_vertices()];
        for (f, t) in mesh.triangles.iter().enumerate() {
            for &v in t {
                incident[v as usize].push(f as u32);
            }
        }
        for v in 0..mesh.n_vertices() as u32 {
            let (t1, t2) = (one.topology(), two.topology());
            assert_eq!(t1.ring(v), t2.ring(v));
            assert_eq!(t1.ring_faces(v), t2.ring_faces(v));
            assert_eq!(t1.is_boundary_vertex(v), t2.is_boundary_vertex(v));
            let (ring, faces) = (t1.ring(v), t1.ring_faces(v));
            let mut sorted = faces.to_vec();
            sorted.sort_unstable();
            assert_eq!(sorted, incident[v as usize], "vertex {v}");
            let open = t1.is_boundary_vertex(v);
            assert_eq!(ring.len(), faces.len() + open as usize);
            for (j, &f) in faces.iter().enumerate() {
                let t = mesh.triangles[f as usize];
                let (a, b) = (ring[j], ring[(j + 1) % ring.len()]);
                let c = t.iter().position(|&x| x == v).unwrap();
                assert_eq!(
                    (t[(c + 1) % 3], t[(c + 2) % 3]),
                    (a, b),
                    "vertex {v} face {f}"
                );
            }
        }
        assert_eq!(
            one.topology().boundary_loops(),
            two.topology().boundary_loops()
        );
        assert_eq!(one.topology().genus(), 0);
    }
}
