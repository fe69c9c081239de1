"""Solver: forward and inverse batches, round trips, threads, anchors, pickling."""

import copy
import multiprocessing
import pickle
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pytest

import wavg
from conftest import random_weights


@pytest.fixture(scope="module")
def solver(surface, anchors):
    return wavg.Solver(surface, anchors)


def test_forward_shapes_and_round_trip(surface, solver):
    rng = np.random.default_rng(1)
    W = random_weights(rng, 500, solver.anchor_count)
    P = solver.forward(W)
    assert isinstance(P, wavg.Points)
    assert P.face.shape == (500,) and P.face.dtype == np.int64
    assert P.bary.shape == (500, 3) and P.xyz.shape == (500, 3) and P.ok.dtype == np.bool_
    assert P.ok.all()
    # xyz is the barycentric combination of the face's corners.
    V, F = surface.vertices, surface.faces
    assert np.allclose(np.einsum("qi,qij->qj", P.bary, V[F[P.face]]), P.xyz)
    # Inverse then forward returns to the points.
    W2, ok = solver.inverse(P.face, P.bary)
    assert W2.shape == (500, solver.anchor_count) and ok.all()
    assert np.allclose(W2.sum(axis=1), 1.0)
    P2 = solver.forward(W2)
    edge = np.linalg.norm(V[F[:, 0]] - V[F[:, 1]], axis=1).mean()
    assert np.max(np.linalg.norm(P2.xyz - P.xyz, axis=1)) < 1e-3 * edge


def test_anchor_weights_give_the_anchor(surface, anchors, solver):
    W = np.eye(len(anchors))
    P = solver.forward(W)
    assert np.allclose(P.xyz, surface.vertices[anchors], atol=1e-9)


def test_one_query_is_squeezed(solver):
    w = np.full(solver.anchor_count, 1 / solver.anchor_count)
    p = solver.forward(w)
    P = solver.forward(w[None])
    assert p.face == P.face[0] and p.ok == P.ok[0]
    assert np.array_equal(p.xyz, P.xyz[0]) and p.bary.shape == (3,)


def test_weights_dtype_and_layout(solver):
    rng = np.random.default_rng(2)
    W = random_weights(rng, 200, solver.anchor_count)
    ref = solver.forward(W)
    for W2 in (np.asfortranarray(W), np.repeat(W, 2, axis=0)[::2], np.repeat(W, 2, axis=1)[:, ::2], W.tolist()):
        assert np.array_equal(solver.forward(W2).xyz, ref.xyz)
    W32 = W.astype(np.float32)
    assert np.array_equal(solver.forward(W32).xyz, solver.forward(W32.astype(np.float64)).xyz)
    # An unaligned array (a view at an odd byte offset of a buffer) is read, not taken as empty.
    buf = bytearray(W.nbytes + 1)
    Wu = np.frombuffer(buf, dtype=W.dtype, count=W.size, offset=1).reshape(W.shape)
    Wu[...] = W
    assert not Wu.flags.aligned
    assert np.array_equal(solver.forward(Wu).xyz, ref.xyz)


def test_threads_equal_one_thread(solver):
    rng = np.random.default_rng(3)
    W = random_weights(rng, 2000, solver.anchor_count)
    a, b, c = (solver.forward(W, threads=t) for t in (1, 2, None))
    for x in (b, c):
        assert np.array_equal(a.face, x.face) and np.array_equal(a.xyz, x.xyz)
    wa, oa = solver.inverse(a.face, a.bary, threads=1)
    wb, ob = solver.inverse(a.face, a.bary, threads=None)
    assert np.array_equal(wa, wb) and np.array_equal(oa, ob)


def test_malformed_weights_refuse_the_call_in_a_batch_as_alone(solver):
    # The rule of every door (`wavg::check_weight_rows`): weights that do not sum to 1
    # refuse the request, naming the first bad row counting from 1; only rows without an
    # answer are `ok` False.
    k = solver.anchor_count
    W = np.full((3, k), 1 / k)
    W[1] *= 0.6
    with pytest.raises(ValueError, match=r"W row 2: weights sum to 0\.6"):
        solver.forward(W)
    with pytest.raises(ValueError, match=r"W: weights sum to 0\.6"):
        solver.forward(W[1])
    W[1, 1] = np.nan
    with pytest.raises(ValueError, match="W row 2: weight 2 is not finite"):
        solver.forward(W)
    assert list(solver.forward(np.full((2, k), 1 / k)).ok) == [True, True]


def test_inverse_paper_weights(solver, surface):
    faces, bary = surface.vertex_points(np.arange(0, surface.vertex_count, 7))
    W, ok = solver.inverse(faces, bary, verified=False)
    assert np.allclose(W[ok].sum(axis=1), 1.0)


def test_verified_inverse_rows_not_ok_are_nan(surface):
    # Three anchors do not reach most of a torus: those rows have no weights (NaN rows,
    # as `wavg inverse --verified` prints `none not-reached`), though the paper's weights
    # exist there.
    sol = wavg.Solver(surface, surface.spread_anchors(3, seed=0))
    faces, bary = surface.sample_points(2000, seed=1)
    W, ok = sol.inverse(faces, bary)
    assert 0 < (~ok).sum() < len(ok)
    assert np.isnan(W[~ok]).all() and np.isfinite(W[ok]).all()
    paper, paper_ok = sol.inverse(faces, bary, verified=False)
    assert paper_ok.all() and np.isfinite(paper[~ok]).all()


def test_inverse_into_out(solver, surface):
    faces, bary = surface.vertex_points(np.arange(0, surface.vertex_count, 5))
    k, q = solver.anchor_count, len(faces)
    for verified in (False, True):
        want, want_ok = solver.inverse(faces, bary, verified=verified)
        out = np.full((q, k), 7.0)
        W, ok = solver.inverse(faces, bary, verified=verified, out=out)
        assert W is out and np.array_equal(W, want, equal_nan=True) and np.array_equal(ok, want_ok)
    for bad, err in (
        (np.zeros((q, k), np.float32), TypeError),
        (np.zeros((q + 1, k)), ValueError),
        (np.zeros((k, q)).T, ValueError),
        ([[0.0] * k] * q, TypeError),
    ):
        with pytest.raises(err, match="out must be"):
            solver.inverse(faces, bary, out=bad)
    ro = np.zeros((q, k))
    ro.flags.writeable = False
    with pytest.raises(ValueError, match="out"):
        solver.inverse(faces, bary, out=ro)


def test_point_anchors_equal_vertex_anchors(surface, anchors, solver):
    faces, bary = surface.vertex_points(anchors)
    s2 = wavg.Solver(surface, (faces, bary))
    W = random_weights(np.random.default_rng(4), 100, len(anchors))
    assert np.allclose(s2.forward(W).xyz, solver.forward(W).xyz, atol=1e-12)


def test_set_anchor(surface, anchors):
    s = wavg.Solver(surface, anchors)
    s.set_anchor(0, 3)
    e = np.zeros(len(anchors))
    e[0] = 1
    assert np.allclose(s.forward(e).xyz, surface.vertices[3], atol=1e-9)
    f, b = surface.vertex_points([7])
    s.set_anchor(1, (int(f[0]), b[0]))
    e = np.roll(e, 1)
    assert np.allclose(s.forward(e).xyz, surface.vertices[7], atol=1e-9)
    assert s.anchor_count == len(anchors)


def test_pickle_and_deepcopy(surface, solver):
    W = random_weights(np.random.default_rng(5), 300, solver.anchor_count)
    ref = solver.forward(W)
    for s in (pickle.loads(pickle.dumps(solver)), copy.deepcopy(solver), copy.copy(solver)):
        out = s.forward(W)
        assert np.array_equal(out.xyz, ref.xyz) and np.array_equal(out.face, ref.face)
    S2 = pickle.loads(pickle.dumps(surface))
    assert np.array_equal(S2.embedding, surface.embedding)
    assert np.array_equal(S2.faces, surface.faces)


def test_copies_keep_the_embedding_the_solver_was_made_with(torus_mesh, anchors):
    S = wavg.Surface(*torus_mesh)  # the 3-D positions as the embedding
    sol = wavg.Solver(S, anchors)
    W = random_weights(np.random.default_rng(8), 50, sol.anchor_count)
    ref = sol.forward(W)
    S.precompute(landmarks=60, progress=False)  # the surface moves on; the solver does not
    for s in (pickle.loads(pickle.dumps(sol)), copy.copy(sol), copy.deepcopy(sol)):
        out = s.forward(W)
        assert np.array_equal(out.face, ref.face) and np.array_equal(out.xyz, ref.xyz)
    assert not np.array_equal(wavg.Solver(S, anchors).forward(W).xyz, ref.xyz)
    # Their surfaces are the one the solver was made from (no embedding then).
    assert not copy.deepcopy(sol).surface.has_embedding
    assert not pickle.loads(pickle.dumps(sol)).surface.has_embedding


def test_integer_and_thread_arguments_are_checked_by_name(surface, solver):
    W = random_weights(np.random.default_rng(9), 3, solver.anchor_count)
    for bad in (0, -1, 10**6, 2**70):
        with pytest.raises(ValueError, match="threads"):
            solver.forward(W, threads=bad)
    with pytest.raises(ValueError, match="n must be"):
        surface.sample_points(10**9)
    with pytest.raises(ValueError, match="n must be"):
        surface.sample_points(-1)
    with pytest.raises(ValueError, match="seed"):
        surface.sample_points(3, seed=-1)
    with pytest.raises(ValueError, match="k must be"):
        surface.spread_anchors(-1)
    with pytest.raises(ValueError, match="k must be"):
        surface.spread_anchors(surface.vertex_count + 1)
    with pytest.raises(ValueError, match="landmarks"):
        surface.precompute(landmarks=2**70, progress=False)
    with pytest.raises(ValueError, match="seed"):
        surface.precompute(seed=-1, progress=False)
    with pytest.raises(TypeError, match="n"):
        surface.sample_points(2.5)
    with pytest.raises(ValueError, match="i must be"):
        wavg.Solver(surface, solver.anchor_points).set_anchor(99, 3)
    f, b = surface.sample_points(5, seed=2**64 - 1)
    assert f.shape == (5,) and b.shape == (5, 3)
    for bad in (True, 1.5, np.float64(2.0), "2"):
        with pytest.raises(TypeError, match="threads"):
            solver.forward(W, threads=bad)
    anchors = solver.anchor_points
    with pytest.raises(ValueError, match="samples"):
        wavg.spline(surface, anchors, samples=2**70)
    with pytest.raises(TypeError, match="degree"):
        wavg.spline(surface, anchors, degree=2.0)
    with pytest.raises(ValueError, match="width"):
        wavg.render(surface, size=(2**70, 10))
    s = wavg.Solver(surface, anchors)
    with pytest.raises(ValueError, match="i must be"):
        s.set_anchor(2**70, 3)
    with pytest.raises(ValueError, match="vertex_or_point"):
        s.set_anchor(0, 2**70)


def _forward_in_worker(args):
    solver, W = args
    return solver.forward(W).xyz


@pytest.mark.parametrize("start", ["fork", "spawn"])
def test_pickle_through_process_pool(solver, start):
    W = random_weights(np.random.default_rng(6), 200, solver.anchor_count)
    ref = solver.forward(W).xyz  # the parent's thread pool runs before any fork
    ctx = multiprocessing.get_context(start)
    with ProcessPoolExecutor(max_workers=2, mp_context=ctx) as pool:
        outs = list(pool.map(_forward_in_worker, [(solver, W[:100]), (solver, W[100:])]))
    assert np.array_equal(np.vstack(outs), ref)


def test_one_off_functions(torus_mesh, anchors):
    V, F = torus_mesh
    S = wavg.Surface(V, F)
    S.precompute(progress=False)
    sol = wavg.Solver(S, anchors)
    W = random_weights(np.random.default_rng(7), 20, len(anchors))
    P = wavg.weighted_average(V, F, anchors, W)
    assert np.array_equal(P.xyz, sol.forward(W).xyz)
    W2, ok = wavg.barycentric_weights(V, F, anchors, P.face, P.bary)
    W3, ok3 = sol.inverse(P.face, P.bary)
    assert np.array_equal(W2, W3) and np.array_equal(ok, ok3)


def test_help_shows_shapes():
    doc = wavg.Solver.forward.__doc__
    assert "(q, k)" in doc and "float64" in doc and "bool" in doc
    assert "(q, 3)" in wavg.Solver.inverse.__doc__ or "(q, k)" in wavg.Solver.inverse.__doc__
