"""Benchmarks of wavg.batch (issue targets and the figures of docs/scaling.md).

    python python/benchmarks/bench_batch.py                 # everything (about 10 minutes on 2 cores)
    python python/benchmarks/bench_batch.py --only engine   # one part: engine, kills, overhead, costs

* engine: 16 precomputes of 20k-vertex meshes (1000 landmarks, one thread each) on a Dask
  LocalCluster of 2 single-thread worker processes and on a ProcessPoolExecutor(2),
  alternated ``--rounds`` times in one run; prints each wall time and the ratio.
* kills: ``--kill-runs`` runs of 16 small precomputes on the LocalCluster, each with a
  random worker SIGKILLed after a random number of finished jobs; counts lost outputs
  (an input without its output), duplicated ones (files not belonging to exactly one
  input), leftovers (temporary files), jobs not ``done`` and outputs differing from a
  serial run.
* overhead: per-task cost of the engine: 1000 no-op tasks through Dask and through the
  process pool, and a rerun of 200 skipped jobs (fingerprint check included).
* costs: one asset's precompute (20k vertices), correspondence (20k onto 20k vertices) and
  texture transfer at 2048^2, each on one thread.
"""

from __future__ import annotations

import argparse
import concurrent.futures as cf
import multiprocessing
import os
import random
import shutil
import signal
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

# The tests' fixtures; `wavg` is the installed package.
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
import batch_fixtures as bf  # noqa: E402

import wavg  # noqa: E402
import wavg.batch as wb  # noqa: E402
from wavg.batch import store  # noqa: E402


def make_meshes(folder: Path, count: int, n: int) -> list[str]:
    """``count`` varied meshes of about ``n`` vertices: sheets and spheres of four shapes."""
    folder.mkdir(parents=True, exist_ok=True)
    side = int(round(n**0.5))
    lat = int(round((n / 2) ** 0.5))
    out = []
    for i in range(count):
        kind = i % 4
        if kind == 0:
            v, f, uv = bf.sheet(side, side, "bump", 0.2 + 0.05 * i)
        elif kind == 1:
            v, f, uv = bf.sheet(side + 3, side - 3, "wave", 0.1 + 0.02 * i)
        elif kind == 2:
            (v, f), uv = bf.sphere(lat, 2 * lat, (1.0, 1.0 + 0.05 * i, 0.8)), None
        else:
            (v, f), uv = bf.sphere(lat, 2 * lat, noise=0.02, seed=i), None
        out.append(str(bf.write_obj(folder / f"m{i:02d}.obj", v, f, uv)))
    return out


def local_cluster(n: int, profile: bool = True):
    import dask
    from distributed import Client, LocalCluster

    with dask.config.set({"distributed.worker.profile.enabled": profile}):
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None)
    return cluster, Client(cluster)


def engine(tmp: Path, rounds: int, vertices: int, profile: bool) -> None:
    meshes = make_meshes(tmp / "m20k", 16, vertices)
    verts = [wavg.read_mesh(m)[0].shape[0] for m in meshes]
    print(f"engine: 16 meshes, {min(verts)}-{max(verts)} vertices, 1000 landmarks, 1 thread per job, Dask profiler {'on' if profile else 'off'}")
    cluster, client = local_cluster(2, profile)
    pool = cf.ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("spawn"))
    pool.submit(int).result()  # start the pool's processes outside the timing
    ratios = []
    try:
        for r in range(rounds):
            times, busy, cpu = {}, {}, {}
            for name, ex in (("dask", client), ("pool", pool)) if r % 2 == 0 else (("pool", pool), ("dask", client)):
                out = tmp / f"engine-{name}-{r}"
                t0 = time.perf_counter()
                m = wb.precompute_all(meshes, out, ex)
                times[name] = time.perf_counter() - t0
                busy[name] = sum(j["seconds"] for j in m)
                cpu[name] = sum(j["cpu_seconds"] for j in m)
                assert m.counts["done"] == 16, m.failed
                shutil.rmtree(out)
            ratios.append(times["dask"] / times["pool"])
            print(
                f"  round {r}: LocalCluster {times['dask']:.1f} s, ProcessPool {times['pool']:.1f} s, ratio {ratios[-1]:.3f}; "
                f"job seconds summed {busy['dask']:.1f} / {busy['pool']:.1f}, CPU {cpu['dask']:.1f} / {cpu['pool']:.1f}; "
                f"engine overhead (wall - job seconds / 2) {times['dask'] - busy['dask'] / 2:.1f} / {times['pool'] - busy['pool'] / 2:.1f} s"
            )
        print(f"engine ratio (Dask / pool): median {np.median(ratios):.3f}, range {min(ratios):.3f}-{max(ratios):.3f}")
    finally:
        pool.shutdown()
        client.close()
        cluster.close()


def kills(tmp: Path, runs: int, seed: int) -> None:
    rng = random.Random(seed)
    meshes = make_meshes(tmp / "m2k", 16, 2500)
    ref = wb.precompute_all(meshes, tmp / "kill-ref", landmarks=200)
    reference = {Path(j["output"]).name: wavg.Surface.open(j["input"], embedding=j["output"]).embedding for j in ref}
    source = {Path(j["output"]).name: j["input"] for j in ref}
    cluster, client = local_cluster(2)
    lost = dup = leftovers = not_done = differ = killed = resubmitted = 0
    t0 = time.perf_counter()
    try:
        for run in range(runs):
            out = tmp / f"kill-{run}"
            when = rng.randint(0, 12)
            state: dict[str, object] = {}

            def progress(finished: int, total: int, failed: int) -> None:
                if finished == when and "pid" not in state:
                    pids = client.run(os.getpid)
                    busy = [pids[w] for w, keys in client.processing().items() if keys and w in pids]
                    victim = rng.choice(busy or list(pids.values()))
                    os.kill(victim, signal.SIGKILL)
                    state["pid"] = victim

            m = wb.precompute_all(meshes, out, client, landmarks=200, progress=progress)
            killed += "pid" in state
            not_done += sum(j["status"] != "done" for j in m)
            resubmitted += sum(j["attempts"] > 1 for j in m)
            expected = {Path(j["output"]).name for j in ref}
            names = {p.name for p in out.iterdir()}
            leftovers += sum(store.TMP_MARK in n for n in names)
            lost += len(expected - names)
            extra = names - expected - {n + store.SIDECAR for n in expected} - {"manifest.json"}
            dup += len([n for n in extra if store.TMP_MARK not in n]) + (len(m) - len({j["output"] for j in m}))
            for n in expected & names:
                emb = wavg.Surface.open(source[n], embedding=str(out / n)).embedding
                differ += not np.array_equal(emb, reference[n])
            client.wait_for_workers(2, timeout=120)
            shutil.rmtree(out)
    finally:
        client.close()
        cluster.close()
    print(
        f"kills: {runs} runs x 16 jobs, {killed} workers killed, {resubmitted} jobs resubmitted by the driver; "
        f"lost {lost}, duplicated {dup}, temporary files left {leftovers}, not done {not_done}, "
        f"differing from serial {differ} ({time.perf_counter() - t0:.0f} s)"
    )


def noop(x: int) -> int:
    return x


def overhead(tmp: Path) -> None:
    n = 1000
    cluster, client = local_cluster(2)
    pool = cf.ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("spawn"))
    try:
        client.submit(noop, -1).result()
        pool.submit(noop, -1).result()
        for name, ex in (("dask", client), ("pool", pool)):
            t0 = time.perf_counter()
            futs = [ex.submit(noop, i, **({"pure": False} if name == "dask" else {})) for i in range(n)]
            if name == "dask":
                client.gather(futs)
            else:
                [f.result() for f in futs]
            dt = time.perf_counter() - t0
            print(f"overhead: {n} no-op tasks via {name}: {dt / n * 1e3:.2f} ms per task (2 workers)")
        meshes = make_meshes(tmp / "m200", 200, 300)
        out = tmp / "overhead-skip"
        wb.precompute_all(meshes, out, client, landmarks=50)
        for name, ex in (("dask", client), ("pool", pool), ("in-process", None)):
            t0 = time.perf_counter()  # a rerun: every job is a skip
            m = wb.precompute_all(meshes, out, ex, landmarks=50)
            dt = time.perf_counter() - t0
            assert m.counts["skipped"] == 200, m.counts
            print(f"overhead: 200 skipped jobs via {name}: {dt / 200 * 1e3:.2f} ms per job (fingerprint check, manifest)")
    finally:
        pool.shutdown()
        client.close()
        cluster.close()


def costs(tmp: Path) -> None:
    folder = tmp / "costs"
    folder.mkdir(parents=True, exist_ok=True)
    side = 141
    t_v, t_f, t_uv = bf.sheet(side, side, "bump", 0.3)
    d_v, d_f, d_uv = bf.sheet(side, side, "wave", 0.2)
    tmpl = bf.write_obj(folder / "template.obj", t_v, t_f, t_uv)
    targ = bf.write_obj(folder / "target.obj", d_v, d_f, d_uv)
    anchors = [bf.sheet_anchors(folder / f"{n}.txt", side, side) for n in ("ta", "da")]
    tex = folder / "tex.png"
    wavg.save_png(str(tex), bf.checker(512, 16))
    emb = wb.precompute_all([tmpl, targ], folder / "emb")
    for j in emb:
        print(f"cost: precompute {j['vertices']} vertices, 1000 landmarks, 1 thread: {j['seconds']:.2f} s wall, {j['cpu_seconds']:.2f} s CPU")
    co = wb.correspond_all((tmpl, emb[0]["output"]), anchors[0], [(targ, anchors[1], emb[1]["output"])], folder / "co")
    j = co[0]
    print(f"cost: correspond {j['vertices']} onto {len(d_v)} vertices, 1 thread: {j['seconds']:.2f} s wall, {j['cpu_seconds']:.2f} s CPU ({j['map_seconds']:.2f} s map), valid {j['valid_fraction']:.3f}")
    tr = wb.transfer_all((tmpl, emb[0]["output"]), tex, anchors[0], [(targ, anchors[1], emb[1]["output"])], folder / "tr", size=2048)
    j = tr[0]
    print(f"cost: transfer 2048^2, 1 thread: {j['seconds']:.2f} s wall, {j['cpu_seconds']:.2f} s CPU ({j['transfer_seconds']:.2f} s transfer), {j['texels_per_s']:.0f} texels/s, valid {j['valid_fraction']:.3f}")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--only", choices=("engine", "kills", "overhead", "costs"))
    p.add_argument("--rounds", type=int, default=2, help="Alternated Dask/pool rounds of the engine part (default 2)")
    p.add_argument("--kill-runs", type=int, default=20)
    p.add_argument("--no-profile", action="store_true", help="Turn off the Dask workers' statistical profiler")
    p.add_argument("--engine-vertices", type=int, default=20000, help="Vertices per mesh of the engine part (default 20000)")
    p.add_argument("--seed", type=int, default=0)
    args = p.parse_args()
    print(f"wavg {store.package_version()}, {os.cpu_count()} CPUs, {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}")
    with tempfile.TemporaryDirectory(prefix="wavg-bench-batch-") as d:
        tmp = Path(d)
        for part in ("costs", "overhead", "engine", "kills"):
            if args.only in (None, part):
                {"costs": lambda: costs(tmp), "overhead": lambda: overhead(tmp), "engine": lambda: engine(tmp, args.rounds, args.engine_vertices, not args.no_profile),
                 "kills": lambda: kills(tmp, args.kill_runs, args.seed)}[part]()  # fmt: skip
                sys.stdout.flush()


if __name__ == "__main__":
    main()
