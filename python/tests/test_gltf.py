"""glTF files written by other tools read back as one welded surface: trimesh (its texture
export needs pillow) and pygltflib (a torus whose texture is cut along both seams) and Blender's own exporter give
the right vertex count after welding, genus 1, the same texture coordinates per corner, and
``scene.glb#Name`` picks one mesh."""

import json
import os
import shutil
import subprocess

import numpy as np
import pygltflib
import pytest
import trimesh

import wavg


def seamed_torus(nu=16, nv=8):
    """A torus as glTF exporters write it: (nu + 1) x (nv + 1) vertices, the seam copies at
    exactly the same positions, uv in OBJ's convention (v up)."""
    i, j = np.meshgrid(np.arange(nu + 1), np.arange(nv + 1), indexing="ij")
    u, v = 2 * np.pi * (i % nu) / nu, 2 * np.pi * (j % nv) / nv
    r = 1.0 + 0.3 * np.cos(v)
    V = np.stack([r * np.cos(u), r * np.sin(u), 0.3 * np.sin(v)], -1).reshape(-1, 3)
    UV = np.stack([i / nu, j / nv], -1).reshape(-1, 2)
    a = i[:-1, :-1] * (nv + 1) + j[:-1, :-1]
    b, c, d = a + nv + 1, a + nv + 2, a + 1
    F = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3),
                        np.stack([a, c, d], -1).reshape(-1, 3)])
    return V.astype(np.float32), F.astype(np.uint32), UV.astype(np.float32)


def genus(V, F):
    edges = {tuple(sorted(e)) for t in F.tolist() for e in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0]))}
    return (2 - (len(V) - len(edges) + len(F))) // 2


def check_welded(path, nu, nv, corner_uv):
    V, F = wavg.read_mesh(path)
    assert V.shape == (nu * nv, 3) and F.shape == (2 * nu * nv, 3)
    assert genus(V, F) == 1
    S = wavg.Surface.open(path)  # validated: a closed oriented manifold
    np.testing.assert_allclose(S.uv, corner_uv, atol=1e-6)


def test_trimesh_glb_reads_back_welded_with_its_uvs(tmp_path):
    nu, nv = 16, 8
    V, F, UV = seamed_torus(nu, nv)
    mesh = trimesh.Trimesh(V, F, visual=trimesh.visual.TextureVisuals(uv=UV), process=False)
    path = tmp_path / "torus.glb"
    mesh.export(path)
    check_welded(path, nu, nv, UV[F])
    # `#Name` picks the mesh by its name in the file (trimesh names it after the geometry).
    names = [m.name for m in pygltflib.GLTF2().load(str(path)).meshes]
    V2, _ = wavg.read_mesh(f"{path}#{names[0]}")
    assert len(V2) == nu * nv
    with pytest.raises(wavg.WavgIOError, match="no mesh or node named"):
        wavg.read_mesh(f"{path}#no such mesh")


def test_pygltflib_gltf_with_a_bin_beside_it(tmp_path):
    nu, nv = 12, 6
    V, F, UV = seamed_torus(nu, nv)
    gltf_uv = UV.copy()
    gltf_uv[:, 1] = 1 - gltf_uv[:, 1]  # glTF's v runs down the image
    blobs = [V.tobytes(), gltf_uv.tobytes(), F.tobytes()]
    offsets = np.cumsum([0] + [len(b) for b in blobs])
    g = pygltflib.GLTF2(
        scene=0,
        scenes=[pygltflib.Scene(nodes=[0])],
        nodes=[pygltflib.Node(mesh=0)],
        meshes=[pygltflib.Mesh(name="Torus", primitives=[pygltflib.Primitive(
            attributes=pygltflib.Attributes(POSITION=0, TEXCOORD_0=1), indices=2)])],
        accessors=[
            pygltflib.Accessor(bufferView=0, componentType=pygltflib.FLOAT, count=len(V),
                               type=pygltflib.VEC3, min=V.min(0).tolist(), max=V.max(0).tolist()),
            pygltflib.Accessor(bufferView=1, componentType=pygltflib.FLOAT, count=len(V),
                               type=pygltflib.VEC2),
            pygltflib.Accessor(bufferView=2, componentType=pygltflib.UNSIGNED_INT,
                               count=F.size, type=pygltflib.SCALAR),
        ],
        bufferViews=[pygltflib.BufferView(buffer=0, byteOffset=int(o), byteLength=len(b))
                     for o, b in zip(offsets, blobs)],
        buffers=[pygltflib.Buffer(uri="torus.bin", byteLength=int(offsets[-1]))],
    )
    (tmp_path / "torus.bin").write_bytes(b"".join(blobs))
    g.save_json(str(tmp_path / "torus.gltf"))
    check_welded(tmp_path / "torus.gltf", nu, nv, UV[F.astype(np.int64)])
    assert len(wavg.read_mesh(f"{tmp_path / 'torus.gltf'}#Torus")[0]) == nu * nv


BLENDER_EXPORT = """
import bpy, json, sys
out, uvs = sys.argv[-2], sys.argv[-1]
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.mesh.primitive_torus_add(major_segments=24, minor_segments=10, generate_uvs=True)
me = bpy.context.object.data
uv = me.uv_layers.active.data
corners = [[list(me.vertices[l.vertex_index].co), list(uv[l.index].uv)] for l in me.loops]
json.dump({"vertices": len(me.vertices), "corners": corners}, open(uvs, "w"))
bpy.ops.export_scene.gltf(filepath=out, export_format="GLB")
"""


@pytest.mark.skipif(shutil.which("blender") is None, reason="Blender is not installed")
def test_blender_glb_reads_back_welded_with_its_uvs(tmp_path):
    out, uvs = tmp_path / "torus.glb", tmp_path / "uvs.json"
    # Blender's glTF exporter needs NumPy: Debian's python3-numpy, or this environment's.
    env = dict(os.environ, PYTHONPATH=os.path.dirname(os.path.dirname(np.__file__)))
    subprocess.run(["blender", "-b", "--factory-startup", "--python-exit-code", "1",
                    "--python-expr", BLENDER_EXPORT, "--", str(out), str(uvs)],
                   check=True, capture_output=True, env=env, timeout=300)
    ref = json.loads(uvs.read_text())
    V, F = wavg.read_mesh(out)
    assert len(V) == ref["vertices"] == 24 * 10  # the exporter split it at every seam
    assert genus(V, F) == 1
    S = wavg.Surface.open(out)
    # The same (position, uv) corners: Blender's z-up (x, y, z) is glTF's (x, z, -y).
    def key(p, t):
        return tuple(np.round(p, 4)) + tuple(np.round(t, 4))
    want = {key((p[0], p[2], -p[1]), t) for p, t in ref["corners"]}
    got = {key(V[v], S.uv[f, k]) for f, tri in enumerate(F) for k, v in enumerate(tri)}
    assert got == want
