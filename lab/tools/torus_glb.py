"""Writes a GLB of a torus cut along both UV seams, as glTF exporters write a closed model:
(NU + 1) x (NV + 1) vertices, NU x NV once welded, 2 NU NV triangles, TEXCOORD_0.
For the load benchmark (BENCHMARKS.md): `python3 lab/tools/torus_glb.py NU NV OUT.glb`;
web/tests/test_gltf.py imports `torus_glb`. Needs numpy."""

import json
import struct
import sys

import numpy as np


def torus_glb(nu, nv):
    i, j = np.meshgrid(np.arange(nu + 1), np.arange(nv + 1), indexing="ij")
    u, v = 2 * np.pi * (i % nu) / nu, 2 * np.pi * (j % nv) / nv
    r = 1.0 + 0.35 * np.cos(v)
    V = np.stack([r * np.cos(u), r * np.sin(u), 0.35 * np.sin(v)], -1).reshape(-1, 3).astype("<f4")
    UV = np.stack([i / nu, 1 - j / nv], -1).reshape(-1, 2).astype("<f4")
    a = i[:-1, :-1] * (nv + 1) + j[:-1, :-1]
    F = np.concatenate([np.stack([a, a + nv + 1, a + nv + 2], -1).reshape(-1, 3),
                        np.stack([a, a + nv + 2, a + 1], -1).reshape(-1, 3)]).astype("<u4")
    blobs = [V.tobytes(), UV.tobytes(), F.tobytes()]
    offsets = np.cumsum([0] + [len(b) for b in blobs]).tolist()
    doc = {
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"name": "Torus", "primitives": [
            {"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2}]}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": len(V), "type": "VEC3",
             "min": V.min(0).tolist(), "max": V.max(0).tolist()},
            {"bufferView": 1, "componentType": 5126, "count": len(V), "type": "VEC2"},
            {"bufferView": 2, "componentType": 5125, "count": F.size, "type": "SCALAR"}],
        "bufferViews": [{"buffer": 0, "byteOffset": o, "byteLength": len(b)}
                        for o, b in zip(offsets, blobs)],
        "buffers": [{"byteLength": offsets[-1]}],
    }
    js = json.dumps(doc).encode()
    js += b" " * (-len(js) % 4)
    body = b"".join(blobs)
    total = 12 + 8 + len(js) + 8 + len(body)
    return (struct.pack("<4sII", b"glTF", 2, total) + struct.pack("<II", len(js), 0x4E4F534A) + js
            + struct.pack("<II", len(body), 0x004E4942) + body)


if __name__ == "__main__":
    nu, nv, out = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
    with open(out, "wb") as f:
        f.write(torus_glb(nu, nv))
