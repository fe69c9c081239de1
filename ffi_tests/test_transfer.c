/* wavg_transfer_texture: a texture carried from a surface onto itself comes back (each
 * texel finds its own point, hence its own colour), and bad arguments write nothing. */
#include "check.h"

enum { NA = MAP_ANCHORS, W = 256 };

/* The one atlas of the test: `n` (u, v) pairs `uv` with the face triples `uvf`. */
typedef struct {
  const double *uv;
  size_t n;
  const uint32_t *uvf;
} atlas;

/* wavg_transfer_texture of the W x W image `src` from `source` to `target`, both on the
 * atlas `a`, into a W x W `out` with `stride`. */
static wavg_status transfer(const wavg_solver *source, const wavg_solver *target, atlas a,
                            const uint8_t *src, uint32_t stride, uint8_t *out, size_t *valid,
                            size_t *covered) {
  return wavg_transfer_texture(source, a.uv, a.n, a.uvf, src, W, W, target, a.uv, a.n, a.uvf, W, W,
                               stride, out, valid, covered);
}

int main(void) {
  map_fixture fx;
  map_fixture_init(&fx);
  wavg_solver *solver = fx.solver, *fewer = fx.fewer;

  /* An atlas of separate triangles: face f in cell f of a k x k grid. */
  size_t k = 1;
  while (k * k < fx.nt) k++;
  double *uv = malloc(6 * fx.nt * sizeof *uv);
  uint32_t *uvf = malloc(3 * fx.nt * sizeof *uvf);
  for (size_t f = 0; f < fx.nt; f++) {
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
  atlas a = {uv, 3 * fx.nt, uvf};
  size_t valid = 0, covered = 0;
  CHECK_OK(transfer(solver, solver, a, src, 1, out, &valid, &covered));
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
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, transfer(solver, fewer, a, src, 4, out, NULL, NULL));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, transfer(solver, solver, a, src, 0, out, NULL, NULL));
  uvf[5] = (uint32_t)(3 * fx.nt); /* out of range */
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, transfer(solver, solver, a, src, 4, out, NULL, NULL));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, transfer(NULL, solver, a, src, 4, out, NULL, NULL));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, transfer(solver, solver, a, src, 4, NULL, NULL, NULL));
  CHECK(out[0] == 0xAB && out[4 * W * W - 1] == 0xAB);

  free(uv);
  free(uvf);
  free(src);
  free(out);
  map_fixture_free(&fx);
  return check_report("test_transfer");
}
