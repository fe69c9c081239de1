"""Decals computed before the click and kept after it. ``wavg.decal`` costs ~19 ms of CPU
on 25k vertices and reading its anchor group from Blender 1.4-15 ms (:mod:`.group_cache`),
more than half of ``wavg.decal_uv``'s latency budget. So:

* the last decal of each object is kept with its inputs (the surface, the anchors and
  their (u, v)): a run whose inputs are the same (run again, or after an edit that left
  the anchors as they were) takes it instead of computing it;
* after a geometry update of the active object that ``wavg.decal_uv`` ran on (an edit of
  its anchor group, Weight Paint...), once Blender has been idle for :data:`IDLE` seconds
  a timer reads its anchor group and ``wavg_invalid`` (kept by :mod:`.group_cache`), its
  mesh (kept by :mod:`.surfaces`) and the (u, v) attribute, and starts the decal in a
  worker thread (wavg releases the GIL): the click that follows finds all of it done.

Results are matched by their inputs, never by time, so a stale one is never used."""

import threading
import time
import traceback

import bpy
import numpy as np
from bpy.app.handlers import persistent

from . import group_cache, surfaces
from .errors import wavg

#: Seconds without a geometry update of the object before its decal is read ahead: a
#: stroke of Weight Paint is not interrupted by reads.
IDLE = 0.25
#: Modes in which the mesh's own data is current, so its decal can be read ahead (Weight
#: Paint writes vertex groups to the mesh itself; Edit mode keeps its edits apart).
READ_MODES = ('OBJECT', 'WEIGHT_PAINT')
#: Objects whose decal is kept (the most recent ones).
MAX_KEPT = 4

# Object pointer -> the settings of its last wavg.decal_uv: (anchor group, attribute,
# mesh pointer, object name). A pointer may be reused by a later object: the worst that
# does is one needless read ahead, since results are matched by their inputs.
_SETTINGS = {}
# Object pointer -> _Decal (done or under way), most recent last.
_DECALS = {}
# When each object's geometry last changed (perf_counter seconds), while a read waits.
_CHANGED = {}
# Decals computed on a worker thread / taken from memory (for tests).
COMPUTED_AHEAD = [0]
TAKEN = [0]


class _Decal:
    """One ``wavg.decal`` of ``surface`` with anchors ``anchors`` and their (u, v)
    ``anchor_uv``, run here or in a worker thread."""

    def __init__(self, surface, anchors, anchor_uv):
        self.surface = surface
        self.anchors = np.array(anchors, dtype=np.int64)
        self.anchor_uv = np.array(anchor_uv, dtype=np.float64)
        self.result = None
        self.error = None
        self.thread = None

    def matches(self, surface, anchors, anchor_uv):
        return (self.surface is surface and np.array_equal(self.anchors, anchors)
                and np.array_equal(self.anchor_uv, anchor_uv))

    def run(self):
        try:
            uv, valid = wavg().decal(self.surface, self.anchors, self.anchor_uv)
            self.result = (np.asarray(uv, dtype=np.float64), np.asarray(valid, dtype=bool))
        except Exception as e:  # noqa: BLE001 (raised again by `get` on Blender's thread)
            self.error = e

    def start(self):
        self.thread = threading.Thread(target=self.run, daemon=True)
        self.thread.start()

    def get(self):
        """``(uv, valid)`` (waiting for a worker thread), or the error it raised."""
        if self.thread is not None:
            self.thread.join()
        if self.error is not None:
            raise self.error
        return self.result


def _keep(obj, decal):
    ptr = obj.as_pointer()
    _DECALS.pop(ptr, None)
    while len(_DECALS) >= MAX_KEPT:
        del _DECALS[next(iter(_DECALS))]
    _DECALS[ptr] = decal


def decal(obj, surface, anchors, anchor_uv):
    """``(uv, valid)`` of ``wavg.decal(surface, anchors, anchor_uv)`` for ``obj``: the
    one kept or read ahead when its inputs are these, else computed now (and kept). Raises
    what ``wavg.decal`` raises."""
    kept = _DECALS.get(obj.as_pointer())
    if kept is not None and kept.matches(surface, anchors, anchor_uv):
        try:
            got = kept.get()
        except Exception:  # noqa: BLE001 (computed again below, raising on this thread)
            got = None
        if got is not None:
            TAKEN[0] += 1
            return got
    d = _Decal(surface, anchors, anchor_uv)
    d.run()
    result = d.get()
    _keep(obj, d)
    return result


def remember_settings(obj, group, attribute):
    """Records what ``wavg.decal_uv`` ran with on ``obj``: its decal is read ahead with
    these after the next geometry update."""
    _SETTINGS[obj.as_pointer()] = (group, attribute, obj.data.as_pointer(), obj.name)


def read_ahead(obj, context=None):
    """Reads what a ``wavg.decal_uv`` with ``obj``'s last settings needs and starts its
    decal in a worker thread; True when one started. Only in Object and Weight Paint mode
    (:data:`READ_MODES`; the groups read are kept for Object mode only), with the
    embedding in memory and valid inputs (the operator reports the others)."""
    from .meshdata import point_attribute_2d
    from .op_decal import INVALID_GROUP

    context = context or bpy.context
    settings = _SETTINGS.get(obj.as_pointer()) if obj is not None else None
    if settings is None or obj.type != 'MESH' or obj.mode not in READ_MODES:
        return False
    group_name, attribute, mesh_ptr, name = settings
    if (mesh_ptr, name) != (obj.data.as_pointer(), obj.name):
        return False
    group = obj.vertex_groups.get(group_name)
    if group is None:
        return False
    mesh = surfaces.mesh_input(obj)
    surface = surfaces.cached(mesh.key)
    if surface is None:
        return False
    groups = [group]
    invalid = obj.vertex_groups.get(INVALID_GROUP)
    if invalid is not None and invalid.name != group.name:
        groups.append(invalid)  # so the operator can leave an unchanged one alone
    anchors = group_cache.members_of(context, obj, groups)[group.name][0]
    if len(anchors) < 3:
        return False
    try:
        anchor_uv = point_attribute_2d(obj, attribute)[anchors]
    except Exception:  # noqa: BLE001 (no such attribute: the operator says so)
        return False
    if not np.all(np.isfinite(anchor_uv)):
        return False
    kept = _DECALS.get(obj.as_pointer())
    if kept is not None and kept.matches(surface, anchors, anchor_uv):
        return False
    d = _Decal(surface, anchors, anchor_uv)
    _keep(obj, d)
    d.start()
    COMPUTED_AHEAD[0] += 1
    return True


def _idle():
    """The timer: reads the active object's decal ahead once its geometry has not changed
    for :data:`IDLE` seconds."""
    try:
        obj = bpy.context.view_layer.objects.active
        ptr = obj.as_pointer() if obj is not None else None
        if ptr not in _CHANGED:
            _CHANGED.clear()
            return None
        wait = _CHANGED[ptr] + IDLE - time.perf_counter()
        if wait > 0:
            return wait
        _CHANGED.clear()
        read_ahead(obj)
    except Exception:  # reading ahead must never break Blender
        traceback.print_exc()
        _CHANGED.clear()
    return None


def _original(idb):
    return getattr(idb, "original", idb)


@persistent
def on_depsgraph_update(scene, depsgraph):
    """Notes a geometry update of an object ``wavg.decal_uv`` ran on and starts the idle
    timer."""
    if not _SETTINGS:
        return
    for u in depsgraph.updates:
        if not u.is_updated_geometry:
            continue
        ptr = _original(u.id).as_pointer()
        for p, setting in _SETTINGS.items():
            if ptr in (p, setting[2]):
                _CHANGED[p] = time.perf_counter()
    if _CHANGED and not bpy.app.timers.is_registered(_idle):
        bpy.app.timers.register(_idle, first_interval=IDLE)


def forget_all():
    """Drops every kept decal and setting (a running worker ends on its own)."""
    _SETTINGS.clear()
    _DECALS.clear()
    _CHANGED.clear()


@persistent
def on_load(*_args):
    forget_all()


def register():
    if on_depsgraph_update not in bpy.app.handlers.depsgraph_update_post:
        bpy.app.handlers.depsgraph_update_post.append(on_depsgraph_update)
    if on_load not in bpy.app.handlers.load_post:
        bpy.app.handlers.load_post.append(on_load)


def unregister():
    for name, fn in (("depsgraph_update_post", on_depsgraph_update), ("load_post", on_load)):
        handlers = getattr(bpy.app.handlers, name)
        if fn in handlers:
            handlers.remove(fn)
    if bpy.app.timers.is_registered(_idle):
        bpy.app.timers.unregister(_idle)
    forget_all()
