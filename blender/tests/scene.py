"""Scene helpers of the headless tests: meshes built in code, selections, a snapshot of
everything an operator could change, and surface-distance checks."""

import math

import bmesh
import bpy
import numpy as np


def clear():
    """Removes every object and data block the tests make, leaving an empty scene."""
    if bpy.context.view_layer.objects.active is not None and bpy.context.object.mode != 'OBJECT':
        bpy.ops.object.mode_set(mode='OBJECT')
    for coll in (bpy.data.objects, bpy.data.meshes, bpy.data.curves, bpy.data.images,
                 bpy.data.materials):
        for block in list(coll):
            coll.remove(block)


def link(name, bm):
    """A mesh object ``name`` from ``bm`` (freed), linked to the scene."""
    me = bpy.data.meshes.new(name)
    bm.to_mesh(me)
    bm.free()
    obj = bpy.data.objects.new(name, me)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def icosphere(name, subdivisions=3, radius=1.0, scale=(1.0, 1.0, 1.0)):
    """An icosphere (with UVs), optionally scaled per axis in its mesh data."""
    bm = bmesh.new()
    bm.loops.layers.uv.new("UVMap")
    bmesh.ops.create_icosphere(bm, subdivisions=subdivisions, radius=radius, calc_uvs=True)
    bmesh.ops.scale(bm, vec=scale, verts=bm.verts)
    return link(name, bm)


def uv_sphere(name, u=32, v=16, radius=1.0):
    """A UV sphere with its UV layout."""
    bm = bmesh.new()
    bm.loops.layers.uv.new("UVMap")
    bmesh.ops.create_uvsphere(bm, u_segments=u, v_segments=v, radius=radius, calc_uvs=True)
    return link(name, bm)


def fin():
    """Three triangles sharing one edge: not a manifold."""
    bm = bmesh.new()
    a, b = bm.verts.new((0, 0, 0)), bm.verts.new((1, 0, 0))
    for p in ((0.5, 1, 0), (0.5, -1, 0), (0.5, 0, 1)):
        bm.faces.new((a, b, bm.verts.new(p)))
    return link("fin", bm)


def activate(obj, *others):
    """``obj`` active and selected (with ``others``), in Object mode."""
    if bpy.context.object is not None and bpy.context.object.mode != 'OBJECT':
        bpy.ops.object.mode_set(mode='OBJECT')
    for o in bpy.context.view_layer.objects:
        o.select_set(False)
    for o in (obj, *others):
        o.select_set(True)
    bpy.context.view_layer.objects.active = obj


def select_in_order(obj, ids, edit=True):
    """Selects vertices ``ids`` one by one (select history) in Edit mode; back to Object
    mode unless ``edit``."""
    activate(obj)
    bpy.ops.object.mode_set(mode='EDIT')
    bm = bmesh.from_edit_mesh(obj.data)
    bm.verts.ensure_lookup_table()
    for v in bm.verts:
        v.select_set(False)
    bm.select_history.clear()
    for i in ids:
        bm.verts[int(i)].select_set(True)
        bm.select_history.add(bm.verts[int(i)])
    bmesh.update_edit_mesh(obj.data)
    if not edit:
        bpy.ops.object.mode_set(mode='OBJECT')


def nearest_vertices(obj, directions):
    """The vertex farthest along each direction (distinct extreme points of a shape)."""
    V = arrays(obj)[0]
    return [int(np.argmax(V @ np.asarray(d, dtype=np.float64))) for d in directions]


def arrays(obj):
    """``(V, F)`` as the add-on reads them (float32 positions as float64, loop triangles)."""
    me = obj.data
    V = np.empty(len(me.vertices) * 3, dtype=np.float32)
    me.vertices.foreach_get("co", V)
    me.calc_loop_triangles()
    F = np.empty(len(me.loop_triangles) * 3, dtype=np.int32)
    me.loop_triangles.foreach_get("vertices", F)
    return V.reshape(-1, 3).astype(np.float64), F.reshape(-1, 3).astype(np.int64)


def diagonal(obj):
    V = arrays(obj)[0]
    return float(np.linalg.norm(V.max(axis=0) - V.min(axis=0)))


def surface_distance(obj, points):
    """Largest distance of ``points`` (object space of ``obj``) to its surface."""
    worst = 0.0
    for p in points:
        ok, loc, _normal, _face = obj.closest_point_on_mesh(tuple(float(x) for x in p))
        assert ok, f"no closest point on '{obj.name}' for {p}"
        worst = max(worst, float(np.linalg.norm(np.array(loc) - np.asarray(p))))
    return worst


def circle_uv(obj, ids, name="wavg_uv"):
    """Puts the vertices ``ids`` on a circle of the (u, v) square, in order (centre
    (0.5, 0.5), radius 0.5), as the 2-D point attribute ``name`` (the decal's anchors;
    other vertices get (0, 0)); returns the ``(n, 2)`` values."""
    attr = obj.data.attributes.new(name, 'FLOAT2', 'POINT')
    uv = np.zeros((len(obj.data.vertices), 2), dtype=np.float32)
    for k, i in enumerate(ids):
        t = 2 * math.pi * k / len(ids)
        uv[i] = (0.5 + 0.5 * math.cos(t), 0.5 + 0.5 * math.sin(t))
    attr.data.foreach_set("vector", uv.ravel())
    return uv


def curve_points(curve_obj):
    """All points of a poly curve ``(q, 3)`` in its object space."""
    out = []
    for sp in curve_obj.data.splines:
        co = np.empty(len(sp.points) * 4, dtype=np.float32)
        sp.points.foreach_get("co", co)
        out.append(co.reshape(-1, 4)[:, :3])
    return np.concatenate(out).astype(np.float64)


def group_ids(obj, name):
    """Vertex ids in vertex group ``name`` (by id)."""
    g = obj.vertex_groups[name]
    return sorted(v.index for v in obj.data.vertices for x in v.groups if x.group == g.index)


# Attributes Blender itself adds or drops when a mesh goes in and out of Edit mode (4.x).
BUILTIN_ATTRIBUTES = {"position", "sharp_face", "sharp_edge", "material_index"}


def internal_attribute(name):
    return name.startswith(".") or name in BUILTIN_ATTRIBUTES


def snapshot():
    """Everything the operators may change, as comparable values."""
    snap = {}
    for o in bpy.data.objects:
        snap["object " + o.name] = (
            o.type,
            o.parent.name if o.parent else None,
            tuple(round(x, 7) for x in o.location),
            sorted(k for k in o.keys() if not k.startswith("_")),
            [(g.name, tuple(group_ids(o, g.name))) for g in o.vertex_groups],
            [s.material.name if s.material else None for s in o.material_slots],
        )
    for m in bpy.data.meshes:
        co = np.empty(len(m.vertices) * 3, dtype=np.float32)
        m.vertices.foreach_get("co", co)
        keys = [k.name for k in m.shape_keys.key_blocks] if m.shape_keys else []
        snap["mesh " + m.name] = (
            len(m.vertices),
            co.tobytes(),
            [u.name for u in m.uv_layers],
            sorted(a.name for a in m.attributes if not internal_attribute(a.name)),
            keys,
        )
    for c in bpy.data.curves:
        snap["curve " + c.name] = [len(s.points) for s in c.splines]
    for kind in ("images", "materials"):
        snap[kind] = sorted(x.name for x in getattr(bpy.data, kind))
    return snap


def diff(a, b):
    """The keys whose values differ between two snapshots."""
    return sorted(k for k in set(a) | set(b) if a.get(k) != b.get(k))


def describe_change(a, b):
    """Which parts of a snapshot value differ."""
    if isinstance(a, tuple) and isinstance(b, tuple) and len(a) == len(b):
        return ", ".join(f"[{i}] {x!r:.120} -> {y!r:.120}" for i, (x, y) in enumerate(zip(a, b))
                         if x != y)
    return f"{a!r:.120} -> {b!r:.120}"
