"""Worker processes answer as the parent does: the children of `concurrent.futures` and
`multiprocessing.Pool` with each start method (fork, forkserver, spawn), joblib's workers
(when installed) and Dask's worker processes, after the parent has used every threaded
call. A pickled `Solver` travels to each; every wait has a timeout, so a hang fails the
test instead of stopping the suite."""

import concurrent.futures as cf
import contextlib
import multiprocessing

import numpy as np
import pytest

import wavg
from conftest import random_weights, torus

TIMEOUT = 120
METHODS = [m for m in ("fork", "forkserver", "spawn") if m in multiprocessing.get_all_start_methods()]


def answers(sol, W, faces, bary):
    """Every threaded call of the package on `sol`'s surface, on all cores and on 2
    threads: the arrays they return, in order."""
    S = sol.surface
    out = []
    for threads in (None, 2):
        P = sol.forward(W, threads=threads)
        out += [P.face, P.bary, P.xyz, P.ok]
        out += list(sol.inverse(faces, bary, threads=threads))
        out += list(sol.inverse(faces, bary, verified=False, threads=threads))
        out += [wavg.spline(S, sol.anchor_points, samples=50, threads=threads).xyz]
        uv = np.linspace(0, 1, 2 * sol.anchor_count).reshape(-1, 2)
        out += list(wavg.decal(S, sol.anchor_points, uv, threads=threads))
        c = wavg.correspond(S, S, sol.anchor_points, sol.anchor_points, threads=threads)
        out += [c.face, c.bary, c.valid]
        tex = np.arange(16 * 16 * 4, dtype=np.uint8).reshape(16, 16, 4)
        out += [wavg.transfer_texture(S, tex, S, sol.anchor_points, sol.anchor_points,
                                      size=(16, 16), threads=threads)]
    out += [S.vertex_points(np.arange(50))[1], *S.sample_points(500, seed=3),
            S.spread_anchors(6, seed=2)]
    small = wavg.Surface(*torus(30, 12))
    for threads in (None, 2):
        small.precompute(landmarks=60, progress=False, threads=threads)
        out.append(small.embedding)
    r = wavg.Remesher(small, small.vertices[[0, 90, 200, 150]], [[0, 1, 2], [0, 2, 3]], levels=1, smooth=1)
    out.append(r.run()[0])
    out.append(wavg.render(S, size=(40, 30), points=S.vertices[:5]))
    return out


@pytest.fixture(scope="module")
def job():
    """A solver on a mesh large enough for the batches and the projector's set-up to run
    in parallel (a small one stays on the calling thread and would not meet a dead pool),
    its queries, and the answers of the parent, which thereby used every threaded call."""
    V, F = torus(160, 64)
    ang = np.stack([np.arctan2(V[:, 1], V[:, 0]), np.arctan2(V[:, 2], np.hypot(V[:, 0], V[:, 1]) - 1)], -1)
    S = wavg.Surface(V, F, uv=(ang[F] / (2 * np.pi)) % 1.0)
    S.precompute(landmarks=120, progress=False)
    sol = wavg.Solver(S, S.spread_anchors(10, seed=1))
    rng = np.random.default_rng(5)
    W = random_weights(rng, 3000, sol.anchor_count)
    faces, bary = S.sample_points(3000, seed=4)
    args = (sol, W, faces, bary)
    return args, answers(*args)


def assert_same(got, want):
    assert len(got) == len(want)
    for i, (g, w) in enumerate(zip(got, want)):
        assert np.array_equal(g, w, equal_nan=g.dtype.kind == "f"), f"answer {i} differs"


@contextlib.contextmanager
def killed_on_exit(executor):
    """`executor`, whose worker processes are killed on leaving (a hung worker would make
    the usual shutdown wait forever)."""
    try:
        yield executor
    finally:
        for p in list((getattr(executor, "_processes", None) or {}).values()):
            p.kill()
        executor.shutdown(wait=False, cancel_futures=True)


@pytest.mark.parametrize("method", METHODS)
def test_process_pool_executor(job, method):
    args, want = job
    ctx = multiprocessing.get_context(method)
    with killed_on_exit(cf.ProcessPoolExecutor(2, mp_context=ctx)) as ex:
        futures = [ex.submit(answers, *args) for _ in range(2)]
        for f in futures:
            assert_same(f.result(timeout=TIMEOUT), want)


@pytest.mark.parametrize("method", METHODS)
def test_multiprocessing_pool(job, method):
    args, want = job
    pool = multiprocessing.get_context(method).Pool(2)
    try:
        results = [pool.apply_async(answers, args) for _ in range(2)]
        for r in results:
            assert_same(r.get(timeout=TIMEOUT), want)
    finally:
        pool.terminate()
        pool.join()


@pytest.mark.parametrize("backend", ["loky", "multiprocessing"])
def test_joblib(job, backend):
    joblib = pytest.importorskip("joblib")
    args, want = job
    with joblib.Parallel(n_jobs=2, backend=backend, timeout=TIMEOUT) as parallel:
        for got in parallel(joblib.delayed(answers)(*args) for _ in range(2)):
            assert_same(got, want)


def test_dask_worker_processes(job):
    distributed = pytest.importorskip("distributed")
    args, want = job
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        futures = [client.submit(answers, *args, pure=False) for _ in range(2)]
        for f in futures:
            assert_same(f.result(timeout=TIMEOUT), want)
