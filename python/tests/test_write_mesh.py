"""wavg.write_mesh: every format read_mesh reads, plus glTF (.glb, .gltf + .bin), read
back here with the standard library (the GLB header, JSON and buffer)."""

import json
import os
import pathlib
import shutil
import struct

import numpy as np
import pytest

import wavg


def keep(path, name):
    """A copy for the Khronos validator of `cargo xtask test` ($WAVG_GLTF_DIR)."""
    folder = os.environ.get("WAVG_GLTF_DIR")
    if not folder:
        return
    out = pathlib.Path(folder) / name
    out.mkdir(parents=True, exist_ok=True)
    shutil.copy(path, out)
    if path.suffix == ".gltf":
        shutil.copy(path.with_suffix(".bin"), out)


def glb_parts(path):
    """(JSON document, buffer bytes) of a .glb."""
    data = pathlib.Path(path).read_bytes()
    magic, version, total = struct.unpack_from("<4sII", data, 0)
    assert (magic, version, total) == (b"glTF", 2, len(data))
    n, kind = struct.unpack_from("<I4s", data, 12)
    assert kind == b"JSON"
    doc = json.loads(data[20:20 + n])
    m, kind = struct.unpack_from("<I4s", data, 20 + n)
    assert kind == b"BIN\0"
    return doc, data[28 + n:28 + n + m]


def accessor(doc, buf, index):
    a = doc["accessors"][index]
    v = doc["bufferViews"][a["bufferView"]]
    dtype = {5126: np.float32, 5125: np.uint32}[a["componentType"]]
    width = {"SCALAR": 1, "VEC2": 2, "VEC3": 3}[a["type"]]
    start = v.get("byteOffset", 0)
    out = np.frombuffer(buf[start:start + v["byteLength"]], dtype=dtype)
    return out.reshape(a["count"], width)


def test_obj_and_ply_round_trip_exactly(tmp_path, torus_mesh):
    V, F = torus_mesh
    for name in ["t.obj", "t.ply", "t.off.gz"]:
        wavg.write_mesh(tmp_path / name, V, F)
        V2, F2 = wavg.read_mesh(tmp_path / name)
        np.testing.assert_array_equal(V2, V)
        np.testing.assert_array_equal(F2, F)


def test_glb_holds_the_mesh_in_float32_and_splits_uv_seams(tmp_path, torus_mesh):
    V, F = torus_mesh
    uv = V[F][:, :, :2] * 0.25 + 0.5  # per corner; equal per vertex: no seam
    uv[0] = [[0, 0], [1, 0], [0, 1]]  # face 0 differs: its three corners split
    path = tmp_path / "t.glb"
    wavg.write_mesh(path, V, F, uv=uv)
    keep(path, "python_write_mesh_glb")
    doc, buf = glb_parts(path)
    prim = doc["meshes"][0]["primitives"][0]
    P = accessor(doc, buf, prim["attributes"]["POSITION"])
    T = accessor(doc, buf, prim["attributes"]["TEXCOORD_0"])
    I = accessor(doc, buf, prim["indices"]).reshape(-1, 3)
    assert len(I) == len(F)
    assert len(P) == len(V) + 3
    np.testing.assert_array_equal(P[I], V[F].astype(np.float32))
    st = uv.astype(np.float64).copy()
    st[..., 1] = 1 - st[..., 1]
    np.testing.assert_array_equal(T[I], st.astype(np.float32))


def test_gltf_writes_its_bin_beside_it(tmp_path, torus_mesh):
    V, F = torus_mesh
    path = tmp_path / "t.gltf"
    wavg.write_mesh(path, V, F)
    keep(path, "python_write_mesh_gltf")
    doc = json.loads(path.read_text())
    assert doc["buffers"][0]["uri"] == "t.bin"
    assert (tmp_path / "t.bin").stat().st_size == doc["buffers"][0]["byteLength"]


def test_bad_input_raises_and_writes_nothing(tmp_path, torus_mesh):
    V, F = torus_mesh
    with pytest.raises(ValueError):
        wavg.write_mesh(tmp_path / "a.glb", V, F[:, :2])
    with pytest.raises(wavg.WavgError):
        wavg.write_mesh(tmp_path / "a.stl", V, F)
    for name in ("a.gltf.gz", "a.glb.gz"):
        with pytest.raises(wavg.WavgError, match=r"\.gl(tf|b)\.gz is not written.*\.obj, \.off or \.ply"):
            wavg.write_mesh(tmp_path / name, V, F)
    with pytest.raises(ValueError, match="#Body selects a mesh"):
        wavg.write_mesh(tmp_path / "a.glb#Body", V, F)
    V = V.copy()
    V[0, 0] = 1e300  # beyond float32
    with pytest.raises(wavg.WavgError):
        wavg.write_mesh(tmp_path / "a.glb", V, F)
    assert list(tmp_path.iterdir()) == []
