/* Cancellation from the progress callback: the call returns WAVG_STATUS_CANCELLED and
 * leaves the surface unchanged; a later precomputation without cancelling succeeds. */
#include "check.h"

typedef struct {
  int calls;
  int cancel_after;
} counter;

static bool cancel_soon(wavg_stage stage, double fraction, void *user_data) {
  (void)stage;
  (void)fraction;
  counter *c = (counter *)user_data;
  c->calls++;
  return c->calls <= c->cancel_after;
}

int main(void) {
  double *xyz;
  uint32_t *tris;
  size_t nv, nt;
  wavg_surface *s = torus_surface(60, 24, &xyz, &nv, &tris, &nt);
  double *before = malloc(sizeof(double) * 8 * nv), *after = malloc(sizeof(double) * 8 * nv);
  CHECK_OK(wavg_surface_embedding(s, before, 8 * nv));
  wavg_precompute_options o = wavg_precompute_options_default();
  o.landmarks = 200;
  /* Cancel at the first report, then at a later one (another stage). */
  int cancel_points[] = {0, 3};
  for (int k = 0; k < 2; k++) {
    counter c = {0, cancel_points[k]};
    CHECK_FAILS(WAVG_STATUS_CANCELLED, wavg_surface_precompute(s, &o, cancel_soon, &c));
    CHECK(c.calls == cancel_points[k] + 1 || c.calls > cancel_points[k]);
    size_t n = 7;
    CHECK_OK(wavg_surface_landmarks(s, NULL, 0, &n));
    CHECK(n == 0);
    CHECK_OK(wavg_surface_embedding(s, after, 8 * nv));
    CHECK(memcmp(before, after, sizeof(double) * 8 * nv) == 0);
  }
  counter never = {0, 1 << 30};
  CHECK_OK(wavg_surface_precompute(s, &o, cancel_soon, &never));
  size_t n = 0;
  CHECK_OK(wavg_surface_landmarks(s, NULL, 0, &n));
  CHECK(n == 200);
  wavg_surface_free(s);
  free(xyz); free(tris); free(before); free(after);
  return check_report("test_cancel");
}
