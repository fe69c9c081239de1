/* wavg_surface_open_with_embedding: a mesh file and its .wavg in one call give the same
 * surface as opening, then loading the embedding; NULL embedding is wavg_surface_open;
 * failures leave *out alone. Also checks a saved file with the version-2 envelope check
 * that crates/wavg-embed/FORMAT.md gives C readers. */
#include <stdint.h>

#include "check.h"

static uint64_t rotl(uint64_t x, int r) { return (x << r) | (x >> (64 - r)); }

/* The format's word hash, transcribed from FORMAT.md. */
static uint64_t word_hash(const uint8_t *p, size_t n_words) {
  const uint64_t P1 = 0x9e3779b185ebca87ull, P2 = 0xc2b2ae3d27d4eb4full,
                 P3 = 0x165667b19e3779f9ull;
  uint64_t h = 0x2545f4914f6cdd1dull, w;
  for (size_t i = 0; i < n_words; i++) {
    memcpy(&w, p + 8 * i, 8);
    h = rotl(h ^ (w * P2), 31) * P1;
  }
  h ^= h >> 33;
  h *= P2;
  h ^= h >> 29;
  h *= P3;
  h ^= h >> 32;
  return h;
}

/* Whether the file at `path` is a version-2 .wavg whose checksum matches. */
static int file_ok(const char *path) {
  FILE *f = fopen(path, "rb");
  if (!f) return 0;
  fseek(f, 0, SEEK_END);
  long len = ftell(f);
  fseek(f, 0, SEEK_SET);
  uint8_t *buf = malloc((size_t)len);
  size_t got = fread(buf, 1, (size_t)len, f);
  fclose(f);
  uint64_t sum;
  uint32_t version;
  int ok = got == (size_t)len && len >= 136 && len % 8 == 0 && memcmp(buf, "WAVGEMB\0", 8) == 0;
  if (ok) {
    memcpy(&version, buf + 8, 4);
    memcpy(&sum, buf + len - 8, 8);
    ok = version == 2 && word_hash(buf, (size_t)len / 8 - 1) == sum;
    buf[len / 2] ^= 1; /* one flipped bit in the body is seen */
    ok = ok && word_hash(buf, (size_t)len / 8 - 1) != sum;
  }
  free(buf);
  return ok;
}

/* Writes the mesh as an OFF file (%.17g gives back every double exactly). */
static void write_off(const char *path, const double *xyz, size_t nv, const uint32_t *tris,
                      size_t nt) {
  FILE *f = fopen(path, "w");
  CHECK(f != NULL);
  if (!f) exit(1);
  fprintf(f, "OFF\n%zu %zu 0\n", nv, nt);
  for (size_t i = 0; i < nv; i++)
    fprintf(f, "%.17g %.17g %.17g\n", xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
  for (size_t t = 0; t < nt; t++)
    fprintf(f, "3 %u %u %u\n", tris[3 * t], tris[3 * t + 1], tris[3 * t + 2]);
  fclose(f);
}

int main(void) {
  double *xyz;
  uint32_t *tris;
  size_t nv, nt;
  wavg_surface *s = torus_surface(40, 14, &xyz, &nv, &tris, &nt);
  wavg_precompute_options opts = wavg_precompute_options_default();
  opts.landmarks = 40;
  opts.quality_pairs = 0;
  CHECK_OK(wavg_surface_precompute(s, &opts, NULL, NULL));
  const char *mesh = "test_open_embedding.off", *emb_path = "test_open_embedding.wavg";
  write_off(mesh, xyz, nv, tris, nt);
  CHECK_OK(wavg_surface_save_embedding(s, emb_path));
  CHECK(file_ok(emb_path));

  /* One call: the same embedding and landmarks as the surface that computed them. */
  wavg_surface *opened = NULL;
  CHECK_OK(wavg_surface_open_with_embedding(mesh, emb_path, &opened));
  CHECK(wavg_surface_vertex_count(opened) == nv && wavg_surface_face_count(opened) == nt);
  double *a = malloc(sizeof(double) * 8 * nv), *b = malloc(sizeof(double) * 8 * nv);
  CHECK_OK(wavg_surface_embedding(s, a, 8 * nv));
  CHECK_OK(wavg_surface_embedding(opened, b, 8 * nv));
  CHECK(memcmp(a, b, sizeof(double) * 8 * nv) == 0);
  size_t k = 0;
  CHECK_OK(wavg_surface_landmarks(opened, NULL, 0, &k));
  CHECK(k == 40);

  /* NULL embedding: the surface wavg_surface_open gives (embedding = positions). */
  wavg_surface *plain = NULL;
  CHECK_OK(wavg_surface_open_with_embedding(mesh, NULL, &plain));
  CHECK_OK(wavg_surface_embedding(plain, b, 8 * nv));
  CHECK(b[8 * 7] == xyz[3 * 7] && b[8 * 7 + 2] == xyz[3 * 7 + 2] && b[8 * 7 + 3] == 0.0);
  CHECK_OK(wavg_surface_landmarks(plain, NULL, 0, &k));
  CHECK(k == 0);

  /* Failures leave *out unchanged. */
  wavg_surface *untouched = (wavg_surface *)&k;
  CHECK_FAILS(WAVG_STATUS_IO,
              wavg_surface_open_with_embedding(mesh, "no/such/file.wavg", &untouched));
  CHECK_FAILS(WAVG_STATUS_IO,
              wavg_surface_open_with_embedding("no/such/mesh.off", emb_path, &untouched));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT,
              wavg_surface_open_with_embedding(NULL, emb_path, &untouched));
  CHECK_FAILS(WAVG_STATUS_INVALID_ARGUMENT, wavg_surface_open_with_embedding(mesh, NULL, NULL));
  /* An embedding made for another mesh (another torus) is refused. */
  double *xyz2;
  uint32_t *tris2;
  size_t nv2, nt2;
  wavg_surface *other = torus_surface(40, 14, &xyz2, &nv2, &tris2, &nt2);
  xyz2[0] += 1e-9;
  const char *other_mesh = "test_open_embedding_other.off";
  write_off(other_mesh, xyz2, nv2, tris2, nt2);
  CHECK_FAILS(WAVG_STATUS_IO,
              wavg_surface_open_with_embedding(other_mesh, emb_path, &untouched));
  CHECK(untouched == (wavg_surface *)&k);

  remove(mesh);
  remove(other_mesh);
  remove(emb_path);
  free(a);
  free(b);
  free(xyz);
  free(tris);
  free(xyz2);
  free(tris2);
  wavg_surface_free(s);
  wavg_surface_free(opened);
  wavg_surface_free(plain);
  wavg_surface_free(other);
  return check_report("test_open_embedding");
}
