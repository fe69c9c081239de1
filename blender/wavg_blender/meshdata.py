"""Reading a Blender mesh as wavg sees it: vertex positions (object space), the loop
triangles as faces, the fingerprint that keys the embedding cache, the selection (in
selection order), vertex groups, point attributes and UV layers. Nothing here changes the
scene."""

import hashlib
from functools import cached_property

import bmesh
import numpy as np

from .errors import AddonError


class MeshInput:
    """A mesh object's geometry as arrays.

    ``V`` ``(n, 3)`` float64 object-space positions, ``F`` ``(m, 3)`` int64 vertex ids of
    the loop triangles (Blender's triangulation of the polygons, so vertex ids are the
    mesh's own), ``tri_loops`` ``(m, 3)`` their loop ids (for UVs), ``key`` the fingerprint.
    """

    def __init__(self, obj):
        if obj is None or obj.type != 'MESH':
            raise AddonError("the active object must be a mesh")
        if obj.mode == 'EDIT':
            obj.update_from_editmode()
        me = obj.data
        n = len(me.vertices)
        co = positions(me)
        me.calc_loop_triangles()
        m = len(me.loop_triangles)
        if n == 0 or m == 0:
            raise AddonError(f"'{obj.name}' has no faces: wavg needs a triangle mesh surface")
        self._tri_loops = None
        self._topology = topology(me)
        if len(self._topology) == 2:  # Blender 4: triangles' loops and loops' vertices
            loops = np.empty(m * 3, dtype=np.uint32)
            me.loop_triangles.foreach_get("loops", loops)
            tris = self._topology[1][loops]
            self._tri_loops = loops.reshape(m, 3).astype(np.int64)
        else:
            # uint32 buffers: Blender's index type, read without a per-item conversion.
            tris = np.empty(m * 3, dtype=np.uint32)
            me.loop_triangles.foreach_get("vertices", tris)
        self.obj = obj
        self.name = obj.name
        self.key = fingerprint(co, tris)
        self.V = co.reshape(n, 3).astype(np.float64)
        self.F = tris.reshape(m, 3).astype(np.int64)
        self._co = co

    def unchanged(self, obj):
        """True when ``obj`` (in Object mode) still has this mesh: the same positions and
        polygons (so the same triangulation and fingerprint). A check in bulk (~0.5 ms on
        25k vertices) instead of a read and a hash (~2.5 ms): after an edit of anything
        else (a vertex group, Weight Paint) the mesh need not be read again."""
        if (obj is None or obj != self.obj or obj.name != self.name or obj.type != 'MESH'
                or obj.mode != 'OBJECT'):
            return False
        me = obj.data
        if len(me.vertices) * 3 != len(self._co):
            return False
        if not np.array_equal(positions(me), self._co):
            return False
        now = topology(me)
        return all(len(a) == len(b) and np.array_equal(a, b)
                   for a, b in zip(now, self._topology))

    @property
    def tri_loops(self):
        """``(m, 3)`` loop ids of the triangles (read on first use: only UVs need them)."""
        if self._tri_loops is None:
            loops = np.empty(len(self.F) * 3, dtype=np.uint32)
            self.obj.data.loop_triangles.foreach_get("loops", loops)
            self._tri_loops = loops.reshape(-1, 3).astype(np.int64)
        return self._tri_loops

    @cached_property
    def diagonal(self):
        """Length of the bounding-box diagonal (object space; computed once)."""
        return float(np.linalg.norm(self.V.max(axis=0) - self.V.min(axis=0)))


def positions(me):
    """The vertex positions of ``me``, flat float32: Blender 4's ``position`` attribute
    (read in bulk) or the vertices' ``co`` (Blender 3, where that is the bulk read)."""
    co = np.empty(len(me.vertices) * 3, dtype=np.float32)
    attr = me.attributes.get("position")
    if attr is not None and attr.domain == 'POINT' and attr.data_type == 'FLOAT_VECTOR':
        attr.data.foreach_get("vector", co)
    else:
        me.vertices.foreach_get("co", co)
    return co


def corner_vertices(me):
    """The vertex of each loop of ``me`` as uint32: Blender 4's ``.corner_vert``
    attribute (int32, read in bulk; ``vertex_index`` converts per item there, ~3 ms on
    100k loops), else the loops' ``vertex_index`` (uint32, Blender 3's bulk read)."""
    attr = me.attributes.get(".corner_vert")
    if attr is not None and attr.domain == 'CORNER' and attr.data_type == 'INT':
        out = np.empty(len(me.loops), dtype=np.int32)
        attr.data.foreach_get("value", out)
        return out.view(np.uint32)
    out = np.empty(len(me.loops), dtype=np.uint32)
    me.loops.foreach_get("vertex_index", out)
    return out


def topology(me):
    """The polygons of ``me`` as arrays: with the positions, what Blender's triangulation
    depends on. Blender 4 (``.corner_vert``): the polygons' loop starts (its offsets: the
    counts follow) and the loops' vertices; Blender 3: loop starts, loop counts and the
    loops' vertices. uint32 buffers are what Blender 3 reads without a per-item
    conversion (int32 ones cost 10x)."""
    starts = np.empty(len(me.polygons), dtype=np.uint32)
    me.polygons.foreach_get("loop_start", starts)
    if me.attributes.get(".corner_vert") is not None:
        return [starts, corner_vertices(me)]
    counts = np.empty(len(me.polygons), dtype=np.uint32)
    me.polygons.foreach_get("loop_total", counts)
    return [starts, counts, corner_vertices(me)]


def fingerprint(co, tris):
    """A 16-hex-digit key of the exact positions and triangles (BLAKE2b over the counts,
    Blender's float32 positions and the uint32 vertex ids of the triangles, little-endian),
    naming the cached ``.wavg`` file; the file itself carries wavg's own fingerprint of the
    mesh, checked when it is loaded."""
    h = hashlib.blake2b(digest_size=8)
    h.update(np.array([len(co) // 3, len(tris) // 3], dtype="<u8"))
    h.update(np.ascontiguousarray(co, dtype="<f4"))
    h.update(np.ascontiguousarray(tris, dtype="<u4"))
    return h.hexdigest()


def selected_vertices(obj, ordered=True):
    """``(ordered, selected)``: the selected vertices in selection order (the select
    history: ``bmesh`` in Edit mode, the order stored in the mesh in Object mode; empty when
    ``ordered`` is false, which skips reading it) and all selected vertex ids by id (a
    NumPy array).

    Read without visiting every vertex from Python: in Object mode the selection flags in
    bulk; in Edit mode, when the history holds every selected vertex (they were
    Shift-clicked), the history itself, else the flags of the mesh synced from Edit mode."""
    me = obj.data
    if obj.mode != 'EDIT':
        flags = np.zeros(len(me.vertices), dtype=bool)
        me.vertices.foreach_get("select", flags)
        selected = np.flatnonzero(flags)
        if not ordered:
            return [], selected
        if len(selected) == 0:
            return [], selected
        bm = bmesh.new()
        try:  # only the select history is read: no normals
            bm.from_mesh(me, face_normals=False, vertex_normals=False)
        except TypeError:
            bm.from_mesh(me)
        owned = True
    else:
        bm = bmesh.from_edit_mesh(me)
        owned = False
        selected = None
    try:
        bm.verts.index_update()
        history = []
        seen = set()
        for elem in bm.select_history:
            if isinstance(elem, bmesh.types.BMVert) and elem.select and elem.index not in seen:
                seen.add(elem.index)
                history.append(elem.index)
        if selected is None:
            if len(history) == me.total_vert_sel:
                selected = np.array(sorted(history), dtype=np.int64)
            else:
                obj.update_from_editmode()
                flags = np.zeros(len(me.vertices), dtype=bool)
                me.vertices.foreach_get("select", flags)
                selected = np.flatnonzero(flags)
    finally:
        if owned:
            bm.free()
    return history if ordered else [], selected


def vertex_group(obj, name):
    """The vertex group ``name`` of ``obj``, or an :class:`AddonError` listing the groups."""
    group = obj.vertex_groups.get(name)
    if group is None:
        have = ", ".join(g.name for g in obj.vertex_groups) or "none"
        raise AddonError(f"'{obj.name}' has no vertex group '{name}' (its groups: {have})")
    return group


def group_members(obj, group):
    """``(ids, weights)`` of the vertices in ``group`` with a weight above zero, by id."""
    index = group.index
    ids, weights = [], []
    for v in obj.data.vertices:
        for g in v.groups:
            if g.group == index:
                w = g.weight
                if w > 0.0:
                    ids.append(v.index)
                    weights.append(w)
                break
    return np.array(ids, dtype=np.int64), np.array(weights, dtype=np.float64)


def groups_members(obj, groups):
    """``{name: (ids, weights)}`` of each of ``groups`` as :func:`group_members` gives it,
    read in one visit of every vertex (about the cost of reading one group, ~6 ms on 25k
    vertices: Blender has no bulk read of vertex groups)."""
    if len(groups) == 1:
        return {groups[0].name: group_members(obj, groups[0])}
    slots = {g.index: ([], []) for g in groups}
    get = slots.get
    for v in obj.data.vertices:
        for g in v.groups:
            slot = get(g.group)
            if slot is not None:
                w = g.weight
                if w > 0.0:
                    slot[0].append(v.index)
                    slot[1].append(w)
    return {
        g.name: (np.array(slots[g.index][0], dtype=np.int64),
                 np.array(slots[g.index][1], dtype=np.float64))
        for g in groups
    }


def weights_of(group, ids):
    """The weight of each vertex of ``ids`` in ``group`` (0 where it is not a member)."""
    out = np.zeros(len(ids), dtype=np.float64)
    for i, v in enumerate(ids):
        try:
            out[i] = group.weight(int(v))
        except RuntimeError:
            out[i] = 0.0
    return out


def point_attribute_2d(obj, name):
    """The per-vertex 2-vector attribute ``name`` as ``(n, 2)`` float64 (a FLOAT2 attribute,
    or the first two components of a FLOAT_VECTOR one)."""
    me = obj.data
    attr = me.attributes.get(name)
    if attr is None:
        raise AddonError(f"'{obj.name}' has no attribute '{name}' (a 2-D vector on points)")
    if attr.domain != 'POINT' or attr.data_type not in ('FLOAT2', 'FLOAT_VECTOR'):
        raise AddonError(
            f"attribute '{name}' of '{obj.name}' is {attr.data_type} on {attr.domain}; "
            "it must be a 2-D vector (FLOAT2) on points"
        )
    width = 2 if attr.data_type == 'FLOAT2' else 3
    flat = np.empty(len(me.vertices) * width, dtype=np.float32)
    attr.data.foreach_get("vector", flat)
    return flat.reshape(-1, width)[:, :2].astype(np.float64)


def uv_corners(obj, tri_loops, layer=None):
    """``(uv, uv_faces)``: the UV layer's coordinates per loop ``(loops, 2)`` and the loop
    ids of each triangle ``(m, 3)`` (a wavg texture-coordinate pair), or ``None`` when the
    mesh has no UV layer."""
    me = obj.data
    uv_layer = me.uv_layers.get(layer) if layer else me.uv_layers.active
    if uv_layer is None:
        return None
    flat = np.empty(len(me.loops) * 2, dtype=np.float32)
    uv_layer.data.foreach_get("uv", flat)
    return flat.reshape(-1, 2).astype(np.float64), tri_loops
