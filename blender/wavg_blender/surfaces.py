"""wavg surfaces of mesh objects and their embeddings.

An embedding is cached in a ``.wavg`` file named by the mesh's fingerprint
(``wavg-<key>.wavg``): beside the saved ``.blend`` file, or in the user cache
(``$WAVG_BLENDER_CACHE``, else ``$XDG_CACHE_HOME/wavg-blender``, else
``~/.cache/wavg-blender``) while the ``.blend`` is unsaved. Loaded surfaces are kept in
memory by the same key, so moving a control point does not read the file again.
"""

import os

import bpy
import numpy as np
from mathutils.bvhtree import BVHTree

from .errors import AddonError, describe, wavg
from .meshdata import MeshInput

# Surfaces with their embedding, by mesh fingerprint.
_SURFACES = {}
# Positions, triangles and BVH tree of each surface (see `geometry`), by mesh fingerprint.
_TREES = {}


def user_cache_dir():
    """The user cache folder for embeddings of unsaved files."""
    env = os.environ.get("WAVG_BLENDER_CACHE")
    if env:
        return env
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return os.path.join(base, "wavg-blender")


def cache_dirs():
    """Where embeddings are looked up, the first one being where they are written."""
    dirs = []
    if bpy.data.filepath:
        dirs.append(os.path.dirname(os.path.abspath(bpy.data.filepath)))
    dirs.append(user_cache_dir())
    return dirs


def file_name(key):
    """The cache file name of the mesh with fingerprint ``key``."""
    return f"wavg-{key}.wavg"


def find_embedding(key):
    """The cached ``.wavg`` file of the mesh with fingerprint ``key``, or ``None``."""
    for d in cache_dirs():
        path = os.path.join(d, file_name(key))
        if os.path.isfile(path):
            return path
    return None


def write_path(key):
    """Where a new embedding of the mesh ``key`` is written (the folder is created)."""
    d = cache_dirs()[0]
    os.makedirs(d, exist_ok=True)
    return os.path.join(d, file_name(key))


def new_surface(mesh):
    """A ``wavg.Surface`` of ``mesh`` (a :class:`MeshInput`) without embedding; a mesh wavg
    refuses (non-manifold, degenerate) is an :class:`AddonError` naming the problems."""
    w = wavg()
    try:
        return w.Surface(mesh.V, mesh.F)
    except w.InvalidMeshError as e:
        raise AddonError(
            f"'{mesh.name}' is not a valid manifold triangle mesh ({describe(e)}); "
            "Mesh > Clean Up or `wavg repair` can fix many such meshes"
        ) from e
    except (w.WavgError, ValueError, TypeError) as e:
        raise AddonError(f"wavg cannot use '{mesh.name}': {describe(e)}") from e


def remember(key, surface):
    """Keeps ``surface`` (with its embedding) in memory under ``key``."""
    _SURFACES[key] = surface
    _TREES.pop(key, None)


def cached(key):
    """The in-memory surface of fingerprint ``key``, or ``None``."""
    return _SURFACES.get(key)


def surface_of(obj):
    """``(surface, mesh)`` for the mesh object ``obj``: the mesh as arrays and its
    ``wavg.Surface`` with the embedding from memory or the cache file. An object without
    embedding is an :class:`AddonError` telling to run wavg.precompute."""
    mesh = MeshInput(obj)
    s = _SURFACES.get(mesh.key)
    if s is not None:
        return s, mesh
    path = find_embedding(mesh.key)
    if path is None:
        new_surface(mesh)  # a broken mesh says so before the missing embedding
        raise AddonError(
            f"'{obj.name}' has no embedding: run wavg.precompute on it first "
            "(the embedding belongs to the exact mesh; any edit of it needs a new one)"
        )
    s = new_surface(mesh)
    w = wavg()
    try:
        s.load_embedding(path)
    except (w.WavgError, ValueError, OSError) as e:
        raise AddonError(
            f"the cached embedding {path} does not load for '{obj.name}' ({describe(e)}); "
            "run wavg.precompute again"
        ) from e
    remember(mesh.key, s)
    return s, mesh


def geometry(key, surface):
    """``(V, F, tree, diagonal)`` of ``surface``: its positions and triangles as arrays, a
    BVH tree over the triangles (closest-point queries) and the bounding-box diagonal,
    cached by ``key``."""
    g = _TREES.get(key)
    if g is None:
        V = np.asarray(surface.vertices, dtype=np.float64)
        F = np.asarray(surface.faces, dtype=np.int64)
        t = BVHTree.FromPolygons(V.tolist(), F.tolist(), all_triangles=True, epsilon=0.0)
        diagonal = float(np.linalg.norm(V.max(axis=0) - V.min(axis=0)))
        g = _TREES[key] = (V, F, t, diagonal)
    return g


def forget_all():
    """Drops the in-memory surfaces (e.g. when the add-on is disabled)."""
    _SURFACES.clear()
    _TREES.clear()


def textured(mesh, uv):
    """A ``wavg.Surface`` of ``mesh`` (a :class:`MeshInput` whose embedding is cached)
    carrying per-corner texture coordinates ``uv`` ``(m, 3, 2)``, for texture transfer."""
    w = wavg()
    path = find_embedding(mesh.key)
    if path is None:
        raise AddonError(f"'{mesh.name}' has no embedding: run wavg.precompute on it first")
    try:
        s = w.Surface(mesh.V, mesh.F, uv=uv)
        s.load_embedding(path)
    except (w.WavgError, ValueError, TypeError, OSError) as e:
        raise AddonError(f"wavg cannot use the UVs of '{mesh.name}': {describe(e)}") from e
    return s
