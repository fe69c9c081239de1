//! The defaults of remeshing every front end offers (`wavg remesh`, `/api/remesh` and
//! `/api/cage`, Python's `Remesher`), and the size of the cage decimated from a surface
//! to start from.

/// Default levels of splitting.
pub const DEFAULT_LEVELS: usize = 2;

/// Default Laplacian smoothing steps after splitting.
pub const DEFAULT_SMOOTH_STEPS: usize = 3;

/// Default vertex count of a starting cage decimated from the surface: coarse enough to
/// drag by hand, fine enough to follow the shape of a typical model.
pub const DEFAULT_CAGE_VERTICES: usize = 40;

/// Fewest vertices of a decimated cage (a tetrahedron).
pub const MIN_CAGE_VERTICES: usize = 4;

/// Most vertices of a decimated cage: a cage is a coarse base, and remeshing multiplies
/// its faces.
pub const MAX_CAGE_VERTICES: usize = 5000;

/// The largest cage a surface of `n_vertices` vertices gives: its vertex count within
/// [`MIN_CAGE_VERTICES`]`..=`[`MAX_CAGE_VERTICES`].
pub fn max_cage_vertices(n_vertices: usize) -> usize {
    n_vertices.clamp(MIN_CAGE_VERTICES, MAX_CAGE_VERTICES)
}

/// The default cage size for a surface of `n_vertices` vertices: [`DEFAULT_CAGE_VERTICES`],
/// or [`max_cage_vertices`] when that is smaller.
pub fn default_cage_vertices(n_vertices: usize) -> usize {
    DEFAULT_CAGE_VERTICES.min(max_cage_vertices(n_vertices))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cage_sizes_stay_within_the_surface_and_the_bounds() {
        assert_eq!(max_cage_vertices(2), MIN_CAGE_VERTICES);
        assert_eq!(max_cage_vertices(30), 30);
        assert_eq!(max_cage_vertices(1_000_000), MAX_CAGE_VERTICES);
        assert_eq!(default_cage_vertices(30), 30);
        assert_eq!(default_cage_vertices(1_000_000), DEFAULT_CAGE_VERTICES);
        assert_eq!(default_cage_vertices(2), MIN_CAGE_VERTICES);
    }
}
