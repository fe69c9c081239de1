/* wavg_correspond, wavg_correspond_vertices and wavg_decal_uv: a surface mapped onto
 * itself is the identity, an anchor's decal coordinates are its own, per-point statuses,
 * and bad arguments that write nothing. */
#include "check.h"

enum { NA = MAP_ANCHORS, NP = 64 };

int main(void) {
  map_fixture fx;
  map_fixture_init(&fx);
  wavg_solver *solver = fx.solver, *fewer = fx.fewer;

  /* Points: vertices spread over the torus. */
  wavg_point pts[NP], out[NP];
  double pos[3 * NP];
  wavg_status st[NP];
  for (int i = 0; i < NP; i++) CHECK_OK(wavg_surface_vertex_point(fx.s, (uint32_t)(i * 11), &pts[i]));
  wavg_status r = wavg_correspond(solver, solver, pts, NP, true, -0.1, out, pos, st);
  CHECK(r == WAVG_STATUS_OK || r == WAVG_STATUS_NO_SOLUTION);
  int ok = 0;
  for (int i = 0; i < NP; i++) {
    if (st[i] == WAVG_STATUS_OK) ok++;
    if (out[i].face != UINT32_MAX)
      for (int k = 0; k < 3; k++) CHECK(fabs(pos[3 * i + k] - fx.xyz[3 * (i * 11) + k]) < 1e-6);
  }
  CHECK(ok > NP / 2);

  /* Every vertex, local test: nearly all kept, all onto themselves. */
  wavg_point *vout = malloc(fx.nv * sizeof *vout);
  double *vpos = malloc(3 * fx.nv * sizeof *vpos);
  wavg_status *vst = malloc(fx.nv * sizeof *vst);
  r = wavg_correspond_vertices(solver, solver, true, true, -0.1, vout, vpos, vst);
  CHECK(r == WAVG_STATUS_OK || r == WAVG_STATUS_NO_SOLUTION);
  size_t kept = 0;
  for (size_t v = 0; v < fx.nv; v++)
    if (vst[v] == WAVG_STATUS_OK) {
      kept++;
      for (int k = 0; k < 3; k++) CHECK(fabs(vpos[3 * v + k] - fx.xyz[3 * v + k]) < 1e-6);
    }
  CHECK(kept > fx.nv * 95 / 100);

  /* Decal: anchor a carries (a, 2a); the anchors' own points get their own coordinates. */
  double uv[2 * NA], out_uv[2 * NA];
  for (int a = 0; a < NA; a++) {
    uv[2 * a] = a;
    uv[2 * a + 1] = 2 * a;
  }
  wavg_status dst[NA];
  r = wavg_decal_uv(solver, uv, fx.anchors, NA, -0.1, out_uv, dst);
  CHECK(r == WAVG_STATUS_OK || r == WAVG_STATUS_NO_SOLUTION);
  for (int a = 0; a < NA; a++) {
    CHECK(fabs(out_uv[2 * a] - a) < 1e-6 && fabs(out_uv[2 * a + 1] - 2 * a) < 1e-6);
  }

  /* Bad arguments: a status, a message, and untouched outputs. */
  memset(out, 0xAB, sizeof out);
  wavg_point before = out[0];
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_correspond(solver, fewer, pts, NP, true, -0.1, out, pos, st));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_correspond(solver, solver, pts, 0, true, -0.1, out, pos, st));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_correspond(NULL, solver, pts, NP, true, -0.1, out, pos, st));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_correspond(solver, solver, pts, NP, true, NAN, out, pos, st));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_correspond(solver, solver, pts, NP, true, 5.0, out, pos, st));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_correspond(solver, solver, NULL, NP, true, -0.1, out, pos, st));
  CHECK(memcmp(&out[0], &before, sizeof before) == 0);
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_correspond_vertices(solver, fewer, true, true, -0.1, vout, vpos, vst));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_correspond_vertices(solver, solver, true, true, -0.1, NULL, vpos, vst));
  double saved = out_uv[0];
  uv[3] = NAN;
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_decal_uv(solver, uv, fx.anchors, NA, -0.1, out_uv, dst));
  uv[3] = 2;
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_decal_uv(solver, uv, fx.anchors, 0, -0.1, out_uv, dst));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_decal_uv(solver, NULL, fx.anchors, NA, -0.1, out_uv, dst));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_decal_uv(solver, uv, fx.anchors, NA, INFINITY, out_uv, dst));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_decal_uv(solver, uv, fx.anchors, NA, 0.5, out_uv, dst));
  CHECK(out_uv[0] == saved);

  free(vout);
  free(vpos);
  free(vst);
  map_fixture_free(&fx);
  return check_report("test_maps");
}
