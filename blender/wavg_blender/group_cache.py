"""Members of an anchor vertex group kept between operator runs (a :mod:`.memo` store).
Blender 3.4 has no bulk read of vertex groups, so reading one visits every vertex from
Python (~9 ms on 25k vertices); a decal run again on the same anchors reads them from here
instead. An entry is used only for an object in Object mode whose mesh, vertex count, group
index and name are those it was read with; writers evaluate their own writes before storing
(:func:`keep`)."""

import numpy as np

from . import memo
from .meshdata import group_members

# Object pointer -> (key, ids, weights).
_ENTRIES = memo.store()
# How many reads were answered from memory (for tests).
HITS = [0]


def _key(obj, group):
    return memo.identity(obj) + (group.index, group.name)


def members(context, obj, group):
    """``(ids, weights)`` of the members of ``group`` with a weight above zero (as
    :func:`~.meshdata.group_members`), from memory when the entry is still valid."""
    memo.settle(context)
    entry = _ENTRIES.get(obj.as_pointer())
    if obj.mode == 'OBJECT' and entry is not None and entry[0] == _key(obj, group):
        HITS[0] += 1
        return entry[1].copy(), entry[2].copy()
    ids, weights = group_members(obj, group)
    return ids, weights


def keep(context, obj, group_name, ids, weights):
    """After an operator wrote ``obj``'s mesh: evaluates those writes (dropping the old
    entry), then remembers ``(ids, weights)`` as the members of ``group_name``."""
    memo.settle(context)
    group = obj.vertex_groups.get(group_name)
    if obj.mode != 'OBJECT' or group is None:
        return
    _ENTRIES[obj.as_pointer()] = (_key(obj, group), np.array(ids), np.array(weights))
