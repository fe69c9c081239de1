"""Embeddings read in worker threads before an operator asks for them (``wavg.Surface``
and ``Surface.load_cached`` release the GIL while they work, and nothing here touches
Blender's data): :func:`start` begins a read for a mesh (a :class:`~.meshdata.MeshInput`
read on Blender's thread), :func:`take` waits for it and hands over the surface."""

import os
import threading

from .errors import wavg


class _Read:
    """One read: the mesh's surface with the cached embedding of the given options from
    the first folder holding one, and its closest-point geometry."""

    def __init__(self, mesh, options, dirs):
        self.V, self.F = mesh.V, mesh.F
        self.options, self.dirs = options, list(dirs)
        self.result = None
        self.thread = threading.Thread(target=self._run, daemon=True)

    def _run(self):
        from .surfaces import build_geometry

        try:
            w = wavg()
            s = w.Surface(self.V, self.F)
            landmarks, seed = self.options
            for d in self.dirs:
                if os.path.isdir(d) and s.load_cached(landmarks=landmarks, seed=seed, cache=d):
                    self.result = (s, build_geometry(s))
                    return
        except Exception:  # noqa: BLE001 (the operator reads it again and reports why not)
            self.result = None


# Mesh fingerprint -> its read, started and not yet taken (oldest first).
_READS = {}
#: Reads kept waiting to be taken: activating many meshes in turn does not keep all of them
#: in memory.
MAX_READS = 4
# Reads started (for tests).
STARTED = [0]


def start(mesh, options, dirs):
    """Starts reading the embedding of ``mesh`` with ``options`` (``(landmarks, seed)``)
    from the folders ``dirs``; False when a read of that mesh is under way already."""
    if mesh.key in _READS:
        return False
    while len(_READS) >= MAX_READS:
        del _READS[next(iter(_READS))]  # a running read ends on its own, unused
    read = _Read(mesh, options, dirs)
    _READS[mesh.key] = read
    read.thread.start()
    STARTED[0] += 1
    return True


def take(key):
    """``(surface, geometry)`` read for the mesh of fingerprint ``key`` (waiting for the
    read to end), or ``None`` when none was started or it found nothing."""
    read = _READS.pop(key, None)
    if read is None:
        return None
    read.thread.join()
    return read.result


def forget_all():
    """Drops the reads (a running one ends on its own)."""
    _READS.clear()
