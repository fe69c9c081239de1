"""A decal: texture coordinates from three anchors, shown as a scalar colouring."""
import sys
import numpy as np
import wavg
from _mesh import torus

out = sys.argv[1] if len(sys.argv) > 1 else "."
S = wavg.Surface(*torus())
S.precompute(landmarks=200, progress=False)
a = S.spread_anchors(3, seed=1)
uv, valid = wavg.decal(S, a, [[0, 0], [1, 0], [0, 1]])
print(f"{valid.mean():.0%} of the vertices have decal coordinates")
u = np.where(valid, uv[:, 0], 0.0)
wavg.save_png(f"{out}/decal.png", wavg.render(S, scalar=u, points=S.vertices[a]))
