/* Eight threads on one solver at once give exactly the results of one thread. */
#include <pthread.h>

#include "check.h"

enum { NA = 16, NQ = 4000, NT = 8, ROUNDS = 3 };

static const wavg_solver *solver;
static wavg_point pts[NQ];
static double ref_inv[NQ * NA], ref_ver[NQ * NA], fwd_in[NQ * NA], ref_xyz[3 * NQ];
static wavg_point ref_back[NQ];
static int mismatches[NT];

static void *worker(void *arg) {
  int id = (int)(size_t)arg;
  bool verified = id % 2 == 1;
  double *w = malloc(sizeof(double) * NQ * NA);
  double *xyz = malloc(sizeof(double) * 3 * NQ);
  wavg_point *back = malloc(sizeof(wavg_point) * NQ);
  for (int r = 0; r < ROUNDS; r++) {
    wavg_inverse(solver, pts, NQ, verified, w, NULL);
    if (memcmp(w, verified ? ref_ver : ref_inv, sizeof(double) * NQ * NA) != 0) mismatches[id]++;
    wavg_forward(solver, fwd_in, NQ, back, xyz, NULL);
    for (int i = 0; i < NQ; i++) /* field by field: the struct has padding */
      if (!same_point(back[i], ref_back[i])) {
        mismatches[id]++;
        break;
      }
    if (memcmp(xyz, ref_xyz, sizeof(double) * 3 * NQ) != 0) mismatches[id]++;
  }
  free(w);
  free(xyz);
  free(back);
  return NULL;
}

int main(void) {
  double *xyz;
  uint32_t *tris;
  size_t nv, nt;
  wavg_surface *s = torus_surface(64, 24, &xyz, &nv, &tris, &nt);
  precompute_quick(s, 100);
  wavg_point anchors[NA];
  vertex_anchors(s, NA, 97, anchors);
  wavg_solver *sv = NULL;
  CHECK_OK(wavg_solver_new(s, anchors, NA, &sv));
  solver = sv;
  unsigned long long seed = 7;
  for (int i = 0; i < NQ; i++) pts[i] = random_point(&seed, nt);

  /* References from this thread alone. */
  wavg_status st[NQ];
  wavg_inverse(solver, pts, NQ, true, ref_ver, NULL);
  wavg_inverse(solver, pts, NQ, false, ref_inv, st);
  memcpy(fwd_in, ref_inv, sizeof fwd_in);
  int answered = 0;
  for (int i = 0; i < NQ; i++) {
    if (st[i] == WAVG_STATUS_OK) answered++;
    else
      for (int k = 0; k < NA; k++) fwd_in[i * NA + k] = k == 0 ? 1.0 : 0.0;
  }
  CHECK(answered > NQ / 2);
  CHECK_OK(wavg_forward(solver, fwd_in, NQ, ref_back, ref_xyz, NULL));

  pthread_t th[NT];
  for (int t = 0; t < NT; t++) pthread_create(&th[t], NULL, worker, (void *)(size_t)t);
  for (int t = 0; t < NT; t++) pthread_join(th[t], NULL);
  for (int t = 0; t < NT; t++) CHECK(mismatches[t] == 0);
  wavg_solver_free(sv);
  wavg_surface_free(s);
  free(xyz);
  free(tris);
  return check_report("test_threads");
}
