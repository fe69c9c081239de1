"""A closed B-spline on a surface through five control vertices, drawn to spline.png."""
import sys
import wavg
from _mesh import torus

out = sys.argv[1] if len(sys.argv) > 1 else "."
S = wavg.Surface(*torus())
S.precompute(landmarks=200)
control = S.spread_anchors(5, seed=3)
curve = wavg.spline(S, control, samples=300, degree=3, closed=True)
print(f"{curve.ok.sum()} of {len(curve.ok)} samples on the surface")
wavg.save_png(f"{out}/spline.png", wavg.render(S, curves=[curve], points=S.vertices[control]))
