"""Surface: construction from arrays and files, properties, embeddings, dtype variants."""

import numpy as np
import pytest

import wavg
from conftest import torus, write_obj


def test_read_mesh_matches_arrays(tmp_path, torus_mesh):
    V, F = torus_mesh
    write_obj(tmp_path / "t.obj", V, F)
    V2, F2 = wavg.read_mesh(tmp_path / "t.obj")
    assert V2.dtype == np.float64 and V2.shape == V.shape
    assert F2.dtype == np.int64 and F2.shape == F.shape
    assert np.array_equal(V2, V) and np.array_equal(F2, F)


def test_builtin_meshes_open_as_on_the_command_line(tmp_path):
    V, F = wavg.read_mesh("builtin:torus")
    assert V.shape == (1536, 3) and F.shape == (3072, 3)
    s = wavg.Surface.open("builtin:torus")
    assert s.vertex_count == 1536 and np.array_equal(s.vertices, V)
    with pytest.raises(ValueError, match="unknown builtin mesh 'teapot'; available: icosphere"):
        wavg.Surface.open("builtin:teapot")
    # A file of that name elsewhere is still a file.
    with pytest.raises(FileNotFoundError):
        wavg.Surface.open(tmp_path / "builtin:torus")


def test_properties(surface, torus_mesh):
    V, F = torus_mesh
    assert surface.vertex_count == len(V) and surface.face_count == len(F)
    assert np.array_equal(surface.vertices, V) and np.array_equal(surface.faces, F)
    assert surface.embedding.shape == (len(V), 8) and surface.embedding.dtype == np.float64
    assert surface.has_embedding
    lm = surface.landmarks
    assert lm.dtype == np.int64 and 0 < len(lm) <= 80 and lm.max() < len(V)
    assert surface.uv is None


def test_no_embedding_before_precompute(torus_mesh):
    S = wavg.Surface(*torus_mesh)
    assert S.embedding is None and not S.has_embedding and len(S.landmarks) == 0
    with pytest.raises(wavg.WavgError):
        S.save_embedding("never-written.wavg")


def test_embedding_round_trip(tmp_path, surface, torus_mesh):
    path = tmp_path / "t.wavg"
    surface.save_embedding(path)
    S2 = wavg.Surface(*torus_mesh)
    S2.load_embedding(path)
    assert np.array_equal(S2.embedding, surface.embedding)
    write_obj(tmp_path / "t.obj", *torus_mesh)
    S3 = wavg.Surface.open(tmp_path / "t.obj", embedding=path)
    assert np.array_equal(S3.embedding, surface.embedding)
    before = (tmp_path / "t.obj").read_bytes()
    with pytest.raises(ValueError, match="mesh file"):
        surface.save_embedding(tmp_path / "t.obj")  # would destroy the mesh
    assert (tmp_path / "t.obj").read_bytes() == before


def test_embedding_of_another_mesh_is_refused(tmp_path, surface):
    path = tmp_path / "t.wavg"
    surface.save_embedding(path)
    other = wavg.Surface(*torus(20, 10))
    with pytest.raises(wavg.WavgError):
        other.load_embedding(path)
    assert other.embedding is None


def unaligned(a):
    """A C-contiguous copy of `a` at an odd byte offset of a buffer (NumPy flags it unaligned)."""
    buf = bytearray(a.nbytes + 1)
    u = np.frombuffer(buf, dtype=a.dtype, count=a.size, offset=1).reshape(a.shape)
    u[...] = a
    assert not u.flags.aligned and u.flags.c_contiguous
    return u


@pytest.mark.parametrize(
    "variant", ["float32", "fortran", "slice", "list", "int32", "uint16", "unaligned"]
)
def test_dtype_and_layout_variants(variant, torus_mesh):
    V, F = torus_mesh
    if variant == "float32":
        V2, F2, Vexp = V.astype(np.float32), F, V.astype(np.float32).astype(np.float64)
    elif variant == "fortran":
        V2, F2, Vexp = np.asfortranarray(V), np.asfortranarray(F), V
    elif variant == "slice":
        big = np.zeros((len(V), 6))
        big[:, ::2] = V
        V2, F2, Vexp = big[:, ::2], F, V
    elif variant == "list":
        V2, F2, Vexp = V.tolist(), F.tolist(), V
    elif variant == "int32":
        V2, F2, Vexp = V, F.astype(np.int32), V
    elif variant == "uint16":
        V2, F2, Vexp = V, F.astype(np.uint16), V
    else:
        V2, F2, Vexp = unaligned(V), unaligned(F), V
    S = wavg.Surface(V2, F2)
    assert np.array_equal(S.vertices, Vexp) and np.array_equal(S.faces, F)


def test_vertex_points(surface):
    ids = np.array([0, 5, 17])
    faces, bary = surface.vertex_points(ids)
    assert faces.shape == (3,) and bary.shape == (3, 3)
    F, V = surface.faces, surface.vertices
    for v, f, b in zip(ids, faces, bary):
        assert np.allclose(b @ V[F[f]], V[v])


def test_from_trimesh_duck(torus_mesh):
    class Mesh:
        vertices, faces = torus_mesh
    S = wavg.Surface.from_trimesh(Mesh())
    assert S.vertex_count == len(torus_mesh[0])


def test_uv_round_trip(torus_mesh):
    V, F = torus_mesh
    uv = np.random.default_rng(0).random((len(F), 3, 2))
    S = wavg.Surface(V, F, uv=uv)
    assert np.array_equal(S.uv, uv)


def test_precompute_report_and_progress(torus_mesh):
    S = wavg.Surface(*torus_mesh)
    calls = []
    report = S.precompute(landmarks=40, progress=lambda s, d, t: calls.append((s, d, t)))
    assert {"landmarks", "stages", "seconds"} <= set(report)
    assert all(isinstance(s, str) and 0 <= d <= t for s, d, t in calls)


def test_progress_is_a_flag_or_a_callable(torus_mesh):
    S = wavg.Surface(*torus_mesh)
    for bad in (5, 0, 0.5, "yes"):
        with pytest.raises(TypeError, match="progress must be True, False, None or a callable"):
            S.precompute(landmarks=40, progress=bad)
    assert S.embedding is None
    S.precompute(landmarks=40, progress=False)
    assert S.embedding is not None


def test_precompute_cancel_leaves_surface_unchanged(torus_mesh):
    S = wavg.Surface(*torus(60, 30))
    with pytest.raises(wavg.CancelledError):
        S.precompute(landmarks=200, progress=lambda *a: False)
    assert S.embedding is None


def test_precompute_cancels_on_any_false_answer_but_none(torus_mesh):
    # A deadline test written with NumPy answers `np.False_`, which is not `False`.
    S = wavg.Surface(*torus(60, 30))
    for answer in (np.False_, 0):
        with pytest.raises(wavg.CancelledError):
            S.precompute(landmarks=200, progress=lambda *a: answer)
        assert S.embedding is None
    S.precompute(landmarks=30, progress=lambda *a: None)  # returning nothing goes on
    assert S.embedding is not None


def test_progress_exception_propagates(torus_mesh):
    S = wavg.Surface(*torus(60, 30))

    def boom(*a):
        raise RuntimeError("from the callback")
    with pytest.raises(RuntimeError, match="from the callback"):
        S.precompute(landmarks=200, progress=boom)
    assert S.embedding is None


def test_load_embedding_during_precompute_is_refused(tmp_path, surface, torus_mesh):
    # The progress callback runs while the precompute does: what another thread could do
    # then, it does here, deterministically.
    other = tmp_path / "other.wavg"
    surface.save_embedding(other)
    S = wavg.Surface(*torus_mesh)
    refused = []

    def meddle(stage, done, total):
        if not refused:
            for call in (lambda: S.load_embedding(other), lambda: S.precompute(landmarks=20, progress=False)):
                with pytest.raises(RuntimeError, match="precompute"):
                    call()
                refused.append(call)
        return True
    S.precompute(landmarks=30, progress=meddle)
    assert len(refused) == 2
    mine = S.embedding.copy()
    assert not np.array_equal(mine, surface.embedding)  # the precompute's, not the loaded one
    S.load_embedding(other)  # after it: allowed again
    assert np.array_equal(S.embedding, surface.embedding)
    # A cancelled precompute frees the surface too.
    with pytest.raises(wavg.CancelledError):
        S.precompute(landmarks=30, progress=lambda *a: False)
    S.load_embedding(other)


def test_precompute_threads_equal(torus_mesh):
    a = wavg.Surface(*torus_mesh)
    b = wavg.Surface(*torus_mesh)
    a.precompute(landmarks=60, threads=1, progress=False)
    b.precompute(landmarks=60, threads=None, progress=False)
    assert np.array_equal(a.embedding, b.embedding)


def test_real_mesh_with_uv(data_dir):
    S = wavg.Surface.open(data_dir / "textured" / "spot" / "spot_triangulated.obj")
    assert S.uv.shape == (S.face_count, 3, 2)


def test_sample_points_are_seeded_and_uniform_by_area(surface):
    faces, bary = surface.sample_points(60_000, seed=3)
    again, bary2 = surface.sample_points(60_000, seed=3)
    assert np.array_equal(faces, again) and np.array_equal(bary, bary2)
    assert not np.array_equal(faces, surface.sample_points(60_000, seed=4)[0])
    assert faces.dtype == np.int64 and bary.shape == (60_000, 3)
    assert (bary >= 0).all() and np.allclose(bary.sum(axis=1), 1.0)
    V, F = surface.vertices, surface.faces
    area = np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)
    expected = area / area.sum() * len(faces)
    counts = np.bincount(faces, minlength=len(F))
    # Each face's count within 5 standard deviations of a binomial with its area share.
    assert (np.abs(counts - expected) <= 5 * np.sqrt(expected) + 1).all()
    # Within a face, uniform: the mean barycentric coordinate is 1/3.
    assert np.allclose(bary.mean(axis=0), 1 / 3, atol=0.01)
    assert surface.sample_points(0)[0].shape == (0,)
