"""Maps a torus onto a stretched copy through 24 paired anchors; prints the report."""
import sys
import wavg
from _mesh import torus

V, F = torus()
src, dst = wavg.Surface(V, F), wavg.Surface(V * [1.5, 1.0, 0.8], F)
for S in (src, dst):
    S.precompute(landmarks=200, progress=False)
anchors = src.spread_anchors(24)  # the same vertex ids correspond on both
m = wavg.correspond(src, dst, anchors, anchors)
print(f"valid {m.report['valid_fraction']:.3f}, stretch {m.report['stretch']}")
err = abs(m.xyz[m.valid] - dst.vertices[m.valid]).max()
print(f"largest error against the known map: {err:.2e}")
