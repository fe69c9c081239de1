"""Members of vertex groups kept between operator runs (a :mod:`.memo` store). Blender 3.4
has no bulk read of vertex groups, so reading one visits every vertex from Python (~9 ms on
25k vertices): a decal run again on the same anchors reads them from here, and finds its
``wavg_invalid`` group already holding what it would write. An entry is used only for an
object in Object mode whose mesh and vertex count are those it was read with, and a group
whose index and name are; writers evaluate their own writes before storing (:func:`keep`)."""

import numpy as np

from . import memo
from .meshdata import group_members

# Object pointer -> (key, {group name: (group index, ids, weights)}).
_ENTRIES = memo.store()
# How many reads were answered from memory (for tests).
HITS = [0]


def known(obj, group):
    """``(ids, weights)`` of ``group`` as last read or written, when still valid, else
    ``None`` (pending updates must have been evaluated: :func:`members` does)."""
    entry = _ENTRIES.get(obj.as_pointer())
    if obj.mode != 'OBJECT' or entry is None or entry[0] != memo.identity(obj):
        return None
    got = entry[1].get(group.name)
    if got is None or got[0] != group.index:
        return None
    return got[1].copy(), got[2].copy()


def members(context, obj, group):
    """``(ids, weights)`` of the members of ``group`` with a weight above zero (as
    :func:`~.meshdata.group_members`), from memory when the entry is still valid."""
    memo.settle(context)
    got = known(obj, group)
    if got is not None:
        HITS[0] += 1
        return got
    return group_members(obj, group)


def keep(context, obj, groups):
    """After an operator wrote ``obj``'s mesh: evaluates those writes (dropping the old
    entry), then remembers ``groups`` (``{name: (ids, weights)}``) as the members of those
    vertex groups."""
    memo.settle(context)
    if obj.mode != 'OBJECT':
        return
    entry = {}
    for name, (ids, weights) in groups.items():
        group = obj.vertex_groups.get(name)
        if group is not None:
            entry[name] = (group.index, np.array(ids), np.array(weights))
    _ENTRIES[obj.as_pointer()] = (memo.identity(obj), entry)
