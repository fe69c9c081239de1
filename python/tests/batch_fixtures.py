"""Small meshes, anchors and a texture generated in code for the wavg.batch tests and the
benchmark: UV-mapped sheets of several resolutions and shapes (template and targets),
closed surfaces (sphere, ellipsoid, torus) and one invalid mesh."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

#: Parametric positions (u, v) of the anchors, shared by every sheet so that anchor i of
#: one sheet corresponds to anchor i of another.
ANCHOR_UV = [(0.1, 0.1), (0.9, 0.1), (0.9, 0.9), (0.1, 0.9), (0.5, 0.5), (0.5, 0.1), (0.9, 0.5), (0.5, 0.9), (0.1, 0.5)]


def write_obj(path: Path, v: np.ndarray, f: np.ndarray, uv: np.ndarray | None = None) -> Path:
    """An OBJ file; with ``uv`` (one per vertex) faces are ``a/a b/b c/c``."""
    lines = [f"v {x!r} {y!r} {z!r}" for x, y, z in v.tolist()]
    if uv is not None:
        lines += [f"vt {s!r} {t!r}" for s, t in uv.tolist()]
        lines += [f"f {a + 1}/{a + 1} {b + 1}/{b + 1} {c + 1}/{c + 1}" for a, b, c in f.tolist()]
    else:
        lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in f.tolist()]
    path.write_text("\n".join(lines) + "\n")
    return path


def grid(nu: int, nv: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Parameters ``(u, v)`` in [0, 1]^2 of an nu x nv grid and its triangles."""
    u, v = np.meshgrid(np.linspace(0, 1, nu), np.linspace(0, 1, nv), indexing="xy")
    uv = np.stack([u.ravel(), v.ravel()], axis=1)
    faces = []
    for j in range(nv - 1):
        for i in range(nu - 1):
            a, b, c, d = j * nu + i, j * nu + i + 1, (j + 1) * nu + i + 1, (j + 1) * nu + i
            faces += [(a, b, c), (a, c, d)]
    return uv, np.array(faces, dtype=np.int64), np.array([nu, nv])


def sheet(nu: int, nv: int, shape: str, amp: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A UV-mapped sheet: ``bump`` (a Gaussian hill), ``wave``, ``bend`` (part of a
    cylinder) or ``saddle``; returns V, F, per-vertex UV."""
    uv, f, _ = grid(nu, nv)
    u, v = uv[:, 0], uv[:, 1]
    x, y = 2 * u - 1, 2 * v - 1
    if shape == "bump":
        z = amp * np.exp(-4 * (x**2 + y**2))
    elif shape == "wave":
        z = amp * np.sin(math.pi * x) * np.cos(0.5 * math.pi * y)
    elif shape == "saddle":
        z = amp * x * y
    elif shape == "bend":
        t = amp * x
        x, z = np.sin(t) / amp, (1 - np.cos(t)) / amp
    else:
        raise ValueError(shape)
    return np.stack([x, y, z], axis=1), f, uv


def sphere(n_lat: int, n_lon: int, radii: tuple[float, float, float] = (1, 1, 1), noise: float = 0.0, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """A closed latitude-longitude sphere (or ellipsoid), optionally with radial noise."""
    verts = [(0.0, 0.0, 1.0)]
    for i in range(1, n_lat):
        th = math.pi * i / n_lat
        for j in range(n_lon):
            ph = 2 * math.pi * j / n_lon
            verts.append((math.sin(th) * math.cos(ph), math.sin(th) * math.sin(ph), math.cos(th)))
    verts.append((0.0, 0.0, -1.0))
    v = np.array(verts) * np.array(radii)
    if noise:
        v *= 1 + noise * np.random.default_rng(seed).uniform(-1, 1, (len(v), 1))
    faces = []
    ring = lambda i, j: 1 + (i - 1) * n_lon + (j % n_lon)  # noqa: E731
    south = len(v) - 1
    for j in range(n_lon):
        faces.append((0, ring(1, j), ring(1, j + 1)))
        faces.append((south, ring(n_lat - 1, j + 1), ring(n_lat - 1, j)))
    for i in range(1, n_lat - 1):
        for j in range(n_lon):
            a, b, c, d = ring(i, j), ring(i + 1, j), ring(i + 1, j + 1), ring(i, j + 1)
            faces += [(a, b, c), (a, c, d)]
    return v, np.array(faces, dtype=np.int64)


def torus(n_u: int, n_v: int, r_big: float = 1.0, r_small: float = 0.4) -> tuple[np.ndarray, np.ndarray]:
    """A closed torus."""
    verts, faces = [], []
    for i in range(n_u):
        a = 2 * math.pi * i / n_u
        for j in range(n_v):
            b = 2 * math.pi * j / n_v
            verts.append(((r_big + r_small * math.cos(b)) * math.cos(a), (r_big + r_small * math.cos(b)) * math.sin(a), r_small * math.sin(b)))
    idx = lambda i, j: (i % n_u) * n_v + (j % n_v)  # noqa: E731
    for i in range(n_u):
        for j in range(n_v):
            faces += [(idx(i, j), idx(i + 1, j), idx(i + 1, j + 1)), (idx(i, j), idx(i + 1, j + 1), idx(i, j + 1))]
    return np.array(verts), np.array(faces, dtype=np.int64)


def invalid_mesh(path: Path) -> Path:
    """Three triangles sharing one edge (a non-manifold edge): no embedding is possible."""
    v = np.array([[0, 0, 0], [1, 0, 0], [0.5, 1, 0], [0.5, -1, 0], [0.5, 0, 1]], dtype=float)
    f = np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4]], dtype=np.int64)
    return write_obj(path, v, f)


def sheet_anchors(path: Path, nu: int, nv: int) -> Path:
    """The anchors file of an nu x nv sheet: the vertex nearest each of :data:`ANCHOR_UV`."""
    lines = []
    for u, v in ANCHOR_UV:
        i, j = round(u * (nu - 1)), round(v * (nv - 1))
        lines.append(f"v {j * nu + i}")
    path.write_text("# anchors at fixed (u, v) positions\n" + "\n".join(lines) + "\n")
    return path


def checker(size: int = 64, cells: int = 8) -> np.ndarray:
    """An RGB checkerboard with a colour ramp, (size, size, 3) uint8."""
    y, x = np.mgrid[0:size, 0:size]
    on = ((x * cells // size) + (y * cells // size)) % 2 == 0
    img = np.zeros((size, size, 3), dtype=np.uint8)
    img[..., 0] = np.where(on, 230, 30)
    img[..., 1] = (255 * x // max(size - 1, 1)).astype(np.uint8)
    img[..., 2] = (255 * y // max(size - 1, 1)).astype(np.uint8)
    return img


#: The sheets of the tests: name -> (nu, nv, shape, amplitude). The first is the template.
SHEETS = {
    "template": (12, 12, "bump", 0.3),
    "bump-fine": (16, 14, "bump", 0.5),
    "wave": (14, 12, "wave", 0.25),
    "bend": (18, 10, "bend", 1.2),
    "saddle": (11, 13, "saddle", 0.4),
    "flat-coarse": (9, 9, "bump", 0.05),
    "wave-fine": (20, 16, "wave", 0.15),
    "bend-tall": (10, 20, "bend", 0.8),
    "bump-wide": (22, 11, "bump", 0.2),
}


def make_assets(folder: Path) -> dict[str, object]:
    """Writes the fixtures into ``folder``: the template (mesh, anchors, texture), 8 sheet
    targets with anchors, 3 closed meshes and an invalid one. Returns their paths:
    ``template``, ``template_anchors``, ``texture``, ``targets`` (list of (mesh, anchors),
    the invalid mesh last), ``meshes`` (every mesh for precompute, the invalid one among
    them) and ``invalid``."""
    import wavg

    folder.mkdir(parents=True, exist_ok=True)
    paths: dict[str, Path] = {}
    anchors: dict[str, Path] = {}
    for name, (nu, nv, shape, amp) in SHEETS.items():
        v, f, uv = sheet(nu, nv, shape, amp)
        paths[name] = write_obj(folder / f"{name}.obj", v, f, uv)
        anchors[name] = sheet_anchors(folder / f"{name}.anchors.txt", nu, nv)
    closed = {
        "sphere": sphere(8, 14),
        "ellipsoid": sphere(9, 12, (1.5, 1.0, 0.7)),
        "noisy-sphere": sphere(10, 16, noise=0.05, seed=3),
        "torus": torus(16, 8),
    }
    for name, (v, f) in closed.items():
        paths[name] = write_obj(folder / f"{name}.obj", v, f)
    invalid = invalid_mesh(folder / "nonmanifold.obj")
    (folder / "nonmanifold.anchors.txt").write_text("v 0\n" * len(ANCHOR_UV))
    texture = folder / "checker.png"
    wavg.save_png(str(texture), checker())
    targets = [(str(paths[n]), str(anchors[n])) for n in SHEETS if n != "template"]
    targets.append((str(invalid), str(folder / "nonmanifold.anchors.txt")))
    meshes = [str(p) for p in paths.values()] + [str(invalid)]
    return {
        "template": str(paths["template"]),
        "template_anchors": str(anchors["template"]),
        "texture": str(texture),
        "targets": targets,
        "meshes": meshes,
        "invalid": str(invalid),
    }
