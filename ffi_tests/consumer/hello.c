/* The smallest wavg program: a weighted average of three vertices of a mesh. */
#include <stdio.h>
#include <wavg.h>

int main(int argc, char **argv) {
  wavg_surface *s = NULL;
  wavg_solver *solver = NULL;
  wavg_precompute_options opts = wavg_precompute_options_default();
  opts.landmarks = 300;
  wavg_point anchors[3], p;
  double w[3] = {0.5, 0.3, 0.2}, xyz[3];
  if (argc < 2 || wavg_surface_open(argv[1], &s) || wavg_surface_precompute(s, &opts, NULL, NULL))
    goto fail;
  for (uint32_t i = 0; i < 3; i++)
    if (wavg_surface_vertex_point(s, i * 1000, &anchors[i])) goto fail;
  if (wavg_solver_new(s, anchors, 3, &solver) || wavg_forward(solver, w, 1, &p, xyz, NULL))
    goto fail;
  printf("face %u, position (%g, %g, %g)\n", p.face, xyz[0], xyz[1], xyz[2]);
  wavg_solver_free(solver);
  wavg_surface_free(s);
  return 0;
fail:
  fprintf(stderr, "%s\n", argc < 2 ? "usage: hello MESH" : wavg_last_error());
  wavg_solver_free(solver);
  wavg_surface_free(s);
  return 1;
}
