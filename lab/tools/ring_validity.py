#!/usr/bin/env python3
"""Judges a pose pair's map with validity tests at the scale of a vertex's k-ring.

A benchmark tool, not part of the build (needs numpy). For each source vertex it fits an
affine map from its k-ring's source positions (in the ring's tangent plane, oriented like
the source normal) to their images, and tests: the vertex's image against the fit
(`resid`, within TAU mapped edge lengths), the fit's orientation against the ground
truth's vertex normal (`orient`), and its singular values within 4x of the map's median
edge-length ratio (`stretch`). Prints, per test, the fraction kept, the mean error of the
kept vertices (fraction of the target's bounding-box diagonal), how many vertices with an
error above 2% it rejects, and how many below 1% it rejects.

    python3 lab/tools/ring_validity.py SOURCE.obj.gz TARGET.obj.gz MAP.txt

MAP.txt: `wavg correspond ... --validity paper --max-negative -100` (every answered vertex).
"""
import gzip
import sys

import numpy as np


def load_obj(path):
    verts, faces = [], []
    with gzip.open(path, "rt") as f:
        for line in f:
            p = line.split()
            if not p:
                continue
            if p[0] == "v":
                verts.append(list(map(float, p[1:4])))
            elif p[0] == "f":
                faces.append([int(x.split("/")[0]) - 1 for x in p[1:4]])
    return np.array(verts), np.array(faces)


def vertex_normals(x, faces):
    fn = np.cross(x[faces[:, 1]] - x[faces[:, 0]], x[faces[:, 2]] - x[faces[:, 0]])
    vn = np.zeros_like(x)
    for k in range(3):
        np.add.at(vn, faces[:, k], fn)
    return vn


def main():
    src, faces = load_obj(sys.argv[1])
    tgt, _ = load_obj(sys.argv[2])
    lines = open(sys.argv[3]).read().split("\n")
    n = len(src)
    img = np.full((n, 3), np.nan)
    ok = np.zeros(n, bool)
    for i in range(n):
        p = lines[i].split()
        if p[0] != "none":
            img[i] = list(map(float, p[4:7]))
            ok[i] = True
    diag = np.linalg.norm(tgt.max(0) - tgt.min(0))
    err = np.linalg.norm(img - tgt, axis=1) / diag
    nb = [set() for _ in range(n)]
    for a, b, c in faces:
        nb[a] |= {b, c}
        nb[b] |= {a, c}
        nb[c] |= {a, b}
    tn, sn = vertex_normals(tgt, faces), vertex_normals(src, faces)
    e = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    ratio = np.linalg.norm(img[e[:, 0]] - img[e[:, 1]], axis=1) / np.linalg.norm(
        src[e[:, 0]] - src[e[:, 1]], axis=1
    )
    scale = np.nanmedian(ratio)

    def tests(v, tau, rings):
        if not ok[v]:
            return (False, False, False)
        ring, front = {v}, {v}
        for _ in range(rings):
            front = set().union(*[nb[u] for u in front]) - ring
            ring |= front
        ring = [u for u in ring if ok[u] and u != v]
        if len(ring) < 4:
            return (True, True, True)
        s, m = src[ring], img[ring]
        sc, mc = s.mean(0), m.mean(0)
        basis = np.linalg.svd(s - sc, full_matrices=False)[2][:2].T.copy()
        if np.dot(np.cross(basis[:, 0], basis[:, 1]), sn[v]) < 0:
            basis[:, 1] *= -1
        a = np.linalg.lstsq((s - sc) @ basis, m - mc, rcond=None)[0]
        pred = ((src[v] - sc) @ basis) @ a + mc
        edge = np.mean([np.linalg.norm(img[u] - img[v]) for u in nb[v] if ok[u]] or [1e9])
        sv = np.linalg.svd(a, compute_uv=False)
        return (
            np.linalg.norm(img[v] - pred) <= tau * edge,
            np.dot(np.cross(a[0], a[1]), tn[v]) > 0,
            sv.max() < 4 * scale and sv.min() > scale / 4,
        )

    big = err > 0.02
    for tau in (2.0,):
        for rings in (1, 2, 3):
            t = np.array([tests(v, tau, rings) for v in range(n)])
            for name, kept in [
                ("resid", t[:, 0]),
                ("orient", t[:, 1]),
                ("stretch", t[:, 2]),
                ("all", t.all(1)),
            ]:
                kept = kept & ok
                print(
                    f"tau {tau} rings {rings} {name:8s}: kept {kept.mean():.3f} "
                    f"mean error {err[kept].mean():.4f} rejected >2%: {(big & ~kept).sum()}/"
                    f"{(big & ok).sum()} rejected <1%: {((err < 0.01) & ~kept).sum()}"
                )


if __name__ == "__main__":
    main()
