// A spline on a surface (the paper's application): a closed uniform cubic B-spline whose
// control points are mesh vertices, each sample the weighted average of the control
// points with the B-spline basis weights. Writes the curve as an OBJ polyline.
//
//   wavg_spline MESH OUT.obj [CONTROL_VERTEX...]
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>

#include "wavg.hpp"

int main(int argc, char **argv) try {
  if (argc < 3) {
    std::cerr << "usage: wavg_spline MESH OUT.obj [CONTROL_VERTEX...]\n";
    return 2;
  }
  wavg::Surface surface = wavg::Surface::open(argv[1]);
  wavg_precompute_options opts = wavg_precompute_options_default();
  opts.landmarks = std::min<size_t>(300, surface.vertex_count());
  opts.quality_pairs = 0;
  surface.precompute(&opts);

  // Control points: given vertices, or six landmarks spread over the surface.
  std::vector<wavg_point> control;
  for (int i = 3; i < argc; i++) control.push_back(surface.vertex_point(std::atoi(argv[i])));
  if (control.empty()) {
    std::vector<uint32_t> lm = surface.landmarks();
    for (size_t i = 0; i < 6; i++) control.push_back(surface.vertex_point(lm[i * lm.size() / 6]));
  }
  const size_t k = control.size(), samples_per_span = 32, n = k * samples_per_span;
  wavg::Solver solver(surface, control);

  // Closed uniform cubic B-spline: span i uses control points i-1..i+2 (cyclically).
  std::vector<double> weights(n * k, 0.0);
  for (size_t s = 0; s < n; s++) {
    size_t span = s / samples_per_span;
    double t = double(s % samples_per_span) / samples_per_span;
    double b[4] = {(1 - t) * (1 - t) * (1 - t) / 6, (3 * t * t * t - 6 * t * t + 4) / 6,
                   (-3 * t * t * t + 3 * t * t + 3 * t + 1) / 6, t * t * t / 6};
    for (int j = 0; j < 4; j++) weights[s * k + (span + k - 1 + j) % k] += b[j];
  }
  wavg::ForwardBatch curve = solver.forward(weights);

  std::ofstream out(argv[2]);
  size_t written = 0;
  for (size_t s = 0; s < n; s++) {
    if (curve.statuses[s] != WAVG_STATUS_OK) continue;
    out << "v " << curve.xyz[3 * s] << ' ' << curve.xyz[3 * s + 1] << ' '
        << curve.xyz[3 * s + 2] << '\n';
    written++;
  }
  out << 'l';
  for (size_t i = 1; i <= written; i++) out << ' ' << i;
  if (written) out << " 1";
  out << '\n';
  std::cout << "wrote " << written << " of " << n << " curve samples to " << argv[2] << '\n';
  return written == n ? 0 : 1;
} catch (const wavg::Error &e) {
  std::cerr << "wavg error " << e.status() << ": " << e.what() << '\n';
  return 1;
}
