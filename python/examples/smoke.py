"""Checks an installed wavg in a few seconds, with no data files and no Rust toolchain.

    python smoke.py

Builds a torus in code (`_mesh.py`, beside it, as for the other examples), precomputes
its embedding, solves forward and inverse problems with NumPy arrays in and out, and
checks that they agree and that bad input raises the package's exceptions. Prints one line and exits 0 when everything holds; an assertion
names what does not. `cargo xtask test` runs it against the release wheel in every
CPython and NumPy it installs the wheel with.
"""

import sys

import numpy as np

import wavg
from _mesh import torus


def main():
    V, F = torus(n=32, m=12)
    # float32 vertices and int32 faces: the package takes any float and integer dtype.
    S = wavg.Surface(V.astype(np.float32), F.astype(np.int32))
    report = S.precompute(progress=False)
    assert S.embedding.shape == (S.vertex_count, 8), S.embedding.shape
    assert np.isfinite(S.embedding).all()
    assert isinstance(report, dict)

    anchors = S.spread_anchors(5)
    sol = wavg.Solver(S, anchors)
    faces, bary = S.sample_points(64, seed=1)
    W, ok = sol.inverse(faces, bary)
    assert W.shape == (64, 5) and ok.dtype == np.bool_, (W.shape, ok.dtype)
    assert ok.sum() >= 48, f"only {ok.sum()} of 64 inverse problems verified"
    assert np.allclose(W[ok].sum(axis=1), 1.0)

    # The verified weights lead back to their points: forward of inverse is the identity.
    back = sol.forward(W[ok])
    assert back.ok.all()
    corners = S.vertices[S.faces[faces[ok]]]
    points = np.einsum("qk,qkd->qd", bary[ok], corners)
    gap = np.linalg.norm(back.xyz - points, axis=1).max()
    assert gap < 1e-3, f"round trip off by {gap}"

    try:
        wavg.Solver(S, np.array([0, S.vertex_count + 7]))
    except ValueError as e:
        assert "out of range" in str(e), e
    else:
        raise AssertionError("an anchor past the last vertex was accepted")

    print(f"wavg {wavg.__version__} smoke ok: numpy {np.__version__}, "
          f"python {sys.version.split()[0]}, {int(ok.sum())}/64 round trips, gap {gap:.1e}")


if __name__ == "__main__":
    main()
