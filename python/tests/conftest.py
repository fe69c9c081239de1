"""Shared fixtures: meshes generated in code, the real-mesh folder and the CLI binary."""

import os
import pathlib
import shutil

import numpy as np
import pytest

import wavg

ROOT = pathlib.Path(__file__).resolve().parents[2]


def torus(n=24, m=12, R=1.0, r=0.4):
    """A closed torus: n x m grid, two counter-clockwise triangles per cell."""
    u = np.arange(n) * 2 * np.pi / n
    v = np.arange(m) * 2 * np.pi / m
    uu, vv = np.meshgrid(u, v, indexing="ij")
    V = np.stack([(R + r * np.cos(vv)) * np.cos(uu), (R + r * np.cos(vv)) * np.sin(uu),
                  r * np.sin(vv)], axis=-1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(n), np.arange(m), indexing="ij")
    a = i * m + j
    b = ((i + 1) % n) * m + j
    c = ((i + 1) % n) * m + (j + 1) % m
    d = i * m + (j + 1) % m
    F = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3),
                        np.stack([a, c, d], -1).reshape(-1, 3)])
    return V, F


def write_obj(path, V, F):
    with open(path, "w") as f:
        for p in V:
            f.write("v {!r} {!r} {!r}\n".format(*map(float, p)))
        for t in F:
            f.write("f {} {} {}\n".format(*(int(x) + 1 for x in t)))


@pytest.fixture(scope="session", autouse=True)
def own_cache(tmp_path_factory):
    """The CLI's embedding cache: $WAVG_CACHE_DIR when set, else a temporary folder (never
    the user's ~/.cache/wavg)."""
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("WAVG_CACHE_DIR", os.environ.get("WAVG_CACHE_DIR") or str(tmp_path_factory.mktemp("cache")))
        yield


@pytest.fixture(scope="session")
def torus_mesh():
    return torus()


@pytest.fixture(scope="session")
def surface(torus_mesh):
    """An embedded torus (precomputed once per session)."""
    S = wavg.Surface(*torus_mesh)
    S.precompute(landmarks=80, progress=False)
    return S


@pytest.fixture(scope="session")
def anchors(surface):
    return surface.spread_anchors(12, seed=0)


@pytest.fixture(scope="session")
def data_dir():
    d = pathlib.Path(os.environ.get("WAVG_DATA_DIR", ROOT.parent / "shared" / "data"))
    if not (d / "meshes").is_dir():
        pytest.skip(f"real meshes not found in {d} (set WAVG_DATA_DIR)")
    return d


@pytest.fixture(scope="session")
def cli():
    """The `wavg` command line program (WAVG_CLI, target/debug/wavg or on PATH)."""
    for c in (os.environ.get("WAVG_CLI"), ROOT / "target" / "debug" / "wavg", shutil.which("wavg")):
        if c and pathlib.Path(c).is_file():
            return str(c)
    pytest.skip("the wavg CLI is not built (cargo build); set WAVG_CLI")


def random_weights(rng, q, k):
    W = rng.random((q, k))
    return W / W.sum(axis=1, keepdims=True)


@pytest.fixture(scope="session")
def libwavg():
    """The C library libwavg.so (WAVG_LIBWAVG, else target/debug/libwavg.so)."""
    for c in (os.environ.get("WAVG_LIBWAVG"), ROOT / "target" / "debug" / "libwavg.so"):
        if c and pathlib.Path(c).is_file():
            return str(c)
    pytest.skip("libwavg.so is not built (cargo build -p wavg-ffi); set WAVG_LIBWAVG")
