/* wavg_remesher: a quad cage on a torus refined on the surface (closed-form counts, every
 * vertex on the mesh), a dragged base vertex recomputed warm, and bad arguments that
 * leave outputs and handles untouched. */
#include "check.h"

enum { NU = 8, NV = 4, NB = NU * NV };

int main(void) {
  double *xyz, *bxyz;
  uint32_t *tris, *btris;
  size_t nv, nt, nbv, nbt;
  make_torus(48, 16, 0.35, &xyz, &nv, &tris, &nt);
  /* The base: an 8 x 4 quad grid on the same torus (pairs of triangles joined). */
  make_torus(NU, NV, 0.35, &bxyz, &nbv, &btris, &nbt);
  uint32_t sizes[NB], quads[4 * NB];
  for (size_t q = 0; q < NB; q++) {
    const uint32_t *t = btris + 6 * q;
    sizes[q] = 4;
    quads[4 * q] = t[0];
    quads[4 * q + 1] = t[1];
    quads[4 * q + 2] = t[2];
    quads[4 * q + 3] = t[5];
  }
  wavg_surface *s = NULL;
  CHECK_OK(wavg_surface_from_arrays(xyz, nv, tris, nt, &s));
  precompute_quick(s, 60);

  wavg_remesher *r = NULL;
  CHECK_OK(wavg_remesher_new(s, bxyz, NB, sizes, NB, quads, 0.0, &r));
  /* Nothing to read before a run. */
  CHECK(wavg_remesher_count(r, 0) == 0);
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_remesher_get(r, NULL, NULL, NULL, NULL));

  /* Two levels: V = 32 + 64 + 32 = 128, then 128 + 256 + 128 = 512; F = 32 * 16. */
  CHECK_OK(wavg_remesher_run(r, 2, 3));
  size_t v = wavg_remesher_count(r, 0), f = wavg_remesher_count(r, 1);
  size_t ni = wavg_remesher_count(r, 2);
  CHECK(v == 512 && f == 512 && ni == 4 * 512);
  wavg_point *pts = (wavg_point *)malloc(sizeof(wavg_point) * v);
  double *pos = (double *)malloc(sizeof(double) * 3 * v);
  uint32_t *fs = (uint32_t *)malloc(sizeof(uint32_t) * f);
  uint32_t *fi = (uint32_t *)malloc(sizeof(uint32_t) * ni);
  CHECK_OK(wavg_remesher_get(r, pts, pos, fs, fi));
  for (size_t i = 0; i < v; i++) {
    double p[3];
    CHECK(pts[i].face < nt);
    point_position(xyz, tris, pts[i], p);
    CHECK(dist3(p, pos + 3 * i) < 1e-12);
  }
  for (size_t i = 0; i < f; i++) CHECK(fs[i] == 4);
  for (size_t i = 0; i < ni; i++) CHECK(fi[i] < v);

  /* Drag base vertex 0 (mesh vertex 0) onto mesh vertex 1, recompute warm. */
  wavg_point b0, target;
  CHECK_OK(wavg_remesher_base_point(r, 0, &b0));
  CHECK_OK(wavg_surface_vertex_point(s, 1, &target));
  CHECK_OK(wavg_remesher_move_vertex(r, 0, target));
  CHECK_OK(wavg_remesher_run(r, 2, 3));
  CHECK(wavg_remesher_count(r, 0) == 512);
  /* Without smoothing (which moves base vertices too) the output starts with the base. */
  CHECK_OK(wavg_remesher_run(r, 2, 0));
  CHECK_OK(wavg_remesher_get(r, NULL, pos, NULL, NULL));
  CHECK(dist3(pos, xyz + 3) < 1e-12);

  /* Bad arguments: a status, a message, nothing changed. */
  wavg_remesher *none = NULL;
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_remesher_run(r, 9, 0));
  /* Too many smoothing steps: refused, not allocated for. */
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_remesher_run(r, 1, UINT32_MAX));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_remesher_run(NULL, 1, 0));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_remesher_move_vertex(r, NB, target));
  wavg_point bad = target;
  bad.bary[0] = 2.0;
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_remesher_move_vertex(r, 0, bad));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_remesher_base_point(r, NB, &b0));
  CHECK(wavg_remesher_count(r, 0) == 512 && wavg_remesher_count(NULL, 0) == 0);
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT,
              wavg_remesher_new(NULL, bxyz, NB, sizes, NB, quads, 0.0, &none));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT,
              wavg_remesher_new(s, bxyz, 0, sizes, NB, quads, 0.0, &none));
  quads[5] = NB; /* out of range */
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT,
              wavg_remesher_new(s, bxyz, NB, sizes, NB, quads, 0.0, &none));
  quads[5] = quads[4];
  CHECK_FAILS(WAVG_STATUS_INVALID_MESH, /* face 1 repeats a corner */
              wavg_remesher_new(s, bxyz, NB, sizes, NB, quads, 0.0, &none));
  quads[5] = btris[6 + 1];
  bxyz[0] *= 3.0; /* far from the surface */
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT,
              wavg_remesher_new(s, bxyz, NB, sizes, NB, quads, 0.0, &none));
  bxyz[0] /= 3.0;
  sizes[0] = 2;
  CHECK_FAILS(WAVG_STATUS_INVALID_MESH,
              wavg_remesher_new(s, bxyz, NB, sizes, NB, quads, 0.0, &none));
  CHECK(none == NULL);

  wavg_remesher_free(r);
  wavg_remesher_free(NULL);
  wavg_surface_free(s);
  free(pts);
  free(pos);
  free(fs);
  free(fi);
  free(xyz);
  free(tris);
  free(bxyz);
  free(btris);
  return check_report("test_remesh");
}
