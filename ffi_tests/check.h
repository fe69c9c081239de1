/* Tiny test helpers shared by the C tests: CHECK macros and a torus made in code. */
#ifndef WAVG_FFI_TESTS_CHECK_H
#define WAVG_FFI_TESTS_CHECK_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "wavg.h"

static int check_failures = 0;

#define CHECK(cond)                                                                 \
  do {                                                                              \
    if (!(cond)) {                                                                  \
      fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #cond);      \
      check_failures++;                                                             \
    }                                                                               \
  } while (0)

/* A call that must succeed. */
#define CHECK_OK(call)                                                              \
  do {                                                                              \
    wavg_status s_ = (call);                                                        \
    if (s_ != WAVG_STATUS_OK) {                                                     \
      fprintf(stderr, "%s:%d: %s returned %d: %s\n", __FILE__, __LINE__, #call,     \
              (int)s_, wavg_last_error());                                          \
      exit(1);                                                                      \
    }                                                                               \
  } while (0)

/* A call that must fail with `expected` and leave a non-empty message. */
#define CHECK_FAILS(expected, call)                                                 \
  do {                                                                              \
    wavg_status s_ = (call);                                                        \
    if (s_ != (expected)) {                                                         \
      fprintf(stderr, "%s:%d: %s returned %d, expected %d (%s)\n", __FILE__,        \
              __LINE__, #call, (int)s_, (int)(expected), wavg_last_error());        \
      check_failures++;                                                             \
    } else if (wavg_last_error()[0] == '\0') {                                      \
      fprintf(stderr, "%s:%d: %s failed without a message\n", __FILE__, __LINE__,   \
              #call);                                                               \
      check_failures++;                                                             \
    }                                                                               \
  } while (0)

static inline int check_report(const char *name) {
  if (check_failures) {
    fprintf(stderr, "%s: %d check(s) failed\n", name, check_failures);
    return 1;
  }
  printf("%s: all checks passed\n", name);
  return 0;
}

/* A torus with `nu` x `nv` vertices (radii 1 and r), counter-clockwise from outside.
 * Arrays are malloc'ed; the caller frees them. */
static inline void make_torus(size_t nu, size_t nv, double r, double **xyz, size_t *n_vertices,
                       uint32_t **tris, size_t *n_triangles) {
  const double pi = 3.14159265358979323846;
  *n_vertices = nu * nv;
  *n_triangles = 2 * nu * nv;
  *xyz = (double *)malloc(sizeof(double) * 3 * *n_vertices);
  *tris = (uint32_t *)malloc(sizeof(uint32_t) * 3 * *n_triangles);
  for (size_t i = 0; i < nu; i++) {
    for (size_t j = 0; j < nv; j++) {
      double u = 2 * pi * (double)i / (double)nu, v = 2 * pi * (double)j / (double)nv;
      double *p = *xyz + 3 * (i * nv + j);
      p[0] = (1 + r * cos(v)) * cos(u);
      p[1] = (1 + r * cos(v)) * sin(u);
      p[2] = r * sin(v);
    }
  }
  size_t t = 0;
  for (size_t i = 0; i < nu; i++) {
    for (size_t j = 0; j < nv; j++) {
      uint32_t a = (uint32_t)(i * nv + j), b = (uint32_t)(((i + 1) % nu) * nv + j);
      uint32_t c = (uint32_t)(((i + 1) % nu) * nv + (j + 1) % nv);
      uint32_t d = (uint32_t)(i * nv + (j + 1) % nv);
      uint32_t *q = *tris + 3 * t;
      q[0] = a; q[1] = b; q[2] = c;
      q[3] = a; q[4] = c; q[5] = d;
      t += 2;
    }
  }
}

/* A `nu` x `nv` torus (radii 1 and 0.35) as a surface; its arrays are returned for the
 * caller to free. */
static inline wavg_surface *torus_surface(size_t nu, size_t nv, double **xyz, size_t *n_vertices,
                                          uint32_t **tris, size_t *n_triangles) {
  make_torus(nu, nv, 0.35, xyz, n_vertices, tris, n_triangles);
  wavg_surface *s = NULL;
  CHECK_OK(wavg_surface_from_arrays(*xyz, *n_vertices, *tris, *n_triangles, &s));
  return s;
}

/* A small precomputation for tests: `landmarks` landmarks, no quality check. */
static inline void precompute_quick(wavg_surface *s, size_t landmarks) {
  wavg_precompute_options opts = wavg_precompute_options_default();
  opts.landmarks = landmarks;
  opts.quality_pairs = 0;
  CHECK_OK(wavg_surface_precompute(s, &opts, NULL, NULL));
}

/* The 48 x 16 test torus as a surface with a small precomputed embedding (60 landmarks,
 * no quality check); its arrays are returned for the caller to free. */
static inline wavg_surface *precomputed_torus(double **xyz, size_t *n_vertices, uint32_t **tris,
                                              size_t *n_triangles) {
  wavg_surface *s = torus_surface(48, 16, xyz, n_vertices, tris, n_triangles);
  precompute_quick(s, 60);
  return s;
}

/* `n` anchors at vertices 0, `step`, 2 `step`, ... of `s`. */
static inline void vertex_anchors(wavg_surface *s, size_t n, uint32_t step, wavg_point *anchors) {
  for (size_t a = 0; a < n; a++) CHECK_OK(wavg_surface_vertex_point(s, (uint32_t)a * step, &anchors[a]));
}

/* A solver over the `n` anchors and one over all but the last (a solver of another anchor
 * count, for the argument checks of two-solver entries). */
static inline void solver_and_fewer(wavg_surface *s, const wavg_point *anchors, size_t n,
                                    wavg_solver **solver, wavg_solver **fewer) {
  CHECK_OK(wavg_solver_new(s, anchors, n, solver));
  CHECK_OK(wavg_solver_new(s, anchors, n - 1, fewer));
}

/* The set-up of the tests of the two-surface entries (maps, texture transfer): the
 * precomputed torus with its arrays, MAP_ANCHORS anchors at every 61st vertex, a solver
 * over them and one over all but the last. */
enum { MAP_ANCHORS = 12 };
typedef struct {
  double *xyz;
  uint32_t *tris;
  size_t nv, nt;
  wavg_surface *s;
  wavg_point anchors[MAP_ANCHORS];
  wavg_solver *solver, *fewer;
} map_fixture;

static inline void map_fixture_init(map_fixture *fx) {
  fx->s = precomputed_torus(&fx->xyz, &fx->nv, &fx->tris, &fx->nt);
  vertex_anchors(fx->s, MAP_ANCHORS, 61, fx->anchors);
  solver_and_fewer(fx->s, fx->anchors, MAP_ANCHORS, &fx->solver, &fx->fewer);
}

static inline void map_fixture_free(map_fixture *fx) {
  wavg_solver_free(fx->fewer);
  wavg_solver_free(fx->solver);
  wavg_surface_free(fx->s);
  free(fx->xyz);
  free(fx->tris);
}

/* The 3-D position of a surface point from the mesh arrays. */
static inline void point_position(const double *xyz, const uint32_t *tris, wavg_point p,
                           double out[3]) {
  for (int k = 0; k < 3; k++) {
    out[k] = 0;
    for (int c = 0; c < 3; c++) out[k] += p.bary[c] * xyz[3 * tris[3 * p.face + c] + k];
  }
}

static inline double dist3(const double a[3], const double b[3]) {
  return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
              (a[2] - b[2]) * (a[2] - b[2]));
}

/* Whether two points are equal (field by field: the struct has padding). */
static inline int same_point(wavg_point a, wavg_point b) {
  return a.face == b.face && memcmp(a.bary, b.bary, sizeof a.bary) == 0;
}

/* Deterministic pseudo-random numbers in [0, 1). */
static inline double rnd(unsigned long long *state) {
  *state = *state * 6364136223846793005ULL + 1442695040888963407ULL;
  return (double)(*state >> 11) / 9007199254740992.0;
}

/* A random surface point with all barycentric coordinates positive. */
static inline wavg_point random_point(unsigned long long *state, size_t n_faces) {
  wavg_point p;
  p.face = (uint32_t)(rnd(state) * (double)n_faces);
  double a = 0.05 + rnd(state), b = 0.05 + rnd(state), c = 0.05 + rnd(state);
  double s = a + b + c;
  p.bary[0] = a / s;
  p.bary[1] = b / s;
  p.bary[2] = 1.0 - a / s - b / s;
  return p;
}

#endif
