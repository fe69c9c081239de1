"""What the add-on read from an object and keeps until the object's geometry changes: the
mesh as arrays with its fingerprint (``mesh_input``), the members of anchor vertex groups
(``group_cache``). Reading a 25k-vertex mesh and hashing it costs 3-10 ms, syncing it out
of Edit mode as much again, and Blender 3.4 has no bulk read of vertex groups.

Each store maps an object's pointer to an entry whose first item is a key starting with
:func:`identity`; an entry is used only when that key still matches. Entries are dropped
when the depsgraph reports a geometry update of the object or its mesh (every edit of the
mesh or of its vertex groups, in any mode, tags one), on undo, redo and file load. Readers
evaluate pending updates first (:func:`settle`), so no edit can slip between an entry and
the data it describes."""

import bpy
from bpy.app.handlers import persistent

# The stores (dicts: object pointer -> (key, ...)) whose entries the handlers drop.
_STORES = []
# Stores emptied only on undo, redo, file load and `forget_all` (their users check an
# entry's data before using it).
_RELOAD_STORES = []


def store():
    """A new store, emptied with the others."""
    entries = {}
    _STORES.append(entries)
    return entries


def reload_store():
    """A new store that survives geometry updates (its user checks each entry) and is
    emptied on undo, redo and file load, which replace the data its entries refer to."""
    entries = {}
    _RELOAD_STORES.append(entries)
    return entries


def identity(obj):
    """The start of every key: the object and its mesh as they are now (item 2 is the
    mesh's pointer, by which a geometry update of the mesh drops the entry)."""
    me = obj.data
    return (obj.name, getattr(obj, "session_uid", 0), me.as_pointer(), len(me.vertices),
            obj.mode)


def settle(context):
    """Evaluates pending updates, so that the handler drops what they made stale."""
    context.view_layer.update()


def forget_all():
    """Drops every entry of every store."""
    for entries in _STORES + _RELOAD_STORES:
        entries.clear()


def _original(idb):
    return getattr(idb, "original", idb)


@persistent
def on_depsgraph_update(scene, depsgraph):
    """Drops the entries of objects and meshes whose geometry changed."""
    if not any(_STORES):
        return
    changed = {_original(u.id).as_pointer() for u in depsgraph.updates if u.is_updated_geometry}
    if not changed:
        return
    for entries in _STORES:
        for ptr, entry in list(entries.items()):
            if ptr in changed or entry[0][2] in changed:
                del entries[ptr]


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
