//! Certification and the global searches: branch and bound over the bounding volume
//! hierarchy (the exhaustive search), the literal brute force, and the Euclidean closest
//! point baseline.

use super::*;

impl Projector {
    /// `try_face` if the triangle's own box is closer than `sqrt(bound)` and the answer
    /// is strictly closer than that (Newton's method skipped where the triangle provably
    /// holds no projection: the same answer).
    #[inline]
    pub(super) fn try_face_bounded(&self, f: FaceId, y: &Vec8, bound: f64) -> Option<Best> {
        self.try_face_bounded_with(f, y, bound, true)
    }

    /// [`Projector::try_face_bounded`], with the exclusion test or (`filter == false`,
    /// for the brute force) without.
    #[inline(always)]
    fn try_face_bounded_with(&self, f: FaceId, y: &Vec8, bound: f64, filter: bool) -> Option<Best> {
        let [a, b, c] = self.corners(f);
        let lo = a.inf(&b).inf(&c);
        let hi = a.sup(&b).sup(&c);
        let mut s = 0.0;
        for k in 0..8 {
            let d = (lo[k] - y[k]).max(y[k] - hi[k]).max(0.0);
            s += d * d;
        }
        if s >= bound {
            return None;
        }
        // The (clamped) Phong point lies in the triangle, so the Euclidean distance is a
        // lower bound too, tighter than the box and cheaper than Newton.
        let w = closest_point_barycentric(y, &a, &b, &c);
        if (a * w[0] + b * w[1] + c * w[2] - y).norm_squared() >= bound {
            return None;
        }
        let r = if filter {
            self.try_face_filtered(f, y)
        } else {
            self.try_face(f, y)
        };
        r.filter(|r| r.d2 < bound)
    }

    /// The closest valid Phong projection over all triangles, with the brute force's
    /// answer: the least distance, ties to the lowest face index. Best-first branch and
    /// bound over the hierarchy: the Phong point of a triangle is a convex combination of
    /// its embedded corners, so a box's distance bounds from below the distance of every
    /// triangle under it; nodes are opened nearest first and the search stops at the
    /// first box farther than the best valid projection so far. Boxes at exactly that
    /// distance are still opened (the bound is the next float up), as they may hold an
    /// equally close face of lower index. Subtrees whose tangent-cone bound proves that
    /// none of their triangles holds a projection are skipped.
    pub(super) fn exhaustive(&self, y: &Vec8) -> Option<Best> {
        let mut bound = f64::INFINITY;
        let mut best: Option<Best> = None;
        let keep = cone::keep_filter(self, y);
        self.bvh
            .search_best_first_pruned(y, &mut bound, keep, |f, bound| {
                // `try_face_bounded` keeps answers below the bound: not farther than the best.
                if let Some(b) = self.try_face_bounded(f, y, *bound) {
                    let better = best.is_none_or(|x| b.d2 < x.d2 || (b.d2 == x.d2 && f < x.face));
                    if better {
                        best = Some(b);
                        // The next float up (d2 >= 0): keep boxes at exactly this distance.
                        *bound = f64::from_bits(b.d2.to_bits() + 1);
                    }
                }
            });
        best
    }

    /// Guaranteed path: the closest valid Phong projection over all triangles (best-first
    /// branch and bound over the bounding volume hierarchy, exact: the same answer as
    /// [`Projector::project_brute_force`], ties to the lowest face index).
    pub fn project_exhaustive(&self, y: &Vec8) -> Result<Projection, ProjectError> {
        if !y.iter().all(|v| v.is_finite()) {
            return Err(ProjectError::NonFiniteQuery);
        }
        self.exhaustive(y)
            .map(|b| Self::finish(b, ProjectionPath::Exhaustive))
            .ok_or(ProjectError::NoProjection)
    }

    /// The closest valid Phong projection by a literal scan over every triangle (skipping
    /// only triangles whose bounding box or Euclidean distance is farther than the best so
    /// far; Newton's method on every other one). Slow; for tests and for checking the
    /// other two paths.
    pub fn project_brute_force(&self, y: &Vec8) -> Result<Projection, ProjectError> {
        if !y.iter().all(|v| v.is_finite()) {
            return Err(ProjectError::NonFiniteQuery);
        }
        let mut best: Option<Best> = None;
        for f in 0..self.faces.len() as u32 {
            let bound = best.map_or(f64::INFINITY, |b| b.d2);
            if let Some(b) = self.try_face_bounded_with(f, y, bound, false) {
                best = Some(b);
            }
        }
        best.map(|b| Self::finish(b, ProjectionPath::Exhaustive))
            .ok_or(ProjectError::NoProjection)
    }

    /// Euclidean closest point on the embedded mesh (baseline; discontinuous). A
    /// non-finite query gives a point of face 0 at infinite distance.
    pub fn project_euclidean(&self, y: &Vec8) -> Projection {
        let mut best = Best {
            face: 0,
            xi: [1.0 / 3.0; 3],
            d2: f64::INFINITY,
        };
        if y.iter().all(|v| v.is_finite()) {
            let mut bound = f64::INFINITY;
            self.bvh.search(y, &mut bound, |f, bound| {
                let [a, b, c] = self.corners(f);
                let xi = closest_point_barycentric(y, &a, &b, &c);
                let d2 = (a * xi[0] + b * xi[1] + c * xi[2] - y).norm_squared();
                if d2 < *bound {
                    *bound = d2;
                    best = Best { face: f, xi, d2 };
                }
            });
        }
        Self::finish(best, ProjectionPath::Euclidean)
    }
}
