"""Semiregular remeshing of a coarse quad cage on a torus; moves one cage vertex."""
import sys
import numpy as np
import wavg
from _mesh import torus

S = wavg.Surface(*torus())
S.precompute(landmarks=200, progress=False)
# The cage: every 8th ring and every 4th vertex of it, as quads.
n, m = 6, 4
ids = np.array([[(i * 8) * 16 + j * 4 for j in range(m)] for i in range(n)])
quads = [[ids[i, j], ids[(i + 1) % n, j], ids[(i + 1) % n, (j + 1) % m], ids[i, (j + 1) % m]]
         for i in range(n) for j in range(m)]
cage = np.arange(n * m).reshape(n, m)
faces = [[cage[i, j], cage[(i + 1) % n, j], cage[(i + 1) % n, (j + 1) % m], cage[i, (j + 1) % m]]
         for i in range(n) for j in range(m)]
r = wavg.Remesher(S, S.vertices[ids.ravel()], faces, levels=2, smooth=3)
V, Fq = r.run()
print(f"{len(V)} vertices, {len(Fq)} faces, largest distance off the surface {r.report['max_offsurface']:.1e}")
r.move_vertex(0, S.vertices[ids[0, 0]] + [0.0, 0.05, 0.0])
V2, _ = r.run()
print(f"after the move: {np.abs(V2 - V).max():.3f} largest vertex change")
