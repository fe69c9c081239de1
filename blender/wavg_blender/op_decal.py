"""``wavg.decal_uv``: a UV layer from anchors (the vertices of a vertex group) and their
(u, v) (a 2-D point attribute); vertices whose weights are not meaningful go into the
vertex group ``wavg_invalid``."""

import bpy
import numpy as np

from . import decal_memo, group_cache, surfaces
from .common import ActiveMeshOperator, active_mesh, object_mode
from .errors import AddonError, describe, wavg
from .meshdata import corner_vertices, point_attribute_2d, vertex_group

INVALID_GROUP = "wavg_invalid"
MAX_UV_LAYERS = 8


def set_uv_layer(obj, name, per_vertex_uv):
    """Writes ``per_vertex_uv`` ``(n, 2)`` to UV layer ``name`` (created when missing) of
    ``obj`` in Object mode: every loop gets its vertex's coordinates. Blender 3.5+ keeps a
    UV layer as a 2-D corner attribute, written through it in bulk (the layer's ``uv``
    converts per item there: ~4 ms on 100k loops in 4.5, 0.02 through the attribute)."""
    me = obj.data
    active = me.uv_layers.active_index
    layer = me.uv_layers.get(name) or me.uv_layers.new(name=name, do_init=False)
    if active >= 0:
        me.uv_layers.active_index = active
    loop_vertex = corner_vertices(me)
    uv = np.ascontiguousarray(per_vertex_uv[loop_vertex], dtype=np.float32).ravel()
    attr = me.attributes.get(layer.name)
    if attr is not None and attr.domain == 'CORNER' and attr.data_type == 'FLOAT2':
        attr.data.foreach_set("vector", uv)
    else:
        layer.data.foreach_set("uv", uv)
    me.update()


def check_uv_layer_room(obj, name):
    if obj.data.uv_layers.get(name) is None and len(obj.data.uv_layers) >= MAX_UV_LAYERS:
        raise AddonError(
            f"'{obj.name}' already has {MAX_UV_LAYERS} UV layers, Blender's limit; remove one"
        )


def set_invalid_group(obj, ids, known=None):
    """Vertex group ``wavg_invalid`` of ``obj`` holds exactly ``ids`` (weight 1). When
    ``known`` (its members as :func:`.group_cache.known` gives them) says what it holds,
    only the difference is written (nothing when there is none; a decal after a small
    edit changes a few hundred of its ~20k members; a member of weight 0 counts as absent,
    as everywhere in the add-on); else it is made anew."""
    ids = np.asarray(ids, dtype=np.int64)
    old = obj.vertex_groups.get(INVALID_GROUP)
    if old is not None and known is not None:
        held = known[0][known[1] == 1.0]
        gone = np.setdiff1d(known[0], ids, assume_unique=True)
        new = np.setdiff1d(ids, held, assume_unique=True)
        if len(gone):
            old.remove(gone.tolist())
        if len(new):
            old.add(new.tolist(), 1.0, 'REPLACE')
        return
    if old is not None:
        obj.vertex_groups.remove(old)
    group = obj.vertex_groups.new(name=INVALID_GROUP)
    if len(ids):
        group.add(ids.tolist(), 1.0, 'REPLACE')


class WAVG_OT_decal_uv(ActiveMeshOperator, bpy.types.Operator):
    """Make a UV layer from anchor vertices (a vertex group) and their (u, v) (a 2-D point
    attribute); vertices without meaningful coordinates go into vertex group wavg_invalid"""

    bl_idname = "wavg.decal_uv"
    bl_label = "Decal UV"
    bl_options = {'REGISTER', 'UNDO'}

    group: bpy.props.StringProperty(
        name="Anchors", default="wavg_anchors", description="Vertex group of the anchors"
    )
    attribute: bpy.props.StringProperty(
        name="UV attribute", default="wavg_uv", description="2-D point attribute with their (u, v)"
    )
    uv_layer: bpy.props.StringProperty(
        name="UV layer", default="wavg_decal", description="UV layer written"
    )

    def _run(self, context):
        obj = active_mesh(context)
        if not self.uv_layer:
            raise AddonError("give the name of the UV layer to write")
        surface, mesh = surfaces.surface_of(obj)
        anchors, weights = group_cache.members(context, obj, vertex_group(obj, self.group))
        old_invalid = obj.vertex_groups.get(INVALID_GROUP)
        if old_invalid is not None:
            old_invalid = group_cache.known(obj, old_invalid)
        if len(anchors) < 3:
            raise AddonError(
                f"too few anchors: vertex group '{self.group}' holds {len(anchors)} "
                "vertices; a decal needs at least 3"
            )
        anchor_uv = point_attribute_2d(obj, self.attribute)[anchors]
        if not np.all(np.isfinite(anchor_uv)):
            raise AddonError(f"attribute '{self.attribute}' is not finite at every anchor")
        check_uv_layer_room(obj, self.uv_layer)
        w = wavg()
        try:
            uv, valid = decal_memo.decal(obj, surface, anchors, anchor_uv)
        except (w.WavgError, ValueError, TypeError) as e:
            raise AddonError(f"wavg cannot make this decal: {describe(e)}") from e
        decal_memo.remember_settings(obj, self.group, self.attribute)
        with object_mode(context):
            set_uv_layer(obj, self.uv_layer, np.where(np.isfinite(uv), uv, 0.0))
            invalid = np.flatnonzero(~valid)
            set_invalid_group(obj, invalid, old_invalid)
        # What was written is known; neither write changed the geometry read.
        kept = {INVALID_GROUP: (invalid, np.ones(len(invalid)))}
        if self.group != INVALID_GROUP:
            kept[self.group] = (anchors, weights)
        group_cache.keep(context, obj, kept)
        surfaces.keep_mesh(obj, mesh)
        fraction = float(valid.mean())
        self.report(
            {'INFO'},
            f"UV layer '{self.uv_layer}': {fraction:.1%} of the vertices valid, "
            f"{int((~valid).sum())} in '{INVALID_GROUP}'",
        )
        return {'FINISHED'}
