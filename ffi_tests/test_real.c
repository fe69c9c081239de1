/* Real meshes through the C interface: open, precompute (1000 landmarks), save and load
 * the embedding, verified inverse and forward round trips; broken files are refused.
 * Usage: test_real DATA_DIR MESH... (relative to DATA_DIR); SKIPPED without the data. */
#include <sys/stat.h>

#include "check.h"

static double mean_edge(const double *xyz, const uint32_t *tris, size_t nt) {
  double sum = 0;
  for (size_t f = 0; f < nt; f++)
    for (int c = 0; c < 3; c++)
      sum += dist3(xyz + 3 * tris[3 * f + c], xyz + 3 * tris[3 * f + (c + 1) % 3]);
  return sum / (double)(3 * nt);
}

static void run_mesh(const char *path) {
  enum { NA = 24, NQ = 5000 };
  wavg_surface *s = NULL;
  CHECK_OK(wavg_surface_open(path, &s));
  size_t nv = wavg_surface_vertex_count(s), nt = wavg_surface_face_count(s);
  double *xyz = malloc(sizeof(double) * 3 * nv);
  uint32_t *tris = malloc(sizeof(uint32_t) * 3 * nt);
  CHECK_OK(wavg_surface_positions(s, xyz, 3 * nv));
  CHECK_OK(wavg_surface_triangles(s, tris, 3 * nt));
  CHECK_OK(wavg_surface_precompute(s, NULL, NULL, NULL));
  size_t nl = 0;
  CHECK_OK(wavg_surface_landmarks(s, NULL, 0, &nl));
  /* The 1000 asked for, plus those around thin parts (the armadillo's fingers): at most as
     many again. */
  CHECK(nl >= 1000 && nl <= 2000);
  uint32_t *lm = malloc(sizeof(uint32_t) * nl);
  CHECK_OK(wavg_surface_landmarks(s, lm, nl, &nl));

  /* Save and load into a second surface opened from the same file. */
  CHECK_OK(wavg_surface_save_embedding(s, "test_real.wavg"));
  wavg_surface *s2 = NULL;
  CHECK_OK(wavg_surface_open(path, &s2));
  CHECK_OK(wavg_surface_load_embedding(s2, "test_real.wavg"));
  remove("test_real.wavg");
  double *e1 = malloc(sizeof(double) * 8 * nv), *e2 = malloc(sizeof(double) * 8 * nv);
  CHECK_OK(wavg_surface_embedding(s, e1, 8 * nv));
  CHECK_OK(wavg_surface_embedding(s2, e2, 8 * nv));
  CHECK(memcmp(e1, e2, sizeof(double) * 8 * nv) == 0);

  wavg_point anchors[NA];
  for (size_t i = 0; i < NA; i++)
    CHECK_OK(wavg_surface_vertex_point(s2, lm[i * (nl / NA)], &anchors[i]));
  wavg_solver *solver = NULL;
  CHECK_OK(wavg_solver_new(s2, anchors, NA, &solver));
  wavg_point *pts = malloc(sizeof(wavg_point) * NQ), *back = malloc(sizeof(wavg_point) * NQ);
  double *w = malloc(sizeof(double) * NQ * NA), *bxyz = malloc(sizeof(double) * 3 * NQ);
  wavg_status *st = malloc(sizeof(wavg_status) * NQ);
  unsigned long long seed = 3;
  for (size_t i = 0; i < NQ; i++) pts[i] = random_point(&seed, nt);
  wavg_status call = wavg_inverse(solver, pts, NQ, true, w, st);
  CHECK(call == WAVG_STATUS_OK || call == WAVG_STATUS_NO_SOLUTION);
  size_t ok = 0;
  for (size_t i = 0; i < NQ; i++) {
    if (st[i] == WAVG_STATUS_OK) ok++;
    else {
      CHECK(st[i] == WAVG_STATUS_NO_SOLUTION);
      for (size_t k = 0; k < NA; k++) w[i * NA + k] = 1.0 / NA; /* any valid row */
    }
  }
  CHECK(ok >= NQ * 9 / 10);
  wavg_status fcall = wavg_forward(solver, w, NQ, back, bxyz, st);
  CHECK(fcall == WAVG_STATUS_OK || fcall == WAVG_STATUS_NO_SOLUTION);
  double tol = 1e-3 * mean_edge(xyz, tris, nt) * 1.0000001;
  size_t returned = 0;
  for (size_t i = 0; i < NQ; i++) {
    double p[3];
    point_position(xyz, tris, pts[i], p);
    if (st[i] == WAVG_STATUS_OK && dist3(p, bxyz + 3 * i) <= tol) returned++;
  }
  CHECK(returned >= ok); /* every verified row returns to its point */
  printf("%s: %zu vertices, %zu/%d verified inverses, %zu round trips within %.3g\n", path,
         nv, ok, NQ, returned, tol);
  wavg_solver_free(solver);
  wavg_surface_free(s);
  wavg_surface_free(s2);
  free(xyz); free(tris); free(lm); free(e1); free(e2); free(pts); free(back); free(w);
  free(bxyz); free(st);
}

int main(int argc, char **argv) {
  struct stat sb;
  if (argc < 2 || stat(argv[1], &sb) != 0) {
    printf("SKIPPED: no test data folder (set WAVG_DATA_DIR)\n");
    return 77; /* ctest's SKIP_RETURN_CODE: reported as skipped, not passed */
  }
  char path[4096];
  for (int i = 2; i < argc; i++) {
    snprintf(path, sizeof path, "%s/%s", argv[1], argv[i]);
    run_mesh(path);
  }
  /* Broken files are refused with a status and a message. */
  struct {
    const char *file;
    wavg_status expected;
  } bad[] = {{"bad/tosca_cat0_malformed.off", WAVG_STATUS_IO},
             {"bad/trimesh_joined_tetrahedra.obj", WAVG_STATUS_INVALID_MESH},
             {"bad/camel-reference.obj.gz", WAVG_STATUS_INVALID_MESH},
             {"bad/cow.obj", WAVG_STATUS_INVALID_MESH},
             {"bad/beetle.obj", WAVG_STATUS_INVALID_MESH},
             {"bad/suzanne.obj", WAVG_STATUS_INVALID_MESH},
             {"meshes/no-such-mesh.off", WAVG_STATUS_IO}};
  for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
    wavg_surface *s = (wavg_surface *)0x1;
    snprintf(path, sizeof path, "%s/%s", argv[1], bad[i].file);
    CHECK_FAILS(bad[i].expected, wavg_surface_open(path, &s));
    CHECK(s == (wavg_surface *)0x1);
  }
  return check_report("test_real");
}
