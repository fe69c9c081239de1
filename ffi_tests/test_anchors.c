/* wavg_surface_spread_anchors: K distinct vertices, the same for the same seed, each the
 * vertex farthest in the embedding from those before it (farthest-point sampling, as
 * `wavg anchors` spreads them), before and after a precomputation; bad arguments refused
 * with the output untouched. */
#include "check.h"

#define K 24

/* Squared distance between vertices a and b of an embedding (8 doubles per vertex). */
static double dist2(const double *emb, uint32_t a, uint32_t b) {
  double s = 0;
  for (int k = 0; k < 8; k++) {
    double d = emb[8 * a + k] - emb[8 * b + k];
    s += d * d;
  }
  return s;
}

/* Checks `a` (K vertices of a surface with `nv` vertices): distinct, in range, and each
 * after the first at the largest distance from those before it (within rounding). */
static void check_spread(const wavg_surface *s, const uint32_t *a, size_t nv) {
  double *emb = malloc(sizeof(double) * 8 * nv);
  double *near = malloc(sizeof(double) * nv);
  CHECK_OK(wavg_surface_embedding(s, emb, 8 * nv));
  for (size_t v = 0; v < nv; v++) near[v] = INFINITY;
  for (int i = 0; i < K; i++) {
    CHECK(a[i] < nv);
    for (int j = 0; j < i; j++) CHECK(a[i] != a[j]);
    if (i > 0) {
      double best = 0;
      for (size_t v = 0; v < nv; v++)
        if (near[v] > best) best = near[v];
      CHECK(near[a[i]] >= best * (1 - 1e-12));
    }
    for (size_t v = 0; v < nv; v++) {
      double d = dist2(emb, a[i], (uint32_t)v);
      if (d < near[v]) near[v] = d;
    }
  }
  free(emb);
  free(near);
}

int main(void) {
  double *xyz;
  uint32_t *tris;
  size_t nv, nt;
  wavg_surface *s = torus_surface(48, 16, &xyz, &nv, &tris, &nt);

  /* Before a precomputation: spread in the vertex positions. */
  uint32_t a[K], b[K], c[K];
  CHECK_OK(wavg_surface_spread_anchors(s, K, 7, a));
  check_spread(s, a, nv);
  CHECK_OK(wavg_surface_spread_anchors(s, K, 7, b));
  CHECK(memcmp(a, b, sizeof a) == 0);
  /* A prefix of a longer spread with the same seed. */
  CHECK_OK(wavg_surface_spread_anchors(s, 5, 7, c));
  CHECK(memcmp(a, c, 5 * sizeof(uint32_t)) == 0);
  /* Another seed, another first vertex. */
  CHECK_OK(wavg_surface_spread_anchors(s, K, 8, b));
  CHECK(b[0] != a[0]);
  check_spread(s, b, nv);
  /* k = 0 writes nothing, even to NULL. */
  CHECK_OK(wavg_surface_spread_anchors(s, 0, 7, NULL));

  /* Refused, with `out_vertices` untouched. */
  uint32_t untouched[K];
  memset(untouched, 0xAB, sizeof untouched);
  memcpy(c, untouched, sizeof c);
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_surface_spread_anchors(s, nv + 1, 7, c));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_surface_spread_anchors(NULL, K, 7, c));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_surface_spread_anchors(s, K, 7, NULL));
  CHECK(memcmp(c, untouched, sizeof c) == 0);
  wavg_surface_free(s);
  free(xyz);
  free(tris);

  /* After a precomputation: spread in the embedding. */
  s = precomputed_torus(&xyz, &nv, &tris, &nt);
  CHECK_OK(wavg_surface_spread_anchors(s, K, 7, b));
  check_spread(s, b, nv);
  CHECK(b[0] == a[0]); /* the first vertex is the seed's alone */
  CHECK_OK(wavg_surface_spread_anchors(s, K, 7, c));
  CHECK(memcmp(b, c, sizeof b) == 0);
  wavg_surface_free(s);
  free(xyz);
  free(tris);
  return check_report("test_anchors");
}
