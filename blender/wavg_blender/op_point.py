"""``wavg.place_point``: an Empty ``wavg_point`` at the weighted average of the selected
vertices, child of the mesh, kept on the surface when the vertex-group weights change (see
``live.py``)."""

import bpy
import numpy as np

from . import surfaces
from .common import ActiveMeshOperator, active_mesh
from .errors import AddonError, describe, wavg
from .meshdata import selected_vertices, vertex_group, weights_of


def average(surface, anchors, weights):
    """The weighted average of the anchor vertices as a ``wavg.Points`` of one row; the
    weights are normalised to sum to 1."""
    total = float(np.sum(weights))
    if not np.isfinite(total) or total <= 0.0:
        raise AddonError(
            "the weights of the selected vertices sum to zero: give some of them a weight "
            "in the vertex group"
        )
    w = wavg()
    try:
        pts = w.Solver(surface, anchors).forward(np.asarray(weights, dtype=np.float64)[None, :] / total)
    except (w.WavgError, ValueError, TypeError) as e:
        raise AddonError(f"wavg cannot average these vertices: {describe(e)}") from e
    if not bool(pts.ok[0]):
        raise AddonError("these weights have no average on the surface (the projection failed)")
    return pts


def anchor_weights(obj, anchors, group):
    """The weights of the anchors: from vertex group ``group``, uniform when it is empty."""
    if not group:
        return np.ones(len(anchors))
    return weights_of(vertex_group(obj, group), anchors)


class WAVG_OT_place_point(ActiveMeshOperator, bpy.types.Operator):
    """Add an Empty at the weighted average of the selected vertices on the surface (weights
    from a vertex group, uniform without one); it follows when the weights change"""

    bl_idname = "wavg.place_point"
    bl_label = "Place Weighted Average"
    bl_options = {'REGISTER', 'UNDO'}

    group: bpy.props.StringProperty(
        name="Weights", default="", description="Vertex group with the weights (empty: uniform)"
    )

    def _run(self, context):
        obj = active_mesh(context)
        surface, mesh = surfaces.surface_of(obj)
        _, selected = selected_vertices(obj, ordered=False)
        if len(selected) == 0:
            raise AddonError("select at least one vertex of the mesh (in Edit mode)")
        anchors = np.array(selected, dtype=np.int64)
        weights = anchor_weights(obj, anchors, self.group)
        pts = average(surface, anchors, weights)

        empty = bpy.data.objects.new("wavg_point", None)
        empty.empty_display_type = 'SPHERE'
        empty.empty_display_size = max(0.015 * mesh.diagonal, 1e-6)
        for coll in obj.users_collection[:1] or [context.scene.collection]:
            coll.objects.link(empty)
        empty.parent = obj
        empty.matrix_parent_inverse.identity()
        empty.location = pts.xyz[0]
        empty["wavg_mesh"] = obj
        empty["wavg_key"] = mesh.key
        empty["wavg_group"] = self.group
        empty["wavg_anchors"] = [int(a) for a in anchors]
        empty["wavg_weights"] = [float(x) for x in weights]
        empty["wavg_face"] = int(pts.face[0])
        empty["wavg_bary"] = [float(x) for x in pts.bary[0]]
        self.report({'INFO'}, f"{empty.name} at the average of {len(anchors)} vertices")
        return {'FINISHED'}


def follow_weights(empty):
    """Moves a ``wavg_point`` Empty to the average of its anchors under the current weights
    of its vertex group; True when it moved. Used by the depsgraph handler."""
    obj = empty.get("wavg_mesh")
    group = empty.get("wavg_group", "")
    if obj is None or not group or obj.vertex_groups.get(group) is None:
        return False
    surface = surfaces.cached(empty.get("wavg_key", ""))
    if surface is None:
        return False
    anchors = np.array(empty["wavg_anchors"], dtype=np.int64)
    weights = weights_of(obj.vertex_groups[group], anchors)
    if np.array_equal(weights, np.array(empty["wavg_weights"], dtype=np.float64)):
        return False
    try:
        pts = average(surface, anchors, weights)
    except AddonError:
        return False
    empty.location = pts.xyz[0]
    empty["wavg_weights"] = [float(x) for x in weights]
    empty["wavg_face"] = int(pts.face[0])
    empty["wavg_bary"] = [float(x) for x in pts.bary[0]]
    return True
