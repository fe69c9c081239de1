"""wavg surfaces of mesh objects and their embeddings.

Embeddings live in the embedding cache every way into wavg shares (``wavg cache list``
shows them; the key is the mesh's fingerprint and the precompute options): in a folder
beside the saved ``.blend`` file, or in the user cache (``$WAVG_BLENDER_CACHE`` when set,
else ``wavg.cache_dir()``: ``$WAVG_CACHE_DIR``, else the platform's user cache, where the
command line and Python find them too) while the ``.blend`` is unsaved. The options a
precompute used are kept on the object (custom properties ``wavg_landmarks``, 0 for the
library's choice, and ``wavg_seed``), so a lookup uses the same key. Loaded surfaces are
kept in memory by the mesh's fingerprint, so moving a control point does not read the file
again, and the mesh read from an object is kept until its geometry changes (:mod:`.memo`),
so an operator run again neither reads nor hashes it.
"""

import os

import bpy
import numpy as np
from mathutils.bvhtree import BVHTree

from . import background, memo
from .errors import AddonError, describe, wavg
from .meshdata import MeshInput

# Surfaces with their embedding, by mesh fingerprint.
_SURFACES = {}
# Positions, triangles and BVH tree of each surface (see `geometry`), by mesh fingerprint.
_TREES = {}
# Object pointer -> (key, MeshInput): the mesh read last from each object.
_MESHES = memo.store()
# Object pointer -> the mesh read last from it, kept across geometry updates and used again
# only when `MeshInput.unchanged` says it still is the object's mesh (oldest first).
_LAST = memo.reload_store()
#: Objects whose last mesh is kept that way.
MAX_LAST = 8
# Embeddings read on Blender's thread (for tests).
LOADS = [0]


def user_cache_dir():
    """The user cache folder (embeddings of unsaved files): ``$WAVG_BLENDER_CACHE``, else
    the cache every way into wavg shares (``None`` when there is none)."""
    return os.environ.get("WAVG_BLENDER_CACHE") or wavg().cache_dir()


def cache_dirs():
    """Where embeddings are looked up, the first one being where they are written."""
    dirs = []
    if bpy.data.filepath:
        dirs.append(os.path.dirname(os.path.abspath(bpy.data.filepath)))
    user = user_cache_dir()
    if user:
        dirs.append(user)
    return dirs


def write_dir():
    """The folder a new embedding is cached in (created), or ``None`` when there is none."""
    dirs = cache_dirs()
    if not dirs:
        return None
    os.makedirs(dirs[0], exist_ok=True)
    return dirs[0]


def landmarks_arg(landmarks):
    """A landmarks setting as ``precompute`` takes it: 0 (the add-on's default) becomes
    ``None``, the library's choice."""
    return int(landmarks) or None


def options(obj):
    """``(landmarks, seed)`` of the embedding precomputed for ``obj`` (its custom
    properties; the defaults for an object without them), as ``load_cached`` takes them."""
    return landmarks_arg(obj.get("wavg_landmarks", 0)), int(obj.get("wavg_seed", 0))


def remember_options(obj, landmarks, seed, path):
    """Records on ``obj`` the options its embedding was precomputed with and the cache
    entry it went to (``path``, or ``None``)."""
    obj["wavg_landmarks"] = int(landmarks or 0)
    obj["wavg_seed"] = int(seed)
    if path:
        obj["wavg_embedding"] = str(path)
    elif "wavg_embedding" in obj:
        del obj["wavg_embedding"]


def find_embedding(obj):
    """The cache entry (``.wavg`` file) recorded on ``obj`` by its precompute when it still
    exists, else ``None``: a cheap check for the UI (lookups go through the cache key)."""
    path = obj.get("wavg_embedding")
    return path if path and os.path.isfile(path) else None


def load_cached(surface, obj):
    """Loads into ``surface`` (of ``obj``'s mesh) the cached embedding of the options
    recorded on ``obj``; returns the folder it came from, or ``None`` when no folder holds
    one. An entry that does not load is an :class:`AddonError`."""
    landmarks, seed = options(obj)
    w = wavg()
    for d in cache_dirs():
        if not os.path.isdir(d):
            continue
        try:
            LOADS[0] += 1
            if surface.load_cached(landmarks=landmarks, seed=seed, cache=d):
                return d
        except (w.WavgError, ValueError, OSError) as e:
            raise AddonError(
                f"the cached embedding in {d} does not load for '{obj.name}' ({describe(e)}); "
                "run wavg.precompute again"
            ) from e
    return None


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


def remember(key, surface, geometry_of=None):
    """Keeps ``surface`` (with its embedding) in memory under ``key``, with its
    closest-point tree (``geometry_of``, else built here: in the one-off of loading or
    computing the embedding, ~50 ms on 25k vertices, not at the first move of a spline's
    control point)."""
    _SURFACES[key] = surface
    _TREES[key] = geometry_of if geometry_of is not None else build_geometry(surface)


def cached(key):
    """The in-memory surface of fingerprint ``key``, or ``None``."""
    return _SURFACES.get(key)


def mesh_input(obj):
    """The :class:`MeshInput` of the mesh object ``obj``, from memory while the object, its
    mode and its geometry are those it was read with."""
    if obj is None or obj.type != 'MESH':
        return MeshInput(obj)  # says why not
    memo.settle(bpy.context)
    entry = _MESHES.get(obj.as_pointer())
    if entry is not None and entry[0] == memo.identity(obj):
        return entry[1]
    last = _LAST.get(obj.as_pointer())
    if last is not None and last.unchanged(obj):
        mesh = last  # only something else than the positions and polygons changed
    else:
        mesh = MeshInput(obj)
    if obj.mode == 'EDIT':
        memo.settle(bpy.context)  # the sync out of Edit mode tagged the mesh: not an edit
    _MESHES[obj.as_pointer()] = (memo.identity(obj), mesh)
    _LAST.pop(obj.as_pointer(), None)
    while len(_LAST) >= MAX_LAST:
        del _LAST[next(iter(_LAST))]
    _LAST[obj.as_pointer()] = mesh
    return mesh


def keep_mesh(obj, mesh):
    """After an operator wrote data of ``obj``'s mesh other than its positions and faces
    (UV layers, vertex groups) and evaluated those writes: ``mesh`` is still what
    :func:`mesh_input` would read (Object mode only)."""
    if obj.mode == 'OBJECT' and mesh.obj == obj:
        _MESHES[obj.as_pointer()] = (memo.identity(obj), mesh)


def surface_of(obj):
    """``(surface, mesh)`` for the mesh object ``obj``: the mesh as arrays and its
    ``wavg.Surface`` with the embedding from memory or the cache. An object without
    embedding is an :class:`AddonError` telling to run wavg.precompute."""
    mesh = mesh_input(obj)
    s = _SURFACES.get(mesh.key)
    if s is not None:
        return s, mesh
    read = background.take(mesh.key)
    if read is not None:
        remember(mesh.key, *read)
        return read[0], mesh
    s = new_surface(mesh)  # a broken mesh says so before the missing embedding
    if load_cached(s, obj) is None:
        raise AddonError(
            f"'{obj.name}' has no embedding: run wavg.precompute on it first "
            "(the embedding belongs to the exact mesh; any edit of it needs a new one)"
        )
    remember(mesh.key, s)
    return s, mesh


def geometry(key, surface):
    """``(V, F, tree, diagonal)`` of ``surface``: its positions and triangles as arrays, a
    BVH tree over the triangles (closest-point queries) and the bounding-box diagonal,
    cached by ``key``."""
    g = _TREES.get(key)
    if g is None:
        g = _TREES[key] = build_geometry(surface)
    return g


def build_geometry(surface):
    """``(V, F, tree, diagonal)`` of ``surface`` (see :func:`geometry`); touches no Blender
    data, so a worker thread may build it."""
    V = np.asarray(surface.vertices, dtype=np.float64)
    F = np.asarray(surface.faces, dtype=np.int64)
    t = BVHTree.FromPolygons(V.tolist(), F.tolist(), all_triangles=True, epsilon=0.0)
    return V, F, t, float(np.linalg.norm(V.max(axis=0) - V.min(axis=0)))


def forget_all():
    """Drops the in-memory surfaces and meshes (e.g. when the add-on is disabled)."""
    _SURFACES.clear()
    _TREES.clear()
    _MESHES.clear()
    _LAST.clear()
    background.forget_all()


def read_ahead(obj):
    """Starts reading the embedding recorded on the mesh object ``obj`` in a worker thread
    (:mod:`.background`), unless it is in memory or being read already; True when started.
    Its first operator then finds it in memory instead of reading it (~0.2 s on 25k
    vertices)."""
    if obj is None or obj.type != 'MESH' or find_embedding(obj) is None:
        return False
    mesh = mesh_input(obj)
    if mesh.key in _SURFACES:
        return False
    return background.start(mesh, options(obj), cache_dirs())


def textured(mesh, uv):
    """A ``wavg.Surface`` of ``mesh`` (a :class:`MeshInput` whose embedding is cached)
    carrying per-corner texture coordinates ``uv`` ``(m, 3, 2)``, for texture transfer."""
    w = wavg()
    try:
        s = w.Surface(mesh.V, mesh.F, uv=uv)
    except (w.WavgError, ValueError, TypeError, OSError) as e:
        raise AddonError(f"wavg cannot use the UVs of '{mesh.name}': {describe(e)}") from e
    if load_cached(s, mesh.obj) is None:
        raise AddonError(f"'{mesh.name}' has no embedding: run wavg.precompute on it first")
    return s
