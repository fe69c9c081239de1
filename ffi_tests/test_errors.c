/* Every bad input returns its status and a message and changes no output. */
#include "check.h"

#define SENTINEL_PTR ((void *)0x1)

int main(void) {
  double *xyz;
  uint32_t *tris;
  size_t nv, nt;
  make_torus(32, 12, 0.35, &xyz, &nv, &tris, &nt);

  /* Surface construction. */
  wavg_surface *s = (wavg_surface *)SENTINEL_PTR;
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_surface_from_arrays(NULL, nv, tris, nt, &s));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_surface_from_arrays(xyz, nv, NULL, nt, &s));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_surface_from_arrays(xyz, 0, tris, nt, &s));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_surface_from_arrays(xyz, nv, tris, 0, &s));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_surface_from_arrays(xyz, nv, tris, nt, NULL));
  /* Fewer vertices than the triangles use: an index out of range. */
  CHECK_FAILS(WAVG_STATUS_INVALID_MESH, wavg_surface_from_arrays(xyz, nv - 1, tris, nt, &s));
  /* A NaN coordinate. */
  double saved = xyz[7];
  xyz[7] = NAN;
  CHECK_FAILS(WAVG_STATUS_INVALID_MESH, wavg_surface_from_arrays(xyz, nv, tris, nt, &s));
  xyz[7] = saved;
  /* Non-manifold: three triangles on one edge. */
  const double fan_xyz[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1};
  const uint32_t fan_tris[] = {0, 1, 2, 1, 0, 3, 0, 1, 4};
  CHECK_FAILS(WAVG_STATUS_INVALID_MESH, wavg_surface_from_arrays(fan_xyz, 5, fan_tris, 3, &s));
  CHECK(s == (wavg_surface *)SENTINEL_PTR);
  /* Files. */
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_surface_open(NULL, &s));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_surface_open("x.obj", NULL));
  CHECK_FAILS(WAVG_STATUS_IO, wavg_surface_open("no/such/mesh.obj", &s));
  CHECK(s == (wavg_surface *)SENTINEL_PTR);

  CHECK_OK(wavg_surface_from_arrays(xyz, nv, tris, nt, &s));

  /* Queries on NULL and with wrong lengths. */
  CHECK(wavg_surface_vertex_count(NULL) == 0);
  CHECK(wavg_surface_face_count(NULL) == 0);
  wavg_point p = {7, {0.25, 0.25, 0.5}};
  const wavg_point p0 = p;
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_surface_vertex_point(NULL, 0, &p));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_surface_vertex_point(s, 0, NULL));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_surface_vertex_point(s, (uint32_t)nv, &p));
  CHECK(memcmp(&p, &p0, sizeof p) == 0);
  double *buf = malloc(sizeof(double) * 8 * nv);
  for (size_t i = 0; i < 8 * nv; i++) buf[i] = -7.0;
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_surface_embedding(s, buf, 8 * nv - 1));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_surface_embedding(s, NULL, 8 * nv));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_surface_embedding(NULL, buf, 8 * nv));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_surface_positions(s, buf, 3 * nv - 1));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_surface_positions(s, NULL, 3 * nv));
  uint32_t *ibuf = malloc(sizeof(uint32_t) * 3 * nt);
  ibuf[0] = 12345;
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_surface_triangles(s, ibuf, 3 * nt - 1));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_surface_triangles(NULL, ibuf, 3 * nt));
  CHECK(ibuf[0] == 12345);
  for (size_t i = 0; i < 8 * nv; i++) CHECK(buf[i] == -7.0);
  size_t n = 42;
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_surface_landmarks(s, NULL, 0, NULL));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_surface_landmarks(NULL, NULL, 0, &n));
  CHECK(n == 42);

  /* Saving without an embedding; loading missing and corrupt files. */
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_surface_save_embedding(s, "never.wavg"));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_surface_save_embedding(s, NULL));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_surface_save_embedding(NULL, "x.wavg"));
  CHECK_FAILS(WAVG_STATUS_IO, wavg_surface_load_embedding(s, "no/such/file.wavg"));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_surface_load_embedding(s, NULL));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_surface_load_embedding(NULL, "x.wavg"));
  FILE *f = fopen("test_errors_corrupt.wavg", "wb");
  fputs("WAVG this is not an embedding file at all, just some text of some length", f);
  fclose(f);
  CHECK_FAILS(WAVG_STATUS_IO, wavg_surface_load_embedding(s, "test_errors_corrupt.wavg"));
  remove("test_errors_corrupt.wavg");
  n = 42;
  CHECK_OK(wavg_surface_landmarks(s, NULL, 0, &n));
  CHECK(n == 0); /* still no embedding */

  /* Precompute options. */
  wavg_precompute_options o = wavg_precompute_options_default();
  o.landmarks = 3;
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_surface_precompute(s, &o, NULL, NULL));
  o = wavg_precompute_options_default();
  o.struct_size = 0;
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_surface_precompute(s, &o, NULL, NULL));
  o = wavg_precompute_options_default();
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_surface_precompute(NULL, &o, NULL, NULL));
  o = wavg_precompute_options_default();
  o.struct_size = sizeof o - 1; /* shorter than any published layout */
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_surface_precompute(s, &o, NULL, NULL));
  n = 42;
  CHECK_OK(wavg_surface_landmarks(s, NULL, 0, &n));
  CHECK(n == 0);
  /* A caller compiled against a newer header (a longer struct) is accepted; the fields
   * this library does not know are ignored. */
  {
    struct {
      wavg_precompute_options known;
      uint64_t from_the_future;
    } newer;
    newer.known = wavg_precompute_options_default();
    newer.known.struct_size = sizeof newer;
    newer.known.landmarks = 20;
    newer.known.quality_pairs = 0;
    newer.from_the_future = 0xdeadbeef;
    wavg_surface *s3 = NULL;
    CHECK_OK(wavg_surface_from_arrays(xyz, nv, tris, nt, &s3));
    CHECK_OK(wavg_surface_precompute(s3, &newer.known, NULL, NULL));
    CHECK_OK(wavg_surface_landmarks(s3, NULL, 0, &n));
    CHECK(n == 20);
    wavg_surface_free(s3);
  }
  /* Nor can a single triangle (fewer than 4 vertices), whatever the options. */
  {
    const double tri_xyz[] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    const uint32_t tri_idx[] = {0, 1, 2};
    wavg_surface *one = NULL;
    CHECK_OK(wavg_surface_from_arrays(tri_xyz, 3, tri_idx, 1, &one));
    o = wavg_precompute_options_default();
    CHECK_FAILS(WAVG_STATUS_INVALID_MESH, wavg_surface_precompute(one, &o, NULL, NULL));
    wavg_surface_free(one);
  }
  /* A mesh with two components cannot be embedded. */
  {
    double *x2 = malloc(sizeof(double) * 6 * nv);
    uint32_t *t2 = malloc(sizeof(uint32_t) * 6 * nt);
    memcpy(x2, xyz, sizeof(double) * 3 * nv);
    for (size_t i = 0; i < 3 * nv; i++) x2[3 * nv + i] = xyz[i] + (i % 3 == 0 ? 5.0 : 0.0);
    memcpy(t2, tris, sizeof(uint32_t) * 3 * nt);
    for (size_t i = 0; i < 3 * nt; i++) t2[3 * nt + i] = tris[i] + (uint32_t)nv;
    wavg_surface *two = NULL;
    CHECK_OK(wavg_surface_from_arrays(x2, 2 * nv, t2, 2 * nt, &two));
    o = wavg_precompute_options_default();
    o.landmarks = 20;
    CHECK_FAILS(WAVG_STATUS_INVALID_MESH, wavg_surface_precompute(two, &o, NULL, NULL));
    wavg_surface_free(two);
    free(x2);
    free(t2);
  }

  /* A .wavg made for another mesh is refused. */
  {
    double *x3;
    uint32_t *t3;
    size_t nv3, nt3;
    make_torus(20, 10, 0.4, &x3, &nv3, &t3, &nt3);
    wavg_surface *other = NULL;
    CHECK_OK(wavg_surface_from_arrays(x3, nv3, t3, nt3, &other));
    o = wavg_precompute_options_default();
    o.landmarks = 20;
    o.quality_pairs = 0;
    CHECK_OK(wavg_surface_precompute(other, &o, NULL, NULL));
    CHECK_OK(wavg_surface_save_embedding(other, "test_errors_other.wavg"));
    CHECK_FAILS(WAVG_STATUS_IO, wavg_surface_load_embedding(s, "test_errors_other.wavg"));
    remove("test_errors_other.wavg");
    wavg_surface_free(other);
    free(x3);
    free(t3);
  }

  /* Solvers. */
  enum { NA = 6 };
  wavg_point anchors[NA];
  for (int i = 0; i < NA; i++) CHECK_OK(wavg_surface_vertex_point(s, (uint32_t)(i * 61), &anchors[i]));
  wavg_solver *solver = (wavg_solver *)SENTINEL_PTR;
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_solver_new(NULL, anchors, NA, &solver));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_solver_new(s, NULL, NA, &solver));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_solver_new(s, anchors, 0, &solver));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_solver_new(s, anchors, NA, NULL));
  wavg_point bad_face = {(uint32_t)nt, {1, 0, 0}};
  wavg_point bad_bary = {3, {0.5, 0.5, 0.5}};
  wavg_point nan_bary = {3, {NAN, 0.5, 0.5}};
  wavg_point with_bad[NA];
  memcpy(with_bad, anchors, sizeof anchors);
  with_bad[2] = bad_face;
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_solver_new(s, with_bad, NA, &solver));
  with_bad[2] = bad_bary;
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_solver_new(s, with_bad, NA, &solver));
  /* A count whose array cannot exist (its byte size overflows) is refused, not wrapped. */
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT,
              wavg_solver_new(s, anchors, (size_t)1 << (sizeof(size_t) * 8 - 1), &solver));
  CHECK(solver == (wavg_solver *)SENTINEL_PTR);
  CHECK_OK(wavg_solver_new(s, anchors, NA, &solver));
  CHECK(wavg_solver_anchor_count(NULL) == 0);
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_solver_set_anchor(NULL, 0, anchors[0]));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_solver_set_anchor(solver, NA, anchors[0]));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_solver_set_anchor(solver, 0, bad_face));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_solver_set_anchor(solver, 0, nan_bary));
  CHECK(wavg_solver_anchor_count(solver) == NA);

  /* Forward: call-level errors write nothing. */
  double w[3 * NA] = {0};
  for (int k = 0; k < NA; k++) w[k] = 1.0 / NA;
  wavg_point out[3];
  double oxyz[9];
  wavg_status st[3];
  memset(out, 0x5a, sizeof out);
  memset(oxyz, 0x5a, sizeof oxyz);
  memset(st, 0x5a, sizeof st);
  unsigned char out0[sizeof out], oxyz0[sizeof oxyz], st0[sizeof st];
  memcpy(out0, out, sizeof out);
  memcpy(oxyz0, oxyz, sizeof oxyz);
  memcpy(st0, st, sizeof st);
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_forward(NULL, w, 1, out, oxyz, st));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_forward(solver, NULL, 1, out, oxyz, st));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_forward(solver, w, 0, out, oxyz, st));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_forward(solver, w, 1, NULL, oxyz, st));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT,
              wavg_forward(solver, w, SIZE_MAX / 4, out, oxyz, st));
  CHECK(memcmp(out, out0, sizeof out) == 0);
  CHECK(memcmp(oxyz, oxyz0, sizeof oxyz) == 0);
  CHECK(memcmp(st, st0, sizeof st) == 0);

  /* Forward: per-query errors (NaN weights, weights not summing to 1) mark their query
   * and the others are answered. */
  for (int k = 0; k < NA; k++) {
    w[NA + k] = 1.0 / NA;
    w[2 * NA + k] = 0.5 / NA;
  }
  w[NA + 1] = NAN;
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_forward(solver, w, 3, out, oxyz, st));
  CHECK(st[0] == WAVG_STATUS_OK && out[0].face < nt && isfinite(oxyz[0]));
  CHECK(st[1] == WAVG_STATUS_INVALID_ARGUMENT && out[1].face == UINT32_MAX);
  CHECK(isnan(oxyz[3]) && isnan(oxyz[4]) && isnan(oxyz[5]) && isnan(out[1].bary[0]));
  CHECK(st[2] == WAVG_STATUS_INVALID_ARGUMENT && out[2].face == UINT32_MAX);
  CHECK(strstr(wavg_last_error(), "query 2") != NULL); /* the second, counted from 1 */

  /* Inverse: call-level errors write nothing; bad points are marked. */
  wavg_point pts[3] = {{5, {0.2, 0.3, 0.5}}, bad_face, bad_bary};
  double iw[3 * NA];
  for (int i = 0; i < 3 * NA; i++) iw[i] = -3.0;
  memset(st, 0x5a, sizeof st);
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_inverse(NULL, pts, 3, false, iw, st));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_inverse(solver, NULL, 3, false, iw, st));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_inverse(solver, pts, 0, false, iw, st));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_inverse(solver, pts, 3, false, NULL, st));
  for (int i = 0; i < 3 * NA; i++) CHECK(iw[i] == -3.0);
  CHECK(memcmp(st, st0, sizeof st) == 0);
  for (int verified = 0; verified < 2; verified++) {
    CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_inverse(solver, pts, 3, verified, iw, st));
    CHECK(st[0] == WAVG_STATUS_OK && isfinite(iw[0]));
    CHECK(st[1] == WAVG_STATUS_INVALID_ARGUMENT && isnan(iw[NA]));
    CHECK(st[2] == WAVG_STATUS_INVALID_ARGUMENT && isnan(iw[2 * NA]));
  }

  /* Decimation arguments. */
  wavg_surface *coarse = (wavg_surface *)SENTINEL_PTR;
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_surface_decimate(NULL, 10, NULL, &coarse));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_surface_decimate(s, 0, NULL, &coarse));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_surface_decimate(s, nv + 1, NULL, &coarse));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_surface_decimate(s, 10, NULL, NULL));
  CHECK(coarse == (wavg_surface *)SENTINEL_PTR);

  wavg_solver_free(solver);
  wavg_surface_free(s);
  free(xyz); free(tris); free(buf); free(ibuf);
  return check_report("test_errors");
}
