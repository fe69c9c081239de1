/* A glTF file through the C ABI's open call: a tetrahedron whose first corner is written
 * twice (as exporters split a vertex at a UV seam) opens welded, `FILE#NAME` picks the
 * mesh, and a truncated file or an unknown name is WAVG_STATUS_IO. */
#include <stdio.h>
#include <string.h>

#include "check.h"

static void put_u32(FILE *f, uint32_t x) {
  unsigned char b[4] = {x & 255, (x >> 8) & 255, (x >> 16) & 255, (x >> 24) & 255};
  fwrite(b, 1, 4, f);
}

/* Writes the GLB to `path`, cut after `keep` bytes (all of it when larger). */
static void write_glb(const char *path, size_t keep) {
  static const float pos[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
  static const uint32_t idx[12] = {0, 2, 1, 4, 1, 3, 1, 2, 3, 2, 0, 3};
  char json[1024];
  int n = snprintf(json, sizeof json,
                   "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
                   "\"nodes\":[{\"mesh\":0}],\"meshes\":[{\"name\":\"Tet\",\"primitives\":[{"
                   "\"attributes\":{\"POSITION\":0},\"indices\":1}]}],\"accessors\":["
                   "{\"bufferView\":0,\"componentType\":5126,\"count\":5,\"type\":\"VEC3\"},"
                   "{\"bufferView\":1,\"componentType\":5125,\"count\":12,\"type\":\"SCALAR\"}],"
                   "\"bufferViews\":[{\"buffer\":0,\"byteLength\":60},"
                   "{\"buffer\":0,\"byteOffset\":60,\"byteLength\":48}],"
                   "\"buffers\":[{\"byteLength\":108}]}");
  while (n % 4 != 0) json[n++] = ' ';
  unsigned char buf[2048];
  FILE *mem = fmemopen(buf, sizeof buf, "wb");
  CHECK(mem != NULL);
  fwrite("glTF", 1, 4, mem);
  put_u32(mem, 2);
  put_u32(mem, (uint32_t)(12 + 8 + n + 8 + 108));
  put_u32(mem, (uint32_t)n);
  put_u32(mem, 0x4E4F534Au);
  fwrite(json, 1, (size_t)n, mem);
  put_u32(mem, 108);
  put_u32(mem, 0x004E4942u);
  for (int i = 0; i < 15; i++) { /* little-endian hosts only, as the ABI is tested */
    fwrite(&pos[i], 4, 1, mem);
  }
  for (int i = 0; i < 12; i++) put_u32(mem, idx[i]);
  size_t total = (size_t)ftell(mem);
  fclose(mem);
  FILE *f = fopen(path, "wb");
  CHECK(f != NULL);
  fwrite(buf, 1, keep < total ? keep : total, f);
  fclose(f);
}

int main(void) {
  const char *path = "test_gltf_tet.glb";
  wavg_surface *s = NULL;
  write_glb(path, (size_t)-1);
  CHECK_OK(wavg_surface_open(path, &s));
  CHECK(wavg_surface_vertex_count(s) == 4); /* five written, one weld */
  CHECK(wavg_surface_face_count(s) == 4);
  wavg_surface_free(s);
  s = NULL;
  CHECK_OK(wavg_surface_open("test_gltf_tet.glb#Tet", &s));
  CHECK(wavg_surface_vertex_count(s) == 4);
  wavg_surface_free(s);
  s = NULL;
  CHECK_FAILS(WAVG_STATUS_IO, wavg_surface_open("test_gltf_tet.glb#Body", &s));
  write_glb(path, 100);
  CHECK_FAILS(WAVG_STATUS_IO, wavg_surface_open(path, &s));
  CHECK(s == NULL);
  remove(path);
  printf("gltf: ok\n");
  return 0;
}
