// Correspondence and texture transfer between two meshes (the paper's application):
// anchors at corresponding vertices on both; each source vertex's weights (inverse
// problem on the source) placed on the target (forward problem). Writes, per source
// vertex, the corresponding target point "face b0 b1 b2" and, if the source OBJ has
// texture coordinates per vertex, the target can look its texture up there.
//
//   wavg_transfer SOURCE TARGET OUT.txt [N_ANCHORS]
// The anchors are N (default 40) vertices with the same index on both meshes (for
// meshes in vertex correspondence, e.g. poses of one character); a plugin would take
// them from the user.
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iostream>

#include "wavg.hpp"

int main(int argc, char **argv) try {
  if (argc < 4) {
    std::cerr << "usage: wavg_transfer SOURCE TARGET OUT.txt [N_ANCHORS]\n";
    return 2;
  }
  size_t n_anchors = argc > 4 ? std::strtoul(argv[4], nullptr, 10) : 40;
  wavg::Surface source = wavg::Surface::open(argv[1]);
  wavg::Surface target = wavg::Surface::open(argv[2]);
  wavg_precompute_options opts = wavg_precompute_options_default();
  opts.landmarks = 500;
  opts.quality_pairs = 0;
  source.precompute(&opts);
  target.precompute(&opts);

  // Anchors: landmarks of the source, at the same vertex indices on the target.
  std::vector<uint32_t> lm = source.landmarks();
  std::vector<wavg_point> on_source, on_target;
  for (size_t i = 0; i < n_anchors; i++) {
    uint32_t v = lm[i * lm.size() / n_anchors];
    on_source.push_back(source.vertex_point(v));
    on_target.push_back(target.vertex_point(v));
  }
  wavg::Solver from(source, on_source), to(target, on_target);

  const size_t nv = source.vertex_count();
  std::vector<wavg_point> points(nv);
  for (uint32_t v = 0; v < nv; v++) points[v] = source.vertex_point(v);
  std::vector<wavg_status> inv_status;
  std::vector<double> w = from.inverse(points, true, &inv_status);
  for (size_t v = 0; v < nv; v++)  // points without weights: skip (their rows are NaN)
    if (inv_status[v] != WAVG_STATUS_OK)
      for (size_t k = 0; k < n_anchors; k++) w[v * n_anchors + k] = 1.0 / double(n_anchors);
  wavg::ForwardBatch mapped = to.forward(w);

  // Quality against the identity map (exact for meshes in vertex correspondence).
  std::vector<double> txyz = target.positions();
  double diag = 0;
  {
    double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
    for (size_t i = 0; i < txyz.size(); i++) {
      lo[i % 3] = std::min(lo[i % 3], txyz[i]);
      hi[i % 3] = std::max(hi[i % 3], txyz[i]);
    }
    diag = std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                     (hi[2] - lo[2]) * (hi[2] - lo[2]));
  }
  std::ofstream out(argv[3]);
  size_t ok = 0;
  double err_sum = 0;
  for (size_t v = 0; v < nv; v++) {
    bool good = inv_status[v] == WAVG_STATUS_OK && mapped.statuses[v] == WAVG_STATUS_OK;
    const wavg_point &p = mapped.points[v];
    out << (good ? long(p.face) : -1L) << ' ' << p.bary[0] << ' ' << p.bary[1] << ' '
        << p.bary[2] << '\n';
    if (!good || v >= txyz.size() / 3) continue;
    ok++;
    const double *q = &mapped.xyz[3 * v], *t = &txyz[3 * v];
    err_sum += std::sqrt((q[0] - t[0]) * (q[0] - t[0]) + (q[1] - t[1]) * (q[1] - t[1]) +
                         (q[2] - t[2]) * (q[2] - t[2]));
  }
  double mean_err = ok ? err_sum / double(ok) / diag : NAN;
  std::cout << "{\"vertices\": " << nv << ", \"mapped\": " << ok
            << ", \"mean_error_over_diagonal\": " << mean_err << "}\n";
  // For meshes in correspondence the map should be close to the identity.
  return ok >= nv * 9 / 10 && mean_err < 0.05 ? 0 : 1;
} catch (const wavg::Error &e) {
  std::cerr << "wavg error " << e.status() << ": " << e.what() << '\n';
  return 1;
}
