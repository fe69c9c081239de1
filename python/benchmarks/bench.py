"""Targets of the Python package, measured against the CLI in the same run.

    python python/benchmarks/bench.py [--mesh meshes/armadillo.obj.gz] [--anchors 93] [--queries 100000]
                           [--threads 2] [--wheel target/wheels-release/wavg-*.whl]

Solver.forward / Solver.inverse (paper weights) on the N surface points and K anchors of
`wavg bench roundtrip` (S.sample_points, S.spread_anchors) on T threads, best of 3, against
`wavg bench roundtrip --json` (forward_us / inverse_us) on the same embedding, in
interleaved rounds (medians compared); the time of
`import wavg` (best of 5 fresh interpreters); the wheel's size. Needs the `wavg` CLI
($WAVG_CLI or target/release/wavg or target/debug/wavg) and $WAVG_DATA_DIR.
"""

import argparse
import glob
import json
import os
import pathlib
import subprocess
import sys
import tempfile
import time

import numpy as np

import wavg

ROOT = pathlib.Path(__file__).resolve().parents[2]


def cli_path():
    for c in (os.environ.get("WAVG_CLI"), ROOT / "target/release/wavg", ROOT / "target/debug/wavg"):
        if c and pathlib.Path(c).is_file():
            return str(c)
    sys.exit("the wavg CLI is not built (cargo build --release -p wavg-cli), or set WAVG_CLI")


def best(f, repeat=3):
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        f()
        times.append(time.perf_counter() - t)
    return min(times)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--mesh", default="meshes/armadillo.obj.gz")
    ap.add_argument("--anchors", type=int, default=93)
    ap.add_argument("--queries", type=int, default=100_000)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--landmarks", type=int, default=1000)
    ap.add_argument("--wheel", default=None)
    ap.add_argument("--rounds", type=int, default=5, help="interleaved Python / CLI rounds (default 5)")
    a = ap.parse_args()
    data = pathlib.Path(os.environ.get("WAVG_DATA_DIR", ROOT.parent / "shared" / "data"))
    mesh = data / a.mesh
    cli = cli_path()
    with tempfile.TemporaryDirectory() as tmp:
        emb = pathlib.Path(tmp) / "m.wavg"
        S = wavg.Surface.open(mesh)
        t = time.perf_counter()
        S.precompute(landmarks=a.landmarks, progress=False)
        pre = time.perf_counter() - t
        S.save_embedding(emb)
        sol = wavg.Solver(S, S.spread_anchors(a.anchors, seed=0))
        # The CLI's points and anchors (its seed 0 draws points with seed 1): the same work.
        faces, bary = S.sample_points(a.queries, seed=1)
        W, ok = sol.inverse(faces, bary, verified=False, threads=a.threads)
        W_ok = np.ascontiguousarray(W[ok])  # selected once, outside the timed calls
        # Interleaved rounds: each round times Python once (best of 3) and the CLI once, so
        # both sides see the same machine; the medians are compared.
        out = np.empty_like(W)
        rounds = []
        for _ in range(a.rounds):
            t_inv = best(lambda: sol.inverse(faces, bary, verified=False, threads=a.threads))
            t_out = best(lambda: sol.inverse(faces, bary, verified=False, threads=a.threads, out=out))
            t_fwd = best(lambda: sol.forward(W_ok, threads=a.threads))
            r = subprocess.run([cli, "bench", "roundtrip", "--mesh", str(mesh), "--embedding", str(emb),
                                "--anchors", str(a.anchors), "--queries", str(a.queries),
                                "--threads", str(a.threads), "--json"],
                               check=True, capture_output=True, text=True)
            ref = json.loads(r.stdout)
            q_us = a.queries / 1e6
            rounds.append((t_inv / q_us, ref["inverse_us"], t_fwd / ok.sum() * 1e6, ref["forward_us"], t_out / q_us, ref["inverse_us"]))
    med = np.median(np.array(rounds), axis=0)
    py_inv, cli_inv, py_fwd, cli_fwd, py_out, _ = med
    imports = []
    for _ in range(5):
        out = subprocess.run([sys.executable, "-c", "import time; t = time.perf_counter(); import wavg; "
                              "print(time.perf_counter() - t)"], capture_output=True, text=True, check=True)
        imports.append(float(out.stdout))
    wheels = glob.glob(a.wheel) if a.wheel else sorted(glob.glob(str(ROOT / "target/wheels*/wavg-*.whl")))
    print(f"mesh {a.mesh}: {S.vertex_count} vertices, precompute {pre:.1f} s; "
          f"{a.anchors} anchors, {a.queries} queries, {a.threads} threads")
    print(f"medians of {a.rounds} interleaved rounds (ratio range over the rounds in brackets)")
    print(f"{'':28}{'python us':>10}{'cli us':>10}{'ratio':>8}  target")
    for name, p, c, i in (("Solver.inverse (paper)", py_inv, cli_inv, 0), ("Solver.inverse (paper, out=)", py_out, cli_inv, 4),
                          ("Solver.forward", py_fwd, cli_fwd, 2)):
        per = [r[i] / r[i + 1] for r in rounds]
        print(f"{name:28}{p:10.3f}{c:10.3f}{p / c:8.3f}  <= 1.15  ({min(per):.2f}-{max(per):.2f})")
    print(f"{'import wavg (best of 5)':28}{min(imports):10.3f} s{'':8}  <= 0.3 s")
    for w in wheels:
        print(f"wheel {pathlib.Path(w).parent.name}/{pathlib.Path(w).name}: "
              f"{os.path.getsize(w) / 2**20:.1f} MB  (<= 15 MB)")


if __name__ == "__main__":
    main()
