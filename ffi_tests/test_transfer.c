/* wavg_transfer_texture: a texture carried from a surface onto itself comes back (each
 * texel finds its own point, hence its own colour), and bad arguments write nothing. */
#include "check.h"

enum { NA = 12, W = 256 };

int main(void) {
  double *xyz;
  uint32_t *tris;
  size_t nv, nt;
  wavg_surface *s = precomputed_torus(&xyz, &nv, &tris, &nt);
  wavg_point anchors[NA];
  vertex_anchors(s, NA, 61, anchors);
  wavg_solver *solver = NULL, *fewer = NULL;
  solver_and_fewer(s, anchors, NA, &solver, &fewer);

  /* An atlas of separate triangles: face f in cell f of a k x k grid. */
  size_t k = 1;
  while (k * k < nt) k++;
  double *uv = malloc(6 * nt * sizeof *uv);
  uint32_t *uvf = malloc(3 * nt * sizeof *uvf);
  for (size_t f = 0; f < nt; f++) {
    double x0 = (double)(f % k) / (double)k, y0 = (double)(f / k) / (double)k, c = 1.0 / (double)k;
    double corner[6] = {x0 + 0.1 * c, y0 + 0.1 * c, x0 + 0.9 * c, y0 + 0.1 * c, x0 + 0.1 * c, y0 + 0.9 * c};
    for (int i = 0; i < 6; i++) uv[6 * f + (size_t)i] = corner[i];
    for (int i = 0; i < 3; i++) uvf[3 * f + (size_t)i] = (uint32_t)(3 * f + (size_t)i);
  }
  /* A smooth gradient image. */
  uint8_t *src = malloc(4 * W * W), *out = malloc(4 * W * W);
  for (int y = 0; y < W; y++)
    for (int x = 0; x < W; x++) {
      uint8_t *p = src + 4 * (y * W + x);
      p[0] = (uint8_t)x, p[1] = (uint8_t)y, p[2] = 128, p[3] = 255;
    }
  size_t valid = 0, covered = 0;
  CHECK_OK(wavg_transfer_texture(solver, uv, 3 * nt, uvf, src, W, W, solver, uv, 3 * nt, uvf, W, W, 1,
                                 out, &valid, &covered));
  CHECK(covered > 10000 && valid >= covered * 99 / 100);
  size_t opaque = 0, close = 0;
  for (int i = 0; i < W * W; i++) {
    if (out[4 * i + 3] == 0) continue;
    opaque++;
    int d = abs(out[4 * i] - src[4 * i]) + abs(out[4 * i + 1] - src[4 * i + 1]);
    if (d <= 3) close++;
  }
  CHECK(opaque >= covered);
  CHECK(close >= covered * 9 / 10);

  /* Bad arguments: a status, a message, and an untouched output. */
  memset(out, 0xAB, 4 * W * W);
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT,
              wavg_transfer_texture(solver, uv, 3 * nt, uvf, src, W, W, fewer, uv, 3 * nt, uvf, W, W, 4,
                                    out, NULL, NULL));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT,
              wavg_transfer_texture(solver, uv, 3 * nt, uvf, src, W, W, solver, uv, 3 * nt, uvf, W, W, 0,
                                    out, NULL, NULL));
  uvf[5] = (uint32_t)(3 * nt); /* out of range */
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT,
              wavg_transfer_texture(solver, uv, 3 * nt, uvf, src, W, W, solver, uv, 3 * nt, uvf, W, W, 4,
                                    out, NULL, NULL));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT,
              wavg_transfer_texture(NULL, uv, 3 * nt, uvf, src, W, W, solver, uv, 3 * nt, uvf, W, W, 4,
                                    out, NULL, NULL));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT,
              wavg_transfer_texture(solver, uv, 3 * nt, uvf, src, W, W, solver, uv, 3 * nt, uvf, W, W, 4,
                                    NULL, NULL, NULL));
  CHECK(out[0] == 0xAB && out[4 * W * W - 1] == 0xAB);

  wavg_solver_free(fewer);
  wavg_solver_free(solver);
  wavg_surface_free(s);
  free(uv);
  free(uvf);
  free(src);
  free(out);
  free(xyz);
  free(tris);
  return check_report("test_transfer");
}
