"""The decal kept and read ahead (``decal_memo``): a run whose inputs are those of the last
decal takes it, any change of the anchors or their (u, v) computes it again, and after an
edit the idle read-ahead leaves the click nothing to read or compute; every result is
``wavg.decal``'s."""

import time

import bpy
import numpy as np

import scene
from cases import decal_setup, precompute
from cases_more import check_decal


def uv_attribute(obj):
    me = obj.data
    flat = np.empty(len(me.vertices) * 2, dtype=np.float32)
    me.attributes["wavg_uv"].data.foreach_get("vector", flat)
    return flat.reshape(-1, 2)


def set_uv_attribute(obj, uv):
    obj.data.attributes["wavg_uv"].data.foreach_set("vector", uv.astype(np.float32).ravel())


def test_decal_kept(ctx):
    """Run again, or after an edit leaving the anchors as they were, the decal is taken
    from memory; a changed (u, v), a moved anchor, another surface compute it again."""
    from wavg_blender import decal_memo

    ico = scene.icosphere("ico", subdivisions=3)
    precompute(ico)
    anchors, _uv = decal_setup(ico)
    scene.activate(ico)
    taken = decal_memo.TAKEN[0]
    bpy.ops.wavg.decal_uv()
    assert decal_memo.TAKEN[0] == taken, "a first decal was found in memory"
    check_decal(ico, anchors)
    bpy.ops.wavg.decal_uv()
    assert decal_memo.TAKEN[0] == taken + 1, "the decal run again was computed again"
    check_decal(ico, anchors)
    group = ico.vertex_groups["wavg_anchors"]
    group.add([anchors[0]], 1.0, 'REPLACE')  # an edit that keeps the anchors
    bpy.ops.wavg.decal_uv()
    assert decal_memo.TAKEN[0] == taken + 2, "same anchors after an edit: not taken"
    check_decal(ico, anchors)
    uv = uv_attribute(ico)
    uv[anchors[1]] += (0.25, -0.125)  # written without an update: only the values tell
    set_uv_attribute(ico, uv)
    bpy.ops.wavg.decal_uv()
    assert decal_memo.TAKEN[0] == taken + 2, "a decal of other (u, v) was taken"
    check_decal(ico, anchors)
    moved = scene.nearest_vertices(ico, [(0.2, 0.3, 1.0)])[0]
    assert moved not in anchors
    uv[moved] = uv[anchors[0]]
    set_uv_attribute(ico, uv)
    group.remove([anchors[0]])
    group.add([moved], 1.0, 'REPLACE')
    anchors = sorted(anchors[1:] + [moved])
    bpy.ops.wavg.decal_uv()
    assert decal_memo.TAKEN[0] == taken + 2, "a decal of other anchors was taken"
    check_decal(ico, anchors)
    # Another mesh of the same anchors and (u, v): its own decal.
    other = scene.icosphere("other", subdivisions=3, scale=(1.0, 1.0, 0.8))
    precompute(other)
    other = bpy.data.objects["other"]
    group = other.vertex_groups.new(name="wavg_anchors")
    group.add(anchors, 1.0, 'REPLACE')
    other.data.attributes.new("wavg_uv", 'FLOAT2', 'POINT')
    set_uv_attribute(other, uv)
    scene.activate(other)
    bpy.ops.wavg.decal_uv()
    assert decal_memo.TAKEN[0] == taken + 2, "another surface's decal was taken"
    check_decal(other, anchors)


def test_decal_read_ahead(ctx):
    """After an edit of the anchors, the idle timer reads the anchor group, wavg_invalid
    and the (u, v) and computes the decal in a worker thread: the click then reads no group
    and computes nothing, with wavg.decal's result. Nothing is read ahead in Edit mode, for
    an object the operator never ran on, or when the decal is already there."""
    from wavg_blender import decal_memo, group_cache

    decal_memo.forget_all()  # an object of an earlier test may have had this address
    ico = scene.icosphere("ico", subdivisions=3)
    precompute(ico)
    anchors, _uv = decal_setup(ico)
    scene.activate(ico)
    assert not decal_memo.read_ahead(ico), "read ahead before the operator ever ran"
    bpy.ops.wavg.decal_uv()
    assert not decal_memo.read_ahead(ico), "read ahead though the decal is in memory"
    decal_memo._CHANGED.clear()  # the operator's own writes count as an update too
    uv = uv_attribute(ico)
    moved = scene.nearest_vertices(ico, [(-0.2, 0.3, 1.0)])[0]
    assert moved not in anchors
    uv[moved] = uv[anchors[-1]]
    set_uv_attribute(ico, uv)
    group = ico.vertex_groups["wavg_anchors"]
    group.remove([anchors[-1]])
    group.add([moved], 1.0, 'REPLACE')
    anchors = sorted(anchors[:-1] + [moved])
    bpy.context.view_layer.update()
    # The edit started the idle timer; it runs once the object has been left alone.
    assert ico.as_pointer() in decal_memo._CHANGED, "the edit was not noticed"
    assert bpy.app.timers.is_registered(decal_memo._idle), "no idle timer"
    assert 0 < decal_memo._idle() <= decal_memo.IDLE, "read ahead during the edit"
    decal_memo._CHANGED[ico.as_pointer()] -= decal_memo.IDLE
    ahead = decal_memo.COMPUTED_AHEAD[0]
    assert decal_memo._idle() is None
    assert decal_memo.COMPUTED_AHEAD[0] == ahead + 1, "the idle timer read nothing ahead"
    hits, taken = group_cache.HITS[0], decal_memo.TAKEN[0]
    bpy.ops.wavg.decal_uv()
    assert group_cache.HITS[0] == hits + 1, "the click read the anchor group"
    assert decal_memo.TAKEN[0] == taken + 1, "the click computed the decal"
    check_decal(ico, anchors)
    # Read ahead, then edited again before the click: the click sees the edit.
    group.add([moved], 0.0, 'REPLACE')
    anchors.remove(moved)
    uv[anchors[0]] += (0.5, 0.5)
    set_uv_attribute(ico, uv)
    bpy.context.view_layer.update()
    assert decal_memo.read_ahead(ico)
    uv[anchors[0]] -= (0.5, 0.5)
    set_uv_attribute(ico, uv)
    bpy.ops.wavg.decal_uv()
    check_decal(ico, anchors)
    # Not in Edit mode, nor for an object the operator never ran on.
    bpy.ops.object.mode_set(mode='EDIT')
    assert not decal_memo.read_ahead(ico), "read ahead in Edit mode"
    bpy.ops.object.mode_set(mode='OBJECT')
    other = scene.icosphere("other", subdivisions=2)
    assert not decal_memo.read_ahead(other)
    decal_memo._CHANGED.clear()
    # In Weight Paint mode (which writes the groups to the mesh itself) it is read ahead;
    # the click back in Object mode takes that decal.
    bpy.ops.object.mode_set(mode='WEIGHT_PAINT')
    group.add([anchors[0]], 0.0, 'REPLACE')
    painted = anchors[1:]
    bpy.context.view_layer.update()
    assert decal_memo.read_ahead(ico), "nothing read ahead in Weight Paint mode"
    bpy.ops.object.mode_set(mode='OBJECT')
    taken = decal_memo.TAKEN[0]
    bpy.ops.wavg.decal_uv()
    assert decal_memo.TAKEN[0] == taken + 1, "the decal read ahead in Weight Paint not taken"
    check_decal(ico, painted)
    group.add([anchors[0]], 1.0, 'REPLACE')
    # The worker's decal is the operator's own (one made on Blender's thread).
    group.add([moved], 1.0, 'REPLACE')
    anchors = sorted(anchors + [moved])
    bpy.context.view_layer.update()
    start = time.perf_counter()
    assert decal_memo.read_ahead(ico)
    kept = decal_memo._DECALS[ico.as_pointer()]
    ahead_uv, ahead_valid = kept.get()
    decal_memo.forget_all()
    bpy.ops.wavg.decal_uv()
    assert decal_memo._DECALS[ico.as_pointer()] is not kept
    now_uv, now_valid = decal_memo._DECALS[ico.as_pointer()].get()
    assert np.array_equal(ahead_valid, now_valid)
    assert np.array_equal(ahead_uv, now_uv, equal_nan=True)
    print(f"    read ahead and its decal: {1e3 * (time.perf_counter() - start):.1f} ms")


def test_mesh_checked_not_read(ctx):
    """After a geometry update that left the positions and polygons (a vertex group
    edited), the mesh read before is used again; a moved vertex or a flipped edge (same
    positions, other triangles) is read anew, with its own fingerprint."""
    import bmesh
    from wavg_blender import surfaces

    ico = scene.icosphere("ico", subdivisions=2)
    scene.activate(ico)
    first = surfaces.mesh_input(ico)
    group = ico.vertex_groups.new(name="g")
    group.add([3], 0.5, 'REPLACE')
    bpy.context.view_layer.update()
    assert surfaces.mesh_input(ico) is first, "a vertex group edit made the mesh be read"
    me = ico.data
    me.vertices[7].co.x += 0.05
    me.update()
    moved = surfaces.mesh_input(ico)
    assert moved is not first and moved.key != first.key, "a moved vertex was not seen"
    me.vertices[7].co.x -= 0.05
    me.update()
    back = surfaces.mesh_input(ico)
    assert back.key == first.key and np.array_equal(back.F, first.F)
    bm = bmesh.new()
    bm.from_mesh(me)
    bm.edges.ensure_lookup_table()
    inner = next(e for e in bm.edges if len(e.link_faces) == 2)
    bmesh.ops.rotate_edges(bm, edges=[inner], use_ccw=False)
    bm.to_mesh(me)
    bm.free()
    me.update()
    flipped = surfaces.mesh_input(ico)
    assert flipped is not back and flipped.key != back.key, "a flipped edge was not seen"
    assert np.array_equal(flipped.V, back.V), "the flip moved a vertex"
    bpy.ops.ed.undo_push(message="flipped")
    bpy.ops.ed.undo()
    assert not surfaces._LAST, "meshes kept across an undo"


def test_group_read(ctx):
    """Vertex groups read through Geometry Nodes (Blender 4+) give what the visit of every
    vertex gives, weight for weight, leave nothing behind and keep the mesh read; the read
    declines (``None``) where it does not apply."""
    from wavg_blender import group_cache, group_read, surfaces
    from wavg_blender.meshdata import groups_members

    ico = scene.icosphere("ico", subdivisions=3)
    scene.activate(ico)
    n = len(ico.data.vertices)
    a = ico.vertex_groups.new(name="a")
    b = ico.vertex_groups.new(name="b weights")
    empty = ico.vertex_groups.new(name="empty")
    for v in range(0, n, 3):
        a.add([v], (v % 7) / 6.0, 'REPLACE')  # weight 0 every 7th: absent, as in the visit
    b.add(list(range(n // 2)), 0.375, 'REPLACE')
    b.add([1, 5], 1.0, 'REPLACE')
    groups = [a, b, empty]
    want = groups_members(ico, groups)
    assert len(want["a"][0]) > 30 and 0.0 in [(v % 7) / 6.0 for v in range(0, n, 3)]
    bpy.context.view_layer.update()
    kept = surfaces.mesh_input(ico)
    counts = [len(c) for c in (bpy.data.objects, bpy.data.meshes, bpy.data.node_groups)]
    before = group_read.READS[0]
    # The cost model: a small mesh is visited, a large one read in bulk, unless the scene
    # has too many objects.
    learned = group_read._SCALE[0]
    group_read._SCALE[0] = 1.0  # as at the start of a session
    assert not group_read.worth_it(bpy.context, n)
    assert group_read.members(bpy.context, ico, groups) is None, "a small mesh read in bulk"
    objects = len(bpy.context.view_layer.objects)
    assert group_read.worth_it(bpy.context, 25_000) is (objects < 250)
    assert not group_read.worth_it(bpy.context, 100 * max(objects, 2))  # per object: 100
    visit_us = group_read.VISIT_US
    group_read.VISIT_US = 1e6  # every mesh read in bulk, for this test
    try:
        got = group_read.members(bpy.context, ico, groups)
        got_cache = group_cache.members_of(bpy.context, ico, [a])["a"][0].tolist()
    finally:
        group_read.VISIT_US = visit_us
        group_read._SCALE[0] = learned
    if bpy.app.version < group_read.MIN_VERSION:
        assert got is None, "read through Geometry Nodes before Blender 4"
        assert group_read.READS[0] == before
    else:
        assert set(got) == set(want)
        for name, (ids, weights) in want.items():
            assert got[name][0].dtype == ids.dtype and got[name][1].dtype == weights.dtype
            assert np.array_equal(got[name][0], ids), name
            assert np.array_equal(got[name][1], weights), name
        # What the operators read goes this way.
        assert got_cache == want["a"][0].tolist()
        assert group_read.READS[0] == before + 2, "the group cache did not read in bulk"
    assert [len(c) for c in (bpy.data.objects, bpy.data.meshes, bpy.data.node_groups)] \
        == counts, "the read left data behind"
    bpy.context.view_layer.update()
    assert surfaces.mesh_input(ico) is kept, "the read made the mesh be read again"
    # Where it declines: a group named like an attribute, shape keys, Edit mode.
    # (Blender 4 refuses an attribute named like a group; a group named like an
    # attribute it may make.)
    ico.data.attributes.new("clash", 'FLOAT', 'POINT')
    clash = ico.vertex_groups.new(name="clash")
    clash.add([0, 1, 2], 1.0, 'REPLACE')
    if clash.name == "clash" and ico.data.attributes.get("clash") is not None:
        assert group_read.members(bpy.context, ico, [clash]) is None, "an ambiguous name read"
        assert group_cache.members_of(bpy.context, ico, [clash])["clash"][0].tolist() == \
            [0, 1, 2]
    bpy.ops.object.mode_set(mode='EDIT')
    assert group_read.members(bpy.context, ico, [a]) is None, "read in Edit mode"
    bpy.ops.object.mode_set(mode='OBJECT')
    ico.shape_key_add(name="Basis")
    assert group_read.members(bpy.context, ico, [a]) is None, "read with shape keys"


TESTS = [test_decal_kept, test_decal_read_ahead, test_mesh_checked_not_read, test_group_read]
