/* wavg_spline: clamped, closed and Bezier curves through a solver's anchors, ends on their
 * control points, per-sample answers, and bad arguments that write nothing. */
#include "check.h"

enum { NA = 6, NS = 200 };

int main(void) {
  double *xyz;
  uint32_t *tris;
  size_t nv, nt;
  wavg_surface *s = precomputed_torus(&xyz, &nv, &tris, &nt);

  uint32_t ids[NA] = {0, 120, 250, 380, 500, 640};
  wavg_point anchors[NA];
  for (int a = 0; a < NA; a++) CHECK_OK(wavg_surface_vertex_point(s, ids[a], &anchors[a]));
  wavg_solver *solver = NULL;
  CHECK_OK(wavg_solver_new(s, anchors, NA, &solver));

  wavg_point pts[NS];
  double pos[3 * NS];
  wavg_status st[NS];
  /* Clamped cubic: starts at anchor 0 and ends at anchor NA-1. */
  CHECK_OK(wavg_spline(solver, 3, false, false, NS, pts, pos, st));
  for (int i = 0; i < NS; i++) CHECK(st[i] == WAVG_STATUS_OK && pts[i].face < nt);
  for (int k = 0; k < 3; k++) {
    CHECK(fabs(pos[k] - xyz[3 * ids[0] + k]) < 1e-9);
    CHECK(fabs(pos[3 * (NS - 1) + k] - xyz[3 * ids[NA - 1] + k]) < 1e-9);
  }
  /* Closed quintic and Bezier: every sample answered, positions finite. */
  CHECK_OK(wavg_spline(solver, 5, true, false, NS, pts, NULL, NULL));
  CHECK_OK(wavg_spline(solver, 0, false, true, NS, pts, pos, st));
  for (int i = 0; i < 3 * NS; i++) CHECK(isfinite(pos[i]));

  /* Bad arguments: a status, a message, and untouched outputs. */
  memset(pts, 0xAB, sizeof pts);
  wavg_point before = pts[0];
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_spline(solver, 0, false, false, NS, pts, pos, st));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_spline(solver, 6, true, false, NS, pts, pos, st));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_spline(solver, 3, false, false, 0, pts, pos, st));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_spline(NULL, 3, false, false, NS, pts, pos, st));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_spline(solver, 3, false, false, NS, NULL, pos, st));
  CHECK(memcmp(&pts[0], &before, sizeof before) == 0);

  wavg_solver_free(solver);
  wavg_surface_free(s);
  free(xyz);
  free(tris);
  return check_report("test_spline");
}
