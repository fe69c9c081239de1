"""Vertex-group weights read in bulk through Geometry Nodes (Blender 4+).

Blender's Python API has no bulk read of vertex groups: visiting every vertex costs ~14 ms
on 25k vertices in 4.5 (~6 ms in 3.4). Geometry Nodes see a vertex group as a float
attribute on points, so a throwaway object holding a copy of the mesh and a node group that
stores each group under a plain attribute name, evaluated once, hands every weight over in
one ``foreach_get``: ~1 ms on 25k vertices in Blender 4.2, 4.5 and 5.0, where a mesh copy
shares its arrays. In 3.4 the copy and its evaluation cost about what the visit costs
(5.6 ms), so :func:`members` declines there and the visit stays.

The copy keeps the object's own mesh out of the depsgraph update (nothing the add-on keeps
for it is dropped), and the object, the copy and the node group are removed before
:func:`members` returns. Adding and removing them makes Blender rebuild the relations of
the whole depsgraph twice, a cost that grows with the scene (4.5, 25k vertices, read and
rebuilds: 1.8 ms with 4 objects, 4.7 with 104, 15 with 304, 84 with 1004). So the read is
used only where it is expected to cost less than the visit (:func:`worth_it`:
:data:`VISIT_US` per vertex against :func:`expected_us` of the view layer's objects), and
each read measures its cost against that estimate, so a scene whose objects cost more to
relate (modifiers, drivers, constraints) raises the estimate for the next."""

import time

import bpy
import numpy as np

#: The first Blender whose mesh copies share their arrays, where this read pays.
MIN_VERSION = (4, 0, 0)
#: Modes in which the mesh holds the groups as they are (Edit mode keeps its edits apart).
READ_MODES = ('OBJECT', 'WEIGHT_PAINT')
#: Microseconds of CPU the visit of one vertex costs (4.5: 14-15 ms on 25k vertices).
VISIT_US = 0.55
#: Microseconds of CPU of this read in an empty scene, and what ``k`` objects of the view
#: layer add: ``OBJECT_US * k + PAIR_US * k**2`` (the two relation rebuilds; fitted to 4.5
#: with 4-1004 objects).
BASE_US = 1500.0
OBJECT_US = 30.0
PAIR_US = 0.05
#: The fewest objects with which a read's cost rescales the estimate (in a smaller scene
#: the rebuilds are lost in the rest).
MIN_OBJECTS = 50
# Reads made through Geometry Nodes (for tests).
READS = [0]
# What the last read cost over what the estimate said of the objects (at least 1).
_SCALE = [1.0]


def expected_us(objects):
    """The expected CPU microseconds of a read with ``objects`` objects in the view layer."""
    return BASE_US + _SCALE[0] * (OBJECT_US * objects + PAIR_US * objects * objects)


def worth_it(context, n_vertices):
    """True when a read of a mesh of ``n_vertices`` through Geometry Nodes is expected to
    cost less than the visit in the current scene."""
    return expected_us(len(context.view_layer.objects)) < VISIT_US * n_vertices


def members(context, obj, groups):
    """``{name: (ids, weights)}`` of each of ``groups`` of ``obj``, as
    :func:`~.meshdata.groups_members` gives it (the vertices of weight above zero by id,
    their weights as float64), or ``None`` when this read does not apply: Blender before
    :data:`MIN_VERSION`, a mode outside :data:`READ_MODES`, shape keys (a copy would copy
    them too), a group named like one of the mesh's attributes (the name would be
    ambiguous), a scene where the visit is expected to cost less (:func:`worth_it`), or
    any failure. Evaluates the view layer's pending updates."""
    me = obj.data
    if (bpy.app.version < MIN_VERSION or obj.mode not in READ_MODES or me.is_editmode
            or me.shape_keys is not None or not groups
            or any(me.attributes.get(g.name) is not None for g in groups)
            or not worth_it(context, len(me.vertices))):
        return None
    n = len(me.vertices)
    objects = len(context.view_layer.objects)
    start = time.process_time()
    made = []  # removed in reverse order whatever happens
    try:
        tree = _node_tree([g.name for g in groups])
        made.append((bpy.data.node_groups, tree))
        copy = me.copy()
        made.append((bpy.data.meshes, copy))
        reader = bpy.data.objects.new(".wavg_group_read", copy)
        made.append((bpy.data.objects, reader))
        context.scene.collection.objects.link(reader)
        reader.modifiers.new("wavg_group_read", 'NODES').node_group = tree
        evaluated = reader.evaluated_get(context.evaluated_depsgraph_get()).data
        if len(evaluated.vertices) != n:
            return None
        out = {}
        for k, g in enumerate(groups):
            attr = evaluated.attributes.get(_stored(k))
            if attr is None or attr.domain != 'POINT' or attr.data_type != 'FLOAT':
                return None
            w = np.empty(n, dtype=np.float32)
            attr.data.foreach_get("value", w)
            ids = np.flatnonzero(w > 0.0)
            out[g.name] = (ids.astype(np.int64), w[ids].astype(np.float64))
        READS[0] += 1
        return out
    except Exception:  # noqa: BLE001 (the caller visits the vertices instead)
        return None
    finally:
        for collection, item in reversed(made):
            try:
                collection.remove(item)
            except Exception:  # noqa: BLE001 (already gone: nothing left to remove)
                pass
        try:
            context.view_layer.update()  # the second rebuild, counted here
        except Exception:  # noqa: BLE001 (the next update does it)
            pass
        if objects >= MIN_OBJECTS:
            spent = 1e6 * (time.process_time() - start)
            model = OBJECT_US * objects + PAIR_US * objects * objects
            _SCALE[0] = max(1.0, (spent - BASE_US) / model)


def _stored(k):
    """The attribute the ``k``-th group's weights are stored under."""
    return f"wavg_group_read_{k}"


def _node_tree(names):
    """A Geometry Nodes tree storing the weights of each vertex group of ``names`` as the
    float point attribute :func:`_stored` of its position."""
    tree = bpy.data.node_groups.new(".wavg_group_read", 'GeometryNodeTree')
    tree.interface.new_socket("Geometry", in_out='INPUT', socket_type='NodeSocketGeometry')
    tree.interface.new_socket("Geometry", in_out='OUTPUT', socket_type='NodeSocketGeometry')
    geometry = tree.nodes.new('NodeGroupInput').outputs[0]
    for k, name in enumerate(names):
        read = tree.nodes.new('GeometryNodeInputNamedAttribute')
        read.data_type = 'FLOAT'
        read.inputs["Name"].default_value = name
        store = tree.nodes.new('GeometryNodeStoreNamedAttribute')
        store.data_type = 'FLOAT'
        store.domain = 'POINT'
        store.inputs["Name"].default_value = _stored(k)
        tree.links.new(geometry, store.inputs["Geometry"])
        tree.links.new(_enabled(read.outputs, "Attribute"), _enabled(store.inputs, "Value"))
        geometry = store.outputs["Geometry"]
    tree.links.new(geometry, tree.nodes.new('NodeGroupOutput').inputs[0])
    return tree


def _enabled(sockets, name):
    """The socket called ``name`` that the node's data type enables."""
    return next(s for s in sockets if s.name == name and s.enabled)
