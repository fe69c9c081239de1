/* Happy path of every entry on a torus made in code: surface from arrays, queries,
 * precompute with progress, save/load, solver, forward/inverse (plain and verified),
 * set_anchor, decimation. */
#include "check.h"

static int progress_calls = 0;

static bool count_progress(wavg_stage stage, double fraction, void *user_data) {
  CHECK(stage >= WAVG_STAGE_DECIMATE && stage <= WAVG_STAGE_QUALITY);
  CHECK(fraction >= 0.0 && fraction <= 1.0);
  CHECK(user_data == &progress_calls);
  progress_calls++;
  return true;
}

int main(void) {
  CHECK(wavg_abi_version() == WAVG_ABI_VERSION);
  char version[32];
  snprintf(version, sizeof version, "%d.%d.%d", WAVG_VERSION_MAJOR, WAVG_VERSION_MINOR,
           WAVG_VERSION_PATCH);
  CHECK(strcmp(wavg_version(), version) == 0);
  CHECK(strcmp(wavg_last_error(), "") == 0);

  double *xyz;
  uint32_t *tris;
  size_t nv, nt;
  wavg_surface *s = torus_surface(48, 16, &xyz, &nv, &tris, &nt);
  CHECK(wavg_surface_vertex_count(s) == nv);
  CHECK(wavg_surface_face_count(s) == nt);

  /* Positions and triangles come back as given. */
  double *pos = malloc(sizeof(double) * 3 * nv);
  uint32_t *tri = malloc(sizeof(uint32_t) * 3 * nt);
  CHECK_OK(wavg_surface_positions(s, pos, 3 * nv));
  CHECK_OK(wavg_surface_triangles(s, tri, 3 * nt));
  CHECK(memcmp(pos, xyz, sizeof(double) * 3 * nv) == 0);
  CHECK(memcmp(tri, tris, sizeof(uint32_t) * 3 * nt) == 0);

  /* Before precomputation: the embedding is the positions padded with zeros. */
  double *emb = malloc(sizeof(double) * 8 * nv);
  CHECK_OK(wavg_surface_embedding(s, emb, 8 * nv));
  CHECK(emb[8 * 5 + 0] == xyz[3 * 5 + 0] && emb[8 * 5 + 2] == xyz[3 * 5 + 2]);
  CHECK(emb[8 * 5 + 3] == 0.0 && emb[8 * 5 + 7] == 0.0);
  size_t n_landmarks = 99;
  CHECK_OK(wavg_surface_landmarks(s, NULL, 0, &n_landmarks));
  CHECK(n_landmarks == 0);

  /* Vertex point: a corner of a triangle holding the vertex. */
  wavg_point vp;
  CHECK_OK(wavg_surface_vertex_point(s, 17, &vp));
  CHECK(vp.face < nt);
  int corner = -1;
  for (int c = 0; c < 3; c++)
    if (vp.bary[c] == 1.0) corner = c;
  CHECK(corner >= 0 && tris[3 * vp.face + corner] == 17);

  /* Precompute with options and a progress callback. */
  wavg_precompute_options opts = wavg_precompute_options_default();
  CHECK(opts.struct_size == sizeof(wavg_precompute_options));
  CHECK(opts.landmarks == 1000);
  opts.landmarks = 60;
  opts.quality_pairs = 0;
  CHECK_OK(wavg_surface_precompute(s, &opts, count_progress, &progress_calls));
  CHECK(progress_calls > 0);
  CHECK_OK(wavg_surface_landmarks(s, NULL, 0, &n_landmarks));
  CHECK(n_landmarks == 60);
  uint32_t landmarks[60];
  size_t got = 0;
  CHECK_OK(wavg_surface_landmarks(s, landmarks, 60, &got));
  CHECK(got == 60);
  for (size_t i = 1; i < 60; i++) CHECK(landmarks[i - 1] < landmarks[i]);
  CHECK_OK(wavg_surface_embedding(s, emb, 8 * nv));
  double spread = 0;
  for (size_t i = 0; i < 8 * nv; i++) {
    CHECK(isfinite(emb[i]));
    spread = fmax(spread, fabs(emb[i]));
  }
  CHECK(spread > 0.5);

  /* Save, then load into a fresh surface on the same arrays: same embedding. */
  const char *path = "test_api_torus.wavg";
  CHECK_OK(wavg_surface_save_embedding(s, path));
  wavg_surface *s2 = NULL;
  CHECK_OK(wavg_surface_from_arrays(xyz, nv, tris, nt, &s2));
  CHECK_OK(wavg_surface_load_embedding(s2, path));
  double *emb2 = malloc(sizeof(double) * 8 * nv);
  CHECK_OK(wavg_surface_embedding(s2, emb2, 8 * nv));
  CHECK(memcmp(emb, emb2, sizeof(double) * 8 * nv) == 0);
  remove(path);

  /* A solver on 12 landmark vertices. */
  enum { NA = 30, NQ = 500 };
  wavg_point anchors[NA];
  for (size_t i = 0; i < NA; i++)
    CHECK_OK(wavg_surface_vertex_point(s, landmarks[i * 2], &anchors[i]));
  wavg_solver *solver = NULL;
  CHECK_OK(wavg_solver_new(s, anchors, NA, &solver));
  CHECK(wavg_solver_anchor_count(solver) == NA);

  /* Inverse then forward returns to the points (those the inverse answered). */
  unsigned long long seed = 1;
  wavg_point pts[NQ], back[NQ];
  static double w[NQ * NA], back_xyz[3 * NQ];
  wavg_status st[NQ];
  for (size_t i = 0; i < NQ; i++) pts[i] = random_point(&seed, nt);
  wavg_status call = wavg_inverse(solver, pts, NQ, false, w, st);
  CHECK(call == WAVG_STATUS_OK || call == WAVG_STATUS_NO_SOLUTION);
  size_t answered = 0, returned = 0;
  for (size_t i = 0; i < NQ; i++) {
    if (st[i] != WAVG_STATUS_OK) continue;
    answered++;
    double sum = 0;
    for (size_t k = 0; k < NA; k++) sum += w[i * NA + k];
    CHECK(fabs(sum - 1.0) < 1e-9);
  }
  CHECK(answered > NQ * 9 / 10);
  /* Replace failed rows by a valid one so the forward batch is all valid. */
  for (size_t i = 0; i < NQ; i++)
    if (st[i] != WAVG_STATUS_OK)
      for (size_t k = 0; k < NA; k++) w[i * NA + k] = k == 0 ? 1.0 : 0.0;
  CHECK_OK(wavg_forward(solver, w, NQ, back, back_xyz, st));
  for (size_t i = 0; i < NQ; i++) {
    double p[3], q[3];
    CHECK(st[i] == WAVG_STATUS_OK);
    CHECK(back[i].face < nt);
    point_position(xyz, tris, pts[i], p);
    point_position(xyz, tris, back[i], q);
    CHECK(dist3(q, back_xyz + 3 * i) < 1e-9);
    if (dist3(p, q) < 1e-6) returned++;
  }
  CHECK(returned > NQ * 9 / 10);
  /* Outputs optional: NULL xyz and statuses give the same points. */
  wavg_point back2[NQ];
  CHECK_OK(wavg_forward(solver, w, NQ, back2, NULL, NULL));
  for (size_t i = 0; i < NQ; i++) CHECK(same_point(back[i], back2[i]));

  /* Verified inverse: every answered row returns to its point. */
  call = wavg_inverse(solver, pts, NQ, true, w, st);
  CHECK(call == WAVG_STATUS_OK || call == WAVG_STATUS_NO_SOLUTION);
  size_t verified = 0;
  for (size_t i = 0; i < NQ; i++) {
    if (st[i] != WAVG_STATUS_OK) {
      CHECK(st[i] == WAVG_STATUS_NO_SOLUTION);
      CHECK(isnan(w[i * NA]));
      continue;
    }
    verified++;
    wavg_point b;
    double p[3], q[3];
    CHECK_OK(wavg_forward(solver, w + i * NA, 1, &b, q, NULL));
    point_position(xyz, tris, pts[i], p);
    CHECK(dist3(p, q) < 1e-3 * 0.2); /* tolerance 1e-3 mean edge lengths (< 0.2 here) */
  }
  CHECK(verified >= answered * 9 / 10);

  /* set_anchor moves an anchor: the weights of a point change. */
  double w1[NA], w2[NA];
  CHECK_OK(wavg_inverse(solver, &anchors[3], 1, false, w1, NULL));
  CHECK(fabs(w1[3] - 1.0) < 1e-6);
  wavg_point moved;
  CHECK_OK(wavg_surface_vertex_point(s, landmarks[57], &moved));
  CHECK_OK(wavg_solver_set_anchor(solver, 3, moved));
  CHECK_OK(wavg_inverse(solver, &moved, 1, false, w2, NULL));
  CHECK(fabs(w2[3] - 1.0) < 1e-6);

  /* Decimation: the coarse vertices are original vertices at the same positions. */
  wavg_surface *coarse = NULL;
  uint32_t original[100];
  CHECK_OK(wavg_surface_decimate(s, 100, original, &coarse));
  CHECK(wavg_surface_vertex_count(coarse) == 100);
  CHECK(wavg_surface_face_count(coarse) == 200); /* genus 1: F = 2V */
  double cpos[300];
  CHECK_OK(wavg_surface_positions(coarse, cpos, 300));
  for (size_t i = 0; i < 100; i++) {
    if (i) CHECK(original[i - 1] < original[i]);
    CHECK(memcmp(cpos + 3 * i, xyz + 3 * original[i], 3 * sizeof(double)) == 0);
  }

  /* The solver outlives its surface. */
  wavg_surface_free(s);
  wavg_surface_free(s2);
  wavg_surface_free(coarse);
  CHECK_OK(wavg_forward(solver, w1, 1, back, NULL, NULL));
  wavg_solver_free(solver);
  wavg_surface_free(NULL);
  wavg_solver_free(NULL);
  free(xyz); free(tris); free(pos); free(tri); free(emb); free(emb2);
  return check_report("test_api");
}
