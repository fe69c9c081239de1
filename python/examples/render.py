"""Precomputes, solves one batch of forward problems and renders the answers to a PNG."""
import sys
import numpy as np
import wavg
from _mesh import torus

out = sys.argv[1] if len(sys.argv) > 1 else "."
S = wavg.Surface(*torus())
S.precompute(landmarks=200, progress=False)
solver = wavg.Solver(S, S.spread_anchors(8))
W = np.random.default_rng(0).dirichlet(np.ones(8), size=200)
pts = solver.forward(W)
img = wavg.render(S, size=(640, 480), view=(35, 30), points=pts, scalar=S.vertices[:, 2])
wavg.save_png(f"{out}/render.png", img)
print(f"{pts.ok.sum()} points drawn to {out}/render.png")
