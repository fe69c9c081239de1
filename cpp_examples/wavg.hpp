// A small C++17 wrapper of the wavg C interface: RAII handles and exceptions.
//
//   wavg::Surface s = wavg::Surface::open("pig.off");
//   s.precompute();
//   wavg::Solver solver(s, {s.vertex_point(0), s.vertex_point(100), s.vertex_point(200)});
//   auto w = solver.inverse({s.vertex_point(50)});
//
// Copy this header into a plugin; it depends only on wavg.h.
#ifndef WAVG_HPP
#define WAVG_HPP

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "wavg.h"

namespace wavg {

/// A failed call: its status and the library's message.
class Error : public std::runtime_error {
 public:
  Error(wavg_status status, const std::string &message)
      : std::runtime_error(message), status_(status) {}
  wavg_status status() const noexcept { return status_; }

 private:
  wavg_status status_;
};

/// Throws the calling thread's last error when `s` is not WAVG_STATUS_OK.
inline void check(wavg_status s) {
  if (s != WAVG_STATUS_OK) throw Error(s, wavg_last_error());
}

/// Throws for a batch call's status only when no query carries it (a call-level error);
/// per-query failures are left in `statuses`.
inline void check_batch(wavg_status s, const std::vector<wavg_status> &statuses) {
  if (s == WAVG_STATUS_OK) return;
  for (wavg_status q : statuses)
    if (q == s) return;
  check(s);
}

struct SurfaceDeleter {
  void operator()(wavg_surface *s) const noexcept { wavg_surface_free(s); }
};
struct SolverDeleter {
  void operator()(wavg_solver *s) const noexcept { wavg_solver_free(s); }
};

/// A mesh with its embedding (move-only; const methods are thread-safe).
class Surface {
 public:
  static Surface open(const std::string &path) {
    wavg_surface *s = nullptr;
    check(wavg_surface_open(path.c_str(), &s));
    return Surface(s);
  }
  static Surface from_arrays(const std::vector<double> &xyz,
                             const std::vector<uint32_t> &triangles) {
    wavg_surface *s = nullptr;
    check(wavg_surface_from_arrays(xyz.data(), xyz.size() / 3, triangles.data(),
                                   triangles.size() / 3, &s));
    return Surface(s);
  }

  /// Computes the embedding (`options` nullptr: defaults).
  void precompute(const wavg_precompute_options *options = nullptr,
                  wavg_progress_fn progress = nullptr, void *user_data = nullptr) {
    check(wavg_surface_precompute(h_.get(), options, progress, user_data));
  }
  void load_embedding(const std::string &path) {
    check(wavg_surface_load_embedding(h_.get(), path.c_str()));
  }
  void save_embedding(const std::string &path) const {
    check(wavg_surface_save_embedding(h_.get(), path.c_str()));
  }
  size_t vertex_count() const { return wavg_surface_vertex_count(h_.get()); }
  size_t face_count() const { return wavg_surface_face_count(h_.get()); }
  wavg_point vertex_point(uint32_t v) const {
    wavg_point p;
    check(wavg_surface_vertex_point(h_.get(), v, &p));
    return p;
  }
  std::vector<double> positions() const {
    std::vector<double> out(3 * vertex_count());
    check(wavg_surface_positions(h_.get(), out.data(), out.size()));
    return out;
  }
  std::vector<uint32_t> triangles() const {
    std::vector<uint32_t> out(3 * face_count());
    check(wavg_surface_triangles(h_.get(), out.data(), out.size()));
    return out;
  }
  /// 8 coordinates per vertex.
  std::vector<double> embedding() const {
    std::vector<double> out(8 * vertex_count());
    check(wavg_surface_embedding(h_.get(), out.data(), out.size()));
    return out;
  }
  std::vector<uint32_t> landmarks() const {
    size_t n = 0;
    check(wavg_surface_landmarks(h_.get(), nullptr, 0, &n));
    std::vector<uint32_t> out(n);
    if (n) check(wavg_surface_landmarks(h_.get(), out.data(), n, &n));
    return out;
  }
  /// The mesh decimated to `target` vertices; `original` receives their original ids.
  Surface decimate(size_t target, std::vector<uint32_t> *original = nullptr) const {
    std::vector<uint32_t> ids(target);
    wavg_surface *s = nullptr;
    check(wavg_surface_decimate(h_.get(), target, ids.data(), &s));
    if (original) *original = std::move(ids);
    return Surface(s);
  }
  /// The 3-D position of a surface point.
  static void position(const std::vector<double> &xyz, const std::vector<uint32_t> &tris,
                       const wavg_point &p, double out[3]) {
    for (int k = 0; k < 3; k++) {
      out[k] = 0;
      for (int c = 0; c < 3; c++) out[k] += p.bary[c] * xyz[3 * tris[3 * p.face + c] + k];
    }
  }
  const wavg_surface *get() const noexcept { return h_.get(); }

 private:
  explicit Surface(wavg_surface *s) : h_(s) {}
  std::unique_ptr<wavg_surface, SurfaceDeleter> h_;
};

/// Answers of a forward batch: one point, position and status per query.
struct ForwardBatch {
  std::vector<wavg_point> points;
  std::vector<double> xyz;
  std::vector<wavg_status> statuses;
};

/// Forward and inverse problems for one set of anchors (move-only; const methods are
/// thread-safe).
class Solver {
 public:
  Solver(const Surface &surface, const std::vector<wavg_point> &anchors) {
    wavg_solver *s = nullptr;
    check(wavg_solver_new(surface.get(), anchors.data(), anchors.size(), &s));
    h_.reset(s);
  }
  size_t anchor_count() const { return wavg_solver_anchor_count(h_.get()); }
  void set_anchor(size_t index, const wavg_point &p) {
    check(wavg_solver_set_anchor(h_.get(), index, p));
  }
  /// `weights`: one row of `anchor_count()` weights per query.
  ForwardBatch forward(const std::vector<double> &weights) const {
    size_t n = weights.size() / anchor_count();
    ForwardBatch out{std::vector<wavg_point>(n), std::vector<double>(3 * n),
                     std::vector<wavg_status>(n, WAVG_STATUS_OK)};
    check_batch(wavg_forward(h_.get(), weights.data(), n, out.points.data(), out.xyz.data(),
                             out.statuses.data()),
                out.statuses);
    return out;
  }
  /// One row of `anchor_count()` weights per point (NaN rows for points without an
  /// answer, whose status goes to `statuses` when given).
  std::vector<double> inverse(const std::vector<wavg_point> &points, bool verified = false,
                              std::vector<wavg_status> *statuses = nullptr) const {
    std::vector<double> w(points.size() * anchor_count());
    std::vector<wavg_status> st(points.size(), WAVG_STATUS_OK);
    check_batch(wavg_inverse(h_.get(), points.data(), points.size(), verified, w.data(),
                             st.data()),
                st);
    if (statuses) *statuses = std::move(st);
    return w;
  }
  const wavg_solver *get() const noexcept { return h_.get(); }

 private:
  std::unique_ptr<wavg_solver, SolverDeleter> h_;
};

}  // namespace wavg

#endif
