#!/usr/bin/env python3
"""Farthest-point anchors along mesh edges, as a `v VERTEX` anchors file.

A benchmark tool, not part of the build (standard library only). Starts at vertex 0 and
repeatedly adds the vertex farthest (Dijkstra over edge lengths) from those chosen, so the
same ids serve every mesh that shares the connectivity (pose pairs).

    python3 lab/tools/fps_anchors.py MESH.{obj,off}[.gz] K OUT.txt
"""
import gzip
import heapq
import math
import sys


def load_mesh(path):
    opener = gzip.open if path.endswith(".gz") else open
    verts, faces = [], []
    with opener(path, "rt") as f:
        if path.removesuffix(".gz").endswith(".off"):
            words = f.read().split()
            nv, nf = int(words[1]), int(words[2])
            at = 4
            for _ in range(nv):
                verts.append(tuple(map(float, words[at : at + 3])))
                at += 3
            for _ in range(nf):
                k = int(words[at])
                faces.append([int(x) for x in words[at + 1 : at + 1 + k]])
                at += 1 + k
            return verts, faces
        for line in f:
            p = line.split()
            if not p:
                continue
            if p[0] == "v":
                verts.append(tuple(map(float, p[1:4])))
            elif p[0] == "f":
                faces.append([int(x.split("/")[0]) - 1 for x in p[1:]])
    return verts, faces


def main():
    path, k, out = sys.argv[1], int(sys.argv[2]), sys.argv[3]
    verts, faces = load_mesh(path)
    adj = [dict() for _ in verts]
    for f in faces:
        for i in range(len(f)):
            a, b = f[i], f[(i + 1) % len(f)]
            d = math.dist(verts[a], verts[b])
            adj[a][b] = d
            adj[b][a] = d
    dist = [math.inf] * len(verts)

    def relax_from(s):
        dist[s] = 0.0
        heap = [(0.0, s)]
        while heap:
            d, u = heapq.heappop(heap)
            if d > dist[u]:
                continue
            for w, e in adj[u].items():
                if d + e < dist[w]:
                    dist[w] = d + e
                    heapq.heappush(heap, (d + e, w))

    chosen = [0]
    relax_from(0)
    while len(chosen) < k:
        far = max(range(len(verts)), key=lambda i: dist[i])
        chosen.append(far)
        relax_from(far)
    with open(out, "w") as f:
        f.writelines(f"v {a}\n" for a in chosen)


if __name__ == "__main__":
    main()
