//! A geometric nested-dissection ordering for sparse Cholesky factorisations of mesh
//! operators.
//!
//! The vertices are split in two by the median plane across the longest side of their
//! bounding box; the vertices of one half that are coupled to the other half form the
//! separator, which is eliminated last, after both halves have been ordered the same way
//! recursively. On a surface mesh a plane cuts the matrix graph along curves, so separators
//! hold O(√n) vertices and the factor has O(n log n) entries, where a minimum-degree
//! ordering grows faster on large meshes. Small parts are kept in their given order.

/// Parts with at most this many vertices are not split further.
const LEAF: usize = 32;

/// The nested-dissection elimination order of the symmetric pattern whose lower triangle
/// is given in compressed-column form (`col_ptr`, `row_idx`; the diagonal may be present or
/// not), with `positions[i]` the location of unknown `i`.
///
/// Returns `(forward, inverse)`: `forward[k]` is the unknown eliminated `k`-th and
/// `inverse[forward[k]] == k`.
pub(crate) fn nested_dissection(
    col_ptr: &[usize],
    row_idx: &[usize],
    positions: &[[f64; 3]],
) -> (Vec<usize>, Vec<usize>) {
    let n = positions.len();
    let adjacency = Adjacency::from_lower(n, col_ptr, row_idx);
    let mut side = vec![Side::Out; n];
    let mut order = Vec::with_capacity(n);
    let mut parts = vec![Part::Split((0..n as u32).collect())];
    // Depth-first with an explicit stack: a part is replaced by (first half, second half,
    // separator), processed in that order, so each separator follows both its halves.
    while let Some(part) = parts.pop() {
        match part {
            Part::Done(vertices) => order.extend(vertices.iter().map(|&v| v as usize)),
            Part::Split(vertices) if vertices.len() <= LEAF => {
                order.extend(vertices.iter().map(|&v| v as usize));
            }
            Part::Split(vertices) => {
                let (a, b, separator) = dissect(vertices, positions, &adjacency, &mut side);
                parts.push(Part::Done(separator));
                parts.push(Part::Split(b));
                parts.push(Part::Split(a));
            }
        }
    }
    let mut inverse = vec![0; n];
    for (k, &v) in order.iter().enumerate() {
        inverse[v] = k;
    }
    (order, inverse)
}

/// A part of the vertex set still to order.
enum Part {
    /// To be split further (or kept whole if small).
    Split(Vec<u32>),
    /// A separator, appended as it is.
    Done(Vec<u32>),
}

/// Which half of the part being split a vertex lies in.
#[derive(Clone, Copy, PartialEq)]
enum Side {
    Out,
    First,
    Second,
}

/// Symmetric adjacency lists (without the diagonal) in compressed-row form.
struct Adjacency {
    ptr: Vec<usize>,
    idx: Vec<u32>,
}

impl Adjacency {
    fn from_lower(n: usize, col_ptr: &[usize], row_idx: &[usize]) -> Self {
        let mut degree = vec![0usize; n + 1];
        for j in 0..n {
            for &i in &row_idx[col_ptr[j]..col_ptr[j + 1]] {
                if i != j {
                    degree[i] += 1;
                    degree[j] += 1;
                }
            }
        }
        let mut ptr = vec![0usize; n + 1];
        for v in 0..n {
            ptr[v + 1] = ptr[v] + degree[v];
        }
        let mut fill = ptr[..n].to_vec();
        let mut idx = vec![0u32; ptr[n]];
        for j in 0..n {
            for &i in &row_idx[col_ptr[j]..col_ptr[j + 1]] {
                if i != j {
                    idx[fill[i]] = j as u32;
                    fill[i] += 1;
                    idx[fill[j]] = i as u32;
                    fill[j] += 1;
                }
            }
        }
        Self { ptr, idx }
    }

    fn neighbours(&self, v: u32) -> &[u32] {
        &self.idx[self.ptr[v as usize]..self.ptr[v as usize + 1]]
    }
}

/// Splits `vertices` at the median across the longest side of their bounding box and
/// returns the two halves without the separator, and the separator: the boundary vertices
/// of whichever half has fewer of them.
fn dissect(
    mut vertices: Vec<u32>,
    positions: &[[f64; 3]],
    adjacency: &Adjacency,
    side: &mut [Side],
) -> (Vec<u32>, Vec<u32>, Vec<u32>) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for &v in &vertices {
        let p = positions[v as usize];
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let axis = (0..3)
        .max_by(|&a, &b| (hi[a] - lo[a]).total_cmp(&(hi[b] - lo[b])))
        .unwrap_or(0);
    let mid = vertices.len() / 2;
    vertices.select_nth_unstable_by(mid, |&a, &b| {
        positions[a as usize][axis].total_cmp(&positions[b as usize][axis])
    });
    let (first, second) = vertices.split_at(mid);
    for &v in first {
        side[v as usize] = Side::First;
    }
    for &v in second {
        side[v as usize] = Side::Second;
    }
    let touches = |v: u32, other: Side| {
        adjacency
            .neighbours(v)
            .iter()
            .any(|&u| side[u as usize] == other)
    };
    let first_boundary: Vec<bool> = first.iter().map(|&v| touches(v, Side::Second)).collect();
    let second_boundary: Vec<bool> = second.iter().map(|&v| touches(v, Side::First)).collect();
    for &v in &vertices {
        side[v as usize] = Side::Out;
    }
    let count = |flags: &[bool]| flags.iter().filter(|&&f| f).count();
    let (cut, cut_flags, keep) = if count(&first_boundary) <= count(&second_boundary) {
        (first, first_boundary, second)
    } else {
        (second, second_boundary, first)
    };
    let mut separator = Vec::new();
    let mut rest = Vec::with_capacity(cut.len());
    for (&v, &on) in cut.iter().zip(&cut_flags) {
        if on {
            separator.push(v);
        } else {
            rest.push(v);
        }
    }
    (rest, keep.to_vec(), separator)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lower triangle of the 5-point Laplacian pattern of an `m x m` grid.
    fn grid(m: usize) -> (Vec<usize>, Vec<usize>, Vec<[f64; 3]>) {
        let id = |x: usize, y: usize| y * m + x;
        let mut col_ptr = vec![0];
        let mut row_idx = Vec::new();
        let mut positions = Vec::new();
        for y in 0..m {
            for x in 0..m {
                let j = id(x, y);
                row_idx.push(j);
                if x + 1 < m {
                    row_idx.push(id(x + 1, y));
                }
                if y + 1 < m {
                    row_idx.push(id(x, y + 1));
                }
                col_ptr.push(row_idx.len());
                positions.push([x as f64, y as f64, 0.0]);
            }
        }
        (col_ptr, row_idx, positions)
    }

    #[test]
    fn is_a_permutation_with_its_inverse() {
        let (c, r, p) = grid(37);
        let (fwd, inv) = nested_dissection(&c, &r, &p);
        let mut seen = vec![false; p.len()];
        for (k, &v) in fwd.iter().enumerate() {
            assert!(!seen[v]);
            seen[v] = true;
            assert_eq!(inv[v], k);
        }
    }

    #[test]
    fn the_last_separator_splits_the_grid() {
        // The final vertices eliminated form the top-level separator: removing them leaves
        // no edge between the vertices eliminated before, split at the median line.
        let m = 64;
        let (c, r, p) = grid(m);
        let (fwd, _) = nested_dissection(&c, &r, &p);
        // The top-level separator of a square grid is one grid line: m vertices.
        let sep = &fwd[fwd.len() - m..];
        let x0 = p[sep[0]][0];
        let y0 = p[sep[0]][1];
        assert!(
            sep.iter().all(|&v| p[v][0] == x0) || sep.iter().all(|&v| p[v][1] == y0),
            "the last {m} vertices are not one grid line"
        );
    }

    #[test]
    fn small_patterns_keep_their_order() {
        let (c, r, p) = grid(5);
        let (fwd, _) = nested_dissection(&c, &r, &p);
        assert_eq!(fwd, (0..25).collect::<Vec<_>>());
    }
}
