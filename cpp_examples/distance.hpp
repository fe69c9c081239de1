// Closest points on a triangle mesh (a bounding-volume hierarchy over its triangles) and
// the sampled two-sided distance between two meshes: the harness scores both
// decimations with it.
#ifndef WAVG_HARNESS_DISTANCE_HPP
#define WAVG_HARNESS_DISTANCE_HPP

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

namespace harness {

using Vec3 = Eigen::Vector3d;

/// A triangle soup: positions (3 per vertex) and triangles (3 indices each).
struct Soup {
  std::vector<Vec3> v;
  std::vector<std::array<uint32_t, 3>> f;
  Vec3 corner(size_t t, int c) const { return v[f[t][c]]; }
  Vec3 normal(size_t t) const {
    return (corner(t, 1) - corner(t, 0)).cross(corner(t, 2) - corner(t, 0));
  }
};

/// Closest point of triangle abc to p (Ericson, Real-Time Collision Detection 5.1.5).
inline Vec3 closest_on_triangle(const Vec3 &p, const Vec3 &a, const Vec3 &b, const Vec3 &c) {
  Vec3 ab = b - a, ac = c - a, ap = p - a;
  double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  Vec3 bp = p - b;
  double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  Vec3 cp = p - c;
  double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

/// Bounding-volume hierarchy over a soup's triangles for nearest-triangle queries.
class Bvh {
 public:
  explicit Bvh(const Soup &s) : s_(s), order_(s.f.size()) {
    for (size_t i = 0; i < order_.size(); i++) order_[i] = uint32_t(i);
    centroid_.resize(s.f.size());
    for (size_t t = 0; t < s.f.size(); t++)
      centroid_[t] = (s.corner(t, 0) + s.corner(t, 1) + s.corner(t, 2)) / 3.0;
    build(0, order_.size());
  }

  /// Squared distance from p to the mesh and the nearest triangle.
  std::pair<double, uint32_t> nearest(const Vec3 &p) const {
    double best = std::numeric_limits<double>::infinity();
    uint32_t tri = 0;
    visit(0, p, best, tri);
    return {best, tri};
  }

 private:
  struct Node {
    Vec3 lo, hi;
    uint32_t begin, end, left, right;  // leaf when left == 0
  };

  uint32_t build(size_t begin, size_t end) {
    Node n;
    n.lo = Vec3::Constant(std::numeric_limits<double>::infinity());
    n.hi = -n.lo;
    for (size_t i = begin; i < end; i++)
      for (int c = 0; c < 3; c++) {
        n.lo = n.lo.cwiseMin(s_.corner(order_[i], c));
        n.hi = n.hi.cwiseMax(s_.corner(order_[i], c));
      }
    n.begin = uint32_t(begin);
    n.end = uint32_t(end);
    n.left = n.right = 0;
    uint32_t id = uint32_t(nodes_.size());
    nodes_.push_back(n);
    if (end - begin > 4) {
      int axis;
      (n.hi - n.lo).maxCoeff(&axis);
      size_t mid = (begin + end) / 2;
      std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end,
                       [&](uint32_t a, uint32_t b) { return centroid_[a][axis] < centroid_[b][axis]; });
      uint32_t l = build(begin, mid), r = build(mid, end);
      nodes_[id].left = l;
      nodes_[id].right = r;
    }
    return id;
  }

  double box_dist2(const Node &n, const Vec3 &p) const {
    Vec3 d = (n.lo - p).cwiseMax(p - n.hi).cwiseMax(0.0);
    return d.squaredNorm();
  }

  void visit(uint32_t id, const Vec3 &p, double &best, uint32_t &tri) const {
    const Node &n = nodes_[id];
    if (box_dist2(n, p) >= best) return;
    if (n.left == 0) {
      for (uint32_t i = n.begin; i < n.end; i++) {
        uint32_t t = order_[i];
        double d = (closest_on_triangle(p, s_.corner(t, 0), s_.corner(t, 1), s_.corner(t, 2)) - p)
                       .squaredNorm();
        if (d < best) {
          best = d;
          tri = t;
        }
      }
      return;
    }
    uint32_t a = n.left, b = n.right;
    if (box_dist2(nodes_[b], p) < box_dist2(nodes_[a], p)) std::swap(a, b);
    visit(a, p, best, tri);
    visit(b, p, best, tri);
  }

  const Soup &s_;
  std::vector<uint32_t> order_;
  std::vector<Vec3> centroid_;
  std::vector<Node> nodes_;
};

/// Points on a soup: its vertices and `extra` area-uniform random samples (fixed seed).
inline std::vector<Vec3> samples(const Soup &s, size_t extra, uint32_t seed) {
  std::vector<Vec3> out(s.v.begin(), s.v.end());
  std::vector<double> cdf(s.f.size());
  double total = 0;
  for (size_t t = 0; t < s.f.size(); t++) cdf[t] = total += 0.5 * s.normal(t).norm();
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (size_t k = 0; k < extra; k++) {
    size_t t = std::lower_bound(cdf.begin(), cdf.end(), u(rng) * total) - cdf.begin();
    t = std::min(t, s.f.size() - 1);
    double r1 = std::sqrt(u(rng)), r2 = u(rng);
    out.push_back((1 - r1) * s.corner(t, 0) + r1 * (1 - r2) * s.corner(t, 1) +
                  r1 * r2 * s.corner(t, 2));
  }
  return out;
}

/// Sampled two-sided distance between two surfaces.
struct TwoSided {
  double hausdorff;  ///< largest distance either way
  double mean;       ///< mean of the two directions' mean distances
};

inline TwoSided two_sided(const Soup &a, const Bvh &bvh_a, const Soup &b, const Bvh &bvh_b,
                          size_t extra_samples) {
  double h = 0, means[2];
  const Soup *from[2] = {&a, &b};
  const Bvh *to[2] = {&bvh_b, &bvh_a};
  for (int dir = 0; dir < 2; dir++) {
    std::vector<Vec3> pts = samples(*from[dir], extra_samples, 12345 + dir);
    double sum = 0;
    for (const Vec3 &p : pts) {
      double d = std::sqrt(to[dir]->nearest(p).first);
      h = std::max(h, d);
      sum += d;
    }
    means[dir] = sum / double(pts.size());
  }
  return {h, 0.5 * (means[0] + means[1])};
}

}  // namespace harness

#endif
