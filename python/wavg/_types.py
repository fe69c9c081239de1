"""The named tuples wavg returns."""

from typing import TYPE_CHECKING, NamedTuple

if TYPE_CHECKING:  # NumPy loads on the first call that needs it, not on `import wavg`.
    import numpy as np


class Points(NamedTuple):
    """Surface points found by forward problems, one row per query.

    ``face (q,) int64`` (-1 without an answer), ``bary (q, 3) float64`` barycentric
    coordinates in that face, ``xyz (q, 3) float64`` 3-D positions (NaN without an
    answer), ``ok (q,) bool``.
    """

    face: "np.ndarray"
    bary: "np.ndarray"
    xyz: "np.ndarray"
    ok: "np.ndarray"


class Correspondence(NamedTuple):
    """A map of every source vertex onto the target (``wavg.correspond``).

    ``face (n,) int64`` and ``bary (n, 3) float64`` on the target, ``xyz (n, 3) float64``
    (NaN where the vertex has no image), ``valid (n,) bool`` (kept by the validity test),
    ``reason (n,)`` str (``valid``, ``unanswered``, ``no-round-trip``,
    ``negative-weight``, ``inconsistent``), ``report`` dict with the keys of
    ``wavg correspond --json``.
    """

    face: "np.ndarray"
    bary: "np.ndarray"
    xyz: "np.ndarray"
    valid: "np.ndarray"
    reason: "np.ndarray"
    report: dict
