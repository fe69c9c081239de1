//! A bounding volume hierarchy of the embedded triangles in R^8 (axis-aligned boxes, f32,
//! rounded outwards so the bounds stay conservative). It turns "is there a closer valid
//! projection anywhere?" into a branch and bound that only visits triangles whose box is
//! closer than the best answer so far.

use crate::Vec8;

/// Triangles per leaf.
const LEAF: usize = 4;
/// Traversal stack size; the median split keeps the depth near log2(faces / LEAF).
const STACK: usize = 96;

#[derive(Clone, Copy, Debug, Default)]
struct Node {
    lo: [f32; 8],
    hi: [f32; 8],
    /// Leaf: first index into `items`; interior: index of the right child (left is next).
    a: u32,
    /// Leaf: number of items (> 0); interior: 0.
    n: u32,
}

/// The hierarchy: nodes in depth-first order and the face ids in leaf order.
#[derive(Clone, Debug)]
pub(crate) struct Bvh {
    nodes: Vec<Node>,
    items: Vec<u32>,
}

/// The largest f32 not above `x` (conservative lower bound).
fn down(x: f64) -> f32 {
    let f = x as f32;
    if f as f64 > x { step(f, false) } else { f }
}

/// The smallest f32 not below `x` (conservative upper bound).
fn up(x: f64) -> f32 {
    let f = x as f32;
    if (f as f64) < x { step(f, true) } else { f }
}

/// Neighbouring f32 towards +inf (`up`) or -inf (`f32::next_up` needs Rust 1.86).
fn step(f: f32, up: bool) -> f32 {
    if f.is_nan() || f.is_infinite() {
        return f;
    }
    if f == 0.0 {
        let tiny = f32::from_bits(1);
        return if up { tiny } else { -tiny };
    }
    let b = f.to_bits();
    let away = (f > 0.0) == up;
    f32::from_bits(if away { b + 1 } else { b - 1 })
}

impl Bvh {
    /// Builds the hierarchy over the triangles `tris` with corners `coords` (median
    /// splits along the widest axis of the centroids; large subtrees in parallel).
    pub(crate) fn new(tris: &[[u32; 3]], coords: &[Vec8]) -> Self {
        use rayon::prelude::*;
        let mut items: Vec<u32> = (0..tris.len() as u32).collect();
        let centers: Vec<[f32; 8]> = tris
            .par_iter()
            .with_min_len(4096)
            .map(|t| {
                let c =
                    (coords[t[0] as usize] + coords[t[1] as usize] + coords[t[2] as usize]) / 3.0;
                std::array::from_fn(|k| c[k] as f32)
            })
            .collect();
        let mut nodes = vec![Node::default(); node_count(tris.len())];
        if !tris.is_empty() {
            let geo = Geometry {
                tris,
                coords,
                centers: &centers,
            };
            build(&mut nodes, 0, &mut items, 0, &geo);
        }
        Self { nodes, items }
    }

    /// Heap bytes used.
    pub(crate) fn bytes(&self) -> usize {
        self.nodes.len() * std::mem::size_of::<Node>() + self.items.len() * 4
    }

    /// Branch and bound: visits (in roughly nearest-first order) every face whose box is
    /// closer to `y` than `sqrt(*best)`; `visit(face, best)` may lower `*best`.
    pub(crate) fn search(&self, y: &Vec8, best: &mut f64, visit: impl FnMut(u32, &mut f64)) {
        self.search_pruned(y, best, |_, _, _| true, visit);
    }

    /// [`Bvh::search`] that skips every subtree `keep(node, lo, hi)` rejects (`lo`, `hi`:
    /// the node's box, which holds every corner of its triangles).
    pub(crate) fn search_pruned(
        &self,
        y: &Vec8,
        best: &mut f64,
        keep: impl Fn(usize, &[f32; 8], &[f32; 8]) -> bool,
        mut visit: impl FnMut(u32, &mut f64),
    ) {
        self.search_leaves(y, best, keep, |faces, best| {
            for &f in faces {
                visit(f, best);
            }
        });
    }

    /// [`Bvh::search_pruned`] visiting a leaf's faces at once: `visit(faces, best)` (so
    /// the visitor can request all their data before reading any).
    pub(crate) fn search_leaves(
        &self,
        y: &Vec8,
        best: &mut f64,
        keep: impl Fn(usize, &[f32; 8], &[f32; 8]) -> bool,
        mut visit: impl FnMut(&[u32], &mut f64),
    ) {
        if self.nodes.is_empty() {
            return;
        }
        let mut stack = [0u32; STACK];
        let mut sp = 1;
        let mut dist = [0.0f64; STACK];
        dist[0] = box_dist2(&self.nodes[0], y);
        while sp > 0 {
            sp -= 1;
            let ni = stack[sp] as usize;
            if dist[sp] >= *best {
                continue;
            }
            let node = &self.nodes[ni];
            if !keep(ni, &node.lo, &node.hi) {
                continue;
            }
            if node.n > 0 {
                visit(
                    &self.items[node.a as usize..(node.a + node.n) as usize],
                    best,
                );
                continue;
            }
            let (l, r) = (ni + 1, node.a as usize);
            let dl = box_dist2(&self.nodes[l], y);
            let dr = box_dist2(&self.nodes[r], y);
            // Push the farther child first so the nearer is explored first.
            let (first, df, second, ds) = if dl <= dr {
                (r, dr, l, dl)
            } else {
                (l, dl, r, dr)
            };
            if sp + 2 > STACK {
                // Cannot happen with median splits; be safe: visit the subtree exhaustively.
                self.visit_all(first, &mut |f, b| visit(&[f], b), best);
                self.visit_all(second, &mut |f, b| visit(&[f], b), best);
                continue;
            }
            if df < *best {
                stack[sp] = first as u32;
                dist[sp] = df;
                sp += 1;
            }
            if ds < *best {
                stack[sp] = second as u32;
                dist[sp] = ds;
                sp += 1;
            }
        }
    }

    /// Best-first branch and bound: visits the leaves in increasing order of their box's
    /// distance to `y`, and stops at the first box not closer than `sqrt(*best)`;
    /// `visit(face, best)` may lower `*best`. A box's distance bounds from below the
    /// distance of every point in the convex hull of its triangles' corners, so every face
    /// not visited is at least `sqrt(*best)` away. Visits fewer faces than
    /// [`Bvh::search`] when the first leaves reached depth first are far from the answer.
    /// Subtrees that `keep(node, lo, hi)` rejects are skipped (as in [`Bvh::search_pruned`]).
    pub(crate) fn search_best_first_pruned(
        &self,
        y: &Vec8,
        best: &mut f64,
        keep: impl Fn(usize, &[f32; 8], &[f32; 8]) -> bool,
        mut visit: impl FnMut(u32, &mut f64),
    ) {
        use std::cmp::Reverse;
        use std::collections::BinaryHeap;
        if self.nodes.is_empty() {
            return;
        }
        // Squared distances are non-negative, so their bit patterns sort like the values.
        let mut heap = BinaryHeap::with_capacity(2 * STACK);
        heap.push(Reverse((box_dist2(&self.nodes[0], y).to_bits(), 0u32)));
        while let Some(Reverse((d, ni))) = heap.pop() {
            if f64::from_bits(d) >= *best {
                break;
            }
            let node = &self.nodes[ni as usize];
            if !keep(ni as usize, &node.lo, &node.hi) {
                continue;
            }
            if node.n > 0 {
                for &f in &self.items[node.a as usize..(node.a + node.n) as usize] {
                    visit(f, best);
                }
                continue;
            }
            for c in [ni + 1, node.a] {
                let dc = box_dist2(&self.nodes[c as usize], y);
                if dc < *best {
                    heap.push(Reverse((dc.to_bits(), c)));
                }
            }
        }
    }

    /// Number of nodes (indices `0..n`; a node's children have larger indices).
    pub(crate) fn n_nodes(&self) -> usize {
        self.nodes.len()
    }

    /// Node `ni`: `Ok((left, right))` children of an interior node, `Err(faces)` of a leaf.
    pub(crate) fn node(&self, ni: usize) -> Result<(usize, usize), &[u32]> {
        let n = &self.nodes[ni];
        if n.n > 0 {
            Err(&self.items[n.a as usize..(n.a + n.n) as usize])
        } else {
            Ok((ni + 1, n.a as usize))
        }
    }

    /// The box of node `ni` (`lo`, `hi`): it holds every corner of the node's triangles.
    pub(crate) fn node_box(&self, ni: usize) -> (&[f32; 8], &[f32; 8]) {
        (&self.nodes[ni].lo, &self.nodes[ni].hi)
    }

    fn visit_all(&self, ni: usize, visit: &mut impl FnMut(u32, &mut f64), best: &mut f64) {
        let node = &self.nodes[ni];
        if node.n > 0 {
            for &f in &self.items[node.a as usize..(node.a + node.n) as usize] {
                visit(f, best);
            }
        } else {
            self.visit_all(ni + 1, visit, best);
            self.visit_all(node.a as usize, visit, best);
        }
    }
}

#[inline]
fn box_dist2(n: &Node, y: &Vec8) -> f64 {
    let mut s = 0.0;
    for k in 0..8 {
        let lo = n.lo[k] as f64;
        let hi = n.hi[k] as f64;
        let d = (lo - y[k]).max(y[k] - hi).max(0.0);
        s += d * d;
    }
    s
}

/// Subtrees of at least this many faces are built in parallel.
const PARALLEL_BUILD: usize = 8192;

/// Nodes of the tree over `n` faces (median splits down to `LEAF`).
fn node_count(n: usize) -> usize {
    if n == 0 {
        0
    } else if n <= LEAF {
        1
    } else {
        1 + node_count(n / 2) + node_count(n - n / 2)
    }
}

struct Geometry<'a> {
    tris: &'a [[u32; 3]],
    coords: &'a [Vec8],
    centers: &'a [[f32; 8]],
}

/// Builds the subtree over `items` (at `offset` in the item list) into `nodes`, whose
/// first entry has absolute index `base`; returns its bounding box.
fn build(
    nodes: &mut [Node],
    base: usize,
    items: &mut [u32],
    offset: usize,
    g: &Geometry,
) -> ([f64; 8], [f64; 8]) {
    if items.len() <= LEAF {
        let mut lo = [f64::INFINITY; 8];
        let mut hi = [f64::NEG_INFINITY; 8];
        for &f in items.iter() {
            for &v in &g.tris[f as usize] {
                let c = &g.coords[v as usize];
                for k in 0..8 {
                    lo[k] = lo[k].min(c[k]);
                    hi[k] = hi[k].max(c[k]);
                }
            }
        }
        nodes[0] = Node {
            lo: std::array::from_fn(|k| down(lo[k])),
            hi: std::array::from_fn(|k| up(hi[k])),
            a: offset as u32,
            n: items.len() as u32,
        };
        return (lo, hi);
    }
    let mut clo = [f32::INFINITY; 8];
    let mut chi = [f32::NEG_INFINITY; 8];
    for &f in items.iter() {
        let c = &g.centers[f as usize];
        for k in 0..8 {
            clo[k] = clo[k].min(c[k]);
            chi[k] = chi[k].max(c[k]);
        }
    }
    let mut axis = 0;
    for k in 1..8 {
        if chi[k] - clo[k] > chi[axis] - clo[axis] {
            axis = k;
        }
    }
    let mid = items.len() / 2;
    items.select_nth_unstable_by(mid, |&a, &b| {
        g.centers[a as usize][axis].total_cmp(&g.centers[b as usize][axis])
    });
    let parallel = items.len() >= PARALLEL_BUILD;
    let (left, right) = items.split_at_mut(mid);
    let nl = node_count(left.len());
    let (me, rest) = nodes.split_at_mut(1);
    let (ln, rn) = rest.split_at_mut(nl);
    let right_base = base + 1 + nl;
    let ((llo, lhi), (rlo, rhi)) = if parallel {
        rayon::join(
            || build(ln, base + 1, left, offset, g),
            || build(rn, right_base, right, offset + mid, g),
        )
    } else {
        (
            build(ln, base + 1, left, offset, g),
            build(rn, right_base, right, offset + mid, g),
        )
    };
    let lo: [f64; 8] = std::array::from_fn(|k| llo[k].min(rlo[k]));
    let hi: [f64; 8] = std::array::from_fn(|k| lhi[k].max(rhi[k]));
    me[0] = Node {
        lo: std::array::from_fn(|k| down(lo[k])),
        hi: std::array::from_fn(|k| up(hi[k])),
        a: right_base as u32,
        n: 0,
    };
    (lo, hi)
}
