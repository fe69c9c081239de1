"""Every error: typed, naming the argument; and a fuzz run of random arrays to every entry."""

import numpy as np
import pytest

import wavg
from conftest import torus


def test_exception_hierarchy():
    assert issubclass(wavg.InvalidMeshError, wavg.WavgError)
    assert issubclass(wavg.InvalidMeshError, ValueError)
    assert issubclass(wavg.InvalidArgumentError, ValueError)
    assert issubclass(wavg.WavgIOError, OSError)
    assert issubclass(wavg.OutOfMemoryError, wavg.WavgError)
    assert issubclass(wavg.OutOfMemoryError, MemoryError)


def test_invalid_mesh_lists_problems(torus_mesh):
    V, F = torus_mesh
    with pytest.raises(wavg.InvalidMeshError) as e:
        wavg.Surface(V, np.vstack([F, F[:1]]))
    assert any("duplicates" in p for p in e.value.problems)
    V2 = V.copy()
    V2[3] = np.nan
    with pytest.raises(ValueError, match="V"):
        wavg.Surface(V2, F)


def test_mesh_scale_out_of_range_says_how_to_rescale(torus_mesh):
    V, F = torus_mesh
    for scale, word in [(1e-100, "scale the mesh up"), (1e40, "scale the mesh down")]:
        with pytest.raises(wavg.InvalidArgumentError, match=word):
            wavg.Surface(V * scale, F)
    # Within the range, any scale works, the same shape giving the same weights.
    faces, bary = np.array([0, 7]), np.array([[0.2, 0.3, 0.5], [0.6, 0.2, 0.2]])
    W = [wavg.Solver(wavg.Surface(V * s, F), [0, 50, 100, 150]).inverse(faces, bary)[0]
         for s in (1e-50, 1.0, 1e30)]
    assert np.allclose(W[0], W[1], atol=1e-9) and np.allclose(W[2], W[1], atol=1e-9)


@pytest.mark.parametrize("V_bad, F_bad, exc, word", [
    ("shape", None, ValueError, "V"),
    (None, "shape", ValueError, "F"),
    (None, "float", TypeError, "F"),
    ("str", None, TypeError, "V"),
    (None, "range", ValueError, "F"),
    (None, "negative", ValueError, "F"),
])
def test_bad_mesh_arguments(torus_mesh, V_bad, F_bad, exc, word):
    V, F = torus_mesh
    V = {"shape": V[:, :2], "str": np.array([["a", "b", "c"]]), None: V}[V_bad]
    F = {"shape": F[:, :2], "float": F.astype(float), "range": F + len(V) * 10,
         "negative": F - 1, None: F}[F_bad]
    with pytest.raises(exc, match=word):
        wavg.Surface(V, F)


def test_missing_files(tmp_path, surface):
    with pytest.raises(FileNotFoundError):
        wavg.read_mesh(tmp_path / "none.obj")
    with pytest.raises(FileNotFoundError):
        wavg.Surface.open(tmp_path / "none.off")
    with pytest.raises(FileNotFoundError):
        surface.load_embedding(tmp_path / "none.wavg")
    with pytest.raises(FileNotFoundError):
        wavg.read_png(tmp_path / "none.png")


def test_unreadable_file(tmp_path):
    p = tmp_path / "bad.obj"
    p.write_text("v 1 2\nf 1 2 3 x\n")
    with pytest.raises(wavg.WavgError):
        wavg.read_mesh(p)


def test_solver_argument_errors(surface, anchors):
    with pytest.raises(ValueError, match="anchors"):
        wavg.Solver(surface, [surface.vertex_count])
    with pytest.raises(ValueError, match="anchors"):
        wavg.Solver(surface, np.array([], dtype=np.int64))
    with pytest.raises(TypeError, match="anchors"):
        wavg.Solver(surface, [0.5, 1.5])
    s = wavg.Solver(surface, anchors)
    k = s.anchor_count
    with pytest.raises(ValueError, match=r"W .*\(q, %d\)" % k):
        s.forward(np.ones((3, k + 1)))
    with pytest.raises(TypeError, match="W"):
        s.forward(np.ones((3, k), dtype=complex))
    with pytest.raises(ValueError, match="threads"):
        s.forward(np.ones(k) / k, threads=0)
    with pytest.raises(ValueError, match="faces"):
        s.inverse([surface.face_count], [[1, 0, 0]])
    with pytest.raises(ValueError, match="bary"):
        s.inverse([0], [[np.nan, 0, 0]])
    with pytest.raises(ValueError, match="same length"):
        s.inverse([0, 1], [[1, 0, 0]])
    with pytest.raises(ValueError, match="i"):
        s.set_anchor(k, 0)
    with pytest.raises(TypeError, match="vertex_or_point"):
        s.set_anchor(0, "x")


def test_app_argument_errors(surface, anchors):
    with pytest.raises(ValueError, match="validity"):
        wavg.correspond(surface, surface, anchors, anchors, validity="global")
    with pytest.raises(ValueError, match="dst_anchors"):
        wavg.correspond(surface, surface, anchors, anchors[:-1])
    with pytest.raises(ValueError, match="uv"):
        wavg.decal(surface, anchors[:3], np.zeros((2, 2)))
    with pytest.raises(ValueError, match="samples"):
        wavg.spline(surface, anchors[:4], samples=0)
    with pytest.raises(ValueError, match="size"):
        wavg.render(surface, size=(0, 10))
    with pytest.raises(ValueError, match="scalar"):
        wavg.render(surface, scalar=np.zeros(3))
    with pytest.raises(TypeError, match="texture"):
        wavg.render(surface, texture=np.zeros((4, 4, 4)))
    with pytest.raises(wavg.InvalidArgumentError):
        wavg.transfer_texture(surface, np.zeros((4, 4, 4), np.uint8), surface, anchors, anchors)
    with pytest.raises(ValueError, match="levels"):
        wavg.Remesher(surface, surface.vertices[:4], [[0, 1, 2]], levels=-1)


def _random_array(rng):
    kind = rng.integers(0, 9)
    ndim = int(rng.integers(0, 4))
    shape = tuple(int(x) for x in rng.choice([0, 1, 2, 3, 4, 8, 12, 50], size=ndim))
    if kind == 0:
        return rng.normal(size=shape) * 10.0 ** rng.integers(-300, 300)
    if kind == 1:
        a = rng.normal(size=shape)
        a[rng.random(shape) < 0.3] = rng.choice([np.nan, np.inf, -np.inf])
        return a
    if kind == 2:
        return rng.integers(-2**62, 2**62, size=shape, dtype=np.int64)
    if kind == 3:
        return rng.integers(0, 2**64 - 1, size=shape, dtype=np.uint64)
    if kind == 4:
        return rng.integers(-5, 600, size=shape).astype(rng.choice([np.int8, np.int32, np.float32]))
    if kind == 5:
        return np.zeros(shape, dtype=rng.choice([bool, complex, object]))
    if kind == 6:
        return np.full(shape, "x")
    if kind == 7:
        return rng.random(shape)
    return [[1, 2], [3]]  # ragged


def test_fuzz_random_arrays_only_raise_python_exceptions(surface, anchors):
    rng = np.random.default_rng(2024)
    small = wavg.Surface(*torus(8, 4))
    sol = wavg.Solver(surface, anchors)
    k = len(anchors)
    good_W = np.full((2, k), 1 / k)
    entries = {
        "Surface(V)": lambda a: wavg.Surface(a, small.faces),
        "Surface(F)": lambda a: wavg.Surface(small.vertices, a),
        "Surface(uv)": lambda a: wavg.Surface(small.vertices, small.faces, uv=a),
        "Solver": lambda a: wavg.Solver(surface, a),
        "forward": lambda a: sol.forward(a),
        "inverse(faces)": lambda a: sol.inverse(a, np.full((3, 3), 1 / 3)),
        "inverse(bary)": lambda a: sol.inverse(np.zeros(3, np.int64), a),
        "set_anchor": lambda a: wavg.Solver(surface, anchors).set_anchor(0, a),
        "vertex_points": lambda a: surface.vertex_points(a),
        "weighted_average(weights)": lambda a: wavg.weighted_average(
            small.vertices, small.faces, [0, 5, 9], a),
        "barycentric_weights(bary)": lambda a: wavg.barycentric_weights(
            small.vertices, small.faces, [0, 5, 9], [0], a),
        "spline": lambda a: wavg.spline(surface, a, samples=5),
        "correspond": lambda a: wavg.correspond(surface, surface, anchors, a),
        "decal": lambda a: wavg.decal(surface, anchors[:3], a),
        "transfer_texture": lambda a: wavg.transfer_texture(
            surface, a, surface, anchors, anchors, size=(8, 8)),
        "render(points)": lambda a: wavg.render(surface, size=(16, 12), points=a),
        "render(scalar)": lambda a: wavg.render(surface, size=(16, 12), scalar=a),
        "render(texture)": lambda a: wavg.render(surface, size=(16, 12), texture=a),
        "Remesher(base_V)": lambda a: wavg.Remesher(surface, a, [[0, 1, 2]], levels=0, smooth=0),
        "Remesher(base_F)": lambda a: wavg.Remesher(surface, surface.vertices, a, levels=0, smooth=0),
        "forward(good)": lambda a: sol.forward(good_W),
    }
    arrays = [_random_array(rng) for _ in range(500)]
    seen = {}
    for name, call in entries.items():
        for a in arrays:
            try:
                out = call(a)
            except Exception as e:  # noqa: BLE001 - any Python exception is the contract
                seen[type(e).__name__] = seen.get(type(e).__name__, 0) + 1
                continue
            # An answer never holds NaN where it claims to be ok.
            if isinstance(out, wavg.Points):
                ok = np.asarray(out.ok)
                assert not np.isnan(np.asarray(out.xyz)[ok]).any(), name
    assert seen.get("ValueError", 0) + seen.get("TypeError", 0) > 1000
