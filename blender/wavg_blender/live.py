"""Live updates: a depsgraph handler that re-evaluates a ``wavg_spline`` when one of its
control Empties moves and moves a ``wavg_point`` when the weights of its vertex group
change. Nothing here raises into Blender: a failure is printed and skipped."""

import traceback

import bpy
from bpy.app.handlers import persistent

from .op_point import follow_weights
from .op_spline import follow_controls

_BUSY = [False]


def _original(idb):
    return getattr(idb, "original", idb)


@persistent
def on_depsgraph_update(scene, depsgraph):
    """Collects the moved control points and the changed meshes of this update."""
    if _BUSY[0]:
        return
    curves, meshes = {}, {}
    for u in depsgraph.updates:
        ob = _original(u.id)
        if not isinstance(ob, bpy.types.Object):
            continue
        if u.is_updated_transform and "wavg_curve" in ob:
            curve = ob["wavg_curve"]
            if curve is not None:
                curves[curve.name] = curve
        if u.is_updated_geometry and ob.type == 'MESH':
            meshes[ob.name] = ob
    if not curves and not meshes:
        return
    _BUSY[0] = True
    try:
        for curve in curves.values():
            follow_controls(curve)
        for mesh_obj in meshes.values():
            for child in mesh_obj.children:
                if "wavg_anchors" in child:
                    follow_weights(child)
    except Exception:  # a handler must never break Blender
        traceback.print_exc()
    finally:
        _BUSY[0] = False


def register():
    if on_depsgraph_update not in bpy.app.handlers.depsgraph_update_post:
        bpy.app.handlers.depsgraph_update_post.append(on_depsgraph_update)


def unregister():
    if on_depsgraph_update in bpy.app.handlers.depsgraph_update_post:
        bpy.app.handlers.depsgraph_update_post.remove(on_depsgraph_update)
