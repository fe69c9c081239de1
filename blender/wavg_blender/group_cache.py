"""Members of an anchor vertex group kept between operator runs. Blender 3.4 has no bulk
read of vertex groups, so reading one visits every vertex from Python (~9 ms on 25k
vertices); a decal run again on the same anchors reads them from here instead.

An entry is used only for an object in Object mode whose mesh, vertex count, group index
and name are those it was read with, and it is dropped when the depsgraph reports a
geometry update of the object or its mesh (every edit of vertex groups or of the mesh
tags one), on undo, redo and file load. Readers evaluate pending updates first
(:func:`members`), and writers evaluate their own writes before storing (:func:`keep`),
so no edit can slip between an entry and the data it describes."""

import bpy
import numpy as np
from bpy.app.handlers import persistent

from .meshdata import group_members

# Object pointer -> (key, ids, weights).
_ENTRIES = {}
# How many reads were answered from memory (for tests).
HITS = [0]


def _key(obj, group):
    me = obj.data
    return (obj.name, getattr(obj, "session_uid", 0), me.as_pointer(), len(me.vertices),
            group.index, group.name)


def members(context, obj, group):
    """``(ids, weights)`` of the members of ``group`` with a weight above zero (as
    :func:`~.meshdata.group_members`), from memory when the entry is still valid."""
    context.view_layer.update()  # pending edits reach the handler, which drops entries
    entry = _ENTRIES.get(obj.as_pointer())
    if obj.mode == 'OBJECT' and entry is not None and entry[0] == _key(obj, group):
        HITS[0] += 1
        return entry[1].copy(), entry[2].copy()
    ids, weights = group_members(obj, group)
    return ids, weights


def keep(context, obj, group_name, ids, weights):
    """After an operator wrote ``obj``'s mesh: evaluates those writes (dropping the old
    entry), then remembers ``(ids, weights)`` as the members of ``group_name``."""
    context.view_layer.update()
    group = obj.vertex_groups.get(group_name)
    if obj.mode != 'OBJECT' or group is None:
        return
    _ENTRIES[obj.as_pointer()] = (_key(obj, group), np.array(ids), np.array(weights))


def forget_all():
    """Drops every entry."""
    _ENTRIES.clear()


def _original(idb):
    return getattr(idb, "original", idb)


@persistent
def on_depsgraph_update(scene, depsgraph):
    """Drops the entries of objects and meshes whose geometry changed."""
    if not _ENTRIES:
        return
    changed = {_original(u.id).as_pointer() for u in depsgraph.updates if u.is_updated_geometry}
    if not changed:
        return
    for ptr, entry in list(_ENTRIES.items()):
        if ptr in changed or entry[0][2] in changed:
            del _ENTRIES[ptr]


@persistent
def on_reload(*_args):
    """Undo, redo and file load replace the data: drops every entry."""
    forget_all()


_HANDLERS = (
    ("depsgraph_update_post", on_depsgraph_update),
    ("undo_post", on_reload),
    ("redo_post", on_reload),
    ("load_post", on_reload),
)


def register():
    for name, fn in _HANDLERS:
        handlers = getattr(bpy.app.handlers, name)
        if fn not in handlers:
            handlers.append(fn)


def unregister():
    for name, fn in _HANDLERS:
        handlers = getattr(bpy.app.handlers, name)
        if fn in handlers:
            handlers.remove(fn)
    forget_all()
