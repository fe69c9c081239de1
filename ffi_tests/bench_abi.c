/* Timings of the C interface's batch calls (not a test): wavg_forward, wavg_inverse and
 * the verified wavg_inverse on QUERIES random points, best of ROUNDS.
 *   bench_abi MESH [QUERIES=100000] [ROUNDS=5] [ANCHORS=32]
 * The Rust side of the comparison, in the same process, is the lab's abi_overhead program
 * (cargo xtask lab abi_overhead). */
#include <time.h>

#include "check.h"

static double now_ms(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec * 1e3 + (double)t.tv_nsec * 1e-6;
}

int main(int argc, char **argv) {
  if (argc < 2) {
    fprintf(stderr, "usage: bench_abi MESH [QUERIES] [ROUNDS] [ANCHORS]\n");
    return 2;
  }
  size_t nq = argc > 2 ? strtoul(argv[2], NULL, 10) : 100000;
  int rounds = argc > 3 ? atoi(argv[3]) : 5;
  size_t na = argc > 4 ? strtoul(argv[4], NULL, 10) : 32;
  wavg_surface *s = NULL;
  CHECK_OK(wavg_surface_open(argv[1], &s));
  wavg_precompute_options o = wavg_precompute_options_default();
  o.quality_pairs = 0;
  CHECK_OK(wavg_surface_precompute(s, &o, NULL, NULL));
  size_t nl = 0, nt = wavg_surface_face_count(s);
  CHECK_OK(wavg_surface_landmarks(s, NULL, 0, &nl));
  uint32_t *lm = malloc(sizeof(uint32_t) * nl);
  CHECK_OK(wavg_surface_landmarks(s, lm, nl, &nl));
  wavg_point *anchors = malloc(sizeof(wavg_point) * na);
  for (size_t i = 0; i < na; i++) CHECK_OK(wavg_surface_vertex_point(s, lm[i * nl / na], &anchors[i]));
  wavg_solver *solver = NULL;
  CHECK_OK(wavg_solver_new(s, anchors, na, &solver));

  unsigned long long seed = 11;
  wavg_point *pts = malloc(sizeof(wavg_point) * nq), *out = malloc(sizeof(wavg_point) * nq);
  double *w = malloc(sizeof(double) * nq * na), *fw = malloc(sizeof(double) * nq * na);
  double *xyz = malloc(sizeof(double) * 3 * nq);
  wavg_status *st = malloc(sizeof(wavg_status) * nq);
  for (size_t i = 0; i < nq; i++) pts[i] = random_point(&seed, nt);
  wavg_inverse(solver, pts, nq, false, fw, st);
  for (size_t i = 0; i < nq; i++)
    if (st[i] != WAVG_STATUS_OK)
      for (size_t k = 0; k < na; k++) fw[i * na + k] = k == 0 ? 1.0 : 0.0;

  double best[3] = {1e300, 1e300, 1e300};
  for (int r = 0; r < rounds; r++) {
    double t = now_ms();
    wavg_forward(solver, fw, nq, out, xyz, st);
    best[0] = fmin(best[0], now_ms() - t);
    t = now_ms();
    wavg_inverse(solver, pts, nq, false, w, st);
    best[1] = fmin(best[1], now_ms() - t);
    t = now_ms();
    wavg_inverse(solver, pts, nq, true, w, st);
    best[2] = fmin(best[2], now_ms() - t);
  }
  printf("queries %zu, anchors %zu, best of %d\n", nq, na, rounds);
  printf("%-18s %10s %12s\n", "operation", "c_abi_ms", "us_per_query");
  const char *names[3] = {"forward", "inverse", "inverse_verified"};
  for (int k = 0; k < 3; k++)
    printf("%-18s %10.2f %12.3f\n", names[k], best[k], best[k] * 1e3 / (double)nq);
  wavg_solver_free(solver);
  wavg_surface_free(s);
  free(lm); free(anchors); free(pts); free(out); free(w); free(fw); free(xyz); free(st);
  return 0;
}
