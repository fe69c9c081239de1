"""What every operator shares: reporting errors instead of raising them, Object mode while
mesh data is written, anchors given as surface points, closest points on a surface."""

import traceback
from contextlib import contextmanager

import bpy
import numpy as np
from mathutils import Vector
from mathutils.interpolate import poly_3d_calc

from .errors import AddonError, describe


def guarded(op, step):
    """Runs ``step()`` (which returns the operator's result set); an :class:`AddonError` or
    any other exception becomes ``self.report({'ERROR'}, ...)`` and ``{'CANCELLED'}``.
    Operators validate and compute everything before they change the scene, so a
    cancelled operator has changed nothing."""
    try:
        return step()
    except AddonError as e:
        op.report({'ERROR'}, str(e))
    except Exception as e:  # wavg or Blender failed unexpectedly: report, never crash
        traceback.print_exc()
        op.report({'ERROR'}, f"wavg failed: {describe(e)}")
    return {'CANCELLED'}


class ActiveMeshOperator:
    """Mix-in of the operators that work on the active mesh object: available when the
    active object is a mesh; ``execute`` runs the operator's ``_run(context)`` under
    :func:`guarded`."""

    @classmethod
    def poll(cls, context):
        obj = context.view_layer.objects.active
        return obj is not None and obj.type == 'MESH'

    def execute(self, context):
        return guarded(self, lambda: self._run(context))


@contextmanager
def object_mode(context):
    """Object mode for the block (mesh data such as UV layers, vertex groups and shape keys
    is written there), then the mode the objects were in."""
    obj = context.view_layer.objects.active
    mode = obj.mode if obj is not None else 'OBJECT'
    if mode != 'OBJECT':
        bpy.ops.object.mode_set(mode='OBJECT')
    try:
        yield
    finally:
        if mode != 'OBJECT' and context.view_layer.objects.active is obj:
            bpy.ops.object.mode_set(mode=mode)


def active_mesh(context):
    """The active object, which must be a mesh."""
    obj = context.view_layer.objects.active
    if obj is None or obj.type != 'MESH':
        raise AddonError("make a mesh object active first")
    return obj


def closest_points(tree, V, F, points):
    """``(faces, bary, xyz, dist)``: for each point (object space) the closest point on the
    surface given by ``tree`` (a BVH of the triangles ``F`` over ``V``)."""
    k = len(points)
    faces = np.empty(k, dtype=np.int64)
    bary = np.empty((k, 3))
    xyz = np.empty((k, 3))
    dist = np.empty(k)
    for i, p in enumerate(points):
        loc, _normal, index, d = tree.find_nearest(p)
        if index is None:
            raise AddonError("no surface point found near a control point")
        corners = [Vector(V[j]) for j in F[index]]
        faces[i], xyz[i], dist[i] = index, loc, d
        bary[i] = poly_3d_calc(corners, loc)
    return faces, bary, xyz, dist
