"""Transfers a checkerboard texture from a torus onto a scaled copy with its own UVs."""
import sys
import numpy as np
import wavg
from _mesh import torus

out = sys.argv[1] if len(sys.argv) > 1 else "."
V, F = torus()
ang = np.stack([np.arctan2(V[:, 1], V[:, 0]), np.arctan2(V[:, 2], np.hypot(V[:, 0], V[:, 1]) - 1)], -1)
uv = np.clip(ang[F] / (2 * np.pi) + 0.5, 0, 1)  # per-corner (u, v)
src, dst = wavg.Surface(V, F, uv=uv), wavg.Surface(V * 2.0, F, uv=uv)
for S in (src, dst):
    S.precompute(landmarks=200, progress=False)
checker = ((np.indices((128, 128)) // 16).sum(0) % 2 * 255).astype(np.uint8)
tex = np.dstack([checker, checker, checker, np.full_like(checker, 255)])
a = src.spread_anchors(24)
out_tex = wavg.transfer_texture(src, tex, dst, a, a, size=(128, 128))
print(f"{(out_tex[..., 3] > 0).mean():.0%} of the texels transferred")
wavg.save_png(f"{out}/transferred.png", out_tex)
