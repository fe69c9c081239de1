"""Whole-process behaviour: no leak over large batches, Ctrl-C stops a precompute,
`import wavg` stays light, `wavg.__version__` is the crate's."""

import importlib.metadata
import os
import re
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

import wavg
from conftest import ROOT, random_weights


def _rss_mb():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20


@pytest.mark.skipif(not os.path.exists("/proc/self/statm"), reason="needs /proc")
def test_forward_batches_do_not_leak(surface):
    sol = wavg.Solver(surface, surface.spread_anchors(6, seed=1))
    W = random_weights(np.random.default_rng(0), 400_000, 6)
    rss = []
    for _ in range(12):
        P = sol.forward(W)
        assert P.ok.mean() > 0.99
        del P
        rss.append(_rss_mb())
    # After warm-up the resident size stays flat (a leak of the 4*10^5 results would add
    # about 24 MB per repetition: 7 repetitions, 168 MB).
    assert max(rss[5:]) - rss[4] < 40, rss


def test_version_is_the_workspace_version():
    cargo = (ROOT / "Cargo.toml").read_text()
    want = re.search(r'^\[workspace\.package\]$[^\[]*?^version = "([^"]+)"$', cargo, re.M).group(1)
    assert wavg.__version__ == want
    assert wavg._wavg.__version__ == want == importlib.metadata.version("wavg")


IMPORT_ONLY = "import sys, time; t = time.perf_counter(); import wavg; print(time.perf_counter() - t); print('dask' in sys.modules)"


def test_import_is_light():
    out = subprocess.run([sys.executable, "-c", IMPORT_ONLY], capture_output=True, text=True,
                         check=True).stdout.split()
    assert out[1] == "False"  # wavg.batch (Dask) is imported only on first use
    assert float(out[0]) < 2.0  # generous here; python/benchmarks/bench.py measures the 0.3 s target


CHILD = textwrap.dedent("""
    import sys, wavg
    from conftest import torus
    S = wavg.Surface(*torus(300, 150))
    print("start", flush=True)
    try:
        S.precompute(landmarks=1000, progress=False)
    except KeyboardInterrupt:
        print("interrupted", S.embedding is None, flush=True)
        sys.exit(3)
    print("finished", flush=True)
""")


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")
def test_ctrl_c_interrupts_precompute():
    p = subprocess.Popen([sys.executable, "-c", CHILD], stdout=subprocess.PIPE, text=True,
                         cwd=os.path.dirname(__file__))
    assert p.stdout.readline().strip() == "start"
    time.sleep(1.0)
    t = time.monotonic()
    p.send_signal(signal.SIGINT)
    out, _ = p.communicate(timeout=60)
    waited = time.monotonic() - t
    if "finished" in out:
        pytest.skip("the precompute finished before the signal")
    assert p.returncode == 3 and "interrupted True" in out, out
    assert waited < 1.5, waited


@pytest.mark.parametrize("at", ["decimate", "geodesics", "mds"])
def test_cancel_is_seen_at_once_in_every_stage(at):
    # Like Blender's Esc: another thread asks to stop and the callable answers False the
    # next time it is called. It is called at every poll, also while the progress stands
    # still (the end of the geodesics, about a second here, overlaps a sparse
    # factorization), and the call returns without waiting for the worker's next checkpoint.
    import threading

    from conftest import torus

    S = wavg.Surface(*torus(240, 120))
    stop = threading.Event()
    asked = []

    def ask():
        asked.append(time.monotonic())
        stop.set()

    def progress(stage, done, total):
        if stage == at and not asked and (at != "geodesics" or done == total):
            threading.Timer(0.05, ask).start()
        return not stop.is_set()

    with pytest.raises(wavg.CancelledError):
        S.precompute(landmarks=600, progress=progress)
    waited = time.monotonic() - asked[0]
    assert S.embedding is None
    assert waited < 0.5, waited


def test_the_callable_sees_every_stage_in_order():
    # However short a stage, the callable is called for it: a small mesh passes through
    # some stages between two polls.
    from conftest import torus

    calls = []
    S = wavg.Surface(*torus(40, 20))
    S.precompute(landmarks=100, progress=lambda *a: calls.append(a))
    stages = [s for i, (s, _, _) in enumerate(calls) if i == 0 or calls[i - 1][0] != s]
    assert stages == ["decimate", "geodesics", "mds", "lsmesh", "quality"], calls
    assert all(0 <= d <= t for _, d, t in calls)
    assert calls[-1][1] == calls[-1][2], calls[-1]


OUT_OF_MEMORY = textwrap.dedent("""
    import wavg
    from conftest import torus
    S = wavg.Surface(*torus())
    try:
        S.precompute(landmarks=40, progress=False, cache=False)
    except wavg.OutOfMemoryError as e:
        assert isinstance(e, MemoryError) and isinstance(e, wavg.WavgError)
        print("refused:", e)
""")


def test_a_precompute_beyond_the_available_memory_raises_out_of_memory():
    # The environment override stands in for a small machine; the check runs before any work.
    env = dict(os.environ, WAVG_MEMORY_AVAILABLE="1M")
    out = subprocess.run([sys.executable, "-c", OUT_OF_MEMORY], capture_output=True, text=True,
                         env=env, cwd=os.path.dirname(__file__), check=True).stdout
    assert out.startswith("refused:") and "are available" in out, out
