from ._errors import (CancelledError, InvalidArgumentError, InvalidMeshError, NoSolutionError,
                      OutOfMemoryError, WavgError, WavgIOError)
from ._types import Correspondence, Points
from ._wavg import (Remesher, Solver, Surface, __version__, cache_dir, cache_entries, correspond,
                    decal, read_anchors, read_mesh, read_png, render, save_png, spline,
                    transfer_texture, write_anchors, write_mesh)

import numpy as np
import numpy.typing as npt
from typing import Any, Optional, Tuple

def weighted_average(V: npt.ArrayLike, F: npt.ArrayLike, anchors: Any, weights: npt.ArrayLike,
                     threads: Optional[int] = None) -> Points: ...
def barycentric_weights(V: npt.ArrayLike, F: npt.ArrayLike, anchors: Any, faces: npt.ArrayLike,
                        bary: npt.ArrayLike, threads: Optional[int] = None) -> Tuple[np.ndarray, np.ndarray]: ...
def __getattr__(name: str) -> Any: ...
