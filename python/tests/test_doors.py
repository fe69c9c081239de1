"""The cross-door test: one mesh of more than 1000 vertices, default options everywhere,
and every way into wavg computes the same embedding (byte-identical `.wavg` files): `wavg
precompute`, the CLI's cache entry, Python without and with the cache (its entry written by
"python"), and the C ABI through ctypes."""

import ctypes
import json
import os
import subprocess

import numpy as np
import pytest

import wavg
from conftest import torus, write_obj


@pytest.fixture(scope="module")
def mesh(tmp_path_factory):
    """A 1152-vertex torus as OBJ: more vertices than the default 1000 landmarks, so the
    library's choice of landmarks matters."""
    V, F = torus(n=48, m=24)
    path = tmp_path_factory.mktemp("doors") / "m.obj"
    write_obj(path, V, F)
    assert len(V) > 1000
    return path


def run(cli, *args, cache):
    env = dict(os.environ, WAVG_CACHE_DIR=str(cache))
    return subprocess.run([cli, *map(str, args)], check=True, capture_output=True, text=True, env=env).stdout


def c_precompute(lib_path, mesh, out):
    """wavg_surface_open, wavg_surface_precompute (NULL options: the defaults),
    wavg_surface_save_embedding, wavg_surface_free."""
    lib = ctypes.CDLL(lib_path)
    lib.wavg_surface_open.argtypes = [ctypes.c_char_p, ctypes.POINTER(ctypes.c_void_p)]
    lib.wavg_surface_open.restype = ctypes.c_int
    lib.wavg_surface_precompute.argtypes = [ctypes.c_void_p] * 4
    lib.wavg_surface_precompute.restype = ctypes.c_int
    lib.wavg_surface_save_embedding.argtypes = [ctypes.c_void_p, ctypes.c_char_p]
    lib.wavg_surface_save_embedding.restype = ctypes.c_int
    lib.wavg_surface_free.argtypes = [ctypes.c_void_p]
    lib.wavg_surface_free.restype = None
    s = ctypes.c_void_p()
    assert lib.wavg_surface_open(os.fsencode(mesh), ctypes.byref(s)) == 0
    try:
        assert lib.wavg_surface_precompute(s, None, None, None) == 0
        assert lib.wavg_surface_save_embedding(s, os.fsencode(out)) == 0
    finally:
        lib.wavg_surface_free(s)


def test_every_door_makes_the_same_embedding(tmp_path, mesh, cli, libwavg):
    files = {}
    # The CLI: `wavg precompute` without options, then the cache entry `wavg anchors` fills.
    files["cli precompute"] = tmp_path / "cli.wavg"
    run(cli, "precompute", mesh, "-o", files["cli precompute"], cache=tmp_path / "cache-pre")
    cli_cache = tmp_path / "cache-cli"
    run(cli, "anchors", "--mesh", mesh, "--count", 4, "-o", tmp_path / "a.txt", cache=cli_cache)
    entries = json.loads(run(cli, "cache", "list", "--json", cache=cli_cache))["entries"]
    assert len(entries) == 1 and entries[0]["writer"] == "cli"
    files["cli cache"] = cli_cache / (entries[0]["key"] + ".wavg")
    # Python without a cache.
    s = wavg.Surface.open(mesh)
    report = s.precompute(cache=False, progress=False)
    assert report["cached"] is False and report["cache_path"] is None
    files["python"] = tmp_path / "py.wavg"
    s.save_embedding(files["python"])
    # Python with a cache folder: one entry, written by "python", under the CLI's key.
    py_cache = tmp_path / "cache-py"
    report = wavg.Surface.open(mesh).precompute(cache=py_cache, progress=False)
    (entry,) = wavg.cache_entries(py_cache)
    assert entry["writer"] == "python" and entry["key"] == entries[0]["key"]
    assert report["cache_path"] == entry["path"]
    files["python cache"] = py_cache / (entry["key"] + ".wavg")
    # The C ABI with NULL options.
    files["C"] = tmp_path / "c.wavg"
    c_precompute(libwavg, mesh, files["C"])

    ref = files["cli precompute"].read_bytes()
    emb = wavg.Surface.open(mesh, embedding=files["cli precompute"])
    assert len(emb.landmarks) == 1000
    for door, path in files.items():
        other = wavg.Surface.open(mesh, embedding=path)
        np.testing.assert_array_equal(other.embedding, emb.embedding, err_msg=door)
        np.testing.assert_array_equal(other.landmarks, emb.landmarks, err_msg=door)
        assert path.read_bytes() == ref, f"{door}: {path} differs from `wavg precompute`'s file"
