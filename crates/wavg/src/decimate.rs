//! Decimation of a surface's mesh to a vertex count (the landmark decimation of the
//! precomputation, exposed for tools that want the coarse mesh itself).

use wavg_embed::{DecimateOptions, Progress};

use crate::Surface;
use crate::error::Result;

/// A decimated surface: the coarse mesh and where its vertices came from.
#[derive(Clone, Debug)]
pub struct Decimation {
    /// The coarse mesh as a surface (positions as its embedding).
    pub surface: Surface,
    /// Original vertex id of each coarse vertex, ascending (coarse vertex `i` is original
    /// vertex `original[i]`, at the same position).
    pub original: Vec<u32>,
}

impl Surface {
    /// Decimates the mesh by halfedge collapses with quadric priorities and a bound on
    /// normal flips (see [`wavg_embed::decimate`]) to `opts.target` vertices; this surface
    /// is unchanged. Topology (genus, boundary loops, manifoldness) is preserved.
    pub fn decimate(&self, opts: &DecimateOptions, progress: &dyn Progress) -> Result<Decimation> {
        let d = wavg_embed::decimate(self.mesh(), opts, progress)?;
        Ok(Decimation {
            surface: Surface::from_mesh(d.mesh)?,
            original: d.landmarks,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::NoProgress;

    #[test]
    fn coarse_vertices_are_original_vertices() {
        let s = Surface::from_mesh(wavg_mesh::procedural::torus(40, 20, 1.0, 0.3)).unwrap();
        let opts = DecimateOptions {
            target: 100,
            ..Default::default()
        };
        let d = s.decimate(&opts, &NoProgress).unwrap();
        assert_eq!(d.surface.n_vertices(), 100);
        assert!(d.original.windows(2).all(|w| w[0] < w[1]));
        let (fine, coarse) = (&s.mesh().positions, &d.surface.mesh().positions);
        for (i, &v) in d.original.iter().enumerate() {
            assert_eq!(coarse[i], fine[v as usize]);
        }
        // A torus keeps its genus: V - E + F = 0, so F = 2V for a closed triangle mesh.
        assert_eq!(d.surface.n_faces(), 200);
    }
}
