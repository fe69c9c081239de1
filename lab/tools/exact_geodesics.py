#!/usr/bin/env python3
"""Checks a `.wavg` embedding against exact polyhedral geodesics (MMP).

A benchmark tool, not part of the build: it needs `pip install numpy pygeodesic`.

    python3 lab/tools/exact_geodesics.py MESH EMBEDDING.wavg [--sources 32] [--targets 32] [--seed 0] [--json]

For `sources x targets` seeded random vertex pairs it compares the embedding's Euclidean
distance d with the exact geodesic distance g and reports:

* `rel_err_p50`, `rel_err_p90`: quantiles of |d - g| / g over all pairs;
* `near_rel_err_p50`: the same over pairs closer than 10% of the bounding-box diagonal;
* `over_ratio_max`, `under_ratio_min`: the largest and smallest d / g;
* `collapsed_pairs`: pairs embedded closer than half their straight-line distance
  (d < |p - q| / 2), the sign of a folded extremity, with the worst of them.

MESH is OBJ or OFF, optionally gzipped (the readers here handle triangle meshes only).
"""

import argparse
import gzip
import json
import struct
import sys

import numpy as np
from pygeodesic import geodesic


def read_mesh(path):
    opener = gzip.open if path.endswith(".gz") else open
    with opener(path, "rt") as f:
        text = f.read()
    stem = path[:-3] if path.endswith(".gz") else path
    if stem.endswith(".off"):
        toks = text.split()
        if toks[0] != "OFF":
            sys.exit(f"{path}: not an OFF file")
        nv, nf = int(toks[1]), int(toks[2])
        at = 4
        pts = np.array(toks[at : at + 3 * nv], dtype=float).reshape(nv, 3)
        at += 3 * nv
        faces = []
        for _ in range(nf):
            n = int(toks[at])
            ids = [int(t) for t in toks[at + 1 : at + 1 + n]]
            faces += [[ids[0], ids[k], ids[k + 1]] for k in range(1, n - 1)]
            at += 1 + n
        return pts, np.array(faces, dtype=np.int32)
    pts, faces = [], []
    for line in text.splitlines():
        p = line.split()
        if not p:
            continue
        if p[0] == "v":
            pts.append([float(x) for x in p[1:4]])
        elif p[0] == "f":
            ids = [int(t.split("/")[0]) for t in p[1:]]
            ids = [i - 1 if i > 0 else len(pts) + i for i in ids]
            faces += [[ids[0], ids[k], ids[k + 1]] for k in range(1, len(ids) - 1)]
    return np.array(pts, dtype=float), np.array(faces, dtype=np.int32)


def read_wavg(path):
    with open(path, "rb") as f:
        data = f.read()
    if data[:8] != b"WAVGEMB\0":
        sys.exit(f"{path}: not a .wavg file")
    dim, nv = struct.unpack_from("<IQ", data, 12)
    coords = np.frombuffer(data, dtype="<f8", count=nv * dim, offset=128)
    return coords.reshape(nv, dim)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("mesh")
    ap.add_argument("embedding")
    ap.add_argument("--sources", type=int, default=32)
    ap.add_argument("--targets", type=int, default=32)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--json", action="store_true")
    a = ap.parse_args()

    pts, faces = read_mesh(a.mesh)
    emb = read_wavg(a.embedding)
    if emb.shape[0] != pts.shape[0]:
        sys.exit(f"the embedding has {emb.shape[0]} vertices, the mesh {pts.shape[0]}")
    diag = float(np.linalg.norm(pts.max(0) - pts.min(0)))
    rng = np.random.default_rng(a.seed)
    algo = geodesic.PyGeodesicAlgorithmExact(pts, faces)

    rows = []
    for s in rng.choice(len(pts), a.sources, replace=False):
        targets = rng.choice(len(pts), a.targets, replace=False)
        targets = targets[targets != s]
        g, _ = algo.geodesicDistances(np.array([s]), targets)
        for t, gt in zip(targets, g):
            if not np.isfinite(gt) or gt <= 0:
                continue
            d = float(np.linalg.norm(emb[s] - emb[t]))
            straight = float(np.linalg.norm(pts[s] - pts[t]))
            rows.append((int(s), int(t), float(gt), d, straight))
    if not rows:
        sys.exit("no connected pairs")
    g = np.array([r[2] for r in rows])
    d = np.array([r[3] for r in rows])
    straight = np.array([r[4] for r in rows])
    rel = np.abs(d - g) / g
    near = g < 0.1 * diag
    collapsed = d < 0.5 * straight
    worst = None
    if collapsed.any():
        i = int(np.argmin(np.where(collapsed, d / straight, np.inf)))
        worst = {"source": rows[i][0], "target": rows[i][1], "geodesic": rows[i][2],
                 "embedded": rows[i][3], "straight": rows[i][4]}
    report = {
        "pairs": len(rows),
        "rel_err_p50": float(np.quantile(rel, 0.5)),
        "rel_err_p90": float(np.quantile(rel, 0.9)),
        "near_pairs": int(near.sum()),
        "near_rel_err_p50": float(np.quantile(rel[near], 0.5)) if near.any() else None,
        "over_ratio_max": float((d / g).max()),
        "under_ratio_min": float((d / g).min()),
        "collapsed_pairs": int(collapsed.sum()),
        "worst_collapsed": worst,
    }
    if a.json:
        print(json.dumps(report))
    else:
        for k, v in report.items():
            print(f"{k:18} {v}")


if __name__ == "__main__":
    main()
