"""Members of vertex groups kept between operator runs (a :mod:`.memo` store). Blender has
no bulk read of vertex groups: a read goes through Geometry Nodes where that pays
(:mod:`.group_read`, ~1 ms on 25k vertices in 4.x) and visits every vertex from Python
elsewhere (~6 ms in 3.4); a decal run again on the same anchors reads them from here, and
finds its ``wavg_invalid`` group already holding what it would write. An entry is used only for an
object in Object mode whose mesh and vertex count are those it was read with, and a group
whose index and name are; writers evaluate their own writes before storing (:func:`keep`)."""

import numpy as np

from . import group_read, memo
from .meshdata import groups_members

# Object pointer -> (key, {group name: (group index, ids, weights)}).
_ENTRIES = memo.store()
# How many reads were answered wholly from memory (for tests).
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
    return members_of(context, obj, [group])[group.name]


def members_of(context, obj, groups):
    """``{name: (ids, weights)}`` of each of ``groups``: from memory where the entry is
    still valid, the others read together (:mod:`.group_read`, else one visit of the
    vertices) and remembered (Object mode only; the read is of the settled mesh, so it stays valid until the next geometry
    update)."""
    memo.settle(context)
    out, missing = {}, []
    for g in groups:
        got = known(obj, g)
        if got is None:
            missing.append(g)
        else:
            out[g.name] = got
    if not missing:
        HITS[0] += 1
    else:
        read = group_read.members(context, obj, missing)
        if read is None:
            read = groups_members(obj, missing)
        out.update(read)
        if obj.mode == 'OBJECT':
            _remember(obj, read)
    return out


def _remember(obj, groups):
    """Adds ``groups`` (``{name: (ids, weights)}``, read or written just now) to ``obj``'s
    entry, starting a new entry when the old one no longer matches the object."""
    key = memo.identity(obj)
    entry = _ENTRIES.get(obj.as_pointer())
    kept = entry[1] if entry is not None and entry[0] == key else {}
    for name, (ids, weights) in groups.items():
        group = obj.vertex_groups.get(name)
        if group is not None:
            kept[name] = (group.index, np.array(ids), np.array(weights))
    _ENTRIES[obj.as_pointer()] = (key, kept)


def keep(context, obj, groups):
    """After an operator wrote ``obj``'s mesh: evaluates those writes (dropping the old
    entry), then remembers ``groups`` (``{name: (ids, weights)}``) as the members of those
    vertex groups."""
    memo.settle(context)
    if obj.mode != 'OBJECT':
        return
    _ENTRIES.pop(obj.as_pointer(), None)
    _remember(obj, groups)
