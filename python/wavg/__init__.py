"""wavg: weighted averages of points on triangle meshes, with NumPy arrays.

Make a ``Surface`` (from arrays or a file), compute or load its embedding, make a
``Solver`` for a set of anchors, then ask forward problems (weights to points) and inverse
problems (points to weights) in parallel batches. The applications (``spline``,
``correspond``, ``decal``, ``transfer_texture``, ``Remesher``, ``render``) have the names
of the ``wavg`` commands. Arrays come back as float64 / int64 / bool NumPy arrays; a
query without an answer is a row of the ``ok``/``valid`` mask.
"""

from ._errors import (
    CancelledError,
    InvalidArgumentError,
    InvalidMeshError,
    NoSolutionError,
    OutOfMemoryError,
    WavgError,
    WavgIOError,
)
from ._types import Correspondence, Points
from ._wavg import (
    Solver,
    Surface,
    __version__,
    cache_dir,
    cache_entries,
    read_anchors,
    read_mesh,
    write_anchors,
    write_mesh,
)
from . import _wavg

__all__ = [
    "CancelledError",
    "Correspondence",
    "InvalidArgumentError",
    "InvalidMeshError",
    "NoSolutionError",
    "OutOfMemoryError",
    "Points",
    "Remesher",
    "Solver",
    "Surface",
    "WavgError",
    "WavgIOError",
    "barycentric_weights",
    "cache_dir",
    "cache_entries",
    "correspond",
    "decal",
    "read_anchors",
    "read_mesh",
    "read_png",
    "render",
    "save_png",
    "spline",
    "transfer_texture",
    "weighted_average",
    "write_anchors",
    "write_mesh",
]

_APPS = (
    "Remesher", "correspond", "decal", "read_png", "render", "save_png", "spline",
    "transfer_texture",
)
for _name in _APPS:
    if hasattr(_wavg, _name):
        globals()[_name] = getattr(_wavg, _name)
del _name


def weighted_average(V, F, anchors, weights, threads=None) -> Points:
    """weighted_average(V, F, anchors, weights) -> Points

    One-off forward problem on the mesh ``V (n, 3)``, ``F (m, 3)``: precomputes its
    embedding, makes a solver for ``anchors`` (``(k,)`` vertex ids or ``(faces, bary)``)
    and returns the weighted averages for ``weights`` (``(k,)`` or ``(q, k)``). Nothing
    is cached: for many calls on one mesh, use ``Surface`` and ``Solver``.
    """
    surface = Surface(V, F)
    surface.precompute(progress=False, threads=threads)
    return Solver(surface, anchors).forward(weights, threads=threads)


def barycentric_weights(V, F, anchors, faces, bary, threads=None):
    """barycentric_weights(V, F, anchors, faces, bary) -> (W (q, k) float64, ok (q,) bool)

    One-off inverse problem on the mesh ``V (n, 3)``, ``F (m, 3)``: precomputes its
    embedding and returns the verified generalised barycentric weights of the surface
    points ``faces (q,)``, ``bary (q, 3)`` with respect to ``anchors`` (NaN rows where
    ``ok`` is False).
    """
    surface = Surface(V, F)
    surface.precompute(progress=False, threads=threads)
    return Solver(surface, anchors).inverse(faces, bary, threads=threads)


def __getattr__(name):
    # `wavg.batch` (Dask) is imported on first use, so `import wavg` stays light.
    if name == "batch":
        import importlib

        module = importlib.import_module(".batch", __name__)
        globals()["batch"] = module
        return module
    raise AttributeError(f"module 'wavg' has no attribute {name!r}")
